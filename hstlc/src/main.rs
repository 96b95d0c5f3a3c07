//! `hstlc`: the hstl command line. The program is the library's [`hstlc::run`].
//!
//! Exit status: 0 when the command succeeded (warnings allowed), 1 when the input has
//! errors, 2 when the command could not run (a missing file, a bad flag, a failed write),
//! 141 when the reader of standard output stopped reading.

use std::process::ExitCode;

fn main() -> ExitCode {
    ExitCode::from(hstlc::run(std::env::args_os()))
}
