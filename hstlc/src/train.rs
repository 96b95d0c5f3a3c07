//! `hstlc train`: learn a hierarchical policy for a spec, and write it with its pictures.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

use clap::{Args, ValueEnum};
use hstl::runtime::eval::{AgentController, RegionTable, WindowConfig, window_rate};
use hstl::runtime::{GridWorld, Learner, Policy, TaskSpec, seeded_rng};

use crate::artifacts::{self, OutDir, OutFile};
use crate::cli_error::CliError;
use crate::{CmdResult, Status, spec_file};

/// Arguments of `hstlc train`.
#[derive(Args, Debug)]
pub struct TrainArgs {
    /// The spec file (`-` reads standard input).
    #[arg(value_name = "SPEC")]
    pub spec: PathBuf,
    /// The environment.
    #[arg(long, value_enum, default_value_t = EnvName::Gridworld)]
    pub env: EnvName,
    /// The seed of the one random generator every draw comes from.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Training episodes (overrides the spec's `learn { episodes }`).
    #[arg(long, value_name = "N")]
    pub episodes: Option<usize>,
    /// The folder to write `policy.json`, `curve.csv` and the pictures into (replaced as a
    /// whole: it must be new, empty, or an earlier run's).
    #[arg(long, value_name = "DIR", default_value = "out/train")]
    pub out: PathBuf,
    /// The spec to use when the file holds more than one.
    #[arg(long = "spec", value_name = "NAME")]
    pub spec_name: Option<String>,
}

/// The environments `train` knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum EnvName {
    /// The paper's grid world: 15 x 15, each action taken with probability 0.7.
    Gridworld,
}

/// One trained policy and what was measured while training it.
pub struct Outcome {
    /// The policy document.
    pub policy: Policy,
    /// Reward per episode.
    pub curve: Vec<f64>,
    /// Primitive steps taken.
    pub steps: u64,
    /// Wall-clock seconds spent training.
    pub secs: f64,
    /// The greedy agent.
    pub agent: hstl::runtime::Agent,
}

/// Runs `hstlc train`.
pub fn run(args: &TrainArgs) -> CmdResult {
    let Some(loaded) = spec_file::load(&args.spec, args.spec_name.as_deref())? else {
        return Ok(Status::Errors);
    };
    let mut spec = loaded.trainable()?;
    if let Some(e) = args.episodes {
        if e == 0 {
            return Err(CliError::new("`--episodes` must be at least 1", None));
        }
        spec.learn.episodes = e;
    }
    let env = match args.env {
        EnvName::Gridworld => GridWorld::default(),
    };
    // Before the long part: a folder another run holds is refused at once.
    let out = OutDir::lock(&args.out)?;
    let bar = progress_bar(spec.learn.episodes as u64);
    let outcome = train(&spec, &env, args.seed, &loaded.file, |episode, reward| {
        bar.set_position(episode as u64 + 1);
        bar.set_message(format!("reward {reward:.1}"));
    })?;
    bar.finish_and_clear();

    let mut files = vec![
        OutFile::text("policy.json", policy_json(&outcome.policy, &loaded.source, args.seed)?),
        OutFile::text("curve.csv", artifacts::curve_csv(&outcome.curve)),
    ];
    let mut rng = seeded_rng(args.seed ^ PICTURE_SEED);
    files.extend(artifacts::agent_pictures(&spec, &env, &outcome.agent, &mut rng)?);
    files.push(artifacts::curve_picture(
        &format!("Learning curve of {} (seed {})", spec.name, args.seed),
        std::slice::from_ref(&outcome.curve),
    )?);
    let window = window_report(&spec, &env, &outcome.agent, args.seed)?;
    let written = out.write(&files)?;

    let tail = tail_mean(&outcome.curve, 100);
    println!(
        "trained `{}` on {} (seed {}): {} episodes, {} steps in {:.2} s ({:.1}M steps/s)",
        spec.name,
        env_words(&env),
        args.seed,
        outcome.curve.len(),
        outcome.steps,
        outcome.secs,
        outcome.steps as f64 / outcome.secs.max(1e-9) / 1e6
    );
    println!(
        "  reward per episode: {tail:.2} (mean of the last {} episodes)",
        outcome.curve.len().min(100)
    );
    if let Some((rate, robustness)) = window {
        println!(
            "  window rate {rate:.3} over {} greedy runs of {} steps; task robustness {robustness:.2} (mean over runs)",
            WindowConfig::default().starts,
            WindowConfig::default().steps
        );
    }
    println!("  wrote {} files to {}: {}", written.len(), args.out.display(), names(&files));
    Ok(Status::Clean)
}

/// The seed offset of the generator that draws the sample runs of the pictures.
pub const PICTURE_SEED: u64 = 0x9e37_79b9_7f4a_7c15;
/// The seed offset of the generator that draws the evaluation's starts.
pub const EVAL_SEED: u64 = 0x5eed;

/// Trains `spec` on `env` from `seed`; `progress` sees each episode and its reward.
pub fn train(
    spec: &TaskSpec,
    env: &GridWorld,
    seed: u64,
    file: &str,
    progress: impl FnMut(usize, f64),
) -> Result<Outcome, CliError> {
    let mut learner = Learner::new(spec, env).map_err(|e| {
        CliError::new(
            format!("{file}: cannot train `{}`: {e}", spec.name),
            Some(
                "options need `int` state variables with ranges that fit the environment, and \
                 at least one option"
                    .to_string(),
            ),
        )
    })?;
    let mut rng = seeded_rng(seed);
    let start = Instant::now();
    let trained = learner.train(&mut rng, progress);
    let secs = start.elapsed().as_secs_f64();
    let policy = Policy::new(&learner);
    Ok(Outcome { policy, curve: trained.curve, steps: trained.steps, secs, agent: learner.agent() })
}

/// `policy.json`: the runtime's document, plus the spec's source and the seed, so that
/// `eval` needs nothing else.
pub fn policy_json(policy: &Policy, source: &str, seed: u64) -> Result<String, CliError> {
    let extra = [("spec_source", source.into()), ("seed", seed.into())];
    policy.to_json_with(&extra).map_err(|e| CliError::new(e.to_string(), None))
}

/// The window rate and mean task robustness of the greedy agent, for persistent tasks.
pub fn window_report(
    spec: &TaskSpec,
    env: &GridWorld,
    agent: &hstl::runtime::Agent,
    seed: u64,
) -> Result<Option<(f64, f64)>, CliError> {
    if spec.regions.is_empty() {
        return Ok(None);
    }
    let regions = RegionTable::new(spec, env).map_err(|e| CliError::new(e.to_string(), None))?;
    let mut rng = seeded_rng(seed ^ EVAL_SEED);
    let report = window_rate(
        env,
        &mut AgentController::new(agent),
        &regions,
        WindowConfig::default(),
        &mut rng,
    )
    .map_err(|e| CliError::new(e.to_string(), None))?;
    let robustness = report.robustness.iter().sum::<f64>() / report.robustness.len() as f64;
    Ok(Some((report.rate, robustness)))
}

/// The mean of the last `n` values.
pub fn tail_mean(curve: &[f64], n: usize) -> f64 {
    let tail = &curve[curve.len().saturating_sub(n)..];
    tail.iter().sum::<f64>() / tail.len().max(1) as f64
}

/// `gridworld 15 x 15, p = 0.7`.
pub fn env_words(env: &GridWorld) -> String {
    format!("gridworld {} x {}, p = {}", env.width(), env.height(), env.p())
}

fn names(files: &[OutFile]) -> String {
    files.iter().map(|f| f.name.as_str()).collect::<Vec<_>>().join(", ")
}

/// A bar on a terminal, nothing otherwise.
fn progress_bar(len: u64) -> indicatif::ProgressBar {
    if !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(len);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "training {bar:40} {pos}/{len} episodes, {msg} ({eta} left)",
    ) {
        bar.set_style(style);
    }
    bar
}
