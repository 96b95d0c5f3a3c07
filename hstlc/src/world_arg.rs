//! `--world NAME|FILE.toml`: a built-in world by name, or a world file.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use hstl::lang::syntax::Spec;
use hstl::lang::{Parsed, SpecWorld, WorldProblem};
use hstl::world::{AnyWorld, Facts, GridWorld};

use crate::cli_error::CliError;
use crate::input;

/// A world and how messages name it.
#[derive(Clone)]
pub struct LoadedWorld {
    /// The world: a grid, a plane or `mountain-car`.
    pub world: AnyWorld,
    /// ``world `four-rooms` `` or ``world `office` (maps/office.toml)``.
    pub label: String,
    /// The world file, for one read from a file.
    pub file: Option<String>,
}

/// The `--world` help text.
pub const WORLD_HELP: &str = "The grid world: a built-in name (`paper`, the paper's 15 x 15 \
open grid with slip 0.3, or `four-rooms`) or a world file (`FILE.toml`, see README \
\"Worlds\")";

impl LoadedWorld {
    /// The world `arg` names: a built-in name, or a path to a world file. Errors name the
    /// file, line and column.
    pub fn load(arg: &str) -> Result<LoadedWorld, CliError> {
        LoadedWorld::named(arg, None).map_err(|e| match e {
            CliError::Read { .. } => CliError::new(e.to_string(), Some(hstl::world::read_help())),
            other => other,
        })
    }

    /// The world a spec's `world "ARG";` item names: a built-in name, or a world file's
    /// path relative to `base` (the spec file's folder; `None`: the current folder). A file
    /// that cannot be read is `CliError::Read`, without help ([`item_help`] gives one).
    pub fn named(arg: &str, base: Option<&Path>) -> Result<LoadedWorld, CliError> {
        if let Some(world) = AnyWorld::builtin(arg) {
            let label = hstl::world::any_label(&world, None);
            return Ok(LoadedWorld { world, label, file: None });
        }
        let path: PathBuf = match base {
            Some(base) if Path::new(arg).is_relative() => base.join(arg),
            _ => PathBuf::from(arg),
        };
        let path = path.as_path();
        if !hstl::world::looks_like_file(arg) && !path.exists() {
            let unknown = hstl::world::unknown(arg);
            return Err(CliError::new(unknown.message, unknown.help));
        }
        // A file that cannot be read stays `CliError::Read`, so each caller says how to fix
        // it (too large or not UTF-8 say so already).
        let input::Input { name: file, text, .. } =
            input::read_regular_text(path, hstl::world::MAX_WORLD_BYTES as u64, "world file")?;
        let stem = path.file_stem().map_or("world".into(), |s| s.to_string_lossy().into_owned());
        let world = hstl::world::any_from_file(&text, &file, &stem)
            .map_err(|p| CliError::new(p.message, p.help))?;
        let label = hstl::world::any_label(&world, Some(&file));
        Ok(LoadedWorld { world, label, file: Some(file) })
    }

    /// The world's name, size and slip, for summaries.
    pub fn words(&self) -> String {
        hstl::world::words(&self.world, self.file.as_deref())
    }
}

/// ``world `four-rooms` (13 x 13, 65 walls, slip 0.3)``, with the file it was read from
/// before the size (see [`hstl::world::words`]).
pub fn world_words(world: &GridWorld, file: Option<&str>) -> String {
    hstl::world::words(&AnyWorld::Grid(world.clone()), file)
}

/// Where a spec's world comes from when it is checked.
pub enum WorldChoice<'a> {
    /// `--world`: every spec with options is checked against this world, whatever it names.
    Override(&'a LoadedWorld),
    /// Each spec's own `world` item, its path relative to this folder (the spec file's;
    /// `None`: the current folder, for standard input). A spec without one is checked alone.
    FromSpecs(Option<&'a Path>),
}

/// The worlds the specs of one text name, each read once, as the checks see them.
pub struct SpecWorlds {
    named: HashMap<String, Result<(LoadedWorld, Facts), WorldProblem>>,
    imposed: Option<Facts>,
}

impl SpecWorlds {
    /// Reads the world each spec of `parsed` names, relative to `base`; with `imposed`
    /// (`--world`), the specs are checked against that one instead.
    pub fn resolve(
        parsed: &Parsed,
        base: Option<&Path>,
        imposed: Option<&LoadedWorld>,
    ) -> SpecWorlds {
        let mut named = HashMap::new();
        for spec in &parsed.file.specs {
            if let Some(item) = hstl::lang::world_item(spec)
                && !named.contains_key(&item.name)
            {
                let loaded = LoadedWorld::named(&item.name, base)
                    .map(|w| {
                        let facts = hstl::world::any_facts(&w.world, &w.label);
                        (w, facts)
                    })
                    .map_err(|e| WorldProblem { message: e.to_string(), help: item_help(&e) });
                named.insert(item.name.clone(), loaded);
            }
        }
        let imposed = imposed.map(|w| hstl::world::any_facts(&w.world, &w.label));
        SpecWorlds { named, imposed }
    }

    /// What `spec` is checked against.
    pub fn lookup(&self, spec: &Spec) -> SpecWorld<'_> {
        if let Some(facts) = &self.imposed {
            return facts.spec_world();
        }
        match hstl::lang::world_item(spec).and_then(|item| self.named.get(&item.name)) {
            Some(Ok((_, facts))) => facts.spec_world(),
            Some(Err(problem)) => SpecWorld::Unavailable(problem),
            None => SpecWorld::Alone,
        }
    }

    /// The world that a `world "NAME";` item names, read, or why it could not be.
    pub fn get(&self, name: &str) -> Option<Result<&LoadedWorld, &WorldProblem>> {
        self.named.get(name).map(|r| r.as_ref().map(|(w, _)| w))
    }
}

/// Checks `source` (the file `path`; `None` for standard input) with each spec against its
/// world: the one it names, or `imposed` (`--world`).
pub fn check_source(
    source: &str,
    path: Option<&Path>,
    imposed: Option<&LoadedWorld>,
) -> (hstl::lang::Checked, SpecWorlds) {
    let parsed = hstl::lang::parse(source);
    let worlds = SpecWorlds::resolve(&parsed, spec_folder(path), imposed);
    let checked = hstl::lang::check_parsed_with_worlds(source, parsed, &|spec| worlds.lookup(spec));
    (checked, worlds)
}

/// The folder a spec file's `world` paths are relative to: the file's own (`None`: the
/// current folder).
pub fn spec_folder(path: Option<&Path>) -> Option<&Path> {
    path.and_then(Path::parent).filter(|p| !p.as_os_str().is_empty())
}

/// The note printed when `--world` replaces a different world that a spec names.
pub fn override_note(
    file: &str,
    spec: &str,
    named: &str,
    worlds: &SpecWorlds,
    imposed: &LoadedWorld,
) -> Option<String> {
    let same = matches!(worlds.get(named), Some(Ok(w)) if w.world == imposed.world);
    (!same).then(|| {
        format!(
            "note: {file}: spec `{spec}` names world `{named}`; `--world` checks it against {} instead\n",
            imposed.label
        )
    })
}

/// How to fix a `world` item whose world cannot be had: the world file's own help for a
/// malformed one, else where its path starts from.
pub fn item_help(e: &CliError) -> String {
    match e {
        CliError::Other { help: Some(help), .. } => help.clone(),
        _ => format!(
            "a world file's path is relative to the spec file's folder; or name a built-in \
             world ({})",
            hstl::world::builtin_list()
        ),
    }
}
