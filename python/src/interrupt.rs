//! Long calls that Ctrl-C ends. The work runs on a thread of its own while the calling
//! thread, holding the GIL only for a moment every [`SIGNAL_EVERY`], runs Python's signal
//! handlers: a `KeyboardInterrupt` ends the call at once. The work's thread is then told to
//! stop ([`hstl::robustness::cancel`]): the evaluators and the scan of a trace for NaN
//! comparisons stop within a few milliseconds, other work finishes; either way its result
//! is dropped, and it holds only what was moved into it.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use pyo3::prelude::*;

use crate::errors::value_error;

/// How often a watched call runs Python's signal handlers.
pub const SIGNAL_EVERY: Duration = Duration::from_millis(100);

/// Work over fewer values than this runs on the calling thread with the GIL released: it
/// ends within a few milliseconds, and a thread of its own would cost more than it saves.
pub const WATCHED_VALUES: usize = 1 << 20;

/// Runs `work` with the GIL released, on a thread of its own when it reads `values` or
/// more values, so that Ctrl-C (or any signal handler that raises) ends the call.
pub fn run<T: Send + 'static>(
    py: Python<'_>,
    values: usize,
    work: impl FnOnce() -> T + Send + 'static,
) -> PyResult<T> {
    if values < WATCHED_VALUES {
        return Ok(py.detach(work));
    }
    let (tx, rx) = mpsc::channel();
    let stop = Arc::new(AtomicBool::new(false));
    let raised = Arc::clone(&stop);
    std::thread::Builder::new()
        .name("hstl-evaluate".into())
        .spawn(move || {
            let _watch = hstl::robustness::cancel::stop_on(raised);
            // The receiver is gone when the call was interrupted: nothing to send to.
            let _ = tx.send(work());
        })
        .map_err(|e| value_error(format!("cannot start a thread to evaluate on: {e}"), None))?;
    wait(py, rx, || stop.store(true, Ordering::Relaxed), "the evaluating thread failed")
}

/// What a thread sends on `rx`, waited for with the GIL released and taken back every
/// [`SIGNAL_EVERY`] to run Python's signal handlers: when one raises, `on_interrupt` is
/// called (to tell the thread to stop) and the call ends with its exception; `failed` words
/// a thread that ended without sending.
pub fn wait<T: Send>(
    py: Python<'_>,
    rx: mpsc::Receiver<T>,
    on_interrupt: impl FnOnce(),
    failed: &str,
) -> PyResult<T> {
    let mut rx = rx;
    loop {
        // The receiver goes along and back: it may not be shared with the GIL released.
        let (back, got) = py.detach(move || {
            let got = rx.recv_timeout(SIGNAL_EVERY);
            (rx, got)
        });
        rx = back;
        match got {
            Ok(done) => return Ok(done),
            Err(mpsc::RecvTimeoutError::Timeout) => {
                if let Err(e) = py.check_signals() {
                    on_interrupt();
                    return Err(e);
                }
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => return Err(value_error(failed, None)),
        }
    }
}
