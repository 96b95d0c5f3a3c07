//! A gymnasium environment with `Discrete` observations as the learner's [`Env`]: every
//! call goes back into Python (the GIL taken for it), so it is slower than a native world.
//!
//! The learner (and a replay) only ever steps from the state the environment is in, after
//! `reset`. Each `reset` seeds the Python environment with a seed drawn from the learner's
//! one generator, so the same seed gives the same episodes and the same Q-tables whatever
//! the environment did before. A step that reports `terminated` or `truncated` ends the
//! learner's episode there ([`Env::episode_end`]): the next one starts with a reset, so
//! every step the learner counts is a call of `env.step`; a terminal state is valued as
//! one the robot stays in, a truncated one as usual. (A replay that steps on leaves
//! the robot in that state, without calling Python, until it resets.) The first Python exception (in `reset`, `step`,
//! or a bad observation) stops the run: every later call returns at once, the caller
//! stops at the end of the episode and raises it.

use std::cell::{Cell, RefCell};
use std::collections::HashMap;

use hstl::runtime::{Env, EpisodeEnd, Rng, RngExt, TaskSpec, Value, json};
use numpy::PyArrayMethods;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::errors::value_error;
use crate::trace::state_values;

/// The most observations a gymnasium environment may have for tabular learning (the
/// largest grid world's cells).
pub const MAX_OBSERVATIONS: usize = hstl::runtime::env::MAX_GRID_CELLS;
/// The most Q-values of one flat table, observations times actions (the largest grid
/// world's).
pub const MAX_FLAT_VALUES: usize = 4 * MAX_OBSERVATIONS;

/// What the package knows of a gymnasium environment's spaces (read by `hstl._train`).
#[derive(Clone, Debug)]
pub struct Spaces {
    /// The environment's id (`spec.id`), or its class name.
    pub name: String,
    /// `observation_space.n` and `.start`.
    pub observations: usize,
    pub observation_start: i64,
    /// `action_space.n` and `.start`.
    pub actions: usize,
    pub action_start: i64,
}

/// The learner's view of a gymnasium environment.
pub struct PyEnv {
    env: Py<PyAny>,
    spaces: Spaces,
    vars: Vec<String>,
    /// `values[s * vars + i]`: state variable `i` in observation `start + s`.
    values: Vec<f64>,
    current: Cell<usize>,
    /// The last step terminated or truncated: stay until the next reset.
    absorbed: Cell<bool>,
    /// How the last step ended the episode, if it did.
    end: Cell<Option<EpisodeEnd>>,
    error: RefCell<Option<PyErr>>,
}

impl Spaces {
    /// ``` `FrozenLake-v1` (Discrete(16) observations, Discrete(4) actions) ```.
    pub fn describe(&self) -> String {
        let space = |n: usize, start: i64| match start {
            0 => format!("Discrete({n})"),
            s => format!("Discrete({n}, start={s})"),
        };
        format!(
            "`{}` ({} observations, {} actions)",
            self.name,
            space(self.observations, self.observation_start),
            space(self.actions, self.action_start)
        )
    }

    /// `policy.json`'s `env.params` for an environment with these spaces.
    pub fn params(&self) -> Value {
        json!({
            "gymnasium": true,
            "observations": self.observations,
            "observation_start": self.observation_start,
            "actions": self.actions,
            "action_start": self.action_start,
        })
    }
}

impl PyEnv {
    /// The adapter of `env`, whose observation `o` has the state `valuation(o)` (a mapping
    /// from the spec's state variables to numbers, or numbers in their order). Calls
    /// `valuation` once per observation, and checks every value against the spec's domain.
    pub fn new(
        env: &Bound<'_, PyAny>,
        valuation: &Bound<'_, PyAny>,
        spaces: Spaces,
        spec: &TaskSpec,
    ) -> PyResult<PyEnv> {
        let n = spaces.observations;
        if n == 0 || n > MAX_OBSERVATIONS {
            return Err(value_error(
                format!(
                    "the environment has {n} observations; the learner's tables take 1 to {MAX_OBSERVATIONS}"
                ),
                Some("give the environment a smaller `Discrete` observation space".into()),
            ));
        }
        if spaces.actions == 0 || n.saturating_mul(spaces.actions) > MAX_FLAT_VALUES {
            return Err(value_error(
                format!(
                    "{n} observations and {} actions are more than the {MAX_FLAT_VALUES} Q-values a flat table may have",
                    spaces.actions
                ),
                Some("give the environment fewer observations or actions".into()),
            ));
        }
        let vars: Vec<String> = spec.state_vars.iter().map(|v| v.name.clone()).collect();
        let mut values = Vec::with_capacity(n * vars.len());
        let mut seen: HashMap<Vec<u64>, i64> = HashMap::with_capacity(n);
        for s in 0..n {
            let obs = spaces.observation_start + s as i64;
            let state = valuation.call1((obs,)).map_err(|e| prefix(env.py(), e, obs))?;
            let row = state_values(&state, &vars).map_err(|e| prefix(env.py(), e, obs))?;
            if row.len() != vars.len() {
                return Err(value_error(
                    format!(
                        "valuation({obs}) gives {} values; the spec has {} state variables",
                        row.len(),
                        vars.len()
                    ),
                    Some(format!("return a dict of {}", vars.join(", "))),
                ));
            }
            for (v, &x) in spec.state_vars.iter().zip(&row) {
                let fits = v.domain.as_ref().is_some_and(|d| {
                    x.fract() == 0.0 && x >= *d.start() as f64 && x <= *d.end() as f64
                });
                if !fits {
                    let domain = v
                        .domain
                        .as_ref()
                        .map_or("no range".to_string(), |d| format!("{}..={}", d.start(), d.end()));
                    return Err(value_error(
                        format!(
                            "valuation({obs}) gives `{}` = {x}, outside its declared domain {domain}",
                            v.name
                        ),
                        Some("declare the range the valuation gives, or fix the valuation".into()),
                    ));
                }
            }
            let key: Vec<u64> = row.iter().map(|x| (x + 0.0).to_bits()).collect();
            if let Some(other) = seen.insert(key, obs) {
                return Err(value_error(
                    format!("observations {other} and {obs} have the same valuation"),
                    Some(
                        "policy.json names states by their values: give each observation its own, \
                         such as a state variable `s: int` that is the observation itself"
                            .into(),
                    ),
                ));
            }
            values.extend(row);
        }
        Ok(PyEnv {
            env: env.clone().unbind(),
            spaces,
            vars,
            values,
            current: Cell::new(0),
            absorbed: Cell::new(false),
            end: Cell::new(None),
            error: RefCell::new(None),
        })
    }

    /// The first Python error of the run, if any (taken: a later call sees none).
    pub fn take_error(&self) -> Option<PyErr> {
        self.error.borrow_mut().take()
    }

    /// Whether a Python error stopped the run.
    pub fn failed(&self) -> bool {
        self.error.borrow().is_some()
    }

    fn fail(&self, e: PyErr) {
        let mut slot = self.error.borrow_mut();
        if slot.is_none() {
            *slot = Some(e);
        }
    }

    /// The state index of an observation, checked against the space.
    fn index_of(&self, obs: &Bound<'_, PyAny>, call: &str) -> PyResult<usize> {
        let Spaces { observations: n, observation_start: start, .. } = self.spaces;
        let value: i64 = obs.extract().map_err(|_| {
            value_error(
                format!("env.{call} gave the observation {}, not an integer", repr(obs)),
                Some("train on an environment whose observation space is `Discrete`".into()),
            )
        })?;
        match value.checked_sub(start).and_then(|i| usize::try_from(i).ok()).filter(|&i| i < n) {
            Some(i) => Ok(i),
            None => Err(value_error(
                format!(
                    "env.{call} gave the observation {value}, outside Discrete({n}, start={start})"
                ),
                None,
            )),
        }
    }

    fn call_reset(&self, seed: u64) -> PyResult<usize> {
        Python::attach(|py| {
            let kwargs = PyDict::new(py);
            kwargs.set_item("seed", seed)?;
            let out = self.env.bind(py).call_method("reset", (), Some(&kwargs))?;
            let pair = out.cast::<PyTuple>().map_err(|_| {
                value_error(format!("env.reset gave {}, not (observation, info)", repr(&out)), None)
            })?;
            if pair.len() != 2 {
                return Err(value_error(
                    format!("env.reset gave {} values, not (observation, info)", pair.len()),
                    None,
                ));
            }
            self.index_of(&pair.get_item(0)?, "reset")
        })
    }

    fn call_step(&self, action: usize) -> PyResult<(usize, Option<EpisodeEnd>)> {
        Python::attach(|py| {
            let action = self.spaces.action_start + action as i64;
            let out = self.env.bind(py).call_method1("step", (action,))?;
            let five = out.cast::<PyTuple>().map_err(|_| {
                value_error(
                    format!(
                        "env.step gave {}, not (observation, reward, terminated, truncated, info)",
                        repr(&out)
                    ),
                    None,
                )
            })?;
            if five.len() != 5 {
                return Err(value_error(
                    format!(
                        "env.step gave {} values, not (observation, reward, terminated, truncated, info)",
                        five.len()
                    ),
                    None,
                ));
            }
            let next = self.index_of(&five.get_item(0)?, "step")?;
            let end = if five.get_item(2)?.is_truthy()? {
                Some(EpisodeEnd::Terminated)
            } else if five.get_item(3)?.is_truthy()? {
                Some(EpisodeEnd::Truncated)
            } else {
                None
            };
            Ok((next, end))
        })
    }
}

impl Env for PyEnv {
    type State = usize;

    fn name(&self) -> &str {
        &self.spaces.name
    }

    fn params(&self) -> Value {
        self.spaces.params()
    }

    fn state_vars(&self) -> Vec<String> {
        self.vars.clone()
    }

    fn actions(&self) -> Vec<String> {
        (0..self.spaces.actions)
            .map(|a| (self.spaces.action_start + a as i64).to_string())
            .collect()
    }

    fn num_states(&self) -> usize {
        self.spaces.observations
    }

    fn index(&self, state: &usize) -> usize {
        *state
    }

    fn state(&self, index: usize) -> Option<usize> {
        (index < self.spaces.observations).then_some(index)
    }

    fn valuation(&self, state: &usize, out: &mut Vec<f64>) {
        out.clear();
        let k = self.vars.len();
        if let Some(row) = self.values.get(state * k..(state + 1) * k) {
            out.extend_from_slice(row);
        }
    }

    fn reset(&self, rng: &mut Rng) -> usize {
        // Drawn even after a failure, so that the generator's draws do not depend on it.
        let seed: u64 = rng.random();
        if self.failed() {
            return self.current.get();
        }
        match self.call_reset(seed) {
            Ok(s) => {
                self.current.set(s);
                self.absorbed.set(false);
                self.end.set(None);
            }
            Err(e) => self.fail(e),
        }
        self.current.get()
    }

    fn episode_end(&self) -> Option<EpisodeEnd> {
        self.end.get()
    }

    fn step(&self, state: &usize, action: usize, _rng: &mut Rng) -> usize {
        if self.failed() || self.absorbed.get() || action >= self.spaces.actions {
            return *state;
        }
        if *state != self.current.get() {
            self.fail(value_error(
                format!(
                    "the learner stepped from state {state}, but the environment is in state {}",
                    self.current.get()
                ),
                None,
            ));
            return *state;
        }
        match self.call_step(action) {
            Ok((next, end)) => {
                self.current.set(next);
                self.absorbed.set(end.is_some());
                self.end.set(end);
            }
            Err(e) => self.fail(e),
        }
        self.current.get()
    }
}

/// `valuation(OBS): ` before an error's message, keeping its type.
fn prefix(py: Python<'_>, e: PyErr, obs: i64) -> PyErr {
    let text = format!("valuation({obs}): {}", e.value(py));
    let kind = e.get_type(py);
    match kind.call1((text,)) {
        Ok(v) => PyErr::from_value(v),
        Err(_) => e,
    }
}

fn repr(obj: &Bound<'_, PyAny>) -> String {
    obj.repr().map_or_else(|_| "?".to_string(), |r| r.to_string())
}

/// A gymnasium environment with a bounded `Box` observation space and `Discrete` actions as
/// a [`World`](hstl::runtime::World) of the approximate learner: its state is the
/// valuation of the last observation. Every call goes back into Python (the GIL taken for
/// it).
///
/// Each `reset` seeds the Python environment with a seed drawn from the learner's one
/// generator, as [`PyEnv`] does. Every observation is checked: its shape, that each
/// component is a finite number inside the `Box`, and that the valuation gives each state
/// variable a finite value inside the range the spec declares (the tiling's). A step that
/// reports `terminated` or `truncated` leaves the robot in that state, without calling
/// Python, until the learner's next episode resets it. The first Python exception stops
/// the run: later calls return at once, and the caller raises it.
pub struct BoxEnv {
    env: Py<PyAny>,
    valuation: Option<Py<PyAny>>,
    described: hstl::gym::Described,
    /// The spec's declared range of each state variable.
    lo: Vec<f64>,
    hi: Vec<f64>,
    current: RefCell<Vec<f64>>,
    absorbed: Cell<bool>,
    /// `env.step` calls so far, for messages.
    steps: Cell<u64>,
    error: RefCell<Option<PyErr>>,
}

impl BoxEnv {
    /// The adapter of `env` (spaces as `described` records them) for `spec`, whose
    /// observation `o` has the state `valuation(o)`, or the observation's components in
    /// the spec's order when `valuation` is None.
    pub fn new(
        env: &Bound<'_, PyAny>,
        valuation: Option<&Bound<'_, PyAny>>,
        described: hstl::gym::Described,
        spec: &TaskSpec,
    ) -> PyResult<BoxEnv> {
        let vars = &described.vars;
        if valuation.is_none() && described.low.len() != vars.len() {
            return Err(value_error(
                format!(
                    "the observation has {} components and spec `{}` {} state variables ({}), so \
                     they cannot be read in order",
                    described.low.len(),
                    spec.name,
                    vars.len(),
                    vars.join(", ")
                ),
                Some(format!(
                    "pass valuation=, a function from an observation to the state variables, \
                     such as `lambda o: {{{}}}`",
                    vars.iter()
                        .enumerate()
                        .map(|(i, v)| format!("\"{v}\": o[{i}]"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            ));
        }
        let (lo, hi) = match &spec.learn.tiles {
            Some(t) => (t.lo.clone(), t.hi.clone()),
            None => (vec![f64::NEG_INFINITY; vars.len()], vec![f64::INFINITY; vars.len()]),
        };
        Ok(BoxEnv {
            env: env.clone().unbind(),
            valuation: valuation.map(|v| v.clone().unbind()),
            described,
            lo,
            hi,
            current: RefCell::new(Vec::new()),
            absorbed: Cell::new(false),
            steps: Cell::new(0),
            error: RefCell::new(None),
        })
    }

    /// The spaces as `policy.json` records them.
    pub fn described(&self) -> &hstl::gym::Described {
        &self.described
    }

    /// The first Python error of the run, if any (taken: a later call sees none).
    pub fn take_error(&self) -> Option<PyErr> {
        self.error.borrow_mut().take()
    }

    /// Whether a Python error stopped the run.
    pub fn failed(&self) -> bool {
        self.error.borrow().is_some()
    }

    fn fail(&self, e: PyErr) {
        let mut slot = self.error.borrow_mut();
        if slot.is_none() {
            *slot = Some(e);
        }
    }

    /// The state of an observation, every number checked; `call` names where it came from.
    pub fn state_of(&self, obs: &Bound<'_, PyAny>, call: &str) -> PyResult<Vec<f64>> {
        let py = obs.py();
        let d = &self.described;
        let array =
            py.import("numpy")?.call_method1("asarray", (obs, "float64")).map_err(|_| {
                value_error(
                    format!("{call} gave the observation {}, not numbers", repr(obs)),
                    Some("train on an environment whose observation space is a `Box`".into()),
                )
            })?;
        let array = array.cast_into::<numpy::PyArrayDyn<f64>>().map_err(|_| {
            value_error(format!("{call} gave the observation {}, not numbers", repr(obs)), None)
        })?;
        let values: Vec<f64> = array.readonly().as_array().iter().copied().collect();
        if values.len() != d.low.len() {
            return Err(value_error(
                format!(
                    "{call} gave an observation of {} components; its `Box` has {}",
                    values.len(),
                    d.low.len()
                ),
                Some("give the environment an observation space that its observations fit".into()),
            ));
        }
        for (i, &v) in values.iter().enumerate() {
            if !(v >= d.low[i] && v <= d.high[i]) {
                let num = hstl::runtime::plane::num;
                return Err(value_error(
                    format!(
                        "{call} gave an observation whose component {i} is {}, outside its `Box` \
                         [{}, {}]",
                        num(v),
                        num(d.low[i]),
                        num(d.high[i])
                    ),
                    Some(
                        "the learner tiles the `Box`: bound the observation space so that it \
                         holds every observation (or clip the observations)"
                            .into(),
                    ),
                ));
            }
        }
        let state = match &self.valuation {
            None => values,
            Some(f) => {
                let given = f.bind(py).call1((array,)).map_err(|e| {
                    let text = format!("valuation (after {call}): {}", e.value(py));
                    match e.get_type(py).call1((text,)) {
                        Ok(v) => PyErr::from_value(v),
                        Err(_) => e,
                    }
                })?;
                let row = state_values(&given, &d.vars)?;
                if row.len() != d.vars.len() {
                    return Err(value_error(
                        format!(
                            "valuation gives {} values; the spec has {} state variables",
                            row.len(),
                            d.vars.len()
                        ),
                        Some(format!("return a dict of {}", d.vars.join(", "))),
                    ));
                }
                row
            }
        };
        for (i, &x) in state.iter().enumerate() {
            if !(x >= self.lo[i] && x <= self.hi[i]) {
                let num = hstl::runtime::plane::num;
                return Err(value_error(
                    format!(
                        "after {call}, `{}` = {} is outside its declared range {}..={}",
                        d.vars[i],
                        num(x),
                        num(self.lo[i]),
                        num(self.hi[i])
                    ),
                    Some("declare the range the observations take, or fix the valuation".into()),
                ));
            }
        }
        Ok(state)
    }

    fn call_reset(&self, seed: u64) -> PyResult<Vec<f64>> {
        Python::attach(|py| {
            let kwargs = PyDict::new(py);
            kwargs.set_item("seed", seed)?;
            let out = self.env.bind(py).call_method("reset", (), Some(&kwargs))?;
            let pair = out.cast::<PyTuple>().map_err(|_| {
                value_error(format!("env.reset gave {}, not (observation, info)", repr(&out)), None)
            })?;
            if pair.len() != 2 {
                return Err(value_error(
                    format!("env.reset gave {} values, not (observation, info)", pair.len()),
                    None,
                ));
            }
            self.state_of(&pair.get_item(0)?, "env.reset")
        })
    }

    fn call_step(&self, action: usize) -> PyResult<(Vec<f64>, bool)> {
        Python::attach(|py| {
            let action = self.described.action_start + action as i64;
            let out = self.env.bind(py).call_method1("step", (action,))?;
            let five = out.cast::<PyTuple>().ok().filter(|t| t.len() == 5).ok_or_else(|| {
                value_error(
                    format!(
                        "env.step gave {}, not (observation, reward, terminated, truncated, info)",
                        repr(&out)
                    ),
                    None,
                )
            })?;
            self.steps.set(self.steps.get() + 1);
            let call = format!("env.step (call {})", self.steps.get());
            let next = self.state_of(&five.get_item(0)?, &call)?;
            let ended = five.get_item(2)?.is_truthy()? || five.get_item(3)?.is_truthy()?;
            Ok((next, ended))
        })
    }
}

impl hstl::runtime::World for BoxEnv {
    type State = Vec<f64>;

    fn name(&self) -> &str {
        &self.described.name
    }

    fn params(&self) -> Value {
        self.described.params()
    }

    fn state_vars(&self) -> Vec<String> {
        self.described.vars.clone()
    }

    fn actions(&self) -> Vec<String> {
        hstl::runtime::World::actions(&self.described)
    }

    fn valuation(&self, state: &Vec<f64>, out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(state);
    }

    fn reset(&self, rng: &mut Rng) -> Vec<f64> {
        // Drawn even after a failure, so that the generator's draws do not depend on it.
        let seed: u64 = rng.random();
        if !self.failed() {
            match self.call_reset(seed) {
                Ok(s) => {
                    *self.current.borrow_mut() = s;
                    self.absorbed.set(false);
                }
                Err(e) => self.fail(e),
            }
        }
        self.current_or_zeros()
    }

    fn step(&self, state: &Vec<f64>, action: usize, _rng: &mut Rng) -> Vec<f64> {
        if self.failed() || self.absorbed.get() || action >= self.described.actions {
            return state.clone();
        }
        if *state != *self.current.borrow() {
            self.fail(value_error(
                "the learner stepped from a state the environment is not in",
                None,
            ));
            return state.clone();
        }
        match self.call_step(action) {
            Ok((next, ended)) => {
                *self.current.borrow_mut() = next;
                self.absorbed.set(ended);
            }
            Err(e) => self.fail(e),
        }
        self.current_or_zeros()
    }
}

impl BoxEnv {
    /// The current state; zeros inside the ranges before the first reset succeeded.
    fn current_or_zeros(&self) -> Vec<f64> {
        let current = self.current.borrow();
        if current.len() == self.described.vars.len() {
            current.clone()
        } else {
            self.lo.iter().map(|&l| if l.is_finite() { l } else { 0.0 }).collect()
        }
    }
}
