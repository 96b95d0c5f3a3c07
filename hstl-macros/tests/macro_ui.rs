//! Compile-fail cases: the message and the caret of each diagnostic family, as rustc
//! prints them for a user of the macro. The cases live in the workspace's `tests/ui`.

#[test]
fn diagnostics_point_at_the_offending_tokens() {
    let t = trybuild::TestCases::new();
    t.compile_fail("../tests/ui/*.rs");
}
