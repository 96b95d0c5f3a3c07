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
use crate::world_arg::LoadedWorld;

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

/// Reads and checks `path` (against `world`, for the commands that train) and picks the
/// spec named `wanted` (or the only one). A file with
/// errors has its diagnostics printed to standard error, as `check` renders them, and gives
/// `Ok(None)`: the caller exits with status 1.
pub fn load(
    path: &Path,
    wanted: Option<&str>,
    world: Option<&LoadedWorld>,
) -> Result<Option<LoadedSpec>, CliError> {
    let (file, source) = read_input(path, "<stdin>")?;
    let loaded = match world {
        Some(w) => hstl::load::load_in_world(&source, wanted, &w.world, &w.label),
        None => hstl::load::load(&source, wanted),
    };
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
