//! `hstl.Policy`: a trained policy, its `policy.json`, replays and evaluation.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Mutex;

use hstl::Problem;
use hstl::continuous;
use hstl::evaluate::{self, Evaluation, Replay, Runs};
use hstl::runtime::approx::{ApproxAgent, Stepper};
use hstl::runtime::eval::{AgentController, AgentProgress, Controller};
use hstl::runtime::optimum::SolveConfig;
use hstl::runtime::{Agent, Env, GridWorld, Rng, TaskSpec, Value};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyInt, PyTuple};

use crate::continuous::ContinuousWorld;
use crate::errors::{self, policy_error, problem_error, value_error};
use crate::gym::{BoxEnv, PyEnv, Spaces};
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
    /// Every state's values (in `state_vars` order, as `f64` bits) to its index.
    states: HashMap<Vec<u64>, usize>,
    /// Where `act` is in the running option.
    runner: Mutex<Runner>,
}

/// A replay in the environment the document describes.
enum Replayed {
    /// A grid world: `env` holds it whole.
    Grid(Replay<GridWorld>),
    /// A gymnasium environment, which the document cannot rebuild: its states as listed.
    Listed(Replay<Listed>, Spaces),
    /// A learned function in a continuous world (a plane, `mountain-car`) it holds whole.
    Tiles(Box<continuous::Replay>),
    /// A learned function in a gymnasium environment with a `Box` observation space, which
    /// the document describes.
    GymTiles(Box<continuous::GymReplay>),
}

#[derive(Default)]
struct Runner {
    progress: AgentProgress,
    /// An action was given and its outcome not seen yet: the next state is it.
    pending: bool,
    /// A learned function's run so far.
    stepper: Stepper,
}

/// The states a `policy.json` lists (those of its first flat policy, in index order), as
/// an environment: what a policy trained on a gymnasium environment is checked against.
/// It cannot move: a replay that steps needs the environment itself.
#[derive(Clone, Debug)]
pub struct Listed {
    name: String,
    params: Value,
    vars: Vec<String>,
    actions: Vec<String>,
    values: Vec<f64>,
    states: usize,
}

impl Listed {
    fn of(policy: &hstl::runtime::Policy) -> Result<Listed, Problem> {
        let bad =
            |m: String| Problem::new(m, "pass the policy.json that `hstl.train` wrote".to_string());
        let entries = policy
            .flat_policies
            .values()
            .next()
            .ok_or_else(|| bad("it has no flat policy to list its states".into()))?;
        let mut values = Vec::with_capacity(entries.len() * policy.state_vars.len());
        for (s, e) in entries.iter().enumerate() {
            for var in &policy.state_vars {
                let v = e.state.get(var).ok_or_else(|| {
                    bad(format!("state {s} of its flat policies has no number for `{var}`"))
                })?;
                values.push(v);
            }
        }
        Ok(Listed {
            name: policy.env.name.clone(),
            params: policy.env.params.clone(),
            vars: policy.state_vars.clone(),
            actions: policy.actions.clone(),
            values,
            states: entries.len(),
        })
    }
}

impl Env for Listed {
    type State = usize;

    fn name(&self) -> &str {
        &self.name
    }

    fn params(&self) -> Value {
        self.params.clone()
    }

    fn state_vars(&self) -> Vec<String> {
        self.vars.clone()
    }

    fn actions(&self) -> Vec<String> {
        self.actions.clone()
    }

    fn num_states(&self) -> usize {
        self.states
    }

    fn index(&self, state: &usize) -> usize {
        *state
    }

    fn state(&self, index: usize) -> Option<usize> {
        (index < self.states).then_some(index)
    }

    fn valuation(&self, state: &usize, out: &mut Vec<f64>) {
        out.clear();
        let k = self.vars.len();
        if let Some(row) = self.values.get(state * k..(state + 1) * k) {
            out.extend_from_slice(row);
        }
    }

    fn reset(&self, _rng: &mut Rng) -> usize {
        0
    }

    fn step(&self, state: &usize, _action: usize, _rng: &mut Rng) -> usize {
        *state
    }
}

impl Replayed {
    /// The tabular agent; None for a learned function.
    fn agent(&self) -> Option<&Agent> {
        match self {
            Replayed::Grid(r) => Some(&r.agent),
            Replayed::Listed(r, _) => Some(&r.agent),
            Replayed::Tiles(_) | Replayed::GymTiles(_) => None,
        }
    }

    fn spec(&self) -> &TaskSpec {
        match self {
            Replayed::Grid(r) => &r.spec,
            Replayed::Listed(r, _) => &r.spec,
            Replayed::Tiles(r) => &r.spec,
            Replayed::GymTiles(r) => &r.spec,
        }
    }

    /// The tabular document; None for a learned function.
    fn document(&self) -> Option<&hstl::runtime::Policy> {
        match self {
            Replayed::Grid(r) => Some(&r.policy),
            Replayed::Listed(r, _) => Some(&r.policy),
            Replayed::Tiles(_) | Replayed::GymTiles(_) => None,
        }
    }

    fn source(&self) -> &str {
        match self {
            Replayed::Grid(r) => &r.source,
            Replayed::Listed(r, _) => &r.source,
            Replayed::Tiles(r) => &r.source,
            Replayed::GymTiles(r) => &r.source,
        }
    }

    fn seed(&self) -> Option<u64> {
        match self {
            Replayed::Grid(r) => r.seed,
            Replayed::Listed(r, _) => r.seed,
            Replayed::Tiles(r) => r.seed,
            Replayed::GymTiles(r) => r.seed,
        }
    }

    fn env_name(&self) -> String {
        match self {
            Replayed::Tiles(r) => r.world.name().to_string(),
            Replayed::GymTiles(r) => r.env.name.clone(),
            _ => self.document().map_or(String::new(), |d| d.env.name.clone()),
        }
    }

    fn state_vars(&self) -> Vec<String> {
        match self {
            Replayed::Tiles(r) => r.agent.model.vars.clone(),
            Replayed::GymTiles(r) => r.agent.model.vars.clone(),
            _ => self.document().map_or(Vec::new(), |d| d.state_vars.clone()),
        }
    }

    fn actions(&self) -> Vec<String> {
        match self {
            Replayed::Tiles(r) => ContinuousWorld::actions_of(&r.world),
            Replayed::GymTiles(r) => hstl::runtime::World::actions(&r.env),
            _ => self.document().map_or(Vec::new(), |d| d.actions.clone()),
        }
    }

    /// A learned function's agent and what `act` needs of its world: the first action's
    /// value, and which actions a state blocks.
    fn tiles(&self) -> Option<(&ApproxAgent, i64)> {
        match self {
            Replayed::Tiles(r) => Some((&r.agent, 0)),
            Replayed::GymTiles(r) => Some((&r.agent, r.env.action_start)),
            _ => None,
        }
    }
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
            py.detach(|| replay_any(&text)).map_err(|p| policy_error(&p.in_file(file)))?;
        if matches!(replayed, Replayed::Tiles(_) | Replayed::GymTiles(_)) {
            let states = HashMap::new();
            return Ok(Policy { text, replayed, curve, steps, states, runner: Mutex::default() });
        }
        let mut states = HashMap::new();
        let mut row = Vec::new();
        let mut index = |env: &dyn Fn(usize, &mut Vec<f64>), n: usize| {
            for s in 0..n {
                env(s, &mut row);
                states.insert(key(&row), s);
            }
        };
        match &replayed {
            Replayed::Grid(r) => index(
                &|s, out| {
                    if let Some(c) = r.env.state(s) {
                        r.env.valuation(&c, out)
                    }
                },
                r.env.num_states(),
            ),
            Replayed::Listed(r, _) => index(&|s, out| r.env.valuation(&s, out), r.env.num_states()),
            Replayed::Tiles(_) | Replayed::GymTiles(_) => {}
        }
        Ok(Policy { text, replayed, curve, steps, states, runner: Mutex::default() })
    }

    /// The state index of `state`, as `act` takes it.
    fn index_of(&self, state: &Bound<'_, PyAny>) -> PyResult<usize> {
        if let Replayed::Listed(r, spaces) = &self.replayed
            && state.is_instance_of::<PyInt>()
        {
            let obs: i64 = state.extract()?;
            let n = r.env.num_states();
            return obs
                .checked_sub(spaces.observation_start)
                .and_then(|i| usize::try_from(i).ok())
                .filter(|&i| i < n)
                .ok_or_else(|| {
                    value_error(
                        format!(
                            "observation {obs} is outside Discrete({n}, start={})",
                            spaces.observation_start
                        ),
                        None,
                    )
                });
        }
        let vars = &self.replayed.state_vars();
        let values = state_values(state, vars)?;
        self.states.get(&key(&values)).copied().ok_or_else(|| {
            let shown: Vec<String> =
                vars.iter().zip(&values).map(|(v, x)| format!("{v} = {x}")).collect();
            value_error(
                format!("the policy has no state {}", shown.join(", ")),
                Some(match &self.replayed {
                    Replayed::Grid(r) => {
                        format!("give a free cell of {}", hstl::world::label(&r.env, None))
                    }
                    _ => "give an observation of the environment".into(),
                }),
            )
        })
    }
}

/// Replays a grid world policy, or a gymnasium one against the states it lists.
fn replay_any(text: &str) -> Result<Replayed, Problem> {
    if continuous::is_learned_function_text(text) {
        return Ok(match continuous::replay_text_any(text)? {
            continuous::AnyReplay::World(r) => Replayed::Tiles(Box::new(r)),
            continuous::AnyReplay::Gym(r) => Replayed::GymTiles(Box::new(r)),
        });
    }
    // One typed pass over the document; the world it names decides the replay.
    let document = evaluate::read(text)?;
    let params = &document.policy.env.params;
    let gymnasium = params.get("gymnasium").and_then(Value::as_bool) == Some(true);
    if !gymnasium {
        return evaluate::replay_grid(document).map(Replayed::Grid);
    }
    let params = params.clone();
    let count =
        |key: &str| params.get(key).and_then(Value::as_u64).and_then(|n| usize::try_from(n).ok());
    let start = |key: &str| params.get(key).and_then(Value::as_i64);
    let replay = evaluate::replay_document(document, |p| Listed::of(p))?;
    let spaces = match (
        count("observations"),
        start("observation_start"),
        count("actions"),
        start("action_start"),
    ) {
        (Some(observations), Some(observation_start), Some(actions), Some(action_start)) => {
            Spaces {
                name: replay.policy.env.name.clone(),
                observations,
                observation_start,
                actions,
                action_start,
            }
        }
        _ => {
            return Err(Problem::new(
                "its `env.params` lack the spaces of its gymnasium environment",
                "pass the policy.json that `hstl.train` wrote".to_string(),
            ));
        }
    };
    Ok(Replayed::Listed(replay, spaces))
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
        if let Some((agent, start)) = self.replayed.tiles() {
            let vars = self.replayed.state_vars();
            let values = state_values(state, &vars)?;
            let blocked = match &self.replayed {
                Replayed::Tiles(r) => hstl::gym::start(&r.world, &values)
                    .map(|_| hstl::gym::blocked(&r.world, &values))
                    .map_err(|p| problem_error(&p))?,
                _ => {
                    in_ranges(self.replayed.spec(), &vars, &values)?;
                    Vec::new()
                }
            };
            let mut runner = self.runner.lock().unwrap_or_else(|p| p.into_inner());
            let (action, _) = runner.stepper.act(agent, &values, &blocked);
            return Ok(start + action as i64);
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
        let start = match &self.replayed {
            Replayed::Listed(_, spaces) => spaces.action_start,
            _ => 0,
        };
        Ok(start + decision.action as i64)
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
                if given.name != spaces.name || given.params() != spaces.params() {
                    return Err(value_error(
                        format!(
                            "the policy was trained on {}; `env` is {}",
                            spaces.describe(),
                            given.describe()
                        ),
                        Some("pass the environment it was trained in".into()),
                    ));
                }
                let pyenv = PyEnv::new(env, valuation, given, &listed.spec)?;
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
                    return Err(e);
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
                let (agent, _) = self
                    .replayed
                    .tiles()
                    .ok_or_else(|| value_error("the policy holds no learned function", None))?;
                self.check_env(&described)?;
                let boxed = BoxEnv::new(env, valuation, described, spec)?;
                let (result, boxed) =
                    py.detach(move || (continuous::evaluate_in(spec, agent, &boxed, runs), boxed));
                if let Some(e) = boxed.take_error() {
                    return Err(e);
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

    /// Checks that a gymnasium environment's spaces are those the policy was trained with:
    /// for a world it holds, the world's bounds and actions; else the recorded spaces.
    fn check_env(&self, given: &hstl::gym::Described) -> PyResult<()> {
        let fits = match &self.replayed {
            Replayed::Tiles(r) => {
                let bounds = hstl::gym::bounds(&r.world);
                let n = ContinuousWorld::actions_of(&r.world).len();
                let same =
                    bounds.as_ref().is_some_and(|(lo, hi)| *lo == given.low && *hi == given.high);
                if same && n == given.actions && given.action_start == 0 {
                    return Ok(());
                }
                format!(
                    "world `{}` (a Box of {} components, Discrete({n}))",
                    r.world.name(),
                    bounds.map_or(0, |b| b.0.len())
                )
            }
            Replayed::GymTiles(r) => {
                if r.env.name == given.name && r.env.params() == given.params() {
                    return Ok(());
                }
                r.env.describe()
            }
            _ => return Ok(()),
        };
        Err(value_error(
            format!("the policy was trained on {fits}; `env` is {}", given.describe()),
            Some("pass the environment it was trained in (the same spaces and bounds)".into()),
        ))
    }
}

/// Checks a learned function's state against the ranges its spec declares (the tiling's).
fn in_ranges(spec: &TaskSpec, vars: &[String], values: &[f64]) -> PyResult<()> {
    if values.len() != vars.len() {
        return Err(value_error(
            format!(
                "a state of the policy has {} numbers ({}), not {}",
                vars.len(),
                vars.join(", "),
                values.len()
            ),
            Some("give the state variables' values in order, or a dict of them".into()),
        ));
    }
    let Some(t) = &spec.learn.tiles else { return Ok(()) };
    for (i, &x) in values.iter().enumerate() {
        let (Some(&lo), Some(&hi)) = (t.lo.get(i), t.hi.get(i)) else { continue };
        if !(x >= lo && x <= hi) {
            let num = hstl::runtime::plane::num;
            return Err(value_error(
                format!(
                    "`{}` = {} is outside its declared range {}..={}",
                    vars[i],
                    num(x),
                    num(lo),
                    num(hi)
                ),
                Some("give a state the policy was trained on".into()),
            ));
        }
    }
    Ok(())
}

/// A state's values as a lookup key (`-0` read as `0`).
fn key(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| (v + 0.0).to_bits()).collect()
}
