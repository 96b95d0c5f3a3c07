//! The reference evaluator: the semantics table of the language reference, read literally.
//!
//! It is slow on purpose (every operator re-reads its whole window) and exists to be
//! obviously right. The fast evaluators are tested against it. It computes every node's
//! signal in node order (children before parents), so it never recurses.
//!
//! NaN policy: min and max are Rust's [`f64::min`] and [`f64::max`] (IEEE `minNum` and
//! `maxNum`): a NaN operand is skipped. `&&`, `||` and the temporal operators fold from
//! `+inf` or `-inf`, so they never give NaN; `!` keeps a NaN, and `->` gives NaN only when
//! both sides are NaN. NaN itself comes only from atoms (`sqrt(-1)`, `inf - inf`, a
//! variable the trace lacks).

use crate::formula::Node;
use crate::{Formula, NodeId, Trace};

/// `rho(f, t)` on `trace`. Steps at or past the end of the trace see empty windows.
///
/// Only the steps `t ..= t + H` are computed for a formula of horizon `H` (from step 0
/// when it has a past-time operator): `rho(f, t)` reads no other.
pub fn robustness(f: &Formula, trace: &Trace, t: usize) -> f64 {
    let n = trace.len();
    let stop = match f.horizon() {
        Some(h) => t.saturating_add(h).saturating_add(1).min(n.max(t + 1)),
        None => n.max(t + 1),
    };
    let from = if f.has_past() { 0 } else { t };
    if !f.has_past() && stop == t + 1 {
        return at_one_step(f, trace, t);
    }
    signals(f, trace, from, stop)[f.root().index()][t - from]
}

/// `rho(f, t)` when it reads step `t` alone (a state formula, or a step past the end):
/// one value per node, windows holding `t` or nothing.
fn at_one_step(f: &Formula, trace: &Trace, t: usize) -> f64 {
    let n = trace.len();
    let mut vals: Vec<f64> = Vec::with_capacity(f.len());
    for node in f.nodes() {
        let at = |k: usize| vals[k];
        let window = |i: &crate::Interval| i.window(t, n.min(t + 1));
        let x = match node {
            Node::True => f64::INFINITY,
            Node::False => f64::NEG_INFINITY,
            Node::Const(c) => *c,
            Node::Var(i) if t < n && *i < trace.vars() => trace.column(*i)[t],
            Node::Var(_) => f64::NAN,
            Node::Neg(e) => -at(e.index()),
            Node::Abs(e) => at(e.index()).abs(),
            Node::Sqrt(e) => at(e.index()).sqrt(),
            Node::Add(a, b) => at(a.index()) + at(b.index()),
            Node::Sub(a, b) => at(a.index()) - at(b.index()),
            Node::Mul(a, b) => at(a.index()) * at(b.index()),
            Node::Div(a, b) => at(a.index()) / at(b.index()),
            Node::Cmp { .. } if t >= n => f64::NAN,
            Node::Cmp { lhs, op, rhs } => op.robustness(at(lhs.index()), at(rhs.index())),
            Node::Not(g) => -at(g.index()),
            Node::And(gs) => gs.iter().map(|g| at(g.index())).fold(f64::INFINITY, f64::min),
            Node::Or(gs) => gs.iter().map(|g| at(g.index())).fold(f64::NEG_INFINITY, f64::max),
            Node::Implies(g, h) => (-at(g.index())).max(at(h.index())),
            Node::Always(i, g) => window(i).map(|_| at(g.index())).fold(f64::INFINITY, f64::min),
            Node::Eventually(i, g) => {
                window(i).map(|_| at(g.index())).fold(f64::NEG_INFINITY, f64::max)
            }
            // The left side's minimum is over no step before `t`.
            Node::Until(i, _, h) => window(i)
                .map(|_| at(h.index()).min(f64::INFINITY))
                .fold(f64::NEG_INFINITY, f64::max),
            // Step `t + 1` is not read.
            Node::Next(_) => f64::INFINITY,
            // Not reached: a formula with a past-time operator reads from step 0.
            Node::Historically(..) | Node::Prev(_) => f64::INFINITY,
            Node::Once(..) | Node::Since(..) => f64::NEG_INFINITY,
        };
        vals.push(x);
    }
    vals[f.root().index()]
}

/// `rho(f, t)` for every step `t` of `trace`.
pub fn signal(f: &Formula, trace: &Trace) -> Vec<f64> {
    let mut all = signals(f, trace, 0, trace.len());
    std::mem::take(&mut all[f.root().index()])
}

/// The signal of every node of `f` at the steps `from .. to` (steps past the trace see
/// NaN atoms and empty windows); an operator at `u` reads its operands at `u..to`, so the
/// values are exact where `u + horizon < to` or `to` is at least the trace's length. A
/// past-time operator reads `from..=u`: exact when `from` is 0.
fn signals(f: &Formula, trace: &Trace, from: usize, to: usize) -> Vec<Vec<f64>> {
    let n = trace.len();
    let steps = to.saturating_sub(from);
    let mut sig: Vec<Vec<f64>> = Vec::with_capacity(f.len());
    for node in f.nodes() {
        // `at(k, u)`: node `k` at step `u` (absolute).
        let at = |k: usize, u: usize| sig[k][u - from];
        let window = |i: &crate::Interval, u: usize| i.window(u, n.min(to));
        // Past windows, cut at `from` (which is 0 when the formula has a past operator);
        // a step past the trace sees an empty window, as for the future operators.
        let past = |i: &crate::Interval, u: usize| {
            if u >= n {
                return 0..0;
            }
            let w = i.past_window(u);
            w.start.max(from)..w.end.max(from)
        };
        let values: Vec<f64> = (from..to)
            .map(|u| match node {
                Node::True => f64::INFINITY,
                Node::False => f64::NEG_INFINITY,
                Node::Const(c) => *c,
                Node::Var(i) if u < n && *i < trace.vars() => trace.column(*i)[u],
                Node::Var(_) => f64::NAN,
                Node::Neg(e) => -at(e.index(), u),
                Node::Abs(e) => at(e.index(), u).abs(),
                Node::Sqrt(e) => at(e.index(), u).sqrt(),
                Node::Add(a, b) => at(a.index(), u) + at(b.index(), u),
                Node::Sub(a, b) => at(a.index(), u) - at(b.index(), u),
                Node::Mul(a, b) => at(a.index(), u) * at(b.index(), u),
                Node::Div(a, b) => at(a.index(), u) / at(b.index(), u),
                Node::Cmp { lhs, op, rhs } => {
                    if u >= n {
                        return f64::NAN;
                    }
                    op.robustness(at(lhs.index(), u), at(rhs.index(), u))
                }
                Node::Not(g) => -at(g.index(), u),
                Node::And(gs) => gs.iter().map(|g| at(g.index(), u)).fold(f64::INFINITY, f64::min),
                Node::Or(gs) => {
                    gs.iter().map(|g| at(g.index(), u)).fold(f64::NEG_INFINITY, f64::max)
                }
                Node::Implies(g, h) => (-at(g.index(), u)).max(at(h.index(), u)),
                Node::Always(i, g) => {
                    window(i, u).map(|w| at(g.index(), w)).fold(f64::INFINITY, f64::min)
                }
                Node::Eventually(i, g) => {
                    window(i, u).map(|w| at(g.index(), w)).fold(f64::NEG_INFINITY, f64::max)
                }
                Node::Until(i, g, h) => window(i, u)
                    .map(|w| {
                        let before = (u..w).map(|v| at(g.index(), v)).fold(f64::INFINITY, f64::min);
                        at(h.index(), w).min(before)
                    })
                    .fold(f64::NEG_INFINITY, f64::max),
                // `next f` is `always[1..=1] f`: `+inf` where step `u + 1` does not exist.
                Node::Next(g) => (u + 1..(u + 2).min(n.min(to)))
                    .map(|w| at(g.index(), w))
                    .fold(f64::INFINITY, f64::min),
                // `prev f` is `historically[1..=1] f`: `+inf` at step 0.
                Node::Prev(g) => {
                    let w = if u >= n { 0..0 } else { u.saturating_sub(1).max(from)..u };
                    w.map(|w| at(g.index(), w)).fold(f64::INFINITY, f64::min)
                }
                Node::Historically(i, g) => {
                    past(i, u).map(|w| at(g.index(), w)).fold(f64::INFINITY, f64::min)
                }
                Node::Once(i, g) => {
                    past(i, u).map(|w| at(g.index(), w)).fold(f64::NEG_INFINITY, f64::max)
                }
                Node::Since(i, g, h) => past(i, u)
                    .map(|w| {
                        let after =
                            (w + 1..=u).map(|v| at(g.index(), v)).fold(f64::INFINITY, f64::min);
                        at(h.index(), w).min(after)
                    })
                    .fold(f64::NEG_INFINITY, f64::max),
            })
            .collect();
        debug_assert_eq!(values.len(), steps);
        sig.push(values);
    }
    sig
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
            let body = task.sub(body);
            let last = (m - 1).saturating_sub(h);
            let sig = signal(&body, segment);
            sig[..=last].iter().fold(f64::INFINITY, |a, b| a.min(*b))
        }
        None => robustness(task, segment, 0),
    }
}

/// For a task `always[0..] f` with a finite horizon of `f`, the node `f` and that horizon.
pub fn persistent_body(task: &Formula) -> Option<(NodeId, usize)> {
    match task.root_node() {
        Node::Always(i, body) if *i == crate::Interval::ALL => {
            Some((*body, task.horizon_of(*body)?))
        }
        _ => None,
    }
}
