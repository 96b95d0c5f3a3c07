//! The hstl language: grammar, syntax tree, name resolution, checks and the checked spec.
//!
//! Parsing and checking never fail: they return what they could build together with a
//! list of plain-data [`Diagnostic`]s. This crate knows nothing of miette, LSP or proc macros.

pub mod codes;
pub mod diagnostic;
pub mod parser;
pub mod syntax;

pub use diagnostic::{Diagnostic, Label, Severity};
pub use parser::{Parsed, parse};
pub mod check;
pub mod checked;

pub use check::{Checked, check};
pub use checked::*;
pub mod position;
pub mod render;

pub use position::{LineIndex, Position};
pub use render::render_plain;
