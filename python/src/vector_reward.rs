//! `hstl._hstl.EpisodeBatch`: what `hstl.STLVectorReward` scores a vector step with, one
//! call for every environment of the vector.

use hstl::reward::{EpisodeBatch as Inner, EpisodeMonitor, RewardForm, Shaping, StepScore};
use numpy::{PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::errors::{lower_error, trace_error, value_error};
use crate::spec::Spec;

/// The episodes of a vector of `envs` environments, each reading state variable `i` (in
/// `state_vars` order) from column `indices[i]` of its observation row. See
/// `hstl.STLVectorReward`.
#[pyclass(module = "hstl._hstl")]
pub struct EpisodeBatch {
    inner: Inner,
    persistent: bool,
    /// Which rows start a new episode at the next step (the environments whose episode
    /// ended at the last one: gymnasium's next-step autoreset).
    starts: Vec<bool>,
    scores: Vec<StepScore>,
}

/// The most environments one batch scores: each holds a copy of the episode monitor, and
/// a vector past this is no gymnasium vector one process steps.
const MAX_ENVS: usize = 1 << 12;

/// A vector step's scores: the rewards, the task's robustness and, for a persistent task,
/// whether each window is kept.
type Scored<'py> =
    (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>, Option<Bound<'py, PyArray1<bool>>>);

#[pymethods]
impl EpisodeBatch {
    #[new]
    #[pyo3(signature = (spec, envs, indices, formula=None, reward="robustness", offset=0.0, scale=1.0))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        spec: &Bound<'_, Spec>,
        envs: usize,
        indices: Vec<usize>,
        formula: Option<&str>,
        reward: &str,
        offset: f64,
        scale: f64,
    ) -> PyResult<EpisodeBatch> {
        let spec = spec.get();
        let one = EpisodeMonitor::new(&spec.spec, &spec.source, formula)
            .map_err(|e| lower_error(&spec.filename, &e))?;
        let bad = |e: hstl::reward::RewardError| value_error(e.to_string(), e.help());
        let form = RewardForm::parse(reward).map_err(bad)?;
        let one = one.with_shaping(Shaping { form, offset, scale }, formula).map_err(bad)?;
        let vars = one.state_vars();
        if indices.len() != vars.len() {
            return Err(value_error(
                format!("{} observation indices for {} state variables", indices.len(), vars.len()),
                Some("give one index for each state variable, in `state_vars` order".into()),
            ));
        }
        if envs > MAX_ENVS {
            return Err(value_error(
                format!("a vector of {envs} environments; at most {MAX_ENVS} are scored together"),
                Some("split the environments into vectors of fewer".into()),
            ));
        }
        let persistent = one.is_persistent();
        Ok(EpisodeBatch {
            inner: Inner::new(&one, envs, indices),
            persistent,
            starts: vec![false; envs],
            scores: Vec::with_capacity(envs),
        })
    }

    /// Starts every episode at the rows of `obs` (float64, shape (envs, columns)) and
    /// returns their scores, each reward 0.
    fn _reset<'py>(&mut self, obs: PyReadonlyArray2<'py, f64>) -> PyResult<Scored<'py>> {
        let py = obs.py();
        let (data, width) = self.rows(&obs)?;
        self.inner.reset(data, width, &mut self.scores).map_err(|e| row_error(py, &e))?;
        self.starts.fill(false);
        Ok(self.scored(py))
    }

    /// Scores one vector step: row `i` of `obs` is environment `i`'s new observation,
    /// `ends[i]` whether its episode ended there. A row after an ended episode is the
    /// first of the next one (next-step autoreset): it starts anew, its reward 0.
    fn _step<'py>(
        &mut self,
        obs: PyReadonlyArray2<'py, f64>,
        ends: PyReadonlyArray1<'py, bool>,
    ) -> PyResult<Scored<'py>> {
        let py = obs.py();
        let (data, width) = self.rows(&obs)?;
        let ends =
            ends.as_slice().ok().filter(|e| e.len() == self.inner.len()).ok_or_else(|| {
                value_error(
                    format!("`terminated | truncated` must hold {} booleans", self.inner.len()),
                    None,
                )
            })?;
        self.inner
            .step(data, width, ends, &self.starts, &mut self.scores)
            .map_err(|e| row_error(py, &e))?;
        self.starts.copy_from_slice(ends);
        Ok(self.scored(py))
    }

    /// The number of environments.
    #[getter]
    fn envs(&self) -> usize {
        self.inner.len()
    }

    /// Whether the task is persistent (`info["window_kept"]` is given).
    #[getter]
    fn persistent(&self) -> bool {
        self.persistent
    }
}

impl EpisodeBatch {
    /// The observations as rows, checked against the vector's shape.
    fn rows<'a>(&self, obs: &'a PyReadonlyArray2<'_, f64>) -> PyResult<(&'a [f64], usize)> {
        let shape = obs.shape();
        let (n, width) = (shape[0], shape[1]);
        if n != self.inner.len() || width < self.inner.width() {
            return Err(value_error(
                format!(
                    "the observations have shape ({n}, {width}); this vector of {} environments \
                     reads columns up to {}",
                    self.inner.len(),
                    self.inner.width().saturating_sub(1)
                ),
                Some("pass the vector environment's observations, one row an environment".into()),
            ));
        }
        let c_ordered = obs.is_c_contiguous();
        let data = obs.as_slice().ok().filter(|_| c_ordered).ok_or_else(|| {
            value_error("the observations must be a C-ordered float64 array", None)
        })?;
        Ok((data, width))
    }

    fn scored<'py>(&self, py: Python<'py>) -> Scored<'py> {
        let rewards = PyArray1::from_iter(py, self.scores.iter().map(|s| s.reward));
        let task = PyArray1::from_iter(py, self.scores.iter().map(|s| s.task_robustness));
        let kept = self.persistent.then(|| {
            PyArray1::from_iter(py, self.scores.iter().map(|s| s.window_kept == Some(true)))
        });
        (rewards, task, kept)
    }
}

/// A row's error, naming its environment.
fn row_error(py: Python<'_>, e: &hstl::reward::RowError) -> PyErr {
    let inner = trace_error(py, &e.error);
    let message = format!("environment {} of the vector: {}", e.env, inner.value(py));
    PyErr::from_type(inner.get_type(py), message)
}
