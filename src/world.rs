//! Grid worlds: built in by name or read from world files, and specs checked against them.
//!
//! A world is data: the CLI and the Python package read a world file's text (or take a
//! built-in name), build a [`GridWorld`] with [`GridWorld::from_toml`] or
//! [`GridWorld::builtin`], and check a spec against it with [`check`] before training, so
//! that what `hstlc check --world` accepts is what `hstlc train --world` trains. Both
//! front ends name worlds ([`label`]) and word a bad world file ([`from_file`]) or name
//! ([`unknown`]) with the functions here.
//!
//! ```
//! let world = hstl::world::GridWorld::builtin("four-rooms").unwrap();
//! let src = "spec S { state { x: int in 0..=14, y: int in 0..=14 }
//!            let Goal = x > 9 && y > 9; task eventually[0..40] Goal; option Goal; }";
//! let checked = hstl::world::check(src, &world, "world `four-rooms`");
//! assert_eq!(checked.diagnostics[0].code, "HSTL030"); // four-rooms is 13 x 13
//! ```

use hstl_lang::{BoxFacts, Checked, LineIndex, SpecWorld, WorldFacts};
use hstl_runtime::Env;

use crate::Problem;

pub use hstl_runtime::GridWorld;
pub use hstl_runtime::world::{
    AnyWorld, BUILTIN, CAR_BUILTIN, DEFAULT_SLIP, MAX_WORLD_BYTES, MAX_WORLD_LINES, PLANE_BUILTIN,
    WorldError,
};

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

/// What the checks know of a world of any kind.
#[derive(Clone, Debug, PartialEq)]
pub enum Facts {
    /// A grid world's cells.
    Grid(WorldFacts),
    /// A continuous world's state variables and ranges.
    Box(BoxFacts),
}

impl Facts {
    /// What a spec is checked against in this world.
    pub fn spec_world(&self) -> SpecWorld<'_> {
        match self {
            Facts::Grid(f) => SpecWorld::Facts(f),
            Facts::Box(f) => SpecWorld::Box(f),
        }
    }
}

/// What the front end's checks need to know of a world of any kind (see [`facts`]).
pub fn any_facts(world: &AnyWorld, label: &str) -> Facts {
    match world {
        AnyWorld::Grid(g) => Facts::Grid(facts(g, label)),
        AnyWorld::Plane(p) => {
            let ([x0, x1], [y0, y1]) = p.extent();
            let vars = vec![("x".to_string(), x0, x1), ("y".to_string(), y0, y1)];
            Facts::Box(BoxFacts {
                label: label.to_string(),
                vars,
                actions: p.headings() as u64,
                fit: tile_fit(world),
            })
        }
        AnyWorld::MountainCar(car) => {
            use hstl_runtime::MountainCar as C;
            let vars = vec![
                ("x".to_string(), C::MIN_POSITION, C::MAX_POSITION),
                ("v".to_string(), -C::MAX_SPEED, C::MAX_SPEED),
            ];
            let actions = hstl_runtime::World::actions(car).len() as u64;
            Facts::Box(BoxFacts { label: label.to_string(), vars, actions, fit: tile_fit(world) })
        }
    }
}

/// [`label`] for a world of any kind.
pub fn any_label(world: &AnyWorld, file: Option<&str>) -> String {
    match file {
        Some(file) => format!("world `{}` ({file})", world.name()),
        None => format!("world `{}`", world.name()),
    }
}

/// [`from_file`] for a world file of any kind (`kind = "plane"` or a grid).
pub fn any_from_file(text: &str, file: &str, stem: &str) -> Result<AnyWorld, Problem> {
    AnyWorld::from_toml(text, stem).map_err(|e| {
        let at = e.span.as_ref().map_or(String::new(), |span| {
            let p = LineIndex::new(text).position(text, span.start);
            format!("{}:{}: ", p.line, p.column)
        });
        Problem::new(format!("{file}:{at}{}", e.message), e.help.clone())
    })
}

/// A world's kind, size and dynamics in words, for summaries: ``world `four-rooms` (13 x
/// 13, 65 walls, slip 0.3)``, ``world `yard` (yard.toml; plane 20 x 10, step 0.5, 8
/// headings, slip 0.1, noise 0.05, 2 obstacles)``, with the file it was read from.
pub fn words(world: &AnyWorld, file: Option<&str>) -> String {
    let from = file.map_or(String::new(), |f| format!("{f}; "));
    let name = world.name();
    // Nine decimals: a `policy.json` written before worlds stores p, and 1 - 0.7 is not 0.3.
    // A plane's numbers may be anything finite: past moderate magnitudes, with an exponent.
    let round = |v: f64| {
        let a = v.abs();
        if a == 0.0 || (1e-5..1e16).contains(&a) {
            ((v * 1e9).round() / 1e9).to_string()
        } else {
            hstl_runtime::plane::num(v)
        }
    };
    match world {
        AnyWorld::Grid(g) => {
            let cells = g.width() * g.height();
            let walls = match cells - Env::num_states(g) {
                0 => String::new(),
                1 => ", 1 wall".into(),
                n => format!(", {n} walls"),
            };
            format!(
                "world `{name}` ({from}{} x {}{walls}, slip {})",
                g.width(),
                g.height(),
                round(g.slip())
            )
        }
        AnyWorld::Plane(p) => {
            let ([x0, x1], [y0, y1]) = p.extent();
            // A width past the largest double is shown as its extent.
            let size = |lo: f64, hi: f64| {
                if (hi - lo).is_finite() {
                    round(hi - lo)
                } else {
                    format!("[{}, {}]", hstl_runtime::plane::num(lo), hstl_runtime::plane::num(hi))
                }
            };
            let obstacles = match p.obstacles().len() {
                0 => String::new(),
                1 => ", 1 obstacle".into(),
                n => format!(", {n} obstacles"),
            };
            format!(
                "world `{name}` ({from}plane {} x {}, step {}, {} headings, slip {}, noise {}{obstacles})",
                size(x0, x1),
                size(y0, y1),
                hstl_runtime::plane::num(p.step_length()),
                p.headings(),
                round(p.slip()),
                hstl_runtime::plane::num(p.noise())
            )
        }
        AnyWorld::MountainCar(_) => {
            format!("world `{name}` ({from}gymnasium's MountainCar-v0 dynamics, no goal)")
        }
    }
}

/// The built-in names of every kind, quoted and listed.
pub fn builtin_list() -> String {
    AnyWorld::builtin_names().iter().map(|b| format!("`{b}`")).collect::<Vec<_>>().join(", ")
}

/// How messages name a world: ``world `paper` `` for a built-in one, ``world `office`
/// (maps/office.toml)`` for one read from a file.
pub fn label(world: &GridWorld, file: Option<&str>) -> String {
    match file {
        Some(file) => format!("world `{}` ({file})", world.world_name()),
        None => format!("world `{}`", world.world_name()),
    }
}

/// Whether a world argument that is no built-in name reads as a world file by its form
/// (it ends in `.toml` or holds a path separator); a caller also takes a path that exists.
pub fn looks_like_file(arg: &str) -> bool {
    arg.ends_with(".toml") || arg.contains(['/', '\\'])
}

/// A name that is neither a built-in world nor a world file.
pub fn unknown(name: &str) -> Problem {
    Problem::new(
        format!("unknown world `{name}`"),
        format!(
            "use a built-in world ({}) or the path of a world file such as `office.toml`",
            builtin_names()
        ),
    )
}

/// How to fix a world file that cannot be read.
pub fn read_help() -> String {
    format!("check the path of the world file, or use a built-in world ({})", builtin_names())
}

/// The world in `text`, the world file `file` (named `stem` when the file gives no
/// `name`); an error names the file, line and column: ``office.toml:5:4: unknown
/// character `o` in the map``.
pub fn from_file(text: &str, file: &str, stem: &str) -> Result<GridWorld, Problem> {
    GridWorld::from_toml(text, stem).map_err(|e| {
        let at = e.span.as_ref().map_or(String::new(), |span| {
            let p = LineIndex::new(text).position(text, span.start);
            format!("{}:{}: ", p.line, p.column)
        });
        Problem::new(format!("{file}:{at}{}", e.message), e.help.clone())
    })
}

/// The built-in worlds' names, quoted and listed.
fn builtin_names() -> String {
    builtin_list()
}

/// How `world` lays tiles along a variable whose `bins` a spec leaves out: the one rule
/// `check` counts by and training lays them by.
pub fn tile_fit(world: &AnyWorld) -> Option<hstl_lang::budget::TileFit> {
    use hstl_lang::budget::TileFit;
    match world {
        AnyWorld::Plane(p) => Some(TileFit::Step(p.step_length())),
        AnyWorld::MountainCar(_) => Some(TileFit::Fixed(hstl_lang::budget::CAR_BINS)),
        AnyWorld::Grid(_) => None,
    }
}
