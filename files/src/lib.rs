//! The file handling of hstl's shells, written once: bounded reads ([`read`]: a file read
//! within a stated size, never to its end first; a named pipe or a device refused before a
//! byte is read where a reader asks for a regular file) and whole-file writes
//! ([`write`](mod@write): a temporary file beside the target, synced, then renamed over
//! it). The command line
//! (`hstlc`), the `hstl!` macro, the Python package and the output folders
//! (`hstl-outdir`) all read and write through here, so that they refuse the same inputs in
//! the same words. File names in messages are lossless ([`words::path_words`]).
//!
//! This crate knows nothing of the learner, the language or the facade: it depends on the
//! standard library (and `libc` on Unix) only.

pub mod read;
pub mod words;
pub mod write;

mod problem;

pub use problem::Problem;
pub use read::{ReadError, Text};

/// A file to write: its name inside an output folder and its bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OutFile {
    /// The file name, such as `policy.json`.
    pub name: String,
    /// The whole contents.
    pub contents: Vec<u8>,
}

impl OutFile {
    /// A file from text.
    pub fn text(name: impl Into<String>, text: String) -> OutFile {
        OutFile { name: name.into(), contents: text.into_bytes() }
    }
}
