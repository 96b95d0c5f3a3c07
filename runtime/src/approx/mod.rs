//! The hierarchical learner without tables: Algorithm 1 of Li & Belta (2016) with linear
//! function approximation over tile-coded features (Sutton & Barto, ch. 9-10), for worlds
//! whose state is continuous ([`crate::PlaneWorld`], [`crate::MountainCar`], a user's
//! [`crate::World`]).
//!
//! - [`tiles`]: the tile coder (offset tilings of the state's box; hashed past three
//!   dimensions).
//! - [`learn`]: the learner: one action-value function per primitive option (reward
//!   `rho(reach, s')`, as the tabular learner's) and one for the options level over a
//!   coarser tiling and the task memory's buckets; intra-option updates of every suffix,
//!   epsilon-greedy at both levels, `reward: window`, `avoid:`.
//! - task progress ([`crate::progress`]): which goals of a task that is not persistent a
//!   run has met, seen by the options level beside the state.
//! - [`agent`]: the greedy policy, greedy runs as data, the window and satisfaction rates.
//!
//! Nothing here names a state index, a table or a grid: a state is the world's own value,
//! read through [`crate::World::valuation`]. The same seed gives the same weights, bit for
//! bit: every draw comes from the one generator passed in, in a fixed order.

pub mod agent;
pub mod learn;
mod model;
pub mod tiles;

pub use agent::{ApproxAgent, GreedyRun, Stepper, WindowSummary, task_robustness};
pub use learn::ApproxLearner;
pub use model::{Model, Shape, Weights};
pub use tiles::TileCoder;
