//! The hstl language: grammar, syntax tree, name resolution, checks and the checked spec.
//!
//! # Pipeline
//! 1. [`parse`] (module [`parser`]): a small lexer records every comment and token; a
//!    balanced-delimiter scanner splits the file into spec headers and items (an item ends
//!    at a `;` or a closing `}` at depth 0, or where the next item keyword starts); pest
//!    (`grammar.pest`) parses each piece on its own. A piece that does not parse gives one
//!    `HSTL001` at the exact position with what was expected in words, and is skipped, so
//!    one broken item never hides errors in the others. The result is a [`syntax::File`]
//!    with a byte range on every node and name, doc comments on the nodes they document,
//!    and every comment's range (for a formatter).
//! 2. [`check()`] (module [`check`](mod@check)): resolves names (state variables and `let`s share one
//!    namespace, options have their own), detects `let` cycles, classifies lets (state or
//!    temporal), checks options, the options set and learning parameters, and runs the
//!    finite-domain checks by enumerating the declared `int` domain. It builds one [`CheckedSpec`] per spec: names resolved to indices,
//!    defaults filled in, the options set expanded.
//! 3. Diagnostics are plain data ([`Diagnostic`]); [`render_plain`] renders them like
//!    rustc, [`LineIndex`] converts byte offsets to lines and columns (characters and
//!    UTF-16), and [`codes`] explains every code.
//!
//! # Invariants
//! - [`parse`] and [`check()`] never fail and never panic, whatever the input: problems
//!   are diagnostics. Every diagnostic range lies on char boundaries inside the source.
//! - Recursion is bounded: brackets (and block comments) nested more than
//!   [`parser::MAX_NESTING`] deep and formulas taller than [`parser::MAX_HEIGHT`] are
//!   reported before pest or any recursive pass sees them; operator chains and prefix
//!   operators are flat repetitions in the grammar; chains of lets are walked
//!   iteratively. pest is built without `std`, so this bound, not pest's stack probe, is
//!   what keeps deep input from exhausting the stack.
//! - The finite-domain checks enumerate at most [`check::MAX_DOMAIN_STATES`] states and
//!   [`check::MAX_DOMAIN_WORK`] formula evaluations; beyond that they are skipped with the
//!   warning `HSTL022`.
//! - Diagnostics are sorted by position, deduplicated and capped at
//!   [`check::MAX_DIAGNOSTICS`] per file; one `HSTL024` says how many more there were.
//! - A [`CheckedSpec`] is always returned for a spec whose header parsed; where a part did
//!   not check it holds [`CFormulaKind::Invalid`] / [`CExprKind::Invalid`], and an error
//!   was reported. The finite-domain checks run only on specs without errors.
//! - Messages have no trailing period; codes are stable (see [`codes::CODES`]).
//!
//! # Regions
//! The warnings `HSTL102`/`HSTL103` concern *regions*: a state formula that an option
//! reaches (its `reach`, or the `let` its name names), or the `Rj` of a task of the form
//! `always[0..] (eventually[0..N1] R1 && ... )`. They are reported at the `let`'s name
//! (or at the formula when it is written inline).
//!
//! This crate knows nothing of miette, LSP, syn or proc macros: each edge converts.

// pest is built without `std`: its per-call native stack probe cost a fifth of the parse
// time, and the parser bounds recursion itself (bracket nesting, formula height). The
// generated parser then names `crate::alloc`.
extern crate alloc;

pub mod budget;
pub mod check;
pub mod checked;
pub mod codes;
pub mod diagnostic;
pub mod format;
pub mod incremental;
pub mod limits;
pub mod lints;
pub mod parser;
pub mod position;
pub mod preset;
pub mod render;
pub mod severity;
pub mod suggest;
pub mod syntax;
pub mod wording;
pub mod world;

pub use check::{
    Checked, check, check_in_world, check_parsed, check_parsed_in_world, check_parsed_with_worlds,
};

/// The largest spec text the tools read, in bytes (64 MiB): `hstlc` and the macro's
/// `include "path"` refuse a larger file before reading all of it.
pub const MAX_SOURCE_BYTES: u64 = 64 << 20;
pub use checked::*;
pub use diagnostic::{Diagnostic, Label, Severity};
pub use format::format;
pub use parser::{KEYWORDS, Parsed, parse};
pub use position::{LineIndex, Location, Position};
pub use render::{FileDiagnostics, render_concise, render_plain};
pub use world::{BoxFacts, SpecWorld, WorldFacts, WorldProblem, world_item};
