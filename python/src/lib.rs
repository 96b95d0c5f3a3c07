//! `hstl._hstl`: the Python package's native module, a thin PyO3 shell over the `hstl`
//! facade (`hstl::load`, `hstl::monitor`, `hstl::world`, `hstl::train`,
//! `hstl::evaluate`, `hstl::reward`, `hstl::study`), as the `hstl!` macro is over hstl-lang.
//!
//! Everything that computes lives in the facade and is tested there. This crate converts
//! Python values into borrowed samples (contiguous float64 arrays are read in place; other
//! numbers are converted once by numpy), releases the GIL while Rust computes, and turns
//! the facade's errors into Python exceptions with the command line's words.

mod check;
mod cli;
mod continuous;
mod dense;
mod diagnostic;
mod errors;
mod files;
mod gym;
mod interrupt;
mod online;
mod policy;
mod reward;
mod spec;
mod study;
mod trace;
mod train;
mod vector_reward;
mod world;

use pyo3::prelude::*;

/// Exact Signal Temporal Logic monitors for hstl task specs, on numpy arrays.
#[pymodule]
fn _hstl(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<spec::Spec>()?;
    m.add_class::<diagnostic::Diagnostic>()?;
    m.add_class::<online::OnlineMonitor>()?;
    m.add_class::<world::World>()?;
    m.add_class::<world::Generator>()?;
    m.add_class::<continuous::ContinuousWorld>()?;
    m.add_class::<policy::Policy>()?;
    m.add_class::<reward::EpisodeMonitor>()?;
    m.add_class::<vector_reward::EpisodeBatch>()?;
    m.add_function(wrap_pyfunction!(check::check, m)?)?;
    m.add_function(wrap_pyfunction!(check::explain, m)?)?;
    m.add_function(wrap_pyfunction!(cli::cli, m)?)?;
    m.add_function(wrap_pyfunction!(continuous::_mountain_car_patrol, m)?)?;
    m.add_function(wrap_pyfunction!(continuous::_resolve_any_world, m)?)?;
    m.add_function(wrap_pyfunction!(spec::formula, m)?)?;
    m.add_function(wrap_pyfunction!(train::_train_world, m)?)?;
    m.add_function(wrap_pyfunction!(train::_train_env, m)?)?;
    m.add_function(wrap_pyfunction!(train::_train_continuous, m)?)?;
    m.add_function(wrap_pyfunction!(train::_train_box, m)?)?;
    m.add_class::<study::_StudyOut>()?;
    m.add_function(wrap_pyfunction!(study::_study_task, m)?)?;
    m.add_function(wrap_pyfunction!(study::_study_seeds, m)?)?;
    m.add_function(wrap_pyfunction!(study::_study_optimum, m)?)?;
    m.add_function(wrap_pyfunction!(study::_study_summary, m)?)?;
    m.add_function(wrap_pyfunction!(study::_train_chunks, m)?)?;
    m.add("LEARN_KEYS", hstl::train::LEARN_KEYS.to_vec())?;
    m.add("BUILTIN_WORLDS", hstl::world::AnyWorld::builtin_names())?;
    m.add("MAX_EPISODES", hstl::lang::budget::MAX_EPISODES)?;
    m.add("EVAL_SEED", hstl::train::EVAL_SEED)?;
    m.add("MAX_ONLINE_VALUES", hstl::robustness::MAX_ONLINE_VALUES)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
