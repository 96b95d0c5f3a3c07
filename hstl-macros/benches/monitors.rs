//! Generated monitors against the runtime's interpreter (the offline evaluator) on the
//! robustness benchmarks' formulas F1 and F2, over a 1,000,000-step random walk.
//!
//! `cargo bench -p hstl-macros --bench monitors -- --warm-up-time 1 --measurement-time 3`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use hstl::robustness::{Evaluator, Trace};
use hstl_macros::hstl;
use std::hint::black_box;

hstl! {
    /// F1: a 41-step always over region A.
    spec F1 {
        state { x: int in 0..=14, y: int in 0..=14 }
        task always[0..=40] (x > 3 && x < 9 && y > 10 && y < 14);
    }
    /// F2: the case study's persistent task.
    spec F2 {
        state { x: int in 0..=14, y: int in 0..=14 }
        let A = x > 3 && x < 9 && y > 10 && y < 14;
        let B = x > 1 && x < 5 && y > 1 && y < 5;
        let C = 9 < x < 13 && 1 < y < 7;
        task always[0..] (eventually[0..40] A && eventually[0..40] B && eventually[0..40] C);
    }
}

const STEPS: usize = 1_000_000;

/// A walk from (7, 7) on the 15 x 15 grid, moves drawn by splitmix64 from a fixed seed.
fn walk() -> Vec<(i64, i64)> {
    let mut state: u64 = 0x5eed_2016;
    let (mut x, mut y) = (7i64, 7i64);
    let mut out = Vec::with_capacity(STEPS);
    for _ in 0..STEPS {
        out.push((x, y));
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        let (dx, dy) = match (z ^ (z >> 31)) % 4 {
            0 => (0, 1),
            1 => (0, -1),
            2 => (-1, 0),
            _ => (1, 0),
        };
        if (0..=14).contains(&(x + dx)) && (0..=14).contains(&(y + dy)) {
            x += dx;
            y += dy;
        }
    }
    out
}

fn monitors(c: &mut Criterion) {
    let cells = walk();
    let trace = Trace::from_columns(vec![
        cells.iter().map(|c| c.0 as f64).collect(),
        cells.iter().map(|c| c.1 as f64).collect(),
    ])
    .expect("two columns of equal length");
    let s1: Vec<f1::State> = cells.iter().map(|&(x, y)| f1::State { x, y }).collect();
    let s2: Vec<f2::State> = cells.iter().map(|&(x, y)| f2::State { x, y }).collect();
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
