//! The house's shape, checked over the source tree (ARCHITECTURE.md, "Invariants"): inside
//! a crate, files do not import each other in a circle, so that a lower phase never looks as
//! if it needed a higher one, and a file over 800 lines says at its top why it is one file
//! (or is listed as still to be split).
//!
//! A file's imports are the `crate::`, `super::` and `self::` paths of its code (`use`
//! items, braces expanded, and paths written inline), each taken to the deepest module file
//! it names. Paths through the crate root's re-exports are not followed. Test modules (from
//! a `#[cfg(test)]` at the start of a line, and files named `tests.rs`) are skipped, since
//! a test module reads its parent by design.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every crate's source folder.
const CRATES: [&str; 11] = [
    "hstl-lang/src",
    "hstl-macros/src",
    "robustness/src",
    "runtime/src",
    "pictures/src",
    "files/src",
    "outdir/src",
    "ide/src",
    "src",
    "hstlc/src",
    "python/src",
];

/// The circles that are still there, each with why. The test fails on a circle not listed
/// here and on a listed one that is gone, so the list stays the truth.
const KNOWN_CIRCLES: &[(&str, &[&str], &str)] = &[(
    "robustness/src",
    &["formula", "offline::plan"],
    "a `Formula` holds the offline evaluator's `Plan`, made once when the formula is built, \
         and the plan is made from its nodes",
)];

/// The most lines a source file has (its code before a test module) without saying at its
/// top why it is one file.
const LONG_FILE: usize = 800;

/// The files over [`LONG_FILE`] lines that are still to be split (issue 29), by path from
/// the workspace root. The test fails on a long file neither listed here nor giving its
/// reason (a `//!` line starting `One file:` in its first 40 lines), and on a listed one
/// that is no longer long.
const LONG_FILES_TO_SPLIT: &[&str] = &[];

/// A module's path inside its crate (`["plan_reach", "choices"]`; the root is empty).
type Module = Vec<String>;

#[test]
fn no_circle_of_files_inside_a_crate() {
    let mut found = BTreeSet::new();
    for src in CRATES {
        for circle in circles(src) {
            let names: Vec<String> = circle.iter().map(display).collect();
            found.insert((src.to_string(), names));
        }
    }
    let known: BTreeSet<(String, Vec<String>)> = KNOWN_CIRCLES
        .iter()
        .map(|(src, mods, _)| {
            let mut mods: Vec<String> = mods.iter().map(|m| m.to_string()).collect();
            mods.sort();
            (src.to_string(), mods)
        })
        .collect();
    let new: Vec<_> = found.difference(&known).collect();
    let gone: Vec<_> = known.difference(&found).collect();
    assert!(
        new.is_empty(),
        "files that import each other in a circle (move what they share to a module of its \
         own that both import):\n{}",
        new.iter()
            .map(|(src, m)| format!("  {src}: {}", m.join(", ")))
            .collect::<Vec<_>>()
            .join("\n")
    );
    assert!(
        gone.is_empty(),
        "circles in KNOWN_CIRCLES that are gone (remove them from the list):\n{}",
        gone.iter()
            .map(|(src, m)| format!("  {src}: {}", m.join(", ")))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

#[test]
fn a_long_file_says_why_it_is_one_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (mut unexplained, mut not_long) = (Vec::new(), Vec::new());
    let listed: BTreeSet<&str> = LONG_FILES_TO_SPLIT.iter().copied().collect();
    let mut seen: BTreeSet<String> = BTreeSet::new();
    for src in CRATES {
        for path in module_files(&root.join(src)).into_values() {
            let text = std::fs::read_to_string(&path).expect("a readable source file");
            let lines = text.lines().take_while(|l| !l.starts_with("#[cfg(test)]")).count();
            let rel =
                path.strip_prefix(root).expect("under the root").to_string_lossy().to_string();
            seen.insert(rel.clone());
            let says_why =
                text.lines().take(40).any(|l| l.trim_start().starts_with("//! One file:"));
            if lines > LONG_FILE && !says_why && !listed.contains(rel.as_str()) {
                unexplained.push(format!("  {rel}: {lines} lines"));
            }
            if lines <= LONG_FILE && listed.contains(rel.as_str()) {
                not_long.push(format!("  {rel}: {lines} lines"));
            }
        }
    }
    not_long.extend(
        listed.iter().filter(|f| !seen.contains(**f)).map(|f| format!("  {f}: no such file")),
    );
    assert!(
        unexplained.is_empty(),
        "files over {LONG_FILE} lines that do not say why they are one file (split them along \
         their seams, or give the reason in a `//! One file:` line at the top):\n{}",
        unexplained.join("\n")
    );
    assert!(
        not_long.is_empty(),
        "files in LONG_FILES_TO_SPLIT that are no longer long (remove them from the list):\n{}",
        not_long.join("\n")
    );
}

#[test]
fn the_circle_finder_sees_use_items_braces_and_inline_paths() {
    let code = "use crate::{a::X, b::{c::Y, Z}};\nuse super::d;\nfn f() { crate::e::g(); }\n";
    let mut paths = imports(code);
    paths.sort();
    let want: Vec<Vec<&str>> = vec![
        vec!["crate", "a", "X"],
        vec!["crate", "b", "Z"],
        vec!["crate", "b", "c", "Y"],
        vec!["crate", "e", "g"],
        vec!["super", "d"],
    ];
    assert_eq!(paths, want);
}

/// The circles among `src`'s files, each sorted, as module paths.
fn circles(src: &str) -> Vec<Vec<Module>> {
    let files = module_files(&Path::new(env!("CARGO_MANIFEST_DIR")).join(src));
    let mut edges: BTreeMap<Module, BTreeSet<Module>> = BTreeMap::new();
    for (module, path) in &files {
        let text = std::fs::read_to_string(path).expect("a readable source file");
        let to = edges.entry(module.clone()).or_default();
        for import in imports(&code_of(&text)) {
            if let Some(target) = resolve(module, &import, &files)
                && &target != module
                && !target.is_empty()
            {
                to.insert(target);
            }
        }
    }
    // The strongly connected components, by reachability: the graphs are small.
    let reach = |from: &Module| -> BTreeSet<Module> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.clone()];
        while let Some(m) = stack.pop() {
            for next in edges.get(&m).into_iter().flatten() {
                if seen.insert(next.clone()) {
                    stack.push(next.clone());
                }
            }
        }
        seen
    };
    let reached: BTreeMap<&Module, BTreeSet<Module>> =
        files.keys().map(|m| (m, reach(m))).collect();
    let mut out: BTreeSet<Vec<Module>> = BTreeSet::new();
    for (m, from_m) in &reached {
        if !from_m.contains(*m) {
            continue;
        }
        let circle: Vec<Module> =
            from_m.iter().filter(|other| reached[other].contains(*m)).cloned().collect();
        out.insert(circle);
    }
    out.into_iter().collect()
}

/// The module files under `src`, by module path.
fn module_files(src: &Path) -> BTreeMap<Module, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("a readable source folder").flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") && !p.ends_with("tests.rs") {
                let rel = p.strip_prefix(src).expect("under src").with_extension("");
                let mut module: Module =
                    rel.iter().map(|part| part.to_string_lossy().into_owned()).collect();
                if matches!(module.last().map(String::as_str), Some("mod" | "lib" | "main")) {
                    module.pop();
                }
                out.insert(module, p);
            }
        }
    }
    assert!(!out.is_empty(), "no source under {}", src.display());
    out
}

/// `text` without comments, cut at a test module.
fn code_of(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with("#[cfg(test)]") {
            break;
        }
        let line = line.split("//").next().unwrap_or("");
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The `crate::`, `super::` and `self::` paths of `code`, braces of `use` items expanded.
fn imports(code: &str) -> Vec<Vec<&str>> {
    let mut out = Vec::new();
    // `use` items first; the code between them is searched for paths written inline.
    let mut between = Vec::new();
    let mut rest = code;
    while let Some(at) = find_word(rest, "use") {
        between.push(&rest[..at]);
        let after = &rest[at + 3..];
        let end = after.find(';').unwrap_or(after.len());
        let tree = after[..end].trim();
        if ["crate::", "super::", "self::"].iter().any(|p| tree.starts_with(p)) {
            expand(Vec::new(), tree, &mut out);
        }
        rest = &after[end..];
    }
    between.push(rest);
    for part in between {
        for start in ["crate::", "super::"] {
            let mut from = 0;
            while let Some(i) = part[from..].find(start) {
                let at = from + i;
                from = at + start.len();
                let before = part[..at].chars().next_back();
                if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                    continue;
                }
                let path = part[at..]
                    .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                    .next()
                    .unwrap_or("")
                    .split("::")
                    .filter(|s| !s.is_empty())
                    .collect();
                out.push(path);
            }
        }
    }
    out
}

/// Where `word` starts in `text` as a whole word.
fn find_word(text: &str, word: &str) -> Option<usize> {
    let mut from = 0;
    while let Some(i) = text[from..].find(word) {
        let at = from + i;
        let before = text[..at].chars().next_back();
        let after = text[at + word.len()..].chars().next();
        if !before.is_some_and(|c| c.is_alphanumeric() || c == '_')
            && after.is_some_and(char::is_whitespace)
        {
            return Some(at);
        }
        from = at + word.len();
    }
    None
}

/// The paths of one use tree (`a::{b, c::{d}}`) appended to `prefix`.
fn expand<'a>(prefix: Vec<&'a str>, tree: &'a str, out: &mut Vec<Vec<&'a str>>) {
    let tree = tree.trim();
    let Some(open) = tree.find('{') else {
        let name = tree.split(" as ").next().unwrap_or("").trim();
        let mut path = prefix;
        path.extend(name.split("::").map(str::trim).filter(|s| !s.is_empty()));
        if !path.is_empty() {
            out.push(path);
        }
        return;
    };
    let mut path = prefix;
    path.extend(tree[..open].split("::").map(str::trim).filter(|s| !s.is_empty()));
    let inner = &tree[open + 1..tree.rfind('}').unwrap_or(tree.len())];
    let (mut depth, mut start) = (0, 0);
    for (i, c) in inner.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                expand(path.clone(), &inner[start..i], out);
                start = i + 1;
            }
            _ => {}
        }
    }
    expand(path, &inner[start..], out);
}

/// The module file an import names, from `module`: its deepest prefix that is a file.
fn resolve(module: &Module, import: &[&str], files: &BTreeMap<Module, PathBuf>) -> Option<Module> {
    let (mut base, mut rest): (Module, &[&str]) = match import.first() {
        Some(&"crate") => (Vec::new(), &import[1..]),
        Some(&"super" | &"self") => (module.clone(), import),
        _ => return None,
    };
    while let Some(first) = rest.first() {
        match *first {
            "super" => {
                base.pop();
            }
            "self" => {}
            _ => break,
        }
        rest = &rest[1..];
    }
    base.extend(rest.iter().map(|s| s.to_string()));
    (0..=base.len()).rev().map(|k| base[..k].to_vec()).find(|m| files.contains_key(m))
}

fn display(module: &Module) -> String {
    if module.is_empty() { "the crate root".to_string() } else { module.join("::") }
}
