//! What a trace, a batch or a `windows` choice that cannot be scored says: the errors of
//! [`super::Monitor`] and [`super::Online`], each with how to fix it.

use std::fmt;

/// A trace or a state that cannot be scored.
#[derive(Clone, Debug, PartialEq)]
pub enum TraceError {
    /// The trace lacks a state variable.
    Missing {
        /// The state variable.
        var: String,
        /// The names the trace has, where the caller knows them.
        known: Option<Vec<String>>,
        /// The spec's state variables, in order.
        vars: Vec<String>,
    },
    /// Two state variables have different numbers of samples.
    Ragged {
        /// The first state variable.
        first: String,
        /// Its samples.
        first_len: usize,
        /// The state variable whose length differs.
        var: String,
        /// Its samples.
        len: usize,
    },
    /// The trace has no samples.
    Empty,
    /// A sample is NaN.
    NotANumber {
        /// The state variable.
        var: String,
        /// The step, counted from 0.
        step: usize,
    },
    /// A sample of an `int` state variable is not a whole number, or outside its range.
    NotInDomain {
        /// The state variable.
        var: String,
        /// The step, counted from 0.
        step: usize,
        /// The sample.
        value: f64,
        /// The variable's declared range, if any.
        range: Option<(i64, i64)>,
    },
    /// An expression of the formula computes NaN on a step (`sqrt` of a negative, `0 / 0`,
    /// `inf - inf`, ...): robustness has no value there.
    Undefined {
        /// The step, counted from 0.
        step: usize,
        /// The innermost expression that is NaN, or the comparison, in hstl syntax.
        expr: String,
        /// The operation that gave NaN, with its operands (`the square root of -1`).
        operation: String,
    },
    /// A state (for the online monitor) has the wrong number of values.
    Width {
        /// The spec's state variables, in order.
        vars: Vec<String>,
        /// The number of values given.
        found: usize,
    },
    /// Row-major data whose rows are too short for the picks, or not whole.
    Layout {
        /// Values in the data.
        len: usize,
        /// Values per row.
        width: usize,
    },
    /// The online monitor would pass its memory budget: `steps` states wait for verdicts
    /// that the formula's horizon (`None`: unbounded) holds back.
    Budget {
        /// The states kept.
        steps: usize,
        /// The formula's horizon in steps.
        horizon: Option<usize>,
        /// The most values the monitor keeps.
        limit: usize,
    },
}

/// A trace of a batch that cannot be scored.
#[derive(Clone, Debug, PartialEq)]
pub enum BatchError {
    /// Trace `trace` (counted from 0) is not a valid trace.
    Trace {
        /// Its index in the batch.
        trace: usize,
        /// What is wrong with it.
        error: TraceError,
    },
    /// Trace `trace` has `steps` steps where trace 0 has `first_steps`.
    Steps {
        /// Its index in the batch.
        trace: usize,
        /// Its steps.
        steps: usize,
        /// The steps of trace 0.
        first_steps: usize,
    },
}

/// A `windows` choice that is neither `clipped` nor `complete`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownWindows(pub String);

impl UnknownWindows {
    /// How to fix it.
    pub fn help(&self) -> String {
        "pass \"clipped\" (windows cut at the end of the trace, the default) or \"complete\" \
         (only steps whose windows lie inside the trace)"
            .to_string()
    }
}

impl fmt::Display for UnknownWindows {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown windows `{}`", self.0)
    }
}

impl std::error::Error for UnknownWindows {}

impl TraceError {
    /// How to fix it, where one fits.
    pub fn help(&self) -> Option<String> {
        Some(match self {
            TraceError::Missing { known: Some(known), vars, .. } => format!(
                "the trace has {}; the spec's state variables are {}",
                quote_list(known),
                quote_list(vars)
            ),
            TraceError::Missing { known: None, vars, .. } => {
                format!("the spec's state variables are {}", quote_list(vars))
            }
            TraceError::Ragged { .. } => {
                "give every state variable one sample per step".to_string()
            }
            TraceError::Empty => "give every state variable at least one sample".to_string(),
            TraceError::NotANumber { .. } => "robustness has no meaning for NaN: drop the \
                step or give it a number (`inf` and `-inf` are allowed)"
                .to_string(),
            TraceError::Width { vars, .. } => {
                format!("give one value per state variable, in the order {}", quote_list(vars))
            }
            TraceError::NotInDomain { var, range: Some((lo, hi)), value, .. }
                if value.is_finite() && value.fract() == 0.0 =>
            {
                format!(
                    "the spec declares `{var}: int in {lo}..={hi}`: widen the range or fix the trace"
                )
            }
            TraceError::NotInDomain { var, .. } => {
                format!("`{var}` is an `int` state variable: give whole numbers such as `3`")
            }
            TraceError::Undefined { .. } => "robustness has no meaning for NaN: write the \
                expression so that it is defined on every state the trace can hold (for \
                example `sqrt(abs(x))`), or fix the trace"
                .to_string(),
            TraceError::Layout { .. } => return None,
            TraceError::Budget { .. } => "a verdict waits until the formula's window has passed: \
                monitor the whole trace offline instead (without `--online`), or shorten the \
                window"
                .to_string(),
        })
    }
}

impl fmt::Display for TraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TraceError::Missing { var, .. } => write!(f, "missing state variable `{var}`"),
            TraceError::Ragged { first, first_len, var, len } => write!(
                f,
                "state variable `{var}` has {}, but `{first}` has {}",
                samples_word(*len),
                samples_word(*first_len)
            ),
            TraceError::Empty => f.write_str("the trace has no samples"),
            TraceError::NotANumber { var, step } => write!(f, "`{var}` is NaN at step {step}"),
            TraceError::Undefined { step, expr, operation } => {
                write!(f, "`{expr}` is NaN at step {step}: {operation}")
            }
            TraceError::NotInDomain { var, step, value, range: Some((lo, hi)) }
                if value.is_finite() && value.fract() == 0.0 =>
            {
                write!(f, "`{var}` is {value} at step {step}, outside its range {lo}..={hi}")
            }
            TraceError::NotInDomain { var, step, value, .. } => {
                write!(f, "`{var}` is {value} at step {step}, not a whole number")
            }
            TraceError::Width { vars, found } => write!(
                f,
                "the state has {found} value{}, the spec has {} state variable{}",
                if *found == 1 { "" } else { "s" },
                vars.len(),
                if vars.len() == 1 { "" } else { "s" }
            ),
            TraceError::Layout { len, width } => {
                write!(f, "{len} samples do not make whole rows of {width}")
            }
            TraceError::Budget { steps, horizon, limit } => {
                let window = match horizon {
                    Some(h) => format!("the formula looks {h} steps ahead"),
                    None => "the formula has an unbounded operator".to_string(),
                };
                write!(
                    f,
                    "the online monitor holds {steps} states without a verdict ({window}), \
                     and one more would pass its budget of {limit} values"
                )
            }
        }
    }
}

impl std::error::Error for TraceError {}

impl BatchError {
    /// How to fix it, where one fits.
    pub fn help(&self) -> Option<String> {
        match self {
            BatchError::Trace { error, .. } => error.help(),
            BatchError::Steps { .. } => {
                Some("cut or pad the traces to one length, or score each with `signal`".to_string())
            }
        }
    }
}

impl fmt::Display for BatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BatchError::Trace { trace, error } => write!(f, "trace {trace}: {error}"),
            BatchError::Steps { trace, steps, first_steps } => {
                write!(f, "trace {trace} has {steps} steps, but trace 0 has {first_steps}")
            }
        }
    }
}

impl std::error::Error for BatchError {}

fn samples_word(n: usize) -> String {
    if n == 1 { "1 sample".to_string() } else { format!("{n} samples") }
}

fn quote_list(names: &[String]) -> String {
    if names.is_empty() {
        return "none".to_string();
    }
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}
