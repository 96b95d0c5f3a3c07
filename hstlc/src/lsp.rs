//! `hstlc lsp`: a synchronous Language Server on standard input and output.
//!
//! Diagnostics are exactly those of `hstlc check`, published on open and on every change
//! and cleared on close. Documents are synchronised in full; each version is checked once
//! and the result ([`features::Analysis`]) answers hover, definition, references,
//! document symbols, completion and formatting. Positions use UTF-8 when the client
//! offers it, else UTF-16. A malformed request or an internal error is answered with an
//! error response and logged to standard error; the server goes on.

use std::collections::HashMap;
use std::panic::{AssertUnwindSafe, catch_unwind};

use std::io::{BufRead, Write as _};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use lsp_server::{Connection, ErrorCode, Message, Notification, Request, RequestId, Response};
use lsp_types::notification::{
    DidChangeTextDocument, DidCloseTextDocument, DidOpenTextDocument, Notification as _,
    PublishDiagnostics,
};
use lsp_types::request::{
    Completion, DocumentSymbolRequest, Formatting, GotoDefinition, HoverRequest, References,
    Request as _,
};
use lsp_types::{
    InitializeParams, PositionEncodingKind, PublishDiagnosticsParams, ServerCapabilities,
    TextDocumentSyncCapability, TextDocumentSyncKind, Uri,
};
use serde_json::Value;

use crate::cli_error::CliError;
use crate::{CmdResult, Status};

mod convert;
mod features;
#[cfg(test)]
mod tests;

use convert::Encoding;
use features::Analysis;

/// Runs the server on standard input and output until the client says `exit`. Exit
/// status 0 after `shutdown` then `exit`, 1 when the client exits without `shutdown` or
/// goes away.
pub fn run() -> CmdResult {
    let (server, client) = Connection::memory();
    let Connection { sender: to_server, receiver: from_server } = client;
    let inject = server.sender.clone();
    // The reader may keep a sender alive (blocked on standard input), so the writer stops
    // on this flag once everything sent before it is written.
    let done = Arc::new(AtomicBool::new(false));
    let writer_done = Arc::clone(&done);
    let writer = std::thread::spawn(move || {
        let stdout = std::io::stdout();
        loop {
            match from_server.recv_timeout(Duration::from_millis(20)) {
                Ok(message) => {
                    let mut out = stdout.lock();
                    if message.write(&mut out).and_then(|()| out.flush()).is_err() {
                        eprintln!("hstlc lsp: cannot write to standard output; stopping");
                        return;
                    }
                }
                Err(e) if e.is_timeout() && !writer_done.load(Ordering::SeqCst) => {}
                Err(_) => return,
            }
        }
    });
    // Not joined: it may be blocked reading standard input when the server stops.
    std::thread::spawn(move || {
        read_stdin(
            |m| to_server.send(m).is_ok(),
            |m| {
                let _ = inject.send(m);
            },
        )
    });
    let clean = serve(&server).map_err(|e| CliError::new(format!("language server: {e}"), None));
    drop(server);
    done.store(true, Ordering::SeqCst);
    let _ = writer.join();
    Ok(if clean? { Status::Clean } else { Status::Errors })
}

/// Reads framed messages from standard input and hands them to the server. A message
/// that is not valid JSON-RPC is logged and skipped; when it carries an `id`, the client
/// gets an `InvalidRequest` error response for it.
fn read_stdin(to_server: impl Fn(Message) -> bool, to_client: impl Fn(Message)) {
    let stdin = std::io::stdin();
    let mut input = stdin.lock();
    loop {
        let body = match read_frame(&mut input) {
            Ok(Some(body)) => body,
            Ok(None) => return,
            Err(e) => {
                eprintln!("hstlc lsp: malformed message header: {e}");
                continue;
            }
        };
        match serde_json::from_slice::<Message>(&body) {
            Ok(message) => {
                let exit = matches!(&message, Message::Notification(n) if n.method == "exit");
                if !to_server(message) || exit {
                    return;
                }
            }
            Err(e) => {
                eprintln!("hstlc lsp: malformed message: {e}");
                let id = serde_json::from_slice::<Value>(&body).ok().and_then(|v| match &v["id"] {
                    Value::Number(n) => {
                        n.as_i64().and_then(|n| i32::try_from(n).ok()).map(RequestId::from)
                    }
                    Value::String(s) => Some(RequestId::from(s.clone())),
                    _ => None,
                });
                if let Some(id) = id {
                    let message = format!("invalid request: {e}");
                    let response = Response::new_err(id, ErrorCode::InvalidRequest as i32, message);
                    to_client(Message::Response(response));
                }
            }
        }
    }
}

/// One frame: headers up to an empty line, then `Content-Length` bytes. `None` at the
/// end of the input.
fn read_frame(input: &mut impl BufRead) -> std::io::Result<Option<Vec<u8>>> {
    let mut length = None;
    let mut line = String::new();
    loop {
        line.clear();
        if input.read_line(&mut line)? == 0 {
            return Ok(None);
        }
        let header = line.trim_end_matches(['\r', '\n']);
        if header.is_empty() {
            if length.is_some() {
                break;
            }
            continue;
        }
        if let Some((name, value)) = header.split_once(':')
            && name.trim().eq_ignore_ascii_case("content-length")
        {
            length = value.trim().parse::<usize>().ok();
            if length.is_none() {
                return Err(std::io::Error::other(format!(
                    "bad Content-Length `{}`",
                    value.trim()
                )));
            }
        }
    }
    let mut body = vec![0; length.unwrap_or(0)];
    input.read_exact(&mut body)?;
    Ok(Some(body))
}

/// Serves one client over `connection`: the handshake, then messages until the client
/// exits. Returns whether it shut down cleanly (`shutdown`, then `exit`).
pub fn serve(connection: &Connection) -> Result<bool, String> {
    let (id, params) = connection.initialize_start().map_err(|e| e.to_string())?;
    let params: InitializeParams = serde_json::from_value(params).unwrap_or_else(|e| {
        eprintln!("hstlc lsp: initialize: {e}; using default client capabilities");
        InitializeParams::default()
    });
    let encoding = negotiate_encoding(&params);
    let capabilities = ServerCapabilities {
        position_encoding: Some(match encoding {
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
    let result = serde_json::json!({
        "capabilities": capabilities,
        "serverInfo": { "name": "hstlc", "version": env!("CARGO_PKG_VERSION") },
    });
    connection.initialize_finish(id, result).map_err(|e| e.to_string())?;
    let mut server = Server::new(encoding);
    for message in &connection.receiver {
        match message {
            Message::Request(request) => {
                if connection.handle_shutdown(&request).map_err(|e| e.to_string())? {
                    return Ok(true);
                }
                let response = server.answer(request);
                send(connection, Message::Response(response));
            }
            Message::Notification(n) => {
                if n.method == "exit" {
                    eprintln!("hstlc lsp: exit without shutdown");
                    return Ok(false);
                }
                for out in server.notify(n) {
                    send(connection, Message::Notification(out));
                }
                // Free the previous versions once the diagnostics are on their way.
                server.trash.clear();
            }
            Message::Response(_) => {}
        }
    }
    Ok(false)
}

/// The server's state: the open documents and the negotiated position encoding.
pub struct Server {
    encoding: Encoding,
    documents: HashMap<Uri, Analysis>,
    /// What is left of replaced versions, freed after answering.
    trash: Vec<features::Leftovers>,
}

type Answer = Result<Value, (ErrorCode, String)>;

impl Server {
    /// A server with no open document.
    pub fn new(encoding: Encoding) -> Self {
        Server { encoding, documents: HashMap::new(), trash: Vec::new() }
    }

    /// Answers a request; never panics (an internal error becomes an error response).
    fn answer(&mut self, request: Request) -> Response {
        let id = request.id.clone();
        let method = request.method.clone();
        match catch_unwind(AssertUnwindSafe(|| self.dispatch(request))) {
            Ok(Ok(value)) => Response::new_ok(id, value),
            Ok(Err((code, message))) => {
                eprintln!("hstlc lsp: {method}: {message}");
                Response::new_err(id, code as i32, message)
            }
            Err(_) => {
                eprintln!("hstlc lsp: internal error while answering {method}");
                Response::new_err(
                    id,
                    ErrorCode::InternalError as i32,
                    format!("internal error in {method}"),
                )
            }
        }
    }

    fn document(&self, uri: &Uri) -> Result<&Analysis, (ErrorCode, String)> {
        self.documents.get(uri).ok_or_else(|| {
            (ErrorCode::InvalidParams, format!("document `{}` is not open", uri.as_str()))
        })
    }

    fn dispatch(&mut self, request: Request) -> Answer {
        let Request { method, params, .. } = request;
        match method.as_str() {
            HoverRequest::METHOD => {
                let p: lsp_types::HoverParams = parse(params)?;
                let pos = p.text_document_position_params;
                let doc = self.document(&pos.text_document.uri)?;
                to_json(features::hover(doc, pos.position))
            }
            GotoDefinition::METHOD => {
                let p: lsp_types::GotoDefinitionParams = parse(params)?;
                let pos = p.text_document_position_params;
                let doc = self.document(&pos.text_document.uri)?;
                let uri = pos.text_document.uri.clone();
                to_json(
                    features::definition(doc, pos.position)
                        .map(|range| lsp_types::Location { uri, range }),
                )
            }
            References::METHOD => {
                let p: lsp_types::ReferenceParams = parse(params)?;
                let pos = p.text_document_position;
                let doc = self.document(&pos.text_document.uri)?;
                let refs: Vec<lsp_types::Location> =
                    features::references(doc, pos.position, p.context.include_declaration)
                        .into_iter()
                        .map(|range| lsp_types::Location {
                            uri: pos.text_document.uri.clone(),
                            range,
                        })
                        .collect();
                to_json(refs)
            }
            DocumentSymbolRequest::METHOD => {
                let p: lsp_types::DocumentSymbolParams = parse(params)?;
                let doc = self.document(&p.text_document.uri)?;
                to_json(lsp_types::DocumentSymbolResponse::Nested(features::symbols(doc)))
            }
            Completion::METHOD => {
                let p: lsp_types::CompletionParams = parse(params)?;
                let pos = p.text_document_position;
                let doc = self.document(&pos.text_document.uri)?;
                to_json(lsp_types::CompletionResponse::Array(features::completion(
                    doc,
                    pos.position,
                )))
            }
            Formatting::METHOD => {
                let p: lsp_types::DocumentFormattingParams = parse(params)?;
                let doc = self.document(&p.text_document.uri)?;
                let edits = features::format(doc).map_err(|e| (ErrorCode::RequestFailed, e))?;
                to_json(edits)
            }
            // Lets the tests reach the internal-error path.
            #[cfg(test)]
            "hstlc/testPanic" => panic!("a deliberate panic"),
            _ => Err((ErrorCode::MethodNotFound, format!("unsupported request `{method}`"))),
        }
    }

    /// Applies a notification; returns the notifications to send back. A malformed one
    /// is logged and ignored.
    pub fn notify(&mut self, n: Notification) -> Vec<Notification> {
        let method = n.method.clone();
        match catch_unwind(AssertUnwindSafe(|| self.apply(n))) {
            Ok(Ok(out)) => out,
            Ok(Err(e)) => {
                eprintln!("hstlc lsp: {method}: {e}");
                Vec::new()
            }
            Err(_) => {
                eprintln!("hstlc lsp: internal error while handling {method}");
                Vec::new()
            }
        }
    }

    fn apply(&mut self, n: Notification) -> Result<Vec<Notification>, String> {
        let uri = match n.method.as_str() {
            DidOpenTextDocument::METHOD => {
                let p: lsp_types::DidOpenTextDocumentParams =
                    serde_json::from_value(n.params).map_err(|e| e.to_string())?;
                self.update(p.text_document.uri.clone(), p.text_document.text);
                p.text_document.uri
            }
            DidChangeTextDocument::METHOD => {
                let p: lsp_types::DidChangeTextDocumentParams =
                    serde_json::from_value(n.params).map_err(|e| e.to_string())?;
                // Full synchronisation: the last change holds the whole text.
                let Some(change) = p.content_changes.into_iter().last() else {
                    return Ok(Vec::new());
                };
                if change.range.is_some() {
                    return Err("only full-document changes are supported".into());
                }
                let uri = p.text_document.uri;
                let next = match self.documents.remove(&uri) {
                    Some(prev) => {
                        let (next, leftovers) = Analysis::update(prev, change.text, self.encoding);
                        self.trash.push(leftovers);
                        next
                    }
                    None => Analysis::new(change.text, self.encoding),
                };
                self.documents.insert(uri.clone(), next);
                uri
            }
            DidCloseTextDocument::METHOD => {
                let p: lsp_types::DidCloseTextDocumentParams =
                    serde_json::from_value(n.params).map_err(|e| e.to_string())?;
                self.documents.remove(&p.text_document.uri);
                return Ok(vec![publish(p.text_document.uri, Vec::new())]);
            }
            _ => return Ok(Vec::new()),
        };
        let diagnostics =
            self.documents.get(&uri).map(|a| features::diagnostics(a, &uri)).unwrap_or_default();
        Ok(vec![publish(uri, diagnostics)])
    }

    /// Checks a new version of a document.
    pub fn update(&mut self, uri: Uri, text: String) {
        self.documents.insert(uri, Analysis::new(text, self.encoding));
    }
}

fn publish(uri: Uri, diagnostics: Vec<lsp_types::Diagnostic>) -> Notification {
    Notification::new(
        PublishDiagnostics::METHOD.to_string(),
        PublishDiagnosticsParams { uri, diagnostics, version: None },
    )
}

fn parse<T: serde::de::DeserializeOwned>(params: Value) -> Result<T, (ErrorCode, String)> {
    serde_json::from_value(params)
        .map_err(|e| (ErrorCode::InvalidParams, format!("invalid parameters: {e}")))
}

fn to_json<T: serde::Serialize>(v: T) -> Answer {
    serde_json::to_value(v).map_err(|e| (ErrorCode::InternalError, e.to_string()))
}

fn send(connection: &Connection, message: Message) {
    if connection.sender.send(message).is_err() {
        eprintln!("hstlc lsp: the client has gone away");
    }
}

/// UTF-8 when the client offers it (no conversion needed), else the protocol's UTF-16.
fn negotiate_encoding(params: &InitializeParams) -> Encoding {
    let offered = params.capabilities.general.as_ref().and_then(|g| g.position_encodings.as_ref());
    match offered {
        Some(kinds) if kinds.contains(&PositionEncodingKind::UTF8) => Encoding::Utf8,
        _ => Encoding::Utf16,
    }
}
