//! An episode scored state by state: a reward per step and the task's own success, what
//! the Python package's `hstl.STLReward` reports.
//!
//! An [`EpisodeMonitor`] takes the states `s_0, s_1, ...` of one episode and gives, after
//! state `s_t`:
//! - the **reward** `rho(formula, t)` over the trace so far, `s_0 ..= s_t`, for the task or
//!   a `let`. hstl's operators look only forward and windows are clipped at the end of the
//!   trace, so this is the formula on `s_t` alone: for a state formula (a region) it is the
//!   value of the full trace's signal at `t`; a temporal operator sees only the present
//!   (`eventually[0..40] A` is `A` at `t`, `eventually[5..9] A` is `-inf`);
//! - the **task's robustness** `rho(task, 0)` over `s_0 ..= s_t`, the value
//!   `hstlc monitor` prints for the trace so far;
//! - for a persistent task (`always[0..] (eventually[0..N1] R1 && ...)`), whether the
//!   window ending at `t` is **kept** (`psi(t)` of LANGUAGE.md: every region held within
//!   its last `N_j` steps), the measure the window rate counts.
//!
//! Cost per state: the reward is `O(|formula|)` (the formula on one state). The task's
//! robustness is kept up to date without evaluating the trace again where the formula
//! allows: `!`, `&&`, `||` and `->` combine their parts' running values, and `always`
//! distributes over `&&` (`eventually` over `||`); `always[c..] eventually[J] f` and
//! `eventually[c..] always[J] f` with `f` a state formula (the persistent task's parts)
//! take `O(1)` amortised through the online monitor of the inner operator;
//! `always[I] f` and `eventually[I] f` with `f` of finite horizon `h` fold the values of
//! `f` that are final and evaluate only the last `h` states again, `O(h)` a step; any
//! other part with a finite horizon `H` is evaluated over the states so far until `H + 1`
//! have arrived and is fixed from then on. Only a part that is none of these (an
//! unbounded `until`, or an unbounded operator over another one) is evaluated over the
//! whole trace at every step.
//!
//! ```
//! let src = "spec S { state { x: float } let Hot = x > 2; task eventually[0..] Hot; }";
//! let loaded = hstl::load::load(src, None).unwrap();
//! let mut episode = hstl::reward::EpisodeMonitor::new(&loaded.spec, src, Some("Hot")).unwrap();
//! let first = episode.push(&[1.0]).unwrap();
//! assert_eq!((first.reward, first.task_robustness), (-1.0, -1.0));
//! let second = episode.push(&[5.0]).unwrap();
//! assert_eq!((second.reward, second.task_robustness), (3.0, 3.0));
//! assert_eq!(episode.push(&[0.0]).unwrap().task_robustness, 3.0);
//! ```

use hstl_lang::CheckedSpec;
use hstl_robustness::{Bound, Evaluator, Formula, Interval, OnlineMonitor};

use crate::lower::{self, LowerError};
use crate::monitor::{NanProne, TraceError};

/// Scores the states of one episode as they arrive (see the module docs).
#[derive(Clone, Debug)]
pub struct EpisodeMonitor {
    vars: Vec<String>,
    reward: Formula,
    task: Running,
    /// Each region of a persistent task: its state formula and `N_j`.
    regions: Vec<(Formula, usize)>,
    /// `tau_j`: steps since region `j` last held, capped at `N_j`.
    tau: Vec<usize>,
    steps: usize,
    eval: Evaluator,
    /// The comparisons that can compute a NaN: a state where one does is refused.
    nan_prone: NanProne,
}

/// What one state of an episode earned.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepScore {
    /// `rho(formula, t)` over the trace so far.
    pub reward: f64,
    /// `rho(task, 0)` over the trace so far.
    pub task_robustness: f64,
    /// For a persistent task, whether every region held within its window ending here.
    pub window_kept: Option<bool>,
}

/// `rho(f, 0)` over a trace that grows by one state at a time.
#[derive(Clone, Debug)]
enum Running {
    /// A part evaluated over the states so far, fixed once its horizon has passed.
    Whole {
        formula: Formula,
        horizon: Option<usize>,
        states: Columns,
        fixed: Option<f64>,
    },
    /// `always[I] f` (`min`) or `eventually[I] f` (`max`) with `f` of finite horizon `h`.
    Window {
        always: bool,
        interval: Interval,
        body: Formula,
        horizon: usize,
        /// The fold of the final values of `f` in the window.
        settled: f64,
        /// The states from the first position whose value of `f` is not final.
        states: Columns,
        /// The position of the first state in `states`.
        first: usize,
    },
    /// `always[c..] g` (`min`) or `eventually[c..] g` (`max`), `g` being
    /// `eventually[I] f` or `always[I] f` (the other operator) with `f` a state formula:
    /// the persistent task's shape, `O(1)` amortised a step. The positions whose value of
    /// `g` is final come from the online monitor of `g`; every other position's window is
    /// clipped at the end of the trace to a suffix of it, and of those suffixes the
    /// latest position's (`g` on the last state alone) is the least for `always` over
    /// `eventually` (the greatest for the dual), so it alone stands for them.
    Stream {
        always: bool,
        /// The outer operator's first offset `c`.
        from: usize,
        /// `g`, evaluated on the last state alone.
        body: Formula,
        /// The online monitor of `g`: its final values, in order.
        online: Box<OnlineMonitor>,
        /// The fold of the final values of `g` at positions from `c` on.
        settled: f64,
    },
    Not(Box<Running>),
    And(Vec<Running>),
    Or(Vec<Running>),
    Implies(Box<Running>, Box<Running>),
}

/// States kept as columns, the oldest dropped from the front in amortised `O(1)`.
#[derive(Clone, Debug)]
struct Columns {
    columns: Vec<Vec<f64>>,
    /// Index of the first live state in every column.
    start: usize,
}

impl EpisodeMonitor {
    /// Rewards by the task of `spec` (`formula = None`) or by the `let` called `formula`;
    /// `source` is the text `spec` was checked from (it names the regions of a persistent
    /// task).
    pub fn new(
        spec: &CheckedSpec,
        source: &str,
        formula: Option<&str>,
    ) -> Result<EpisodeMonitor, LowerError> {
        let task = lower::task(spec)?;
        let reward = match formula {
            None => task.clone(),
            Some(name) => lower::let_formula(spec, name)?,
        };
        let regions: Vec<(Formula, usize)> = lower::task_spec(spec, source)?
            .regions
            .into_iter()
            .map(|r| (r.formula, r.horizon))
            .collect();
        let vars: Vec<String> = spec.state_vars.iter().map(|v| v.name.clone()).collect();
        let tau = regions.iter().map(|r| r.1).collect();
        let mut scored: Vec<&Formula> = vec![&task, &reward];
        scored.extend(regions.iter().map(|r| &r.0));
        let nan_prone = NanProne::of_all(&scored, &vars);
        let task = Running::new(&task, vars.len());
        let eval = Evaluator::new();
        Ok(EpisodeMonitor { vars, reward, task, regions, tau, steps: 0, eval, nan_prone })
    }

    /// The state variables, in the order [`EpisodeMonitor::push`] takes their values.
    pub fn state_vars(&self) -> &[String] {
        &self.vars
    }

    /// Whether the task is persistent, so that [`StepScore::window_kept`] is given.
    pub fn is_persistent(&self) -> bool {
        !self.regions.is_empty()
    }

    /// The states pushed since creation or the last [`EpisodeMonitor::reset`].
    pub fn steps(&self) -> usize {
        self.steps
    }

    /// Starts a new episode.
    pub fn reset(&mut self) {
        self.task.reset();
        self.tau.iter_mut().zip(&self.regions).for_each(|(t, r)| *t = r.1);
        self.steps = 0;
    }

    /// Appends state `s_t` (`state[i]` is state variable `i`) and scores it. A state with
    /// NaN or the wrong number of values is refused and changes nothing.
    pub fn push(&mut self, state: &[f64]) -> Result<StepScore, TraceError> {
        if state.len() != self.vars.len() {
            return Err(TraceError::Width { vars: self.vars.clone(), found: state.len() });
        }
        if let Some(var) = state.iter().position(|v| v.is_nan()) {
            return Err(TraceError::NotANumber { var: self.vars[var].clone(), step: self.steps });
        }
        self.nan_prone.check_state(state, self.steps)?;
        self.steps += 1;
        let reward = at_state(&self.reward, state);
        let window_kept = if self.regions.is_empty() {
            None
        } else {
            let mut kept = true;
            for ((formula, n), tau) in self.regions.iter().zip(&mut self.tau) {
                let inside = at_state(formula, state) > 0.0;
                *tau = if inside { 0 } else { (*tau + 1).min(*n) };
                kept &= *tau < *n;
            }
            Some(kept)
        };
        let task_robustness = self.task.push(state, self.steps, &mut self.eval);
        Ok(StepScore { reward, task_robustness, window_kept })
    }
}

impl Running {
    fn new(f: &Formula, vars: usize) -> Running {
        let whole = || Running::Whole {
            formula: f.clone(),
            horizon: f.horizon(),
            states: Columns::new(vars),
            fixed: None,
        };
        match f {
            Formula::Not(g) => Running::Not(Box::new(Running::new(g, vars))),
            Formula::And(gs) => Running::And(gs.iter().map(|g| Running::new(g, vars)).collect()),
            Formula::Or(gs) => Running::Or(gs.iter().map(|g| Running::new(g, vars)).collect()),
            Formula::Implies(g, h) => {
                Running::Implies(Box::new(Running::new(g, vars)), Box::new(Running::new(h, vars)))
            }
            // `always` distributes over `&&` and `eventually` over `||` (the same min or
            // max, clipped windows and empty ones alike), so each part can take a
            // cheaper shape below.
            Formula::Always(interval, body) if matches!(**body, Formula::And(_)) => {
                let Formula::And(gs) = &**body else { unreachable!("matched above") };
                let part = |g: &Formula| Formula::Always(*interval, Box::new(g.clone()));
                Running::And(gs.iter().map(|g| Running::new(&part(g), vars)).collect())
            }
            Formula::Eventually(interval, body) if matches!(**body, Formula::Or(_)) => {
                let Formula::Or(gs) = &**body else { unreachable!("matched above") };
                let part = |g: &Formula| Formula::Eventually(*interval, Box::new(g.clone()));
                Running::Or(gs.iter().map(|g| Running::new(&part(g), vars)).collect())
            }
            Formula::Always(interval, body) | Formula::Eventually(interval, body)
                if interval.end == Bound::Unbounded && is_dual_over_state(f) =>
            {
                let always = matches!(f, Formula::Always(..));
                Running::Stream {
                    always,
                    from: interval.start,
                    body: (**body).clone(),
                    online: Box::new(OnlineMonitor::new(body, vars)),
                    settled: identity(always),
                }
            }
            Formula::Always(interval, body) | Formula::Eventually(interval, body) => {
                match body.horizon() {
                    Some(horizon) => Running::Window {
                        always: matches!(f, Formula::Always(..)),
                        interval: *interval,
                        body: (**body).clone(),
                        horizon,
                        settled: identity(matches!(f, Formula::Always(..))),
                        states: Columns::new(vars),
                        first: 0,
                    },
                    None => whole(),
                }
            }
            _ => whole(),
        }
    }

    fn reset(&mut self) {
        match self {
            Running::Whole { states, fixed, .. } => {
                states.clear();
                *fixed = None;
            }
            Running::Window { always, settled, states, first, .. } => {
                *settled = identity(*always);
                states.clear();
                *first = 0;
            }
            Running::Stream { always, online, settled, .. } => {
                // Ending the trace readies the monitor for a new one.
                online.finish();
                *settled = identity(*always);
            }
            Running::Not(g) => g.reset(),
            Running::And(gs) | Running::Or(gs) => gs.iter_mut().for_each(Running::reset),
            Running::Implies(g, h) => {
                g.reset();
                h.reset();
            }
        }
    }

    /// Takes state number `n - 1` (so `n` states are in) and gives `rho(f, 0)` over them,
    /// as the reference evaluator combines it.
    fn push(&mut self, state: &[f64], n: usize, eval: &mut Evaluator) -> f64 {
        match self {
            Running::Whole { formula, horizon, states, fixed } => {
                if let Some(v) = fixed {
                    return *v;
                }
                states.push(state);
                let value =
                    eval.robustness_of_slices(formula, &states.slices()).unwrap_or(f64::NAN);
                if horizon.is_some_and(|h| n > h) {
                    // Every state the value can read has arrived.
                    *fixed = Some(value);
                    states.clear();
                }
                value
            }
            Running::Window { always, interval, body, horizon, settled, states, first } => {
                let fold = |a: f64, b: f64| if *always { a.min(b) } else { a.max(b) };
                states.push(state);
                let signal = eval.signal_of_slices(body, &states.slices()).unwrap_or(&[]);
                let ever = interval.window(0, usize::MAX);
                let now = interval.window(0, n);
                let mut value = *settled;
                let mut final_here = false;
                for (i, &v) in signal.iter().enumerate() {
                    let position = *first + i;
                    if i == 0 && position + *horizon < n {
                        // The value at the first position has read every state it needs.
                        final_here = true;
                        if ever.contains(&position) {
                            *settled = fold(*settled, v);
                        }
                        value = *settled;
                    } else if now.contains(&position) {
                        value = fold(value, v);
                    }
                }
                if final_here {
                    states.pop_front();
                    *first += 1;
                }
                value
            }
            Running::Stream { always, from, body, online, settled } => {
                let fold = |a: f64, b: f64| if *always { a.min(b) } else { a.max(b) };
                // The state has the monitor's width and no NaN (checked by the caller).
                if let Ok(Some(verdict)) = online.push(state)
                    && verdict.step >= *from
                {
                    *settled = fold(*settled, verdict.value);
                }
                if n <= *from {
                    // No position of the outer window has arrived.
                    return *settled;
                }
                fold(*settled, at_state(body, state))
            }
            Running::Not(g) => -g.push(state, n, eval),
            Running::And(gs) => {
                gs.iter_mut().map(|g| g.push(state, n, eval)).fold(f64::INFINITY, f64::min)
            }
            Running::Or(gs) => {
                gs.iter_mut().map(|g| g.push(state, n, eval)).fold(f64::NEG_INFINITY, f64::max)
            }
            Running::Implies(g, h) => {
                let a = g.push(state, n, eval);
                (-a).max(h.push(state, n, eval))
            }
        }
    }
}

/// `rho(f, 0)` over the one-state trace `state`: the reference semantics with `n = 1`
/// (a window holds step 0 or nothing), without building a trace. The parser bounds a
/// formula's height, so the recursion is bounded too.
fn at_state(f: &Formula, state: &[f64]) -> f64 {
    let holds_now = |i: &Interval| !i.window(0, 1).is_empty();
    match f {
        Formula::True => f64::INFINITY,
        Formula::False => f64::NEG_INFINITY,
        Formula::Cmp { lhs, op, rhs } => op.robustness(lhs.eval(state), rhs.eval(state)),
        Formula::Not(g) => -at_state(g, state),
        Formula::And(gs) => gs.iter().map(|g| at_state(g, state)).fold(f64::INFINITY, f64::min),
        Formula::Or(gs) => gs.iter().map(|g| at_state(g, state)).fold(f64::NEG_INFINITY, f64::max),
        Formula::Implies(g, h) => (-at_state(g, state)).max(at_state(h, state)),
        Formula::Always(i, g) if holds_now(i) => f64::INFINITY.min(at_state(g, state)),
        Formula::Always(..) => f64::INFINITY,
        Formula::Eventually(i, g) if holds_now(i) => f64::NEG_INFINITY.max(at_state(g, state)),
        Formula::Eventually(..) => f64::NEG_INFINITY,
        // Nothing comes before step 0, so the left side's minimum is over no step.
        Formula::Until(i, _, h) if holds_now(i) => {
            f64::NEG_INFINITY.max(at_state(h, state).min(f64::INFINITY))
        }
        Formula::Until(..) => f64::NEG_INFINITY,
    }
}

/// Whether `f` is `always[I] eventually[J] g` or `eventually[I] always[J] g` with `g` a
/// state formula (horizon 0) and `J` bounded: what [`Running::Stream`] takes.
fn is_dual_over_state(f: &Formula) -> bool {
    let inner = match f {
        Formula::Always(_, body) => match &**body {
            Formula::Eventually(j, g) => Some((j, g)),
            _ => None,
        },
        Formula::Eventually(_, body) => match &**body {
            Formula::Always(j, g) => Some((j, g)),
            _ => None,
        },
        _ => None,
    };
    inner.is_some_and(|(j, g)| j.end != Bound::Unbounded && g.horizon() == Some(0))
}

/// The value of an empty window: `+inf` for `always`, `-inf` for `eventually`.
fn identity(always: bool) -> f64 {
    if always { f64::INFINITY } else { f64::NEG_INFINITY }
}

impl Columns {
    fn new(vars: usize) -> Columns {
        Columns { columns: vec![Vec::new(); vars], start: 0 }
    }

    fn push(&mut self, state: &[f64]) {
        for (column, &v) in self.columns.iter_mut().zip(state) {
            column.push(v);
        }
    }

    fn pop_front(&mut self) {
        self.start += 1;
        let len = self.columns.first().map_or(0, Vec::len);
        // Drop the dead front once it is as long as the live part: amortised O(1).
        if self.start * 2 >= len && self.start > 0 {
            for column in &mut self.columns {
                column.drain(..self.start);
            }
            self.start = 0;
        }
    }

    fn clear(&mut self) {
        self.columns.iter_mut().for_each(Vec::clear);
        self.start = 0;
    }

    fn slices(&self) -> Vec<&[f64]> {
        self.columns.iter().map(|c| &c[self.start..]).collect()
    }
}
