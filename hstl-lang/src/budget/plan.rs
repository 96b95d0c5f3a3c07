//! The budget of `plan: model` (the runtime's `hstl_runtime::plan::PlanSize`): the numbers
//! in its tables and the work of a sweep, counted as the runtime counts them, so that `check`
//! refuses what training would, and the work the preset allows it.

use crate::wording::thousands;

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
