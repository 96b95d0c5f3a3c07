//! `hstlc study`: train several specs over many seeds, compare them, and write each one's
//! pictures. The paper's case study is `scripts/case-study`, which runs this on the four
//! variants in `examples/specs/`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use clap::Args;
use hstl::runtime::eval::RegionTable;
use hstl::runtime::optimum::{Moves, SolveConfig, solve};
use hstl::runtime::{Agent, GridWorld, Intra, Region, RewardKind, TaskSpec, seeded_rng};

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
    /// The folder for each spec's policy and pictures (of its median seed), curves and
    /// per-seed figures (`seeds.csv`), and the learning curves of all specs in one figure
    /// (`curves.svg`, with every seed's in `curves.csv`).
    #[arg(long, value_name = "DIR", default_value = "out/study")]
    pub out: PathBuf,
}

/// What one training run measured.
#[derive(Clone, Debug)]
struct RunResult {
    seed: u64,
    secs: f64,
    steps: u64,
    tail_reward: f64,
    window: Option<f64>,
    /// For a reach-avoid task: the satisfaction rate and the optimal one.
    reach_avoid: Option<(f64, f64)>,
    curve: Vec<f64>,
    /// The run's `policy.json` and greedy agent, kept while they fit the budget: the
    /// median seed's are written without training it again.
    kept: Option<(String, Agent)>,
}

/// The bytes of trained policies a study keeps in memory for the median seed's files; past
/// it, the median seed is trained again (same seed, same bits) instead.
const KEEP_BUDGET: usize = 256 << 20;

/// The seed whose policy and pictures stand for a spec, and why.
struct Median {
    /// Its index among the results (seed order).
    index: usize,
    /// Said under the pictures' titles: the seed and what it is the median of.
    note: String,
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
    let labels = labels(&args.specs);
    // Every spec's (and variant's) curves, for the figure of all of them.
    let mut all_curves: Vec<(String, RewardKind, Vec<Vec<f64>>)> = Vec::new();
    let mut summary = String::from("spec,measure,optimum,ratio_mean,ratio_min,train_secs_mean\n");
    for (((_, l, spec), label), out) in loaded.iter().zip(&labels).zip(outs) {
        let budget = AtomicUsize::new(KEEP_BUDGET);
        let results = run_seeds(spec, env, args.seeds, threads, l, Some(&budget))?;
        let w_star = if args.no_optimum || spec.regions.is_empty() {
            None
        } else {
            Some(optimum(&mut optima, spec, env)?)
        };
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
        summary.push_str(&summary_line(label, &results, w_star));
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
        let mut variant = None;
        if args.both_intra && one_leg {
            // The rules differ only on suffixes inside a later leg.
            outln!("  intra: paper and remaining agree here: every option has one leg")?;
        } else if args.both_intra {
            let mut other = spec.clone();
            other.learn.intra = match spec.learn.intra {
                Intra::Paper => Intra::Remaining,
                Intra::Remaining => Intra::Paper,
            };
            let alt = run_seeds(&other, env, args.seeds, threads, l, None)?;
            outln!("  with intra: {} instead:", intra_word(other.learn.intra))?;
            print_table(&alt, w_star)?;
            variant = Some((
                format!("{label}, intra {}", intra_word(other.learn.intra)),
                other.learn.reward,
                alt.into_iter().map(|r| r.curve).collect(),
            ));
        }
        let dir = out.path().to_path_buf();
        let median = median(&results);
        outln!("  policy.json and pictures: {}", median.note)?;
        write_outputs(out, spec, env, l, label, &results, &median)?;
        outln!("  wrote {}", dir.display())?;
        // The variant's curves follow the spec's in the figure.
        all_curves.push((
            label.clone(),
            spec.learn.reward,
            results.into_iter().map(|r| r.curve).collect(),
        ));
        all_curves.extend(variant);
    }
    let mut files = all_curves_files(&all_curves, args.seeds)?;
    files.push(OutFile::text("summary.csv", summary));
    artifacts::write_beside(&args.out, &files)?;
    outln!()?;
    outln!(
        "wrote {} and {}: the learning curves of every spec; {}: each spec's measure",
        args.out.join("curves.svg").display(),
        args.out.join("curves.csv").display(),
        args.out.join("summary.csv").display()
    )?;
    Ok(Status::Clean)
}

/// The name of each spec in the legend and in `curves.csv`: its file name, or the path as
/// given where two files share a name.
fn labels(paths: &[PathBuf]) -> Vec<String> {
    let names: Vec<String> = paths
        .iter()
        .map(|p| {
            p.file_name().map_or(p.display().to_string(), |n| n.to_string_lossy().into_owned())
        })
        .collect();
    names
        .iter()
        .zip(paths)
        .map(|(name, path)| {
            if names.iter().filter(|n| *n == name).count() > 1 {
                path.display().to_string()
            } else {
                name.clone()
            }
        })
        .collect()
}

/// `curves.svg`, the curves of every spec (one panel per kind of options reward, which do
/// not share a scale), and `curves.csv`, every seed's reward per episode.
fn all_curves_files(
    curves: &[(String, RewardKind, Vec<Vec<f64>>)],
    seeds: u64,
) -> Result<Vec<OutFile>, CliError> {
    let mut csv = String::from("spec,seed,episode,reward\n");
    for (label, _, runs) in curves {
        let spec = csv_field(label);
        for (seed, curve) in runs.iter().enumerate() {
            for (e, r) in curve.iter().enumerate() {
                csv.push_str(&format!("{spec},{seed},{},{r}\n", e + 1));
            }
        }
    }
    let mut panels: Vec<(RewardKind, hstl_pictures::Panel)> = Vec::new();
    for (label, kind, runs) in curves {
        let series = hstl_pictures::Series { label: label.clone(), seeds: runs.clone() };
        match panels.iter_mut().find(|(k, _)| k == kind) {
            Some((_, panel)) => panel.series.push(series),
            None => panels.push((
                *kind,
                hstl_pictures::Panel { y_label: reward_axis(*kind).into(), series: vec![series] },
            )),
        }
    }
    let panels: Vec<hstl_pictures::Panel> = panels.into_iter().map(|(_, p)| p).collect();
    let episodes = curves.iter().flat_map(|(_, _, r)| r.iter().map(Vec::len)).max().unwrap_or(0);
    let plural = if seeds == 1 { "" } else { "s" };
    let title = format!(
        "Learning curves of {} spec{}\n{seeds} seed{plural} each",
        curves.len(),
        if curves.len() == 1 { "" } else { "s" }
    );
    let svg = hstl_pictures::learning_curves(&title, &panels, (episodes / 60).max(1))
        .map_err(|e| CliError::new(format!("cannot draw a picture: {e}"), None))?;
    Ok(vec![OutFile::text("curves.svg", svg), OutFile::text("curves.csv", csv)])
}

/// The y axis of a kind of options reward.
fn reward_axis(kind: RewardKind) -> &'static str {
    match kind {
        RewardKind::Segment => "reward per episode (robustness)",
        RewardKind::Window => "reward per episode (kept windows)",
    }
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_owned()
    }
}

/// The seed whose files stand for the spec: the median by window rate W for a persistent
/// task, by reward (mean of the last 100 episodes) otherwise; of an even number, the lower
/// of the two middle ones, and the lower seed on a tie.
fn median(results: &[RunResult]) -> Median {
    let by_window = results.iter().all(|r| r.window.is_some());
    let by_reach = !by_window && results.iter().all(|r| r.reach_avoid.is_some());
    let key = |r: &RunResult| {
        if by_window {
            r.window.unwrap_or(f64::NAN)
        } else if by_reach {
            r.reach_avoid.map_or(f64::NAN, |p| p.0)
        } else {
            r.tail_reward
        }
    };
    let mut order: Vec<usize> = (0..results.len()).collect();
    order.sort_by(|&a, &b| key(&results[a]).total_cmp(&key(&results[b])).then(a.cmp(&b)));
    let index = order.get(results.len().saturating_sub(1) / 2).copied().unwrap_or(0);
    let Some(r) = results.get(index) else {
        return Median { index, note: "no seed".into() };
    };
    let note = if results.len() == 1 {
        format!("seed {} (the only seed)", r.seed)
    } else if by_window {
        format!(
            "seed {}, the median of {} seeds by window rate (W = {:.3})",
            r.seed,
            results.len(),
            key(r)
        )
    } else if by_reach {
        format!(
            "seed {}, the median of {} seeds by satisfaction rate (P = {:.3})",
            r.seed,
            results.len(),
            key(r)
        )
    } else {
        format!(
            "seed {}, the median of {} seeds by reward (last 100 episodes: {:.2})",
            r.seed,
            results.len(),
            key(r)
        )
    };
    Median { index, note }
}

/// Trains `spec` for seeds `0..seeds` on `threads` workers; results in seed order. With a
/// `budget`, each run's policy and agent are kept while the bytes left allow.
fn run_seeds(
    spec: &TaskSpec,
    env: &GridWorld,
    seeds: u64,
    threads: usize,
    loaded: &spec_file::LoadedSpec,
    budget: Option<&AtomicUsize>,
) -> Result<Vec<RunResult>, CliError> {
    let threads = threads.min(seeds as usize).max(1) as u64;
    let share = |w: u64| {
        (0..seeds)
            .filter(|s| s % threads == w)
            .map(|seed| (seed, one_run(spec, env, seed, loaded, budget)))
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

fn one_run(
    spec: &TaskSpec,
    env: &GridWorld,
    seed: u64,
    loaded: &spec_file::LoadedSpec,
    budget: Option<&AtomicUsize>,
) -> Result<RunResult, CliError> {
    let outcome = train::train(spec, env, seed, &loaded.file, |_, _| {})?;
    let window = train::window_report(spec, env, &outcome.agent, seed)?.map(|(rate, _)| rate);
    let reach_avoid = hstl::train::reach_avoid_summary(spec, env, &outcome.agent, seed)
        .map_err(|e| CliError::new(e.to_string(), None))?
        .map(|r| (r.rate, r.optimum));
    let kept = match budget {
        Some(budget) if budget.load(Ordering::Relaxed) > 0 => {
            let json = train::policy_json(&outcome.policy, &loaded.source, seed)?;
            let bytes = json.len() + agent_bytes(&outcome.agent);
            let reserved = budget
                .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |left| left.checked_sub(bytes))
                .is_ok();
            reserved.then_some((json, outcome.agent))
        }
        _ => None,
    };
    Ok(RunResult {
        seed,
        secs: outcome.secs,
        steps: outcome.steps,
        tail_reward: tail_mean(&outcome.curve, 100),
        window,
        reach_avoid,
        curve: outcome.curve,
        kept,
    })
}

/// About the bytes an agent's tables take.
fn agent_bytes(agent: &Agent) -> usize {
    let words = agent.options.len()
        + agent.flat.iter().map(Vec::len).sum::<usize>()
        + agent.legs.iter().map(Vec::len).sum::<usize>();
    words * std::mem::size_of::<usize>() + agent.terminate.iter().map(Vec::len).sum::<usize>()
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
    let o = solve(&Moves::of(env), &regions, SolveConfig::default())
        .map_err(|e| CliError::new(e.to_string(), Some(crate::eval::SKIP_OPTIMUM.into())))?;
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
    let reach: Vec<(f64, f64)> = results.iter().filter_map(|r| r.reach_avoid).collect();
    if reach.len() == results.len()
        && let Some(&(_, best)) = reach.first()
    {
        row("satisfaction rate P", reach.iter().map(|r| r.0).collect(), 3)?;
        if best > 0.0 {
            row(&format!("P/P* (P* = {best:.4})"), reach.iter().map(|r| r.0 / best).collect(), 3)?;
        }
    }
    Ok(())
}

/// One spec's line of `summary.csv`: the measure (`W/W*` for a persistent task, `P/P*` for
/// a reach-avoid task), its mean and minimum over seeds, and the mean training time.
fn summary_line(label: &str, results: &[RunResult], w_star: Option<f64>) -> String {
    let secs = mean(&results.iter().map(|r| r.secs).collect::<Vec<_>>());
    let reach: Vec<(f64, f64)> = results.iter().filter_map(|r| r.reach_avoid).collect();
    let windows: Vec<f64> = results.iter().filter_map(|r| r.window).collect();
    let (measure, best, ratios) =
        if !reach.is_empty() && reach.len() == results.len() && reach[0].1 > 0.0 {
            let best = reach[0].1;
            ("P/P*", best, reach.iter().map(|r| r.0 / best).collect::<Vec<_>>())
        } else if let Some(w) = w_star.filter(|_| windows.len() == results.len()) {
            ("W/W*", w, windows.iter().map(|x| x / w).collect())
        } else {
            return format!("{},,,,,{secs}\n", csv_field(label));
        };
    let (lo, _) = range(&ratios);
    format!("{},{measure},{best},{},{lo},{secs}\n", csv_field(label), mean(&ratios))
}

/// The median seed's policy, curve and pictures, the learning curves of all seeds, and
/// `seeds.csv` with each seed's figures.
fn write_outputs(
    out: OutDir,
    spec: &TaskSpec,
    env: &GridWorld,
    loaded: &spec_file::LoadedSpec,
    label: &str,
    results: &[RunResult],
    median: &Median,
) -> Result<(), CliError> {
    let Some(chosen) = results.get(median.index) else {
        return Err(CliError::new("the study has no seed to draw", None));
    };
    let seed = chosen.seed;
    // Training is deterministic: a run that was not kept is trained again, to the same bits.
    let (policy, agent) = match &chosen.kept {
        Some((json, agent)) => (json.clone(), agent.clone()),
        None => {
            let outcome = train::train(spec, env, seed, &loaded.file, |_, _| {})?;
            (train::policy_json(&outcome.policy, &loaded.source, seed)?, outcome.agent)
        }
    };
    let mut files = vec![
        OutFile::text("policy.json", policy),
        OutFile::text("curve.csv", artifacts::curve_csv(&chosen.curve)),
    ];
    let mut rng = seeded_rng(seed ^ PICTURE_SEED);
    let regions = artifacts::pictured_regions(loaded)?;
    let captions = artifacts::Captions { subject: label.to_owned(), note: median.note.clone() };
    match artifacts::too_large_to_draw(env) {
        Some(why) => println!("  {why}"),
        None => files
            .extend(artifacts::agent_pictures(spec, env, &regions, &agent, &captions, &mut rng)?),
    }
    let mut seeds =
        String::from("seed,train_secs,steps,reward_last_100,window_rate,satisfaction_rate\n");
    for r in results {
        let window = r.window.map_or(String::new(), |w| w.to_string());
        let sat = r.reach_avoid.map_or(String::new(), |p| p.0.to_string());
        seeds.push_str(&format!(
            "{},{},{},{},{window},{sat}\n",
            r.seed, r.secs, r.steps, r.tail_reward
        ));
    }
    files.push(OutFile::text("seeds.csv", seeds));
    let curves: Vec<Vec<f64>> = results.iter().map(|r| r.curve.clone()).collect();
    files.push(artifacts::curve_picture(
        &format!("{label}: learning curves\n{} seeds of `{}`", curves.len(), spec.name),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
        let mut out: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
            .expect("the folder")
            .map(|e| {
                let e = e.expect("an entry");
                (
                    e.file_name().to_string_lossy().into_owned(),
                    std::fs::read(e.path()).expect("read"),
                )
            })
            .collect();
        out.sort();
        out
    }

    /// Whether the median seed's run was kept or is trained again, its files are the same.
    #[test]
    fn the_median_seed_is_the_same_kept_or_trained_again() {
        let world = LoadedWorld::load("paper").expect("the paper world");
        let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cli/small.hstl"));
        let loaded = spec_file::load(path, None, Some(&world)).expect("loads").expect("checks");
        let spec = loaded.trainable().expect("trainable");
        let dir = tempfile::tempdir().expect("temp dir");
        let mut written = Vec::new();
        for (name, budget) in [("kept", KEEP_BUDGET), ("again", 0)] {
            let budget = AtomicUsize::new(budget);
            let results =
                run_seeds(&spec, &world.world, 3, 2, &loaded, Some(&budget)).expect("trains");
            assert_eq!(results.iter().all(|r| r.kept.is_some()), name == "kept");
            let median = median(&results);
            let out = dir.path().join(name);
            let dir = OutDir::lock(&out).expect("locks");
            write_outputs(dir, &spec, &world.world, &loaded, "small.hstl", &results, &median)
                .expect("writes");
            written.push(files(&out));
        }
        // Every file but `seeds.csv`, whose training times differ.
        let names = |w: &[(String, Vec<u8>)]| w.iter().map(|(n, _)| n.clone()).collect::<Vec<_>>();
        assert_eq!(names(&written[0]), names(&written[1]));
        for ((name, a), (_, b)) in written[0].iter().zip(&written[1]) {
            assert!(name == "seeds.csv" || a == b, "{name} differs");
        }
    }

    #[test]
    fn csv_fields_are_quoted_when_they_must_be() {
        assert_eq!(csv_field("plain.hstl"), "plain.hstl");
        assert_eq!(csv_field("a.hstl, intra remaining"), "\"a.hstl, intra remaining\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }

    #[test]
    fn labels_are_file_names_unless_two_files_share_one() {
        let paths: Vec<PathBuf> =
            ["a/x.hstl", "b/x.hstl", "c/y.hstl"].iter().map(PathBuf::from).collect();
        assert_eq!(labels(&paths), ["a/x.hstl", "b/x.hstl", "y.hstl"]);
    }
}
