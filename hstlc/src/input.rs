//! Reading the files a user names (or standard input), within stated sizes: a spec is at
//! most [`hstl::lang::MAX_SOURCE_BYTES`], a `policy.json` at most [`MAX_POLICY_BYTES`];
//! traces are read as a stream by [`crate::trace_csv`], within their own limits. A file
//! past its limit is refused after reading one byte more than the limit, so `/dev/zero`
//! or an endless pipe cannot run the memory out.

use std::path::Path;

use hstl_files::ReadError;

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
    if path == Path::new("-") {
        let read = hstl_files::read::read_stream(std::io::stdin().lock(), limit);
        return input(stdin_name.to_string(), Path::new(stdin_name), read, what);
    }
    let read = hstl_files::read::read_file(path, limit);
    input(hstl::load::path_words(path), path, read, what)
}

/// Reads the regular file `path` as [`read_text`] does, and refuses anything else (a named
/// pipe, a device, a socket) before reading a byte ([`hstl::load::open_regular`]): a world
/// file that a spec names is read by `check` and by the language server on every
/// keystroke, and opening a named pipe would wait for a writer forever.
pub fn read_regular_text(path: &Path, limit: u64, what: &str) -> Result<Input, CliError> {
    let read = hstl_files::read::read_regular(path, limit);
    input(hstl::load::path_words(path), path, read, what)
}

/// The [`Input`] read from `name` (at `path`), or the error worded for the command line.
fn input(
    name: String,
    path: &Path,
    read: Result<hstl_files::Text, ReadError>,
    what: &str,
) -> Result<Input, CliError> {
    match read {
        Ok(t) => Ok(Input { name, text: t.text, bom: t.bom }),
        Err(e) => Err(match e.problem(&name, what, "hstlc") {
            Ok(refused) => refused.into(),
            Err(source) => CliError::Read { path: path.to_path_buf(), source },
        }),
    }
}
