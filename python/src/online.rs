//! `hstl.OnlineMonitor`.

use hstl::monitor::{Online, OnlineState};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::errors::trace_error;
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
#[pyclass(module = "hstl")]
pub struct OnlineMonitor {
    inner: Online,
    spec: Py<Spec>,
    formula: Option<String>,
}

impl OnlineMonitor {
    pub fn new(inner: Online, spec: Py<Spec>, formula: Option<String>) -> OnlineMonitor {
        OnlineMonitor { inner, spec, formula }
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
        let state = this.inner.snapshot();
        let args =
            (this.spec.clone_ref(slf.py()), this.formula.clone(), state.skipped, state.states)
                .into_pyobject(slf.py())?;
        Ok((slf.get_type().getattr("_restore")?, args))
    }

    /// Appends one state, a mapping from state variable names to numbers (or a sequence of
    /// numbers in the order of `state_vars`), and returns the verdict it completes,
    /// `(step, value)`, or None while no new step is final. A state with NaN or a missing
    /// variable raises and changes nothing.
    fn update(
        &mut self,
        py: Python<'_>,
        state: &Bound<'_, PyAny>,
    ) -> PyResult<Option<(usize, f64)>> {
        let values = state_values(state, self.inner.state_vars())?;
        let verdict = self.inner.push(&values).map_err(|e| trace_error(py, &e))?;
        Ok(verdict.map(|v| (v.step, v.value)))
    }

    /// The value the first step without a verdict would have if the trace ended now;
    /// None when every step so far has its verdict. Not final: later states may change it.
    fn provisional(&mut self) -> Option<f64> {
        self.inner.provisional()
    }

    /// Ends the trace and returns the verdicts of every step still open, `[(step, value),
    /// ...]`. The monitor then starts a new trace at step 0.
    fn finish(&mut self) -> Vec<(usize, f64)> {
        self.inner.finish().into_iter().map(|v| (v.step, v.value)).collect()
    }

    /// The horizon `H`: a step's value is final `H` states after it. None when unbounded.
    #[getter]
    fn horizon(&self) -> Option<usize> {
        self.inner.horizon()
    }

    /// The number of states given since creation or the last `finish()`.
    #[getter]
    fn steps(&self) -> usize {
        self.inner.steps()
    }

    /// The state variables, in the order a sequence state lists them.
    #[getter]
    fn state_vars(&self) -> Vec<String> {
        self.inner.state_vars().to_vec()
    }

    fn __repr__(&self) -> String {
        let h = self.inner.horizon().map_or("unbounded".to_string(), |h| h.to_string());
        format!("<hstl.OnlineMonitor horizon {h}, {} steps>", self.inner.steps())
    }
}
