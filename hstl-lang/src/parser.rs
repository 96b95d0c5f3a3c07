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

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TokKind {
    Word,
    Number,
    Punct,
    Doc,
    /// A string literal, quotes included (closed or not: an open one ends at the line's end).
    Str,
    Other,
}

#[derive(Clone, Copy, Debug)]
pub(crate) struct Tok {
    pub(crate) kind: TokKind,
    pub(crate) start: usize,
    pub(crate) end: usize,
}

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

/// The lexer's message for a string without its closing quote.
const UNTERMINATED_STRING: &str = "unterminated string";

/// U+FEFF in UTF-8.
const BOM: &[u8] = "\u{feff}".as_bytes();

/// White space as the grammar's `WHITESPACE` reads it: space and `\t` to `\r`, so the
/// vertical tab too (which `u8::is_ascii_whitespace` leaves out).
pub(crate) fn is_space(c: u8) -> bool {
    matches!(c, b' ' | b'\t'..=b'\r')
}

pub(crate) fn lex(src: &str, comments: &mut Vec<Comment>, diags: &mut Vec<Diagnostic>) -> Vec<Tok> {
    let b = src.as_bytes();
    let mut toks = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let start = i;
        if is_space(c) {
            i += 1;
        } else if b[i..].starts_with(BOM) {
            // The grammar reads a byte order mark as whitespace (editors on Windows write one).
            i += BOM.len();
        } else if b[i..].starts_with(b"//") {
            while i < b.len() && b[i] != b'\n' && b[i] != b'\r' {
                i += 1;
            }
            let is_doc = b[start..].starts_with(b"///") && !b[start..].starts_with(b"////");
            if is_doc {
                toks.push(Tok { kind: TokKind::Doc, start, end: i });
            }
            let kind = if is_doc { CommentKind::Doc } else { CommentKind::Line };
            comments.push(Comment { kind, range: start..i });
        } else if b[i..].starts_with(b"/*") {
            let mut depth = 0usize;
            let mut deepest = 0usize;
            while i < b.len() {
                if b[i..].starts_with(b"/*") {
                    depth += 1;
                    deepest = deepest.max(depth);
                    i += 2;
                } else if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            if depth > 0 {
                i = b.len();
                diags.push(
                    Diagnostic::new("HSTL001", start..start + 2, "unterminated block comment")
                        .with_help("close it with `*/`"),
                );
            }
            if deepest > MAX_NESTING {
                // pest parses nested comments recursively: keep such text away from it.
                diags.push(Diagnostic::new(
                    "HSTL001",
                    start..start + 2,
                    format!("block comments nested too deeply (more than {MAX_NESTING} levels)"),
                ));
            }
            comments.push(Comment { kind: CommentKind::Block, range: start..i });
        } else if c == b'"' {
            i += 1;
            let mut closed = false;
            while i < b.len() && b[i] != b'\n' && b[i] != b'\r' {
                match b[i] {
                    b'"' => {
                        i += 1;
                        closed = true;
                        break;
                    }
                    // An escape is two bytes; only `\"` and `\\` are valid, which pest decides.
                    b'\\' if i + 1 < b.len() && matches!(b[i + 1], b'"' | b'\\') => i += 2,
                    _ => i += 1,
                }
            }
            if !closed {
                diags.push(
                    Diagnostic::new("HSTL001", start..start + 1, UNTERMINATED_STRING)
                        .with_help("close the string with `\"` on the same line"),
                );
            }
            toks.push(Tok { kind: TokKind::Str, start, end: i });
        } else if c.is_ascii_alphabetic() || c == b'_' {
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            toks.push(Tok { kind: TokKind::Word, start, end: i });
        } else if c.is_ascii_digit() {
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
            if i + 1 < b.len() && b[i] == b'.' && b[i + 1].is_ascii_digit() {
                i += 1;
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
            }
            if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                let mut j = i + 1;
                if j < b.len() && (b[j] == b'+' || b[j] == b'-') {
                    j += 1;
                }
                if j < b.len() && b[j].is_ascii_digit() {
                    i = j;
                    while i < b.len() && b[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            toks.push(Tok { kind: TokKind::Number, start, end: i });
        } else if c.is_ascii() {
            // Joint operators stay one token so that an error points at all of `..=`.
            let ops: [&[u8]; 10] =
                [b"..=", b"..", b"->", b"&&", b"||", b"<=", b">=", b"==", b"!=", b"::"];
            let len = ops.iter().find(|op| b[i..].starts_with(op)).map_or(1, |op| op.len());
            i += len;
            toks.push(Tok { kind: TokKind::Punct, start, end: i });
        } else {
            let len = src[i..].chars().next().map_or(1, char::len_utf8);
            i += len;
            toks.push(Tok { kind: TokKind::Other, start, end: i });
        }
    }
    toks
}

const ITEM_KEYWORDS: [&str; 6] = ["let", "task", "option", "state", "learn", "spec"];

struct Splitter<'a, 'd> {
    src: &'a str,
    deep_comments: Vec<Range<usize>>,
    /// Where each unterminated string starts, in source order (already reported).
    open_strings: Vec<usize>,
    toks: &'a [Tok],
    ends: &'a [usize],
    i: usize,
    /// Whether large specs are parsed on several threads.
    parallel: bool,
    diagnostics: &'d mut Vec<Diagnostic>,
}

impl Splitter<'_, '_> {
    fn text(&self, k: usize) -> &str {
        let t = self.toks[k];
        &self.src[t.start..t.end]
    }

    fn is(&self, k: usize, s: &str) -> bool {
        k < self.toks.len() && self.text(k) == s
    }

    /// Parses one spec starting at `self.i`, or skips junk up to the next `spec`.
    fn spec(&mut self) -> Option<Spec> {
        let start = self.i;
        let mut k = start;
        while k < self.toks.len() && self.toks[k].kind == TokKind::Doc {
            k += 1;
        }
        if !self.is(k, "spec") {
            // Junk at the top level: report it once and skip to the next spec.
            let bad = if k < self.toks.len() { k } else { start };
            let t = self.toks[bad];
            let (range, found) = if k < self.toks.len() {
                (t.start..t.end, format!("`{}`", self.text(bad)))
            } else {
                (t.end..t.end, "end of file".to_string())
            };
            let help = if found == "`;`" {
                "remove this `;`: a spec ends at its `}`"
            } else {
                "a file holds specs: `spec Name { ... }`"
            };
            self.diagnostics.push(
                Diagnostic::new("HSTL001", range, format!("expected `spec`, found {found}"))
                    .with_help(help),
            );
            self.i = k + 1;
            while self.i < self.toks.len() && !self.is(self.i, "spec") {
                self.i += 1;
            }
            // Docs in front of the next spec belong to it.
            while self.i > k + 1 && self.toks[self.i - 1].kind == TokKind::Doc {
                self.i -= 1;
            }
            return None;
        }
        let spec_kw = k;
        // Header: docs, `spec`, a name and `{`.
        let mut h = spec_kw + 1;
        while h < self.toks.len() && h < spec_kw + 3 && !self.is(h, "{") {
            h += 1;
        }
        let has_brace = self.is(h, "{");
        let header_end = if has_brace { h + 1 } else { h.min(self.toks.len()) };
        let head_range = self.toks[start].start..self.toks[header_end - 1].end;
        let mut doc = None;
        let mut name =
            Ident { name: String::new(), range: self.toks[spec_kw].start..self.toks[spec_kw].end };
        let head = if self.has_deep_comment(&head_range) {
            Err(None)
        } else {
            parse_detailed(Rule::spec_head, &self.src[head_range.clone()]).map_err(Some)
        };
        match head {
            Ok(mut pairs) => {
                let mut docs = Vec::new();
                if let Some(head) = pairs.next() {
                    for p in head.into_inner() {
                        match p.as_rule() {
                            Rule::doc => docs.push(p),
                            Rule::ident => name = ident(&p, head_range.start),
                            _ => {}
                        }
                    }
                }
                doc = make_doc(docs, head_range.start);
            }
            Err(None) => {}
            Err(Some(e)) => {
                self.diagnostics.push(self.syntax_error(&e, head_range.clone()));
            }
        }
        self.i = header_end;
        let mut items = Vec::new();
        let mut broken = Vec::new();
        let mut end = head_range.end;
        if !has_brace {
            // Without a body there is nothing more to read in this spec.
            return Some(Spec {
                doc,
                name,
                items,
                broken: Vec::new(),
                range: head_range.start..end,
            });
        }
        let mut bounds = Vec::new();
        let mut unclosed = None;
        loop {
            if self.i >= self.toks.len() {
                let at = self.src.len();
                unclosed = Some(
                    Diagnostic::new("HSTL001", at..at, "expected `}`, found end of file")
                        .with_label(self.toks[h].start..self.toks[h].end, "this `{` is not closed")
                        .with_help("close the spec with `}`"),
                );
                end = at;
                break;
            }
            if self.is(self.i, "}") {
                end = self.toks[self.i].end;
                self.i += 1;
                break;
            }
            if self.is(self.i, "spec") {
                let t = self.toks[self.i];
                unclosed = Some(
                    Diagnostic::new("HSTL001", t.start..t.end, "expected `}`, found `spec`")
                        .with_label(self.toks[h].start..self.toks[h].end, "this `{` is not closed")
                        .with_help("close the previous spec with `}` before starting another"),
                );
                end = self.toks[self.i - 1].end;
                break;
            }
            let (a, b) = self.item_bounds();
            self.i = b;
            bounds.push((a, b));
        }
        // Items are independent once split: parse them, then report in source order.
        for ((a, b), (item, mut diags)) in bounds.iter().zip(self.items(&bounds)) {
            self.diagnostics.append(&mut diags);
            match item {
                Some(item) => items.push(item),
                None => broken.push(self.broken(*a, *b)),
            }
        }
        self.diagnostics.extend(unclosed);
        Some(Spec { doc, name, items, broken, range: head_range.start..end })
    }

    /// Finds the tokens `[a, b)` of the item starting at `self.i`.
    fn item_bounds(&mut self) -> (usize, usize) {
        let a = self.i;
        let mut k = a;
        let mut depth = 0usize;
        let mut brace_depth = 0usize;
        let mut seen_non_doc = false;
        while k < self.toks.len() {
            let t = self.toks[k];
            let s = self.text(k);
            if seen_non_doc && k > a {
                let starts_item = (t.kind == TokKind::Word && ITEM_KEYWORDS.contains(&s))
                    || (s == "options" && brace_depth == 0)
                    || (s == "world"
                        && self.toks.get(k + 1).is_some_and(|n| n.kind == TokKind::Str))
                    || (t.kind == TokKind::Doc && depth == 0);
                if starts_item {
                    break;
                }
            }
            if depth == 0 && s == "}" {
                break;
            }
            if t.kind != TokKind::Doc {
                seen_non_doc = true;
            }
            k += 1;
            match s {
                "(" | "[" | "{" => {
                    depth += 1;
                    brace_depth += usize::from(s == "{");
                }
                ")" | "]" | "}" => {
                    depth = depth.saturating_sub(1);
                    if s == "}" {
                        brace_depth = brace_depth.saturating_sub(1);
                        if depth == 0 {
                            break;
                        }
                    }
                }
                ";" if depth == 0 => break,
                _ => {}
            }
        }
        (a, k.max(a + 1).min(self.toks.len()))
    }

    /// What a broken item seems to declare, from its tokens.
    fn broken(&self, a: usize, b: usize) -> BrokenItem {
        let mut k = a;
        while k < b && self.toks[k].kind == TokKind::Doc {
            k += 1;
        }
        let keyword =
            (k < b && self.toks[k].kind == TokKind::Word).then(|| self.text(k).to_string());
        let mut names = Vec::new();
        match keyword.as_deref() {
            Some("let" | "option") if k + 1 < b && self.toks[k + 1].kind == TokKind::Word => {
                names.push(self.text(k + 1).to_string());
            }
            Some("state") => {
                for j in k + 1..b.saturating_sub(1) {
                    if self.toks[j].kind == TokKind::Word && self.is(j + 1, ":") {
                        names.push(self.text(j).to_string());
                    }
                }
            }
            _ => {}
        }
        BrokenItem { keyword, names, range: self.toks[a].start..self.toks[b - 1].end }
    }

    /// Whether a block comment nested too deeply for pest lies inside `range` (it was
    /// reported by the lexer).
    fn has_deep_comment(&self, range: &Range<usize>) -> bool {
        // The comments are in source order and do not overlap.
        let k = self.deep_comments.partition_point(|c| c.end <= range.start);
        self.deep_comments.get(k).is_some_and(|c| c.start < range.end)
    }

    /// Whether a string that the lexer found unterminated (and reported) lies inside `range`.
    fn has_open_string(&self, range: &Range<usize>) -> bool {
        let k = self.open_strings.partition_point(|&s| s < range.start);
        self.open_strings.get(k).is_some_and(|&s| s < range.end)
    }

    /// Parses the items of `bounds` (token ranges), on several threads when there are
    /// many; each result comes with the item's diagnostics, in the order of `bounds`.
    fn items(&self, bounds: &[(usize, usize)]) -> Vec<ItemResult> {
        let serial = || bounds.iter().map(|&(a, b)| self.item(a, b)).collect();
        // Asking for the core count reads files, so small inputs never ask.
        if !self.parallel || bounds.len() < PARALLEL_ITEMS {
            return serial();
        }
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get()).min(MAX_THREADS);
        if threads < 2 {
            return serial();
        }
        let chunk = bounds.len().div_ceil(threads);
        let run = |part: &[(usize, usize)]| -> Vec<ItemResult> {
            part.iter().map(|&(a, b)| self.item(a, b)).collect()
        };
        std::thread::scope(|scope| {
            let mut parts = bounds.chunks(chunk);
            let first = parts.next().unwrap_or(&[]);
            let handles: Vec<_> = parts
                .map(|part| {
                    let spawned =
                        std::thread::Builder::new().spawn_scoped(scope, move || run(part));
                    (part, spawned)
                })
                .collect();
            let mut out = run(first);
            for (part, spawned) in handles {
                // A thread that could not start (or failed) leaves its part to this one.
                match spawned.ok().and_then(|h| h.join().ok()) {
                    Some(results) => out.extend(results),
                    None => out.extend(run(part)),
                }
            }
            out
        })
    }

    /// Parses the item of tokens `[a, b)`: the item, or `None` if it is broken, and its
    /// diagnostics.
    fn item(&self, a: usize, b: usize) -> ItemResult {
        let mut diagnostics = Vec::new();
        let item = self.item_into(a, b, &mut diagnostics);
        (item, diagnostics)
    }

    fn item_into(&self, a: usize, b: usize, diagnostics: &mut Vec<Diagnostic>) -> Option<Item> {
        let range = self.toks[a].start..self.toks[b - 1].end;
        if self.has_deep_comment(&range) || self.has_open_string(&range) {
            return None;
        }
        // Bracket nesting is checked before pest so that deep input cannot exhaust the stack.
        let mut depth = 0usize;
        for k in a..b {
            match self.text(k) {
                "(" | "[" | "{" => {
                    depth += 1;
                    if depth > MAX_NESTING {
                        let t = self.toks[k];
                        diagnostics.push(Diagnostic::new(
                            "HSTL001",
                            t.start..t.end,
                            format!("brackets nested too deeply (more than {MAX_NESTING} levels)"),
                        ));
                        return None;
                    }
                }
                ")" | "]" | "}" => depth = depth.saturating_sub(1),
                _ => {}
            }
        }
        let mut fb =
            Builder { offset: range.start, ends: &self.ends[a..b], diagnostics: Vec::new() };
        let mut fast = Fast { src: self.src, toks: &self.toks[a..b], b: &mut fb };
        if let Some(item) = fast.let_item()
            && fb.diagnostics.is_empty()
        {
            return Some(item);
        }
        let text = &self.src[range.clone()];
        match parse_detailed(Rule::item_entry, text) {
            Ok(mut pairs) => {
                let entry = pairs.next()?;
                let inner = entry.into_inner().find(|p| p.as_rule() != Rule::EOI)?;
                let mut b = Builder {
                    offset: range.start,
                    ends: &self.ends[a..b],
                    diagnostics: Vec::new(),
                };
                match b.item(inner) {
                    Ok(item) => {
                        diagnostics.append(&mut b.diagnostics);
                        Some(item)
                    }
                    Err(Fail(d)) => {
                        diagnostics.push(d);
                        None
                    }
                }
            }
            Err(e) => {
                diagnostics.push(self.syntax_error(&e, range));
                None
            }
        }
    }

    /// Turns a pest error on the text `piece` into an HSTL001 with readable expectations.
    fn syntax_error(&self, e: &pest::error::Error<Rule>, piece: Range<usize>) -> Diagnostic {
        let loc = match e.location {
            pest::error::InputLocation::Pos(p) => p,
            pest::error::InputLocation::Span((s, _)) => s,
        };
        let attempts = e.parse_attempts();
        let far = attempts.as_ref().map_or(loc, |a| a.max_position.max(loc));
        let pos = piece.start + far;
        let mut expected: Vec<String> = Vec::new();
        if let Some(attempts) = &attempts {
            // `ParsingToken` is not exported; its display is the literal for exact tokens.
            let tokens: Vec<String> =
                attempts.expected_tokens().iter().map(ToString::to_string).collect();
            expected.extend(describe_tokens(tokens));
        }
        if expected.is_empty()
            && far == loc
            && let pest::error::ErrorVariant::ParsingError { positives, .. } = &e.variant
        {
            expected.extend(positives.iter().filter_map(|r| rule_words(*r)).map(String::from));
        }
        let mut seen = std::collections::BTreeSet::new();
        expected.retain(|w| seen.insert(w.clone()));
        expected.sort_by_key(|w| (w.starts_with('`'), w.clone()));
        let what = match expected.len() {
            0 => "something else".to_string(),
            1 => expected[0].clone(),
            n => format!("{} or {}", expected[..n - 1].join(", "), expected[n - 1]),
        };
        // What was found: the next token in the whole file after the error position.
        // The tokens are in source order: a binary search keeps many errors linear.
        let k = self.toks.partition_point(|t| t.start < pos);
        let next = self.toks.get(k);
        let (range, found) = match next {
            Some(t) if t.start < piece.end => {
                (t.start..t.end, format!("`{}`", &self.src[t.start..t.end]))
            }
            Some(t) => (pos..pos, format!("`{}`", &self.src[t.start..t.end])),
            None => (pos..pos, "end of file".to_string()),
        };
        let limit = matches!(&e.variant,
            pest::error::ErrorVariant::CustomError { message } if message.contains("limit reached"));
        let message = if limit {
            "input too deeply nested to parse".to_string()
        } else {
            format!("expected {what}, found {found}")
        };
        let d = Diagnostic::new("HSTL001", range, message);
        match self.hint(k, &expected, &piece) {
            Some(help) if !limit => d.with_help(help),
            _ => d,
        }
    }

    /// Help for a syntax error found at token `k` (`expected` in words): a misspelt
    /// keyword, an interval written with a comma, a `;` too many.
    fn hint(&self, k: usize, expected: &[String], piece: &Range<usize>) -> Option<String> {
        let text = |j: usize| self.toks.get(j).map(|t| &self.src[t.start..t.end]);
        let found = text(k)?;
        let expects = |w: &str| expected.iter().any(|e| e == w);
        if found == ";" && expects("`let`") {
            return Some("remove this `;`: an item ends with its own".into());
        }
        if found == "[" {
            let before = text(k.wrapping_sub(1));
            if before == Some("prev") {
                return Some(
                    "`prev` takes no interval: it looks one step back; for a window write \
                     `once[a..=b] f` or `historically[a..=b] f`"
                        .into(),
                );
            }
            if before == Some("next") {
                return Some(
                    "`next` takes no interval: it looks one step ahead; for a window write \
                     `eventually[a..=b] f` or `always[a..=b] f`"
                        .into(),
                );
            }
        }
        if found == "," && expects("`..`") {
            let number =
                |j: usize| self.toks.get(j).filter(|t| t.kind == TokKind::Number).map(|_| text(j));
            let (a, b) = (number(k.wrapping_sub(1)).flatten()?, number(k + 1).flatten()?);
            return Some(format!(
                "an interval is a Rust range: `[{a}..={b}]` holds the steps {a} to {b}, \
                 `[{a}..{b}]` leaves out {b}"
            ));
        }
        if found == ":" && expects("`..`") {
            let number =
                |j: usize| self.toks.get(j).filter(|t| t.kind == TokKind::Number).map(|_| text(j));
            let (a, b) = (number(k.wrapping_sub(1)).flatten()?, number(k + 1).flatten()?);
            return Some(format!(
                "rtamt writes `[{a}:{b}]`; hstl writes `[{a}..={b}]` (the steps {a} to {b}), or \
                 `[{a}..{b}]` to leave out {b}"
            ));
        }
        // rtamt's and the textbooks' spellings, here or just before the error.
        for j in [k, k.wrapping_sub(1)] {
            let hint = match text(j) {
                Some("and" | "&" | "AND") => "write `&&` for and",
                Some("or" | "|" | "OR") => "write `||` for or",
                Some("not" | "NOT" | "~") => "write `!` for not",
                Some("implies" | "=>") => "write `->` for implies",
                Some("G") => "write `always` for G (□): `always[0..=10] f`",
                Some("F") => "write `eventually` for F (◇): `eventually[0..=10] f`",
                Some("U") => "write `until` for U: `f until[0..=10] g`",
                Some("H") => "write `historically` for H: `historically[0..=10] f`",
                Some("O") => "write `once` for O: `once[0..=10] f`",
                Some("S") => "write `since` for S: `f since[0..=10] g`",
                _ => continue,
            };
            return Some(hint.into());
        }
        // A word just before the error, or at it, that is a keyword misspelt.
        for j in [k.wrapping_sub(1), k] {
            let Some(t) = self.toks.get(j).filter(|t| t.kind == TokKind::Word) else { continue };
            if t.start < piece.start || KEYWORDS.contains(&&self.src[t.start..t.end]) {
                continue;
            }
            let word = &self.src[t.start..t.end];
            if let Some(kw) =
                crate::check::closest(word, KEYWORDS.iter().copied(), &mut u64::MAX.clone())
            {
                return Some(format!("did you mean `{kw}`?"));
            }
        }
        None
    }
}

/// Parses `text` again with pest's error details on, which name the literal tokens that
/// were expected (`;`, `&&`, ...). Details are switched on for the rest of the process
/// rather than toggled, so that parallel parses always see the same setting once an
/// error has been seen; they cost time only on the slow path of reporting.
fn reparse_with_detail(rule: Rule, text: &str) -> Option<pest::error::Error<Rule>> {
    pest::set_error_detail(true);
    DETAILS_ON.store(true, std::sync::atomic::Ordering::Release);
    HstlParser::parse(rule, text).err()
}

/// Whether pest collects error details: set right after pest's own switch, so a parse
/// that starts after reading `true` here has them.
static DETAILS_ON: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Parses `text` as `rule`; an error comes with pest's details (parsed a second time with
/// them if they were off).
fn parse_detailed(rule: Rule, text: &str) -> Result<Pairs<'_, Rule>, pest::error::Error<Rule>> {
    let detailed = DETAILS_ON.load(std::sync::atomic::Ordering::Acquire);
    HstlParser::parse(rule, text)
        .map_err(|e| if detailed { e } else { reparse_with_detail(rule, text).unwrap_or(e) })
}

/// Groups the literal tokens pest expected into a few readable words.
fn describe_tokens(tokens: Vec<String>) -> Vec<String> {
    const NOISE: [&str; 8] = ["/*", "//", "\u{feff}", ".", "e", "E", "BUILTIN_RULE", "+"];
    let mut set: std::collections::BTreeSet<String> = tokens
        .into_iter()
        .filter(|t| !(t.trim().is_empty() || t.len() == 4 && t.get(1..3) == Some("..")))
        .collect();
    // `+` alone is the exponent sign of a number; as an operator it comes with `*` and `/`.
    if set.contains("*") {
        set.insert("plus".into());
    }
    for n in NOISE {
        set.remove(n);
    }
    let mut out = Vec::new();
    let take = |set: &mut std::collections::BTreeSet<String>, group: &[&str]| -> bool {
        let mut any = false;
        for g in group {
            any |= set.remove(*g);
        }
        any
    };
    if take(
        &mut set,
        &["!", "always", "eventually", "once", "historically", "prev", "next", "true", "false"],
    ) {
        take(&mut set, &["(", "-", "abs", "sqrt", "_"]);
        out.push("a formula".to_string());
    } else if take(&mut set, &["abs", "sqrt"]) {
        take(&mut set, &["(", "-", "_"]);
        out.push("an expression".to_string());
    }
    if take(&mut set, &["_"]) {
        out.push("a name".to_string());
    }
    let cmp = take(&mut set, &["<", "<=", ">", ">=", "==", "!="]);
    let arith = take(&mut set, &["plus", "-", "*", "/"]);
    let logic = ["&&", "||", "->", "until", "since"].iter().any(|t| set.contains(*t));
    if cmp as u8 + arith as u8 + logic as u8 >= 2 {
        take(&mut set, &["&&", "||", "->", "until", "since"]);
        out.push("an operator".to_string());
    } else if cmp {
        out.push("a comparison operator".to_string());
    } else if arith {
        out.push("an arithmetic operator".to_string());
    }
    out.extend(set.into_iter().map(|t| format!("`{t}`")));
    out
}

/// Readable words for the rules pest reports as expected; `None` hides a rule.
fn rule_words(r: Rule) -> Option<&'static str> {
    Some(match r {
        Rule::ident => "a name",
        Rule::number | Rule::neg_number => "a number",
        Rule::doc => "a doc comment",
        Rule::formula => "a formula",
        Rule::paren_f => "a formula",
        Rule::comparison | Rule::expr => "an expression",
        Rule::cmp_op => "a comparison operator",
        Rule::add_op | Rule::mul_op => "an arithmetic operator",
        Rule::implies_op => "`->`",
        Rule::until_op => "`until`",
        Rule::since_op => "`since`",
        Rule::not_op => "`!`",
        Rule::or_op => "`||`",
        Rule::and_op => "`&&`",
        Rule::neg_op => "`-`",
        Rule::always_op => "`always`",
        Rule::eventually_op => "`eventually`",
        Rule::once_op => "`once`",
        Rule::historically_op => "`historically`",
        Rule::prev_op => "`prev`",
        Rule::next_op => "`next`",
        Rule::interval => "an interval such as `[0..40]`",
        Rule::incl_op | Rule::excl_op | Rule::range_op => "`..` or `..=`",
        Rule::var => "a state variable",
        Rule::var_type => "`int`, `float` or `time`",
        Rule::range_lit => "a range such as `0..=14`",
        Rule::field => "an option field (`reach`, `init` or `terminate`)",
        Rule::field_value => "a formula or `argmax`",
        Rule::option_body => "`;` or `{`",
        Rule::options_list => "`{`",
        Rule::options_gen | Rule::gen_kind => "`sequences` or `permutations`",
        Rule::seq => "an option name or `[A, B, ...]`",
        Rule::param => "a learning parameter",
        Rule::param_name => "a parameter name",
        Rule::param_value => "a parameter value",
        Rule::param_group => "`{`",
        Rule::state_item
        | Rule::let_item
        | Rule::task_item
        | Rule::option_item
        | Rule::options_item
        | Rule::learn_item
        | Rule::world_item => {
            "an item (`state`, `let`, `task`, `option`, `options`, `learn` or `world`)"
        }
        Rule::string => "a string such as `\"four-rooms\"`",
        Rule::k_world => "`world`",
        Rule::func => "`abs` or `sqrt`",
        Rule::call => "a function call",
        Rule::k_spec => "`spec`",
        Rule::k_state => "`state`",
        Rule::k_int => "`int`",
        Rule::k_float => "`float`",
        Rule::k_time => "`time`",
        Rule::k_in => "`in`",
        Rule::k_let => "`let`",
        Rule::k_task => "`task`",
        Rule::k_option => "`option`",
        Rule::k_options => "`options`",
        Rule::k_sequences => "`sequences`",
        Rule::k_permutations => "`permutations`",
        Rule::k_learn => "`learn`",
        Rule::k_always => "`always`",
        Rule::k_eventually => "`eventually`",
        Rule::k_until => "`until`",
        Rule::k_once => "`once`",
        Rule::k_historically => "`historically`",
        Rule::k_since => "`since`",
        Rule::k_prev => "`prev`",
        Rule::k_next => "`next`",
        Rule::k_true => "`true`",
        Rule::k_false => "`false`",
        Rule::k_abs => "`abs`",
        Rule::k_sqrt => "`sqrt`",
        Rule::k_argmax => "`argmax`",
        Rule::EOI => "the end of the item",
        _ => return None,
    })
}

fn ident(p: &Pair<'_, Rule>, offset: usize) -> Ident {
    let s = p.as_span();
    Ident { name: s.as_str().to_string(), range: s.start() + offset..s.end() + offset }
}

fn make_doc(docs: Vec<Pair<'_, Rule>>, offset: usize) -> Option<Doc> {
    if docs.is_empty() {
        return None;
    }
    let mut doc = Doc::default();
    for d in docs {
        let s = d.as_span();
        let text = s.as_str().trim_start_matches("///").trim_end_matches('\r');
        doc.lines.push(text.strip_prefix(' ').unwrap_or(text).to_string());
        doc.ranges.push(s.start() + offset..s.end() + offset);
    }
    Some(doc)
}

/// Builds syntax nodes from pest pairs of one item; `offset` is the item's byte offset.
struct Builder<'t> {
    offset: usize,
    /// End offsets of every token of the file, ascending: pest spans may include trailing
    /// whitespace and comments, and node ranges end at their last token instead.
    ends: &'t [usize],
    diagnostics: Vec<Diagnostic>,
}

type Res<T> = Result<T, Fail>;

/// An operand of a product, with the operator before it (`None` for the first) and its
/// height.
type Factor = (Option<BinOp>, (Expr, usize));

/// A formula operator: prefix (`!`, `always`, `eventually`, `once`, `historically`,
/// `prev`, `next`) or infix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum OpKind {
    Not,
    Always,
    Eventually,
    Once,
    Historically,
    Prev,
    Next,
    Implies,
    Or,
    And,
    Until,
    Since,
}

impl OpKind {
    /// Whether the operator comes before its one operand.
    fn is_prefix(self) -> bool {
        matches!(
            self,
            OpKind::Not
                | OpKind::Always
                | OpKind::Eventually
                | OpKind::Once
                | OpKind::Historically
                | OpKind::Prev
                | OpKind::Next
        )
    }

    /// Whether the operator takes an interval.
    fn takes_interval(self) -> bool {
        matches!(
            self,
            OpKind::Always
                | OpKind::Eventually
                | OpKind::Once
                | OpKind::Historically
                | OpKind::Until
                | OpKind::Since
        )
    }

    /// The prefix operator applied to `b`.
    fn apply(self, interval: Option<Interval>, b: Box<Formula>) -> FormulaKind {
        match self {
            OpKind::Not => FormulaKind::Not(b),
            OpKind::Always => FormulaKind::Always(interval, b),
            OpKind::Once => FormulaKind::Once(interval, b),
            OpKind::Historically => FormulaKind::Historically(interval, b),
            OpKind::Prev => FormulaKind::Prev(b),
            OpKind::Next => FormulaKind::Next(b),
            _ => FormulaKind::Eventually(interval, b),
        }
    }
}

/// A formula operator with its byte range (keyword and interval) and interval.
struct Op {
    kind: OpKind,
    range: Range<usize>,
    interval: Option<Interval>,
}

/// One element of a formula's flat sequence.
enum Piece {
    Op(Op),
    Operand(Formula, usize),
}

/// One element of an expression's flat sequence.
enum EPiece {
    /// A prefix `-` starting at this offset.
    Neg(usize),
    /// `+` or `-` between terms.
    Add(BinOp),
    /// `*` or `/` between factors.
    Mul(BinOp),
    /// An operand with its height.
    Operand(Expr, usize),
}

impl Builder<'_> {
    fn range(&self, p: &Pair<'_, Rule>) -> Range<usize> {
        let s = p.as_span();
        let (start, mut end) = (s.start() + self.offset, s.end() + self.offset);
        let k = self.ends.partition_point(|&e| e <= end);
        if k > 0 && self.ends[k - 1] > start {
            end = self.ends[k - 1];
        }
        start..end
    }

    fn number(&self, p: &Pair<'_, Rule>) -> NumberLit {
        let text = p.as_str().to_string();
        NumberLit { value: text.parse().unwrap_or(f64::NAN), text, range: self.range(p) }
    }

    /// `-` and a number (white space between them dropped from the text).
    fn neg_number(&self, p: &Pair<'_, Rule>) -> NumberLit {
        let text: String = p.as_str().split_whitespace().collect();
        NumberLit { value: text.parse().unwrap_or(f64::NAN), text, range: self.range(p) }
    }

    fn too_tall(&self, range: Range<usize>) -> Fail {
        Fail(
            Diagnostic::new(
                "HSTL001",
                range,
                format!("formula or expression too deeply nested (more than {MAX_HEIGHT} levels)"),
            )
            .with_help("split it into several `let`s"),
        )
    }

    fn item(&mut self, p: Pair<'_, Rule>) -> Res<Item> {
        let range = self.range(&p);
        let rule = p.as_rule();
        let mut docs = Vec::new();
        let mut rest = Vec::new();
        for c in p.into_inner() {
            if c.as_rule() == Rule::doc { docs.push(c) } else { rest.push(c) }
        }
        let doc = make_doc(docs, self.offset);
        Ok(match rule {
            Rule::state_item => {
                let mut vars = Vec::new();
                for v in rest.into_iter().filter(|c| c.as_rule() == Rule::var) {
                    vars.push(self.var(v));
                }
                Item::State(StateBlock { vars, range })
            }
            Rule::let_item => {
                let name =
                    rest.iter().find(|c| c.as_rule() == Rule::ident).map(|c| ident(c, self.offset));
                let f = rest.into_iter().find(|c| c.as_rule() == Rule::formula);
                match (name, f) {
                    (Some(name), Some(f)) => {
                        let (formula, _) = self.formula(f)?;
                        Item::Let(Let { doc, name, formula, range })
                    }
                    _ => return Err(self.internal(range)),
                }
            }
            Rule::task_item => {
                let kw = rest.iter().find(|c| c.as_rule() == Rule::k_task).map(|c| self.range(c));
                let f = rest.into_iter().find(|c| c.as_rule() == Rule::formula);
                match (kw, f) {
                    (Some(keyword_range), Some(f)) => {
                        let (formula, _) = self.formula(f)?;
                        Item::Task(Task { doc, formula, keyword_range, range })
                    }
                    _ => return Err(self.internal(range)),
                }
            }
            Rule::option_item => {
                let mut name = None;
                let mut fields = None;
                for c in rest {
                    match c.as_rule() {
                        Rule::ident => name = Some(ident(&c, self.offset)),
                        Rule::option_body => {
                            let mut fs = Vec::new();
                            for f in c.into_inner() {
                                fs.push(self.field(f)?);
                            }
                            fields = Some(fs);
                        }
                        _ => {}
                    }
                }
                let Some(name) = name else { return Err(self.internal(range)) };
                Item::Option(OptionDecl { doc, name, fields, range })
            }
            Rule::options_item => {
                let mut kind = None;
                for c in rest {
                    match c.as_rule() {
                        Rule::options_list => {
                            let mut seqs = Vec::new();
                            for s in c.into_inner() {
                                let r = self.range(&s);
                                let bracketed = s.as_str().starts_with('[');
                                let legs = s.into_inner().map(|i| ident(&i, self.offset)).collect();
                                seqs.push(SeqItem { legs, bracketed, range: r });
                            }
                            kind = Some(OptionsKind::List(seqs));
                        }
                        Rule::options_gen => {
                            let mut perm = false;
                            let mut names = Vec::new();
                            for g in c.into_inner() {
                                match g.as_rule() {
                                    Rule::gen_kind => perm = g.as_str() == "permutations",
                                    Rule::ident => names.push(ident(&g, self.offset)),
                                    _ => {}
                                }
                            }
                            kind = Some(if perm {
                                OptionsKind::Permutations(names)
                            } else {
                                OptionsKind::Sequences(names)
                            });
                        }
                        _ => {}
                    }
                }
                let Some(kind) = kind else { return Err(self.internal(range)) };
                Item::Options(OptionsItem { kind, range })
            }
            Rule::learn_item => {
                let params = rest
                    .into_iter()
                    .filter(|c| c.as_rule() == Rule::param)
                    .map(|c| self.param(c))
                    .collect::<Res<Vec<_>>>()?;
                Item::Learn(Learn { params, range })
            }
            Rule::world_item => {
                let Some(lit) = rest.iter().find(|c| c.as_rule() == Rule::string) else {
                    return Err(self.internal(range));
                };
                let name_range = self.range(lit);
                let name = unescape(lit.as_str());
                Item::World(WorldItem { doc, name, name_range, range })
            }
            _ => return Err(self.internal(range)),
        })
    }

    fn internal(&self, range: Range<usize>) -> Fail {
        Fail(Diagnostic::new("HSTL001", range, "could not read this item"))
    }

    fn var(&self, p: Pair<'_, Rule>) -> StateVar {
        let range = self.range(&p);
        let mut docs = Vec::new();
        let mut name = Ident { name: String::new(), range: range.clone() };
        let mut ty = VarType::Int;
        let mut ty_range = range.clone();
        let mut domain = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::doc => docs.push(c),
                Rule::ident => name = ident(&c, self.offset),
                Rule::var_type => {
                    ty_range = self.range(&c);
                    ty = match c.as_str() {
                        "int" => VarType::Int,
                        "time" => VarType::Time,
                        _ => VarType::Float,
                    };
                }
                Rule::range_lit => {
                    let r = self.range(&c);
                    let mut nums = Vec::new();
                    let mut inclusive = false;
                    for x in c.into_inner() {
                        match x.as_rule() {
                            Rule::number => nums.push(self.number(&x)),
                            Rule::neg_number => nums.push(self.neg_number(&x)),
                            Rule::range_op => inclusive = x.as_str() == "..=",
                            _ => {}
                        }
                    }
                    if let (Some(hi), Some(lo)) = (nums.pop(), nums.pop()) {
                        domain = Some(RangeLit { lo, hi, inclusive, range: r });
                    }
                }
                _ => {}
            }
        }
        StateVar { doc: make_doc(docs, self.offset), name, ty, ty_range, domain, range }
    }

    fn field(&mut self, p: Pair<'_, Rule>) -> Res<OptionField> {
        let range = self.range(&p);
        let mut name = None;
        let mut value = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::ident => name = Some(ident(&c, self.offset)),
                Rule::field_value => {
                    let r = self.range(&c);
                    let inner = c.into_inner().next();
                    value = Some(match inner {
                        Some(f) if f.as_rule() == Rule::formula => {
                            FieldValue::Formula(self.formula(f)?.0)
                        }
                        _ => FieldValue::Argmax(r),
                    });
                }
                _ => {}
            }
        }
        match (name, value) {
            (Some(name), Some(value)) => Ok(OptionField { name, value, range }),
            _ => Err(self.internal(range)),
        }
    }

    fn param(&self, p: Pair<'_, Rule>) -> Res<Param> {
        let range = self.range(&p);
        let mut name = None;
        let mut value = None;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::param_name => name = Some(ident(&c, self.offset)),
                Rule::param_value => {
                    let Some(v) = c.into_inner().next() else { continue };
                    value = Some(match v.as_rule() {
                        Rule::number => ParamValue::Number(self.number(&v)),
                        Rule::neg_number => ParamValue::Number(self.neg_number(&v)),
                        Rule::ident => ParamValue::Word(ident(&v, self.offset)),
                        _ => {
                            let r = self.range(&v);
                            let ps =
                                v.into_inner().map(|q| self.param(q)).collect::<Res<Vec<_>>>()?;
                            ParamValue::Group(ps, r)
                        }
                    });
                }
                _ => {}
            }
        }
        match (name, value) {
            (Some(name), Some(value)) => Ok(Param { name, value, range }),
            _ => Err(self.internal(range)),
        }
    }

    fn interval(&self, p: Pair<'_, Rule>) -> Interval {
        let range = self.range(&p);
        let mut nums = Vec::new();
        let mut inclusive = false;
        for c in p.into_inner() {
            match c.as_rule() {
                Rule::number => nums.push(self.number(&c)),
                Rule::incl_op => inclusive = true,
                _ => {}
            }
        }
        let mut it = nums.into_iter();
        let start = it.next().unwrap_or(NumberLit {
            value: 0.0,
            text: "0".into(),
            range: range.start..range.start,
        });
        Interval { start, end: it.next(), inclusive, range }
    }

    /// Builds a formula from a `formula` pair (a flat sequence of prefix operators,
    /// operands and infix operators) and returns it with its height.
    fn formula(&mut self, p: Pair<'_, Rule>) -> Res<(Formula, usize)> {
        // Fast path for a lone operand, the common case, without the bookkeeping below.
        let mut kids = p.clone().into_inner();
        if let (Some(only), None) = (kids.next(), kids.next()) {
            return self.primary(only);
        }
        let range = self.range(&p);
        let mut kids = p.into_inner();
        self.assemble(range, &mut |b: &mut Self| kids.next().map(|c| b.piece(c)))
    }

    /// One child of a `formula` pair as a piece: an operator or an operand.
    fn piece(&mut self, c: Pair<'_, Rule>) -> Res<Piece> {
        let kind = match c.as_rule() {
            Rule::not_op => OpKind::Not,
            Rule::always_op => OpKind::Always,
            Rule::eventually_op => OpKind::Eventually,
            Rule::once_op => OpKind::Once,
            Rule::historically_op => OpKind::Historically,
            Rule::prev_op => OpKind::Prev,
            Rule::next_op => OpKind::Next,
            Rule::implies_op => OpKind::Implies,
            Rule::or_op => OpKind::Or,
            Rule::and_op => OpKind::And,
            Rule::until_op => OpKind::Until,
            Rule::since_op => OpKind::Since,
            _ => {
                let (f, h) = self.primary(c)?;
                return Ok(Piece::Operand(f, h));
            }
        };
        let range = self.range(&c);
        let interval = if kind.takes_interval() {
            c.into_inner().find(|c| c.as_rule() == Rule::interval).map(|i| self.interval(i))
        } else {
            None
        };
        Ok(Piece::Op(Op { kind, range, interval }))
    }

    /// Builds a formula from its pieces in source order (prefix operators, operands and
    /// infix operators), applying precedence; `range` is the whole formula's, for errors.
    fn assemble(
        &mut self,
        range: Range<usize>,
        next: &mut dyn FnMut(&mut Self) -> Option<Res<Piece>>,
    ) -> Res<(Formula, usize)> {
        // Operands (each with its prefix operators) and the infix operators between them.
        let mut operands: Vec<(Formula, usize)> = Vec::new();
        let mut ops: Vec<Op> = Vec::new();
        let mut prefixes: Vec<Op> = Vec::new();
        while let Some(piece) = next(self) {
            match piece? {
                Piece::Op(op) if op.kind.is_prefix() => {
                    if prefixes.len() >= MAX_HEIGHT {
                        return Err(self.too_tall(range));
                    }
                    prefixes.push(op);
                }
                Piece::Op(op) => ops.push(op),
                Piece::Operand(mut f, mut h) => {
                    for op in prefixes.drain(..).rev() {
                        let r = op.range.start..f.range.end;
                        let kind = op.kind.apply(op.interval, Box::new(f));
                        f = Formula { kind, range: r };
                        h += 1;
                    }
                    if h > MAX_HEIGHT {
                        return Err(self.too_tall(range));
                    }
                    operands.push((f, h));
                }
            }
        }
        if operands.len() != ops.len() + 1 {
            return Err(self.internal(range));
        }
        if !ops.iter().any(|op| op.kind == OpKind::Implies) {
            return self.disjunction(operands, ops);
        }
        // Split at `->` (loosest, right-associative), then `||`, then `&&`, then `until`
        // and `since`.
        let mut segments: Vec<(Formula, usize)> = Vec::new();
        let mut operands = operands.into_iter();
        let mut group: Vec<(Formula, usize)> = operands.next().into_iter().collect();
        let mut group_ops: Vec<Op> = Vec::new();
        for (op, rhs) in ops.into_iter().zip(operands) {
            if op.kind == OpKind::Implies {
                segments.push(
                    self.disjunction(std::mem::take(&mut group), std::mem::take(&mut group_ops))?,
                );
            } else {
                group_ops.push(op);
            }
            group.push(rhs);
        }
        segments.push(self.disjunction(group, group_ops)?);
        let (mut acc, mut h) = segments.pop().ok_or_else(|| self.internal(range.clone()))?;
        while let Some((lhs, hl)) = segments.pop() {
            h = h.max(hl) + 1;
            if h > MAX_HEIGHT {
                return Err(self.too_tall(range));
            }
            let r = lhs.range.start..acc.range.end;
            acc = Formula { kind: FormulaKind::Implies(Box::new(lhs), Box::new(acc)), range: r };
        }
        Ok((acc, h))
    }

    /// Operands joined by `||`, `&&`, `until` and `since` (no `->`): `until` and `since`
    /// chains are folded as they come, grouped by `&&`, and those by `||`.
    fn disjunction(
        &mut self,
        operands: Vec<(Formula, usize)>,
        ops: Vec<Op>,
    ) -> Res<(Formula, usize)> {
        let mut operands = operands.into_iter();
        let Some(mut chain) = operands.next() else {
            return Err(Fail(Diagnostic::new("HSTL001", 0..0, "could not read this formula")));
        };
        // `until` and `since` operators folded into `chain` so far, and the first one's word.
        let mut untils = 0;
        let mut first = "until";
        let mut and_parts: Vec<(Formula, usize)> = Vec::new();
        let mut or_parts: Vec<(Formula, usize)> = Vec::new();
        for (op, rhs) in ops.into_iter().zip(operands) {
            match op.kind {
                OpKind::Or => {
                    and_parts.push(std::mem::replace(&mut chain, rhs));
                    or_parts.push(self.nary(std::mem::take(&mut and_parts), false)?);
                    untils = 0;
                }
                OpKind::And => {
                    and_parts.push(std::mem::replace(&mut chain, rhs));
                    untils = 0;
                }
                _ => {
                    let word = if op.kind == OpKind::Since { "since" } else { "until" };
                    if untils == 0 {
                        first = word;
                    }
                    chain = self.until(chain, op, rhs, untils, first)?;
                    untils += 1;
                }
            }
        }
        and_parts.push(chain);
        or_parts.push(self.nary(and_parts, false)?);
        self.nary(or_parts, true)
    }

    /// `acc until rhs` (or `since`), where `acc` already folds `count` `until`s and
    /// `since`s, the first of them `first` (a chain is reported as HSTL021 at its second
    /// operator and built from the left).
    fn until(
        &mut self,
        (acc, h): (Formula, usize),
        op: Op,
        (rhs, hr): (Formula, usize),
        count: usize,
        first: &str,
    ) -> Res<(Formula, usize)> {
        let since = op.kind == OpKind::Since;
        if count == 1 {
            let word = if since { "since" } else { "until" };
            let message = if word == first {
                format!("`{word}` is not chainable")
            } else {
                format!("`{first}` and `{word}` do not chain")
            };
            self.diagnostics.push(
                Diagnostic::new("HSTL021", op.range.clone(), message)
                    .with_label(acc.range.clone(), {
                        let article = if first == "until" { "an" } else { "a" };
                        format!("this is already {article} `{first}` formula")
                    })
                    .with_help(format!(
                        "add parentheses: `(a {first} b) {word} c` or `a {first} (b {word} c)`"
                    )),
            );
        }
        let h = h.max(hr) + 1;
        if h > MAX_HEIGHT {
            return Err(self.too_tall(acc.range.start..rhs.range.end));
        }
        let r = acc.range.start..rhs.range.end;
        let (a, b) = (Box::new(acc), Box::new(rhs));
        let kind = if since {
            FormulaKind::Since(a, op.interval, b)
        } else {
            FormulaKind::Until(a, op.interval, b)
        };
        Ok((Formula { kind, range: r }, h))
    }

    /// One operand, or an `Or`/`And` node over two or more.
    fn nary(&self, mut parts: Vec<(Formula, usize)>, or: bool) -> Res<(Formula, usize)> {
        if parts.len() == 1 {
            return parts.pop().ok_or_else(|| self.internal(0..0));
        }
        let h = parts.iter().map(|p| p.1).max().unwrap_or(0) + 1;
        let r = match (parts.first(), parts.last()) {
            (Some(a), Some(b)) => a.0.range.start..b.0.range.end,
            _ => return Err(self.internal(0..0)),
        };
        let fs = parts.into_iter().map(|p| p.0).collect();
        let kind = if or { FormulaKind::Or(fs) } else { FormulaKind::And(fs) };
        Ok((Formula { kind, range: r }, h))
    }

    /// An operand of a formula: `true`, `false`, a name, a comparison or `( formula )`.
    fn primary(&mut self, p: Pair<'_, Rule>) -> Res<(Formula, usize)> {
        let range = self.range(&p);
        match p.as_rule() {
            Rule::k_true => Ok((Formula { kind: FormulaKind::True, range }, 1)),
            Rule::k_false => Ok((Formula { kind: FormulaKind::False, range }, 1)),
            Rule::ident => {
                Ok((Formula { kind: FormulaKind::Name(ident(&p, self.offset)), range }, 1))
            }
            Rule::paren_f => {
                let f = p.into_inner().next().ok_or_else(|| self.internal(range.clone()))?;
                let (f, h) = self.formula(f)?;
                Ok((Formula { kind: FormulaKind::Paren(Box::new(f)), range }, h + 1))
            }
            Rule::comparison => {
                let mut it = p.into_inner();
                let e0 = it.next().ok_or_else(|| self.internal(range.clone()))?;
                let (first, mut h) = self.expr(e0)?;
                let mut rest = Vec::new();
                while let (Some(op), Some(e)) = (it.next(), it.next()) {
                    let cmp = match op.as_str() {
                        "<" => CmpOp::Lt,
                        "<=" => CmpOp::Le,
                        ">" => CmpOp::Gt,
                        ">=" => CmpOp::Ge,
                        "==" => CmpOp::Eq,
                        _ => CmpOp::Ne,
                    };
                    let (e, he) = self.expr(e)?;
                    h = h.max(he);
                    rest.push((cmp, self.range(&op), e));
                }
                Ok((Formula { kind: FormulaKind::Compare { first, rest }, range }, h + 1))
            }
            _ => Err(self.internal(range)),
        }
    }

    /// Builds an expression from an `expr` pair (prefix `-`, operands and `+ - * /`) and
    /// returns it with its height.
    fn expr(&mut self, p: Pair<'_, Rule>) -> Res<(Expr, usize)> {
        // Fast path for a lone operand, the common case.
        let mut kids = p.clone().into_inner();
        if let (Some(only), None) = (kids.next(), kids.next()) {
            return self.operand(only);
        }
        let range = self.range(&p);
        let mut kids = p.into_inner();
        self.assemble_expr(range, &mut |b: &mut Self| {
            kids.next().map(|c| match c.as_rule() {
                Rule::neg_op => Ok(EPiece::Neg(b.range(&c).start)),
                Rule::add_op => Ok(EPiece::Add(if c.as_str().starts_with('+') {
                    BinOp::Add
                } else {
                    BinOp::Sub
                })),
                Rule::mul_op => {
                    Ok(EPiece::Mul(if c.as_str() == "*" { BinOp::Mul } else { BinOp::Div }))
                }
                _ => b.operand(c).map(|(e, h)| EPiece::Operand(e, h)),
            })
        })
    }

    /// Builds an expression from its pieces in source order, applying precedence;
    /// `range` is the whole expression's, for errors.
    fn assemble_expr(
        &mut self,
        range: Range<usize>,
        next: &mut dyn FnMut(&mut Self) -> Option<Res<EPiece>>,
    ) -> Res<(Expr, usize)> {
        // Terms joined by `+`/`-`; each term is operands joined by `*`/`/`.
        let mut sums: Vec<(Option<BinOp>, Vec<Factor>)> = vec![(None, Vec::new())];
        let mut negs: Vec<usize> = Vec::new();
        let mut pending: Option<BinOp> = None;
        while let Some(piece) = next(self) {
            match piece? {
                EPiece::Neg(start) => {
                    if negs.len() >= MAX_HEIGHT {
                        return Err(self.too_tall(range));
                    }
                    negs.push(start);
                }
                EPiece::Add(op) => sums.push((Some(op), Vec::new())),
                EPiece::Mul(op) => pending = Some(op),
                EPiece::Operand(mut e, mut h) => {
                    for start in negs.drain(..).rev() {
                        let r = start..e.range.end;
                        e = Expr { kind: ExprKind::Neg(Box::new(e)), range: r };
                        h += 1;
                    }
                    if let Some(last) = sums.last_mut() {
                        last.1.push((pending.take(), (e, h)));
                    }
                }
            }
        }
        let mut acc: Option<(Expr, usize)> = None;
        for (add, factors) in sums {
            let mut term: Option<(Expr, usize)> = None;
            for (mul, (e, h)) in factors {
                term = Some(match (term, mul) {
                    (Some((a, ha)), Some(op)) => self.binary(op, a, ha, e, h, &range)?,
                    _ => (e, h),
                });
            }
            let Some((t, ht)) = term else { return Err(self.internal(range)) };
            acc = Some(match (acc, add) {
                (Some((a, ha)), Some(op)) => self.binary(op, a, ha, t, ht, &range)?,
                _ => (t, ht),
            });
        }
        acc.ok_or_else(|| self.internal(range))
    }

    #[allow(clippy::too_many_arguments)]
    fn binary(
        &self,
        op: BinOp,
        a: Expr,
        ha: usize,
        b: Expr,
        hb: usize,
        whole: &Range<usize>,
    ) -> Res<(Expr, usize)> {
        let h = ha.max(hb) + 1;
        if h > MAX_HEIGHT {
            return Err(self.too_tall(whole.clone()));
        }
        let r = a.range.start..b.range.end;
        Ok((Expr { kind: ExprKind::Binary(op, Box::new(a), Box::new(b)), range: r }, h))
    }

    /// An operand of an expression: a number, a name, `( expr )` or a call.
    fn operand(&mut self, c: Pair<'_, Rule>) -> Res<(Expr, usize)> {
        let range = self.range(&c);
        match c.as_rule() {
            Rule::number => Ok((Expr { kind: ExprKind::Number(self.number(&c)), range }, 1)),
            Rule::ident => Ok((Expr { kind: ExprKind::Name(ident(&c, self.offset)), range }, 1)),
            Rule::paren_e => {
                let f = c.into_inner().next().ok_or_else(|| self.internal(range.clone()))?;
                let (e, h) = self.expr(f)?;
                Ok((Expr { kind: ExprKind::Paren(Box::new(e)), range }, h + 1))
            }
            Rule::call => {
                let mut it = c.into_inner();
                let func = it.next().ok_or_else(|| self.internal(range.clone()))?;
                let func = if func.as_str() == "abs" { Func::Abs } else { Func::Sqrt };
                let arg = it.next().ok_or_else(|| self.internal(range.clone()))?;
                let (e, h) = self.expr(arg)?;
                Ok((Expr { kind: ExprKind::Call(func, Box::new(e)), range }, h + 1))
            }
            _ => Err(self.internal(range)),
        }
    }
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

/// A direct parser of `let` items over the lexer's tokens, for speed: it follows the
/// grammar's rules for `let_item`, `formula` and `expr` one for one (ordered choice,
/// greedy repetition with backtracking to the last complete repetition, the same
/// lookaheads) with a token for each of pest's terminals. It gives up (`None`) on
/// anything else, and the item then goes through pest, so pest stays the judge of the
/// language and of every error: an item this parser accepts is one pest accepts, with
/// the same tree (tested against pest in `fast_tests`).
struct Fast<'t, 'b> {
    src: &'t str,
    /// The item's tokens.
    toks: &'t [Tok],
    b: &'b mut Builder<'t>,
}

impl Fast<'_, '_> {
    fn text(&self, k: usize) -> &str {
        self.toks.get(k).map_or("", |t| &self.src[t.start..t.end])
    }

    fn is(&self, k: usize, s: &str) -> bool {
        self.text(k) == s
    }

    fn word(&self, k: usize) -> bool {
        self.toks.get(k).is_some_and(|t| t.kind == TokKind::Word)
    }

    /// `ident`: a word that is not a keyword.
    fn ident(&self, k: usize) -> Option<Ident> {
        if !self.word(k) || KEYWORDS.contains(&self.text(k)) {
            return None;
        }
        let t = self.toks[k];
        Some(Ident { name: self.text(k).to_string(), range: t.start..t.end })
    }

    fn number(&self, k: usize) -> Option<NumberLit> {
        let t = self.toks.get(k)?;
        if t.kind != TokKind::Number {
            return None;
        }
        let text = self.text(k).to_string();
        Some(NumberLit { value: text.parse().unwrap_or(f64::NAN), text, range: t.start..t.end })
    }

    /// Byte range from the start of token `a` to the end of token `b - 1`.
    fn span(&self, a: usize, b: usize) -> Range<usize> {
        self.toks[a].start..self.toks[b - 1].end
    }

    /// Whether pest's `cmp_op` would match at token `k` (pest compares characters).
    fn cmp_ahead(&self, k: usize) -> bool {
        let t = self.text(k);
        t.starts_with(['<', '>']) || t.starts_with("==") || t.starts_with("!=")
    }

    /// `add_op`: `+`, or `-` not followed by `>`.
    fn add_ahead(&self, k: usize) -> bool {
        let t = self.text(k);
        t.starts_with('+') || (t == "-" && !self.text(k + 1).starts_with('>'))
    }

    /// `neg_op`: `-` not followed by `>`.
    fn neg_ahead(&self, k: usize) -> bool {
        self.is(k, "-") && !self.text(k + 1).starts_with('>')
    }

    fn mul_ahead(&self, k: usize) -> bool {
        self.text(k).starts_with(['*', '/'])
    }

    /// `let_item` over all the tokens: `doc* let ident = formula ;`.
    fn let_item(&mut self) -> Option<Item> {
        let mut k = 0;
        let mut doc = Doc::default();
        while let Some(t) = self.toks.get(k).filter(|t| t.kind == TokKind::Doc) {
            let text = self.text(k).trim_start_matches("///").trim_end_matches('\r');
            doc.lines.push(text.strip_prefix(' ').unwrap_or(text).to_string());
            doc.ranges.push(t.start..t.end);
            k += 1;
        }
        if !self.is(k, "let") {
            return None;
        }
        let name = self.ident(k + 1)?;
        if !self.is(k + 2, "=") {
            return None;
        }
        let ((formula, _), k) = self.formula(k + 3)?;
        if !self.is(k, ";") || k + 1 != self.toks.len() {
            return None;
        }
        let doc = (!doc.lines.is_empty()).then_some(doc);
        Some(Item::Let(Let { doc, name, formula, range: self.span(0, k + 1) }))
    }

    /// `interval? `: the interval and the next token, or `None` and `k`.
    fn interval(&self, k: usize) -> (Option<Interval>, usize) {
        let parse = || {
            if !self.is(k, "[") {
                return None;
            }
            let start = self.number(k + 1)?;
            let (end, inclusive, j) = if self.is(k + 2, "..=") {
                (Some(self.number(k + 3)?), true, k + 4)
            } else if self.is(k + 2, "..") {
                match self.number(k + 3) {
                    Some(n) => (Some(n), false, k + 4),
                    None => (None, false, k + 3),
                }
            } else {
                return None;
            };
            if !self.is(j, "]") {
                return None;
            }
            Some((Interval { start, end, inclusive, range: self.span(k, j + 1) }, j + 1))
        };
        match parse() {
            Some((i, j)) => (Some(i), j),
            None => (None, k),
        }
    }

    /// `f_prefix*`, appended to `pieces`; returns the next token.
    fn prefixes(&self, mut k: usize, pieces: &mut Vec<Piece>) -> usize {
        loop {
            let kind = match self.text(k) {
                "!" if !self.text(k + 1).starts_with('=') => OpKind::Not,
                "always" if self.word(k) => OpKind::Always,
                "eventually" if self.word(k) => OpKind::Eventually,
                "once" if self.word(k) => OpKind::Once,
                "historically" if self.word(k) => OpKind::Historically,
                "prev" if self.word(k) => OpKind::Prev,
                "next" if self.word(k) => OpKind::Next,
                _ => return k,
            };
            let (interval, j) =
                if kind.takes_interval() { self.interval(k + 1) } else { (None, k + 1) };
            pieces.push(Piece::Op(Op { kind, range: self.span(k, j), interval }));
            k = j;
        }
    }

    /// `f_infix`: the operator and the next token.
    fn infix(&self, k: usize) -> Option<(Op, usize)> {
        let kind = match self.text(k) {
            "->" => OpKind::Implies,
            "||" => OpKind::Or,
            "&&" => OpKind::And,
            "until" if self.word(k) => OpKind::Until,
            "since" if self.word(k) => OpKind::Since,
            _ => return None,
        };
        let (interval, j) =
            if kind.takes_interval() { self.interval(k + 1) } else { (None, k + 1) };
        Some((Op { kind, range: self.span(k, j), interval }, j))
    }

    /// `formula`: the formula with its height and the next token.
    fn formula(&mut self, k0: usize) -> Option<((Formula, usize), usize)> {
        let mut pieces = Vec::new();
        let mut k = self.prefixes(k0, &mut pieces);
        let (f, h, j) = self.primary(k)?;
        k = j;
        if pieces.is_empty() && self.infix(k).is_none() {
            return Some(((f, h), k));
        }
        pieces.push(Piece::Operand(f, h));
        while let Some((op, j)) = self.infix(k) {
            let (save_len, save_k) = (pieces.len(), k);
            pieces.push(Piece::Op(op));
            let j = self.prefixes(j, &mut pieces);
            match self.primary(j) {
                Some((f, h, j)) => {
                    pieces.push(Piece::Operand(f, h));
                    k = j;
                }
                None => {
                    pieces.truncate(save_len);
                    k = save_k;
                    break;
                }
            }
        }
        if pieces.len() == 1 {
            if let Some(Piece::Operand(f, h)) = pieces.pop() {
                return Some(((f, h), k));
            }
            return None;
        }
        if let Some(built) = Self::uniform(&mut pieces) {
            return Some((built?, k));
        }
        let range = self.span(k0, k);
        let mut pieces = pieces.into_iter();
        let built = self.b.assemble(range, &mut |_| pieces.next().map(Ok)).ok()?;
        Some((built, k))
    }

    /// Operands joined by one of `&&` or `||` only, without prefix operators: the `And`
    /// or `Or` node that [`Builder::assemble`] builds, built directly (`Some(None)` if an
    /// operand is too tall, left to pest to report); `None` for other sequences.
    fn uniform(pieces: &mut Vec<Piece>) -> Option<Option<(Formula, usize)>> {
        let Some(Piece::Op(first)) = pieces.get(1) else { return None };
        let kind = first.kind;
        if !matches!(kind, OpKind::And | OpKind::Or) {
            return None;
        }
        let alternating = pieces.iter().enumerate().all(|(i, p)| match p {
            Piece::Operand(..) => i % 2 == 0,
            Piece::Op(op) => i % 2 == 1 && op.kind == kind,
        });
        if !alternating {
            return None;
        }
        let mut parts = Vec::with_capacity(pieces.len() / 2 + 1);
        let mut h = 0;
        for p in pieces.drain(..) {
            if let Piece::Operand(f, hf) = p {
                if hf > MAX_HEIGHT {
                    return Some(None);
                }
                h = h.max(hf);
                parts.push(f);
            }
        }
        let range = match (parts.first(), parts.last()) {
            (Some(a), Some(b)) => a.range.start..b.range.end,
            _ => return Some(None),
        };
        let kind =
            if kind == OpKind::And { FormulaKind::And(parts) } else { FormulaKind::Or(parts) };
        Some(Some((Formula { kind, range }, h + 1)))
    }

    /// `f_primary`: `true | false | name_ref | comparison | paren_f`.
    fn primary(&mut self, k: usize) -> Option<(Formula, usize, usize)> {
        let t = self.toks.get(k)?;
        let range = t.start..t.end;
        if self.word(k) {
            if self.is(k, "true") {
                return Some((Formula { kind: FormulaKind::True, range }, 1, k + 1));
            }
            if self.is(k, "false") {
                return Some((Formula { kind: FormulaKind::False, range }, 1, k + 1));
            }
            if let Some(name) = self.ident(k) {
                let j = k + 1;
                if !(self.cmp_ahead(j) || self.add_ahead(j) || self.mul_ahead(j)) {
                    return Some((Formula { kind: FormulaKind::Name(name), range }, 1, j));
                }
            }
        }
        if let Some(c) = self.comparison(k) {
            return Some(c);
        }
        if self.is(k, "(") {
            let ((f, h), j) = self.formula(k + 1)?;
            if self.is(j, ")") {
                let range = self.span(k, j + 1);
                return Some((
                    Formula { kind: FormulaKind::Paren(Box::new(f)), range },
                    h + 1,
                    j + 1,
                ));
            }
        }
        None
    }

    /// `comparison`: `expr (cmp_op expr)+`.
    fn comparison(&mut self, k: usize) -> Option<(Formula, usize, usize)> {
        let ((first, mut h), mut j) = self.expr(k)?;
        let mut rest = Vec::new();
        loop {
            let cmp = match self.text(j) {
                "<" => CmpOp::Lt,
                "<=" => CmpOp::Le,
                ">" => CmpOp::Gt,
                ">=" => CmpOp::Ge,
                "==" => CmpOp::Eq,
                "!=" => CmpOp::Ne,
                _ => break,
            };
            let Some(((e, he), next)) = self.expr(j + 1) else { break };
            h = h.max(he);
            rest.push((cmp, self.span(j, j + 1), e));
            j = next;
        }
        if rest.is_empty() {
            return None;
        }
        let range = self.span(k, j);
        Some((Formula { kind: FormulaKind::Compare { first, rest }, range }, h + 1, j))
    }

    /// `expr`: the expression with its height and the next token.
    fn expr(&mut self, k0: usize) -> Option<((Expr, usize), usize)> {
        let mut pieces = Vec::new();
        let mut k = k0;
        let negs = |s: &Self, mut k: usize, pieces: &mut Vec<EPiece>| {
            while s.neg_ahead(k) {
                pieces.push(EPiece::Neg(s.toks[k].start));
                k += 1;
            }
            k
        };
        k = negs(self, k, &mut pieces);
        let (e, h, j) = self.operand(k)?;
        k = j;
        if pieces.is_empty() && !(self.add_ahead(k) || self.mul_ahead(k)) {
            return Some(((e, h), k));
        }
        pieces.push(EPiece::Operand(e, h));
        loop {
            // Tokens, not characters, from here on: a doc comment starts with `/` but
            // cannot be followed by an operand, which is where pest fails on it.
            let op = match self.text(k) {
                "+" => EPiece::Add(BinOp::Add),
                "-" if self.add_ahead(k) => EPiece::Add(BinOp::Sub),
                "*" => EPiece::Mul(BinOp::Mul),
                "/" => EPiece::Mul(BinOp::Div),
                _ => break,
            };
            let (save_len, save_k) = (pieces.len(), k);
            pieces.push(op);
            let j = negs(self, k + 1, &mut pieces);
            match self.operand(j) {
                Some((e, h, j)) => {
                    pieces.push(EPiece::Operand(e, h));
                    k = j;
                }
                None => {
                    pieces.truncate(save_len);
                    k = save_k;
                    break;
                }
            }
        }
        if pieces.len() == 1 {
            if let Some(EPiece::Operand(e, h)) = pieces.pop() {
                return Some(((e, h), k));
            }
            return None;
        }
        let range = self.span(k0, k);
        // Operands joined by `+`/`-` only, or by `*`/`/` only, without a prefix `-`: a
        // fold from the left, as [`Builder::assemble_expr`] builds it.
        let adds = pieces.iter().all(|p| matches!(p, EPiece::Operand(..) | EPiece::Add(_)));
        let muls = pieces.iter().all(|p| matches!(p, EPiece::Operand(..) | EPiece::Mul(_)));
        if adds || muls {
            let mut pieces = pieces.into_iter();
            let Some(EPiece::Operand(mut acc, mut h)) = pieces.next() else { return None };
            while let (Some(EPiece::Add(op) | EPiece::Mul(op)), Some(EPiece::Operand(e, he))) =
                (pieces.next(), pieces.next())
            {
                (acc, h) = self.b.binary(op, acc, h, e, he, &range).ok()?;
            }
            return Some(((acc, h), k));
        }
        let mut pieces = pieces.into_iter();
        let built = self.b.assemble_expr(range, &mut |_| pieces.next().map(Ok)).ok()?;
        Some((built, k))
    }

    /// `e_primary`: `number | paren_e | call | ident`.
    fn operand(&mut self, k: usize) -> Option<(Expr, usize, usize)> {
        if let Some(n) = self.number(k) {
            let range = n.range.clone();
            return Some((Expr { kind: ExprKind::Number(n), range }, 1, k + 1));
        }
        if self.is(k, "(") {
            if let Some(((e, h), j)) = self.expr(k + 1)
                && self.is(j, ")")
            {
                let range = self.span(k, j + 1);
                return Some((Expr { kind: ExprKind::Paren(Box::new(e)), range }, h + 1, j + 1));
            }
            return None;
        }
        if self.word(k) && (self.is(k, "abs") || self.is(k, "sqrt")) {
            let func = if self.is(k, "abs") { Func::Abs } else { Func::Sqrt };
            if !self.is(k + 1, "(") {
                return None;
            }
            let ((e, h), j) = self.expr(k + 2)?;
            if !self.is(j, ")") {
                return None;
            }
            let range = self.span(k, j + 1);
            return Some((Expr { kind: ExprKind::Call(func, Box::new(e)), range }, h + 1, j + 1));
        }
        let name = self.ident(k)?;
        let range = name.range.clone();
        Some((Expr { kind: ExprKind::Name(name), range }, 1, k + 1))
    }
}

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

#[cfg(test)]
mod fast_tests {
    //! The direct `let` parser against pest: whenever it accepts an item, pest accepts it
    //! too and builds the same tree, without diagnostics.
    use super::*;
    use proptest::prelude::*;

    /// `text` cut to its first and last tokens, as the splitter hands items over.
    fn trimmed(text: &str) -> Option<String> {
        let toks = lex(text, &mut Vec::new(), &mut Vec::new());
        let (first, last) = (toks.first()?, toks.last()?);
        Some(text[first.start..last.end].to_string())
    }

    fn via_pest(text: &str, ends: &[usize]) -> Option<(Item, Vec<Diagnostic>)> {
        let mut pairs = HstlParser::parse(Rule::item_entry, text).ok()?;
        let inner = pairs.next()?.into_inner().find(|p| p.as_rule() != Rule::EOI)?;
        let mut b = Builder { offset: 0, ends, diagnostics: Vec::new() };
        let item = b.item(inner).ok()?;
        Some((item, b.diagnostics))
    }

    /// Whether the direct parser accepted `text`; panics if it disagrees with pest.
    fn agree(text: &str) -> bool {
        let Some(text) = trimmed(text) else { return false };
        let mut diags = Vec::new();
        let toks = lex(&text, &mut Vec::new(), &mut diags);
        if !diags.is_empty() {
            return false;
        }
        let ends: Vec<usize> = toks.iter().map(|t| t.end).collect();
        let mut b = Builder { offset: 0, ends: &ends, diagnostics: Vec::new() };
        let fast = Fast { src: &text, toks: &toks, b: &mut b }.let_item();
        let Some(fast) = fast.filter(|_| b.diagnostics.is_empty()) else { return false };
        match via_pest(&text, &ends) {
            Some((item, d)) => {
                assert_eq!(item, fast, "different trees for {text:?}");
                assert!(d.is_empty(), "pest reports {d:?} for {text:?}");
            }
            None => panic!("the direct parser accepts {text:?}, pest does not"),
        }
        true
    }

    #[test]
    fn fixture_lets_agree() {
        let mut accepted = 0;
        let mut dirs = vec![
            concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/valid").to_string(),
            concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/invalid").to_string(),
            concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/specs").to_string(),
        ];
        while let Some(dir) = dirs.pop() {
            let Ok(entries) = std::fs::read_dir(&dir) else { continue };
            for e in entries.flatten() {
                let path = e.path();
                if path.is_dir() {
                    dirs.push(path.display().to_string());
                    continue;
                }
                let Ok(src) = std::fs::read_to_string(&path) else { continue };
                // Every `let ... ;` piece of the file, as the splitter cuts it.
                let toks = lex(&src, &mut Vec::new(), &mut Vec::new());
                for (i, t) in toks.iter().enumerate() {
                    if &src[t.start..t.end] != "let" {
                        continue;
                    }
                    let mut a = i;
                    while a > 0 && toks[a - 1].kind == TokKind::Doc {
                        a -= 1;
                    }
                    let end = toks[i..].iter().find(|t| &src[t.start..t.end] == ";");
                    if let Some(end) = end {
                        accepted += usize::from(agree(&src[toks[a].start..end.end]));
                    }
                }
            }
        }
        assert!(accepted > 50, "only {accepted} fixture lets went through the direct parser");
    }

    const TOKENS: [&str; 45] = [
        "a",
        "b",
        "v0",
        "x_1",
        "true",
        "false",
        "always",
        "eventually",
        "until",
        "once",
        "historically",
        "since",
        "prev",
        "next",
        "!",
        "(",
        ")",
        "[",
        "]",
        "0",
        "1",
        "2.5",
        "1e3",
        "..",
        "..=",
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
        "->",
        "&&",
        "||",
        "abs",
        "sqrt",
        "=",
        ";",
        "///d\n",
        "in",
        ",",
    ];
    const SEPS: [&str; 10] =
        ["", " ", " ", "\n", "/* c */", "// c\n", "\t", "\u{b}", "\u{feff}", "//// c\n"];

    /// A formula of the language, as text.
    fn formula() -> impl Strategy<Value = String> {
        let expr = prop_oneof![
            Just("v0".to_string()),
            Just("2.5".to_string()),
            Just("-x_1".to_string()),
            Just("abs(v0 - 3)".to_string()),
            Just("(a + 1) * b / 2".to_string()),
            Just("sqrt(a*a)".to_string()),
        ];
        let cmp =
            (expr.clone(), prop::sample::select(vec!["<", "<=", ">", ">=", "==", "!="]), expr)
                .prop_map(|(a, op, b)| format!("{a} {op} {b}"));
        let leaf = prop_oneof![
            Just("true".to_string()),
            Just("false".to_string()),
            Just("L1".to_string()),
            cmp.clone(),
            (cmp, prop::sample::select(vec!["<", "<="]), Just("9"))
                .prop_map(|(c, op, n)| format!("{c} {op} {n}")),
        ];
        leaf.prop_recursive(4, 24, 3, |inner| {
            prop_oneof![
                (
                    inner.clone(),
                    prop::sample::select(vec![
                        "&&",
                        "||",
                        "->",
                        "until",
                        "until[0..3]",
                        "since",
                        "since[1..=4]"
                    ]),
                    inner.clone()
                )
                    .prop_map(|(a, op, b)| format!("{a} {op} {b}")),
                (
                    prop::sample::select(vec![
                        "!",
                        "always",
                        "eventually[0..=5]",
                        "always[2..]",
                        "!!",
                        "once",
                        "once[0..=5]",
                        "historically[2..]",
                        "prev",
                        "next",
                        "prev next !"
                    ]),
                    inner.clone()
                )
                    .prop_map(|(op, f)| format!("{op} {f}")),
                inner.prop_map(|f| format!("({f})")),
            ]
        })
    }

    /// A `let` around a formula, with its tokens re-joined by random separators and one
    /// token possibly replaced, inserted or deleted.
    fn item() -> impl Strategy<Value = String> {
        (
            formula(),
            prop::collection::vec(prop::sample::select(SEPS.to_vec()), 64),
            0usize..4,
            any::<prop::sample::Index>(),
            prop::sample::select(TOKENS.to_vec()),
            any::<bool>(),
        )
            .prop_map(|(f, seps, edit, at, tok, doc)| {
                let text = format!("{}let L = {f};", if doc { "/// d\n" } else { "" });
                let toks = lex(&text, &mut Vec::new(), &mut Vec::new());
                let mut words: Vec<String> =
                    toks.iter().map(|t| text[t.start..t.end].to_string()).collect();
                let i = at.index(words.len());
                match edit {
                    1 => words[i] = tok.to_string(),
                    2 => words.insert(i, tok.to_string()),
                    3 => {
                        words.remove(i);
                    }
                    _ => {}
                }
                let mut out = String::new();
                for (k, w) in words.iter().enumerate() {
                    out.push_str(w);
                    let sep = seps[k % seps.len()];
                    // Adjacent words would merge into one: keep a space between them.
                    out.push_str(if sep.is_empty() { " " } else { sep });
                }
                out
            })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]
        #[test]
        fn direct_parser_agrees_with_pest(text in item()) {
            agree(&text);
        }

        #[test]
        fn tight_text_agrees(f in formula()) {
            // No spaces at all where the language allows it.
            let tight: String = format!("let L={f};").split(' ').collect::<Vec<_>>().join("");
            agree(&tight);
            // A formula of the language goes through the direct parser, unless it chains
            // `until` or `since` (reported, so left to pest).
            let spaced = format!("let L = {f};");
            let chained = f.matches("until").count() + f.matches("since").count() > 1;
            prop_assert!(agree(&spaced) || chained, "{}", spaced);
        }
    }
}
