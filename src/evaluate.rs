//! Replaying a trained policy: what `hstlc eval` computes, shared with the Python package
//! (`hstl.Policy.load`, `policy.evaluate`) so that both check a `policy.json` the same way,
//! refuse the same documents in the same words and report the same figures.
//!
//! [`replay`] reads a `policy.json` and checks it whole against the spec in its
//! `spec_source` and the world in its `env`; [`evaluate`] runs the greedy agent from
//! random starts and measures the window rate of a persistent task (or the task's
//! robustness over each run of another task); [`baseline`] runs the hand-written
//! nearest-cell cycle over the same starts and slips; [`optimum`] is `W*`.
//!
//! ```
//! let src = "spec S { state { x: int in 0..=14, y: int in 0..=14 } let A = x < 3;
//!            let B = x > 11; task always[0..] (eventually[0..30] A && eventually[0..30] B);
//!            option A; option B; learn { episodes: 2, choices: 5 } }";
//! let loaded = hstl::load::load(src, None).unwrap();
//! let spec = hstl::train::trainable(&loaded.spec, src, "s.hstl").unwrap();
//! let world = hstl::world::GridWorld::builtin("paper").unwrap();
//! let trained = hstl::train::train(&spec, &world, 0, |_, _| {}).unwrap();
//! let text = hstl::train::policy_json(&trained.policy, src, 0).unwrap();
//! let replay = hstl::evaluate::replay(&text).unwrap();
//! let runs = hstl::evaluate::Runs { starts: 2, steps: 200, ..Default::default() };
//! match hstl::evaluate::evaluate(&replay, runs).unwrap() {
//!     hstl::evaluate::Evaluation::Window { report } => assert!((0.0..=1.0).contains(&report.rate)),
//!     hstl::evaluate::Evaluation::Robustness { .. } => unreachable!("a persistent task"),
//! }
//! ```

use hstl_robustness::{Trace, offline};
use hstl_runtime::eval::{
    AgentController, EntryCycle, RegionTable, WindowConfig, WindowReport, rollout, sample_runs,
    window_rate,
};
use hstl_runtime::moves::Moves;
use hstl_runtime::optimum::{Optimum, SolveConfig, solve};
use hstl_runtime::policy::EnvInfo;
use hstl_runtime::{Agent, Env, GridWorld, Policy, TaskSpec, seeded_rng};

use crate::Problem;

/// The largest `policy.json` the front ends read: 1 GiB.
pub const MAX_POLICY_BYTES: u64 = 1 << 30;
/// At most this many runs in one evaluation.
pub const MAX_STARTS: usize = 100_000;
/// At most this many steps in one run (a run is kept whole for its robustness).
pub const MAX_STEPS: usize = 1_000_000;
/// At most this many steps over all runs of one evaluation.
pub const MAX_EVAL_STEPS: usize = 200_000_000;

/// A `policy.json` checked against its spec and environment, ready to replay.
#[derive(Clone, Debug)]
pub struct Replay<E> {
    /// The document.
    pub policy: Policy,
    /// The spec it was trained on, from its `spec_source`.
    pub spec: TaskSpec,
    /// The environment it was trained in.
    pub env: E,
    /// The greedy agent the document describes.
    pub agent: Agent,
    /// The text of the spec file it was trained on (its `spec_source`).
    pub source: String,
    /// The seed it was trained from (its `seed`), when the document records one.
    pub seed: Option<u64>,
}

/// How the greedy runs of an evaluation go: `hstlc eval`'s `--starts`, `--steps`,
/// `--burn-in` and `--seed`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Runs {
    /// Greedy runs, each from a random start.
    pub starts: usize,
    /// Steps per run.
    pub steps: usize,
    /// Steps at the start of each run that the window rate does not count.
    pub burn_in: usize,
    /// The seed of the random starts and slips.
    pub seed: u64,
}

/// What an evaluation measured.
#[derive(Clone, Debug, PartialEq)]
pub enum Evaluation {
    /// A persistent task: the window rate, per run and pooled, and the task's robustness
    /// over each run.
    Window {
        /// The measurement.
        report: WindowReport,
    },
    /// Another task: its robustness over each run.
    Robustness {
        /// `rho(task, 0)` over each run, in order, windows clipped at the run's end.
        values: Vec<f64>,
        /// The same over complete windows: `None` for a run too short for any.
        complete: Vec<Option<f64>>,
    },
}

impl Default for Runs {
    /// `hstlc eval`'s defaults: 100 runs of 2000 steps, the first 100 not counted, seed 0.
    fn default() -> Runs {
        let w = WindowConfig::default();
        Runs { starts: w.starts, steps: w.steps, burn_in: w.burn_in, seed: 0 }
    }
}

impl Runs {
    /// Checks the counts against the budgets before anything runs. `flag` names a setting
    /// (`starts`, `steps`) as the caller's users write it, quoted (`` `--starts` ``).
    pub fn check_budget(&self, flag: impl Fn(&str) -> String) -> Result<(), Problem> {
        for (name, value, max) in
            [("starts", self.starts, MAX_STARTS), ("steps", self.steps, MAX_STEPS)]
        {
            if value == 0 || value > max {
                return Err(Problem::new(
                    format!("{} must be in 1..={max}; got {value}", flag(name)),
                    None,
                ));
            }
        }
        if self.starts.saturating_mul(self.steps) > MAX_EVAL_STEPS {
            return Err(Problem::new(
                format!(
                    "{} runs of {} steps are more than the {MAX_EVAL_STEPS} steps an evaluation may take",
                    self.starts, self.steps
                ),
                format!("lower {} or {}", flag("starts"), flag("steps")),
            ));
        }
        Ok(())
    }

    /// Checks that the burn-in leaves steps to count, for a persistent task (the window
    /// rate counts the steps after it). `flag` names a setting as in [`Runs::check_budget`].
    pub fn check_burn_in(
        &self,
        spec: &TaskSpec,
        flag: impl Fn(&str) -> String,
    ) -> Result<(), Problem> {
        if spec.regions.is_empty() || self.burn_in < self.steps {
            return Ok(());
        }
        Err(Problem::new(
            format!(
                "a burn-in of {} steps leaves nothing of {}-step runs",
                self.burn_in, self.steps
            ),
            format!("use {} smaller than {}", flag("burn_in"), flag("steps")),
        ))
    }

    fn window(&self) -> WindowConfig {
        WindowConfig { starts: self.starts, steps: self.steps, burn_in: self.burn_in }
    }
}

/// The `policy.json` in `text`, checked whole against the spec in its `spec_source` and
/// the grid world in its `env` (a document written before world files loads as the open
/// grid it was). Messages are worded as `hstlc eval` prints them, after `FILE: `.
pub fn replay(text: &str) -> Result<Replay<GridWorld>, Problem> {
    replay_grid(read(text)?)
}

/// [`replay`] of a document already read.
pub fn replay_grid(document: Document) -> Result<Replay<GridWorld>, Problem> {
    replay_document(document, |policy| {
        let help = || "the `env` entry must hold the world `hstlc train` wrote (`slip` and `map`)";
        // Through the one reader of worlds in documents, which also holds a built-in
        // world's name to that world's parameters.
        let any = hstl_runtime::world::AnyWorld::from_params(&policy.env.name, &policy.env.params)
            .map_err(|e| Problem::new(format!("its world: {e}"), help().to_string()))?;
        let hstl_runtime::world::AnyWorld::Grid(env) = any else {
            return Err(Problem::new(
                "its world is not a grid, which the tables of `q_tables` are learned on",
                help().to_string(),
            ));
        };
        if policy.env.params.get("map").is_none() {
            // Written before world files: the open grid it was, in today's terms.
            policy.env = EnvInfo { name: env.name().to_string(), params: env.params() };
        }
        Ok(env)
    })
}

/// [`replay`] in the environment `make_env` builds from the document (it may bring the
/// document's `env` entry up to date).
pub fn replay_in<E: Env>(
    text: &str,
    make_env: impl FnOnce(&mut Policy) -> Result<E, Problem>,
) -> Result<Replay<E>, Problem> {
    replay_document(read(text)?, make_env)
}

/// A `policy.json` as read, not yet checked: the document, the spec's text it was trained
/// on (`spec_source`) and its seed.
#[derive(Clone, Debug)]
pub struct Document {
    /// The document.
    pub policy: Policy,
    /// Its `spec_source`.
    pub source: String,
    /// Its `seed`, when it records one.
    pub seed: Option<u64>,
}

/// Reads a `policy.json` in one typed pass (fields it does not know skipped, not kept):
/// the document, its `spec_source` (a string, required) and its `seed` (a whole number
/// from 0 to 2^64 - 1, if present).
pub fn read(text: &str) -> Result<Document, Problem> {
    let (policy, extra) = Policy::from_json_with(text, &["spec_source", "seed"]).map_err(|e| {
        Problem::new(e.to_string(), "pass the policy.json that `hstlc train` wrote".to_string())
    })?;
    let again = || "train the policy again with `hstlc train`".to_string();
    let source = match extra.get("spec_source") {
        Some(serde_json::Value::String(s)) => s.clone(),
        Some(_) => {
            return Err(Problem::new("its `spec_source` is not a string of hstl text", again()));
        }
        None => {
            return Err(Problem::new(
                "it has no `spec_source` entry with the spec it was trained on",
                again(),
            ));
        }
    };
    let seed = match extra.get("seed") {
        None => None,
        Some(v) => Some(v.as_u64().ok_or_else(|| {
            Problem::new(
                format!("its `seed` is {v}, not a whole number from 0 to 2^64 - 1"),
                again(),
            )
        })?),
    };
    Ok(Document { policy, source, seed })
}

/// [`replay_in`] of a document already read.
pub fn replay_document<E: Env>(
    document: Document,
    make_env: impl FnOnce(&mut Policy) -> Result<E, Problem>,
) -> Result<Replay<E>, Problem> {
    let Document { mut policy, source, seed } = document;
    let spec = lowered(&source, &policy.spec)
        .map_err(|m| Problem::new(m, "train the policy again with `hstlc train`".to_string()))?;
    let trained = policy.memory.as_ref().map_or(0, |m| m.buckets as u64);
    let preset_changed = preset_memory_changed(
        &hstl_lang::check(&source),
        &policy.spec,
        trained,
        spec.learn.memory as u64,
    );
    let env = make_env(&mut policy)?;
    // Only a document that is a whole policy of the memory it records was trained so; any
    // other is an edit.
    if let Some(p) = preset_changed {
        let mut then = spec.clone();
        then.learn.memory = trained as usize;
        if policy.check_against(&then, &env).is_ok() {
            return Err(p);
        }
    }
    let agent = policy.check_against(&spec, &env).map_err(|e| {
        Problem::new(
            e.to_string(),
            "the file was edited or damaged: train the policy again with `hstlc train`".to_string(),
        )
    })?;
    Ok(Replay { policy, spec, env, agent, source, seed })
}

/// The spec that `policy.json` was trained from, checked and lowered again.
pub fn spec_of(policy_text: &str, expected: &str) -> Result<TaskSpec, String> {
    let document = read(policy_text).map_err(|p| p.message)?;
    lowered(&document.source, expected)
}

/// Why a policy trained with `memory: trained` does not replay on its spec, when the
/// spec's memory is `preset: auto`'s choice (no `memory` written beside it) and the preset
/// now gives `memory: now`: the preset's sizing changed since the policy was trained (it
/// is held to the memory budget), and the file is not damaged. `None` otherwise.
pub fn preset_memory_changed(
    checked: &hstl_lang::Checked,
    name: &str,
    trained: u64,
    now: u64,
) -> Option<Problem> {
    use hstl_lang::syntax::Item;
    if trained == now {
        return None;
    }
    let spec = checked.specs.iter().find(|s| s.name == name)?;
    let written = checked.file.specs.iter().find(|s| s.name.name == name)?;
    let memory_written = written
        .items
        .iter()
        .any(|i| matches!(i, Item::Learn(l) if l.params.iter().any(|p| p.name.name == "memory")));
    if spec.learn.preset != hstl_lang::Preset::Auto || memory_written {
        return None;
    }
    Some(Problem::new(
        format!(
            "it was trained with `memory: {trained}`, which `preset: auto` chose then; its spec's `preset: auto` now gives `memory: {now}` (the preset has changed since, not the file)"
        ),
        format!(
            "train the policy again with `hstlc train`, or write `memory: {trained}` beside `preset: auto` in the spec's `learn` item and train it again to keep the earlier memory"
        ),
    ))
}

/// The spec called `expected` in `source`, checked and lowered.
fn lowered(source: &str, expected: &str) -> Result<TaskSpec, String> {
    let checked = hstl_lang::check(source);
    if checked.has_errors() {
        return Err("its `spec_source` does not check; run `hstlc check` on the spec".into());
    }
    let spec = checked
        .specs
        .iter()
        .find(|s| s.name == expected)
        .ok_or_else(|| format!("its `spec_source` has no spec named `{expected}`"))?;
    crate::lower::task_spec(spec, source).map_err(|e| e.to_string())
}

/// Runs the greedy agent `runs.starts` times from random starts (drawn, with the slips,
/// from one generator seeded with `runs.seed`) and measures the window rate of a
/// persistent task, or the task's robustness over each run of another task.
pub fn evaluate<E: Env>(replay: &Replay<E>, runs: Runs) -> Result<Evaluation, Problem> {
    let Replay { spec, env, agent, .. } = replay;
    let mut rng = seeded_rng(runs.seed);
    let mut controller = AgentController::new(agent);
    if spec.regions.is_empty() {
        // Not a persistent task: the task's robustness over each run is the measure.
        let all_states = state_trace(spec, env)?;
        let mut values = Vec::with_capacity(runs.starts);
        let mut complete = Vec::with_capacity(runs.starts);
        for _ in 0..runs.starts {
            let start = env.index(&env.reset(&mut rng));
            let states: Vec<usize> = rollout(env, &mut controller, start, runs.steps, &mut rng)
                .iter()
                .map(|s| s.state)
                .collect();
            let trace = trace_of_run(&all_states, &states)?;
            values.push(offline::robustness(&spec.task, &trace));
            complete.push(hstl_robustness::complete::robustness(&spec.task, &trace));
        }
        return Ok(Evaluation::Robustness { values, complete });
    }
    let regions = RegionTable::new(spec, env).map_err(|e| Problem::new(e.to_string(), None))?;
    let report =
        window_rate(env, &mut controller, &regions, runs.window(), &mut rng).map_err(|e| {
            Problem::new(
                e.to_string(),
                "use a burn-in smaller than the steps, and at least one start".to_string(),
            )
        })?;
    Ok(Evaluation::Window { report })
}

/// The window rate of the hand-written yardstick (the regions in turn, each by a shortest
/// path around the walls) over the same starts and slips as [`evaluate`]: a learned policy
/// below it has not learned the legs. `None` for a task that is not persistent, or whose
/// regions the cycle cannot visit.
pub fn baseline(replay: &Replay<GridWorld>, runs: Runs) -> Result<Option<f64>, Problem> {
    let Replay { spec, env, .. } = replay;
    if spec.regions.is_empty() {
        return Ok(None);
    }
    let regions = RegionTable::new(spec, env).map_err(|e| Problem::new(e.to_string(), None))?;
    let Ok(mut cycle) = EntryCycle::new(env, &regions) else { return Ok(None) };
    let report = window_rate(env, &mut cycle, &regions, runs.window(), &mut seeded_rng(runs.seed))
        .map_err(|e| Problem::new(e.to_string(), None))?;
    Ok(Some(report.rate))
}

/// The optimal window rate `W*` of the policy's persistent task on its world (value
/// iteration; a few seconds for the case study), or `None` for another task.
pub fn optimum(
    replay: &Replay<GridWorld>,
    config: SolveConfig,
) -> Result<Option<Optimum>, Problem> {
    let Replay { spec, env, .. } = replay;
    if spec.regions.is_empty() {
        return Ok(None);
    }
    let regions = RegionTable::new(spec, env).map_err(|e| Problem::new(e.to_string(), None))?;
    solve(&Moves::of(env), &regions, config)
        .map(Some)
        .map_err(|e| Problem::new(e.to_string(), None))
}

/// The first `n` greedy runs [`evaluate`] scores with `runs` (the same starts and slips,
/// drawn from the same generator), each as a `run_K.csv` file (DESIGN.md, "greedy runs as
/// data"): `t,VAR...,action,option`, one row per step, then the final state with empty
/// action and option.
pub fn greedy_run_files<E: Env>(
    replay: &Replay<E>,
    n: usize,
    runs: Runs,
) -> Result<Vec<crate::outfile::OutFile>, Problem> {
    let Replay { spec, env, agent, .. } = replay;
    let states = state_trace(spec, env)?;
    let actions = env.actions();
    let names: Vec<&str> = spec.state_vars.iter().map(|v| v.name.as_str()).collect();
    let mut rng = seeded_rng(runs.seed);
    let mut controller = AgentController::new(agent);
    let sampled = sample_runs(env, &mut controller, n, runs.steps, &mut rng);
    let mut row = Vec::new();
    let mut line = |out: &mut String, t: usize, s: usize, act: Option<(usize, usize)>| {
        out.push_str(&t.to_string());
        states.row_into(s, &mut row);
        for &v in &row {
            out.push(',');
            out.push_str(&crate::outfile::number(v));
        }
        match act {
            Some((a, o)) => {
                out.push(',');
                out.push_str(actions.get(a).map_or("", String::as_str));
                out.push(',');
                out.push_str(spec.options.get(o).map_or("", |x| x.name.as_str()));
            }
            None => out.push_str(",,"),
        }
        out.push('\n');
    };
    Ok(sampled
        .iter()
        .enumerate()
        .map(|(k, run)| {
            let mut out = format!("t,{},action,option\n", names.join(","));
            for (t, step) in run.iter().enumerate() {
                line(&mut out, t, step.state, Some((step.decision.action, step.decision.option)));
            }
            if let Some(last) = run.last() {
                line(&mut out, run.len(), last.next, None);
            }
            crate::outfile::OutFile::text(format!("run_{}.csv", k + 1), out)
        })
        .collect())
}

/// Row `s`: the values of the spec's state variables in state `s` of `env`.
pub fn state_trace<E: Env>(spec: &TaskSpec, env: &E) -> Result<Trace, Problem> {
    let env_vars = env.state_vars();
    let picks = spec
        .state_vars
        .iter()
        .map(|v| {
            env_vars.iter().position(|e| *e == v.name).ok_or_else(|| {
                Problem::new(
                    format!(
                        "state variable `{}` is not one of the {} environment's",
                        v.name,
                        env.name()
                    ),
                    format!("the environment has {}", env_vars.join(", ")),
                )
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut columns = vec![Vec::with_capacity(env.num_states()); picks.len()];
    let mut row = Vec::new();
    for s in 0..env.num_states() {
        let Some(state) = env.state(s) else { continue };
        env.valuation(&state, &mut row);
        for (col, &i) in columns.iter_mut().zip(&picks) {
            col.push(row.get(i).copied().unwrap_or(f64::NAN));
        }
    }
    Trace::from_columns(columns).map_err(|e| Problem::new(e.to_string(), None))
}

/// The trace of one run (indices into `states`, the trace of every state of the
/// environment).
fn trace_of_run(states: &Trace, run: &[usize]) -> Result<Trace, Problem> {
    let mut trace = Trace::new(states.vars());
    let mut row = Vec::with_capacity(states.vars());
    for &s in run {
        states.row_into(s, &mut row);
        trace.push(&row).map_err(|e| Problem::new(e.to_string(), None))?;
    }
    Ok(trace)
}

/// The runs that satisfy the task, over complete windows: a run's robustness over complete
/// windows is above 0, or, for a run too short for a complete window (an episode that
/// ended early), its robustness with windows clipped at its end is. `clipped` and
/// `complete` are per run, as [`Evaluation`] holds them.
pub fn satisfied(clipped: &[f64], complete: &[Option<f64>]) -> usize {
    clipped.iter().zip(complete).filter(|(c, v)| v.unwrap_or(**c) > 0.0).count()
}
