//! The sizes a spec's `learn` item controls, held to stated limits before anything is
//! trained, so that the learner, `policy.json` and the evaluation never allocate what a
//! spec asks for unchecked. The limits are documented in LANGUAGE.md ("Limits"); the CLI
//! holds its flags (`--episodes`) to the same ones.

use crate::checked::{CheckedSpec, Reward};
use crate::diagnostic::Diagnostic;
use crate::syntax::{self, ParamValue};
pub use crate::wording::thousands;

pub mod tiles;

pub use tiles::{CAR_BINS, MAX_STEP_BINS, TileFit, tiling_features};

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

/// `HSTL016` for a `learn` count above its limit, `HSTL033` for a window of memory or the
/// window reward beyond theirs.
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

/// The memory a run of what `check` accepts stays within, at the defaults: 2 GiB. `train`,
/// `eval`, `study` (its training threads counted) and `hstl.Policy.load` each fit in it.
pub const MEMORY_BUDGET: u64 = 2 << 30;
/// `check` reports the estimate (`HSTL180`) above this: 512 MiB.
pub const MEMORY_NOTE: u64 = 512 << 20;
/// What every run takes beside its tables and documents, at most: the program, the spec,
/// the pictures, the learning curve and the evaluation's runs at the defaults.
pub const FIXED_BYTES: u64 = 64 << 20;
/// The exact optimum's tables, at most, which `eval` of a persistent task computes (the
/// runtime's solver refuses more before allocating: 64 bytes per state of its
/// `max_states`, 2^24).
pub const OPTIMUM_BYTES: u64 = 1 << 30;
/// The grid worlds' action count (`Up`, `Down`, `Left`, `Right`).
pub const GRID_ACTIONS: u64 = 4;

/// At most this many goals are tracked by the options level of a task that is not
/// persistent (the runtime's `hstl_runtime::progress::MAX_GOALS`).
pub const MAX_GOALS: u64 = 4;

/// `plan: model` on a reach task judges the avoidance at most this many steps past the
/// latest deadline (the runtime's `plan_reach::TAIL_STEPS`).
pub const PLAN_TAIL_STEPS: u64 = 400;
/// The reach planner's limits (the runtime's `plan_reach::MAX_VALUES`, the candidates it
/// keeps, `plan_reach::CANDIDATES`, and `choices::MAX_WORK`): past them it keeps the
/// learned values.
const PLAN_REACH_VALUES: u64 = 1 << 24;
const PLAN_REACH_CANDIDATES: u64 = 24;
const PLAN_REACH_WORK: u64 = 1 << 26;
/// At most this many next states per state and action in a grid world's model (a move, and
/// the slips to the other neighbours or staying).
const GRID_SUCCESSORS: u64 = 5;

/// The sizes the tabular learner's memory grows with: what [`cost`] reads.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Sizes {
    /// States of the world (or of the spec's domain, which bounds them).
    pub states: u64,
    /// State variables.
    pub vars: u64,
    /// Actions of the world.
    pub actions: u64,
    /// Primitive options.
    pub primitives: u64,
    /// Options of the options set.
    pub options: u64,
    /// Regions the memory counts (0 without memory).
    pub regions: u64,
    /// Memory values `(B + 1)^k` (1 without memory).
    pub values: u64,
    /// Goals the options level of a task that is not persistent tracks, at most
    /// [`MAX_GOALS`] (0 for a persistent task, or one without goals): its table and its
    /// `options_policy` hold `2^goals` rows per observation.
    pub goals: u64,
    /// `plan: model` on a reach task: the latest goal's deadline `T` (the steps its legs
    /// are planned over), 0 when there is no such planning.
    pub plan_horizon: u64,
    /// Legs of all options together (what a planned hierarchy runs).
    pub legs: u64,
    /// Bytes of the longest state as `policy.json` writes it (`{"x": 12, "y": 14}`).
    pub state_text: u64,
    /// Bytes of the longest option or action name.
    pub name_text: u64,
    /// The product of the task's windows over its regions, 0 for a task that is not
    /// persistent (whose `eval` computes no exact optimum).
    pub windows: u64,
}

/// What a spec's runs take, in bytes, by [`cost`]'s model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Cost {
    /// `policy.json` as written.
    pub policy_bytes: u64,
    /// The `policy.json` document in memory, as written or as read (the read one's lists
    /// have room to grow: counted twice).
    pub document: u64,
    /// The learner: its per-state tables and Q-tables.
    pub learner: u64,
    /// A greedy agent: its tables over state indices.
    pub agent: u64,
    /// `train`: the learner (and the reach planner of `plan: model`), its agent, the
    /// document, its text as it is written, and [`FIXED_BYTES`].
    pub train: u64,
    /// `hstl.Policy.load` (and `eval` before it evaluates): the text, the document read,
    /// the learner that checks it and two agents, and [`FIXED_BYTES`].
    pub load: u64,
    /// `eval`: [`Cost::load`] and the exact optimum's tables.
    pub evaluate: u64,
}

impl Cost {
    /// The largest of the runs, and its name (`train`, `eval`): what must fit the budget.
    pub fn peak(&self) -> (u64, &'static str) {
        if self.evaluate > self.train { (self.evaluate, "eval") } else { (self.train, "train") }
    }

    /// The largest of what the spec's own sizes make grow (`train` and `load`, not the
    /// optimum's fixed limit), and its name: what `HSTL180` notes.
    pub fn own(&self) -> (u64, &'static str) {
        if self.load > self.train { (self.load, "eval") } else { (self.train, "train") }
    }
}

/// The bytes an allocation of `n` bytes takes from the allocator, at most (8 bytes of
/// header, rounded up to 16, at least 32).
const fn allocation(n: u64) -> u64 {
    if n == 0 {
        return 0;
    }
    let padded = (n + 8).div_ceil(16) * 16;
    if padded < 32 { 32 } else { padded }
}

/// The memory model of the tabular learner, `policy.json` and its evaluation, counted from
/// the runtime's own layouts (saturating): `hstl/tests/cost.rs` holds the figures against
/// what the runs allocate.
pub fn cost(s: &Sizes) -> Cost {
    let m = |a: u64, b: u64| a.saturating_mul(b);
    let add = |parts: &[u64]| parts.iter().fold(0u64, |a, &b| a.saturating_add(b));
    let (n, p, o) = (s.states, s.primitives, s.options);
    let goals = s.goals.min(MAX_GOALS);
    // The options level observes the state, the memory's value and the goals met.
    let observations = m(m(n, s.values), 1 << goals);
    let with_memory = s.regions > 0;
    // A state: its shared names' handle and its values' box, and their allocation.
    let state = 32 + allocation(8 * s.vars);
    // An entry: the state, the buckets, the goals met, the choice's name, and their
    // allocations (the goals met grow as pushed: room for 4 at least).
    let entry = state + 72 + allocation(s.name_text);
    let options_entry = add(&[
        entry,
        if with_memory { allocation(8 * s.regions) } else { 0 },
        if goals > 0 { allocation(8 * goals.max(4)) } else { 0 },
    ]);
    // As written: indent, keys and punctuation, the state, the buckets, the goals met,
    // the name.
    let text_entry = 36 + s.state_text + s.name_text;
    let text_options_entry = add(&[
        text_entry,
        if with_memory { 14 + 4 * s.regions } else { 0 },
        if goals > 0 { 17 + 3 * goals } else { 0 },
    ]);
    let text_value = 20;
    let q_values = add(&[m(m(n, s.actions), p), m(observations, o)]);
    let options_entries = if with_memory || goals > 0 { observations } else { n };
    // Every state's valuation, which the goals are read from: the learner's and each
    // agent's copy.
    let goal_rows = if goals > 0 { m(n, 8 * s.vars) } else { 0 };
    let policy_bytes = add(&[
        m(options_entries, text_options_entry),
        // Flat policies, termination sets and the memory's region states: a state each.
        m(m(n, p), text_entry),
        m(m(n, p + s.regions), s.state_text + 2),
        m(q_values, text_value),
    ]);
    let document = add(&[
        m(options_entries, options_entry),
        m(m(n, p), entry),
        // Termination sets, the memory's region states, and the states listed once.
        m(m(n, p + s.regions + 1), state),
        m(q_values, 8),
    ]);
    // `plan: model` on a reach task: the model's counts and moves, each leg's tables over
    // the steps to the deadline and its candidates, and the hierarchy's passes (how often
    // each decision point is reached at each step, and its running legs).
    let plan = if s.plan_horizon == 0 {
        0
    } else {
        let (sa, codes) = (m(n, s.actions), 1u64 << goals);
        let steps = s.plan_horizon.saturating_add(PLAN_TAIL_STEPS + 1);
        let points = m(n, codes);
        let successors = m(sa, 2 * (24 + allocation(16 * GRID_SUCCESSORS)));
        add(&[
            successors,
            m(m(s.plan_horizon.max(1), sa).min(PLAN_REACH_VALUES), 8),
            m(m(sa, PLAN_REACH_CANDIDATES), 8),
            m(m(steps, points).min(PLAN_REACH_WORK), 8),
            m(m(points, 4 * s.legs.max(1) + o + 2), 8),
            m(m(points, o), 16),
        ])
    };
    let learner = add(&[
        // Valuations, reach, termination and avoided states, available options.
        m(n, 8 * s.vars + 10 * p + 24 + allocation(8 * o) + 16),
        m(m(m(n, s.actions), p), 8),
        m(m(observations, o), 8),
        // The memory's region states.
        m(n, s.regions),
        goal_rows,
    ]);
    let agent = add(&[m(observations, 8), m(n, 9 * p), m(m(observations, o), 8), goal_rows]);
    let text = policy_bytes;
    // The text is written into a buffer that doubles as it grows: at most twice the text,
    // and the half it moves out of while it grows.
    let train = add(&[learner, plan, agent, document, m(text, 3), FIXED_BYTES]);
    // With goals, the replay reads the valuations once more to find them.
    let load = add(&[text, m(document, 2), learner, m(agent, 2), goal_rows, FIXED_BYTES]);
    // The solver's own limit: its tables are refused past it, before they are allocated.
    let optimum = if s.windows == 0 { 0 } else { OPTIMUM_BYTES };
    Cost {
        policy_bytes,
        document,
        learner,
        agent,
        train,
        load,
        evaluate: load.saturating_add(optimum),
    }
}

/// ` x 4 sets of goals met` for a task whose options level tracks 2 goals; empty without
/// goals.
pub fn goal_words(s: &Sizes) -> String {
    match s.goals.min(MAX_GOALS) {
        0 => String::new(),
        g => format!(" x {} sets of goals met", 1u64 << g),
    }
}

/// `bytes` in the largest unit that keeps it above 1: `1.6 GiB`, `425 MiB`.
pub fn bytes_words(bytes: u64) -> String {
    let units = [(1u64 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")];
    for (unit, name) in units {
        if bytes >= unit {
            let v = bytes as f64 / unit as f64;
            return if v < 10.0 { format!("{v:.1} {name}") } else { format!("{v:.0} {name}") };
        }
    }
    format!("{bytes} bytes")
}

/// The sizes of a checked spec's tabular learner, counted from its declared domain (which
/// bounds a world's states), or `None` for a spec the tabular learner does not run (no
/// options, or a state that is not all `int`).
pub fn spec_sizes(src: &str, out: &CheckedSpec) -> Option<Sizes> {
    use crate::checked::Domain;
    if out.primitives.is_empty() || out.is_continuous() {
        return None;
    }
    let states = out.domain_size()?;
    let digits = |v: i64| v.to_string().len() as u64;
    let mut state_text = 2u64;
    for v in &out.state_vars {
        let Domain::Int { lo, hi } = v.domain else { return None };
        state_text += v.name.len() as u64 + 6 + digits(lo).max(digits(hi));
    }
    let conjuncts = out.persistent_conjuncts(src);
    let counted = out.learn.memory > 0 || out.learn.reward == Reward::Window;
    let regions = if counted { conjuncts.as_ref().map_or(0, Vec::len) as u64 } else { 0 };
    let values = if regions > 0 {
        (out.learn.memory + 1).checked_pow(u32::try_from(regions).ok()?).unwrap_or(u64::MAX)
    } else {
        1
    };
    let names =
        out.primitives.iter().map(|p| p.name.len()).chain(out.options.iter().map(|o| o.name.len()));
    let name_text = names.max().unwrap_or(0).max(5) as u64;
    let goals = if conjuncts.is_some() { 0 } else { goals_at_most(out) };
    let plan_horizon =
        if out.learn.plan == crate::checked::Plan::Model && crate::preset::is_reach_task(out) {
            latest_deadline(out)
        } else {
            0
        };
    let legs = out.options.iter().map(|o| o.sequence.len() as u64).sum();
    let windows =
        conjuncts.map_or(0, |c| c.iter().fold(1u64, |a, c| a.saturating_mul(c.steps.max(1))));
    Some(Sizes {
        states,
        vars: out.state_vars.len() as u64,
        actions: GRID_ACTIONS,
        primitives: out.primitives.len() as u64,
        options: out.options.len() as u64,
        regions,
        values,
        goals,
        plan_horizon,
        legs,
        state_text,
        name_text,
        windows,
    })
}

/// The latest deadline `T` of the task's `eventually[0..=T]` conjuncts (at least 1).
fn latest_deadline(out: &CheckedSpec) -> u64 {
    use crate::checked::{Bound, CFormulaKind};
    let Some(task) = &out.task else { return 1 };
    let parts = match &task.formula.kind {
        CFormulaKind::And(parts) => parts.as_slice(),
        _ => std::slice::from_ref(&task.formula),
    };
    let ends = parts.iter().filter_map(|p| match &p.kind {
        CFormulaKind::Eventually(iv, _) => match iv.end {
            Bound::Inclusive(t) => Some(t),
            Bound::Exclusive(t) => Some(t.saturating_sub(1)),
            Bound::Unbounded => None,
        },
        _ => None,
    });
    ends.max().unwrap_or(0).max(1)
}

/// At most the goals the runtime finds in the task of a spec that is not persistent (its
/// `hstl_runtime::progress::Progress`): the top-level conjuncts (of the task, or of the
/// `let` it names) other than state formulas and `always`, at most [`MAX_GOALS`]. A goal
/// is monotone with an `eventually`; counting more conjuncts only makes the model larger.
fn goals_at_most(out: &CheckedSpec) -> u64 {
    (goal_candidates(out).len() as u64).min(MAX_GOALS)
}

/// The top-level conjuncts of the task (or of the `let` it names) that may be goals: all
/// but state formulas and `always`.
fn goal_candidates(out: &CheckedSpec) -> Vec<&crate::checked::CFormula> {
    use crate::checked::{CFormula, CFormulaKind};
    fn through_lets<'a>(out: &'a CheckedSpec, mut f: &'a CFormula) -> &'a CFormula {
        // A chain of lets is at most as long as the lets (a cycle was an error).
        for _ in 0..=out.lets.len() {
            match &f.kind {
                CFormulaKind::Let(i) => match out.lets.get(*i) {
                    Some(l) => f = &l.formula,
                    None => break,
                },
                _ => break,
            }
        }
        f
    }
    let Some(task) = &out.task else { return Vec::new() };
    let root = through_lets(out, &task.formula);
    let parts: Vec<&CFormula> = match &root.kind {
        CFormulaKind::And(parts) => parts.iter().collect(),
        _ => vec![root],
    };
    parts
        .into_iter()
        .filter(|p| {
            !out.is_state_formula(p)
                && !matches!(through_lets(out, p).kind, CFormulaKind::Always(..))
        })
        .collect()
}

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

/// `HSTL084` when the runs of a spec would take more than [`MEMORY_BUDGET`] by [`cost`]'s
/// model, `HSTL180` when more than [`MEMORY_NOTE`]; at the `learn` item's `memory` (or the
/// item, or the spec's name).
pub(crate) fn memory(
    src: &str,
    learn: Option<&syntax::Learn>,
    out: &CheckedSpec,
    world: Option<&crate::world::BoxFacts>,
) -> Option<Diagnostic> {
    let at = learn.map_or(out.name_range.clone(), |l| {
        l.params
            .iter()
            .find(|p| p.name.name == "memory")
            .map_or(l.range.clone(), |p| p.range.clone())
    });
    if out.is_continuous() {
        let sizes =
            approx_spec_sizes(src, out, world.and_then(|w| w.fit), world.map(|w| w.actions))?;
        return approx_memory(&sizes, at, world.map(|w| w.label.as_str()));
    }
    let sizes = spec_sizes(src, out)?;
    let c = cost(&sizes);
    let (peak, run) = c.peak();
    if peak <= MEMORY_BUDGET && c.own().0 <= MEMORY_NOTE {
        return None;
    }
    let what = format!(
        "{} states x {} memory values{} x {} options, and `policy.json` of {}",
        thousands(sizes.states),
        thousands(sizes.values),
        goal_words(&sizes),
        sizes.options,
        bytes_words(c.policy_bytes)
    );
    let figures = format!("train {}, eval {}", bytes_words(c.train), bytes_words(c.evaluate));
    if peak > MEMORY_BUDGET {
        Some(
            Diagnostic::new(
                "HSTL084",
                at,
                format!(
                    "`{run}` of this spec would take about {} ({what}; {figures}), more than the {} memory budget",
                    bytes_words(peak),
                    bytes_words(MEMORY_BUDGET)
                ),
            )
            .with_help("use fewer memory values (a smaller `memory: B`, or fewer regions), a smaller world, or fewer options"),
        )
    } else {
        let (own, run) = c.own();
        Some(
            Diagnostic::new(
                "HSTL180",
                at,
                format!(
                    "`{run}` of this spec will take about {} of the {} memory budget ({what}; {figures})",
                    bytes_words(own),
                    bytes_words(MEMORY_BUDGET)
                ),
            )
            .with_help("fewer memory values, a smaller world or fewer options make it smaller"),
        )
    }
}

/// At most this many weights in the approximate learner (the runtime's
/// `hstl_runtime::approx::MAX_WEIGHTS`), whatever the memory budget says.
pub const MAX_WEIGHTS: u64 = 1 << 25;
/// The actions `check` counts for a continuous spec whose world it does not know (a
/// gymnasium environment given at training): the fewest a world has. `train` counts the
/// world's own.
pub const UNKNOWN_WORLD_ACTIONS: u64 = 2;

/// The sizes the approximate learner's weights grow with: what [`approx_weights`] and
/// [`approx_cost`] read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct ApproxSizes {
    /// Features of the flat levels' tiling (tilings times the slots of one).
    pub flat_features: u64,
    /// Features of the options level's coarser tiling.
    pub options_features: u64,
    /// Actions of the world.
    pub actions: u64,
    /// Primitive options.
    pub primitives: u64,
    /// Options of the options set.
    pub options: u64,
    /// Codes the options level tells apart: memory values `(B + 1)^k` times `2^goals`.
    pub codes: u64,
}

/// The approximate learner's weights: each primitive's per action over the flat tiling,
/// and each option's per code over the options tiling. The one count `check` reports and
/// `train` refuses by (saturating).
pub fn approx_weights(s: &ApproxSizes) -> u64 {
    let flat = s.flat_features.saturating_mul(s.actions).saturating_mul(s.primitives);
    let options = s.options_features.saturating_mul(s.options).saturating_mul(s.codes);
    flat.saturating_add(options)
}

/// Bytes of one weight in the `policy.json` document as it is built before it is written:
/// the pair's value in the list (room for the list to double: 64), its two-element array
/// (80) and the hex digits' string (32).
const WEIGHT_DOCUMENT: u64 = 176;
/// Bytes of one weight as written (pretty-printed over four lines, indented).
const WEIGHT_TEXT: u64 = 72;
/// Bytes of one weight entry as read back (a pair, in a list that may double).
const WEIGHT_READ: u64 = 48;

/// The memory model of the approximate learner, its `policy.json` and its evaluation, in
/// the terms of [`cost`], every weight counted as non-zero (`policy.json` lists those):
/// training holds the learner's weights and the agent's copy, the document and its text as
/// it grows; a replay the text, the entries read and three sets of weights.
/// `hstl/tests/cost.rs` holds the figures against what the runs allocate.
pub fn approx_cost(s: &ApproxSizes) -> Cost {
    let w = approx_weights(s);
    let m = |a: u64, b: u64| a.saturating_mul(b);
    let learner = m(w, 8);
    let agent = m(w, 8);
    let document = m(w, WEIGHT_DOCUMENT);
    let policy_bytes = m(w, WEIGHT_TEXT);
    let train = [learner, agent, document, m(policy_bytes, 3), FIXED_BYTES]
        .iter()
        .fold(0u64, |a, &b| a.saturating_add(b));
    let load = [policy_bytes, m(w, WEIGHT_READ), m(learner, 3), FIXED_BYTES]
        .iter()
        .fold(0u64, |a, &b| a.saturating_add(b));
    Cost { policy_bytes, document, learner, agent, train, load, evaluate: load }
}

/// The sizes of a checked continuous spec's approximate learner, or `None` for a spec the
/// approximate learner does not run (no options, no tiling, an unbounded variable). The
/// tiles along a variable are the spec's `bins`, else what `fit` lays for the world
/// (`None`: the spec's tile box as it is, which is how a gymnasium environment is tiled);
/// the actions are `actions` (`None`: [`UNKNOWN_WORLD_ACTIONS`]).
pub fn approx_spec_sizes(
    src: &str,
    out: &CheckedSpec,
    fit: Option<TileFit>,
    actions: Option<u64>,
) -> Option<ApproxSizes> {
    if out.primitives.is_empty() || !out.is_continuous() {
        return None;
    }
    // A spec with options over a float state is tiled (by default, when it says nothing).
    let tiles = out.learn.tiles.unwrap_or_default();
    let tile_box = out.tile_box_of(tiles)?;
    let bins: Vec<u64> = (0..tile_box.bins.len())
        .map(|d| match (tiles.bins, fit) {
            (None, Some(f)) => f.bins(tile_box.hi[d] - tile_box.lo[d], tile_box.bins[d]),
            _ => tile_box.bins[d],
        })
        .collect();
    // The options level's tiling: half the tiles (at least one) and half the tilings
    // (rounded up), as the runtime's `Model` lays it.
    let coarse: Vec<u64> = bins.iter().map(|b| (b / 2).max(1)).collect();
    let conjuncts = out.persistent_conjuncts(src);
    let counted = out.learn.memory > 0 || out.learn.reward == Reward::Window;
    let regions = if counted { conjuncts.as_ref().map_or(0, Vec::len) as u64 } else { 0 };
    let values = if out.learn.memory > 0 && regions > 0 {
        (out.learn.memory + 1).checked_pow(u32::try_from(regions).ok()?).unwrap_or(u64::MAX)
    } else {
        1
    };
    let goals = if counted { 0 } else { goals_at_most(out) };
    Some(ApproxSizes {
        flat_features: tiling_features(&bins, tile_box.tilings),
        options_features: tiling_features(&coarse, tile_box.tilings.div_ceil(2)),
        actions: actions.unwrap_or(UNKNOWN_WORLD_ACTIONS),
        primitives: out.primitives.len() as u64,
        options: out.options.len() as u64,
        codes: values.saturating_mul(1 << goals),
    })
}

/// `HSTL084` when the approximate learner of a continuous spec would hold more than
/// [`MAX_WEIGHTS`] weights or take more than [`MEMORY_BUDGET`], `HSTL180` when more than
/// [`MEMORY_NOTE`] (see [`memory`]).
fn approx_memory(
    sizes: &ApproxSizes,
    at: std::ops::Range<usize>,
    world: Option<&str>,
) -> Option<Diagnostic> {
    let c = approx_cost(sizes);
    let weights = approx_weights(sizes);
    let (peak, run) = c.peak();
    if peak <= MEMORY_BUDGET && weights <= MAX_WEIGHTS && c.own().0 <= MEMORY_NOTE {
        return None;
    }
    let on = world.map_or(String::new(), |w| format!(" on {w}"));
    let what = approx_words(sizes);
    let figures = format!(
        "train {}, eval {}, `policy.json` up to {}",
        bytes_words(c.train),
        bytes_words(c.evaluate),
        bytes_words(c.policy_bytes)
    );
    let help = "use fewer memory values (a smaller `memory: B`, or fewer regions), fewer tiles or tilings (`tiles: { tilings: N, bins: N }`), or fewer options";
    if weights > MAX_WEIGHTS || peak > MEMORY_BUDGET {
        let over = if weights > MAX_WEIGHTS {
            format!("more than the {} weights the learner may hold", thousands(MAX_WEIGHTS))
        } else {
            format!(
                "`{run}` would take about {}, more than the {} memory budget",
                bytes_words(peak),
                bytes_words(MEMORY_BUDGET)
            )
        };
        Some(
            Diagnostic::new(
                "HSTL084",
                at,
                format!("the learned function of this spec{on} has {what}; {figures}: {over}"),
            )
            .with_help(help),
        )
    } else {
        let (own, run) = c.own();
        Some(
            Diagnostic::new(
                "HSTL180",
                at,
                format!(
                    "`{run}` of this spec{on} will take about {} of the {} memory budget (the learned function has {what}; {figures})",
                    bytes_words(own),
                    bytes_words(MEMORY_BUDGET)
                ),
            )
            .with_help(
                "fewer memory values, fewer tiles or tilings, or fewer options make it smaller",
            ),
        )
    }
}

/// `8,912,896 weights (2 primitives x 2 actions x 131,072 features, and 2 options x 64
/// codes of the memory and goals x 65,536 features)`.
pub fn approx_words(s: &ApproxSizes) -> String {
    format!(
        "{} weights ({} primitives x {} actions x {} features, and {} options x {} codes of the memory and goals x {} features)",
        thousands(approx_weights(s)),
        s.primitives,
        s.actions,
        thousands(s.flat_features),
        s.options,
        thousands(s.codes),
        thousands(s.options_features)
    )
}
