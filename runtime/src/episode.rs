//! What the two learners' episodes share, given one home: the loop over training episodes,
//! the loop over option choices (with the hold once every goal is met), the epsilon-greedy
//! draw and its schedule, and the discount powers of the intra-option updates. The tabular
//! learner (`learn`) and the approximate one (`approx::learn`) both call these; each keeps
//! only what its representation changes (a row of a table or a sum of weights, a state
//! index or a valuation).

use std::ops::ControlFlow;

use hstl_robustness::Formula;
use rand::RngExt;

use crate::Rng;
use crate::progress::run_steps;
use crate::spec::LevelParams;

/// The curve of `episodes` episodes, each run by `episode`, calling `progress(episode,
/// reward)` after each and stopping after the one for which it breaks.
pub(crate) fn train_episodes(
    episodes: usize,
    mut episode: impl FnMut() -> f64,
    mut progress: impl FnMut(usize, f64) -> ControlFlow<()>,
) -> Vec<f64> {
    let mut curve = Vec::with_capacity(episodes);
    for e in 0..episodes {
        let reward = episode();
        curve.push(reward);
        if progress(e, reward).is_break() {
            break;
        }
    }
    curve
}

/// How many options an episode chooses: `learn.choices`, and past them, once every goal of
/// a task that is not persistent is met, on to the task's horizon, as a greedy run does
/// (the options level learns to keep the rest where the run then is; with one option it
/// has nothing to learn).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Choices {
    limit: usize,
    /// Every goal met, and the steps to hold to.
    hold: Option<(usize, usize)>,
}

impl Choices {
    /// The choices of an episode of `task` with `legs` options, `limit` choices and, for a
    /// task with goals, `all_met` (the code of every goal met).
    pub(crate) fn new(limit: usize, all_met: Option<usize>, legs: usize, task: &Formula) -> Self {
        let hold = all_met.filter(|_| legs > 1).map(|all| (all, run_steps(task) - 1));
        Choices { limit, hold }
    }

    /// Whether the episode makes choice number `choice`, with the goals `met` so far after
    /// `steps` steps.
    pub(crate) fn go_on(&self, choice: usize, met: usize, steps: usize) -> bool {
        let holding = self.hold.is_some_and(|(all, h)| met == all && steps < h);
        choice < self.limit || holding
    }
}

/// Whether the next move explores: epsilon of `level` after `*count` draws (`min_epsilon`
/// from `floor` on, see [`floor_from`]), the count advanced, and one uniform draw from
/// `rng` below it.
#[inline]
pub(crate) fn explores(
    level: &LevelParams,
    floor: Option<u64>,
    count: &mut u64,
    rng: &mut Rng,
) -> bool {
    // At and past the floor `epsilon_at` is `min_epsilon` (or a value equal to it): the
    // comparison below is the same.
    let eps = match floor {
        Some(floor) if *count >= floor => level.min_epsilon,
        _ => level.epsilon_at(*count),
    };
    *count += 1;
    rng.random::<f64>() < eps
}

/// The least `n` with `epsilon - decay * n <= min_epsilon`, from which
/// [`LevelParams::epsilon_at`] is `min_epsilon`, or `None` when no `u64` reaches it. With
/// `decay >= 0` (validated) the expression does not increase with `n`: every rounded
/// operation is monotone.
pub(crate) fn floor_from(level: &LevelParams) -> Option<u64> {
    let at_floor = |n: u64| level.epsilon - level.decay * n as f64 <= level.min_epsilon;
    if !at_floor(u64::MAX) {
        return None;
    }
    let (mut lo, mut hi) = (0, u64::MAX);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if at_floor(mid) { hi = mid } else { lo = mid + 1 }
    }
    Some(lo)
}

/// `powers[i] = gamma^i` for every `i <= k`, extending what is there.
pub(crate) fn gamma_powers_to(powers: &mut Vec<f64>, gamma: f64, k: usize) {
    if powers.len() <= k {
        let last = powers.len();
        powers.extend((last..=k).map(|i| gamma.powi(i as i32)));
    }
}

/// `out[j]`: the window reward of the suffix of a run from position `j`, `R_j = psi(j + 1) +
/// gamma R_{j + 1}` with `R_k = 0` (`k = psi.len() - 1`): the discounted count of the
/// suffix's steps whose windows are all kept.
pub(crate) fn window_suffix_rewards(psi: &[bool], gamma: f64, out: &mut Vec<f64>) {
    let k = psi.len() - 1;
    out.clear();
    out.resize(k + 1, 0.0);
    for j in (0..k).rev() {
        let kept = if psi[j + 1] { 1.0 } else { 0.0 };
        out[j] = kept + gamma * out[j + 1];
    }
}

/// The segment rewards of every suffix of a run along which goals were met: `met[j]` is the
/// goals-met code at position `j`, and `score(code, into)` fills `into[j]` with the reward of
/// every suffix against the conjuncts still open under `code` (`k + 1` values). The
/// positions under the run's first code take its scores, each later stretch under one code
/// the scores under that code (`other` is a buffer).
pub(crate) fn goal_suffix_rewards(
    met: &[usize],
    k: usize,
    out: &mut Vec<f64>,
    other: &mut Vec<f64>,
    mut score: impl FnMut(usize, &mut Vec<f64>),
) {
    score(met.first().copied().unwrap_or(0), out);
    let mut j = 0;
    while let Some(offset) = met.get(j..).and_then(|m| m.iter().position(|&x| x != m[0])) {
        j += offset;
        let code = met[j];
        score(code, other);
        let until = met[j..].iter().position(|&m| m != code).map_or(k + 1, |e| j + e);
        out[j..until].copy_from_slice(&other[j..until]);
    }
}
