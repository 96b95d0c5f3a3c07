//! Environments after the gymnasium conventions: [`World`], what every environment has,
//! and [`Env`], a finite world whose states are numbered for tabular learning.
//!
//! A finite environment implements [`Env`] alone and is a [`World`] through the blanket
//! implementation below; a continuous one ([`PlaneWorld`](crate::PlaneWorld),
//! [`MountainCar`](crate::MountainCar)) implements [`World`]. Code that only resets, steps
//! and reads valuations (rollouts, monitors) can take any `W: World`; the Q-tables need
//! `E: Env`.
//!
//! The grid worlds live in [`crate::grid`]; their paths here are kept for existing users.

use std::fmt;

use serde_json::Value;

use crate::Rng;
pub use crate::grid::{Cell, GRID_ACTIONS, GridWorld, MAX_GRID_CELLS, Tile};

/// An environment: states, a finite set of actions, and seeded dynamics. Every random draw
/// comes from the caller's generator, so the same seed gives the same run.
///
/// Implement this for an environment whose states cannot be numbered (continuous ones);
/// implement [`Env`] instead for a finite one, which makes it a `World` too.
pub trait World {
    /// A state of the environment.
    type State: Clone + fmt::Debug + PartialEq;

    /// The environment's name, as `policy.json` records it.
    fn name(&self) -> &str;
    /// The environment's parameters, as `policy.json` records them (a JSON object).
    fn params(&self) -> Value;
    /// The names of the state variables, in the order of [`World::valuation`].
    fn state_vars(&self) -> Vec<String>;
    /// The names of the actions; an action is an index into this list.
    fn actions(&self) -> Vec<String>;
    /// The values of the state variables at `state`, written into `out`.
    fn valuation(&self, state: &Self::State, out: &mut Vec<f64>);
    /// A start state.
    fn reset(&self, rng: &mut Rng) -> Self::State;
    /// The state after taking `action` in `state`. An action outside the set leaves the
    /// state unchanged.
    fn step(&self, state: &Self::State, action: usize, rng: &mut Rng) -> Self::State;
    /// Whether `action`'s nominal move from `state` is blocked (a wall or the edge in its
    /// way), so that but for noise it leaves the state where it is. The approximate
    /// learner and its greedy agent never choose a blocked action: a function approximator
    /// may rank one first at a wall, and a greedy run would then stand still forever. The
    /// default: no action is ever blocked.
    fn blocked(&self, _state: &Self::State, _action: usize) -> bool {
        false
    }
}

/// A finite environment for tabular learning: a [`World`] whose states are numbered
/// `0..num_states()`. Every random draw comes from the caller's generator.
///
/// It declares the [`World`] methods itself, and every `Env` is a `World` through a
/// blanket implementation, so that an environment written before the split (one `impl
/// Env` block) still compiles unchanged; a type implements one of the two, never both.
/// With both traits imported, call a shared method on a concrete type as `Env::step(..)`
/// or `World::step(..)`: the method name alone is ambiguous there.
pub trait Env {
    /// A state of the environment.
    type State: Clone + fmt::Debug + PartialEq;

    /// The environment's name, as `policy.json` records it.
    fn name(&self) -> &str;
    /// The environment's parameters, as `policy.json` records them (a JSON object).
    fn params(&self) -> Value;
    /// The names of the state variables, in the order of [`Env::valuation`].
    fn state_vars(&self) -> Vec<String>;
    /// The names of the actions; an action is an index into this list.
    fn actions(&self) -> Vec<String>;
    /// The number of states; indices run over `0..num_states()`.
    fn num_states(&self) -> usize;
    /// The index of a state.
    fn index(&self, state: &Self::State) -> usize;
    /// The state with this index, or `None` past the end.
    fn state(&self, index: usize) -> Option<Self::State>;
    /// The values of the state variables at `state`, written into `out`.
    fn valuation(&self, state: &Self::State, out: &mut Vec<f64>);
    /// A start state.
    fn reset(&self, rng: &mut Rng) -> Self::State;
    /// The state after taking `action` in `state`. An action outside the set leaves the
    /// state unchanged.
    fn step(&self, state: &Self::State, action: usize, rng: &mut Rng) -> Self::State;
    /// Whether the last [`Env::step`] ended the environment's own episode, and how (a
    /// gymnasium environment's `terminated` or `truncated`): the learner then ends its
    /// episode there, and starts the next with [`Env::reset`], so every step it counts is
    /// one the environment took. A world whose episodes never end (every built-in one)
    /// keeps the default, `None`.
    fn episode_end(&self) -> Option<EpisodeEnd> {
        None
    }
}

/// How an environment's episode ended ([`Env::episode_end`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EpisodeEnd {
    /// In a terminal state (gymnasium's `terminated`): the robot would stay there, so the
    /// learner values the state as one it never leaves.
    Terminated,
    /// Cut off (gymnasium's `truncated`, a time limit): the state is valued as usual.
    Truncated,
}

impl<E: Env> World for E {
    type State = E::State;

    fn name(&self) -> &str {
        Env::name(self)
    }

    fn params(&self) -> Value {
        Env::params(self)
    }

    fn state_vars(&self) -> Vec<String> {
        Env::state_vars(self)
    }

    fn actions(&self) -> Vec<String> {
        Env::actions(self)
    }

    fn valuation(&self, state: &E::State, out: &mut Vec<f64>) {
        Env::valuation(self, state, out)
    }

    fn reset(&self, rng: &mut Rng) -> E::State {
        Env::reset(self, rng)
    }

    #[inline]
    fn step(&self, state: &E::State, action: usize, rng: &mut Rng) -> E::State {
        Env::step(self, state, action, rng)
    }
}
