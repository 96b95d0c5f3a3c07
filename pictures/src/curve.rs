//! Learning curves: reward per episode over several seeds, of one spec or of several
//! overlaid.

use plotters::element::{DashedPathElement, EmptyElement};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::draw::{
    FONT, LABEL_SIZE, draw_err, draw_text, draw_title, shorten, text_style, title_height,
    title_parts,
};
use crate::palette::{GRID_LINE, INK, series_color};
use crate::{PictureError, Result};

/// The curves of several specs (or variants) on one reward scale: one panel of
/// [`learning_curves`].
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// The y axis's name, such as `reward per episode`.
    pub y_label: String,
    /// The curves drawn in the panel, each a mean line over a band.
    pub series: Vec<Series>,
}

/// The learning curves of one spec (or variant) over its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// The name in the legend, such as the spec's file name.
    pub label: String,
    /// Reward per episode of each seed.
    pub seeds: Vec<Vec<f64>>,
}

/// Curves longer than this are thinned (after smoothing) to keep the SVG small.
const MAX_POINTS: usize = 2000;
/// Rewards beyond this size are refused: the axis arithmetic would overflow.
const LIMIT: f64 = 1e300;
const WIDTH: u32 = 900;
/// The height of one panel in pixels.
const PANEL_HEIGHT: i32 = 470;
/// Space for the title at the top, without its note.
const TITLE_SPACE: i32 = 48;
/// Labels on the y axis closer than this many pixels to a plateau's label are left out.
const LABEL_GAP: i32 = 18;
/// At most this many panels in one figure.
const MAX_PANELS: usize = 16;
/// The plateau is the mean line's average over this share of the last episodes.
const PLATEAU_SHARE: usize = 10;

/// The per-episode statistics over seeds.
#[derive(Debug, Clone, Copy)]
struct Stat {
    mean: f64,
    min: f64,
    max: f64,
}

/// One series, smoothed and summarised.
struct Prepared {
    label: String,
    seeds: usize,
    skipped: usize,
    episodes: usize,
    /// Stretches of the kept episodes without gaps, as `(episode number, stats)`.
    runs: Vec<Vec<(i64, Stat)>>,
    /// The mean line's average over the last tenth of the episodes.
    plateau: Option<f64>,
    low: f64,
    high: f64,
}

/// Draws the learning curve: the mean over seeds of the reward per episode as a line, over
/// a band from the lowest to the highest seed, after a trailing moving average of `smooth`
/// episodes (0 and 1 both mean no smoothing). Episodes are numbered from 1. The mean
/// line's plateau (its average over the last tenth of the episodes) is a dashed line with
/// its value written on the y axis.
///
/// Seeds may have different lengths: each episode is summarised over the seeds that reached
/// it. Non-finite rewards (NaN, infinities) are skipped, their number is noted in the
/// legend, and an episode with no finite value leaves a gap. Errors when there are no seeds,
/// every seed is empty, no reward is finite, or a reward is beyond ±1e300.
pub fn learning_curve(title: &str, seeds: &[Vec<f64>], smooth: usize) -> Result<String> {
    let window = smooth.max(1);
    let series = prepare("", seeds, window)?;
    draw(title, &[("reward per episode".to_owned(), vec![series])], window, true)
}

/// Draws the learning curves of several specs in one figure, as in the paper's Figure 3:
/// per series a mean line over a band from the lowest to the highest seed, each in its own
/// colour, named in the legend, with its plateau marked on the y axis (see
/// [`learning_curve`]). Each panel has its own y axis, stacked over one episode axis: curves
/// of different kinds of reward go in different panels.
///
/// Errors for no panel, an empty panel, more than 16 panels, or a series that
/// [`learning_curve`] would refuse (the message names the series).
pub fn learning_curves(title: &str, panels: &[Panel], smooth: usize) -> Result<String> {
    if panels.is_empty() {
        return Err(PictureError::new("a figure of learning curves needs at least one panel"));
    }
    if panels.len() > MAX_PANELS {
        return Err(PictureError::new(format!(
            "{} panels are too many for one figure (at most {MAX_PANELS})",
            panels.len()
        )));
    }
    let window = smooth.max(1);
    let mut prepared = Vec::with_capacity(panels.len());
    for panel in panels {
        if panel.series.is_empty() {
            return Err(PictureError::new(format!(
                "panel `{}` has no curve; give it at least one series",
                shorten(&panel.y_label)
            )));
        }
        let series = panel
            .series
            .iter()
            .map(|s| {
                prepare(&s.label, &s.seeds, window).map_err(|e| {
                    PictureError::new(format!("`{}`: {}", shorten(&s.label), e.message()))
                })
            })
            .collect::<Result<Vec<_>>>()?;
        prepared.push((panel.y_label.clone(), series));
    }
    draw(title, &prepared, window, false)
}

/// Checks, smooths and summarises one series.
fn prepare(label: &str, seeds: &[Vec<f64>], window: usize) -> Result<Prepared> {
    if seeds.is_empty() {
        return Err(PictureError::new("a learning curve needs at least one seed"));
    }
    let episodes = seeds.iter().map(Vec::len).max().unwrap_or(0);
    if episodes == 0 {
        return Err(PictureError::new("every seed is empty: there are no rewards to draw"));
    }
    let total: usize = seeds.iter().map(Vec::len).sum();
    let skipped = seeds.iter().flatten().filter(|v| !v.is_finite()).count();
    if skipped == total {
        return Err(PictureError::new(format!(
            "no reward is finite (all {total} values are NaN or infinite)"
        )));
    }
    for (s, seed) in seeds.iter().enumerate() {
        if let Some((e, v)) =
            seed.iter().enumerate().find(|(_, v)| v.is_finite() && v.abs() > LIMIT)
        {
            return Err(PictureError::new(format!(
                "reward {v:e} in episode {} of seed {} is too large to draw (beyond ±{LIMIT:e})",
                e + 1,
                s + 1
            )));
        }
    }
    let smoothed: Vec<Vec<Option<f64>>> =
        seeds.iter().map(|seed| moving_average(seed, window)).collect();
    let stats: Vec<Option<Stat>> = (0..episodes).map(|e| summarise(&smoothed, e)).collect();
    // Thin long curves, always keeping the last episode.
    let stride = episodes.div_ceil(MAX_POINTS);
    let mut kept: Vec<usize> = (0..episodes).step_by(stride).collect();
    if kept.last() != Some(&(episodes - 1)) {
        kept.push(episodes - 1);
    }
    let runs = finite_runs(&kept, &stats);
    let (low, high) = stats
        .iter()
        .flatten()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| (lo.min(s.min), hi.max(s.max)));
    let tail = episodes.div_ceil(PLATEAU_SHARE);
    let means: Vec<f64> = stats[episodes - tail..].iter().flatten().map(|s| s.mean).collect();
    let plateau = (!means.is_empty())
        .then(|| means.iter().map(|m| m / means.len() as f64).sum::<f64>())
        .filter(|p| p.is_finite());
    Ok(Prepared {
        label: label.to_owned(),
        seeds: seeds.len(),
        skipped,
        episodes,
        runs,
        plateau,
        low,
        high,
    })
}

/// Draws the prepared panels: the title, then each panel's chart, ticks and legend.
fn draw(
    title: &str,
    panels: &[(String, Vec<Prepared>)],
    window: usize,
    single: bool,
) -> Result<String> {
    let title = title_parts(title);
    let top = TITLE_SPACE + title_height(&title);
    let height = top + PANEL_HEIGHT * panels.len() as i32;
    let episodes = panels.iter().flat_map(|(_, s)| s.iter().map(|p| p.episodes)).max().unwrap_or(1);
    let (x0, x1) = if episodes == 1 { (0_i64, 2_i64) } else { (1, episodes as i64) };
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, height as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        draw_title(&root, &title, WIDTH as i32 / 2)?;
        let (_, body) = root.split_vertically(top);
        let areas = body.split_evenly((panels.len(), 1));
        // A series keeps one colour over the panels: they count on from panel to panel.
        let mut first_colour = 0;
        for (i, (area, (y_label, series))) in areas.iter().zip(panels).enumerate() {
            // The notes on lines, bands and dashes hold for every panel: the first says them.
            let notes = if i == 0 { legend_notes(panels, window, single) } else { Vec::new() };
            let look = Look { x: (x0, x1), window, single, first_colour, notes: &notes };
            draw_panel(&root, area, y_label, series, &look)?;
            first_colour += series.len();
        }
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
}

/// What every panel of a figure shares.
struct Look<'a> {
    /// The episode axis.
    x: (i64, i64),
    /// The moving average's window.
    window: usize,
    /// A single curve (its legend names seeds, not specs).
    single: bool,
    /// The colour index of the panel's first series.
    first_colour: usize,
    /// Rows under the series in the legend.
    notes: &'a [String],
}

/// Draws one panel on `area`; texts outside the chart go on `root` in its pixels.
fn draw_panel(
    root: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    y_label: &str,
    series: &[Prepared],
    look: &Look<'_>,
) -> Result<()> {
    let Look { x: (x0, x1), window, single, first_colour, notes } = *look;
    let colour = |i: usize| series_color(first_colour + i);
    let low = series.iter().map(|s| s.low).fold(f64::INFINITY, f64::min);
    let high = series.iter().map(|s| s.high).fold(f64::NEG_INFINITY, f64::max);
    let pad = if high > low { (high - low) * 0.06 } else { low.abs().max(1.0) * 0.1 };
    let (y0, y1) = (low - pad, high + pad);
    let mut chart = ChartBuilder::on(area)
        .margin(18)
        .margin_top(4)
        .x_label_area_size(56)
        .y_label_area_size(84)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(draw_err)?;
    chart
        .configure_mesh()
        .x_desc("episode")
        .y_desc(shorten(y_label))
        .axis_desc_style((FONT, LABEL_SIZE).into_font().color(&INK))
        .label_style((FONT, LABEL_SIZE * 0.85).into_font().color(&INK))
        .bold_line_style(GRID_LINE.mix(0.6))
        .light_line_style(TRANSPARENT)
        .axis_style(INK)
        .x_labels(10)
        .y_labels(0)
        .disable_y_mesh()
        .draw()
        .map_err(draw_err)?;
    // The y axis: round ticks, and each plateau's value where it lies.
    let (_, top_px) = chart.backend_coord(&(x0, y1));
    let (_, bottom_px) = chart.backend_coord(&(x0, y0));
    let (ticks, step) = nice_ticks(y0, y1, 8);
    let mut plateaus: Vec<(i32, f64, RGBColor)> = series
        .iter()
        .enumerate()
        .filter_map(|(i, s)| {
            Some((chart.backend_coord(&(x0, s.plateau?)).1, s.plateau?, colour(i)))
        })
        .collect();
    plateaus.sort_by_key(|p| p.0);
    // Labels of plateaus close together are pushed apart (the dashed lines stay exact).
    let mut label_y: Vec<i32> = Vec::with_capacity(plateaus.len());
    for &(y, _, _) in &plateaus {
        let y = label_y.last().map_or(y, |&prev| y.max(prev + LABEL_GAP));
        label_y.push(y);
    }
    let (axis_x, _) = chart.backend_coord(&(x0, y0));
    let (right_x, _) = chart.backend_coord(&(x1, y0));
    let tick_style = text_style(LABEL_SIZE * 0.85, &INK, HPos::Right, VPos::Center);
    for &v in &ticks {
        let (_, y) = chart.backend_coord(&(x0, v));
        root.draw(&PathElement::new(vec![(axis_x, y), (right_x, y)], GRID_LINE.mix(0.6)))
            .map_err(draw_err)?;
        if label_y.iter().any(|&p| (p - y).abs() < LABEL_GAP) {
            continue;
        }
        root.draw(&PathElement::new(vec![(axis_x - 5, y), (axis_x, y)], INK.stroke_width(1)))
            .map_err(draw_err)?;
        draw_text(root, &format_tick(v, step), (axis_x - 8, y), &tick_style)?;
    }
    for (i, s) in series.iter().enumerate() {
        let c = colour(i);
        if s.seeds > 1 {
            let bands = s.runs.iter().map(|run| {
                let upper = run.iter().map(|&(e, st)| (e, st.max));
                let lower = run.iter().rev().map(|&(e, st)| (e, st.min));
                Polygon::new(
                    upper.chain(lower).collect::<Vec<_>>(),
                    c.mix(band_alpha(series.len())).filled(),
                )
            });
            let drawn = chart.draw_series(bands).map_err(draw_err)?;
            if single {
                drawn.label("lowest to highest seed").legend(move |(x, y)| {
                    Rectangle::new([(x, y - 7), (x + 22, y + 7)], c.mix(0.22).filled())
                });
            }
        }
    }
    for (i, s) in series.iter().enumerate() {
        let c = colour(i);
        let lines = s.runs.iter().map(|run| {
            let points: Vec<(i64, f64)> = run.iter().map(|&(e, st)| (e, st.mean)).collect();
            PathElement::new(points, c.stroke_width(2))
        });
        let label = if single {
            let mut label = if s.seeds > 1 {
                format!("mean of {} seeds", s.seeds)
            } else {
                "reward".to_owned()
            };
            if window > 1 {
                label.push_str(&format!(", moving average of {window} episodes"));
            }
            label
        } else {
            let seeds =
                if s.seeds == 1 { "1 seed".to_owned() } else { format!("{} seeds", s.seeds) };
            format!("{} ({seeds})", shorten(&s.label))
        };
        // A single curve's band has a legend row of its own.
        let swatch = if s.seeds > 1 && !single { 0.22 } else { 0.0 };
        chart.draw_series(lines).map_err(draw_err)?.label(label).legend(move |(x, y)| {
            // Parts of a composed element are placed relative to its anchor.
            let band = Rectangle::new([(0, -6), (22, 6)], c.mix(swatch).filled());
            let line = PathElement::new(vec![(0, 0), (22, 0)], c.stroke_width(2));
            EmptyElement::at((x, y)) + band + line
        });
    }
    for ((y, value, c), &ly) in plateaus.iter().zip(&label_y) {
        root.draw(&DashedPathElement::new(
            vec![(axis_x, *y), (right_x, *y)],
            6,
            4,
            c.mix(0.8).stroke_width(1),
        ))
        .map_err(draw_err)?;
        root.draw(&PathElement::new(vec![(axis_x - 5, *y), (axis_x, *y)], c.stroke_width(2)))
            .map_err(draw_err)?;
        let style = TextStyle::from((FONT, LABEL_SIZE * 0.85, FontStyle::Bold).into_font())
            .color(c)
            .pos(Pos::new(HPos::Right, VPos::Center));
        if ly >= top_px - LABEL_GAP && ly <= bottom_px + LABEL_GAP {
            draw_text(root, &format_tick(*value, step / 10.0), (axis_x - 8, ly), &style)?;
        }
    }
    for note in notes {
        chart
            .draw_series(std::iter::empty::<EmptyElement<(i64, f64), _>>())
            .map_err(draw_err)?
            .label(note)
            .legend(EmptyElement::at);
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.9))
        .border_style(GRID_LINE)
        .label_font((FONT, LABEL_SIZE).into_font().color(&INK))
        .draw()
        .map_err(draw_err)
}

/// The legend's notes under the curves: what the plateau, lines and bands are, and the
/// values skipped.
fn legend_notes(panels: &[(String, Vec<Prepared>)], window: usize, single: bool) -> Vec<String> {
    let series: Vec<&Prepared> = panels.iter().flat_map(|(_, s)| s).collect();
    let several = series.iter().any(|s| s.seeds > 1);
    let mut notes = Vec::new();
    if !single {
        let mut what = "lines: mean".to_owned();
        if several {
            what.push_str(", bands: lowest to highest seed");
        }
        notes.push(what);
        if window > 1 {
            notes.push(format!("moving average of {window} episodes"));
        }
    }
    if series.iter().any(|s| s.plateau.is_some()) {
        notes.push(format!("dashes: mean of the last {}% of episodes", 100 / PLATEAU_SHARE));
    }
    let skipped: usize = series.iter().map(|s| s.skipped).sum();
    if skipped > 0 {
        let plural = if skipped == 1 { "" } else { "s" };
        notes.push(format!("{skipped} non-finite value{plural} skipped"));
    }
    notes
}

/// The opacity of bands: lighter when several overlap.
fn band_alpha(series: usize) -> f64 {
    if series > 1 { 0.14 } else { 0.22 }
}

/// Round tick values for the range `lo..=hi`, about `target` of them (1, 2 or 5 times a
/// power of ten apart), and their spacing; none when the range is empty or not finite.
fn nice_ticks(lo: f64, hi: f64, target: usize) -> (Vec<f64>, f64) {
    let span = hi - lo;
    if !(span.is_finite() && span > 0.0) {
        return (Vec::new(), f64::NAN);
    }
    let raw = span / target.max(1) as f64;
    let magnitude = 10f64.powf(raw.log10().floor());
    let Some(step) = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * magnitude)
        .find(|&s| s >= raw)
        .filter(|s| s.is_finite() && *s > 0.0)
    else {
        return (Vec::new(), f64::NAN);
    };
    let first = (lo / step).ceil();
    let ticks: Vec<f64> = (0..=target * 3)
        .map(|k| (first + k as f64) * step)
        .take_while(|&v| v <= hi)
        // -0 and rounding dust near zero print as 0.
        .map(|v| if v.abs() < step * 1e-9 { 0.0 } else { v })
        .collect();
    (ticks, step)
}

/// A tick value printed with just the digits its spacing `step` needs: no `.0` on whole
/// numbers, and powers of ten for very large or very small values.
fn format_tick(value: f64, step: f64) -> String {
    let value = if value.abs() < step.abs() * 1e-9 { 0.0 } else { value };
    if !step.is_finite() || step <= 0.0 {
        return trim_float(value);
    }
    let step_exp = step.log10().floor();
    if value.abs() >= 1e6 || step < 1e-4 {
        let value_exp = if value == 0.0 { step_exp } else { value.abs().log10().floor() };
        let digits = (value_exp - step_exp).clamp(0.0, 6.0) as usize;
        return format!("{value:.digits$e}");
    }
    let decimals = (-step_exp).max(0.0) as usize;
    format!("{value:.decimals$}")
}

/// A number without a trailing `.0`.
fn trim_float(value: f64) -> String {
    let text = format!("{value}");
    text.strip_suffix(".0").map_or(text.clone(), str::to_owned)
}

/// The trailing moving average over the finite values among the last `window` episodes;
/// `None` where that window holds no finite value.
fn moving_average(seed: &[f64], window: usize) -> Vec<Option<f64>> {
    let mut out = Vec::with_capacity(seed.len());
    let (mut sum, mut count) = (0.0, 0_usize);
    for (i, &value) in seed.iter().enumerate() {
        if value.is_finite() {
            sum += value;
            count += 1;
        }
        if i >= window {
            let old = seed[i - window];
            if old.is_finite() {
                sum -= old;
                count -= 1;
            }
        }
        let mean = match count {
            0 => None,
            // The running sum can overflow for huge rewards: average term by term instead.
            _ if !sum.is_finite() => {
                let from = (i + 1).saturating_sub(window);
                let finite = seed[from..=i].iter().filter(|v| v.is_finite());
                Some(finite.map(|v| v / count as f64).sum())
            }
            _ => Some(sum / count as f64),
        };
        out.push(mean);
    }
    out
}

/// Mean, lowest and highest smoothed reward at `episode` over the seeds that have one.
fn summarise(smoothed: &[Vec<Option<f64>>], episode: usize) -> Option<Stat> {
    let values: Vec<f64> =
        smoothed.iter().filter_map(|seed| seed.get(episode).copied().flatten()).collect();
    if values.is_empty() {
        return None;
    }
    // Term by term, so that huge rewards cannot overflow the sum.
    let mean = values.iter().map(|v| v / values.len() as f64).sum();
    let min = values.iter().copied().fold(f64::INFINITY, f64::min);
    let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    Some(Stat { mean, min, max })
}

/// Splits the kept episodes into stretches without gaps, as `(episode number, stats)`.
fn finite_runs(kept: &[usize], stats: &[Option<Stat>]) -> Vec<Vec<(i64, Stat)>> {
    let mut runs: Vec<Vec<(i64, Stat)>> = Vec::new();
    let mut current = Vec::new();
    for &e in kept {
        match stats.get(e).copied().flatten() {
            Some(stat) => current.push((e as i64 + 1, stat)),
            None if !current.is_empty() => runs.push(std::mem::take(&mut current)),
            None => {}
        }
    }
    if !current.is_empty() {
        runs.push(current);
    }
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_average_matches_a_direct_mean_and_skips_non_finite() {
        let big = 1e308;
        let seeds: [&[f64]; 2] = [
            &[1.0, f64::NAN, 3.0, 5.0, f64::INFINITY, f64::NAN, f64::NAN, 7.0],
            // Sums of these overflow although every mean is finite.
            &[big, big, big, -big, big, big],
        ];
        for seed in seeds {
            let window = 3;
            let got = moving_average(seed, window);
            for (i, value) in got.iter().enumerate() {
                let from = (i + 1).saturating_sub(window);
                let finite: Vec<f64> =
                    seed[from..=i].iter().copied().filter(|v| v.is_finite()).collect();
                let n = finite.len() as f64;
                let expected =
                    (!finite.is_empty()).then(|| finite.iter().map(|v| v / n).sum::<f64>());
                match (value, expected) {
                    (Some(a), Some(b)) => {
                        assert!(
                            (a - b).abs() <= 1e-12 * b.abs().max(1.0),
                            "episode {i}: {a} vs {b}"
                        )
                    }
                    (a, b) => assert_eq!(a.is_none(), b.is_none(), "episode {i}"),
                }
            }
        }
    }

    #[test]
    fn a_run_splits_at_gaps() {
        let stat = Some(Stat { mean: 0.0, min: 0.0, max: 0.0 });
        let stats = [stat, None, stat, stat, None];
        let runs = finite_runs(&[0, 1, 2, 3, 4], &stats);
        let lengths: Vec<usize> = runs.iter().map(Vec::len).collect();
        assert_eq!(lengths, [1, 2]);
        assert_eq!(runs[1][0].0, 3);
    }

    #[test]
    fn ticks_are_round_and_printed_without_needless_digits() {
        let (ticks, step) = nice_ticks(-1290.0, -290.0, 8);
        assert_eq!(step, 200.0);
        let labels: Vec<String> = ticks.iter().map(|&v| format_tick(v, step)).collect();
        assert_eq!(labels, ["-1200", "-1000", "-800", "-600", "-400"]);
        let (ticks, step) = nice_ticks(-0.03, 0.81, 8);
        assert_eq!(step, 0.2);
        let labels: Vec<String> = ticks.iter().map(|&v| format_tick(v, step)).collect();
        assert_eq!(labels, ["0.0", "0.2", "0.4", "0.6", "0.8"]);
        assert_eq!(format_tick(-334.03, 10.0), "-334");
        assert_eq!(format_tick(0.7004, 0.01), "0.70");
        assert_eq!(format_tick(2e300, 1e299), "2.0e300");
        assert_eq!(format_tick(3e-7, 1e-7), "3e-7");
        // Empty and non-finite ranges give no ticks rather than looping.
        for (lo, hi) in [(1.0, 1.0), (0.0, 5e-324), (f64::NEG_INFINITY, 0.0), (f64::NAN, 1.0)] {
            let (ticks, _) = nice_ticks(lo, hi, 8);
            assert!(ticks.len() <= 25, "{lo}..{hi}: {ticks:?}");
        }
    }
}
