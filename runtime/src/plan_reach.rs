//! `learn { plan: model }` on a reach task (`eventually[0..=T] Goal && always !R`, one or
//! more goals each with its deadline): the legs planned from the transitions seen in
//! training instead of trusting the learned flat values (LANGUAGE.md, "Presets").
//!
//! A leg learned from the reward `min(rho(Goal), -rho(R))` with discount 0.9 heads for the
//! goal with a margin from `R`, which is not the task: the task is the probability of
//! arriving by step `T` without ever entering `R`. So after training, for every leg that
//! stops on entering one of the task's goals, dynamic programming under the model gives
//! `Q_h(s, a)`, the probability of entering the goal within `h` more steps without entering
//! an avoided state, after `a` in `s` and the best actions from there. The best action
//! depends on the steps left, but a leg's table is one action per state, so the planner
//! weighs the stationary policies `pi_h` (each state's best action with `h` steps left, or
//! with more where `h` are too few to arrive): for each it computes exactly, under the
//! model and from the episode starts seen in training, the probability that the leg alone
//! satisfies the goal's conjunct and the task's avoidance, and keeps the best. Its table
//! holds `Q_h` for the tried actions and [`crate::plan::UNTRIED`] for the others; a state
//! where nothing is known keeps its learned values.
//!
//! With several goals each leg is planned against its own deadline from the starts of
//! training; the options level stays Q-learned, but for a hold: a leg that enters no goal
//! and keeps out of exactly the task's avoided states (`keep_clear`, which `preset: auto`
//! adds). Once every goal is met only the avoidance is left, so the hold's leg is planned
//! to keep out longest, and the options values of those observations become the
//! probability of keeping out over the next [`TAIL_STEPS`] steps if each option's first leg
//! were followed throughout; before then the hold enters no goal, so it is never chosen.

mod choices;

use crate::plan::UNTRIED;
use crate::reach_avoid::ReachAvoid;
use crate::tables::Tables;
use crate::{Env, Error, TaskSpec};

/// At most this many numbers in the planner's tables (horizons times states times actions).
const MAX_VALUES: usize = 1 << 24;
/// At most this many stationary policies are weighed per leg.
const CANDIDATES: usize = 24;
/// Past the goal's deadline, an unbounded avoidance is judged over at most this many more
/// steps when the candidates are weighed.
const TAIL_STEPS: usize = 400;

/// The task's goals and avoided states, and which leg enters which goal.
#[derive(Clone, Debug)]
pub(crate) struct ReachPlanner {
    task: ReachAvoid,
    /// `goal_of[p]`: the goal (0 for the first, `1 + j` for `also[j]`) primitive `p` stops
    /// on entering, if any.
    goal_of: Vec<Option<usize>>,
    /// `hold[p]`: primitive `p` enters no goal and keeps out of exactly the task's avoided
    /// states.
    hold: Vec<bool>,
}

/// Where the options values are in their table: `options[obs * n + o]`, the observation of
/// state `s`, memory value `v` and goals met `m` being `(s * values + v) * codes + m`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct OptionsLayout {
    pub values: usize,
    pub codes: usize,
    /// The code of every goal met.
    pub all_met: usize,
}

impl ReachPlanner {
    /// The planner of `spec`'s legs, or `None` when its task is not a reach task.
    pub fn new<E: Env>(
        spec: &TaskSpec,
        env: &E,
        tables: &Tables,
    ) -> Result<Option<ReachPlanner>, Error> {
        let Some(task) =
            ReachAvoid::of_spec(spec, env, crate::eval::WindowConfig::default().steps)?
        else {
            return Ok(None);
        };
        let goals: Vec<&Vec<bool>> =
            std::iter::once(&task.goal).chain(task.also.iter().map(|(g, _)| g)).collect();
        let goal_of = (0..tables.term.len())
            .map(|p| {
                let stops: Vec<bool> = (0..tables.states)
                    .map(|s| tables.term[p][s] && !tables.ends[p].as_ref().is_some_and(|e| e[s]))
                    .collect();
                goals.iter().position(|g| **g == stops && g.iter().any(|&x| x))
            })
            .collect::<Vec<_>>();
        let hold = (0..tables.term.len())
            .map(|p| goal_of[p].is_none() && tables.ends[p].as_ref() == Some(&task.avoid))
            .collect();
        Ok(Some(ReachPlanner { task, goal_of, hold }))
    }

    /// The steps a hold leg is planned to keep out over: the avoidance's, at most
    /// [`TAIL_STEPS`].
    fn hold_steps(&self) -> usize {
        self.task.avoid_through.clamp(1, TAIL_STEPS)
    }

    /// The flat tables with every leg that enters a goal planned under `moves` (the
    /// model's `moves[s * actions + a]`), from the episode starts `starts` (counts per
    /// state).
    pub fn legs(
        &self,
        tables: &Tables,
        flat: &[Vec<f64>],
        moves: &[Vec<(usize, f64)>],
        starts: &[u32],
    ) -> Vec<Vec<f64>> {
        let mut out = flat.to_vec();
        let total: f64 = starts.iter().map(|&c| f64::from(c)).sum();
        if total == 0.0 {
            return out;
        }
        let start: Vec<f64> = starts.iter().map(|&c| f64::from(c) / total).collect();
        if self.hold.iter().any(|&h| h) {
            let leg = LegTask {
                goal: &self.task.goal,
                avoid: &self.task.avoid,
                reach_by: 0,
                avoid_through: self.task.avoid_through,
            };
            let (_, rows) = leg.safety(tables.states, tables.actions, moves, self.hold_steps());
            for p in (0..self.hold.len()).filter(|&p| self.hold[p]) {
                overlay(&mut out[p], &rows, tables.actions);
            }
        }
        for (p, goal) in self.goal_of.iter().enumerate() {
            let Some(j) = *goal else { continue };
            if let Some(table) = self.leg(j).plan(tables.states, tables.actions, moves, &start) {
                overlay(&mut out[p], &table, tables.actions);
            }
        }
        out
    }

    /// The legs `flat` (from [`ReachPlanner::legs`]) and the options values `options`
    /// (laid out as `layout` says) planned together under `moves`, from the episode starts
    /// `starts` (counts per state): the holds first ([`ReachPlanner::holds`]); then, without
    /// memory, the choices improved on the whole task's success probability (`choices`),
    /// each goal's leg replaced by the candidate best for the whole task under those
    /// choices (a leg is planned alone from the starts of training, where the hierarchy
    /// runs it from where the leg before it arrives, with the time that leaves), and the
    /// choices improved again. `learned` are the learned flat values, which a planned leg
    /// keeps where the model knows nothing.
    #[allow(clippy::too_many_arguments)]
    pub fn hierarchy(
        &self,
        tables: &Tables,
        learned: &[Vec<f64>],
        mut flat: Vec<Vec<f64>>,
        moves: &[Vec<(usize, f64)>],
        starts: &[u32],
        options: &[f64],
        layout: OptionsLayout,
    ) -> (Vec<Vec<f64>>, Vec<f64>) {
        let mut out = self.holds(tables, &flat, moves, options, layout);
        let total: f64 = starts.iter().map(|&c| f64::from(c)).sum();
        if layout.values != 1 || total == 0.0 {
            return (flat, out);
        }
        let start: Vec<f64> = starts.iter().map(|&c| f64::from(c) / total).collect();
        let hierarchy = |flat: &[Vec<f64>]| {
            choices::Hierarchy::new(&self.task, tables, flat, moves, layout.codes)
        };
        let Some(h) = hierarchy(&flat) else { return (flat, out) };
        if let Some(better) = h.improve(&out, &start) {
            out = better;
        }
        let (states, actions) = (tables.states, tables.actions);
        let mut changed = false;
        for (p, goal) in self.goal_of.iter().enumerate() {
            let Some(j) = *goal else { continue };
            let Some(candidates) = self.leg(j).candidates(states, actions, moves, &start) else {
                continue;
            };
            let mut best: Option<(f64, Vec<f64>)> = None;
            for (_, table) in candidates {
                let mut trial = flat.clone();
                trial[p] = learned[p].clone();
                overlay(&mut trial[p], &table, actions);
                let value = hierarchy(&trial).map_or(0.0, |h| h.success(&out, &start));
                if best.as_ref().is_none_or(|(b, _)| value > *b) {
                    best = Some((value, trial.swap_remove(p)));
                }
            }
            if let Some((_, leg)) = best
                && leg != flat[p]
            {
                flat[p] = leg;
                changed = true;
            }
        }
        if changed
            && let Some(h) = hierarchy(&flat)
            && let Some(better) = h.improve(&out, &start)
        {
            out = better;
        }
        (flat, out)
    }

    /// The task of the leg that enters goal `j` (0 for the first, `1 + i` for `also[i]`).
    fn leg(&self, j: usize) -> LegTask<'_> {
        let (goal, reach_by) = match j {
            0 => (&self.task.goal, self.task.reach_by),
            j => (&self.task.also[j - 1].0, self.task.also[j - 1].1),
        };
        LegTask { goal, avoid: &self.task.avoid, reach_by, avoid_through: self.task.avoid_through }
    }

    /// The options values `options` with the holds planned: where every goal is met, each
    /// option's value is the probability under `moves` of keeping out of the avoided states
    /// over the next steps if its first leg's greedy actions in `flat` were followed
    /// throughout (0 from a state with no known action); before then a hold option is worth
    /// [`UNTRIED`]. Unchanged without a hold option.
    fn holds(
        &self,
        tables: &Tables,
        flat: &[Vec<f64>],
        moves: &[Vec<(usize, f64)>],
        options: &[f64],
        layout: OptionsLayout,
    ) -> Vec<f64> {
        let mut out = options.to_vec();
        let n = tables.legs.len();
        let is_hold = |o: usize| tables.legs[o].first().is_some_and(|&p| self.hold[p]);
        if !(0..n).any(is_hold) {
            return out;
        }
        let (states, actions) = (tables.states, tables.actions);
        // survive[o][s]: the probability of keeping out from `s` under option `o`'s first leg.
        let survive: Vec<Vec<f64>> = (0..n)
            .map(|o| {
                let p = tables.legs[o][0];
                let step: Vec<Option<usize>> = (0..states)
                    .map(|s| {
                        let row = &flat[p][s * actions..][..actions];
                        let a = crate::greedy::argmax(row);
                        (!moves[s * actions + a].is_empty()).then_some(a)
                    })
                    .collect();
                let mut w: Vec<f64> =
                    (0..states).map(|s| if self.task.avoid[s] { 0.0 } else { 1.0 }).collect();
                for _ in 0..self.hold_steps() {
                    w = (0..states)
                        .map(|s| match step[s] {
                            Some(a) if !self.task.avoid[s] => {
                                moves[s * actions + a].iter().map(|&(t, q)| q * w[t]).sum()
                            }
                            _ => 0.0,
                        })
                        .collect();
                }
                w
            })
            .collect();
        let OptionsLayout { values, codes, all_met } = layout;
        for s in 0..states {
            for v in 0..values {
                for met in 0..codes {
                    let row = &mut out[((s * values + v) * codes + met) * n..][..n];
                    for (o, value) in row.iter_mut().enumerate() {
                        if met == all_met {
                            *value = survive[o][s];
                        } else if is_hold(o) {
                            *value = UNTRIED;
                        }
                    }
                }
            }
        }
        out
    }
}

/// `planned`'s rows over `table` where it knows something (a row not all [`UNTRIED`]).
fn overlay(table: &mut [f64], planned: &[f64], actions: usize) {
    for (row, new) in table.chunks_mut(actions).zip(planned.chunks(actions)) {
        if new.iter().any(|&v| v > UNTRIED) {
            row.copy_from_slice(new);
        }
    }
}

/// One leg's task: enter `goal` by step `reach_by`, never entering `avoid` through step
/// `avoid_through`.
struct LegTask<'a> {
    goal: &'a [bool],
    avoid: &'a [bool],
    reach_by: usize,
    avoid_through: usize,
}

impl LegTask<'_> {
    /// The planned table, `Q(s, a)` with [`UNTRIED`] for untried actions and a row of
    /// [`UNTRIED`] where nothing is known: the best of [`LegTask::candidates`] alone, the
    /// first on a tie; `None` when the tables would be too large.
    fn plan(
        &self,
        states: usize,
        actions: usize,
        moves: &[Vec<(usize, f64)>],
        start: &[f64],
    ) -> Option<Vec<f64>> {
        let mut best: Option<(f64, Vec<f64>)> = None;
        for (value, table) in self.candidates(states, actions, moves, start)? {
            if best.as_ref().is_none_or(|(b, _)| value > *b) {
                best = Some((value, table));
            }
        }
        best.map(|(_, table)| table)
    }

    /// The candidate tables, each with the probability under the model and from `start`
    /// that the leg alone satisfies the goal's conjunct and the task's avoidance: the
    /// stationary policies "act as if `h` steps were left", from the longest horizon down,
    /// each followed by its variant whose goal cells keep out of the avoided states longest
    /// when the avoidance outlasts the deadline; `None` when the tables would be too large.
    fn candidates(
        &self,
        states: usize,
        actions: usize,
        moves: &[Vec<(usize, f64)>],
        start: &[f64],
    ) -> Option<Vec<(f64, Vec<f64>)>> {
        let horizon = self.reach_by.max(1);
        if horizon.checked_mul(states)?.checked_mul(actions)? > MAX_VALUES {
            return None;
        }
        // q[h - 1]: Q_h over states and actions, for h = 1..=horizon.
        let mut q: Vec<Vec<f64>> = Vec::with_capacity(horizon);
        let mut v = vec![0.0f64; states];
        let arrive = |v: &[f64], n: usize| -> f64 {
            if self.avoid[n] {
                0.0
            } else if self.goal[n] {
                1.0
            } else {
                v[n]
            }
        };
        for _ in 0..horizon {
            let mut qh = vec![UNTRIED; states * actions];
            let mut next = vec![0.0f64; states];
            for s in 0..states {
                let mut best = 0.0f64;
                for a in 0..actions {
                    let m = &moves[s * actions + a];
                    if m.is_empty() {
                        continue;
                    }
                    let value: f64 = m.iter().map(|&(n, w)| w * arrive(&v, n)).sum();
                    qh[s * actions + a] = value;
                    best = best.max(value);
                }
                next[s] = best;
            }
            q.push(qh);
            v = next;
        }
        // The row of the horizon a state's action comes from: the best with `h` steps
        // left, or with the fewest more under which the goal can be entered at all.
        let row_of = |h: usize, s: usize| -> Option<&[f64]> {
            q[h - 1..]
                .iter()
                .map(|qh| &qh[s * actions..][..actions])
                .find(|row| row[crate::greedy::argmax(row)] > 0.0)
        };
        let policy = |h: usize| -> Vec<Option<usize>> {
            (0..states).map(|s| row_of(h, s).map(crate::greedy::argmax)).collect()
        };
        let table = |h: usize, keep_out: Option<&(Vec<Option<usize>>, Vec<f64>)>| -> Vec<f64> {
            let mut table = vec![UNTRIED; states * actions];
            for s in 0..states {
                let row = match keep_out {
                    Some((safe, rows)) if self.goal[s] && safe[s].is_some() => {
                        Some(&rows[s * actions..][..actions])
                    }
                    _ => row_of(h, s),
                };
                if let Some(row) = row {
                    table[s * actions..][..actions].copy_from_slice(row);
                }
            }
            table
        };
        // Once the goal has held, only the avoidance is left: in the goal's cells the
        // variants keep out of the avoided states longest.
        let tail = self.last().saturating_sub(self.reach_by);
        let safe = (tail > 0).then(|| self.safety(states, actions, moves, tail));
        let step = horizon.div_ceil(CANDIDATES).max(1);
        let mut out = Vec::new();
        let mut h = horizon;
        loop {
            let mut pi = policy(h);
            out.push((self.evaluate(&pi, moves, actions, start), table(h, None)));
            if let Some(safe) = &safe {
                for s in (0..states).filter(|&s| self.goal[s] && safe.0[s].is_some()) {
                    pi[s] = safe.0[s];
                }
                out.push((self.evaluate(&pi, moves, actions, start), table(h, Some(safe))));
            }
            if h <= step {
                break;
            }
            h -= step;
        }
        Some(out)
    }

    /// The last step the candidates are judged to: the deadline, and past it the
    /// avoidance for at most [`TAIL_STEPS`] more.
    fn last(&self) -> usize {
        self.avoid_through.min(self.reach_by.saturating_add(TAIL_STEPS)).max(self.reach_by)
    }

    /// The actions that keep out of the avoided states longest over `steps` steps under the
    /// model, per state (`None` where nothing is known or nothing keeps out), and their
    /// values, [`UNTRIED`] for untried actions.
    fn safety(
        &self,
        states: usize,
        actions: usize,
        moves: &[Vec<(usize, f64)>],
        steps: usize,
    ) -> (Vec<Option<usize>>, Vec<f64>) {
        let mut w: Vec<f64> = (0..states).map(|s| if self.avoid[s] { 0.0 } else { 1.0 }).collect();
        let mut rows = vec![UNTRIED; states * actions];
        for _ in 0..steps {
            let mut next = vec![0.0f64; states];
            for s in (0..states).filter(|&s| !self.avoid[s]) {
                for a in 0..actions {
                    let m = &moves[s * actions + a];
                    if m.is_empty() {
                        continue;
                    }
                    let value: f64 = m.iter().map(|&(n, p)| p * w[n]).sum();
                    rows[s * actions + a] = value;
                    next[s] = next[s].max(value);
                }
            }
            w = next;
        }
        let chosen = (0..states)
            .map(|s| {
                let row = &rows[s * actions..][..actions];
                let best = crate::greedy::argmax(row);
                (row[best] > 0.0).then_some(best)
            })
            .collect();
        (chosen, rows)
    }

    /// The probability, under the model and from `start`, that a run following `policy`
    /// enters the goal by `reach_by` without entering an avoided state through
    /// `avoid_through` (a state with no known action stays where it is and fails).
    fn evaluate(
        &self,
        policy: &[Option<usize>],
        moves: &[Vec<(usize, f64)>],
        actions: usize,
        start: &[f64],
    ) -> f64 {
        let states = policy.len();
        let last = self.last();
        // after[r][s]: the probability of success from state s at step t + 1.
        let mut after = [vec![0.0f64; states], vec![0.0f64; states]];
        for t in (0..=last).rev() {
            let mut now = [vec![0.0f64; states], vec![0.0f64; states]];
            for (r, row) in now.iter_mut().enumerate() {
                for s in 0..states {
                    if t <= self.avoid_through && self.avoid[s] {
                        continue;
                    }
                    let reached = r == 1 || (t <= self.reach_by && self.goal[s]);
                    if reached && t >= last {
                        row[s] = 1.0;
                        continue;
                    }
                    if !reached && t >= self.reach_by {
                        continue;
                    }
                    let Some(a) = policy[s] else { continue };
                    let next = &after[usize::from(reached)];
                    row[s] = moves[s * actions + a].iter().map(|&(n, w)| w * next[n]).sum();
                }
            }
            after = now;
        }
        start.iter().zip(&after[0]).map(|(w, v)| w * v).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A corridor of five states, actions Left (0) and Right (1), deterministic moves.
    fn corridor() -> Vec<Vec<(usize, f64)>> {
        (0..5)
            .flat_map(|s: usize| [vec![(s.saturating_sub(1), 1.0)], vec![((s + 1).min(4), 1.0)]])
            .collect()
    }

    #[test]
    fn a_planned_leg_takes_the_way_that_arrives_in_time() {
        let moves = corridor();
        let goal = [false, false, false, false, true];
        let avoid = [true, false, false, false, false];
        let mut start = vec![0.0; 5];
        start[1] = 1.0;
        let leg = LegTask { goal: &goal, avoid: &avoid, reach_by: 3, avoid_through: 3 };
        let table = leg.plan(5, 2, &moves, &start).expect("small");
        for s in 1..4 {
            assert!(table[s * 2 + 1] > table[s * 2], "state {s}: {:?}", &table[s * 2..][..2]);
        }
        // Right from 1 arrives at step 3: the task holds for certain.
        let right = vec![Some(1); 5];
        assert_eq!(leg.evaluate(&right, &moves, 2, &start), 1.0);
        let left = vec![Some(0); 5];
        assert_eq!(leg.evaluate(&left, &moves, 2, &start), 0.0);
        // Two steps are too few from state 1: the model knows no way there, so its row is
        // left to the learned values; from 2 and 3 the goal is reached.
        let leg = LegTask { goal: &goal, avoid: &avoid, reach_by: 2, avoid_through: 2 };
        let table = leg.plan(5, 2, &moves, &start).expect("small");
        assert_eq!(&table[2..4], [UNTRIED, UNTRIED]);
        assert!(table[2 * 2 + 1] > table[2 * 2]);
    }
}
