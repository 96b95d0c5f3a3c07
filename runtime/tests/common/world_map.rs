//! Worlds from ASCII maps, as the world files' contract reads them (`.` free, `#` wall,
//! `S` start; the last line is `y = 0`): the solver's `Moves` and the cells, for the tests
//! and benches of the optimum. (The runtime's own `GridWorld` gains walls separately.)
#![allow(dead_code)]

use hstl_runtime::moves::Moves;

/// A map's free cells and moves.
pub struct MapWorld {
    pub moves: Moves,
    /// `cells[s]`: the `(x, y)` of state `s`; states run over the free cells by `y`, then `x`.
    pub cells: Vec<(usize, usize)>,
}

/// The four-rooms world of the design's "world files" contract.
pub const FOUR_ROOMS: &str = "
#############
#.....#.....#
#.....#.....#
#...........#
#.....#.....#
#.....#.....#
##.####.....#
#.....###.###
#.....#.....#
#.....#.....#
#...........#
#.....#.....#
#############
";

impl MapWorld {
    /// The world of `map` where the chosen action is taken with probability `p`.
    pub fn new(map: &str, p: f64) -> MapWorld {
        let lines: Vec<&str> = map.trim_matches('\n').lines().collect();
        let height = lines.len();
        let at = |x: usize, y: usize| lines[height - 1 - y].as_bytes()[x];
        let mut cells = Vec::new();
        let mut starts = Vec::new();
        for y in 0..height {
            for x in 0..lines[height - 1 - y].len() {
                match at(x, y) {
                    b'#' => {}
                    c => {
                        assert!(c == b'.' || c == b'S', "unknown map character {}", c as char);
                        if c == b'S' {
                            starts.push(cells.len() as u32);
                        }
                        cells.push((x, y));
                    }
                }
            }
        }
        let index = |x: i64, y: i64| {
            cells.iter().position(|&c| c == (x as usize, y as usize)).map(|i| i as u32)
        };
        let dest = (0..cells.len())
            .map(|s| {
                let (x, y) = (cells[s].0 as i64, cells[s].1 as i64);
                // Up, Down, Left, Right; a wall or the edge keeps the robot in place.
                [(0, 1), (0, -1), (-1, 0), (1, 0)].map(|(dx, dy)| {
                    let (nx, ny) = (x + dx, y + dy);
                    let inside = nx >= 0 && ny >= 0 && (ny as usize) < height;
                    inside.then(|| index(nx, ny)).flatten().unwrap_or(s as u32)
                })
            })
            .collect();
        if starts.is_empty() {
            starts = (0..cells.len() as u32).collect();
        }
        MapWorld { moves: Moves { dest, p, starts }, cells }
    }

    /// Per state, whether `(x, y)` satisfies `inside`.
    pub fn region(&self, inside: impl Fn(usize, usize) -> bool) -> Vec<bool> {
        self.cells.iter().map(|&(x, y)| inside(x, y)).collect()
    }

    /// The state at `(x, y)`.
    pub fn state(&self, x: usize, y: usize) -> u32 {
        self.cells.iter().position(|&c| c == (x, y)).expect("a free cell") as u32
    }
}
