//! `hstl.Spec`.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use hstl::lang::CheckedSpec;
use hstl::monitor::{Dense, Front, Monitor};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::dense;
use crate::diagnostic::Diagnostic;
use crate::errors::{self, batch_error, diagnostics_of, lower_error, trace_error, value_error};
use crate::interrupt;
use crate::online::OnlineMonitor;
use crate::trace::{Copied, hold, hold_batch};

/// A checked hstl spec: its state variables, its `let`s and its task, ready to monitor
/// traces.
///
/// Make one with `Spec.load(path)` or `Spec.parse(text)`; both raise `hstl.SpecError` when
/// the text does not check. A trace maps each state variable's name to one sample per
/// step (a dict of arrays or sequences, a pandas DataFrame), or is a 2-D array of shape
/// (steps, columns) whose columns `columns=` names (by default the state variables, in
/// order). `formula` names a `let` to score instead of the task. Values are exactly those
/// of `hstlc monitor`, bit for bit.
///
/// A spec pickles by its source text, file name and spec name.
#[pyclass(module = "hstl", frozen)]
pub struct Spec {
    pub(crate) source: String,
    pub(crate) filename: String,
    requested: Option<String>,
    /// The formula text of a spec made by `hstl.formula` (its diagnostics are positioned
    /// in it).
    formula: Option<String>,
    pub(crate) spec: CheckedSpec,
    warnings: Vec<hstl::lang::Diagnostic>,
    /// Lowered monitors by formula name (`None`: the task), made on first use.
    monitors: Mutex<HashMap<Option<String>, Arc<Monitor>>>,
    /// The same for a dense-time spec.
    dense: Mutex<HashMap<Option<String>, Arc<Dense>>>,
}

impl Spec {
    /// Checks `source` (reported as `filename`) and picks the spec called `name`; its
    /// warnings are issued as `hstl.SpecWarning`s unless `quiet`.
    pub(crate) fn from_source(
        py: Python<'_>,
        source: String,
        filename: String,
        name: Option<String>,
        quiet: bool,
    ) -> PyResult<Spec> {
        let loaded = py
            .detach(|| hstl::load::load(&source, name.as_deref()))
            .map_err(|e| errors::load_error(py, &filename, &source, e))?;
        if !quiet {
            errors::warn_spec(py, &filename, &source, &loaded.diagnostics)?;
        }
        Ok(Spec {
            source,
            filename,
            requested: name,
            formula: None,
            spec: loaded.spec,
            warnings: loaded.diagnostics,
            monitors: Mutex::new(HashMap::new()),
            dense: Mutex::new(HashMap::new()),
        })
    }

    /// The spec of the one formula `text` (see `hstl.formula`); its warnings are issued
    /// as `hstl.SpecWarning`s unless `quiet`.
    pub(crate) fn from_formula(py: Python<'_>, text: String, quiet: bool) -> PyResult<Spec> {
        let filename = "<formula>".to_string();
        let made = py
            .detach(|| hstl::load::formula(&text))
            .map_err(|e| errors::load_error(py, &filename, &text, e))?;
        if !quiet {
            errors::warn_spec(py, &filename, &text, &made.loaded.diagnostics)?;
        }
        Ok(Spec {
            source: made.source,
            filename,
            requested: Some(hstl::load::FORMULA_SPEC.to_string()),
            formula: Some(text),
            spec: made.loaded.spec,
            warnings: made.loaded.diagnostics,
            monitors: Mutex::new(HashMap::new()),
            dense: Mutex::new(HashMap::new()),
        })
    }

    /// A new online monitor of the task or of the `let` called `formula`.
    pub(crate) fn online_of(&self, formula: Option<&str>) -> PyResult<hstl::monitor::Online> {
        Ok(self.monitor(formula)?.online())
    }

    /// The dense-time monitor of the task or of the `let` called `formula`, lowered once.
    pub(crate) fn dense(&self, formula: Option<&str>) -> PyResult<Arc<Dense>> {
        let key = formula.map(str::to_string);
        let mut monitors = self.dense.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(m) = monitors.get(&key) {
            return Ok(Arc::clone(m));
        }
        let m =
            Arc::new(Dense::new(&self.spec, formula).map_err(|e| lower_error(&self.filename, &e))?);
        monitors.insert(key, Arc::clone(&m));
        Ok(m)
    }

    /// The error for a dense-only keyword given with a discrete-time spec.
    fn discrete_only(&self, gap: Option<&Bound<'_, PyAny>>, relative: bool) -> PyResult<()> {
        if gap.is_some_and(|g| !g.is_none()) {
            return Err(dense::dense_only(&self.spec.name, "max_gap"));
        }
        if relative {
            return Err(dense::dense_only(&self.spec.name, "relative"));
        }
        Ok(())
    }

    /// The monitor of the task or of the `let` called `formula`, lowered once.
    fn monitor(&self, formula: Option<&str>) -> PyResult<Arc<Monitor>> {
        let key = formula.map(str::to_string);
        let mut monitors = self.monitors.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(m) = monitors.get(&key) {
            return Ok(Arc::clone(m));
        }
        let m = Arc::new(
            Monitor::new(&self.spec, formula).map_err(|e| lower_error(&self.filename, &e))?,
        );
        monitors.insert(key, Arc::clone(&m));
        Ok(m)
    }
}

impl Spec {
    /// `signal_batch` of a dense-time spec: a list of `(times, values)`.
    #[allow(clippy::too_many_arguments)]
    fn dense_batch<'py>(
        &self,
        py: Python<'py>,
        traces: &Bound<'py, PyAny>,
        formula: Option<&str>,
        columns: Option<&Bound<'py, PyAny>>,
        threads: usize,
        windows: hstl::monitor::Windows,
        max_gap: Option<&Bound<'py, PyAny>>,
        relative: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let monitor = self.dense(formula)?;
        let gap = dense::max_gap(max_gap)?;
        if traces.is_instance_of::<pyo3::types::PyString>() || dense::is_one_trace(traces)? {
            return Err(crate::errors::type_error(
                "a batch is a list of traces",
                Some("for one trace call `signal`".into()),
            ));
        }
        let mut built = Vec::new();
        for (i, item) in traces.try_iter()?.enumerate() {
            let item = item?;
            let held = dense::hold(&item, columns, &monitor)
                .and_then(|h| dense::build(py, &h, &monitor, gap.as_ref()))
                .map_err(|e| dense::prefixed(py, e, i))?;
            built.push(held);
        }
        let results = py.detach(|| monitor.signal_batch(&built, threads, windows));
        let list = pyo3::types::PyList::empty(py);
        for (i, (result, trace)) in results.into_iter().zip(&built).enumerate() {
            let (signal, end) = result.map_err(|p| {
                let axis = hstl::monitor::TimeAxis {
                    relative: false,
                    origin: trace.origin(),
                    t0: trace.t0(),
                };
                dense::prefixed(py, dense::problem_error(&p, &monitor, Some(&axis)), i)
            })?;
            let (times, values) = dense::arrays(py, &signal, end, trace, relative)?;
            list.append(PyTuple::new(py, [times, values.into_any()])?)?;
        }
        Ok(list.into_any())
    }
}

/// A spec whose task is the one formula `text`, such as `"always[0..=10] x > 0.5"`, with
/// every method of a spec: its state variables are the names the formula reads, as floats
/// in the order they first appear (`state_vars`); its name is `Formula`, its filename
/// `<formula>`, and its `source` the spec text written for it. Raises `hstl.SpecError`
/// (positioned in `text`) when the text is not one formula that checks.
#[pyfunction]
pub fn formula(py: Python<'_>, text: String) -> PyResult<Spec> {
    Spec::from_formula(py, text, false)
}

/// The `windows=` choice, or a `ValueError` naming both.
fn windows_of(name: &str) -> PyResult<hstl::monitor::Windows> {
    hstl::monitor::Windows::parse(name).map_err(|e| value_error(e.to_string(), Some(e.help())))
}

#[pymethods]
impl Spec {
    /// Reads and checks the spec file at `path`, and picks the spec called `name` (needed
    /// when the file holds several).
    ///
    /// Raises `FileNotFoundError` (or another `OSError`) when the file cannot be read, and
    /// `hstl.SpecError` when it does not check or holds no such spec.
    #[staticmethod]
    #[pyo3(signature = (path, name=None))]
    fn load(py: Python<'_>, path: PathBuf, name: Option<String>) -> PyResult<Spec> {
        let source = crate::files::read_text(&path, hstl::lang::MAX_SOURCE_BYTES, "spec", |e| {
            errors::read_error(&path, e)
        })?;
        Spec::from_source(py, source, path.display().to_string(), name, false)
    }

    /// Checks the spec text `text` (reported as `filename`), and picks the spec called
    /// `name` (needed when the text holds several).
    ///
    /// Raises `hstl.SpecError` when it does not check or holds no such spec.
    #[staticmethod]
    #[pyo3(signature = (text, filename="<string>".to_string(), name=None))]
    fn parse(
        py: Python<'_>,
        text: String,
        filename: String,
        name: Option<String>,
    ) -> PyResult<Spec> {
        Spec::from_source(py, text, filename, name, false)
    }

    /// `hstl.formula` without the warnings: how a spec made from a formula unpickles.
    #[staticmethod]
    fn _unpickle_formula(py: Python<'_>, text: String) -> PyResult<Spec> {
        Spec::from_formula(py, text, true)
    }

    /// `parse` without the warnings, which the original already issued: how a spec
    /// unpickles.
    #[staticmethod]
    fn _unpickle(
        py: Python<'_>,
        text: String,
        filename: String,
        name: Option<String>,
    ) -> PyResult<Spec> {
        Spec::from_source(py, text, filename, name, true)
    }

    /// The spec's name.
    #[getter]
    fn name(&self) -> &str {
        &self.spec.name
    }

    /// The file name it was loaded from, or the `filename` given to `parse`.
    #[getter]
    fn filename(&self) -> &str {
        &self.filename
    }

    /// The world the spec names with `world "...";` (a built-in name, or a world file's
    /// path relative to the spec file), or None.
    #[getter]
    fn world(&self) -> Option<&str> {
        self.spec.world.as_ref().map(|w| w.name.as_str())
    }

    /// Whether some state variable is a `float`: the spec is learned with tilings, in a
    /// continuous world (`paper-plane` when it names none).
    #[getter]
    fn is_continuous(&self) -> bool {
        self.spec.is_continuous()
    }

    /// The source text it was checked from.
    #[getter]
    fn source(&self) -> &str {
        &self.source
    }

    /// The state variables, in declaration order: the columns a trace needs.
    #[getter]
    fn state_vars(&self) -> Vec<String> {
        self.spec.state_vars.iter().map(|v| v.name.clone()).collect()
    }

    /// The time variable of a dense-time spec (its trace column holds each row's stamp);
    /// None for a discrete-time spec.
    #[getter]
    fn time_var(&self) -> Option<&str> {
        self.spec.time.as_ref().map(|t| t.name.as_str())
    }

    /// The names of the `let`s, in declaration order: what `formula=` can name.
    #[getter]
    fn lets(&self) -> Vec<String> {
        self.spec.lets.iter().map(|l| l.name.clone()).collect()
    }

    /// The file's warnings (a spec with errors does not load), as `hstl.Diagnostic`s.
    #[getter]
    fn diagnostics(&self) -> Vec<Diagnostic> {
        diagnostics_of(
            &self.filename,
            self.formula.as_ref().unwrap_or(&self.source),
            &self.warnings,
        )
    }

    /// The horizon `H` of the task (or of the `let` called `formula`): its value at step
    /// `t` depends on steps `t` to `t + H` only. None when unbounded.
    #[pyo3(signature = (formula=None))]
    fn horizon(&self, formula: Option<&str>) -> PyResult<Option<usize>> {
        Ok(self.monitor(formula)?.horizon())
    }

    /// The robustness of the trace at step 0, as `hstlc monitor` prints it (`inf` and
    /// `-inf` when infinite).
    ///
    /// For a formula with horizon `H` only the first `H + 1` steps are read (and checked
    /// for NaN), so a long float64 trace costs no more than a short one.
    ///
    /// `windows="complete"` counts a step only if every window its value needs lies
    /// inside the trace (`hstlc monitor --windows complete`): NaN when step 0 is
    /// undetermined (the trace is too short for its windows). The whole trace is read.
    ///
    /// A dense-time spec (one with a `time` variable) takes a mapping with the time column
    /// (NaN in a variable's column: no new sample) and gives the robustness at the first
    /// stamp; `max_gap` refuses a gap between consecutive stamps larger than it (in the
    /// time column's unit), as `hstlc monitor --max-gap` does.
    #[pyo3(signature = (trace, formula=None, *, columns=None, windows="clipped", max_gap=None))]
    fn robustness(
        &self,
        py: Python<'_>,
        trace: &Bound<'_, PyAny>,
        formula: Option<&str>,
        columns: Option<&Bound<'_, PyAny>>,
        windows: &str,
        max_gap: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<f64> {
        let windows = windows_of(windows)?;
        if self.spec.is_dense() {
            let monitor = self.dense(formula)?;
            let gap = dense::max_gap(max_gap)?;
            let held = dense::hold(trace, columns, &monitor)?;
            let trace = dense::build(py, &held, &monitor, gap.as_ref())?;
            let values = trace.len().saturating_mul(held.1.len() + 1);
            let (value, trace, monitor) = interrupt::run(py, values, move || {
                (monitor.robustness_in(&trace, windows), trace, monitor)
            })?;
            let value = value.map_err(|p| {
                let axis = hstl::monitor::TimeAxis {
                    relative: false,
                    origin: trace.origin(),
                    t0: trace.t0(),
                };
                dense::problem_error(&p, &monitor, Some(&axis))
            })?;
            return Ok(value.unwrap_or(f64::NAN));
        }
        self.discrete_only(max_gap, false)?;
        let monitor = self.monitor(formula)?;
        let held = hold(trace, columns, &monitor)?;
        let samples = held.samples()?;
        // Over clipped windows only the steps up to the horizon are read, and copied.
        let steps = match windows {
            hstl::monitor::Windows::Clipped => {
                monitor.samples_read(monitor.lengths(&samples).map_err(|e| trace_error(py, &e))?)
            }
            hstl::monitor::Windows::Complete => usize::MAX,
        };
        let copied = Copied::prefix(&samples, steps);
        let (value, copied) = interrupt::run(py, copied.values(), move || {
            (monitor.robustness_in(&copied.samples(), windows), copied)
        })?;
        copied.recycle();
        value.map_err(|e| trace_error(py, &e))
    }

    /// The robustness signal of the trace: a float64 array with one value per step, the
    /// rows `hstlc monitor --signal` prints.
    ///
    /// `windows="complete"` counts a step only if every window its value needs lies
    /// inside the trace (`--windows complete`); the later steps, undetermined, are NaN
    /// (the empty fields of `--signal`).
    ///
    /// A dense-time spec gives `(times, values)` instead: the change points of the signal
    /// (the rows of `hstlc monitor --signal`), each value holding from its time until the
    /// next. Times are in the time column's scale: int64 for whole-number stamps of 2^53
    /// or more (nanoseconds since the epoch), exact; float64 otherwise; float64 from the
    /// first stamp with `relative=True` (`--relative`). Over complete windows the last
    /// value may be NaN: the times from there on are undetermined.
    #[pyo3(signature = (trace, formula=None, *, columns=None, windows="clipped", max_gap=None, relative=false))]
    #[allow(clippy::too_many_arguments)]
    fn signal<'py>(
        &self,
        py: Python<'py>,
        trace: &Bound<'py, PyAny>,
        formula: Option<&str>,
        columns: Option<&Bound<'py, PyAny>>,
        windows: &str,
        max_gap: Option<&Bound<'py, PyAny>>,
        relative: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let windows = windows_of(windows)?;
        if self.spec.is_dense() {
            let monitor = self.dense(formula)?;
            let gap = dense::max_gap(max_gap)?;
            let held = dense::hold(trace, columns, &monitor)?;
            let trace = dense::build(py, &held, &monitor, gap.as_ref())?;
            let values = trace.len().saturating_mul(held.1.len() + 1);
            let (done, trace, monitor) = interrupt::run(py, values, move || {
                (monitor.signal_in(&trace, windows), trace, monitor)
            })?;
            let (signal, end) = done.map_err(|p| {
                let axis = hstl::monitor::TimeAxis {
                    relative: false,
                    origin: trace.origin(),
                    t0: trace.t0(),
                };
                dense::problem_error(&p, &monitor, Some(&axis))
            })?;
            let (times, values) = dense::arrays(py, &signal, end, &trace, relative)?;
            return Ok(PyTuple::new(py, [times, values.into_any()])?.into_any());
        }
        self.discrete_only(max_gap, relative)?;
        let monitor = self.monitor(formula)?;
        let copied = hold(trace, columns, &monitor)?.copied()?;
        let (signal, copied) = interrupt::run(py, copied.values(), move || {
            (monitor.signal_in(&copied.samples(), windows), copied)
        })?;
        copied.recycle();
        let signal = signal.map_err(|e| trace_error(py, &e))?;
        Ok(PyArray1::from_vec(py, signal).into_any())
    }

    /// The robustness signals of many traces of one length, on `threads` threads (default:
    /// every core): a float64 array of shape (traces, steps) whose row `i` equals
    /// `signal(traces[i])`.
    ///
    /// `traces` is a list of traces (as `signal` takes them), a 3-D array of shape
    /// (traces, steps, columns) whose columns `columns=` names, or a mapping from each
    /// state variable to a 2-D array of shape (traces, steps). `windows` is as for
    /// `signal`.
    ///
    /// A dense-time spec takes a list of traces (as `signal` takes them, of any lengths)
    /// and gives a list of `(times, values)`, one per trace, as `signal` gives them.
    #[pyo3(signature = (traces, formula=None, *, columns=None, threads=None, windows="clipped", max_gap=None, relative=false))]
    #[allow(clippy::too_many_arguments)]
    fn signal_batch<'py>(
        &self,
        py: Python<'py>,
        traces: &Bound<'py, PyAny>,
        formula: Option<&str>,
        columns: Option<&Bound<'py, PyAny>>,
        threads: Option<usize>,
        windows: &str,
        max_gap: Option<&Bound<'py, PyAny>>,
        relative: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        let windows = windows_of(windows)?;
        let threads = match threads {
            Some(0) => return Err(value_error("`threads` must be at least 1", None)),
            Some(n) => n,
            None => std::thread::available_parallelism().map_or(1, |n| n.get()),
        };
        if self.spec.is_dense() {
            return self
                .dense_batch(py, traces, formula, columns, threads, windows, max_gap, relative);
        }
        self.discrete_only(max_gap, relative)?;
        let monitor = self.monitor(formula)?;
        let held = hold_batch(traces, columns, &monitor)?;
        let copied = held.copied()?;
        let n = copied.len();
        let values = copied.iter().map(Copied::values).sum();
        let (done, copied) = interrupt::run(py, values, move || {
            let samples: Vec<_> = copied.iter().map(Copied::samples).collect();
            (monitor.signal_batch_in(&samples, threads, windows), copied)
        })?;
        copied.into_iter().for_each(Copied::recycle);
        let (out, steps) = done.map_err(|e| batch_error(py, &e))?;
        // An array of no traces still has steps.
        let steps = if n == 0 { held.shape_steps().unwrap_or(0) } else { steps };
        Ok(PyArray1::from_vec(py, out).reshape([n, steps])?.into_any())
    }

    /// An online monitor of the task (or of the `let` called `formula`), fed one state at
    /// a time; see `hstl.OnlineMonitor`.
    ///
    /// For a dense-time spec it takes `update(t, state)` rows (see `hstl.OnlineMonitor`);
    /// `max_gap` and `relative` are as for `signal`. `windows="complete"` gives a value
    /// only where every window it needs lies inside the trace (`hstlc monitor --online
    /// --windows complete`): a dense-time monitor gives each change point once it also lies
    /// before the complete end of the rows so far, and `finish()` ends with `(t, nan)`
    /// where the undetermined times start; a discrete-time one gives at `finish()` the
    /// verdicts of the steps whose windows lie inside the trace.
    #[pyo3(signature = (formula=None, *, windows="clipped", max_gap=None, relative=false))]
    fn online(
        slf: &Bound<'_, Self>,
        formula: Option<&str>,
        windows: &str,
        max_gap: Option<&Bound<'_, PyAny>>,
        relative: bool,
    ) -> PyResult<OnlineMonitor> {
        let this = slf.get();
        let windows = windows_of(windows)?;
        if this.spec.is_dense() {
            let monitor = this.dense(formula)?;
            let live = monitor
                .live(dense::max_gap(max_gap)?, windows, Front::Python)
                .map_err(|p| dense::problem_error(&p, &monitor, None))?
                .relative(relative);
            return Ok(OnlineMonitor::dense(
                monitor,
                live,
                slf.clone().into_any().unbind(),
                formula.map(String::from),
            ));
        }
        this.discrete_only(max_gap, relative)?;
        let inner = this.online_of(formula)?;
        Ok(OnlineMonitor::new(
            inner,
            windows,
            slf.clone().into_any().unbind(),
            formula.map(String::from),
        ))
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let this = slf.get();
        if let Some(text) = &this.formula {
            let args = PyTuple::new(py, [text.clone()])?;
            return Ok((slf.get_type().getattr("_unpickle_formula")?, args));
        }
        let parse = slf.get_type().getattr("_unpickle")?;
        let args = PyTuple::new(
            py,
            [
                this.source.clone().into_pyobject(py)?.into_any(),
                this.filename.clone().into_pyobject(py)?.into_any(),
                this.requested.clone().into_pyobject(py)?.into_any(),
            ],
        )?;
        Ok((parse, args))
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<Spec>().is_ok_and(|o| {
            let o = o.get();
            (&o.source, &o.filename, &o.spec.name)
                == (&self.source, &self.filename, &self.spec.name)
        })
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (&self.source, &self.filename, &self.spec.name).hash(&mut h);
        h.finish()
    }

    fn __repr__(&self) -> String {
        format!("<hstl.Spec {} from {}>", self.spec.name, self.filename)
    }
}
