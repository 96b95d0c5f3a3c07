//! The monitor memory of persistent tasks (LANGUAGE.md, "Persistent tasks beyond the paper").
//!
//! For a task `always[0..] (eventually[0..N1] R1 && ... && eventually[0..Nk] Rk)` the
//! memory keeps, for each conjunct `j`, the counter `tau_j`: the steps since `R_j` last held.
//! It is 0 while `R_j` holds, grows by one per primitive step elsewhere and stops at `N_j`
//! (expired). An episode starts with `tau_j = N_j`, or 0 when the start state satisfies
//! `R_j`. The step signal `psi` is 1 when every `tau_j < N_j`: the `N_j`-step windows
//! ending at that step all visited their region.
//!
//! With `memory: B` the options policy observes the state together with one bucket per
//! conjunct: `b_j = floor(tau_j * B / N_j)` while `tau_j < N_j`, and a bucket of its own,
//! `b_j = B`, once `tau_j = N_j`. An observation is `state * values() + code`, the code
//! being the buckets read as the digits of a number in base `B + 1`, `b_1` first.

use crate::{Env, Error, TaskSpec};

/// At most this many memory values `(B + 1)^k`.
const MAX_VALUES: usize = 1 << 24;

/// The counters' dynamics and the buckets of a persistent task.
#[derive(Clone, Debug, PartialEq)]
pub struct Memory {
    /// The region names, in conjunct order.
    pub regions: Vec<String>,
    /// `N_j` of each region.
    pub horizons: Vec<usize>,
    /// `B`, the buckets of an unexpired counter; 0 when the options policy sees no memory
    /// (the counters still drive `reward: window`).
    pub buckets: usize,
    /// `holds[j][s]`: region `j` holds in state `s`.
    pub holds: Vec<Vec<bool>>,
}

/// The longest window a memory counts over: the learner keeps a table entry per step of
/// each window. The front end holds specs to the same limit (`hstl_lang::budget`).
pub const MAX_WINDOW: usize = 1_000_000;

impl Memory {
    /// A memory over `holds[j][s]` with horizons `N_j` and `B` buckets. Fails when the
    /// lists disagree in length, a horizon is 0, or there would be too many memory values.
    pub fn new(
        regions: Vec<String>,
        horizons: Vec<usize>,
        buckets: usize,
        holds: Vec<Vec<bool>>,
    ) -> Result<Memory, Error> {
        let err = |m: String| Err(Error::Config(m));
        if regions.is_empty() {
            return err("the memory needs at least one region".into());
        }
        if horizons.len() != regions.len() || holds.len() != regions.len() {
            return err(format!(
                "the memory has {} regions, {} horizons and {} membership tables; give one \
                 of each per region",
                regions.len(),
                horizons.len(),
                holds.len()
            ));
        }
        if let Some(j) = horizons.iter().position(|&n| n == 0) {
            return err(format!("region {} has a zero-step window", regions[j]));
        }
        if let Some(j) = horizons.iter().position(|&n| n > MAX_WINDOW) {
            return err(format!(
                "region {} has a {}-step window; memory counts windows of at most {MAX_WINDOW} steps",
                regions[j], horizons[j]
            ));
        }
        if holds.iter().any(|h| h.len() != holds[0].len()) {
            return err("the region membership tables cover different numbers of states".into());
        }
        let values = u32::try_from(regions.len())
            .ok()
            .and_then(|k| buckets.checked_add(1)?.checked_pow(k))
            .filter(|&v| v <= MAX_VALUES);
        if values.is_none() {
            return err(format!(
                "memory: {buckets} over {} regions gives more than {MAX_VALUES} memory values; \
                 use fewer buckets",
                regions.len()
            ));
        }
        Ok(Memory { regions, horizons, buckets, holds })
    }

    /// The memory a spec asks for on `env`: `Some` when it sets `memory: B > 0` or
    /// `reward: window`, `None` otherwise. Fails when the spec has no regions or does not
    /// fit `env`.
    pub fn of_spec<E: Env>(spec: &TaskSpec, env: &E) -> Result<Option<Memory>, Error> {
        let l = &spec.learn;
        if l.memory == 0 && l.reward == crate::RewardKind::Segment {
            return Ok(None);
        }
        let table = crate::eval::RegionTable::new(spec, env)?;
        let names = spec.regions.iter().map(|r| r.name.clone()).collect();
        Memory::new(names, table.horizons, l.memory, table.holds).map(Some)
    }

    /// The number of regions `k`.
    pub fn len(&self) -> usize {
        self.horizons.len()
    }

    /// Whether the memory has no region (never true for a memory built by [`Memory::new`]).
    pub fn is_empty(&self) -> bool {
        self.horizons.is_empty()
    }

    /// The number of states the membership tables cover.
    pub fn states(&self) -> usize {
        self.holds.first().map_or(0, Vec::len)
    }

    /// Whether region `j` holds in state `s` (no region holds past the table).
    #[inline]
    pub fn holds(&self, j: usize, s: usize) -> bool {
        self.holds[j].get(s).copied().unwrap_or(false)
    }

    /// The counters at an episode's start in state `s`, written into `tau`.
    pub fn start(&self, s: usize, tau: &mut Vec<usize>) {
        tau.clear();
        tau.extend((0..self.len()).map(|j| if self.holds(j, s) { 0 } else { self.horizons[j] }));
    }

    /// The counters after a primitive step into `next`.
    #[inline]
    pub fn step(&self, next: usize, tau: &mut [usize]) {
        for (j, t) in tau.iter_mut().enumerate() {
            *t = if self.holds(j, next) { 0 } else { (*t + 1).min(self.horizons[j]) };
        }
    }

    /// `psi`: whether every counter is below its horizon.
    #[inline]
    pub fn kept(&self, tau: &[usize]) -> bool {
        tau.iter().zip(&self.horizons).all(|(t, n)| t < n)
    }

    /// The bucket of counter value `tau` of region `j`: `floor(tau * B / N_j)` below
    /// `N_j`, `B` once expired.
    #[inline]
    pub fn bucket(&self, j: usize, tau: usize) -> usize {
        let n = self.horizons[j];
        if tau >= n { self.buckets } else { tau * self.buckets / n }
    }

    /// The buckets of the counters `tau`.
    pub fn buckets_of(&self, tau: &[usize]) -> Vec<usize> {
        tau.iter().enumerate().map(|(j, &t)| self.bucket(j, t)).collect()
    }

    /// The number of memory values the options policy tells apart: `(B + 1)^k`, or 1 when
    /// `B = 0`.
    pub fn values(&self) -> usize {
        if self.buckets == 0 { 1 } else { (self.buckets + 1).pow(self.len() as u32) }
    }

    /// The code of the counters `tau` (0 when `B = 0`).
    #[inline]
    pub fn code(&self, tau: &[usize]) -> usize {
        if self.buckets == 0 {
            return 0;
        }
        tau.iter().enumerate().fold(0, |c, (j, &t)| c * (self.buckets + 1) + self.bucket(j, t))
    }

    /// The code of the buckets `b`, or `None` when `b` has the wrong length or a bucket
    /// above `B`.
    pub fn code_of_buckets(&self, b: &[usize]) -> Option<usize> {
        if self.buckets == 0 || b.len() != self.len() || b.iter().any(|&v| v > self.buckets) {
            return None;
        }
        Some(b.iter().fold(0, |c, &v| c * (self.buckets + 1) + v))
    }

    /// The buckets of a code.
    pub fn decode(&self, mut code: usize) -> Vec<usize> {
        let mut b = vec![0; self.len()];
        if self.buckets == 0 {
            return b;
        }
        for v in b.iter_mut().rev() {
            *v = code % (self.buckets + 1);
            code /= self.buckets + 1;
        }
        b
    }

    /// Whether memory code `code` can be observed in state `s`: inside region `j`,
    /// `tau_j = 0`, so `b_j = 0`.
    pub fn consistent(&self, s: usize, mut code: usize) -> bool {
        if self.buckets == 0 {
            return true;
        }
        for j in (0..self.len()).rev() {
            if !code.is_multiple_of(self.buckets + 1) && self.holds(j, s) {
                return false;
            }
            code /= self.buckets + 1;
        }
        true
    }

    /// The observation of state `s` with counters `tau`: `s * values() + code(tau)`.
    #[inline]
    pub fn observation(&self, s: usize, tau: &[usize]) -> usize {
        s * self.values() + self.code(tau)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One row of 6 cells; R1 holds at x = 0, R2 at x = 4 and 5.
    fn line(buckets: usize, horizons: Vec<usize>) -> Memory {
        let holds = vec![(0..6).map(|x| x == 0).collect(), (0..6).map(|x| x >= 4).collect()];
        Memory::new(vec!["R1".into(), "R2".into()], horizons, buckets, holds).unwrap()
    }

    #[test]
    fn counters_and_buckets_follow_a_hand_written_trajectory() {
        // N = (4, 6), B = 2: b_1 = floor(tau_1 * 2 / 4) below 4, b_2 = floor(tau_2 * 2 / 6)
        // below 6; an expired counter has bucket 2, of its own.
        let m = line(2, vec![4, 6]);
        let mut tau = Vec::new();
        // The episode starts inside R2 (x = 4): tau_2 = 0, R1 has not held: tau_1 = N_1.
        m.start(4, &mut tau);
        assert_eq!(tau, [4, 0]);
        assert_eq!(m.buckets_of(&tau), [2, 0]);
        assert!(!m.kept(&tau));
        let path = [3, 2, 1, 0, 1, 2, 3, 3, 3, 2, 1];
        // (tau_1, tau_2) after each step, by hand.
        let want_tau = [
            [4, 1],
            [4, 2],
            [4, 3],
            [0, 4],
            [1, 5],
            [2, 6],
            [3, 6],
            [4, 6],
            [4, 6],
            [4, 6],
            [4, 6],
        ];
        let want_b = [
            [2, 0],
            [2, 0],
            [2, 1],
            [0, 1],
            [0, 1],
            [1, 2],
            [1, 2],
            [2, 2],
            [2, 2],
            [2, 2],
            [2, 2],
        ];
        let want_psi = [false, false, false, true, true, false, false, false, false, false, false];
        for (i, &x) in path.iter().enumerate() {
            m.step(x, &mut tau);
            assert_eq!(tau, want_tau[i], "step {i}");
            assert_eq!(m.buckets_of(&tau), want_b[i], "step {i}");
            assert_eq!(m.kept(&tau), want_psi[i], "step {i}");
            let code = m.code(&tau);
            assert_eq!(m.decode(code), want_b[i]);
            assert_eq!(m.code_of_buckets(&want_b[i]), Some(code));
            assert!(m.consistent(x, code));
            assert_eq!(m.observation(x, &tau), x * 9 + code);
        }
        // An episode starting outside every region: both counters start expired.
        m.start(2, &mut tau);
        assert_eq!((tau.clone(), m.buckets_of(&tau)), (vec![4, 6], vec![2, 2]));
        // The expired bucket is not the last bucket of a live counter: tau = N - 1 is in
        // bucket B - 1.
        assert_eq!((m.bucket(0, 3), m.bucket(0, 4)), (1, 2));
        assert_eq!((m.bucket(1, 5), m.bucket(1, 6)), (1, 2));
    }

    #[test]
    fn codes_and_consistency() {
        let m = line(3, vec![8, 8]);
        assert_eq!(m.values(), 16);
        for code in 0..16 {
            assert_eq!(m.code_of_buckets(&m.decode(code)), Some(code));
        }
        assert_eq!(m.code_of_buckets(&[1, 2]), Some(6));
        assert_eq!(m.code_of_buckets(&[4, 0]), None);
        assert_eq!(m.code_of_buckets(&[1]), None);
        // At x = 0 (R1 holds) b_1 must be 0; at x = 2 anything goes.
        assert!(m.consistent(0, 3) && !m.consistent(0, 4));
        assert!((0..16).all(|c| m.consistent(2, c)));
        // B = 0: the counters run, the options policy sees nothing.
        let off = line(0, vec![4, 6]);
        assert_eq!((off.values(), off.code(&[1, 2])), (1, 0));
    }

    #[test]
    fn bad_memories_are_errors() {
        let holds = vec![vec![true, false]];
        let cases = [
            (vec![], vec![], 2, vec![], "at least one region"),
            (vec!["R".to_string()], vec![0], 2, holds.clone(), "zero-step window"),
            (vec!["R".to_string()], vec![3, 4], 2, holds.clone(), "one of each per region"),
            (vec!["R".to_string()], vec![3], 1 << 25, holds.clone(), "use fewer buckets"),
        ];
        for (names, horizons, b, h, want) in cases {
            let err = Memory::new(names, horizons, b, h).unwrap_err().to_string();
            assert!(err.contains(want), "{want}: {err}");
        }
    }
}
