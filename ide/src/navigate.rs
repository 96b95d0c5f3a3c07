//! Navigation: where a name is declared (on a `world` item's string, the world file),
//! every place it is written, and the outline of a document. Byte ranges in, byte ranges
//! out.

use std::ops::Range;

use hstl::lang::syntax::Item;

use crate::analysis::Analysis;
use crate::hover::{snippet, world_at};

/// What an outline entry is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OutlineKind {
    /// A spec, with its items as children.
    Spec,
    /// A state variable.
    Variable,
    /// A `let`.
    Let,
    /// The task.
    Task,
    /// A primitive option.
    Option,
    /// The options set.
    Options,
    /// The `learn` item.
    Learn,
    /// The `world` item.
    World,
}

/// One entry of a document's outline.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Outline {
    /// The name shown.
    pub name: String,
    /// A word or the entry's text beside the name.
    pub detail: Option<String>,
    /// What it is.
    pub kind: OutlineKind,
    /// The whole item.
    pub range: Range<usize>,
    /// Its name (what is selected when the entry is chosen).
    pub selection: Range<usize>,
    /// A spec's items.
    pub children: Option<Vec<Outline>>,
}

/// Where a go-to-definition leads.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Target {
    /// A byte range of the same document.
    Here(Range<usize>),
    /// The start of another file (a world file).
    File(std::path::PathBuf),
}

/// Where the symbol at `pos` is declared; on a `world` item's string, the world file.
pub fn definition(a: &Analysis, offset: usize) -> Option<Target> {
    if let Some(item) = world_at(a, offset) {
        return a.worlds.get(&item.name)?.path.clone().map(Target::File);
    }
    let o = a.symbol_at(offset)?;
    let d = a.declaration(&o.symbol)?;
    Some(Target::Here(d.range.clone()))
}

/// Every occurrence of the symbol at `pos`.
pub fn references(a: &Analysis, offset: usize, include_declaration: bool) -> Vec<Range<usize>> {
    let Some(o) = a.symbol_at(offset) else { return Vec::new() };
    a.occurrences()
        .iter()
        .filter(|x| x.symbol == o.symbol && (include_declaration || !x.decl))
        .map(|x| x.range.clone())
        .collect()
}

/// The outline: each spec with its state variables, lets, task, options, options set and
/// learning parameters.
pub fn symbols(a: &Analysis) -> Vec<Outline> {
    let sym = |name: String,
               detail: Option<String>,
               kind,
               range: &Range<usize>,
               sel: &Range<usize>,
               children: Option<Vec<Outline>>| Outline {
        name,
        detail,
        kind,
        range: range.clone(),
        selection: sel.clone(),
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
                            OutlineKind::Variable,
                            &v.range,
                            &v.name.range,
                            None,
                        ));
                    }
                }
                Item::Let(l) => children.push(sym(
                    l.name.name.clone(),
                    Some(snippet(&a.text, &l.formula.range)),
                    OutlineKind::Let,
                    &l.range,
                    &l.name.range,
                    None,
                )),
                Item::Task(t) => children.push(sym(
                    "task".into(),
                    Some(snippet(&a.text, &t.formula.range)),
                    OutlineKind::Task,
                    &t.range,
                    &t.keyword_range,
                    None,
                )),
                Item::Option(o) => children.push(sym(
                    o.name.name.clone(),
                    Some("option".into()),
                    OutlineKind::Option,
                    &o.range,
                    &o.name.range,
                    None,
                )),
                Item::Options(o) => {
                    let sel = o.range.start..o.range.start + "options".len();
                    children.push(sym(
                        "options".into(),
                        Some(snippet(&a.text, &o.range)),
                        OutlineKind::Options,
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
                        OutlineKind::Learn,
                        &l.range,
                        &sel,
                        None,
                    ));
                }
                Item::World(w) => children.push(sym(
                    "world".into(),
                    Some(w.name.clone()),
                    OutlineKind::World,
                    &w.range,
                    &w.name_range,
                    None,
                )),
            }
        }
        out.push(sym(
            spec.name.name.clone(),
            Some("spec".into()),
            OutlineKind::Spec,
            &spec.range,
            &spec.name.range,
            Some(children),
        ));
    }
    out
}
