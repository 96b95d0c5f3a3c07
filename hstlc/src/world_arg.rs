//! `--world NAME|FILE.toml`: a built-in world by name, or a world file.

use std::path::Path;

use hstl::world::GridWorld;

use crate::cli_error::CliError;
use crate::input;

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
            let label = hstl::world::label(&world, None);
            return Ok(LoadedWorld { world, label, file: None });
        }
        let path = Path::new(arg);
        if !hstl::world::looks_like_file(arg) && !path.exists() {
            let unknown = hstl::world::unknown(arg);
            return Err(CliError::new(unknown.message, unknown.help));
        }
        let input::Input { name: file, text, .. } =
            input::read_text(path, "<stdin>", hstl::lang::MAX_SOURCE_BYTES, "world file").map_err(
                |e| match e {
                    // Too large or not UTF-8 say how to fix it already.
                    CliError::Read { .. } => {
                        CliError::new(e.to_string(), Some(hstl::world::read_help()))
                    }
                    other => other,
                },
            )?;
        let stem = path.file_stem().map_or("world".into(), |s| s.to_string_lossy().into_owned());
        let world = hstl::world::from_file(&text, &file, &stem)
            .map_err(|p| CliError::new(p.message, p.help))?;
        let label = hstl::world::label(&world, Some(&file));
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
