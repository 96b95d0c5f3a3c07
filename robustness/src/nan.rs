//! Where a NaN comes from, so that callers can refuse it instead of letting a min or max
//! skip it.
//!
//! A trace without NaN gives a NaN robustness only at a comparison whose expressions
//! compute one: `sqrt` of a negative number, `0 / 0`, `inf / inf`, `0 * inf`,
//! `inf - inf`, or a comparison of two infinities of one sign. A [`NanCheck`] finds the
//! comparisons of a formula that can do so (most cannot: `x > 3` never does) and, state by
//! state, names the operation that did.

use crate::Formula;
use crate::formula::{ExprId, Node, NodeId};
use std::fmt;

/// The operation that made a NaN out of numbers, with its operands.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Operation {
    /// `sqrt(v)` with `v < 0`.
    Sqrt(f64),
    /// `a / b` with both zero or both infinite.
    Div(f64, f64),
    /// `a * b` with a zero and an infinity.
    Mul(f64, f64),
    /// `a + b` with opposite infinities.
    Add(f64, f64),
    /// `a - b` with equal infinities.
    Sub(f64, f64),
    /// The comparison's robustness (a difference) of two equal infinities.
    Compare(f64, f64),
}

/// Where a NaN arose on one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NanCause {
    /// The comparison whose robustness is NaN.
    pub atom: NodeId,
    /// The innermost expression that is NaN; `None` when the operands are numbers and the
    /// comparison itself is not.
    pub expr: Option<ExprId>,
    /// What it computed.
    pub operation: Operation,
}

/// The comparisons of one formula that can be NaN on a state without NaN, checked one
/// state at a time.
#[derive(Clone, Debug)]
pub struct NanCheck {
    atoms: Vec<NodeId>,
}

impl NanCheck {
    /// The check of `formula`'s comparisons.
    pub fn new(formula: &Formula) -> NanCheck {
        let nodes = formula.nodes();
        let finite = |e: &ExprId| matches!(nodes[e.index()], Node::Const(c) if c.is_finite());
        let plain = |e: &ExprId| matches!(nodes[e.index()], Node::Var(_) | Node::Const(_));
        let atoms = nodes
            .iter()
            .enumerate()
            .filter(|(_, n)| match n {
                // Not when one side is a finite constant and the other a variable or one.
                Node::Cmp { lhs, rhs, .. } => {
                    !((finite(lhs) && plain(rhs)) || (finite(rhs) && plain(lhs)))
                }
                _ => false,
            })
            .map(|(i, _)| NodeId::from_index(i))
            .collect();
        NanCheck { atoms }
    }

    /// Whether no comparison can be NaN (then [`NanCheck::check`] always passes).
    pub fn is_empty(&self) -> bool {
        self.atoms.is_empty()
    }

    /// The first comparison (in node order) of `formula` (the one this check was made
    /// for) that is NaN on `state` (`state[i]` is variable `i`, none of them NaN), and why;
    /// `None` when every one is a number. `values` is scratch space, reused across calls.
    pub fn check(
        &self,
        formula: &Formula,
        state: &[f64],
        values: &mut Vec<f64>,
    ) -> Option<NanCause> {
        let last = self.atoms.last()?.index();
        let nodes = formula.nodes();
        values.clear();
        for node in &nodes[..=last] {
            let v = crate::formula::expr_value(node, values, state);
            values.push(v);
        }
        for &atom in &self.atoms {
            let Node::Cmp { lhs, op, rhs } = &nodes[atom.index()] else { continue };
            let (l, r) = (values[lhs.index()], values[rhs.index()]);
            if let Some(e) = [lhs, rhs].into_iter().find(|e| values[e.index()].is_nan()) {
                let (expr, operation) = origin(nodes, values, *e);
                return Some(NanCause { atom, expr: Some(expr), operation });
            }
            if op.robustness(l, r).is_nan() {
                return Some(NanCause { atom, expr: None, operation: Operation::Compare(l, r) });
            }
        }
        None
    }
}

/// The innermost NaN below expression node `e` (itself NaN): follow NaN operands down.
fn origin(nodes: &[Node], values: &[f64], mut e: ExprId) -> (ExprId, Operation) {
    loop {
        let node = &nodes[e.index()];
        let v = |k: &ExprId| values[k.index()];
        let nan_kid = match node {
            Node::Neg(a) | Node::Abs(a) | Node::Sqrt(a) => [Some(a), None],
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) => {
                [Some(a), Some(b)]
            }
            _ => [None, None],
        }
        .into_iter()
        .flatten()
        .find(|k| v(k).is_nan());
        if let Some(k) = nan_kid {
            e = *k;
            continue;
        }
        let operation = match node {
            Node::Sqrt(a) => Operation::Sqrt(v(a)),
            Node::Add(a, b) => Operation::Add(v(a), v(b)),
            Node::Sub(a, b) => Operation::Sub(v(a), v(b)),
            Node::Mul(a, b) => Operation::Mul(v(a), v(b)),
            Node::Div(a, b) => Operation::Div(v(a), v(b)),
            // A NaN constant or variable: reported as the comparison of its value.
            _ => Operation::Compare(f64::NAN, f64::NAN),
        };
        return (e, operation);
    }
}

impl fmt::Display for Operation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Operation::Sqrt(v) => write!(f, "the square root of {v}"),
            Operation::Div(a, b) => write!(f, "{a} / {b}"),
            Operation::Mul(a, b) => write!(f, "{a} * {b}"),
            Operation::Add(a, b) => write!(f, "{a} + {b}"),
            Operation::Sub(a, b) => write!(f, "{a} - {b}"),
            Operation::Compare(a, b) => write!(f, "the comparison of {a} with {b}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CmpOp, Expr, Interval};

    fn x() -> Expr {
        Expr::var(0)
    }

    #[test]
    fn plain_comparisons_are_never_nan_prone() {
        let f = Formula::always(
            Interval::ALL,
            Formula::and(vec![
                Formula::cmp(x(), CmpOp::Gt, Expr::constant(3.0)),
                Formula::cmp(Expr::constant(1.0), CmpOp::Lt, x()),
            ]),
        );
        assert!(NanCheck::new(&f).is_empty());
    }

    #[test]
    fn the_square_root_of_a_negative_is_named() {
        let f = Formula::not(Formula::cmp(Expr::sqrt(x()), CmpOp::Gt, Expr::constant(1.0)));
        let check = NanCheck::new(&f);
        assert!(!check.is_empty());
        assert_eq!(check.check(&f, &[4.0], &mut Vec::new()), None);
        let cause = check.check(&f, &[-1.0], &mut Vec::new()).unwrap();
        let names = ["x"];
        let expr = f.expr_at(cause.expr.unwrap());
        assert_eq!(expr.display_with(&names).to_string(), "sqrt(x)");
        assert_eq!(cause.operation.to_string(), "the square root of -1");
    }

    #[test]
    fn the_innermost_operation_is_named() {
        // (x / x) + 1 at x = 0: the division, not the sum.
        let sum = Expr::add(Expr::div(x(), x()), Expr::constant(1.0));
        let f = Formula::cmp(sum, CmpOp::Ge, Expr::constant(0.0));
        let check = NanCheck::new(&f);
        let cause = check.check(&f, &[0.0], &mut Vec::new()).unwrap();
        assert_eq!(f.expr_at(cause.expr.unwrap()).display_with(&["x"]).to_string(), "x / x");
        assert_eq!(cause.operation, Operation::Div(0.0, 0.0));
    }

    #[test]
    fn two_equal_infinities_compared_are_nan() {
        let f = Formula::cmp(x(), CmpOp::Gt, Expr::var(1));
        let check = NanCheck::new(&f);
        assert_eq!(check.check(&f, &[f64::INFINITY, 1.0], &mut Vec::new()), None);
        let cause = check.check(&f, &[f64::INFINITY, f64::INFINITY], &mut Vec::new()).unwrap();
        assert_eq!(cause.expr, None);
        assert_eq!(cause.operation.to_string(), "the comparison of inf with inf");
    }
}
