//! The memory model of the tabular learner, `policy.json` and its evaluation ([`cost`]),
//! counted from the runtime's own layouts, and the sizes a checked spec gives it
//! ([`spec_sizes`]).

use crate::checked::{CheckedSpec, Reward};

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
pub(super) fn goals_at_most(out: &CheckedSpec) -> u64 {
    (goal_candidates(out).len() as u64).min(MAX_GOALS)
}

/// The top-level conjuncts of the task (or of the `let` it names) that may be goals: all
/// but state formulas and `always`.
pub(super) fn goal_candidates(out: &CheckedSpec) -> Vec<&crate::checked::CFormula> {
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
