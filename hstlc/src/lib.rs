//! The library half of `hstlc`: the language server behind `hstlc lsp` and the CSV trace
//! reader of `hstlc monitor`, a library so that the fuzz targets (`fuzz/` at the
//! repository root) and their smoke test drive the same code as the binary. The other
//! commands live in the binary.

pub mod lsp;
pub mod trace_csv;
