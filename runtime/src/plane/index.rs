//! A spatial index of a plane world's obstacles: uniform buckets over the extent, built
//! once per world, so that a move is tested against the obstacles near it rather than
//! against every one.
//!
//! **Same answers, bit for bit.** The index only leaves out obstacles whose bounding box
//! (widened by a relative margin far above any rounding of its corners) is apart from the
//! segment's: such an obstacle does not touch the segment, and the exact segment tests of
//! [`crate::geometry`] say so, since they decide exactly whenever no product of coordinate
//! differences overflows or underflows. That holds when every number involved (the
//! extent, the obstacles and both ends of the segment) is zero or between [`TAME_LO`] and
//! [`TAME_HI`] in magnitude: a difference of two such numbers is zero or between about
//! 1e-36 and 4e20, and the tests' products of up to four differences (and their exact
//! error terms) stay far inside the doubles' normal range. For anything else (a world of
//! extreme numbers, a position next to zero), and for a segment that spans many buckets,
//! [`ObstacleIndex::candidates`] answers `None` and the caller tests every obstacle, as
//! before. The obstacles it does give are in index order, so the tests run in the same
//! order as over the whole list.

use super::obstacle::Obstacle;

/// Below this many obstacles every move tests them all: an index would not pay.
const MIN_INDEXED: usize = 16;
/// Buckets per obstacle, about.
const BUCKETS_PER_OBSTACLE: usize = 4;
/// The most buckets along one axis.
const MAX_SIDE: usize = 256;
/// A segment over more buckets than this is tested against every obstacle.
const MAX_QUERY_BUCKETS: usize = 64;
/// The most candidates gathered on the stack; past it every obstacle is tested.
const MAX_CANDIDATES: usize = 256;
/// The smallest non-zero magnitude the index works with (see the module docs).
pub(crate) const TAME_LO: f64 = 1e-20;
/// The largest magnitude the index works with (see the module docs).
pub(crate) const TAME_HI: f64 = 1e20;
/// The relative margin an obstacle's bounding box is widened by, far above the rounding of
/// `cx - r` and `cx + r` (half a unit in the last place).
const MARGIN: f64 = 1e-9;

/// Whether `v` is zero or between [`TAME_LO`] and [`TAME_HI`] in magnitude.
fn tame(v: f64) -> bool {
    v == 0.0 || (TAME_LO..=TAME_HI).contains(&v.abs())
}

/// Uniform buckets over a plane world's extent, each listing (in index order) the
/// obstacles whose widened bounding box meets it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ObstacleIndex {
    /// The extent's lower corner.
    x0: f64,
    y0: f64,
    /// Buckets per unit along each axis.
    sx: f64,
    sy: f64,
    /// Buckets along each axis.
    nx: usize,
    ny: usize,
    /// `items[starts[b]..starts[b + 1]]`: the obstacles of bucket `b = j * nx + i`.
    starts: Vec<u32>,
    items: Vec<u32>,
}

impl ObstacleIndex {
    /// The index of `obstacles` over the extent `x` by `y`, or `None` when every move
    /// should test every obstacle: few obstacles, or numbers outside the tame range.
    pub(crate) fn build(x: [f64; 2], y: [f64; 2], obstacles: &[Obstacle]) -> Option<Self> {
        if obstacles.len() < MIN_INDEXED || obstacles.len() > u32::MAX as usize {
            return None;
        }
        let numbers = obstacles.iter().flat_map(|o| match *o {
            Obstacle::Circle { cx, cy, r } => [cx, cy, r, 0.0],
            Obstacle::Rect { x0, y0, x1, y1 } => [x0, y0, x1, y1],
        });
        if !x.iter().chain(&y).copied().chain(numbers).all(tame) {
            return None;
        }
        let (w, h) = (x[1] - x[0], y[1] - y[0]);
        if !(w > 0.0 && h > 0.0) {
            return None;
        }
        // About BUCKETS_PER_OBSTACLE buckets an obstacle, square-ish.
        let total = (obstacles.len() * BUCKETS_PER_OBSTACLE) as f64;
        let side = |share: f64| (total * share).sqrt().ceil().clamp(1.0, MAX_SIDE as f64) as usize;
        let (nx, ny) = (side(w / h), side(h / w));
        let mut index = ObstacleIndex {
            x0: x[0],
            y0: y[0],
            sx: nx as f64 / w,
            sy: ny as f64 / h,
            nx,
            ny,
            starts: Vec::new(),
            items: Vec::new(),
        };
        let ranges: Vec<[usize; 4]> =
            obstacles.iter().map(|o| index.buckets(widened_box(o))).collect();
        let mut counts = vec![0u32; nx * ny + 1];
        for &[i0, i1, j0, j1] in &ranges {
            for j in j0..=j1 {
                for i in i0..=i1 {
                    counts[j * nx + i + 1] += 1;
                }
            }
        }
        for b in 1..counts.len() {
            counts[b] += counts[b - 1];
        }
        let mut fill = counts.clone();
        index.items = vec![0; counts[nx * ny] as usize];
        // Obstacles in index order: each bucket's list is sorted.
        for (o, &[i0, i1, j0, j1]) in ranges.iter().enumerate() {
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let b = j * nx + i;
                    index.items[fill[b] as usize] = o as u32;
                    fill[b] += 1;
                }
            }
        }
        index.starts = counts;
        Some(index)
    }

    /// The bucket column of `v`: monotone in `v`, clamped to the grid.
    fn column(&self, v: f64) -> usize {
        (((v - self.x0) * self.sx).floor().max(0.0) as usize).min(self.nx - 1)
    }

    /// The bucket row of `v`: monotone in `v`, clamped to the grid.
    fn row(&self, v: f64) -> usize {
        (((v - self.y0) * self.sy).floor().max(0.0) as usize).min(self.ny - 1)
    }

    /// The buckets `[i0, i1, j0, j1]` (inclusive) the box `[x0, y0, x1, y1]` meets. Since
    /// [`Self::column`] and [`Self::row`] are monotone, two boxes that meet have bucket
    /// ranges that meet.
    fn buckets(&self, b: [f64; 4]) -> [usize; 4] {
        [self.column(b[0]), self.column(b[2]), self.row(b[1]), self.row(b[3])]
    }

    /// Calls `test` on each obstacle that may touch the closed segment from `p` to `q`, in
    /// index order, until one returns `true`; `Some` of whether one did, or `None` when the
    /// caller must test every obstacle (see the module docs).
    pub(crate) fn any_near(
        &self,
        p: (f64, f64),
        q: (f64, f64),
        mut test: impl FnMut(usize) -> bool,
    ) -> Option<bool> {
        if ![p.0, p.1, q.0, q.1].into_iter().all(tame) {
            return None;
        }
        let [i0, i1, j0, j1] =
            self.buckets([p.0.min(q.0), p.1.min(q.1), p.0.max(q.0), p.1.max(q.1)]);
        let spanned = (i1 - i0 + 1) * (j1 - j0 + 1);
        if spanned == 1 {
            let b = j0 * self.nx + i0;
            let list = &self.items[self.starts[b] as usize..self.starts[b + 1] as usize];
            return Some(list.iter().any(|&o| test(o as usize)));
        }
        if spanned > MAX_QUERY_BUCKETS {
            return None;
        }
        let mut found = [0u32; MAX_CANDIDATES];
        let mut n = 0;
        for j in j0..=j1 {
            for i in i0..=i1 {
                let b = j * self.nx + i;
                let list = &self.items[self.starts[b] as usize..self.starts[b + 1] as usize];
                if n + list.len() > MAX_CANDIDATES {
                    return None;
                }
                found[n..n + list.len()].copy_from_slice(list);
                n += list.len();
            }
        }
        let found = &mut found[..n];
        found.sort_unstable();
        let mut last = None;
        Some(found.iter().any(|&o| {
            let repeat = last == Some(o);
            last = Some(o);
            !repeat && test(o as usize)
        }))
    }
}

/// The obstacle's bounding box `[x0, y0, x1, y1]`, widened by [`MARGIN`] of its
/// magnitude: it holds every point of the obstacle whatever the rounding of its corners.
fn widened_box(o: &Obstacle) -> [f64; 4] {
    let [x0, y0, x1, y1] = match *o {
        Obstacle::Circle { cx, cy, r } => [cx - r, cy - r, cx + r, cy + r],
        Obstacle::Rect { x0, y0, x1, y1 } => [x0, y0, x1, y1],
    };
    let m = MARGIN * [x0, y0, x1, y1].iter().fold(0.0f64, |a, v| a.max(v.abs()));
    [x0 - m, y0 - m, x1 + m, y1 + m]
}

#[cfg(test)]
mod tests {
    use super::super::{PlaneConfig, PlaneWorld, Point};
    use super::*;
    use crate::env::World;
    use rand::{RngExt, SeedableRng};

    /// A world of `n` random circles and rectangles on `[0, w] x [0, h]`.
    fn random_world(rng: &mut crate::Rng, n: usize, w: f64, h: f64, size: f64) -> PlaneConfig {
        let obstacles = (0..n)
            .map(|_| {
                let (x, y) = (rng.random::<f64>() * w, rng.random::<f64>() * h);
                let s = size * (0.1 + rng.random::<f64>());
                if rng.random::<bool>() {
                    Obstacle::Circle { cx: x, cy: y, r: s }
                } else {
                    Obstacle::Rect { x0: x, y0: y, x1: x + s, y1: y + s * 0.5 }
                }
            })
            .collect();
        PlaneConfig {
            x: [0.0, w],
            y: [0.0, h],
            step: 0.7,
            headings: 8,
            slip: 0.2,
            noise: 0.3,
            obstacles,
            start: None,
        }
    }

    /// The answers without the index: every obstacle, in order.
    fn linear_segment(world: &PlaneWorld, p: Point, q: Point) -> bool {
        let (x, y) = world.extent();
        let inside = |p: Point| x[0] <= p.x && p.x <= x[1] && y[0] <= p.y && p.y <= y[1];
        inside(p) && inside(q) && !world.obstacles().iter().any(|o| o.touches_segment(p, q))
    }

    fn linear_point(world: &PlaneWorld, p: Point) -> bool {
        let (x, y) = world.extent();
        x[0] <= p.x
            && p.x <= x[1]
            && y[0] <= p.y
            && p.y <= y[1]
            && !world.obstacles().iter().any(|o| o.contains(p))
    }

    #[test]
    fn the_indexed_tests_answer_as_the_linear_ones_over_random_worlds() {
        let mut rng = crate::Rng::seed_from_u64(11);
        let mut checked = 0;
        for round in 0..40 {
            let n = [16, 40, 200, 1024][round % 4];
            let (w, h): (f64, f64) =
                [(14.0, 14.0), (50.0, 3.0), (1.0, 1.0), (1e6, 2e6)][round / 4 % 4];
            let size = w.min(h) / (n as f64).sqrt() * [0.2, 1.0, 3.0][round % 3];
            let Ok(world) = PlaneWorld::new("r", random_world(&mut rng, n, w, h, size)) else {
                continue;
            };
            assert!(world.index.is_some());
            for _ in 0..2_000 {
                let p = Point { x: rng.random::<f64>() * w, y: rng.random::<f64>() * h };
                // Moves of a step, long moves, points, and ends on obstacles' edges.
                let len = [0.0, 0.01, 1.0, w / 3.0][rng.random_range(0..4)];
                let a = rng.random::<f64>() * std::f64::consts::TAU;
                let mut q = Point { x: p.x + len * a.cos(), y: p.y + len * a.sin() };
                if rng.random_range(0..8) == 0 {
                    match world.obstacles()[rng.random_range(0..n)] {
                        Obstacle::Circle { cx, cy, r } => q = Point { x: cx + r, y: cy },
                        Obstacle::Rect { x0, y1, .. } => q = Point { x: x0, y: y1 },
                    }
                }
                assert_eq!(
                    world.segment_is_free(p, q),
                    linear_segment(&world, p, q),
                    "{p:?} {q:?}"
                );
                assert_eq!(world.is_free(q), linear_point(&world, q), "{q:?}");
                checked += 1;
            }
            // Whole runs: the same positions step by step.
            let mut a = crate::Rng::seed_from_u64(round as u64);
            let mut s = world.reset(&mut a);
            for t in 0..500 {
                let to = world.step(&s, t % 8, &mut a);
                let free = linear_segment(&world, s, Point { x: to.x, y: to.y });
                assert!(to == s || free);
                s = to;
            }
        }
        assert!(checked > 40_000, "{checked}");
    }

    #[test]
    fn extreme_numbers_and_few_obstacles_are_not_indexed() {
        let mut rng = crate::Rng::seed_from_u64(3);
        let few = random_world(&mut rng, 8, 14.0, 14.0, 0.3);
        assert!(PlaneWorld::new("f", few).unwrap().index.is_none());
        let mut huge = random_world(&mut rng, 64, 14.0, 14.0, 0.3);
        huge.x = [0.0, 1e30];
        assert!(PlaneWorld::new("h", huge).unwrap().index.is_none());
        // A position next to zero is tested against every obstacle.
        let world = PlaneWorld::new("w", random_world(&mut rng, 64, 14.0, 14.0, 0.3)).unwrap();
        let index = world.index.as_ref().unwrap();
        assert_eq!(index.any_near((1e-300, 1.0), (1.0, 1.0), |_| true), None);
        assert!(index.any_near((0.0, 1.0), (1.0, 1.0), |_| false).is_some());
    }
}
