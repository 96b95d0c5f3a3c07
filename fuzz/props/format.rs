//! The formatter on any text: never a panic; what it formats parses to the same tree
//! (only the space between tokens changes), keeps its comments, and formats to itself.

/// The property; panics when it fails.
pub fn check(data: &[u8]) {
    let Ok(src) = std::str::from_utf8(data) else { return };
    let Ok(formatted) = hstl::lang::format(src) else { return };
    let before = hstl::lang::check(src);
    let after = hstl::lang::check(&formatted);
    assert_eq!(before.has_errors(), after.has_errors(), "{formatted}");
    let codes = |c: &hstl::lang::Checked| c.diagnostics.iter().map(|d| d.code).collect::<Vec<_>>();
    assert_eq!(codes(&before), codes(&after), "{formatted}");
    assert_eq!(before.file.comments.len(), after.file.comments.len(), "comments lost: {formatted}");
    let again = hstl::lang::format(&formatted).expect("formatted text formats");
    assert_eq!(again, formatted, "not idempotent");
}
