//! Bounded reads: a file (or a stream such as standard input) read as UTF-8 text of at most
//! a stated number of bytes. A regular file past its limit is refused by its size, without
//! reading it; anything else after one byte more than the limit, so `/dev/zero` or an
//! endless pipe cannot run the memory out. A leading byte order mark is dropped (and
//! reported, so that a rewrite can keep it); text that is not UTF-8 is refused at the line
//! and column of its first bad byte. [`read_regular`] also refuses a named pipe, a device
//! or a socket before reading a byte ([`open_regular`]).

use std::io::Read;
use std::path::Path;

use crate::Problem;
use crate::words::{escape_controls, size_words};

/// A text read within its limit.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Text {
    /// The text, without a leading byte order mark.
    pub text: String,
    /// Whether the bytes started with a byte order mark (U+FEFF), as Excel and some
    /// Windows editors write: it is no part of the text, and a rewrite keeps it.
    pub bom: bool,
}

/// Why a text could not be read.
#[derive(Debug)]
pub enum ReadError {
    /// The file could not be opened or read (a folder is one of kind `IsADirectory`); the
    /// caller words it with the path ([`crate::words::read_error`]).
    Io(std::io::Error),
    /// Not a regular file: what it is, as "a named pipe, not a regular file" (only from
    /// [`read_regular`]).
    NotRegular(String),
    /// More bytes than the limit.
    TooLarge {
        /// The limit, in bytes.
        limit: u64,
    },
    /// The bytes are not UTF-8.
    NotUtf8 {
        /// 1-based line of the first bad byte.
        line: usize,
        /// 1-based column of the first bad byte, in characters.
        column: usize,
    },
}

impl ReadError {
    /// The error in words for a refused file, or the I/O error of one that could not be
    /// read (which the caller words with the path): `name` is the file as messages show
    /// it, `what` the kind of file ("spec", "policy"), `program` the reader ("hstlc",
    /// "hstl").
    pub fn problem(self, name: &str, what: &str, program: &str) -> Result<Problem, std::io::Error> {
        Ok(match self {
            ReadError::Io(e) => return Err(e),
            ReadError::NotRegular(kind) => Problem::new(
                format!("`{}` is {kind}", escape_controls(name)),
                Some(format!(
                    "a {what} is read only from a regular file: save it as one and name that file"
                )),
            ),
            ReadError::TooLarge { limit } => Problem::new(
                format!("`{name}` is larger than {}, the limit for a {what}", size_words(limit)),
                Some(format!(
                    "check that `{name}` is the {what} you meant; {program} reads no larger one"
                )),
            ),
            ReadError::NotUtf8 { line, column } => Problem::new(
                format!("{name}:{line}:{column}: the file is not UTF-8 text"),
                Some(format!("save it as UTF-8; {program} reads no other encoding")),
            ),
        })
    }
}

/// The text of the file at `path`, at most `limit` bytes. A folder is refused before a
/// byte is read; a named pipe is read (up to one byte past the limit), waiting for its
/// writer.
pub fn read_file(path: &Path, limit: u64) -> Result<Text, ReadError> {
    let file = std::fs::File::open(path).map_err(ReadError::Io)?;
    let meta = file.metadata().map_err(ReadError::Io)?;
    if meta.is_dir() {
        return Err(ReadError::Io(is_a_folder()));
    }
    // A regular file's size is known: refuse it without reading.
    if meta.is_file() && meta.len() > limit {
        return Err(ReadError::TooLarge { limit });
    }
    read_stream(file, limit)
}

/// [`read_file`] of a regular file only: anything else is refused before a byte is read
/// ([`open_regular`]), so that a named pipe cannot make the reader wait forever.
pub fn read_regular(path: &Path, limit: u64) -> Result<Text, ReadError> {
    let file = open_regular(path).map_err(|e| {
        if e.kind() == std::io::ErrorKind::InvalidInput {
            ReadError::NotRegular(e.to_string())
        } else {
            ReadError::Io(e)
        }
    })?;
    let len = file.metadata().map_err(ReadError::Io)?.len();
    if len > limit {
        return Err(ReadError::TooLarge { limit });
    }
    read_stream(file, limit)
}

/// The text of the stream `r` (standard input), at most `limit` bytes: one byte more is
/// read and the stream refused.
pub fn read_stream(r: impl Read, limit: u64) -> Result<Text, ReadError> {
    let bytes = read_capped(r, limit).map_err(ReadError::Io)?;
    let Some(bytes) = bytes else { return Err(ReadError::TooLarge { limit }) };
    decode(bytes)
}

/// At most `limit` bytes of `r`, or `None` if it holds more.
pub fn read_capped(r: impl Read, limit: u64) -> std::io::Result<Option<Vec<u8>>> {
    let mut bytes = Vec::new();
    r.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    Ok((bytes.len() as u64 <= limit).then_some(bytes))
}

/// The text of `bytes`, its byte order mark dropped, or where its first bad byte is.
pub fn decode(mut bytes: Vec<u8>) -> Result<Text, ReadError> {
    let bom = bytes.starts_with("\u{feff}".as_bytes());
    if bom {
        bytes.drain(..3);
    }
    match String::from_utf8(bytes) {
        Ok(text) => Ok(Text { text, bom }),
        Err(e) => {
            let at = e.utf8_error().valid_up_to();
            let bytes = e.into_bytes();
            // The text before the bad byte is valid.
            let before = std::str::from_utf8(&bytes[..at]).unwrap_or_default();
            let (line, column) = end_position(before);
            Err(ReadError::NotUtf8 { line, column })
        }
    }
}

/// The 1-based line and character column just past the end of `text`, as
/// `hstl_lang::LineIndex` counts them: lines end at `\n`, `\r\n` or a lone `\r`, and a
/// `\r` before `\n` is a character of its line (`tests/twins.rs` holds the two equal).
pub fn end_position(text: &str) -> (usize, usize) {
    let bytes = text.as_bytes();
    let mut line = 1;
    let mut start = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'\n' || b == b'\r' && bytes.get(i + 1) != Some(&b'\n') {
            line += 1;
            start = i + 1;
        }
    }
    (line, text[start..].chars().count() + 1)
}

fn is_a_folder() -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::IsADirectory, "is a folder")
}

/// What a file that is neither a regular file nor a folder is, in words ("a named pipe",
/// "a device", "a socket", "a special file").
pub fn special_kind(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a named pipe";
        }
        if t.is_char_device() || t.is_block_device() {
            return "a device";
        }
        if t.is_socket() {
            return "a socket";
        }
    }
    let _ = meta;
    "a special file"
}

/// Opens `path` for reading when it is a regular file. A folder is an error of kind
/// `IsADirectory`; a named pipe, a device or a socket one of kind `InvalidInput` whose
/// message says what it is ("a named pipe, not a regular file"), before a byte is read: a
/// file that a spec names (its `world` item) is read by `check` and by the language server
/// on every keystroke, and opening a named pipe for reading waits for a writer, forever if
/// none comes. The file is opened without waiting and then looked at.
pub fn open_regular(path: &Path) -> std::io::Result<std::fs::File> {
    #[cfg(unix)]
    let file = {
        use std::os::unix::fs::OpenOptionsExt;
        std::fs::OpenOptions::new().read(true).custom_flags(libc::O_NONBLOCK).open(path)?
    };
    #[cfg(not(unix))]
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    if meta.is_dir() {
        return Err(is_a_folder());
    }
    if meta.is_file() {
        return Ok(file);
    }
    Err(std::io::Error::new(
        std::io::ErrorKind::InvalidInput,
        format!("{}, not a regular file", special_kind(&meta)),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_bom_and_encoding() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let path = tmp.path().join("a.hstl");
        // (contents, limit, the text read or the problem's message)
        let cases: &[(&[u8], u64, Result<&str, &str>)] = &[
            (b"spec", 4, Ok("spec")),
            (b"spec!", 4, Err("`a` is larger than 4 bytes, the limit for a spec")),
            (b"\xef\xbb\xbfspec", 4, Err("`a` is larger than 4 bytes, the limit for a spec")),
            (b"\xef\xbb\xbfspec", 7, Ok("spec")),
            (b"ok\r\nx\xc3\xa9\xff", 64, Err("a:2:3: the file is not UTF-8 text")),
            (b"a\rb\xff", 64, Err("a:2:2: the file is not UTF-8 text")),
        ];
        for (bytes, limit, want) in cases {
            std::fs::write(&path, bytes).expect("write");
            for read in [read_file(&path, *limit), read_regular(&path, *limit)] {
                let got = read
                    .map(|t| t.text)
                    .map_err(|e| e.problem("a", "spec", "hstlc").expect("worded").message);
                assert_eq!(got.as_deref().map_err(String::as_str), *want, "{bytes:?}");
            }
        }
        // A byte order mark is reported.
        std::fs::write(&path, b"\xef\xbb\xbfspec").expect("write");
        assert!(read_file(&path, 64).expect("reads").bom);
        // A stream is refused one byte past its limit.
        let endless = std::io::repeat(b'x');
        let err = read_stream(endless, 1 << 10).expect_err("too large");
        assert!(matches!(err, ReadError::TooLarge { limit: 1024 }));
    }

    #[test]
    fn folders_and_special_files_are_refused_before_reading() {
        let tmp = tempfile::tempdir().expect("temp dir");
        for read in [read_file(tmp.path(), 10), read_regular(tmp.path(), 10)] {
            match read {
                Err(ReadError::Io(e)) => assert_eq!(e.kind(), std::io::ErrorKind::IsADirectory),
                other => panic!("a folder read: {other:?}"),
            }
        }
        #[cfg(unix)]
        {
            let fifo = tmp.path().join("pipe");
            let c = std::ffi::CString::new(fifo.to_string_lossy().as_bytes()).expect("path");
            // SAFETY: a valid NUL-terminated path.
            assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
            let err = read_regular(&fifo, 10).expect_err("a named pipe");
            let p = err.problem("pipe", "world file", "hstl").expect("worded");
            assert_eq!(p.message, "`pipe` is a named pipe, not a regular file");
        }
    }
}
