//! What the server answers, from one [`Analysis`] of a document: `hstl-ide`'s answers on
//! byte offsets, converted to and from the protocol's positions in the negotiated
//! encoding (diagnostics and formatting, which are conversions only, are made here).

use std::ops::{Deref, DerefMut};
use std::path::Path;

use hstl::lang::Severity;
use hstl_ide::{CompletionKind, OutlineKind};
use lsp_types::{
    CompletionItem, CompletionItemKind, DiagnosticRelatedInformation, DiagnosticSeverity,
    DocumentSymbol, Hover, HoverContents, Location, MarkupContent, MarkupKind, NumberOrString,
    Position, SymbolKind, TextEdit, Uri,
};

pub use hstl_ide::Leftovers;
use hstl_ide::worlds::WorldCache;

use super::convert::{Converter, Encoding};

/// Everything the server knows about one version of a document: `hstl-ide`'s analysis
/// (which it reads through, as `a.text`, `a.checked`, `a.worlds`) and the position
/// conversion for its text.
pub struct Analysis {
    ide: hstl_ide::Analysis,
    /// Position conversion for this text.
    pub conv: Converter,
}

impl Deref for Analysis {
    type Target = hstl_ide::Analysis;

    fn deref(&self) -> &hstl_ide::Analysis {
        &self.ide
    }
}

impl DerefMut for Analysis {
    fn deref_mut(&mut self) -> &mut hstl_ide::Analysis {
        &mut self.ide
    }
}

impl Analysis {
    /// Checks `text` and indexes its names.
    pub fn new(
        text: String,
        enc: Encoding,
        worlds: &mut WorldCache,
        folder: Option<&Path>,
    ) -> Self {
        let conv = Converter::new(&text, enc);
        Analysis { ide: hstl_ide::Analysis::new(text, worlds, folder), conv }
    }

    /// The analysis of a new version of the text of `prev` (see
    /// [`hstl_ide::Analysis::update`]), and what is left of `prev`, to be freed after
    /// answering.
    pub fn update(
        prev: Analysis,
        text: String,
        enc: Encoding,
        worlds: &mut WorldCache,
        folder: Option<&Path>,
    ) -> (Self, Leftovers) {
        let conv = Converter::new(&text, enc);
        let (ide, leftovers) = hstl_ide::Analysis::update(prev.ide, text, worlds, folder);
        (Analysis { ide, conv }, leftovers)
    }

    /// The whole analysis, to be dropped later.
    pub fn into_leftovers(self) -> Leftovers {
        self.ide.into_leftovers()
    }

    fn offset(&self, pos: Position) -> usize {
        self.conv.offset(&self.text, pos)
    }

    fn range(&self, r: &std::ops::Range<usize>) -> lsp_types::Range {
        self.conv.range(&self.text, r)
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
/// interval in words ([`hstl_ide::hover`]), as Markdown.
pub fn hover(a: &Analysis, pos: Position) -> Option<Hover> {
    let (range, text) = hstl_ide::hover(a, a.offset(pos))?;
    Some(Hover {
        contents: HoverContents::Markup(MarkupContent { kind: MarkupKind::Markdown, value: text }),
        range: Some(a.range(&range)),
    })
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
    Some(match hstl_ide::definition(a, a.offset(pos))? {
        hstl_ide::Target::Here(r) => Target::Here(a.range(&r)),
        hstl_ide::Target::File(path) => Target::File(path),
    })
}

/// Every occurrence of the symbol at `pos`.
pub fn references(a: &Analysis, pos: Position, include_declaration: bool) -> Vec<lsp_types::Range> {
    hstl_ide::references(a, a.offset(pos), include_declaration).iter().map(|r| a.range(r)).collect()
}

/// The outline: each spec with its state variables, lets, task, options, options set and
/// learning parameters.
pub fn symbols(a: &Analysis) -> Vec<DocumentSymbol> {
    hstl_ide::symbols(a).into_iter().map(|o| symbol(a, o)).collect()
}

#[allow(deprecated)] // `DocumentSymbol::deprecated` must be named to build one.
fn symbol(a: &Analysis, o: hstl_ide::Outline) -> DocumentSymbol {
    DocumentSymbol {
        name: o.name,
        detail: o.detail,
        kind: match o.kind {
            OutlineKind::Spec => SymbolKind::MODULE,
            OutlineKind::Variable => SymbolKind::FIELD,
            OutlineKind::Let => SymbolKind::CONSTANT,
            OutlineKind::Task => SymbolKind::EVENT,
            OutlineKind::Option => SymbolKind::METHOD,
            OutlineKind::Options => SymbolKind::ENUM,
            OutlineKind::Learn => SymbolKind::PROPERTY,
            OutlineKind::World => SymbolKind::FILE,
        },
        tags: None,
        deprecated: None,
        range: a.range(&o.range),
        selection_range: a.range(&o.selection),
        children: o.children.map(|c| c.into_iter().map(|o| symbol(a, o)).collect()),
    }
}

/// Keywords, then the names of the spec the cursor is in; inside the string of a `world`
/// item, the built-in worlds and the world files beside the document
/// ([`hstl_ide::completion`]).
pub fn completion(a: &Analysis, pos: Position) -> Vec<CompletionItem> {
    hstl_ide::completion(a, a.offset(pos))
        .into_iter()
        .map(|c| CompletionItem {
            label: c.label,
            kind: Some(match c.kind {
                CompletionKind::Keyword => CompletionItemKind::KEYWORD,
                CompletionKind::Variable => CompletionItemKind::VARIABLE,
                CompletionKind::Let | CompletionKind::BuiltinWorld => CompletionItemKind::CONSTANT,
                CompletionKind::Option => CompletionItemKind::METHOD,
                CompletionKind::Unparsed => CompletionItemKind::TEXT,
                CompletionKind::WorldFile => CompletionItemKind::FILE,
            }),
            detail: c.detail,
            ..CompletionItem::default()
        })
        .collect()
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
