//! An environment stepped from outside (`hstl::outside`, what the Python package's
//! gymnasium adapter runs): a corridor of ten observations numbered from 100, whose two
//! calls are plain Rust here. It trains as a native environment would, the same seed
//! giving the same Q-tables; every step the learner counts is a call; what the calls give
//! that does not fit the spaces or the spec stops the run with the words users see; and
//! the trained `policy.json` replays against the states it lists (`hstl::replayed`).

use std::cell::{Cell, RefCell};
use std::ops::ControlFlow;

use hstl::outside::{Calls, DiscreteEnv, Failure, Spaces};
use hstl::replayed::{Replayed, StateIndex};
use hstl::runtime::{EpisodeEnd, TaskSpec};

const SPEC: &str = "spec ReachEnd {
    state { x: int in 0..=9 }
    let End = x > 8;
    task eventually[0..30] End;
    option End;
    learn { episodes: 60, choices: 20 }
}";

/// Observations `100..110`; action 1 moves right, action 0 left; the right end
/// terminates. `bad` makes a call give a wrong observation or fail from the given reset on.
struct Corridor {
    at: Cell<i64>,
    resets: Cell<u64>,
    steps: Cell<u64>,
    seeds: RefCell<Vec<u64>>,
    bad: Option<(u64, Bad)>,
}

#[derive(Clone, Copy)]
enum Bad {
    Outside,
    Fails,
}

impl Corridor {
    fn new(bad: Option<(u64, Bad)>) -> Corridor {
        Corridor {
            at: Cell::new(100),
            resets: Cell::new(0),
            steps: Cell::new(0),
            seeds: RefCell::new(Vec::new()),
            bad,
        }
    }
}

impl Calls for Corridor {
    type Error = String;

    fn reset(&self, seed: u64) -> Result<i64, String> {
        self.resets.set(self.resets.get() + 1);
        self.seeds.borrow_mut().push(seed);
        self.at.set(100 + (seed % 5) as i64);
        match self.bad {
            Some((n, Bad::Outside)) if self.resets.get() >= n => Ok(7),
            Some((n, Bad::Fails)) if self.resets.get() >= n => Err("the robot fell".into()),
            _ => Ok(self.at.get()),
        }
    }

    fn step(&self, action: i64) -> Result<(i64, Option<EpisodeEnd>), String> {
        self.steps.set(self.steps.get() + 1);
        let next = if action == 1 { self.at.get() + 1 } else { self.at.get() - 1 };
        self.at.set(next.clamp(100, 109));
        let end = (self.at.get() == 109).then_some(EpisodeEnd::Terminated);
        Ok((self.at.get(), end))
    }
}

fn spec() -> TaskSpec {
    let checked = hstl::lang::check(SPEC);
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics);
    hstl::lower::task_spec(&checked.specs[0], SPEC).expect("lowers")
}

fn spaces(observations: usize) -> Spaces {
    Spaces {
        name: "Corridor-v0".into(),
        observations,
        observation_start: 100,
        actions: 2,
        action_start: 0,
    }
}

fn env(bad: Option<(u64, Bad)>) -> DiscreteEnv<Corridor> {
    DiscreteEnv::new(Corridor::new(bad), spaces(10), &spec(), |o| Ok(vec![(o - 100) as f64]))
        .unwrap_or_else(|e| panic!("{e:?}"))
}

fn train(env: &DiscreteEnv<Corridor>, seed: u64) -> hstl::train::Trained {
    hstl::train::train_until(&spec(), env, seed, |_, _| {
        if env.failed() { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
    })
    .expect("trains")
}

#[test]
fn it_trains_like_a_native_env_and_replays_against_the_states_it_lists() {
    let (a, b) = (env(None), env(None));
    let (ta, tb) = (train(&a, 5), train(&b, 5));
    assert!(a.take_error().is_none());
    // The same seed: the same seeds passed to `reset`, the same document.
    assert_eq!(a.spaces(), b.spaces());
    assert_eq!(ta.policy.to_json().expect("json"), tb.policy.to_json().expect("json"));
    // Every step the learner counted was a call of `step`.
    assert_eq!(ta.steps, a.calls().steps.get());
    assert_eq!(*a.calls().seeds.borrow(), *b.calls().seeds.borrow());
    // Every cell left of the end moves right.
    assert!(ta.agent.flat[0][..9].iter().all(|&x| x == 1), "{:?}", ta.agent.flat[0]);

    let text = hstl::train::policy_json(&ta.policy, SPEC, 5).expect("json");
    let replayed = Replayed::read(&text).expect("replays");
    let Replayed::Listed(_, listed) = &replayed else { panic!("not a gymnasium replay") };
    assert_eq!(listed, &spaces(10));
    let index = StateIndex::of(&replayed);
    assert_eq!(replayed.state_index(&index, &[3.0]).expect("state"), 3);
    assert_eq!(replayed.state_index(&index, &[-0.0]).expect("state"), 0);
    assert_eq!(
        replayed.state_index(&index, &[12.0]).expect_err("no such state").message,
        "the policy has no state x = 12"
    );
    assert_eq!(replayed.observation_index(104).map(Result::ok), Some(Some(4)));
    assert_eq!(
        replayed.observation_index(110).map(|r| r.expect_err("outside").message),
        Some("observation 110 is outside Discrete(10, start=100)".to_string())
    );
    // The environment must be the one trained on.
    let other = Spaces { actions: 3, ..spaces(10) };
    let p = listed.check_same(&other).expect_err("other spaces");
    assert_eq!(
        p.message,
        "the policy was trained on `Corridor-v0` (Discrete(10, start=100) observations, \
         Discrete(2) actions); `env` is `Corridor-v0` (Discrete(10, start=100) observations, \
         Discrete(3) actions)"
    );
}

/// An observation's values.
type Valuation = dyn Fn(i64) -> Vec<f64>;

#[test]
fn what_does_not_fit_stops_the_run_in_words() {
    // (the environment's fault, the words)
    let outside = env(Some((3, Bad::Outside)));
    train(&outside, 1);
    match outside.take_error() {
        Some(Failure::Refused(p)) => {
            assert_eq!(
                p.message,
                "env.reset gave the observation 7, outside Discrete(10, start=100)"
            )
        }
        other => panic!("{other:?}"),
    }
    let fails = env(Some((2, Bad::Fails)));
    train(&fails, 1);
    assert!(matches!(fails.take_error(), Some(Failure::Call(e)) if e == "the robot fell"));
    // Taken once.
    assert!(fails.take_error().is_none());

    let spec = spec();
    let made = |n: usize, valuation: &dyn Fn(i64) -> Vec<f64>| {
        DiscreteEnv::new(Corridor::new(None), spaces(n), &spec, |o| Ok(valuation(o))).err().map(
            |e| match e {
                Failure::Refused(p) => p.message,
                Failure::Call(e) => e,
            },
        )
    };
    let cases: [(usize, &Valuation, &str); 4] = [
        (
            0,
            &|o| vec![(o - 100) as f64],
            "the environment has 0 observations; the learner's tables take 1 to",
        ),
        (10, &|_| vec![1.0], "observations 100 and 101 have the same valuation"),
        (
            10,
            &|o| vec![(o - 99) as f64],
            "valuation(109) gives `x` = 10, outside its declared domain 0..=9",
        ),
        (10, &|_| vec![1.0, 2.0], "valuation(100) gives 2 values; the spec has 1 state variables"),
    ];
    for (n, valuation, want) in cases {
        let got = made(n, valuation).expect("refused");
        assert!(got.starts_with(want), "{got}");
    }
}

/// A one-dimensional `Box` environment: observations `[p]` with `p` in `0..=10`, the
/// state `x` declared in `0..=4`; each step moves `p` by the action's value and gives what
/// `obs` then says (`None`: the position).
struct Line {
    at: Cell<f64>,
    obs: Option<Vec<f64>>,
    valued: Option<Vec<f64>>,
}

impl hstl::outside::BoxCalls for Line {
    type Error = String;
    type Obs = Vec<f64>;

    fn reset(&self, _seed: u64, _call: &str) -> Result<(Vec<f64>, Vec<f64>), String> {
        self.at.set(1.0);
        Ok((vec![1.0], vec![1.0]))
    }

    fn step(&self, action: i64, _call: &str) -> Result<(Vec<f64>, Vec<f64>, bool), String> {
        self.at.set(self.at.get() + action as f64);
        let numbers = self.obs.clone().unwrap_or_else(|| vec![self.at.get()]);
        Ok((numbers.clone(), numbers, false))
    }

    fn valuation(&self, _obs: &Vec<f64>, _call: &str) -> Option<Result<Vec<f64>, String>> {
        self.valued.clone().map(Ok)
    }
}

#[test]
fn a_box_environment_checks_every_observation_in_words() {
    use hstl::runtime::World;
    let src = "spec L {
    state { x: float in 0..=4 }
    let Far = x > 3;
    task eventually[0..20] Far;
    option Far;
    learn { preset: auto }
}";
    let checked = hstl::lang::check(src);
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics);
    let spec = hstl::lower::task_spec(&checked.specs[0], src).expect("lowers");
    let described = || {
        hstl::gym::Described::new("Line-v0", vec!["x".into()], vec![0.0], vec![10.0], 3, -1)
            .expect("described")
    };
    // (what the step gives, the refusal)
    let cases: [(Option<Vec<f64>>, &str); 3] = [
        (None, ""),
        (
            Some(vec![1.0, 2.0]),
            "env.step (call 1) gave an observation of 2 components; its `Box` has 1",
        ),
        (
            Some(vec![11.0]),
            "env.step (call 1) gave an observation whose component 0 is 11, outside its `Box` [0, 10]",
        ),
    ];
    for (obs, want) in cases {
        let calls = Line { at: Cell::new(0.0), obs, valued: None };
        let env = hstl::outside::BoxEnv::new(calls, false, described(), &spec).expect("made");
        let mut rng = hstl::runtime::seeded_rng(3);
        let start = env.reset(&mut rng);
        assert_eq!(start, [1.0]);
        // Action 2 is the environment's action 1: one step right.
        let next = env.step(&start, 2, &mut rng);
        match env.take_error() {
            None => {
                assert_eq!(want, "");
                assert_eq!(next, [2.0]);
            }
            Some(Failure::Refused(p)) => assert_eq!(p.message, want),
            Some(Failure::Call(e)) => panic!("{e}"),
        }
    }
    // A valuation of the wrong size, at the first observation.
    let calls = Line { at: Cell::new(0.0), obs: None, valued: Some(vec![1.0, 1.0]) };
    let env = hstl::outside::BoxEnv::new(calls, true, described(), &spec).expect("made");
    env.reset(&mut hstl::runtime::seeded_rng(3));
    let Some(Failure::Refused(p)) = env.take_error() else { panic!("not refused") };
    assert_eq!(p.message, "valuation gives 2 values; the spec has 1 state variables");
    // The declared range: a position of 5 is inside the `Box` but outside `x`'s range.
    let calls = Line { at: Cell::new(0.0), obs: Some(vec![5.0]), valued: None };
    let env = hstl::outside::BoxEnv::new(calls, false, described(), &spec).expect("made");
    let mut rng = hstl::runtime::seeded_rng(3);
    let start = env.reset(&mut rng);
    env.step(&start, 2, &mut rng);
    let Some(Failure::Refused(p)) = env.take_error() else { panic!("not refused") };
    assert_eq!(p.message, "after env.step (call 1), `x` = 5 is outside its declared range 0..=4");
}
