//! What `train` and `study` write: pictures of a trained agent, the learning curve, and the
//! all-or-nothing write of an output folder ([`OutDir`]).

use std::path::{Path, PathBuf};

use hstl::robustness::{Formula, Trace, reference};
use hstl::runtime::eval::{AgentController, sample_runs};
use hstl::runtime::{Agent, Env, GridWorld, Rng, TaskSpec};
use hstl_pictures as pic;

use hstl::lang::{CFormula, CFormulaKind, CheckedSpec, LetKind};

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

/// The file that marks a folder as one run's output: a later run may replace the folder.
pub const MARKER: &str = ".hstlc-run";

/// An output folder that this run holds (see [`OutDir::lock`]) and will write whole.
///
/// The files go to a hidden sibling folder first, each one synced to disk; then the folder
/// is synced and renamed into place. A folder an earlier run wrote is moved aside just
/// before and removed just after, so at every moment `dir` is the old run's folder, no
/// folder, or the new run's folder, never a mix. A run killed on the way leaves only hidden
/// siblings (`.NAME.tmp-*`, `.NAME.old-*`), which the next run into `dir` removes. Another
/// run into the same folder is refused while this one holds it: the lock is the operating
/// system's lock on `.NAME.lock` beside the folder, released when the process ends however
/// it ends, so a killed run leaves no stale lock.
pub struct OutDir {
    dir: PathBuf,
    parent: PathBuf,
    name: String,
    /// Holds the lock while this value lives.
    _lock: std::fs::File,
}

impl OutDir {
    /// Takes the folder `dir` for this run: refuses it when another run holds it, or when
    /// it holds files no run writes (it will be replaced as a whole). Call it before the
    /// long work, so that a refusal comes at once.
    pub fn lock(dir: &Path) -> Result<OutDir, CliError> {
        let write_err = |path: &Path| {
            let path = path.to_path_buf();
            move |source| CliError::Write { path, source }
        };
        // `--out .`, or a symbolic link: the folder it names.
        let dir = if dir.file_name().is_none() || dir.is_symlink() {
            std::fs::canonicalize(dir).map_err(write_err(dir))?
        } else {
            dir.to_path_buf()
        };
        let name = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let parent = match dir.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent).map_err(write_err(&dir))?;
        let lock_path = parent.join(format!(".{name}.lock"));
        let lock = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(&lock_path)
            .map_err(write_err(&lock_path))?;
        match lock.try_lock() {
            Ok(()) => {}
            Err(std::fs::TryLockError::WouldBlock) => {
                return Err(CliError::new(
                    format!("`{}` is being written by another hstlc run", dir.display()),
                    Some("wait for that run to finish, or choose another `--out`".to_string()),
                ));
            }
            // A file system without locks: go on without one.
            Err(std::fs::TryLockError::Error(_)) => {}
        }
        // This run holds the folder: hidden siblings left by killed runs are stale.
        if let Ok(entries) = std::fs::read_dir(&parent) {
            let (tmp, old) = (format!(".{name}.tmp-"), format!(".{name}.old-"));
            for entry in entries.flatten() {
                let n = entry.file_name().to_string_lossy().into_owned();
                if n.starts_with(&tmp) || n.starts_with(&old) {
                    let _ = std::fs::remove_dir_all(entry.path());
                }
            }
        }
        let out = OutDir { dir, parent, name, _lock: lock };
        out.replaceable()?;
        Ok(out)
    }

    /// Writes `files` as the folder, whole or not at all (see [`OutDir`]); the paths
    /// written, in order.
    pub fn write(self, files: &[OutFile]) -> Result<Vec<PathBuf>, CliError> {
        check_names(files)?;
        self.replaceable()?;
        let tmp = unique_sibling(&self.parent, &format!(".{}.tmp-", self.name), true)
            .map_err(|source| CliError::Write { path: self.dir.clone(), source })?;
        let guard = RemoveOnDrop(Some(tmp.clone()));
        for file in files {
            let path = tmp.join(&file.name);
            write_synced(&path, &file.contents)
                .map_err(|source| CliError::Write { path: self.dir.join(&file.name), source })?;
        }
        let marker = "This folder is one run of hstlc, written as a whole; the next run into it \
                      replaces it.\n";
        write_synced(&tmp.join(MARKER), marker.as_bytes())
            .map_err(|source| CliError::Write { path: self.dir.join(MARKER), source })?;
        sync_dir(&tmp);
        let swap_err = |source| CliError::Write { path: self.dir.clone(), source };
        if std::fs::symlink_metadata(&self.dir).is_ok() {
            let old = unique_sibling(&self.parent, &format!(".{}.old-", self.name), false)
                .map_err(swap_err)?;
            std::fs::rename(&self.dir, &old).map_err(swap_err)?;
            if let Err(source) = std::fs::rename(&tmp, &self.dir) {
                // Put the old run back.
                let _ = std::fs::rename(&old, &self.dir);
                return Err(swap_err(source));
            }
            sync_dir(&self.parent);
            let _ = std::fs::remove_dir_all(&old);
        } else {
            std::fs::rename(&tmp, &self.dir).map_err(swap_err)?;
            sync_dir(&self.parent);
        }
        std::mem::forget(guard);
        Ok(files.iter().map(|f| self.dir.join(&f.name)).collect())
    }

    /// The folder to be written.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// Refuses a folder this run may not replace: a file, or a folder holding anything
    /// that is not a run's output (a folder that an older hstlc wrote, before the marker,
    /// holds only files named as a run's).
    fn replaceable(&self) -> Result<(), CliError> {
        let meta = match std::fs::symlink_metadata(&self.dir) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
            Err(source) => return Err(CliError::Write { path: self.dir.clone(), source }),
            Ok(meta) => meta,
        };
        if !meta.is_dir() {
            return Err(CliError::new(
                format!("`{}` is a file, not a folder", self.dir.display()),
                Some("choose another `--out`".to_string()),
            ));
        }
        let entries = std::fs::read_dir(&self.dir)
            .map_err(|source| CliError::Write { path: self.dir.clone(), source })?;
        let mut foreign = Vec::new();
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if name == MARKER {
                return Ok(());
            }
            let is_file = entry.file_type().is_ok_and(|t| t.is_file());
            if !(is_file && is_run_file(&name)) {
                foreign.push(format!("`{name}`"));
            }
        }
        if foreign.is_empty() {
            return Ok(());
        }
        foreign.sort();
        let shown = foreign.len().min(5);
        let more = if foreign.len() > shown {
            format!(" and {} more", foreign.len() - shown)
        } else {
            String::new()
        };
        Err(CliError::new(
            format!(
                "`{}` holds {}{more}, which no hstlc run writes",
                self.dir.display(),
                foreign[..shown].join(", ")
            ),
            Some(
                "hstlc replaces its output folder as a whole: choose a new or empty `--out`, \
                 or move those out of it"
                    .to_string(),
            ),
        ))
    }
}

/// Writes `files` into the folder `dir` (made if missing) beside what it holds, each file
/// whole or not at all (written to a hidden temporary file, synced, renamed over the old
/// one): for files such as a study's `curves.svg` that sit beside the runs' folders.
pub fn write_beside(dir: &Path, files: &[OutFile]) -> Result<Vec<PathBuf>, CliError> {
    check_names(files)?;
    let err = |path: PathBuf| move |source| CliError::Write { path, source };
    std::fs::create_dir_all(dir).map_err(err(dir.to_path_buf()))?;
    let mut written = Vec::new();
    for file in files {
        let path = dir.join(&file.name);
        let tmp = (0..1000)
            .map(|n| dir.join(format!(".{}.{}-{n}.tmp", file.name, std::process::id())))
            .find(|p| std::fs::symlink_metadata(p).is_err())
            .ok_or_else(|| {
                err(path.clone())(std::io::Error::new(
                    std::io::ErrorKind::AlreadyExists,
                    "no free temporary name",
                ))
            })?;
        if let Err(source) = write_synced(&tmp, &file.contents) {
            let _ = std::fs::remove_file(&tmp);
            return Err(CliError::Write { path, source });
        }
        if let Err(source) = std::fs::rename(&tmp, &path) {
            let _ = std::fs::remove_file(&tmp);
            return Err(CliError::Write { path, source });
        }
        written.push(path);
    }
    sync_dir(dir);
    Ok(written)
}

/// Removes a folder when dropped (a write that failed half way), unless forgotten.
struct RemoveOnDrop(Option<PathBuf>);

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        if let Some(path) = self.0.take() {
            let _ = std::fs::remove_dir_all(path);
        }
    }
}

/// Whether a run of this or an earlier hstlc writes a file of this name.
fn is_run_file(name: &str) -> bool {
    matches!(name, "policy.json" | "curve.csv" | "seeds.csv")
        || name.ends_with(".svg")
        || (name.starts_with('.') && name.ends_with(".tmp"))
}

/// Refuses names that are not plain file names, or that two files share (also when they
/// differ only in case, as they would on a case-insensitive file system).
fn check_names(files: &[OutFile]) -> Result<(), CliError> {
    let mut seen = std::collections::HashSet::new();
    for f in files {
        let plain = !f.name.is_empty()
            && f.name != "."
            && f.name != ".."
            && f.name != MARKER
            && f.name.len() <= 255
            && !f.name.contains(['/', '\\', '\0']);
        if !plain || !seen.insert(f.name.to_lowercase()) {
            return Err(CliError::new(
                format!("cannot write `{}`: the name is not a plain file name of its own", f.name),
                None,
            ));
        }
    }
    Ok(())
}

/// Creates a new, empty file (never an existing one), writes `bytes` and syncs them.
fn write_synced(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    use std::io::Write;
    let mut file = std::fs::OpenOptions::new().write(true).create_new(true).open(path)?;
    file.write_all(bytes)?;
    file.sync_all()
}

/// Syncs a folder's entries to disk, where the file system allows it.
pub fn sync_dir(dir: &Path) {
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
}

/// A path `parent/PREFIX<pid>-<n>` that no entry has, created as a folder when `create`.
fn unique_sibling(parent: &Path, prefix: &str, create: bool) -> std::io::Result<PathBuf> {
    for n in 0..1000 {
        let path = parent.join(format!("{prefix}{}-{n}", std::process::id()));
        if create {
            match std::fs::create_dir(&path) {
                Ok(()) => return Ok(path),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        } else if std::fs::symlink_metadata(&path).is_err() {
            return Ok(path);
        }
    }
    Err(std::io::Error::new(std::io::ErrorKind::AlreadyExists, "no free temporary name"))
}

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
) -> Result<Vec<OutFile>, CliError> {
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
    for (file, what, tau) in option_slices(spec, agent) {
        let choices: Vec<((i64, i64), String)> = cells
            .iter()
            .enumerate()
            .filter_map(|(s, &c)| {
                let o = *agent.options.get(agent.observation(s, &tau))?;
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
    run: &[hstl::runtime::eval::Step],
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
pub fn curve_picture(title: &str, curves: &[Vec<f64>]) -> Result<OutFile, CliError> {
    let smooth = (curves.first().map_or(0, Vec::len) / 60).max(1);
    let svg = pic::learning_curve(title, curves, smooth).map_err(picture_error)?;
    Ok(OutFile::text("curve.svg", svg))
}

/// The options maps to draw, as (file, what the map shows, memory): one without memory;
/// with memory, one per region, as the agent sees the grid right after leaving that region
/// with every other counter expired.
fn option_slices(spec: &TaskSpec, agent: &Agent) -> Vec<(String, String, Vec<usize>)> {
    let horizons: Vec<usize> = spec.regions.iter().map(|r| r.horizon).collect();
    if agent.memory.is_none() || horizons.is_empty() {
        return vec![("options.svg".into(), "options policy".into(), horizons)];
    }
    spec.regions
        .iter()
        .enumerate()
        .map(|(j, r)| {
            let mut tau = horizons.clone();
            tau[j] = 1;
            (
                format!("options_after_{}.svg", file_safe(&r.name)),
                format!("options policy one step after {} (others overdue)", r.name),
                tau,
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
pub fn pictured_regions(loaded: &LoadedSpec) -> Result<Vec<PicturedRegion>, CliError> {
    let spec = &loaded.spec;
    let lower_err =
        |e: hstl::lower::LowerError| CliError::new(format!("{}: {e}", loaded.file), None);
    let mut out: Vec<PicturedRegion> = Vec::new();
    for p in &spec.primitives {
        let formula = hstl::lower::formula(spec, &p.reach).ok_or_else(|| {
            lower_err(hstl::lower::LowerError::Invalid { spec: spec.name.clone() })
        })?;
        out.push(PicturedRegion { name: p.name.clone(), formula, kind: pic::RegionKind::Reach });
    }
    for (i, negated_only) in task_lets(spec) {
        let Some(l) = spec.lets.get(i) else { continue };
        let formula = hstl::lower::let_formula(spec, &l.name).map_err(lower_err)?;
        // An option's region drawn already under the option's name.
        if out.iter().any(|r| r.formula == formula) {
            continue;
        }
        let kind = if negated_only { pic::RegionKind::Avoid } else { pic::RegionKind::Other };
        out.push(PicturedRegion { name: l.name.clone(), formula, kind });
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
            CFormulaKind::Always(_, a)
            | CFormulaKind::Eventually(_, a)
            | CFormulaKind::Once(_, a)
            | CFormulaKind::Historically(_, a)
            | CFormulaKind::Prev(a)
            | CFormulaKind::Next(a) => stack.push((a, negated)),
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                stack.extend(v.iter().rev().map(|g| (g, negated)))
            }
            CFormulaKind::Implies(a, b) => {
                stack.push((b, negated));
                stack.push((a, None));
            }
            CFormulaKind::Until(_, a, b) | CFormulaKind::Since(_, a, b) => {
                stack.push((b, negated));
                stack.push((a, negated));
            }
            CFormulaKind::True
            | CFormulaKind::False
            | CFormulaKind::Cmp(..)
            | CFormulaKind::Invalid => {}
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
pub fn state_trace(spec: &TaskSpec, env: &GridWorld) -> Result<Trace, CliError> {
    Ok(hstl::evaluate::state_trace(spec, env)?)
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

fn picture_error(e: pic::PictureError) -> CliError {
    CliError::new(format!("cannot draw a picture: {e}"), None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world_arg::LoadedWorld;

    fn kinds(task: &str) -> Vec<(String, pic::RegionKind)> {
        let source = format!(
            "spec Kinds {{\n    state {{ x: int in 0..=14, y: int in 0..=14 }}\n    \
             let Goal = x > 11 && y > 11;\n    let Obstacle = x > 5 && x < 9 && y > 4 && y < 10;\n    \
             let Pit = x < 2 && y < 2;\n    let Zone = x > 11 && y < 3;\n    \
             let Near = x < 3 && y > 11;\n    let Both = x > 3 && x < 5 && y < 3;\n    \
             let Safe = always[0..20] !Obstacle;\n    task {task};\n    \
             option Goal;\n    options {{ Goal }}\n}}\n"
        );
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("kinds.hstl");
        std::fs::write(&path, source).expect("write the spec");
        let world = LoadedWorld::load("paper").expect("paper");
        let loaded =
            crate::spec_file::load(&path, None, Some(&world)).expect("loads").expect("checks");
        pictured_regions(&loaded).expect("regions").into_iter().map(|r| (r.name, r.kind)).collect()
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
}
