//! Every spec in docs/LANGUAGE.md and in examples/specs checks without errors, as
//! `hstlc check` would report them (warnings allowed, exit status 0).

use std::path::Path;

fn assert_checks(name: &str, src: &str) {
    let checked = hstl::lang::check(src);
    assert!(
        !checked.has_errors(),
        "{name} has errors:\n{}",
        hstl::lang::render_plain(src, name, &checked.diagnostics)
    );
    assert!(!checked.specs.is_empty(), "{name} holds no spec");
}

#[test]
fn every_spec_in_the_language_document_checks() {
    let doc =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/LANGUAGE.md"))
            .expect("docs/LANGUAGE.md");
    let mut blocks = Vec::new();
    let mut current: Option<String> = None;
    for line in doc.lines() {
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
    // Blocks that are whole specs; the others are items shown on their own (the memory
    // variant's items are examples/specs/surveillance_memory.hstl, checked below).
    let specs: Vec<&String> = blocks.iter().filter(|b| b.contains("spec ")).collect();
    assert!(specs.len() >= 2, "found {} spec blocks", specs.len());
    for (i, block) in specs.iter().enumerate() {
        assert_checks(&format!("LANGUAGE.md spec block {}", i + 1), block);
    }
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
