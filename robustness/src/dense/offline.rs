//! Offline dense-time robustness: every node's whole signal, as change points.
//!
//! Each operator is one pass over its operands' change points:
//! - comparisons and `!`, `&&`, `||`, `->` combine their operands point by point over the
//!   union of their change points;
//! - `eventually`, `always`, `once` and `historically` are a sliding maximum or minimum
//!   over time windows: piece `k` of the operand (value `v_k` on `[s_k, s_(k+1))`) meets the
//!   future window `[t+a, t+b]` exactly for `t` in `[s_k - b, s_(k+1) - a)` and the past
//!   window `[t-b, t-a]` for `t` in `[s_k + a, s_(k+1) + b)`, each end one IEEE operation
//!   as in rtamt. Starts and ends both increase with `k`, so one sweep with a monotone
//!   deque gives the window's extreme at every change point: linear in the number of
//!   pieces, whatever the window's length;
//! - untimed `until` and `since` are one backward (forward) recurrence over the union of
//!   their operands' change points, and timed ones are decomposed as rtamt decomposes them
//!   (see [`crate::dense`]).

use super::until::BoundedUntil;
use super::{DenseError, DenseFormula, DenseSignal};
use crate::formula::{ExprId, Node};
use std::collections::VecDeque;

/// Which way a window looks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Dir {
    Future,
    Past,
}

/// The extreme a window takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Ext {
    Max,
    Min,
}

impl Ext {
    #[inline]
    pub(crate) fn identity(self) -> f64 {
        match self {
            Ext::Max => f64::NEG_INFINITY,
            Ext::Min => f64::INFINITY,
        }
    }

    /// Whether `new` makes `old` useless in a monotone deque (`old` no better than `new`).
    #[inline]
    pub(crate) fn dominates(self, new: f64, old: f64) -> bool {
        match self {
            Ext::Max => old <= new,
            Ext::Min => old >= new,
        }
    }
}

pub(crate) use super::minmax::{max, min};

/// The rows an evaluation reads: stamps and every variable's value at each.
pub(crate) struct Rows<'a> {
    pub times: &'a [f64],
    pub columns: Vec<&'a [f64]>,
}

/// One node's result: an expression's value at every row, or a formula's signal.
enum Val {
    Expr(Vec<f64>),
    Sig(DenseSignal),
    /// A node no later node reads any more.
    Dropped,
}

/// Every node of `df`'s formula in order; returns the root's signal.
///
/// With `complete`, every formula node's signal is cut at its complete end (see
/// [`DenseFormula::complete_signal`]): its operands' signals are cut at theirs before it
/// reads them, each holding its value at its end after it, as if the trace ended there.
/// The root's complete end is returned beside it (the last stamp without `complete`).
pub(crate) fn evaluate(
    df: &DenseFormula,
    rows: &Rows<'_>,
    complete: bool,
) -> Result<(DenseSignal, f64), DenseError> {
    let nodes = df.formula.nodes();
    let n = rows.times.len();
    let t0 = rows.times[0];
    let t_last = rows.times[n - 1];
    // Each formula node's complete end (unused for expressions).
    let mut ends = vec![t_last; nodes.len()];
    // The last node reading each node, so signals are freed once read for the last time.
    let mut last_use = vec![0usize; nodes.len()];
    for (i, node) in nodes.iter().enumerate() {
        for c in node.children() {
            last_use[c] = i;
        }
    }
    let mut vals: Vec<Val> = Vec::with_capacity(nodes.len());
    for (i, node) in nodes.iter().enumerate() {
        if crate::cancel::requested() {
            // Nobody waits for the result (see `cancel`): NaN from the start, as the
            // discrete evaluator gives.
            let mut stopped = DenseSignal::with_capacity(1);
            stopped.push(t0, f64::NAN);
            return Ok((stopped, t_last));
        }
        let e = |id: &ExprId| match &vals[id.index()] {
            Val::Expr(v) => v.as_slice(),
            _ => unreachable!("an expression operand is an expression"),
        };
        let s = |id: usize| match &vals[id] {
            Val::Sig(s) => s,
            _ => unreachable!("a formula operand is a formula"),
        };
        let map = |a: &[f64], g: fn(f64) -> f64| a.iter().map(|&x| g(x)).collect::<Vec<_>>();
        let zip = |a: &[f64], b: &[f64], g: fn(f64, f64) -> f64| {
            a.iter().zip(b).map(|(&x, &y)| g(x, y)).collect::<Vec<_>>()
        };
        let constant = |v: f64| {
            let mut sig = DenseSignal::with_capacity(1);
            sig.push(t0, v);
            sig
        };
        let val = match node {
            Node::Const(c) => Val::Expr(vec![*c; n]),
            Node::Var(j) => Val::Expr(rows.columns[*j].to_vec()),
            Node::Neg(a) => Val::Expr(map(e(a), |x| -x)),
            Node::Abs(a) => Val::Expr(map(e(a), f64::abs)),
            Node::Sqrt(a) => Val::Expr(map(e(a), f64::sqrt)),
            Node::Add(a, b) => Val::Expr(zip(e(a), e(b), |x, y| x + y)),
            Node::Sub(a, b) => Val::Expr(zip(e(a), e(b), |x, y| x - y)),
            Node::Mul(a, b) => Val::Expr(zip(e(a), e(b), |x, y| x * y)),
            Node::Div(a, b) => Val::Expr(zip(e(a), e(b), |x, y| x / y)),
            Node::True => Val::Sig(constant(f64::INFINITY)),
            Node::False => Val::Sig(constant(f64::NEG_INFINITY)),
            Node::Cmp { lhs, op, rhs } => {
                let (l, r) = (e(lhs), e(rhs));
                let mut sig = DenseSignal::with_capacity(n);
                for (k, &t) in rows.times.iter().enumerate() {
                    let v = op.robustness(l[k], r[k]);
                    if v.is_nan() {
                        return Err(DenseError::Nan { time: t, atom: df.atom_text(i) });
                    }
                    sig.push(t, v);
                }
                Val::Sig(sig)
            }
            Node::Not(a) => {
                let a = s(a.index());
                let mut sig = DenseSignal::with_capacity(a.len());
                for (t, v) in a.points() {
                    sig.push(t, -v);
                }
                Val::Sig(sig)
            }
            Node::And(gs) | Node::Or(gs) => {
                let and = matches!(node, Node::And(_));
                let g = if and { min } else { max };
                match gs.split_first() {
                    None => Val::Sig(constant(if and { f64::INFINITY } else { f64::NEG_INFINITY })),
                    Some((first, [])) => Val::Sig(s(first.index()).clone()),
                    Some(_) => {
                        let sigs: Vec<&DenseSignal> = gs.iter().map(|h| s(h.index())).collect();
                        Val::Sig(combine_all(&sigs, g))
                    }
                }
            }
            Node::Implies(a, b) => Val::Sig(combine(s(a.index()), s(b.index()), |x, y| max(-x, y))),
            Node::Eventually(_, a) | Node::Always(_, a) => {
                let (lo, hi) = df.bounds[i];
                let ext = if matches!(node, Node::Eventually(..)) { Ext::Max } else { Ext::Min };
                Val::Sig(window(s(a.index()), t0, Dir::Future, lo, hi, ext))
            }
            Node::Once(_, a) | Node::Historically(_, a) => {
                let (lo, hi) = df.bounds[i];
                let ext = if matches!(node, Node::Once(..)) { Ext::Max } else { Ext::Min };
                Val::Sig(window(s(a.index()), t0, Dir::Past, lo, hi, ext))
            }
            Node::Until(_, f, g) | Node::Since(_, f, g) => {
                let (a, b) = df.bounds[i];
                let (f, g) = (s(f.index()), s(g.index()));
                match node {
                    // Bounded until: the streaming sweep, the online monitor's.
                    Node::Until(..) if b < f64::INFINITY => Val::Sig(bounded_until(f, g, t0, a, b)),
                    Node::Until(..) => Val::Sig(timed_until(f, g, t0, Dir::Future, a, b)),
                    _ => Val::Sig(timed_until(f, g, t0, Dir::Past, a, b)),
                }
            }
            Node::Prev(_) | Node::Next(_) => {
                unreachable!("DenseFormula::new rejects prev and next")
            }
        };
        let mut val = val;
        if complete && let Val::Sig(sig) = &mut val {
            ends[i] = complete_end(node, &ends, df.bounds[i], t_last);
            sig.cut(ends[i]);
        }
        vals.push(val);
        for c in node.children() {
            if last_use[c] == i {
                vals[c] = Val::Dropped;
            }
        }
    }
    let end = ends[nodes.len() - 1];
    match vals.pop() {
        Some(Val::Sig(s)) => Ok((s, end)),
        _ => unreachable!("the root is a formula"),
    }
}

/// The root's complete end over a trace whose last stamp is `t_last`: what [`evaluate`]
/// returns beside the signal with `complete`, without computing the signal (an
/// expression node's end is `t_last`, as its operands' are).
pub(crate) fn complete_end_of(df: &DenseFormula, t_last: f64) -> f64 {
    let nodes = df.formula.nodes();
    let mut ends = vec![t_last; nodes.len()];
    for (i, node) in nodes.iter().enumerate() {
        ends[i] = complete_end(node, &ends, df.bounds[i], t_last);
    }
    ends.last().copied().unwrap_or(t_last)
}

/// The complete end of formula node `node` (interval `(a, b)`), given its operands'
/// `ends`: the last time whose windows lie inside them, each window end one IEEE
/// subtraction as a breakpoint is.
fn complete_end(node: &Node, ends: &[f64], (a, b): (f64, f64), t_last: f64) -> f64 {
    let operands = node.children().map(|c| ends[c]).reduce(f64::min).unwrap_or(t_last);
    let reach = if b == f64::INFINITY { a } else { b };
    match node {
        Node::Eventually(..) | Node::Always(..) | Node::Until(..) => operands - reach,
        _ => operands,
    }
}

/// `g(a(t), b(t))` point by point over the union of the change points.
pub(crate) fn combine(
    a: &DenseSignal,
    b: &DenseSignal,
    g: impl Fn(f64, f64) -> f64,
) -> DenseSignal {
    let (ta, va, tb, vb) = (&a.times, &a.values, &b.times, &b.values);
    let mut out = DenseSignal::with_capacity(ta.len().max(tb.len()));
    let (mut i, mut j) = (0usize, 0usize);
    // Both start at the trace's first stamp.
    while i < ta.len() || j < tb.len() {
        let t = match (ta.get(i), tb.get(j)) {
            (Some(&x), Some(&y)) => x.min(y),
            (Some(&x), None) => x,
            (None, Some(&y)) => y,
            (None, None) => break,
        };
        if ta.get(i) == Some(&t) {
            i += 1;
        }
        if tb.get(j) == Some(&t) {
            j += 1;
        }
        out.push(t, g(va[i.max(1) - 1], vb[j.max(1) - 1]));
    }
    out
}

/// `g` folded over every operand's value, point by point over the union of the change
/// points: one pass for all operands.
fn combine_all(sigs: &[&DenseSignal], g: fn(f64, f64) -> f64) -> DenseSignal {
    let mut next = vec![0usize; sigs.len()];
    let mut cur = vec![0.0; sigs.len()];
    let mut out = DenseSignal::with_capacity(sigs.iter().map(|s| s.len()).max().unwrap_or(0));
    loop {
        let mut t: Option<f64> = None;
        for (sig, &k) in sigs.iter().zip(&next) {
            if let Some(&x) = sig.times.get(k)
                && t.is_none_or(|t| x < t)
            {
                t = Some(x);
            }
        }
        let Some(t) = t else { break };
        for ((sig, k), c) in sigs.iter().zip(&mut next).zip(&mut cur) {
            if sig.times.get(*k) == Some(&t) {
                *c = sig.values[*k];
                *k += 1;
            }
        }
        let v = cur[1..].iter().fold(cur[0], |acc, &x| g(acc, x));
        out.push(t, v);
    }
    out
}

/// The window operator over `sig` at every `t >= t0`: the extreme of the values of the
/// pieces that meet `[t+a, t+b]` (future) or `[t-b, t-a]` clipped at `t0` (past); the
/// identity when none does. `b` may be infinite.
pub(crate) fn window(
    sig: &DenseSignal,
    t0: f64,
    dir: Dir,
    a: f64,
    b: f64,
    ext: Ext,
) -> DenseSignal {
    let (s, v) = (&sig.times, &sig.values);
    let k_end = s.len();
    // Piece k meets the window exactly for t in [start(k), end(k)).
    let start = |k: usize| match dir {
        Dir::Future => s[k] - b,
        Dir::Past => s[k] + a,
    };
    let end = |k: usize| match (dir, s.get(k + 1)) {
        (_, None) => f64::INFINITY,
        (Dir::Future, Some(&next)) => next - a,
        (Dir::Past, Some(&next)) => next + b,
    };
    let mut out = DenseSignal::with_capacity(k_end);
    let mut dq: VecDeque<usize> = VecDeque::new();
    let (mut i, mut j) = (0usize, 0usize);
    let mut t = t0;
    loop {
        while i < k_end && start(i) <= t {
            // A piece already past its end (an empty interval) never enters.
            if i >= j {
                while dq.back().is_some_and(|&q| ext.dominates(v[i], v[q])) {
                    dq.pop_back();
                }
                dq.push_back(i);
            }
            i += 1;
        }
        while j < k_end && end(j) <= t {
            if dq.front() == Some(&j) {
                dq.pop_front();
            }
            j += 1;
        }
        out.push(t, dq.front().map_or(ext.identity(), |&q| v[q]));
        let next_start = if i < k_end { start(i) } else { f64::INFINITY };
        let next_end = if j < k_end { end(j) } else { f64::INFINITY };
        let next = next_start.min(next_end);
        if next == f64::INFINITY {
            break;
        }
        t = next;
    }
    out
}

/// The earlier of `f`'s change point `i` and `g`'s change point `j` (either past its
/// signal's end left out), or `None` when both are past the end.
fn next_time(f: &DenseSignal, g: &DenseSignal, i: usize, j: usize) -> Option<f64> {
    match (f.times.get(i), g.times.get(j)) {
        (Some(&x), Some(&y)) => Some(x.min(y)),
        (Some(&x), None) => Some(x),
        (None, Some(&y)) => Some(y),
        (None, None) => None,
    }
}

/// `f until[a..=b] g`, `b` finite, by the sweep of [`super::until`]: the same values as
/// [`timed_until`] at every time, and the same operations as the online monitor.
fn bounded_until(f: &DenseSignal, g: &DenseSignal, t0: f64, a: f64, b: f64) -> DenseSignal {
    let mut u = BoundedUntil::new(a, b);
    let mut points = Vec::new();
    let (mut i, mut j, mut fed) = (0usize, 0usize, 0usize);
    while let Some(t) = next_time(f, g, i, j) {
        // Every piece before `t` is in: sweep now and then, so that the sweep keeps a
        // window's pieces rather than the trace's.
        if fed % 512 == 511 {
            u.advance(t0, t, &mut points);
        }
        if f.times.get(i) == Some(&t) {
            i += 1;
        }
        if g.times.get(j) == Some(&t) {
            j += 1;
        }
        u.feed(t, f.values[i.max(1) - 1], g.values[j.max(1) - 1]);
        fed += 1;
    }
    u.advance(t0, f64::INFINITY, &mut points);
    let mut out = DenseSignal::with_capacity(points.len());
    for (t, v) in points {
        out.push(t, v);
    }
    out
}

/// Untimed `f until g` (future) or `f since g` (past): over the union of the change points,
/// `u_k = max(min(f_k, g_k), min(f_k, u_(k±1)))`, `-inf` beyond the last (first) piece.
pub(crate) fn untimed_until(f: &DenseSignal, g: &DenseSignal, dir: Dir) -> DenseSignal {
    // The union of the change points with both values at each.
    let mut times = Vec::with_capacity(f.len().max(g.len()));
    let mut fv = Vec::with_capacity(times.capacity());
    let mut gv = Vec::with_capacity(times.capacity());
    let (mut i, mut j) = (0usize, 0usize);
    while let Some(t) = next_time(f, g, i, j) {
        if f.times.get(i) == Some(&t) {
            i += 1;
        }
        if g.times.get(j) == Some(&t) {
            j += 1;
        }
        times.push(t);
        fv.push(f.values[i.max(1) - 1]);
        gv.push(g.values[j.max(1) - 1]);
    }
    let n = times.len();
    let mut u = vec![0.0; n];
    let mut acc = f64::NEG_INFINITY;
    let step = |k: usize, acc: f64| max(min(fv[k], gv[k]), min(fv[k], acc));
    match dir {
        Dir::Future => {
            for k in (0..n).rev() {
                acc = step(k, acc);
                u[k] = acc;
            }
        }
        Dir::Past => {
            for (k, uk) in u.iter_mut().enumerate() {
                acc = step(k, acc);
                *uk = acc;
            }
        }
    }
    let mut out = DenseSignal::with_capacity(n);
    for (t, v) in times.into_iter().zip(u) {
        out.push(t, v);
    }
    out
}

/// `f until[a..=b] g` (future) or `f since[a..=b] g` (past), `b` possibly infinite, as
/// rtamt decomposes them:
/// - `eventually[a..=b] g && always[0..=a] (f until g)`, `always[0..=a] (f until g) &&
///   eventually[a..] g` when unbounded (for `a = 0` the `always` is the identity);
/// - `since` likewise with `once` and `historically`.
pub(crate) fn timed_until(
    f: &DenseSignal,
    g: &DenseSignal,
    t0: f64,
    dir: Dir,
    a: f64,
    b: f64,
) -> DenseSignal {
    let u = untimed_until(f, g, dir);
    if a == 0.0 && b == f64::INFINITY {
        return u;
    }
    let reach = window(g, t0, dir, a, b, Ext::Max);
    let hold = if a == 0.0 { u } else { window(&u, t0, dir, 0.0, a, Ext::Min) };
    if b == f64::INFINITY { combine(&hold, &reach, min) } else { combine(&reach, &hold, min) }
}
