//! Python traces as the facade's borrowed samples.
//!
//! A trace is a mapping from state variable names to 1-D arrays or sequences (a dict, a
//! pandas DataFrame, a numpy structured array: anything with `keys()` and `[name]`), or a
//! 2-D array of shape (steps, columns) whose columns are named by `columns` (by default the
//! spec's state variables, in order). Contiguous float64 arrays are read in place; anything
//! else numpy converts to float64 once. The samples are copied out while the GIL is held
//! ([`Copied`]), so that what the facade scores with the GIL released is what it checked.

use hstl::monitor::{Monitor, Samples, TraceError};
use numpy::{
    PyArray1, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyBytes, PyDict, PyList, PyString, PyTuple};

use crate::errors::{trace_error, type_error, value_error};

/// One trace's arrays, borrowed read-only, and how its samples lie in them.
pub enum Held<'py> {
    /// One 1-D contiguous float64 array per state variable, in the spec's order.
    Columns(Vec<PyReadonlyArrayDyn<'py, f64>>),
    /// A 2-D float64 array of shape (steps, width), contiguous in C order (row-major) or
    /// Fortran order (column-major); `picks[i]` is state variable `i`'s column.
    Matrix {
        array: PyReadonlyArrayDyn<'py, f64>,
        fortran: bool,
        steps: usize,
        width: usize,
        picks: Vec<usize>,
    },
}

/// Many traces' arrays.
pub enum HeldBatch<'py> {
    /// Each trace on its own.
    Each(Vec<Held<'py>>),
    /// A C-ordered float64 array of shape (traces, steps, width).
    Cube {
        array: PyReadonlyArrayDyn<'py, f64>,
        traces: usize,
        steps: usize,
        width: usize,
        picks: Vec<usize>,
    },
    /// One C-ordered float64 array of shape (traces, steps) per state variable.
    PerVariable { arrays: Vec<PyReadonlyArrayDyn<'py, f64>>, traces: usize, steps: usize },
}

impl Held<'_> {
    /// The samples, borrowed from the arrays.
    pub fn samples(&self) -> PyResult<Samples<'_>> {
        match self {
            Held::Columns(arrays) => {
                Ok(Samples::Columns(arrays.iter().map(|a| slice(a)).collect::<PyResult<Vec<_>>>()?))
            }
            Held::Matrix { array, fortran: false, width, picks, .. } => {
                Ok(Samples::Rows { data: slice(array)?, width: *width, picks: picks.clone() })
            }
            Held::Matrix { array, fortran: true, steps, picks, .. } => {
                let data = slice(array)?;
                let column = |p: usize| data.get(p * steps..(p + 1) * steps).ok_or_else(layout);
                Ok(Samples::Columns(picks.iter().map(|&p| column(p)).collect::<PyResult<_>>()?))
            }
        }
    }
}

/// A trace's samples copied out of its arrays while the GIL is held: once it is released,
/// another Python thread may write to the arrays, and the facade must score the values it
/// checked. The copies go into buffers kept from earlier calls on the same thread
/// ([`Copied::recycle`]): fresh memory costs a page fault every 4 KiB, three times the
/// evaluation of a simple task; kept buffers cost a memory copy.
pub enum Copied {
    /// One column per state variable, in the spec's order.
    Columns(Vec<Vec<f64>>),
    /// Row-major samples, as [`Samples::Rows`].
    Rows { data: Vec<f64>, width: usize, picks: Vec<usize> },
}

/// At most this many values of buffers are kept for the next copy on a thread (32 MiB).
const SPARE_VALUES: usize = 1 << 22;

thread_local! {
    /// Buffers of earlier copies on this thread, for the next.
    static SPARE: std::cell::RefCell<Vec<Vec<f64>>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// A copy of `values` in a kept buffer when there is one.
fn copy_of(values: &[f64]) -> Vec<f64> {
    let mut out = SPARE.with(|s| s.borrow_mut().pop()).unwrap_or_default();
    out.clear();
    out.extend_from_slice(values);
    out
}

impl Copied {
    /// A copy of `samples`.
    pub fn of(samples: &Samples<'_>) -> Copied {
        Copied::prefix(samples, usize::MAX)
    }

    /// A copy of the first `steps` steps of `samples` (all of them when there are fewer),
    /// for a call that reads no further.
    pub fn prefix(samples: &Samples<'_>, steps: usize) -> Copied {
        match samples {
            Samples::Columns(cols) => {
                Copied::Columns(cols.iter().map(|c| copy_of(&c[..steps.min(c.len())])).collect())
            }
            Samples::Rows { data, width, picks } => {
                let end = steps.saturating_mul(*width).min(data.len());
                Copied::Rows { data: copy_of(&data[..end]), width: *width, picks: picks.clone() }
            }
        }
    }

    /// The samples, borrowed from the copy.
    pub fn samples(&self) -> Samples<'_> {
        match self {
            Copied::Columns(cols) => Samples::Columns(cols.iter().map(Vec::as_slice).collect()),
            Copied::Rows { data, width, picks } => {
                Samples::Rows { data, width: *width, picks: picks.clone() }
            }
        }
    }

    /// How many values the copy holds.
    pub fn values(&self) -> usize {
        match self {
            Copied::Columns(cols) => cols.iter().map(Vec::len).sum(),
            Copied::Rows { data, .. } => data.len(),
        }
    }

    /// Keeps the copy's buffers for the next copy on this thread, up to [`SPARE_VALUES`].
    pub fn recycle(self) {
        let buffers = match self {
            Copied::Columns(cols) => cols,
            Copied::Rows { data, .. } => vec![data],
        };
        SPARE.with(|s| {
            let mut spare = s.borrow_mut();
            let mut kept: usize = spare.iter().map(Vec::capacity).sum();
            for b in buffers {
                if kept + b.capacity() <= SPARE_VALUES {
                    kept += b.capacity();
                    spare.push(b);
                }
            }
        });
    }
}

impl Held<'_> {
    /// The samples, copied while the GIL is held.
    pub fn copied(&self) -> PyResult<Copied> {
        Ok(Copied::of(&self.samples()?))
    }
}

impl HeldBatch<'_> {
    /// Each trace's samples, copied while the GIL is held.
    pub fn copied(&self) -> PyResult<Vec<Copied>> {
        Ok(self.samples()?.iter().map(Copied::of).collect())
    }

    /// The steps the batch's shape gives, when it has a shape (an array of no traces still
    /// has steps).
    pub fn shape_steps(&self) -> Option<usize> {
        match self {
            HeldBatch::Each(_) => None,
            HeldBatch::Cube { steps, .. } | HeldBatch::PerVariable { steps, .. } => Some(*steps),
        }
    }

    /// Every trace's samples, borrowed from the arrays.
    pub fn samples(&self) -> PyResult<Vec<Samples<'_>>> {
        match self {
            HeldBatch::Each(held) => held.iter().map(Held::samples).collect(),
            HeldBatch::Cube { array, traces, steps, width, picks } => {
                let data = slice(array)?;
                let per = steps * width;
                (0..*traces)
                    .map(|i| {
                        let data = data.get(i * per..(i + 1) * per).ok_or_else(layout)?;
                        Ok(Samples::Rows { data, width: *width, picks: picks.clone() })
                    })
                    .collect()
            }
            HeldBatch::PerVariable { arrays, traces, steps } => {
                let data = arrays.iter().map(|a| slice(a)).collect::<PyResult<Vec<_>>>()?;
                (0..*traces)
                    .map(|i| {
                        let rows = data.iter().map(|d| d.get(i * steps..(i + 1) * steps));
                        Ok(Samples::Columns(rows.collect::<Option<Vec<_>>>().ok_or_else(layout)?))
                    })
                    .collect()
            }
        }
    }
}

/// Borrows one trace.
pub fn hold<'py>(
    trace: &Bound<'py, PyAny>,
    columns: Option<&Bound<'py, PyAny>>,
    monitor: &Monitor,
) -> PyResult<Held<'py>> {
    let py = trace.py();
    if let Ok(array) = trace.cast::<PyUntypedArray>() {
        if let Some(names) = field_names(array)? {
            no_columns(columns, "a structured array names its own fields")?;
            return hold_mapping(trace, Some(names), monitor);
        }
        if array.ndim() != 2 {
            return Err(value_error(
                format!("a trace array must be 2-D (steps, columns); got shape {}", shape(array)),
                Some(
                    "for one state variable pass `{\"x\": array}` or `array[:, None]`; for \
                     many traces call `signal_batch`"
                        .into(),
                ),
            ));
        }
        let (steps, width) = (array.shape()[0], array.shape()[1]);
        let picks = picks(py, columns, width, monitor, "the array")?;
        let array = float_array(trace, "the trace")?;
        let fortran = !array.is_c_contiguous();
        return Ok(Held::Matrix { array: readonly(&array)?, fortran, steps, width, picks });
    }
    if is_mapping(trace)? {
        no_columns(columns, "a mapping names its own columns")?;
        return hold_mapping(trace, None, monitor);
    }
    Err(type_error(
        format!(
            "a trace is a mapping from state variable names to arrays, or a 2-D array; got {}",
            type_name(trace)
        ),
        Some(
            "pass a dict such as `{\"x\": xs, \"y\": ys}`, a pandas DataFrame, or a numpy array \
             of shape (steps, columns)"
                .into(),
        ),
    ))
}

/// Borrows many traces: a list (any iterable) of traces, a 3-D array of shape (traces,
/// steps, columns), or a mapping from state variable names to 2-D arrays (traces, steps).
pub fn hold_batch<'py>(
    traces: &Bound<'py, PyAny>,
    columns: Option<&Bound<'py, PyAny>>,
    monitor: &Monitor,
) -> PyResult<HeldBatch<'py>> {
    let py = traces.py();
    if let Ok(array) = traces.cast::<PyUntypedArray>() {
        if array.ndim() != 3 || field_names(array)?.is_some() {
            return Err(value_error(
                format!(
                    "a batch array must be 3-D (traces, steps, columns) of numbers; got shape {}",
                    shape(array)
                ),
                Some("for one trace call `signal`".into()),
            ));
        }
        let (n, steps, width) = (array.shape()[0], array.shape()[1], array.shape()[2]);
        let picks = picks(py, columns, width, monitor, "the batch array")?;
        let array = c_float_array(traces, "the batch")?;
        return Ok(HeldBatch::Cube { array: readonly(&array)?, traces: n, steps, width, picks });
    }
    if is_mapping(traces)? {
        no_columns(columns, "a mapping names its own columns")?;
        return hold_per_variable(traces, monitor);
    }
    if traces.is_instance_of::<PyString>() || traces.is_instance_of::<PyBytes>() {
        return Err(type_error(
            format!("a batch is a list of traces or a 3-D array; got {}", type_name(traces)),
            None,
        ));
    }
    let items = traces.try_iter().map_err(|_| {
        type_error(
            format!("a batch is a list of traces or a 3-D array; got {}", type_name(traces)),
            Some("pass a list of dicts or DataFrames, or an array (traces, steps, columns)".into()),
        )
    })?;
    let mut held = Vec::new();
    for (i, item) in items.enumerate() {
        held.push(
            hold(&item?, columns, monitor).map_err(|e| prefix(py, e, &format!("trace {i}: ")))?,
        );
    }
    Ok(HeldBatch::Each(held))
}

/// The values of one state for the online monitor: a mapping from names to numbers, or a
/// sequence of numbers in the order of the spec's state variables.
pub fn state_values(state: &Bound<'_, PyAny>, vars: &[String]) -> PyResult<Vec<f64>> {
    let py = state.py();
    let number = |v: Bound<'_, PyAny>, var: &str| {
        v.extract::<f64>().map_err(|_| {
            type_error(format!("`{var}` must be a number; got {}", type_name(&v)), None)
        })
    };
    // The common kinds first, without the attribute lookups (and the exceptions they
    // raise) that tell any mapping from any sequence: this runs at every step of an
    // environment.
    if let Ok(dict) = state.cast_exact::<PyDict>() {
        return vars
            .iter()
            .map(|var| match dict.get_item(var)? {
                Some(v) => number(v, var),
                None => Err(missing(py, var, Some(keys(state)), vars)),
            })
            .collect();
    }
    let numbers = |items: &mut dyn Iterator<Item = Bound<'_, PyAny>>| {
        items
            .zip(vars.iter().chain(std::iter::repeat(&String::new())))
            .map(|(v, var)| number(v, if var.is_empty() { "a value" } else { var }))
            .collect::<PyResult<Vec<f64>>>()
    };
    if let Ok(tuple) = state.cast_exact::<PyTuple>() {
        return numbers(&mut tuple.iter());
    }
    if let Ok(list) = state.cast_exact::<PyList>() {
        return numbers(&mut list.iter());
    }
    if let Ok(array) = state.cast::<PyArray1<f64>>().map(|a| a.try_readonly())
        && let Ok(array) = array
    {
        return Ok(array.as_array().to_vec());
    }
    if let Ok(array) = state.cast::<PyArray1<i64>>().map(|a| a.try_readonly())
        && let Ok(array) = array
    {
        return Ok(array.as_array().iter().map(|&v| v as f64).collect());
    }
    if is_mapping(state)? {
        return vars
            .iter()
            .map(|var| match state.get_item(var) {
                Ok(v) => number(v, var),
                Err(e) if e.is_instance_of::<PyKeyError>(py) => {
                    Err(missing(py, var, Some(keys(state)), vars))
                }
                Err(e) => Err(e),
            })
            .collect();
    }
    if state.is_instance_of::<PyString>() {
        return Err(type_error("a state is a mapping or a sequence of numbers; got str", None));
    }
    let items = state.try_iter().map_err(|_| {
        type_error(
            format!("a state is a mapping or a sequence of numbers; got {}", type_name(state)),
            Some("pass a dict such as `{\"x\": 1, \"y\": 2}`".into()),
        )
    })?;
    let values = items
        .zip(vars.iter().chain(std::iter::repeat(&String::new())))
        .map(|(v, var)| number(v?, if var.is_empty() { "a value" } else { var }))
        .collect::<PyResult<Vec<f64>>>()?;
    Ok(values)
}

/// One trace given as a mapping, or a structured array with these field names.
fn hold_mapping<'py>(
    trace: &Bound<'py, PyAny>,
    fields: Option<Vec<String>>,
    monitor: &Monitor,
) -> PyResult<Held<'py>> {
    let mut arrays = Vec::with_capacity(monitor.state_vars().len());
    for var in monitor.state_vars() {
        let value = lookup(trace, var, fields.as_deref(), monitor)?;
        let array = float_array(&value, &format!("state variable `{var}`"))?;
        if array.ndim() != 1 {
            return Err(value_error(
                format!(
                    "state variable `{var}` must be 1-D, one sample per step; got shape {}",
                    shape(array.as_untyped())
                ),
                None,
            ));
        }
        arrays.push(readonly(&array)?);
    }
    Ok(Held::Columns(arrays))
}

/// A batch given as a mapping from state variable names to 2-D arrays (traces, steps).
fn hold_per_variable<'py>(
    traces: &Bound<'py, PyAny>,
    monitor: &Monitor,
) -> PyResult<HeldBatch<'py>> {
    let mut arrays = Vec::with_capacity(monitor.state_vars().len());
    let mut first: Option<(String, Vec<usize>)> = None;
    for var in monitor.state_vars() {
        let value = lookup(traces, var, None, monitor)?;
        let array = c_float_array(&value, &format!("state variable `{var}`"))?;
        let dims = array.shape().to_vec();
        if dims.len() != 2 {
            return Err(value_error(
                format!(
                    "in a batch, state variable `{var}` must be 2-D (traces, steps); got shape {}",
                    shape(array.as_untyped())
                ),
                Some("for one trace call `signal`".into()),
            ));
        }
        match &first {
            Some((name, d)) if *d != dims => {
                return Err(value_error(
                    format!(
                        "state variable `{var}` has shape {}, but `{name}` has {}",
                        tuple(&dims),
                        tuple(d)
                    ),
                    Some("give every state variable one sample per trace and step".into()),
                ));
            }
            Some(_) => {}
            None => first = Some((var.clone(), dims)),
        }
        arrays.push(readonly(&array)?);
    }
    let (traces, steps) = first.map_or((0, 0), |(_, d)| (d[0], d[1]));
    Ok(HeldBatch::PerVariable { arrays, traces, steps })
}

/// `trace[var]`, or the error `hstlc monitor` gives for a missing column.
fn lookup<'py>(
    trace: &Bound<'py, PyAny>,
    var: &str,
    fields: Option<&[String]>,
    monitor: &Monitor,
) -> PyResult<Bound<'py, PyAny>> {
    let py = trace.py();
    column(trace, var, fields, |known| missing(py, var, Some(known), monitor.state_vars()))
}

/// `trace[var]`; where `fields` (a record array's names) or the mapping has no `var`, the
/// error `missing` makes from the names there are.
pub fn column<'py>(
    trace: &Bound<'py, PyAny>,
    var: &str,
    fields: Option<&[String]>,
    missing: impl Fn(Vec<String>) -> PyErr,
) -> PyResult<Bound<'py, PyAny>> {
    if let Some(fields) = fields
        && !fields.iter().any(|f| f == var)
    {
        return Err(missing(fields.to_vec()));
    }
    match trace.get_item(var) {
        Ok(v) => Ok(v),
        Err(e) if e.is_instance_of::<PyKeyError>(trace.py()) => Err(missing(keys(trace))),
        Err(e) => Err(e),
    }
}

fn missing(py: Python<'_>, var: &str, known: Option<Vec<String>>, vars: &[String]) -> PyErr {
    let known = known.filter(|k| !k.is_empty());
    trace_error(py, &TraceError::Missing { var: var.to_string(), known, vars: vars.to_vec() })
}

/// The names of a mapping's keys, as text; empty when it has none or they cannot be listed.
pub fn keys(mapping: &Bound<'_, PyAny>) -> Vec<String> {
    let Ok(keys) = mapping.call_method0("keys").and_then(|k| k.try_iter()) else {
        return Vec::new();
    };
    keys.filter_map(|k| k.ok()?.str().ok().map(|s| s.to_string())).collect()
}

/// For each state variable, its column among `columns` (or the state variables in order).
fn picks(
    py: Python<'_>,
    columns: Option<&Bound<'_, PyAny>>,
    width: usize,
    monitor: &Monitor,
    what: &str,
) -> PyResult<Vec<usize>> {
    let vars = monitor.state_vars();
    let names: Vec<String> = match columns {
        Some(c) if !c.is_none() => {
            if c.is_instance_of::<PyString>() {
                return Err(type_error("`columns` must be a sequence of names; got str", None));
            }
            let names: Vec<String> = c.extract().map_err(|_| {
                type_error(
                    format!("`columns` must be a sequence of names (str); got {}", type_name(c)),
                    None,
                )
            })?;
            if names.len() != width {
                return Err(value_error(
                    format!("`columns` names {} columns, but {what} has {width}", names.len()),
                    Some("give one name per column of the array".into()),
                ));
            }
            names
        }
        _ => {
            if width != vars.len() {
                return Err(value_error(
                    format!(
                        "{what} has {width} column{}, but the spec has {} state variable{}",
                        plural(width),
                        vars.len(),
                        plural(vars.len())
                    ),
                    Some(format!(
                        "name the columns with `columns=[...]`, or give them in the order {}",
                        quote_list(vars)
                    )),
                ));
            }
            vars.to_vec()
        }
    };
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    monitor.picks(&names).map_err(|e| trace_error(py, &e))
}

/// `obj` as a float64 array contiguous in C or Fortran order: itself when it is one,
/// otherwise converted by numpy once. Refuses anything but booleans, integers and floats.
pub fn float_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>()
        && (a.is_c_contiguous() || a.is_fortran_contiguous())
    {
        return Ok(a.clone());
    }
    convert(obj, what)
}

/// As [`float_array`], but contiguous in C order.
fn c_float_array<'py>(
    obj: &Bound<'py, PyAny>,
    what: &str,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>()
        && a.is_c_contiguous()
    {
        return Ok(a.clone());
    }
    convert(obj, what)
}

/// `numpy.asarray(obj, dtype=float64, order="C")` once `obj` is known to hold numbers.
fn convert<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let py = obj.py();
    let array = numpy_function(py, &ASARRAY, "asarray")?.call1((obj,)).map_err(|e| {
        if e.is_instance_of::<PyValueError>(py) || e.is_instance_of::<PyTypeError>(py) {
            value_error(format!("{what} is not an array of numbers: {}", e.value(py)), None)
        } else {
            e
        }
    })?;
    let array = array.cast_into::<PyUntypedArray>()?;
    let dtype = array.dtype();
    if !matches!(dtype.kind(), b'b' | b'i' | b'u' | b'f') {
        return Err(type_error(
            format!("{what} holds values of dtype {}, not numbers", dtype.str()?),
            Some("give int or float values".into()),
        ));
    }
    // `asarray` keeps a 0-d array 0-d (where `ascontiguousarray` would make it 1-d), so
    // the callers' shape checks see what was given.
    let kwargs = PyDict::new(py);
    kwargs.set_item("dtype", "float64")?;
    kwargs.set_item("order", "C")?;
    let converted = numpy_function(py, &ASARRAY, "asarray")?.call((array,), Some(&kwargs))?;
    Ok(converted.cast_into::<PyArrayDyn<f64>>()?)
}

static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();

fn numpy_function<'py>(
    py: Python<'py>,
    cell: &'static PyOnceLock<Py<PyAny>>,
    name: &str,
) -> PyResult<&'py Bound<'py, PyAny>> {
    cell.import(py, "numpy", name)
}

fn readonly<'py>(a: &Bound<'py, PyArrayDyn<f64>>) -> PyResult<PyReadonlyArrayDyn<'py, f64>> {
    a.try_readonly().map_err(|e| value_error(format!("the array cannot be read: {e}"), None))
}

fn slice<'a>(a: &'a PyReadonlyArrayDyn<'_, f64>) -> PyResult<&'a [f64]> {
    a.as_slice().map_err(|e| value_error(format!("the array cannot be read: {e}"), None))
}

fn layout() -> PyErr {
    value_error("the array's data does not match its shape", None)
}

/// A structured array's field names.
fn field_names(array: &Bound<'_, PyUntypedArray>) -> PyResult<Option<Vec<String>>> {
    let names = array.dtype().getattr("names")?;
    if names.is_none() { Ok(None) } else { Ok(Some(names.extract()?)) }
}

pub fn is_mapping(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    Ok(obj.hasattr("keys")? && obj.hasattr("__getitem__")? && !obj.is_instance_of::<PyString>())
}

fn no_columns(columns: Option<&Bound<'_, PyAny>>, why: &str) -> PyResult<()> {
    match columns {
        Some(c) if !c.is_none() => Err(type_error(
            format!("`columns` names the columns of a 2-D array; {why}"),
            Some("leave out `columns`".into()),
        )),
        _ => Ok(()),
    }
}

/// Adds `text` before an exception's message, keeping its type.
fn prefix(py: Python<'_>, e: PyErr, text: &str) -> PyErr {
    let value = e.value(py);
    let message = value
        .getattr("args")
        .ok()
        .and_then(|a| a.get_item(0).ok())
        .and_then(|m| m.extract::<String>().ok());
    match message {
        Some(m) => match value.get_type().call1((format!("{text}{m}"),)) {
            Ok(new) => PyErr::from_value(new),
            Err(_) => e,
        },
        None => e,
    }
}

fn shape(array: &Bound<'_, PyUntypedArray>) -> String {
    tuple(array.shape())
}

fn tuple(dims: &[usize]) -> String {
    match dims {
        [one] => format!("({one},)"),
        _ => format!("({})", dims.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")),
    }
}

pub fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type().name().map_or_else(|_| "an object".into(), |n| n.to_string())
}

fn plural(n: usize) -> &'static str {
    if n == 1 { "" } else { "s" }
}

fn quote_list(names: &[String]) -> String {
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}
