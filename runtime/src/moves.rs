//! A grid world's moves as plain data: the world model the exact solvers read
//! ([`optimum`](crate::optimum), [`reach_avoid`](crate::reach_avoid)).
//!
//! Four actions (Up, Down, Left, Right), each taking the intended one with probability `p`
//! and each other with `(1 - p) / 3`, built from a [`GridWorld`] or given as data.

use crate::{Env, Error, GridWorld};

/// A world's moves as plain data: the solver's view of a grid world.
#[derive(Clone, Debug, PartialEq)]
pub struct Moves {
    /// `dest[s][a]`: the state the intended action `a` (Up, Down, Left, Right) leads to from
    /// state `s` (itself when a wall or the edge blocks it).
    pub dest: Vec<[u32; 4]>,
    /// The probability that the intended action is taken; otherwise one of the other three
    /// is, each with probability `(1 - p) / 3`.
    pub p: f64,
    /// The start states, each equally likely.
    pub starts: Vec<u32>,
}

impl Moves {
    /// The moves of `grid`: from each state, where each action leads without slipping
    /// (walls and edges keep the robot in place), and its start states.
    pub fn of(grid: &GridWorld) -> Moves {
        let dest = (0..grid.num_states())
            .map(|s| std::array::from_fn(|a| grid.dest(s, a) as u32))
            .collect();
        let starts = grid.starts().into_iter().map(|s| s as u32).collect();
        Moves { dest, p: grid.p(), starts }
    }

    /// The number of states.
    pub fn states(&self) -> usize {
        self.dest.len()
    }

    /// Checks the moves: targets in range, `p` a probability, a start set of states.
    pub(crate) fn check(&self) -> Result<(), Error> {
        let n = self.dest.len();
        if n == 0 {
            return Err(Error::Env("the world has no state".into()));
        }
        if n > u32::MAX as usize / 2 {
            return Err(Error::Env(format!("the world has {n} states, too many")));
        }
        if !(0.0..=1.0).contains(&self.p) {
            return Err(Error::Env(format!("p = {} is not a probability in [0, 1]", self.p)));
        }
        if let Some((s, to)) = self
            .dest
            .iter()
            .enumerate()
            .find_map(|(s, d)| d.iter().find(|&&t| t as usize >= n).map(|&t| (s, t)))
        {
            return Err(Error::Env(format!(
                "a move from state {s} leads to state {to}, but the world has {n} states"
            )));
        }
        if self.starts.is_empty() {
            return Err(Error::Env("the world has no start state".into()));
        }
        if let Some(&s) = self.starts.iter().find(|&&s| s as usize >= n) {
            return Err(Error::Env(format!(
                "start state {s} is not a state of the world, which has {n}"
            )));
        }
        Ok(())
    }

    /// The connected components: per state, its component's index, in order of the
    /// component's first state. Fails when a move cannot be undone.
    pub(crate) fn components(&self) -> Result<Vec<u32>, Error> {
        let n = self.dest.len();
        for (s, d) in self.dest.iter().enumerate() {
            for &t in d {
                if t as usize != s && !self.dest[t as usize].contains(&(s as u32)) {
                    return Err(Error::Env(format!(
                        "a move leads from state {s} to state {t} but none leads back; the \
                         optimum needs moves that can be undone, as on a grid"
                    )));
                }
            }
        }
        let mut comp = vec![u32::MAX; n];
        let mut count = 0u32;
        let mut stack = Vec::new();
        for s in 0..n {
            if comp[s] != u32::MAX {
                continue;
            }
            comp[s] = count;
            stack.push(s);
            while let Some(c) = stack.pop() {
                for &t in &self.dest[c] {
                    if comp[t as usize] == u32::MAX {
                        comp[t as usize] = count;
                        stack.push(t as usize);
                    }
                }
            }
            count += 1;
        }
        Ok(comp)
    }
}
