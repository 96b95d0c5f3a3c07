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
    /// `slip[i]`: the least draw `u >= p` that slips to the `i + 2`-th other action or
    /// later (see [`GridWorld::step`]); infinite when there is none below 1.
    slip: [f64; 2],
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
        Ok(GridWorld { width, height, p, slip: slip_thresholds(p) })
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
    #[inline]
    pub fn intended(&self, cell: Cell, action: usize) -> Cell {
        // Only one coordinate changes, so clamping it to the grid is staying in place;
        // written without branches because slips make the action unpredictable.
        // Coordinates fit in `i64`: the grid has at most `u32::MAX` cells.
        const DX: [i64; 4] = [0, 0, -1, 1];
        const DY: [i64; 4] = [1, -1, 0, 0];
        let Some((&dx, &dy)) = DX.get(action).zip(DY.get(action)) else { return cell };
        let x = (cell.x as i64 + dx).clamp(0, self.width as i64 - 1);
        let y = (cell.y as i64 + dy).clamp(0, self.height as i64 - 1);
        Cell { x: x as usize, y: y as usize }
    }
}

/// Which of the three other actions a draw `u >= p` slips to, as the contract computes it.
fn slip_index(p: f64, u: f64) -> usize {
    (((u - p) / (1.0 - p) * 3.0) as usize).min(2)
}

/// `[t1, t2]`: the least draws in `[p, 1)` with `slip_index` at least 1 and 2, or infinity.
/// `slip_index` does not decrease in `u` (each rounded operation is monotone), so for every
/// `u` in `[p, 1)` it equals the number of thresholds at or below `u`.
fn slip_thresholds(p: f64) -> [f64; 2] {
    // Non-negative doubles are ordered as their bits.
    let lo = if p > 0.0 { p.to_bits() } else { 0 };
    let hi = 1.0f64.to_bits();
    [1, 2].map(|k| {
        // The least bits in `lo..hi` whose value reaches `k`, or `hi` when none does.
        let (mut a, mut b) = (lo, hi);
        while a < b {
            let mid = a + (b - a) / 2;
            if slip_index(p, f64::from_bits(mid)) >= k { b = mid } else { a = mid + 1 }
        }
        if a < hi { f64::from_bits(a) } else { f64::INFINITY }
    })
}

impl Default for GridWorld {
    /// The paper's 15 x 15 grid with p = 0.7.
    fn default() -> GridWorld {
        GridWorld { width: 15, height: 15, p: 0.7, slip: slip_thresholds(0.7) }
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

    #[inline]
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

    #[inline]
    fn step(&self, state: &Cell, action: usize, rng: &mut Rng) -> Cell {
        if action >= GRID_ACTIONS.len() {
            return *state;
        }
        // One uniform draw decides both whether the robot slips and where: below `p` it
        // takes the chosen action, the rest of [0, 1) splits evenly over the other three:
        // the `k`-th other action with `k = min(2, floor((u - p) / (1 - p) * 3))`, which
        // the two thresholds give without the division (see `slip_index`). Computed
        // without branches: the slip is a coin flip the CPU cannot predict.
        let u = rng.random::<f64>();
        let k = usize::from(u >= self.slip[0]) + usize::from(u >= self.slip[1]);
        let other = k + usize::from(k >= action);
        let taken = if u < self.p { action } else { other };
        self.intended(*state, taken)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::seeded_rng;

    /// The thresholds give the contract's slip index for every draw at or above `p`: at
    /// each threshold, one ulp either side, and on many random draws.
    #[test]
    fn slip_thresholds_give_the_contracts_slip_index() {
        let mut rng = seeded_rng(7);
        for p in [0.0, 1e-9, 0.3, 1.0 / 3.0, 0.5, 0.7, 0.9, 0.999_999, 1.0] {
            let grid = GridWorld::new(3, 3, p).unwrap();
            let by_thresholds =
                |u: f64| usize::from(u >= grid.slip[0]) + usize::from(u >= grid.slip[1]);
            let mut draws: Vec<f64> = (0..100_000).map(|_| rng.random::<f64>()).collect();
            for t in grid.slip.into_iter().filter(|t| t.is_finite()) {
                draws.extend([t, f64::from_bits(t.to_bits() - 1), f64::from_bits(t.to_bits() + 1)]);
            }
            draws.extend([p, 1.0 - f64::EPSILON / 2.0]);
            for u in draws.into_iter().filter(|&u| u >= p && u < 1.0) {
                assert_eq!(by_thresholds(u), slip_index(p, u), "p = {p}, u = {u:e}");
            }
        }
        // At p = 0.7 each other action takes a tenth of [0, 1).
        let [t1, t2] = GridWorld::default().slip;
        assert!((t1 - 0.8).abs() < 1e-12 && (t2 - 0.9).abs() < 1e-12, "{t1} {t2}");
    }
}
