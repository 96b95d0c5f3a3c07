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
    assert_eq!(back.agent_for(&spec, &env).unwrap(), agent);
}

/// The corridor as an episodic environment: an episode ends at the right end (as a
/// gymnasium environment's `terminated`). It counts its steps and resets, and notes a step
/// taken after an episode ended without a reset between.
struct Episodic {
    corridor: Corridor,
    ended: std::cell::Cell<bool>,
    steps: std::cell::Cell<u64>,
    resets: std::cell::Cell<u64>,
    stepped_after_end: std::cell::Cell<bool>,
}

impl Env for Episodic {
    type State = usize;

    fn name(&self) -> &str {
        "episodic-corridor"
    }

    fn params(&self) -> hstl::runtime::Value {
        self.corridor.params()
    }

    fn state_vars(&self) -> Vec<String> {
        self.corridor.state_vars()
    }

    fn actions(&self) -> Vec<String> {
        Env::actions(&self.corridor)
    }

    fn num_states(&self) -> usize {
        self.corridor.num_states()
    }

    fn index(&self, state: &usize) -> usize {
        *state
    }

    fn state(&self, index: usize) -> Option<usize> {
        Env::state(&self.corridor, index)
    }

    fn valuation(&self, state: &usize, out: &mut Vec<f64>) {
        Env::valuation(&self.corridor, state, out)
    }

    fn reset(&self, rng: &mut hstl::runtime::Rng) -> usize {
        self.resets.set(self.resets.get() + 1);
        self.ended.set(false);
        // Always from the left end, so that an episode takes several steps.
        let _ = Env::reset(&self.corridor, rng);
        0
    }

    fn step(&self, state: &usize, action: usize, rng: &mut hstl::runtime::Rng) -> usize {
        if self.ended.get() {
            self.stepped_after_end.set(true);
        }
        self.steps.set(self.steps.get() + 1);
        let next = Env::step(&self.corridor, state, action, rng);
        self.ended.set(next == self.corridor.len - 1);
        next
    }

    fn episode_end(&self) -> Option<hstl::runtime::EpisodeEnd> {
        self.ended.get().then_some(hstl::runtime::EpisodeEnd::Terminated)
    }
}

#[test]
fn an_episode_the_environment_ends_ends_the_learners_and_only_real_steps_count() {
    let checked = hstl::lang::check(SPEC);
    let mut spec = hstl::lower::task_spec(&checked.specs[0], SPEC).unwrap();
    spec.learn.episodes = 60;
    let env = Episodic {
        corridor: Corridor { len: 10, slip: 0.2 },
        ended: Default::default(),
        steps: Default::default(),
        resets: Default::default(),
        stepped_after_end: Default::default(),
    };
    let mut learner = Learner::new(&spec, &env).unwrap();
    let trained = learner.train(&mut seeded_rng(3), |_, _| {});
    assert!(!env.stepped_after_end.get(), "a step after the episode ended, without a reset");
    assert_eq!(trained.steps, env.steps.get(), "every counted step is one the environment took");
    assert_eq!(env.resets.get(), 60);
    // The learner's episodes stop at the end: far fewer steps than choices x max_steps
    // per episode, and the greedy policy walks right.
    assert!(trained.steps < 60 * 20 * spec.learn.max_steps as u64 / 4, "{}", trained.steps);
    assert!(learner.agent().flat[0][..9].iter().all(|&a| a == 1));
}
