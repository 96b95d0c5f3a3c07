//! What the checks know of the world a spec is trained in: the facts the checker reads.
//!
//! A spec names its world with an item `world "NAME_OR_PATH";` (a built-in world's name, or
//! a world file's path relative to the spec file). The front end reads no file: the caller
//! (the CLI, the language server, Python) finds the world each spec names, or the one a
//! command line imposes, and passes it as plain data ([`SpecWorld`], [`WorldFacts`]) to
//! [`crate::check_parsed_with_worlds`]; the entry points that run the checker against a
//! world live with the checker ([`crate::check`](mod@crate::check)), so that this file, which
//! the checker reads, reads nothing of the checker. A spec checked [`SpecWorld::Alone`] gets no world facts and
//! no world diagnostics: a custom Rust or gymnasium environment is a world no check can see.
//!
//! Against a world, every check of [`crate::check()`] runs, plus these, on each spec that
//! has options (a spec without options is never trained):
//! - `HSTL030`: the state variables must be `x: int in 0..=W-1` and `y: int in 0..=H-1`;
//! - `HSTL031`: a region an option reaches has no free cell (an error; a region only the
//!   task names stays the warning `HSTL102`);
//! - `HSTL032`: an option's termination set has no free cell;
//! - `HSTL131`: no start can reach a region (walls cut it off).
//!
//! and `HSTL034` at the `world` item when the world it names cannot be had. A world never
//! hides another diagnostic: the spec's own checks report the same with or without it.
//! With a world the state fits, the finite-domain checks (`HSTL018`, `HSTL020`, `HSTL102`,
//! `HSTL103`) range over the free cells only: walls are not states.

use crate::budget::tiles::TileFit;
use crate::checked::{CheckedSpec, Domain, VarType};
use crate::diagnostic::Diagnostic;
use crate::syntax::{Item, Spec, WorldItem};

/// What the checks know of a grid world.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WorldFacts {
    /// How messages name the world, such as ``world `office` (office.toml)``.
    pub label: String,
    /// Columns; `x` runs over `0..width`.
    pub width: usize,
    /// Rows; `y` runs over `0..height`.
    pub height: usize,
    /// Per cell `y * width + x`: whether it is free (not a wall).
    pub free: Vec<bool>,
    /// Per cell `y * width + x`: whether some start can reach it.
    pub reachable: Vec<bool>,
}

/// Why the world a spec names could not be had: an unknown name, a missing or malformed
/// world file. Reported as `HSTL034` at the spec's `world` item.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WorldProblem {
    /// What is wrong (for a malformed file, its `FILE:LINE:COL` first), without a trailing
    /// period.
    pub message: String,
    /// How to fix it.
    pub help: String,
}

/// What the checks know of a continuous world (a plane, mountain-car): its state
/// variables and their ranges.
#[derive(Clone, Debug, PartialEq)]
pub struct BoxFacts {
    /// How messages name the world, such as ``world `yard` (yard.toml)``.
    pub label: String,
    /// Each state variable: its name and its range `[lo, hi]`, in the world's order.
    pub vars: Vec<(String, f64, f64)>,
    /// Its actions (headings, pushes).
    pub actions: u64,
    /// How it lays tiles along a variable whose `bins` a spec leaves out (`None`: the
    /// spec's tile box as it is).
    pub fit: Option<TileFit>,
}

/// What one spec is checked against.
#[derive(Clone, Copy, Debug)]
pub enum SpecWorld<'w> {
    /// No world: the spec is checked alone.
    Alone,
    /// A grid world whose facts are known.
    Facts(&'w WorldFacts),
    /// A continuous world whose state variables are known.
    Box(&'w BoxFacts),
    /// The world the spec names, which could not be had.
    Unavailable(&'w WorldProblem),
}

/// The spec's `world` item (the first, if it has several: the others are reported).
pub fn world_item(spec: &Spec) -> Option<&WorldItem> {
    spec.items.iter().find_map(|i| match i {
        Item::World(w) => Some(w),
        _ => None,
    })
}

/// Per state of a spec's declared domain (in the order the finite-domain checks number
/// them): whether it is a free cell, and whether a start reaches it.
pub(crate) struct DomainMask {
    pub present: Vec<bool>,
    pub reachable: Vec<bool>,
}

impl WorldFacts {
    /// The state block a spec needs for this world.
    fn declaration(&self) -> String {
        format!(
            "`x: int in 0..={}, y: int in 0..={}`",
            self.width.saturating_sub(1),
            self.height.saturating_sub(1)
        )
    }

    fn cell(&self, x: usize, y: usize) -> Option<usize> {
        (x < self.width && y < self.height)
            .then(|| y * self.width + x)
            .filter(|&c| c < self.free.len())
    }

    /// `HSTL030` for each state variable that does not fit, or the mask of the domain's
    /// states when they all fit.
    pub(crate) fn fit(
        &self,
        spec: &CheckedSpec,
        push: &mut impl FnMut(Diagnostic),
    ) -> Option<DomainMask> {
        let help = format!(
            "declare the state as {} to match {} ({} x {})",
            self.declaration(),
            self.label,
            self.width,
            self.height
        );
        let mut fits = true;
        let wanted = [("x", self.width, "wide"), ("y", self.height, "high")];
        for v in &spec.state_vars {
            let mut wrong = |message: String| {
                fits = false;
                push(
                    Diagnostic::new("HSTL030", v.name_range.start..v.range.end, message)
                        .with_help(help.clone()),
                );
            };
            let Some(&(_, n, along)) = wanted.iter().find(|w| w.0 == v.name) else {
                wrong(format!(
                    "state variable `{}` is not a variable of {}: a grid world's state is its \
                     cell `x`, `y`",
                    v.name, self.label
                ));
                continue;
            };
            let hi = n.saturating_sub(1) as i64;
            if !(v.ty == VarType::Int && v.domain == Domain::Int { lo: 0, hi }) {
                wrong(format!(
                    "state variable `{}` must be `int in 0..={hi}`: {} is {n} cells {along}",
                    v.name, self.label
                ));
            }
        }
        for (name, _, _) in wanted {
            if !spec.state_vars.iter().any(|v| v.name == name) {
                fits = false;
                push(missing_variable(spec, name, &self.label, &help));
            }
        }
        if !fits {
            return None;
        }
        // The finite-domain checks number states with the last declared variable fastest.
        let x_first = spec.state_vars.first().is_some_and(|v| v.name == "x");
        let n = self.width.checked_mul(self.height)?;
        let mut present = Vec::with_capacity(n);
        let mut reachable = Vec::with_capacity(n);
        for k in 0..n {
            let (x, y) = if x_first {
                (k / self.height, k % self.height)
            } else {
                (k % self.width, k / self.width)
            };
            let cell = self.cell(x, y);
            present.push(cell.is_some_and(|c| self.free[c]));
            reachable.push(cell.is_some_and(|c| self.reachable.get(c).copied().unwrap_or(false)));
        }
        Some(DomainMask { present, reachable })
    }
}

impl BoxFacts {
    /// The state block a spec needs for this world.
    fn declaration(&self) -> String {
        let vars: Vec<String> = self
            .vars
            .iter()
            .map(|(n, lo, hi)| format!("{n}: float in {}..={}", literal(*lo), literal(*hi)))
            .collect();
        format!("`{}`", vars.join(", "))
    }

    /// `HSTL030` for each state variable of `spec` that is not the world's, with its range.
    pub(crate) fn fit(&self, spec: &CheckedSpec, push: &mut impl FnMut(Diagnostic)) {
        let help = format!("declare the state as {} to match {}", self.declaration(), self.label);
        for v in &spec.state_vars {
            let Some((_, lo, hi)) = self.vars.iter().find(|w| w.0 == v.name) else {
                let names: Vec<&str> = self.vars.iter().map(|w| w.0.as_str()).collect();
                push(
                    Diagnostic::new(
                        "HSTL030",
                        v.name_range.start..v.range.end,
                        format!(
                            "state variable `{}` is not a variable of {}, whose state is {}",
                            v.name,
                            self.label,
                            names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
                        ),
                    )
                    .with_help(help.clone()),
                );
                continue;
            };
            let right = v.ty == VarType::Float
                && matches!(v.domain, Domain::Float { lo: a, hi: b, inclusive: true } if a == *lo && b == *hi);
            if !right {
                push(
                    Diagnostic::new(
                        "HSTL030",
                        v.name_range.start..v.range.end,
                        format!(
                            "state variable `{}` must be `float in {}..={}`: the range of {}",
                            v.name,
                            literal(*lo),
                            literal(*hi),
                            self.label
                        ),
                    )
                    .with_help(help.clone()),
                );
            }
        }
        for (name, _, _) in &self.vars {
            if !spec.state_vars.iter().any(|v| &v.name == name) {
                push(missing_variable(spec, name, &self.label, &help));
            }
        }
    }
}

/// A bound as a spec writes it, read back to the same double: plain for moderate
/// magnitudes (`0`, `14`, `-2.5`), with an exponent past them (`1e300`, `5e-324`), so that
/// no message spells out three hundred digits.
fn literal(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-5..1e16).contains(&a) { v.to_string() } else { format!("{v:e}") }
}

/// `HSTL030` for a variable `name` that the world `label` needs and the spec's state lacks,
/// at the state's variables (or the spec's name when it has none).
fn missing_variable(spec: &CheckedSpec, name: &str, label: &str, help: &str) -> Diagnostic {
    let at = spec
        .state_vars
        .first()
        .map_or(spec.name_range.clone(), |v| v.name_range.start..v.range.end);
    Diagnostic::new(
        "HSTL030",
        at,
        format!("the state has no variable `{name}`, which {label} needs"),
    )
    .with_help(help.to_string())
}
