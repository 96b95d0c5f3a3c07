//! Plane worlds: a point robot in a bounded plane with circle and rectangle obstacles.
//!
//! **Contract** (DESIGN.md, "plane worlds"): the state is `(x, y)` in the extent
//! `[x0, x1] x [y0, y1]`; the actions are `headings` directions evenly spaced
//! counter-clockwise from east (4: `E N W S`; 8: `E NE N NW W SW S SE`; other counts from 3
//! to 64: `H0 H1 ...`). A move takes the chosen heading, or with probability `slip` one of
//! the other `headings - 1` (the opposite included), each equally likely; goes `step` along
//! it; and adds Gaussian noise N(0, noise^2) to each coordinate. If the straight segment
//! from the position to that endpoint leaves the extent or touches an obstacle, the robot
//! stays exactly where it is. The extent and the obstacles are closed: a position on the
//! extent's edge is inside it, and a segment that touches an obstacle's edge is blocked
//! (decided exactly, see [`Obstacle::touches_segment`]).
//!
//! **Draws**, in this order, all from the caller's generator, so that a seed gives the
//! same run bit for bit on every platform:
//! - [`reset`](World::reset): per attempt, a uniform `u` then `v` in `[0, 1)`, the
//!   position `((1-u) x0 + u x1, (1-v) y0 + v y1)` of the start rectangle, until it is
//!   free (see [`PlaneWorld::start_attempts`]).
//! - [`step`](World::step): nothing for an action outside the set. Otherwise, when
//!   `slip > 0`, one uniform in `[0, 1)`: below `slip` the move slips, and then one uniform
//!   integer `k` in `0..headings-1` picks the `k`-th of the other headings in index order.
//!   Then, when `noise > 0`, a pair of standard normals by the polar method
//!   ([`draw::normal_pair`]): the first for `x`, the second for `y`. The endpoint is
//!   `x + (step * ux + noise * zx)` and likewise for `y`.
//!
//! **Start.** Episodes start uniformly on the free part of the start rectangle (clipped to
//! the extent; by default the whole extent), by rejection sampling. When the world is
//! built, the start rectangle is cut into boxes (a quadtree, breadth first, within a
//! budget), each found exactly free of every obstacle, inside one, or neither and cut
//! further. The free boxes give a lower bound on the free part's share of the rectangle:
//! none at all (every box inside an obstacle) is an error, and so is a share below
//! [`MIN_START_FREE`] (a sliver too thin to sample). The bound also sets how many attempts
//! a reset makes before it gives up: enough that giving up has a probability below
//! `e^-50`; then it starts at the centre of the largest free box.

use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2};

use rand::RngExt;
use serde_json::{Value, json};

use crate::draw;
use crate::env::World;
use crate::geometry::Xy;
use crate::{Error, Rng};

mod errors;
mod index;
mod obstacle;
mod start;

pub use errors::num;
pub(crate) use errors::*;
use index::ObstacleIndex;
pub use obstacle::{Obstacle, Point};
use start::free_boxes;

/// What a plane world is made of, as a world file gives it.
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneConfig {
    /// The extent along x, `[lo, hi]`, finite, `lo < hi`.
    pub x: [f64; 2],
    /// The extent along y, `[lo, hi]`, finite, `lo < hi`.
    pub y: [f64; 2],
    /// How far the chosen heading moves the robot in one step; positive and finite.
    pub step: f64,
    /// The number of headings, from 3 to 64.
    pub headings: usize,
    /// The probability that one of the other headings is taken instead, in `[0, 1]`.
    pub slip: f64,
    /// The standard deviation of the Gaussian noise on each coordinate; `>= 0`, finite.
    pub noise: f64,
    /// The obstacles, at most [`MAX_OBSTACLES`].
    pub obstacles: Vec<Obstacle>,
    /// The start rectangle `[x0, y0, x1, y1]` (`x0 <= x1`, `y0 <= y1`; a segment or a
    /// point is allowed), clipped to the extent; `None` for the whole extent.
    pub start: Option<[f64; 4]>,
}

/// The most obstacles a plane world may have: every step tests each one.
pub const MAX_OBSTACLES: usize = 1024;

/// The fewest and the most headings.
pub const HEADINGS: std::ops::RangeInclusive<usize> = 3..=64;

/// The least share of the start rectangle that must be found free (see the module docs).
pub const MIN_START_FREE: f64 = 1e-4;

/// The built-in plane worlds, by name.
pub const PLANE_BUILTIN: [&str; 1] = ["paper-plane"];

/// A plane world (see the module docs for the contract and the draws).
#[derive(Clone, Debug, PartialEq)]
pub struct PlaneWorld {
    name: String,
    /// As given, with `start` set to the clipped start rectangle.
    config: PlaneConfig,
    /// The clipped start rectangle.
    start: [f64; 4],
    /// Per heading, its unit vector.
    dirs: Vec<Xy>,
    /// How many positions a reset draws before it gives up.
    attempts: u32,
    /// Where a reset that gave up starts: the centre of the largest free box.
    fallback: Point,
    /// A lower bound on the free share of the start rectangle.
    start_free: f64,
    /// The obstacles in buckets over the extent (`None`: every move tests them all).
    index: Option<Box<ObstacleIndex>>,
}

impl PlaneWorld {
    /// The world `config` describes, named `name`. Fails with what is wrong when a number is
    /// out of its range (see [`PlaneConfig`]), the start rectangle lies outside the extent,
    /// or its free part is empty or too thin to start from.
    pub fn new(name: &str, config: PlaneConfig) -> Result<PlaneWorld, Error> {
        PlaneWorld::build(name, config).map_err(|e| Error::Env(e.message))
    }

    pub(crate) fn build(name: &str, mut config: PlaneConfig) -> Result<PlaneWorld, ConfigError> {
        let err = |field, message: String, help| Err(ConfigError { field, message, help });
        for (axis, [lo, hi]) in [("x", config.x), ("y", config.y)] {
            let field = |i| if axis == "x" { Field::X(i) } else { Field::Y(i) };
            if let Some(i) = [lo, hi].iter().position(|v| !v.is_finite()) {
                let message =
                    format!("{axis} = {}: the extent's bounds must be finite", list(&[lo, hi]));
                return err(field(Some(i)), message, EXTENT_HELP);
            }
            if lo >= hi {
                let message = format!(
                    "{axis} = {}: the lower bound must be less than the upper",
                    list(&[lo, hi])
                );
                return err(field(None), message, EXTENT_HELP);
            }
            // Every length in the world (tiles, pictures, distances) is a difference of
            // positions: the widest must be a double too.
            if !(hi - lo).is_finite() {
                let message = format!(
                    "{axis} = {}: the extent is wider than the largest number, {}",
                    list(&[lo, hi]),
                    num(f64::MAX)
                );
                return err(field(None), message, EXTENT_HELP);
            }
        }
        if !(config.step > 0.0 && config.step.is_finite()) {
            let message = format!("step = {} is not a positive finite number", num(config.step));
            return err(Field::Step, message, STEP_HELP);
        }
        if !HEADINGS.contains(&config.headings) {
            let message =
                format!("headings = {} is not a whole number from 3 to 64", config.headings);
            return err(Field::Headings, message, HEADINGS_HELP);
        }
        if !(0.0..=1.0).contains(&config.slip) {
            let message = format!("slip = {} is not a probability in [0, 1]", num(config.slip));
            return err(Field::Slip, message, SLIP_HELP);
        }
        if !(config.noise >= 0.0 && config.noise.is_finite()) {
            let message =
                format!("noise = {} is not a non-negative finite number", num(config.noise));
            return err(Field::Noise, message, NOISE_HELP);
        }
        if config.obstacles.len() > MAX_OBSTACLES {
            let message = format!(
                "the world has {} obstacles, more than the {MAX_OBSTACLES} a world may have",
                config.obstacles.len()
            );
            return err(Field::Obstacles, message, "merge obstacles, or leave some out");
        }
        for (i, o) in config.obstacles.iter().enumerate() {
            let numbers = o.numbers();
            let (kind, help) = match o {
                Obstacle::Circle { .. } => ("circle", CIRCLE_HELP),
                Obstacle::Rect { .. } => ("rect", RECT_HELP),
            };
            if let Some(j) = numbers.iter().position(|v| !v.is_finite()) {
                let message = format!("{kind} {}: its numbers must be finite", list(&numbers));
                return err(Field::Obstacle(i, Some(j)), message, help);
            }
            match *o {
                Obstacle::Circle { r, .. } if r <= 0.0 => {
                    let message = format!("circle {}: its radius must be positive", list(&numbers));
                    return err(Field::Obstacle(i, Some(2)), message, help);
                }
                Obstacle::Rect { x0, y0, x1, y1 } if x0 >= x1 || y0 >= y1 => {
                    let which = if x0 >= x1 {
                        "x0 must be less than x1"
                    } else {
                        "y0 must be less than y1"
                    };
                    let message = format!("rect {} is empty: {which}", list(&numbers));
                    return err(Field::Obstacle(i, None), message, help);
                }
                _ => {}
            }
        }
        let [ex0, ex1, ey0, ey1] = [config.x[0], config.x[1], config.y[0], config.y[1]];
        let given = config.start;
        let start = match given {
            None => [ex0, ey0, ex1, ey1],
            Some(s) => {
                if let Some(j) = s.iter().position(|v| !v.is_finite()) {
                    let message = format!("start = {}: its numbers must be finite", list(&s));
                    return err(Field::Start(Some(j)), message, START_HELP);
                }
                if s[0] > s[2] || s[1] > s[3] {
                    let which =
                        if s[0] > s[2] { "x0 must not exceed x1" } else { "y0 must not exceed y1" };
                    let message = format!("start = {}: {which}", list(&s));
                    return err(Field::Start(None), message, START_HELP);
                }
                let clipped = [s[0].max(ex0), s[1].max(ey0), s[2].min(ex1), s[3].min(ey1)];
                if clipped[0] > clipped[2] || clipped[1] > clipped[3] {
                    let message = format!(
                        "start = {} lies outside the extent x in {}, y in {}",
                        list(&s),
                        list(&config.x),
                        list(&config.y)
                    );
                    return err(Field::Start(None), message, START_HELP);
                }
                clipped
            }
        };
        let found = free_boxes(start, &config.obstacles);
        let (what, field) = match given {
            Some(s) => (format!("start = {}", list(&s)), Field::Start(None)),
            None => ("the extent".to_string(), Field::Obstacles),
        };
        let Some(fallback) = found.largest.filter(|_| found.share > 0.0) else {
            let message = if found.complete {
                format!("no position in {what} is free: obstacles cover all of it")
            } else {
                format!("no free position was found in {what}: obstacles cover nearly all of it")
            };
            return err(field, message, FREE_HELP);
        };
        if found.share < MIN_START_FREE {
            let message = format!(
                "the free part of {what} is too small to start from: less than 1/{} of it was found free",
                (1.0 / MIN_START_FREE).round()
            );
            return err(field, message, FREE_HELP);
        }
        // Enough attempts that all fail with probability (1 - share)^n < e^-50.
        let attempts = (50.0 / found.share).ceil().min(f64::from(u32::MAX)) as u32;
        config.start = Some(start);
        let dirs = (0..config.headings).map(|k| heading_vector(k, config.headings)).collect();
        let index = ObstacleIndex::build(config.x, config.y, &config.obstacles).map(Box::new);
        Ok(PlaneWorld {
            name: name.to_string(),
            config,
            start,
            dirs,
            attempts,
            fallback,
            start_free: found.share,
            index,
        })
    }

    /// The world's configuration, with `start` the start rectangle clipped to the extent.
    pub fn config(&self) -> &PlaneConfig {
        &self.config
    }

    /// The world's name (`paper-plane`, or the name its file gives).
    pub fn world_name(&self) -> &str {
        &self.name
    }

    /// The extent along x and along y, each `[lo, hi]`.
    pub fn extent(&self) -> ([f64; 2], [f64; 2]) {
        (self.config.x, self.config.y)
    }

    /// How far the chosen heading moves the robot in one step.
    pub fn step_length(&self) -> f64 {
        self.config.step
    }

    /// The number of headings (actions).
    pub fn headings(&self) -> usize {
        self.config.headings
    }

    /// The probability that one of the other headings is taken.
    pub fn slip(&self) -> f64 {
        self.config.slip
    }

    /// The standard deviation of the noise on each coordinate of a move.
    pub fn noise(&self) -> f64 {
        self.config.noise
    }

    /// The obstacles.
    pub fn obstacles(&self) -> &[Obstacle] {
        &self.config.obstacles
    }

    /// The start rectangle `[x0, y0, x1, y1]`, clipped to the extent.
    pub fn start(&self) -> [f64; 4] {
        self.start
    }

    /// The unit vector of heading `k` (exact along the axes), or `None` past the last.
    pub fn heading(&self, k: usize) -> Option<(f64, f64)> {
        self.dirs.get(k).copied()
    }

    /// How many positions a reset draws before it gives up and starts at the centre of the
    /// largest free box found when the world was built (with probability below `e^-50`).
    pub fn start_attempts(&self) -> u32 {
        self.attempts
    }

    /// A lower bound on the free share of the start rectangle, found when the world was
    /// built (at least [`MIN_START_FREE`]).
    pub fn start_free_share(&self) -> f64 {
        self.start_free
    }

    /// Whether `p` is a free position: in the extent and in no obstacle.
    pub fn is_free(&self, p: Point) -> bool {
        self.in_extent(p) && !self.touches_obstacle(p, p, |o| o.contains(p))
    }

    /// Whether the robot may move from `p` straight to `q`: the segment stays in the
    /// extent and touches no obstacle.
    pub fn segment_is_free(&self, p: Point, q: Point) -> bool {
        // The extent is convex: the segment stays in it when both ends do.
        self.in_extent(p)
            && self.in_extent(q)
            && !self.touches_obstacle(p, q, |o| o.touches_segment(p, q))
    }

    /// Whether `test` holds for an obstacle, of those near the segment from `p` to `q`
    /// (the index's buckets), or of all of them; in index order either way, with the same
    /// answer (see the `index` module).
    fn touches_obstacle(&self, p: Point, q: Point, test: impl Fn(&Obstacle) -> bool) -> bool {
        let all = &self.config.obstacles;
        self.index
            .as_ref()
            .and_then(|i| i.any_near(p.xy(), q.xy(), |o| test(&all[o])))
            .unwrap_or_else(|| all.iter().any(&test))
    }

    fn in_extent(&self, p: Point) -> bool {
        let (x, y) = (self.config.x, self.config.y);
        x[0] <= p.x && p.x <= x[1] && y[0] <= p.y && p.y <= y[1]
    }

    /// The world from the `params` object that [`World::params`] writes.
    pub fn from_params(name: &str, params: &Value) -> Result<PlaneWorld, Error> {
        let bad =
            |what: &str| Error::Env(format!("the plane world's `{what}` is missing or malformed"));
        let number = |key: &str| params.get(key).and_then(Value::as_f64).ok_or_else(|| bad(key));
        let numbers = |v: &Value, n: usize| -> Option<Vec<f64>> {
            let a = v.as_array().filter(|a| a.len() == n)?;
            a.iter().map(Value::as_f64).collect()
        };
        let pair = |key: &str| -> Result<[f64; 2], Error> {
            let v = params.get(key).and_then(|v| numbers(v, 2)).ok_or_else(|| bad(key))?;
            Ok([v[0], v[1]])
        };
        if params.get("kind").and_then(Value::as_str) != Some("plane") {
            return Err(Error::Env("the world's `kind` is not \"plane\"".into()));
        }
        let headings = params
            .get("headings")
            .and_then(Value::as_u64)
            .and_then(|h| usize::try_from(h).ok())
            .ok_or_else(|| bad("headings"))?;
        let list =
            params.get("obstacles").and_then(Value::as_array).ok_or_else(|| bad("obstacles"))?;
        if list.len() > MAX_OBSTACLES {
            return Err(Error::Env(format!(
                "the world has {} obstacles, more than the {MAX_OBSTACLES} a world may have",
                list.len()
            )));
        }
        let mut obstacles = Vec::with_capacity(list.len());
        for o in list {
            let circle = o.get("circle").and_then(|v| numbers(v, 3));
            let rect = o.get("rect").and_then(|v| numbers(v, 4));
            let one = o.as_object().is_some_and(|m| m.len() == 1);
            obstacles.push(match (circle, rect) {
                (Some(c), None) if one => Obstacle::Circle { cx: c[0], cy: c[1], r: c[2] },
                (None, Some(r)) if one => Obstacle::Rect { x0: r[0], y0: r[1], x1: r[2], y1: r[3] },
                _ => return Err(bad("obstacles")),
            });
        }
        let start = match params.get("start") {
            None | Some(Value::Null) => None,
            Some(v) => {
                let s = numbers(v, 4).ok_or_else(|| bad("start"))?;
                Some([s[0], s[1], s[2], s[3]])
            }
        };
        let config = PlaneConfig {
            x: pair("x")?,
            y: pair("y")?,
            step: number("step")?,
            headings,
            slip: number("slip")?,
            noise: number("noise")?,
            obstacles,
            start,
        };
        PlaneWorld::new(name, config)
    }

    /// A built-in plane world by name (see [`PLANE_BUILTIN`]).
    pub fn builtin(name: &str) -> Option<PlaneWorld> {
        (name == "paper-plane").then(paper_plane)
    }
}

/// The paper's case study as a plane: `x` and `y` in [0, 14], step 1, 4 headings, slip 0.3,
/// noise 0.1, no obstacles.
pub fn paper_plane() -> PlaneWorld {
    let config = PlaneConfig {
        x: [0.0, 14.0],
        y: [0.0, 14.0],
        step: 1.0,
        headings: 4,
        slip: 0.3,
        noise: 0.1,
        obstacles: Vec::new(),
        start: None,
    };
    match PlaneWorld::build("paper-plane", config) {
        Ok(world) => world,
        // A fixed, valid configuration: `build` accepts it.
        Err(_) => unreachable!("the paper's plane is a valid world"),
    }
}

/// The names of `n` headings: `E N W S`, `E NE N NW W SW S SE`, or `H0 H1 ...`.
pub fn heading_names(n: usize) -> Vec<String> {
    match n {
        4 => ["E", "N", "W", "S"].map(String::from).to_vec(),
        8 => ["E", "NE", "N", "NW", "W", "SW", "S", "SE"].map(String::from).to_vec(),
        _ => (0..n).map(|k| format!("H{k}")).collect(),
    }
}

/// The unit vector of heading `k` of `n`, at `k * 360 / n` degrees counter-clockwise from
/// east. The angle is a whole number of quarter turns plus `a` in `[0, 90)` degrees; the
/// quarter turns swap and negate exactly, `a = 0` is exact and `a = 45` is
/// `(1/sqrt 2, 1/sqrt 2)`, and the rest is computed in `[0, 45)` degrees (an angle above
/// 45 from its complement), so the set is as symmetric as the count allows.
fn heading_vector(k: usize, n: usize) -> Xy {
    let (quarter, rest) = ((4 * k) / n, (4 * k) % n);
    let angle = |r: usize| FRAC_PI_2 * r as f64 / n as f64;
    let (c, s) = if rest == 0 {
        (1.0, 0.0)
    } else if 2 * rest == n {
        (FRAC_1_SQRT_2, FRAC_1_SQRT_2)
    } else if 2 * rest < n {
        draw::cos_sin(angle(rest))
    } else {
        let (c, s) = draw::cos_sin(angle(n - rest));
        (s, c)
    };
    // `0.0 - v` rather than `-v`, so that no component is -0.
    match quarter {
        0 => (c, s),
        1 => (0.0 - s, c),
        2 => (0.0 - c, 0.0 - s),
        _ => (s, 0.0 - c),
    }
}

impl World for PlaneWorld {
    type State = Point;

    fn name(&self) -> &str {
        &self.name
    }

    /// The world whole: `kind` ("plane"), `x`, `y`, `step`, `headings`, `slip`, `noise`,
    /// `obstacles` and `start` (clipped to the extent).
    fn params(&self) -> Value {
        let c = &self.config;
        json!({
            "kind": "plane",
            "x": c.x,
            "y": c.y,
            "step": c.step,
            "headings": c.headings,
            "slip": c.slip,
            "noise": c.noise,
            "obstacles": c.obstacles.iter().map(Obstacle::to_json).collect::<Vec<_>>(),
            "start": self.start,
        })
    }

    fn state_vars(&self) -> Vec<String> {
        vec!["x".into(), "y".into()]
    }

    fn actions(&self) -> Vec<String> {
        heading_names(self.config.headings)
    }

    fn valuation(&self, state: &Point, out: &mut Vec<f64>) {
        out.clear();
        out.extend([state.x, state.y]);
    }

    fn reset(&self, rng: &mut Rng) -> Point {
        let [x0, y0, x1, y1] = self.start;
        for _ in 0..self.attempts {
            let x = draw::uniform_in(rng, x0, x1);
            let y = draw::uniform_in(rng, y0, y1);
            let p = Point { x, y };
            if self.is_free(p) {
                return p;
            }
        }
        self.fallback
    }

    fn step(&self, state: &Point, action: usize, rng: &mut Rng) -> Point {
        let n = self.config.headings;
        if action >= n {
            return *state;
        }
        let mut heading = action;
        if self.config.slip > 0.0 && rng.random::<f64>() < self.config.slip {
            let k = rng.random_range(0..n - 1);
            heading = k + usize::from(k >= action);
        }
        let (ux, uy) = self.dirs[heading];
        let step = self.config.step;
        let (mut dx, mut dy) = (step * ux, step * uy);
        if self.config.noise > 0.0 {
            let [zx, zy] = draw::normal_pair(rng);
            dx += self.config.noise * zx;
            dy += self.config.noise * zy;
        }
        let to = Point { x: state.x + dx, y: state.y + dy };
        if self.segment_is_free(*state, to) { to } else { *state }
    }

    /// The heading's move without slip or noise leaves the extent or touches an obstacle.
    fn blocked(&self, state: &Point, action: usize) -> bool {
        let Some(&(ux, uy)) = self.dirs.get(action) else { return true };
        let step = self.config.step;
        !self.segment_is_free(*state, Point { x: state.x + step * ux, y: state.y + step * uy })
    }
}
