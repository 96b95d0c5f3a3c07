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
use hstl_robustness::{StateEval, Trace};
use rand::RngExt;

use super::model::mask;
pub use super::model::{MAX_WEIGHTS, Model, Shape, Weights};
use crate::episode::{self, Choices, explores, gamma_powers_to, train_episodes};
use crate::progress::{GoalTracker, Progress};
use crate::spec::{LevelParams, RewardKind};
use crate::{Error, Rng, TaskSpec, World};

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

impl<S> Run<S> {
    /// Appends position `state`, its valuation `x` and what the options level sees there
    /// (`g` is a buffer for its features).
    fn record(
        &mut self,
        model: &Model,
        state: S,
        x: &[f64],
        g: &mut Vec<usize>,
        tau: &[usize],
        met: usize,
    ) {
        self.states.push(state);
        self.values.extend_from_slice(x);
        model.options_coder.features(x, g);
        self.options_features.extend_from_slice(g);
        self.codes.push(model.code(tau, met));
        self.met.push(met);
    }
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
        run.record(model, state.clone(), &s.x, &mut s.g, &s.tau, s.goals.met());
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
                run.record(model, next.clone(), &s.x_next, &mut s.g, &s.tau, s.goals.met());
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
            episode::window_suffix_rewards(&run.psi, self.spec.learn.options.gamma, out);
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
        // Goals met along the run: the positions after score against the rest.
        episode::goal_suffix_rewards(&run.met, k, out, other, &mut score);
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
            // A NaN reward: a suffix the scorer's budget left unscored.
            if s.rewards[j].is_nan() {
                continue;
            }
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

/// An action drawn uniformly from those not `blocked` (from all when every one is).
fn random_unblocked(blocked: &[bool], rng: &mut Rng) -> usize {
    let open = blocked.iter().filter(|&&b| !b).count();
    if open == 0 {
        return rng.random_range(0..blocked.len());
    }
    let k = rng.random_range(0..open);
    blocked.iter().enumerate().filter(|(_, b)| !**b).nth(k).map_or(0, |(a, _)| a)
}
