//! The two queues between the threads of the server, both bounded.
//!
//! [`Inbox`]: decoded messages from the reader to the server, at most [`INBOX_BYTES`] of
//! message bodies (the reader waits when it is full, so a client that writes faster than
//! the server works is held back by its own pipe). It also tells the server whether the
//! reader holds more input than it has handed over, so that the server analyses a
//! document only once a burst of changes is over.
//!
//! [`Outbox`]: serialised messages from the server to the writer, at most
//! [`OUTBOX_BYTES`]: the server waits when a client reads slowly. Diagnostics are not
//! queued one per version: a document has at most one `publishDiagnostics` waiting, and a
//! newer one replaces it (the client only ever needs the newest).

use std::collections::{HashMap, VecDeque};
use std::sync::{Condvar, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use super::transport::{Incoming, Problem};

/// Most bytes of message bodies waiting for the server (64 MiB; one message larger than
/// what is left is still taken when the queue is empty).
pub const INBOX_BYTES: usize = 64 << 20;

/// Most bytes of serialised messages waiting for the client (16 MiB; one larger message
/// is still taken when the queue is empty).
pub const OUTBOX_BYTES: usize = 16 << 20;

/// How long the server waits for a reader that holds part of a message before it does
/// its idle work anyway.
const IDLE_GRACE: Duration = Duration::from_millis(100);

/// What the server does next.
#[derive(Debug)]
pub enum Next {
    /// Handle this message.
    Message(Incoming),
    /// Nothing to handle and the reader is waiting for input: do the idle work.
    Idle,
    /// The input is over (`Some`: how it ended badly).
    End(Option<Problem>),
}

/// Messages from the reader to the server.
pub struct Inbox {
    state: Mutex<InboxState>,
    changed: Condvar,
    budget: usize,
}

struct InboxState {
    queue: VecDeque<(Incoming, usize)>,
    bytes: usize,
    /// The reader had more input buffered when it handed over the last message.
    reader_busy: bool,
    end: Option<Option<Problem>>,
    server_gone: bool,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Inbox {
    /// An empty inbox holding at most `budget` bytes of messages.
    pub fn new(budget: usize) -> Self {
        let state = InboxState {
            queue: VecDeque::new(),
            bytes: 0,
            reader_busy: false,
            end: None,
            server_gone: false,
        };
        Inbox { state: Mutex::new(state), changed: Condvar::new(), budget }
    }

    /// Hands a message of `bytes` over, waiting while the inbox is full. `busy`: more
    /// input is already buffered. `false` when the server has stopped.
    pub fn push(&self, message: Incoming, bytes: usize, busy: bool) -> bool {
        let mut s = lock(&self.state);
        while !s.server_gone && !s.queue.is_empty() && s.bytes + bytes > self.budget {
            s = self.changed.wait(s).unwrap_or_else(PoisonError::into_inner);
        }
        if s.server_gone {
            return false;
        }
        s.queue.push_back((message, bytes));
        s.bytes += bytes;
        s.reader_busy = busy;
        self.changed.notify_all();
        true
    }

    /// The input is over; the server gets [`Next::End`] once the queue is empty.
    pub fn close(&self, problem: Option<Problem>) {
        let mut s = lock(&self.state);
        s.end = Some(problem);
        self.changed.notify_all();
    }

    /// The server has stopped: the reader's next [`Inbox::push`] returns `false`.
    pub fn stop(&self) {
        let mut s = lock(&self.state);
        s.server_gone = true;
        s.queue.clear();
        self.changed.notify_all();
    }

    /// The next thing for the server to do; waits for a message unless `idle_work` is
    /// pending and the reader holds no more input.
    pub fn next(&self, idle_work: bool) -> Next {
        let mut s = lock(&self.state);
        loop {
            if let Some((message, bytes)) = s.queue.pop_front() {
                s.bytes -= bytes;
                self.changed.notify_all();
                return Next::Message(message);
            }
            if let Some(end) = s.end.take() {
                return Next::End(end);
            }
            if idle_work && !s.reader_busy {
                return Next::Idle;
            }
            if idle_work {
                let (guard, wait) = self
                    .changed
                    .wait_timeout(s, IDLE_GRACE)
                    .unwrap_or_else(PoisonError::into_inner);
                s = guard;
                if wait.timed_out() && s.queue.is_empty() {
                    s.reader_busy = false;
                }
            } else {
                s = self.changed.wait(s).unwrap_or_else(PoisonError::into_inner);
            }
        }
    }
}

/// A message for the client, serialised (the body of one frame).
#[derive(Debug, PartialEq, Eq)]
pub enum Outgoing {
    /// A response or a notification, sent in order.
    Message(Vec<u8>),
    /// A `publishDiagnostics` for the document `uri`, which replaces a waiting one.
    Diagnostics {
        /// The document.
        uri: String,
        /// The notification.
        body: Vec<u8>,
    },
}

/// Where the server sends messages.
pub trait Sink {
    /// Queues (or writes) one message.
    fn send(&mut self, message: Outgoing);
}

/// A session written whole into memory (for the fuzz targets and tests): every message
/// in order, framed, none replaced.
impl Sink for Vec<u8> {
    fn send(&mut self, message: Outgoing) {
        let body = match message {
            Outgoing::Message(body) | Outgoing::Diagnostics { body, .. } => body,
        };
        // Writing into a `Vec` cannot fail.
        let _ = super::transport::write_frame(self, &body);
    }
}

/// Messages from the server to the writer.
pub struct Outbox {
    state: Mutex<OutboxState>,
    changed: Condvar,
    budget: usize,
}

enum Slot {
    Message(Vec<u8>),
    /// The waiting diagnostics of this document (in `OutboxState::diagnostics`).
    Diagnostics(String),
}

struct OutboxState {
    queue: VecDeque<Slot>,
    diagnostics: HashMap<String, Vec<u8>>,
    bytes: usize,
    closed: bool,
    broken: bool,
    superseded: u64,
}

impl Outbox {
    /// An empty outbox holding at most `budget` bytes.
    pub fn new(budget: usize) -> Self {
        let state = OutboxState {
            queue: VecDeque::new(),
            diagnostics: HashMap::new(),
            bytes: 0,
            closed: false,
            broken: false,
            superseded: 0,
        };
        Outbox { state: Mutex::new(state), changed: Condvar::new(), budget }
    }

    /// Queues a message, waiting while the queue is full. Diagnostics replace the waiting
    /// ones of their document and never wait (there is at most one per open document).
    /// Dropped once the output is broken.
    pub fn push(&self, message: Outgoing) {
        let mut s = lock(&self.state);
        match message {
            Outgoing::Message(body) => {
                while !s.broken && s.bytes > 0 && s.bytes + body.len() > self.budget {
                    s = self.changed.wait(s).unwrap_or_else(PoisonError::into_inner);
                }
                if s.broken {
                    return;
                }
                s.bytes += body.len();
                s.queue.push_back(Slot::Message(body));
            }
            Outgoing::Diagnostics { uri, body } => {
                if s.broken {
                    return;
                }
                let added = body.len();
                match s.diagnostics.get_mut(&uri) {
                    Some(waiting) => {
                        let removed = std::mem::replace(waiting, body).len();
                        s.bytes = s.bytes - removed + added;
                        s.superseded += 1;
                    }
                    None => {
                        s.diagnostics.insert(uri.clone(), body);
                        s.bytes += added;
                        s.queue.push_back(Slot::Diagnostics(uri));
                    }
                }
            }
        }
        self.changed.notify_all();
    }

    /// The next message to write, waiting for one; `None` once the outbox is closed and
    /// empty, or broken.
    pub fn pop(&self) -> Option<Vec<u8>> {
        let mut s = lock(&self.state);
        loop {
            if s.broken {
                return None;
            }
            while let Some(slot) = s.queue.pop_front() {
                let body = match slot {
                    Slot::Message(body) => body,
                    Slot::Diagnostics(uri) => match s.diagnostics.remove(&uri) {
                        Some(body) => body,
                        None => continue,
                    },
                };
                s.bytes -= body.len();
                self.changed.notify_all();
                return Some(body);
            }
            if s.closed {
                return None;
            }
            s = self.changed.wait(s).unwrap_or_else(PoisonError::into_inner);
        }
    }

    /// Whether nothing is waiting (the writer flushes then).
    pub fn is_empty(&self) -> bool {
        lock(&self.state).queue.is_empty()
    }

    /// No more messages will come; the writer stops once the queue is written.
    pub fn close(&self) {
        lock(&self.state).closed = true;
        self.changed.notify_all();
    }

    /// The output cannot be written: drop everything, and whatever comes later.
    pub fn fail(&self) {
        let mut s = lock(&self.state);
        s.broken = true;
        s.queue.clear();
        s.diagnostics.clear();
        s.bytes = 0;
        self.changed.notify_all();
    }

    /// Whether the output has failed.
    pub fn is_broken(&self) -> bool {
        lock(&self.state).broken
    }

    /// How many waiting `publishDiagnostics` were replaced by newer ones.
    pub fn superseded(&self) -> u64 {
        lock(&self.state).superseded
    }
}

impl Sink for &Outbox {
    fn send(&mut self, message: Outgoing) {
        self.push(message);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn diags(uri: &str, v: u8) -> Outgoing {
        Outgoing::Diagnostics { uri: uri.into(), body: vec![v; 3] }
    }

    /// Pushes `messages` (no writer running), closes, and pops everything.
    fn check(messages: Vec<Outgoing>, expect: &[Vec<u8>], superseded: u64) {
        let out = Outbox::new(1 << 20);
        for m in messages {
            out.push(m);
        }
        out.close();
        let got: Vec<Vec<u8>> = std::iter::from_fn(|| out.pop()).collect();
        assert_eq!(got, expect);
        assert_eq!(out.superseded(), superseded);
    }

    #[test]
    fn newer_diagnostics_replace_waiting_ones_in_place() {
        let m = |b: u8| Outgoing::Message(vec![b]);
        check(vec![m(1), m(2)], &[vec![1], vec![2]], 0);
        // Three versions of `a` while the client reads nothing: the newest is written,
        // where the first was queued; `b` keeps its own.
        check(
            vec![diags("a", 1), m(9), diags("b", 5), diags("a", 2), diags("a", 3)],
            &[vec![3; 3], vec![9], vec![5; 3]],
            2,
        );
    }

    #[test]
    fn a_full_outbox_holds_the_server_until_the_writer_takes_a_message() {
        let out = std::sync::Arc::new(Outbox::new(10));
        out.push(Outgoing::Message(vec![0; 8]));
        let pusher = {
            let out = std::sync::Arc::clone(&out);
            // 8 + 8 > 10: waits until the first message is taken.
            std::thread::spawn(move || out.push(Outgoing::Message(vec![1; 8])))
        };
        assert_eq!(out.pop(), Some(vec![0; 8]));
        pusher.join().expect("the pusher ends once there is room");
        assert_eq!(out.pop(), Some(vec![1; 8]));
        // A broken output drops what comes and never waits.
        out.fail();
        out.push(Outgoing::Message(vec![2; 100]));
        assert_eq!(out.pop(), None);
    }

    #[test]
    fn the_inbox_reports_idle_only_when_the_reader_has_nothing_buffered() {
        let inbox = Inbox::new(1 << 20);
        let note =
            |m: &str| Incoming::Notification { method: m.into(), params: Default::default() };
        assert!(inbox.push(note("a"), 10, true));
        assert!(matches!(inbox.next(true), Next::Message(_)));
        assert!(inbox.push(note("b"), 10, false));
        assert!(matches!(inbox.next(true), Next::Message(_)));
        assert!(matches!(inbox.next(true), Next::Idle));
        inbox.close(None);
        assert!(matches!(inbox.next(false), Next::End(None)));
        inbox.stop();
        assert!(!inbox.push(note("c"), 10, false));
    }
}
