//! Studies and Ray Tune: `hstl._hstl._study_task`, `_study_seeds`, `_study_optimum`,
//! `_study_summary`, `_StudyOut` (which `hstl.study` calls, on this machine or in Ray
//! tasks) and `_train_chunks` (which `hstl.tune` calls). Everything they compute is the
//! facade's (`hstl::study`, `hstl::train`), so `hstlc study` and every backend of
//! `hstl.study` give the same figures, bit for bit.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::Instant;

use hstl::runtime::TaskSpec;
use hstl::study::{self as facade, CurveSet, SeedRun, Stats, StudiedSpec};
use hstl_outdir::{OutDir, StudyDir, Writer};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::continuous::ContinuousWorld;
use crate::errors::{self, problem_error, value_error, write_error};
use crate::interrupt;
use crate::spec::Spec;
use crate::world::World;

/// A study's world: a grid (tables, W*) or a continuous one (tilings, no exact optimum).
enum StudyWorld<'a> {
    Grid(&'a World),
    Continuous(&'a ContinuousWorld),
}

impl<'a> StudyWorld<'a> {
    fn of(world: &'a Bound<'_, PyAny>) -> PyResult<StudyWorld<'a>> {
        if let Ok(w) = world.cast::<World>() {
            return Ok(StudyWorld::Grid(w.get()));
        }
        if let Ok(w) = world.cast::<ContinuousWorld>() {
            return Ok(StudyWorld::Continuous(w.get()));
        }
        Err(errors::type_error(
            "a study's world is a `hstl.World` or a `hstl.ContinuousWorld`",
            Some("pass a built-in world's name or a world file's path".into()),
        ))
    }
}

/// `task_of` in either kind of world: a continuous world's tiling fitted.
fn task_in(
    py: Python<'_>,
    spec: &Spec,
    world: &StudyWorld<'_>,
    episodes: Option<usize>,
) -> PyResult<(TaskSpec, hstl::lang::CheckedSpec)> {
    match world {
        StudyWorld::Grid(w) => task_of(py, spec, w, episodes, None),
        StudyWorld::Continuous(w) => {
            let label = hstl::world::any_label(&w.world, w.file.as_deref());
            let loaded = py
                .detach(|| {
                    hstl::load::load_in_any_world(
                        &spec.source,
                        Some(&spec.spec.name),
                        &w.world,
                        &label,
                    )
                })
                .map_err(|e| errors::load_error(py, &spec.filename, &spec.source, e))?;
            let mut task = hstl::train::trainable(&loaded.spec, &spec.source, &spec.filename)
                .map_err(|p| problem_error(&p))?;
            hstl::train::set_episodes(&mut task, episodes).map_err(|p| problem_error(&p))?;
            hstl::continuous::fit_tiles(&mut task, &loaded.spec, &w.world);
            Ok((task, loaded.spec))
        }
    }
}

/// The spec checked against the world (the diagnostics of `hstlc check --world` as
/// `hstl.SpecError`), with `episodes` and the `learn` values of `learn` set.
fn task_of(
    py: Python<'_>,
    spec: &Spec,
    world: &World,
    episodes: Option<usize>,
    learn: Option<&Bound<'_, PyDict>>,
) -> PyResult<(TaskSpec, hstl::lang::CheckedSpec)> {
    let label = world.label();
    let loaded = py
        .detach(|| {
            hstl::load::load_in_world(&spec.source, Some(&spec.spec.name), &world.world, &label)
        })
        .map_err(|e| errors::load_error(py, &spec.filename, &spec.source, e))?;
    let mut task = hstl::train::trainable(&loaded.spec, &spec.source, &spec.filename)
        .map_err(|p| problem_error(&p))?;
    hstl::train::set_episodes(&mut task, episodes).map_err(|p| problem_error(&p))?;
    if let Some(learn) = learn {
        for (key, value) in learn.iter() {
            let key: String = key.extract()?;
            let value: f64 = value.extract().map_err(|_| {
                value_error(
                    format!("`{key}` must be a number"),
                    Some("Tune's config gives each `learn` value a number".into()),
                )
            })?;
            hstl::train::set_learn(&mut task, &key, value).map_err(|p| problem_error(&p))?;
        }
        hstl::train::check_learn(&task).map_err(|p| problem_error(&p))?;
    }
    Ok((task, loaded.spec))
}

/// Checks `spec` against `world` as a study trains it; what the driver needs before it
/// sends seeds anywhere: `(name, episodes, regions)`, `regions` a key equal for specs with
/// the same regions (which share W*), or None for a task without them.
#[pyfunction]
#[pyo3(signature = (spec, world, episodes=None))]
pub fn _study_task(
    py: Python<'_>,
    spec: &Bound<'_, Spec>,
    world: &Bound<'_, PyAny>,
    episodes: Option<usize>,
) -> PyResult<(String, usize, Option<String>)> {
    let (task, _) = task_in(py, spec.get(), &StudyWorld::of(world)?, episodes)?;
    // The regions' data, only ever compared (never shown).
    let key = (!task.regions.is_empty()).then(|| format!("{:?}", task.regions)); // not a message
    Ok((task.name, task.learn.episodes, key))
}

/// Trains `spec` in `world` for each of `seeds` on `threads` threads (the GIL released) and
/// returns one dict per seed: `seed`, `window_rate` (or None), `reward` (per episode, the
/// mean of the last 100), `seconds` (training), `steps` and `curve` (reward per episode);
/// in a continuous world, `satisfaction` is the satisfaction rate P of a task that is not
/// persistent.
#[pyfunction]
#[pyo3(signature = (spec, world, seeds, episodes=None, threads=1))]
pub fn _study_seeds<'py>(
    py: Python<'py>,
    spec: &Bound<'py, Spec>,
    world: &Bound<'py, PyAny>,
    seeds: Vec<u64>,
    episodes: Option<usize>,
    threads: usize,
) -> PyResult<Bound<'py, PyList>> {
    let spec = spec.get();
    let world = StudyWorld::of(world)?;
    let (task, _) = task_in(py, spec, &world, episodes)?;
    let threads = threads.max(1);
    let start = Instant::now();
    let clock = move || start.elapsed().as_secs_f64();
    let stop = AtomicBool::new(false);
    let (tx, rx) = mpsc::channel();
    // The seeds train on threads of their own while this one, holding the GIL only for a
    // moment every `interrupt::SIGNAL_EVERY`, watches for Ctrl-C: on it no further seed starts.
    let done = std::thread::scope(|scope| {
        let (task, stop, clock) = (&task, &stop, &clock);
        let trainer = std::thread::Builder::new().spawn_scoped(scope, move || {
            let done = match world {
                StudyWorld::Grid(w) => facade::run_seeds(
                    task,
                    &w.world,
                    &seeds,
                    threads,
                    &spec.filename,
                    clock,
                    None,
                    Some(stop),
                )
                .map(|runs| runs.into_iter().map(|(run, _)| (run, None)).collect::<Vec<_>>()),
                StudyWorld::Continuous(w) => facade::run_continuous_seeds(
                    task,
                    &w.world,
                    &seeds,
                    threads,
                    &spec.filename,
                    clock,
                    Some(stop),
                ),
            };
            let _ = tx.send(done);
        });
        if trainer.is_err() {
            return Err(value_error("cannot start a thread to train on", None));
        }
        // On Ctrl-C no further seed starts; the seeds under way end before the scope does.
        let stopping = || stop.store(true, Ordering::Relaxed);
        let done = interrupt::wait(py, rx, stopping, "a training thread failed")?;
        done.map_err(|p| problem_error(&p))
    })?;
    let out = PyList::empty(py);
    for (run, rate) in done {
        let d = run_dict(py, &run)?;
        if let Some(p) = rate {
            d.set_item("satisfaction", p)?;
        }
        out.append(d)?;
    }
    Ok(out)
}

fn run_dict<'py>(py: Python<'py>, run: &SeedRun) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("seed", run.seed)?;
    d.set_item("window_rate", run.window_rate)?;
    d.set_item("satisfaction", run.satisfaction)?;
    d.set_item("reward", run.reward)?;
    d.set_item("seconds", run.secs)?;
    d.set_item("steps", run.steps)?;
    d.set_item("curve", run.curve.clone())?;
    Ok(d)
}

/// A run back from its dict (as `_study_seeds` made it, maybe in another process).
fn run_of(d: &Bound<'_, PyAny>) -> PyResult<SeedRun> {
    let get = |key: &str| d.get_item(key);
    Ok(SeedRun {
        seed: get("seed")?.extract()?,
        secs: get("seconds")?.extract()?,
        steps: get("steps")?.extract()?,
        reward: get("reward")?.extract()?,
        window_rate: get("window_rate")?.extract()?,
        // A continuous world's P has no exact optimum beside it: no pair to summarise.
        satisfaction: get("satisfaction")?.extract().unwrap_or(None),
        curve: get("curve")?.extract()?,
    })
}

/// W* of the spec's regions in the world (value iteration, the GIL released), or None for
/// a task without regions.
#[pyfunction]
pub fn _study_optimum(
    py: Python<'_>,
    spec: &Bound<'_, Spec>,
    world: &Bound<'_, PyAny>,
) -> PyResult<Option<f64>> {
    let world = match StudyWorld::of(world)? {
        // No exact optimum on a continuous world.
        StudyWorld::Continuous(_) => return Ok(None),
        StudyWorld::Grid(w) => w,
    };
    let (task, _) = task_of(py, spec.get(), world, None, None)?;
    let optimum = py.detach(|| facade::optimum(&task, &world.world)).map_err(|p| {
        value_error(p.message, Some("pass `optimum=False` to skip the optimum W*".into()))
    })?;
    Ok(optimum.map(|o| o.gain))
}

/// A spec's figures over its runs, as `hstlc study` prints them: a dict of dicts with
/// `mean`, `sd`, `min` and `max` for `seconds`, `reward`, and, where every seed has one,
/// `window_rate` and (with `optimum`) `ratio`, W/W*.
#[pyfunction]
#[pyo3(signature = (runs, optimum=None))]
pub fn _study_summary<'py>(
    py: Python<'py>,
    runs: Vec<Bound<'py, PyAny>>,
    optimum: Option<f64>,
) -> PyResult<Bound<'py, PyDict>> {
    let runs = runs.iter().map(run_of).collect::<PyResult<Vec<_>>>()?;
    let s = facade::summary(&runs, optimum);
    let stats = |s: Stats| -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        d.set_item("mean", s.mean)?;
        d.set_item("sd", s.sd)?;
        d.set_item("min", s.min)?;
        d.set_item("max", s.max)?;
        Ok(d)
    };
    let d = PyDict::new(py);
    d.set_item("seconds", stats(s.seconds)?)?;
    d.set_item("reward", stats(s.reward)?)?;
    if let Some(w) = s.window_rate {
        d.set_item("window_rate", stats(w)?)?;
    }
    if let Some(r) = s.ratio {
        d.set_item("ratio", stats(r)?)?;
    }
    Ok(d)
}

/// A study's output folder, as `hstlc study --out` writes it: each spec's folder taken
/// (locked) when this is made, so that a folder another run holds is refused before any
/// training; written by `write` once every result is in, each folder whole or not at all.
#[pyclass(module = "hstl._hstl")]
pub struct _StudyOut {
    paths: Vec<PathBuf>,
    spec_dirs: Vec<PathBuf>,
    dirs: Option<(StudyDir, Vec<OutDir>)>,
}

#[pymethods]
impl _StudyOut {
    /// Takes `out` and its folder for each spec, named from `paths` (each spec's file, or a
    /// name for a spec parsed from text) as `hstlc study` names them; a user's files at its
    /// top, or another run's folder in it, are refused unless `force` (as `hstlc study
    /// --force`).
    #[new]
    #[pyo3(signature = (out, paths, force=false))]
    fn new(out: PathBuf, paths: Vec<PathBuf>, force: bool) -> PyResult<_StudyOut> {
        let spec_dirs = facade::spec_dirs(&out, &paths);
        let dirs = StudyDir::take(&out, &spec_dirs, force, Writer::PYTHON).map_err(outdir_error)?;
        Ok(_StudyOut { paths, spec_dirs, dirs: Some(dirs) })
    }

    /// Writes every spec's folder, then `curves.svg` and `curves.csv` beside them. `runs[i]`
    /// holds spec `i`'s dicts from `_study_seeds`; its median seed is trained again for its
    /// policy and pictures (same seed, same bits); `optima[i]` is spec `i`'s W*, if known,
    /// for `summary.csv`. The paths written.
    #[pyo3(signature = (specs, world, runs, episodes=None, optima=None))]
    fn write(
        &mut self,
        py: Python<'_>,
        specs: Vec<Bound<'_, Spec>>,
        world: &Bound<'_, World>,
        runs: Vec<Vec<Bound<'_, PyAny>>>,
        episodes: Option<usize>,
        optima: Option<Vec<Option<f64>>>,
    ) -> PyResult<Vec<PathBuf>> {
        let Some((study_dir, dirs)) = self.dirs.take() else {
            return Err(value_error(
                "this study's folder is written already",
                Some("make a new one for another study".into()),
            ));
        };
        if specs.len() != dirs.len() || runs.len() != dirs.len() {
            return Err(value_error(
                format!(
                    "`specs` and `runs` must hold one entry per folder: {} folders, {} specs, {} lists of runs",
                    dirs.len(),
                    specs.len(),
                    runs.len()
                ),
                None,
            ));
        }
        let labels = facade::labels(&self.paths);
        let world = world.get();
        let mut written = Vec::new();
        let mut curves = Vec::new();
        let mut summary = String::from(facade::SUMMARY_HEADER);
        for (i, (((spec, runs), dir), label)) in
            specs.iter().zip(&runs).zip(dirs).zip(&labels).enumerate()
        {
            let spec = spec.get();
            let (task, checked) = task_of(py, spec, world, episodes, None)?;
            let runs = runs.iter().map(run_of).collect::<PyResult<Vec<_>>>()?;
            let w_star = optima.as_ref().and_then(|o| o.get(i).copied().flatten());
            summary.push_str(&facade::summary_line(label, &runs, w_star));
            let files = py
                .detach(|| {
                    let median = facade::median(&runs);
                    let seed = runs.get(median.index).map_or(0, |r| r.seed);
                    let chosen = facade::median_policy(
                        &task,
                        &world.world,
                        seed,
                        &spec.source,
                        &spec.filename,
                        None,
                    )?;
                    let studied =
                        StudiedSpec { spec: &task, checked: &checked, file: &spec.filename, label };
                    facade::spec_files(&studied, &world.world, &runs, &median, &chosen)
                })
                .map_err(|p| problem_error(&p))?;
            written.push(dir.path().to_path_buf());
            py.detach(|| dir.write(&files.0)).map_err(outdir_error)?;
            curves.push(CurveSet {
                label: label.clone(),
                kind: task.learn.reward,
                runs: runs.into_iter().map(|r| (r.seed, r.curve)).collect(),
            });
        }
        let seeds = curves.first().map_or(0, |c| c.runs.len());
        let mut files = facade::curves_files(&curves, seeds).map_err(|p| problem_error(&p))?;
        files.push(hstl::artifacts::OutFile::text("summary.csv", summary));
        written.extend(study_dir.write(&files, &self.spec_dirs).map_err(outdir_error)?);
        Ok(written)
    }
}

fn outdir_error(e: hstl_outdir::Error) -> PyErr {
    match e {
        hstl_outdir::Error::Write { path, source } => write_error(&path, &source),
        hstl_outdir::Error::Refused(p) => problem_error(&p),
    }
}

/// Trains `spec` in `world` from `seed` in chunks of `chunk` episodes, with `learn`'s
/// values (see `hstl::train::LEARN_KEYS`) set over the spec's; after each chunk it calls
/// `report(episodes, reward, window_rate, robustness)` with the GIL (the last two None for
/// a task without regions), and stops when `report` returns True. Returns the episodes
/// trained.
#[pyfunction]
#[pyo3(signature = (spec, world, seed, chunk, report, learn=None))]
pub fn _train_chunks(
    py: Python<'_>,
    spec: &Bound<'_, Spec>,
    world: &Bound<'_, World>,
    seed: u64,
    chunk: usize,
    report: Py<PyAny>,
    learn: Option<&Bound<'_, PyDict>>,
) -> PyResult<usize> {
    if chunk == 0 {
        return Err(value_error("`chunk` must be at least 1", None));
    }
    let (spec, world) = (spec.get(), world.get());
    let (task, _) = task_of(py, spec, world, None, learn)?;
    let mut failure = None;
    let trained = py.detach(|| {
        hstl::train::train_in_chunks(&task, &world.world, seed, chunk, |at| {
            let called = Python::attach(|py| -> PyResult<bool> {
                py.check_signals()?;
                let (rate, robustness) = at.window.map(|w| (w.rate, w.robustness)).unzip();
                report.call1(py, (at.episodes, at.reward, rate, robustness))?.is_truthy(py)
            });
            match called {
                Ok(false) => ControlFlow::Continue(()),
                Ok(true) => ControlFlow::Break(()),
                Err(e) => {
                    failure = Some(e);
                    ControlFlow::Break(())
                }
            }
        })
    });
    if let Some(e) = failure {
        return Err(e);
    }
    let trained = trained
        .map_err(|e| problem_error(&hstl::train::cannot_train(&spec.filename, &task.name, &e)))?;
    Ok(trained.curve.len())
}
