//! The memory model (`hstl_lang::budget::cost`) against what training, writing and
//! reading `policy.json` allocate, measured by a counting allocator: the model bounds each
//! run from above and is not far above it, so that what `check` accepts within the budget
//! runs within it. Also: a `policy.json` is read in one typed pass (a large field no policy
//! has costs nothing to skip).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

use hstl_lang::budget::{FIXED_BYTES, cost, spec_sizes};

struct Counting;

static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call is passed to the system allocator unchanged; the counters only add.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        CURRENT.fetch_sub(layout.size(), Ordering::Relaxed);
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // A moving realloc holds both blocks for a moment: counted as such.
        let now = CURRENT.fetch_add(new_size, Ordering::Relaxed) + new_size;
        PEAK.fetch_max(now, Ordering::Relaxed);
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if p.is_null() {
            CURRENT.fetch_sub(new_size, Ordering::Relaxed);
        } else {
            CURRENT.fetch_sub(layout.size(), Ordering::Relaxed);
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// What `f` allocates at most beyond what was allocated before it.
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, u64) {
    let base = CURRENT.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let out = f();
    (out, (PEAK.load(Ordering::Relaxed) - base) as u64)
}

fn spec(memory: u64, regions: &[&str]) -> String {
    let lets = [
        "let A = x > 3 && x < 9 && y > 10 && y < 14;",
        "let B = x > 1 && x < 5 && y > 1 && y < 5;",
        "let C = 9 < x < 13 && 1 < y < 7;",
    ];
    let used: Vec<&str> = lets
        .iter()
        .copied()
        .filter(|l| regions.iter().any(|r| l.starts_with(&format!("let {r} "))))
        .collect();
    let task: Vec<String> = regions.iter().map(|r| format!("eventually[0..40] {r}")).collect();
    let options: Vec<String> = regions
        .iter()
        .map(|r| format!("option {r} {{ reach: {r}, init: !{r}, terminate: {r} }}"))
        .collect();
    format!(
        "spec S {{ state {{ x: int in 0..=14, y: int in 0..=14 }} {} task always[0..] ({}); {} \
         options {{ {} }} learn {{ episodes: 2, choices: 5, memory: {memory}, reward: window }} }}",
        used.join(" "),
        task.join(" && "),
        options.join(" "),
        regions.join(", ")
    )
}

/// Reach A and then B, never entering O: two goals, and `keep_clear` from the preset.
const REACH_TWO: &str = "spec Two {
    state { x: int in 0..=14, y: int in 0..=14 }
    let A = x > 11 && y < 3;
    let B = x < 3 && y > 11;
    let O = x > 5 && x < 9 && y > 5 && y < 9;
    task eventually[0..=30] A && eventually[0..=60] B && always !O;
    option A;
    option B;
    learn { preset: auto, episodes: 20 }
}
";

// One test: the counters are the process's, so nothing else may run beside it.
#[test]
fn memory() {
    the_memory_model_bounds_training_writing_and_reading_a_policy();
    a_large_unknown_field_is_skipped_not_kept();
    the_memory_model_bounds_a_learned_function();
}

/// The approximate learner's part of the model (`budget::approx_cost`) over a plane spec:
/// its weights all made non-zero before `policy.json` is written (the worst case, since the
/// document lists the non-zero ones), training and writing, then reading back, stay within
/// the model, and not far below it.
fn the_memory_model_bounds_a_learned_function() {
    use hstl::runtime::world::AnyWorld;
    let world = AnyWorld::builtin("paper-plane").expect("paper-plane");
    for memory in [2, 6] {
        let src = format!(
            "spec P {{ state {{ x: float in 0..=14, y: float in 0..=14 }}
               let A = x > 3.5 && x < 8.5 && y > 10.5 && y < 13.5;
               let B = x > 1.5 && x < 4.5 && y > 1.5 && y < 4.5;
               let C = 9.5 < x < 12.5 && 1.5 < y < 6.5;
               task always[0..] (eventually[0..40] A && eventually[0..40] B && eventually[0..40] C);
               option A; option B; option C;
               learn {{ preset: auto, memory: {memory}, episodes: 1, choices: 2 }} }}"
        );
        let loaded = hstl::load::load(&src, None).expect("checks");
        let mut task = hstl::train::trainable(&loaded.spec, &src, "s.hstl").expect("trainable");
        hstl::continuous::fit_tiles(&mut task, &loaded.spec, &world);
        let AnyWorld::Plane(plane) = &world else { unreachable!() };
        let sizes = hstl::cost::approx_sizes(&task, plane).expect("sizes");
        let model = hstl_lang::budget::approx_cost(&sizes);
        let (text, train) = peak_of(|| {
            let mut trained = hstl::continuous::train(&task, &world, 0, |_, _| {}).expect("trains");
            let w = &mut trained.agent.weights;
            for (i, v) in w.flat.iter_mut().flatten().chain(w.options.iter_mut()).enumerate() {
                *v = 1.0 + i as f64;
            }
            hstl::continuous::policy_json(&task, &world, &trained.agent, &src, 0).expect("writes")
        });
        let (replay, load) = peak_of(|| hstl::continuous::replay_text(&text).expect("replays"));
        drop(replay);
        let bytes = text.len() as u64;
        let modelled_train = model.train - FIXED_BYTES;
        let modelled_load = model.load - FIXED_BYTES - model.policy_bytes;
        let what = format!("learned function, memory {memory}");
        eprintln!(
            "{what}: {} weights, train {train} (model {modelled_train}), load {load} (model {modelled_load}), text {bytes} (model {})",
            hstl_lang::budget::approx_weights(&sizes),
            model.policy_bytes
        );
        assert!(
            bytes <= model.policy_bytes,
            "{what}: policy.json {bytes} > {}",
            model.policy_bytes
        );
        assert!(train <= modelled_train, "{what}: train {train} > {modelled_train}");
        assert!(load <= modelled_load, "{what}: load {load} > {modelled_load}");
        assert!(modelled_train <= 4 * train, "{what}: train {train}, model {modelled_train}");
        assert!(modelled_load <= 4 * load, "{what}: load {load}, model {modelled_load}");
    }
}

fn the_memory_model_bounds_training_writing_and_reading_a_policy() {
    let world = hstl::world::GridWorld::builtin("paper").expect("paper");
    let cases =
        [(0, &["A", "B"][..]), (4, &["A", "B"]), (8, &["A", "B", "C"]), (12, &["A", "B", "C"])];
    let persistent =
        cases.iter().map(|&(memory, regions)| (memory, regions, spec(memory, regions)));
    // A task with goals: the options level's table and `options_policy` hold a row per
    // set of goals met (2^2 here), and the preset adds `keep_clear`.
    let goals = (0, &["goals"][..], REACH_TWO.to_string());
    for (memory, regions, src) in persistent.chain(std::iter::once(goals)) {
        let loaded = hstl::load::load(&src, None).expect("checks");
        let sizes = spec_sizes(&src, &loaded.spec).expect("a tabular spec");
        if regions == ["goals"] {
            assert_eq!(sizes.goals, 2, "two goals");
            let names: Vec<&str> = loaded.spec.options.iter().map(|o| o.name.as_str()).collect();
            assert!(names.contains(&"keep_clear"), "{names:?}");
            assert_eq!(sizes.options, names.len() as u64);
        }
        let model = cost(&sizes);
        let task = hstl::train::trainable(&loaded.spec, &src, "s.hstl").expect("trainable");
        // The facade's sizes (the world's states) are the checker's on the open grid.
        assert_eq!(hstl::cost::sizes(&task, &world), sizes, "memory {memory}");
        let (text, train) = peak_of(|| {
            let trained = hstl::train::train(&task, &world, 0, |_, _| {}).expect("trains");
            hstl::train::policy_json(&trained.policy, &src, 0).expect("writes")
        });
        let (replay, load) = peak_of(|| hstl::evaluate::replay(&text).expect("replays"));
        drop(replay);
        let what = format!("memory {memory} over {regions:?}");
        let bytes = text.len() as u64;
        assert!(
            bytes <= model.policy_bytes,
            "{what}: policy.json {bytes} > {}",
            model.policy_bytes
        );
        assert!(
            model.policy_bytes <= 2 * bytes,
            "{what}: policy.json {bytes}, model {}",
            model.policy_bytes
        );
        let modelled_train = model.train - FIXED_BYTES;
        // The text is held by the caller while the document is read.
        let modelled_load = model.load - FIXED_BYTES - model.policy_bytes;
        eprintln!(
            "{what}: train {train} (model {modelled_train}), load {load} (model {modelled_load}), text {bytes}"
        );
        assert!(
            train <= modelled_train,
            "{what}: training took {train} bytes, the model {modelled_train}"
        );
        assert!(
            load <= modelled_load,
            "{what}: reading took {load} bytes, the model {modelled_load}"
        );
        if memory >= 8 {
            // Where the tables dominate, the model is an upper bound, not a guess.
            assert!(modelled_train <= 4 * train, "{what}: train {train}, model {modelled_train}");
            assert!(modelled_load <= 4 * load, "{what}: load {load}, model {modelled_load}");
        }
    }
}

/// Issue 30: `eval` and `hstl.Policy.load` parsed `policy.json` a second time as a generic
/// JSON value (16 bytes per byte): a field no policy has now costs nothing to skip.
fn a_large_unknown_field_is_skipped_not_kept() {
    let src = spec(0, &["A", "B"]);
    let loaded = hstl::load::load(&src, None).expect("checks");
    let task = hstl::train::trainable(&loaded.spec, &src, "s.hstl").expect("trainable");
    let world = hstl::world::GridWorld::builtin("paper").expect("paper");
    let trained = hstl::train::train(&task, &world, 0, |_, _| {}).expect("trains");
    let text = hstl::train::policy_json(&trained.policy, &src, 0).expect("writes");
    let padding = format!("[{}0]", "0, ".repeat(2_000_000));
    let padded = format!("{{\"padding\": {padding}, {}", &text[1..]);
    drop(padding);
    let (_, plain) = peak_of(|| hstl::evaluate::replay(&text).expect("replays"));
    let (_, with_padding) = peak_of(|| hstl::evaluate::replay(&padded).expect("replays"));
    assert!(
        with_padding <= plain + (1 << 20),
        "6 MB of padding took {with_padding} bytes to read, the policy alone {plain}"
    );
}
