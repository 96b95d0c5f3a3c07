//! `check` never panics and every diagnostic range lies on char boundaries inside the
//! source: random bytes, grammar-aware mutations of the valid fixtures, and pathological
//! sizes. `PROPTEST_CASES` overrides the case count of each property (default 1,000).

use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

use hstl_lang::check;

const FIXTURES: [&str; 7] = [
    include_str!("fixtures/valid/case_study_ot1.hstl"),
    include_str!("fixtures/valid/case_study_ot2.hstl"),
    include_str!("fixtures/valid/assembly.hstl"),
    include_str!("fixtures/valid/dock.hstl"),
    include_str!("fixtures/valid/memory_window.hstl"),
    include_str!("fixtures/valid/stop_on_entry.hstl"),
    include_str!("fixtures/valid/macro_spacing.hstl"),
];

/// Tokens of the grammar (and a few that are not), to insert at random.
const VOCAB: [&str; 58] = [
    "spec",
    "state",
    "int",
    "float",
    "in",
    "let",
    "task",
    "option",
    "options",
    "sequences",
    "permutations",
    "learn",
    "always",
    "eventually",
    "until",
    "true",
    "false",
    "abs",
    "sqrt",
    "argmax",
    "{",
    "}",
    "(",
    ")",
    "[",
    "]",
    ";",
    ",",
    ":",
    "=",
    "..",
    "..=",
    "->",
    "&&",
    "||",
    "!",
    "<",
    "<=",
    ">",
    ">=",
    "==",
    "!=",
    "+",
    "-",
    "*",
    "/",
    "x",
    "A",
    "0",
    "40",
    "0.5",
    "1e-6",
    "///",
    "/*",
    "*/",
    "//",
    "é",
    "\n",
];

#[derive(Clone, Debug)]
enum Mutation {
    Delete(usize),
    Duplicate(usize),
    Swap(usize, usize),
    Insert(usize, usize),
    Truncate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        any::<usize>().prop_map(Mutation::Delete),
        any::<usize>().prop_map(Mutation::Duplicate),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::Swap(a, b)),
        (any::<usize>(), 0..VOCAB.len()).prop_map(|(a, k)| Mutation::Insert(a, k)),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

/// Splits a text into words, numbers, single punctuation characters and whitespace runs.
fn tokens(src: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    let mut prev_kind = 0u8;
    for c in src.chars() {
        let kind = if c.is_alphanumeric() || c == '_' || c == '.' {
            1
        } else if c.is_whitespace() {
            2
        } else {
            3
        };
        match out.last_mut() {
            Some(last) if kind == prev_kind && kind != 3 => last.push(c),
            _ => out.push(c.to_string()),
        }
        prev_kind = kind;
    }
    out
}

fn mutate(src: &str, muts: &[Mutation]) -> String {
    let mut toks = tokens(src);
    for m in muts {
        let n = toks.len().max(1);
        match *m {
            Mutation::Delete(i) if !toks.is_empty() => {
                toks.remove(i % n);
            }
            Mutation::Duplicate(i) if !toks.is_empty() => {
                let t = toks[i % n].clone();
                toks.insert(i % n, t);
            }
            Mutation::Swap(a, b) if !toks.is_empty() => toks.swap(a % n, b % n),
            Mutation::Insert(i, k) => toks.insert(i % (toks.len() + 1), format!(" {} ", VOCAB[k])),
            Mutation::Truncate(i) => toks.truncate(i % (toks.len() + 1)),
            _ => {}
        }
    }
    toks.concat()
}

/// Checks `src` and asserts that every range of every diagnostic is a valid slice.
fn assert_sane(src: &str) {
    let checked = check(src);
    for d in &checked.diagnostics {
        let ranges = std::iter::once(&d.range).chain(d.labels.iter().map(|l| &l.range));
        for r in ranges {
            assert!(r.start <= r.end && r.end <= src.len(), "{d:?} in {src:?}");
            assert!(
                src.is_char_boundary(r.start) && src.is_char_boundary(r.end),
                "{d:?} in {src:?}"
            );
        }
        assert!(!d.message.is_empty() && !d.message.ends_with('.'));
    }
}

fn config() -> Config {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(1000);
    Config {
        cases,
        rng_seed: RngSeed::Fixed(0x4853_544c),
        failure_persistence: None,
        ..Config::default()
    }
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        assert_sane(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn mutated_fixtures_never_panic(
        which in 0..FIXTURES.len(),
        muts in proptest::collection::vec(mutation(), 1..8),
    ) {
        assert_sane(&mutate(FIXTURES[which], &muts));
    }
}

#[test]
fn pathological_inputs_are_reported_not_crashed_on() {
    let wrap = |body: String| format!("spec S {{ state {{ x: int in 0..=3 }} {body} }}");
    let cases = [
        wrap(format!("let A = {}x > 1{};", "(".repeat(5000), ")".repeat(5000))),
        wrap(format!("let A = {} x > 1;", "! ".repeat(5000))),
        wrap(format!("let A = {} x > 1;", "! ".repeat(100_000))),
        wrap(format!("let A = {} x > 1;", "- ".repeat(100_000))),
        wrap(format!("let A = {} x > 1;", "eventually ".repeat(100_000))),
        wrap(format!("let A = {} > 1; task A;", vec!["x"; 20000].join(" + "))),
        wrap(format!("let A = {}; task A;", vec!["x > 1"; 20000].join(" && "))),
        wrap(format!("let A = {};", "always ".repeat(3000) + "x > 1")),
        wrap(
            (0..3000).map(|i| format!("let L{i} = L{} && x > 1;", i + 1)).collect::<String>()
                + "let L3000 = x > 1; task L0;",
        ),
        wrap("/* unterminated".into()),
        wrap(format!("let A = {}{} x > 1; task A;", "/*".repeat(100_000), "*/".repeat(100_000))),
        format!("spec {}{} S {{ }}", "/*".repeat(100_000), "*/".repeat(100_000)),
        "{".repeat(100_000),
        "spec".repeat(10_000),
    ];
    for src in &cases {
        assert_sane(src);
    }
    // The long chains must be reported, not silently accepted as something else.
    assert!(check(&cases[0]).has_errors());
    assert!(check(&cases[2]).has_errors());
}
