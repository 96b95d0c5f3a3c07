//! Parse + check of a generated 10,000-line spec: state variables with finite domains,
//! thousands of lets, a task and a few options.

#[path = "common/mod.rs"]
mod common;

use common::big_spec;
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let src = big_spec(10_000);
    // `HSTL_BENCH_ONCE=parse|check`: one call and no timing, for callgrind.
    match std::env::var("HSTL_BENCH_ONCE").as_deref() {
        Ok("parse") => return drop(black_box(hstl_lang::parse(black_box(&src)))),
        Ok("check") => return drop(black_box(hstl_lang::check(black_box(&src)))),
        Ok("phases") => return phases(&src),
        _ => {}
    }
    assert!(src.lines().count() >= 10_000);
    let checked = hstl_lang::check(&src);
    assert!(
        !checked.has_errors(),
        "{:?}",
        &checked.diagnostics[..3.min(checked.diagnostics.len())]
    );
    c.bench_function("check 10k-line spec", |b| b.iter(|| hstl_lang::check(black_box(&src))));
    c.bench_function("parse 10k-line spec", |b| b.iter(|| hstl_lang::parse(black_box(&src))));
}

/// The median time of each phase of `check` over 30 runs: parse, the checks, and
/// dropping the result.
fn phases(src: &str) {
    use std::time::Instant;
    let mut times: [Vec<f64>; 3] = Default::default();
    for _ in 0..30 {
        let t0 = Instant::now();
        let parsed = hstl_lang::parse(black_box(src));
        let t1 = Instant::now();
        let checked = hstl_lang::check::check_parsed(src, parsed);
        let t2 = Instant::now();
        drop(black_box(checked));
        let t3 = Instant::now();
        for (v, d) in times.iter_mut().zip([t1 - t0, t2 - t1, t3 - t2]) {
            v.push(d.as_secs_f64() * 1e3);
        }
    }
    for (name, mut v) in ["parse", "checks", "drop"].into_iter().zip(times) {
        v.sort_by(f64::total_cmp);
        println!("{name}: median {:.2} ms, min {:.2} ms", v[v.len() / 2], v[0]);
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
