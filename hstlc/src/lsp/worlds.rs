//! The worlds that open documents name (`world "NAME_OR_PATH";`), as the checks see them.
//!
//! A path is relative to the document's folder. A world file is read once and read again
//! when its size or modification time changes (checked at every analysis, and on
//! `workspace/didChangeWatchedFiles`), so the editor follows a map being edited beside the
//! spec. At most [`MAX_CACHED_WORLDS`] files are kept; the cache is a convenience, never
//! a bound on what a document may name.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

use hstl::lang::syntax::Spec;
use hstl::lang::{Parsed, SpecWorld, WorldProblem};
use hstl::world::Facts;
use lsp_types::Uri;

use crate::world_arg::{LoadedWorld, item_help};

/// World files kept read at once; past it the cache starts afresh.
pub const MAX_CACHED_WORLDS: usize = 32;

/// What a world name resolved to.
#[derive(Clone, Debug)]
pub struct Resolved {
    /// The world file, for a name that is no built-in world.
    pub path: Option<PathBuf>,
    /// The world's facts and words (``world `yard` (yard.toml; 20 x 10, slip 0.1)``), or why
    /// it could not be had.
    pub world: Arc<Result<(Facts, String), WorldProblem>>,
}

/// The worlds of one analysis, by the text of each `world` item.
#[derive(Clone, Debug, Default)]
pub struct DocWorlds {
    by_name: HashMap<String, Resolved>,
    /// The document's folder, which relative paths start from.
    folder: Option<PathBuf>,
}

impl DocWorlds {
    /// What `spec` is checked against: the world it names, or nothing.
    pub fn lookup(&self, spec: &Spec) -> SpecWorld<'_> {
        let Some(item) = hstl::lang::world_item(spec) else { return SpecWorld::Alone };
        match self.by_name.get(&item.name).map(|r| r.world.as_ref()) {
            Some(Ok((facts, _))) => facts.spec_world(),
            Some(Err(problem)) => SpecWorld::Unavailable(problem),
            None => SpecWorld::Alone,
        }
    }

    /// What the `world` item `name` resolved to.
    pub fn get(&self, name: &str) -> Option<&Resolved> {
        self.by_name.get(name)
    }

    /// The document's folder, if it is a file.
    pub fn folder(&self) -> Option<&Path> {
        self.folder.as_deref()
    }

    /// Whether any world of this analysis was read from a file.
    pub fn has_files(&self) -> bool {
        self.by_name.values().any(|r| r.path.is_some())
    }
}

/// World files read so far, with the size and time they were read at.
#[derive(Default)]
pub struct WorldCache {
    files: HashMap<PathBuf, (Option<(SystemTime, u64)>, Resolved)>,
}

impl WorldCache {
    /// The worlds the specs of `parsed` name, paths relative to `folder` (the document's;
    /// `None` for a document that is not a file, whose relative paths cannot be read).
    pub fn resolve(&mut self, parsed: &Parsed, folder: Option<&Path>) -> DocWorlds {
        let mut by_name = HashMap::new();
        for spec in &parsed.file.specs {
            if let Some(item) = hstl::lang::world_item(spec)
                && !by_name.contains_key(&item.name)
            {
                by_name.insert(item.name.clone(), self.one(&item.name, folder));
            }
        }
        DocWorlds { by_name, folder: folder.map(Path::to_path_buf) }
    }

    fn one(&mut self, name: &str, folder: Option<&Path>) -> Resolved {
        if hstl::world::AnyWorld::builtin(name).is_some() {
            return Resolved { path: None, world: Arc::new(load(name, None)) };
        }
        let path = match folder {
            Some(folder) if Path::new(name).is_relative() => folder.join(name),
            _ if Path::new(name).is_relative() => {
                let problem = WorldProblem {
                    message: format!(
                        "world `{name}` is no built-in world, and this document is no file: its path has no folder to be relative to"
                    ),
                    help:
                        "save the spec as a file, or use a built-in world (`paper`, `four-rooms`)"
                            .into(),
                };
                return Resolved { path: None, world: Arc::new(Err(problem)) };
            }
            _ => PathBuf::from(name),
        };
        let stamp = std::fs::metadata(&path)
            .ok()
            .map(|m| (m.modified().unwrap_or(SystemTime::UNIX_EPOCH), m.len()));
        if let Some((seen, resolved)) = self.files.get(&path)
            && *seen == stamp
            && stamp.is_some()
        {
            return resolved.clone();
        }
        if self.files.len() >= MAX_CACHED_WORLDS {
            self.files.clear();
        }
        let resolved = Resolved { path: Some(path.clone()), world: Arc::new(load(name, folder)) };
        self.files.insert(path, (stamp, resolved.clone()));
        resolved
    }
}

/// Reads the world `name` names as `hstlc check` does.
fn load(name: &str, folder: Option<&Path>) -> Result<(Facts, String), WorldProblem> {
    let world = LoadedWorld::named(name, folder)
        .map_err(|e| WorldProblem { message: e.to_string(), help: item_help(&e) })?;
    Ok((hstl::world::any_facts(&world.world, &world.label), world.words()))
}

/// The file a `file:` URI names, or `None` for another scheme.
pub fn uri_path(uri: &Uri) -> Option<PathBuf> {
    let s = uri.as_str();
    let rest = s.strip_prefix("file://")?;
    // `file:///path` or `file://localhost/path`.
    let rest = rest.strip_prefix("localhost").unwrap_or(rest);
    if !rest.starts_with('/') {
        return None;
    }
    let bytes = percent_decode(rest)?;
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStringExt;
        Some(PathBuf::from(std::ffi::OsString::from_vec(bytes)))
    }
    #[cfg(not(unix))]
    {
        String::from_utf8(bytes).ok().map(PathBuf::from)
    }
}

/// The `file:` URI of an absolute path.
pub fn path_uri(path: &Path) -> Option<Uri> {
    let path = std::path::absolute(path).ok()?;
    let text = path.to_str()?;
    let mut out = String::from("file://");
    for b in text.bytes() {
        if b.is_ascii_alphanumeric() || b"/-._~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out.parse().ok()
}

fn percent_decode(s: &str) -> Option<Vec<u8>> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        if b[i] == b'%' {
            let hex = s.get(i + 1..i + 3)?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            i += 3;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    Some(out)
}
