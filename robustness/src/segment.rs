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

use crate::kernels::Kernels;
use crate::offline::{Evaluator, Lattice, Max, Min, fold_operand, piece_len};
use crate::{CmpOp, Expr, Formula, Interval, Trace, reference};

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
/// see them. Every maximal state subformula of the task (one with no temporal operator)
/// is computed once per state, in [`TabularScorer::new`]; a segment then only gathers
/// those values and runs the temporal operators. An index outside the table reads as a
/// state whose atoms are all NaN.
///
/// The values are [`SegmentScorer`]'s on the segment's states, bit for bit: the state
/// values come from the same evaluator code, and the temporal operators run the same
/// kernels over the same pieces.
#[derive(Clone, Debug)]
pub struct TabularScorer {
    /// `tables[j][s]`: the robustness of state subformula `j` in the state with index `s`;
    /// the last entry is its value when every atom is NaN.
    tables: Vec<Vec<f64>>,
    /// The task, or for a task `always[0..] f` with a finite horizon of `f`, `f`.
    plan: Node,
    /// The horizon of `f` when the task is `always[0..] f`.
    persistent: Option<usize>,
    work: Work,
}

/// A task with its state subformulas replaced by per-state tables.
#[derive(Clone, Debug)]
struct Node {
    op: Op,
    /// The subformula's horizon.
    horizon: Option<usize>,
}

#[derive(Clone, Debug)]
enum Op {
    /// Maximal state subformula `j`: `tables[j]`.
    State(usize),
    Not(Box<Node>),
    And(Vec<Node>),
    Or(Vec<Node>),
    Implies(Box<Node>, Box<Node>),
    Always(Interval, Box<Node>),
    Eventually(Interval, Box<Node>),
    Until(Interval, Box<Node>, Box<Node>),
}

/// The buffers of [`TabularScorer`]'s evaluation.
#[derive(Clone, Debug, Default)]
struct Work {
    pool: Vec<Vec<f64>>,
    kernels: Kernels,
    /// Prefix and suffix folds of [`van_herk`].
    pre: Vec<f64>,
    suf: Vec<f64>,
}

impl TabularScorer {
    /// A scorer for `task` over `states`, whose row `i` is the state with index `i`.
    pub fn new(task: &Formula, states: &Trace) -> TabularScorer {
        let mut atoms = Vec::new();
        let task = lift_atoms(task, &mut atoms);
        // One column per atom over the states and a last row of NaN, and one more column
        // so that the trace has a column even when the task has no atom.
        let mut row = Vec::with_capacity(states.vars());
        let mut columns = vec![Vec::with_capacity(states.len() + 1); atoms.len() + 1];
        for s in 0..states.len() {
            states.row_into(s, &mut row);
            for ((lhs, op, rhs), col) in atoms.iter().zip(&mut columns) {
                col.push(op.robustness(lhs.eval(&row), rhs.eval(&row)));
            }
        }
        for col in &mut columns[..atoms.len()] {
            col.push(f64::NAN);
        }
        columns[atoms.len()].resize(states.len() + 1, 0.0);
        let atom_trace = Trace::from_columns(columns).expect("columns of equal length");
        let (root, persistent) = match reference::persistent_body(&task) {
            Some((body, h)) => (body, Some(h)),
            None => (&task, None),
        };
        let mut subformulas = Vec::new();
        let plan = compile(root, &mut subformulas);
        let mut eval = Evaluator::new();
        let tables = subformulas.iter().map(|f| eval.signal(f, &atom_trace).to_vec()).collect();
        TabularScorer { tables, plan, persistent, work: Work::default() }
    }

    /// The reward of the option execution through the states `segment`.
    pub fn reward(&mut self, segment: &[usize]) -> f64 {
        let m = segment.len();
        if m == 0 {
            return f64::NAN;
        }
        match self.persistent {
            Some(h) => {
                let last = (m - 1).saturating_sub(h);
                let sig = self.work.eval(&self.plan, &self.tables, segment);
                let r = sig[..=last].iter().fold(f64::INFINITY, |a, b| a.min(*b));
                self.work.pool.push(sig);
                r
            }
            None => {
                let n = match self.plan.horizon {
                    Some(h) => m.min(h.saturating_add(1)),
                    None => m,
                };
                let sig = self.work.eval(&self.plan, &self.tables, &segment[..n]);
                let r = sig[0];
                self.work.pool.push(sig);
                r
            }
        }
    }

    /// `out[i]` becomes the reward of the suffix `segment[i..]`, for every `i`.
    pub fn suffix_rewards(&mut self, segment: &[usize], out: &mut Vec<f64>) {
        let m = segment.len();
        out.clear();
        let sig = self.work.eval(&self.plan, &self.tables, segment);
        match self.persistent {
            Some(h) => {
                out.resize(m, 0.0);
                if m > 0 {
                    let cut = (m - 1).saturating_sub(h);
                    // A suffix shorter than the horizon keeps only its step 0.
                    for (o, &v) in out[cut + 1..].iter_mut().zip(&sig[cut + 1..]) {
                        *o = f64::INFINITY.min(v);
                    }
                    // The others take the running minimum of `sig[i..=cut]`.
                    let mut acc = f64::INFINITY;
                    for (o, &v) in out[..=cut].iter_mut().zip(&sig[..=cut]).rev() {
                        acc = acc.min(v);
                        *o = acc;
                    }
                }
            }
            None => out.extend_from_slice(&sig),
        }
        self.work.pool.push(sig);
    }
}

/// `f` as a [`Node`]; its maximal state subformulas are appended to `states` (equal ones
/// shared).
fn compile(f: &Formula, states: &mut Vec<Formula>) -> Node {
    let horizon = f.horizon();
    let mut sub = |g: &Formula| Box::new(compile(g, states));
    let op = match f {
        _ if f.is_state_formula() => {
            let j = states.iter().position(|g| g == f).unwrap_or_else(|| {
                states.push(f.clone());
                states.len() - 1
            });
            Op::State(j)
        }
        Formula::Not(g) => Op::Not(sub(g)),
        Formula::Implies(g, h) => {
            let g = sub(g);
            Op::Implies(g, sub(h))
        }
        Formula::Always(i, g) => Op::Always(*i, sub(g)),
        Formula::Eventually(i, g) => Op::Eventually(*i, sub(g)),
        Formula::Until(i, g, h) => {
            let g = sub(g);
            Op::Until(*i, g, sub(h))
        }
        Formula::And(gs) => Op::And(gs.iter().map(|g| compile(g, states)).collect()),
        Formula::Or(gs) => Op::Or(gs.iter().map(|g| compile(g, states)).collect()),
        // State formulas were taken above.
        Formula::True | Formula::False | Formula::Cmp { .. } => {
            unreachable!("a formula without temporal operator is a state formula")
        }
    };
    Node { op, horizon }
}

impl Work {
    /// A buffer of `n` values, stale: every operator overwrites its whole output.
    fn take(&mut self, n: usize) -> Vec<f64> {
        let mut v = self.pool.pop().unwrap_or_default();
        if v.len() < n {
            v.resize(n, 0.0);
        } else {
            v.truncate(n);
        }
        v
    }

    /// The signal of `node` over the states `seg`, in pieces as [`Evaluator`] cuts them.
    fn eval(&mut self, node: &Node, tables: &[Vec<f64>], seg: &[usize]) -> Vec<f64> {
        let n = seg.len();
        let piece = match (&node.op, node.horizon) {
            (Op::State(_), _) | (_, None) => usize::MAX,
            (_, Some(h)) => piece_len(h),
        };
        if n / 2 <= piece {
            return self.eval_whole(node, tables, seg);
        }
        let h = node.horizon.unwrap_or(0);
        let mut out = self.take(n);
        let mut lo = 0;
        while lo < n {
            let hi = (lo + piece).min(n);
            let end = hi.saturating_add(h).min(n);
            let v = self.eval_whole(node, tables, &seg[lo..end]);
            out[lo..hi].copy_from_slice(&v[..hi - lo]);
            self.pool.push(v);
            lo = hi;
        }
        out
    }

    /// [`Work::eval`] in one piece, operator by operator as [`Evaluator`] does.
    fn eval_whole(&mut self, node: &Node, tables: &[Vec<f64>], seg: &[usize]) -> Vec<f64> {
        match &node.op {
            Op::State(j) => {
                let table = &tables[*j];
                let nan_row = table.len() - 1;
                let mut out = self.take(seg.len());
                for (o, &s) in out.iter_mut().zip(seg) {
                    *o = table[s.min(nan_row)];
                }
                out
            }
            Op::Not(g) => {
                let mut out = self.eval(g, tables, seg);
                out.iter_mut().for_each(|v| *v = -*v);
                out
            }
            Op::And(gs) => self.fold::<Min>(gs, tables, seg),
            Op::Or(gs) => self.fold::<Max>(gs, tables, seg),
            Op::Implies(g, h) => {
                let mut out = self.eval(g, tables, seg);
                let rhs = self.eval(h, tables, seg);
                out.iter_mut().zip(&rhs).for_each(|(a, b)| *a = (-*a).max(*b));
                self.pool.push(rhs);
                out
            }
            Op::Always(i, g) => {
                let mut out = self.eval(g, tables, seg);
                self.window::<Min>(i, &mut out, Kernels::always);
                out
            }
            Op::Eventually(i, g) => {
                let mut out = self.eval(g, tables, seg);
                self.window::<Max>(i, &mut out, Kernels::eventually);
                out
            }
            Op::Until(i, g, h) => {
                let mut lhs = self.eval(g, tables, seg);
                let mut out = self.eval(h, tables, seg);
                self.kernels.until(i, &mut lhs, &mut out);
                self.pool.push(lhs);
                out
            }
        }
    }

    /// `buf[t]` becomes the `L`-fold of `buf` over the window of `i` at `t`, as `kernel`
    /// (the kernels' `L`-window) computes it; the common case (a bounded window of two
    /// steps or more that starts inside `buf`) runs [`van_herk`] below.
    fn window<L: Lattice>(
        &mut self,
        i: &Interval,
        buf: &mut [f64],
        kernel: fn(&mut Kernels, &Interval, &mut [f64]),
    ) {
        let n = buf.len();
        let len = match i.last_offset() {
            Some(last) if !i.is_empty() && i.start < n => (last - i.start).saturating_add(1),
            _ => 1,
        };
        if len == 1 {
            kernel(&mut self.kernels, i, buf);
            return;
        }
        van_herk::<L>(buf, i.start, len.min(n), &mut self.pre, &mut self.suf);
    }

    fn fold<L: Lattice>(&mut self, gs: &[Node], tables: &[Vec<f64>], seg: &[usize]) -> Vec<f64> {
        let Some((first, rest)) = gs.split_first() else {
            let mut out = self.take(seg.len());
            out.fill(L::ID);
            return out;
        };
        let mut out = self.eval(first, tables, seg);
        if rest.is_empty() {
            fold_operand::<L>(&mut out, None, true);
        }
        for (k, g) in rest.iter().enumerate() {
            let v = self.eval(g, tables, seg);
            fold_operand::<L>(&mut out, Some(&v), k == 0);
            self.pool.push(v);
        }
        out
    }
}

/// `buf[t]` becomes the `L`-fold of `buf[t + a ..= t + a + len - 1]` (clipped at the end),
/// with `2 <= len <= n` and `a < n`: the blocks, folds and combinations of the evaluator's
/// van Herk/Gil-Werman kernel, in the same order and so with the same bits (signed zeros
/// included), in straight loops for the short segments of option executions.
fn van_herk<L: Lattice>(
    buf: &mut [f64],
    a: usize,
    len: usize,
    pre: &mut Vec<f64>,
    suf: &mut Vec<f64>,
) {
    let n = buf.len();
    if a == 0 && len == n {
        // One block (a segment no longer than the window): every window is a suffix of
        // it, and the first also takes the block's prefix fold, as below.
        let p_last = buf.iter().fold(L::ID, |acc, &x| L::acc(acc, x));
        let mut acc = L::ID;
        for x in buf.iter_mut().rev() {
            acc = L::acc(acc, *x);
            *x = acc;
        }
        buf[0] = L::acc(buf[0], p_last);
        return;
    }
    // Both are overwritten in full below: only their lengths matter.
    pre.resize(n, 0.0);
    pre.truncate(n);
    suf.resize(n, 0.0);
    suf.truncate(n);
    for ((x, p), s) in buf.chunks(len).zip(pre.chunks_mut(len)).zip(suf.chunks_mut(len)) {
        let (p, s) = (&mut p[..x.len()], &mut s[..x.len()]);
        let mut acc = L::ID;
        for j in 0..x.len() {
            acc = L::acc(acc, x[j]);
            p[j] = acc;
        }
        let mut acc = L::ID;
        for j in (0..x.len()).rev() {
            acc = L::acc(acc, x[j]);
            s[j] = acc;
        }
    }
    // Window `s ..= s + len - 1`, `s = t + a`: the suffix of `s`'s block and the prefix of
    // the next block; clipped windows reach at most into the last block.
    let span = len - 1;
    let full = n.saturating_sub(span + a);
    let (pre, suf) = (&pre[..], &suf[..]);
    for ((o, &s), &p) in buf[..full].iter_mut().zip(&suf[a..]).zip(&pre[(a + span).min(n)..]) {
        *o = L::acc(s, p);
    }
    let last_block = (n - 1) / len * len;
    let mid = last_block.clamp(full + a, n);
    let p_last = pre[n - 1];
    for (o, &s) in buf[full..mid - a].iter_mut().zip(&suf[full + a..mid]) {
        *o = L::acc(s, p_last);
    }
    buf[mid - a..n - a].copy_from_slice(&suf[mid..]);
    buf[n - a..].fill(L::ID);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Bound;

    fn x(op: CmpOp, c: f64) -> Formula {
        Formula::Cmp { lhs: Expr::Var(0), op, rhs: Expr::Const(c) }
    }

    fn window(a: usize, b: Bound) -> Interval {
        Interval { start: a, end: b }
    }

    fn not(f: Formula) -> Formula {
        Formula::Not(Box::new(f))
    }

    fn ev(i: Interval, f: Formula) -> Formula {
        Formula::Eventually(i, Box::new(f))
    }

    fn alw(i: Interval, f: Formula) -> Formula {
        Formula::Always(i, Box::new(f))
    }

    /// Tasks over `x` with every operator, persistent or not; the negations make signed
    /// zeros (`-(5 - 5)`) meet unsigned ones in the folds.
    fn tasks() -> Vec<Formula> {
        use Bound::{Exclusive, Inclusive, Unbounded};
        use CmpOp::{Ge, Gt, Le, Lt};
        let band = Formula::And(vec![x(Gt, 3.0), x(Lt, 7.0)]);
        let body = Formula::And(vec![
            ev(window(0, Exclusive(5)), x(Gt, 7.0)),
            ev(window(0, Exclusive(5)), x(Lt, 2.0)),
            ev(window(0, Exclusive(5)), band.clone()),
        ]);
        let until = Formula::Until(
            window(1, Inclusive(4)),
            Box::new(not(x(Ge, 5.0))),
            Box::new(Formula::Or(vec![x(Le, 5.0), not(band.clone())])),
        );
        let implies = Formula::Implies(
            Box::new(not(ev(window(1, Inclusive(3)), band.clone()))),
            Box::new(alw(window(0, Inclusive(2)), x(Lt, 9.0))),
        );
        // `-0` at x = 5 and `+0` at x = 8 in one state formula's values.
        let zeros = Formula::Or(vec![not(x(Ge, 5.0)), x(Ge, 8.0)]);
        vec![
            ev(window(0, Exclusive(5)), zeros.clone()),
            alw(window(0, Exclusive(5)), zeros.clone()),
            alw(Interval::ALL, ev(window(0, Inclusive(3)), zeros)),
            alw(Interval::ALL, body.clone()),
            alw(Interval::ALL, until.clone()),
            alw(Interval::ALL, implies.clone()),
            alw(Interval::ALL, Formula::Or(vec![not(body.clone()), x(Gt, 5.0)])),
            body,
            until,
            implies,
            not(ev(window(2, Unbounded), not(x(Gt, 5.0)))),
            Formula::Until(window(0, Unbounded), Box::new(x(Lt, 8.0)), Box::new(x(Gt, 8.0))),
            not(band),
            alw(window(6, Inclusive(9)), x(Gt, 5.0)),
            alw(Interval::ALL, ev(window(30, Exclusive(70)), x(Lt, 1.0))),
            Formula::And(vec![]),
            alw(window(0, Inclusive(3)), Formula::True),
        ]
    }

    /// The fast tabular scorer gives [`SegmentScorer`]'s values on the segment's states,
    /// bit for bit: short segments, segments past the horizon, segments long enough to be
    /// cut in pieces, and indices outside the table (a state whose `x` is NaN).
    #[test]
    fn tabular_scores_equal_the_segment_scorers_bit_for_bit() {
        let states = Trace::from_columns(vec![(0..11).map(f64::from).collect()]).unwrap();
        let mut lcg: u64 = 0x2016;
        let mut next = move |n: u64| {
            lcg =
                lcg.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            ((lcg >> 33) % n) as usize
        };
        for task in tasks() {
            let mut tab = TabularScorer::new(&task, &states);
            let mut seg_scorer = SegmentScorer::new(&task);
            // Walks over the table with a few indices outside it: many short ones (one van
            // Herk block), then longer ones; and walks where `-0` (x = 5) and `+0` (x = 8)
            // meet in one window, both ways round.
            let short = (0..400).map(|i| i % 13);
            let mut segments: Vec<Vec<usize>> = short
                .chain([40, 97, 2 * 8192 + 300])
                .map(|len| {
                    let mut seg = vec![next(11)];
                    while seg.len() < len {
                        let last = seg[seg.len() - 1].min(10);
                        seg.push(match next(40) {
                            0 => 11 + next(3),
                            k => (last + (k % 3)).saturating_sub(1).min(10),
                        });
                    }
                    seg.truncate(len);
                    seg
                })
                .collect();
            segments.extend([vec![5, 6, 7, 8], vec![8, 7, 6, 5], vec![5, 8, 5, 8, 8, 5, 5, 8, 8]]);
            for seg in segments {
                let len = seg.len();
                let rows: Vec<f64> =
                    seg.iter().map(|&s| if s < 11 { s as f64 } else { f64::NAN }).collect();
                let trace = Trace::from_columns(vec![rows]).unwrap();
                let (mut got, mut want) = (Vec::new(), Vec::new());
                tab.suffix_rewards(&seg, &mut got);
                seg_scorer.suffix_rewards(&trace, &mut want);
                let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                assert_eq!(bits(&got), bits(&want), "{task:?}, length {len}");
                let (r, w) = (tab.reward(&seg), seg_scorer.reward(&trace));
                assert_eq!(r.to_bits(), w.to_bits(), "{task:?}, length {len}: {r} vs {w}");
            }
        }
    }
}
