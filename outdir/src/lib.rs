//! Output folders of hstl runs, written whole or not at all: [`OutDir`] holds one run's
//! folder (an operating-system lock beside it) and writes it as a hidden sibling, synced,
//! then renamed into place; [`write_beside`] writes single files the same way. `hstlc` and
//! the Python package both write through here, so a folder one of them wrote the other
//! replaces, and two runs of either never write the same folder at once.
//!
//! The files themselves are plain data ([`OutFile`]), made by the facade
//! (`hstl::artifacts`, `hstl::study`); the writing pieces (exclusive creation, syncing,
//! a free hidden name, exchanging two folders) are `hstl-files`'s, and this crate, like
//! it, knows nothing of the learner.

use std::fmt;
use std::path::{Path, PathBuf};

pub use hstl_files::OutFile;
use hstl_files::Problem;
use hstl_files::words::path_words;
pub use hstl_files::write::sync_dir;
use hstl_files::write::{exchange, exchange_unsupported, unique_sibling, write_synced};

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
    Refused(Problem),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Write { path, source } => {
                write!(
                    f,
                    "cannot write `{}`: {}",
                    path_words(path),
                    hstl_files::words::io_reason(source)
                )
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
    Error::Refused(Problem::new(message, help))
}

/// An output folder that this run holds (see [`OutDir::lock`]) and will write whole.
///
/// The files go to a hidden sibling folder first, each one synced to disk; then the folder
/// is synced and put in place. A folder an earlier run wrote is exchanged with the new one
/// in one step (Linux's `renameat2(RENAME_EXCHANGE)`), then removed, so at every moment
/// `dir` is the old run's folder or the new run's, never a mix and never neither. Where
/// folders cannot be exchanged (another system, a file system without the call), the old
/// folder is renamed aside to `.NAME.old-*` and the new one renamed in; a run killed
/// between the two leaves the old folder there, and the next run into `dir` puts it back
/// before anything else. A run killed on the way leaves only hidden siblings
/// (`.NAME.tmp-*`), which the next run into `dir` removes. Another run into the same folder
/// is refused while this one holds it: the lock is the operating system's lock on
/// `.NAME.lock` beside the folder, taken only once the folder is known to be replaceable,
/// released when the process ends however it ends (a killed run leaves no stale lock), and
/// the file removed when this value is dropped (see [`Lock`]).
#[derive(Debug)]
pub struct OutDir {
    dir: PathBuf,
    parent: PathBuf,
    name: String,
    writer: Writer,
    /// Holds the lock while this value lives.
    _lock: Lock,
}

impl OutDir {
    /// Takes the folder `dir` for this run: refuses it when another run holds it, or when
    /// it holds files no run writes (it will be replaced as a whole). Call it before the
    /// long work, so that a refusal comes at once.
    pub fn lock(dir: &Path, writer: Writer) -> Result<OutDir, Error> {
        let dir = named_folder(dir)?;
        let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        // A target refused as it stands gets nothing beside it, not even a lock.
        replaceable(&dir, writer)?;
        std::fs::create_dir_all(&parent).map_err(write_err(&dir))?;
        let lock = Lock::take(&dir, writer)?;
        // This run holds the folder: hidden siblings left by killed runs are stale. A
        // folder a killed run had moved aside (`.NAME.old-*`, only where folders cannot be
        // exchanged, see `OutDir`) is put back when nothing took its place; the others go.
        if let Ok(entries) = std::fs::read_dir(&parent) {
            let (tmp, old) = (format!(".{name}.tmp-"), format!(".{name}.old-"));
            let mut stale: Vec<(bool, PathBuf)> = entries
                .flatten()
                .filter_map(|entry| {
                    let n = entry.file_name().to_string_lossy().into_owned();
                    let is_old = n.starts_with(&old);
                    (is_old || n.starts_with(&tmp)).then(|| (is_old, entry.path()))
                })
                .collect();
            // Old folders first, so that one of them can be put back.
            stale.sort_by_key(|(is_old, _)| !is_old);
            for (is_old, path) in stale {
                let restored = is_old
                    && std::fs::symlink_metadata(&dir).is_err()
                    && std::fs::rename(&path, &dir).is_ok();
                if !restored {
                    let _ = std::fs::remove_dir_all(path);
                }
            }
        }
        let out = OutDir { dir, parent, name, writer, _lock: lock };
        replaceable(&out.dir, out.writer)?;
        Ok(out)
    }

    /// Writes `files` as the folder, whole or not at all (see [`OutDir`]); the paths
    /// written, in order.
    pub fn write(self, files: &[OutFile]) -> Result<Vec<PathBuf>, Error> {
        check_names(files)?;
        replaceable(&self.dir, self.writer)?;
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
            match exchange(&tmp, &self.dir) {
                // `dir` is the new folder, `tmp` the old one: the guard removes it.
                Ok(()) => {
                    step(&self.dir);
                    sync_dir(&self.parent);
                    return Ok(files.iter().map(|f| self.dir.join(&f.name)).collect());
                }
                Err(e) if exchange_unsupported(&e) => {}
                Err(source) => return Err(swap_err(source)),
            }
            // No exchange here: the old folder waits under a hidden name that the next run
            // into `dir` puts back if this one is killed before the new one is in place.
            let old = unique_sibling(&self.parent, &format!(".{}.old-", self.name), false)
                .map_err(swap_err)?;
            std::fs::rename(&self.dir, &old).map_err(swap_err)?;
            step(&self.dir);
            if let Err(source) = std::fs::rename(&tmp, &self.dir) {
                // Put the old run back.
                let _ = std::fs::rename(&old, &self.dir);
                return Err(swap_err(source));
            }
            step(&self.dir);
            sync_dir(&self.parent);
            let _ = std::fs::remove_dir_all(&old);
        } else {
            std::fs::rename(&tmp, &self.dir).map_err(swap_err)?;
            step(&self.dir);
            sync_dir(&self.parent);
        }
        std::mem::forget(guard);
        Ok(files.iter().map(|f| self.dir.join(&f.name)).collect())
    }

    /// The folder to be written.
    pub fn path(&self) -> &Path {
        &self.dir
    }
}

/// Whether the folder `dir` is there (false when nothing is); a file there is refused.
fn folder_there(dir: &Path, writer: Writer) -> Result<bool, Error> {
    let meta = match std::fs::symlink_metadata(dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(false),
        Err(source) => return Err(Error::Write { path: dir.to_path_buf(), source }),
        Ok(meta) => meta,
    };
    if !meta.is_dir() {
        return Err(refused(
            format!("`{}` is a file, not a folder", path_words(dir)),
            Some(format!("choose another {}", writer.option)),
        ));
    }
    Ok(true)
}

/// Refuses a folder this run may not replace: a file, or a folder holding anything
/// that is not a run's output (a folder that an older hstlc wrote, before the marker,
/// holds only files named as a run's).
fn replaceable(dir: &Path, writer: Writer) -> Result<(), Error> {
    if !folder_there(dir, writer)? {
        return Ok(());
    }
    let entries = std::fs::read_dir(dir)
        .map_err(|source| Error::Write { path: dir.to_path_buf(), source })?;
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
            path_words(dir),
            foreign[..shown].join(", "),
            writer.program
        ),
        Some(format!(
            "{} replaces its output folder as a whole: choose a new or empty {}, or move \
             those out of it",
            writer.program, writer.option
        )),
    ))
}

/// The file that marks a study's folder: the names of what a study wrote at its top, one a
/// line (its own files and its specs' folders). A file at the top that it does not name is
/// a user's, and is never replaced without `--force` (`force=True`).
pub const STUDY_MARKER: &str = ".hstlc-study";

/// The files a study writes at the top of its folder, beside its specs' folders.
pub const STUDY_FILES: [&str; 3] = ["curves.svg", "curves.csv", "summary.csv"];

/// A study's folder, held by this run (a [`Lock`] on it, beside it): its specs' folders
/// ([`OutDir`]s, taken by [`StudyDir::take`]) and the files at its top, written last by
/// [`StudyDir::write`].
///
/// The files at the top describe every spec folder in the study's folder, or the run is
/// refused: a folder that another run wrote there (one holding [`MARKER`], or one the last
/// study named) and that this study does not write would be left beside a summary that
/// does not describe it. With `force` such folders are removed, and a user's files of the
/// top files' names replaced; without it either is refused before any training, naming
/// the file or folder and how to proceed. Anything else in the folder is left alone.
#[derive(Debug)]
pub struct StudyDir {
    dir: PathBuf,
    /// Held while this value lives.
    _lock: Lock,
}

impl StudyDir {
    /// Takes the study folder `dir` and its specs' folders `spec_dirs` (each one inside
    /// `dir`), or refuses them (see [`StudyDir`]). Call it before the long work.
    pub fn take(
        dir: &Path,
        spec_dirs: &[PathBuf],
        force: bool,
        writer: Writer,
    ) -> Result<(StudyDir, Vec<OutDir>), Error> {
        let dir = named_folder(dir)?;
        let ours: Vec<String> = spec_dirs
            .iter()
            .filter_map(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
            .collect();
        // A target refused as it stands gets nothing beside it; checked again once held.
        study_refusal(&dir, &ours, force, writer)?;
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(write_err(&dir))?;
        let lock = Lock::take(&dir, writer)?;
        for stale in study_refusal(&dir, &ours, force, writer)? {
            // Taken first, so that a folder another run is writing is refused, not removed.
            let held = OutDir::lock(&stale, writer)?;
            std::fs::remove_dir_all(&stale).map_err(write_err(&stale))?;
            drop(held);
        }
        let study = StudyDir { dir: dir.clone(), _lock: lock };
        let outs = spec_dirs
            .iter()
            .map(|d| OutDir::lock(&dir.join(d.file_name().unwrap_or_default()), writer))
            .collect::<Result<Vec<_>, _>>()?;
        Ok((study, outs))
    }

    /// Writes the files at the top of the study's folder, each whole or not at all, after
    /// the marker that names them and `spec_dirs`; the paths written.
    pub fn write(self, files: &[OutFile], spec_dirs: &[PathBuf]) -> Result<Vec<PathBuf>, Error> {
        let mut names: Vec<String> = files.iter().map(|f| f.name.clone()).collect();
        names.extend(
            spec_dirs.iter().filter_map(|d| d.file_name().map(|n| n.to_string_lossy().into())),
        );
        let marker = format!(
            "# What an hstl study wrote in this folder; a later study replaces these.\n{}\n",
            names.join("\n")
        );
        write_beside(&self.dir, &[OutFile::text(STUDY_MARKER, marker)])?;
        write_beside(&self.dir, files)
    }
}

/// Refuses a study folder whose top a study may not write (see [`StudyDir`]), or returns
/// the folders of other runs to remove first (only with `force`).
fn study_refusal(
    dir: &Path,
    ours: &[String],
    force: bool,
    writer: Writer,
) -> Result<Vec<PathBuf>, Error> {
    if !folder_there(dir, writer)? {
        return Ok(Vec::new());
    }
    let listed: Vec<String> = std::fs::read_to_string(dir.join(STUDY_MARKER))
        .map(|t| t.lines().filter(|l| !l.starts_with('#')).map(str::to_string).collect())
        .unwrap_or_default();
    let force_help = |what: &str| {
        Some(format!(
            "move it out of the folder, choose another {}, or {what} ({})",
            writer.option,
            if writer.program == "hstl" { "`force=True`" } else { "`--force`" }
        ))
    };
    for name in STUDY_FILES {
        let path = dir.join(name);
        let Ok(meta) = std::fs::symlink_metadata(&path) else { continue };
        if !meta.is_file() {
            return Err(refused(
                format!(
                    "`{}` is in the way of a study's `{name}`: it is not a file",
                    path_words(&path)
                ),
                Some(format!("move it out of the folder, or choose another {}", writer.option)),
            ));
        }
        if !force && !listed.iter().any(|l| l == name) {
            return Err(refused(
                format!(
                    "`{}` was not written by a study, and would be replaced",
                    path_words(&path)
                ),
                force_help("replace it"),
            ));
        }
    }
    let entries = std::fs::read_dir(dir)
        .map_err(|source| Error::Write { path: dir.to_path_buf(), source })?;
    let mut stale = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        // Hidden siblings of the specs' folders are their runs' (see `OutDir::lock`).
        if name.starts_with('.')
            || ours.iter().any(|o| o.eq_ignore_ascii_case(&name))
            || !entry.file_type().is_ok_and(|t| t.is_dir())
        {
            continue;
        }
        let path = entry.path();
        if path.join(MARKER).is_file() || listed.contains(&name) {
            stale.push(path);
        }
    }
    stale.sort();
    if let Some(first) = stale.first().filter(|_| !force) {
        return Err(refused(
            format!(
                "`{}` holds `{}`, another run's folder, which this study's summary would not \
                 describe",
                path_words(dir),
                first.file_name().unwrap_or_default().to_string_lossy()
            ),
            force_help("remove it"),
        ));
    }
    Ok(stale)
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
        hstl_files::write::replace(&path, &file.contents)
            .map_err(|source| Error::Write { path: path.clone(), source })?;
        written.push(path);
    }
    Ok(written)
}

/// The lock on one output folder's name: the operating system's lock on `.NAME.lock`
/// beside it, held while this value lives. Dropping it removes the file, then releases the
/// lock, so no lock file outlives its run (one killed outright leaves its file, unlocked,
/// and the next run into the folder takes and removes it). A run that opened the file just
/// before its holder removed it finds, once it holds the lock, that the name now names
/// another file or none, and takes the lock again under the name.
#[derive(Debug)]
pub struct Lock {
    path: PathBuf,
    file: std::fs::File,
}

impl Lock {
    /// Takes the lock on the folder `dir` (whose parent must exist), or refuses it when
    /// another run holds it.
    pub fn take(dir: &Path, writer: Writer) -> Result<Lock, Error> {
        let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let path = parent.join(format!(".{name}.lock"));
        for _ in 0..100 {
            let file = std::fs::OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(|source| Error::Write { path: path.clone(), source })?;
            match file.try_lock() {
                Ok(()) => {}
                Err(std::fs::TryLockError::WouldBlock) => {
                    return Err(refused(
                        format!(
                            "`{}` is being written by another {} run",
                            path_words(dir),
                            writer.program
                        ),
                        Some(format!(
                            "wait for that run to finish, or choose another {}",
                            writer.option
                        )),
                    ));
                }
                // A file system without locks: go on without one.
                Err(std::fs::TryLockError::Error(_)) => return Ok(Lock { path, file }),
            }
            if same_file(&file, &path) {
                return Ok(Lock { path, file });
            }
        }
        Err(refused(
            format!("`{}` is being written by other {} runs", path_words(dir), writer.program),
            Some(format!("wait for them to finish, or choose another {}", writer.option)),
        ))
    }
}

impl Drop for Lock {
    fn drop(&mut self) {
        // Removed while still held: a run waiting on this file sees it gone and retakes.
        if same_file(&self.file, &self.path) {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Whether `path` still names the open `file`.
fn same_file(file: &std::fs::File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), std::fs::symlink_metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = file;
        path.exists()
    }
}

/// What tests call after each step of `OutDir::write` that renames the folder.
#[cfg(test)]
type StepHook = Box<dyn Fn(&Path)>;

#[cfg(test)]
thread_local! {
    /// Called with the folder after each step that renames it (tests only).
    static STEP: std::cell::RefCell<Option<StepHook>> =
        const { std::cell::RefCell::new(None) };
}

/// A step of `OutDir::write` that renamed `dir` is done (tests watch these).
fn step(dir: &Path) {
    #[cfg(test)]
    STEP.with(|s| {
        if let Some(f) = s.borrow().as_ref() {
            f(dir)
        }
    });
    #[cfg(not(test))]
    let _ = dir;
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
/// A write error at `path`, for `map_err`.
fn write_err(path: &Path) -> impl FnOnce(std::io::Error) -> Error {
    let path = path.to_path_buf();
    move |source| Error::Write { path, source }
}

/// The folder `dir` names: `--out .`, or a symbolic link, resolved to the folder itself.
fn named_folder(dir: &Path) -> Result<PathBuf, Error> {
    if dir.file_name().is_none() || dir.is_symlink() {
        std::fs::canonicalize(dir).map_err(write_err(dir))
    } else {
        Ok(dir.to_path_buf())
    }
}

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
        // Only the folder: no hidden sibling and no lock file is left.
        assert_eq!(names(tmp.path()), ["run"]);
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

    /// Hostile round 2: a refused target gets no lock file beside it, and a run's lock
    /// file goes with the run.
    #[test]
    fn no_lock_file_outlives_its_run_or_lands_beside_a_refused_target() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let file = tmp.path().join("passwd");
        std::fs::write(&file, "root").expect("write");
        let e = OutDir::lock(&file, Writer::CLI).expect_err("a file");
        assert!(e.to_string().contains("is a file, not a folder"), "{e}");
        let mine = tmp.path().join("mine");
        std::fs::create_dir(&mine).expect("mkdir");
        std::fs::write(mine.join("notes.txt"), "keep").expect("write");
        OutDir::lock(&mine, Writer::CLI).expect_err("foreign");
        assert_eq!(names(tmp.path()), ["mine", "passwd"]);
        // Taken and dropped unwritten (a run that failed): its lock goes too.
        let run = tmp.path().join("run");
        let out = OutDir::lock(&run, Writer::CLI).expect("locks");
        assert!(tmp.path().join(".run.lock").exists());
        drop(out);
        assert_eq!(names(tmp.path()), ["mine", "passwd"]);
        // A holder's lock survives a refused second taker.
        let out = OutDir::lock(&run, Writer::CLI).expect("locks");
        OutDir::lock(&run, Writer::CLI).expect_err("held");
        assert!(tmp.path().join(".run.lock").exists());
        // A lock file a killed run left (unlocked) is taken and removed.
        out.write(&[OutFile::text("a.svg", "a".into())]).expect("writes");
        std::fs::write(tmp.path().join(".run.lock"), "").expect("a killed run's lock");
        let out = OutDir::lock(&run, Writer::CLI).expect("locks");
        out.write(&[OutFile::text("a.svg", "b".into())]).expect("writes");
        assert_eq!(names(tmp.path()), ["mine", "passwd", "run"]);
    }

    /// Hostile round 2: a run killed after moving the old folder aside and before putting
    /// the new one in place left no `run`; the next run puts the old one back instead of
    /// removing it.
    #[test]
    fn a_folder_moved_aside_by_a_killed_run_is_put_back() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let run = tmp.path().join("run");
        let old = tmp.path().join(".run.old-99999-0");
        std::fs::create_dir(&old).expect("mkdir");
        std::fs::write(old.join(MARKER), "").expect("write");
        std::fs::write(old.join("policy.json"), "the old run").expect("write");
        let half = tmp.path().join(".run.tmp-99999-0");
        std::fs::create_dir(&half).expect("mkdir");
        std::fs::write(half.join("policy.json"), "the killed run").expect("write");
        let out = OutDir::lock(&run, Writer::CLI).expect("locks");
        assert_eq!(names(tmp.path()), [".run.lock", "run"]);
        assert_eq!(std::fs::read_to_string(run.join("policy.json")).expect("read"), "the old run");
        drop(out);
        assert_eq!(names(tmp.path()), ["run"]);
    }

    /// Hostile round 2: replacing a folder never leaves neither the old nor the new: after
    /// every step that renames it, the folder is whole, the old run's or the new one's.
    #[cfg(target_os = "linux")]
    #[test]
    fn replacing_a_folder_never_leaves_neither() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let run = tmp.path().join("run");
        OutDir::lock(&run, Writer::CLI)
            .expect("locks")
            .write(&[OutFile::text("policy.json", "old".into())])
            .expect("writes");
        let seen = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
        let log = seen.clone();
        STEP.with(|s| {
            *s.borrow_mut() = Some(Box::new(move |dir: &Path| {
                log.borrow_mut().push(std::fs::read_to_string(dir.join("policy.json")).ok())
            }))
        });
        OutDir::lock(&run, Writer::CLI)
            .expect("locks")
            .write(&[OutFile::text("policy.json", "new".into())])
            .expect("writes");
        STEP.with(|s| *s.borrow_mut() = None);
        let seen = seen.borrow();
        assert!(!seen.is_empty());
        assert!(
            seen.iter().all(|s| s.as_deref().is_some_and(|t| t == "old" || t == "new")),
            "{seen:?}"
        );
        assert_eq!(names(tmp.path()), ["run"]);
    }
}
