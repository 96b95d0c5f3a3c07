//! The facade's errors as Python exceptions, worded as the command line words them.
//!
//! A message with a hint reads `message` then `\n  help: hint`, as `hstlc` prints it.

use std::path::Path;

use hstl::lang::{Diagnostic as LangDiagnostic, LineIndex};
use hstl::load::LoadError;
use hstl::lower::LowerError;
use hstl::monitor::{BatchError, TraceError};
use pyo3::exceptions::{
    PyFileNotFoundError, PyIsADirectoryError, PyOSError, PyPermissionError, PyValueError,
};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyType;

use crate::spec::Diagnostic;

/// `message`, and the hint on a line of its own.
pub fn with_help(message: impl Into<String>, help: Option<String>) -> String {
    let mut text = message.into();
    if let Some(help) = help {
        text.push_str("\n  help: ");
        text.push_str(&help);
    }
    text
}

/// A `ValueError` with a hint.
pub fn value_error(message: impl Into<String>, help: Option<String>) -> PyErr {
    PyValueError::new_err(with_help(message, help))
}

/// A `TypeError` with a hint.
pub fn type_error(message: impl Into<String>, help: Option<String>) -> PyErr {
    pyo3::exceptions::PyTypeError::new_err(with_help(message, help))
}

/// `hstl.SpecError(message, diagnostics)`.
pub fn spec_error(py: Python<'_>, message: String, diagnostics: Vec<Diagnostic>) -> PyErr {
    match python_class(py, &SPEC_ERROR, "SpecError")
        .and_then(|cls| cls.call1((message.clone(), diagnostics)))
    {
        Ok(e) => PyErr::from_value(e),
        Err(e) => e,
    }
}

/// A missing state variable: `hstl.MissingVariableError`, a `KeyError`.
pub fn missing_variable(py: Python<'_>, message: String) -> PyErr {
    match python_class(py, &MISSING_VARIABLE, "MissingVariableError")
        .and_then(|cls| cls.call1((message,)))
    {
        Ok(e) => PyErr::from_value(e),
        Err(e) => e,
    }
}

/// A trace that cannot be scored.
pub fn trace_error(py: Python<'_>, e: &TraceError) -> PyErr {
    let text = with_help(e.to_string(), e.help());
    match e {
        TraceError::Missing { .. } => missing_variable(py, text),
        _ => PyValueError::new_err(text),
    }
}

/// A batch that cannot be scored.
pub fn batch_error(py: Python<'_>, e: &BatchError) -> PyErr {
    let text = with_help(e.to_string(), e.help());
    match e {
        BatchError::Trace { error: TraceError::Missing { .. }, .. } => missing_variable(py, text),
        _ => PyValueError::new_err(text),
    }
}

/// A formula that cannot be monitored, as `hstlc monitor --formula` reports it.
pub fn lower_error(file: &str, e: &LowerError) -> PyErr {
    let help = match e {
        LowerError::UnknownLet { .. } => Some("leave out `formula` to score the task".to_string()),
        LowerError::Invalid { .. } => None,
    };
    value_error(format!("{file}: {e}"), help)
}

/// A source text that gave no spec: `hstl.SpecError`, with the diagnostics when it has
/// errors (its `str()` is then what `hstlc check --format concise` prints).
pub fn load_error(py: Python<'_>, file: &str, source: &str, e: LoadError) -> PyErr {
    match e {
        LoadError::Invalid(diagnostics) => {
            let concise = hstl::lang::render_concise(&[hstl::lang::FileDiagnostics {
                name: file,
                source,
                diagnostics: &diagnostics,
            }]);
            let list = diagnostics_of(file, source, &diagnostics);
            spec_error(py, concise.trim_end().to_string(), list)
        }
        e => spec_error(py, with_help(format!("{file}: {e}"), e.help("`name=`")), Vec::new()),
    }
}

/// A file that could not be read, as the matching `OSError`, with the CLI's words.
pub fn read_error(path: &Path, e: &std::io::Error) -> PyErr {
    let message = hstl::load::read_error(path, e);
    match e.kind() {
        std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(with_help(
            message,
            Some("check the path; it is read relative to the working directory".into()),
        )),
        std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(message),
        std::io::ErrorKind::IsADirectory => PyIsADirectoryError::new_err(message),
        std::io::ErrorKind::InvalidData => value_error(message, Some("save it as UTF-8".into())),
        _ => PyOSError::new_err(message),
    }
}

/// The diagnostics of `source` as Python objects, positioned as `check --format json`.
pub fn diagnostics_of(file: &str, source: &str, diagnostics: &[LangDiagnostic]) -> Vec<Diagnostic> {
    let index = LineIndex::new(source);
    diagnostics.iter().map(|d| Diagnostic::new(file, d, index.location(source, &d.range))).collect()
}

static SPEC_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static MISSING_VARIABLE: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// A class of the package's pure-Python part (`hstl._errors`).
fn python_class<'py>(
    py: Python<'py>,
    cell: &'static PyOnceLock<Py<PyType>>,
    name: &str,
) -> PyResult<&'py Bound<'py, PyType>> {
    cell.import(py, "hstl._errors", name)
}
