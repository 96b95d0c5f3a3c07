//! Trains the case study once and reports the time, the steps per second and the window
//! rate of the greedy policy.
//!
//! `cargo run --release -p hstl-runtime --example train -- [SEED] [o_t2] [entry] [memory]
//! [remaining] [episodes=N] [no-eval]`
//! (`memory`: the fourth variant, options {A, B, C} with `memory: 8` and `reward: window`;
//! `remaining`: `intra: remaining`; `episodes=N`: train N episodes; `no-eval`: skip the
//! window rate, for instruction counts of the training alone under callgrind). It also
//! prints a hash of the Q-tables' bits and the learning curve, to check that a change to
//! the learner leaves the results bit-identical.

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use hstl_runtime::eval::{AgentController, RegionTable, WindowConfig, window_rate};
use hstl_runtime::{GridWorld, Learner, seeded_rng};

/// Seconds this thread has spent on a CPU (Linux `schedstat`), which a busy machine
/// inflates less than the wall clock; `None` elsewhere.
fn cpu_secs() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(ns / 1e9)
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let seed: u64 = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(1);
    let has = |flag: &str| args.iter().any(|a| a == flag);
    let mut spec = if has("memory") {
        common::case_study_memory()
    } else {
        common::case_study(has("o_t2"), has("entry"))
    };
    if has("remaining") {
        spec.learn.intra = hstl_runtime::Intra::Remaining;
    }
    if let Some(n) = args.iter().find_map(|a| a.strip_prefix("episodes=")?.parse().ok()) {
        spec.learn.episodes = n;
    }
    let env = GridWorld::default();
    let t = Instant::now();
    let cpu = cpu_secs();
    let mut learner = Learner::new(&spec, &env).expect("the case study is valid");
    let trained = learner.train(&mut seeded_rng(seed), |_, _| {});
    let secs = t.elapsed().as_secs_f64();
    if let (Some(a), Some(b)) = (cpu, cpu_secs()) {
        println!("training on the CPU: {:.3} s", b - a);
    }
    println!(
        "{} options, seed {seed}: {:.3} s, {} steps, {:.2}M steps/s",
        spec.options.len(),
        secs,
        trained.steps,
        trained.steps as f64 / secs / 1e6
    );
    println!("bits {:016x}", bits_hash(learner.q(), &trained.curve));
    if has("no-eval") {
        return;
    }
    let regions = RegionTable::new(&spec, &env).expect("the case study has regions");
    let agent = learner.agent();
    let report = window_rate(
        &env,
        &mut AgentController::new(&agent),
        &regions,
        WindowConfig::default(),
        &mut seeded_rng(seed ^ 0x5eed),
    )
    .expect("default config is valid");
    println!("window rate {:.3}", report.rate);
}

/// FNV-1a over the bits of every Q-value, the counters and the curve.
fn bits_hash(q: &hstl_runtime::QTables, curve: &[f64]) -> u64 {
    let values = q.flat.iter().flatten().chain(&q.options).chain(curve).map(|v| v.to_bits());
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for word in values.chain([q.steps, q.choices]) {
        for byte in word.to_le_bytes() {
            h = (h ^ u64::from(byte)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}
