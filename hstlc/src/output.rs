//! Standard output and standard error of the commands, every write checked.
//!
//! Commands print through [`out!`] and [`outln!`] (like `print!` and `println!`, but a
//! `Result`): a write that fails stops the command with an error (exit status 2 and one
//! line on standard error: a full disk, `/dev/full`), and a reader that stopped reading
//! (`hstlc fmt a b c | head -1`) ends it quietly with status 141, what a shell reports for a
//! Unix tool stopped by a closed pipe (128 + SIGPIPE). Messages for people go to standard
//! error through [`errln!`] and [`err!`], whose failures are ignored: nobody is left to tell.

use std::io::Write;
use std::path::PathBuf;

use crate::cli_error::CliError;

/// The exit status of a command whose reader closed standard output.
pub const BROKEN_PIPE_STATUS: u8 = 141;

/// Writes to standard output, like `print!`; `Err` when the write fails.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::output::print(format_args!($($arg)*))
    };
}

/// Writes a line to standard output, like `println!`; `Err` when the write fails.
macro_rules! outln {
    () => {
        $crate::output::print(format_args!("\n"))
    };
    ($($arg:tt)*) => {
        $crate::output::print(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// Writes to standard error, like `eprint!`, ignoring failures.
macro_rules! err {
    ($($arg:tt)*) => {
        $crate::output::eprint(format_args!($($arg)*))
    };
}

/// Writes a line to standard error, like `eprintln!`, ignoring failures.
macro_rules! errln {
    ($($arg:tt)*) => {
        $crate::output::eprint(format_args!("{}\n", format_args!($($arg)*)))
    };
}

/// Writes `args` to standard output (line-buffered: [`flush`] at the end).
pub fn print(args: std::fmt::Arguments<'_>) -> Result<(), CliError> {
    std::io::stdout().lock().write_fmt(args).map_err(stdout_error)
}

/// Writes out what standard output still buffers.
pub fn flush() -> Result<(), CliError> {
    std::io::stdout().lock().flush().map_err(stdout_error)
}

/// Writes `args` to standard error; a failure is ignored.
pub fn eprint(args: std::fmt::Arguments<'_>) {
    let _ = std::io::stderr().lock().write_fmt(args);
}

/// The error of a failed write to standard output.
pub fn stdout_error(source: std::io::Error) -> CliError {
    CliError::Write { path: PathBuf::from("<stdout>"), source }
}

/// Whether `e` is standard output's reader going away (a broken pipe).
pub fn is_broken_pipe(e: &CliError) -> bool {
    matches!(e, CliError::Write { source, .. } if source.kind() == std::io::ErrorKind::BrokenPipe)
}

pub(crate) use {err, errln, out, outln};

/// A path as messages show it: its control characters escaped (see
/// [`hstl::load::escape_controls`]).
pub fn shown(path: &std::path::Path) -> String {
    hstl::load::path_words(path)
}
