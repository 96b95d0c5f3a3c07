//! Colours: a categorical palette for options and the fixed colours of the pictures.

use plotters::style::{HSLColor, RGBColor};

/// Twenty colours chosen to be told apart (Trubetskoy's "20 distinct colours"), ordered so
/// that the first ones differ most.
const DISTINCT: [RGBColor; 20] = [
    RGBColor(0xe6, 0x19, 0x4b), // red
    RGBColor(0x3c, 0xb4, 0x4b), // green
    RGBColor(0x43, 0x63, 0xd8), // blue
    RGBColor(0xf5, 0x82, 0x31), // orange
    RGBColor(0x91, 0x1e, 0xb4), // purple
    RGBColor(0x42, 0xd4, 0xf4), // cyan
    RGBColor(0xff, 0xe1, 0x19), // yellow
    RGBColor(0xf0, 0x32, 0xe6), // magenta
    RGBColor(0xbf, 0xef, 0x45), // lime
    RGBColor(0x46, 0x99, 0x90), // teal
    RGBColor(0x9a, 0x63, 0x24), // brown
    RGBColor(0xfa, 0xbe, 0xd4), // pink
    RGBColor(0x80, 0x00, 0x00), // maroon
    RGBColor(0xdc, 0xbe, 0xff), // lavender
    RGBColor(0x80, 0x80, 0x00), // olive
    RGBColor(0xaa, 0xff, 0xc3), // mint
    RGBColor(0x00, 0x00, 0x75), // navy
    RGBColor(0xff, 0xd8, 0xb1), // apricot
    RGBColor(0xa9, 0xa9, 0xa9), // grey
    RGBColor(0xff, 0xfa, 0xc8), // beige
];

/// Arrows, text and outlines.
pub(crate) const INK: RGBColor = RGBColor(0x22, 0x22, 0x22);
/// Cell boundaries.
pub(crate) const GRID_LINE: RGBColor = RGBColor(0xcc, 0xcc, 0xcc);
/// Region shading (drawn with transparency) and outline.
pub(crate) const REGION: RGBColor = RGBColor(0x55, 0x55, 0x55);
/// Walls.
pub(crate) const WALL: RGBColor = RGBColor(0x4a, 0x4a, 0x4a);
/// Start-cell markers.
pub(crate) const START_CELL: RGBColor = RGBColor(0x2c, 0x7f, 0xb8);
/// Termination markers.
pub(crate) const TERMINATE: RGBColor = RGBColor(0xd6, 0x27, 0x28);
/// Regions to avoid: hatching, outline and label.
pub(crate) const AVOID: RGBColor = RGBColor(0xc0, 0x1c, 0x28);
/// Notes under titles.
pub(crate) const NOTE: RGBColor = RGBColor(0x55, 0x55, 0x55);

/// Matplotlib's "tab10": the colours of the learning curves, the first for a single curve.
const SERIES: [RGBColor; 10] = [
    RGBColor(0x1f, 0x77, 0xb4),
    RGBColor(0xff, 0x7f, 0x0e),
    RGBColor(0x2c, 0xa0, 0x2c),
    RGBColor(0xd6, 0x27, 0x28),
    RGBColor(0x94, 0x67, 0xbd),
    RGBColor(0x8c, 0x56, 0x4b),
    RGBColor(0xe3, 0x77, 0xc2),
    RGBColor(0x7f, 0x7f, 0x7f),
    RGBColor(0xbc, 0xbd, 0x22),
    RGBColor(0x17, 0xbe, 0xcf),
];

/// The colour of an option at time `t` in `[0, 1]` along a sample run: a light tint of it
/// early, the colour itself half-way, a dark shade late.
pub(crate) fn shade(colour: RGBColor, t: f64) -> RGBColor {
    let t = if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 };
    let (towards, share) =
        if t < 0.5 { (255.0, 0.75 * (1.0 - 2.0 * t)) } else { (0.0, 0.5 * (2.0 * t - 1.0)) };
    let mix = |c: u8| (c as f64 + (towards - c as f64) * share).round() as u8;
    RGBColor(mix(colour.0), mix(colour.1), mix(colour.2))
}

/// The colour of the curve of series `index`.
pub(crate) fn series_color(index: usize) -> RGBColor {
    SERIES.get(index).copied().unwrap_or_else(|| option_color(index))
}

/// The colour of the option at `index` in the legend order; stable for a given index.
pub(crate) fn option_color(index: usize) -> RGBColor {
    if let Some(colour) = DISTINCT.get(index) {
        return *colour;
    }
    // Past the table, step the hue by the golden angle so neighbours stay apart.
    let k = (index - DISTINCT.len()) as f64;
    let hue = (k * 0.381_966_011_250_105).fract();
    let lightness = if index.is_multiple_of(2) { 0.45 } else { 0.65 };
    let (r, g, b) = hsl_to_rgb(hue, 0.75, lightness);
    RGBColor(r, g, b)
}

fn hsl_to_rgb(h: f64, s: f64, l: f64) -> (u8, u8, u8) {
    use plotters::style::Color;
    let (r, g, b) = HSLColor(h, s, l).rgb();
    (r, g, b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shades_run_from_light_to_dark() {
        let luma = |c: RGBColor| 0.299 * c.0 as f64 + 0.587 * c.1 as f64 + 0.114 * c.2 as f64;
        for colour in (0..10).map(option_color) {
            let values: Vec<f64> = (0..=20).map(|i| luma(shade(colour, i as f64 / 20.0))).collect();
            assert!(values.windows(2).all(|w| w[1] <= w[0]), "{colour:?}: {values:?}");
            assert!(values[0] - values[20] > 100.0, "{colour:?}: {values:?}");
            assert_eq!(shade(colour, 0.5), colour);
            assert_eq!(shade(colour, f64::NAN), shade(colour, 0.0));
        }
    }

    #[test]
    fn first_forty_colours_are_pairwise_different() {
        let colours: Vec<RGBColor> = (0..40).map(option_color).collect();
        for (i, a) in colours.iter().enumerate() {
            for b in &colours[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }
}
