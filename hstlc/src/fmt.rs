//! `hstlc fmt`: the canonical layout of spec files.
//!
//! Without flags it prints the formatted text of each input to standard output. `--check`
//! prints nothing but the names of the files that would change and exits 1 when there
//! is one; `--write` rewrites the files that change, whole or not at all (a new file
//! renamed over the old): a symbolic link's target is rewritten, permissions and a byte
//! order mark are kept, and a hard-linked file becomes a file of its own, with a note (see
//! `write_whole`).
//! A file with syntax errors is left as it is: its errors go to standard error, rendered
//! as `hstlc check` renders them, and the exit status is 1. An unreadable input stops the
//! run before anything is printed (exit status 2).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use clap::Args;

use crate::check::Checked;
use crate::cli_error::CliError;
use crate::output::{err, errln, out, outln};
use crate::{CmdResult, Status, input, render};

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
        .map(|path| {
            input::read_text(path, &args.stdin_filename, hstl::lang::MAX_SOURCE_BYTES, "spec")
                .map(|i| (path, i))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut status = Status::Clean;
    let mut broken = Vec::new();
    for (path, input::Input { name, text: source, bom }) in inputs {
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
                outln!("{}", hstl::load::escape_controls(&name))?;
                status = Status::Errors;
            }
        } else if args.write && !is_stdin {
            if formatted != source {
                write_whole(path, &formatted, bom)?;
            }
        } else {
            out!("{formatted}")?;
        }
    }
    if !broken.is_empty() {
        err!("{}", render::full(&broken, std::io::stderr().is_terminal()));
    }
    Ok(status)
}

/// Rewrites the file `path` with `text` (after the byte order mark it had), whole or not at
/// all, as the same file as far as one rename allows ([`hstl_files::write::rewrite`]: a
/// symbolic link stays and the file it points to is rewritten, the permissions, owner and
/// group are kept). A file with several hard links becomes a file of its own under the name
/// given; its other names keep the old text, and a note on standard error says so, naming
/// the file.
fn write_whole(path: &Path, text: &str, bom: bool) -> Result<(), CliError> {
    let mut bytes = Vec::with_capacity(text.len() + 3);
    if bom {
        bytes.extend_from_slice("\u{feff}".as_bytes());
    }
    bytes.extend_from_slice(text.as_bytes());
    let others = hstl_files::write::rewrite(path, &bytes)
        .map_err(|source| CliError::Write { path: path.to_path_buf(), source })?;
    if others > 0 {
        errln!(
            "note: `{}` had {} other hard link{}: it is now a file of its own, and {} the \
             text before formatting (run `hstlc fmt --write` on {} too)",
            hstl::load::path_words(path),
            others,
            if others == 1 { "" } else { "s" },
            if others == 1 { "that name keeps" } else { "those names keep" },
            if others == 1 { "it" } else { "them" },
        );
    }
    Ok(())
}
