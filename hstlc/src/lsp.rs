//! `hstlc lsp`: a Language Server on standard input and output, on plain threads (no
//! async runtime).
//!
//! Diagnostics are exactly those of `hstlc check`, published (with the document's
//! version) after open and change and cleared on close. Documents are synchronised in
//! full; each version is checked at most once, and that analysis answers hover,
//! definition, references, document symbols, completion and formatting. Positions use
//! UTF-8 when the client offers it, else UTF-16.
//!
//! Hostile or broken input is survived by design:
//! - [`transport`] reads frames with every size checked before it is read: a body over
//!   [`MAX_MESSAGE_BYTES`] (64 MiB) is skipped in small chunks, never allocated; a frame
//!   with a bad, missing or conflicting `Content-Length` is skipped up to the next
//!   `Content-Length:` header. A body that is not a JSON-RPC message (invalid UTF-8 or
//!   JSON, trailing characters, an object as `id`) is answered with `ParseError` or
//!   `InvalidRequest` when an id can be read, always logged to standard error, and the
//!   server goes on.
//! - Lifecycle: before `initialize`, requests get `ServerNotInitialized` and
//!   notifications other than `exit` are dropped; after `shutdown`, requests get
//!   `InvalidRequest`. Only `exit` ends the server.
//! - The messages waiting for the server and for the client are bounded (64 and 16
//!   MiB), and a document has at most one `publishDiagnostics` waiting: a newer
//!   one replaces it, so a client that reads slowly costs bounded memory.
//! - A change only stores the text; the newest text is analysed when a request needs it
//!   or the server is idle, so a burst of changes costs one analysis.
//! - A document over [`MAX_DOCUMENT_BYTES`] (4 MiB) is not analysed: the client is told
//!   once (`window/showMessage`), and requests on it fail with that reason.
//! - Walks of syntax trees keep their own stacks; a request that panics is answered with
//!   `InternalError`.

use std::io::{BufReader, BufWriter, Read, Write};
use std::sync::Arc;
use std::sync::mpsc;
use std::time::Duration;

mod convert;
mod features;
mod queue;
mod server;
#[cfg(test)]
mod tests;
pub mod transport;
mod worlds;

pub use server::MAX_DOCUMENT_BYTES;
pub use transport::MAX_MESSAGE_BYTES;

use queue::{Inbox, Next, Outbox};
use server::{Flow, Log, Server};
use transport::{Frame, FrameReader, Incoming};

/// How a session ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ending {
    /// `exit` after `shutdown`: exit status 0.
    Exit,
    /// `exit` without `shutdown`: exit status 1.
    ExitWithoutShutdown,
    /// The input ended without `exit`: exit status 1.
    InputClosed,
    /// The output could not be written: exit status 1.
    OutputClosed,
}

impl Ending {
    /// Whether the client shut the server down properly (exit status 0).
    pub fn is_clean(self) -> bool {
        self == Ending::Exit
    }
}

/// How long the server waits, after `exit`, for the writer to hand the last messages to
/// a client that does not read them.
const FLUSH_WAIT: Duration = Duration::from_secs(5);

/// Input buffered by the reader: a burst of small messages is read in one go.
const READ_BUFFER: usize = 64 << 10;

/// Runs the server on standard input and output until the client says `exit` or goes
/// away. See [`Ending`] for the exit status.
pub fn run() -> std::io::Result<Ending> {
    serve(std::io::stdin(), std::io::stdout())
}

/// Serves one client: a reader thread decodes `input` into a bounded inbox, this thread
/// runs the server, and a writer thread writes a bounded outbox to `output`. Returns once the client exits or the input ends (the reader thread may be
/// left blocked on `input`). Errors only when a thread cannot start.
pub fn serve<R, W>(input: R, output: W) -> std::io::Result<Ending>
where
    R: Read + Send + 'static,
    W: Write + Send + 'static,
{
    let inbox = Arc::new(Inbox::new(queue::INBOX_BYTES));
    let outbox = Arc::new(Outbox::new(queue::OUTBOX_BYTES));
    {
        let inbox = Arc::clone(&inbox);
        std::thread::Builder::new()
            .name("hstlc-lsp-reader".into())
            .spawn(move || read_loop(input, &inbox))?;
    }
    let (written, writer_done) = mpsc::channel();
    {
        let outbox = Arc::clone(&outbox);
        std::thread::Builder::new().name("hstlc-lsp-writer".into()).spawn(move || {
            if let Err(e) = write_loop(output, &outbox) {
                eprintln!("hstlc lsp: cannot write to the client: {e}; stopping");
                outbox.fail();
            }
            let _ = written.send(());
        })?;
    }
    let mut server = Server::new(Log::stderr());
    let ending = loop {
        if outbox.is_broken() {
            break Ending::OutputClosed;
        }
        match inbox.next(server.has_idle_work()) {
            Next::Message(message) => {
                if let Flow::Exit(ending) = server.handle(message, &mut &*outbox) {
                    break ending;
                }
            }
            Next::Idle => server.idle_step(&mut &*outbox),
            Next::End(problem) => {
                if let Some(problem) = problem {
                    server.log(problem);
                }
                server.log("the client closed the connection without `exit`");
                break Ending::InputClosed;
            }
        }
    };
    inbox.stop();
    outbox.close();
    // The writer ends once everything queued is written, unless the client stopped
    // reading.
    let _ = writer_done.recv_timeout(FLUSH_WAIT);
    let superseded = outbox.superseded();
    if superseded > 0 {
        server.log(format_args!(
            "{superseded} publishDiagnostics replaced by newer ones before the client read them"
        ));
    }
    Ok(ending)
}

/// Reads frames into the inbox until the input ends, the client says `exit` or the
/// server stops.
fn read_loop(input: impl Read, inbox: &Inbox) {
    let mut frames = FrameReader::new(BufReader::with_capacity(READ_BUFFER, input));
    loop {
        let frame = frames.next_frame();
        let bytes = match &frame {
            Frame::Message(body) | Frame::BadHeader { body, .. } => body.len(),
            Frame::Skipped(_) => 0,
            Frame::End(problem) => {
                inbox.close(problem.clone());
                return;
            }
        };
        let Some(message) = Incoming::from_frame(frame) else { continue };
        let exit = message.is_exit();
        let busy = !frames.get_ref().buffer().is_empty();
        if !inbox.push(message, bytes, busy) || exit {
            return;
        }
    }
}

/// Writes the outbox to `output`, flushing whenever it is empty.
fn write_loop(output: impl Write, outbox: &Outbox) -> std::io::Result<()> {
    let mut out = BufWriter::with_capacity(64 << 10, output);
    while let Some(body) = outbox.pop() {
        transport::write_frame(&mut out, &body)?;
        if outbox.is_empty() {
            out.flush()?;
        }
    }
    out.flush()
}

/// Serves a whole session read from `input`, on this thread, and returns what the server
/// wrote (every message, framed, in order) and how the session ended. Logs nothing. It
/// runs the same reader and server as [`serve`], without the threads: the fuzz target
/// `lsp_session` drives it.
pub fn serve_bytes(input: &[u8]) -> (Vec<u8>, Ending) {
    let mut frames = FrameReader::new(input);
    let mut server = Server::new(Log::quiet());
    let mut out = Vec::new();
    loop {
        let frame = frames.next_frame();
        if let Frame::End(_) = frame {
            break;
        }
        let Some(message) = Incoming::from_frame(frame) else { continue };
        if let Flow::Exit(ending) = server.handle(message, &mut out) {
            return (out, ending);
        }
        if frames.get_ref().is_empty() {
            while server.has_idle_work() {
                server.idle_step(&mut out);
            }
        }
    }
    (out, Ending::InputClosed)
}
