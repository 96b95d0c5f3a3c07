//! The invariants ARCHITECTURE.md states as absences, checked over the source tree: what a
//! machine can check by reading the code. Comment lines are skipped, and so is the rest of
//! a file from a `#[cfg(test)]` at the start of a line (test modules close the files), and
//! files named `tests.rs` (test modules of their own).

use std::path::{Path, PathBuf};

/// The library crates: they compute and return, and never print or read the clock.
const LIBRARIES: [&str; 8] = [
    "hstl-lang/src",
    "robustness/src",
    "runtime/src",
    "src",
    "pictures/src",
    "files/src",
    "outdir/src",
    "ide/src",
];

/// The lines of every `.rs` file under `dir` (relative to the workspace root) that are code,
/// as `(file, line number, text)`.
fn code_lines(dir: &str) -> Vec<(PathBuf, usize, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut stack = vec![root.join(dir)];
    let mut out = Vec::new();
    while let Some(path) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&path) else { continue };
        for entry in entries.flatten() {
            let p = entry.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "rs") && !p.ends_with("tests.rs") {
                let text = std::fs::read_to_string(&p).expect("a readable source file");
                for (i, line) in text.lines().enumerate() {
                    if line.starts_with("#[cfg(test)]") {
                        break;
                    }
                    if !line.trim_start().starts_with("//") {
                        out.push((p.clone(), i + 1, line.to_string()));
                    }
                }
            }
        }
    }
    assert!(!out.is_empty(), "no source under {dir}");
    out
}

/// Every code line under `dirs` that contains one of `words`.
fn offenders(dirs: &[&str], words: &[&str]) -> Vec<String> {
    let mut found = Vec::new();
    for dir in dirs {
        for (file, n, line) in code_lines(dir) {
            if let Some(w) = words.iter().find(|w| line.contains(*w)) {
                found.push(format!("{}:{n}: `{w}` in {}", file.display(), line.trim()));
            }
        }
    }
    found
}

#[test]
fn library_crates_never_print() {
    let words =
        ["println!", "eprintln!", "print!(", "eprint!(", "io::stdout", "io::stderr", "dbg!("];
    let found = offenders(&LIBRARIES, &words);
    assert!(found.is_empty(), "only the shells write to the terminal:\n{}", found.join("\n"));
}

#[test]
fn library_crates_read_no_clock_and_no_unseeded_randomness() {
    let words = [
        "Instant::now",
        "SystemTime::now",
        "thread_rng",
        "rand::rng()",
        "OsRng",
        "from_os_rng",
        "from_entropy",
    ];
    let found = offenders(&LIBRARIES, &words);
    assert!(
        found.is_empty(),
        "every draw comes from the seeded generator passed in:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_approximate_learner_names_no_state_index_table_or_grid() {
    let words =
        ["Tables", "GridWorld", "num_states", ": Env", "E: Env", "impl Env", ".index(", "Memory"];
    let found = offenders(&["runtime/src/approx"], &words);
    assert!(
        found.is_empty(),
        "the approximate learner sees states through World::valuation:\n{}",
        found.join("\n")
    );
}

#[test]
fn nothing_above_the_runtime_makes_a_grid_of_its_own() {
    let words = ["GridWorld::new", "GridWorld::default", "GridWorld::paper", "GridWorld::open"];
    let found = offenders(&["hstlc/src", "python/src"], &words);
    assert!(
        found.is_empty(),
        "the shells take every world from --world, the world item or policy.json:\n{}",
        found.join("\n")
    );
}

/// Issue 30: messages once showed Rust's `Debug` form of lists and values (`["a", "b"]`,
/// `Circle { cx: 1.0, .. }`); they are worded (`a, b and c`, names in backticks, numbers
/// as `policy.json` writes them). No `{:?}` outside asserts and panics, in the library
/// crates and the shells alike; a line that formats a value only to compare it says so
/// with `// not a message`.
#[test]
fn messages_never_show_rust_debug_formatting() {
    let mut dirs = LIBRARIES.to_vec();
    dirs.extend(["hstlc/src", "python/src", "hstl-macros/src"]);
    let found: Vec<String> = offenders(&dirs, &[":?}"])
        .into_iter()
        .filter(|l| {
            !["assert", "panic!", "unreachable!", "// not a message"].iter().any(|w| l.contains(w))
        })
        .collect();
    assert!(found.is_empty(), "word what a message shows:\n{}", found.join("\n"));
}

/// The crates a crate's `Cargo.toml` links (its `[dependencies]` and target-specific
/// dependencies; not its dev-dependencies).
fn dependencies(krate: &str) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join(krate).join("Cargo.toml")).expect("Cargo.toml");
    let mut linked = false;
    let mut out = Vec::new();
    for line in text.lines().map(str::trim) {
        if line.starts_with('[') {
            linked = line.ends_with("dependencies]") && !line.contains("dev-dependencies");
        } else if linked && let Some((name, _)) = line.split_once('=') {
            out.push(name.trim().to_string());
        }
    }
    out
}

/// The shells' file library knows nothing of the learner (std and libc only), the output
/// folders only it, and the editor features nothing of the protocol.
#[test]
fn the_shell_libraries_link_what_they_say() {
    assert_eq!(dependencies("files"), ["libc"], "hstl-files: std and libc only");
    assert_eq!(dependencies("outdir"), ["hstl-files"], "hstl-outdir: only hstl-files");
    let ide = dependencies("ide");
    let protocol: Vec<&String> = ide
        .iter()
        .filter(|d| d.starts_with("lsp") || d.contains("json") || d.contains("jsonrpc"))
        .collect();
    assert!(protocol.is_empty(), "hstl-ide knows nothing of LSP: {protocol:?}");
    let found = offenders(&["ide/src"], &["lsp_types", "lsp_server", "serde_json", "Uri"]);
    assert!(found.is_empty(), "hstl-ide knows nothing of LSP:\n{}", found.join("\n"));
}
