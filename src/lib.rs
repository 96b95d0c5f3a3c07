//! hstl: Signal Temporal Logic task specs, and hierarchical reinforcement learning from them.
//!
//! This is the package users depend on. It re-exports the pieces:
//! - [`lang`]: the language front end (parse, check, diagnostics, checked specs);
//! - [`robustness`]: exact STL robustness (reference, offline, online, segment rewards);
//! - [`runtime`]: environments, the hierarchical learner, policies and evaluation;
//! - [`hstl!`]: a spec written inline in Rust, checked when the crate compiles and turned
//!   into typed Rust;
//!
//! and [`lower`] turns a checked spec into the runtime's data at run time (the path the
//! command line takes).
//!
//! ```
//! let src = "spec S { state { x: int in 0..=9 } let Goal = x > 6; task eventually[0..5] Goal;
//!            option Goal; options { Goal } }";
//! let checked = hstl::lang::check(src);
//! assert!(!checked.has_errors());
//! let spec = hstl::lower::task_spec(&checked.specs[0], src).unwrap();
//! assert_eq!(spec.primitives[0].name, "Goal");
//! ```

// The macro's generated code names `::hstl`, which must also resolve inside this package's
// own tests and examples.
extern crate self as hstl;

pub mod lower;

pub use hstl_lang as lang;
pub use hstl_macros::hstl;
pub use hstl_robustness as robustness;
pub use hstl_runtime as runtime;
