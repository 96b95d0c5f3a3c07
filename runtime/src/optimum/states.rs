//! The reachable states of one component and their value table: the clocks in the
//! solver's order, the closure of the fresh states under every move (bit sets), and the
//! table laid out in rows, segments and pieces (see the module docs of [`super`]).

use crate::Error;

/// The windows in the solver's order: the longest window last, as the row dimension, the
/// others by decreasing window.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Clocks {
    /// `n[j]`: `N` of the solver's region `j`.
    pub(super) n: Vec<usize>,
    /// `order[j]`: the task's index of the solver's region `j`.
    pub(super) order: Vec<usize>,
    /// Strides of the prefix clocks `u_0 .. u_{k-2}` in a prefix index; the last is 1.
    pub(super) stride: Vec<usize>,
    /// The number of prefix indices, `N_0 * ... * N_{k-2}`.
    pub(super) prefixes: usize,
}

/// One component's world, its cells numbered `0..cells`.
pub(super) struct World {
    pub(super) dest: Vec<[u32; 4]>,
    pub(super) mask: Vec<u8>,
}

/// A run of consecutive `u_{k-1}` of one row `(cell, prefix)`, stored contiguously.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Segment {
    /// Index of the first entry in the value table.
    pub(super) start: u32,
    pub(super) len: u32,
    /// `u_{k-1}` of the first entry.
    pub(super) u0: u32,
}

/// Consecutive entries whose successors in each direction are consecutive too, or one
/// entry (where the move resets the row's clock), and whose moves keep the windows alike:
/// entry `i` reads `at[d] + i` in direction `d` (`at[d]` when bit `d` of `fixed` is set) and
/// earns 1 when bit `d` of `kept` is set. The sweep runs over these.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Piece {
    pub(super) start: u32,
    pub(super) len: u32,
    pub(super) at: [u32; 4],
    pub(super) fixed: u8,
    pub(super) kept: u8,
}

/// The solved values of one component.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Table {
    pub(super) dest: Vec<[u32; 4]>,
    pub(super) mask: Vec<u8>,
    pub(super) segs: Vec<Segment>,
    pub(super) pieces: Vec<Piece>,
    /// Per row `cell * prefixes + prefix`: its first segment and the number of them.
    pub(super) rows: Vec<(u32, u32)>,
    pub(super) values: Vec<f64>,
}

impl Clocks {
    pub(super) fn new(horizons: &[usize]) -> Clocks {
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

    pub(super) fn last(&self) -> usize {
        self.n.len() - 1
    }

    /// The cap `N_j - 1` of a stored clock (`tau_j = N_j`, expired).
    pub(super) fn cap(&self, j: usize) -> usize {
        self.n[j] - 1
    }

    /// The stored clock `u_j` after moving from a cell with regions `from` into one with
    /// regions `to`.
    pub(super) fn next_u(&self, j: usize, u: usize, from: u8, to: u8) -> usize {
        if (from | to) >> j & 1 == 1 { 0 } else { (u + 1).min(self.cap(j)) }
    }

    /// Whether window `j` is kept on arriving in a cell with regions `to` with clock `u`.
    pub(super) fn kept(&self, j: usize, u: usize, to: u8) -> bool {
        to >> j & 1 == 1 || u < self.cap(j)
    }

    /// The prefix clocks of a prefix index.
    pub(super) fn prefix(&self, index: usize, out: &mut [usize]) {
        for (j, u) in out.iter_mut().enumerate() {
            *u = index / self.stride[j] % self.n[j];
        }
    }

    /// The prefix index reached by moving from regions `from` into `to` with prefix clocks
    /// `u`, and whether those windows are kept on arrival.
    pub(super) fn next_prefix(&self, u: &[usize], from: u8, to: u8) -> (usize, bool) {
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
    pub(super) fn stored<'a>(
        &'a self,
        mask: u8,
        tau: &'a [usize],
    ) -> impl Iterator<Item = usize> + 'a {
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
    pub(super) fn sweep_order(&self) -> Vec<u32> {
        (0..self.prefixes as u32).rev().collect()
    }

    /// Words of the row bit set over `u_{k-1}`.
    pub(super) fn words(&self) -> usize {
        self.n[self.last()].div_ceil(64)
    }

    /// The states reachable from the fresh state of every cell: per row `cell * prefixes +
    /// prefix`, a bit set over `u_{k-1}`, and their number; `None` as soon as there are
    /// more than `limit`.
    pub(super) fn reachable(&self, world: &World, limit: usize) -> Option<(Vec<u64>, usize)> {
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
    pub(super) fn table_bytes(&self, reach: &[u64], count: usize, cells: usize) -> usize {
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
    pub(super) fn table(&self, world: World, reach: &[u64], count: usize) -> Result<Table, Error> {
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
pub(super) fn find(segs: &[Segment], (first, n): (u32, u32), u: usize) -> Option<u32> {
    segs[first as usize..(first + n) as usize]
        .iter()
        .find(|s| (s.u0 as usize..(s.u0 + s.len) as usize).contains(&u))
        .map(|s| s.start + (u as u32 - s.u0))
}

/// `out`: the bit set `set` over `0..=cap` with every clock advanced by one, capped.
pub(super) fn shift_capped(set: &[u64], cap: usize, out: &mut [u64]) {
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
    /// The value of the state `(cell, clocks)`, if it is stored.
    pub(super) fn value(&self, clocks: &Clocks, cell: usize, u: &[usize]) -> Option<f64> {
        let last = clocks.last();
        let prefix: usize = u[..last].iter().zip(&clocks.stride).map(|(u, s)| u * s).sum();
        let row = *self.rows.get(cell * clocks.prefixes + prefix)?;
        find(&self.segs, row, u[last]).map(|i| self.values[i as usize])
    }
}
