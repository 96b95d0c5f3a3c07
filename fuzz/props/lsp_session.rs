//! A whole language server session, run on one thread by `hstlc::lsp::serve_bytes`: the
//! same reader, decoder and server as `hstlc lsp`. The input is a sequence of message
//! bodies cut at `0xff` bytes, each framed correctly (the frame reader has its own
//! target); an input starting with `raw:` is the byte stream itself.
//!
//! Checked: the server never panics (libFuzzer aborts on any panic, even a caught one),
//! writes only well-formed frames of JSON-RPC 2.0 objects, and answers every request
//! (and every malformed message whose id can be read) before `exit` exactly once.
use std::collections::HashMap;

use hstlc::lsp::serve_bytes;
use hstlc::lsp::transport::{Frame, FrameReader, Incoming, write_frame};
use serde_json::Value;

/// The property; panics when it fails.
pub fn check(data: &[u8]) {
    let stream = match data.strip_prefix(b"raw:") {
        Some(raw) => raw.to_vec(),
        None => {
            let mut stream = Vec::new();
            for body in data.split(|&b| b == 0xff) {
                write_frame(&mut stream, body).expect("writing to memory");
            }
            stream
        }
    };

    // What must be answered: requests and malformed messages with an id, up to `exit`.
    let mut expected: HashMap<String, usize> = HashMap::new();
    let mut reader = FrameReader::new(&stream[..]);
    loop {
        let frame = reader.next_frame();
        if let Frame::End(_) = frame {
            break;
        }
        match Incoming::from_frame(frame) {
            Some(Incoming::Request { id, .. }) | Some(Incoming::Invalid { id: Some(id), .. }) => {
                *expected.entry(id.to_json().to_string()).or_default() += 1;
            }
            Some(m) if m.is_exit() => break,
            _ => {}
        }
    }

    let (output, _ending) = serve_bytes(&stream);

    let mut answered: HashMap<String, usize> = HashMap::new();
    let mut reader = FrameReader::new(&output[..]);
    loop {
        match reader.next_frame() {
            Frame::Message(body) => {
                let message: Value = serde_json::from_slice(&body).expect("the server writes JSON");
                assert_eq!(message["jsonrpc"], "2.0", "{message}");
                match message.get("id") {
                    Some(id) => {
                        let result = message.get("result").is_some();
                        let error = message.get("error").is_some();
                        assert!(result != error, "one of result and error: {message}");
                        *answered.entry(id.to_string()).or_default() += 1;
                    }
                    None => assert!(message["method"].is_string(), "{message}"),
                }
            }
            Frame::End(None) => break,
            other => panic!("the server wrote a malformed frame: {other:?}"),
        }
    }
    assert_eq!(answered, expected);
}
