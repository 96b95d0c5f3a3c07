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
/// The learning curve's line and band.
pub(crate) const CURVE: RGBColor = RGBColor(0x1f, 0x77, 0xb4);

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
    fn first_forty_colours_are_pairwise_different() {
        let colours: Vec<RGBColor> = (0..40).map(option_color).collect();
        for (i, a) in colours.iter().enumerate() {
            for b in &colours[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }
}
