//! One spec from source text: checked, and picked by name from the specs of its file.
//!
//! This is what the command line (`hstlc monitor`, `train`, `study`) and the Python package
//! (`hstl.Spec.load`, `hstl.Spec.parse`) share, so both refuse the same files with the same
//! words. Reading the file is the caller's part (nothing here touches the file system);
//! [`read_error`] words a failed read the same way for both.

use std::fmt;

use hstl_lang::{CheckedSpec, Diagnostic};

/// A spec that checked without errors.
#[derive(Clone, Debug)]
pub struct Loaded {
    /// The checked spec.
    pub spec: CheckedSpec,
    /// The file's diagnostics: warnings only, in source order.
    pub diagnostics: Vec<Diagnostic>,
}

/// Why no spec came out of a source text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LoadError {
    /// The text has errors: all its diagnostics (warnings too), in source order.
    Invalid(Vec<Diagnostic>),
    /// The text holds no spec.
    NoSpec,
    /// The text holds several specs and none was asked for.
    Several {
        /// The specs' names, in source order.
        names: Vec<String>,
    },
    /// No spec has the name asked for.
    Unknown {
        /// The name asked for.
        wanted: String,
        /// The specs' names, in source order.
        names: Vec<String>,
    },
}

impl LoadError {
    /// How to fix it; `pick` is how the caller's users name a spec, such as `--spec NAME`.
    pub fn help(&self, pick: &str) -> Option<String> {
        match self {
            LoadError::Invalid(_) => None,
            LoadError::NoSpec => Some("write `spec Name { ... }` in it".to_string()),
            LoadError::Several { names } => {
                Some(format!("pick one with {pick}: {}", quote_list(names)))
            }
            LoadError::Unknown { names, .. } => {
                Some(format!("the file holds {}", quote_list(names)))
            }
        }
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LoadError::Invalid(diagnostics) => {
                let errors = diagnostics.iter().filter(|d| d.is_error()).count();
                let s = if errors == 1 { "" } else { "s" };
                write!(f, "the file has {errors} error{s}")
            }
            LoadError::NoSpec => f.write_str("the file holds no spec"),
            LoadError::Several { names } => write!(f, "the file holds {} specs", names.len()),
            LoadError::Unknown { wanted, .. } => write!(f, "no spec named `{wanted}`"),
        }
    }
}

impl std::error::Error for LoadError {}

/// Checks `source` and picks the spec named `wanted`, or the only one.
pub fn load(source: &str, wanted: Option<&str>) -> Result<Loaded, LoadError> {
    pick(hstl_lang::check(source), wanted)
}

/// [`load`], with the specs that have options also checked against `world` (`label`
/// names it in messages, see [`crate::world::check`]): what the commands that train use.
pub fn load_in_world(
    source: &str,
    wanted: Option<&str>,
    world: &crate::world::GridWorld,
    label: &str,
) -> Result<Loaded, LoadError> {
    pick(crate::world::check(source, world, label), wanted)
}

/// [`load_in_world`] in a world of any kind (a grid, a plane, `mountain-car`): every spec
/// is checked against it, as `hstlc train --world` checks them.
pub fn load_in_any_world(
    source: &str,
    wanted: Option<&str>,
    world: &crate::world::AnyWorld,
    label: &str,
) -> Result<Loaded, LoadError> {
    let facts = crate::world::any_facts(world, label);
    let parsed = hstl_lang::parse(source);
    pick(hstl_lang::check_parsed_with_worlds(source, parsed, &|_| facts.spec_world()), wanted)
}

/// The spec named `wanted` (or the only one) of a checked text without errors.
pub fn pick(mut checked: hstl_lang::Checked, wanted: Option<&str>) -> Result<Loaded, LoadError> {
    if checked.has_errors() {
        return Err(LoadError::Invalid(checked.diagnostics));
    }
    let names = || checked.specs.iter().map(|s| s.name.clone()).collect::<Vec<_>>();
    let index = match (wanted, checked.specs.len()) {
        (None, 1) => 0,
        (None, 0) => return Err(LoadError::NoSpec),
        (None, _) => return Err(LoadError::Several { names: names() }),
        (Some(w), _) => checked
            .specs
            .iter()
            .position(|s| s.name == w)
            .ok_or_else(|| LoadError::Unknown { wanted: w.to_string(), names: names() })?,
    };
    let spec = checked.specs.swap_remove(index);
    Ok(Loaded { spec, diagnostics: checked.diagnostics })
}

/// The spec of one formula ([`formula`]): its source and the checked spec.
#[derive(Clone, Debug)]
pub struct FormulaSpec {
    /// The spec text written for it: `spec Formula { state { ... } task FORMULA; }`.
    pub source: String,
    /// The checked spec, whose task is the formula.
    pub loaded: Loaded,
}

/// The name of the spec [`formula`] writes.
pub const FORMULA_SPEC: &str = "Formula";

/// A spec whose task is the one formula `text` (`always[0..=10] x > 0.5`), its state
/// variables every name the formula reads, as `float`s in the order they first appear.
/// Diagnostics are positioned in `text`. A text that is not one formula (a `;`, `{` or
/// `}`) or reads no state variable is refused with a diagnostic at its start.
pub fn formula(text: &str) -> Result<FormulaSpec, LoadError> {
    let refuse = |message: &str, help: &str| {
        let mut d = Diagnostic::new("HSTL001", 0..0, message);
        d.help = Some(help.to_string());
        LoadError::Invalid(vec![d])
    };
    if let Some(c) = text.chars().find(|c| matches!(c, ';' | '{' | '}')) {
        return Err(refuse(
            &format!("a formula has no `{c}`: write one formula, such as `always[0..=10] x > 0.5`"),
            "write a whole spec with `Spec.parse`",
        ));
    }
    // The text on its own line, so that a `//` comment in it ends there.
    let write = |vars: &[String]| {
        let state = if vars.is_empty() {
            "_: float".to_string()
        } else {
            vars.iter().map(|v| format!("{v}: float")).collect::<Vec<_>>().join(", ")
        };
        let prefix = format!("spec {FORMULA_SPEC} {{ state {{ {state} }} task\n");
        let source = format!("{prefix}{text}\n;\n}}\n");
        (prefix.len(), source)
    };
    // The names the formula reads are those the checker does not know without them.
    let (start, probe) = write(&[]);
    let mut vars: Vec<String> = Vec::new();
    for d in hstl_lang::check(&probe).diagnostics {
        let inside = d.range.start >= start && d.range.end <= start + text.len();
        if d.code == "HSTL002" && inside {
            let name = probe[d.range.clone()].to_string();
            if !vars.contains(&name) {
                vars.push(name);
            }
        }
    }
    let (start, source) = write(&vars);
    let shift = |d: Diagnostic| {
        let at = |i: usize| i.saturating_sub(start).min(text.len());
        Diagnostic {
            range: at(d.range.start)..at(d.range.end),
            labels: d
                .labels
                .into_iter()
                .map(|l| hstl_lang::diagnostic::Label {
                    range: at(l.range.start)..at(l.range.end),
                    ..l
                })
                .collect(),
            ..d
        }
    };
    let loaded = match load(&source, Some(FORMULA_SPEC)) {
        Ok(loaded) => loaded,
        Err(LoadError::Invalid(ds)) => {
            return Err(LoadError::Invalid(ds.into_iter().map(shift).collect()));
        }
        Err(e) => return Err(e),
    };
    if vars.is_empty() {
        return Err(refuse(
            "the formula reads no state variable",
            "name one, such as `x > 0.5`, or write a whole spec with `Spec.parse`",
        ));
    }
    let loaded =
        Loaded { diagnostics: loaded.diagnostics.into_iter().map(shift).collect(), ..loaded };
    Ok(FormulaSpec { source, loaded })
}

/// Every diagnostic of `source` (errors, warnings and notes, in source order), as `hstlc
/// check` reports them; the specs with options are also checked against `world` (its label
/// naming it in messages) when one is given.
pub fn check(source: &str, world: Option<(&crate::world::GridWorld, &str)>) -> Vec<Diagnostic> {
    match world {
        Some((world, label)) => crate::world::check(source, world, label).diagnostics,
        None => hstl_lang::check(source).diagnostics,
    }
}

/// The long explanation of a diagnostic code (case-insensitive), as `hstlc explain`
/// prints it: `CODE (name): summary`, a blank line and the explanation.
pub fn explain(code: &str) -> Result<String, UnknownCode> {
    let wanted = code.trim().to_ascii_uppercase();
    let info = hstl_lang::codes::lookup(&wanted).ok_or_else(|| UnknownCode(code.to_string()))?;
    Ok(format!(
        "{} ({}): {}\n\n{}",
        info.code,
        info.name,
        info.summary,
        info.explanation.trim_end()
    ))
}

/// A code that names no diagnostic.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownCode(pub String);

impl UnknownCode {
    /// How to fix it: the known codes.
    pub fn help(&self) -> String {
        let known: Vec<&str> = hstl_lang::codes::CODES.iter().map(|c| c.code).collect();
        format!("known codes: {}", known.join(", "))
    }
}

impl fmt::Display for UnknownCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown diagnostic code `{}`", self.0)
    }
}

impl std::error::Error for UnknownCode {}

pub use hstl_files::read::open_regular;
pub use hstl_files::words::{escape_controls, io_reason, path_words, read_error};

fn quote_list(names: &[String]) -> String {
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}
