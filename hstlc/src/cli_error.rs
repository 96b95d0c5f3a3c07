//! Errors that keep a command from running (exit status 2).

use std::fmt;
use std::path::PathBuf;

/// Why a command could not run.
#[derive(Debug)]
pub enum CliError {
    /// A file could not be read.
    Read {
        /// The file.
        path: PathBuf,
        /// The reason.
        source: std::io::Error,
    },
    /// A file could not be written.
    Write {
        /// The file.
        path: PathBuf,
        /// The reason.
        source: std::io::Error,
    },
    /// Any other problem, with what to do about it.
    Other {
        /// What is wrong.
        message: String,
        /// How to fix it.
        help: Option<String>,
    },
}

impl CliError {
    /// An error with a message and a hint.
    pub fn new(message: impl Into<String>, help: impl Into<Option<String>>) -> CliError {
        CliError::Other { message: message.into(), help: help.into() }
    }

    /// How to fix it, where one fits.
    pub fn help(&self) -> Option<String> {
        match self {
            CliError::Read { source, .. } if source.kind() == std::io::ErrorKind::NotFound => {
                Some("check the path; use `-` to read standard input".into())
            }
            CliError::Read { .. } | CliError::Write { .. } => None,
            CliError::Other { help, .. } => help.clone(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::Read { path, source } => f.write_str(&hstl::load::read_error(path, source)),
            CliError::Write { path, source } => {
                write!(
                    f,
                    "cannot write `{}`: {}",
                    hstl::load::path_words(path),
                    hstl::load::io_reason(source)
                )
            }
            CliError::Other { message, .. } => f.write_str(message),
        }
    }
}

impl std::error::Error for CliError {}

impl From<hstl::Problem> for CliError {
    fn from(p: hstl::Problem) -> CliError {
        CliError::new(p.message, p.help)
    }
}

impl From<hstl_outdir::Error> for CliError {
    fn from(e: hstl_outdir::Error) -> CliError {
        match e {
            hstl_outdir::Error::Write { path, source } => CliError::Write { path, source },
            hstl_outdir::Error::Refused(p) => p.into(),
        }
    }
}
