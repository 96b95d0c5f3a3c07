//! The approximate learner in the one memory model (`hstl_lang::budget::approx_weights`):
//! `check` and `train` count a learned function's weights alike, and that count is what
//! the runtime allocates; a spec over the budget is refused by `check` (HSTL084), and
//! `preset: auto` sizes the memory of a continuous spec to fit. A policy trained when the
//! preset chose another memory is refused for that reason, in words.

use hstl::runtime::approx::Model;
use hstl::runtime::world::AnyWorld;
use hstl::runtime::{Rng, World};
use hstl_lang::budget::{self, MAX_WEIGHTS};
use serde_json::{Value, json};

const PLANE: &str = "spec P {
    state { x: float in 0..=14, y: float in 0..=14 }
    let A = x > 3.5 && x < 8.5 && y > 10.5 && y < 13.5;
    let B = x > 1.5 && x < 4.5 && y > 1.5 && y < 4.5;
    let C = 9.5 < x < 12.5 && 1.5 < y < 6.5;
    task always[0..] (eventually[0..40] A && eventually[0..40] B && eventually[0..40] C);
    option A; option B; option C;
    learn { LEARN }
}";

const CAR: &str = "spec M {
    state { x: float in -1.2..=0.6, v: float in -0.07..=0.07 }
    let Left = x < -0.9;
    let Right = x > 0.3;
    task always[0..] (eventually[0..200] Left && eventually[0..200] Right);
    option Left; option Right;
    learn { LEARN }
}";

const REACH: &str = "spec R {
    state { x: float in 0..=14, y: float in 0..=14 }
    let A = x > 10 && y > 10;
    let B = x < 3 && y < 3;
    task eventually[0..=300] A && eventually[0..=300] B;
    option A; option B;
    learn { LEARN }
}";

/// The CartPole patrol of `bench/field/specs/cartpole_patrol.hstl`: four float variables,
/// so the tilings are hashed, and three regions counted by the memory.
const CARTPOLE: &str = "spec CartPolePatrol {
    state {
        x: float in -4.8..=4.8,
        dx: float in -10.0..=10.0,
        theta: float in -0.42..=0.42,
        dtheta: float in -10.0..=10.0,
    }
    let left = x < -1.0;
    let right = x > 1.0;
    let fallen = theta <= -0.2095 || theta >= 0.2095 || x <= -2.4 || x >= 2.4;
    task always[0..] (eventually[0..200] left && eventually[0..200] right) && always[0..] !fallen;
    option left;
    option right;
    learn { LEARN }
}";

fn spec(template: &str, learn: &str) -> String {
    template.replace("LEARN", learn)
}

/// What `check` counts for `src` against `world`, and the diagnostics' codes.
fn check_count(src: &str, world: Option<&AnyWorld>) -> (u64, Vec<String>) {
    let facts = world.map(|w| hstl::world::any_facts(w, "the world"));
    let checked = match &facts {
        Some(f) => {
            hstl_lang::check_parsed_with_worlds(src, hstl_lang::parse(src), &|_| f.spec_world())
        }
        None => hstl_lang::check(src),
    };
    let codes = checked.diagnostics.iter().map(|d| d.code.to_string()).collect();
    let (fit, actions) = match &facts {
        Some(hstl::world::Facts::Box(b)) => (b.fit, Some(b.actions)),
        _ => (None, None),
    };
    let sizes =
        budget::approx_spec_sizes(src, &checked.specs[0], fit, actions).expect("continuous");
    (budget::approx_weights(&sizes), codes)
}

/// What `train` counts for `src` in `world` (its tiling fitted as training fits it).
fn train_count<W: World>(
    src: &str,
    world: &W,
    any: Option<&AnyWorld>,
) -> (u64, hstl::runtime::TaskSpec) {
    let checked = hstl_lang::check(src);
    let picked = &checked.specs[0];
    let mut task = hstl::train::trainable(picked, src, "s.hstl").expect("trainable");
    if let Some(w) = any {
        hstl::continuous::fit_tiles(&mut task, picked, w);
    }
    let sizes = hstl::cost::approx_sizes(&task, world).expect("sizes");
    (budget::approx_weights(&sizes), task)
}

#[test]
fn check_and_train_count_the_weights_the_runtime_allocates() {
    let plane = AnyWorld::builtin("paper-plane").expect("paper-plane");
    let car = AnyWorld::builtin("mountain-car").expect("mountain-car");
    let yard = AnyWorld::from_toml(
        &std::fs::read_to_string("examples/worlds/yard.toml").expect("yard.toml"),
        "yard",
    )
    .expect("yard");
    let cases = [
        (spec(PLANE, "preset: auto"), &plane),
        (spec(PLANE, "preset: auto, memory: 12"), &plane),
        (spec(PLANE, "preset: auto, memory: 4, tiles: { tilings: 16, bins: 30 }"), &plane),
        (spec(PLANE, "preset: auto, tiles: { tilings: 3 }"), &plane),
        (spec(CAR, "preset: auto"), &car),
        (spec(CAR, "preset: auto, memory: 20"), &car),
        (spec(REACH, "preset: auto"), &plane),
        (spec(PLANE, "preset: auto"), &yard),
    ];
    let mut seen = Vec::new();
    for (src, world) in cases {
        let (checked, codes) = check_count(&src, Some(world));
        assert!(!codes.iter().any(|c| c == "HSTL084"), "{src}: {codes:?}");
        let (trained, task) = match world {
            AnyWorld::Plane(w) => train_count(&src, w, Some(world)),
            AnyWorld::MountainCar(w) => train_count(&src, w, Some(world)),
            AnyWorld::Grid(_) => unreachable!(),
        };
        assert_eq!(checked, trained, "{src}");
        // The count is the weights the learner holds.
        let allocated = match world {
            AnyWorld::Plane(w) => Model::new(&task, w).expect("model").zero_weights(),
            AnyWorld::MountainCar(w) => Model::new(&task, w).expect("model").zero_weights(),
            AnyWorld::Grid(_) => unreachable!(),
        };
        let held = allocated.flat.iter().map(Vec::len).sum::<usize>() + allocated.options.len();
        assert_eq!(held as u64, trained, "{src}");
        seen.push(trained);
    }
    // The cases differ: the count follows the tiles, tilings, memory, goals and world.
    seen.sort_unstable();
    seen.dedup();
    assert!(seen.len() >= 7, "{seen:?}");
}

/// A CartPole-like world: four variables in the spec's box, two pushes.
struct Cart;

impl World for Cart {
    type State = [f64; 4];
    fn name(&self) -> &str {
        "cart"
    }
    fn params(&self) -> Value {
        json!({})
    }
    fn state_vars(&self) -> Vec<String> {
        ["x", "dx", "theta", "dtheta"].map(String::from).to_vec()
    }
    fn actions(&self) -> Vec<String> {
        vec!["left".into(), "right".into()]
    }
    fn valuation(&self, state: &[f64; 4], out: &mut Vec<f64>) {
        out.clear();
        out.extend(state);
    }
    fn reset(&self, _rng: &mut Rng) -> [f64; 4] {
        [0.0; 4]
    }
    fn step(&self, state: &[f64; 4], _action: usize, _rng: &mut Rng) -> [f64; 4] {
        *state
    }
}

#[test]
fn the_cartpole_preset_fits_and_its_old_memory_is_refused_by_check_and_train_alike() {
    // The preset's memory (30 buckets from the 200-step deadlines) is made coarser until
    // the learned function fits: check is clean of HSTL084, and train takes it.
    let auto = spec(CARTPOLE, "preset: auto");
    let checked = hstl_lang::check(&auto);
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics);
    let memory = checked.specs[0].learn.memory;
    assert!((1..30).contains(&memory), "memory {memory}");
    let (counted, _) = check_count(&auto, None);
    let (trained, task) = train_count(&auto, &Cart, None);
    assert_eq!(counted, trained);
    assert!(hstl::cost::check_approx(&task, &Cart).is_ok());
    // The preset's first choice, written out, is over the budget: check refuses it with
    // HSTL084, and train with the same count in its message.
    let written = spec(CARTPOLE, "preset: auto, memory: 30");
    let (counted, codes) = check_count(&written, None);
    assert!(counted > MAX_WEIGHTS, "{counted}");
    assert!(codes.iter().any(|c| c == "HSTL084"), "{codes:?}");
    let d = hstl_lang::check(&written);
    let message = &d.diagnostics.iter().find(|d| d.code == "HSTL084").expect("HSTL084").message;
    let words = budget::thousands(counted);
    assert!(message.contains(&words), "{message}");
    let (trained, task) = train_count(&written, &Cart, None);
    assert_eq!(counted, trained);
    let refused = hstl::cost::check_approx(&task, &Cart).expect_err("over the budget");
    assert!(refused.message.contains(&words), "{}", refused.message);
    assert!(!refused.message.contains('{'), "{}", refused.message);
}

#[test]
fn a_policy_from_before_the_presets_memory_changed_is_refused_for_that_reason() {
    // Trained when `preset: auto` chose `memory: 3`: the document's `spec_source` is what
    // the spec says today (`preset: auto`, which now gives another memory).
    let then = spec(PLANE, "preset: auto, memory: 3, episodes: 2, choices: 3");
    let now = spec(PLANE, "preset: auto, episodes: 2, choices: 3");
    let now_memory = hstl_lang::check(&now).specs[0].learn.memory;
    assert_ne!(now_memory, 3);
    let world = AnyWorld::builtin("paper-plane").expect("paper-plane");
    let checked = hstl_lang::check(&then);
    let mut task = hstl::train::trainable(&checked.specs[0], &then, "s.hstl").expect("trainable");
    hstl::continuous::fit_tiles(&mut task, &checked.specs[0], &world);
    let trained = hstl::continuous::train(&task, &world, 1, |_, _| {}).expect("trains");
    let text =
        hstl::continuous::policy_json(&task, &world, &trained.agent, &then, 1).expect("writes");
    let mut doc: Value = serde_json::from_str(&text).expect("json");
    doc["spec_source"] = json!(now);
    let old = serde_json::to_string(&doc).expect("json");
    let refused = hstl::continuous::replay_text(&old).expect_err("another memory");
    assert!(refused.message.contains("trained with `memory: 3`"), "{}", refused.message);
    assert!(
        refused.message.contains(&format!("now gives `memory: {now_memory}`")),
        "{}",
        refused.message
    );
    assert!(!refused.message.contains("edited or damaged"), "{}", refused.message);
    let help = refused.help.as_deref().unwrap_or("");
    assert!(help.contains("write `memory: 3`"), "{help}");
    // The same document with `memory: 3` written in its spec replays.
    assert!(hstl::continuous::replay_text(&text).is_ok());

    // The tables' form alike (a grid spec whose memory the preset chose).
    let grid = |learn: &str| {
        format!(
            "spec G {{ state {{ x: int in 0..=14, y: int in 0..=14 }}
              let A = x > 3 && x < 9 && y > 10 && y < 14;
              let B = x > 1 && x < 5 && y > 1 && y < 5;
              task always[0..] (eventually[0..40] A && eventually[0..40] B);
              option A; option B; learn {{ {learn} }} }}"
        )
    };
    let then = grid("preset: auto, memory: 2, episodes: 2, choices: 3");
    let now = grid("preset: auto, episodes: 2, choices: 3");
    let loaded = hstl::load::load(&then, None).expect("checks");
    let task = hstl::train::trainable(&loaded.spec, &then, "g.hstl").expect("trainable");
    let paper = hstl::runtime::GridWorld::builtin("paper").expect("paper");
    let trained = hstl::train::train(&task, &paper, 1, |_, _| {}).expect("trains");
    let text = hstl::train::policy_json(&trained.policy, &then, 1).expect("writes");
    let mut doc: Value = serde_json::from_str(&text).expect("json");
    doc["spec_source"] = json!(now);
    let refused = hstl::evaluate::replay(&serde_json::to_string(&doc).expect("json"))
        .expect_err("another memory");
    assert!(refused.message.contains("trained with `memory: 2`"), "{}", refused.message);
    assert!(!refused.message.contains("edited or damaged"));
    // A memory written in the spec and edited in the document is still an edit.
    let written = grid("memory: 5, reward: window, episodes: 2, choices: 3");
    doc["spec_source"] = json!(written);
    let refused =
        hstl::evaluate::replay(&serde_json::to_string(&doc).expect("json")).expect_err("edited");
    assert!(!refused.message.contains("preset"), "{}", refused.message);
}
