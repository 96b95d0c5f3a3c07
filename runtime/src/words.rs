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

#[cfg(test)]
mod tests {
    #[test]
    fn lists_read_as_words() {
        assert_eq!(super::and_list::<&str>(&[]), "");
        assert_eq!(super::and_list(&["`a`"]), "`a`");
        assert_eq!(super::and_list(&["`a`", "`b`"]), "`a` and `b`");
        assert_eq!(super::and_list(&["1", "2", "3"]), "1, 2 and 3");
    }
}
