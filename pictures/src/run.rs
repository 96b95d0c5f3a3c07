//! Sample runs: the path of one rollout over the grid in the colour of the option in force,
//! shaded light to dark over time, with its slips marked, and a timeline of the options and
//! slips under it.

use std::collections::{HashMap, HashSet};

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use crate::draw::{
    Area, LABEL_SIZE, LegendEntry, Mark, draw_end, draw_err, draw_slip, draw_start, draw_text,
    option_band, text_style,
};
use crate::grid::{
    Canvas, LEFT, Layers, check_cell, check_grid, option_order, region_legend, render,
};
use crate::palette::{INK, option_color, shade};
use crate::{Grid, PictureError, Result};

/// One step of a sample run: where the robot is, the option in force, and where the
/// chosen action leads without a slip.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunStep {
    /// The cell, `(x, y)`.
    pub cell: (i64, i64),
    /// The option in force when the move from this cell was decided.
    pub option: String,
    /// The cell the chosen action leads to without a slip, or `None` where that is not
    /// known (a hand-drawn run, or the last step). The move from this step slipped when
    /// the next step's cell differs from it.
    pub intended: Option<(i64, i64)>,
}

/// A sample run shows its direction on every this many moves.
const HEAD_EVERY: usize = 4;
/// The height of the timeline under the grid, in pixels.
const TIMELINE: i32 = 56;
/// Repeated passes along one cell edge take these lanes in turn, in units of the lane
/// spacing across the edge, so that they lie side by side.
const LANES: [i32; 7] = [0, 1, -1, 2, -2, 3, -3];

/// Draws a sample run: the path through the cell centres, each move in the colour of the
/// option in force, shaded by time (a light tint early, the colour itself half-way, a dark
/// shade late) over a dark casing; the start and end marked; each slip (a move that did not
/// end where the chosen action leads, see [`RunStep::intended`]) marked by a dotted stub
/// towards the intended cell ending in a cross. Repeated passes along one edge lie side by
/// side. Under the grid, a timeline shows the option in force at every step, shaded the
/// same way, with the slips above it.
///
/// Options take their colours from their position in `legend_order`, then their first
/// appearance, so a run's colours match an [`crate::options_policy`] picture drawn with the
/// same order; the legend lists only the options the run uses.
///
/// Errors for an empty run, an empty or too large grid, or a step or intended cell outside
/// the grid.
pub fn sample_run(
    grid: &Grid,
    title: &str,
    steps: &[RunStep],
    legend_order: &[String],
) -> Result<String> {
    check_grid(grid)?;
    if steps.is_empty() {
        return Err(PictureError::new("a sample run needs at least one step"));
    }
    for step in steps {
        check_cell(grid, step.cell, "step")?;
        if let Some(cell) = step.intended {
            check_cell(grid, cell, "intended")?;
        }
    }
    let order = option_order(legend_order, steps.iter().map(|s| s.option.as_str()));
    let index: HashMap<&str, usize> =
        order.iter().enumerate().map(|(i, name)| (name.as_str(), i)).collect();
    let colour_of = |name: &str| index.get(name).map_or(INK, |&i| option_color(i));
    let used: HashSet<&str> = steps.iter().map(|s| s.option.as_str()).collect();
    let moves = steps.len() - 1;
    let slips: Vec<usize> =
        (0..moves).filter(|&i| steps[i].intended.is_some_and(|c| c != steps[i + 1].cell)).collect();
    let mut legend: Vec<LegendEntry> = order
        .iter()
        .enumerate()
        .filter(|(_, name)| used.contains(name.as_str()))
        .map(|(i, name)| LegendEntry::new(Mark::Swatch(option_color(i)), name))
        .collect();
    legend.push(LegendEntry::new(Mark::Ramp, "light early, dark late"));
    legend.push(LegendEntry::new(Mark::Start, "start"));
    legend.push(LegendEntry::new(Mark::End, "end"));
    legend.push(LegendEntry::new(Mark::Slip, "slip (dots: move chosen)"));
    legend.extend(region_legend(grid));
    let plural = |n: usize, word: &str| format!("{n} {word}{}", if n == 1 { "" } else { "s" });
    legend.push(LegendEntry::new(
        Mark::Blank,
        format!("{}, {}", plural(moves, "move"), plural(slips.len(), "slip")),
    ));
    let over = |area: &Area<'_>, canvas: &Canvas| -> Result<()> {
        draw_path(area, canvas, steps, &colour_of)?;
        for &i in &slips {
            if let Some(intended) = steps[i].intended {
                let (fx, fy) = canvas.centre(steps[i].cell.0, steps[i].cell.1);
                let (tx, ty) = canvas.centre(intended.0, intended.1);
                let reach = 0.42;
                let to = (
                    fx + ((tx - fx) as f64 * reach).round() as i32,
                    fy + ((ty - fy) as f64 * reach).round() as i32,
                );
                draw_slip(area, (fx, fy), to, (canvas.cell / 9).clamp(3, 6))?;
            }
        }
        let half = (canvas.cell / 4).max(4);
        let (sx, sy) = steps[0].cell;
        let (ex, ey) = steps[moves].cell;
        draw_start(area, canvas.centre(sx, sy), half + 1)?;
        draw_end(area, canvas.centre(ex, ey), half - 1)
    };
    let footer = |area: &Area<'_>, canvas: &Canvas, top: i32| -> Result<()> {
        draw_timeline(area, canvas, top, steps, &slips, &colour_of)
    };
    let layers = Layers { footer: Some((TIMELINE, &footer)), ..Layers::over(&over) };
    render(grid, title, "Option", &legend, layers)
}

/// Draws the path: each move a piece of its own in its shaded option colour, over a dark
/// casing, joined to the previous piece where lanes change.
fn draw_path(
    area: &Area<'_>,
    canvas: &Canvas,
    steps: &[RunStep],
    colour_of: &dyn Fn(&str) -> RGBColor,
) -> Result<()> {
    let moves = steps.len() - 1;
    let core = (canvas.cell / 9).clamp(2, 5) as u32;
    let casing = core + 2;
    let spacing = (casing as i32 + 1).min(canvas.cell / 6).max(2);
    let max_lane = ((canvas.cell as f64 * 0.4) / spacing as f64).floor() as i32;
    let lanes: Vec<i32> = LANES.iter().copied().filter(|l| l.abs() <= max_lane).collect();
    // Passes so far along each cell edge, keyed by its two cells in order.
    let mut passes: HashMap<[(i64, i64); 2], usize> = HashMap::new();
    // Each move as a polyline of pixels with its colour.
    let mut pieces: Vec<(Vec<(i32, i32)>, RGBColor)> = Vec::new();
    let mut last_end: Option<(i32, i32)> = None;
    for i in 0..moves {
        let (from, to) = (steps[i].cell, steps[i + 1].cell);
        if from == to {
            continue;
        }
        let edge = [from.min(to), from.max(to)];
        let pass = passes.entry(edge).or_insert(0);
        let lane = lanes[*pass % lanes.len()] * spacing;
        *pass += 1;
        // Across a horizontal move the lanes are rows of pixels, across a vertical one
        // columns; the same for both directions, so passes back and forth separate too.
        let shift = if from.1 == to.1 { (0, lane) } else { (lane, 0) };
        let at = |(x, y): (i64, i64)| {
            let (px, py) = canvas.centre(x, y);
            (px + shift.0, py + shift.1)
        };
        let (a, b) = (at(from), at(to));
        let mut points = Vec::with_capacity(3);
        if let Some(end) = last_end.filter(|&e| e != a) {
            points.push(end);
        }
        points.extend([a, b]);
        last_end = Some(b);
        let t = if moves > 1 { i as f64 / (moves - 1) as f64 } else { 0.0 };
        pieces.push((points, shade(colour_of(&steps[i].option), t)));
    }
    for (points, _) in &pieces {
        area.draw(&PathElement::new(points.clone(), INK.mix(0.8).stroke_width(casing)))
            .map_err(draw_err)?;
    }
    for (points, colour) in &pieces {
        area.draw(&PathElement::new(points.clone(), colour.stroke_width(core)))
            .map_err(draw_err)?;
    }
    // Heads on every few moves show which way the robot went.
    for (points, colour) in pieces.iter().skip(1).step_by(HEAD_EVERY) {
        let n = points.len();
        draw_head(area, points[n - 2], points[n - 1], canvas.cell as f64 * 0.28, *colour)?;
    }
    Ok(())
}

/// Draws the timeline under the grid: the slips, and the option in force at each step,
/// shaded by time as the path is, with step numbers.
fn draw_timeline(
    area: &Area<'_>,
    canvas: &Canvas,
    top: i32,
    steps: &[RunStep],
    slips: &[usize],
    colour_of: &dyn Fn(&str) -> RGBColor,
) -> Result<()> {
    let moves = steps.len() - 1;
    let span = moves.max(1);
    let (left, right) = (canvas.left, canvas.right());
    let x_of = |i: usize| left + ((right - left) as f64 * i as f64 / span as f64).round() as i32;
    let label = text_style(LABEL_SIZE * 0.75, &INK, HPos::Right, VPos::Center);
    let (slip_y, band) = (top + 6, (top + 13, top + 29));
    draw_text(area, "slips", (LEFT - 6, slip_y), &label)?;
    draw_text(area, "option", (LEFT - 6, (band.0 + band.1) / 2), &label)?;
    option_band(area, span, &x_of, band, |i| steps[i].option.as_str(), colour_of)?;
    for &i in slips {
        let x = (x_of(i) + x_of(i + 1)) / 2;
        let arm = 3;
        let cross = [
            [(x - arm, slip_y - arm), (x + arm, slip_y + arm)],
            [(x - arm, slip_y + arm), (x + arm, slip_y - arm)],
        ];
        for line in cross {
            area.draw(&PathElement::new(line.to_vec(), INK.stroke_width(2))).map_err(draw_err)?;
        }
    }
    step_axis(area, span, &x_of, band)
}

/// The step numbers under a timeline's band: ticks at `x_of(i)` for every few steps `i`
/// of `0..=span`, numbered, and the word "step" after the band's right end.
pub(crate) fn step_axis(
    area: &Area<'_>,
    span: usize,
    x_of: &dyn Fn(usize) -> i32,
    band: (i32, i32),
) -> Result<()> {
    let (left, right) = (x_of(0), x_of(span));
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

/// The least of 1, 2, 5, 10, 20, 50, ... that labels `span` steps with at most `labels`
/// numbers.
pub(crate) fn tick_step(span: usize, labels: usize) -> usize {
    let mut unit = 1;
    loop {
        for m in [1, 2, 5] {
            let step = unit * m;
            if span / step <= labels {
                return step;
            }
        }
        unit = unit.saturating_mul(10);
        if unit >= span.max(1) {
            return unit.max(1);
        }
    }
}

/// Draws a small triangle in the middle of the move from `from` to `to`, pointing along it.
pub(crate) fn draw_head(
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tick_steps_keep_the_labels_few() {
        assert_eq!(tick_step(119, 10), 20);
        assert_eq!(tick_step(10, 10), 1);
        assert_eq!(tick_step(1, 10), 1);
        assert_eq!(tick_step(2000, 8), 500);
        assert_eq!(tick_step(7, 0), 10);
    }
}
