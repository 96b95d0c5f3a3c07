//! `--world NAME|FILE.toml`: a built-in world by name, or a world file.

use std::path::Path;

use hstl::lang::LineIndex;
use hstl::world::{BUILTIN, GridWorld};

use crate::check::read_input;
use crate::cli_error::CliError;

/// A world and how messages name it.
pub struct LoadedWorld {
    /// The world.
    pub world: GridWorld,
    /// ``world `four-rooms` `` or ``world `office` (maps/office.toml)``.
    pub label: String,
    /// The world file, for one read from a file.
    pub file: Option<String>,
}

/// The `--world` help text.
pub const WORLD_HELP: &str = "The grid world: a built-in name (`paper`, the paper's 15 x 15 \
open grid with slip 0.3, or `four-rooms`) or a world file (`FILE.toml`, see README \
\"Worlds\")";

impl LoadedWorld {
    /// The world `arg` names: a built-in name, or a path to a world file. Errors name the
    /// file, line and column.
    pub fn load(arg: &str) -> Result<LoadedWorld, CliError> {
        if let Some(world) = GridWorld::builtin(arg) {
            return Ok(LoadedWorld { world, label: format!("world `{arg}`"), file: None });
        }
        let path = Path::new(arg);
        let looks_like_file = arg.ends_with(".toml") || arg.contains(['/', '\\']) || path.exists();
        if !looks_like_file {
            return Err(CliError::new(
                format!("unknown world `{arg}`"),
                Some(format!(
                    "use a built-in world ({}) or the path of a world file such as `office.toml`",
                    BUILTIN.map(|b| format!("`{b}`")).join(", ")
                )),
            ));
        }
        let (file, text) = read_input(path, "<stdin>").map_err(|e| {
            CliError::new(
                e.to_string(),
                Some(format!(
                    "check the path of the world file, or use a built-in world ({})",
                    BUILTIN.map(|b| format!("`{b}`")).join(", ")
                )),
            )
        })?;
        let stem = path.file_stem().map_or("world".into(), |s| s.to_string_lossy().into_owned());
        let world = GridWorld::from_toml(&text, &stem).map_err(|e| {
            let at = e.span.as_ref().map_or(String::new(), |span| {
                let p = LineIndex::new(&text).position(&text, span.start);
                format!("{}:{}: ", p.line, p.column)
            });
            CliError::new(format!("{file}:{at}{}", e.message), Some(e.help.clone()))
        })?;
        let label = format!("world `{}` ({file})", world.world_name());
        Ok(LoadedWorld { world, label, file: Some(file) })
    }

    /// The world's name, size and slip, for summaries.
    pub fn words(&self) -> String {
        world_words(&self.world, self.file.as_deref())
    }
}

/// ``world `four-rooms` (13 x 13, 65 walls, slip 0.3)``, with the file it was read from
/// before the size.
pub fn world_words(world: &GridWorld, file: Option<&str>) -> String {
    let cells = world.width() * world.height();
    let walls = cells - hstl::runtime::Env::num_states(world);
    let walls = match walls {
        0 => String::new(),
        1 => ", 1 wall".into(),
        n => format!(", {n} walls"),
    };
    // Nine decimals: a `policy.json` written before worlds stores p, and 1 - 0.7 is not 0.3.
    let slip = (world.slip() * 1e9).round() / 1e9;
    let from = file.map_or(String::new(), |f| format!("{f}; "));
    let name = world.world_name();
    format!("world `{name}` ({from}{} x {}{walls}, slip {slip})", world.width(), world.height())
}
