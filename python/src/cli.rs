//! `hstl._hstl.cli`: the `hstlc` command line, which the wheel installs as the `hstlc`
//! command (`hstl._cli:main`).

use std::ffi::OsString;

use pyo3::prelude::*;

/// Runs the `hstlc` command line with `argv` (the program's name first, as `sys.argv`)
/// and returns its exit status: what the native `hstlc` binary prints and returns, since
/// both are `hstlc::run`. It writes to this process's standard output and error (file
/// descriptors 1 and 2, not `sys.stdout`) and reads its standard input. The GIL is
/// released while it runs.
#[pyfunction]
pub fn cli(py: Python<'_>, argv: Vec<OsString>) -> u8 {
    py.detach(|| hstlc::run(argv))
}
