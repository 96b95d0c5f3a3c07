//! A user's own `Env` (a 1-D corridor, `examples/corridor.rs`) trains through the facade,
//! with no dependency but `hstl`.

#[path = "../examples/corridor.rs"]
mod corridor;

use corridor::{Corridor, SPEC};
use hstl::runtime::eval::{AgentController, rollout};
use hstl::runtime::{Env, Learner, Policy, seeded_rng};

#[test]
fn a_corridor_learns_to_walk_right_and_its_policy_round_trips() {
    let checked = hstl::lang::check(SPEC);
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics);
    let spec = hstl::lower::task_spec(&checked.specs[0], SPEC).unwrap();
    let env = Corridor { len: 10, slip: 0.2 };
    let mut learner = Learner::new(&spec, &env).unwrap();
    learner.train(&mut seeded_rng(1), |_, _| {});
    let agent = learner.agent();
    // Every cell left of the goal moves right (action 1).
    assert!(agent.flat[0][..9].iter().all(|&a| a == 1), "{:?}", agent.flat[0]);
    // A greedy run from the left end reaches the goal.
    let run = rollout(&env, &mut AgentController::new(&agent), 0, 30, &mut seeded_rng(2));
    assert!(
        run.iter().any(|s| s.state == 9),
        "{:?}",
        run.iter().map(|s| s.state).collect::<Vec<_>>()
    );
    // policy.json records the corridor and reloads onto it.
    let policy = Policy::new(&learner);
    assert_eq!(policy.env.name, "corridor");
    assert_eq!(policy.env.params, env.params());
    let back = Policy::from_json(&policy.to_json().unwrap()).unwrap();
    assert_eq!(back.agent(&env).unwrap(), agent);
}
