//! Grid worlds: the paper's open grid and the user's own maps (walls and start cells).

use rand::RngExt;
use serde_json::{Value, json};

use crate::{Env, Error, Rng};

/// A grid world: the paper's open grid, or a map with walls and start cells read from a
/// world file (see [`crate::world`]).
///
/// **Contract** (DESIGN.md): `x` in `0..=width-1` (left to right), `y` in `0..=height-1`
/// (bottom to top); actions `Up` (y+1), `Down` (y-1), `Left` (x-1), `Right` (x+1); with
/// probability `p = 1 - slip` the chosen action is taken, otherwise one of the other three,
/// each equally likely; a move into a wall or off the grid leaves the robot in place. Only
/// free cells are states, numbered row by row from the bottom (`y`, then `x`). Episodes
/// start on a start cell, uniformly; a map without `S` cells starts on every free cell.
#[derive(Clone, Debug, PartialEq)]
pub struct GridWorld {
    name: String,
    width: usize,
    height: usize,
    slip: f64,
    p: f64,
    /// `thresholds[i]`: the least draw `u >= p` that slips to the `i + 2`-th other action
    /// or later (see [`GridWorld::step`]); infinite when there is none below 1.
    thresholds: [f64; 2],
    /// No walls: a state's index is `y * width + x` and moves clamp to the grid.
    open: bool,
    /// Per grid cell (`y * width + x`): its state index, or [`NO_STATE`] for a wall.
    state_of: Vec<u32>,
    /// Per state: its cell.
    cells: Vec<Cell>,
    /// Per state and action: the state the action leads to without slipping.
    dest: Vec<[u32; 4]>,
    /// The start states, ascending; empty when every state is a start.
    starts: Vec<u32>,
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

/// The most cells (free or wall) a grid world may have: the learner's tables grow with
/// them, and every per-cell table is allocated only after this check.
pub const MAX_GRID_CELLS: usize = 1 << 20;

/// The state index of a wall in `state_of`.
const NO_STATE: u32 = u32::MAX;

impl GridWorld {
    /// An open `width` x `height` grid (no walls, every cell a start) whose chosen action
    /// is taken with probability `p`, named `gridworld`.
    pub fn new(width: usize, height: usize, p: f64) -> Result<GridWorld, Error> {
        if !(0.0..=1.0).contains(&p) {
            return Err(Error::Env(format!("p = {p} is not a probability in [0, 1]")));
        }
        check_size(width, height)?;
        let free = vec![vec![Tile::Free; width]; height];
        GridWorld::build("gridworld".into(), 1.0 - p, p, &free)
    }

    /// A grid from its rows, top row first (`rows[0]` is `y = height - 1`), with the
    /// probability `slip` that the chosen action is not taken. Fails for an empty or
    /// ragged map, one without a free cell, too many cells, or a slip outside `[0, 1]`.
    pub fn from_rows(name: &str, slip: f64, rows: &[Vec<Tile>]) -> Result<GridWorld, Error> {
        if !(0.0..=1.0).contains(&slip) {
            return Err(Error::Env(format!("slip = {slip} is not a probability in [0, 1]")));
        }
        let width = rows.first().map_or(0, Vec::len);
        check_size(width, rows.len())?;
        if let Some(i) = rows.iter().position(|r| r.len() != width) {
            return Err(Error::Env(format!(
                "map row {} has {} cells, the first has {width}",
                i + 1,
                rows[i].len()
            )));
        }
        GridWorld::build(name.into(), slip, 1.0 - slip, rows)
    }

    /// The grid from the `params` object that [`Env::params`] writes (`slip` and `map`),
    /// or the `width`, `height` and `p` of a `policy.json` written before world files.
    pub fn from_params(name: &str, params: &Value) -> Result<GridWorld, Error> {
        let field = |key: &str| params.get(key);
        if let Some(map) = field("map") {
            let slip = field("slip").and_then(Value::as_f64).ok_or_else(|| {
                Error::Env("the world's `slip` is missing or not a number".into())
            })?;
            let lines = map
                .as_array()
                .ok_or_else(|| Error::Env("the world's `map` is not a list of strings".into()))?;
            if lines.len() > MAX_GRID_CELLS {
                return Err(Error::Env(format!("the world's map has {} rows", lines.len())));
            }
            let mut rows = Vec::with_capacity(lines.len());
            let mut cells = 0usize;
            for (i, line) in lines.iter().enumerate() {
                let text = line.as_str().ok_or_else(|| {
                    Error::Env(format!("row {} of the world's `map` is not a string", i + 1))
                })?;
                cells = cells.saturating_add(text.len());
                if cells > MAX_GRID_CELLS {
                    return Err(Error::Env(format!(
                        "the world's map has more than {MAX_GRID_CELLS} cells"
                    )));
                }
                let row = text
                    .chars()
                    .map(|c| {
                        Tile::from_char(c).ok_or_else(|| {
                            Error::Env(format!(
                                "row {} of the world's `map` holds `{}`, not `.`, `#` or `S`",
                                i + 1,
                                crate::words::visible_char(c)
                            ))
                        })
                    })
                    .collect::<Result<Vec<_>, _>>()?;
                rows.push(row);
            }
            return GridWorld::from_rows(name, slip, &rows);
        }
        let size = |key: &str| {
            field(key).and_then(Value::as_u64).and_then(|v| usize::try_from(v).ok()).ok_or_else(
                || Error::Env(format!("grid parameter {key} is missing or not a count")),
            )
        };
        let p = field("p")
            .and_then(Value::as_f64)
            .ok_or_else(|| Error::Env("grid parameter p is missing or not a number".into()))?;
        let (width, height) = (size("width")?, size("height")?);
        let mut grid = GridWorld::new(width, height, p)?;
        grid.name = name.into();
        Ok(grid)
    }

    fn build(name: String, slip: f64, p: f64, rows: &[Vec<Tile>]) -> Result<GridWorld, Error> {
        let (width, height) = (rows.first().map_or(0, Vec::len), rows.len());
        let tile = |x: usize, y: usize| rows[height - 1 - y][x];
        let mut state_of = vec![NO_STATE; width * height];
        let mut cells = Vec::new();
        let mut starts = Vec::new();
        for y in 0..height {
            for x in 0..width {
                let t = tile(x, y);
                if t == Tile::Wall {
                    continue;
                }
                if t == Tile::Start {
                    starts.push(cells.len() as u32);
                }
                state_of[y * width + x] = cells.len() as u32;
                cells.push(Cell { x, y });
            }
        }
        if cells.is_empty() {
            return Err(Error::Env("the map has no free cell".into()));
        }
        if starts.len() == cells.len() {
            starts.clear();
        }
        let open = cells.len() == width * height;
        let mut grid = GridWorld {
            name,
            width,
            height,
            slip,
            p,
            thresholds: slip_thresholds(p),
            open,
            state_of,
            cells,
            dest: Vec::new(),
            starts,
        };
        grid.dest = grid
            .cells
            .iter()
            .map(|&c| std::array::from_fn(|a| grid.state_of[grid.move_from(c, a)]))
            .collect();
        Ok(grid)
    }

    /// The grid cell (`y * width + x`) that `action` leads to from `cell` on a grid
    /// without walls, or `cell` itself when that one is a wall or off the grid.
    fn move_from(&self, cell: Cell, action: usize) -> usize {
        const DX: [i64; 4] = [0, 0, -1, 1];
        const DY: [i64; 4] = [1, -1, 0, 0];
        let here = cell.y * self.width + cell.x;
        let (x, y) = (cell.x as i64 + DX[action], cell.y as i64 + DY[action]);
        if x < 0 || y < 0 || x >= self.width as i64 || y >= self.height as i64 {
            return here;
        }
        let to = y as usize * self.width + x as usize;
        if self.state_of[to] == NO_STATE { here } else { to }
    }

    /// The world's name (`paper`, `four-rooms`, or the name its file gives).
    pub fn world_name(&self) -> &str {
        &self.name
    }

    /// The width (number of columns).
    pub fn width(&self) -> usize {
        self.width
    }

    /// The height (number of rows).
    pub fn height(&self) -> usize {
        self.height
    }

    /// The probability that the chosen action is taken, `1 - slip`.
    pub fn p(&self) -> f64 {
        self.p
    }

    /// The probability that the chosen action is not taken.
    pub fn slip(&self) -> f64 {
        self.slip
    }

    /// Whether `(x, y)` is a free cell (on the grid and not a wall).
    pub fn is_free(&self, x: usize, y: usize) -> bool {
        x < self.width && y < self.height && self.state_of[y * self.width + x] != NO_STATE
    }

    /// Whether the map has walls.
    pub fn has_walls(&self) -> bool {
        !self.open
    }

    /// The start states (indices), ascending: the `S` cells, or every state.
    pub fn starts(&self) -> Vec<usize> {
        if self.starts.is_empty() {
            (0..self.cells.len()).collect()
        } else {
            self.starts.iter().map(|&s| s as usize).collect()
        }
    }

    /// Whether the map marks start cells (`S`); without them every free cell is a start.
    pub fn has_start_cells(&self) -> bool {
        !self.starts.is_empty()
    }

    /// The state that `action` leads to from state `s` without slipping (`s` itself for
    /// an action or state out of range).
    pub fn dest(&self, s: usize, action: usize) -> usize {
        self.dest.get(s).and_then(|d| d.get(action)).map_or(s, |&t| t as usize)
    }

    /// Where `action` leads from `cell` without slipping; into a wall or off the grid
    /// stays in place.
    #[inline]
    pub fn intended(&self, cell: Cell, action: usize) -> Cell {
        if action >= GRID_ACTIONS.len() {
            return cell;
        }
        if self.open {
            // Only one coordinate changes, so clamping it to the grid is staying in place;
            // written without branches because slips make the action unpredictable.
            // Coordinates fit in `i64`: the grid has at most `MAX_GRID_CELLS` cells.
            const DX: [i64; 4] = [0, 0, -1, 1];
            const DY: [i64; 4] = [1, -1, 0, 0];
            let x = (cell.x as i64 + DX[action]).clamp(0, self.width as i64 - 1);
            let y = (cell.y as i64 + DY[action]).clamp(0, self.height as i64 - 1);
            return Cell { x: x as usize, y: y as usize };
        }
        match self.index_of(cell) {
            Some(s) => self.cells[self.dest[s][action] as usize],
            None => cell,
        }
    }

    /// The map's rows as a world file writes them, top row first: `.` free, `#` wall,
    /// `S` start.
    pub fn map_lines(&self) -> Vec<String> {
        let start: std::collections::HashSet<u32> = self.starts.iter().copied().collect();
        (0..self.height)
            .rev()
            .map(|y| {
                (0..self.width)
                    .map(|x| match self.state_of[y * self.width + x] {
                        NO_STATE => '#',
                        s if start.contains(&s) => 'S',
                        _ => '.',
                    })
                    .collect()
            })
            .collect()
    }

    /// The states reachable from some start (walls can cut a map into parts). Slips only
    /// ever move to a neighbour, and every neighbour can be reached on purpose, so this is
    /// reachability on the map.
    pub fn reachable(&self) -> Vec<bool> {
        let mut seen = vec![false; self.cells.len()];
        let mut queue: std::collections::VecDeque<usize> = self.starts().into();
        for &s in &queue {
            seen[s] = true;
        }
        while let Some(s) = queue.pop_front() {
            for &t in &self.dest[s] {
                if !std::mem::replace(&mut seen[t as usize], true) {
                    queue.push_back(t as usize);
                }
            }
        }
        seen
    }

    /// Shortest path lengths (in moves, without slips) from every state to `target`, or
    /// `u32::MAX` where it cannot be reached.
    pub fn distances_to(&self, target: usize) -> Vec<u32> {
        let mut dist = vec![u32::MAX; self.cells.len()];
        if target >= dist.len() {
            return dist;
        }
        dist[target] = 0;
        let mut queue = std::collections::VecDeque::from([target]);
        // Moves are symmetric (a neighbour's move back returns), so distances from the
        // target are distances to it.
        while let Some(s) = queue.pop_front() {
            for &t in &self.dest[s] {
                let t = t as usize;
                if dist[t] == u32::MAX {
                    dist[t] = dist[s] + 1;
                    queue.push_back(t);
                }
            }
        }
        dist
    }

    fn index_of(&self, cell: Cell) -> Option<usize> {
        if cell.x >= self.width || cell.y >= self.height {
            return None;
        }
        match self.state_of[cell.y * self.width + cell.x] {
            NO_STATE => None,
            s => Some(s as usize),
        }
    }
}

/// One character of a map.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tile {
    /// `.`: a free cell.
    Free,
    /// `#`: a wall.
    Wall,
    /// `S`: a free cell where episodes may start.
    Start,
}

impl Tile {
    /// The tile a map character stands for.
    pub fn from_char(c: char) -> Option<Tile> {
        match c {
            '.' => Some(Tile::Free),
            '#' => Some(Tile::Wall),
            'S' => Some(Tile::Start),
            _ => None,
        }
    }
}

fn check_size(width: usize, height: usize) -> Result<(), Error> {
    if width == 0 || height == 0 {
        return Err(Error::Env(format!("a {width} x {height} grid has no cell")));
    }
    if width.checked_mul(height).is_none_or(|n| n > MAX_GRID_CELLS) {
        return Err(Error::Env(format!(
            "a {width} x {height} grid has more than {MAX_GRID_CELLS} cells"
        )));
    }
    Ok(())
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

/// The slip of a world file that does not set one.
pub const DEFAULT_SLIP: f64 = 0.3;

/// The paper's world: 15 x 15, no walls, slip 0.3.
pub(crate) fn paper() -> GridWorld {
    let rows = vec![vec![Tile::Free; 15]; 15];
    match GridWorld::from_rows("paper", DEFAULT_SLIP, &rows) {
        Ok(world) => world,
        // A fixed, valid map: `from_rows` accepts it.
        Err(_) => unreachable!("the paper's world is a valid map"),
    }
}

impl Default for GridWorld {
    /// The paper's world, built in as `paper`: 15 x 15, no walls, slip 0.3 (p = 0.7).
    fn default() -> GridWorld {
        paper()
    }
}

impl Env for GridWorld {
    type State = Cell;

    fn name(&self) -> &str {
        &self.name
    }

    /// The world whole, as `policy.json` keeps it: `slip` and the `map`'s rows.
    fn params(&self) -> Value {
        json!({ "slip": self.slip, "map": self.map_lines() })
    }

    fn state_vars(&self) -> Vec<String> {
        vec!["x".into(), "y".into()]
    }

    fn actions(&self) -> Vec<String> {
        GRID_ACTIONS.iter().map(|a| a.to_string()).collect()
    }

    fn num_states(&self) -> usize {
        self.cells.len()
    }

    #[inline]
    fn index(&self, state: &Cell) -> usize {
        if self.open {
            state.y * self.width + state.x
        } else {
            self.index_of(*state).unwrap_or(usize::MAX)
        }
    }

    fn state(&self, index: usize) -> Option<Cell> {
        self.cells.get(index).copied()
    }

    fn valuation(&self, state: &Cell, out: &mut Vec<f64>) {
        out.clear();
        out.extend([state.x as f64, state.y as f64]);
    }

    fn reset(&self, rng: &mut Rng) -> Cell {
        if self.open && self.starts.is_empty() {
            // The paper's draw, kept so that its runs stay bit for bit.
            return Cell {
                x: rng.random_range(0..self.width),
                y: rng.random_range(0..self.height),
            };
        }
        let n = if self.starts.is_empty() { self.cells.len() } else { self.starts.len() };
        let k = rng.random_range(0..n);
        let s = if self.starts.is_empty() { k } else { self.starts[k] as usize };
        self.cells[s]
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
        let k = usize::from(u >= self.thresholds[0]) + usize::from(u >= self.thresholds[1]);
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
            let by_thresholds = |u: f64| {
                usize::from(u >= grid.thresholds[0]) + usize::from(u >= grid.thresholds[1])
            };
            let mut draws: Vec<f64> = (0..100_000).map(|_| rng.random::<f64>()).collect();
            for t in grid.thresholds.into_iter().filter(|t| t.is_finite()) {
                draws.extend([t, f64::from_bits(t.to_bits() - 1), f64::from_bits(t.to_bits() + 1)]);
            }
            draws.extend([p, 1.0 - f64::EPSILON / 2.0]);
            for u in draws.into_iter().filter(|&u| u >= p && u < 1.0) {
                assert_eq!(by_thresholds(u), slip_index(p, u), "p = {p}, u = {u:e}");
            }
        }
        // At p = 0.7 each other action takes a tenth of [0, 1).
        let [t1, t2] = GridWorld::default().thresholds;
        assert!((t1 - 0.8).abs() < 1e-12 && (t2 - 0.9).abs() < 1e-12, "{t1} {t2}");
    }
}
