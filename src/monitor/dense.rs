//! Monitoring a dense-time spec (one with a `time` variable) over time-stamped samples:
//! what `hstlc monitor` computes for such a spec. The semantics are rtamt's dense-time STL
//! ([`hstl_robustness::dense`]); the spec's decimal bounds are read through its
//! [`TimeScale`].

use std::fmt;

use hstl_lang::CheckedSpec;
use hstl_robustness::MAX_ONLINE_VALUES;
use hstl_robustness::dense::{
    DenseError, DenseFormula, DenseMonitor, DenseSignal, DenseTrace, DenseTraceBuilder, TimeScale,
};

pub use super::stamps::time_text;
use super::stamps::{Front, MaxGap, Place, Stamp, StampError, StampRules, TimeAxis};
use super::{MAX_BATCH_THREADS, Windows};
use crate::lower::{self, LowerError};

/// The task of a dense-time spec, or one of its `let`s, ready to score time-stamped
/// traces.
///
/// ```
/// use hstl::robustness::dense::DenseTrace;
/// let src = "spec Log { state { t: time, x: float } task eventually[0..=1.5] x > 1; }";
/// let checked = hstl::lang::check(src);
/// let monitor = hstl::monitor::Dense::new(&checked.specs[0], None).unwrap();
/// // x is 0 from t = 0, 2 from t = 1.5: the window [0, 1.5] at t = 0 sees the 2.
/// let trace = DenseTrace::from_samples(&[vec![(0.0, 0.0), (1.5, 2.0)]]).unwrap();
/// assert_eq!(monitor.robustness(&trace).unwrap(), 1.0);
/// ```
#[derive(Clone, Debug)]
pub struct Dense {
    time: String,
    vars: Vec<String>,
    formula: DenseFormula,
    /// The formula as messages name it: `the task` or `` `NAME` ``.
    what: String,
}

/// Why a dense-time trace cannot be scored, in the spec's names.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseProblem {
    /// What is wrong.
    pub message: String,
    /// How to fix it, where one fits.
    pub help: Option<String>,
    /// The trace row it is about (counted from 0), where it is about one.
    pub row: Option<usize>,
    /// The state variable it is about, where it is about one (its index in
    /// [`Dense::state_vars`]).
    pub var: Option<usize>,
    /// The time it is about (relative to [`DenseTrace::origin`] when set), where it is
    /// about one: the message does not say it, so that callers write it in their scale.
    pub time: Option<f64>,
}

impl fmt::Display for DenseProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for DenseProblem {}

impl Dense {
    /// The task of the dense-time spec `spec` (`formula = None`) or the `let` called
    /// `formula`.
    pub fn new(spec: &CheckedSpec, formula: Option<&str>) -> Result<Dense, LowerError> {
        let formula_name = formula;
        let Some(time) = &spec.time else {
            return Err(LowerError::TimeModel { spec: spec.name.clone(), dense: false });
        };
        let f = match formula {
            None => lower::task(spec)?,
            Some(name) => lower::let_formula(spec, name)?,
        };
        // The checker rejects what has no dense meaning; a spec with errors does not
        // lower, so this only fails on a spec whose errors were ignored.
        let formula = DenseFormula::new(&f, TimeScale::decimals(spec.time_decimals))
            .map_err(|_| LowerError::Invalid { spec: spec.name.clone() })?;
        Ok(Dense {
            time: time.name.clone(),
            vars: spec.state_vars.iter().map(|v| v.name.clone()).collect(),
            formula,
            what: formula_name.map_or_else(|| "the task".to_string(), |f| format!("`{f}`")),
        })
    }

    /// The time variable: the trace column with the time stamps.
    pub fn time_var(&self) -> &str {
        &self.time
    }

    /// The formula as messages name it: `the task`, or the `let`'s name in backticks.
    pub fn what(&self) -> &str {
        &self.what
    }

    /// The spec's state variables, in order (the time variable is not one).
    pub fn state_vars(&self) -> &[String] {
        &self.vars
    }

    /// Whether every interval bound is a whole number of the time column's unit, so that
    /// whole-number stamps give whole-number change points (`s - b`, `s + a`).
    pub fn whole_bounds(&self) -> bool {
        use hstl_robustness::{Bound, Node};
        let scale = self.formula.scale();
        let whole = |n: usize| scale.bound(n).fract() == 0.0;
        self.formula.formula().nodes().iter().all(|node| match node {
            Node::Always(i, _)
            | Node::Eventually(i, _)
            | Node::Until(i, ..)
            | Node::Once(i, _)
            | Node::Historically(i, _)
            | Node::Since(i, ..) => {
                whole(i.start)
                    && match i.end {
                        Bound::Inclusive(b) | Bound::Exclusive(b) => whole(b),
                        Bound::Unbounded => true,
                    }
            }
            _ => true,
        })
    }

    /// The formula, checked for dense time, with its bounds' time scale.
    pub fn formula(&self) -> &DenseFormula {
        &self.formula
    }

    /// The robustness signal from the trace's first stamp on, as change points (relative
    /// to [`DenseTrace::origin`] when the stamps are whole numbers).
    pub fn signal(&self, trace: &DenseTrace) -> Result<DenseSignal, DenseProblem> {
        self.formula.signal(trace).map_err(|e| self.problem(e))
    }

    /// The robustness at the trace's first stamp.
    pub fn robustness(&self, trace: &DenseTrace) -> Result<f64, DenseProblem> {
        Ok(self.signal(trace)?.first())
    }

    /// The robustness over complete windows ([`DenseFormula::complete_signal`]): the
    /// signal cut at its complete end, and that end (nothing is determined when it comes
    /// before the first stamp).
    pub fn complete_signal(&self, trace: &DenseTrace) -> Result<(DenseSignal, f64), DenseProblem> {
        self.formula.complete_signal(trace).map_err(|e| self.problem(e))
    }

    /// The signal over `windows`, and the time up to which it is determined (`None` over
    /// clipped windows, where every time is).
    pub fn signal_in(
        &self,
        trace: &DenseTrace,
        windows: Windows,
    ) -> Result<(DenseSignal, Option<f64>), DenseProblem> {
        match windows {
            Windows::Clipped => Ok((self.signal(trace)?, None)),
            Windows::Complete => {
                let (signal, end) = self.complete_signal(trace)?;
                Ok((signal, Some(end)))
            }
        }
    }

    /// The robustness at the first stamp over `windows`; `None` when it is undetermined
    /// (complete windows that run past the last stamp).
    pub fn robustness_in(
        &self,
        trace: &DenseTrace,
        windows: Windows,
    ) -> Result<Option<f64>, DenseProblem> {
        let (signal, end) = self.signal_in(trace, windows)?;
        Ok(end.is_none_or(|e| e >= trace.t0()).then(|| signal.first()))
    }

    /// [`Dense::signal_in`] of many traces, on up to `threads` threads (at most
    /// [`MAX_BATCH_THREADS`]); one result per trace, in order.
    pub fn signal_batch(
        &self,
        traces: &[DenseTrace],
        threads: usize,
        windows: Windows,
    ) -> Vec<Result<(DenseSignal, Option<f64>), DenseProblem>> {
        let workers = threads.clamp(1, MAX_BATCH_THREADS).min(traces.len().max(1));
        let chunk = traces.len().div_ceil(workers).max(1);
        std::thread::scope(|scope| {
            let handles: Vec<_> = traces
                .chunks(chunk)
                .map(|part| {
                    scope.spawn(move || {
                        part.iter().map(|t| self.signal_in(t, windows)).collect::<Vec<_>>()
                    })
                })
                .collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)))
                .collect()
        })
    }

    /// An online monitor: rows pushed one at a time, each change point returned once no
    /// later row can change it.
    pub fn online(&self) -> Result<DenseMonitor, DenseProblem> {
        DenseMonitor::new(&self.formula, self.vars.len()).map_err(|e| self.problem(e))
    }

    /// An online monitor that takes stamps as given (whole numbers or doubles, read by
    /// [`StampRules`]), refuses a gap larger than `gap`, gives its change points over
    /// `windows` (over complete windows, each once it also lies before the complete end of
    /// the rows so far), holds at most [`MAX_ONLINE_VALUES`] values, and words its errors
    /// for `front`. Complete windows need bounded future operators: an unbounded one
    /// decides nothing before the trace ends.
    pub fn live(
        &self,
        gap: Option<MaxGap>,
        windows: Windows,
        front: Front,
    ) -> Result<DenseLive, DenseProblem> {
        if windows == Windows::Complete && !self.formula.future_reach().is_finite() {
            // Over complete windows an unbounded operator reads up to its operand's own
            // complete end, which only the whole trace gives.
            return Err(DenseProblem {
                message: format!(
                    "{} needs bounded future operators, and {} has an unbounded one (such as \
                     `always`): no value is final before the input ends",
                    front.online_complete(),
                    self.what
                ),
                help: Some(format!(
                    "{}: the trace is scored whole, over complete windows, with the same result",
                    front.whole_complete()
                )),
                row: None,
                var: None,
                time: None,
            });
        }
        Ok(DenseLive {
            monitor: self.online()?,
            rules: StampRules::new(gap, front),
            windows,
            relative: false,
            limit: MAX_ONLINE_VALUES,
            rows: 0,
            t0: 0.0,
            held: Vec::new(),
            stopped: None,
        })
    }

    /// The trace of a time column and one column per state variable (in
    /// [`Dense::state_vars`]' order), all of one length: row `k` has stamp `time[k]`, and a
    /// NaN in a variable's column is no new sample (the variable keeps its value), as an
    /// empty CSV cell is. Stamps are read by [`StampRules`]; a gap larger than `gap` is
    /// refused (worded for `front`). Problems name the row (counted from 0) and the
    /// variable.
    pub fn trace(
        &self,
        time: StampColumn<'_>,
        columns: &[&[f64]],
        gap: Option<MaxGap>,
        front: Front,
    ) -> Result<DenseTrace, DenseProblem> {
        let n = time.len();
        if columns.len() != self.vars.len() {
            return Err(DenseProblem {
                message: format!(
                    "{} columns given for {} state variables",
                    columns.len(),
                    self.vars.len()
                ),
                help: None,
                row: None,
                var: None,
                time: None,
            });
        }
        if let Some(var) = columns.iter().position(|c| c.len() != n) {
            return Err(DenseProblem {
                message: format!(
                    "`{}` has {} samples, but the time column `{}` has {n}",
                    self.vars[var],
                    columns[var].len(),
                    self.time
                ),
                help: Some(
                    "give one value per row (NaN where a variable has no new sample)".to_string(),
                ),
                row: None,
                var: Some(var),
                time: None,
            });
        }
        let mut rows = self.rows(gap, front);
        let mut cells = vec![None; self.vars.len()];
        for k in 0..n {
            for (cell, col) in cells.iter_mut().zip(columns) {
                let v = col[k];
                *cell = (!v.is_nan()).then_some(v);
            }
            rows.push(self, time.get(k), &cells, Place::Row(k))?;
        }
        rows.build(self)
    }

    /// A trace read row by row ([`DenseRows::push`]) by the stamp rules of every reader.
    pub fn rows(&self, gap: Option<MaxGap>, front: Front) -> DenseRows {
        DenseRows {
            rules: StampRules::new(gap, front),
            builder: DenseTraceBuilder::new(self.vars.len()),
        }
    }

    /// A stamp [`super::StampOrder`] refused, at row `row`.
    pub fn stamp_problem(&self, e: &StampError, row: usize) -> DenseProblem {
        DenseProblem {
            message: e.message(&self.time),
            help: Some(e.help()),
            row: Some(row),
            var: None,
            time: None,
        }
    }

    /// The core's error in the spec's names.
    pub fn problem(&self, e: DenseError) -> DenseProblem {
        use hstl_robustness::dense::DenseTraceError as T;
        let name = |i: usize| self.vars.get(i).cloned().unwrap_or_else(|| format!("column {i}"));
        let plain = |message: String| DenseProblem {
            message,
            help: None,
            row: None,
            var: None,
            time: None,
        };
        match e {
            DenseError::Nan { time, atom } => DenseProblem {
                message: format!("the comparison `{}` computes NaN", self.named(&atom)),
                help: Some(
                    "robustness has no meaning for NaN: write the comparison so that it is \
                     defined on every sample (`sqrt` of a negative, `0 / 0` and `inf - inf` \
                     are NaN)"
                        .to_string(),
                ),
                row: None,
                var: None,
                time: Some(time),
            },
            DenseError::Trace(t) => match t {
                T::NanValue { var, row } => DenseProblem {
                    message: format!("`{}` is NaN", name(var)),
                    help: Some(
                        "robustness has no meaning for NaN: give a number (`inf` and `-inf` \
                         are allowed), or leave the cell empty to keep the last value"
                            .to_string(),
                    ),
                    row: Some(row),
                    var: Some(var),
                    time: None,
                },
                T::MissingFirst { var, t0 } => DenseProblem {
                    message: format!("`{}` has no sample at the first time stamp, {t0}", name(var)),
                    help: Some(
                        "every variable needs a value at the first stamp: no value exists \
                         before it"
                            .to_string(),
                    ),
                    row: Some(0),
                    var: Some(var),
                    time: None,
                },
                T::NotIncreasing { row, previous, stamp } => DenseProblem {
                    message: format!(
                        "the time stamp {stamp} does not come after the previous one, {previous}"
                    ),
                    help: Some(
                        "time stamps must strictly increase: sort the rows, or merge \
                                rows with the same stamp"
                            .to_string(),
                    ),
                    row: Some(row),
                    var: None,
                    time: None,
                },
                T::Inexact { row, .. } | T::MixedStamps { row } | T::BadStamp { row, .. } => {
                    let help = match t {
                        T::Inexact { .. } => {
                            "whole-number stamps are taken relative to the first, within 2^53 \
                             units of it: monitor the parts of the trace before and after the \
                             jump separately, or write the stamps in a coarser unit"
                        }
                        T::MixedStamps { .. } => {
                            "write every stamp of a trace as a whole number, or every one as a \
                             decimal"
                        }
                        _ => "write each row's stamp as a finite number, such as `0.02`",
                    };
                    DenseProblem {
                        row: Some(row),
                        help: Some(help.to_string()),
                        ..plain(strip_row(&t.to_string()))
                    }
                }
                T::Empty | T::RowWidth { .. } => plain(t.to_string()),
            },
            other => plain(self.named(&other.to_string())),
        }
    }

    /// `text` with the core's variable names (`v0`, `v1`, ...) replaced by the spec's.
    fn named(&self, text: &str) -> String {
        let mut out = String::with_capacity(text.len());
        let bytes = text.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            let word_start =
                i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'_');
            if word_start && bytes[i] == b'v' {
                let digits = bytes[i + 1..].iter().take_while(|b| b.is_ascii_digit()).count();
                let end = i + 1 + digits;
                let word_end = end >= bytes.len()
                    || !(bytes[end].is_ascii_alphanumeric() || bytes[end] == b'_');
                if digits > 0
                    && word_end
                    && let Some(name) =
                        text[i + 1..end].parse::<usize>().ok().and_then(|k| self.vars.get(k))
                {
                    out.push_str(name);
                    i = end;
                    continue;
                }
            }
            let c = text[i..].chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
        }
        out
    }
}

/// A time column: whole numbers (as integer numpy columns hold them) or doubles.
#[derive(Clone, Copy, Debug)]
pub enum StampColumn<'a> {
    /// Signed whole numbers.
    Int(&'a [i64]),
    /// Unsigned whole numbers.
    UInt(&'a [u64]),
    /// Doubles.
    Real(&'a [f64]),
}

impl StampColumn<'_> {
    /// The number of stamps.
    pub fn len(&self) -> usize {
        match self {
            StampColumn::Int(s) => s.len(),
            StampColumn::UInt(s) => s.len(),
            StampColumn::Real(s) => s.len(),
        }
    }

    /// Whether there is no stamp.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Stamp `k`.
    pub fn get(&self, k: usize) -> Stamp {
        match self {
            StampColumn::Int(s) => Stamp::Int(i128::from(s[k])),
            StampColumn::UInt(s) => Stamp::Int(i128::from(s[k])),
            StampColumn::Real(s) => Stamp::Real(s[k]),
        }
    }
}

/// A dense-time trace read row by row ([`Dense::rows`]): stamps by [`StampRules`], each
/// row's cells as [`DenseTraceBuilder`] takes them.
#[derive(Clone, Debug)]
pub struct DenseRows {
    rules: StampRules,
    builder: DenseTraceBuilder,
}

impl DenseRows {
    /// Appends a row (`None`: no new sample of that variable), `at` where the reader found
    /// it. A refused row changes nothing; problems name the row counted from 0.
    pub fn push(
        &mut self,
        dense: &Dense,
        stamp: Stamp,
        cells: &[Option<f64>],
        at: Place,
    ) -> Result<(), DenseProblem> {
        let row = self.builder.len();
        let stamp = self.rules.check(dense, stamp, row)?;
        stamp.push(&mut self.builder, cells).map_err(|e| {
            let mut p = dense.problem(DenseError::Trace(e));
            p.row = p.row.map(|_| row);
            p
        })?;
        self.rules.take(stamp, at);
        Ok(())
    }

    /// The rows pushed so far.
    pub fn len(&self) -> usize {
        self.builder.len()
    }

    /// Whether no row was pushed.
    pub fn is_empty(&self) -> bool {
        self.builder.is_empty()
    }

    /// The trace; fails if no row was pushed.
    pub fn build(self, dense: &Dense) -> Result<DenseTrace, DenseProblem> {
        self.builder.build().map_err(|e| dense.problem(DenseError::Trace(e)))
    }
}

/// A dense-time monitor fed rows as they arrive ([`Dense::live`]): stamps read by
/// [`StampRules`], gaps checked, change points given over clipped or complete windows,
/// memory bounded by [`MAX_ONLINE_VALUES`]. What `hstlc monitor --online` and Python's
/// `OnlineMonitor` run for a dense-time spec.
#[derive(Clone, Debug)]
pub struct DenseLive {
    monitor: DenseMonitor,
    rules: StampRules,
    windows: Windows,
    /// Times relative to the first stamp.
    relative: bool,
    /// The most values held.
    limit: usize,
    rows: usize,
    /// The first stamp, when stamps are doubles.
    t0: f64,
    /// Over complete windows: decided change points not yet known to lie before the
    /// complete end.
    held: Vec<(f64, f64)>,
    /// The row where a comparison computed NaN: the trace cannot go on.
    stopped: Option<usize>,
}

impl DenseLive {
    /// The same monitor with its times relative to the first stamp (`relative`) or in the
    /// time column's scale.
    pub fn relative(mut self, relative: bool) -> DenseLive {
        self.relative = relative;
        self
    }

    /// The same monitor holding at most `limit` values (at most [`MAX_ONLINE_VALUES`]).
    pub fn with_limit(mut self, limit: usize) -> DenseLive {
        self.limit = limit.min(MAX_ONLINE_VALUES);
        self
    }

    /// The most values the monitor holds.
    pub fn limit(&self) -> usize {
        self.limit
    }

    /// Appends a row (`None`: no new sample of that variable) and returns the change points
    /// it decided, `(t, value)`, times relative to [`DenseLive::origin`] when set. A row
    /// refused for its stamp or its cells changes nothing; a row on which a comparison
    /// computes NaN stops the trace (until [`DenseLive::finish`]). Errors name the row
    /// counted from 0 ([`DenseLive::push_at`] for rows found elsewhere).
    pub fn push(
        &mut self,
        dense: &Dense,
        stamp: Stamp,
        cells: &[Option<f64>],
    ) -> Result<Vec<(f64, f64)>, DenseProblem> {
        self.push_at(dense, stamp, cells, Place::Row(self.rows))
    }

    /// [`DenseLive::push`] of a row the reader found at `at` (a file's line, say), which a
    /// later row's gap error names.
    pub fn push_at(
        &mut self,
        dense: &Dense,
        stamp: Stamp,
        cells: &[Option<f64>],
        at: Place,
    ) -> Result<Vec<(f64, f64)>, DenseProblem> {
        let row = self.rows;
        if let Some(stop) = self.stopped {
            return Err(DenseProblem {
                message: format!(
                    "the trace stopped at row {stop}, where a comparison computed NaN"
                ),
                help: Some("call `finish()` to start a new trace".to_string()),
                row: Some(row),
                var: None,
                time: None,
            });
        }
        let stamp = self.rules.check(dense, stamp, row)?;
        let width = dense.vars.len() + 1;
        if self.monitor.kept().saturating_add(1).saturating_mul(width) > self.limit {
            let why = if dense.formula.future_reach().is_finite() {
                "its windows read"
            } else {
                "until the trace ends (it has an unbounded future operator, such as `always`)"
            };
            let front = self.rules.front();
            return Err(DenseProblem {
                message: format!(
                    "the monitor holds more than {} values, and {} keeps every row {why}",
                    self.limit, dense.what
                ),
                help: Some(format!(
                    "monitor a formula with bounded windows ({} with a `let`), or {}",
                    front.formula(),
                    front.end_sooner()
                )),
                row: Some(row),
                var: None,
                time: None,
            });
        }
        // The core checks the cells before it takes the row: a refused row changes nothing.
        let decided = match stamp {
            Stamp::Int(s) => self.monitor.push_int(s, cells),
            Stamp::Real(t) => self.monitor.push(t, cells),
        }
        .map_err(|e| {
            if matches!(e, DenseError::Nan { .. }) {
                self.stopped = Some(row);
            }
            let mut p = dense.problem(e);
            p.row = p.row.map(|_| row);
            p
        })?;
        if row == 0
            && let Stamp::Real(t) = stamp
        {
            self.t0 = t;
        }
        self.rules.take(stamp, at);
        self.rows += 1;
        if self.windows == Windows::Clipped {
            return Ok(decided);
        }
        self.held.extend(decided);
        let end = self.complete_end(dense).unwrap_or(f64::NEG_INFINITY);
        let before = self.held.partition_point(|&(t, _)| t < end);
        Ok(self.held.drain(..before).collect())
    }

    /// Over complete windows, the time up to which the rows so far determine the signal
    /// (`None` over clipped windows, or before the first row).
    pub fn complete_end(&self, dense: &Dense) -> Option<f64> {
        let (_, last) = self.monitor.span()?;
        (self.windows == Windows::Complete).then(|| dense.formula.complete_end(last))
    }

    /// Ends the trace: the change points not returned yet, up to the last stamp; over
    /// complete windows, those before the complete end and then, if the complete end comes
    /// before the last stamp, a point at it (or at the first stamp, if it comes before)
    /// with the value NaN: the times from it on are undetermined. The monitor then starts
    /// a new trace.
    pub fn finish(&mut self, dense: &Dense) -> Result<Vec<(f64, f64)>, DenseProblem> {
        let span = self.monitor.span();
        let end = self.complete_end(dense);
        let rest = self.monitor.finish().map_err(|e| dense.problem(e));
        let mut held = std::mem::take(&mut self.held);
        self.rules.restart();
        self.rows = 0;
        self.t0 = 0.0;
        if self.stopped.take().is_some() {
            // The operators stopped halfway through a row: start afresh.
            self.monitor = dense.online()?;
            return Ok(Vec::new());
        }
        let rest = rest?;
        let (Some(end), Some((t0, last))) = (end, span) else { return Ok(rest) };
        held.extend(rest);
        if end < last {
            held.truncate(held.partition_point(|&(t, _)| t < end));
            held.push((end.max(t0), f64::NAN));
        }
        Ok(held)
    }

    /// The rows given since creation or the last [`DenseLive::finish`].
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The first whole-number stamp, when stamps are whole numbers beyond 2^53.
    pub fn origin(&self) -> Option<i128> {
        self.monitor.origin()
    }

    /// How this trace's times are written: relative to the first stamp (`relative`) or in
    /// the column's scale.
    pub fn axis(&self, relative: bool) -> TimeAxis {
        TimeAxis { relative, origin: self.origin(), t0: self.t0 }
    }

    /// How this trace's times are written, as the monitor was set ([`DenseLive::relative`]).
    pub fn times(&self) -> TimeAxis {
        self.axis(self.relative)
    }

    /// Whether times are relative to the first stamp.
    pub fn is_relative(&self) -> bool {
        self.relative
    }

    /// The windows the change points are given over.
    pub fn windows(&self) -> Windows {
        self.windows
    }

    /// The gap bound, if any.
    pub fn max_gap(&self) -> Option<&MaxGap> {
        self.rules.gap()
    }
}

/// A [`DenseLive`] monitor's state as plain data ([`DenseLive::snapshot`]): its settings,
/// the stamp of its last row, the change points it holds back, and its operators' state
/// ([`DenseMonitor::save`]'s bytes). [`DenseLive::restore`] checks every field.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseLiveState {
    /// The windows change points are given over.
    pub windows: Windows,
    /// Whether times are relative to the first stamp.
    pub relative: bool,
    /// The gap bound as written, if any.
    pub max_gap: Option<String>,
    /// The most values the monitor holds.
    pub limit: usize,
    /// The rows given since the trace began.
    pub rows: usize,
    /// The last row's stamp as the trace took it (a whole number for stamps beyond 2^53).
    pub last: Option<Stamp>,
    /// The first stamp, when stamps are doubles (0 otherwise).
    pub t0: f64,
    /// Over complete windows: decided change points not yet known to lie before the
    /// complete end.
    pub held: Vec<(f64, f64)>,
    /// The row where a comparison computed NaN, if one did.
    pub stopped: Option<usize>,
    /// The operators' state: [`DenseMonitor::save`]'s bytes.
    pub monitor: Vec<u8>,
}

impl DenseLive {
    /// The monitor's state as plain data, from which [`DenseLive::restore`] continues
    /// exactly (the same change points, bit for bit, and the same errors).
    pub fn snapshot(&self) -> DenseLiveState {
        DenseLiveState {
            windows: self.windows,
            relative: self.relative,
            max_gap: self.rules.gap().map(|g| g.text().to_string()),
            limit: self.limit,
            rows: self.rows,
            last: self.rules.last(),
            t0: self.t0,
            held: self.held.clone(),
            stopped: self.stopped,
            monitor: self.monitor.save(),
        }
    }

    /// The monitor `state` describes, for `dense` (the monitor's formula), worded for
    /// `front`. Every field is checked against the others and the operators' state: a
    /// state that no monitor of this formula could have reached is refused, saying what
    /// does not fit.
    pub fn restore(
        dense: &Dense,
        state: &DenseLiveState,
        front: Front,
    ) -> Result<DenseLive, DenseProblem> {
        let bad = |what: String| DenseProblem {
            message: format!("the saved monitor state is damaged: {what}"),
            help: Some(
                "save the monitor again from a running one (pickle it); a state changed by \
                 hand, cut short or saved by another formula is refused"
                    .to_string(),
            ),
            row: None,
            var: None,
            time: None,
        };
        let gap = match &state.max_gap {
            Some(text) => Some(
                MaxGap::parse(text, front.max_gap())
                    .map_err(|p| bad(format!("its gap bound: {}", p.message)))?,
            ),
            None => None,
        };
        if !(1..=MAX_ONLINE_VALUES).contains(&state.limit) {
            return Err(bad(format!(
                "its budget is {} values, and a monitor holds 1 to {MAX_ONLINE_VALUES}",
                state.limit
            )));
        }
        if state.windows == Windows::Complete && !dense.formula.future_reach().is_finite() {
            return Err(bad(format!(
                "it is over complete windows, and {} has an unbounded future operator",
                dense.what
            )));
        }
        let monitor = DenseMonitor::load(&dense.formula, dense.vars.len(), &state.monitor)
            .map_err(|e| bad(format!("its operators: {e}")))?;
        let rows = state.rows;
        if state.stopped.is_some_and(|s| s != rows) {
            return Err(bad(format!(
                "it stopped at row {}, and it has {rows} rows",
                state.stopped.unwrap_or(0)
            )));
        }
        if (rows == 0) != state.last.is_none() {
            let last = state.last.map_or_else(|| "none".to_string(), |s| s.to_string());
            return Err(bad(format!("it has {rows} rows, and its last stamp is {last}")));
        }
        if !(state.t0.is_finite() && (rows > 0 || state.t0 == 0.0)) {
            return Err(bad(format!("its first stamp is {}", state.t0)));
        }
        if state.stopped.is_none() {
            if monitor.rows() != rows {
                return Err(bad(format!(
                    "it has {rows} rows, and its operators have taken {}",
                    monitor.rows()
                )));
            }
            // The last stamp as the operators hold it: relative to the first whole-number
            // stamp, or the double itself.
            let fits = match (state.last, monitor.span(), monitor.origin()) {
                (None, None, _) => true,
                (Some(Stamp::Int(s)), Some((t0, x)), Some(o)) => {
                    let rel = s.checked_sub(o).filter(|&d| d >= 0);
                    state.t0 == 0.0
                        && t0 == 0.0
                        && rel.is_some_and(|d| d as f64 == x && (d as f64) as i128 == d)
                }
                (Some(Stamp::Real(t)), Some((t0, x)), None) => t == x && state.t0 == t0,
                _ => false,
            };
            if !fits {
                return Err(bad(
                    "its stamps (the first and the last row's) do not agree with its operators'"
                        .to_string(),
                ));
            }
        }
        // Held points: decided, so at or before the last stamp, after the complete end (of
        // the rows before a row that stopped the trace, whose operators stopped halfway).
        let span = monitor.span();
        let end = span.map(|(_, x)| dense.formula.complete_end(x));
        let mut prev = f64::NEG_INFINITY;
        for &(t, v) in &state.held {
            let inside = state.stopped.is_some()
                || span.is_some_and(|(_, x)| t <= x) && end.is_some_and(|e| t >= e);
            if !(t.is_finite() && t > prev && !v.is_nan() && inside) {
                return Err(bad(format!(
                    "a change point it holds back, ({t}, {v}), is not a decided point after the \
                     complete end, in order"
                )));
            }
            prev = t;
        }
        if state.windows == Windows::Clipped && !state.held.is_empty() {
            return Err(bad("it holds change points back over clipped windows".to_string()));
        }
        let prev_at = rows.checked_sub(1).map(Place::Row);
        Ok(DenseLive {
            monitor,
            rules: StampRules::resume(gap, front, state.last, prev_at),
            windows: state.windows,
            relative: state.relative,
            limit: state.limit,
            rows,
            t0: state.t0,
            held: state.held.clone(),
            stopped: state.stopped,
        })
    }
}

/// The core's `row N: ` prefix dropped (callers say where themselves).
fn strip_row(message: &str) -> String {
    match message.strip_prefix("row ").and_then(|m| m.split_once(": ")) {
        Some((n, rest)) if n.bytes().all(|b| b.is_ascii_digit()) => rest.to_string(),
        _ => message.to_string(),
    }
}

/// Checking a stamp is worded with the dense spec's names, so it lives with [`Dense`].
impl StampRules {
    /// The stamp of the next row (row `row` of the trace, counted from 0) as the trace
    /// takes it, or what is wrong with it (worded with `dense`'s time variable); nothing
    /// changes until [`StampRules::take`].
    pub fn check(&self, dense: &Dense, stamp: Stamp, row: usize) -> Result<Stamp, DenseProblem> {
        let prev = self.order.last();
        let mut order = self.order.clone();
        let stamp = order.next(stamp).map_err(|e| dense.stamp_problem(&e, row))?;
        if let (Some(gap), Some(p)) = (&self.gap, prev)
            && let Some(width) = gap.exceeded(p, stamp)
        {
            let at = self.prev_at.map_or_else(String::new, |at| format!(" ({at})"));
            let p = gap.problem(&width, (p, &at), stamp, dense.time_var(), self.front.max_gap());
            return Err(DenseProblem {
                message: p.message,
                help: p.help,
                row: Some(row),
                var: None,
                time: None,
            });
        }
        Ok(stamp)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_number_times_print_exactly_in_the_column_scale() {
        let ns = 1_700_000_000_123_456_789i128;
        assert_eq!(time_text(Some(ns), 0.0), "1700000000123456789");
        assert_eq!(time_text(Some(ns), 250.0), "1700000000123457039");
        assert_eq!(time_text(Some(ns), 2.5), "1700000000123456791.5");
        assert_eq!(time_text(Some(10), 0.39999999999999997), "10.39999999999999997");
        assert_eq!(time_text(None, 0.39999999999999997), "0.39999999999999997");
        assert_eq!(time_text(None, 3.0), "3");
    }

    #[test]
    fn core_names_become_the_spec_names() {
        let src = "spec S { state { t: time, speed: float, v1: float } \
                   task eventually[0..=1] speed > 1; }";
        let checked = hstl_lang::check(src);
        let d = Dense::new(&checked.specs[0], None).unwrap();
        assert_eq!(d.named("v0 - v1 > 0 and v10"), "speed - v1 > 0 and v10");
        assert_eq!(d.time_var(), "t");
        assert_eq!(d.state_vars(), ["speed", "v1"]);
        // A discrete monitor refuses the dense spec, and the reverse.
        assert!(matches!(
            crate::monitor::Monitor::new(&checked.specs[0], None),
            Err(LowerError::TimeModel { dense: true, .. })
        ));
        let discrete = hstl_lang::check("spec D { state { x: float } task x > 1; }");
        assert!(matches!(
            Dense::new(&discrete.specs[0], None),
            Err(LowerError::TimeModel { dense: false, .. })
        ));
    }

    #[test]
    fn decimal_bounds_read_through_the_spec_scale() {
        // The worked example of DENSE-TIME.md: `always[0.5..=1.5] x > 1`.
        let src = "spec S { state { t: time, x: float } task always[0.5..=1.5] x > 1; }";
        let checked = hstl_lang::check(src);
        let d = Dense::new(&checked.specs[0], None).unwrap();
        let x = vec![(0.0, 1.0), (1.0, 2.0), (2.0, 3.0), (3.5, 0.5), (5.0, 4.0)];
        let trace = DenseTrace::from_samples(&[x]).unwrap();
        let s = d.signal(&trace).unwrap();
        let points: Vec<(f64, f64)> = s.until(trace.t_last()).collect();
        assert_eq!(points, [(0.0, 0.0), (0.5, 1.0), (1.5, 2.0), (2.0, -0.5), (4.5, 3.0)]);
    }
}
