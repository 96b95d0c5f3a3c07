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

/// A `policy.json` of a learned function, checked whole against its spec and world.
#[derive(Clone, Debug)]
pub struct Replay {
    /// The spec it was trained on, lowered again from `spec_source`, its tiling fitted.
    pub spec: TaskSpec,
    /// The world it was trained in.
    pub world: AnyWorld,
    /// The greedy agent the document describes.
    pub agent: ApproxAgent,
    /// The spec file's text.
    pub source: String,
    /// The seed it was trained from, when recorded.
    pub seed: Option<u64>,
}

/// Reads a learned-function `policy.json` (see the module docs); messages are worded as
/// `hstlc eval` prints them, after `FILE: `.
pub fn replay(doc: &Value) -> Result<Replay, Problem> {
    let weights = doc.get("weights").map(SparseWeights::of_value);
    replay_parts(doc, weights)
}

/// [`replay`] of a `policy.json`'s text, read in one pass: the weights (most of a large
/// document) straight into compact `(index, bits)` pairs, the rest as a document, so that
/// memory stays near the text's own size, not the 16 times a generic document takes.
pub fn replay_text(text: &str) -> Result<Replay, Problem> {
    let edited = "the file was edited or damaged: train the policy again with `hstlc train`";
    let mut de = serde_json::Deserializer::from_str(text);
    let (doc, weights) = serde::Deserializer::deserialize_map(&mut de, TopLevel)
        .and_then(|parts| de.end().map(|()| parts))
        .map_err(|e| Problem::new(format!("not a valid policy.json: {e}"), Some(edited.into())))?;
    replay_parts(&doc, weights)
}

/// A learned function's `policy.json` trained in a gymnasium environment (see
/// [`Described`]), checked whole against its spec and the spaces it records.
#[derive(Clone, Debug)]
pub struct GymReplay {
    /// The spec it was trained on, lowered again from `spec_source`.
    pub spec: TaskSpec,
    /// The environment's spaces as the document records them.
    pub env: Described,
    /// The greedy agent the document describes.
    pub agent: ApproxAgent,
    /// The spec file's text.
    pub source: String,
    /// The seed it was trained from, when recorded.
    pub seed: Option<u64>,
}

/// A learned function's `policy.json` of either kind.
#[derive(Clone, Debug)]
pub enum AnyReplay {
    /// Trained in a world the document holds whole (a plane, `mountain-car`).
    World(Replay),
    /// Trained in a gymnasium environment the document describes.
    Gym(GymReplay),
}

/// [`replay_text`], also of a document trained in a gymnasium environment.
pub fn replay_text_any(text: &str) -> Result<AnyReplay, Problem> {
    let edited = "the file was edited or damaged: train the policy again with `hstlc train`";
    let mut de = serde_json::Deserializer::from_str(text);
    let (doc, weights) = serde::Deserializer::deserialize_map(&mut de, TopLevel)
        .and_then(|parts| de.end().map(|()| parts))
        .map_err(|e| Problem::new(format!("not a valid policy.json: {e}"), Some(edited.into())))?;
    let env = doc.get("env");
    let params = env.and_then(|e| e.get("params"));
    if !params.is_some_and(Described::is_gymnasium) {
        return replay_parts(&doc, weights).map(AnyReplay::World);
    }
    let name = env.and_then(|e| e.get("name")).and_then(Value::as_str).unwrap_or("");
    let vars: Vec<String> = doc
        .get("state_vars")
        .and_then(Value::as_array)
        .map(|l| l.iter().filter_map(Value::as_str).map(str::to_string).collect())
        .unwrap_or_default();
    let described = Described::from_params(name, vars, params.unwrap_or(&Value::Null))?;
    let words = EnvWords::of(&described);
    let Parts { spec, agent, source, seed } = replay_core(
        &doc,
        weights,
        &words,
        |_, _| {},
        |spec| zero_of(spec, &described).and_then(|z| ApproxAgent::new(spec, &described, z)),
    )?;
    Ok(AnyReplay::Gym(GymReplay { spec, env: described, agent, source, seed }))
}

/// A list of sparse entries as a document gives it (`None`: not a list), each `(index,
/// bits)`, or `None` where it is not `[INDEX, "16 hex digits"]`.
type Entries = Option<Vec<Option<(u64, u64)>>>;

/// `weights.flat`: each option's name and entries, in the document's order.
type FlatEntries = Vec<(String, Entries)>;

/// The learned weights as a document gives them.
#[derive(Clone, Debug, Default)]
struct SparseWeights {
    flat_len: Option<u64>,
    options_len: Option<u64>,
    /// `None`: no `flat` object.
    flat: Option<FlatEntries>,
    options: Option<Entries>,
}

impl SparseWeights {
    fn of_value(v: &Value) -> SparseWeights {
        let list = |v: &Value| v.as_array().map(|a| a.iter().map(entry).collect());
        SparseWeights {
            flat_len: v.get("flat_len").and_then(Value::as_u64),
            options_len: v.get("options_len").and_then(Value::as_u64),
            flat: v
                .get("flat")
                .and_then(Value::as_object)
                .map(|m| m.iter().map(|(k, e)| (k.clone(), list(e))).collect()),
            options: v.get("options").map(list),
        }
    }
}

/// `[INDEX, "16 hex digits"]` as `(index, bits)`.
fn entry(e: &Value) -> Option<(u64, u64)> {
    let pair = e.as_array().filter(|p| p.len() == 2)?;
    let h =
        pair[1].as_str().filter(|h| h.len() == 16 && h.bytes().all(|b| b.is_ascii_hexdigit()))?;
    Some((pair[0].as_u64()?, u64::from_str_radix(h, 16).ok()?))
}

/// The most JSON values (numbers, strings, lists, objects) that the entries of a learned
/// function's `policy.json` other than its weights may hold together: the world's 1,024
/// obstacles take about 6,000, so a document past this is no `policy.json` `hstlc train`
/// wrote, and is refused while it is read, before it takes memory.
pub const MAX_HEADER_VALUES: usize = 1 << 20;

/// The most options `weights.flat` may name (a spec has far fewer primitive options).
const MAX_FLAT_NAMES: usize = 1 << 16;

/// The most JSON values one weight entry `[INDEX, "16 hex digits"]` may hold (it holds 3).
const MAX_ENTRY_VALUES: usize = 8;

/// The top-level entries a learned function's `policy.json` has besides `weights`; any
/// other is skipped as it is read.
const HEADER_KEYS: [&str; 13] = [
    "spec",
    "env",
    "state_vars",
    "actions",
    "options",
    "learner",
    "tiles",
    "memory",
    "switch",
    "steps",
    "choices",
    "spec_source",
    "seed",
];

/// Reads the top level of a `policy.json`: `weights` as [`SparseWeights`], the entries of
/// [`HEADER_KEYS`] kept within [`MAX_HEADER_VALUES`], any other skipped; a key given twice
/// is an error.
struct TopLevel;

impl<'de> serde::de::Visitor<'de> for TopLevel {
    type Value = (Value, Option<SparseWeights>);
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON object")
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let (mut doc, mut weights) = (serde_json::Map::new(), None);
        let left = std::cell::Cell::new(MAX_HEADER_VALUES);
        let mut seen: Vec<String> = Vec::new();
        while let Some(key) = map.next_key::<String>()? {
            if seen.contains(&key) {
                return Err(serde::de::Error::custom(format_args!(
                    "the entry `{}` is given twice",
                    crate::load::escape_controls(&key)
                )));
            }
            if key == "weights" {
                weights = Some(map.next_value_seed(WeightsSeed { left: &left })?);
            } else if HEADER_KEYS.contains(&key.as_str()) {
                let v = map.next_value_seed(Bounded { left: &left, what: "the document" })?;
                doc.insert(key.clone(), v);
            } else {
                map.next_value::<serde::de::IgnoredAny>()?;
                continue;
            }
            seen.push(key);
        }
        Ok((Value::Object(doc), weights))
    }
}

/// Reads one JSON value, counting it and everything in it against `left`: past the budget,
/// an error naming `what`, so that no part of a document takes more memory than its
/// budget allows, whatever it holds.
struct Bounded<'a> {
    left: &'a std::cell::Cell<usize>,
    what: &'static str,
}

impl Bounded<'_> {
    fn take<E: serde::de::Error>(&self) -> Result<(), E> {
        match self.left.get().checked_sub(1) {
            Some(left) => {
                self.left.set(left);
                Ok(())
            }
            None => Err(E::custom(format_args!(
                "{} holds more values than a policy.json `hstlc train` writes",
                self.what
            ))),
        }
    }
}

impl<'de> serde::de::DeserializeSeed<'de> for Bounded<'_> {
    type Value = Value;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for Bounded<'_> {
    type Value = Value;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E: serde::de::Error>(self, v: bool) -> Result<Value, E> {
        self.take()?;
        Ok(Value::Bool(v))
    }
    fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Value, E> {
        self.take()?;
        Ok(Value::from(v))
    }
    fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Value, E> {
        self.take()?;
        Ok(Value::from(v))
    }
    fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Value, E> {
        self.take()?;
        Ok(serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number))
    }
    fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Value, E> {
        self.take()?;
        Ok(Value::String(v.to_string()))
    }
    fn visit_string<E: serde::de::Error>(self, v: String) -> Result<Value, E> {
        self.take()?;
        Ok(Value::String(v))
    }
    fn visit_unit<E: serde::de::Error>(self) -> Result<Value, E> {
        self.take()?;
        Ok(Value::Null)
    }
    fn visit_none<E: serde::de::Error>(self) -> Result<Value, E> {
        self.visit_unit()
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        self.take()?;
        let mut out = Vec::new();
        while let Some(v) = seq.next_element_seed(Bounded { left: self.left, what: self.what })? {
            out.push(v);
        }
        Ok(Value::Array(out))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        self.take()?;
        let mut out = serde_json::Map::new();
        while let Some(k) = map.next_key::<String>()? {
            self.take()?;
            let v = map.next_value_seed(Bounded { left: self.left, what: self.what })?;
            out.insert(k, v);
        }
        Ok(Value::Object(out))
    }
}

/// Reads `weights`: its lengths, and its lists entry by entry; anything but the lists counts
/// against `left`.
struct WeightsSeed<'a> {
    left: &'a std::cell::Cell<usize>,
}

impl<'de> serde::de::DeserializeSeed<'de> for WeightsSeed<'_> {
    type Value = SparseWeights;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<SparseWeights, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> serde::de::Visitor<'de> for WeightsSeed<'_> {
    type Value = SparseWeights;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("the weights object")
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(
        self,
        mut map: A,
    ) -> Result<SparseWeights, A::Error> {
        let mut out = SparseWeights::default();
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "flat_len" => {
                    let v = map.next_value_seed(Bounded { left: self.left, what: "`weights`" })?;
                    out.flat_len = v.as_u64();
                }
                "options_len" => {
                    let v = map.next_value_seed(Bounded { left: self.left, what: "`weights`" })?;
                    out.options_len = v.as_u64();
                }
                "options" => out.options = Some(map.next_value_seed(EntriesSeed)?),
                "flat" => out.flat = map.next_value_seed(FlatSeed)?,
                _ => {
                    map.next_value::<serde::de::IgnoredAny>()?;
                }
            }
        }
        Ok(out)
    }
    // Anything else is no weights object: replay then says which field is missing.
    fn visit_seq<A: serde::de::SeqAccess<'de>>(
        self,
        mut seq: A,
    ) -> Result<SparseWeights, A::Error> {
        while seq.next_element::<serde::de::IgnoredAny>()?.is_some() {}
        Ok(SparseWeights::default())
    }
    fn visit_str<E>(self, _: &str) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_u64<E>(self, _: u64) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_i64<E>(self, _: i64) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_f64<E>(self, _: f64) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_bool<E>(self, _: bool) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
    fn visit_unit<E>(self) -> Result<SparseWeights, E> {
        Ok(SparseWeights::default())
    }
}

/// Reads `weights.flat`: option name to entries; `None` for anything but an object.
struct FlatSeed;

impl<'de> serde::de::DeserializeSeed<'de> for FlatSeed {
    type Value = Option<FlatEntries>;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        let v = d.deserialize_any(EntriesOrMap)?;
        Ok(match v {
            Lists::Map(m) => Some(m),
            _ => None,
        })
    }
}

/// Reads a list of entries; `None` for anything but a list.
struct EntriesSeed;

impl<'de> serde::de::DeserializeSeed<'de> for EntriesSeed {
    type Value = Entries;
    fn deserialize<D: serde::Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        Ok(match d.deserialize_any(EntriesOrMap)? {
            Lists::List(l) => Some(l),
            _ => None,
        })
    }
}

/// A list of entries, a map of such lists, or something else.
enum Lists {
    List(Vec<Option<(u64, u64)>>),
    Map(FlatEntries),
    Other,
}

struct EntriesOrMap;

impl<'de> serde::de::Visitor<'de> for EntriesOrMap {
    type Value = Lists;
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a list of weights")
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Lists, A::Error> {
        let mut out = Vec::new();
        // One small entry at a time: only its compact form stays, and an entry that holds
        // more than an entry does is refused as it is read.
        loop {
            let left = std::cell::Cell::new(MAX_ENTRY_VALUES);
            let seed = Bounded { left: &left, what: "an entry of `weights`" };
            let Some(e) = seq.next_element_seed(seed)? else { break };
            out.push(entry(&e));
        }
        Ok(Lists::List(out))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Lists, A::Error> {
        let mut out = Vec::new();
        while let Some(key) = map.next_key::<String>()? {
            if out.len() == MAX_FLAT_NAMES {
                return Err(serde::de::Error::custom(format_args!(
                    "`weights.flat` names more than {MAX_FLAT_NAMES} options"
                )));
            }
            out.push((key, map.next_value_seed(EntriesSeed)?));
        }
        Ok(Lists::Map(out))
    }
    fn visit_str<E>(self, _: &str) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_u64<E>(self, _: u64) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_i64<E>(self, _: i64) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_f64<E>(self, _: f64) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_bool<E>(self, _: bool) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
    fn visit_unit<E>(self) -> Result<Lists, E> {
        Ok(Lists::Other)
    }
}

/// [`replay`] of the document `doc` and its weights, read apart.
fn replay_parts(doc: &Value, weights_doc: Option<SparseWeights>) -> Result<Replay, Problem> {
    let edited =
        || "the file was edited or damaged: train the policy again with `hstlc train`".to_string();
    let env = doc.get("env").ok_or_else(|| Problem::new("it has no `env` entry", edited()))?;
    let world_name = env.get("name").and_then(Value::as_str).unwrap_or("");
    let params = env.get("params").cloned().unwrap_or(Value::Null);
    let world = AnyWorld::from_params(world_name, &params)
        .map_err(|e| Problem::new(format!("its world: {e}"), edited()))?;
    if !world.is_continuous() {
        return Err(Problem::new(
            "its world is a grid, which a learned function is not trained in",
            edited(),
        ));
    }
    let words = EnvWords::of_any(&world).map_err(|e| Problem::new(e.to_string(), edited()))?;
    let parts = replay_core(
        doc,
        weights_doc,
        &words,
        |spec, picked| fit_tiles(spec, picked, &world),
        |spec| with_world!(&world, w => zero_of(spec, w).and_then(|z| ApproxAgent::new(spec, w, z))),
    )?;
    let Parts { spec, agent, source, seed } = parts;
    Ok(Replay { spec, world, agent, source, seed })
}

/// What [`replay_core`] reads back besides the world.
struct Parts {
    spec: TaskSpec,
    agent: ApproxAgent,
    source: String,
    seed: Option<u64>,
}

/// Reads a learned function's document in the environment `env` names: `fit` lays the
/// tiling over it and `zero` makes the agent of zero weights there.
fn replay_core(
    doc: &Value,
    weights_doc: Option<SparseWeights>,
    words: &EnvWords,
    fit: impl FnOnce(&mut TaskSpec, &CheckedSpec),
    zero: impl FnOnce(&TaskSpec) -> Result<ApproxAgent, Error>,
) -> Result<Parts, Problem> {
    let retrain = || "train the policy again with `hstlc train`".to_string();
    let edited =
        || "the file was edited or damaged: train the policy again with `hstlc train`".to_string();
    let field = |name: &str| {
        doc.get(name).ok_or_else(|| Problem::new(format!("it has no `{name}` entry"), edited()))
    };
    let source = field("spec_source")?
        .as_str()
        .ok_or_else(|| Problem::new("its `spec_source` is not a string", edited()))?
        .to_string();
    let name = field("spec")?
        .as_str()
        .ok_or_else(|| Problem::new("its `spec` is not a string", edited()))?;
    let seed = match doc.get("seed") {
        None => None,
        Some(v) => Some(
            v.as_u64().ok_or_else(|| Problem::new("its `seed` is not a whole number", edited()))?,
        ),
    };
    let checked = hstl_lang::check(&source);
    let picked = checked
        .specs
        .iter()
        .find(|s| s.name == name)
        .filter(|_| !checked.has_errors())
        .ok_or_else(|| {
            Problem::new(
                format!("its `spec_source` does not hold a valid spec `{name}`"),
                retrain(),
            )
        })?;
    let mut spec = crate::lower::task_spec(picked, &source)
        .map_err(|e| Problem::new(e.to_string(), retrain()))?;
    let trained = doc.get("memory").and_then(|m| m.get("buckets")).and_then(Value::as_u64);
    let preset_changed = crate::evaluate::preset_memory_changed(
        &checked,
        name,
        trained.unwrap_or(0),
        spec.learn.memory as u64,
    );
    fit(&mut spec, picked);
    // Only a document whose weights have the shape of the memory it records was trained
    // so; any other is an edit.
    if let Some(p) = preset_changed {
        let mut then = spec.clone();
        then.learn.memory = usize::try_from(trained.unwrap_or(0)).unwrap_or(usize::MAX);
        let options_len = weights_doc.as_ref().and_then(|w| w.options_len);
        let shape = hstl_runtime::approx::Model::shape_with(&then, words.actions.len());
        let fits = shape.ok().and_then(|s| {
            Some(s.options_features.checked_mul(s.options)?.checked_mul(s.codes)? as u64)
        });
        if fits.is_some() && fits == options_len {
            return Err(p);
        }
    }
    // The document's tiling must be the one the spec and the world give.
    let agent0 = zero(&spec)
        .map_err(|e| Problem::new(format!("it does not fit its spec and world: {e}"), retrain()))?;
    // Every entry the spec, the world and the model determine must be as `policy_json`
    // writes it: the tiling, the world whole, the names of the variables, actions and
    // options, the memory and the switch.
    let expected = header(&spec, words, &agent0.model)
        .map_err(|e| Problem::new(format!("it does not fit its spec and world: {e}"), retrain()))?;
    field("tiles")?;
    for (key, want) in &expected {
        if doc.get(key) != Some(want) {
            let message = match key.as_str() {
                "tiles" => "its `tiles` are not the tiling its spec and world give".to_string(),
                "env" => "its `env` is not the world as `hstlc train` writes it".to_string(),
                "memory" | "switch" if doc.get(key).is_none() => {
                    format!("it has no `{key}` entry, which its spec gives")
                }
                _ => format!("its `{key}` is not what its spec and world give"),
            };
            return Err(Problem::new(message, edited()));
        }
    }
    for key in ["memory", "switch"] {
        if doc.get(key).is_some() && !expected.contains_key(key) {
            let message = format!("it has a `{key}` entry, which its spec does not give");
            return Err(Problem::new(message, edited()));
        }
    }
    let count = |key: &str| match doc.get(key) {
        None => Ok(0),
        Some(v) => v
            .as_u64()
            .ok_or_else(|| Problem::new(format!("its `{key}` is not a whole number"), edited())),
    };
    let (steps, choices) = (count("steps")?, count("choices")?);
    let weights_doc =
        weights_doc.ok_or_else(|| Problem::new("it has no `weights` entry", edited()))?;
    let mut weights = agent0.weights.clone();
    let flat_len = weights.flat.first().map_or(0, Vec::len);
    if weights_doc.flat_len != Some(flat_len as u64)
        || weights_doc.options_len != Some(weights.options.len() as u64)
    {
        return Err(Problem::new(
            "its weights do not have the shape of its spec and world",
            edited(),
        ));
    }
    let flat = weights_doc
        .flat
        .as_ref()
        .ok_or_else(|| Problem::new("its `weights.flat` is not an object", edited()))?;
    let mut names: Vec<&str> = flat.iter().map(|(k, _)| k.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    if names.len() != flat.len() || flat.len() != spec.primitives.len() {
        return Err(Problem::new(
            "its `weights.flat` does not name every primitive option once",
            edited(),
        ));
    }
    for (p, prim) in spec.primitives.iter().enumerate() {
        let entries = flat.iter().find(|(k, _)| *k == prim.name).ok_or_else(|| {
            Problem::new(
                format!("its `weights.flat` has no entry for option `{}`", prim.name),
                edited(),
            )
        })?;
        fill(&mut weights.flat[p], entries.1.as_deref(), &format!("weights.flat.{}", prim.name))
            .map_err(|m| Problem::new(m, edited()))?;
    }
    let options = weights_doc
        .options
        .as_ref()
        .ok_or_else(|| Problem::new("it has no `weights.options`", edited()))?;
    fill(&mut weights.options, options.as_deref(), "weights.options")
        .map_err(|m| Problem::new(m, edited()))?;
    weights.steps = steps;
    weights.choices = choices;
    let agent = ApproxAgent { weights, ..agent0 };
    Ok(Parts { spec, agent, source, seed })
}

/// Zeroed weights of `spec`'s model in `w`.
fn zero_of<W: hstl_runtime::World>(spec: &TaskSpec, w: &W) -> Result<Weights, Error> {
    Ok(hstl_runtime::approx::Model::new(spec, w)?.zero_weights())
}

/// Fills `into` from sparse `[[index, "hex bits"], ...]` entries (`None`: not a list; an
/// entry `None`: not of that form): every index in range and given once, every value
/// finite.
fn fill(
    into: &mut [f64],
    entries: Option<&[Option<(u64, u64)>]>,
    what: &str,
) -> Result<(), String> {
    let list = entries.ok_or_else(|| format!("its `{what}` is not a list"))?;
    if list.len() > into.len() {
        return Err(format!("its `{what}` has more entries than weights"));
    }
    let mut seen = vec![false; into.len()];
    for e in list {
        let Some((i, bits)) = *e else {
            return Err(format!("an entry of its `{what}` is not `[INDEX, \"16 hex digits\"]`"));
        };
        let v = f64::from_bits(bits);
        let i = usize::try_from(i).unwrap_or(usize::MAX);
        if i >= into.len() || seen[i] {
            return Err(format!("its `{what}` has index {i} out of range or twice"));
        }
        if !v.is_finite() {
            return Err(format!("its `{what}` has a value that is not a finite number"));
        }
        seen[i] = true;
        into[i] = v;
    }
    Ok(())
}

/// What an evaluation of a learned function measured.
#[derive(Clone, Debug, PartialEq)]
pub enum Evaluation {
    /// A persistent task: the window rate.
    Window(WindowSummary),
    /// Another task: the share of runs that satisfy it.
    Satisfaction {
        /// The share of runs whose trace satisfies the task.
        rate: f64,
    },
}

/// Runs the greedy agent from `runs.starts` random starts (one generator seeded with
/// `runs.seed`) and measures the window rate of a persistent task, or the share of runs
/// that satisfy another.
pub fn evaluate(replay: &Replay, runs: Runs) -> Result<Evaluation, Problem> {
    let Replay { spec, world, agent, .. } = replay;
    with_world!(world, w => Ok(evaluate_in(spec, agent, w, runs)))
        .map_err(|e: Error| Problem::new(e.to_string(), None))?
}

/// [`evaluate`] of `agent` (trained on `spec`) in any world, such as a gymnasium
/// environment stepped through Python.
pub fn evaluate_in<W: hstl_runtime::World>(
    spec: &TaskSpec,
    agent: &ApproxAgent,
    world: &W,
    runs: Runs,
) -> Result<Evaluation, Problem> {
    let mut rng = seeded_rng(runs.seed);
    let result = if agent.model.is_persistent() {
        agent
            .window_rate(world, spec, runs.starts, runs.steps, runs.burn_in, &mut rng)
            .map(Evaluation::Window)
    } else {
        Ok(Evaluation::Satisfaction {
            rate: agent.satisfaction(world, spec, runs.starts, runs.steps, &mut rng),
        })
    };
    result.map_err(|e| Problem::new(e.to_string(), None))
}

/// The evaluation `hstlc train` prints after training from `seed` (its own generator).
pub fn after_training(
    spec: &TaskSpec,
    world: &AnyWorld,
    agent: &ApproxAgent,
    seed: u64,
) -> Result<Evaluation, Problem> {
    let replay = Replay {
        spec: spec.clone(),
        world: world.clone(),
        agent: agent.clone(),
        source: String::new(),
        seed: Some(seed),
    };
    evaluate(&replay, runs_after_training(spec, seed))
}

/// The runs [`after_training`] scores a policy trained from `seed` with: 100 runs of 2,000
/// steps for a persistent task, else 1,000 runs of the task's horizon.
pub fn runs_after_training(spec: &TaskSpec, seed: u64) -> Runs {
    let runs = Runs { seed: seed ^ EVAL_SEED, ..Runs::default() };
    if spec.regions.is_empty() {
        Runs { starts: 1000, steps: task_steps(spec), ..runs }
    } else {
        runs
    }
}

/// The steps a run of a task that is not persistent needs: its horizon and one, at most
/// [`MAX_RUN_STEPS`](hstl_runtime::progress::MAX_RUN_STEPS) (an unbounded task gets
/// [`UNBOUNDED_RUN_STEPS`](hstl_runtime::progress::UNBOUNDED_RUN_STEPS)).
pub fn task_steps(spec: &TaskSpec) -> usize {
    hstl_runtime::progress::run_steps(&spec.task)
}

/// `DIR/run_K.csv` of greedy runs (the contract "greedy runs as data"): `t,VAR...,action,
/// option`, one row per step and one more for the final state.
pub fn run_csv(replay: &Replay, run: &hstl_runtime::approx::GreedyRun) -> String {
    let vars = replay.agent.model.vars.len();
    let actions: Vec<String> =
        with_world!(&replay.world, w => Ok::<_, Error>(hstl_runtime::World::actions(w)))
            .unwrap_or_default();
    let mut out = format!("t,{},action,option\n", replay.agent.model.vars.join(","));
    for (t, row) in run.values.chunks(vars).enumerate() {
        out.push_str(&t.to_string());
        for &v in row {
            out.push(',');
            out.push_str(&number(v));
        }
        match (run.actions.get(t), run.options.get(t)) {
            (Some(&a), Some(&o)) => {
                out.push(',');
                out.push_str(actions.get(a).map_or("", String::as_str));
                out.push(',');
                out.push_str(&replay.spec.options.get(o).map_or(String::new(), |x| x.name.clone()));
            }
            _ => out.push_str(",,"),
        }
        out.push('\n');
    }
    out
}

/// `runs` greedy runs of `steps` actions from the world's starts (seeded with `seed`).
pub fn greedy_runs(
    replay: &Replay,
    runs: usize,
    steps: usize,
    seed: u64,
) -> Vec<hstl_runtime::approx::GreedyRun> {
    let mut rng = seeded_rng(seed);
    let result: Result<Vec<_>, Error> = with_world!(&replay.world, w => {
        Ok((0..runs).map(|_| {
            let start = hstl_runtime::World::reset(w, &mut rng);
            replay.agent.run(w, start, steps, &mut rng)
        }).collect())
    });
    result.unwrap_or_default()
}

pub use crate::outfile::number;
