//! Name resolution and every check of LANGUAGE.md, building [`CheckedSpec`]s.
//!
//! This file holds the entry points, the per-spec state `Cx` and the walk over a spec's
//! items; each pass lives in a file of its own: `resolve` (variables, lets, formulas),
//! `options`, `learn` and `domain` (the finite-domain pass).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// A fast hasher for the names of a spec (FxHash's multiply-rotate, eight bytes at a
/// time): names come from the checked file, and nothing depends on the table's order.
#[derive(Clone, Copy, Default)]
struct NameHasher(u64);

impl Hasher for NameHasher {
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            let mut w = [0u8; 8];
            w.copy_from_slice(c);
            self.add(u64::from_le_bytes(w));
        }
        for &b in chunks.remainder() {
            self.add(u64::from(b));
        }
    }

    fn write_u8(&mut self, i: u8) {
        self.add(u64::from(i));
    }

    fn write_usize(&mut self, i: usize) {
        self.add(i as u64);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

impl NameHasher {
    fn add(&mut self, w: u64) {
        self.0 = (self.0.rotate_left(5) ^ w).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}
use std::ops::Range;

use crate::budget;
use crate::checked::*;
use crate::diagnostic::{self, Diagnostic};
use crate::parser::parse;
use crate::syntax::{self, FieldValue, Formula, FormulaKind, Item, OptionsKind, ParamValue};
use crate::world::{BoxFacts, DomainMask, SpecWorld, WorldFacts, WorldProblem};

mod domain;
mod learn;
mod options;
mod resolve;
mod time;

use self::time::time_decimals;
use crate::suggest::{closest, some_names};
use crate::wording::{plural, state_text};

pub use self::time::MAX_TIME_BOUND;
pub use crate::limits::{MAX_DOMAIN_STATES, MAX_DOMAIN_WORK};
pub use crate::suggest::{MAX_SUGGEST_CHARS, SUGGEST_BUDGET};
pub use crate::wording::thousands;
pub use options::expand;

/// At most this many diagnostics are reported per file.
pub const MAX_DIAGNOSTICS: usize = 200;

/// At most this many counterfactual memory values per option execution.
pub const MAX_COUNTERFACTUAL: u64 = 1000;

/// The fields an option may have.
const OPTION_FIELDS: [&str; 4] = ["reach", "init", "terminate", "avoid"];

/// At most this many tilings in `learn { tiles: { tilings } }`.
pub const MAX_TILINGS: u64 = 64;

/// At most this many tiles along a variable in `learn { tiles: { bins } }`.
pub const MAX_TILE_BINS: u64 = 1024;

/// The expanded options set may hold at most this many options.
pub const MAX_OPTIONS: u64 = 10_000;

/// The result of [`check`].
#[derive(Clone, Debug)]
pub struct Checked {
    /// The syntax tree the checks ran on (for tools that need both).
    pub file: syntax::File,
    /// One checked spec per spec of the file whose header parsed, in source order. A spec
    /// with errors is still present, with the parts that did check.
    pub specs: Vec<CheckedSpec>,
    /// Every diagnostic (syntax and semantic), sorted by position, deduplicated, capped at
    /// [`MAX_DIAGNOSTICS`].
    pub diagnostics: Vec<Diagnostic>,
}

impl Checked {
    /// Whether any diagnostic is an error.
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}

/// Parses and checks a source text. Never fails and never panics.
pub fn check(src: &str) -> Checked {
    check_parsed(src, parse(src))
}

/// Checks a source text that is already parsed: `parsed` must be what [`parse`] gives for
/// `src` (an editor that re-parses only what changed, see [`crate::incremental`], builds
/// it without parsing the whole text). Never fails and never panics.
pub fn check_parsed(src: &str, parsed: crate::parser::Parsed) -> Checked {
    check_parsed_in(src, parsed, &|_| SpecWorld::Alone)
}

/// Parses and checks `src` as [`crate::check()`] does, and checks each spec with options
/// against `world`, whatever world the spec names (a command line's `--world`). Never fails
/// and never panics.
pub fn check_in_world(src: &str, world: &WorldFacts) -> Checked {
    check_parsed_in(src, parse(src), &|_| SpecWorld::Facts(world))
}

/// [`check_in_world`] on a text that is already parsed (see [`check_parsed`]): what
/// an editor that re-parses only what changed calls.
pub fn check_parsed_in_world(
    src: &str,
    parsed: crate::parser::Parsed,
    world: &WorldFacts,
) -> Checked {
    check_parsed_in(src, parsed, &|_| SpecWorld::Facts(world))
}

/// Checks a parsed text with each spec against the world `world_of` gives for it (usually
/// the one its [`crate::world_item`] names, found by the caller). Never fails and never panics.
pub fn check_parsed_with_worlds<'w>(
    src: &str,
    parsed: crate::parser::Parsed,
    world_of: &dyn Fn(&syntax::Spec) -> SpecWorld<'w>,
) -> Checked {
    check_parsed_in(src, parsed, world_of)
}

/// [`check_parsed`], with each spec checked against the world `world_of` gives for it.
pub(crate) fn check_parsed_in<'w>(
    src: &str,
    parsed: crate::parser::Parsed,
    world_of: &dyn Fn(&syntax::Spec) -> SpecWorld<'w>,
) -> Checked {
    let mut diags = parsed.diagnostics;
    let mut specs = Vec::new();
    let mut seen: HashMap<String, Range<usize>> = HashMap::new();
    let mut suggest_budget = SUGGEST_BUDGET;
    for spec in &parsed.file.specs {
        if spec.name.name.is_empty() {
            continue;
        }
        if let Some(first) = seen.get(&spec.name.name) {
            diags.push(
                Diagnostic::new(
                    "HSTL003",
                    spec.name.range.clone(),
                    format!("duplicate spec name `{}`", spec.name.name),
                )
                .with_label(first.clone(), "first defined here")
                .with_help("give each spec of a file its own name"),
            );
        } else {
            seen.insert(spec.name.name.clone(), spec.name.range.clone());
        }
        let (mut world, mut world_problem, mut box_world) = (None, None, None);
        match world_of(spec) {
            SpecWorld::Alone => {}
            SpecWorld::Facts(facts) => world = Some(facts),
            SpecWorld::Box(facts) => box_world = Some(facts),
            SpecWorld::Unavailable(problem) => world_problem = Some(problem),
        }
        let mut cx = Cx {
            src,
            world,
            world_problem,
            box_world,
            diags: Vec::new(),
            names: HashMap::default(),
            let_refs: Vec::new(),
            broken_names: spec.broken.iter().flat_map(|b| b.names.iter().cloned()).collect(),
            suggest_budget,
            dense: false,
            time_decimals: 0,
        };
        let checked = cx.spec(spec);
        suggest_budget = cx.suggest_budget;
        diags.append(&mut cx.diags);
        crate::lints::long_names(spec, &mut diags);
        crate::lints::constant_formulas(&checked, &mut diags);
        crate::lints::inclusive_int_bounds(&checked, src, &mut diags);
        crate::lints::undefined_expressions(&checked, src, &mut diags);
        crate::lints::unbounded_past_in_long_runs(&checked, &mut diags);
        specs.push(checked);
    }
    let diagnostics = diagnostic::finish(diags, MAX_DIAGNOSTICS, src.len());
    Checked { file: parsed.file, specs, diagnostics }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum NameRef {
    Var(usize),
    Let(usize),
    /// The time variable of a dense-time spec: no formula may read it.
    Time,
}

/// Per-spec checking state.
struct Cx<'s> {
    src: &'s str,
    /// The world the spec is checked against, if any.
    world: Option<&'s WorldFacts>,
    /// Why the world the spec names could not be had, if so.
    world_problem: Option<&'s WorldProblem>,
    /// The continuous world the spec is checked against, if any.
    box_world: Option<&'s BoxFacts>,
    diags: Vec<Diagnostic>,
    names: HashMap<String, (NameRef, Range<usize>), BuildHasherDefault<NameHasher>>,
    /// Let references found while resolving the current formula: (let index, range).
    let_refs: Vec<(usize, Range<usize>)>,
    /// Names declared by items that did not parse: unknown-name errors about them would
    /// only repeat the syntax error.
    broken_names: std::collections::HashSet<String>,
    /// What is left of the file's [`SUGGEST_BUDGET`].
    suggest_budget: u64,
    /// The spec declares a time variable: a dense-time spec.
    dense: bool,
    /// The decimals of the dense spec's bounds (see [`CheckedSpec::time_decimals`]).
    time_decimals: u32,
}

fn doc_text(d: &Option<syntax::Doc>) -> Option<String> {
    d.as_ref().map(syntax::Doc::text)
}

impl Cx<'_> {
    fn push(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    fn error_count(&self) -> usize {
        self.diags.iter().filter(|d| d.is_error()).count()
    }

    fn spec(&mut self, spec: &syntax::Spec) -> CheckedSpec {
        let mut out = CheckedSpec {
            name: spec.name.name.clone(),
            doc: doc_text(&spec.doc),
            name_range: spec.name.range.clone(),
            range: spec.range.clone(),
            state_vars: Vec::new(),
            lets: Vec::new(),
            let_order: Vec::new(),
            task: None,
            primitives: Vec::new(),
            options: Vec::new(),
            learn: LearnParams::default(),
            preset_expansion: None,
            world: None,
            time: None,
            time_decimals: 0,
        };
        self.dense = spec.items.iter().any(|i| match i {
            Item::State(b) => b.vars.iter().any(|v| v.ty == syntax::VarType::Time),
            _ => false,
        });
        if self.dense {
            self.time_decimals = time_decimals(spec);
            out.time_decimals = self.time_decimals;
        }
        // Once-only items.
        let mut firsts: HashMap<&'static str, Range<usize>> = HashMap::new();
        let mut lets = Vec::new();
        let mut tasks = Vec::new();
        let mut option_decls = Vec::new();
        let mut options_item = None;
        let mut learn = None;
        for item in &spec.items {
            let once = match item {
                Item::State(_) => Some("state"),
                Item::Task(_) => Some("task"),
                Item::Options(_) => Some("options"),
                Item::Learn(_) => Some("learn"),
                Item::World(_) => Some("world"),
                _ => None,
            };
            if let Some(kw) = once {
                let r = item.range();
                let kw_range = r.start..(r.start + kw.len()).min(r.end);
                let kw_range = match item {
                    Item::Task(t) => t.keyword_range.clone(),
                    _ => kw_range,
                };
                if let Some(first) = firsts.get(kw) {
                    self.push(
                        Diagnostic::new("HSTL003", kw_range, format!("a second `{kw}` item"))
                            .with_label(first.clone(), "first given here")
                            .with_help(format!("a spec has at most one `{kw}` item: merge them")),
                    );
                    continue;
                }
                firsts.insert(kw, kw_range);
            }
            if self.dense
                && let Some(what) = match item {
                    Item::Option(_) => Some("an `option`"),
                    Item::Options(_) => Some("an `options` item"),
                    Item::Learn(_) => Some("a `learn` item"),
                    Item::World(_) => Some("a `world`"),
                    _ => None,
                }
            {
                let r = item.range();
                let kw = match item {
                    Item::Option(o) => o.name.range.clone(),
                    Item::Options(_) => r.start..(r.start + "options".len()).min(r.end),
                    Item::Learn(_) => r.start..(r.start + "learn".len()).min(r.end),
                    Item::World(w) => w.name_range.clone(),
                    _ => r.clone(),
                };
                let d = Diagnostic::new(
                    "HSTL083",
                    kw,
                    format!(
                        "{what} in a dense-time spec: a spec with a time variable is for \
                         monitoring time-stamped traces, not for learning"
                    ),
                )
                .with_help(
                    "remove it, or remove the time variable to learn in discrete steps \
                     (the learner's world moves in steps)",
                );
                let d = match &out.time {
                    Some(t) => d.with_label(t.name_range.clone(), "the time variable"),
                    None => d,
                };
                self.push(d);
                continue;
            }
            match item {
                Item::State(b) => self.state_block(b, &mut out),
                Item::Let(l) => lets.push(l),
                Item::Task(t) => tasks.push(t),
                Item::Option(o) => option_decls.push(o),
                Item::Options(o) => options_item = Some(o),
                Item::Learn(l) => learn = Some(l),
                Item::World(w) => {
                    out.world = Some(WorldRef { name: w.name.clone(), range: w.name_range.clone() })
                }
            }
        }
        self.lets(&lets, &mut out);
        match tasks.first() {
            Some(t) => {
                let formula = self.formula(&t.formula);
                out.task =
                    Some(TaskInfo { formula, doc: doc_text(&t.doc), range: t.range.clone() });
            }
            None if spec.broken.iter().any(|b| b.keyword.as_deref() == Some("task")) => {}
            None => {
                let r = if spec.name.name.is_empty() {
                    spec.range.start..spec.range.start
                } else {
                    spec.name.range.clone()
                };
                self.push(
                    Diagnostic::new(
                        "HSTL015",
                        r,
                        format!("spec `{}` has no `task`", spec.name.name),
                    )
                    .with_help("add the task, such as `task always[0..] eventually[0..40] A;`"),
                );
            }
        }
        let preset = learn.map_or(Preset::Paper, preset_of);
        let filled = self.options(&option_decls, options_item, spec, preset, &mut out);
        if let Some(l) = learn {
            self.learn(l, preset, &mut out);
            self.counterfactual_needs(l, &out);
            self.plan_needs(l, &mut out);
        }
        // A float state is learned with tilings, whatever the preset.
        if out.is_continuous() && !out.primitives.is_empty() && out.learn.tiles.is_none() {
            out.learn.tiles = Some(Tiles::default());
        }
        if preset == Preset::Auto {
            let (fields, set) = &filled;
            out.preset_expansion = Some(crate::preset::expansion(&out, self.src, fields, *set));
        }
        self.safety_unseen(&out);
        self.persistent_needs(learn, &out);
        if let Some(l) = learn {
            self.diags.extend(crate::budget::learning(self.src, l, &out));
        }
        if self.error_count() == 0
            && let Some(d) = crate::budget::memory(self.src, learn, &out, self.box_world)
        {
            self.push(d);
        }
        if self.error_count() == 0
            && let Some(d) = crate::budget::goal_text(self.src, &out)
        {
            self.push(d);
        }
        self.mark_used(&mut out);
        // A broken item or an invalid part may have used any let: stay quiet then.
        if out.task.is_some() && spec.broken.is_empty() && self.error_count() == 0 {
            // One warning per unused let, possibly thousands: the code's severity is
            // looked up once.
            let unused = Diagnostic::new("HSTL101", 0..0, String::new())
                .with_help("use it in the task or an option, or remove it");
            for l in &out.lets {
                if !l.used {
                    self.push(Diagnostic {
                        range: l.name_range.clone(),
                        message: format!("unused `let` `{}`", l.name),
                        ..unused.clone()
                    });
                }
            }
        }
        // The world's diagnostics come beside the spec's own, never instead of them: the
        // spec's checks below run as they would without a world.
        let spec_errors = self.error_count();
        if let (Some(problem), Some(item)) = (self.world_problem, &out.world) {
            self.push(
                Diagnostic::new("HSTL034", item.range.clone(), problem.message.clone())
                    .with_help(problem.help.clone()),
            );
        }
        let state_broken = spec.broken.iter().any(|b| b.keyword.as_deref() == Some("state"));
        if let Some(b) = self.box_world
            && !out.primitives.is_empty()
            && !state_broken
        {
            let mut found = Vec::new();
            b.fit(&out, &mut |d| found.push(d));
            self.diags.append(&mut found);
        }
        let mask = match self.world {
            Some(world) if !out.primitives.is_empty() && !state_broken => {
                let mut found = Vec::new();
                let mask = world.fit(&out, &mut |d| found.push(d));
                self.diags.append(&mut found);
                mask
            }
            _ => None,
        };
        if spec_errors == 0 {
            let plan_written =
                learn.is_some_and(|l| l.params.iter().any(|p| p.name.name == "plan"));
            let too_large =
                self.finite_domain(&out, options_item, spec, mask.as_ref(), plan_written);
            if too_large {
                // Only the preset asked for the plan: it Q-learns the options level instead.
                out.learn.plan = Plan::Off;
                let (fields, set) = &filled;
                out.preset_expansion = Some(crate::preset::expansion(&out, self.src, fields, *set));
            }
        }
        out
    }
}

/// The preset a `learn` item names: `auto` when its first `preset` parameter is `auto`, the
/// paper's otherwise (a bad value is reported where the `learn` item is checked).
fn preset_of(l: &syntax::Learn) -> Preset {
    match l.params.iter().find(|p| p.name.name == "preset").map(|p| &p.value) {
        Some(ParamValue::Word(w)) if w.name == "auto" => Preset::Auto,
        _ => Preset::Paper,
    }
}
