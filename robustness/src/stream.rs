//! Streaming evaluation of bounded formulas: one stream per formula node, each turning
//! its operands' final values into its own as soon as they are determined.
//!
//! A node with horizon `h` emits `rho(t)` when state `t + h` arrives, so every node emits
//! exactly one value per state once warmed up. Each node keeps its recent values for the
//! parents that read them later (at most the difference of their horizons), and a window
//! or until keeps `O(h)` values. Windows use monotonic deques; bounded until uses the
//! block decomposition of the offline evaluator, run forwards. Past-time operators look
//! back, the direction the states arrive in: `once` and `historically` keep a monotonic
//! deque over their past window (and the last `a` values, not yet in it), `since` a
//! forward recurrence over blocks of its window's length (the mirror image of until's
//! decomposition), so each keeps `O(b)` values for an interval `[a..b]`. Values equal the
//! offline evaluator's (same min/max selections, same NaN policy). Windows clipped by the
//! end of the trace are computed at [`Stream::finish`] (or, for a formula without past-time
//! operators, offline by the monitor). The nodes are walked in order on every push: nothing
//! recurses, and a shared node is computed once.

use crate::formula::{Node, expr_value};
use crate::primitives::{Lattice, Max, Min};
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
    PastWindow(Box<PastWindow>),
    Since(Box<Since>),
}

/// `once` (max) or `historically` (min) over the past window `[t - last, t - a]`, clipped
/// at step 0 (`prev` is `historically[1..=1]`).
#[derive(Clone, Debug)]
struct PastWindow {
    max: bool,
    a: usize,
    /// The farthest offset back; `None` when the window runs back to step 0.
    last: Option<usize>,
    /// No step is ever in the window (`[3..3]`).
    empty: bool,
    /// Operand values received so far.
    seen: usize,
    /// The last `a` operand values, not in any window yet.
    delay: VecDeque<f64>,
    /// Monotonic deque of `(step, value)` (bounded window): the front is the extremum.
    deque: VecDeque<(usize, f64)>,
    /// The fold of every value that entered (unbounded window).
    acc: f64,
}

/// `f since[a..=last] g`: `min(min f over (t - a, t], S(t - a))`, where `S(e)` is
/// `since[0..=span]` at `e` (`span = last - a`). Cut the steps into blocks of `span + 1`:
/// the witnesses of `e` are a prefix of its block (a forward recurrence, `p`) and a suffix
/// of the block before (`q`, computed backwards once that block is complete), the latter
/// bounded by the minimum of `f` over `e`'s block up to `e` (`pf`).
#[derive(Clone, Debug)]
struct Since {
    a: usize,
    /// `last - a`; `None` when unbounded (back to step 0).
    span: Option<usize>,
    empty: bool,
    seen: usize,
    /// The last `a` pairs `(f, g)`, not witnesses yet (NaN read as `+inf`).
    delay: VecDeque<(f64, f64)>,
    /// Monotonic min deque over the last `a` values of `f`, with their steps.
    head: VecDeque<(usize, f64)>,
    /// Witness steps (`e`) taken so far.
    witnesses: usize,
    /// The recurrence over the current block's prefix (or the whole past, unbounded).
    p: f64,
    pf: f64,
    /// The current block's pairs, for `q` once it is complete.
    block: Vec<(f64, f64)>,
    /// `q[j]`: since over steps `j ..` of the previous block, to its end.
    q: Vec<f64>,
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
    interval: Interval,
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
                    Node::Always(i, _) | Node::Eventually(i, _) => {
                        Kind::Window(Box::new(Window::new(matches!(node, Node::Eventually(..)), i)))
                    }
                    Node::Once(i, _) | Node::Historically(i, _) => Kind::PastWindow(Box::new(
                        PastWindow::new(matches!(node, Node::Once(..)), i),
                    )),
                    Node::Prev(_) => Kind::PastWindow(Box::new(PastWindow::new(
                        false,
                        &Interval { start: 1, end: Bound::Inclusive(1) },
                    ))),
                    Node::Next(_) => Kind::Window(Box::new(Window {
                        max: false,
                        a: 1,
                        last: Some(1),
                        end: 1,
                        seen: 0,
                        deque: VecDeque::new(),
                    })),
                    Node::Since(i, ..) => Kind::Since(Box::new(Since::new(i))),
                    Node::Until(i, ..) => Kind::Until(Box::new(Until {
                        interval: *i,
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
            Node::Once(_, g) | Node::Historically(_, g) | Node::Prev(g) | Node::Next(g) => {
                let x = self.at(g.index(), s);
                match &mut self.nodes[v].kind {
                    Kind::PastWindow(w) => Some(w.take(x)),
                    Kind::Window(w) => w.take(x),
                    _ => None,
                }
            }
            Node::Since(_, g, h) => {
                let (x, y) = (self.at(g.index(), s), self.at(h.index(), s));
                match &mut self.nodes[v].kind {
                    Kind::Since(u) => Some(u.take(x, y)),
                    _ => None,
                }
            }
            _ => None,
        }
    }

    /// Ends the trace: the root's values at the steps that had none yet, windows clipped
    /// at the end of the trace. Each node in turn takes its operands' remaining values and
    /// then gives its own clipped ones, so every node ends with values up to the last step.
    /// The stream is spent afterwards.
    pub(crate) fn finish(&mut self, f: &Formula) -> Vec<f64> {
        let n = self.pushed;
        let nodes = f.nodes();
        let h = f.horizon().unwrap_or(0);
        // The root's steps without a verdict.
        let first = n.saturating_sub(h);
        for slot in &mut self.nodes {
            slot.keep = usize::MAX;
        }
        for (v, node) in nodes.iter().enumerate() {
            if matches!(self.nodes[v].kind, Kind::Skip | Kind::State) {
                continue;
            }
            // Operand steps read so far: one per push from push `lag` on.
            let lag = self.nodes[v].lag;
            for s in n.saturating_sub(lag)..n {
                if let Some(x) = self.temporal(node, v, s) {
                    self.nodes[v].hist.push_back(x);
                }
            }
            let slot = &mut self.nodes[v];
            let tail = match &mut slot.kind {
                Kind::Window(w) => w.finish(n),
                Kind::Until(u) => u.finish(),
                _ => Vec::new(),
            };
            slot.hist.extend(tail);
        }
        let root = &self.nodes[self.root];
        (first..n)
            .map(|t| root.hist.get(t.wrapping_sub(root.base)).copied().unwrap_or(f64::NAN))
            .collect()
    }
}

impl PastWindow {
    fn new(max: bool, i: &Interval) -> PastWindow {
        PastWindow {
            max,
            a: i.start,
            last: i.last_offset(),
            empty: i.is_empty(),
            seen: 0,
            delay: VecDeque::new(),
            deque: VecDeque::new(),
            acc: if max { NEG_INF } else { INF },
        }
    }

    /// Takes the operand's value at the next step `t`; returns this node's value at `t`.
    fn take(&mut self, v: f64) -> f64 {
        let t = self.seen;
        self.seen += 1;
        let id = if self.max { NEG_INF } else { INF };
        if self.empty {
            return id;
        }
        self.delay.push_back(v);
        // The value `a` steps back enters the window now.
        if self.delay.len() > self.a
            && let Some(x) = self.delay.pop_front()
        {
            let k = t - self.a;
            if self.last.is_none() {
                self.acc = if self.max { Max::acc(self.acc, x) } else { Min::acc(self.acc, x) };
            } else if !x.is_nan() {
                while let Some(&(_, b)) = self.deque.back() {
                    if (self.max && b <= x) || (!self.max && b >= x) {
                        self.deque.pop_back();
                    } else {
                        break;
                    }
                }
                self.deque.push_back((k, x));
            }
        }
        let Some(last) = self.last else { return self.acc };
        if t < self.a {
            return id;
        }
        let first = t.saturating_sub(last);
        while self.deque.front().is_some_and(|&(k, _)| k < first) {
            self.deque.pop_front();
        }
        self.deque.front().map_or(id, |&(_, v)| v)
    }
}

impl Since {
    fn new(i: &Interval) -> Since {
        Since {
            a: i.start,
            span: i.last_offset().map(|l| l.saturating_sub(i.start)),
            empty: i.is_empty(),
            seen: 0,
            delay: VecDeque::new(),
            head: VecDeque::new(),
            witnesses: 0,
            p: NEG_INF,
            pf: INF,
            block: Vec::new(),
            q: Vec::new(),
        }
    }

    /// Takes the operands' values at the next step `t`; returns this node's value at `t`.
    fn take(&mut self, f: f64, g: f64) -> f64 {
        let t = self.seen;
        self.seen += 1;
        if self.empty {
            return NEG_INF;
        }
        // NaN reads as `+inf` on both sides, as the min folds of the reference skip it.
        let (f, g) = (Min::acc(INF, f), Min::acc(INF, g));
        // min f over (t - a, t]: the steps after the latest witness.
        if self.a > 0 {
            while self.head.back().is_some_and(|&(_, b)| b >= f) {
                self.head.pop_back();
            }
            self.head.push_back((t, f));
            while self.head.front().is_some_and(|&(k, _)| k.saturating_add(self.a) <= t) {
                self.head.pop_front();
            }
        }
        self.delay.push_back((f, g));
        if self.delay.len() <= self.a {
            return NEG_INF;
        }
        let Some((fe, ge)) = self.delay.pop_front() else { return NEG_INF };
        let head = self.head.front().map_or(INF, |&(_, v)| v);
        let s = self.witness(fe, ge);
        Min::acc(head, s)
    }

    /// `S(e)` for the next witness step `e`, given `f` and `g` at `e`.
    fn witness(&mut self, f: f64, g: f64) -> f64 {
        let e = self.witnesses;
        self.witnesses += 1;
        let Some(span) = self.span else {
            // Untimed: out(e) = max(g(e), min(f(e), out(e - 1))).
            self.p = Max::acc(g, Min::acc(f, self.p));
            return self.p;
        };
        let len = span.saturating_add(1);
        let j = e % len;
        if j == 0 {
            self.p = NEG_INF;
            self.pf = INF;
            self.block.clear();
        }
        self.p = Max::acc(g, Min::acc(f, self.p));
        self.pf = Min::acc(self.pf, f);
        self.block.push((f, g));
        // Witnesses in the previous block: from `e - span`, its offset `j + 1`.
        let out = match self.q.get(j + 1) {
            Some(&q) if e >= len => Max::acc(self.p, Min::acc(self.pf, q)),
            _ => self.p,
        };
        if j + 1 == len {
            // The block is complete: since over each of its suffixes, backwards.
            self.q.clear();
            self.q.resize(len, NEG_INF);
            let (mut acc, mut sf) = (NEG_INF, INF);
            for k in (0..len).rev() {
                let (fk, gk) = self.block[k];
                acc = Max::acc(acc, Min::acc(gk, sf));
                self.q[k] = acc;
                sf = Min::acc(sf, fk);
            }
        }
        out
    }
}

impl Window {
    /// The values at the steps after the last one given, windows clipped at the end of a
    /// trace of `n` steps, once every operand value has been taken.
    fn finish(&mut self, n: usize) -> Vec<f64> {
        let id = if self.max { NEG_INF } else { INF };
        let first = n.saturating_sub(self.end);
        (first..n)
            .map(|t| {
                if self.last.is_none() {
                    return id;
                }
                let lo = t.saturating_add(self.a);
                while self.deque.front().is_some_and(|&(k, _)| k < lo) {
                    self.deque.pop_front();
                }
                self.deque.front().map_or(id, |&(_, v)| v)
            })
            .collect()
    }
}

impl Until {
    /// The values at the steps after the last one given, windows clipped at the end of the
    /// trace, once every operand value has been taken: the offline kernel over the values
    /// still held, which start at the first step without a value.
    fn finish(&mut self) -> Vec<f64> {
        if self.last.is_none() {
            // An empty window keeps no values: `-inf` at every step still open.
            return vec![NEG_INF; self.seen.min(self.end)];
        }
        let mut lhs: Vec<f64> = self.fv.drain(..).collect();
        let mut out: Vec<f64> = self.gv.drain(..).collect();
        crate::kernels::Kernels::new().until(&self.interval, &mut lhs, &mut out);
        out
    }
}

/// `always[I] f` (a sliding minimum) or `eventually[I] f` (maximum) over the values of `f`
/// given one step at a time: the online monitor's stream of such a node on its own, for a
/// caller that computes `f` itself (the facade's episode reward, which evaluates every
/// state formula of a task in one pass). Amortised `O(1)` a value, `O(b)` values kept for
/// `I = [a..=b]`; the values, and the ties between equal ones, are the online monitor's.
#[derive(Clone, Debug)]
pub struct WindowStream {
    window: Window,
}

impl WindowStream {
    /// The stream of `always[interval]` (`always = true`) or `eventually[interval]`; `None`
    /// for an unbounded interval, whose value is never final before the trace ends.
    pub fn new(always: bool, interval: &Interval) -> Option<WindowStream> {
        if interval.end == Bound::Unbounded {
            return None;
        }
        Some(WindowStream { window: Window::new(!always, interval) })
    }

    /// Takes `f` at the next step; returns the operator's value at the step it makes final
    /// (step `t` once `f` at `t + b` is in), counted from the first value after creation or
    /// [`WindowStream::clear`]. `f` is not NaN (a NaN is skipped, as the online monitor
    /// skips it).
    pub fn push(&mut self, f: f64) -> Option<crate::Verdict> {
        let j = self.window.seen;
        let value = self.window.take(f)?;
        Some(crate::Verdict { step: j - self.window.end, value })
    }

    /// Forgets every value: a new trace starts.
    pub fn clear(&mut self) {
        // The deque keeps its allocation.
        self.window.seen = 0;
        self.window.deque.clear();
    }
}

impl Window {
    fn new(max: bool, i: &Interval) -> Window {
        Window { max, a: i.start, last: last(i), end: end(i), seen: 0, deque: VecDeque::new() }
    }

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
pub(crate) fn state_value(node: &Node, vals: &[f64], row: &[f64]) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::WindowStream;
    use crate::{CmpOp, Expr, Formula, Interval, OnlineMonitor};

    /// The window on its own gives the online monitor's verdicts of `always[I] x > 0` and
    /// `eventually[I] x > 0` over the values of `x > 0`, bit for bit (signed zeros and
    /// ties included), across a restart.
    #[test]
    fn a_window_stream_gives_the_online_monitors_verdicts() {
        let xs: Vec<f64> = (0..200u64)
            .map(|k| match (k * 2654435761) % 7 {
                0 => 0.0,
                1 => -0.0,
                r => r as f64 - 3.5,
            })
            .collect();
        let atom = Formula::cmp(Expr::var(0), CmpOp::Gt, Expr::constant(0.0));
        for (a, b, inclusive) in
            [(0, 0, true), (0, 3, true), (2, 5, true), (1, 4, false), (3, 3, false)]
        {
            let end =
                if inclusive { crate::Bound::Inclusive(b) } else { crate::Bound::Exclusive(b) };
            let i = Interval { start: a, end };
            for always in [true, false] {
                let f = if always {
                    Formula::always(i, atom.clone())
                } else {
                    Formula::eventually(i, atom.clone())
                };
                let mut online = OnlineMonitor::new(&f, 1);
                let mut window = WindowStream::new(always, &i).unwrap();
                for round in 0..2 {
                    for &x in &xs {
                        let want = online.push(&[x]).unwrap();
                        let got = window.push(x - 0.0);
                        assert_eq!(
                            got.map(|v| (v.step, v.value.to_bits())),
                            want.map(|v| (v.step, v.value.to_bits())),
                            "{f}, round {round}"
                        );
                    }
                    online.finish();
                    window.clear();
                }
            }
        }
    }
}
