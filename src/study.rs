//! A study: one or more specs trained over many seeds and compared, what `hstlc study` and
//! the Python package's `hstl.study` compute. Both go through here, so their figures agree
//! bit for bit for the same seeds (training time excepted), and so do the files of their
//! output folders ([`spec_files`], [`curves_files`]), which the callers write.
//!
//! Library code reads no clock: the caller passes one ([`Clock`]) to time each seed.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use hstl_lang::CheckedSpec;
use hstl_runtime::eval::RegionTable;
use hstl_runtime::moves::Moves;
use hstl_runtime::optimum::{SolveConfig, solve};
use hstl_runtime::{Agent, GridWorld, RewardKind, TaskSpec, seeded_rng};

use crate::Problem;
use crate::artifacts::{self, Captions, OutFile};
use crate::seeds::PICTURE_SEED;
use crate::train::Trained;

/// Seconds since a fixed moment of the caller's choice (an `Instant` it took): the facade
/// reads no clock of its own.
pub type Clock<'a> = &'a (dyn Fn() -> f64 + Sync);

pub use crate::train::{TAIL, tail_mean};

/// What one seed's training run measured.
#[derive(Clone, Debug, PartialEq)]
pub struct SeedRun {
    /// The seed.
    pub seed: u64,
    /// Seconds spent training (not the evaluation after it), by the caller's clock.
    pub secs: f64,
    /// Primitive steps taken.
    pub steps: u64,
    /// Reward per episode, the mean of the last [`TAIL`] episodes.
    pub reward: f64,
    /// The greedy policy's window rate W, for a persistent task.
    pub window_rate: Option<f64>,
    /// For a reach-avoid task: the greedy policy's satisfaction rate P and the exact
    /// optimal one P*.
    pub satisfaction: Option<(f64, f64)>,
    /// Reward per episode, every episode.
    pub curve: Vec<f64>,
}

/// A trained seed's `policy.json` and greedy agent, kept so that the median seed's files
/// are written without training it again.
#[derive(Clone, Debug)]
pub struct Kept {
    /// The `policy.json` text.
    pub policy: String,
    /// The greedy agent.
    pub agent: Agent,
}

/// How many bytes of trained policies [`run_seeds`] may keep, and the spec's source they
/// are written with.
pub struct Keep<'a> {
    /// The spec's source text, which `policy.json` holds.
    pub source: &'a str,
    /// Bytes left; each kept run takes its share, and past it runs are not kept.
    pub budget: &'a AtomicUsize,
}

/// Trains `spec` in `env` from `seed` and measures the greedy policy (`file` names the
/// spec in messages); the run's figures and what training made.
pub fn run_seed(
    spec: &TaskSpec,
    env: &GridWorld,
    seed: u64,
    file: &str,
    clock: Clock<'_>,
) -> Result<(SeedRun, Trained), Problem> {
    run_seed_until(spec, env, seed, file, clock, None)
}

/// [`run_seed`] that ends training after the episode under way once `stop` is set (and
/// then fails: a study stopped has no figures for the seed).
pub fn run_seed_until(
    spec: &TaskSpec,
    env: &GridWorld,
    seed: u64,
    file: &str,
    clock: Clock<'_>,
    stop: Option<&AtomicBool>,
) -> Result<(SeedRun, Trained), Problem> {
    let start = clock();
    let trained = crate::train::train_until(spec, env, seed, |_, _| until(stop))
        .map_err(|e| crate::train::cannot_train(file, &spec.name, &e))?;
    if stopped(stop) {
        return Err(stopped_problem());
    }
    let secs = clock() - start;
    let window = crate::train::window_summary(spec, env, &trained.agent, seed)
        .map_err(|e| Problem::new(e.to_string(), None))?
        .map(|s| s.rate);
    let satisfaction = crate::train::reach_avoid_summary(spec, env, &trained.agent, seed)
        .map_err(|e| Problem::new(e.to_string(), None))?
        .map(|r| (r.rate, r.optimum));
    let run = SeedRun {
        seed,
        secs,
        steps: trained.steps,
        reward: tail_mean(&trained.curve, TAIL),
        window_rate: window,
        satisfaction,
        curve: trained.curve.clone(),
    };
    Ok((run, trained))
}

/// Trains `spec` for each of `seeds` on up to `threads` threads, each thread taking the next
/// seed not yet taken (seeds differ in length); results in the order of `seeds`. With
/// `keep`, each run's policy and agent are kept while the budget allows. Once `stop` is
/// set, no further seed starts and the call fails (the Python package sets it on Ctrl-C).
#[allow(clippy::too_many_arguments)]
pub fn run_seeds(
    spec: &TaskSpec,
    env: &GridWorld,
    seeds: &[u64],
    threads: usize,
    file: &str,
    clock: Clock<'_>,
    keep: Option<&Keep<'_>>,
    stop: Option<&AtomicBool>,
) -> Result<Vec<(SeedRun, Option<Kept>)>, Problem> {
    // Each thread trains one seed at a time: only as many as fit the memory budget.
    let cost = crate::cost::check(spec, env).map_err(|p| p.in_file(file))?;
    let kept_bytes = keep.map_or(0, |k| k.budget.load(Ordering::Relaxed) as u64);
    let threads =
        crate::cost::threads_within_budget(&cost, kept_bytes, threads.min(seeds.len()).max(1));
    let one = |seed: u64| -> Result<(SeedRun, Option<Kept>), Problem> {
        let (run, trained) = run_seed_until(spec, env, seed, file, clock, stop)?;
        let kept = match keep {
            Some(k) if k.budget.load(Ordering::Relaxed) > 0 => {
                let policy = crate::train::policy_json(&trained.policy, k.source, seed)
                    .map_err(|e| Problem::new(e.to_string(), None))?;
                let bytes = policy.len() + agent_bytes(&trained.agent);
                let reserved = k
                    .budget
                    .fetch_update(Ordering::Relaxed, Ordering::Relaxed, |left| {
                        left.checked_sub(bytes)
                    })
                    .is_ok();
                reserved.then_some(Kept { policy, agent: trained.agent })
            }
            _ => None,
        };
        Ok((run, kept))
    };
    on_threads(seeds, threads, stop, &one)
}

/// `one(seed)` for each of `seeds` on up to `threads` threads, each thread taking the next
/// seed not yet taken; results in the order of `seeds`. Once `stop` is set, no further
/// seed starts and the call fails.
/// Whether `stop` is set.
fn stopped(stop: Option<&AtomicBool>) -> bool {
    stop.is_some_and(|s| s.load(Ordering::Relaxed))
}

/// A training progress callback's answer: break once `stop` is set (Ctrl-C in Python), so
/// that a long seed ends after its episode under way, not at its last one.
fn until(stop: Option<&AtomicBool>) -> std::ops::ControlFlow<()> {
    if stopped(stop) {
        std::ops::ControlFlow::Break(())
    } else {
        std::ops::ControlFlow::Continue(())
    }
}

fn stopped_problem() -> Problem {
    Problem::new("the study was stopped before every seed was trained", None)
}

fn on_threads<T: Send>(
    seeds: &[u64],
    threads: usize,
    stop: Option<&AtomicBool>,
    one: &(dyn Fn(u64) -> Result<T, Problem> + Sync),
) -> Result<Vec<T>, Problem> {
    let threads = threads.min(seeds.len()).max(1);
    type Done<T> = Vec<(usize, Result<T, Problem>)>;
    let next = AtomicUsize::new(0);
    let stopped = || stop.is_some_and(|s| s.load(Ordering::Relaxed));
    let work = || -> Done<T> {
        let mut done = Vec::new();
        while !stopped() {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(&seed) = seeds.get(i) else { break };
            done.push((i, one(seed)));
        }
        done
    };
    let mut all: Done<T> = std::thread::scope(|scope| {
        let work = &work;
        // The calling thread is one of the workers; a thread the system would not start
        // leaves its seeds to the others.
        let workers: Vec<_> = (1..threads)
            .filter_map(|_| std::thread::Builder::new().spawn_scoped(scope, work).ok())
            .collect();
        let mut all = work();
        for worker in workers {
            all.extend(worker.join().unwrap_or_default());
        }
        all
    });
    if stopped() {
        return Err(Problem::new("the study was stopped before every seed was trained", None));
    }
    if all.len() != seeds.len() {
        return Err(Problem::new("a training thread failed", None));
    }
    all.sort_by_key(|(i, _)| *i);
    all.into_iter().map(|(_, r)| r).collect()
}

/// [`run_seeds`] of a spec on a continuous world (its tiling fitted, see
/// [`crate::continuous::fit_tiles`]), as `hstlc study` trains one: each seed with the
/// approximate learner, its greedy policy measured on the runs of evaluation seed
/// `seed ^ EVAL_SEED` ([`crate::continuous::after_training`]). A persistent task's window
/// rate is the run's `window_rate`; another task's satisfaction rate P (no exact optimum
/// exists to pair it with) comes beside the run.
pub fn run_continuous_seeds(
    spec: &TaskSpec,
    world: &hstl_runtime::world::AnyWorld,
    seeds: &[u64],
    threads: usize,
    file: &str,
    clock: Clock<'_>,
    stop: Option<&AtomicBool>,
) -> Result<Vec<(SeedRun, Option<f64>)>, Problem> {
    use crate::continuous as c;
    // Each thread trains one seed at a time: only as many as fit the memory budget (the
    // continuous study keeps no policies; it writes none).
    use hstl_runtime::world::AnyWorld;
    let cost = match world {
        AnyWorld::Plane(w) => crate::cost::check_approx(spec, w),
        AnyWorld::MountainCar(w) => crate::cost::check_approx(spec, w),
        AnyWorld::Grid(_) => Err(Problem::new("a grid world is learned with tables", None)),
    }
    .map_err(|p| p.in_file(file))?;
    let threads = crate::cost::threads_within_budget(&cost, 0, threads.min(seeds.len()).max(1));
    let one = |seed: u64| -> Result<(SeedRun, Option<f64>), Problem> {
        let start = clock();
        let trained = c::train_until(spec, world, seed, |_, _| until(stop))
            .map_err(|e| crate::train::cannot_train(file, &spec.name, &e))?;
        if stopped(stop) {
            return Err(stopped_problem());
        }
        let secs = clock() - start;
        let (window_rate, satisfaction) =
            match c::after_training(spec, world, &trained.agent, seed)? {
                c::Evaluation::Window(w) => (Some(w.rate), None),
                c::Evaluation::Satisfaction { rate } => (None, Some(rate)),
            };
        let run = SeedRun {
            seed,
            secs,
            steps: trained.steps,
            reward: tail_mean(&trained.curve, TAIL),
            window_rate,
            satisfaction: None,
            curve: trained.curve,
        };
        Ok((run, satisfaction))
    };
    on_threads(seeds, threads, stop, &one)
}

/// About the bytes an agent's tables take.
fn agent_bytes(agent: &Agent) -> usize {
    let words = agent.options.len()
        + agent.flat.iter().map(Vec::len).sum::<usize>()
        + agent.legs.iter().map(Vec::len).sum::<usize>();
    words * std::mem::size_of::<usize>() + agent.terminate.iter().map(Vec::len).sum::<usize>()
}

/// The mean, sample standard deviation, least and greatest of some values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stats {
    /// The mean (0 for no values).
    pub mean: f64,
    /// The sample standard deviation (over `n - 1`; 0 for one value).
    pub sd: f64,
    /// The least value (infinity for none).
    pub min: f64,
    /// The greatest value (minus infinity for none).
    pub max: f64,
}

impl Stats {
    /// The figures of `values`.
    pub fn of(values: &[f64]) -> Stats {
        let mean = values.iter().sum::<f64>() / values.len().max(1) as f64;
        let sd = (values.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>()
            / (values.len().max(2) - 1) as f64)
            .sqrt();
        let (min, max) = values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        Stats { mean, sd, min, max }
    }
}

/// A spec's figures over its seeds, as `hstlc study` prints them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Summary {
    /// Training seconds.
    pub seconds: Stats,
    /// Primitive steps per second of training, in millions.
    pub steps_per_second: Stats,
    /// Reward per episode, mean of the last [`TAIL`] episodes.
    pub reward: Stats,
    /// The window rate W, when every seed has one (a persistent task).
    pub window_rate: Option<Stats>,
    /// W / W*, when every seed has W and the optimum is known.
    pub ratio: Option<Stats>,
    /// The satisfaction rate P, when every seed has one (a reach-avoid task).
    pub satisfaction: Option<Stats>,
    /// P / P* and P*, when every seed has P and P* is above 0.
    pub satisfaction_ratio: Option<(Stats, f64)>,
}

/// W* at or below this is 0: no policy keeps the task, and W/W* is undefined.
pub const MIN_OPTIMUM: f64 = 1e-9;

/// Whether W/W* is defined for the optimum `w_star`: at W* = 0 (no policy keeps the task)
/// it is not, and every front end says so in [`RATIO_UNDEFINED`]'s words (an empty cell in
/// CSV, `None` in Python), never NaN or infinity.
pub fn ratio_defined(w_star: f64) -> bool {
    w_star > MIN_OPTIMUM
}

/// What W/W* is when W* = 0.
pub const RATIO_UNDEFINED: &str = "W/W* undefined (W* = 0: no policy keeps the task)";

/// The figures of `runs`, W/W* against `optimum` (none when it is 0, see
/// [`ratio_defined`]).
pub fn summary(runs: &[SeedRun], optimum: Option<f64>) -> Summary {
    let of = |f: &dyn Fn(&SeedRun) -> f64| Stats::of(&runs.iter().map(f).collect::<Vec<_>>());
    let windows: Vec<f64> = runs.iter().filter_map(|r| r.window_rate).collect();
    let all = windows.len() == runs.len();
    let reach: Vec<(f64, f64)> = runs.iter().filter_map(|r| r.satisfaction).collect();
    let all_reach = !runs.is_empty() && reach.len() == runs.len();
    let best = reach.first().map_or(0.0, |r| r.1);
    Summary {
        satisfaction: all_reach.then(|| Stats::of(&reach.iter().map(|r| r.0).collect::<Vec<_>>())),
        satisfaction_ratio: (all_reach && best > 0.0)
            .then(|| (Stats::of(&reach.iter().map(|r| r.0 / best).collect::<Vec<_>>()), best)),
        seconds: of(&|r| r.secs),
        steps_per_second: of(&|r| r.steps as f64 / r.secs.max(1e-9) / 1e6),
        reward: of(&|r| r.reward),
        window_rate: all.then(|| Stats::of(&windows)),
        ratio: optimum
            .filter(|w| all && ratio_defined(*w))
            .map(|w| Stats::of(&windows.iter().map(|x| x / w).collect::<Vec<_>>())),
    }
}

/// The optimum W* of a persistent task on `env` (`None` for a task without regions).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Optimum {
    /// W*.
    pub gain: f64,
    /// Value-iteration sweeps.
    pub iterations: usize,
    /// Whether the bracket closed below the tolerance.
    pub converged: bool,
}

/// W* of `spec`'s regions on `env`, or `None` when the task has no regions.
pub fn optimum(spec: &TaskSpec, env: &GridWorld) -> Result<Option<Optimum>, Problem> {
    if spec.regions.is_empty() {
        return Ok(None);
    }
    let regions = RegionTable::new(spec, env).map_err(|e| Problem::new(e.to_string(), None))?;
    let o = solve(&Moves::of(env), &regions, SolveConfig::default())
        .map_err(|e| Problem::new(e.to_string(), None))?;
    Ok(Some(Optimum { gain: o.gain, iterations: o.iterations, converged: o.converged }))
}

/// The seed whose files stand for a spec, and why.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Median {
    /// Its index among the runs.
    pub index: usize,
    /// Said under the pictures' titles: the seed and what it is the median of.
    pub note: String,
}

/// The seed whose files stand for the spec: the median by window rate W for a persistent
/// task, by reward (mean of the last 100 episodes) otherwise; of an even number, the lower
/// of the two middle ones, and the earlier run on a tie.
pub fn median(runs: &[SeedRun]) -> Median {
    let by_window = runs.iter().all(|r| r.window_rate.is_some());
    let by_reach = !by_window && runs.iter().all(|r| r.satisfaction.is_some());
    let key = |r: &SeedRun| {
        if by_window {
            r.window_rate.unwrap_or(f64::NAN)
        } else if by_reach {
            r.satisfaction.map_or(f64::NAN, |p| p.0)
        } else {
            r.reward
        }
    };
    let mut order: Vec<usize> = (0..runs.len()).collect();
    order.sort_by(|&a, &b| key(&runs[a]).total_cmp(&key(&runs[b])).then(a.cmp(&b)));
    let index = order.get(runs.len().saturating_sub(1) / 2).copied().unwrap_or(0);
    let Some(r) = runs.get(index) else {
        return Median { index, note: "no seed".into() };
    };
    let note = if runs.len() == 1 {
        format!("seed {} (the only seed)", r.seed)
    } else if by_window {
        format!(
            "seed {}, the median of {} seeds by window rate (W = {:.3})",
            r.seed,
            runs.len(),
            key(r)
        )
    } else if by_reach {
        format!(
            "seed {}, the median of {} seeds by satisfaction rate (P = {:.3})",
            r.seed,
            runs.len(),
            key(r)
        )
    } else {
        format!(
            "seed {}, the median of {} seeds by reward (last 100 episodes: {:.2})",
            r.seed,
            runs.len(),
            key(r)
        )
    };
    Median { index, note }
}

/// The median seed's `policy.json` and agent: the kept ones, or trained again (training is
/// deterministic: same seed, same bits).
pub fn median_policy(
    spec: &TaskSpec,
    env: &GridWorld,
    seed: u64,
    source: &str,
    file: &str,
    kept: Option<&Kept>,
) -> Result<Kept, Problem> {
    if let Some(k) = kept {
        return Ok(k.clone());
    }
    let trained = crate::train::train(spec, env, seed, |_, _| {})
        .map_err(|e| crate::train::cannot_train(file, &spec.name, &e))?;
    let policy = crate::train::policy_json(&trained.policy, source, seed)
        .map_err(|e| Problem::new(e.to_string(), None))?;
    Ok(Kept { policy, agent: trained.agent })
}

/// One spec of a study, as its files need it.
pub struct StudiedSpec<'a> {
    /// The runtime's spec (with the study's episodes).
    pub spec: &'a TaskSpec,
    /// The checked spec, for the regions its pictures draw.
    pub checked: &'a CheckedSpec,
    /// The file it came from, as messages name it.
    pub file: &'a str,
    /// Its name in titles and in `curves.csv` (see [`labels`]).
    pub label: &'a str,
}

/// A spec's folder: the median seed's `policy.json`, `curve.csv` and pictures, the
/// learning curves of all seeds (`curve.svg`) and `seeds.csv` with each seed's figures;
/// and why the grid pictures were left out, when the world is too large to draw.
pub fn spec_files(
    studied: &StudiedSpec<'_>,
    env: &GridWorld,
    runs: &[SeedRun],
    median: &Median,
    chosen: &Kept,
) -> Result<(Vec<OutFile>, Option<String>), Problem> {
    let Some(run) = runs.get(median.index) else {
        return Err(Problem::new("the study has no seed to draw", None));
    };
    let spec = studied.spec;
    let mut files = vec![
        OutFile::text("policy.json", chosen.policy.clone()),
        OutFile::text("curve.csv", artifacts::curve_csv(&run.curve)),
    ];
    let mut rng = seeded_rng(run.seed ^ PICTURE_SEED);
    let regions = artifacts::pictured_regions(studied.checked, studied.file)?;
    let captions = Captions { subject: studied.label.to_owned(), note: median.note.clone() };
    let skipped = artifacts::too_large_to_draw(env);
    if skipped.is_none() {
        files.extend(artifacts::agent_pictures(
            spec,
            env,
            &regions,
            &chosen.agent,
            &captions,
            &mut rng,
        )?);
    }
    let mut seeds =
        String::from("seed,train_secs,steps,reward_last_100,window_rate,satisfaction_rate\n");
    for r in runs {
        let window = r.window_rate.map_or(String::new(), |w| w.to_string());
        let sat = r.satisfaction.map_or(String::new(), |p| p.0.to_string());
        seeds.push_str(&format!("{},{},{},{},{window},{sat}\n", r.seed, r.secs, r.steps, r.reward));
    }
    files.push(OutFile::text("seeds.csv", seeds));
    let curves: Vec<Vec<f64>> = runs.iter().map(|r| r.curve.clone()).collect();
    files.push(artifacts::curve_picture(
        &format!("{}: learning curves\n{} seeds of `{}`", studied.label, curves.len(), spec.name),
        &curves,
    )?);
    Ok((files, skipped))
}

/// The header of a study's `summary.csv`; [`summary_line`] gives its rows.
pub const SUMMARY_HEADER: &str = "spec,measure,optimum,ratio_mean,ratio_min,train_secs_mean\n";

/// One spec's line of `summary.csv`: the measure (`W/W*` for a persistent task, `P/P*` for
/// a reach-avoid task), its mean and minimum over seeds (empty where undefined: W* = 0),
/// and the mean training time.
pub fn summary_line(label: &str, runs: &[SeedRun], w_star: Option<f64>) -> String {
    let s = summary(runs, w_star);
    let secs = s.seconds.mean;
    let (measure, best, ratio) = if let Some((ratio, best)) = s.satisfaction_ratio {
        ("P/P*", best, ratio)
    } else if let (Some(ratio), Some(w)) = (s.ratio, w_star) {
        ("W/W*", w, ratio)
    } else if let (Some(_), Some(w)) = (s.window_rate, w_star) {
        // W* = 0: the ratio is undefined, its cells empty.
        return format!("{},W/W*,{w},,,{secs}\n", csv_field(label));
    } else {
        return format!("{},,,,,{secs}\n", csv_field(label));
    };
    format!("{},{measure},{best},{},{},{secs}\n", csv_field(label), ratio.mean, ratio.min)
}

/// One spec's (or variant's) learning curves in the figure of all of them.
#[derive(Clone, Debug, PartialEq)]
pub struct CurveSet {
    /// The legend's and `curves.csv`'s name for it.
    pub label: String,
    /// Its options reward: curves of different kinds get panels of their own.
    pub kind: RewardKind,
    /// Each seed's reward per episode, with the seed.
    pub runs: Vec<(u64, Vec<f64>)>,
}

/// `curves.svg`, the curves of every spec (one panel per kind of options reward, which do
/// not share a scale), and `curves.csv`, every seed's reward per episode; `seeds` is the
/// count the title gives.
pub fn curves_files(curves: &[CurveSet], seeds: usize) -> Result<Vec<OutFile>, Problem> {
    let mut csv = String::from("spec,seed,episode,reward\n");
    for set in curves {
        let spec = csv_field(&set.label);
        for (seed, curve) in &set.runs {
            for (e, r) in curve.iter().enumerate() {
                csv.push_str(&format!("{spec},{seed},{},{r}\n", e + 1));
            }
        }
    }
    let mut panels: Vec<(RewardKind, hstl_pictures::Panel)> = Vec::new();
    for set in curves {
        let series = hstl_pictures::Series {
            label: set.label.clone(),
            seeds: set.runs.iter().map(|(_, c)| c.clone()).collect(),
        };
        match panels.iter_mut().find(|(k, _)| *k == set.kind) {
            Some((_, panel)) => panel.series.push(series),
            None => panels.push((
                set.kind,
                hstl_pictures::Panel {
                    y_label: reward_axis(set.kind).into(),
                    series: vec![series],
                },
            )),
        }
    }
    let panels: Vec<hstl_pictures::Panel> = panels.into_iter().map(|(_, p)| p).collect();
    let episodes =
        curves.iter().flat_map(|s| s.runs.iter().map(|(_, c)| c.len())).max().unwrap_or(0);
    let plural = if seeds == 1 { "" } else { "s" };
    let title = format!(
        "Learning curves of {} spec{}\n{seeds} seed{plural} each",
        curves.len(),
        if curves.len() == 1 { "" } else { "s" }
    );
    let svg = hstl_pictures::learning_curves(&title, &panels, (episodes / 60).max(1))
        .map_err(|e| Problem::new(format!("cannot draw a picture: {e}"), None))?;
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
pub fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_owned()
    }
}

/// The name of each spec in the legend and in `curves.csv`: its file name, or the path as
/// given where two files share a name.
pub fn labels(paths: &[PathBuf]) -> Vec<String> {
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

/// Each spec's folder under `out`: its file's stem, and `-2`, `-3`, ... after a stem that an
/// earlier spec of the list has (ignoring case): `a/spec.hstl b/spec.hstl` get `spec` and
/// `spec-2`.
pub fn spec_dirs(out: &Path, specs: &[PathBuf]) -> Vec<PathBuf> {
    let mut taken = std::collections::HashSet::new();
    specs
        .iter()
        .map(|path| {
            let stem = path
                .file_stem()
                .map_or("spec".into(), |s| artifacts::file_safe(&s.to_string_lossy()));
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

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "spec Small {
    state { x: int in 0..=14, y: int in 0..=14 }
    let A = x > 10 && y > 10;
    let B = x < 4 && y < 4;
    task always[0..] (eventually[0..40] A && eventually[0..40] B);
    option A;
    option B;
    options { A, B }
    learn { episodes: 30, choices: 10 }
}
";

    fn small() -> (crate::load::Loaded, TaskSpec, GridWorld) {
        let world = GridWorld::builtin("paper").expect("paper");
        let loaded = crate::load::load_in_world(SMALL, None, &world, "world `paper`")
            .unwrap_or_else(|e| panic!("{e}"));
        let spec = crate::train::trainable(&loaded.spec, SMALL, "small.hstl").expect("trains");
        (loaded, spec, world)
    }

    fn no_clock() -> f64 {
        0.0
    }

    #[test]
    fn threads_do_not_change_a_seed_s_figures() {
        let (_, spec, world) = small();
        let seeds = [4, 0, 7, 1, 2];
        let one = run_seeds(&spec, &world, &seeds, 1, "small.hstl", &no_clock, None, None)
            .expect("trains");
        let three = run_seeds(&spec, &world, &seeds, 3, "small.hstl", &no_clock, None, None)
            .expect("trains");
        let runs =
            |v: Vec<(SeedRun, Option<Kept>)>| v.into_iter().map(|(r, _)| r).collect::<Vec<_>>();
        let (one, three) = (runs(one), runs(three));
        assert_eq!(one, three);
        assert_eq!(one.iter().map(|r| r.seed).collect::<Vec<_>>(), seeds);
        // Each run is the one `hstl::train` makes for its seed.
        let (run, trained) = run_seed(&spec, &world, 7, "small.hstl", &no_clock).expect("trains");
        assert_eq!(run, one[2]);
        assert_eq!(trained.curve, one[2].curve);
        assert_eq!(run.reward, tail_mean(&trained.curve, TAIL));
        assert!(run.window_rate.is_some_and(|w| (0.0..=1.0).contains(&w)));
    }

    #[test]
    fn a_study_stopped_trains_no_further_seed() {
        let (_, spec, world) = small();
        let stop = AtomicBool::new(true);
        let e = run_seeds(&spec, &world, &[0, 1], 2, "small.hstl", &no_clock, None, Some(&stop))
            .expect_err("stopped");
        assert_eq!(e.message, "the study was stopped before every seed was trained");
    }

    #[test]
    fn stats_are_the_sample_figures() {
        let s = Stats::of(&[1.0, 2.0, 6.0]);
        assert_eq!((s.mean, s.min, s.max), (3.0, 1.0, 6.0));
        assert_eq!(s.sd, (7.0f64).sqrt());
        // One value has no spread; none has the empty range.
        assert_eq!(Stats::of(&[5.0]).sd, 0.0);
        let none = Stats::of(&[]);
        assert_eq!((none.mean, none.min, none.max), (0.0, f64::INFINITY, f64::NEG_INFINITY));
    }

    #[test]
    fn no_policy_keeps_the_task_and_the_ratio_is_undefined_not_nan() {
        let run = |w: f64| SeedRun {
            seed: 0,
            window_rate: Some(w),
            satisfaction: None,
            reward: 0.0,
            secs: 1.0,
            steps: 1,
            curve: vec![],
        };
        let runs = [run(0.0), run(0.0)];
        assert_eq!(summary(&runs, Some(0.0)).ratio, None);
        let line = summary_line("zero.hstl", &runs, Some(0.0));
        assert_eq!(line, "zero.hstl,W/W*,0,,,1\n");
    }

    #[test]
    fn the_summary_has_w_over_w_star_only_where_every_seed_has_w() {
        let run = |seed, w: Option<f64>| SeedRun {
            seed,
            secs: 0.5,
            steps: 1_000_000,
            reward: seed as f64,
            window_rate: w,
            satisfaction: None,
            curve: vec![],
        };
        let runs = [run(0, Some(0.4)), run(1, Some(0.8))];
        let s = summary(&runs, Some(0.8));
        assert_eq!(s.ratio.map(|r| (r.min, r.max)), Some((0.5, 1.0)));
        assert_eq!(s.steps_per_second.mean, 2.0);
        let partial = [run(0, Some(0.4)), run(1, None)];
        assert_eq!(summary(&partial, Some(0.8)).window_rate, None);
        assert_eq!(summary(&partial, Some(0.8)).ratio, None);
        // The median is by W when every seed has it, by reward otherwise.
        assert_eq!(median(&runs).index, 0);
        let three = [run(0, None), run(5, None), run(2, None)];
        assert_eq!(median(&three).index, 2);
        assert_eq!(
            median(&three).note,
            "seed 2, the median of 3 seeds by reward (last 100 episodes: 2.00)"
        );
    }

    #[test]
    fn a_kept_median_and_one_trained_again_give_the_same_files() {
        let (loaded, spec, world) = small();
        let budget = AtomicUsize::new(1 << 30);
        let keep = Keep { source: SMALL, budget: &budget };
        let done =
            run_seeds(&spec, &world, &[0, 1, 2], 2, "small.hstl", &no_clock, Some(&keep), None)
                .expect("trains");
        let (runs, kept): (Vec<SeedRun>, Vec<Option<Kept>>) = done.into_iter().unzip();
        let m = median(&runs);
        let studied =
            StudiedSpec { spec: &spec, checked: &loaded.spec, file: "small.hstl", label: "small" };
        let seed = runs[m.index].seed;
        let files = |k: Option<&Kept>| {
            let chosen =
                median_policy(&spec, &world, seed, SMALL, "small.hstl", k).expect("policy");
            spec_files(&studied, &world, &runs, &m, &chosen).expect("files").0
        };
        let (a, b) = (files(kept[m.index].as_ref()), files(None));
        assert!(kept[m.index].is_some());
        assert_eq!(a, b);
        let names: Vec<&str> = a.iter().map(|f| f.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "policy.json",
                "curve.csv",
                "flat_A.svg",
                "flat_B.svg",
                "options.svg",
                "run_1.svg",
                "run_2.svg",
                "seeds.csv",
                "curve.svg"
            ]
        );
    }

    #[test]
    fn labels_dirs_and_csv_fields() {
        let paths: Vec<PathBuf> =
            ["a/x.hstl", "b/x.hstl", "c/y.hstl"].iter().map(PathBuf::from).collect();
        assert_eq!(labels(&paths), ["a/x.hstl", "b/x.hstl", "y.hstl"]);
        let dirs = spec_dirs(Path::new("out"), &paths);
        assert_eq!(dirs, [Path::new("out/x"), Path::new("out/x-2"), Path::new("out/y")]);
        assert_eq!(csv_field("a.hstl, intra remaining"), "\"a.hstl, intra remaining\"");
        assert_eq!(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
    }
}
