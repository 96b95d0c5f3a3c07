//! `learn { preset: auto }`: the recommended configuration for the task's form
//! (LANGUAGE.md, "Presets"), and the safety conjuncts it fills `avoid:` from.
//!
//! For a persistent task `always[0..] (eventually[0..N1] R1 && ...)` the preset gives every
//! option the entry form (`init: !R`, `terminate: R`), makes the options set one option per
//! region, and sets a memory sized from the deadlines, the window reward and the tuned step
//! sizes. For any other task with options it makes the legs stop on entering their region.
//! Wherever the task has safety conjuncts (`always !R`), every option gets `avoid:` of their
//! regions. A task that is not persistent and keeps out of `R` for good (`always !R`, no
//! window) gets one more option, [`KEEP_CLEAR`], for after its goals: once they are met
//! only the avoidance is left, which no leg that enters a goal keeps well. Anything written
//! beside the preset is kept.

use crate::checked::{CFormula, CFormulaKind, CheckedSpec, LearnParams, Terminate};

/// The flat step size of the preset: with slips the flat Q-values are noisy at the paper's
/// 0.2, and every step the learned legs lose costs the task.
pub const FLAT_ALPHA: f64 = 0.05;
/// The options level's discount of the preset (per step, with the window reward).
pub const OPTIONS_GAMMA: f64 = 0.98;
/// The options level's step size of the preset: with `switch: step` 0.1 kept 0.923 of W*
/// on the case study over 10 seeds, 0.05 0.913 and 0.2 0.923. The options level is short
/// of samples (2400 episodes kept 0.935, 4800 0.941), but the paper's 1200 episodes keep
/// every suite task near 1 s of training.
pub const OPTIONS_ALPHA: f64 = 0.1;
/// The flat discount of the preset on a continuous state: a leg there takes many small
/// steps (MountainCar swings back and forth for about a hundred), which the paper's 0.9
/// discounts to nothing; with 0.99 the MountainCar patrol keeps 0.96 of its windows, with
/// 0.9 under 0.1.
pub const CONTINUOUS_FLAT_GAMMA: f64 = 0.99;
/// The flat step size of the preset on a continuous state, shared by the active tiles.
pub const CONTINUOUS_FLAT_ALPHA: f64 = 0.1;
/// Episodes of the preset for a task that is not persistent: a reach task is decided in
/// its first legs, so many short episodes from random starts learn the approach, where the
/// paper's long ones spend their choices at the goal (the suite's reach-avoid tasks: 0.94
/// of the optimum against 0.76 and 0.84 with 1200 episodes of 200 choices).
pub const REACH_EPISODES: u64 = 6000;
/// Option choices per episode of the preset for a task that is not persistent.
pub const REACH_CHOICES: u64 = 10;
/// The steps one memory bucket spans, at most.
pub const BUCKET_STEPS: u64 = 5;
/// The preset keeps the memory values `(B + 1)^k` at most this many, so that the options
/// table stays small enough to learn in the default episodes.
pub const MAX_MEMORY_VALUES: u64 = 1000;

/// The option the preset adds for a task that keeps out of its avoided regions for good
/// ([`keeps_clear_for_good`]): `option keep_clear { reach: !R, terminate: argmax, avoid: R }`,
/// a leg to the states farthest from `R` (by robustness), which the options level picks once
/// the goals are met.
pub const KEEP_CLEAR: &str = "keep_clear";

/// Whether the preset adds [`KEEP_CLEAR`]: the task is not persistent, has an `eventually`
/// conjunct, and a safety conjunct with no end (`always !R`, `always[0..] !R`), and the
/// state is finite (`terminate: argmax` enumerates it).
pub fn keeps_clear_for_good(spec: &CheckedSpec, src: &str) -> bool {
    use crate::checked::Bound;
    let Some(task) = &spec.task else { return false };
    if spec.is_continuous() || spec.persistent_conjuncts(src).is_some() {
        return false;
    }
    let parts: Vec<&CFormula> = match &task.formula.kind {
        CFormulaKind::And(parts) => parts.iter().collect(),
        _ => vec![&task.formula],
    };
    let goal = parts.iter().any(|c| matches!(c.kind, CFormulaKind::Eventually(..)));
    let for_good = safety_conjuncts(spec).iter().any(
        |c| matches!(&c.conjunct.kind, CFormulaKind::Always(iv, _) if iv.end == Bound::Unbounded),
    );
    goal && for_good
}

/// A conjunct `always[I] !R` of the task (or the task itself), with `R` a state formula.
#[derive(Clone, Debug, PartialEq)]
pub struct SafetyConjunct<'a> {
    /// The avoided region `R`.
    pub region: &'a CFormula,
    /// The conjunct, `always[I] !R`.
    pub conjunct: &'a CFormula,
}

/// The safety conjuncts of the task: among its top-level conjuncts (or the task alone),
/// those of the form `always[I] !R`, bounded or not, with `R` a state formula.
pub fn safety_conjuncts(spec: &CheckedSpec) -> Vec<SafetyConjunct<'_>> {
    let Some(task) = &spec.task else { return Vec::new() };
    let parts: Vec<&CFormula> = match &task.formula.kind {
        CFormulaKind::And(parts) => parts.iter().collect(),
        _ => vec![&task.formula],
    };
    parts
        .into_iter()
        .filter_map(|c| {
            let CFormulaKind::Always(_, body) = &c.kind else { return None };
            let CFormulaKind::Not(r) = &body.kind else { return None };
            spec.is_state_formula(r).then_some(SafetyConjunct { region: r, conjunct: c })
        })
        .collect()
}

/// At most this many goals in a reach task the preset plans (as the runtime's
/// `reach_avoid::MAX_GOALS`).
pub const MAX_REACH_GOALS: usize = 4;

/// Whether the task is a reach task the legs of which `plan: model` plans: its top-level
/// conjuncts are one to [`MAX_REACH_GOALS`] `eventually[0..T] G` (bounded, from step 0) and
/// one or more `always[0..T'] !R` sharing one window, every `G` and `R` a state formula.
pub fn is_reach_task(spec: &CheckedSpec) -> bool {
    use crate::checked::Bound;
    let Some(task) = &spec.task else { return false };
    let CFormulaKind::And(parts) = &task.formula.kind else { return false };
    let (mut goals, mut window) = (0, None);
    for part in parts {
        match &part.kind {
            CFormulaKind::Eventually(iv, g)
                if iv.start == 0
                    && matches!(iv.end, Bound::Inclusive(_) | Bound::Exclusive(1..))
                    && spec.is_state_formula(g) =>
            {
                goals += 1;
            }
            CFormulaKind::Always(iv, body) => {
                let CFormulaKind::Not(r) = &body.kind else { return false };
                if iv.start != 0 || !spec.is_state_formula(r) {
                    return false;
                }
                if window.is_some_and(|w| w != iv.end) {
                    return false;
                }
                window = Some(iv.end);
            }
            _ => return false,
        }
    }
    (1..=MAX_REACH_GOALS).contains(&goals) && window.is_some()
}

/// The `avoid` formula of the safety conjuncts: their region, or the `||` of their regions.
pub fn avoid_formula(safety: &[SafetyConjunct<'_>]) -> Option<CFormula> {
    match safety {
        [] => None,
        [one] => Some(one.region.clone()),
        many => Some(CFormula {
            kind: CFormulaKind::Or(many.iter().map(|c| c.region.clone()).collect()),
            range: many[0].region.range.clone(),
        }),
    }
}

/// Whether the `avoid` formula `avoid` covers region `r`: it is `r`, or one of its
/// disjuncts is (compared by the `let` named, or by source text).
pub fn covers(avoid: &CFormula, r: &CFormula, src: &str) -> bool {
    let same = |a: &CFormula| match (&a.kind, &r.kind) {
        (CFormulaKind::Let(i), CFormulaKind::Let(j)) => i == j,
        _ => src.get(a.range.clone()).map(str::trim) == src.get(r.range.clone()).map(str::trim),
    };
    match &avoid.kind {
        CFormulaKind::Or(parts) => same(avoid) || parts.iter().any(same),
        _ => same(avoid),
    }
}

/// The memory buckets `B` for deadlines `horizons` over `k` regions (those with a window
/// longer than one step): one bucket per [`BUCKET_STEPS`] steps of the longest deadline,
/// fewer when `(B + 1)^k` would exceed [`MAX_MEMORY_VALUES`], at least 1.
pub fn memory_buckets(horizons: &[u64]) -> u64 {
    let longest = horizons.iter().copied().max().unwrap_or(1);
    let mut b = longest.div_ceil(BUCKET_STEPS).max(1);
    // A one-step window (a safety conjunct's) takes two of its `B + 1` values only: kept
    // or not. It does not make the others' buckets coarser.
    let k = u32::try_from(horizons.iter().filter(|&&n| n > 1).count()).unwrap_or(u32::MAX);
    while b > 1 && (b + 1).checked_pow(k).is_none_or(|v| v > MAX_MEMORY_VALUES) {
        b -= 1;
    }
    b
}

/// The `learn` values the preset sets for a spec whose task has the persistent form with
/// deadlines `horizons` (`None` for another form), before any value written beside it; a
/// `reach` task ([`is_reach_task`]) gets its legs planned (`plan: model`). On a
/// `continuous` state the options level is Q-learned over tilings (`plan: model` plans over
/// the finite states of a grid) and the legs learn with [`CONTINUOUS_FLAT_GAMMA`] and
/// [`CONTINUOUS_FLAT_ALPHA`].
pub fn learn(horizons: Option<&[u64]>, reach: bool, continuous: bool, learn: &mut LearnParams) {
    if continuous {
        learn.flat.gamma = CONTINUOUS_FLAT_GAMMA;
        learn.flat.alpha = CONTINUOUS_FLAT_ALPHA;
    } else {
        learn.flat.alpha = FLAT_ALPHA;
    }
    match horizons {
        Some(h) => {
            learn.memory = memory_buckets(h);
            learn.reward = crate::checked::Reward::Window;
            learn.options.gamma = OPTIONS_GAMMA;
            learn.options.alpha = OPTIONS_ALPHA;
            learn.switch = crate::checked::Switch::Step;
            if !continuous {
                learn.plan = crate::checked::Plan::Model;
            }
        }
        None => {
            learn.episodes = REACH_EPISODES;
            learn.choices = REACH_CHOICES;
            if reach && !continuous {
                learn.plan = crate::checked::Plan::Model;
            }
        }
    }
}

/// What the preset expanded to in `spec`, as hstl text: each option's fields, the options
/// set, and the `learn` values in force (after the values written beside the preset).
pub fn expansion(spec: &CheckedSpec, src: &str, filled: &[[bool; 4]], set_filled: bool) -> String {
    let text = |f: &CFormula| -> String {
        match &f.kind {
            CFormulaKind::Let(i) => spec.lets.get(*i).map_or(String::new(), |l| l.name.clone()),
            CFormulaKind::Not(a) => format!("!{}", paren(&inner_text(spec, a, src))),
            CFormulaKind::Or(parts) => {
                parts.iter().map(|p| inner_text(spec, p, src)).collect::<Vec<_>>().join(" || ")
            }
            _ => src.get(f.range.clone()).unwrap_or("").trim().to_string(),
        }
    };
    let mut lines = Vec::new();
    for (p, filled) in spec.primitives.iter().zip(filled) {
        let mut fields = Vec::new();
        if filled[3]
            && let Some(a) = &p.avoid
        {
            fields.push(format!("reach: !{}", paren(&text(a))));
            fields.push("terminate: argmax".to_string());
        }
        if filled[0] {
            fields.push(format!("init: {}", text(&p.init)));
        }
        if filled[1]
            && let Terminate::Formula(f) = &p.terminate
        {
            fields.push(format!("terminate: {}", text(f)));
        }
        if filled[2]
            && let Some(a) = &p.avoid
        {
            fields.push(format!("avoid: {}", text(a)));
        }
        if filled[3] {
            lines.push(
                "// added, and in the options set: once the goals are met, only the avoidance is left"
                    .to_string(),
            );
        }
        if !fields.is_empty() {
            lines.push(format!("option {} {{ {} }}", p.name, fields.join(", ")));
        }
    }
    if set_filled {
        let names: Vec<&str> = spec.options.iter().map(|o| o.name.as_str()).collect();
        lines.push(format!("options {{ {} }}", names.join(", ")));
    }
    let l = &spec.learn;
    let mut params = Vec::new();
    if l.reward != crate::checked::Reward::Window {
        params.push(format!("episodes: {}, choices: {}", l.episodes, l.choices));
    }
    if l.memory > 0 {
        params.push(format!("memory: {}", l.memory));
    }
    if l.reward == crate::checked::Reward::Window {
        params.push("reward: window".to_string());
    }
    if l.switch == crate::checked::Switch::Step {
        params.push("switch: step".to_string());
    }
    if l.plan == crate::checked::Plan::Model {
        params.push("plan: model".to_string());
    }
    if spec.is_continuous() {
        params.push(format!("flat: {{ gamma: {}, alpha: {} }}", l.flat.gamma, l.flat.alpha));
    } else {
        params.push(format!("flat: {{ alpha: {} }}", l.flat.alpha));
    }
    if l.reward == crate::checked::Reward::Window {
        params
            .push(format!("options: {{ gamma: {}, alpha: {} }}", l.options.gamma, l.options.alpha));
    }
    if let Some(t) = &l.tiles {
        let bins = t.bins.map_or(String::new(), |b| format!(", bins: {b}"));
        params.push(format!("tiles: {{ tilings: {}{bins} }}", t.tilings));
    }
    lines.push(format!("learn {{ {} }}", params.join(", ")));
    lines.join("\n")
}

/// A formula's text: a `let`'s name, or its source.
fn inner_text(spec: &CheckedSpec, f: &CFormula, src: &str) -> String {
    match &f.kind {
        CFormulaKind::Let(i) => spec.lets.get(*i).map_or(String::new(), |l| l.name.clone()),
        _ => src.get(f.range.clone()).unwrap_or("").trim().to_string(),
    }
}

/// `text` in parentheses unless it is a plain name.
fn paren(text: &str) -> String {
    if text.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        text.to_string()
    } else {
        format!("({text})")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn memory_is_sized_from_the_deadlines_within_the_budget() {
        // The case study: 40 steps, three regions: 8 buckets (9^3 = 729 values).
        assert_eq!(memory_buckets(&[40, 40, 40]), 8);
        // 60 steps over two regions: 12 buckets (169 values).
        assert_eq!(memory_buckets(&[25, 60]), 12);
        // Four regions: (B + 1)^4 <= 1000 gives B = 4.
        assert_eq!(memory_buckets(&[40, 40, 40, 40]), 4);
        // Short deadlines: one bucket per 5 steps, at least one.
        assert_eq!(memory_buckets(&[3]), 1);
        assert_eq!(memory_buckets(&[12, 7]), 3);
        // A safety conjunct's one-step window does not make the others coarser.
        assert_eq!(memory_buckets(&[40, 40, 40, 1]), 8);
        assert_eq!(memory_buckets(&[40, 40, 40, 1, 1]), 8);
    }
}
