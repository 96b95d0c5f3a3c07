//! A gymnasium environment with `Discrete` observations as the learner's `Env`
//! ([`hstl::outside::DiscreteEnv`], which decides everything; this module makes its two
//! calls into Python, the GIL taken for each, so it is slower than a native world), and
//! one with a `Box` observation space as the approximate learner's world ([`BoxEnv`]).
//! Each `reset` seeds the Python environment with a seed drawn from the learner's one
//! generator. The first Python exception (in `reset`, `step`, or a bad observation)
//! stops the run: every later call returns at once, the caller stops at the end of the
//! episode and raises it.

use hstl::outside::{BoxCalls, Calls, DiscreteEnv, Failure};
use hstl::runtime::{EpisodeEnd, TaskSpec};
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
        let state =
            valuation.call1((obs,)).map_err(|e| prefix(py, e, &format!("valuation({obs})")))?;
        state_values(&state, &vars).map_err(|e| prefix(py, e, &format!("valuation({obs})")))
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

/// `env.reset(seed=seed)`'s observation, its answer checked to be `(observation, info)`.
fn reset<'py>(env: &Bound<'py, PyAny>, seed: u64) -> PyResult<Bound<'py, PyAny>> {
    let kwargs = PyDict::new(env.py());
    kwargs.set_item("seed", seed)?;
    let out = env.call_method("reset", (), Some(&kwargs))?;
    let pair = out.cast::<PyTuple>().map_err(|_| {
        value_error(format!("env.reset gave {}, not (observation, info)", repr(&out)), None)
    })?;
    if pair.len() != 2 {
        return Err(value_error(
            format!("env.reset gave {} values, not (observation, info)", pair.len()),
            None,
        ));
    }
    pair.get_item(0)
}

/// `env.step(action)`'s answer, checked to be `(observation, reward, terminated,
/// truncated, info)`.
fn step<'py>(env: &Bound<'py, PyAny>, action: i64) -> PyResult<Bound<'py, PyTuple>> {
    let out = env.call_method1("step", (action,))?;
    let five = out.cast_into::<PyTuple>().map_err(|e| {
        value_error(
            format!(
                "env.step gave {}, not (observation, reward, terminated, truncated, info)",
                repr(&e.into_inner())
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
    Ok(five)
}

impl Calls for PyCalls {
    type Error = PyErr;

    fn reset(&self, seed: u64) -> PyResult<i64> {
        Python::attach(|py| observation(&reset(self.env.bind(py), seed)?, "reset"))
    }

    fn step(&self, action: i64) -> PyResult<(i64, Option<EpisodeEnd>)> {
        Python::attach(|py| {
            let five = step(self.env.bind(py), action)?;
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

/// `head: ` before an error's message (`valuation(OBS)`), keeping its type.
fn prefix(py: Python<'_>, e: PyErr, head: &str) -> PyErr {
    let text = format!("{head}: {}", e.value(py));
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
/// a [`World`](hstl::runtime::World) of the approximate learner
/// ([`hstl::outside::BoxEnv`], which checks every observation; its calls go into Python).
pub type BoxEnv = hstl::outside::BoxEnv<PyBoxCalls>;

/// The calls of a gymnasium environment with a `Box` observation space, into Python, and
/// its valuation.
pub struct PyBoxCalls {
    env: Py<PyAny>,
    valuation: Option<Py<PyAny>>,
    vars: Vec<String>,
}

/// The adapter of `env` (spaces as `described` records them) for `spec`, whose
/// observation `o` has the state `valuation(o)`, or the observation's components in the
/// spec's order when `valuation` is None.
pub fn box_env(
    env: &Bound<'_, PyAny>,
    valuation: Option<&Bound<'_, PyAny>>,
    described: hstl::gym::Described,
    spec: &TaskSpec,
) -> PyResult<BoxEnv> {
    let calls = PyBoxCalls {
        env: env.clone().unbind(),
        valuation: valuation.map(|v| v.clone().unbind()),
        vars: described.vars.clone(),
    };
    BoxEnv::new(calls, valuation.is_some(), described, spec).map_err(|p| problem_error(&p))
}

/// `obs` as a float64 array and its numbers; `call` names where it came from.
fn numbers(obs: &Bound<'_, PyAny>, call: &str) -> PyResult<(Py<PyAny>, Vec<f64>)> {
    let py = obs.py();
    let array = py.import("numpy")?.call_method1("asarray", (obs, "float64")).map_err(|_| {
        value_error(
            format!("{call} gave the observation {}, not numbers", repr(obs)),
            Some("train on an environment whose observation space is a `Box`".into()),
        )
    })?;
    let array = array.cast_into::<numpy::PyArrayDyn<f64>>().map_err(|_| {
        value_error(format!("{call} gave the observation {}, not numbers", repr(obs)), None)
    })?;
    let values: Vec<f64> = array.readonly().as_array().iter().copied().collect();
    Ok((array.into_any().unbind(), values))
}

impl BoxCalls for PyBoxCalls {
    type Error = PyErr;
    type Obs = Py<PyAny>;

    fn reset(&self, seed: u64, call: &str) -> PyResult<(Py<PyAny>, Vec<f64>)> {
        Python::attach(|py| numbers(&reset(self.env.bind(py), seed)?, call))
    }

    fn step(&self, action: i64, call: &str) -> PyResult<(Py<PyAny>, Vec<f64>, bool)> {
        Python::attach(|py| {
            let five = step(self.env.bind(py), action)?;
            let (obs, values) = numbers(&five.get_item(0)?, call)?;
            let ended = five.get_item(2)?.is_truthy()? || five.get_item(3)?.is_truthy()?;
            Ok((obs, values, ended))
        })
    }

    fn valuation(&self, obs: &Py<PyAny>, call: &str) -> Option<PyResult<Vec<f64>>> {
        let f = self.valuation.as_ref()?;
        Some(Python::attach(|py| {
            let given = f
                .bind(py)
                .call1((obs.bind(py),))
                .map_err(|e| prefix(py, e, &format!("valuation (after {call})")))?;
            state_values(&given, &self.vars)
        }))
    }
}
