//! Parse + check of a generated 10,000-line spec: state variables with finite domains,
//! thousands of lets, a task and a few options.

use criterion::{Criterion, criterion_group, criterion_main};
use std::fmt::Write as _;
use std::hint::black_box;

/// A spec of about `lines` lines. Each let compares the variables and every third one
/// also refers to one of the first 97 lets (shared helpers), so that name resolution and
/// the dependency order have work without building one 3,000-let chain.
fn big_spec(lines: usize) -> String {
    let mut s = String::from("/// Generated.\nspec Big {\n    state {\n");
    for v in 0..4 {
        let _ = writeln!(s, "        /// Variable {v}.\n        v{v}: int in 0..=9,");
    }
    s.push_str("    }\n");
    let lets = lines;
    for i in 0..lets {
        let (a, b) = (i % 4, (i + 1) % 4);
        if i >= 3 && i % 3 == 0 {
            let _ = writeln!(
                s,
                "    let L{i} = L{} || (v{a} + {} > v{b} && abs(v{a} - 3) < 2.5);",
                (i / 3) % 97 * 3 + 1,
                i % 7
            );
        } else {
            let _ = writeln!(
                s,
                "    let L{i} = {} < v{a} < {} && v{b} >= {}; // region {i}",
                i % 5,
                5 + i % 5,
                i % 3
            );
        }
    }
    let task: Vec<String> =
        (0..4).map(|k| format!("eventually[0..40] L{}", lets - 1 - k)).collect();
    let _ = writeln!(s, "    task always[0..] ({});", task.join(" && "));
    for k in 0..4 {
        let _ = writeln!(s, "    option L{};", lets - 1 - k);
    }
    s.push_str("    learn { episodes: 100, flat: { gamma: 0.95 } }\n}\n");
    s
}

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
