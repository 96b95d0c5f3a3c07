//! A plain rustc-style renderer, for tests and for the macro's file errors.

use std::fmt::Write as _;
use std::ops::Range;

use crate::diagnostic::{Diagnostic, Severity};
use crate::position::LineIndex;

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
        let sev = match d.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
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
