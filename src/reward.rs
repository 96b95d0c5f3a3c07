//! An episode scored state by state: a reward per step and the task's own success, what
//! the Python package's `hstl.STLReward` reports.
//!
//! An [`EpisodeMonitor`] takes the states `s_0, s_1, ...` of one episode and gives, after
//! state `s_t`:
//! - the **reward** `rho(formula, t)` over the trace so far, `s_0 ..= s_t`, for the task or
//!   a `let`. The future operators' windows are clipped at the end of the trace, so without
//!   a past-time operator this is the formula on `s_t` alone: for a state formula (a
//!   region) it is the value of the full trace's signal at `t`; a temporal operator sees
//!   only the present (`eventually[0..40] A` is `A` at `t`, `eventually[5..9] A` is
//!   `-inf`). A formula with a past-time operator (`once[0..10] A`) reads the states before
//!   `s_t` too: it is evaluated over the states so far, `O(t)` a step;
//! - the **task's robustness** `rho(task, 0)` over `s_0 ..= s_t`, the value
//!   `hstlc monitor` prints for the trace so far;
//! - for a persistent task (`always[0..] (eventually[0..N1] R1 && ...)`), whether the
//!   window ending at `t` is **kept** (`psi(t)` of LANGUAGE.md: every region held within
//!   its last `N_j` steps), the measure the window rate counts.
//!
//! The reward takes one of four forms ([`RewardForm`]), then `scale * value + offset`
//! ([`Shaping`]): the robustness above, `rho(formula, t)`; its **increment**, the change
//! of `rho(formula, 0)` over the prefix since the state before, so the rewards of an
//! episode add up to the formula's robustness over the whole episode; the **window**
//! reward of a persistent task, 1 for a state whose windows are all kept and 0 otherwise
//! (the learner's reward); and the **sparse** reward, `rho(formula, 0)` over the episode
//! at its last state ([`EpisodeMonitor::push_last`]) and 0 before.
//!
//! Cost per state: everything read off the new state alone (the reward without a
//! past-time operator, the regions, the state formulas of the task's parts) is one pass
//! over one flat DAG holding them all, each shared node once, `O(|formula|)`; a reward
//! with a past-time operator is `O(t |formula|)`. The task's
//! robustness is kept up to date without evaluating the trace again where the formula
//! allows: `!`, `&&`, `||` and `->` combine their parts' running values, and `always`
//! distributes over `&&` (`eventually` over `||`); `always[I] f` with `f` a state formula
//! (a safety conjunct) folds `f`'s value, `O(1)`; `always[c..] eventually[J] f` and
//! `eventually[c..] always[J] f` with `f` a state formula (the persistent task's parts)
//! take `O(1)` amortised through a sliding window over `f`'s values
//! ([`hstl_robustness::WindowStream`], the online monitor's stream of the inner operator);
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
use hstl_robustness::{
    Bound, Evaluator, Formula, FormulaBuilder, Interval, Node, NodeId, OnlineMonitor, WindowStream,
};

use std::fmt;

use crate::lower::{self, LowerError};
use crate::monitor::{NanProne, TraceError};

/// What an [`EpisodeMonitor`] rewards a state with (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RewardForm {
    /// `rho(formula, t)` over the trace so far.
    Robustness,
    /// The change of `rho(formula, 0)` over the prefix since the state before: an
    /// episode's rewards add up to the formula's robustness over the episode.
    Increment,
    /// 1 when every window of the persistent task ending at the state is kept, else 0.
    Window,
    /// `rho(formula, 0)` over the episode at its last state, 0 before.
    Sparse,
}

impl RewardForm {
    /// Every form, in the order of [`RewardForm::NAMES`].
    pub const ALL: [RewardForm; 4] =
        [RewardForm::Robustness, RewardForm::Increment, RewardForm::Window, RewardForm::Sparse];

    /// The forms' names, as `STLReward(reward=...)` takes them.
    pub const NAMES: [&str; 4] = ["robustness", "increment", "window", "sparse"];

    /// The form called `name`.
    pub fn parse(name: &str) -> Result<RewardForm, RewardError> {
        Self::NAMES
            .iter()
            .position(|n| *n == name)
            .map(|i| Self::ALL[i])
            .ok_or_else(|| RewardError::UnknownForm(name.to_string()))
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        Self::NAMES[Self::ALL.iter().position(|f| *f == self).unwrap_or(0)]
    }
}

/// The reward's form and the affine map applied to it: `scale * value + offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shaping {
    /// The form.
    pub form: RewardForm,
    /// Added to every state's reward (a bonus per step when positive).
    pub offset: f64,
    /// Multiplies the form's value; positive and finite.
    pub scale: f64,
}

impl Default for Shaping {
    fn default() -> Shaping {
        Shaping { form: RewardForm::Robustness, offset: 0.0, scale: 1.0 }
    }
}

/// A reward form that does not fit the spec, or an offset or scale out of range.
#[derive(Clone, Debug, PartialEq)]
pub enum RewardError {
    /// No form has this name.
    UnknownForm(String),
    /// The window reward of a task that is not persistent.
    NotPersistent,
    /// The window reward with a `let` named: it scores the task's windows.
    WindowOfLet(String),
    /// An offset that is not finite.
    Offset(f64),
    /// A scale that is not positive and finite.
    Scale(f64),
}

impl fmt::Display for RewardError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RewardError::UnknownForm(name) => write!(f, "unknown reward form `{name}`"),
            RewardError::NotPersistent => {
                write!(f, "reward form `window` needs a persistent task, and this task is not one")
            }
            RewardError::WindowOfLet(name) => {
                write!(f, "reward form `window` scores the task's windows, not the `let` `{name}`")
            }
            RewardError::Offset(v) => write!(f, "reward offset must be a finite number; got {v}"),
            RewardError::Scale(v) => {
                write!(f, "reward scale must be a positive finite number; got {v}")
            }
        }
    }
}

impl RewardError {
    /// How to fix it.
    pub fn help(&self) -> Option<String> {
        Some(match self {
            RewardError::UnknownForm(_) => {
                format!("the forms are {}", RewardForm::NAMES.map(|n| format!("`{n}`")).join(", "))
            }
            RewardError::NotPersistent => {
                "a persistent task reads `always[0..] (eventually[0..N1] R1 && ...)`; \
                 for another task use `increment` or `sparse`"
                    .to_string()
            }
            RewardError::WindowOfLet(_) => "leave out the formula".to_string(),
            RewardError::Offset(_) => "pass a number such as 0.0 or 1.0".to_string(),
            RewardError::Scale(_) => "pass a number such as 1.0 or 0.1".to_string(),
        })
    }
}

impl std::error::Error for RewardError {}

/// Scores the states of one episode as they arrive (see the module docs).
#[derive(Clone, Debug)]
pub struct EpisodeMonitor {
    vars: Vec<String>,
    reward: Formula,
    task: Running,
    shaping: Shaping,
    /// `rho(formula, 0)` over the prefix, for a `let` rewarded by increment or sparsely
    /// (the task's is `task`).
    prefix: Option<Running>,
    /// The last finite `rho(formula, 0)` that an increment counted from (0 at first).
    baseline: f64,
    /// The states of the episode so far, row after row: what [`EpisodeMonitor::restore`]
    /// replays.
    log: Vec<f64>,
    /// Every value a push reads off the new state alone (the reward, the regions, the
    /// parts of `task` and `prefix`), in one pass.
    program: Program,
    /// The formulas `program` evaluates, in slot order (each with whether it is folded as
    /// the offline evaluator folds); the first `base_slots` are the reward's, the
    /// regions' and the task's, the rest `prefix`'s.
    slots: Vec<(Formula, bool)>,
    base_slots: usize,
    /// The reward's slot, when it is read off the state alone (no past-time operator).
    reward_slot: Option<usize>,
    /// The states so far, when the reward formula has a past-time operator and a future
    /// one (a future window clipped at `t` reads the whole prefix again).
    history: Option<Columns>,
    /// The reward formula's online monitor, when it has a past-time operator and no future
    /// one: `rho(formula, t)` is then final once `s_t` is in, and its streaming past
    /// windows give it in `O(|formula|)` a step (it was `O(t)`: quadratic over an episode).
    past: Option<OnlineMonitor>,
    /// Each region of a persistent task: its state formula and `N_j`.
    regions: Vec<(Formula, usize)>,
    /// Each region's slot.
    region_slots: Vec<usize>,
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
    /// The reward in the monitor's form (`rho(formula, t)` over the trace so far by
    /// default), scaled and offset.
    pub reward: f64,
    /// `rho(task, 0)` over the trace so far.
    pub task_robustness: f64,
    /// For a persistent task, whether every region held within its window ending here.
    pub window_kept: Option<bool>,
}

/// `rho(f, 0)` over a trace that grows by one state at a time: the formula's boolean
/// skeleton as a list of parts, each reading earlier ones (a shared subformula is one
/// part), so a push is one forward pass.
#[derive(Clone, Debug)]
struct Running {
    parts: Vec<Part>,
    /// Each part's value after the last push.
    values: Vec<f64>,
}

/// One part of a [`Running`]; the combinators name earlier parts by index.
#[derive(Clone, Debug)]
enum Part {
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
    /// `always[I] f` (`min`) or `eventually[I] f` (`max`) with `f` a state formula: the
    /// value of `f` at a position is final when its state arrives, so the fold of those in
    /// the window is the value, `O(|f|)` a step and nothing kept.
    Fold {
        always: bool,
        /// The positions the window holds in a trace of any length.
        window: std::ops::Range<usize>,
        /// The slot of `f` on the last state, as the offline evaluator computes it.
        body: usize,
        /// The fold of `f` over the positions so far in the window.
        settled: f64,
    },
    /// `always[c..] g` (`min`) or `eventually[c..] g` (`max`), `g` being
    /// `eventually[I] f` or `always[I] f` (the other operator) with `f` a state formula:
    /// the persistent task's shape, `O(1)` amortised a step. The positions whose value of
    /// `g` is final come from the sliding window of `g` over the values of `f` (the online
    /// monitor's stream of `g`); every other position's window is clipped at the end of
    /// the trace to a suffix of it, and of those suffixes the latest position's (`g` on the
    /// last state alone) is the least for `always` over `eventually` (the greatest for the
    /// dual), so it alone stands for them.
    Stream {
        always: bool,
        /// The outer operator's first offset `c`.
        from: usize,
        /// The slot of `g` on the last state alone.
        body: usize,
        /// The slot of `f` on the last state.
        inner: usize,
        /// `g`'s final values, in order.
        window: WindowStream,
        /// The fold of the final values of `g` at positions from `c` on.
        settled: f64,
    },
    Not(usize),
    And(Vec<usize>),
    Or(Vec<usize>),
    Implies(usize, usize),
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
        // The slots: every scored formula is evaluated on each state (its comparisons are
        // the ones a NaN is looked for in), the reward's and the regions' read back.
        let mut slots: Vec<(Formula, bool)> = vec![(task.clone(), false), (reward.clone(), false)];
        let reward_slot = (!reward.has_past()).then_some(1);
        let region_slots = regions
            .iter()
            .map(|(f, _)| {
                slots.push((f.clone(), false));
                slots.len() - 1
            })
            .collect();
        let task = Running::new(&task, vars.len(), &mut slots);
        let base_slots = slots.len();
        let program = Program::new(&slots);
        let pure_past = reward.has_past() && reward.horizon() == Some(0);
        let history = (reward.has_past() && !pure_past).then(|| Columns::new(vars.len()));
        let past = pure_past.then(|| OnlineMonitor::new(&reward, vars.len()));
        Ok(EpisodeMonitor {
            vars,
            reward,
            task,
            shaping: Shaping::default(),
            prefix: None,
            baseline: 0.0,
            log: Vec::new(),
            program,
            slots,
            base_slots,
            reward_slot,
            history,
            past,
            regions,
            region_slots,
            tau,
            steps: 0,
            eval: Evaluator::new(),
            nan_prone,
        })
    }

    /// The same monitor rewarding in the form and with the offset and scale of `shaping`;
    /// `formula` is the `let` it was made for (`None`: the task).
    pub fn with_shaping(
        mut self,
        shaping: Shaping,
        formula: Option<&str>,
    ) -> Result<EpisodeMonitor, RewardError> {
        if !shaping.offset.is_finite() {
            return Err(RewardError::Offset(shaping.offset));
        }
        if !(shaping.scale.is_finite() && shaping.scale > 0.0) {
            return Err(RewardError::Scale(shaping.scale));
        }
        match (shaping.form, formula) {
            (RewardForm::Window, Some(name)) => {
                return Err(RewardError::WindowOfLet(name.to_string()));
            }
            (RewardForm::Window, None) if !self.is_persistent() => {
                return Err(RewardError::NotPersistent);
            }
            (RewardForm::Increment | RewardForm::Sparse, Some(_)) => {
                self.slots.truncate(self.base_slots);
                self.prefix = Some(Running::new(&self.reward, self.vars.len(), &mut self.slots));
                self.program = Program::new(&self.slots);
            }
            _ => {
                self.prefix = None;
                self.slots.truncate(self.base_slots);
                self.program = Program::new(&self.slots);
            }
        }
        self.shaping = shaping;
        self.reset();
        Ok(self)
    }

    /// The reward's form, offset and scale.
    pub fn shaping(&self) -> Shaping {
        self.shaping
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
        if let Some(h) = &mut self.history {
            h.clear();
        }
        if let Some(m) = &mut self.past {
            *m = OnlineMonitor::new(&self.reward, self.vars.len());
        }
        self.tau.iter_mut().zip(&self.regions).for_each(|(t, r)| *t = r.1);
        if let Some(prefix) = &mut self.prefix {
            prefix.reset();
        }
        self.baseline = 0.0;
        self.log.clear();
        self.steps = 0;
    }

    /// The states of the episode so far, row after row (`state_vars().len()` values a
    /// state): plain data from which [`EpisodeMonitor::restore`] makes a monitor with the
    /// same spec, formula and shaping continue exactly where this one is, as a copy or
    /// across processes. It grows by one state a step until the next reset.
    pub fn episode_states(&self) -> &[f64] {
        &self.log
    }

    /// Starts a new episode and pushes `states` (as [`EpisodeMonitor::episode_states`]
    /// gives them), leaving the monitor as the one that gave them was.
    pub fn restore(&mut self, states: &[f64]) -> Result<(), TraceError> {
        self.reset();
        let width = self.vars.len();
        if width == 0 {
            return Ok(());
        }
        if !states.len().is_multiple_of(width) {
            return Err(TraceError::Layout { len: states.len(), width });
        }
        for state in states.chunks(width) {
            if let Err(e) = self.push(state) {
                self.reset();
                return Err(e);
            }
        }
        Ok(())
    }

    /// Appends state `s_t` (`state[i]` is state variable `i`) and scores it. A state with
    /// NaN or the wrong number of values is refused and changes nothing.
    ///
    /// The first state of an episode (the one a reset gives, which no action led to) earns
    /// no increment: the increments of the later states add up to `rho(formula, 0)` over
    /// the episode (a value that is not finite counting as 0).
    pub fn push(&mut self, state: &[f64]) -> Result<StepScore, TraceError> {
        self.push_scored(state, false)
    }

    /// [`EpisodeMonitor::push`] for the episode's last state: the sparse form rewards it
    /// with `rho(formula, 0)` over the episode. The next push still continues the episode;
    /// [`EpisodeMonitor::reset`] starts the next one.
    pub fn push_last(&mut self, state: &[f64]) -> Result<StepScore, TraceError> {
        self.push_scored(state, true)
    }

    fn push_scored(&mut self, state: &[f64], last: bool) -> Result<StepScore, TraceError> {
        if state.len() != self.vars.len() {
            return Err(TraceError::Width { vars: self.vars.clone(), found: state.len() });
        }
        if let Some(var) = state.iter().position(|v| v.is_nan()) {
            return Err(TraceError::NotANumber { var: self.vars[var].clone(), step: self.steps });
        }
        // Every comparison of the scored formulas is in the program: only when one of them
        // is NaN on this state is the state looked at again for the error's words.
        if self.program.run(state) {
            self.nan_prone.check_state(state, self.steps)?;
        }
        self.steps += 1;
        self.log.extend_from_slice(state);
        let program = &self.program;
        let robustness = match (&mut self.history, &mut self.past, self.reward_slot) {
            _ if self.shaping.form != RewardForm::Robustness => f64::NAN,
            (Some(history), _, _) => {
                history.push(state);
                let signal = self.eval.signal_of_slices(&self.reward, &history.slices());
                signal.ok().and_then(|s| s.last().copied()).unwrap_or(f64::NAN)
            }
            (None, Some(past), _) => past.push(state).ok().flatten().map_or(f64::NAN, |v| v.value),
            (None, None, Some(slot)) => program.value(slot),
            (None, None, None) => f64::NAN,
        };
        let window_kept = if self.regions.is_empty() {
            None
        } else {
            let mut kept = true;
            for ((&slot, (_, n)), tau) in
                self.region_slots.iter().zip(&self.regions).zip(&mut self.tau)
            {
                let inside = program.value(slot) > 0.0;
                *tau = if inside { 0 } else { (*tau + 1).min(*n) };
                kept &= *tau < *n;
            }
            Some(kept)
        };
        let mut ctx = Context { program, eval: &mut self.eval };
        let task_robustness = self.task.push(state, self.steps, &mut ctx);
        let prefix = match &mut self.prefix {
            Some(p) => p.push(state, self.steps, &mut ctx),
            None => task_robustness,
        };
        let value = match self.shaping.form {
            RewardForm::Robustness => robustness,
            RewardForm::Window => f64::from(u8::from(window_kept == Some(true))),
            RewardForm::Sparse if last => prefix,
            RewardForm::Sparse => 0.0,
            RewardForm::Increment => {
                let now = if prefix.is_finite() { prefix } else { 0.0 };
                // The first state of an episode earns nothing; the baseline stays 0.
                let gain = if self.steps == 1 { 0.0 } else { now - self.baseline };
                if self.steps > 1 {
                    self.baseline = now;
                }
                gain
            }
        };
        let reward = match self.shaping {
            // Bit for bit the form's value (`-0.0 + 0.0` would be `0.0`).
            Shaping { offset: 0.0, scale: 1.0, .. } => value,
            Shaping { offset, scale, .. } => scale * value + offset,
        };
        Ok(StepScore { reward, task_robustness, window_kept })
    }
}

impl Running {
    /// The parts of `f`: its `!`, `&&`, `||` and `->` (and `always` over `&&`, `eventually`
    /// over `||`, which distribute) split down to the parts [`Part::leaf`] shapes, with an
    /// explicit stack, each distinct subformula once.
    fn new(f: &Formula, vars: usize, slots: &mut Vec<(Formula, bool)>) -> Running {
        let mut b = FormulaBuilder::new();
        let root = b.formula(f);
        let mut index: std::collections::HashMap<NodeId, usize> = Default::default();
        let mut parts: Vec<Part> = Vec::new();
        // (node, whether its operands are done)
        let mut stack = vec![(root, false)];
        while let Some((v, ready)) = stack.pop() {
            if index.contains_key(&v) {
                continue;
            }
            let ops = operands(&mut b, v);
            if !ready {
                stack.push((v, true));
                for &g in ops.iter().flatten().rev() {
                    if !index.contains_key(&g) {
                        stack.push((g, false));
                    }
                }
                continue;
            }
            let at = |g: &NodeId| index[g];
            let part = match (b.node(v), ops) {
                (Node::Not(_), Some(gs)) => Part::Not(at(&gs[0])),
                (Node::Implies(..), Some(gs)) => Part::Implies(at(&gs[0]), at(&gs[1])),
                (Node::And(_) | Node::Always(..), Some(gs)) => {
                    Part::And(gs.iter().map(at).collect())
                }
                (Node::Or(_) | Node::Eventually(..), Some(gs)) => {
                    Part::Or(gs.iter().map(at).collect())
                }
                _ => Part::leaf(&b.build(v), vars, slots),
            };
            index.insert(v, parts.len());
            parts.push(part);
        }
        let values = vec![f64::NAN; parts.len()];
        Running { parts, values }
    }

    fn reset(&mut self) {
        self.parts.iter_mut().for_each(Part::reset);
    }

    /// Takes state number `n - 1` (so `n` states are in) and gives `rho(f, 0)` over them.
    fn push(&mut self, state: &[f64], n: usize, ctx: &mut Context<'_>) -> f64 {
        for k in 0..self.parts.len() {
            let v = self.parts[k].push(state, n, ctx, &self.values);
            self.values[k] = v;
        }
        self.values.last().copied().unwrap_or(f64::NAN)
    }
}

/// The nodes `v` splits into for [`Running`] (`None`: `v` is a leaf part). `always[I]` over
/// `&&` becomes the `&&` of `always[I]` over each conjunct (and `eventually[I]` over `||`
/// the `||`), new nodes added to `b`.
fn operands(b: &mut FormulaBuilder, v: NodeId) -> Option<Vec<NodeId>> {
    match b.node(v).clone() {
        Node::Not(g) => Some(vec![g]),
        Node::And(gs) | Node::Or(gs) => Some(gs),
        Node::Implies(g, h) => Some(vec![g, h]),
        Node::Always(i, body) | Node::Eventually(i, body) => {
            let always = matches!(b.node(v), Node::Always(..));
            let gs = match (b.node(body), always) {
                (Node::And(gs), true) | (Node::Or(gs), false) => gs.clone(),
                _ => return None,
            };
            let ids = gs
                .into_iter()
                .map(|g| if always { b.always(i, g) } else { b.eventually(i, g) })
                .collect();
            Some(ids)
        }
        _ => None,
    }
}

impl Part {
    /// The leaf part of `f`, the cheapest shape its form allows.
    fn leaf(f: &Formula, vars: usize, slots: &mut Vec<(Formula, bool)>) -> Part {
        let whole = || Part::Whole {
            formula: f.clone(),
            horizon: f.horizon(),
            states: Columns::new(vars),
            fixed: None,
        };
        match f.root_node() {
            Node::Always(interval, body) | Node::Eventually(interval, body)
                if interval.end == Bound::Unbounded && is_dual_over_state(f) =>
            {
                let always = matches!(f.root_node(), Node::Always(..));
                let body = f.sub(*body);
                let (inner_always, j, inner) = match body.root_node() {
                    Node::Always(j, g) => (true, *j, body.sub(*g)),
                    Node::Eventually(j, g) => (false, *j, body.sub(*g)),
                    _ => return whole(),
                };
                let Some(window) = WindowStream::new(inner_always, &j) else { return whole() };
                slots.push((body, false));
                slots.push((inner, false));
                Part::Stream {
                    always,
                    from: interval.start,
                    body: slots.len() - 2,
                    inner: slots.len() - 1,
                    window,
                    settled: identity(always),
                }
            }
            // A state formula's value at a position is final at once.
            Node::Always(interval, body) | Node::Eventually(interval, body)
                if f.is_state(*body) && !f.has_past() =>
            {
                let always = matches!(f.root_node(), Node::Always(..));
                slots.push((f.sub(*body), true));
                Part::Fold {
                    always,
                    window: interval.window(0, usize::MAX),
                    body: slots.len() - 1,
                    settled: identity(always),
                }
            }
            // The window drops the states before its first open position, which a
            // past-time operator would read.
            Node::Always(interval, body) | Node::Eventually(interval, body) if !f.has_past() => {
                match f.horizon_of(*body) {
                    Some(horizon) => Part::Window {
                        always: matches!(f.root_node(), Node::Always(..)),
                        interval: *interval,
                        body: f.sub(*body),
                        horizon,
                        settled: identity(matches!(f.root_node(), Node::Always(..))),
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
            Part::Whole { states, fixed, .. } => {
                states.clear();
                *fixed = None;
            }
            Part::Window { always, settled, states, first, .. } => {
                *settled = identity(*always);
                states.clear();
                *first = 0;
            }
            Part::Fold { always, settled, .. } => *settled = identity(*always),
            Part::Stream { always, window, settled, .. } => {
                window.clear();
                *settled = identity(*always);
            }
            Part::Not(_) | Part::And(_) | Part::Or(_) | Part::Implies(..) => {}
        }
    }

    /// Takes state number `n - 1` (so `n` states are in) and gives `rho(f, 0)` over them,
    /// as the reference evaluator combines it; `values` holds the earlier parts' values.
    fn push(&mut self, state: &[f64], n: usize, ctx: &mut Context<'_>, values: &[f64]) -> f64 {
        let eval = &mut *ctx.eval;
        match self {
            Part::Whole { formula, horizon, states, fixed } => {
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
            Part::Window { always, interval, body, horizon, settled, states, first } => {
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
            Part::Fold { always, window, body, settled } => {
                if window.contains(&(n - 1)) {
                    let v = ctx.program.value(*body);
                    *settled = if *always { settled.min(v) } else { settled.max(v) };
                }
                *settled
            }
            Part::Stream { always, from, body, inner, window, settled } => {
                let fold = |a: f64, b: f64| if *always { a.min(b) } else { a.max(b) };
                // The state has no NaN (checked by the caller).
                if let Some(verdict) = window.push(ctx.program.value(*inner))
                    && verdict.step >= *from
                {
                    *settled = fold(*settled, verdict.value);
                }
                if n <= *from {
                    // No position of the outer window has arrived.
                    return *settled;
                }
                fold(*settled, ctx.program.value(*body))
            }
            Part::Not(g) => -values[*g],
            Part::And(gs) => gs.iter().map(|g| values[*g]).fold(f64::INFINITY, f64::min),
            Part::Or(gs) => gs.iter().map(|g| values[*g]).fold(f64::NEG_INFINITY, f64::max),
            Part::Implies(g, h) => (-values[*g]).max(values[*h]),
        }
    }
}

/// What a part's push reads besides the state: the program's values on it, and the
/// evaluator of the parts evaluated over the states so far.
struct Context<'a> {
    program: &'a Program,
    eval: &'a mut Evaluator,
}

/// Formulas evaluated on the newest state alone in one pass over one DAG that holds them
/// all, each shared subformula once: a push reads the reward, the regions and the parts'
/// state formulas off it instead of evaluating each formula on its own. The DAG is laid out
/// flat ([`Op`], 16 bytes a node, operands by index), so that a push between two steps of
/// a physics engine, which has the caches to itself, touches few lines.
///
/// A slot is `rho(f, 0)` over the one-state trace `state` (the reference semantics with
/// `n = 1`: a window holds step 0 or nothing), or, when asked, with the offline evaluator's
/// folds (`&&` and `||` keep the running value on a tie of `0` and `-0`), so that a value
/// folded over steps is the offline evaluator's bit for bit: those slots' `&&`, `||`, `!`
/// and `->` nodes are laid out a second time, over the same comparisons.
#[derive(Clone, Debug)]
struct Program {
    ops: Vec<Op>,
    /// The operands of the `&&` and `||` ops, each op's in a run.
    args: Vec<u32>,
    /// Each slot's value's index.
    roots: Vec<u32>,
    /// Each op's value on the last state run.
    values: Vec<f64>,
}

/// One node of a [`Program`]; operands are indices of earlier values.
#[derive(Clone, Copy, Debug)]
enum Op {
    Const(f64),
    Var(u32),
    Neg(u32),
    Abs(u32),
    Sqrt(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    /// A comparison: `a - b` (`b - a` for `<`, as [`hstl_robustness::CmpOp::robustness`]).
    Cmp(u32, u32),
    Not(u32),
    /// `&&` over `args[start..start + len]`, folded as `f64::min` (or the offline
    /// evaluator's fold when `offline`).
    And {
        start: u32,
        len: u32,
        offline: bool,
    },
    Or {
        start: u32,
        len: u32,
        offline: bool,
    },
    Implies(u32, u32),
    /// `+inf.min(v)`: an `always` whose window holds the one step.
    MinInf(u32),
    /// `-inf.max(v)`: an `eventually` (or past `once`) whose window holds the one step.
    MaxNegInf(u32),
    /// `-inf.max(v.min(+inf))`: an `until` or `since` whose window holds the one step.
    UntilNow(u32),
}

impl Program {
    fn new(slots: &[(Formula, bool)]) -> Program {
        let mut b = FormulaBuilder::new();
        let ids: Vec<NodeId> = slots.iter().map(|(f, _)| b.formula(f)).collect();
        let root = b.and(ids);
        let formula = b.build(root);
        // `&&` keeps its operands as given, so they are the slots in order.
        let slot_nodes: Vec<usize> = match formula.root_node() {
            Node::And(gs) => gs.iter().map(|g| g.index()).collect(),
            _ => Vec::new(),
        };
        let nodes = formula.nodes();
        let mut ops = Vec::with_capacity(nodes.len());
        let mut args: Vec<u32> = Vec::new();
        let ix = |k: usize| k as u32;
        let holds_now = |i: &Interval| !i.window(0, 1).is_empty();
        let past_now = |i: &Interval| i.past_window(0).contains(&0);
        let fold = |gs: &[NodeId], map: &dyn Fn(usize) -> u32, args: &mut Vec<u32>| {
            let start = ix(args.len());
            args.extend(gs.iter().map(|g| map(g.index())));
            (start, ix(gs.len()))
        };
        for node in nodes {
            let e = |g: &hstl_robustness::ExprId| ix(g.index());
            let v = |g: &NodeId| ix(g.index());
            let op = match node {
                Node::Const(c) => Op::Const(*c),
                Node::Var(i) => Op::Var(ix(*i)),
                Node::Neg(a) => Op::Neg(e(a)),
                Node::Abs(a) => Op::Abs(e(a)),
                Node::Sqrt(a) => Op::Sqrt(e(a)),
                Node::Add(a, c) => Op::Add(e(a), e(c)),
                Node::Sub(a, c) => Op::Sub(e(a), e(c)),
                Node::Mul(a, c) => Op::Mul(e(a), e(c)),
                Node::Div(a, c) => Op::Div(e(a), e(c)),
                Node::True => Op::Const(f64::INFINITY),
                Node::False => Op::Const(f64::NEG_INFINITY),
                Node::Cmp { lhs, op, rhs } => match op {
                    hstl_robustness::CmpOp::Lt | hstl_robustness::CmpOp::Le => {
                        Op::Cmp(e(rhs), e(lhs))
                    }
                    hstl_robustness::CmpOp::Gt | hstl_robustness::CmpOp::Ge => {
                        Op::Cmp(e(lhs), e(rhs))
                    }
                },
                Node::Not(g) => Op::Not(v(g)),
                Node::And(gs) => {
                    let (start, len) = fold(gs, &|k| ix(k), &mut args);
                    Op::And { start, len, offline: false }
                }
                Node::Or(gs) => {
                    let (start, len) = fold(gs, &|k| ix(k), &mut args);
                    Op::Or { start, len, offline: false }
                }
                Node::Implies(g, h) => Op::Implies(v(g), v(h)),
                Node::Always(i, g) if holds_now(i) => Op::MinInf(v(g)),
                Node::Always(..) => Op::Const(f64::INFINITY),
                Node::Eventually(i, g) if holds_now(i) => Op::MaxNegInf(v(g)),
                Node::Eventually(..) => Op::Const(f64::NEG_INFINITY),
                // Nothing comes before step 0, so the left side's minimum is over no step.
                Node::Until(i, _, h) if holds_now(i) => Op::UntilNow(v(h)),
                Node::Until(..) => Op::Const(f64::NEG_INFINITY),
                // Past windows at step 0 hold step 0 when they start there.
                Node::Historically(i, g) if past_now(i) => Op::MinInf(v(g)),
                Node::Historically(..) => Op::Const(f64::INFINITY),
                Node::Once(i, g) if past_now(i) => Op::MaxNegInf(v(g)),
                Node::Once(..) => Op::Const(f64::NEG_INFINITY),
                Node::Since(i, _, h) if past_now(i) => Op::UntilNow(v(h)),
                Node::Since(..) => Op::Const(f64::NEG_INFINITY),
                // Weak: the step before (or after) a one-state trace does not exist.
                Node::Prev(_) | Node::Next(_) => Op::Const(f64::INFINITY),
            };
            ops.push(op);
        }
        // The offline-folded slots (state formulas): their connectives again, over the
        // same atoms, in node order, each once.
        let mut offline: Vec<Option<u32>> = vec![None; nodes.len()];
        let mut wanted = vec![false; nodes.len()];
        for (&k, (_, off)) in slot_nodes.iter().zip(slots) {
            wanted[k] |= *off;
        }
        for k in (0..nodes.len()).rev() {
            if wanted[k] {
                for c in nodes[k].children() {
                    wanted[c] = true;
                }
            }
        }
        for (k, node) in nodes.iter().enumerate() {
            if !wanted[k] {
                continue;
            }
            let map = |c: usize| offline[c].unwrap_or(ix(c));
            let op = match node {
                Node::Not(g) => Op::Not(map(g.index())),
                Node::Implies(g, h) => Op::Implies(map(g.index()), map(h.index())),
                Node::And(gs) => {
                    let (start, len) = fold(gs, &map, &mut args);
                    Op::And { start, len, offline: true }
                }
                Node::Or(gs) => {
                    let (start, len) = fold(gs, &map, &mut args);
                    Op::Or { start, len, offline: true }
                }
                _ => continue,
            };
            offline[k] = Some(ix(ops.len()));
            ops.push(op);
        }
        let roots = slot_nodes
            .iter()
            .zip(slots)
            .map(|(&k, (_, off))| if *off { offline[k].unwrap_or(ix(k)) } else { ix(k) })
            .collect();
        let values = vec![0.0; ops.len()];
        Program { ops, args, roots, values }
    }

    /// Evaluates every slot on `state`; returns whether a comparison is NaN there.
    fn run(&mut self, state: &[f64]) -> bool {
        let mut nan = false;
        let (ops, args, vals) = (&self.ops, &self.args, &mut self.values);
        for k in 0..ops.len() {
            let v = |i: u32| vals[i as usize];
            let run = |start: u32, len: u32| &args[start as usize..(start + len) as usize];
            let x = match ops[k] {
                Op::Const(c) => c,
                Op::Var(i) => state.get(i as usize).copied().unwrap_or(f64::NAN),
                Op::Neg(a) => -v(a),
                Op::Abs(a) => v(a).abs(),
                Op::Sqrt(a) => v(a).sqrt(),
                Op::Add(a, b) => v(a) + v(b),
                Op::Sub(a, b) => v(a) - v(b),
                Op::Mul(a, b) => v(a) * v(b),
                Op::Div(a, b) => v(a) / v(b),
                Op::Cmp(a, b) => {
                    let x = v(a) - v(b);
                    nan |= x.is_nan();
                    x
                }
                Op::Not(g) => -v(g),
                Op::And { start, len, offline: false } => {
                    run(start, len).iter().map(|&g| v(g)).fold(f64::INFINITY, f64::min)
                }
                Op::And { start, len, offline: true } => run(start, len)
                    .iter()
                    .map(|&g| v(g))
                    .fold(f64::INFINITY, |a, x| if x < a { x } else { a }),
                Op::Or { start, len, offline: false } => {
                    run(start, len).iter().map(|&g| v(g)).fold(f64::NEG_INFINITY, f64::max)
                }
                Op::Or { start, len, offline: true } => run(start, len)
                    .iter()
                    .map(|&g| v(g))
                    .fold(f64::NEG_INFINITY, |a, x| if x > a { x } else { a }),
                Op::Implies(g, h) => (-v(g)).max(v(h)),
                Op::MinInf(g) => f64::INFINITY.min(v(g)),
                Op::MaxNegInf(g) => f64::NEG_INFINITY.max(v(g)),
                Op::UntilNow(h) => f64::NEG_INFINITY.max(v(h).min(f64::INFINITY)),
            };
            vals[k] = x;
        }
        nan
    }

    /// Slot `slot`'s value on the last state run.
    fn value(&self, slot: usize) -> f64 {
        self.values[self.roots[slot] as usize]
    }
}

/// Whether `f` is `always[I] eventually[J] g` or `eventually[I] always[J] g` with `g` a
/// state formula (no temporal operator) and `J` bounded: what [`Part::Stream`] takes.
fn is_dual_over_state(f: &Formula) -> bool {
    let inner = match f.root_node() {
        Node::Always(_, body) => match &f[*body] {
            Node::Eventually(j, g) => Some((j, g)),
            _ => None,
        },
        Node::Eventually(_, body) => match &f[*body] {
            Node::Always(j, g) => Some((j, g)),
            _ => None,
        },
        _ => None,
    };
    inner.is_some_and(|(j, g)| j.end != Bound::Unbounded && f.is_state(*g))
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
