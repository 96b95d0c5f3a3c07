//! Name resolution and every check of LANGUAGE.md, building [`CheckedSpec`]s.

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

/// At most this many diagnostics are reported per file.
pub const MAX_DIAGNOSTICS: usize = 200;

/// The finite-domain checks enumerate at most this many states.
pub const MAX_DOMAIN_STATES: u64 = 1_000_000;

/// The finite-domain checks evaluate at most this many formulas (states times the
/// formulas and lets evaluated per state).
pub const MAX_DOMAIN_WORK: u64 = 20_000_000;

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

/// Names longer than this many characters get no "did you mean" help (and are never
/// suggested): a comparison costs the product of the two lengths.
pub const MAX_SUGGEST_CHARS: usize = 64;

/// The "did you mean" searches of one file compare at most this many pairs of characters
/// (and candidates) in all; past that they suggest nothing, so that a file with many
/// unknown names among many declared ones still checks in linear time.
pub const SUGGEST_BUDGET: u64 = 20_000_000;

/// The edit distance of `a` and `b` (insertions, deletions, substitutions and swaps of two
/// neighbours, each costing 1), if it is at most `limit`. `rows` is scratch space, reused
/// between calls.
fn distance_within(a: &[char], b: &[char], limit: usize, rows: &mut Vec<usize>) -> Option<usize> {
    if a.len().abs_diff(b.len()) > limit {
        return None;
    }
    let w = b.len() + 1;
    rows.clear();
    rows.resize(3 * w, 0);
    // Three rows: the one before the previous (for swaps), the previous and the current.
    let (mut older, mut prev, mut cur) = (0, w, 2 * w);
    for (j, cell) in rows[prev..prev + w].iter_mut().enumerate() {
        *cell = j;
    }
    for (i, &ca) in a.iter().enumerate() {
        rows[cur] = i + 1;
        let mut best = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let mut d = (rows[prev + j] + usize::from(ca != cb))
                .min(rows[prev + j + 1] + 1)
                .min(rows[cur + j] + 1);
            if i > 0 && j > 0 && ca == b[j - 1] && a[i - 1] == cb {
                d = d.min(rows[older + j - 1] + 1);
            }
            rows[cur + j + 1] = d;
            best = best.min(d);
        }
        if best > limit {
            return None;
        }
        (older, prev, cur) = (prev, cur, older);
    }
    let d = rows[prev + b.len()];
    (d <= limit).then_some(d)
}

/// The candidate closest to `name` (ties: the first in alphabetical order), if it is close
/// enough to be a typo: at most a third of the name's characters differ. Each compared
/// character pair and candidate costs one unit of `budget`; with the budget spent, nothing
/// is suggested.
pub(crate) fn closest<'a>(
    name: &str,
    candidates: impl Iterator<Item = &'a str>,
    budget: &mut u64,
) -> Option<&'a str> {
    let a: Vec<char> = name.chars().take(MAX_SUGGEST_CHARS + 1).collect();
    if a.len() > MAX_SUGGEST_CHARS || *budget == 0 {
        return None;
    }
    let len = a.len();
    let limit = (len / 3).max(1);
    let mut rows = Vec::new();
    let mut b: Vec<char> = Vec::with_capacity(MAX_SUGGEST_CHARS + 1);
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        if *budget == 0 {
            // A partial search could miss the closest name: suggest none.
            return None;
        }
        *budget -= 1;
        // A character takes one to four bytes: most candidates fail on their byte length.
        if c.len() + limit < len || c.len() > 4 * (len + limit) {
            continue;
        }
        b.clear();
        b.extend(c.chars().take(MAX_SUGGEST_CHARS + 1));
        if b.len() > MAX_SUGGEST_CHARS || b.len().abs_diff(len) > limit {
            continue;
        }
        *budget = budget.saturating_sub((len * b.len()) as u64);
        if let Some(d) = distance_within(&a, &b, limit, &mut rows)
            && d < len
            && best.is_none_or(|old| (d, c) < old)
        {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// At most `shown` names joined by commas, then how many there are in all.
fn some_names(names: &[&str], shown: usize) -> String {
    if names.len() <= shown {
        names.join(", ")
    } else {
        format!("{}, ... ({} in all)", names[..shown].join(", "), names.len())
    }
}

fn state_text(spec_vars: &[StateVarInfo], s: &[f64]) -> String {
    spec_vars
        .iter()
        .zip(s)
        .map(|(v, x)| format!("{} = {}", v.name, x))
        .collect::<Vec<_>>()
        .join(", ")
}

fn plural(n: u64, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
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

    fn state_block(&mut self, b: &syntax::StateBlock, out: &mut CheckedSpec) {
        for v in &b.vars {
            if v.ty == syntax::VarType::Time {
                self.time_var(v, out);
                continue;
            }
            let domain = self.domain(v);
            if let Some((_, first)) = self.names.get(&v.name.name) {
                let first = first.clone();
                self.push(
                    Diagnostic::new(
                        "HSTL003",
                        v.name.range.clone(),
                        format!("duplicate name `{}`", v.name.name),
                    )
                    .with_label(first, "first defined here")
                    .with_help("rename one of them"),
                );
                continue;
            }
            self.names.insert(
                v.name.name.clone(),
                (NameRef::Var(out.state_vars.len()), v.name.range.clone()),
            );
            out.state_vars.push(StateVarInfo {
                name: v.name.name.clone(),
                ty: v.ty,
                domain,
                doc: doc_text(&v.doc),
                name_range: v.name.range.clone(),
                range: v.range.clone(),
            });
        }
    }

    /// `t: time`: the spec's time variable (at most one, without a range).
    fn time_var(&mut self, v: &syntax::StateVar, out: &mut CheckedSpec) {
        if let Some(r) = &v.domain {
            self.push(
                Diagnostic::new(
                    "HSTL080",
                    r.range.clone(),
                    format!("the time variable `{}` has a range", v.name.name),
                )
                .with_help(format!(
                    "time stamps are any strictly increasing numbers: write `{}: time`",
                    v.name.name
                )),
            );
        }
        if let Some(first) = &out.time {
            self.push(
                Diagnostic::new(
                    "HSTL080",
                    v.ty_range.clone(),
                    format!("a second time variable `{}`", v.name.name),
                )
                .with_label(first.name_range.clone(), "the time variable")
                .with_help(format!(
                    "a trace has one time column: make `{}` a `float`, or remove it",
                    v.name.name
                )),
            );
            return;
        }
        if let Some((_, first)) = self.names.get(&v.name.name) {
            let first = first.clone();
            self.push(
                Diagnostic::new(
                    "HSTL003",
                    v.name.range.clone(),
                    format!("duplicate name `{}`", v.name.name),
                )
                .with_label(first, "first defined here")
                .with_help("rename one of them"),
            );
            return;
        }
        self.names.insert(v.name.name.clone(), (NameRef::Time, v.name.range.clone()));
        out.time = Some(TimeVarInfo {
            name: v.name.name.clone(),
            doc: doc_text(&v.doc),
            name_range: v.name.range.clone(),
            range: v.range.clone(),
        });
    }

    /// The time variable used in a formula or an expression.
    fn time_in_formula(&mut self, id: &syntax::Ident, def: Range<usize>) {
        self.push(
            Diagnostic::new(
                "HSTL082",
                id.range.clone(),
                format!("`{}` is the time variable: a formula cannot read it", id.name),
            )
            .with_label(def, "declared as the time stamps here")
            .with_help(
                "robustness is a function of time, not of the stamps' values: say when with an \
                 interval, such as `eventually[0..=2.5] x > 1`",
            ),
        );
    }

    fn domain(&mut self, v: &syntax::StateVar) -> Domain {
        let Some(r) = &v.domain else { return Domain::Unbounded };
        match v.ty {
            syntax::VarType::Float => {
                let empty =
                    if r.inclusive { r.hi.value < r.lo.value } else { r.hi.value <= r.lo.value };
                if empty {
                    self.push(
                        Diagnostic::new(
                            "HSTL005",
                            r.range.clone(),
                            format!("empty range `{}` for `{}`", self.text(&r.range), v.name.name),
                        )
                        .with_help("the upper bound must exceed the lower one"),
                    );
                    return Domain::Unbounded;
                }
                Domain::Float { lo: r.lo.value, hi: r.hi.value, inclusive: r.inclusive }
            }
            syntax::VarType::Time => Domain::Unbounded,
            syntax::VarType::Int => {
                let lo = self.int_bound(&r.lo, "range");
                let hi = self.int_bound(&r.hi, "range");
                let (Some(lo), Some(hi)) = (lo, hi) else { return Domain::Unbounded };
                let hi_incl = if r.inclusive { hi } else { hi - 1 };
                if hi_incl < lo {
                    let (msg, help) = if hi < lo {
                        ("inverted", "swap the bounds".to_string())
                    } else {
                        (
                            "empty",
                            format!(
                                "`{lo}..{hi}` excludes {hi}: write `{lo}..={hi}` to include it"
                            ),
                        )
                    };
                    self.push(
                        Diagnostic::new(
                            "HSTL005",
                            r.range.clone(),
                            format!("{msg} range `{}` for `{}`", self.text(&r.range), v.name.name),
                        )
                        .with_help(help),
                    );
                    return Domain::Unbounded;
                }
                Domain::Int { lo, hi: hi_incl }
            }
        }
    }

    fn text(&self, r: &Range<usize>) -> &str {
        self.src.get(r.clone()).unwrap_or("")
    }

    fn int_bound(&mut self, n: &syntax::NumberLit, what: &str) -> Option<i64> {
        // A domain bound may be negative (`-5..=5`); an interval's never is (the grammar).
        let (negative, magnitude) = match n.text.strip_prefix('-') {
            Some(digits) if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) => {
                (true, digits.parse::<u64>().ok())
            }
            _ => (false, n.as_integer()),
        };
        let value = magnitude.and_then(|v| i64::try_from(v).ok()).filter(|&v| v < i64::MAX / 4);
        match value.map(|v| if negative { -v } else { v }) {
            Some(v) => Some(v),
            _ => {
                let digits = n.text.strip_prefix('-').unwrap_or(&n.text);
                let whole = !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit());
                let msg = if whole {
                    format!("{what} bound `{}` is too large", n.text)
                } else {
                    format!("{what} bound `{}` is not a whole number", n.text)
                };
                let help = if what == "interval" && !whole {
                    "interval bounds count steps: write digits only, such as `40`; for bounds \
                     in seconds (`[0..=2.5]`), monitor time-stamped traces: declare the time \
                     column in `state`, such as `t: time`"
                } else {
                    "bounds count steps or integer values: write digits only, such as `40`"
                };
                self.push(Diagnostic::new("HSTL006", n.range.clone(), msg).with_help(help));
                None
            }
        }
    }

    fn lets(&mut self, lets: &[&syntax::Let], out: &mut CheckedSpec) {
        // Declare every name first so that lets may refer to later ones.
        let mut kept = Vec::new();
        for l in lets {
            if let Some((_, first)) = self.names.get(&l.name.name) {
                let first = first.clone();
                self.push(
                    Diagnostic::new(
                        "HSTL003",
                        l.name.range.clone(),
                        format!("duplicate name `{}`", l.name.name),
                    )
                    .with_label(first, "first defined here")
                    .with_help("rename one of them"),
                );
                kept.push(false);
                continue;
            }
            let idx = out.lets.len();
            self.names.insert(l.name.name.clone(), (NameRef::Let(idx), l.name.range.clone()));
            out.lets.push(LetInfo {
                name: l.name.name.clone(),
                formula: CFormula { kind: CFormulaKind::Invalid, range: l.formula.range.clone() },
                kind: LetKind::State,
                used: false,
                doc: doc_text(&l.doc),
                name_range: l.name.range.clone(),
                range: l.range.clone(),
            });
            kept.push(true);
        }
        let mut edges: Vec<Vec<(usize, Range<usize>)>> = vec![Vec::new(); out.lets.len()];
        let mut idx = 0;
        for (l, keep) in lets.iter().zip(kept) {
            self.let_refs.clear();
            let f = self.formula(&l.formula);
            if keep {
                out.lets[idx].formula = f;
                edges[idx] = std::mem::take(&mut self.let_refs);
                idx += 1;
            }
        }
        // Kahn's algorithm: lets left over are in or behind a cycle.
        let n = out.lets.len();
        let mut indeg = vec![0usize; n];
        let mut users: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (i, es) in edges.iter().enumerate() {
            for (j, _) in es {
                indeg[i] += 1;
                users[*j].push(i);
            }
        }
        let mut queue: Vec<usize> = (0..n).filter(|&i| indeg[i] == 0).collect();
        let mut order = Vec::new();
        while let Some(j) = queue.pop() {
            order.push(j);
            for &i in &users[j] {
                indeg[i] -= 1;
                if indeg[i] == 0 {
                    queue.push(i);
                }
            }
        }
        let mut placed = vec![false; n];
        for &i in &order {
            placed[i] = true;
        }
        let mut reported = vec![false; n];
        for start in 0..n {
            if placed[start] || reported[start] {
                continue;
            }
            // Follow unplaced references until a let repeats: that is a cycle.
            let mut path: Vec<(usize, Range<usize>)> = Vec::new();
            let mut pos: HashMap<usize, usize> = HashMap::new();
            let mut cur = start;
            let cycle = loop {
                if let Some(&p) = pos.get(&cur) {
                    break path[p..].to_vec();
                }
                pos.insert(cur, path.len());
                let Some((next, r)) = edges[cur].iter().find(|(j, _)| !placed[*j]).cloned() else {
                    break Vec::new();
                };
                path.push((cur, r));
                cur = next;
            };
            if cycle.is_empty() || cycle.iter().any(|(i, _)| reported[*i]) {
                continue;
            }
            for (i, _) in &cycle {
                reported[*i] = true;
            }
            let first = cycle[0].0;
            let lname = &out.lets[first].name;
            let d = if cycle.len() == 1 {
                Diagnostic::new(
                    "HSTL004",
                    out.lets[first].name_range.clone(),
                    format!("`{lname}` refers to itself"),
                )
                .with_label(cycle[0].1.clone(), "here")
            } else {
                let mut names: Vec<String> =
                    cycle.iter().map(|(i, _)| format!("`{}`", out.lets[*i].name)).collect();
                names.push(format!("`{lname}`"));
                let mut d = Diagnostic::new(
                    "HSTL004",
                    out.lets[first].name_range.clone(),
                    format!("`{lname}` refers to itself: {}", names.join(" -> ")),
                );
                for (i, r) in &cycle {
                    let to = match edges[*i].iter().find(|(_, rr)| rr == r) {
                        Some((j, _)) => out.lets[*j].name.clone(),
                        None => String::new(),
                    };
                    d = d
                        .with_label(r.clone(), format!("`{}` uses `{to}` here", out.lets[*i].name));
                }
                d
            };
            self.push(d.with_help("write one of these formulas without the reference"));
        }
        // Kinds, in dependency order; lets in or behind a cycle are judged on their own text.
        let mut temporal = vec![false; n];
        for &i in &order {
            let mut t = has_temporal_node(&out.lets[i].formula);
            for (j, _) in &edges[i] {
                t |= temporal[*j];
            }
            temporal[i] = t;
        }
        for i in 0..n {
            if !placed[i] {
                temporal[i] = has_temporal_node(&out.lets[i].formula);
            }
            out.lets[i].kind = if temporal[i] { LetKind::Temporal } else { LetKind::State };
        }
        // A dependency order with ties broken by declaration order, for stable output.
        out.let_order = dependency_order(&edges, &placed);
    }

    /// A bound of a dense spec's interval, in `10^-time_decimals` of the time unit.
    fn time_bound(&mut self, n: &syntax::NumberLit) -> Option<u64> {
        let scaled = decimal(&n.text).and_then(|(m, d)| {
            let p = 10u128.checked_pow(self.time_decimals.checked_sub(d)?)?;
            u64::try_from(m.checked_mul(p)?).ok().filter(|&v| v <= MAX_TIME_BOUND)
        });
        if scaled.is_none() {
            self.push(
                Diagnostic::new(
                    "HSTL006",
                    n.range.clone(),
                    format!("interval bound `{}` is too large or has too many digits", n.text),
                )
                .with_help(format!(
                    "the spec's bounds are counted in units of 10^-{} (its longest fraction): \
                     write at most {} digits in all",
                    self.time_decimals,
                    MAX_TIME_BOUND.to_string().len() - 1
                )),
            );
        }
        scaled
    }

    fn interval(&mut self, i: &Option<syntax::Interval>) -> Option<Interval> {
        let Some(i) = i else {
            return Some(Interval { start: 0, end: Bound::Unbounded, range: None });
        };
        if self.dense {
            return self.dense_interval(i);
        }
        let a = self.int_bound(&i.start, "interval");
        let b = match &i.end {
            Some(e) => Some(self.int_bound(e, "interval")?),
            None => None,
        };
        let a = a?;
        let end = match b {
            None => Bound::Unbounded,
            Some(b) => {
                let empty = if i.inclusive { b < a } else { b <= a };
                if empty {
                    let text = self.text(&i.range).to_string();
                    let (msg, help) = if b < a {
                        (format!("inverted interval `{text}`"), "swap the bounds".to_string())
                    } else {
                        (
                            format!("empty interval `{text}`"),
                            format!(
                                "`[{a}..{b}]` excludes step {b}: write `[{a}..={b}]` for that single step"
                            ),
                        )
                    };
                    self.push(Diagnostic::new("HSTL005", i.range.clone(), msg).with_help(help));
                    return None;
                }
                if i.inclusive { Bound::Inclusive(b as u64) } else { Bound::Exclusive(b as u64) }
            }
        };
        Some(Interval { start: a as u64, end, range: Some(i.range.clone()) })
    }

    /// An interval of a dense-time spec: decimal bounds, closed or unbounded.
    fn dense_interval(&mut self, i: &syntax::Interval) -> Option<Interval> {
        let a = self.time_bound(&i.start);
        let b = match &i.end {
            Some(e) => Some(self.time_bound(e)?),
            None => None,
        };
        let a = a?;
        let text = self.text(&i.range).to_string();
        let end = match b {
            None => Bound::Unbounded,
            Some(_) if !i.inclusive => {
                let lo = &i.start.text;
                let hi = i.end.as_ref().map_or("", |e| e.text.as_str());
                self.push(
                    Diagnostic::new(
                        "HSTL081",
                        i.range.clone(),
                        format!("the half-open interval `{text}` has no dense-time meaning"),
                    )
                    .with_help(format!(
                        "it would give values that hold at single instants: write the closed \
                         interval `[{lo}..={hi}]`"
                    )),
                );
                return None;
            }
            Some(b) if b < a => {
                self.push(
                    Diagnostic::new(
                        "HSTL005",
                        i.range.clone(),
                        format!("inverted interval `{text}`"),
                    )
                    .with_help("swap the bounds"),
                );
                return None;
            }
            Some(b) => Bound::Inclusive(b),
        };
        Some(Interval { start: a, end, range: Some(i.range.clone()) })
    }

    /// `prev` or `next` in a dense-time spec.
    fn no_dense_step(&mut self, f: &Formula, op: &str) {
        let at = f.range.start..(f.range.start + op.len()).min(f.range.end);
        self.push(
            Diagnostic::new("HSTL081", at, format!("`{op}` has no dense-time meaning")).with_help(
                format!(
                    "in continuous time there is no {} sample: say how far with an interval, such \
                 as `{}[0..=0.1] f`",
                    if op == "prev" { "previous" } else { "next" },
                    if op == "prev" { "once" } else { "eventually" }
                ),
            ),
        );
    }

    fn formula(&mut self, f: &Formula) -> CFormula {
        let range = f.range.clone();
        let invalid = CFormula { kind: CFormulaKind::Invalid, range: range.clone() };
        let kind = match &f.kind {
            FormulaKind::True => CFormulaKind::True,
            FormulaKind::False => CFormulaKind::False,
            FormulaKind::Paren(g) => return self.formula(g),
            FormulaKind::Name(id) => match self.names.get(&id.name) {
                Some((NameRef::Let(j), _)) => {
                    let j = *j;
                    self.let_refs.push((j, id.range.clone()));
                    CFormulaKind::Let(j)
                }
                Some((NameRef::Time, def)) => {
                    let def = def.clone();
                    self.time_in_formula(id, def);
                    return invalid;
                }
                Some((NameRef::Var(_), def)) => {
                    let def = def.clone();
                    self.push(
                        Diagnostic::new(
                            "HSTL008",
                            id.range.clone(),
                            format!("`{}` is a state variable, not a formula", id.name),
                        )
                        .with_label(def, "declared here")
                        .with_help(format!("compare it, such as `{} > 0`", id.name)),
                    );
                    return invalid;
                }
                None => {
                    self.unknown(id, true);
                    return invalid;
                }
            },
            FormulaKind::Compare { first, rest } => {
                let mut parts = Vec::new();
                let mut lhs = self.expr(first);
                let mut ok = true;
                for (k, (op, op_range, e)) in rest.iter().enumerate() {
                    let rhs = self.expr(e);
                    let cop = match op {
                        syntax::CmpOp::Lt => Some(CmpOp::Lt),
                        syntax::CmpOp::Le => Some(CmpOp::Le),
                        syntax::CmpOp::Gt => Some(CmpOp::Gt),
                        syntax::CmpOp::Ge => Some(CmpOp::Ge),
                        syntax::CmpOp::Eq | syntax::CmpOp::Ne => {
                            self.push(
                                Diagnostic::new(
                                    "HSTL007",
                                    op_range.clone(),
                                    format!("`{}` has no robustness", op.as_str()),
                                )
                                .with_help("use a band, such as `abs(x - 3) < 0.5`"),
                            );
                            None
                        }
                    };
                    match cop {
                        // The last expression is moved, not copied: it ends the chain.
                        Some(c) if k + 1 == rest.len() => {
                            let range = lhs.range.start..rhs.range.end;
                            parts.push(CFormula { range, kind: CFormulaKind::Cmp(c, lhs, rhs) });
                            break;
                        }
                        Some(c) => {
                            let next = rhs.clone();
                            let range = lhs.range.start..rhs.range.end;
                            parts.push(CFormula { range, kind: CFormulaKind::Cmp(c, lhs, rhs) });
                            lhs = next;
                        }
                        None => {
                            ok = false;
                            lhs = rhs;
                        }
                    }
                }
                if !ok {
                    return invalid;
                }
                if parts.len() == 1 {
                    return parts.pop().unwrap_or(invalid);
                }
                CFormulaKind::And(parts)
            }
            FormulaKind::Not(g) => CFormulaKind::Not(Box::new(self.formula(g))),
            FormulaKind::Always(i, g) => {
                let iv = self.interval(i);
                let g = self.formula(g);
                match iv {
                    Some(iv) => CFormulaKind::Always(iv, Box::new(g)),
                    None => return invalid,
                }
            }
            FormulaKind::Eventually(i, g) => {
                let iv = self.interval(i);
                let g = self.formula(g);
                match iv {
                    Some(iv) => CFormulaKind::Eventually(iv, Box::new(g)),
                    None => return invalid,
                }
            }
            FormulaKind::Until(a, i, b) => {
                let a = self.formula(a);
                let iv = self.interval(i);
                let b = self.formula(b);
                match iv {
                    Some(iv) => CFormulaKind::Until(iv, Box::new(a), Box::new(b)),
                    None => return invalid,
                }
            }
            FormulaKind::Once(i, g) => {
                let iv = self.interval(i);
                let g = self.formula(g);
                match iv {
                    Some(iv) => CFormulaKind::Once(iv, Box::new(g)),
                    None => return invalid,
                }
            }
            FormulaKind::Historically(i, g) => {
                let iv = self.interval(i);
                let g = self.formula(g);
                match iv {
                    Some(iv) => CFormulaKind::Historically(iv, Box::new(g)),
                    None => return invalid,
                }
            }
            FormulaKind::Since(a, i, b) => {
                let a = self.formula(a);
                let iv = self.interval(i);
                let b = self.formula(b);
                match iv {
                    Some(iv) => CFormulaKind::Since(iv, Box::new(a), Box::new(b)),
                    None => return invalid,
                }
            }
            FormulaKind::Prev(g) if self.dense => {
                self.no_dense_step(f, "prev");
                self.formula(g);
                return invalid;
            }
            FormulaKind::Next(g) if self.dense => {
                self.no_dense_step(f, "next");
                self.formula(g);
                return invalid;
            }
            FormulaKind::Prev(g) => CFormulaKind::Prev(Box::new(self.formula(g))),
            FormulaKind::Next(g) => CFormulaKind::Next(Box::new(self.formula(g))),
            FormulaKind::And(v) => CFormulaKind::And(v.iter().map(|g| self.formula(g)).collect()),
            FormulaKind::Or(v) => CFormulaKind::Or(v.iter().map(|g| self.formula(g)).collect()),
            FormulaKind::Implies(a, b) => {
                CFormulaKind::Implies(Box::new(self.formula(a)), Box::new(self.formula(b)))
            }
        };
        CFormula { kind, range }
    }

    fn unknown(&mut self, id: &syntax::Ident, formula: bool) {
        if self.broken_names.contains(&id.name) {
            return;
        }
        let want = if formula { NameRef::Let(0) } else { NameRef::Var(0) };
        let same_kind = |r: &NameRef| {
            matches!(
                (r, want),
                (NameRef::Let(_), NameRef::Let(_)) | (NameRef::Var(_), NameRef::Var(_))
            )
        };
        let cands = self.names.iter().filter(|(_, (r, _))| same_kind(r)).map(|(n, _)| n.as_str());
        let mut d =
            Diagnostic::new("HSTL002", id.range.clone(), format!("unknown name `{}`", id.name));
        d = match closest(&id.name, cands, &mut self.suggest_budget) {
            Some(c) => d.with_help(format!("did you mean `{c}`?")),
            None if formula => d.with_help(format!("declare it: `let {} = ...;`", id.name)),
            None => d.with_help(format!("declare it in `state {{ {}: int in 0..=9 }}`", id.name)),
        };
        self.push(d);
    }

    fn expr(&mut self, e: &syntax::Expr) -> CExpr {
        use syntax::ExprKind as K;
        let range = e.range.clone();
        let invalid = CExpr { kind: CExprKind::Invalid, range: range.clone() };
        let kind = match &e.kind {
            K::Number(n) => CExprKind::Const(n.value),
            K::Paren(a) => return self.expr(a),
            K::Name(id) => match self.names.get(&id.name) {
                Some((NameRef::Var(i), _)) => CExprKind::Var(*i),
                Some((NameRef::Time, def)) => {
                    let def = def.clone();
                    self.time_in_formula(id, def);
                    return invalid;
                }
                Some((NameRef::Let(_), def)) => {
                    let def = def.clone();
                    self.push(
                        Diagnostic::new(
                            "HSTL008",
                            id.range.clone(),
                            format!("`{}` is a formula, not a number", id.name),
                        )
                        .with_label(def, "defined here")
                        .with_help("comparisons relate numbers: state variables, constants and arithmetic; combine formulas with `&&`, `||`"),
                    );
                    return invalid;
                }
                None => {
                    self.unknown(id, false);
                    return invalid;
                }
            },
            K::Neg(a) => CExprKind::Neg(Box::new(self.expr(a))),
            K::Call(f, a) => {
                let a = Box::new(self.expr(a));
                match f {
                    syntax::Func::Abs => CExprKind::Abs(a),
                    syntax::Func::Sqrt => CExprKind::Sqrt(a),
                }
            }
            K::Binary(op, a, b) => {
                let (a, b) = (Box::new(self.expr(a)), Box::new(self.expr(b)));
                match op {
                    syntax::BinOp::Add => CExprKind::Add(a, b),
                    syntax::BinOp::Sub => CExprKind::Sub(a, b),
                    syntax::BinOp::Mul => CExprKind::Mul(a, b),
                    syntax::BinOp::Div => CExprKind::Div(a, b),
                }
            }
        };
        CExpr { kind, range }
    }

    /// Where a formula stops being a state formula: the temporal node, or a let reference
    /// to a temporal let (with that let's name range).
    fn temporal_site(&self, f: &CFormula, lets: &[LetInfo]) -> Option<TemporalSite> {
        match &f.kind {
            kind if kind.is_temporal() => Some((f.range.clone(), None)),
            CFormulaKind::Let(i) => {
                let l = lets.get(*i)?;
                (l.kind == LetKind::Temporal)
                    .then(|| (f.range.clone(), Some((l.name_range.clone(), l.name.clone()))))
            }
            CFormulaKind::Not(a) => self.temporal_site(a, lets),
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                v.iter().find_map(|g| self.temporal_site(g, lets))
            }
            CFormulaKind::Implies(a, b) => {
                self.temporal_site(a, lets).or_else(|| self.temporal_site(b, lets))
            }
            _ => None,
        }
    }

    fn require_state(&mut self, f: &CFormula, field: &str, option: &str, lets: &[LetInfo]) {
        if let Some((r, via)) = self.temporal_site(f, lets) {
            let mut d = Diagnostic::new(
                "HSTL009",
                r,
                format!("temporal operator in the `{field}` of option `{option}`"),
            )
            .with_help("reach, init and terminate are evaluated on one state: use a formula without temporal operators (`always`, `eventually`, `until`, `once`, `historically`, `since`, `prev`, `next`)");
            if let Some((lr, name)) = via {
                d = d.with_label(lr, format!("`{name}` is a temporal formula"));
            }
            self.push(d);
        }
    }

    /// Checks the options and builds the set; with `preset: auto`, fills in what the preset
    /// gives. Returns which of `init`, `terminate` and `avoid` it filled in per primitive
    /// (and whether it added the primitive), and whether it chose the options set.
    fn options(
        &mut self,
        decls: &[&syntax::OptionDecl],
        item: Option<&syntax::OptionsItem>,
        spec: &syntax::Spec,
        preset: Preset,
        out: &mut CheckedSpec,
    ) -> (Vec<[bool; 4]>, bool) {
        let auto = preset == Preset::Auto;
        let persistent = auto && out.persistent_conjuncts(self.src).is_some();
        let auto_avoid = if auto {
            crate::preset::avoid_formula(&crate::preset::safety_conjuncts(out))
        } else {
            None
        };
        let mut filled: Vec<[bool; 4]> = Vec::new();
        let mut by_name: HashMap<String, (usize, Range<usize>)> = HashMap::new();
        for o in decls {
            if let Some((_, first)) = by_name.get(&o.name.name) {
                let first = first.clone();
                self.push(
                    Diagnostic::new(
                        "HSTL003",
                        o.name.range.clone(),
                        format!("duplicate option `{}`", o.name.name),
                    )
                    .with_label(first, "first declared here")
                    .with_help("rename one of them"),
                );
                continue;
            }
            let mut reach = None;
            let mut init = None;
            let mut terminate = None;
            let mut avoid = None;
            let mut seen: HashMap<String, Range<usize>> = HashMap::new();
            for f in o.fields.iter().flatten() {
                let key = f.name.name.as_str();
                if !OPTION_FIELDS.contains(&key) {
                    let mut d = Diagnostic::new(
                        "HSTL019",
                        f.name.range.clone(),
                        format!("unknown option field `{key}`"),
                    );
                    d = match closest(key, OPTION_FIELDS.into_iter(), &mut u64::MAX.clone()) {
                        Some(c) => d.with_help(format!("did you mean `{c}`?")),
                        None => {
                            d.with_help("an option has `reach`, `init`, `terminate` and `avoid`")
                        }
                    };
                    self.push(d);
                    continue;
                }
                if let Some(first) = seen.get(key) {
                    self.push(
                        Diagnostic::new(
                            "HSTL019",
                            f.name.range.clone(),
                            format!("`{key}` given twice"),
                        )
                        .with_label(first.clone(), "first given here")
                        .with_help("give each field once"),
                    );
                    continue;
                }
                seen.insert(key.to_string(), f.name.range.clone());
                let value = match &f.value {
                    FieldValue::Argmax(_) if key == "terminate" => {
                        terminate = Some(Terminate::Argmax);
                        continue;
                    }
                    FieldValue::Argmax(r) => {
                        self.push(
                            Diagnostic::new(
                                "HSTL008",
                                r.clone(),
                                format!("`argmax` where the `{key}` formula is expected"),
                            )
                            .with_help("`argmax` is only allowed in `terminate`"),
                        );
                        CFormula { kind: CFormulaKind::Invalid, range: r.clone() }
                    }
                    FieldValue::Formula(g) => self.formula(g),
                };
                self.require_state(&value, key, &o.name.name, &out.lets);
                match key {
                    "reach" => reach = Some(value),
                    "init" => init = Some(value),
                    "avoid" => avoid = Some(value),
                    _ => terminate = Some(Terminate::Formula(value)),
                }
            }
            let reach = match reach {
                Some(r) => r,
                None => {
                    let kind = match self.names.get(&o.name.name) {
                        Some((NameRef::Let(j), _)) => CFormulaKind::Let(*j),
                        Some((NameRef::Var(_) | NameRef::Time, def)) => {
                            let def = def.clone();
                            self.push(
                                Diagnostic::new(
                                    "HSTL010",
                                    o.name.range.clone(),
                                    format!(
                                        "option `{}` names a state variable, not a `let`",
                                        o.name.name
                                    ),
                                )
                                .with_label(def, "declared here")
                                .with_help(
                                    "give the option a `reach` field, or name it after a `let`",
                                ),
                            );
                            CFormulaKind::Invalid
                        }
                        None if self.broken_names.contains(&o.name.name) => CFormulaKind::Invalid,
                        None => {
                            let lets = out.lets.iter().map(|l| l.name.as_str());
                            let mut d = Diagnostic::new(
                                "HSTL010",
                                o.name.range.clone(),
                                format!("option `{}` names no `let`", o.name.name),
                            );
                            d = match closest(&o.name.name, lets, &mut self.suggest_budget) {
                                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                                None => d.with_help(format!(
                                    "declare `let {} = ...;` or give the option a `reach` field",
                                    o.name.name
                                )),
                            };
                            self.push(d);
                            CFormulaKind::Invalid
                        }
                    };
                    let f = CFormula { kind, range: o.name.range.clone() };
                    self.require_state(&f, "reach", &o.name.name, &out.lets);
                    f
                }
            };
            by_name.insert(o.name.name.clone(), (out.primitives.len(), o.name.range.clone()));
            // The preset fills in only what was not written: the entry form (`init: !R` on a
            // persistent task, `terminate: R`) and the task's avoided regions.
            let valid = !matches!(reach.kind, CFormulaKind::Invalid);
            let fill = [
                persistent && valid && init.is_none(),
                auto && valid && terminate.is_none(),
                avoid.is_none() && auto_avoid.is_some(),
            ];
            filled.push([fill[0], fill[1], fill[2], false]);
            if fill[0] {
                init = Some(CFormula {
                    kind: CFormulaKind::Not(Box::new(reach.clone())),
                    range: reach.range.clone(),
                });
            }
            if fill[1] {
                terminate = Some(Terminate::Formula(reach.clone()));
            }
            if fill[2] {
                avoid = auto_avoid.clone();
            }
            out.primitives.push(PrimitiveOption {
                name: o.name.name.clone(),
                reach,
                init: init
                    .unwrap_or(CFormula { kind: CFormulaKind::True, range: o.name.range.clone() }),
                terminate: terminate.unwrap_or(Terminate::Argmax),
                avoid,
                doc: doc_text(&o.doc),
                name_range: o.name.range.clone(),
                range: o.range.clone(),
            });
        }
        // HSTL014: options need a bounded state space (tables or tilings cover it).
        if let Some(first) = decls.first() {
            for v in &out.state_vars {
                if v.domain == Domain::Unbounded {
                    let (ty, example) = match v.ty {
                        syntax::VarType::Int => ("int", "int in 0..=N"),
                        syntax::VarType::Float | syntax::VarType::Time => {
                            ("float", "float in LO..=HI")
                        }
                    };
                    self.push(
                        Diagnostic::new(
                            "HSTL014",
                            v.name_range.clone(),
                            format!("state variable `{}` has no bounds", v.name),
                        )
                        .with_label(first.name.range.clone(), "options are declared here")
                        .with_help(format!(
                            "options need a bounded state space: declare `{}: {example}` (it is `{ty}` without a range)",
                            v.name
                        )),
                    );
                }
            }
            // HSTL025: the most robust state of a region is found by enumerating the domain.
            if let Some(v) =
                out.state_vars.iter().find(|v| matches!(v.domain, Domain::Float { .. }))
            {
                for p in out.primitives.iter().filter(|p| p.terminate == Terminate::Argmax) {
                    self.push(
                        Diagnostic::new(
                            "HSTL025",
                            p.name_range.clone(),
                            format!(
                                "option `{}` stops where its region is most robust (`terminate: argmax`, the default), which needs a finite domain, but `{}` is a `float`",
                                p.name, v.name
                            ),
                        )
                        .with_help(format!(
                            "stop on entering the region: `option {} {{ terminate: {} }}`, or `learn {{ preset: auto }}`, which does so",
                            p.name,
                            self.src.get(p.reach.range.clone()).unwrap_or("REGION")
                        )),
                    );
                }
            }
        }
        // The options set.
        let names: Vec<String> = out.primitives.iter().map(|p| p.name.clone()).collect();
        let mut declared: Vec<&str> = names.iter().map(String::as_str).collect();
        declared.sort_unstable();
        let declared_list = some_names(&declared, 10);
        let resolve = |cx: &mut Self, legs: &[syntax::Ident]| -> Option<Vec<usize>> {
            let mut seq: Vec<usize> = Vec::new();
            let mut firsts: HashMap<usize, Range<usize>> = HashMap::new();
            let mut ok = true;
            for leg in legs {
                match by_name.get(&leg.name) {
                    None if cx.broken_names.contains(&leg.name) => ok = false,
                    None => {
                        let mut d = Diagnostic::new(
                            "HSTL011",
                            leg.range.clone(),
                            format!("unknown option `{}`", leg.name),
                        );
                        d = match closest(
                            &leg.name,
                            declared.iter().copied(),
                            &mut cx.suggest_budget,
                        ) {
                            Some(c) => d.with_help(format!("did you mean `{c}`?")),
                            None if declared.is_empty() => {
                                d.with_help(format!("declare it: `option {};`", leg.name))
                            }
                            None => d.with_help(format!("declared options: {declared_list}")),
                        };
                        cx.push(d);
                        ok = false;
                    }
                    Some((i, _)) => {
                        if let Some(first) = firsts.get(i) {
                            cx.push(
                                Diagnostic::new(
                                    "HSTL012",
                                    leg.range.clone(),
                                    format!("option `{}` is repeated", leg.name),
                                )
                                .with_label(first.clone(), "first listed here")
                                .with_help("list each option once"),
                            );
                            ok = false;
                        } else {
                            firsts.insert(*i, leg.range.clone());
                            seq.push(*i);
                        }
                    }
                }
            }
            ok.then_some(seq)
        };
        let mut set: Vec<CombinedOption> = Vec::new();
        let mut set_filled = false;
        let make = |seq: Vec<usize>, range: Range<usize>| CombinedOption {
            name: seq.iter().map(|&i| names[i].as_str()).collect(),
            sequence: seq,
            range,
        };
        match item.map(|i| (&i.kind, i.range.clone())) {
            Some((OptionsKind::List(items), _)) => {
                for s in items {
                    if let Some(seq) = resolve(self, &s.legs) {
                        set.push(make(seq, s.range.clone()));
                    }
                }
            }
            Some((OptionsKind::Sequences(legs), r))
            | Some((OptionsKind::Permutations(legs), r)) => {
                let perm = matches!(item.map(|i| &i.kind), Some(OptionsKind::Permutations(_)));
                if let Some(base) = resolve(self, legs)
                    && self.set_size_ok(base.len(), perm, r.clone())
                {
                    for seq in expand(&base, perm) {
                        set.push(make(seq, r.clone()));
                    }
                }
            }
            None if persistent => {
                // One option per region: with memory the options policy chains them.
                let r = decls.first().map_or(spec.name.range.clone(), |d| d.name.range.clone());
                set_filled = true;
                for i in 0..out.primitives.len() {
                    set.push(make(vec![i], r.clone()));
                }
            }
            None => {
                let base: Vec<usize> = (0..out.primitives.len()).collect();
                let r = decls.first().map_or(spec.name.range.clone(), |d| d.name.range.clone());
                if self.set_size_ok(base.len(), false, r.clone()) {
                    for seq in expand(&base, false) {
                        set.push(make(seq, r.clone()));
                    }
                }
            }
        }
        let mut seen: HashMap<String, Range<usize>> = HashMap::new();
        for o in set {
            if let Some(first) = seen.get(&o.name) {
                self.push(
                    Diagnostic::new("HSTL013", o.range.clone(), format!("two options named `{}`", o.name))
                        .with_label(first.clone(), "the first one comes from here")
                        .with_help("combined options are named by concatenating their legs: rename a primitive option or drop an entry"),
                );
                continue;
            }
            seen.insert(o.name.clone(), o.range.clone());
            out.options.push(o);
        }
        self.add_keep_clear(auto_avoid, &by_name, &seen, out, &mut filled);
        (filled, set_filled)
    }

    /// With `preset: auto` on a task that keeps out of its avoided regions for good, adds
    /// the primitive and option [`crate::preset::KEEP_CLEAR`] (unless the spec uses the name).
    fn add_keep_clear(
        &self,
        avoid: Option<CFormula>,
        primitives: &HashMap<String, (usize, Range<usize>)>,
        options: &HashMap<String, Range<usize>>,
        out: &mut CheckedSpec,
        filled: &mut Vec<[bool; 4]>,
    ) {
        let name = crate::preset::KEEP_CLEAR;
        let Some(avoid) = avoid else { return };
        let taken = primitives.contains_key(name)
            || options.contains_key(name)
            || out.lets.iter().any(|l| l.name == name);
        if taken || out.primitives.is_empty() || !crate::preset::keeps_clear_for_good(out, self.src)
        {
            return;
        }
        // Named where its reason is: the first avoidance for good.
        let range = crate::preset::safety_conjuncts(out)
            .first()
            .map_or(avoid.range.clone(), |c| c.conjunct.range.clone());
        out.primitives.push(PrimitiveOption {
            name: name.to_string(),
            reach: CFormula { kind: CFormulaKind::Not(Box::new(avoid.clone())), range: avoid.range.clone() },
            init: CFormula { kind: CFormulaKind::True, range: range.clone() },
            terminate: Terminate::Argmax,
            avoid: Some(avoid),
            doc: Some("Added by `preset: auto`: once the goals are met, keep clear of the avoided regions.".to_string()),
            name_range: range.clone(),
            range: range.clone(),
        });
        filled.push([false, false, true, true]);
        let leg = out.primitives.len() - 1;
        out.options.push(CombinedOption { name: name.to_string(), sequence: vec![leg], range });
    }

    fn set_size_ok(&mut self, n: usize, perm: bool, range: Range<usize>) -> bool {
        let size = set_size(n, perm);
        if size > MAX_OPTIONS {
            let what = if perm { "permutations" } else { "sequences" };
            self.push(
                Diagnostic::new(
                    "HSTL023",
                    range,
                    format!(
                        "`{what}` of {n} options gives {} options, more than {}",
                        thousands(size),
                        thousands(MAX_OPTIONS)
                    ),
                )
                .with_help("list the sequences you need: `options { A, [A, B], ... }`"),
            );
            return false;
        }
        true
    }

    fn learn(&mut self, l: &syntax::Learn, preset: Preset, out: &mut CheckedSpec) {
        const TOP: [&str; 13] = [
            "preset",
            "episodes",
            "choices",
            "max_steps",
            "memory",
            "intra",
            "reward",
            "counterfactual",
            "switch",
            "plan",
            "flat",
            "options",
            "tiles",
        ];
        if preset == Preset::Auto {
            // The preset first: every value written beside it overrides it.
            let horizons: Option<Vec<u64>> =
                out.persistent_conjuncts(self.src).map(|cs| cs.iter().map(|c| c.steps).collect());
            out.learn.preset = Preset::Auto;
            let reach = crate::preset::is_reach_task(out);
            crate::preset::learn(horizons.as_deref(), reach, out.is_continuous(), &mut out.learn);
            // The memory the preset sizes from the deadlines, made coarser until the runs
            // fit the memory budget without the note of HSTL180.
            // A continuous spec's learned function is counted over the spec's own tile box
            // (the checked spec is the same whatever the world; `check` against a world
            // counts that world's tiles and actions).
            // `note`: above the note of HSTL180 too, not only the budget.
            let over = |out: &CheckedSpec, note: bool| {
                let too_big = |c: crate::budget::Cost| {
                    c.peak().0 > crate::budget::MEMORY_BUDGET
                        || (note && c.own().0 > crate::budget::MEMORY_NOTE)
                };
                if out.is_continuous() {
                    return crate::budget::approx_spec_sizes(self.src, out, None, None)
                        .is_some_and(|s| {
                            crate::budget::approx_weights(&s) > crate::budget::MAX_WEIGHTS
                                || too_big(crate::budget::approx_cost(&s))
                        });
                }
                crate::budget::spec_sizes(self.src, out)
                    .map(|s| crate::budget::cost(&s))
                    .is_some_and(too_big)
            };
            while out.learn.memory > 1 && over(out, true) {
                out.learn.memory -= 1;
            }
            // Past the budget with even one bucket a region (a large world, many regions):
            // no memory, so that the preset never fails the check on its own choice (the
            // window reward still scores the options; `plan: model` needs the memory and is
            // left out).
            if out.learn.memory == 1 && over(out, false) {
                out.learn.memory = 0;
            }
        }
        let mut seen: HashMap<String, Range<usize>> = HashMap::new();
        for p in &l.params {
            let key = p.name.name.as_str();
            if !self.param_name_ok(p, &TOP, &mut seen) {
                continue;
            }
            match key {
                // Read before the options (`preset_of`); checked here.
                "preset" => {
                    self.word(p, &["paper", "auto"]);
                }
                "counterfactual" => {
                    if let Some(v) = self.whole(p, 0) {
                        if v > MAX_COUNTERFACTUAL {
                            self.push(
                                Diagnostic::new(
                                    "HSTL016",
                                    value_range(&p.value),
                                    format!("`counterfactual` must be at most {MAX_COUNTERFACTUAL}, found {v}"),
                                )
                                .with_help("a few memory values per option execution are enough, such as `counterfactual: 8`"),
                            );
                        } else {
                            out.learn.counterfactual = v;
                        }
                    }
                }
                "episodes" | "choices" | "max_steps" | "memory" => {
                    let min = if key == "memory" { 0 } else { 1 };
                    if let Some(v) = self.whole(p, min) {
                        match key {
                            "episodes" => out.learn.episodes = v,
                            "choices" => out.learn.choices = v,
                            "max_steps" => out.learn.max_steps = v,
                            _ => out.learn.memory = v,
                        }
                    }
                }
                "intra" => match self.word(p, &["paper", "remaining"]).as_deref() {
                    Some("paper") => out.learn.intra = Intra::Paper,
                    Some(_) => out.learn.intra = Intra::Remaining,
                    None => {}
                },
                "switch" => match self.word(p, &["termination", "step"]).as_deref() {
                    Some("termination") => out.learn.switch = Switch::Termination,
                    Some(_) => out.learn.switch = Switch::Step,
                    None => {}
                },
                "plan" => match self.word(p, &["off", "model"]).as_deref() {
                    Some("off") => out.learn.plan = Plan::Off,
                    Some(_) => out.learn.plan = Plan::Model,
                    None => {}
                },
                "reward" => match self.word(p, &["segment", "window"]).as_deref() {
                    Some("segment") => out.learn.reward = Reward::Segment,
                    Some(_) => out.learn.reward = Reward::Window,
                    None => {}
                },
                _ => {
                    let ParamValue::Group(ps, _) = &p.value else {
                        self.push(
                            Diagnostic::new(
                                "HSTL016",
                                value_range(&p.value),
                                format!("`{key}` takes a group of parameters"),
                            )
                            .with_help(format!("write `{key}: {{ gamma: 0.9, alpha: 0.5 }}`")),
                        );
                        continue;
                    };
                    if key == "tiles" {
                        let mut t = out.learn.tiles.unwrap_or_default();
                        self.tiles(ps, &mut t);
                        out.learn.tiles = Some(t);
                        continue;
                    }
                    let mut q = if key == "flat" { out.learn.flat } else { out.learn.options };
                    self.qparams(ps, key, &mut q);
                    if key == "flat" { out.learn.flat = q } else { out.learn.options = q }
                }
            }
        }
    }

    /// HSTL071: counterfactual updates replay the memory's counters and the window reward:
    /// they need both.
    fn counterfactual_needs(&mut self, l: &syntax::Learn, out: &CheckedSpec) {
        let learn = &out.learn;
        if learn.counterfactual == 0 || (learn.memory > 0 && learn.reward == Reward::Window) {
            return;
        }
        let Some(p) = l.params.iter().find(|p| p.name.name == "counterfactual") else { return };
        let missing = match (learn.memory > 0, learn.reward == Reward::Window) {
            (false, false) => "`memory` and `reward: window`",
            (false, true) => "`memory`",
            _ => "`reward: window`",
        };
        self.push(
            Diagnostic::new(
                "HSTL071",
                p.range.clone(),
                format!("`counterfactual` needs {missing}"),
            )
            .with_help("counterfactual updates replay the memory's counters along each option's run and score it by the window reward: add `memory: 8, reward: window`, or write `learn { preset: auto }` on a persistent task"),
        );
    }

    /// HSTL072: `plan: model` plans the options level of a persistent task over the
    /// memory's counters, one option per region: a spec of another shape is refused where
    /// it writes `plan: model`, and left to Q-learning where only the preset asked for it.
    fn plan_needs(&mut self, l: &syntax::Learn, out: &mut CheckedSpec) {
        if out.learn.plan != Plan::Model {
            return;
        }
        let Some(missing) = plan_missing(out, self.src) else { return };
        match l.params.iter().find(|p| p.name.name == "plan") {
            Some(p) => self.push(
                Diagnostic::new("HSTL072", p.range.clone(), format!("`plan: model` needs {missing}"))
                    .with_help("planning values the options of a persistent task `always[0..] (eventually[0..N] A && ...)` over the memory's counters: write `learn { preset: auto }` with `option A;` per region, or remove `plan: model`"),
            ),
            None => out.learn.plan = Plan::Off,
        }
    }

    fn param_name_ok(
        &mut self,
        p: &syntax::Param,
        known: &[&str],
        seen: &mut HashMap<String, Range<usize>>,
    ) -> bool {
        let key = p.name.name.as_str();
        if !known.contains(&key) {
            let mut d = Diagnostic::new(
                "HSTL019",
                p.name.range.clone(),
                format!("unknown parameter `{key}`"),
            );
            d = match closest(key, known.iter().copied(), &mut u64::MAX.clone()) {
                Some(c) => d.with_help(format!("did you mean `{c}`?")),
                None => d.with_help(format!("known parameters: {}", known.join(", "))),
            };
            self.push(d);
            return false;
        }
        if let Some(first) = seen.get(key) {
            self.push(
                Diagnostic::new(
                    "HSTL019",
                    p.name.range.clone(),
                    format!("parameter `{key}` given twice"),
                )
                .with_label(first.clone(), "first given here")
                .with_help("give each parameter once"),
            );
            return false;
        }
        seen.insert(key.to_string(), p.name.range.clone());
        true
    }

    fn whole(&mut self, p: &syntax::Param, min: u64) -> Option<u64> {
        let key = &p.name.name;
        let cond = if min == 0 { ">= 0" } else { "> 0" };
        match &p.value {
            ParamValue::Number(n) => match n.as_integer() {
                Some(v) if v >= min => Some(v),
                _ => {
                    self.push(
                        Diagnostic::new(
                            "HSTL016",
                            n.range.clone(),
                            format!("`{key}` must be a whole number {cond}, found `{}`", n.text),
                        )
                        .with_help(format!(
                            "write a whole number {cond}, such as `{}`",
                            min.max(1) * 100
                        )),
                    );
                    None
                }
            },
            v => {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        value_range(v),
                        format!("`{key}` must be a whole number {cond}"),
                    )
                    .with_help(format!("write a number, such as `{key}: {}`", min.max(1) * 100)),
                );
                None
            }
        }
    }

    fn word(&mut self, p: &syntax::Param, allowed: &[&str]) -> Option<String> {
        let key = &p.name.name;
        let options = format!("`{}` or `{}`", allowed[0], allowed[1]);
        match &p.value {
            ParamValue::Word(w) if allowed.contains(&w.name.as_str()) => Some(w.name.clone()),
            v => {
                let mut d = Diagnostic::new(
                    "HSTL016",
                    value_range(v),
                    format!("`{key}` must be {options}, found `{}`", self.text(&value_range(v))),
                );
                d = match v {
                    ParamValue::Word(w) => {
                        match closest(&w.name, allowed.iter().copied(), &mut u64::MAX.clone()) {
                            Some(c) => d.with_help(format!("did you mean `{c}`?")),
                            None => d.with_help(format!("write {options}")),
                        }
                    }
                    _ => d.with_help(format!("write {options}")),
                };
                self.push(d);
                None
            }
        }
    }

    /// `tiles: { tilings: N, bins: N }`.
    fn tiles(&mut self, ps: &[syntax::Param], t: &mut Tiles) {
        const KNOWN: [&str; 2] = ["tilings", "bins"];
        let mut seen: HashMap<String, Range<usize>> = HashMap::new();
        for p in ps {
            if !self.param_name_ok(p, &KNOWN, &mut seen) {
                continue;
            }
            let (key, max) = if p.name.name == "tilings" {
                ("tilings", MAX_TILINGS)
            } else {
                ("bins", MAX_TILE_BINS)
            };
            let Some(v) = self.whole(p, 1) else { continue };
            if v > max {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        value_range(&p.value),
                        format!("`tiles.{key}` must be at most {max}, found {v}"),
                    )
                    .with_help(if key == "tilings" {
                        "8 tilings are the usual choice".to_string()
                    } else {
                        "tiles about one world step wide are the usual choice".to_string()
                    }),
                );
                continue;
            }
            if key == "tilings" {
                t.tilings = v;
            } else {
                t.bins = Some(v);
            }
        }
    }

    fn qparams(&mut self, ps: &[syntax::Param], group: &str, q: &mut QParams) {
        const KNOWN: [&str; 5] = ["gamma", "alpha", "epsilon", "min_epsilon", "decay"];
        let mut seen: HashMap<String, Range<usize>> = HashMap::new();
        let mut ranges: HashMap<&str, Range<usize>> = HashMap::new();
        for p in ps {
            if !self.param_name_ok(p, &KNOWN, &mut seen) {
                continue;
            }
            let key = p.name.name.as_str();
            let ParamValue::Number(n) = &p.value else {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        value_range(&p.value),
                        format!("`{group}.{key}` must be a number"),
                    )
                    .with_help("write a number, such as `0.9`"),
                );
                continue;
            };
            let v = n.value;
            let (ok, cond) = match key {
                "gamma" | "alpha" => (v > 0.0 && v <= 1.0, "in (0, 1]"),
                "epsilon" | "min_epsilon" => ((0.0..=1.0).contains(&v), "in [0, 1]"),
                _ => (v >= 0.0 && v.is_finite(), ">= 0"),
            };
            if !ok {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        n.range.clone(),
                        format!("`{group}.{key}` must be {cond}, found `{}`", n.text),
                    )
                    .with_help(format!("choose a value {cond}")),
                );
                continue;
            }
            let k = KNOWN.iter().copied().find(|k| *k == key).unwrap_or("decay");
            ranges.insert(k, n.range.clone());
            match key {
                "gamma" => q.gamma = v,
                "alpha" => q.alpha = v,
                "epsilon" => q.epsilon = v,
                "min_epsilon" => q.min_epsilon = v,
                _ => q.decay = v,
            }
        }
        if q.min_epsilon > q.epsilon {
            let r = ranges.get("min_epsilon").or(ranges.get("epsilon")).cloned();
            if let Some(r) = r {
                self.push(
                    Diagnostic::new(
                        "HSTL016",
                        r,
                        format!(
                            "`{group}.min_epsilon` ({}) exceeds `{group}.epsilon` ({})",
                            q.min_epsilon, q.epsilon
                        ),
                    )
                    .with_help("0 <= min_epsilon <= epsilon <= 1"),
                );
            }
        }
    }

    /// HSTL170: a safety conjunct `always !R` of the task that no option's `avoid` covers:
    /// the legs' reward never sees it, so nothing below the options level keeps out of `R`.
    fn safety_unseen(&mut self, out: &CheckedSpec) {
        if out.primitives.is_empty() {
            return;
        }
        for c in crate::preset::safety_conjuncts(out) {
            let seen = out.primitives.iter().any(|p| {
                p.avoid.as_ref().is_some_and(|a| crate::preset::covers(a, c.region, self.src))
            });
            if seen {
                continue;
            }
            let name = match c.region.kind {
                CFormulaKind::Let(i) => out.lets.get(i).map_or(String::new(), |l| l.name.clone()),
                _ => self.src.get(c.region.range.clone()).unwrap_or("").trim().to_string(),
            };
            self.push(
                Diagnostic::new(
                    "HSTL170",
                    c.conjunct.range.clone(),
                    format!(
                        "no option's reward sees the safety conjunct: the legs may enter `{name}`"
                    ),
                )
                .with_help(format!(
                    "give the options `avoid: {name}`, or write `learn {{ preset: auto }}`"
                )),
            );
        }
    }

    fn persistent_needs(&mut self, learn: Option<&syntax::Learn>, out: &CheckedSpec) {
        let Some(l) = learn else { return };
        let Some(task) = &out.task else { return };
        if matches!(task.formula.kind, CFormulaKind::Invalid)
            || out.persistent_conjuncts(self.src).is_some()
        {
            return;
        }
        for p in &l.params {
            let needs = match (&p.name.name[..], &p.value) {
                ("memory", ParamValue::Number(n)) => n.as_integer().is_some_and(|v| v > 0),
                ("reward", ParamValue::Word(w)) => w.name == "window",
                _ => false,
            };
            if needs {
                self.push(
                    Diagnostic::new(
                        "HSTL017",
                        p.range.clone(),
                        format!("`{}` needs a persistent task", self.text(&p.range)),
                    )
                    .with_label(task.formula.range.clone(), "this task is not of that form")
                    .with_help("write the task as `always[0..] (eventually[0..N1] R1 && ... && eventually[0..Nk] Rk)` with state formulas Rj"),
                );
            }
        }
    }

    fn mark_used(&mut self, out: &mut CheckedSpec) {
        let mut stack: Vec<usize> = Vec::new();
        let push_refs =
            |f: &CFormula, stack: &mut Vec<usize>| visit_lets(f, &mut |i| stack.push(i));
        if let Some(t) = &out.task {
            push_refs(&t.formula, &mut stack);
        }
        for p in &out.primitives {
            push_refs(&p.reach, &mut stack);
            push_refs(&p.init, &mut stack);
            if let Terminate::Formula(f) = &p.terminate {
                push_refs(f, &mut stack);
            }
            if let Some(f) = &p.avoid {
                push_refs(f, &mut stack);
            }
        }
        while let Some(i) = stack.pop() {
            if let Some(l) = out.lets.get_mut(i)
                && !l.used
            {
                l.used = true;
                let f = l.formula.clone();
                push_refs(&f, &mut stack);
            }
        }
    }

    /// The checks that enumerate the declared `int` domain: empty and full regions,
    /// states where no option can start, and gaps inside sequences.
    // `k` numbers a state and indexes several per-option tables at once.
    #[allow(clippy::needless_range_loop)]
    fn finite_domain(
        &mut self,
        out: &CheckedSpec,
        item: Option<&syntax::OptionsItem>,
        spec: &syntax::Spec,
        mask: Option<&DomainMask>,
        plan_written: bool,
    ) -> bool {
        // Where the domain is not counted, the preset cannot know that planning fits: it
        // Q-learns (a `plan: model` written out is left to the runtime's own limits).
        let preset_plans = out.learn.plan == Plan::Model && !plan_written;
        let Some(size) = out.domain_size() else { return preset_plans };
        if out.state_vars.is_empty() {
            return preset_plans;
        }
        if size > MAX_DOMAIN_STATES {
            let r =
                out.state_vars[0].range.start..out.state_vars[out.state_vars.len() - 1].range.end;
            self.push(
                Diagnostic::new(
                    "HSTL022",
                    r,
                    format!(
                        "the domain has {} states, more than the 1,000,000 the finite-domain checks enumerate; they are skipped",
                        thousands(size)
                    ),
                )
                .with_help("shrink the `int` ranges to get the region and option checks"),
            );
            return preset_plans;
        }
        // Regions: lets an option reaches, and the Rj of a persistent task.
        let mut regions: Vec<(CFormula, Range<usize>, String)> = Vec::new();
        let add_region = |f: &CFormula, regions: &mut Vec<(CFormula, Range<usize>, String)>| {
            if !out.is_state_formula(f) {
                return;
            }
            let (range, name) = match f.kind {
                CFormulaKind::Let(i) => (out.lets[i].name_range.clone(), out.lets[i].name.clone()),
                _ => (f.range.clone(), self.src.get(f.range.clone()).unwrap_or("").to_string()),
            };
            if !regions.iter().any(|(_, r, _)| *r == range) {
                regions.push((f.clone(), range, name));
            }
        };
        for p in &out.primitives {
            add_region(&p.reach, &mut regions);
        }
        // The regions before this index are reached by an option.
        let reached = regions.len();
        // A safety conjunct's `!S` is no region to visit: `S` is checked as written.
        for c in out.persistent_conjuncts(self.src).unwrap_or_default() {
            if !c.safety {
                add_region(&c.region, &mut regions);
            }
        }
        let present = |k: usize| mask.is_none_or(|m| m.present[k]);
        let np = out.primitives.len();
        let mut roots: Vec<&CFormula> = regions.iter().map(|(f, _, _)| f).collect();
        for p in &out.primitives {
            roots.push(&p.reach);
            roots.push(&p.init);
            if let Terminate::Formula(f) = &p.terminate {
                roots.push(f);
            }
            if let Some(f) = &p.avoid {
                roots.push(f);
            }
        }
        let ev = StateEvaluator::new(out, &roots);
        // Bound the time spent: each state evaluates the lets the regions need.
        let work = size.saturating_mul((ev.needed_lets() + roots.len()) as u64);
        if work > MAX_DOMAIN_WORK {
            let r =
                out.state_vars[0].range.start..out.state_vars[out.state_vars.len() - 1].range.end;
            self.push(
                Diagnostic::new(
                    "HSTL022",
                    r,
                    format!(
                        "the finite-domain checks would evaluate {} formulas ({} states, {} lets), more than {}; they are skipped",
                        thousands(work),
                        thousands(size),
                        ev.needed_lets(),
                        thousands(MAX_DOMAIN_WORK)
                    ),
                )
                .with_help("shrink the `int` ranges, or shorten the chains of lets the regions use"),
            );
            return preset_plans;
        }
        let n = size as usize;
        let states = |k: usize| -> Vec<f64> {
            let mut s = vec![0.0; out.state_vars.len()];
            let mut rest = k;
            for (j, v) in out.state_vars.iter().enumerate().rev() {
                if let Domain::Int { lo, hi } = v.domain {
                    let w = (hi - lo + 1) as usize;
                    s[j] = (lo + (rest % w) as i64) as f64;
                    rest /= w;
                }
            }
            s
        };
        // Pass 1: region counts and the maximum robustness of each reach. States are
        // independent: large domains are split into contiguous chunks run on several
        // threads, merged in state order (the same counts, maxima and sets). The preset's
        // choice to plan is made on the map without its walls, so that the macro (which
        // sees no world) and the CLI (which does) choose alike.
        let count_walls = preset_plans && mask.is_some();
        let chunks = over_states(out, &roots, n, work, |ev, ks| {
            let mut region_sat = vec![0u64; regions.len()];
            let mut region_walls = vec![0u64; regions.len()];
            let mut region_reachable = vec![0u64; regions.len()];
            let mut reach_max = vec![f64::NEG_INFINITY; np];
            let mut init_set = vec![Vec::with_capacity(ks.len()); np];
            for k in ks {
                if !present(k) {
                    // A wall: no state, so in no set.
                    init_set.iter_mut().for_each(|set| set.push(false));
                    if count_walls {
                        let s = states(k);
                        ev.load(&s);
                        for (r, (f, _, _)) in regions.iter().enumerate() {
                            region_walls[r] += u64::from(ev.robustness(f, &s) > 0.0);
                        }
                    }
                    continue;
                }
                let s = states(k);
                ev.load(&s);
                let reachable = mask.is_none_or(|m| m.reachable[k]);
                for (r, (f, _, _)) in regions.iter().enumerate() {
                    if ev.robustness(f, &s) > 0.0 {
                        region_sat[r] += 1;
                        region_reachable[r] += u64::from(reachable);
                    }
                }
                for (p, prim) in out.primitives.iter().enumerate() {
                    let v = ev.robustness(&prim.reach, &s);
                    if v > reach_max[p] {
                        reach_max[p] = v;
                    }
                    init_set[p].push(ev.robustness(&prim.init, &s) > 0.0);
                }
            }
            (region_sat, region_walls, region_reachable, reach_max, init_set)
        });
        let mut region_sat = vec![0u64; regions.len()];
        let mut region_walls = vec![0u64; regions.len()];
        let mut region_reachable = vec![0u64; regions.len()];
        let mut reach_max = vec![f64::NEG_INFINITY; np];
        let mut init_set: Vec<Vec<bool>> = vec![Vec::with_capacity(n); np];
        for (sat, walls, reachable, max, init) in chunks {
            for (total, c) in region_sat.iter_mut().zip(sat) {
                *total += c;
            }
            for (total, c) in region_walls.iter_mut().zip(walls) {
                *total += c;
            }
            for (total, c) in region_reachable.iter_mut().zip(reachable) {
                *total += c;
            }
            // Chunks in state order, and only a larger value replaces: the first maximum.
            for (m, v) in reach_max.iter_mut().zip(max) {
                if v > *m {
                    *m = v;
                }
            }
            for (set, part) in init_set.iter_mut().zip(init) {
                set.extend(part);
            }
        }
        let size_without_walls = size;
        let size = match mask {
            Some(m) => m.present.iter().filter(|&&p| p).count() as u64,
            None => size,
        };
        let mut plan_too_large = false;
        if out.learn.plan == Plan::Model
            && let (Some(conjuncts), Some(task)) = (out.persistent_conjuncts(self.src), &out.task)
        {
            let range_of = |f: &CFormula| match f.kind {
                CFormulaKind::Let(i) => out.lets[i].name_range.clone(),
                _ => f.range.clone(),
            };
            // Region cells under walls are counted only for the preset (zero otherwise).
            let cells: Vec<u64> = conjuncts
                .iter()
                .map(|c| {
                    let r = range_of(&c.region);
                    let at = regions.iter().position(|(_, at, _)| *at == r);
                    at.map_or(0, |i| region_sat[i] + region_walls[i])
                })
                .collect();
            let states = if preset_plans { size_without_walls } else { size };
            let horizons: Vec<u64> = conjuncts.iter().map(|c| c.steps).collect();
            let l = &out.learn;
            let options = out.options.len() as u64;
            let exceeded =
                budget::plan_exceeded(states, &cells, &horizons, options, l.memory, l.max_steps);
            if preset_plans {
                // The preset plans only what takes a fraction of a second. The sizes grow
                // with the walls counted in, so what it plans fits the map with them too.
                plan_too_large = exceeded.is_some()
                    || budget::plan_time(states, &cells, &horizons, options, l.memory)
                        > budget::PRESET_PLAN_WORK;
            } else if let Some(why) = exceeded {
                self.push(
                    Diagnostic::new("HSTL033", task.formula.range.clone(), why).with_help(
                        "use smaller or fewer regions, or shorter windows, or write `plan: off` to Q-learn the options level",
                    ),
                );
            }
        }
        let world = self.world.filter(|_| mask.is_some());
        for (r, (_, range, name)) in regions.iter().enumerate() {
            if let Some(world) = world
                && region_sat[r] == 0
            {
                let (code, what) = if r < reached {
                    ("HSTL031", "an option reaches it, so the option cannot succeed")
                } else {
                    ("HSTL102", "the task cannot be kept")
                };
                self.push(
                    Diagnostic::new(
                        code,
                        range.clone(),
                        format!(
                            "no free cell of {} satisfies region `{name}`: {what}",
                            world.label
                        ),
                    )
                    .with_help(
                        "check the bounds against the map: walls are not cells the robot can be in",
                    ),
                );
            } else if let Some(world) = world
                && region_reachable[r] == 0
            {
                self.push(
                    Diagnostic::new(
                        "HSTL131",
                        range.clone(),
                        format!("no start of {} can reach region `{name}`: walls cut it off", world.label),
                    )
                    .with_help("open a way through the walls, add a start cell (`S`) on its side, or move the region"),
                );
            } else if region_sat[r] == 0 {
                self.push(
                    Diagnostic::new(
                        "HSTL102",
                        range.clone(),
                        format!("no state of the domain satisfies region `{name}`"),
                    )
                    .with_help("check the bounds against the `int` ranges (on integers, `3 < x < 4` is empty)"),
                );
            } else if region_sat[r] == size {
                self.push(
                    Diagnostic::new(
                        "HSTL103",
                        range.clone(),
                        format!("every state of the domain satisfies region `{name}`"),
                    )
                    .with_help("tighten the formula: reaching it needs no learning"),
                );
            }
        }
        if out.options.is_empty() {
            return plan_too_large;
        }
        // Pass 2: termination sets.
        // With them, per primitive, the termination states outside its avoided region.
        let chunks = over_states(out, &roots, n, work, |ev, ks| {
            let mut term_set = vec![Vec::with_capacity(ks.len()); np];
            let mut safe_stops = vec![0u64; np];
            for k in ks {
                if !present(k) {
                    term_set.iter_mut().for_each(|set| set.push(false));
                    continue;
                }
                let s = states(k);
                ev.load(&s);
                for (p, prim) in out.primitives.iter().enumerate() {
                    let stops = match &prim.terminate {
                        Terminate::Argmax => ev.robustness(&prim.reach, &s) == reach_max[p],
                        Terminate::Formula(f) => ev.robustness(f, &s) > 0.0,
                    };
                    term_set[p].push(stops);
                    let avoided = prim.avoid.as_ref().is_some_and(|a| ev.robustness(a, &s) >= 0.0);
                    safe_stops[p] += u64::from(stops && !avoided);
                }
            }
            (term_set, safe_stops)
        });
        let mut term_set: Vec<Vec<bool>> = vec![Vec::with_capacity(n); np];
        let mut safe_stops = vec![0u64; np];
        for (chunk, safe) in chunks {
            for (set, part) in term_set.iter_mut().zip(chunk) {
                set.extend(part);
            }
            for (total, c) in safe_stops.iter_mut().zip(safe) {
                *total += c;
            }
        }
        // HSTL070: every state where a leg stops lies in the region it avoids.
        for (p, prim) in out.primitives.iter().enumerate() {
            if let Some(a) = &prim.avoid
                && safe_stops[p] == 0
                && term_set[p].iter().any(|&t| t)
            {
                self.push(
                    Diagnostic::new(
                        "HSTL070",
                        a.range.clone(),
                        format!(
                            "option `{}` avoids every state where it stops: it cannot succeed without entering its `avoid` region",
                            prim.name
                        ),
                    )
                    .with_label(prim.name_range.clone(), format!("`{}` is declared here", prim.name))
                    .with_help("narrow the `avoid` region, or move the option's region out of it"),
                );
            }
        }
        // HSTL032: a termination set with no state (argmax sets never are empty).
        for (p, prim) in out.primitives.iter().enumerate() {
            if let Terminate::Formula(f) = &prim.terminate
                && !term_set[p].iter().any(|&t| t)
            {
                let place = world.map_or("state of the domain".to_string(), |w| {
                    format!("free cell of {}", w.label)
                });
                self.push(
                    Diagnostic::new(
                        "HSTL032",
                        f.range.clone(),
                        format!("option `{}` can never stop: no {place} satisfies its `terminate`", prim.name),
                    )
                    .with_label(prim.name_range.clone(), format!("`{}` is declared here", prim.name))
                    .with_help("widen the `terminate` formula, or leave it out to stop where the region is most robust"),
                );
            }
        }
        // HSTL018: states where no option of the set can start.
        let firsts: Vec<usize> =
            out.options.iter().filter_map(|o| o.sequence.first().copied()).collect();
        let stuck: Vec<usize> =
            (0..n).filter(|&k| present(k) && !firsts.iter().any(|&p| init_set[p][k])).collect();
        if let Some(&k) = stuck.first() {
            let r = item.map_or(spec.name.range.clone(), |i| i.range.clone());
            self.push(
                Diagnostic::new(
                    "HSTL018",
                    r,
                    format!(
                        "no option of the set can start in {}, such as {}",
                        plural(stuck.len() as u64, "state", "states"),
                        state_text(&out.state_vars, &states(k))
                    ),
                )
                .with_help("widen an option's `init`, or add an option that can start there"),
            );
        }
        // HSTL020: a leg that can terminate outside the next leg's initiation set.
        let mut reported: Vec<(usize, usize)> = Vec::new();
        for o in &out.options {
            for w in o.sequence.windows(2) {
                let (a, b) = (w[0], w[1]);
                if reported.contains(&(a, b)) {
                    continue;
                }
                let bad: Vec<usize> =
                    (0..n).filter(|&k| term_set[a][k] && !init_set[b][k]).collect();
                if let Some(&k) = bad.first() {
                    reported.push((a, b));
                    let (pa, pb) = (&out.primitives[a], &out.primitives[b]);
                    self.push(
                        Diagnostic::new(
                            "HSTL020",
                            o.range.clone(),
                            format!(
                                "in `{}`, `{}` can terminate in {} where `{}` cannot start, such as {}",
                                o.name,
                                pa.name,
                                plural(bad.len() as u64, "state", "states"),
                                pb.name,
                                state_text(&out.state_vars, &states(k))
                            ),
                        )
                        .with_label(pa.name_range.clone(), format!("`{}` is declared here", pa.name))
                        .with_label(pb.init.range.clone(), format!("`{}` can start only where this holds", pb.name))
                        .with_help(format!("widen the `init` of `{}` or narrow the `terminate` of `{}`", pb.name, pa.name)),
                    );
                }
            }
        }
        plan_too_large
    }
}

/// `1234567` as `1,234,567`.
/// The largest interval bound of a dense-time spec once scaled by its decimals: 10^18,
/// so that a bound and a sum of two stay far inside `u64` and `usize`.
pub const MAX_TIME_BOUND: u64 = 1_000_000_000_000_000_000;

/// A decimal as written (`2.5`, `10`, `1e-3`): its digits as a whole number and its
/// number of decimals (`(25, 1)`), trailing zeros dropped. `None` for anything else.
fn decimal(text: &str) -> Option<(u128, u32)> {
    let (mantissa, exp) = match text.find(['e', 'E']) {
        Some(k) => (&text[..k], text[k + 1..].parse::<i32>().ok()?),
        None => (text, 0),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    if int.is_empty() || !int.bytes().chain(frac.bytes()).all(|c| c.is_ascii_digit()) {
        return None;
    }
    let frac = frac.trim_end_matches('0');
    let digits = format!("{int}{frac}");
    let digits = digits.trim_start_matches('0');
    if digits.len() > 38 {
        return None;
    }
    let mut n: u128 = if digits.is_empty() { 0 } else { digits.parse().ok()? };
    let mut decimals = i64::try_from(frac.len()).ok()? - i64::from(exp);
    while decimals < 0 {
        n = n.checked_mul(10)?;
        decimals += 1;
    }
    while decimals > 0 && n.is_multiple_of(10) && n != 0 {
        n /= 10;
        decimals -= 1;
    }
    if n == 0 {
        decimals = 0;
    }
    Some((n, u32::try_from(decimals).ok()?))
}

/// The most decimals any interval bound of the spec is written with (at most 18: more
/// are reported as too many digits).
fn time_decimals(spec: &syntax::Spec) -> u32 {
    let mut most = 0;
    let mut stack: Vec<&Formula> = Vec::new();
    for item in &spec.items {
        match item {
            Item::Let(l) => stack.push(&l.formula),
            Item::Task(t) => stack.push(&t.formula),
            _ => {}
        }
    }
    while let Some(f) = stack.pop() {
        let (interval, kids): (Option<&syntax::Interval>, Vec<&Formula>) = match &f.kind {
            FormulaKind::Always(i, g)
            | FormulaKind::Eventually(i, g)
            | FormulaKind::Once(i, g)
            | FormulaKind::Historically(i, g) => (i.as_ref(), vec![g]),
            FormulaKind::Until(a, i, b) | FormulaKind::Since(a, i, b) => (i.as_ref(), vec![a, b]),
            FormulaKind::Not(g)
            | FormulaKind::Paren(g)
            | FormulaKind::Prev(g)
            | FormulaKind::Next(g) => (None, vec![g]),
            FormulaKind::Implies(a, b) => (None, vec![a, b]),
            FormulaKind::And(v) | FormulaKind::Or(v) => (None, v.iter().collect()),
            FormulaKind::True
            | FormulaKind::False
            | FormulaKind::Name(_)
            | FormulaKind::Compare { .. } => (None, Vec::new()),
        };
        if let Some(i) = interval {
            for n in std::iter::once(&i.start).chain(&i.end) {
                if let Some((_, d)) = decimal(&n.text)
                    && d <= 18
                {
                    most = most.max(d);
                }
            }
        }
        stack.extend(kids);
    }
    most
}

/// `n` with a comma between each group of three digits: `33,554,432`.
pub fn thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Where a formula stops being a state formula, and the temporal let it goes through.
type TemporalSite = (Range<usize>, Option<(Range<usize>, String)>);

/// The preset a `learn` item names: `auto` when its first `preset` parameter is `auto`, the
/// paper's otherwise (a bad value is reported where the `learn` item is checked).
fn preset_of(l: &syntax::Learn) -> Preset {
    match l.params.iter().find(|p| p.name.name == "preset").map(|p| &p.value) {
        Some(ParamValue::Word(w)) if w.name == "auto" => Preset::Auto,
        _ => Preset::Paper,
    }
}

fn value_range(v: &ParamValue) -> Range<usize> {
    match v {
        ParamValue::Number(n) => n.range.clone(),
        ParamValue::Word(w) => w.range.clone(),
        ParamValue::Group(_, r) => r.clone(),
    }
}

#[cfg(test)]
thread_local! {
    /// Tests set this to run the finite-domain passes on one thread, for comparison.
    static ONE_THREAD: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether a test asked for one thread.
fn one_thread() -> bool {
    #[cfg(test)]
    let one = ONE_THREAD.with(std::cell::Cell::get);
    #[cfg(not(test))]
    let one = false;
    one
}

/// Work (states times formulas) from which the finite-domain passes use several threads.
const PARALLEL_DOMAIN_WORK: u64 = 100_000;

/// Runs `pass` over the states `0..n` with an evaluator of `roots`: in one piece, or for
/// `work` of at least [`PARALLEL_DOMAIN_WORK`] in contiguous chunks on up to four
/// threads. The results come in state order.
fn over_states<T: Send>(
    out: &CheckedSpec,
    roots: &[&CFormula],
    n: usize,
    work: u64,
    pass: impl Fn(&mut StateEvaluator<'_>, Range<usize>) -> T + Sync,
) -> Vec<T> {
    let run = |ks: Range<usize>| pass(&mut StateEvaluator::new(out, roots), ks);
    // Asking for the core count reads files, so small work never asks.
    if work < PARALLEL_DOMAIN_WORK || one_thread() {
        return vec![run(0..n)];
    }
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get()).min(4);
    if threads < 2 || n < threads {
        return vec![run(0..n)];
    }
    let chunk = n.div_ceil(threads);
    let parts: Vec<Range<usize>> = (0..n).step_by(chunk).map(|a| a..(a + chunk).min(n)).collect();
    std::thread::scope(|scope| {
        let run = &run;
        let handles: Vec<_> = parts[1..]
            .iter()
            .map(|ks| {
                let ks = ks.clone();
                (ks.clone(), std::thread::Builder::new().spawn_scoped(scope, move || run(ks)))
            })
            .collect();
        let mut results = vec![run(parts[0].clone())];
        for (ks, spawned) in handles {
            // A thread that could not start (or failed) leaves its chunk to this one.
            match spawned.ok().and_then(|h| h.join().ok()) {
                Some(r) => results.push(r),
                None => results.push(run(ks)),
            }
        }
        results
    })
}

fn has_temporal_node(f: &CFormula) -> bool {
    match &f.kind {
        kind if kind.is_temporal() => true,
        CFormulaKind::Not(a) => has_temporal_node(a),
        CFormulaKind::And(v) | CFormulaKind::Or(v) => v.iter().any(has_temporal_node),
        CFormulaKind::Implies(a, b) => has_temporal_node(a) || has_temporal_node(b),
        _ => false,
    }
}

/// Lets in an order where each comes after the lets it uses, ties by declaration order;
/// lets not placed (in or behind a cycle) are left out.
fn dependency_order(edges: &[Vec<(usize, Range<usize>)>], placed: &[bool]) -> Vec<usize> {
    let n = edges.len();
    let mut indeg = vec![0usize; n];
    let mut users: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, es) in edges.iter().enumerate() {
        for (j, _) in es {
            indeg[i] += 1;
            users[*j].push(i);
        }
    }
    let mut heap: std::collections::BinaryHeap<std::cmp::Reverse<usize>> =
        (0..n).filter(|&i| indeg[i] == 0 && placed[i]).map(std::cmp::Reverse).collect();
    let mut order = Vec::new();
    while let Some(std::cmp::Reverse(j)) = heap.pop() {
        order.push(j);
        for &i in &users[j] {
            indeg[i] -= 1;
            if indeg[i] == 0 && placed[i] {
                heap.push(std::cmp::Reverse(i));
            }
        }
    }
    order
}

/// Number of options `sequences` (2^n - 1) or `permutations` (sum of n!/(n-k)!) gives,
/// saturating.
fn set_size(n: usize, perm: bool) -> u64 {
    if !perm {
        return if n >= 63 { u64::MAX } else { (1u64 << n) - 1 };
    }
    let mut total: u64 = 0;
    let mut term: u64 = 1;
    for k in 0..n {
        term = term.saturating_mul((n - k) as u64);
        total = total.saturating_add(term);
    }
    total
}

/// Expands `sequences` (subsequences in listed order) or `permutations` (orderings of
/// subsets), by size and then lexicographic order of positions.
pub fn expand(base: &[usize], perm: bool) -> Vec<Vec<usize>> {
    let n = base.len();
    let mut out = Vec::new();
    for size in 1..=n {
        let mut found: Vec<Vec<usize>> = Vec::new();
        let mut cur: Vec<usize> = Vec::new();
        let mut used = vec![false; n];
        gen_positions(n, size, perm, &mut cur, &mut used, &mut found);
        out.extend(found.into_iter().map(|pos| pos.into_iter().map(|p| base[p]).collect()));
    }
    out
}

fn gen_positions(
    n: usize,
    size: usize,
    perm: bool,
    cur: &mut Vec<usize>,
    used: &mut [bool],
    out: &mut Vec<Vec<usize>>,
) {
    if cur.len() == size {
        out.push(cur.clone());
        return;
    }
    let from = if perm { 0 } else { cur.last().map_or(0, |&l| l + 1) };
    for p in from..n {
        if used[p] {
            continue;
        }
        used[p] = true;
        cur.push(p);
        gen_positions(n, size, perm, cur, used, out);
        cur.pop();
        used[p] = false;
    }
}

/// What a spec lacks for `plan: model`, or `None` when it has it all: a persistent task,
/// `memory`, `reward: window`, an options gamma below 1, and an options set of one option
/// per region, each a single leg that stops on entering its region (no `avoid`).
fn plan_missing(out: &CheckedSpec, src: &str) -> Option<&'static str> {
    let Some(regions) = out.persistent_conjuncts(src) else {
        // A reach task: its legs are planned, whatever the options.
        if crate::preset::is_reach_task(out) && !out.is_continuous() {
            return None;
        }
        return Some(
            "a persistent task `always[0..] (eventually[0..N] A && ...)` or a reach task \
             `eventually[0..T] G && always !R`",
        );
    };
    if regions.iter().any(|r| r.safety) {
        return Some("a task without safety conjuncts `always !R` (the legs avoid them instead)");
    }
    let l = &out.learn;
    if l.memory == 0 {
        return Some("`memory`");
    }
    if l.reward != Reward::Window {
        return Some("`reward: window`");
    }
    if l.options.gamma >= 1.0 {
        return Some("an options gamma below 1");
    }
    let enters_a_region = |o: &CombinedOption| -> bool {
        let [p] = o.sequence.as_slice() else { return false };
        let Some(p) = out.primitives.get(*p) else { return false };
        let Terminate::Formula(t) = &p.terminate else { return false };
        p.avoid.is_none() && regions.iter().any(|r| crate::preset::covers(t, &r.region, src))
    };
    if out.options.is_empty() || !out.options.iter().all(enters_a_region) {
        return Some("options of one leg each that stop on entering a region of the task");
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fixtures whose finite-domain checks report something, with their domains widened
    /// so that the passes run on several threads: the same diagnostics as on one thread.
    #[test]
    fn domain_passes_on_threads_match_one_thread() {
        let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures");
        for name in [
            "invalid/HSTL020_sequence_gap.hstl",
            "invalid/HSTL018_no_option_can_start.hstl",
            "invalid/HSTL102_empty_region.hstl",
            "invalid/HSTL103_full_region.hstl",
            "valid/case_study_ot1.hstl",
        ] {
            let text = std::fs::read_to_string(format!("{dir}/{name}")).unwrap_or_default();
            assert!(text.contains("0..=14") || text.contains("0..=9"), "{name}");
            let wide = text.replace("0..=14", "0..=239").replace("0..=9", "0..=239");
            let threads = check(&wide);
            ONE_THREAD.with(|c| c.set(true));
            let one = check(&wide);
            ONE_THREAD.with(|c| c.set(false));
            assert_eq!(format!("{:?}", threads.diagnostics), format!("{:?}", one.diagnostics));
            assert_eq!(format!("{:?}", threads.specs), format!("{:?}", one.specs));
            if name.starts_with("invalid") {
                let code = &name[8..15];
                assert!(
                    threads.diagnostics.iter().any(|d| d.code == code),
                    "{name}: {:?}",
                    threads.diagnostics
                );
            }
        }
    }

    #[test]
    fn did_you_mean_counts_swaps_and_stays_bounded() {
        let unlimited = || u64::MAX;
        let params = ["alpha", "decay", "epsilon", "gamma", "min_epsilon"];
        let suggest = |name: &str| closest(name, params.iter().copied(), &mut unlimited());
        assert_eq!(suggest("gama"), Some("gamma"));
        assert_eq!(suggest("alpah"), Some("alpha"), "a swap of two neighbours costs one");
        assert_eq!(suggest("epsilno"), Some("epsilon"));
        assert_eq!(suggest("zzz"), None);
        // Too long to compare, and no budget: no suggestion, no work.
        let long = "a".repeat(100_000);
        assert_eq!(closest(&long, [long.as_str()].into_iter(), &mut unlimited()), None);
        assert_eq!(closest("gama", params.iter().copied(), &mut 0), None);
        // A search the budget cannot finish suggests nothing rather than a worse name.
        assert_eq!(closest("gama", params.iter().copied(), &mut 2), None);
        let mut budget = 1_000;
        assert_eq!(closest("gama", params.iter().copied(), &mut budget), Some("gamma"));
        assert!(budget < 1_000, "the search was charged");
    }
}
