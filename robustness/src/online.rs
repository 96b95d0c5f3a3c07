//! The online monitor: states arrive one at a time, verdicts leave as soon as they are known.
//!
//! For a formula with a finite horizon `H`, `rho(f, t)` depends on `s_t ..= s_{t+H}` only,
//! so it is final once state `t + H` has arrived: [`OnlineMonitor::push`] returns it then.
//! Past-time operators read earlier states too, which their streaming nodes keep (`O(b)`
//! values for an interval `[a..b]`, a running value for `[a..]`).
//! Each operator is a streaming node (monotonic deques for `always`/`eventually`, the
//! offline evaluator's block decomposition run forwards for `until`), so a push costs
//! amortised `O(1)` per operator and the monitor holds `O(H)` values per operator plus the
//! last `H` states, whatever the trace length. [`OnlineMonitor::finish`] ends the trace and
//! returns the steps still open, evaluated offline on those last states with their windows
//! clipped at the end of the trace, exactly as the offline evaluators clip them.
//!
//! For a formula with an unbounded operator no verdict is final before the trace ends: a
//! later state can still change `rho(f, t)`. [`OnlineMonitor::push`] then returns nothing,
//! the monitor keeps every state, and [`OnlineMonitor::provisional`] gives the value the
//! first open step would have if the trace ended now (it is not a verdict).

use crate::stream::Stream;
use crate::{Formula, TraceError, offline::Evaluator};

/// The most values (states' samples and the operators' kept values, one of each per kept
/// state) an [`OnlineMonitor`] keeps: 1 GiB of doubles.
pub const MAX_ONLINE_VALUES: usize = 1 << 27;

/// The final robustness of the trace at one step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Verdict {
    /// The step `t`, counted from the first state pushed after creation or [`finish`].
    ///
    /// [`finish`]: OnlineMonitor::finish
    pub step: usize,
    /// `rho(f, t)`.
    pub value: f64,
}

/// Monitors one formula over a trace pushed state by state.
#[derive(Clone, Debug)]
pub struct OnlineMonitor {
    formula: Formula,
    horizon: Option<usize>,
    /// The streaming operators of a bounded formula.
    nodes: Option<Stream>,
    columns: Vec<Vec<f64>>,
    /// The length of every column (kept apart so a formula over no variable works).
    len: usize,
    /// Index in `columns` of the first step without a verdict.
    start: usize,
    /// The step number of that index.
    first_step: usize,
    eval: Evaluator,
    /// The most values kept, [`MAX_ONLINE_VALUES`] unless set.
    limit: usize,
}

impl OnlineMonitor {
    /// A monitor for `formula` over states of `vars` variables.
    pub fn new(formula: &Formula, vars: usize) -> OnlineMonitor {
        OnlineMonitor {
            formula: formula.clone(),
            horizon: formula.horizon(),
            nodes: Stream::build(formula),
            columns: vec![Vec::new(); vars],
            len: 0,
            start: 0,
            first_step: 0,
            eval: Evaluator::new(),
            limit: MAX_ONLINE_VALUES,
        }
    }

    /// The same monitor keeping at most `limit` values (see [`MAX_ONLINE_VALUES`]).
    pub fn with_limit(mut self, limit: usize) -> OnlineMonitor {
        self.limit = limit;
        self
    }

    /// The formula's horizon; `None` when unbounded (no verdict before [`finish`]).
    ///
    /// [`finish`]: OnlineMonitor::finish
    pub fn horizon(&self) -> Option<usize> {
        self.horizon
    }

    /// The number of states pushed since creation or the last [`finish`].
    ///
    /// [`finish`]: OnlineMonitor::finish
    pub fn steps(&self) -> usize {
        self.first_step + self.buffered()
    }

    /// The states of the steps without a verdict, one column per variable (the last `H`
    /// states of a bounded formula once warmed up; every state of an unbounded one).
    pub fn open_columns(&self) -> Vec<&[f64]> {
        self.columns.iter().map(|c| &c[self.start..]).collect()
    }

    /// Appends one state, `state[i]` being variable `i`, and returns the verdict it
    /// completes: `rho(f, t)` for `t = steps - 1 - H`, once `H + 1` states are in.
    pub fn push(&mut self, state: &[f64]) -> Result<Option<Verdict>, TraceError> {
        if state.len() != self.columns.len() {
            return Err(TraceError::RowWidth { expected: self.columns.len(), found: state.len() });
        }
        // Each kept state costs its samples and, at worst, a value in every operator.
        let per_state = self.columns.len() + self.formula.nodes().len();
        if (self.len + 1).saturating_mul(per_state) > self.limit {
            return Err(TraceError::Budget {
                steps: self.len,
                horizon: self.horizon,
                limit: self.limit,
            });
        }
        for (c, v) in self.columns.iter_mut().zip(state) {
            c.push(*v);
        }
        self.len += 1;
        let (Some(h), Some(nodes)) = (self.horizon, &mut self.nodes) else { return Ok(None) };
        // Every node emits one value per state once warmed up: at most one verdict here.
        let Some(value) = nodes.push(&self.formula, state) else { return Ok(None) };
        let window = h.saturating_add(1);
        let verdict = Verdict { step: self.first_step, value };
        self.start += 1;
        self.first_step += 1;
        // Dropping the decided prefix now and then keeps memory at O(H), amortised O(1).
        if self.start >= window.max(64) {
            let start = self.start;
            self.columns.iter_mut().for_each(|c| {
                c.drain(..start);
            });
            self.len -= start;
            self.start = 0;
        }
        Ok(Some(verdict))
    }

    /// What `rho(f, t)` at the first step without a verdict would be if the trace ended
    /// now; `None` when every pushed step has its verdict. Not final: later states may
    /// change it.
    pub fn provisional(&mut self) -> Option<f64> {
        if self.buffered() == 0 {
            return None;
        }
        let cols: Vec<&[f64]> = self.columns.iter().map(|c| &c[self.start..]).collect();
        Some(self.eval.robustness_of_columns(&self.formula, &cols, self.buffered()))
    }

    /// What [`OnlineMonitor::finish`] would give if the trace ended now, the monitor left
    /// as it is: `rho(f, t)` at every step without a verdict, oldest first, windows
    /// clipped after the last state pushed. Its last value is `rho(f, t)` at the newest
    /// state over the trace so far. A bounded formula with a past-time operator ends a
    /// copy of its streams, `O(H |f|)` plus the values its past windows keep (one for a
    /// window without an end), however long the trace; another formula evaluates the
    /// states kept (the last `H` of a bounded one).
    pub fn open_values(&mut self) -> Vec<f64> {
        let n = self.buffered();
        if n == 0 {
            return Vec::new();
        }
        match &self.nodes {
            Some(nodes) if self.formula.has_past() => nodes.clone().finish(&self.formula),
            _ => {
                let cols: Vec<&[f64]> = self.columns.iter().map(|c| &c[self.start..]).collect();
                self.eval.signal_of_columns(&self.formula, &cols, n).to_vec()
            }
        }
    }

    /// Ends the trace: the verdicts of every step still open, windows clipped at the end
    /// of the trace. The monitor is then ready for a new trace, counting from step 0.
    pub fn finish(&mut self) -> Vec<Verdict> {
        let n = self.buffered();
        let first = self.first_step;
        let out = match &mut self.nodes {
            // The states before the open steps are gone, but a past-time operator reads
            // them: the streams, which hold what they need of them, end the trace.
            Some(nodes) if self.formula.has_past() => nodes
                .finish(&self.formula)
                .into_iter()
                .enumerate()
                .map(|(i, value)| Verdict { step: first + i, value })
                .collect(),
            _ => {
                let cols: Vec<&[f64]> = self.columns.iter().map(|c| &c[self.start..]).collect();
                self.eval
                    .signal_of_columns(&self.formula, &cols, n)
                    .iter()
                    .enumerate()
                    .map(|(i, &value)| Verdict { step: first + i, value })
                    .collect()
            }
        };
        self.reset();
        out
    }

    /// Ends the trace over complete windows ([`crate::complete`]): the verdicts of the
    /// open steps that are complete. A bounded formula has none (its complete steps are
    /// exactly those [`OnlineMonitor::push`] gave); an unbounded one gets its whole
    /// complete prefix. Later steps are undetermined. The monitor is then ready for a new
    /// trace, counting from step 0.
    pub fn finish_complete(&mut self) -> Vec<Verdict> {
        let mut out = Vec::new();
        if self.horizon.is_none() && self.buffered() > 0 {
            let cols: Vec<Vec<f64>> =
                self.columns.iter().map(|c| c[self.start..].to_vec()).collect();
            if let Ok(trace) = crate::Trace::from_columns(cols) {
                let first = self.first_step;
                out = crate::complete::signal(&self.formula, &trace)
                    .into_iter()
                    .enumerate()
                    .map(|(i, value)| Verdict { step: first + i, value })
                    .collect();
            }
        }
        self.reset();
        out
    }

    /// Drops the trace without ending it: the monitor is ready for a new trace, counting
    /// from step 0.
    pub fn reset(&mut self) {
        self.columns.iter_mut().for_each(Vec::clear);
        self.len = 0;
        self.start = 0;
        self.first_step = 0;
        self.nodes = Stream::build(&self.formula);
    }

    fn buffered(&self) -> usize {
        self.len - self.start
    }
}
