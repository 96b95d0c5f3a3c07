//! The Gauss-Seidel sweeps over one component's table: the Bellman update with the
//! Newton gain, damping, and the bracket `[min(T V - V), max(T V - V)]` (see the module
//! docs of [`super`]).

use std::cell::Cell;

use super::SolveConfig;
use super::states::{Piece, Table};
use crate::Error;

/// What one component's solve found.
pub(super) struct Outcome {
    pub(super) lower: f64,
    pub(super) upper: f64,
    pub(super) sweeps: usize,
    pub(super) converged: bool,
}

/// Sweeps without the spread of the changes halving before the updates are damped more.
const PATIENCE: usize = 12;

/// A sweep's totals over the entries.
struct SweepStats {
    value_change: f64,
    horizon_change: f64,
    lo: f64,
    hi: f64,
}

impl Table {
    /// Solves the component: Gauss-Seidel sweeps with the Newton gain, then the bracket.
    pub(super) fn solve(self, p: f64, config: SolveConfig) -> Result<(Table, Outcome), Error> {
        let mut table = self;
        let count = table.values.len();
        let mut horizon: Vec<f64> = vec![0.0; count];
        let mut gain = 0.0f64;
        // Steps per sweep, from the horizons until it settles, then held.
        let (mut steps, mut settled) = (0.0f64, 0);
        // Nearly deterministic worlds can make the sweeps oscillate: when the spread of the
        // changes stops halving and keeps rising now and then (rather than shrinking slowly),
        // the updates are damped, which keeps their fixed points.
        let mut damping: f64 = 1.0;
        let (mut best, mut since, mut rises, mut last) = (f64::INFINITY, 0, 0, f64::INFINITY);
        let mut trigger = 2.0 * config.tolerance;
        let mut sweeps = 0;
        let mut bracket = None;
        while sweeps < config.max_iterations {
            sweeps += 1;
            let track = settled < 2;
            let horizon = track.then_some(&mut horizon[..]);
            let stats = table.sweep(horizon, gain, p, damping);
            if !(stats.value_change.is_finite() && stats.lo.is_finite() && stats.hi.is_finite()) {
                return Err(Error::Config("value iteration diverged".into()));
            }
            let dv = stats.value_change / count as f64;
            if track {
                let dh = stats.horizon_change / count as f64;
                settled = if (dh - steps).abs() < 0.02 * dh { settled + 1 } else { 0 };
                if sweeps >= 30 {
                    settled = 2;
                }
                steps = dh;
            }
            if steps > 0.0 && steps.is_finite() {
                // A step's reward is 0 or 1, so the gain lies in [0, 1]: a Newton step past
                // it (a sweep whose values moved far more than its horizons did) is held
                // there instead of feeding a drift that grows without bound.
                gain = (gain + damping * dv / steps).clamp(0.0, 1.0);
            }
            let spread = stats.hi - stats.lo;
            rises += usize::from(spread >= last);
            last = spread;
            if spread < best / 2.0 {
                (best, since, rises) = (spread, 0, 0);
            } else {
                since += 1;
                if since == PATIENCE {
                    if rises * 4 >= PATIENCE && damping > 0.2 {
                        damping *= 0.6;
                        settled = 0;
                    }
                    (best, since, rises) = (spread, 0, 0);
                }
            }
            if spread < trigger {
                let (lo, hi) = table.bracket(p);
                bracket = Some((lo, hi));
                if hi - lo < config.tolerance {
                    break;
                }
                trigger = spread / 2.0;
            }
        }
        let (lower, upper) = match bracket {
            Some(b) if b.1 - b.0 < config.tolerance => b,
            _ => table.bracket(p),
        };
        let converged = upper - lower < config.tolerance;
        // The controller needs the values and where they are, not the sweep's pieces.
        table.pieces = Vec::new();
        Ok((table, Outcome { lower, upper, sweeps, converged }))
    }

    /// One Gauss-Seidel sweep in place: each value becomes its Bellman update less `gain`;
    /// with `horizon`, each horizon becomes one more than its successors' along the chosen
    /// action.
    fn sweep(&mut self, horizon: Option<&mut [f64]>, gain: f64, p: f64, step: f64) -> SweepStats {
        let values = Cell::from_mut(&mut self.values[..]).as_slice_of_cells();
        let kernel = Kernel { q: (1.0 - p) / 3.0, p, gain, step };
        // The best action has the largest successor value, or the smallest when a slip is
        // likelier than the chosen action (`p < q`).
        let maximise = kernel.p >= kernel.q;
        match horizon {
            Some(h) => {
                let horizon = Cell::from_mut(h).as_slice_of_cells();
                if maximise {
                    kernel.run::<true, true>(&self.pieces, values, horizon)
                } else {
                    kernel.run::<true, false>(&self.pieces, values, horizon)
                }
            }
            None if maximise => kernel.run::<false, true>(&self.pieces, values, &[]),
            None => kernel.run::<false, false>(&self.pieces, values, &[]),
        }
    }

    /// `[min(T V - V), max(T V - V)]` over the stored states, in `f64` and widened by a
    /// bound on its rounding: it contains the component's optimal gain.
    fn bracket(&self, p: f64) -> (f64, f64) {
        let q = (1.0 - p) / 3.0;
        let values = &self.values;
        let (mut lo, mut hi, mut big) = (f64::INFINITY, f64::NEG_INFINITY, 0.0f64);
        for piece in &self.pieces {
            for i in 0..piece.len as usize {
                let w: [f64; 4] = std::array::from_fn(|d| {
                    let step = usize::from(piece.fixed >> d & 1 == 0);
                    let at = piece.at[d] as usize + i * step;
                    f64::from(piece.kept >> d & 1) + values[at]
                });
                let sum: f64 = w.iter().sum();
                let best =
                    w.iter().map(|&x| p * x + q * (sum - x)).fold(f64::NEG_INFINITY, f64::max);
                let own = values[piece.start as usize + i];
                let r = best - own;
                lo = lo.min(r);
                hi = hi.max(r);
                big = big.max(own.abs());
            }
        }
        // Each residual is a few roundings of sums of terms below `big + 1`.
        let slack = 64.0 * f64::EPSILON * (big + 1.0);
        (lo - slack, hi + slack)
    }
}

/// The Bellman update of one sweep, its constants hoisted.
struct Kernel {
    p: f64,
    q: f64,
    gain: f64,
    /// The step towards the update: 1, or less to damp oscillations.
    step: f64,
}

impl Kernel {
    /// Updates the entry `own` from its successors `at` (index, and whether the move keeps
    /// the windows), adding the changes to `sums` and `stats`.
    #[inline(always)]
    fn update<const TRACK: bool, const MAX: bool>(
        &self,
        values: &[Cell<f64>],
        horizon: &[Cell<f64>],
        at: [(usize, f64); 4],
        own: usize,
        sums: &mut (f64, f64),
        stats: &mut SweepStats,
    ) {
        let [a, b, c, d] = at.map(|(i, bonus)| values[i].get() + bonus);
        // Plain comparisons, which compile to min / max instructions rather than branches.
        let pick = |x: f64, y: f64| {
            if MAX {
                if y > x { y } else { x }
            } else if y < x {
                y
            } else {
                x
            }
        };
        let best = pick(pick(a, b), pick(c, d));
        let tv = self.q * (a + b + c + d) + (self.p - self.q) * best - self.gain;
        let own_value = &values[own];
        let change = tv - own_value.get();
        own_value.set(own_value.get() + self.step * change);
        sums.0 += change;
        stats.lo = if change < stats.lo { change } else { stats.lo };
        stats.hi = if change > stats.hi { change } else { stats.hi };
        if TRACK {
            let [ha, hb, hc, hd] = at.map(|(i, _)| horizon[i].get());
            // The horizon of the action `pick` chose, by the same comparisons.
            let pair = |x: (f64, f64), y: (f64, f64)| {
                let take = if MAX { y.0 > x.0 } else { y.0 < x.0 };
                (if take { y.0 } else { x.0 }, if take { y.1 } else { x.1 })
            };
            let hbest = pair(pair((a, ha), (b, hb)), pair((c, hc), (d, hd))).1;
            let th = 1.0 + self.q * (ha + hb + hc + hd) + (self.p - self.q) * hbest;
            let own_horizon = &horizon[own];
            let change = th - own_horizon.get();
            sums.1 += change;
            own_horizon.set(own_horizon.get() + self.step * change);
        }
    }

    /// Sweeps `pieces` in order, in place; tracks the horizons when `TRACK`.
    fn run<const TRACK: bool, const MAX: bool>(
        &self,
        pieces: &[Piece],
        values: &[Cell<f64>],
        horizon: &[Cell<f64>],
    ) -> SweepStats {
        let mut stats = SweepStats {
            value_change: 0.0,
            horizon_change: 0.0,
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
        };
        for piece in pieces {
            let step: [usize; 4] = std::array::from_fn(|d| usize::from(piece.fixed >> d & 1 == 0));
            let bonus: [f64; 4] = std::array::from_fn(|d| f64::from(piece.kept >> d & 1));
            let mut at = piece.at.map(|a| a as usize);
            let mut sums: (f64, f64) = (0.0, 0.0);
            for own in piece.start as usize..(piece.start + piece.len) as usize {
                let from = std::array::from_fn(|d| (at[d], bonus[d]));
                self.update::<TRACK, MAX>(values, horizon, from, own, &mut sums, &mut stats);
                for d in 0..4 {
                    at[d] += step[d];
                }
            }
            stats.value_change += sums.0;
            stats.horizon_change += sums.1;
        }
        stats
    }
}
