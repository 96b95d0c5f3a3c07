//! The tabular learner's options level sees the goals a run has met (LANGUAGE.md, "Task
//! progress"): once the sequence is done, it keeps the rest of the task instead of starting
//! the sequence again.

use hstl::runtime::eval::{AgentController, rollout};
use hstl::runtime::{Env, GridWorld, Learner, Policy, seeded_rng};

/// Reach A (one corner) within 25 steps and B (the opposite one) within 50, never entering
/// O (the middle) over 100 steps. Starting [A, B] again from B crosses the grid past O; B
/// alone stays in its corner.
const SEQUENCE: &str = "spec Sequence {
    state { x: int in 0..=9, y: int in 0..=9 }
    let A = x > 7 && y < 2;
    let B = x < 2 && y > 7;
    let O = x > 2 && x < 7 && y > 2 && y < 7;
    task eventually[0..=25] A && eventually[0..=50] B && always[0..=100] !O;
    option A;
    option B;
    options { [A, B], B }
    learn { preset: auto }
}
";

fn lowered(src: &str) -> hstl::runtime::TaskSpec {
    let checked = hstl::lang::check(src);
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics);
    hstl::lower::task_spec(&checked.specs[0], src).expect("lowers")
}

#[test]
fn once_the_sequence_is_done_the_options_level_keeps_the_rest() {
    let env = GridWorld::new(10, 10, 0.9).expect("a grid");
    let spec = lowered(SEQUENCE);
    let mut learner = Learner::new(&spec, &env).expect("a learner");
    learner.train(&mut seeded_rng(1), |_, _| {});
    let agent = learner.agent();
    let goals = agent.goals.as_ref().expect("the sequence is a goal");
    assert_eq!(goals.progress.goals(), 2);
    // The document lists the goal and an options entry per state and goals met, and loads
    // back to the same agent with the spec, not without it.
    let policy = Policy::new(&learner);
    assert_eq!(policy.goals.as_ref().map(Vec::len), Some(2));
    assert_eq!(policy.options_policy.len(), 4 * 100);
    let back = Policy::from_json(&policy.to_json().expect("JSON")).expect("reads back");
    back.check_against(&spec, &env).expect("consistent");
    assert_eq!(back.agent_for(&spec, &env).expect("an agent"), agent);
    let refused = back.agent(&env).expect_err("needs the spec").to_string();
    assert!(refused.contains("agent_for"), "{refused}");

    // Near the optimum: the exact satisfaction probability of the best policy.
    let summary = hstl::train::reach_avoid_summary(&spec, &env, &agent, 1)
        .expect("evaluates")
        .expect("a reach-avoid task");
    assert!(summary.rate >= 0.9 * summary.optimum, "{} of {}", summary.rate, summary.optimum);
    // Once both are met, the options level picks B, which stays in its corner.
    let in_b = |s: usize| s % 10 < 2 && s / 10 > 7;
    let in_a = |s: usize| s % 10 > 7 && s / 10 < 2;
    let (mut after, mut holding) = (0, 0);
    let mut rng = seeded_rng(7);
    let mut controller = AgentController::new(&agent);
    for _ in 0..50 {
        let start = env.index(&env.reset(&mut rng));
        let run = rollout(&env, &mut controller, start, 100, &mut rng);
        let states: Vec<usize> = run.iter().map(|s| s.state).collect();
        // Both goals met in time: A by step 25, then B by step 50.
        let a = states.iter().position(|&s| in_a(s)).filter(|&a| a <= 25);
        let b = a.and_then(|a| (a..run.len()).find(|&t| in_b(states[t])));
        if let Some(met) = b.filter(|&b| b <= 50) {
            // From the step after the one that enters B, which ends the leg.
            after += run.len() - met - 1;
            holding += run[met + 1..].iter().filter(|s| s.decision.option == 1).count();
        }
    }
    assert!(after > 0, "no run met the goals");
    assert!(holding as f64 >= 0.9 * after as f64, "{holding} of {after} steps held");
}
