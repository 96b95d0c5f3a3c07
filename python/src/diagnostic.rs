//! `hstl.Diagnostic`: one diagnostic of a spec, as `hstlc check --format json` positions it.
//! Its own module, since both the checker's calls and the exceptions make them.

use hstl::lang::Location;
use pyo3::prelude::*;

/// One diagnostic of `hstlc check`, positioned as `hstlc check --format json` gives it:
/// lines and columns 1-based, columns counted in characters, the end exclusive.
#[pyclass(module = "hstl", frozen, eq, hash, get_all)]
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Diagnostic {
    /// The file name, as given to `Spec.load` or `Spec.parse`.
    file: String,
    /// `"error"` or `"warning"`.
    severity: String,
    /// The stable code, such as `HSTL015`; `hstlc explain CODE` explains it.
    code: String,
    /// What is wrong.
    message: String,
    /// 1-based line of the start.
    line: usize,
    /// 1-based column of the start, in characters.
    column: usize,
    /// 1-based line of the end.
    end_line: usize,
    /// 1-based column just past the end, in characters.
    end_column: usize,
    /// How to fix it, or None.
    help: Option<String>,
}

impl Diagnostic {
    /// The line `hstlc check --format concise` prints for it.
    pub fn concise(&self) -> String {
        format!(
            "{}:{}:{}: {} {}: {}",
            self.file, self.line, self.column, self.code, self.severity, self.message
        )
    }

    /// How to fix it.
    pub fn help(&self) -> Option<&str> {
        self.help.as_deref()
    }

    pub fn new(file: &str, d: &hstl::lang::Diagnostic, at: Location) -> Diagnostic {
        Diagnostic {
            file: file.to_string(),
            severity: d.severity.as_str().to_string(),
            code: d.code.to_string(),
            message: d.message.clone(),
            line: at.line,
            column: at.column,
            end_line: at.end_line,
            end_column: at.end_column,
            help: d.help.clone(),
        }
    }
}

#[pymethods]
impl Diagnostic {
    #[new]
    #[pyo3(signature = (file, severity, code, message, line, column, end_line, end_column, help=None))]
    #[allow(clippy::too_many_arguments)]
    fn py_new(
        file: String,
        severity: String,
        code: String,
        message: String,
        line: usize,
        column: usize,
        end_line: usize,
        end_column: usize,
        help: Option<String>,
    ) -> Diagnostic {
        Diagnostic { file, severity, code, message, line, column, end_line, end_column, help }
    }

    fn __getnewargs__(
        &self,
    ) -> (String, String, String, String, usize, usize, usize, usize, Option<String>) {
        let d = self.clone();
        (d.file, d.severity, d.code, d.message, d.line, d.column, d.end_line, d.end_column, d.help)
    }

    fn __repr__(&self) -> String {
        format!(
            "Diagnostic({}:{}:{}: {} {}: {})",
            self.file, self.line, self.column, self.code, self.severity, self.message
        )
    }

    /// The line `hstlc check --format concise` prints for it.
    fn __str__(&self) -> String {
        self.concise()
    }
}
