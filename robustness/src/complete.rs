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
//!
//! A bounded operator's value at a complete step is the clipped one. An unbounded
//! operator ranges over its operands' complete prefix, as if the trace ended there: the
//! persistent task `always[0..] (eventually[0..40] A && ...)` is then the minimum over the
//! steps whose 40-step windows are whole. Steps past the complete prefix are undetermined.

use crate::kernels::{Kernels, and_into, or_into};
use crate::{Bound, Formula, Trace};

/// The steps of `f` on a trace of `n` states whose value is determined.
pub fn complete_len(f: &Formula, n: usize) -> usize {
    let mut lens: Vec<usize> = Vec::new();
    for node in post_order(f) {
        let kids = lens.split_off(lens.len() - arity(node));
        lens.push(node_len(node, kids.into_iter().min().unwrap_or(n)));
    }
    lens.pop().unwrap_or(n)
}

/// `rho(f, t)` over complete windows for every complete step `t` (see the module docs):
/// as long as [`complete_len`], empty when no step is determined.
pub fn signal(f: &Formula, trace: &Trace) -> Vec<f64> {
    let n = trace.len();
    let mut kernels = Kernels::new();
    let mut row = Vec::new();
    let mut values: Vec<Vec<f64>> = Vec::new();
    for node in post_order(f) {
        let v = match node {
            Formula::True => vec![f64::INFINITY; n],
            Formula::False => vec![f64::NEG_INFINITY; n],
            Formula::Cmp { lhs, op, rhs } => (0..n)
                .map(|t| {
                    trace.row_into(t, &mut row);
                    op.robustness(lhs.eval(&row), rhs.eval(&row))
                })
                .collect(),
            Formula::Not(_) => {
                let mut v = values.pop().unwrap_or_default();
                v.iter_mut().for_each(|x| *x = -*x);
                v
            }
            Formula::And(gs) | Formula::Or(gs) => {
                let kids = values.split_off(values.len() - gs.len());
                let m = kids.iter().map(Vec::len).min().unwrap_or(n);
                let and = matches!(node, Formula::And(_));
                let mut acc = vec![if and { f64::INFINITY } else { f64::NEG_INFINITY }; m];
                for k in &kids {
                    if and { and_into(&mut acc, &k[..m]) } else { or_into(&mut acc, &k[..m]) }
                }
                acc
            }
            Formula::Implies(..) => {
                let g = values.pop().unwrap_or_default();
                let f = values.pop().unwrap_or_default();
                let m = f.len().min(g.len());
                (0..m).map(|t| (-f[t]).max(g[t])).collect()
            }
            Formula::Always(i, _) | Formula::Eventually(i, _) => {
                let mut v = values.pop().unwrap_or_default();
                if matches!(node, Formula::Always(..)) {
                    kernels.always(i, &mut v);
                } else {
                    kernels.eventually(i, &mut v);
                }
                let c = node_len(node, v.len());
                v.truncate(c);
                v
            }
            Formula::Until(i, ..) => {
                let mut g = values.pop().unwrap_or_default();
                let mut f = values.pop().unwrap_or_default();
                let m = f.len().min(g.len());
                g.truncate(m);
                kernels.until(i, &mut f, &mut g);
                g.truncate(node_len(node, m));
                g
            }
        };
        values.push(v);
    }
    values.pop().unwrap_or_default()
}

/// `rho(f, 0)` over complete windows, or `None` when step 0 is undetermined.
pub fn robustness(f: &Formula, trace: &Trace) -> Option<f64> {
    signal(f, trace).first().copied()
}

/// A node's complete steps, given the fewest complete steps `m` among its operands.
fn node_len(node: &Formula, m: usize) -> usize {
    match node {
        Formula::Always(i, _) | Formula::Eventually(i, _) | Formula::Until(i, ..) => match i.end {
            Bound::Unbounded => m.saturating_sub(i.start),
            _ => m.saturating_sub(i.last_offset().unwrap_or(0)),
        },
        _ => m,
    }
}

/// How many operands `node` has.
fn arity(node: &Formula) -> usize {
    match node {
        Formula::True | Formula::False | Formula::Cmp { .. } => 0,
        Formula::Not(_) | Formula::Always(..) | Formula::Eventually(..) => 1,
        Formula::Implies(..) | Formula::Until(..) => 2,
        Formula::And(gs) | Formula::Or(gs) => gs.len(),
    }
}

/// The nodes of `f`, each after its operands (in order), found without recursion.
fn post_order(f: &Formula) -> Vec<&Formula> {
    let mut order = Vec::new();
    let mut stack = vec![f];
    // Parents before children, children right to left: reversed, a post-order.
    while let Some(node) = stack.pop() {
        order.push(node);
        match node {
            Formula::True | Formula::False | Formula::Cmp { .. } => {}
            Formula::Not(g) | Formula::Always(_, g) | Formula::Eventually(_, g) => stack.push(g),
            Formula::And(gs) | Formula::Or(gs) => stack.extend(gs.iter()),
            Formula::Implies(g, h) | Formula::Until(_, g, h) => {
                stack.push(g);
                stack.push(h);
            }
        }
    }
    order.reverse();
    order
}
