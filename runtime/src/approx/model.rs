//! The approximate learner's model: what the learner and the greedy agent share (the
//! spec's formulas, the tile codings and the memory's dynamics, all over the world's
//! values), its learned [`Weights`] and their [`Shape`] (see [`crate::approx::learn`] for
//! the algorithm).

use hstl_robustness::{Formula, StateEval};

use super::tiles::TileCoder;
use crate::progress::Progress;
use crate::spec::{RewardKind, Terminate, TileParams};
use crate::{Error, TaskSpec, World};

/// At most this many weights in all (flat and options), 8 bytes each.
pub const MAX_WEIGHTS: usize = 1 << 25;

/// Lattice points per variable when the worst reward of a leg with `avoid` is looked for.
const LATTICE: usize = 33;

/// The learned weights, enough to act greedily and to continue training.
#[derive(Clone, Debug, PartialEq)]
pub struct Weights {
    /// `flat[p][a * F + f]`: primitive `p`'s weight of feature `f` for action `a`.
    pub flat: Vec<Vec<f64>>,
    /// `options[(code * n_options + o) * G + g]`: option `o`'s weight of options feature
    /// `g` under memory code `code`.
    pub options: Vec<f64>,
    /// Primitive steps taken so far (drives the flat epsilon).
    pub steps: u64,
    /// Option choices made so far (drives the options epsilon).
    pub choices: u64,
}

/// What the learner and the greedy agent share: the spec's formulas, the codings and the
/// memory's dynamics, all over the world's values.
#[derive(Clone, Debug)]
pub struct Model {
    /// The spec's state variables' names, in valuation order.
    pub vars: Vec<String>,
    /// Actions of the world.
    pub actions: usize,
    /// The flat levels' coding.
    pub flat_coder: TileCoder,
    /// The options level's coding.
    pub options_coder: TileCoder,
    pub(super) reach: Vec<Formula>,
    pub(super) init: Vec<Formula>,
    pub(super) terminate: Vec<Formula>,
    /// Each leg's `avoid` region and the reward of entering it, worse than any outside.
    pub(super) avoid: Vec<Option<(Formula, f64)>>,
    /// For each region, the primitive whose reach formula it is, if any.
    pub(super) region_reach: Vec<Option<usize>>,
    /// For each primitive, the primitive whose reach formula is its termination formula.
    pub(super) stop_reach: Vec<Option<usize>>,
    /// `legs[o]`: the primitives option `o` runs.
    pub legs: Vec<Vec<usize>>,
    /// The persistent task's regions and windows (empty for another task).
    pub(super) regions: Vec<(Formula, usize)>,
    /// Memory buckets `B` (0: the options level sees no memory).
    pub buckets: usize,
    /// The goals of a task that is not persistent, if it has any.
    pub progress: Option<Progress>,
    /// Codes the options level tells apart: `(B + 1)^k` memory codes (1 without memory)
    /// times `2^goals` progress codes.
    pub values: usize,
    /// Steps after which a leg is cut off.
    pub max_steps: usize,
    pub(super) shape: Shape,
}

/// What the count of a model's weights is made of: each primitive's weights per action
/// over the flat tiling, and each option's per code over the options tiling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    /// Features of the flat levels' tiling.
    pub flat_features: usize,
    /// Features of the options level's tiling.
    pub options_features: usize,
    /// Actions of the world.
    pub actions: usize,
    /// Primitives.
    pub primitives: usize,
    /// Options.
    pub options: usize,
    /// Codes the options level tells apart (`usize::MAX` when they overflow).
    pub codes: usize,
}

impl Shape {
    /// The weights in all, `None` when they overflow.
    pub fn weights(&self) -> Option<usize> {
        let flat = self.flat_features.checked_mul(self.actions)?.checked_mul(self.primitives)?;
        let options = self.options_features.checked_mul(self.options)?.checked_mul(self.codes)?;
        flat.checked_add(options)
    }
}

impl Model {
    /// The model of `spec` in `world`. Fails for a spec the approximate learner cannot
    /// run (no `tiles` settings, `terminate: argmax`, a world whose variables are not the
    /// spec's) or one too large for [`MAX_WEIGHTS`].
    pub fn new<W: World>(spec: &TaskSpec, world: &W) -> Result<Model, Error> {
        let Some(tiles) = &spec.learn.tiles else {
            return Err(Error::Config("the approximate learner needs `tiles` settings".into()));
        };
        let vars: Vec<String> = spec.state_vars.iter().map(|v| v.name.clone()).collect();
        if world.state_vars() != vars {
            return Err(Error::Spec(format!(
                "the spec's state variables ({}) are not the world's ({})",
                vars.join(", "),
                world.state_vars().join(", ")
            )));
        }
        let actions = world.actions().len();
        if actions == 0 {
            return Err(Error::Env(format!("environment {} has no action", world.name())));
        }
        let flat_coder = coder(tiles, 1, tiles.tilings)?;
        let options_coder = coder(tiles, 2, tiles.tilings.div_ceil(2))?;
        let mut reach = Vec::new();
        let mut init = Vec::new();
        let mut terminate = Vec::new();
        for p in &spec.primitives {
            let stop = match &p.terminate {
                Terminate::Formula(f) => f.clone(),
                Terminate::Argmax => {
                    return Err(Error::Spec(format!(
                        "option {} stops where its region is most robust (argmax), which needs a \
                         finite state space; give it `terminate: REGION`",
                        p.name
                    )));
                }
            };
            reach.push(p.reach.clone());
            init.push(p.init.clone());
            terminate.push(stop);
        }
        let gamma = spec.learn.flat.gamma;
        let forever = if gamma < 1.0 { 1.0 / (1.0 - gamma) } else { spec.learn.max_steps as f64 };
        let avoid = spec
            .primitives
            .iter()
            .map(|p| {
                p.avoid.as_ref().map(|r| {
                    let worst = worst_outside(&p.reach, r, tiles);
                    (r.clone(), (worst - 1.0) * forever)
                })
            })
            .collect();
        let persistent = spec.learn.memory > 0 || spec.learn.reward == RewardKind::Window;
        let regions: Vec<(Formula, usize)> = if persistent {
            spec.regions.iter().map(|r| (r.formula.clone(), r.horizon.max(1))).collect()
        } else {
            Vec::new()
        };
        if persistent && regions.is_empty() {
            return Err(Error::Spec(
                "memory and `reward: window` need a persistent task with regions".into(),
            ));
        }
        let buckets = spec.learn.memory;
        let progress = if persistent { None } else { Progress::of_task(&spec.task) };
        let memory_values = if buckets == 0 {
            Some(1)
        } else {
            u32::try_from(regions.len()).ok().and_then(|k| (buckets + 1).checked_pow(k))
        };
        let values =
            memory_values.and_then(|v| v.checked_mul(progress.as_ref().map_or(1, Progress::codes)));
        let legs: Vec<Vec<usize>> = spec.options.iter().map(|o| o.sequence.clone()).collect();
        let shape = Model::shape_of(spec, world)?;
        let (Some(values), Some(total)) = (values, shape.weights()) else {
            return Err(Error::Config("the weights would not fit in memory".into()));
        };
        if total > MAX_WEIGHTS {
            return Err(Error::Config(format!(
                "{total} weights are more than the {MAX_WEIGHTS} allowed; use fewer tiles, \
                 tilings or memory buckets"
            )));
        }
        // Formulas the task and the options share are evaluated once per step.
        let same_reach = |f: &Formula| reach.iter().position(|r| r == f);
        let region_reach = regions.iter().map(|(r, _)| same_reach(r)).collect();
        let stop_reach = terminate.iter().map(same_reach).collect();
        Ok(Model {
            vars,
            actions,
            flat_coder,
            options_coder,
            reach,
            init,
            terminate,
            avoid,
            region_reach,
            stop_reach,
            legs,
            regions,
            buckets,
            progress,
            values,
            max_steps: spec.learn.max_steps,
            shape,
        })
    }

    /// What the weights' count is made of (see [`Shape`]).
    pub fn shape(&self) -> Shape {
        self.shape
    }

    /// The shape of `spec`'s weights in `world`, without allocating them: what the
    /// facade counts against the memory budget before it builds a [`Model`].
    pub fn shape_of<W: World>(spec: &TaskSpec, world: &W) -> Result<Shape, Error> {
        Model::shape_with(spec, world.actions().len())
    }

    /// [`Model::shape_of`] in a world of `actions` actions.
    pub fn shape_with(spec: &TaskSpec, actions: usize) -> Result<Shape, Error> {
        let Some(tiles) = &spec.learn.tiles else {
            return Err(Error::Config("the approximate learner needs `tiles` settings".into()));
        };
        let flat_coder = coder(tiles, 1, tiles.tilings)?;
        let options_coder = coder(tiles, 2, tiles.tilings.div_ceil(2))?;
        let persistent = spec.learn.memory > 0 || spec.learn.reward == RewardKind::Window;
        let regions = if persistent { spec.regions.len() } else { 0 };
        let progress = if persistent { None } else { Progress::of_task(&spec.task) };
        let memory = if spec.learn.memory == 0 {
            Some(1)
        } else {
            u32::try_from(regions).ok().and_then(|k| (spec.learn.memory + 1).checked_pow(k))
        };
        let codes =
            memory.and_then(|v| v.checked_mul(progress.as_ref().map_or(1, Progress::codes)));
        Ok(Shape {
            flat_features: flat_coder.len(),
            options_features: options_coder.len(),
            actions,
            primitives: spec.primitives.len(),
            options: spec.options.len(),
            codes: codes.unwrap_or(usize::MAX),
        })
    }

    /// Zeroed weights of this model's shape.
    pub fn zero_weights(&self) -> Weights {
        let flat = vec![vec![0.0; self.flat_coder.len() * self.actions]; self.reach.len()];
        let options = vec![0.0; self.values * self.legs.len() * self.options_coder.len()];
        Weights { flat, options, steps: 0, choices: 0 }
    }

    /// Whether `weights` has this model's shape.
    pub fn fits(&self, weights: &Weights) -> bool {
        let zero = self.zero_weights();
        weights.flat.len() == zero.flat.len()
            && weights.flat.iter().all(|w| w.len() == zero.flat[0].len())
            && weights.options.len() == zero.options.len()
    }

    /// The options whose first leg may start at the valuation `x` (every option when none
    /// may: a continuous state has no place to refuse).
    pub fn available(&self, eval: &mut StateEval, x: &[f64], out: &mut Vec<usize>) {
        out.clear();
        for (o, legs) in self.legs.iter().enumerate() {
            if eval.value(&self.init[legs[0]], x) > 0.0 {
                out.push(o);
            }
        }
        if out.is_empty() {
            out.extend(0..self.legs.len());
        }
    }

    /// Whether primitive `p` stops at `x`: its termination formula holds, or it entered its
    /// avoided region.
    pub fn stops(&self, eval: &mut StateEval, p: usize, x: &[f64]) -> bool {
        eval.value(&self.terminate[p], x) > 0.0
            || self.avoid[p].as_ref().is_some_and(|(r, _)| eval.value(r, x) >= 0.0)
    }

    /// [`Model::stops`] with `rho(reach_q, x)` of every primitive `q` known (`reach`).
    pub(super) fn stops_knowing(
        &self,
        eval: &mut StateEval,
        p: usize,
        x: &[f64],
        reach: &[f64],
    ) -> bool {
        let stop = match self.stop_reach[p] {
            Some(q) => reach[q],
            None => eval.value(&self.terminate[p], x),
        };
        stop > 0.0 || self.avoid[p].as_ref().is_some_and(|(r, _)| eval.value(r, x) >= 0.0)
    }

    /// [`Model::step_counters`] with `rho(reach_q, x)` of every primitive `q` known.
    pub(super) fn step_counters_knowing(
        &self,
        eval: &mut StateEval,
        x: &[f64],
        reach: &[f64],
        tau: &mut [usize],
    ) -> bool {
        let mut kept = true;
        for (j, ((r, n), t)) in self.regions.iter().zip(tau.iter_mut()).enumerate() {
            let v = match self.region_reach[j] {
                Some(q) => reach[q],
                None => eval.value(r, x),
            };
            *t = if v > 0.0 { 0 } else { (*t + 1).min(*n) };
            kept &= *t < *n;
        }
        kept
    }

    /// `rho(reach_p, x)` of every primitive, into `out`.
    pub(super) fn reach_values(&self, eval: &mut StateEval, x: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(self.reach.iter().map(|r| eval.value(r, x)));
    }

    /// The window of each region of a persistent task, in conjunct order.
    pub fn horizons(&self) -> impl Iterator<Item = usize> + '_ {
        self.regions.iter().map(|(_, n)| *n)
    }

    /// Whether the task is persistent (its memory's counters run).
    pub fn is_persistent(&self) -> bool {
        !self.regions.is_empty()
    }

    /// The counters at the start of an episode in `x`: 0 for a region that holds there,
    /// else the window (expired).
    pub fn start_counters(&self, eval: &mut StateEval, x: &[f64], tau: &mut Vec<usize>) {
        tau.clear();
        for (r, n) in &self.regions {
            tau.push(if eval.value(r, x) > 0.0 { 0 } else { *n });
        }
    }

    /// Moves the counters on to `x`; returns `psi` (every window kept).
    pub fn step_counters(&self, eval: &mut StateEval, x: &[f64], tau: &mut [usize]) -> bool {
        let mut kept = true;
        for ((r, n), t) in self.regions.iter().zip(tau.iter_mut()) {
            *t = if eval.value(r, x) > 0.0 { 0 } else { (*t + 1).min(*n) };
            kept &= *t < *n;
        }
        kept
    }

    /// The options level's code of the counters `tau` and the goals met `met` (a
    /// [`Progress`] mask; 0 for a task without goals).
    pub fn code(&self, tau: &[usize], met: usize) -> usize {
        let progress = self.progress.as_ref().map_or(1, Progress::codes);
        if self.buckets == 0 {
            return met;
        }
        let b = self.buckets;
        let memory = tau.iter().zip(&self.regions).fold(0, |code, (&t, (_, n))| {
            let bucket = if t >= *n { b } else { t * b / n };
            code * (b + 1) + bucket
        });
        memory * progress + met
    }

    /// `Q_p(x, a)` for every action, from the features `f` of `x`, into `out`.
    pub(super) fn flat_values(&self, w: &[f64], f: &[usize], out: &mut [f64]) {
        let n = self.flat_coder.len();
        for (a, q) in out.iter_mut().enumerate() {
            let row = &w[a * n..][..n];
            *q = f.iter().map(|&i| row[i]).sum();
        }
    }

    /// The greedy action of primitive `p` at the features `f` among the actions not
    /// `blocked` (all of them when every one is); the lowest index among ties.
    pub fn greedy_action(
        &self,
        weights: &Weights,
        p: usize,
        f: &[usize],
        blocked: &[bool],
        scratch: &mut Vec<f64>,
    ) -> usize {
        scratch.resize(self.actions, 0.0);
        self.flat_values(&weights.flat[p], f, scratch);
        mask(scratch, blocked);
        crate::greedy::argmax(scratch)
    }

    /// Which actions the world blocks at `state`, into `out`.
    pub fn blocked<W: World>(&self, world: &W, state: &W::State, out: &mut Vec<bool>) {
        out.clear();
        out.extend((0..self.actions).map(|a| world.blocked(state, a)));
    }

    /// `Q(obs, o)` under memory code `code`, from the options features `g`.
    pub fn option_value(&self, weights: &Weights, code: usize, o: usize, g: &[usize]) -> f64 {
        let n = self.options_coder.len();
        let row = &weights.options[(code * self.legs.len() + o) * n..][..n];
        g.iter().map(|&i| row[i]).sum()
    }

    /// The available option with the largest value; the first among ties.
    pub fn best_option(
        &self,
        weights: &Weights,
        code: usize,
        g: &[usize],
        available: &[usize],
    ) -> usize {
        let mut best = available[0];
        let mut top = self.option_value(weights, code, best, g);
        for &o in &available[1..] {
            let v = self.option_value(weights, code, o, g);
            if v > top || top.is_nan() && !v.is_nan() {
                (best, top) = (o, v);
            }
        }
        best
    }
}

/// The coding of `tiles` with every variable's tile count divided by `coarser` (at least 1).
fn coder(tiles: &TileParams, coarser: usize, tilings: usize) -> Result<TileCoder, Error> {
    let bins: Vec<usize> = tiles.bins.iter().map(|b| (b / coarser).max(1)).collect();
    TileCoder::new(&tiles.lo, &tiles.hi, &bins, tilings).map_err(Error::Config)
}

/// The worst flat reward outside `avoid` of a leg reaching `reach`: the least
/// `min(rho(reach), -rho(avoid))` over a lattice of the box where `avoid` does not hold
/// (`LATTICE` points per variable, at most 4,096 in all), or 0 when that is larger.
fn worst_outside(reach: &Formula, avoid: &Formula, tiles: &TileParams) -> f64 {
    let dims = tiles.lo.len();
    let per = (1..=LATTICE).rev().find(|&n| n.checked_pow(dims as u32).is_some_and(|t| t <= 4096));
    let per = per.unwrap_or(1).max(2);
    let total = per.saturating_pow(dims as u32).min(4096);
    let mut eval = StateEval::new();
    let mut x = vec![0.0; dims];
    let mut worst = 0.0f64;
    for mut k in 0..total {
        for (d, v) in x.iter_mut().enumerate() {
            let i = k % per;
            k /= per;
            *v = tiles.lo[d] + (tiles.hi[d] - tiles.lo[d]) * i as f64 / (per - 1) as f64;
        }
        let a = eval.value(avoid, &x);
        if a < 0.0 {
            let r = eval.value(reach, &x).min(-a);
            if r.is_finite() {
                worst = worst.min(r);
            }
        }
    }
    worst
}

/// Sets the values of the `blocked` actions to minus infinity, unless every one is blocked.
pub(super) fn mask(q: &mut [f64], blocked: &[bool]) {
    if blocked.iter().all(|&b| b) {
        return;
    }
    for (v, &b) in q.iter_mut().zip(blocked) {
        if b {
            *v = f64::NEG_INFINITY;
        }
    }
}
