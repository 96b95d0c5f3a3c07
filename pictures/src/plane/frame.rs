//! The frame every plane picture is drawn in: its layout in pixels, axes and ticks, the
//! legend, obstacles, region outlines and names, and one or more maps side by side.

use std::collections::HashSet;

use plotters::prelude::*;
use plotters::style::FontTransform;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::types::*;
use crate::draw::{
    Area, LABEL_SIZE, LegendEntry, Mark, clean_text, draw_dashed, draw_err, draw_legend,
    draw_region_fill, draw_region_hatch, draw_text, draw_title, legend_size, name_box, shorten,
    tag_colour, tag_leader, text_style, text_width, title_height, title_parts, title_width,
};
use crate::grid::{cell_boxes, round_joins};
use crate::label::{CellBox, best_box};
use crate::palette::{AVOID, GRID_LINE, INK, REGION, START_CELL, WALL};
use crate::{RegionKind, Result};

/// Where a plane is drawn on the canvas, in pixels, and its extent.
#[derive(Debug, Clone, Copy)]
pub(super) struct Frame {
    pub(super) left: i32,
    pub(super) top: i32,
    pub(super) width: i32,
    pub(super) height: i32,
    pub(super) x: [f64; 2],
    pub(super) y: [f64; 2],
}

/// A pixel coordinate from a float, kept in a sane range (a point may lie off the frame).
pub(super) fn px(v: f64) -> i32 {
    if v.is_finite() { v.clamp(-100_000.0, 100_000.0).round() as i32 } else { 0 }
}

impl Frame {
    /// The pixel of the point `(x, y)`, as floats.
    pub(super) fn at_f(&self, (x, y): (f64, f64)) -> (f64, f64) {
        let [x0, x1] = self.x;
        let [y0, y1] = self.y;
        (
            self.left as f64 + (x - x0) / (x1 - x0) * self.width as f64,
            self.top as f64 + (y1 - y) / (y1 - y0) * self.height as f64,
        )
    }

    /// The pixel of the point `(x, y)`.
    pub(super) fn at(&self, p: (f64, f64)) -> (i32, i32) {
        let (a, b) = self.at_f(p);
        (px(a), px(b))
    }

    pub(super) fn right(&self) -> i32 {
        self.left + self.width
    }

    pub(super) fn bottom(&self) -> i32 {
        self.top + self.height
    }

    /// The pixel column of the left edge of raster column `i` of `n`.
    pub(super) fn column_px(&self, i: i64, n: usize) -> i32 {
        self.left + (i as f64 * self.width as f64 / n as f64).round() as i32
    }

    /// The pixel row of the bottom edge of raster row `j` of `n`.
    pub(super) fn row_px(&self, j: i64, n: usize) -> i32 {
        self.bottom() - (j as f64 * self.height as f64 / n as f64).round() as i32
    }

    /// The pixel rectangle of a box of raster cells.
    pub(super) fn box_rect(&self, b: CellBox, columns: usize, rows: usize) -> [(i32, i32); 2] {
        [
            (self.column_px(b.x0, columns), self.row_px(b.y1 + 1, rows)),
            (self.column_px(b.x1 + 1, columns), self.row_px(b.y0, rows)),
        ]
    }

    /// Clips a pixel polygon to the frame (Sutherland-Hodgman; the frame is convex).
    pub(super) fn clip(&self, polygon: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
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
pub(super) type Layer<'f> = &'f dyn Fn(&Area<'_>, &Frame) -> Result<()>;

/// A drawing step a picture builds for each of its maps.
pub(super) type OwnedLayer = Box<dyn Fn(&Area<'_>, &Frame) -> Result<()>>;

/// A drawing step under the map's axes, given the frame and the top of its strip.
pub(super) type Footer<'f> = &'f dyn Fn(&Area<'_>, &Frame, i32) -> Result<()>;

/// One map of a picture: a label over it and its layers.
pub(super) struct Panel<'f> {
    pub(super) label: String,
    /// Drawn under the region outlines and obstacles (colours).
    pub(super) under: Layer<'f>,
    /// Drawn over everything else in the frame (arrows, paths).
    pub(super) over: Layer<'f>,
}

pub(super) fn nothing(_: &Area<'_>, _: &Frame) -> Result<()> {
    Ok(())
}

pub(super) const TOP: i32 = 56;
pub(super) const LEFT_MARGIN: i32 = 10;
pub(super) const BOTTOM: i32 = 52;
pub(super) const GAP: i32 = 28;
pub(super) const RIGHT: i32 = 16;
pub(super) const PANEL_GAP: i32 = 24;
pub(super) const PANEL_LABEL: i32 = 26;
/// The longer side of a map drawn alone, in pixels.
pub(super) const FRAME_PIXELS: f64 = 600.0;
/// The longer side of each of several maps, in pixels.
pub(super) const SMALL_FRAME_PIXELS: f64 = 340.0;
/// The largest pixel size of a region's name in its box.
pub(super) const TAG_PX: f64 = 13.0;
/// Tick labels at least this many pixels apart along x, and along y.
pub(super) const X_TICK_GAP: i32 = 70;
pub(super) const Y_TICK_GAP: i32 = 40;
/// A sample run shows its direction on every this many moves.
pub(super) const HEAD_EVERY: usize = 4;
/// The height of a sample run's timeline, in pixels.
pub(super) const TIMELINE: i32 = 76;

/// The pixel size of each map of `plane` when `panels` are drawn.
pub(super) fn frame_size(plane: &Plane, panels: usize) -> (i32, i32) {
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
pub(super) const EXPONENT: usize = usize::MAX;

/// Round tick values over `[lo, hi]` at least `gap` pixels apart on `pixels`, and the
/// decimals to write them with ([`EXPONENT`] for exponent form).
pub(super) fn ticks([lo, hi]: [f64; 2], pixels: i32, gap: i32) -> (Vec<f64>, usize) {
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
pub(super) fn tick_label(v: f64, decimals: usize) -> String {
    let text = if decimals == EXPONENT { format!("{v:.2e}") } else { format!("{v:.decimals$}") };
    match text.strip_prefix('-') {
        Some(rest) if rest.chars().all(|c| c == '0' || c == '.') => rest.to_owned(),
        _ => text,
    }
}

/// The legend rows for the kinds of regions, the obstacles and the start area of a plane.
pub(super) fn frame_legend(plane: &Plane) -> Vec<LegendEntry> {
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
pub(super) fn cells_where<T>(raster: &Raster<T>, keep: impl Fn(&T) -> bool) -> Vec<(i64, i64)> {
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
pub(super) fn render(
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
pub(super) fn draw_map(
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
pub(super) fn draw_obstacle(area: &Area<'_>, frame: &Frame, shape: &Shape) -> Result<()> {
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
pub(super) fn draw_outline(area: &Area<'_>, frame: &Frame, region: &PlaneRegion) -> Result<()> {
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
pub(super) fn draw_region_name(
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
    let colour = tag_colour(region.kind);
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
        (keep_inside(x), tag_leader(area, x, (t, bottom), h, frame.top, colour)?)
    };
    name_box(area, name, (centre_x, box_top), (w, h), size, colour)
}
