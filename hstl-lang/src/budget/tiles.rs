//! The tile coder's layout as the checks count it (the runtime's `approx::tiles`): how many
//! features a tiling has, and how a continuous world lays tiles along a variable a spec
//! leaves without `bins` ([`TileFit`], a fact of the world that [`crate::world::BoxFacts`]
//! carries). Reads nothing else of the crate.

/// The tile coder's layout (the runtime's `approx::tiles`): a tiling is laid out densely up
/// to this many variables and tiles, else hashed into [`HASHED_TILES`] slots.
const MAX_DENSE_DIMS: usize = 3;
const MAX_DENSE_TILES: u64 = 1 << 16;
const HASHED_TILES: u64 = 1 << 14;
/// The most tiles along a variable that a plane world's step sets (the facade's
/// `continuous::MAX_STEP_BINS`).
pub const MAX_STEP_BINS: u64 = 64;
/// Tiles along each variable of `mountain-car` when the spec sets none (the facade's
/// `continuous::CAR_BINS`).
pub const CAR_BINS: u64 = 12;

/// How a continuous world lays tiles along a variable whose `bins` the spec leaves out.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TileFit {
    /// A tile about one step wide: `width / step` rounded, from 2 to [`MAX_STEP_BINS`] (a
    /// plane world).
    Step(f64),
    /// This many tiles (`mountain-car`: [`CAR_BINS`]).
    Fixed(u64),
}

impl TileFit {
    /// Tiles along a variable of range `width` (`declared`: what the spec's tile box gives,
    /// kept when the width over the step is not a finite number).
    pub fn bins(self, width: f64, declared: u64) -> u64 {
        match self {
            TileFit::Step(step) => {
                let n = (width / step).round();
                if n.is_finite() { (n as u64).clamp(2, MAX_STEP_BINS) } else { declared }
            }
            TileFit::Fixed(n) => n,
        }
    }
}

/// The features of a tile coding with `bins[d]` tiles along each variable and `tilings`
/// tilings (the runtime's `TileCoder::len`): one tile more along each variable for the
/// offset, laid out densely over up to 3 variables and 65,536 tiles a tiling, else hashed
/// into 16,384 slots a tiling. Saturating.
pub fn tiling_features(bins: &[u64], tilings: u64) -> u64 {
    let dense = bins.iter().try_fold(1u64, |acc, &b| acc.checked_mul(b.checked_add(1)?));
    let per_tiling = match dense {
        Some(n) if bins.len() <= MAX_DENSE_DIMS && n <= MAX_DENSE_TILES => n,
        _ => HASHED_TILES,
    };
    per_tiling.saturating_mul(tilings)
}
