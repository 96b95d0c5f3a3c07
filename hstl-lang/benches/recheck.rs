//! What an editor waits for after one keystroke in a 10,000-line spec. The language
//! server re-parses only the items around the change (`incremental::reparse`, with the
//! previous parse) and checks the whole spec (`check_parsed`); for comparison, the full
//! `check` of the new text, and formatting it. The target for re-checking is 50 ms.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use hstl_lang::incremental::{Reuse, reparse};
use std::fmt::Write as _;
use std::hint::black_box;

/// The spec of `benches/check.rs`: about `lines` lines of lets over four bounded
/// variables, a persistent task over the last four lets and four options.
fn big_spec(lines: usize) -> String {
    let mut s = String::from("/// Generated.\nspec Big {\n    state {\n");
    for v in 0..4 {
        let _ = writeln!(s, "        /// Variable {v}.\n        v{v}: int in 0..=9,");
    }
    s.push_str("    }\n");
    for i in 0..lines {
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
        (0..4).map(|k| format!("eventually[0..40] L{}", lines - 1 - k)).collect();
    let _ = writeln!(s, "    task always[0..] ({});", task.join(" && "));
    for k in 0..4 {
        let _ = writeln!(s, "    option L{};", lines - 1 - k);
    }
    s.push_str("    learn { episodes: 100, flat: { gamma: 0.95 } }\n}\n");
    s
}

fn bench(c: &mut Criterion) {
    let src = big_spec(10_000);
    assert!(src.lines().count() >= 10_000);
    // One keystroke in the middle of the file: a bound of one let changes.
    let at = src.find("let L5000 = ").expect("let L5000") + "let L5000 = ".len();
    let mut edited = src.clone();
    edited.replace_range(at..at + 1, "1");
    assert_ne!(edited, src);
    let checked = hstl_lang::check(&edited);
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics.first());
    let prev = hstl_lang::parse(&src);
    let (again, reuse) = reparse(prev.clone(), &src, &edited);
    assert!(matches!(reuse, Reuse::Partial(n) if n < 1000), "{reuse:?}");
    assert_eq!(hstl_lang::check_parsed(&edited, again).diagnostics, checked.diagnostics);
    c.bench_function("re-check 10k-line spec after one change (incremental)", |b| {
        b.iter_batched(
            || prev.clone(),
            |prev| {
                let (parsed, _) = reparse(prev, black_box(&src), black_box(&edited));
                hstl_lang::check_parsed(&edited, parsed)
            },
            BatchSize::LargeInput,
        )
    });
    c.bench_function("re-parse 10k-line spec after one change (incremental)", |b| {
        b.iter_batched(
            || prev.clone(),
            |prev| reparse(prev, black_box(&src), black_box(&edited)),
            BatchSize::LargeInput,
        )
    });
    c.bench_function("check 10k-line spec from scratch after one change", |b| {
        b.iter(|| hstl_lang::check(black_box(&edited)))
    });
    c.bench_function("format 10k-line spec", |b| {
        b.iter(|| hstl_lang::format(black_box(&edited)).map(|s| s.len()))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
