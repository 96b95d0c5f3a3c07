//! Loading one spec from a file for the commands that run it (`monitor`, `train`, `study`).

use std::io::IsTerminal;
use std::path::Path;

use hstl::lang::CheckedSpec;
use hstl::runtime::TaskSpec;

use crate::check::{Checked, read_input};
use crate::cli_error::CliError;
use crate::render;

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
    /// The spec as the runtime's data.
    pub fn task_spec(&self) -> Result<TaskSpec, CliError> {
        hstl::lower::task_spec(&self.spec, &self.source)
            .map_err(|e| CliError::new(format!("{}: {e}", self.file), None))
    }
}

/// Reads and checks `path` and picks the spec named `wanted` (or the only one). A file with
/// errors has its diagnostics printed to standard error, as `check` renders them, and gives
/// `Ok(None)`: the caller exits with status 1.
pub fn load(path: &Path, wanted: Option<&str>) -> Result<Option<LoadedSpec>, CliError> {
    let (file, source) = read_input(path, "<stdin>")?;
    let mut checked = hstl::lang::check(&source);
    if checked.has_errors() {
        let report = Checked { name: file, source, diagnostics: checked.diagnostics };
        eprint!("{}", render::full(std::slice::from_ref(&report), std::io::stderr().is_terminal()));
        return Ok(None);
    }
    let index = pick(&checked.specs, wanted, &file)?;
    let spec = checked.specs.swap_remove(index);
    Ok(Some(LoadedSpec { file, source, spec }))
}

/// The index of the spec named `wanted`, or of the only one in the file.
fn pick(specs: &[CheckedSpec], wanted: Option<&str>, file: &str) -> Result<usize, CliError> {
    let names = || specs.iter().map(|s| format!("`{}`", s.name)).collect::<Vec<_>>().join(", ");
    match (wanted, specs.len()) {
        (None, 1) => Ok(0),
        (None, 0) => Err(CliError::new(
            format!("{file}: the file holds no spec"),
            Some("write `spec Name { ... }` in it".to_string()),
        )),
        (None, n) => Err(CliError::new(
            format!("{file}: the file holds {n} specs"),
            Some(format!("pick one with `--spec NAME`: {}", names())),
        )),
        (Some(w), _) => specs.iter().position(|s| s.name == w).ok_or_else(|| {
            CliError::new(
                format!("{file}: no spec named `{w}`"),
                Some(format!("the file holds {}", names())),
            )
        }),
    }
}
