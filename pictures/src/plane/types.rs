//! The plane pictures' input: the frame's data, rasters, arrows, runs, and the limits
//! every picture checks first.

use crate::draw::{clean_text, shorten};
use crate::{PictureError, RegionKind, Result};

/// The most cells a raster may have (a region's or an options map's).
pub const MAX_RASTER_CELLS: usize = 1 << 20;
/// The most columns or rows a raster may have.
pub const MAX_RASTER_SIDE: usize = 2048;
/// The most arrows (and, separately, termination points) a flat policy may draw.
pub const MAX_ARROWS: usize = 10_000;
/// The most steps a sample run may have.
pub const MAX_RUN_STEPS: usize = 100_000;
/// The most maps an options policy may draw in one picture.
pub const MAX_PANELS: usize = 36;

/// The frame under every plane picture: the extent, the axes' names, obstacles, the start
/// area and regions.
///
/// `x` runs left to right and `y` bottom to top, both in the world's units.
#[derive(Debug, Clone, PartialEq)]
pub struct Plane {
    /// The extent along the horizontal axis, `[lo, hi]` with `lo < hi`, both finite.
    pub x: [f64; 2],
    /// The extent along the vertical axis, `[lo, hi]` with `lo < hi`, both finite.
    pub y: [f64; 2],
    /// The horizontal axis's name (a state variable's, such as `x`).
    pub x_label: String,
    /// The vertical axis's name (such as `y`, or `v` in a phase plane).
    pub y_label: String,
    /// Whether one unit is as long on both axes (a plane world); `false` for a phase plane,
    /// whose axes have different units and which is drawn 4:3. Even to scale, a side is
    /// drawn at least a fifth as long as the other.
    pub to_scale: bool,
    /// Obstacles, drawn filled dark and clipped to the extent.
    pub obstacles: Vec<Shape>,
    /// The start area `[x0, y0, x1, y1]`, drawn as a dashed rectangle; `None` when episodes
    /// start anywhere.
    pub start: Option<[f64; 4]>,
    /// Regions, each sampled on a raster over the extent.
    pub regions: Vec<PlaneRegion>,
}

/// An obstacle's shape, in the plane's units; edges included.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// The disk of centre `(cx, cy)` and radius `r > 0`.
    Circle {
        /// The centre's x.
        cx: f64,
        /// The centre's y.
        cy: f64,
        /// The radius.
        r: f64,
    },
    /// The rectangle `[x0, x1] x [y0, y1]`, `x0 < x1`, `y0 < y1`.
    Rect {
        /// The left edge.
        x0: f64,
        /// The bottom edge.
        y0: f64,
        /// The right edge.
        x1: f64,
        /// The top edge.
        y1: f64,
    },
}

/// Values on a lattice of equal cells over the plane's extent: `columns` left to right,
/// `rows` bottom to top, `values` row by row from the bottom row (the value of column `i`,
/// row `j` is `values[j * columns + i]`). Cell `(i, j)` covers the `i`-th of `columns` equal
/// slices of the extent along `x` and the `j`-th of `rows` along `y`; [`Plane::centre`] is
/// where to sample it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Raster<T> {
    /// Cells along `x`.
    pub columns: usize,
    /// Cells along `y`.
    pub rows: usize,
    /// The values, `columns * rows` of them, bottom row first.
    pub values: Vec<T>,
}

impl<T> Raster<T> {
    /// The raster whose cell `(column, row)` holds `f(column, row)`. Errors for an empty
    /// raster or one past [`MAX_RASTER_SIDE`] or [`MAX_RASTER_CELLS`], before calling `f`.
    pub fn from_fn(
        columns: usize,
        rows: usize,
        mut f: impl FnMut(usize, usize) -> T,
    ) -> Result<Raster<T>> {
        check_raster_size(columns, rows, "raster")?;
        let mut values = Vec::with_capacity(columns * rows);
        for row in 0..rows {
            for column in 0..columns {
                values.push(f(column, row));
            }
        }
        Ok(Raster { columns, rows, values })
    }

    /// The value of cell `(column, row)`, or `None` outside the raster.
    pub fn get(&self, column: usize, row: usize) -> Option<&T> {
        if column < self.columns && row < self.rows {
            self.values.get(row * self.columns + column)
        } else {
            None
        }
    }

    /// Checks the size and the number of values; `what` names the raster in the error.
    pub(super) fn check(&self, what: &str) -> Result<()> {
        check_raster_size(self.columns, self.rows, what)?;
        if self.values.len() != self.columns * self.rows {
            return Err(PictureError::new(format!(
                "{what} has {} values for {} x {} cells",
                self.values.len(),
                self.columns,
                self.rows
            )));
        }
        Ok(())
    }
}

fn check_raster_size(columns: usize, rows: usize, what: &str) -> Result<()> {
    if columns == 0 || rows == 0 {
        return Err(PictureError::new(format!("{what} is empty ({columns} x {rows} cells)")));
    }
    let cells = columns.checked_mul(rows);
    if columns > MAX_RASTER_SIDE
        || rows > MAX_RASTER_SIDE
        || cells.is_none_or(|c| c > MAX_RASTER_CELLS)
    {
        return Err(PictureError::new(format!(
            "{what} is too large to draw ({columns} x {rows} cells; at most {MAX_RASTER_SIDE} a \
             side and {MAX_RASTER_CELLS} in all)"
        )));
    }
    Ok(())
}

/// A named region sampled on a raster: where it holds, and what it is to the task.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlaneRegion {
    /// The label written on the region.
    pub name: String,
    /// What the region is to the task: to reach (shaded grey), to avoid (hatched red) or
    /// another (dashed outline).
    pub kind: RegionKind,
    /// Whether the region holds at each cell's centre.
    pub holds: Raster<bool>,
}

/// The greedy action of a flat policy at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arrow {
    /// Where, in the plane's units.
    pub x: f64,
    /// Where, in the plane's units.
    pub y: f64,
    /// The way the action points on the picture (`+x` right, `+y` up; the length does not
    /// matter), or `None` for an action without a direction, drawn as a ring (`none` on
    /// `mountain-car`).
    pub direction: Option<(f64, f64)>,
}

/// One map of an options policy: the option picked in each cell for one memory value.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlaneSlice {
    /// What the map shows (such as `one step after A`), written over it; empty for none.
    pub label: String,
    /// The picked option's index into the options list, or `None` where none is picked.
    pub choices: Raster<Option<usize>>,
}

/// What happened to the move from a step of a sample run to the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Outcome {
    /// The move went the way the action chose, or nothing is known of it.
    #[default]
    AsChosen,
    /// Another action was taken instead (a slip).
    Slipped,
    /// The move was blocked: the robot stayed where it was.
    Blocked,
}

/// One step of a sample run on a plane.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneStep {
    /// Where the robot is, in the plane's units.
    pub x: f64,
    /// Where the robot is, in the plane's units.
    pub y: f64,
    /// The option in force (an index into the options list), or `None`.
    pub option: Option<usize>,
    /// What happened to the move from this step to the next (ignored on the last step).
    pub outcome: Outcome,
    /// Where the chosen action leads from here without slip or noise, if known: a slip or
    /// a blocked move is drawn as a dotted stub towards it.
    pub intended: Option<(f64, f64)>,
    /// The regions (indices into [`Plane::regions`]) the robot entered at this step: they
    /// hold here and did not at the step before.
    pub entered: Vec<usize>,
}

impl PlaneStep {
    /// A step at `(x, y)` under `option`, moving as chosen, entering no region.
    pub fn at(x: f64, y: f64, option: Option<usize>) -> PlaneStep {
        PlaneStep { x, y, option, outcome: Outcome::AsChosen, intended: None, entered: Vec::new() }
    }
}

impl Plane {
    /// A plane of extent `x` by `y` with axes named `x` and `y`, to scale, with nothing on it.
    pub fn new(x: [f64; 2], y: [f64; 2]) -> Plane {
        Plane {
            x,
            y,
            x_label: "x".into(),
            y_label: "y".into(),
            to_scale: true,
            obstacles: Vec::new(),
            start: None,
            regions: Vec::new(),
        }
    }

    /// The centre of cell `(column, row)` of a raster of `columns` x `rows` cells over the
    /// extent: where a region or a policy is sampled for that cell.
    pub fn centre(&self, columns: usize, rows: usize, column: usize, row: usize) -> (f64, f64) {
        let at = |[lo, hi]: [f64; 2], n: usize, i: usize| {
            lo + (hi - lo) * (i as f64 + 0.5) / n.max(1) as f64
        };
        (at(self.x, columns, column), at(self.y, rows, row))
    }

    /// The centres of every cell of a raster of `columns` x `rows` cells, in the raster's
    /// order (bottom row first). Errors where [`Raster::from_fn`] would.
    pub fn lattice(&self, columns: usize, rows: usize) -> Result<Vec<(f64, f64)>> {
        Raster::from_fn(columns, rows, |i, j| self.centre(columns, rows, i, j)).map(|r| r.values)
    }

    /// Checks the extent, the obstacles, the start area and the regions' rasters.
    pub fn check(&self) -> Result<()> {
        for (name, [lo, hi]) in [(&self.x_label, self.x), (&self.y_label, self.y)] {
            let width = hi - lo;
            if !(lo.is_finite() && hi.is_finite() && width.is_finite() && width > 0.0) {
                return Err(PictureError::new(format!(
                    "the extent along `{}` is [{lo}, {hi}]; it must be finite and not empty",
                    shorten(&clean_text(name))
                )));
            }
        }
        for (k, shape) in self.obstacles.iter().enumerate() {
            let ok = match *shape {
                Shape::Circle { cx, cy, r } => {
                    cx.is_finite() && cy.is_finite() && r.is_finite() && r > 0.0
                }
                Shape::Rect { x0, y0, x1, y1 } => {
                    [x0, y0, x1, y1].iter().all(|v| v.is_finite()) && x0 < x1 && y0 < y1
                }
            };
            if !ok {
                return Err(PictureError::new(format!(
                    "obstacle {} ({}) is not a finite circle of positive radius or a \
                     rectangle with x0 < x1 and y0 < y1",
                    k + 1,
                    shape_words(shape)
                )));
            }
        }
        if let Some([x0, y0, x1, y1]) = self.start
            && !([x0, y0, x1, y1].iter().all(|v| v.is_finite()) && x0 <= x1 && y0 <= y1)
        {
            return Err(PictureError::new(format!(
                "the start area [{x0}, {y0}, {x1}, {y1}] is not a finite rectangle"
            )));
        }
        for region in &self.regions {
            region.holds.check(&format!("region `{}`", shorten(&clean_text(&region.name))))?;
        }
        Ok(())
    }

    /// Checks that `(x, y)` is finite and inside the extent; `what` names it in the error.
    pub(super) fn check_point(&self, (x, y): (f64, f64), what: &str) -> Result<()> {
        let inside = |v: f64, [lo, hi]: [f64; 2]| lo <= v && v <= hi;
        if !(x.is_finite() && y.is_finite()) {
            return Err(PictureError::new(format!("{what} ({x}, {y}) is not a finite point")));
        }
        if inside(x, self.x) && inside(y, self.y) {
            Ok(())
        } else {
            Err(PictureError::new(format!(
                "{what} ({x}, {y}) is outside the extent [{}, {}] x [{}, {}]",
                self.x[0], self.x[1], self.y[0], self.y[1]
            )))
        }
    }
}

/// An obstacle as a world file writes it: `circle [cx, cy, r]`, `rect [x0, y0, x1, y1]`.
fn shape_words(shape: &Shape) -> String {
    let (kind, numbers) = match *shape {
        Shape::Circle { cx, cy, r } => ("circle", vec![cx, cy, r]),
        Shape::Rect { x0, y0, x1, y1 } => ("rect", vec![x0, y0, x1, y1]),
    };
    let numbers: Vec<String> = numbers.iter().map(ToString::to_string).collect();
    format!("{kind} [{}]", numbers.join(", "))
}
