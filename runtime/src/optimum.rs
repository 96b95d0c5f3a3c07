//! The exact optimal window rate of a persistent task on the [`GridWorld`].
//!
//! The state is `(cell, tau_1, ..., tau_k)`, `tau_j` being the steps since region `j` last
//! held, capped at `N_j`; a step earns `psi = 1` when every `tau_j < N_j` after it (the
//! `N_j`-step windows ending there all visited their region). The optimal long-run share of
//! such steps is the gain `W*` of an average-reward MDP, found by relative value iteration.
//!
//! Since `tau_j = 0` exactly when the cell lies in region `j`, a cell outside region `j`
//! stores `tau_j` in `1..=N_j` as `u_j = tau_j - 1` (`N_j` values) and a cell inside
//! stores only `u_j = 0`: the table has `cells * N_1 * ... * N_k` entries (14.4M for the
//! case study), in `f32`. The iteration is damped (`V <- V + beta (T V - V)`), which
//! keeps it from oscillating on the grid's period-2 moves; for any `V`,
//! `min(T V - V) <= W* <= max(T V - V)`, so stopping when that span is below the tolerance
//! brackets `W*`.

use crate::eval::{Controller, Decision, RegionTable};
use crate::{Error, GridWorld};

/// How value iteration runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveConfig {
    /// Stop when `max(T V - V) - min(T V - V)` is below this.
    pub tolerance: f64,
    /// Give up after this many sweeps.
    pub max_iterations: usize,
    /// The damping `beta` in `(0, 1]`.
    pub damping: f32,
    /// Worker threads.
    pub threads: usize,
}

/// The optimal window rate and how it was found.
#[derive(Clone, Debug, PartialEq)]
pub struct Optimum {
    /// `W*`, the midpoint of the bracket.
    pub gain: f64,
    /// A lower bound on `W*`.
    pub lower: f64,
    /// An upper bound on `W*`.
    pub upper: f64,
    /// Sweeps done.
    pub iterations: usize,
    /// Whether the bracket closed below the tolerance.
    pub converged: bool,
    /// Entries in the value table.
    pub states: usize,
    values: Vec<f32>,
    layout: Layout,
}

/// Acts greedily on the values of an [`Optimum`], tracking `tau` itself.
#[derive(Clone, Debug)]
pub struct OptimalController<'a> {
    optimum: &'a Optimum,
    tau: Vec<usize>,
    fresh: bool,
}

/// The shape of the problem and of the value table.
#[derive(Clone, Debug, PartialEq)]
struct Layout {
    width: usize,
    cells: usize,
    p: f32,
    /// `dest[c][d]`: where direction `d` leads from cell `c`.
    dest: Vec<[usize; 4]>,
    /// `inside[j][c]`: cell `c` lies in region `j`.
    inside: Vec<Vec<bool>>,
    n: Vec<usize>,
    /// Strides of the `u_j` dimensions; the last is 1.
    stride: Vec<usize>,
    /// Entries per cell.
    per_cell: usize,
}

impl Default for SolveConfig {
    /// Tolerance 1e-4, at most 20000 sweeps, damping 0.9, two threads.
    fn default() -> SolveConfig {
        SolveConfig { tolerance: 1e-4, max_iterations: 20_000, damping: 0.9, threads: 2 }
    }
}

/// `W*` for `regions` on `grid` by relative value iteration.
pub fn solve(
    grid: &GridWorld,
    regions: &RegionTable,
    config: SolveConfig,
) -> Result<Optimum, Error> {
    let layout = Layout::new(grid, regions)?;
    let damping_ok = config.damping > 0.0 && config.damping <= 1.0;
    if !damping_ok || config.tolerance.is_nan() || config.tolerance <= 0.0 {
        return Err(Error::Config(format!(
            "value iteration needs damping in (0, 1] and tolerance > 0, not {config:?}"
        )));
    }
    let total = layout.cells * layout.per_cell;
    let mut values = vec![0.0f32; total];
    let mut next = vec![0.0f32; total];
    let threads = config.threads.clamp(1, layout.cells);
    let chunk_cells = layout.cells.div_ceil(threads);
    let (mut lower, mut upper) = (0.0f64, 1.0f64);
    let mut shift = 0.0f32;
    let mut iterations = 0;
    while iterations < config.max_iterations {
        iterations += 1;
        let bounds: Vec<(f32, f32)> = std::thread::scope(|scope| {
            let handles: Vec<_> = next
                .chunks_mut(chunk_cells * layout.per_cell)
                .enumerate()
                .map(|(i, out)| {
                    let (layout, values) = (&layout, &values);
                    scope.spawn(move || {
                        layout.sweep(values, out, i * chunk_cells, config.damping, shift)
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap_or((f32::NAN, f32::NAN))).collect()
        });
        lower = bounds.iter().map(|b| b.0 as f64).fold(f64::INFINITY, f64::min);
        upper = bounds.iter().map(|b| b.1 as f64).fold(f64::NEG_INFINITY, f64::max);
        std::mem::swap(&mut values, &mut next);
        if !(lower.is_finite() && upper.is_finite()) {
            return Err(Error::Config("value iteration diverged".into()));
        }
        // Keeps the values near zero: they would otherwise grow by W* per sweep.
        shift = config.damping * ((lower + upper) / 2.0) as f32;
        if upper - lower < config.tolerance {
            break;
        }
    }
    Ok(Optimum {
        gain: (lower + upper) / 2.0,
        lower,
        upper,
        iterations,
        converged: upper - lower < config.tolerance,
        states: total,
        values,
        layout,
    })
}

impl Layout {
    fn new(grid: &GridWorld, regions: &RegionTable) -> Result<Layout, Error> {
        let (width, cells) = (grid.width(), grid.width() * grid.height());
        if regions.holds.is_empty() {
            return Err(Error::Config("the task has no region".into()));
        }
        if regions.holds.iter().any(|h| h.len() != cells) {
            return Err(Error::Config("the regions were not computed on this grid".into()));
        }
        if regions.horizons.contains(&0) {
            return Err(Error::Config("a region has a zero-step window".into()));
        }
        let k = regions.horizons.len();
        let mut stride = vec![1usize; k];
        for j in (0..k.saturating_sub(1)).rev() {
            stride[j] = stride[j + 1].saturating_mul(regions.horizons[j + 1]);
        }
        let per_cell = stride[0].saturating_mul(regions.horizons[0]);
        if per_cell.saturating_mul(cells) > 400_000_000 {
            return Err(Error::Config(format!(
                "{cells} cells with windows {:?} need more than 400M values",
                regions.horizons
            )));
        }
        let dest = (0..cells)
            .map(|c| {
                let cell = crate::env::Cell { x: c % width, y: c / width };
                std::array::from_fn(|d| {
                    let to = grid.intended(cell, d);
                    to.y * width + to.x
                })
            })
            .collect();
        Ok(Layout {
            width,
            cells,
            p: grid.p() as f32,
            dest,
            inside: regions.holds.clone(),
            n: regions.horizons.clone(),
            stride,
            per_cell,
        })
    }

    /// The stored `u_j` of a cell for the true `tau_j`.
    fn u(&self, j: usize, cell: usize, tau: usize) -> usize {
        if self.inside[j][cell] { 0 } else { tau.clamp(1, self.n[j]) - 1 }
    }

    /// The `u_j` after moving from `cell` (with stored `u`) into `to`.
    fn next_u(&self, j: usize, cell: usize, u: usize, to: usize) -> usize {
        if self.inside[j][to] || self.inside[j][cell] { 0 } else { (u + 1).min(self.n[j] - 1) }
    }

    /// Whether the windows are kept on arriving in `to` with stored `u`.
    fn kept(&self, j: usize, to: usize, u: usize) -> bool {
        self.inside[j][to] || u + 1 < self.n[j]
    }

    /// One damped sweep of the cells from `first` on into `out`; returns the min and max of
    /// `T V - V` over the entries in use.
    fn sweep(
        &self,
        values: &[f32],
        out: &mut [f32],
        first: usize,
        beta: f32,
        shift: f32,
    ) -> (f32, f32) {
        let k = self.n.len();
        let last = k - 1;
        let q = (1.0 - self.p) / 3.0;
        let mut u = vec![0usize; k];
        let maximise = self.p >= q;
        let mut w = [(); 4].map(|_| vec![0.0f32; self.n[last]]);
        let mut diffs = vec![0.0f32; self.n[last]];
        let (mut lo8, mut hi8) = ([f32::INFINITY; 8], [f32::NEG_INFINITY; 8]);
        for (ci, out_cell) in out.chunks_mut(self.per_cell).enumerate() {
            let c = first + ci;
            let dest = self.dest[c];
            let len: Vec<usize> =
                (0..k).map(|j| if self.inside[j][c] { 1 } else { self.n[j] }).collect();
            u.iter_mut().for_each(|v| *v = 0);
            loop {
                // The prefix u_1..u_{k-1}: per direction, the target offset and whether
                // those regions keep their windows.
                let mut base = [0usize; 4];
                let mut ok = [true; 4];
                for d in 0..4 {
                    let to = dest[d];
                    base[d] = to * self.per_cell;
                    for (j, &uj) in u.iter().enumerate().take(last) {
                        let nu = self.next_u(j, c, uj, to);
                        base[d] += nu * self.stride[j];
                        ok[d] &= self.kept(j, to, nu);
                    }
                }
                let own: usize = (0..last).map(|j| u[j] * self.stride[j]).sum();
                let nk = self.n[last];
                let in_c = self.inside[last][c];
                let m = len[last];
                // Per direction, the value of arriving: one slice per direction, filled
                // with straight-line loops the compiler vectorises.
                for d in 0..4 {
                    let to = dest[d];
                    let in_to = self.inside[last][to];
                    let wd = &mut w[d][..m];
                    if in_to || in_c {
                        // u_k resets: every entry reads the same target.
                        let kept = ok[d] && (in_to || 1 < nk);
                        wd.fill(kept as u8 as f32 + values[base[d]]);
                    } else {
                        // u_k advances by one, capped at N_k - 1 (expired): entry `uk` reads
                        // `uk + 1`, and keeps its windows while that is below N_k - 1.
                        let bonus = ok[d] as u8 as f32;
                        let src = &values[base[d]..base[d] + nk];
                        let split = nk.saturating_sub(2);
                        for (x, &v) in wd[..split].iter_mut().zip(&src[1..]) {
                            *x = bonus + v;
                        }
                        wd[split..].fill(src[nk - 1]);
                    }
                }
                let old_row = &values[c * self.per_cell + own..][..m];
                let out_row = &mut out_cell[own..][..m];
                let (wa, wb, wc, wd) = (&w[0][..m], &w[1][..m], &w[2][..m], &w[3][..m]);
                for i in 0..m {
                    let sum = wa[i] + wb[i] + wc[i] + wd[i];
                    let best = if maximise {
                        wa[i].max(wb[i]).max(wc[i]).max(wd[i])
                    } else {
                        wa[i].min(wb[i]).min(wc[i]).min(wd[i])
                    };
                    let tv = q * sum + (self.p - q) * best;
                    let diff = tv - old_row[i];
                    diffs[i] = diff;
                    out_row[i] = old_row[i] + beta * diff - shift;
                }
                // Eight lanes, so that the reduction vectorises.
                let (chunks, rest) = diffs[..m].as_chunks::<8>();
                for chunk in chunks {
                    for l in 0..8 {
                        lo8[l] = if chunk[l] < lo8[l] { chunk[l] } else { lo8[l] };
                        hi8[l] = if chunk[l] > hi8[l] { chunk[l] } else { hi8[l] };
                    }
                }
                for &d in rest {
                    lo8[0] = lo8[0].min(d);
                    hi8[0] = hi8[0].max(d);
                }
                // Odometer over the prefix dimensions.
                let mut done = true;
                let mut j = last;
                while j > 0 {
                    j -= 1;
                    u[j] += 1;
                    if u[j] < len[j] {
                        done = false;
                        break;
                    }
                    u[j] = 0;
                }
                if done {
                    break;
                }
            }
        }
        let lo = lo8.iter().copied().fold(f32::INFINITY, f32::min);
        let hi = hi8.iter().copied().fold(f32::NEG_INFINITY, f32::max);
        (lo, hi)
    }

    /// Index of `(cell, tau)` in the value table.
    fn index(&self, cell: usize, tau: &[usize]) -> usize {
        cell * self.per_cell
            + (0..self.n.len()).map(|j| self.u(j, cell, tau[j]) * self.stride[j]).sum::<usize>()
    }
}

impl Optimum {
    /// A controller that acts greedily on the computed values.
    pub fn controller(&self) -> OptimalController<'_> {
        OptimalController { optimum: self, tau: self.layout.n.clone(), fresh: true }
    }
}

impl OptimalController<'_> {
    fn update_tau(&mut self, s: usize) {
        let l = &self.optimum.layout;
        for (j, t) in self.tau.iter_mut().enumerate() {
            *t =
                if l.inside[j].get(s).copied().unwrap_or(false) { 0 } else { (*t + 1).min(l.n[j]) };
        }
    }
}

impl Controller for OptimalController<'_> {
    fn reset(&mut self) {
        self.tau.clone_from(&self.optimum.layout.n);
        self.fresh = true;
    }

    fn act(&mut self, s: usize) -> Decision {
        if s >= self.optimum.layout.cells {
            // Not a cell of the solved grid: take no valid action.
            return Decision { action: usize::MAX, option: 0, leg: 0 };
        }
        if self.fresh {
            // The start state counts as visited for the regions it lies in.
            let l = &self.optimum.layout;
            for (j, t) in self.tau.iter_mut().enumerate() {
                *t = if l.inside[j][s] { 0 } else { l.n[j] };
            }
            self.fresh = false;
        }
        let l = &self.optimum.layout;
        let mut w = [0.0f32; 4];
        let mut next_tau = self.tau.clone();
        for (d, wd) in w.iter_mut().enumerate() {
            let to = l.dest[s][d];
            let mut kept = true;
            for (j, t) in next_tau.iter_mut().enumerate() {
                *t = if l.inside[j][to] { 0 } else { (self.tau[j] + 1).min(l.n[j]) };
                kept &= *t < l.n[j];
            }
            *wd = kept as u8 as f32 + self.optimum.values[l.index(to, &next_tau)];
        }
        let q = (1.0 - l.p) / 3.0;
        let sum: f32 = w.iter().sum();
        let value = |a: usize| l.p * w[a] + q * (sum - w[a]);
        let action = (1..4).fold(0, |best, a| if value(a) > value(best) { a } else { best });
        Decision { action, option: 0, leg: 0 }
    }

    fn observe(&mut self, next: usize) {
        self.update_tau(next);
    }
}

impl Optimum {
    /// The grid width the values were computed for.
    pub fn width(&self) -> usize {
        self.layout.width
    }
}
