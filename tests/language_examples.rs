//! Every spec in docs/LANGUAGE.md, README.md, examples/specs and examples/suite checks
//! without errors, as `hstlc check` would report them (warnings allowed, exit status 0):
//! against the world its doc comment names (`--world NAME|FILE.toml`, or the suite's
//! ``World: `NAME|FILE.toml` ``), or the default `paper`.

use std::path::Path;

use hstl::world::GridWorld;

/// The world a spec's text names with `--world`, as `hstlc` resolves it (paths are relative
/// to the package root).
fn world_of(src: &str) -> (GridWorld, String) {
    let named = src.split("--world").nth(1).or_else(|| src.split("World: ").nth(1));
    let Some(arg) = named.and_then(|rest| rest.split_whitespace().next()) else {
        return (GridWorld::default(), "world `paper`".into());
    };
    let arg = arg.trim_start_matches('`').trim_end_matches(['`', ')', '.', ',']);
    if let Some(world) = GridWorld::builtin(arg) {
        return (world, format!("world `{arg}`"));
    }
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(arg);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{arg}: {e}"));
    let world = GridWorld::from_toml(&text, "world").unwrap_or_else(|e| panic!("{arg}: {e}"));
    let label = format!("world `{}` ({arg})", world.world_name());
    (world, label)
}

fn assert_checks(name: &str, src: &str) {
    let (world, label) = world_of(src);
    let checked = hstl::world::check(src, &world, &label);
    assert!(
        !checked.has_errors(),
        "{name} has errors:\n{}",
        hstl::lang::render_plain(src, name, &checked.diagnostics)
    );
    assert!(!checked.specs.is_empty(), "{name} holds no spec");
}

/// The ```` ```hstl ```` blocks of a Markdown file under the package root.
fn hstl_blocks(doc: &str) -> Vec<String> {
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(doc))
        .unwrap_or_else(|e| panic!("{doc}: {e}"));
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in text.lines() {
        match (&mut current, line.trim_start()) {
            (None, l) if l.starts_with("```hstl") => current = Some(String::new()),
            (Some(_), l) if l.starts_with("```") => blocks.extend(current.take()),
            (Some(text), _) => {
                text.push_str(line);
                text.push('\n');
            }
            (None, _) => {}
        }
    }
    blocks
}

#[test]
fn every_spec_in_the_language_document_and_the_readme_checks() {
    for doc in ["docs/LANGUAGE.md", "README.md"] {
        // Blocks that are whole specs; the others are items shown on their own (the memory
        // variant's items are examples/specs/surveillance_memory.hstl, checked below).
        let blocks = hstl_blocks(doc);
        let specs: Vec<&String> = blocks.iter().filter(|b| b.contains("spec ")).collect();
        assert!(!specs.is_empty(), "{doc}: no spec blocks");
        for (i, block) in specs.iter().enumerate() {
            assert_checks(&format!("{doc} spec block {}", i + 1), block);
        }
    }
}

/// The suite's tasks check against their worlds with no diagnostic at all: in particular no
/// `HSTL170`, since the preset gives every option the task's avoided regions.
#[test]
fn every_suite_task_checks_cleanly_against_its_world() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/suite");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("examples/suite") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "hstl") {
            let src = std::fs::read_to_string(&path).expect("readable");
            let (world, label) = world_of(&src);
            assert!(src.contains("World: "), "{} names no world", path.display());
            let checked = hstl::world::check(&src, &world, &label);
            assert!(
                checked.diagnostics.is_empty(),
                "{}:\n{}",
                path.display(),
                hstl::lang::render_plain(&src, "suite", &checked.diagnostics)
            );
            assert!(checked.specs.iter().all(|s| s.preset_expansion.is_some()));
            // The world adds diagnostics only: the `hstl!` macro, which sees none, trains
            // the same learner.
            assert_eq!(checked.specs, hstl::lang::check(&src).specs, "{}", path.display());
            n += 1;
        }
    }
    assert!(n >= 8, "only {n} suite tasks");
}

#[test]
fn every_example_spec_checks() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/specs");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).expect("examples/specs") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "hstl") {
            let src = std::fs::read_to_string(&path).expect("readable");
            assert_checks(&path.display().to_string(), &src);
            n += 1;
        }
    }
    assert!(n >= 5, "only {n} example specs");
}
