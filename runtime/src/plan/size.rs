//! The sizes that bound the planner's memory and time, checked before training starts.

/// At most this many numbers in the planner's tables (durations, arrival cells, values).
pub const MAX_PLAN_VALUES: usize = 1 << 26;
/// At most this many operations in a sweep of value iteration, or in filling the table.
pub const MAX_PLAN_WORK: usize = 1 << 31;
/// Arrival cells less likely than this (given an arrival) are left out of a leg's model.
pub(super) const RARE_ARRIVAL: f64 = 1e-3;
/// Durations of a leg are modelled up to this many times the longest window.
pub(super) const WINDOWS_OF_DURATION: usize = 4;

/// The sizes that bound the planner's memory and time: the front end holds a spec to the
/// same limits (`hstl_lang::budget::plan_exceeded`, one arithmetic: `tests/limits.rs`).
#[derive(Clone, Copy, Debug)]
pub struct PlanSize<'a> {
    /// The environment's states.
    pub states: usize,
    /// The states in each region of the task.
    pub cells: &'a [usize],
    /// Each region's window `N_j`.
    pub horizons: &'a [usize],
    /// The options, one per region.
    pub options: usize,
    /// The memory buckets `B`.
    pub buckets: usize,
    /// `max_steps`, where a leg is cut off.
    pub max_steps: usize,
}

impl PlanSize<'_> {
    /// Why planning would pass [`MAX_PLAN_VALUES`] or [`MAX_PLAN_WORK`], or `None`.
    pub fn exceeded(&self) -> Option<String> {
        let PlanSize { states, cells, horizons, options, buckets, max_steps } = *self;
        let longest = horizons.iter().copied().max().unwrap_or(1);
        let max_duration = max_steps.min(WINDOWS_OF_DURATION.saturating_mul(longest)).max(1);
        let total = cells.iter().try_fold(0usize, |a, &c| a.checked_add(c));
        let grid = |skip: usize| -> Option<usize> {
            (0..horizons.len())
                .filter(|&j| j != skip)
                .try_fold(1usize, |acc, j| acc.checked_mul(horizons[j].checked_add(1)?))
        };
        let sizes = [
            states.checked_mul(max_duration + 1).and_then(|v| v.checked_mul(options)),
            total.and_then(|t| states.checked_mul(t)),
            total.and_then(|t| t.checked_mul(grid(usize::MAX)?)),
        ];
        if sizes.iter().any(|v| v.is_none_or(|v| v > MAX_PLAN_VALUES)) {
            return Some(format!(
                "over {states} states, {} regions with windows of up to {longest} steps needs \
                 more than {MAX_PLAN_VALUES} planned values; use fewer regions or shorter \
                 windows, or `plan: off`",
                horizons.len()
            ));
        }
        // The work of a value iteration sweep and of filling the options table: every
        // state a leg starts from, times the cells it may arrive in (at most 1 /
        // RARE_ARRIVAL of them once the rare ones are dropped), times a grid of counters.
        let widest = cells.iter().copied().max().unwrap_or(0).min((1.0 / RARE_ARRIVAL) as usize);
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
                "over {states} states and regions of up to {widest} cells with windows of up \
                 to {longest} steps needs more than {MAX_PLAN_WORK} operations per sweep; use \
                 smaller regions, fewer regions or shorter windows, or `plan: off`"
            ));
        }
        None
    }
}
