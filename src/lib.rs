//! hstl: Signal Temporal Logic task specs, and hierarchical reinforcement learning from them.
//!
//! This is the package users depend on. It re-exports the pieces:
//! - [`lang`]: the language front end (parse, check, diagnostics, checked specs);
//! - [`robustness`]: exact STL robustness (reference, offline, online, segment rewards);
//! - [`runtime`]: environments, the hierarchical learner, policies and evaluation;
//!
//! and [`lower`] turns a checked spec into the runtime's data.

pub use hstl_lang as lang;
pub use hstl_robustness as robustness;
pub use hstl_runtime as runtime;
