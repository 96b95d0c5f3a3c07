//! Traces: one sample of every state variable per discrete time step.

use std::fmt;

/// A finite trace stored column by column, so evaluators stream over one variable at a time.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    columns: Vec<Vec<f64>>,
    len: usize,
}

/// A trace that could not be built.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TraceError {
    /// Column `column` has `found` samples where the first one has `expected`.
    Ragged {
        /// The offending column.
        column: usize,
        /// The length of column 0.
        expected: usize,
        /// The length of the offending column.
        found: usize,
    },
    /// A row has `found` values for `expected` variables.
    RowWidth {
        /// The number of variables.
        expected: usize,
        /// The number of values given.
        found: usize,
    },
    /// The online monitor would keep more than `limit` values: `steps` states wait for
    /// their verdicts, which a window as long as the formula's `horizon` (`None`:
    /// unbounded) holds back.
    Budget {
        /// The states kept when the next one was refused.
        steps: usize,
        /// The formula's horizon in steps, `None` when unbounded.
        horizon: Option<usize>,
        /// The most values the monitor keeps.
        limit: usize,
    },
}

impl fmt::Display for TraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TraceError::Ragged { column, expected, found } => {
                write!(f, "column {column} has {found} samples, but column 0 has {expected}")
            }
            TraceError::RowWidth { expected, found } => {
                write!(f, "a row has {found} values for {expected} variables")
            }
            TraceError::Budget { steps, horizon, limit } => {
                let window = match horizon {
                    Some(h) => format!("a horizon of {h} steps"),
                    None => "an unbounded operator".to_string(),
                };
                write!(
                    f,
                    "the online monitor keeps {steps} states waiting for verdicts that {window} \
                     holds back, and would pass its budget of {limit} values"
                )
            }
        }
    }
}

impl std::error::Error for TraceError {}

impl Trace {
    /// An empty trace over `vars` variables.
    pub fn new(vars: usize) -> Trace {
        Trace { columns: vec![Vec::new(); vars], len: 0 }
    }

    /// A trace from one column per variable; all columns must have the same length.
    pub fn from_columns(columns: Vec<Vec<f64>>) -> Result<Trace, TraceError> {
        let len = columns.first().map_or(0, Vec::len);
        if let Some((column, c)) = columns.iter().enumerate().find(|(_, c)| c.len() != len) {
            return Err(TraceError::Ragged { column, expected: len, found: c.len() });
        }
        Ok(Trace { columns, len })
    }

    /// Appends one sample, `row[i]` being variable `i`.
    pub fn push(&mut self, row: &[f64]) -> Result<(), TraceError> {
        if row.len() != self.columns.len() {
            return Err(TraceError::RowWidth { expected: self.columns.len(), found: row.len() });
        }
        for (c, v) in self.columns.iter_mut().zip(row) {
            c.push(*v);
        }
        self.len += 1;
        Ok(())
    }

    /// Removes every sample and keeps the allocations.
    pub fn clear(&mut self) {
        self.columns.iter_mut().for_each(Vec::clear);
        self.len = 0;
    }

    /// The number of steps.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the trace has no step.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The number of state variables.
    pub fn vars(&self) -> usize {
        self.columns.len()
    }

    /// The samples of variable `i`.
    pub fn column(&self, i: usize) -> &[f64] {
        &self.columns[i]
    }

    /// The values of every variable at step `t`, written into `out`.
    pub fn row_into(&self, t: usize, out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.columns.iter().map(|c| c[t]));
    }
}
