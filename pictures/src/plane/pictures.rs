//! The plane pictures themselves: a flat policy's arrows, the options policy's maps and a
//! sample run, each over the frame.

use std::collections::HashSet;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::frame::*;
use super::types::*;
use crate::draw::{
    Area, LABEL_SIZE, LegendEntry, Mark, clean_text, draw_arrow, draw_blocked, draw_end,
    draw_entry, draw_err, draw_slip, draw_start, draw_still, draw_terminate, draw_text,
    option_band, shorten, text_style, text_width,
};
use crate::grid::cell_boxes;
use crate::label::CellBox;
use crate::palette::{AVOID, INK, option_color, shade};
use crate::run::{draw_head, step_axis};
use crate::{PictureError, Result};

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
pub(super) fn draw_run_path(
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
pub(super) fn draw_run_timeline(
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
    option_band(area, span, &x_of, band, |i| steps[i].option, colour_of)?;
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
    step_axis(area, span, &x_of, band)
}
