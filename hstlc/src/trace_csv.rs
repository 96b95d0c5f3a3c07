//! Reading traces from CSV for `hstlc monitor`, as a stream.
//!
//! The header names the columns; every state variable of the spec must be one of them,
//! each name once; other columns are ignored (and listed, so that the caller can say so).
//! Values are decimal numbers, `inf` or `-inf`; an `int` variable's values are whole numbers
//! inside its declared range. Fields are separated by commas and trimmed; quotes around a
//! header name are removed. Lines end at `\n`, `\r\n` or a lone `\r`; blank lines are
//! skipped; a byte order mark before the header is dropped.
//!
//! A dense-time spec's trace ([`TraceRows::next_dense_row`]) has the time column first: each
//! row's stamp (whole numbers read as integers, others as doubles; the facade's
//! [`hstl::monitor::StampRules`] decide which a trace takes and their order), and an empty
//! cell of another column is no new sample.
//!
//! Limits, checked while reading: a file holds at most [`MAX_TRACE_BYTES`], a line at most
//! [`MAX_LINE_BYTES`], the trace at most [`MAX_TRACE_VALUES`] values. The reader keeps one
//! line and the trace's columns in memory, never the file.
//!
//! This module depends on nothing else of the CLI: it is part of the crate's library, for
//! the fuzz target `trace_csv`.

use std::fmt;
use std::io::BufRead;

use hstl::lang::wording::thousands;
use hstl::robustness::Trace;

/// The largest trace file read: 1 GiB.
pub const MAX_TRACE_BYTES: u64 = 1 << 30;
/// The longest line of a trace: 1 MiB.
pub const MAX_LINE_BYTES: usize = 1 << 20;
/// The most values a trace may hold (rows times the spec's state variables): 2^25, which
/// take 256 MiB.
pub const MAX_TRACE_VALUES: usize = 1 << 25;

/// What a column must hold.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColumnKind {
    /// Any number, `inf` or `-inf`.
    Real,
    /// Whole numbers, inside `lo..=hi` when a range is declared.
    Int(Option<(i64, i64)>),
}

/// A column the spec needs: a state variable.
#[derive(Clone, Copy, Debug)]
pub struct Column<'a> {
    /// The state variable's name.
    pub name: &'a str,
    /// What its values must be.
    pub kind: ColumnKind,
}

/// A trace read from CSV.
#[derive(Debug)]
pub struct TraceRead {
    /// Column `i` is the `i`-th requested variable.
    pub trace: Trace,
    /// The header's names that are no state variable, in header order.
    pub ignored: Vec<String>,
    /// `(step, line)` for the first step and each step after skipped blank lines: enough to
    /// give any step's line without a number per row.
    lines: Vec<(usize, usize)>,
}

impl TraceRead {
    /// The line of the file that holds step `step`.
    pub fn line_of(&self, step: usize) -> usize {
        let k = self.lines.partition_point(|&(s, _)| s <= step);
        match k.checked_sub(1).and_then(|k| self.lines.get(k)) {
            Some(&(s, line)) => line + (step - s),
            None => 1,
        }
    }
}

/// Why a trace could not be read.
#[derive(Debug)]
pub enum ReadError {
    /// The text is not a valid trace.
    Csv(CsvError),
    /// Reading failed.
    Io(std::io::Error),
}

/// A problem in a CSV file, with its 1-based line and column (in characters).
#[derive(Debug, PartialEq)]
pub struct CsvError {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What is wrong.
    pub message: String,
    /// How to fix it.
    pub help: Option<String>,
}

impl fmt::Display for CsvError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}: {}", self.line, self.column, self.message)
    }
}

impl From<CsvError> for ReadError {
    fn from(e: CsvError) -> ReadError {
        ReadError::Csv(e)
    }
}

/// Reads a trace whose column `i` is `vars[i]` from `reader`.
pub fn read_trace(reader: impl BufRead, vars: &[Column<'_>]) -> Result<TraceRead, ReadError> {
    let mut rows = TraceRows::new(reader, vars, Limit::File)?;
    let mut columns = vec![Vec::new(); vars.len()];
    let mut state = vec![0.0; vars.len()];
    let mut count = 0usize;
    let mut lines: Vec<(usize, usize)> = Vec::new();
    while let Some(line) = rows.next_row(&mut state)? {
        if lines.last().is_none_or(|&(s, l)| l + (count - s) != line) {
            lines.push((count, line));
        }
        count += 1;
        if count.saturating_mul(vars.len()) > MAX_TRACE_VALUES {
            return Err(csv(
                line,
                1,
                format!(
                    "the trace holds more than {} values (rows times state variables)",
                    thousands(MAX_TRACE_VALUES as u64)
                ),
                "monitor a shorter stretch of it: split the file".to_string(),
            )
            .into());
        }
        for (col, &v) in columns.iter_mut().zip(&state) {
            col.push(v);
        }
    }
    if count == 0 {
        return Err(rows.no_samples().into());
    }
    let ignored = rows.ignored;
    let trace =
        Trace::from_columns(columns).map_err(|e| csv(1, 1, e.to_string(), String::new()))?;
    Ok(TraceRead { trace, ignored, lines })
}

/// A row's time stamp, as written: whole numbers are read as integers (never rounded
/// through a double), anything else as the nearest double.
pub use hstl::monitor::Stamp;

/// One row of a dense-time trace: its line, its stamp (with the stamp's column) and one
/// cell per variable, `None` where the cell is empty (no new sample).
#[derive(Debug)]
pub struct DenseRow {
    /// The 1-based line.
    pub line: usize,
    /// The time stamp.
    pub stamp: Stamp,
    /// The 1-based column (in characters) of the stamp.
    pub stamp_column: usize,
}

impl<R: BufRead> TraceRows<'_, R> {
    /// Reads the next row of a dense-time trace: `vars[0]` is the time column, and
    /// `cells[i]` receives `vars[i + 1]`'s cell (`None` where it is empty). `None` at the
    /// end of the input. Every cell of the first row must be filled.
    pub fn next_dense_row(
        &mut self,
        cells: &mut [Option<f64>],
        first: bool,
    ) -> Result<Option<DenseRow>, ReadError> {
        let help = "every row needs one field per header column (an empty one keeps the \
                    variable's value)";
        let Some((i, line)) = next_fields(&mut self.lines, &mut self.row, self.width, help)? else {
            return Ok(None);
        };
        let (time_pick, time) = (self.picks[0], self.vars[0].name);
        let (stamp_column, field) = (self.row[time_pick].0, &line[self.row[time_pick].1.clone()]);
        let stamp = stamp(field, time).map_err(|(m, h)| csv(i, stamp_column, m, h))?;
        for ((out, &pick), var) in cells.iter_mut().zip(&self.picks[1..]).zip(&self.vars[1..]) {
            let (column, field) = (self.row[pick].0, &line[self.row[pick].1.clone()]);
            *out = if field.is_empty() {
                if first {
                    return Err(csv(
                        i,
                        column,
                        format!("`{}` is empty in the first row", var.name),
                        format!(
                            "every variable needs a value at the first time stamp (no \
                             value exists before it): give `{}` one",
                            var.name
                        ),
                    )
                    .into());
                }
                None
            } else {
                Some(value(field, var).map_err(|(message, help)| csv(i, column, message, help))?)
            };
        }
        Ok(Some(DenseRow { line: i, stamp, stamp_column }))
    }
}

/// A time stamp: digits (with a sign) as an integer, any other number as a double.
fn stamp(field: &str, time: &str) -> Result<Stamp, (String, String)> {
    let help = || {
        format!(
            "`{time}` is the time variable: write each row's stamp as a finite number, such as \
             `0.02` or `1700000000123456789`"
        )
    };
    if field.is_empty() {
        return Err((format!("the time stamp in column `{time}` is empty"), help()));
    }
    let digits = field.strip_prefix(['-', '+']).unwrap_or(field);
    if !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()) {
        return match field.parse::<i128>() {
            Ok(n) if (i128::from(i64::MIN)..=i128::from(u64::MAX)).contains(&n) => {
                Ok(Stamp::Int(n))
            }
            _ => Err((format!("the time stamp `{field}` in column `{time}` is too large"), help())),
        };
    }
    match field.parse::<f64>() {
        Ok(t) if t.is_finite() => Ok(Stamp::Real(t)),
        _ => Err((
            format!("the time stamp `{field}` in column `{time}` is not a finite number"),
            help(),
        )),
    }
}

/// How much of a stream the reader takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Limit {
    /// A file: at most [`MAX_TRACE_BYTES`].
    File,
    /// An endless stream (`monitor --online`): any length, one line at a time.
    Stream,
}

/// A CSV trace read row by row: the header first, then one state per call, so that a
/// caller can act on each row as it arrives on a pipe.
pub struct TraceRows<'v, R> {
    lines: Lines<R>,
    vars: &'v [Column<'v>],
    /// The header's column count.
    width: usize,
    /// The header column of each state variable.
    picks: Vec<usize>,
    /// The header's names that are no state variable, in header order.
    pub ignored: Vec<String>,
    header_line: usize,
    /// Each field of the current row: its column and its byte range in the line.
    row: Vec<(usize, std::ops::Range<usize>)>,
}

impl<'v, R: BufRead> TraceRows<'v, R> {
    /// Reads the header (blank lines before it are skipped) and checks it against `vars`.
    pub fn new(reader: R, vars: &'v [Column<'v>], limit: Limit) -> Result<Self, ReadError> {
        let mut lines = Lines::new(reader, limit);
        let names: Vec<String> = loop {
            let Some((line, bytes)) = lines.next()? else {
                return Err(csv(
                    1,
                    1,
                    "the file is empty",
                    format!(
                        "the first line must name the columns, such as `{}`",
                        vars.iter().map(|v| v.name).collect::<Vec<_>>().join(",")
                    ),
                )
                .into());
            };
            let text = utf8(line, bytes)?;
            if text.trim().is_empty() {
                continue;
            }
            break header(line, text, vars)?;
        };
        let picks =
            vars.iter().map(|v| names.iter().position(|n| n == v.name).unwrap_or(0)).collect();
        let ignored = names
            .iter()
            .filter(|n| !n.is_empty() && !vars.iter().any(|v| v.name == *n))
            .cloned()
            .collect();
        let header_line = lines.number;
        Ok(TraceRows {
            lines,
            vars,
            width: names.len(),
            picks,
            ignored,
            header_line,
            row: Vec::with_capacity(names.len()),
        })
    }

    /// Reads the next row into `state` (`state[i]` is `vars[i]`) and returns its line
    /// number, or `None` at the end of the input. Blank lines are skipped.
    pub fn next_row(&mut self, state: &mut [f64]) -> Result<Option<usize>, ReadError> {
        let help = "every row needs one value per header column";
        let Some((i, line)) = next_fields(&mut self.lines, &mut self.row, self.width, help)? else {
            return Ok(None);
        };
        for ((out, &pick), var) in state.iter_mut().zip(&self.picks).zip(self.vars) {
            let (column, field) = (self.row[pick].0, &line[self.row[pick].1.clone()]);
            *out = value(field, var).map_err(|(message, help)| csv(i, column, message, help))?;
        }
        Ok(Some(i))
    }

    /// The error for a trace that ended right after its header.
    pub fn no_samples(&self) -> CsvError {
        csv(
            self.header_line,
            1,
            "the trace has no samples",
            "add one row per time step below the header".to_string(),
        )
    }
}

/// The next row that is not blank: its line number and text, its fields' columns and
/// byte ranges in `row`, checked to be `width` of them (`help` says what a row needs).
fn next_fields<'l, R: BufRead>(
    lines: &'l mut Lines<R>,
    row: &mut Vec<(usize, std::ops::Range<usize>)>,
    width: usize,
    help: &str,
) -> Result<Option<(usize, &'l str)>, ReadError> {
    let i = loop {
        let Some((i, bytes)) = lines.next()? else { return Ok(None) };
        if !utf8(i, bytes)?.trim().is_empty() {
            break i;
        }
    };
    // Read again, checked again: a borrow returned from inside the loop would hold `lines`.
    let line = utf8(i, &lines.line)?;
    row.clear();
    row.extend(field_ranges(line));
    if row.len() != width {
        let column = match row.get(width) {
            Some((column, _)) => *column,
            None => line.chars().count() + 1,
        };
        return Err(csv(
            i,
            column,
            format!("this row has {}, the header has {width}", fields_word(row.len())),
            help.to_string(),
        )
        .into());
    }
    Ok(Some((i, line)))
}

/// The header's names, checked: each variable present, no name twice.
fn header(line: usize, text: &str, vars: &[Column<'_>]) -> Result<Vec<String>, CsvError> {
    let fields: Vec<(usize, String)> =
        fields(text).map(|(c, f)| (c, f.trim_matches('"').to_string())).collect();
    let mut seen: std::collections::HashMap<&str, usize> = std::collections::HashMap::new();
    // Unnamed columns (such as after a trailing comma) are ignored, however many.
    for (column, name) in fields.iter().filter(|(_, n)| !n.is_empty()) {
        if let Some(first) = seen.insert(name, *column) {
            return Err(csv(
                line,
                *column,
                format!("the header names column `{name}` twice (first at column {first})"),
                "give each column its own name".to_string(),
            ));
        }
    }
    let names: Vec<String> = fields.into_iter().map(|(_, n)| n).collect();
    for var in vars {
        if !names.iter().any(|n| n == var.name) {
            return Err(csv(
                line,
                1,
                format!("missing column `{}`", var.name),
                format!(
                    "the header has {}; the spec's state variables are {}",
                    quote_list(names.iter().map(String::as_str)),
                    quote_list(vars.iter().map(|v| v.name))
                ),
            ));
        }
    }
    Ok(names)
}

/// The value of `field` for `var`, or what is wrong with it and how to fix it.
fn value(field: &str, var: &Column<'_>) -> Result<f64, (String, String)> {
    // NaN has no robustness meaning and is refused.
    let Some(v) = field.parse::<f64>().ok().filter(|v| !v.is_nan()) else {
        return Err((
            format!("`{field}` in column `{}` is not a number", var.name),
            "write a decimal number such as `3`, `-0.5` or `1e-3`, or `inf`".to_string(),
        ));
    };
    let ColumnKind::Int(range) = var.kind else { return Ok(v) };
    if !v.is_finite() || v.fract() != 0.0 {
        return Err((
            format!("`{field}` in column `{}` is not a whole number", var.name),
            format!("`{}` is an `int` state variable: write whole numbers such as `3`", var.name),
        ));
    }
    if let Some((lo, hi)) = range
        && (v < lo as f64 || v > hi as f64)
    {
        return Err((
            format!("`{field}` in column `{}` is outside its range {lo}..={hi}", var.name),
            format!(
                "the spec declares `{}: int in {lo}..={hi}`: widen the range or fix the trace",
                var.name
            ),
        ));
    }
    Ok(v)
}

fn csv(line: usize, column: usize, message: impl Into<String>, help: String) -> CsvError {
    CsvError { line, column, message: message.into(), help: (!help.is_empty()).then_some(help) }
}

/// The text of line `line`, or where it stops being UTF-8.
fn utf8(line: usize, bytes: &[u8]) -> Result<&str, CsvError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let good = std::str::from_utf8(&bytes[..e.valid_up_to()]).unwrap_or_default();
        csv(
            line,
            good.chars().count() + 1,
            "the file is not UTF-8 text",
            "save the trace as UTF-8 (plain CSV)".to_string(),
        )
    })
}

/// The lines of a byte stream, each without its line break, within the limits.
struct Lines<R> {
    reader: R,
    line: Vec<u8>,
    /// The last line ended with `\r`: a `\n` right after it belongs to that break.
    after_cr: bool,
    /// Bytes read so far.
    read: u64,
    /// The 1-based number of the line last returned.
    number: usize,
    limit: Limit,
}

impl<R: BufRead> Lines<R> {
    fn new(reader: R, limit: Limit) -> Self {
        Lines { reader, line: Vec::new(), after_cr: false, read: 0, number: 0, limit }
    }

    /// The next line and its number, or `None` at the end; a byte order mark at the start
    /// of the file is dropped.
    fn next(&mut self) -> Result<Option<(usize, &[u8])>, ReadError> {
        self.line.clear();
        let mut started = false;
        loop {
            let chunk = self.reader.fill_buf().map_err(ReadError::Io)?;
            if chunk.is_empty() {
                if !started {
                    return Ok(None);
                }
                break;
            }
            if std::mem::take(&mut self.after_cr) && chunk[0] == b'\n' {
                self.reader.consume(1);
                self.read += 1;
                continue;
            }
            started = true;
            let (take, done) = match chunk.iter().position(|&b| b == b'\n' || b == b'\r') {
                Some(k) => {
                    self.after_cr = chunk[k] == b'\r';
                    self.line.extend_from_slice(&chunk[..k]);
                    (k + 1, true)
                }
                None => {
                    self.line.extend_from_slice(chunk);
                    (chunk.len(), false)
                }
            };
            self.reader.consume(take);
            self.read += take as u64;
            self.within_limits()?;
            if done {
                break;
            }
        }
        self.number += 1;
        if self.number == 1 && self.line.starts_with("\u{feff}".as_bytes()) {
            self.line.drain(..3);
        }
        Ok(Some((self.number, &self.line)))
    }

    fn within_limits(&self) -> Result<(), CsvError> {
        let line = self.number + 1;
        if self.limit == Limit::File && self.read > MAX_TRACE_BYTES {
            return Err(csv(
                line,
                1,
                format!(
                    "the file is larger than {} MiB, the limit for a trace",
                    MAX_TRACE_BYTES >> 20
                ),
                "monitor a shorter stretch of it: split the file".to_string(),
            ));
        }
        if self.line.len() > MAX_LINE_BYTES {
            return Err(csv(
                line,
                1,
                format!("line {line} is longer than {} MiB", MAX_LINE_BYTES >> 20),
                "a trace has one short row per time step: check that this is a CSV file"
                    .to_string(),
            ));
        }
        Ok(())
    }
}

/// The fields of one line with the 1-based character column where each starts, trimmed.
fn fields(line: &str) -> impl Iterator<Item = (usize, &str)> {
    field_ranges(line).map(|(column, range)| (column, &line[range]))
}

/// The fields of one line: the 1-based character column where each starts and its byte
/// range, trimmed.
fn field_ranges(line: &str) -> impl Iterator<Item = (usize, std::ops::Range<usize>)> + '_ {
    let mut column = 1;
    let mut offset = 0;
    line.split(',').map(move |raw| {
        let trimmed = raw.trim_start();
        let lead = raw.len() - trimmed.len();
        let start = column + raw[..lead].chars().count();
        let range = offset + lead..offset + lead + trimmed.trim_end().len();
        column += raw.chars().count() + 1;
        offset += raw.len() + 1;
        (start, range)
    })
}

fn fields_word(n: usize) -> String {
    if n == 1 { "1 field".into() } else { format!("{n} fields") }
}

fn quote_list<'a>(items: impl Iterator<Item = &'a str>) -> String {
    items.map(|s| format!("`{s}`")).collect::<Vec<_>>().join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    const XY: [Column<'static>; 2] = [
        Column { name: "x", kind: ColumnKind::Real },
        Column { name: "y", kind: ColumnKind::Real },
    ];

    fn read(text: &str, vars: &[Column<'_>]) -> Result<TraceRead, CsvError> {
        read_trace(text.as_bytes(), vars).map_err(|e| match e {
            ReadError::Csv(e) => e,
            ReadError::Io(e) => panic!("reading a slice failed: {e}"),
        })
    }

    fn err(text: &str) -> (usize, usize, String) {
        err_with(text, &XY)
    }

    fn err_with(text: &str, vars: &[Column<'_>]) -> (usize, usize, String) {
        let e = read(text, vars).unwrap_err();
        (e.line, e.column, e.message)
    }

    #[test]
    fn reads_named_columns_in_spec_order() {
        let t = read("t,y,x\n0,1,2\n1,3,-inf\n", &XY).unwrap();
        assert_eq!(t.trace.column(0), &[2.0, f64::NEG_INFINITY]);
        assert_eq!(t.trace.column(1), &[1.0, 3.0]);
        assert_eq!(t.ignored, ["t"]);
    }

    #[test]
    fn locates_bad_input() {
        assert_eq!(err(""), (1, 1, "the file is empty".into()));
        assert_eq!(err("x,z\n1,2\n"), (1, 1, "missing column `y`".into()));
        assert_eq!(err("x,y\n1, oops\n"), (2, 4, "`oops` in column `y` is not a number".into()));
        assert_eq!(err("x,y\n1,2\n1\n"), (3, 2, "this row has 1 field, the header has 2".into()));
        assert_eq!(err("x,y\n1,2,3\n"), (2, 5, "this row has 3 fields, the header has 2".into()));
        assert_eq!(err("x,y\n"), (1, 1, "the trace has no samples".into()));
        assert_eq!(err("x,y\nNaN,1\n"), (2, 1, "`NaN` in column `x` is not a number".into()));
    }

    #[test]
    fn every_line_break_style_and_a_byte_order_mark() {
        for text in ["\u{feff}x,y\n1,2\n3,4\n", "x,y\r1,2\r3,4\r", "x,y\r\n1,2\r\n3,4"] {
            let t = read(text, &XY).unwrap();
            assert_eq!(t.trace.column(1), &[2.0, 4.0], "{text:?}");
        }
        // The bad value is on line 3 whatever ends the lines.
        for text in ["x,y\r1,2\r3,z\r", "x,y\r\n1,2\r\n3,z\r\n", "\u{feff}x,y\n1,2\n3,z\n"] {
            assert_eq!(err(text), (3, 3, "`z` in column `y` is not a number".into()), "{text:?}");
        }
    }

    #[test]
    fn a_name_twice_in_the_header_is_an_error() {
        assert_eq!(
            err("x,y, x\n1,2,3\n"),
            (1, 6, "the header names column `x` twice (first at column 1)".into())
        );
        assert_eq!(
            err("x,y,t,t\n1,2,3,4\n"),
            (1, 7, "the header names column `t` twice (first at column 5)".into())
        );
    }

    #[test]
    fn int_columns_hold_whole_numbers_in_range() {
        let vars = [
            Column { name: "x", kind: ColumnKind::Int(Some((0, 14))) },
            Column { name: "y", kind: ColumnKind::Int(None) },
        ];
        assert!(read("x,y\n0,-7\n14,1e3\n", &vars).is_ok());
        assert_eq!(
            err_with("x,y\n1.5,2\n", &vars),
            (2, 1, "`1.5` in column `x` is not a whole number".into())
        );
        assert_eq!(
            err_with("x,y\n15,2\n", &vars),
            (2, 1, "`15` in column `x` is outside its range 0..=14".into())
        );
        assert_eq!(
            err_with("x,y\n1,inf\n", &vars),
            (2, 3, "`inf` in column `y` is not a whole number".into())
        );
    }

    #[test]
    fn limits_are_errors_not_allocations() {
        // A line without an end (such as `/dev/zero`) stops at the line limit.
        let long = vec![b'0'; MAX_LINE_BYTES + 10];
        let e = read_trace(&long[..], &XY).unwrap_err();
        let ReadError::Csv(e) = e else { panic!("not a CSV error") };
        assert_eq!((e.line, e.message.as_str()), (1, "line 1 is longer than 1 MiB"));
        // Not UTF-8: the column of the first bad byte.
        assert_eq!(err_with_bytes(b"x,y\n1,\xff\n"), (2, 3, "the file is not UTF-8 text".into()));
    }

    fn err_with_bytes(bytes: &[u8]) -> (usize, usize, String) {
        match read_trace(bytes, &XY).unwrap_err() {
            ReadError::Csv(e) => (e.line, e.column, e.message),
            ReadError::Io(e) => panic!("{e}"),
        }
    }
}
