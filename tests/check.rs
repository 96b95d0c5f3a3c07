//! The checker as the Python package calls it (`hstl::load::check`, `hstl::load::explain`):
//! every diagnostic, warnings included, with or without a world; the long explanations.

use hstl::lang::Severity;
use hstl::load::{check, explain, load};
use hstl::runtime::GridWorld;

const INCLUSIVE: &str = "spec S { state { x: int in 0..=14, y: int in 0..=14 } \
                         let Top = x >= 8; task eventually[0..] Top; }";

#[test]
fn check_gives_the_warnings_that_loading_keeps() {
    let diagnostics = check(INCLUSIVE, None);
    assert!(diagnostics.iter().any(|d| d.code == "HSTL150" && d.severity == Severity::Warning));
    assert!(diagnostics.iter().all(|d| !d.is_error()));
    assert_eq!(load(INCLUSIVE, None).unwrap().diagnostics, diagnostics);
}

#[test]
fn check_gives_errors_too_and_checks_options_against_a_world() {
    let broken = "spec S { state { x: float } task eventually[0..] Nowhere; }";
    assert!(check(broken, None).iter().any(|d| d.is_error()));
    let paper = GridWorld::builtin("paper").unwrap();
    let outside = "spec S { state { x: int in 0..=14, y: int in 0..=14 } \
                   let Far = x > 40; task always[0..] eventually[0..=20] Far; option Far; }";
    let alone = check(outside, None);
    let in_world = check(outside, Some((&paper, "world `paper`")));
    assert!(alone.iter().all(|d| d.code != "HSTL031"), "{alone:?}");
    assert!(in_world.iter().any(|d| d.code == "HSTL031" && d.message.contains("world `paper`")));
}

#[test]
fn explain_gives_the_long_text_and_names_the_known_codes_otherwise() {
    let text = explain("hstl150").unwrap();
    assert!(text.starts_with("HSTL150 (inclusive-bound-on-int): "), "{text}");
    assert!(text.contains("\n\nThe robustness of `x <= 3`"), "{text}");
    let e = explain("HSTL9999").unwrap_err();
    assert_eq!(e.to_string(), "unknown diagnostic code `HSTL9999`");
    assert!(e.help().starts_with("known codes: HSTL001, "), "{}", e.help());
}

#[test]
fn a_formula_alone_is_a_spec_over_the_names_it_reads() {
    let f =
        hstl::load::formula("always[0..=10] (x > 0.5 && eventually[0..3] y < speed * 2)").unwrap();
    let vars: Vec<&str> = f.loaded.spec.state_vars.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(vars, ["x", "y", "speed"]);
    assert_eq!(f.loaded.spec.name, "Formula");
    assert!(f.loaded.diagnostics.is_empty(), "{:?}", f.loaded.diagnostics);
    // The source is a spec that loads again, to the same task.
    let again = load(&f.source, Some("Formula")).unwrap();
    assert_eq!(again.spec.state_vars.len(), 3);
    // A comment at the end does not swallow the rest.
    assert!(hstl::load::formula("x > 1 // done").is_ok());
}

#[test]
fn a_formula_that_does_not_check_is_refused_at_its_own_positions() {
    let text = "always[0..=10] x >";
    let Err(hstl::load::LoadError::Invalid(ds)) = hstl::load::formula(text) else {
        panic!("not refused")
    };
    assert!(ds.iter().all(|d| d.range.end <= text.len()), "{ds:?}");
    assert!(ds.iter().any(|d| d.is_error()));
    for bad in ["x > 1; y > 2", "spec S { }"] {
        let Err(hstl::load::LoadError::Invalid(ds)) = hstl::load::formula(bad) else {
            panic!("{bad} not refused")
        };
        assert!(ds[0].message.starts_with("a formula has no `"), "{}", ds[0].message);
    }
    let Err(hstl::load::LoadError::Invalid(ds)) = hstl::load::formula("true") else {
        panic!("not refused")
    };
    assert_eq!(ds[0].message, "the formula reads no state variable");
}
