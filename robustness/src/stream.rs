//! Streaming evaluation of bounded formulas: one stream per formula node, each turning
//! its operands' final values into its own as soon as they are determined.
//!
//! A node with horizon `h` emits `rho(t)` when state `t + h` arrives, so every node emits
//! exactly one value per state once warmed up. Each node keeps its recent values for the
//! parents that read them later (at most the difference of their horizons), and a window
//! or until keeps `O(h)` values. Windows use monotonic deques; bounded until uses the
//! block decomposition of the offline evaluator, run forwards. Values equal the offline
//! evaluator's (same min/max selections, same NaN policy). Only windows clipped by the end
//! of the trace are left out: the monitor evaluates those offline at `finish`. The nodes
//! are walked in order on every push: nothing recurses, and a shared node is computed once.

use crate::formula::{Node, expr_value};
use crate::offline::{Lattice, Max, Min};
use crate::{Bound, Formula, Interval};
use std::collections::VecDeque;

const INF: f64 = f64::INFINITY;
const NEG_INF: f64 = f64::NEG_INFINITY;

/// The streams of every node of one bounded formula.
#[derive(Clone, Debug)]
pub(crate) struct Stream {
    nodes: Vec<Slot>,
    /// Each node's value on the current state (state nodes only).
    vals: Vec<f64>,
    /// States pushed so far.
    pushed: usize,
    root: usize,
}

/// One node's stream.
#[derive(Clone, Debug)]
struct Slot {
    kind: Kind,
    /// Final values for consecutive steps, the oldest (step `base`) first.
    hist: VecDeque<f64>,
    base: usize,
    /// How many values to keep for the readers that lag behind.
    keep: usize,
    /// At push `j` the node reads its operands at step `j - lag` (the largest operand
    /// horizon).
    lag: usize,
}

#[derive(Clone, Debug)]
enum Kind {
    /// An expression, or a state formula no temporal node reads: nothing streamed.
    Skip,
    /// A state formula a temporal node reads: its value on each state.
    State,
    Not,
    Fold,
    Implies,
    Window(Box<Window>),
    Until(Box<Until>),
}

/// `always` (min) or `eventually` (max) over `[t + a, t + last]`.
#[derive(Clone, Debug)]
struct Window {
    max: bool,
    a: usize,
    /// `None` when the interval is empty.
    last: Option<usize>,
    /// The node emits step `t` when its operand's step `t + end` arrives.
    end: usize,
    /// Operand values received so far.
    seen: usize,
    /// Monotonic deque of `(step, value)`: the front is the window's min (or max).
    deque: VecDeque<(usize, f64)>,
}

/// `f until[a..=last] g`, see `offline::block_until` for the decomposition.
#[derive(Clone, Debug)]
struct Until {
    a: usize,
    last: Option<usize>,
    end: usize,
    seen: usize,
    /// Step of the front of `fv`, `gv`, `su`, `sf` and `p`.
    base: usize,
    fv: VecDeque<f64>,
    /// `g` with NaN read as `+inf` (the `lhs` part alone then decides).
    gv: VecDeque<f64>,
    su: VecDeque<f64>,
    sf: VecDeque<f64>,
    p: VecDeque<f64>,
    pf: f64,
    pu: f64,
    /// Monotonic min deque over `f` for `min f[t..t+a)`, and the next step to enter it.
    a_deque: VecDeque<(usize, f64)>,
    a_next: usize,
}

impl Stream {
    /// The streams of a formula with a finite horizon; `None` for an unbounded one.
    pub(crate) fn build(f: &Formula) -> Option<Stream> {
        f.horizon()?;
        let nodes = f.nodes();
        let h = |k: usize| f.horizon_of(crate::NodeId::from_index(k)).unwrap_or(0);
        let root = f.root().index();
        let mut slots: Vec<Slot> = nodes
            .iter()
            .enumerate()
            .map(|(v, node)| {
                let state = f.is_state(crate::NodeId::from_index(v)) && !node.is_expr();
                let lag = node.children().map(h).max().unwrap_or(0);
                let kind = match node {
                    _ if state => Kind::Skip,
                    Node::Not(_) => Kind::Not,
                    Node::And(_) | Node::Or(_) => Kind::Fold,
                    Node::Implies(..) => Kind::Implies,
                    Node::Always(i, _) | Node::Eventually(i, _) => Kind::Window(Box::new(Window {
                        max: matches!(node, Node::Eventually(..)),
                        a: i.start,
                        last: last(i),
                        end: end(i),
                        seen: 0,
                        deque: VecDeque::new(),
                    })),
                    Node::Until(i, ..) => Kind::Until(Box::new(Until {
                        a: i.start,
                        last: last(i),
                        end: end(i),
                        seen: 0,
                        base: 0,
                        fv: VecDeque::new(),
                        gv: VecDeque::new(),
                        su: VecDeque::new(),
                        sf: VecDeque::new(),
                        p: VecDeque::new(),
                        pf: INF,
                        pu: NEG_INF,
                        a_deque: VecDeque::new(),
                        a_next: 0,
                    })),
                    _ => Kind::Skip,
                };
                Slot { kind, hist: VecDeque::new(), base: 0, keep: 1, lag }
            })
            .collect();
        // A state node read by a temporal node (or the root) streams its values; every
        // node keeps what its slowest reader still needs.
        for (v, node) in nodes.iter().enumerate() {
            let temporal = !matches!(slots[v].kind, Kind::Skip | Kind::State);
            if !temporal {
                continue;
            }
            for c in node.children() {
                if matches!(slots[c].kind, Kind::Skip) {
                    slots[c].kind = Kind::State;
                }
                let keep = slots[v].lag - h(c) + 1;
                slots[c].keep = slots[c].keep.max(keep);
            }
        }
        if matches!(slots[root].kind, Kind::Skip) {
            slots[root].kind = Kind::State;
        }
        Some(Stream { nodes: slots, vals: vec![f64::NAN; nodes.len()], pushed: 0, root })
    }

    /// Feeds one state; returns the root's value that became final, if any.
    pub(crate) fn push(&mut self, f: &Formula, row: &[f64]) -> Option<f64> {
        let j = self.pushed;
        self.pushed += 1;
        let nodes = f.nodes();
        for (v, node) in nodes.iter().enumerate() {
            let x = match &self.nodes[v].kind {
                Kind::Skip | Kind::State => {
                    let x = state_value(node, &self.vals, row);
                    self.vals[v] = x;
                    if matches!(self.nodes[v].kind, Kind::Skip) {
                        continue;
                    }
                    Some(x)
                }
                _ => {
                    let lag = self.nodes[v].lag;
                    let Some(s) = j.checked_sub(lag) else { continue };
                    self.temporal(node, v, s)
                }
            };
            if let Some(x) = x {
                let slot = &mut self.nodes[v];
                slot.hist.push_back(x);
                if slot.hist.len() > slot.keep {
                    slot.hist.pop_front();
                    slot.base += 1;
                }
            }
        }
        let root = &self.nodes[self.root];
        let h = f.horizon().unwrap_or(0);
        // The root emits step `j - h` at push `j`.
        j.checked_sub(h).and_then(|t| root.hist.get(t.wrapping_sub(root.base)).copied())
    }

    /// Node `c`'s final value at step `s`.
    fn at(&self, c: usize, s: usize) -> f64 {
        let slot = &self.nodes[c];
        slot.hist.get(s.wrapping_sub(slot.base)).copied().unwrap_or(f64::NAN)
    }

    /// Temporal node `v` takes its operands at step `s`; returns its next value if final.
    fn temporal(&mut self, node: &Node, v: usize, s: usize) -> Option<f64> {
        match node {
            Node::Not(g) => Some(-self.at(g.index(), s)),
            Node::And(gs) | Node::Or(gs) => {
                let max = matches!(node, Node::Or(_));
                let mut acc = if max { NEG_INF } else { INF };
                for g in gs {
                    let x = self.at(g.index(), s);
                    acc = if max { Max::acc(acc, x) } else { Min::acc(acc, x) };
                }
                Some(acc)
            }
            Node::Implies(g, h) => Some((-self.at(g.index(), s)).max(self.at(h.index(), s))),
            Node::Always(_, g) | Node::Eventually(_, g) => {
                let x = self.at(g.index(), s);
                match &mut self.nodes[v].kind {
                    Kind::Window(w) => w.take(x),
                    _ => None,
                }
            }
            Node::Until(_, g, h) => {
                let (x, y) = (self.at(g.index(), s), self.at(h.index(), s));
                match &mut self.nodes[v].kind {
                    Kind::Until(u) => u.take(x, y),
                    _ => None,
                }
            }
            _ => None,
        }
    }
}

impl Window {
    /// Takes the operand's next value; returns this node's next value once final.
    fn take(&mut self, v: f64) -> Option<f64> {
        let j = self.seen;
        self.seen += 1;
        let id = if self.max { NEG_INF } else { INF };
        if self.last.is_some() && !v.is_nan() {
            // A newer value at least as good makes older ones useless: they leave sooner.
            while let Some(&(_, b)) = self.deque.back() {
                if (self.max && b <= v) || (!self.max && b >= v) {
                    self.deque.pop_back();
                } else {
                    break;
                }
            }
            self.deque.push_back((j, v));
        }
        let t = j.checked_sub(self.end)?;
        if self.last.is_none() {
            return Some(id);
        }
        let first = t.saturating_add(self.a);
        while self.deque.front().is_some_and(|&(k, _)| k < first) {
            self.deque.pop_front();
        }
        Some(self.deque.front().map_or(id, |&(_, v)| v))
    }
}

impl Until {
    /// Takes the operands' next values; returns this node's next value once final.
    fn take(&mut self, f: f64, g: f64) -> Option<f64> {
        let j = self.seen;
        self.seen += 1;
        let Some(last) = self.last else {
            return j.checked_sub(self.end).map(|_| NEG_INF);
        };
        let span = last - self.a;
        let len = span.saturating_add(1);
        let g = Min::acc(INF, g);
        self.fv.push_back(f);
        self.gv.push_back(g);
        // Forwards through the current block: the until over its prefix.
        if j.is_multiple_of(len) {
            self.pf = INF;
            self.pu = NEG_INF;
        }
        self.pu = Max::acc(self.pu, Min::acc(g, self.pf));
        self.p.push_back(self.pu);
        self.pf = Min::acc(self.pf, f);
        self.su.push_back(NEG_INF);
        self.sf.push_back(INF);
        // A block just completed: the until over each of its suffixes, backwards.
        if j % len == len - 1 {
            let (mut sua, mut sfa) = (NEG_INF, INF);
            for k in (j + 1 - len..=j).rev() {
                let i = k - self.base;
                sua = Max::acc(Min::acc(sua, self.fv[i]), self.gv[i]);
                self.su[i] = sua;
                sfa = Min::acc(sfa, self.fv[i]);
                self.sf[i] = sfa;
            }
        }
        let t = j.checked_sub(self.end)?;
        let s = t + self.a;
        // min f[t..t+a): the deque takes f up to t + a - 1, and drops steps before t.
        let mut head = INF;
        if self.a > 0 {
            while self.a_next < s {
                let v = self.fv[self.a_next - self.base];
                if !v.is_nan() {
                    while self.a_deque.back().is_some_and(|&(_, b)| b >= v) {
                        self.a_deque.pop_back();
                    }
                    self.a_deque.push_back((self.a_next, v));
                }
                self.a_next += 1;
            }
            while self.a_deque.front().is_some_and(|&(k, _)| k < t) {
                self.a_deque.pop_front();
            }
            head = self.a_deque.front().map_or(INF, |&(_, v)| v);
        }
        let i = s - self.base;
        let tail = if s.is_multiple_of(len) {
            self.su[i]
        } else {
            Max::acc(self.su[i], Min::acc(self.sf[i], self.p[j - self.base]))
        };
        // Steps before `t + 1` are never read again: the next output starts there, and
        // blocks still to complete start after it.
        while self.base <= t {
            self.fv.pop_front();
            self.gv.pop_front();
            self.su.pop_front();
            self.sf.pop_front();
            self.p.pop_front();
            self.base += 1;
        }
        Some(Min::acc(head, tail))
    }
}

/// The last offset of a non-empty interval, `None` when empty.
fn last(i: &Interval) -> Option<usize> {
    if i.is_empty() { None } else { i.last_offset() }
}

/// The offset whose arrival makes a step final: the interval's contribution to the horizon.
fn end(i: &Interval) -> usize {
    match i.end {
        Bound::Unbounded => usize::MAX,
        Bound::Exclusive(b) => b.saturating_sub(1),
        Bound::Inclusive(b) => b,
    }
}

/// `rho` of state node `node` on one state, given the values of earlier nodes on it, as
/// the reference evaluator computes it.
fn state_value(node: &Node, vals: &[f64], row: &[f64]) -> f64 {
    let v = |k: &crate::NodeId| vals[k.index()];
    match node {
        Node::True => INF,
        Node::False => NEG_INF,
        Node::Cmp { lhs, op, rhs } => op.robustness(vals[lhs.index()], vals[rhs.index()]),
        Node::Not(g) => -v(g),
        Node::And(gs) => gs.iter().map(v).fold(INF, f64::min),
        Node::Or(gs) => gs.iter().map(v).fold(NEG_INF, f64::max),
        Node::Implies(g, h) => (-v(g)).max(v(h)),
        _ => expr_value(node, vals, row),
    }
}
