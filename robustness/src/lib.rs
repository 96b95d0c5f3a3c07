//! Signal Temporal Logic robustness on finite, discrete-time traces.
//!
//! This crate is the monitoring half of the hstl runtime. It knows nothing of the hstl
//! language: callers build a [`Formula`] directly, or have the `hstl` facade lower a
//! checked spec into one. Semantics follow the hstl language reference ("Meaning"):
//! windows are clipped at the end of the trace, an empty `always` window is `+inf`, an
//! empty `eventually` or `until` window is `-inf`.
//!
//! - [`reference`] follows the semantics table literally; it is the test oracle.

pub mod formula;
pub mod reference;
pub mod segment;
pub mod trace;

pub use formula::{Bound, CmpOp, Expr, Formula, Interval};
pub use trace::{Trace, TraceError};
