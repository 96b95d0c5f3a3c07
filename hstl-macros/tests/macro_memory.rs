//! The memory variant of the case study (`memory: 8`, `reward: window`) through the macro:
//! the generated spec carries the memory and the window reward to the runtime, and the
//! learner trains on it.

use hstl::hstl;

hstl! { include "../examples/specs/surveillance_memory.hstl" }

#[test]
fn the_memory_spec_carries_memory_and_the_window_reward() {
    use hstl::runtime::{Intra, RewardKind, Spec};
    let spec = surveillance_memory::SurveillanceMemory.task_spec();
    spec.validate().expect("the memory variant is a valid runtime spec");
    assert_eq!(spec.learn.memory, 8);
    assert_eq!(spec.learn.reward, RewardKind::Window);
    assert_eq!(spec.learn.intra, Intra::Paper);
    assert_eq!((spec.learn.options.gamma, spec.learn.options.alpha), (0.98, 0.1));
    assert_eq!(spec.options.iter().map(|o| o.name.as_str()).collect::<Vec<_>>(), ["A", "B", "C"]);
    assert_eq!(spec.regions.iter().map(|r| r.horizon).collect::<Vec<_>>(), [40, 40, 40]);
}

#[test]
fn the_memory_spec_trains_through_the_macro() {
    use hstl::runtime::{GridWorld, Learner, Policy, Spec, seeded_rng};
    let mut spec = surveillance_memory::SurveillanceMemory.task_spec();
    spec.learn.episodes = 3;
    spec.learn.choices = 10;
    let env = GridWorld::default();
    let train = |seed| {
        let mut learner = Learner::new(&spec, &env).expect("the memory variant fits the grid");
        let trained = learner.train(&mut seeded_rng(seed), |_, _| {});
        let agent = learner.agent();
        (trained.curve, learner.q().clone(), agent, Policy::new(&learner))
    };
    let (curve, q, agent, policy) = train(3);
    assert_eq!(curve.len(), 3);
    // A window reward is a discounted count of kept steps: never negative.
    assert!(curve.iter().all(|&r| r >= 0.0), "{curve:?}");
    // The options table is indexed by state and memory: 225 cells x 9^3 values x 3 options.
    assert_eq!(q.options.len(), 225 * 729 * 3);
    assert_eq!(agent.memory.as_ref().map(|m| m.buckets), Some(8));
    assert_eq!(
        policy.memory.as_ref().map(|m| m.regions.clone()),
        Some(vec!["A".to_string(), "B".to_string(), "C".to_string()])
    );
    let (curve2, q2, _, _) = train(3);
    assert_eq!((curve, q), (curve2, q2));
}
