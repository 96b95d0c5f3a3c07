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
//!   `s_t` too: its streaming online monitor gives it, `O(|formula|)` a step, once the
//!   future operators above its past ones are replaced by their value at the last step
//!   ([`hstl_robustness::last_step`]); with a future operator of horizon `h` under a past
//!   one (`once[0..] eventually[0..3] A`), the monitor's open steps are ended as if the
//!   trace stopped at `s_t` ([`OnlineMonitor::open_values`]), `O(h |formula|)` a step plus a
//!   copy of what its past windows keep, whatever the episode's length; when the formula
//!   reads back fewer than [`FEW_STATES`] states
//!   ([`hstl_robustness::segment::start_reach`]), those are evaluated again instead,
//!   which is faster. Only a future window without an end
//!   under a past one without an end (`once[0..] eventually[0..] A`) reads all the states
//!   so far, `O(t)`;
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
//! with a past-time operator is `O(|formula|)` through its online monitor, and
//! `O(h |formula|)` with a future operator of horizon `h` under a past one
//! (`O(t |formula|)` when both windows have no end). The task's
//! robustness is kept up to date without evaluating the trace again where the formula
//! allows: `!`, `&&`, `||` and `->` combine their parts' running values, and `always`
//! distributes over `&&` (`eventually` over `||`); `always[I] f` with `f` a state formula
//! (a safety conjunct) folds `f`'s value, `O(1)`; `always[c..] eventually[J] f` and
//! `eventually[c..] always[J] f` with `f` a state formula (the persistent task's parts)
//! take `O(1)` amortised through a sliding window over `f`'s values
//! ([`hstl_robustness::WindowStream`], the online monitor's stream of the inner operator),
//! and `O(1)` with `J` unbounded ("infinitely often": the value at the last state);
//! `always[I] f` and `eventually[I] f` with `f` of finite horizon `h` fold the values of
//! `f` that are final (its online monitor's verdicts, a past-time operator in `f`
//! included) and end the last `h` as if the trace stopped there, `O(h)` a step; any
//! other part with a finite horizon `H` is evaluated over the states so far until `H + 1`
//! have arrived and is fixed from then on. Only a part that is none of these (an
//! unbounded `until`, or an unbounded operator over another unbounded one that is not
//! the shape above) is evaluated over the whole trace at every step.
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
use hstl_robustness::{Evaluator, Formula, OnlineMonitor, last_step};

use std::fmt;

use crate::lower::{self, LowerError};
use crate::monitor::{NanProne, TraceError};

mod batch;
mod program;
mod running;

pub use batch::{EpisodeBatch, RowError};
use program::Program;
use running::{Columns, Context, Running};

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

/// Below this many states read back (the reward's [`hstl_robustness::segment::start_reach`]),
/// a reward with a future operator under a past one evaluates them again each step, which
/// measured faster than copying and ending the online monitor's streams (`cargo bench
/// --bench monitor -- reward/`); from this many on, or without an end, it takes the monitor.
pub const FEW_STATES: usize = 128;

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
    /// The reward's slot, when it is read off the state alone (no past-time operator, or
    /// none left at the last step).
    reward_slot: Option<usize>,
    /// The states so far, when the reward formula has a future operator without an end
    /// under a past one (no online monitor then): only the last `start_reach + 1` when its
    /// past windows are bounded, since the value at the newest state reads no state before
    /// them (`O(reach)` a step, not `O(t)`).
    history: Option<(Columns, Option<usize>)>,
    /// The online monitor of the reward formula at the last step
    /// ([`last_step::at_last_step`]), when it has a past-time operator and a finite horizon
    /// `h` (that of the future operators under its past ones): `rho(formula, t)` is its
    /// verdict at once when `h = 0`, and otherwise the newest of its open steps ended as if
    /// the trace stopped at `s_t`, `O(h |formula|)` a step plus a copy of what its past
    /// windows keep (it was `O(t)`: quadratic over an episode).
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
        // The reward is read at the newest state only: its future operators that no past
        // one reads are what they are at the trace's last step, so a past operator inside
        // a future one is scored online too, and one inside an empty window not at all.
        let at_end = reward.has_past().then(|| last_step::at_last_step(&reward));
        let reward_slot = match &at_end {
            None => Some(1),
            Some(f) if !f.has_past() => {
                slots.push((f.clone(), false));
                Some(slots.len() - 1)
            }
            Some(_) => None,
        };
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
        // The episode keeps every state anyway: the monitor, which keeps the last `h` and
        // what its past windows need, has no limit of its own.
        // A future operator under a past one: the last `reach + 1` states evaluated again
        // when they are few (cheaper than copying a monitor's streams), the online monitor
        // when they are many or every state, and every state only when the monitor cannot
        // stream the formula (a future window without an end under a past one).
        let reach = hstl_robustness::segment::start_reach(&reward);
        let few = reach.is_some_and(|r| r < FEW_STATES);
        let past = at_end
            .filter(|f| f.has_past() && f.horizon().is_some())
            .filter(|f| f.horizon() == Some(0) || !few)
            .map(|f| OnlineMonitor::new(&f, vars.len()).with_limit(usize::MAX));
        let history =
            (reward_slot.is_none() && past.is_none()).then(|| (Columns::new(vars.len()), reach));
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
        if let Some((h, _)) = &mut self.history {
            h.clear();
        }
        if let Some(m) = &mut self.past {
            m.reset();
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
            (Some((history, reach)), _, _) => {
                history.push(state);
                if let Some(reach) = *reach {
                    while history.len() > reach.saturating_add(1) {
                        history.pop_front();
                    }
                }
                let signal = self.eval.signal_of_slices(&self.reward, &history.slices());
                signal.ok().and_then(|s| s.last().copied()).unwrap_or(f64::NAN)
            }
            // With no future operator left the value is final at once; otherwise it is the
            // newest open step's, as if the episode ended here.
            (None, Some(past), _) => match past.push(state) {
                Ok(Some(verdict)) if past.horizon() == Some(0) => verdict.value,
                Ok(_) => past.open_values().last().copied().unwrap_or(f64::NAN),
                Err(_) => f64::NAN,
            },
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
