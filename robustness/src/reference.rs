//! The reference evaluator: the semantics table of the language reference, read literally.
//!
//! It is slow on purpose (every operator re-reads its whole window) and exists to be
//! obviously right. The fast evaluators are tested against it.
//!
//! NaN policy: min and max are Rust's [`f64::min`] and [`f64::max`] (IEEE `minNum` and
//! `maxNum`): a NaN operand is skipped. `&&`, `||` and the temporal operators fold from
//! `+inf` or `-inf`, so they never give NaN; `!` keeps a NaN, and `->` gives NaN only when
//! both sides are NaN. NaN itself comes only from atoms (`sqrt(-1)`, `inf - inf`, a
//! variable the trace lacks).

use crate::{Formula, Trace};

/// `rho(f, t)` on `trace`. Steps at or past the end of the trace see empty windows.
pub fn robustness(f: &Formula, trace: &Trace, t: usize) -> f64 {
    let n = trace.len();
    match f {
        Formula::True => f64::INFINITY,
        Formula::False => f64::NEG_INFINITY,
        Formula::Cmp { lhs, op, rhs } => {
            if t >= n {
                return f64::NAN;
            }
            let mut row = Vec::with_capacity(trace.vars());
            trace.row_into(t, &mut row);
            op.robustness(lhs.eval(&row), rhs.eval(&row))
        }
        Formula::Not(g) => -robustness(g, trace, t),
        Formula::And(gs) => {
            gs.iter().map(|g| robustness(g, trace, t)).fold(f64::INFINITY, f64::min)
        }
        Formula::Or(gs) => {
            gs.iter().map(|g| robustness(g, trace, t)).fold(f64::NEG_INFINITY, f64::max)
        }
        Formula::Implies(g, h) => (-robustness(g, trace, t)).max(robustness(h, trace, t)),
        Formula::Always(i, g) => {
            i.window(t, n).map(|u| robustness(g, trace, u)).fold(f64::INFINITY, f64::min)
        }
        Formula::Eventually(i, g) => {
            i.window(t, n).map(|u| robustness(g, trace, u)).fold(f64::NEG_INFINITY, f64::max)
        }
        Formula::Until(i, g, h) => i
            .window(t, n)
            .map(|u| {
                let before = (t..u).map(|v| robustness(g, trace, v)).fold(f64::INFINITY, f64::min);
                robustness(h, trace, u).min(before)
            })
            .fold(f64::NEG_INFINITY, f64::max),
    }
}

/// `rho(f, t)` for every step `t` of `trace`.
pub fn signal(f: &Formula, trace: &Trace) -> Vec<f64> {
    (0..trace.len()).map(|t| robustness(f, trace, t)).collect()
}

/// The reward of an option execution whose states form `segment`, as the language
/// reference defines it: a task `always[0..] f` with a finite horizon `H` of `f` is the
/// minimum of `rho(f, t)` over `0 <= t <= max(0, m - 1 - H)`; any other task is
/// `rho(task, 0)`. An empty segment has no reward and gives NaN.
pub fn segment_reward(task: &Formula, segment: &Trace) -> f64 {
    let m = segment.len();
    if m == 0 {
        return f64::NAN;
    }
    match persistent_body(task) {
        Some((body, h)) => {
            let last = (m - 1).saturating_sub(h);
            (0..=last).map(|t| robustness(body, segment, t)).fold(f64::INFINITY, f64::min)
        }
        None => robustness(task, segment, 0),
    }
}

/// For a task `always[0..] f` with a finite horizon of `f`, the body `f` and that horizon.
pub fn persistent_body(task: &Formula) -> Option<(&Formula, usize)> {
    match task {
        Formula::Always(i, body) if *i == crate::Interval::ALL => Some((body, body.horizon()?)),
        _ => None,
    }
}
