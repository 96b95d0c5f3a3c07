//! The CLI's CSV trace reader on any bytes, for a real and a ranged `int` column: never a
//! panic; a trace it accepts has one value per row and column, each a number (no NaN), the
//! `int` ones whole and in range; an error names a line and column inside the input.
use hstlc::trace_csv::{Column, ColumnKind, ReadError, read_trace};

/// The property; panics when it fails.
pub fn check(data: &[u8]) {
    let vars = [
        Column { name: "x", kind: ColumnKind::Real },
        Column { name: "k", kind: ColumnKind::Int(Some((-3, 14))) },
    ];
    match read_trace(data, &vars) {
        Ok(read) => {
            let t = &read.trace;
            assert!(!t.is_empty());
            assert!(t.column(0).iter().all(|v| !v.is_nan()));
            assert!(t.column(1).iter().all(|v| v.fract() == 0.0 && (-3.0..=14.0).contains(v)));
            assert!(read.ignored.iter().all(|n| n != "x" && n != "k" && !n.is_empty()));
        }
        Err(ReadError::Csv(e)) => {
            let lines = data.iter().filter(|&&b| b == b'\n' || b == b'\r').count() + 1;
            assert!(e.line >= 1 && e.line <= lines, "line {} of {lines}", e.line);
            assert!(e.column >= 1 && e.column <= data.len() + 1, "column {}", e.column);
            assert!(!e.message.ends_with('.'), "{}", e.message);
        }
        Err(ReadError::Io(e)) => panic!("reading a slice failed: {e}"),
    }
}
