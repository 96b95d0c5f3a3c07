//! The offline evaluator's runner: a plan's groups computed in order over the trace, state
//! nodes in chunks and bounded groups in cache-sized pieces, each buffer taken from a pool
//! and given back after its last reader.

use super::plan::{Group, NONE, Role};
use crate::formula::Node;
use crate::kernels::Kernels;
use crate::primitives::{Lattice, Max, Min, fold_operand, piece_len};
use crate::{CmpOp, Formula, Interval};

const INF: f64 = f64::INFINITY;
const NEG_INF: f64 = f64::NEG_INFINITY;
/// Samples per chunk for state formulas: a handful of chunk buffers stay in L1.
const CHUNK: usize = 512;

/// Where the state nodes' values come from.
#[derive(Clone, Copy)]
pub(crate) enum Source<'a> {
    /// Computed from the trace's columns.
    Columns(&'a [&'a [f64]]),
    /// Looked up: `tables[v][seg[t]]` for each stored state node `v`, its last entry
    /// standing for an index past the table.
    Tables { tables: &'a [Vec<f64>], seg: &'a [usize] },
}

/// An operand of a state node over one chunk: a slice of values or one value for all.
#[derive(Clone, Copy)]
enum Src<'a> {
    Slice(&'a [f64]),
    Scalar(f64),
}

/// `op(out[i], a[i], b[i])` for every `i`, whatever mix of slices and scalars `a`, `b` are.
#[inline(always)]
fn zip2(out: &mut [f64], a: Src<'_>, b: Src<'_>, op: impl Fn(&mut f64, f64, f64)) {
    match (a, b) {
        (Src::Slice(a), Src::Slice(b)) => {
            out.iter_mut().zip(a).zip(b).for_each(|((o, x), y)| op(o, *x, *y))
        }
        (Src::Slice(a), Src::Scalar(y)) => out.iter_mut().zip(a).for_each(|(o, x)| op(o, *x, y)),
        (Src::Scalar(x), Src::Slice(b)) => out.iter_mut().zip(b).for_each(|(o, y)| op(o, x, *y)),
        (Src::Scalar(x), Src::Scalar(y)) => out.iter_mut().for_each(|o| op(o, x, y)),
    }
}

/// The buffers of an evaluation, kept between calls.
#[derive(Clone, Debug, Default)]
pub(crate) struct Runner {
    pool: Vec<Vec<f64>>,
    chunks: Vec<Vec<f64>>,
    kernels: Kernels,
    /// Whole signals of group roots still to be read, by node.
    full: Vec<Vec<f64>>,
    /// Piece buffers of the current group's members, by node.
    piece: Vec<Vec<f64>>,
    /// Chunk buffers of the current group's state members, by node.
    chunk: Vec<Vec<f64>>,
    state_left: Vec<u32>,
    temporal_left: Vec<u32>,
    ext_left: Vec<u32>,
}

impl Runner {
    /// A buffer of `n` values, stale: every operator overwrites its whole output.
    pub(crate) fn take(&mut self, n: usize) -> Vec<f64> {
        // The shortest buffer that is long enough, else the longest: growing a buffer's
        // length writes zeros, so big buffers are kept for big requests.
        let fit =
            self.pool.iter().enumerate().filter(|(_, v)| v.len() >= n).min_by_key(|(_, v)| v.len());
        let pick = fit.or_else(|| self.pool.iter().enumerate().max_by_key(|(_, v)| v.len()));
        let mut v = match pick.map(|(i, _)| i) {
            Some(i) => self.pool.swap_remove(i),
            None => Vec::new(),
        };
        if v.len() < n {
            v.resize(n, 0.0);
        } else {
            v.truncate(n);
        }
        v
    }

    /// Gives a buffer back to the pool.
    pub(crate) fn put(&mut self, v: Vec<f64>) {
        if v.capacity() > 0 {
            self.pool.push(v);
        }
    }

    /// The signal of `f`'s root over the first `n` steps.
    pub(crate) fn run(&mut self, f: &Formula, src: Source<'_>, n: usize) -> Vec<f64> {
        let plan = f.plan();
        let len = f.len();
        for v in [&mut self.full, &mut self.piece, &mut self.chunk] {
            v.resize_with(len, Vec::new);
        }
        self.state_left.resize(len, 0);
        self.temporal_left.resize(len, 0);
        self.ext_left.clear();
        self.ext_left.extend_from_slice(&plan.ext_reads);
        for g in &plan.groups {
            if crate::cancel::requested() {
                return vec![f64::NAN; n];
            }
            let root = g.root;
            let piece = match f.horizons()[root] {
                Some(h) if !f.states()[root] && !f.nodes()[root].is_past() => piece_len(h),
                _ => usize::MAX,
            };
            let out = if n / 2 <= piece {
                match self.group(f, g, src, 0, n, true) {
                    Some(out) => out,
                    None => return vec![f64::NAN; n],
                }
            } else {
                let h = f.horizons()[root].unwrap_or(0);
                let mut out = self.take(n);
                let mut lo = 0;
                while lo < n {
                    if crate::cancel::requested() {
                        return vec![f64::NAN; n];
                    }
                    let hi = (lo + piece).min(n);
                    let end = hi.saturating_add(h).min(n);
                    let Some(v) = self.group(f, g, src, lo, end - lo, hi == n) else {
                        return vec![f64::NAN; n];
                    };
                    out[lo..hi].copy_from_slice(&v[..hi - lo]);
                    self.put(v);
                    lo = hi;
                }
                out
            };
            self.full[root] = out;
            // Group roots no later group reads go back to the pool.
            for &v in g.state.iter().chain(&g.temporal) {
                for c in f.nodes()[v].children() {
                    if plan.owner[c] != NONE
                        && plan.owner[c] != plan.owner[v]
                        && self.ext_left[c] == 0
                    {
                        let buf = std::mem::take(&mut self.full[c]);
                        self.put(buf);
                    }
                }
            }
        }
        std::mem::take(&mut self.full[f.root().index()])
    }

    /// The group's root over steps `lo .. lo + m`. `last` says this is the group's last
    /// piece (the reads of other groups' roots are then counted off). `None` when the
    /// thread's flag was raised (see [`crate::cancel`]): a group over a whole long trace
    /// looks at it between chunks of its state members and between its temporal ones, so
    /// a large one stops within a fraction of a second too.
    fn group(
        &mut self,
        f: &Formula,
        g: &Group,
        src: Source<'_>,
        lo: usize,
        m: usize,
        last: bool,
    ) -> Option<Vec<f64>> {
        let plan = f.plan();
        for &s in &g.state {
            if plan.role[s] == Role::Piece {
                self.piece[s] = self.take(m);
            }
        }
        if !self.state_phase(f, g, src, lo, m) {
            return None;
        }
        if last {
            for &s in &g.state {
                for c in f.nodes()[s].children() {
                    if plan.owner[c] != NONE && plan.owner[c] != plan.owner[s] {
                        self.ext_left[c] -= 1;
                    }
                }
            }
        }
        for &v in g.state.iter().chain(&g.temporal) {
            self.temporal_left[v] = plan.temporal_reads[v];
        }
        // A whole-trace group (one piece) may take a group root's buffer for its own.
        let whole = last && lo == 0;
        for (k, &v) in g.temporal.iter().enumerate() {
            // Between the members of a long group only: `run` looked before this one, and
            // a short segment (a suffix the learner scores) takes no more looks than it did.
            if k > 0 && m > CHUNK && crate::cancel::requested() {
                return None;
            }
            let out = self.temporal(f, v, lo, m, last, whole);
            self.piece[v] = out;
        }
        let out = std::mem::take(&mut self.piece[g.root]);
        for &v in g.state.iter().chain(&g.temporal) {
            let buf = std::mem::take(&mut self.piece[v]);
            self.put(buf);
        }
        Some(out)
    }

    /// The stored state members of `g` over steps `lo .. lo + m`; `false` when stopped by
    /// the thread's flag.
    fn state_phase(
        &mut self,
        f: &Formula,
        g: &Group,
        src: Source<'_>,
        lo: usize,
        m: usize,
    ) -> bool {
        let plan = f.plan();
        let cols = match src {
            Source::Tables { tables, seg } => {
                for &s in &g.state {
                    if plan.role[s] != Role::Piece {
                        continue;
                    }
                    let table = &tables[s];
                    let nan_row = table.len() - 1;
                    for (o, &k) in self.piece[s].iter_mut().zip(&seg[lo..lo + m]) {
                        *o = table[k.min(nan_row)];
                    }
                }
                return true;
            }
            Source::Columns(cols) => cols,
        };
        let mut c0 = 0;
        while c0 < m {
            // Between chunks: `run` looked before the first.
            if c0 > 0 && crate::cancel::requested() {
                return false;
            }
            let c1 = (c0 + CHUNK).min(m);
            for &s in &g.state {
                self.state_left[s] = plan.state_reads[s];
            }
            for &s in &g.state {
                let piece = plan.role[s] == Role::Piece;
                let mut target = if piece {
                    std::mem::take(&mut self.piece[s])
                } else {
                    self.chunks.pop().unwrap_or_else(|| vec![0.0; CHUNK])
                };
                let out = if piece { &mut target[c0..c1] } else { &mut target[..c1 - c0] };
                self.state_node(f, s, cols, lo, c0, out);
                if piece {
                    self.piece[s] = target;
                } else {
                    self.chunk[s] = target;
                }
                // A chunk buffer read for the last time goes back.
                for c in f.nodes()[s].children() {
                    if plan.role[c] == Role::Chunk && plan.owner[c] == plan.owner[s] {
                        self.state_left[c] -= 1;
                        if self.state_left[c] == 0 {
                            let buf = std::mem::take(&mut self.chunk[c]);
                            self.chunks.push(buf);
                        }
                    }
                }
            }
            c0 = c1;
        }
        true
    }

    /// Operand `c` of state node `s` over chunk `c0 ..` of the piece at `lo`.
    #[allow(clippy::too_many_arguments)]
    fn src<'a>(
        &'a self,
        f: &'a Formula,
        s: usize,
        c: usize,
        cols: &[&'a [f64]],
        lo: usize,
        c0: usize,
        len: usize,
    ) -> Src<'a> {
        let plan = f.plan();
        match &f.nodes()[c] {
            Node::Var(i) => match cols.get(*i) {
                Some(col) => Src::Slice(&col[lo + c0..lo + c0 + len]),
                None => Src::Scalar(f64::NAN),
            },
            Node::Const(x) => Src::Scalar(*x),
            _ if plan.owner[c] != plan.owner[s] => {
                Src::Slice(&self.full[c][lo + c0..lo + c0 + len])
            }
            _ if plan.role[c] == Role::Piece => Src::Slice(&self.piece[c][c0..c0 + len]),
            _ => Src::Slice(&self.chunk[c][..len]),
        }
    }

    /// State node `s` on steps `lo + c0 .. lo + c0 + out.len()`, into `out`.
    fn state_node(
        &self,
        f: &Formula,
        s: usize,
        cols: &[&[f64]],
        lo: usize,
        c0: usize,
        out: &mut [f64],
    ) {
        let len = out.len();
        let src = |c: usize| self.src(f, s, c, cols, lo, c0, len);
        let set = |o: &mut f64, x: f64, _: f64| *o = x;
        match &f.nodes()[s] {
            Node::True => out.fill(INF),
            Node::False => out.fill(NEG_INF),
            Node::Cmp { lhs, op, rhs } => {
                let (a, b) = (src(lhs.index()), src(rhs.index()));
                match op {
                    CmpOp::Lt | CmpOp::Le => zip2(out, a, b, |o, x, y| *o = y - x),
                    CmpOp::Gt | CmpOp::Ge => zip2(out, a, b, |o, x, y| *o = x - y),
                }
            }
            Node::Const(x) => out.fill(*x),
            Node::Var(_) => zip2(out, src(s), Src::Scalar(0.0), set),
            Node::Neg(a) => zip2(out, src(a.index()), Src::Scalar(0.0), |o, x, _| *o = -x),
            Node::Abs(a) => zip2(out, src(a.index()), Src::Scalar(0.0), |o, x, _| *o = x.abs()),
            Node::Sqrt(a) => zip2(out, src(a.index()), Src::Scalar(0.0), |o, x, _| *o = x.sqrt()),
            Node::Add(a, b) => zip2(out, src(a.index()), src(b.index()), |o, x, y| *o = x + y),
            Node::Sub(a, b) => zip2(out, src(a.index()), src(b.index()), |o, x, y| *o = x - y),
            Node::Mul(a, b) => zip2(out, src(a.index()), src(b.index()), |o, x, y| *o = x * y),
            Node::Div(a, b) => zip2(out, src(a.index()), src(b.index()), |o, x, y| *o = x / y),
            Node::Not(g) => zip2(out, src(g.index()), Src::Scalar(0.0), |o, x, _| *o = -x),
            Node::Implies(g, h) => {
                zip2(out, src(g.index()), src(h.index()), |o, x, y| *o = (-x).max(y))
            }
            Node::And(gs) => self.fold_chunk::<Min>(f, s, gs, cols, lo, c0, out),
            Node::Or(gs) => self.fold_chunk::<Max>(f, s, gs, cols, lo, c0, out),
            // Temporal nodes are never state members.
            Node::Always(..)
            | Node::Eventually(..)
            | Node::Until(..)
            | Node::Once(..)
            | Node::Historically(..)
            | Node::Since(..)
            | Node::Prev(_)
            | Node::Next(_) => out.fill(f64::NAN),
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn fold_chunk<L: Lattice>(
        &self,
        f: &Formula,
        s: usize,
        gs: &[crate::NodeId],
        cols: &[&[f64]],
        lo: usize,
        c0: usize,
        out: &mut [f64],
    ) {
        let len = out.len();
        let src = |c: usize| self.src(f, s, c, cols, lo, c0, len);
        out.fill(L::ID);
        for g in gs {
            let g = g.index();
            // `x op c` folds straight in: no pass through a buffer of its own.
            if f.plan().role[g] == Role::Fused
                && let Node::Cmp { lhs, op, rhs } = &f.nodes()[g]
            {
                let (a, b) = (src(lhs.index()), src(rhs.index()));
                match op {
                    CmpOp::Lt | CmpOp::Le => zip2(out, a, b, |o, x, y| *o = L::acc(*o, y - x)),
                    CmpOp::Gt | CmpOp::Ge => zip2(out, a, b, |o, x, y| *o = L::acc(*o, x - y)),
                }
                continue;
            }
            zip2(out, src(g), Src::Scalar(0.0), |o, x, _| *o = L::acc(*o, x));
        }
    }

    /// Operand `c` of temporal node `v` over the piece, as a buffer of its own: the
    /// operand's buffer when this is its last read, else a copy.
    #[allow(clippy::too_many_arguments)]
    fn own(
        &mut self,
        f: &Formula,
        v: usize,
        c: usize,
        lo: usize,
        m: usize,
        last: bool,
        whole: bool,
    ) -> Vec<f64> {
        let plan = f.plan();
        if plan.owner[c] == plan.owner[v] {
            self.temporal_left[c] -= 1;
            if self.temporal_left[c] == 0 {
                return std::mem::take(&mut self.piece[c]);
            }
            let mut out = self.take(m);
            out.copy_from_slice(&self.piece[c][..m]);
            return out;
        }
        if last {
            self.ext_left[c] -= 1;
        }
        if whole && self.ext_left[c] == 0 {
            return std::mem::take(&mut self.full[c]);
        }
        let mut out = self.take(m);
        out.copy_from_slice(&self.full[c][lo..lo + m]);
        out
    }

    /// Operand `c` of temporal node `v` over the piece, borrowed.
    fn read(&self, f: &Formula, v: usize, c: usize, lo: usize, m: usize) -> &[f64] {
        let plan = f.plan();
        if plan.owner[c] == plan.owner[v] { &self.piece[c][..m] } else { &self.full[c][lo..lo + m] }
    }

    /// Counts off a [`Runner::read`] of operand `c` by temporal node `v`.
    fn done(&mut self, f: &Formula, v: usize, c: usize, last: bool) {
        let plan = f.plan();
        if plan.owner[c] == plan.owner[v] {
            self.temporal_left[c] -= 1;
            if self.temporal_left[c] == 0 {
                let buf = std::mem::take(&mut self.piece[c]);
                self.put(buf);
            }
        } else if last {
            self.ext_left[c] -= 1;
        }
    }

    /// Temporal node `v` over steps `lo .. lo + m`.
    fn temporal(
        &mut self,
        f: &Formula,
        v: usize,
        lo: usize,
        m: usize,
        last: bool,
        whole: bool,
    ) -> Vec<f64> {
        match &f.nodes()[v] {
            Node::Not(g) => {
                let mut out = self.own(f, v, g.index(), lo, m, last, whole);
                out.iter_mut().for_each(|x| *x = -*x);
                out
            }
            Node::And(gs) => self.fold::<Min>(f, v, gs, lo, m, last, whole),
            Node::Or(gs) => self.fold::<Max>(f, v, gs, lo, m, last, whole),
            Node::Implies(g, h) => {
                let mut out = self.own(f, v, g.index(), lo, m, last, whole);
                let rhs = self.read(f, v, h.index(), lo, m);
                out.iter_mut().zip(rhs).for_each(|(a, b)| *a = (-*a).max(*b));
                self.done(f, v, h.index(), last);
                out
            }
            Node::Always(i, g) => {
                let mut out = self.own(f, v, g.index(), lo, m, last, whole);
                self.window::<Min>(i, &mut out);
                out
            }
            Node::Eventually(i, g) => {
                let mut out = self.own(f, v, g.index(), lo, m, last, whole);
                self.window::<Max>(i, &mut out);
                out
            }
            Node::Until(i, g, h) => {
                let mut lhs = self.own(f, v, g.index(), lo, m, last, whole);
                let mut out = self.own(f, v, h.index(), lo, m, last, whole);
                self.kernels.until(i, &mut lhs, &mut out);
                self.put(lhs);
                out
            }
            // Past-time operators: the future kernels on the reversed signal (a group of
            // their own, over the whole trace).
            Node::Once(i, g) => {
                let mut out = self.own(f, v, g.index(), lo, m, last, whole);
                self.kernels.once(i, &mut out);
                out
            }
            Node::Historically(i, g) => {
                let mut out = self.own(f, v, g.index(), lo, m, last, whole);
                self.kernels.historically(i, &mut out);
                out
            }
            Node::Since(i, g, h) => {
                let mut lhs = self.own(f, v, g.index(), lo, m, last, whole);
                let mut out = self.own(f, v, h.index(), lo, m, last, whole);
                self.kernels.since(i, &mut lhs, &mut out);
                self.put(lhs);
                out
            }
            Node::Prev(g) => {
                let mut out = self.own(f, v, g.index(), lo, m, last, whole);
                self.kernels.prev(&mut out);
                out
            }
            Node::Next(g) => {
                let mut out = self.own(f, v, g.index(), lo, m, last, whole);
                self.kernels.next(&mut out);
                out
            }
            // State nodes are state members, computed in chunks.
            _ => {
                let mut out = self.take(m);
                out.fill(f64::NAN);
                out
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn fold<L: Lattice>(
        &mut self,
        f: &Formula,
        v: usize,
        gs: &[crate::NodeId],
        lo: usize,
        m: usize,
        last: bool,
        whole: bool,
    ) -> Vec<f64> {
        let Some((first, rest)) = gs.split_first() else {
            let mut out = self.take(m);
            out.fill(L::ID);
            return out;
        };
        // The first operand's buffer becomes the output; folding it into `ID` (which
        // drops a NaN) happens in the first combining pass rather than a pass of its own.
        let mut out = self.own(f, v, first.index(), lo, m, last, whole);
        if rest.is_empty() {
            fold_operand::<L>(&mut out, None, true);
        }
        for (k, g) in rest.iter().enumerate() {
            fold_operand::<L>(&mut out, Some(self.read(f, v, g.index(), lo, m)), k == 0);
            self.done(f, v, g.index(), last);
        }
        out
    }

    /// `buf[t]` becomes the `L`-fold of `buf` over the window of `i` at `t`, in place.
    fn window<L: Lattice>(&mut self, i: &Interval, buf: &mut [f64]) {
        self.kernels.window::<L>(buf, i);
    }
}
