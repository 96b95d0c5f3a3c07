//! Training a spec in an environment, as `hstlc train` does, so that every front end (the
//! CLI, the Python package) writes the same `policy.json`, bit for bit, for the same seed.

use std::ops::ControlFlow;

use hstl_lang::{CheckedSpec, Domain, LineIndex};
use hstl_runtime::eval::{AgentController, RegionTable, WindowConfig, window_rate};
use hstl_runtime::{Agent, Env, Error, Learner, Policy, TaskSpec, seeded_rng};

use crate::Problem;

/// The seed offset of the generator that draws the sample runs of the pictures.
pub const PICTURE_SEED: u64 = 0x9e37_79b9_7f4a_7c15;
/// The seed offset of the generator that draws the evaluation's starts after training.
pub const EVAL_SEED: u64 = 0x5eed;

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
    /// The task's robustness over each run, averaged.
    pub robustness: f64,
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
    if let Some(v) = spec.state_vars.iter().find(|v| !matches!(v.domain, Domain::Int { .. })) {
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
    let mut learner = Learner::new(spec, env)?;
    let trained = learner.train_until(&mut seeded_rng(seed), progress);
    let policy = Policy::new(&learner);
    Ok(Trained { policy, curve: trained.curve, steps: trained.steps, agent: learner.agent() })
}

/// Training `spec_name` (from `file`) failed with `error`: the spec does not fit the
/// environment in a way its check cannot see.
pub fn cannot_train(file: &str, spec_name: &str, error: &Error) -> Problem {
    Problem::new(
        format!("{file}: cannot train `{spec_name}`: {error}"),
        "run `hstlc check` with the same `--world` to see where the spec and the world differ"
            .to_string(),
    )
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
    Ok(Some(WindowSummary { rate: report.rate, robustness }))
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
    use hstl_runtime::optimum::Moves;
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
