//! `hstl._hstl.EpisodeMonitor`: what `hstl.STLReward` scores each step with.

use hstl::reward::{EpisodeMonitor as Inner, RewardForm, Shaping};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::errors::{lower_error, trace_error, value_error};
use crate::spec::Spec;
use crate::trace::state_values;

/// Scores the states of one episode as they arrive: the reward `rho(formula, t)` over the
/// states so far, the task's robustness `rho(task, 0)` over them and, for a persistent
/// task, whether the window ending at `t` is kept. See `hstl.STLReward`.
///
/// It pickles and copies mid-episode: by its spec, formula, reward form and the states of
/// the episode so far, which the copy replays.
#[pyclass(module = "hstl._hstl")]
pub struct EpisodeMonitor {
    inner: Inner,
    spec: Py<Spec>,
    formula: Option<String>,
}

#[pymethods]
impl EpisodeMonitor {
    #[new]
    #[pyo3(signature = (spec, formula=None, reward="robustness", offset=0.0, scale=1.0))]
    fn new(
        spec: &Bound<'_, Spec>,
        formula: Option<&str>,
        reward: &str,
        offset: f64,
        scale: f64,
    ) -> PyResult<EpisodeMonitor> {
        let spec_obj = spec;
        let spec = spec.get();
        let inner = Inner::new(&spec.spec, &spec.source, formula)
            .map_err(|e| lower_error(&spec.filename, &e))?;
        let bad = |e: hstl::reward::RewardError| value_error(e.to_string(), e.help());
        let form = RewardForm::parse(reward).map_err(bad)?;
        let inner = inner.with_shaping(Shaping { form, offset, scale }, formula).map_err(bad)?;
        Ok(EpisodeMonitor {
            inner,
            spec: spec_obj.clone().unbind(),
            formula: formula.map(String::from),
        })
    }

    /// The monitor `__reduce__` describes: made anew, then the episode's states replayed.
    #[staticmethod]
    #[allow(clippy::too_many_arguments)]
    fn _restore(
        py: Python<'_>,
        spec: &Bound<'_, Spec>,
        formula: Option<&str>,
        reward: &str,
        offset: f64,
        scale: f64,
        states: Vec<f64>,
    ) -> PyResult<EpisodeMonitor> {
        let mut monitor = EpisodeMonitor::new(spec, formula, reward, offset, scale)?;
        monitor.inner.restore(&states).map_err(|e| trace_error(py, &e))?;
        Ok(monitor)
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let this = slf.borrow();
        let shaping = this.inner.shaping();
        let args = (
            this.spec.clone_ref(slf.py()),
            this.formula.clone(),
            shaping.form.name(),
            shaping.offset,
            shaping.scale,
            this.inner.episode_states().to_vec(),
        )
            .into_pyobject(slf.py())?;
        Ok((slf.get_type().getattr("_restore")?, args))
    }

    /// Starts a new episode.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// Appends one state (a mapping from state variable names to numbers, or numbers in
    /// the order of `state_vars`) and returns `(reward, task_robustness, window_kept)`;
    /// `window_kept` is None for a task that is not persistent. `last=True` marks the
    /// episode's last state (the sparse reward is given there).
    #[pyo3(signature = (state, last=false))]
    fn push(
        &mut self,
        py: Python<'_>,
        state: &Bound<'_, PyAny>,
        last: bool,
    ) -> PyResult<(f64, f64, Option<bool>)> {
        let values = state_values(state, self.inner.state_vars())?;
        let score = if last { self.inner.push_last(&values) } else { self.inner.push(&values) };
        let score = score.map_err(|e| trace_error(py, &e))?;
        Ok((score.reward, score.task_robustness, score.window_kept))
    }

    /// The state variables, in the order a sequence state lists them.
    #[getter]
    fn state_vars(&self) -> Vec<String> {
        self.inner.state_vars().to_vec()
    }

    /// Whether the task is persistent (`always[0..] (eventually[0..N1] R1 && ...)`).
    #[getter]
    fn persistent(&self) -> bool {
        self.inner.is_persistent()
    }

    /// The reward's form: "robustness", "increment", "window" or "sparse".
    #[getter]
    fn reward(&self) -> &'static str {
        self.inner.shaping().form.name()
    }

    /// Added to every step's reward.
    #[getter]
    fn offset(&self) -> f64 {
        self.inner.shaping().offset
    }

    /// Multiplies the form's value.
    #[getter]
    fn scale(&self) -> f64 {
        self.inner.shaping().scale
    }

    /// The states given since creation or the last `reset()`.
    #[getter]
    fn steps(&self) -> usize {
        self.inner.steps()
    }
}
