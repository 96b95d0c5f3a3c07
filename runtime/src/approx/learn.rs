//! Algorithm 1 with linear function approximation: the tabular learner's updates
//! ([`crate::learn`]) with every Q-value a sum of tile weights.
//!
//! **Flat level.** Primitive `p` has one weight vector per action over the state's tiles:
//! `Q_p(s, a) = sum_t w_p[a][phi_t(s)]`. Every primitive step `s -a-> s'`, whichever
//! option runs, updates every primitive (off-policy, semi-gradient Q-learning): reward
//! `rho(reach_p, s')`, target `r + gamma max_a' Q_p(s', a')`, each active weight moved by
//! `alpha / tilings` times the error. A leg with `avoid: R` earns `min(rho(reach),
//! rho(!R))` outside `R` and, on entering, a penalty worse than any reward outside (the
//! worst over a lattice of the box, less one, earned forever), without bootstrapping.
//! Actions the world blocks at a state ([`World::blocked`]) are never chosen there, and
//! the target's `max` skips them: a function approximator may rank a move into a wall
//! first, and a greedy run would then stand still for good.
//!
//! **Options level.** `Q(obs, o) = sum_t v_o[code][psi_t(s)]`, `psi` a coarser tiling of the
//! state and `code` the memory's buckets of a persistent task (its counters, exact, are
//! what keeps a long window Markov; the buckets are what the policy tells apart), so that
//! the options level never grows with the window's length. An option run from `s_0` to
//! `s_k` updates every suffix `s_j .. s_k` (intra-option, `j = 0` first) toward its own
//! reward plus `gamma^(k-j) max_{o' available at s_k} Q(obs_k, o')`, all bootstrapping from
//! the values before this execution's updates, as the tabular learner does.
//!
//! **Progress.** For a task that is not persistent, the code also holds which of its
//! goals the episode has met ([`Progress`]), read where a leg ends, and an execution is
//! scored against the conjuncts still open: after `eventually (A && eventually B) &&
//! always !O` is met, only `always !O` is left to keep.
//!
//! Exploration, episodes, `max_steps`, `reward: window` and `switch: step` (in the greedy
//! agent) are the tabular learner's. Nothing here names a state index or a table: states
//! are the world's own values, seen through [`World::valuation`].

use std::ops::ControlFlow;

use hstl_robustness::segment::SegmentScorer;
use hstl_robustness::{Formula, StateEval, Trace};
use rand::RngExt;

use super::tiles::TileCoder;
use crate::episode::{Choices, explores, gamma_powers_to, train_episodes};
use crate::progress::{GoalTracker, Progress};
use crate::spec::{LevelParams, RewardKind, Terminate, TileParams};
use crate::{Error, Rng, TaskSpec, World};

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
    reach: Vec<Formula>,
    init: Vec<Formula>,
    terminate: Vec<Formula>,
    /// Each leg's `avoid` region and the reward of entering it, worse than any outside.
    avoid: Vec<Option<(Formula, f64)>>,
    /// For each region, the primitive whose reach formula it is, if any.
    region_reach: Vec<Option<usize>>,
    /// For each primitive, the primitive whose reach formula is its termination formula.
    stop_reach: Vec<Option<usize>>,
    /// `legs[o]`: the primitives option `o` runs.
    pub legs: Vec<Vec<usize>>,
    /// The persistent task's regions and windows (empty for another task).
    regions: Vec<(Formula, usize)>,
    /// Memory buckets `B` (0: the options level sees no memory).
    pub buckets: usize,
    /// The goals of a task that is not persistent, if it has any.
    pub progress: Option<Progress>,
    /// Codes the options level tells apart: `(B + 1)^k` memory codes (1 without memory)
    /// times `2^goals` progress codes.
    pub values: usize,
    /// Steps after which a leg is cut off.
    pub max_steps: usize,
    shape: Shape,
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
    fn stops_knowing(&self, eval: &mut StateEval, p: usize, x: &[f64], reach: &[f64]) -> bool {
        let stop = match self.stop_reach[p] {
            Some(q) => reach[q],
            None => eval.value(&self.terminate[p], x),
        };
        stop > 0.0 || self.avoid[p].as_ref().is_some_and(|(r, _)| eval.value(r, x) >= 0.0)
    }

    /// [`Model::step_counters`] with `rho(reach_q, x)` of every primitive `q` known.
    fn step_counters_knowing(
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
    fn reach_values(&self, eval: &mut StateEval, x: &[f64], out: &mut Vec<f64>) {
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
    fn flat_values(&self, w: &[f64], f: &[usize], out: &mut [f64]) {
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

/// The result of [`ApproxLearner::train`].
#[derive(Clone, Debug, PartialEq)]
pub struct Trained {
    /// The learning curve: per episode, the sum of the rewards of its options.
    pub curve: Vec<f64>,
    /// Primitive steps taken in this call.
    pub steps: u64,
}

/// Trains one spec in one world with linear function approximation.
#[derive(Clone, Debug)]
pub struct ApproxLearner<'w, W: World> {
    world: &'w W,
    spec: TaskSpec,
    model: Model,
    weights: Weights,
    /// `reward: segment`'s scorers, one per progress code (the whole task at 0; `None`
    /// where nothing is left to keep); empty for `reward: window`.
    scorers: Vec<Option<SegmentScorer>>,
    eval: StateEval,
    gamma_powers: Vec<f64>,
}

/// One option execution: the valuations, features and memory along it.
#[derive(Clone, Debug)]
struct Run<S> {
    /// The world's states `s_0 .. s_k`.
    states: Vec<S>,
    /// Valuations, `vars` values per position.
    values: Vec<f64>,
    /// Options features, `tilings` per position.
    options_features: Vec<usize>,
    /// The memory code at each position.
    codes: Vec<usize>,
    /// `psi` at each position (empty for a task without counters).
    psi: Vec<bool>,
    /// The goals met at each position.
    met: Vec<usize>,
}

impl<'w, W: World> ApproxLearner<'w, W> {
    /// A learner with zeroed weights (see [`Model::new`] for what fails).
    pub fn new(spec: &TaskSpec, world: &'w W) -> Result<ApproxLearner<'w, W>, Error> {
        spec.validate()?;
        let model = Model::new(spec, world)?;
        let weights = model.zero_weights();
        let scorers = match (spec.learn.reward, &model.progress) {
            (RewardKind::Window, _) => Vec::new(),
            (RewardKind::Segment, Some(progress)) => progress.scorers(),
            (RewardKind::Segment, None) => vec![Some(SegmentScorer::new(&spec.task))],
        };
        Ok(ApproxLearner {
            world,
            spec: spec.clone(),
            model,
            weights,
            scorers,
            eval: StateEval::new(),
            gamma_powers: vec![1.0],
        })
    }

    /// Continues from earlier weights (for instance from a loaded `policy.json`).
    pub fn with_weights(mut self, weights: Weights) -> Result<ApproxLearner<'w, W>, Error> {
        if !self.model.fits(&weights) {
            return Err(Error::Config(
                "the weights do not have the shape of this spec and world".into(),
            ));
        }
        self.weights = weights;
        Ok(self)
    }

    /// The learned weights.
    pub fn weights(&self) -> &Weights {
        &self.weights
    }

    /// The model the weights are read with.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The spec being learned.
    pub fn spec(&self) -> &TaskSpec {
        &self.spec
    }

    /// Runs `learn.episodes` episodes, calling `progress(episode, reward)` after each.
    pub fn train(&mut self, rng: &mut Rng, mut progress: impl FnMut(usize, f64)) -> Trained {
        self.train_until(rng, |e, r| {
            progress(e, r);
            ControlFlow::Continue(())
        })
    }

    /// [`ApproxLearner::train`], stopped after the episode for which `progress` breaks.
    pub fn train_until(
        &mut self,
        rng: &mut Rng,
        mut progress: impl FnMut(usize, f64) -> ControlFlow<()>,
    ) -> Trained {
        let before = self.weights.steps;
        let mut run = Run::default();
        let mut scratch = Scratch::default();
        let curve = train_episodes(
            self.spec.learn.episodes,
            || self.episode(rng, &mut run, &mut scratch),
            &mut progress,
        );
        Trained { curve, steps: self.weights.steps - before }
    }

    fn episode(&mut self, rng: &mut Rng, run: &mut Run<W::State>, s: &mut Scratch) -> f64 {
        let mut state = self.world.reset(rng);
        self.world.valuation(&state, &mut s.x);
        self.model.start_counters(&mut self.eval, &s.x, &mut s.tau);
        s.goals.start(&s.x);
        if let Some(progress) = &self.model.progress {
            s.goals.read(progress);
        }
        let mut total = 0.0;
        let choices = Choices::new(
            self.spec.learn.choices,
            self.model.progress.as_ref().map(Progress::all_met),
            self.model.legs.len(),
            &self.spec.task,
        );
        let mut steps = 0;
        for choice in 0.. {
            if !choices.go_on(choice, s.goals.met(), steps) {
                break;
            }
            let o = self.choose_option(rng, s);
            self.run_option(o, &state, rng, run, s);
            self.suffix_rewards(run, &mut s.rewards, &mut s.other_rewards);
            total += s.rewards[0];
            self.update_options(o, run, s);
            steps += run.states.len() - 1;
            state = run.states.last().cloned().unwrap_or(state);
            let vars = self.model.vars.len();
            s.x.clear();
            s.x.extend_from_slice(&run.values[run.values.len() - vars..]);
        }
        total
    }

    fn choose_option(&mut self, rng: &mut Rng, s: &mut Scratch) -> usize {
        let explore = explores(&self.spec.learn.options, None, &mut self.weights.choices, rng);
        self.model.available(&mut self.eval, &s.x, &mut s.available);
        if explore {
            return s.available[rng.random_range(0..s.available.len())];
        }
        self.model.options_coder.features(&s.x, &mut s.g);
        let code = self.model.code(&s.tau, s.goals.met());
        self.model.best_option(&self.weights, code, &s.g, &s.available)
    }

    fn run_option(
        &mut self,
        o: usize,
        start: &W::State,
        rng: &mut Rng,
        run: &mut Run<W::State>,
        s: &mut Scratch,
    ) {
        let flat = self.spec.learn.flat;
        let model = &self.model;
        let vars = model.vars.len();
        run.states.clear();
        run.values.clear();
        run.options_features.clear();
        run.codes.clear();
        run.psi.clear();
        run.met.clear();
        let mut state = start.clone();
        model.blocked(self.world, &state, &mut s.blocked);
        run.states.push(state.clone());
        run.values.extend_from_slice(&s.x);
        model.options_coder.features(&s.x, &mut s.g);
        run.options_features.extend_from_slice(&s.g);
        run.codes.push(model.code(&s.tau, s.goals.met()));
        run.met.push(s.goals.met());
        if model.is_persistent() {
            run.psi.push(s.tau.iter().zip(&model.regions).all(|(t, (_, n))| t < n));
        }
        model.flat_coder.features(&s.x, &mut s.f);
        for &p in &model.legs[o] {
            for _ in 0..model.max_steps {
                let a = if explores(&flat, None, &mut self.weights.steps, rng) {
                    random_unblocked(&s.blocked, rng)
                } else {
                    model.greedy_action(&self.weights, p, &s.f, &s.blocked, &mut s.q)
                };
                let next = self.world.step(&state, a, rng);
                self.world.valuation(&next, &mut s.x_next);
                model.blocked(self.world, &next, &mut s.blocked_next);
                model.flat_coder.features(&s.x_next, &mut s.f_next);
                model.reach_values(&mut self.eval, &s.x_next, &mut s.reach_next);
                update_flat(model, &mut self.weights.flat, &mut self.eval, flat, a, s);
                if model.is_persistent() {
                    let kept = model.step_counters_knowing(
                        &mut self.eval,
                        &s.x_next,
                        &s.reach_next,
                        &mut s.tau,
                    );
                    run.psi.push(kept);
                }
                run.states.push(next.clone());
                run.values.extend_from_slice(&s.x_next);
                model.options_coder.features(&s.x_next, &mut s.g);
                run.options_features.extend_from_slice(&s.g);
                run.codes.push(model.code(&s.tau, s.goals.met()));
                run.met.push(s.goals.met());
                if model.progress.is_some() {
                    s.goals.push(&s.x_next);
                }
                state = next;
                std::mem::swap(&mut s.f, &mut s.f_next);
                std::mem::swap(&mut s.x, &mut s.x_next);
                std::mem::swap(&mut s.blocked, &mut s.blocked_next);
                std::mem::swap(&mut s.reach, &mut s.reach_next);
                if model.stops_knowing(&mut self.eval, p, &s.x, &s.reach) {
                    break;
                }
            }
            // A leg ends where a goal's region is entered: the code from here on says so.
            if let Some(progress) = &model.progress {
                let met = s.goals.read(progress);
                if let (Some(m), Some(c)) = (run.met.last_mut(), run.codes.last_mut()) {
                    (*m, *c) = (met, model.code(&s.tau, met));
                }
            }
        }
        debug_assert_eq!(run.values.len(), run.states.len() * vars);
    }

    /// `out[j]`: the reward of the suffix of `run` from position `j`, scored against what
    /// is left of the task at `j` (`other` is a buffer).
    fn suffix_rewards(&mut self, run: &Run<W::State>, out: &mut Vec<f64>, other: &mut Vec<f64>) {
        let k = run.states.len() - 1;
        if self.scorers.is_empty() {
            let gamma = self.spec.learn.options.gamma;
            out.clear();
            out.resize(k + 1, 0.0);
            for j in (0..k).rev() {
                out[j] = f64::from(u8::from(run.psi[j + 1])) + gamma * out[j + 1];
            }
            return;
        }
        let vars = self.model.vars.len();
        let columns =
            (0..vars).map(|d| run.values.iter().skip(d).step_by(vars).copied().collect()).collect();
        let Ok(trace) = Trace::from_columns(columns) else {
            out.clear();
            out.resize(k + 1, 0.0);
            return;
        };
        let mut score = |met: usize, into: &mut Vec<f64>| match self.scorers.get_mut(met) {
            Some(Some(scorer)) => scorer.suffix_rewards(&trace, into),
            _ => {
                into.clear();
                into.resize(k + 1, 0.0);
            }
        };
        let first = run.met.first().copied().unwrap_or(0);
        score(first, out);
        // Goals met along the run: the positions after score against the rest.
        let mut j = 0;
        while let Some(offset) = run.met[j..].iter().position(|&m| m != run.met[j]) {
            j += offset;
            let met = run.met[j];
            score(met, other);
            let until = run.met[j..].iter().position(|&m| m != met).map_or(k + 1, |e| j + e);
            out[j..until].copy_from_slice(&other[j..until]);
        }
    }

    fn update_options(&mut self, o: usize, run: &Run<W::State>, s: &mut Scratch) {
        let params = self.spec.learn.options;
        let model = &self.model;
        let t = model.options_coder.tilings();
        let k = run.states.len() - 1;
        let vars = model.vars.len();
        let end_g = &run.options_features[k * t..][..t];
        model.available(&mut self.eval, &run.values[k * vars..][..vars], &mut s.available);
        let best = s
            .available
            .iter()
            .map(|&b| model.option_value(&self.weights, run.codes[k], b, end_g))
            .fold(f64::NEG_INFINITY, f64::max);
        gamma_powers_to(&mut self.gamma_powers, params.gamma, k);
        let n = model.options_coder.len();
        let step = params.alpha / t as f64;
        for j in 0..k {
            let g = &run.options_features[j * t..][..t];
            let target = s.rewards[j] + self.gamma_powers[k - j] * best;
            let base = (run.codes[j] * model.legs.len() + o) * n;
            let q: f64 = g.iter().map(|&i| self.weights.options[base + i]).sum();
            let delta = step * (target - q);
            for &i in g {
                self.weights.options[base + i] += delta;
            }
        }
    }
}

impl<S> Default for Run<S> {
    fn default() -> Self {
        Run {
            states: Vec::new(),
            values: Vec::new(),
            options_features: Vec::new(),
            codes: Vec::new(),
            psi: Vec::new(),
            met: Vec::new(),
        }
    }
}

/// Buffers reused across steps.
#[derive(Clone, Debug, Default)]
struct Scratch {
    /// The actions blocked at `x`, and at `x_next`.
    blocked: Vec<bool>,
    blocked_next: Vec<bool>,
    /// `rho(reach_p, .)` of every primitive at `x_next`, and after a step at `x`.
    reach_next: Vec<f64>,
    reach: Vec<f64>,
    x: Vec<f64>,
    x_next: Vec<f64>,
    f: Vec<usize>,
    f_next: Vec<usize>,
    g: Vec<usize>,
    q: Vec<f64>,
    tau: Vec<usize>,
    available: Vec<usize>,
    rewards: Vec<f64>,
    /// The suffix rewards under another progress code.
    other_rewards: Vec<f64>,
    /// The episode so far and the goals it has met.
    goals: GoalTracker,
}

/// The flat update of every primitive after the step `x -a-> x_next` (features `f`,
/// `f_next` in `s`), bootstrapping from the actions not blocked at `x_next`.
fn update_flat(
    model: &Model,
    flat_weights: &mut [Vec<f64>],
    eval: &mut StateEval,
    params: LevelParams,
    a: usize,
    s: &mut Scratch,
) {
    let n = model.flat_coder.len();
    let step = params.alpha / model.flat_coder.tilings() as f64;
    s.q.resize(model.actions, 0.0);
    for (p, w) in flat_weights.iter_mut().enumerate() {
        let mut reward = s.reach_next[p];
        let mut ends = false;
        if let Some((r, penalty)) = &model.avoid[p] {
            let inside = eval.value(r, &s.x_next);
            if inside >= 0.0 {
                (reward, ends) = (*penalty, true);
            } else {
                reward = reward.min(-inside);
            }
        }
        let best = if ends {
            0.0
        } else {
            model.flat_values(w, &s.f_next, &mut s.q);
            mask(&mut s.q, &s.blocked_next);
            s.q.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        };
        let row = &mut w[a * n..][..n];
        let q: f64 = s.f.iter().map(|&i| row[i]).sum();
        let delta = step * (reward + params.gamma * best - q);
        for &i in &s.f {
            row[i] += delta;
        }
    }
}

/// Sets the values of the `blocked` actions to minus infinity, unless every one is blocked.
fn mask(q: &mut [f64], blocked: &[bool]) {
    if blocked.iter().all(|&b| b) {
        return;
    }
    for (v, &b) in q.iter_mut().zip(blocked) {
        if b {
            *v = f64::NEG_INFINITY;
        }
    }
}

/// An action drawn uniformly from those not `blocked` (from all when every one is).
fn random_unblocked(blocked: &[bool], rng: &mut Rng) -> usize {
    let open = blocked.iter().filter(|&&b| !b).count();
    if open == 0 {
        return rng.random_range(0..blocked.len());
    }
    let k = rng.random_range(0..open);
    blocked.iter().enumerate().filter(|(_, b)| !**b).nth(k).map_or(0, |(a, _)| a)
}
