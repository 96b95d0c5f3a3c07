//! Grid pictures: flat policies and the options policy, and the layout every grid picture
//! shares (regions, walls, start cells, axes and the legend).

use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::draw::{
    Area, LABEL_SIZE, LegendEntry, Mark, clean_text, draw_arrow, draw_dashed, draw_err,
    draw_legend, draw_region_fill, draw_region_hatch, draw_start_cell, draw_terminate, draw_text,
    draw_title, legend_size, name_box, shorten, tag_colour, tag_leader, text_style, text_width,
    title_height, title_parts, title_width,
};
use crate::label::{CellBox, best_box};
use crate::palette::{AVOID, GRID_LINE, INK, REGION, WALL, option_color};
use crate::{Action, Cell, Grid, MAX_GRID_SIDE, PictureError, RegionKind, Result};

/// Pixel geometry of the grid on the canvas.
pub(crate) struct Canvas {
    /// Side of one cell in pixels.
    pub(crate) cell: i32,
    /// Left edge of the grid.
    pub(crate) left: i32,
    /// Top edge of the grid.
    pub(crate) top: i32,
    /// Columns.
    pub(crate) width: i64,
    /// Rows.
    pub(crate) height: i64,
}

/// A drawing step of a picture, given the canvas.
pub(crate) type Layer<'f> = &'f dyn Fn(&Area<'_>, &Canvas) -> Result<()>;

/// A drawing step under the grid's axes, given the canvas and the top of its strip.
pub(crate) type Footer<'f> = &'f dyn Fn(&Area<'_>, &Canvas, i32) -> Result<()>;

/// What a picture draws on top of the shaded regions.
pub(crate) struct Layers<'f> {
    /// Drawn under the cell boundaries and region outlines (cell colours).
    pub(crate) under: Layer<'f>,
    /// Drawn over everything else in the grid (arrows, markers, paths).
    pub(crate) over: Layer<'f>,
    /// A strip under the grid's axes of this many pixels, and what is drawn there: its
    /// top edge is the third argument.
    pub(crate) footer: Option<(i32, Footer<'f>)>,
    /// Region names as tabs on the regions' top edges (for pictures with a mark in every
    /// cell) instead of inside them.
    pub(crate) edge_labels: bool,
}

impl<'f> Layers<'f> {
    /// Only a layer under the boundaries.
    fn under(under: Layer<'f>) -> Layers<'f> {
        Layers { under, over: &|_, _| Ok(()), footer: None, edge_labels: false }
    }

    /// Only a layer over everything.
    pub(crate) fn over(over: Layer<'f>) -> Layers<'f> {
        Layers { under: &|_, _| Ok(()), over, footer: None, edge_labels: false }
    }
}

const TOP: i32 = 56;
pub(crate) const LEFT: i32 = 52;
const BOTTOM: i32 = 48;
const GAP: i32 = 28;
const RIGHT: i32 = 16;
/// The grid's longer side aims at about this many pixels.
const GRID_PIXELS: i32 = 600;
/// Cells smaller than this many pixels get no boundary lines: they would grey the map.
const MIN_LINED_CELL: i32 = 10;
/// Region names smaller than this many pixels inside the region go beside it instead.
const MIN_INSIDE_LABEL_PX: f64 = 10.0;
/// Region names smaller than this are written over the arrows and paths, in a box; larger
/// ones faint under them.
const MIN_FAINT_LABEL_PX: f64 = 26.0;
/// The largest pixel size of a name in a box.
const TAG_PX: f64 = 13.0;

impl Canvas {
    /// The top-left pixel of cell `(x, y)`; rows grow upwards, pixels downwards.
    pub(crate) fn corner(&self, x: i64, y: i64) -> (i32, i32) {
        (self.left + x as i32 * self.cell, self.top + (self.height - 1 - y) as i32 * self.cell)
    }

    /// The centre pixel of cell `(x, y)`.
    pub(crate) fn centre(&self, x: i64, y: i64) -> (i32, i32) {
        let (left, top) = self.corner(x, y);
        (left + self.cell / 2, top + self.cell / 2)
    }

    /// The pixel rectangle of cell `(x, y)`.
    pub(crate) fn rect(&self, x: i64, y: i64) -> [(i32, i32); 2] {
        let (left, top) = self.corner(x, y);
        [(left, top), (left + self.cell, top + self.cell)]
    }

    /// The pixel rectangle of a box of cells.
    fn box_rect(&self, b: CellBox) -> [(i32, i32); 2] {
        let [(l, t), _] = self.rect(b.x0, b.y1);
        let [_, (r, bottom)] = self.rect(b.x1, b.y0);
        [(l, t), (r, bottom)]
    }

    /// The right edge of the grid in pixels.
    pub(crate) fn right(&self) -> i32 {
        self.left + self.cell * self.width as i32
    }

    /// The bottom edge of the grid in pixels.
    pub(crate) fn bottom(&self) -> i32 {
        self.top + self.cell * self.height as i32
    }
}

/// Draws a flat policy: an arrow for the action in each given cell and a dot on each
/// termination cell, over the shaded regions (named in tabs on their top edges), with a
/// legend.
///
/// Cells without an action are left empty. Errors for an empty or too large grid, a cell
/// outside the grid, or two actions for one cell.
pub fn flat_policy(
    grid: &Grid,
    title: &str,
    arrows: &[Cell],
    terminate: &[(i64, i64)],
) -> Result<String> {
    check_grid(grid)?;
    let mut seen = HashSet::new();
    for cell in arrows {
        check_cell(grid, (cell.x, cell.y), "arrow")?;
        if !seen.insert((cell.x, cell.y)) {
            return Err(PictureError::new(format!(
                "cell ({}, {}) has more than one action",
                cell.x, cell.y
            )));
        }
    }
    for &cell in terminate {
        check_cell(grid, cell, "termination")?;
    }
    let mut legend = region_legend(grid);
    legend.push(LegendEntry::new(Mark::Arrow, "action taken"));
    legend.push(LegendEntry::new(Mark::Terminate, "terminates"));
    let over = |area: &Area<'_>, canvas: &Canvas| -> Result<()> {
        for cell in arrows {
            let (cx, cy) = canvas.centre(cell.x, cell.y);
            let dir = match cell.action {
                Action::Up => (0.0, -1.0),
                Action::Down => (0.0, 1.0),
                Action::Left => (-1.0, 0.0),
                Action::Right => (1.0, 0.0),
            };
            draw_arrow(area, (cx as f64, cy as f64), dir, canvas.cell as f64)?;
        }
        for &(x, y) in terminate.iter().collect::<BTreeSet<_>>() {
            draw_terminate(area, canvas.centre(x, y), canvas.cell as f64)?;
        }
        Ok(())
    };
    // Arrows fill every cell: names go on the regions' edges, where they hide the least.
    render(grid, title, "Legend", &legend, Layers { edge_labels: true, ..Layers::over(&over) })
}

/// Draws the options policy: each cell filled with the colour of the option chosen there,
/// with a legend of the options in `legend_order` followed by any other chosen option in
/// order of first appearance. Cells without a choice are left blank.
///
/// The colour of an option depends only on its position in that order, so pictures drawn
/// with the same `legend_order` agree. Errors for an empty or too large grid, a cell outside
/// the grid, or two options for one cell.
pub fn options_policy(
    grid: &Grid,
    title: &str,
    choices: &[((i64, i64), String)],
    legend_order: &[String],
) -> Result<String> {
    check_grid(grid)?;
    let mut seen = HashSet::new();
    for (cell, _) in choices {
        check_cell(grid, *cell, "choice")?;
        if !seen.insert(*cell) {
            return Err(PictureError::new(format!(
                "cell ({}, {}) has more than one option",
                cell.0, cell.1
            )));
        }
    }
    let order = option_order(legend_order, choices.iter().map(|(_, name)| name.as_str()));
    let mut legend: Vec<LegendEntry> = order
        .iter()
        .enumerate()
        .map(|(i, name)| LegendEntry::new(Mark::Swatch(option_color(i)), name))
        .collect();
    let walls: HashSet<(i64, i64)> = grid.walls.iter().copied().collect();
    let free = grid.width * grid.height - walls.len();
    if seen.iter().filter(|c| !walls.contains(c)).count() < free {
        legend.push(LegendEntry::new(Mark::Swatch(WHITE), "no choice"));
    }
    legend.extend(region_legend(grid));
    let index: HashMap<&str, usize> =
        order.iter().enumerate().map(|(i, name)| (name.as_str(), i)).collect();
    // Cells by option, drawn as a few rectangles each.
    let mut by_option: BTreeMap<usize, Vec<(i64, i64)>> = BTreeMap::new();
    for (cell, name) in choices {
        by_option
            .entry(index.get(name.as_str()).copied().unwrap_or(usize::MAX))
            .or_default()
            .push(*cell);
    }
    let under = |area: &Area<'_>, canvas: &Canvas| -> Result<()> {
        for (&i, cells) in &by_option {
            let colour = if i == usize::MAX { INK } else { option_color(i) };
            for b in cell_boxes(cells.iter().copied()) {
                area.draw(&Rectangle::new(canvas.box_rect(b), colour.filled()))
                    .map_err(draw_err)?;
            }
        }
        Ok(())
    };
    render(grid, title, "Option", &legend, Layers::under(&under))
}

/// One memory slice of an options policy with memory: a label (such as `b = [0, 4, 8]`)
/// and the option chosen in each cell for that memory value.
pub type Slice = (String, Vec<((i64, i64), String)>);

/// Draws an options policy with memory as one [`options_policy`] map per slice, titled
/// `"{title}, {label}"` (the label joins the title's first line, before any note). The colours agree across the maps: every map uses `legend_order`
/// followed by the options the slices choose, in order of first appearance over all
/// slices.
///
/// Errors for no slice, or whatever [`options_policy`] rejects in a slice (the message
/// names the slice).
pub fn options_policy_slices(
    grid: &Grid,
    title: &str,
    slices: &[Slice],
    legend_order: &[String],
) -> Result<Vec<String>> {
    if slices.is_empty() {
        return Err(PictureError::new("no memory slice to draw; give at least one"));
    }
    let order = option_order(
        legend_order,
        slices.iter().flat_map(|(_, choices)| choices.iter().map(|(_, name)| name.as_str())),
    );
    slices
        .iter()
        .map(|(label, choices)| {
            let title = match (label.is_empty(), title.split_once('\n')) {
                (true, _) => title.to_owned(),
                (false, Some((head, note))) => format!("{head}, {label}\n{note}"),
                (false, None) => format!("{title}, {label}"),
            };
            options_policy(grid, &title, choices, &order)
                .map_err(|e| PictureError::new(format!("memory slice `{label}`: {}", e.message())))
        })
        .collect()
}

/// Checks the grid's size and that every region cell lies inside it.
pub(crate) fn check_grid(grid: &Grid) -> Result<()> {
    if grid.width == 0 || grid.height == 0 {
        return Err(PictureError::new(format!(
            "the grid is empty ({} x {} cells)",
            grid.width, grid.height
        )));
    }
    if grid.width > MAX_GRID_SIDE || grid.height > MAX_GRID_SIDE {
        return Err(PictureError::new(format!(
            "the grid is too large to draw ({} x {} cells, at most {MAX_GRID_SIDE} a side)",
            grid.width, grid.height
        )));
    }
    for region in &grid.regions {
        for &cell in &region.cells {
            check_cell(grid, cell, &format!("region `{}`", clean_text(&region.name)))?;
        }
    }
    for &cell in &grid.walls {
        check_cell(grid, cell, "wall")?;
    }
    for &cell in &grid.starts {
        check_cell(grid, cell, "start")?;
    }
    Ok(())
}

/// Checks that `cell` lies inside the grid; `what` names the cell in the error.
pub(crate) fn check_cell(grid: &Grid, (x, y): (i64, i64), what: &str) -> Result<()> {
    let inside = |v: i64, side: usize| v >= 0 && (v as u64) < side as u64;
    if inside(x, grid.width) && inside(y, grid.height) {
        Ok(())
    } else {
        Err(PictureError::new(format!(
            "{what} cell ({x}, {y}) is outside the {} x {} grid",
            grid.width, grid.height
        )))
    }
}

/// The options in legend order: `preferred` first (without repeats), then the others in
/// order of first appearance.
pub(crate) fn option_order<'a>(
    preferred: &'a [String],
    used: impl Iterator<Item = &'a str>,
) -> Vec<String> {
    let mut order: Vec<String> = Vec::new();
    let mut seen = HashSet::new();
    for name in preferred.iter().map(String::as_str).chain(used) {
        if seen.insert(name) {
            order.push(name.to_owned());
        }
    }
    order
}

/// The legend rows for the kinds of regions, the walls and the start cells the grid has.
pub(crate) fn region_legend(grid: &Grid) -> Vec<LegendEntry> {
    let mut rows = Vec::new();
    for (kind, label) in [
        (RegionKind::Reach, "region to reach"),
        (RegionKind::Avoid, "region to avoid"),
        (RegionKind::Other, "other region"),
    ] {
        if grid.regions.iter().any(|r| r.kind == kind && !r.cells.is_empty()) {
            rows.push(LegendEntry::new(Mark::Region(kind), label));
        }
    }
    if !grid.walls.is_empty() {
        rows.push(LegendEntry::new(Mark::Wall, "wall"));
    }
    if !grid.starts.is_empty() {
        rows.push(LegendEntry::new(Mark::StartCell, "start cell"));
    }
    rows
}

/// Rectangles that cover the cells exactly, so that a large area is a few rectangles
/// instead of one per cell: each row's runs of consecutive columns, stacked where the same
/// run continues on the next row.
pub(crate) fn cell_boxes(cells: impl IntoIterator<Item = (i64, i64)>) -> Vec<CellBox> {
    let sorted: BTreeSet<(i64, i64)> = cells.into_iter().map(|(x, y)| (y, x)).collect();
    let mut runs: Vec<(i64, i64, i64)> = Vec::new();
    for (y, x) in sorted {
        match runs.last_mut() {
            Some((ry, _, x1)) if *ry == y && *x1 + 1 == x => *x1 = x,
            _ => runs.push((y, x, x)),
        }
    }
    let mut boxes: Vec<CellBox> = Vec::new();
    // The box each run of columns is growing, by its columns.
    let mut open: HashMap<(i64, i64), usize> = HashMap::new();
    for (y, x0, x1) in runs {
        match open.get(&(x0, x1)) {
            Some(&i) if boxes[i].y1 + 1 == y => boxes[i].y1 = y,
            _ => {
                open.insert((x0, x1), boxes.len());
                boxes.push(CellBox { x0, x1, y0: y, y1: y });
            }
        }
    }
    boxes
}

/// Lays out and draws a grid picture: title, shaded regions, the layers, cell boundaries,
/// region outlines and labels, axis labels, the legend on the right and the footer.
pub(crate) fn render(
    grid: &Grid,
    title: &str,
    heading: &str,
    legend: &[LegendEntry],
    layers: Layers<'_>,
) -> Result<String> {
    let side = grid.width.max(grid.height) as i32;
    let cell = (GRID_PIXELS / side).clamp(8, 48);
    let title = title_parts(title);
    let top = TOP + title_height(&title);
    let canvas =
        Canvas { cell, left: LEFT, top, width: grid.width as i64, height: grid.height as i64 };
    let grid_w = cell * grid.width as i32;
    let grid_h = cell * grid.height as i32;
    let (legend_w, legend_h) = legend_size(heading, legend);
    let footer_h = layers.footer.map_or(0, |(h, _)| h);
    let width = (LEFT + grid_w + GAP + legend_w + RIGHT).max(title_width(&title));
    let height = (top + grid_h + BOTTOM + footer_h).max(top + legend_h + 16);
    let walls: HashSet<(i64, i64)> = grid.walls.iter().copied().collect();
    let mut svg = String::new();
    {
        let area =
            SVGBackend::with_string(&mut svg, (width as u32, height as u32)).into_drawing_area();
        area.fill(&WHITE).map_err(draw_err)?;
        draw_title(&area, &title, width / 2)?;
        for region in &grid.regions {
            for b in cell_boxes(region.cells.iter().copied()) {
                draw_region_fill(&area, region.kind, canvas.box_rect(b))?;
            }
        }
        (layers.under)(&area, &canvas)?;
        for region in grid.regions.iter().filter(|r| r.kind == RegionKind::Avoid) {
            for b in cell_boxes(region.cells.iter().copied()) {
                draw_region_hatch(&area, region.kind, canvas.box_rect(b))?;
            }
        }
        for b in cell_boxes(walls.iter().copied()) {
            area.draw(&Rectangle::new(canvas.box_rect(b), WALL.filled())).map_err(draw_err)?;
        }
        draw_cell_lines(&area, &canvas)?;
        for &(x, y) in &grid.starts {
            draw_start_cell(&area, canvas.corner(x, y), canvas.cell)?;
        }
        let mut tags = Vec::new();
        for region in &grid.regions {
            draw_outline(&area, &canvas, region.kind, &region.cells)?;
            if layers.edge_labels {
                tags.extend(edge_tag(&canvas, region.kind, &region.name, &region.cells));
            } else {
                tags.extend(draw_label(&area, &canvas, region.kind, &region.name, &region.cells)?);
            }
        }
        (layers.over)(&area, &canvas)?;
        for tag in &tags {
            draw_tag(&area, &canvas, tag)?;
        }
        draw_axes(&area, &canvas)?;
        draw_legend(&area, (LEFT + grid_w + GAP, top - 4), heading, legend)?;
        if let Some((_, footer)) = layers.footer {
            footer(&area, &canvas, canvas.bottom() + BOTTOM)?;
        }
        area.present().map_err(draw_err)?;
    }
    Ok(round_joins(svg))
}

/// Gives every line of the picture round ends and corners, so that the pieces of a path
/// join without notches (plotters writes neither attribute; they are inherited).
pub(crate) fn round_joins(svg: String) -> String {
    let Some(open_end) = svg.find('>') else { return svg };
    let Some(close) = svg.rfind("</svg>") else { return svg };
    let mut out = String::with_capacity(svg.len() + 80);
    out.push_str(&svg[..=open_end]);
    out.push_str("\n<g stroke-linecap=\"round\" stroke-linejoin=\"round\">");
    out.push_str(&svg[open_end + 1..close]);
    out.push_str("</g>\n");
    out.push_str(&svg[close..]);
    out
}

/// Draws the cell boundaries (for cells large enough) and the grid's border.
fn draw_cell_lines(area: &Area<'_>, canvas: &Canvas) -> Result<()> {
    let (right, bottom) = (canvas.right(), canvas.bottom());
    if canvas.cell >= MIN_LINED_CELL {
        let thin = GRID_LINE.stroke_width(1);
        for i in 1..canvas.width as i32 {
            let x = canvas.left + i * canvas.cell;
            area.draw(&PathElement::new(vec![(x, canvas.top), (x, bottom)], thin))
                .map_err(draw_err)?;
        }
        for j in 1..canvas.height as i32 {
            let y = canvas.top + j * canvas.cell;
            area.draw(&PathElement::new(vec![(canvas.left, y), (right, y)], thin))
                .map_err(draw_err)?;
        }
    }
    area.draw(&Rectangle::new([(canvas.left, canvas.top), (right, bottom)], INK.stroke_width(2)))
        .map_err(draw_err)
}

/// Draws a region's outline: the cell edges it shares with no other of its cells, joined
/// into straight runs; solid grey for a region to reach, solid red for one to avoid, dashed
/// grey for others.
fn draw_outline(
    area: &Area<'_>,
    canvas: &Canvas,
    kind: RegionKind,
    cells: &[(i64, i64)],
) -> Result<()> {
    let set: HashSet<(i64, i64)> = cells.iter().copied().collect();
    // Horizontal edges keyed by the grid line (0 = bottom of row 0) and the cells along it,
    // vertical ones likewise by column line.
    let mut horizontal: BTreeMap<i64, BTreeSet<i64>> = BTreeMap::new();
    let mut vertical: BTreeMap<i64, BTreeSet<i64>> = BTreeMap::new();
    for &(x, y) in &set {
        if !set.contains(&(x, y + 1)) {
            horizontal.entry(y + 1).or_default().insert(x);
        }
        if !set.contains(&(x, y - 1)) {
            horizontal.entry(y).or_default().insert(x);
        }
        if !set.contains(&(x - 1, y)) {
            vertical.entry(x).or_default().insert(y);
        }
        if !set.contains(&(x + 1, y)) {
            vertical.entry(x + 1).or_default().insert(y);
        }
    }
    let style = match kind {
        RegionKind::Avoid => AVOID.stroke_width(2),
        RegionKind::Reach | RegionKind::Other => REGION.stroke_width(2),
    };
    let line = |from: (i32, i32), to: (i32, i32)| -> Result<()> {
        match kind {
            RegionKind::Other => draw_dashed(area, from, to, style),
            _ => area.draw(&PathElement::new(vec![from, to], style)).map_err(draw_err),
        }
    };
    // Pixel of the grid-line crossing (column line `x`, row line `y`).
    let at = |x: i64, y: i64| {
        (
            canvas.left + x as i32 * canvas.cell,
            canvas.top + (canvas.height - y) as i32 * canvas.cell,
        )
    };
    for (&y, xs) in &horizontal {
        for (x0, x1) in spans(xs) {
            line(at(x0, y), at(x1 + 1, y))?;
        }
    }
    for (&x, ys) in &vertical {
        for (y0, y1) in spans(ys) {
            line(at(x, y1 + 1), at(x, y0))?;
        }
    }
    Ok(())
}

/// The maximal runs of consecutive values, as `(first, last)`.
fn spans(values: &BTreeSet<i64>) -> Vec<(i64, i64)> {
    let mut out: Vec<(i64, i64)> = Vec::new();
    for &v in values {
        match out.last_mut() {
            Some((_, last)) if *last + 1 == v => *last = v,
            _ => out.push((v, v)),
        }
    }
    out
}

/// A region name to write over everything else: in a small white box inside the region
/// (`bounds` is the rectangle it is centred in), or beside the region (`bounds` is the
/// region's bounding box).
struct Tag {
    name: String,
    kind: RegionKind,
    bounds: [(i32, i32); 2],
    /// The pixel size of the text.
    pixels: f64,
    place: Place,
}

/// Where a boxed region name goes relative to its `bounds`.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Place {
    /// Centred in them.
    Inside,
    /// Just above them (below when there is no room), with a short leader.
    Beside,
    /// Across their top edge, like a tab: over arrows, it hides only the rims of the cells.
    Edge,
}

/// Writes a region's name inside it, as large as fits its largest rectangle of cells.
/// A large name is drawn faint, under the arrows and paths; a smaller one is returned to
/// be drawn over them in a small box, inside the region when it is still readable there,
/// beside the region otherwise.
fn draw_label(
    area: &Area<'_>,
    canvas: &Canvas,
    kind: RegionKind,
    name: &str,
    cells: &[(i64, i64)],
) -> Result<Option<Tag>> {
    let set: HashSet<(i64, i64)> = cells.iter().copied().collect();
    let name = shorten(&clean_text(name));
    let chars = name.chars().count();
    let Some((b, pixels)) = best_box(&set, chars, canvas.cell as f64) else {
        return Ok(None);
    };
    if pixels < MIN_INSIDE_LABEL_PX {
        let (min_x, max_x, min_y, max_y) = bounds(&set);
        let bounds = canvas.box_rect(CellBox { x0: min_x, x1: max_x, y0: min_y, y1: max_y });
        return Ok(Some(Tag { name, kind, bounds, pixels: TAG_PX, place: Place::Beside }));
    }
    let bounds = canvas.box_rect(b);
    if pixels < MIN_FAINT_LABEL_PX {
        // The box's margins must fit too.
        let pixels = pixels.min(TAG_PX);
        return Ok(Some(Tag { name, kind, bounds, pixels, place: Place::Inside }));
    }
    let [(l, t), (r, bottom)] = bounds;
    let faint = match kind {
        RegionKind::Avoid => AVOID.mix(0.5),
        RegionKind::Reach | RegionKind::Other => REGION.mix(0.42),
    };
    let style = TextStyle::from((crate::draw::FONT, pixels * 1.24, FontStyle::Bold).into_font())
        .color(&faint)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw(&Text::new(name, ((l + r) / 2, (t + bottom) / 2), style)).map_err(draw_err)?;
    Ok(None)
}

/// A region's name as a tab across the top edge of its topmost row of cells (the longest
/// run there), for pictures whose every cell holds a mark.
fn edge_tag(canvas: &Canvas, kind: RegionKind, name: &str, cells: &[(i64, i64)]) -> Option<Tag> {
    let top = cells.iter().map(|&(_, y)| y).max()?;
    let row: BTreeSet<i64> = cells.iter().filter(|&&(_, y)| y == top).map(|&(x, _)| x).collect();
    let (x0, x1) = spans(&row).into_iter().max_by_key(|(a, b)| (b - a, -a))?;
    let bounds = canvas.box_rect(CellBox { x0, x1, y0: top, y1: top });
    let name = shorten(&clean_text(name));
    Some(Tag { name, kind, bounds, pixels: TAG_PX, place: Place::Edge })
}

/// The bounding box of a non-empty set of cells, as `(min_x, max_x, min_y, max_y)`.
fn bounds(set: &HashSet<(i64, i64)>) -> (i64, i64, i64, i64) {
    let mut it = set.iter();
    let Some(&(x, y)) = it.next() else { return (0, 0, 0, 0) };
    it.fold((x, x, y, y), |(ax, bx, ay, by), &(x, y)| (ax.min(x), bx.max(x), ay.min(y), by.max(y)))
}

/// Writes a region's name in a small white box: centred in its rectangle when inside, else
/// just above the region (below it when there is no room above) with a short leader, kept
/// inside the grid horizontally.
fn draw_tag(area: &Area<'_>, canvas: &Canvas, tag: &Tag) -> Result<()> {
    let [(l, t), (r, b)] = tag.bounds;
    let size = tag.pixels * 1.24;
    let w = text_width(&tag.name, size) + 6;
    let h = tag.pixels.round() as i32 + 4;
    let colour = tag_colour(tag.kind);
    let keep_inside =
        |x: i32| x.clamp(canvas.left + w / 2, (canvas.right() - w / 2).max(canvas.left + w / 2));
    let (centre_x, box_top) = match tag.place {
        Place::Inside => ((l + r) / 2, (t + b) / 2 - h / 2),
        Place::Edge => (keep_inside((l + r) / 2), t - h / 2),
        Place::Beside => {
            let x = (l + r) / 2;
            (keep_inside(x), tag_leader(area, x, (t, b), h, canvas.top, colour)?)
        }
    };
    name_box(area, tag.name.clone(), (centre_x, box_top), (w, h), size, colour)
}

/// The step between labelled rows and columns: the least of 1, 2, 5, 10, 20, 25, 50, 100
/// that keeps the numbers apart.
fn axis_step(canvas: &Canvas, label_px: i32) -> i64 {
    let digits = canvas.width.max(canvas.height).to_string().len() as i32;
    let needed = (label_px * (digits + 1)) as f64 / canvas.cell as f64;
    [1, 2, 5, 10, 20, 25, 50, 100].into_iter().find(|&s| s as f64 >= needed).unwrap_or(100)
}

/// Writes the column numbers under the grid and the row numbers left of it.
fn draw_axes(area: &Area<'_>, canvas: &Canvas) -> Result<()> {
    let size = LABEL_SIZE * 0.85;
    let label_px = (size / 1.24) as i32;
    let step = axis_step(canvas, label_px);
    let bottom = canvas.bottom();
    let below = text_style(size, &INK, HPos::Center, VPos::Top);
    for x in (0..canvas.width).step_by(step as usize) {
        let (cx, _) = canvas.centre(x, 0);
        draw_text(area, &x.to_string(), (cx, bottom + 6), &below)?;
    }
    let beside = text_style(size, &INK, HPos::Right, VPos::Center);
    for y in (0..canvas.height).step_by(step as usize) {
        let (_, cy) = canvas.centre(0, y);
        draw_text(area, &y.to_string(), (canvas.left - 6, cy), &beside)?;
    }
    let name = text_style(LABEL_SIZE, &INK, HPos::Center, VPos::Top);
    draw_text(area, "x", ((canvas.left + canvas.right()) / 2, bottom + 8 + label_px), &name)?;
    let name = text_style(LABEL_SIZE, &INK, HPos::Center, VPos::Center);
    draw_text(area, "y", (14, canvas.top + (bottom - canvas.top) / 2), &name)
}
