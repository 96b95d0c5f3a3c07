//! Files and sizes in messages: paths shown losslessly and safely, the OS reason of an I/O
//! error, and sizes in the units a limit is stated in.

use std::path::Path;

/// `` cannot read `PATH`: REASON ``, the OS reason in lower case without its
/// "(os error N)" tail.
pub fn read_error(path: &Path, error: &std::io::Error) -> String {
    format!("cannot read `{}`: {}", path_words(path), io_reason(error))
}

/// A path as messages show it, losslessly: its text as it is, control characters escaped
/// ([`escape_controls`]), and each byte that is not UTF-8 as `\xff` (where `display()`
/// shows U+FFFD for every one of them, so that two files print under one name).
pub fn path_words(path: &Path) -> String {
    #[cfg(unix)]
    let bytes = std::os::unix::ffi::OsStrExt::as_bytes(path.as_os_str());
    #[cfg(not(unix))]
    let owned = path.to_string_lossy().into_owned().into_bytes();
    #[cfg(not(unix))]
    let bytes = owned.as_slice();
    let mut out = String::with_capacity(bytes.len());
    for chunk in bytes.utf8_chunks() {
        out.push_str(&escape_controls(chunk.valid()));
        for b in chunk.invalid() {
            out.push_str(&format!("\\x{b:02x}"));
        }
    }
    out
}

/// `text` with its control characters (and the bidirectional controls, which reorder what
/// a terminal shows) escaped as `\x1b` or `\u{202e}`: a name shown in a message cannot
/// clear the screen, retitle the window, move the cursor or hide what follows. Other text,
/// non-ASCII letters included, is shown as it is.
pub fn escape_controls(text: &str) -> std::borrow::Cow<'_, str> {
    let bidi = |c: char| matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
    let unsafe_char = |c: char| c.is_control() || bidi(c);
    if !text.chars().any(unsafe_char) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            c if (c as u32) < 0x80 && unsafe_char(c) => {
                out.push_str(&format!("\\x{:02x}", c as u32))
            }
            c if unsafe_char(c) => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    std::borrow::Cow::Owned(out)
}

/// The OS reason of an I/O error in lower case, without the "(os error N)" tail.
pub fn io_reason(e: &std::io::Error) -> String {
    let text = e.to_string();
    let text = text.split(" (os error").next().unwrap_or(&text).to_string();
    let mut chars = text.chars();
    match chars.next() {
        Some(c) => c.to_lowercase().chain(chars).collect(),
        None => text,
    }
}

/// `1 GiB`, `64 MiB`, `512 KiB` or `100 bytes`: a limit in the largest unit that states
/// it exactly.
pub fn size_words(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b.is_multiple_of(1 << 30) => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b.is_multiple_of(1 << 20) => format!("{} MiB", b >> 20),
        b if b >= 1 << 10 && b.is_multiple_of(1 << 10) => format!("{} KiB", b >> 10),
        b => format!("{b} bytes"),
    }
}
