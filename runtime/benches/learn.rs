//! Full case-study training runs: O_T1 (7 options) and O_T2 (15 options), 1200 episodes of
//! 200 choices with the paper's parameters and argmax termination, and the memory variant
//! (options {A, B, C}, `memory: 8`, `reward: window`), seed 1; throughput is in primitive
//! steps.
//!
//! `cargo bench -p hstl-runtime --bench learn -- --warm-up-time 1 --measurement-time 3`

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use hstl_runtime::{GridWorld, Learner, seeded_rng};

fn training(c: &mut Criterion) {
    let env = GridWorld::default();
    let mut group = c.benchmark_group("train");
    group.sample_size(10);
    for name in ["O_T1", "O_T2", "memory"] {
        let spec = match name {
            "memory" => common::case_study_memory(),
            _ => common::case_study(name == "O_T2", false),
        };
        let train = || {
            let mut learner = Learner::new(&spec, &env).expect("the case study is valid");
            learner.train(&mut seeded_rng(1), |_, _| {}).steps
        };
        // The same seed every time, so every iteration takes the same steps: criterion
        // reports primitive steps per second.
        group.throughput(Throughput::Elements(train()));
        group.bench_function(name, |b| b.iter(train));
    }
    group.finish();
}

criterion_group!(benches, training);
criterion_main!(benches);
