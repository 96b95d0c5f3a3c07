//! Training a spec in an environment, as `hstlc train` does, so that every front end (the
//! CLI, the Python package) writes the same `policy.json`, bit for bit, for the same seed.

use hstl_runtime::eval::{AgentController, RegionTable, WindowConfig, window_rate};
use hstl_runtime::{Agent, Env, Error, Learner, Policy, TaskSpec, seeded_rng};

/// The seed offset of the generator that draws the sample runs of the pictures.
pub const PICTURE_SEED: u64 = 0x9e37_79b9_7f4a_7c15;
/// The seed offset of the generator that draws the evaluation's starts after training.
pub const EVAL_SEED: u64 = 0x5eed;

/// A trained policy and what training measured (wall-clock time is the caller's to take).
#[derive(Clone, Debug)]
pub struct Trained {
    /// The policy document.
    pub policy: Policy,
    /// The summed option rewards of each episode.
    pub curve: Vec<f64>,
    /// Primitive steps taken.
    pub steps: u64,
    /// The greedy agent.
    pub agent: Agent,
}

/// The window rate and mean task robustness of a greedy agent over
/// [`WindowConfig::default`] runs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WindowSummary {
    /// The share of counted steps whose windows all visit their region.
    pub rate: f64,
    /// The task's robustness over each run, averaged.
    pub robustness: f64,
}

/// Trains `spec` in `env` from `seed` (the one generator every draw comes from);
/// `progress` sees each episode and its reward.
pub fn train<E: Env>(
    spec: &TaskSpec,
    env: &E,
    seed: u64,
    progress: impl FnMut(usize, f64),
) -> Result<Trained, Error> {
    let mut learner = Learner::new(spec, env)?;
    let trained = learner.train(&mut seeded_rng(seed), progress);
    let policy = Policy::new(&learner);
    Ok(Trained { policy, curve: trained.curve, steps: trained.steps, agent: learner.agent() })
}

/// `policy.json`: the runtime's document, plus the spec's source and the seed, so that a
/// replay needs nothing else.
pub fn policy_json(policy: &Policy, source: &str, seed: u64) -> Result<String, Error> {
    let extra = [("spec_source", source.into()), ("seed", seed.into())];
    policy.to_json_with(&extra)
}

/// The window rate of the greedy `agent` after training from `seed`, for a persistent
/// task (`None` for a task of another form).
pub fn window_summary<E: Env>(
    spec: &TaskSpec,
    env: &E,
    agent: &Agent,
    seed: u64,
) -> Result<Option<WindowSummary>, Error> {
    if spec.regions.is_empty() {
        return Ok(None);
    }
    let regions = RegionTable::new(spec, env)?;
    let mut rng = seeded_rng(seed ^ EVAL_SEED);
    let mut controller = AgentController::new(agent);
    let report = window_rate(env, &mut controller, &regions, WindowConfig::default(), &mut rng)?;
    let robustness = report.robustness.iter().sum::<f64>() / report.robustness.len() as f64;
    Ok(Some(WindowSummary { rate: report.rate, robustness }))
}
