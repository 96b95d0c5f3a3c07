//! `hstl.World`, and the generator `hstl.GridWorldEnv` draws from.

use std::path::{Path, PathBuf};

use hstl::runtime::{
    Cell, Env, GridWorld, Rng, Value, json, rng_from_state, rng_state, seeded_rng,
};
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use crate::errors::{self, world_error};

/// A grid world: the paper's open grid, four rooms, or a map read from a world file.
///
/// Make one with `World.builtin(name)` (`"paper"`, the paper's 15 x 15 open grid with slip
/// 0.3, or `"four-rooms"`), `World.load(path)` (a world file, see the README's "Worlds")
/// or `World.parse(text)`. `x` counts columns from 0 at the left, `y` rows from 0 at the
/// bottom; only free cells are states, numbered row by row from the bottom.
///
/// A world pickles by its contents (name, slip and map).
#[pyclass(module = "hstl", frozen)]
pub struct World {
    pub world: GridWorld,
    /// The file it was read from, as given; None for a built-in or parsed world.
    pub file: Option<String>,
}

/// The one random generator of a `GridWorldEnv` (ChaCha8, as the learner's), seeded by
/// `reset(seed=...)`. It pickles and copies by its whole state: the copy draws what the
/// original would.
#[pyclass(module = "hstl._hstl")]
pub struct Generator {
    pub rng: Rng,
}

#[pymethods]
impl Generator {
    #[new]
    fn new(seed: u64) -> Generator {
        Generator { rng: seeded_rng(seed) }
    }

    /// The generator whose state `__reduce__` gave: key, stream and word position (high
    /// and low 64 bits).
    #[staticmethod]
    fn _from_state(key: [u8; 32], stream: u64, pos_high: u64, pos_low: u64) -> Generator {
        let pos = (u128::from(pos_high) << 64) | u128::from(pos_low);
        Generator { rng: rng_from_state(key, stream, pos) }
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let (key, stream, pos) = rng_state(&slf.borrow().rng);
        let args = (key, stream, (pos >> 64) as u64, pos as u64).into_pyobject(slf.py())?;
        Ok((slf.get_type().getattr("_from_state")?, args))
    }
}

impl World {
    pub fn new(world: GridWorld, file: Option<String>) -> World {
        World { world, file }
    }

    /// How messages name the world: ``world `paper` `` or ``world `office` (office.toml)``.
    pub fn label(&self) -> String {
        hstl::world::label(&self.world, self.file.as_deref())
    }

    /// The world in the file at `path`, with the CLI's words for every error.
    pub fn read(path: &Path) -> PyResult<World> {
        let w = crate::files::read_world(path)?;
        let world =
            hstl::world::from_file(&w.text, &w.file, &w.stem).map_err(|p| world_error(&p))?;
        Ok(World::new(world, Some(w.file)))
    }

    /// A built-in world's name or a world file's path, as `hstlc --world` reads it.
    pub fn resolve(arg: &str) -> PyResult<World> {
        if let Some(world) = GridWorld::builtin(arg) {
            return Ok(World::new(world, None));
        }
        if !hstl::world::looks_like_file(arg) && !Path::new(arg).exists() {
            return Err(world_error(&hstl::world::unknown(arg)));
        }
        World::read(Path::new(arg))
    }

    fn cell(&self, s: usize) -> (usize, usize) {
        self.world.state(s).map_or((0, 0), |c| (c.x, c.y))
    }
}

#[pymethods]
impl World {
    /// Reads the world file at `path`. Raises `hstl.WorldError` (a `ValueError`) at the
    /// file's line and column when it is not a valid world, and `FileNotFoundError` (or
    /// another `OSError`) when it cannot be read.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<World> {
        World::read(&path)
    }

    /// A built-in world by name: `"paper"` or `"four-rooms"`. Raises `hstl.WorldError`
    /// for any other name.
    #[staticmethod]
    fn builtin(name: &str) -> PyResult<World> {
        GridWorld::builtin(name)
            .map(|w| World::new(w, None))
            .ok_or_else(|| world_error(&hstl::world::unknown(name)))
    }

    /// The world in the text of a world file, reported as `filename` in errors and named
    /// `name` when the text gives no `name`.
    #[staticmethod]
    #[pyo3(signature = (text, filename="<string>".to_string(), name="world".to_string()))]
    fn parse(text: &str, filename: String, name: String) -> PyResult<World> {
        let world = hstl::world::from_file(text, &filename, &name).map_err(|p| world_error(&p))?;
        Ok(World::new(world, None))
    }

    /// The world's name: `paper`, `four-rooms`, or what its file names it.
    #[getter]
    fn name(&self) -> &str {
        self.world.world_name()
    }

    /// The number of columns.
    #[getter]
    fn width(&self) -> usize {
        self.world.width()
    }

    /// The number of rows.
    #[getter]
    fn height(&self) -> usize {
        self.world.height()
    }

    /// The probability that the chosen action is not taken (then one of the other three
    /// is, each equally likely).
    #[getter]
    fn slip(&self) -> f64 {
        self.world.slip()
    }

    /// The map's lines as a world file writes them, top row first: `.` free, `#` wall,
    /// `S` start.
    #[getter]
    fn map(&self) -> Vec<String> {
        self.world.map_lines()
    }

    /// The free cells `(x, y)`, in state order (row by row from the bottom).
    #[getter]
    fn free_cells(&self) -> Vec<(usize, usize)> {
        (0..self.world.num_states()).map(|s| self.cell(s)).collect()
    }

    /// The cells `(x, y)` where episodes start: the `S` cells, or every free cell.
    #[getter]
    fn starts(&self) -> Vec<(usize, usize)> {
        self.world.starts().into_iter().map(|s| self.cell(s)).collect()
    }

    /// The number of free cells (the learner's states).
    #[getter]
    fn num_states(&self) -> usize {
        self.world.num_states()
    }

    /// The action names, in index order: `Up` (y + 1), `Down`, `Left` (x - 1), `Right`.
    #[getter]
    fn actions(&self) -> Vec<String> {
        self.world.actions()
    }

    /// The file the world was read from, as given to `World.load`; None otherwise.
    #[getter]
    fn file(&self) -> Option<&str> {
        self.file.as_deref()
    }

    /// Whether `(x, y)` is a free cell (on the map and not a wall).
    fn is_free(&self, x: i64, y: i64) -> bool {
        match (usize::try_from(x), usize::try_from(y)) {
            (Ok(x), Ok(y)) => self.world.is_free(x, y),
            _ => false,
        }
    }

    /// A built-in world's name or a world file's path, as `hstlc --world` reads it.
    #[staticmethod]
    #[pyo3(name = "_resolve")]
    fn py_resolve(arg: &str) -> PyResult<World> {
        World::resolve(arg)
    }

    /// A start state drawn from `generator`: `(state, x, y)`.
    fn _reset(&self, generator: &mut Generator) -> (usize, usize, usize) {
        let cell = self.world.reset(&mut generator.rng);
        (self.world.index(&cell), cell.x, cell.y)
    }

    /// The state after taking `action` in state `state`, drawn from `generator`:
    /// `(state, x, y)`.
    fn _step(
        &self,
        state: usize,
        action: usize,
        generator: &mut Generator,
    ) -> (usize, usize, usize) {
        let here = self.world.state(state).unwrap_or(Cell { x: 0, y: 0 });
        let next = self.world.step(&here, action, &mut generator.rng);
        (self.world.index(&next), next.x, next.y)
    }

    /// The state index of the free cell `(x, y)`, or None.
    fn _index(&self, x: i64, y: i64) -> Option<usize> {
        self.is_free(x, y).then(|| self.world.index(&Cell { x: x as usize, y: y as usize }))
    }

    #[staticmethod]
    fn _from_contents(
        name: &str,
        slip: f64,
        map: Vec<String>,
        file: Option<String>,
    ) -> PyResult<World> {
        let params: Value = json!({ "slip": slip, "map": map });
        let world = GridWorld::from_params(name, &params)
            .map_err(|e| errors::value_error(format!("not a world: {e}"), None))?;
        Ok(World::new(world, file))
    }

    fn __reduce__<'py>(
        slf: &Bound<'py, Self>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let py = slf.py();
        let this = slf.get();
        let args = (
            this.world.world_name().to_string(),
            this.world.slip(),
            this.world.map_lines(),
            this.file.clone(),
        )
            .into_pyobject(py)?;
        Ok((slf.get_type().getattr("_from_contents")?, args))
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other.cast::<World>().is_ok_and(|o| o.get().world == self.world)
    }

    fn __hash__(&self) -> u64 {
        use std::hash::{Hash, Hasher};
        let mut h = std::collections::hash_map::DefaultHasher::new();
        (self.world.world_name(), self.world.slip().to_bits(), self.world.map_lines()).hash(&mut h);
        h.finish()
    }

    fn __repr__(&self) -> String {
        let walls = self.world.width() * self.world.height() - self.world.num_states();
        format!(
            "<hstl.World `{}` {} x {}, {walls} walls, slip {}>",
            self.world.world_name(),
            self.world.width(),
            self.world.height(),
            self.world.slip()
        )
    }
}
