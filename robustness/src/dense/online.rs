//! The online dense-time monitor: samples arrive one row at a time, change points of the
//! robustness signal leave once no later sample can change them.

use super::offline::{self, Rows};
use super::{DenseError, DenseFormula, DenseTraceBuilder};

/// Monitors a [`DenseFormula`] over rows of time-stamped samples pushed one at a time.
///
/// After a row with stamp `X`, the signal is decided on `[t0, X - H)` where `H` is the
/// formula's future reach ([`DenseFormula::future_reach`]), less a few ulps: a later sample
/// starts after `X` and a value at `t` reads no further than `t + H`. [`DenseMonitor::push`]
/// returns the change points that became decided (`(t, value)`: the value holds from `t`
/// until the next change point); [`DenseMonitor::finish`] ends the trace and returns the
/// rest up to the last stamp. Together they are exactly [`DenseFormula::signal`]'s change
/// points up to the last stamp.
///
/// The monitor keeps only the rows the undecided part reads: those within the future and
/// past reaches of the decided frontier, so memory is bounded by the windows (an unbounded
/// operator keeps every row, and an unbounded future operator decides nothing before the
/// end). Each decision re-evaluates the kept rows; by default that happens at every push
/// (verdicts as soon as they are decided), and [`DenseMonitor::set_batch`] trades delay for
/// throughput (one evaluation per `n` rows).
#[derive(Clone, Debug)]
pub struct DenseMonitor {
    formula: DenseFormula,
    rows: DenseTraceBuilder,
    vars: usize,
    /// Change points before this time have been returned.
    decided: f64,
    /// The last value returned.
    last: Option<f64>,
    batch: usize,
    pending: usize,
}

/// `x` lowered by a relative margin of a few ulps (and a tiny absolute one), so a frontier
/// computed in rounded arithmetic stays on the safe side.
fn down(x: f64, scale: f64) -> f64 {
    x - (x.abs() + scale) * f64::EPSILON * 16.0 - f64::MIN_POSITIVE
}

impl DenseMonitor {
    /// A monitor for `formula` over rows of `vars` variables.
    pub fn new(formula: &DenseFormula, vars: usize) -> Result<DenseMonitor, DenseError> {
        if let Some(var) = formula.formula().max_var()
            && var >= vars
        {
            return Err(DenseError::MissingVar { var, vars });
        }
        Ok(DenseMonitor {
            formula: formula.clone(),
            rows: DenseTraceBuilder::new(vars),
            vars,
            decided: f64::NEG_INFINITY,
            last: None,
            batch: 1,
            pending: 0,
        })
    }

    /// Evaluates once every `n` rows (at least 1) instead of at every row: verdicts come up
    /// to `n` rows late, and the work per row drops from the window's length to about
    /// `1 + window / n`.
    pub fn set_batch(&mut self, n: usize) {
        self.batch = n.max(1);
    }

    /// The number of rows kept.
    pub fn kept(&self) -> usize {
        self.rows.rows().0.len()
    }

    /// Appends a row with stamp `t` (`None`: no new sample of that variable) and returns
    /// the change points it decided.
    pub fn push(&mut self, t: f64, cells: &[Option<f64>]) -> Result<Vec<(f64, f64)>, DenseError> {
        self.rows.push(t, cells)?;
        self.advance()
    }

    /// [`DenseMonitor::push`] with a whole-number stamp (nanoseconds, say), taken relative
    /// to the first row's stamp in integer arithmetic; the change points' times are
    /// relative to it too ([`DenseMonitor::origin`]).
    pub fn push_int(
        &mut self,
        stamp: impl Into<i128>,
        cells: &[Option<f64>],
    ) -> Result<Vec<(f64, f64)>, DenseError> {
        self.rows.push_int(stamp, cells)?;
        self.advance()
    }

    /// The first whole-number stamp, when rows have whole-number stamps.
    pub fn origin(&self) -> Option<i128> {
        self.rows.origin()
    }

    fn advance(&mut self) -> Result<Vec<(f64, f64)>, DenseError> {
        self.pending += 1;
        let (times, _) = self.rows.rows();
        if self.decided == f64::NEG_INFINITY {
            self.decided = times[0];
        }
        let x = times[times.len() - 1];
        let reach = self.formula.future_reach();
        let frontier = down(x - reach, reach);
        if self.pending < self.batch || frontier <= self.decided {
            return Ok(Vec::new());
        }
        self.pending = 0;
        let out = self.emit(frontier, true)?;
        self.forget();
        Ok(out)
    }

    /// Evaluates the kept rows and returns the new change points before `frontier` (up to
    /// it, inclusive, when not `open`).
    fn emit(&mut self, frontier: f64, open: bool) -> Result<Vec<(f64, f64)>, DenseError> {
        let (times, columns) = self.rows.rows();
        let rows = Rows { times, columns: columns.iter().map(Vec::as_slice).collect() };
        let sig = offline::evaluate(&self.formula, &rows)?;
        let mut out = Vec::new();
        // The kept rows give the right values from `decided` on (see `forget`).
        let from = sig.times.partition_point(|&s| s < self.decided);
        for (&t, &v) in sig.times[from..].iter().zip(&sig.values[from..]) {
            if if open { t >= frontier } else { t > frontier } {
                break;
            }
            if self.last != Some(v) {
                out.push((t, v));
                self.last = Some(v);
            }
        }
        // A value decided at `decided` and unchanged since: nothing to emit, but the
        // frontier moves on.
        self.decided = frontier;
        Ok(out)
    }

    /// Drops the rows no undecided value reads: a value at `t >= decided` reads back no
    /// further than `decided - past_reach`, so the last row at or before that is the first
    /// one kept (it holds the values there).
    fn forget(&mut self) {
        let reach = self.formula.past_reach();
        if reach == f64::INFINITY {
            return;
        }
        let keep_from = down(self.decided - reach, reach);
        let (times, _) = self.rows.rows();
        let k = times.partition_point(|&s| s <= keep_from);
        // Dropping is a copy of what is kept: do it when it halves the rows at least.
        if k > times.len() / 2 {
            self.rows.drop_front(k - 1);
        }
    }

    /// Ends the trace: the change points not returned yet, up to the last stamp. The
    /// monitor is then ready for a new trace.
    pub fn finish(&mut self) -> Result<Vec<(f64, f64)>, DenseError> {
        let (times, _) = self.rows.rows();
        let out = match times.last() {
            None => Vec::new(),
            Some(&t_last) => self.emit(t_last, false)?,
        };
        self.rows = DenseTraceBuilder::new(self.vars);
        self.decided = f64::NEG_INFINITY;
        self.last = None;
        self.pending = 0;
        Ok(out)
    }
}
