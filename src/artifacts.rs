//! What a trained agent's output folder holds, as plain data: the pictures of the paper's
//! Figures 2 and 3 (flat policies, the options policy, sample runs, the learning curve) and
//! the learning curve as CSV, each an [`OutFile`] (a name and its bytes). `hstlc train`,
//! `hstlc study` and the Python package's `hstl.study` make their files here and write them
//! through `hstl-outdir`, so the folders they write are the same, byte for byte.

use std::path::Path;

use hstl_lang::{CFormula, CFormulaKind, CheckedSpec, LetKind};
use hstl_pictures as pic;
use hstl_robustness::{Formula, Trace, reference};
use hstl_runtime::eval::{AgentController, sample_runs};
use hstl_runtime::{Agent, Env, GridWorld, Rng, TaskSpec};

use crate::Problem;

pub use crate::outfile::OutFile;

/// What the pictures of a trained agent say about where they come from.
#[derive(Clone, Debug)]
pub struct Captions {
    /// What was trained, leading every title: the spec's file name, or a variant of it.
    pub subject: String,
    /// The line under every title: which seed, and why that one.
    pub note: String,
}

/// A region a picture draws: its name, where it holds, and what it is to the task.
#[derive(Clone, Debug)]
pub struct PicturedRegion {
    /// The option's or the `let`'s name.
    pub name: String,
    /// The state formula that holds on the region's cells.
    pub formula: Formula,
    /// A region to reach (an option's), to avoid (negated in the task), or another.
    pub kind: pic::RegionKind,
}

/// Why a world gets no grid pictures, if it is too large to draw.
pub fn too_large_to_draw(env: &GridWorld) -> Option<String> {
    let side = pic::MAX_GRID_SIDE;
    (env.width() > side || env.height() > side).then(|| {
        format!(
            "no grid pictures: the world is {} x {} cells, and pictures are drawn up to {side} a side",
            env.width(),
            env.height()
        )
    })
}

/// What the pictures of a spec file name it by: the file's name without its folders, and
/// the spec's name when one was picked from a file of several.
pub fn subject(file: &str, spec: Option<&str>) -> String {
    let name =
        Path::new(file).file_name().map_or(file.to_owned(), |n| n.to_string_lossy().into_owned());
    match spec {
        Some(spec) => format!("{name}, spec {spec}"),
        None => name,
    }
}

/// `episode,reward` rows, episodes counted from 1.
pub fn curve_csv(curve: &[f64]) -> String {
    let mut out = String::from("episode,reward\n");
    for (e, r) in curve.iter().enumerate() {
        out.push_str(&format!("{},{r}\n", e + 1));
    }
    out
}

/// The paper's Figure 2 for a trained agent in a grid world: one arrow field per primitive
/// option with its termination states, the options policy (one map per region visited last
/// when the agent has memory), and two sample runs with their slips, over the world's
/// walls, start cells and `regions` (see [`pictured_regions`]); every title names
/// `captions.subject`, with `captions.note` under it.
pub fn agent_pictures(
    spec: &TaskSpec,
    env: &GridWorld,
    regions: &[PicturedRegion],
    agent: &Agent,
    captions: &Captions,
    rng: &mut Rng,
) -> Result<Vec<OutFile>, Problem> {
    let title = |what: &str| format!("{}: {what}\n{}", captions.subject, captions.note);
    let cells = cells(env);
    let states = state_trace(spec, env)?;
    let grid = picture_grid(env, regions, &states, &cells);
    let actions = env.actions();
    let action = |a: usize| match actions.get(a).map(String::as_str) {
        Some("Up") => Some(pic::Action::Up),
        Some("Down") => Some(pic::Action::Down),
        Some("Left") => Some(pic::Action::Left),
        Some("Right") => Some(pic::Action::Right),
        _ => None,
    };
    let mut out = Vec::new();
    for (p, prim) in spec.primitives.iter().enumerate() {
        let arrows: Vec<pic::Cell> = cells
            .iter()
            .enumerate()
            .filter_map(|(s, &(x, y))| {
                action(*agent.flat.get(p)?.get(s)?).map(|action| pic::Cell { x, y, action })
            })
            .collect();
        let terminate: Vec<(i64, i64)> = cells
            .iter()
            .enumerate()
            .filter(|&(s, _)| agent.terminate.get(p).and_then(|t| t.get(s)).copied() == Some(true))
            .map(|(_, &c)| c)
            .collect();
        let title = title(&format!("flat policy of option {}", prim.name));
        let svg = pic::flat_policy(&grid, &title, &arrows, &terminate).map_err(picture_error)?;
        out.push(OutFile::text(format!("flat_{}.svg", file_safe(&prim.name)), svg));
    }
    let names: Vec<String> = spec.options.iter().map(|o| o.name.clone()).collect();
    for (file, what, tau, met) in option_slices(spec, agent) {
        let choices: Vec<((i64, i64), String)> = cells
            .iter()
            .enumerate()
            .filter_map(|(s, &c)| {
                let o = *agent.options.get(agent.observation(s, &tau, met))?;
                Some((c, names.get(o)?.clone()))
            })
            .collect();
        let svg =
            pic::options_policy(&grid, &title(&what), &choices, &names).map_err(picture_error)?;
        out.push(OutFile::text(file, svg));
    }
    let runs = sample_runs(env, &mut AgentController::new(agent), 2, RUN_STEPS, rng);
    for (i, run) in runs.iter().enumerate() {
        let steps = run_steps(env, &cells, &names, run);
        let title = format!(
            "{}: sample run {}\n{}; {} steps of the greedy policy",
            captions.subject,
            i + 1,
            captions.note,
            run.len()
        );
        let svg = pic::sample_run(&grid, &title, &steps, &names).map_err(picture_error)?;
        out.push(OutFile::text(format!("run_{}.svg", i + 1), svg));
    }
    uniquify(&mut out);
    Ok(out)
}

/// Steps of each sample run.
const RUN_STEPS: usize = 120;

/// A rollout as the picture's steps: each state's cell, its option, and the cell its action
/// leads to without a slip; then the cell the last action led to.
fn run_steps(
    env: &GridWorld,
    cells: &[(i64, i64)],
    names: &[String],
    run: &[hstl_runtime::eval::Step],
) -> Vec<pic::RunStep> {
    let cell = |s: usize| cells.get(s).copied().unwrap_or((-1, -1));
    let name = |o: usize| names.get(o).cloned().unwrap_or_default();
    let mut steps: Vec<pic::RunStep> = run
        .iter()
        .map(|step| pic::RunStep {
            cell: cell(step.state),
            option: name(step.decision.option),
            intended: Some(cell(env.dest(step.state, step.decision.action))),
        })
        .collect();
    if let Some(last) = run.last() {
        steps.push(pic::RunStep {
            cell: cell(last.next),
            option: name(last.decision.option),
            intended: None,
        });
    }
    steps
}

/// The learning curve of one or more seeds (a band over seeds), as in the paper's Figure 3.
pub fn curve_picture(title: &str, curves: &[Vec<f64>]) -> Result<OutFile, Problem> {
    let smooth = (curves.first().map_or(0, Vec::len) / 60).max(1);
    let svg = pic::learning_curve(title, curves, smooth).map_err(picture_error)?;
    Ok(OutFile::text("curve.svg", svg))
}

/// The options maps to draw, as (file, what the map shows, memory, goals met): one
/// without memory; with goals, one before any goal is met and one once all are; with
/// memory, one per region, as the agent sees the grid right after leaving that region with
/// every other counter expired.
fn option_slices(spec: &TaskSpec, agent: &Agent) -> Vec<(String, String, Vec<usize>, usize)> {
    let horizons: Vec<usize> = spec.regions.iter().map(|r| r.horizon).collect();
    if let Some(g) = &agent.goals {
        return vec![
            ("options.svg".into(), "options policy before any goal is met".into(), Vec::new(), 0),
            (
                "options_goals_met.svg".into(),
                "options policy once every goal is met".into(),
                Vec::new(),
                g.progress.all_met(),
            ),
        ];
    }
    if agent.memory.is_none() || horizons.is_empty() {
        return vec![("options.svg".into(), "options policy".into(), horizons, 0)];
    }
    // A one-step window (a safety conjunct `always !S` is the region `!S` so) is kept where
    // the state is: every map shows it kept, and none is drawn after it.
    let kept_now: Vec<usize> = horizons.iter().map(|&n| if n == 1 { 0 } else { n }).collect();
    spec.regions
        .iter()
        .enumerate()
        .filter(|(_, r)| r.horizon > 1)
        .map(|(j, r)| {
            let mut tau = kept_now.clone();
            tau[j] = 1;
            (
                format!("options_after_{}.svg", file_safe(&r.name)),
                format!("options policy one step after {} (others overdue)", r.name),
                tau,
                0,
            )
        })
        .collect()
}

/// The grid under every picture: the world's walls and start cells, and the regions.
fn picture_grid(
    env: &GridWorld,
    regions: &[PicturedRegion],
    states: &Trace,
    cells: &[(i64, i64)],
) -> pic::Grid {
    let (w, h) = (env.width() as i64, env.height() as i64);
    let walls = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .filter(|&(x, y)| !env.is_free(x as usize, y as usize))
        .collect();
    let starts = if env.has_start_cells() {
        env.starts().into_iter().filter_map(|s| cells.get(s).copied()).collect()
    } else {
        Vec::new()
    };
    pic::Grid {
        width: env.width(),
        height: env.height(),
        regions: regions
            .iter()
            .map(|r| pic::Region {
                name: r.name.clone(),
                cells: holding(&r.formula, states, cells),
                kind: r.kind,
            })
            .collect(),
        walls,
        starts,
    }
}

/// The regions a picture shows: each option's region (named by the option, to reach), then
/// every state `let` the task names, directly or through temporal lets: to avoid when the
/// task only negates it (an obstacle in `always !Obstacle`), another region otherwise.
/// Lets used only inside other state lets are not drawn.
pub fn pictured_regions(spec: &CheckedSpec, file: &str) -> Result<Vec<PicturedRegion>, Problem> {
    let lower_err = |e: crate::lower::LowerError| Problem::new(format!("{file}: {e}"), None);
    let mut out: Vec<PicturedRegion> = Vec::new();
    for p in &spec.primitives {
        let formula = crate::lower::formula(spec, &p.reach).ok_or_else(|| {
            lower_err(crate::lower::LowerError::Invalid { spec: spec.name.clone() })
        })?;
        out.push(PicturedRegion { name: p.name.clone(), formula, kind: pic::RegionKind::Reach });
    }
    for (i, negated_only) in task_lets(spec) {
        let Some(l) = spec.lets.get(i) else { continue };
        let formula = crate::lower::let_formula(spec, &l.name).map_err(lower_err)?;
        // An option's region drawn already under the option's name.
        if out.iter().any(|r| r.formula == formula) {
            continue;
        }
        let kind = if negated_only { pic::RegionKind::Avoid } else { pic::RegionKind::Other };
        out.push(PicturedRegion { name: l.name.clone(), formula, kind });
    }
    // The regions the legs keep out of (`avoid:`), when the task does not name them.
    for p in &spec.primitives {
        let Some(avoid) = &p.avoid else { continue };
        let parts = match &avoid.kind {
            CFormulaKind::Or(parts) => parts.iter().collect(),
            _ => vec![avoid],
        };
        for part in parts {
            let Some(formula) = crate::lower::formula(spec, part) else { continue };
            if out.iter().any(|r| r.formula == formula) {
                continue;
            }
            let name = match part.kind {
                CFormulaKind::Let(i) => spec.lets.get(i).map_or("avoid".into(), |l| l.name.clone()),
                _ => "avoid".into(),
            };
            out.push(PicturedRegion { name, formula, kind: pic::RegionKind::Avoid });
        }
    }
    Ok(out)
}

/// The state lets the task names, directly or through temporal lets, in the order it names
/// them, each with whether the task only ever negates it (under an odd number of `!`,
/// outside the left side of any `->`, which neither requires nor forbids it).
fn task_lets(spec: &CheckedSpec) -> Vec<(usize, bool)> {
    // Per let: seen other than negated, seen negated.
    let mut seen = vec![(false, false); spec.lets.len()];
    let mut order = Vec::new();
    let Some(task) = &spec.task else { return Vec::new() };
    // `Some(negated)`, or `None` on the left of `->`. Depth first with an explicit stack (a
    // deep formula must not overflow the call stack), children pushed in reverse so that
    // lets come out in source order.
    let mut stack: Vec<(&CFormula, Option<bool>)> = vec![(&task.formula, Some(false))];
    while let Some((f, negated)) = stack.pop() {
        match &f.kind {
            CFormulaKind::Let(i) => {
                let (Some(l), Some(flags)) = (spec.lets.get(*i), seen.get_mut(*i)) else {
                    continue;
                };
                let first = *flags == (false, false);
                let flag = if negated == Some(true) { &mut flags.1 } else { &mut flags.0 };
                let again = std::mem::replace(flag, true);
                match l.kind {
                    LetKind::State if first => order.push(*i),
                    LetKind::State => {}
                    LetKind::Temporal if !again => stack.push((&l.formula, negated)),
                    LetKind::Temporal => {}
                }
            }
            CFormulaKind::Not(a) => stack.push((a, negated.map(|n| !n))),
            CFormulaKind::Implies(a, b) => {
                stack.push((b, negated));
                stack.push((a, None));
            }
            // Every other operand keeps the polarity; pushed last first, to visit in order.
            _ => stack.extend(f.operands().into_iter().rev().map(|g| (g, negated))),
        }
    }
    order.into_iter().map(|i| (i, seen[i] == (false, true))).collect()
}

/// `(x, y)` of every state index.
fn cells(env: &GridWorld) -> Vec<(i64, i64)> {
    (0..env.num_states())
        .map(|s| env.state(s).map_or((-1, -1), |c| (c.x as i64, c.y as i64)))
        .collect()
}

/// Every state of `env` as one step of a trace (step `s` is state index `s`), in the
/// spec's variable order (the facade's, which `eval` uses too).
pub fn state_trace(spec: &TaskSpec, env: &GridWorld) -> Result<Trace, Problem> {
    crate::evaluate::state_trace(spec, env)
}

/// The cells where the state formula `f` holds.
fn holding(f: &Formula, states: &Trace, cells: &[(i64, i64)]) -> Vec<(i64, i64)> {
    (0..states.len())
        .filter(|&s| reference::robustness(f, states, s) > 0.0)
        .map(|s| cells[s])
        .collect()
}

/// A name fit for a file name: letters, digits, `-` and `_` kept, the rest `_`, at most 64
/// characters (names are at most 64 characters; an inline region's formula may be longer).
pub fn file_safe(name: &str) -> String {
    name.chars()
        .take(64)
        .map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' })
        .collect()
}

/// Makes the names of `files` unique, ignoring case (as a case-insensitive file system
/// would): a later file whose name is taken gets `_2`, `_3`, ... before its extension. Two
/// inline regions such as `x > 3` and `x < 3` both read `x___3`.
fn uniquify(files: &mut [OutFile]) {
    let mut taken = std::collections::HashSet::new();
    for f in files {
        if taken.insert(f.name.to_lowercase()) {
            continue;
        }
        let (stem, ext) = match f.name.rsplit_once('.') {
            Some((s, e)) => (s.to_string(), format!(".{e}")),
            None => (f.name.clone(), String::new()),
        };
        let mut k = 2;
        while !taken.insert(format!("{stem}_{k}{ext}").to_lowercase()) {
            k += 1;
        }
        f.name = format!("{stem}_{k}{ext}");
    }
}

fn picture_error(e: pic::PictureError) -> Problem {
    Problem::new(format!("cannot draw a picture: {e}"), None)
}

/// The pictures of a policy learned on a continuous world (see [`crate::continuous`]), as
/// the grid's [`agent_pictures`] names them: `flat_{OPTION}.svg` (each primitive option's
/// greedy action on a lattice of points, with the points where it terminates),
/// `options.svg` (the option picked over the extent; with memory, one map per region, as
/// the agent sees the world one step after leaving it with every other counter expired, all
/// in this one picture) and `run_1.svg`, `run_2.svg` (greedy runs from the world's starts,
/// drawn from `seed ^ PICTURE_SEED`, with their slips, blocked moves and region entries).
///
/// A plane world is drawn to scale with its obstacles and start area; `mountain-car` as its
/// `(x, v)` phase plane. Regions are the spec's state formulas (see [`pictured_regions`])
/// sampled at the centres of a fine raster. A slip is inferred from the step data: the
/// move's direction lies nearer another heading than the one chosen (with noise this is a
/// reading, not a record); a blocked move is one after which the robot stayed exactly
/// where it was.
pub fn plane_pictures(
    spec: &hstl_runtime::TaskSpec,
    world: &hstl_runtime::world::AnyWorld,
    checked: &CheckedSpec,
    agent: &hstl_runtime::approx::ApproxAgent,
    subject: &str,
    seed: u64,
) -> Result<Vec<OutFile>, Problem> {
    use hstl_runtime::world::AnyWorld;
    let m = &agent.model;
    let note = format!("seed {seed}");
    let title = |what: &str| format!("{subject}: {what}\n{note}");
    let regions = pictured_regions(checked, subject)?;
    let mut plane = match world {
        AnyWorld::Plane(w) => plane_frame(w),
        AnyWorld::MountainCar(_) => {
            use hstl_runtime::MountainCar as Car;
            let mut p = pic::Plane::new(
                [Car::MIN_POSITION, Car::MAX_POSITION],
                [-Car::MAX_SPEED, Car::MAX_SPEED],
            );
            p.to_scale = false;
            p
        }
        AnyWorld::Grid(_) => {
            return Err(Problem::new("a grid world is drawn by its own pictures", None));
        }
    };
    if let [x, y] = m.vars.as_slice() {
        plane.x_label = x.clone();
        plane.y_label = y.clone();
    } else {
        return Err(Problem::new(
            format!("cannot draw a world of {} state variables on a plane", m.vars.len()),
            None,
        ));
    }
    let (columns, rows) = raster_size(&plane);
    let mut eval = hstl_robustness::StateEval::new();
    for r in &regions {
        let holds = pic::Raster::from_fn(columns, rows, |i, j| {
            let (x, y) = plane.centre(columns, rows, i, j);
            eval.value(&r.formula, &[x, y]) > 0.0
        })
        .map_err(picture_error)?;
        plane.regions.push(pic::PlaneRegion { name: r.name.clone(), kind: r.kind, holds });
    }
    let mut out = Vec::new();

    // Flat policies: the greedy action on a lattice of free points.
    let (lx, ly) = arrow_lattice(world, &plane);
    let lattice: Vec<(f64, f64)> = plane
        .lattice(lx, ly)
        .map_err(picture_error)?
        .into_iter()
        .filter(|&(x, y)| match world {
            AnyWorld::Plane(w) => w.is_free(hstl_runtime::plane::Point { x, y }),
            _ => true,
        })
        .collect();
    let direction = |a: usize| -> Option<(f64, f64)> {
        match world {
            AnyWorld::Plane(w) => w.heading(a),
            _ => match a {
                0 => Some((-1.0, 0.0)),
                2 => Some((1.0, 0.0)),
                _ => None,
            },
        }
    };
    // The agent never takes a move the world blocks: neither do the arrows.
    let blocked = |x: f64, y: f64, out: &mut Vec<bool>| match world {
        AnyWorld::Plane(w) => m.blocked(w, &hstl_runtime::plane::Point { x, y }, out),
        _ => {
            out.clear();
            out.resize(m.actions, false);
        }
    };
    let (mut f, mut scratch, mut mask) = (Vec::new(), Vec::new(), Vec::new());
    for (p, prim) in spec.primitives.iter().enumerate() {
        let mut arrows = Vec::with_capacity(lattice.len());
        let mut terminate = Vec::new();
        for &(x, y) in &lattice {
            m.flat_coder.features(&[x, y], &mut f);
            blocked(x, y, &mut mask);
            let a = m.greedy_action(&agent.weights, p, &f, &mask, &mut scratch);
            arrows.push(pic::Arrow { x, y, direction: direction(a) });
            if let hstl_runtime::spec::Terminate::Formula(stop) = &prim.terminate
                && eval.value(stop, &[x, y]) > 0.0
            {
                terminate.push((x, y));
            }
        }
        let title = title(&format!("flat policy of option {}", prim.name));
        let svg =
            pic::plane_flat_policy(&plane, &title, &arrows, &terminate).map_err(picture_error)?;
        out.push(OutFile::text(format!("flat_{}.svg", file_safe(&prim.name)), svg));
    }

    // The options policy, one map per memory slice.
    let names: Vec<String> = spec.options.iter().map(|o| o.name.clone()).collect();
    let horizons: Vec<usize> = m.horizons().collect();
    let slices: Vec<(String, Vec<usize>, usize)> = if let Some(progress) = &m.progress {
        // A task with goals: before any is met, and once every one is.
        vec![
            ("before the goal".to_string(), horizons.clone(), 0),
            ("once the goal is met".to_string(), horizons.clone(), progress.all_met()),
        ]
    } else if m.buckets == 0 || horizons.is_empty() {
        vec![(String::new(), horizons.clone(), 0)]
    } else {
        spec.regions
            .iter()
            .enumerate()
            .map(|(j, r)| {
                let mut tau = horizons.clone();
                tau[j] = 1;
                (format!("one step after {}", r.name), tau, 0)
            })
            .collect()
    };
    let (mut g, mut available) = (Vec::new(), Vec::new());
    let mut maps = Vec::with_capacity(slices.len());
    for (label, tau, met) in &slices {
        let code = m.code(tau, *met);
        let choices = pic::Raster::from_fn(columns, rows, |i, j| {
            let (x, y) = plane.centre(columns, rows, i, j);
            m.available(&mut eval, &[x, y], &mut available);
            m.options_coder.features(&[x, y], &mut g);
            Some(m.best_option(&agent.weights, code, &g, &available))
        })
        .map_err(picture_error)?;
        maps.push(pic::PlaneSlice { label: label.clone(), choices });
    }
    let what = match (maps.len(), &m.progress) {
        (1, _) => "options policy",
        (_, Some(_)) => "options policy before and after the goal",
        _ => "options policy by memory (others overdue)",
    };
    let svg =
        pic::plane_options_policy(&plane, &title(what), &maps, &names).map_err(picture_error)?;
    out.push(OutFile::text("options.svg", svg));

    // Sample runs of the greedy policy.
    let steps = plane_run_steps(spec, m);
    let mut rng = hstl_runtime::seeded_rng(seed ^ crate::seeds::PICTURE_SEED);
    for k in 1..=2 {
        let run = match world {
            AnyWorld::Plane(w) => {
                let start = hstl_runtime::World::reset(w, &mut rng);
                agent.run(w, start, steps, &mut rng)
            }
            AnyWorld::MountainCar(w) => {
                let start = hstl_runtime::World::reset(w, &mut rng);
                agent.run(w, start, steps, &mut rng)
            }
            AnyWorld::Grid(_) => {
                return Err(Problem::new("a grid world is drawn by its own pictures", None));
            }
        };
        let picture_steps = picture_run(world, &regions, &run, &mut eval);
        let title = format!(
            "{subject}: sample run {k}\n{note}; {} steps of the greedy policy",
            run.actions.len()
        );
        let svg =
            pic::plane_sample_run(&plane, &title, &picture_steps, &names).map_err(picture_error)?;
        out.push(OutFile::text(format!("run_{k}.svg"), svg));
    }
    uniquify(&mut out);
    Ok(out)
}

/// The frame of a plane world: its extent, obstacles and start area (none when episodes
/// start anywhere).
fn plane_frame(w: &hstl_runtime::PlaneWorld) -> pic::Plane {
    use hstl_runtime::plane::Obstacle;
    let (x, y) = w.extent();
    let mut plane = pic::Plane::new(x, y);
    plane.obstacles = w
        .obstacles()
        .iter()
        .map(|o| match *o {
            Obstacle::Circle { cx, cy, r } => pic::Shape::Circle { cx, cy, r },
            Obstacle::Rect { x0, y0, x1, y1 } => pic::Shape::Rect { x0, y0, x1, y1 },
        })
        .collect();
    let start = w.start();
    plane.start = (start != [x[0], y[0], x[1], y[1]]).then_some(start);
    plane
}

/// Raster cells along each axis for regions and options maps: about four pixels each on a
/// lone map, the longer side 150.
fn raster_size(plane: &pic::Plane) -> (usize, usize) {
    const SIDE: f64 = 150.0;
    if !plane.to_scale {
        return (160, 120);
    }
    let (w, h) = (plane.x[1] - plane.x[0], plane.y[1] - plane.y[0]);
    let long = w.max(h);
    let n = |v: f64| ((SIDE * v / long).round() as usize).clamp(30, 150);
    (n(w), n(h))
}

/// Arrows along each axis: one per step of a plane world (between 2 and 40), a fixed
/// lattice on `mountain-car`.
fn arrow_lattice(world: &hstl_runtime::world::AnyWorld, plane: &pic::Plane) -> (usize, usize) {
    match world {
        hstl_runtime::world::AnyWorld::Plane(w) => {
            let n = |[lo, hi]: [f64; 2]| {
                let k = ((hi - lo) / w.step_length()).round();
                if k.is_finite() { (k as usize).clamp(2, 40) } else { 2 }
            };
            (n(plane.x), n(plane.y))
        }
        _ => (18, 14),
    }
}

/// Steps of each sample run on a continuous world: twice the longest window of a
/// persistent task (at least 120), the task's horizon and one otherwise (120 for a task
/// without one); at most 400, which a picture still shows.
fn plane_run_steps(spec: &TaskSpec, m: &hstl_runtime::approx::Model) -> usize {
    let steps = match m.horizons().max() {
        Some(h) => h.saturating_mul(2).max(RUN_STEPS),
        None => spec.task.horizon().map_or(RUN_STEPS, |h| h.saturating_add(1)),
    };
    steps.clamp(20, 400)
}

/// A greedy run as the picture's steps: each position, its option, what happened to its
/// move (a plane's blocked moves and slips, inferred from the positions), where the chosen
/// heading leads without slip or noise, and the regions entered there.
fn picture_run(
    world: &hstl_runtime::world::AnyWorld,
    regions: &[PicturedRegion],
    run: &hstl_runtime::approx::GreedyRun,
    eval: &mut hstl_robustness::StateEval,
) -> Vec<pic::PlaneStep> {
    let points: Vec<(f64, f64)> = run.values.chunks_exact(2).map(|c| (c[0], c[1])).collect();
    let mut before: Vec<bool> = Vec::new();
    let mut steps = Vec::with_capacity(points.len());
    for (t, &(x, y)) in points.iter().enumerate() {
        let holds: Vec<bool> =
            regions.iter().map(|r| eval.value(&r.formula, &[x, y]) > 0.0).collect();
        let entered = if t == 0 {
            Vec::new()
        } else {
            (0..regions.len()).filter(|&r| holds[r] && !before[r]).collect()
        };
        before = holds;
        let mut step =
            pic::PlaneStep { entered, ..pic::PlaneStep::at(x, y, run.options.get(t).copied()) };
        if let (hstl_runtime::world::AnyWorld::Plane(w), Some(&a), Some(&(nx, ny))) =
            (world, run.actions.get(t), points.get(t + 1))
            && let Some((ux, uy)) = w.heading(a)
        {
            let length = w.step_length();
            step.intended = Some((x + length * ux, y + length * uy));
            let (dx, dy) = (nx - x, ny - y);
            step.outcome = if dx == 0.0 && dy == 0.0 {
                pic::Outcome::Blocked
            } else {
                let nearest = (0..w.headings())
                    .filter_map(|k| w.heading(k).map(|(hx, hy)| (k, hx * dx + hy * dy)))
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                    .map(|(k, _)| k);
                if nearest == Some(a) { pic::Outcome::AsChosen } else { pic::Outcome::Slipped }
            };
        }
        steps.push(step);
    }
    steps
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(task: &str) -> Vec<(String, pic::RegionKind)> {
        let source = format!(
            "spec Kinds {{\n    state {{ x: int in 0..=14, y: int in 0..=14 }}\n    \
             let Goal = x > 11 && y > 11;\n    let Obstacle = x > 5 && x < 9 && y > 4 && y < 10;\n    \
             let Pit = x < 2 && y < 2;\n    let Zone = x > 11 && y < 3;\n    \
             let Near = x < 3 && y > 11;\n    let Both = x > 3 && x < 5 && y < 3;\n    \
             let Safe = always[0..20] !Obstacle;\n    task {task};\n    \
             option Goal;\n    options {{ Goal }}\n}}\n"
        );
        let world = GridWorld::builtin("paper").expect("paper");
        let loaded = crate::load::load_in_world(&source, None, &world, "world `paper`")
            .unwrap_or_else(|e| panic!("{e}"));
        pictured_regions(&loaded.spec, "kinds.hstl")
            .expect("regions")
            .into_iter()
            .map(|r| (r.name, r.kind))
            .collect()
    }

    #[test]
    fn lets_the_task_only_negates_are_regions_to_avoid() {
        use pic::RegionKind::{Avoid, Other, Reach};
        let named = |list: &[(&str, pic::RegionKind)]| -> Vec<(String, pic::RegionKind)> {
            list.iter().map(|(n, k)| ((*n).to_owned(), *k)).collect()
        };
        // Through a temporal let and under `until`, beside a let on the left of `->` (not
        // forbidden), one named positively and one named both ways.
        let task = "eventually[0..40] Goal && Safe && (!Pit until[0..40] Goal) \
                    && (Near -> eventually[0..10] Zone) && eventually[0..5] Both && always[0..5] !Both";
        assert_eq!(
            kinds(task),
            named(&[
                ("Goal", Reach),
                ("Obstacle", Avoid),
                ("Pit", Avoid),
                ("Near", Other),
                ("Zone", Other),
                ("Both", Other)
            ])
        );
        // `!!Pit` is Pit itself.
        assert_eq!(
            kinds("eventually[0..40] Goal && always[0..5] !!Pit"),
            named(&[("Goal", Reach), ("Pit", Other)])
        );
    }

    #[test]
    fn a_region_only_an_option_avoids_is_a_region_to_avoid() {
        let source = "spec Legs {\n    state { x: int in 0..=14, y: int in 0..=14 }\n    \
                      let Goal = x > 11 && y > 11;\n    let Pit = x < 2 && y < 2;\n    \
                      let Pond = x > 5 && x < 9 && y > 5 && y < 9;\n    \
                      task eventually[0..40] Goal;\n    option Goal { avoid: Pit || Pond }\n}\n";
        let world = GridWorld::builtin("paper").expect("paper");
        let loaded = crate::load::load_in_world(source, None, &world, "world `paper`")
            .unwrap_or_else(|e| panic!("{e}"));
        let got: Vec<(String, pic::RegionKind)> = pictured_regions(&loaded.spec, "legs.hstl")
            .expect("regions")
            .into_iter()
            .map(|r| (r.name, r.kind))
            .collect();
        use pic::RegionKind::{Avoid, Reach};
        let want = [("Goal", Reach), ("Pit", Avoid), ("Pond", Avoid)];
        assert_eq!(got, want.map(|(n, k)| (n.to_owned(), k)).to_vec());
    }
}
