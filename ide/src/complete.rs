//! Completion: keywords and the names of the spec the cursor is in; inside a `world`
//! item's string, the built-in worlds and the world files beside the document.

use crate::analysis::{Analysis, SymKind};

/// What a completion offers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompletionKind {
    /// A keyword of the language (or a long-form option's field).
    Keyword,
    /// A state variable.
    Variable,
    /// A `let`.
    Let,
    /// A primitive option.
    Option,
    /// A name declared by an item that does not parse yet.
    Unparsed,
    /// A built-in world's name.
    BuiltinWorld,
    /// A world file beside the document.
    WorldFile,
}

/// One completion.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Completion {
    /// The text inserted.
    pub label: String,
    /// What it is.
    pub kind: CompletionKind,
    /// What it is, in words.
    pub detail: Option<String>,
}

/// Words completion offers beside the grammar's keywords ([`hstl::lang::KEYWORDS`]): the
/// fields of a long-form option, which are not reserved.
const FIELD_WORDS: [&str; 3] = ["reach", "init", "terminate"];

/// Keywords, then the names of the spec the cursor is in (variables, lets, options;
/// also those declared by items that do not parse yet). Inside the string of a `world`
/// item: the built-in worlds and the world files beside the document.
pub fn completion(a: &Analysis, offset: usize) -> Vec<Completion> {
    if in_world_string(&a.text, offset) {
        return world_completion(a);
    }
    let mut items: Vec<Completion> = hstl::lang::KEYWORDS
        .iter()
        .chain(FIELD_WORDS.iter())
        .chain(["world"].iter())
        .map(|k| Completion {
            label: (*k).to_string(),
            kind: CompletionKind::Keyword,
            detail: None,
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
            SymKind::Var => (CompletionKind::Variable, "state variable"),
            SymKind::Let => (CompletionKind::Let, "let"),
            SymKind::Option => (CompletionKind::Option, "option"),
        };
        items.push(Completion {
            label: o.symbol.name.clone(),
            kind,
            detail: Some(detail.to_string()),
        });
    }
    for &i in &inside {
        for b in &specs[i].broken {
            for name in &b.names {
                if seen.insert((SymKind::Let, name.clone())) {
                    items.push(Completion {
                        label: name.clone(),
                        kind: CompletionKind::Unparsed,
                        detail: Some("declared by an item that does not parse yet".into()),
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
fn world_completion(a: &Analysis) -> Vec<Completion> {
    let mut items: Vec<Completion> = hstl::world::AnyWorld::builtin_names()
        .into_iter()
        .map(|name| Completion {
            label: name.to_string(),
            kind: CompletionKind::BuiltinWorld,
            detail: Some("built-in world".into()),
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
    items.extend(files.into_iter().map(|name| Completion {
        label: name,
        kind: CompletionKind::WorldFile,
        detail: Some("world file beside the spec".into()),
    }));
    items
}
