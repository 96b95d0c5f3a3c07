//! `hstl.Policy`: a trained policy, its `policy.json`, replays and evaluation.

use std::path::PathBuf;
use std::sync::Mutex;

use hstl::Problem;
use hstl::continuous;
use hstl::evaluate::{self, Evaluation, Replay, Runs};
use hstl::replayed::{Replayed, StateIndex};
use hstl::runtime::approx::Stepper;
use hstl::runtime::eval::{AgentController, AgentProgress, Controller};
use hstl::runtime::optimum::SolveConfig;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyInt, PyTuple};

use crate::continuous::ContinuousWorld;
use crate::errors::{self, policy_error, problem_error, value_error};
use crate::gym::{Spaces, box_env, failure_error, py_env};
use crate::spec::Spec;
use crate::trace::state_values;
use crate::world::World;

/// The help of an optimum that cannot be computed (`hstlc eval` says `--no-optimum`).
const SKIP_OPTIMUM: &str = "pass `optimum=False` to skip the optimum W*";

/// A trained policy: the options policy and one flat policy per primitive option, with
/// the Q-tables they are greedy in, as `policy.json` holds them.
///
/// `hstl.train(...)` returns one; `Policy.load(path)` reads the `policy.json` that
/// `hstlc train` or `policy.save(path)` wrote and checks it whole against the spec in its
/// `spec_source` and the world in its `env`, as `hstlc eval` does (a document edited by
/// hand or damaged raises `hstl.PolicyError`). `policy.act(state)` runs the policy one
/// step at a time, `policy.evaluate()` measures it as `hstlc eval` does.
///
/// A policy pickles by its contents (the `policy.json` text, the learning curve).
#[pyclass(module = "hstl", frozen)]
pub struct Policy {
    text: String,
    replayed: Replayed,
    curve: Option<Vec<f64>>,
    steps: Option<u64>,
    /// Every tabular state's values to its index.
    states: StateIndex,
    /// Where `act` is in the running option.
    runner: Mutex<Runner>,
}

#[derive(Default)]
struct Runner {
    progress: AgentProgress,
    /// An action was given and its outcome not seen yet: the next state is it.
    pending: bool,
    /// A learned function's run so far.
    stepper: Stepper,
}

impl Policy {
    /// The policy in `text` (reported as `file`), checked whole; `curve` and `steps` are
    /// what training measured, when it ran in this process.
    pub fn from_text(
        py: Python<'_>,
        text: String,
        file: &str,
        curve: Option<Vec<f64>>,
        steps: Option<u64>,
    ) -> PyResult<Policy> {
        let replayed =
            py.detach(|| Replayed::read(&text)).map_err(|p| policy_error(&p.in_file(file)))?;
        let states = StateIndex::of(&replayed);
        Ok(Policy { text, replayed, curve, steps, states, runner: Mutex::default() })
    }

    /// The state index of `state`, as `act` takes it.
    fn index_of(&self, state: &Bound<'_, PyAny>) -> PyResult<usize> {
        if matches!(self.replayed, Replayed::Listed(..))
            && state.is_instance_of::<PyInt>()
            && let Some(index) = self.replayed.observation_index(state.extract()?)
        {
            return index.map_err(|p| problem_error(&p));
        }
        let values = state_values(state, &self.replayed.state_vars())?;
        self.replayed.state_index(&self.states, &values).map_err(|p| problem_error(&p))
    }
}

#[pymethods]
impl Policy {
    /// Reads the `policy.json` at `path` and checks it whole, as `hstlc eval` does.
    ///
    /// Raises `hstl.PolicyError` (a `ValueError`) for a document that is not a policy,
    /// was edited or damaged, or does not fit its own spec and world, and
    /// `FileNotFoundError` (or another `OSError`) when it cannot be read.
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Policy> {
        let text =
            crate::files::read_text(&path, hstl::evaluate::MAX_POLICY_BYTES, "policy", |e| {
                errors::read_error(&path, e)
            })?;
        Policy::from_text(py, text, &path.display().to_string(), None, None)
    }

    /// The policy in the text of a `policy.json`, reported as `filename` in errors.
    #[staticmethod]
    #[pyo3(signature = (text, filename="<string>".to_string()))]
    fn from_json(py: Python<'_>, text: String, filename: String) -> PyResult<Policy> {
        Policy::from_text(py, text, &filename, None, None)
    }

    /// Writes the `policy.json` to `path`, whole or not at all (a temporary file in the
    /// same folder, then renamed), byte for byte what `hstlc train` writes for the same
    /// spec, world, seed and episodes.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        py.detach(|| hstl_files::write::replace(&path, self.text.as_bytes()))
            .map_err(|e| errors::write_error(&path, &e))
    }

    /// The `policy.json` text.
    #[getter]
    fn json(&self) -> &str {
        &self.text
    }

    /// The spec the policy was trained on (from the document's `spec_source`).
    #[getter]
    fn spec(&self, py: Python<'_>) -> PyResult<Spec> {
        let source = self.replayed.source().to_string();
        let name = self.replayed.spec().name.clone();
        Spec::from_source(py, source, "<spec_source>".into(), Some(name), true)
    }

    /// The spec's name.
    #[getter]
    fn spec_name(&self) -> &str {
        &self.replayed.spec().name
    }

    /// The world the policy was trained in: a `hstl.World` (a grid) or a
    /// `hstl.ContinuousWorld` (a plane, `mountain-car`); None for a gymnasium environment.
    #[getter]
    fn world(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        Ok(match &self.replayed {
            Replayed::Grid(r) => Some(Py::new(py, World::new(r.env.clone(), None))?.into_any()),
            Replayed::Tiles(r) => {
                Some(Py::new(py, ContinuousWorld::of(r.world.clone()))?.into_any())
            }
            Replayed::Listed(..) | Replayed::GymTiles(_) => None,
        })
    }

    /// Whether the policy is a learned function (the approximate learner's tiling and
    /// weights, on a continuous state) rather than Q-tables.
    #[getter]
    fn learned_function(&self) -> bool {
        self.replayed.tiles().is_some()
    }

    /// The environment's name: the world's, or the gymnasium environment's id.
    #[getter]
    fn env_name(&self) -> String {
        self.replayed.env_name()
    }

    /// The seed it was trained from, when the document records it.
    #[getter]
    fn seed(&self) -> Option<u64> {
        self.replayed.seed()
    }

    /// The state variables, in the order `act` takes a sequence state.
    #[getter]
    fn state_vars(&self) -> Vec<String> {
        self.replayed.state_vars()
    }

    /// The action names, in index order (`act` returns the index).
    #[getter]
    fn actions(&self) -> Vec<String> {
        self.replayed.actions()
    }

    /// The options' names, in the options set's order (the columns of
    /// `q_tables["options"]`).
    #[getter]
    fn options(&self) -> Vec<String> {
        self.replayed.spec().options.iter().map(|o| o.name.clone()).collect()
    }

    /// The summed option rewards of each training episode (float64), when training ran in
    /// this process (or was pickled with it); None for a loaded policy.
    #[getter]
    fn curve<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.curve.as_ref().map(|c| PyArray1::from_slice(py, c))
    }

    /// Primitive steps taken in training, when it ran in this process; None otherwise.
    #[getter]
    fn steps(&self) -> Option<u64> {
        self.steps
    }

    /// The Q-tables as float64 arrays, bit for bit as `policy.json` stores them:
    /// `{"flat": {primitive: (states, actions)}, "options": (observations, options)}`,
    /// states in index order (for a grid world: row by row from the bottom, see
    /// `World.free_cells`); with `memory: B` an observation is `state * values + memory`.
    #[getter]
    fn q_tables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let Some(doc) = self.replayed.document() else {
            return Err(value_error(
                "a learned function has no Q-tables: its weights over a tiling are in `policy.json`",
                Some(
                    "read `policy.json` (`policy.json`'s `weights`), or call `act` and `evaluate`"
                        .into(),
                ),
            ));
        };
        let q = doc.q_tables().map_err(|e| value_error(e.to_string(), None))?;
        let actions = doc.actions.len().max(1);
        let options = doc.options.len().max(1);
        let flat = PyDict::new(py);
        for (p, table) in doc.primitives.iter().zip(q.flat) {
            let rows = table.len() / actions;
            flat.set_item(&p.name, PyArray1::from_vec(py, table).reshape([rows, actions])?)?;
        }
        let rows = q.options.len() / options;
        let out = PyDict::new(py);
        out.set_item("flat", flat)?;
        out.set_item("options", PyArray1::from_vec(py, q.options).reshape([rows, options])?)?;
        Ok(out)
    }

    /// The greedy action in `state`, running the policy's options across calls: the
    /// options policy picks an option where none runs, its legs follow their flat
    /// policies, a leg ends in its termination set. Each call sees the state the previous
    /// action led to; call `reset()` at the start of every episode.
    ///
    /// `state` is an observation of the environment the policy was trained in (a grid
    /// world's `(x, y)`, a gymnasium environment's integer, a continuous world's `(x, y)`
    /// or `(x, v)` array) or a mapping from the state variables to values; for a policy
    /// trained on a `Box` environment with a `valuation`, the valuation's result. A
    /// learned function's state must lie in its world (or the ranges its spec declares):
    /// NaN, infinite or outside values are refused. Returns the action's index (for a
    /// gymnasium environment, the action itself).
    fn act(&self, state: &Bound<'_, PyAny>) -> PyResult<i64> {
        if let Some(agent) = self.replayed.tiles() {
            let values = state_values(state, &self.replayed.state_vars())?;
            let blocked = self.replayed.blocked(&values).map_err(|p| problem_error(&p))?;
            let mut runner = self.runner.lock().unwrap_or_else(|p| p.into_inner());
            let (action, _) = runner.stepper.act(agent, &values, &blocked);
            return Ok(self.replayed.action_start() + action as i64);
        }
        let s = self.index_of(state)?;
        let Some(agent) = self.replayed.agent() else {
            return Err(value_error(
                "the policy holds neither Q-tables nor a learned function",
                None,
            ));
        };
        let mut runner = self.runner.lock().unwrap_or_else(|p| p.into_inner());
        let mut controller = AgentController::resume(agent, std::mem::take(&mut runner.progress));
        if runner.pending {
            controller.observe(s);
        }
        let decision = controller.act(s);
        runner.progress = controller.pause();
        runner.pending = true;
        Ok(self.replayed.action_start() + decision.action as i64)
    }

    /// Forgets the running option (and the memory counters): the next `act` starts afresh.
    fn reset(&self) {
        *self.runner.lock().unwrap_or_else(|p| p.into_inner()) = Runner::default();
    }

    /// Replays the policy greedily as `hstlc eval` does and returns what it measured.
    ///
    /// `starts` runs of `steps` steps from random starts (the starts and slips drawn from
    /// one generator seeded with `seed`). `hstl.study` and `hstlc study` measure the
    /// policy trained from seed `s` on other runs, those of `seed=s ^ hstl.EVAL_SEED` (with
    /// the defaults of `starts`, `steps` and `burn_in`): pass that seed to get their
    /// figures; the default `seed=0` scores every policy on the same runs. For a persistent task the dict holds
    /// `window_rate` (pooled over the runs; the share of steps after `burn_in` whose
    /// windows visit every region), `window_rates` (per run), `baseline` (the hand-written
    /// nearest-cell cycle on the same starts and slips) and, with `optimum=True`,
    /// `optimum` (`W*`, by value iteration: a few seconds for the case study),
    /// `optimum_bounds` and `optimum_converged`; for any task `robustness` (the task's
    /// robustness over each run, windows clipped at the run's end), `robustness_mean`,
    /// `robustness_complete` (over complete windows; None for a run too short for one),
    /// `satisfied` (runs with positive robustness over complete windows; a run too short
    /// for one is judged with its windows clipped) and
    /// `satisfied_clipped` (the same, windows clipped); for a persistent task
    /// `windows_kept` (per run, the share of its complete steps where the task's body
    /// holds). Keys that do not apply hold None.
    ///
    /// A policy trained on a gymnasium environment is replayed in `env` (the same
    /// environment, with the same `valuation`), more slowly; its `baseline` and `optimum`
    /// are None.
    #[pyo3(signature = (starts=100, steps=None, burn_in=100, seed=0, optimum=true, *, env=None, valuation=None))]
    #[allow(clippy::too_many_arguments)]
    fn evaluate<'py>(
        &self,
        py: Python<'py>,
        starts: usize,
        steps: Option<usize>,
        burn_in: usize,
        seed: u64,
        optimum: bool,
        env: Option<&Bound<'py, PyAny>>,
        valuation: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        if self.replayed.tiles().is_some() {
            return self.evaluate_tiles(py, starts, steps, burn_in, seed, optimum, env, valuation);
        }
        let steps = steps.unwrap_or(Runs::default().steps);
        let runs = Runs { starts, steps, burn_in, seed };
        let flag = |name: &str| format!("`{name}`");
        runs.check_budget(flag).map_err(|p| problem_error(&p))?;
        runs.check_burn_in(self.replayed.spec(), flag).map_err(|p| problem_error(&p))?;
        let (evaluation, baseline, best) = match &self.replayed {
            Replayed::Grid(replay) => {
                if env.is_some() || valuation.is_some() {
                    return Err(PyTypeError::new_err(
                        "`env` and `valuation` are for a policy trained on a gymnasium environment; this one holds its world",
                    ));
                }
                py.detach(|| -> Result<_, Problem> {
                    let evaluation = evaluate::evaluate(replay, runs)?;
                    let baseline = evaluate::baseline(replay, runs)?;
                    let best = match optimum {
                        true => evaluate::optimum(replay, SolveConfig::default())
                            .map_err(|p| Problem::new(p.message, SKIP_OPTIMUM.to_string()))?,
                        false => None,
                    };
                    Ok((evaluation, baseline, best))
                })
                .map_err(|p| problem_error(&p))?
            }
            Replayed::Tiles(_) | Replayed::GymTiles(_) => {
                return Err(value_error("a learned function is evaluated apart", None));
            }
            Replayed::Listed(listed, spaces) => {
                let (Some(env), Some(valuation)) = (env, valuation) else {
                    return Err(PyTypeError::new_err(errors::with_help(
                        "this policy was trained on a gymnasium environment, which policy.json cannot rebuild",
                        Some("pass `env=` (the environment) and `valuation=` (as given to `hstl.train`)".into()),
                    )));
                };
                let (name, observations, observation_start, actions, action_start) = py
                    .import("hstl._train")?
                    .call_method1("_spaces", (env,))?
                    .extract::<(String, usize, i64, usize, i64)>()?;
                let given = Spaces { name, observations, observation_start, actions, action_start };
                spaces.check_same(&given).map_err(|p| problem_error(&p))?;
                let pyenv = py_env(env, valuation, given, &listed.spec)?;
                let agent = listed.policy.agent_for(&listed.spec, &pyenv).map_err(|e| {
                    value_error(
                        e.to_string(),
                        Some("pass the environment and valuation it was trained with".into()),
                    )
                })?;
                let replay = Replay {
                    policy: listed.policy.clone(),
                    spec: listed.spec.clone(),
                    env: pyenv,
                    agent,
                    source: listed.source.clone(),
                    seed: listed.seed,
                };
                let (result, replay) =
                    py.detach(move || (evaluate::evaluate(&replay, runs), replay));
                if let Some(e) = replay.env.take_error() {
                    return Err(failure_error(e));
                }
                (result.map_err(|p| problem_error(&p))?, None, None)
            }
        };
        let out = PyDict::new(py);
        let (robustness, complete) = match evaluation {
            Evaluation::Window { report } => {
                out.set_item("window_rate", report.rate)?;
                out.set_item("window_rates", report.per_rollout)?;
                out.set_item("windows_kept", report.kept)?;
                (report.robustness, report.complete)
            }
            Evaluation::Robustness { values, complete } => {
                out.set_item("window_rate", py.None())?;
                out.set_item("window_rates", py.None())?;
                out.set_item("windows_kept", py.None())?;
                (values, complete)
            }
        };
        let mean = robustness.iter().sum::<f64>() / robustness.len().max(1) as f64;
        out.set_item("robustness_mean", mean)?;
        // Satisfaction is counted over complete windows: clipped windows at a run's end make
        // a persistent task fail on nearly every finite run.
        let satisfied = evaluate::satisfied(&robustness, &complete);
        out.set_item("satisfied", satisfied)?;
        out.set_item("satisfied_clipped", robustness.iter().filter(|&&v| v > 0.0).count())?;
        out.set_item("robustness", robustness)?;
        out.set_item("robustness_complete", complete)?;
        out.set_item("baseline", baseline)?;
        out.set_item("optimum", best.as_ref().map(|o| o.gain))?;
        out.set_item("optimum_bounds", best.as_ref().map(|o| (o.lower, o.upper)))?;
        out.set_item("optimum_converged", best.as_ref().map(|o| o.converged))?;
        for (k, v) in [("starts", starts), ("steps", steps), ("burn_in", burn_in)] {
            out.set_item(k, v)?;
        }
        out.set_item("seed", seed)?;
        Ok(out)
    }

    #[staticmethod]
    fn _from_contents(
        py: Python<'_>,
        text: String,
        curve: Option<Vec<f64>>,
        steps: Option<u64>,
    ) -> PyResult<Policy> {
        Policy::from_text(py, text, "<pickle>", curve, steps)
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let this = slf.get();
        let args = (this.text.clone(), this.curve.clone(), this.steps).into_pyobject(slf.py())?;
        Ok((slf.get_type().getattr("_from_contents")?, args))
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<Policy>().is_ok_and(|o| o.get().text == self.text)
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        self.text.hash(&mut h);
        h.finish()
    }

    fn __repr__(&self) -> String {
        let seed = self.seed().map_or(String::new(), |s| format!(" (seed {s})"));
        format!("<hstl.Policy of `{}` on `{}`{seed}>", self.replayed.spec().name, self.env_name())
    }
}

impl Policy {
    /// `evaluate` of a learned function: natively in the world the document holds, or in
    /// `env` (a gymnasium environment with a `Box` observation space) through Python.
    #[allow(clippy::too_many_arguments)]
    fn evaluate_tiles<'py>(
        &self,
        py: Python<'py>,
        starts: usize,
        steps: Option<usize>,
        burn_in: usize,
        seed: u64,
        optimum: bool,
        env: Option<&Bound<'py, PyAny>>,
        valuation: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let spec = self.replayed.spec();
        // A reach task is decided within its horizon, as `hstlc eval` runs it.
        let steps = match steps {
            Some(n) => n,
            None if spec.regions.is_empty() => continuous::task_steps(spec),
            None => Runs::default().steps,
        };
        let runs = Runs { starts, steps, burn_in, seed };
        let flag = |name: &str| format!("`{name}`");
        runs.check_budget(flag).map_err(|p| problem_error(&p))?;
        runs.check_burn_in(spec, flag).map_err(|p| problem_error(&p))?;
        let (evaluation, reference) = match (&self.replayed, env) {
            (Replayed::Tiles(replay), None) => {
                if valuation.is_some() {
                    return Err(PyTypeError::new_err("`valuation` goes with `env=`"));
                }
                py.detach(|| -> Result<_, Problem> {
                    let evaluation = continuous::evaluate(replay, runs)?;
                    let reference = match optimum {
                        true => hstl::reference::Reference::new(&replay.spec, &replay.world)
                            .ok()
                            .map(|r| r.evaluate(runs)),
                        false => None,
                    };
                    Ok((evaluation, reference))
                })
                .map_err(|p| problem_error(&p))?
            }
            (Replayed::GymTiles(_), None) => {
                return Err(PyTypeError::new_err(errors::with_help(
                    "this policy was trained on a gymnasium environment, which policy.json cannot rebuild",
                    Some(
                        "pass `env=` (the environment) and `valuation=` (as given to `hstl.train`)"
                            .into(),
                    ),
                )));
            }
            (_, Some(env)) => {
                let given = py
                    .import("hstl._train")?
                    .call_method1("_box_spaces", (env,))?
                    .extract::<(String, Vec<f64>, Vec<f64>, usize, i64)>()?;
                let (name, low, high, actions, action_start) = given;
                let vars = self.replayed.state_vars();
                let described =
                    hstl::gym::Described::new(&name, vars, low, high, actions, action_start)
                        .map_err(|p| problem_error(&p))?;
                let agent = self
                    .replayed
                    .tiles()
                    .ok_or_else(|| value_error("the policy holds no learned function", None))?;
                self.replayed.check_box_env(&described).map_err(|p| problem_error(&p))?;
                let boxed = box_env(env, valuation, described, spec)?;
                let (result, boxed) =
                    py.detach(move || (continuous::evaluate_in(spec, agent, &boxed, runs), boxed));
                if let Some(e) = boxed.take_error() {
                    return Err(failure_error(e));
                }
                (result.map_err(|p| problem_error(&p))?, None)
            }
            _ => return Err(value_error("the policy holds no learned function", None)),
        };
        let out = PyDict::new(py);
        match evaluation {
            continuous::Evaluation::Window(w) => {
                out.set_item("window_rate", w.rate)?;
                out.set_item("window_rates", w.per_run)?;
                out.set_item("satisfaction", py.None())?;
                let mean = w.robustness.iter().sum::<f64>() / w.robustness.len().max(1) as f64;
                out.set_item("robustness_mean", mean)?;
                out.set_item("robustness", w.robustness)?;
            }
            continuous::Evaluation::Satisfaction { rate } => {
                out.set_item("window_rate", py.None())?;
                out.set_item("window_rates", py.None())?;
                out.set_item("satisfaction", rate)?;
                out.set_item("robustness_mean", py.None())?;
                out.set_item("robustness", py.None())?;
            }
        }
        let reference = reference.map(|r| match r {
            continuous::Evaluation::Window(w) => w.rate,
            continuous::Evaluation::Satisfaction { rate } => rate,
        });
        out.set_item("reference", reference)?;
        out.set_item("baseline", py.None())?;
        out.set_item("optimum", py.None())?;
        for (k, v) in [("starts", starts), ("steps", steps), ("burn_in", burn_in)] {
            out.set_item(k, v)?;
        }
        out.set_item("seed", seed)?;
        Ok(out)
    }
}
