//! `hstlc study`: train several specs over many seeds, compare them, and write each one's
//! pictures. The paper's case study is `scripts/case-study`, which runs this on the seven
//! variants in `examples/specs/`. The figures and the files come from the facade
//! (`hstl::study`), which the Python package's `hstl.study` calls too; this module prints
//! and writes them.

use std::path::PathBuf;
use std::sync::atomic::AtomicUsize;
use std::time::Instant;

use clap::Args;
use hstl::artifacts::OutFile;
use hstl::runtime::{GridWorld, Intra, Region, TaskSpec};
use hstl::study::{self as facade, CurveSet, Keep, Kept, SeedRun, Stats, StudiedSpec};
use hstl::world::AnyWorld;
use hstl_outdir::{OutDir, StudyDir, Writer};

use crate::cli_error::CliError;
use crate::output::outln;
use crate::train;
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
    /// The grid world to train every spec in, instead of the ones they name (default:
    /// `paper` for a spec that names none).
    #[arg(long, value_name = "NAME|FILE.toml", long_help = WORLD_HELP)]
    pub world: Option<String>,
    /// Worker threads (default: every core; at most 256).
    #[arg(long, value_parser = clap::builder::RangedU64ValueParser::<usize>::new().range(1..=256))]
    pub threads: Option<usize>,
    /// The folder for each spec's policy and pictures (of its median seed), curves and
    /// per-seed figures (`seeds.csv`), and the learning curves of all specs in one figure
    /// (`curves.svg`, with every seed's in `curves.csv`).
    #[arg(long, value_name = "DIR", default_value = "out/study")]
    pub out: PathBuf,
    /// Replace files at the top of `--out` that no study wrote (`curves.csv`, `curves.svg`,
    /// `summary.csv`), and remove other runs' folders there that this study does not write
    /// (otherwise either refuses the run before any training).
    #[arg(long)]
    pub force: bool,
}

/// The bytes of trained policies a study keeps in memory for the median seed's files; past
/// it, the median seed is trained again (same seed, same bits) instead.
const KEEP_BUDGET: usize = 256 << 20;

/// Runs `hstlc study`.
pub fn run(args: &StudyArgs) -> CmdResult {
    // Check every spec against the world before the long part starts.
    let mut loaded = Vec::new();
    let mut worlds: Vec<LoadedWorld> = Vec::new();
    for path in &args.specs {
        let Some((l, world)) = spec_file::load_trainable(path, None, args.world.as_deref())? else {
            return Ok(Status::Errors);
        };
        let mut spec = l.trainable()?;
        if let Some(e) = args.episodes {
            spec.learn.episodes = e;
        }
        loaded.push((path.clone(), l, spec));
        worlds.push(world);
    }
    // Each spec's folder, taken before the long part: a folder another run holds is
    // refused at once, and two specs of one name get folders of their own.
    // The study's own folder is held too, and its top files (written last) must describe
    // every spec folder in it: another run's folder there, or a user's `summary.csv`, is
    // refused now unless `--force`.
    let spec_dirs = facade::spec_dirs(&args.out, &args.specs);
    let (study_dir, outs) = StudyDir::take(&args.out, &spec_dirs, args.force, Writer::CLI)?;
    let threads = args
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, usize::from))
        .max(1);
    let one_world = worlds.windows(2).all(|w| w[0].world == w[1].world);
    let on = match worlds.first() {
        Some(w) if one_world => w.words(),
        _ => "the worlds they name".to_string(),
    };
    outln!("study: {} specs x {} seeds on {on}, {threads} threads", loaded.len(), args.seeds)?;
    let seeds: Vec<u64> = (0..args.seeds).collect();
    let mut optima: Vec<(Vec<Region>, GridWorld, f64)> = Vec::new();
    let mut baseline: Option<(String, f64, hstl::runtime::RewardKind)> = None;
    let labels = facade::labels(&args.specs);
    // Every spec's (and variant's) curves, for the figure of all of them.
    let mut all_curves: Vec<CurveSet> = Vec::new();
    let mut summary = String::from(facade::SUMMARY_HEADER);
    for ((((_, l, spec), label), out), world) in loaded.iter().zip(&labels).zip(outs).zip(&worlds) {
        let env = match &world.world {
            AnyWorld::Grid(g) => g,
            continuous => {
                let (line, curves) =
                    continuous_spec(spec, l, label, continuous, &seeds, threads, out)?;
                summary.push_str(&line);
                all_curves.push(curves);
                continue;
            }
        };
        let budget = AtomicUsize::new(KEEP_BUDGET);
        let keep = Keep { source: &l.source, budget: &budget };
        let (results, kept) = run_seeds(spec, env, &seeds, threads, l, Some(&keep))?;
        let w_star = if args.no_optimum || spec.regions.is_empty() {
            None
        } else {
            Some(optimum(&mut optima, spec, env)?)
        };
        outln!()?;
        if !one_world {
            outln!("{label}: on {}", world.words())?;
        }
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
        summary.push_str(&facade::summary_line(label, &results, w_star));
        let reward = facade::Stats::of(&results.iter().map(|r| r.reward).collect::<Vec<_>>()).mean;
        // Rewards compare only under the same options-level reward.
        match &baseline {
            None => baseline = Some((label.clone(), reward, spec.learn.reward)),
            Some((base, b, kind)) if *kind == spec.learn.reward && *b == 0.0 => {
                outln!("  reward not compared with {base}: its mean reward per episode is 0")?
            }
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
            let (alt, _) = run_seeds(&other, env, &seeds, threads, l, None)?;
            outln!("  with intra: {} instead:", intra_word(other.learn.intra))?;
            print_table(&alt, w_star)?;
            variant = Some(CurveSet {
                label: format!("{label}, intra {}", intra_word(other.learn.intra)),
                kind: other.learn.reward,
                runs: alt.into_iter().map(|r| (r.seed, r.curve)).collect(),
            });
        }
        let dir = out.path().to_path_buf();
        let median = facade::median(&results);
        outln!("  policy.json and pictures: {}", median.note)?;
        let studied = StudiedSpec { spec, checked: &l.spec, file: &l.file, label };
        let seed = results.get(median.index).map_or(0, |r| r.seed);
        let chosen = facade::median_policy(
            spec,
            env,
            seed,
            &l.source,
            &l.file,
            kept.get(median.index).and_then(Option::as_ref),
        )?;
        let (files, skipped) = facade::spec_files(&studied, env, &results, &median, &chosen)?;
        if let Some(why) = skipped {
            outln!("  {why}")?;
        }
        out.write(&files)?;
        outln!("  wrote {}", crate::output::shown(&dir))?;
        // The variant's curves follow the spec's in the figure.
        all_curves.push(CurveSet {
            label: label.clone(),
            kind: spec.learn.reward,
            runs: results.into_iter().map(|r| (r.seed, r.curve)).collect(),
        });
        all_curves.extend(variant);
    }
    let mut files = facade::curves_files(&all_curves, seeds.len())?;
    files.push(OutFile::text("summary.csv", summary));
    study_dir.write(&files, &spec_dirs)?;
    outln!()?;
    outln!(
        "wrote {} and {}: the learning curves of every spec; {}: each spec's measure",
        crate::output::shown(&args.out.join("curves.svg")),
        crate::output::shown(&args.out.join("curves.csv")),
        crate::output::shown(&args.out.join("summary.csv"))
    )?;
    Ok(Status::Clean)
}

/// One spec of a study on a continuous world: each seed trained with the approximate
/// learner and its greedy policy measured (the window rate W of a persistent task, the
/// satisfaction rate P of another; no exact optimum exists to divide by), the table
/// printed, the median seed's `policy.json` and curve written. Returns its `summary.csv`
/// line (the measure's own mean and minimum, the optimum empty) and its curves.
fn continuous_spec(
    spec: &TaskSpec,
    l: &spec_file::LoadedSpec,
    label: &str,
    world: &AnyWorld,
    seeds: &[u64],
    threads: usize,
    out: OutDir,
) -> Result<(String, CurveSet), CliError> {
    use hstl::continuous as c;
    let mut spec = spec.clone();
    c::fit_tiles(&mut spec, &l.spec, world);
    // Each seed as `hstl.study` trains it (the facade's), timed by this process's clock.
    let start = Instant::now();
    let clock = move || start.elapsed().as_secs_f64();
    let done = facade::run_continuous_seeds(&spec, world, seeds, threads, &l.file, &clock, None)
        .map_err(|p| CliError::new(p.message, p.help))?;
    let mut runs: Vec<(usize, SeedResult)> = done
        .into_iter()
        .enumerate()
        .map(|(i, (run, satisfaction))| {
            let rate = run.window_rate.or(satisfaction).ok_or_else(|| {
                CliError::new(format!("seed {} measured neither W nor P", run.seed), None)
            })?;
            Ok((i, SeedResult { rate, secs: run.secs, steps: run.steps, curve: run.curve }))
        })
        .collect::<Result<_, CliError>>()?;
    runs.sort_by_key(|r| r.0);
    let persistent = !spec.regions.is_empty();
    let measure = if persistent { "W" } else { "P" };
    let rates: Vec<f64> = runs.iter().map(|r| r.1.rate).collect();
    let secs: Vec<f64> = runs.iter().map(|r| r.1.secs).collect();
    let speed: Vec<f64> =
        runs.iter().map(|r| r.1.steps as f64 / r.1.secs.max(1e-9) / 1e6).collect();
    let rewards: Vec<f64> =
        runs.iter().map(|r| facade::tail_mean(&r.1.curve, facade::TAIL)).collect();
    outln!()?;
    outln!(
        "{label}: `{}` on a continuous world, {} options, {} seeds x {} episodes x {} choices, tiles {}",
        spec.name,
        spec.options.len(),
        seeds.len(),
        spec.learn.episodes,
        spec.learn.choices,
        spec.learn.tiles.as_ref().map_or(String::new(), |t| format!(
            "{} tilings of {}",
            t.tilings,
            t.bins.iter().map(usize::to_string).collect::<Vec<_>>().join(" x ")
        ))
    )?;
    let row = |name: &str, s: Stats, digits: usize| {
        let Stats { mean: m, sd, min: lo, max: hi } = s;
        outln!("  {name:<34} {m:>9.digits$} {sd:>9.digits$} {lo:>9.digits$} {hi:>9.digits$}")
    };
    outln!("  {:<34} {:>9} {:>9} {:>9} {:>9}", "", "mean", "sd", "min", "max")?;
    row("training time (s)", Stats::of(&secs), 3)?;
    row("primitive steps/s (millions)", Stats::of(&speed), 2)?;
    row("reward per episode (last 100)", Stats::of(&rewards), 2)?;
    let name = if persistent { "window rate W" } else { "satisfaction rate P" };
    row(name, Stats::of(&rates), 3)?;
    // No exact optimum here: a planned reference, scored on the same runs, stands beside.
    let planned: Result<Vec<f64>, String> = hstl::reference::Reference::new(&spec, world)
        .map(|reference| {
            seeds
                .iter()
                .map(|&s| match reference.evaluate(c::runs_after_training(&spec, s)) {
                    c::Evaluation::Window(w) => w.rate,
                    c::Evaluation::Satisfaction { rate } => rate,
                })
                .collect()
        })
        .map_err(|e| e.message);
    match &planned {
        Ok(planned) => {
            let ratio: Vec<f64> =
                rates.iter().zip(planned).filter(|(_, p)| **p > 0.0).map(|(r, p)| r / p).collect();
            row(&format!("planned reference {measure}"), Stats::of(planned), 3)?;
            if ratio.len() == rates.len() {
                row(&format!("{measure} / reference"), Stats::of(&ratio), 3)?;
            } else {
                outln!(
                    "  {measure} / reference undefined: the reference keeps nothing on some seeds"
                )?;
            }
            outln!(
                "  no exact optimum on a continuous world; the reference is a planner (LANGUAGE.md, \"References\")"
            )?;
        }
        Err(e) => outln!("  no exact optimum on a continuous world, and no reference: {e}")?,
    }
    // The median seed by the measure; its policy is trained again (same seed, same bits).
    let mut order: Vec<usize> = (0..runs.len()).collect();
    order.sort_by(|&a, &b| rates[a].total_cmp(&rates[b]).then(a.cmp(&b)));
    let median = order.get(runs.len().saturating_sub(1) / 2).copied().unwrap_or(0);
    let seed = seeds.get(median).copied().unwrap_or(0);
    let trained =
        c::train(&spec, world, seed, |_, _| {}).map_err(|e| CliError::new(e.to_string(), None))?;
    let policy = c::policy_json(&spec, world, &trained.agent, &l.source, seed)
        .map_err(|e| CliError::new(e.to_string(), None))?;
    let reference_at = |i: usize| {
        planned.as_ref().ok().and_then(|p| p.get(i)).map_or(String::new(), f64::to_string)
    };
    let seeds_csv: String =
        std::iter::once(format!("seed,{measure},reward,train_secs,reference_{measure}\n"))
            .chain(runs.iter().map(|(i, r)| {
                format!(
                    "{},{},{},{},{}\n",
                    seeds[*i],
                    r.rate,
                    facade::tail_mean(&r.curve, facade::TAIL),
                    r.secs,
                    reference_at(*i)
                )
            }))
            .collect();
    let mut files = vec![
        OutFile::text("policy.json", policy),
        OutFile::text("curve.csv", hstl::artifacts::curve_csv(&trained.curve)),
        OutFile::text("seeds.csv", seeds_csv),
    ];
    // The median seed's pictures, as `train` draws them.
    let subject = hstl::artifacts::subject(&l.file, None);
    files.extend(hstl::artifacts::plane_pictures(
        &spec,
        world,
        &l.spec,
        &trained.agent,
        &subject,
        seed,
    )?);
    let dir = out.path().to_path_buf();
    out.write(&files)?;
    outln!(
        "  policy.json: seed {seed}, the median of {} seeds by {measure} ({:.3})",
        runs.len(),
        rates[median]
    )?;
    outln!("  wrote {}", crate::output::shown(&dir))?;
    let s = Stats::of(&rates);
    let line = format!(
        "{},{measure},,{},{},{}\n",
        facade::csv_field(label),
        s.mean,
        s.min,
        Stats::of(&secs).mean
    );
    let curves = CurveSet {
        label: label.to_string(),
        kind: spec.learn.reward,
        runs: runs.into_iter().map(|(i, r)| (seeds[i], r.curve)).collect(),
    };
    Ok((line, curves))
}

/// What one seed of a continuous study measured.
struct SeedResult {
    /// W or P.
    rate: f64,
    secs: f64,
    steps: u64,
    curve: Vec<f64>,
}

/// Trains `spec` for `seeds` on `threads` workers, timed by this process's clock.
fn run_seeds(
    spec: &TaskSpec,
    env: &GridWorld,
    seeds: &[u64],
    threads: usize,
    loaded: &spec_file::LoadedSpec,
    keep: Option<&Keep<'_>>,
) -> Result<(Vec<SeedRun>, Vec<Option<Kept>>), CliError> {
    let start = Instant::now();
    let clock = move || start.elapsed().as_secs_f64();
    let done = facade::run_seeds(spec, env, seeds, threads, &loaded.file, &clock, keep, None)?;
    Ok(done.into_iter().unzip())
}

/// W* for the spec's regions, solved once per distinct region set.
fn optimum(
    cache: &mut Vec<(Vec<Region>, GridWorld, f64)>,
    spec: &TaskSpec,
    env: &GridWorld,
) -> Result<f64, CliError> {
    if let Some((_, _, w)) = cache.iter().find(|(r, e, _)| *r == spec.regions && e == env) {
        return Ok(*w);
    }
    let start = Instant::now();
    let o = facade::optimum(spec, env)
        .map_err(|p| CliError::new(p.message, Some(crate::eval::SKIP_OPTIMUM.into())))?
        .ok_or_else(|| CliError::new("the task has no regions to keep", None))?;
    outln!(
        "optimum for regions {}: W* = {:.4} (value iteration, {} sweeps, {:.1} s{})",
        spec.regions.iter().map(|r| r.name.as_str()).collect::<Vec<_>>().join(", "),
        o.gain,
        o.iterations,
        start.elapsed().as_secs_f64(),
        if o.converged { "" } else { ", not converged" }
    )?;
    cache.push((spec.regions.clone(), env.clone(), o.gain));
    Ok(o.gain)
}

fn print_table(results: &[SeedRun], w_star: Option<f64>) -> Result<(), CliError> {
    let row = |name: &str, s: Stats, digits: usize| {
        let Stats { mean: m, sd, min: lo, max: hi } = s;
        outln!("  {name:<34} {m:>9.digits$} {sd:>9.digits$} {lo:>9.digits$} {hi:>9.digits$}")
    };
    let s = facade::summary(results, w_star);
    outln!("  {:<34} {:>9} {:>9} {:>9} {:>9}", "", "mean", "sd", "min", "max")?;
    row("training time (s)", s.seconds, 3)?;
    row("primitive steps/s (millions)", s.steps_per_second, 2)?;
    row("reward per episode (last 100)", s.reward, 2)?;
    if let Some(w) = s.window_rate {
        row("window rate W", w, 3)?;
        match (s.ratio, w_star) {
            (Some(r), Some(w)) => row(&format!("W/W* (W* = {w:.4})"), r, 3)?,
            (None, Some(_)) => outln!("  {}", facade::RATIO_UNDEFINED)?,
            _ => {}
        }
    }
    if let Some(p) = s.satisfaction {
        row("satisfaction rate P", p, 3)?;
        if let Some((r, best)) = s.satisfaction_ratio {
            row(&format!("P/P* (P* = {best:.4})"), r, 3)?;
        }
    }
    Ok(())
}

fn intra_word(i: Intra) -> &'static str {
    match i {
        Intra::Paper => "paper",
        Intra::Remaining => "remaining",
    }
}
