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
