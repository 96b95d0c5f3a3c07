//! `hstl.OnlineMonitor`.

use std::sync::Arc;

use hstl::monitor::{
    Dense, DenseLive, DenseLiveState, Front, Online, OnlineState, Stamp, TimeAxis, Windows,
};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyTuple};

use crate::dense;
use crate::errors::{trace_error, type_error, value_error};
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
/// `MAX_ONLINE_VALUES` values). Over `windows="complete"` a change point comes once it
/// also lies before the complete end of the rows so far, and `finish()` ends with
/// `(t, nan)` where the undetermined times start.
///
/// A dense monitor pickles and copies mid-trace too: by its spec, formula, settings and
/// its operators' state (every window's pieces and deques, a window's worth each, and the
/// change points decided but not yet returned), which the copy continues from bit for bit.
/// A pickled state that was cut short or changed is refused with a `ValueError` saying
/// what does not fit.
#[pyclass(module = "hstl")]
pub struct OnlineMonitor {
    inner: Inner,
    /// The `hstl.Spec` it monitors, held for pickling only: a restored monitor is made by
    /// calling its `online` as a user would, so this module names no `Spec` (and `spec`,
    /// which makes monitors, is the one that imports this one).
    spec: Py<PyAny>,
    formula: Option<String>,
}

enum Inner {
    Discrete(Online, Windows),
    Dense { monitor: Arc<Dense>, live: DenseLive },
}

/// `windows=` as written.
fn windows_name(w: Windows) -> &'static str {
    match w {
        Windows::Clipped => "clipped",
        Windows::Complete => "complete",
    }
}

/// Field `key` of a pickled dense monitor's state, or a `ValueError` naming it and what it
/// should be.
fn field<'py, T: for<'a> FromPyObject<'a, 'py>>(
    state: &Bound<'py, PyDict>,
    key: &str,
    what: &str,
) -> PyResult<T> {
    let bad = |found: String| {
        value_error(
            format!("the pickled monitor state's `{key}` is {found}, not {what}"),
            Some(
                "pickle the monitor again from a running one; a state changed by hand is refused"
                    .into(),
            ),
        )
    };
    let Some(v) = state.get_item(key)? else { return Err(bad("missing".to_string())) };
    v.extract::<T>()
        .map_err(|_| bad(v.repr().map_or_else(|_| "unreadable".to_string(), |r| r.to_string())))
}

/// A new monitor of `spec` (an `hstl.Spec`), made by its `online` as a user makes one:
/// what a pickled monitor is restored into.
fn made_by<'py>(
    spec: &Bound<'py, PyAny>,
    formula: Option<&str>,
    windows: Windows,
) -> PyResult<Bound<'py, OnlineMonitor>> {
    let kwargs = PyDict::new(spec.py());
    kwargs.set_item("windows", windows_name(windows))?;
    let made = spec.call_method("online", (formula,), Some(&kwargs))?;
    made.cast_into::<OnlineMonitor>().map_err(|e| {
        type_error(
            format!("`spec.online` gave {}, not an `hstl.OnlineMonitor`", e.into_inner()),
            Some("restore a pickled monitor with the `hstl.Spec` it was pickled with".into()),
        )
    })
}

impl OnlineMonitor {
    pub fn new(
        inner: Online,
        windows: Windows,
        spec: Py<PyAny>,
        formula: Option<String>,
    ) -> OnlineMonitor {
        OnlineMonitor { inner: Inner::Discrete(inner, windows), spec, formula }
    }

    pub fn dense(
        monitor: Arc<Dense>,
        live: DenseLive,
        spec: Py<PyAny>,
        formula: Option<String>,
    ) -> OnlineMonitor {
        OnlineMonitor { inner: Inner::Dense { monitor, live }, spec, formula }
    }

    fn discrete(&mut self, what: &str) -> PyResult<&mut Online> {
        match &mut self.inner {
            Inner::Discrete(o, _) => Ok(o),
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
    /// The monitor `__reduce__` describes: `spec.online(formula, windows=windows)`, then
    /// the states replayed after `skipped` steps.
    #[staticmethod]
    #[pyo3(signature = (spec, formula, skipped, states, windows="clipped"))]
    fn _restore<'py>(
        spec: &Bound<'py, PyAny>,
        formula: Option<String>,
        skipped: usize,
        states: Vec<f64>,
        windows: &str,
    ) -> PyResult<Bound<'py, OnlineMonitor>> {
        let windows =
            Windows::parse(windows).map_err(|e| value_error(e.to_string(), Some(e.help())))?;
        let made = made_by(spec, formula.as_deref(), windows)?;
        {
            let mut this = made.borrow_mut();
            let inner = this.discrete("a discrete-time monitor's pickled state").map_err(|_| {
                value_error(
                    "the pickled monitor state is a discrete-time monitor's, and its spec is \
                     dense-time",
                    Some("pickle the monitor again from a running one".into()),
                )
            })?;
            inner
                .restore(&OnlineState { skipped, states })
                .map_err(|e| trace_error(spec.py(), &e))?;
        }
        Ok(made)
    }

    /// The dense-time monitor `__reduce__` describes: `spec.online(formula)` restored from
    /// `state`, a dict of the facade's plain data (every field checked).
    #[staticmethod]
    fn _restore_dense<'py>(
        spec: &Bound<'py, PyAny>,
        formula: Option<String>,
        state: &Bound<'py, PyDict>,
    ) -> PyResult<Bound<'py, OnlineMonitor>> {
        let made = made_by(spec, formula.as_deref(), Windows::Clipped)?;
        let monitor = match &made.borrow().inner {
            Inner::Dense { monitor, .. } => Arc::clone(monitor),
            Inner::Discrete(..) => {
                return Err(value_error(
                    "the pickled monitor state is a dense-time monitor's, and its spec is \
                     discrete-time",
                    Some("pickle the monitor again from a running one".into()),
                ));
            }
        };
        let windows: String = field(state, "windows", "\"clipped\" or \"complete\"")?;
        let windows = Windows::parse(&windows).map_err(|e| {
            value_error(format!("the pickled monitor state's `windows`: {e}"), Some(e.help()))
        })?;
        let last = match state.get_item("last")? {
            Some(v) if !v.is_none() => Some(dense::stamp(&v).map_err(|e| {
                value_error(
                    format!("the pickled monitor state's `last` stamp: {e}"),
                    Some("pickle the monitor again from a running one".into()),
                )
            })?),
            _ => None,
        };
        let bytes: Vec<u8> = field(state, "monitor", "bytes")?;
        let saved = DenseLiveState {
            windows,
            relative: field(state, "relative", "a bool")?,
            max_gap: field(state, "max_gap", "a string or None")?,
            limit: field(state, "limit", "a count of values")?,
            rows: field(state, "rows", "a count of rows")?,
            last,
            t0: field(state, "t0", "a number")?,
            held: field(state, "held", "a list of (time, value) pairs")?,
            stopped: field(state, "stopped", "a row or None")?,
            monitor: bytes,
        };
        let live = DenseLive::restore(&monitor, &saved, Front::Python)
            .map_err(|p| dense::problem_error(&p, &monitor, None))?;
        made.borrow_mut().inner = Inner::Dense { monitor, live };
        Ok(made)
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let this = slf.borrow();
        let spec = this.spec.clone_ref(py);
        match &this.inner {
            Inner::Discrete(inner, windows) => {
                let state = inner.snapshot();
                let args = (
                    spec,
                    this.formula.clone(),
                    state.skipped,
                    state.states,
                    windows_name(*windows),
                )
                    .into_pyobject(py)?;
                Ok((slf.get_type().getattr("_restore")?, args))
            }
            Inner::Dense { live, .. } => {
                let s = live.snapshot();
                let d = PyDict::new(py);
                d.set_item("windows", windows_name(s.windows))?;
                d.set_item("relative", s.relative)?;
                d.set_item("max_gap", s.max_gap)?;
                d.set_item("limit", s.limit)?;
                d.set_item("rows", s.rows)?;
                match s.last {
                    Some(Stamp::Int(n)) => d.set_item("last", n)?,
                    Some(Stamp::Real(t)) => d.set_item("last", t)?,
                    None => d.set_item("last", py.None())?,
                }
                d.set_item("t0", s.t0)?;
                d.set_item("held", s.held)?;
                d.set_item("stopped", s.stopped)?;
                d.set_item("monitor", PyBytes::new(py, &s.monitor))?;
                let args = (spec, this.formula.clone(), d).into_pyobject(py)?;
                Ok((slf.get_type().getattr("_restore_dense")?, args))
            }
        }
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
            Inner::Discrete(inner, _) => {
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
            Inner::Dense { monitor, live } => {
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
                Ok(Self::points(py, live.times(), decided)?.into_any())
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
            Inner::Discrete(inner, windows) => {
                let verdicts = match windows {
                    Windows::Clipped => inner.finish(),
                    Windows::Complete => inner.finish_complete(),
                };
                let rows: Vec<(usize, f64)> =
                    verdicts.into_iter().map(|v| (v.step, v.value)).collect();
                PyList::new(py, rows)
            }
            Inner::Dense { monitor, live } => {
                // The axis of the trace that ends (`finish` starts a new one).
                let (axis, plain) = (live.times(), live.axis(false));
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
            Inner::Discrete(inner, _) => inner.horizon(),
            Inner::Dense { .. } => None,
        }
    }

    /// The number of states (rows) given since creation or the last `finish()`.
    #[getter]
    fn steps(&self) -> usize {
        match &self.inner {
            Inner::Discrete(inner, _) => inner.steps(),
            Inner::Dense { live, .. } => live.rows(),
        }
    }

    /// The state variables, in the order a sequence state lists them.
    #[getter]
    fn state_vars(&self) -> Vec<String> {
        match &self.inner {
            Inner::Discrete(inner, _) => inner.state_vars().to_vec(),
            Inner::Dense { monitor, .. } => monitor.state_vars().to_vec(),
        }
    }

    /// The time variable of a dense-time monitor; None for a discrete-time one.
    #[getter]
    fn time_var(&self) -> Option<String> {
        match &self.inner {
            Inner::Discrete(..) => None,
            Inner::Dense { monitor, .. } => Some(monitor.time_var().to_string()),
        }
    }

    /// A copy mid-trace.
    fn __deepcopy__(&self, py: Python<'_>, _memo: &Bound<'_, PyDict>) -> OnlineMonitor {
        let inner = match &self.inner {
            Inner::Discrete(o, w) => Inner::Discrete(o.clone(), *w),
            Inner::Dense { monitor, live } => {
                Inner::Dense { monitor: Arc::clone(monitor), live: live.clone() }
            }
        };
        OnlineMonitor { inner, spec: self.spec.clone_ref(py), formula: self.formula.clone() }
    }

    fn __copy__(&self, py: Python<'_>) -> OnlineMonitor {
        self.__deepcopy__(py, &PyDict::new(py))
    }

    fn __repr__(&self) -> String {
        match &self.inner {
            Inner::Discrete(inner, _) => {
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
