//! `hstlc`, the hstl command line, as a library: [`run`] is the whole program, which the
//! binary (`src/main.rs`) and the Python package's `hstlc` command (`hstl._hstl.cli`) both
//! call, so the two print the same and exit alike. The language server behind `hstlc lsp`,
//! the CSV trace reader of `hstlc monitor`, and what both share with the commands (bounded
//! file reads, worlds by name or file) are public too, so that the fuzz targets (`fuzz/` at
//! the repository root) and their smoke test drive the same code as the binary.

mod check;
pub mod cli_error;
mod eval;
mod explain;
mod fmt;
pub mod input;
pub mod lsp;
mod monitor;
mod monitor_dense;
mod monitor_input;
mod output;
mod render;
mod spec_file;
mod study;
pub mod trace_csv;
mod train;
pub mod world_arg;

use std::ffi::OsString;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::cli_error::CliError;

/// Check, monitor and learn from hstl task specs.
#[derive(Parser, Debug)]
#[command(name = "hstlc", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Check spec files and print their diagnostics.
    Check(check::CheckArgs),
    /// Print the long explanation of a diagnostic code, such as HSTL003.
    Explain(explain::ExplainArgs),
    /// Print spec files in the canonical layout (or check or rewrite them).
    Fmt(fmt::FmtArgs),
    /// Run the language server on standard input and output.
    Lsp,
    /// Score a trace (CSV) against the task or a `let`.
    Monitor(monitor::MonitorArgs),
    /// Learn a hierarchical policy for a spec; write policy.json, curve.csv and pictures.
    Train(train::TrainArgs),
    /// Replay a trained policy.json and report how well it keeps the task.
    Eval(eval::EvalArgs),
    /// Train several specs over many seeds and compare them (the paper's case study).
    Study(study::StudyArgs),
}

/// Runs `hstlc` with the command line `args` (the program's name first, as
/// [`std::env::args_os`] gives it) and returns its exit status: what the `hstlc` binary
/// does, and what the Python package's `hstlc` command calls. It prints to this process's
/// standard output and error and reads its standard input.
///
/// Exit status: 0 when the command succeeded (warnings allowed), 1 when the input has
/// errors, 2 when the command could not run (a missing file, a bad flag, a failed write),
/// 141 when the reader of standard output stopped reading (see the `output` module).
pub fn run<I, T>(args: I) -> u8
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            // clap prints help and version to stdout with status 0, usage errors with 2.
            let status = if e.use_stderr() { 2 } else { 0 };
            return match e.print() {
                Ok(()) => status,
                Err(source) => exit_on(&output::stdout_error(source)),
            };
        }
    };
    let result = match cli.command {
        Command::Check(args) => check::run(&args),
        Command::Explain(args) => explain::run(&args),
        Command::Fmt(args) => fmt::run(&args),
        Command::Lsp => lsp_command(),
        Command::Monitor(args) => monitor::run(&args),
        Command::Train(args) => train::run(&args),
        Command::Eval(args) => eval::run(&args),
        Command::Study(args) => study::run(&args),
    };
    // What standard output still buffers is written before the status is decided.
    match result.and_then(|status| output::flush().map(|()| status)) {
        Ok(status) => status.code(),
        Err(e) => exit_on(&e),
    }
}

/// `hstlc lsp`: status 0 after `shutdown` then `exit`, 1 when the client exits without
/// `shutdown` or goes away.
fn lsp_command() -> CmdResult {
    match lsp::run() {
        Ok(ending) if ending.is_clean() => Ok(Status::Clean),
        Ok(_) => Ok(Status::Errors),
        Err(e) => Err(CliError::new(format!("cannot start the language server: {e}"), None)),
    }
}

/// The exit status for an error that stopped a command: quiet status 141 when the reader of
/// standard output went away (see [`output`]), else the error on standard error and 2.
fn exit_on(e: &CliError) -> u8 {
    if output::is_broken_pipe(e) {
        return output::BROKEN_PIPE_STATUS;
    }
    output::errln!("{}", render::cli_error(e));
    2
}

/// How a command that ran went.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Nothing wrong (warnings allowed).
    Clean,
    /// The input has errors.
    Errors,
}

impl Status {
    /// The exit status: 0 for [`Status::Clean`], 1 for [`Status::Errors`].
    pub fn code(self) -> u8 {
        match self {
            Status::Clean => 0,
            Status::Errors => 1,
        }
    }
}

impl From<Status> for ExitCode {
    fn from(s: Status) -> ExitCode {
        ExitCode::from(s.code())
    }
}

/// The result of a command: a status, or an error that kept it from running.
pub type CmdResult = Result<Status, CliError>;
