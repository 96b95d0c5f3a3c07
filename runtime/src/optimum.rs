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

use std::cell::Cell;
use std::fmt;

use crate::Error;
use crate::eval::{Controller, Decision, RegionTable};
use crate::moves::Moves;

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

/// The windows in the solver's order: the longest window last, as the row dimension, the
/// others by decreasing window.
#[derive(Clone, Debug, PartialEq)]
struct Clocks {
    /// `n[j]`: `N` of the solver's region `j`.
    n: Vec<usize>,
    /// `order[j]`: the task's index of the solver's region `j`.
    order: Vec<usize>,
    /// Strides of the prefix clocks `u_0 .. u_{k-2}` in a prefix index; the last is 1.
    stride: Vec<usize>,
    /// The number of prefix indices, `N_0 * ... * N_{k-2}`.
    prefixes: usize,
}

/// One component's world, its cells numbered `0..cells`.
struct World {
    dest: Vec<[u32; 4]>,
    mask: Vec<u8>,
}

/// A run of consecutive `u_{k-1}` of one row `(cell, prefix)`, stored contiguously.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Segment {
    /// Index of the first entry in the value table.
    start: u32,
    len: u32,
    /// `u_{k-1}` of the first entry.
    u0: u32,
}

/// Consecutive entries whose successors in each direction are consecutive too, or one
/// entry (where the move resets the row's clock), and whose moves keep the windows alike:
/// entry `i` reads `at[d] + i` in direction `d` (`at[d]` when bit `d` of `fixed` is set) and
/// earns 1 when bit `d` of `kept` is set. The sweep runs over these.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Piece {
    start: u32,
    len: u32,
    at: [u32; 4],
    fixed: u8,
    kept: u8,
}

/// The solved values of one component.
#[derive(Clone, Debug, PartialEq)]
struct Table {
    dest: Vec<[u32; 4]>,
    mask: Vec<u8>,
    segs: Vec<Segment>,
    pieces: Vec<Piece>,
    /// Per row `cell * prefixes + prefix`: its first segment and the number of them.
    rows: Vec<(u32, u32)>,
    values: Vec<f64>,
}

/// What one component's solve found.
struct Outcome {
    lower: f64,
    upper: f64,
    sweeps: usize,
    converged: bool,
}

/// The most regions a task may have (a cell's regions are the bits of a `u8`).
const MAX_REGIONS: usize = 8;

/// States of the full space searched for reachable ones, at most, per state of
/// [`SolveConfig::max_states`].
const SEARCH_PER_STATE: u128 = 32;

/// Bytes of tables, at most, per state of [`SolveConfig::max_states`].
const BYTES_PER_STATE: usize = 64;

/// Sweeps without the spread of the changes halving before the updates are damped more.
const PATIENCE: usize = 12;

/// A sweep's totals over the entries.
struct SweepStats {
    value_change: f64,
    horizon_change: f64,
    lo: f64,
    hi: f64,
}

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

impl Clocks {
    fn new(horizons: &[usize]) -> Clocks {
        let k = horizons.len();
        // The longest window is the row (the longest contiguous runs); the others lead by
        // decreasing window, since the leading region's entries are the sweep's breaks and
        // the one with the longest window is entered least often. Stable: ties keep the
        // task's order.
        let mut order: Vec<usize> = (0..k).collect();
        order.sort_by_key(|&j| std::cmp::Reverse(horizons[j]));
        order.rotate_left(1);
        let n: Vec<usize> = order.iter().map(|&j| horizons[j]).collect();
        let mut stride = vec![1usize; k - 1];
        for j in (0..stride.len().saturating_sub(1)).rev() {
            stride[j] = stride[j + 1] * n[j + 1];
        }
        let prefixes = n[..k - 1].iter().product();
        Clocks { n, order, stride, prefixes }
    }

    fn last(&self) -> usize {
        self.n.len() - 1
    }

    /// The cap `N_j - 1` of a stored clock (`tau_j = N_j`, expired).
    fn cap(&self, j: usize) -> usize {
        self.n[j] - 1
    }

    /// The stored clock `u_j` after moving from a cell with regions `from` into one with
    /// regions `to`.
    fn next_u(&self, j: usize, u: usize, from: u8, to: u8) -> usize {
        if (from | to) >> j & 1 == 1 { 0 } else { (u + 1).min(self.cap(j)) }
    }

    /// Whether window `j` is kept on arriving in a cell with regions `to` with clock `u`.
    fn kept(&self, j: usize, u: usize, to: u8) -> bool {
        to >> j & 1 == 1 || u < self.cap(j)
    }

    /// The prefix clocks of a prefix index.
    fn prefix(&self, index: usize, out: &mut [usize]) {
        for (j, u) in out.iter_mut().enumerate() {
            *u = index / self.stride[j] % self.n[j];
        }
    }

    /// The prefix index reached by moving from regions `from` into `to` with prefix clocks
    /// `u`, and whether those windows are kept on arrival.
    fn next_prefix(&self, u: &[usize], from: u8, to: u8) -> (usize, bool) {
        let mut index = 0;
        let mut kept = true;
        for (j, &uj) in u.iter().enumerate() {
            let nu = self.next_u(j, uj, from, to);
            index += nu * self.stride[j];
            kept &= self.kept(j, nu, to);
        }
        (index, kept)
    }

    /// The stored clocks of a cell with regions `mask` for the true `tau`.
    fn stored<'a>(&'a self, mask: u8, tau: &'a [usize]) -> impl Iterator<Item = usize> + 'a {
        tau.iter().enumerate().map(
            move |(j, &t)| {
                if mask >> j & 1 == 1 { 0 } else { t.clamp(1, self.n[j]) - 1 }
            },
        )
    }

    /// Prefix indices from old clocks to fresh ones: decreasing, so lexicographically by
    /// `u_0`, then `u_1`, ... A step that enters no region advances every clock, so it leads
    /// to a state swept earlier; so does entering region `j` while some clock before `u_j`
    /// advances. Only entering region 0 (or another while the ones before it have expired)
    /// leads to a state swept later: about once a round of the regions.
    fn sweep_order(&self) -> Vec<u32> {
        (0..self.prefixes as u32).rev().collect()
    }

    /// Words of the row bit set over `u_{k-1}`.
    fn words(&self) -> usize {
        self.n[self.last()].div_ceil(64)
    }

    /// The states reachable from the fresh state of every cell: per row `cell * prefixes +
    /// prefix`, a bit set over `u_{k-1}`, and their number; `None` as soon as there are
    /// more than `limit`.
    fn reachable(&self, world: &World, limit: usize) -> Option<(Vec<u64>, usize)> {
        let (last, words) = (self.last(), self.words());
        let cap = self.cap(last);
        let mut bits = vec![0u64; world.dest.len() * self.prefixes * words];
        let mut count = 0;
        let mut u = vec![0usize; self.n.len()];
        for (c, &m) in world.mask.iter().enumerate() {
            u.iter_mut().zip(self.stored(m, &self.n)).for_each(|(a, b)| *a = b);
            let prefix: usize = u[..last].iter().zip(&self.stride).map(|(u, s)| u * s).sum();
            let word = &mut bits[(c * self.prefixes + prefix) * words + u[last] / 64];
            count += usize::from(*word >> (u[last] % 64) & 1 == 0);
            *word |= 1 << (u[last] % 64);
        }
        // Old clocks last: a pass carries every walk forward to its next region entry.
        let mut order = self.sweep_order();
        order.reverse();
        let mut shifted = vec![0u64; words];
        loop {
            let before = count;
            for &prefix in &order {
                let prefix = prefix as usize;
                self.prefix(prefix, &mut u[..last]);
                for c in 0..world.dest.len() {
                    let row = c * self.prefixes + prefix;
                    if bits[row * words..][..words].iter().all(|&w| w == 0) {
                        continue;
                    }
                    let from = world.mask[c];
                    for &to in &world.dest[c] {
                        let to_mask = world.mask[to as usize];
                        let (next, _) = self.next_prefix(&u[..last], from, to_mask);
                        let target = to as usize * self.prefixes + next;
                        if (from | to_mask) >> last & 1 == 1 {
                            shifted.fill(0);
                            shifted[0] = 1;
                        } else {
                            shift_capped(&bits[row * words..][..words], cap, &mut shifted);
                        }
                        for (t, &s) in bits[target * words..][..words].iter_mut().zip(&shifted) {
                            count += (s & !*t).count_ones() as usize;
                            *t |= s;
                        }
                    }
                    if count > limit {
                        return None;
                    }
                }
            }
            if count == before {
                return Some((bits, count));
            }
        }
    }

    /// The bytes [`Clocks::table`] allocates for these reachable states (at most).
    fn table_bytes(&self, reach: &[u64], count: usize, cells: usize) -> usize {
        // A run starts at each set bit whose lower neighbour is clear.
        let words = self.words();
        let runs: usize = reach
            .chunks(words)
            .map(|row| {
                let mut carry = 0;
                row.iter()
                    .map(|&w| {
                        let starts = w & !(w << 1 | carry);
                        carry = w >> 63;
                        starts.count_ones() as usize
                    })
                    .sum::<usize>()
            })
            .sum();
        let rows = cells * self.prefixes;
        count * 2 * size_of::<f64>()
            + runs * (size_of::<Segment>() + 2 * size_of::<Piece>())
            + rows * size_of::<(u32, u32)>()
    }

    /// The segments of the reachable rows in sweep order, their successors, and zero values.
    fn table(&self, world: World, reach: &[u64], count: usize) -> Result<Table, Error> {
        let (last, words) = (self.last(), self.words());
        let cap = self.cap(last);
        let cells = world.dest.len();
        let mut rows = vec![(0u32, 0u32); cells * self.prefixes];
        let mut segs: Vec<Segment> = Vec::new();
        let mut start = 0u32;
        let order = self.sweep_order();
        for &prefix in &order {
            for c in 0..cells {
                let row = c * self.prefixes + prefix as usize;
                let first = segs.len() as u32;
                let set = &reach[row * words..][..words];
                let mut i = 0;
                while i <= cap {
                    if set[i / 64] >> (i % 64) & 1 == 0 {
                        i += 1;
                        continue;
                    }
                    let u0 = i;
                    while i <= cap && set[i / 64] >> (i % 64) & 1 == 1 {
                        i += 1;
                    }
                    let len = (i - u0) as u32;
                    segs.push(Segment { start, len, u0: u0 as u32 });
                    start += len;
                }
                rows[row] = (first, segs.len() as u32 - first);
            }
        }
        debug_assert_eq!(start as usize, count);
        // Successors: by closure, each lies in a segment of its row. Per direction, the
        // first successor, whether the clock advances, and up to which entry (below `lim`)
        // the clock stays below its cap and the windows are kept.
        let closed = || Error::Config("internal error: the reachable states are not closed".into());
        let mut u = vec![0usize; last];
        let mut pieces = Vec::with_capacity(segs.len() * 2);
        for &prefix in &order {
            let prefix = prefix as usize;
            self.prefix(prefix, &mut u);
            for c in 0..cells {
                let (first, n) = rows[c * self.prefixes + prefix];
                let from = world.mask[c];
                for seg in &segs[first as usize..(first + n) as usize] {
                    let mut at = [0u32; 4];
                    let (mut fixed, mut ok) = (0u8, 0u8);
                    let mut run = seg.len as usize;
                    for (d, &to) in world.dest[c].iter().enumerate() {
                        let to_mask = world.mask[to as usize];
                        let (next, kept) = self.next_prefix(&u, from, to_mask);
                        let target = to as usize * self.prefixes + next;
                        let reset = (from | to_mask) >> last & 1 == 1;
                        let nu0 = if reset { 0 } else { (seg.u0 as usize + 1).min(cap) };
                        at[d] = find(&segs, rows[target], nu0).ok_or_else(closed)?;
                        if reset {
                            fixed |= 1 << d;
                            ok |= u8::from(kept && (to_mask >> last & 1 == 1 || cap > 0)) << d;
                        } else {
                            ok |= u8::from(kept) << d;
                            run = run.min(cap - nu0);
                        }
                    }
                    let run = run as u32;
                    if run > 0 {
                        pieces.push(Piece { start: seg.start, len: run, at, fixed, kept: ok });
                    }
                    // The rest reach the cap in every advancing direction: their successors
                    // there are all the capped entry (`at + run`), which keeps nothing.
                    if run < seg.len {
                        let at = std::array::from_fn(|d| {
                            at[d] + if fixed >> d & 1 == 1 { 0 } else { run }
                        });
                        let (start, len) = (seg.start + run, seg.len - run);
                        pieces.push(Piece { start, len, at, fixed: 0xf, kept: ok & fixed });
                    }
                }
            }
        }
        Ok(Table {
            dest: world.dest,
            mask: world.mask,
            segs,
            pieces,
            rows,
            values: vec![0.0; count],
        })
    }
}

/// The value index of `u_{k-1} = u` in a row given by its `(first segment, count)`.
fn find(segs: &[Segment], (first, n): (u32, u32), u: usize) -> Option<u32> {
    segs[first as usize..(first + n) as usize]
        .iter()
        .find(|s| (s.u0 as usize..(s.u0 + s.len) as usize).contains(&u))
        .map(|s| s.start + (u as u32 - s.u0))
}

/// `out`: the bit set `set` over `0..=cap` with every clock advanced by one, capped.
fn shift_capped(set: &[u64], cap: usize, out: &mut [u64]) {
    let mut carry = 0;
    for (o, &w) in out.iter_mut().zip(set) {
        *o = w << 1 | carry;
        carry = w >> 63;
    }
    let at_cap = set[cap / 64] >> (cap % 64) & 1;
    // Drop what moved past the cap, then keep the cap's own bit there.
    let top = cap + 1;
    if !top.is_multiple_of(64) {
        out[top / 64] &= (1u64 << (top % 64)) - 1;
    }
    for o in out.iter_mut().skip(top.div_ceil(64)) {
        *o = 0;
    }
    out[cap / 64] |= at_cap << (cap % 64);
}

impl Table {
    /// Solves the component: Gauss-Seidel sweeps with the Newton gain, then the bracket.
    fn solve(self, p: f64, config: SolveConfig) -> Result<(Table, Outcome), Error> {
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

    /// The value of the state `(cell, clocks)`, if it is stored.
    fn value(&self, clocks: &Clocks, cell: usize, u: &[usize]) -> Option<f64> {
        let last = clocks.last();
        let prefix: usize = u[..last].iter().zip(&clocks.stride).map(|(u, s)| u * s).sum();
        let row = *self.rows.get(cell * clocks.prefixes + prefix)?;
        find(&self.segs, row, u[last]).map(|i| self.values[i as usize])
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
