//! How long the macro takes to expand the case study, measured on its plain function.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

#[allow(dead_code, missing_docs)]
#[path = "../src/expand/mod.rs"]
mod expand;

fn expand_case_study(c: &mut Criterion) {
    let text = include_str!("../specs/case_study.hstl");
    let tokens: proc_macro2::TokenStream =
        text.parse().expect("the case study lexes as Rust tokens");
    c.bench_function("expand/case_study", |b| b.iter(|| expand::expand(black_box(tokens.clone()))));
}

criterion_group!(benches, expand_case_study);
criterion_main!(benches);
