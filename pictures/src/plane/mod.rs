//! Plane pictures: the pictures of a policy learned on a continuous world (a plane world, or
//! a phase plane such as `mountain-car`'s `(x, v)`), in the grid pictures' style.
//!
//! A [`Plane`] is the frame under every such picture: the extent in the world's own units
//! with numbered axes, obstacles (circles and rectangles, drawn dark as walls are), the
//! start area, and regions. A region is whatever state formula the spec names, so the
//! caller samples it on a [`Raster`] (whether it holds at each raster cell's centre) and the
//! picture shades, hatches and outlines those cells as a grid picture does its region
//! cells.
//!
//! On top of the frame: the greedy action of a primitive option as arrows on a lattice of
//! points ([`plane_flat_policy`]), the options policy as a raster coloured by the option
//! picked, one small map per memory slice in one picture ([`plane_options_policy`]), and a
//! sample run as a path shaded by time with its slips, blocked moves and region entries
//! ([`plane_sample_run`]).
//!
//! Every function checks its input first: an empty or non-finite extent, a point that is
//! not finite or lies outside the extent, a raster of the wrong size or past
//! [`MAX_RASTER_CELLS`], more than [`MAX_ARROWS`] arrows or [`MAX_RUN_STEPS`] steps is a
//! [`PictureError`], never a panic.

mod frame;
mod pictures;
mod types;

pub use pictures::{plane_flat_policy, plane_options_policy, plane_sample_run};
pub use types::*;

#[cfg(test)]
mod tests {
    use super::frame::*;

    #[test]
    fn ticks_are_round_and_inside() {
        let (t, d) = ticks([0.0, 14.0], 600, 70);
        assert_eq!(t, vec![0.0, 2.0, 4.0, 6.0, 8.0, 10.0, 12.0, 14.0]);
        assert_eq!(d, 0);
        let (t, d) = ticks([-0.07, 0.07], 450, 40);
        assert!(t.iter().all(|v| (-0.07..=0.07).contains(v)), "{t:?}");
        assert_eq!(d, 2);
        assert_eq!(tick_label(-0.0, 2), "0.00");
        assert_eq!(tick_label(-1e-17, 2), "0.00");
        assert_eq!(tick_label(0.04, 2), "0.04");
        assert_eq!(tick_label(3e9, EXPONENT), "3.00e9");
        assert_eq!(ticks([0.0, 1e9], 600, 70).1, EXPONENT);
        // A huge extent falls back to its ends.
        let (t, _) = ticks([-1e300, 1e300], 600, 70);
        assert!(!t.is_empty() && t.len() <= 201);
    }

    #[test]
    fn clipping_keeps_a_polygon_inside_the_frame() {
        let frame =
            Frame { left: 0, top: 0, width: 100, height: 100, x: [0.0, 1.0], y: [0.0, 1.0] };
        let square = vec![(-50.0, -50.0), (50.0, -50.0), (50.0, 50.0), (-50.0, 50.0)];
        let clipped = frame.clip(square);
        assert!(
            clipped.iter().all(|&(x, y)| (0.0..=100.0).contains(&x) && (0.0..=100.0).contains(&y))
        );
        assert!(clipped.len() >= 4);
        assert!(frame.clip(vec![(200.0, 200.0), (300.0, 200.0), (300.0, 300.0)]).is_empty());
    }
}
