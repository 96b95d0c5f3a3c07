//! The options level of a reach task planned with its legs (`plan: model`).
//!
//! Q-learned from segment rewards, the options level of a task such as `eventually[0..=15] A
//! && eventually[0..=50] B` may head for `B` first from where `A` was in reach: the rewards
//! of both choices are negative robustness alike. Under the model the greedy hierarchy is a
//! policy whose success probability is computable: the state of a run is the step, the state,
//! the goals reached in time and the option and leg running. So the choices are improved
//! as a policy is: for the current choices, a forward pass gives how often each decision
//! point `(step, state, goals met)` is reached from the starts seen in training, a backward
//! pass gives each option's probability of success from it, and each `(state, goals met)`
//! takes the option best on average over its steps. The best of a few rounds is kept,
//! judged by its success probability; where a round never decides, the values stay.

use super::TAIL_STEPS;
use crate::greedy::{argmax, best_of};
use crate::reach_avoid::ReachAvoid;
use crate::tables::Tables;

/// Rounds of improvement at most.
const ROUNDS: usize = 4;
/// At most this many values in a pass (steps x states x goal codes x running legs); larger
/// tasks keep their learned choices.
const MAX_WORK: usize = 1 << 26;

/// The greedy hierarchy of a reach task under a model of its moves.
pub(super) struct Hierarchy<'a> {
    task: &'a ReachAvoid,
    tables: &'a Tables,
    moves: &'a [Vec<(usize, f64)>],
    /// `step[p][s]`: primitive `p`'s greedy action in `s`, `None` where no move is known.
    step: Vec<Vec<Option<usize>>>,
    /// `in_goal[s]`: the goals (bits) whose region holds at `s`.
    in_goal: Vec<usize>,
    /// `due[t]`: the goals (bits) that may still be entered at step `t`.
    due: Vec<usize>,
    /// The last step judged: the deadlines, and past them the avoidance for at most
    /// [`TAIL_STEPS`] more.
    last: usize,
    codes: usize,
    /// `slot[o]`: where option `o`'s first leg is among the running legs.
    slot: Vec<usize>,
    /// `running[k]`: the option and leg of running leg `k`.
    running: Vec<(usize, usize)>,
}

/// A round's result: the success probability from the starts, and per decision point
/// `(state, goals met)` how often it is reached and each option's value summed over steps.
struct Round {
    success: f64,
    reached: Vec<f64>,
    value: Vec<f64>,
}

impl<'a> Hierarchy<'a> {
    /// The hierarchy of `flat`'s greedy legs, or `None` when its passes would be too large
    /// or `codes` does not count the task's goals.
    pub fn new(
        task: &'a ReachAvoid,
        tables: &'a Tables,
        flat: &[Vec<f64>],
        moves: &'a [Vec<(usize, f64)>],
        codes: usize,
    ) -> Option<Hierarchy<'a>> {
        let (states, actions) = (tables.states, tables.actions);
        let goals: Vec<(&Vec<bool>, usize)> = std::iter::once((&task.goal, task.reach_by))
            .chain(task.also.iter().map(|(g, by)| (g, *by)))
            .collect();
        if codes != 1 << goals.len() {
            return None;
        }
        let deadline: Vec<usize> = goals.iter().map(|g| g.1).collect();
        let reach_by = deadline.iter().copied().max().unwrap_or(0);
        let last = task.avoid_through.min(reach_by.saturating_add(TAIL_STEPS)).max(reach_by);
        let mut slot = Vec::with_capacity(tables.legs.len());
        let mut running = Vec::new();
        for (o, legs) in tables.legs.iter().enumerate() {
            slot.push(running.len());
            running.extend((0..legs.len()).map(|l| (o, l)));
        }
        let work = (last + 1)
            .checked_mul(states)?
            .checked_mul(codes)?
            .checked_mul(running.len().max(tables.legs.len()))?;
        if work > MAX_WORK {
            return None;
        }
        let step = flat
            .iter()
            .map(|table| {
                (0..states)
                    .map(|s| {
                        let a = argmax(&table[s * actions..][..actions]);
                        (!moves[s * actions + a].is_empty()).then_some(a)
                    })
                    .collect()
            })
            .collect();
        let in_goal = (0..states)
            .map(|s| goals.iter().enumerate().filter(|(_, g)| g.0[s]).map(|(j, _)| 1 << j).sum())
            .collect();
        let due = (0..=last)
            .map(|t| {
                deadline.iter().enumerate().filter(|(_, d)| t <= **d).map(|(j, _)| 1 << j).sum()
            })
            .collect();
        Some(Hierarchy { task, tables, moves, step, in_goal, due, last, codes, slot, running })
    }

    /// The options values `table` (`options[(s * codes + met) * n + o]`, one memory value)
    /// with the choices improved, or `None` when no round improves on it.
    pub fn improve(&self, table: &[f64], start: &[f64]) -> Option<Vec<f64>> {
        let n = self.tables.legs.len();
        let mut current = table.to_vec();
        let mut round = self.round(&self.choices(&current), start);
        let mut best: Option<(f64, Vec<f64>)> = None;
        let first = round.success;
        for _ in 0..ROUNDS {
            // The values of this round's choices, where they were reached.
            let mut next = current.clone();
            for (point, &times) in round.reached.iter().enumerate() {
                if times > 0.0 {
                    let row = &mut next[point * n..][..n];
                    for (v, sum) in row.iter_mut().zip(&round.value[point * n..][..n]) {
                        *v = sum / times;
                    }
                }
            }
            let choices = self.choices(&next);
            if choices == self.choices(&current) {
                break;
            }
            let after = self.round(&choices, start);
            if after.success <= best.as_ref().map_or(first, |b| b.0) {
                break;
            }
            best = Some((after.success, next.clone()));
            current = next;
            round = after;
        }
        best.map(|(_, table)| table)
    }

    /// The success probability from `start` of the choices greedy on `table`.
    pub fn success(&self, table: &[f64], start: &[f64]) -> f64 {
        self.backward(&self.choices(table), start, None).success
    }

    /// The option greedy on `table` at each `(state, goals met)`, among those available.
    fn choices(&self, table: &[f64]) -> Vec<usize> {
        let n = self.tables.legs.len();
        (0..self.tables.states * self.codes)
            .map(|point| {
                best_of(&self.tables.available[point / self.codes], &table[point * n..][..n])
            })
            .collect()
    }

    /// The goals met after entering `s` at step `t` with `met` before, or `None` when the
    /// run fails there (an avoided state, or a goal past its deadline).
    fn enter(&self, s: usize, t: usize, met: usize) -> Option<usize> {
        if self.task.avoid[s] && t <= self.task.avoid_through {
            return None;
        }
        let due = self.due[t];
        let met = met | (self.in_goal[s] & due);
        // A goal that can no longer be entered and was not is lost.
        let late = !due & (self.codes - 1) & !met != 0;
        (!late).then_some(met)
    }

    /// One forward and one backward pass under `choices`.
    fn round(&self, choices: &[usize], start: &[f64]) -> Round {
        let reached = self.forward(choices, start);
        self.backward(choices, start, Some(&reached))
    }

    /// How often each decision point is reached at each step under `choices`:
    /// `reached[(t * states + s) * codes + met]`.
    fn forward(&self, choices: &[usize], start: &[f64]) -> Vec<f64> {
        let (states, actions, codes) = (self.tables.states, self.tables.actions, self.codes);
        let k = self.running.len();
        // Forward: how often each decision point is reached at each step.
        let mut reached = vec![0.0f64; (self.last + 1) * states * codes];
        let mut mass = vec![0.0f64; states * codes * k];
        for (s, &w) in start.iter().enumerate() {
            if w > 0.0
                && let Some(met) = self.enter(s, 0, 0)
            {
                let point = s * codes + met;
                reached[point] += w;
                mass[point * k + self.slot[choices[point]]] += w;
            }
        }
        for t in 0..self.last {
            let mut after = vec![0.0f64; states * codes * k];
            let now = (t + 1) * states * codes;
            for (i, &m) in mass.iter().enumerate().filter(|(_, m)| **m > 0.0) {
                let (point, r) = (i / k, i % k);
                let (s, met) = (point / codes, point % codes);
                let (o, l) = self.running[r];
                let p = self.tables.legs[o][l];
                let Some(a) = self.step[p][s] else { continue };
                for &(next, w) in &self.moves[s * actions + a] {
                    let Some(met) = self.enter(next, t + 1, met) else { continue };
                    let to = next * codes + met;
                    if !self.tables.term[p][next] {
                        after[to * k + r] += m * w;
                    } else if l + 1 < self.tables.legs[o].len() {
                        after[to * k + r + 1] += m * w;
                    } else {
                        reached[now + to] += m * w;
                        after[to * k + self.slot[choices[to]]] += m * w;
                    }
                }
            }
            mass = after;
        }
        reached
    }

    /// The probability of success from each running leg under `choices`, summed into each
    /// option's value where `reached` says a decision point is reached (without it, the
    /// success probability alone).
    fn backward(&self, choices: &[usize], start: &[f64], reached: Option<&[f64]>) -> Round {
        let (states, actions, codes) = (self.tables.states, self.tables.actions, self.codes);
        let (n, k) = (self.tables.legs.len(), self.running.len());
        let all = codes - 1;
        // Backward: the probability of success from each running leg, summed into each
        // option's value where a decision point is reached.
        let sums = if reached.is_some() { states * codes } else { 0 };
        let mut value = vec![0.0f64; sums * n];
        let mut times = vec![0.0f64; sums];
        let mut later = vec![0.0f64; states * codes * k];
        let mut decide = vec![0.0f64; states * codes];
        let mut here = vec![0.0f64; states * codes * k];
        for t in (0..self.last).rev() {
            here.fill(0.0);
            // A run at step `t` has met every goal past its deadline: other rows stay 0
            // (past the last deadline, only the row of every goal met is computed).
            let lost = !self.due[t] & all;
            let (due, lost_next) = (self.due[t + 1], !self.due[t + 1] & all);
            let avoiding = t < self.task.avoid_through;
            for s in 0..states {
                for (r, &(o, l)) in self.running.iter().enumerate() {
                    let p = self.tables.legs[o][l];
                    let Some(a) = self.step[p][s] else { continue };
                    let (moves, term) = (&self.moves[s * actions + a], &self.tables.term[p]);
                    let last_leg = l + 1 == self.tables.legs[o].len();
                    for met in (0..codes).filter(|met| lost & !met == 0) {
                        let mut v = 0.0;
                        for &(next, w) in moves {
                            // `enter(next, t + 1, met)`, with what depends on `t` hoisted.
                            if avoiding && self.task.avoid[next] {
                                continue;
                            }
                            let met = met | (self.in_goal[next] & due);
                            if lost_next & !met != 0 {
                                continue;
                            }
                            let to = next * codes + met;
                            v += w * if t + 1 == self.last {
                                f64::from(u8::from(met == all))
                            } else if !term[next] {
                                later[to * k + r]
                            } else if !last_leg {
                                later[to * k + r + 1]
                            } else {
                                decide[to]
                            };
                        }
                        here[(s * codes + met) * k + r] = v;
                    }
                }
            }
            let base = t * states * codes;
            for point in 0..states * codes {
                decide[point] = here[point * k + self.slot[choices[point]]];
                let Some(reached) = reached else { continue };
                let w = reached[base + point];
                if w > 0.0 {
                    times[point] += w;
                    for &o in &self.tables.available[point / codes] {
                        value[point * n + o] += w * here[point * k + self.slot[o]];
                    }
                }
            }
            std::mem::swap(&mut later, &mut here);
        }
        let success = start
            .iter()
            .enumerate()
            .filter_map(|(s, &w)| Some(w * decide[s * codes + self.enter(s, 0, 0)?]))
            .sum();
        Round { success, reached: times, value }
    }
}
