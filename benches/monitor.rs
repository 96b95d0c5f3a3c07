//! The facade's monitors on the benchmark walk: the calls the Python package makes
//! (`Monitor::signal` on borrowed columns, allocating its result; row-major samples; a
//! batch of 1,000 traces x 1,000 steps on 1 and 2 threads), the native side of
//! `bench/python/bench.py`.
//!
//! `STLReward`'s episode scoring too (`reward/`).
//!
//! `cargo bench -p hstl --bench monitor -- --warm-up-time 1 --measurement-time 3`

#[path = "../robustness/benches/walk.rs"]
#[allow(dead_code)]
mod walk;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use hstl::monitor::{Monitor, Samples};
use std::hint::black_box;

const SPEC: &str = include_str!("../bench/python/bench.hstl");
/// The batch: the walk cut into this many traces of this many steps.
const TRACES: usize = 1000;
const STEPS: usize = 1000;

fn benches(c: &mut Criterion) {
    let trace = walk::walk(walk::STEPS, &mut walk::SplitMix64(walk::SEED));
    let (x, y) = (trace.column(0), trace.column(1));
    let rows: Vec<f64> = x.iter().zip(y).flat_map(|(x, y)| [*x, *y]).collect();
    let spec = hstl::load::load(SPEC, None).expect("the bench spec checks").spec;
    let cases = [
        ("F1_w40", Some("F1_w40")),
        ("F1_w4000", Some("F1_w4000")),
        ("F2", None),
        ("F3", Some("F3")),
    ];
    let monitor = |formula| Monitor::new(&spec, formula).expect("the bench formulas lower");
    // The same formulas as hstl-robustness's bench, so the figures compare.
    let lowered = |name| hstl::lower::let_formula(&spec, name).expect("a bench let");
    assert_eq!(lowered("F1_w40"), walk::f1(40));
    assert_eq!(lowered("F1_w4000"), walk::f1(4000));
    assert_eq!(hstl::lower::task(&spec).expect("the task"), walk::f2());
    assert_eq!(lowered("F3"), walk::f3());

    let mut g = c.benchmark_group("monitor/signal");
    g.throughput(Throughput::Elements(trace.len() as u64));
    g.sample_size(20);
    for (name, formula) in cases {
        let m = monitor(formula);
        g.bench_function(name, |b| {
            b.iter(|| black_box(m.signal(&Samples::Columns(vec![x, y])).map(|s| s[0])))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("monitor/signal_rows");
    g.throughput(Throughput::Elements(trace.len() as u64));
    g.sample_size(20);
    let m = monitor(Some("F1_w40"));
    g.bench_function("F1_w40", |b| {
        let samples = Samples::Rows { data: &rows, width: 2, picks: vec![0, 1] };
        b.iter(|| black_box(m.signal(&samples).map(|s| s[0])))
    });
    g.finish();

    let batch: Vec<Samples<'_>> = (0..TRACES)
        .map(|i| {
            Samples::Columns(vec![&x[i * STEPS..(i + 1) * STEPS], &y[i * STEPS..(i + 1) * STEPS]])
        })
        .collect();
    let mut g = c.benchmark_group("monitor/signal_batch");
    g.throughput(Throughput::Elements((TRACES * STEPS) as u64));
    g.sample_size(10);
    for (name, formula) in [("F1_w40", Some("F1_w40")), ("F2", None)] {
        let m = monitor(formula);
        for threads in [1, 2] {
            g.bench_function(format!("{name}/{threads}_threads"), |b| {
                b.iter(|| black_box(m.signal_batch(&batch, threads).map(|(s, _)| s[0])))
            });
        }
    }
    g.finish();
}

/// `STLReward`'s per-step scoring over an episode of 5,000 steps, for a reward with a past
/// operator inside a future one (scored online since the reward is read at the last step;
/// it evaluated the whole prefix each step before), for one with a future operator inside
/// a bounded past one and inside a past one without an end (the online monitor's state
/// copied and its open steps ended each step; the kept states, or the whole prefix,
/// evaluated again before), and for a task with a past operator under `always[0..]`, whose
/// robustness the monitor reports too (its operand's online monitor; the whole prefix
/// before), and for "infinitely often" (`always[0..] eventually[0..]`, the value at the
/// last state; the whole prefix before).
fn reward(c: &mut Criterion) {
    let src = "spec R { state { x: float, y: float } \
               let Recent = eventually[0..=5] once[0..=10] x > 8; \
               let Lately = once[0..=10] eventually[0..=5] x > 8; \
               let Ever = once[0..] eventually[0..=5] x > 8; \
               let Long = once[0..=500] eventually[0..=5] x > 8; \
               task always[0..] eventually[0..40] x > 8; }";
    let past_task = "spec P { state { x: float, y: float } \
               task always[0..] (x > 8 -> once[0..=10] eventually[0..=3] y > 0); }";
    let recurrence = "spec G { state { x: float, y: float } \
               task always[0..] eventually[0..] x > 8; }";
    let spec = hstl::load::load(src, None).expect("the spec checks").spec;
    let trace = walk::walk(5_000, &mut walk::SplitMix64(walk::SEED));
    let (x, y) = (trace.column(0), trace.column(1));
    let mut g = c.benchmark_group("reward");
    g.sample_size(10);
    g.throughput(Throughput::Elements(x.len() as u64));
    let past_spec = hstl::load::load(past_task, None).expect("the spec checks").spec;
    let recurrence_spec = hstl::load::load(recurrence, None).expect("the spec checks").spec;
    for (name, src, spec, reward) in [
        ("past_inside_future_5000", src, &spec, Some("Recent")),
        ("future_inside_past_5000", src, &spec, Some("Lately")),
        ("future_inside_long_past_5000", src, &spec, Some("Long")),
        ("future_inside_unbounded_past_5000", src, &spec, Some("Ever")),
        ("task_with_past_5000", past_task, &past_spec, None),
        ("task_recurrence_5000", recurrence, &recurrence_spec, None),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut episode =
                    hstl::reward::EpisodeMonitor::new(spec, src, reward).expect("a reward");
                let mut sum = 0.0;
                for (x, y) in x.iter().zip(y) {
                    sum += episode.push(&[*x, *y]).expect("a state").reward;
                }
                black_box(sum)
            })
        });
    }
}

criterion_group!(monitor, benches, reward);
criterion_main!(monitor);
