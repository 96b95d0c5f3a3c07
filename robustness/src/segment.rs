//! Rewards of option executions: the task's robustness over a segment of states, and
//! over every suffix of a segment.
//!
//! The semantics are those of [`reference::segment_reward`].
//! Suffix rewards come from one signal over the whole segment: `rho(f, t)` depends only on
//! the states from `t` to the end, and every suffix ends where the segment ends, so the
//! robustness at step 0 of the suffix from `i` is the segment's `rho(f, i)`, windows
//! clipped alike. For a persistent task `always[0..] f` with `hor(f) = H`, the suffix from
//! `i` takes the minimum of `rho(f, u)` over `i <= u <= max(i, m - 1 - H)`: one backward
//! running minimum gives all of them. A task with a past-time operator reads the states
//! before `t` too, so a suffix is not the segment's tail there, but only near its start:
//! when every past window is bounded, `f`'s value in the suffix from `i` equals its value
//! in the segment from step `i + R` on, where `R` is `f`'s reach back (see
//! `start_reach`). Each suffix then evaluates its first `R + H` steps alone and takes
//! the rest from the one running minimum: `O(m (R + H))` for a segment of `m` steps. A
//! task without a horizon, or with an unbounded past window, scores each suffix on its
//! own, quadratic in the segment's length.
//!
//! So that scoring stays linear in a segment's length whatever the task, the steps the
//! suffixes evaluate on their own are held to [`SUFFIX_BUDGET`] per step of the segment.
//! Past it, only every `s`-th suffix from the segment's start is scored, with the
//! smallest `s` that fits, and the others are NaN: each scored suffix keeps its exact
//! value, and an intra-option update from a subset of a run's states is as sound as one
//! from all of them (the paper's SMDP update uses the first alone).

use crate::formula::{Node, expr_value};
use crate::offline::{Evaluator, Runner, Source};
use crate::primitives::{Lattice, Max, Min};
use crate::{CmpOp, Formula, FormulaBuilder, NodeId, Trace, reference};

/// How many steps the suffixes of one segment may evaluate on their own, per step of the
/// segment: scoring a segment's suffixes costs at most this many evaluated steps for each
/// of its steps. A task whose suffixes would cost more (a past window without an end, or
/// one longer than about this, on a long segment) has only every `s`-th suffix scored, the
/// others NaN. A past window of at most 128 steps under a horizon of at most 128 never
/// thins, nor does a segment of at most 512 steps.
pub const SUFFIX_BUDGET: usize = 256;

/// Scores segments of a trace against one task, reusing its buffers between calls.
#[derive(Clone, Debug)]
pub struct SegmentScorer {
    task: Formula,
    /// For a task `always[0..] f` with a finite horizon of `f`: `f` and that horizon.
    body: Option<(Formula, usize)>,
    /// For a task that reads the past: `f`'s [`start_reach`] (`None`: unbounded).
    reach: Option<usize>,
    eval: Evaluator,
}

impl SegmentScorer {
    /// A scorer for `task`.
    pub fn new(task: &Formula) -> SegmentScorer {
        let body = reference::persistent_body(task).map(|(f, h)| (task.sub(f), h));
        let reach = body.as_ref().and_then(|(f, _)| start_reach(f));
        SegmentScorer { task: task.clone(), body, reach, eval: Evaluator::new() }
    }
    /// The reward of one option execution whose states are `segment`; NaN when empty.
    pub fn reward(&mut self, segment: &Trace) -> f64 {
        let cols = columns(segment);
        self.reward_of_columns(&cols, segment.len())
    }

    /// `out[i]` becomes the reward of the suffix `segment[i..]`, for every `i`, or NaN for
    /// a suffix left unscored by [`SUFFIX_BUDGET`] (never `out[0]`).
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
        if self.task.has_past() {
            if let (Some((body, h)), Some(reach)) = (&self.body, self.reach) {
                let (h, eval) = (*h, &mut self.eval);
                let sig = eval.signal_of_columns(body, cols, m).to_vec();
                past_persistent_suffixes(m, h, reach, &sig, out, |i, n, k| {
                    let head: Vec<&[f64]> = cols.iter().map(|c| &c[i..i + n]).collect();
                    first_min(&eval.signal_of_columns(body, &head, n)[..k])
                });
                return;
            }
            let every = stride(m, |i| own_steps(m - i, self.body.is_some(), self.task.horizon()));
            for i in 0..m {
                let r = if i % every == 0 {
                    let tail: Vec<&[f64]> = cols.iter().map(|c| &c[i..m]).collect();
                    self.reward_of_columns(&tail, m - i)
                } else {
                    f64::NAN
                };
                out.push(r);
            }
            return;
        }
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
/// see them. Every state subformula the temporal operators read is computed once per
/// state, in [`TabularScorer::new`]; a segment then only gathers those values and runs
/// the temporal operators. An index outside the table reads as a state whose atoms are
/// all NaN.
///
/// The values are [`SegmentScorer`]'s on the segment's states, bit for bit: the state
/// values are computed with the same operations in the same order, and the temporal
/// operators run the same kernels over the same pieces.
#[derive(Clone, Debug)]
pub struct TabularScorer {
    /// The task, or for a task `always[0..] f` with a finite horizon of `f`, `f`.
    plan: Formula,
    /// `tables[v][s]`: the robustness of state node `v` of `plan` in the state with index
    /// `s`, for the nodes the evaluation stores (empty for the others); the last entry is
    /// its value when every atom is NaN.
    tables: Vec<Vec<f64>>,
    /// The horizon of `f` when the task is `always[0..] f`.
    persistent: Option<usize>,
    /// The task has a past-time operator: suffixes differ from the segment near their
    /// start.
    past: bool,
    /// The plan's [`start_reach`] when the task is persistent (`None`: unbounded).
    reach: Option<usize>,
    runner: Runner,
}

impl TabularScorer {
    /// A scorer for `task` over `states`, whose row `i` is the state with index `i`.
    pub fn new(task: &Formula, states: &Trace) -> TabularScorer {
        let past = task.has_past();
        let (plan, persistent) = match reference::persistent_body(task) {
            Some((body, h)) => (task.sub(body), Some(h)),
            None => (task.clone(), None),
        };
        let nodes = plan.nodes();
        let state = plan.states();
        // The state nodes a temporal node reads (or the root, when a state formula).
        let mut stored = vec![false; nodes.len()];
        for (v, node) in nodes.iter().enumerate() {
            if !state[v] {
                node.children().for_each(|c| stored[c] |= state[c]);
            }
        }
        stored[plan.root().index()] |= state[plan.root().index()];
        let mut tables: Vec<Vec<f64>> = Vec::new();
        let slot: Vec<Option<usize>> = stored
            .iter()
            .map(|&s| {
                s.then(|| {
                    tables.push(Vec::with_capacity(states.len() + 1));
                    tables.len() - 1
                })
            })
            .collect();
        let mut row = Vec::with_capacity(states.vars());
        let mut vals = vec![f64::NAN; nodes.len()];
        // Every state, then the state whose atoms are all NaN.
        for s in 0..=states.len() {
            let real = s < states.len();
            if real {
                states.row_into(s, &mut row);
            }
            for (v, node) in nodes.iter().enumerate() {
                if !state[v] {
                    continue;
                }
                let x = |k: &crate::NodeId| vals[k.index()];
                vals[v] = match node {
                    Node::True => f64::INFINITY,
                    Node::False => f64::NEG_INFINITY,
                    Node::Cmp { .. } if !real => f64::NAN,
                    Node::Cmp { lhs, op, rhs } => {
                        op.robustness(vals[lhs.index()], vals[rhs.index()])
                    }
                    Node::Not(g) => -x(g),
                    // As the evaluator folds a state `&&` or `||`: from the identity.
                    Node::And(gs) => gs.iter().fold(Min::ID, |a, g| Min::acc(a, x(g))),
                    Node::Or(gs) => gs.iter().fold(Max::ID, |a, g| Max::acc(a, x(g))),
                    Node::Implies(g, h) => (-x(g)).max(x(h)),
                    _ if real => expr_value(node, &vals, &row),
                    _ => f64::NAN,
                };
            }
            for (v, j) in slot.iter().enumerate() {
                if let Some(j) = j {
                    tables[*j].push(vals[v]);
                }
            }
        }
        // The temporal skeleton alone, each stored state node an atom `a_j > 0` whose
        // values are looked up in `tables[j]`: a segment costs nothing per state node.
        let mut b = FormulaBuilder::new();
        let mut map: Vec<Option<NodeId>> = vec![None; nodes.len()];
        let (zero, gt) = (b.constant(0.0), CmpOp::Gt);
        for (v, node) in nodes.iter().enumerate() {
            let m = |c: &NodeId| map[c.index()].unwrap_or(c.to_owned());
            map[v] = match (slot[v], node) {
                (Some(j), _) => {
                    let a = b.var(j);
                    Some(b.cmp(a, gt, zero))
                }
                _ if state[v] => None,
                (_, Node::Not(g)) => Some(b.not(m(g))),
                (_, Node::And(gs)) => Some(b.and(gs.iter().map(m).collect())),
                (_, Node::Or(gs)) => Some(b.or(gs.iter().map(m).collect())),
                (_, Node::Implies(g, h)) => Some(b.implies(m(g), m(h))),
                (_, Node::Always(i, g)) => Some(b.always(*i, m(g))),
                (_, Node::Eventually(i, g)) => Some(b.eventually(*i, m(g))),
                (_, Node::Until(i, g, h)) => Some(b.until(*i, m(g), m(h))),
                (_, Node::Once(i, g)) => Some(b.once(*i, m(g))),
                (_, Node::Historically(i, g)) => Some(b.historically(*i, m(g))),
                (_, Node::Since(i, g, h)) => Some(b.since(*i, m(g), m(h))),
                (_, Node::Prev(g)) => Some(b.prev(m(g))),
                (_, Node::Next(g)) => Some(b.next(m(g))),
                _ => None,
            };
        }
        let root = map[plan.root().index()].unwrap_or_else(|| b.bool(false));
        let plan = b.build(root);
        // The tables by the skeleton's node ids.
        let mut by_node = vec![Vec::new(); plan.len()];
        for (v, node) in plan.nodes().iter().enumerate() {
            if let Node::Cmp { lhs, .. } = node
                && let Node::Var(j) = plan[*lhs]
            {
                by_node[v] = std::mem::take(&mut tables[j]);
            }
        }
        let reach = persistent.and_then(|_| start_reach(&plan));
        TabularScorer { plan, tables: by_node, persistent, past, reach, runner: Runner::default() }
    }

    fn signal(&mut self, seg: &[usize]) -> Vec<f64> {
        let src = Source::Tables { tables: &self.tables, seg };
        self.runner.run(&self.plan, src, seg.len())
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
                let sig = self.signal(segment);
                let r = sig[..=last].iter().fold(f64::INFINITY, |a, b| a.min(*b));
                self.runner.put(sig);
                r
            }
            None => {
                let n = match self.plan.horizon() {
                    Some(h) => m.min(h.saturating_add(1)),
                    None => m,
                };
                let sig = self.signal(&segment[..n]);
                let r = sig[0];
                self.runner.put(sig);
                r
            }
        }
    }

    /// `out[i]` becomes the reward of the suffix `segment[i..]`, for every `i`, or NaN for
    /// a suffix left unscored by [`SUFFIX_BUDGET`] (never `out[0]`).
    pub fn suffix_rewards(&mut self, segment: &[usize], out: &mut Vec<f64>) {
        let m = segment.len();
        out.clear();
        if self.past {
            if let (Some(h), Some(reach)) = (self.persistent, self.reach) {
                let sig = self.signal(segment);
                past_persistent_suffixes(m, h, reach, &sig, out, |i, n, k| {
                    let head = self.signal(&segment[i..i + n]);
                    let r = first_min(&head[..k]);
                    self.runner.put(head);
                    r
                });
                self.runner.put(sig);
                return;
            }
            let (persistent, horizon) = (self.persistent.is_some(), self.plan.horizon());
            let every = stride(m, |i| own_steps(m - i, persistent, horizon));
            for i in 0..m {
                let r = if i % every == 0 { self.reward(&segment[i..]) } else { f64::NAN };
                out.push(r);
            }
            return;
        }
        let sig = self.signal(segment);
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
        self.runner.put(sig);
    }
}

/// How many steps after a segment's start `f`'s value may differ from its value over a
/// longer history: at every step `t >= i + start_reach(f)` of the suffix from `i`, `f`
/// reads no step before `i`, and so has the segment's value. `None` when a past window is
/// unbounded. An upper bound: a larger reach only costs time.
///
/// So `f`'s value at a trace's last step `t` is its value over the last `start_reach(f) +
/// 1` steps alone: what a reward read at the newest state keeps of the episode.
pub fn start_reach(f: &Formula) -> Option<usize> {
    let mut reach: Vec<Option<usize>> = Vec::with_capacity(f.len());
    let window = |i: &crate::Interval| crate::formula::window_end(i);
    for node in f.nodes() {
        let of = |k: &NodeId| reach[k.index()];
        let r = match node {
            // `f` at `t` reads its operand from `t + a` on.
            Node::Always(i, g) | Node::Eventually(i, g) => of(g).map(|r| r.saturating_sub(i.start)),
            Node::Until(i, g, h) => {
                of(g).and_then(|g| of(h).map(|h| g.max(h.saturating_sub(i.start))))
            }
            Node::Next(g) => of(g).map(|r| r.saturating_sub(1)),
            // `f` at `t` reads its operands from `t - b` on.
            Node::Once(i, g) | Node::Historically(i, g) => {
                window(i).and_then(|b| of(g)?.checked_add(b))
            }
            Node::Since(i, g, h) => window(i).and_then(|b| of(g)?.max(of(h)?).checked_add(b)),
            Node::Prev(g) => of(g).and_then(|r| r.checked_add(1)),
            _ => node.children().try_fold(0usize, |acc, k| reach[k].map(|r| acc.max(r))),
        };
        reach.push(r);
    }
    reach[f.root().index()]
}

/// `out[i]`: the reward of the suffix from `i` of a segment of `m` steps for the task
/// `always[0..] f`, `f` of horizon `h` and [`start_reach`] `reach`, given `f`'s signal
/// `sig` over the whole segment. `head(i, n, k)`: the least of `f`'s first `k` values over
/// the `n` steps from `i`; each of those values reads at most `h` steps ahead, so `n =
/// k + h` steps (or the rest of the segment) give them exactly. NaN for the suffixes
/// [`SUFFIX_BUDGET`] leaves unscored.
fn past_persistent_suffixes(
    m: usize,
    h: usize,
    reach: usize,
    sig: &[f64],
    out: &mut Vec<f64>,
    mut head: impl FnMut(usize, usize, usize) -> f64,
) {
    out.clear();
    if m == 0 {
        return;
    }
    // The steps up to `cut` count in every suffix that reaches it; `tail[u]`: the least of
    // `sig[u..=cut]`, `+inf` past `cut`.
    let cut = (m - 1).saturating_sub(h);
    let mut tail = vec![f64::INFINITY; cut + 2];
    for u in (0..=cut).rev() {
        tail[u] = tail[u + 1].min(sig[u]);
    }
    // The suffix from `i`: whether it is shorter than the horizon, how many of its first
    // values differ from the segment's, and the steps that evaluating them reads.
    let plan = |i: usize| {
        // A suffix shorter than the horizon keeps only its step 0.
        let short = m - 1 - i < h;
        let counted = if short { 1 } else { cut - i + 1 };
        let k = counted.min(reach);
        let n = if k == 0 { 0 } else { (m - i).min(k.saturating_add(h)) };
        (short, k, n)
    };
    // Each suffix reads at most `reach + h` steps: within the budget, no count is needed.
    let every = if reach.saturating_add(h) <= SUFFIX_BUDGET { 1 } else { stride(m, |i| plan(i).2) };
    for i in 0..m {
        if i % every != 0 {
            out.push(f64::NAN);
            continue;
        }
        let (short, k, n) = plan(i);
        let rest = match (short, k) {
            (false, _) => tail[i + k],
            (true, 0) => f64::INFINITY.min(sig[i]),
            (true, _) => f64::INFINITY,
        };
        let r = if k == 0 { rest } else { head(i, n, k).min(rest) };
        out.push(r);
    }
}

/// The steps a suffix of `len` steps evaluates when scored on its own: all of them for a
/// persistent task or one without a horizon, else those up to the horizon.
fn own_steps(len: usize, persistent: bool, horizon: Option<usize>) -> usize {
    match (persistent, horizon) {
        (false, Some(h)) => len.min(h.saturating_add(1)),
        _ => len,
    }
}

/// The stride of the suffixes scored in a segment of `m` steps whose suffix from `i`
/// evaluates `cost(i)` steps on its own, `cost` not increasing in `i`: 1 when all of them
/// fit in [`SUFFIX_BUDGET`] steps per step of the segment, else the smallest stride whose
/// suffixes (from the segment's start) do.
fn stride(m: usize, cost: impl Fn(usize) -> usize) -> usize {
    let budget = SUFFIX_BUDGET.saturating_mul(m);
    let scored =
        |every: usize| (0..m).step_by(every).fold(0usize, |a, i| a.saturating_add(cost(i)));
    let total = scored(1);
    if total <= budget {
        return 1;
    }
    // The first suffix costs at most `m`, and each later one at most the mean over the
    // stride before it: `m + total / every` steps in all, so this loop ends at once or
    // soon after.
    let mut every = total.div_ceil(budget.max(1)).max(2);
    while scored(every) > budget {
        every += 1;
    }
    every
}

/// The least of `values`, from `+inf` as the reference folds.
fn first_min(values: &[f64]) -> f64 {
    values.iter().fold(f64::INFINITY, |a, b| a.min(*b))
}

fn columns(trace: &Trace) -> Vec<&[f64]> {
    (0..trace.vars()).map(|i| trace.column(i)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Bound, CmpOp, Expr, Interval};

    fn x(op: CmpOp, c: f64) -> Formula {
        Formula::cmp(Expr::var(0), op, Expr::constant(c))
    }

    fn window(a: usize, b: Bound) -> Interval {
        Interval { start: a, end: b }
    }

    fn not(f: Formula) -> Formula {
        Formula::not(f)
    }

    fn ev(i: Interval, f: Formula) -> Formula {
        Formula::eventually(i, f)
    }

    fn alw(i: Interval, f: Formula) -> Formula {
        Formula::always(i, f)
    }

    /// Tasks over `x` with every operator, persistent or not; the negations make signed
    /// zeros (`-(5 - 5)`) meet unsigned ones in the folds.
    fn tasks() -> Vec<Formula> {
        use Bound::{Exclusive, Inclusive, Unbounded};
        use CmpOp::{Ge, Gt, Le, Lt};
        let band = Formula::and(vec![x(Gt, 3.0), x(Lt, 7.0)]);
        let body = Formula::and(vec![
            ev(window(0, Exclusive(5)), x(Gt, 7.0)),
            ev(window(0, Exclusive(5)), x(Lt, 2.0)),
            ev(window(0, Exclusive(5)), band.clone()),
        ]);
        let until = Formula::until(
            window(1, Inclusive(4)),
            not(x(Ge, 5.0)),
            Formula::or(vec![x(Le, 5.0), not(band.clone())]),
        );
        let implies = Formula::implies(
            not(ev(window(1, Inclusive(3)), band.clone())),
            alw(window(0, Inclusive(2)), x(Lt, 9.0)),
        );
        // `-0` at x = 5 and `+0` at x = 8 in one state formula's values.
        let zeros = Formula::or(vec![not(x(Ge, 5.0)), x(Ge, 8.0)]);
        vec![
            ev(window(0, Exclusive(5)), zeros.clone()),
            alw(window(0, Exclusive(5)), zeros.clone()),
            alw(Interval::ALL, ev(window(0, Inclusive(3)), zeros)),
            alw(Interval::ALL, body.clone()),
            alw(Interval::ALL, until.clone()),
            alw(Interval::ALL, implies.clone()),
            alw(Interval::ALL, Formula::or(vec![not(body.clone()), x(Gt, 5.0)])),
            body,
            until,
            implies,
            not(ev(window(2, Unbounded), not(x(Gt, 5.0)))),
            Formula::until(window(0, Unbounded), x(Lt, 8.0), x(Gt, 8.0)),
            not(band),
            alw(window(6, Inclusive(9)), x(Gt, 5.0)),
            alw(Interval::ALL, ev(window(30, Exclusive(70)), x(Lt, 1.0))),
            Formula::and(vec![]),
            alw(window(0, Inclusive(3)), Formula::bool(true)),
            // Past windows without an end: the long segments are thinned.
            alw(Interval::ALL, Formula::once(window(0, Unbounded), x(Gt, 8.0))),
            ev(window(0, Unbounded), Formula::historically(window(0, Unbounded), x(Lt, 9.0))),
            Formula::once(window(0, Unbounded), x(Gt, 8.0)),
        ]
        .into_iter()
        .chain(bounded_past_tasks())
        .collect()
    }

    /// Persistent tasks whose body reads a bounded past: the suffix rewards take the
    /// segment's signal from `start_reach` steps after each suffix's start.
    fn bounded_past_tasks() -> Vec<Formula> {
        use Bound::{Exclusive, Inclusive};
        use CmpOp::{Gt, Lt};
        let once = |i, f| Formula::once(i, f);
        let hist = |i, f| Formula::historically(i, f);
        vec![
            // Reach 4: seen above 7 within the last four steps, at every step.
            alw(Interval::ALL, once(window(0, Inclusive(4)), x(Gt, 7.0))),
            // Reach 3, horizon 5: a response that also looks back.
            alw(
                Interval::ALL,
                Formula::implies(
                    hist(window(1, Exclusive(4)), x(Lt, 5.0)),
                    ev(window(0, Inclusive(5)), x(Gt, 6.0)),
                ),
            ),
            // Reach 0: the past is read only where the suffix has it.
            alw(Interval::ALL, ev(window(3, Inclusive(6)), Formula::prev(x(Gt, 4.0)))),
            // A suffix's first steps decide its minimum: each errs if read with history.
            alw(
                Interval::ALL,
                Formula::or(vec![once(window(0, Inclusive(4)), x(Gt, 7.0)), x(Lt, 1.0)]),
            ),
            alw(Interval::ALL, Formula::or(vec![Formula::prev(x(Gt, 4.0)), x(Gt, 6.0)])),
            // A past window inside a future one, and `since`.
            alw(
                Interval::ALL,
                ev(
                    window(1, Inclusive(2)),
                    Formula::since(window(0, Inclusive(3)), x(Lt, 9.0), x(Gt, 6.0)),
                ),
            ),
        ]
    }

    #[test]
    fn start_reach_counts_the_steps_a_suffix_reads_before_its_start() {
        use Bound::{Inclusive, Unbounded};
        let p = x(CmpOp::Gt, 1.0);
        let reach = |f: Formula| start_reach(&f);
        assert_eq!(reach(p.clone()), Some(0));
        assert_eq!(reach(ev(window(0, Inclusive(9)), p.clone())), Some(0));
        assert_eq!(reach(Formula::prev(p.clone())), Some(1));
        assert_eq!(reach(Formula::once(window(2, Inclusive(5)), p.clone())), Some(5));
        assert_eq!(reach(Formula::once(window(0, Unbounded), p.clone())), None);
        let nested = Formula::historically(window(0, Inclusive(3)), Formula::prev(p.clone()));
        assert_eq!(reach(nested.clone()), Some(4));
        assert_eq!(reach(ev(window(2, Inclusive(7)), nested.clone())), Some(2));
        assert_eq!(reach(ev(window(6, Inclusive(7)), nested)), Some(0));
        let since = Formula::since(window(0, Inclusive(2)), Formula::prev(p.clone()), p.clone());
        assert_eq!(reach(since), Some(3));
        let until = Formula::until(window(3, Inclusive(4)), Formula::prev(p.clone()), p);
        assert_eq!(reach(until), Some(1));
    }

    #[test]
    fn past_suffix_rewards_equal_the_reference_on_long_segments() {
        use Bound::Unbounded;
        let mut lcg: u64 = 0x2026;
        let mut next = move || {
            lcg =
                lcg.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            ((lcg >> 33) % 11) as f64
        };
        let unbounded = alw(Interval::ALL, Formula::once(window(0, Unbounded), x(CmpOp::Gt, 8.0)));
        for task in bounded_past_tasks().into_iter().chain([unbounded]) {
            // Short segments, where a suffix's start decides its minimum, and long ones.
            let lengths = (0..=24).flat_map(|len| [len; 12]).chain([40, 250]);
            for len in lengths {
                let rows: Vec<f64> = (0..len).map(|_| next()).collect();
                let trace = Trace::from_columns(vec![rows]).unwrap();
                let mut got = Vec::new();
                SegmentScorer::new(&task).suffix_rewards(&trace, &mut got);
                for (i, g) in got.iter().enumerate() {
                    let tail = Trace::from_columns(vec![trace.column(0)[i..].to_vec()]).unwrap();
                    let want = reference::segment_reward(&task, &tail);
                    assert_eq!(g.to_bits(), want.to_bits(), "{task:?}, length {len}, suffix {i}");
                }
            }
        }
    }

    /// Past the budget, the suffixes from every `s`-th step are scored exactly and the others
    /// are NaN, with the smallest `s` whose suffixes fit in `SUFFIX_BUDGET` steps per step;
    /// within it every suffix is scored.
    #[test]
    fn long_segments_score_every_suffix_that_fits_the_budget_and_no_more() {
        use Bound::{Inclusive, Unbounded};
        let once = |i, f| Formula::once(i, f);
        let tasks = [
            // Every suffix reads back to its own start: `m - i` steps.
            alw(Interval::ALL, once(window(0, Unbounded), x(CmpOp::Gt, 8.0))),
            // A bounded window longer than the budget: `R + H` steps a suffix.
            alw(Interval::ALL, once(window(0, Inclusive(400)), x(CmpOp::Gt, 8.0))),
            // Within the budget: never thinned.
            alw(Interval::ALL, once(window(0, Inclusive(100)), x(CmpOp::Gt, 8.0))),
        ];
        for (task, (m, thinned)) in tasks.iter().zip([(3000, true), (3000, true), (3000, false)]) {
            let rows: Vec<f64> = (0..m).map(|i| ((i * 7919) % 11) as f64).collect();
            let trace = Trace::from_columns(vec![rows]).unwrap();
            let mut scorer = SegmentScorer::new(task);
            let mut got = Vec::new();
            scorer.suffix_rewards(&trace, &mut got);
            let scored: Vec<usize> = (0..m).filter(|&i| !got[i].is_nan()).collect();
            let every = scored.get(1).copied().unwrap_or(m);
            assert_eq!(thinned, every > 1, "{task:?}");
            assert_eq!(scored, (0..m).step_by(every).collect::<Vec<_>>(), "{task:?}");
            for &i in &scored {
                let tail = Trace::from_columns(vec![trace.column(0)[i..].to_vec()]).unwrap();
                assert_eq!(got[i].to_bits(), scorer.reward(&tail).to_bits(), "{task:?} suffix {i}");
            }
            // The steps the scored suffixes read before the running minimum takes over.
            let reach = start_reach(&task.sub(reference::persistent_body(task).unwrap().0));
            let cost = |i: usize| reach.map_or(m - i, |r| (m - i).min(r));
            let spent = |s: usize| (0..m).step_by(s).map(cost).sum::<usize>();
            assert!(spent(every) <= SUFFIX_BUDGET * m, "{task:?}: {} steps", spent(every));
            if thinned {
                assert!(spent(every - 1) > SUFFIX_BUDGET * m, "{task:?}: stride {every} too wide");
            }
        }
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
