//! `hstlc`: the hstl command line.
//!
//! Exit status: 0 when the command succeeded (warnings allowed), 1 when the input has
//! errors, 2 when the command could not run (a missing file, a bad flag, a failed write),
//! 141 when the reader of standard output stopped reading (see [`output`]).

mod check;
use hstlc::cli_error;
mod eval;
mod explain;
mod fmt;
use hstlc::input;
mod monitor;
mod monitor_dense;
mod output;
mod render;
mod spec_file;
mod study;
use hstlc::trace_csv;
mod train;
use hstlc::world_arg;

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

fn main() -> ExitCode {
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            // clap prints help and version to stdout with status 0, usage errors with 2.
            let status = if e.use_stderr() { 2 } else { 0 };
            return match e.print() {
                Ok(()) => ExitCode::from(status),
                Err(source) => exit_on(&output::stdout_error(source)),
            };
        }
    };
    let result = match cli.command {
        Command::Check(args) => check::run(&args),
        Command::Explain(args) => explain::run(&args),
        Command::Fmt(args) => fmt::run(&args),
        Command::Lsp => lsp(),
        Command::Monitor(args) => monitor::run(&args),
        Command::Train(args) => train::run(&args),
        Command::Eval(args) => eval::run(&args),
        Command::Study(args) => study::run(&args),
    };
    // What standard output still buffers is written before the status is decided.
    match result.and_then(|status| output::flush().map(|()| status)) {
        Ok(status) => status.into(),
        Err(e) => exit_on(&e),
    }
}

/// `hstlc lsp`: status 0 after `shutdown` then `exit`, 1 when the client exits without
/// `shutdown` or goes away.
fn lsp() -> CmdResult {
    match hstlc::lsp::run() {
        Ok(ending) if ending.is_clean() => Ok(Status::Clean),
        Ok(_) => Ok(Status::Errors),
        Err(e) => Err(CliError::new(format!("cannot start the language server: {e}"), None)),
    }
}

/// The exit status for an error that stopped a command: quiet status 141 when the reader of
/// standard output went away (see [`output`]), else the error on standard error and 2.
fn exit_on(e: &CliError) -> ExitCode {
    if output::is_broken_pipe(e) {
        return ExitCode::from(output::BROKEN_PIPE_STATUS);
    }
    output::errln!("{}", render::cli_error(e));
    ExitCode::from(2)
}

/// How a command that ran went.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Nothing wrong (warnings allowed).
    Clean,
    /// The input has errors.
    Errors,
}

impl From<Status> for ExitCode {
    fn from(s: Status) -> ExitCode {
        match s {
            Status::Clean => ExitCode::SUCCESS,
            Status::Errors => ExitCode::from(1),
        }
    }
}

/// The result of a command: a status, or an error that kept it from running.
pub type CmdResult = Result<Status, CliError>;
