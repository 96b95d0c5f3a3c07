//! Training a spec in an environment, as `hstlc train` does, so that every front end (the
//! CLI, the Python package) writes the same `policy.json`, bit for bit, for the same seed.

use std::ops::ControlFlow;

use hstl_lang::{CheckedSpec, Domain, LineIndex};
use hstl_runtime::eval::{AgentController, RegionTable, WindowConfig, window_rate};
use hstl_runtime::{Agent, Env, Error, Learner, Policy, TaskSpec, seeded_rng};

use crate::Problem;

pub use crate::seeds::{EVAL_SEED, PICTURE_SEED};

/// The episodes at the end of training whose mean reward a study reports.
pub const TAIL: usize = 100;

/// The mean of the last `n` values (0 for none).
pub fn tail_mean(curve: &[f64], n: usize) -> f64 {
    let tail = &curve[curve.len().saturating_sub(n)..];
    tail.iter().sum::<f64>() / tail.len().max(1) as f64
}

/// A trained policy and what training measured (wall-clock time is the caller's to take).
#[derive(Clone, Debug)]
pub struct Trained {
    /// The policy document.
    pub policy: Policy,
    /// The summed option rewards of each episode.
    pub curve: Vec<f64>,
    /// Primitive steps taken.
    pub steps: u64,
    /// The greedy agent.
    pub agent: Agent,
}

/// The window rate and mean task robustness of a greedy agent over
/// [`WindowConfig::default`] runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowSummary {
    /// The share of counted steps whose windows all visit their region.
    pub rate: f64,
    /// The task's robustness over each run, windows clipped at its end, averaged.
    pub robustness: f64,
    /// The share of each run's complete steps where the task's body holds (every window
    /// kept), averaged over the runs long enough for a complete window.
    pub kept: Option<f64>,
}

/// The spec as the runtime's data, when it can be trained: it has options, and every
/// state variable is an `int` with a range (the learner's tables enumerate them). `source`
/// is the text it was checked from and `file` names it in messages, which point at
/// `FILE:LINE:COL`.
pub fn trainable(spec: &CheckedSpec, source: &str, file: &str) -> Result<TaskSpec, Problem> {
    let at = |offset: usize| {
        let p = LineIndex::new(source).position(source, offset);
        format!("{file}:{}:{}", p.line, p.column)
    };
    if spec.primitives.is_empty() {
        return Err(Problem::new(
            format!("{}: spec `{}` has no options to train", at(spec.name_range.start), spec.name),
            "add an option per region, such as `option A;` for `let A = ...;`".to_string(),
        ));
    }
    if hstl_lang::lints::task_is_constant(spec) {
        let task = spec.task.as_ref().map_or(spec.name_range.start, |t| t.formula.range.start);
        return Err(Problem::new(
            format!(
                "{}: HSTL104: spec `{}` has a task that refers to no state variable: its \
                 robustness is the same on every run, so there is nothing to learn",
                at(task),
                spec.name
            ),
            "write the task over the state, such as `task always[0..] eventually[0..40] A;` \
             (`hstlc explain HSTL104`)"
                .to_string(),
        ));
    }
    let tiled = spec.learn.tiles.is_some();
    // Tables need an `int` range; tilings any bounded domain.
    let learnable = |v: &&hstl_lang::StateVarInfo| {
        matches!(v.domain, Domain::Int { .. }) || tiled && v.domain != Domain::Unbounded
    };
    if let Some(v) = spec.state_vars.iter().find(|v| !learnable(v)) {
        return Err(Problem::new(
            format!(
                "{}: state variable `{}` needs an `int` range for training",
                at(v.name_range.start),
                v.name
            ),
            format!("declare it like `{}: int in 0..=14`, matching the world's size", v.name),
        ));
    }
    crate::lower::task_spec(spec, source).map_err(|e| Problem::new(format!("{file}: {e}"), None))
}

/// Trains `spec` in `env` from `seed` (the one generator every draw comes from);
/// `progress` sees each episode and its reward.
pub fn train<E: Env>(
    spec: &TaskSpec,
    env: &E,
    seed: u64,
    mut progress: impl FnMut(usize, f64),
) -> Result<Trained, Error> {
    train_until(spec, env, seed, |episode, reward| {
        progress(episode, reward);
        ControlFlow::Continue(())
    })
}

/// [`train`], stopped after the episode for which `progress` breaks (see
/// [`Learner::train_until`]): the curve then holds the episodes done, and the policy is
/// the one those episodes learned.
pub fn train_until<E: Env>(
    spec: &TaskSpec,
    env: &E,
    seed: u64,
    progress: impl FnMut(usize, f64) -> ControlFlow<()>,
) -> Result<Trained, Error> {
    // The memory model first: nothing over the budget is allocated.
    crate::cost::check(spec, env).map_err(|p| Error::Config(p.message))?;
    let mut learner = Learner::new(spec, env)?;
    let trained = learner.train_until(&mut seeded_rng(seed), progress);
    let policy = Policy::new(&learner);
    Ok(Trained { policy, curve: trained.curve, steps: trained.steps, agent: learner.agent() })
}

/// Training `spec_name` (from `file`) failed with `error`: the spec does not fit the
/// environment in a way its check cannot see.
pub fn cannot_train(file: &str, spec_name: &str, error: &Error) -> Problem {
    let help = match error {
        // Often a size the spec chose, which the message names; sometimes the world.
        Error::Config(_) => {
            "lower the sizes the message names in the spec's `learn` item, or run `hstlc \
             check` with the same `--world` to see where the spec and the world differ"
        }
        _ => "run `hstlc check` with the same `--world` to see where the spec and the world differ",
    };
    Problem::new(format!("{file}: cannot train `{spec_name}`: {error}"), help.to_string())
}

/// `policy.json`: the runtime's document, plus the spec's source and the seed, so that a
/// replay needs nothing else.
pub fn policy_json(policy: &Policy, source: &str, seed: u64) -> Result<String, Error> {
    let extra = [("spec_source", source.into()), ("seed", seed.into())];
    policy.to_json_with(&extra)
}

/// The window rate of the greedy `agent` after training from `seed`, for a persistent
/// task (`None` for a task of another form).
pub fn window_summary<E: Env>(
    spec: &TaskSpec,
    env: &E,
    agent: &Agent,
    seed: u64,
) -> Result<Option<WindowSummary>, Error> {
    if spec.regions.is_empty() {
        return Ok(None);
    }
    let regions = RegionTable::new(spec, env)?;
    let mut rng = seeded_rng(seed ^ EVAL_SEED);
    let mut controller = AgentController::new(agent);
    let report = window_rate(env, &mut controller, &regions, WindowConfig::default(), &mut rng)?;
    let robustness = report.robustness.iter().sum::<f64>() / report.robustness.len() as f64;
    let shares: Vec<f64> = report.kept.iter().flatten().copied().collect();
    let kept = (!shares.is_empty()).then(|| shares.iter().sum::<f64>() / shares.len() as f64);
    Ok(Some(WindowSummary { rate: report.rate, robustness, kept }))
}

/// The `learn` values [`set_learn`] takes, as Ray Tune's config names them: the counts,
/// and each level's Q-learning parameters as `LEVEL_PARAM`.
pub const LEARN_KEYS: [&str; 13] = [
    "episodes",
    "choices",
    "max_steps",
    "flat_gamma",
    "flat_alpha",
    "flat_epsilon",
    "flat_min_epsilon",
    "flat_decay",
    "options_gamma",
    "options_alpha",
    "options_epsilon",
    "options_min_epsilon",
    "options_decay",
];

/// Sets one `learn` value of `spec` (a key of [`LEARN_KEYS`]), held to the range the
/// spec's own `learn { ... }` is checked against; `min_epsilon <= epsilon` is checked by
/// [`check_learn`] once every value is set.
pub fn set_learn(spec: &mut TaskSpec, key: &str, value: f64) -> Result<(), Problem> {
    use hstl_lang::budget::{MAX_CHOICES, MAX_EPISODES, MAX_STEPS};
    let bad = |cond: &str| {
        Problem::new(
            format!("`{key}` must be {cond}, found `{value}`"),
            format!("choose a value {cond}"),
        )
    };
    let count = |limit: u64| -> Result<usize, Problem> {
        let cond = format!("a whole number in 1..={limit}");
        if value.fract() != 0.0 || !(1.0..=limit as f64).contains(&value) {
            return Err(bad(&cond));
        }
        Ok(value as usize)
    };
    let learn = &mut spec.learn;
    match key {
        "episodes" => learn.episodes = count(MAX_EPISODES)?,
        "choices" => learn.choices = count(MAX_CHOICES)?,
        "max_steps" => learn.max_steps = count(MAX_STEPS)?,
        _ => {
            let (level, param) = match key.split_once('_') {
                Some(("flat", p)) => (&mut learn.flat, p),
                Some(("options", p)) => (&mut learn.options, p),
                _ => return Err(unknown_learn(key)),
            };
            let (ok, cond) = match param {
                "gamma" | "alpha" => (value > 0.0 && value <= 1.0, "in (0, 1]"),
                "epsilon" | "min_epsilon" => ((0.0..=1.0).contains(&value), "in [0, 1]"),
                "decay" => (value >= 0.0 && value.is_finite(), ">= 0"),
                _ => return Err(unknown_learn(key)),
            };
            if !ok {
                return Err(bad(cond));
            }
            match param {
                "gamma" => level.gamma = value,
                "alpha" => level.alpha = value,
                "epsilon" => level.epsilon = value,
                "min_epsilon" => level.min_epsilon = value,
                _ => level.decay = value,
            }
        }
    }
    Ok(())
}

/// Sets the episodes `spec` trains for to `episodes` (a caller's override of
/// `learn { episodes }`), held to `1..=MAX_EPISODES`; `None` keeps the spec's own.
pub fn set_episodes(spec: &mut TaskSpec, episodes: Option<usize>) -> Result<(), Problem> {
    use hstl_lang::budget::MAX_EPISODES;
    if let Some(n) = episodes {
        if n == 0 || n as u64 > MAX_EPISODES {
            return Err(Problem::new(
                format!("`episodes` must be in 1..={MAX_EPISODES}; got {n}"),
                "leave it out to train the spec's `learn { episodes }`".to_string(),
            ));
        }
        spec.learn.episodes = n;
    }
    Ok(())
}

/// Refuses `learn` values that are each in range but do not fit together: a level's
/// `min_epsilon` above its `epsilon`.
pub fn check_learn(spec: &TaskSpec) -> Result<(), Problem> {
    for (name, level) in [("flat", &spec.learn.flat), ("options", &spec.learn.options)] {
        if level.min_epsilon > level.epsilon {
            return Err(Problem::new(
                format!(
                    "`{name}_min_epsilon` ({}) exceeds `{name}_epsilon` ({})",
                    level.min_epsilon, level.epsilon
                ),
                "0 <= min_epsilon <= epsilon <= 1".to_string(),
            ));
        }
    }
    Ok(())
}

fn unknown_learn(key: &str) -> Problem {
    Problem::new(
        format!("`{key}` is not a `learn` value that can be set"),
        format!("use one of {}", LEARN_KEYS.map(|k| format!("`{k}`")).join(", ")),
    )
}

/// Where training stood after a chunk of episodes (see [`train_in_chunks`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// Episodes trained so far.
    pub episodes: usize,
    /// Primitive steps taken so far.
    pub steps: u64,
    /// Reward per episode, the mean of the last 100 episodes so far.
    pub reward: f64,
    /// The greedy policy's window rate and robustness now, for a persistent task.
    pub window: Option<WindowSummary>,
}

/// [`train`] in chunks of `chunk` episodes: after each, the greedy policy is measured as
/// after training and `report` sees where training stands (it breaks to stop early, as a
/// scheduler such as ASHA does). Run to the end, training is draw for draw the one
/// [`train`] does: the measurements draw from a generator of their own.
pub fn train_in_chunks<E: Env>(
    spec: &TaskSpec,
    env: &E,
    seed: u64,
    chunk: usize,
    mut report: impl FnMut(&Checkpoint) -> ControlFlow<()>,
) -> Result<Trained, Error> {
    let chunk = chunk.max(1);
    let total = spec.learn.episodes;
    let mut learner = Learner::new(spec, env)?;
    let mut rng = seeded_rng(seed);
    let mut curve = Vec::with_capacity(total);
    let mut steps = 0;
    while curve.len() < total {
        let size = chunk.min(total - curve.len());
        // Each call would run `episodes` episodes; it stops after this chunk's.
        let part = learner.train_until(&mut rng, |e, _| {
            if e + 1 >= size { ControlFlow::Break(()) } else { ControlFlow::Continue(()) }
        });
        curve.extend(part.curve);
        steps += part.steps;
        let window = window_summary(spec, env, &learner.agent(), seed)?;
        let at =
            Checkpoint { episodes: curve.len(), steps, reward: tail_mean(&curve, TAIL), window };
        if report(&at).is_break() {
            break;
        }
    }
    let policy = Policy::new(&learner);
    Ok(Trained { policy, curve, steps, agent: learner.agent() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use hstl_runtime::GridWorld;

    const SMALL: &str = "spec Small {
    state { x: int in 0..=14, y: int in 0..=14 }
    let A = x > 10 && y > 10;
    let B = x < 4 && y < 4;
    task always[0..] (eventually[0..40] A && eventually[0..40] B);
    option A;
    option B;
    options { A, B }
    learn { episodes: 25, choices: 10 }
}
";

    fn small() -> (TaskSpec, GridWorld) {
        let world = GridWorld::builtin("paper").expect("paper");
        let loaded = crate::load::load_in_world(SMALL, None, &world, "world `paper`")
            .unwrap_or_else(|e| panic!("{e}"));
        (trainable(&loaded.spec, SMALL, "small.hstl").expect("trains"), world)
    }

    #[test]
    fn an_episodes_override_is_held_to_the_spec_s_range() {
        use hstl_lang::budget::MAX_EPISODES;
        let (spec, _) = small();
        let max = usize::try_from(MAX_EPISODES).expect("fits");
        for (episodes, expect) in [
            (None, Ok(spec.learn.episodes)),
            (Some(1), Ok(1)),
            (Some(max), Ok(max)),
            (Some(0), Err("got 0".to_string())),
            (Some(max + 1), Err(format!("must be in 1..={MAX_EPISODES}; got {}", max + 1))),
        ] {
            let mut task = spec.clone();
            match (set_episodes(&mut task, episodes), expect) {
                (Ok(()), Ok(n)) => assert_eq!(task.learn.episodes, n, "{episodes:?}"),
                (Err(p), Err(part)) => {
                    assert!(p.message.contains(&part), "{}", p.message);
                    assert_eq!(task.learn.episodes, spec.learn.episodes, "left as it was");
                }
                (got, _) => panic!("{episodes:?}: {:?}", got.map_err(|p| p.message)),
            }
        }
    }

    #[test]
    fn chunks_train_draw_for_draw_as_one_run() {
        let (spec, world) = small();
        let whole = train(&spec, &world, 3, |_, _| {}).expect("trains");
        let mut seen = Vec::new();
        let chunked = train_in_chunks(&spec, &world, 3, 10, |at| {
            seen.push(at.clone());
            ControlFlow::Continue(())
        })
        .expect("trains");
        assert_eq!(chunked.curve, whole.curve);
        assert_eq!(chunked.steps, whole.steps);
        assert_eq!(chunked.agent, whole.agent);
        assert_eq!(seen.iter().map(|c| c.episodes).collect::<Vec<_>>(), [10, 20, 25]);
        // The last checkpoint measures the trained policy as a study does.
        let last = seen.last().expect("a checkpoint");
        assert_eq!(last.window, window_summary(&spec, &world, &whole.agent, 3).expect("W"));
        assert_eq!(last.reward, tail_mean(&whole.curve, 100));
        // Stopped after the first chunk: the curve holds its episodes.
        let stopped =
            train_in_chunks(&spec, &world, 3, 10, |_| ControlFlow::Break(())).expect("trains");
        assert_eq!(stopped.curve, whole.curve[..10]);
    }

    #[test]
    fn learn_values_are_held_to_the_spec_s_ranges() {
        let (mut spec, _) = small();
        set_learn(&mut spec, "flat_alpha", 0.35).expect("in range");
        set_learn(&mut spec, "options_gamma", 1.0).expect("in range");
        set_learn(&mut spec, "episodes", 40.0).expect("in range");
        assert_eq!(
            (spec.learn.flat.alpha, spec.learn.options.gamma, spec.learn.episodes),
            (0.35, 1.0, 40)
        );
        let refused = |key: &str, value: f64| {
            let mut s = spec.clone();
            set_learn(&mut s, key, value).expect_err("refused").message
        };
        assert_eq!(refused("flat_alpha", 0.0), "`flat_alpha` must be in (0, 1], found `0`");
        assert_eq!(
            refused("episodes", 2.5),
            "`episodes` must be a whole number in 1..=10000000, found `2.5`"
        );
        assert_eq!(refused("flat_decay", f64::NAN), "`flat_decay` must be >= 0, found `NaN`");
        assert_eq!(
            refused("options_beta", 0.1),
            "`options_beta` is not a `learn` value that can be set"
        );
        assert_eq!(refused("memory", 1.0), "`memory` is not a `learn` value that can be set");
        set_learn(&mut spec, "flat_min_epsilon", 0.9).expect("in range");
        assert_eq!(
            check_learn(&spec).expect_err("crossed").message,
            "`flat_min_epsilon` (0.9) exceeds `flat_epsilon` (0.8)"
        );
    }
}

/// Runs the reach-avoid measure takes: the satisfaction rate's standard error is at most
/// 0.016 with this many.
pub const REACH_AVOID_RUNS: usize = 1000;

/// The satisfaction rate of a greedy agent on a reach-avoid task, and the most any policy
/// can give it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReachAvoidSummary {
    /// The share of [`REACH_AVOID_RUNS`] runs, from random starts, that satisfy the task.
    pub rate: f64,
    /// The exact optimal probability of satisfying it from a random start (dynamic
    /// programming on step, state and whether the goal has held).
    pub optimum: f64,
    /// The states of each run: `max(T, T_avoid) + 1`, or the [`WindowConfig::default`]
    /// steps for `always[0..] !R`.
    pub run_len: usize,
}

/// [`ReachAvoidSummary`] of the greedy `agent` after training from `seed`, for a task of the
/// reach-avoid form `eventually[0..T] Goal && always[I] !R ...` on a grid world (`None`
/// for a task of another form).
pub fn reach_avoid_summary(
    spec: &TaskSpec,
    env: &hstl_runtime::GridWorld,
    agent: &Agent,
    seed: u64,
) -> Result<Option<ReachAvoidSummary>, Error> {
    use hstl_runtime::moves::Moves;
    use hstl_runtime::reach_avoid::{ReachAvoid, solve_reach_avoid};
    let Some(task) = ReachAvoid::of_spec(spec, env, WindowConfig::default().steps)? else {
        return Ok(None);
    };
    let optimum = solve_reach_avoid(&Moves::of(env), &task, 1 << 26)?;
    let mut rng = seeded_rng(seed ^ EVAL_SEED);
    let mut controller = AgentController::new(agent);
    let rate = task.satisfaction_rate(env, &mut controller, REACH_AVOID_RUNS, &mut rng);
    Ok(Some(ReachAvoidSummary { rate, optimum: optimum.probability, run_len: task.run_len() }))
}
