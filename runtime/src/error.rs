//! The crate's error type.

use std::fmt;

/// Everything that can go wrong in the runtime. Each variant carries a message that says
/// what is wrong, written for the user.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Error {
    /// The task spec is inconsistent or does not fit the environment.
    Spec(String),
    /// The environment is misconfigured.
    Env(String),
    /// A `policy.json` document could not be read or does not fit the environment.
    Policy(String),
    /// Training or evaluation cannot run with these settings.
    Config(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Spec(m) => write!(f, "invalid spec: {m}"),
            Error::Env(m) => write!(f, "invalid environment: {m}"),
            Error::Policy(m) => write!(f, "invalid policy: {m}"),
            Error::Config(m) => write!(f, "invalid configuration: {m}"),
        }
    }
}

impl std::error::Error for Error {}
