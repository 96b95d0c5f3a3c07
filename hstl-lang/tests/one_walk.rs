//! One walk: the operands of each formula node kind are listed in one place per tree
//! ([`hstl_lang::checked::CFormula::operands`] and [`hstl_lang::syntax::Formula::operands`]),
//! and every walk that does the same thing for each operand goes through them.
//!
//! What this checks: it reads every Rust source of the workspace, splits it into functions
//! (a function runs from its `fn` line to the next `fn` line of the file), and lists the
//! functions that name every variant of `CFormulaKind`, or every variant of the syntax
//! tree's `FormulaKind`. Such a function either computes something per kind (lowering, an
//! evaluator, a printer, the code generator) and is named below with its reason, or it is a
//! walk that lists node kinds by hand and should call `operands()`; the test fails on it.
//! A function named below that no longer names every variant fails the test too, so the
//! list stays the list of what is there. The variants are read from the enums themselves.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The functions that may name every variant, as (file, function, why).
const PER_KIND: &[(&str, &str, &str)] = &[
    ("hstl-lang/src/checked.rs", "operands", "the operands of the checked tree, listed once"),
    ("hstl-lang/src/syntax.rs", "operands", "the operands of the syntax tree, listed once"),
    ("hstl-lang/src/syntax.rs", "operands_mut", "the same, mutable"),
    ("hstl-lang/src/check/resolve.rs", "formula", "lowering: each kind to its checked node"),
    ("hstl-lang/src/checked.rs", "eval_formula", "an evaluator: each kind's robustness"),
    ("src/lower.rs", "lower", "lowering: each checked kind to its runtime formula"),
    ("hstl-macros/src/expand/codegen/body.rs", "operator", "generated code per kind"),
    ("hstl-macros/src/expand/codegen/body.rs", "point", "generated code per kind"),
    ("hstl-macros/src/expand/codegen/data.rs", "formula_data", "generated data per kind"),
    ("hstl-macros/src/expand/codegen/monitor.rs", "empty_value", "each kind's value on no steps"),
    ("hstl-macros/src/expand/codegen/monitor.rs", "horizon", "each kind's horizon"),
    ("ide/src/hover.rs", "operator_of", "hover: each operator's own words"),
    ("hstl-lang/tests/syntax.rs", "shape", "a test printer: each kind's own text"),
    ("hstl-macros/tests/macro_differential.rs", "lower", "a test lowering to runtime formulas"),
];

/// The variant names of `pub enum <name>` in `src`.
fn variants(src: &str, name: &str) -> BTreeSet<String> {
    let start = src.find(&format!("pub enum {name} {{")).expect("the enum is declared");
    let body = &src[start..];
    let body = &body[..body.find("\n}").expect("the enum ends")];
    body.lines()
        .skip(1)
        .filter_map(|l| l.strip_prefix("    "))
        .filter(|l| l.starts_with(|c: char| c.is_ascii_uppercase()))
        .map(|l| l.chars().take_while(|c| c.is_alphanumeric()).collect())
        .collect()
}

/// The name of the function a line declares, if it does.
fn fn_name(line: &str) -> Option<&str> {
    let mut rest = line.trim_start();
    for prefix in ["pub(crate) ", "pub(super) ", "pub ", "const ", "unsafe "] {
        rest = rest.strip_prefix(prefix).unwrap_or(rest);
    }
    let rest = rest.strip_prefix("fn ")?;
    let end = rest.find(|c: char| !(c.is_alphanumeric() || c == '_'))?;
    Some(&rest[..end])
}

/// The variants each function of `src` names, for the checked tree and the syntax tree.
fn functions(src: &str) -> Vec<(String, BTreeSet<String>, BTreeSet<String>)> {
    let mut out: Vec<(String, BTreeSet<String>, BTreeSet<String>)> = Vec::new();
    for line in src.lines() {
        if let Some(name) = fn_name(line) {
            out.push((name.to_string(), BTreeSet::new(), BTreeSet::new()));
        }
        let Some((_, checked, syntax)) = out.last_mut() else { continue };
        for (at, _) in line.match_indices("FormulaKind::") {
            let variant: String = line[at + "FormulaKind::".len()..]
                .chars()
                .take_while(|c| c.is_alphanumeric())
                .collect();
            if line[..at].ends_with('C') {
                checked.insert(variant);
            } else {
                syntax.insert(variant);
            }
        }
    }
    out
}

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.starts_with('.') || name == "target" {
            continue;
        }
        if path.is_dir() {
            sources(&path, out);
        } else if name.ends_with(".rs") {
            out.push(path);
        }
    }
}

#[test]
fn walks_over_formulas_go_through_operands() {
    let lang = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = lang.parent().expect("hstl-lang sits in the workspace");
    let read = |p: &str| std::fs::read_to_string(lang.join(p)).expect("a source of hstl-lang");
    let checked_kinds = variants(&read("src/checked.rs"), "CFormulaKind");
    let syntax_kinds = variants(&read("src/syntax.rs"), "FormulaKind");
    assert!(checked_kinds.len() >= 16 && syntax_kinds.len() >= 17, "the enums were read");

    let mut files = Vec::new();
    sources(root, &mut files);
    files.sort();
    let mut found = BTreeSet::new();
    for path in &files {
        let src = std::fs::read_to_string(path).expect("a readable source");
        let rel =
            path.strip_prefix(root).expect("under the root").to_string_lossy().replace('\\', "/");
        for (name, checked, syntax) in functions(&src) {
            if checked.is_superset(&checked_kinds) || syntax.is_superset(&syntax_kinds) {
                found.insert((rel.clone(), name));
            }
        }
    }
    let allowed: BTreeSet<(String, String)> =
        PER_KIND.iter().map(|(f, n, _)| (f.to_string(), n.to_string())).collect();
    let by_hand: Vec<_> = found.difference(&allowed).collect();
    assert!(
        by_hand.is_empty(),
        "these functions name every formula node kind: walk with `operands()`, or, if the \
         function computes something per kind, add it to PER_KIND with its reason: {by_hand:?}"
    );
    let gone: Vec<_> = allowed.difference(&found).collect();
    assert!(gone.is_empty(), "PER_KIND names functions that no longer name every kind: {gone:?}");
}
