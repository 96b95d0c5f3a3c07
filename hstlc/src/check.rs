//! `hstlc check`: diagnostics of spec files in four formats.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use hstl::lang::Severity;

use crate::cli_error::CliError;
use crate::output::out;
pub use crate::render::Checked;
use crate::world_arg::{LoadedWorld, check_source, override_note};
use crate::{CmdResult, Status, input, render};

/// Arguments of `hstlc check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Spec files to check; `-` reads standard input.
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Full)]
    pub format: Format,
    /// The name to report for standard input.
    #[arg(long, value_name = "NAME", default_value = "<stdin>")]
    pub stdin_filename: String,
    #[arg(long, value_name = "NAME|FILE.toml", long_help = CHECK_WORLD_HELP)]
    /// The grid world the specs with options are checked against, instead of the ones they
    /// name.
    pub world: Option<String>,
}

/// The `--world` help text of `check`.
const CHECK_WORLD_HELP: &str = "The grid world to check the specs with options against, \
instead of the world each names with `world \"...\";`: a built-in name (`paper`, the paper's \
15 x 15 open grid with slip 0.3, or `four-rooms`) or a world file (`FILE.toml`, see README \
\"Worlds\"). Without it, a spec is checked against the world it names, or alone when it names \
none";

/// How `check` prints diagnostics.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Rendered with the source and carets (colour only on a terminal).
    Full,
    /// One line each: `path:line:col: CODE message`.
    Concise,
    /// One JSON array of objects.
    Json,
    /// SARIF 2.1.0.
    Sarif,
}

/// Runs `hstlc check`.
pub fn run(args: &CheckArgs) -> CmdResult {
    // Read every input first: an unreadable file stops the run before anything prints.
    let imposed = args.world.as_deref().map(LoadedWorld::load).transpose()?;
    let inputs = args
        .files
        .iter()
        .map(|path| read_input(path, &args.stdin_filename).map(|(n, s)| (path, n, s)))
        .collect::<Result<Vec<_>, _>>()?;
    let mut notes = String::new();
    let checked: Vec<Checked> = inputs
        .into_iter()
        .map(|(path, name, source)| {
            let path = (path != Path::new("-")).then_some(path.as_path());
            let (result, worlds) = check_source(&source, path, imposed.as_ref());
            for spec in &result.specs {
                if let (Some(named), Some(imposed)) = (&spec.world, &imposed) {
                    notes.extend(override_note(&name, &spec.name, &named.name, &worlds, imposed));
                }
                if let Some(e) = &spec.preset_expansion {
                    notes.push_str(&preset_note(&name, &spec.name, e));
                }
                notes.push_str(&continuous_note(&name, spec));
            }
            Checked { name, source, diagnostics: result.diagnostics }
        })
        .collect();
    let out = match args.format {
        Format::Full => render::full(&checked, std::io::stdout().is_terminal()),
        Format::Concise => render::concise(&checked),
        Format::Json => render::json(&checked),
        Format::Sarif => render::sarif(&checked),
    };
    out!("{out}")?;
    // The machine formats stay one document each.
    if matches!(args.format, Format::Full | Format::Concise) {
        out!("{notes}")?;
    }
    let errors = checked.iter().flat_map(|c| &c.diagnostics).any(|d| d.severity == Severity::Error);
    Ok(if errors { Status::Errors } else { Status::Clean })
}

/// The note that says what `preset: auto` expanded to in spec `spec` of file `file`.
pub fn preset_note(file: &str, spec: &str, expansion: &str) -> String {
    format!(
        "note: {file}: in spec `{spec}`, `preset: auto` stands for\n    {}\n",
        expansion.replace('\n', "\n    ")
    )
}

/// The note that the finite-domain checks, which enumerate an `int` domain, skip a spec
/// with options over a `float` state (empty for any other spec), as `HSTL022` says for a
/// domain too large to enumerate.
pub fn continuous_note(file: &str, spec: &hstl::lang::CheckedSpec) -> String {
    let Some(v) = spec.state_vars.iter().find(|v| v.ty == hstl::lang::syntax::VarType::Float)
    else {
        return String::new();
    };
    if spec.primitives.is_empty() {
        return String::new();
    }
    format!(
        "note: {file}: in spec `{}`, `{}` is a `float`: the checks that enumerate the domain \
         (empty or full regions, states where no option can start, gaps in sequences: \
         HSTL018, HSTL020, HSTL102, HSTL103) do not run on a continuous state\n",
        spec.name, v.name
    )
}

/// Reads a spec file, or standard input for `-`, and names it for reports (see
/// [`input::read_text`]: at most [`hstl::lang::MAX_SOURCE_BYTES`], UTF-8, a byte order
/// mark dropped).
pub fn read_input(path: &Path, stdin_name: &str) -> Result<(String, String), CliError> {
    let input = input::read_text(path, stdin_name, hstl::lang::MAX_SOURCE_BYTES, "spec")?;
    Ok((input.name, input.text))
}
