//! The offline evaluator's kernels over plain slices, for code that computes the operand
//! signals itself (the `hstl!` macro's generated monitors).
//!
//! [`Evaluator`](crate::Evaluator) is an interpreter: it walks a [`Formula`](crate::Formula)
//! and calls these kernels on whole columns. A monitor generated for one formula can
//! compute its state subformulas as fused loops over its own state type and hand the
//! temporal structure to the very same code: [`Kernels::always`], [`Kernels::eventually`]
//! and [`Kernels::until`] (and the past-time [`Kernels::once`], [`Kernels::historically`],
//! [`Kernels::since`], [`Kernels::prev`], with [`Kernels::next`]) turn an operand signal
//! into the operator's signal in place, and
//! [`pieces`] evaluates a formula with a finite horizon in cache-sized pieces, as the
//! evaluator does. The values are the evaluator's, bit for bit, NaN policy included (see
//! [`offline`](crate::offline)).
//!
//! ```
//! use hstl_robustness::kernels::{self, Kernels};
//! use hstl_robustness::{Bound, Interval};
//!
//! // rho(eventually[0..=1] x > 2, t) on x = 1, 5, 3, 0.
//! let xs = [1.0_f64, 5.0, 3.0, 0.0];
//! let mut k = Kernels::new();
//! let window = Interval { start: 0, end: Bound::Inclusive(1) };
//! let signal = kernels::pieces(xs.len(), 1, |steps| {
//!     let mut atom: Vec<f64> = xs[steps].iter().map(|x| x - 2.0).collect();
//!     k.eventually(&window, &mut atom);
//!     atom
//! });
//! assert_eq!(signal, [3.0, 3.0, 1.0, -2.0]);
//! ```

use std::ops::Range;

use crate::primitives::{
    Lattice, Max, Min, block_until, piece_len, shift_left, suffix_fold, van_herk,
};
use crate::{Bound, Interval};

const INF: f64 = f64::INFINITY;
const NEG_INF: f64 = f64::NEG_INFINITY;

/// The scratch buffers of the sliding-window and until kernels. Keep one and reuse it:
/// once its buffers are as long as the longest signal, the kernels allocate nothing.
#[derive(Clone, Debug, Default)]
pub struct Kernels {
    scratch_a: Vec<f64>,
    scratch_b: Vec<f64>,
    scratch_c: Vec<f64>,
}

impl Kernels {
    /// Kernels with no buffers yet.
    pub fn new() -> Kernels {
        Kernels::default()
    }

    /// `buf` holds `rho(g, t)` for every step of a trace; it becomes
    /// `rho(always[interval] g, t)`: the minimum over the window at `t`, clipped at the end
    /// of `buf`, `+inf` when empty, NaN samples skipped.
    pub fn always(&mut self, interval: &Interval, buf: &mut [f64]) {
        self.window::<Min>(buf, interval);
    }

    /// `buf` holds `rho(g, t)` for every step of a trace; it becomes
    /// `rho(eventually[interval] g, t)`: the maximum over the window at `t`, clipped at the
    /// end of `buf`, `-inf` when empty, NaN samples skipped.
    pub fn eventually(&mut self, interval: &Interval, buf: &mut [f64]) {
        self.window::<Max>(buf, interval);
    }

    /// `lhs` holds `rho(f, t)` and `out` holds `rho(g, t)`, equally long; `out` becomes
    /// `rho(f until[interval] g, t)`. `lhs` is used as scratch and left unspecified.
    ///
    /// # Panics
    /// When `lhs` is shorter than `out`.
    pub fn until(&mut self, interval: &Interval, lhs: &mut [f64], out: &mut [f64]) {
        let n = out.len();
        let lhs = &mut lhs[..n];
        let a = interval.start;
        if interval.is_empty() || a >= n {
            out.fill(NEG_INF);
            return;
        }
        // rho(t) = min(always[0..a] lhs at t, U(t + a)), where U is `until[0..=len-1]`
        // (or unbounded) at `t + a`: the `lhs` samples before `t + a` bound every candidate.
        match interval.last_offset() {
            None => {
                let mut next = NEG_INF;
                for (g, f) in out.iter_mut().zip(lhs.iter()).rev() {
                    next = Max::acc(Min::acc(next, *f), Min::acc(INF, *g));
                    *g = next;
                }
            }
            // A span past the trace's end is as good as `n`, and cannot overflow.
            Some(last) => block_until(
                lhs,
                out,
                (last - a).min(n),
                [&mut self.scratch_a, &mut self.scratch_b, &mut self.scratch_c],
            ),
        }
        if a > 0 {
            self.window::<Min>(lhs, &Interval { start: 0, end: Bound::Exclusive(a) });
            for t in 0..n - a {
                out[t] = Min::acc(lhs[t], out[t + a]);
            }
            out[n - a..].fill(NEG_INF);
        }
    }

    /// `buf` holds `rho(g, t)` for every step of a trace; it becomes
    /// `rho(once[interval] g, t)`: the maximum over the past window at `t`, clipped at the
    /// start of `buf`, `-inf` when empty, NaN samples skipped. It is the time reversal of
    /// `eventually` (`rev(E(rev(v)))`), so it costs what [`Kernels::eventually`] does,
    /// whatever the window.
    pub fn once(&mut self, interval: &Interval, buf: &mut [f64]) {
        buf.reverse();
        self.window::<Max>(buf, interval);
        buf.reverse();
    }

    /// `buf` holds `rho(g, t)`; it becomes `rho(historically[interval] g, t)`: the minimum
    /// over the past window, `+inf` when empty, NaN samples skipped (`always`, reversed).
    pub fn historically(&mut self, interval: &Interval, buf: &mut [f64]) {
        buf.reverse();
        self.window::<Min>(buf, interval);
        buf.reverse();
    }

    /// `lhs` holds `rho(f, t)` and `out` holds `rho(g, t)`, equally long; `out` becomes
    /// `rho(f since[interval] g, t)`, the time reversal of `until`. `lhs` is used as
    /// scratch and left unspecified.
    ///
    /// # Panics
    /// When `lhs` is shorter than `out`.
    pub fn since(&mut self, interval: &Interval, lhs: &mut [f64], out: &mut [f64]) {
        let n = out.len();
        let lhs = &mut lhs[..n];
        lhs.reverse();
        out.reverse();
        self.until(interval, lhs, out);
        out.reverse();
    }

    /// `buf` holds `rho(g, t)`; it becomes `rho(prev g, t)`: `rho(g, t - 1)`, and `+inf` at
    /// step 0 (and for a NaN sample, as `historically[1..=1]` skips it).
    pub fn prev(&mut self, buf: &mut [f64]) {
        let n = buf.len();
        if n == 0 {
            return;
        }
        buf.copy_within(..n - 1, 1);
        buf[0] = INF;
        buf.iter_mut().for_each(|v| *v = Min::acc(INF, *v));
    }

    /// `buf` holds `rho(g, t)`; it becomes `rho(next g, t)`: `rho(g, t + 1)`, and `+inf` at
    /// the last step (and for a NaN sample, as `always[1..=1]` skips it).
    pub fn next(&mut self, buf: &mut [f64]) {
        self.window::<Min>(buf, &Interval { start: 1, end: Bound::Inclusive(1) });
    }

    /// `buf[t]` becomes the `L`-fold of `buf` over the window of `i` at `t`, in place.
    pub(crate) fn window<L: Lattice>(&mut self, buf: &mut [f64], i: &Interval) {
        let n = buf.len();
        let a = i.start;
        if i.is_empty() || a >= n {
            buf.fill(L::ID);
            return;
        }
        let Some(last) = i.last_offset() else {
            // Unbounded: a suffix fold, then a shift by `a`.
            suffix_fold::<L>(buf);
            shift_left::<L>(buf, a);
            return;
        };
        // The window at `t` is `s ..= s + len - 1` with `s = t + a`, clipped at `n`.
        let len = (last - a).saturating_add(1);
        if len == 1 {
            buf.iter_mut().for_each(|v| *v = L::acc(L::ID, *v));
            shift_left::<L>(buf, a);
            return;
        }
        let len = len.min(n);
        van_herk::<L>(buf, a, len, &mut self.scratch_a, &mut self.scratch_b);
    }
}

/// `acc[t]` becomes `rho(f && g, t)` given `acc = rho(f, ·)` and `x = rho(g, ·)`: the
/// minimum, a NaN `x[t]` skipped. `acc` must hold no NaN (fold a first operand into
/// `+inf` with [`f64::min`] to drop its NaN), as every temporal operator's signal does.
///
/// # Panics
/// When `x` is shorter than `acc`.
pub fn and_into(acc: &mut [f64], x: &[f64]) {
    let x = &x[..acc.len()];
    acc.iter_mut().zip(x).for_each(|(a, b)| *a = Min::acc(*a, *b));
}

/// `acc[t]` becomes `rho(f || g, t)` given `acc = rho(f, ·)` and `x = rho(g, ·)`: the
/// maximum, a NaN `x[t]` skipped. `acc` must hold no NaN, as for [`and_into`].
///
/// # Panics
/// When `x` is shorter than `acc`.
pub fn or_into(acc: &mut [f64], x: &[f64]) {
    let x = &x[..acc.len()];
    acc.iter_mut().zip(x).for_each(|(a, b)| *a = Max::acc(*a, *b));
}

/// The signal of a formula with a finite horizon over `n` steps, computed in cache-sized
/// pieces as [`Evaluator`](crate::Evaluator) computes it.
///
/// `eval(lo..end)` must return the formula's signal on the sub-trace of steps `lo..end`
/// (`end - lo` values). `rho(t)` reads only steps `t ..= t + horizon`, so each piece of
/// steps is evaluated with the `horizon` steps after it, its windows clipped only where the
/// trace really ends; every buffer then stays in cache. A trace of at most twice a piece
/// is evaluated whole, with one call `eval(0..n)`. `horizon` must be the formula's horizon
/// (or more): a smaller one gives wrong values near the piece boundaries.
///
/// # Panics
/// When `eval` returns fewer values than asked for.
pub fn pieces(
    n: usize,
    horizon: usize,
    mut eval: impl FnMut(Range<usize>) -> Vec<f64>,
) -> Vec<f64> {
    let piece = piece_len(horizon);
    if n / 2 <= piece {
        return eval(0..n);
    }
    let mut out = Vec::with_capacity(n);
    let mut lo = 0;
    while lo < n {
        let hi = (lo + piece).min(n);
        let end = hi.saturating_add(horizon).min(n);
        let v = eval(lo..end);
        out.extend_from_slice(&v[..hi - lo]);
        lo = hi;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{CmpOp, Expr, Formula, Trace, offline};

    /// `x` on a walk long enough to be cut in pieces, with NaN and infinite samples.
    fn column(n: usize) -> Vec<f64> {
        let mut state: u64 = 0x2016;
        (0..n)
            .map(|t| {
                state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                match t % 997 {
                    13 => f64::NAN,
                    14 => f64::INFINITY,
                    15 => f64::NEG_INFINITY,
                    _ => (state >> 40) as f64 / 16_777_216.0 - 0.5,
                }
            })
            .collect()
    }

    fn atom(c: f64) -> Formula {
        Formula::cmp(Expr::var(0), CmpOp::Gt, Expr::constant(c))
    }

    fn same(a: &[f64], b: &[f64]) -> bool {
        a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x == y || (x.is_nan() && y.is_nan()))
    }

    #[test]
    fn pieces_and_kernels_give_the_evaluators_signal() {
        let xs = column(40_000);
        let trace = Trace::from_columns(vec![xs.clone()]).expect("one column");
        let mut k = Kernels::new();
        let intervals = [
            Interval { start: 0, end: Bound::Inclusive(40) },
            Interval { start: 3, end: Bound::Exclusive(9) },
            Interval { start: 2, end: Bound::Inclusive(2) },
            Interval { start: 5, end: Bound::Exclusive(5) },
            Interval { start: 0, end: Bound::Inclusive(3000) },
        ];
        for i in intervals {
            let h = i.last_offset().unwrap_or(0);
            let f = Formula::always(i, atom(0.1));
            let got = pieces(xs.len(), h, |r| {
                let mut v: Vec<f64> = xs[r].iter().map(|x| x - 0.1).collect();
                k.always(&i, &mut v);
                v
            });
            assert!(same(&got, &offline::signal(&f, &trace)), "always{i}");
            let f = Formula::eventually(i, atom(0.1));
            let got = pieces(xs.len(), h, |r| {
                let mut v: Vec<f64> = xs[r].iter().map(|x| x - 0.1).collect();
                k.eventually(&i, &mut v);
                v
            });
            assert!(same(&got, &offline::signal(&f, &trace)), "eventually{i}");
            let f = Formula::until(i, atom(-0.4), atom(0.3));
            let got = pieces(xs.len(), h, |r| {
                let mut lhs: Vec<f64> = xs[r.clone()].iter().map(|x| x + 0.4).collect();
                let mut out: Vec<f64> = xs[r].iter().map(|x| x - 0.3).collect();
                k.until(&i, &mut lhs, &mut out);
                out
            });
            assert!(same(&got, &offline::signal(&f, &trace)), "until{i}");
        }
        // Unbounded windows: whole signals.
        let mut v: Vec<f64> = xs.iter().map(|x| x - 0.1).collect();
        k.always(&Interval { start: 4, end: Bound::Unbounded }, &mut v);
        let f = Formula::always(Interval { start: 4, end: Bound::Unbounded }, atom(0.1));
        assert!(same(&v, &offline::signal(&f, &trace)));
    }

    #[test]
    fn folds_skip_nan_operands() {
        let mut acc = vec![1.0, 2.0, f64::INFINITY];
        and_into(&mut acc, &[0.5, f64::NAN, 3.0]);
        assert!(same(&acc, &[0.5, 2.0, 3.0]));
        or_into(&mut acc, &[f64::NAN, 4.0, f64::NEG_INFINITY]);
        assert!(same(&acc, &[0.5, 4.0, 3.0]));
    }
}
