//! `hstlc monitor`: the robustness of recorded traces, or of a stream as it arrives.
//!
//! One trace: the value at step 0, or `t,robustness` rows with `--signal`. A dense-time
//! spec (one with a `time` variable) is monitored over time stamps (`monitor_dense`). Several traces
//! (or a folder of `.csv` files): one `trace,robustness` row each, scored on every core.
//! `--online`: one trace read row by row (a pipe), each step's row printed and flushed as
//! soon as its value is final; the same rows as `--signal`.
//!
//! Exit status: 0 with the result on standard output; 1 when the spec has errors (its
//! diagnostics go to standard error, as `check` renders them); 2 when the command could not
//! run: an unreadable file, a malformed trace, an unknown `--formula` or `--spec`. On 1 and 2
//! nothing is printed to standard output, except that `--online` has already printed the
//! rows it could before a malformed row.

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use hstl::lang::CheckedSpec;
use hstl::monitor::{Monitor, TraceError};

use crate::cli_error::CliError;
pub use crate::monitor_input::{MonitorArgs, Windows};
use crate::monitor_input::{columns, note_ignored, read_error, trace_name, trace_paths};
use crate::output::{errln, outln};
use crate::trace_csv::{Column, Limit, MAX_TRACE_VALUES, ReadError, TraceRead, TraceRows};
use crate::{CmdResult, Status, spec_file, trace_csv};

/// A trace's values: `values[t]` for the determined steps, of `steps` in the trace.
struct Scored {
    values: Vec<f64>,
    steps: usize,
}

/// Runs `hstlc monitor`.
pub fn run(args: &MonitorArgs) -> CmdResult {
    let stdin_traces = args.trace.iter().filter(|t| t.as_os_str() == "-").count();
    if args.spec.as_os_str() == "-" && stdin_traces > 0 {
        return Err(CliError::new(
            "the spec and the trace cannot both come from standard input",
            Some("pass at least one of them as a file".to_string()),
        ));
    }
    if stdin_traces > 1 {
        return Err(CliError::new(
            "standard input (`--trace -`) can be read only once",
            Some("give `--trace -` once, and the other traces as files".to_string()),
        ));
    }
    let traces = trace_paths(&args.trace)?;
    let batch = traces.len() > 1 || args.trace.iter().any(|t| t.is_dir());
    if args.online && batch {
        return Err(CliError::new(
            "`--online` reads one trace as a stream",
            Some("give one `--trace` (a file or `-` for a pipe) with `--online`".to_string()),
        ));
    }
    let Some(loaded) = spec_file::load(&args.spec, args.spec_name.as_deref())? else {
        return Ok(Status::Errors);
    };
    let (spec, name) = (&loaded.spec, &loaded.file);
    if spec.is_dense() {
        return crate::monitor_dense::run(args, spec, name, &traces);
    }
    let dense_only = [(args.max_gap.is_some(), "--max-gap"), (args.relative, "--relative")];
    if let Some((_, flag)) = dense_only.iter().find(|(set, _)| *set) {
        return Err(CliError::new(
            format!(
                "{name}: `{flag}` is for dense-time specs, and spec `{}` counts steps (it has \
                 no `time` variable)",
                spec.name
            ),
            Some(format!(
                "leave out `{flag}`, or give the spec a state variable `t: time` whose column \
                 holds each row's time stamp"
            )),
        ));
    }
    let monitor = Monitor::new(spec, args.formula.as_deref()).map_err(|e| {
        let help = match &e {
            hstl::lower::LowerError::UnknownLet { .. } => {
                Some("leave out `--formula` to score the task".to_string())
            }
            hstl::lower::LowerError::Invalid { .. } | hstl::lower::LowerError::TimeModel { .. } => {
                None
            }
        };
        CliError::new(format!("{name}: {e}"), help)
    })?;
    let columns = columns(spec);
    if args.online {
        return online(&monitor, &columns, &traces[0], spec, args.formula.as_deref(), args.windows);
    }
    if batch {
        let threads = args.threads.map_or_else(
            || std::thread::available_parallelism().map_or(1, usize::from),
            usize::from,
        );
        return score_batch(&monitor, &columns, &traces, args.signal, args.windows, threads, spec);
    }
    let read = read_trace(&traces[0], &columns)?;
    note_ignored(&read.ignored, spec);
    let name = trace_name(&traces[0]);
    let scored = score(&monitor, &read, args.signal, args.windows)
        .map_err(|e| trace_error(&name, &read, e))?;
    note_undetermined(&scored, args.signal);

    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let written = if args.signal {
        writeln!(out, "t,robustness").and_then(|()| {
            (0..scored.steps).try_for_each(|t| writeln!(out, "{t},{}", scored.cell(t)))
        })
    } else {
        writeln!(out, "{}", scored.first())
    }
    .and_then(|()| out.flush());
    // A signal can be long: it goes through its own buffer, its errors as all output's.
    written.map_err(crate::output::stdout_error)?;
    Ok(Status::Clean)
}

/// The signal of a trace read whole, or its value at step 0.
fn score(
    monitor: &Monitor,
    read: &TraceRead,
    signal: bool,
    windows: Windows,
) -> Result<Scored, TraceError> {
    let steps = if signal { read.trace.len() } else { 1 };
    let values = match (windows, signal) {
        (Windows::Clipped, true) => monitor.signal_of_trace(&read.trace)?,
        (Windows::Clipped, false) => vec![monitor.robustness_of_trace(&read.trace)?],
        (Windows::Complete, _) => {
            let mut v = monitor.complete_signal_of_trace(&read.trace)?;
            v.truncate(steps);
            v
        }
    };
    Ok(Scored { values, steps })
}

impl Scored {
    /// Step `t`'s value as a CSV field: empty when undetermined.
    fn cell(&self, t: usize) -> String {
        self.values.get(t).map_or_else(String::new, f64::to_string)
    }

    /// The value at step 0, or `undetermined`.
    fn first(&self) -> String {
        self.values.first().map_or_else(|| "undetermined".to_string(), f64::to_string)
    }

    fn undetermined(&self) -> usize {
        self.steps - self.values.len()
    }
}

/// Says on standard error which steps of one trace complete windows left undetermined.
fn note_undetermined(one: &Scored, signal: bool) {
    if one.undetermined() == 0 {
        return;
    }
    if signal {
        errln!(
            "note: over complete windows, steps {} to {} are undetermined: their windows run \
             past the end of the trace (their values are left empty)",
            one.values.len(),
            one.steps - 1
        );
    } else {
        errln!(
            "note: over complete windows, step 0 is undetermined: its windows run past the end \
             of the trace"
        );
    }
}

/// Says once, on standard error, how many steps of a batch complete windows left
/// undetermined.
fn note_undetermined_rows(rows: &[(&PathBuf, Scored)], signal: bool) {
    let open: usize = rows.iter().map(|(_, s)| s.undetermined()).sum();
    match (open, signal) {
        (0, _) => {}
        (_, true) => errln!(
            "note: over complete windows, {open} step{} of the traces {} undetermined: their \
             windows run past the end of their trace (their values are left empty)",
            if open == 1 { "" } else { "s" },
            if open == 1 { "is" } else { "are" }
        ),
        (_, false) => errln!(
            "note: over complete windows, step 0 of {open} trace{} is undetermined: its \
             windows run past the end of the trace (printed as `undetermined`)",
            if open == 1 { "" } else { "s" }
        ),
    }
}

/// A trace the reader accepted but the monitor cannot score (an expression NaN on a
/// step), at the line of that step.
fn trace_error(name: &str, read: &TraceRead, e: TraceError) -> CliError {
    let line = match &e {
        TraceError::Undefined { step, .. } => read.line_of(*step),
        _ => 1,
    };
    CliError::new(format!("{name}:{line}:1: {e}"), e.help())
}

/// Reads the trace at `path` (standard input for `-`) for the state variables of `spec`.
fn read_trace(path: &Path, columns: &[Column<'_>]) -> Result<TraceRead, CliError> {
    let name = trace_name(path);
    let read = if path == Path::new("-") {
        trace_csv::read_trace(std::io::stdin().lock(), columns)
    } else {
        let file = std::fs::File::open(path)
            .map_err(|source| CliError::Read { path: path.to_path_buf(), source })?;
        trace_csv::read_trace(BufReader::new(file), columns)
    };
    read.map_err(|e| read_error(&name, e))
}

/// Scores every trace on `threads` threads, then prints one `trace,robustness` row per
/// trace in the order given (`trace,t,robustness` per step with `--signal`). A trace that
/// cannot be read stops the batch before anything is printed.
fn score_batch(
    monitor: &Monitor,
    columns: &[Column<'_>],
    traces: &[PathBuf],
    signal: bool,
    windows: Windows,
    threads: usize,
    spec: &CheckedSpec,
) -> CmdResult {
    let next = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    type Result = std::result::Result<(Scored, Vec<String>), CliError>;
    let results: Vec<Mutex<Option<Result>>> = traces.iter().map(|_| Mutex::new(None)).collect();
    let work = || {
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= traces.len() || failed.load(Ordering::Relaxed) {
                break;
            }
            let scored = read_trace(&traces[i], columns).and_then(|read| {
                let scored = score(monitor, &read, signal, windows)
                    .map_err(|e| trace_error(&trace_name(&traces[i]), &read, e))?;
                Ok((scored, read.ignored))
            });
            failed.fetch_or(scored.is_err(), Ordering::Relaxed);
            *results[i].lock().unwrap_or_else(|e| e.into_inner()) = Some(scored);
        }
    };
    std::thread::scope(|scope| {
        for _ in 1..threads.min(traces.len()) {
            // A thread that cannot start leaves its share to the others.
            let _ = std::thread::Builder::new().spawn_scoped(scope, work);
        }
        work();
    });
    let mut rows = Vec::with_capacity(traces.len());
    let mut ignored: Vec<String> = Vec::new();
    for (path, slot) in traces.iter().zip(results) {
        match slot.into_inner().unwrap_or_else(|e| e.into_inner()) {
            Some(Ok((scored, names))) => {
                for n in names {
                    if !ignored.contains(&n) {
                        ignored.push(n);
                    }
                }
                rows.push((path, scored));
            }
            Some(Err(e)) => return Err(e),
            // Not scored: an earlier error stopped the batch; it is reported above.
            None => {}
        }
    }
    note_ignored(&ignored, spec);
    note_undetermined_rows(&rows, signal);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let written = if signal {
        writeln!(out, "trace,t,robustness").and_then(|()| {
            rows.iter().try_for_each(|(path, scored)| {
                let name = hstl::study::csv_field(&trace_name(path));
                (0..scored.steps).try_for_each(|t| writeln!(out, "{name},{t},{}", scored.cell(t)))
            })
        })
    } else {
        writeln!(out, "trace,robustness").and_then(|()| {
            rows.iter().try_for_each(|(path, scored)| {
                writeln!(out, "{},{}", hstl::study::csv_field(&trace_name(path)), scored.first())
            })
        })
    }
    .and_then(|()| out.flush());
    written.map_err(crate::output::stdout_error)?;
    Ok(Status::Clean)
}

/// `--online`: reads the trace row by row and prints each step's `t,robustness` as soon
/// as it is final, flushed per line; at the end of the input, the steps still open (their
/// windows clipped at the end, as `--signal` computes them).
fn online(
    monitor: &Monitor,
    columns: &[Column<'_>],
    path: &Path,
    spec: &CheckedSpec,
    formula: Option<&str>,
    windows: Windows,
) -> CmdResult {
    let name = trace_name(path);
    let stdin;
    let file;
    let reader: Box<dyn BufRead> = if path == Path::new("-") {
        stdin = std::io::stdin();
        Box::new(stdin.lock())
    } else {
        file = std::fs::File::open(path)
            .map_err(|source| CliError::Read { path: path.to_path_buf(), source })?;
        Box::new(BufReader::new(file))
    };
    let mut rows =
        TraceRows::new(reader, columns, Limit::Stream).map_err(|e| read_error(&name, e))?;
    note_ignored(&rows.ignored, spec);
    let mut live = monitor.online();
    let what = formula.map_or_else(|| "the task".to_string(), |f| format!("`{f}`"));
    if live.horizon().is_none() {
        errln!(
            "note: {what} has an unbounded future operator (such as `always[0..]`): no step's \
             value is final before the input ends, so the values follow at its end, and the \
             stream may hold at most {} values",
            MAX_TRACE_VALUES
        );
    }
    outln!("t,robustness")?;
    let mut state = vec![0.0; columns.len()];
    let bounded = live.horizon().is_some();
    while let Some(line) = rows.next_row(&mut state).map_err(|e| read_error(&name, e))? {
        if !bounded && (live.steps() + 1).saturating_mul(columns.len().max(1)) > MAX_TRACE_VALUES {
            return Err(CliError::new(
                format!(
                    "{name}:{line}:1: the stream holds more than {MAX_TRACE_VALUES} values, and \
                     {what} keeps every state until the input ends"
                ),
                Some(
                    "monitor a formula with bounded windows (`--formula` with a `let`), or \
                     end the stream sooner"
                        .to_string(),
                ),
            ));
        }
        let verdict = live
            .push(&state)
            .map_err(|e| CliError::new(format!("{name}:{line}:1: {e}"), e.help()))?;
        if let Some(v) = verdict {
            outln!("{},{}", v.step, v.value)?;
        }
    }
    if live.steps() == 0 {
        return Err(read_error(&name, ReadError::Csv(rows.no_samples())));
    }
    let steps = live.steps();
    let last = match windows {
        Windows::Clipped => live.finish(),
        Windows::Complete => live.finish_complete(),
    };
    let mut determined = steps;
    if windows == Windows::Complete {
        // Verdicts come in step order: the steps after the last are undetermined.
        determined = last
            .last()
            .map_or(0, |v| v.step + 1)
            .max(steps.saturating_sub(live.horizon().map_or(steps, |h| h.min(steps))));
    }
    for v in last {
        outln!("{},{}", v.step, v.value)?;
    }
    for t in determined..steps {
        outln!("{t},")?;
    }
    if determined < steps {
        errln!(
            "note: over complete windows, steps {determined} to {} are undetermined: their \
             windows run past the end of the trace (their values are left empty)",
            steps - 1
        );
    }
    Ok(Status::Clean)
}
