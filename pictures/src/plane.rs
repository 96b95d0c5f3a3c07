//! Plane pictures: the pictures of a policy learned on a continuous world (a plane world, or
//! a phase plane such as `mountain-car`'s `(x, v)`), in the grid pictures' style.
//!
//! A [`Plane`] is the frame under every such picture: the extent in the world's own units
//! with numbered axes, obstacles (circles and rectangles, drawn dark as walls are), the
//! start area, and regions. A region is whatever state formula the spec names, so the
//! caller samples it on a [`Raster`] (whether it holds at each raster cell's centre) and the
//! picture shades, hatches and outlines those cells as a grid picture does its region
//! cells.
//!
//! On top of the frame: the greedy action of a primitive option as arrows on a lattice of
//! points ([`plane_flat_policy`]), the options policy as a raster coloured by the option
//! picked, one small map per memory slice in one picture ([`plane_options_policy`]), and a
//! sample run as a path shaded by time with its slips, blocked moves and region entries
//! ([`plane_sample_run`]).
//!
//! Every function checks its input first: an empty or non-finite extent, a point that is
//! not finite or lies outside the extent, a raster of the wrong size or past
//! [`MAX_RASTER_CELLS`], more than [`MAX_ARROWS`] arrows or [`MAX_RUN_STEPS`] steps is a
//! [`PictureError`], never a panic.

use std::collections::HashSet;

use plotters::prelude::*;
use plotters::style::FontTransform;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::draw::{
    Area, LABEL_SIZE, LegendEntry, Mark, clean_text, draw_arrow, draw_blocked, draw_dashed,
    draw_end, draw_entry, draw_err, draw_legend, draw_region_fill, draw_region_hatch, draw_slip,
    draw_start, draw_still, draw_terminate, draw_text, draw_title, legend_size, shorten,
    text_style, text_width, title_height, title_parts, title_width,
};
use crate::grid::{cell_boxes, round_joins};
use crate::label::{CellBox, best_box};
use crate::palette::{AVOID, GRID_LINE, INK, REGION, START_CELL, WALL, option_color, shade};
use crate::run::{draw_head, tick_step};
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
    fn check(&self, what: &str) -> Result<()> {
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
    fn check_point(&self, (x, y): (f64, f64), what: &str) -> Result<()> {
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

/// Where a plane is drawn on the canvas, in pixels, and its extent.
#[derive(Debug, Clone, Copy)]
struct Frame {
    left: i32,
    top: i32,
    width: i32,
    height: i32,
    x: [f64; 2],
    y: [f64; 2],
}

/// A pixel coordinate from a float, kept in a sane range (a point may lie off the frame).
fn px(v: f64) -> i32 {
    if v.is_finite() { v.clamp(-100_000.0, 100_000.0).round() as i32 } else { 0 }
}

impl Frame {
    /// The pixel of the point `(x, y)`, as floats.
    fn at_f(&self, (x, y): (f64, f64)) -> (f64, f64) {
        let [x0, x1] = self.x;
        let [y0, y1] = self.y;
        (
            self.left as f64 + (x - x0) / (x1 - x0) * self.width as f64,
            self.top as f64 + (y1 - y) / (y1 - y0) * self.height as f64,
        )
    }

    /// The pixel of the point `(x, y)`.
    fn at(&self, p: (f64, f64)) -> (i32, i32) {
        let (a, b) = self.at_f(p);
        (px(a), px(b))
    }

    fn right(&self) -> i32 {
        self.left + self.width
    }

    fn bottom(&self) -> i32 {
        self.top + self.height
    }

    /// The pixel column of the left edge of raster column `i` of `n`.
    fn column_px(&self, i: i64, n: usize) -> i32 {
        self.left + (i as f64 * self.width as f64 / n as f64).round() as i32
    }

    /// The pixel row of the bottom edge of raster row `j` of `n`.
    fn row_px(&self, j: i64, n: usize) -> i32 {
        self.bottom() - (j as f64 * self.height as f64 / n as f64).round() as i32
    }

    /// The pixel rectangle of a box of raster cells.
    fn box_rect(&self, b: CellBox, columns: usize, rows: usize) -> [(i32, i32); 2] {
        [
            (self.column_px(b.x0, columns), self.row_px(b.y1 + 1, rows)),
            (self.column_px(b.x1 + 1, columns), self.row_px(b.y0, rows)),
        ]
    }

    /// Clips a pixel polygon to the frame (Sutherland-Hodgman; the frame is convex).
    fn clip(&self, polygon: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
        let (l, t, r, b) =
            (self.left as f64, self.top as f64, self.right() as f64, self.bottom() as f64);
        // Each edge: inside test and the intersection of a segment with its line.
        type Inside = fn((f64, f64), f64) -> bool;
        let edges: [(Inside, f64, bool); 4] = [
            (|p, v| p.0 >= v, l, true),
            (|p, v| p.0 <= v, r, true),
            (|p, v| p.1 >= v, t, false),
            (|p, v| p.1 <= v, b, false),
        ];
        let mut points = polygon;
        for (inside, v, vertical) in edges {
            let input = std::mem::take(&mut points);
            let n = input.len();
            for i in 0..n {
                let (p, q) = (input[i], input[(i + 1) % n]);
                let cross = |p: (f64, f64), q: (f64, f64)| {
                    if vertical {
                        let s = (v - p.0) / (q.0 - p.0);
                        (v, p.1 + s * (q.1 - p.1))
                    } else {
                        let s = (v - p.1) / (q.1 - p.1);
                        (p.0 + s * (q.0 - p.0), v)
                    }
                };
                match (inside(p, v), inside(q, v)) {
                    (true, true) => points.push(q),
                    (true, false) => points.push(cross(p, q)),
                    (false, true) => {
                        points.push(cross(p, q));
                        points.push(q);
                    }
                    (false, false) => {}
                }
            }
        }
        points
    }
}

/// A drawing step of a plane picture, given the frame of its map.
type Layer<'f> = &'f dyn Fn(&Area<'_>, &Frame) -> Result<()>;

/// A drawing step a picture builds for each of its maps.
type OwnedLayer = Box<dyn Fn(&Area<'_>, &Frame) -> Result<()>>;

/// A drawing step under the map's axes, given the frame and the top of its strip.
type Footer<'f> = &'f dyn Fn(&Area<'_>, &Frame, i32) -> Result<()>;

/// One map of a picture: a label over it and its layers.
struct Panel<'f> {
    label: String,
    /// Drawn under the region outlines and obstacles (colours).
    under: Layer<'f>,
    /// Drawn over everything else in the frame (arrows, paths).
    over: Layer<'f>,
}

fn nothing(_: &Area<'_>, _: &Frame) -> Result<()> {
    Ok(())
}

const TOP: i32 = 56;
const LEFT_MARGIN: i32 = 10;
const BOTTOM: i32 = 52;
const GAP: i32 = 28;
const RIGHT: i32 = 16;
const PANEL_GAP: i32 = 24;
const PANEL_LABEL: i32 = 26;
/// The longer side of a map drawn alone, in pixels.
const FRAME_PIXELS: f64 = 600.0;
/// The longer side of each of several maps, in pixels.
const SMALL_FRAME_PIXELS: f64 = 340.0;
/// The largest pixel size of a region's name in its box.
const TAG_PX: f64 = 13.0;
/// Tick labels at least this many pixels apart along x, and along y.
const X_TICK_GAP: i32 = 70;
const Y_TICK_GAP: i32 = 40;
/// A sample run shows its direction on every this many moves.
const HEAD_EVERY: usize = 4;
/// The height of a sample run's timeline, in pixels.
const TIMELINE: i32 = 76;
/// The timeline's shading changes in at most this many pieces.
const RAMP_PIECES: usize = 240;

/// The pixel size of each map of `plane` when `panels` are drawn.
fn frame_size(plane: &Plane, panels: usize) -> (i32, i32) {
    let side = if panels > 1 { SMALL_FRAME_PIXELS } else { FRAME_PIXELS };
    if !plane.to_scale {
        return (side as i32, (side * 0.75) as i32);
    }
    let (w, h) = (plane.x[1] - plane.x[0], plane.y[1] - plane.y[0]);
    let scale = side / w.max(h);
    let fit = |v: f64| (v * scale).clamp(side * 0.2, side).round() as i32;
    (fit(w), fit(h))
}

/// Tick labels written in exponent form: for steps too large or small for plain digits.
const EXPONENT: usize = usize::MAX;

/// Round tick values over `[lo, hi]` at least `gap` pixels apart on `pixels`, and the
/// decimals to write them with ([`EXPONENT`] for exponent form).
fn ticks([lo, hi]: [f64; 2], pixels: i32, gap: i32) -> (Vec<f64>, usize) {
    let most = (pixels / gap.max(1)).max(1) as f64;
    let raw = (hi - lo) / most;
    if !(raw.is_finite() && raw > 0.0) {
        return (vec![lo, hi], EXPONENT);
    }
    let exponent = raw.log10().floor();
    let unit = 10f64.powf(exponent);
    let step =
        [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * unit).find(|&s| s >= raw).unwrap_or(10.0 * unit);
    let decimals = if !(1e-5..1e7).contains(&step) {
        EXPONENT
    } else if step >= 1.0 {
        0
    } else {
        (-step.log10().floor()) as usize
    };
    let (first, last) = ((lo / step).ceil(), (hi / step).floor());
    if !(first.is_finite() && last.is_finite()) || last - first > 200.0 || last < first {
        return (vec![lo, hi], EXPONENT);
    }
    let values = (first as i64..=last as i64).map(|k| k as f64 * step).collect();
    (values, decimals)
}

/// A tick value written with `decimals` (or in exponent form for [`EXPONENT`]), without a
/// minus on zero.
fn tick_label(v: f64, decimals: usize) -> String {
    let text = if decimals == EXPONENT { format!("{v:.2e}") } else { format!("{v:.decimals$}") };
    match text.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_owned(),
        _ => text,
    }
}

/// The legend rows for the kinds of regions, the obstacles and the start area of a plane.
fn frame_legend(plane: &Plane) -> Vec<LegendEntry> {
    let mut rows = Vec::new();
    for (kind, label) in [
        (RegionKind::Reach, "region to reach"),
        (RegionKind::Avoid, "region to avoid"),
        (RegionKind::Other, "other region"),
    ] {
        if plane.regions.iter().any(|r| r.kind == kind && r.holds.values.iter().any(|&h| h)) {
            rows.push(LegendEntry::new(Mark::Region(kind), label));
        }
    }
    if !plane.obstacles.is_empty() {
        rows.push(LegendEntry::new(Mark::Wall, "obstacle"));
    }
    if plane.start.is_some() {
        rows.push(LegendEntry::new(Mark::StartArea, "start area"));
    }
    rows
}

/// The cells of a raster where `keep` holds, as `(column, row)`.
fn cells_where<T>(raster: &Raster<T>, keep: impl Fn(&T) -> bool) -> Vec<(i64, i64)> {
    raster
        .values
        .iter()
        .enumerate()
        .filter(|(_, v)| keep(v))
        .map(|(k, _)| ((k % raster.columns) as i64, (k / raster.columns) as i64))
        .collect()
}

/// Lays out and draws a plane picture: the title, one map per panel (in rows of up to
/// three, each with its label, regions, layers, obstacles, start area, outlines, region
/// names and axes), the legend on the right, and the footer under a lone map.
fn render(
    plane: &Plane,
    title: &str,
    heading: &str,
    legend: &[LegendEntry],
    panels: &[Panel<'_>],
    footer: Option<(i32, Footer<'_>)>,
) -> Result<String> {
    let n = panels.len().max(1);
    let columns = if n == 4 { 2 } else { n.min(3) };
    let rows = n.div_ceil(columns);
    let (fw, fh) = frame_size(plane, n);
    let (x_ticks, x_decimals) = ticks(plane.x, fw, X_TICK_GAP);
    let (y_ticks, y_decimals) = ticks(plane.y, fh, Y_TICK_GAP);
    let tick_size = LABEL_SIZE * 0.85;
    let y_label_w =
        y_ticks.iter().map(|&v| text_width(&tick_label(v, y_decimals), tick_size)).max();
    let y_name = shorten(&clean_text(&plane.y_label));
    let rotate = y_name.chars().count() > 3;
    let name_w = if rotate { 26 } else { text_width(&y_name, LABEL_SIZE) + 12 };
    let axis_left = y_label_w.unwrap_or(0) + 10 + name_w;
    let labelled = panels.iter().any(|p| !p.label.is_empty());
    let label_h = if labelled { PANEL_LABEL } else { 0 };
    let title = title_parts(title);
    let top = TOP + title_height(&title);
    let panel_w = axis_left + fw + PANEL_GAP;
    let panel_h = label_h + fh + BOTTOM;
    let maps_w = LEFT_MARGIN + panel_w * columns as i32 - PANEL_GAP;
    let (legend_w, legend_h) = legend_size(heading, legend);
    let footer_h = footer.map_or(0, |(h, _)| h);
    let width = (maps_w + GAP + legend_w + RIGHT).max(title_width(&title));
    let height = (top + panel_h * rows as i32 + footer_h).max(top + legend_h + 16);
    let mut svg = String::new();
    {
        let area =
            SVGBackend::with_string(&mut svg, (width as u32, height as u32)).into_drawing_area();
        area.fill(&WHITE).map_err(draw_err)?;
        draw_title(&area, &title, width / 2)?;
        let mut last = None;
        for (k, panel) in panels.iter().enumerate() {
            let (col, row) = ((k % columns) as i32, (k / columns) as i32);
            let frame = Frame {
                left: LEFT_MARGIN + col * panel_w + axis_left,
                top: top + row * panel_h + label_h,
                width: fw,
                height: fh,
                x: plane.x,
                y: plane.y,
            };
            if !panel.label.is_empty() {
                let style =
                    TextStyle::from((crate::draw::FONT, LABEL_SIZE, FontStyle::Bold).into_font())
                        .color(&INK)
                        .pos(Pos::new(HPos::Center, VPos::Bottom));
                let label = shorten(&clean_text(&panel.label));
                draw_text(&area, &label, (frame.left + fw / 2, frame.top - 6), &style)?;
            }
            draw_map(&area, &frame, plane, panel, (&x_ticks, x_decimals), (&y_ticks, y_decimals))?;
            let name = text_style(LABEL_SIZE, &INK, HPos::Center, VPos::Top);
            let below = frame.bottom() + 8 + (tick_size / 1.24) as i32;
            let x_name = shorten(&clean_text(&plane.x_label));
            draw_text(&area, &x_name, (frame.left + fw / 2, below), &name)?;
            let middle = (frame.left - axis_left + 6 + name_w / 2, frame.top + fh / 2);
            if rotate {
                let style = text_style(LABEL_SIZE, &INK, HPos::Center, VPos::Center)
                    .transform(FontTransform::Rotate270);
                draw_text(&area, &y_name, middle, &style)?;
            } else {
                let style = text_style(LABEL_SIZE, &INK, HPos::Center, VPos::Center);
                draw_text(&area, &y_name, middle, &style)?;
            }
            last = Some(frame);
        }
        draw_legend(&area, (maps_w + GAP, top - 4), heading, legend)?;
        if let (Some((_, footer)), Some(frame)) = (footer, last) {
            footer(&area, &frame, frame.bottom() + BOTTOM)?;
        }
        area.present().map_err(draw_err)?;
    }
    Ok(round_joins(svg))
}

/// Draws one map: tick lines, region shading, the panel's under layer, hatching,
/// obstacles, the start area, the border, region outlines, the over layer, region names and
/// the tick labels.
fn draw_map(
    area: &Area<'_>,
    frame: &Frame,
    plane: &Plane,
    panel: &Panel<'_>,
    (x_ticks, x_decimals): (&[f64], usize),
    (y_ticks, y_decimals): (&[f64], usize),
) -> Result<()> {
    let thin = GRID_LINE.stroke_width(1);
    for &v in x_ticks {
        let (x, _) = frame.at((v, plane.y[0]));
        area.draw(&PathElement::new(vec![(x, frame.top), (x, frame.bottom())], thin))
            .map_err(draw_err)?;
    }
    for &v in y_ticks {
        let (_, y) = frame.at((plane.x[0], v));
        area.draw(&PathElement::new(vec![(frame.left, y), (frame.right(), y)], thin))
            .map_err(draw_err)?;
    }
    let region_cells: Vec<Vec<(i64, i64)>> =
        plane.regions.iter().map(|r| cells_where(&r.holds, |&h| h)).collect();
    for (region, cells) in plane.regions.iter().zip(&region_cells) {
        for b in cell_boxes(cells.iter().copied()) {
            let rect = frame.box_rect(b, region.holds.columns, region.holds.rows);
            draw_region_fill(area, region.kind, rect)?;
        }
    }
    (panel.under)(area, frame)?;
    for (region, cells) in plane.regions.iter().zip(&region_cells) {
        if region.kind == RegionKind::Avoid {
            for b in cell_boxes(cells.iter().copied()) {
                let rect = frame.box_rect(b, region.holds.columns, region.holds.rows);
                draw_region_hatch(area, region.kind, rect)?;
            }
        }
    }
    for shape in &plane.obstacles {
        draw_obstacle(area, frame, shape)?;
    }
    if let Some([x0, y0, x1, y1]) = plane.start {
        let clip = |v: f64, [lo, hi]: [f64; 2]| v.clamp(lo, hi);
        let (l, b) = frame.at((clip(x0, plane.x), clip(y0, plane.y)));
        let (r, t) = frame.at((clip(x1, plane.x), clip(y1, plane.y)));
        let corners = [(l, t), (r, t), (r, b), (l, b)];
        for i in 0..4 {
            draw_dashed(area, corners[i], corners[(i + 1) % 4], START_CELL.stroke_width(2))?;
        }
    }
    area.draw(&Rectangle::new(
        [(frame.left, frame.top), (frame.right(), frame.bottom())],
        INK.stroke_width(2),
    ))
    .map_err(draw_err)?;
    for region in &plane.regions {
        draw_outline(area, frame, region)?;
    }
    (panel.over)(area, frame)?;
    for (region, cells) in plane.regions.iter().zip(&region_cells) {
        draw_region_name(area, frame, region, cells)?;
    }
    let size = LABEL_SIZE * 0.85;
    let below = text_style(size, &INK, HPos::Center, VPos::Top);
    for &v in x_ticks {
        let (x, _) = frame.at((v, plane.y[0]));
        area.draw(&PathElement::new(
            vec![(x, frame.bottom()), (x, frame.bottom() + 4)],
            INK.stroke_width(1),
        ))
        .map_err(draw_err)?;
        draw_text(area, &tick_label(v, x_decimals), (x, frame.bottom() + 6), &below)?;
    }
    let beside = text_style(size, &INK, HPos::Right, VPos::Center);
    for &v in y_ticks {
        let (_, y) = frame.at((plane.x[0], v));
        area.draw(&PathElement::new(
            vec![(frame.left - 4, y), (frame.left, y)],
            INK.stroke_width(1),
        ))
        .map_err(draw_err)?;
        draw_text(area, &tick_label(v, y_decimals), (frame.left - 6, y), &beside)?;
    }
    Ok(())
}

/// Draws an obstacle filled dark, clipped to the frame.
fn draw_obstacle(area: &Area<'_>, frame: &Frame, shape: &Shape) -> Result<()> {
    let polygon: Vec<(f64, f64)> = match *shape {
        Shape::Rect { x0, y0, x1, y1 } => {
            [(x0, y0), (x1, y0), (x1, y1), (x0, y1)].iter().map(|&p| frame.at_f(p)).collect()
        }
        Shape::Circle { cx, cy, r } => {
            let (a, _) = frame.at_f((cx - r, cy));
            let (b, _) = frame.at_f((cx + r, cy));
            let n = ((b - a).abs() * 0.6).clamp(24.0, 180.0) as usize;
            (0..n)
                .map(|k| {
                    let t = std::f64::consts::TAU * k as f64 / n as f64;
                    frame.at_f((cx + r * t.cos(), cy + r * t.sin()))
                })
                .collect()
        }
    };
    let clipped = frame.clip(polygon);
    if clipped.len() < 3 {
        return Ok(());
    }
    let points: Vec<(i32, i32)> = clipped.iter().map(|&(x, y)| (px(x), px(y))).collect();
    area.draw(&Polygon::new(points, WALL.filled())).map_err(draw_err)
}

/// Draws a region's outline along the raster's cell edges between its cells and the
/// others, joined into straight runs: solid grey to reach, solid red to avoid, dashed grey
/// for another.
fn draw_outline(area: &Area<'_>, frame: &Frame, region: &PlaneRegion) -> Result<()> {
    let r = &region.holds;
    let (cols, rows) = (r.columns, r.rows);
    let holds = |i: i64, j: i64| {
        i >= 0 && j >= 0 && r.get(i as usize, j as usize).copied().unwrap_or(false)
    };
    let style = match region.kind {
        RegionKind::Avoid => AVOID.stroke_width(2),
        RegionKind::Reach | RegionKind::Other => REGION.stroke_width(2),
    };
    let line = |from: (i32, i32), to: (i32, i32)| -> Result<()> {
        match region.kind {
            RegionKind::Other => draw_dashed(area, from, to, style),
            _ => area.draw(&PathElement::new(vec![from, to], style)).map_err(draw_err),
        }
    };
    // Horizontal edges: along row line `j` (the bottom of row `j`), runs of columns where
    // the cells below and above differ; the frame's border is drawn already.
    for j in 1..rows as i64 {
        let mut start = None;
        for i in 0..=cols as i64 {
            let edge = i < cols as i64 && holds(i, j - 1) != holds(i, j);
            match (edge, start) {
                (true, None) => start = Some(i),
                (false, Some(s)) => {
                    let y = frame.row_px(j, rows);
                    line((frame.column_px(s, cols), y), (frame.column_px(i, cols), y))?;
                    start = None;
                }
                _ => {}
            }
        }
    }
    for i in 1..cols as i64 {
        let mut start = None;
        for j in 0..=rows as i64 {
            let edge = j < rows as i64 && holds(i - 1, j) != holds(i, j);
            match (edge, start) {
                (true, None) => start = Some(j),
                (false, Some(s)) => {
                    let x = frame.column_px(i, cols);
                    line((x, frame.row_px(s, rows)), (x, frame.row_px(j, rows)))?;
                    start = None;
                }
                _ => {}
            }
        }
    }
    Ok(())
}

/// Writes a region's name in a small white box: in its largest rectangle of cells when the
/// box fits there, else just above the region (below it when there is no room) with a
/// short leader.
fn draw_region_name(
    area: &Area<'_>,
    frame: &Frame,
    region: &PlaneRegion,
    cells: &[(i64, i64)],
) -> Result<()> {
    let (cols, rows) = (region.holds.columns, region.holds.rows);
    let set: HashSet<(i64, i64)> = cells.iter().copied().collect();
    let name = shorten(&clean_text(&region.name));
    let cell = (frame.width as f64 / cols as f64).min(frame.height as f64 / rows as f64);
    let Some((b, _)) = best_box(&set, name.chars().count(), cell.max(0.01)) else {
        return Ok(());
    };
    let size = TAG_PX * 1.24;
    let w = text_width(&name, size) + 6;
    let h = TAG_PX.round() as i32 + 4;
    let colour = match region.kind {
        RegionKind::Avoid => AVOID,
        RegionKind::Reach | RegionKind::Other => INK,
    };
    let [(l, t), (r, bottom)] = frame.box_rect(b, cols, rows);
    let keep_inside =
        |x: i32| x.clamp(frame.left + w / 2, (frame.right() - w / 2).max(frame.left + w / 2));
    let (centre_x, box_top) = if r - l >= w + 2 && bottom - t >= h + 2 {
        ((l + r) / 2, (t + bottom) / 2 - h / 2)
    } else {
        // Above the whole region, with a leader from its top edge.
        let (x0, x1) =
            cells.iter().fold((i64::MAX, i64::MIN), |(a, b), c| (a.min(c.0), b.max(c.0)));
        let (y0, y1) =
            cells.iter().fold((i64::MAX, i64::MIN), |(a, b), c| (a.min(c.1), b.max(c.1)));
        let [(l, t), (r, bottom)] = frame.box_rect(CellBox { x0, x1, y0, y1 }, cols, rows);
        let x = (l + r) / 2;
        let (box_top, from, to) = if t - 4 - h >= frame.top {
            (t - 4 - h, t - 4, t)
        } else {
            (bottom + 4, bottom + 4, bottom)
        };
        area.draw(&PathElement::new(vec![(x, from), (x, to)], colour.stroke_width(1)))
            .map_err(draw_err)?;
        (keep_inside(x), box_top)
    };
    let rect = [(centre_x - w / 2, box_top), (centre_x + w / 2, box_top + h)];
    area.draw(&Rectangle::new(rect, WHITE.mix(0.85).filled())).map_err(draw_err)?;
    area.draw(&Rectangle::new(rect, colour.stroke_width(1))).map_err(draw_err)?;
    let style = TextStyle::from((crate::draw::FONT, size, FontStyle::Bold).into_font())
        .color(&colour)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw(&Text::new(name, (centre_x, box_top + h / 2), style)).map_err(draw_err)
}

/// Draws a flat policy on a plane: at each arrow's point, an arrow the way its greedy
/// action points (a ring for an action without a direction), and a red dot at each point
/// where the option terminates, over the frame (see [`Plane`]), with a legend.
///
/// The arrows' size follows their density: about as long as the space each has. Errors
/// for a bad frame (see [`Plane::check`]), more than [`MAX_ARROWS`] arrows or termination
/// points, a point that is not finite or outside the extent, or a direction that is not
/// finite or is zero.
pub fn plane_flat_policy(
    plane: &Plane,
    title: &str,
    arrows: &[Arrow],
    terminate: &[(f64, f64)],
) -> Result<String> {
    plane.check()?;
    for (count, what) in [(arrows.len(), "arrows"), (terminate.len(), "termination points")] {
        if count > MAX_ARROWS {
            return Err(PictureError::new(format!(
                "{count} {what} are too many to draw (at most {MAX_ARROWS})"
            )));
        }
    }
    for a in arrows {
        plane.check_point((a.x, a.y), "arrow")?;
        if let Some((dx, dy)) = a.direction
            && !(dx.is_finite() && dy.is_finite() && (dx != 0.0 || dy != 0.0))
        {
            return Err(PictureError::new(format!(
                "the arrow at ({}, {}) points along ({dx}, {dy}), which is no direction; give \
                 `None` for an action without one",
                a.x, a.y
            )));
        }
    }
    for &p in terminate {
        plane.check_point(p, "termination point")?;
    }
    let mut legend = frame_legend(plane);
    legend.push(LegendEntry::new(Mark::Arrow, "greedy action"));
    if arrows.iter().any(|a| a.direction.is_none()) {
        legend.push(LegendEntry::new(Mark::Still, "action without a direction"));
    }
    if !terminate.is_empty() {
        legend.push(LegendEntry::new(Mark::Terminate, "terminates"));
    }
    let (fw, fh) = frame_size(plane, 1);
    let spacing = ((fw as f64 * fh as f64) / arrows.len().max(1) as f64).sqrt().clamp(8.0, 48.0);
    let over = |area: &Area<'_>, frame: &Frame| -> Result<()> {
        for a in arrows {
            let centre = frame.at_f((a.x, a.y));
            match a.direction {
                Some((dx, dy)) => {
                    // Screen y grows downwards; scale first so huge components stay finite.
                    let scale = dx.abs().max(dy.abs());
                    let (dx, dy) = (dx / scale, -dy / scale);
                    let length = dx.hypot(dy);
                    draw_arrow(area, centre, (dx / length, dy / length), spacing * 0.95)?;
                }
                None => draw_still(area, (px(centre.0), px(centre.1)), spacing)?,
            }
        }
        for &p in terminate {
            draw_terminate(area, frame.at(p), spacing * 0.6)?;
        }
        Ok(())
    };
    let panel = Panel { label: String::new(), under: &nothing, over: &over };
    render(plane, title, "Legend", &legend, &[panel], None)
}

/// Draws an options policy on a plane: each raster cell filled with the colour of the
/// option picked there (white where none is), one map per slice (a memory value), all in
/// one picture with one legend, maps in rows of up to three.
///
/// Options take their colours from their position in `options`, as
/// [`crate::options_policy`] gives them, so the maps agree with each other and with a
/// [`plane_sample_run`] given the same list. Errors for a bad frame, no slice or more than
/// [`MAX_PANELS`], a raster of the wrong size, or a choice past the end of `options` (the
/// message names the slice).
pub fn plane_options_policy(
    plane: &Plane,
    title: &str,
    slices: &[PlaneSlice],
    options: &[String],
) -> Result<String> {
    plane.check()?;
    if slices.is_empty() {
        return Err(PictureError::new("no options map to draw; give at least one slice"));
    }
    if slices.len() > MAX_PANELS {
        return Err(PictureError::new(format!(
            "{} options maps are too many for one picture (at most {MAX_PANELS})",
            slices.len()
        )));
    }
    for slice in slices {
        let what = if slice.label.is_empty() {
            "the options map".to_owned()
        } else {
            format!("options map `{}`", shorten(&clean_text(&slice.label)))
        };
        slice.choices.check(&what)?;
        if let Some(&o) = slice.choices.values.iter().flatten().find(|&&o| o >= options.len()) {
            return Err(PictureError::new(format!(
                "{what} picks option {o}, but there are {} options",
                options.len()
            )));
        }
    }
    let mut legend: Vec<LegendEntry> = options
        .iter()
        .enumerate()
        .map(|(i, name)| LegendEntry::new(Mark::Swatch(option_color(i)), name))
        .collect();
    if slices.iter().any(|s| s.choices.values.iter().any(Option::is_none)) {
        legend.push(LegendEntry::new(Mark::Swatch(WHITE), "no choice"));
    }
    legend.extend(frame_legend(plane));
    let layers: Vec<OwnedLayer> = slices
        .iter()
        .map(|slice| {
            let boxes: Vec<(usize, Vec<CellBox>)> = (0..options.len())
                .map(|o| (o, cell_boxes(cells_where(&slice.choices, |&c| c == Some(o)))))
                .filter(|(_, b)| !b.is_empty())
                .collect();
            let (cols, rows) = (slice.choices.columns, slice.choices.rows);
            Box::new(move |area: &Area<'_>, frame: &Frame| -> Result<()> {
                for (o, list) in &boxes {
                    for &b in list {
                        let rect = frame.box_rect(b, cols, rows);
                        area.draw(&Rectangle::new(rect, option_color(*o).filled()))
                            .map_err(draw_err)?;
                    }
                }
                Ok(())
            }) as OwnedLayer
        })
        .collect();
    let panels: Vec<Panel<'_>> = slices
        .iter()
        .zip(&layers)
        .map(|(slice, layer)| Panel {
            label: slice.label.clone(),
            under: layer.as_ref(),
            over: &nothing,
        })
        .collect();
    render(plane, title, "Option", &legend, &panels, None)
}

/// Draws a sample run on a plane: the path through the robot's positions, each move in the
/// colour of the option in force, shaded by time (a light tint early, the colour itself
/// half-way, a dark shade late) over a dark casing, with its direction shown every few
/// moves; the start and end marked; each slip a dotted stub towards where the chosen action
/// led, ending in a cross, and each blocked move one ending in a red bar (from
/// [`PlaneStep::intended`]; a blocked move without it is a bar at the point); each region
/// entry a diamond, the first entry of each region with its name. Under the map, a timeline shows the option in
/// force at every step, shaded the same way, with the slips, blocked moves and entries
/// above it.
///
/// Options take their colours from their position in `options`; the legend lists only the
/// options the run uses. Errors for a bad frame, an empty run or one of more than
/// [`MAX_RUN_STEPS`] steps, a step that is not finite or lies outside the extent, an
/// intended point that is not finite, an option past the end of `options`, or an entered
/// region past the end of the plane's regions.
pub fn plane_sample_run(
    plane: &Plane,
    title: &str,
    steps: &[PlaneStep],
    options: &[String],
) -> Result<String> {
    plane.check()?;
    if steps.is_empty() {
        return Err(PictureError::new("a sample run needs at least one step"));
    }
    if steps.len() > MAX_RUN_STEPS {
        return Err(PictureError::new(format!(
            "a sample run of {} steps is too long to draw (at most {MAX_RUN_STEPS})",
            steps.len()
        )));
    }
    for (t, s) in steps.iter().enumerate() {
        plane.check_point((s.x, s.y), &format!("step {t} at"))?;
        if let Some((x, y)) = s.intended
            && !(x.is_finite() && y.is_finite())
        {
            return Err(PictureError::new(format!(
                "step {t}'s intended point ({x}, {y}) is not finite"
            )));
        }
        if let Some(o) = s.option.filter(|&o| o >= options.len()) {
            return Err(PictureError::new(format!(
                "step {t} runs option {o}, but there are {} options",
                options.len()
            )));
        }
        if let Some(&r) = s.entered.iter().find(|&&r| r >= plane.regions.len()) {
            return Err(PictureError::new(format!(
                "step {t} enters region {r}, but the plane has {} regions",
                plane.regions.len()
            )));
        }
    }
    let colour_of = |o: Option<usize>| o.map_or(INK, option_color);
    let moves = steps.len() - 1;
    let count = |o: Outcome| steps[..moves].iter().filter(|s| s.outcome == o).count();
    let (slips, blocked) = (count(Outcome::Slipped), count(Outcome::Blocked));
    let entries: usize = steps.iter().map(|s| s.entered.len()).sum();
    let used: HashSet<usize> = steps.iter().filter_map(|s| s.option).collect();
    let mut legend: Vec<LegendEntry> = options
        .iter()
        .enumerate()
        .filter(|(i, _)| used.contains(i))
        .map(|(i, name)| LegendEntry::new(Mark::Swatch(option_color(i)), name))
        .collect();
    legend.push(LegendEntry::new(Mark::Ramp, "light early, dark late"));
    legend.push(LegendEntry::new(Mark::Start, "start"));
    legend.push(LegendEntry::new(Mark::End, "end"));
    if slips > 0 {
        legend.push(LegendEntry::new(Mark::Slip, "slip (dots: move chosen)"));
    }
    if blocked > 0 {
        legend.push(LegendEntry::new(Mark::Blocked, "blocked (dots: move chosen)"));
    }
    if entries > 0 {
        legend.push(LegendEntry::new(Mark::Entry, "enters a region"));
    }
    legend.extend(frame_legend(plane));
    let plural = |n: usize, word: &str| format!("{n} {word}{}", if n == 1 { "" } else { "s" });
    legend.push(LegendEntry::new(
        Mark::Blank,
        format!("{}, {}, {blocked} blocked", plural(moves, "move"), plural(slips, "slip")),
    ));
    let over = |area: &Area<'_>, frame: &Frame| -> Result<()> {
        draw_run_path(area, frame, steps, &colour_of)?;
        for s in &steps[..moves] {
            let from = frame.at((s.x, s.y));
            let to = s.intended.map(|p| {
                let (fx, fy) = frame.at_f((s.x, s.y));
                let (tx, ty) = frame.at_f(p);
                // Most of the way, kept near the frame.
                let reach = 0.6;
                (
                    px((fx + (tx - fx) * reach)
                        .clamp(frame.left as f64 - 12.0, frame.right() as f64 + 12.0)),
                    px((fy + (ty - fy) * reach)
                        .clamp(frame.top as f64 - 12.0, frame.bottom() as f64 + 12.0)),
                )
            });
            match (s.outcome, to) {
                (Outcome::Slipped, Some(to)) => draw_slip(area, from, to, 4)?,
                (Outcome::Blocked, Some(to)) => draw_blocked(area, from, to, 6)?,
                (Outcome::Blocked, None) => {
                    draw_blocked(area, (from.0 - 8, from.1), (from.0 + 8, from.1), 6)?
                }
                _ => {}
            }
        }
        // Every entry a diamond; the region's name beside its first only (the timeline
        // names them all).
        let mut named = HashSet::new();
        for s in steps {
            for &r in &s.entered {
                let at = frame.at((s.x, s.y));
                draw_entry(area, at, 6)?;
                if !named.insert(r) {
                    continue;
                }
                let name = shorten(&clean_text(&plane.regions[r].name));
                let style = TextStyle::from(
                    (crate::draw::FONT, LABEL_SIZE * 0.7, FontStyle::Bold).into_font(),
                )
                .color(&INK)
                .pos(Pos::new(HPos::Left, VPos::Bottom));
                draw_text(area, &name, (at.0 + 7, at.1 - 5), &style)?;
            }
        }
        let first = &steps[0];
        let last = &steps[moves];
        draw_start(area, frame.at((first.x, first.y)), 8)?;
        draw_end(area, frame.at((last.x, last.y)), 5)
    };
    let footer = |area: &Area<'_>, frame: &Frame, top: i32| -> Result<()> {
        draw_run_timeline(area, frame, top, steps, plane, &colour_of)
    };
    let panel = Panel { label: String::new(), under: &nothing, over: &over };
    render(plane, title, "Option", &legend, &[panel], Some((TIMELINE, &footer)))
}

/// Draws a run's path: each move a piece of its own in its shaded option colour over a
/// dark casing, with a head every few moves.
fn draw_run_path(
    area: &Area<'_>,
    frame: &Frame,
    steps: &[PlaneStep],
    colour_of: &dyn Fn(Option<usize>) -> RGBColor,
) -> Result<()> {
    let moves = steps.len() - 1;
    let mut pieces: Vec<(Vec<(i32, i32)>, RGBColor)> = Vec::new();
    for i in 0..moves {
        let (a, b) =
            (frame.at((steps[i].x, steps[i].y)), frame.at((steps[i + 1].x, steps[i + 1].y)));
        if a == b {
            continue;
        }
        let t = if moves > 1 { i as f64 / (moves - 1) as f64 } else { 0.0 };
        pieces.push((vec![a, b], shade(colour_of(steps[i].option), t)));
    }
    for (points, _) in &pieces {
        area.draw(&PathElement::new(points.clone(), INK.mix(0.8).stroke_width(5)))
            .map_err(draw_err)?;
    }
    for (points, colour) in &pieces {
        area.draw(&PathElement::new(points.clone(), colour.stroke_width(3))).map_err(draw_err)?;
    }
    for (points, colour) in pieces.iter().skip(1).step_by(HEAD_EVERY) {
        draw_head(area, points[0], points[1], 9.0, *colour)?;
    }
    Ok(())
}

/// Draws a run's timeline under the map: slips and blocked moves, region entries, and the
/// option in force at each step shaded by time, with step numbers.
fn draw_run_timeline(
    area: &Area<'_>,
    frame: &Frame,
    top: i32,
    steps: &[PlaneStep],
    plane: &Plane,
    colour_of: &dyn Fn(Option<usize>) -> RGBColor,
) -> Result<()> {
    let moves = steps.len() - 1;
    let span = moves.max(1);
    let (left, right) = (frame.left, frame.right());
    let x_of = |i: usize| left + ((right - left) as f64 * i as f64 / span as f64).round() as i32;
    let label = text_style(LABEL_SIZE * 0.75, &INK, HPos::Right, VPos::Center);
    let (event_y, entry_y, band) = (top + 6, top + 22, (top + 33, top + 49));
    draw_text(area, "slips", (left - 6, event_y), &label)?;
    draw_text(area, "enters", (left - 6, entry_y), &label)?;
    draw_text(area, "option", (left - 6, (band.0 + band.1) / 2), &label)?;
    let piece = |i: usize| i * RAMP_PIECES / span;
    let mut start = 0;
    while start < span {
        let o = steps[start].option;
        let mut end = start + 1;
        while end < span && steps[end].option == o && piece(end) == piece(start) {
            end += 1;
        }
        let t = if span > 1 { start as f64 / (span - 1) as f64 } else { 0.0 };
        let rect = [(x_of(start), band.0), (x_of(end), band.1)];
        area.draw(&Rectangle::new(rect, shade(colour_of(o), t).filled())).map_err(draw_err)?;
        start = end;
    }
    area.draw(&Rectangle::new([(left, band.0), (right, band.1)], INK.stroke_width(1)))
        .map_err(draw_err)?;
    for (i, s) in steps[..moves].iter().enumerate() {
        let x = (x_of(i) + x_of(i + 1)) / 2;
        match s.outcome {
            Outcome::Slipped => {
                let arm = 3;
                for line in [
                    [(x - arm, event_y - arm), (x + arm, event_y + arm)],
                    [(x - arm, event_y + arm), (x + arm, event_y - arm)],
                ] {
                    area.draw(&PathElement::new(line.to_vec(), INK.stroke_width(2)))
                        .map_err(draw_err)?;
                }
            }
            Outcome::Blocked => {
                area.draw(&PathElement::new(
                    vec![(x, event_y - 5), (x, event_y + 5)],
                    AVOID.stroke_width(3),
                ))
                .map_err(draw_err)?;
            }
            Outcome::AsChosen => {}
        }
    }
    // Region names at their entries, each drawn where it does not overlap the last one.
    let small =
        TextStyle::from((crate::draw::FONT, LABEL_SIZE * 0.65, FontStyle::Bold).into_font())
            .color(&INK)
            .pos(Pos::new(HPos::Center, VPos::Center));
    let mut free_from = i32::MIN;
    for (i, s) in steps.iter().enumerate() {
        for &r in &s.entered {
            let x = x_of(i);
            let name = shorten(&clean_text(&plane.regions[r].name));
            let w = text_width(&name, LABEL_SIZE * 0.65);
            area.draw(&PathElement::new(vec![(x, entry_y + 6), (x, band.0)], INK.stroke_width(1)))
                .map_err(draw_err)?;
            if x - w / 2 >= free_from {
                draw_text(area, &name, (x, entry_y), &small)?;
                free_from = x + w / 2 + 3;
            }
        }
    }
    let every = tick_step(span, ((right - left) / 60).max(1) as usize);
    let below = text_style(LABEL_SIZE * 0.75, &INK, HPos::Center, VPos::Top);
    for i in (0..=span).step_by(every) {
        let x = x_of(i);
        area.draw(&PathElement::new(vec![(x, band.1), (x, band.1 + 4)], INK.stroke_width(1)))
            .map_err(draw_err)?;
        draw_text(area, &i.to_string(), (x, band.1 + 6), &below)?;
    }
    let after = text_style(LABEL_SIZE * 0.75, &INK, HPos::Left, VPos::Center);
    draw_text(area, "step", (right + 8, (band.0 + band.1) / 2), &after)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_inside() {
        let (t, d) = ticks([0.0, 14.0], 600, 70);
        assert_eq!(t, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0]);
        assert_eq!(d, 0);
        let (t, d) = ticks([-0.07, 0.07], 450, 40);
        assert!(t.iter().all(|v| (-0.07..=0.07).contains(v)), "{t:?}");
        assert_eq!(d, 2);
        assert_eq!(tick_label(-0.0, 2), "0.00");
        assert_eq!(tick_label(-1e-17, 2), "0.00");
        assert_eq!(tick_label(0.04, 2), "0.04");
        assert_eq!(tick_label(3e9, EXPONENT), "3.00e9");
        assert_eq!(ticks([0.0, 1e9], 600, 70).1, EXPONENT);
        // A huge extent falls back to its ends.
        let (t, _) = ticks([-1e300, 1e300], 600, 70);
        assert!(!t.is_empty() && t.len() <= 201);
    }

    #[test]
    fn clipping_keeps_a_polygon_inside_the_frame() {
        let frame =
            Frame { left: 0, top: 0, width: 100, height: 100, x: [0.0, 1.0], y: [0.0, 1.0] };
        let square = vec![(-50.0, -50.0), (50.0, -50.0), (50.0, 50.0), (-50.0, 50.0)];
        let clipped = frame.clip(square);
        assert!(
            clipped.iter().all(|&(x, y)| (0.0..=100.0).contains(&x) && (0.0..=100.0).contains(&y))
        );
        assert!(clipped.len() >= 4);
        assert!(frame.clip(vec![(200.0, 200.0), (300.0, 200.0), (300.0, 300.0)]).is_empty());
    }
}
