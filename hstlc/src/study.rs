//! `hstlc study`: train several specs over many seeds, compare them, and write each one's
//! pictures. The paper's case study is `scripts/case-study`, which runs this on the four
//! variants in `examples/specs/`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;
use hstl::runtime::eval::RegionTable;
use hstl::runtime::optimum::{SolveConfig, solve};
use hstl::runtime::{Agent, GridWorld, Intra, Policy, Region, RewardKind, TaskSpec, seeded_rng};

use crate::artifacts::{self, OutDir, OutFile};
use crate::cli_error::CliError;
use crate::output::outln;
use crate::train::{self, PICTURE_SEED, tail_mean};
use crate::world_arg::{LoadedWorld, WORLD_HELP};
use crate::{CmdResult, Status, spec_file};

/// Arguments of `hstlc study`.
#[derive(Args, Debug)]
pub struct StudyArgs {
    /// The spec files to train and compare; the first is the baseline of the reward
    /// comparison.
    #[arg(required = true, value_name = "SPEC")]
    pub specs: Vec<PathBuf>,
    /// Seeds per spec: 0, 1, ... N-1 (at most 100,000).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(u64).range(1..=100_000))]
    pub seeds: u64,
    /// Training episodes (overrides each spec's `learn { episodes }`; at most 10,000,000).
    #[arg(long, value_name = "N", value_parser = train::episodes_flag())]
    pub episodes: Option<usize>,
    /// Also train each spec with the other `intra` crediting rule, and report both.
    #[arg(long)]
    pub both_intra: bool,
    /// Skip the optimum W* (value iteration takes a few seconds per region set).
    #[arg(long)]
    pub no_optimum: bool,
    /// The grid world to train in.
    #[arg(long, value_name = "NAME|FILE.toml", default_value = "paper", long_help = WORLD_HELP)]
    pub world: String,
    /// Worker threads (default: every core; at most 256).
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=256))]
    pub threads: Option<usize>,
    /// The folder for each spec's policy (first seed), curves, pictures and per-seed
    /// figures (`seeds.csv`).
    #[arg(long, value_name = "DIR", default_value = "out/study")]
    pub out: PathBuf,
}

/// What one training run measured.
#[derive(Clone, Debug)]
struct RunResult {
    secs: f64,
    steps: u64,
    tail_reward: f64,
    window: Option<f64>,
    curve: Vec<f64>,
    /// Seed 0's greedy policy, kept for the pictures and `policy.json`.
    first: Option<(Policy, Agent)>,
}

/// Runs `hstlc study`.
pub fn run(args: &StudyArgs) -> CmdResult {
    // Check every spec against the world before the long part starts.
    let world = LoadedWorld::load(&args.world)?;
    let mut loaded = Vec::new();
    for path in &args.specs {
        let Some(l) = spec_file::load(path, None, Some(&world))? else {
            return Ok(Status::Errors);
        };
        let mut spec = l.trainable()?;
        if let Some(e) = args.episodes {
            spec.learn.episodes = e;
        }
        loaded.push((path.clone(), l, spec));
    }
    // Each spec's folder, taken before the long part: a folder another run holds is
    // refused at once, and two specs of one name get folders of their own.
    let outs = spec_dirs(&args.out, &args.specs)
        .iter()
        .map(|d| OutDir::lock(d))
        .collect::<Result<Vec<_>, _>>()?;
    let env = &world.world;
    let threads = args
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from))
        .max(1);
    outln!(
        "study: {} specs x {} seeds on {}, {threads} threads",
        loaded.len(),
        args.seeds,
        world.words()
    )?;
    let mut optima: Vec<(Vec<Region>, f64)> = Vec::new();
    let mut baseline: Option<(String, f64, RewardKind)> = None;
    for ((path, l, spec), out) in loaded.iter().zip(outs) {
        let results = run_seeds(spec, env, args.seeds, threads, &l.file)?;
        let w_star = if args.no_optimum || spec.regions.is_empty() {
            None
        } else {
            Some(optimum(&mut optima, spec, env)?)
        };
        let label = path.file_name().map_or(l.file.clone(), |n| n.to_string_lossy().into_owned());
        outln!()?;
        outln!(
            "{label}: `{}`, {} options, intra: {}, {} seeds x {} episodes x {} choices",
            spec.name,
            spec.options.len(),
            intra_word(spec.learn.intra),
            args.seeds,
            spec.learn.episodes,
            spec.learn.choices
        )?;
        print_table(&results, w_star)?;
        let reward = mean(&results.iter().map(|r| r.tail_reward).collect::<Vec<_>>());
        // Rewards compare only under the same options-level reward.
        match &baseline {
            None => baseline = Some((label.clone(), reward, spec.learn.reward)),
            Some((base, b, kind)) if *kind == spec.learn.reward => outln!(
                "  reward vs {base}: {:+.1}% (mean reward per episode, last 100 episodes)",
                100.0 * (reward - b) / b.abs()
            )?,
            Some((base, _, _)) => outln!(
                "  reward not compared with {base}: its options earn another kind of reward"
            )?,
        }
        let one_leg = spec.options.iter().all(|o| o.sequence.len() == 1);
        if args.both_intra && one_leg {
            // The rules differ only on suffixes inside a later leg.
            outln!("  intra: paper and remaining agree here: every option has one leg")?;
        } else if args.both_intra {
            let mut other = spec.clone();
            other.learn.intra = match spec.learn.intra {
                Intra::Paper => Intra::Remaining,
                Intra::Remaining => Intra::Paper,
            };
            let alt = run_seeds(&other, env, args.seeds, threads, &l.file)?;
            outln!("  with intra: {} instead:", intra_word(other.learn.intra))?;
            print_table(&alt, w_star)?;
        }
        let dir = out.path().to_path_buf();
        write_outputs(out, spec, env, l, &results)?;
        outln!("  wrote {}", dir.display())?;
    }
    Ok(Status::Clean)
}

/// Trains `spec` for seeds `0..seeds` on `threads` workers; results in seed order.
fn run_seeds(
    spec: &TaskSpec,
    env: &GridWorld,
    seeds: u64,
    threads: usize,
    file: &str,
) -> Result<Vec<RunResult>, CliError> {
    let threads = threads.min(seeds as usize).max(1) as u64;
    let share = |w: u64| {
        (0..seeds)
            .filter(|s| s % threads == w)
            .map(|seed| (seed, one_run(spec, env, seed, file)))
            .collect::<Vec<_>>()
    };
    let mut all: Vec<(u64, Result<RunResult, CliError>)> = std::thread::scope(|scope| {
        let share = &share;
        let workers: Vec<_> = (0..threads)
            .map(|w| (w, std::thread::Builder::new().spawn_scoped(scope, move || share(w))))
            .collect();
        let mut all = Vec::new();
        for (w, worker) in workers {
            match worker {
                Ok(handle) => all.extend(handle.join().unwrap_or_default()),
                // A thread the system would not start: its seeds run here.
                Err(_) => all.extend(share(w)),
            }
        }
        all
    });
    if all.len() as u64 != seeds {
        return Err(CliError::new("a training thread failed", None));
    }
    all.sort_by_key(|(seed, _)| *seed);
    all.into_iter().map(|(_, r)| r).collect()
}

fn one_run(spec: &TaskSpec, env: &GridWorld, seed: u64, file: &str) -> Result<RunResult, CliError> {
    let outcome = train::train(spec, env, seed, file, |_, _| {})?;
    let window = train::window_report(spec, env, &outcome.agent, seed)?.map(|(rate, _)| rate);
    Ok(RunResult {
        secs: outcome.secs,
        steps: outcome.steps,
        tail_reward: tail_mean(&outcome.curve, 100),
        window,
        curve: outcome.curve,
        first: (seed == 0).then_some((outcome.policy, outcome.agent)),
    })
}

/// W* for the spec's regions, solved once per distinct region set.
fn optimum(
    cache: &mut Vec<(Vec<Region>, f64)>,
    spec: &TaskSpec,
    env: &GridWorld,
) -> Result<f64, CliError> {
    if let Some((_, w)) = cache.iter().find(|(r, _)| *r == spec.regions) {
        return Ok(*w);
    }
    let regions = RegionTable::new(spec, env).map_err(|e| CliError::new(e.to_string(), None))?;
    let start = Instant::now();
    let o = solve(env, &regions, SolveConfig::default())
        .map_err(|e| CliError::new(e.to_string(), None))?;
    outln!(
        "optimum for regions {}: W* = {:.4} (value iteration, {} sweeps, {:.1} s{})",
        spec.regions.iter().map(|r| r.name.as_str()).collect::<Vec<_>>().join(", "),
        o.gain,
        o.iterations,
        start.elapsed().as_secs_f64(),
        if o.converged { "" } else { ", not converged" }
    )?;
    cache.push((spec.regions.clone(), o.gain));
    Ok(o.gain)
}

fn print_table(results: &[RunResult], w_star: Option<f64>) -> Result<(), CliError> {
    let row = |name: &str, values: Vec<f64>, digits: usize| {
        let (lo, hi) = range(&values);
        let m = mean(&values);
        // The sample standard deviation over seeds.
        let sd = (values.iter().map(|v| (v - m) * (v - m)).sum::<f64>()
            / (values.len().max(2) - 1) as f64)
            .sqrt();
        outln!("  {name:<34} {m:>9.digits$} {sd:>9.digits$} {lo:>9.digits$} {hi:>9.digits$}")
    };
    outln!("  {:<34} {:>9} {:>9} {:>9} {:>9}", "", "mean", "sd", "min", "max")?;
    row("training time (s)", results.iter().map(|r| r.secs).collect(), 3)?;
    row(
        "primitive steps/s (millions)",
        results.iter().map(|r| r.steps as f64 / r.secs.max(1e-9) / 1e6).collect(),
        2,
    )?;
    row("reward per episode (last 100)", results.iter().map(|r| r.tail_reward).collect(), 2)?;
    let windows: Vec<f64> = results.iter().filter_map(|r| r.window).collect();
    if windows.len() == results.len() {
        row("window rate W", windows.clone(), 3)?;
        if let Some(w) = w_star {
            row(&format!("W/W* (W* = {w:.4})"), windows.iter().map(|x| x / w).collect(), 3)?;
        }
    }
    Ok(())
}

/// Seed 0's policy, curve and pictures, the learning curves of all seeds, and
/// `seeds.csv` with each seed's figures.
fn write_outputs(
    out: OutDir,
    spec: &TaskSpec,
    env: &GridWorld,
    loaded: &spec_file::LoadedSpec,
    results: &[RunResult],
) -> Result<(), CliError> {
    // Seeds run from 0, so the first result is seed 0's.
    let Some(RunResult { curve, first: Some((policy, agent)), .. }) = results.first() else {
        return Err(CliError::new("seed 0 did not report its policy", None));
    };
    let mut files = vec![
        OutFile::text("policy.json", train::policy_json(policy, &loaded.source, 0)?),
        OutFile::text("curve.csv", artifacts::curve_csv(curve)),
    ];
    let mut rng = seeded_rng(PICTURE_SEED);
    let regions = artifacts::pictured_regions(loaded)?;
    files.extend(artifacts::agent_pictures(spec, env, &regions, agent, &mut rng)?);
    let mut seeds = String::from("seed,train_secs,steps,reward_last_100,window_rate\n");
    for (seed, r) in results.iter().enumerate() {
        let window = r.window.map_or(String::new(), |w| w.to_string());
        seeds.push_str(&format!("{seed},{},{},{},{window}\n", r.secs, r.steps, r.tail_reward));
    }
    files.push(OutFile::text("seeds.csv", seeds));
    let curves: Vec<Vec<f64>> = results.iter().map(|r| r.curve.clone()).collect();
    files.push(artifacts::curve_picture(
        &format!("Learning curve of {} over {} seeds", spec.name, curves.len()),
        &curves,
    )?);
    out.write(&files).map(|_| ())
}

/// Each spec's folder under `out`: its file's stem, and `-2`, `-3`, ... after a stem that an
/// earlier spec of the list has (ignoring case): `study a/spec.hstl b/spec.hstl` writes
/// `spec` and `spec-2`.
fn spec_dirs(out: &Path, specs: &[PathBuf]) -> Vec<PathBuf> {
    let mut taken = std::collections::HashSet::new();
    specs
        .iter()
        .map(|path| {
            let stem = stem(path);
            let mut name = stem.clone();
            let mut k = 2;
            while !taken.insert(name.to_lowercase()) {
                name = format!("{stem}-{k}");
                k += 1;
            }
            out.join(name)
        })
        .collect()
}

fn stem(path: &Path) -> String {
    path.file_stem().map_or("spec".into(), |s| artifacts::file_safe(&s.to_string_lossy()))
}

fn intra_word(i: Intra) -> &'static str {
    match i {
        Intra::Paper => "paper",
        Intra::Remaining => "remaining",
    }
}

/// The mean (0 for no values).
pub fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The smallest and the largest value.
pub fn range(v: &[f64]) -> (f64, f64) {
    v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)))
}
