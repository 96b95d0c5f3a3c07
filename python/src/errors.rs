//! The facade's errors as Python exceptions, worded as the command line words them.
//!
//! A message with a hint reads `message` then `\n  help: hint`, as `hstlc` prints it.

use std::path::Path;

use hstl::Problem;
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

use crate::diagnostic::Diagnostic;

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
    package_error(py, &MISSING_VARIABLE, "MissingVariableError", message)
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
        LowerError::TimeModel { dense: true, .. } => Some(
            "dense-time specs are monitored by `hstlc monitor` for now; the Python package \
             monitors discrete-time specs"
                .to_string(),
        ),
        LowerError::Invalid { .. } | LowerError::TimeModel { .. } => None,
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
    let help = match e.kind() {
        std::io::ErrorKind::NotFound => {
            Some("check the path; it is read relative to the working directory".to_string())
        }
        std::io::ErrorKind::InvalidData => Some("save it as UTF-8".to_string()),
        _ => None,
    };
    os_error(with_help(message, help), e)
}

/// [`read_error`] with `help` whatever the reason, as `hstlc` words a world file it
/// cannot read.
pub fn read_error_with(path: &Path, e: &std::io::Error, help: String) -> PyErr {
    os_error(with_help(hstl::load::read_error(path, e), Some(help)), e)
}

/// A file that could not be written, as the matching `OSError`, with the CLI's words.
pub fn write_error(path: &Path, e: &std::io::Error) -> PyErr {
    os_error(
        format!("cannot write `{}`: {}", hstl::load::path_words(path), hstl::load::io_reason(e)),
        e,
    )
}

/// The `OSError` subclass of `e`'s kind (a `ValueError` for text that is not UTF-8).
fn os_error(text: String, e: &std::io::Error) -> PyErr {
    match e.kind() {
        std::io::ErrorKind::NotFound => PyFileNotFoundError::new_err(text),
        std::io::ErrorKind::PermissionDenied => PyPermissionError::new_err(text),
        std::io::ErrorKind::IsADirectory => PyIsADirectoryError::new_err(text),
        std::io::ErrorKind::InvalidData => PyValueError::new_err(text),
        _ => PyOSError::new_err(text),
    }
}

/// A `ValueError` with the problem's words.
pub fn problem_error(p: &Problem) -> PyErr {
    value_error(p.message.clone(), p.help.clone())
}

/// A world file or name that gives no world: `hstl.WorldError`, a `ValueError`.
pub fn world_error(p: &Problem) -> PyErr {
    Python::attach(|py| {
        package_error(py, &WORLD_ERROR, "WorldError", with_help(p.message.clone(), p.help.clone()))
    })
}

/// A `policy.json` that cannot be replayed: `hstl.PolicyError`, a `ValueError`.
pub fn policy_error(p: &Problem) -> PyErr {
    Python::attach(|py| {
        package_error(
            py,
            &POLICY_ERROR,
            "PolicyError",
            with_help(p.message.clone(), p.help.clone()),
        )
    })
}

/// An instance of the package's exception class `name`, made with `message`.
fn package_error(
    py: Python<'_>,
    cell: &'static PyOnceLock<Py<PyType>>,
    name: &str,
    message: String,
) -> PyErr {
    match python_class(py, cell, name).and_then(|cls| cls.call1((message,))) {
        Ok(e) => PyErr::from_value(e),
        Err(e) => e,
    }
}

/// The diagnostics of `source` as Python objects, positioned as `check --format json`.
pub fn diagnostics_of(file: &str, source: &str, diagnostics: &[LangDiagnostic]) -> Vec<Diagnostic> {
    let index = LineIndex::new(source);
    diagnostics.iter().map(|d| Diagnostic::new(file, d, index.location(source, &d.range))).collect()
}

/// Issues each of `warnings` (the diagnostics of `source`, reported as `file`) as a Python
/// warning of category `hstl.SpecWarning`: its text is the `hstlc check --format concise`
/// line and the hint, and its `diagnostic` the `hstl.Diagnostic`. Raises when a warnings
/// filter turns them into errors.
pub fn warn_spec(
    py: Python<'_>,
    file: &str,
    source: &str,
    warnings: &[LangDiagnostic],
) -> PyResult<()> {
    if warnings.is_empty() {
        return Ok(());
    }
    let category = python_class(py, &SPEC_WARNING, "SpecWarning")?;
    let warn = py.import("warnings")?.getattr("warn")?;
    for d in diagnostics_of(file, source, warnings) {
        let text = with_help(d.concise(), d.help().map(String::from));
        warn.call1((category.call1((text, d))?,))?;
    }
    Ok(())
}

static SPEC_WARNING: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static SPEC_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static MISSING_VARIABLE: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static WORLD_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();
static POLICY_ERROR: PyOnceLock<Py<PyType>> = PyOnceLock::new();

/// A class of the package's pure-Python part (`hstl._errors`).
fn python_class<'py>(
    py: Python<'py>,
    cell: &'static PyOnceLock<Py<PyType>>,
    name: &str,
) -> PyResult<&'py Bound<'py, PyType>> {
    cell.import(py, "hstl._errors", name)
}
