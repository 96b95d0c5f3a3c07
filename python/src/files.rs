//! Reading the files a user names, within the command line's limits, through `hstl-files`
//! as `hstlc`'s `input` reads them: a spec or a world file at most
//! [`hstl::lang::MAX_SOURCE_BYTES`], a `policy.json` at most
//! [`hstl::evaluate::MAX_POLICY_BYTES`]. A regular file past its limit is refused by its size, anything else after one byte more than the limit, so a huge file
//! or `/dev/zero` cannot run the memory out. A leading byte order mark is dropped; text that
//! is not UTF-8 is refused at the line and column of its first bad byte.

use std::path::Path;

use hstl_files::{ReadError, Text};
use pyo3::prelude::*;

use crate::errors::problem_error;

/// The text of the file at `path`, at most `limit` bytes; `what` names the kind of file in
/// errors ("spec"), and `io_error` words a file that cannot be read.
pub fn read_text(
    path: &Path,
    limit: u64,
    what: &str,
    io_error: impl FnOnce(&std::io::Error) -> PyErr,
) -> PyResult<String> {
    text(path, hstl_files::read::read_file(path, limit), what, io_error)
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
    text(path, hstl_files::read::read_regular(path, limit), what, io_error)
}

/// A world file's text, read as `hstlc --world` reads it, with its name as errors give it
/// and the name a world without `name = ...` takes (the file's stem).
pub struct WorldText {
    /// The file's text.
    pub text: String,
    /// The path as errors show it.
    pub file: String,
    /// The file's stem, or `world`.
    pub stem: String,
}

/// The world file at `path` ([`read_regular_text`] at most
/// [`hstl::world::MAX_WORLD_BYTES`]), with the CLI's words for a file that cannot be read.
pub fn read_world(path: &Path) -> PyResult<WorldText> {
    let text = read_regular_text(path, hstl::world::MAX_WORLD_BYTES as u64, "world file", |e| {
        crate::errors::read_error_with(path, e, hstl::world::read_help())
    })?;
    let file = path.display().to_string();
    let stem = path.file_stem().map_or("world".into(), |s| s.to_string_lossy().into_owned());
    Ok(WorldText { text, file, stem })
}

/// The text read, or the error in the package's words.
fn text(
    path: &Path,
    read: Result<Text, ReadError>,
    what: &str,
    io_error: impl FnOnce(&std::io::Error) -> PyErr,
) -> PyResult<String> {
    match read {
        Ok(t) => Ok(t.text),
        Err(e) => Err(match e.problem(&hstl::load::path_words(path), what, "hstl") {
            Ok(refused) => problem_error(&refused),
            Err(e) => io_error(&e),
        }),
    }
}
