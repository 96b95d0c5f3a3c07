//! Diagnostics as plain data. Each edge (CLI, macro, language server) renders them its own way.

use std::ops::Range;

/// How bad a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// The spec is still usable.
    Warning,
    /// The spec cannot be used.
    Error,
}

/// A secondary source location that matters to a diagnostic, such as a first definition.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Label {
    /// Byte range in the source text.
    pub range: Range<usize>,
    /// What this place has to do with the diagnostic.
    pub message: String,
}

/// One problem found in a source text.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Diagnostic {
    /// The stable code, such as `HSTL001`; `hstlc explain CODE` prints its long explanation.
    pub code: &'static str,
    /// Error or warning.
    pub severity: Severity,
    /// Byte range of the offending text. Empty at the end of the input.
    pub range: Range<usize>,
    /// What is wrong, without a trailing period.
    pub message: String,
    /// Related places.
    pub labels: Vec<Label>,
    /// How to fix it, where one fits.
    pub help: Option<String>,
}
