//! `hstl.ContinuousWorld`: a plane world or `mountain-car`, as `hstl.PlaneEnv` and
//! `hstl.MountainCarEnv` step it (through `hstl::gym`, one call a step).

use std::path::{Path, PathBuf};

use hstl::runtime::Value;
use hstl::world::AnyWorld;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::errors::{self, problem_error, world_error};
use crate::world::Generator;

/// A continuous world: a plane world (a point robot in a bounded plane with obstacles) or
/// `mountain-car` (gymnasium's MountainCar-v0 dynamics, without its goal).
///
/// Make one with `ContinuousWorld.builtin(name)` (`"paper-plane"`, the paper's case study
/// as a plane, or `"mountain-car"`), `ContinuousWorld.load(path)` (a world file with
/// `kind = "plane"`, see the README's "Worlds") or `ContinuousWorld.parse(text)`. Its
/// state is its `state_vars` (`x, y` for a plane, `x, v` for `mountain-car`), each within
/// `low` and `high`; its actions are `actions` (a plane's headings; `left`, `none`,
/// `right`).
///
/// A world pickles by its contents (name and parameters).
#[pyclass(module = "hstl", frozen)]
pub struct ContinuousWorld {
    pub world: AnyWorld,
    /// The file it was read from, as given; None for a built-in or parsed world.
    pub file: Option<String>,
}

impl ContinuousWorld {
    /// A world a policy holds (continuous, as its replay checked).
    pub fn of(world: AnyWorld) -> ContinuousWorld {
        ContinuousWorld { world, file: None }
    }

    /// A continuous world's action names.
    pub fn actions_of(world: &AnyWorld) -> Vec<String> {
        hstl::replayed::world_actions(world)
    }

    fn new(world: AnyWorld, file: Option<String>) -> PyResult<ContinuousWorld> {
        if world.is_continuous() {
            return Ok(ContinuousWorld { world, file });
        }
        let name = file.as_deref().unwrap_or(world.name()).to_string();
        Err(world_error(&hstl::Problem::new(
            format!("`{name}` is a grid world, not a continuous one"),
            "use `hstl.World` and `hstl.GridWorldEnv` for a grid world, or give a plane world \
             (`kind = \"plane\"`) or `mountain-car`"
                .to_string(),
        )))
    }

    /// The world in the file at `path`, with the CLI's words for every error.
    pub fn read(path: &Path) -> PyResult<ContinuousWorld> {
        let (world, file) = read_any(path)?;
        ContinuousWorld::new(world, Some(file))
    }

    /// A built-in continuous world's name or a world file's path.
    pub fn resolve(arg: &str) -> PyResult<ContinuousWorld> {
        if let Some(world) = AnyWorld::builtin(arg) {
            return ContinuousWorld::new(world, None);
        }
        if !hstl::world::looks_like_file(arg) && !Path::new(arg).exists() {
            return Err(world_error(&hstl::world::unknown(arg)));
        }
        ContinuousWorld::read(Path::new(arg))
    }

    fn values(state: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        state.extract::<Vec<f64>>().map_err(|_| {
            errors::type_error(
                format!(
                    "a state is a sequence of numbers, not {}",
                    state.get_type().name().map_or("?".into(), |n| n.to_string())
                ),
                Some("give the state variables' values in order, such as (x, y)".into()),
            )
        })
    }
}

#[pymethods]
impl ContinuousWorld {
    /// Reads the world file at `path` (a plane world). Raises `hstl.WorldError` (a
    /// `ValueError`) at the file's line and column when it is not a valid world or is a grid
    /// world, and `FileNotFoundError` (or another `OSError`) when it cannot be read.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<ContinuousWorld> {
        ContinuousWorld::read(&path)
    }

    /// A built-in continuous world by name: `"paper-plane"` or `"mountain-car"`. Raises
    /// `hstl.WorldError` for any other name.
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<ContinuousWorld> {
        match AnyWorld::builtin(name) {
            Some(w) => ContinuousWorld::new(w, None),
            None => Err(world_error(&hstl::world::unknown(name))),
        }
    }

    /// The world in the text of a world file, reported as `filename` in errors and named
    /// `name` when the text gives no `name`.
    #[staticmethod]
    #[pyo3(signature = (text, filename="<string>".to_string(), name="world".to_string()))]
    fn parse(text: &str, filename: String, name: String) -> PyResult<ContinuousWorld> {
        let world =
            hstl::world::any_from_file(text, &filename, &name).map_err(|p| world_error(&p))?;
        ContinuousWorld::new(world, None)
    }

    /// A built-in world's name or a world file's path, as `hstlc --world` reads it.
    #[staticmethod]
    #[pyo3(name = "_resolve")]
    fn py_resolve(arg: &str) -> PyResult<ContinuousWorld> {
        ContinuousWorld::resolve(arg)
    }

    /// The world's name: `paper-plane`, `mountain-car`, or what its file names it.
    #[getter]
    fn name(&self) -> &str {
        self.world.name()
    }

    /// `"plane"` or `"mountain-car"`.
    #[getter]
    fn kind(&self) -> &str {
        match self.world {
            AnyWorld::MountainCar(_) => "mountain-car",
            _ => "plane",
        }
    }

    /// The state variables, in the order of a state's numbers.
    #[getter]
    fn state_vars(&self) -> Vec<String> {
        match &self.world {
            AnyWorld::Plane(p) => hstl::runtime::World::state_vars(p),
            AnyWorld::MountainCar(c) => hstl::runtime::World::state_vars(c),
            AnyWorld::Grid(_) => Vec::new(),
        }
    }

    /// The action names, in index order.
    #[getter]
    fn actions(&self) -> Vec<String> {
        ContinuousWorld::actions_of(&self.world)
    }

    /// Each state variable's least value (a plane's extent; `mountain-car`'s position and
    /// speed limits).
    #[getter]
    fn low(&self) -> Vec<f64> {
        hstl::gym::bounds(&self.world).map(|b| b.0).unwrap_or_default()
    }

    /// Each state variable's greatest value.
    #[getter]
    fn high(&self) -> Vec<f64> {
        hstl::gym::bounds(&self.world).map(|b| b.1).unwrap_or_default()
    }

    /// The file the world was read from, as given; None otherwise.
    #[getter]
    fn file(&self) -> Option<&str> {
        self.file.as_deref()
    }

    /// The world's parameters as `policy.json`'s `env.params` holds them (JSON text).
    #[getter]
    fn params_json(&self) -> String {
        self.world.params().to_string()
    }

    /// A start state drawn from `generator`.
    fn _reset(&self, generator: &mut Generator) -> PyResult<Vec<f64>> {
        hstl::gym::reset(&self.world, &mut generator.rng).map_err(|p| problem_error(&p))
    }

    /// The state after `action` from `state`, drawn from `generator`.
    fn _step(
        &self,
        state: &Bound<'_, PyAny>,
        action: usize,
        generator: &mut Generator,
    ) -> PyResult<Vec<f64>> {
        let values = ContinuousWorld::values(state)?;
        hstl::gym::step(&self.world, &values, action, &mut generator.rng)
            .map_err(|p| problem_error(&p))
    }

    /// `state` checked as a start state.
    fn _start(&self, state: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        let values = ContinuousWorld::values(state)?;
        hstl::gym::start(&self.world, &values).map_err(|p| problem_error(&p))
    }

    #[staticmethod]
    fn _from_params(name: &str, params: &str, file: Option<String>) -> PyResult<ContinuousWorld> {
        let params: Value =
            params.parse().map_err(|e| errors::value_error(format!("not a world: {e}"), None))?;
        let world = AnyWorld::from_params(name, &params)
            .map_err(|e| errors::value_error(format!("not a world: {e}"), None))?;
        ContinuousWorld::new(world, file)
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let this = slf.get();
        let args = (this.world.name().to_string(), this.params_json(), this.file.clone())
            .into_pyobject(slf.py())?;
        Ok((slf.get_type().getattr("_from_params")?, args))
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<ContinuousWorld>().is_ok_and(|o| o.get().world == self.world)
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (self.world.name(), self.params_json()).hash(&mut h);
        h.finish()
    }

    fn __repr__(&self) -> String {
        format!("<hstl.ContinuousWorld {}>", hstl::world::words(&self.world, None))
    }
}

/// A built-in world's name or a world file's path, as `hstlc --world` reads it: a
/// The world in the file at `path`, of either kind, and the file's name as errors give it,
/// with the CLI's words for every error.
fn read_any(path: &Path) -> PyResult<(AnyWorld, String)> {
    let w = crate::files::read_world(path)?;
    let world =
        hstl::world::any_from_file(&w.text, &w.file, &w.stem).map_err(|p| world_error(&p))?;
    Ok((world, w.file))
}

/// `hstl.World` for a grid, a `hstl.ContinuousWorld` for a plane or `mountain-car`.
#[pyfunction]
pub fn _resolve_any_world(py: Python<'_>, arg: &str) -> PyResult<Py<PyAny>> {
    let (world, file) = match AnyWorld::builtin(arg) {
        Some(world) => (world, None),
        None => {
            if !hstl::world::looks_like_file(arg) && !Path::new(arg).exists() {
                return Err(world_error(&hstl::world::unknown(arg)));
            }
            let (world, file) = read_any(Path::new(arg))?;
            (world, Some(file))
        }
    };
    Ok(match world {
        AnyWorld::Grid(g) => Py::new(py, crate::world::World::new(g, file))?.into_any(),
        continuous => Py::new(py, ContinuousWorld { world: continuous, file })?.into_any(),
    })
}

/// The spec source of the MountainCar patrol with window `window` (see
/// `hstl::gym::mountain_car_patrol`).
#[pyfunction]
pub fn _mountain_car_patrol(window: i64) -> PyResult<String> {
    hstl::gym::mountain_car_patrol(window).map_err(|p| problem_error(&p))
}
