//! Number and list wording for diagnostics: `1,234,567`, `2 states`, `x = 1, y = 2`.

use crate::checked::StateVarInfo;

/// `1234567` as `1,234,567`.
pub fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A state as `x = 1, y = 2`.
pub(crate) fn state_text(spec_vars: &[StateVarInfo], s: &[f64]) -> String {
    spec_vars
        .iter()
        .zip(s)
        .map(|(v, x)| format!("{} = {}", v.name, x))
        .collect::<Vec<_>>()
        .join(", ")
}

/// `n` and the noun in the singular or plural: `1 state`, `2 states`.
pub(crate) fn plural(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}
