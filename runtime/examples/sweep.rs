//! Trains the case study over many seeds for five variants (O_T1/O_T2 x argmax/entry
//! termination, and `memory`: options {A, B, C} with `memory: 8` and `reward: window`) on
//! two threads and reports the window rate, W/W*, training time, the window rate of the
//! learned legs driven through the fixed cycle A -> B -> C, and the O_T2 vs O_T1 reward
//! difference.
//!
//! `cargo run --release -p hstl-runtime --example sweep -- [SEEDS] [EPISODES] [VARIANT]
//! [THREADS]` (VARIANT, such as `O_T2 argmax` or `memory`, runs that variant alone, `all`
//! runs every one; EPISODES `-` keeps 1200; SEEDS 0 stops after the optimum and the
//! hand-written cycle; THREADS, 2 by default, trains that many seeds at once: use 1 for
//! training times on an otherwise idle machine).
//!
//! The memory variant's figures: `cargo run --release -p hstl-runtime --example sweep -- 20 -
//! memory 1`. `memory off` is the same spec with `memory: 0` (the window reward alone);
//! `memory flat alpha X` is the same spec with the flat step size X instead of 0.2.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use hstl_runtime::eval::{
    AgentController, EntryCycle, LegCycle, RegionTable, WindowConfig, window_rate,
};
use hstl_runtime::moves::Moves;
use hstl_runtime::optimum::{SolveConfig, solve};
use hstl_runtime::{GridWorld, Learner, TaskSpec, seeded_rng};

/// Seconds this thread has spent on a CPU (Linux `schedstat`), which a busy machine
/// inflates less than the wall clock; NaN elsewhere.
fn cpu_secs() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|t| t.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns / 1e9)
}

/// What one training run measured.
#[derive(Clone, Debug)]
struct Outcome {
    rate: f64,
    secs: f64,
    cpu: f64,
    tail_reward: f64,
    steps: u64,
    legs: f64,
}

/// The spec of a variant by name.
fn variant(name: &str) -> TaskSpec {
    match name {
        "memory" => common::case_study_memory(),
        "memory off" => {
            let mut spec = common::case_study_memory();
            spec.learn.memory = 0;
            spec
        }
        _ if name.starts_with("memory flat alpha ") => {
            let mut spec = common::case_study_memory();
            spec.learn.flat.alpha = name["memory flat alpha ".len()..].parse().expect("a number");
            spec
        }
        _ => common::case_study(name.starts_with("O_T2"), name.ends_with("entry")),
    }
}

fn run(name: &str, seed: u64, episodes: Option<usize>) -> Outcome {
    let mut spec = variant(name);
    if let Some(e) = episodes {
        spec.learn.episodes = e;
    }
    let env = GridWorld::default();
    let mut rng = seeded_rng(seed);
    let t = Instant::now();
    let cpu = cpu_secs();
    let mut learner = Learner::new(&spec, &env).expect("the case study is valid");
    let trained = learner.train(&mut rng, |_, _| {});
    let secs = t.elapsed().as_secs_f64();
    let cpu = cpu_secs() - cpu;
    let agent = learner.agent();
    let regions = RegionTable::new(&spec, &env).expect("the case study has regions");
    let mut eval_rng = seeded_rng(seed ^ 0x5eed);
    let report = window_rate(
        &env,
        &mut AgentController::new(&agent),
        &regions,
        WindowConfig::default(),
        &mut eval_rng,
    )
    .expect("default window config is valid");
    let mut legs = LegCycle::new(&agent, vec![0, 1, 2]).expect("three primitives");
    let legs = window_rate(&env, &mut legs, &regions, WindowConfig::default(), &mut eval_rng)
        .expect("default window config is valid");
    let tail = &trained.curve[trained.curve.len().saturating_sub(100)..];
    Outcome {
        rate: report.rate,
        secs,
        cpu,
        tail_reward: tail.iter().sum::<f64>() / tail.len() as f64,
        steps: trained.steps,
        legs: legs.rate,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seeds: u64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(20);
    let episodes: Option<usize> = args.get(2).and_then(|a| a.parse().ok());
    let only = args.get(3).filter(|v| *v != "all");
    let threads: u64 = args.get(4).and_then(|a| a.parse().ok()).unwrap_or(2).max(1);
    let env = GridWorld::default();
    let spec = common::case_study(false, false);
    let regions = RegionTable::new(&spec, &env).expect("the case study has regions");
    let t = Instant::now();
    let optimum =
        solve(&Moves::of(&env), &regions, SolveConfig::default()).expect("the optimum is solvable");
    println!(
        "W* = {:.4} in [{:.5}, {:.5}], {} sweeps over {} states, {:.1} s (converged: {})",
        optimum.gain,
        optimum.lower,
        optimum.upper,
        optimum.iterations,
        optimum.states,
        t.elapsed().as_secs_f64(),
        optimum.converged
    );
    let w_star = optimum.gain;
    let mut rng = seeded_rng(1);
    let check =
        window_rate(&env, &mut optimum.controller(), &regions, WindowConfig::default(), &mut rng)
            .expect("valid config");
    println!("greedy on the optimal values, simulated: {:.4}", check.rate);
    let mut cycle = EntryCycle::new(&env, &regions).expect("regions are non-empty");
    let c = window_rate(&env, &mut cycle, &regions, WindowConfig::default(), &mut rng)
        .expect("valid config");
    println!("nearest-cell entry cycle A->B->C: {:.4} (W/W* {:.3})", c.rate, c.rate / w_star);
    if seeds == 0 {
        return;
    }
    let mut tails = Vec::new();
    let mut names =
        vec!["O_T1 argmax", "O_T2 argmax", "O_T1 entry", "O_T2 entry", "memory", "memory off"];
    if let Some(o) = only.filter(|o| o.starts_with("memory flat alpha ")) {
        names.push(o);
    }
    for name in names {
        if only.is_some_and(|o| o != name) {
            continue;
        }
        let outcomes: Vec<Outcome> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..threads)
                .map(|w| {
                    scope.spawn(move || {
                        (0..seeds)
                            .filter(|s| s % threads == w)
                            .map(|s| (s, run(name, s, episodes)))
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            let mut all: Vec<(u64, Outcome)> =
                handles.into_iter().flat_map(|h| h.join().expect("worker")).collect();
            all.sort_by_key(|(s, _)| *s);
            all.into_iter().map(|(_, o)| o).collect()
        });
        let stat = |f: &dyn Fn(&Outcome) -> f64| {
            let v: Vec<f64> = outcomes.iter().map(f).collect();
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let (lo, hi) = v
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
            (mean, lo, hi)
        };
        let (r, rlo, rhi) = stat(&|o| o.rate);
        let (s, slo, shi) = stat(&|o| o.secs);
        let (tr, _, _) = stat(&|o| o.tail_reward);
        let (st, _, _) = stat(&|o| o.steps as f64);
        let (cpu, cpu_lo, cpu_hi) = stat(&|o| o.cpu);
        let (lg, llo, lhi) = stat(&|o| o.legs);
        let sd = (outcomes.iter().map(|o| (o.rate - r).powi(2)).sum::<f64>()
            / (outcomes.len().max(2) - 1) as f64)
            .sqrt();
        // How much of the spread over seeds the legs explain.
        let cov = outcomes.iter().map(|o| (o.rate - r) * (o.legs - lg)).sum::<f64>();
        let var_legs = outcomes.iter().map(|o| (o.legs - lg).powi(2)).sum::<f64>();
        let var_rate = outcomes.iter().map(|o| (o.rate - r).powi(2)).sum::<f64>();
        let corr = cov / (var_legs * var_rate).sqrt();
        let mut secs: Vec<f64> = outcomes.iter().map(|o| o.secs).collect();
        secs.sort_by(f64::total_cmp);
        println!(
            "{name}: window rate {r:.3} ({rlo:.3}-{rhi:.3}, sd {sd:.3}), W/W* {:.3}, train {s:.2} s ({slo:.2}-{shi:.2}, median {:.2}; on the CPU {cpu:.2} s, {cpu_lo:.2}-{cpu_hi:.2}), {:.2}M steps/s, last-100 reward/episode {tr:.2}, learned legs through A->B->C {lg:.3} ({llo:.3}-{lhi:.3}), corr(W, legs) {corr:.2}",
            r / w_star,
            secs[secs.len() / 2],
            st / s / 1e6
        );
        if !name.starts_with("memory") {
            tails.push(tr);
        }
    }
    if tails.len() < 4 {
        return;
    }
    let diff = |a: f64, b: f64| 100.0 * (b - a) / a.abs();
    println!(
        "O_T2 vs O_T1 reward: argmax {:+.1}%, entry {:+.1}%",
        diff(tails[0], tails[1]),
        diff(tails[2], tails[3])
    );
}
