//! Specs on continuous worlds (plane worlds, `mountain-car`): training with the approximate
//! learner ([`hstl_runtime::approx`]), its `policy.json` (the tiling and the weights), and
//! replaying one: what `hstlc train`, `eval` and `study` do on such a world, shared with the
//! Python package.
//!
//! **`policy.json` of a learned function.** Beside the contract's `spec`, `env`,
//! `state_vars`, `actions` and `options` (and `spec_source`, `seed`), it holds:
//! - `"learner": "tiles"`;
//! - `"tiles"`: `{"tilings", "bins", "lo", "hi", "options_tilings", "options_bins"}`, the
//!   flat levels' tiling of the state's box and the options level's coarser one;
//! - `"memory"`: `{"regions", "horizons", "buckets"}` for a persistent task;
//! - `"weights"`: `{"flat": {PRIMITIVE: [[INDEX, BITS], ...]}, "options": [[INDEX, BITS],
//!   ...], "flat_len", "options_len"}`, the non-zero weights only (flat index `a * F + f`
//!   for action `a` and feature `f`; options index `(code * n_options + o) * G + g`), each
//!   value the 16 hex digits of its `f64` bits, as `q_tables` holds Q-values;
//! - `"steps"`, `"choices"`: how far training went.
//!
//! A replay lowers the spec from `spec_source` again, lays the tiling over the world again
//! and refuses a document whose tiling, shapes, indices or values do not fit them.

use std::ops::ControlFlow;

use hstl_lang::CheckedSpec;
use hstl_runtime::approx::{ApproxAgent, ApproxLearner, Weights, WindowSummary};
use hstl_runtime::world::AnyWorld;
use hstl_runtime::{Error, TaskSpec, seeded_rng};
use serde_json::{Value, json};

use crate::Problem;
use crate::evaluate::Runs;
use crate::gym::Described;
use crate::seeds::EVAL_SEED;

/// The most tiles along a variable that a world's step sets (a tile about one step wide).
pub const MAX_STEP_BINS: usize = hstl_lang::budget::MAX_STEP_BINS as usize;

/// Tiles along each variable of `mountain-car` when the spec sets none.
pub const CAR_BINS: usize = hstl_lang::budget::CAR_BINS as usize;

/// Runs `$body` with `$w` bound to the continuous world inside `$world` (an error for a
/// grid).
macro_rules! with_world {
    ($world:expr, $w:ident => $body:expr) => {
        match $world {
            AnyWorld::Plane($w) => $body,
            AnyWorld::MountainCar($w) => $body,
            AnyWorld::Grid(_) => Err(grid_error()),
        }
    };
}

mod read;
mod replay;

pub use read::MAX_HEADER_VALUES;
pub use replay::{
    AnyReplay, Evaluation, GymReplay, Replay, after_training, evaluate, evaluate_in, greedy_runs,
    replay, replay_text, replay_text_any, run_csv, runs_after_training, task_steps,
};

fn grid_error() -> Error {
    Error::Config("a grid world is learned with tables, not tilings".into())
}

/// Lays the spec's tiling over `world`: where the spec sets no `bins`, a plane's tile is
/// about one step wide (at most [`MAX_STEP_BINS`] along a variable) and `mountain-car`'s
/// variables get [`CAR_BINS`] each.
pub fn fit_tiles(spec: &mut TaskSpec, checked: &CheckedSpec, world: &AnyWorld) {
    let (Some(t), Some(declared)) = (spec.learn.tiles.as_mut(), checked.learn.tiles) else {
        return;
    };
    if declared.bins.is_some() {
        return;
    }
    let Some(fit) = tile_fit(world) else { return };
    for (d, bins) in t.bins.iter_mut().enumerate() {
        let n = fit.bins(t.hi[d] - t.lo[d], *bins as u64);
        *bins = usize::try_from(n).unwrap_or(*bins);
    }
}

pub use crate::world::tile_fit;

/// A trained learned function and what training measured.
#[derive(Clone, Debug)]
pub struct Trained {
    /// The greedy agent (its model and weights).
    pub agent: ApproxAgent,
    /// The summed option rewards of each episode.
    pub curve: Vec<f64>,
    /// Primitive steps taken.
    pub steps: u64,
}

/// Trains `spec` (its tiling fitted, see [`fit_tiles`]) in the continuous `world` from
/// `seed`; `progress` sees each episode and its reward and may stop training.
pub fn train_until(
    spec: &TaskSpec,
    world: &AnyWorld,
    seed: u64,
    progress: impl FnMut(usize, f64) -> ControlFlow<()>,
) -> Result<Trained, Error> {
    with_world!(world, w => train_world_until(spec, w, seed, progress))
}

/// [`train_until`] in any [`World`](hstl_runtime::World) (such as a gymnasium environment
/// stepped through Python); the spec's tiling is used as it is.
pub fn train_world_until<W: hstl_runtime::World>(
    spec: &TaskSpec,
    world: &W,
    seed: u64,
    progress: impl FnMut(usize, f64) -> ControlFlow<()>,
) -> Result<Trained, Error> {
    // The memory model first: nothing over the budget is allocated.
    crate::cost::check_approx(spec, world).map_err(|p| Error::Config(p.message))?;
    let mut learner = ApproxLearner::new(spec, world)?;
    let trained = learner.train_until(&mut seeded_rng(seed), progress);
    let agent = ApproxAgent::new(spec, world, learner.weights().clone())?;
    Ok(Trained { agent, curve: trained.curve, steps: trained.steps })
}

/// [`train_until`] without stopping.
pub fn train(
    spec: &TaskSpec,
    world: &AnyWorld,
    seed: u64,
    mut progress: impl FnMut(usize, f64),
) -> Result<Trained, Error> {
    train_until(spec, world, seed, |e, r| {
        progress(e, r);
        ControlFlow::Continue(())
    })
}

/// `policy.json` of a learned function (see the module docs).
pub fn policy_json(
    spec: &TaskSpec,
    world: &AnyWorld,
    agent: &ApproxAgent,
    source: &str,
    seed: u64,
) -> Result<String, Error> {
    policy_doc(spec, &EnvWords::of_any(world)?, agent, source, seed)
}

/// [`policy_json`] of a learned function trained in any [`World`](hstl_runtime::World),
/// such as a [`Described`] gymnasium environment: `env` holds its name and parameters.
pub fn policy_json_in<W: hstl_runtime::World>(
    spec: &TaskSpec,
    world: &W,
    agent: &ApproxAgent,
    source: &str,
    seed: u64,
) -> Result<String, Error> {
    policy_doc(spec, &EnvWords::of(world), agent, source, seed)
}

fn policy_doc(
    spec: &TaskSpec,
    env: &EnvWords,
    agent: &ApproxAgent,
    source: &str,
    seed: u64,
) -> Result<String, Error> {
    let w = &agent.weights;
    let sparse = |v: &[f64]| -> Vec<Value> {
        // Each weight as the 16 hex digits of its bits, as `q_tables` holds Q-values, so
        // that the document loads back to the same bits (`-0.0` included).
        v.iter()
            .enumerate()
            .filter(|(_, x)| x.to_bits() != 0)
            .map(|(i, x)| json!([i, format!("{:016x}", x.to_bits())]))
            .collect()
    };
    let flat: serde_json::Map<String, Value> = spec
        .primitives
        .iter()
        .zip(&w.flat)
        .map(|(p, v)| (p.name.clone(), Value::Array(sparse(v))))
        .collect();
    let mut doc = header(spec, env, &agent.model)?;
    doc.insert(
        "weights".into(),
        json!({
            "flat_len": w.flat.first().map_or(0, Vec::len),
            "options_len": w.options.len(),
            "flat": flat,
            "options": sparse(&w.options),
        }),
    );
    doc.insert("steps".into(), json!(w.steps));
    doc.insert("choices".into(), json!(w.choices));
    doc.insert("spec_source".into(), json!(source));
    doc.insert("seed".into(), json!(seed));
    // The digest of the weights as the readers will see them, from the weights themselves.
    let nonzero = read::nonzero;
    let checksum = read::digest(&doc, |d| {
        let lens = (Some(w.flat.first().map_or(0, Vec::len) as u64), Some(w.options.len() as u64));
        let flat = spec.primitives.iter().zip(&w.flat).map(|(p, v)| (p.name.as_str(), nonzero(v)));
        read::digest_weights(d, lens, Some(flat.collect()), Some(nonzero(&w.options)));
    });
    doc.insert("checksum".into(), json!(checksum));
    serde_json::to_string_pretty(&Value::Object(doc)).map_err(|e| Error::Config(e.to_string()))
}

/// How `policy.json` names an environment: its name, parameters and actions.
struct EnvWords {
    name: String,
    params: Value,
    actions: Vec<String>,
}

impl EnvWords {
    fn of<W: hstl_runtime::World>(w: &W) -> EnvWords {
        EnvWords { name: w.name().to_string(), params: w.params(), actions: w.actions() }
    }

    fn of_any(world: &AnyWorld) -> Result<EnvWords, Error> {
        with_world!(world, w => Ok(EnvWords::of(w)))
    }
}

/// The entries of a learned function's `policy.json` that its spec, world and model
/// determine: everything but the weights, the counts of training and the source. A replay
/// requires each of them as written.
fn header(
    spec: &TaskSpec,
    env: &EnvWords,
    m: &hstl_runtime::approx::Model,
) -> Result<serde_json::Map<String, Value>, Error> {
    let actions = &env.actions;
    let options: Vec<Value> = spec
        .options
        .iter()
        .map(|o| {
            let seq: Vec<&str> =
                o.sequence.iter().map(|&p| spec.primitives[p].name.as_str()).collect();
            json!({"name": o.name, "sequence": seq})
        })
        .collect();
    let mut doc = serde_json::Map::new();
    doc.insert("spec".into(), json!(spec.name));
    doc.insert("env".into(), json!({"name": env.name, "params": env.params}));
    doc.insert("state_vars".into(), json!(m.vars));
    doc.insert("actions".into(), json!(actions));
    doc.insert("options".into(), json!(options));
    doc.insert("learner".into(), json!("tiles"));
    doc.insert(
        "tiles".into(),
        json!({
            "tilings": m.flat_coder.tilings(),
            "bins": m.flat_coder.bins(),
            "lo": m.flat_coder.lo(),
            "hi": m.flat_coder.hi(),
            "options_tilings": m.options_coder.tilings(),
            "options_bins": m.options_coder.bins(),
        }),
    );
    if m.is_persistent() {
        let regions: Vec<&str> = spec.regions.iter().map(|r| r.name.as_str()).collect();
        let horizons: Vec<usize> = m.horizons().collect();
        doc.insert(
            "memory".into(),
            json!({"regions": regions, "horizons": horizons, "buckets": m.buckets}),
        );
    }
    if spec.learn.switch == hstl_runtime::Switch::Step {
        doc.insert("switch".into(), json!("step"));
    }
    Ok(doc)
}

/// Whether a `policy.json` (already parsed) holds a learned function.
pub fn is_learned_function(doc: &Value) -> bool {
    doc.get("learner").and_then(Value::as_str) == Some("tiles")
}

/// [`is_learned_function`] of a `policy.json`'s text, read in one pass that keeps nothing
/// but the top-level `learner` entry: a tabular policy is then parsed once, by its own
/// typed reader, not also as a generic document (16 bytes of memory per byte of text). A
/// document that says `"learner": "tiles"` before it breaks off is one too, so that its
/// error is the learned function's reader's (where it breaks off), not the tables'.
pub fn is_learned_function_text(text: &str) -> bool {
    use serde::de::{Deserializer, IgnoredAny, MapAccess, Visitor};
    struct Learner<'a>(&'a std::cell::Cell<bool>);
    impl<'de> Visitor<'de> for Learner<'_> {
        type Value = ();
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("a JSON object")
        }
        fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
            while let Some(key) = map.next_key::<std::borrow::Cow<'de, str>>()? {
                if key == "learner" {
                    let tiles =
                        map.next_value::<std::borrow::Cow<'de, str>>().is_ok_and(|v| v == "tiles");
                    self.0.set(tiles);
                    if tiles {
                        return Ok(());
                    }
                } else {
                    map.next_value::<IgnoredAny>()?;
                }
            }
            Ok(())
        }
    }
    let tiles = std::cell::Cell::new(false);
    let mut de = serde_json::Deserializer::from_str(text);
    let _ = de.deserialize_map(Learner(&tiles));
    tiles.get()
}

pub use crate::outfile::number;
