//! Diagnostics as plain data. Each edge (CLI, macro, language server) renders them its own way.

use std::ops::Range;

pub use crate::severity::Severity;

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

impl Diagnostic {
    /// A diagnostic with the severity of its code in [`crate::codes`] and no labels or help.
    pub fn new(code: &'static str, range: Range<usize>, message: impl Into<String>) -> Self {
        let severity = crate::codes::lookup(code).map_or(Severity::Error, |c| c.severity);
        Diagnostic {
            code,
            severity,
            range,
            message: message.into(),
            labels: Vec::new(),
            help: None,
        }
    }

    /// Adds a related place.
    pub fn with_label(mut self, range: Range<usize>, message: impl Into<String>) -> Self {
        self.labels.push(Label { range, message: message.into() });
        self
    }

    /// Sets the help text.
    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    /// Whether this is an error (rather than a warning).
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// Sorts diagnostics by position, drops exact duplicates and caps the count at `cap`,
/// appending one `HSTL024` diagnostic that says how many more were suppressed.
pub fn finish(mut diagnostics: Vec<Diagnostic>, cap: usize, src_len: usize) -> Vec<Diagnostic> {
    diagnostics.sort_by(|a, b| {
        (a.range.start, a.range.end, a.code, &a.message).cmp(&(
            b.range.start,
            b.range.end,
            b.code,
            &b.message,
        ))
    });
    diagnostics.dedup();
    if diagnostics.len() > cap {
        let rest = diagnostics.split_off(cap);
        let errors = rest.iter().filter(|d| d.is_error()).count();
        let mut last = Diagnostic::new(
            "HSTL024",
            src_len..src_len,
            format!(
                "{} more diagnostics suppressed ({} errors, {} warnings)",
                rest.len(),
                errors,
                rest.len() - errors
            ),
        )
        .with_help(format!("fix the first {cap} and check again"));
        if errors > 0 {
            last.severity = Severity::Error;
        }
        diagnostics.push(last);
    }
    diagnostics
}
