//! `hstlc lsp` as a process, JSON-RPC over pipes, against a hostile client (issue 11,
//! class 4): oversized and malformed frames, requests out of the lifecycle, bursts of
//! changes, a client that reads slowly, and a document over the size limit. After each,
//! the server must still answer; `shutdown` then `exit` ends it with status 0, anything
//! else with status 1.
//!
//! Inputs are generated here. Memory is checked through `/proc` (Linux) where the point
//! is that something was never held whole; no test measures time.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, channel};
use std::thread::JoinHandle;
use std::time::Duration;

use serde_json::{Value, json};

const URI: &str = "file:///tmp/s.hstl";

/// Guards the tests against a server that never answers (a failure, not a measurement).
const STUCK: Duration = Duration::from_secs(120);

struct Server {
    child: Child,
    stdin: Option<ChildStdin>,
    messages: Receiver<Value>,
    /// While set, the client reads nothing from the server.
    paused: Arc<AtomicBool>,
    stderr: Option<JoinHandle<String>>,
    /// Notifications received while waiting for responses.
    notifications: Vec<Value>,
}

impl Server {
    fn start() -> Server {
        let mut child = Command::new(env!("CARGO_BIN_EXE_hstlc"))
            .arg("lsp")
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start hstlc lsp");
        let stdin = child.stdin.take();
        let mut stdout = BufReader::new(child.stdout.take().expect("stdout"));
        let (tx, messages) = channel();
        let paused = Arc::new(AtomicBool::new(false));
        let pause = Arc::clone(&paused);
        std::thread::spawn(move || {
            loop {
                while pause.load(Ordering::SeqCst) {
                    std::thread::sleep(Duration::from_millis(10));
                }
                let Some(m) = read_message(&mut stdout) else { return };
                if tx.send(m).is_err() {
                    return;
                }
            }
        });
        // Read all along, so that logging never blocks the server.
        let mut err = child.stderr.take().expect("stderr");
        let stderr = std::thread::spawn(move || {
            let mut text = String::new();
            let _ = err.read_to_string(&mut text);
            text
        });
        Server { child, stdin, messages, paused, stderr: Some(stderr), notifications: Vec::new() }
    }

    /// Starts a server and initialises it.
    fn initialized() -> Server {
        let mut s = Server::start();
        s.send(json!({ "jsonrpc": "2.0", "id": 0, "method": "initialize", "params": { "capabilities": {} } }));
        let init = s.response(0);
        assert!(init["result"]["capabilities"]["hoverProvider"].as_bool().unwrap_or(false));
        s.notify("initialized", json!({}));
        s
    }

    fn write(&mut self, bytes: &[u8]) {
        let stdin = self.stdin.as_mut().expect("stdin open");
        stdin.write_all(bytes).expect("write");
        stdin.flush().expect("flush");
    }

    fn send(&mut self, message: Value) {
        self.write(&frame(message.to_string().as_bytes()));
    }

    fn request(&mut self, id: i64, method: &str, params: Value) {
        self.send(json!({ "jsonrpc": "2.0", "id": id, "method": method, "params": params }));
    }

    fn notify(&mut self, method: &str, params: Value) {
        self.send(json!({ "jsonrpc": "2.0", "method": method, "params": params }));
    }

    fn next(&mut self) -> Value {
        self.messages.recv_timeout(STUCK).expect("the server answers")
    }

    /// The response with this id; notifications on the way are kept, any other response
    /// fails the test.
    fn response(&mut self, id: i64) -> Value {
        loop {
            let m = self.next();
            if m.get("method").is_some() {
                self.notifications.push(m);
                continue;
            }
            assert_eq!(m["id"], id, "responses come in order: {m}");
            return m;
        }
    }

    /// The `publishDiagnostics` received so far for `URI`.
    fn published(&self) -> Vec<&Value> {
        self.notifications
            .iter()
            .filter(|n| {
                n["method"] == "textDocument/publishDiagnostics" && n["params"]["uri"] == URI
            })
            .collect()
    }

    fn open(&mut self, text: &str) {
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": URI, "languageId": "hstl", "version": 1, "text": text } }),
        );
    }

    fn hover(&mut self, id: i64, line: u32, character: u32) -> Value {
        self.request(
            id,
            "textDocument/hover",
            json!({ "textDocument": { "uri": URI }, "position": { "line": line, "character": character } }),
        );
        self.response(id)
    }

    /// The server's peak resident memory, in MiB (`None` without `/proc`).
    fn peak_rss_mib(&self) -> Option<u64> {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.child.id())).ok()?;
        let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
        let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
        Some(kib / 1024)
    }

    fn shutdown(mut self) -> String {
        self.request(999_999, "shutdown", Value::Null);
        assert_eq!(self.response(999_999)["result"], Value::Null);
        self.notify("exit", Value::Null);
        let (code, stderr) = self.finish();
        assert_eq!(code, Some(0), "{stderr}");
        stderr
    }

    /// Closes standard input and waits: the exit status and what was logged.
    fn finish(mut self) -> (Option<i32>, String) {
        drop(self.stdin.take());
        let status = self.child.wait().expect("wait");
        let stderr = self.stderr.take().map(|h| h.join().expect("stderr")).unwrap_or_default();
        (status.code(), stderr)
    }
}

fn frame(body: &[u8]) -> Vec<u8> {
    let mut out = format!("Content-Length: {}\r\n\r\n", body.len()).into_bytes();
    out.extend_from_slice(body);
    out
}

/// One message from the server, checked to be a well-formed frame of JSON-RPC 2.0.
fn read_message(input: &mut impl BufRead) -> Option<Value> {
    let mut length = None;
    loop {
        let mut line = String::new();
        if input.read_line(&mut line).ok()? == 0 {
            return None;
        }
        let line = line.strip_suffix("\r\n").expect("headers end in CRLF");
        if line.is_empty() {
            break;
        }
        let value = line.strip_prefix("Content-Length: ").expect("only Content-Length");
        length = Some(value.parse::<usize>().expect("a length"));
    }
    let mut body = vec![0; length.expect("Content-Length")];
    input.read_exact(&mut body).ok()?;
    let message: Value = serde_json::from_slice(&body).expect("JSON from the server");
    assert_eq!(message["jsonrpc"], "2.0", "{message}");
    Some(message)
}

const SPEC: &str =
    "spec S {\n    state { x: int in 0..=3 }\n    let A = x > 1;\n    task always A;\n}\n";

#[test]
fn oversized_frames_are_skipped_without_being_held() {
    // Lengths past the limit with no body behind them: refused, and the end of the
    // input inside the announced body ends the server cleanly.
    for length in ["1000000000000", "18446744073709551615"] {
        let mut s = Server::initialized();
        s.write(format!("Content-Length: {length}\r\n\r\n{{}}").as_bytes());
        let (code, stderr) = s.finish();
        assert_eq!(code, Some(1), "{stderr}");
        assert!(
            stderr.contains(&format!("a {length}-byte message is larger than the limit of 64 MiB")),
            "{stderr}"
        );
        assert!(stderr.contains("the input ended inside a message body (2 of"), "{stderr}");
    }

    let mut s = Server::initialized();
    s.open(SPEC);
    // A length past 64 bits: the stream is resynchronised at the next header.
    s.write(b"Content-Length: 18446744073709551616\r\n\r\n{\"jsonrpc\":\"2.0\",\"id\":50,\"method\":\"shutdown\"}");
    assert!(s.hover(1, 3, 10)["result"]["contents"]["value"].as_str().unwrap().contains("always"));
    // A real 65 MiB message: read and dropped in chunks, then the next request answered.
    let pad = 65 << 20;
    let mut big = format!("Content-Length: {}\r\n\r\n{{\"jsonrpc\":\"2.0\",\"id\":51,\"method\":\"shutdown\",\"params\":{{\"pad\":\"", pad + 80).into_bytes();
    let header = big.len()
        - "{\"jsonrpc\":\"2.0\",\"id\":51,\"method\":\"shutdown\",\"params\":{\"pad\":\"".len();
    big.resize(header + pad + 80 - 3, b' ');
    big.extend_from_slice(b"\"}}");
    s.write(&big);
    drop(big);
    assert!(s.hover(2, 3, 10)["result"]["contents"]["value"].as_str().unwrap().contains("always"));
    if let Some(peak) = s.peak_rss_mib() {
        assert!(peak < 64, "the skipped 65 MiB body was held: peak {peak} MiB");
    }
    let stderr = s.shutdown();
    assert!(stderr.contains("Content-Length does not fit in 64 bits"), "{stderr}");
    assert!(stderr.contains(&format!("a {}-byte message is larger", pad + 80)), "{stderr}");
}

/// A malformed frame, and what the client gets for it: `Some((id, code))` for an error
/// response, `None` when no id can be read (then it is only logged).
struct Case {
    name: &'static str,
    bytes: Vec<u8>,
    answer: Option<(i64, i64)>,
}

fn case(name: &'static str, bytes: impl Into<Vec<u8>>, answer: Option<(i64, i64)>) -> Case {
    Case { name, bytes: bytes.into(), answer }
}

const PARSE_ERROR: i64 = -32700;
const INVALID_REQUEST: i64 = -32600;

#[test]
fn malformed_frames_are_answered_or_skipped_and_the_server_goes_on() {
    // Most carry a `shutdown` that must not run: if one did, every later request would
    // be refused and the final `shutdown` would fail.
    let shutdown = |id: i64| format!("{{\"jsonrpc\":\"2.0\",\"id\":{id},\"method\":\"shutdown\"}}");
    let with_length = |headers: &str, body: &str| format!("{headers}\r\n\r\n{body}").into_bytes();
    let body = shutdown(100);
    let n = body.len();
    let long = "a".repeat(9000);
    let cases = vec![
        case("non-numeric length", with_length("Content-Length: abc", &body), None),
        case("negative length", with_length("Content-Length: -5", &body), None),
        case(
            "length with trailing junk",
            with_length(&format!("Content-Length: {n}x"), &body),
            None,
        ),
        case("empty length", with_length("Content-Length:", &body), None),
        case(
            "conflicting lengths",
            with_length(&format!("Content-Length: {n}\r\nContent-Length: 3"), &body),
            None,
        ),
        case(
            "no length",
            with_length("Content-Type: application/vscode-jsonrpc; charset=utf-8", &body),
            None,
        ),
        case(
            "header block too long",
            with_length(&format!("Content-Length: {n}\r\nX-Pad: {long}"), &body),
            None,
        ),
        case(
            "repeated length",
            with_length(&format!("Content-Length: {n}\r\ncontent-length: {n}"), &body),
            Some((100, INVALID_REQUEST)),
        ),
        case(
            "header without a colon",
            with_length(&format!("Content-Length: {n}\r\nGarbage"), &body),
            Some((100, INVALID_REQUEST)),
        ),
        case("not JSON", frame(b"{this is not json"), None),
        case("empty body", frame(b""), None),
        case(
            "trailing characters",
            frame(format!("{} x", shutdown(101)).as_bytes()),
            Some((101, PARSE_ERROR)),
        ),
        case(
            "two messages in one frame",
            frame(format!("{}{}", shutdown(102), shutdown(103)).as_bytes()),
            Some((102, PARSE_ERROR)),
        ),
        case(
            "invalid UTF-8",
            frame(b"{\"jsonrpc\":\"2.0\",\"id\":104,\"method\":\"shut\xffdown\"}"),
            Some((104, PARSE_ERROR)),
        ),
        case(
            "an object as id",
            frame(br#"{"jsonrpc":"2.0","id":{"a":1},"method":"shutdown"}"#),
            None,
        ),
        case("an array as id", frame(br#"{"jsonrpc":"2.0","id":[1],"method":"shutdown"}"#), None),
        case("a fraction as id", frame(br#"{"jsonrpc":"2.0","id":1.5,"method":"shutdown"}"#), None),
        case("null as id", frame(br#"{"jsonrpc":"2.0","id":null,"method":"shutdown"}"#), None),
        case(
            "method not a string",
            frame(br#"{"jsonrpc":"2.0","id":105,"method":5}"#),
            Some((105, INVALID_REQUEST)),
        ),
        case("no method", frame(br#"{"jsonrpc":"2.0","id":106}"#), Some((106, INVALID_REQUEST))),
        case(
            "wrong version",
            frame(br#"{"jsonrpc":"1.0","id":107,"method":"shutdown"}"#),
            Some((107, INVALID_REQUEST)),
        ),
        case(
            "params a string",
            frame(br#"{"jsonrpc":"2.0","id":108,"method":"shutdown","params":"x"}"#),
            Some((108, INVALID_REQUEST)),
        ),
        case("a batch", frame(format!("[{}]", shutdown(109)).as_bytes()), None),
        case("a number", frame(b"42"), None),
        case("nesting past serde's limit", frame("[".repeat(100_000).as_bytes()), None),
        case("blank lines between frames", b"\r\n\r\n\n".to_vec(), None),
    ];
    let mut s = Server::initialized();
    s.open(SPEC);
    let mut id = 1;
    for case in &cases {
        s.write(&case.bytes);
        id += 1;
        s.request(
            id,
            "textDocument/hover",
            json!({ "textDocument": { "uri": URI }, "position": { "line": 3, "character": 10 } }),
        );
        if let Some((err_id, code)) = case.answer {
            let r = s.response(err_id);
            assert_eq!(r["error"]["code"], code, "{}: {r}", case.name);
        }
        let r = s.response(id);
        let hover = r["result"]["contents"]["value"].as_str().unwrap_or_default();
        assert!(hover.contains("always"), "{}: the next request is answered: {r}", case.name);
    }
    // Ids need not fit in 32 bits; headers may end in a bare LF.
    s.send(json!({ "jsonrpc": "2.0", "id": 9_007_199_254_740_993_u64, "method": "textDocument/hover", "params": { "textDocument": { "uri": URI }, "position": { "line": 3, "character": 10 } } }));
    let r = s.next();
    assert_eq!(r["id"], 9_007_199_254_740_993_u64);
    assert!(r["result"].is_object(), "{r}");
    let body = r#"{"jsonrpc":"2.0","id":"lf","method":"textDocument/hover","params":{"textDocument":{"uri":"file:///tmp/s.hstl"},"position":{"line":3,"character":10}}}"#;
    s.write(format!("Content-Length: {}\n\n{body}", body.len()).as_bytes());
    let r = s.next();
    assert_eq!(r["id"], "lf");
    assert!(r["result"].is_object(), "{r}");
    let stderr = s.shutdown();
    for logged in [
        "Content-Length `abc` is not a decimal number",
        "Content-Length is given twice (",
        "a message without Content-Length",
        "message headers longer than 8 KiB",
        "request 100: malformed message header: Content-Length is given twice",
        "request 101: the message is not valid JSON: trailing characters",
        "request 104: the message is not valid UTF-8 (at byte 40)",
        "the id must be an integer or a string",
        "the message is not valid JSON: recursion limit exceeded",
    ] {
        assert!(stderr.contains(logged), "{logged} not in {stderr}");
    }
}

#[test]
fn requests_out_of_the_lifecycle_are_refused_and_the_server_goes_on() {
    let mut s = Server::start();
    // Before `initialize`: refused; a notification is dropped.
    s.request(1, "textDocument/hover", json!({}));
    assert_eq!(s.response(1)["error"]["code"], -32002);
    s.request(2, "shutdown", Value::Null);
    assert_eq!(s.response(2)["error"]["code"], -32002);
    s.open(SPEC);
    s.request(3, "initialize", json!({ "capabilities": {} }));
    assert!(s.response(3)["result"]["capabilities"].is_object());
    // A request before `initialized` is answered.
    s.request(4, "textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    let r = s.response(4);
    assert!(
        r["error"]["message"].as_str().unwrap().contains("is not open"),
        "the early didOpen was dropped: {r}"
    );
    s.notify("initialized", json!({}));
    s.request(5, "initialize", json!({ "capabilities": {} }));
    assert_eq!(s.response(5)["error"]["code"], INVALID_REQUEST);
    s.open(SPEC);
    assert!(s.hover(6, 3, 10)["result"].is_object());
    // After `shutdown`: refused, `shutdown` included; only `exit` acts.
    s.request(7, "shutdown", Value::Null);
    assert_eq!(s.response(7)["result"], Value::Null);
    let r = s.hover(8, 3, 10);
    assert_eq!(r["error"]["code"], INVALID_REQUEST, "{r}");
    s.request(9, "shutdown", Value::Null);
    assert_eq!(s.response(9)["error"]["code"], INVALID_REQUEST);
    s.notify("textDocument/didClose", json!({ "textDocument": { "uri": URI } }));
    s.notify("exit", Value::Null);
    let (code, stderr) = s.finish();
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stderr.contains("`textDocument/didOpen` before `initialize`: ignored"), "{stderr}");
    assert!(stderr.contains("`textDocument/didClose` after `shutdown`: ignored"), "{stderr}");

    // `exit` before `initialize`, `exit` without `shutdown`, or the client going away:
    // status 1.
    let mut s = Server::start();
    s.notify("exit", Value::Null);
    assert_eq!(s.finish().0, Some(1));
    let mut s = Server::initialized();
    s.notify("exit", Value::Null);
    assert_eq!(s.finish().0, Some(1));
    let s = Server::start();
    let (code, stderr) = s.finish();
    assert_eq!(code, Some(1), "{stderr}");
}

/// A version of [`SPEC`] whose let and diagnostics tell versions apart: `A` compares
/// with `v`, and the task names an unknown `Bv`.
fn version_text(v: usize) -> String {
    format!(
        "spec S {{\n    state {{ x: int in 0..=3 }}\n    let A = x > {v};\n    task always B{v};\n}}\n"
    )
}

#[test]
fn a_burst_of_changes_is_analysed_once_before_the_next_request() {
    let mut s = Server::initialized();
    s.open(&version_text(1));
    s.hover(1, 2, 8);
    let before = s.published().len();
    // 200 changes and a hover in one write (about 50 KB: one read for the server).
    let mut burst = Vec::new();
    for v in 2..=201 {
        let change = json!({ "jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
            "textDocument": { "uri": URI, "version": v }, "contentChanges": [{ "text": version_text(v) }] } });
        burst.extend(frame(change.to_string().as_bytes()));
    }
    let hover = json!({ "jsonrpc": "2.0", "id": 2, "method": "textDocument/hover", "params": {
        "textDocument": { "uri": URI }, "position": { "line": 2, "character": 8 } } });
    burst.extend(frame(hover.to_string().as_bytes()));
    s.write(&burst);
    let r = s.response(2);
    // The hover is about the newest text.
    let text = r["result"]["contents"]["value"].as_str().unwrap_or_default();
    assert!(text.contains("let A = x > 201;"), "{r}");
    // Diagnostics for the analysed versions come before the answer; only the last
    // version was analysed (the burst might reach the server in a few reads, not 200).
    let published = &s.published()[before..];
    assert!(!published.is_empty() && published.len() < 10, "{} publishes", published.len());
    let last = published.last().unwrap();
    assert_eq!(last["params"]["version"], 201);
    let diagnostics = last["params"]["diagnostics"].to_string();
    assert!(diagnostics.contains("B201") && !diagnostics.contains("B200"), "{diagnostics}");
    s.shutdown();
}

#[test]
fn a_client_that_reads_slowly_gets_the_newest_diagnostics_not_every_version() {
    // 300 unknown names: 200 diagnostics and one "more were found" per version, about
    // 60 KB of JSON, so that one publish fills the pipe the client does not read.
    let text = |v: usize| {
        let lets: String = (0..300).map(|i| format!("    let A{i} = y{i} > {v};\n")).collect();
        format!("spec S {{\n    state {{ x: int in 0..=3 }}\n{lets}    task always A0;\n}}\n")
    };
    let mut s = Server::initialized();
    s.open(&text(1));
    s.hover(1, 2, 9);
    let before = s.published().len();
    // 100 versions, each followed by a hover (which needs it analysed), none read.
    s.paused.store(true, Ordering::SeqCst);
    let versions = 100;
    for v in 2..=versions + 1 {
        s.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": URI, "version": v }, "contentChanges": [{ "text": text(v) }] }),
        );
        s.request(
            v as i64,
            "textDocument/hover",
            json!({ "textDocument": { "uri": URI }, "position": { "line": 2, "character": 9 } }),
        );
    }
    // Four 30 MB notifications: the reader holds the third until the server has taken
    // the first from its 64 MiB inbox, so once the fourth is written, the server has
    // handled every version (and the client has read nothing).
    let pad = format!(
        "{{\"jsonrpc\":\"2.0\",\"method\":\"$/pad\",\"params\":{{\"pad\":\"{}\"}}}}",
        " ".repeat(30 << 20)
    );
    for _ in 0..4 {
        s.write(&frame(pad.as_bytes()));
    }
    drop(pad);
    // Now read: every hover is answered, in order; most diagnostics were replaced.
    s.paused.store(false, Ordering::SeqCst);
    for v in 2..=versions + 1 {
        let r = s.response(v as i64);
        let text = r["result"]["contents"]["value"].as_str().unwrap_or_default();
        assert!(text.contains(&format!("y0 > {v}")), "hover {v}: {r}");
    }
    let published = &s.published()[before..];
    assert!(published.len() < 10, "{} of {versions} versions were written", published.len());
    assert_eq!(published.last().unwrap()["params"]["version"], versions + 1);
    if let Some(peak) = s.peak_rss_mib() {
        assert!(peak < 256, "peak {peak} MiB");
    }
    let stderr = s.shutdown();
    assert!(stderr.contains("publishDiagnostics replaced by newer ones"), "{stderr}");
}

#[test]
fn a_document_over_the_size_limit_is_refused_with_bounded_memory() {
    let mut s = Server::initialized();
    // About 10 MB of lets.
    let lets: String = (0..450_000).map(|i| format!("    let L{i} = x > {};\n", i % 4)).collect();
    let big =
        format!("spec S {{\n    state {{ x: int in 0..=3 }}\n{lets}    task always L0;\n}}\n");
    assert!(big.len() > 10_000_000);
    s.open(&big);
    drop(big);
    s.request(1, "textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    let r = s.response(1);
    assert_eq!(r["error"]["code"], -32803, "{r}");
    let message = r["error"]["message"].as_str().unwrap();
    assert!(message.contains("more than the 4 MiB the language server analyses"), "{message}");
    let shown = s
        .notifications
        .iter()
        .find(|n| n["method"] == "window/showMessage")
        .expect("the user is told");
    assert!(shown["params"]["message"].as_str().unwrap().contains("hstlc check"));
    assert_eq!(s.published().last().unwrap()["params"]["diagnostics"], json!([]));
    if let Some(peak) = s.peak_rss_mib() {
        assert!(peak < 256, "peak {peak} MiB for a 10 MB document");
    }
    // Cut down below the limit, it is analysed again.
    s.notify(
        "textDocument/didChange",
        json!({ "textDocument": { "uri": URI, "version": 2 }, "contentChanges": [{ "text": SPEC }] }),
    );
    s.request(2, "textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    assert_eq!(s.response(2)["result"][0]["name"], "S");
    s.shutdown();
}
