//! Task progress: which goals of a task that is not persistent an episode has already met.
//!
//! A task such as `eventually[0..k] (A && eventually[0..k] (B && ...)) && always[0..T] !O`
//! is judged on the whole run from step 0. Once the run has met its goal (the first
//! conjunct), the options level must still keep the rest (stay out of `O`) for the
//! remaining steps; scored against the whole task, every later option execution looks
//! alike (none of them reaches `A` from where the run now is), and the learned choice is to
//! start the sequence again, through `O`. So the options level sees, beside the state,
//! which goals are met, and an execution is scored against the conjuncts still open.
//!
//! A *goal* is a top-level conjunct of the task that, once a prefix of the run satisfies
//! it, every longer run satisfies: made of state formulas, `&&`, `||` and `eventually`
//! (windows clipped at the end of the prefix, so a longer prefix can only raise its
//! robustness), with at least one `eventually`. Goals are checked where a leg of an option
//! ends (a goal's regions are entered there), reading at most the goal's horizon.

use hstl_robustness::offline::Evaluator;
use hstl_robustness::segment::SegmentScorer;
use hstl_robustness::{Formula, Node, NodeId, Trace};

/// At most this many goals are tracked (the options level's weights double with each).
pub const MAX_GOALS: usize = 4;

/// The longest text of one goal, written out as `policy.json` holds it (every subformula
/// wherever it is used, so a formula of few nodes can be written out at great length):
/// 1 MiB. A task with a longer goal is refused ([`Progress::goal_texts`]).
pub const MAX_GOAL_TEXT: usize = 1 << 20;

/// A greedy run of a task that is not persistent lasts its horizon and one step, at most
/// this many (what `eval` and `study` judge it over, and what training holds to).
pub const MAX_RUN_STEPS: usize = 100_000;

/// The steps a greedy run of a task without a horizon (`always !R`) lasts, as a persistent
/// task's runs do ([`crate::eval::WindowConfig`]'s default).
pub const UNBOUNDED_RUN_STEPS: usize = 2000;

/// The steps a greedy run of `task` (not persistent) lasts: its horizon and one, at most
/// [`MAX_RUN_STEPS`]; [`UNBOUNDED_RUN_STEPS`] for an unbounded task.
pub fn run_steps(task: &Formula) -> usize {
    task.horizon().map_or(UNBOUNDED_RUN_STEPS, |h| h.saturating_add(1).min(MAX_RUN_STEPS))
}

/// The goals of a task and the rest of the task once some are met.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress {
    /// The goals, in conjunct order, each with its horizon (`None`: unbounded).
    goals: Vec<(Formula, Option<usize>)>,
    /// `rest[mask]`: the task's conjuncts other than the goals in `mask`, or `None` when
    /// nothing is left to keep.
    rest: Vec<Option<Formula>>,
}

impl Progress {
    /// The progress of `task`, or `None` when it has no goal (a persistent task, a state
    /// formula, a task whose conjuncts can still fail once met). At most [`MAX_GOALS`]
    /// goals, the first in conjunct order; the others stay in the rest.
    pub fn of_task(task: &Formula) -> Option<Progress> {
        let parts: Vec<NodeId> = match task.root_node() {
            Node::And(parts) => parts.clone(),
            _ => vec![task.root()],
        };
        let mut goals = Vec::new();
        let mut others = Vec::new();
        for &p in &parts {
            if goals.len() < MAX_GOALS && is_goal(task, p) {
                goals.push((task.sub(p), task.horizon_of(p)));
            } else {
                others.push(task.sub(p));
            }
        }
        if goals.is_empty() {
            return None;
        }
        let rest = (0..1usize << goals.len())
            .map(|mask| {
                if mask == 0 {
                    return Some(task.clone());
                }
                let open: Vec<Formula> = goals
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| mask & (1 << j) == 0)
                    .map(|(_, (g, _))| g.clone())
                    .chain(others.iter().cloned())
                    .collect();
                match open.len() {
                    0 => None,
                    1 => open.into_iter().next(),
                    _ => Some(Formula::and(open)),
                }
            })
            .collect();
        Some(Progress { goals, rest })
    }

    /// The number of goals.
    pub fn goals(&self) -> usize {
        self.goals.len()
    }

    /// The number of progress codes, `2^goals`.
    pub fn codes(&self) -> usize {
        1 << self.goals.len()
    }

    /// The code with every goal met.
    pub fn all_met(&self) -> usize {
        self.codes() - 1
    }

    /// What is left of the task once the goals in `mask` are met (`None`: nothing).
    pub fn rest(&self, mask: usize) -> Option<&Formula> {
        self.rest.get(mask).and_then(Option::as_ref)
    }

    /// The goals, in conjunct order.
    pub fn goal_formulas(&self) -> impl Iterator<Item = &Formula> {
        self.goals.iter().map(|(g, _)| g)
    }

    /// The goals as text, in conjunct order, as `policy.json` holds them; fails (without
    /// writing more than [`MAX_GOAL_TEXT`] bytes) for a goal longer than that.
    pub fn goal_texts(&self) -> Result<Vec<String>, crate::Error> {
        /// A text that refuses to grow past [`MAX_GOAL_TEXT`].
        struct Capped(String);
        impl std::fmt::Write for Capped {
            fn write_str(&mut self, s: &str) -> std::fmt::Result {
                if self.0.len() + s.len() > MAX_GOAL_TEXT {
                    return Err(std::fmt::Error);
                }
                self.0.push_str(s);
                Ok(())
            }
        }
        self.goal_formulas()
            .enumerate()
            .map(|(j, g)| {
                let mut text = Capped(String::new());
                std::fmt::write(&mut text, format_args!("{g}")).map_err(|_| {
                    crate::Error::Config(format!(
                        "goal {} of the task is longer than {} bytes written out (each `let` \
                         in it is written wherever it is used); write it with fewer nested lets",
                        j + 1,
                        MAX_GOAL_TEXT
                    ))
                })?;
                Ok(text.0)
            })
            .collect()
    }

    /// The goals in `mask`, by their index in conjunct order.
    pub fn decode(&self, mask: usize) -> Vec<usize> {
        (0..self.goals.len()).filter(|j| mask & (1 << j) != 0).collect()
    }

    /// The mask of the goals listed by index; `None` when an index is not a goal's.
    pub fn encode(&self, met: &[usize]) -> Option<usize> {
        met.iter().try_fold(0, |mask, &j| (j < self.goals.len()).then_some(mask | (1 << j)))
    }

    /// A segment scorer for each progress code.
    pub fn scorers(&self) -> Vec<Option<SegmentScorer>> {
        self.rest.iter().map(|r| r.as_ref().map(SegmentScorer::new)).collect()
    }

    /// `mask` with every goal the prefix `columns` (one column per variable) meets added.
    /// A goal whose horizon the prefix has passed without meeting it stays unmet for good:
    /// it joins `given_up` and is not read again.
    fn update(
        &self,
        mask: usize,
        columns: &[&[f64]],
        eval: &mut Evaluator,
        given_up: &mut usize,
    ) -> usize {
        let len = columns.first().map_or(0, |c| c.len());
        let mut mask = mask;
        for (j, (goal, horizon)) in self.goals.iter().enumerate() {
            let bit = 1 << j;
            if mask & bit != 0 || *given_up & bit != 0 {
                continue;
            }
            if eval.robustness_of_slices(goal, columns).is_ok_and(|v| v > 0.0) {
                mask |= bit;
            } else if horizon.is_some_and(|h| len > h) {
                *given_up |= bit;
            }
        }
        mask
    }
}

/// A run so far and the goals it has met, read where asked (where a leg ends): what the
/// learner and the greedy agent keep alike.
#[derive(Clone, Debug, Default)]
pub struct GoalTracker {
    /// The run's valuations, one column per variable.
    columns: Vec<Vec<f64>>,
    met: usize,
    given_up: usize,
    eval: Evaluator,
}

impl GoalTracker {
    /// Starts a run in the valuation `x`: no goal met yet.
    pub fn start(&mut self, x: &[f64]) {
        self.columns.resize_with(x.len(), Vec::new);
        for (column, &v) in self.columns.iter_mut().zip(x) {
            column.clear();
            column.push(v);
        }
        (self.met, self.given_up) = (0, 0);
    }

    /// Appends the valuation `x` to the run.
    pub fn push(&mut self, x: &[f64]) {
        for (column, &v) in self.columns.iter_mut().zip(x) {
            column.push(v);
        }
    }

    /// Adds the goals of `progress` the run so far meets; returns the goals met.
    pub fn read(&mut self, progress: &Progress) -> usize {
        let columns: Vec<&[f64]> = self.columns.iter().map(Vec::as_slice).collect();
        self.met = progress.update(self.met, &columns, &mut self.eval, &mut self.given_up);
        self.met
    }

    /// The goals met when last read (a [`Progress`] mask).
    pub fn met(&self) -> usize {
        self.met
    }
}

/// The goals of a task over a world of numbered states: its [`Progress`] and every state's
/// valuation, which the tabular learner and a greedy agent over state indices read goals
/// from.
#[derive(Clone, Debug, PartialEq)]
pub struct StateGoals {
    /// The task's goals.
    pub progress: Progress,
    /// `rows[s * vars ..][.. vars]`: state `s`'s valuation, in the spec's variable order.
    rows: Vec<f64>,
    vars: usize,
}

impl StateGoals {
    /// The goals of `task` over the states whose valuations are the rows of `states`, or
    /// `None` when the task has none.
    pub fn of_task(task: &Formula, states: &Trace) -> Option<StateGoals> {
        let progress = Progress::of_task(task)?;
        let vars = states.vars();
        let mut rows = Vec::with_capacity(states.len() * vars);
        let mut row = Vec::with_capacity(vars);
        for s in 0..states.len() {
            states.row_into(s, &mut row);
            rows.extend_from_slice(&row);
        }
        Some(StateGoals { progress, rows, vars })
    }

    /// The valuation of state `s` (empty past the last state).
    pub fn row(&self, s: usize) -> &[f64] {
        self.rows.get(s * self.vars..(s + 1) * self.vars).unwrap_or(&[])
    }

    /// The number of progress codes.
    pub fn codes(&self) -> usize {
        self.progress.codes()
    }

    /// Starts `tracker` on a run in state `s` and reads the goals met there.
    pub fn start(&self, tracker: &mut GoalTracker, s: usize) -> usize {
        tracker.start(self.row(s));
        tracker.read(&self.progress)
    }

    /// Moves `tracker` on to state `s`.
    pub fn push(&self, tracker: &mut GoalTracker, s: usize) {
        tracker.push(self.row(s));
    }
}

impl PartialEq for GoalTracker {
    /// The same run and the same goals met (the evaluator is a cache).
    fn eq(&self, other: &GoalTracker) -> bool {
        (&self.columns, self.met, self.given_up) == (&other.columns, other.met, other.given_up)
    }
}

/// Whether the conjunct at `at` is a goal: monotone in the prefix, with an `eventually`.
fn is_goal(task: &Formula, at: NodeId) -> bool {
    let mut stack = vec![at];
    let mut temporal = false;
    while let Some(id) = stack.pop() {
        if task.is_state(id) {
            continue;
        }
        match &task[id] {
            Node::And(fs) | Node::Or(fs) => stack.extend(fs.iter().copied()),
            Node::Eventually(_, f) => {
                temporal = true;
                stack.push(*f);
            }
            _ => return false,
        }
    }
    temporal
}

#[cfg(test)]
mod tests {
    use super::*;
    use hstl_robustness::{Bound, CmpOp, Expr, Interval};

    fn above(var: usize, c: f64) -> Formula {
        Formula::cmp(Expr::var(var), CmpOp::Gt, Expr::constant(c))
    }

    fn within(n: usize, f: Formula) -> Formula {
        Formula::eventually(Interval { start: 0, end: Bound::Inclusive(n) }, f)
    }

    #[test]
    fn a_sequence_with_a_safety_conjunct_has_one_goal_and_keeps_the_safety() {
        let (a, b, o) = (above(0, 5.0), above(1, 5.0), above(0, 100.0));
        let goal = within(10, Formula::and(vec![a, within(10, b)]));
        let safe = Formula::always(
            Interval { start: 0, end: Bound::Inclusive(30) },
            Formula::not(o.clone()),
        );
        let task = Formula::and(vec![goal.clone(), safe.clone()]);
        let p = Progress::of_task(&task).expect("a goal");
        assert_eq!(p.goals(), 1);
        assert_eq!(p.rest(0), Some(&task));
        assert_eq!(p.rest(1), Some(&safe));
        assert!(Progress::of_task(&safe).is_none(), "an always conjunct can fail once met");
        assert!(Progress::of_task(&o).is_none(), "a state formula is decided at step 0");
        assert_eq!(Progress::of_task(&goal).map(|p| p.rest(1).cloned()), Some(None));
    }

    #[test]
    fn a_goal_is_met_once_a_prefix_satisfies_it_and_given_up_past_its_horizon() {
        let goal = within(3, above(0, 5.0));
        let p = Progress::of_task(&goal).unwrap();
        let mut run = GoalTracker::default();
        run.start(&[0.0]);
        run.push(&[1.0]);
        assert_eq!(run.read(&p), 0);
        run.push(&[7.0]);
        assert_eq!(run.read(&p), 1);
        run.push(&[0.0]);
        assert_eq!(run.read(&p), 1, "a met goal stays met");
        run.start(&[0.0]);
        for v in [0.0, 0.0, 0.0, 9.0] {
            run.push(&[v]);
        }
        assert_eq!(run.read(&p), 0, "9 comes past the window");
        assert_eq!(run.given_up, 1, "past its horizon the goal is not read again");
    }
}
