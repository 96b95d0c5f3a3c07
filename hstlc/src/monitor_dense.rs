//! `hstlc monitor` on a dense-time spec (one with a `time` variable): the trace's time
//! column holds each row's stamp, an empty cell is no new sample, and the output's times
//! are in the time column's own scale.
//!
//! One trace: the robustness at the first stamp, or `t,robustness` rows at the change
//! points of the signal with `--signal`. Several traces: one `trace,robustness` row each
//! (`trace,t,robustness` rows with `--signal`). `--online`: the change points printed as
//! soon as no later row can change them. The facade computes ([`hstl::monitor::Dense`]);
//! this module reads and prints.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};

use hstl::lang::CheckedSpec;
use hstl::monitor::{Dense, DenseProblem, time_text};
use hstl::robustness::dense::{DenseTrace, DenseTraceBuilder, DenseTraceError};

use crate::cli_error::CliError;
use crate::monitor::{MonitorArgs, Windows, columns, note_ignored, read_error, trace_name};
use crate::output::{errln, outln};
use crate::trace_csv::{
    Column, ColumnKind, DenseRow, Limit, MAX_TRACE_VALUES, ReadError, Stamp, StampOrder, TraceRows,
};
use crate::{CmdResult, Status};

/// A dense-time trace read whole, with the line of every row.
struct DenseRead {
    trace: DenseTrace,
    ignored: Vec<String>,
    lines: Vec<usize>,
}

/// Runs `hstlc monitor` for the dense-time spec `spec` (from the file `name`).
pub fn run(args: &MonitorArgs, spec: &CheckedSpec, name: &str, traces: &[PathBuf]) -> CmdResult {
    if args.windows == Windows::Complete {
        return Err(CliError::new(
            format!(
                "{name}: `--windows complete` is not supported yet for dense-time specs (spec \
                 `{}` has a `time` variable)",
                spec.name
            ),
            Some(
                "leave it out: a dense-time window is never cut at the end of the trace (after \
                 the last stamp every variable keeps its last value)"
                    .to_string(),
            ),
        ));
    }
    let monitor = Dense::new(spec, args.formula.as_deref()).map_err(|e| {
        let help = match &e {
            hstl::lower::LowerError::UnknownLet { .. } => {
                Some("leave out `--formula` to score the task".to_string())
            }
            _ => None,
        };
        CliError::new(format!("{name}: {e}"), help)
    })?;
    let gap = args.max_gap.as_deref().map(MaxGap::parse).transpose()?;
    let mut cols = vec![Column { name: monitor.time_var(), kind: ColumnKind::Real }];
    cols.extend(columns(spec));
    let opts = Options { gap: gap.as_ref(), relative: args.relative };
    if args.online {
        return online(&monitor, &cols, &traces[0], spec, args.formula.as_deref(), opts);
    }
    let batch = traces.len() > 1 || args.trace.iter().any(|t| t.is_dir());
    let mut scored = Vec::with_capacity(traces.len());
    let mut ignored: Vec<String> = Vec::new();
    for path in traces {
        let read = read_dense(path, &cols, &monitor, opts.gap)?;
        for n in &read.ignored {
            if !ignored.contains(n) {
                ignored.push(n.clone());
            }
        }
        let signal = monitor.signal(&read.trace).map_err(|e| located(path, &read, e))?;
        let times =
            Times { relative: opts.relative, origin: read.trace.origin(), t0: read.trace.t0() };
        let rows: Vec<(String, f64)> = if args.signal {
            signal.until(read.trace.t_last()).map(|(t, v)| (times.text(t), v)).collect()
        } else {
            vec![(String::new(), signal.first())]
        };
        scored.push((path, rows));
    }
    note_ignored(&ignored, spec);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let written = match (batch, args.signal) {
        (false, true) => writeln!(out, "t,robustness")
            .and_then(|()| scored[0].1.iter().try_for_each(|(t, v)| writeln!(out, "{t},{v}"))),
        (false, false) => writeln!(out, "{}", scored[0].1[0].1),
        (true, true) => writeln!(out, "trace,t,robustness").and_then(|()| {
            scored.iter().try_for_each(|(path, rows)| {
                let name = csv_field(&trace_name(path));
                rows.iter().try_for_each(|(t, v)| writeln!(out, "{name},{t},{v}"))
            })
        }),
        (true, false) => writeln!(out, "trace,robustness").and_then(|()| {
            scored.iter().try_for_each(|(path, rows)| {
                writeln!(out, "{},{}", csv_field(&trace_name(path)), rows[0].1)
            })
        }),
    }
    .and_then(|()| out.flush());
    written.map_err(crate::output::stdout_error)?;
    Ok(Status::Clean)
}

/// Opens a trace (standard input for `-`).
fn open(path: &Path) -> Result<Box<dyn BufRead>, CliError> {
    if path == Path::new("-") {
        return Ok(Box::new(std::io::stdin().lock()));
    }
    let file = std::fs::File::open(path)
        .map_err(|source| CliError::Read { path: path.to_path_buf(), source })?;
    Ok(Box::new(BufReader::new(file)))
}

/// Reads a whole dense-time trace: `cols[0]` is the time column.
fn read_dense(
    path: &Path,
    cols: &[Column<'_>],
    monitor: &Dense,
    gap: Option<&MaxGap>,
) -> Result<DenseRead, CliError> {
    let name = trace_name(path);
    let mut rows =
        TraceRows::new(open(path)?, cols, Limit::File).map_err(|e| read_error(&name, e))?;
    let mut builder = DenseTraceBuilder::new(cols.len() - 1);
    let mut order = StampOrder::default();
    let mut cells = vec![None; cols.len() - 1];
    let mut lines = Vec::new();
    let mut gaps = Gaps::default();
    while let Some(row) =
        rows.next_dense_row(&mut cells, lines.is_empty()).map_err(|e| read_error(&name, e))?
    {
        let stamp =
            order.next(&row, cols[0].name).map_err(|e| read_error(&name, ReadError::Csv(e)))?;
        gaps.check(gap, stamp, &row, &name, cols[0].name)?;
        if (lines.len() + 1).saturating_mul(cols.len()) > MAX_TRACE_VALUES {
            return Err(CliError::new(
                format!(
                    "{name}:{}:1: the trace holds more than {MAX_TRACE_VALUES} values (rows \
                     times columns)",
                    row.line
                ),
                Some("monitor a shorter stretch of it: split the file".to_string()),
            ));
        }
        push(&mut builder, stamp, &cells).map_err(|e| stamp_error(&name, &row, monitor, e))?;
        lines.push(row.line);
    }
    if lines.is_empty() {
        return Err(read_error(&name, ReadError::Csv(rows.no_samples())));
    }
    let ignored = rows.ignored;
    let trace = builder.build().map_err(|e| CliError::new(format!("{name}: {e}"), None))?;
    Ok(DenseRead { trace, ignored, lines })
}

fn push(
    b: &mut DenseTraceBuilder,
    stamp: Stamp,
    cells: &[Option<f64>],
) -> Result<(), DenseTraceError> {
    match stamp {
        Stamp::Int(s) => b.push_int(s, cells),
        Stamp::Real(t) => b.push(t, cells),
    }
}

/// A stamp the trace cannot take (the reader checked everything else), at its cell.
fn stamp_error(name: &str, row: &DenseRow, monitor: &Dense, e: DenseTraceError) -> CliError {
    let p = monitor.problem(hstl::robustness::dense::DenseError::Trace(e));
    CliError::new(format!("{name}:{}:{}: {}", row.line, row.stamp_column, p.message), p.help)
}

/// The monitor's error on a trace read whole, at the line of its row where it has one.
fn located(path: &Path, read: &DenseRead, p: DenseProblem) -> CliError {
    let times = read.trace.times();
    // A time falls in the row whose stamp is the last at or before it.
    let row = p.row.or_else(|| p.time.map(|t| times.partition_point(|&s| s <= t).max(1) - 1));
    let line = row.and_then(|r| read.lines.get(r)).copied().unwrap_or(1);
    CliError::new(
        format!("{}:{line}:1: {}{}", trace_name(path), p.message, at_time(&p, read.trace.origin())),
        p.help,
    )
}

/// ` at time T` for a problem about a time, in the time column's scale.
fn at_time(p: &DenseProblem, origin: Option<i128>) -> String {
    p.time.map_or_else(String::new, |t| format!(" at time {}", time_text(origin, t)))
}

/// `--online`: each change point printed (and flushed) once no later row can change it.
fn online(
    monitor: &Dense,
    cols: &[Column<'_>],
    path: &Path,
    spec: &CheckedSpec,
    formula: Option<&str>,
    opts: Options<'_>,
) -> CmdResult {
    let name = trace_name(path);
    let mut rows =
        TraceRows::new(open(path)?, cols, Limit::Stream).map_err(|e| read_error(&name, e))?;
    note_ignored(&rows.ignored, spec);
    let mut live = monitor.online().map_err(|p| CliError::new(format!("{name}: {p}"), p.help))?;
    let what = formula.map_or_else(|| "the task".to_string(), |f| format!("`{f}`"));
    let bounded = monitor.formula().future_reach().is_finite();
    if !bounded {
        errln!(
            "note: {what} has an unbounded future operator (such as `always`): no value is \
             final before the input ends, so the rows follow at its end, and the stream may \
             hold at most {MAX_TRACE_VALUES} values"
        );
    }
    outln!("t,robustness")?;
    let mut order = StampOrder::default();
    let mut cells = vec![None; cols.len() - 1];
    let mut count = 0usize;
    let mut gaps = Gaps::default();
    let mut times = Times { relative: opts.relative, origin: None, t0: 0.0 };
    while let Some(row) =
        rows.next_dense_row(&mut cells, count == 0).map_err(|e| read_error(&name, e))?
    {
        let stamp =
            order.next(&row, cols[0].name).map_err(|e| read_error(&name, ReadError::Csv(e)))?;
        gaps.check(opts.gap, stamp, &row, &name, cols[0].name)?;
        if count == 0
            && let Stamp::Real(t) = stamp
        {
            times.t0 = t;
        }
        count += 1;
        if live.kept().saturating_add(1).saturating_mul(cols.len()) > MAX_TRACE_VALUES {
            return Err(CliError::new(
                format!(
                    "{name}:{}:1: the monitor holds more than {MAX_TRACE_VALUES} values, and \
                     {what} keeps every row its windows read",
                    row.line
                ),
                Some(
                    "monitor a formula with bounded windows (`--formula` with a `let`), or end \
                     the stream sooner"
                        .to_string(),
                ),
            ));
        }
        let decided = match stamp {
            Stamp::Int(s) => live.push_int(s, &cells),
            Stamp::Real(t) => live.push(t, &cells),
        }
        .map_err(|e| {
            let p = monitor.problem(e);
            let when = at_time(&p, live.origin());
            CliError::new(
                format!("{name}:{}:{}: {}{when}", row.line, row.stamp_column, p.message),
                p.help,
            )
        })?;
        times.origin = live.origin();
        for (t, v) in decided {
            outln!("{},{v}", times.text(t))?;
        }
    }
    if count == 0 {
        return Err(read_error(&name, ReadError::Csv(rows.no_samples())));
    }
    let origin = live.origin();
    let rest = live.finish().map_err(|e| {
        let p = monitor.problem(e);
        CliError::new(format!("{name}: {}{}", p.message, at_time(&p, origin)), p.help)
    })?;
    for (t, v) in rest {
        outln!("{},{v}", times.text(t))?;
    }
    Ok(Status::Clean)
}

/// A CSV field, quoted when it holds a comma, a quote or a line break.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_string()
    }
}

/// The options that shape reading and printing a dense-time trace.
#[derive(Clone, Copy)]
struct Options<'a> {
    gap: Option<&'a MaxGap>,
    relative: bool,
}

/// How the output's times print: in the time column's scale, or relative to the first
/// stamp (`--relative`).
struct Times {
    relative: bool,
    /// The first whole-number stamp, when stamps are whole numbers beyond 2^53 (the times
    /// are then relative to it already, computed in integer arithmetic).
    origin: Option<i128>,
    /// The first stamp, when stamps are doubles.
    t0: f64,
}

impl Times {
    fn text(&self, t: f64) -> String {
        match (self.relative, self.origin) {
            (false, origin) => time_text(origin, t),
            (true, Some(_)) => t.to_string(),
            // Exact: the difference of the two times as they print.
            (true, None) => decimal_difference(&t.to_string(), &self.t0.to_string()),
        }
    }
}

/// `--max-gap`: the bound exactly as written (`digits / 10^decimals`) and as the nearest
/// double.
struct MaxGap {
    text: String,
    digits: u128,
    decimals: u32,
    bound: f64,
}

impl MaxGap {
    fn parse(text: &str) -> Result<MaxGap, CliError> {
        let bad = || {
            CliError::new(
                format!("`--max-gap {text}` is not a time: give a number of 0 or more"),
                Some(
                    "the gap is in the time column's unit, such as `0.5` for stamps in \
                     seconds or `500000000` for nanoseconds"
                        .to_string(),
                ),
            )
        };
        let bound: f64 = text.trim().parse().map_err(|_| bad())?;
        if !(bound.is_finite() && bound >= 0.0) {
            return Err(bad());
        }
        // A number, but one whose exact value has more digits than the exact comparison of
        // gaps holds (`1e300`, 39 digits and more).
        let (digits, decimals) = hstl::robustness::dense::TimeScale::parse_decimal(text)
            .ok_or_else(|| {
                CliError::new(
                    format!(
                        "`--max-gap {text}` has more digits than a gap is compared with \
                         exactly: at most 38 in all, with the zeros an exponent stands for"
                    ),
                    Some(
                        "write the gap with at most 38 digits, such as `1e37`, or leave \
                         `--max-gap` out"
                            .to_string(),
                    ),
                )
            })?;
        Ok(MaxGap { text: text.trim().to_string(), digits, decimals, bound })
    }

    /// Whether the gap from `prev` to `now` is larger than the bound, computed exactly;
    /// with the gap as written.
    fn exceeded(&self, prev: Stamp, now: Stamp) -> Option<String> {
        match (prev, now) {
            (Stamp::Int(p), Stamp::Int(s)) => {
                let gap = u128::try_from(s - p).unwrap_or(0);
                // gap > digits / 10^decimals, with no rounding (an overflow is larger).
                let scaled = 10u128.checked_pow(self.decimals).and_then(|m| gap.checked_mul(m));
                scaled.is_none_or(|g| g > self.digits).then(|| gap.to_string())
            }
            (Stamp::Real(p), Stamp::Real(s)) => {
                // `d` is `s - p` rounded and `err` the rounding error (Knuth's two-sum):
                // rounding is monotone, so the exact gap exceeds the bound exactly when
                // `d` does, or `d` equals it and the error is positive.
                let d = s - p;
                let sv = d + p;
                let err = (s - sv) + (-p - (d - sv));
                (d > self.bound || d == self.bound && err > 0.0)
                    .then(|| decimal_difference(&s.to_string(), &p.to_string()))
            }
            // A trace's stamps are all of one kind (`StampOrder`).
            _ => None,
        }
    }
}

/// The previous row's stamp and line, for `--max-gap`.
#[derive(Default)]
struct Gaps {
    last: Option<(Stamp, usize)>,
}

impl Gaps {
    /// An error if the gap from the previous row to `row` (with stamp `stamp`) is larger
    /// than `gap`.
    fn check(
        &mut self,
        gap: Option<&MaxGap>,
        stamp: Stamp,
        row: &DenseRow,
        name: &str,
        time: &str,
    ) -> Result<(), CliError> {
        let Some(gap) = gap else { return Ok(()) };
        if let Some((prev, line)) = self.last
            && let Some(width) = gap.exceeded(prev, stamp)
        {
            return Err(CliError::new(
                format!(
                    "{name}:{}:{}: the time stamp {} in column `{time}` comes {width} after the \
                     previous one, {} (line {line}): more than `--max-gap {}`",
                    row.line,
                    row.stamp_column,
                    stamp_text(stamp),
                    stamp_text(prev),
                    gap.text
                ),
                Some(
                    "each variable would keep its value across the gap: fill the gap with \
                     samples, monitor the parts before and after it separately, or raise \
                     `--max-gap`"
                        .to_string(),
                ),
            ));
        }
        self.last = Some((stamp, row.line));
        Ok(())
    }
}

fn stamp_text(stamp: Stamp) -> String {
    match stamp {
        Stamp::Int(n) => n.to_string(),
        Stamp::Real(t) => t.to_string(),
    }
}

/// `a - b` for two decimals as Rust prints doubles (`-12.5`, `0.001`: no exponent),
/// exactly, printed the same way.
fn decimal_difference(a: &str, b: &str) -> String {
    fn parts(x: &str) -> (bool, &str, &str) {
        let (neg, x) = x.strip_prefix('-').map_or((false, x), |r| (true, r));
        let (int, frac) = x.split_once('.').unwrap_or((x, ""));
        (neg, int, frac)
    }
    let ((na, ia, fa), (nb, ib, fb)) = (parts(a), parts(b));
    let scale = fa.len().max(fb.len());
    // One more integer digit than either, for a carry.
    let width = ia.len().max(ib.len()) + 1;
    let digits = |int: &str, frac: &str| {
        let mut v = vec![0u8; width - int.len()];
        v.extend(int.bytes().chain(frac.bytes()).map(|c| c.wrapping_sub(b'0')));
        v.resize(width + scale, 0);
        v
    };
    let (da, db) = (digits(ia, fa), digits(ib, fb));
    // `a - b` is `±(|a| + |b|)` for opposite signs, `±(|a| - |b|)` otherwise.
    let (neg, mag) = if na != nb {
        (na, add_digits(&da, &db))
    } else if da >= db {
        (na, sub_digits(&da, &db))
    } else {
        (!na, sub_digits(&db, &da))
    };
    let text = |d: &[u8]| d.iter().map(|&c| char::from(b'0' + c)).collect::<String>();
    let int = text(&mag[..width]);
    let int = int.trim_start_matches('0');
    let frac = text(&mag[width..]);
    let frac = frac.trim_end_matches('0');
    if int.is_empty() && frac.is_empty() {
        return "0".to_string();
    }
    let sign = if neg { "-" } else { "" };
    let int = if int.is_empty() { "0" } else { int };
    if frac.is_empty() { format!("{sign}{int}") } else { format!("{sign}{int}.{frac}") }
}

/// The sum of two equally long digit strings (most significant first; no overflow out of
/// the first digit).
fn add_digits(a: &[u8], b: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; a.len()];
    let mut carry = 0u8;
    for k in (0..a.len()).rev() {
        let s = a[k] + b[k] + carry;
        out[k] = s % 10;
        carry = s / 10;
    }
    out
}

/// `a - b` for two equally long digit strings with `a >= b`.
fn sub_digits(a: &[u8], b: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; a.len()];
    let mut borrow = 0u8;
    for k in (0..a.len()).rev() {
        let (d, sub) = (a[k], b[k] + borrow);
        if d >= sub {
            out[k] = d - sub;
            borrow = 0;
        } else {
            out[k] = d + 10 - sub;
            borrow = 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_differences_are_exact() {
        assert_eq!(decimal_difference("0.3", "0.1"), "0.2");
        assert_eq!(decimal_difference("1700000000.4", "1700000000"), "0.4");
        assert_eq!(decimal_difference("5", "-2.25"), "7.25");
        assert_eq!(decimal_difference("-2.25", "5"), "-7.25");
        assert_eq!(decimal_difference("-1", "-3.5"), "2.5");
        assert_eq!(decimal_difference("0.1", "0.3"), "-0.2");
        assert_eq!(decimal_difference("99.99", "0.01"), "99.98");
        assert_eq!(decimal_difference("99.99", "-0.01"), "100");
        assert_eq!(decimal_difference("2", "2"), "0");
        assert_eq!(decimal_difference("-0", "0"), "0");
        assert_eq!(decimal_difference("0.30000000000000004", "0"), "0.30000000000000004");
    }

    #[test]
    fn gaps_compare_exactly() {
        let g = MaxGap::parse("0.1").expect("a time");
        // 0.3 - 0.2 (as doubles) is exactly 0.0999999999999999778: below the double 0.1.
        assert!(g.exceeded(Stamp::Real(0.2), Stamp::Real(0.3)).is_none());
        assert!(g.exceeded(Stamp::Real(0.0), Stamp::Real(0.1)).is_none());
        assert_eq!(g.exceeded(Stamp::Real(0.0), Stamp::Real(0.25)).as_deref(), Some("0.25"));
        let ns = MaxGap::parse("0.5").expect("a time");
        let t = 1_700_000_000_000_000_000i128;
        assert!(ns.exceeded(Stamp::Int(t), Stamp::Int(t + 1)).is_some());
        let ns = MaxGap::parse("500000000").expect("a time");
        assert!(ns.exceeded(Stamp::Int(t), Stamp::Int(t + 500_000_000)).is_none());
        assert_eq!(
            ns.exceeded(Stamp::Int(t), Stamp::Int(t + 500_000_001)).as_deref(),
            Some("500000001")
        );
        assert!(MaxGap::parse("-1").is_err());
        assert!(MaxGap::parse("inf").is_err());
    }
}
