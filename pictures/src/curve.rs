//! The learning curve: reward per episode over several seeds.

use plotters::element::EmptyElement;
use plotters::prelude::*;

use crate::draw::{FONT, LABEL_SIZE, TITLE_SIZE, draw_err, title_text};
use crate::palette::{CURVE, GRID_LINE, INK};
use crate::{PictureError, Result};

/// Curves longer than this are thinned (after smoothing) to keep the SVG small.
const MAX_POINTS: usize = 2000;
/// Rewards beyond this size are refused: the axis arithmetic would overflow.
const LIMIT: f64 = 1e300;
const WIDTH: u32 = 900;
const HEIGHT: u32 = 540;

/// The per-episode statistics over seeds.
#[derive(Debug, Clone, Copy)]
struct Stat {
    mean: f64,
    min: f64,
    max: f64,
}

/// Draws the learning curve: the mean over seeds of the reward per episode as a line, over
/// a band from the lowest to the highest seed, after a trailing moving average of `smooth`
/// episodes (0 and 1 both mean no smoothing). Episodes are numbered from 1.
///
/// Seeds may have different lengths: each episode is summarised over the seeds that reached
/// it. Non-finite rewards (NaN, infinities) are skipped, their number is noted in the
/// legend, and an episode with no finite value leaves a gap. Errors when there are no seeds,
/// every seed is empty, no reward is finite, or a reward is beyond ±1e300.
pub fn learning_curve(title: &str, seeds: &[Vec<f64>], smooth: usize) -> Result<String> {
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
    let window = smooth.max(1);
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
    let pad = if high > low { (high - low) * 0.06 } else { low.abs().max(1.0) * 0.1 };
    let (y0, y1) = (low - pad, high + pad);
    let (x0, x1) = if episodes == 1 { (0_i64, 2_i64) } else { (1, episodes as i64) };

    let several = seeds.len() > 1;
    let mut line_label =
        if several { format!("mean of {} seeds", seeds.len()) } else { "reward".to_owned() };
    if window > 1 {
        line_label.push_str(&format!(", moving average of {window} episodes"));
    }

    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (WIDTH, HEIGHT)).into_drawing_area();
        root.fill(&WHITE).map_err(draw_err)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title_text(title), (FONT, TITLE_SIZE, FontStyle::Bold).into_font().color(&INK))
            .margin(18)
            .x_label_area_size(56)
            .y_label_area_size(84)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(draw_err)?;
        chart
            .configure_mesh()
            .x_desc("episode")
            .y_desc("reward per episode")
            .axis_desc_style((FONT, LABEL_SIZE).into_font().color(&INK))
            .label_style((FONT, LABEL_SIZE * 0.85).into_font().color(&INK))
            .bold_line_style(GRID_LINE.mix(0.6))
            .light_line_style(TRANSPARENT)
            .axis_style(INK)
            .x_labels(10)
            .y_labels(8)
            .draw()
            .map_err(draw_err)?;
        if several {
            let bands = runs.iter().map(|run| {
                let upper = run.iter().map(|&(e, s)| (e, s.max));
                let lower = run.iter().rev().map(|&(e, s)| (e, s.min));
                Polygon::new(upper.chain(lower).collect::<Vec<_>>(), CURVE.mix(0.22).filled())
            });
            chart.draw_series(bands).map_err(draw_err)?.label("lowest to highest seed").legend(
                |(x, y)| Rectangle::new([(x, y - 7), (x + 22, y + 7)], CURVE.mix(0.22).filled()),
            );
        }
        let lines = runs.iter().map(|run| {
            let points: Vec<(i64, f64)> = run.iter().map(|&(e, s)| (e, s.mean)).collect();
            PathElement::new(points, CURVE.stroke_width(2))
        });
        chart
            .draw_series(lines)
            .map_err(draw_err)?
            .label(line_label)
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], CURVE.stroke_width(2)));
        if skipped > 0 {
            let plural = if skipped == 1 { "" } else { "s" };
            chart
                .draw_series(std::iter::empty::<EmptyElement<(i64, f64), _>>())
                .map_err(draw_err)?
                .label(format!("{skipped} non-finite value{plural} skipped"))
                .legend(EmptyElement::at);
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.9))
            .border_style(GRID_LINE)
            .label_font((FONT, LABEL_SIZE).into_font().color(&INK))
            .draw()
            .map_err(draw_err)?;
        root.present().map_err(draw_err)?;
    }
    Ok(svg)
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
    let mean = values.iter().sum::<f64>() / values.len() as f64;
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
}
