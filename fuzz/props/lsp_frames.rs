//! The language server's frame reader on any bytes: it ends, every frame it returns
//! consumed input, no body is over the limit, and decoding a body never panics. Then a
//! round trip: the input cut at `0xff` bytes into bodies, framed, reads back as exactly
//! those bodies.
use hstlc::lsp::MAX_MESSAGE_BYTES;
use hstlc::lsp::transport::{Frame, FrameReader, Incoming, write_frame};

/// The property; panics when it fails.
pub fn check(data: &[u8]) {
    let mut reader = FrameReader::new(data);
    let mut frames = 0;
    loop {
        let frame = reader.next_frame();
        frames += 1;
        // Each frame but the last consumed at least its header.
        assert!(frames <= data.len() + 1, "the reader does not advance");
        match &frame {
            Frame::End(_) => break,
            Frame::Message(body) | Frame::BadHeader { body, .. } => {
                assert!(body.len() as u64 <= MAX_MESSAGE_BYTES);
            }
            Frame::Skipped(_) => {}
        }
        let _ = Incoming::from_frame(frame);
    }

    let bodies: Vec<&[u8]> = data.split(|&b| b == 0xff).collect();
    let mut stream = Vec::new();
    for body in &bodies {
        write_frame(&mut stream, body).expect("writing to memory");
    }
    let mut reader = FrameReader::new(&stream[..]);
    for body in &bodies {
        assert_eq!(reader.next_frame(), Frame::Message(body.to_vec()));
    }
    assert_eq!(reader.next_frame(), Frame::End(None));
}
