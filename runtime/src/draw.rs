//! The draws of the continuous worlds, from the one generator and reproducible bit for bit
//! on every platform: a uniform position in an interval and a pair of standard normals.
//!
//! Rust's `ln`, `sin` and `cos` are not: their precision is left to the platform and may
//! differ between machines, Rust versions and even calls. The functions here use only
//! `+`, `-`, `*`, `/` and `sqrt`, which IEEE 754 rounds exactly, so the same seed gives the
//! same bits everywhere.

use rand::RngExt;

use crate::Rng;

/// A position uniform in `[lo, hi]` from one uniform draw `u` in `[0, 1)`:
/// `(1 - u) * lo + u * hi`, clamped to the interval. Written so that nothing overflows
/// for any finite bounds; `lo == hi` gives `lo`.
pub fn uniform_in(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    lerp(lo, hi, rng.random::<f64>())
}

/// `(1 - u) * lo + u * hi` clamped to `[lo, hi]` (`lo <= hi`).
pub(crate) fn lerp(lo: f64, hi: f64, u: f64) -> f64 {
    ((1.0 - u) * lo + u * hi).clamp(lo, hi)
}

/// Two independent standard normal values, by Marsaglia's polar method: draw `u` and `v`
/// uniform in `[-1, 1)` (each `2 * w - 1` from one uniform `w` in `[0, 1)`, `u` first)
/// until `s = u^2 + v^2` is in `(0, 1)`, then return `u * f` and `v * f` with
/// `f = sqrt(-2 ln(s) / s)`. Each attempt is accepted with probability pi/4, so it takes
/// 2.55 uniform draws on average.
pub fn normal_pair(rng: &mut Rng) -> [f64; 2] {
    loop {
        let u = 2.0 * rng.random::<f64>() - 1.0;
        let v = 2.0 * rng.random::<f64>() - 1.0;
        let s = u * u + v * v;
        if s > 0.0 && s < 1.0 {
            let f = (-2.0 * ln(s) / s).sqrt();
            return [u * f, v * f];
        }
    }
}

/// ln 2 split so that `k * LN2_HI` is exact for every exponent `k` of a double (its low 32
/// bits are zero): 6.93147180369123816490e-01 and 1.90821492927058770002e-10.
const LN2_HI: f64 = f64::from_bits(0x3fe6_2e42_fee0_0000);
const LN2_LO: f64 = f64::from_bits(0x3dea_39ef_3579_3c76);

/// The natural logarithm of a positive finite `x`, within a few units in the last place,
/// from basic operations only. `x = 2^k * m` with `m` in `(sqrt(2)/2, sqrt(2)]`, and
/// `ln m = 2 atanh(t)` with `t = (m - 1) / (m + 1)`, `|t| <= 0.172`, whose series
/// `2 (t + t^3/3 + t^5/5 + ...)` has converged to below 1e-18 after the `t^23` term.
pub(crate) fn ln(x: f64) -> f64 {
    if x.is_nan() || x < 0.0 {
        return f64::NAN;
    }
    if x == 0.0 {
        return f64::NEG_INFINITY;
    }
    if x == f64::INFINITY {
        return x;
    }
    // Subnormals: scale into the normal range first.
    let (x, mut k) = if x < f64::MIN_POSITIVE { (x * 2f64.powi(54), -54i64) } else { (x, 0) };
    let bits = x.to_bits();
    k += ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mut m = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    if m > std::f64::consts::SQRT_2 {
        m *= 0.5;
        k += 1;
    }
    let f = m - 1.0;
    let t = f / (2.0 + f);
    let z = t * t;
    // z * (1/3 + z * (1/5 + ... + z * 1/23)), by Horner's rule from the last term.
    let mut series = 0.0;
    for j in (1..=11).rev() {
        series = z * (1.0 / f64::from(2 * j + 1) + series);
    }
    let ln_m = 2.0 * t + 2.0 * t * series;
    let k = k as f64;
    k * LN2_HI + (ln_m + k * LN2_LO)
}

/// `(cos a, sin a)` for `a` in `[0, pi/4]`, from their Taylor series (to the `a^21` and
/// `a^20` terms, below 1e-20 there), by Horner's rule.
pub(crate) fn cos_sin(a: f64) -> (f64, f64) {
    let z = a * a;
    let (mut c, mut s) = (1.0, 1.0);
    for j in (1..=10).rev() {
        let j = f64::from(j);
        // cos: 1 - z/(1*2) (1 - z/(3*4) (...)); sin: a (1 - z/(2*3) (1 - z/(4*5) (...))).
        c = 1.0 - z / ((2.0 * j - 1.0) * (2.0 * j)) * c;
        s = 1.0 - z / ((2.0 * j) * (2.0 * j + 1.0)) * s;
    }
    (c, a * s)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seeded_rng;

    /// Units in the last place between two doubles of one sign.
    fn ulps(a: f64, b: f64) -> u64 {
        a.to_bits().abs_diff(b.to_bits())
    }

    #[test]
    fn ln_is_within_a_few_ulps_of_the_platforms() {
        let mut rng = seeded_rng(1);
        let mut worst = 0;
        for i in 0..200_000 {
            let x = match i % 4 {
                0 => rng.random::<f64>(),
                1 => 1.0 + (rng.random::<f64>() - 0.5) * 1e-6,
                2 => rng.random::<f64>().powi(40),
                _ => f64::from_bits(rng.random_range(1..0x7fefffffffffffffu64)),
            };
            if x <= 0.0 || x == 1.0 {
                continue;
            }
            let (mine, std) = (ln(x), x.ln());
            let d = if mine.signum() == std.signum() { ulps(mine, std) } else { u64::MAX };
            assert!(d <= 2 || (mine - std).abs() < 1e-300, "ln({x:e}) = {mine:e}, std {std:e}");
            worst = worst.max(d);
        }
        assert!(worst <= 2, "{worst}");
        assert_eq!(ln(1.0), 0.0);
        assert_eq!(ln(2.0), std::f64::consts::LN_2);
        assert_eq!(ln(0.0), f64::NEG_INFINITY);
        assert!(ln(-1.0).is_nan() && ln(f64::NAN).is_nan());
        assert!((ln(f64::from_bits(1)) - (-744.4400719213812)).abs() < 1e-12);
    }

    #[test]
    fn cos_sin_are_within_an_ulp_of_the_platforms() {
        for i in 0..=100_000 {
            let a = std::f64::consts::FRAC_PI_4 * f64::from(i) / 100_000.0;
            let (c, s) = cos_sin(a);
            assert!(ulps(c, a.cos()) <= 1, "cos {a}");
            assert!(ulps(s, a.sin()) <= 1 || a == 0.0, "sin {a}: {s:e} {:e}", a.sin());
        }
        assert_eq!(cos_sin(0.0), (1.0, 0.0));
    }

    #[test]
    fn uniform_stays_in_its_interval() {
        let mut rng = seeded_rng(3);
        for (lo, hi) in
            [(0.0, 1.0), (-1e308, 1e308), (-f64::MAX, f64::MAX), (2.5, 2.5), (-3.0, -2.0)]
        {
            for _ in 0..1000 {
                let x = uniform_in(&mut rng, lo, hi);
                assert!(lo <= x && x <= hi, "{x} in [{lo}, {hi}]");
            }
        }
        assert_eq!(lerp(0.0, 10.0, 0.0), 0.0);
        assert_eq!(lerp(-1.0, 1.0, 0.5), 0.0);
    }
}
