//! Environments after the gymnasium conventions, and the paper's grid world.

use std::fmt;

use rand::RngExt;
use serde_json::{Value, json};

use crate::{Error, Rng};

/// A finite environment for tabular learning. Every random draw comes from the caller's
/// generator.
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
}

/// The grid world of the paper. **Contract:** `x` in `0..=width-1` (left to right), `y` in
/// `0..=height-1` (bottom to top); actions `Up` (y+1), `Down` (y-1), `Left` (x-1),
/// `Right` (x+1); with probability `p` the chosen action is taken, otherwise one of the
/// other three, each equally likely; a move off the grid leaves the robot in place.
#[derive(Clone, Debug, PartialEq)]
pub struct GridWorld {
    width: usize,
    height: usize,
    p: f64,
}

/// A cell of the [`GridWorld`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Cell {
    /// Column, left to right.
    pub x: usize,
    /// Row, bottom to top.
    pub y: usize,
}

/// The actions of the [`GridWorld`], in index order.
pub const GRID_ACTIONS: [&str; 4] = ["Up", "Down", "Left", "Right"];

impl GridWorld {
    /// A `width` x `height` grid whose chosen action is taken with probability `p`.
    pub fn new(width: usize, height: usize, p: f64) -> Result<GridWorld, Error> {
        if width == 0 || height == 0 {
            return Err(Error::Env(format!("a {width} x {height} grid has no cell")));
        }
        if width.checked_mul(height).is_none_or(|n| n > u32::MAX as usize) {
            return Err(Error::Env(format!("a {width} x {height} grid is too large")));
        }
        if !(0.0..=1.0).contains(&p) {
            return Err(Error::Env(format!("p = {p} is not a probability in [0, 1]")));
        }
        Ok(GridWorld { width, height, p })
    }

    /// The grid from the `params` object that [`Env::params`] writes.
    pub fn from_params(params: &Value) -> Result<GridWorld, Error> {
        let field = |name: &str| {
            params.get(name).ok_or_else(|| Error::Env(format!("grid parameter {name} is missing")))
        };
        let size = |name: &str| {
            field(name)?.as_u64().and_then(|v| usize::try_from(v).ok()).ok_or_else(|| {
                Error::Env(format!("grid parameter {name} is not a non-negative integer"))
            })
        };
        let p = field("p")?
            .as_f64()
            .ok_or_else(|| Error::Env("grid parameter p is not a number".into()))?;
        GridWorld::new(size("width")?, size("height")?, p)
    }

    /// The width (number of columns).
    pub fn width(&self) -> usize {
        self.width
    }

    /// The height (number of rows).
    pub fn height(&self) -> usize {
        self.height
    }

    /// The probability that the chosen action is taken.
    pub fn p(&self) -> f64 {
        self.p
    }

    /// Where `action` leads from `cell` without slipping; off the grid stays in place.
    pub fn intended(&self, cell: Cell, action: usize) -> Cell {
        // Only one coordinate changes, so clamping it to the grid is staying in place;
        // written without branches because slips make the action unpredictable.
        const DX: [isize; 4] = [0, 0, -1, 1];
        const DY: [isize; 4] = [1, -1, 0, 0];
        let Some((&dx, &dy)) = DX.get(action).zip(DY.get(action)) else { return cell };
        let x = cell.x.saturating_add_signed(dx).min(self.width - 1);
        let y = cell.y.saturating_add_signed(dy).min(self.height - 1);
        Cell { x, y }
    }
}

impl Default for GridWorld {
    /// The paper's 15 x 15 grid with p = 0.7.
    fn default() -> GridWorld {
        GridWorld { width: 15, height: 15, p: 0.7 }
    }
}

impl Env for GridWorld {
    type State = Cell;

    fn name(&self) -> &str {
        "gridworld"
    }

    fn params(&self) -> Value {
        json!({ "width": self.width, "height": self.height, "p": self.p })
    }

    fn state_vars(&self) -> Vec<String> {
        vec!["x".into(), "y".into()]
    }

    fn actions(&self) -> Vec<String> {
        GRID_ACTIONS.iter().map(|a| a.to_string()).collect()
    }

    fn num_states(&self) -> usize {
        self.width * self.height
    }

    fn index(&self, state: &Cell) -> usize {
        state.y * self.width + state.x
    }

    fn state(&self, index: usize) -> Option<Cell> {
        (index < self.num_states()).then(|| Cell { x: index % self.width, y: index / self.width })
    }

    fn valuation(&self, state: &Cell, out: &mut Vec<f64>) {
        out.clear();
        out.extend([state.x as f64, state.y as f64]);
    }

    fn reset(&self, rng: &mut Rng) -> Cell {
        Cell { x: rng.random_range(0..self.width), y: rng.random_range(0..self.height) }
    }

    fn step(&self, state: &Cell, action: usize, rng: &mut Rng) -> Cell {
        if action >= GRID_ACTIONS.len() {
            return *state;
        }
        // One uniform draw decides both whether the robot slips and where: below `p` it
        // takes the chosen action, the rest of [0, 1) splits evenly over the other three.
        // Computed without branches: the slip is a coin flip the CPU cannot predict.
        let u = rng.random::<f64>();
        let k = (((u - self.p) / (1.0 - self.p) * 3.0) as usize).min(2);
        let other = k + usize::from(k >= action);
        let taken = if u < self.p { action } else { other };
        self.intended(*state, taken)
    }
}
