//! World files: grid worlds (TOML maps) and plane worlds (`kind = "plane"`), and the
//! worlds built in by name.
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
//!
//! **Contract** (DESIGN.md, "plane worlds"): a file with `kind = "plane"` is a
//! [`PlaneWorld`]; `kind = "grid"` (or no `kind`) is the map above, read exactly as
//! before. The keys of a plane world: `name` (optional), `kind`, `x` and `y` (the extent,
//! `[lo, hi]` with `lo < hi`, finite), `step` (positive, finite), `headings` (3 to 64),
//! `slip` (in `[0, 1]`, default 0), `noise` (`>= 0`, finite, default 0), `obstacles`
//! (optional, at most [`MAX_OBSTACLES`]: `{ circle = [cx, cy, r] }` with `r > 0`, or
//! `{ rect = [x0, y0, x1, y1] }` with `x0 < x1` and `y0 < y1`) and `start` (optional,
//! `[x0, y0, x1, y1]`, clipped to the extent; it needs a free part). Numbers may be
//! written as integers. Every error points at the key or value it is about, and unknown
//! keys are refused.
//!
//! ```
//! use hstl_runtime::world::AnyWorld;
//! use hstl_runtime::World;
//!
//! let text = "kind = \"plane\"\nx = [0, 20]\ny = [0, 10]\nstep = 0.5\nheadings = 8\n\
//!             obstacles = [{ circle = [10, 5, 1.5] }]\nstart = [0, 0, 2, 2]\n";
//! let AnyWorld::Plane(world) = AnyWorld::from_toml(text, "yard")? else { panic!() };
//! assert_eq!(world.name(), "yard");
//! assert_eq!(world.actions(), ["E", "NE", "N", "NW", "W", "SW", "S", "SE"]);
//! # Ok::<(), hstl_runtime::world::WorldError>(())
//! ```

mod plane;

use std::fmt;
use std::ops::Range;

use serde::Deserialize;
use serde_json::Value;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

use crate::grid::{MAX_GRID_CELLS, Tile};
use crate::plane::PlaneWorld;
pub use crate::plane::{MAX_OBSTACLES, PLANE_BUILTIN};
use crate::{Error, GridWorld, MountainCar, World};

/// The names of the built-in grid worlds, for [`builtin`]; [`PLANE_BUILTIN`] names the
/// plane ones, and [`AnyWorld::builtin`] takes both.
pub const BUILTIN: [&str; 2] = ["paper", "four-rooms"];

pub use crate::grid::DEFAULT_SLIP;

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

/// The keys of a grid world file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WorldFile {
    name: Option<Spanned<String>>,
    slip: Option<Spanned<f64>>,
    map: Spanned<String>,
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
    /// The grid world in a world file's text. `default_name` names it when the file has no
    /// `name` (the CLI passes the file name without its extension). A plane world file is
    /// an error here: [`AnyWorld::from_toml`] reads both kinds.
    pub fn from_toml(text: &str, default_name: &str) -> Result<GridWorld, WorldError> {
        parse(text, default_name)
    }

    /// A built-in grid world by name (see [`BUILTIN`]).
    pub fn builtin(name: &str) -> Option<GridWorld> {
        builtin(name)
    }
}

impl PlaneWorld {
    /// The plane world in a world file's text (`kind = "plane"`). `default_name` names it
    /// when the file has no `name`. A grid world file is an error here.
    pub fn from_toml(text: &str, default_name: &str) -> Result<PlaneWorld, WorldError> {
        let (table, kind) = document(text)?;
        match kind {
            Some((Kind::Plane, _)) => plane::parse(table, default_name),
            _ => Err(WorldError::new(
                "this is a grid world; only a plane world can be used here",
                kind.map(|(_, span)| span),
                "give a plane world file, one with `kind = \"plane\"`",
            )),
        }
    }
}

/// A world of either kind a world file describes.
#[derive(Clone, Debug, PartialEq)]
pub enum AnyWorld {
    /// A grid world: a map of cells (`kind = "grid"`, the default).
    Grid(GridWorld),
    /// A plane world: a bounded plane (`kind = "plane"`).
    Plane(PlaneWorld),
    /// Gymnasium's MountainCar-v0 dynamics, built in as `mountain-car`.
    MountainCar(MountainCar),
}

/// The names of the built-in continuous worlds that are no plane: `mountain-car`.
pub const CAR_BUILTIN: [&str; 1] = ["mountain-car"];

impl AnyWorld {
    /// The world in a world file's text, of the kind its `kind` says. `default_name` names
    /// it when the file has no `name`.
    pub fn from_toml(text: &str, default_name: &str) -> Result<AnyWorld, WorldError> {
        let (mut table, kind) = document(text)?;
        match kind {
            Some((Kind::Plane, _)) => plane::parse(table, default_name).map(AnyWorld::Plane),
            _ => {
                table.get_mut().remove("kind");
                parse_grid(text, table, default_name).map(AnyWorld::Grid)
            }
        }
    }

    /// A built-in world by name: a grid ([`BUILTIN`]) or a plane ([`PLANE_BUILTIN`]).
    pub fn builtin(name: &str) -> Option<AnyWorld> {
        if CAR_BUILTIN.contains(&name) {
            return Some(AnyWorld::MountainCar(MountainCar));
        }
        builtin(name).map(AnyWorld::Grid).or_else(|| PlaneWorld::builtin(name).map(AnyWorld::Plane))
    }

    /// Every built-in world's name: grids, planes, then the others.
    pub fn builtin_names() -> Vec<&'static str> {
        BUILTIN.iter().chain(&PLANE_BUILTIN).chain(&CAR_BUILTIN).copied().collect()
    }

    /// Whether the world's state is continuous (a plane, mountain-car): the approximate
    /// learner trains in it.
    pub fn is_continuous(&self) -> bool {
        !matches!(self, AnyWorld::Grid(_))
    }

    /// The world from `policy.json`'s `env`: its name and the `params` that
    /// [`World::params`] wrote. `"kind": "plane"` is a plane world; no `kind` (or
    /// `"grid"`) a grid world, also one written before worlds existed.
    pub fn from_params(name: &str, params: &Value) -> Result<AnyWorld, Error> {
        if let Some(problem) = name_problem(name) {
            return Err(Error::Env(problem));
        }
        let world = match params.get("kind") {
            None => GridWorld::from_params(name, params).map(AnyWorld::Grid),
            Some(Value::String(k)) if k == "grid" => {
                GridWorld::from_params(name, params).map(AnyWorld::Grid)
            }
            Some(Value::String(k)) if k == "plane" => {
                PlaneWorld::from_params(name, params).map(AnyWorld::Plane)
            }
            Some(Value::String(k)) if k == "mountain-car" => {
                MountainCar::from_params(params).map(AnyWorld::MountainCar)
            }
            Some(_) => {
                Err(Error::Env("the world's `kind` is neither \"grid\" nor \"plane\"".into()))
            }
        }?;
        // A built-in world's name stands for that world: another world under it is not it.
        if let Some(builtin) = AnyWorld::builtin(name)
            && builtin != world
        {
            return Err(Error::Env(format!(
                "the world is named `{name}`, a built-in world, but its parameters are not `{name}`'s"
            )));
        }
        Ok(world)
    }

    /// The world's name.
    pub fn name(&self) -> &str {
        match self {
            AnyWorld::Grid(w) => World::name(w),
            AnyWorld::Plane(w) => w.name(),
            AnyWorld::MountainCar(w) => w.name(),
        }
    }

    /// The world's parameters, as `policy.json` keeps them (see [`World::params`]).
    pub fn params(&self) -> Value {
        match self {
            AnyWorld::Grid(w) => World::params(w),
            AnyWorld::Plane(w) => w.params(),
            AnyWorld::MountainCar(w) => w.params(),
        }
    }
}

/// A built-in grid world by name: `paper` (the paper's 15 x 15 open grid, slip 0.3) or
/// `four-rooms` (13 x 13 with outer walls, four rooms joined by one-cell doorways).
pub fn builtin(name: &str) -> Option<GridWorld> {
    let text = match name {
        "paper" => return Some(crate::grid::paper()),
        "four-rooms" => FOUR_ROOMS,
        _ => return None,
    };
    parse(text, name).ok()
}

/// The four-rooms world, as DESIGN.md draws it.
const FOUR_ROOMS: &str = include_str!("worlds/four-rooms.toml");

/// Parses a grid world file (see the module docs). A plane world file (`kind = "plane"`)
/// is an error here: read it with [`AnyWorld::from_toml`].
pub fn parse(text: &str, default_name: &str) -> Result<GridWorld, WorldError> {
    let (mut table, kind) = document(text)?;
    if let Some((Kind::Plane, span)) = kind {
        return Err(WorldError::new(
            "this is a plane world (`kind = \"plane\"`); only a grid world can be used here",
            Some(span),
            "give a grid world file (one with a `map`), or use a program that runs plane worlds",
        ));
    }
    // `kind = "grid"` says what no `kind` says; the grid's keys are read as before.
    table.get_mut().remove("kind");
    parse_grid(text, table, default_name)
}

/// What a world file's `kind` says.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    Grid,
    Plane,
}

/// The file's TOML table, and its `kind` with the span of its value if it has one.
type Document<'t> = (Spanned<DeTable<'t>>, Option<(Kind, Range<usize>)>);

/// Parses the TOML and reads `kind`.
fn document(text: &str) -> Result<Document<'_>, WorldError> {
    // The TOML parser keeps tens of bytes per line: the size is checked before it runs.
    if text.len() > MAX_WORLD_BYTES {
        return Err(WorldError::new(
            format!(
                "the world file has {} bytes, more than the {} a world file may have",
                grouped(text.len()),
                grouped(MAX_WORLD_BYTES)
            ),
            None,
            SIZE_HELP,
        ));
    }
    if let Some((at, _)) = text.match_indices('\n').nth(MAX_WORLD_LINES) {
        return Err(WorldError::new(
            format!("the world file has more than {} lines", grouped(MAX_WORLD_LINES)),
            Some(at..at + 1),
            SIZE_HELP,
        ));
    }
    // And so is the number of values: the parser keeps about a hundred bytes per value.
    if let Some(at) = past_value_budget(text) {
        return Err(WorldError::new(
            format!(
                "the world file holds more than {} values (numbers, strings, lists, tables)",
                grouped(MAX_WORLD_VALUES)
            ),
            Some(at..at + 1),
            SIZE_HELP,
        ));
    }
    let table = DeTable::parse(text).map_err(|e| {
        let message = e.message().trim_end_matches(['\n', '.']).replace('\n', "; ");
        if message == "recursion limit" {
            // The parser's limit on dotted keys comes without a place: the first line with
            // that many dots is it.
            let at = text
                .lines()
                .scan(0, |start, line| {
                    let here = *start;
                    *start += line.len() + 1;
                    Some((here, line))
                })
                .find(|(_, line)| line.matches('.').count() >= DOTTED_LIMIT - 1)
                .map(|(at, line)| at..at + line.len());
            return WorldError::new(
                format!("a key has more than {} dotted parts", DOTTED_LIMIT - 1),
                at.or(e.span()),
                "write the world's keys as the world file format names them, such as `x = [0.0, 20.0]`; no world key is nested",
            );
        }
        WorldError::new(message, e.span(), TOML_HELP)
    })?;
    let kind = match table.get_ref().get("kind") {
        None => None,
        Some(value) => {
            let span = value.span();
            let kind = match value.get_ref().as_str() {
                Some("grid") => Kind::Grid,
                Some("plane") => Kind::Plane,
                Some(other) => {
                    return Err(WorldError::new(
                        format!("unknown world kind `{}`", crate::words::visible(other)),
                        Some(span),
                        KIND_HELP,
                    ));
                }
                None => {
                    return Err(WorldError::new(
                        format!("kind must be a string, not {}", describe(value.get_ref())),
                        Some(span),
                        KIND_HELP,
                    ));
                }
            };
            Some((kind, span))
        }
    };
    Ok((table, kind))
}

/// The most values (numbers, strings, lists, tables, keys) a world file may hold: a
/// plane's [`crate::plane::MAX_OBSTACLES`] obstacles take about 6,000, a grid's map is one.
pub const MAX_WORLD_VALUES: usize = 1 << 16;

/// The TOML parser's limit on the parts of a dotted key.
const DOTTED_LIMIT: usize = 80;

/// Where a world file's text passes [`MAX_WORLD_VALUES`], if it does, counted before it is
/// parsed: each value but the first follows one of `[ { , = .` outside strings and comments
/// (a dot in a number counts too, which only over-counts).
fn past_value_budget(text: &str) -> Option<usize> {
    let b = text.as_bytes();
    let mut count = 0usize;
    let mut i = 0;
    // Skips a string opened at `i` by `quote` (`"` with escapes, `'` without), one line or
    // three quotes long; returns where it ends.
    let skip = |i: usize, quote: u8| -> usize {
        let triple = b.len() >= i + 3 && b[i + 1] == quote && b[i + 2] == quote;
        let mut j = if triple { i + 3 } else { i + 1 };
        while j < b.len() {
            match b[j] {
                b'\\' if quote == b'"' => j += 2,
                c if c == quote && !triple => return j + 1,
                c if c == quote && b.len() >= j + 3 && b[j + 1] == quote && b[j + 2] == quote => {
                    return j + 3;
                }
                b'\n' if !triple => return j + 1,
                _ => j += 1,
            }
        }
        b.len()
    };
    while i < b.len() {
        match b[i] {
            b'#' => {
                i = b[i..].iter().position(|&c| c == b'\n').map_or(b.len(), |n| i + n + 1);
            }
            q @ (b'"' | b'\'') => i = skip(i, q),
            b'[' | b'{' | b',' | b'=' | b'.' => {
                count += 1;
                if count > MAX_WORLD_VALUES {
                    return Some(i);
                }
                i += 1;
            }
            _ => i += 1,
        }
    }
    None
}

/// The most bytes a world file may have: a map of [`crate::grid::MAX_GRID_CELLS`] cells,
/// its line ends and comments, or a plane's [`crate::plane::MAX_OBSTACLES`] obstacles, fit.
pub const MAX_WORLD_BYTES: usize = 8 << 20;

/// The most lines a world file may have: a map's rows (one cell wide, at most
/// [`crate::grid::MAX_GRID_CELLS`] of them) and room for the rest.
pub const MAX_WORLD_LINES: usize = crate::grid::MAX_GRID_CELLS + 4096;

/// `n` with a comma between groups of three digits: `1,052,672`.
fn grouped(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

const SIZE_HELP: &str = "a world file holds one map of at most 1,048,576 cells, or a plane with at \
                         most 1,024 obstacles; check that this is the file you meant";

const TOML_HELP: &str =
    "a world file is TOML: `name = \"...\"`, `slip = 0.3`, `map = \"\"\"...\"\"\"`";
const KIND_HELP: &str =
    "a world's `kind` is \"grid\" (a map, the default) or \"plane\" (a bounded plane)";
const NAME_HELP: &str = "give a short name such as `name = \"office\"`, or leave it out";

/// What kind of TOML value `v` is, for messages.
fn describe(v: &DeValue<'_>) -> &'static str {
    match v {
        DeValue::String(_) => "a string",
        DeValue::Integer(_) | DeValue::Float(_) => "a number",
        DeValue::Boolean(_) => "a boolean",
        DeValue::Datetime(_) => "a date",
        DeValue::Array(_) => "a list",
        DeValue::Table(_) => "a table",
    }
}

/// The world's name: the file's `name` (1 to 200 characters) or `default_name`.
fn world_name(
    name: Option<(&str, Range<usize>)>,
    default_name: &str,
) -> Result<String, WorldError> {
    match name {
        Some((n, span)) => match name_problem(n) {
            Some(problem) => Err(WorldError::new(problem, Some(span), NAME_HELP)),
            None => Ok(n.to_string()),
        },
        None => Ok(default_name.to_string()),
    }
}

/// What is wrong with a world's name, if anything: it holds 1 to 200 bytes, not all white
/// space, and no control character (a name is shown in messages, written into
/// `policy.json` and drawn into pictures, so none may move a terminal's cursor or hide what
/// follows it).
pub fn name_problem(name: &str) -> Option<String> {
    if name.trim().is_empty() || name.len() > 200 {
        return Some("the world's name must hold 1 to 200 characters".into());
    }
    let bidi = |c: char| matches!(c, '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}');
    name.chars().find(|&c| c.is_control() || bidi(c)).map(|c| {
        format!(
            "the world's name holds the control character U+{:04X}; a name is plain text",
            u32::from(c)
        )
    })
}

/// Reads a grid world from the file's table (without `kind`).
fn parse_grid(
    text: &str,
    table: Spanned<DeTable<'_>>,
    default_name: &str,
) -> Result<GridWorld, WorldError> {
    let file = WorldFile::deserialize(toml::de::Deserializer::from(table)).map_err(|e| {
        let message = e.message().trim_end_matches(['\n', '.']).replace('\n', "; ");
        let help = if message.contains("unknown field") {
            "a world file has only the keys `name`, `slip` and `map`"
        } else if message.contains("missing field") {
            "add the map, such as `map = \"\"\"` then one line per row and `\"\"\"`"
        } else {
            TOML_HELP
        };
        WorldError::new(message, e.span(), help)
    })?;
    let name =
        world_name(file.name.as_ref().map(|n| (n.get_ref().as_str(), n.span())), default_name)?;
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
                    format!("a blank (`{}`) in the map", crate::words::visible_char(c))
                } else {
                    format!("unknown character `{}` in the map", crate::words::visible_char(c))
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
    use crate::{Env, World};

    /// A file of line ends only cost the TOML parser tens of bytes a line (a 63 MiB one took
    /// 3.1 GB and 12 s): past the limits it is refused before parsing, the line named.
    #[test]
    fn oversized_world_files_are_refused_before_parsing() {
        let lines = "\n".repeat(MAX_WORLD_LINES + 1);
        let e = AnyWorld::from_toml(&lines, "w").expect_err("too many lines");
        assert_eq!(e.message, "the world file has more than 1,052,672 lines");
        assert_eq!(e.span, Some(MAX_WORLD_LINES..MAX_WORLD_LINES + 1));
        let bytes = " ".repeat(MAX_WORLD_BYTES + 1);
        let e = AnyWorld::from_toml(&bytes, "w").expect_err("too many bytes");
        assert!(e.message.contains("8,388,609 bytes, more than the 8,388,608"), "{}", e.message);
        // A tall map, 65,536 rows of one cell, still reads.
        let tall = format!("map = \"\"\"\n{}\"\"\"\n", ".\n".repeat(1 << 16));
        assert!(AnyWorld::from_toml(&tall, "tall").is_ok());
    }

    /// Issue 30 (the campaign on world files): 400,000 obstacles fit in the 8 MiB a world
    /// file may have, and the parser took 796 MB for them before the count refused them.
    #[test]
    fn the_values_of_a_world_file_are_counted_before_it_is_parsed() {
        let head = "kind = \"plane\"\nx = [0.0, 9.0]\ny = [0.0, 9.0]\nstep = 1.0\nheadings = 4\n";
        let many = format!("{head}obstacles = [\n{}]\n", "{circle=[1,1,1]},\n".repeat(400_000));
        assert!(many.len() < MAX_WORLD_BYTES);
        let e = AnyWorld::from_toml(&many, "w").expect_err("too many values");
        assert_eq!(
            e.message,
            "the world file holds more than 65,536 values (numbers, strings, lists, tables)"
        );
        let at = e.span.expect("placed").start;
        assert!(many[..at].starts_with(head) && at < many.len() / 2, "{at}");
        // Strings and comments are not counted: a map full of commas and brackets is one
        // value, and so is a comment.
        let map = format!(
            "# {}\nname = \"{}\"\nmap = \"\"\"\n{}\"\"\"\n",
            ",".repeat(100_000),
            "a",
            "..\n".repeat(1_000)
        );
        assert_eq!(past_value_budget(&map), None);
        let quoted = format!("a = '{}'\nb = \"\\\"{}\"\n", "[".repeat(70_000), ",".repeat(70_000));
        assert_eq!(past_value_budget(&quoted), None);
        // The largest world a file may describe is far inside the budget.
        let obstacles = "{ rect = [1.5, 1.5, 2.5, 2.5] },\n".repeat(MAX_OBSTACLES);
        let full = format!("{head}obstacles = [\n{obstacles}]\n");
        assert_eq!(past_value_budget(&full), None);
    }

    /// Issue 30: an extent of finite bounds whose width overflows was accepted, trained
    /// with every state in one tile, and failed only when its pictures were drawn.
    #[test]
    fn an_extent_wider_than_the_largest_double_is_refused() {
        let text = "kind = \"plane\"\nx = [-1.7976931348623157e308, 1.7976931348623157e308]\n\
                    y = [0.0, 1.0]\nstep = 1.0\nheadings = 4\n";
        let e = AnyWorld::from_toml(text, "w").expect_err("too wide");
        assert!(e.message.contains("the extent is wider than the largest number"), "{}", e.message);
        assert_eq!(e.span.map(|s| s.start), text.find('['));
        let lo = [-f64::MAX, 0.0];
        let e = crate::approx::tiles::TileCoder::new(&lo, &[f64::MAX, 1.0], &[4, 4], 2)
            .expect_err("a tiling of an infinite width");
        assert!(e.contains("finite width") && e.contains("-1.7976931348623157e308"), "{e}");
    }

    /// Issue 30: a dotted key past the parser's depth was "recursion limit", with no place.
    #[test]
    fn a_key_with_too_many_dotted_parts_is_placed() {
        let text = format!("kind = \"plane\"\n[{}]\nb = 1\n", vec!["a"; 100].join("."));
        let e = AnyWorld::from_toml(&text, "w").expect_err("too deep");
        assert_eq!(e.message, "a key has more than 79 dotted parts");
        assert_eq!(e.span.map(|s| s.start), Some(15));
    }

    /// Issue 30: a world's name reaches terminals, `policy.json` and pictures; one with a
    /// control character (an escape sequence) was shown raw.
    #[test]
    fn a_world_name_with_a_control_character_is_refused() {
        let text = "name = \"a\\u001b[31mred\"\nmap = \"\"\"\n..\n\"\"\"\n";
        let e = AnyWorld::from_toml(text, "w").expect_err("a control character");
        assert!(e.message.contains("control character U+001B"), "{}", e.message);
        let grid = builtin("paper").expect("paper");
        let e = AnyWorld::from_params("a\u{202e}b", &World::params(&grid)).expect_err("bidi");
        assert!(e.to_string().contains("U+202E"), "{e}");
        // A built-in world's name on other parameters is not that world.
        let four = builtin("four-rooms").expect("four-rooms");
        let e = AnyWorld::from_params("paper", &World::params(&four)).expect_err("not paper");
        assert!(e.to_string().contains("built-in world"), "{e}");
        assert!(AnyWorld::from_params("paper", &World::params(&grid)).is_ok());
        let plane = AnyWorld::builtin("paper-plane").expect("paper-plane");
        assert_eq!(AnyWorld::from_params("paper-plane", &plane.params()).ok(), Some(plane));
    }

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
