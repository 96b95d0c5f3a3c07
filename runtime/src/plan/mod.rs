//! `learn { plan: model }`: the options values of a persistent task planned instead of
//! Q-learned (LANGUAGE.md, "Planning the options level").
//!
//! Q-learning the options level needs a sample of every (state, memory, option) it values;
//! on the case study that is 225 states times 729 memory values, and 1,200 episodes leave
//! most of them rarely seen. But of what an option earns, only the leg's travel is
//! unknown: the counters `tau_j` and the window reward follow from the spec. So the learner
//! records the transitions it sees (a tabular model of the environment), and after
//! training computes from them, under each option's greedy leg, how many steps the leg
//! takes from each state (`f[s][d]`) and which cell of its region it arrives in (`g[s][c]`).
//! Value iteration then runs over the states where a leg arrives, each with the exact
//! counters of the regions it is not in, and the options table is filled for every state
//! and memory code from the counters in the middle of each bucket.
//!
//! [`PlanSize`] is public: the front end holds specs to the same limits.
//!
//! An option `o` that enters region `j` from state `s` with counters `tau` and arrives
//! after `d` steps earns `sum_{m=1..d} gamma^(m-1) psi(m)`: `psi(m) = 1` for `m < d`
//! while every `tau_i + m < N_i`, and at `m = d` while every `tau_i + d < N_i`, `i != j`
//! (`tau_j` is then 0). Its value is the expectation over `d` and the arrival cell `c` of
//! that reward plus `gamma^d V_c(tau')`, with `tau'_i = min(tau_i + d, N_i)`. The model
//! leaves out regions a leg crosses on its way (their counters are not reset) and the
//! steps it lingers in the region it starts from.
//!
//! Three parts: `model` (the transitions counted in training), `size` (the budget a
//! spec is held to before training starts) and `solve` (the quickest legs, value
//! iteration over their durations and arrivals, and the filled options table).

mod model;
mod size;
mod solve;

pub(crate) use model::Model;
pub use size::{MAX_PLAN_VALUES, MAX_PLAN_WORK, PlanSize};
pub(crate) use solve::{Planner, UNTRIED};
