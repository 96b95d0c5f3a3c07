//! `hstl.check` and `hstl.explain`: the checker and the long explanations of its codes.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyString;

use crate::diagnostic::Diagnostic;
use crate::errors::{self, diagnostics_of, value_error};
use crate::world::World;

/// Every diagnostic of a spec file or text (errors, warnings and notes, in source order),
/// as `hstlc check --format json` gives them; the specs with options are checked against
/// `world` too (a `hstl.World`, a built-in name or a world file) when one is given.
///
/// `path_or_text` is a path (a `str` without a newline or `{`, or an `os.PathLike`) or
/// spec text (reported as `<string>`). Never raises for a spec that does not check: its
/// errors are in the list.
#[pyfunction]
#[pyo3(signature = (path_or_text, world=None))]
pub fn check(
    py: Python<'_>,
    path_or_text: &Bound<'_, PyAny>,
    world: Option<&Bound<'_, PyAny>>,
) -> PyResult<Vec<Diagnostic>> {
    let (file, source) = match path_or_text.cast::<PyString>() {
        Ok(s) => {
            let s: String = s.extract()?;
            if s.contains('\n') || s.contains('{') {
                ("<string>".to_string(), s)
            } else {
                read(PathBuf::from(&s))?
            }
        }
        Err(_) => read(path_or_text.extract::<PathBuf>().map_err(|_| {
            errors::type_error(
                format!(
                    "`path_or_text` must be a path or spec text; got {}",
                    type_name(path_or_text)
                ),
                Some("pass a spec file's path or the spec's text".to_string()),
            )
        })?)?,
    };
    let world = match world {
        None => None,
        Some(w) => Some(match w.cast::<World>() {
            Ok(w) => w.clone(),
            Err(_) => {
                let arg: PathBuf = w.extract().map_err(|_| {
                    errors::type_error(
                        format!(
                            "`world` must be a hstl.World, a built-in name or a world file; got {}",
                            type_name(w)
                        ),
                        Some("pass \"paper\", \"four-rooms\" or a world file's path".to_string()),
                    )
                })?;
                Bound::new(py, World::resolve(&arg.display().to_string())?)?
            }
        }),
    };
    let diagnostics = match &world {
        Some(w) => {
            let w = w.get();
            let label = w.label();
            py.detach(|| hstl::load::check(&source, Some((&w.world, &label))))
        }
        None => py.detach(|| hstl::load::check(&source, None)),
    };
    Ok(diagnostics_of(&file, &source, &diagnostics))
}

/// The name of `value`'s type, for messages.
fn type_name(value: &Bound<'_, PyAny>) -> String {
    value.get_type().name().map_or_else(|_| "?".to_string(), |n| n.to_string())
}

/// The spec file at `path`: its name as messages give it, and its text.
fn read(path: PathBuf) -> PyResult<(String, String)> {
    let text = crate::files::read_text(&path, hstl::lang::MAX_SOURCE_BYTES, "spec", |e| {
        errors::read_error(&path, e)
    })?;
    Ok((path.display().to_string(), text))
}

/// The long explanation of a diagnostic code such as `"HSTL150"` (case-insensitive), as
/// `hstlc explain` prints it. Raises `ValueError` naming the known codes for another.
#[pyfunction]
pub fn explain(code: &str) -> PyResult<String> {
    hstl::load::explain(code).map_err(|e| value_error(e.to_string(), Some(e.help())))
}
