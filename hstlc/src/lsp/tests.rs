//! In-process protocol tests: a client talks to [`super::serve`] over pipes.

use std::io::BufReader;
use std::path::Path;
use std::sync::mpsc::{Receiver, channel};
use std::thread::JoinHandle;
use std::time::Duration;

use hstl::lang::LineIndex;
use lsp_server::{Message, Notification, Request, RequestId, ResponseError};
use serde_json::{Value, json};

use super::transport::{Frame, FrameReader, Incoming, Problem, decode};

const URI: &str = "file:///tmp/spec.hstl";

/// Guards the tests against a server that never answers (a failure, not a measurement).
const STUCK: Duration = Duration::from_secs(120);

/// A spec with a missing `;` after `let B = ...` (HSTL001 after `x > 3`) and a
/// duplicate `let` (HSTL003 with a related location).
const BROKEN: &str = "spec S {
    state { x: int in 0..=14, y: int in 0..=14 }
    let A = x > 1 && y < 2;
    let A = x < 3;
    let B = x > 3
    let C = y > 0;
    task always[0..10] eventually[0..=3] A;
}
";

const FIXED: &str = "/// A spec.
spec S {
    state { x: int in 0..=14, y: int in 0..=14 }
    /// Where x is large and y small.
    let A = x > 1 && y < 2;
    let B = x > 3;
    task always[0..10] (eventually[0..=3] A || B);
    option A;
    option B { reach: B, init: x < 15, terminate: B }
    options sequences(A, B);
}
";

/// A response, split for the asserts.
#[derive(Debug)]
struct Reply {
    result: Option<Value>,
    error: Option<ResponseError>,
}

/// A client of [`super::serve`] over in-memory pipes, framing with `lsp-server`'s own
/// reader and writer.
struct Client {
    to_server: Option<std::io::PipeWriter>,
    from_server: Receiver<Message>,
    server: Option<JoinHandle<std::io::Result<super::Ending>>>,
    next_id: i32,
    notifications: Vec<Notification>,
    /// The document the client edits.
    uri: String,
}

impl Client {
    /// Starts a server and initialises it; returns the client and the `initialize` result.
    fn start(capabilities: Value) -> (Client, Value) {
        let (server_in, to_server) = std::io::pipe().expect("pipe");
        let (from_server, server_out) = std::io::pipe().expect("pipe");
        let handle = std::thread::spawn(move || super::serve(server_in, server_out));
        let (tx, messages) = channel();
        std::thread::spawn(move || {
            let mut input = BufReader::new(from_server);
            while let Ok(Some(m)) = Message::read(&mut input) {
                if tx.send(m).is_err() {
                    return;
                }
            }
        });
        let mut c = Client {
            to_server: Some(to_server),
            from_server: messages,
            server: Some(handle),
            next_id: 0,
            notifications: vec![],
            uri: URI.to_string(),
        };
        let init = c.request("initialize", json!({ "capabilities": capabilities }));
        let result = init.result.expect("initialize succeeds");
        c.notify("initialized", json!({}));
        (c, result)
    }

    fn send(&mut self, message: Message) {
        let out = self.to_server.as_mut().expect("the client is connected");
        message.write(out).expect("server is up");
    }

    fn request(&mut self, method: &str, params: Value) -> Reply {
        self.next_id += 1;
        let id = RequestId::from(self.next_id);
        let req = Request { id: id.clone(), method: method.into(), params };
        self.send(Message::Request(req));
        loop {
            match self.recv() {
                Message::Response(r) if r.id == id => {
                    return match r.response_result {
                        Ok(v) => Reply { result: Some(v), error: None },
                        Err(e) => Reply { result: None, error: Some(e) },
                    };
                }
                Message::Notification(n) => self.notifications.push(n),
                other => panic!("unexpected message {other:?}"),
            }
        }
    }

    fn notify(&mut self, method: &str, params: Value) {
        let n = Notification { method: method.into(), params };
        self.send(Message::Notification(n));
    }

    fn recv(&mut self) -> Message {
        self.from_server.recv_timeout(STUCK).expect("the server answers")
    }

    /// The next `publishDiagnostics` for the document.
    fn diagnostics(&mut self) -> Vec<Value> {
        let n = if self.notifications.is_empty() {
            match self.recv() {
                Message::Notification(n) => n,
                other => panic!("expected a notification, got {other:?}"),
            }
        } else {
            self.notifications.remove(0)
        };
        assert_eq!(n.method, "textDocument/publishDiagnostics");
        assert_eq!(n.params["uri"], self.uri.as_str());
        n.params["diagnostics"].as_array().cloned().unwrap_or_default()
    }

    fn open(&mut self, text: &str) -> Vec<Value> {
        self.notify(
            "textDocument/didOpen",
            json!({ "textDocument": { "uri": self.uri, "languageId": "hstl", "version": 1, "text": text } }),
        );
        self.diagnostics()
    }

    fn change(&mut self, version: i32, text: &str) -> Vec<Value> {
        self.notify(
            "textDocument/didChange",
            json!({ "textDocument": { "uri": self.uri, "version": version }, "contentChanges": [{ "text": text }] }),
        );
        self.diagnostics()
    }

    fn at(&mut self, method: &str, line: u32, character: u32) -> Reply {
        self.request(
            method,
            json!({ "textDocument": { "uri": self.uri }, "position": { "line": line, "character": character }, "context": { "includeDeclaration": true } }),
        )
    }

    fn shutdown(mut self) {
        let r = self.request("shutdown", Value::Null);
        assert!(r.error.is_none(), "{r:?}");
        self.notify("exit", Value::Null);
        let result = self.server.take().map(|h| h.join().expect("server thread ends"));
        assert_eq!(result.map(|r| r.expect("threads start")), Some(super::Ending::Exit));
    }
}

/// `(line, character)` (0-based) of the first occurrence of `needle` in `text`, plus `skip`.
fn pos_of(text: &str, needle: &str, nth: usize, skip: u32) -> (u32, u32) {
    let at = text.match_indices(needle).nth(nth).expect("needle in text").0;
    let p = LineIndex::new(text).position(text, at);
    ((p.line - 1) as u32, p.utf16_column as u32 + skip)
}

fn lsp_range(text: &str, r: &std::ops::Range<usize>) -> Value {
    let index = LineIndex::new(text);
    let (a, b) = (index.position(text, r.start), index.position(text, r.end));
    json!({
        "start": { "line": a.line - 1, "character": a.utf16_column },
        "end": { "line": b.line - 1, "character": b.utf16_column },
    })
}

#[test]
fn a_session_from_initialize_to_shutdown() {
    let (mut c, init) = Client::start(json!({}));
    assert_eq!(init["capabilities"]["positionEncoding"], "utf-16");
    assert_eq!(init["capabilities"]["textDocumentSync"], 1);
    assert_eq!(init["capabilities"]["hoverProvider"], true);

    // Open: exactly the diagnostics of `check`, with codes and related locations.
    let diags = c.open(BROKEN);
    let expected =
        hstl::world::check(BROKEN, &hstl::world::GridWorld::default(), "world `paper`").diagnostics;
    assert_eq!(diags.len(), expected.len(), "{diags:#?}");
    for (got, want) in diags.iter().zip(&expected) {
        assert_eq!(got["code"], want.code);
        assert_eq!(got["range"], lsp_range(BROKEN, &want.range));
        assert!(got["message"].as_str().unwrap().starts_with(&want.message));
    }
    let syntax = diags.iter().find(|d| d["code"] == "HSTL001").expect("syntax error");
    // Reported where the `;` is missing: right after `x > 3`.
    let (line, col) = pos_of(BROKEN, "x > 3\n", 0, 5);
    assert_eq!(syntax["range"]["start"], json!({ "line": line, "character": col }));
    assert_eq!(syntax["severity"], 1);
    let dup = diags.iter().find(|d| d["code"] == "HSTL003").expect("duplicate let");
    let related = &dup["relatedInformation"][0];
    assert_eq!(related["location"]["uri"], URI);
    let (line, col) = pos_of(BROKEN, "A", 0, 0);
    assert_eq!(related["location"]["range"]["start"], json!({ "line": line, "character": col }));

    // Change to a fixed text: the diagnostics clear.
    assert_eq!(c.change(2, FIXED), Vec::<Value>::new());

    // Hover on `always`: the meaning and the interval in words.
    let (line, col) = pos_of(FIXED, "always", 0, 2);
    let hover = c.at("textDocument/hover", line, col);
    let text = hover.result.as_ref().unwrap()["contents"]["value"].as_str().unwrap().to_string();
    assert!(text.contains("minimum"), "{text}");
    assert!(text.contains("`t+9`") && text.contains("10 steps"), "{text}");
    // On `eventually[0..=3]`: inclusive interval.
    let (line, col) = pos_of(FIXED, "eventually", 0, 1);
    let text =
        c.at("textDocument/hover", line, col).result.unwrap()["contents"]["value"].to_string();
    assert!(text.contains("maximum") && text.contains("4 steps"), "{text}");
    // On `&&`.
    let (line, col) = pos_of(FIXED, "&&", 0, 1);
    let text =
        c.at("textDocument/hover", line, col).result.unwrap()["contents"]["value"].to_string();
    assert!(text.contains("minimum"), "{text}");
    // On the let A: its definition and how many of the 225 states satisfy it
    // (x in 2..=14 and y in 0..=1: 26 states).
    let (line, col) = pos_of(FIXED, "A =", 0, 0);
    let text =
        c.at("textDocument/hover", line, col).result.unwrap()["contents"]["value"].to_string();
    assert!(text.contains("let A = x > 1 && y < 2;"), "{text}");
    assert!(text.contains("in 26 of the 225 states"), "{text}");
    assert!(text.contains("Where x is large and y small."), "{text}");
    // On `option A;`: the option, and the let it reaches.
    let (line, col) = pos_of(FIXED, "option A", 0, 7);
    let text =
        c.at("textDocument/hover", line, col).result.unwrap()["contents"]["value"].to_string();
    assert!(text.contains("option A") && text.contains("let A = x > 1 && y < 2;"), "{text}");
    assert!(text.contains("init: `true` (default"), "{text}");
    // On option B: sequence, init, terminate.
    let (line, col) = pos_of(FIXED, "option B", 0, 7);
    let text =
        c.at("textDocument/hover", line, col).result.unwrap()["contents"]["value"].to_string();
    assert!(text.contains("init: `x < 15`") && text.contains("terminate: `B`"), "{text}");
    assert!(text.contains("`[A, B]`"), "{text}");
    // On blank space: nothing.
    let r = c.at("textDocument/hover", 0, 0);
    assert_eq!(r.result, Some(Value::Null));

    // Definition of `A` in the task: the let's name. From `option A;`, also the let.
    let decl = pos_of(FIXED, "A =", 0, 0);
    let decl = json!({ "line": decl.0, "character": decl.1 });
    let (line, col) = pos_of(FIXED, "A ||", 0, 0);
    let def = c.at("textDocument/definition", line, col).result.unwrap();
    assert_eq!(def["uri"], URI);
    assert_eq!(def["range"]["start"], decl);
    let (line, col) = pos_of(FIXED, "option A", 0, 7);
    assert_eq!(c.at("textDocument/definition", line, col).result.unwrap()["range"]["start"], decl);
    // Definition of the option B in `sequences(A, B)`: the option's name.
    let (line, col) = pos_of(FIXED, "B);", 1, 0);
    let def = c.at("textDocument/definition", line, col).result.unwrap();
    let want = pos_of(FIXED, "B {", 0, 0);
    assert_eq!(def["range"]["start"], json!({ "line": want.0, "character": want.1 }));
    // A state variable.
    let (line, col) = pos_of(FIXED, "y < 2", 0, 0);
    let def = c.at("textDocument/definition", line, col).result.unwrap();
    let want = pos_of(FIXED, "y: int", 0, 0);
    assert_eq!(def["range"]["start"], json!({ "line": want.0, "character": want.1 }));

    // References of the let B: declaration, task, `reach`, `terminate`.
    let (line, col) = pos_of(FIXED, "B =", 0, 0);
    let refs = c.at("textDocument/references", line, col).result.unwrap();
    assert_eq!(refs.as_array().map(Vec::len), Some(4), "{refs:#}");

    // Document symbols: the spec with its items.
    let r = c.request("textDocument/documentSymbol", json!({ "textDocument": { "uri": URI } }));
    let syms = r.result.unwrap();
    assert_eq!(syms[0]["name"], "S");
    let names: Vec<&str> =
        syms[0]["children"].as_array().unwrap().iter().filter_map(|s| s["name"].as_str()).collect();
    assert_eq!(names, ["x", "y", "A", "B", "task", "A", "B", "options"]);

    // Completion: keywords and the names in scope.
    let r = c.request(
        "textDocument/completion",
        json!({ "textDocument": { "uri": URI }, "position": { "line": 6, "character": 10 } }),
    );
    let labels: Vec<String> = r
        .result
        .unwrap()
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|i| i["label"].as_str().map(String::from))
        .collect();
    for want in ["always", "eventually", "x", "y", "A", "B"] {
        assert!(labels.iter().any(|l| l == want), "{want} missing from {labels:?}");
    }

    // Formatting: one edit to the canonical text.
    let r = c.request(
        "textDocument/formatting",
        json!({ "textDocument": { "uri": URI }, "options": { "tabSize": 4, "insertSpaces": true } }),
    );
    let edits = r.result.unwrap();
    assert_eq!(edits[0]["newText"], hstl::lang::format(FIXED).unwrap());
    assert_eq!(edits[0]["range"]["start"], json!({ "line": 0, "character": 0 }));

    // A malformed request: an error response, and the server goes on.
    let r = c.request("textDocument/hover", json!({ "textDocument": 42 }));
    assert_eq!(r.error.as_ref().map(|e| e.code), Some(lsp_server::ErrorCode::InvalidParams as i32));
    // An internal error: an error response, and the server goes on.
    let r = c.request("hstlc/testPanic", json!({}));
    assert_eq!(r.error.map(|e| e.code), Some(lsp_server::ErrorCode::InternalError as i32));
    let r = c.request("textDocument/frobnicate", json!({}));
    assert_eq!(r.error.map(|e| e.code), Some(lsp_server::ErrorCode::MethodNotFound as i32));
    let r = c.at("textDocument/hover", 99, 0);
    assert!(r.error.is_none());
    // A malformed notification is ignored.
    c.notify("textDocument/didChange", json!({ "nonsense": true }));
    // Formatting a file with syntax errors fails with a message and changes nothing.
    c.change(3, BROKEN);
    let r = c.request("textDocument/formatting", json!({ "textDocument": { "uri": URI }, "options": { "tabSize": 4, "insertSpaces": true } }));
    let e = r.error.expect("formatting refuses");
    assert!(e.message.contains("syntax error at line 5, column 18"), "{}", e.message);

    // Close: the diagnostics clear.
    c.notify("textDocument/didClose", json!({ "textDocument": { "uri": URI } }));
    assert_eq!(c.diagnostics(), Vec::<Value>::new());
    c.shutdown();
}

#[test]
fn utf8_is_used_when_offered() {
    let (mut c, init) =
        Client::start(json!({ "general": { "positionEncodings": ["utf-8", "utf-16"] } }));
    assert_eq!(init["capabilities"]["positionEncoding"], "utf-8");
    let text =
        "spec S {\n    state { x: int in 0..=3 }\n    /* é𝛼 */ let A = x > 1;\n    task B;\n}\n";
    let diags = c.open(text);
    let unknown = diags.iter().find(|d| d["code"] == "HSTL002").expect("unknown name B");
    // `    task B;`: B at byte 9 of line 3.
    assert_eq!(unknown["range"]["start"], json!({ "line": 3, "character": 9 }));
    // Hover on `A` after the multi-byte comment: byte column 21.
    let r = c.at("textDocument/hover", 2, 21);
    let text = r.result.unwrap()["contents"]["value"].to_string();
    assert!(text.contains("let A = x > 1;"), "{text}");
    c.shutdown();
}

/// Every invalid fixture: the published diagnostics are `check`'s, positions in UTF-16.
#[test]
fn diagnostics_match_check_on_every_invalid_fixture() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../hstl-lang/tests/fixtures/invalid");
    let mut files: Vec<_> =
        std::fs::read_dir(&dir).unwrap().filter_map(Result::ok).map(|e| e.path()).collect();
    files.sort();
    assert!(files.len() > 20);
    let (mut c, _) = Client::start(json!({}));
    let mut version = 1;
    c.open("");
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        version += 1;
        let got = c.change(version, &text);
        let want = crate::world_arg::check_source(&text, None, None).0.diagnostics;
        assert_eq!(got.len(), want.len(), "{}", path.display());
        for (g, w) in got.iter().zip(&want) {
            assert_eq!(g["code"], w.code, "{}", path.display());
            assert_eq!(g["range"], lsp_range(&text, &w.range), "{}", path.display());
            let sev = if w.is_error() { 1 } else { 2 };
            assert_eq!(g["severity"], sev);
            assert_eq!(
                g["relatedInformation"].as_array().map_or(0, Vec::len),
                w.labels.len(),
                "{}",
                path.display()
            );
        }
    }
    c.shutdown();
}

/// Typing into an open document (each keystroke re-parses only around the change): the
/// published diagnostics are `check`'s after every keystroke.
#[test]
fn keystrokes_publish_checks_diagnostics() {
    let (mut c, _) = Client::start(json!({}));
    c.open(FIXED);
    let mut text = FIXED.to_string();
    let mut version = 1;
    let at = text.find("let B").expect("let B");
    // Break the line piece by piece, then type it back.
    let typed = "let D = x < 2 && eventually B;\n    ";
    for k in 0..=typed.len() {
        let mut next = FIXED.to_string();
        next.insert_str(at, &typed[..k]);
        version += 1;
        let got = c.change(version, &next);
        let want = hstl::world::check(&next, &hstl::world::GridWorld::default(), "world `paper`")
            .diagnostics;
        let got: Vec<(String, Value)> = got
            .iter()
            .map(|d| (d["code"].as_str().unwrap_or("").to_string(), d["range"].clone()))
            .collect();
        let want: Vec<(String, Value)> =
            want.iter().map(|d| (d.code.to_string(), lsp_range(&next, &d.range))).collect();
        assert_eq!(got, want, "after typing {:?}", &typed[..k]);
        text = next;
    }
    assert!(text.contains("let D"));
    c.shutdown();
}

/// Hover on `preset` shows what it stands for in this spec; on an option, the `avoid` it
/// was given.
#[test]
fn hover_on_preset_shows_its_expansion() {
    const PRESET: &str = "spec R {
    state { x: int in 0..=14, y: int in 0..=14 }
    let Goal = x > 11 && y > 11;
    let Pit = 5 < x < 9 && 5 < y < 9;
    task eventually[0..=30] Goal && always !Pit;
    option Goal;
    learn { preset: auto }
}
";
    let (mut c, _) = Client::start(json!({}));
    assert_eq!(c.open(PRESET), Vec::<Value>::new());
    let (line, col) = pos_of(PRESET, "preset", 0, 2);
    let text =
        c.at("textDocument/hover", line, col).result.unwrap()["contents"]["value"].to_string();
    assert!(text.contains("preset: auto") && text.contains("avoid: Pit"), "{text}");
    assert!(text.contains("episodes: 6000, choices: 10"), "{text}");
    let (line, col) = pos_of(PRESET, "option Goal", 0, 7);
    let text =
        c.at("textDocument/hover", line, col).result.unwrap()["contents"]["value"].to_string();
    assert!(text.contains("- avoid: `Pit`"), "{text}");
    assert!(text.contains("- terminate: `Goal` (from `preset: auto`"), "{text}");
    assert!(text.contains("- init: `true` (default"), "{text}");
    // `preset: paper` (the default) says so.
    let paper = PRESET.replace("preset: auto", "preset: paper");
    c.change(2, &paper);
    let (line, col) = pos_of(&paper, "paper", 0, 1);
    let text =
        c.at("textDocument/hover", line, col).result.unwrap()["contents"]["value"].to_string();
    assert!(text.contains("preset: paper") && text.contains("Table II"), "{text}");
    c.shutdown();
}

/// A tall formula (250 nested `!`, under the parser's height limit) and a long `&&`
/// chain: hover, references and symbols answer from the innermost name outwards (the
/// walks keep their own stacks).
#[test]
fn tall_formulas_are_walked_without_recursion() {
    let nots = "!".repeat(250);
    let chain = vec!["x > 1"; 2000].join(" && ");
    let text = format!(
        "spec S {{\n    state {{ x: int in 0..=3 }}\n    let A = {nots}(x > 2);\n    let B = {chain};\n    task always (A || B);\n}}\n"
    );
    assert!(
        hstl::world::check(&text, &hstl::world::GridWorld::default(), "world `paper`")
            .diagnostics
            .iter()
            .all(|d| !d.is_error())
    );
    let (mut c, _) = Client::start(json!({}));
    c.open(&text);
    // On the `>` inside the 250 `!`.
    let (line, col) = pos_of(&text, "> 2", 0, 0);
    let r = c.at("textDocument/hover", line, col);
    let hover = r.result.unwrap()["contents"]["value"].to_string();
    assert!(hover.contains("how far `e1` is above `e2`"), "{hover}");
    // On a `!` half way in.
    let (line, col) = pos_of(&text, "!", 125, 0);
    let hover =
        c.at("textDocument/hover", line, col).result.unwrap()["contents"]["value"].to_string();
    assert!(hover.contains("(not)"), "{hover}");
    // `x`: declared once, used once in A and 2,000 times in B.
    let (line, col) = pos_of(&text, "x > 2", 0, 0);
    let refs = c.at("textDocument/references", line, col).result.unwrap();
    assert_eq!(refs.as_array().map(Vec::len), Some(2002));
    c.shutdown();
}

/// What [`super::transport::FrameReader`] reads from `input`, frame by frame, up to the
/// end.
fn check_frames(input: &[u8], expect: &[Frame]) {
    let mut reader = FrameReader::new(input);
    let mut got = Vec::new();
    loop {
        let frame = reader.next_frame();
        let end = matches!(frame, Frame::End(_));
        got.push(frame);
        if end {
            break;
        }
        assert!(got.len() <= input.len() + 1, "every frame consumes input");
    }
    assert_eq!(got, expect, "input {:?}", String::from_utf8_lossy(input));
}

#[test]
fn the_frame_reader_skips_what_it_cannot_read_and_finds_the_next_frame() {
    use Frame::*;
    let msg = |s: &str| Message(s.as_bytes().to_vec());
    check_frames(b"", &[End(None)]);
    check_frames(b"Content-Length: 2\r\n\r\n{}", &[msg("{}"), End(None)]);
    // Blank lines between frames, bare LF, any case, spaces, other headers.
    check_frames(
        b"\r\n\r\ncontent-length:2\n\n{}CONTENT-LENGTH :  3 \r\nContent-Type: x\r\n\r\n[1]",
        &[msg("{}"), msg("[1]"), End(None)],
    );
    // The next frame after a bad length starts at the next `Content-Length:`, even one
    // glued to the body before it.
    check_frames(
        b"Content-Length: 2x\r\n\r\n{ ... }Content-Length: 2\r\n\r\n{}",
        &[Skipped(Problem::BadLength("2x".into())), msg("{}"), End(None)],
    );
    check_frames(
        b"Content-Length: 99999999999999999999\r\n\r\n{}",
        &[Skipped(Problem::LengthOverflow), End(None)],
    );
    check_frames(
        b"Content-Type: a\r\n\r\n{}content-LENGTH: 1\r\n\r\n1",
        &[Skipped(Problem::MissingLength), msg("1"), End(None)],
    );
    check_frames(
        b"Content-Length: 2\r\nContent-Length: 3\r\n\r\n{}Content-Length: 1\r\n\r\n1",
        &[Skipped(Problem::ConflictingLengths(2, 3)), msg("1"), End(None)],
    );
    // A wrong header with a usable length: the body is read, to find its id.
    check_frames(
        b"Content-Length: 2\r\nContent-Length: 2\r\n\r\n{}",
        &[BadHeader { problem: Problem::DuplicateLength, body: b"{}".to_vec() }, End(None)],
    );
    check_frames(
        b"Content-Length: 2\r\nno colon\r\n\r\n{}",
        &[
            BadHeader {
                problem: Problem::MalformedHeader("no colon".into()),
                body: b"{}".to_vec(),
            },
            End(None),
        ],
    );
    // Too large: refused at once, the body skipped (up to the end of the input here).
    check_frames(
        b"Content-Length: 67108865\r\n\r\n{}",
        &[
            Skipped(Problem::TooLarge(67_108_865)),
            End(Some(Problem::EndInBody { read: 2, expected: 67_108_865 })),
        ],
    );
    let mut huge = b"Content-Length: 67108865\r\n\r\n".to_vec();
    huge.resize(huge.len() + 67_108_865, b'x');
    huge.extend_from_slice(b"Content-Length: 2\r\n\r\n{}");
    check_frames(&huge, &[Skipped(Problem::TooLarge(67_108_865)), msg("{}"), End(None)]);
    // Headers past 8 KiB.
    let mut long = b"Content-Length: 2\r\nX: ".to_vec();
    long.resize(9000, b'a');
    long.extend_from_slice(b"\r\n\r\n{}Content-Length: 1\r\n\r\n1");
    check_frames(&long, &[Skipped(Problem::HeadersTooLong), msg("1"), End(None)]);
    // Ends inside a frame.
    check_frames(b"Content-Length: 5\r\n", &[End(Some(Problem::EndInHeaders))]);
    check_frames(
        b"Content-Length: 5\r\n\r\n{}",
        &[End(Some(Problem::EndInBody { read: 2, expected: 5 }))],
    );
}

/// `decode(body)` in words.
fn check_decode(body: &[u8], expect: &str) {
    let got = match decode(body) {
        Incoming::Request { id, method, .. } => format!("request {id} {method}"),
        Incoming::Notification { method, .. } => format!("notification {method}"),
        Incoming::Response => "response".to_string(),
        Incoming::Invalid { id: Some(id), code, message } => {
            format!("invalid {} to {id}: {message}", code as i32)
        }
        Incoming::Invalid { id: None, code, message } => {
            format!("invalid {}: {message}", code as i32)
        }
    };
    assert!(got.starts_with(expect), "{:?}: {got}", String::from_utf8_lossy(body));
}

#[test]
fn bodies_decode_to_messages_or_to_errors_with_the_id_when_it_can_be_read() {
    check_decode(br#"{"jsonrpc":"2.0","id":1,"method":"m"}"#, "request 1 m");
    check_decode(br#"{"id":"a","method":"m","params":[]}"#, "request \"a\" m");
    check_decode(
        br#"{"jsonrpc":"2.0","id":18446744073709551615,"method":"m"}"#,
        "request 18446744073709551615 m",
    );
    check_decode(br#"{"jsonrpc":"2.0","method":"exit"}"#, "notification exit");
    check_decode(br#"{"jsonrpc":"2.0","id":1,"result":null}"#, "response");
    check_decode(
        br#"{"jsonrpc":"2.0","id":2,"method":"m"} {"#,
        "invalid -32700 to 2: the message is not valid JSON: trailing characters",
    );
    check_decode(
        b"{\"id\":3,\"method\":\"\xc0\"}",
        "invalid -32700 to 3: the message is not valid UTF-8 (at byte 18)",
    );
    check_decode(b"{\"id\":3,", "invalid -32700: the message is not valid JSON: EOF");
    check_decode(
        br#"{"id":{"x":1},"method":"m"}"#,
        "invalid -32600: the id must be an integer or a string",
    );
    check_decode(br#"{"id":1e3,"method":"m"}"#, "invalid -32600: the id must be");
    check_decode(br#"{"id":-1.5,"method":"m"}"#, "invalid -32600: the id must be");
    check_decode(br#"{"id":4,"method":null}"#, "invalid -32600 to 4: `method` must be a string");
    check_decode(br#"{"id":5,"method":"m","params":1}"#, "invalid -32600 to 5: `params` must be");
    check_decode(br#"{"jsonrpc":2,"id":6,"method":"m"}"#, "invalid -32600 to 6: `jsonrpc` must be");
    check_decode(br#"{"jsonrpc":"2.0"}"#, "invalid -32600: a message needs a `method`");
    check_decode(b"[]", "invalid -32600: a message must be a JSON object");
    check_decode(
        "[".repeat(10_000).as_bytes(),
        "invalid -32700: the message is not valid JSON: recursion limit exceeded",
    );
}

/// Runs `messages` as one stream through [`super::serve_bytes`] (one thread, no timing):
/// how it ended, and each message written, in words, with the messages.
fn session(messages: &[Value]) -> (super::Ending, Vec<String>, Vec<Message>) {
    let mut input = Vec::new();
    for m in messages {
        super::transport::write_frame(&mut input, m.to_string().as_bytes()).unwrap();
    }
    let (output, ending) = super::serve_bytes(&input);
    let mut out = BufReader::new(&output[..]);
    let mut written = Vec::new();
    while let Some(m) = Message::read(&mut out).expect("the server writes frames") {
        written.push(m);
    }
    let words = written
        .iter()
        .map(|m| match m {
            Message::Response(r) => format!("response {}", r.id),
            Message::Notification(n) => {
                let uri =
                    n.params["uri"].as_str().unwrap_or_default().trim_start_matches("file:///");
                format!("{} {uri} {}", n.method, n.params["version"])
            }
            Message::Request(r) => format!("request {}", r.method),
        })
        .collect();
    (ending, words, written)
}

fn open_doc(uri: &str, text: &str) -> Value {
    json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {
        "textDocument": { "uri": uri, "languageId": "hstl", "version": 1, "text": text } } })
}

const INIT: [&str; 2] = [
    r#"{"jsonrpc":"2.0","id":1,"method":"initialize","params":{"capabilities":{}}}"#,
    r#"{"jsonrpc":"2.0","method":"initialized","params":{}}"#,
];

/// A session as one stream, on one thread: 200 changes queued behind each other cost
/// one analysis, of the newest text, before the hover behind them is answered.
#[test]
fn queued_changes_are_coalesced_into_one_analysis() {
    let text = |v: i32| {
        format!(
            "spec S {{\n    state {{ x: int in 0..=3 }}\n    let A = x > {v};\n    task always B{v};\n}}\n"
        )
    };
    let mut messages: Vec<Value> = INIT.iter().map(|m| serde_json::from_str(m).unwrap()).collect();
    messages.push(open_doc(URI, &text(1)));
    for v in 2..=201 {
        messages.push(json!({ "jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
            "textDocument": { "uri": URI, "version": v }, "contentChanges": [{ "text": text(v) }] } }));
    }
    messages.push(json!({ "jsonrpc": "2.0", "id": 2, "method": "textDocument/hover", "params": {
        "textDocument": { "uri": URI }, "position": { "line": 2, "character": 8 } } }));
    messages.push(json!({ "jsonrpc": "2.0", "id": 3, "method": "shutdown" }));
    messages.push(json!({ "jsonrpc": "2.0", "method": "exit" }));
    let (ending, words, written) = session(&messages);
    assert_eq!(ending, super::Ending::Exit);
    assert_eq!(
        words,
        [
            "response 1",
            "textDocument/publishDiagnostics tmp/spec.hstl 201",
            "response 2",
            "response 3"
        ]
    );
    let Message::Response(hover) = &written[2] else { unreachable!() };
    let hover = hover.response_result.as_ref().unwrap()["contents"]["value"].to_string();
    assert!(hover.contains("let A = x > 201;"), "{hover}");
}

/// Idle work follows the documents: a document closed before it was analysed is never
/// analysed, the others are, in the order they changed, once the input is drained.
#[test]
fn idle_analysis_skips_closed_documents_and_keeps_the_order_of_changes() {
    let spec =
        "spec S {\n    state { x: int in 0..=3 }\n    let A = x > 1;\n    task always A;\n}\n";
    let mut messages: Vec<Value> = INIT.iter().map(|m| serde_json::from_str(m).unwrap()).collect();
    for name in ["a", "b", "c", "d"] {
        messages.push(open_doc(&format!("file:///{name}"), spec));
    }
    messages.push(json!({ "jsonrpc": "2.0", "method": "textDocument/didClose", "params": { "textDocument": { "uri": "file:///b" } } }));
    // A request analyses its document now; the rest wait for the idle work.
    messages.push(json!({ "jsonrpc": "2.0", "id": 2, "method": "textDocument/documentSymbol", "params": { "textDocument": { "uri": "file:///c" } } }));
    messages.push(json!({ "jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
        "textDocument": { "uri": "file:///a", "version": 2 }, "contentChanges": [{ "text": spec }] } }));
    let (ending, words, _) = session(&messages);
    assert_eq!(ending, super::Ending::InputClosed);
    assert_eq!(
        words,
        [
            "response 1",
            "textDocument/publishDiagnostics b null",
            "textDocument/publishDiagnostics c 1",
            "response 2",
            "textDocument/publishDiagnostics a 2",
            "textDocument/publishDiagnostics d 1",
        ]
    );
}

/// A spec names its world: the editor reads it relative to the document, underlines a
/// missing one at the item, hovers and goes to the world file, completes names inside the
/// string, and reads the file again when it changes.
#[test]
fn the_world_a_spec_names() {
    let dir = tempfile::tempdir().expect("temp dir");
    let world = dir.path().join("nook.toml");
    std::fs::write(&world, "map = \"\"\"\n.....\n.....\n.....\n.....\n\"\"\"\n").expect("world");
    let spec = "spec Nook {
    world \"nook.toml\";
    state { x: int in 0..=4, y: int in 0..=3 }
    let Corner = x > 2 && y > 1;
    task always[0..] eventually[0..20] Corner;
    option Corner;
}
";
    let (mut c, _) = Client::start(json!({}));
    c.uri = super::worlds::path_uri(&dir.path().join("spec.hstl")).expect("uri").to_string();
    // The world fits: no diagnostics (against `paper` the state would not fit).
    assert_eq!(c.open(spec), Vec::<Value>::new());
    // Hover on the string names the world; go to definition opens its file.
    let (line, col) = pos_of(spec, "nook.toml", 0, 2);
    let hover = c.at("textDocument/hover", line, col).result.expect("hover");
    let text = hover["contents"]["value"].as_str().unwrap_or_default().to_string();
    assert!(text.contains("world `nook`") && text.contains("5 x 4"), "{text}");
    let target = c.at("textDocument/definition", line, col).result.expect("definition");
    let want = super::worlds::path_uri(&world).expect("uri").to_string();
    assert_eq!(target["uri"], want.as_str());
    // Inside the string: the built-in worlds and the world files beside the spec.
    let params =
        json!({ "textDocument": { "uri": c.uri }, "position": { "line": line, "character": col } });
    let items = c.request("textDocument/completion", params).result.expect("completion");
    let labels: Vec<&str> =
        items.as_array().unwrap().iter().filter_map(|i| i["label"].as_str()).collect();
    assert_eq!(labels, ["paper", "four-rooms", "paper-plane", "mountain-car", "nook.toml"]);
    // The world file shrinks: the spec no longer fits, once the editor says files changed.
    std::fs::write(&world, "map = \"\"\"\n...\n...\n\"\"\"\n").expect("world");
    c.notify("workspace/didChangeWatchedFiles", json!({ "changes": [] }));
    let diags = c.diagnostics();
    assert!(diags.iter().any(|d| d["code"] == "HSTL030"), "{diags:#?}");
    // A missing world: HSTL034 at the item, beside the spec's own diagnostics.
    let missing =
        spec.replace("nook.toml", "nowhere.toml").replace("option Corner;", "option Cornr;");
    let diags = c.change(3, &missing);
    let codes: Vec<&str> = diags.iter().filter_map(|d| d["code"].as_str()).collect();
    assert!(codes.contains(&"HSTL034") && codes.contains(&"HSTL010"), "{codes:?}");
    let at = diags.iter().find(|d| d["code"] == "HSTL034").expect("HSTL034");
    let (line, col) = pos_of(&missing, "\"nowhere.toml\"", 0, 0);
    assert_eq!(at["range"]["start"], json!({ "line": line, "character": col }));
    c.shutdown();
}

/// Issue 30: the server kept every open document analysed (12 documents took 3.3 GB). The
/// analysed text stays within `MAX_ANALYSED_BYTES` whatever the client opens: the analyses
/// used least recently are dropped, and a request on one of those documents analyses it
/// again and answers as before.
#[test]
fn the_analysed_documents_stay_within_their_budget() {
    use super::server::{Log, Server};
    use super::transport::{Id, Incoming};
    // The budget scaled down with the documents (16 MiB against 4 MiB documents).
    const MAX_ANALYSED_BYTES: usize = 200_000;
    let mut server = Server::with_analysed_budget(Log::quiet(), MAX_ANALYSED_BYTES);
    let mut out: Vec<u8> = Vec::new();
    let note =
        |method: &str, params: Value| Incoming::Notification { method: method.to_string(), params };
    let init: Value = serde_json::from_str(INIT[0]).unwrap();
    server.handle(
        Incoming::Request {
            id: Id::Number(1.into()),
            method: "initialize".into(),
            params: init["params"].clone(),
        },
        &mut out,
    );
    server.handle(note("initialized", json!({})), &mut out);
    // Each document about 60 KB of lets.
    let doc = |k: usize| {
        let lets: String = (0..2_500).map(|i| format!("    let L{i} = x > {};\n", i % 7)).collect();
        format!("spec S{k} {{\n    state {{ x: int in 0..=9 }}\n{lets}    task always L1;\n}}\n")
    };
    let text = doc(0);
    assert!(text.len() > 50_000 && text.len() < 70_000, "{}", text.len());
    let documents = 8;
    for k in 0..documents {
        let uri = format!("file:///d{k}.hstl");
        server.handle(
            note("textDocument/didOpen", open_doc(&uri, &doc(k))["params"].clone()),
            &mut out,
        );
        while server.has_idle_work() {
            server.idle_step(&mut out);
        }
        let (n, bytes) = server.analysed();
        assert!(bytes <= MAX_ANALYSED_BYTES, "{n} documents, {bytes} bytes analysed");
        assert!(n >= 1);
    }
    assert!(documents * text.len() > MAX_ANALYSED_BYTES, "the budget is passed");
    // The first document's analysis was dropped; a hover analyses it again.
    out.clear();
    server.handle(
        Incoming::Request {
            id: Id::Number(2.into()),
            method: "textDocument/hover".into(),
            params: json!({ "textDocument": { "uri": "file:///d0.hstl" },
                            "position": { "line": 3, "character": 9 } }),
        },
        &mut out,
    );
    let answer = String::from_utf8_lossy(&out);
    assert!(answer.contains("let L1 = x > 1"), "{}", &answer[..answer.len().min(500)]);
    let (_, bytes) = server.analysed();
    assert!(bytes <= MAX_ANALYSED_BYTES, "{bytes}");
}
