//! The `hstl!` macro: hstl task specs written inline (or included from a `.hstl` file)
//! and compiled to Rust.
//!
//! ```ignore
//! hstl::hstl! {
//!     spec Reach {
//!         state { x: int in 0..=9 }
//!         let Goal = x > 7;
//!         task eventually[0..20] Goal;
//!     }
//! }
//! let rho = reach::task::robustness(&[reach::State { x: 8 }]);
//! ```
//!
//! Each spec becomes a module named after it in snake case, holding:
//! - `State`: one field per state variable (`int` is `i64`, `float` is `f64`);
//! - `Primitive` and `Options`: the primitive options and the options set, with `ALL`,
//!   `name()`, `index()` and (for `Options`) `sequence()`;
//! - `task` and `lets::<name>`: monitors with `formula()`, `signal(&[State])` (and
//!   `signal_with`, which reuses the caller's kernel buffers), `robustness(&[State])`, an
//!   `Online` monitor, and `at(&State)` for state formulas;
//! - a unit struct named after the spec implementing `hstl::runtime::Spec`.
//!
//! The offline monitors compute each state subformula as one expression per step over
//! `&[State]`, and hand the temporal operators to the kernels the runtime's offline
//! evaluator runs (`hstl::robustness::kernels`: van Herk windows, block until, cache-sized
//! pieces), so they give its values bit for bit and are at least as fast.
//!
//! Errors are reported at the offending tokens (for an included file, at the `include`
//! with `path:line:col` in the message). Warnings become uses of a deprecated item, so
//! rustc prints them as `use of deprecated constant` warnings at the offending tokens
//! (`#![deny(warnings)]` turns them into errors). Users call it as `hstl::hstl!`, which
//! passes `$crate` in: generated code then reaches the runtime through the facade under
//! whatever name the dependency has. Called directly, it names `::hstl`.

mod expand;

/// Compiles hstl specs (inline tokens, or `include "path"` relative to the crate root)
/// into a module per spec. See the crate documentation for what each module holds.
#[proc_macro]
pub fn hstl(input: proc_macro::TokenStream) -> proc_macro::TokenStream {
    expand::expand(input.into()).into()
}
