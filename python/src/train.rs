//! Training: `hstl._hstl._train_world` and `_train_env`, which `hstl.train` calls.
//!
//! Both release the GIL while the learner runs. Every `PROGRESS_EVERY` (and after the
//! last episode) they take it back to check for signals (Ctrl-C stops training with
//! `KeyboardInterrupt`) and to call `progress(done, total, last_reward)`; an exception
//! from either stops training after the episode it came in and is raised.

use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use hstl::runtime::{Error, TaskSpec};
use hstl::train::{policy_json, train_until};
use pyo3::prelude::*;

use crate::continuous::ContinuousWorld;
use crate::errors::{self, problem_error, value_error};
use crate::gym::{Spaces, box_env, failure_error, py_env};
use crate::policy::Policy;
use crate::spec::Spec;
use crate::world::World;

/// How often training stops to check signals and report progress.
const PROGRESS_EVERY: Duration = Duration::from_millis(100);

/// Trains `spec` in `world` as `hstlc train --world --seed --episodes` does: the spec is
/// checked against the world first (the diagnostics of `hstlc check --world`), and the
/// policy's `policy.json` is byte for byte the one `hstlc train` writes.
#[pyfunction]
#[pyo3(signature = (spec, world, seed, episodes=None, progress=None))]
pub fn _train_world(
    py: Python<'_>,
    spec: &Bound<'_, Spec>,
    world: &Bound<'_, World>,
    seed: u64,
    episodes: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Policy> {
    let spec = spec.get();
    let world = world.get();
    let label = world.label();
    let loaded = py
        .detach(|| {
            hstl::load::load_in_world(&spec.source, Some(&spec.spec.name), &world.world, &label)
        })
        .map_err(|e| errors::load_error(py, &spec.filename, &spec.source, e))?;
    let task = trainable(&loaded.spec, spec, episodes)?;
    let mut failure = None;
    let trained = py.detach(|| {
        let mut reporter = Reporter::new(progress.as_ref(), task.learn.episodes);
        let trained = train_until(&task, &world.world, seed, |e, r| reporter.tick(e, r));
        failure = reporter.failure;
        trained
    });
    if let Some(e) = failure {
        return Err(e);
    }
    let trained = trained
        .map_err(|e| problem_error(&hstl::train::cannot_train(&spec.filename, &task.name, &e)))?;
    let text = policy_json(&trained.policy, &spec.source, seed)
        .map_err(|e| value_error(e.to_string(), None))?;
    Policy::from_text(py, text, "<trained>", Some(trained.curve), Some(trained.steps))
}

/// Trains `spec` in a gymnasium environment whose observation `o` has the state
/// `valuation(o)` (see `crate::gym` for how its calls go).
#[pyfunction]
#[pyo3(signature = (spec, env, valuation, seed, name, observations, observation_start, actions, action_start, episodes=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn _train_env(
    py: Python<'_>,
    spec: &Bound<'_, Spec>,
    env: &Bound<'_, PyAny>,
    valuation: &Bound<'_, PyAny>,
    seed: u64,
    name: String,
    observations: usize,
    observation_start: i64,
    actions: usize,
    action_start: i64,
    episodes: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Policy> {
    let spec = spec.get();
    let task = trainable(&spec.spec, spec, episodes)?;
    let spaces = Spaces { name, observations, observation_start, actions, action_start };
    let pyenv = py_env(env, valuation, spaces, &task)?;
    let (trained, failure, pyenv) = py.detach(move || {
        let mut reporter = Reporter::new(progress.as_ref(), task.learn.episodes);
        let trained = train_until(&task, &pyenv, seed, |e, r| {
            if pyenv.failed() { ControlFlow::Break(()) } else { reporter.tick(e, r) }
        });
        (trained, reporter.failure, pyenv)
    });
    if let Some(e) = pyenv.take_error().map(failure_error).or(failure) {
        return Err(e);
    }
    let trained = trained.map_err(|e| cannot_train_env(&spec.filename, spec, &e))?;
    let text = policy_json(&trained.policy, &spec.source, seed)
        .map_err(|e| value_error(e.to_string(), None))?;
    Policy::from_text(py, text, "<trained>", Some(trained.curve), Some(trained.steps))
}

/// Trains `spec` in a continuous world (a plane, `mountain-car`) with the approximate
/// learner, as `hstlc train --world --seed --episodes` does: the spec is checked against
/// the world first, and the policy's `policy.json` is byte for byte the one `hstlc train`
/// writes.
#[pyfunction]
#[pyo3(signature = (spec, world, seed, episodes=None, progress=None))]
pub fn _train_continuous(
    py: Python<'_>,
    spec: &Bound<'_, Spec>,
    world: &Bound<'_, ContinuousWorld>,
    seed: u64,
    episodes: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Policy> {
    let spec = spec.get();
    let world = world.get();
    let label = hstl::world::any_label(&world.world, world.file.as_deref());
    let loaded = py
        .detach(|| {
            hstl::load::load_in_any_world(&spec.source, Some(&spec.spec.name), &world.world, &label)
        })
        .map_err(|e| errors::load_error(py, &spec.filename, &spec.source, e))?;
    let mut task = trainable(&loaded.spec, spec, episodes)?;
    hstl::continuous::fit_tiles(&mut task, &loaded.spec, &world.world);
    let mut failure = None;
    let trained = py.detach(|| {
        let mut reporter = Reporter::new(progress.as_ref(), task.learn.episodes);
        let trained =
            hstl::continuous::train_until(&task, &world.world, seed, |e, r| reporter.tick(e, r));
        failure = reporter.failure;
        trained
    });
    if let Some(e) = failure {
        return Err(e);
    }
    let trained = trained
        .map_err(|e| problem_error(&hstl::train::cannot_train(&spec.filename, &task.name, &e)))?;
    let text =
        hstl::continuous::policy_json(&task, &world.world, &trained.agent, &spec.source, seed)
            .map_err(|e| value_error(e.to_string(), None))?;
    Policy::from_text(py, text, "<trained>", Some(trained.curve), Some(trained.steps))
}

/// Trains `spec` with the approximate learner in a gymnasium environment with a bounded
/// `Box` observation space (`low`, `high`) and `Discrete` actions, whose observation `o`
/// has the state `valuation(o)` (None: the observation's components in order); see
/// `hstl::outside::BoxEnv` for how its calls go.
#[pyfunction]
#[pyo3(signature = (spec, env, valuation, seed, name, low, high, actions, action_start, episodes=None, progress=None))]
#[allow(clippy::too_many_arguments)]
pub fn _train_box(
    py: Python<'_>,
    spec: &Bound<'_, Spec>,
    env: &Bound<'_, PyAny>,
    valuation: Option<&Bound<'_, PyAny>>,
    seed: u64,
    name: String,
    low: Vec<f64>,
    high: Vec<f64>,
    actions: usize,
    action_start: i64,
    episodes: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Policy> {
    let spec = spec.get();
    let task = trainable(&spec.spec, spec, episodes)?;
    if task.learn.tiles.is_none() {
        return Err(value_error(
            format!(
                "{}: spec `{}` is learned with tables, which a `Box` observation space cannot index",
                spec.filename, task.name
            ),
            Some("declare the state variables as `float` ranges (`x: float in 0..=14`), which the approximate learner tiles".into()),
        ));
    }
    let vars: Vec<String> = task.state_vars.iter().map(|v| v.name.clone()).collect();
    let described = hstl::gym::Described::new(&name, vars, low, high, actions, action_start)
        .map_err(|p| problem_error(&p))?;
    let boxed = box_env(env, valuation, described, &task)?;
    let (trained, failure, boxed) = py.detach(move || {
        let mut reporter = Reporter::new(progress.as_ref(), task.learn.episodes);
        let trained = hstl::continuous::train_world_until(&task, &boxed, seed, |e, r| {
            if boxed.failed() { ControlFlow::Break(()) } else { reporter.tick(e, r) }
        })
        .map(|t| (t, task));
        (trained, reporter.failure, boxed)
    });
    if let Some(e) = boxed.take_error().map(failure_error).or(failure) {
        return Err(e);
    }
    let (trained, task) = trained.map_err(|e| cannot_train_env(&spec.filename, spec, &e))?;
    let text = hstl::continuous::policy_json_in(
        &task,
        boxed.described(),
        &trained.agent,
        &spec.source,
        seed,
    )
    .map_err(|e| value_error(e.to_string(), None))?;
    Policy::from_text(py, text, "<trained>", Some(trained.curve), Some(trained.steps))
}

/// The spec as the learner's data, with `episodes` in the budget of `learn { episodes }`.
fn trainable(
    checked: &hstl::lang::CheckedSpec,
    spec: &Spec,
    episodes: Option<usize>,
) -> PyResult<TaskSpec> {
    let mut task = hstl::train::trainable(checked, &spec.source, &spec.filename)
        .map_err(|p| problem_error(&p))?;
    hstl::train::set_episodes(&mut task, episodes).map_err(|p| problem_error(&p))?;
    Ok(task)
}

fn cannot_train_env(file: &str, spec: &Spec, e: &Error) -> PyErr {
    value_error(
        format!("{file}: cannot train `{}` on the environment: {e}", spec.spec.name),
        Some("check the spec's options against the states `valuation` gives".into()),
    )
}

/// Checks for signals and reports progress, at most every [`PROGRESS_EVERY`].
struct Reporter<'a> {
    progress: Option<&'a Py<PyAny>>,
    episodes: usize,
    last: Instant,
    failure: Option<PyErr>,
}

impl<'a> Reporter<'a> {
    fn new(progress: Option<&'a Py<PyAny>>, episodes: usize) -> Reporter<'a> {
        Reporter { progress, episodes, last: Instant::now(), failure: None }
    }

    fn tick(&mut self, episode: usize, reward: f64) -> ControlFlow<()> {
        let done = episode + 1;
        if done < self.episodes && self.last.elapsed() < PROGRESS_EVERY {
            return ControlFlow::Continue(());
        }
        self.last = Instant::now();
        let reported = Python::attach(|py| {
            py.check_signals()?;
            if let Some(callback) = self.progress {
                callback.call1(py, (done, self.episodes, reward))?;
            }
            Ok::<(), PyErr>(())
        });
        match reported {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                self.failure = Some(e);
                ControlFlow::Break(())
            }
        }
    }
}
