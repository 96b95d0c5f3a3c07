//! The primitives the evaluator, the tabular scorer and the kernels share: the min/max
//! [`Lattice`], n-ary folds, shifts, suffix folds, the one van Herk/Gil-Werman sliding
//! window and the blocked bounded `until`. Every fold skips NaN samples and keeps the
//! first of equal values (so the sign of a zero), which is what makes the evaluators agree
//! bit for bit (see [`offline`](crate::offline)).

const INF: f64 = f64::INFINITY;
const NEG_INF: f64 = f64::NEG_INFINITY;
/// The least number of steps per piece of a bounded temporal formula: its buffers stay
/// in L2.
const PIECE: usize = 8192;

/// A min or a max, with its identity.
pub(crate) trait Lattice {
    const ID: f64;
    /// `minNum(acc, x)` (or `maxNum`) when `acc` is not NaN, in one instruction: a NaN `x`
    /// fails the comparison and leaves `acc`. Every fold starts at `ID`, so none holds NaN.
    fn acc(acc: f64, x: f64) -> f64;
}

/// One step of an n-ary `&&` (`L = Min`) or `||` (`Max`): `out` becomes the fold of `out`
/// and `v`. `first` says `out` still holds the first operand's raw values, which are folded
/// into `ID` here (dropping a NaN) rather than in a pass of their own; `v = None` does only
/// that, for a lone operand.
#[inline]
pub(crate) fn fold_operand<L: Lattice>(out: &mut [f64], v: Option<&[f64]>, first: bool) {
    match (v, first) {
        (None, _) => out.iter_mut().for_each(|a| *a = L::acc(L::ID, *a)),
        (Some(v), true) => {
            out.iter_mut().zip(v).for_each(|(a, b)| *a = L::acc(L::acc(L::ID, *a), *b))
        }
        (Some(v), false) => out.iter_mut().zip(v).for_each(|(a, b)| *a = L::acc(*a, *b)),
    }
}

pub(crate) struct Min;
pub(crate) struct Max;

impl Lattice for Min {
    const ID: f64 = INF;
    #[inline(always)]
    fn acc(acc: f64, x: f64) -> f64 {
        if x < acc { x } else { acc }
    }
}

impl Lattice for Max {
    const ID: f64 = NEG_INF;
    #[inline(always)]
    fn acc(acc: f64, x: f64) -> f64 {
        if x > acc { x } else { acc }
    }
}

/// The steps per piece of a temporal formula with horizon `h`: its buffers stay in L2.
pub(crate) fn piece_len(h: usize) -> usize {
    PIECE.max(h.saturating_mul(16))
}

/// `buf[t] = buf[t + a]`, and the identity where `t + a` is past the end.
pub(crate) fn shift_left<L: Lattice>(buf: &mut [f64], a: usize) {
    let n = buf.len();
    let a = a.min(n);
    buf.copy_within(a.., 0);
    buf[n - a..].fill(L::ID);
}

/// `out[s]` becomes `max over s <= u <= min(s + span, n - 1) of min(g[u], lhs[s..u])`, `g`
/// being `out` on entry: `lhs until[0..=span] g` at every `s`.
///
/// The van Herk idea carried over to until: cut the trace into blocks of `span + 1`. The
/// window of `s` covers the rest of its block and a prefix of the next one. Within the
/// block the answer is the unbounded until restricted to the block (`su`, a backward
/// recurrence); in the next block it is `min(lhs[s..block end], p[e])`, where `p[e]` is the
/// until over the next block's prefix up to `e` (a forward recurrence). Every sample costs
/// a fixed number of min/max, whatever the span, and no step branches on the data.
pub(crate) fn block_until(lhs: &[f64], out: &mut [f64], span: usize, scratch: [&mut Vec<f64>; 3]) {
    let n = out.len();
    let [su, sf, p] = scratch;
    for v in [&mut *su, &mut *sf, &mut *p] {
        v.resize(n, 0.0);
        v.truncate(n);
    }
    let len = span + 1;
    let mut b0 = 0;
    while b0 < n {
        let b1 = (b0 + len).min(n);
        let (f, g) = (&lhs[b0..b1], &out[b0..b1]);
        let (su, sf, p) = (&mut su[b0..b1], &mut sf[b0..b1], &mut p[b0..b1]);
        let m = f.len();
        // Forwards: `pf` = min lhs[b0..u), `pu` = the until over [b0, u].
        let (mut pf, mut pu) = (INF, NEG_INF);
        // Backwards: `sfa` = min lhs[u..b1), `sua` = the until over [u, b1).
        let (mut sfa, mut sua) = (INF, NEG_INF);
        for j in 0..m {
            // A NaN `g` leaves only the `lhs` part: `min(INF, NaN)` is `INF`.
            pu = Max::acc(pu, Min::acc(Min::acc(INF, g[j]), pf));
            p[j] = pu;
            pf = Min::acc(pf, f[j]);
            let k = m - 1 - j;
            sua = Max::acc(Min::acc(sua, f[k]), Min::acc(INF, g[k]));
            su[k] = sua;
            sfa = Min::acc(sfa, f[k]);
            sf[k] = sfa;
        }
        b0 = b1;
    }
    let (su, sf, p) = (&su[..], &sf[..], &p[..]);
    // Unclipped windows: when `s` starts a block, `p[s + span]` is `su[s]`, so one formula
    // serves every `s`.
    let full = n.saturating_sub(span);
    for (s, o) in out[..full].iter_mut().enumerate() {
        *o = Max::acc(su[s], Min::acc(sf[s], p[s + span]));
    }
    // Windows clipped at the end reach at most into the last block.
    let last_block = (n - 1) / len * len;
    for (s, o) in out.iter_mut().enumerate().skip(full) {
        *o = if s >= last_block { su[s] } else { Max::acc(su[s], Min::acc(sf[s], p[n - 1])) };
    }
}

/// `buf[t]` becomes the fold of `buf[t..]`. (Folding four pieces side by side to break
/// the dependency chain measured no faster.)
pub(crate) fn suffix_fold<L: Lattice>(buf: &mut [f64]) {
    let mut acc = L::ID;
    for v in buf.iter_mut().rev() {
        acc = L::acc(acc, *v);
        *v = acc;
    }
}

/// `buf[t]` becomes the `L`-fold of `buf[t + a ..= t + a + len - 1]` (clipped at the end),
/// with `2 <= len <= n` and `a < n`: van Herk/Gil-Werman over blocks of `len` samples, for
/// the evaluator's long columns and the tabular scorer's short segments alike.
///
/// Each window's value is `L::acc(suffix fold of its start's block, prefix fold of the
/// next block up to its end)`, each fold taken in sample order from `L::ID`: the same
/// operations in the same order whatever the loop shapes below, so the same bits (signed
/// zeros included; a NaN sample is skipped, as `L::acc` does).
pub(crate) fn van_herk<L: Lattice>(
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
    // Prefix folds run forwards and suffix folds backwards inside each block. Each fold is
    // a dependency chain, so two blocks run side by side: four independent chains.
    let mut b0 = 0;
    while b0 + 2 * len <= n {
        let (x0, x1) = buf[b0..b0 + 2 * len].split_at(len);
        let (p0, p1) = pre[b0..b0 + 2 * len].split_at_mut(len);
        let (s0, s1) = suf[b0..b0 + 2 * len].split_at_mut(len);
        let (mut pa0, mut pa1, mut sa0, mut sa1) = (L::ID, L::ID, L::ID, L::ID);
        for j in 0..len {
            let k = len - 1 - j;
            pa0 = L::acc(pa0, x0[j]);
            p0[j] = pa0;
            pa1 = L::acc(pa1, x1[j]);
            p1[j] = pa1;
            sa0 = L::acc(sa0, x0[k]);
            s0[k] = sa0;
            sa1 = L::acc(sa1, x1[k]);
            s1[k] = sa1;
        }
        b0 += 2 * len;
    }
    while b0 < n {
        let b1 = (b0 + len).min(n);
        let (x, p, s) = (&buf[b0..b1], &mut pre[b0..b1], &mut suf[b0..b1]);
        let m = x.len();
        let (mut pa, mut sa) = (L::ID, L::ID);
        for j in 0..m {
            pa = L::acc(pa, x[j]);
            p[j] = pa;
            sa = L::acc(sa, x[m - 1 - j]);
            s[m - 1 - j] = sa;
        }
        b0 = b1;
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
