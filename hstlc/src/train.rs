//! `hstlc train`: learn a hierarchical policy for a spec, and write it with its pictures.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use hstl::runtime::eval::WindowConfig;
use hstl::runtime::{GridWorld, Policy, TaskSpec, seeded_rng};
use hstl::world::AnyWorld;

use crate::cli_error::CliError;
use crate::output::outln;
use crate::world_arg::WORLD_HELP;
use crate::{CmdResult, Status, spec_file};
use hstl::artifacts::{self, OutFile};
use hstl_outdir::{OutDir, Writer};

/// Arguments of `hstlc train`.
#[derive(Args, Debug)]
pub struct TrainArgs {
    /// The spec file (`-` reads standard input).
    #[arg(value_name = "SPEC")]
    pub spec: PathBuf,
    /// The grid world to train in, instead of the one the spec names (default: `paper`).
    #[arg(long, value_name = "NAME|FILE.toml", long_help = WORLD_HELP)]
    pub world: Option<String>,
    /// The seed of the one random generator every draw comes from.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Training episodes (overrides the spec's `learn { episodes }`; at most 10,000,000).
    #[arg(long, value_name = "N", value_parser = episodes_flag())]
    pub episodes: Option<usize>,
    /// The folder to write `policy.json`, `curve.csv` and the pictures into (replaced as a
    /// whole: it must be new, empty, or an earlier run's).
    #[arg(long, value_name = "DIR", default_value = "out/train")]
    pub out: PathBuf,
    /// The spec to use when the file holds more than one.
    #[arg(long = "spec", value_name = "NAME")]
    pub spec_name: Option<String>,
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
    let loaded =
        spec_file::load_trainable(&args.spec, args.spec_name.as_deref(), args.world.as_deref())?;
    let Some((loaded, world)) = loaded else {
        return Ok(Status::Errors);
    };
    let mut spec = loaded.trainable()?;
    if let Some(e) = args.episodes {
        spec.learn.episodes = e;
    }
    let env = match &world.world {
        AnyWorld::Grid(g) => g,
        continuous => return run_continuous(args, &loaded, spec, continuous, &world),
    };
    // Before the long part: a folder another run holds is refused at once.
    let out = OutDir::lock(&args.out, Writer::CLI)?;
    let bar = progress_bar(spec.learn.episodes as u64);
    let outcome = train(&spec, env, args.seed, &loaded.file, |episode, reward| {
        bar.set_position(episode as u64 + 1);
        bar.set_message(format!("reward {reward:.1}"));
    })?;
    bar.finish_and_clear();

    let mut files = vec![
        OutFile::text("policy.json", policy_json(&outcome.policy, &loaded.source, args.seed)?),
        OutFile::text("curve.csv", artifacts::curve_csv(&outcome.curve)),
    ];
    let mut rng = seeded_rng(args.seed ^ PICTURE_SEED);
    let regions = artifacts::pictured_regions(&loaded.spec, &loaded.file)?;
    let captions = artifacts::Captions {
        subject: artifacts::subject(&loaded.file, args.spec_name.as_deref()),
        note: format!("seed {}", args.seed),
    };
    let skipped = artifacts::too_large_to_draw(env);
    if skipped.is_none() {
        files.extend(artifacts::agent_pictures(
            &spec,
            env,
            &regions,
            &outcome.agent,
            &captions,
            &mut rng,
        )?);
    }
    files.push(artifacts::curve_picture(
        &format!("{}: learning curve\n{}", captions.subject, captions.note),
        std::slice::from_ref(&outcome.curve),
    )?);
    let window = window_report(&spec, env, &outcome.agent, args.seed)?;
    let written = out.write(&files)?;

    let tail = tail_mean(&outcome.curve, 100);
    outln!(
        "trained `{}` on {} (seed {}): {} episodes, {} steps in {:.2} s ({:.1}M steps/s)",
        spec.name,
        world.words(),
        args.seed,
        outcome.curve.len(),
        outcome.steps,
        outcome.secs,
        outcome.steps as f64 / outcome.secs.max(1e-9) / 1e6
    )?;
    outln!(
        "  reward per episode: {tail:.2} (mean of the last {} episodes)",
        outcome.curve.len().min(100)
    )?;
    if let Some((rate, kept)) = window {
        let kept = kept.map_or_else(String::new, |k| {
            format!(
                "; over complete windows the task's body holds on {:.1}% of the steps",
                100.0 * k
            )
        });
        outln!(
            "  window rate {rate:.3} over {} greedy runs of {} steps{kept}",
            WindowConfig::default().starts,
            WindowConfig::default().steps
        )?;
    }
    print_written(written.len(), &args.out, &files)?;
    if let Some(why) = skipped {
        outln!("  {why}")?;
    }
    Ok(Status::Clean)
}

/// `hstlc train` on a continuous world: the approximate learner, its `policy.json`, the
/// learning curve, and the greedy policy's window or satisfaction rate.
fn run_continuous(
    args: &TrainArgs,
    loaded: &spec_file::LoadedSpec,
    mut spec: TaskSpec,
    world: &AnyWorld,
    loaded_world: &crate::world_arg::LoadedWorld,
) -> CmdResult {
    use hstl::continuous as c;
    c::fit_tiles(&mut spec, &loaded.spec, world);
    let out = OutDir::lock(&args.out, Writer::CLI)?;
    let bar = progress_bar(spec.learn.episodes as u64);
    let start = Instant::now();
    let trained = c::train(&spec, world, args.seed, |episode, reward| {
        bar.set_position(episode as u64 + 1);
        bar.set_message(format!("reward {reward:.1}"));
    })
    .map_err(|e| {
        let p = hstl::train::cannot_train(&loaded.file, &spec.name, &e);
        CliError::new(p.message, p.help)
    })?;
    let secs = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let policy = c::policy_json(&spec, world, &trained.agent, &loaded.source, args.seed)
        .map_err(|e| CliError::new(e.to_string(), None))?;
    let subject = artifacts::subject(&loaded.file, args.spec_name.as_deref());
    let mut files = vec![
        OutFile::text("policy.json", policy),
        OutFile::text("curve.csv", artifacts::curve_csv(&trained.curve)),
    ];
    files.extend(artifacts::plane_pictures(
        &spec,
        world,
        &loaded.spec,
        &trained.agent,
        &subject,
        args.seed,
    )?);
    files.push(artifacts::curve_picture(
        &format!("{subject}: learning curve\nseed {}", args.seed),
        std::slice::from_ref(&trained.curve),
    )?);
    let evaluation = c::after_training(&spec, world, &trained.agent, args.seed)?;
    let written = out.write(&files)?;
    outln!(
        "trained `{}` on {} (seed {}): {} episodes, {} steps in {:.2} s ({:.1}M steps/s), tiles {}",
        spec.name,
        loaded_world.words(),
        args.seed,
        trained.curve.len(),
        trained.steps,
        secs,
        trained.steps as f64 / secs.max(1e-9) / 1e6,
        tiles_words(&trained.agent.model)
    )?;
    outln!(
        "  reward per episode: {:.2} (mean of the last {} episodes)",
        tail_mean(&trained.curve, 100),
        trained.curve.len().min(100)
    )?;
    match evaluation {
        c::Evaluation::Window(w) => outln!(
            "  window rate {:.3} over {} greedy runs of {} steps (no exact optimum on a continuous world)",
            w.rate,
            WindowConfig::default().starts,
            WindowConfig::default().steps
        )?,
        c::Evaluation::Satisfaction { rate } => outln!(
            "  satisfied in {rate:.3} of 1000 greedy runs of {} steps (no exact optimum on a continuous world)",
            c::task_steps(&spec)
        )?,
    }
    print_written(written.len(), &args.out, &files)?;
    Ok(Status::Clean)
}

/// ``8 tilings of 14 x 14`` (and the options level's).
pub fn tiles_words(m: &hstl::runtime::approx::Model) -> String {
    let dims = |b: Vec<usize>| b.iter().map(usize::to_string).collect::<Vec<_>>().join(" x ");
    format!(
        "{} tilings of {} (options level: {} of {})",
        m.flat_coder.tilings(),
        dims(m.flat_coder.bins()),
        m.options_coder.tilings(),
        dims(m.options_coder.bins())
    )
}

/// `--episodes`: 1 to the limit a spec's `learn { episodes }` has.
pub fn episodes_flag() -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::new().range(1..=hstl::lang::budget::MAX_EPISODES)
}

pub use hstl::train::PICTURE_SEED;

/// Trains `spec` in `env` from `seed`, timed; `progress` sees each episode and its reward.
pub fn train(
    spec: &TaskSpec,
    env: &GridWorld,
    seed: u64,
    file: &str,
    progress: impl FnMut(usize, f64),
) -> Result<Outcome, CliError> {
    let start = Instant::now();
    let trained = hstl::train::train(spec, env, seed, progress).map_err(|e| {
        let p = hstl::train::cannot_train(file, &spec.name, &e);
        CliError::new(p.message, p.help)
    })?;
    let secs = start.elapsed().as_secs_f64();
    let hstl::train::Trained { policy, curve, steps, agent } = trained;
    Ok(Outcome { policy, curve, steps, secs, agent })
}

/// `policy.json`, as every front end writes it.
pub fn policy_json(policy: &Policy, source: &str, seed: u64) -> Result<String, CliError> {
    hstl::train::policy_json(policy, source, seed).map_err(|e| CliError::new(e.to_string(), None))
}

/// The window rate of the greedy agent, and the share of steps keeping every complete
/// window, for persistent tasks.
pub fn window_report(
    spec: &TaskSpec,
    env: &GridWorld,
    agent: &hstl::runtime::Agent,
    seed: u64,
) -> Result<Option<(f64, Option<f64>)>, CliError> {
    let summary = hstl::train::window_summary(spec, env, agent, seed)
        .map_err(|e| CliError::new(e.to_string(), None))?;
    Ok(summary.map(|s| (s.rate, s.kept)))
}

pub use hstl::study::tail_mean;

/// `wrote N files to OUT: a, b, c`.
fn print_written(
    count: usize,
    out: &std::path::Path,
    files: &[OutFile],
) -> Result<(), crate::cli_error::CliError> {
    let names = files.iter().map(|f| f.name.as_str()).collect::<Vec<_>>().join(", ");
    outln!("  wrote {count} files to {}: {names}", crate::output::shown(out))?;
    Ok(())
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
