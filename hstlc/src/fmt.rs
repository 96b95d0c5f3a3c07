//! `hstlc fmt`: the canonical layout of spec files.
//!
//! Without flags it prints the formatted text of each input to standard output. `--check`
//! prints nothing but the names of the files that would change and exits 1 when there
//! is one; `--write` rewrites the files that change in place (a whole new file or none).
//! A file with syntax errors is left as it is: its errors go to standard error, rendered
//! as `hstlc check` renders them, and the exit status is 1. An unreadable input stops the
//! run before anything is printed (exit status 2).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use clap::Args;

use crate::check::{Checked, read_input};
use crate::cli_error::CliError;
use crate::{CmdResult, Status, render};

/// Arguments of `hstlc fmt`.
#[derive(Args, Debug)]
pub struct FmtArgs {
    /// Spec files to format; `-` reads standard input.
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// Print the names of the files that would change, change nothing, and exit 1 if any
    /// would.
    #[arg(long, conflicts_with = "write")]
    pub check: bool,
    /// Rewrite the files that change in place (standard input is printed).
    #[arg(long)]
    pub write: bool,
    /// The name to report for standard input.
    #[arg(long, value_name = "NAME", default_value = "<stdin>")]
    pub stdin_filename: String,
}

/// Runs `hstlc fmt`.
pub fn run(args: &FmtArgs) -> CmdResult {
    let inputs = args
        .files
        .iter()
        .map(|path| read_input(path, &args.stdin_filename).map(|(name, text)| (path, name, text)))
        .collect::<Result<Vec<_>, _>>()?;
    let mut status = Status::Clean;
    let mut broken = Vec::new();
    for (path, name, source) in inputs {
        let formatted = match hstl::lang::format(&source) {
            Ok(text) => text,
            Err(diagnostics) => {
                status = Status::Errors;
                broken.push(Checked { name, source, diagnostics });
                continue;
            }
        };
        let is_stdin = path.as_path() == Path::new("-");
        if args.check {
            if formatted != source {
                println!("{name}");
                status = Status::Errors;
            }
        } else if args.write && !is_stdin {
            if formatted != source {
                write_whole(path, &formatted)?;
            }
        } else {
            print!("{formatted}");
        }
    }
    if !broken.is_empty() {
        eprint!("{}", render::full(&broken, std::io::stderr().is_terminal()));
    }
    Ok(status)
}

/// Writes `text` to a temporary file beside `path`, then renames it over `path`.
fn write_whole(path: &Path, text: &str) -> Result<(), CliError> {
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.hstlc-fmt.tmp"));
    let result = std::fs::write(&tmp, text).and_then(|()| std::fs::rename(&tmp, path));
    result.map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        CliError::Write { path: path.to_path_buf(), source }
    })
}
