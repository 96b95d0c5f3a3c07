//! libFuzzer over the property in `fuzz/props/lsp_session.rs` (also replayed and mutated by
//! `hstlc/tests/fuzz_smoke.rs` in every test run).
#![no_main]

#[path = "../props/lsp_session.rs"]
mod prop;

libfuzzer_sys::fuzz_target!(|data: &[u8]| prop::check(data));
