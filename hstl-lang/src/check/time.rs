//! The time bounds of a dense-time spec in decimals: how many decimals its intervals are
//! written with, and each bound as a whole number of `10^-decimals` of the time unit.

use crate::syntax::{self, Formula, Item};

/// The largest interval bound of a dense-time spec once scaled by its decimals: 10^18,
/// so that a bound and a sum of two stay far inside `u64` and `usize`.
pub const MAX_TIME_BOUND: u64 = 1_000_000_000_000_000_000;

/// A decimal as written (`2.5`, `10`, `1e-3`): its digits as a whole number and its
/// number of decimals (`(25, 1)`), trailing zeros dropped. `None` for anything else.
pub(super) fn decimal(text: &str) -> Option<(u128, u32)> {
    let (mantissa, exp) = match text.find(['e', 'E']) {
        Some(k) => (&text[..k], text[k + 1..].parse::<i32>().ok()?),
        None => (text, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    if int.is_empty() || !int.bytes().chain(frac.bytes()).all(|c| c.is_ascii_digit()) {
        return None;
    }
    let frac = frac.trim_end_matches('0');
    let digits = format!("{int}{frac}");
    let digits = digits.trim_start_matches('0');
    if digits.len() > 38 {
        return None;
    }
    let mut n: u128 = if digits.is_empty() { 0 } else { digits.parse().ok()? };
    let mut decimals = i64::try_from(frac.len()).ok()? - i64::from(exp);
    while decimals < 0 {
        n = n.checked_mul(10)?;
        decimals += 1;
    }
    while decimals > 0 && n.is_multiple_of(10) && n != 0 {
        n /= 10;
        decimals -= 1;
    }
    if n == 0 {
        decimals = 0;
    }
    Some((n, u32::try_from(decimals).ok()?))
}

/// The most decimals any interval bound of the spec is written with (at most 18: more
/// are reported as too many digits).
pub(super) fn time_decimals(spec: &syntax::Spec) -> u32 {
    let mut most = 0;
    let mut stack: Vec<&Formula> = Vec::new();
    for item in &spec.items {
        match item {
            Item::Let(l) => stack.push(&l.formula),
            Item::Task(t) => stack.push(&t.formula),
            _ => {}
        }
    }
    while let Some(f) = stack.pop() {
        let (interval, kids) = (f.kind.interval(), f.operands());
        if let Some(i) = interval {
            for n in std::iter::once(&i.start).chain(&i.end) {
                if let Some((_, d)) = decimal(&n.text)
                    && d <= 18
                {
                    most = most.max(d);
                }
            }
        }
        stack.extend(kids);
    }
    most
}
