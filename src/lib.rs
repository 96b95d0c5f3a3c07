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
//! command line takes); [`world`] reads grid worlds and checks specs against them,
//! [`train`] trains a spec as `hstlc train` does, [`evaluate`] replays a `policy.json`
//! as `hstlc eval` does, and [`reward`] scores an episode state by state (the Python
//! package's `STLReward`); [`study`] trains specs over many seeds and compares them (what
//! `hstlc study` and `hstl.study` report), and [`artifacts`] makes the files of a trained
//! agent's output folder as plain data. Every front end words what it refuses with a
//! [`Problem`].
//!
//! ```
//! let src = "spec S { state { x: int in 0..=9 } let Goal = x > 6; task eventually[0..5] Goal;
//!            option Goal; options { Goal } }";
//! let checked = hstl::lang::check(src);
//! assert!(!checked.has_errors());
//! let spec = hstl::lower::task_spec(&checked.specs[0], src).unwrap();
//! assert_eq!(spec.primitives[0].name, "Goal");
//! ```

pub mod artifacts;
pub mod continuous;
pub mod cost;
pub mod evaluate;
pub mod gym;
pub mod load;
pub mod lower;
pub mod monitor;
pub mod outfile;
pub mod outside;
pub mod reference;
pub mod replayed;
pub mod reward;
pub mod seeds;
pub mod study;
pub mod train;
pub mod world;

pub use hstl_files::Problem;

pub use hstl_lang as lang;
pub use hstl_robustness as robustness;
pub use hstl_runtime as runtime;

/// Compiles hstl specs, written inline or included from a file, into Rust: a module per
/// spec with its `State` type, option enums, monitors for the task and every `let`, and an
/// implementation of [`runtime::Spec`].
///
/// ```
/// hstl::hstl! {
///     /// Reach the goal within 20 steps.
///     spec Reach {
///         state { x: int in 0..=9 }
///         let Goal = x > 7;
///         task eventually[0..20] Goal;
///         option Goal;
///     }
/// }
/// let rho = reach::task::robustness(&[reach::State { x: 3 }, reach::State { x: 9 }]);
/// assert_eq!(rho, 2.0);
/// ```
///
/// `hstl! { include "specs/task.hstl" }` reads the file relative to the crate's
/// `CARGO_MANIFEST_DIR` at compile time and rebuilds when it changes. A spec with errors is
/// a compile error at the offending tokens; warnings show as deprecation warnings there.
/// The generated code names this crate through `$crate`, so it works under any name the
/// dependency is given. See `hstl_macros` for the generated items in detail.
#[macro_export]
macro_rules! hstl {
    ($($body:tt)*) => {
        $crate::__private::hstl! { $crate; $($body)* }
    };
}

#[doc(hidden)]
pub mod __private {
    pub use hstl_macros::hstl;
}
