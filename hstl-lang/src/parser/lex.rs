//! The lexer: comments, tokens and string literals, shared by the parser, the formatter
//! and the incremental re-parse.

use super::*;

/// What a token is, as far as splitting items and formatting need to know.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum TokKind {
    Word,
    Number,
    Punct,
    Doc,
    /// A string literal, quotes included (closed or not: an open one ends at the line's end).
    Str,
    Other,
    /// A `//` comment: only in the formatter's stream (the parser keeps comments apart).
    LineComment,
    /// A `/* */` comment: likewise.
    BlockComment,
}

/// A token: its kind and byte range.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tok {
    pub(crate) kind: TokKind,
    pub(crate) start: usize,
    pub(crate) end: usize,
}

impl Tok {
    /// Whether the token is a comment (which only the formatter's stream holds).
    pub(crate) fn is_comment(self) -> bool {
        matches!(self.kind, TokKind::LineComment | TokKind::BlockComment)
    }
}

/// The lexer's message for a string without its closing quote.
pub(super) const UNTERMINATED_STRING: &str = "unterminated string";

/// U+FEFF in UTF-8.
pub(super) const BOM: &[u8] = "\u{feff}".as_bytes();

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
