//! Plain-text renderers: rustc-style (for tests and the macro's file errors), and the
//! one-line-per-diagnostic `concise` format that `hstlc check` prints and the Python
//! package's `SpecError` shows.

use std::fmt::Write as _;
use std::ops::Range;

use crate::diagnostic::{Diagnostic, Severity};
use crate::position::LineIndex;

/// One input's diagnostics with the text they point into.
#[derive(Clone, Copy, Debug)]
pub struct FileDiagnostics<'a> {
    /// The name to report: a path, or a name such as `<stdin>`.
    pub name: &'a str,
    /// The source text the diagnostics' ranges index.
    pub source: &'a str,
    /// The diagnostics, in the order to report them.
    pub diagnostics: &'a [Diagnostic],
}

/// The `concise` format: one line per diagnostic, `path:line:col: CODE severity: message`
/// (1-based, columns in characters), its help (if any) indented on the next line as
/// `  help: ...`, then the [`summary`] line; every line ends with `\n`.
pub fn render_concise(files: &[FileDiagnostics<'_>]) -> String {
    let mut out = String::new();
    for file in files {
        let index = LineIndex::new(file.source);
        for d in file.diagnostics {
            let start = index.position(file.source, d.range.start);
            let _ = writeln!(
                out,
                "{}:{}:{}: {} {}: {}",
                file.name,
                start.line,
                start.column,
                d.code,
                d.severity.as_str(),
                d.message
            );
            if let Some(help) = &d.help {
                let _ = writeln!(out, "  help: {help}");
            }
        }
    }
    out.push_str(&summary(files));
    out.push('\n');
    out
}

/// The line that ends the human formats: `checked 2 files: 1 error, 3 warnings`, or
/// `checked 1 file: no problems`.
pub fn summary(files: &[FileDiagnostics<'_>]) -> String {
    let all = || files.iter().flat_map(|f| f.diagnostics);
    let errors = all().filter(|d| d.severity == Severity::Error).count();
    let warnings = all().filter(|d| d.severity == Severity::Warning).count();
    let checked = plural(files.len(), "file");
    if errors + warnings == 0 {
        format!("checked {checked}: no problems")
    } else {
        format!("checked {checked}: {}, {}", plural(errors, "error"), plural(warnings, "warning"))
    }
}

fn plural(n: usize, word: &str) -> String {
    if n == 1 { format!("1 {word}") } else { format!("{n} {word}s") }
}

/// Renders diagnostics in the style of rustc, without colour:
///
/// ```text
/// error[HSTL003]: duplicate name `A`
///  --> spec.hstl:5:9
///   |
/// 5 |     let A = y > 1;
///   |         ^
///   |
///  ::: spec.hstl:4:9
///   |
/// 4 |     let A = x > 1;
///   |         - first defined here
///   = help: rename one of them
/// ```
pub fn render_plain(path: &str, src: &str, diagnostics: &[Diagnostic]) -> String {
    let index = LineIndex::new(src);
    let mut out = String::new();
    for d in diagnostics {
        let sev = d.severity.as_str();
        let mut lines: Vec<usize> = vec![index.position(src, d.range.start).line];
        lines.extend(d.labels.iter().map(|l| index.position(src, l.range.start).line));
        let width = lines.iter().max().copied().unwrap_or(1).to_string().len();
        let pad = " ".repeat(width);
        let p = index.position(src, d.range.start);
        let _ = writeln!(out, "{sev}[{}]: {}", d.code, d.message);
        let _ = writeln!(out, "{pad}--> {path}:{}:{}", p.line, p.column);
        let _ = writeln!(out, "{pad} |");
        snippet(&mut out, src, &index, &d.range, '^', "", width);
        for l in &d.labels {
            let lp = index.position(src, l.range.start);
            let _ = writeln!(out, "{pad} |");
            let _ = writeln!(out, "{pad}::: {path}:{}:{}", lp.line, lp.column);
            let _ = writeln!(out, "{pad} |");
            snippet(&mut out, src, &index, &l.range, '-', &l.message, width);
        }
        if let Some(h) = &d.help {
            let _ = writeln!(out, "{pad} = help: {h}");
        }
        out.push('\n');
    }
    out
}

/// Writes the first line of `range` with marks under the part of it the range covers.
fn snippet(
    out: &mut String,
    src: &str,
    index: &LineIndex,
    range: &Range<usize>,
    mark: char,
    message: &str,
    width: usize,
) {
    let p = index.position(src, range.start);
    let line = index.line_range(src, p.line);
    let text = src.get(line.clone()).unwrap_or("");
    let start = range.start.clamp(line.start, line.end);
    let end = range.end.clamp(start, line.end);
    let before = src.get(line.start..start).map_or(0, |s| s.chars().count());
    let under = src.get(start..end).map_or(0, |s| s.chars().count()).max(1);
    let pad = " ".repeat(width);
    let _ = writeln!(out, "{:>width$} | {}", p.line, text.replace('\t', " "));
    let marks: String = std::iter::repeat_n(mark, under).collect();
    let sep = if message.is_empty() { "" } else { " " };
    let _ = writeln!(out, "{pad} | {}{marks}{sep}{message}", " ".repeat(before));
}
