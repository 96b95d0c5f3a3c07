//! The macro's work as plain functions over `proc_macro2` tokens, so it runs (and is
//! tested and benchmarked) outside the compiler.

pub mod codegen;
pub mod report;
pub mod source;

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use hstl_lang::{Checked, Diagnostic, Severity};
use proc_macro2::{Span, TokenStream, TokenTree};
use quote::quote;

use report::Target;
use source::Source;

/// Expands the body of `hstl! { ... }`: either hstl items, or `include "path"` naming a
/// file relative to `CARGO_MANIFEST_DIR`. The facade's `hstl::hstl!` prefixes the body
/// with `$crate ;`, and generated code then names the facade by `$crate`, which works
/// under any name the user gave the dependency; without the prefix it names `::hstl`.
pub fn expand(input: TokenStream) -> TokenStream {
    let (root, input) = split_root(input);
    match include_path(&input) {
        Some(Ok((path, spans))) => expand_file_with(&path, spans, &root),
        Some(Err(e)) => e.to_compile_error(),
        None => expand_tokens_with(input, &root),
    }
}

/// The facade's path, when the input starts with `$crate ;`, and the rest of the input.
fn split_root(input: TokenStream) -> (TokenStream, TokenStream) {
    let mut tokens = input.clone().into_iter();
    if let (Some(TokenTree::Ident(root)), Some(TokenTree::Punct(semi))) =
        (tokens.next(), tokens.next())
        && root == "$crate"
        && semi.as_char() == ';'
    {
        return (TokenTree::Ident(root).into(), tokens.collect());
    }
    (quote!(::hstl), input)
}

/// Expands hstl items given as tokens; generated code names the facade by `root`.
fn expand_tokens_with(input: TokenStream, root: &TokenStream) -> TokenStream {
    let source = Source::from_tokens(input);
    let checked = hstl_lang::check(&source.text);
    emit(&Target::Tokens(&source), &source.text, &checked, TokenStream::new(), root)
}

/// Expands the hstl file at `path` (relative to `CARGO_MANIFEST_DIR`), reporting at
/// `spans` (the `include "..."` tokens).
fn expand_file_with(path: &str, spans: (Span, Span), root: &TokenStream) -> TokenStream {
    let full = resolve(path);
    let text = match read_spec(&full) {
        Ok(t) => t,
        Err(msg) => return report::spanned_error(spans.0, spans.1, &msg).to_compile_error(),
    };
    let checked = hstl_lang::check(&text);
    // Ties the crate to the file, so cargo rebuilds when it changes.
    let abs = full.to_string_lossy().into_owned();
    let track = quote!(
        const _: &str = ::core::include_str!(#abs);
    );
    emit(&Target::File { path, text: &text, spans }, &text, &checked, track, root)
}

/// The text of the spec file at `path`, read within [`hstl_lang::MAX_SOURCE_BYTES`] through
/// `hstl-files` as `hstlc` reads a spec (a larger file, or an endless one such as
/// `/dev/zero`, is refused after one byte more), or the error to report.
fn read_spec(path: &Path) -> Result<String, String> {
    hstl_files::read::read_file(path, hstl_lang::MAX_SOURCE_BYTES).map(|t| t.text).map_err(|e| {
        match e.problem(&hstl_files::words::path_words(path), "spec", "hstl!") {
            Ok(refused) => refused.message,
            Err(e) => hstl_files::words::read_error(path, &e),
        }
    })
}

fn emit(
    target: &Target,
    text: &str,
    checked: &Checked,
    mut out: TokenStream,
    root: &TokenStream,
) -> TokenStream {
    let mut seen = HashSet::new();
    let mut dense: Option<syn::Error> = None;
    for spec in &checked.specs {
        if !seen.insert(codegen::module_name(spec)) {
            continue;
        }
        if let Some(t) = &spec.time {
            // The generated monitors count steps; a dense spec's meaning is in time.
            let e = report::error_at(
                target,
                spec.name_range.clone(),
                &format!(
                    "`{}` is a dense-time spec (`{}: time`): `hstl!` generates discrete-time \
                     monitors only\n  = help: monitor it at run time with \
                     `hstl::monitor::Dense` (or `hstlc monitor`), or declare the time \
                     variable's column as a `float` to count steps",
                    spec.name, t.name
                ),
            );
            match &mut dense {
                Some(d) => d.combine(e),
                None => dense = Some(e),
            }
            continue;
        }
        let complete = !checked
            .diagnostics
            .iter()
            .any(|d| d.severity == Severity::Error && overlaps(d, &spec.range));
        out.extend(codegen::spec_module(spec, text, complete, root));
    }
    if let Some(e) = dense {
        out.extend(e.to_compile_error());
    }
    out.extend(report::warnings(target, &checked.diagnostics));
    if let Some(e) = report::errors(target, &checked.diagnostics) {
        // `compile_error! { ... }` with braces: valid in item position without a `;`.
        out.extend(e.to_compile_error());
    }
    out
}

fn overlaps(d: &Diagnostic, range: &std::ops::Range<usize>) -> bool {
    d.range.start < range.end && range.start <= d.range.end
}

/// `include "path"` (with an optional `;`): the path and the spans to report at.
fn include_path(input: &TokenStream) -> Option<syn::Result<(String, (Span, Span))>> {
    let tts: Vec<TokenTree> = input.clone().into_iter().collect();
    let (kw, rest) = tts.split_first()?;
    let TokenTree::Ident(kw) = kw else { return None };
    if kw != "include" {
        return None;
    }
    let first = kw.span();
    let err =
        |span: Span| report::spanned_error(first, span, "expected `include \"path/to/spec.hstl\"`");
    let lit = match rest {
        [TokenTree::Literal(l)] => l,
        [TokenTree::Literal(l), TokenTree::Punct(p)] if p.as_char() == ';' => l,
        _ => return Some(Err(err(rest.last().map_or(first, TokenTree::span)))),
    };
    match syn::parse2::<syn::LitStr>(TokenTree::Literal(lit.clone()).into()) {
        Ok(s) => Some(Ok((s.value(), (first, lit.span())))),
        Err(_) => Some(Err(err(lit.span()))),
    }
}

fn resolve(path: &str) -> PathBuf {
    let p = Path::new(path);
    if p.is_absolute() {
        return p.to_path_buf();
    }
    match std::env::var_os("CARGO_MANIFEST_DIR") {
        Some(dir) => Path::new(&dir).join(p),
        None => p.to_path_buf(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proc_macro2::Delimiter;

    /// Generated code laid out one statement or item per line, for readable snapshots.
    fn pretty(tokens: TokenStream) -> String {
        fn walk(tokens: TokenStream, depth: usize, out: &mut String) {
            let pad = |out: &mut String, depth: usize| {
                if out.ends_with('\n') {
                    out.push_str(&"    ".repeat(depth));
                }
            };
            for tt in tokens {
                pad(out, depth);
                match tt {
                    TokenTree::Group(g) if g.delimiter() == Delimiter::Brace => {
                        out.push_str("{\n");
                        walk(g.stream(), depth + 1, out);
                        if !out.ends_with('\n') {
                            out.push('\n');
                        }
                        out.push_str(&"    ".repeat(depth));
                        out.push_str("}\n");
                    }
                    // A call taking a closure with a block body: the block laid out too.
                    TokenTree::Group(g)
                        if g.delimiter() == Delimiter::Parenthesis
                            && closure_block(&g.stream()) =>
                    {
                        out.push('(');
                        walk(g.stream(), depth, out);
                        if out.ends_with("}\n") {
                            out.pop();
                        }
                        out.push_str(") ");
                    }
                    TokenTree::Punct(p) if p.as_char() == ';' => out.push_str(";\n"),
                    TokenTree::Punct(p)
                        if p.as_char() == ',' && depth > 0 && out.ends_with("}\n") =>
                    {
                        out.pop();
                        out.push_str(",\n");
                    }
                    TokenTree::Punct(p) if p.spacing() == proc_macro2::Spacing::Joint => {
                        out.push(p.as_char())
                    }
                    other => {
                        out.push_str(&other.to_string());
                        out.push(' ');
                    }
                }
            }
        }
        // Whether the tokens hold a closure with a block body (`|..| { .. }`).
        fn closure_block(tokens: &TokenStream) -> bool {
            let tts: Vec<TokenTree> = tokens.clone().into_iter().collect();
            tts.windows(2).any(|w| {
                matches!(&w[0], TokenTree::Punct(p) if p.as_char() == '|')
                    && matches!(&w[1], TokenTree::Group(b) if b.delimiter() == Delimiter::Brace)
            })
        }
        let mut out = String::new();
        walk(tokens, 0, &mut out);
        out.lines().map(str::trim_end).collect::<Vec<_>>().join("\n")
    }

    /// The deepest group nesting and the number of token trees of `tokens`, by an explicit
    /// stack.
    fn shape(tokens: TokenStream) -> (usize, usize) {
        let (mut deepest, mut count) = (0, 0);
        let mut stack = vec![(tokens.into_iter(), 0usize)];
        while let Some((mut iter, depth)) = stack.pop() {
            if let Some(tt) = iter.next() {
                count += 1;
                stack.push((iter, depth));
                if let TokenTree::Group(g) = tt {
                    deepest = deepest.max(depth + 1);
                    stack.push((g.stream().into_iter(), depth + 1));
                }
            }
        }
        (deepest, count)
    }

    /// Issue 11, classes 1 and 2: the code for a chain of lets names each let once and is
    /// never nested deeper than one let's body, so rustc sees neither a tree as large as
    /// the lets written out nor an expression as deep as the chain.
    #[test]
    fn chains_of_lets_give_linear_flat_code() {
        let expand_lets = |lets: &str, top: &str| {
            let src = format!(
                "spec S {{ state {{ x: int in 0..=14 }} {lets} task always[0..=5] {top}; }}"
            );
            shape(expand(src.parse().expect("lexes")))
        };
        let doubling = |n: usize| {
            let mut lets = String::from("let L0 = x > 3;");
            for k in 1..n {
                lets.push_str(&format!("let L{k} = L{} && L{};", k - 1, k - 1));
            }
            expand_lets(&lets, &format!("L{}", n - 1))
        };
        let (depth12, size12) = doubling(12);
        let (depth24, size24) = doubling(24);
        // Twice the lets, about twice the code (a tree would be 4096 times larger).
        assert!(size24 < 3 * size12, "{size12} then {size24} token trees");
        assert_eq!(depth12, depth24);
        // 255 lets of 250 nested `always` each: as deep as 12 lets of 1, bar one let's body.
        let mut lets = String::from("let T0 = x > 3;");
        for k in 1..255 {
            lets.push_str(&format!("let T{k} = {}T{};", "always[0..=1] ".repeat(250), k - 1));
        }
        let (depth, size) = expand_lets(&lets, "T254");
        assert!(depth <= depth12 + 4, "nested {depth} deep");
        assert!(size < 300 * 255 * 250, "{size} token trees");
    }

    #[test]
    fn case_study_expansion() {
        let text = include_str!("../../specs/case_study.hstl");
        let tokens: TokenStream = text.parse().expect("the case study lexes as Rust tokens");
        insta::assert_snapshot!(pretty(expand(tokens)));
    }

    #[test]
    fn errors_and_best_effort_code_come_together() {
        let tokens: TokenStream =
            "spec S { state { x: float } let A = x > 1; let B = x < ; task A; }"
                .parse()
                .expect("lexes");
        let out = expand(tokens).to_string();
        // One error, and the parts that checked are still generated.
        assert_eq!(out.matches("compile_error").count(), 1, "{out}");
        assert!(out.contains("pub mod s"), "{out}");
        assert!(out.contains("pub struct State"), "{out}");
        assert!(out.contains("pub mod a"), "{out}");
        assert!(!out.contains("impl :: hstl :: runtime :: Spec"), "{out}");
    }

    #[test]
    fn a_dense_spec_is_one_clear_error_and_no_module() {
        let tokens: TokenStream =
            "spec Log { state { t: time, x: float } task eventually[0..=2.5] x > 1; } \
             spec Steps { state { x: float } task eventually[0..3] x > 1; }"
                .parse()
                .expect("lexes");
        let out = expand(tokens).to_string();
        assert_eq!(out.matches("compile_error").count(), 1, "{out}");
        assert!(out.contains("is a dense-time spec"), "{out}");
        assert!(out.contains("hstl::monitor::Dense"), "{out}");
        assert!(!out.contains("pub mod log"), "{out}");
        // The other spec of the input is generated as usual.
        assert!(out.contains("pub mod steps"), "{out}");
    }

    #[test]
    fn every_runtime_path_goes_through_the_root() {
        // `hstl::hstl!` passes `$crate` as the root (which proc_macro2 cannot build outside
        // the compiler); any other path shows the same substitution.
        let input: TokenStream = "spec S { state { x: int in 0..=3 } let A = x > 1; \
             task always[0..] eventually[0..4] A; option A; }"
            .parse()
            .expect("lexes");
        let out = expand_tokens_with(input.clone(), &quote!(::renamed)).to_string();
        assert!(!out.contains(":: hstl ::"), "{out}");
        assert!(out.contains(":: renamed :: runtime :: Spec"), "{out}");
        assert!(out.contains(":: renamed :: robustness :: Formula"), "{out}");
        assert!(out.contains(":: renamed :: robustness :: kernels"), "{out}");
        // Called directly, without the facade's prefix, it names `::hstl`.
        assert!(expand(input).to_string().contains(":: hstl :: runtime :: Spec"));
    }

    #[test]
    fn include_forms() {
        let ok: TokenStream = "include \"specs/case_study.hstl\";".parse().expect("lexes");
        assert!(matches!(include_path(&ok), Some(Ok((p, _))) if p == "specs/case_study.hstl"));
        for bad in ["include", "include x", "include \"a\" \"b\""] {
            let tokens: TokenStream = bad.parse().expect("lexes");
            assert!(matches!(include_path(&tokens), Some(Err(_))), "{bad}");
        }
        let items: TokenStream = "spec include {}".parse().expect("lexes");
        assert!(include_path(&items).is_none());
        let missing = expand_file_with(
            "no/such/file.hstl",
            (Span::call_site(), Span::call_site()),
            &quote!(::hstl),
        );
        assert!(missing.to_string().contains("cannot read"), "{missing}");
    }

    #[test]
    fn included_file_errors_name_path_line_and_column() {
        let path = std::env::temp_dir().join(format!("hstl-macros-{}.hstl", std::process::id()));
        std::fs::write(&path, "spec S {\n    state { x: float }\n    task always Goal;\n}\n")
            .expect("temp file");
        let shown = path.display().to_string();
        let out = expand_file_with(&shown, (Span::call_site(), Span::call_site()), &quote!(::hstl))
            .to_string();
        std::fs::remove_file(&path).ok();
        assert!(out.contains(&format!("{shown}:3:17: unknown name `Goal` [HSTL002]")), "{out}");
        assert!(out.contains("include_str"), "{out}");
    }

    #[test]
    fn warnings_become_deprecated_uses() {
        let tokens: TokenStream =
            "spec S { state { x: float } let A = x > 1; let Spare = x < 0; task A; }"
                .parse()
                .expect("lexes");
        let out = expand(tokens).to_string();
        assert!(!out.contains("compile_error"), "{out}");
        assert_eq!(out.matches("deprecated").count(), 1, "{out}");
        assert!(out.contains("unused `let` `Spare`"), "{out}");
    }

    #[test]
    fn an_endless_include_is_refused_at_the_limit() {
        if !Path::new("/dev/zero").exists() {
            return;
        }
        let out =
            expand_file_with("/dev/zero", (Span::call_site(), Span::call_site()), &quote!(::hstl))
                .to_string();
        assert!(out.contains("`/dev/zero` is larger than 64 MiB, the limit for a spec"), "{out}");
        assert!(!out.contains("include_str"), "{out}");
    }
}
