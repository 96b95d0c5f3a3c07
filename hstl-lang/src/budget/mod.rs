//! The sizes a spec's `learn` item controls, held to stated limits before anything is
//! trained, so that the learner, `policy.json` and the evaluation never allocate what a
//! spec asks for unchecked. The limits are documented in LANGUAGE.md ("Limits"); the CLI
//! holds its flags (`--episodes`) to the same ones.

use crate::checked::{CheckedSpec, Reward};
use crate::diagnostic::Diagnostic;
use crate::syntax::{self, ParamValue};
pub use crate::wording::thousands;

mod approx;
mod cost;
mod goal_text;
mod plan;
pub mod tiles;

pub use approx::*;
pub use cost::*;
pub use goal_text::MAX_GOAL_TEXT;
pub(crate) use goal_text::goal_text;
pub use plan::*;
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
