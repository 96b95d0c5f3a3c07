//! The online dense-time monitor: samples arrive one row at a time, change points of the
//! robustness signal leave once no later sample can change them.
//!
//! Every node of the formula is a streaming operator: it takes its operands' new change
//! points and how far they are final (a *frontier* `F`: every change point before `F` has
//! been given, and the values before `F` are final), and gives its own new change points
//! and frontier, in one pass over what is new:
//! - a comparison gives a point at each row (final up to the row's stamp);
//! - `!`, `&&`, `||` and `->` merge their operands' points up to the least of their
//!   frontiers, as the offline evaluator merges whole signals;
//! - `eventually`, `always`, `once` and `historically` run the offline sliding window (a
//!   monotone deque over pieces) up to the time no piece still to come can reach: for a
//!   future window `[a, b]` over an operand final up to `F`, a later piece starts at
//!   `s - b >= F - b` and the last known piece ends at `s' - a >= F - a`, so every event
//!   before `F - b` (one IEEE operation, as the window's own ends) is final; past windows
//!   likewise up to `F + a`. The deque and the pieces kept span one window;
//! - `since` (timed or not) is rtamt's decomposition (`once[a..=b] g && historically[0..=a]
//!   (f since g)`) of streaming parts: untimed `since` is a forward recurrence;
//! - bounded `until[a..=b]` is a sweep over the union of its operands' pieces (a monotone
//!   deque and a two-stack queue, see `super::until`), decided up to `F - b` like a window;
//!   the offline evaluator runs the same sweep;
//! - unbounded `until` (`[a..]`, untimed) is a backward recurrence from the end of the
//!   trace: its node keeps its operands' points and evaluates them offline at the end.
//!
//! Each operator computes the same values at the same breakpoints as the offline evaluator
//! (the same IEEE operations in the same order), so the monitor's change points are
//! [`DenseFormula::signal`]'s bit for bit.

use super::{DenseError, DenseFormula, DenseTraceBuilder};
use crate::formula::Node;
use std::collections::VecDeque;

mod ops;
mod save;

use ops::*;

/// Monitors a [`DenseFormula`] over rows of time-stamped samples pushed one at a time.
///
/// [`DenseMonitor::push`] returns the change points that became final (`(t, value)`: the
/// value holds from `t` until the next change point); [`DenseMonitor::finish`] ends the
/// trace and returns the rest up to the last stamp. Together they are exactly
/// [`DenseFormula::signal`]'s change points up to the last stamp. A change point at `t` is
/// given once a row stamped after `t + H` has arrived (give or take a few ulps), `H` the
/// formula's future reach ([`DenseFormula::future_reach`]), and never before a row stamped
/// at or after `t` (past operators could tell earlier, but the trace may end first).
///
/// The monitor is incremental: each operator keeps only the pieces its window spans (see
/// the module's source for how), so the work per row does not grow with the windows'
/// lengths and memory is bounded by them, bounded `until` included. An unbounded future
/// operator (`eventually[a..]`, `always`, `until[a..]`) decides nothing before the end and
/// keeps everything; an unbounded past one (`once[a..]`, `historically`) keeps only its
/// running extreme.
#[derive(Clone, Debug)]
pub struct DenseMonitor {
    formula: DenseFormula,
    rows: DenseTraceBuilder,
    vars: usize,
    ops: Vec<Op>,
    /// Each expression node's value at the last row.
    ev: Vec<f64>,
    /// Each node's change points given in this step.
    fresh: Vec<Vec<(f64, f64)>>,
    /// Each node's frontier.
    front: Vec<f64>,
    /// The first stamp; NaN before the first row.
    t0: f64,
    /// The last stamp.
    x: f64,
    /// The root's final change points after the last stamp (given once a row reaches them).
    held: VecDeque<(f64, f64)>,
}

impl DenseMonitor {
    /// A monitor for `formula` over rows of `vars` variables.
    pub fn new(formula: &DenseFormula, vars: usize) -> Result<DenseMonitor, DenseError> {
        if let Some(var) = formula.formula().max_var()
            && var >= vars
        {
            return Err(DenseError::MissingVar { var, vars });
        }
        let n = formula.formula.nodes().len();
        Ok(DenseMonitor {
            formula: formula.clone(),
            rows: DenseTraceBuilder::new(vars),
            vars,
            ops: ops(formula),
            ev: vec![0.0; n],
            fresh: vec![Vec::new(); n],
            front: vec![f64::NEG_INFINITY; n],
            t0: f64::NAN,
            x: f64::NAN,
            held: VecDeque::new(),
        })
    }

    /// Has no effect: kept for compatibility. (The monitor used to re-evaluate its window
    /// at every row, and batching rows traded delay for throughput; it is now incremental.)
    pub fn set_batch(&mut self, n: usize) {
        let _ = n;
    }

    /// The number of pieces and change points the monitor holds (its operators' windows'
    /// worth), bounded by the windows' lengths for bounded windows.
    pub fn kept(&self) -> usize {
        self.ops.iter().map(Op::kept).sum::<usize>() + self.held.len() + 1
    }

    /// Appends a row with stamp `t` (`None`: no new sample of that variable) and returns
    /// the change points it decided.
    pub fn push(&mut self, t: f64, cells: &[Option<f64>]) -> Result<Vec<(f64, f64)>, DenseError> {
        self.rows.push(t, cells)?;
        self.row()
    }

    /// [`DenseMonitor::push`] with a whole-number stamp (nanoseconds, say), taken relative
    /// to the first row's stamp in integer arithmetic; the change points' times are
    /// relative to it too ([`DenseMonitor::origin`]).
    pub fn push_int(
        &mut self,
        stamp: impl Into<i128>,
        cells: &[Option<f64>],
    ) -> Result<Vec<(f64, f64)>, DenseError> {
        self.rows.push_int(stamp, cells)?;
        self.row()
    }

    /// The first and the last stamp pushed since the trace began, in the times of the
    /// change points (relative to [`DenseMonitor::origin`] for whole-number stamps); `None`
    /// before the first row.
    pub fn span(&self) -> Option<(f64, f64)> {
        (!self.t0.is_nan()).then_some((self.t0, self.x))
    }

    /// The rows pushed since the trace began.
    pub fn rows(&self) -> usize {
        self.rows.len()
    }

    /// The first whole-number stamp, when rows have whole-number stamps.
    pub fn origin(&self) -> Option<i128> {
        self.rows.origin()
    }

    /// The row just pushed: one step of every node.
    fn row(&mut self) -> Result<Vec<(f64, f64)>, DenseError> {
        let (times, _) = self.rows.rows();
        if times.len() > 1 {
            // Only the last row is needed (it holds the values of empty cells).
            self.rows.drop_front(times.len() - 1);
        }
        let (times, _) = self.rows.rows();
        let t = times[times.len() - 1];
        if self.t0.is_nan() {
            self.t0 = t;
        }
        self.x = t;
        self.step(Some(t))?;
        Ok(self.release(t))
    }

    /// The root's points up to `upto`.
    fn release(&mut self, upto: f64) -> Vec<(f64, f64)> {
        let mut out = Vec::new();
        while let Some(&(t, v)) = self.held.front() {
            if t > upto {
                break;
            }
            out.push((t, v));
            self.held.pop_front();
        }
        out
    }

    /// Every node in order, on the last row (`Some(t)`) or at the end of the trace.
    fn step(&mut self, row: Option<f64>) -> Result<(), DenseError> {
        let DenseMonitor { formula, rows, ops, ev, fresh, front, t0, held, .. } = self;
        let t0 = *t0;
        let nodes = formula.formula.nodes();
        let (_, columns) = rows.rows();
        for f in fresh.iter_mut() {
            f.clear();
        }
        for (i, node) in nodes.iter().enumerate() {
            let (done, rest) = fresh.split_at_mut(i);
            let out = &mut rest[0];
            let fr = |id: usize| (front[id], done[id].as_slice());
            let new_front = match &mut ops[i] {
                Op::Expr => {
                    if row.is_some() {
                        let e = |id: &crate::formula::ExprId| ev[id.index()];
                        ev[i] = match node {
                            Node::Const(c) => *c,
                            Node::Var(j) => *columns[*j].last().expect("a row"),
                            Node::Neg(a) => -e(a),
                            Node::Abs(a) => e(a).abs(),
                            Node::Sqrt(a) => e(a).sqrt(),
                            Node::Add(a, b) => e(a) + e(b),
                            Node::Sub(a, b) => e(a) - e(b),
                            Node::Mul(a, b) => e(a) * e(b),
                            Node::Div(a, b) => e(a) / e(b),
                            _ => unreachable!("an expression node"),
                        };
                    }
                    continue;
                }
                Op::Cmp(dd) => match row {
                    Some(t) => {
                        let Node::Cmp { lhs, op, rhs } = node else { unreachable!("a comparison") };
                        let v = op.robustness(ev[lhs.index()], ev[rhs.index()]);
                        if v.is_nan() {
                            return Err(DenseError::Nan { time: t, atom: formula.atom_text(i) });
                        }
                        dd.push(out, t, v);
                        t
                    }
                    None => INF,
                },
                Op::Constant(v, dd) => {
                    dd.push(out, t0, *v);
                    INF
                }
                Op::Not(dd) => {
                    let Node::Not(a) = node else { unreachable!("a negation") };
                    for &(t, v) in &done[a.index()] {
                        dd.push(out, t, -v);
                    }
                    front[a.index()]
                }
                Op::Copy => {
                    let (Node::And(gs) | Node::Or(gs)) = node else { unreachable!("and, or") };
                    let c = gs[0].index();
                    out.extend_from_slice(&done[c]);
                    front[c]
                }
                Op::Merge(m) => {
                    let mut f = INF;
                    let mut feed = |k: usize, c: usize| {
                        m.feed(k, &done[c]);
                        f = f.min(front[c]);
                    };
                    match node {
                        Node::And(gs) | Node::Or(gs) => {
                            for (k, g) in gs.iter().enumerate() {
                                feed(k, g.index());
                            }
                        }
                        Node::Implies(a, b) => {
                            feed(0, a.index());
                            feed(1, b.index());
                        }
                        _ => unreachable!("a merge"),
                    }
                    m.advance(f, out);
                    f
                }
                Op::Win(w) => {
                    let c = node.children().next().expect("an operand");
                    w.feed(&done[c]);
                    w.advance(t0, front[c], out)
                }
                Op::Since(s) => {
                    let Node::Since(_, f, g) = node else { unreachable!("since") };
                    s.advance(t0, fr(f.index()), fr(g.index()), out)
                }
                Op::Bounded(p) => {
                    let Node::Until(_, f, g) = node else { unreachable!("until") };
                    let (pieces, until) = &mut **p;
                    let operands = front[f.index()].min(front[g.index()]);
                    pieces.feed(&done[f.index()], &done[g.index()]);
                    pieces.advance(operands, until);
                    until.advance(t0, operands, out)
                }
                Op::Until(u) => {
                    let Node::Until(_, f, g) = node else { unreachable!("until") };
                    u.advance(t0, fr(f.index()), fr(g.index()), out)
                }
            };
            front[i] = new_front;
        }
        let root = formula.formula.root().index();
        held.extend(fresh[root].iter().copied());
        Ok(())
    }

    /// Ends the trace: the change points not returned yet, up to the last stamp. The
    /// monitor is then ready for a new trace.
    pub fn finish(&mut self) -> Result<Vec<(f64, f64)>, DenseError> {
        if self.t0.is_nan() {
            return Ok(Vec::new());
        }
        let result = self.step(None);
        let x = self.x;
        let out = self.release(x);
        *self = DenseMonitor::new(&self.formula, self.vars)?;
        result.map(|()| out)
    }
}
