//! Grid worlds: built in by name or read from world files, and specs checked against them.
//!
//! A world is data: the CLI and the Python package read a world file's text (or take a
//! built-in name), build a [`GridWorld`] with [`GridWorld::from_toml`] or
//! [`GridWorld::builtin`], and check a spec against it with [`check`] before training, so
//! that what `hstlc check --world` accepts is what `hstlc train --world` trains.
//!
//! ```
//! let world = hstl::world::GridWorld::builtin("four-rooms").unwrap();
//! let src = "spec S { state { x: int in 0..=14, y: int in 0..=14 }
//!            let Goal = x > 9 && y > 9; task eventually[0..40] Goal; option Goal; }";
//! let checked = hstl::world::check(src, &world, "world `four-rooms`");
//! assert_eq!(checked.diagnostics[0].code, "HSTL030"); // four-rooms is 13 x 13
//! ```

use hstl_lang::{Checked, WorldFacts};
use hstl_runtime::Env;

pub use hstl_runtime::GridWorld;
pub use hstl_runtime::world::{BUILTIN, DEFAULT_SLIP, WorldError};

/// What the front end's checks need to know of `world`; `label` names it in messages,
/// such as ``world `office` (office.toml)``.
pub fn facts(world: &GridWorld, label: &str) -> WorldFacts {
    let (width, height) = (world.width(), world.height());
    let mut free = vec![false; width * height];
    let mut reachable = vec![false; width * height];
    for (s, reached) in world.reachable().into_iter().enumerate() {
        if let Some(cell) = world.state(s) {
            free[cell.y * width + cell.x] = true;
            reachable[cell.y * width + cell.x] = reached;
        }
    }
    WorldFacts { label: label.to_string(), width, height, free, reachable }
}

/// Parses and checks `src`, and checks each spec with options against `world` (see
/// [`hstl_lang::world`]). Never fails and never panics.
pub fn check(src: &str, world: &GridWorld, label: &str) -> Checked {
    hstl_lang::check_in_world(src, &facts(world, label))
}
