//! Checking hostile input in linear time (issue 11, class 9): a file with tens of
//! thousands of syntax errors, many unknown names among many declared ones, and one
//! misspelt 100,000-character name. Each case asserts what `check` reports before timing it.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

/// A spec whose `errors` lets each miss their right-hand side.
fn syntax_errors(errors: usize) -> String {
    let mut s = String::from("spec S { state { x: int in 0..=9 }\n");
    for _ in 0..errors {
        s.push_str("let A = x > ;\n");
    }
    s.push_str("task x > 1; }\n");
    s
}

/// A spec with `n` lets and `n` references to names that differ from one of them by one
/// letter: every reference is an unknown name with a close match.
fn unknown_names(n: usize) -> String {
    let mut s = String::from("spec S { state { x: int in 0..=9 }\n");
    for i in 0..n {
        s.push_str(&format!("let L{i} = x > 1;\nlet M{i} = Z{i} && x < 3;\n"));
    }
    s.push_str("task L0; }\n");
    s
}

/// A spec that refers to a 100,000-character name one letter off a declared one.
fn long_misspelt_name() -> String {
    let name = "a".repeat(100_000);
    let typo = format!("b{}", &name[1..]);
    format!("spec S {{ state {{ x: int in 0..=9 }} let {name} = x > 1; task {typo}; }}\n")
}

fn count(src: &str) -> (usize, String) {
    let checked = hstl_lang::check(src);
    let last = checked.diagnostics.last().map_or(String::new(), |d| d.message.clone());
    (checked.diagnostics.len(), last)
}

fn bench(c: &mut Criterion) {
    let cap = hstl_lang::check::MAX_DIAGNOSTICS;
    let mut group = c.benchmark_group("hostile");
    group.sample_size(10);
    for errors in [40_000, 400_000] {
        let src = syntax_errors(errors);
        let (n, last) = count(&src);
        assert_eq!(n, cap + 1, "capped, with one diagnostic that says how many more");
        assert!(last.starts_with(&format!("{} more", errors - cap)), "{last}");
        group.bench_function(format!("check {errors} syntax errors"), |b| {
            b.iter(|| hstl_lang::check(black_box(&src)))
        });
    }
    let src = unknown_names(40_000);
    let checked = hstl_lang::check(&src);
    assert!(checked.diagnostics[0].help.as_deref().is_some_and(|h| h.contains("did you mean")));
    group.bench_function("check 40000 unknown names among 80000 lets", |b| {
        b.iter(|| hstl_lang::check(black_box(&src)))
    });
    let src = long_misspelt_name();
    assert!(hstl_lang::check(&src).has_errors());
    group.bench_function("check a misspelt 100000-character name", |b| {
        b.iter(|| hstl_lang::check(black_box(&src)))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
