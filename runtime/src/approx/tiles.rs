//! Tile coding (Sutton & Barto, 2nd ed., section 9.5.4): a state in a box becomes the
//! indices of the one tile it falls in on each of several offset tilings.
//!
//! Each tiling cuts variable `d`'s range `[lo_d, hi_d]` into `bins_d` tiles of width
//! `w_d = (hi_d - lo_d) / bins_d`, with one tile more to cover the offset. Tiling `t` is
//! shifted by `t * k_d * w_d / tilings` along variable `d`, `k_d` the `d`-th odd number
//! (1, 3, 5, ...): the asymmetric offsets the book recommends, so that the tilings do not
//! line up along the diagonal. A value outside the box is clamped to it.
//!
//! Past [`MAX_DENSE_DIMS`] variables, or past [`MAX_DENSE_TILES`] tiles per tiling, the
//! tile coordinates are hashed into [`HASHED_TILES`] slots per tiling (collisions share a
//! weight), so that the memory stays bounded whatever the dimension.

/// Dimensions up to which the tiles of a tiling are laid out densely.
pub const MAX_DENSE_DIMS: usize = 3;

/// Tiles per tiling up to which a tiling is laid out densely.
pub const MAX_DENSE_TILES: usize = 1 << 16;

/// Slots per tiling when the tile coordinates are hashed.
pub const HASHED_TILES: usize = 1 << 14;

/// The most tilings.
pub const MAX_TILINGS: usize = 64;

/// The most tiles along one variable.
pub const MAX_BINS: usize = 1024;

/// A tile coding of a box of `dims` variables.
#[derive(Clone, Debug, PartialEq)]
pub struct TileCoder {
    lo: Vec<f64>,
    hi: Vec<f64>,
    /// `1 / w_d`.
    inv_width: Vec<f64>,
    /// Tiles along each variable, the offset's one included (`bins_d + 1`).
    spans: Vec<usize>,
    /// `offsets[t * dims + d]`: tiling `t`'s shift along `d`, in tiles.
    offsets: Vec<f64>,
    tilings: usize,
    /// Slots per tiling.
    per_tiling: usize,
    hashed: bool,
}

impl TileCoder {
    /// A coding of the box `lo[d] <= x_d <= hi[d]` with `bins[d]` tiles along each variable
    /// and `tilings` tilings. Fails (with a message) for an empty or infinite box, no
    /// variable, or counts out of range.
    pub fn new(
        lo: &[f64],
        hi: &[f64],
        bins: &[usize],
        tilings: usize,
    ) -> Result<TileCoder, String> {
        let dims = lo.len();
        if dims == 0 || hi.len() != dims || bins.len() != dims {
            return Err("a tiling needs one bound pair and one tile count per variable".into());
        }
        if !(1..=MAX_TILINGS).contains(&tilings) {
            return Err(format!("tilings = {tilings} is not in 1..={MAX_TILINGS}"));
        }
        for d in 0..dims {
            if !(lo[d].is_finite()
                && hi[d].is_finite()
                && lo[d] < hi[d]
                && (hi[d] - lo[d]).is_finite())
            {
                return Err(format!(
                    "variable {} has the range [{}, {}]; a tiling needs finite bounds, the lower \
                     below the upper, and a finite width",
                    d + 1,
                    crate::plane::num(lo[d]),
                    crate::plane::num(hi[d])
                ));
            }
            if !(1..=MAX_BINS).contains(&bins[d]) {
                return Err(format!(
                    "{} tiles along variable {} is not in 1..={MAX_BINS}",
                    bins[d],
                    d + 1
                ));
            }
        }
        let spans: Vec<usize> = bins.iter().map(|b| b + 1).collect();
        let dense = spans.iter().try_fold(1usize, |acc, &s| acc.checked_mul(s));
        let (per_tiling, hashed) = match dense {
            Some(n) if dims <= MAX_DENSE_DIMS && n <= MAX_DENSE_TILES => (n, false),
            _ => (HASHED_TILES, true),
        };
        let inv_width = (0..dims).map(|d| bins[d] as f64 / (hi[d] - lo[d])).collect();
        let offsets = (0..tilings)
            .flat_map(|t| {
                (0..dims).map(move |d| ((t * (2 * d + 1)) % tilings) as f64 / tilings as f64)
            })
            .collect();
        Ok(TileCoder {
            lo: lo.to_vec(),
            hi: hi.to_vec(),
            inv_width,
            spans,
            offsets,
            tilings,
            per_tiling,
            hashed,
        })
    }

    /// The number of tilings: how many features are active in every state.
    pub fn tilings(&self) -> usize {
        self.tilings
    }

    /// The number of features: tilings times the slots of one tiling.
    pub fn len(&self) -> usize {
        self.tilings * self.per_tiling
    }

    /// Whether there are no features (never: a coder has at least one tile).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Whether the tiles are hashed.
    pub fn is_hashed(&self) -> bool {
        self.hashed
    }

    /// The variables' lower bounds.
    pub fn lo(&self) -> &[f64] {
        &self.lo
    }

    /// The variables' upper bounds.
    pub fn hi(&self) -> &[f64] {
        &self.hi
    }

    /// Tiles along each variable (without the offset's one).
    pub fn bins(&self) -> Vec<usize> {
        self.spans.iter().map(|s| s - 1).collect()
    }

    /// The active feature of each tiling at `x` (one value per variable), written into
    /// `out` (cleared first), in tiling order. A NaN value counts as the lower bound.
    pub fn features(&self, x: &[f64], out: &mut Vec<usize>) {
        out.clear();
        let dims = self.lo.len();
        // The position in tiles along each variable, shared by every tiling.
        let mut scaled = [0.0f64; MAX_DENSE_DIMS];
        let mut wide = Vec::new();
        let scaled: &mut [f64] = if dims <= MAX_DENSE_DIMS {
            &mut scaled[..dims]
        } else {
            wide.resize(dims, 0.0);
            &mut wide
        };
        for (d, s) in scaled.iter_mut().enumerate() {
            let v = x.get(d).copied().unwrap_or(self.lo[d]);
            // `max` then `min` maps NaN to the lower bound.
            let v = v.max(self.lo[d]).min(self.hi[d]);
            *s = (v - self.lo[d]) * self.inv_width[d];
        }
        for t in 0..self.tilings {
            let mut index = 0usize;
            let mut hash = 0x9e37_79b9_7f4a_7c15u64 ^ t as u64;
            for (d, s) in scaled.iter().enumerate() {
                let pos = s + self.offsets[t * dims + d];
                let tile = (pos as usize).min(self.spans[d] - 1);
                if self.hashed {
                    hash = (hash ^ tile as u64).wrapping_mul(0x0000_0100_0000_01b3);
                } else {
                    index = index * self.spans[d] + tile;
                }
            }
            if self.hashed {
                index = (hash ^ (hash >> 29)) as usize % self.per_tiling;
            }
            out.push(t * self.per_tiling + index);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_feature_per_tiling_and_nearby_states_share_most() {
        let c = TileCoder::new(&[0.0, 0.0], &[14.0, 14.0], &[14, 14], 8).unwrap();
        assert_eq!(c.len(), 8 * 15 * 15);
        let (mut a, mut b, mut far) = (Vec::new(), Vec::new(), Vec::new());
        c.features(&[3.0, 4.0], &mut a);
        c.features(&[3.2, 4.1], &mut b);
        c.features(&[11.0, 1.0], &mut far);
        assert_eq!(a.len(), 8);
        assert!(a.iter().enumerate().all(|(t, &f)| f / (15 * 15) == t));
        let shared = a.iter().zip(&b).filter(|(x, y)| x == y).count();
        assert!(shared >= 5, "{shared} of 8");
        assert_eq!(a.iter().zip(&far).filter(|(x, y)| x == y).count(), 0);
        // Outside the box and NaN are clamped, never out of range.
        for x in [[-1e300, 1e300], [f64::NAN, f64::INFINITY], [14.0, 14.0]] {
            c.features(&x, &mut a);
            assert!(a.iter().all(|&f| f < c.len()));
        }
    }

    #[test]
    fn many_dimensions_are_hashed_within_bounds() {
        let c = TileCoder::new(&[0.0; 6], &[1.0; 6], &[10; 6], 4).unwrap();
        assert!(c.is_hashed());
        assert_eq!(c.len(), 4 * HASHED_TILES);
        let mut f = Vec::new();
        c.features(&[0.1, 0.9, 0.5, 0.3, 0.7, 0.2], &mut f);
        assert!(f.iter().enumerate().all(|(t, &i)| i / HASHED_TILES == t));
    }

    #[test]
    fn bad_boxes_are_refused() {
        assert!(TileCoder::new(&[1.0], &[1.0], &[4], 8).is_err());
        assert!(TileCoder::new(&[0.0], &[f64::INFINITY], &[4], 8).is_err());
        assert!(TileCoder::new(&[0.0], &[1.0], &[0], 8).is_err());
        assert!(TileCoder::new(&[0.0], &[1.0], &[4], 0).is_err());
        assert!(TileCoder::new(&[], &[], &[], 8).is_err());
    }
}
