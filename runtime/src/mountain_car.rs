//! Gymnasium's MountainCar-v0 as a [`World`]: a car in a valley, too weak to drive up the
//! right hill without swinging back and forth first.
//!
//! The dynamics are gymnasium's (`MountainCarEnv.step`), with its constants and its order
//! of operations, in double precision as gymnasium computes its state:
//!
//! ```text
//! v <- v + ((action - 1) * 0.001 + cos(3 x) * (-0.0025)), clipped to [-0.07, 0.07]
//! x <- x + v, clipped to [-1.2, 0.6]
//! if x == -1.2 and v < 0: v <- 0        (the left wall stops the car)
//! ```
//!
//! `cos` is the platform's, as CPython's `math.cos` is, so the states equal gymnasium's bit
//! for bit on the same machine (`tests/mountain_car.rs` holds them against a recorded
//! run). Unlike gymnasium, nothing terminates at the goal (`x >= 0.5`): the task says what
//! to reach. A reset draws `x` uniformly in `[-0.6, -0.4]` (one uniform draw, see
//! [`draw::uniform_in`]) and sets `v = 0`.

use serde_json::{Value, json};

use crate::draw;
use crate::env::World;
use crate::{Error, Rng};

/// The state of the [`MountainCar`]: position and velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CarState {
    /// The position, in `[-1.2, 0.6]`.
    pub x: f64,
    /// The velocity, in `[-0.07, 0.07]`.
    pub v: f64,
}

/// Gymnasium's MountainCar-v0 (see the module docs): state variables `x` and `v`, actions
/// `left`, `none` and `right`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MountainCar;

impl MountainCar {
    /// The least position (the left wall).
    pub const MIN_POSITION: f64 = -1.2;
    /// The greatest position.
    pub const MAX_POSITION: f64 = 0.6;
    /// The greatest speed either way.
    pub const MAX_SPEED: f64 = 0.07;
    /// Gymnasium's goal position (where its episodes end; not here).
    pub const GOAL_POSITION: f64 = 0.5;
    /// The engine's push per step.
    pub const FORCE: f64 = 0.001;
    /// The pull of the slope, times `cos(3 x)`.
    pub const GRAVITY: f64 = 0.0025;

    /// The world from the `params` object that [`World::params`] writes.
    pub fn from_params(params: &Value) -> Result<MountainCar, Error> {
        match params.get("kind").and_then(Value::as_str) {
            Some("mountain-car") => Ok(MountainCar),
            _ => Err(Error::Env("the world's `kind` is not \"mountain-car\"".into())),
        }
    }
}

impl World for MountainCar {
    type State = CarState;

    fn name(&self) -> &str {
        "mountain-car"
    }

    /// `{"kind": "mountain-car"}`: the dynamics have no parameters.
    fn params(&self) -> Value {
        json!({ "kind": "mountain-car" })
    }

    fn state_vars(&self) -> Vec<String> {
        vec!["x".into(), "v".into()]
    }

    fn actions(&self) -> Vec<String> {
        vec!["left".into(), "none".into(), "right".into()]
    }

    fn valuation(&self, state: &CarState, out: &mut Vec<f64>) {
        out.clear();
        out.extend([state.x, state.v]);
    }

    fn reset(&self, rng: &mut Rng) -> CarState {
        CarState { x: draw::uniform_in(rng, -0.6, -0.4), v: 0.0 }
    }

    fn step(&self, state: &CarState, action: usize, _rng: &mut Rng) -> CarState {
        if action > 2 {
            return *state;
        }
        let push = (action as f64 - 1.0) * Self::FORCE;
        let v = state.v + (push + (3.0 * state.x).cos() * (-Self::GRAVITY));
        let v = v.clamp(-Self::MAX_SPEED, Self::MAX_SPEED);
        let x = (state.x + v).clamp(Self::MIN_POSITION, Self::MAX_POSITION);
        let v = if x == Self::MIN_POSITION && v < 0.0 { 0.0 } else { v };
        CarState { x, v }
    }
}
