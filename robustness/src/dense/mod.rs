//! Dense-time robustness: rtamt's dense-time STL over time-stamped, piecewise-constant
//! signals.
//!
//! A [`DenseTrace`] holds time-stamped samples, each variable a right-continuous step
//! function that holds its last value forever after the last stamp. `rho(f, t)` is defined
//! for every real `t >= t0` (the first stamp):
//!
//! | formula | `rho(f, t)` |
//! |---|---|
//! | `eventually[a..=b] f` | max of `rho(f, t')` over `t'` in `[t+a, t+b]` |
//! | `always[a..=b] f` | min over the same window |
//! | `eventually[a..] f`, `always[a..] f` | max / min over `[t+a, +inf)` |
//! | `f until[a..=b] g` | max over `t'` in `[t+a, t+b]` of min(`rho(g, t')`, min of `rho(f)` over `[t, t']`) |
//! | `once[a..=b] f` | max over `t'` in `[t-b, t-a]` with `t' >= t0`; `-inf` if empty |
//! | `historically[a..=b] f` | min over the same; `+inf` if empty |
//! | `f since[a..=b] g` | max over those `t'` of min(`rho(g, t')`, min of `rho(f)` over `[t', t]`) |
//!
//! Comparisons, `!`, `&&`, `||` and `->` are pointwise. Future windows are never clipped
//! (past the last stamp they read the held values); past windows are clipped at `t0`.
//! `prev`, `next` and half-open intervals `[a..b]` have no dense meaning:
//! [`DenseFormula::new`] rejects them.
//!
//! Interval bounds are [`Formula`] bounds (whole numbers) read through a [`TimeScale`]:
//! with `TimeScale::decimals(1)` the bound `25` means `2.5`, read as the nearest double.
//! Every breakpoint is computed as rtamt computes it, one IEEE operation per window end
//! (`s_k - b`, `s_k + a`), so results match rtamt's bit for bit. Timed `until` and `since`
//! take the values of rtamt's decomposition (`eventually[a..=b] g && always[0..=a] (f until
//! g)`, and so on); bounded `until` computes them by a sweep over pieces that reads no
//! further than its window and equals the decomposition value for value at every time
//! (the sign of a zero aside, which is not pinned). The full statement, with where rtamt is wrong and hstl is not, is
//! `docs/DENSE-TIME-DEVIATIONS.md` in the repository.
//!
//! - [`DenseFormula::signal`] computes the whole signal offline, in time linear in the
//!   number of change points whatever the windows' lengths;
//! - [`DenseMonitor`] takes samples one at a time and gives each change point of the
//!   signal once no later sample can change it, streaming: its work per row does not grow
//!   with the windows' lengths.

mod minmax;
mod offline;
mod online;
mod saved;
mod signal;
mod trace;
mod until;

pub use online::DenseMonitor;
pub use saved::{SavedStateError, resum};
pub use signal::DenseSignal;
pub use trace::{DenseTrace, DenseTraceBuilder, DenseTraceError};

use crate::Formula;
use crate::formula::{Bound, Interval, Node};
use std::fmt;

/// How whole-number interval bounds read as times: bound `n` is `n / 10^decimals`, read as
/// the nearest double (so `3` with one decimal is `0.3`, not `3 * 0.1`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct TimeScale {
    decimals: u32,
}

impl TimeScale {
    /// Bounds are whole numbers of the time column's unit.
    pub const WHOLE: TimeScale = TimeScale { decimals: 0 };

    /// Bounds are counted in `10^-decimals` of the time column's unit.
    pub fn decimals(decimals: u32) -> TimeScale {
        TimeScale { decimals }
    }

    /// The number of decimals.
    pub fn decimal_places(self) -> u32 {
        self.decimals
    }

    /// The time bound `n` stands for: the double nearest `n / 10^decimals`.
    pub fn bound(self, n: usize) -> f64 {
        if self.decimals == 0 {
            // Rounds to nearest, as reading the decimal would.
            n as f64
        } else {
            format!("{n}e-{}", self.decimals).parse().unwrap_or(f64::NAN)
        }
    }

    /// The bound `n` written as a decimal (`25` with one decimal is `2.5`).
    pub fn text(self, n: usize) -> String {
        let d = self.decimals as usize;
        if d == 0 {
            return n.to_string();
        }
        let digits = format!("{n:0>width$}", width = d + 1);
        let (int, frac) = digits.split_at(digits.len() - d);
        let frac = frac.trim_end_matches('0');
        if frac.is_empty() { int.to_string() } else { format!("{int}.{frac}") }
    }

    /// The interval as written with this scale (`[0..=2.5]`).
    pub fn interval_text(self, i: &Interval) -> String {
        let a = self.text(i.start);
        match i.end {
            Bound::Unbounded => format!("[{a}..]"),
            Bound::Exclusive(b) => format!("[{a}..{}]", self.text(b)),
            Bound::Inclusive(b) => format!("[{a}..={}]", self.text(b)),
        }
    }

    /// Reads a decimal bound as written (`2.5`, `10`, `1e-3`): its digits as a whole number
    /// and its number of decimals, so that `TimeScale::decimals(d).bound(n)` reads it back.
    /// `None` for a negative, non-numeric or too long number.
    pub fn parse_decimal(text: &str) -> Option<(u128, u32)> {
        let text = text.trim();
        let (mantissa, exp) = match text.find(['e', 'E']) {
            Some(k) => (&text[..k], text[k + 1..].parse::<i32>().ok()?),
            None => (text, 0),
        };
        let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
        if int.is_empty() && frac.is_empty()
            || !int.bytes().chain(frac.bytes()).all(|c| c.is_ascii_digit())
        {
            return None;
        }
        let frac = frac.trim_end_matches('0');
        let digits: String = format!("{int}{frac}");
        let mut n: u128 = if digits.is_empty() { 0 } else { digits.parse().ok()? };
        let mut decimals = i64::try_from(frac.len()).ok()? - i64::from(exp);
        while decimals < 0 {
            n = n.checked_mul(10)?;
            decimals += 1;
        }
        while decimals > 0 && n.is_multiple_of(10) && n != 0 {
            n /= 10;
            decimals -= 1;
        }
        if n == 0 {
            decimals = 0;
        }
        Some((n, u32::try_from(decimals).ok()?))
    }
}

/// Why a formula cannot be monitored in dense time, or an evaluation failed.
#[derive(Clone, Debug, PartialEq)]
pub enum DenseError {
    /// `prev` or `next`: no dense-time meaning.
    NoDenseMeaning {
        /// The operator.
        op: &'static str,
    },
    /// A half-open interval `[a..b]`: it gives values that hold at single instants.
    HalfOpen {
        /// The interval as written.
        interval: String,
    },
    /// An interval whose end comes before its start.
    Inverted {
        /// The interval as written.
        interval: String,
    },
    /// A bound that is not a number once scaled.
    BadBound {
        /// The interval as written.
        interval: String,
    },
    /// The formula reads a variable the trace does not have.
    MissingVar {
        /// The variable's index.
        var: usize,
        /// The trace's number of variables.
        vars: usize,
    },
    /// A comparison computes NaN (`sqrt(-1)`, `inf - inf`, ...).
    Nan {
        /// The time (relative to the trace's origin, if any) where it does.
        time: f64,
        /// The comparison, variables written `v0`, `v1`, ...
        atom: String,
    },
    /// The trace could not be built.
    Trace(DenseTraceError),
}

impl fmt::Display for DenseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DenseError::NoDenseMeaning { op } => write!(
                f,
                "`{op}` has no dense-time meaning (there is no next or previous sample in \
                 continuous time)"
            ),
            DenseError::HalfOpen { interval } => write!(
                f,
                "the half-open interval `{interval}` has no dense-time meaning; write `[a..=b]`"
            ),
            DenseError::Inverted { interval } => {
                write!(f, "the interval `{interval}` ends before it starts")
            }
            DenseError::BadBound { interval } => {
                write!(f, "a bound of the interval `{interval}` is not a finite time")
            }
            DenseError::MissingVar { var, vars } => write!(
                f,
                "the formula reads variable {var}, but the trace has {vars} variable{}",
                if *vars == 1 { "" } else { "s" }
            ),
            DenseError::Nan { time, atom } => {
                write!(f, "the comparison `{atom}` computes NaN at time {time}")
            }
            DenseError::Trace(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for DenseError {}

impl From<DenseTraceError> for DenseError {
    fn from(e: DenseTraceError) -> DenseError {
        DenseError::Trace(e)
    }
}

/// A formula checked for dense time, with its interval bounds read as times.
///
/// Build one with [`DenseFormula::new`], then compute signals on any number of traces.
#[derive(Clone, Debug)]
pub struct DenseFormula {
    formula: Formula,
    scale: TimeScale,
    /// `(a, b)` for every temporal node (`b` infinite when unbounded); `(0, 0)` elsewhere.
    bounds: Vec<(f64, f64)>,
    /// How far into the future and the past the root's value reads (exact arithmetic,
    /// rounded up; infinite when unbounded).
    future: f64,
    past: f64,
}

impl DenseFormula {
    /// Checks `formula` for dense time: no `prev` or `next`, no half-open or inverted
    /// interval; bounds read through `scale`.
    pub fn new(formula: &Formula, scale: TimeScale) -> Result<DenseFormula, DenseError> {
        let nodes = formula.nodes();
        let mut bounds = vec![(0.0, 0.0); nodes.len()];
        let mut future = vec![0.0f64; nodes.len()];
        let mut past = vec![0.0f64; nodes.len()];
        for (k, node) in nodes.iter().enumerate() {
            let kids = |h: &[f64]| node.children().map(|c| h[c]).fold(0.0, f64::max);
            let (f, p) = (kids(&future), kids(&past));
            let interval = match node {
                Node::Prev(_) => return Err(DenseError::NoDenseMeaning { op: "prev" }),
                Node::Next(_) => return Err(DenseError::NoDenseMeaning { op: "next" }),
                Node::Always(i, _)
                | Node::Eventually(i, _)
                | Node::Until(i, ..)
                | Node::Once(i, _)
                | Node::Historically(i, _)
                | Node::Since(i, ..) => Some(*i),
                _ => None,
            };
            let (mut f, mut p) = (f, p);
            if let Some(i) = interval {
                let text = || scale.interval_text(&i);
                let a = scale.bound(i.start);
                let b = match i.end {
                    Bound::Unbounded => f64::INFINITY,
                    Bound::Inclusive(b) => scale.bound(b),
                    Bound::Exclusive(_) => return Err(DenseError::HalfOpen { interval: text() }),
                };
                if !a.is_finite() || b.is_nan() {
                    return Err(DenseError::BadBound { interval: text() });
                }
                if b < a {
                    return Err(DenseError::Inverted { interval: text() });
                }
                bounds[k] = (a, b);
                if node.is_past() {
                    p = up(p + b);
                } else {
                    f = up(f + b);
                }
            }
            future[k] = f;
            past[k] = p;
        }
        let root = formula.root().index();
        Ok(DenseFormula {
            formula: formula.clone(),
            scale,
            bounds,
            future: future[root],
            past: past[root],
        })
    }

    /// The formula.
    pub fn formula(&self) -> &Formula {
        &self.formula
    }

    /// How its bounds read as times.
    pub fn scale(&self) -> TimeScale {
        self.scale
    }

    /// How far past `t` the value at `t` may read (an upper bound; infinite for an
    /// unbounded future operator).
    pub fn future_reach(&self) -> f64 {
        self.future
    }

    /// How far before `t` the value at `t` may read (an upper bound; infinite for an
    /// unbounded past operator).
    pub fn past_reach(&self) -> f64 {
        self.past
    }

    /// The robustness signal on `trace`, from its first stamp on (the last value holds
    /// forever; see [`DenseSignal::until`] for the part up to the last stamp).
    pub fn signal(&self, trace: &DenseTrace) -> Result<DenseSignal, DenseError> {
        self.check_vars(trace.vars())?;
        let rows = offline::Rows {
            times: trace.times(),
            columns: trace.columns().iter().map(Vec::as_slice).collect(),
        };
        Ok(offline::evaluate(self, &rows, false)?.0)
    }

    /// The robustness over complete windows (`hstlc monitor --windows complete`): the
    /// signal at the times whose windows lie inside the trace, and the last such time,
    /// `end` (the signal is determined on `[t0, end]`; nothing is when `end < t0`).
    ///
    /// Each node has a complete end: the last stamp for a comparison, `true` and `false`;
    /// the least of its operands' for `!`, `&&`, `||`, `->` and the past operators; that
    /// less `b` for `eventually[a..=b]`, `always[a..=b]` and `until[a..=b]` (less `a` for
    /// `[a..]`), one IEEE subtraction as a breakpoint is. An operator reads its operands'
    /// signals cut at their ends, each holding its value at its end after it, as if the
    /// trace ended there: a bounded window of a complete time reads only complete times
    /// (its value is the ordinary one), and an unbounded one ranges over its operand's
    /// complete part. The returned signal is cut at `end` likewise.
    pub fn complete_signal(&self, trace: &DenseTrace) -> Result<(DenseSignal, f64), DenseError> {
        self.check_vars(trace.vars())?;
        let rows = offline::Rows {
            times: trace.times(),
            columns: trace.columns().iter().map(Vec::as_slice).collect(),
        };
        offline::evaluate(self, &rows, true)
    }

    /// The complete end ([`DenseFormula::complete_signal`]) of a trace whose last stamp is
    /// `t_last`, bit for bit, without a trace: what an online monitor over complete windows
    /// cuts at.
    pub fn complete_end(&self, t_last: f64) -> f64 {
        offline::complete_end_of(self, t_last)
    }

    /// The robustness at the trace's first stamp.
    pub fn robustness(&self, trace: &DenseTrace) -> Result<f64, DenseError> {
        Ok(self.signal(trace)?.first())
    }

    fn check_vars(&self, vars: usize) -> Result<(), DenseError> {
        match self.formula.max_var() {
            Some(var) if var >= vars => Err(DenseError::MissingVar { var, vars }),
            _ => Ok(()),
        }
    }

    /// Comparison node `i` in hstl syntax.
    fn atom_text(&self, i: usize) -> String {
        let sub = self.formula.sub(crate::NodeId::from_index(i));
        sub.to_string()
    }
}

/// `x` nudged up by a relative 2^-50: horizons are upper bounds despite rounding.
fn up(x: f64) -> f64 {
    x + x.abs() * f64::EPSILON * 4.0
}

/// The dense-time signal of `formula` (bounds read through `scale`) on `trace`.
pub fn signal(
    formula: &Formula,
    scale: TimeScale,
    trace: &DenseTrace,
) -> Result<DenseSignal, DenseError> {
    DenseFormula::new(formula, scale)?.signal(trace)
}
