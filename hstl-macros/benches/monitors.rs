//! Generated monitors against the runtime's interpreter (the offline evaluator) on the
//! robustness benchmarks' formulas F1 and F2, over a 1,000,000-step random walk.
//!
//! `cargo bench -p hstl-macros --bench monitors -- --warm-up-time 1 --measurement-time 3`

#[path = "data/mod.rs"]
mod data;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use data::{Data, STEPS, f1, f2};
use hstl::robustness::Evaluator;
use std::hint::black_box;

fn monitors(c: &mut Criterion) {
    let Data { trace, s1, s2 } = Data::default();
    let (g1, g2) = (f1::task::formula(), f2::task::formula());
    let mut ev = Evaluator::new();
    assert_eq!(f1::task::signal(&s1), ev.signal(&g1, &trace), "F1 monitors agree");
    assert_eq!(f2::task::signal(&s2), ev.signal(&g2, &trace), "F2 monitors agree");

    let mut g = c.benchmark_group("signal");
    g.throughput(Throughput::Elements(STEPS as u64));
    g.sample_size(10);
    g.bench_function("F1_w40/generated", |b| {
        b.iter(|| black_box(f1::task::signal(black_box(&s1))[0]))
    });
    g.bench_function("F1_w40/interpreter", |b| {
        b.iter(|| black_box(ev.signal(&g1, black_box(&trace))[0]))
    });
    g.bench_function("F2/generated", |b| b.iter(|| black_box(f2::task::signal(black_box(&s2))[0])));
    g.bench_function("F2/interpreter", |b| {
        b.iter(|| black_box(ev.signal(&g2, black_box(&trace))[0]))
    });
    g.finish();
}

criterion_group!(benches, monitors);
criterion_main!(benches);
