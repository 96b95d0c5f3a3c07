//! Monitoring recorded traces against a checked spec: what `hstlc monitor` and the Python
//! package share, so both give the same numbers, bit for bit, and refuse the same traces.
//!
//! A [`Monitor`] is the task of a spec, or one of its `let`s, lowered once. It scores
//! traces given as borrowed samples ([`Samples`]): columns are read in place, row-major
//! data is copied once into columns. A trace must have at least one sample, the same
//! number for every state variable, and no NaN (NaN has no robustness meaning); `inf` and
//! `-inf` are allowed. [`Monitor::signal_batch`] scores many traces on several threads;
//! [`Online`] takes one state at a time. A dense-time spec (one with a `time` variable) is
//! monitored by [`Dense`] instead, over time-stamped samples.

use std::fmt;
use std::sync::{Mutex, PoisonError};

use hstl_lang::{CheckedSpec, Domain, VarType};
use hstl_robustness::nan::NanCheck;
use hstl_robustness::{self as rob, Evaluator, OnlineMonitor, Verdict, offline};

use crate::lower::{self, LowerError};

mod dense;
mod stamps;
pub use dense::{
    Dense, DenseLive, DenseLiveState, DenseProblem, DenseRows, StampColumn, time_text,
};
pub use stamps::{
    Front, MaxGap, Place, Stamp, StampError, StampOrder, StampRules, TimeAxis, decimal_difference,
    signal_rows,
};

/// The most threads [`Monitor::signal_batch`] starts, whatever it is asked for.
pub const MAX_BATCH_THREADS: usize = 64;

/// The task of a spec, or one of its `let`s, ready to score traces.
#[derive(Clone, Debug)]
pub struct Monitor {
    vars: Vec<String>,
    /// What each state variable's values must be.
    domains: Vec<ValueDomain>,
    formula: rob::Formula,
    /// The comparisons that can compute a NaN from numbers (most specs have none).
    nan_prone: NanProne,
}

/// The comparisons of a formula that can compute a NaN, each checked on every step read,
/// so that a NaN is an error instead of a value a min or max skips.
#[derive(Clone, Debug, Default)]
pub(crate) struct NanProne {
    /// Each formula with its comparisons that can be NaN; formulas without any are left
    /// out.
    checks: Vec<(rob::Formula, NanCheck)>,
    vars: Vec<String>,
}

/// The values a state variable may take: any number, or whole numbers (in a range when
/// the spec declares one), as `hstlc monitor`'s CSV reader checks them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ValueDomain {
    /// Any number, `inf` or `-inf` (a `float` variable).
    Real,
    /// Whole numbers, inside `lo..=hi` when declared (an `int` variable).
    Int(Option<(i64, i64)>),
}

impl ValueDomain {
    /// The domains of a spec's state variables, in order.
    pub fn of(spec: &CheckedSpec) -> Vec<ValueDomain> {
        spec.state_vars
            .iter()
            .map(|v| match (v.ty, &v.domain) {
                (_, Domain::Int { lo, hi }) => ValueDomain::Int(Some((*lo, *hi))),
                (VarType::Int, _) => ValueDomain::Int(None),
                _ => ValueDomain::Real,
            })
            .collect()
    }

    /// Whether `v` (not NaN) is a value of this domain.
    fn holds(self, v: f64) -> bool {
        match self {
            ValueDomain::Real => true,
            ValueDomain::Int(range) => {
                v.is_finite()
                    && v.fract() == 0.0
                    && range.is_none_or(|(lo, hi)| v >= lo as f64 && v <= hi as f64)
            }
        }
    }
}

/// The samples of one trace, borrowed.
#[derive(Clone, Debug)]
pub enum Samples<'a> {
    /// One column per state variable, in the spec's order, read in place.
    Columns(Vec<&'a [f64]>),
    /// Row-major samples: state variable `i` at step `t` is `data[t * width + picks[i]]`.
    Rows {
        /// The samples, row by row.
        data: &'a [f64],
        /// Values per row (at least one more than the largest pick).
        width: usize,
        /// For each state variable, in the spec's order, its index in a row.
        picks: Vec<usize>,
    },
}

/// A trace or a state that cannot be scored.
#[derive(Clone, Debug, PartialEq)]
pub enum TraceError {
    /// The trace lacks a state variable.
    Missing {
        /// The state variable.
        var: String,
        /// The names the trace has, where the caller knows them.
        known: Option<Vec<String>>,
        /// The spec's state variables, in order.
        vars: Vec<String>,
    },
    /// Two state variables have different numbers of samples.
    Ragged {
        /// The first state variable.
        first: String,
        /// Its samples.
        first_len: usize,
        /// The state variable whose length differs.
        var: String,
        /// Its samples.
        len: usize,
    },
    /// The trace has no samples.
    Empty,
    /// A sample is NaN.
    NotANumber {
        /// The state variable.
        var: String,
        /// The step, counted from 0.
        step: usize,
    },
    /// A sample of an `int` state variable is not a whole number, or outside its range.
    NotInDomain {
        /// The state variable.
        var: String,
        /// The step, counted from 0.
        step: usize,
        /// The sample.
        value: f64,
        /// The variable's declared range, if any.
        range: Option<(i64, i64)>,
    },
    /// An expression of the formula computes NaN on a step (`sqrt` of a negative, `0 / 0`,
    /// `inf - inf`, ...): robustness has no value there.
    Undefined {
        /// The step, counted from 0.
        step: usize,
        /// The innermost expression that is NaN, or the comparison, in hstl syntax.
        expr: String,
        /// The operation that gave NaN, with its operands (`the square root of -1`).
        operation: String,
    },
    /// A state (for the online monitor) has the wrong number of values.
    Width {
        /// The spec's state variables, in order.
        vars: Vec<String>,
        /// The number of values given.
        found: usize,
    },
    /// Row-major data whose rows are too short for the picks, or not whole.
    Layout {
        /// Values in the data.
        len: usize,
        /// Values per row.
        width: usize,
    },
    /// The online monitor would pass its memory budget: `steps` states wait for verdicts
    /// that the formula's horizon (`None`: unbounded) holds back.
    Budget {
        /// The states kept.
        steps: usize,
        /// The formula's horizon in steps.
        horizon: Option<usize>,
        /// The most values the monitor keeps.
        limit: usize,
    },
}

/// A trace of a batch that cannot be scored.
#[derive(Clone, Debug, PartialEq)]
pub enum BatchError {
    /// Trace `trace` (counted from 0) is not a valid trace.
    Trace {
        /// Its index in the batch.
        trace: usize,
        /// What is wrong with it.
        error: TraceError,
    },
    /// Trace `trace` has `steps` steps where trace 0 has `first_steps`.
    Steps {
        /// Its index in the batch.
        trace: usize,
        /// Its steps.
        steps: usize,
        /// The steps of trace 0.
        first_steps: usize,
    },
}

/// How the windows at the end of a finite trace count (`hstlc monitor --windows`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Windows {
    /// Clipped at the end of the trace (rtamt's semantics, the default).
    #[default]
    Clipped,
    /// A step counts only if every window its value needs lies inside the trace
    /// ([`hstl_robustness::complete`]); later steps are undetermined (NaN).
    Complete,
}

impl Windows {
    /// The choice called `name` (`"clipped"` or `"complete"`).
    pub fn parse(name: &str) -> Result<Windows, UnknownWindows> {
        match name {
            "clipped" => Ok(Windows::Clipped),
            "complete" => Ok(Windows::Complete),
            _ => Err(UnknownWindows(name.to_string())),
        }
    }
}

/// A `windows` choice that is neither `clipped` nor `complete`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnknownWindows(pub String);

impl UnknownWindows {
    /// How to fix it.
    pub fn help(&self) -> String {
        "pass \"clipped\" (windows cut at the end of the trace, the default) or \"complete\" \
         (only steps whose windows lie inside the trace)"
            .to_string()
    }
}

impl fmt::Display for UnknownWindows {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown windows `{}`", self.0)
    }
}

impl std::error::Error for UnknownWindows {}

/// An online monitor over named state variables: one state at a time, NaN refused.
#[derive(Clone, Debug)]
pub struct Online {
    vars: Vec<String>,
    domains: Vec<ValueDomain>,
    nan_prone: NanProne,
    inner: OnlineMonitor,
    /// The steps before the states `inner` was given: a restored monitor's.
    offset: usize,
    /// The last states of the trace, for a formula with a past-time operator (whose
    /// verdicts read states the monitor no longer holds): what a snapshot replays.
    log: Option<History>,
}

/// The states a snapshot of a past-time formula replays: every state from the first whose
/// values a verdict still to come can read (the formula's lookback before the first open
/// step), or every state of the trace when that reach is unbounded.
#[derive(Clone, Debug)]
struct History {
    /// States, row after row.
    states: Vec<f64>,
    /// The step of the first state in `states`.
    first: usize,
    /// How many states to keep; `None`: all.
    keep: Option<usize>,
}

/// An online monitor's state as plain data ([`Online::snapshot`]): the states it replays
/// and the steps before them.
#[derive(Clone, Debug, PartialEq)]
pub struct OnlineState {
    /// The steps before `states`, whose verdicts were all given.
    pub skipped: usize,
    /// States, row after row (one value per state variable).
    pub states: Vec<f64>,
}

impl Monitor {
    /// The task of `spec` (`formula = None`) or the `let` called `formula`.
    pub fn new(spec: &CheckedSpec, formula: Option<&str>) -> Result<Monitor, LowerError> {
        if spec.is_dense() {
            return Err(LowerError::TimeModel { spec: spec.name.clone(), dense: true });
        }
        let formula = match formula {
            None => lower::task(spec)?,
            Some(name) => lower::let_formula(spec, name)?,
        };
        let vars: Vec<String> = spec.state_vars.iter().map(|v| v.name.clone()).collect();
        let nan_prone = NanProne::of(&formula, &vars);
        Ok(Monitor { vars, domains: ValueDomain::of(spec), formula, nan_prone })
    }

    /// The spec's state variables, in order: the columns a trace must have.
    pub fn state_vars(&self) -> &[String] {
        &self.vars
    }

    /// The formula's horizon: its value at step `t` reads steps `t ..= t + H` only. `None`
    /// when unbounded.
    pub fn horizon(&self) -> Option<usize> {
        self.formula.horizon()
    }

    /// How many leading samples of a `len`-step trace [`Monitor::robustness`] reads.
    pub fn samples_read(&self, len: usize) -> usize {
        self.horizon().map_or(len, |h| len.min(h.saturating_add(1)))
    }

    /// For each state variable, its index in `names` (the columns of row-major data).
    pub fn picks(&self, names: &[&str]) -> Result<Vec<usize>, TraceError> {
        self.vars
            .iter()
            .map(|v| {
                names.iter().position(|n| n == v).ok_or_else(|| TraceError::Missing {
                    var: v.clone(),
                    known: Some(names.iter().map(|n| n.to_string()).collect()),
                    vars: self.vars.clone(),
                })
            })
            .collect()
    }

    /// The robustness signal: `rho(f, t)` for every step `t`.
    pub fn signal(&self, samples: &Samples<'_>) -> Result<Vec<f64>, TraceError> {
        let len = self.lengths(samples)?;
        self.check_nan(samples, len)?;
        let mut scratch = Vec::new();
        let cols = columns(samples, len, &mut scratch);
        offline::signal_of_slices(&self.formula, &cols).map_err(|e| self.ragged(&cols, e))
    }

    /// The robustness at step 0. Only the samples it reads ([`Monitor::samples_read`]) are
    /// checked for NaN and, for row-major data, copied: the cost depends on the horizon,
    /// not on the trace's length.
    pub fn robustness(&self, samples: &Samples<'_>) -> Result<f64, TraceError> {
        let read = self.samples_read(self.lengths(samples)?);
        self.check_nan(samples, read)?;
        let mut scratch = Vec::new();
        let cols = columns(samples, read, &mut scratch);
        Evaluator::new()
            .robustness_of_slices(&self.formula, &cols)
            .map_err(|e| self.ragged(&cols, e))
    }

    /// The signal over complete windows ([`hstl_robustness::complete`]): `rho(f, t)` for
    /// the steps whose every window lies inside the trace, as long as there are such
    /// steps (later steps are undetermined).
    pub fn complete_signal(&self, samples: &Samples<'_>) -> Result<Vec<f64>, TraceError> {
        let len = self.lengths(samples)?;
        self.check_nan(samples, len)?;
        let mut scratch = Vec::new();
        let cols = columns(samples, len, &mut scratch);
        let trace = rob::Trace::from_columns(cols.iter().map(|c| c.to_vec()).collect())
            .map_err(|e| self.ragged(&cols, e))?;
        Ok(rob::complete::signal(&self.formula, &trace))
    }

    /// The signal with `windows` counted as asked, one value per step: over complete
    /// windows the undetermined steps (past the complete prefix) are NaN.
    pub fn signal_in(
        &self,
        samples: &Samples<'_>,
        windows: Windows,
    ) -> Result<Vec<f64>, TraceError> {
        match windows {
            Windows::Clipped => self.signal(samples),
            Windows::Complete => {
                let len = self.lengths(samples)?;
                let mut signal = self.complete_signal(samples)?;
                signal.resize(len, f64::NAN);
                Ok(signal)
            }
        }
    }

    /// The robustness at step 0 with `windows` counted as asked: NaN over complete windows
    /// when step 0 is undetermined (the trace is too short for its windows).
    pub fn robustness_in(
        &self,
        samples: &Samples<'_>,
        windows: Windows,
    ) -> Result<f64, TraceError> {
        match windows {
            Windows::Clipped => self.robustness(samples),
            Windows::Complete => {
                Ok(self.complete_signal(samples)?.first().copied().unwrap_or(f64::NAN))
            }
        }
    }

    /// [`Monitor::complete_signal`] of a trace whose samples its reader checked.
    pub fn complete_signal_of_trace(&self, trace: &rob::Trace) -> Result<Vec<f64>, TraceError> {
        self.nan_prone.check_trace(trace, trace.len())?;
        Ok(rob::complete::signal(&self.formula, trace))
    }

    /// [`Monitor::signal`] of a trace whose samples its reader checked (the CLI's CSV
    /// reader): only the expressions are checked here.
    pub fn signal_of_trace(&self, trace: &rob::Trace) -> Result<Vec<f64>, TraceError> {
        self.nan_prone.check_trace(trace, trace.len())?;
        Ok(offline::signal(&self.formula, trace))
    }

    /// [`Monitor::robustness`] of a trace whose samples its reader checked.
    pub fn robustness_of_trace(&self, trace: &rob::Trace) -> Result<f64, TraceError> {
        self.nan_prone.check_trace(trace, self.samples_read(trace.len()))?;
        Ok(offline::robustness(&self.formula, trace))
    }

    /// The steps of every trace of a batch, when they are valid and have one length.
    pub fn batch_steps(&self, traces: &[Samples<'_>]) -> Result<usize, BatchError> {
        let mut first_steps = None;
        for (trace, samples) in traces.iter().enumerate() {
            let steps =
                self.lengths(samples).map_err(|error| BatchError::Trace { trace, error })?;
            match first_steps {
                None => first_steps = Some(steps),
                Some(first_steps) if steps != first_steps => {
                    return Err(BatchError::Steps { trace, steps, first_steps });
                }
                Some(_) => {}
            }
        }
        Ok(first_steps.unwrap_or(0))
    }

    /// The signals of many traces of one length (see [`Monitor::batch_steps`]) on up to
    /// `threads` threads (at most [`MAX_BATCH_THREADS`]), row-major: trace `i`'s signal is `[i * steps .. (i + 1) * steps]`
    /// of the result, and equals what [`Monitor::signal`] gives for that trace alone. Of
    /// several bad traces, the one of the lowest index is reported.
    pub fn signal_batch(
        &self,
        traces: &[Samples<'_>],
        threads: usize,
    ) -> Result<(Vec<f64>, usize), BatchError> {
        self.signal_batch_in(traces, threads, Windows::Clipped)
    }

    /// [`Monitor::signal_batch`] with `windows` counted as asked (see
    /// [`Monitor::signal_in`]).
    pub fn signal_batch_in(
        &self,
        traces: &[Samples<'_>],
        threads: usize,
        windows: Windows,
    ) -> Result<(Vec<f64>, usize), BatchError> {
        let steps = self.batch_steps(traces)?;
        let mut out = vec![0.0; traces.len() * steps];
        if traces.is_empty() {
            return Ok((out, steps));
        }
        let workers = threads.clamp(1, traces.len().min(MAX_BATCH_THREADS));
        // A few pieces per worker, taken from a queue: a worker the OS delays takes fewer.
        let pieces = if workers == 1 { 1 } else { 4 * workers };
        let per = traces.len().div_ceil(pieces);
        let work = |first: usize, traces: &[Samples<'_>], out: &mut [f64]| {
            let mut eval = Evaluator::new();
            let mut scratch = Vec::new();
            for (k, (samples, row)) in traces.iter().zip(out.chunks_mut(steps)).enumerate() {
                let fail = |error| BatchError::Trace { trace: first + k, error };
                self.check_nan(samples, steps).map_err(fail)?;
                let cols = columns(samples, steps, &mut scratch);
                if windows == Windows::Complete {
                    let trace = rob::Trace::from_columns(cols.iter().map(|c| c.to_vec()).collect())
                        .map_err(|e| fail(self.ragged(&cols, e)))?;
                    let signal = rob::complete::signal(&self.formula, &trace);
                    row.fill(f64::NAN);
                    row[..signal.len()].copy_from_slice(&signal);
                    continue;
                }
                let signal = eval
                    .signal_of_slices(&self.formula, &cols)
                    .map_err(|e| fail(self.ragged(&cols, e)))?;
                row.copy_from_slice(signal);
            }
            Ok(())
        };
        let jobs: Vec<_> = traces
            .chunks(per)
            .zip(out.chunks_mut(per * steps))
            .enumerate()
            .map(|(i, (traces, out))| (i * per, traces, out))
            .collect();
        let queue = Mutex::new(jobs);
        let run = || {
            let mut failed = Vec::new();
            loop {
                let job = queue.lock().unwrap_or_else(PoisonError::into_inner).pop();
                let Some((first, traces, out)) = job else { return failed };
                if let Err(e) = work(first, traces, out) {
                    failed.push((first, e));
                }
            }
        };
        let run = &run;
        let mut failed = std::thread::scope(|scope| {
            // A thread the OS refuses is no error: the others, and this one, take its share.
            let helpers: Vec<_> = (1..workers)
                .filter_map(|_| std::thread::Builder::new().spawn_scoped(scope, run).ok())
                .collect();
            let mut failed = run();
            for h in helpers {
                failed.extend(h.join().unwrap_or_else(|panic| std::panic::resume_unwind(panic)));
            }
            failed
        });
        // Each piece reports its first bad trace; the first piece's is the first of all.
        failed.sort_by_key(|(first, _)| *first);
        match failed.into_iter().next() {
            Some((_, e)) => Err(e),
            None => Ok((out, steps)),
        }
    }

    /// An online monitor of this formula.
    pub fn online(&self) -> Online {
        Online {
            vars: self.vars.clone(),
            domains: self.domains.clone(),
            nan_prone: self.nan_prone.clone(),
            inner: OnlineMonitor::new(&self.formula, self.vars.len()),
            offset: 0,
            log: self.formula.has_past().then(|| History {
                states: Vec::new(),
                first: 0,
                // The first open step is at most `H` back, and reads at most `lookback`
                // before it.
                keep: lookback(&self.formula)
                    .zip(self.formula.horizon())
                    .map(|(l, h)| l.saturating_add(h).saturating_add(1)),
            }),
        }
    }

    /// The evaluator's length error in the spec's names (the checks before it should
    /// have caught it).
    fn ragged(&self, cols: &[&[f64]], e: rob::TraceError) -> TraceError {
        let rob::TraceError::Ragged { column, expected, found } = e else {
            return TraceError::Width { vars: self.vars.clone(), found: cols.len() };
        };
        let name = |i: usize| self.vars.get(i).cloned().unwrap_or_else(|| format!("column {i}"));
        TraceError::Ragged { first: name(0), first_len: expected, var: name(column), len: found }
    }

    /// The number of steps, when the samples have one per state variable and step.
    pub fn lengths(&self, samples: &Samples<'_>) -> Result<usize, TraceError> {
        let len = match samples {
            Samples::Columns(cols) => {
                if cols.len() != self.vars.len() {
                    return Err(TraceError::Width { vars: self.vars.clone(), found: cols.len() });
                }
                let len = cols.first().map_or(0, |c| c.len());
                if let Some(i) = cols.iter().position(|c| c.len() != len) {
                    return Err(TraceError::Ragged {
                        first: self.vars[0].clone(),
                        first_len: len,
                        var: self.vars[i].clone(),
                        len: cols[i].len(),
                    });
                }
                len
            }
            Samples::Rows { data, width, picks } => {
                if picks.len() != self.vars.len() {
                    return Err(TraceError::Width { vars: self.vars.clone(), found: picks.len() });
                }
                let whole = *width > 0 && data.len() % width == 0;
                if !whole || picks.iter().any(|p| p >= width) {
                    return Err(TraceError::Layout { len: data.len(), width: *width });
                }
                data.len() / width
            }
        };
        if len == 0 { Err(TraceError::Empty) } else { Ok(len) }
    }

    /// The first NaN, or the first sample of an `int` variable that is not one of its
    /// values, among the first `read` steps, as an error.
    fn check_nan(&self, samples: &Samples<'_>, read: usize) -> Result<(), TraceError> {
        let nan =
            |var: usize, step: usize| TraceError::NotANumber { var: self.vars[var].clone(), step };
        match samples {
            Samples::Columns(cols) => {
                for (var, col) in cols.iter().enumerate() {
                    let col = &col[..read.min(col.len())];
                    if let Some(step) = first_nan(col) {
                        return Err(nan(var, step));
                    }
                    let domain = self.domains[var];
                    if domain != ValueDomain::Real
                        && let Some(step) = col.iter().position(|&v| !domain.holds(v))
                    {
                        return Err(self.not_in_domain(var, step, col[step]));
                    }
                }
            }
            Samples::Rows { data, width, picks } => {
                let rows = &data[..read.saturating_mul(*width).min(data.len())];
                if first_nan(rows).is_some() {
                    // Rare: find the first NaN that a state variable's column holds.
                    let hit = rows.chunks(*width).enumerate().find_map(|(step, row)| {
                        picks
                            .iter()
                            .position(|&p| row.get(p).is_some_and(|v| v.is_nan()))
                            .map(|var| (var, step))
                    });
                    if let Some((var, step)) = hit {
                        return Err(nan(var, step));
                    }
                }
                for (var, (&pick, &domain)) in picks.iter().zip(&self.domains).enumerate() {
                    if domain == ValueDomain::Real {
                        continue;
                    }
                    let bad = rows.chunks(*width).enumerate().find_map(|(step, row)| {
                        row.get(pick)
                            .filter(|&&v| !v.is_nan() && !domain.holds(v))
                            .map(|&v| (step, v))
                    });
                    if let Some((step, v)) = bad {
                        return Err(self.not_in_domain(var, step, v));
                    }
                }
            }
        }
        self.nan_prone.check(samples, read)
    }

    fn not_in_domain(&self, var: usize, step: usize, value: f64) -> TraceError {
        let range = match self.domains[var] {
            ValueDomain::Int(range) => range,
            ValueDomain::Real => None,
        };
        TraceError::NotInDomain { var: self.vars[var].clone(), step, value, range }
    }
}

impl Online {
    /// The state variables, in the order [`Online::push`] takes their values.
    pub fn state_vars(&self) -> &[String] {
        &self.vars
    }

    /// The formula's horizon `H`; `None` when unbounded (no verdict before
    /// [`Online::finish`]).
    pub fn horizon(&self) -> Option<usize> {
        self.inner.horizon()
    }

    /// The number of states pushed since creation or the last [`Online::finish`].
    pub fn steps(&self) -> usize {
        self.offset + self.inner.steps()
    }

    /// The monitor's state as plain data: the states from the first step without a
    /// verdict on (at most `H` for a bounded formula; every state of the trace for an
    /// unbounded one), or for a formula with a past-time operator also the states before
    /// it that its past windows read (every state when they are unbounded), and how many
    /// steps came before. [`Online::restore`] on a monitor of the same formula continues
    /// exactly from it.
    pub fn snapshot(&self) -> OnlineState {
        if let Some(log) = &self.log {
            return OnlineState { skipped: log.first, states: log.states.clone() };
        }
        let columns = self.inner.open_columns();
        let open = columns.first().map_or(0, |c| c.len());
        let states = (0..open).flat_map(|t| columns.iter().map(move |c| c[t])).collect();
        OnlineState { skipped: self.steps() - open, states }
    }

    /// Starts a new trace and replays `state`, so the monitor continues where the one
    /// that gave the snapshot was (same formula). States it would refuse are refused and
    /// leave it at a new trace.
    pub fn restore(&mut self, state: &OnlineState) -> Result<(), TraceError> {
        self.finish();
        let width = self.vars.len();
        if width == 0 || !state.states.len().is_multiple_of(width) {
            return Err(TraceError::Layout { len: state.states.len(), width });
        }
        for row in state.states.chunks(width) {
            // The verdicts of replayed steps were given before the snapshot.
            if let Err(e) = self.push(row) {
                self.finish();
                return Err(e);
            }
        }
        self.offset = state.skipped;
        if let Some(log) = &mut self.log {
            log.first = state.skipped;
        }
        Ok(())
    }

    /// Appends one state (`state[i]` is state variable `i`) and returns the verdict it
    /// completes: the final `rho(f, t)` for `t = steps - 1 - H`, once `H + 1` states are
    /// in. A state with NaN is refused and changes nothing.
    pub fn push(&mut self, state: &[f64]) -> Result<Option<Verdict>, TraceError> {
        if state.len() != self.vars.len() {
            return Err(TraceError::Width { vars: self.vars.clone(), found: state.len() });
        }
        if let Some(var) = state.iter().position(|v| v.is_nan()) {
            return Err(TraceError::NotANumber { var: self.vars[var].clone(), step: self.steps() });
        }
        if let Some(var) = state.iter().zip(&self.domains).position(|(&v, d)| !d.holds(v)) {
            let range = match self.domains[var] {
                ValueDomain::Int(range) => range,
                ValueDomain::Real => None,
            };
            let (var_name, step) = (self.vars[var].clone(), self.steps());
            return Err(TraceError::NotInDomain { var: var_name, step, value: state[var], range });
        }
        self.nan_prone.check_state(state, self.steps())?;
        let verdict = self.inner.push(state).map_err(|e| match e {
            rob::TraceError::Budget { steps, horizon, limit } => {
                TraceError::Budget { steps, horizon, limit }
            }
            _ => TraceError::Width { vars: self.vars.clone(), found: state.len() },
        })?;
        if let Some(log) = &mut self.log {
            log.states.extend_from_slice(state);
            let width = state.len().max(1);
            let held = log.states.len() / width;
            // Drop the oldest states now and then: amortised O(1), at most twice `keep`.
            if let Some(keep) = log.keep
                && held >= 2 * keep.max(32)
            {
                let drop = held - keep;
                log.states.drain(..drop * width);
                log.first += drop;
            }
        }
        Ok(verdict.map(|v| Verdict { step: v.step + self.offset, ..v }))
    }

    /// What `rho(f, t)` at the first step without a verdict would be if the trace ended
    /// now; `None` when every step pushed has its verdict. Not final.
    pub fn provisional(&mut self) -> Option<f64> {
        self.inner.provisional()
    }

    /// Ends the trace: the verdicts of every step still open, windows clipped at the end.
    /// The monitor then starts a new trace at step 0.
    pub fn finish(&mut self) -> Vec<Verdict> {
        let out = self.inner.finish();
        self.new_trace(out)
    }

    /// Ends the trace over complete windows: the verdicts of the open steps whose windows
    /// all lie inside the trace (none for a bounded formula); later steps are undetermined.
    /// The monitor then starts a new trace at step 0.
    pub fn finish_complete(&mut self) -> Vec<Verdict> {
        let out = self.inner.finish_complete();
        self.new_trace(out)
    }

    /// The verdicts `out` numbered from the trace's start; the monitor at a new trace.
    fn new_trace(&mut self, out: Vec<Verdict>) -> Vec<Verdict> {
        let offset = std::mem::take(&mut self.offset);
        if let Some(log) = &mut self.log {
            log.states.clear();
            log.first = 0;
        }
        out.into_iter().map(|v| Verdict { step: v.step + offset, ..v }).collect()
    }
}

/// How many steps before `t` the robustness at `t` may read (`None`: unbounded): a past
/// window `[a..b]` adds `b`, `prev` one step; a future operator's operands count as they
/// are.
fn lookback(f: &rob::Formula) -> Option<usize> {
    use rob::{Bound, Node};
    let mut back: Vec<Option<usize>> = Vec::with_capacity(f.nodes().len());
    for node in f.nodes() {
        let kids = node.children().try_fold(0usize, |a, k| back[k].map(|b| a.max(b)));
        let reach = |i: &rob::Interval| match i.end {
            Bound::Unbounded => None,
            Bound::Inclusive(b) => Some(b),
            Bound::Exclusive(b) => Some(b.saturating_sub(1)),
        };
        back.push(match node {
            Node::Historically(i, _) | Node::Once(i, _) | Node::Since(i, _, _) => {
                kids.zip(reach(i)).map(|(k, b)| k.saturating_add(b))
            }
            Node::Prev(_) => kids.map(|k| k.saturating_add(1)),
            _ => kids,
        });
    }
    back.last().copied().flatten()
}

impl NanProne {
    pub(crate) fn of(formula: &rob::Formula, vars: &[String]) -> NanProne {
        NanProne::of_all(&[formula], vars)
    }

    /// The comparisons of all `formulas`.
    pub(crate) fn of_all(formulas: &[&rob::Formula], vars: &[String]) -> NanProne {
        let checks: Vec<(rob::Formula, NanCheck)> = formulas
            .iter()
            .map(|f| ((*f).clone(), NanCheck::new(f)))
            .filter(|(_, c)| !c.is_empty())
            .collect();
        let vars = if checks.is_empty() { Vec::new() } else { vars.to_vec() };
        NanProne { checks, vars }
    }

    /// The first comparison that is NaN on the first `read` steps, as an error.
    fn check(&self, samples: &Samples<'_>, read: usize) -> Result<(), TraceError> {
        if self.checks.is_empty() {
            return Ok(());
        }
        let mut state = vec![0.0; self.vars.len()];
        let mut values = Vec::new();
        for step in 0..read {
            match samples {
                Samples::Columns(cols) => {
                    for (v, col) in state.iter_mut().zip(cols) {
                        *v = col[step];
                    }
                }
                Samples::Rows { data, width, picks } => {
                    let row = &data[step * width..(step + 1) * width];
                    for (v, &p) in state.iter_mut().zip(picks) {
                        *v = row[p];
                    }
                }
            }
            self.check_state_with(&state, step, &mut values)?;
        }
        Ok(())
    }

    fn check_trace(&self, trace: &rob::Trace, read: usize) -> Result<(), TraceError> {
        if self.checks.is_empty() {
            return Ok(());
        }
        let cols: Vec<&[f64]> = (0..trace.vars()).map(|i| trace.column(i)).collect();
        self.check(&Samples::Columns(cols), read.min(trace.len()))
    }

    /// The first comparison that is NaN on `state` (step `step`), as an error.
    pub(crate) fn check_state(&self, state: &[f64], step: usize) -> Result<(), TraceError> {
        self.check_state_with(state, step, &mut Vec::new())
    }

    /// [`NanProne::check_state`] with scratch space for the expressions' values.
    fn check_state_with(
        &self,
        state: &[f64],
        step: usize,
        values: &mut Vec<f64>,
    ) -> Result<(), TraceError> {
        for (formula, check) in &self.checks {
            if let Some(cause) = check.check(formula, state, values) {
                let names: Vec<&str> = self.vars.iter().map(String::as_str).collect();
                let expr = match cause.expr {
                    Some(e) => formula.expr_at(e).display_with(&names).to_string(),
                    None => formula.sub(cause.atom).display_with(&names).to_string(),
                };
                return Err(TraceError::Undefined {
                    step,
                    expr,
                    operation: cause.operation.to_string(),
                });
            }
        }
        Ok(())
    }
}

impl TraceError {
    /// How to fix it, where one fits.
    pub fn help(&self) -> Option<String> {
        Some(match self {
            TraceError::Missing { known: Some(known), vars, .. } => format!(
                "the trace has {}; the spec's state variables are {}",
                quote_list(known),
                quote_list(vars)
            ),
            TraceError::Missing { known: None, vars, .. } => {
                format!("the spec's state variables are {}", quote_list(vars))
            }
            TraceError::Ragged { .. } => {
                "give every state variable one sample per step".to_string()
            }
            TraceError::Empty => "give every state variable at least one sample".to_string(),
            TraceError::NotANumber { .. } => "robustness has no meaning for NaN: drop the \
                step or give it a number (`inf` and `-inf` are allowed)"
                .to_string(),
            TraceError::Width { vars, .. } => {
                format!("give one value per state variable, in the order {}", quote_list(vars))
            }
            TraceError::NotInDomain { var, range: Some((lo, hi)), value, .. }
                if value.is_finite() && value.fract() == 0.0 =>
            {
                format!(
                    "the spec declares `{var}: int in {lo}..={hi}`: widen the range or fix the trace"
                )
            }
            TraceError::NotInDomain { var, .. } => {
                format!("`{var}` is an `int` state variable: give whole numbers such as `3`")
            }
            TraceError::Undefined { .. } => "robustness has no meaning for NaN: write the \
                expression so that it is defined on every state the trace can hold (for \
                example `sqrt(abs(x))`), or fix the trace"
                .to_string(),
            TraceError::Layout { .. } => return None,
            TraceError::Budget { .. } => "a verdict waits until the formula's window has passed: \
                monitor the whole trace offline instead (without `--online`), or shorten the \
                window"
                .to_string(),
        })
    }
}

impl fmt::Display for TraceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TraceError::Missing { var, .. } => write!(f, "missing state variable `{var}`"),
            TraceError::Ragged { first, first_len, var, len } => write!(
                f,
                "state variable `{var}` has {}, but `{first}` has {}",
                samples_word(*len),
                samples_word(*first_len)
            ),
            TraceError::Empty => f.write_str("the trace has no samples"),
            TraceError::NotANumber { var, step } => write!(f, "`{var}` is NaN at step {step}"),
            TraceError::Undefined { step, expr, operation } => {
                write!(f, "`{expr}` is NaN at step {step}: {operation}")
            }
            TraceError::NotInDomain { var, step, value, range: Some((lo, hi)) }
                if value.is_finite() && value.fract() == 0.0 =>
            {
                write!(f, "`{var}` is {value} at step {step}, outside its range {lo}..={hi}")
            }
            TraceError::NotInDomain { var, step, value, .. } => {
                write!(f, "`{var}` is {value} at step {step}, not a whole number")
            }
            TraceError::Width { vars, found } => write!(
                f,
                "the state has {found} value{}, the spec has {} state variable{}",
                if *found == 1 { "" } else { "s" },
                vars.len(),
                if vars.len() == 1 { "" } else { "s" }
            ),
            TraceError::Layout { len, width } => {
                write!(f, "{len} samples do not make whole rows of {width}")
            }
            TraceError::Budget { steps, horizon, limit } => {
                let window = match horizon {
                    Some(h) => format!("the formula looks {h} steps ahead"),
                    None => "the formula has an unbounded operator".to_string(),
                };
                write!(
                    f,
                    "the online monitor holds {steps} states without a verdict ({window}), \
                     and one more would pass its budget of {limit} values"
                )
            }
        }
    }
}

impl std::error::Error for TraceError {}

impl BatchError {
    /// How to fix it, where one fits.
    pub fn help(&self) -> Option<String> {
        match self {
            BatchError::Trace { error, .. } => error.help(),
            BatchError::Steps { .. } => {
                Some("cut or pad the traces to one length, or score each with `signal`".to_string())
            }
        }
    }
}

impl fmt::Display for BatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BatchError::Trace { trace, error } => write!(f, "trace {trace}: {error}"),
            BatchError::Steps { trace, steps, first_steps } => {
                write!(f, "trace {trace} has {steps} steps, but trace 0 has {first_steps}")
            }
        }
    }
}

impl std::error::Error for BatchError {}

/// The first `len` steps of the samples as columns: borrowed as they are, or for row-major
/// data copied into `scratch`.
fn columns<'s>(
    samples: &'s Samples<'_>,
    len: usize,
    scratch: &'s mut Vec<Vec<f64>>,
) -> Vec<&'s [f64]> {
    match samples {
        Samples::Columns(cols) => cols.iter().map(|c| &c[..len.min(c.len())]).collect(),
        Samples::Rows { data, width, picks } => {
            scratch.resize_with(picks.len(), Vec::new);
            for (col, &p) in scratch.iter_mut().zip(picks) {
                col.clear();
                col.extend(data.get(p..).unwrap_or(&[]).iter().step_by(*width).take(len));
            }
            scratch.iter().map(Vec::as_slice).collect()
        }
    }
}

/// The index of the first NaN. Scans blocks without an early exit inside them, so the
/// check vectorises; the common case (no NaN) costs a fraction of a nanosecond a sample.
fn first_nan(values: &[f64]) -> Option<usize> {
    const BLOCK: usize = 256;
    values.chunks(BLOCK).enumerate().find_map(|(b, block)| {
        #[allow(clippy::eq_op)] // `v != v` is the branch-free NaN test.
        let any = block.iter().fold(false, |acc, v| acc | (v != v));
        any.then(|| b * BLOCK + block.iter().position(|v| v.is_nan()).unwrap_or(0))
    })
}

fn samples_word(n: usize) -> String {
    if n == 1 { "1 sample".to_string() } else { format!("{n} samples") }
}

fn quote_list(names: &[String]) -> String {
    if names.is_empty() {
        return "none".to_string();
    }
    names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
}
