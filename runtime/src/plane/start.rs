//! Where a plane world's episodes may start: the start rectangle cut into boxes (a
//! quadtree, breadth first, within a budget), each found exactly free of every obstacle,
//! inside one, or neither and cut further (see the module docs of [`super`]).

use super::obstacle::{Obstacle, Point};
use crate::geometry;

/// What the quadtree found in a start rectangle.
pub(super) struct Found {
    /// A lower bound on the free share of the rectangle.
    pub(super) share: f64,
    /// The centre of the largest free box.
    pub(super) largest: Option<Point>,
    /// Whether every box was classified (the share is then exact).
    pub(super) complete: bool,
}

/// How many boxes the quadtree may classify, and how many box-obstacle tests it may make.
const MAX_BOXES: usize = 1 << 16;
const MAX_TESTS: usize = 1 << 22;

/// Cuts `rect` into boxes free of every obstacle, inside one, or cut further, breadth
/// first within the budgets above (see the module docs).
pub(super) fn free_boxes(rect: [f64; 4], obstacles: &[Obstacle]) -> Found {
    // Each box with its share of `rect` and the obstacles that touch it without covering it.
    let mut queue = std::collections::VecDeque::new();
    queue.push_back((rect, 1.0f64, (0..obstacles.len() as u32).collect::<Vec<u32>>()));
    let (mut share, mut largest, mut best) = (0.0, None, 0.0);
    let (mut boxes, mut tests) = (0usize, 0usize);
    while let Some((b, part, near)) = queue.pop_front() {
        if boxes >= MAX_BOXES || tests >= MAX_TESTS {
            return Found { share, largest, complete: false };
        }
        boxes += 1;
        tests += near.len();
        let mut touching = Vec::new();
        let mut inside = false;
        for &i in &near {
            match relation(b, &obstacles[i as usize]) {
                Relation::Apart => {}
                Relation::Inside => {
                    inside = true;
                    break;
                }
                Relation::Across => touching.push(i),
            }
        }
        if inside {
            continue;
        }
        if touching.is_empty() {
            share += part;
            if part > best {
                best = part;
                largest = Some(Point { x: mid(b[0], b[2]), y: mid(b[1], b[3]) });
            }
            continue;
        }
        // Cut along each axis that still has room between its ends.
        let (mx, my) = (mid(b[0], b[2]), mid(b[1], b[3]));
        let xs: &[[f64; 2]] =
            if mx > b[0] && mx < b[2] { &[[b[0], mx], [mx, b[2]]] } else { &[[b[0], b[2]]] };
        let ys: &[[f64; 2]] =
            if my > b[1] && my < b[3] { &[[b[1], my], [my, b[3]]] } else { &[[b[1], b[3]]] };
        let pieces = xs.len() * ys.len();
        if pieces == 1 {
            // Too small to cut: neither free nor covered as far as doubles can tell.
            continue;
        }
        for x in xs {
            for y in ys {
                queue.push_back(([x[0], y[0], x[1], y[1]], part / pieces as f64, touching.clone()));
            }
        }
    }
    Found { share, largest, complete: true }
}

fn mid(lo: f64, hi: f64) -> f64 {
    lo / 2.0 + hi / 2.0
}

enum Relation {
    /// The box and the obstacle do not touch.
    Apart,
    /// The box lies in the obstacle.
    Inside,
    /// Neither, as far as the tests tell.
    Across,
}

/// How the closed box `b` lies to an obstacle.
fn relation(b: [f64; 4], o: &Obstacle) -> Relation {
    match *o {
        Obstacle::Rect { x0, y0, x1, y1 } => {
            if b[2] < x0 || b[0] > x1 || b[3] < y0 || b[1] > y1 {
                Relation::Apart
            } else if x0 <= b[0] && b[2] <= x1 && y0 <= b[1] && b[3] <= y1 {
                Relation::Inside
            } else {
                Relation::Across
            }
        }
        Obstacle::Circle { cx, cy, r } => {
            // The point of the box nearest the centre decides whether they touch.
            let near = (cx.clamp(b[0], b[2]), cy.clamp(b[1], b[3]));
            if !geometry::in_disk(near, (cx, cy), r) {
                return Relation::Apart;
            }
            let corners = [(b[0], b[1]), (b[2], b[1]), (b[2], b[3]), (b[0], b[3])];
            if corners.iter().all(|&p| geometry::in_disk(p, (cx, cy), r)) {
                Relation::Inside
            } else {
                Relation::Across
            }
        }
    }
}
