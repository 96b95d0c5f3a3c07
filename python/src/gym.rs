//! A gymnasium environment with `Discrete` observations as the learner's [`Env`]
//! ([`hstl::outside::DiscreteEnv`], which decides everything; this module makes its two
//! calls into Python, the GIL taken for each, so it is slower than a native world), and
//! one with a `Box` observation space as the approximate learner's world ([`BoxEnv`]).
//! Each `reset` seeds the Python environment with a seed drawn from the learner's one
//! generator. The first Python exception (in `reset`, `step`, or a bad observation)
//! stops the run: every later call returns at once, the caller stops at the end of the
//! episode and raises it.

use std::cell::{Cell, RefCell};

use hstl::outside::{Calls, DiscreteEnv, Failure};
use hstl::runtime::{EpisodeEnd, Rng, RngExt, TaskSpec, Value};
use numpy::PyArrayMethods;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

pub use hstl::outside::Spaces;

use crate::errors::{problem_error, value_error};
use crate::trace::state_values;

/// The learner's view of a gymnasium environment with `Discrete` spaces.
pub type PyEnv = DiscreteEnv<PyCalls>;

/// The calls of a gymnasium environment, into Python.
pub struct PyCalls {
    env: Py<PyAny>,
}

/// The adapter of `env`, whose observation `o` has the state `valuation(o)` (a mapping
/// from the spec's state variables to numbers, or numbers in their order); see
/// [`DiscreteEnv::new`] for what is checked.
pub fn py_env(
    env: &Bound<'_, PyAny>,
    valuation: &Bound<'_, PyAny>,
    spaces: Spaces,
    spec: &TaskSpec,
) -> PyResult<PyEnv> {
    let vars: Vec<String> = spec.state_vars.iter().map(|v| v.name.clone()).collect();
    let py = env.py();
    let calls = PyCalls { env: env.clone().unbind() };
    DiscreteEnv::new(calls, spaces, spec, |obs| {
        let state = valuation.call1((obs,)).map_err(|e| prefix(py, e, obs))?;
        state_values(&state, &vars).map_err(|e| prefix(py, e, obs))
    })
    .map_err(failure_error)
}

/// A run's failure as the Python exception to raise.
pub fn failure_error(f: Failure<PyErr>) -> PyErr {
    match f {
        Failure::Call(e) => e,
        Failure::Refused(p) => problem_error(&p),
    }
}

/// The integer observation `obs` that `env.CALL` gave.
fn observation(obs: &Bound<'_, PyAny>, call: &str) -> PyResult<i64> {
    obs.extract().map_err(|_| {
        value_error(
            format!("env.{call} gave the observation {}, not an integer", repr(obs)),
            Some("train on an environment whose observation space is `Discrete`".into()),
        )
    })
}

impl Calls for PyCalls {
    type Error = PyErr;

    fn reset(&self, seed: u64) -> PyResult<i64> {
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
            observation(&pair.get_item(0)?, "reset")
        })
    }

    fn step(&self, action: i64) -> PyResult<(i64, Option<EpisodeEnd>)> {
        Python::attach(|py| {
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
            let next = observation(&five.get_item(0)?, "step")?;
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
