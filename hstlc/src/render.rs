//! Rendering diagnostics and command errors for people and for tools.

use std::fmt;

use hstl::lang::{Diagnostic, FileDiagnostics, LineIndex, Severity};
use miette::{
    GraphicalReportHandler, GraphicalTheme, LabeledSpan, MietteError, MietteSpanContents,
    SourceSpan, SpanContents,
};
use serde_json::{Value, json};

use crate::cli_error::CliError;

/// One checked input: its name, text and diagnostics.
pub struct Checked {
    /// The path, or the `--stdin-filename` name.
    pub name: String,
    /// The source text.
    pub source: String,
    /// Everything the front end found, in source order.
    pub diagnostics: Vec<Diagnostic>,
}

/// The `full` format: miette's graphical reports, then a summary line.
pub fn full(files: &[Checked], colour: bool) -> String {
    let theme = if colour { GraphicalTheme::unicode() } else { GraphicalTheme::unicode_nocolor() };
    let handler = GraphicalReportHandler::new_themed(theme).with_width(100);
    let mut out = String::new();
    for file in files {
        let index = LineIndex::new(&file.source);
        for d in &file.diagnostics {
            let excerpt = Excerpt::new(&file.name, &file.source, &index, d);
            let report = Report { diagnostic: d, excerpt: &excerpt };
            // Writing into a String cannot fail.
            let _ = handler.render_report(&mut out, &report);
            out.push('\n');
        }
    }
    out.push_str(&summary(files));
    out.push('\n');
    out
}

/// The `concise` format: `path:line:col: CODE message`, the help (if any) indented on the
/// next line, then a summary line.
pub fn concise(files: &[Checked]) -> String {
    let names: Vec<String> =
        files.iter().map(|f| hstl::load::escape_controls(&f.name).into_owned()).collect();
    let shown: Vec<FileDiagnostics<'_>> = files
        .iter()
        .zip(&names)
        .map(|(f, name)| FileDiagnostics { name, source: &f.source, diagnostics: &f.diagnostics })
        .collect();
    hstl::lang::render_concise(&shown)
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
        let artifact = artifact_location(&file.name);
        let location = |range: &std::ops::Range<usize>, message: Option<&str>| {
            let mut loc = json!({
                "physicalLocation": {
                    "artifactLocation": artifact,
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

/// SARIF's `artifactLocation` of a file as `check` names it: an absolute path as a `file:`
/// URI, a relative one (or a `--stdin-filename`) as a relative reference from the
/// `%SRCROOT%` base, percent-encoded either way (RFC 3986: a space is `%20`).
fn artifact_location(name: &str) -> Value {
    let encoded = percent_encode(name);
    if name.starts_with('/') {
        json!({ "uri": format!("file://{encoded}") })
    } else {
        json!({ "uri": encoded, "uriBaseId": "%SRCROOT%" })
    }
}

/// `path` with every byte but the unreserved characters and `/` written as `%XX`.
fn percent_encode(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    for b in path.bytes() {
        if b.is_ascii_alphanumeric() || b"-._~/".contains(&b) {
            out.push(char::from(b));
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
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
    out.push_str(&escape_lines(&e.to_string()));
    if let Some(help) = e.help() {
        out.push_str(&format!("\n  help: {}", escape_lines(&help)));
    }
    out
}

/// `text` with the control characters of each line escaped (its line ends kept): the names
/// a message quotes reach the terminal as text, never as commands to it.
pub fn escape_lines(text: &str) -> String {
    text.split('\n').map(|l| hstl::load::escape_controls(l)).collect::<Vec<_>>().join("\n")
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

/// A front-end diagnostic seen through miette's eyes, its ranges mapped into its excerpt.
struct Report<'a> {
    diagnostic: &'a Diagnostic,
    excerpt: &'a Excerpt,
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
        Some(self.excerpt)
    }

    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        let d = self.diagnostic;
        let spans = &self.excerpt.spans;
        let primary = LabeledSpan::new_primary_with_span(None, spans[0]);
        let related = d
            .labels
            .iter()
            .zip(&spans[1..])
            .map(|(l, &span)| LabeledSpan::new_with_span(Some(l.message.clone()), span));
        Some(Box::new(std::iter::once(primary).chain(related)))
    }
}

/// Lines longer than this many characters are shown as windows around the places a
/// diagnostic marks: miette cannot lay out a column past 65,535, and a minified line is
/// unreadable whole.
const LONG_LINE: usize = 200;
/// Characters kept on each side of a marked place in a long line (and at the start of a
/// long line with no marked place).
const WINDOW: usize = 40;
/// A range over more lines than this is marked on its first line only.
const MAX_RANGE_LINES: usize = 12;
/// Marked places at most this many lines apart are shown in one snippet, with the lines
/// between them.
const MAX_GAP: usize = 8;
/// Stands for the characters left out of a long line.
const ELLIPSIS: &str = "…";

/// The lines one diagnostic shows, as miette reads them: each line break written as `\n`
/// (miette knows no lone `\r`), long lines cut down to windows around the marked places.
/// Line numbers and columns are the file's, and `spans` are the diagnostic's ranges (the
/// primary first, then its labels') mapped into `text`.
struct Excerpt {
    name: String,
    text: String,
    lines: Vec<ShownLine>,
    spans: Vec<SourceSpan>,
    /// The file's 0-based line and character column of the primary range's start: the
    /// header's position (a start inside a line break has no place in the excerpt's text).
    start: (usize, usize),
}

/// One line of the file in an excerpt.
struct ShownLine {
    /// The 0-based line number in the file.
    number: usize,
    /// The snippet it belongs to: lines of one snippet are consecutive in the file.
    block: usize,
    /// Its text in the excerpt, without the line break.
    range: std::ops::Range<usize>,
    /// Whether a `\n` follows it in the excerpt.
    has_break: bool,
    /// Where the file's line starts, where its text ends and where the next line starts.
    file: (usize, usize, usize),
    /// The parts of the line shown, in order.
    pieces: Vec<Piece>,
}

/// A run of a line's characters that an excerpt shows.
struct Piece {
    /// Its bytes in the file.
    file: std::ops::Range<usize>,
    /// Where it starts in the excerpt.
    start: usize,
    /// Its 0-based character column in the file's line.
    column: usize,
}

impl Excerpt {
    fn new(name: &str, src: &str, index: &LineIndex, d: &Diagnostic) -> Excerpt {
        let clamp = |o: usize| {
            let mut o = o.min(src.len());
            while !src.is_char_boundary(o) {
                o -= 1;
            }
            o
        };
        let line_of = |o: usize| index.position(src, o).line - 1;
        // Every marked range in the file: its bytes and its first and last lines.
        let mut marks: Vec<(usize, usize, usize, usize)> = Vec::new();
        for r in std::iter::once(&d.range).chain(d.labels.iter().map(|l| &l.range)) {
            let start = clamp(r.start);
            let mut end = clamp(r.end).max(start);
            let first = line_of(start);
            let mut last = if end > start { line_of(end - 1) } else { first };
            if last - first >= MAX_RANGE_LINES {
                end = index.line_range(src, first + 1).end.max(start);
                last = first;
            }
            marks.push((start, end, first, last));
        }
        // The lines to show: each marked range with a line of context either side, and the
        // lines between ranges close to each other.
        let lines_in_file = index.line_count();
        let mut wanted: Vec<(usize, usize)> = marks
            .iter()
            .map(|&(_, _, first, last)| {
                (first.saturating_sub(1), (last + 1).min(lines_in_file - 1))
            })
            .collect();
        wanted.sort_unstable();
        let mut blocks: Vec<(usize, usize)> = Vec::new();
        for (a, b) in wanted {
            match blocks.last_mut() {
                Some(last) if a <= last.1 + MAX_GAP + 1 => last.1 = last.1.max(b),
                _ => blocks.push((a, b)),
            }
        }
        let mut text = String::new();
        let mut lines = Vec::new();
        for (block, &(a, b)) in blocks.iter().enumerate() {
            for number in a..=b {
                let range = index.line_range(src, number + 1);
                let next = if number + 1 < lines_in_file {
                    index.line_range(src, number + 2).start
                } else {
                    src.len()
                };
                let points: Vec<usize> = marks
                    .iter()
                    .flat_map(|&(s, e, _, _)| [s, e])
                    .filter(|&o| range.start <= o && o <= range.end)
                    .collect();
                let start = text.len();
                let pieces = show_line(src, range.clone(), &points, &mut text);
                let has_break = next > range.end;
                let line = ShownLine {
                    number,
                    block,
                    range: start..text.len(),
                    has_break,
                    file: (range.start, range.end, next),
                    pieces,
                };
                if has_break {
                    text.push('\n');
                }
                lines.push(line);
            }
        }
        let p = index.position(src, marks[0].0);
        let start = (p.line - 1, p.column - 1);
        let name = hstl::load::escape_controls(name).into_owned();
        let mut excerpt = Excerpt { name, text, lines, spans: Vec::new(), start };
        excerpt.spans = marks
            .iter()
            .map(|&(s, e, _, _)| {
                let (a, b) = (excerpt.to_text(s), excerpt.to_text(e));
                SourceSpan::new(a.into(), b.saturating_sub(a))
            })
            .collect();
        excerpt
    }

    /// The excerpt's offset of a file offset on a shown line.
    fn to_text(&self, offset: usize) -> usize {
        let k = self.lines.partition_point(|l| l.file.0 <= offset).max(1) - 1;
        let Some(line) = self.lines.get(k) else { return 0 };
        if offset > line.file.1 {
            // Inside the line break.
            return line.range.end + usize::from(line.has_break);
        }
        for (i, p) in line.pieces.iter().enumerate() {
            if offset < p.file.start {
                return p.start;
            }
            if offset <= p.file.end {
                return p.start + (offset - p.file.start);
            }
            if i + 1 == line.pieces.len() {
                return line.range.end;
            }
        }
        line.range.start
    }

    /// The index of the shown line holding excerpt offset `offset`.
    fn line_at(&self, offset: usize) -> usize {
        self.lines.partition_point(|l| l.range.start <= offset).max(1) - 1
    }

    /// The file's 0-based character column of excerpt offset `offset` on line `k`.
    fn column(&self, k: usize, offset: usize) -> usize {
        let line = &self.lines[k];
        let mut column = 0;
        for p in &line.pieces {
            let end = p.start + (p.file.end - p.file.start);
            if offset < p.start {
                return p.column;
            }
            column =
                p.column + self.text.get(p.start..offset.min(end)).map_or(0, |s| s.chars().count());
            if offset <= end {
                return column;
            }
        }
        column
    }
}

/// Writes the line `range` of `src` into `out`, whole if short, else as windows around the
/// marked offsets `points` joined by an ellipsis; returns the pieces written.
fn show_line(
    src: &str,
    range: std::ops::Range<usize>,
    points: &[usize],
    out: &mut String,
) -> Vec<Piece> {
    let line = &src[range.clone()];
    // Most lines are short: no character count needed.
    if line.len() <= LONG_LINE || line.chars().count() <= LONG_LINE {
        let piece = Piece { file: range.clone(), start: out.len(), column: 0 };
        out.push_str(line);
        return vec![piece];
    }
    // Byte offsets (within the line) of the character boundaries WINDOW characters around
    // each point; merged where they overlap.
    let back = |o: usize| line[..o].char_indices().rev().nth(WINDOW - 1).map_or(0, |(i, _)| i);
    let ahead = |o: usize| line[o..].char_indices().nth(WINDOW).map_or(line.len(), |(i, _)| o + i);
    let mut windows: Vec<(usize, usize)> = if points.is_empty() {
        vec![(0, ahead(0))]
    } else {
        points.iter().map(|&p| p - range.start).map(|o| (back(o), ahead(o))).collect()
    };
    windows.sort_unstable();
    let mut merged: Vec<(usize, usize)> = Vec::new();
    for (a, b) in windows {
        match merged.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => merged.push((a, b)),
        }
    }
    let mut pieces = Vec::new();
    let mut column = 0;
    let mut counted = 0;
    for (a, b) in merged {
        if a > 0 {
            out.push_str(ELLIPSIS);
        }
        column += line[counted..a].chars().count();
        pieces.push(Piece { file: range.start + a..range.start + b, start: out.len(), column });
        out.push_str(&line[a..b]);
        column += line[a..b].chars().count();
        counted = b;
    }
    if counted < line.len() {
        out.push_str(ELLIPSIS);
    }
    pieces
}

impl miette::SourceCode for Excerpt {
    fn read_span<'a>(
        &'a self,
        span: &SourceSpan,
        before: usize,
        after: usize,
    ) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        let (start, len) = (span.offset(), span.len());
        if start + len > self.text.len() || self.lines.is_empty() {
            return Err(MietteError::OutOfBounds);
        }
        let (first, last) =
            (self.line_at(start), self.line_at((start + len).max(1) - 1).max(self.line_at(start)));
        let block = self.lines[first].block;
        if self.lines[last].block != block {
            return Err(MietteError::OutOfBounds);
        }
        let block_start =
            self.lines[..first].iter().rposition(|l| l.block != block).map_or(0, |i| i + 1);
        let block_end = self.lines[last..]
            .iter()
            .position(|l| l.block != block)
            .map_or(self.lines.len(), |i| last + i)
            - 1;
        let a = first.saturating_sub(before).max(block_start);
        let b = (last + after).min(block_end);
        let data_start = self.lines[a].range.start;
        let data_end = self.lines[b].range.end + usize::from(self.lines[b].has_break);
        let primary = self.spans.first().is_some_and(|p| p.offset() == start);
        let (line, column) = match before {
            0 if primary => self.start,
            0 => (self.lines[a].number, self.column(first, start)),
            _ => (self.lines[a].number, 0),
        };
        // Miette joins two snippets when the first one's line plus its line count reaches
        // the second one's line: counting to the end of the block joins exactly the
        // snippets of one block.
        let line_count = block_end - a + 1;
        Ok(Box::new(MietteSpanContents::new_named(
            self.name.clone(),
            &self.text.as_bytes()[data_start..data_end],
            SourceSpan::new(data_start.into(), data_end - data_start),
            line,
            column,
            line_count,
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every diagnostic range over texts with long lines, every line end and wide
    /// characters renders without a panic, in bounded size, with the position `concise`
    /// gives in its header, and underlines on the line it names.
    #[test]
    fn excerpts_show_every_range_at_its_position() {
        let long = format!("let A = {}x > 1;", "é && ".repeat(300));
        let texts = [
            "spec S {\n  let A = x;\n}\n".to_string(),
            "a\r\nbb\r\n\r\nccc".to_string(),
            "a\rbb\r\rccc\r".to_string(),
            format!("spec S {{\n{long}\n  task A;\n}}"),
            format!("{long}\r{long}"),
        ];
        for text in &texts {
            let index = LineIndex::new(text);
            let bounds: Vec<usize> =
                (0..=text.len()).filter(|&o| text.is_char_boundary(o)).collect();
            let step = (bounds.len() / 40).max(1);
            for &start in bounds.iter().step_by(step) {
                for &end in bounds.iter().filter(|&&e| e >= start).step_by(step * 3) {
                    let mut d = Diagnostic::new("HSTL002", start..end, "a message");
                    d = d.with_label(end..end, "here").with_label(0..1.min(text.len()), "first");
                    let file = Checked {
                        name: "t.hstl".into(),
                        source: text.clone(),
                        diagnostics: vec![d],
                    };
                    let shown = full(std::slice::from_ref(&file), false);
                    let p = index.position(text, start);
                    assert!(
                        shown.contains(&format!("[t.hstl:{}:{}]", p.line, p.column)),
                        "{start}..{end} of {text:?}:\n{shown}"
                    );
                    assert!(shown.len() < 3_000, "{start}..{end}: {} bytes", shown.len());
                }
            }
        }
    }
}
