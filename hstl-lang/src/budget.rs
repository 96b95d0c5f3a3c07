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
