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
    let wanted = args.code.trim().to_ascii_uppercase();
    let Some(info) = hstl::lang::codes::lookup(&wanted) else {
        let known: Vec<&str> = hstl::lang::codes::CODES.iter().map(|c| c.code).collect();
        return Err(CliError::new(
            format!("unknown diagnostic code `{}`", args.code),
            Some(format!("known codes: {}", known.join(", "))),
        ));
    };
    outln!("{} ({}): {}\n\n{}", info.code, info.name, info.summary, info.explanation.trim_end())?;
    Ok(Status::Clean)
}
