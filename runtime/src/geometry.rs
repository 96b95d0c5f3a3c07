//! Exact segment tests for the plane worlds: does a closed segment touch a closed disk or
//! a closed axis-aligned rectangle?
//!
//! Touching decides whether a move is blocked, so the tests decide it exactly for the
//! doubles they are given, not for nearby ones: a move that grazes a corner or runs along
//! an edge is blocked whatever the rounding. Each test reduces to the signs of a few
//! polynomials in the coordinates (degree 2 or 4). A sign is first read from the
//! floating-point value, when that value is farther from zero than any rounding of its
//! terms could carry it (a bound of 1e-12 of the sum of the terms' magnitudes, far above
//! the few units in the last place the evaluation can lose); otherwise it is computed
//! exactly, as a sum of non-overlapping doubles (Shewchuk's expansions: error-free sums
//! and products, the products through `mul_add`, which is exact by IEEE 754).
//!
//! The exact path is exact while no product of two coordinate differences overflows or
//! underflows: for coordinates and radii between about 1e-140 and 1e140 in magnitude (or
//! zero), which holds every world a person writes. Where a value overflows, the tests
//! answer "touches", so a move is blocked rather than let through an obstacle.

use std::cmp::Ordering;

/// A point of the plane, `(x, y)`.
pub(crate) type Xy = (f64, f64);

/// How far a floating-point value must be from zero, relative to the sum of its terms'
/// magnitudes, for its sign to be trusted.
const FILTER: f64 = 1e-12;

/// Below this sum of term magnitudes, products may have underflowed: compute exactly.
const TINY: f64 = 1e-250;

/// Whether the closed segment `p`-`q` touches the closed disk of centre `c` and radius
/// `r`. A zero-length segment is the point.
pub(crate) fn segment_touches_disk(p: Xy, q: Xy, c: Xy, r: f64) -> bool {
    if in_disk(p, c, r) || in_disk(q, c, r) {
        return true;
    }
    // Neither end is in the disk: the segment touches it only if the point of the line
    // nearest to the centre lies strictly between the ends and is within `r`. An unknown
    // sign (overflow) leans towards touching.
    let positive = |o: Option<Ordering>| !matches!(o, Some(Ordering::Less | Ordering::Equal));
    positive(dot_sign(p, q, c))
        && positive(dot_sign(q, p, c))
        && line_within(p, q, c, r) != Some(Ordering::Less)
}

/// Whether the point `p` is in the closed disk of centre `c` and radius `r`.
pub(crate) fn in_disk(p: Xy, c: Xy, r: f64) -> bool {
    // r^2 - |p - c|^2 >= 0; an unknown sign (overflow) counts as inside.
    disk_sign(p, c, r) != Some(Ordering::Less)
}

/// Whether the closed segment `p`-`q` touches the closed rectangle `[x0, x1] x [y0, y1]`
/// (given as `[x0, y0, x1, y1]`, `x0 <= x1`, `y0 <= y1`).
pub(crate) fn segment_touches_rect(p: Xy, q: Xy, rect: [f64; 4]) -> bool {
    let [x0, y0, x1, y1] = rect;
    // Separated along an axis (comparisons of doubles are exact).
    if p.0.max(q.0) < x0 || p.0.min(q.0) > x1 || p.1.max(q.1) < y0 || p.1.min(q.1) > y1 {
        return false;
    }
    // Otherwise only the segment's own line can separate them: every corner strictly on
    // one side of it.
    let corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)];
    let sides = corners.map(|c| orient(p, q, c));
    let all = |o: Ordering| sides.iter().all(|&s| s == Some(o));
    !(all(Ordering::Less) || all(Ordering::Greater))
}

/// Whether the point `p` is in the closed rectangle `[x0, y0, x1, y1]`.
pub(crate) fn in_rect(p: Xy, rect: [f64; 4]) -> bool {
    let [x0, y0, x1, y1] = rect;
    x0 <= p.0 && p.0 <= x1 && y0 <= p.1 && p.1 <= y1
}

/// The sign of `r^2 - |p - c|^2`: `Less` outside the disk, `Equal` on its circle.
fn disk_sign(p: Xy, c: Xy, r: f64) -> Option<Ordering> {
    let (dx, dy) = (p.0 - c.0, p.1 - c.1);
    let (a, b, rr) = (dx * dx, dy * dy, r * r);
    filtered(rr - (a + b), rr + a + b, || {
        let dx = Expansion::diff(p.0, c.0);
        let dy = Expansion::diff(p.1, c.1);
        let r = Expansion::of(r);
        r.mul(&r).sub(&dx.mul(&dx)).sub(&dy.mul(&dy))
    })
}

/// The sign of `(b - a) . (c - a)`: `Greater` when `c` lies ahead of `a` towards `b`.
fn dot_sign(a: Xy, b: Xy, c: Xy) -> Option<Ordering> {
    let l = (b.0 - a.0) * (c.0 - a.0);
    let r = (b.1 - a.1) * (c.1 - a.1);
    filtered(l + r, l.abs() + r.abs(), || {
        let l = Expansion::diff(b.0, a.0).mul(&Expansion::diff(c.0, a.0));
        let r = Expansion::diff(b.1, a.1).mul(&Expansion::diff(c.1, a.1));
        l.add(&r)
    })
}

/// The sign of `(b - a) x (c - a)`: `Greater` when `c` lies left of the line from `a`
/// to `b`, `Equal` on it.
fn orient(a: Xy, b: Xy, c: Xy) -> Option<Ordering> {
    let l = (b.0 - a.0) * (c.1 - a.1);
    let r = (b.1 - a.1) * (c.0 - a.0);
    filtered(l - r, l.abs() + r.abs(), || {
        let l = Expansion::diff(b.0, a.0).mul(&Expansion::diff(c.1, a.1));
        let r = Expansion::diff(b.1, a.1).mul(&Expansion::diff(c.0, a.0));
        l.sub(&r)
    })
}

/// The sign of `r^2 |q - p|^2 - ((q - p) x (c - p))^2`: not `Less` when the line through
/// `p` and `q` passes within `r` of `c`.
fn line_within(p: Xy, q: Xy, c: Xy, r: f64) -> Option<Ordering> {
    let (dx, dy, ex, ey) = (q.0 - p.0, q.1 - p.1, c.0 - p.0, c.1 - p.1);
    let (l, m) = (dx * ey, dy * ex);
    let cross = l - m;
    let cross_terms = l.abs() + m.abs();
    let reach = r * r * (dx * dx + dy * dy);
    filtered(reach - cross * cross, reach + cross_terms * cross_terms, || {
        let (dx, dy) = (Expansion::diff(q.0, p.0), Expansion::diff(q.1, p.1));
        let (ex, ey) = (Expansion::diff(c.0, p.0), Expansion::diff(c.1, p.1));
        let cross = dx.mul(&ey).sub(&dy.mul(&ex));
        let r = Expansion::of(r);
        let reach = r.mul(&r).mul(&dx.mul(&dx).add(&dy.mul(&dy)));
        reach.sub(&cross.mul(&cross))
    })
}

/// The sign of a value computed in floating point as `approx`, whose terms' magnitudes sum
/// to `terms`, or of `exact()` when the rounding could have changed it. `None` when even
/// the exact value overflows.
fn filtered(approx: f64, terms: f64, exact: impl FnOnce() -> Expansion) -> Option<Ordering> {
    if approx.is_finite() && terms.is_finite() && terms > TINY && approx.abs() > FILTER * terms {
        return approx.partial_cmp(&0.0);
    }
    exact().sign()
}

/// A real number as a sum of doubles whose bits do not overlap, smallest magnitude first
/// (Shewchuk, "Adaptive Precision Floating-Point Arithmetic", 1997): the sign of the sum
/// is the sign of its largest non-zero term.
#[derive(Clone, Debug)]
struct Expansion(Vec<f64>);

/// `a + b` as a rounded sum and its exact error.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bv = s - a;
    let av = s - bv;
    (s, (a - av) + (b - bv))
}

/// `a * b` as a rounded product and its exact error (the fused multiply-add rounds once).
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

impl Expansion {
    fn of(a: f64) -> Expansion {
        Expansion(vec![a])
    }

    /// `a - b`, exactly.
    fn diff(a: f64, b: f64) -> Expansion {
        let (s, e) = two_sum(a, -b);
        Expansion(vec![e, s])
    }

    /// Adds one double, keeping the terms non-overlapping (Shewchuk's Grow-Expansion).
    fn grow(&mut self, b: f64) {
        let mut q = b;
        for h in &mut self.0 {
            let (s, e) = two_sum(q, *h);
            *h = e;
            q = s;
        }
        self.0.push(q);
        // Zeros carry nothing; dropping them keeps products short.
        self.0.retain(|&h| h != 0.0);
    }

    fn add(&self, other: &Expansion) -> Expansion {
        let mut sum = self.clone();
        for &b in &other.0 {
            sum.grow(b);
        }
        sum
    }

    fn sub(&self, other: &Expansion) -> Expansion {
        let mut sum = self.clone();
        for &b in &other.0 {
            sum.grow(-b);
        }
        sum
    }

    fn mul(&self, other: &Expansion) -> Expansion {
        let mut product = Expansion(Vec::with_capacity(2 * self.0.len() * other.0.len()));
        for &a in &self.0 {
            for &b in &other.0 {
                let (p, e) = two_product(a, b);
                product.grow(e);
                product.grow(p);
            }
        }
        product
    }

    /// The sign of the sum, or `None` when a term is not finite.
    fn sign(&self) -> Option<Ordering> {
        if self.0.iter().any(|h| !h.is_finite()) {
            return None;
        }
        self.0
            .iter()
            .rev()
            .find(|&&h| h != 0.0)
            .map_or(Some(Ordering::Equal), |h| h.partial_cmp(&0.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const C: Xy = (5.0, 5.0);

    #[test]
    fn disk_touching_tangent_and_missing() {
        // Along y = 4 past a unit circle at (5, 5): tangent at (5, 4), touching.
        assert!(segment_touches_disk((3.0, 4.0), (7.0, 4.0), C, 1.0));
        // A hair below misses.
        let below = f64::from_bits(4.0f64.to_bits() - 1);
        assert!(!segment_touches_disk((3.0, below), (7.0, below), C, 1.0));
        // Ends on the circle, outside otherwise.
        assert!(segment_touches_disk((5.0, 2.0), (5.0, 4.0), C, 1.0));
        assert!(segment_touches_disk((5.0, 6.0), (9.0, 9.0), C, 1.0));
        // Stops just short of it.
        let short = f64::from_bits(4.0f64.to_bits() - 1);
        assert!(!segment_touches_disk((5.0, 2.0), (5.0, short), C, 1.0));
        // Through the centre, both ends outside.
        assert!(segment_touches_disk((0.0, 0.0), (10.0, 10.0), C, 1.0));
        // The nearest point of the line lies beyond an end: the segment misses although
        // its line passes through the disk.
        assert!(!segment_touches_disk((0.0, 0.0), (3.0, 3.0), C, 1.0));
        assert!(!segment_touches_disk((3.0, 3.0), (0.0, 0.0), C, 1.0));
        // Wholly inside, and a zero-length segment inside, on and outside the circle.
        assert!(segment_touches_disk((4.9, 5.0), (5.1, 5.2), C, 1.0));
        assert!(segment_touches_disk((5.0, 5.0), (5.0, 5.0), C, 1.0));
        assert!(segment_touches_disk((6.0, 5.0), (6.0, 5.0), C, 1.0));
        assert!(!segment_touches_disk((6.5, 5.0), (6.5, 5.0), C, 1.0));
    }

    #[test]
    fn diagonal_tangents_are_decided_exactly() {
        // Direction (3, 4) and a centre offset (-4, 3) * t from a point of the line: the
        // distance is 5t. With binary fractions every number is a double, and the
        // floating-point evaluation of the degree-4 test rounds.
        let t = 0.375;
        let p = (1.0 / 1024.0 + 0.1, 7.0 / 64.0);
        let d = (3.0 * 0.8125, 4.0 * 0.8125);
        let foot = (p.0 + d.0 * 0.5, p.1 + d.1 * 0.5);
        let c = (foot.0 - 4.0 * t, foot.1 + 3.0 * t);
        let q = (p.0 + d.0, p.1 + d.1);
        assert!(segment_touches_disk(p, q, c, 5.0 * t));
        let less = f64::from_bits((5.0 * t).to_bits() - 1);
        assert!(!segment_touches_disk(p, q, c, less));
    }

    #[test]
    fn rect_edges_corners_and_insides() {
        let r = [4.0, 0.0, 5.0, 6.0];
        // Along the left edge, and ending on it.
        assert!(segment_touches_rect((4.0, -1.0), (4.0, 7.0), r));
        assert!(segment_touches_rect((3.0, 2.0), (4.0, 2.0), r));
        // One ulp short of the edge.
        let short = f64::from_bits(4.0f64.to_bits() - 1);
        assert!(!segment_touches_rect((3.0, 2.0), (short, 2.0), r));
        // Through a corner only, diagonally.
        assert!(segment_touches_rect((3.0, 7.0), (5.0, 5.0), r));
        assert!(segment_touches_rect((3.0, 5.0), (4.5, 6.5), r));
        // Past the corner by a little.
        assert!(!segment_touches_rect((3.0, 5.125), (4.5, 6.625), r));
        // The bounding boxes overlap, the segment passes outside the corner.
        assert!(!segment_touches_rect((3.0, 6.5), (4.5, 7.0), r));
        // Crossing without an end inside, inside wholly, a point inside and on an edge.
        assert!(segment_touches_rect((3.0, 3.0), (6.0, 3.0), r));
        assert!(segment_touches_rect((4.2, 1.0), (4.8, 5.0), r));
        assert!(segment_touches_rect((4.5, 3.0), (4.5, 3.0), r));
        assert!(segment_touches_rect((5.0, 6.0), (5.0, 6.0), r));
        assert!(!segment_touches_rect((5.5, 3.0), (5.5, 3.0), r));
    }

    #[test]
    fn expansions_add_and_multiply_exactly() {
        // (1 + 2^-60)^2 - 1 - 2^-59 = 2^-120: far below what a double carries beside 1.
        let tiny = 2f64.powi(-60);
        let a = Expansion::of(1.0).add(&Expansion::of(tiny));
        let e = a.mul(&a).sub(&Expansion::of(1.0)).sub(&Expansion::of(2.0 * tiny));
        assert_eq!(e.sign(), Some(Ordering::Greater));
        assert_eq!(e.0.iter().sum::<f64>(), 2f64.powi(-120));
        assert_eq!(Expansion::of(f64::INFINITY).sign(), None);
        assert_eq!(Expansion::diff(3.0, 3.0).sign(), Some(Ordering::Equal));
    }

    /// A signed integer of any size: enough arithmetic for an exact oracle.
    #[derive(Clone, Debug, PartialEq, Eq)]
    struct Big {
        negative: bool,
        /// Base 2^32, least significant first, no trailing zeros.
        limbs: Vec<u32>,
    }

    impl Big {
        /// `x * 2^1074` exactly, for any finite `x`.
        fn of(x: f64) -> Big {
            assert!(x.is_finite());
            let bits = x.to_bits();
            let exp = ((bits >> 52) & 0x7ff) as i64;
            let frac = bits & 0x000f_ffff_ffff_ffff;
            // x = m * 2^(e - 1074) with e >= 0.
            let (m, e) = if exp == 0 { (frac, 0) } else { (frac | 1 << 52, exp - 1) };
            let mut out = Big::int(i128::from(m)).mul(&Big::int(1i128 << (e % 32)));
            let mut shifted = vec![0u32; (e / 32) as usize];
            shifted.extend(out.limbs);
            out.limbs = shifted;
            if out.limbs.iter().all(|&l| l == 0) {
                out.limbs.clear();
            }
            if x < 0.0 { out.neg() } else { out }
        }

        fn int(v: i128) -> Big {
            let mut m = v.unsigned_abs();
            let mut limbs = Vec::new();
            while m > 0 {
                limbs.push(m as u32);
                m >>= 32;
            }
            Big { negative: v < 0, limbs }
        }

        fn cmp_mag(a: &[u32], b: &[u32]) -> Ordering {
            a.len().cmp(&b.len()).then_with(|| a.iter().rev().cmp(b.iter().rev()))
        }

        fn add_mag(a: &[u32], b: &[u32]) -> Vec<u32> {
            let mut out = Vec::new();
            let mut carry = 0u64;
            for i in 0..a.len().max(b.len()) {
                let s =
                    u64::from(*a.get(i).unwrap_or(&0)) + u64::from(*b.get(i).unwrap_or(&0)) + carry;
                out.push(s as u32);
                carry = s >> 32;
            }
            if carry > 0 {
                out.push(carry as u32);
            }
            out
        }

        /// `a - b` for `|a| >= |b|`.
        fn sub_mag(a: &[u32], b: &[u32]) -> Vec<u32> {
            let mut out = Vec::new();
            let mut borrow = 0i64;
            for (i, &ai) in a.iter().enumerate() {
                let mut d = i64::from(ai) - i64::from(*b.get(i).unwrap_or(&0)) - borrow;
                borrow = i64::from(d < 0);
                if d < 0 {
                    d += 1 << 32;
                }
                out.push(d as u32);
            }
            while out.last() == Some(&0) {
                out.pop();
            }
            out
        }

        fn add(&self, o: &Big) -> Big {
            if self.negative == o.negative {
                return Big { negative: self.negative, limbs: Big::add_mag(&self.limbs, &o.limbs) };
            }
            match Big::cmp_mag(&self.limbs, &o.limbs) {
                Ordering::Less => {
                    Big { negative: o.negative, limbs: Big::sub_mag(&o.limbs, &self.limbs) }
                }
                _ => {
                    let limbs = Big::sub_mag(&self.limbs, &o.limbs);
                    Big { negative: self.negative && !limbs.is_empty(), limbs }
                }
            }
        }

        fn neg(&self) -> Big {
            Big { negative: !self.negative && !self.limbs.is_empty(), limbs: self.limbs.clone() }
        }

        fn sub(&self, o: &Big) -> Big {
            self.add(&o.neg())
        }

        fn mul(&self, o: &Big) -> Big {
            let mut out = vec![0u64; self.limbs.len() + o.limbs.len() + 1];
            for (i, &a) in self.limbs.iter().enumerate() {
                let mut carry = 0u64;
                for (j, &b) in o.limbs.iter().enumerate() {
                    let t = out[i + j] + u64::from(a) * u64::from(b) + carry;
                    out[i + j] = t & 0xffff_ffff;
                    carry = t >> 32;
                }
                let mut k = i + o.limbs.len();
                while carry > 0 {
                    let t = out[k] + carry;
                    out[k] = t & 0xffff_ffff;
                    carry = t >> 32;
                    k += 1;
                }
            }
            let mut limbs: Vec<u32> = out.into_iter().map(|v| v as u32).collect();
            while limbs.last() == Some(&0) {
                limbs.pop();
            }
            Big { negative: (self.negative != o.negative) && !limbs.is_empty(), limbs }
        }

        fn sign(&self) -> Ordering {
            if self.limbs.is_empty() {
                Ordering::Equal
            } else if self.negative {
                Ordering::Less
            } else {
                Ordering::Greater
            }
        }
    }

    /// The segment tests over exact integers: the oracle.
    mod oracle {
        use super::Big;
        use std::cmp::Ordering;

        type P = (f64, f64);

        fn b(p: P) -> (Big, Big) {
            (Big::of(p.0), Big::of(p.1))
        }

        pub fn disk(p: P, q: P, c: P, r: f64) -> bool {
            let (p, q, c, r) = (b(p), b(q), b(c), Big::of(r));
            let rr = r.mul(&r);
            let inside = |p: &(Big, Big)| {
                let (dx, dy) = (p.0.sub(&c.0), p.1.sub(&c.1));
                rr.sub(&dx.mul(&dx)).sub(&dy.mul(&dy)).sign() != Ordering::Less
            };
            if inside(&p) || inside(&q) {
                return true;
            }
            let (dx, dy) = (q.0.sub(&p.0), q.1.sub(&p.1));
            let ahead =
                c.0.sub(&p.0).mul(&dx).add(&c.1.sub(&p.1).mul(&dy)).sign() == Ordering::Greater;
            let behind =
                c.0.sub(&q.0).mul(&dx).add(&c.1.sub(&q.1).mul(&dy)).sign() == Ordering::Less;
            let cross = dx.mul(&c.1.sub(&p.1)).sub(&dy.mul(&c.0.sub(&p.0)));
            let reach = rr.mul(&dx.mul(&dx).add(&dy.mul(&dy)));
            ahead && behind && reach.sub(&cross.mul(&cross)).sign() != Ordering::Less
        }

        pub fn rect(p: P, q: P, r: [f64; 4]) -> bool {
            let [x0, y0, x1, y1] = r;
            if p.0.max(q.0) < x0 || p.0.min(q.0) > x1 || p.1.max(q.1) < y0 || p.1.min(q.1) > y1 {
                return false;
            }
            let (bp, bq) = (b(p), b(q));
            let side = |c: P| {
                let c = b(c);
                bq.0.sub(&bp.0)
                    .mul(&c.1.sub(&bp.1))
                    .sub(&bq.1.sub(&bp.1).mul(&c.0.sub(&bp.0)))
                    .sign()
            };
            let s = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)].map(side);
            !(s.iter().all(|&v| v == Ordering::Less) || s.iter().all(|&v| v == Ordering::Greater))
        }
    }

    /// Near-degenerate cases, where a floating-point evaluation gets signs wrong: segments
    /// built in floating point to graze a corner or a circle, then moved by a few ulps.
    fn nudge(v: f64, ulps: i64) -> f64 {
        f64::from_bits((v.to_bits() as i64 + ulps) as u64)
    }

    /// A double with a full mantissa in `[2^-8, 2^8)`, either sign.
    fn full() -> impl Strategy<Value = f64> {
        (any::<u64>(), -8i32..8, any::<bool>()).prop_map(|(m, e, neg)| {
            let v =
                f64::from_bits((m & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000) * 2f64.powi(e);
            if neg { -v } else { v }
        })
    }

    const SCALE: f64 = 1048576.0;

    /// Coordinates with many fraction bits, on a grid coarse enough that touching happens
    /// often: `k / 2^20` for `k` within `2^28`.
    fn coord() -> impl Strategy<Value = i128> {
        prop_oneof![-(1i128 << 28)..(1 << 28), (-8i128..8).prop_map(|k| k << 20)]
    }

    fn f(k: i128) -> f64 {
        k as f64 / SCALE
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 4000, failure_persistence: None, ..ProptestConfig::default() })]

        #[test]
        fn disk_test_is_exact(p in (coord(), coord()), q in (coord(), coord()),
                              c in (coord(), coord()), r in 1i128..(1 << 27)) {
            let (p, q, c, r) = ((f(p.0), f(p.1)), (f(q.0), f(q.1)), (f(c.0), f(c.1)), f(r));
            prop_assert_eq!(segment_touches_disk(p, q, c, r), oracle::disk(p, q, c, r));
        }

        #[test]
        fn tangent_lines_are_exact(px in coord(), py in coord(), a in -64i128..64, b in -64i128..64,
                                   s in 1i128..4096, t in -4096i128..4096, u in 0i128..4096) {
            // The line through p with direction (a, b) * s; the centre at the foot
            // p + (a, b) * u, offset by (-b, a) * t: distance |t| * |(a, b)|, a double
            // when (a, b) is a Pythagorean direction, and otherwise only nearly.
            prop_assume!(a != 0 || b != 0);
            let p = (px, py);
            let q = (px + a * s, py + b * s);
            let c = (px + a * u - b * t, py + b * u + a * t);
            for r in [t.abs() * 5, t.abs() * 5 + 1, (t.abs() * 5 - 1).max(1)] {
                let (p, q, c, r) = ((f(p.0), f(p.1)), (f(q.0), f(q.1)), (f(c.0), f(c.1)), f(r));
                prop_assert_eq!(segment_touches_disk(p, q, c, r), oracle::disk(p, q, c, r));
            }
        }

        #[test]
        fn rect_test_is_exact(p in (coord(), coord()), q in (coord(), coord()),
                              a in (coord(), coord()), b in (coord(), coord())) {
            let r = [a.0.min(b.0), a.1.min(b.1), a.0.max(b.0), a.1.max(b.1)];
            let (p, q, r) = ((f(p.0), f(p.1)), (f(q.0), f(q.1)), r.map(f));
            prop_assert_eq!(segment_touches_rect(p, q, r), oracle::rect(p, q, r));
        }

        #[test]
        fn segments_through_corners_are_exact(cx in coord(), cy in coord(), a in -64i128..64,
                                              b in -64i128..64, s in 0i128..4096, t in 0i128..4096,
                                              w in 1i128..4096, h in 1i128..4096, corner in 0usize..4) {
            // A segment through a corner of the rectangle, in any direction.
            let p = (cx - a * s, cy - b * s);
            let q = (cx + a * t, cy + b * t);
            let r = match corner {
                0 => [cx, cy, cx + w, cy + h],
                1 => [cx - w, cy, cx, cy + h],
                2 => [cx - w, cy - h, cx, cy],
                _ => [cx, cy - h, cx + w, cy],
            };
            prop_assert!(segment_touches_rect((f(p.0), f(p.1)), (f(q.0), f(q.1)), r.map(f)));
            // Moved off the corner by one grid step across the segment, outwards.
            let off = match corner { 0 => (-1, -1), 1 => (1, -1), 2 => (1, 1), _ => (-1, 1) };
            let (p, q) = ((p.0 + off.0, p.1 + off.1), (q.0 + off.0, q.1 + off.1));
            let (p, q, r) = ((f(p.0), f(p.1)), (f(q.0), f(q.1)), r.map(f));
            prop_assert_eq!(segment_touches_rect(p, q, r), oracle::rect(p, q, r));
        }

        #[test]
        fn near_grazes_of_corners_are_exact(c in (full(), full()), d in (full(), full()),
                                            s in 0.25f64..4.0, t in 0.25f64..4.0,
                                            w in 0.5f64..2.0, nudges in proptest::collection::vec(-4i64..=4, 4)) {
            // A segment through the corner (c) of a rectangle, in floating point, then
            // moved by a few ulps: the corner is then a hair off the line either way.
            let p = (nudge(c.0 - d.0 * s, nudges[0]), nudge(c.1 - d.1 * s, nudges[1]));
            let q = (nudge(c.0 + d.0 * t, nudges[2]), nudge(c.1 + d.1 * t, nudges[3]));
            for r in [[c.0, c.1, c.0 + w, c.1 + w], [c.0 - w, c.1 - w, c.0, c.1],
                      [c.0 - w, c.1, c.0, c.1 + w], [c.0, c.1 - w, c.0 + w, c.1]] {
                prop_assert_eq!(segment_touches_rect(p, q, r), oracle::rect(p, q, r));
            }
        }

        #[test]
        fn near_tangents_of_circles_are_exact(c in (full(), full()), d in (full(), full()),
                                              r in 0.25f64..4.0, s in 0.5f64..4.0,
                                              nudges in proptest::collection::vec(-4i64..=4, 5)) {
            // A segment along the tangent at a point of the circle, in floating point,
            // then moved by a few ulps.
            let len = (d.0 * d.0 + d.1 * d.1).sqrt();
            prop_assume!(len > 1e-3);
            let (ux, uy) = (d.0 / len, d.1 / len);
            let foot = (c.0 - uy * r, c.1 + ux * r);
            let p = (nudge(foot.0 - ux * s, nudges[0]), nudge(foot.1 - uy * s, nudges[1]));
            let q = (nudge(foot.0 + ux * s, nudges[2]), nudge(foot.1 + uy * s, nudges[3]));
            let r = nudge(r, nudges[4]);
            prop_assert_eq!(segment_touches_disk(p, q, c, r), oracle::disk(p, q, c, r));
        }
    }
}
