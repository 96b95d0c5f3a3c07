//! `hstl.OnlineMonitor`.

use std::sync::Arc;

use hstl::monitor::{Dense, DenseLive, Online, OnlineState, TimeAxis};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};

use crate::dense;
use crate::errors::{trace_error, type_error};
use crate::spec::Spec;
use crate::trace::state_values;

/// An online monitor: states arrive one at a time, each step's robustness leaves as soon as
/// it is final. Made by `Spec.online(formula=None)`.
///
/// For a formula with a finite horizon `H` (`horizon`), the robustness at step `t` depends
/// on states `t` to `t + H` only, so it is final once state `t + H` has arrived: `update`
/// returns it then, as `(t, value)`. `finish()` ends the trace and returns the steps still
/// open, their windows clipped at the end of the trace exactly as `Spec.signal` clips
/// them; together they give every step of `Spec.signal`, value for value. Memory stays
/// `O(H)` whatever the trace's length.
///
/// For an unbounded formula (`horizon` is None) no value is final before the trace ends:
/// `update` returns None, and `provisional()` gives what the first open step would be if
/// the trace ended now (a running value, not a verdict).
///
/// It pickles and copies mid-trace (for worker processes, `copy.deepcopy`): by its spec,
/// formula and the states of the steps still open (at most `H`; every state of the trace
/// for an unbounded formula), with the states before them that its past-time operators
/// read (every state when a past window is unbounded, such as `once[0..]`), which the
/// copy replays.
///
/// On a dense-time spec (one with a `time` variable) rows arrive as `update(t, state)`:
/// `t` the row's stamp (an int stays whole: nanoseconds since the epoch are never rounded),
/// `state` a mapping from state variables to numbers, where a variable left out (or None,
/// or NaN) has no new sample, or a sequence of one number per state variable (NaN: no new
/// sample). `update` returns the change points `[(t, value), ...]` that row decided (each
/// value holds from its `t` until the next), at the latest once a row after `t + H`
/// arrives for a formula whose windows reach `H` ahead; `finish()` returns the rest up to
/// the last stamp. Together they are `Spec.signal`'s change points, bit for bit. Times are
/// in the time column's scale (int for whole-number stamps of 2^53 or more), or float
/// from the first stamp with `relative=True`. Memory is bounded by the windows (at most
/// `MAX_ONLINE_VALUES` values). A dense monitor deep-copies (`copy.deepcopy`) but does not
/// pickle yet.
#[pyclass(module = "hstl")]
pub struct OnlineMonitor {
    inner: Inner,
    spec: Py<Spec>,
    formula: Option<String>,
}

enum Inner {
    Discrete(Online),
    Dense { monitor: Arc<Dense>, live: DenseLive, relative: bool },
}

impl OnlineMonitor {
    pub fn new(inner: Online, spec: Py<Spec>, formula: Option<String>) -> OnlineMonitor {
        OnlineMonitor { inner: Inner::Discrete(inner), spec, formula }
    }

    pub fn dense(
        monitor: Arc<Dense>,
        live: DenseLive,
        relative: bool,
        spec: Py<Spec>,
        formula: Option<String>,
    ) -> OnlineMonitor {
        OnlineMonitor { inner: Inner::Dense { monitor, live, relative }, spec, formula }
    }

    fn discrete(&mut self, what: &str) -> PyResult<&mut Online> {
        match &mut self.inner {
            Inner::Discrete(o) => Ok(o),
            Inner::Dense { .. } => Err(type_error(
                format!("`{what}` is for discrete-time monitors; this one is dense-time"),
                None,
            )),
        }
    }

    /// Change points as Python `(t, value)` pairs in the monitor's time scale.
    fn points<'py>(
        py: Python<'py>,
        axis: TimeAxis,
        points: Vec<(f64, f64)>,
    ) -> PyResult<Bound<'py, PyList>> {
        let relative = axis.relative;
        let list = PyList::empty(py);
        for (t, v) in points {
            let t = if axis.origin.is_some() && !relative {
                match axis.whole(t) {
                    Some(n) => n.into_pyobject(py)?.into_any(),
                    None => return Err(dense::between_stamps(&axis.text(t))),
                }
            } else {
                axis.double(t).into_pyobject(py)?.into_any()
            };
            list.append((t, v))?;
        }
        Ok(list)
    }
}

#[pymethods]
impl OnlineMonitor {
    /// The monitor `__reduce__` describes: `spec.online(formula)`, then the states
    /// replayed after `skipped` steps.
    #[staticmethod]
    fn _restore(
        py: Python<'_>,
        spec: &Bound<'_, Spec>,
        formula: Option<String>,
        skipped: usize,
        states: Vec<f64>,
    ) -> PyResult<OnlineMonitor> {
        let mut inner = spec.get().online_of(formula.as_deref())?;
        inner.restore(&OnlineState { skipped, states }).map_err(|e| trace_error(py, &e))?;
        Ok(OnlineMonitor::new(inner, spec.clone().unbind(), formula))
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let this = slf.borrow();
        let Inner::Discrete(inner) = &this.inner else {
            return Err(PyTypeError::new_err(
                "a dense-time OnlineMonitor cannot be pickled yet\n  help: `copy.deepcopy` \
                 copies it; to move it to another process, send the rows since the last \
                 `finish()` and replay them",
            ));
        };
        let state = inner.snapshot();
        let args =
            (this.spec.clone_ref(slf.py()), this.formula.clone(), state.skipped, state.states)
                .into_pyobject(slf.py())?;
        Ok((slf.get_type().getattr("_restore")?, args))
    }

    /// Appends one state, a mapping from state variable names to numbers (or a sequence of
    /// numbers in the order of `state_vars`), and returns the verdict it completes,
    /// `(step, value)`, or None while no new step is final. A state with NaN or a missing
    /// variable raises and changes nothing.
    ///
    /// On a dense-time monitor: `update(t, state)` appends the row stamped `t` and returns
    /// the change points it decided, `[(t, value), ...]` (possibly empty). A row refused
    /// for its stamp or its values changes nothing.
    #[pyo3(signature = (state, row=None))]
    fn update<'py>(
        &mut self,
        py: Python<'py>,
        state: &Bound<'py, PyAny>,
        row: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        match &mut self.inner {
            Inner::Discrete(inner) => {
                if row.is_some() {
                    return Err(type_error(
                        "`update` of a discrete-time monitor takes one state",
                        Some("pass the state alone: steps have no time stamps".into()),
                    ));
                }
                let values = state_values(state, inner.state_vars())?;
                let verdict = inner.push(&values).map_err(|e| trace_error(py, &e))?;
                verdict.map(|v| (v.step, v.value)).into_pyobject(py).map(|o| o.into_any())
            }
            Inner::Dense { monitor, live, relative } => {
                let Some(row) = row else {
                    return Err(type_error(
                        format!(
                            "`update` of a dense-time monitor takes the row's time stamp and \
                             its state: `update(t, state)`; `{}` is the time variable",
                            monitor.time_var()
                        ),
                        None,
                    ));
                };
                let stamp = dense::stamp(state)?;
                let cells = dense::cells(row, monitor.state_vars())?;
                let decided = live
                    .push(monitor, stamp, &cells)
                    .map_err(|p| dense::problem_error(&p, monitor, Some(&live.axis(false))))?;
                Ok(Self::points(py, live.axis(*relative), decided)?.into_any())
            }
        }
    }

    /// The value the first step without a verdict would have if the trace ended now;
    /// None when every step so far has its verdict. Not final: later states may change it.
    /// Discrete-time monitors only.
    fn provisional(&mut self) -> PyResult<Option<f64>> {
        Ok(self.discrete("provisional")?.provisional())
    }

    /// Ends the trace and returns the verdicts of every step still open, `[(step, value),
    /// ...]` (a dense-time monitor: the change points up to the last stamp, `[(t, value),
    /// ...]`). The monitor then starts a new trace.
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        match &mut self.inner {
            Inner::Discrete(inner) => {
                let rows: Vec<(usize, f64)> =
                    inner.finish().into_iter().map(|v| (v.step, v.value)).collect();
                PyList::new(py, rows)
            }
            Inner::Dense { monitor, live, relative } => {
                // The axis of the trace that ends (`finish` starts a new one).
                let (axis, plain) = (live.axis(*relative), live.axis(false));
                let rest = live
                    .finish(monitor)
                    .map_err(|p| dense::problem_error(&p, monitor, Some(&plain)))?;
                Self::points(py, axis, rest)
            }
        }
    }

    /// The horizon `H`: a step's value is final `H` states after it. None when unbounded
    /// (and for a dense-time monitor, whose reach is a time: see `Spec.signal`).
    #[getter]
    fn horizon(&self) -> Option<usize> {
        match &self.inner {
            Inner::Discrete(inner) => inner.horizon(),
            Inner::Dense { .. } => None,
        }
    }

    /// The number of states (rows) given since creation or the last `finish()`.
    #[getter]
    fn steps(&self) -> usize {
        match &self.inner {
            Inner::Discrete(inner) => inner.steps(),
            Inner::Dense { live, .. } => live.rows(),
        }
    }

    /// The state variables, in the order a sequence state lists them.
    #[getter]
    fn state_vars(&self) -> Vec<String> {
        match &self.inner {
            Inner::Discrete(inner) => inner.state_vars().to_vec(),
            Inner::Dense { monitor, .. } => monitor.state_vars().to_vec(),
        }
    }

    /// The time variable of a dense-time monitor; None for a discrete-time one.
    #[getter]
    fn time_var(&self) -> Option<String> {
        match &self.inner {
            Inner::Discrete(_) => None,
            Inner::Dense { monitor, .. } => Some(monitor.time_var().to_string()),
        }
    }

    /// A copy mid-trace.
    fn __deepcopy__(&self, py: Python<'_>, _memo: &Bound<'_, PyDict>) -> OnlineMonitor {
        let inner = match &self.inner {
            Inner::Discrete(o) => Inner::Discrete(o.clone()),
            Inner::Dense { monitor, live, relative } => Inner::Dense {
                monitor: Arc::clone(monitor),
                live: live.clone(),
                relative: *relative,
            },
        };
        OnlineMonitor { inner, spec: self.spec.clone_ref(py), formula: self.formula.clone() }
    }

    fn __copy__(&self, py: Python<'_>) -> OnlineMonitor {
        self.__deepcopy__(py, &PyDict::new(py))
    }

    fn __repr__(&self) -> String {
        match &self.inner {
            Inner::Discrete(inner) => {
                let h = inner.horizon().map_or("unbounded".to_string(), |h| h.to_string());
                format!("<hstl.OnlineMonitor horizon {h}, {} steps>", inner.steps())
            }
            Inner::Dense { monitor, live, .. } => format!(
                "<hstl.OnlineMonitor dense time `{}`, {} rows>",
                monitor.time_var(),
                live.rows()
            ),
        }
    }
}
