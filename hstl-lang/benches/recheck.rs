//! What an editor waits for after one keystroke in a 10,000-line spec. The language
//! server re-parses only the items around the change (`incremental::reparse`, with the
//! previous parse) and checks the whole spec (`check_parsed`); for comparison, the full
//! `check` of the new text, and formatting it. The target for re-checking is 50 ms.

#[path = "common/mod.rs"]
mod common;

use common::big_spec;
use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use hstl_lang::incremental::{Reuse, reparse};
use std::hint::black_box;

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
