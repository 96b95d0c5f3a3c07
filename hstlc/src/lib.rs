//! The library half of `hstlc`: the language server behind `hstlc lsp`, the CSV trace
//! reader of `hstlc monitor`, and what both share with the commands (bounded file reads,
//! worlds by name or file), a library so that the fuzz targets (`fuzz/` at the repository
//! root) and their smoke test drive the same code as the binary. The other commands live
//! in the binary.

pub mod cli_error;
pub mod input;
pub mod lsp;
pub mod trace_csv;
pub mod world_arg;
