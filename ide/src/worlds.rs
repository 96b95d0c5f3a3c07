//! The worlds that open documents name (`world "NAME_OR_PATH";`), as the checks see them.
//!
//! A path is relative to the document's folder. A world file is read once and read again
//! when its size or modification time changes (checked at every analysis, and on
//! `workspace/didChangeWatchedFiles`), so the editor follows a map being edited beside the
//! spec. At most [`MAX_CACHED_WORLDS`] files are kept; the cache is a convenience, never
//! a bound on what a document may name. How a world is read is the caller's
//! ([`Loader`]: `hstlc` reads one as `hstlc check` does).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::SystemTime;

use hstl::lang::syntax::Spec;
use hstl::lang::{Parsed, SpecWorld, WorldProblem};
use hstl::world::Facts;

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

/// Reads the world a `world` item names (a built-in world's name, or a file's path
/// relative to `folder`): its facts and words, or why it cannot be had.
pub type Loader = fn(&str, Option<&Path>) -> Result<(Facts, String), WorldProblem>;

/// World files read so far, with the size and time they were read at.
pub struct WorldCache {
    files: HashMap<PathBuf, (Option<(SystemTime, u64)>, Resolved)>,
    load: Loader,
}

impl WorldCache {
    /// An empty cache that reads worlds with `load`.
    pub fn new(load: Loader) -> WorldCache {
        WorldCache { files: HashMap::new(), load }
    }

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
            return Resolved { path: None, world: Arc::new((self.load)(name, None)) };
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
        let resolved =
            Resolved { path: Some(path.clone()), world: Arc::new((self.load)(name, folder)) };
        self.files.insert(path, (stamp, resolved.clone()));
        resolved
    }
}
