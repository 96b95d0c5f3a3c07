//! Lists in messages, worded: `a, b and c`.

/// `a`, `a and b`, `a, b and c`: the items as they are (callers put names in backticks).
pub(crate) fn and_list<T: AsRef<str>>(items: &[T]) -> String {
    match items {
        [] => String::new(),
        [one] => one.as_ref().to_string(),
        [rest @ .., last] => {
            let rest: Vec<&str> = rest.iter().map(AsRef::as_ref).collect();
            format!("{} and {}", rest.join(", "), last.as_ref())
        }
    }
}

/// `text` as a message shows it: as it is, letters of any script included, but each control
/// character (and bidirectional control) escaped as `\x1b` or `\u{202e}`, as the facade's
/// `escape_controls` does (Rust's `escape_default` also spelt `é` as `\u{e9}`).
pub(crate) fn visible(text: &str) -> String {
    let bidi = |c: char| matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            c if (c as u32) < 0x80 && c.is_control() => {
                out.push_str(&format!("\\x{:02x}", c as u32))
            }
            c if c.is_control() || bidi(c) => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    out
}

/// [`visible`] of one character.
pub(crate) fn visible_char(c: char) -> String {
    visible(c.encode_utf8(&mut [0; 4]))
}

#[cfg(test)]
mod tests {
    #[test]
    fn lists_read_as_words() {
        assert_eq!(super::and_list::<&str>(&[]), "");
        assert_eq!(super::and_list(&["`a`"]), "`a`");
        assert_eq!(super::and_list(&["`a`", "`b`"]), "`a` and `b`");
        assert_eq!(super::and_list(&["1", "2", "3"]), "1, 2 and 3");
    }

    #[test]
    fn letters_stay_and_controls_are_escaped() {
        assert_eq!(super::visible("café"), "café");
        assert_eq!(super::visible("a\u{1b}[2J\t"), "a\\x1b[2J\\x09");
        assert_eq!(super::visible("\u{202e}x"), "\\u{202e}x");
        assert_eq!(super::visible_char('é'), "é");
    }
}
