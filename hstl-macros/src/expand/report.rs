//! hstl diagnostics as Rust compile errors and warnings.

use hstl_lang::{Diagnostic, Severity};
use proc_macro2::{Ident, Span, TokenStream};
use quote::{quote, quote_spanned};

use super::source::Source;

/// Where diagnostics point: at tokens of the macro input, or all at one place (an
/// `include` token) with `path:line:col` in the message.
pub enum Target<'a> {
    /// The input tokens the text was rebuilt from.
    Tokens(&'a Source),
    /// A file read at compile time, reported at the `include` tokens.
    File {
        /// The path as the user wrote it.
        path: &'a str,
        /// The file's text.
        text: &'a str,
        /// First and last span of the `include "..."` tokens.
        spans: (Span, Span),
    },
}

/// An error over the tokens from `first` to `last`. `Span::join` is unstable, so the
/// range is carried by a two-token stream as `syn::Error::new_spanned` reads it.
pub fn spanned_error(first: Span, last: Span, message: &str) -> syn::Error {
    let a = Ident::new("first", first);
    let b = Ident::new("last", last);
    syn::Error::new_spanned(quote!(#a #b), message)
}

/// The compile errors of every error diagnostic (labels become separate `note:` errors at
/// their own spans), combined; `None` when there is none.
pub fn errors(target: &Target, diagnostics: &[Diagnostic]) -> Option<syn::Error> {
    let mut all: Option<syn::Error> = None;
    let mut add = |e: syn::Error| match &mut all {
        Some(a) => a.combine(e),
        None => all = Some(e),
    };
    for d in diagnostics.iter().filter(|d| d.severity == Severity::Error) {
        let (first, last) = spans(target, d.range.clone());
        add(spanned_error(first, last, &message(target, d)));
        for label in &d.labels {
            let (first, last) = spans(target, label.range.clone());
            let at = match target {
                Target::Tokens(_) => String::new(),
                Target::File { path, text, .. } => {
                    format!("{}: ", location(path, text, label.range.start))
                }
            };
            add(spanned_error(first, last, &format!("note: {at}{} [{}]", label.message, d.code)));
        }
    }
    all
}

/// Warnings as uses of a deprecated item: a stable way to make rustc print a warning at
/// the offending tokens. `#![deny(warnings)]` turns them into errors, as it should.
pub fn warnings(target: &Target, diagnostics: &[Diagnostic]) -> TokenStream {
    diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Warning)
        .map(|d| {
            let (first, _) = spans(target, d.range.clone());
            let note = message(target, d);
            let used = quote_spanned!(first=> hstl_warning);
            quote! {
                const _: () = {
                    #[deprecated(note = #note)]
                    #[allow(non_upper_case_globals)]
                    const hstl_warning: () = ();
                    #used
                };
            }
        })
        .collect()
}

/// An error of the macro's own at the text `range` (`path:line:col: ` in front for files).
pub fn error_at(target: &Target, range: std::ops::Range<usize>, message: &str) -> syn::Error {
    let (first, last) = spans(target, range.clone());
    match target {
        Target::Tokens(_) => spanned_error(first, last, message),
        Target::File { path, text, .. } => {
            spanned_error(first, last, &format!("{}: {message}", location(path, text, range.start)))
        }
    }
}

fn spans(target: &Target, range: std::ops::Range<usize>) -> (Span, Span) {
    match target {
        Target::Tokens(src) => src.spans(range),
        Target::File { spans, .. } => *spans,
    }
}

/// `message [CODE]`, the help on its own line, and `path:line:col: ` in front for files.
fn message(target: &Target, d: &Diagnostic) -> String {
    let mut m = match target {
        Target::Tokens(_) => format!("{} [{}]", d.message, d.code),
        Target::File { path, text, .. } => {
            format!("{}: {} [{}]", location(path, text, d.range.start), d.message, d.code)
        }
    };
    if let Some(help) = &d.help {
        m.push_str("\n  = help: ");
        m.push_str(help);
    }
    m
}

fn location(path: &str, text: &str, offset: usize) -> String {
    let p = hstl_lang::LineIndex::new(text).position(text, offset);
    format!("{path}:{}:{}", p.line, p.column)
}
