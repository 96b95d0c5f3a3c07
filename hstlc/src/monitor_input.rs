//! What `hstlc monitor` takes in, shared by its discrete (`monitor`) and dense-time
//! (`monitor_dense`) paths: the arguments, the trace files, the CSV columns a spec reads,
//! and the notes and errors about reading them. Both paths import it; neither imports the
//! other's helpers.

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use hstl::lang::{CheckedSpec, Domain, VarType};

use crate::cli_error::CliError;
use crate::output::errln;
use crate::trace_csv::{Column, ColumnKind, ReadError};

/// Arguments of `hstlc monitor`.
#[derive(Args, Debug)]
pub struct MonitorArgs {
    /// The spec file (`-` reads standard input).
    #[arg(value_name = "SPEC")]
    pub spec: PathBuf,
    /// The trace: a CSV file whose header names the state variables (`-` reads standard
    /// input); for a dense-time spec also its time variable, whose column holds each row's
    /// time stamp (an empty cell of another column: no new sample). Give it more than once, or a folder (its `.csv` files), to score many
    /// traces: one `trace,robustness` row each.
    #[arg(long, value_name = "FILE.csv|DIR", required = true)]
    pub trace: Vec<PathBuf>,
    /// Score this `let` instead of the task.
    #[arg(long, value_name = "NAME")]
    pub formula: Option<String>,
    /// Print `t,robustness` rows for every step instead of the value at step 0 (for a
    /// dense-time spec: at every change point of the signal, times in the time column's
    /// scale).
    #[arg(long)]
    pub signal: bool,
    /// Read the trace as a stream (a pipe from a live system) and print each step's
    /// `t,robustness` row as soon as its value is final, in memory bounded by the formula's
    /// horizon.
    #[arg(long, conflicts_with = "signal")]
    pub online: bool,
    /// The spec to use when the file holds more than one.
    #[arg(long = "spec", value_name = "NAME")]
    pub spec_name: Option<String>,
    /// Windows at the trace's end: `clipped` (rtamt's semantics) cuts them short;
    /// `complete` counts a step only if every window it needs lies inside the trace, and
    /// leaves later steps undetermined (empty in `--signal` rows). See docs/LANGUAGE.md.
    #[arg(long, value_enum, default_value_t = Windows::Clipped)]
    pub windows: Windows,
    /// Dense-time specs: the largest gap allowed between consecutive time stamps, in the
    /// time column's unit (`0.5`, or `500000000` for nanoseconds). A larger gap is an error
    /// naming the line and both stamps, instead of each variable's value silently held
    /// across it.
    #[arg(long, value_name = "SECONDS")]
    pub max_gap: Option<String>,
    /// Dense-time specs: print times relative to the first stamp (exact: the difference of
    /// the stamps as written, in integer arithmetic for whole-number stamps) instead of in
    /// the time column's own scale.
    #[arg(long)]
    pub relative: bool,
    /// Threads that score a batch of traces (default: one per core).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u16).range(1..=256))]
    pub threads: Option<u16>,
}

/// How windows that run past the end of a trace count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Windows {
    /// Cut at the end of the trace (empty windows give `inf` or `-inf`), as rtamt does.
    Clipped,
    /// A step counts only if its windows lie inside the trace; later steps are
    /// undetermined.
    Complete,
}

/// The most trace files one batch scores.
pub const MAX_BATCH_TRACES: usize = 100_000;

/// The trace files to score: each `--trace` as given, a folder as its `.csv` files in name
/// order, regular files only (the others skipped with a note).
pub(crate) fn trace_paths(given: &[PathBuf]) -> Result<Vec<PathBuf>, CliError> {
    let mut paths = Vec::new();
    for path in given {
        if !path.is_dir() {
            paths.push(path.clone());
            continue;
        }
        let entries = std::fs::read_dir(path)
            .map_err(|source| CliError::Read { path: path.clone(), source })?;
        let mut found = Vec::new();
        let mut skipped = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|source| CliError::Read { path: path.clone(), source })?;
            let p = entry.path();
            if !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("csv")) {
                continue;
            }
            // Only regular files (or links to them): a named pipe would wait for a writer
            // forever, a device would never end. A file that cannot be looked at is kept,
            // for its read error.
            match std::fs::metadata(&p) {
                Ok(meta) if meta.is_dir() => {}
                Ok(meta) if !meta.is_file() => {
                    skipped.push((p, hstl_files::read::special_kind(&meta)))
                }
                _ => found.push(p),
            }
            if found.len() > MAX_BATCH_TRACES {
                break;
            }
        }
        skipped.sort();
        for (p, what) in &skipped {
            let shown = hstl::load::path_words(p);
            errln!(
                "note: skipped `{}`: {what}, not a regular file",
                hstl::load::escape_controls(&shown)
            );
        }
        if found.is_empty() {
            return Err(CliError::new(
                format!("`{}` holds no `.csv` file", hstl::load::path_words(path)),
                Some("pass a folder of CSV traces, or the trace files themselves".to_string()),
            ));
        }
        found.sort();
        paths.extend(found);
    }
    if paths.len() > MAX_BATCH_TRACES {
        return Err(CliError::new(
            format!("more than {MAX_BATCH_TRACES} traces in one batch"),
            Some("score them in several runs".to_string()),
        ));
    }
    Ok(paths)
}

/// The CSV columns the spec's state variables need.
pub(crate) fn columns(spec: &CheckedSpec) -> Vec<Column<'_>> {
    spec.state_vars
        .iter()
        .map(|v| Column {
            name: &v.name,
            kind: match (v.ty, &v.domain) {
                (_, Domain::Int { lo, hi }) => ColumnKind::Int(Some((*lo, *hi))),
                (VarType::Int, _) => ColumnKind::Int(None),
                _ => ColumnKind::Real,
            },
        })
        .collect()
}

/// Says once which columns of a trace the spec does not name.
pub(crate) fn note_ignored(ignored: &[String], spec: &CheckedSpec) {
    if ignored.is_empty() {
        return;
    }
    let names: Vec<String> =
        ignored.iter().map(|n| format!("`{}`", hstl::load::escape_controls(n))).collect();
    let (what, verb) = if names.len() == 1 {
        ("column", "is not a state variable")
    } else {
        ("columns", "are not state variables")
    };
    errln!("note: {what} {} {verb} of `{}`: ignored", names.join(", "), spec.name);
}

/// The name a trace path is reported by.
pub(crate) fn trace_name(path: &Path) -> String {
    if path == Path::new("-") { "<stdin>".to_string() } else { hstl::load::path_words(path) }
}

/// A reader's error, at the trace's `name:line:column`.
pub(crate) fn read_error(name: &str, e: ReadError) -> CliError {
    match e {
        ReadError::Io(source) => CliError::Read { path: PathBuf::from(name), source },
        ReadError::Csv(e) => {
            CliError::new(format!("{name}:{}:{}: {}", e.line, e.column, e.message), e.help)
        }
    }
}
