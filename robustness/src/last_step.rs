//! A formula's robustness at the last step of a trace, as a formula without the future
//! operators that only the last step could reach.
//!
//! At the last step `t` of a trace every future window is clipped to `{t}` or to nothing:
//! `always[a..b] f` is `f` there when `a = 0` and `+inf` otherwise, `eventually[a..b] f`
//! is `f` or `-inf`, `f until[a..b] g` is `g` or `-inf`, and `next f` is `+inf`. A future
//! operator that no past operator reads is only ever evaluated at `t`, so it can be
//! replaced by what it is there; one under a past operator is read at earlier steps and is
//! kept. [`at_last_step`] does that replacement: a reward `rho(f, t)` over the trace so
//! far whose future operators all sit above its past ones becomes a past-time formula,
//! which the online monitor scores in `O(|f|)` a step instead of `O(t)`.

use crate::formula::{Formula, FormulaBuilder, Node, NodeId};

/// The formula whose robustness at the last step of every trace is `f`'s there, bit for
/// bit: the future operators that no past operator reads replaced by their value at the
/// last step (see the module docs).
pub fn at_last_step(f: &Formula) -> Formula {
    let nodes = f.nodes();
    let mut b = FormulaBuilder::new();
    // Every node as it is, imported once: a state formula or a past operator is read so.
    let kept = b.formula_nodes(f);
    // `end[v]`: node `v` at the last step (`None` for expressions, which only the kept
    // nodes read).
    let mut end: Vec<Option<NodeId>> = Vec::with_capacity(nodes.len());
    for (v, node) in nodes.iter().enumerate() {
        let at = |k: &NodeId, end: &[Option<NodeId>]| end[k.index()].expect("children first");
        let e = match node {
            _ if node.is_expr() => None,
            Node::Not(g) => Some(b.not(at(g, &end))),
            Node::And(gs) => Some(b.and(gs.iter().map(|g| at(g, &end)).collect())),
            Node::Or(gs) => Some(b.or(gs.iter().map(|g| at(g, &end)).collect())),
            Node::Implies(g, h) => Some(b.implies(at(g, &end), at(h, &end))),
            Node::Always(i, g) => Some(if reads_now(i) { at(g, &end) } else { b.bool(true) }),
            Node::Eventually(i, g) => Some(if reads_now(i) { at(g, &end) } else { b.bool(false) }),
            Node::Until(i, _, h) => Some(if reads_now(i) { at(h, &end) } else { b.bool(false) }),
            Node::Next(_) => Some(b.bool(true)),
            // A state formula, or a past operator: read as it is.
            _ => Some(kept[v]),
        };
        end.push(e);
    }
    let root = end[f.root().index()].expect("a formula's root is a formula node");
    b.build(root)
}

/// Whether a future window starting at `t` holds `t` itself.
fn reads_now(i: &crate::Interval) -> bool {
    i.start == 0 && !i.is_empty()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Bound, CmpOp, Expr, Interval, Trace, reference};

    fn x(op: CmpOp, c: f64) -> Formula {
        Formula::cmp(Expr::var(0), op, Expr::constant(c))
    }

    fn iv(a: usize, b: Bound) -> Interval {
        Interval { start: a, end: b }
    }

    #[test]
    fn the_last_step_of_every_prefix_is_the_formula_s() {
        use Bound::{Exclusive, Inclusive, Unbounded};
        use CmpOp::{Gt, Lt};
        let once = Formula::once(iv(0, Inclusive(3)), x(Gt, 6.0));
        let hist = Formula::historically(iv(1, Unbounded), x(Lt, 8.0));
        let future_over_past = [
            Formula::eventually(iv(0, Inclusive(5)), once.clone()),
            Formula::always(iv(0, Unbounded), Formula::or(vec![once.clone(), x(Lt, 2.0)])),
            Formula::always(iv(2, Inclusive(5)), hist.clone()),
            Formula::eventually(iv(1, Exclusive(4)), once.clone()),
            Formula::until(iv(0, Inclusive(4)), hist.clone(), once.clone()),
            Formula::until(iv(2, Inclusive(4)), hist.clone(), once.clone()),
            Formula::next(once.clone()),
            Formula::implies(
                Formula::prev(x(Gt, 3.0)),
                Formula::eventually(iv(0, Unbounded), hist),
            ),
            // A future operator under a past one is kept.
            Formula::once(
                iv(0, Inclusive(2)),
                Formula::eventually(iv(0, Inclusive(2)), x(Gt, 5.0)),
            ),
        ];
        let mut lcg: u64 = 7;
        let rows: Vec<f64> = (0..60)
            .map(|_| {
                lcg = lcg.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                ((lcg >> 33) % 11) as f64
            })
            .collect();
        for f in future_over_past {
            let g = at_last_step(&f);
            for n in 1..=rows.len() {
                let prefix = Trace::from_columns(vec![rows[..n].to_vec()]).unwrap();
                let (want, got) = (reference::signal(&f, &prefix), reference::signal(&g, &prefix));
                let (w, v) = (want[n - 1], got[n - 1]);
                assert_eq!(w.to_bits(), v.to_bits(), "{f:?} at step {}: {w} vs {v}", n - 1);
            }
        }
    }

    #[test]
    fn only_future_operators_under_a_past_one_keep_a_horizon() {
        let once = Formula::once(iv(0, Bound::Inclusive(3)), x(CmpOp::Gt, 6.0));
        let top = Formula::eventually(iv(0, Bound::Inclusive(9)), once);
        assert_eq!(top.horizon(), Some(9));
        assert_eq!(at_last_step(&top).horizon(), Some(0));
        let under = Formula::once(
            iv(0, Bound::Inclusive(2)),
            Formula::eventually(iv(0, Bound::Inclusive(2)), x(CmpOp::Gt, 5.0)),
        );
        assert_eq!(at_last_step(&under).horizon(), Some(2));
    }
}
