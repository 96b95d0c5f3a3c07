//! The memory model at run time: [`hstl_lang::budget::cost`] over the sizes of a spec in
//! the world it runs in (its states counted, not its domain), so that `train`, `study` and
//! the Python package refuse what would not fit the budget before the learner allocates,
//! whatever world or environment they were given, and `study` runs only as many training
//! threads as fit in it.

use hstl_lang::budget::{self, ApproxSizes, Cost, MAX_WEIGHTS, MEMORY_BUDGET, Sizes, bytes_words};
use hstl_runtime::{Env, Error, TaskSpec, World};

use crate::Problem;

/// The sizes of `spec`'s tabular learner in `env`.
pub fn sizes<E: Env>(spec: &TaskSpec, env: &E) -> Sizes {
    let states = env.num_states() as u64;
    let counted = spec.learn.memory > 0 || spec.learn.reward == hstl_runtime::RewardKind::Window;
    let regions = if counted { spec.regions.len() as u64 } else { 0 };
    let values = u32::try_from(regions)
        .ok()
        .and_then(|k| (spec.learn.memory as u64 + 1).checked_pow(k))
        .unwrap_or(u64::MAX);
    // The longest state as written: each value's digits from the largest magnitude.
    let mut widest = vec![1u64; spec.state_vars.len()];
    let mut row = Vec::new();
    let vars = env.state_vars();
    for s in 0..env.num_states() {
        let Some(state) = env.state(s) else { continue };
        env.valuation(&state, &mut row);
        for (w, v) in widest.iter_mut().zip(&row) {
            *w = (*w).max(format!("{v}").len() as u64);
        }
    }
    let state_text = 2 + vars.iter().zip(&widest).map(|(n, w)| n.len() as u64 + 6 + w).sum::<u64>();
    let names = spec
        .primitives
        .iter()
        .map(|p| p.name.len())
        .chain(spec.options.iter().map(|o| o.name.len()));
    let actions = env.actions();
    let name_text = names.chain(actions.iter().map(String::len)).max().unwrap_or(0).max(5) as u64;
    // The goals the options level of a task that is not persistent tracks (the learner's
    // own count).
    let goals = if spec.regions.is_empty() {
        hstl_runtime::progress::Progress::of_task(&spec.task).map_or(0, |p| p.goals() as u64)
    } else {
        0
    };
    // `plan: model` on a reach task: the latest deadline its legs are planned over.
    let form = hstl_runtime::reach_avoid::reach_avoid_form(&spec.task);
    let plan_horizon = match (spec.learn.plan, form) {
        (hstl_runtime::Plan::Model, Some(f)) if spec.regions.is_empty() => {
            let last = f.also.iter().map(|&(_, t)| t).fold(f.reach_by, usize::max);
            last.max(1) as u64
        }
        _ => 0,
    };
    let legs = spec.options.iter().map(|o| o.sequence.len() as u64).sum();
    let windows = if spec.regions.is_empty() {
        0
    } else {
        spec.regions.iter().fold(1u64, |a, r| a.saturating_mul(r.horizon.max(1) as u64))
    };
    Sizes {
        states,
        vars: vars.len() as u64,
        actions: actions.len() as u64,
        primitives: spec.primitives.len() as u64,
        options: spec.options.len() as u64,
        regions,
        values,
        goals,
        plan_horizon,
        legs,
        state_text,
        name_text,
        windows,
    }
}

/// The cost of training `spec` in `env`, or why it would not fit the memory budget: the
/// figure, the budget and how to make it smaller.
pub fn check<E: Env>(spec: &TaskSpec, env: &E) -> Result<Cost, Problem> {
    let s = sizes(spec, env);
    let cost = budget::cost(&s);
    let (peak, run) = cost.peak();
    if peak <= MEMORY_BUDGET {
        return Ok(cost);
    }
    Err(Problem::new(
        format!(
            "`{run}` of `{}` on {} would take about {} ({} states x {} memory values{} x {} options, and `policy.json` of {}), more than the {} memory budget",
            spec.name,
            env.name(),
            bytes_words(peak),
            s.states,
            s.values,
            budget::goal_words(&s),
            s.options,
            bytes_words(cost.policy_bytes),
            bytes_words(MEMORY_BUDGET)
        ),
        "use fewer memory values (a smaller `memory: B`, or fewer regions), a smaller world, or fewer options".to_string(),
    ))
}

/// How many of `threads` training threads fit in the memory budget at once, each taking
/// `cost.train`, beside `reserved` bytes (the policies a study keeps); at least one.
pub fn threads_within_budget(cost: &Cost, reserved: u64, threads: usize) -> usize {
    let fit = MEMORY_BUDGET.saturating_sub(reserved) / cost.train.max(1);
    threads.min(usize::try_from(fit).unwrap_or(usize::MAX)).max(1)
}

/// The sizes of `spec`'s approximate learner in `world` (its tiling as given: fitted to
/// the world first, see [`crate::continuous::fit_tiles`]), read off the runtime's own
/// codings.
pub fn approx_sizes<W: World>(spec: &TaskSpec, world: &W) -> Result<ApproxSizes, Error> {
    let s = hstl_runtime::approx::Model::shape_of(spec, world)?;
    Ok(ApproxSizes {
        flat_features: s.flat_features as u64,
        options_features: s.options_features as u64,
        actions: s.actions as u64,
        primitives: s.primitives as u64,
        options: s.options as u64,
        codes: s.codes as u64,
    })
}

/// The cost of training `spec` with the approximate learner in `world`, or why it would not
/// fit: more than [`MAX_WEIGHTS`] weights or the memory budget, by the count `check`
/// reports ([`budget::approx_weights`]).
pub fn check_approx<W: World>(spec: &TaskSpec, world: &W) -> Result<Cost, Problem> {
    let s = approx_sizes(spec, world).map_err(|e| Problem::new(e.to_string(), None))?;
    let cost = budget::approx_cost(&s);
    let weights = budget::approx_weights(&s);
    let (peak, run) = cost.peak();
    if peak <= MEMORY_BUDGET && weights <= MAX_WEIGHTS {
        return Ok(cost);
    }
    let over = if weights > MAX_WEIGHTS {
        format!("more than the {} weights the learner may hold", budget::thousands(MAX_WEIGHTS))
    } else {
        format!(
            "`{run}` would take about {}, more than the {} memory budget",
            bytes_words(peak),
            bytes_words(MEMORY_BUDGET)
        )
    };
    Err(Problem::new(
        format!(
            "the learned function of `{}` on {} has {}: {over}",
            spec.name,
            world.name(),
            budget::approx_words(&s)
        ),
        "use fewer memory values (a smaller `memory: B`, or fewer regions), fewer tiles or tilings (`tiles: { tilings: N, bins: N }`), or fewer options".to_string(),
    ))
}
