//! The online monitor over named state variables ([`Online`]): one state at a time, NaN
//! and values outside a variable's domain refused, and its state as plain data to save and
//! restore.

use hstl_robustness::{self as rob, OnlineMonitor, Verdict};

use super::errors::TraceError;
use super::{Monitor, NanProne, ValueDomain};

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
