//! Bounded `f until[a..=b] g` in dense time as a sliding window over pieces, streaming.
//!
//! Cut time at the union of `f`'s and `g`'s change points: piece `k` starts at `s_k` and
//! holds `f_k`, `g_k`. At time `t` let `m` be the piece holding `t`, `L` the last piece
//! with `s_k - a <= t` and `M` the last with `s_k - b <= t` (each one IEEE subtraction, as
//! the offline window operators compute their breakpoints). Then
//!
//! `rho(t) = min(min f over pieces m..L-1, until over pieces L..M)`,
//!
//! the until over a run of pieces being `max over k' of min(g_k', min f over L..k')`. This
//! is, value for value at every `t`, rtamt's decomposition `eventually[a..=b] g &&
//! always[0..=a] (f until g)` over the same breakpoints (`timed_until` in `offline`): the
//! decomposition's untimed `until` reads to the end of the trace, but whatever it reads past
//! piece `M` is cut off by the `eventually`, because min and max form a lattice (the test
//! `equals_the_decomposition` holds the two against each other). `m`, `L` and `M` only
//! grow with `t`, so one sweep over the breakpoints does it: a monotone deque for the min
//! of `f`, and a two-stack queue for the until over `L..M` (pieces enter at the back with a
//! running forward fold; when the front runs out the back is folded backwards into
//! suffixes). Each piece is folded at most twice: amortised `O(1)` per piece whatever the
//! window's length, and only the pieces from `m` to `M` are kept.
//!
//! The offline evaluator and the online monitor both run this sweep, and its operations
//! depend only on the breakpoints, not on how the pieces arrive, so they agree bit for bit
//! (the sign of a zero included).

use super::minmax::{max, min};
use super::saved::{Reader, SavedStateError, Writer};
use std::collections::VecDeque;

const INF: f64 = f64::INFINITY;

/// Two runs of pieces as one until: `(min f, until)` of the first, then the second.
#[inline]
fn join((f1, u1): (f64, f64), (f2, u2): (f64, f64)) -> (f64, f64) {
    (min(f1, f2), max(u1, min(f1, u2)))
}

/// One piece as a run: `(f, min(g, f))`.
#[inline]
fn piece(f: f64, g: f64) -> (f64, f64) {
    (f, min(g, f))
}

/// The operands' change points merged into pieces, up to the operands' frontier.
#[derive(Clone, Debug, Default)]
pub(crate) struct Pieces {
    f: VecDeque<(f64, f64)>,
    g: VecDeque<(f64, f64)>,
    cur: (f64, f64),
}

impl Pieces {
    pub(crate) fn feed(&mut self, f: &[(f64, f64)], g: &[(f64, f64)]) {
        self.f.extend(f.iter().copied());
        self.g.extend(g.iter().copied());
    }

    pub(crate) fn kept(&self) -> usize {
        self.f.len() + self.g.len()
    }

    /// Every union time before `frontier` into `until`.
    pub(crate) fn advance(&mut self, frontier: f64, until: &mut BoundedUntil) {
        loop {
            let t = match (self.f.front(), self.g.front()) {
                (Some(&(x, _)), Some(&(y, _))) => x.min(y),
                (Some(&(x, _)), None) => x,
                (None, Some(&(y, _))) => y,
                (None, None) => break,
            };
            if t >= frontier {
                break;
            }
            if self.f.front().is_some_and(|p| p.0 == t) {
                self.cur.0 = self.f.pop_front().map_or(self.cur.0, |p| p.1);
            }
            if self.g.front().is_some_and(|p| p.0 == t) {
                self.cur.1 = self.g.pop_front().map_or(self.cur.1, |p| p.1);
            }
            until.feed(t, self.cur.0, self.cur.1);
        }
    }
}

/// The sweep of the module's documentation, fed piece by piece.
#[derive(Clone, Debug)]
pub(crate) struct BoundedUntil {
    a: f64,
    b: f64,
    /// Pieces from `base` on: start, `f`, `g`.
    p: VecDeque<(f64, f64, f64)>,
    base: usize,
    /// How many pieces have `s_k - b <= t` (`M + 1`), `s_k - a <= t` (`L + 1`), `s_k <= t`
    /// (`m + 1`), at the last time swept.
    ne: usize,
    nl: usize,
    nm: usize,
    /// `f` over pieces `m..L`, a monotone deque of `(index, f)`.
    minf: VecDeque<(usize, f64)>,
    /// The two-stack queue over pieces `L..=M`: suffix runs, the top starting at `L`, and
    /// the run of the pieces entered since the last fold (from `back_start`).
    front: Vec<(f64, f64)>,
    back: (f64, f64),
    back_start: usize,
    swept: bool,
    last: Option<f64>,
}

impl BoundedUntil {
    /// `until[a..=b]`, `0 <= a <= b < inf`.
    pub(crate) fn new(a: f64, b: f64) -> BoundedUntil {
        BoundedUntil {
            a,
            b,
            p: VecDeque::new(),
            base: 0,
            ne: 0,
            nl: 0,
            nm: 0,
            minf: VecDeque::new(),
            front: Vec::new(),
            back: (INF, f64::NEG_INFINITY),
            back_start: 0,
            swept: false,
            last: None,
        }
    }

    /// The lower bound `a`.
    pub(crate) fn a(&self) -> f64 {
        self.a
    }

    /// The upper bound `b`.
    pub(crate) fn b(&self) -> f64 {
        self.b
    }

    /// The next piece: from `t` on, `f` is `fv` and `g` is `gv`.
    #[inline]
    pub(crate) fn feed(&mut self, t: f64, fv: f64, gv: f64) {
        self.p.push_back((t, fv, gv));
    }

    pub(crate) fn kept(&self) -> usize {
        self.p.len() + self.minf.len() + self.front.len()
    }

    fn received(&self) -> usize {
        self.base + self.p.len()
    }

    #[inline]
    fn at(&self, k: usize) -> (f64, f64, f64) {
        self.p[k - self.base]
    }

    /// Sweeps every breakpoint before the pieces' frontier (`INF`: every piece is in)
    /// allows, pushing the change points into `out`; returns the output's frontier.
    pub(crate) fn advance(&mut self, t0: f64, pieces: f64, out: &mut Vec<(f64, f64)>) -> f64 {
        let rec = self.received();
        if rec == 0 {
            // Operands start at the first stamp: none yet means nothing is final.
            return f64::NEG_INFINITY;
        }
        // A piece still to come starts at `s >= pieces`: its breakpoints are no sooner
        // than `pieces - b` (rounding is monotone).
        let limit = if pieces == INF { INF } else { pieces - self.b };
        // Where `M`, `L` and `m` move next (each one IEEE subtraction).
        let next = |this: &Self, n: usize, d: f64| if n < rec { this.at(n).0 - d } else { limit };
        let (mut te, mut tl, mut tm) =
            (next(self, self.ne, self.b), next(self, self.nl, self.a), next(self, self.nm, 0.0));
        let mut t = if self.swept { te.min(tl).min(tm) } else { t0 };
        // `M`, `L`, `m` move in that order, so `m <= L <= M` stays true.
        while t < limit {
            while te <= t {
                let (_, fv, gv) = self.at(self.ne);
                self.back = join(self.back, piece(fv, gv));
                self.ne += 1;
                te = next(self, self.ne, self.b);
            }
            while tl <= t {
                if self.nl > 0 {
                    // Piece `L` leaves the until for the min of `f`.
                    let k = self.nl - 1;
                    self.pop_front(k);
                    let fv = self.at(k).1;
                    while self.minf.back().is_some_and(|&(_, q)| q >= fv) {
                        self.minf.pop_back();
                    }
                    self.minf.push_back((k, fv));
                }
                self.nl += 1;
                tl = next(self, self.nl, self.a);
            }
            while tm <= t {
                if self.nm > 0 && self.minf.front().is_some_and(|q| q.0 == self.nm - 1) {
                    self.minf.pop_front();
                }
                self.nm += 1;
                tm = next(self, self.nm, 0.0);
            }
            // Pieces before `m` are done with.
            while self.base + 1 < self.nm {
                self.p.pop_front();
                self.base += 1;
            }
            let v = self.value();
            if self.last != Some(v) {
                out.push((t, v));
                self.last = Some(v);
            }
            self.swept = true;
            t = te.min(tl).min(tm);
        }
        limit
    }

    /// Drops piece `k`, the queue's first, folding the back into suffixes if needed.
    fn pop_front(&mut self, k: usize) {
        if self.front.is_empty() {
            let mut run = (INF, f64::NEG_INFINITY);
            for j in (k..self.ne).rev() {
                let (_, fv, gv) = self.at(j);
                run = join(piece(fv, gv), run);
                self.front.push(run);
            }
            self.back = (INF, f64::NEG_INFINITY);
            self.back_start = self.ne;
        }
        self.front.pop();
    }

    /// `rho` at the last time swept.
    #[inline]
    fn value(&self) -> f64 {
        let run = match self.front.last() {
            Some(&top) if self.back_start < self.ne => join(top, self.back).1,
            Some(&top) => top.1,
            None => self.back.1,
        };
        match self.minf.front() {
            Some(&(_, fv)) => min(fv, run),
            None => run,
        }
    }
}

impl Pieces {
    pub(crate) fn save(&self, w: &mut Writer) {
        w.points(self.f.iter());
        w.points(self.g.iter());
        w.f64(self.cur.0);
        w.f64(self.cur.1);
    }

    pub(crate) fn load(r: &mut Reader<'_>) -> Result<Pieces, SavedStateError> {
        let f = r.points("an until's left operand")?.into();
        let g = r.points("an until's right operand")?.into();
        let cur = (r.value("an until's left value")?, r.value("an until's right value")?);
        Ok(Pieces { f, g, cur })
    }
}

impl BoundedUntil {
    pub(crate) fn save(&self, w: &mut Writer) {
        w.count(self.p.len());
        for &(t, f, g) in &self.p {
            w.f64(t);
            w.f64(f);
            w.f64(g);
        }
        for n in [self.base, self.ne, self.nl, self.nm, self.back_start] {
            w.count(n);
        }
        w.count(self.minf.len());
        for &(k, f) in &self.minf {
            w.count(k);
            w.f64(f);
        }
        w.count(self.front.len());
        for &(f, u) in &self.front {
            w.f64(f);
            w.f64(u);
        }
        w.f64(self.back.0);
        w.f64(self.back.1);
        w.word(u64::from(self.swept));
        w.opt_f64(self.last);
    }

    /// The sweep of `until[a..=b]` as [`BoundedUntil::save`] wrote it; the monotone deque
    /// and the folds are checked against their recomputation from the pieces.
    pub(crate) fn load(
        r: &mut Reader<'_>,
        a: f64,
        b: f64,
    ) -> Result<BoundedUntil, SavedStateError> {
        let what = "a bounded until's pieces";
        let n = r.count(3, what)?;
        let mut p = VecDeque::with_capacity(n);
        for _ in 0..n {
            let t = r.time(what)?;
            if p.back().is_some_and(|&(q, _, _): &(f64, f64, f64)| t <= q) {
                return Err(r.bad("a bounded until's pieces: the times do not increase"));
            }
            p.push_back((t, r.value(what)?, r.value(what)?));
        }
        let mut counts = [0usize; 5];
        for c in &mut counts {
            *c = r.index(usize::MAX >> 2, "a bounded until's position")?;
        }
        let [base, ne, nl, nm, back_start] = counts;
        let rec = base + n;
        if !(nm <= nl && nl <= ne && ne <= rec && base < nm.max(1) && back_start <= ne) {
            return Err(r.bad(&format!(
                "a bounded until's positions do not fit together (pieces {base} to {rec}, \
                 M {ne}, L {nl}, m {nm})"
            )));
        }
        let mut until = BoundedUntil::new(a, b);
        until.p = p;
        until.base = base;
        until.ne = ne;
        until.nl = nl;
        until.nm = nm;
        until.back_start = back_start;
        let k = r.count(2, "a bounded until's minimum")?;
        let mut minf = VecDeque::with_capacity(k);
        for _ in 0..k {
            let i = r.index(usize::MAX >> 2, "a bounded until's minimum")?;
            minf.push_back((i, r.value("a bounded until's minimum")?));
        }
        // The min of `f` over pieces `m..L` as the sweep keeps it.
        let mut want: VecDeque<(usize, f64)> = VecDeque::new();
        for i in nm.max(1) - 1..nl.max(1) - 1 {
            let fv = until.at(i).1;
            while want.back().is_some_and(|&(_, q)| q >= fv) {
                want.pop_back();
            }
            want.push_back((i, fv));
        }
        if !same(&minf, &want) {
            return Err(r.bad("a bounded until's minimum is not that of its pieces"));
        }
        until.minf = minf;
        let k = r.count(2, "a bounded until's runs")?;
        let mut front = Vec::with_capacity(k);
        for _ in 0..k {
            front.push((r.value("a bounded until's runs")?, r.value("a bounded until's runs")?));
        }
        let back = (r.value("a bounded until's run")?, r.value("a bounded until's run")?);
        // The queue holds pieces `L..=M`: the runs from `L` to `back_start`, then the back.
        if back_start.checked_sub(front.len()) != Some(nl.max(1) - 1) {
            return Err(r.bad("a bounded until's runs do not cover its window"));
        }
        let mut run = (INF, f64::NEG_INFINITY);
        for (q, &saved) in front.iter().enumerate() {
            let (_, fv, gv) = until.at(back_start - 1 - q);
            run = join(piece(fv, gv), run);
            if !same_pair(run, saved) {
                return Err(r.bad("a bounded until's runs are not those of its pieces"));
            }
        }
        let mut run = (INF, f64::NEG_INFINITY);
        for j in back_start..ne {
            let (_, fv, gv) = until.at(j);
            run = join(run, piece(fv, gv));
        }
        if !same_pair(run, back) {
            return Err(r.bad("a bounded until's last run is not that of its pieces"));
        }
        until.front = front;
        until.back = back;
        until.swept = r.flag("whether a bounded until swept")?;
        until.last = r.opt_value("a bounded until's last value")?;
        Ok(until)
    }
}

/// Two runs equal to the bit.
fn same_pair(x: (f64, f64), y: (f64, f64)) -> bool {
    x.0.to_bits() == y.0.to_bits() && x.1.to_bits() == y.1.to_bits()
}

/// Two monotone deques equal to the bit.
pub(crate) fn same(x: &VecDeque<(usize, f64)>, y: &VecDeque<(usize, f64)>) -> bool {
    x.len() == y.len() && x.iter().zip(y).all(|(p, q)| p.0 == q.0 && p.1.to_bits() == q.1.to_bits())
}

#[cfg(test)]
mod tests {
    use super::super::DenseSignal;
    use super::super::offline::{Dir, timed_until};
    use super::*;

    /// The sweep over whole signals.
    fn sweep(f: &DenseSignal, g: &DenseSignal, t0: f64, a: f64, b: f64) -> Vec<(f64, f64)> {
        let mut p = Pieces::default();
        p.feed(&f.points().collect::<Vec<_>>(), &g.points().collect::<Vec<_>>());
        let mut u = BoundedUntil::new(a, b);
        p.advance(INF, &mut u);
        let mut out = Vec::new();
        u.advance(t0, INF, &mut out);
        out
    }

    /// A small deterministic generator.
    fn next(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    fn signal(state: &mut u64, t0: f64, unit: f64, n: usize) -> DenseSignal {
        let mut s = DenseSignal::default();
        let mut k = 0u64;
        for j in 0..n {
            let v = match next(state) % 12 {
                10 => INF,
                11 => f64::NEG_INFINITY,
                r => r as f64 - 5.0,
            };
            // Stamps one rounding from a whole number of units, as a CSV's decimals are.
            let t = if j == 0 { t0 } else { t0 + (k as f64) * unit };
            s.push(t, v);
            k += 1 + next(state) % 6;
        }
        s
    }

    /// Value for value at every breakpoint (and so the same change points), the sweep is
    /// rtamt's decomposition, with decimal stamps and bounds that round.
    #[test]
    fn equals_the_decomposition() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        for case in 0..20_000 {
            let unit = if case % 2 == 0 { 0.1 } else { 0.25 };
            let t0 = (next(&mut state) % 7) as f64 * unit;
            let n = 1 + (next(&mut state) % 40) as usize;
            let f = signal(&mut state, t0, unit, n);
            let g = signal(&mut state, t0, unit, n);
            let a = (next(&mut state) % 8) as f64 * unit;
            let b = a + (next(&mut state) % 12) as f64 * unit;
            let want = timed_until(&f, &g, t0, Dir::Future, a, b);
            let got = sweep(&f, &g, t0, a, b);
            let want: Vec<(f64, f64)> = want.points().collect();
            assert_eq!(got.len(), want.len(), "case {case}: {got:?} {want:?}");
            for (x, y) in got.iter().zip(&want) {
                assert!(x.0.to_bits() == y.0.to_bits() && x.1 == y.1, "case {case}: {x:?} {y:?}");
            }
        }
    }
}
