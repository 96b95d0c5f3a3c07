//! Every spec in docs/LANGUAGE.md, README.md, examples/specs and examples/suite checks
//! without errors, as `hstlc check` would report them (warnings allowed, exit status 0):
//! each spec against the world it names (`world "...";`, a path relative to its file), or
//! alone when it names none.

use std::collections::HashMap;
use std::path::Path;

use hstl::lang::{Checked, SpecWorld};
use hstl::world::{AnyWorld, Facts};

/// Checks `src` as `hstlc check` does: every `world` item read relative to `base`. A world
/// that cannot be read fails the test.
fn check(name: &str, src: &str, base: &Path) -> Checked {
    let parsed = hstl::lang::parse(src);
    let mut worlds: HashMap<String, Facts> = HashMap::new();
    for spec in &parsed.file.specs {
        let Some(item) = hstl::lang::world_item(spec) else { continue };
        let world = AnyWorld::builtin(&item.name).unwrap_or_else(|| {
            let path = base.join(&item.name);
            let text = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("{name}: world {}: {e}", path.display()));
            AnyWorld::from_toml(&text, "world")
                .unwrap_or_else(|e| panic!("{name}: world {}: {e}", path.display()))
        });
        let label = hstl::world::any_label(&world, None);
        worlds.insert(item.name.clone(), hstl::world::any_facts(&world, &label));
    }
    hstl::lang::check_parsed_with_worlds(src, parsed, &|spec| match hstl::lang::world_item(spec)
        .and_then(|w| worlds.get(&w.name))
    {
        Some(Facts::Grid(facts)) => SpecWorld::Facts(facts),
        Some(Facts::Box(facts)) => SpecWorld::Box(facts),
        None => SpecWorld::Alone,
    })
}

fn assert_checks(name: &str, src: &str, base: &Path) {
    let checked = check(name, src, base);
    assert!(
        !checked.has_errors(),
        "{name} has errors:\n{}",
        hstl::lang::render_plain(src, name, &checked.diagnostics)
    );
    assert!(!checked.specs.is_empty(), "{name} holds no spec");
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
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
        // A block's world file is named as from a spec in examples/specs.
        let base = root().join("examples/specs");
        for (i, block) in specs.iter().enumerate() {
            assert_checks(&format!("{doc} spec block {}", i + 1), block, &base);
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
            assert!(src.contains("world \""), "{} names no world", path.display());
            let checked = check(&path.display().to_string(), &src, &dir);
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
            assert_checks(&path.display().to_string(), &src, &dir);
            n += 1;
        }
    }
    assert!(n >= 5, "only {n} example specs");
}

/// The dense-time example checks, and its robustness is what the README prints.
#[test]
fn the_dense_example_gives_the_readme_numbers() {
    let dir = root().join("examples/dense");
    let src = std::fs::read_to_string(dir.join("braking.hstl")).expect("braking.hstl");
    assert_checks("examples/dense/braking.hstl", &src, &dir);
    let checked = hstl::lang::check(&src);
    let monitor = hstl::monitor::Dense::new(&checked.specs[0], None).expect("a dense monitor");
    let csv = std::fs::read_to_string(dir.join("braking.csv")).expect("braking.csv");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("a header").split(',').collect();
    assert_eq!(header[0], monitor.time_var());
    let mut b = hstl::robustness::dense::DenseTraceBuilder::new(monitor.state_vars().len());
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        let values: Vec<Option<f64>> = monitor
            .state_vars()
            .iter()
            .map(|v| {
                let k = header.iter().position(|h| h == v).expect("a column");
                (!cells[k].is_empty()).then(|| cells[k].parse().expect("a number"))
            })
            .collect();
        b.push(cells[0].parse().expect("a stamp"), &values).expect("a row");
    }
    let trace = b.build().expect("a trace");
    let signal = monitor.signal(&trace).expect("a signal");
    let rows: Vec<String> = signal.until(trace.t_last()).map(|(t, v)| format!("{t},{v}")).collect();
    let readme = std::fs::read_to_string(root().join("README.md")).expect("README.md");
    let printed = format!("t,robustness\n{}\n", rows.join("\n"));
    assert!(readme.contains(&printed), "README.md does not show:\n{printed}");
    assert_eq!(signal.first().to_string(), "-0.09999999999999998");
}
