//! Option runs far longer than the suffix budget, under a past window without an end: the
//! scorer scores only some suffixes of each run (`hstl_robustness::segment::SUFFIX_BUDGET`),
//! and the learner leaves the others out of its updates.

use hstl::runtime::robustness::segment::SUFFIX_BUDGET;
use hstl::runtime::{GridWorld, Learner, seeded_rng};

/// A far corner on a 60 x 60 grid, from random starts with the flat level exploring at
/// every step: the first runs are random walks of thousands of steps.
const WATCH: &str = "spec Watch {
    state { x: int in 0..=59, y: int in 0..=59 }
    let Corner = x > 56 && y > 56;
    let Left = x < 3;
    task always[0..] (once[0..] Left -> y > 1);
    option Corner;
    learn {
        episodes: 3,
        choices: 2,
        max_steps: 20000,
        flat: { gamma: 0.9, alpha: 0.2, epsilon: 1, min_epsilon: 1, decay: 0 },
    }
}
";

#[test]
fn runs_past_the_suffix_budget_train_and_leave_no_nan_in_the_options_table() {
    let checked = hstl::lang::check(WATCH);
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics);
    // `check` says the runs will be thinned.
    assert!(checked.diagnostics.iter().any(|d| d.code == "HSTL190"), "{:?}", checked.diagnostics);
    let spec = hstl::lower::task_spec(&checked.specs[0], WATCH).expect("lowers");
    let env = GridWorld::new(60, 60, 1.0).expect("a grid");
    let mut learner = Learner::new(&spec, &env).expect("a learner");
    let before = learner.q().options.clone();
    learner.train(&mut seeded_rng(3), |_, _| {});
    let q = learner.q();
    // Some run was long enough to be thinned: 2 * budget steps.
    assert!(q.steps > 2 * SUFFIX_BUDGET as u64, "{} steps", q.steps);
    let nan = q.options.iter().filter(|v| v.is_nan()).count();
    assert_eq!(nan, 0, "{nan} NaN options values");
    let changed = q.options.iter().zip(&before).filter(|(a, b)| a != b).count();
    assert!(changed > 0, "no options value learned");
}

/// The same on `paper-plane` with the approximate learner.
const PLANE_WATCH: &str = "spec PlaneWatch {
    world \"paper-plane\";
    state { x: float in 0..=14, y: float in 0..=14 }
    let Corner = x > 13.5 && y > 13.5;
    let Left = x < 1;
    task always[0..] (once[0..] Left -> y > 0.5);
    option Corner;
    learn {
        preset: auto,
        episodes: 3,
        choices: 2,
        max_steps: 20000,
        flat: { gamma: 0.9, alpha: 0.2, epsilon: 1, min_epsilon: 1, decay: 0 },
    }
}
";

#[test]
fn the_approximate_learner_leaves_no_nan_in_its_options_weights() {
    use hstl::continuous as c;
    let world = hstl::world::AnyWorld::builtin("paper-plane").expect("built in");
    let loaded = hstl::load::load(PLANE_WATCH, None).expect("the spec checks");
    let mut spec =
        hstl::train::trainable(&loaded.spec, PLANE_WATCH, "spec.hstl").expect("trainable");
    c::fit_tiles(&mut spec, &loaded.spec, &world);
    let t = c::train(&spec, &world, 3, |_, _| {}).expect("trains");
    let w = &t.agent.weights.options;
    let nan = w.iter().filter(|v| v.is_nan()).count();
    assert_eq!(nan, 0, "{nan} NaN options weights");
    assert!(w.iter().any(|&v| v != 0.0), "no options weight learned");
}
