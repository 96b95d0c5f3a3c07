//! The index of one version of a document: its parse and check ([`Analysis`], the same
//! diagnostics as `hstlc check`, each spec against the world it names) and every place a
//! name is written ([`Occurrence`]), built on the first request that needs it.

use std::cell::OnceCell;
use std::collections::HashSet;
use std::ops::Range;
use std::path::Path;

use hstl::lang::CheckedSpec;
use hstl::lang::syntax::{
    self, Expr, ExprKind, FieldValue, Formula, FormulaKind, Item, OptionsKind, Spec,
};

use crate::worlds::{DocWorlds, WorldCache};

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
    /// The worlds the specs name, as they were checked against.
    pub worlds: DocWorlds,
}

impl Analysis {
    /// Checks `text` and indexes its names.
    pub fn new(text: String, worlds: &mut WorldCache, folder: Option<&Path>) -> Self {
        let parsed = hstl::lang::parse(&text);
        Self::from_parsed(text, parsed, worlds, folder)
    }

    /// The analysis of a new version of the text of `prev`: only the items around the
    /// change are parsed again (see `hstl_lang::incremental`), then the whole is checked.
    ///
    /// Also returns what is left of `prev` (the old text and checked specs), so that the
    /// caller can free it after answering rather than before.
    pub fn update(
        prev: Analysis,
        text: String,
        worlds: &mut WorldCache,
        folder: Option<&Path>,
    ) -> (Self, Leftovers) {
        let Analysis { text: old, checked, parse_diagnostics, occurrences, .. } = prev;
        let hstl::lang::Checked { file, specs, diagnostics } = checked;
        let prev = hstl::lang::Parsed { file, diagnostics: parse_diagnostics };
        let (parsed, _) = hstl::lang::incremental::reparse(prev, &old, &text);
        let next = Self::from_parsed(text, parsed, worlds, folder);
        (next, Leftovers { _parts: Box::new((old, specs, diagnostics, occurrences)) })
    }

    /// The whole analysis, to be dropped later.
    pub fn into_leftovers(self) -> Leftovers {
        Leftovers { _parts: Box::new(self) }
    }

    fn from_parsed(
        text: String,
        parsed: hstl::lang::Parsed,
        cache: &mut WorldCache,
        folder: Option<&Path>,
    ) -> Self {
        let parse_diagnostics = parsed.diagnostics.clone();
        // The same diagnostics as `hstlc check`: each spec against the world it names.
        let worlds = cache.resolve(&parsed, folder);
        let checked =
            hstl::lang::check_parsed_with_worlds(&text, parsed, &|spec| worlds.lookup(spec));
        Analysis { text, checked, parse_diagnostics, occurrences: OnceCell::new(), worlds }
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

    /// The occurrences whose range holds `offset`.
    pub fn occurrences_at(&self, offset: usize) -> impl Iterator<Item = &Occurrence> {
        let all = self.occurrences();
        let first = all.partition_point(|o| o.range.end < offset);
        all[first..]
            .iter()
            .take_while(move |o| o.range.start <= offset)
            .filter(move |o| o.range.start <= offset && offset <= o.range.end)
    }

    /// The declaration of a symbol (its first one).
    pub fn declaration(&self, symbol: &Symbol) -> Option<&Occurrence> {
        self.occurrences().iter().find(|o| o.decl && &o.symbol == symbol)
    }

    /// The checked spec of syntax spec `i`.
    pub fn checked_spec(&self, i: usize) -> Option<&CheckedSpec> {
        let spec = self.checked.file.specs.get(i)?;
        self.checked.specs.iter().find(|c| c.name_range == spec.name.range && !c.name.is_empty())
    }

    /// The symbol the cursor is on: for a name that is both an option's declaration and
    /// a reference to the `let` it reaches (`option A;`), the `let`.
    pub fn symbol_at(&self, offset: usize) -> Option<&Occurrence> {
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
