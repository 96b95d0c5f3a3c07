//! Signal Temporal Logic robustness on finite, discrete-time traces.
//!
//! This crate is the monitoring half of the hstl runtime. It knows nothing of the hstl
//! language: callers build a [`Formula`] directly, or have the `hstl` facade lower a
//! checked spec into one. Semantics follow the hstl language reference ("Meaning"):
//! windows are clipped at the end of the trace, an empty `always` window is `+inf`, an
//! empty `eventually` or `until` window is `-inf`. The past-time operators (`once`,
//! `historically`, `since`, weak `prev`, and `next`) follow rtamt's discrete-time
//! semantics, their windows clipped at the start of the trace.
//!
//! - [`reference`](mod@reference) follows the semantics table literally; it is the test oracle.
//! - [`offline`] computes whole signals fast, and the robustness at step 0 from the
//!   formula's horizon alone.
//! - [`online`] monitors a trace fed one state at a time.
//! - [`kernels`] are [`offline`]'s sliding-window, until and piecewise kernels over plain
//!   slices, for monitors that compute their operand signals themselves.
//! - [`segment`] scores option executions and all their suffixes for the learner.
//!
//! - [`dense`] is dense time: time-stamped, piecewise-constant signals (rtamt's
//!   dense-time STL), offline and online.
//!
//! - [`nan`] finds the comparisons that compute a NaN, so callers can refuse it.
//!
//! All evaluators give the same values; [`offline`] states the NaN policy they share.

pub mod cancel;
pub mod complete;
pub mod dense;
pub mod formula;
pub mod kernels;
pub mod last_step;
pub mod nan;
pub mod offline;
pub mod online;
mod primitives;
pub mod reference;
pub mod segment;
pub mod state;
mod stream;
pub mod trace;

pub use formula::{Bound, CmpOp, Expr, ExprId, Formula, FormulaBuilder, Interval, Node, NodeId};
pub use offline::Evaluator;
pub use online::{MAX_ONLINE_VALUES, OnlineMonitor, Verdict};
pub use state::StateEval;
pub use stream::WindowStream;
pub use trace::{Trace, TraceError};
