//! The wire: frames (`Content-Length` headers, a blank line, then the body) read from a
//! byte stream, and JSON-RPC messages decoded from their bodies.
//!
//! Every size is checked before anything is read into memory: a frame longer than
//! [`MAX_MESSAGE_BYTES`] is skipped by reading and discarding its body in small chunks,
//! and a header block longer than [`MAX_HEADER_BYTES`] is abandoned. A frame whose length
//! cannot be known (a bad, missing or conflicting `Content-Length`) is skipped by
//! discarding input up to the next `Content-Length:` header. Nothing here panics, blocks
//! on anything but the input, or recurses: a malformed frame costs its own bytes, and the
//! next well-formed one is read as usual.

use std::fmt;
use std::io::{self, BufRead, Read as _};

use lsp_server::ErrorCode;
use serde_json::{Map, Value};

/// Longest message body read (64 MiB); a longer frame is skipped, never allocated.
pub const MAX_MESSAGE_BYTES: u64 = 64 << 20;

/// Longest header block (8 KiB); past it the headers are abandoned.
pub const MAX_HEADER_BYTES: usize = 8 << 10;

/// The header that starts every frame, which resynchronisation looks for.
const LENGTH_HEADER: &[u8] = b"content-length:";

/// The first allocation for a body; it doubles up to the announced length.
const CHUNK: u64 = 64 << 10;

/// One step of reading the input.
#[derive(Debug, PartialEq, Eq)]
pub enum Frame {
    /// The body of a well-formed frame.
    Message(Vec<u8>),
    /// A frame with a wrong header but a known length: its body was read (only to find
    /// an id to answer); it is not executed.
    BadHeader {
        /// What is wrong with the headers.
        problem: Problem,
        /// The body.
        body: Vec<u8>,
    },
    /// Input that was skipped, and why.
    Skipped(Problem),
    /// The end of the input; `Some` when it ended inside a frame or could not be read.
    End(Option<Problem>),
}

/// What is wrong with a frame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Problem {
    /// `Content-Length` is larger than [`MAX_MESSAGE_BYTES`] (its body is skipped).
    TooLarge(u64),
    /// `Content-Length` does not fit in 64 bits.
    LengthOverflow,
    /// `Content-Length` is not a decimal number (the value, shortened).
    BadLength(String),
    /// Two `Content-Length` headers with the same value.
    DuplicateLength,
    /// Two `Content-Length` headers with different values.
    ConflictingLengths(u64, u64),
    /// The headers ended without a `Content-Length`.
    MissingLength,
    /// The header block is longer than [`MAX_HEADER_BYTES`].
    HeadersTooLong,
    /// A header line that is not `Name: value` in ASCII (shortened).
    MalformedHeader(String),
    /// The input ended inside a frame's headers.
    EndInHeaders,
    /// The input ended inside a frame's body (`read` of `expected` bytes).
    EndInBody {
        /// Bytes read.
        read: u64,
        /// Bytes announced.
        expected: u64,
    },
    /// Reading the input failed.
    Read(String),
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Problem::TooLarge(n) => write!(
                f,
                "a {n}-byte message is larger than the limit of {} MiB; skipping its body",
                MAX_MESSAGE_BYTES >> 20
            ),
            Problem::LengthOverflow => {
                write!(f, "Content-Length does not fit in 64 bits; skipping to the next header")
            }
            Problem::BadLength(v) => write!(
                f,
                "Content-Length `{v}` is not a decimal number; skipping to the next header"
            ),
            Problem::DuplicateLength => write!(f, "Content-Length is given twice"),
            Problem::ConflictingLengths(a, b) => write!(
                f,
                "Content-Length is given twice ({a} and {b}); skipping to the next header"
            ),
            Problem::MissingLength => {
                write!(f, "a message without Content-Length; skipping to the next header")
            }
            Problem::HeadersTooLong => write!(
                f,
                "message headers longer than {} KiB; skipping to the next header",
                MAX_HEADER_BYTES >> 10
            ),
            Problem::MalformedHeader(h) => {
                write!(f, "header `{h}` is not `Name: value` in ASCII")
            }
            Problem::EndInHeaders => write!(f, "the input ended inside a message header"),
            Problem::EndInBody { read, expected } => {
                write!(f, "the input ended inside a message body ({read} of {expected} bytes)")
            }
            Problem::Read(e) => write!(f, "cannot read standard input: {e}"),
        }
    }
}

/// Reads frames from a buffered byte stream.
pub struct FrameReader<R> {
    input: R,
    /// Resynchronisation has just consumed a `Content-Length:`; the next header block
    /// starts inside that header.
    resumed: bool,
    /// Input still to be skipped for the last frame reported: a problem is reported as
    /// soon as it is seen, before the (possibly endless) input it spoils is read.
    skip: Skip,
}

#[derive(Clone, Copy)]
enum Skip {
    Nothing,
    /// The body of a frame too large to read.
    Bytes(u64),
    /// Everything up to the next `Content-Length:`.
    ToNextHeader,
}

/// What the headers of one frame said.
struct Headers {
    /// The body's length, or why it is unknown.
    length: Result<u64, Problem>,
    /// Another problem with the headers (the length is still usable).
    problem: Option<Problem>,
}

impl<R: BufRead> FrameReader<R> {
    /// A reader at the start of `input`.
    pub fn new(input: R) -> Self {
        FrameReader { input, resumed: false, skip: Skip::Nothing }
    }

    /// The underlying input (to see whether more of it is already buffered).
    pub fn get_ref(&self) -> &R {
        &self.input
    }

    /// The next frame, or what was skipped. After [`Frame::End`] every call returns
    /// `End` again (or a frame, if the input grows).
    pub fn next_frame(&mut self) -> Frame {
        let skipped = match std::mem::replace(&mut self.skip, Skip::Nothing) {
            Skip::Nothing => Ok(()),
            Skip::Bytes(n) => self.discard(n).map_err(Some),
            Skip::ToNextHeader => self.resynchronise(),
        };
        if let Err(end) = skipped {
            return Frame::End(end);
        }
        let headers = match self.headers() {
            Ok(Some(h)) => h,
            Ok(None) => return Frame::End(None),
            Err(p) => return Frame::End(Some(p)),
        };
        match headers.length {
            Ok(n) if n > MAX_MESSAGE_BYTES => {
                self.skip = Skip::Bytes(n);
                Frame::Skipped(Problem::TooLarge(n))
            }
            Ok(n) => match self.body(n) {
                Ok(body) => match headers.problem {
                    None => Frame::Message(body),
                    Some(problem) => Frame::BadHeader { problem, body },
                },
                Err(p) => Frame::End(Some(p)),
            },
            Err(problem) => {
                self.skip = Skip::ToNextHeader;
                Frame::Skipped(problem)
            }
        }
    }

    /// Reads one header block. `None` at the end of the input before any header.
    fn headers(&mut self) -> Result<Option<Headers>, Problem> {
        let mut length: Option<Result<u64, Problem>> = None;
        let mut problem = None;
        let mut budget = MAX_HEADER_BYTES;
        let mut line = Vec::new();
        let mut started = false;
        loop {
            line.clear();
            if std::mem::take(&mut self.resumed) {
                line.extend_from_slice(b"Content-Length:");
                started = true;
            }
            match self.line(&mut line, &mut budget) {
                Ok(true) => {}
                Ok(false) if !started && line.is_empty() => return Ok(None),
                Ok(false) => return Err(Problem::EndInHeaders),
                Err(LineError::TooLong) => {
                    return Ok(Some(Headers {
                        length: Err(Problem::HeadersTooLong),
                        problem: None,
                    }));
                }
                Err(LineError::Read(e)) => return Err(Problem::Read(e.to_string())),
            }
            let text = trim_line_end(&line);
            if text.is_empty() {
                if !started {
                    // Blank lines between frames are tolerated.
                    continue;
                }
                break;
            }
            started = true;
            let Some((name, value)) = split_header(text) else {
                problem.get_or_insert(Problem::MalformedHeader(shorten(text)));
                continue;
            };
            if !name.eq_ignore_ascii_case("content-length") {
                continue;
            }
            let this = parse_length(value);
            length = Some(match (length, this) {
                (None, this) => this,
                (Some(Ok(a)), Ok(b)) if a == b => {
                    problem.get_or_insert(Problem::DuplicateLength);
                    Ok(a)
                }
                (Some(Ok(a)), Ok(b)) => Err(Problem::ConflictingLengths(a, b)),
                (Some(Err(p)), _) | (Some(Ok(_)), Err(p)) => Err(p),
            });
        }
        let length = length.unwrap_or(Err(Problem::MissingLength));
        Ok(Some(Headers { length, problem }))
    }

    /// Appends one line (up to and including `\n`) to `line`, charging `budget`. `false`
    /// at the end of the input.
    fn line(&mut self, line: &mut Vec<u8>, budget: &mut usize) -> Result<bool, LineError> {
        loop {
            let buf = match self.input.fill_buf() {
                Ok(buf) => buf,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(LineError::Read(e)),
            };
            if buf.is_empty() {
                return Ok(false);
            }
            let (take, done) = match buf.iter().position(|&b| b == b'\n') {
                Some(i) => (i + 1, true),
                None => (buf.len(), false),
            };
            if take > *budget {
                let n = *budget;
                self.input.consume(n);
                *budget = 0;
                return Err(LineError::TooLong);
            }
            line.extend_from_slice(&buf[..take]);
            self.input.consume(take);
            *budget -= take;
            if done {
                return Ok(true);
            }
        }
    }

    /// Reads a body of `n` bytes (at most [`MAX_MESSAGE_BYTES`]). Memory grows with the
    /// bytes that arrive, doubling from 64 KiB and never past `n`: an announced length
    /// with nothing behind it costs nothing.
    fn body(&mut self, n: u64) -> Result<Vec<u8>, Problem> {
        let mut body = Vec::new();
        while (body.len() as u64) < n {
            let have = body.len() as u64;
            let step = (n - have).min(have.max(CHUNK));
            // `step` is at most 64 MiB, so it fits in `usize`.
            body.reserve_exact(step as usize);
            match (&mut self.input).take(step).read_to_end(&mut body) {
                Ok(0) => return Err(Problem::EndInBody { read: have, expected: n }),
                Ok(_) => {}
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(Problem::Read(e.to_string())),
            }
        }
        Ok(body)
    }

    /// Reads and drops `n` bytes, a buffer at a time.
    fn discard(&mut self, n: u64) -> Result<(), Problem> {
        let mut left = n;
        while left > 0 {
            let buf = match self.input.fill_buf() {
                Ok(buf) => buf,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(Problem::Read(e.to_string())),
            };
            if buf.is_empty() {
                return Err(Problem::EndInBody { read: n - left, expected: n });
            }
            let take = buf.len().min(usize::try_from(left).unwrap_or(usize::MAX));
            self.input.consume(take);
            left -= take as u64;
        }
        Ok(())
    }

    /// Drops input up to and including the next `Content-Length:` (any case), so that
    /// the next header block starts there. `Err(None)` at the end of the input.
    fn resynchronise(&mut self) -> Result<(), Option<Problem>> {
        // `content-length:` has no proper prefix that is also a suffix, so a mismatch
        // restarts the match at this byte.
        let mut matched = 0;
        loop {
            let buf = match self.input.fill_buf() {
                Ok(buf) => buf,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(Some(Problem::Read(e.to_string()))),
            };
            if buf.is_empty() {
                return Err(None);
            }
            let mut used = buf.len();
            for (i, &b) in buf.iter().enumerate() {
                let b = b.to_ascii_lowercase();
                if b == LENGTH_HEADER[matched] {
                    matched += 1;
                } else {
                    matched = usize::from(b == LENGTH_HEADER[0]);
                }
                if matched == LENGTH_HEADER.len() {
                    used = i + 1;
                    break;
                }
            }
            self.input.consume(used);
            if matched == LENGTH_HEADER.len() {
                self.resumed = true;
                return Ok(());
            }
        }
    }
}

enum LineError {
    TooLong,
    Read(io::Error),
}

fn trim_line_end(line: &[u8]) -> &[u8] {
    let mut end = line.len();
    while end > 0 && matches!(line[end - 1], b'\n' | b'\r') {
        end -= 1;
    }
    &line[..end]
}

/// `Name: value` in printable ASCII.
fn split_header(line: &[u8]) -> Option<(&str, &str)> {
    let text = std::str::from_utf8(line).ok()?;
    if !text.bytes().all(|b| b == b'\t' || (b' '..=b'~').contains(&b)) {
        return None;
    }
    let (name, value) = text.split_once(':')?;
    let name = name.trim();
    if name.is_empty() || name.contains([' ', '\t']) {
        return None;
    }
    Some((name, value.trim()))
}

fn parse_length(value: &str) -> Result<u64, Problem> {
    if value.is_empty() || !value.bytes().all(|b| b.is_ascii_digit()) {
        return Err(Problem::BadLength(shorten(value.as_bytes())));
    }
    value.parse::<u64>().map_err(|_| Problem::LengthOverflow)
}

/// At most 40 characters of `bytes`, for a log line.
fn shorten(bytes: &[u8]) -> String {
    let text = String::from_utf8_lossy(bytes);
    let mut out: String = text.chars().take(40).flat_map(char::escape_default).collect();
    if text.chars().nth(40).is_some() {
        out.push_str("...");
    }
    out
}

/// A request id as the client sent it: an integer or a string.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Id {
    /// An integer id.
    Number(serde_json::Number),
    /// A string id.
    String(String),
}

impl Id {
    /// The id in `value`, when it is an integer or a string.
    pub fn from_json(value: &Value) -> Option<Id> {
        match value {
            Value::Number(n) if n.is_i64() || n.is_u64() => Some(Id::Number(n.clone())),
            Value::String(s) => Some(Id::String(s.clone())),
            _ => None,
        }
    }

    /// The id as JSON.
    pub fn to_json(&self) -> Value {
        match self {
            Id::Number(n) => Value::Number(n.clone()),
            Id::String(s) => Value::String(s.clone()),
        }
    }
}

impl fmt::Display for Id {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Id::Number(n) => write!(f, "{n}"),
            Id::String(s) => write!(f, "\"{}\"", shorten(s.as_bytes())),
        }
    }
}

/// A decoded message from the client.
#[derive(Debug)]
pub enum Incoming {
    /// A request: it gets exactly one response.
    Request {
        /// Its id.
        id: Id,
        /// The method.
        method: String,
        /// The parameters (`null` when absent).
        params: Value,
    },
    /// A notification.
    Notification {
        /// The method.
        method: String,
        /// The parameters (`null` when absent).
        params: Value,
    },
    /// A response to a request of the server (it sends none, so it is ignored).
    Response,
    /// Not a message the server can act on: logged, and answered with `code` when an
    /// id could be read.
    Invalid {
        /// The id, when one could be read.
        id: Option<Id>,
        /// The error code to answer with.
        code: ErrorCode,
        /// What is wrong.
        message: String,
    },
}

impl Incoming {
    /// Whether this is the `exit` notification.
    pub fn is_exit(&self) -> bool {
        matches!(self, Incoming::Notification { method, .. } if method == "exit")
    }

    /// What a skipped or malformed frame becomes.
    pub fn from_frame(frame: Frame) -> Option<Incoming> {
        match frame {
            Frame::Message(body) => Some(decode(&body)),
            Frame::BadHeader { problem, body } => Some(Incoming::Invalid {
                id: recover_id(&body),
                code: ErrorCode::InvalidRequest,
                message: format!("malformed message header: {problem}"),
            }),
            Frame::Skipped(problem) => Some(Incoming::Invalid {
                id: None,
                code: ErrorCode::InvalidRequest,
                message: format!("malformed message: {problem}"),
            }),
            Frame::End(_) => None,
        }
    }
}

/// Decodes one body: UTF-8, then one JSON value, then the shape of a JSON-RPC message.
/// Never panics; what is not a message becomes [`Incoming::Invalid`], with the id when
/// one can be read (from the first JSON value of the body, read leniently).
pub fn decode(body: &[u8]) -> Incoming {
    let text = match std::str::from_utf8(body) {
        Ok(text) => text,
        Err(e) => {
            return Incoming::Invalid {
                id: recover_id(body),
                code: ErrorCode::ParseError,
                message: format!("the message is not valid UTF-8 (at byte {})", e.valid_up_to()),
            };
        }
    };
    let value: Value = match serde_json::from_str(text) {
        Ok(v) => v,
        Err(e) => {
            return Incoming::Invalid {
                id: recover_id(body),
                code: ErrorCode::ParseError,
                message: format!("the message is not valid JSON: {e}"),
            };
        }
    };
    let Value::Object(object) = value else {
        return invalid(None, "a message must be a JSON object (batches are not supported)");
    };
    message(object)
}

fn invalid(id: Option<Id>, message: &str) -> Incoming {
    Incoming::Invalid { id, code: ErrorCode::InvalidRequest, message: message.to_string() }
}

fn message(mut object: Map<String, Value>) -> Incoming {
    let id = match object.get("id") {
        None => None,
        Some(v) => match Id::from_json(v) {
            Some(id) => Some(id),
            None => return invalid(None, "the id must be an integer or a string"),
        },
    };
    match object.get("jsonrpc") {
        None => {}
        Some(Value::String(v)) if v == "2.0" => {}
        Some(_) => return invalid(id, "`jsonrpc` must be \"2.0\""),
    }
    let params = object.remove("params").unwrap_or(Value::Null);
    if !matches!(params, Value::Null | Value::Object(_) | Value::Array(_)) {
        return invalid(id, "`params` must be an object or an array");
    }
    match object.remove("method") {
        Some(Value::String(method)) => match id {
            Some(id) => Incoming::Request { id, method, params },
            None => Incoming::Notification { method, params },
        },
        Some(_) => invalid(id, "`method` must be a string"),
        None if id.is_some() && (object.contains_key("result") || object.contains_key("error")) => {
            Incoming::Response
        }
        None => invalid(id, "a message needs a `method` (or a `result` or `error`)"),
    }
}

/// The id of a body that is not a valid message: read from its first JSON value (so that
/// trailing characters or a bad header do not hide it), with invalid UTF-8 replaced.
fn recover_id(body: &[u8]) -> Option<Id> {
    let text = String::from_utf8_lossy(body);
    let first = serde_json::Deserializer::from_str(&text).into_iter::<Value>().next()?.ok()?;
    Id::from_json(first.get("id")?)
}

/// Frames a body for the wire: the header, then the body.
pub fn write_frame(out: &mut impl io::Write, body: &[u8]) -> io::Result<()> {
    write!(out, "Content-Length: {}\r\n\r\n", body.len())?;
    out.write_all(body)
}
