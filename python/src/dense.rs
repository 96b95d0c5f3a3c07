//! Dense-time specs (a `NAME: time` state variable) from Python: traces as a time column
//! and one column per state variable, read into the facade's [`DenseTrace`]
//! ([`hstl::monitor::Dense::trace`]), signals returned as `(times, values)` arrays in the
//! time column's scale. The rules (which stamps stay whole numbers, their order, gaps,
//! complete windows) are the facade's, shared with `hstlc monitor`.

use hstl::monitor::{
    Dense, DenseProblem, Front, MaxGap, Stamp, StampColumn, TimeAxis, TraceError, signal_rows,
};
use hstl::robustness::dense::{DenseSignal, DenseTrace};
use numpy::{
    PyArray1, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyKeyError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

use crate::errors::{missing_variable, type_error, value_error, with_help};
use crate::trace::{column, float_array, is_mapping, type_name};

/// The name `max_gap=` errors give the setting.
pub const GAP_FLAG: &str = "max_gap=";

/// A time column, owned (converted from numpy once).
pub enum Stamps {
    Int(Vec<i64>),
    UInt(Vec<u64>),
    Real(Vec<f64>),
}

impl Stamps {
    fn column(&self) -> StampColumn<'_> {
        match self {
            Stamps::Int(v) => StampColumn::Int(v),
            Stamps::UInt(v) => StampColumn::UInt(v),
            Stamps::Real(v) => StampColumn::Real(v),
        }
    }
}

/// `max_gap=`: a number (read as Python writes it, the shortest text that reads back to
/// it) or a string such as `"0.5"`.
pub fn max_gap(gap: Option<&Bound<'_, PyAny>>) -> PyResult<Option<MaxGap>> {
    let Some(gap) = gap.filter(|g| !g.is_none()) else { return Ok(None) };
    if gap.is_instance_of::<pyo3::types::PyBool>() {
        return Err(type_error("`max_gap` must be a number or a string; got bool", None));
    }
    let text = if gap.is_instance_of::<PyString>() {
        gap.extract::<String>()?
    } else if gap.hasattr("__index__")? || gap.hasattr("__float__")? {
        gap.str()?.to_string()
    } else {
        return Err(type_error(
            format!("`max_gap` must be a number or a string; got {}", type_name(gap)),
            None,
        ));
    };
    MaxGap::parse(&text, GAP_FLAG).map(Some).map_err(|p| value_error(p.message, p.help))
}

/// The error for `max_gap=` or `relative=` given with a discrete-time spec.
pub fn dense_only(spec: &str, what: &str) -> PyErr {
    value_error(
        format!(
            "`{what}` is for dense-time specs, and spec `{spec}` counts steps (it has no `time` \
             variable)"
        ),
        Some(format!(
            "leave out `{what}`, or give the spec a state variable `t: time` whose column holds \
             each row's time stamp"
        )),
    )
}

/// A problem of the facade's as a `ValueError`, where it is in the trace said first
/// (`row R (counted from 0), column `x`: ...`), a time in the column's scale.
pub fn problem_error(p: &DenseProblem, dense: &Dense, axis: Option<&TimeAxis>) -> PyErr {
    let column = p.var.and_then(|v| dense.state_vars().get(v));
    let at = match (p.row, column) {
        (Some(r), Some(c)) => format!("row {r} (counted from 0), column `{c}`: "),
        (Some(r), None) => format!("row {r} (counted from 0): "),
        (None, _) => String::new(),
    };
    let when = match (p.time, axis) {
        (Some(t), Some(axis)) => format!(" at time {}", axis.text(t)),
        (Some(t), None) => format!(" at time {t}"),
        (None, _) => String::new(),
    };
    PyValueError::new_err(with_help(format!("{at}{}{when}", p.message), p.help.clone()))
}

/// One dense-time trace: a mapping (dict, DataFrame, structured array) with the time column
/// and a column per state variable, all 1-D of one length; NaN in a variable's column is no
/// new sample.
pub fn hold<'py>(
    trace: &Bound<'py, PyAny>,
    columns: Option<&Bound<'py, PyAny>>,
    dense: &Dense,
) -> PyResult<(Stamps, Vec<Bound<'py, PyArrayDyn<f64>>>)> {
    if columns.is_some_and(|c| !c.is_none()) {
        return Err(type_error(
            "`columns` names the columns of a 2-D array, and a dense-time trace is a mapping",
            Some("leave out `columns`".into()),
        ));
    }
    let structured = match trace.cast::<PyUntypedArray>() {
        Ok(a) => {
            let names = a.dtype().getattr("names")?;
            if names.is_none() {
                return Err(not_a_mapping(trace));
            }
            Some(names.extract::<Vec<String>>()?)
        }
        Err(_) => None,
    };
    if structured.is_none() && !is_mapping(trace)? {
        return Err(not_a_mapping(trace));
    }
    let time = lookup(trace, dense.time_var(), structured.as_deref(), dense)?;
    let stamps = stamps(&time, dense.time_var())?;
    let mut arrays = Vec::with_capacity(dense.state_vars().len());
    for var in dense.state_vars() {
        let value = lookup(trace, var, structured.as_deref(), dense)?;
        let array = float_array(&value, &format!("state variable `{var}`"))?;
        if array.ndim() != 1 {
            return Err(value_error(
                format!("state variable `{var}` must be 1-D, one value per row"),
                None,
            ));
        }
        arrays.push(array);
    }
    Ok((stamps, arrays))
}

/// Builds the trace from what [`hold`] took, copying it out of the arrays with the GIL held.
pub fn build(
    _py: Python<'_>,
    held: &(Stamps, Vec<Bound<'_, PyArrayDyn<f64>>>),
    dense: &Dense,
    gap: Option<&MaxGap>,
) -> PyResult<DenseTrace> {
    let (stamps, arrays) = held;
    let readonly: Vec<_> = arrays
        .iter()
        .map(|a| {
            a.try_readonly()
                .map_err(|e| value_error(format!("the array cannot be read: {e}"), None))
        })
        .collect::<PyResult<_>>()?;
    let slices: Vec<&[f64]> = readonly
        .iter()
        .map(|a| {
            a.as_slice().map_err(|e| value_error(format!("the array cannot be read: {e}"), None))
        })
        .collect::<PyResult<_>>()?;
    // With the GIL held (`_py`): no other Python thread writes to the arrays while the
    // trace is checked and copied out of them.
    dense
        .trace(stamps.column(), &slices, gap.cloned(), Front::Python)
        .map_err(|p| problem_error(&p, dense, None))
}

fn not_a_mapping(trace: &Bound<'_, PyAny>) -> PyErr {
    type_error(
        format!(
            "a dense-time trace is a mapping from the time variable and the state variables to \
             1-D arrays; got {}",
            type_name(trace)
        ),
        Some(
            "pass a dict such as `{\"t\": stamps, \"x\": xs}` or a pandas DataFrame (NaN where a \
             variable has no new sample)"
                .into(),
        ),
    )
}

/// `trace[name]`, or `hstl.MissingVariableError` naming what is there.
fn lookup<'py>(
    trace: &Bound<'py, PyAny>,
    name: &str,
    fields: Option<&[String]>,
    dense: &Dense,
) -> PyResult<Bound<'py, PyAny>> {
    let py = trace.py();
    let mut vars = vec![dense.time_var().to_string()];
    vars.extend(dense.state_vars().iter().cloned());
    let missing = |known: Vec<String>| {
        let known = Some(known).filter(|k| !k.is_empty());
        let e = TraceError::Missing { var: name.to_string(), known, vars: vars.clone() };
        let mut text = with_help(e.to_string(), e.help());
        if name == dense.time_var() {
            text = with_help(
                format!(
                    "the time column `{name}` is missing: a dense-time trace needs each row's \
                     time stamp"
                ),
                Some(format!(
                    "add a column `{name}` (seconds, or whole-number nanoseconds as ROS 2 \
                     writes them)"
                )),
            );
        }
        missing_variable(py, text)
    };
    column(trace, name, fields, missing)
}

/// The time column: integers kept whole (int64, uint64; datetime64 as nanoseconds),
/// anything else as float64.
fn stamps(obj: &Bound<'_, PyAny>, time: &str) -> PyResult<Stamps> {
    let py = obj.py();
    let np = py.import("numpy")?;
    let array = np.call_method1("asarray", (obj,)).map_err(|e| {
        value_error(
            format!("the time column `{time}` is not an array of numbers: {}", e.value(py)),
            None,
        )
    })?;
    let array = array.cast_into::<PyUntypedArray>()?;
    if array.ndim() != 1 {
        return Err(value_error(
            format!("the time column `{time}` must be 1-D, one stamp per row"),
            None,
        ));
    }
    let kind = array.dtype().kind();
    let as_type = |dtype: &str| -> PyResult<Bound<'_, PyAny>> {
        let kwargs = PyDict::new(py);
        kwargs.set_item("dtype", dtype)?;
        np.call_method("ascontiguousarray", (&array,), Some(&kwargs))
    };
    match kind {
        b'i' => Ok(Stamps::Int(as_type("int64")?.cast_into::<PyArray1<i64>>()?.to_vec()?)),
        b'u' => Ok(Stamps::UInt(as_type("uint64")?.cast_into::<PyArray1<u64>>()?.to_vec()?)),
        b'M' => {
            let ns = as_type("datetime64[ns]")?.call_method1("view", ("int64",))?;
            Ok(Stamps::Int(ns.cast_into::<PyArray1<i64>>()?.to_vec()?))
        }
        b'f' => Ok(Stamps::Real(as_type("float64")?.cast_into::<PyArray1<f64>>()?.to_vec()?)),
        _ => Err(type_error(
            format!("the time column `{time}` holds values of dtype {}, not numbers", array.dtype().str()?),
            Some("give each row's stamp as a number (seconds as floats, or whole nanoseconds as int64)".into()),
        )),
    }
}

/// The change points as numpy arrays `(times, values)`: times in the column's scale (int64
/// for whole-number stamps beyond 2^53, float64 otherwise; float64 relative to the first
/// stamp with `relative`), values float64 with NaN for the undetermined rest (complete
/// windows).
pub fn arrays<'py>(
    py: Python<'py>,
    signal: &DenseSignal,
    end: Option<f64>,
    trace: &DenseTrace,
    relative: bool,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyArray1<f64>>)> {
    let axis = TimeAxis { relative, origin: trace.origin(), t0: trace.t0() };
    let rows = signal_rows(signal, trace.t0(), trace.t_last(), end);
    let values: Vec<f64> = rows.iter().map(|r| r.1.unwrap_or(f64::NAN)).collect();
    let values = PyArray1::from_vec(py, values);
    if axis.origin.is_some() && !relative {
        let mut whole = Vec::with_capacity(rows.len());
        for &(t, _) in &rows {
            let Some(n) = axis.whole(t) else {
                return Err(between_stamps(&axis.text(t)));
            };
            whole.push(n);
        }
        let times = match whole.iter().map(|&n| i64::try_from(n)).collect::<Result<Vec<_>, _>>() {
            Ok(v) => PyArray1::from_vec(py, v).into_any(),
            Err(_) => PyArray1::from_vec(
                py,
                whole.iter().map(|&n| u64::try_from(n).unwrap_or(u64::MAX)).collect::<Vec<_>>(),
            )
            .into_any(),
        };
        return Ok((times, values));
    }
    let times: Vec<f64> = rows.iter().map(|&(t, _)| axis.double(t)).collect();
    Ok((PyArray1::from_vec(py, times).into_any(), values))
}

/// A change point between two whole-number stamps, which an integer cannot hold.
pub fn between_stamps(text: &str) -> PyErr {
    value_error(
        format!(
            "a change point falls between two whole-number stamps, at {text}, which an integer \
             time cannot hold exactly"
        ),
        Some(
            "pass `relative=True` for float64 times from the first stamp (exact), or write the \
             spec's bounds in whole units of the time column"
                .into(),
        ),
    )
}

/// A stamp given to `OnlineMonitor.update`: a Python int stays whole, anything else is a
/// float.
pub fn stamp(t: &Bound<'_, PyAny>) -> PyResult<Stamp> {
    if t.is_instance_of::<pyo3::types::PyBool>() {
        return Err(type_error("a time stamp must be a number; got bool", None));
    }
    if t.hasattr("__index__")? {
        let n: i128 = t.call_method0("__index__")?.extract().map_err(|_| {
            value_error("the time stamp is too large", Some("give stamps within 64 bits".into()))
        })?;
        if !(i128::from(i64::MIN)..=i128::from(u64::MAX)).contains(&n) {
            return Err(value_error(
                format!("the time stamp {n} is too large"),
                Some("give stamps within 64 bits".into()),
            ));
        }
        return Ok(Stamp::Int(n));
    }
    t.extract::<f64>().map(Stamp::Real).map_err(|_| {
        type_error(format!("a time stamp must be a number; got {}", type_name(t)), None)
    })
}

/// One row for `OnlineMonitor.update`: a mapping (a variable it leaves out, or gives as
/// None or NaN, has no new sample) or a sequence of one number per state variable (NaN: no
/// new sample).
pub fn cells(state: &Bound<'_, PyAny>, vars: &[String]) -> PyResult<Vec<Option<f64>>> {
    let number = |v: &Bound<'_, PyAny>, var: &str| -> PyResult<Option<f64>> {
        if v.is_none() {
            return Ok(None);
        }
        let x: f64 = v.extract().map_err(|_| {
            type_error(format!("`{var}` must be a number; got {}", type_name(v)), None)
        })?;
        Ok((!x.is_nan()).then_some(x))
    };
    if is_mapping(state)? {
        return vars
            .iter()
            .map(|var| match state.get_item(var) {
                Ok(v) => number(&v, var),
                Err(e) if e.is_instance_of::<PyKeyError>(state.py()) => Ok(None),
                Err(e) => Err(e),
            })
            .collect();
    }
    if state.is_instance_of::<PyString>() {
        return Err(type_error("a state is a mapping or a sequence of numbers; got str", None));
    }
    let items: Vec<Bound<'_, PyAny>> = state
        .try_iter()
        .map_err(|_| {
            type_error(
                format!("a state is a mapping or a sequence of numbers; got {}", type_name(state)),
                Some(
                    "pass a dict such as `{\"x\": 1.5}` (a variable left out has no new sample)"
                        .into(),
                ),
            )
        })?
        .collect::<PyResult<_>>()?;
    if items.len() != vars.len() {
        return Err(value_error(
            format!("the state has {} values for {} state variables", items.len(), vars.len()),
            Some("give one value per state variable (NaN: no new sample), or a dict".into()),
        ));
    }
    items.iter().zip(vars).map(|(v, var)| number(v, var)).collect()
}

/// Whether `obj` is one trace (a mapping or a structured array) rather than a batch.
pub fn is_one_trace(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    // No array is a dense batch: traces differ in length, so a batch is a list.
    Ok(obj.cast::<PyUntypedArray>().is_ok() || is_mapping(obj)?)
}

/// `trace I: ` before an exception's message, keeping its type.
pub fn prefixed(py: Python<'_>, e: PyErr, i: usize) -> PyErr {
    let value = e.value(py);
    let message = value
        .getattr("args")
        .ok()
        .and_then(|a| a.get_item(0).ok())
        .and_then(|m| m.extract::<String>().ok());
    match message.map(|m| value.get_type().call1((format!("trace {i}: {m}"),))) {
        Some(Ok(new)) => PyErr::from_value(new),
        _ => e,
    }
}
