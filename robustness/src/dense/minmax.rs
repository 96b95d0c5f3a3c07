//! The min and max every dense evaluator folds with (offline, online and the bounded
//! `until`'s sweep), in one place so that they order their operands alike and agree bit for
//! bit: on equal values the first operand is kept.

#[inline]
pub(crate) fn min(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

#[inline]
pub(crate) fn max(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}
