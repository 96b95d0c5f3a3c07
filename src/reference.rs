//! Reference policies for continuous worlds, planned from the world's geometry and the
//! task's regions and independent of the learner: what BENCHMARKS.md measures learned
//! policies against where no exact optimum exists.
//!
//! **Legs on a plane.** Each primitive option gets a shortest-path distance field over a
//! lattice of spacing `step / 2` (at most [`MAX_LATTICE`] points; coarser where the world is
//! larger): Dijkstra over 8 neighbours, an edge only where the world's own segment test lets
//! the robot through and neither end lies in the option's `avoid` region, with the option's
//! stop region (its `terminate` formula, else its reach region) as the source. A step takes
//! the heading whose nominal endpoint is closest to the stop region by that field (a lattice
//! corner's distance plus the way to it); slips and noise are the world's.
//!
//! **Legs on MountainCar.** Energy pumping: push along the velocity, towards the region's
//! side at rest and away from the far wall, which swings the car up to either hill top.
//!
//! **Which leg.** For a persistent task, least laxity first: when a leg ends, the next one
//! goes to the region whose deadline, less the steps already waited and the steps to reach
//! it, is least (a region the robot is in is skipped). For another task, the legs of the
//! options set's first option in turn.
//!
//! The figures are scored as the learner's are: the window rate of a persistent task (every
//! state after the burn-in whose windows all hold), else the share of runs whose trace
//! satisfies the task.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use hstl_robustness::StateEval;
use hstl_runtime::approx::task_robustness;
use hstl_runtime::plane::{PlaneWorld, Point};
use hstl_runtime::world::AnyWorld;
use hstl_runtime::{MountainCar, Rng, TaskSpec, Terminate, World, seeded_rng};

use crate::Problem;
use crate::continuous::Evaluation;
use crate::evaluate::Runs;

/// Lattice points of all distance fields together, at most.
pub const MAX_LATTICE: usize = 1 << 22;

/// Segment tests against one obstacle that planning may make in all, at most (about a
/// second): a world with many obstacles gets a coarser lattice.
pub const MAX_PLAN_WORK: usize = 1 << 28;

/// A reference policy for one spec on one world.
#[derive(Clone, Debug)]
pub struct Reference {
    spec: TaskSpec,
    world: AnyWorld,
    legs: Legs,
}

/// How the legs move the robot.
#[derive(Clone, Debug)]
enum Legs {
    /// One distance field per primitive option.
    Plane(Vec<Field>),
    /// Energy pumping; per option, whether its region lies right of the valley's bottom.
    Car(Vec<bool>),
}

/// Distances (in world units) to an option's stop region over a lattice.
#[derive(Clone, Debug)]
struct Field {
    origin: [f64; 2],
    spacing: f64,
    size: [usize; 2],
    distance: Vec<f64>,
}

impl Reference {
    /// Plans the reference of `spec` (lowered, with its regions) on `world`.
    pub fn new(spec: &TaskSpec, world: &AnyWorld) -> Result<Reference, Problem> {
        if spec.primitives.is_empty() {
            return Err(Problem::new("the reference needs a spec with options", None));
        }
        let legs = match world {
            AnyWorld::Plane(p) => {
                // Each field gets an equal share of the budgets.
                let fields = spec.primitives.len();
                let per_point = 8 * (1 + p.obstacles().len());
                let points = (MAX_LATTICE / fields).min(MAX_PLAN_WORK / fields / per_point).max(4);
                Legs::Plane(spec.primitives.iter().map(|o| Field::plan(p, o, points)).collect())
            }
            AnyWorld::MountainCar(_) => {
                let mut eval = StateEval::new();
                let at = |eval: &mut StateEval, r, x| eval.value(r, &[x, 0.0]);
                Legs::Car(
                    spec.primitives
                        .iter()
                        .map(|o| {
                            at(&mut eval, &o.reach, MountainCar::MAX_POSITION)
                                > at(&mut eval, &o.reach, MountainCar::MIN_POSITION)
                        })
                        .collect(),
                )
            }
            AnyWorld::Grid(_) => {
                return Err(Problem::new(
                    "the reference is for continuous worlds; a grid has an exact optimum",
                    Some("use `hstlc study`, which prints W* on a grid".into()),
                ));
            }
        };
        Ok(Reference { spec: spec.clone(), world: world.clone(), legs })
    }

    /// Scores the reference as `hstlc eval` scores a learned policy: `runs.starts` runs of
    /// `runs.steps` actions from one generator seeded with `runs.seed`.
    pub fn evaluate(&self, runs: Runs) -> Evaluation {
        let mut rng = seeded_rng(runs.seed);
        let persistent = !self.spec.regions.is_empty();
        let (mut kept, mut satisfied, mut per_run, mut robustness) = (0, 0, Vec::new(), Vec::new());
        for _ in 0..runs.starts {
            let values = self.run(runs.steps, &mut rng);
            let vars = self.spec.state_vars.len();
            if persistent {
                let here = self.kept(&values, runs.steps, runs.burn_in);
                kept += here;
                per_run.push(here as f64 / (runs.steps - runs.burn_in).max(1) as f64);
                robustness.push(task_robustness(&self.spec, &values[..runs.steps * vars], vars));
            } else if task_robustness(&self.spec, &values, vars) > 0.0 {
                satisfied += 1;
            }
        }
        if persistent {
            let rate = kept as f64 / (runs.starts * (runs.steps - runs.burn_in)).max(1) as f64;
            Evaluation::Window(hstl_runtime::approx::WindowSummary { rate, per_run, robustness })
        } else {
            Evaluation::Satisfaction { rate: satisfied as f64 / runs.starts.max(1) as f64 }
        }
    }

    /// One run of `steps` actions from a start of the world: `steps + 1` valuations, row
    /// after row.
    pub fn run(&self, steps: usize, rng: &mut Rng) -> Vec<f64> {
        match &self.world {
            AnyWorld::Plane(w) => self.run_in(w, steps, rng),
            AnyWorld::MountainCar(w) => self.run_in(w, steps, rng),
            AnyWorld::Grid(w) => self.run_in(w, steps, rng),
        }
    }

    fn run_in<W: World>(&self, world: &W, steps: usize, rng: &mut Rng) -> Vec<f64> {
        let mut eval = StateEval::new();
        let mut state = world.reset(rng);
        let mut x = Vec::new();
        world.valuation(&state, &mut x);
        let mut values = x.clone();
        let horizons: Vec<usize> = self.spec.regions.iter().map(|r| r.horizon).collect();
        let mut waited: Vec<usize> = horizons.clone();
        let sequence = self.spec.options.first().map(|o| o.sequence.clone()).unwrap_or_default();
        let mut next_leg = 0;
        let mut leg = None;
        for _ in 0..steps {
            self.count(&mut eval, &x, &mut waited);
            if leg.is_some_and(|p| self.stops(&mut eval, p, &x)) {
                leg = None;
            }
            if leg.is_none() {
                leg = if horizons.is_empty() {
                    let p = sequence.get(next_leg).copied();
                    next_leg += 1;
                    p
                } else {
                    self.least_laxity(&mut eval, &x, &waited)
                };
            }
            let action = match leg {
                Some(p) => self.action(p, &x),
                None => 0,
            };
            state = world.step(&state, action, rng);
            world.valuation(&state, &mut x);
            values.extend_from_slice(&x);
        }
        values
    }

    /// Moves the steps waited for each region on to `x`.
    fn count(&self, eval: &mut StateEval, x: &[f64], waited: &mut [usize]) {
        for (r, w) in self.spec.regions.iter().zip(waited) {
            *w = if eval.value(&r.formula, x) > 0.0 { 0 } else { (*w + 1).min(r.horizon) };
        }
    }

    fn stops(&self, eval: &mut StateEval, p: usize, x: &[f64]) -> bool {
        let o = &self.spec.primitives[p];
        match &o.terminate {
            Terminate::Formula(f) => eval.value(f, x) > 0.0,
            Terminate::Argmax => eval.value(&o.reach, x) > 0.0,
        }
    }

    /// The primitive whose region has the least laxity: its deadline less the steps waited
    /// and the steps to get there.
    fn least_laxity(&self, eval: &mut StateEval, x: &[f64], waited: &[usize]) -> Option<usize> {
        let mut best: Option<(f64, usize)> = None;
        for (j, r) in self.spec.regions.iter().enumerate() {
            if eval.value(&r.formula, x) > 0.0 {
                continue;
            }
            let Some(p) = self.spec.primitives.iter().position(|o| o.reach == r.formula) else {
                continue;
            };
            let laxity = r.horizon as f64 - waited[j] as f64 - self.steps_to(p, x);
            if best.is_none_or(|(b, _)| laxity < b) {
                best = Some((laxity, p));
            }
        }
        best.map(|(_, p)| p)
    }

    fn steps_to(&self, p: usize, x: &[f64]) -> f64 {
        match (&self.legs, &self.world) {
            (Legs::Plane(fields), AnyWorld::Plane(w)) => {
                fields[p].at([x[0], x[1]]) / w.step_length()
            }
            _ => 0.0,
        }
    }

    fn action(&self, p: usize, x: &[f64]) -> usize {
        match (&self.legs, &self.world) {
            (Legs::Plane(fields), AnyWorld::Plane(w)) => {
                let here = Point { x: x[0], y: x[1] };
                let mut best = (f64::INFINITY, 0);
                for k in 0..w.headings() {
                    let Some((dx, dy)) = w.heading(k) else { continue };
                    let to = Point {
                        x: here.x + w.step_length() * dx,
                        y: here.y + w.step_length() * dy,
                    };
                    if !w.segment_is_free(here, to) {
                        continue;
                    }
                    let d = fields[p].at([to.x, to.y]);
                    if d < best.0 {
                        best = (d, k);
                    }
                }
                best.1
            }
            (Legs::Car(right_side), _) => {
                // Along the velocity, towards the region at rest, and off the far wall
                // (the right wall does not stop the car, which would rest against it).
                let (at, v) = (x[0], x[1]);
                let right = if right_side[p] {
                    v >= 0.0 || at <= MountainCar::MIN_POSITION
                } else {
                    v > 0.0 && at < MountainCar::MAX_POSITION
                };
                if right { 2 } else { 0 }
            }
            _ => 0,
        }
    }

    /// The states `0..steps` after `burn_in` whose windows all hold, the counters starting
    /// expired, as the learner's evaluation counts them.
    fn kept(&self, values: &[f64], steps: usize, burn_in: usize) -> usize {
        let vars = self.spec.state_vars.len();
        let mut eval = StateEval::new();
        let mut waited: Vec<usize> = self.spec.regions.iter().map(|r| r.horizon).collect();
        let mut kept = 0;
        for (t, x) in values.chunks(vars).take(steps).enumerate() {
            self.count(&mut eval, x, &mut waited);
            if t >= burn_in && self.spec.regions.iter().zip(&waited).all(|(r, &w)| w < r.horizon) {
                kept += 1;
            }
        }
        kept
    }
}

impl Field {
    /// The field of `option`'s stop region on a lattice of at most `points` points.
    fn plan(world: &PlaneWorld, option: &hstl_runtime::PrimitiveOption, points: usize) -> Field {
        let ([x0, x1], [y0, y1]) = world.extent();
        // Half a step, or the least normal double for a step so small that half of it is
        // zero (doubling zero would never thin the lattice out).
        let mut spacing = (world.step_length() / 2.0).max(f64::MIN_POSITIVE);
        // Lattice points along a width: a width of 1e300 steps saturates (a float cast
        // does), and so must the point past it, or it wraps to no point at all.
        let along = |w: f64, s: f64| ((w / s).ceil() as usize).saturating_add(1);
        let cells = |s: f64| (along(x1 - x0, s), along(y1 - y0, s));
        while {
            let (nx, ny) = cells(spacing);
            nx.saturating_mul(ny) > points
        } {
            spacing *= 2.0;
        }
        let (nx, ny) = cells(spacing);
        let point = |i: usize, j: usize| Point {
            x: (x0 + i as f64 * spacing).min(x1),
            y: (y0 + j as f64 * spacing).min(y1),
        };
        let mut eval = StateEval::new();
        let stop = match &option.terminate {
            Terminate::Formula(f) => f,
            Terminate::Argmax => &option.reach,
        };
        let mut open = vec![false; nx * ny];
        let mut distance = vec![f64::INFINITY; nx * ny];
        let mut heap = BinaryHeap::new();
        for j in 0..ny {
            for i in 0..nx {
                let p = point(i, j);
                let xy = [p.x, p.y];
                let avoided = option.avoid.as_ref().is_some_and(|a| eval.value(a, &xy) >= 0.0);
                open[j * nx + i] = world.is_free(p) && !avoided;
                if open[j * nx + i] && eval.value(stop, &xy) > 0.0 {
                    distance[j * nx + i] = 0.0;
                    heap.push(Visit { d: 0.0, at: j * nx + i });
                }
            }
        }
        while let Some(Visit { d, at }) = heap.pop() {
            if d > distance[at] {
                continue;
            }
            let (i, j) = (at % nx, at / nx);
            let here = point(i, j);
            for (di, dj) in
                [(-1i64, -1i64), (0, -1), (1, -1), (-1, 0), (1, 0), (-1, 1), (0, 1), (1, 1)]
            {
                let (Some(a), Some(b)) =
                    (i.checked_add_signed(di as isize), j.checked_add_signed(dj as isize))
                else {
                    continue;
                };
                if a >= nx || b >= ny || !open[b * nx + a] {
                    continue;
                }
                let there = point(a, b);
                let nd = d + (there.x - here.x).hypot(there.y - here.y);
                if nd < distance[b * nx + a] && world.segment_is_free(here, there) {
                    distance[b * nx + a] = nd;
                    heap.push(Visit { d: nd, at: b * nx + a });
                }
            }
        }
        Field { origin: [x0, y0], spacing, size: [nx, ny], distance }
    }

    /// The distance from `p` to the region through the nearest lattice corners.
    fn at(&self, p: [f64; 2]) -> f64 {
        let [nx, ny] = self.size;
        let fx = ((p[0] - self.origin[0]) / self.spacing).max(0.0);
        let fy = ((p[1] - self.origin[1]) / self.spacing).max(0.0);
        let (i, j) = ((fx.floor() as usize).min(nx - 1), (fy.floor() as usize).min(ny - 1));
        let mut best = f64::INFINITY;
        for (a, b) in [(i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)] {
            if a < nx && b < ny {
                let (cx, cy) = (
                    self.origin[0] + a as f64 * self.spacing,
                    self.origin[1] + b as f64 * self.spacing,
                );
                best = best.min(self.distance[b * nx + a] + (p[0] - cx).hypot(p[1] - cy));
            }
        }
        best
    }
}

/// A lattice point on Dijkstra's frontier, nearest first.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Visit {
    d: f64,
    at: usize,
}

impl Eq for Visit {}

impl Ord for Visit {
    fn cmp(&self, other: &Self) -> Ordering {
        other.d.total_cmp(&self.d).then(other.at.cmp(&self.at))
    }
}

impl PartialOrd for Visit {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
