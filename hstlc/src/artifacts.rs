//! What `train` and `study` write: pictures of a trained agent, the learning curve, and the
//! all-or-nothing write of an output folder.

use std::path::{Path, PathBuf};

use hstl::robustness::{Formula, Trace, reference};
use hstl::runtime::eval::{AgentController, sample_runs};
use hstl::runtime::{Agent, Env, GridWorld, Rng, TaskSpec};
use hstl_pictures as pic;

use hstl::lang::{LetKind, visit_lets};

use crate::cli_error::CliError;
use crate::spec_file::LoadedSpec;

/// A file to write: its name inside the output folder and its bytes.
pub struct OutFile {
    /// The file name, such as `policy.json`.
    pub name: String,
    /// The whole contents.
    pub contents: Vec<u8>,
}

impl OutFile {
    /// A file from text.
    pub fn text(name: impl Into<String>, text: String) -> OutFile {
        OutFile { name: name.into(), contents: text.into_bytes() }
    }
}

/// Writes every file into `dir`, whole or not at all: each goes to a temporary file in
/// `dir` first, and only when all of them are written are they renamed into place. On an
/// error the temporary files are removed and nothing in `dir` has changed.
pub fn write_all(dir: &Path, files: &[OutFile]) -> Result<Vec<PathBuf>, CliError> {
    std::fs::create_dir_all(dir)
        .map_err(|source| CliError::Write { path: dir.to_path_buf(), source })?;
    // A rename can only fail on a target we can see now (a folder in the way): refuse
    // before anything is written, so the renames below all go through.
    for file in files {
        let target = dir.join(&file.name);
        if target.is_dir() {
            return Err(CliError::new(
                format!("cannot write `{}`: a folder of that name is in the way", target.display()),
                Some("move the folder away or choose another `--out`".to_string()),
            ));
        }
    }
    let mut temps: Vec<(PathBuf, PathBuf)> = Vec::with_capacity(files.len());
    let cleanup = |temps: &[(PathBuf, PathBuf)]| {
        for (tmp, _) in temps {
            let _ = std::fs::remove_file(tmp);
        }
    };
    for file in files {
        let target = dir.join(&file.name);
        let tmp = dir.join(format!(".{}.{}.tmp", file.name, std::process::id()));
        if let Err(source) = std::fs::write(&tmp, &file.contents) {
            let _ = std::fs::remove_file(&tmp);
            cleanup(&temps);
            return Err(CliError::Write { path: target, source });
        }
        temps.push((tmp, target));
    }
    for (i, (tmp, target)) in temps.iter().enumerate() {
        if let Err(source) = std::fs::rename(tmp, target) {
            cleanup(&temps[i..]);
            return Err(CliError::Write { path: target.clone(), source });
        }
    }
    Ok(temps.into_iter().map(|(_, target)| target).collect())
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
/// when the agent has memory), and two sample runs, over the world's walls, start cells and
/// `regions` (see [`pictured_regions`]).
pub fn agent_pictures(
    spec: &TaskSpec,
    env: &GridWorld,
    regions: &[(String, Formula)],
    agent: &Agent,
    rng: &mut Rng,
) -> Result<Vec<OutFile>, CliError> {
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
        let title = format!("Flat policy of option {} (terminates on dots)", prim.name);
        let svg = pic::flat_policy(&grid, &title, &arrows, &terminate).map_err(picture_error)?;
        out.push(OutFile::text(format!("flat_{}.svg", file_safe(&prim.name)), svg));
    }
    let names: Vec<String> = spec.options.iter().map(|o| o.name.clone()).collect();
    for (file, title, tau) in option_slices(spec, agent) {
        let choices: Vec<((i64, i64), String)> = cells
            .iter()
            .enumerate()
            .filter_map(|(s, &c)| {
                let o = *agent.options.get(agent.observation(s, &tau))?;
                Some((c, names.get(o)?.clone()))
            })
            .collect();
        let svg = pic::options_policy(&grid, &title, &choices, &names).map_err(picture_error)?;
        out.push(OutFile::text(file, svg));
    }
    let runs = sample_runs(env, &mut AgentController::new(agent), 2, 120, rng);
    for (i, run) in runs.iter().enumerate() {
        let steps: Vec<((i64, i64), String)> = run
            .iter()
            .filter_map(|step| {
                let cell = *cells.get(step.state)?;
                Some((cell, names.get(step.decision.option)?.clone()))
            })
            .collect();
        let title = format!("Sample run {} ({} steps, greedy)", i + 1, run.len());
        let svg = pic::sample_run_ordered(&grid, &title, &steps, &names).map_err(picture_error)?;
        out.push(OutFile::text(format!("run_{}.svg", i + 1), svg));
    }
    Ok(out)
}

/// The learning curve of one or more seeds (a band over seeds), as in the paper's Figure 3.
pub fn curve_picture(title: &str, curves: &[Vec<f64>]) -> Result<OutFile, CliError> {
    let smooth = (curves.first().map_or(0, Vec::len) / 60).max(1);
    let svg = pic::learning_curve(title, curves, smooth).map_err(picture_error)?;
    Ok(OutFile::text("curve.svg", svg))
}

/// The options maps to draw: one without memory; with memory, one per region, as the agent
/// sees the grid right after leaving that region with every other counter expired.
fn option_slices(spec: &TaskSpec, agent: &Agent) -> Vec<(String, String, Vec<usize>)> {
    let horizons: Vec<usize> = spec.regions.iter().map(|r| r.horizon).collect();
    if agent.memory.is_none() || horizons.is_empty() {
        return vec![("options.svg".into(), "Options policy".into(), horizons)];
    }
    spec.regions
        .iter()
        .enumerate()
        .map(|(j, r)| {
            let mut tau = horizons.clone();
            tau[j] = 1;
            (
                format!("options_after_{}.svg", file_safe(&r.name)),
                format!("Options policy one step after {} (others overdue)", r.name),
                tau,
            )
        })
        .collect()
}

/// The grid under every picture: the world's walls and start cells, and the regions.
fn picture_grid(
    env: &GridWorld,
    regions: &[(String, Formula)],
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
            .map(|(name, f)| pic::Region { name: name.clone(), cells: holding(f, states, cells) })
            .collect(),
        walls,
        starts,
    }
}

/// The regions a picture shows: each option's region (named by the option), then every
/// state `let` the task names, directly or through temporal lets (an obstacle in
/// `always !Obstacle`, say). Lets used only inside other state lets are not drawn.
pub fn pictured_regions(loaded: &LoadedSpec) -> Result<Vec<(String, Formula)>, CliError> {
    let spec = &loaded.spec;
    let lower_err =
        |e: hstl::lower::LowerError| CliError::new(format!("{}: {e}", loaded.file), None);
    let mut out: Vec<(String, Formula)> = Vec::new();
    for p in &spec.primitives {
        let f = hstl::lower::formula(spec, &p.reach).ok_or_else(|| {
            lower_err(hstl::lower::LowerError::Invalid { spec: spec.name.clone() })
        })?;
        out.push((p.name.clone(), f));
    }
    let mut drawn: Vec<Formula> = out.iter().map(|(_, f)| f.clone()).collect();
    let mut stack = Vec::new();
    let mut seen = vec![false; spec.lets.len()];
    if let Some(task) = &spec.task {
        visit_lets(&task.formula, &mut |i| stack.push(i));
    }
    // Depth first, so that lets come out in the order the task names them.
    stack.reverse();
    while let Some(i) = stack.pop() {
        let Some(l) = spec.lets.get(i) else { continue };
        if std::mem::replace(&mut seen[i], true) {
            continue;
        }
        match l.kind {
            LetKind::Temporal => {
                let mut inner = Vec::new();
                visit_lets(&l.formula, &mut |j| inner.push(j));
                stack.extend(inner.into_iter().rev());
            }
            LetKind::State => {
                let f = hstl::lower::let_formula(spec, &l.name).map_err(lower_err)?;
                // An option's region drawn already under the option's name.
                if !drawn.contains(&f) {
                    drawn.push(f.clone());
                    out.push((l.name.clone(), f));
                }
            }
        }
    }
    Ok(out)
}

/// `(x, y)` of every state index.
fn cells(env: &GridWorld) -> Vec<(i64, i64)> {
    (0..env.num_states())
        .map(|s| env.state(s).map_or((-1, -1), |c| (c.x as i64, c.y as i64)))
        .collect()
}

/// Every state of `env` as one step of a trace (step `s` is state index `s`), in the
/// spec's variable order.
pub fn state_trace(spec: &TaskSpec, env: &GridWorld) -> Result<Trace, CliError> {
    let env_vars = env.state_vars();
    let picks = spec
        .state_vars
        .iter()
        .map(|v| {
            env_vars.iter().position(|e| *e == v.name).ok_or_else(|| {
                CliError::new(
                    format!(
                        "state variable `{}` is not one of the {} environment's",
                        v.name,
                        env.name()
                    ),
                    Some(format!("the environment has {}", env_vars.join(", "))),
                )
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut columns = vec![Vec::with_capacity(env.num_states()); picks.len()];
    let mut row = Vec::new();
    for s in 0..env.num_states() {
        let Some(state) = env.state(s) else { continue };
        env.valuation(&state, &mut row);
        for (col, &i) in columns.iter_mut().zip(&picks) {
            col.push(row.get(i).copied().unwrap_or(f64::NAN));
        }
    }
    Trace::from_columns(columns).map_err(|e| CliError::new(e.to_string(), None))
}

/// The cells where the state formula `f` holds.
fn holding(f: &Formula, states: &Trace, cells: &[(i64, i64)]) -> Vec<(i64, i64)> {
    (0..states.len())
        .filter(|&s| reference::robustness(f, states, s) > 0.0)
        .map(|s| cells[s])
        .collect()
}

/// A name fit for a file name: letters, digits, `-` and `_` kept, the rest `_`.
pub fn file_safe(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect()
}

fn picture_error(e: pic::PictureError) -> CliError {
    CliError::new(format!("cannot draw a picture: {e}"), None)
}
