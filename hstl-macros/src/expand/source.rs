//! Rust tokens back to hstl source text, with a map from byte ranges to token spans.

use std::ops::Range;

use proc_macro2::{Delimiter, Spacing, Span, TokenStream, TokenTree};

/// The source text rebuilt from a token stream, and where each token landed in it.
#[derive(Clone, Debug)]
pub struct Source {
    /// The rebuilt text: one space between tokens, none inside a run of joint punctuation,
    /// doc attributes as `///` lines.
    pub text: String,
    /// One entry per token (a joint punctuation run, a doc attribute and each delimiter
    /// count as one), in text order.
    pub entries: Vec<Entry>,
}

/// Where one token (or merged run) sits in the text and which spans it came from.
#[derive(Clone, Debug)]
pub struct Entry {
    /// Byte range in [`Source::text`].
    pub range: Range<usize>,
    /// Span of the first token of the run.
    pub first: Span,
    /// Span of the last token of the run.
    pub last: Span,
}

impl Source {
    /// Rebuilds the source text of a token stream.
    pub fn from_tokens(tokens: TokenStream) -> Source {
        let mut b = Builder { text: String::new(), entries: Vec::new(), glue: false };
        b.stream(tokens);
        Source { text: b.text, entries: b.entries }
    }

    /// The spans of the first and last token a byte range covers. An empty range maps to
    /// the token at or after it (the last token at the end of the text); a range that
    /// covers no token maps to the next token.
    pub fn spans(&self, range: Range<usize>) -> (Span, Span) {
        let Some(last_entry) = self.entries.last() else {
            return (Span::call_site(), Span::call_site());
        };
        let overlaps = |e: &&Entry| {
            e.range.start < range.end.max(range.start + 1) && range.start < e.range.end
        };
        let first = self.entries.iter().find(overlaps);
        let last = self.entries.iter().rev().find(overlaps);
        match (first, last) {
            (Some(a), Some(b)) if !range.is_empty() => (a.first, b.last),
            _ => {
                let e =
                    self.entries.iter().find(|e| e.range.end > range.start).unwrap_or(last_entry);
                (e.first, e.last)
            }
        }
    }
}

struct Builder {
    text: String,
    entries: Vec<Entry>,
    // The previous token was joint punctuation, so a following punct extends its entry.
    glue: bool,
}

impl Builder {
    fn stream(&mut self, tokens: TokenStream) {
        let mut iter = tokens.into_iter().peekable();
        while let Some(tt) = iter.next() {
            if let TokenTree::Punct(p) = &tt
                && p.as_char() == '#'
                && let Some(TokenTree::Group(g)) = iter.peek()
                && let Some(doc) = doc_text(g)
            {
                let (first, last) = (p.span(), g.span());
                self.doc(&doc, first, last);
                iter.next();
                continue;
            }
            self.token(tt);
        }
    }

    fn token(&mut self, tt: TokenTree) {
        match tt {
            TokenTree::Group(g) => {
                let (open, close) = match g.delimiter() {
                    Delimiter::Parenthesis => ("(", ")"),
                    Delimiter::Brace => ("{", "}"),
                    Delimiter::Bracket => ("[", "]"),
                    Delimiter::None => ("", ""),
                };
                if !open.is_empty() {
                    self.push(open, g.span_open());
                }
                self.stream(g.stream());
                if !close.is_empty() {
                    self.push(close, g.span_close());
                }
            }
            TokenTree::Punct(p) => {
                let s = p.as_char().to_string();
                if self.glue
                    && let Some(e) = self.entries.last_mut()
                {
                    self.text.push_str(&s);
                    e.range.end = self.text.len();
                    e.last = p.span();
                } else {
                    self.push(&s, p.span());
                }
                self.glue = p.spacing() == Spacing::Joint;
            }
            TokenTree::Ident(i) => {
                // `r#type` names `type`: hstl has no raw identifiers and few keywords.
                let name = i.to_string();
                self.push(name.strip_prefix("r#").unwrap_or(&name), i.span());
            }
            TokenTree::Literal(l) => self.push(&l.to_string(), l.span()),
        }
    }

    fn separate(&mut self) {
        if !self.text.is_empty() && !self.text.ends_with('\n') {
            self.text.push(' ');
        }
    }

    fn push(&mut self, s: &str, span: Span) {
        self.separate();
        let start = self.text.len();
        self.text.push_str(s);
        self.entries.push(Entry { range: start..self.text.len(), first: span, last: span });
        self.glue = false;
    }

    fn doc(&mut self, doc: &str, first: Span, last: Span) {
        if !self.text.is_empty() && !self.text.ends_with('\n') {
            self.text.push('\n');
        }
        let start = self.text.len();
        for (i, line) in doc.split('\n').enumerate() {
            if i > 0 {
                self.text.push('\n');
            }
            self.text.push_str("///");
            self.text.push_str(line.trim_end_matches('\r'));
        }
        self.entries.push(Entry { range: start..self.text.len(), first, last });
        self.text.push('\n');
        self.glue = false;
    }
}

/// The text of a `[doc = "..."]` attribute body, unescaped.
fn doc_text(g: &proc_macro2::Group) -> Option<String> {
    if g.delimiter() != Delimiter::Bracket {
        return None;
    }
    let tts: Vec<TokenTree> = g.stream().into_iter().collect();
    match tts.as_slice() {
        [TokenTree::Ident(i), TokenTree::Punct(p), TokenTree::Literal(l)]
            if i == "doc" && p.as_char() == '=' =>
        {
            let lit: syn::LitStr = syn::parse2(TokenTree::Literal(l.clone()).into()).ok()?;
            Some(lit.value())
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source(text: &str) -> Source {
        Source::from_tokens(text.parse().expect("test input lexes"))
    }

    /// The (line, column) of the start of the first span and the end of the last.
    fn located(src: &Source, range: Range<usize>) -> ((usize, usize), (usize, usize)) {
        let (a, b) = src.spans(range);
        ((a.start().line, a.start().column), (b.end().line, b.end().column))
    }

    /// Each entry's text, for whole-map comparisons.
    fn pieces(src: &Source) -> Vec<&str> {
        src.entries.iter().map(|e| &src.text[e.range.clone()]).collect()
    }

    #[test]
    fn tokens_are_separated_by_one_space_and_joint_punct_is_glued() {
        let cases = [
            ("a&&b", "a && b", vec!["a", "&&", "b"]),
            ("x in 0..=14", "x in 0 ..= 14", vec!["x", "in", "0", "..=", "14"]),
            ("a -> b", "a -> b", vec!["a", "->", "b"]),
            ("a & & b", "a & & b", vec!["a", "&", "&", "b"]),
            ("x > -3", "x > - 3", vec!["x", ">", "-", "3"]),
            ("x>-3", "x >- 3", vec!["x", ">-", "3"]),
            ("r#type > 1", "type > 1", vec!["type", ">", "1"]),
        ];
        for (input, text, entries) in cases {
            let src = source(input);
            assert_eq!(src.text, text, "input {input:?}");
            assert_eq!(pieces(&src), entries, "input {input:?}");
        }
    }

    #[test]
    fn nested_groups_emit_their_delimiters() {
        let src = source("f(a[1..], {b})");
        assert_eq!(src.text, "f ( a [ 1 .. ] , { b } )");
        assert_eq!(pieces(&src), ["f", "(", "a", "[", "1", "..", "]", ",", "{", "b", "}", ")"]);
        // The entry of each closing delimiter points at that delimiter's column.
        let close = src.entries.iter().find(|e| &src.text[e.range.clone()] == "]").unwrap();
        assert_eq!(close.first.start().column, 7);
    }

    #[test]
    fn doc_attributes_become_doc_lines() {
        let src = source("/// Column.\nx: int,\n/** two\nlines */\ny: int");
        assert_eq!(src.text, "/// Column.\nx : int ,\n/// two\n///lines \ny : int");
        let doc = &src.entries[0];
        assert_eq!(&src.text[doc.range.clone()], "/// Column.");
        assert_eq!(located(&src, doc.range.clone()), ((1, 0), (1, 11)));
        // An attribute that is not a doc comment stays tokens.
        assert_eq!(source("#[cfg(x)] a").text, "# [ cfg ( x ) ] a");
    }

    #[test]
    fn byte_ranges_map_back_to_first_and_last_token() {
        let src = source("let A = x > 3 &&\n  y <= 14;");
        let at = |s: &str| src.text.find(s).unwrap();
        // One token.
        assert_eq!(located(&src, at("A")..at("A") + 1), ((1, 4), (1, 5)));
        // A range over several tokens, across a line.
        assert_eq!(located(&src, at("x")..at(";")), ((1, 8), (2, 9)));
        // A range that starts inside `<=` still underlines all of it.
        assert_eq!(located(&src, at("<=") + 1..at("<=") + 2), ((2, 4), (2, 6)));
        // An empty range at the end maps to the last token.
        assert_eq!(located(&src, src.text.len()..src.text.len()), ((2, 9), (2, 10)));
        // An empty range between tokens maps to the next one.
        assert_eq!(located(&src, at("=") + 1..at("=") + 1), ((1, 8), (1, 9)));
    }

    #[test]
    fn empty_input_maps_to_call_site() {
        let src = source("");
        assert_eq!(src.text, "");
        let (a, _) = src.spans(0..0);
        assert_eq!(format!("{a:?}"), format!("{:?}", Span::call_site()));
    }
}
