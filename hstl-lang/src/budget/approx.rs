//! The approximate learner's sizes: its weights ([`approx_weights`]), its memory model in
//! the terms of [`cost`](super::cost::cost) ([`approx_cost`]), the sizes a checked continuous spec gives
//! it, and `HSTL084`/`HSTL180` for it.

use super::cost::{Cost, FIXED_BYTES, MEMORY_BUDGET, MEMORY_NOTE, bytes_words, goals_at_most};
use super::tiles::{TileFit, tiling_features};
use crate::checked::{CheckedSpec, Reward};
use crate::diagnostic::Diagnostic;
use crate::wording::thousands;

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
/// the terms of [`cost`](super::cost::cost), every weight counted as non-zero (`policy.json` lists those):
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
pub(super) fn approx_memory(
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
