//! How bad a diagnostic is: the one type that both the table of codes ([`crate::codes`]) and
//! the diagnostics ([`crate::diagnostic`]) read, so that neither reads the other back.

/// How bad a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// The spec is still usable.
    Warning,
    /// The spec cannot be used.
    Error,
}

impl Severity {
    /// `"error"` or `"warning"`, as every text and machine format spells it.
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
        }
    }
}
