//! Drawing helpers shared by the pictures: text, markers and the legend.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::palette::{AVOID, INK, NOTE, REGION, START_CELL, TERMINATE, WALL, shade};
use crate::{PictureError, RegionKind};

/// The drawing area every picture draws on.
pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Font size of titles, in plotters units (the SVG gets `size / 1.24` pixels).
pub(crate) const TITLE_SIZE: f64 = 26.0;
/// Font size of labels and the legend, in plotters units.
pub(crate) const LABEL_SIZE: f64 = 18.0;
/// Font size of the note under a title, in plotters units.
pub(crate) const NOTE_SIZE: f64 = 17.0;
/// The height a title's note line adds, in pixels.
pub(crate) const NOTE_HEIGHT: i32 = 20;
/// Height of one legend row in pixels.
pub(crate) const LEGEND_ROW: i32 = 24;
/// Width reserved for a legend mark in pixels.
pub(crate) const LEGEND_MARK: i32 = 30;
/// Longest label shown in full; longer ones are cut to keep the legend narrow.
const MAX_LABEL_CHARS: usize = 40;
/// Longest title shown in full.
const MAX_TITLE_CHARS: usize = 150;
/// The font family of every text.
pub(crate) const FONT: &str = "sans-serif";

/// What a legend row shows before its label.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Mark {
    /// A filled square of the colour.
    Swatch(RGBColor),
    /// A square drawn like a region of the kind.
    Region(RegionKind),
    /// A right-pointing arrow like a flat-policy action.
    Arrow,
    /// A termination dot.
    Terminate,
    /// The start marker of a sample run.
    Start,
    /// The end marker of a sample run.
    End,
    /// A wall cell.
    Wall,
    /// A start cell's corner triangle.
    StartCell,
    /// A bar of the sample runs' shading over time, light to dark.
    Ramp,
    /// A slip: the dotted intended move ending in a cross.
    Slip,
    /// No mark: a note.
    Blank,
    /// An action without a direction on a plane's arrow field: a ring.
    Still,
    /// A plane's start area: a dashed square in the start colour.
    StartArea,
    /// A blocked move: the dotted intended move ending in a bar.
    Blocked,
    /// A region entered along a sample run: a small diamond.
    Entry,
}

/// One legend row.
#[derive(Debug, Clone)]
pub(crate) struct LegendEntry {
    pub(crate) mark: Mark,
    pub(crate) label: String,
}

impl LegendEntry {
    pub(crate) fn new(mark: Mark, label: impl AsRef<str>) -> Self {
        let label = label.as_ref();
        // An option without a name would leave a bare swatch; say so instead.
        let label = if label.trim().is_empty() { "(no name)" } else { label };
        Self { mark, label: shorten(&clean_text(label)) }
    }
}

/// Turns a plotters drawing error into a picture error.
pub(crate) fn draw_err<E: std::fmt::Display>(error: E) -> PictureError {
    PictureError::new(format!("cannot draw the picture: {error}"))
}

/// Replaces characters XML cannot hold (control characters) so the SVG always parses.
pub(crate) fn clean_text(text: &str) -> String {
    text.chars().map(|c| if c.is_control() { '\u{fffd}' } else { c }).collect()
}

/// Cuts long labels so one odd name cannot make the picture very wide.
pub(crate) fn shorten(text: &str) -> String {
    shorten_to(text, MAX_LABEL_CHARS)
}

/// The title as drawn: printable, and cut so that a huge title cannot make a huge picture.
pub(crate) fn title_text(title: &str) -> String {
    shorten_to(&clean_text(title), MAX_TITLE_CHARS)
}

/// Cuts `text` to at most `limit` characters, marking the cut with an ellipsis.
fn shorten_to(text: &str, limit: usize) -> String {
    if text.chars().count() <= limit {
        return text.to_owned();
    }
    let mut short: String = text.chars().take(limit - 1).collect();
    short.push('…');
    short
}

/// A generous estimate of the rendered width of `text` at plotters font `size`, in pixels.
pub(crate) fn text_width(text: &str, size: f64) -> i32 {
    (text.chars().count() as f64 * size / 1.24 * 0.62).ceil() as i32
}

/// A text style anchored at the given position.
pub(crate) fn text_style(
    size: f64,
    colour: &'static RGBColor,
    h: HPos,
    v: VPos,
) -> TextStyle<'static> {
    TextStyle::from((FONT, size).into_font()).color(colour).pos(Pos::new(h, v))
}

/// Draws `text` with its anchor at `at`.
pub(crate) fn draw_text(
    area: &Area<'_>,
    text: &str,
    at: (i32, i32),
    style: &TextStyle<'_>,
) -> crate::Result<()> {
    area.draw(&Text::new(clean_text(text), at, style.clone())).map_err(draw_err)
}

/// A title split into its first line and the note after the first newline (empty when
/// there is none), each printable and cut to a bounded length.
pub(crate) fn title_parts(title: &str) -> (String, String) {
    let (head, note) = title.split_once('\n').unwrap_or((title, ""));
    (title_text(head), title_text(&note.replace('\n', " ")))
}

/// The pixel width a title and its note need.
pub(crate) fn title_width((head, note): &(String, String)) -> i32 {
    text_width(head, TITLE_SIZE).max(text_width(note, NOTE_SIZE)) + 32
}

/// The pixel height a title and its note take at the top of a picture.
pub(crate) fn title_height((_, note): &(String, String)) -> i32 {
    if note.is_empty() { 0 } else { NOTE_HEIGHT }
}

/// Draws the title centred at the top of the picture, and its note under it.
pub(crate) fn draw_title(
    area: &Area<'_>,
    (head, note): &(String, String),
    centre_x: i32,
) -> crate::Result<()> {
    let style = TextStyle::from((FONT, TITLE_SIZE, FontStyle::Bold).into_font())
        .color(&INK)
        .pos(Pos::new(HPos::Center, VPos::Top));
    draw_text(area, head, (centre_x, 12), &style)?;
    if !note.is_empty() {
        let style = text_style(NOTE_SIZE, &NOTE, HPos::Center, VPos::Top);
        draw_text(area, note, (centre_x, 40), &style)?;
    }
    Ok(())
}

/// The pixel size of a legend with `entries`.
pub(crate) fn legend_size(heading: &str, entries: &[LegendEntry]) -> (i32, i32) {
    let widest = entries
        .iter()
        .map(|e| LEGEND_MARK + 8 + text_width(&e.label, LABEL_SIZE))
        .chain(std::iter::once(text_width(heading, LABEL_SIZE)))
        .max()
        .unwrap_or(0);
    (widest + 8, LEGEND_ROW * (entries.len() as i32 + 1))
}

/// Draws the legend with its top-left corner at `origin`.
pub(crate) fn draw_legend(
    area: &Area<'_>,
    origin: (i32, i32),
    heading: &str,
    entries: &[LegendEntry],
) -> crate::Result<()> {
    let (x, y) = origin;
    let bold = TextStyle::from((FONT, LABEL_SIZE, FontStyle::Bold).into_font())
        .color(&INK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    draw_text(area, heading, (x, y + LEGEND_ROW / 2), &bold)?;
    let plain = text_style(LABEL_SIZE, &INK, HPos::Left, VPos::Center);
    for (row, entry) in entries.iter().enumerate() {
        let cy = y + LEGEND_ROW * (row as i32 + 1) + LEGEND_ROW / 2;
        draw_mark(area, entry.mark, (x + LEGEND_MARK / 2, cy), 16)?;
        let label_x = if matches!(entry.mark, Mark::Blank) { x } else { x + LEGEND_MARK + 8 };
        draw_text(area, &entry.label, (label_x, cy), &plain)?;
    }
    Ok(())
}

/// Draws a legend mark of about `size` pixels centred at `centre`.
fn draw_mark(area: &Area<'_>, mark: Mark, centre: (i32, i32), size: i32) -> crate::Result<()> {
    let (cx, cy) = centre;
    let half = size / 2;
    let square = [(cx - half, cy - half), (cx + half, cy + half)];
    match mark {
        Mark::Swatch(colour) => {
            area.draw(&Rectangle::new(square, colour.filled())).map_err(draw_err)?;
            area.draw(&Rectangle::new(square, INK.stroke_width(1))).map_err(draw_err)
        }
        Mark::Region(kind) => {
            draw_region_fill(area, kind, square)?;
            draw_region_hatch(area, kind, square)?;
            draw_region_box(area, kind, square)
        }
        Mark::Ramp => {
            let steps = 8;
            let (left, right) = (cx - half - 4, cx + half + 4);
            for i in 0..steps {
                let l = left + (right - left) * i / steps;
                let r = left + (right - left) * (i + 1) / steps;
                let colour = shade(REGION, i as f64 / (steps - 1) as f64);
                area.draw(&Rectangle::new([(l, cy - 5), (r, cy + 5)], colour.filled()))
                    .map_err(draw_err)?;
            }
            area.draw(&Rectangle::new([(left, cy - 5), (right, cy + 5)], INK.stroke_width(1)))
                .map_err(draw_err)
        }
        Mark::Slip => {
            let from = (cx - half - 2, cy);
            let to = (cx + half - 4, cy);
            draw_slip(area, from, to, 5)
        }
        Mark::Arrow => draw_arrow(area, (cx as f64, cy as f64), (1.0, 0.0), size as f64 * 1.4),
        Mark::Terminate => draw_terminate(area, (cx, cy), size as f64 * 1.4),
        Mark::Start => draw_start(area, (cx, cy), half),
        Mark::Wall => area.draw(&Rectangle::new(square, WALL.filled())).map_err(draw_err),
        Mark::StartCell => {
            area.draw(&Rectangle::new(square, INK.stroke_width(1))).map_err(draw_err)?;
            draw_start_cell(area, square[0], size)
        }
        Mark::End => draw_end(area, (cx, cy), half),
        Mark::Blank => Ok(()),
        Mark::Still => draw_still(area, (cx, cy), size as f64 * 1.4),
        Mark::StartArea => {
            let corners = [square[0], (cx + half, cy - half), square[1], (cx - half, cy + half)];
            for i in 0..4 {
                draw_dashed(area, corners[i], corners[(i + 1) % 4], START_CELL.stroke_width(2))?;
            }
            Ok(())
        }
        Mark::Blocked => draw_blocked(area, (cx - half - 2, cy), (cx + half - 4, cy), 6),
        Mark::Entry => draw_entry(area, (cx, cy), 6),
    }
}

/// Marks a start cell whose top-left pixel is `corner` and side `cell`: a filled
/// triangle in its top-left corner.
pub(crate) fn draw_start_cell(area: &Area<'_>, corner: (i32, i32), cell: i32) -> crate::Result<()> {
    let (l, t) = corner;
    let leg = (cell * 2 / 5).max(3);
    let tri = vec![(l + 1, t + 1), (l + 1 + leg, t + 1), (l + 1, t + 1 + leg)];
    area.draw(&Polygon::new(tri, START_CELL.filled())).map_err(draw_err)
}

/// Opacity of region shading.
pub(crate) const REGION_ALPHA: f64 = 0.16;
/// Opacity of the shading of a region to avoid.
const AVOID_ALPHA: f64 = 0.10;

/// Shades the pixel rectangle `rect` as part of a region of `kind`: grey for a region to
/// reach, light red for one to avoid, nothing for other regions.
pub(crate) fn draw_region_fill(
    area: &Area<'_>,
    kind: RegionKind,
    rect: [(i32, i32); 2],
) -> crate::Result<()> {
    let colour = match kind {
        RegionKind::Reach => REGION.mix(REGION_ALPHA),
        RegionKind::Avoid => AVOID.mix(AVOID_ALPHA),
        RegionKind::Other => return Ok(()),
    };
    area.draw(&Rectangle::new(rect, colour.filled())).map_err(draw_err)
}

/// Hatches the pixel rectangle `rect` red when it is part of a region to avoid; drawn over
/// cell colours, so an obstacle shows on the options map too.
pub(crate) fn draw_region_hatch(
    area: &Area<'_>,
    kind: RegionKind,
    rect: [(i32, i32); 2],
) -> crate::Result<()> {
    if kind == RegionKind::Avoid { draw_hatching(area, rect, 9) } else { Ok(()) }
}

/// Red diagonal lines (`/`) every `spacing` pixels across `rect`, clipped to it; the lines of
/// neighbouring rectangles meet, since they lie on one lattice of the whole picture.
fn draw_hatching(area: &Area<'_>, rect: [(i32, i32); 2], spacing: i32) -> crate::Result<()> {
    let [(l, t), (r, b)] = rect;
    let style = AVOID.mix(0.55).stroke_width(1);
    // Lines x + y = c for c on the lattice, between the rectangle's corners.
    let first = (l + t).div_euclid(spacing) * spacing;
    let mut c = first;
    while c <= r + b {
        if c > l + t {
            // Enter at the left or bottom edge, leave at the top or right edge.
            let start = if c - l <= b { (l, c - l) } else { (c - b, b) };
            let end = if c - t <= r { (c - t, t) } else { (r, c - r) };
            area.draw(&PathElement::new(vec![start, end], style)).map_err(draw_err)?;
        }
        c += spacing;
    }
    Ok(())
}

/// Draws the outline of a lone square of a region of `kind` (for the legend).
fn draw_region_box(area: &Area<'_>, kind: RegionKind, rect: [(i32, i32); 2]) -> crate::Result<()> {
    let [(l, t), (r, b)] = rect;
    let corners = [(l, t), (r, t), (r, b), (l, b), (l, t)];
    match kind {
        RegionKind::Reach => {
            area.draw(&Rectangle::new(rect, REGION.stroke_width(2))).map_err(draw_err)
        }
        RegionKind::Avoid => {
            area.draw(&Rectangle::new(rect, AVOID.stroke_width(2))).map_err(draw_err)
        }
        RegionKind::Other => {
            for pair in corners.windows(2) {
                draw_dashed(area, pair[0], pair[1], REGION.stroke_width(2))?;
            }
            Ok(())
        }
    }
}

/// A dashed line from `from` to `to` (dashes of 5 pixels with gaps of 4).
pub(crate) fn draw_dashed(
    area: &Area<'_>,
    from: (i32, i32),
    to: (i32, i32),
    style: ShapeStyle,
) -> crate::Result<()> {
    area.draw(&DashedPathElement::new(vec![from, to], 5, 4, style)).map_err(draw_err)
}

/// Draws a slip from the pixel `from` (the cell the robot slipped in) towards `to` (where
/// the chosen action would have led): a dotted line ending in a cross of half-size `arm`,
/// dark on a white halo so it shows over any colour.
pub(crate) fn draw_slip(
    area: &Area<'_>,
    from: (i32, i32),
    to: (i32, i32),
    arm: i32,
) -> crate::Result<()> {
    let (x, y) = to;
    let cross =
        [[(x - arm, y - arm), (x + arm, y + arm)], [(x - arm, y + arm), (x + arm, y - arm)]];
    for line in &cross {
        area.draw(&PathElement::new(line.to_vec(), WHITE.stroke_width(5))).map_err(draw_err)?;
    }
    area.draw(&DashedPathElement::new(vec![from, to], 2, 3, INK.stroke_width(2)))
        .map_err(draw_err)?;
    for line in &cross {
        area.draw(&PathElement::new(line.to_vec(), INK.stroke_width(2))).map_err(draw_err)?;
    }
    Ok(())
}

/// Draws an arrow centred at `centre` pointing along the unit screen vector `dir`, sized for
/// a cell of `cell` pixels, as one filled polygon so each arrow is one SVG element.
pub(crate) fn draw_arrow(
    area: &Area<'_>,
    centre: (f64, f64),
    dir: (f64, f64),
    cell: f64,
) -> crate::Result<()> {
    let (cx, cy) = centre;
    let (dx, dy) = dir;
    // The perpendicular of the direction, to widen the shaft and head.
    let (px, py) = (-dy, dx);
    let shaft = (cell * 0.05).max(1.0);
    let head = cell * 0.2;
    let at = |along: f64, across: f64| {
        (
            (cx + dx * along + px * across).round() as i32,
            (cy + dy * along + py * across).round() as i32,
        )
    };
    let tail = -cell * 0.34;
    let neck = cell * 0.02;
    let tip = cell * 0.34;
    let points = vec![
        at(tail, shaft),
        at(neck, shaft),
        at(neck, head),
        at(tip, 0.0),
        at(neck, -head),
        at(neck, -shaft),
        at(tail, -shaft),
    ];
    area.draw(&Polygon::new(points, INK.filled())).map_err(draw_err)
}

/// Draws a termination marker (a red dot with a white ring) for a cell of `cell` pixels.
pub(crate) fn draw_terminate(area: &Area<'_>, centre: (i32, i32), cell: f64) -> crate::Result<()> {
    let radius = (cell * 0.22).round().max(3.0) as i32;
    area.draw(&Circle::new(centre, radius + 2, WHITE.filled())).map_err(draw_err)?;
    area.draw(&Circle::new(centre, radius, TERMINATE.filled())).map_err(draw_err)
}

/// Draws the start marker: a white disc with a thick dark ring.
pub(crate) fn draw_start(area: &Area<'_>, centre: (i32, i32), radius: i32) -> crate::Result<()> {
    area.draw(&Circle::new(centre, radius, WHITE.filled())).map_err(draw_err)?;
    area.draw(&Circle::new(centre, radius, INK.stroke_width(3))).map_err(draw_err)
}

/// Draws the end marker: a dark square with a white border.
pub(crate) fn draw_end(area: &Area<'_>, centre: (i32, i32), half: i32) -> crate::Result<()> {
    let (cx, cy) = centre;
    let outer = [(cx - half - 1, cy - half - 1), (cx + half + 1, cy + half + 1)];
    let inner = [(cx - half + 1, cy - half + 1), (cx + half - 1, cy + half - 1)];
    area.draw(&Rectangle::new(outer, WHITE.filled())).map_err(draw_err)?;
    area.draw(&Rectangle::new(inner, INK.filled())).map_err(draw_err)
}

/// Draws an action without a direction (such as `none` on `mountain-car`) at `centre`, for
/// arrows spaced `cell` pixels apart: a dark ring.
pub(crate) fn draw_still(area: &Area<'_>, centre: (i32, i32), cell: f64) -> crate::Result<()> {
    let radius = (cell * 0.16).round().max(2.0) as i32;
    area.draw(&Circle::new(centre, radius, INK.stroke_width(2))).map_err(draw_err)
}

/// Draws a blocked move from the pixel `from` (where the robot stayed) towards `to` (where
/// the chosen action would have led): a dotted line ending in a bar across it of half-size
/// `arm`, dark on a white halo.
pub(crate) fn draw_blocked(
    area: &Area<'_>,
    from: (i32, i32),
    to: (i32, i32),
    arm: i32,
) -> crate::Result<()> {
    let (dx, dy) = ((to.0 - from.0) as f64, (to.1 - from.1) as f64);
    let length = dx.hypot(dy);
    let (ux, uy) = if length > 0.0 { (dx / length, dy / length) } else { (1.0, 0.0) };
    let arm = arm as f64;
    let bar = vec![
        ((to.0 as f64 - uy * arm).round() as i32, (to.1 as f64 + ux * arm).round() as i32),
        ((to.0 as f64 + uy * arm).round() as i32, (to.1 as f64 - ux * arm).round() as i32),
    ];
    area.draw(&PathElement::new(bar.clone(), WHITE.stroke_width(6))).map_err(draw_err)?;
    area.draw(&DashedPathElement::new(vec![from, to], 2, 3, INK.stroke_width(2)))
        .map_err(draw_err)?;
    area.draw(&PathElement::new(bar, AVOID.stroke_width(3))).map_err(draw_err)
}

/// Draws the mark of a region entered along a run: a white diamond of half-size `half`
/// with a dark outline.
pub(crate) fn draw_entry(area: &Area<'_>, centre: (i32, i32), half: i32) -> crate::Result<()> {
    let (cx, cy) = centre;
    let points = vec![(cx, cy - half), (cx + half, cy), (cx, cy + half), (cx - half, cy)];
    area.draw(&Polygon::new(points.clone(), WHITE.filled())).map_err(draw_err)?;
    let mut outline = points;
    outline.push(outline[0]);
    area.draw(&PathElement::new(outline, INK.stroke_width(2))).map_err(draw_err)
}

/// The steps of a run divided into a ramp of this many pieces: steps under one option and
/// in one piece share a rectangle of the band.
pub(crate) const RAMP_PIECES: usize = 240;

/// A run's option band between `band.0` and `band.1`: steps `0..span` (step `i` from
/// `x_of(i)` to `x_of(i + 1)`), each in the colour of its option, `option(i)`, shaded by
/// its time in the run, and a frame around the band.
pub(crate) fn option_band<K: PartialEq>(
    area: &Area<'_>,
    span: usize,
    x_of: &dyn Fn(usize) -> i32,
    band: (i32, i32),
    option: impl Fn(usize) -> K,
    colour_of: impl Fn(K) -> RGBColor,
) -> Result<(), PictureError> {
    let piece = |i: usize| i * RAMP_PIECES / span;
    let mut start = 0;
    while start < span {
        let o = option(start);
        let mut end = start + 1;
        while end < span && option(end) == o && piece(end) == piece(start) {
            end += 1;
        }
        let t = if span > 1 { start as f64 / (span - 1) as f64 } else { 0.0 };
        let rect = [(x_of(start), band.0), (x_of(end), band.1)];
        area.draw(&Rectangle::new(rect, shade(colour_of(o), t).filled())).map_err(draw_err)?;
        start = end;
    }
    area.draw(&Rectangle::new([(x_of(0), band.0), (x_of(span), band.1)], INK.stroke_width(1)))
        .map_err(draw_err)?;
    Ok(())
}

/// The colour a region's name is written in: the avoid colour for a region to avoid.
pub(crate) fn tag_colour(kind: RegionKind) -> RGBColor {
    match kind {
        RegionKind::Avoid => AVOID,
        RegionKind::Reach | RegionKind::Other => INK,
    }
}

/// Places a name box `h` pixels high beside a region whose edges are at `t` and `bottom`:
/// above it, or below it when the box would cross `top`, with a leader at `x` from the
/// region's edge. Returns the box's top.
pub(crate) fn tag_leader(
    area: &Area<'_>,
    x: i32,
    (t, bottom): (i32, i32),
    h: i32,
    top: i32,
    colour: RGBColor,
) -> Result<i32, PictureError> {
    let (box_top, from, to) =
        if t - 4 - h >= top { (t - 4 - h, t - 4, t) } else { (bottom + 4, bottom + 4, bottom) };
    area.draw(&PathElement::new(vec![(x, from), (x, to)], colour.stroke_width(1)))
        .map_err(draw_err)?;
    Ok(box_top)
}

/// Writes `name` in bold, `size` pixels, in a white box `w` x `h` centred at `centre_x`
/// with its top at `box_top`, framed in `colour`.
pub(crate) fn name_box(
    area: &Area<'_>,
    name: String,
    (centre_x, box_top): (i32, i32),
    (w, h): (i32, i32),
    size: f64,
    colour: RGBColor,
) -> Result<(), PictureError> {
    let rect = [(centre_x - w / 2, box_top), (centre_x + w / 2, box_top + h)];
    area.draw(&Rectangle::new(rect, WHITE.mix(0.85).filled())).map_err(draw_err)?;
    area.draw(&Rectangle::new(rect, colour.stroke_width(1))).map_err(draw_err)?;
    let style = TextStyle::from((FONT, size, FontStyle::Bold).into_font())
        .color(&colour)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw(&Text::new(name, (centre_x, box_top + h / 2), style)).map_err(draw_err)?;
    Ok(())
}
