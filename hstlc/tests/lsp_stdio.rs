//! `hstlc lsp` as a process, JSON-RPC over pipes: a frame that is not JSON and a request
//! of the wrong shape are answered or skipped, and the server goes on to answer the next
//! requests; `shutdown` then `exit` ends it with status 0, `exit` alone with status 1.

use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

use serde_json::{Value, json};

struct Server {
    child: Child,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
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
        let stdin = child.stdin.take().expect("stdin");
        let stdout = BufReader::new(child.stdout.take().expect("stdout"));
        Server { child, stdin, stdout }
    }

    fn send_raw(&mut self, body: &str) {
        write!(self.stdin, "Content-Length: {}\r\n\r\n{body}", body.len()).expect("write");
        self.stdin.flush().expect("flush");
    }

    fn send(&mut self, message: Value) {
        self.send_raw(&message.to_string());
    }

    fn recv(&mut self) -> Value {
        let mut length = 0;
        loop {
            let mut line = String::new();
            assert!(self.stdout.read_line(&mut line).expect("read") > 0, "server closed stdout");
            let line = line.trim_end();
            if line.is_empty() {
                break;
            }
            if let Some(v) = line.strip_prefix("Content-Length: ") {
                length = v.parse().expect("length");
            }
        }
        let mut body = vec![0; length];
        self.stdout.read_exact(&mut body).expect("body");
        serde_json::from_slice(&body).expect("JSON from the server")
    }

    /// The next message that is not a notification.
    fn response(&mut self) -> Value {
        loop {
            let m = self.recv();
            if m.get("id").is_some() {
                return m;
            }
        }
    }

    fn finish(mut self) -> (Option<i32>, String) {
        drop(self.stdin);
        let status = self.child.wait().expect("wait");
        let mut stderr = String::new();
        if let Some(mut e) = self.child.stderr.take() {
            let _ = e.read_to_string(&mut stderr);
        }
        (status.code(), stderr)
    }
}

const URI: &str = "file:///tmp/s.hstl";

#[test]
fn malformed_messages_do_not_stop_the_server() {
    let mut s = Server::start();
    s.send(json!({ "jsonrpc": "2.0", "id": 1, "method": "initialize", "params": { "capabilities": {} } }));
    let init = s.response();
    assert_eq!(init["id"], 1);
    assert!(init["result"]["capabilities"]["hoverProvider"].as_bool().unwrap_or(false));
    s.send(json!({ "jsonrpc": "2.0", "method": "initialized", "params": {} }));

    // Not JSON at all: logged and skipped.
    s.send_raw("{this is not json");
    // JSON, but not a request: an error response for its id.
    s.send(json!({ "jsonrpc": "2.0", "id": 7, "method": 5 }));
    let r = s.response();
    assert_eq!(r["id"], 7);
    assert_eq!(r["error"]["code"], -32600);
    // A request with bad parameters: an error response.
    s.send(json!({ "jsonrpc": "2.0", "id": 8, "method": "textDocument/hover", "params": [] }));
    let r = s.response();
    assert_eq!(r["id"], 8);
    assert_eq!(r["error"]["code"], -32602);

    // The server still works.
    let text =
        "spec S {\n    state { x: int in 0..=3 }\n    let A = x > 1\n    task always A;\n}\n";
    s.send(json!({ "jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {
        "textDocument": { "uri": URI, "languageId": "hstl", "version": 1, "text": text } } }));
    let diags = s.recv();
    assert_eq!(diags["method"], "textDocument/publishDiagnostics");
    assert_eq!(diags["params"]["diagnostics"][0]["code"], "HSTL001");
    s.send(json!({ "jsonrpc": "2.0", "id": 9, "method": "textDocument/hover", "params": {
        "textDocument": { "uri": URI }, "position": { "line": 3, "character": 10 } } }));
    let r = s.response();
    assert_eq!(r["id"], 9);
    let hover = r["result"]["contents"]["value"].as_str().unwrap_or_default();
    assert!(hover.contains("always"), "{r}");

    s.send(json!({ "jsonrpc": "2.0", "id": 10, "method": "shutdown" }));
    assert_eq!(s.response()["id"], 10);
    s.send(json!({ "jsonrpc": "2.0", "method": "exit" }));
    let (code, stderr) = s.finish();
    assert_eq!(code, Some(0), "{stderr}");
    assert!(stderr.contains("malformed message"), "{stderr}");
}

#[test]
fn exit_without_shutdown_is_status_1() {
    let mut s = Server::start();
    s.send(json!({ "jsonrpc": "2.0", "id": 1, "method": "initialize", "params": { "capabilities": {} } }));
    s.response();
    s.send(json!({ "jsonrpc": "2.0", "method": "initialized", "params": {} }));
    s.send(json!({ "jsonrpc": "2.0", "method": "exit" }));
    let (code, _) = s.finish();
    assert_eq!(code, Some(1));
}

#[test]
fn requests_before_initialize_are_refused_and_end_of_input_ends_the_server() {
    let mut s = Server::start();
    s.send(json!({ "jsonrpc": "2.0", "id": 1, "method": "textDocument/hover", "params": {} }));
    let r = s.response();
    assert_eq!(r["id"], 1);
    assert_eq!(r["error"]["code"], -32002, "{r}");
    // The client goes away without a word: the server ends (it could not finish).
    let (code, stderr) = s.finish();
    assert_eq!(code, Some(2), "{stderr}");
}
