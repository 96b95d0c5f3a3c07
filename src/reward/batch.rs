//! The episodes of a vector of environments (gymnasium's `VectorEnv`) scored side by
//! side: one call a vector step scores every environment's new observation, so the cost
//! of crossing from Python is paid once for all of them (`hstl.STLVectorReward`).

use super::{EpisodeMonitor, StepScore};
use crate::monitor::TraceError;

/// One [`EpisodeMonitor`] for each environment of a vector, reading its state variables
/// off each row of a batch of observations by index.
#[derive(Clone, Debug)]
pub struct EpisodeBatch {
    monitors: Vec<EpisodeMonitor>,
    /// State variable `i` is column `picks[i]` of an observation row.
    picks: Vec<usize>,
    /// The state read off one row (kept to reuse its allocation).
    state: Vec<f64>,
}

/// A row of a batch that could not be scored.
#[derive(Clone, Debug, PartialEq)]
pub struct RowError {
    /// The environment's index in the vector.
    pub env: usize,
    /// What is wrong with its state.
    pub error: TraceError,
}

impl EpisodeBatch {
    /// `envs` copies of `monitor`, each reading state variable `i` from column `picks[i]`
    /// of its row (`picks` in the monitor's `state_vars` order).
    pub fn new(monitor: &EpisodeMonitor, envs: usize, picks: Vec<usize>) -> EpisodeBatch {
        EpisodeBatch { monitors: vec![monitor.clone(); envs], picks, state: Vec::new() }
    }

    /// The number of environments.
    pub fn len(&self) -> usize {
        self.monitors.len()
    }

    /// Whether the vector has no environment.
    pub fn is_empty(&self) -> bool {
        self.monitors.is_empty()
    }

    /// The columns an observation row needs at least.
    pub fn width(&self) -> usize {
        self.picks.iter().max().map_or(0, |m| m + 1)
    }

    /// Starts every episode anew at the rows of `obs` (row-major, `width` values a row,
    /// one row an environment), scoring each first state into `out`.
    pub fn reset(
        &mut self,
        obs: &[f64],
        width: usize,
        out: &mut Vec<StepScore>,
    ) -> Result<(), RowError> {
        let starts = vec![true; self.len()];
        self.step(obs, width, &vec![false; self.len()], &starts, out)
    }

    /// One vector step: row `i` of `obs` is environment `i`'s new observation. `ends[i]`:
    /// its episode ended at this step (terminated or truncated), so the row is its last
    /// state. `starts[i]`: the row is the first state of a new episode (the environment
    /// reset itself after its episode ended, as gymnasium's next-step autoreset does): its
    /// monitor starts anew, and the row's reward is 0 (no step of the task led there).
    pub fn step(
        &mut self,
        obs: &[f64],
        width: usize,
        ends: &[bool],
        starts: &[bool],
        out: &mut Vec<StepScore>,
    ) -> Result<(), RowError> {
        out.clear();
        let n = self.len();
        // The shells check the shapes first; a call that breaks them is refused whole.
        let rows_fit = width >= self.width() && obs.len() == n.saturating_mul(width);
        if !rows_fit || ends.len() != n || starts.len() != n {
            let vars = self.monitors.first().map(|m| m.state_vars().to_vec()).unwrap_or_default();
            return Err(RowError { env: 0, error: TraceError::Width { vars, found: width } });
        }
        for (i, m) in self.monitors.iter_mut().enumerate() {
            let row = &obs[i * width..(i + 1) * width];
            self.state.clear();
            self.state.extend(self.picks.iter().map(|&p| row[p]));
            let fail = |error| RowError { env: i, error };
            let score = if starts[i] {
                m.reset();
                let first = m.push(&self.state).map_err(fail)?;
                StepScore { reward: 0.0, ..first }
            } else if ends[i] {
                m.push_last(&self.state).map_err(fail)?
            } else {
                m.push(&self.state).map_err(fail)?
            };
            out.push(score);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn monitor(src: &str) -> EpisodeMonitor {
        let loaded = crate::load::load(src, None).expect("checks");
        EpisodeMonitor::new(&loaded.spec, src, None).expect("a monitor")
    }

    #[test]
    fn each_row_scores_as_its_own_episode_monitor_does() {
        let src = "spec S { state { x: float, y: float } let A = x > 1; let B = y > 1; \
                   task always[0..] (eventually[0..3] A && eventually[0..3] B); }";
        let one = monitor(src);
        // Two environments; observations (y, pad, x): the picks read x from column 2.
        let mut batch = EpisodeBatch::new(&one, 2, vec![2, 0]);
        let rows: [[f64; 6]; 5] = [
            [0.0, 9.0, 0.0, 2.0, 9.0, 0.0],
            [2.0, 9.0, 0.0, 0.0, 9.0, 2.0],
            [0.0, 9.0, 2.0, 0.0, 9.0, 0.0],
            [0.0, 9.0, 0.0, 0.0, 9.0, 0.0],
            [2.0, 9.0, 2.0, 0.0, 9.0, 0.0],
        ];
        let mut singles = [one.clone(), one.clone()];
        let mut out = Vec::new();
        batch.reset(&rows[0], 3, &mut out).expect("scores");
        for (i, single) in singles.iter_mut().enumerate() {
            let row = &rows[0][i * 3..i * 3 + 3];
            let first = single.push(&[row[2], row[0]]).expect("scores");
            assert_eq!(out[i], StepScore { reward: 0.0, ..first });
        }
        // Environment 1's episode ends at step 2 and restarts at step 3.
        let ends = [[false, false], [false, true], [false, false], [false, false]];
        let starts = [[false, false], [false, false], [false, true], [false, false]];
        for t in 1..5 {
            batch.step(&rows[t], 3, &ends[t - 1], &starts[t - 1], &mut out).expect("scores");
            for (i, single) in singles.iter_mut().enumerate() {
                let row = &rows[t][i * 3..i * 3 + 3];
                let state = [row[2], row[0]];
                let want = if starts[t - 1][i] {
                    single.reset();
                    StepScore { reward: 0.0, ..single.push(&state).expect("scores") }
                } else if ends[t - 1][i] {
                    single.push_last(&state).expect("scores")
                } else {
                    single.push(&state).expect("scores")
                };
                assert_eq!(out[i], want, "step {t}, environment {i}");
            }
        }
    }

    #[test]
    fn a_nan_in_a_row_names_its_environment() {
        let one = monitor("spec S { state { x: float } task x > 0; }");
        let mut batch = EpisodeBatch::new(&one, 3, vec![0]);
        let mut out = Vec::new();
        let e = batch.reset(&[1.0, 2.0, f64::NAN], 1, &mut out).expect_err("NaN");
        assert_eq!(e.env, 2);
        assert!(matches!(e.error, TraceError::NotANumber { .. }), "{:?}", e.error);
    }
}
