//! The library half of `hstlc`: the language server behind `hstlc lsp`, a library so
//! that the fuzz targets (`fuzz/` at the repository root) drive the same code as the
//! binary. The other commands live in the binary.

pub mod lsp;
