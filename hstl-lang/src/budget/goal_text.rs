//! `HSTL084` for a goal of a task that is not persistent whose text, as `policy.json`
//! holds it, could pass [`MAX_GOAL_TEXT`].

use super::cost::{bytes_words, goal_candidates};
use crate::checked::CheckedSpec;
use crate::diagnostic::Diagnostic;

/// The longest text of one goal `policy.json` holds (the runtime's
/// `hstl_runtime::progress::MAX_GOAL_TEXT`): the goals are written out as formulas, every
/// `let` inside them in full wherever it is used.
pub const MAX_GOAL_TEXT: u64 = 1 << 20;

/// `HSTL084` when a goal of a task that is not persistent, written out in full as
/// `policy.json` holds it, could be longer than [`MAX_GOAL_TEXT`] (a `let` used twice in
/// each of many nested lets doubles with each): counted from above, saturating, over the
/// lets once each.
pub(crate) fn goal_text(src: &str, out: &CheckedSpec) -> Option<Diagnostic> {
    if out.primitives.is_empty() || out.is_continuous() || out.persistent_conjuncts(src).is_some() {
        return None;
    }
    let candidates = goal_candidates(out);
    if candidates.is_empty() {
        return None;
    }
    let mut lets = vec![u64::MAX; out.lets.len()];
    for &i in &out.let_order {
        if let Some(l) = out.lets.get(i) {
            lets[i] = formula_text(&l.formula, &lets);
        }
    }
    let (at, bytes) = candidates
        .iter()
        .map(|c| (c.range.clone(), formula_text(c, &lets)))
        .find(|&(_, b)| b > MAX_GOAL_TEXT)?;
    Some(
        Diagnostic::new(
            "HSTL084",
            at,
            format!(
                "this goal, written out in full as `policy.json` holds it, could take {} (each `let` in it is written wherever it is used), more than the {} a goal may",
                if bytes == u64::MAX { "more than 16 EiB".to_string() } else { bytes_words(bytes) },
                bytes_words(MAX_GOAL_TEXT)
            ),
        )
        .with_help("write the goal with fewer nested lets, or lets that do not use the same let twice"),
    )
}

/// The bytes of `f` as the runtime writes it, at most: every node with parentheses, its
/// lets' bytes `lets[i]` (`u64::MAX` for one not counted), saturating. Recursive over one
/// formula, whose height the parser bounds.
fn formula_text(f: &crate::checked::CFormula, lets: &[u64]) -> u64 {
    use crate::checked::CFormulaKind as K;
    let sum = |parts: &[u64]| parts.iter().fold(0u64, |a, &b| a.saturating_add(b));
    // An interval: `[`, two numbers of at most 20 digits, `..=`, `]`.
    let interval = 45;
    let own = match &f.kind {
        K::True | K::False => 5,
        K::Invalid => 0,
        K::Let(i) => lets.get(*i).copied().unwrap_or(u64::MAX),
        K::Cmp(_, a, b) => sum(&[expr_text(a), expr_text(b), 4]),
        K::Not(a) => sum(&[1, formula_text(a, lets)]),
        K::And(v) | K::Or(v) => {
            let parts: Vec<u64> = v.iter().map(|g| formula_text(g, lets)).collect();
            sum(&parts).saturating_add(4u64.saturating_mul(v.len() as u64))
        }
        K::Implies(a, b) => sum(&[formula_text(a, lets), formula_text(b, lets), 4]),
        K::Always(_, a) | K::Eventually(_, a) | K::Once(_, a) | K::Historically(_, a) => {
            sum(&[13 + interval, formula_text(a, lets)])
        }
        K::Until(_, a, b) | K::Since(_, a, b) => {
            sum(&[8 + interval, formula_text(a, lets), formula_text(b, lets)])
        }
        K::Prev(a) | K::Next(a) => sum(&[5, formula_text(a, lets)]),
    };
    own.saturating_add(2)
}

/// The bytes of `e` as the runtime writes it, at most (see [`formula_text`]).
fn expr_text(e: &crate::checked::CExpr) -> u64 {
    use crate::checked::CExprKind as K;
    let own = match &e.kind {
        K::Const(c) => (format!("{c}").len() as u64).max(7),
        K::Var(i) => 1 + i.to_string().len() as u64,
        K::Invalid => 0,
        K::Neg(a) => 1 + expr_text(a),
        K::Abs(a) | K::Sqrt(a) => 6 + expr_text(a),
        K::Add(a, b) | K::Sub(a, b) | K::Mul(a, b) | K::Div(a, b) => {
            expr_text(a).saturating_add(expr_text(b)).saturating_add(3)
        }
    };
    own.saturating_add(2)
}
