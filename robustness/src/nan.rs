//! Where a NaN comes from, so that callers can refuse it instead of letting a min or max
//! skip it.
//!
//! A trace without NaN gives a NaN robustness only at a comparison whose expressions
//! compute one: `sqrt` of a negative number, `0 / 0`, `inf / inf`, `0 * inf`,
//! `inf - inf`, or a comparison of two infinities of one sign. [`nan_prone_atoms`] finds
//! the comparisons that can do so (most cannot: `x > 3` never does), and [`nan_cause`]
//! names the operation that did on one state.

use crate::{CmpOp, Expr, Formula};
use std::fmt;

/// A comparison `lhs op rhs` of a formula.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Atom<'f> {
    /// The left operand.
    pub lhs: &'f Expr,
    /// The comparison.
    pub op: CmpOp,
    /// The right operand.
    pub rhs: &'f Expr,
}

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
pub struct NanCause<'f> {
    /// The innermost expression that is NaN; `None` when the operands are numbers and the
    /// comparison itself is not.
    pub expr: Option<&'f Expr>,
    /// What it computed.
    pub operation: Operation,
}

/// The comparisons of `formula` that can be NaN on a state without NaN, in the order they
/// first appear (each once while there are few).
pub fn nan_prone_atoms(formula: &Formula) -> Vec<Atom<'_>> {
    let mut atoms: Vec<Atom<'_>> = Vec::new();
    let mut stack = vec![formula];
    while let Some(f) = stack.pop() {
        match f {
            Formula::True | Formula::False => {}
            Formula::Cmp { lhs, op, rhs } => {
                let atom = Atom { lhs, op: *op, rhs };
                // Lowering inlines lets, so one atom can appear many times; checking it
                // twice is only slower, so long lists skip the quadratic search.
                if nan_prone(&atom) && (atoms.len() > 64 || !atoms.contains(&atom)) {
                    atoms.push(atom);
                }
            }
            Formula::Not(g) | Formula::Always(_, g) | Formula::Eventually(_, g) => stack.push(g),
            Formula::And(gs) | Formula::Or(gs) => stack.extend(gs.iter().rev()),
            Formula::Implies(a, b) | Formula::Until(_, a, b) => {
                stack.push(b);
                stack.push(a);
            }
        }
    }
    atoms
}

/// Why `atom` is NaN on `state` (`state[i]` is variable `i`, none of them NaN), or `None`
/// when it is a number.
pub fn nan_cause<'f>(atom: &Atom<'f>, state: &[f64]) -> Option<NanCause<'f>> {
    let l = value(atom.lhs, state);
    let r = value(atom.rhs, state);
    if let Err(cause) = l {
        return Some(cause);
    }
    if let Err(cause) = r {
        return Some(cause);
    }
    let (l, r) = (l.ok()?, r.ok()?);
    atom.op
        .robustness(l, r)
        .is_nan()
        .then_some(NanCause { expr: None, operation: Operation::Compare(l, r) })
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

/// Whether the atom can be NaN on a state without NaN: not when one side is a finite
/// constant and the other a variable or a finite constant.
fn nan_prone(atom: &Atom<'_>) -> bool {
    let finite = |e: &Expr| matches!(e, Expr::Const(c) if c.is_finite());
    let plain = |e: &Expr| matches!(e, Expr::Var(_) | Expr::Const(_));
    !((finite(atom.lhs) && plain(atom.rhs)) || (finite(atom.rhs) && plain(atom.lhs)))
}

/// The value of `e`, or the innermost operation that made a NaN of numbers. Expressions
/// are as deep as the checker's nesting limits allow, so this recursion is bounded.
fn value<'f>(e: &'f Expr, s: &[f64]) -> Result<f64, NanCause<'f>> {
    let binary =
        |a: &'f Expr, b: &'f Expr, op: fn(f64, f64) -> f64, what: fn(f64, f64) -> Operation| {
            let (a, b) = (value(a, s)?, value(b, s)?);
            let v = op(a, b);
            if v.is_nan() { Err(NanCause { expr: Some(e), operation: what(a, b) }) } else { Ok(v) }
        };
    match e {
        Expr::Const(c) => Ok(*c),
        Expr::Var(_) => Ok(e.eval(s)),
        Expr::Neg(a) => Ok(-value(a, s)?),
        Expr::Abs(a) => Ok(value(a, s)?.abs()),
        Expr::Sqrt(a) => {
            let v = value(a, s)?;
            if v < 0.0 {
                Err(NanCause { expr: Some(e), operation: Operation::Sqrt(v) })
            } else {
                Ok(v.sqrt())
            }
        }
        Expr::Add(a, b) => binary(a, b, |a, b| a + b, Operation::Add),
        Expr::Sub(a, b) => binary(a, b, |a, b| a - b, Operation::Sub),
        Expr::Mul(a, b) => binary(a, b, |a, b| a * b, Operation::Mul),
        Expr::Div(a, b) => binary(a, b, |a, b| a / b, Operation::Div),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Interval;

    fn x() -> Expr {
        Expr::Var(0)
    }

    fn cmp(lhs: Expr, op: CmpOp, rhs: Expr) -> Formula {
        Formula::Cmp { lhs, op, rhs }
    }

    #[test]
    fn plain_comparisons_are_never_nan_prone() {
        let f = Formula::Always(
            Interval::ALL,
            Box::new(Formula::And(vec![
                cmp(x(), CmpOp::Gt, Expr::Const(3.0)),
                cmp(Expr::Const(1.0), CmpOp::Lt, x()),
            ])),
        );
        assert!(nan_prone_atoms(&f).is_empty());
    }

    #[test]
    fn the_square_root_of_a_negative_is_named() {
        let sqrt = Expr::Sqrt(Box::new(x()));
        let f = Formula::Not(Box::new(cmp(sqrt.clone(), CmpOp::Gt, Expr::Const(1.0))));
        let atoms = nan_prone_atoms(&f);
        assert_eq!(atoms.len(), 1);
        assert_eq!(nan_cause(&atoms[0], &[4.0]), None);
        let cause = nan_cause(&atoms[0], &[-1.0]).unwrap();
        assert_eq!(cause.expr, Some(&sqrt));
        assert_eq!(cause.operation.to_string(), "the square root of -1");
    }

    #[test]
    fn the_innermost_operation_is_named() {
        // (x / x) + 1 at x = 0: the division, not the sum.
        let div = Expr::Div(Box::new(x()), Box::new(x()));
        let sum = Expr::Add(Box::new(div.clone()), Box::new(Expr::Const(1.0)));
        let f = cmp(sum, CmpOp::Ge, Expr::Const(0.0));
        let atoms = nan_prone_atoms(&f);
        let cause = nan_cause(&atoms[0], &[0.0]).unwrap();
        assert_eq!(cause.expr, Some(&div));
        assert_eq!(cause.operation, Operation::Div(0.0, 0.0));
    }

    #[test]
    fn two_equal_infinities_compared_are_nan() {
        let f = cmp(x(), CmpOp::Gt, Expr::Var(1));
        let atoms = nan_prone_atoms(&f);
        assert_eq!(atoms.len(), 1);
        assert_eq!(nan_cause(&atoms[0], &[f64::INFINITY, 1.0]), None);
        let cause = nan_cause(&atoms[0], &[f64::INFINITY, f64::INFINITY]).unwrap();
        assert_eq!(cause.expr, None);
        assert_eq!(cause.operation.to_string(), "the comparison of inf with inf");
    }

    #[test]
    fn a_repeated_atom_is_listed_once() {
        let a = cmp(Expr::Sqrt(Box::new(x())), CmpOp::Gt, Expr::Const(1.0));
        let f = Formula::Or(vec![a.clone(), Formula::Not(Box::new(a))]);
        assert_eq!(nan_prone_atoms(&f).len(), 1);
    }
}
