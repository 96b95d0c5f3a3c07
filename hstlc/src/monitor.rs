//! `hstlc monitor`: the robustness of a recorded trace.
//!
//! Exit status: 0 with the result on standard output; 1 when the spec has errors (its
//! diagnostics go to standard error, as `check` renders them); 2 when the command could not
//! run: an unreadable file, a malformed trace, an unknown `--formula` or `--spec`. On 1 and 2
//! nothing is printed to standard output.

use std::io::Write;
use std::path::PathBuf;

use clap::Args;
use hstl::monitor::Monitor;

use crate::check::read_input;
use crate::cli_error::CliError;
use crate::{CmdResult, Status, spec_file, trace_csv};

/// Arguments of `hstlc monitor`.
#[derive(Args, Debug)]
pub struct MonitorArgs {
    /// The spec file (`-` reads standard input).
    #[arg(value_name = "SPEC")]
    pub spec: PathBuf,
    /// The trace: a CSV file whose header names the state variables (`-` reads standard
    /// input).
    #[arg(long, value_name = "FILE.csv")]
    pub trace: PathBuf,
    /// Score this `let` instead of the task.
    #[arg(long, value_name = "NAME")]
    pub formula: Option<String>,
    /// Print `t,robustness` rows for every step instead of the value at step 0.
    #[arg(long)]
    pub signal: bool,
    /// The spec to use when the file holds more than one.
    #[arg(long = "spec", value_name = "NAME")]
    pub spec_name: Option<String>,
}

/// Runs `hstlc monitor`.
pub fn run(args: &MonitorArgs) -> CmdResult {
    if args.spec.as_os_str() == "-" && args.trace.as_os_str() == "-" {
        return Err(CliError::new(
            "the spec and the trace cannot both come from standard input",
            Some("pass at least one of them as a file".to_string()),
        ));
    }
    let Some(loaded) = spec_file::load(&args.spec, args.spec_name.as_deref(), None)? else {
        return Ok(Status::Errors);
    };
    let (trace_name, trace_text) = read_input(&args.trace, "<stdin>")?;
    let (spec, name) = (&loaded.spec, &loaded.file);
    let monitor = Monitor::new(spec, args.formula.as_deref()).map_err(|e| {
        let help = match &e {
            hstl::lower::LowerError::UnknownLet { .. } => {
                Some("leave out `--formula` to score the task".to_string())
            }
            hstl::lower::LowerError::Invalid { .. } => None,
        };
        CliError::new(format!("{name}: {e}"), help)
    })?;
    let vars: Vec<&str> = monitor.state_vars().iter().map(String::as_str).collect();
    let trace = trace_csv::read_trace(&trace_text, &vars).map_err(|e| {
        CliError::new(format!("{trace_name}:{}:{}: {}", e.line, e.column, e.message), e.help)
    })?;

    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let written = if args.signal {
        let signal = monitor.signal_of_trace(&trace);
        writeln!(out, "t,robustness").and_then(|()| {
            signal.iter().enumerate().try_for_each(|(t, v)| writeln!(out, "{t},{v}"))
        })
    } else {
        writeln!(out, "{}", monitor.robustness_of_trace(&trace))
    }
    .and_then(|()| out.flush());
    match written {
        // A reader that stopped early (`| head`) is not an error.
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(CliError::Write { path: PathBuf::from("<stdout>"), source: e })
        }
        _ => Ok(Status::Clean),
    }
}
