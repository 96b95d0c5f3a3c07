//! Streaming evaluation of bounded formulas: one node per operator, each turning its
//! operands' final values into its own as soon as they are determined.
//!
//! A node with horizon `h` emits `rho(t)` when state `t + h` arrives, so every node emits
//! exactly one value per state once warmed up, and keeps `O(h)` values. Windows use
//! monotonic deques; bounded until uses the block decomposition of the offline evaluator,
//! run forwards. Values equal the offline evaluator's exactly (same min/max selections,
//! same NaN policy). Only windows clipped by the end of the trace are left out: the
//! monitor evaluates those offline at `finish`.

use crate::offline::{Lattice, Max, Min};
use crate::{Bound, Formula, Interval};
use std::collections::VecDeque;

const INF: f64 = f64::INFINITY;
const NEG_INF: f64 = f64::NEG_INFINITY;

/// One operator of the formula with the final values it has produced and not yet handed on.
#[derive(Clone, Debug)]
pub(crate) struct Node {
    kind: Kind,
    /// Final values for consecutive steps, oldest first.
    out: VecDeque<f64>,
}

#[derive(Clone, Debug)]
enum Kind {
    /// A formula without temporal operators, evaluated on each state.
    State(Formula),
    Not(Box<Node>),
    Fold {
        max: bool,
        kids: Vec<Node>,
    },
    Implies(Box<Node>, Box<Node>),
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
    kid: Node,
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
    f: Node,
    g: Node,
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

impl Node {
    /// The node tree of a formula with a finite horizon; `None` for an unbounded one.
    pub(crate) fn build(f: &Formula) -> Option<Node> {
        f.horizon()?;
        Some(Node::new(f))
    }

    fn new(f: &Formula) -> Node {
        let kind = if f.is_state_formula() {
            Kind::State(f.clone())
        } else {
            match f {
                Formula::Not(g) => Kind::Not(Box::new(Node::new(g))),
                Formula::And(gs) => {
                    Kind::Fold { max: false, kids: gs.iter().map(Node::new).collect() }
                }
                Formula::Or(gs) => {
                    Kind::Fold { max: true, kids: gs.iter().map(Node::new).collect() }
                }
                Formula::Implies(g, h) => {
                    Kind::Implies(Box::new(Node::new(g)), Box::new(Node::new(h)))
                }
                Formula::Always(i, g) | Formula::Eventually(i, g) => {
                    Kind::Window(Box::new(Window {
                        max: matches!(f, Formula::Eventually(..)),
                        a: i.start,
                        last: last(i),
                        end: end(i),
                        kid: Node::new(g),
                        seen: 0,
                        deque: VecDeque::new(),
                    }))
                }
                Formula::Until(i, g, h) => Kind::Until(Box::new(Until {
                    a: i.start,
                    last: last(i),
                    end: end(i),
                    f: Node::new(g),
                    g: Node::new(h),
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
                // State formulas took the branch above.
                Formula::True | Formula::False | Formula::Cmp { .. } => Kind::State(f.clone()),
            }
        };
        Node { kind, out: VecDeque::new() }
    }

    /// Takes the oldest final value not yet handed on.
    pub(crate) fn pop(&mut self) -> Option<f64> {
        self.out.pop_front()
    }

    /// Feeds one state to the tree and lets every node emit what became final.
    pub(crate) fn push(&mut self, row: &[f64]) {
        match &mut self.kind {
            Kind::State(f) => self.out.push_back(state_value(f, row)),
            Kind::Not(g) => {
                g.push(row);
                while let Some(v) = g.pop() {
                    self.out.push_back(-v);
                }
            }
            Kind::Fold { max, kids } => {
                kids.iter_mut().for_each(|k| k.push(row));
                // Operands with shorter horizons run ahead; a step is final once all have it.
                while kids.iter().all(|k| !k.out.is_empty()) {
                    let id = if *max { NEG_INF } else { INF };
                    let mut acc = id;
                    for k in kids.iter_mut() {
                        let v = k.pop().unwrap_or(id);
                        acc = if *max { Max::acc(acc, v) } else { Min::acc(acc, v) };
                    }
                    self.out.push_back(acc);
                    if kids.is_empty() {
                        break;
                    }
                }
            }
            Kind::Implies(g, h) => {
                g.push(row);
                h.push(row);
                while !g.out.is_empty() && !h.out.is_empty() {
                    let (a, b) = (g.pop().unwrap_or(NEG_INF), h.pop().unwrap_or(NEG_INF));
                    self.out.push_back((-a).max(b));
                }
            }
            Kind::Window(w) => {
                w.kid.push(row);
                while let Some(v) = w.kid.pop() {
                    if let Some(r) = w.take(v) {
                        self.out.push_back(r);
                    }
                }
            }
            Kind::Until(u) => {
                u.f.push(row);
                u.g.push(row);
                while !u.f.out.is_empty() && !u.g.out.is_empty() {
                    let (f, g) = (u.f.pop().unwrap_or(NEG_INF), u.g.pop().unwrap_or(NEG_INF));
                    if let Some(r) = u.take(f, g) {
                        self.out.push_back(r);
                    }
                }
            }
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

/// `rho(f)` of a state formula on one state, as the reference evaluator computes it.
fn state_value(f: &Formula, row: &[f64]) -> f64 {
    match f {
        Formula::True => INF,
        Formula::False => NEG_INF,
        Formula::Cmp { lhs, op, rhs } => op.robustness(lhs.eval(row), rhs.eval(row)),
        Formula::Not(g) => -state_value(g, row),
        Formula::And(gs) => gs.iter().map(|g| state_value(g, row)).fold(INF, f64::min),
        Formula::Or(gs) => gs.iter().map(|g| state_value(g, row)).fold(NEG_INF, f64::max),
        Formula::Implies(g, h) => (-state_value(g, row)).max(state_value(h, row)),
        // Temporal operators never reach here: `Node::new` sends state formulas only.
        Formula::Always(..) | Formula::Eventually(..) | Formula::Until(..) => f64::NAN,
    }
}
