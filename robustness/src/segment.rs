//! Rewards of option executions: the task's robustness over a segment of states, and
//! over every suffix of a segment.
//!
//! The semantics are those of [`reference::segment_reward`].
//! Suffix rewards come from one signal over the whole segment: `rho(f, t)` depends only on
//! the states from `t` to the end, and every suffix ends where the segment ends, so the
//! robustness at step 0 of the suffix from `i` is the segment's `rho(f, i)`, windows
//! clipped alike. For a persistent task `always[0..] f` with `hor(f) = H`, the suffix from
//! `i` takes the minimum of `rho(f, u)` over `i <= u <= max(i, m - 1 - H)`: one backward
//! running minimum gives all of them.

use crate::offline::Evaluator;
use crate::{CmpOp, Expr, Formula, Trace, reference};

/// Scores segments of a trace against one task, reusing its buffers between calls.
#[derive(Clone, Debug)]
pub struct SegmentScorer {
    task: Formula,
    /// For a task `always[0..] f` with a finite horizon of `f`: `f` and that horizon.
    body: Option<(Formula, usize)>,
    eval: Evaluator,
}

impl SegmentScorer {
    /// A scorer for `task`.
    pub fn new(task: &Formula) -> SegmentScorer {
        let body = reference::persistent_body(task).map(|(f, h)| (f.clone(), h));
        SegmentScorer { task: task.clone(), body, eval: Evaluator::new() }
    }

    /// The reward of one option execution whose states are `segment`; NaN when empty.
    pub fn reward(&mut self, segment: &Trace) -> f64 {
        let cols = columns(segment);
        self.reward_of_columns(&cols, segment.len())
    }

    /// `out[i]` becomes the reward of the suffix `segment[i..]`, for every `i`.
    pub fn suffix_rewards(&mut self, segment: &Trace, out: &mut Vec<f64>) {
        let cols = columns(segment);
        self.suffix_rewards_of_columns(&cols, segment.len(), out);
    }

    fn reward_of_columns(&mut self, cols: &[&[f64]], m: usize) -> f64 {
        if m == 0 {
            return f64::NAN;
        }
        match &self.body {
            Some((body, h)) => {
                let last = (m - 1).saturating_sub(*h);
                let sig = self.eval.signal_of_columns(body, cols, m);
                sig[..=last].iter().fold(f64::INFINITY, |a, b| a.min(*b))
            }
            None => self.eval.robustness_of_columns(&self.task, cols, m),
        }
    }

    fn suffix_rewards_of_columns(&mut self, cols: &[&[f64]], m: usize, out: &mut Vec<f64>) {
        out.clear();
        match &self.body {
            Some((body, h)) => {
                let sig = self.eval.signal_of_columns(body, cols, m);
                out.resize(m, 0.0);
                let cut = m.saturating_sub(1).saturating_sub(*h);
                let mut acc = f64::INFINITY;
                for i in (0..m).rev() {
                    out[i] = if i <= cut {
                        acc = acc.min(sig[i]);
                        acc
                    } else {
                        // A suffix shorter than the horizon keeps only its step 0.
                        f64::INFINITY.min(sig[i])
                    };
                }
            }
            None => out.extend_from_slice(self.eval.signal_of_columns(&self.task, cols, m)),
        }
    }
}

/// Scores segments given as indices into a fixed table of states, as tabular learners
/// see them. Each atomic predicate is computed once per state, in [`TabularScorer::new`];
/// a segment then only gathers those values. An index outside the table reads as NaN.
#[derive(Clone, Debug)]
pub struct TabularScorer {
    /// `atoms[j][s]`: the robustness of atom `j` in the state with index `s`.
    atoms: Vec<Vec<f64>>,
    inner: SegmentScorer,
    /// The gathered atom values of the current segment, one column per atom.
    segment: Vec<Vec<f64>>,
}

impl TabularScorer {
    /// A scorer for `task` over `states`, whose row `i` is the state with index `i`.
    pub fn new(task: &Formula, states: &Trace) -> TabularScorer {
        let mut atoms = Vec::new();
        let task = lift_atoms(task, &mut atoms);
        let mut row = Vec::with_capacity(states.vars());
        let mut table = vec![Vec::with_capacity(states.len()); atoms.len()];
        for s in 0..states.len() {
            states.row_into(s, &mut row);
            for ((lhs, op, rhs), col) in atoms.iter().zip(&mut table) {
                col.push(op.robustness(lhs.eval(&row), rhs.eval(&row)));
            }
        }
        let segment = vec![Vec::new(); table.len()];
        TabularScorer { atoms: table, inner: SegmentScorer::new(&task), segment }
    }

    /// The reward of the option execution through the states `segment`.
    pub fn reward(&mut self, segment: &[usize]) -> f64 {
        self.load(segment);
        let cols: Vec<&[f64]> = self.segment.iter().map(Vec::as_slice).collect();
        self.inner.reward_of_columns(&cols, segment.len())
    }

    /// `out[i]` becomes the reward of the suffix `segment[i..]`, for every `i`.
    pub fn suffix_rewards(&mut self, segment: &[usize], out: &mut Vec<f64>) {
        self.load(segment);
        let cols: Vec<&[f64]> = self.segment.iter().map(Vec::as_slice).collect();
        self.inner.suffix_rewards_of_columns(&cols, segment.len(), out);
    }

    fn load(&mut self, segment: &[usize]) {
        for (table, col) in self.atoms.iter().zip(&mut self.segment) {
            col.clear();
            col.extend(segment.iter().map(|&s| table.get(s).copied().unwrap_or(f64::NAN)));
        }
    }
}

fn columns(trace: &Trace) -> Vec<&[f64]> {
    (0..trace.vars()).map(|i| trace.column(i)).collect()
}

/// `f` with each comparison replaced by `a_j > 0`, `a_j` being a variable that holds the
/// comparison's robustness; `atoms` collects the comparisons, equal ones shared.
/// `v - 0` is `v` for every `f64`, so the values do not change.
fn lift_atoms(f: &Formula, atoms: &mut Vec<(Expr, CmpOp, Expr)>) -> Formula {
    let mut lift = |g: &Formula| Box::new(lift_atoms(g, atoms));
    match f {
        Formula::True => Formula::True,
        Formula::False => Formula::False,
        Formula::Cmp { lhs, op, rhs } => {
            let key = (lhs.clone(), *op, rhs.clone());
            let j = atoms.iter().position(|a| *a == key).unwrap_or_else(|| {
                atoms.push(key);
                atoms.len() - 1
            });
            Formula::Cmp { lhs: Expr::Var(j), op: CmpOp::Gt, rhs: Expr::Const(0.0) }
        }
        Formula::Not(g) => Formula::Not(lift(g)),
        Formula::Implies(g, h) => {
            let g = lift(g);
            Formula::Implies(g, lift(h))
        }
        Formula::Always(i, g) => Formula::Always(*i, lift(g)),
        Formula::Eventually(i, g) => Formula::Eventually(*i, lift(g)),
        Formula::Until(i, g, h) => {
            let g = lift(g);
            Formula::Until(*i, g, lift(h))
        }
        Formula::And(gs) => Formula::And(gs.iter().map(|g| lift_atoms(g, atoms)).collect()),
        Formula::Or(gs) => Formula::Or(gs.iter().map(|g| lift_atoms(g, atoms)).collect()),
    }
}
