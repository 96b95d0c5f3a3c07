//! Grid pictures: flat policies, the options policy and sample runs.

use std::collections::{BTreeSet, HashMap, HashSet};

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use crate::draw::{
    Area, LABEL_SIZE, LegendEntry, Mark, REGION_ALPHA, clean_text, draw_arrow, draw_cased_line,
    draw_end, draw_err, draw_legend, draw_start, draw_start_cell, draw_terminate, draw_text,
    draw_title, legend_size, shorten, text_style, text_width, title_text,
};
use crate::palette::{GRID_LINE, INK, REGION, WALL, option_color};
use crate::{Action, Cell, Grid, MAX_GRID_SIDE, PictureError, Result};

/// Pixel geometry of the grid on the canvas.
struct Canvas {
    /// Side of one cell in pixels.
    cell: i32,
    /// Left edge of the grid.
    left: i32,
    /// Top edge of the grid.
    top: i32,
    /// Columns.
    width: i64,
    /// Rows.
    height: i64,
}

/// What a picture draws on top of the shaded regions.
struct Layers<'f> {
    /// Drawn under the cell boundaries and region outlines (cell colours).
    under: &'f dyn Fn(&Area<'_>, &Canvas) -> Result<()>,
    /// Drawn over everything else in the grid (arrows, markers, paths).
    over: &'f dyn Fn(&Area<'_>, &Canvas) -> Result<()>,
}

const TOP: i32 = 56;
const LEFT: i32 = 52;
const BOTTOM: i32 = 48;
const GAP: i32 = 28;
const RIGHT: i32 = 16;
/// A sample run shows its direction on every this many moves.
const HEAD_EVERY: usize = 4;
/// The grid's longer side aims at about this many pixels.
const GRID_PIXELS: i32 = 600;

impl Canvas {
    /// The top-left pixel of cell `(x, y)`; rows grow upwards, pixels downwards.
    fn corner(&self, x: i64, y: i64) -> (i32, i32) {
        (self.left + x as i32 * self.cell, self.top + (self.height - 1 - y) as i32 * self.cell)
    }

    /// The centre pixel of cell `(x, y)`.
    fn centre(&self, x: i64, y: i64) -> (i32, i32) {
        let (left, top) = self.corner(x, y);
        (left + self.cell / 2, top + self.cell / 2)
    }

    /// The pixel rectangle of cell `(x, y)`.
    fn rect(&self, x: i64, y: i64) -> [(i32, i32); 2] {
        let (left, top) = self.corner(x, y);
        [(left, top), (left + self.cell, top + self.cell)]
    }
}

/// Draws a flat policy: an arrow for the action in each given cell and a dot on each
/// termination cell, over the shaded regions, with a legend.
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
    render(grid, title, "Legend", &legend, Layers { under: &|_, _| Ok(()), over: &over })
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
    if seen.len() < grid.width * grid.height {
        legend.push(LegendEntry::new(Mark::Swatch(WHITE), "no choice"));
    }
    legend.extend(region_legend(grid));
    let index: HashMap<&str, usize> =
        order.iter().enumerate().map(|(i, name)| (name.as_str(), i)).collect();
    let under = |area: &Area<'_>, canvas: &Canvas| -> Result<()> {
        for ((x, y), name) in choices {
            let colour = index.get(name.as_str()).map_or(INK, |&i| option_color(i));
            area.draw(&Rectangle::new(canvas.rect(*x, *y), colour.filled())).map_err(draw_err)?;
        }
        Ok(())
    };
    render(grid, title, "Option", &legend, Layers { under: &under, over: &|_, _| Ok(()) })
}

/// One memory slice of an options policy with memory: a label (such as `b = [0, 4, 8]`)
/// and the option chosen in each cell for that memory value.
pub type Slice = (String, Vec<((i64, i64), String)>);

/// Draws an options policy with memory as one [`options_policy`] map per slice, titled
/// `"{title}, {label}"`. The colours agree across the maps: every map uses `legend_order`
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
            let title =
                if label.is_empty() { title.to_owned() } else { format!("{title}, {label}") };
            options_policy(grid, &title, choices, &order)
                .map_err(|e| PictureError::new(format!("memory slice `{label}`: {}", e.message())))
        })
        .collect()
}

/// Draws a sample run as a path through the cell centres, each segment coloured by the
/// option running when the move was made, with the start and end marked; colours follow
/// the order of first appearance in the run.
///
/// Errors for an empty run, an empty or too large grid, or a step outside the grid.
pub fn sample_run(grid: &Grid, title: &str, steps: &[((i64, i64), String)]) -> Result<String> {
    sample_run_ordered(grid, title, steps, &[])
}

/// Like [`sample_run`], but colours the options by their position in `legend_order` (then by
/// first appearance), so the run's colours match an [`options_policy`] picture drawn with
/// the same order. The legend lists only the options the run uses.
pub fn sample_run_ordered(
    grid: &Grid,
    title: &str,
    steps: &[((i64, i64), String)],
    legend_order: &[String],
) -> Result<String> {
    check_grid(grid)?;
    if steps.is_empty() {
        return Err(PictureError::new("a sample run needs at least one step"));
    }
    for (cell, _) in steps {
        check_cell(grid, *cell, "step")?;
    }
    let order = option_order(legend_order, steps.iter().map(|(_, name)| name.as_str()));
    let used: HashSet<&str> = steps.iter().map(|(_, name)| name.as_str()).collect();
    let mut legend: Vec<LegendEntry> = order
        .iter()
        .enumerate()
        .filter(|(_, name)| used.contains(name.as_str()))
        .map(|(i, name)| LegendEntry::new(Mark::Line(option_color(i)), name))
        .collect();
    legend.push(LegendEntry::new(Mark::Start, "start"));
    legend.push(LegendEntry::new(Mark::End, "end"));
    legend.extend(region_legend(grid));
    let moves = steps.len() - 1;
    legend.push(LegendEntry::new(
        Mark::Blank,
        format!("{moves} move{}", if moves == 1 { "" } else { "s" }),
    ));
    let index: HashMap<&str, usize> =
        order.iter().enumerate().map(|(i, name)| (name.as_str(), i)).collect();
    // Each option used gets its own lane, a small diagonal shift, so that stretches of
    // different options along the same cells stay side by side instead of hiding each other.
    let lanes: HashMap<&str, usize> = order
        .iter()
        .map(String::as_str)
        .filter(|name| used.contains(name))
        .enumerate()
        .map(|(lane, name)| (name, lane))
        .collect();
    let over = |area: &Area<'_>, canvas: &Canvas| -> Result<()> {
        let width = (canvas.cell / 10).max(2) as u32;
        let spacing =
            (canvas.cell as f64 * 0.36 / lanes.len() as f64).min(canvas.cell as f64 * 0.12);
        let shift = |name: &str, (px, py): (i32, i32)| {
            let lane = lanes.get(name).copied().unwrap_or(0) as f64;
            let offset = ((lane - (lanes.len() as f64 - 1.0) / 2.0) * spacing).round() as i32;
            (px + offset, py - offset)
        };
        // One polyline per stretch of steps under the same option; it begins where the
        // previous stretch ended, so the path stays connected across lanes.
        let mut start = 0;
        let mut previous_end: Option<(i32, i32)> = None;
        while start + 1 < steps.len() {
            let name = steps[start].1.as_str();
            let mut end = start + 1;
            while end < steps.len() - 1 && steps[end].1 == name {
                end += 1;
            }
            let colour = index.get(name).map_or(INK, |&i| option_color(i));
            let mut points: Vec<(i32, i32)> = Vec::new();
            for ((x, y), _) in &steps[start..=end] {
                let point = shift(name, canvas.centre(*x, *y));
                if points.last() != Some(&point) {
                    points.push(point);
                }
            }
            // A separate short link avoids the spiky corner a sharp lane change would make.
            if let (Some(from), Some(&to)) = (previous_end, points.first())
                && from != to
            {
                draw_cased_line(area, vec![from, to], colour, width)?;
            }
            previous_end = points.last().copied();
            if points.len() > 1 {
                draw_cased_line(area, points.clone(), colour, width)?;
                // Heads on every few moves show which way the robot went.
                for pair in points.windows(2).skip(1).step_by(HEAD_EVERY) {
                    draw_head(area, pair[0], pair[1], canvas.cell as f64 * 0.3, colour)?;
                }
            }
            start = end;
        }
        let half = (canvas.cell / 4).max(4);
        let ((sx, sy), _) = steps[0];
        let ((ex, ey), _) = steps[steps.len() - 1];
        draw_start(area, canvas.centre(sx, sy), half + 1)?;
        draw_end(area, canvas.centre(ex, ey), half - 1)
    };
    render(grid, title, "Option", &legend, Layers { under: &|_, _| Ok(()), over: &over })
}

/// Draws a small triangle in the middle of the move from `from` to `to`, pointing along it.
fn draw_head(
    area: &Area<'_>,
    from: (i32, i32),
    to: (i32, i32),
    size: f64,
    colour: RGBColor,
) -> Result<()> {
    let (dx, dy) = ((to.0 - from.0) as f64, (to.1 - from.1) as f64);
    let length = dx.hypot(dy);
    if length < size {
        return Ok(());
    }
    let (ux, uy) = (dx / length, dy / length);
    let (mx, my) = ((from.0 + to.0) as f64 / 2.0, (from.1 + to.1) as f64 / 2.0);
    let at = |along: f64, across: f64| {
        (
            (mx + ux * along - uy * across).round() as i32,
            (my + uy * along + ux * across).round() as i32,
        )
    };
    let points =
        vec![at(size * 0.6, 0.0), at(-size * 0.4, size * 0.5), at(-size * 0.4, -size * 0.5)];
    area.draw(&Polygon::new(points.clone(), colour.filled())).map_err(draw_err)?;
    let mut outline = points;
    outline.push(outline[0]);
    area.draw(&PathElement::new(outline, INK.stroke_width(1))).map_err(draw_err)
}

/// Checks the grid's size and that every region cell lies inside it.
fn check_grid(grid: &Grid) -> Result<()> {
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
fn check_cell(grid: &Grid, (x, y): (i64, i64), what: &str) -> Result<()> {
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
fn option_order<'a>(preferred: &'a [String], used: impl Iterator<Item = &'a str>) -> Vec<String> {
    let mut order: Vec<String> = Vec::new();
    let mut seen = HashSet::new();
    for name in preferred.iter().map(String::as_str).chain(used) {
        if seen.insert(name) {
            order.push(name.to_owned());
        }
    }
    order
}

/// The legend rows for the regions, walls and start cells the grid has.
fn region_legend(grid: &Grid) -> Vec<LegendEntry> {
    let mut rows = Vec::new();
    if grid.regions.iter().any(|r| !r.cells.is_empty()) {
        rows.push(LegendEntry::new(Mark::Region, "region"));
    }
    if !grid.walls.is_empty() {
        rows.push(LegendEntry::new(Mark::Wall, "wall"));
    }
    if !grid.starts.is_empty() {
        rows.push(LegendEntry::new(Mark::StartCell, "start cell"));
    }
    rows
}

/// Lays out and draws a grid picture: title, shaded regions, the layers, cell boundaries,
/// region outlines and labels, axis labels and the legend on the right.
fn render(
    grid: &Grid,
    title: &str,
    heading: &str,
    legend: &[LegendEntry],
    layers: Layers<'_>,
) -> Result<String> {
    let side = grid.width.max(grid.height) as i32;
    let cell = (GRID_PIXELS / side).clamp(8, 48);
    let canvas =
        Canvas { cell, left: LEFT, top: TOP, width: grid.width as i64, height: grid.height as i64 };
    let grid_w = cell * grid.width as i32;
    let grid_h = cell * grid.height as i32;
    let (legend_w, legend_h) = legend_size(heading, legend);
    let title = title_text(title);
    let title_w = text_width(&title, crate::draw::TITLE_SIZE) + 32;
    let width = (LEFT + grid_w + GAP + legend_w + RIGHT).max(title_w);
    let height = (TOP + grid_h + BOTTOM).max(TOP + legend_h + 16);
    let mut svg = String::new();
    {
        let area =
            SVGBackend::with_string(&mut svg, (width as u32, height as u32)).into_drawing_area();
        area.fill(&WHITE).map_err(draw_err)?;
        draw_title(&area, &title, width / 2)?;
        for region in &grid.regions {
            let cells: BTreeSet<(i64, i64)> = region.cells.iter().copied().collect();
            for &(x, y) in &cells {
                area.draw(&Rectangle::new(canvas.rect(x, y), REGION.mix(REGION_ALPHA).filled()))
                    .map_err(draw_err)?;
            }
        }
        (layers.under)(&area, &canvas)?;
        for &(x, y) in &grid.walls {
            area.draw(&Rectangle::new(canvas.rect(x, y), WALL.filled())).map_err(draw_err)?;
        }
        draw_cell_lines(&area, &canvas)?;
        for &(x, y) in &grid.starts {
            draw_start_cell(&area, canvas.corner(x, y), canvas.cell)?;
        }
        for region in &grid.regions {
            draw_region(&area, &canvas, &region.name, &region.cells)?;
        }
        (layers.over)(&area, &canvas)?;
        draw_axes(&area, &canvas)?;
        draw_legend(&area, (LEFT + grid_w + GAP, TOP - 4), heading, legend)?;
        area.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// Draws the cell boundaries and the grid's border.
fn draw_cell_lines(area: &Area<'_>, canvas: &Canvas) -> Result<()> {
    let (right, bottom) = (
        canvas.left + canvas.cell * canvas.width as i32,
        canvas.top + canvas.cell * canvas.height as i32,
    );
    let thin = GRID_LINE.stroke_width(1);
    for i in 1..canvas.width as i32 {
        let x = canvas.left + i * canvas.cell;
        area.draw(&PathElement::new(vec![(x, canvas.top), (x, bottom)], thin)).map_err(draw_err)?;
    }
    for j in 1..canvas.height as i32 {
        let y = canvas.top + j * canvas.cell;
        area.draw(&PathElement::new(vec![(canvas.left, y), (right, y)], thin)).map_err(draw_err)?;
    }
    area.draw(&Rectangle::new([(canvas.left, canvas.top), (right, bottom)], INK.stroke_width(2)))
        .map_err(draw_err)
}

/// Draws a region's outline (the cell edges it shares with no other of its cells) and its
/// name, large and faint, over the cell nearest the middle of its bounding box.
fn draw_region(area: &Area<'_>, canvas: &Canvas, name: &str, cells: &[(i64, i64)]) -> Result<()> {
    let set: HashSet<(i64, i64)> = cells.iter().copied().collect();
    let Some(&first) = cells.first() else {
        return Ok(());
    };
    let line = REGION.stroke_width(2);
    let mut sorted: Vec<(i64, i64)> = set.iter().copied().collect();
    sorted.sort_unstable();
    for &(x, y) in &sorted {
        let [(l, t), (r, b)] = canvas.rect(x, y);
        let edges = [
            ((x, y + 1), [(l, t), (r, t)]),
            ((x, y - 1), [(l, b), (r, b)]),
            ((x - 1, y), [(l, t), (l, b)]),
            ((x + 1, y), [(r, t), (r, b)]),
        ];
        for (neighbour, ends) in edges {
            if !set.contains(&neighbour) {
                area.draw(&PathElement::new(ends.to_vec(), line)).map_err(draw_err)?;
            }
        }
    }
    let (min_x, max_x, min_y, max_y) =
        set.iter().fold((first.0, first.0, first.1, first.1), |(ax, bx, ay, by), &(x, y)| {
            (ax.min(x), bx.max(x), ay.min(y), by.max(y))
        });
    let (mid_x, mid_y) = ((min_x + max_x) as f64 / 2.0, (min_y + max_y) as f64 / 2.0);
    let name = shorten(&clean_text(name));
    let chars = name.chars().count().max(1) as f64;
    let (at, box_w, box_h) = if set.contains(&(mid_x.round() as i64, mid_y.round() as i64))
        && is_full_box(&set, (min_x, max_x, min_y, max_y))
    {
        let (l, _) = canvas.corner(min_x, max_y);
        let (r, _) = canvas.corner(max_x + 1, max_y);
        let (_, t) = canvas.corner(min_x, max_y);
        let (_, b) = canvas.corner(min_x, min_y - 1);
        (((l + r) / 2, (t + b) / 2), (r - l) as f64, (b - t) as f64)
    } else {
        // An irregular region: label the cell nearest the middle of its bounding box.
        let &(x, y) = sorted
            .iter()
            .min_by(|a, b| {
                let da = (a.0 as f64 - mid_x).powi(2) + (a.1 as f64 - mid_y).powi(2);
                let db = (b.0 as f64 - mid_x).powi(2) + (b.1 as f64 - mid_y).powi(2);
                da.total_cmp(&db)
            })
            .unwrap_or(&first);
        (canvas.centre(x, y), canvas.cell as f64, canvas.cell as f64)
    };
    // As large as fits the region's box (a one-cell region gets a small label), at most 120.
    let pixels = (box_h * 0.8).min(box_w * 0.9 / (chars * 0.62)).clamp(4.0, 120.0);
    let faint = REGION.mix(0.45);
    let style = TextStyle::from((crate::draw::FONT, pixels * 1.24, FontStyle::Bold).into_font())
        .color(&faint)
        .pos(plotters::style::text_anchor::Pos::new(HPos::Center, VPos::Center));
    area.draw(&Text::new(name, at, style)).map_err(draw_err)
}

/// Whether the cells fill their bounding box completely.
fn is_full_box(
    set: &HashSet<(i64, i64)>,
    (min_x, max_x, min_y, max_y): (i64, i64, i64, i64),
) -> bool {
    let area = (max_x - min_x + 1) as i128 * (max_y - min_y + 1) as i128;
    area == set.len() as i128
}

/// Writes the column numbers under the grid and the row numbers left of it.
fn draw_axes(area: &Area<'_>, canvas: &Canvas) -> Result<()> {
    let size = LABEL_SIZE * 0.85;
    let label_px = (size / 1.24) as i32;
    // Label every k-th cell so numbers never overlap.
    let digits = canvas.width.max(canvas.height).to_string().len() as i32;
    let step = ((label_px * (digits + 1)) / canvas.cell + 1) as i64;
    let bottom = canvas.top + canvas.cell * canvas.height as i32;
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
    let right = canvas.left + canvas.cell * canvas.width as i32;
    let name = text_style(LABEL_SIZE, &INK, HPos::Center, VPos::Top);
    draw_text(area, "x", ((canvas.left + right) / 2, bottom + 8 + label_px), &name)?;
    let name = text_style(LABEL_SIZE, &INK, HPos::Center, VPos::Center);
    draw_text(area, "y", (14, canvas.top + (bottom - canvas.top) / 2), &name)
}
