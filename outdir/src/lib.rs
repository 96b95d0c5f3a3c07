//! Output folders of hstl runs, written whole or not at all: [`OutDir`] holds one run's
//! folder (an operating-system lock beside it) and writes it as a hidden sibling, synced,
//! then renamed into place; [`write_beside`] writes single files the same way. `hstlc` and
//! the Python package both write through here, so a folder one of them wrote the other
//! replaces, and two runs of either never write the same folder at once.
//!
//! The files themselves are plain data ([`OutFile`]), made by the facade
//! (`hstl::artifacts`, `hstl::study`).

use std::fmt;
use std::path::{Path, PathBuf};

pub use hstl::artifacts::OutFile;

/// The file that marks a folder as one run's output: a later run may replace the folder.
pub const MARKER: &str = ".hstlc-run";

/// Who writes: how messages name the program and the setting that chose the folder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Writer {
    /// The program, as in "another hstlc run".
    pub program: &'static str,
    /// The setting that names the folder, as in "choose another `--out`".
    pub option: &'static str,
}

impl Writer {
    /// The command line: `hstlc` and `--out`.
    pub const CLI: Writer = Writer { program: "hstlc", option: "`--out`" };
    /// The Python package: `hstl` and `out=`.
    pub const PYTHON: Writer = Writer { program: "hstl", option: "`out=`" };
}

/// Why a folder could not be taken or written.
#[derive(Debug)]
pub enum Error {
    /// A file or folder could not be written.
    Write {
        /// The path.
        path: PathBuf,
        /// The reason.
        source: std::io::Error,
    },
    /// The folder may not be written (another run holds it, it is a file, it holds files no
    /// run writes, a file name is not plain), and how to fix that.
    Refused(hstl::Problem),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Write { path, source } => {
                write!(f, "cannot write `{}`: {}", path.display(), hstl::load::io_reason(source))
            }
            Error::Refused(p) => f.write_str(&p.message),
        }
    }
}

impl std::error::Error for Error {}

impl Error {
    /// How to fix it, where one fits.
    pub fn help(&self) -> Option<String> {
        match self {
            Error::Write { .. } => None,
            Error::Refused(p) => p.help.clone(),
        }
    }
}

fn refused(message: String, help: Option<String>) -> Error {
    Error::Refused(hstl::Problem::new(message, help))
}

/// An output folder that this run holds (see [`OutDir::lock`]) and will write whole.
///
/// The files go to a hidden sibling folder first, each one synced to disk; then the folder
/// is synced and renamed into place. A folder an earlier run wrote is moved aside just
/// before and removed just after, so at every moment `dir` is the old run's folder, no
/// folder, or the new run's folder, never a mix. A run killed on the way leaves only hidden
/// siblings (`.NAME.tmp-*`, `.NAME.old-*`), which the next run into `dir` removes. Another
/// run into the same folder is refused while this one holds it: the lock is the operating
/// system's lock on `.NAME.lock` beside the folder, released when the process ends however
/// it ends, so a killed run leaves no stale lock.
#[derive(Debug)]
pub struct OutDir {
    dir: PathBuf,
    parent: PathBuf,
    name: String,
    writer: Writer,
    /// Holds the lock while this value lives.
    _lock: std::fs::File,
}

impl OutDir {
    /// Takes the folder `dir` for this run: refuses it when another run holds it, or when
    /// it holds files no run writes (it will be replaced as a whole). Call it before the
    /// long work, so that a refusal comes at once.
    pub fn lock(dir: &Path, writer: Writer) -> Result<OutDir, Error> {
        let write_err = |path: &Path| {
            let path = path.to_path_buf();
            move |source| Error::Write { path, source }
        };
        // `--out .`, or a symbolic link: the folder it names.
        let dir = if dir.file_name().is_none() || dir.is_symlink() {
            std::fs::canonicalize(dir).map_err(write_err(dir))?
        } else {
            dir.to_path_buf()
        };
        let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(write_err(&dir))?;
        let lock_path = parent.join(format!(".{name}.lock"));
        let lock = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&lock_path)
            .map_err(write_err(&lock_path))?;
        match lock.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(refused(
                    format!(
                        "`{}` is being written by another {} run",
                        dir.display(),
                        writer.program
                    ),
                    Some(format!(
                        "wait for that run to finish, or choose another {}",
                        writer.option
                    )),
                ));
            }
            // A file system without locks: go on without one.
            Err(std::fs::TryLockError::Error(_)) => {}
        }
        // This run holds the folder: hidden siblings left by killed runs are stale.
        if let Ok(entries) = std::fs::read_dir(&parent) {
            let (tmp, old) = (format!(".{name}.tmp-"), format!(".{name}.old-"));
            for entry in entries.flatten() {
                let n = entry.file_name().to_string_lossy().into_owned();
                if n.starts_with(&tmp) || n.starts_with(&old) {
                    let _ = std::fs::remove_dir_all(entry.path());
                }
            }
        }
        let out = OutDir { dir, parent, name, writer, _lock: lock };
        out.replaceable()?;
        Ok(out)
    }

    /// Writes `files` as the folder, whole or not at all (see [`OutDir`]); the paths
    /// written, in order.
    pub fn write(self, files: &[OutFile]) -> Result<Vec<PathBuf>, Error> {
        check_names(files)?;
        self.replaceable()?;
        let tmp = unique_sibling(&self.parent, &format!(".{}.tmp-", self.name), true)
            .map_err(|source| Error::Write { path: self.dir.clone(), source })?;
        let guard = RemoveOnDrop(Some(tmp.clone()));
        for file in files {
            let path = tmp.join(&file.name);
            write_synced(&path, &file.contents)
                .map_err(|source| Error::Write { path: self.dir.join(&file.name), source })?;
        }
        let marker = "This folder is one run of hstlc, written as a whole; the next run into it \
                      replaces it.\n";
        write_synced(&tmp.join(MARKER), marker.as_bytes())
            .map_err(|source| Error::Write { path: self.dir.join(MARKER), source })?;
        sync_dir(&tmp);
        let swap_err = |source| Error::Write { path: self.dir.clone(), source };
        if std::fs::symlink_metadata(&self.dir).is_ok() {
            let old = unique_sibling(&self.parent, &format!(".{}.old-", self.name), false)
                .map_err(swap_err)?;
            std::fs::rename(&self.dir, &old).map_err(swap_err)?;
            if let Err(source) = std::fs::rename(&tmp, &self.dir) {
                // Put the old run back.
                let _ = std::fs::rename(&old, &self.dir);
                return Err(swap_err(source));
            }
            sync_dir(&self.parent);
            let _ = std::fs::remove_dir_all(&old);
        } else {
            std::fs::rename(&tmp, &self.dir).map_err(swap_err)?;
            sync_dir(&self.parent);
        }
        std::mem::forget(guard);
        Ok(files.iter().map(|f| self.dir.join(&f.name)).collect())
    }

    /// The folder to be written.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Refuses a folder this run may not replace: a file, or a folder holding anything
    /// that is not a run's output (a folder that an older hstlc wrote, before the marker,
    /// holds only files named as a run's).
    fn replaceable(&self) -> Result<(), Error> {
        let meta = match std::fs::symlink_metadata(&self.dir) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
            Err(source) => return Err(Error::Write { path: self.dir.clone(), source }),
            Ok(meta) => meta,
        };
        if !meta.is_dir() {
            return Err(refused(
                format!("`{}` is a file, not a folder", self.dir.display()),
                Some(format!("choose another {}", self.writer.option)),
            ));
        }
        let entries = std::fs::read_dir(&self.dir)
            .map_err(|source| Error::Write { path: self.dir.clone(), source })?;
        let mut foreign = Vec::new();
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name == MARKER {
                return Ok(());
            }
            let is_file = entry.file_type().is_ok_and(|t| t.is_file());
            if !(is_file && is_run_file(&name)) {
                foreign.push(format!("`{name}`"));
            }
        }
        if foreign.is_empty() {
            return Ok(());
        }
        foreign.sort();
        let shown = foreign.len().min(5);
        let more = if foreign.len() > shown {
            format!(" and {} more", foreign.len() - shown)
        } else {
            String::new()
        };
        Err(refused(
            format!(
                "`{}` holds {}{more}, which no {} run writes",
                self.dir.display(),
                foreign[..shown].join(", "),
                self.writer.program
            ),
            Some(format!(
                "{} replaces its output folder as a whole: choose a new or empty {}, or move \
                 those out of it",
                self.writer.program, self.writer.option
            )),
        ))
    }
}

/// Writes `files` into the folder `dir` (made if missing) beside what it holds, each file
/// whole or not at all (written to a hidden temporary file, synced, renamed over the old
/// one): for files such as a study's `curves.svg` that sit beside the runs' folders.
pub fn write_beside(dir: &Path, files: &[OutFile]) -> Result<Vec<PathBuf>, Error> {
    check_names(files)?;
    let err = |path: PathBuf| move |source| Error::Write { path, source };
    std::fs::create_dir_all(dir).map_err(err(dir.to_path_buf()))?;
    let mut written = Vec::new();
    for file in files {
        let path = dir.join(&file.name);
        let tmp = (0..1000)
            .map(|n| dir.join(format!(".{}.{}-{n}.tmp", file.name, std::process::id())))
            .find(|p| std::fs::symlink_metadata(p).is_err())
            .ok_or_else(|| {
                err(path.clone())(std::io::Error::new(
                    std::io::ErrorKind::AlreadyExists,
                    "no free temporary name",
                ))
            })?;
        if let Err(source) = write_synced(&tmp, &file.contents) {
            let _ = std::fs::remove_file(&tmp);
            return Err(Error::Write { path, source });
        }
        if let Err(source) = std::fs::rename(&tmp, &path) {
            let _ = std::fs::remove_file(&tmp);
            return Err(Error::Write { path, source });
        }
        written.push(path);
    }
    sync_dir(dir);
    Ok(written)
}

/// Removes a folder when dropped (a write that failed half way), unless forgotten.
struct RemoveOnDrop(Option<PathBuf>);

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        if let Some(path) = self.0.take() {
            let _ = std::fs::remove_dir_all(path);
        }
    }
}

/// Whether a run of this or an earlier hstlc writes a file of this name.
fn is_run_file(name: &str) -> bool {
    matches!(name, "policy.json" | "curve.csv" | "seeds.csv")
        || name.ends_with(".svg")
        || (name.starts_with('.') && name.ends_with(".tmp"))
}

/// Refuses names that are not plain file names, or that two files share (also when they
/// differ only in case, as they would on a case-insensitive file system).
fn check_names(files: &[OutFile]) -> Result<(), Error> {
    let mut seen = std::collections::HashSet::new();
    for f in files {
        let plain = !f.name.is_empty()
            && f.name != "."
            && f.name != ".."
            && f.name != MARKER
            && f.name.len() <= 255
            && !f.name.contains(['/', '\\', '\0']);
        if !plain || !seen.insert(f.name.to_lowercase()) {
            return Err(refused(
                format!("cannot write `{}`: the name is not a plain file name of its own", f.name),
                None,
            ));
        }
    }
    Ok(())
}

/// Creates a new, empty file (never an existing one), writes `bytes` and syncs them.
fn write_synced(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let mut file = std::fs::OpenOptions::new().write(true).create_new(true).open(path)?;
    file.write_all(bytes)?;
    file.sync_all()
}

/// Syncs a folder's entries to disk, where the file system allows it.
pub fn sync_dir(dir: &Path) {
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
}

/// A path `parent/PREFIX<pid>-<n>` that no entry has, created as a folder when `create`.
fn unique_sibling(parent: &Path, prefix: &str, create: bool) -> std::io::Result<PathBuf> {
    for n in 0..1000 {
        let path = parent.join(format!("{prefix}{}-{n}", std::process::id()));
        if create {
            match std::fs::create_dir(&path) {
                Ok(()) => return Ok(path),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        } else if std::fs::symlink_metadata(&path).is_err() {
            return Ok(path);
        }
    }
    Err(std::io::Error::new(std::io::ErrorKind::AlreadyExists, "no free temporary name"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .expect("the folder")
            .map(|e| e.expect("an entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_folder_is_replaced_whole_and_a_held_one_refused() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let dir = tmp.path().join("run");
        let out = OutDir::lock(&dir, Writer::PYTHON).expect("locks");
        // Held: a second taker is refused, in the Python package's words.
        let again = OutDir::lock(&dir, Writer::PYTHON).expect_err("held");
        assert!(again.to_string().contains("being written by another hstl run"), "{again}");
        assert_eq!(
            again.help().as_deref(),
            Some("wait for that run to finish, or choose another `out=`")
        );
        out.write(&[OutFile::text("a.svg", "a".into())]).expect("writes");
        assert_eq!(names(&dir), [MARKER, "a.svg"]);
        let out = OutDir::lock(&dir, Writer::CLI).expect("free again");
        out.write(&[OutFile::text("seeds.csv", "s".into())]).expect("writes");
        assert_eq!(names(&dir), [MARKER, "seeds.csv"]);
        // Only the folder and its lock beside it: no hidden sibling is left.
        assert_eq!(names(tmp.path()), [".run.lock", "run"]);
    }

    #[test]
    fn folders_with_foreign_files_and_bad_names_are_refused() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let dir = tmp.path().join("mine");
        std::fs::create_dir(&dir).expect("mkdir");
        std::fs::write(dir.join("notes.txt"), "keep").expect("write");
        let e = OutDir::lock(&dir, Writer::CLI).expect_err("foreign");
        assert_eq!(
            e.to_string(),
            format!("`{}` holds `notes.txt`, which no hstlc run writes", dir.display())
        );
        let other = tmp.path().join("other");
        let out = OutDir::lock(&other, Writer::CLI).expect("locks");
        let e = out.write(&[OutFile::text("../x", String::new())]).expect_err("not plain");
        assert!(e.to_string().contains("not a plain file name"), "{e}");
        assert!(!other.exists());
    }
}
