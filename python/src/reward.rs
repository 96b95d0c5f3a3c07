//! `hstl._hstl.EpisodeMonitor`: what `hstl.STLReward` scores each step with.

use hstl::reward::{EpisodeMonitor as Inner, RewardForm, Shaping, StepScore};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use crate::errors::{lower_error, trace_error, type_error, value_error};
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
    /// Each state variable's index in an observation, for `_step` (`_observe`).
    picks: Option<Vec<usize>>,
    /// The state read off the last observation (kept to reuse its allocation).
    state: Vec<f64>,
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
            picks: None,
            state: Vec::new(),
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
        picks: Option<Vec<usize>>,
    ) -> PyResult<EpisodeMonitor> {
        let mut monitor = EpisodeMonitor::new(spec, formula, reward, offset, scale)?;
        monitor.inner.restore(&states).map_err(|e| trace_error(py, &e))?;
        if let Some(picks) = picks {
            monitor.set_picks(picks)?;
        }
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
            this.picks.clone(),
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

    /// Reads the state variables off an observation by index in `_step`: state variable
    /// `i` (in `state_vars` order) is `observation[indices[i]]`.
    fn _observe(&mut self, indices: Vec<usize>) -> PyResult<()> {
        self.set_picks(indices)
    }

    /// A whole `gymnasium` step for `hstl.STLReward`: takes what the wrapped
    /// environment's `step` returned, `(obs, env_reward, terminated, truncated, info)`,
    /// scores the observation (read by the indices `_observe` set when `valuation` is
    /// None, else `valuation(obs)` as `push` takes it; the last state when `terminated` or
    /// `truncated`) and returns `(obs, reward, terminated, truncated, info)`, `info` a new
    /// dict with `task_robustness`, `window_kept` (persistent tasks) and `env_reward`.
    #[pyo3(signature = (result, valuation=None))]
    fn _step<'py>(
        &mut self,
        result: &Bound<'py, PyTuple>,
        valuation: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let py = result.py();
        if result.len() != 5 {
            return Err(type_error(
                format!(
                    "the wrapped environment's step returned {} values, not the 5 of gymnasium's \
                     (obs, reward, terminated, truncated, info)",
                    result.len()
                ),
                None,
            ));
        }
        let obs = result.get_item(0)?;
        let env_reward = result.get_item(1)?;
        let terminated = result.get_item(2)?;
        let truncated = result.get_item(3)?;
        let last = terminated.is_truthy()? || truncated.is_truthy()?;
        let score = self.score(&obs, valuation, last)?;
        let info = info_with(&result.get_item(4)?, &score)?;
        info.set_item(intern!(py, "env_reward"), env_reward)?;
        PyTuple::new(
            py,
            [
                obs,
                score.reward.into_pyobject(py)?.into_any(),
                terminated,
                truncated,
                info.into_any(),
            ],
        )
    }

    /// `gymnasium`'s reset for `hstl.STLReward`: starts a new episode, scores the first
    /// observation (as `_step` does) and returns `(obs, info)` from what the wrapped
    /// environment's `reset` returned, `info` a new dict with `task_robustness` and
    /// `window_kept` (persistent tasks).
    #[pyo3(signature = (result, valuation=None))]
    fn _reset<'py>(
        &mut self,
        result: &Bound<'py, PyTuple>,
        valuation: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let py = result.py();
        if result.len() != 2 {
            return Err(type_error(
                format!(
                    "the wrapped environment's reset returned {} values, not the 2 of gymnasium's \
                     (obs, info)",
                    result.len()
                ),
                None,
            ));
        }
        let obs = result.get_item(0)?;
        self.inner.reset();
        let score = self.score(&obs, valuation, false)?;
        let info = info_with(&result.get_item(1)?, &score)?;
        PyTuple::new(py, [obs, info.into_any()])
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

impl EpisodeMonitor {
    /// Scores observation `obs`: its entries at the picks when `valuation` is None and
    /// picks are set, else `valuation(obs)` (or `obs` itself) as `push` takes a state.
    fn score(
        &mut self,
        obs: &Bound<'_, PyAny>,
        valuation: Option<&Bound<'_, PyAny>>,
        last: bool,
    ) -> PyResult<StepScore> {
        let score = match (valuation, &self.picks) {
            (None, Some(picks)) => {
                read_picks(obs, picks, self.inner.state_vars(), &mut self.state)?;
                if last { self.inner.push_last(&self.state) } else { self.inner.push(&self.state) }
            }
            (valuation, _) => {
                let state = match valuation {
                    Some(f) => f.call1((obs,))?,
                    None => obs.clone(),
                };
                let values = state_values(&state, self.inner.state_vars())?;
                if last { self.inner.push_last(&values) } else { self.inner.push(&values) }
            }
        };
        score.map_err(|e| trace_error(obs.py(), &e))
    }

    fn set_picks(&mut self, indices: Vec<usize>) -> PyResult<()> {
        let vars = self.inner.state_vars();
        if indices.len() != vars.len() {
            return Err(value_error(
                format!("{} observation indices for {} state variables", indices.len(), vars.len()),
                Some("give one index for each state variable, in `state_vars` order".into()),
            ));
        }
        self.picks = Some(indices);
        Ok(())
    }
}

/// A new dict with `info`'s items (any mapping, as `dict(info)` copies it) and the
/// score's `task_robustness` and `window_kept` (when given).
fn info_with<'py>(info: &Bound<'py, PyAny>, score: &StepScore) -> PyResult<Bound<'py, PyDict>> {
    let py = info.py();
    let info = match info.cast_exact::<PyDict>() {
        Ok(d) => d.copy()?,
        Err(_) => py.get_type::<PyDict>().call1((info,))?.cast_into::<PyDict>()?,
    };
    info.set_item(intern!(py, "task_robustness"), score.task_robustness)?;
    if let Some(kept) = score.window_kept {
        info.set_item(intern!(py, "window_kept"), kept)?;
    }
    Ok(info)
}

/// The entries `picks` of observation `obs` into `out`: a one-dimensional float64 or
/// float32 array read in place, anything else entry by entry (`obs[k]`, a number).
fn read_picks(
    obs: &Bound<'_, PyAny>,
    picks: &[usize],
    vars: &[String],
    out: &mut Vec<f64>,
) -> PyResult<()> {
    out.clear();
    let out_of_range = |len: usize, k: usize, var: &str| {
        value_error(
            format!("the observation has {len} entries, and `{var}` is read from index {k}"),
            Some("give STLReward a valuation that maps each state variable to an index of the observation".into()),
        )
    };
    if let Ok(a) = obs.cast::<PyArray1<f64>>() {
        // SAFETY: the view is read here only, with the GIL held and no Python code run
        // meanwhile, so nothing writes the array while it is read; no view escapes.
        let view = unsafe { a.as_array() };
        for (&k, var) in picks.iter().zip(vars) {
            out.push(*view.get(k).ok_or_else(|| out_of_range(view.len(), k, var))?);
        }
        return Ok(());
    }
    if let Ok(a) = obs.cast::<PyArray1<f32>>() {
        // SAFETY: as above.
        let view = unsafe { a.as_array() };
        for (&k, var) in picks.iter().zip(vars) {
            out.push(f64::from(*view.get(k).ok_or_else(|| out_of_range(view.len(), k, var))?));
        }
        return Ok(());
    }
    for (&k, var) in picks.iter().zip(vars) {
        let item = obs.get_item(k).map_err(|_| {
            let len = obs.len().unwrap_or(0);
            out_of_range(len, k, var)
        })?;
        out.push(item.extract::<f64>().map_err(|_| {
            type_error(format!("`{var}` (observation entry {k}) must be a number"), None)
        })?);
    }
    Ok(())
}
