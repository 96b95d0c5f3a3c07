//! The sizes a spec's `learn` item controls, held to stated limits before anything is
//! trained, so that the learner, `policy.json` and the evaluation never allocate what a
//! spec asks for unchecked. The limits are documented in LANGUAGE.md ("Limits"); the CLI
//! holds its flags (`--episodes`) to the same ones.

use crate::check::thousands;
use crate::checked::{CheckedSpec, Reward};
use crate::diagnostic::Diagnostic;
use crate::syntax::{self, ParamValue};

/// At most this many training episodes (the learning curve keeps one value each).
pub const MAX_EPISODES: u64 = 10_000_000;
/// At most this many option choices per episode.
pub const MAX_CHOICES: u64 = 1_000_000;
/// At most this many steps before a leg is cut off.
pub const MAX_STEPS: u64 = 1_000_000;
/// At most this many memory buckets per region.
pub const MAX_MEMORY: u64 = 255;
/// The longest window `memory` and `reward: window` count over (they keep a table per step).
pub const MAX_WINDOW: u64 = 1_000_000;
/// At most this many observations of the options level with memory (states times memory
/// values): `policy.json` holds one options entry for each.
pub const MAX_OBSERVATIONS: u64 = 1 << 21;

/// `HSTL016` for a `learn` count above its limit, `HSTL033` for memory or window reward
/// beyond theirs.
pub(crate) fn learning(src: &str, learn: &syntax::Learn, out: &CheckedSpec) -> Vec<Diagnostic> {
    let mut found = Vec::new();
    let limits = [
        ("episodes", MAX_EPISODES),
        ("choices", MAX_CHOICES),
        ("max_steps", MAX_STEPS),
        ("memory", MAX_MEMORY),
    ];
    for p in &learn.params {
        let Some(&(key, limit)) = limits.iter().find(|(k, _)| *k == p.name.name) else { continue };
        if let ParamValue::Number(n) = &p.value
            && n.as_integer().is_some_and(|v| v > limit)
        {
            found.push(
                Diagnostic::new(
                    "HSTL016",
                    n.range.clone(),
                    format!("`{key}` is at most {}, found `{}`", thousands(limit), n.text),
                )
                .with_help(format!("write a whole number up to {}", thousands(limit))),
            );
        }
    }
    let l = &out.learn;
    if !found.is_empty() || (l.memory == 0 && l.reward != Reward::Window) {
        return found;
    }
    let Some(conjuncts) = out.persistent_conjuncts(src) else { return found };
    let at = learn
        .params
        .iter()
        .find(|p| p.name.name == "memory" || p.name.name == "reward")
        .map_or(learn.range.clone(), |p| p.range.clone());
    let task = out.task.as_ref().map_or(at.clone(), |t| t.formula.range.clone());
    if let Some(c) = conjuncts.iter().find(|c| c.steps > MAX_WINDOW) {
        found.push(
            Diagnostic::new(
                "HSTL033",
                at.clone(),
                format!(
                    "memory and `reward: window` count windows of at most {} steps; region `{}` has {}",
                    thousands(MAX_WINDOW),
                    c.name,
                    thousands(c.steps)
                ),
            )
            .with_label(task, "the windows are set here")
            .with_help("shorten the window, or train without `memory` and `reward: window`"),
        );
        return found;
    }
    let Some(states) = out.domain_size() else { return found };
    let values = (l.memory + 1).checked_pow(conjuncts.len() as u32);
    let observations = values.and_then(|v| v.checked_mul(states));
    if l.memory > 0 && observations.is_none_or(|n| n > MAX_OBSERVATIONS) {
        let values = values.map_or("too many".into(), thousands);
        found.push(
            Diagnostic::new(
                "HSTL033",
                at,
                format!(
                    "`memory: {}` over {} regions gives {} states x {values} memory values, more than the {} observations the options level may have",
                    l.memory,
                    conjuncts.len(),
                    thousands(states),
                    thousands(MAX_OBSERVATIONS)
                ),
            )
            .with_help("use fewer memory buckets (the case study uses `memory: 8`), or fewer regions"),
        );
    }
    found
}

/// At most this many numbers in `plan: model`'s tables (the runtime's
/// `hstl_runtime::plan::MAX_PLAN_VALUES`).
pub const MAX_PLAN_VALUES: u64 = 1 << 26;
/// At most this many operations in a sweep of `plan: model`'s value iteration or in filling
/// the options table (the runtime's `hstl_runtime::plan::MAX_PLAN_WORK`).
pub const MAX_PLAN_WORK: u64 = 1 << 31;
/// `plan: model` looks at most this many times the longest window ahead.
const PLAN_WINDOWS_OF_DURATION: u64 = 4;
/// At most this many arrival cells per state (the runtime drops rarer ones).
const PLAN_ARRIVALS: u64 = 1000;

/// Why `plan: model` over `states` states, regions of `cells[j]` states with windows
/// `horizons[j]`, `options` options, `buckets` memory buckets and legs cut off after
/// `max_steps` would pass its limits, or `None`: the runtime's arithmetic
/// (`hstl_runtime::plan::PlanSize::exceeded`), so that `check` refuses what training would.
pub fn plan_exceeded(
    states: u64,
    cells: &[u64],
    horizons: &[u64],
    options: u64,
    buckets: u64,
    max_steps: u64,
) -> Option<String> {
    let longest = horizons.iter().copied().max().unwrap_or(1);
    let max_duration = max_steps.min(PLAN_WINDOWS_OF_DURATION.saturating_mul(longest)).max(1);
    let total = cells.iter().try_fold(0u64, |a, &c| a.checked_add(c));
    let grid = |skip: usize| -> Option<u64> {
        (0..horizons.len())
            .filter(|&j| j != skip)
            .try_fold(1u64, |acc, j| acc.checked_mul(horizons[j].checked_add(1)?))
    };
    let sizes = [
        states.checked_mul(max_duration + 1).and_then(|v| v.checked_mul(options)),
        total.and_then(|t| states.checked_mul(t)),
        total.and_then(|t| t.checked_mul(grid(usize::MAX)?)),
    ];
    if sizes.iter().any(|v| v.is_none_or(|v| v > MAX_PLAN_VALUES)) {
        return Some(format!(
            "`plan: model` over {} states and {} regions with windows of up to {} steps needs more than {} planned values",
            thousands(states),
            horizons.len(),
            thousands(longest),
            thousands(MAX_PLAN_VALUES)
        ));
    }
    let widest = cells.iter().copied().max().unwrap_or(0).min(PLAN_ARRIVALS);
    let arrivals = (0..horizons.len()).filter_map(grid).max();
    let values =
        u32::try_from(horizons.len()).ok().and_then(|k| buckets.checked_add(1)?.checked_pow(k));
    let work = [
        total.and_then(|t| t.checked_mul(options)?.checked_mul(widest)?.checked_mul(arrivals?)),
        arrivals
            .and_then(|a| a.checked_mul(widest)?.checked_add(values?))
            .and_then(|v| v.checked_mul(states)?.checked_mul(options)),
    ];
    if work.iter().any(|v| v.is_none_or(|v| v > MAX_PLAN_WORK)) {
        return Some(format!(
            "`plan: model` over {} states and regions of up to {} states with windows of up to {} steps needs more than {} operations per sweep",
            thousands(states),
            thousands(widest),
            thousands(longest),
            thousands(MAX_PLAN_WORK)
        ));
    }
    None
}

/// The work the preset allows `plan: model` (a fraction of a second): about 30 sweeps of
/// value iteration and one fill of the options table, counted as [`plan_time`] does.
pub const PRESET_PLAN_WORK: u64 = 1 << 28;

/// The operations `plan: model` takes, roughly: 30 sweeps of value iteration and the fill
/// of the options table, saturating (the sizes as for [`plan_exceeded`]).
pub fn plan_time(states: u64, cells: &[u64], horizons: &[u64], options: u64, buckets: u64) -> u64 {
    let total = cells.iter().fold(0u64, |a, &c| a.saturating_add(c));
    let widest = cells.iter().copied().max().unwrap_or(0).min(PLAN_ARRIVALS);
    let grid = |skip: usize| -> u64 {
        (0..horizons.len())
            .filter(|&j| j != skip)
            .fold(1u64, |acc, j| acc.saturating_mul(horizons[j].saturating_add(1)))
    };
    let arrivals = (0..horizons.len()).map(grid).max().unwrap_or(u64::MAX);
    let values = buckets.saturating_add(1).saturating_pow(horizons.len() as u32);
    let sweep = total.saturating_mul(options).saturating_mul(widest).saturating_mul(arrivals);
    let fill = arrivals
        .saturating_mul(widest)
        .saturating_add(values)
        .saturating_mul(states)
        .saturating_mul(options);
    sweep.saturating_mul(30).saturating_add(fill)
}
