//! The streaming operators of the online dense-time monitor, one a kind of node: each
//! takes its operands' new change points and frontiers and gives its own (see the module
//! docs of [`super`]).

use super::super::offline::{self, Dir, Ext, max, min};
use super::super::until::{BoundedUntil, Pieces};
use super::super::{DenseFormula, DenseSignal};
use crate::formula::Node;
use std::collections::VecDeque;

/// `x` lowered by a relative margin of a few ulps (and a tiny absolute one), so a frontier
/// computed in rounded arithmetic stays on the safe side.
pub(super) fn down(x: f64, scale: f64) -> f64 {
    x - (x.abs() + scale) * f64::EPSILON * 16.0 - f64::MIN_POSITIVE
}

pub(super) const INF: f64 = f64::INFINITY;

/// Drops a change point that repeats the last value, as [`DenseSignal`] does.
#[derive(Clone, Debug, Default)]
pub(super) struct Dedup {
    pub(super) last: Option<f64>,
}

impl Dedup {
    #[inline]
    pub(super) fn push(&mut self, out: &mut Vec<(f64, f64)>, t: f64, v: f64) {
        if self.last != Some(v) {
            out.push((t, v));
            self.last = Some(v);
        }
    }
}

/// How a merge combines its operands' values.
#[derive(Clone, Copy, Debug)]
pub(super) enum Fold {
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
pub(super) struct Merge {
    pub(super) fold: Fold,
    pub(super) queues: Vec<VecDeque<(f64, f64)>>,
    pub(super) cur: Vec<f64>,
    /// `since`'s running value.
    pub(super) acc: f64,
    pub(super) out: Dedup,
}

impl Merge {
    pub(super) fn new(fold: Fold, n: usize) -> Merge {
        Merge {
            fold,
            queues: vec![VecDeque::new(); n],
            cur: vec![0.0; n],
            acc: f64::NEG_INFINITY,
            out: Dedup::default(),
        }
    }

    pub(super) fn feed(&mut self, k: usize, points: &[(f64, f64)]) {
        self.queues[k].extend(points.iter().copied());
    }

    pub(super) fn kept(&self) -> usize {
        self.queues.iter().map(VecDeque::len).sum()
    }

    /// Every union time before `frontier` (the least of the operands' frontiers: each
    /// operand's points before it have all been fed).
    pub(super) fn advance(&mut self, frontier: f64, out: &mut Vec<(f64, f64)>) {
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
pub(super) struct Win {
    pub(super) dir: Dir,
    pub(super) a: f64,
    pub(super) b: f64,
    pub(super) ext: Ext,
    /// Whether pieces ever leave the window (not for an unbounded past window).
    pub(super) ends: bool,
    /// The pieces from `base` on: their start times and values.
    pub(super) times: VecDeque<f64>,
    pub(super) vals: VecDeque<f64>,
    pub(super) base: usize,
    /// The next piece to enter and the next to leave (absolute indices).
    pub(super) i: usize,
    pub(super) j: usize,
    pub(super) dq: VecDeque<(usize, f64)>,
    /// The last event swept, if any.
    pub(super) swept: Option<f64>,
    pub(super) out: Dedup,
}

impl Win {
    pub(super) fn new(dir: Dir, a: f64, b: f64, ext: Ext) -> Win {
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

    pub(super) fn feed(&mut self, points: &[(f64, f64)]) {
        for &(t, v) in points {
            self.times.push_back(t);
            self.vals.push_back(v);
        }
    }

    pub(super) fn kept(&self) -> usize {
        self.times.len() + self.dq.len()
    }

    pub(super) fn received(&self) -> usize {
        self.base + self.times.len()
    }

    /// When piece `k` starts meeting the window (as offline computes it).
    #[inline]
    pub(super) fn start(&self, k: usize) -> f64 {
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
    pub(super) fn end(&self, k: usize, done: bool) -> Option<f64> {
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
    pub(super) fn advance(&mut self, t0: f64, operand: f64, out: &mut Vec<(f64, f64)>) -> f64 {
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
pub(super) struct SinceNode {
    pub(super) b: f64,
    pub(super) untimed: Merge,
    /// `once[a..=b] g`, `historically[0..=a] (f since g)` (for `a > 0`) and their `&&`;
    /// none for `[0..]`.
    pub(super) reach: Option<Win>,
    pub(super) hold: Option<Win>,
    pub(super) both: Option<Merge>,
}

impl SinceNode {
    pub(super) fn new(a: f64, b: f64) -> SinceNode {
        let untimed = a == 0.0 && b == INF;
        SinceNode {
            b,
            untimed: Merge::new(Fold::Since, 2),
            reach: (!untimed).then(|| Win::new(Dir::Past, a, b, Ext::Max)),
            hold: (a != 0.0).then(|| Win::new(Dir::Past, 0.0, a, Ext::Min)),
            both: (!untimed).then(|| Merge::new(Fold::Min, 2)),
        }
    }

    pub(super) fn kept(&self) -> usize {
        self.untimed.kept()
            + self.reach.as_ref().map_or(0, Win::kept)
            + self.hold.as_ref().map_or(0, Win::kept)
            + self.both.as_ref().map_or(0, Merge::kept)
    }

    pub(super) fn advance(
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
pub(super) struct UntilNode {
    pub(super) a: f64,
    pub(super) b: f64,
    pub(super) f: VecDeque<(f64, f64)>,
    pub(super) g: VecDeque<(f64, f64)>,
    /// The node's frontier; `-inf` before the first step.
    pub(super) decided: f64,
    pub(super) out: Dedup,
}

impl UntilNode {
    pub(super) fn kept(&self) -> usize {
        self.f.len() + self.g.len()
    }

    pub(super) fn advance(
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
pub(super) enum Op {
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
    pub(super) fn kept(&self) -> usize {
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

pub(super) fn ops(df: &DenseFormula) -> Vec<Op> {
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
