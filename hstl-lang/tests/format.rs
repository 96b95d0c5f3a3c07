//! The formatter on every fixture of `tests/fixtures` and every spec of `examples/specs`:
//! idempotent, keeps every comment, changes nothing but layout (the formatted text checks
//! to the same specs and diagnostics, up to byte ranges), and refuses files with syntax
//! errors. The formatted valid fixtures are snapshotted. A property test runs the same
//! checks on grammar-aware mutations of the fixtures.

use std::path::Path;

use hstl_lang::syntax::CommentKind;
use hstl_lang::{check, format, parse};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

/// `(name, source)` of every `.hstl` file in the fixtures and `examples/specs`, sorted.
fn all_specs() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dirs = [
        ("valid", root.join("tests/fixtures/valid")),
        ("invalid", root.join("tests/fixtures/invalid")),
        ("examples", root.join("../examples/specs")),
    ];
    let mut out = Vec::new();
    for (label, dir) in dirs {
        let mut files: Vec<_> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|x| x == "hstl"))
            .collect();
        files.sort();
        assert!(!files.is_empty(), "no specs in {}", dir.display());
        for p in files {
            let name = format!("{label}/{}", p.file_name().unwrap_or_default().to_string_lossy());
            let src = std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{name}: {e}"));
            out.push((name, src));
        }
    }
    out
}

/// Replaces every `a..b` byte range in a debug rendering by `_`.
fn strip_ranges(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = String::with_capacity(s.len());
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() && (i == 0 || !b[i - 1].is_ascii_alphanumeric()) {
            let mut j = i;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            if b[j..].starts_with(b"..") && b.get(j + 2).is_some_and(u8::is_ascii_digit) {
                let mut k = j + 2;
                while k < b.len() && b[k].is_ascii_digit() {
                    k += 1;
                }
                out.push('_');
                i = k;
                continue;
            }
            out.push_str(&s[i..j]);
            i = j;
            continue;
        }
        let c = s[i..].chars().next().unwrap_or(' ');
        out.push(c);
        i += c.len_utf8();
    }
    out
}

/// What checking a text gives, without byte ranges: the specs and the diagnostics'
/// codes, severities and messages (without white space: some quote the source).
fn meaning(src: &str) -> (String, Vec<String>) {
    let checked = check(src);
    let specs = strip_ranges(&format!("{:#?}", checked.specs));
    let diags = checked
        .diagnostics
        .iter()
        .map(|d| {
            format!(
                "{} {:?} {}",
                d.code,
                d.severity,
                d.message.split_whitespace().collect::<String>()
            )
        })
        .collect();
    (specs, diags)
}

/// The text of every comment, in order (plain line comments without trailing white
/// space).
fn comments(src: &str) -> Vec<(CommentKind, String)> {
    parse(src)
        .file
        .comments
        .iter()
        .map(|c| {
            let text = &src[c.range.clone()];
            let text = if c.kind == CommentKind::Line { text.trim_end() } else { text };
            (c.kind, text.to_string())
        })
        .collect()
}

/// Everything the formatter promises, for one input. Returns the formatted text, or
/// `None` when the input has syntax errors (and was correctly refused).
fn holds(name: &str, src: &str) -> Option<String> {
    let parsed = parse(src);
    let has_syntax_errors = parsed.diagnostics.iter().any(|d| d.is_error());
    let formatted = match format(src) {
        Ok(text) => text,
        Err(diags) => {
            assert!(has_syntax_errors, "{name}: refused without a syntax error: {diags:?}");
            assert_eq!(diags, parsed.diagnostics, "{name}: refusal is not the parser's report");
            return None;
        }
    };
    assert!(!has_syntax_errors, "{name}: formatted despite syntax errors");
    assert_eq!(
        format(&formatted).as_deref(),
        Ok(formatted.as_str()),
        "{name}: not idempotent; first pass:\n{formatted}"
    );
    assert_eq!(comments(&formatted), comments(src), "{name}: comments changed:\n{formatted}");
    let (specs_before, diags_before) = meaning(src);
    let (specs_after, diags_after) = meaning(&formatted);
    assert_eq!(specs_after, specs_before, "{name}: checked specs differ:\n{formatted}");
    assert_eq!(diags_after, diags_before, "{name}: diagnostics differ:\n{formatted}");
    Some(formatted)
}

#[test]
fn every_fixture_and_example_formats_faithfully() {
    let mut formatted = 0;
    let mut refused = 0;
    for (name, src) in all_specs() {
        match holds(&name, &src) {
            Some(_) => formatted += 1,
            None => refused += 1,
        }
    }
    // Both paths must have been taken: the invalid fixtures include syntax errors.
    assert!(formatted >= 20, "only {formatted} inputs formatted");
    assert!(refused >= 3, "only {refused} inputs refused");
}

#[test]
fn valid_fixtures_snapshot() {
    for (name, src) in all_specs() {
        // Examples come and go with other work: only the fixtures are snapshotted.
        if !name.starts_with("valid/") {
            continue;
        }
        let out = format(&src).unwrap_or_else(|d| panic!("{name}: {d:?}"));
        let snap = name.replace('/', "__").trim_end_matches(".hstl").to_string();
        insta::assert_snapshot!(snap, out);
    }
}

#[test]
fn comments_stay_in_place() {
    let src = "// head\n/// Doc of S.\nspec S { // after brace\n  state { /* vars */ x: int in 0..=3 // x\n  }\n\n\n  // before A\n  let A = x > 1 /* inline */ && // wrapped\n      x < 3;\n  task always A; /* tail */\n  // before close\n}\n// end\n";
    let out = format(src).unwrap();
    insta::assert_snapshot!("comments_in_place", out);
    assert_eq!(format(&out).unwrap(), out);
    assert_eq!(comments(&out), comments(src));
}

#[test]
fn every_white_space_of_the_grammar_formats_as_a_space() {
    // The grammar's white space is space, `\t` to `\r` and U+FEFF; the vertical tab once
    // lexed as a token of its own, so the formatter wrote it out and added a comma after it.
    let plain = format("spec S {\n    state {\n        x: int in 0..=3,\n    }\n}\n").unwrap();
    for ws in ["\t", "\n", "\u{b}", "\u{c}", "\r", "\u{feff}"] {
        let src = format!("spec S {{\n    state {{\n        x: int in 0..=3,{ws}}}\n}}\n");
        assert_eq!(format(&src).unwrap(), plain, "{ws:?}");
    }
}

/// Lines longer than the formatter's width, so that the properties cover wrapping.
const LONG: &str = "spec Long {\n    state { x: int in 0..=14, y: int in 0..=14 }\n    \
    let Alpha = x > 3 && x < 9 && y > 10 && y < 14 && abs(x - y) < 20 && sqrt(x * x + y * y) > 0.5 && x + y > 1;\n    \
    let Bravo = (x > 1 || y > 1 || x + y > 3 || x - y < 7 || y - x < 7 || x * 2 > y || y * 2 > x || x + y > 20);\n    \
    task always[0..] (eventually[0..40] Alpha && eventually[0..40] Bravo && !(x > 13 && y > 13 && x + y > 26));\n    \
    option Alpha { reach: Alpha, init: x < 14 && y < 14 && x + y < 27 && x - y < 14 && y - x < 14 && x * y < 200 && x + 1 > 0 }\n    \
    option Bravo;\n}\n";

const FIXTURES: [&str; 8] = [
    LONG,
    include_str!("fixtures/valid/case_study_ot1.hstl"),
    include_str!("fixtures/valid/case_study_ot2.hstl"),
    include_str!("fixtures/valid/assembly.hstl"),
    include_str!("fixtures/valid/dock.hstl"),
    include_str!("fixtures/valid/memory_window.hstl"),
    include_str!("fixtures/valid/stop_on_entry.hstl"),
    include_str!("fixtures/valid/macro_spacing.hstl"),
];

/// Pieces to insert: tokens, comments and white space.
const VOCAB: [&str; 26] = [
    " ",
    "\u{b}",
    "\u{c}",
    "\n",
    "\n\n",
    "\t",
    "// c\n",
    "/* b */",
    "/* x\n y */",
    "/// d\n",
    "(",
    ")",
    "!",
    "-",
    "&&",
    "||",
    "->",
    ",",
    ";",
    "x",
    "1",
    "true",
    "always",
    "[0..3]",
    "{",
    "}",
];

/// A fixture with pieces inserted at random offsets (on char boundaries).
fn mutated() -> impl Strategy<Value = String> {
    (0..FIXTURES.len(), prop::collection::vec((any::<prop::sample::Index>(), 0..VOCAB.len()), 1..6))
        .prop_map(|(f, edits)| {
            let mut s = FIXTURES[f].to_string();
            for (at, v) in edits {
                let mut i = at.index(s.len() + 1);
                while !s.is_char_boundary(i) {
                    i -= 1;
                }
                s.insert_str(i, VOCAB[v]);
            }
            s
        })
}

/// Pieces that change only layout: white space and comments.
const LAYOUT: [&str; 7] = [" ", "\n", "\n\n\n", "\t", "// c\n", "/* b */", "/* x\n y */"];

/// A fixture with white space and comments inserted at existing white space outside
/// comments, so that it still parses: the formatter must keep its meaning and every comment.
fn relaid() -> impl Strategy<Value = String> {
    (
        0..FIXTURES.len(),
        prop::collection::vec((any::<prop::sample::Index>(), 0..LAYOUT.len()), 1..12),
    )
        .prop_map(|(f, edits)| {
            let mut s = FIXTURES[f].to_string();
            for (at, v) in edits {
                let in_comment =
                    parse(&s).file.comments.iter().map(|c| c.range.clone()).collect::<Vec<_>>();
                let spaces: Vec<usize> = s
                    .char_indices()
                    .filter(|(i, c)| {
                        c.is_whitespace()
                            && !in_comment.iter().any(|r| (r.start..=r.end).contains(i))
                    })
                    .map(|(i, _)| i)
                    .collect();
                let i = spaces[at.index(spaces.len())];
                s.insert_str(i, LAYOUT[v]);
            }
            s
        })
}

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(200)
}

proptest! {
    #![proptest_config(Config {
        cases: cases(),
        rng_seed: RngSeed::Fixed(0x5eed_f0e7),
        failure_persistence: None,
        ..Config::default()
    })]

    #[test]
    fn mutated_fixtures_format_faithfully(src in mutated()) {
        holds("mutated", &src);
    }

    #[test]
    fn relaid_fixtures_format_faithfully(src in relaid()) {
        // Insertions land outside comments, so the text still parses and the formatter
        // must take this path.
        prop_assert!(holds("relaid", &src).is_some(), "refused:\n{src}");
    }
}
