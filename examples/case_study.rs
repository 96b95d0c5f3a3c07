//! The paper's case study through the `hstl!` macro: the spec file is checked when this
//! example compiles, and becomes typed Rust that trains in a few lines.
//!
//! `cargo run --release --example case_study -- [SEED]`

use hstl::runtime::eval::{AgentController, RegionTable, WindowConfig, window_rate};
use hstl::runtime::{GridWorld, Learner, Spec, seeded_rng};

hstl::hstl! { include "examples/specs/surveillance_ot1.hstl" }

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let seed = std::env::args().nth(1).map_or(Ok(1), |s| s.parse::<u64>())?;
    let spec = surveillance::Surveillance.task_spec();
    let env = GridWorld::default();
    let mut learner = Learner::new(&spec, &env)?;
    let start = std::time::Instant::now();
    let trained = learner.train(&mut seeded_rng(seed), |_, _| {});
    println!(
        "trained {} options of `{}` for {} episodes ({} steps) in {:.2} s",
        spec.options.len(),
        spec.name,
        trained.curve.len(),
        trained.steps,
        start.elapsed().as_secs_f64()
    );
    // The typed side: options know their legs, and every let has monitors.
    for option in surveillance::Options::ALL {
        println!("  option {:<4} runs {:?}", option.name(), option.sequence());
    }
    let agent = learner.agent();
    let regions = RegionTable::new(&spec, &env)?;
    let report = window_rate(
        &env,
        &mut AgentController::new(&agent),
        &regions,
        WindowConfig::default(),
        &mut seeded_rng(seed ^ 0x5eed),
    )?;
    println!("window rate of the greedy policy: {:.3}", report.rate);
    let states = [surveillance::State { x: 5, y: 12 }, surveillance::State { x: 3, y: 3 }];
    println!(
        "robustness of A at step 0 of a two-state trace: {}",
        surveillance::lets::a::robustness(&states)
    );
    Ok(())
}
