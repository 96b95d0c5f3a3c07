//! Parse + check of any bytes (as UTF-8 text, as `hstlc check` reads it): never a panic,
//! every diagnostic range on character boundaries inside the text, diagnostics capped,
//! and the incremental re-parse of a one-byte edit equal to a full parse.

/// The property; panics when it fails.
pub fn check(data: &[u8]) {
    let Ok(src) = std::str::from_utf8(data) else { return };
    // One parse serves the check and the re-parse below (a third of the time per input).
    let parsed = hstl::lang::parse(src);
    let checked = hstl::lang::check_parsed(src, parsed.clone());
    assert!(checked.diagnostics.len() <= hstl::lang::check::MAX_DIAGNOSTICS + 1);
    let index = hstl::lang::LineIndex::new(src);
    for d in &checked.diagnostics {
        for r in std::iter::once(&d.range).chain(d.labels.iter().map(|l| &l.range)) {
            assert!(r.start <= r.end && r.end <= src.len(), "{} {:?}", d.code, r);
            assert!(src.is_char_boundary(r.start) && src.is_char_boundary(r.end), "{}", d.code);
            let p = index.position(src, r.start);
            assert_eq!(index.offset(src, p.line, p.column), r.start, "{}", d.code);
        }
        assert!(!d.message.ends_with('.'), "{}: {}", d.code, d.message);
        assert!(hstl::lang::codes::lookup(d.code).is_some(), "{}", d.code);
    }
    // An edit in the middle: delete one character, re-parse incrementally.
    if let Some((i, c)) = src.char_indices().nth(src.chars().count() / 2) {
        let edited = format!("{}{}", &src[..i], &src[i + c.len_utf8()..]);
        let (again, _) = hstl::lang::incremental::reparse(parsed, src, &edited);
        let full = hstl::lang::parse(&edited);
        assert_eq!(again.file, full.file);
        let mut a = again.diagnostics;
        let mut b = full.diagnostics;
        let key =
            |d: &hstl::lang::Diagnostic| (d.range.start, d.range.end, d.code, d.message.clone());
        a.sort_by_key(key);
        b.sort_by_key(key);
        assert_eq!(a, b);
    }
}
