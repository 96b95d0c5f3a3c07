//! `hstlc eval`: replay a trained policy and report how well it keeps the task.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;
use hstl::robustness::{Trace, offline};
use hstl::runtime::eval::{
    AgentController, EntryCycle, RegionTable, WindowConfig, rollout, window_rate,
};
use hstl::runtime::optimum::{Moves, SolveConfig, solve};
use hstl::runtime::policy::EnvInfo;
use hstl::runtime::{Env, GridWorld, Policy, TaskSpec, seeded_rng};

use crate::artifacts;
use crate::cli_error::CliError;
use crate::output::outln;
use crate::study::{mean, range};
use crate::world_arg::world_words;
use crate::{CmdResult, Status, input};

/// Arguments of `hstlc eval`.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// The `policy.json` that `hstlc train` wrote.
    #[arg(value_name = "POLICY.json")]
    pub policy: PathBuf,
    /// Greedy runs, each from a random start (at most 100,000).
    #[arg(long, default_value_t = 100, value_parser = count(100_000))]
    pub starts: usize,
    /// Steps per run (at most 1,000,000; a run is kept whole for its robustness).
    #[arg(long, default_value_t = 2000, value_parser = count(1_000_000))]
    pub steps: usize,
    /// Steps at the start of each run that the window rate does not count.
    #[arg(long, default_value_t = 100)]
    pub burn_in: usize,
    /// The seed of the random starts and slips.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Skip the optimum W* (value iteration takes a few seconds).
    #[arg(long)]
    pub no_optimum: bool,
}

/// At most this many steps over all runs of one evaluation.
const MAX_EVAL_STEPS: usize = 200_000_000;

/// A count flag from 1 to `max`.
fn count(max: u64) -> clap::builder::RangedU64ValueParser<usize> {
    clap::builder::RangedU64ValueParser::new().range(1..=max)
}

/// The help of an optimum that cannot be computed.
pub const SKIP_OPTIMUM: &str = "pass --no-optimum to skip the optimum W*";

/// Runs `hstlc eval`.
pub fn run(args: &EvalArgs) -> CmdResult {
    // The flags first: nothing is read or printed for a run that cannot happen.
    if args.starts.saturating_mul(args.steps) > MAX_EVAL_STEPS {
        return Err(CliError::new(
            format!(
                "{} runs of {} steps are more than the {MAX_EVAL_STEPS} steps an evaluation may take",
                args.starts, args.steps
            ),
            Some("lower `--starts` or `--steps`".into()),
        ));
    }
    let input::Input { name, text, .. } =
        input::read_text(&args.policy, "<stdin>", input::MAX_POLICY_BYTES, "policy")?;
    let bad = |message: String, help: &str| {
        CliError::new(format!("{name}: {message}"), Some(help.to_string()))
    };
    let policy = Policy::from_json(&text)
        .map_err(|e| bad(e.to_string(), "pass the policy.json that `hstlc train` wrote"))?;
    let spec = spec_of(&text, &policy.spec)
        .map_err(|m| bad(m, "train the policy again with `hstlc train`"))?;
    let env = GridWorld::from_params(&policy.env.name, &policy.env.params).map_err(|e| {
        bad(
            format!("its world: {e}"),
            "the `env` entry must hold the world `hstlc train` wrote (`slip` and `map`)",
        )
    })?;
    let mut policy = policy;
    if policy.env.params.get("map").is_none() {
        // Written before world files: the open grid it was, in today's terms.
        policy.env = EnvInfo { name: env.name().to_string(), params: env.params() };
    }
    policy.check_against(&spec, &env).map_err(|e| {
        bad(
            e.to_string(),
            "the file was edited or damaged: train the policy again with `hstlc train`",
        )
    })?;
    let agent =
        policy.agent(&env).map_err(|e| bad(e.to_string(), "the policy does not fit its world"))?;
    let config = WindowConfig { starts: args.starts, steps: args.steps, burn_in: args.burn_in };
    if !spec.regions.is_empty() && args.burn_in >= args.steps {
        return Err(CliError::new(
            format!(
                "a burn-in of {} steps leaves nothing of {}-step runs",
                args.burn_in, args.steps
            ),
            Some("use `--burn-in` smaller than `--steps`".into()),
        ));
    }
    let mut rng = seeded_rng(args.seed);
    outln!(
        "policy of `{}` on {}: {} options, {} greedy runs of {} steps (seed {})",
        spec.name,
        world_words(&env, None),
        spec.options.len(),
        args.starts,
        args.steps,
        args.seed
    )?;
    if spec.regions.is_empty() {
        // Not a persistent task: the task's robustness over each run is the measure.
        let all_states = artifacts::state_trace(&spec, &env)?;
        let mut controller = AgentController::new(&agent);
        let mut values = Vec::with_capacity(args.starts);
        for _ in 0..args.starts {
            let start = env.index(&env.reset(&mut rng));
            let states: Vec<usize> = rollout(&env, &mut controller, start, args.steps, &mut rng)
                .iter()
                .map(|s| s.state)
                .collect();
            values.push(robustness_of_run(&spec, &all_states, &states)?);
        }
        print_robustness(&values)?;
        return Ok(Status::Clean);
    }
    let regions = RegionTable::new(&spec, &env).map_err(|e| CliError::new(e.to_string(), None))?;
    let report = window_rate(&env, &mut AgentController::new(&agent), &regions, config, &mut rng)
        .map_err(|e| {
        CliError::new(
            e.to_string(),
            Some("use --burn-in smaller than --steps, and --starts > 0".into()),
        )
    })?;
    let (lo, hi) = range(&report.per_rollout);
    outln!(
        "  window rate {:.4} (runs {lo:.3}-{hi:.3}): share of the steps after a {}-step burn-in whose windows visit {}",
        report.rate,
        args.burn_in,
        spec.regions
            .iter()
            .map(|r| format!("{} within {}", r.name, r.horizon))
            .collect::<Vec<_>>()
            .join(", ")
    )?;
    print_robustness(&report.robustness)?;
    // A hand-written yardstick over the same starts and slips: a learned policy below it has
    // not learned the legs.
    if let Ok(mut cycle) = EntryCycle::new(&env, &regions) {
        let base = window_rate(&env, &mut cycle, &regions, config, &mut seeded_rng(args.seed))
            .map_err(|e| CliError::new(e.to_string(), None))?;
        outln!(
            "  hand-written baseline (the regions in turn, each by a shortest path around the walls): window rate {:.4}",
            base.rate
        )?;
    }
    if !args.no_optimum {
        let start = Instant::now();
        let optimum = solve(&Moves::of(&env), &regions, SolveConfig::default())
            .map_err(|e| CliError::new(e.to_string(), Some(SKIP_OPTIMUM.into())))?;
        outln!(
            "  optimum W* = {:.4} (in [{:.4}, {:.4}], value iteration, {:.1} s{}): W/W* = {:.3}",
            optimum.gain,
            optimum.lower,
            optimum.upper,
            start.elapsed().as_secs_f64(),
            if optimum.converged { "" } else { ", not converged" },
            report.rate / optimum.gain
        )?;
    }
    Ok(Status::Clean)
}

/// The spec that `policy.json` was trained from, checked and lowered again.
pub fn spec_of(policy_text: &str, expected: &str) -> Result<TaskSpec, String> {
    let value: serde_json::Value = serde_json::from_str(policy_text).map_err(|e| e.to_string())?;
    let Some(source) = value.get("spec_source").and_then(|s| s.as_str()) else {
        return Err("it has no `spec_source` entry with the spec it was trained on".into());
    };
    let checked = hstl::lang::check(source);
    if checked.has_errors() {
        return Err("its `spec_source` does not check; run `hstlc check` on the spec".into());
    }
    let spec = checked
        .specs
        .iter()
        .find(|s| s.name == expected)
        .ok_or_else(|| format!("its `spec_source` has no spec named `{expected}`"))?;
    hstl::lower::task_spec(spec, source).map_err(|e| e.to_string())
}

/// The task's robustness over the states of one run (indices into `states`, the trace of
/// every state of the environment).
fn robustness_of_run(spec: &TaskSpec, states: &Trace, run: &[usize]) -> Result<f64, CliError> {
    let mut trace = Trace::new(states.vars());
    let mut row = Vec::with_capacity(states.vars());
    for &s in run {
        states.row_into(s, &mut row);
        trace.push(&row).map_err(|e| CliError::new(e.to_string(), None))?;
    }
    Ok(offline::robustness(&spec.task, &trace))
}

fn print_robustness(values: &[f64]) -> Result<(), CliError> {
    let mean = mean(values);
    let (lo, hi) = range(values);
    let satisfied = values.iter().filter(|&&v| v > 0.0).count();
    outln!(
        "  task robustness over each run: mean {mean:.3}, min {lo:.3}, max {hi:.3}; satisfied in {satisfied} of {} runs",
        values.len()
    )
}
