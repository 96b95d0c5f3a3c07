//! Reading the files a user names, within the command line's limits (as `hstlc`'s
//! `input` reads them): a spec or a world file at most [`hstl::lang::MAX_SOURCE_BYTES`], a
//! `policy.json` at most [`hstl::evaluate::MAX_POLICY_BYTES`]. A regular file past its limit
//! is refused by its size, anything else after one byte more than the limit, so a huge file
//! or `/dev/zero` cannot run the memory out. A leading byte order mark is dropped; text that
//! is not UTF-8 is refused at the line and column of its first bad byte.

use std::io::Read;
use std::path::Path;

use pyo3::prelude::*;

use crate::errors::value_error;

/// The text of the file at `path`, at most `limit` bytes; `what` names the kind of file in
/// errors ("spec"), and `io_error` words a file that cannot be read.
pub fn read_text(
    path: &Path,
    limit: u64,
    what: &str,
    io_error: impl FnOnce(&std::io::Error) -> PyErr,
) -> PyResult<String> {
    read(path, limit, what, false, io_error)
}

/// [`read_text`] of a regular file only: a named pipe, a device or a socket is refused
/// before a byte is read ([`hstl::load::open_regular`], as `hstlc` reads world files), so
/// that a named pipe cannot make the call wait for a writer forever.
pub fn read_regular_text(
    path: &Path,
    limit: u64,
    what: &str,
    io_error: impl FnOnce(&std::io::Error) -> PyErr,
) -> PyResult<String> {
    read(path, limit, what, true, io_error)
}

fn read(
    path: &Path,
    limit: u64,
    what: &str,
    regular: bool,
    io_error: impl FnOnce(&std::io::Error) -> PyErr,
) -> PyResult<String> {
    let name = path.display().to_string();
    let read = || -> std::io::Result<Option<Vec<u8>>> {
        let file =
            if regular { hstl::load::open_regular(path)? } else { std::fs::File::open(path)? };
        let meta = file.metadata()?;
        if meta.is_dir() {
            return Err(std::io::Error::new(std::io::ErrorKind::IsADirectory, "is a folder"));
        }
        if meta.is_file() && meta.len() > limit {
            return Ok(None);
        }
        let mut bytes = Vec::new();
        file.take(limit + 1).read_to_end(&mut bytes)?;
        Ok((bytes.len() as u64 <= limit).then_some(bytes))
    };
    let read = read().map_err(|e| {
        if regular && e.kind() == std::io::ErrorKind::InvalidInput {
            value_error(
                format!("`{}` is {e}", hstl::load::escape_controls(&name)),
                Some(format!(
                    "a {what} is read only from a regular file: save it as one and name that file"
                )),
            )
        } else {
            io_error(&e)
        }
    })?;
    let Some(mut bytes) = read else {
        return Err(value_error(
            format!("`{name}` is larger than {}, the limit for a {what}", size_words(limit)),
            Some(format!("check that `{name}` is the {what} you meant; hstl reads no larger one")),
        ));
    };
    if bytes.starts_with("\u{feff}".as_bytes()) {
        bytes.drain(..3);
    }
    String::from_utf8(bytes).map_err(|e| {
        let at = e.utf8_error().valid_up_to();
        let bytes = e.into_bytes();
        let before = std::str::from_utf8(&bytes[..at]).unwrap_or_default();
        let p = hstl::lang::LineIndex::new(before).position(before, at);
        value_error(
            format!("{name}:{}:{}: the file is not UTF-8 text", p.line, p.column),
            Some("save it as UTF-8; hstl reads no other encoding".to_string()),
        )
    })
}

/// `1 GiB`, `64 MiB`, `512 KiB` or `100 bytes`, as `hstlc` words a limit.
fn size_words(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 && b.is_multiple_of(1 << 30) => format!("{} GiB", b >> 30),
        b if b >= 1 << 20 && b.is_multiple_of(1 << 20) => format!("{} MiB", b >> 20),
        b if b >= 1 << 10 && b.is_multiple_of(1 << 10) => format!("{} KiB", b >> 10),
        b => format!("{b} bytes"),
    }
}
