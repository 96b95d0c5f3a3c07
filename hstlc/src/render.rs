//! Rendering diagnostics and command errors for people and for tools.

use std::fmt;

use hstl::lang::{Diagnostic, FileDiagnostics, LineIndex, Severity};
use miette::{GraphicalReportHandler, GraphicalTheme, LabeledSpan, NamedSource, SourceSpan};
use serde_json::{Value, json};

use crate::check::Checked;
use crate::cli_error::CliError;

/// The `full` format: miette's graphical reports, then a summary line.
pub fn full(files: &[Checked], colour: bool) -> String {
    let theme = if colour { GraphicalTheme::unicode() } else { GraphicalTheme::unicode_nocolor() };
    let handler = GraphicalReportHandler::new_themed(theme).with_width(100);
    let mut out = String::new();
    for file in files {
        let source = NamedSource::new(&file.name, file.source.clone());
        for d in &file.diagnostics {
            let report = Report { diagnostic: d, source: &source };
            // Writing into a String cannot fail.
            let _ = handler.render_report(&mut out, &report);
            out.push('\n');
        }
    }
    out.push_str(&summary(files));
    out.push('\n');
    out
}

/// The `concise` format: `path:line:col: CODE message`, then a summary line.
pub fn concise(files: &[Checked]) -> String {
    hstl::lang::render_concise(&file_diagnostics(files))
}

/// The `json` format: one array of flat objects, positions 1-based, end exclusive.
pub fn json(files: &[Checked]) -> String {
    let mut items = Vec::new();
    for file in files {
        let index = LineIndex::new(&file.source);
        for d in &file.diagnostics {
            let at = index.location(&file.source, &d.range);
            items.push(json!({
                "file": file.name,
                "severity": d.severity.as_str(),
                "code": d.code,
                "message": d.message,
                "line": at.line,
                "column": at.column,
                "end_line": at.end_line,
                "end_column": at.end_column,
                "help": d.help,
            }));
        }
    }
    pretty(&Value::Array(items))
}

/// The `sarif` format: SARIF 2.1.0 with one run.
pub fn sarif(files: &[Checked]) -> String {
    let mut rules: Vec<&str> = files.iter().flat_map(|f| &f.diagnostics).map(|d| d.code).collect();
    rules.sort_unstable();
    rules.dedup();
    let rules: Vec<Value> = rules
        .iter()
        .map(|code| {
            let info = hstl::lang::codes::lookup(code);
            json!({
                "id": code,
                "name": info.map(|i| i.name),
                "shortDescription": { "text": info.map_or("", |i| i.summary) },
                "fullDescription": { "text": info.map_or("", |i| i.explanation) },
            })
        })
        .collect();
    let mut results = Vec::new();
    for file in files {
        let index = LineIndex::new(&file.source);
        let region = |range: &std::ops::Range<usize>| {
            let at = index.location(&file.source, range);
            json!({
                "startLine": at.line, "startColumn": at.column,
                "endLine": at.end_line, "endColumn": at.end_column,
            })
        };
        let location = |range: &std::ops::Range<usize>, message: Option<&str>| {
            let mut loc = json!({
                "physicalLocation": {
                    "artifactLocation": { "uri": file.name },
                    "region": region(range),
                }
            });
            if let Some(m) = message {
                loc["message"] = json!({ "text": m });
            }
            loc
        };
        for d in &file.diagnostics {
            let mut text = d.message.clone();
            if let Some(help) = &d.help {
                text.push_str(&format!("\nhelp: {help}"));
            }
            results.push(json!({
                "ruleId": d.code,
                "level": d.severity.as_str(),
                "message": { "text": text },
                "locations": [location(&d.range, None)],
                "relatedLocations": d.labels.iter().enumerate().map(|(i, l)| {
                    let mut loc = location(&l.range, Some(&l.message));
                    loc["id"] = json!(i);
                    loc
                }).collect::<Vec<_>>(),
            }));
        }
    }
    pretty(&json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "hstlc",
                "version": env!("CARGO_PKG_VERSION"),
                "rules": rules,
            }},
            "results": results,
        }],
    }))
}

/// An error that kept a command from running, as miette would print it, without colour
/// codes when standard error is not a terminal.
pub fn cli_error(e: &CliError) -> String {
    use std::io::IsTerminal;
    let mut out = String::new();
    if std::io::stderr().is_terminal() {
        out.push_str("\x1b[1;31merror\x1b[0m: ");
    } else {
        out.push_str("error: ");
    }
    out.push_str(&e.to_string());
    if let Some(help) = e.help() {
        out.push_str(&format!("\n  help: {help}"));
    }
    out
}

/// `checked 2 files: 1 error, 3 warnings`.
fn summary(files: &[Checked]) -> String {
    hstl::lang::render::summary(&file_diagnostics(files))
}

fn file_diagnostics(files: &[Checked]) -> Vec<FileDiagnostics<'_>> {
    files
        .iter()
        .map(|f| FileDiagnostics { name: &f.name, source: &f.source, diagnostics: &f.diagnostics })
        .collect()
}

fn pretty(v: &Value) -> String {
    let mut s = serde_json::to_string_pretty(v).unwrap_or_else(|_| "[]".into());
    s.push('\n');
    s
}

/// A front-end diagnostic seen through miette's eyes.
struct Report<'a> {
    diagnostic: &'a Diagnostic,
    source: &'a NamedSource<String>,
}

impl fmt::Debug for Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.diagnostic, f)
    }
}

impl fmt::Display for Report<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.diagnostic.message)
    }
}

impl std::error::Error for Report<'_> {}

impl miette::Diagnostic for Report<'_> {
    fn code<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        Some(Box::new(self.diagnostic.code))
    }

    fn severity(&self) -> Option<miette::Severity> {
        Some(match self.diagnostic.severity {
            Severity::Error => miette::Severity::Error,
            Severity::Warning => miette::Severity::Warning,
        })
    }

    fn help<'b>(&'b self) -> Option<Box<dyn fmt::Display + 'b>> {
        self.diagnostic.help.as_ref().map(|h| Box::new(h) as Box<dyn fmt::Display>)
    }

    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        Some(self.source)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let d = self.diagnostic;
        let primary = LabeledSpan::new_primary_with_span(None, span(&d.range));
        let related = d
            .labels
            .iter()
            .map(|l| LabeledSpan::new_with_span(Some(l.message.clone()), span(&l.range)));
        Some(Box::new(std::iter::once(primary).chain(related)))
    }
}

fn span(range: &std::ops::Range<usize>) -> SourceSpan {
    SourceSpan::new(range.start.into(), range.end.saturating_sub(range.start))
}
