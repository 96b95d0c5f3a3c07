//! Parsing with recovery: a small lexer finds comments and tokens, a balanced-delimiter
//! scanner splits the file into spec headers and items, and pest parses each piece on its
//! own. A broken item is reported at its exact position and skipped.

use std::ops::Range;

use pest::Parser as _;
use pest::iterators::{Pair, Pairs};

use crate::diagnostic::Diagnostic;
use crate::syntax::*;

/// The result of [`parse`]: the syntax tree of everything that parsed, and the syntax
/// errors (HSTL001, HSTL021).
#[derive(Clone, Debug, Default)]
pub struct Parsed {
    /// The syntax tree; broken items are left out.
    pub file: File,
    /// Syntax diagnostics, in source order.
    pub diagnostics: Vec<Diagnostic>,
}

/// Deepest bracket nesting the parser accepts; deeper input is reported, not parsed.
pub const MAX_NESTING: usize = 64;

/// Tallest formula or expression tree the parser builds (a long `a + b + ...` chain counts
/// one level per operator); taller ones are reported so that later passes cannot
/// overflow the stack.
pub const MAX_HEIGHT: usize = 256;

mod grammar {
    #![allow(missing_docs)]
    #[derive(pest_derive::Parser)]
    #[grammar = "grammar.pest"]
    pub struct HstlParser;
}

use grammar::{HstlParser, Rule};

mod build;
mod errors;
mod fast;
mod items;
mod lex;

use build::*;
use errors::*;
use fast::*;
use items::*;
use lex::*;
pub(crate) use lex::{Tok, TokKind, is_space, lex};

/// Items in a spec from which they are parsed on several threads.
const PARALLEL_ITEMS: usize = 512;

/// Most threads the parser uses.
const MAX_THREADS: usize = 4;

/// A parsed item (`None` if broken) and its diagnostics.
type ItemResult = (Option<Item>, Vec<Diagnostic>);

/// Why building a node failed: the item is reported and skipped.
struct Fail(Diagnostic);

/// Parses a source text. Never fails: what cannot be parsed is reported and skipped.
pub fn parse(src: &str) -> Parsed {
    parse_with(src, true)
}

/// [`parse`], with the items of a large spec parsed on several threads if `parallel`.
fn parse_with(src: &str, parallel: bool) -> Parsed {
    let mut diagnostics = Vec::new();
    let mut comments = Vec::new();
    let toks = lex(src, &mut comments, &mut diagnostics);
    let mut specs = Vec::new();
    let ends: Vec<usize> = toks.iter().map(|t| t.end).collect();
    let deep_comments = diagnostics
        .iter()
        .filter(|d| d.message.starts_with("block comments nested"))
        .filter_map(|d| {
            // Comments are in source order.
            let k = comments.partition_point(|c| c.range.start < d.range.start);
            comments.get(k).filter(|c| c.range.start == d.range.start)
        })
        .map(|c| c.range.clone())
        .collect();
    let open_strings = diagnostics
        .iter()
        .filter(|d| d.message == UNTERMINATED_STRING)
        .map(|d| d.range.start)
        .collect();
    let mut p = Splitter {
        src,
        deep_comments,
        open_strings,
        toks: &toks,
        ends: &ends,
        i: 0,
        parallel,
        diagnostics: &mut diagnostics,
    };
    while p.i < toks.len() {
        if let Some(spec) = p.spec() {
            specs.push(spec);
        }
    }
    Parsed { file: File { specs, comments }, diagnostics }
}

/// The value of a string literal as the grammar reads it (quotes included): `\"` and `\\`
/// resolved.
fn unescape(lit: &str) -> String {
    let inner = lit.strip_prefix('"').and_then(|s| s.strip_suffix('"')).unwrap_or(lit);
    let mut out = String::with_capacity(inner.len());
    let mut chars = inner.chars();
    while let Some(c) = chars.next() {
        if c == '\\' {
            out.extend(chars.next());
        } else {
            out.push(c);
        }
    }
    out
}

/// Words that are keywords of the grammar (`keyword` in `grammar.pest`): never names.
pub const KEYWORDS: [&str; 25] = [
    "spec",
    "state",
    "sequences",
    "sqrt",
    "int",
    "in",
    "float",
    "false",
    "let",
    "learn",
    "task",
    "true",
    "options",
    "option",
    "permutations",
    "always",
    "abs",
    "argmax",
    "eventually",
    "until",
    "once",
    "historically",
    "since",
    "prev",
    "next",
];

#[cfg(test)]
mod parallel_tests {
    use super::*;

    /// A large spec with broken items, unreadable ones and an unclosed brace parses on
    /// several threads exactly as on one.
    #[test]
    fn parallel_parse_is_sequential_parse() {
        let mut src = String::from("spec Big {\n    state { x: int in 0..=9 }\n");
        for i in 0..3000 {
            let item = match i % 10 {
                0 => format!("    let L{i} = x < ;\n"),
                1 => format!("    let L{i} = x > 1 until[0..2] x < 3 until x > 4;\n"),
                2 => format!("    option O{i} {{ reach: L{}, init: true }}\n", i - 1),
                3 => format!("    /// doc {i}\n    let L{i} = always[0..3] (x + 1 > 2) -> !L1;\n"),
                4 => format!("    let L{i} = ((((x)))) < 3 // c\n    ;\n"),
                _ => format!("    let L{i} = x * 2 - 1 >= {i} && x < 9;\n"),
            };
            src.push_str(&item);
        }
        for text in [src.clone(), format!("{src}}}\n"), src.replace("L15 ", "L15 $ ")] {
            assert_eq!(
                format!("{:?}", parse_with(&text, true)),
                format!("{:?}", parse_with(&text, false))
            );
        }
        assert!(parse_with(&src, true).diagnostics.len() > 300);
    }
}
