//! `hstlc explain`: the long explanation of a diagnostic code.

use clap::Args;

use crate::cli_error::CliError;
use crate::output::outln;
use crate::{CmdResult, Status};

/// Arguments of `hstlc explain`.
#[derive(Args, Debug)]
pub struct ExplainArgs {
    /// A diagnostic code, such as HSTL003 (case-insensitive).
    #[arg(value_name = "CODE")]
    pub code: String,
}

/// Runs `hstlc explain`.
pub fn run(args: &ExplainArgs) -> CmdResult {
    let text = hstl::load::explain(&args.code)
        .map_err(|e| CliError::new(e.to_string(), Some(e.help())))?;
    outln!("{text}")?;
    Ok(Status::Clean)
}
