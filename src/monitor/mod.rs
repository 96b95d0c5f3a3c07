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

use std::sync::{Mutex, PoisonError};

use hstl_lang::{CheckedSpec, Domain, VarType};
use hstl_robustness::nan::NanCheck;
use hstl_robustness::{self as rob, Evaluator, offline};

use crate::lower::{self, LowerError};

mod dense;
mod errors;
mod online;
mod stamps;
pub use dense::{
    Dense, DenseLive, DenseLiveState, DenseProblem, DenseRows, StampColumn, time_text,
};
pub use errors::{BatchError, TraceError, UnknownWindows};
pub use online::{Online, OnlineState};
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
        // The helpers stop with this thread when its evaluations are cancelled.
        let flag = hstl_robustness::cancel::current();
        let helper = || {
            let _watch = flag.clone().map(hstl_robustness::cancel::stop_on);
            run()
        };
        let mut failed = std::thread::scope(|scope| {
            // A thread the OS refuses is no error: the others, and this one, take its share.
            let helpers: Vec<_> = (1..workers)
                .filter_map(|_| std::thread::Builder::new().spawn_scoped(scope, helper).ok())
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

/// How many steps the NaN scan takes between looks at the thread's stop flag.
const STOP_EVERY: usize = 4096;

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
            // An interrupted call drops its result, and the evaluation after this scan
            // stops at once: the rest of a long trace is not worth scanning.
            if step % STOP_EVERY == 0 && hstl_robustness::cancel::requested() {
                return Ok(());
            }
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
