//! [`Problem`]: what keeps a call from running, worded for the user, with how to fix it.

use std::fmt;

/// Why something a user asked for cannot run: what is wrong (where, when the input has
/// positions) and how to fix it. Every front end shows the same words: `hstlc` as
/// `error: MESSAGE` and `help: HELP`, the Python package as an exception's message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    /// What is wrong, without a trailing period.
    pub message: String,
    /// How to fix it.
    pub help: Option<String>,
}

impl Problem {
    /// A problem with a message and a hint.
    pub fn new(message: impl Into<String>, help: impl Into<Option<String>>) -> Problem {
        Problem { message: message.into(), help: help.into() }
    }

    /// The same problem, its message after `FILE: `.
    pub fn in_file(self, file: &str) -> Problem {
        Problem { message: format!("{file}: {}", self.message), help: self.help }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Problem {}
