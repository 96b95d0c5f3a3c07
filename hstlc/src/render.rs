//! Rendering diagnostics and command errors for people and for tools.

use std::fmt;

use hstl::lang::{Diagnostic, LineIndex, Severity};
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
    let mut out = String::new();
    for file in files {
        let index = LineIndex::new(&file.source);
        for d in &file.diagnostics {
            let start = index.position(&file.source, d.range.start);
            let kind = severity_word(d.severity);
            out.push_str(&format!(
                "{}:{}:{}: {} {kind}: {}\n",
                file.name, start.line, start.column, d.code, d.message
            ));
        }
    }
    out.push_str(&summary(files));
    out.push('\n');
    out
}

/// The `json` format: one array of flat objects, positions 1-based, end exclusive.
pub fn json(files: &[Checked]) -> String {
    let mut items = Vec::new();
    for file in files {
        let index = LineIndex::new(&file.source);
        for d in &file.diagnostics {
            let start = index.position(&file.source, d.range.start);
            let end = index.position(&file.source, d.range.end);
            items.push(json!({
                "file": file.name,
                "severity": severity_word(d.severity),
                "code": d.code,
                "message": d.message,
                "line": start.line,
                "column": start.column,
                "end_line": end.line,
                "end_column": end.column,
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
            let (s, e) = (
                index.position(&file.source, range.start),
                index.position(&file.source, range.end),
            );
            json!({
                "startLine": s.line, "startColumn": s.column,
                "endLine": e.line, "endColumn": e.column,
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
                "level": match d.severity { Severity::Error => "error", Severity::Warning => "warning" },
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
    let all = || files.iter().flat_map(|f| &f.diagnostics);
    let errors = all().filter(|d| d.severity == Severity::Error).count();
    let warnings = all().filter(|d| d.severity == Severity::Warning).count();
    let n = files.len();
    let files = plural(n, "file");
    if errors + warnings == 0 {
        format!("checked {files}: no problems")
    } else {
        format!("checked {files}: {}, {}", plural(errors, "error"), plural(warnings, "warning"))
    }
}

fn plural(n: usize, word: &str) -> String {
    if n == 1 { format!("1 {word}") } else { format!("{n} {word}s") }
}

fn severity_word(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
    }
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
