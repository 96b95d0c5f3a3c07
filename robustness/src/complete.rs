//! Robustness over complete windows: a step counts only if every window its value needs
//! lies inside the trace.
//!
//! The default semantics clips windows at the end of a finite trace, as rtamt does, so
//! `always[0..] (eventually[0..40] A)` is negative on any trace that does not end inside
//! `A`, however well it kept the task before. Over complete windows each node of the
//! formula has a *complete prefix*, the steps whose value no clipped window touches:
//!
//! | formula | complete steps on `n` states |
//! |---|---|
//! | a comparison, `true`, `false` | `n` |
//! | `!f` | those of `f` |
//! | `f && g`, `f \|\| g`, `f -> g` | the fewest of the operands' |
//! | `always[a..=b] f`, `eventually[a..=b] f` | those of `f`, less `b` |
//! | `f until[a..=b] g` | the fewest of `f`'s and `g`'s, less `b` |
//! | `always[a..] f`, `eventually[a..] f`, `f until[a..] g` | as above, less `a` |
//! | `once[I] f`, `historically[I] f`, `prev f` | those of `f` |
//! | `f since[I] g` | the fewest of `f`'s and `g`'s |
//! | `next f` | those of `f`, less one |
//!
//! A bounded operator's value at a complete step is the clipped one. An unbounded
//! operator ranges over its operands' complete prefix, as if the trace ended there: the
//! persistent task `always[0..] (eventually[0..40] A && ...)` is then the minimum over the
//! steps whose 40-step windows are whole. A past-time operator never looks forward, so its
//! complete prefix is its operands'. Steps past the complete prefix are undetermined.

use crate::formula::Node;
use crate::kernels::{Kernels, and_into, or_into};
use crate::{Bound, Formula, Trace};

/// The steps of `f` on a trace of `n` states whose value is determined.
pub fn complete_len(f: &Formula, n: usize) -> usize {
    let nodes = f.nodes();
    let mut lens: Vec<usize> = Vec::with_capacity(nodes.len());
    for node in nodes {
        let fewest = node.children().map(|k| lens[k]).min().unwrap_or(n);
        lens.push(if node.is_expr() { n } else { node_len(node, fewest) });
    }
    lens.last().copied().unwrap_or(n)
}

/// `rho(f, t)` over complete windows for every complete step `t` (see the module docs):
/// as long as [`complete_len`], empty when no step is determined. Each node's signal is
/// dropped after its last parent used it, so memory follows the widest level of the
/// formula, not its size.
pub fn signal(f: &Formula, trace: &Trace) -> Vec<f64> {
    let nodes = f.nodes();
    let n = trace.len();
    // The last node that reads each node's signal.
    let mut last_use = vec![0usize; nodes.len()];
    for (i, node) in nodes.iter().enumerate() {
        if !node.is_expr() {
            node.children().for_each(|k| last_use[k] = i);
        }
    }
    let mut signals: Vec<Option<Vec<f64>>> = vec![None; nodes.len()];
    let mut kernels = Kernels::new();
    for (i, node) in nodes.iter().enumerate() {
        if node.is_expr() {
            continue;
        }
        // A stopped evaluation's result is dropped (see `crate::cancel`).
        if crate::cancel::requested() {
            return vec![f64::NAN; n];
        }
        let kid = |k: usize| signals[k].as_deref().unwrap_or(&[]);
        let v = match node {
            // A comparison's signal is made when it is reached and dropped after its last
            // reader, so that only the live signals are held, not one per comparison.
            Node::Cmp { lhs, op, rhs } => {
                let mut v = f.expr_at(*lhs).eval_trace(trace);
                let rhs = f.expr_at(*rhs).eval_trace(trace);
                v.iter_mut().zip(&rhs).for_each(|(a, &b)| *a = op.robustness(*a, b));
                v
            }
            Node::True => vec![f64::INFINITY; n],
            Node::False => vec![f64::NEG_INFINITY; n],
            Node::Not(a) => kid(a.index()).iter().map(|x| -x).collect(),
            Node::And(gs) | Node::Or(gs) => {
                let m = gs.iter().map(|g| kid(g.index()).len()).min().unwrap_or(n);
                let and = matches!(node, Node::And(_));
                let mut acc = vec![if and { f64::INFINITY } else { f64::NEG_INFINITY }; m];
                for g in gs {
                    let k = &kid(g.index())[..m];
                    if and { and_into(&mut acc, k) } else { or_into(&mut acc, k) }
                }
                acc
            }
            Node::Implies(a, b) => {
                let (a, b) = (kid(a.index()), kid(b.index()));
                a.iter().zip(b).map(|(a, b)| (-a).max(*b)).collect()
            }
            Node::Always(iv, a) | Node::Eventually(iv, a) => {
                let mut v = kid(a.index()).to_vec();
                if matches!(node, Node::Always(..)) {
                    kernels.always(iv, &mut v);
                } else {
                    kernels.eventually(iv, &mut v);
                }
                v.truncate(node_len(node, v.len()));
                v
            }
            Node::Until(iv, a, b) | Node::Since(iv, a, b) => {
                let (a, b) = (kid(a.index()), kid(b.index()));
                let m = a.len().min(b.len());
                let (mut lhs, mut out) = (a[..m].to_vec(), b[..m].to_vec());
                if matches!(node, Node::Until(..)) {
                    kernels.until(iv, &mut lhs, &mut out);
                } else {
                    kernels.since(iv, &mut lhs, &mut out);
                }
                out.truncate(node_len(node, m));
                out
            }
            Node::Once(iv, a) | Node::Historically(iv, a) => {
                let mut v = kid(a.index()).to_vec();
                if matches!(node, Node::Once(..)) {
                    kernels.once(iv, &mut v);
                } else {
                    kernels.historically(iv, &mut v);
                }
                v
            }
            Node::Prev(a) | Node::Next(a) => {
                let mut v = kid(a.index()).to_vec();
                if matches!(node, Node::Prev(_)) {
                    kernels.prev(&mut v);
                } else {
                    kernels.next(&mut v);
                }
                v.truncate(node_len(node, v.len()));
                v
            }
            _ => Vec::new(),
        };
        signals[i] = Some(v);
        for k in node.children() {
            if last_use[k] == i && k + 1 != nodes.len() {
                signals[k] = None;
            }
        }
    }
    signals.pop().flatten().unwrap_or_default()
}

/// `rho(f, 0)` over complete windows, or `None` when step 0 is undetermined.
pub fn robustness(f: &Formula, trace: &Trace) -> Option<f64> {
    signal(f, trace).first().copied()
}

/// A node's complete steps, given the fewest complete steps `m` among its operands.
fn node_len(node: &Node, m: usize) -> usize {
    match node {
        Node::Always(i, _) | Node::Eventually(i, _) | Node::Until(i, ..) => match i.end {
            Bound::Unbounded => m.saturating_sub(i.start),
            _ => m.saturating_sub(i.last_offset().unwrap_or(0)),
        },
        Node::Next(_) => m.saturating_sub(1),
        _ => m,
    }
}
