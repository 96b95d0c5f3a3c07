//! Robustness throughput on a 1,000,000-step random walk on the 15 x 15 grid world.
//!
//! `cargo bench -p hstl-robustness --bench robustness -- --warm-up-time 1 --measurement-time 3`

#[path = "walk.rs"]
// Shared with the dense bench, which alone uses its stamps.
#[allow(dead_code)]
mod walk;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use hstl_robustness::{Evaluator, Formula, OnlineMonitor, Trace, complete, segment::TabularScorer};
use std::hint::black_box;

fn full_signal(c: &mut Criterion, trace: &Trace, cases: &[(&str, Formula)]) {
    let mut g = c.benchmark_group("signal");
    g.throughput(Throughput::Elements(trace.len() as u64));
    g.sample_size(20);
    let mut ev = Evaluator::new();
    for (name, f) in cases {
        g.bench_function(*name, |b| b.iter(|| black_box(ev.signal(f, black_box(trace))[0])));
    }
    g.finish();
}

/// Over complete windows (`hstlc monitor --complete`, the train and eval reports).
fn complete_signal(c: &mut Criterion, trace: &Trace, cases: &[(&str, Formula)]) {
    let mut g = c.benchmark_group("complete");
    g.throughput(Throughput::Elements(trace.len() as u64));
    g.sample_size(10);
    for (name, f) in cases {
        g.bench_function(*name, |b| b.iter(|| black_box(complete::signal(f, black_box(trace))[0])));
    }
    g.finish();
}

fn online(c: &mut Criterion, trace: &Trace, cases: &[(&str, Formula)]) {
    let mut g = c.benchmark_group("online");
    g.throughput(Throughput::Elements(trace.len() as u64));
    g.sample_size(10);
    let (xs, ys) = (trace.column(0), trace.column(1));
    for (name, f) in cases {
        g.bench_function(*name, |b| {
            b.iter(|| {
                let mut m = OnlineMonitor::new(f, 2);
                let mut acc = 0.0;
                for (x, y) in xs.iter().zip(ys) {
                    if let Ok(Some(v)) = m.push(&[*x, *y]) {
                        acc += v.value;
                    }
                }
                black_box((acc, m.finish().len()))
            })
        });
    }
    g.finish();
}

fn step_zero(c: &mut Criterion, trace: &Trace) {
    let f = walk::f1(40);
    let mut ev = Evaluator::new();
    c.bench_function("step0/F1_w40", |b| b.iter(|| black_box(ev.robustness(&f, black_box(trace)))));
}

fn suffix_rewards(c: &mut Criterion, rng: &mut walk::SplitMix64) {
    // The state table is the 15 x 15 grid; a segment is 40 cell indices of a walk.
    let cells: Vec<(f64, f64)> =
        (0..15).flat_map(|x| (0..15).map(move |y| (f64::from(x), f64::from(y)))).collect();
    let states = Trace::from_columns(vec![
        cells.iter().map(|c| c.0).collect(),
        cells.iter().map(|c| c.1).collect(),
    ])
    .expect("two columns of equal length");
    let seg = walk::walk(40, rng);
    let idx: Vec<usize> =
        (0..40).map(|t| seg.column(0)[t] as usize * 15 + seg.column(1)[t] as usize).collect();
    let mut scorer = TabularScorer::new(&walk::f2(), &states);
    let mut out = Vec::new();
    c.bench_function("suffix_rewards/F2_tabular_40", |b| {
        b.iter(|| {
            scorer.suffix_rewards(black_box(&idx), &mut out);
            black_box(out[0])
        })
    });
}

/// A persistent task that reads the past, over every suffix of a 2,000-step segment: a
/// bounded past window (linear in the segment) against one without an end (each suffix
/// reads back to its own start, held to `SUFFIX_BUDGET` steps per step); and that one over
/// a 100,000-step option run, `max_steps^2 / 2` steps if every suffix were scored.
fn past_suffix_rewards(c: &mut Criterion, rng: &mut walk::SplitMix64) {
    use hstl_robustness::{Bound, CmpOp, Expr, Interval, segment::SegmentScorer};
    let seg = walk::walk(2000, rng);
    let long = walk::walk(100_000, rng);
    let gt = |v, k: f64| Formula::cmp(Expr::var(v), CmpOp::Gt, Expr::constant(k));
    let task = |end| {
        let seen = Formula::once(Interval { start: 0, end }, gt(0, 10.0));
        let soon =
            Formula::eventually(Interval { start: 0, end: Bound::Inclusive(10) }, gt(1, 3.0));
        Formula::always(Interval::ALL, Formula::implies(seen, soon))
    };
    let mut out = Vec::new();
    let cases = [
        ("bounded_20_2000", Bound::Inclusive(20), &seg),
        ("unbounded_2000", Bound::Unbounded, &seg),
        ("unbounded_100000", Bound::Unbounded, &long),
    ];
    for (name, end, seg) in cases {
        let mut scorer = SegmentScorer::new(&task(end));
        c.bench_function(&format!("suffix_rewards/past_{name}"), |b| {
            b.iter(|| {
                scorer.suffix_rewards(black_box(seg), &mut out);
                black_box(out[0])
            })
        });
    }
}

fn benches(c: &mut Criterion) {
    let mut rng = walk::SplitMix64(walk::SEED);
    let trace = walk::walk(walk::STEPS, &mut rng);
    let cases = [
        ("F1_w40", walk::f1(40)),
        ("F1_w4000", walk::f1(4000)),
        ("F2", walk::f2()),
        ("F3", walk::f3()),
        // The past-time mirrors: the same kernels on the reversed signal.
        ("P1_w40", walk::p1(40)),
        ("P1_w4000", walk::p1(4000)),
        ("P2", walk::p2()),
        ("P3", walk::p3()),
    ];
    full_signal(c, &trace, &cases);
    complete_signal(c, &trace, &[("F1_w40", walk::f1(40)), ("F2", walk::f2())]);
    online(
        c,
        &trace,
        &[
            ("F1_w40", walk::f1(40)),
            ("F3", walk::f3()),
            ("P1_w40", walk::p1(40)),
            ("P2", walk::p2()),
            ("P3", walk::p3()),
        ],
    );
    step_zero(c, &trace);
    suffix_rewards(c, &mut rng);
    past_suffix_rewards(c, &mut rng);
}

criterion_group!(robustness, benches);
criterion_main!(robustness);
