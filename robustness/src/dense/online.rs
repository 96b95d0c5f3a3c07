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

use super::offline::{self, Dir, Ext, max, min};
use super::saved::{self, Reader, SavedStateError, Writer};
use super::trace;
use super::until::{BoundedUntil, Pieces};
use super::{DenseError, DenseFormula, DenseSignal, DenseTraceBuilder};
use crate::formula::Node;
use std::collections::VecDeque;

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

/// `x` lowered by a relative margin of a few ulps (and a tiny absolute one), so a frontier
/// computed in rounded arithmetic stays on the safe side.
fn down(x: f64, scale: f64) -> f64 {
    x - (x.abs() + scale) * f64::EPSILON * 16.0 - f64::MIN_POSITIVE
}

const INF: f64 = f64::INFINITY;

/// Drops a change point that repeats the last value, as [`DenseSignal`] does.
#[derive(Clone, Debug, Default)]
struct Dedup {
    last: Option<f64>,
}

impl Dedup {
    #[inline]
    fn push(&mut self, out: &mut Vec<(f64, f64)>, t: f64, v: f64) {
        if self.last != Some(v) {
            out.push((t, v));
            self.last = Some(v);
        }
    }
}

/// How a merge combines its operands' values.
#[derive(Clone, Copy, Debug)]
enum Fold {
    Min,
    Max,
    /// `max(-a, b)`.
    Implies,
    /// Untimed `since`: `u = max(min(f, g), min(f, u_before))`.
    Since,
}

/// Operands' points merged over the union of their change points, up to the least of the
/// operands' frontiers.
#[derive(Clone, Debug)]
struct Merge {
    fold: Fold,
    queues: Vec<VecDeque<(f64, f64)>>,
    cur: Vec<f64>,
    /// `since`'s running value.
    acc: f64,
    out: Dedup,
}

impl Merge {
    fn new(fold: Fold, n: usize) -> Merge {
        Merge {
            fold,
            queues: vec![VecDeque::new(); n],
            cur: vec![0.0; n],
            acc: f64::NEG_INFINITY,
            out: Dedup::default(),
        }
    }

    fn feed(&mut self, k: usize, points: &[(f64, f64)]) {
        self.queues[k].extend(points.iter().copied());
    }

    fn kept(&self) -> usize {
        self.queues.iter().map(VecDeque::len).sum()
    }

    /// Every union time before `frontier` (the least of the operands' frontiers: each
    /// operand's points before it have all been fed).
    fn advance(&mut self, frontier: f64, out: &mut Vec<(f64, f64)>) {
        loop {
            let mut t: Option<f64> = None;
            for q in &self.queues {
                if let Some(&(x, _)) = q.front()
                    && t.is_none_or(|t| x < t)
                {
                    t = Some(x);
                }
            }
            let Some(t) = t else { break };
            if t >= frontier {
                break;
            }
            for (q, c) in self.queues.iter_mut().zip(&mut self.cur) {
                if q.front().is_some_and(|p| p.0 == t) {
                    *c = q.pop_front().map_or(*c, |p| p.1);
                }
            }
            let c = &self.cur;
            let v = match self.fold {
                Fold::Min => c[1..].iter().fold(c[0], |acc, &x| min(acc, x)),
                Fold::Max => c[1..].iter().fold(c[0], |acc, &x| max(acc, x)),
                Fold::Implies => max(-c[0], c[1]),
                Fold::Since => {
                    self.acc = max(min(c[0], c[1]), min(c[0], self.acc));
                    self.acc
                }
            };
            self.out.push(out, t, v);
        }
    }
}

/// A window operator fed piece by piece: the offline sweep, run up to the time no piece
/// still to come can change.
#[derive(Clone, Debug)]
struct Win {
    dir: Dir,
    a: f64,
    b: f64,
    ext: Ext,
    /// Whether pieces ever leave the window (not for an unbounded past window).
    ends: bool,
    /// The pieces from `base` on: their start times and values.
    times: VecDeque<f64>,
    vals: VecDeque<f64>,
    base: usize,
    /// The next piece to enter and the next to leave (absolute indices).
    i: usize,
    j: usize,
    dq: VecDeque<(usize, f64)>,
    /// The last event swept, if any.
    swept: Option<f64>,
    out: Dedup,
}

impl Win {
    fn new(dir: Dir, a: f64, b: f64, ext: Ext) -> Win {
        Win {
            dir,
            a,
            b,
            ext,
            ends: !(dir == Dir::Past && b == INF),
            times: VecDeque::new(),
            vals: VecDeque::new(),
            base: 0,
            i: 0,
            j: 0,
            dq: VecDeque::new(),
            swept: None,
            out: Dedup::default(),
        }
    }

    fn feed(&mut self, points: &[(f64, f64)]) {
        for &(t, v) in points {
            self.times.push_back(t);
            self.vals.push_back(v);
        }
    }

    fn kept(&self) -> usize {
        self.times.len() + self.dq.len()
    }

    fn received(&self) -> usize {
        self.base + self.times.len()
    }

    /// When piece `k` starts meeting the window (as offline computes it).
    #[inline]
    fn start(&self, k: usize) -> f64 {
        // A piece the window does not hold never starts (only a saved state changed by
        // hand could ask for one).
        let Some(&s) = self.times.get(k.wrapping_sub(self.base)) else { return INF };
        match self.dir {
            Dir::Future => s - self.b,
            Dir::Past => s + self.a,
        }
    }

    /// When piece `k` stops meeting the window; `None` while its successor is unknown.
    #[inline]
    fn end(&self, k: usize, done: bool) -> Option<f64> {
        if !self.ends {
            return Some(INF);
        }
        match self.times.get((k + 1).wrapping_sub(self.base)) {
            Some(&next) => Some(match self.dir {
                Dir::Future => next - self.a,
                Dir::Past => next + self.b,
            }),
            None => done.then_some(INF),
        }
    }

    /// Sweeps every event before the operand's frontier allows; returns the output's
    /// frontier.
    fn advance(&mut self, t0: f64, operand: f64, out: &mut Vec<(f64, f64)>) -> f64 {
        let done = operand == INF;
        // A piece still to come starts at `s - b` (`s + a`) with `s >= operand`, and the
        // last known one ends no sooner (rounding is monotone).
        let limit = if done {
            INF
        } else {
            match self.dir {
                Dir::Future => operand - self.b,
                Dir::Past => operand + self.a,
            }
        };
        loop {
            let t = match self.swept {
                None => t0,
                Some(_) => {
                    let rec = self.received();
                    let unknown = if done { INF } else { limit };
                    let next_start = if self.i < rec { self.start(self.i) } else { unknown };
                    let next_end = if self.j < rec {
                        self.end(self.j, done).unwrap_or(unknown)
                    } else {
                        unknown
                    };
                    next_start.min(next_end)
                }
            };
            if t >= limit {
                break;
            }
            let rec = self.received();
            while self.i < rec && self.start(self.i) <= t {
                // A piece already past its end (an empty interval) never enters.
                if self.i >= self.j {
                    let v = self.vals[self.i - self.base];
                    while self.dq.back().is_some_and(|&(_, q)| self.ext.dominates(v, q)) {
                        self.dq.pop_back();
                    }
                    self.dq.push_back((self.i, v));
                }
                self.i += 1;
            }
            while self.j < rec && self.end(self.j, done).is_some_and(|e| e <= t) {
                if self.dq.front().is_some_and(|q| q.0 == self.j) {
                    self.dq.pop_front();
                }
                self.j += 1;
            }
            let v = self.dq.front().map_or(self.ext.identity(), |q| q.1);
            self.out.push(out, t, v);
            self.swept = Some(t);
            // Pieces before the next to leave (to enter, when none leaves) are done with.
            let keep = if self.ends { self.j } else { self.i };
            while self.base < keep && !self.times.is_empty() {
                self.times.pop_front();
                self.vals.pop_front();
                self.base += 1;
            }
        }
        limit
    }
}

/// `f since[a..=b] g` as rtamt decomposes it, of streaming parts.
#[derive(Clone, Debug)]
struct SinceNode {
    b: f64,
    untimed: Merge,
    /// `once[a..=b] g`, `historically[0..=a] (f since g)` (for `a > 0`) and their `&&`;
    /// none for `[0..]`.
    reach: Option<Win>,
    hold: Option<Win>,
    both: Option<Merge>,
}

impl SinceNode {
    fn new(a: f64, b: f64) -> SinceNode {
        let untimed = a == 0.0 && b == INF;
        SinceNode {
            b,
            untimed: Merge::new(Fold::Since, 2),
            reach: (!untimed).then(|| Win::new(Dir::Past, a, b, Ext::Max)),
            hold: (a != 0.0).then(|| Win::new(Dir::Past, 0.0, a, Ext::Min)),
            both: (!untimed).then(|| Merge::new(Fold::Min, 2)),
        }
    }

    fn kept(&self) -> usize {
        self.untimed.kept()
            + self.reach.as_ref().map_or(0, Win::kept)
            + self.hold.as_ref().map_or(0, Win::kept)
            + self.both.as_ref().map_or(0, Merge::kept)
    }

    fn advance(
        &mut self,
        t0: f64,
        (ff, fp): (f64, &[(f64, f64)]),
        (gf, gp): (f64, &[(f64, f64)]),
        out: &mut Vec<(f64, f64)>,
    ) -> f64 {
        self.untimed.feed(0, fp);
        self.untimed.feed(1, gp);
        let uf = ff.min(gf);
        let (Some(reach), Some(both)) = (&mut self.reach, &mut self.both) else {
            self.untimed.advance(uf, out);
            return uf;
        };
        let mut up = Vec::new();
        self.untimed.advance(uf, &mut up);
        reach.feed(gp);
        let mut rp = Vec::new();
        let rf = reach.advance(t0, gf, &mut rp);
        let (hp, hf) = match &mut self.hold {
            Some(hold) => {
                hold.feed(&up);
                let mut hp = Vec::new();
                let hf = hold.advance(t0, uf, &mut hp);
                (hp, hf)
            }
            None => (up, uf),
        };
        if self.b == INF {
            both.feed(0, &hp);
            both.feed(1, &rp);
        } else {
            both.feed(0, &rp);
            both.feed(1, &hp);
        }
        let f = rf.min(hf);
        both.advance(f, out);
        f
    }
}

/// `f until[a..] g` (unbounded; bounded ones are [`BoundedUntil`]): the operands' points
/// are kept and evaluated offline once the trace ends (`F` is infinite only then).
#[derive(Clone, Debug)]
struct UntilNode {
    a: f64,
    b: f64,
    f: VecDeque<(f64, f64)>,
    g: VecDeque<(f64, f64)>,
    /// The node's frontier; `-inf` before the first step.
    decided: f64,
    out: Dedup,
}

impl UntilNode {
    fn kept(&self) -> usize {
        self.f.len() + self.g.len()
    }

    fn advance(
        &mut self,
        t0: f64,
        (ff, fp): (f64, &[(f64, f64)]),
        (gf, gp): (f64, &[(f64, f64)]),
        out: &mut Vec<(f64, f64)>,
    ) -> f64 {
        self.f.extend(fp.iter().copied());
        self.g.extend(gp.iter().copied());
        if self.decided == f64::NEG_INFINITY {
            self.decided = t0;
        }
        let fc = ff.min(gf);
        let frontier = if fc == INF { INF } else { down(fc - self.b, self.b) };
        let d = self.decided;
        if frontier <= d || self.f.is_empty() || self.g.is_empty() {
            return d;
        }
        // The kept points from `d` on: the first holds at `d` (see below), so it is moved
        // to `d`, which changes no value from `d` on.
        let signal = |q: &VecDeque<(f64, f64)>| {
            let mut s = DenseSignal::with_capacity(q.len());
            for (k, &(t, v)) in q.iter().enumerate() {
                s.push(if k == 0 { d } else { t }, v);
            }
            s
        };
        let s = offline::timed_until(
            &signal(&self.f),
            &signal(&self.g),
            d,
            Dir::Future,
            self.a,
            self.b,
        );
        for (t, v) in s.points() {
            if t >= frontier {
                break;
            }
            if t >= d {
                self.out.push(out, t, v);
            }
        }
        self.decided = frontier;
        // Keep the last point at or before the frontier (it holds there) and the rest.
        for q in [&mut self.f, &mut self.g] {
            while q.len() >= 2 && q[1].0 <= frontier {
                q.pop_front();
            }
        }
        frontier
    }
}

/// One node's streaming state.
#[derive(Clone, Debug)]
enum Op {
    /// An expression: a value per row.
    Expr,
    /// A comparison: a point per row.
    Cmp(Dedup),
    /// `true`, `false`, an empty `&&` or `||`: one point at the first stamp.
    Constant(f64, Dedup),
    Not(Dedup),
    /// `&&` or `||` of one operand.
    Copy,
    Merge(Merge),
    Win(Win),
    Since(Box<SinceNode>),
    /// Bounded `until`: the sweep of `super::until`.
    Bounded(Box<(Pieces, BoundedUntil)>),
    /// Unbounded `until`: kept and evaluated at the end.
    Until(Box<UntilNode>),
}

impl Op {
    fn kept(&self) -> usize {
        match self {
            Op::Merge(m) => m.kept(),
            Op::Win(w) => w.kept(),
            Op::Since(s) => s.kept(),
            Op::Bounded(p) => p.0.kept() + p.1.kept(),
            Op::Until(u) => u.kept(),
            _ => 0,
        }
    }
}

fn ops(df: &DenseFormula) -> Vec<Op> {
    let nodes = df.formula.nodes();
    nodes
        .iter()
        .enumerate()
        .map(|(i, node)| {
            let (a, b) = df.bounds[i];
            match node {
                Node::Cmp { .. } => Op::Cmp(Dedup::default()),
                Node::True => Op::Constant(INF, Dedup::default()),
                Node::False => Op::Constant(f64::NEG_INFINITY, Dedup::default()),
                Node::Not(_) => Op::Not(Dedup::default()),
                Node::And(gs) | Node::Or(gs) => {
                    let and = matches!(node, Node::And(_));
                    match gs.len() {
                        0 => Op::Constant(
                            if and { INF } else { f64::NEG_INFINITY },
                            Dedup::default(),
                        ),
                        1 => Op::Copy,
                        n => Op::Merge(Merge::new(if and { Fold::Min } else { Fold::Max }, n)),
                    }
                }
                Node::Implies(..) => Op::Merge(Merge::new(Fold::Implies, 2)),
                Node::Eventually(..) => Op::Win(Win::new(Dir::Future, a, b, Ext::Max)),
                Node::Always(..) => Op::Win(Win::new(Dir::Future, a, b, Ext::Min)),
                Node::Once(..) => Op::Win(Win::new(Dir::Past, a, b, Ext::Max)),
                Node::Historically(..) => Op::Win(Win::new(Dir::Past, a, b, Ext::Min)),
                Node::Since(..) => Op::Since(Box::new(SinceNode::new(a, b))),
                Node::Until(..) if b < INF => {
                    Op::Bounded(Box::new((Pieces::default(), BoundedUntil::new(a, b))))
                }
                Node::Until(..) => Op::Until(Box::new(UntilNode {
                    a,
                    b,
                    f: VecDeque::new(),
                    g: VecDeque::new(),
                    decided: f64::NEG_INFINITY,
                    out: Dedup::default(),
                })),
                _ => Op::Expr,
            }
        })
        .collect()
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

impl Dedup {
    fn save(&self, w: &mut Writer) {
        w.opt_f64(self.last);
    }

    fn load(r: &mut Reader<'_>) -> Result<Dedup, SavedStateError> {
        Ok(Dedup { last: r.opt_value("an operator's last value")? })
    }
}

impl Merge {
    fn save(&self, w: &mut Writer) {
        w.count(self.queues.len());
        for q in &self.queues {
            w.points(q.iter());
        }
        for &c in &self.cur {
            w.f64(c);
        }
        w.f64(self.acc);
        self.out.save(w);
    }

    /// Loads into a merge built for the formula (its fold and operand count).
    fn load(&mut self, r: &mut Reader<'_>) -> Result<(), SavedStateError> {
        let n = r.count(1, "a merge's operands")?;
        if n != self.queues.len() {
            return Err(r.bad(&format!(
                "a merge has {n} operands, and the formula's has {}",
                self.queues.len()
            )));
        }
        for q in &mut self.queues {
            *q = r.points("a merge's operand")?.into();
        }
        for c in &mut self.cur {
            *c = r.value("a merge's operand value")?;
        }
        self.acc = r.value("a since's running value")?;
        self.out = Dedup::load(r)?;
        Ok(())
    }
}

impl Win {
    fn save(&self, w: &mut Writer) {
        w.count(self.times.len());
        for (&t, &v) in self.times.iter().zip(&self.vals) {
            w.f64(t);
            w.f64(v);
        }
        for n in [self.base, self.i, self.j] {
            w.count(n);
        }
        w.count(self.dq.len());
        for &(k, v) in &self.dq {
            w.count(k);
            w.f64(v);
        }
        w.opt_f64(self.swept);
        self.out.save(w);
    }

    /// Loads into a window built for the formula (its direction, bounds and extreme); the
    /// monotone deque of a window whose pieces leave is checked against its recomputation.
    fn load(&mut self, r: &mut Reader<'_>) -> Result<(), SavedStateError> {
        let points = r.points("a window's pieces")?;
        self.times = points.iter().map(|p| p.0).collect();
        self.vals = points.iter().map(|p| p.1).collect();
        let max = usize::MAX >> 2;
        self.base = r.index(max, "a window's first piece")?;
        self.i = r.index(max, "a window's next piece to enter")?;
        self.j = r.index(max, "a window's next piece to leave")?;
        let rec = self.received();
        let fits = if self.ends {
            self.base <= self.j && self.j <= self.i && self.i <= rec
        } else {
            self.j == 0 && self.base <= self.i && self.i <= rec
        };
        if !fits {
            return Err(r.bad(&format!(
                "a window's positions do not fit together (pieces {} to {rec}, entered up to \
                 {}, left up to {})",
                self.base, self.i, self.j
            )));
        }
        let n = r.count(2, "a window's deque")?;
        let mut dq: VecDeque<(usize, f64)> = VecDeque::with_capacity(n);
        for _ in 0..n {
            let k = r.index(max, "a window's deque")?;
            let v = r.value("a window's deque")?;
            let ordered = dq.back().is_none_or(|&(p, q)| p < k && !self.ext.dominates(v, q));
            if !ordered || k >= self.i {
                return Err(r.bad("a window's deque is not monotone over the pieces entered"));
            }
            dq.push_back((k, v));
        }
        if self.ends {
            // Every piece from the next to leave to the next to enter is in the window.
            let mut want: VecDeque<(usize, f64)> = VecDeque::new();
            for k in self.j..self.i {
                let v = self.vals[k - self.base];
                while want.back().is_some_and(|&(_, q)| self.ext.dominates(v, q)) {
                    want.pop_back();
                }
                want.push_back((k, v));
            }
            if !super::until::same(&dq, &want) {
                return Err(r.bad("a window's deque is not that of its pieces"));
            }
        }
        self.dq = dq;
        self.swept = if r.flag("whether a window swept")? {
            Some(r.value("a window's last time")?)
        } else {
            None
        };
        self.out = Dedup::load(r)?;
        Ok(())
    }
}

impl SinceNode {
    fn save(&self, w: &mut Writer) {
        self.untimed.save(w);
        for win in [&self.reach, &self.hold].into_iter().flatten() {
            win.save(w);
        }
        if let Some(both) = &self.both {
            both.save(w);
        }
    }

    fn load(&mut self, r: &mut Reader<'_>) -> Result<(), SavedStateError> {
        self.untimed.load(r)?;
        for win in [&mut self.reach, &mut self.hold].into_iter().flatten() {
            win.load(r)?;
        }
        if let Some(both) = &mut self.both {
            both.load(r)?;
        }
        Ok(())
    }
}

impl UntilNode {
    fn save(&self, w: &mut Writer) {
        w.points(self.f.iter());
        w.points(self.g.iter());
        w.f64(self.decided);
        self.out.save(w);
    }

    fn load(&mut self, r: &mut Reader<'_>) -> Result<(), SavedStateError> {
        self.f = r.points("an until's left operand")?.into();
        self.g = r.points("an until's right operand")?.into();
        self.decided = r.value("an until's frontier")?;
        self.out = Dedup::load(r)?;
        Ok(())
    }
}

impl Op {
    /// The tag a saved state gives the operator.
    fn tag(&self) -> u64 {
        match self {
            Op::Expr => 0,
            Op::Cmp(_) => 1,
            Op::Constant(..) => 2,
            Op::Not(_) => 3,
            Op::Copy => 4,
            Op::Merge(_) => 5,
            Op::Win(_) => 6,
            Op::Since(_) => 7,
            Op::Bounded(_) => 8,
            Op::Until(_) => 9,
        }
    }

    fn save(&self, w: &mut Writer) {
        w.word(self.tag());
        match self {
            Op::Expr | Op::Copy => {}
            Op::Cmp(d) | Op::Constant(_, d) | Op::Not(d) => d.save(w),
            Op::Merge(m) => m.save(w),
            Op::Win(win) => win.save(w),
            Op::Since(s) => s.save(w),
            Op::Bounded(p) => {
                p.0.save(w);
                p.1.save(w);
            }
            Op::Until(u) => u.save(w),
        }
    }

    /// Loads into the operator built for the formula's node `i`.
    fn load(&mut self, r: &mut Reader<'_>, i: usize) -> Result<(), SavedStateError> {
        let tag = r.word("an operator")?;
        if tag != self.tag() {
            return Err(r.bad(&format!(
                "node {i}'s operator is of kind {tag}, and the formula's of kind {}",
                self.tag()
            )));
        }
        match self {
            Op::Expr | Op::Copy => {}
            Op::Cmp(d) | Op::Constant(_, d) | Op::Not(d) => *d = Dedup::load(r)?,
            Op::Merge(m) => m.load(r)?,
            Op::Win(win) => win.load(r)?,
            Op::Since(s) => s.load(r)?,
            Op::Bounded(p) => {
                let (a, b) = (p.1.a(), p.1.b());
                p.0 = Pieces::load(r)?;
                p.1 = BoundedUntil::load(r, a, b)?;
            }
            Op::Until(u) => u.load(r)?,
        }
        Ok(())
    }
}

/// The formula's fingerprint: a saved state is only read back by the formula that saved
/// it.
fn fingerprint(formula: &DenseFormula) -> u64 {
    saved::fnv(format!("{formula:?}").as_bytes()) // not a message: a fingerprint
}

impl DenseMonitor {
    /// The monitor's state as plain data: bytes that [`DenseMonitor::load`] reads back into
    /// a monitor that continues exactly where this one is (the same change points, bit for
    /// bit). They hold the last row, every operator's pieces and deques (a window's worth
    /// each), and the change points decided but not yet given.
    pub fn save(&self) -> Vec<u8> {
        let mut w = Writer::default();
        w.word(saved::MAGIC);
        w.word(saved::VERSION);
        w.word(fingerprint(&self.formula));
        w.count(self.vars);
        w.count(self.ops.len());
        w.f64(self.t0);
        w.f64(self.x);
        w.count(self.rows.len());
        w.opt_i128(self.rows.origin());
        w.opt_i128(self.rows.last_int());
        if !self.t0.is_nan() {
            let (_, columns) = self.rows.rows();
            for c in columns {
                w.f64(c.last().copied().unwrap_or(f64::NAN));
            }
        }
        for &f in &self.front {
            w.f64(f);
        }
        w.points(self.held.iter());
        for op in &self.ops {
            op.save(&mut w);
        }
        let sum = saved::fnv(&w.bytes);
        w.word(sum);
        w.bytes
    }

    /// The monitor [`DenseMonitor::save`] saved, for `formula` over `vars` variables (the
    /// same as the saved monitor's). The bytes end with a checksum, so bytes cut short or
    /// changed are refused; then every field is checked, so that bytes changed on purpose
    /// and summed again ([`resum`](super::resum)) are refused too when they are no state a
    /// monitor could have reached (from another formula, sizes beyond the bytes given,
    /// NaN, times that do not increase, indices out of range, deques and folds that are not
    /// those of their pieces); what no check can tell (one value changed for another) still
    /// never makes the monitor panic.
    pub fn load(
        formula: &DenseFormula,
        vars: usize,
        bytes: &[u8],
    ) -> Result<DenseMonitor, SavedStateError> {
        let mut m = DenseMonitor::new(formula, vars)
            .map_err(|e| SavedStateError { message: e.to_string() })?;
        if bytes.get(..8).is_none_or(|w| w != saved::MAGIC.to_le_bytes()) {
            return Err(SavedStateError {
                message: "the bytes are no saved dense-time monitor (they do not start with \
                          `hstldns1`)"
                    .to_string(),
            });
        }
        let body = bytes.len().saturating_sub(8);
        if bytes.len() < 16
            || !bytes.len().is_multiple_of(8)
            || saved::sum_of(bytes) != saved::fnv(&bytes[..body])
        {
            return Err(SavedStateError {
                message: format!(
                    "the state's checksum does not match its {} bytes: they were cut short or \
                     changed",
                    bytes.len()
                ),
            });
        }
        let mut r = Reader::new(&bytes[..body]);
        r.word("the header")?;
        let version = r.word("the version")?;
        if version != saved::VERSION {
            return Err(r.bad(&format!(
                "the state is of version {version}, and this monitor reads version {}",
                saved::VERSION
            )));
        }
        if r.word("the formula's fingerprint")? != fingerprint(formula) {
            return Err(r.bad("the state was saved by a monitor of another formula"));
        }
        let saved_vars = r.word("the variable count")?;
        let nodes = r.word("the node count")?;
        if saved_vars != vars as u64 || nodes != m.ops.len() as u64 {
            return Err(r.bad(&format!(
                "the state is for {saved_vars} variables and {nodes} nodes, and the monitor \
                 has {vars} and {}",
                m.ops.len()
            )));
        }
        let t0 = r.f64("the first stamp")?;
        let x = r.f64("the last stamp")?;
        let rows = r.index(usize::MAX >> 2, "the row count")?;
        let origin = r.opt_i128("the first whole-number stamp")?;
        let last_int = r.opt_i128("the last whole-number stamp")?;
        if t0.is_nan() && x.is_nan() {
            if rows != 0 || origin.is_some() || last_int.is_some() {
                return Err(r.bad("the state has rows but no first stamp"));
            }
        } else {
            if !(t0.is_finite() && x.is_finite() && t0 <= x && rows >= 1) {
                return Err(r.bad(&format!(
                    "the first stamp {t0} and the last {x} are not finite stamps in order"
                )));
            }
            match (origin, last_int) {
                (None, None) => {}
                (Some(o), Some(l)) => {
                    // Whole-number stamps: the first is 0 from the origin, the last exactly
                    // `l - o` after it.
                    let exact = l >= o && trace::relative(0, l, o).is_ok_and(|t| t == x);
                    if t0 != 0.0 || !exact || (rows == 1 && l != o) {
                        return Err(r.bad(&format!(
                            "the whole-number stamps {o} (first) and {l} (last) do not give \
                             the times {t0} and {x}"
                        )));
                    }
                }
                _ => return Err(r.bad("the state has a first whole-number stamp without a last")),
            }
            if rows == 1 && t0 != x {
                return Err(r.bad("one row, but its first and last stamps differ"));
            }
            let mut values = Vec::with_capacity(vars);
            for _ in 0..vars {
                values.push(r.value("the last row's values")?);
            }
            m.rows = DenseTraceBuilder::resumed(rows, x, &values, origin, last_int);
        }
        m.t0 = t0;
        m.x = x;
        for f in &mut m.front {
            *f = r.value("an operator's frontier")?;
        }
        let held = r.points("the decided change points")?;
        if held.first().is_some_and(|&(t, _)| t <= x || x.is_nan()) {
            return Err(r.bad("a decided change point comes no later than the last stamp"));
        }
        m.held = held.into();
        for (i, op) in m.ops.iter_mut().enumerate() {
            op.load(&mut r, i)?;
        }
        r.finish()?;
        Ok(m)
    }
}
