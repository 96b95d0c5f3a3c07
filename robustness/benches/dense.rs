//! Dense-time throughput: the 1,000,000-step benchmark walk with random irregular stamps
//! (gaps of 1 to 20 ms, uniform, in seconds), offline and online.
//!
//! `cargo bench -p hstl-robustness --bench dense -- --warm-up-time 1 --measurement-time 3`

#[path = "walk.rs"]
#[allow(dead_code)]
mod walk;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use hstl_robustness::dense::{
    DenseFormula, DenseMonitor, DenseTrace, DenseTraceBuilder, TimeScale,
};
use hstl_robustness::{Bound, CmpOp, Expr, Formula, Interval};
use std::hint::black_box;

fn cmp(v: usize, op: CmpOp, c: f64) -> Formula {
    Formula::cmp(Expr::var(v), op, Expr::constant(c))
}

/// `[a..=b]` in milliseconds (`TimeScale::decimals(3)`: bounds in seconds).
fn ms(a: usize, b: usize) -> Interval {
    Interval { start: a, end: Bound::Inclusive(b) }
}

fn region() -> Formula {
    Formula::and(vec![
        cmp(0, CmpOp::Gt, 3.0),
        cmp(0, CmpOp::Lt, 9.0),
        cmp(1, CmpOp::Gt, 10.0),
        cmp(1, CmpOp::Lt, 14.0),
    ])
}

fn cases() -> Vec<(&'static str, Formula)> {
    vec![
        ("D1_always_0.4s", Formula::always(ms(0, 400), region())),
        ("D1_always_40s", Formula::always(ms(0, 40_000), region())),
        (
            "D2_until_0.2s",
            Formula::until(ms(0, 200), cmp(0, CmpOp::Gt, 5.0), cmp(1, CmpOp::Gt, 10.0)),
        ),
        (
            "D3_nested",
            Formula::always(
                ms(0, 400),
                Formula::implies(
                    cmp(0, CmpOp::Gt, 7.0),
                    Formula::eventually(ms(100, 300), cmp(1, CmpOp::Lt, 7.0)),
                ),
            ),
        ),
        ("D4_historically_0.4s", Formula::historically(ms(0, 400), region())),
    ]
}

/// The walk with stamps: row k at the sum of k random gaps of 1..=20 ms, in seconds.
fn trace(steps: usize) -> (Vec<f64>, DenseTrace) {
    let mut rng = walk::SplitMix64(walk::SEED);
    let w = walk::walk(steps, &mut rng);
    let stamps = walk::stamps(steps, &mut rng);
    let mut b = DenseTraceBuilder::new(2);
    for (k, &t) in stamps.iter().enumerate() {
        b.push(t, &[Some(w.column(0)[k]), Some(w.column(1)[k])]).expect("increasing");
    }
    (stamps, b.build().expect("a trace"))
}

fn benches(c: &mut Criterion) {
    let (stamps, trace) = trace(walk::STEPS);
    let scale = TimeScale::decimals(3);
    let cases: Vec<(&str, DenseFormula)> = cases()
        .into_iter()
        .map(|(n, f)| (n, DenseFormula::new(&f, scale).expect("dense")))
        .collect();
    let mut g = c.benchmark_group("dense_offline");
    g.throughput(Throughput::Elements(trace.len() as u64));
    g.sample_size(10);
    for (name, f) in &cases {
        g.bench_function(*name, |b| {
            b.iter(|| black_box(f.signal(black_box(&trace)).unwrap().len()))
        });
    }
    g.finish();
    // Online, a verdict at every push (the monitor gives each change point as soon as it is
    // final). `DENSE_ONLINE_ROWS` shortens the run (the re-evaluating monitor before the
    // streaming one took a window's work per row).
    let rows: usize = std::env::var("DENSE_ONLINE_ROWS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(walk::STEPS)
        .min(walk::STEPS);
    let (xs, ys) = (trace.column(0), trace.column(1));
    let mut g = c.benchmark_group("dense_online_eager");
    g.throughput(Throughput::Elements(rows as u64));
    g.sample_size(10);
    for (name, f) in &cases {
        g.bench_function(*name, |b| {
            b.iter(|| {
                let mut m = DenseMonitor::new(f, 2).unwrap();
                let mut n = 0;
                for k in 0..rows {
                    n += m.push(stamps[k], &[Some(xs[k]), Some(ys[k])]).unwrap().len();
                }
                black_box(n + m.finish().unwrap().len())
            })
        });
    }
    g.finish();
}

criterion_group!(dense, benches);
criterion_main!(dense);
