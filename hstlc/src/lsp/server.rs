//! The protocol state machine and the open documents, independent of threads and pipes:
//! [`Server::handle`] takes one decoded message and sends what it answers to a
//! [`Sink`]; [`Server::idle_step`] analyses a document whose newest text has not been
//! analysed yet.
//!
//! Documents are analysed lazily: a change only stores the text (dropping the previous
//! unanalysed one), and the newest text is analysed when a request needs it or when the
//! server is idle. So a burst of changes costs one analysis, not one per change.

use std::collections::{BTreeMap, HashMap};
use std::fmt::Display;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;

use lsp_server::ErrorCode;
use lsp_types::notification::{
    DidChangeTextDocument, DidChangeWatchedFiles, DidCloseTextDocument, DidOpenTextDocument,
    Notification as _, PublishDiagnostics,
};
use lsp_types::request::{
    Completion, DocumentSymbolRequest, Formatting, GotoDefinition, HoverRequest, References,
    Request as _,
};
use lsp_types::{
    InitializeParams, PositionEncodingKind, PublishDiagnosticsParams, ServerCapabilities,
    TextDocumentSyncCapability, TextDocumentSyncKind, Uri,
};
use serde::Serialize;
use serde_json::Value;

use super::Ending;
use super::convert::Encoding;
use super::features::{self, Analysis, Leftovers};
use super::queue::{Outgoing, Sink};
use super::transport::{Id, Incoming};
use super::worlds::{path_uri, uri_path};
use hstl_ide::worlds::WorldCache;

/// Largest document analysed (4 MiB): a larger one is kept open, but gets no
/// diagnostics or answers, and the client is told once why.
pub const MAX_DOCUMENT_BYTES: usize = 4 << 20;

/// Most text, in bytes, of the documents kept analysed at once (16 MiB): an analysis takes
/// tens of bytes a byte of text, so a client that opens many large documents would grow
/// the server without bound (12 documents took 3.3 GB). Past it, the analyses used least
/// recently are dropped, their text kept, and made again when a request needs one.
pub const MAX_ANALYSED_BYTES: usize = 16 << 20;

/// Most text, in bytes, of every open document together (256 MiB): past it, a document's
/// text is not kept, and the client is told why, as for one too large to analyse.
pub const MAX_OPEN_BYTES: usize = 256 << 20;

/// Most lines the server logs about bad input; the rest are counted, not printed.
const MAX_LOG_LINES: u64 = 1000;

/// Where the protocol is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Phase {
    /// Before `initialize`: requests get `ServerNotInitialized`.
    Uninitialized,
    /// After `initialize`.
    Running,
    /// After `shutdown`: requests get `InvalidRequest`; only `exit` acts.
    ShutDown,
}

/// What the caller does after a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Flow {
    /// Go on.
    Continue,
    /// The client said `exit`.
    Exit(Ending),
}

/// What is known of one version of a document.
enum State {
    /// Nothing analysed yet.
    Unanalysed,
    /// The analysis of a text.
    Analysed(Box<Analysis>),
    /// Too large to analyse (its size in bytes).
    TooLarge(usize),
    /// Analysis failed with an internal error.
    Failed,
    /// Not kept: the open documents' text passed [`MAX_OPEN_BYTES`] (its size in bytes).
    NotKept(usize),
}

struct Document {
    version: i32,
    /// The newest text, when it is newer than `state`.
    pending: Option<String>,
    /// Its key in `Server::stale` while `pending` is set.
    queued: Option<u64>,
    state: State,
    /// When its analysis was last made or read (`Server::clock`).
    used: u64,
}

impl Document {
    /// The bytes of text it keeps.
    fn text_bytes(&self) -> usize {
        let analysed = match &self.state {
            State::Analysed(a) => a.text.len(),
            _ => 0,
        };
        analysed + self.pending.as_ref().map_or(0, String::len)
    }
}

/// Log lines, to standard error or nowhere (the fuzz targets), at most
/// [`MAX_LOG_LINES`] of them.
pub struct Log {
    to_stderr: bool,
    lines: u64,
}

impl Log {
    /// Logs to standard error.
    pub fn stderr() -> Self {
        Log { to_stderr: true, lines: 0 }
    }

    /// Logs nothing.
    pub fn quiet() -> Self {
        Log { to_stderr: false, lines: 0 }
    }

    /// One line, prefixed with `hstlc lsp: `.
    pub fn line(&mut self, message: impl Display) {
        self.lines += 1;
        if !self.to_stderr || self.lines > MAX_LOG_LINES + 1 {
            return;
        }
        if self.lines == MAX_LOG_LINES + 1 {
            eprintln!("hstlc lsp: more than {MAX_LOG_LINES} problems; the rest are not logged");
        } else {
            eprintln!("hstlc lsp: {message}");
        }
    }
}

/// The server: the protocol phase, the negotiated position encoding and the open
/// documents.
pub struct Server {
    phase: Phase,
    encoding: Encoding,
    documents: HashMap<Uri, Document>,
    /// The documents with a text not analysed yet, in the order they got it (keyed by
    /// `Document::queued`): the idle work, found without a scan of every document.
    stale: BTreeMap<u64, Uri>,
    next_stale: u64,
    /// What is left of replaced analyses, dropped once the diagnostics are queued.
    trash: Vec<Leftovers>,
    /// The world files documents name, read once each.
    worlds: WorldCache,
    log: Log,
    /// Counts analyses made and read, for [`Document::used`].
    clock: u64,
    /// [`MAX_ANALYSED_BYTES`] (smaller in tests).
    analysed_budget: usize,
}

type Answer = Result<Vec<u8>, (ErrorCode, String)>;

impl Server {
    /// A server waiting for `initialize`.
    pub fn new(log: Log) -> Self {
        Server {
            phase: Phase::Uninitialized,
            encoding: Encoding::Utf16,
            documents: HashMap::new(),
            stale: BTreeMap::new(),
            next_stale: 0,
            trash: Vec::new(),
            worlds: super::worlds::cache(),
            log,
            clock: 0,
            analysed_budget: MAX_ANALYSED_BYTES,
        }
    }

    /// A server that keeps at most `bytes` of text analysed (for tests).
    #[cfg(test)]
    pub(crate) fn with_analysed_budget(log: Log, bytes: usize) -> Self {
        Server { analysed_budget: bytes, ..Server::new(log) }
    }

    /// Logs one line.
    pub fn log(&mut self, message: impl Display) {
        self.log.line(message);
    }

    /// Handles one message; never panics (an internal error becomes an error response).
    pub fn handle(&mut self, message: Incoming, out: &mut impl Sink) -> Flow {
        match message {
            Incoming::Request { id, method, params } => {
                let body = self.request(&id, &method, params, out);
                out.send(Outgoing::Message(body));
            }
            Incoming::Notification { method, params } => {
                if method == "exit" {
                    return Flow::Exit(if self.phase == Phase::ShutDown {
                        Ending::Exit
                    } else {
                        self.log("exit without shutdown");
                        Ending::ExitWithoutShutdown
                    });
                }
                self.notification(&method, params, out);
            }
            Incoming::Response => {}
            Incoming::Invalid { id, code, message } => {
                match &id {
                    Some(id) => self.log(format_args!("request {id}: {message}")),
                    None => self.log(&message),
                }
                if let Some(id) = id {
                    out.send(Outgoing::Message(error_body(&id, code, &message)));
                }
            }
        }
        Flow::Continue
    }

    /// Whether a document may have a text that is not analysed yet.
    pub fn has_idle_work(&self) -> bool {
        !self.stale.is_empty()
    }

    /// Analyses the next document with a newer text (if it still has one) and publishes
    /// its diagnostics.
    pub fn idle_step(&mut self, out: &mut impl Sink) {
        if let Some((_, uri)) = self.stale.pop_first() {
            self.analyse(&uri, out);
        }
    }

    fn request(&mut self, id: &Id, method: &str, params: Value, out: &mut impl Sink) -> Vec<u8> {
        let answer = match (self.phase, method) {
            (Phase::Uninitialized, "initialize") => self.initialize(id, params),
            (Phase::Uninitialized, _) => Err((
                ErrorCode::ServerNotInitialized,
                format!("`{}` before `initialize`: the server is not initialized", short(method)),
            )),
            (Phase::Running, "initialize") => {
                Err((ErrorCode::InvalidRequest, "the server is already initialized".into()))
            }
            (Phase::Running, "shutdown") => {
                self.phase = Phase::ShutDown;
                reply(id, &Value::Null)
            }
            (Phase::ShutDown, _) => Err((
                ErrorCode::InvalidRequest,
                format!("`{}` after `shutdown`: only `exit` is accepted", short(method)),
            )),
            (Phase::Running, _) => {
                match catch_unwind(AssertUnwindSafe(|| self.dispatch(id, method, params, out))) {
                    Ok(answer) => answer,
                    Err(_) => Err((
                        ErrorCode::InternalError,
                        format!("internal error in {}", short(method)),
                    )),
                }
            }
        };
        match answer {
            Ok(body) => body,
            Err((code, message)) => {
                self.log(format_args!("{} (request {id}): {message}", short(method)));
                error_body(id, code, &message)
            }
        }
    }

    fn initialize(&mut self, id: &Id, params: Value) -> Answer {
        let params: InitializeParams = serde_json::from_value(params).unwrap_or_else(|e| {
            self.log(format_args!("initialize: {e}; using default client capabilities"));
            InitializeParams::default()
        });
        self.encoding = negotiate_encoding(&params);
        let capabilities = ServerCapabilities {
            position_encoding: Some(match self.encoding {
                Encoding::Utf8 => PositionEncodingKind::UTF8,
                Encoding::Utf16 => PositionEncodingKind::UTF16,
            }),
            text_document_sync: Some(TextDocumentSyncCapability::Kind(TextDocumentSyncKind::FULL)),
            hover_provider: Some(true.into()),
            definition_provider: Some(lsp_types::OneOf::Left(true)),
            references_provider: Some(lsp_types::OneOf::Left(true)),
            document_symbol_provider: Some(lsp_types::OneOf::Left(true)),
            document_formatting_provider: Some(lsp_types::OneOf::Left(true)),
            completion_provider: Some(lsp_types::CompletionOptions::default()),
            ..ServerCapabilities::default()
        };
        self.phase = Phase::Running;
        reply(
            id,
            &serde_json::json!({
                "capabilities": capabilities,
                "serverInfo": { "name": "hstlc", "version": env!("CARGO_PKG_VERSION") },
            }),
        )
    }

    /// The analysis of the newest text of `uri`, analysing it first if needed.
    fn document(
        &mut self,
        uri: &Uri,
        out: &mut impl Sink,
    ) -> Result<&Analysis, (ErrorCode, String)> {
        if self.documents.get(uri).is_some_and(|d| d.pending.is_some()) {
            self.analyse(uri, out);
        }
        self.clock += 1;
        let clock = self.clock;
        let Some(doc) = self.documents.get_mut(uri) else {
            return Err((
                ErrorCode::InvalidParams,
                format!("document `{}` is not open", short(uri.as_str())),
            ));
        };
        doc.used = clock;
        let doc = &*doc;
        match &doc.state {
            State::Analysed(a) => Ok(&**a),
            State::TooLarge(n) => Err((ErrorCode::RequestFailed, too_large(uri, *n))),
            State::NotKept(n) => Err((ErrorCode::RequestFailed, not_kept(uri, *n))),
            State::Failed => Err((
                ErrorCode::InternalError,
                format!("internal error while checking `{}`", short(uri.as_str())),
            )),
            State::Unanalysed => Err((
                ErrorCode::InternalError,
                format!("document `{}` is not analysed", short(uri.as_str())),
            )),
        }
    }

    fn dispatch(&mut self, id: &Id, method: &str, params: Value, out: &mut impl Sink) -> Answer {
        match method {
            HoverRequest::METHOD => {
                let p: lsp_types::HoverParams = parse(params)?;
                let pos = p.text_document_position_params;
                let doc = self.document(&pos.text_document.uri, out)?;
                reply(id, &features::hover(doc, pos.position))
            }
            GotoDefinition::METHOD => {
                let p: lsp_types::GotoDefinitionParams = parse(params)?;
                let pos = p.text_document_position_params;
                let doc = self.document(&pos.text_document.uri, out)?;
                let uri = pos.text_document.uri.clone();
                let location = match features::definition(doc, pos.position) {
                    Some(features::Target::Here(range)) => Some(lsp_types::Location { uri, range }),
                    Some(features::Target::File(path)) => path_uri(&path)
                        .map(|uri| lsp_types::Location { uri, range: lsp_types::Range::default() }),
                    None => None,
                };
                reply(id, &location)
            }
            References::METHOD => {
                let p: lsp_types::ReferenceParams = parse(params)?;
                let pos = p.text_document_position;
                let doc = self.document(&pos.text_document.uri, out)?;
                let refs: Vec<lsp_types::Location> =
                    features::references(doc, pos.position, p.context.include_declaration)
                        .into_iter()
                        .map(|range| lsp_types::Location {
                            uri: pos.text_document.uri.clone(),
                            range,
                        })
                        .collect();
                reply(id, &refs)
            }
            DocumentSymbolRequest::METHOD => {
                let p: lsp_types::DocumentSymbolParams = parse(params)?;
                let doc = self.document(&p.text_document.uri, out)?;
                reply(id, &lsp_types::DocumentSymbolResponse::Nested(features::symbols(doc)))
            }
            Completion::METHOD => {
                let p: lsp_types::CompletionParams = parse(params)?;
                let pos = p.text_document_position;
                let doc = self.document(&pos.text_document.uri, out)?;
                let items = features::completion(doc, pos.position);
                reply(id, &lsp_types::CompletionResponse::Array(items))
            }
            Formatting::METHOD => {
                let p: lsp_types::DocumentFormattingParams = parse(params)?;
                let doc = self.document(&p.text_document.uri, out)?;
                let edits = features::format(doc).map_err(|e| (ErrorCode::RequestFailed, e))?;
                reply(id, &edits)
            }
            // Lets the tests reach the internal-error path.
            #[cfg(test)]
            "hstlc/testPanic" => panic!("a deliberate panic"),
            _ => {
                Err((ErrorCode::MethodNotFound, format!("unsupported request `{}`", short(method))))
            }
        }
    }

    fn notification(&mut self, method: &str, params: Value, out: &mut impl Sink) {
        match self.phase {
            Phase::Running => {}
            Phase::Uninitialized => {
                return self.log(format_args!("`{}` before `initialize`: ignored", short(method)));
            }
            Phase::ShutDown => {
                return self.log(format_args!("`{}` after `shutdown`: ignored", short(method)));
            }
        }
        let result = catch_unwind(AssertUnwindSafe(|| self.apply(method, params, out)));
        match result {
            Ok(Ok(())) => {}
            Ok(Err(e)) => self.log(format_args!("{}: {e}", short(method))),
            Err(_) => self.log(format_args!("internal error while handling {}", short(method))),
        }
    }

    /// Applies a document notification; the text is analysed later (see the module docs).
    fn apply(&mut self, method: &str, params: Value, out: &mut impl Sink) -> Result<(), String> {
        match method {
            DidOpenTextDocument::METHOD => {
                let p: lsp_types::DidOpenTextDocumentParams =
                    serde_json::from_value(params).map_err(|e| e.to_string())?;
                let doc = p.text_document;
                self.store(doc.uri, doc.version, doc.text);
            }
            DidChangeTextDocument::METHOD => {
                let p: lsp_types::DidChangeTextDocumentParams =
                    serde_json::from_value(params).map_err(|e| e.to_string())?;
                // Full synchronisation: the last change holds the whole text.
                let Some(change) = p.content_changes.into_iter().last() else {
                    return Ok(());
                };
                if change.range.is_some() {
                    return Err("only full-document changes are supported".into());
                }
                self.store(p.text_document.uri, p.text_document.version, change.text);
            }
            DidChangeWatchedFiles::METHOD => {
                // A world file may have changed: documents that read one are checked again.
                let reread: Vec<Uri> = self
                    .documents
                    .iter()
                    .filter(|(_, d)| {
                        d.pending.is_none()
                            && matches!(&d.state, State::Analysed(a) if a.worlds.has_files())
                    })
                    .map(|(u, _)| u.clone())
                    .collect();
                for uri in reread {
                    let Some(doc) = self.documents.get(&uri) else { continue };
                    let State::Analysed(a) = &doc.state else { continue };
                    let (version, text) = (doc.version, a.text.clone());
                    self.store(uri, version, text);
                }
            }
            DidCloseTextDocument::METHOD => {
                let p: lsp_types::DidCloseTextDocumentParams =
                    serde_json::from_value(params).map_err(|e| e.to_string())?;
                let uri = p.text_document.uri;
                if let Some(doc) = self.documents.remove(&uri) {
                    if let Some(key) = doc.queued {
                        self.stale.remove(&key);
                    }
                    self.discard(doc.state);
                }
                out.send(publish(&uri, None, Vec::new()));
                self.trash.clear();
            }
            _ => {}
        }
        Ok(())
    }

    /// Stores a newer text, replacing one that was never analysed.
    fn store(&mut self, uri: Uri, version: i32, text: String) {
        // The text the other documents keep: with this one past the limit, it is not kept.
        let others: usize = self
            .documents
            .iter()
            .filter(|(u, _)| **u != uri)
            .map(|(_, d)| d.text_bytes())
            .fold(0, usize::saturating_add);
        let doc = self.documents.entry(uri.clone()).or_insert(Document {
            version,
            pending: None,
            queued: None,
            state: State::Unanalysed,
            used: 0,
        });
        doc.version = version;
        if others.saturating_add(text.len()) > MAX_OPEN_BYTES {
            let bytes = text.len();
            drop(text);
            doc.pending = None;
            if let Some(key) = doc.queued.take() {
                self.stale.remove(&key);
            }
            let was = std::mem::replace(&mut doc.state, State::NotKept(bytes));
            if !matches!(was, State::NotKept(_)) {
                let message = not_kept(&uri, bytes);
                self.log(&message);
            }
            self.discard(was);
            self.trash.clear();
            return;
        }
        doc.pending = Some(text);
        if doc.queued.is_none() {
            doc.queued = Some(self.next_stale);
            self.stale.insert(self.next_stale, uri);
            self.next_stale += 1;
        }
    }

    fn discard(&mut self, state: State) {
        if let State::Analysed(a) = state {
            self.trash.push(a.into_leftovers());
        }
    }

    /// Analyses the newest text of `uri` and publishes its diagnostics.
    fn analyse(&mut self, uri: &Uri, out: &mut impl Sink) {
        let Some(doc) = self.documents.get_mut(uri) else { return };
        if let Some(key) = doc.queued.take() {
            self.stale.remove(&key);
        }
        let Some(text) = doc.pending.take() else { return };
        let version = doc.version;
        let prev = std::mem::replace(&mut doc.state, State::Unanalysed);
        let was_too_large = matches!(prev, State::TooLarge(_));
        let encoding = self.encoding;
        let next = if text.len() > MAX_DOCUMENT_BYTES {
            self.discard(prev);
            if !was_too_large {
                let message = too_large(uri, text.len());
                self.log(&message);
                out.send(Outgoing::Message(show_message(&message)));
            }
            State::TooLarge(text.len())
        } else {
            let trash = &mut self.trash;
            let worlds = &mut self.worlds;
            let path = uri_path(uri);
            let folder = path.as_deref().and_then(Path::parent);
            let analysed = catch_unwind(AssertUnwindSafe(|| match prev {
                State::Analysed(prev) => {
                    let (next, leftovers) = Analysis::update(*prev, text, encoding, worlds, folder);
                    trash.push(leftovers);
                    next
                }
                _ => Analysis::new(text, encoding, worlds, folder),
            }));
            match analysed {
                Ok(a) => State::Analysed(Box::new(a)),
                Err(_) => {
                    self.log(format_args!("internal error while checking {}", short(uri.as_str())));
                    State::Failed
                }
            }
        };
        let diagnostics = match &next {
            State::Analysed(a) => features::diagnostics(a, uri),
            _ => Vec::new(),
        };
        self.clock += 1;
        let clock = self.clock;
        if let Some(doc) = self.documents.get_mut(uri) {
            doc.state = next;
            doc.used = clock;
        }
        out.send(publish(uri, Some(version), diagnostics));
        self.evict(uri);
        // Free the previous versions once the diagnostics are on their way.
        self.trash.clear();
    }

    /// Drops the analyses used least recently, other than `keep`'s, until the analysed
    /// text is within [`MAX_ANALYSED_BYTES`]; their text is kept, to be analysed again
    /// when a request needs it.
    fn evict(&mut self, keep: &Uri) {
        let mut analysed: Vec<(u64, usize, Uri)> = self
            .documents
            .iter()
            .filter_map(|(u, d)| match &d.state {
                State::Analysed(a) => Some((d.used, a.text.len(), u.clone())),
                _ => None,
            })
            .collect();
        let mut total: usize = analysed.iter().map(|a| a.1).fold(0, usize::saturating_add);
        if total <= self.analysed_budget {
            return;
        }
        analysed.sort_unstable_by_key(|a| a.0);
        for (_, bytes, uri) in analysed {
            if total <= self.analysed_budget {
                break;
            }
            if &uri == keep {
                continue;
            }
            let Some(doc) = self.documents.get_mut(&uri) else { continue };
            if let State::Analysed(mut a) = std::mem::replace(&mut doc.state, State::Unanalysed) {
                // A newer text, if any, is the one to analyse next time.
                let text = std::mem::take(&mut a.text);
                doc.pending.get_or_insert(text);
                self.trash.push(a.into_leftovers());
                total -= bytes;
            }
        }
    }

    /// How many documents are analysed now, and their text's bytes (for tests).
    #[cfg(test)]
    pub(crate) fn analysed(&self) -> (usize, usize) {
        let texts = self.documents.values().filter_map(|d| match &d.state {
            State::Analysed(a) => Some(a.text.len()),
            _ => None,
        });
        texts.fold((0, 0), |(n, b), t| (n + 1, b + t))
    }
}

fn not_kept(uri: &Uri, bytes: usize) -> String {
    format!(
        "`{}` ({bytes} bytes) is not kept: the open documents hold more than the {} MiB of text the language server keeps; close some, or check it with `hstlc check`",
        short(uri.as_str()),
        MAX_OPEN_BYTES >> 20
    )
}

fn too_large(uri: &Uri, bytes: usize) -> String {
    format!(
        "`{}` has {bytes} bytes, more than the {} MiB the language server analyses; check it with `hstlc check`",
        short(uri.as_str()),
        MAX_DOCUMENT_BYTES >> 20
    )
}

/// At most 200 characters of a name the client chose, for messages and logs.
fn short(s: &str) -> String {
    match s.char_indices().nth(200) {
        Some((i, _)) => format!("{}...", &s[..i]),
        None => s.to_string(),
    }
}

#[derive(Serialize)]
struct ResponseOk<'a, T> {
    jsonrpc: &'static str,
    id: Value,
    result: &'a T,
}

#[derive(Serialize)]
struct ResponseErr<'a> {
    jsonrpc: &'static str,
    id: Value,
    error: ErrorBody<'a>,
}

#[derive(Serialize)]
struct ErrorBody<'a> {
    code: i32,
    message: &'a str,
}

#[derive(Serialize)]
struct NotificationOut<'a, T> {
    jsonrpc: &'static str,
    method: &'a str,
    params: T,
}

/// A response, serialised straight from the typed result (no JSON tree in between).
fn reply<T: Serialize>(id: &Id, result: &T) -> Answer {
    serde_json::to_vec(&ResponseOk { jsonrpc: "2.0", id: id.to_json(), result })
        .map_err(|e| (ErrorCode::InternalError, e.to_string()))
}

fn error_body(id: &Id, code: ErrorCode, message: &str) -> Vec<u8> {
    let response = ResponseErr {
        jsonrpc: "2.0",
        id: id.to_json(),
        error: ErrorBody { code: code as i32, message },
    };
    // Strings and numbers always serialise.
    serde_json::to_vec(&response).unwrap_or_default()
}

fn notification<T: Serialize>(method: &str, params: T) -> Vec<u8> {
    serde_json::to_vec(&NotificationOut { jsonrpc: "2.0", method, params }).unwrap_or_default()
}

fn publish(uri: &Uri, version: Option<i32>, diagnostics: Vec<lsp_types::Diagnostic>) -> Outgoing {
    let params = PublishDiagnosticsParams { uri: uri.clone(), diagnostics, version };
    Outgoing::Diagnostics {
        uri: uri.as_str().to_string(),
        body: notification(PublishDiagnostics::METHOD, params),
    }
}

fn show_message(message: &str) -> Vec<u8> {
    let params = lsp_types::ShowMessageParams {
        typ: lsp_types::MessageType::WARNING,
        message: format!("hstlc: {message}"),
    };
    notification("window/showMessage", params)
}

fn parse<T: serde::de::DeserializeOwned>(params: Value) -> Result<T, (ErrorCode, String)> {
    serde_json::from_value(params)
        .map_err(|e| (ErrorCode::InvalidParams, format!("invalid parameters: {e}")))
}

/// UTF-8 when the client offers it (no conversion needed), else the protocol's UTF-16.
fn negotiate_encoding(params: &InitializeParams) -> Encoding {
    let offered = params.capabilities.general.as_ref().and_then(|g| g.position_encodings.as_ref());
    match offered {
        Some(kinds) if kinds.contains(&PositionEncodingKind::UTF8) => Encoding::Utf8,
        _ => Encoding::Utf16,
    }
}
