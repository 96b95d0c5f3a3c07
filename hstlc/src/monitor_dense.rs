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
use hstl::monitor::{
    Dense, DenseLive, DenseProblem, Front, MaxGap, Place, TimeAxis, Windows as Semantics,
    signal_rows, time_text,
};
use hstl::robustness::dense::DenseTrace;

use crate::cli_error::CliError;
use crate::monitor_input::{MonitorArgs, Windows, columns, note_ignored, read_error, trace_name};
use crate::output::{errln, outln};
use crate::trace_csv::{
    Column, ColumnKind, DenseRow, Limit, MAX_TRACE_VALUES, ReadError, TraceRows,
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
    let windows = match args.windows {
        Windows::Clipped => Semantics::Clipped,
        Windows::Complete => Semantics::Complete,
    };
    let monitor = Dense::new(spec, args.formula.as_deref()).map_err(|e| {
        let help = match &e {
            hstl::lower::LowerError::UnknownLet { .. } => {
                Some("leave out `--formula` to score the task".to_string())
            }
            _ => None,
        };
        CliError::new(format!("{name}: {e}"), help)
    })?;
    let gap = args
        .max_gap
        .as_deref()
        .map(|text| MaxGap::parse(text, "--max-gap ").map_err(|p| CliError::new(p.message, p.help)))
        .transpose()?;
    let mut cols = vec![Column { name: monitor.time_var(), kind: ColumnKind::Real }];
    cols.extend(columns(spec));
    if args.online {
        let live = monitor
            .live(gap, windows, Front::Cli)
            .map_err(|p| CliError::new(format!("{name}: {}", p.message), p.help))?
            .relative(args.relative);
        return online(&monitor, live, &cols, &traces[0], spec);
    }
    let opts = Options { gap: gap.as_ref(), relative: args.relative };
    let batch = traces.len() > 1 || args.trace.iter().any(|t| t.is_dir());
    let mut scored = Vec::with_capacity(traces.len());
    let mut ignored: Vec<String> = Vec::new();
    // Traces with undetermined times (complete windows), and the times they start at.
    let mut open: Vec<(String, Option<String>)> = Vec::new();
    for path in traces {
        let read = read_dense(path, &cols, &monitor, opts.gap.cloned())?;
        for n in &read.ignored {
            if !ignored.contains(n) {
                ignored.push(n.clone());
            }
        }
        let (signal, end) =
            monitor.signal_in(&read.trace, windows).map_err(|e| located(path, &read, e))?;
        let times =
            TimeAxis { relative: opts.relative, origin: read.trace.origin(), t0: read.trace.t0() };
        let (t0, t_last) = (read.trace.t0(), read.trace.t_last());
        let cell = |v: Option<f64>| v.map_or_else(String::new, |v| v.to_string());
        let rows: Vec<(String, String)> = if args.signal {
            signal_rows(&signal, t0, t_last, end)
                .into_iter()
                .map(|(t, v)| (times.text(t), cell(v)))
                .collect()
        } else {
            let first = end.is_none_or(|e| e >= t0).then(|| signal.first());
            vec![(
                String::new(),
                first.map_or_else(|| "undetermined".to_string(), |v| v.to_string()),
            )]
        };
        if let Some(end) = end.filter(|&e| e < t_last && (args.signal || e < t0)) {
            open.push((trace_name(path), (end >= t0).then(|| times.text(end))));
        }
        scored.push((path, rows));
    }
    note_ignored(&ignored, spec);
    note_open(&open, batch);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let written = match (batch, args.signal) {
        (false, true) => writeln!(out, "t,robustness")
            .and_then(|()| scored[0].1.iter().try_for_each(|(t, v)| writeln!(out, "{t},{v}"))),
        (false, false) => writeln!(out, "{}", scored[0].1[0].1),
        (true, true) => writeln!(out, "trace,t,robustness").and_then(|()| {
            scored.iter().try_for_each(|(path, rows)| {
                let name = hstl::study::csv_field(&trace_name(path));
                rows.iter().try_for_each(|(t, v)| writeln!(out, "{name},{t},{v}"))
            })
        }),
        (true, false) => writeln!(out, "trace,robustness").and_then(|()| {
            scored.iter().try_for_each(|(path, rows)| {
                writeln!(out, "{},{}", hstl::study::csv_field(&trace_name(path)), rows[0].1)
            })
        }),
    }
    .and_then(|()| out.flush());
    written.map_err(crate::output::stdout_error)?;
    Ok(Status::Clean)
}

/// Says on standard error which times complete windows left undetermined: for each such
/// trace, its name and the time after which they are (`None`: every time).
fn note_open(open: &[(String, Option<String>)], batch: bool) {
    let when = |end: &Option<String>| match end {
        Some(e) => format!("the times after {e} are"),
        None => "every time is".to_string(),
    };
    match open {
        [] => {}
        [(_, end)] if !batch => errln!(
            "note: over complete windows, {} undetermined: their windows run past the last \
             stamp",
            when(end)
        ),
        _ => {
            let list: Vec<String> =
                open.iter().map(|(name, end)| format!("{name} ({})", when(end))).collect();
            errln!(
                "note: over complete windows, {} trace{} {} undetermined times, whose windows \
                 run past the last stamp: {}",
                open.len(),
                if open.len() == 1 { "" } else { "s" },
                if open.len() == 1 { "has" } else { "have" },
                list.join(", ")
            );
        }
    }
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
    gap: Option<MaxGap>,
) -> Result<DenseRead, CliError> {
    let name = trace_name(path);
    let mut rows =
        TraceRows::new(open(path)?, cols, Limit::File).map_err(|e| read_error(&name, e))?;
    let mut trace = monitor.rows(gap, Front::Cli);
    let mut cells = vec![None; cols.len() - 1];
    let mut lines = Vec::new();
    while let Some(row) =
        rows.next_dense_row(&mut cells, lines.is_empty()).map_err(|e| read_error(&name, e))?
    {
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
        trace
            .push(monitor, row.stamp, &cells, Place::Line(row.line))
            .map_err(|p| at_row(&name, &row, &p, None))?;
        lines.push(row.line);
    }
    if lines.is_empty() {
        return Err(read_error(&name, ReadError::Csv(rows.no_samples())));
    }
    let ignored = rows.ignored;
    let trace = trace.build(monitor).map_err(|p| CliError::new(format!("{name}: {p}"), p.help))?;
    Ok(DenseRead { trace, ignored, lines })
}

/// A problem with the row `row` of the trace `name`, at its stamp's cell (` at time T`
/// added for a problem about a time, in the time column's scale given its `origin`).
fn at_row(name: &str, row: &DenseRow, p: &DenseProblem, origin: Option<i128>) -> CliError {
    CliError::new(
        format!("{name}:{}:{}: {}{}", row.line, row.stamp_column, p.message, at_time(p, origin)),
        p.help.clone(),
    )
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

/// `--online`: each change point printed (and flushed) as soon as the facade's live
/// monitor gives it (over complete windows, once it also lies before the complete end of
/// the rows so far); at the end, the rest, and over complete windows the time from which
/// the signal is undetermined, with no value.
fn online(
    monitor: &Dense,
    mut live: DenseLive,
    cols: &[Column<'_>],
    path: &Path,
    spec: &CheckedSpec,
) -> CmdResult {
    let name = trace_name(path);
    let mut rows =
        TraceRows::new(open(path)?, cols, Limit::Stream).map_err(|e| read_error(&name, e))?;
    note_ignored(&rows.ignored, spec);
    if !monitor.formula().future_reach().is_finite() {
        errln!(
            "note: {} has an unbounded future operator (such as `always`): no value is \
             final before the input ends, so the rows follow at its end, and the stream may \
             hold at most {} values",
            monitor.what(),
            live.limit()
        );
    }
    outln!("t,robustness")?;
    let mut cells = vec![None; cols.len() - 1];
    while let Some(row) =
        rows.next_dense_row(&mut cells, live.rows() == 0).map_err(|e| read_error(&name, e))?
    {
        let decided = live
            .push_at(monitor, row.stamp, &cells, Place::Line(row.line))
            .map_err(|p| at_row(&name, &row, &p, live.origin()))?;
        let times = live.times();
        for (t, v) in decided {
            outln!("{},{v}", times.text(t))?;
        }
    }
    if live.rows() == 0 {
        return Err(read_error(&name, ReadError::Csv(rows.no_samples())));
    }
    let (times, origin) = (live.times(), live.origin());
    let end = live.complete_end(monitor);
    let rest = live.finish(monitor).map_err(|p| {
        CliError::new(format!("{name}: {}{}", p.message, at_time(&p, origin)), p.help)
    })?;
    for &(t, v) in &rest {
        if v.is_nan() {
            // The complete end: the times from it on are undetermined.
            outln!("{},", times.text(t))?;
        } else {
            outln!("{},{v}", times.text(t))?;
        }
    }
    if rest.last().is_some_and(|p| p.1.is_nan())
        && let Some(end) = end
    {
        let t0 = rest.last().map_or(end, |p| p.0);
        note_open(&[(name.clone(), (end >= t0).then(|| times.text(end)))], false);
    }
    Ok(Status::Clean)
}

/// The options that shape reading and printing a dense-time trace.
#[derive(Clone, Copy)]
struct Options<'a> {
    gap: Option<&'a MaxGap>,
    relative: bool,
}
