//! Dense-time traces: time-stamped samples, each variable a step function.

use std::fmt;

/// A dense-time trace: the merge of every variable's time-stamped samples.
///
/// Each variable is a step function: a sample starts a new value at its stamp, and the value
/// holds (right-continuously) until that variable's next sample, and after the last stamp
/// forever. The trace keeps one row per distinct stamp of any variable (the union of the
/// variables' stamps), each row holding every variable's value at that stamp, so a variable
/// without a sample at a row keeps its previous value there.
///
/// Stamps are finite and strictly increasing; every variable has a sample at the first
/// stamp (no value exists before it); values may be infinite but never NaN.
///
/// A trace built from whole-number stamps ([`DenseTrace::from_int_samples`],
/// [`DenseTraceBuilder::push_int`]) holds each stamp relative to the first one, computed in
/// integer arithmetic; [`DenseTrace::origin`] gives the first stamp back.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DenseTrace {
    times: Vec<f64>,
    columns: Vec<Vec<f64>>,
    origin: Option<i128>,
}

/// Why a dense-time trace could not be built (or a sample could not be pushed).
///
/// Rows and samples are counted from 0; callers that read a file add their own offsets.
#[derive(Clone, Debug, PartialEq)]
pub enum DenseTraceError {
    /// No sample at all.
    Empty,
    /// A stamp is NaN or infinite.
    BadStamp {
        /// The row (or the variable's sample) with the stamp.
        row: usize,
        /// The stamp.
        stamp: f64,
    },
    /// A stamp is not greater than the one before it.
    NotIncreasing {
        /// The row (or the variable's sample) with the stamp.
        row: usize,
        /// The stamp before it.
        previous: String,
        /// The stamp.
        stamp: String,
    },
    /// A value is NaN.
    NanValue {
        /// The variable.
        var: usize,
        /// The row (or the variable's sample) with the value.
        row: usize,
    },
    /// A variable has no sample at the first stamp.
    MissingFirst {
        /// The variable.
        var: usize,
        /// The first stamp of the trace.
        t0: String,
    },
    /// A row has the wrong number of cells.
    RowWidth {
        /// The number of variables.
        expected: usize,
        /// The number of cells given.
        found: usize,
    },
    /// A whole-number stamp is too far from the first stamp for a double to hold the
    /// difference exactly.
    Inexact {
        /// The row (or the variable's sample) with the stamp.
        row: usize,
        /// The stamp.
        stamp: i128,
        /// The first stamp.
        origin: i128,
    },
    /// Whole-number and decimal stamps mixed in one trace.
    MixedStamps {
        /// The row where the kind of stamp changed.
        row: usize,
    },
}

impl fmt::Display for DenseTraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DenseTraceError::Empty => write!(f, "the trace has no sample"),
            DenseTraceError::BadStamp { row, stamp } => {
                write!(f, "row {row}: the time stamp {stamp} is not a finite number")
            }
            DenseTraceError::NotIncreasing { row, previous, stamp } => write!(
                f,
                "row {row}: the time stamp {stamp} does not come after the previous one, \
                 {previous} (stamps must strictly increase)"
            ),
            DenseTraceError::NanValue { var, row } => {
                write!(f, "row {row}: variable {var} is NaN")
            }
            DenseTraceError::MissingFirst { var, t0 } => write!(
                f,
                "variable {var} has no sample at the first time stamp, {t0} \
                 (no value exists before it)"
            ),
            DenseTraceError::RowWidth { expected, found } => {
                write!(f, "a row has {found} cells for {expected} variables")
            }
            DenseTraceError::Inexact { row, stamp, origin } => write!(
                f,
                "row {row}: the time stamp {stamp} is {} units after the first stamp {origin}, \
                 more than a double holds exactly (exact up to 2^53 = 9007199254740992 units)",
                stamp - origin
            ),
            DenseTraceError::MixedStamps { row } => {
                write!(f, "row {row}: whole-number and decimal time stamps are mixed in one trace")
            }
        }
    }
}

impl std::error::Error for DenseTraceError {}

/// The relative stamp `stamp - origin` as a double, or an error if not exact.
pub(crate) fn relative(row: usize, stamp: i128, origin: i128) -> Result<f64, DenseTraceError> {
    let rel = stamp - origin;
    let t = rel as f64;
    // `rel` lies within 2^65 of zero, so the cast back is exact whenever `t` is.
    if t.is_finite() && t as i128 == rel {
        Ok(t)
    } else {
        Err(DenseTraceError::Inexact { row, stamp, origin })
    }
}

/// Builds a [`DenseTrace`] row by row, as a CSV file with a time column holds it.
///
/// Each row has a stamp and one cell per variable; an empty cell (`None`) is no new sample
/// (the variable keeps its value). Every cell of the first row must be filled.
#[derive(Clone, Debug)]
pub struct DenseTraceBuilder {
    trace: DenseTrace,
    /// The last whole-number stamp pushed, when stamps are whole numbers.
    last_int: Option<i128>,
    /// Rows forgotten from the front (by the online monitor).
    dropped: usize,
}

impl DenseTraceBuilder {
    /// A builder for a trace over `vars` variables.
    pub fn new(vars: usize) -> DenseTraceBuilder {
        DenseTraceBuilder {
            trace: DenseTrace { times: Vec::new(), columns: vec![Vec::new(); vars], origin: None },
            last_int: None,
            dropped: 0,
        }
    }

    /// The number of rows pushed so far.
    pub fn len(&self) -> usize {
        self.dropped + self.trace.times.len()
    }

    /// Whether no row was pushed.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends a row with a decimal stamp `t`.
    pub fn push(&mut self, t: f64, cells: &[Option<f64>]) -> Result<(), DenseTraceError> {
        let row = self.len();
        if self.trace.origin.is_some() {
            return Err(DenseTraceError::MixedStamps { row });
        }
        if !t.is_finite() {
            return Err(DenseTraceError::BadStamp { row, stamp: t });
        }
        if let Some(&prev) = self.trace.times.last()
            && t <= prev
        {
            return Err(DenseTraceError::NotIncreasing {
                row,
                previous: prev.to_string(),
                stamp: t.to_string(),
            });
        }
        self.push_cells(t, cells)
    }

    /// Appends a row with a whole-number stamp (nanoseconds since the epoch, say), held
    /// relative to the first row's stamp in integer arithmetic.
    ///
    /// Fails where the relative stamp is not exactly a double (more than 2^53 units after
    /// the first one, and off the doubles' grid): it is never rounded.
    pub fn push_int(
        &mut self,
        stamp: impl Into<i128>,
        cells: &[Option<f64>],
    ) -> Result<(), DenseTraceError> {
        let stamp = stamp.into();
        let row = self.len();
        if row > 0 && self.trace.origin.is_none() {
            return Err(DenseTraceError::MixedStamps { row });
        }
        if let Some(prev) = self.last_int
            && stamp <= prev
        {
            return Err(DenseTraceError::NotIncreasing {
                row,
                previous: prev.to_string(),
                stamp: stamp.to_string(),
            });
        }
        let origin = *self.trace.origin.get_or_insert(stamp);
        let t = relative(row, stamp, origin)?;
        self.push_cells(t, cells)?;
        self.last_int = Some(stamp);
        Ok(())
    }

    fn push_cells(&mut self, t: f64, cells: &[Option<f64>]) -> Result<(), DenseTraceError> {
        let row = self.len();
        let vars = self.trace.columns.len();
        if cells.len() != vars {
            return Err(DenseTraceError::RowWidth { expected: vars, found: cells.len() });
        }
        for (var, cell) in cells.iter().enumerate() {
            match cell {
                Some(v) if v.is_nan() => return Err(DenseTraceError::NanValue { var, row }),
                None if row == 0 => {
                    return Err(DenseTraceError::MissingFirst { var, t0: t.to_string() });
                }
                _ => {}
            }
        }
        for (col, cell) in self.trace.columns.iter_mut().zip(cells) {
            let v = match cell {
                Some(v) => *v,
                None => *col.last().expect("row 0 is full"),
            };
            col.push(v);
        }
        self.trace.times.push(t);
        Ok(())
    }

    /// The trace; fails if no row was pushed.
    pub fn build(self) -> Result<DenseTrace, DenseTraceError> {
        if self.trace.times.is_empty() {
            return Err(DenseTraceError::Empty);
        }
        Ok(self.trace)
    }
}

impl DenseTrace {
    /// The trace of one list of `(stamp, value)` samples per variable, merged: the rows are
    /// the union of the variables' stamps, each variable holding its last sample.
    ///
    /// Each list's stamps must be finite and strictly increasing, and every list must
    /// start at the earliest stamp of all. An error's `row` is the sample's index in its
    /// variable's list.
    pub fn from_samples(vars: &[Vec<(f64, f64)>]) -> Result<DenseTrace, DenseTraceError> {
        for samples in vars {
            let mut prev: Option<f64> = None;
            for (row, &(t, _)) in samples.iter().enumerate() {
                if !t.is_finite() {
                    return Err(DenseTraceError::BadStamp { row, stamp: t });
                }
                if let Some(p) = prev
                    && t <= p
                {
                    return Err(DenseTraceError::NotIncreasing {
                        row,
                        previous: p.to_string(),
                        stamp: t.to_string(),
                    });
                }
                prev = Some(t);
            }
        }
        merge(vars, |t| t, None)
    }

    /// [`DenseTrace::from_samples`] with whole-number stamps (`i64` or `u64` nanoseconds,
    /// say), each taken relative to the earliest stamp in integer arithmetic.
    ///
    /// Fails where a relative stamp is not exactly a double (see
    /// [`DenseTraceBuilder::push_int`]).
    pub fn from_int_samples<S: Copy + Into<i128>>(
        vars: &[Vec<(S, f64)>],
    ) -> Result<DenseTrace, DenseTraceError> {
        let mut origin: Option<i128> = None;
        for samples in vars {
            let mut prev: Option<i128> = None;
            for (row, &(s, _)) in samples.iter().enumerate() {
                let s = s.into();
                if let Some(p) = prev
                    && s <= p
                {
                    return Err(DenseTraceError::NotIncreasing {
                        row,
                        previous: p.to_string(),
                        stamp: s.to_string(),
                    });
                }
                prev = Some(s);
                origin = Some(origin.map_or(s, |o| o.min(s)));
            }
        }
        let Some(origin) = origin else { return Err(DenseTraceError::Empty) };
        let mut rel: Vec<Vec<(f64, f64)>> = Vec::with_capacity(vars.len());
        for samples in vars {
            let mut col = Vec::with_capacity(samples.len());
            for (row, &(s, v)) in samples.iter().enumerate() {
                col.push((relative(row, s.into(), origin)?, v));
            }
            rel.push(col);
        }
        merge(&rel, |t| t, Some(origin))
    }

    /// A trace over no variable holding only the given stamps (for formulas over constants).
    pub fn from_times(times: Vec<f64>) -> Result<DenseTrace, DenseTraceError> {
        let mut b = DenseTraceBuilder::new(0);
        for t in times {
            b.push(t, &[])?;
        }
        b.build()
    }

    /// The rows' stamps, strictly increasing (relative to [`DenseTrace::origin`] when set).
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Variable `i`'s value at every row.
    pub fn column(&self, i: usize) -> &[f64] {
        &self.columns[i]
    }

    /// The number of variables.
    pub fn vars(&self) -> usize {
        self.columns.len()
    }

    /// The number of rows (distinct stamps).
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Always false: a built trace has at least one row.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// The first stamp.
    pub fn t0(&self) -> f64 {
        self.times[0]
    }

    /// The last stamp.
    pub fn t_last(&self) -> f64 {
        self.times[self.times.len() - 1]
    }

    /// The first whole-number stamp, when the trace was built from whole-number stamps:
    /// the stamps (and every time computed from them) are then relative to it.
    pub fn origin(&self) -> Option<i128> {
        self.origin
    }

    pub(crate) fn columns(&self) -> &[Vec<f64>] {
        &self.columns
    }
}

/// Merges per-variable sample lists (stamps already validated as increasing).
fn merge(
    vars: &[Vec<(f64, f64)>],
    time: impl Fn(f64) -> f64,
    origin: Option<i128>,
) -> Result<DenseTrace, DenseTraceError> {
    let Some(t0) = vars.iter().filter_map(|s| s.first()).map(|s| time(s.0)).reduce(f64::min) else {
        return Err(DenseTraceError::Empty);
    };
    for (var, samples) in vars.iter().enumerate() {
        match samples.first() {
            Some(&(t, _)) if time(t) == t0 => {}
            _ => return Err(DenseTraceError::MissingFirst { var, t0: t0.to_string() }),
        }
        if let Some(row) = samples.iter().position(|s| s.1.is_nan()) {
            return Err(DenseTraceError::NanValue { var, row });
        }
    }
    let total: usize = vars.iter().map(Vec::len).max().unwrap_or(0);
    let mut times = Vec::with_capacity(total);
    let mut columns: Vec<Vec<f64>> = vec![Vec::with_capacity(total); vars.len()];
    let mut next = vec![0usize; vars.len()];
    loop {
        // The earliest stamp not merged yet, of any variable.
        let t = vars
            .iter()
            .zip(&next)
            .filter_map(|(s, &k)| s.get(k))
            .map(|s| time(s.0))
            .reduce(f64::min);
        let Some(t) = t else { break };
        for ((samples, k), col) in vars.iter().zip(&mut next).zip(&mut columns) {
            let v = match samples.get(*k) {
                Some(&(s, v)) if time(s) == t => {
                    *k += 1;
                    v
                }
                _ => *col.last().expect("every variable starts at t0"),
            };
            col.push(v);
        }
        times.push(t);
    }
    Ok(DenseTrace { times, columns, origin })
}

impl DenseTraceBuilder {
    /// The rows pushed so far (stamps and held values).
    pub(crate) fn rows(&self) -> (&[f64], &[Vec<f64>]) {
        (&self.trace.times, &self.trace.columns)
    }

    /// Forgets the first `k` rows (the monitor's decided past).
    pub(crate) fn drop_front(&mut self, k: usize) {
        self.trace.times.drain(..k);
        self.dropped += k;
        for c in &mut self.trace.columns {
            c.drain(..k);
        }
    }

    /// The first whole-number stamp, when stamps are whole numbers.
    pub(crate) fn origin(&self) -> Option<i128> {
        self.trace.origin
    }

    /// The last whole-number stamp pushed, when stamps are whole numbers.
    pub(crate) fn last_int(&self) -> Option<i128> {
        self.last_int
    }

    /// A builder that has taken `rows` rows, of which it holds the last: stamp `t` (relative
    /// to `origin` for whole-number stamps, the last of which was `last_int`) and
    /// `values`. The caller checked that they fit together.
    pub(crate) fn resumed(
        rows: usize,
        t: f64,
        values: &[f64],
        origin: Option<i128>,
        last_int: Option<i128>,
    ) -> DenseTraceBuilder {
        DenseTraceBuilder {
            trace: DenseTrace {
                times: vec![t],
                columns: values.iter().map(|&v| vec![v]).collect(),
                origin,
            },
            last_int,
            dropped: rows - 1,
        }
    }
}
