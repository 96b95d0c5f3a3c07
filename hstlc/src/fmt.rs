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

use std::io::{IsTerminal, Write};
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
/// all: the new text goes to a new temporary file beside it (created exclusively, under a
/// name no other file has), synced, then renamed over it, so that a run killed at any point
/// leaves the old text or the new, never a mix, and no backup to find. It stays the same
/// file as far as one rename allows:
/// - through a symbolic link the file it points to is rewritten, and the link stays;
/// - the file keeps its permissions (and its owner and group, where that is allowed);
/// - a file with several hard links becomes a file of its own under the name given (no
///   write in place can be whole or nothing); its other names keep the old text, and a
///   note on standard error says so, naming the file.
fn write_whole(path: &Path, text: &str, bom: bool) -> Result<(), CliError> {
    let fail = |source| CliError::Write { path: path.to_path_buf(), source };
    let real = std::fs::canonicalize(path).map_err(fail)?;
    let meta = std::fs::metadata(&real).map_err(fail)?;
    let mut bytes = Vec::with_capacity(text.len() + 3);
    if bom {
        bytes.extend_from_slice("\u{feff}".as_bytes());
    }
    bytes.extend_from_slice(text.as_bytes());
    let (mut tmp, tmp_path) = create_beside(&real, "tmp").map_err(fail)?;
    let written = (|| {
        tmp.write_all(&bytes)?;
        std::fs::set_permissions(&tmp_path, meta.permissions())?;
        keep_owner(&tmp, &meta);
        tmp.sync_all()?;
        std::fs::rename(&tmp_path, &real)
    })();
    if let Err(source) = written {
        let _ = std::fs::remove_file(&tmp_path);
        return Err(fail(source));
    }
    if let Some(dir) = real.parent() {
        hstl_outdir::sync_dir(dir);
    }
    let others = links(&meta).saturating_sub(1);
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

/// A new file beside `real`, `.NAME.hstlc-fmt-<pid>-<n>.<ext>`, created exclusively (with
/// the permissions of `real` on Unix, so that its text is never more readable).
fn create_beside(real: &Path, ext: &str) -> std::io::Result<(std::fs::File, PathBuf)> {
    let dir = real.parent().unwrap_or(Path::new("."));
    let name = real.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
        let mode = std::fs::metadata(real).map_or(0o600, |m| m.permissions().mode() & 0o777);
        options.mode(mode);
    }
    for n in 0..1000 {
        let path = dir.join(format!(".{name}.hstlc-fmt-{}-{n}.{ext}", std::process::id()));
        match options.open(&path) {
            Ok(file) => return Ok((file, path)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(std::io::Error::new(std::io::ErrorKind::AlreadyExists, "no free temporary name"))
}

/// How many hard links the file has (1 where the platform does not say).
fn links(meta: &std::fs::Metadata) -> u64 {
    #[cfg(unix)]
    {
        std::os::unix::fs::MetadataExt::nlink(meta)
    }
    #[cfg(not(unix))]
    {
        let _ = meta;
        1
    }
}

/// Gives `file` the owner and group of `meta`, where this process may (root may; others
/// keep their own user, and the group when they belong to it).
fn keep_owner(file: &std::fs::File, meta: &std::fs::Metadata) {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if std::os::unix::fs::fchown(file, Some(meta.uid()), Some(meta.gid())).is_err() {
            let _ = std::os::unix::fs::fchown(file, None, Some(meta.gid()));
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (file, meta);
    }
}
