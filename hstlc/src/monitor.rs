//! `hstlc monitor`: the robustness of a recorded trace.
//!
//! Exit status: 0 with the result on standard output; 1 when the spec has errors (its
//! diagnostics go to standard error, as `check` renders them); 2 when the command could not
//! run: an unreadable file, a malformed trace, an unknown `--formula` or `--spec`. On 1 and 2
//! nothing is printed to standard output.

use std::io::{BufReader, Write};
use std::path::{Path, PathBuf};

use clap::Args;
use hstl::lang::{CheckedSpec, Domain, VarType};
use hstl::monitor::Monitor;

use crate::cli_error::CliError;
use crate::output::errln;
use crate::trace_csv::{Column, ColumnKind, ReadError, TraceRead};
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
    let read = read_trace(&args.trace, spec)?;
    if !read.ignored.is_empty() {
        let names: Vec<String> = read.ignored.iter().map(|n| format!("`{n}`")).collect();
        let (what, verb) = if names.len() == 1 {
            ("column", "is not a state variable")
        } else {
            ("columns", "are not state variables")
        };
        errln!("note: {what} {} {verb} of `{}`: ignored", names.join(", "), spec.name);
    }
    let trace = read.trace;

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
    // A signal can be long: it goes through its own buffer, its errors as all output's.
    written.map_err(crate::output::stdout_error)?;
    Ok(Status::Clean)
}

/// Reads the trace at `path` (standard input for `-`) for the state variables of `spec`.
fn read_trace(path: &Path, spec: &CheckedSpec) -> Result<TraceRead, CliError> {
    let columns: Vec<Column<'_>> = spec
        .state_vars
        .iter()
        .map(|v| Column {
            name: &v.name,
            kind: match (v.ty, &v.domain) {
                (_, Domain::Int { lo, hi }) => ColumnKind::Int(Some((*lo, *hi))),
                (VarType::Int, _) => ColumnKind::Int(None),
                _ => ColumnKind::Real,
            },
        })
        .collect();
    let (name, read) = if path == Path::new("-") {
        ("<stdin>".to_string(), trace_csv::read_trace(std::io::stdin().lock(), &columns))
    } else {
        let file = std::fs::File::open(path)
            .map_err(|source| CliError::Read { path: path.to_path_buf(), source })?;
        (path.display().to_string(), trace_csv::read_trace(BufReader::new(file), &columns))
    };
    read.map_err(|e| match e {
        ReadError::Io(source) => CliError::Read { path: PathBuf::from(&name), source },
        ReadError::Csv(e) => {
            CliError::new(format!("{name}:{}:{}: {}", e.line, e.column, e.message), e.help)
        }
    })
}
