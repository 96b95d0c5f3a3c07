//! The robustness of a state formula (no temporal operator) on one sample, for callers
//! that meet states one at a time with no trace around them: the approximate learner's
//! rewards, initiation and termination tests on a continuous state.

use crate::Formula;

/// Evaluates state formulas on single samples, reusing one scratch buffer.
#[derive(Clone, Debug, Default)]
pub struct StateEval {
    values: Vec<f64>,
}

impl StateEval {
    /// An evaluator with an empty buffer.
    pub fn new() -> StateEval {
        StateEval::default()
    }

    /// `rho(f, state)` for a state formula `f` (see [`Formula::is_state_formula`]), with
    /// `state[i]` the value of variable `i`, as the reference evaluator gives it at a step
    /// of a trace; NaN for a formula with a temporal operator. The NaN policy is
    /// [`crate::offline`]'s.
    pub fn value(&mut self, f: &Formula, state: &[f64]) -> f64 {
        let nodes = f.nodes();
        self.values.clear();
        for node in nodes {
            let v = crate::stream::state_value(node, &self.values, state);
            self.values.push(v);
        }
        self.values[f.root().index()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CmpOp, Expr, Trace, reference};

    #[test]
    fn equals_the_reference_on_every_state() {
        let x = || Expr::var(0);
        let y = || Expr::var(1);
        let near = Formula::cmp(
            Expr::sqrt(Expr::add(Expr::mul(x(), x()), Expr::mul(y(), y()))),
            CmpOp::Lt,
            Expr::constant(2.0),
        );
        let f = Formula::and(vec![
            near.clone(),
            Formula::not(Formula::cmp(x(), CmpOp::Gt, Expr::constant(1.5))),
            Formula::or(vec![Formula::bool(false), Formula::implies(near, Formula::bool(true))]),
        ]);
        let mut eval = StateEval::new();
        for (a, b) in [(0.0, 0.0), (1.0, -1.5), (3.0, 0.5), (f64::INFINITY, 1.0), (-0.25, 0.0)] {
            let trace = Trace::from_columns(vec![vec![a], vec![b]]).unwrap();
            let want = reference::robustness(&f, &trace, 0);
            assert_eq!(eval.value(&f, &[a, b]).to_bits(), want.to_bits(), "({a}, {b})");
        }
    }
}
