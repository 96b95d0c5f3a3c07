//! World files: a grid world as TOML, and the worlds built in by name.
//!
//! **Contract** (DESIGN.md, "world files"):
//!
//! ```toml
//! name = "two-rooms"   # optional; default: the file name without its extension
//! slip = 0.3           # the chosen action is not taken with this probability; then one
//!                      # of the other three, each equally likely (p = 1 - slip)
//! map = """
//! #######
//! #S.#..#
//! #.....#
//! #######
//! """
//! ```
//!
//! The map's last line is `y = 0`, its first `y = H - 1`; a line's first character is
//! `x = 0`. `.` is a free cell, `#` a wall, `S` a free cell where episodes may start (with
//! no `S`, every free cell is a start). Blank lines at the start and end of the string are
//! ignored; every other line has the same width. Errors carry the byte range in the file
//! they are about, so that a caller can print `FILE:LINE:COL`.
//!
//! ```
//! use hstl_runtime::{Env, GridWorld};
//!
//! let world = GridWorld::from_toml("slip = 0.1\nmap = '''\n#..\nS.#\n'''\n", "tiny")?;
//! assert_eq!((world.world_name(), world.width(), world.height()), ("tiny", 3, 2));
//! assert_eq!(world.num_states(), 4);
//! assert!(!world.is_free(2, 0) && world.is_free(2, 1));
//! # Ok::<(), hstl_runtime::world::WorldError>(())
//! ```

use std::fmt;
use std::ops::Range;

use serde::Deserialize;

use crate::GridWorld;
use crate::env::{MAX_GRID_CELLS, Tile};

/// The names of the built-in worlds, for [`builtin`].
pub const BUILTIN: [&str; 2] = ["paper", "four-rooms"];

/// The slip of a world file that does not set one.
pub const DEFAULT_SLIP: f64 = 0.3;

/// Why a world file could not be read: what is wrong, where, and how to fix it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WorldError {
    /// What is wrong, without a trailing period.
    pub message: String,
    /// The bytes of the file the error is about, when known.
    pub span: Option<Range<usize>>,
    /// How to fix it.
    pub help: String,
}

/// The keys of a world file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WorldFile {
    name: Option<toml::Spanned<String>>,
    slip: Option<toml::Spanned<f64>>,
    map: toml::Spanned<String>,
}

const MAP_HELP: &str = "write the map with `.` for a free cell, `#` for a wall and `S` for a \
                        start cell, one line per row, every line as wide as the first";

impl fmt::Display for WorldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for WorldError {}

impl WorldError {
    fn new(message: impl Into<String>, span: Option<Range<usize>>, help: &str) -> WorldError {
        WorldError { message: message.into(), span, help: help.into() }
    }
}

impl GridWorld {
    /// The world in a world file's text. `default_name` names it when the file has no
    /// `name` (the CLI passes the file name without its extension).
    pub fn from_toml(text: &str, default_name: &str) -> Result<GridWorld, WorldError> {
        parse(text, default_name)
    }

    /// A built-in world by name (see [`BUILTIN`]).
    pub fn builtin(name: &str) -> Option<GridWorld> {
        builtin(name)
    }
}

/// A built-in world by name: `paper` (the paper's 15 x 15 open grid, slip 0.3) or
/// `four-rooms` (13 x 13 with outer walls, four rooms joined by one-cell doorways).
pub fn builtin(name: &str) -> Option<GridWorld> {
    let text = match name {
        "paper" => return Some(paper()),
        "four-rooms" => FOUR_ROOMS,
        _ => return None,
    };
    parse(text, name).ok()
}

/// The paper's world: 15 x 15, no walls, slip 0.3.
pub(crate) fn paper() -> GridWorld {
    let rows = vec![vec![Tile::Free; 15]; 15];
    match GridWorld::from_rows("paper", DEFAULT_SLIP, &rows) {
        Ok(world) => world,
        // A fixed, valid map: `from_rows` accepts it.
        Err(_) => unreachable!("the paper's world is a valid map"),
    }
}

/// The four-rooms world, as DESIGN.md draws it.
const FOUR_ROOMS: &str = include_str!("worlds/four-rooms.toml");

/// Parses a world file (see the module docs).
pub fn parse(text: &str, default_name: &str) -> Result<GridWorld, WorldError> {
    let file: WorldFile = toml::from_str(text).map_err(|e| {
        let message = e.message().trim_end_matches(['\n', '.']).replace('\n', "; ");
        let help = if message.contains("unknown field") {
            "a world file has only the keys `name`, `slip` and `map`"
        } else if message.contains("missing field") {
            "add the map, such as `map = \"\"\"` then one line per row and `\"\"\"`"
        } else {
            "a world file is TOML: `name = \"...\"`, `slip = 0.3`, `map = \"\"\"...\"\"\"`"
        };
        WorldError::new(message, e.span(), help)
    })?;
    let name = match &file.name {
        Some(n) if n.get_ref().trim().is_empty() || n.get_ref().len() > 200 => {
            return Err(WorldError::new(
                "the world's name must hold 1 to 200 characters",
                Some(n.span()),
                "give a short name such as `name = \"office\"`, or leave it out",
            ));
        }
        Some(n) => n.get_ref().clone(),
        None => default_name.to_string(),
    };
    let slip = match &file.slip {
        Some(s) if !(0.0..=1.0).contains(s.get_ref()) => {
            return Err(WorldError::new(
                format!("slip = {} is not a probability in [0, 1]", s.get_ref()),
                Some(s.span()),
                "write a probability such as `slip = 0.3` (the chosen action is taken with 1 - slip)",
            ));
        }
        Some(s) => *s.get_ref(),
        None => DEFAULT_SLIP,
    };
    let rows = map_rows(text, &file.map)?;
    GridWorld::from_rows(&name, slip, &rows)
        .map_err(|e| WorldError::new(e.to_string(), Some(file.map.span()), MAP_HELP))
}

/// The rows of the map, top first, with errors at the map's characters in `text`.
fn map_rows(text: &str, map: &toml::Spanned<String>) -> Result<Vec<Vec<Tile>>, WorldError> {
    let value = map.get_ref();
    let locate = Locator::new(text, map.span(), value);
    let mut lines: Vec<(usize, &str)> = Vec::new();
    let mut offset = 0;
    for line in value.split('\n') {
        lines.push((offset, line.strip_suffix('\r').unwrap_or(line)));
        offset += line.len() + 1;
    }
    let blank = |l: &&(usize, &str)| l.1.trim().is_empty();
    let first = lines.iter().position(|l| !blank(&l));
    let last = lines.iter().rposition(|l| !blank(&l));
    let (Some(first), Some(last)) = (first, last) else {
        return Err(WorldError::new("the map is empty", Some(map.span()), MAP_HELP));
    };
    let lines = &lines[first..=last];
    let width = lines[0].1.chars().count();
    if lines.len() > MAX_GRID_CELLS || width.saturating_mul(lines.len()) > MAX_GRID_CELLS {
        return Err(WorldError::new(
            format!(
                "the map is {width} x {}, more than the {MAX_GRID_CELLS} cells a world may have",
                lines.len()
            ),
            Some(map.span()),
            "draw a smaller map",
        ));
    }
    let mut rows = Vec::with_capacity(lines.len());
    for (i, &(start, line)) in lines.iter().enumerate() {
        let mut row = Vec::with_capacity(width);
        for (at, c) in line.char_indices() {
            let Some(tile) = Tile::from_char(c) else {
                let what = if c.is_whitespace() {
                    format!("a blank (`{}`) in the map", c.escape_default())
                } else {
                    format!("unknown character `{}` in the map", c.escape_default())
                };
                return Err(WorldError::new(
                    what,
                    locate.span(start + at, c.len_utf8()),
                    "a map cell is `.` (free), `#` (wall) or `S` (start); start every line at \
                     the first column",
                ));
            };
            row.push(tile);
        }
        if row.len() != width {
            let at = line.char_indices().nth(width).map_or(line.len(), |(b, _)| b);
            return Err(WorldError::new(
                format!(
                    "map line {} is {} characters wide, the first line is {width}",
                    first + i + 1,
                    row.len()
                ),
                locate.span(start + at, 0),
                "give every line of the map the same width (pad with `#`)",
            ));
        }
        rows.push(row);
    }
    if !rows.iter().flatten().any(|&t| t != Tile::Wall) {
        return Err(WorldError::new("the map has no free cell", Some(map.span()), MAP_HELP));
    }
    Ok(rows)
}

/// Maps byte offsets in a string value to bytes of the file, where the value is the
/// literal's text as written (no escapes).
struct Locator {
    /// The file offset of the value's first byte, when the value is written verbatim.
    start: Option<usize>,
    /// The literal's span, for values written with escapes.
    whole: Range<usize>,
}

impl Locator {
    fn new(text: &str, span: Range<usize>, value: &str) -> Locator {
        let raw = text.get(span.clone()).unwrap_or("");
        let start = ["\"\"\"", "'''", "\"", "'"].iter().find_map(|q| {
            let inner = raw.strip_prefix(q)?.strip_suffix(q)?;
            let skip = if q.len() == 3 {
                // A newline right after the opening quotes is not part of the value.
                if inner.starts_with("\r\n") { 2 } else { usize::from(inner.starts_with('\n')) }
            } else {
                0
            };
            (inner.get(skip..)? == value).then_some(span.start + q.len() + skip)
        });
        Locator { start, whole: span }
    }

    fn span(&self, offset: usize, len: usize) -> Option<Range<usize>> {
        Some(match self.start {
            Some(s) => s + offset..s + offset + len,
            None => self.whole.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Env;

    #[test]
    fn builtins_parse_and_the_paper_is_the_open_grid() {
        for name in BUILTIN {
            let world = builtin(name).unwrap_or_else(|| panic!("{name} parses"));
            assert_eq!(world.world_name(), name);
        }
        let paper = builtin("paper").unwrap();
        assert_eq!((paper.width(), paper.height(), paper.num_states()), (15, 15, 225));
        assert!(!paper.has_walls() && !paper.has_start_cells());
        // The paper's p is exactly 0.7: its runs stay bit for bit.
        assert_eq!(paper.p().to_bits(), 0.7f64.to_bits());
        let rooms = builtin("four-rooms").unwrap();
        assert_eq!((rooms.width(), rooms.height()), (13, 13));
        assert!(builtin("nowhere").is_none());
    }

    #[test]
    fn map_positions_point_into_the_file() {
        let text = "map = \"\"\"\n..#\n.x.\n\"\"\"\n";
        let e = parse(text, "w").unwrap_err();
        assert_eq!(&text[e.span.clone().unwrap()], "x");
        // With an escape the literal is not verbatim: the error covers the whole literal.
        let text = "map = \"..#\\n.x.\"\n";
        let e = parse(text, "w").unwrap_err();
        assert_eq!(&text[e.span.clone().unwrap()], "\"..#\\n.x.\"");
    }
}
