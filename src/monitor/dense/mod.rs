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

mod live;

pub use live::{DenseLive, DenseLiveState};

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
