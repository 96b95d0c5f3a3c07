//! Reading the files a user names (or standard input), within stated sizes: a spec is at
//! most [`hstl::lang::MAX_SOURCE_BYTES`], a `policy.json` at most [`MAX_POLICY_BYTES`];
//! traces are read as a stream by [`crate::trace_csv`], within their own limits. A file
//! past its limit is refused after reading one byte more than the limit, so `/dev/zero`
//! or an endless pipe cannot run the memory out.

use std::io::Read;
use std::path::{Path, PathBuf};

use crate::cli_error::CliError;

/// The largest `policy.json` `eval` reads: 1 GiB.
pub const MAX_POLICY_BYTES: u64 = hstl::evaluate::MAX_POLICY_BYTES;

/// A text read from a file or standard input.
pub struct Input {
    /// The path, or the name given for standard input.
    pub name: String,
    /// The text, without a leading byte order mark.
    pub text: String,
    /// Whether the file started with a byte order mark (U+FEFF), as Excel and some Windows
    /// editors write: it is no part of the text, and `fmt --write` keeps it.
    pub bom: bool,
}

/// Reads `path` (standard input for `-`, reported as `stdin_name`) as UTF-8 text of at
/// most `limit` bytes; `what` names the kind of file in the error ("spec", "policy").
pub fn read_text(path: &Path, stdin_name: &str, limit: u64, what: &str) -> Result<Input, CliError> {
    let (name, bytes) = if path == Path::new("-") {
        let name = stdin_name.to_string();
        let bytes = read_capped(std::io::stdin().lock(), limit)
            .map_err(|source| CliError::Read { path: PathBuf::from(stdin_name), source })?;
        (name, bytes)
    } else {
        let name = hstl::load::path_words(path);
        let read = |path: &Path| -> std::io::Result<Option<Vec<u8>>> {
            let file = std::fs::File::open(path)?;
            let meta = file.metadata()?;
            if meta.is_dir() {
                return Err(std::io::Error::new(std::io::ErrorKind::IsADirectory, "is a folder"));
            }
            // A regular file's size is known: refuse it without reading.
            if meta.is_file() && meta.len() > limit {
                return Ok(None);
            }
            read_capped(file, limit)
        };
        let bytes =
            read(path).map_err(|source| CliError::Read { path: path.to_path_buf(), source })?;
        (name, bytes)
    };
    decode(name, bytes, limit, what)
}

/// Reads the regular file `path` as [`read_text`] does, and refuses anything else (a named
/// pipe, a device, a socket) before reading a byte ([`hstl::load::open_regular`]): a world
/// file that a spec names is read by `check` and by the language server on every
/// keystroke, and opening a named pipe would wait for a writer forever.
pub fn read_regular_text(path: &Path, limit: u64, what: &str) -> Result<Input, CliError> {
    let name = hstl::load::path_words(path);
    let read_err = |source| CliError::Read { path: path.to_path_buf(), source };
    let file = hstl::load::open_regular(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::InvalidInput {
            CliError::new(
                format!("`{}` is {e}", hstl::load::escape_controls(&name)),
                Some(format!(
                    "a {what} is read only from a regular file: save it as one and name that file"
                )),
            )
        } else {
            read_err(e)
        }
    })?;
    let len = file.metadata().map_err(read_err)?.len();
    let bytes = if len > limit { None } else { read_capped(file, limit).map_err(read_err)? };
    decode(name, bytes, limit, what)
}

/// The text of `bytes` read from `name` (`None`: more than `limit` bytes).
fn decode(name: String, bytes: Option<Vec<u8>>, limit: u64, what: &str) -> Result<Input, CliError> {
    let Some(mut bytes) = bytes else {
        return Err(too_large(&name, limit, what));
    };
    let bom = bytes.starts_with("\u{feff}".as_bytes());
    if bom {
        bytes.drain(..3);
    }
    let text = String::from_utf8(bytes).map_err(|e| not_utf8(&name, e))?;
    Ok(Input { name, text, bom })
}

/// `1 GiB`, `64 MiB`, `512 KiB` or `100 bytes`.
pub fn size_words(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b.is_multiple_of(1 << 30) => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b.is_multiple_of(1 << 20) => format!("{} MiB", b >> 20),
        b if b >= 1 << 10 && b.is_multiple_of(1 << 10) => format!("{} KiB", b >> 10),
        b => format!("{b} bytes"),
    }
}

/// At most `limit` bytes of `r`, or `None` if it holds more.
fn read_capped(r: impl Read, limit: u64) -> std::io::Result<Option<Vec<u8>>> {
    let mut bytes = Vec::new();
    r.take(limit + 1).read_to_end(&mut bytes)?;
    Ok((bytes.len() as u64 <= limit).then_some(bytes))
}

fn too_large(name: &str, limit: u64, what: &str) -> CliError {
    CliError::new(
        format!("`{name}` is larger than {}, the limit for a {what}", size_words(limit)),
        Some(format!("check that `{name}` is the {what} you meant; hstlc reads no larger one")),
    )
}

/// The error for bytes that are not UTF-8, at the line and column of the first bad byte.
fn not_utf8(name: &str, e: std::string::FromUtf8Error) -> CliError {
    let at = e.utf8_error().valid_up_to();
    let bytes = e.into_bytes();
    // The text before the bad byte is valid.
    let before = std::str::from_utf8(&bytes[..at]).unwrap_or_default();
    let p = hstl::lang::LineIndex::new(before).position(before, at);
    CliError::new(
        format!("{name}:{}:{}: the file is not UTF-8 text", p.line, p.column),
        Some("save it as UTF-8; hstlc reads no other encoding".to_string()),
    )
}
