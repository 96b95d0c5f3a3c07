//! What the server answers, computed from one [`Analysis`] of a document: diagnostics,
//! hover, definition, references, document symbols, completion and formatting.

use std::cell::OnceCell;
use std::collections::HashSet;
use std::ops::Range;
use std::path::Path;

use hstl::lang::check::MAX_DOMAIN_STATES;
use hstl::lang::syntax::{
    self, CmpOp, Expr, ExprKind, FieldValue, Formula, FormulaKind, Interval, Item, OptionsKind,
    Spec,
};
use hstl::lang::{CheckedSpec, Domain, LetKind, Severity, StateEvaluator};
use lsp_types::{
    CompletionItem, CompletionItemKind, DiagnosticRelatedInformation, DiagnosticSeverity,
    DocumentSymbol, Hover, HoverContents, Location, MarkupContent, MarkupKind, NumberOrString,
    Position, SymbolKind, TextEdit, Uri,
};

use super::convert::{Converter, Encoding};
use super::worlds::{DocWorlds, WorldCache};

/// What a name refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SymKind {
    /// A state variable.
    Var,
    /// A `let`.
    Let,
    /// A primitive option.
    Option,
}

/// A name of one spec.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Symbol {
    /// Index of the spec in the syntax tree.
    pub spec: usize,
    /// What it names.
    pub kind: SymKind,
    /// The name.
    pub name: String,
}

/// One place where a name is written.
#[derive(Clone, Debug)]
pub struct Occurrence {
    /// Byte range of the name.
    pub range: Range<usize>,
    /// What it refers to.
    pub symbol: Symbol,
    /// Whether this is where it is declared.
    pub decl: bool,
}

/// Parts of a previous analysis, to be dropped once the server has answered.
pub struct Leftovers {
    _parts: Box<dyn std::any::Any>,
}

/// Everything the server knows about one version of a document.
pub struct Analysis {
    /// The text.
    pub text: String,
    /// Parse and check results.
    pub checked: hstl::lang::Checked,
    /// The parser's diagnostics (with `checked.file`, the parse that the next version
    /// re-parses incrementally).
    pub parse_diagnostics: Vec<hstl::lang::Diagnostic>,
    /// Every name occurrence, sorted by start; built on the first request that needs it
    /// (a keystroke only needs the diagnostics).
    occurrences: OnceCell<Vec<Occurrence>>,
    /// Position conversion for this text.
    pub conv: Converter,
    /// The worlds the specs name, as they were checked against.
    pub worlds: DocWorlds,
}

impl Analysis {
    /// Checks `text` and indexes its names.
    pub fn new(
        text: String,
        enc: Encoding,
        worlds: &mut WorldCache,
        folder: Option<&Path>,
    ) -> Self {
        let parsed = hstl::lang::parse(&text);
        Self::from_parsed(text, parsed, enc, worlds, folder)
    }

    /// The analysis of a new version of the text of `prev`: only the items around the
    /// change are parsed again (see `hstl_lang::incremental`), then the whole is checked.
    ///
    /// Also returns what is left of `prev` (the old text and checked specs), so that the
    /// caller can free it after answering rather than before.
    pub fn update(
        prev: Analysis,
        text: String,
        enc: Encoding,
        worlds: &mut WorldCache,
        folder: Option<&Path>,
    ) -> (Self, Leftovers) {
        let Analysis { text: old, checked, parse_diagnostics, occurrences, .. } = prev;
        let hstl::lang::Checked { file, specs, diagnostics } = checked;
        let prev = hstl::lang::Parsed { file, diagnostics: parse_diagnostics };
        let (parsed, _) = hstl::lang::incremental::reparse(prev, &old, &text);
        let next = Self::from_parsed(text, parsed, enc, worlds, folder);
        (next, Leftovers { _parts: Box::new((old, specs, diagnostics, occurrences)) })
    }

    /// The whole analysis, to be dropped later.
    pub fn into_leftovers(self) -> Leftovers {
        Leftovers { _parts: Box::new(self) }
    }

    fn from_parsed(
        text: String,
        parsed: hstl::lang::Parsed,
        enc: Encoding,
        cache: &mut WorldCache,
        folder: Option<&Path>,
    ) -> Self {
        let parse_diagnostics = parsed.diagnostics.clone();
        // The same diagnostics as `hstlc check`: each spec against the world it names.
        let worlds = cache.resolve(&parsed, folder);
        let checked =
            hstl::lang::check_parsed_with_worlds(&text, parsed, &|spec| worlds.lookup(spec));
        let conv = Converter::new(&text, enc);
        Analysis { text, checked, parse_diagnostics, occurrences: OnceCell::new(), conv, worlds }
    }

    /// Every name occurrence, sorted by start.
    pub fn occurrences(&self) -> &[Occurrence] {
        self.occurrences.get_or_init(|| {
            let mut occurrences = Vec::new();
            for (i, spec) in self.checked.file.specs.iter().enumerate() {
                index_spec(i, spec, &mut occurrences);
            }
            occurrences.sort_by_key(|o| (o.range.start, !o.decl));
            occurrences
        })
    }

    fn occurrences_at(&self, offset: usize) -> impl Iterator<Item = &Occurrence> {
        let all = self.occurrences();
        let first = all.partition_point(|o| o.range.end < offset);
        all[first..]
            .iter()
            .take_while(move |o| o.range.start <= offset)
            .filter(move |o| o.range.start <= offset && offset <= o.range.end)
    }

    /// The declaration of a symbol (its first one).
    fn declaration(&self, symbol: &Symbol) -> Option<&Occurrence> {
        self.occurrences().iter().find(|o| o.decl && &o.symbol == symbol)
    }

    /// The checked spec of syntax spec `i`.
    fn checked_spec(&self, i: usize) -> Option<&CheckedSpec> {
        let spec = self.checked.file.specs.get(i)?;
        self.checked.specs.iter().find(|c| c.name_range == spec.name.range && !c.name.is_empty())
    }

    /// The symbol the cursor is on: for a name that is both an option's declaration and
    /// a reference to the `let` it reaches (`option A;`), the `let`.
    fn symbol_at(&self, offset: usize) -> Option<&Occurrence> {
        let all: Vec<&Occurrence> = self.occurrences_at(offset).collect();
        all.iter().find(|o| !o.decl).or(all.first()).copied()
    }
}

/// Records the names of one spec.
fn index_spec(spec_i: usize, spec: &Spec, out: &mut Vec<Occurrence>) {
    let mut vars = HashSet::new();
    let mut lets = HashSet::new();
    for item in &spec.items {
        match item {
            Item::State(b) => vars.extend(b.vars.iter().map(|v| v.name.name.as_str())),
            Item::Let(l) => {
                lets.insert(l.name.name.as_str());
            }
            _ => {}
        }
    }
    let sym = |kind, name: &str| Symbol { spec: spec_i, kind, name: name.to_string() };
    let mut push = |range: Range<usize>, kind, name: &str, decl| {
        out.push(Occurrence { range, symbol: sym(kind, name), decl });
    };
    // A name in formula position names a let; in expression position a variable. Either
    // falls back to the other namespace, which they share, so that navigation still
    // works on a spec with a kind error.
    let resolve = |name: &str, formula: bool| {
        let (is_let, is_var) = (lets.contains(name), vars.contains(name));
        match (formula, is_let, is_var) {
            (true, true, _) | (false, true, false) => Some(SymKind::Let),
            (_, _, true) => Some(SymKind::Var),
            _ => None,
        }
    };
    let mut names: Vec<(Range<usize>, String, bool)> = Vec::new();
    for item in &spec.items {
        match item {
            Item::State(b) => {
                for v in &b.vars {
                    push(v.name.range.clone(), SymKind::Var, &v.name.name, true);
                }
            }
            Item::Let(l) => {
                push(l.name.range.clone(), SymKind::Let, &l.name.name, true);
                formula_names(&l.formula, &mut names);
            }
            Item::Task(t) => formula_names(&t.formula, &mut names),
            Item::Option(o) => {
                push(o.name.range.clone(), SymKind::Option, &o.name.name, true);
                match &o.fields {
                    // `option A;` reaches the let `A`.
                    None if lets.contains(o.name.name.as_str()) => {
                        push(o.name.range.clone(), SymKind::Let, &o.name.name, false);
                    }
                    None => {}
                    Some(fields) => {
                        for f in fields {
                            if let FieldValue::Formula(g) = &f.value {
                                formula_names(g, &mut names);
                            }
                        }
                    }
                }
            }
            Item::Options(o) => {
                let idents: Vec<&syntax::Ident> = match &o.kind {
                    OptionsKind::List(seqs) => seqs.iter().flat_map(|s| &s.legs).collect(),
                    OptionsKind::Sequences(v) | OptionsKind::Permutations(v) => v.iter().collect(),
                };
                for id in idents {
                    push(id.range.clone(), SymKind::Option, &id.name, false);
                }
            }
            Item::Learn(_) | Item::World(_) => {}
        }
    }
    for (range, name, formula) in names {
        if let Some(kind) = resolve(&name, formula) {
            push(range, kind, &name, false);
        }
    }
}

/// Every name in a formula: `(range, name, in formula position)`, in source order. The
/// walk keeps its own stack, so a tall tree cannot overflow the thread's.
fn formula_names(f: &Formula, out: &mut Vec<(Range<usize>, String, bool)>) {
    enum Node<'a> {
        Formula(&'a Formula),
        Expr(&'a Expr),
    }
    let mut stack = vec![Node::Formula(f)];
    // Children are pushed last first, so that they are visited in source order.
    while let Some(node) = stack.pop() {
        match node {
            Node::Formula(f) => match &f.kind {
                FormulaKind::Name(id) => out.push((id.range.clone(), id.name.clone(), true)),
                FormulaKind::Compare { first, rest } => {
                    stack.extend(rest.iter().rev().map(|(_, _, e)| Node::Expr(e)));
                    stack.push(Node::Expr(first));
                }
                _ => stack.extend(f.operands().into_iter().rev().map(Node::Formula)),
            },
            Node::Expr(e) => match &e.kind {
                ExprKind::Number(_) => {}
                ExprKind::Name(id) => out.push((id.range.clone(), id.name.clone(), false)),
                ExprKind::Neg(a) | ExprKind::Call(_, a) | ExprKind::Paren(a) => {
                    stack.push(Node::Expr(a));
                }
                ExprKind::Binary(_, a, b) => {
                    stack.push(Node::Expr(b));
                    stack.push(Node::Expr(a));
                }
            },
        }
    }
}

/// The diagnostics of `hstlc check`, converted: code, severity, help appended to the
/// message, labels as related information.
pub fn diagnostics(a: &Analysis, uri: &Uri) -> Vec<lsp_types::Diagnostic> {
    a.checked
        .diagnostics
        .iter()
        .map(|d| {
            let related: Vec<DiagnosticRelatedInformation> = d
                .labels
                .iter()
                .map(|l| DiagnosticRelatedInformation {
                    location: Location { uri: uri.clone(), range: a.conv.range(&a.text, &l.range) },
                    message: l.message.clone(),
                })
                .collect();
            let message = match &d.help {
                Some(help) => format!("{}\nhelp: {help}", d.message),
                None => d.message.clone(),
            };
            lsp_types::Diagnostic {
                range: a.conv.range(&a.text, &d.range),
                severity: Some(match d.severity {
                    Severity::Error => DiagnosticSeverity::ERROR,
                    Severity::Warning => DiagnosticSeverity::WARNING,
                }),
                code: Some(NumberOrString::String(d.code.to_string())),
                source: Some("hstlc".to_string()),
                message,
                related_information: (!related.is_empty()).then_some(related),
                ..lsp_types::Diagnostic::default()
            }
        })
        .collect()
}

/// Hover text: for a name, what it is; for an operator, its robustness meaning and its
/// interval in words.
pub fn hover(a: &Analysis, pos: Position) -> Option<Hover> {
    let offset = a.conv.offset(&a.text, pos);
    // On `option A;` the name is both the option and the let it reaches: the option's
    // hover, which names the let, is what the line is about.
    let option = a.occurrences_at(offset).find(|o| o.symbol.kind == SymKind::Option);
    let (range, text) = match option.or_else(|| a.symbol_at(offset)) {
        Some(o) => (o.range.clone(), symbol_hover(a, &o.symbol)?),
        None => match preset_hover(a, offset).or_else(|| world_hover(a, offset)) {
            Some(found) => found,
            None => operator_hover(a, offset)?,
        },
    };
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent { kind: MarkupKind::Markdown, value: text }),
        range: Some(a.conv.range(&a.text, &range)),
    })
}

/// The `world` item whose string holds `offset`, quotes included.
fn world_at(a: &Analysis, offset: usize) -> Option<&syntax::WorldItem> {
    a.checked.file.specs.iter().flat_map(|s| &s.items).find_map(|i| match i {
        Item::World(w) if w.name_range.start <= offset && offset <= w.name_range.end => Some(w),
        _ => None,
    })
}

/// On a `world` item's string: the world it names (its size and slip), or why it cannot be
/// had.
fn world_hover(a: &Analysis, offset: usize) -> Option<(Range<usize>, String)> {
    let item = world_at(a, offset)?;
    let resolved = a.worlds.get(&item.name)?;
    let text = match resolved.world.as_ref() {
        Ok((_, words)) => format!(
            "**{words}**: the world this spec is written for; `hstlc check`, `train` and \
             `study` use it (`--world` overrides it)"
        ),
        Err(problem) => format!("**world unavailable**: {}", problem.message),
    };
    Some((item.name_range.clone(), text))
}

/// On `preset` in a `learn` item (its name or its value): what the preset sets, and for
/// `auto` what it expanded to in this spec.
fn preset_hover(a: &Analysis, offset: usize) -> Option<(Range<usize>, String)> {
    for (i, spec) in a.checked.file.specs.iter().enumerate() {
        for item in &spec.items {
            let Item::Learn(l) = item else { continue };
            let Some(p) = l.params.iter().find(|p| {
                p.name.name == "preset" && p.range.start <= offset && offset <= p.range.end
            }) else {
                continue;
            };
            let text = match a.checked_spec(i).and_then(|c| c.preset_expansion.as_ref()) {
                Some(e) => format!(
                    "**preset: auto**: the recommended settings for this task's form; values \
                     written beside it override them. Here it stands for:\n```hstl\n{e}\n```"
                ),
                None => "**preset: paper** (the default): the paper's settings, Table II of \
                         Li & Belta (2016); `preset: auto` fills in the recommended ones for the \
                         task's form"
                    .to_string(),
            };
            return Some((p.range.clone(), text));
        }
    }
    None
}

fn snippet(text: &str, r: &Range<usize>) -> String {
    text.get(r.clone()).unwrap_or("").split_whitespace().collect::<Vec<_>>().join(" ")
}

fn symbol_hover(a: &Analysis, s: &Symbol) -> Option<String> {
    let spec = a.checked.file.specs.get(s.spec)?;
    let checked = a.checked_spec(s.spec);
    let mut out = String::new();
    match s.kind {
        SymKind::Var => {
            let v = spec.items.iter().find_map(|i| match i {
                Item::State(b) => b.vars.iter().find(|v| v.name.name == s.name),
                _ => None,
            })?;
            let start = v.name.range.start;
            let what = if v.ty == syntax::VarType::Time {
                "time variable (dense time): its trace column holds the time stamps, strictly \
                 increasing; the other variables hold each sample until their next one, and \
                 the intervals are in this column's unit. No formula reads it."
            } else {
                "state variable"
            };
            out.push_str(&format!(
                "```hstl\n{}\n```\n{what}",
                snippet(&a.text, &(start..v.range.end))
            ));
            if let Some(d) = &v.doc {
                out.push_str(&format!("\n\n{}", d.text()));
            }
        }
        SymKind::Let => {
            let l = spec.items.iter().find_map(|i| match i {
                Item::Let(l) if l.name.name == s.name => Some(l),
                _ => None,
            })?;
            out.push_str(&format!(
                "```hstl\nlet {} = {};\n```\n",
                l.name.name,
                snippet(&a.text, &l.formula.range)
            ));
            let info = checked.and_then(|c| c.lets.iter().find(|i| i.name == s.name));
            if let (Some(c), Some(info)) = (checked, info) {
                match info.kind {
                    LetKind::State => out.push_str("state formula (a region)"),
                    LetKind::Temporal => out.push_str("temporal formula"),
                }
                if !info.used {
                    out.push_str(", not used by the task or an option");
                }
                if info.kind == LetKind::State {
                    match count_states(c, &info.formula) {
                        Some(Ok((n, total))) => out.push_str(&format!(
                            "\n\nholds (robustness > 0) in {n} of the {total} states of the declared domain"
                        )),
                        Some(Err(total)) => out.push_str(&format!(
                            "\n\nthe declared domain has {total} states: too many to count where it holds"
                        )),
                        None => {}
                    }
                }
            }
            if let Some(d) = &l.doc {
                out.push_str(&format!("\n\n{}", d.text()));
            }
        }
        SymKind::Option => {
            let o = spec.items.iter().find_map(|i| match i {
                Item::Option(o) if o.name.name == s.name => Some(o),
                _ => None,
            })?;
            out.push_str(&format!("**option {}** (primitive)\n", o.name.name));
            let field = |name: &str| {
                o.fields.as_ref().and_then(|fs| fs.iter().find(|f| f.name.name == name)).map(|f| {
                    match &f.value {
                        FieldValue::Argmax(_) => "argmax".to_string(),
                        FieldValue::Formula(g) => snippet(&a.text, &g.range),
                    }
                })
            };
            let reach = field("reach").unwrap_or_else(|| o.name.name.clone());
            if o.fields.is_none()
                && let Some(l) = spec.items.iter().find_map(|i| match i {
                    Item::Let(l) if l.name.name == o.name.name => Some(l),
                    _ => None,
                })
            {
                out.push_str(&format!(
                    "```hstl\nlet {} = {};\n```\n",
                    l.name.name,
                    snippet(&a.text, &l.formula.range)
                ));
            }
            out.push_str(&format!(
                "- reach: `{reach}` (flat reward: its robustness after each step)\n"
            ));
            // What `preset: auto` filled in, where the option leaves a field out.
            let prim = checked.and_then(|c| c.primitives.iter().find(|p| p.name == s.name));
            let filled_init = prim.is_some_and(|p| {
                matches!(p.init.kind, hstl::lang::CFormulaKind::Not(_)) && field("init").is_none()
            });
            let filled_term = prim.is_some_and(|p| {
                matches!(p.terminate, hstl::lang::Terminate::Formula(_))
                    && field("terminate").is_none()
            });
            match field("init") {
                Some(init) => out.push_str(&format!("- init: `{init}`\n")),
                None if filled_init => out.push_str(&format!(
                    "- init: `!{reach}` (from `preset: auto`: not chosen inside its region)\n"
                )),
                None => out.push_str("- init: `true` (default: may start anywhere)\n"),
            }
            match field("terminate") {
                Some(t) if t != "argmax" => out.push_str(&format!("- terminate: `{t}`\n")),
                None if filled_term => out.push_str(&format!(
                    "- terminate: `{reach}` (from `preset: auto`: stops on entering its region)\n"
                )),
                _ => out.push_str(&format!(
                    "- terminate: `argmax` (where the robustness of `{reach}` is largest over the declared domain)\n"
                )),
            }
            if let Some(c) = checked
                && let Some(p) = c.primitives.iter().position(|p| p.name == s.name)
            {
                if let Some(avoid) = &c.primitives[p].avoid {
                    let text = match field("avoid") {
                        Some(t) => t,
                        None => match &avoid.kind {
                            hstl::lang::CFormulaKind::Let(k) => {
                                c.lets.get(*k).map_or(String::new(), |l| l.name.clone())
                            }
                            _ => "the task's avoided regions (`preset: auto`)".to_string(),
                        },
                    };
                    out.push_str(&format!(
                        "- avoid: `{text}` (the leg's reward also sees its robustness, and the leg stops on entering it)\n"
                    ));
                }
                let seqs: Vec<String> = c
                    .options
                    .iter()
                    .filter(|o| o.sequence.contains(&p))
                    .map(|o| {
                        let legs: Vec<&str> = o
                            .sequence
                            .iter()
                            .filter_map(|&k| c.primitives.get(k))
                            .map(|p| p.name.as_str())
                            .collect();
                        format!("`[{}]`", legs.join(", "))
                    })
                    .collect();
                if seqs.is_empty() {
                    out.push_str("- in no sequence of the options set\n");
                } else {
                    out.push_str(&format!(
                        "- sequences of the options set with it: {}\n",
                        seqs.join(", ")
                    ));
                }
            }
            if let Some(d) = &o.doc {
                out.push_str(&format!("\n{}", d.text()));
            }
        }
    }
    Some(out)
}

/// `(states where f has robustness > 0, states of the domain)`; `Err(total)` when the
/// domain is too large to enumerate; `None` without a finite `int` domain or when `f`
/// cannot be evaluated.
fn count_states(spec: &CheckedSpec, f: &hstl::lang::CFormula) -> Option<Result<(u64, u64), u64>> {
    let total = spec.domain_size()?;
    if total > MAX_DOMAIN_STATES {
        return Some(Err(total));
    }
    if !spec.is_state_formula(f) {
        return None;
    }
    let bounds: Vec<(i64, i64)> = spec
        .state_vars
        .iter()
        .map(|v| match v.domain {
            Domain::Int { lo, hi } => Some((lo, hi)),
            _ => None,
        })
        .collect::<Option<_>>()?;
    let mut ev = StateEvaluator::new(spec, &[f]);
    let mut values: Vec<i64> = bounds.iter().map(|b| b.0).collect();
    let mut s: Vec<f64> = values.iter().map(|&v| v as f64).collect();
    let mut n = 0;
    for _ in 0..total {
        ev.load(&s);
        let r = ev.robustness(f, &s);
        if r.is_nan() {
            return None;
        }
        n += u64::from(r > 0.0);
        // Next valuation, last variable fastest.
        for k in (0..values.len()).rev() {
            if values[k] < bounds[k].1 {
                values[k] += 1;
                s[k] = values[k] as f64;
                break;
            }
            values[k] = bounds[k].0;
            s[k] = values[k] as f64;
        }
    }
    Some(Ok((n, total)))
}

/// The operator whose token(s) cover `offset`, with its hover text.
fn operator_hover(a: &Analysis, offset: usize) -> Option<(Range<usize>, String)> {
    let mut found = None;
    for spec in &a.checked.file.specs {
        let dense = is_dense(spec);
        for item in &spec.items {
            let mut formulas: Vec<&Formula> = Vec::new();
            match item {
                Item::Let(l) => formulas.push(&l.formula),
                Item::Task(t) => formulas.push(&t.formula),
                Item::Option(o) => {
                    for f in o.fields.iter().flatten() {
                        if let FieldValue::Formula(g) = &f.value {
                            formulas.push(g);
                        }
                    }
                }
                _ => {}
            }
            for f in formulas {
                if found.is_none() {
                    found = find_operator(&a.text, f, offset, dense);
                }
            }
        }
    }
    found
}

/// The first operator, in a pre-order walk of `root`, whose token(s) cover `at`. The walk
/// keeps its own stack, so a tall tree cannot overflow the thread's.
fn find_operator(
    text: &str,
    root: &Formula,
    at: usize,
    dense: bool,
) -> Option<(Range<usize>, String)> {
    let mut stack = vec![root];
    while let Some(f) = stack.pop() {
        if at < f.range.start || at > f.range.end {
            continue;
        }
        if let Some(found) = operator_of(text, f, at, dense, &mut stack) {
            return Some(found);
        }
    }
    None
}

/// The operator of `f` itself when its token(s) cover `at`; otherwise pushes the
/// operands onto `stack`, last first.
fn operator_of<'a>(
    text: &str,
    f: &'a Formula,
    at: usize,
    dense: bool,
    stack: &mut Vec<&'a Formula>,
) -> Option<(Range<usize>, String)> {
    let kw_end = |start: usize, kw: &str| start + kw.len();
    let hit = |r: &Range<usize>| r.start <= at && at <= r.end;
    match &f.kind {
        FormulaKind::Always(iv, g)
        | FormulaKind::Eventually(iv, g)
        | FormulaKind::Once(iv, g)
        | FormulaKind::Historically(iv, g) => {
            let (kw, meaning, past) = match f.kind {
                FormulaKind::Always(..) => (
                    "always",
                    "the minimum of the operand's robustness over the window (`+inf` if the window is empty): positive when the operand holds at every step of it",
                    false,
                ),
                FormulaKind::Eventually(..) => (
                    "eventually",
                    "the maximum of the operand's robustness over the window (`-inf` if the window is empty): positive when the operand holds at some step of it",
                    false,
                ),
                FormulaKind::Once(..) => (
                    "once",
                    "the maximum of the operand's robustness over the past window (`-inf` if the window is empty): positive when the operand held at some step of it",
                    true,
                ),
                _ => (
                    "historically",
                    "the minimum of the operand's robustness over the past window (`+inf` if the window is empty): positive when the operand held at every step of it",
                    true,
                ),
            };
            let span =
                f.range.start..iv.as_ref().map_or(kw_end(f.range.start, kw), |i| i.range.end);
            if hit(&span) {
                return Some((
                    span,
                    format!("**{kw}**: {meaning}.\n\n{}", window_words(iv.as_ref(), past, dense)),
                ));
            }
            stack.push(g);
        }
        FormulaKind::Prev(g) | FormulaKind::Next(g) => {
            let prev = matches!(f.kind, FormulaKind::Prev(_));
            let kw = if prev { "prev" } else { "next" };
            let span = f.range.start..kw_end(f.range.start, kw);
            if hit(&span) {
                let meaning = if prev {
                    "**prev**: the operand's robustness one step back; `+inf` at the first step of the trace, which has none (so `prev f` holds there). The same as `historically[1..=1] f`."
                } else {
                    "**next**: the operand's robustness one step ahead; `+inf` at the last step of the trace, which has none (so `next f` holds there). The same as `always[1..=1] f`."
                };
                return Some((span, meaning.to_string()));
            }
            stack.push(g);
        }
        FormulaKind::Until(l, iv, r) | FormulaKind::Since(l, iv, r) => {
            let since = matches!(f.kind, FormulaKind::Since(..));
            let kw = if since { "since" } else { "until" };
            let span = l.range.end..r.range.start;
            if hit(&span) && text.get(span.clone()).is_some_and(|s| s.contains(kw)) {
                let start = span.start + text[span.clone()].find(kw).unwrap_or(0);
                let end = iv.as_ref().map_or(start + kw.len(), |i| i.range.end);
                let meaning = if since {
                    "**since**: `f since[I] g` is the maximum, over the steps `t'` of the past window, of the minimum of `g`'s robustness at `t'` and `f`'s robustness at every step after `t'` up to and including now: positive when `g` held at some step of the window and `f` has held ever since."
                } else {
                    "**until**: `f until[I] g` is the maximum, over the steps `t'` of the window, of the minimum of `g`'s robustness at `t'` and `f`'s robustness at every step from now up to (not including) `t'`: positive when `g` holds at some step of the window and `f` holds until then."
                };
                return Some((
                    start..end,
                    format!("{meaning}\n\n{}", window_words(iv.as_ref(), since, dense)),
                ));
            }
            stack.push(r);
            stack.push(l);
        }
        FormulaKind::And(v) | FormulaKind::Or(v) => {
            let and = matches!(f.kind, FormulaKind::And(_));
            for w in v.windows(2) {
                let span = w[0].range.end..w[1].range.start;
                if hit(&span) {
                    let op = if and { "&&" } else { "||" };
                    let start =
                        span.start + text.get(span.clone()).and_then(|s| s.find(op)).unwrap_or(0);
                    let meaning = if and {
                        "**&&** (and): the minimum of the operands' robustness: positive when every operand holds."
                    } else {
                        "**||** (or): the maximum of the operands' robustness: positive when some operand holds."
                    };
                    return Some((start..start + 2, meaning.to_string()));
                }
            }
            stack.extend(v.iter().rev());
        }
        FormulaKind::Implies(l, r) => {
            let span = l.range.end..r.range.start;
            if hit(&span) {
                let start =
                    span.start + text.get(span.clone()).and_then(|s| s.find("->")).unwrap_or(0);
                return Some((
                    start..start + 2,
                    "**->** (implies): `f -> g` is `!f || g`: the maximum of minus `f`'s robustness and `g`'s robustness.".to_string(),
                ));
            }
            stack.push(r);
            stack.push(l);
        }
        FormulaKind::Not(g) => {
            let span = f.range.start..f.range.start + 1;
            if hit(&span) && at < span.end {
                return Some((span, "**!** (not): minus the operand's robustness.".to_string()));
            }
            stack.push(g);
        }
        FormulaKind::Paren(g) => stack.push(g),
        FormulaKind::Compare { rest, .. } => {
            for (op, r, _) in rest {
                if hit(r) {
                    let meaning = match op {
                        CmpOp::Lt | CmpOp::Le => format!(
                            "**{}**: `e1 {} e2` has robustness `e2 - e1`: how far `e1` is below `e2`.",
                            op.as_str(),
                            op.as_str()
                        ),
                        CmpOp::Gt | CmpOp::Ge => format!(
                            "**{}**: `e1 {} e2` has robustness `e1 - e2`: how far `e1` is above `e2`.",
                            op.as_str(),
                            op.as_str()
                        ),
                        CmpOp::Eq | CmpOp::Ne => format!(
                            "**{}** has no robustness and is rejected; use a band such as `abs(x - 3) < 0.5`.",
                            op.as_str()
                        ),
                    };
                    return Some((r.clone(), meaning));
                }
            }
        }
        FormulaKind::True | FormulaKind::False | FormulaKind::Name(_) => {}
    }
    None
}

/// A time interval in words: a future window (from now on), or a past one (`past`).
/// Whether a spec declares a time variable (`t: time`): a dense-time spec.
fn is_dense(spec: &syntax::Spec) -> bool {
    spec.items.iter().any(|i| match i {
        Item::State(b) => b.vars.iter().any(|v| v.ty == syntax::VarType::Time),
        _ => false,
    })
}

/// A dense-time spec's window in words: times, not steps.
fn dense_window_words(iv: Option<&Interval>, past: bool) -> String {
    let (a, end, inclusive) = match iv {
        None => ("0", None, true),
        Some(iv) => {
            (iv.start.text.as_str(), iv.end.as_ref().map(|e| e.text.as_str()), iv.inclusive)
        }
    };
    let written = iv.map_or("No interval, so `[0..]`".to_string(), |_| match end {
        Some(b) if inclusive => format!("Interval `[{a}..={b}]`"),
        Some(b) => format!("Interval `[{a}..{b}]`"),
        None => format!("Interval `[{a}..]`"),
    });
    let span = match (end, past) {
        (Some(b), false) => format!("the times `t+{a}` to `t+{b}`, both included"),
        (None, false) => format!("every time from `t+{a}` on"),
        (Some(b), true) => format!("the times `t-{b}` to `t-{a}`, both included"),
        (None, true) => format!("every time from the first stamp to `t-{a}`"),
    };
    let edge = if past {
        "clipped at the first time stamp"
    } else {
        "never clipped: after the last stamp every variable keeps its last value"
    };
    format!(
        "Dense time: {written}: the window is {span}, in the time column's unit ({edge}). \
         Each sample holds until its variable's next one."
    )
}

fn window_words(iv: Option<&Interval>, past: bool, dense: bool) -> String {
    if dense {
        return dense_window_words(iv, past);
    }
    let step = |k: u64| step(k, past);
    let Some(iv) = iv else {
        return if past {
            "No interval, so `[0..]`: the window runs from the start of the trace to the current step."
        } else {
            "No interval, so `[0..]`: the window runs from the current step to the end of the trace."
        }
        .to_string();
    };
    let a = iv.start.as_integer();
    let b = iv.end.as_ref().and_then(|e| e.as_integer());
    let (sign, edge) = if past { ('-', "start") } else { ('+', "end") };
    match (a, b, iv.end.is_some(), iv.inclusive) {
        (Some(a), _, false, _) if past => {
            format!(
                "Interval `[{a}..]`: the window runs from the start of the trace to {}.",
                step(a)
            )
        }
        (Some(a), _, false, _) => {
            format!("Interval `[{a}..]`: the window runs from {} to the end of the trace.", step(a))
        }
        (Some(a), Some(b), true, false) if b > a => format!(
            "Interval `[{a}..{b}]`: the window is {} to {} ({} steps; step `t{sign}{b}` excluded), clipped at the {edge} of the trace.",
            step(if past { b - 1 } else { a }),
            step(if past { a } else { b - 1 }),
            b - a
        ),
        (Some(a), Some(b), true, true) if b >= a => format!(
            "Interval `[{a}..={b}]`: the window is {} to {}, both included ({} steps), clipped at the {edge} of the trace.",
            step(if past { b } else { a }),
            step(if past { a } else { b }),
            b - a + 1
        ),
        _ => "The interval is empty or not made of integers (see the diagnostic).".to_string(),
    }
}

/// Step `t+k` (or `t-k` in the past) in words.
fn step(k: u64, past: bool) -> String {
    match (k, past) {
        (0, _) => "the current step `t`".to_string(),
        (_, false) => format!("step `t+{k}`"),
        (_, true) => format!("step `t-{k}`"),
    }
}

/// Where a go-to-definition leads.
pub enum Target {
    /// A range of the same document.
    Here(lsp_types::Range),
    /// The start of another file (a world file).
    File(std::path::PathBuf),
}

/// Where the symbol at `pos` is declared; on a `world` item's string, the world file.
pub fn definition(a: &Analysis, pos: Position) -> Option<Target> {
    let offset = a.conv.offset(&a.text, pos);
    if let Some(item) = world_at(a, offset) {
        return a.worlds.get(&item.name)?.path.clone().map(Target::File);
    }
    let o = a.symbol_at(offset)?;
    let d = a.declaration(&o.symbol)?;
    Some(Target::Here(a.conv.range(&a.text, &d.range)))
}

/// Every occurrence of the symbol at `pos`.
pub fn references(a: &Analysis, pos: Position, include_declaration: bool) -> Vec<lsp_types::Range> {
    let offset = a.conv.offset(&a.text, pos);
    let Some(o) = a.symbol_at(offset) else { return Vec::new() };
    a.occurrences()
        .iter()
        .filter(|x| x.symbol == o.symbol && (include_declaration || !x.decl))
        .map(|x| a.conv.range(&a.text, &x.range))
        .collect()
}

/// The outline: each spec with its state variables, lets, task, options, options set and
/// learning parameters.
#[allow(deprecated)] // `DocumentSymbol::deprecated` must be named to build one.
pub fn symbols(a: &Analysis) -> Vec<DocumentSymbol> {
    let sym = |name: String,
               detail: Option<String>,
               kind,
               range: &Range<usize>,
               sel: &Range<usize>,
               children: Option<Vec<DocumentSymbol>>| DocumentSymbol {
        name,
        detail,
        kind,
        tags: None,
        deprecated: None,
        range: a.conv.range(&a.text, range),
        selection_range: a.conv.range(&a.text, sel),
        children,
    };
    let mut out = Vec::new();
    for spec in &a.checked.file.specs {
        if spec.name.name.is_empty() {
            continue;
        }
        let mut children = Vec::new();
        for item in &spec.items {
            match item {
                Item::State(b) => {
                    for v in &b.vars {
                        let detail = snippet(&a.text, &(v.ty_range.start..v.range.end));
                        children.push(sym(
                            v.name.name.clone(),
                            Some(detail),
                            SymbolKind::FIELD,
                            &v.range,
                            &v.name.range,
                            None,
                        ));
                    }
                }
                Item::Let(l) => children.push(sym(
                    l.name.name.clone(),
                    Some(snippet(&a.text, &l.formula.range)),
                    SymbolKind::CONSTANT,
                    &l.range,
                    &l.name.range,
                    None,
                )),
                Item::Task(t) => children.push(sym(
                    "task".into(),
                    Some(snippet(&a.text, &t.formula.range)),
                    SymbolKind::EVENT,
                    &t.range,
                    &t.keyword_range,
                    None,
                )),
                Item::Option(o) => children.push(sym(
                    o.name.name.clone(),
                    Some("option".into()),
                    SymbolKind::METHOD,
                    &o.range,
                    &o.name.range,
                    None,
                )),
                Item::Options(o) => {
                    let sel = o.range.start..o.range.start + "options".len();
                    children.push(sym(
                        "options".into(),
                        Some(snippet(&a.text, &o.range)),
                        SymbolKind::ENUM,
                        &o.range,
                        &sel,
                        None,
                    ));
                }
                Item::Learn(l) => {
                    let sel = l.range.start..l.range.start + "learn".len();
                    children.push(sym(
                        "learn".into(),
                        None,
                        SymbolKind::PROPERTY,
                        &l.range,
                        &sel,
                        None,
                    ));
                }
                Item::World(w) => children.push(sym(
                    "world".into(),
                    Some(w.name.clone()),
                    SymbolKind::FILE,
                    &w.range,
                    &w.name_range,
                    None,
                )),
            }
        }
        out.push(sym(
            spec.name.name.clone(),
            Some("spec".into()),
            SymbolKind::MODULE,
            &spec.range,
            &spec.name.range,
            Some(children),
        ));
    }
    out
}

/// Words completion offers beside the grammar's keywords ([`hstl::lang::KEYWORDS`]): the
/// fields of a long-form option, which are not reserved.
const FIELD_WORDS: [&str; 3] = ["reach", "init", "terminate"];

/// Keywords, then the names of the spec the cursor is in (variables, lets, options;
/// also those declared by items that do not parse yet). Inside the string of a `world`
/// item: the built-in worlds and the world files beside the document.
pub fn completion(a: &Analysis, pos: Position) -> Vec<CompletionItem> {
    let offset = a.conv.offset(&a.text, pos);
    if in_world_string(&a.text, offset) {
        return world_completion(a);
    }
    let mut items: Vec<CompletionItem> = hstl::lang::KEYWORDS
        .iter()
        .chain(FIELD_WORDS.iter())
        .chain(["world"].iter())
        .map(|k| CompletionItem {
            label: (*k).to_string(),
            kind: Some(CompletionItemKind::KEYWORD),
            ..CompletionItem::default()
        })
        .collect();
    let specs = &a.checked.file.specs;
    let inside: Vec<usize> = (0..specs.len())
        .filter(|&i| specs[i].range.start <= offset && offset <= specs[i].range.end)
        .collect();
    let mut seen = std::collections::HashSet::new();
    for o in a.occurrences() {
        if !o.decl || !(inside.is_empty() || inside.contains(&o.symbol.spec)) {
            continue;
        }
        if !seen.insert((o.symbol.kind, o.symbol.name.clone())) {
            continue;
        }
        let (kind, detail) = match o.symbol.kind {
            SymKind::Var => (CompletionItemKind::VARIABLE, "state variable"),
            SymKind::Let => (CompletionItemKind::CONSTANT, "let"),
            SymKind::Option => (CompletionItemKind::METHOD, "option"),
        };
        items.push(CompletionItem {
            label: o.symbol.name.clone(),
            kind: Some(kind),
            detail: Some(detail.to_string()),
            ..CompletionItem::default()
        });
    }
    for &i in &inside {
        for b in &specs[i].broken {
            for name in &b.names {
                if seen.insert((SymKind::Let, name.clone())) {
                    items.push(CompletionItem {
                        label: name.clone(),
                        kind: Some(CompletionItemKind::TEXT),
                        detail: Some("declared by an item that does not parse yet".into()),
                        ..CompletionItem::default()
                    });
                }
            }
        }
    }
    items
}

/// Whether `offset` is inside an open `world "...` string: the line before it reads
/// `world`, a quote, and no other quote.
fn in_world_string(text: &str, offset: usize) -> bool {
    let Some(before) = text.get(..offset) else { return false };
    let line = &before[before.rfind(['\n', '\r']).map_or(0, |i| i + 1)..];
    let Some(quote) = line.find('"') else { return false };
    line[..quote].trim_end().ends_with("world") && !line[quote + 1..].contains('"')
}

/// The most world files offered from the document's folder.
const MAX_WORLD_FILES: usize = 200;

/// The built-in worlds, then the `.toml` files in the document's folder.
fn world_completion(a: &Analysis) -> Vec<CompletionItem> {
    let mut items: Vec<CompletionItem> = hstl::world::AnyWorld::builtin_names()
        .into_iter()
        .map(|name| CompletionItem {
            label: name.to_string(),
            kind: Some(CompletionItemKind::CONSTANT),
            detail: Some("built-in world".into()),
            ..CompletionItem::default()
        })
        .collect();
    let Some(folder) = a.worlds.folder() else { return items };
    let Ok(entries) = std::fs::read_dir(folder) else { return items };
    let mut files: Vec<String> = entries
        .filter_map(Result::ok)
        .take(10 * MAX_WORLD_FILES)
        .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    files.sort();
    files.truncate(MAX_WORLD_FILES);
    items.extend(files.into_iter().map(|name| CompletionItem {
        label: name,
        kind: Some(CompletionItemKind::FILE),
        detail: Some("world file beside the spec".into()),
        ..CompletionItem::default()
    }));
    items
}

/// The edits that give the canonical layout (none when it is already canonical), or why
/// the text cannot be formatted.
pub fn format(a: &Analysis) -> Result<Vec<TextEdit>, String> {
    match hstl::lang::format(&a.text) {
        Ok(formatted) if formatted == a.text => Ok(Vec::new()),
        Ok(formatted) => Ok(vec![TextEdit {
            range: a.conv.range(&a.text, &(0..a.text.len())),
            new_text: formatted,
        }]),
        Err(diags) => {
            let first = diags.iter().find(|d| d.is_error()).or(diags.first());
            Err(match first {
                Some(d) => {
                    let p = a.conv.position(&a.text, d.range.start);
                    format!(
                        "cannot format: syntax error at line {}, column {}: {}",
                        p.line + 1,
                        p.character + 1,
                        d.message
                    )
                }
                None => "cannot format: the file has syntax errors".to_string(),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hover text at the `nth` occurrence of `word` in `text`.
    fn hover_at(text: &str, word: &str, nth: usize) -> String {
        let a = Analysis::new(text.to_string(), Encoding::Utf8, &mut WorldCache::default(), None);
        let at = text.match_indices(word).nth(nth).map(|(i, _)| i).expect("the word");
        let pos = a.conv.position(text, at + 1);
        match hover(&a, pos).map(|h| h.contents) {
            Some(HoverContents::Markup(m)) => m.value,
            other => panic!("no hover at `{word}`: {other:?}"),
        }
    }

    #[test]
    fn the_time_variable_and_dense_windows_hover_as_dense_time() {
        let text = "spec S {
    state { t: time, x: float }
    let P = once[0.5..=1] x > 0;
    task eventually[0..=2.5] P;
}
";
        let t = hover_at(text, "t:", 0);
        assert!(t.contains("time variable (dense time)"), "{t}");
        let e = hover_at(text, "eventually", 0);
        assert!(e.contains("the times `t+0` to `t+2.5`"), "{e}");
        let o = hover_at(text, "once", 0);
        assert!(o.contains("`t-1` to `t-0.5`") && o.contains("first time stamp"), "{o}");
    }

    /// Each past-time operator's hover: its meaning, and its window counted back from now.
    #[test]
    fn past_operators_hover_with_their_past_window() {
        let text = "spec S {
    state { x: float, y: float }
    let P = once[2..5] x > 0 || historically[0..=3] y > 0;
    let Q = x > 0 since[1..] y > 0;
    let R = prev x > 0 && next y > 0 && historically x > 0;
    task P && Q && R;
}
";
        let cases: [(&str, usize, &[&str]); 6] = [
            (
                "once",
                0,
                &[
                    "**once**",
                    "maximum",
                    "past window",
                    "`t-4` to step `t-2` (3 steps; step `t-5` excluded), clipped at the start",
                ],
            ),
            (
                "historically",
                0,
                &[
                    "**historically**",
                    "minimum",
                    "`t-3` to the current step `t`, both included (4 steps)",
                ],
            ),
            (
                "since",
                0,
                &[
                    "**since**",
                    "after `t'`",
                    "`[1..]`: the window runs from the start of the trace to step `t-1`",
                ],
            ),
            ("prev", 0, &["**prev**", "one step back", "`+inf` at the first step"]),
            ("next", 0, &["**next**", "one step ahead", "`+inf` at the last step"]),
            (
                "historically",
                1,
                &[
                    "No interval, so `[0..]`: the window runs from the start of the trace to the current step",
                ],
            ),
        ];
        for (word, nth, want) in cases {
            let got = hover_at(text, word, nth);
            for w in want {
                assert!(got.contains(w), "`{word}` #{nth}: {w:?} not in {got:?}");
            }
        }
        // The future operators' windows still count forward.
        let text = "spec S { state { x: float } task eventually[2..5] x > 0; }";
        let got = hover_at(text, "eventually", 0);
        assert!(
            got.contains(
                "step `t+2` to step `t+4` (3 steps; step `t+5` excluded), clipped at the end"
            ),
            "{got}"
        );
    }

    /// Completion offers the past-time keywords with the others.
    #[test]
    fn completion_offers_past_operators() {
        let text = "spec S { state { x: float } task x > 0; }";
        let a = Analysis::new(text.to_string(), Encoding::Utf8, &mut WorldCache::default(), None);
        let labels: Vec<String> = completion(&a, Position { line: 0, character: 30 })
            .into_iter()
            .map(|i| i.label)
            .collect();
        for k in ["once", "historically", "since", "prev", "next"] {
            assert!(labels.iter().any(|l| l == k), "{k} missing from {labels:?}");
        }
    }
}
