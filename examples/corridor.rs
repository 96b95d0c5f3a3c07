//! A user's own environment through the facade alone: a 1-D corridor, not a grid.
//!
//! `hstl` re-exports everything an [`Env`] needs (the generator [`Rng`] and its draws
//! [`RngExt`], the JSON [`Value`] of the parameters and [`json!`]), so this file's crate
//! depends on `hstl` and nothing else.
//!
//! `cargo run --release --example corridor`

use hstl::runtime::{Env, Learner, Rng, RngExt, Value, json, seeded_rng};

/// A corridor of `len` cells, `x = 0` at the left; `Left` and `Right` move one cell, and with
/// probability `slip` the robot stays where it is instead.
#[derive(Clone, Debug)]
pub struct Corridor {
    /// Number of cells.
    pub len: usize,
    /// The probability that a move does not happen.
    pub slip: f64,
}

impl Env for Corridor {
    type State = usize;

    fn name(&self) -> &str {
        "corridor"
    }

    fn params(&self) -> Value {
        json!({ "len": self.len, "slip": self.slip })
    }

    fn state_vars(&self) -> Vec<String> {
        vec!["x".into()]
    }

    fn actions(&self) -> Vec<String> {
        vec!["Left".into(), "Right".into()]
    }

    fn num_states(&self) -> usize {
        self.len
    }

    fn index(&self, state: &usize) -> usize {
        *state
    }

    fn state(&self, index: usize) -> Option<usize> {
        (index < self.len).then_some(index)
    }

    fn valuation(&self, state: &usize, out: &mut Vec<f64>) {
        out.clear();
        out.push(*state as f64);
    }

    fn reset(&self, rng: &mut Rng) -> usize {
        rng.random_range(0..self.len)
    }

    fn step(&self, state: &usize, action: usize, rng: &mut Rng) -> usize {
        if rng.random::<f64>() < self.slip {
            return *state;
        }
        match action {
            0 => state.saturating_sub(1),
            1 => (state + 1).min(self.len - 1),
            _ => *state,
        }
    }
}

/// The task: reach the right end of a 10-cell corridor within 30 steps.
pub const SPEC: &str = "spec ReachEnd {
    state { x: int in 0..=9 }
    let End = x > 8;
    task eventually[0..30] End;
    option End;
    learn { episodes: 200, choices: 20 }
}";

#[allow(dead_code)]
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let checked = hstl::lang::check(SPEC);
    let spec = hstl::lower::task_spec(&checked.specs[0], SPEC)?;
    let env = Corridor { len: 10, slip: 0.2 };
    let mut learner = Learner::new(&spec, &env)?;
    let trained = learner.train(&mut seeded_rng(1), |_, _| {});
    let agent = learner.agent();
    let moves: String = agent.flat[0].iter().map(|&a| if a == 1 { '>' } else { '<' }).collect();
    println!(
        "trained {} episodes ({} steps); greedy moves by cell: {moves}",
        trained.curve.len(),
        trained.steps
    );
    Ok(())
}
