//! The exact optimal window rate `W*` of a persistent task on any grid world.
//!
//! **The problem.** The state is `(cell, tau_1, ..., tau_k)`, `tau_j` being the steps since
//! region `j` last held, capped at `N_j`; a step earns `psi = 1` when every `tau_j < N_j`
//! after it (the `N_j`-step windows ending there all visited their region). The optimal
//! long-run share of such steps is the gain of an average-reward MDP. The world is given as
//! plain [`Moves`]: where each intended action leads from each state, the probability `p`
//! that it is taken (else one of the other three, each `(1 - p) / 3`), and the start set.
//!
//! **Components.** The moves are reversible (every move can be undone, as on a grid with
//! walls), so the states split into connected components, and a component is a world of its
//! own: the robot never leaves it, and within it every cell can be reached from every other.
//! Each component is solved separately. Its optimal gain is the same from every state of it
//! (the clocks forget the past after `N_j` steps, and any cell can be reached), and a
//! component that lacks a cell of some region has gain 0: that window is never kept. `W*`
//! is the mean over the start set of the gain of the start's component.
//!
//! **Reachable states only.** A cell outside region `j` stores `tau_j` in `1..=N_j` as
//! `u_j = tau_j - 1`, a cell inside stores only `u_j = 0`. Of the `cells * N_1 * ... * N_k`
//! combinations, only those some walk can produce are kept (14% on the case study): the
//! closure of the fresh state of every cell under every move, found by propagating bit
//! sets. Any closed set of states has the component's gain, so nothing is lost.
//!
//! **Gauss-Seidel in time order.** A step advances every clock by one unless it enters a
//! region, so sweeping the states from old clocks to fresh ones (lexicographically by the
//! clocks of all regions but the one with the longest window, decreasing; that one's clock
//! runs along each contiguous row) updates most states from successors already updated in
//! the same sweep: one sweep follows a walk about once round the regions, 34 steps on the
//! case study, instead of one step. The states then advance by different numbers of steps per
//! sweep, so the gain cannot be read off the change of the values. Each update subtracts
//! an estimate `g` of the gain per step, and a second table tracks how many steps each
//! value spans (its horizon, one more than its successors' along the chosen action); after
//! each sweep `g += mean(change of V) / mean(change of horizon)`, a Newton step on the
//! drift, held in `[0, 1]` (a step's reward is 0 or 1: a step past it fed a drift that grew
//! without bound on a slow two-room world). At `g = W*` the fixed points of the update are exactly the solutions of the
//! average-reward equation. Once the steps per sweep settle the horizons are no longer
//! tracked. Nearly deterministic worlds can make the sweeps oscillate; when the changes
//! stop shrinking, the updates are damped (`V += step * (update - V)`, the same fixed
//! points). Values are `f64`.
//!
//! **The bracket.** For any values `V` and the Bellman operator `T`, every state's optimal
//! gain lies in `[min(T V - V), max(T V - V)]`. When the sweeps settle, one pass computes
//! that bracket (widened by a bound on its rounding), and the solver stops when it is
//! narrower than the tolerance. It is computed again after the last sweep allowed, so
//! [`Optimum::lower`] and [`Optimum::upper`] always bound `W*`, converged or not. Worlds
//! that mix slowly (nearly deterministic ones with two equally good places to wait) can
//! need thousands of sweeps, as plain value iteration does.
//!
//! **Budgets.** [`SolveConfig::max_states`] bounds the states stored and the work spent
//! finding them, and [`SolveConfig::max_iterations`] the sweeps: a task over the budget is
//! refused before its tables are allocated.

use std::fmt;

use crate::Error;
use crate::eval::{Controller, Decision, RegionTable};
use crate::moves::Moves;

mod states;
mod sweep;

use states::{Clocks, Table, World};

/// How the solver runs and how much it may use.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolveConfig {
    /// Stop when the bracket `[lower, upper]` around `W*` is narrower than this.
    pub tolerance: f64,
    /// Give up after this many sweeps per component (the bracket is still valid).
    pub max_iterations: usize,
    /// The most states the solver stores (at most `2^31 - 1`). Refused before their tables
    /// are allocated: a task with more reachable states, or whose tables would take more
    /// than 64 bytes per state of this, or whose full state space (`cells * N_1 * ... *
    /// N_k`) has more than 32 times this many states (or `cells * N_1 * ... * N_k / max
    /// N_j` more than this many rows), too many to search for the reachable ones.
    pub max_states: usize,
}

/// The optimal window rate and how it was found.
#[derive(Clone, PartialEq)]
pub struct Optimum {
    /// `W*`, the midpoint of the bracket.
    pub gain: f64,
    /// A lower bound on `W*`.
    pub lower: f64,
    /// An upper bound on `W*`.
    pub upper: f64,
    /// Sweeps done (the most over the components), not counting the passes that compute the
    /// bracket.
    pub iterations: usize,
    /// Whether every component's bracket closed below the tolerance.
    pub converged: bool,
    /// States solved: the reachable `(cell, clocks)` states of the start components.
    pub states: usize,
    clocks: Clocks,
    p: f64,
    /// Per state of the world: the regions it lies in, one bit each, in the solver's order.
    mask: Vec<u8>,
    /// Per state of the world: its solved component and its index there, or `None`.
    place: Vec<Option<(u32, u32)>>,
    tables: Vec<Table>,
}

/// Acts greedily on the values of an [`Optimum`], tracking `tau` itself.
#[derive(Clone, Debug)]
pub struct OptimalController<'a> {
    optimum: &'a Optimum,
    /// `tau_j` in the solver's order of the regions.
    tau: [usize; MAX_REGIONS],
    fresh: bool,
}

/// The most regions a task may have (a cell's regions are the bits of a `u8`).
const MAX_REGIONS: usize = 8;

/// States of the full space searched for reachable ones, at most, per state of
/// [`SolveConfig::max_states`].
const SEARCH_PER_STATE: u128 = 32;

/// Bytes of tables, at most, per state of [`SolveConfig::max_states`].
const BYTES_PER_STATE: usize = 64;

impl Default for SolveConfig {
    /// Tolerance 1e-4, at most 1000 sweeps, at most 16M states (1 GiB of tables).
    fn default() -> SolveConfig {
        SolveConfig { tolerance: 1e-4, max_iterations: 1000, max_states: 1 << 24 }
    }
}

/// `W*` for `regions` on the world `moves`: exact up to [`SolveConfig::tolerance`].
pub fn solve(moves: &Moves, regions: &RegionTable, config: SolveConfig) -> Result<Optimum, Error> {
    solve_windows(moves, &regions.holds, &regions.horizons, config)
}

/// `W*` for regions given as plain data: `holds[j][s]` says whether region `j` holds in
/// state `s`, and `horizons[j]` is its window `N_j`.
pub fn solve_windows(
    moves: &Moves,
    holds: &[Vec<bool>],
    horizons: &[usize],
    config: SolveConfig,
) -> Result<Optimum, Error> {
    moves.check()?;
    let n = moves.states();
    if config.tolerance.is_nan() || config.tolerance <= 0.0 {
        return Err(Error::Config(format!(
            "the optimum needs a tolerance above 0, not {}",
            config.tolerance
        )));
    }
    let k = horizons.len();
    if k == 0 || holds.len() != k {
        return Err(Error::Config(if k == 0 {
            "the task has no region".into()
        } else {
            format!("{} region tables for {k} windows", holds.len())
        }));
    }
    if k > MAX_REGIONS {
        return Err(Error::Config(format!(
            "the optimum handles at most {MAX_REGIONS} regions, and the task has {k}; use fewer \
             regions"
        )));
    }
    if holds.iter().any(|h| h.len() != n) {
        return Err(Error::Config(format!(
            "the regions were not computed on this world, which has {n} states"
        )));
    }
    if horizons.contains(&0) {
        return Err(Error::Config("a region has a zero-step window".into()));
    }
    let clocks = Clocks::new(horizons);
    let mask: Vec<u8> = (0..n)
        .map(|s| (0..k).fold(0u8, |m, j| m | (u8::from(holds[clocks.order[j]][s]) << j)))
        .collect();
    let comp = moves.components()?;
    let count = comp.iter().map(|&c| c as usize + 1).max().unwrap_or(0);
    // The states of each component, and whether it can keep every window.
    let mut members: Vec<Vec<u32>> = vec![Vec::new(); count];
    for (s, &c) in comp.iter().enumerate() {
        members[c as usize].push(s as u32);
    }
    let mut starts_in = vec![0usize; count];
    for &s in &moves.starts {
        starts_in[comp[s as usize] as usize] += 1;
    }
    let all = (1u16 << k) - 1;
    let solvable: Vec<usize> = (0..count)
        .filter(|&c| {
            let seen = members[c].iter().fold(0u16, |m, &s| m | mask[s as usize] as u16);
            starts_in[c] > 0 && seen == all
        })
        .collect();
    // The budget, before anything large is allocated.
    let windows = horizons.iter().map(|h| h.to_string()).collect::<Vec<_>>().join(" x ");
    let cells: usize = solvable.iter().map(|&c| members[c].len()).sum();
    let what = format!("{cells} cells x windows {windows}");
    // Indices are `u32`.
    let limit = config.max_states.min(u32::MAX as usize / 2);
    let dense = horizons.iter().fold(cells as u128, |a, &h| a.saturating_mul(h as u128));
    let rows = (cells as u128).saturating_mul(clocks.prefixes as u128);
    let search = (limit as u128).saturating_mul(SEARCH_PER_STATE);
    if dense > search || rows > limit as u128 {
        return Err(Error::Config(format!(
            "the exact optimum's state space has {dense} states ({what}), too many to search \
             (the limit is {search}); use fewer regions or shorter windows"
        )));
    }
    let mut place: Vec<Option<(u32, u32)>> = vec![None; n];
    let mut tables = Vec::new();
    let mut outcomes = Vec::new();
    let (mut states, mut bytes) = (0usize, 0usize);
    for &c in &solvable {
        let cells = &members[c];
        let local_of = |s: u32| cells.binary_search(&s).unwrap_or(0) as u32;
        let world = World {
            dest: cells.iter().map(|&s| moves.dest[s as usize].map(local_of)).collect(),
            mask: cells.iter().map(|&s| mask[s as usize]).collect(),
        };
        let Some((reach, count)) = clocks.reachable(&world, limit - states) else {
            return Err(Error::Config(format!(
                "the exact optimum needs more than {limit} reachable states, the limit \
                 ({what}); use fewer regions or shorter windows"
            )));
        };
        states += count;
        bytes += clocks.table_bytes(&reach, count, world.dest.len());
        if bytes > limit.saturating_mul(BYTES_PER_STATE) {
            return Err(Error::Config(format!(
                "the exact optimum needs {} MiB of tables for {states} reachable states \
                 ({what}), more than the limit of {} MiB; use fewer regions or shorter windows",
                bytes.div_ceil(1 << 20),
                limit.saturating_mul(BYTES_PER_STATE) >> 20
            )));
        }
        let table = clocks.table(world, &reach, count)?;
        drop(reach);
        let (table, outcome) = table.solve(moves.p, config)?;
        for (i, &s) in cells.iter().enumerate() {
            place[s as usize] = Some((tables.len() as u32, i as u32));
        }
        tables.push(table);
        outcomes.push((c, outcome));
    }
    // The mean over the starts; components that cannot keep every window add 0.
    let total = moves.starts.len() as f64;
    let (mut lower, mut upper) = (0.0, 0.0);
    for (c, o) in &outcomes {
        let share = starts_in[*c] as f64 / total;
        lower += share * o.lower;
        upper += share * o.upper;
    }
    Ok(Optimum {
        gain: (lower + upper) / 2.0,
        lower,
        upper,
        iterations: outcomes.iter().map(|(_, o)| o.sweeps).max().unwrap_or(0),
        converged: outcomes.iter().all(|(_, o)| o.converged),
        states,
        clocks,
        p: moves.p,
        mask,
        place,
        tables,
    })
}

impl fmt::Debug for Optimum {
    /// The figures, without the value tables.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Optimum")
            .field("gain", &self.gain)
            .field("lower", &self.lower)
            .field("upper", &self.upper)
            .field("iterations", &self.iterations)
            .field("converged", &self.converged)
            .field("states", &self.states)
            .field("components", &self.tables.len())
            .finish_non_exhaustive()
    }
}

impl Optimum {
    /// A controller that acts greedily on the computed values.
    pub fn controller(&self) -> OptimalController<'_> {
        OptimalController { optimum: self, tau: [0; MAX_REGIONS], fresh: true }
    }
}

impl Controller for OptimalController<'_> {
    fn reset(&mut self) {
        self.fresh = true;
    }

    fn act(&mut self, s: usize) -> Decision {
        let o = self.optimum;
        let n = &o.clocks.n;
        let Some(&mask) = o.mask.get(s) else {
            // Not a state of the solved world: take no valid action.
            return Decision { action: usize::MAX, option: 0, leg: 0 };
        };
        if self.fresh {
            // The start state counts as visited for the regions it lies in.
            for (j, t) in self.tau[..n.len()].iter_mut().enumerate() {
                *t = if mask >> j & 1 == 1 { 0 } else { n[j] };
            }
            self.fresh = false;
        }
        let Some((comp, cell)) = o.place[s] else {
            // A component that cannot keep every window: every action is as good.
            return Decision { action: 0, option: 0, leg: 0 };
        };
        let table = &o.tables[comp as usize];
        let mut w = [0.0f64; 4];
        let mut u = [0usize; MAX_REGIONS];
        for (d, wd) in w.iter_mut().enumerate() {
            let to = table.dest[cell as usize][d] as usize;
            let to_mask = table.mask[to];
            let mut kept = true;
            for (j, uj) in u[..n.len()].iter_mut().enumerate() {
                let inside = to_mask >> j & 1 == 1;
                let tau = if inside { 0 } else { (self.tau[j] + 1).min(n[j]) };
                kept &= tau < n[j];
                *uj = if inside { 0 } else { tau - 1 };
            }
            // Every successor of a reachable state is stored; 0 is only a fallback.
            let value = table.value(&o.clocks, to, &u[..n.len()]).unwrap_or(0.0);
            *wd = f64::from(u8::from(kept)) + value;
        }
        let q = (1.0 - o.p) / 3.0;
        let sum: f64 = w.iter().sum();
        let value = |a: usize| o.p * w[a] + q * (sum - w[a]);
        let action = (1..4).fold(0, |best, a| if value(a) > value(best) { a } else { best });
        Decision { action, option: 0, leg: 0 }
    }

    fn observe(&mut self, next: usize) {
        let o = self.optimum;
        let mask = o.mask.get(next).copied().unwrap_or(0);
        for (j, t) in self.tau[..o.clocks.n.len()].iter_mut().enumerate() {
            *t = if mask >> j & 1 == 1 { 0 } else { (*t + 1).min(o.clocks.n[j]) };
        }
    }
}
