//! `hstl._hstl`: the Python package's native module, a thin PyO3 shell over the `hstl`
//! facade (`hstl::load`, `hstl::monitor`), as the `hstl!` macro is over hstl-lang.
//!
//! Everything that computes lives in the facade and is tested there. This crate converts
//! Python values into borrowed samples (contiguous float64 arrays are read in place; other
//! numbers are converted once by numpy), releases the GIL while Rust computes, and turns
//! the facade's errors into Python exceptions with the command line's words.

mod errors;
mod online;
mod spec;
mod trace;

use pyo3::prelude::*;

/// Exact Signal Temporal Logic monitors for hstl task specs, on numpy arrays.
#[pymodule]
fn _hstl(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<spec::Spec>()?;
    m.add_class::<spec::Diagnostic>()?;
    m.add_class::<online::OnlineMonitor>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
