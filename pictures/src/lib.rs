//! SVG pictures of hstl policies, sample runs and learning curves.
//!
//! The functions take plain data (no learner types) and return a complete SVG document as a
//! `String`, in the style of Figures 2 and 3 of Li & Belta (2016): flat policies as arrow
//! fields, the options policy as a coloured map, sample runs as coloured paths and the
//! learning curve as a mean line over a band of seeds. An options policy with memory is
//! drawn as one map per memory slice ([`options_policy_slices`]); the learning curves of
//! several specs overlay in one figure ([`learning_curves`]).
//!
//! A title may hold a second line after a newline: a note drawn smaller under it (which
//! seed a picture shows, say).
//!
//! Continuous worlds (a plane world, or a phase plane such as `mountain-car`'s) get the
//! same pictures over a [`Plane`]: its extent in the world's units, obstacles, and regions
//! sampled on a [`Raster`] ([`plane_flat_policy`], [`plane_options_policy`],
//! [`plane_sample_run`]).
//!
//! Grid coordinates follow the GridWorld contract: `x` is the column from left to right, `y`
//! the row from bottom to top, and `(0, 0)` is the bottom-left cell.
//!
//! ```
//! use hstl_pictures::{Action, Cell, Grid, Region, flat_policy};
//!
//! let grid = Grid {
//!     width: 3,
//!     height: 2,
//!     regions: vec![Region::new("A", vec![(2, 1)])],
//!     walls: vec![(1, 0)],
//!     starts: vec![],
//! };
//! let arrows = [Cell { x: 0, y: 1, action: Action::Right }, Cell { x: 1, y: 1, action: Action::Right }];
//! let svg = flat_policy(&grid, "Go to A", &arrows, &[(2, 1)])?;
//! assert!(svg.starts_with("<svg"));
//! # Ok::<(), hstl_pictures::PictureError>(())
//! ```
//!
//! Every function checks its input and returns a [`PictureError`] instead of panicking, for
//! example for an empty grid or a cell outside it.

mod curve;
mod draw;
mod grid;
mod label;
mod palette;
mod plane;
mod run;

use std::fmt;

pub use curve::{Panel, Series, learning_curve, learning_curves};
pub use grid::{Slice, flat_policy, options_policy, options_policy_slices};
pub use plane::{
    Arrow, MAX_ARROWS, MAX_PANELS, MAX_RASTER_CELLS, MAX_RASTER_SIDE, MAX_RUN_STEPS, Outcome,
    Plane, PlaneRegion, PlaneSlice, PlaneStep, Raster, Shape, plane_flat_policy,
    plane_options_policy, plane_sample_run,
};
pub use run::{RunStep, sample_run};

/// The largest grid side that can be drawn; larger grids would give unreadable pictures.
pub const MAX_GRID_SIDE: usize = 256;

/// A rectangular grid world with named regions, as drawn under every grid picture.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Grid {
    /// Number of columns; `x` runs over `0..width`.
    pub width: usize,
    /// Number of rows; `y` runs over `0..height`, bottom to top.
    pub height: usize,
    /// Regions drawn as shaded, outlined and labelled cells.
    pub regions: Vec<Region>,
    /// Wall cells as `(x, y)`, drawn filled dark; the robot is never on one.
    pub walls: Vec<(i64, i64)>,
    /// Start cells as `(x, y)`, marked with a small corner triangle; leave it empty when
    /// every free cell is a start.
    pub starts: Vec<(i64, i64)>,
}

/// A named set of cells, drawn shaded with its name written over it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Region {
    /// The label written on the region (for example `A`).
    pub name: String,
    /// The cells of the region as `(x, y)`; any shape is allowed, an empty region is not drawn.
    pub cells: Vec<(i64, i64)>,
    /// What the region is to the task, which decides how it is drawn.
    pub kind: RegionKind,
}

/// What a region is to the task.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum RegionKind {
    /// A region to reach (an option's region): shaded grey with a solid outline.
    #[default]
    Reach,
    /// A region to avoid (an obstacle the task forbids, as in `always !Obstacle`): hatched
    /// red with a red outline.
    Avoid,
    /// Any other region the task names: a dashed outline, unshaded.
    Other,
}

impl Region {
    /// A region to reach with the given name and cells.
    pub fn new(name: impl Into<String>, cells: Vec<(i64, i64)>) -> Region {
        Region { name: name.into(), cells, kind: RegionKind::Reach }
    }

    /// The same region as another kind.
    pub fn with_kind(self, kind: RegionKind) -> Region {
        Region { kind, ..self }
    }
}

/// A primitive action of the grid world.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Action {
    /// Move to `y + 1`.
    Up,
    /// Move to `y - 1`.
    Down,
    /// Move to `x - 1`.
    Left,
    /// Move to `x + 1`.
    Right,
}

/// The action a flat policy takes in one cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cell {
    /// Column, left to right.
    pub x: i64,
    /// Row, bottom to top.
    pub y: i64,
    /// The action chosen in this cell.
    pub action: Action,
}

/// Why a picture could not be drawn.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PictureError {
    message: String,
}

/// The result of drawing a picture: an SVG document or the reason it could not be drawn.
pub type Result<T> = std::result::Result<T, PictureError>;

impl PictureError {
    /// An error with the given message.
    pub fn new(message: impl Into<String>) -> Self {
        Self { message: message.into() }
    }

    /// The message, without a trailing period.
    pub fn message(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for PictureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for PictureError {}
