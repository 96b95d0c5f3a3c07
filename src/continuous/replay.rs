//! Replaying a learned function's `policy.json`: the document checked whole against its
//! spec and world (or the gymnasium spaces it records), its evaluation, and its greedy runs
//! as CSV.

use super::read::{SparseWeights, TopLevel, digest};
use super::*;

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

/// Refuses a document whose `checksum` is not the digest of its entries ([`digest`]); a
/// document without one (written before checksums existed) is read as it is.
fn check_sum(doc: &Value, weights: Option<&SparseWeights>) -> Result<(), Problem> {
    let (Some(map), Some(written)) = (doc.as_object(), doc.get("checksum")) else {
        return Ok(());
    };
    let none = SparseWeights::default();
    let own = digest(map, |d| weights.unwrap_or(&none).digest(d));
    if written.as_str() == Some(own.as_str()) {
        return Ok(());
    }
    let written = written.as_str().map_or_else(|| written.to_string(), str::to_string);
    Err(Problem::new(
        format!(
            "the document was changed after it was written: its `checksum` is {written}, its \
             entries give {own}"
        ),
        Some("train again, or restore the file as it was written".into()),
    ))
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
    let sum = check_sum(&doc, weights.as_ref());
    let described = Described::from_params(name, vars, params.unwrap_or(&Value::Null))?;
    let words = EnvWords::of(&described);
    let Parts { spec, agent, source, seed } = replay_core(
        &doc,
        weights,
        &words,
        |_, _| {},
        |spec| zero_of(spec, &described).and_then(|z| ApproxAgent::new(spec, &described, z)),
    )?;
    sum?;
    Ok(AnyReplay::Gym(GymReplay { spec, env: described, agent, source, seed }))
}

/// [`replay`] of the document `doc` and its weights, read apart.
fn replay_parts(doc: &Value, weights_doc: Option<SparseWeights>) -> Result<Replay, Problem> {
    let edited =
        || "the file was edited or damaged: train the policy again with `hstlc train`".to_string();
    // The entries' own checks first, whose words say what is wrong; the checksum last,
    // for an edit they all let through (a world's slip, a weight's value).
    let sum = check_sum(doc, weights_doc.as_ref());
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
    sum?;
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
