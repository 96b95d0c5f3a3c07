//! A plane world's positions and obstacles, closed sets decided exactly by
//! [`crate::geometry`].

use serde_json::{Value, json};

use crate::geometry::{self, Xy};

/// A position in a plane world: its state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    /// Left to right.
    pub x: f64,
    /// Bottom to top.
    pub y: f64,
}

impl Point {
    pub(super) fn xy(self) -> Xy {
        (self.x, self.y)
    }
}

/// An obstacle of a plane world, a closed set: its edge is part of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Obstacle {
    /// The closed disk of centre `(cx, cy)` and radius `r`.
    Circle {
        /// The centre's x.
        cx: f64,
        /// The centre's y.
        cy: f64,
        /// The radius, positive.
        r: f64,
    },
    /// The closed rectangle `[x0, x1] x [y0, y1]`.
    Rect {
        /// The left edge.
        x0: f64,
        /// The bottom edge.
        y0: f64,
        /// The right edge, greater than `x0`.
        x1: f64,
        /// The top edge, greater than `y0`.
        y1: f64,
    },
}

impl Obstacle {
    /// Whether the point `p` is in the obstacle (its edge included).
    pub fn contains(&self, p: Point) -> bool {
        match *self {
            Obstacle::Circle { cx, cy, r } => geometry::in_disk(p.xy(), (cx, cy), r),
            Obstacle::Rect { x0, y0, x1, y1 } => geometry::in_rect(p.xy(), [x0, y0, x1, y1]),
        }
    }

    /// Whether the closed segment from `p` to `q` touches the obstacle, decided exactly for
    /// these doubles: a segment that grazes a corner or runs along an edge touches it,
    /// whatever the rounding. `p == q` is the point. Exact while the products of
    /// coordinate differences neither overflow nor underflow (numbers between about
    /// 1e-140 and 1e140, or zero); past that, a doubtful case counts as touching.
    pub fn touches_segment(&self, p: Point, q: Point) -> bool {
        match *self {
            Obstacle::Circle { cx, cy, r } => {
                geometry::segment_touches_disk(p.xy(), q.xy(), (cx, cy), r)
            }
            Obstacle::Rect { x0, y0, x1, y1 } => {
                geometry::segment_touches_rect(p.xy(), q.xy(), [x0, y0, x1, y1])
            }
        }
    }

    /// The obstacle as a world file and `policy.json` write it: `{"circle": [cx, cy, r]}`
    /// or `{"rect": [x0, y0, x1, y1]}`.
    pub fn to_json(&self) -> Value {
        match *self {
            Obstacle::Circle { cx, cy, r } => json!({ "circle": [cx, cy, r] }),
            Obstacle::Rect { x0, y0, x1, y1 } => json!({ "rect": [x0, y0, x1, y1] }),
        }
    }

    /// Its numbers, as written.
    pub(super) fn numbers(&self) -> Vec<f64> {
        match *self {
            Obstacle::Circle { cx, cy, r } => vec![cx, cy, r],
            Obstacle::Rect { x0, y0, x1, y1 } => vec![x0, y0, x1, y1],
        }
    }
}
