//! The exact optimal probability of a reach-avoid task on any grid world.
//!
//! The task is `eventually[0..=T] Goal && always[0..=T_avoid] !Avoid` on a run from a
//! uniformly drawn start of the world's [`Moves`]: the goal holds at some step `0..=T` and
//! the avoided set at no step `0..=T_avoid`. A task may name further goals, each with its own
//! deadline (`eventually[0..=T1] A && eventually[0..=T2] B && always !Avoid`, a sequenced
//! reach when `T1 < T2`): each must hold at some step up to its deadline. (An unbounded `always[0..] !Avoid` over runs of
//! `L` states is the same task with `T_avoid = L - 1`, and the goal's window clipped to the
//! run: [`ReachAvoid::over_run`].) Goal and avoided set are given per state.
//!
//! The most probable way to satisfy it may depend on the whole history of the run, but the
//! step, the state and which goals have held yet say all that matters for the rest, so
//! dynamic programming on `(step, state, reached)`, backwards from the last step, gives the
//! maximum over every policy, history-dependent ones included:
//! `V_t(s, r) = max_a sum_s' P(s' | s, a) V_{t+1}(s', r')` with `r' = r || (t <= T &&
//! Goal(s))` (a set of goals for several), 0 once the run fails and 1 once it cannot fail
//! any more.

use crate::Error;
use std::fmt;

use hstl_robustness::{Bound, Formula, Node, reference};

use crate::eval::{Controller, Decision, rollout};
use crate::moves::Moves;
use crate::{Env, Rng, TaskSpec};

/// A task of the reach-avoid form `eventually[0..T] Goal && always[I] !R1 && ...`, read off
/// its formula by [`reach_avoid_form`], with at most [`MAX_GOALS`] goals in all.
#[derive(Clone, Debug, PartialEq)]
pub struct ReachAvoidForm {
    /// The goal's state formula.
    pub goal: Formula,
    /// `T`: the last step at which the goal may hold (inclusive).
    pub reach_by: usize,
    /// The avoided regions' state formulas, one per `always !R` conjunct.
    pub avoid: Vec<Formula>,
    /// The last step they must not hold at (inclusive), or `None` for `always[0..]`.
    pub avoid_through: Option<usize>,
    /// Further goals, `eventually[0..T'] G'` conjuncts after the first, each with its last
    /// step.
    pub also: Vec<(Formula, usize)>,
}

/// At most this many `eventually` conjuncts (goals) in a reach-avoid task.
pub const MAX_GOALS: usize = 4;

/// The last step of a window `[0..b]` or `[0..=b]` (inclusive), `None` for `[0..]`, and
/// `Some(None)` when the window starts later or is empty.
fn last_step(i: &hstl_robustness::Interval) -> Option<Option<usize>> {
    if i.start != 0 {
        return None;
    }
    match i.end {
        Bound::Unbounded => Some(None),
        Bound::Inclusive(b) => Some(Some(b)),
        Bound::Exclusive(b) => b.checked_sub(1).map(Some),
    }
}

/// The reach-avoid form of `task`: one to [`MAX_GOALS`] conjuncts `eventually[0..T] Goal`
/// (bounded) and one or more `always[0..T'] !R` with one window among them, every `Goal` and
/// `R` a state formula; `None` for a task of any other form.
pub fn reach_avoid_form(task: &Formula) -> Option<ReachAvoidForm> {
    let nodes = task.nodes();
    let Node::And(parts) = task.root_node() else { return None };
    let (mut goals, mut avoid, mut through) = (Vec::new(), Vec::new(), None);
    for part in parts {
        match &nodes[part.index()] {
            Node::Eventually(i, g) if task.is_state(*g) && goals.len() < MAX_GOALS => {
                goals.push((task.sub(*g), last_step(i)??));
            }
            Node::Always(i, body) => {
                let Node::Not(r) = &nodes[body.index()] else { return None };
                if !task.is_state(*r) {
                    return None;
                }
                let last = last_step(i)?;
                if through.is_some_and(|t| t != last) {
                    return None;
                }
                through = Some(last);
                avoid.push(task.sub(*r));
            }
            _ => return None,
        }
    }
    let mut goals = goals.into_iter();
    let (goal, reach_by) = goals.next()?;
    Some(ReachAvoidForm { goal, reach_by, avoid, avoid_through: through?, also: goals.collect() })
}

/// A reach-avoid task over the states of a world.
#[derive(Clone, Debug, PartialEq)]
pub struct ReachAvoid {
    /// `goal[s]`: the goal holds in state `s` (its robustness is above 0).
    pub goal: Vec<bool>,
    /// `avoid[s]`: the run fails in state `s`. For `always !Avoid` with robustness above 0,
    /// that is every state where the robustness of `Avoid` is 0 or more: a state on the
    /// boundary of `Avoid` fails `!Avoid` too.
    pub avoid: Vec<bool>,
    /// `T`: the goal must hold at some step `0..=T`.
    pub reach_by: usize,
    /// `T_avoid`: the avoided states must not occur at any step `0..=T_avoid`.
    pub avoid_through: usize,
    /// Further goals, each with its `T`: each must hold at some step up to its own.
    pub also: Vec<(Vec<bool>, usize)>,
}

/// The optimal probability of a [`ReachAvoid`] task, and the values behind it.
#[derive(Clone, PartialEq)]
pub struct ReachAvoidOptimum {
    /// The most probability any policy gives the task, from a uniform start.
    pub probability: f64,
    /// The same from each start, in the order of [`Moves::starts`].
    pub per_start: Vec<f64>,
    task: ReachAvoid,
    dest: Vec<[u32; 4]>,
    p: f64,
    /// The last step that matters, `max(T, T_avoid)`.
    last: usize,
    /// `values[(M * t + r) * states + s]`: `V_t(s, r)`, the best probability from state `s`
    /// at step `t`, bit `j` of `r` saying whether goal `j` held at a step before `t` (`M`
    /// sets of goals).
    values: Vec<f64>,
}

/// Follows the optimal policy of a [`ReachAvoidOptimum`], tracking the step and whether the
/// goal has held.
#[derive(Clone, Debug)]
pub struct ReachAvoidController<'a> {
    optimum: &'a ReachAvoidOptimum,
    step: usize,
    reached: usize,
}

impl ReachAvoid {
    /// The reach-avoid task of `spec` on the states of `env`, over runs of `len` states when
    /// its avoided regions are unbounded (`always[0..] !R`); `None` when the task is not of
    /// the reach-avoid form. The goal holds where its robustness is above 0, a region is
    /// avoided where its robustness is 0 or more (`!R` fails there).
    pub fn of_spec<E: Env>(
        spec: &TaskSpec,
        env: &E,
        len: usize,
    ) -> Result<Option<ReachAvoid>, Error> {
        let Some(form) = reach_avoid_form(&spec.task) else { return Ok(None) };
        let trace = crate::tables::valuations(spec, env)?;
        let n = trace.len();
        let holds = |g: &Formula| -> Vec<bool> {
            (0..n).map(|s| reference::robustness(g, &trace, s) > 0.0).collect()
        };
        let goal = holds(&form.goal);
        let avoid = (0..n)
            .map(|s| form.avoid.iter().any(|r| reference::robustness(r, &trace, s) >= 0.0))
            .collect();
        let also: Vec<(Vec<bool>, usize)> = form.also.iter().map(|(g, t)| (holds(g), *t)).collect();
        let mut task = match form.avoid_through {
            None => ReachAvoid::over_run(goal, avoid, form.reach_by, len)?,
            Some(t) => ReachAvoid {
                goal,
                avoid,
                reach_by: form.reach_by,
                avoid_through: t,
                also: Vec::new(),
            },
        };
        let last = match form.avoid_through {
            None => task.avoid_through,
            Some(_) => usize::MAX,
        };
        task.also = also.into_iter().map(|(g, t)| (g, t.min(last))).collect();
        Ok(Some(task))
    }

    /// The states a run needs to decide the task: `max(T, T_avoid) + 1`.
    pub fn run_len(&self) -> usize {
        self.last().saturating_add(1)
    }

    /// The last step that matters: the latest deadline or `T_avoid`.
    fn last(&self) -> usize {
        self.also.iter().fold(self.reach_by.max(self.avoid_through), |m, (_, t)| m.max(*t))
    }

    /// The goals reached by `reached` in a state where `goal[s]` for the first goal and
    /// `also` for the others, at step `t`.
    fn reach(&self, t: usize, s: usize, reached: usize) -> usize {
        let mut r = reached | usize::from(t <= self.reach_by && self.goal[s]);
        for (j, (g, by)) in self.also.iter().enumerate() {
            if t <= *by && g[s] {
                r |= 2 << j;
            }
        }
        r
    }

    /// The sets of goals a run may have reached: `2^goals`.
    fn masks(&self) -> usize {
        2 << self.also.len()
    }

    /// Whether a run through `states` (from step 0) satisfies the task; a run that ends
    /// before the task is decided satisfies it when the goal has held.
    pub fn satisfied(&self, states: &[usize]) -> bool {
        let mut reached = 0;
        for (t, &s) in states.iter().enumerate().take(self.run_len()) {
            if s >= self.goal.len() || s >= self.avoid.len() {
                return false;
            }
            match self.settle(t, s, reached) {
                (Some(v), _) => return v > 0.0,
                (None, r) => reached = r,
            }
        }
        reached == self.masks() - 1
    }

    /// The share of `runs` runs of [`ReachAvoid::run_len`] states, each from a start drawn by
    /// `env.reset`, that satisfy the task under `controller`.
    pub fn satisfaction_rate<E: Env, C: Controller>(
        &self,
        env: &E,
        controller: &mut C,
        runs: usize,
        rng: &mut Rng,
    ) -> f64 {
        let len = self.run_len();
        let mut kept = 0usize;
        for _ in 0..runs {
            let start = env.index(&env.reset(rng));
            let states: Vec<usize> =
                rollout(env, controller, start, len, rng).iter().map(|s| s.state).collect();
            kept += usize::from(self.satisfied(&states));
        }
        kept as f64 / runs.max(1) as f64
    }

    /// `eventually[0..=reach_by] Goal && always[0..] !Avoid` over runs of `len` states: the
    /// avoided states must not occur in the whole run, and the goal's window is clipped to
    /// it (a goal at step `len` or later is past the run's end).
    pub fn over_run(
        goal: Vec<bool>,
        avoid: Vec<bool>,
        reach_by: usize,
        len: usize,
    ) -> Result<ReachAvoid, Error> {
        let Some(last) = len.checked_sub(1) else {
            return Err(Error::Config("a run of 0 states cannot reach a goal".into()));
        };
        Ok(ReachAvoid {
            goal,
            avoid,
            reach_by: reach_by.min(last),
            avoid_through: last,
            also: Vec::new(),
        })
    }

    /// The outcome of step `t` in state `s` with the goals `reached` from before (a bit per
    /// goal): `Some(1)` when the task can no longer fail, `Some(0)` when it has failed, else
    /// `None`; and the new `reached`.
    fn settle(&self, t: usize, s: usize, reached: usize) -> (Option<f64>, usize) {
        if t <= self.avoid_through && self.avoid[s] {
            return (Some(0.0), reached);
        }
        let reached = self.reach(t, s, reached);
        let all = self.masks() - 1;
        let missed = (reached & 1 == 0 && t >= self.reach_by)
            || self.also.iter().enumerate().any(|(j, (_, by))| reached & (2 << j) == 0 && t >= *by);
        if reached == all && t >= self.avoid_through {
            (Some(1.0), reached)
        } else if missed {
            (Some(0.0), reached)
        } else {
            (None, reached)
        }
    }
}

/// The optimal probability of `task` on `moves`. Fails when the task does not fit the
/// world, or when its table of `2 * (max(T, T_avoid) + 1) * states` values exceeds
/// `max_states`, before allocating it.
pub fn solve_reach_avoid(
    moves: &Moves,
    task: &ReachAvoid,
    max_states: usize,
) -> Result<ReachAvoidOptimum, Error> {
    moves.check()?;
    let n = moves.states();
    if task.goal.len() != n || task.avoid.len() != n || task.also.iter().any(|(g, _)| g.len() != n)
    {
        return Err(Error::Config(format!(
            "the goal and avoided states were not computed on this world, which has {n} \
             states (goal: {}, avoid: {})",
            task.goal.len(),
            task.avoid.len()
        )));
    }
    if task.also.len() >= MAX_GOALS {
        return Err(Error::Config(format!("a reach-avoid task has at most {MAX_GOALS} goals")));
    }
    let last = task.last();
    let masks = task.masks();
    let size = (last as u128 + 1) * masks as u128 * n as u128;
    if size > max_states as u128 {
        return Err(Error::Config(format!(
            "the reach-avoid optimum needs {size} states ({n} states x {} steps x {masks} sets \
             of goals reached), more than the limit of {max_states}; use a shorter deadline or \
             a smaller world",
            last as u128 + 1
        )));
    }
    let mut values = vec![0.0f64; size as usize];
    let q = (1.0 - moves.p) / 3.0;
    for t in (0..=last).rev() {
        for r in 0..masks {
            for s in 0..n {
                let (settled, reached) = task.settle(t, s, r);
                let v = match settled {
                    Some(v) => v,
                    None if t == last => f64::from(u8::from(reached == masks - 1)),
                    None => {
                        let next = &values[(masks * (t + 1) + reached) * n..][..n];
                        best_action(&moves.dest[s], next, moves.p, q).1
                    }
                };
                values[(masks * t + r) * n + s] = v;
            }
        }
    }
    let per_start: Vec<f64> = moves.starts.iter().map(|&s| values[s as usize]).collect();
    let probability = per_start.iter().sum::<f64>() / per_start.len() as f64;
    Ok(ReachAvoidOptimum {
        probability,
        per_start,
        task: task.clone(),
        dest: moves.dest.clone(),
        p: moves.p,
        last,
        values,
    })
}

/// The action with the most probability of success from a state whose moves lead to
/// `dest`, given the next step's values, and that probability; the lowest such action.
fn best_action(dest: &[u32; 4], next: &[f64], p: f64, q: f64) -> (usize, f64) {
    let w = dest.map(|t| next[t as usize]);
    let sum: f64 = w.iter().sum();
    (0..4)
        .map(|a| (a, p * w[a] + q * (sum - w[a])))
        .fold((0, f64::NEG_INFINITY), |best, (a, v)| if v > best.1 { (a, v) } else { best })
}

impl fmt::Debug for ReachAvoidOptimum {
    /// The figures, without the value table.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ReachAvoidOptimum")
            .field("probability", &self.probability)
            .field("starts", &self.per_start.len())
            .field("last_step", &self.last)
            .finish_non_exhaustive()
    }
}

impl ReachAvoidOptimum {
    /// A controller following the optimal policy.
    pub fn controller(&self) -> ReachAvoidController<'_> {
        ReachAvoidController { optimum: self, step: 0, reached: 0 }
    }

    /// The last step that matters, `max(T, T_avoid)`: a run of this many states plus one
    /// decides the task.
    pub fn last_step(&self) -> usize {
        self.last
    }

    /// Whether a run through `states` (from step 0) satisfies the task.
    pub fn satisfied(&self, states: &[usize]) -> bool {
        self.task.satisfied(states)
    }
}

impl Controller for ReachAvoidController<'_> {
    fn reset(&mut self) {
        self.step = 0;
        self.reached = 0;
    }

    fn act(&mut self, s: usize) -> Decision {
        let o = self.optimum;
        let n = o.dest.len();
        if s >= n {
            // Not a state of the solved world: take no valid action.
            return Decision { action: usize::MAX, option: 0, leg: 0 };
        }
        let (settled, reached) = o.task.settle(self.step, s, self.reached);
        self.reached = reached;
        if settled.is_some() || self.step >= o.last {
            // The task is decided: every action is as good.
            return Decision { action: 0, option: 0, leg: 0 };
        }
        let masks = o.task.masks();
        let next = &o.values[(masks * (self.step + 1) + reached) * n..][..n];
        let (action, _) = best_action(&o.dest[s], next, o.p, (1.0 - o.p) / 3.0);
        Decision { action, option: 0, leg: 0 }
    }

    fn observe(&mut self, _next: usize) {
        self.step = self.step.saturating_add(1);
    }
}
