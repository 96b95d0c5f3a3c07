//! The plan itself: each option's leg made the quickest way into its region under the
//! counted transitions, value iteration over the states where legs arrive with the exact
//! counters of the other regions, and the options table filled for every memory code.
//! One file: the legs, the reward and future parts and the sweeps share private
//! types (`Leg`, `Grids`, `Values`); its tests check those parts against literal sums.

use super::size::{PlanSize, RARE_ARRIVAL, WINDOWS_OF_DURATION};
use crate::greedy::argmax;
use crate::memory::Memory;
use crate::tables::Tables;
use crate::{Error, LearnParams};

/// Value iteration stops when no value moves by more than this...
const TOLERANCE: f64 = 1e-5;
/// ... or after this many sweeps.
const MAX_SWEEPS: usize = 2000;
/// The value of an untried action in a leg's table of [`Planner::quickest_legs`].
pub(crate) const UNTRIED: f64 = -1e12;
/// The probability of a leg's longer durations that its value may leave out.
const TAIL: f64 = 1e-7;

/// What planning needs that training does not change: the options' regions and the sizes
/// of the tables, checked against [`MAX_PLAN_VALUES`] before training starts.
#[derive(Clone, Debug)]
pub(crate) struct Planner {
    /// `region[o]`: the task region option `o`'s one leg enters.
    region: Vec<usize>,
    /// The longest modelled duration of a leg.
    max_duration: usize,
}

impl Planner {
    /// The plan of `tables` and `memory` under `learn`, or why the options level of this
    /// spec cannot be planned.
    pub fn new(tables: &Tables, memory: &Memory, learn: &LearnParams) -> Result<Planner, Error> {
        let err = |m: String| Err(Error::Config(format!("plan: model {m}")));
        if memory.buckets == 0 {
            return err("needs a memory (`memory: B` with B > 0)".into());
        }
        if learn.options.gamma >= 1.0 {
            return err("needs an options gamma below 1".into());
        }
        let mut region = Vec::with_capacity(tables.legs.len());
        for legs in &tables.legs {
            let found = match legs.as_slice() {
                [p] => (0..memory.len()).find(|&j| memory.holds[j] == tables.term[*p]),
                _ => None,
            };
            match found {
                Some(j) => region.push(j),
                None => {
                    return err("needs every option to be one leg that ends on entering one of \
                                the task's regions (`option R;` with `terminate: R`)"
                        .into());
                }
            }
        }
        let longest = memory.horizons.iter().copied().max().unwrap_or(1);
        let max_duration = learn.max_steps.min(WINDOWS_OF_DURATION.saturating_mul(longest)).max(1);
        let cells: Vec<usize> =
            memory.holds.iter().map(|h| h.iter().filter(|&&x| x).count()).collect();
        let size = PlanSize {
            states: tables.states,
            cells: &cells,
            horizons: &memory.horizons,
            options: region.len(),
            buckets: memory.buckets,
            max_steps: learn.max_steps,
        };
        if let Some(why) = size.exceeded() {
            return err(why);
        }
        Ok(Planner { region, max_duration })
    }

    /// The flat tables of legs that take the fewest expected steps to their region under
    /// `model`: for every primitive an option runs, `Q(s, a)` is minus the expected steps
    /// to its region after `a` in `s` and the quickest actions from there, over the
    /// actions tried in `s` ([`UNTRIED`] for the others). A state from which no tried
    /// action is known to lead to the region keeps its learned values.
    pub fn quickest_legs(
        &self,
        tables: &Tables,
        memory: &Memory,
        flat: &[Vec<f64>],
        moves: &[Vec<(usize, f64)>],
    ) -> Vec<Vec<f64>> {
        let (states, actions) = (tables.states, tables.actions);
        let mut out = flat.to_vec();
        for (o, legs) in tables.legs.iter().enumerate() {
            let inside = &memory.holds[self.region[o]];
            let (live, steps) = quickest(inside, moves, actions);
            let table = &mut out[legs[0]];
            for s in (0..states).filter(|&s| live[s]) {
                for a in 0..actions {
                    let c = step_cost(inside, &live, &steps, &moves[s * actions + a]);
                    table[s * actions + a] = if c.is_finite() { -c } else { UNTRIED };
                }
            }
        }
        out
    }

    /// The options values of the greedy legs of `flat` under `model`: a table laid out as
    /// the learner's (`[obs * options + o]`).
    pub fn options_values(
        &self,
        tables: &Tables,
        memory: &Memory,
        flat: &[Vec<f64>],
        moves: &[Vec<(usize, f64)>],
        gamma: f64,
    ) -> Vec<f64> {
        let legs: Vec<Leg> = (0..tables.legs.len())
            .map(|o| Leg::new(tables, memory, flat, moves, self, o))
            .collect();
        let grids = Grids::new(memory);
        let values = iterate(tables, memory, &legs, &grids, gamma);
        fill(tables, memory, &legs, &grids, &values, gamma)
    }
}

/// The expected steps into a region after a move (`moves`: its outcomes), then the
/// quickest actions from `steps`; infinite for an untried move or one that may leave `live`.
fn step_cost(inside: &[bool], live: &[bool], steps: &[f64], moves: &[(usize, f64)]) -> f64 {
    if moves.is_empty() || moves.iter().any(|&(n, _)| !inside[n] && !live[n]) {
        return f64::INFINITY;
    }
    1.0 + moves.iter().map(|&(n, w)| if inside[n] { 0.0 } else { w * steps[n] }).sum::<f64>()
}

/// The states outside a region from which the quickest way in can be planned (`live`),
/// and the expected steps from each. A state is live when some tried action keeps the run
/// among live states or enters the region, and the region can be reached from it that
/// way; among those actions every policy that can reach the region does, so value
/// iteration from 0 converges to the expected steps of the quickest one.
fn quickest(inside: &[bool], moves: &[Vec<(usize, f64)>], actions: usize) -> (Vec<bool>, Vec<f64>) {
    let states = inside.len();
    let mut before: Vec<Vec<usize>> = vec![Vec::new(); states];
    for (i, m) in moves.iter().enumerate() {
        for &(n, _) in m {
            before[n].push(i);
        }
    }
    let mut live: Vec<bool> = (0..states).map(|s| !inside[s]).collect();
    let safe = |live: &[bool], i: usize| {
        !moves[i].is_empty() && moves[i].iter().all(|&(n, _)| inside[n] || live[n])
    };
    loop {
        // Backwards from the region over safe actions.
        let mut reaches = inside.to_vec();
        let mut queue: Vec<usize> = (0..states).filter(|&s| inside[s]).collect();
        while let Some(n) = queue.pop() {
            for &i in &before[n] {
                let s = i / actions;
                if live[s] && !reaches[s] && safe(&live, i) {
                    reaches[s] = true;
                    queue.push(s);
                }
            }
        }
        let mut removed = false;
        for s in 0..states {
            if live[s] && !reaches[s] {
                live[s] = false;
                removed = true;
            }
        }
        if !removed {
            break;
        }
    }
    let mut steps: Vec<f64> = live.iter().map(|&l| if l { 0.0 } else { f64::INFINITY }).collect();
    for _ in 0..MAX_SWEEPS {
        let mut change: f64 = 0.0;
        for s in (0..states).filter(|&s| live[s]) {
            let best = (0..actions)
                .map(|a| step_cost(inside, &live, &steps, &moves[s * actions + a]))
                .fold(f64::INFINITY, f64::min);
            change = change.max((best - steps[s]).abs());
            steps[s] = best;
        }
        if change < TOLERANCE {
            break;
        }
    }
    (live, steps)
}

/// One option's leg under its greedy actions, as the model predicts it.
struct Leg {
    /// The region it enters.
    region: usize,
    /// The cells of that region, in state order.
    cells: Vec<usize>,
    /// `f[s * (D + 1) + d]`: the probability of arriving after exactly `d` steps from `s`.
    f: Vec<f64>,
    /// `g[s * cells + c]`: the probability of arriving in `cells[c]`, given an arrival.
    g: Vec<f64>,
    /// `support[s]`: the durations from `s` worth counting, `lo..=hi` (empty: `1..=0`).
    support: Vec<(usize, usize)>,
    /// `D`, the longest modelled duration.
    max_duration: usize,
}

impl Leg {
    fn new(
        tables: &Tables,
        memory: &Memory,
        flat: &[Vec<f64>],
        moves: &[Vec<(usize, f64)>],
        plan: &Planner,
        o: usize,
    ) -> Leg {
        let (states, actions, p) = (tables.states, tables.actions, tables.legs[o][0]);
        let region = plan.region[o];
        let inside = &memory.holds[region];
        let moves: Vec<&[(usize, f64)]> = (0..states)
            .map(|s| moves[s * actions + argmax(&flat[p][s * actions..][..actions])].as_slice())
            .collect();
        let d_max = plan.max_duration;
        // Durations, backwards in d: arriving in one step, or stepping outside the region
        // and arriving in d - 1 from there.
        let mut by_d = vec![0.0; (d_max + 1) * states];
        for d in 1..=d_max {
            for s in 0..states {
                let mut p = 0.0;
                for &(n, w) in moves[s] {
                    if inside[n] {
                        if d == 1 {
                            p += w;
                        }
                    } else if d > 1 {
                        p += w * by_d[(d - 1) * states + n];
                    }
                }
                by_d[d * states + s] = p;
            }
        }
        let mut f = vec![0.0; states * (d_max + 1)];
        let mut support = vec![(1, 0); states];
        for s in 0..states {
            let row = &mut f[s * (d_max + 1)..][..d_max + 1];
            for (d, p) in row.iter_mut().enumerate().skip(1) {
                *p = by_d[d * states + s];
            }
            // The durations worth counting: from the first possible one to where less than
            // `TAIL` of the probability is left (the tail of a leg with slips is long and
            // thin, and would cost as much time as the rest).
            let Some(lo) = row.iter().position(|&p| p > 0.0) else { continue };
            let mut left: f64 = row.iter().sum();
            let mut hi = lo;
            for (d, &p) in row.iter().enumerate().skip(lo) {
                left -= p;
                hi = d;
                if left < TAIL {
                    break;
                }
            }
            support[s] = (lo, hi);
        }
        // Arrival cells: the same recursion over the cell arrived in, to a fixed point.
        let cells: Vec<usize> = (0..states).filter(|&s| inside[s]).collect();
        let slot: Vec<usize> = {
            let mut slot = vec![usize::MAX; states];
            for (c, &s) in cells.iter().enumerate() {
                slot[s] = c;
            }
            slot
        };
        let k = cells.len();
        let mut g = vec![0.0; states * k];
        let mut next = g.clone();
        for _ in 0..d_max {
            let mut change: f64 = 0.0;
            for s in 0..states {
                let row = &mut next[s * k..][..k];
                row.fill(0.0);
                for &(n, w) in moves[s] {
                    if inside[n] {
                        row[slot[n]] += w;
                    } else {
                        for (r, &x) in row.iter_mut().zip(&g[n * k..][..k]) {
                            *r += w * x;
                        }
                    }
                }
                for (r, &x) in row.iter().zip(&g[s * k..][..k]) {
                    change = change.max((r - x).abs());
                }
            }
            std::mem::swap(&mut g, &mut next);
            if change < 1e-12 {
                break;
            }
        }
        for row in g.chunks_mut(k.max(1)) {
            // Cells arrived in rarely are left out (each costs a pass over a grid of
            // values), and the rest share their probability.
            let total: f64 = row.iter().sum();
            row.iter_mut().filter(|x| **x < RARE_ARRIVAL * total).for_each(|x| *x = 0.0);
            let kept: f64 = row.iter().sum();
            if kept > 0.0 {
                row.iter_mut().for_each(|x| *x /= kept);
            }
        }
        Leg { region, cells, f, g, support, max_duration: d_max }
    }

    fn durations(&self, s: usize) -> &[f64] {
        &self.f[s * (self.max_duration + 1)..][..self.max_duration + 1]
    }

    fn arrivals(&self, s: usize) -> &[f64] {
        &self.g[s * self.cells.len()..][..self.cells.len()]
    }
}

/// The reward part of an option's value from one state, `sum_d f[d] R(tau, d)`, in O(1)
/// per counter vector: `R` depends on `tau` only through the last step at which every
/// window is still kept (`all`) and at which every window but the target's is (`others`).
struct RewardSums {
    /// `arrive[x] = sum_{d <= x} f[d]`.
    arrive: Vec<f64>,
    /// `kept_before[x] = sum_{d <= x} f[d] G(d - 1)`, `G(n) = sum_{m=1..n} gamma^(m-1)`.
    kept_before: Vec<f64>,
    /// `kept_at[x] = sum_{d <= x} f[d] gamma^(d-1)`.
    kept_at: Vec<f64>,
    /// `geometric[n] = G(n)` for `n` up to the longest duration.
    geometric: Vec<f64>,
    gamma: f64,
}

impl RewardSums {
    fn new(f: &[f64], gamma: f64) -> RewardSums {
        let n = f.len();
        let (mut arrive, mut kept_before, mut kept_at) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let (mut a, mut b, mut c, mut power, mut g) = (0.0, 0.0, 0.0, 1.0, 0.0);
        let mut geometric = vec![0.0; n];
        for d in 1..n {
            // power = gamma^(d-1), g = G(d-1).
            a += f[d];
            b += f[d] * g;
            c += f[d] * power;
            arrive[d] = a;
            kept_before[d] = b;
            kept_at[d] = c;
            g += power;
            geometric[d] = g;
            power *= gamma;
        }
        RewardSums { arrive, kept_before, kept_at, geometric, gamma }
    }

    fn geometric(&self, n: isize) -> f64 {
        match usize::try_from(n) {
            Err(_) | Ok(0) => 0.0,
            Ok(n) => self.geometric.get(n).copied().unwrap_or_else(|| {
                (1.0 - self.gamma.powi(n.min(i32::MAX as usize) as i32)) / (1.0 - self.gamma)
            }),
        }
    }

    /// `sum_d f[d] R(tau, d)` for `all = min_i (N_i - 1 - tau_i)` and `others` the same
    /// minimum without the target.
    fn value(&self, all: isize, others: isize) -> f64 {
        let last = self.arrive.len() - 1;
        let before = if all < 0 {
            0.0
        } else {
            let x = ((all + 1) as usize).min(last);
            self.kept_before[x] + self.geometric(all) * (self.arrive[last] - self.arrive[x])
        };
        let at = if others < 1 { 0.0 } else { self.kept_at[(others as usize).min(last)] };
        before + at
    }
}

/// The counter grids: a state's values are over the counters of the regions it is not in
/// (the others are 0 there).
struct Grids {
    /// `N_j + 1`, the counter values of region `j`.
    sizes: Vec<usize>,
    horizons: Vec<usize>,
}

impl Grids {
    fn new(memory: &Memory) -> Grids {
        Grids {
            sizes: memory.horizons.iter().map(|n| n + 1).collect(),
            horizons: memory.horizons.clone(),
        }
    }

    /// Strides of a grid over the regions `free` (row-major, the first region slowest); 0
    /// for the others.
    fn strides(&self, free: impl Fn(usize) -> bool) -> (Vec<usize>, usize) {
        let mut strides = vec![0; self.sizes.len()];
        let mut size = 1;
        for j in (0..self.sizes.len()).rev() {
            if free(j) {
                strides[j] = size;
                size *= self.sizes[j];
            }
        }
        (strides, size)
    }

    /// Every counter vector of a grid over `free`, the other counters 0, in index order.
    fn points(&self, free: &[bool]) -> Points<'_> {
        Points {
            sizes: &self.sizes,
            free: free.to_vec(),
            tau: vec![0; self.sizes.len()],
            done: false,
        }
    }
}

/// The counter vectors of a grid, as an odometer.
struct Points<'g> {
    sizes: &'g [usize],
    free: Vec<bool>,
    tau: Vec<usize>,
    done: bool,
}

impl Points<'_> {
    /// The next vector, or `None` at the end.
    fn next(&mut self) -> Option<&[usize]> {
        if self.done {
            return None;
        }
        Some(self.tau.as_slice())
    }

    fn advance(&mut self) {
        for j in (0..self.tau.len()).rev() {
            if !self.free[j] {
                continue;
            }
            self.tau[j] += 1;
            if self.tau[j] < self.sizes[j] {
                return;
            }
            self.tau[j] = 0;
        }
        self.done = true;
    }
}

/// The values of the states where legs arrive, each over its grid.
struct Values {
    /// `offset[s]`: where state `s`'s grid starts in `data` (`usize::MAX`: not planned).
    offset: Vec<usize>,
    /// `strides[s]`: its grid's strides (0 for the regions it is in).
    strides: Vec<Vec<usize>>,
    data: Vec<f64>,
}

impl Values {
    #[inline]
    fn at(&self, s: usize, tau: &[usize]) -> f64 {
        let i: usize = self.strides[s].iter().zip(tau).map(|(a, b)| a * b).sum();
        self.data[self.offset[s] + i]
    }
}

/// The reward part of option `leg`'s value at counters `tau` (`tau_j` = 0 where the state
/// is in region `j`).
fn reward_part(leg: &Leg, sums: &RewardSums, grids: &Grids, tau: &[usize]) -> f64 {
    let (mut all, mut others) = (isize::MAX, isize::MAX);
    for (j, (&t, &n)) in tau.iter().zip(&grids.horizons).enumerate() {
        let left = n as isize - 1 - t as isize;
        all = all.min(left);
        if j != leg.region {
            others = others.min(left);
        }
    }
    sums.value(all, others)
}

/// A leg's durations from one state, discounted: `h[d] = f[d] gamma^d` over its support,
/// and their running sums.
struct Discounted {
    h: Vec<f64>,
    /// `sums[d] = h[lo] + ... + h[d - 1]` (`sums[lo] = 0`).
    sums: Vec<f64>,
    lo: usize,
    hi: usize,
}

impl Discounted {
    fn new(leg: &Leg, s: usize, powers: &[f64]) -> Discounted {
        let f = leg.durations(s);
        let (lo, hi) = leg.support[s];
        let mut h = vec![0.0; hi + 1];
        let mut sums = vec![0.0; hi + 2];
        for d in lo..=hi {
            h[d] = f[d] * powers[d];
            sums[d + 1] = sums[d] + h[d];
        }
        Discounted { h, sums, lo, hi }
    }
}

/// The rest of it, `sum_d f[d] gamma^d arrival(tau + d)`, given the expected arrival values
/// `arrival` (a grid over every region but the target's, strides `ustrides`). It does not
/// read the target's counter. Along `d` the index into `arrival` is linear between the
/// steps at which a counter reaches its horizon (and stays), so the sum runs over those
/// stretches, and the last one, where every counter stays, is one product.
fn future_part(
    leg: &Leg,
    grids: &Grids,
    durations: &Discounted,
    tau: &[usize],
    arrival: &[f64],
    ustrides: &[usize],
) -> f64 {
    let Discounted { h, sums, lo, hi } = durations;
    let (lo, hi) = (*lo, *hi);
    if lo > hi {
        return 0.0;
    }
    // (step at which the counter stops, its stride, its horizon).
    let mut stops: Vec<(usize, usize, usize)> = Vec::with_capacity(tau.len());
    let (mut base, mut slope) = (0, 0);
    for (j, (&t, &n)) in tau.iter().zip(&grids.horizons).enumerate() {
        if j != leg.region && ustrides[j] > 0 {
            stops.push((n.saturating_sub(t), ustrides[j], n));
            base += ustrides[j] * t;
            slope += ustrides[j];
        }
    }
    stops.sort_unstable();
    // index(d) = base + slope * d until the next stop; a stopped counter moves from the
    // slope into the base at its horizon.
    let mut future = 0.0;
    let mut d = lo;
    let mut next = stops.iter().peekable();
    while d <= hi {
        while let Some(&&(at, stride, n)) = next.peek() {
            if at > d {
                break;
            }
            slope -= stride;
            base = base + stride * n - stride * (n - at);
            next.next();
        }
        let end = next.peek().map_or(hi + 1, |&&(at, ..)| at.min(hi + 1));
        if slope == 0 {
            future += arrival[base] * (sums[end] - sums[d]);
        } else {
            for (k, &w) in h[d..end].iter().enumerate() {
                future += w * arrival[base + slope * (d + k)];
            }
        }
        d = end;
    }
    future
}

/// `arrival[x] = sum_c g[s][c] V_c(x)` over the grid of every region but `leg`'s.
fn arrival_values(
    leg: &Leg,
    s: usize,
    values: &Values,
    grids: &Grids,
    out: &mut Vec<f64>,
) -> Vec<usize> {
    let region = leg.region;
    let (ustrides, size) = grids.strides(|j| j != region);
    out.clear();
    out.resize(size, 0.0);
    for (c, &w) in leg.arrivals(s).iter().enumerate() {
        if w == 0.0 {
            continue;
        }
        let cell = leg.cells[c];
        let start = values.offset[cell];
        if values.strides[cell] == ustrides {
            // The usual case: the cell is in the target's region alone.
            for (o, &v) in out.iter_mut().zip(&values.data[start..][..size]) {
                *o += w * v;
            }
            continue;
        }
        let free: Vec<bool> = (0..grids.sizes.len()).map(|j| j != region).collect();
        let mut points = grids.points(&free);
        let mut i = 0;
        while let Some(tau) = points.next() {
            out[i] += w * values.at(cell, tau);
            i += 1;
            points.advance();
        }
    }
    ustrides
}

/// What value iteration needs of one state and available option that no sweep changes.
struct Fixed {
    /// The reward part of the option's value on every point of the state's grid.
    reward: Vec<f64>,
    /// Where each point reads the future part (a grid without the target's counter).
    at: Vec<usize>,
    durations: Discounted,
}

/// Value iteration (Gauss-Seidel) over the states inside some region.
fn iterate(tables: &Tables, memory: &Memory, legs: &[Leg], grids: &Grids, gamma: f64) -> Values {
    let states = tables.states;
    let k = memory.len();
    let mut offset = vec![usize::MAX; states];
    let mut strides = vec![Vec::new(); states];
    let mut size = 0;
    let planned: Vec<usize> = (0..states)
        .filter(|&s| (0..k).any(|j| memory.holds(j, s)) && !tables.available[s].is_empty())
        .collect();
    // Every cell a leg arrives in has a grid, available options or not.
    for s in 0..states {
        if (0..k).any(|j| memory.holds(j, s)) {
            let (st, n) = grids.strides(|j| !memory.holds(j, s));
            offset[s] = size;
            strides[s] = st;
            size += n;
        }
    }
    let mut values = Values { offset, strides, data: vec![0.0; size] };
    let powers = powers(gamma, legs.first().map_or(0, |l| l.max_duration));
    // What does not change from sweep to sweep: per state and available option, the
    // reward part of the value on every point of the state's grid, and where that point
    // reads the future part (a grid without the target's counter).
    let fixed: Vec<Vec<Fixed>> = planned
        .iter()
        .map(|&s| {
            let free: Vec<bool> = (0..k).map(|j| !memory.holds(j, s)).collect();
            tables.available[s]
                .iter()
                .map(|&o| {
                    let leg = &legs[o];
                    let sums = RewardSums::new(leg.durations(s), gamma);
                    let (rstrides, _) = grids.strides(|j| free[j] && j != leg.region);
                    let (mut reward, mut at) = (Vec::new(), Vec::new());
                    let mut points = grids.points(&free);
                    while let Some(tau) = points.next() {
                        reward.push(reward_part(leg, &sums, grids, tau));
                        at.push(rstrides.iter().zip(tau).map(|(a, b)| a * b).sum());
                        points.advance();
                    }
                    Fixed { reward, at, durations: Discounted::new(leg, s, &powers) }
                })
                .collect()
        })
        .collect();
    let (mut arrival, mut fresh, mut future) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..MAX_SWEEPS {
        let mut change: f64 = 0.0;
        for (&s, fixed) in planned.iter().zip(&fixed) {
            let free: Vec<bool> = (0..k).map(|j| !memory.holds(j, s)).collect();
            let n = grids.strides(|j| free[j]).1;
            fresh.clear();
            fresh.resize(n, f64::NEG_INFINITY);
            for (&o, Fixed { reward, at, durations }) in tables.available[s].iter().zip(fixed) {
                let leg = &legs[o];
                let ustrides = arrival_values(leg, s, &values, grids, &mut arrival);
                let rest: Vec<bool> = (0..k).map(|j| free[j] && j != leg.region).collect();
                future.clear();
                let mut points = grids.points(&rest);
                while let Some(tau) = points.next() {
                    future.push(future_part(leg, grids, durations, tau, &arrival, &ustrides));
                    points.advance();
                }
                for ((f, &r), &i) in fresh.iter_mut().zip(reward).zip(at) {
                    *f = f.max(r + future[i]);
                }
            }
            let old = &mut values.data[values.offset[s]..][..n];
            for (o, &v) in old.iter_mut().zip(&fresh) {
                change = change.max((v - *o).abs());
                *o = v;
            }
        }
        if change < TOLERANCE {
            break;
        }
    }
    values
}

/// The options table: every state, every memory code it can observe, every option
/// available there, valued at the counters in the middle of each bucket.
fn fill(
    tables: &Tables,
    memory: &Memory,
    legs: &[Leg],
    grids: &Grids,
    values: &Values,
    gamma: f64,
) -> Vec<f64> {
    let n = tables.legs.len();
    let codes = memory.values();
    let mut table = vec![0.0; tables.states * codes * n];
    let middle: Vec<Vec<usize>> = (0..memory.len())
        .map(|j| {
            let horizon = memory.horizons[j];
            (0..=memory.buckets)
                .map(|b| {
                    let taus: Vec<usize> =
                        (1..=horizon).filter(|&t| memory.bucket(j, t) == b).collect();
                    taus.get(taus.len() / 2).copied().unwrap_or(horizon)
                })
                .collect()
        })
        .collect();
    let powers = powers(gamma, legs.first().map_or(0, |l| l.max_duration));
    let mut arrival = Vec::new();
    let mut tau = vec![0; memory.len()];
    // The future part by code with the target's bucket read as 0 (it does not read it).
    let mut future = vec![f64::NAN; codes];
    let digits = memory.buckets + 1;
    for s in 0..tables.states {
        // Every option whose leg can run here, available or not: a greedy run that
        // interrupts options compares the running one's value at every step.
        for (o, leg) in legs.iter().enumerate() {
            if memory.holds(leg.region, s) {
                continue;
            }
            let sums = RewardSums::new(leg.durations(s), gamma);
            let durations = Discounted::new(leg, s, &powers);
            let ustrides = arrival_values(leg, s, values, grids, &mut arrival);
            let weight = digits.pow((memory.len() - 1 - leg.region) as u32);
            future.fill(f64::NAN);
            for code in (0..codes).filter(|&c| memory.consistent(s, c)) {
                for (j, b) in memory.decode(code).into_iter().enumerate() {
                    tau[j] = if memory.holds(j, s) { 0 } else { middle[j][b] };
                }
                let key = code - (code / weight % digits) * weight;
                if future[key].is_nan() {
                    future[key] = future_part(leg, grids, &durations, &tau, &arrival, &ustrides);
                }
                table[(s * codes + code) * n + o] =
                    reward_part(leg, &sums, grids, &tau) + future[key];
            }
        }
    }
    table
}

/// `gamma^d` for `d = 0..=max`.
fn powers(gamma: f64, max: usize) -> Vec<f64> {
    std::iter::successors(Some(1.0), |p| Some(p * gamma)).take(max + 1).collect()
}

#[cfg(test)]
mod tests {
    use rand::RngExt;

    use super::*;
    use crate::seeded_rng;

    /// `sum_d f[d] R(tau, d)` literally: `psi(m)` for `m < d` while every window is kept,
    /// at `m = d` while every window but the target's is.
    fn reward_literally(
        f: &[f64],
        gamma: f64,
        tau: &[usize],
        horizons: &[usize],
        target: usize,
    ) -> f64 {
        let mut total = 0.0;
        for (d, &p) in f.iter().enumerate().skip(1) {
            let mut r = 0.0;
            for m in 1..=d {
                let kept = tau
                    .iter()
                    .zip(horizons)
                    .enumerate()
                    .all(|(j, (&t, &n))| (m == d && j == target) || t + m < n);
                if kept {
                    r += gamma.powi(m as i32 - 1);
                }
            }
            total += p * r;
        }
        total
    }

    fn random_durations(rng: &mut crate::Rng, len: usize) -> Vec<f64> {
        let mut f: Vec<f64> =
            (0..len).map(|d| if d == 0 { 0.0 } else { rng.random::<f64>() }).collect();
        let total: f64 = f.iter().sum();
        f.iter_mut().for_each(|p| *p /= total);
        f
    }

    fn leg(region: usize, f: Vec<f64>) -> Leg {
        let max_duration = f.len() - 1;
        let lo = f.iter().position(|&p| p > 0.0).unwrap();
        Leg {
            region,
            cells: vec![0],
            g: vec![1.0],
            support: vec![(lo, max_duration)],
            f,
            max_duration,
        }
    }

    #[test]
    fn reward_sums_equal_the_literal_sums() {
        let mut rng = seeded_rng(5);
        let horizons = [7, 4, 9];
        for case in 0..300 {
            let len = 1 + rng.random_range(1..20);
            let f = random_durations(&mut rng, len);
            let gamma = [0.5, 0.9, 0.98][case % 3];
            let tau: Vec<usize> = horizons.iter().map(|&n| rng.random_range(0..=n)).collect();
            let target = rng.random_range(0..3);
            let l = leg(target, f.clone());
            let grids = Grids {
                sizes: horizons.iter().map(|n| n + 1).collect(),
                horizons: horizons.to_vec(),
            };
            let got = reward_part(&l, &RewardSums::new(&f, gamma), &grids, &tau);
            let want = reward_literally(&f, gamma, &tau, &horizons, target);
            assert!((got - want).abs() < 1e-12, "case {case}: {got} against {want}");
        }
    }

    #[test]
    fn the_future_part_by_stretches_equals_the_step_by_step_sum() {
        let mut rng = seeded_rng(6);
        let horizons = vec![5, 3, 8, 4];
        let grids =
            Grids { sizes: horizons.iter().map(|n| n + 1).collect(), horizons: horizons.clone() };
        for case in 0..300 {
            let target = rng.random_range(0..4);
            let len = 1 + rng.random_range(1..15);
            let f = random_durations(&mut rng, len);
            let l = leg(target, f.clone());
            let (ustrides, size) = grids.strides(|j| j != target);
            let arrival: Vec<f64> = (0..size).map(|_| rng.random::<f64>()).collect();
            let tau: Vec<usize> = horizons.iter().map(|&n| rng.random_range(0..=n)).collect();
            let gamma = 0.9;
            let powers = powers(gamma, l.max_duration);
            let got = future_part(
                &l,
                &grids,
                &Discounted::new(&l, 0, &powers),
                &tau,
                &arrival,
                &ustrides,
            );
            let want: f64 = (1..f.len())
                .map(|d| {
                    let i: usize = (0..4)
                        .filter(|&j| j != target)
                        .map(|j| ustrides[j] * (tau[j] + d).min(horizons[j]))
                        .sum();
                    f[d] * gamma.powi(d as i32) * arrival[i]
                })
                .sum();
            assert!((got - want).abs() < 1e-12, "case {case}: {got} against {want}");
        }
    }

    #[test]
    fn the_quickest_legs_avoid_moves_that_may_strand_them() {
        // States 0 -> 1 -> 2 (the region) on a chain, and 3 a trap: from 0, action 1 goes
        // to 2 or the trap; action 0 steps to 1 and then to 2. State 4 was never left.
        let moves = vec![
            vec![(1, 1.0)],
            vec![(2, 0.5), (3, 0.5)], // state 0: actions 0, 1
            vec![(2, 1.0)],
            vec![], // state 1
            vec![],
            vec![], // state 2 (the region)
            vec![(3, 1.0)],
            vec![(3, 1.0)], // state 3: no way out
            vec![],
            vec![], // state 4: untried
        ];
        let inside = [false, false, true, false, false];
        let (live, steps) = quickest(&inside, &moves, 2);
        assert_eq!(live, [true, true, false, false, false]);
        assert_eq!(&steps[..2], [2.0, 1.0]);
    }
}
