//! Drawing helpers shared by the pictures: text, markers and the legend.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::PictureError;
use crate::palette::{INK, REGION, START_CELL, TERMINATE, WALL};

/// The drawing area every picture draws on.
pub(crate) type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;

/// Font size of titles, in plotters units (the SVG gets `size / 1.24` pixels).
pub(crate) const TITLE_SIZE: f64 = 26.0;
/// Font size of labels and the legend, in plotters units.
pub(crate) const LABEL_SIZE: f64 = 18.0;
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
    /// A shaded, outlined square like a region.
    Region,
    /// A right-pointing arrow like a flat-policy action.
    Arrow,
    /// A termination dot.
    Terminate,
    /// A short cased line of the colour, like a sample-run segment.
    Line(RGBColor),
    /// The start marker of a sample run.
    Start,
    /// The end marker of a sample run.
    End,
    /// A wall cell.
    Wall,
    /// A start cell's corner triangle.
    StartCell,
    /// No mark: a note.
    Blank,
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

/// Draws the title centred at the top of the picture.
pub(crate) fn draw_title(area: &Area<'_>, title: &str, centre_x: i32) -> crate::Result<()> {
    let style = TextStyle::from((FONT, TITLE_SIZE, FontStyle::Bold).into_font())
        .color(&INK)
        .pos(Pos::new(HPos::Center, VPos::Top));
    draw_text(area, title, (centre_x, 12), &style)
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
        Mark::Region => {
            area.draw(&Rectangle::new(square, REGION.mix(REGION_ALPHA).filled()))
                .map_err(draw_err)?;
            area.draw(&Rectangle::new(square, REGION.stroke_width(2))).map_err(draw_err)
        }
        Mark::Arrow => draw_arrow(area, (cx as f64, cy as f64), (1.0, 0.0), size as f64 * 1.4),
        Mark::Terminate => draw_terminate(area, (cx, cy), size as f64 * 1.4),
        Mark::Line(colour) => {
            let ends = vec![(cx - half - 4, cy), (cx + half + 4, cy)];
            draw_cased_line(area, ends, colour, 4)
        }
        Mark::Start => draw_start(area, (cx, cy), half),
        Mark::Wall => area.draw(&Rectangle::new(square, WALL.filled())).map_err(draw_err),
        Mark::StartCell => {
            area.draw(&Rectangle::new(square, INK.stroke_width(1))).map_err(draw_err)?;
            draw_start_cell(area, square[0], size)
        }
        Mark::End => draw_end(area, (cx, cy), half),
        Mark::Blank => Ok(()),
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

/// Draws a polyline in `colour` over a dark casing so light colours stay visible on white.
pub(crate) fn draw_cased_line(
    area: &Area<'_>,
    points: Vec<(i32, i32)>,
    colour: RGBColor,
    width: u32,
) -> crate::Result<()> {
    area.draw(&PathElement::new(points.clone(), INK.mix(0.9).stroke_width(width + 2)))
        .map_err(draw_err)?;
    area.draw(&PathElement::new(points, colour.stroke_width(width))).map_err(draw_err)
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
