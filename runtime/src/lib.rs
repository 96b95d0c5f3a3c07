//! The hierarchical learner of Li & Belta, "A Hierarchical Reinforcement Learning Method
//! for Persistent Time-Sensitive Tasks" (2016), Algorithm 1, for hstl task specs.
//!
//! - [`spec`]: the plain data a checked spec lowers into ([`TaskSpec`]) and the [`Spec`]
//!   trait generated code implements.
//! - [`env`](mod@env): the [`World`] trait (gymnasium conventions: reset, step, valuation)
//!   and its finite refinement [`Env`] (numbered states, for the Q-tables).
//! - [`grid`]: the [`GridWorld`]: the paper's open grid or a map with walls.
//! - [`plane`]: the [`PlaneWorld`]: a point robot in a bounded plane with obstacles.
//! - [`mountain_car`]: gymnasium's MountainCar-v0 as a [`World`].
//! - [`draw`]: the draws of the continuous worlds, reproducible on every platform.
//! - [`learn`]: Algorithm 1: flat Q-learning per primitive option, options Q-learning with
//!   intra-option updates, seeded and bit-for-bit reproducible.
//! - [`memory`]: the counters and buckets of `memory: B` and the step signal of
//!   `reward: window` (beyond the paper).
//! - [`plan`]: `plan: model`, the options values planned over the memory's
//!   counters and a model of the learned legs (beyond the paper).
//! - [`policy`]: greedy policies and the `policy.json` document.
//! - [`progress`]: the goals of a task that is not persistent, which the options level of
//!   both learners sees beside the state once a run has met them.
//! - [`eval`]: greedy rollouts, sample runs and the window rate.
//! - [`moves`]: a grid world's moves as plain data, the world model of the exact solvers.
//! - [`optimum`]: the exact optimal window rate `W*` of a persistent task on any grid world.
//! - [`reach_avoid`]: the exact optimal probability of a reach-avoid task.
//! - [`world`]: world files (TOML: grid maps with walls and start cells, and plane worlds)
//!   and the built-in worlds.
//!
//! Every random draw comes from one [`Rng`] (ChaCha8) that the caller seeds and passes in.

pub mod approx;
pub mod digest;
pub mod draw;
pub mod env;
mod episode;
mod error;
pub mod eval;
mod geometry;
mod greedy;
pub mod grid;
pub mod learn;
pub mod memory;
pub mod mountain_car;
pub mod moves;
pub mod optimum;
pub mod plan;
mod plan_reach;
pub mod plane;
pub mod policy;
mod policy_parts;
pub mod progress;
pub mod reach_avoid;
pub mod spec;
mod tables;
mod words;
pub mod world;

pub use env::{Cell, Env, EpisodeEnd, GridWorld, Tile, World};
pub use error::Error;
pub use hstl_robustness as robustness;
pub use learn::{Learner, QTables, Trained};
pub use memory::Memory;
pub use mountain_car::{CarState, MountainCar};
pub use plane::{Obstacle, PlaneConfig, PlaneWorld, Point};
pub use policy::{Agent, Policy};
/// What a [`World`] or [`Env`] implementation needs from `rand` and `serde_json`, re-exported so that it
/// needs neither in its own `Cargo.toml`: the draws of the one generator ([`Rng`]) and the
/// parameters' JSON ([`Value`], [`json!`]).
pub use rand::RngExt;
pub use serde_json::{Value, json};
pub use spec::{
    CombinedOption, Intra, LearnParams, LevelParams, Plan, PrimitiveOption, Region, RewardKind,
    Spec, StateVar, Switch, TaskSpec, Terminate, TileParams,
};

/// The one random generator of the crate: every draw comes from a value of this type.
pub type Rng = rand_chacha::ChaCha8Rng;

/// A generator seeded with `seed`; the same seed gives the same draws on every platform.
pub fn seeded_rng(seed: u64) -> Rng {
    rand::SeedableRng::seed_from_u64(seed)
}

/// A generator's whole state as plain data: its key, stream and position (in 32-bit
/// words), from which [`rng_from_state`] makes a generator that draws what it would draw.
pub fn rng_state(rng: &Rng) -> ([u8; 32], u64, u128) {
    (rng.get_seed(), rng.get_stream(), rng.get_word_pos())
}

/// The generator whose state [`rng_state`] gave.
pub fn rng_from_state(key: [u8; 32], stream: u64, word_pos: u128) -> Rng {
    let mut rng: Rng = rand::SeedableRng::from_seed(key);
    rng.set_stream(stream);
    rng.set_word_pos(word_pos);
    rng
}
