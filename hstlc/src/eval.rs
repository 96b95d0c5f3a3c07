//! `hstlc eval`: replay a trained policy and report how well it keeps the task.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use hstl::evaluate::{self, Evaluation, MAX_STARTS, MAX_STEPS, Runs};
use hstl::runtime::optimum::SolveConfig;

use crate::cli_error::CliError;
use crate::output::outln;
use crate::world_arg::world_words;
use crate::{CmdResult, Status, input};
use hstl::study::Stats;

/// Arguments of `hstlc eval`.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// The `policy.json` that `hstlc train` wrote.
    #[arg(value_name = "POLICY.json")]
    pub policy: PathBuf,
    /// Greedy runs, each from a random start (at most 100,000).
    #[arg(long, default_value_t = 100, value_parser = count(MAX_STARTS))]
    pub starts: usize,
    /// Steps per run (at most 1,000,000; a run is kept whole for its robustness) [default:
    /// 2000; on a continuous world, a task that is not persistent runs its horizon]
    #[arg(long, value_parser = count(MAX_STEPS))]
    pub steps: Option<usize>,
    /// Steps at the start of each run that the window rate does not count.
    #[arg(long, default_value_t = 100)]
    pub burn_in: usize,
    /// The seed of the random starts and slips.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Skip the optimum W* (value iteration takes a few seconds).
    #[arg(long)]
    pub no_optimum: bool,
    /// Also write each greedy run as `DIR/run_K.csv` (`t,VAR...,action,option`, one row per
    /// step and one more for the final state), at most the first 1,000 runs.
    #[arg(long, value_name = "DIR")]
    pub runs: Option<PathBuf>,
}

/// Steps per greedy run unless `--steps` says otherwise.
pub const DEFAULT_STEPS: usize = 2000;

/// At most this many runs are written by `--runs`.
pub const MAX_RUN_FILES: usize = 1000;

/// At most this many rows in all, over the runs `--runs` writes (they are built in memory
/// before the folder is written whole).
pub const MAX_RUN_ROWS: usize = 10_000_000;

/// Refuses a `--runs` that would write more than [`MAX_RUN_ROWS`] rows, before anything runs.
/// The checks on what a run writes, made before anything is printed (the burn-in against
/// the task, the rows `--runs` would write), and the `--runs` folder locked.
fn check_and_lock(
    args: &EvalArgs,
    runs: &Runs,
    spec: &hstl::runtime::TaskSpec,
) -> Result<Option<hstl_outdir::OutDir>, CliError> {
    runs.check_burn_in(spec, flag)?;
    check_run_rows(args, runs.steps)?;
    Ok(args
        .runs
        .as_ref()
        .map(|dir| hstl_outdir::OutDir::lock(dir, hstl_outdir::Writer::CLI))
        .transpose()?)
}

fn check_run_rows(args: &EvalArgs, steps: usize) -> Result<(), CliError> {
    let rows = args.starts.min(MAX_RUN_FILES).saturating_mul(steps.saturating_add(1));
    if args.runs.is_some() && rows > MAX_RUN_ROWS {
        return Err(CliError::new(
            format!(
                "--runs would write {rows} rows ({} runs of {} states), more than {MAX_RUN_ROWS}",
                args.starts.min(MAX_RUN_FILES),
                steps.saturating_add(1)
            ),
            Some("lower --starts or --steps, or leave out --runs".to_string()),
        ));
    }
    Ok(())
}

/// The window rate's line: the rate, its range over the runs, and what a kept step is. A
/// one-step window (a safety conjunct `always[0..] !S`, the region `!S`) holds at the step.
fn window_line(
    rate: f64,
    (lo, hi): (f64, f64),
    burn_in: usize,
    regions: &[hstl::runtime::Region],
) -> String {
    let (visits, safe): (Vec<_>, Vec<_>) = regions.iter().partition(|r| r.horizon > 1);
    let mut what = format!(
        "whose windows visit {}",
        visits
            .iter()
            .map(|r| format!("{} within {}", r.name, r.horizon))
            .collect::<Vec<_>>()
            .join(", ")
    );
    if !safe.is_empty() {
        let names: Vec<&str> = safe.iter().map(|r| r.name.as_str()).collect();
        what.push_str(&format!(" and where {} holds", names.join(" and ")));
    }
    format!(
        "  window rate {rate:.4} (runs {lo:.3}-{hi:.3}): share of the steps after a {burn_in}-step burn-in {what}"
    )
}

/// A count flag from 1 to `max`.
fn count(max: usize) -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::new().range(1..=max as u64)
}

/// A setting as `hstlc eval` spells it: `` `--burn-in` ``.
fn flag(name: &str) -> String {
    format!("`--{}`", name.replace('_', "-"))
}

/// The help of an optimum that cannot be computed.
pub const SKIP_OPTIMUM: &str = "pass --no-optimum to skip the optimum W*";

/// Runs `hstlc eval`.
pub fn run(args: &EvalArgs) -> CmdResult {
    let steps = args.steps.unwrap_or(DEFAULT_STEPS);
    let runs = Runs { starts: args.starts, steps, burn_in: args.burn_in, seed: args.seed };
    // The flags first: nothing is read or printed for a run that cannot happen.
    runs.check_budget(flag)?;
    let input::Input { name, text, .. } =
        input::read_text(&args.policy, "<stdin>", input::MAX_POLICY_BYTES, "policy")?;
    if hstl::continuous::is_learned_function_text(&text) {
        return run_continuous(args, &name, &text, runs);
    }
    let replay = evaluate::replay(&text).map_err(|p| p.in_file(&name))?;
    let (spec, env) = (&replay.spec, &replay.env);
    let out = check_and_lock(args, &runs, spec)?;
    // The optimum W* of a persistent task, solved first: one past its budget is an error
    // before anything is printed, not after the report.
    let optimum = if args.no_optimum || spec.regions.is_empty() {
        None
    } else {
        let start = Instant::now();
        let optimum = evaluate::optimum(&replay, SolveConfig::default())
            .map_err(|p| CliError::new(p.message, Some(SKIP_OPTIMUM.into())))?;
        optimum.map(|o| (o, start.elapsed()))
    };
    outln!(
        "policy of `{}` on {}: {} options, {} greedy runs of {} steps (seed {})",
        spec.name,
        world_words(env, None),
        spec.options.len(),
        args.starts,
        steps,
        args.seed
    )?;
    let report = match evaluate::evaluate(&replay, runs)? {
        Evaluation::Robustness { values, complete } => {
            print_robustness(&values, &complete)?;
            // A reach-avoid task: how often it is satisfied, against the best possible.
            let summary = hstl::train::reach_avoid_summary(spec, env, &replay.agent, args.seed)
                .map_err(|e| CliError::new(e.to_string(), None))?;
            if let Some(r) = summary {
                let ratio = if r.optimum > 0.0 {
                    format!("; P/P* = {:.3}", r.rate / r.optimum)
                } else {
                    String::new()
                };
                outln!(
                    "  reach-avoid: satisfied in {:.4} of {} runs of {} states; the optimum P* = {:.4} (dynamic programming){ratio}",
                    r.rate,
                    hstl::train::REACH_AVOID_RUNS,
                    r.run_len,
                    r.optimum
                )?;
            }
            write_runs(out, &replay, args.starts, runs)?;
            return Ok(Status::Clean);
        }
        Evaluation::Window { report } => report,
    };
    let Stats { min: lo, max: hi, .. } = Stats::of(&report.per_rollout);
    outln!("{}", window_line(report.rate, (lo, hi), args.burn_in, &spec.regions))?;
    print_robustness(&report.robustness, &report.complete)?;
    let shares: Vec<f64> = report.kept.iter().flatten().copied().collect();
    if !shares.is_empty() {
        let Stats { mean, min: lo, max: hi, .. } = Stats::of(&shares);
        outln!(
            "  windows kept, over complete windows: the task's body holds on {:.1}% of each run's complete steps (runs {:.1}-{:.1}%)",
            100.0 * mean,
            100.0 * lo,
            100.0 * hi
        )?;
    }
    if let Some(rate) = evaluate::baseline(&replay, runs)? {
        outln!(
            "  hand-written baseline (the regions in turn, each by a shortest path around the walls): window rate {rate:.4}"
        )?;
    }
    if let Some((optimum, took)) = optimum {
        let ratio = if hstl::study::ratio_defined(optimum.gain) {
            format!("W/W* = {:.3}", report.rate / optimum.gain)
        } else {
            hstl::study::RATIO_UNDEFINED.to_string()
        };
        outln!(
            "  optimum W* = {:.4} (in [{:.4}, {:.4}], value iteration, {:.1} s{}): {ratio}",
            optimum.gain.max(0.0),
            optimum.lower.max(0.0),
            optimum.upper.max(0.0),
            took.as_secs_f64(),
            if optimum.converged { "" } else { ", not converged" },
        )?;
    }
    write_runs(out, &replay, args.starts, runs)?;
    Ok(Status::Clean)
}

/// With `--runs DIR`, writes the first [`MAX_RUN_FILES`] greedy runs of a grid policy.
fn write_runs(
    out: Option<hstl_outdir::OutDir>,
    replay: &evaluate::Replay<hstl::runtime::GridWorld>,
    starts: usize,
    runs: hstl::evaluate::Runs,
) -> Result<(), CliError> {
    let Some(out) = out else { return Ok(()) };
    let n = starts.min(MAX_RUN_FILES);
    let files = evaluate::greedy_run_files(replay, n, runs)?;
    let dir = out.path().to_path_buf();
    out.write(&files)?;
    outln!("  wrote {n} greedy runs to {} (run_1.csv ...)", crate::output::shown(&dir))?;
    Ok(())
}

/// `hstlc eval` of a learned function (a continuous world): the window rate of a
/// persistent task or the satisfaction rate of another, with no exact optimum to divide by;
/// `--runs` writes the greedy runs as data.
fn run_continuous(args: &EvalArgs, name: &str, text: &str, runs: Runs) -> CmdResult {
    use hstl::continuous as c;
    let replay = c::replay_text(text).map_err(|p| p.in_file(name))?;
    let spec = &replay.spec;
    // A reach task is decided within its horizon: a longer run only adds rows.
    let steps = match args.steps {
        None if spec.regions.is_empty() => c::task_steps(spec),
        _ => runs.steps,
    };
    let runs = Runs { steps, ..runs };
    let out = check_and_lock(args, &runs, spec)?;
    outln!(
        "policy of `{}` on {}: {} options, tiles {}, {} greedy runs of {} steps (seed {})",
        spec.name,
        hstl::world::words(&replay.world, None),
        spec.options.len(),
        crate::train::tiles_words(&replay.agent.model),
        args.starts,
        steps,
        args.seed
    )?;
    match c::evaluate(&replay, runs)? {
        c::Evaluation::Window(w) => {
            let Stats { min: lo, max: hi, .. } = Stats::of(&w.per_run);
            outln!("{}", window_line(w.rate, (lo, hi), args.burn_in, &spec.regions))?;
            print_clipped_robustness(&w.robustness)?;
        }
        c::Evaluation::Satisfaction { rate } => {
            outln!("  satisfied in {rate:.4} of {} runs of {} steps", args.starts, steps)?;
        }
    }
    // No exact optimum here: a planned reference on the same runs stands beside.
    match hstl::reference::Reference::new(spec, &replay.world).map(|r| r.evaluate(runs)) {
        Ok(c::Evaluation::Window(w)) => outln!(
            "  planned reference: window rate {:.4} on the same runs (no exact optimum on a continuous world)",
            w.rate
        )?,
        Ok(c::Evaluation::Satisfaction { rate }) => outln!(
            "  planned reference: satisfied in {rate:.4} of the same runs (no exact optimum on a continuous world)"
        )?,
        Err(e) => {
            outln!("  no exact optimum on a continuous world, and no reference: {}", e.message)?
        }
    }
    if let Some(out) = out {
        let n = args.starts.min(MAX_RUN_FILES);
        let files: Vec<hstl::artifacts::OutFile> = c::greedy_runs(&replay, n, steps, args.seed)
            .iter()
            .enumerate()
            .map(|(k, run)| {
                hstl::artifacts::OutFile::text(
                    format!("run_{}.csv", k + 1),
                    c::run_csv(&replay, run),
                )
            })
            .collect();
        let dir = out.path().to_path_buf();
        out.write(&files)?;
        outln!("  wrote {n} greedy runs to {} (run_1.csv ...)", crate::output::shown(&dir))?;
    }
    Ok(Status::Clean)
}

/// A robustness figure: three decimals, or three significant digits and an exponent past a
/// million (a world 1e300 wide has robustness values of that size; three decimals of them
/// are three hundred digits).
fn figure(v: f64) -> String {
    if v.is_finite() && v.abs() >= 1e6 { format!("{v:.3e}") } else { format!("{v:.3}") }
}

/// The task's robustness over each run, windows clipped: its mean, least and greatest.
fn print_clipped_robustness(values: &[f64]) -> Result<(), CliError> {
    let Stats { mean, min: lo, max: hi, .. } = Stats::of(values);
    outln!(
        "  task robustness over each run (windows clipped at the run's end): mean {}, min {}, max {}",
        figure(mean),
        figure(lo),
        figure(hi)
    )?;
    Ok(())
}

/// The task's robustness over each run, windows clipped and complete; satisfaction is
/// counted over complete windows, since clipped ones fail a persistent task at the end of
/// nearly every finite run.
fn print_robustness(values: &[f64], complete: &[Option<f64>]) -> Result<(), CliError> {
    print_clipped_robustness(values)?;
    let determined: Vec<f64> = complete.iter().flatten().copied().collect();
    let satisfied = evaluate::satisfied(values, complete);
    let figures = if determined.is_empty() {
        "no run is long enough for one".to_string()
    } else {
        let Stats { mean, min: lo, max: hi, .. } = Stats::of(&determined);
        format!("mean {}, min {}, max {}", figure(mean), figure(lo), figure(hi))
    };
    let short = complete.len() - determined.len();
    let short = match short {
        0 => String::new(),
        1 => " (1 run too short for one, judged with its windows clipped)".to_string(),
        n => format!(" ({n} runs too short for one, judged with their windows clipped)"),
    };
    outln!(
        "  over complete windows (a step counts only if its windows end inside the run): {figures}; satisfied in {satisfied} of {} runs{short}",
        complete.len()
    )
}
