//! Loading one spec from a file for the commands that run it (`monitor`, `train`, `study`).

use std::io::IsTerminal;
use std::path::Path;

use hstl::lang::CheckedSpec;
use hstl::load::LoadError;
use hstl::runtime::TaskSpec;

use crate::check::{Checked, read_input};
use crate::cli_error::CliError;
use crate::output::err;
use crate::render;
use crate::world_arg::{LoadedWorld, check_source, override_note};

/// A spec that checked without errors.
pub struct LoadedSpec {
    /// The file's name as reported.
    pub file: String,
    /// The file's text.
    pub source: String,
    /// The checked spec.
    pub spec: CheckedSpec,
}

impl LoadedSpec {
    /// The spec as the runtime's data, when it can be trained: it has options, and every
    /// state variable is an `int` with a range (the learner's tables enumerate them).
    pub fn trainable(&self) -> Result<TaskSpec, CliError> {
        hstl::train::trainable(&self.spec, &self.source, &self.file)
            .map_err(|p| CliError::new(p.message, p.help))
    }
}

/// Reads and checks `path` alone (no world: what `monitor` runs) and picks the spec named
/// `wanted` (or the only one). A file with errors has its diagnostics printed to standard
/// error, as `check` renders them, and gives `Ok(None)`: the caller exits with status 1.
pub fn load(path: &Path, wanted: Option<&str>) -> Result<Option<LoadedSpec>, CliError> {
    let (file, source) = read_input(path, "<stdin>")?;
    let loaded = hstl::load::load(&source, wanted);
    picked(file, source, loaded)
}

/// Reads `path` for the commands that train: picks the spec named `wanted` (or the only
/// one) and its world, `flag` (`--world`) when given, else the world the spec names, else
/// `paper`; checks the spec against that world, and says on standard error which world it
/// is when that is not the one the spec names. Errors as [`load`].
pub fn load_trainable(
    path: &Path,
    wanted: Option<&str>,
    flag: Option<&str>,
) -> Result<Option<(LoadedSpec, LoadedWorld)>, CliError> {
    let imposed = flag.map(LoadedWorld::load).transpose()?;
    let (file, source) = read_input(path, "<stdin>")?;
    let on_disk = (path != Path::new("-")).then_some(path);
    let (checked, worlds) = check_source(&source, on_disk, imposed.as_ref());
    let Some(loaded) = picked(file, source, hstl::load::pick(checked, wanted))? else {
        return Ok(None);
    };
    let named = loaded.spec.world.as_ref().map(|w| w.name.clone());
    match (imposed, named) {
        (Some(imposed), named) => {
            if let Some(named) = named
                && let Some(note) =
                    override_note(&loaded.file, &loaded.spec.name, &named, &worlds, &imposed)
            {
                err!("{note}");
            }
            Ok(Some((loaded, imposed)))
        }
        (None, Some(named)) => match worlds.get(&named) {
            Some(Ok(world)) => Ok(Some((loaded, world.clone()))),
            // Checked above: a world that cannot be had is an error (HSTL034).
            _ => {
                Err(CliError::new(format!("{}: world `{named}` cannot be read", loaded.file), None))
            }
        },
        (None, None) => {
            // A spec that names no world trains in `paper` (a `float` one in `paper-plane`,
            // the same world as a plane), checked against it first.
            let default = if loaded.spec.is_continuous() { "paper-plane" } else { "paper" };
            let paper = LoadedWorld::load(default)?;
            if loaded.spec.primitives.is_empty() {
                // Nothing to train: `trainable` says so, without a word on worlds.
                return Ok(Some((loaded, paper)));
            }
            err!(
                "note: {}: spec `{}` names no world (`world \"NAME\";`): training in {}\n",
                loaded.file,
                loaded.spec.name,
                paper.label
            );
            let (checked, _) = check_source(&loaded.source, on_disk, Some(&paper));
            let loaded = picked(loaded.file, loaded.source, hstl::load::pick(checked, wanted))?;
            Ok(loaded.map(|l| (l, paper)))
        }
    }
}

/// The spec `load` picked, or its errors printed.
fn picked(
    file: String,
    source: String,
    loaded: Result<hstl::load::Loaded, LoadError>,
) -> Result<Option<LoadedSpec>, CliError> {
    match loaded {
        Ok(loaded) => Ok(Some(LoadedSpec { file, source, spec: loaded.spec })),
        Err(LoadError::Invalid(diagnostics)) => {
            let report = Checked { name: file, source, diagnostics };
            err!(
                "{}",
                render::full(std::slice::from_ref(&report), std::io::stderr().is_terminal())
            );
            Ok(None)
        }
        Err(e) => Err(CliError::new(format!("{file}: {e}"), e.help("`--spec NAME`"))),
    }
}
