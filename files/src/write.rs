//! Whole-file writes: a file is written to a new temporary file beside its target (created
//! exclusively, under a name no other entry has), synced, then renamed over the target, so
//! that a run killed at any point leaves the old contents or the new, never a mix; a write
//! that fails removes its temporary file. The pieces (exclusive creation, syncing a folder,
//! a free hidden sibling name, exchanging two folders in one step) are here for
//! `hstl-outdir`, which writes whole folders the same way.

use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` whole or not at all (see the module): a file there is
/// replaced, a missing one created. The folder is synced after the rename.
pub fn replace(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let (mut file, tmp) = temp_beside(path, None)?;
    let written = (|| {
        file.write_all(bytes)?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written?;
    sync_dir(&parent(path));
    Ok(())
}

/// Rewrites the existing file `path` with `bytes`, whole or not at all, keeping it the same
/// file as far as one rename allows: through a symbolic link the file it points to is
/// rewritten and the link stays; the file keeps its permissions (and its owner and group,
/// where that is allowed), and its temporary file is never more readable than it. Returns
/// how many other hard links the file had: a file with several becomes a file of its own
/// under the name given (no write in place can be whole or nothing), its other names
/// keeping the old contents, which the caller should say.
pub fn rewrite(path: &Path, bytes: &[u8]) -> std::io::Result<u64> {
    let real = std::fs::canonicalize(path)?;
    let meta = std::fs::metadata(&real)?;
    let (mut tmp, tmp_path) = temp_beside(&real, Some(&meta))?;
    let written = (|| {
        tmp.write_all(bytes)?;
        std::fs::set_permissions(&tmp_path, meta.permissions())?;
        keep_owner(&tmp, &meta);
        tmp.sync_all()?;
        std::fs::rename(&tmp_path, &real)
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp_path);
        return Err(e);
    }
    sync_dir(&parent(&real));
    Ok(links(&meta).saturating_sub(1))
}

/// A new file beside `path`, `.NAME.<pid>-<n>.tmp`, created exclusively (on Unix with the
/// permissions of `like`, so that its contents are never more readable than the file's).
pub fn temp_beside(
    path: &Path,
    like: Option<&std::fs::Metadata>,
) -> std::io::Result<(std::fs::File, PathBuf)> {
    let dir = parent(path);
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    if let Some(meta) = like {
        use std::os::unix::fs::{OpenOptionsExt, PermissionsExt};
        options.mode(meta.permissions().mode() & 0o777);
    }
    #[cfg(not(unix))]
    let _ = like;
    for n in 0..1000 {
        let path = dir.join(format!(".{name}.{}-{n}.tmp", std::process::id()));
        match options.open(&path) {
            Ok(file) => return Ok((file, path)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
    Err(no_free_name())
}

/// Creates a new, empty file (never an existing one), writes `bytes` and syncs them.
pub fn write_synced(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
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
pub fn unique_sibling(parent: &Path, prefix: &str, create: bool) -> std::io::Result<PathBuf> {
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
    Err(no_free_name())
}

/// Exchanges the entries `a` and `b` (both must exist) in one step.
#[cfg(target_os = "linux")]
pub fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use std::ffi::CString;
    use std::os::unix::ffi::OsStrExt;
    let c = |p: &Path| {
        CString::new(p.as_os_str().as_bytes())
            .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e))
    };
    let (a, b) = (c(a)?, c(b)?);
    // SAFETY: both are valid NUL-terminated paths that live across the call.
    let r = unsafe {
        libc::renameat2(
            libc::AT_FDCWD,
            a.as_ptr(),
            libc::AT_FDCWD,
            b.as_ptr(),
            libc::RENAME_EXCHANGE,
        )
    };
    if r == 0 { Ok(()) } else { Err(std::io::Error::last_os_error()) }
}

/// Exchanges the entries `a` and `b` in one step: not on this system.
#[cfg(not(target_os = "linux"))]
pub fn exchange(_: &Path, _: &Path) -> std::io::Result<()> {
    Err(std::io::Error::from(std::io::ErrorKind::Unsupported))
}

/// Whether [`exchange`] failed because the system or the file system lacks it.
pub fn exchange_unsupported(e: &std::io::Error) -> bool {
    #[cfg(target_os = "linux")]
    if matches!(e.raw_os_error(), Some(libc::EINVAL | libc::ENOSYS | libc::EOPNOTSUPP)) {
        return true;
    }
    e.kind() == std::io::ErrorKind::Unsupported
}

/// The folder `path` is in (`.` for a bare name).
fn parent(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

fn no_free_name() -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::AlreadyExists, "no free temporary name")
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
    fn replace_writes_whole_and_leaves_nothing_beside() {
        let tmp = tempfile::tempdir().expect("temp dir");
        let path = tmp.path().join("policy.json");
        replace(&path, b"one").expect("creates");
        replace(&path, b"two").expect("replaces");
        assert_eq!(std::fs::read(&path).expect("read"), b"two");
        assert_eq!(names(tmp.path()), ["policy.json"]);
        // A target that cannot be renamed over (a folder holding a file) keeps its contents,
        // and the temporary file is removed.
        let dir = tmp.path().join("held");
        std::fs::create_dir(&dir).expect("mkdir");
        std::fs::write(dir.join("x"), "x").expect("write");
        replace(&dir, b"three").expect_err("a full folder");
        assert_eq!(names(tmp.path()), ["held", "policy.json"]);
    }

    #[cfg(unix)]
    #[test]
    fn rewrite_keeps_the_link_and_the_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let tmp = tempfile::tempdir().expect("temp dir");
        let real = tmp.path().join("spec.hstl");
        std::fs::write(&real, "old").expect("write");
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).expect("chmod");
        let link = tmp.path().join("link.hstl");
        std::os::unix::fs::symlink(&real, &link).expect("symlink");
        assert_eq!(rewrite(&link, b"new").expect("rewrites"), 0);
        assert!(std::fs::symlink_metadata(&link).expect("link").is_symlink());
        assert_eq!(std::fs::read(&real).expect("read"), b"new");
        let mode = std::fs::metadata(&real).expect("meta").permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
        // A second hard link keeps the old text, and is counted.
        let hard = tmp.path().join("hard.hstl");
        std::fs::hard_link(&real, &hard).expect("hard link");
        assert_eq!(rewrite(&real, b"newer").expect("rewrites"), 1);
        assert_eq!(std::fs::read(&hard).expect("read"), b"new");
        assert_eq!(names(tmp.path()), ["hard.hstl", "link.hstl", "spec.hstl"]);
    }
}
