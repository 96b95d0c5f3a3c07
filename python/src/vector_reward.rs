//! `hstl._hstl.EpisodeBatch`: what `hstl.STLVectorReward` scores a vector step with, one
//! call for every environment of the vector.

use hstl::reward::{EpisodeBatch as Inner, EpisodeMonitor, RewardForm, Shaping, StepScore};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple};

use crate::errors::{lower_error, trace_error, type_error, value_error};
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
    /// Which episodes ended at this step, and the second flags read (kept allocations).
    ends: Vec<bool>,
    flags: Vec<bool>,
    /// All true: every entry of an info array is given (gymnasium's `_name` masks).
    all: Py<PyArray1<bool>>,
}

/// The most environments one batch scores: each holds a copy of the episode monitor, and
/// a vector past this is no gymnasium vector one process steps.
const MAX_ENVS: usize = 1 << 12;

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
        let py = spec.py();
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
            ends: Vec::with_capacity(envs),
            flags: Vec::with_capacity(envs),
            all: PyArray1::from_vec(py, vec![true; envs]).unbind(),
        })
    }

    /// `gymnasium`'s vector reset for `hstl.STLVectorReward`: starts every episode at the
    /// rows of the observations in `result` (what the vector's `reset` returned, `(obs,
    /// info)`) and returns `(obs, info)`, `info` a new dict with `task_robustness` and, for
    /// a persistent task, `window_kept`, each with its `_name` mask.
    fn _reset<'py>(&mut self, result: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyTuple>> {
        let py = result.py();
        let [obs, info] = items(result, "reset", ["obs", "info"])?;
        let rows = self.rows(&obs)?;
        self.inner
            .reset(rows.data(), rows.width, &mut self.scores)
            .map_err(|e| row_error(py, &e))?;
        self.starts.fill(false);
        let info = self.info_with(&info)?;
        PyTuple::new(py, [obs, info.into_any()])
    }

    /// `gymnasium`'s vector step for `hstl.STLVectorReward`, one call for the whole vector:
    /// from `result` (what the vector's `step` returned, `(obs, rewards, terminated,
    /// truncated, info)`), row `i` of `obs` is environment `i`'s new observation, its
    /// episode ended there when `terminated[i] or truncated[i]`, and a row after an ended
    /// episode is the first of the next one (next-step autoreset): it starts anew, its
    /// reward 0. Returns `(obs, rewards, terminated, truncated, info)`, the rewards the
    /// task's and `info` a new dict with `task_robustness`, `window_kept` (persistent tasks)
    /// and `env_reward` (the vector's own rewards), each with its `_name` mask.
    fn _step<'py>(&mut self, result: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyTuple>> {
        let py = result.py();
        let [obs, env_reward, terminated, truncated, info] =
            items(result, "step", ["obs", "rewards", "terminated", "truncated", "info"])?;
        let n = self.inner.len();
        read_flags(&terminated, n, "terminated", &mut self.ends)?;
        read_flags(&truncated, n, "truncated", &mut self.flags)?;
        for (end, &cut) in self.ends.iter_mut().zip(&self.flags) {
            *end |= cut;
        }
        let rows = self.rows(&obs)?;
        self.inner
            .step(rows.data(), rows.width, &self.ends, &self.starts, &mut self.scores)
            .map_err(|e| row_error(py, &e))?;
        self.starts.copy_from_slice(&self.ends);
        let rewards = PyArray1::from_iter(py, self.scores.iter().map(|s| s.reward));
        let info = self.info_with(&info)?;
        info.set_item(intern!(py, "env_reward"), env_reward)?;
        info.set_item(intern!(py, "_env_reward"), self.all.bind(py))?;
        PyTuple::new(py, [obs, rewards.into_any(), terminated, truncated, info.into_any()])
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
    /// The observations as rows, checked against the vector's shape: a C-ordered float64
    /// array read in place, anything else converted by numpy first.
    fn rows<'py>(&self, obs: &Bound<'py, PyAny>) -> PyResult<Rows<'py>> {
        let py = obs.py();
        let array = match obs.cast::<PyArray2<f64>>() {
            Ok(a) if a.is_c_contiguous() => a.clone(),
            _ => {
                let kwargs = PyDict::new(py);
                kwargs.set_item(intern!(py, "dtype"), intern!(py, "float64"))?;
                ASCONTIGUOUSARRAY
                    .import(py, "numpy", "ascontiguousarray")?
                    .call((obs,), Some(&kwargs))
                    .ok()
                    .and_then(|a| a.cast_into::<PyArray2<f64>>().ok())
                    .ok_or_else(|| {
                        let shape = obs
                            .getattr(intern!(py, "shape"))
                            .and_then(|s| s.str())
                            .map_or_else(|_| String::new(), |s| format!(" (shape {s})"));
                        value_error(
                            format!(
                                "the observations{shape} must be a 2-D array of numbers, one row an environment"
                            ),
                            Some("give STLVectorReward a vector environment with a flat Box observation space".into()),
                        )
                    })?
            }
        };
        let shape = array.shape();
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
        Ok(Rows { array, width })
    }

    /// A new dict with `info`'s items (as `dict(info)` copies them) and the scores'
    /// `task_robustness` and (persistent tasks) `window_kept`, each with its mask.
    fn info_with<'py>(&self, info: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyDict>> {
        let py = info.py();
        let info = match info.cast_exact::<PyDict>() {
            Ok(d) => d.copy()?,
            Err(_) => py
                .get_type::<PyDict>()
                .call1((info,))
                .and_then(|d| Ok(d.cast_into::<PyDict>()?))
                .map_err(|_| {
                    let kind =
                        info.get_type().name().map_or_else(|_| "?".into(), |n| n.to_string());
                    type_error(
                        format!("the vector environment's info is a {kind}, not a dict"),
                        None,
                    )
                })?,
        };
        let all = self.all.bind(py);
        let task = PyArray1::from_iter(py, self.scores.iter().map(|s| s.task_robustness));
        info.set_item(intern!(py, "task_robustness"), task)?;
        info.set_item(intern!(py, "_task_robustness"), all)?;
        if self.persistent {
            let kept =
                PyArray1::from_iter(py, self.scores.iter().map(|s| s.window_kept == Some(true)));
            info.set_item(intern!(py, "window_kept"), kept)?;
            info.set_item(intern!(py, "_window_kept"), all)?;
        }
        Ok(info)
    }
}

/// A vector's observations, C-ordered float64, one row an environment.
struct Rows<'py> {
    array: Bound<'py, PyArray2<f64>>,
    width: usize,
}

impl Rows<'_> {
    fn data(&self) -> &[f64] {
        // SAFETY: the rows are read while the GIL is held and no Python code runs, so
        // nothing writes the array meanwhile; the slice does not outlive the call. The
        // array is C-contiguous (checked or made so), hence one slice.
        unsafe { self.array.as_slice() }.unwrap_or(&[])
    }
}

static ASCONTIGUOUSARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

/// The items of a vector environment's `method` result, checked to be as many as
/// gymnasium's.
fn items<'py, const N: usize>(
    result: &Bound<'py, PyAny>,
    method: &str,
    names: [&str; N],
) -> PyResult<[Bound<'py, PyAny>; N]> {
    let result = result.cast::<PyTuple>().map_err(|_| {
        let kind = result.get_type().name().map_or_else(|_| "?".into(), |n| n.to_string());
        type_error(
            format!(
                "the vector environment's {method} returned a {kind}, not the tuple of gymnasium's ({})",
                names.join(", ")
            ),
            None,
        )
    })?;
    if result.len() != N {
        return Err(type_error(
            format!(
                "the vector environment's {method} returned {} values, not the {N} of gymnasium's ({})",
                result.len(),
                names.join(", ")
            ),
            None,
        ));
    }
    let items: Vec<Bound<'py, PyAny>> = result.iter().collect();
    items
        .try_into()
        .map_err(|_| type_error(format!("the vector environment's {method} result changed"), None))
}

/// `flags` as booleans into `out`: a boolean array read in place, anything else entry by
/// entry (each truthy or not), `n` of them.
fn read_flags(flags: &Bound<'_, PyAny>, n: usize, what: &str, out: &mut Vec<bool>) -> PyResult<()> {
    out.clear();
    let wrong = |len: &dyn std::fmt::Display| {
        value_error(format!("`{what}` holds {len} values; this vector has {n} environments"), None)
    };
    if let Ok(a) = flags.cast::<PyArray1<bool>>() {
        // SAFETY: as in `Rows::data`.
        let view = unsafe { a.as_array() };
        if view.len() != n {
            return Err(wrong(&view.len()));
        }
        out.extend(view.iter().copied());
        return Ok(());
    }
    // One past the vector's size is enough to refuse: an endless iterable is not read on.
    let not_flags = || {
        let kind = flags.get_type().name().map_or_else(|_| "?".into(), |n| n.to_string());
        type_error(
            format!(
                "`{what}` must be one boolean for each environment; got a value of type {kind}"
            ),
            Some("pass what the vector environment's step returned".into()),
        )
    };
    for item in flags.try_iter().map_err(|_| not_flags())?.take(n + 1) {
        out.push(item?.is_truthy().map_err(|_| not_flags())?);
    }
    if out.len() != n {
        let len = match flags.len() {
            Ok(len) => len.to_string(),
            Err(_) if out.len() > n => "more".into(),
            Err(_) => out.len().to_string(),
        };
        return Err(wrong(&len));
    }
    Ok(())
}

/// A row's error, naming its environment.
fn row_error(py: Python<'_>, e: &hstl::reward::RowError) -> PyErr {
    let inner = trace_error(py, &e.error);
    let message = format!("environment {} of the vector: {}", e.env, inner.value(py));
    PyErr::from_type(inner.get_type(py), message)
}
