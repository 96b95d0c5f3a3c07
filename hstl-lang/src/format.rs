//! The formatter: one canonical layout for a spec file.
//!
//! [`format()`] re-emits the tokens of the file in their order and changes only the space
//! between them, so the formatted text parses to the same checked spec (up to byte
//! ranges). The layout:
//! - one item per line, indented by four spaces per level; a spec's items at level 1;
//! - `state { ... }`, long-form `option Name { ... }` and `learn { ... }` one entry per
//!   line, with a trailing comma; nested `learn` groups (`flat: { ... }`) and
//!   `options { ... }` lists on one line, without a trailing comma;
//! - one space between tokens, none inside brackets, before `,` `;` `:`, around `..` and
//!   `..=`, after a prefix `!` or `-`, between `abs`/`sqrt`/`sequences`/`permutations`
//!   and `(`, or between `always`/`eventually`/`until` and their interval;
//! - one blank line between specs; blank lines between items, entries and comments are
//!   kept (several become one), none after an opening or before a closing brace;
//! - every comment is kept, in its place: a comment that followed a token on its line
//!   stays there (after one space), one on a line of its own stays on a line of its own,
//!   indented like what follows it; trailing white space is dropped from line comments
//!   (not from doc comments, whose text is part of the checked spec).
//!
//! A `let`, `task` or option field longer than [`MAX_WIDTH`] characters (and without
//! comments) is broken before each operator of its formula's outermost `&&`, `||` or `->`
//! chain, one level deeper; that is the only wrapping. A file with syntax errors is not
//! formatted: [`format()`] returns the parser's diagnostics instead.

use crate::diagnostic::Diagnostic;
use crate::parser::{self, Tok, TokKind as Kind, parse};
use crate::syntax::{
    CommentKind, FieldValue, File, Formula, FormulaKind, Item, OptionsKind, Param, ParamValue,
};

/// One level of indentation.
pub const INDENT: &str = "    ";

/// Lines longer than this (in characters) are broken at the outermost `&&`, `||` or `->`
/// of their formula.
pub const MAX_WIDTH: usize = 100;

/// Formats a source text in the canonical layout.
///
/// Returns every diagnostic of [`parse`] when it reports an error (a file with syntax
/// errors is left to its author); otherwise the formatted text, which ends with one
/// newline (an empty or blank input gives an empty text). Formatting is idempotent:
/// formatting the result again gives the same text.
pub fn format(src: &str) -> Result<String, Vec<Diagnostic>> {
    let parsed = parse(src);
    if parsed.diagnostics.iter().any(Diagnostic::is_error) {
        return Err(parsed.diagnostics);
    }
    let toks = lex(src);
    let plan = Plan::new(&parsed.file, &toks, src);
    Ok(emit(src, &toks, &plan))
}

/// The parser's tokens (the one lexer), with its comments as tokens too, in source order.
pub(crate) fn lex(src: &str) -> Vec<Tok> {
    let mut comments = Vec::new();
    let mut toks = parser::lex(src, &mut comments, &mut Vec::new());
    // Doc comments are tokens already.
    toks.extend(comments.iter().filter_map(|c| {
        let kind = match c.kind {
            CommentKind::Line => Kind::LineComment,
            CommentKind::Block => Kind::BlockComment,
            CommentKind::Doc => return None,
        };
        Some(Tok { kind, start: c.range.start, end: c.range.end })
    }));
    toks.sort_unstable_by_key(|t| t.start);
    toks
}

/// A token that starts a line.
#[derive(Clone, Copy, Debug)]
struct Break {
    /// Indentation level of the token.
    indent: usize,
    /// Indentation level of comments on their own lines just before it.
    comment_indent: usize,
    /// Whether a blank line in the source before it is kept.
    blank_ok: bool,
    /// Whether a blank line always precedes it (a spec after another).
    blank: bool,
}

/// Where the layout differs from "one space between tokens".
struct Plan {
    breaks: Vec<Option<Break>>,
    /// Trailing commas to drop (token indices).
    skip: Vec<bool>,
    /// Tokens after which a trailing comma is added.
    comma_after: Vec<bool>,
}

impl Plan {
    fn new(file: &File, toks: &[Tok], src: &str) -> Plan {
        let n = toks.len();
        let mut plan =
            Plan { breaks: vec![None; n], skip: vec![false; n], comma_after: vec![false; n] };
        let text = |k: usize| &src[toks[k].start..toks[k].end];
        // First token starting at or after `offset`, and the token ending at `offset`.
        let first_at = |offset: usize| toks.partition_point(|t| t.start < offset);
        let ending_at = |offset: usize| {
            let k = toks.partition_point(|t| t.end < offset);
            (k < toks.len() && toks[k].end == offset).then_some(k)
        };
        for (n, spec) in file.specs.iter().enumerate() {
            plan.node(toks, first_at(spec.range.start), 0, n > 0);
            for item in &spec.items {
                plan.node(toks, first_at(item.range().start), 1, false);
                match item {
                    Item::Let(l) => plan.wrap(src, toks, &l.range, &l.formula, 1, 0),
                    Item::Task(t) => plan.wrap(src, toks, &t.range, &t.formula, 1, 0),
                    Item::Option(o) => {
                        for f in o.fields.iter().flatten() {
                            if let FieldValue::Formula(g) = &f.value {
                                plan.wrap(src, toks, &f.range, g, 2, 1);
                            }
                        }
                    }
                    _ => {}
                }
                let (entries, close): (Vec<usize>, usize) = match item {
                    Item::State(b) => (b.vars.iter().map(|v| v.range.start).collect(), b.range.end),
                    Item::Option(o) => match &o.fields {
                        Some(fields) => {
                            (fields.iter().map(|f| f.range.start).collect(), o.range.end)
                        }
                        None => continue,
                    },
                    Item::Learn(l) => {
                        for p in &l.params {
                            plan.inline_groups(p, &ending_at, &text, toks);
                        }
                        (l.params.iter().map(|p| p.range.start).collect(), l.range.end)
                    }
                    Item::Options(o) => {
                        if let OptionsKind::List(_) = o.kind {
                            plan.drop_trailing_comma(ending_at(o.range.end), &text, toks);
                        }
                        continue;
                    }
                    Item::Let(_) | Item::Task(_) | Item::World(_) => continue,
                };
                for start in entries {
                    plan.node(toks, first_at(start), 2, false);
                }
                if let Some(close) = ending_at(close) {
                    plan.breaks[close] =
                        Some(Break { indent: 1, comment_indent: 2, blank_ok: false, blank: false });
                    // The last code token before the brace: a comma, or the last entry's end.
                    if let Some(last) = (0..close).rev().find(|&j| !toks[j].is_comment())
                        && text(last) != ","
                        && text(last) != "{"
                    {
                        plan.comma_after[last] = true;
                    }
                }
            }
            if let Some(close) = ending_at(spec.range.end).filter(|&k| text(k) == "}") {
                plan.breaks[close] =
                    Some(Break { indent: 0, comment_indent: 1, blank_ok: false, blank: false });
            }
        }
        plan
    }

    /// Breaks before the doc lines of a node starting at token `k` and before its first
    /// code token.
    fn node(&mut self, toks: &[Tok], mut k: usize, indent: usize, blank: bool) {
        let mut first = true;
        while k < toks.len() {
            let t = toks[k];
            if t.is_comment() {
                k += 1;
                continue;
            }
            let b = Break { indent, comment_indent: indent, blank_ok: true, blank: blank && first };
            self.breaks[k] = Some(b);
            first = false;
            if t.kind != Kind::Doc {
                break;
            }
            k += 1;
        }
    }

    /// Breaks a line longer than [`MAX_WIDTH`] before each operator of the outermost
    /// `&&`, `||` or `->` chain of its formula (looking through parentheses and prefix
    /// operators), one level deeper than the line. `span` is the item or field; `extra`
    /// counts what follows it on its line (a field's comma). Lines with comments are
    /// left as they are.
    fn wrap(
        &mut self,
        src: &str,
        toks: &[Tok],
        span: &std::ops::Range<usize>,
        f: &Formula,
        indent: usize,
        extra: usize,
    ) {
        let a = toks.partition_point(|t| t.start < span.start);
        let b = toks.partition_point(|t| t.start < span.end);
        let mut width = indent * INDENT.len() + extra;
        let mut prev: Option<Tok> = None;
        let mut prev_minus = false;
        for &t in &toks[a..b] {
            if t.kind == Kind::Doc {
                continue;
            }
            if t.is_comment() {
                return;
            }
            let text = &src[t.start..t.end];
            if let Some(p) = prev {
                width += spacing(&src[p.start..p.end], prev_minus, text).len();
            }
            width += text.chars().count();
            prev_minus = text == "-" && minus_is_prefix(src, prev);
            prev = Some(t);
        }
        if width <= MAX_WIDTH {
            return;
        }
        let mut g = f;
        while let FormulaKind::Paren(x)
        | FormulaKind::Not(x)
        | FormulaKind::Always(_, x)
        | FormulaKind::Eventually(_, x)
        | FormulaKind::Once(_, x)
        | FormulaKind::Historically(_, x)
        | FormulaKind::Prev(x)
        | FormulaKind::Next(x) = &g.kind
        {
            g = x;
        }
        let operands: Vec<&Formula> = match &g.kind {
            FormulaKind::And(v) | FormulaKind::Or(v) => v.iter().collect(),
            FormulaKind::Implies(l, r) => vec![l, r],
            _ => return,
        };
        for w in operands.windows(2) {
            let k = toks.partition_point(|t| t.start < w[0].range.end);
            if let Some(op) = (k..b).find(|&j| !toks[j].is_comment()) {
                let level = indent + 1;
                let brk =
                    Break { indent: level, comment_indent: level, blank_ok: false, blank: false };
                self.breaks[op] = Some(brk);
            }
        }
    }

    /// Nested `{ ... }` groups of a learn parameter stay on one line without a trailing
    /// comma.
    fn inline_groups<'s>(
        &mut self,
        p: &Param,
        ending_at: &dyn Fn(usize) -> Option<usize>,
        text: &dyn Fn(usize) -> &'s str,
        toks: &[Tok],
    ) {
        if let ParamValue::Group(ps, range) = &p.value {
            self.drop_trailing_comma(ending_at(range.end), text, toks);
            for q in ps {
                self.inline_groups(q, ending_at, text, toks);
            }
        }
    }

    /// Drops the comma before the closing brace at token `close`, if there is one.
    fn drop_trailing_comma<'s>(
        &mut self,
        close: Option<usize>,
        text: &dyn Fn(usize) -> &'s str,
        toks: &[Tok],
    ) {
        if let Some(close) = close
            && let Some(last) = (0..close).rev().find(|&j| !toks[j].is_comment())
            && text(last) == ","
        {
            self.skip[last] = true;
        }
    }
}

/// Whether a `-` after token `prev` is a prefix minus.
fn minus_is_prefix(src: &str, prev: Option<Tok>) -> bool {
    match prev {
        None => true,
        Some(p) => {
            let text = &src[p.start..p.end];
            match p.kind {
                // A string is one word as far as the space around it goes: no keyword.
                Kind::Number | Kind::Str => false,
                Kind::Word => matches!(
                    text,
                    "always"
                        | "eventually"
                        | "until"
                        | "once"
                        | "historically"
                        | "since"
                        | "prev"
                        | "next"
                        | "in"
                ),
                _ => text != ")",
            }
        }
    }
}

/// The space between two code tokens on one line.
fn spacing(a: &str, prefix_minus: bool, b: &str) -> &'static str {
    if matches!(b, "," | ";" | ")" | "]" | ":" | ".." | "..=")
        || matches!(a, "(" | "[" | ".." | "..=" | "!")
        || (a == "-" && prefix_minus)
        || (b == "(" && matches!(a, "abs" | "sqrt" | "sequences" | "permutations"))
        || (b == "["
            && matches!(a, "always" | "eventually" | "until" | "once" | "historically" | "since"))
    {
        ""
    } else {
        " "
    }
}

fn emit(src: &str, toks: &[Tok], plan: &Plan) -> String {
    let mut out = String::with_capacity(src.len() + src.len() / 8);
    let newlines = |a: usize, b: usize| src[a..b].bytes().filter(|&c| c == b'\n').count();
    let mut prev: Option<Tok> = None;
    let mut prev_prefix_minus = false;
    let mut last_end = 0usize;
    let mut indent = 0usize;
    let mut pending_newline = false;
    for (k, &t) in toks.iter().enumerate() {
        if plan.skip[k] {
            last_end = t.end;
            continue;
        }
        let text = &src[t.start..t.end];
        let gap = newlines(last_end, t.start);
        if t.is_comment() {
            let own_line = out.is_empty() || gap > 0;
            if out.is_empty() {
            } else if own_line || pending_newline {
                let next = (k + 1..toks.len()).find(|&j| !toks[j].is_comment());
                let level = match next {
                    None => 0,
                    Some(j) => plan.breaks[j].map_or(indent + 1, |b| b.comment_indent),
                };
                let blank = own_line && gap >= 2 && !out.ends_with('{');
                newline(&mut out, blank, level);
            } else {
                out.push(' ');
            }
            if t.kind == Kind::LineComment {
                out.push_str(text.trim_end());
                pending_newline = true;
            } else {
                out.push_str(text);
                let next_start = toks.get(k + 1).map_or(src.len(), |n| n.start);
                pending_newline = newlines(t.end, next_start) > 0;
            }
            last_end = t.end;
            continue;
        }
        if let Some(b) = plan.breaks[k] {
            if !out.is_empty() {
                let blank = b.blank || (b.blank_ok && gap >= 2 && !out.ends_with('{'));
                newline(&mut out, blank, b.indent);
            }
            indent = b.indent;
        } else if pending_newline || t.kind == Kind::Doc {
            newline(&mut out, false, indent + 1);
        } else if let Some(p) = prev {
            out.push_str(spacing(&src[p.start..p.end], prev_prefix_minus, text));
        }
        if t.kind == Kind::Doc {
            // Verbatim: its text, trailing white space included, is the item's doc string.
            out.push_str(text);
            pending_newline = true;
        } else {
            out.push_str(text);
            pending_newline = false;
        }
        prev_prefix_minus = text == "-" && minus_is_prefix(src, prev);
        prev = Some(t);
        if plan.comma_after[k] {
            out.push(',');
            prev = Some(Tok { kind: Kind::Punct, start: 0, end: 0 });
        }
        last_end = t.end;
    }
    if !out.is_empty() {
        out.push('\n');
    }
    out
}

fn newline(out: &mut String, blank: bool, level: usize) {
    while out.ends_with(' ') {
        out.pop();
    }
    out.push('\n');
    if blank {
        out.push('\n');
    }
    for _ in 0..level {
        out.push_str(INDENT);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spaces_operators_and_brackets() {
        let src = "spec S{state{x:int in 0..=9,y:float}let A=x>3&&-x<-(y-1)||!(abs(x)>=2);\
                   task always[0..]eventually[0..=4]A;}";
        let out = format(src).unwrap();
        assert_eq!(
            out,
            "spec S {\n    state {\n        x: int in 0..=9,\n        y: float,\n    }\n    \
             let A = x > 3 && -x < -(y - 1) || !(abs(x) >= 2);\n    \
             task always[0..] eventually[0..=4] A;\n}\n"
        );
        assert_eq!(format(&out).unwrap(), out);
    }

    #[test]
    fn long_lines_break_at_the_outermost_chain() {
        let long =
            "eventually[0..40] Alpha && eventually[0..40] Bravo && eventually[0..40] Charlie";
        let src = format!("spec S {{ task always[0..] ({long});\n let A = x > 1 && y < 2; }}");
        let out = format(&src).unwrap();
        assert_eq!(
            out,
            "spec S {\n    task always[0..] (eventually[0..40] Alpha\n        \
             && eventually[0..40] Bravo\n        && eventually[0..40] Charlie);\n    \
             let A = x > 1 && y < 2;\n}\n"
        );
        assert_eq!(format(&out).unwrap(), out);
        // With a comment inside, the author's line breaks are kept instead.
        let commented = src.replace("Bravo", "Bravo /* b */");
        assert!(format(&commented).unwrap().contains("Alpha && eventually"));
    }

    #[test]
    fn refuses_syntax_errors() {
        let err = format("spec S { let A = ; }").unwrap_err();
        assert!(err.iter().any(|d| d.code == "HSTL001"));
    }

    #[test]
    fn empty_input_stays_empty() {
        assert_eq!(format("").unwrap(), "");
        assert_eq!(format("  \n\n").unwrap(), "");
    }
}
