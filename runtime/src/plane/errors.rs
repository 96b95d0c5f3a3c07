//! What a plane world's configuration error says: the field it is about (so a world file
//! can point at it), and the help for each field.

/// Which part of a configuration an error is about, so a world file can point at it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Field {
    /// The extent along x: the pair, or one bound.
    X(Option<usize>),
    /// The extent along y.
    Y(Option<usize>),
    Step,
    Headings,
    Slip,
    Noise,
    /// The obstacles as a whole.
    Obstacles,
    /// One obstacle, or one of its numbers.
    Obstacle(usize, Option<usize>),
    /// The start rectangle, or one of its numbers.
    Start(Option<usize>),
}

/// A configuration that gives no world: what is wrong, where, and how to fix it.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct ConfigError {
    pub field: Field,
    pub message: String,
    pub help: &'static str,
}

pub(crate) const EXTENT_HELP: &str =
    "write the extent as two finite numbers, lower first, such as `x = [0.0, 20.0]`";
pub(crate) const STEP_HELP: &str =
    "write how far the chosen heading moves the robot in one step, such as `step = 0.5`";
pub(crate) const HEADINGS_HELP: &str = "write `headings = 4` for E N W S, `headings = 8` for E NE \
                                        N NW W SW S SE, or another count from 3 to 64";
pub(crate) const SLIP_HELP: &str = "write a probability such as `slip = 0.1`: one of the other \
                                    headings is taken instead with this probability";
pub(crate) const NOISE_HELP: &str = "write the standard deviation of the noise on each \
                                     coordinate of a move, such as `noise = 0.05`, or 0 for none";
pub(crate) const CIRCLE_HELP: &str =
    "write a circle as `{ circle = [cx, cy, r] }` with finite numbers and a positive radius r";
pub(crate) const RECT_HELP: &str = "write a rectangle as `{ rect = [x0, y0, x1, y1] }`, lower \
                                    left corner first, with x0 < x1 and y0 < y1";
pub(crate) const START_HELP: &str = "write the start rectangle as `start = [x0, y0, x1, y1]`, \
                                     lower left corner first, inside the extent";
pub(super) const FREE_HELP: &str = "move the start rectangle (`start = [x0, y0, x1, y1]`) to where the \
                         obstacles leave room, or make the obstacles smaller";

/// A number as messages show it: plain for moderate magnitudes, with an exponent beyond
/// (`1e300`, `5e-324`), read back to the same double either way.
pub fn num(v: f64) -> String {
    let a = v.abs();
    if v.is_finite() && a != 0.0 && !(1e-5..1e16).contains(&a) {
        format!("{v:e}")
    } else {
        v.to_string()
    }
}

pub(super) fn list(values: &[f64]) -> String {
    let parts: Vec<String> = values.iter().map(|&v| num(v)).collect();
    format!("[{}]", parts.join(", "))
}
