//! Algorithm 1 of Li & Belta (2016): hierarchical Q-learning with options.
//!
//! **Flat level.** Every primitive option `p` has a Q-table over (state, action). Every
//! primitive step `s -a-> s'`, whichever option is running, updates the table of *every*
//! primitive (off-policy): reward `rho(reach_p, s')`, target
//! `r + gamma * max_a' Q_p(s', a')`. The bootstrap is not cut at `p`'s termination set:
//! the paper learns each flat policy as a continuing task, and so do we.
//!
//! **Options level.** An option run from `s_0` to `s_k` (`k` primitive steps over all its
//! legs) updates `Q(s_0, o) += alpha (R + gamma^k max_{o' available at s_k} Q(s_k, o') -
//! Q(s_0, o))`, `R` being the task's segment reward over `s_0 .. s_k`. Then, for
//! `j = 1, ..., k-1` in that order, the suffix `s_j .. s_k` updates the same way with its
//! own reward and `gamma^(k-j)`: `intra: paper` credits the executed option; `intra:
//! remaining` credits the option made of the legs that remain at `s_j` (the state where
//! a leg starts belongs to that leg) when it is in the set and available at `s_j`, and
//! skips the suffix otherwise. All of them bootstrap from `max Q(s_k, .)` as it was
//! before this execution's updates; a later update of a cell that an earlier one changed
//! (a state visited twice) starts from the changed value.
//!
//! **Memory and the window reward** (LANGUAGE.md, "Persistent tasks beyond the paper";
//! see [`crate::memory`]). With `memory: B > 0` the options table is indexed by the
//! observation `state * (B + 1)^k + code(buckets)` instead of the state. The counters
//! `tau_j` start with each episode and are updated after every primitive step; the
//! observation at every position of an option's trajectory is recorded, so that each
//! suffix update uses the memory of its own start, and the bootstrap uses the state and
//! memory at termination. With `reward: window` an option run from `s_i` to `s_k` earns
//! `sum_{j=1..k-i} gamma^(j-1) psi(i + j)` (options gamma) instead of the segment
//! robustness, and each suffix the same sum over its own steps.
//!
//! **Goals** (LANGUAGE.md, "Task progress"; see [`crate::progress`]). For a task that is
//! not persistent, the options table is indexed by the observation times `2^goals` plus
//! the goals the episode has met (read where a leg ends), an execution and each of its
//! suffixes are scored against the conjuncts still open where they start, and once every
//! goal is met the episode goes on to the task's horizon, as a greedy run does.
//!
//! **Options.** An option runs at least one step; a leg stops at the first `s'` in its
//! termination set, or is cut off after `max_steps` steps. Exploration is epsilon-greedy
//! at both levels with linear decay and a floor: the flat epsilon decays per primitive
//! step, the options epsilon per option choice. Greedy ties go to the lowest index.

use std::ops::ControlFlow;

use hstl_robustness::segment::TabularScorer;
use rand::RngExt;

use crate::env::EpisodeEnd;
use crate::episode::{self, Choices, explores, floor_from, gamma_powers_to, train_episodes};
use crate::greedy::{argmax, best_of, max_of};
use crate::memory::Memory;
use crate::plan::{Model, Planner};
use crate::plan_reach::{OptionsLayout, ReachPlanner};
use crate::progress::{GoalTracker, StateGoals};
use crate::spec::{Intra, LearnParams, LevelParams, Plan, RewardKind};
use crate::tables::Tables;
use crate::{Env, Error, Rng, TaskSpec};

/// At most this many options Q-values (observations times options).
const MAX_OPTION_VALUES: usize = 1 << 27;

/// Trains one spec on one environment.
#[derive(Clone, Debug)]
pub struct Learner<'e, E: Env> {
    env: &'e E,
    spec: TaskSpec,
    tables: Tables,
    /// The counters and buckets, when the spec sets `memory` or `reward: window`.
    memory: Option<Memory>,
    reward: Reward,
    q: QTables,
    /// The fast form of `memory` that the steps update.
    counters: Option<Counters>,
    /// `tau_j` of the running episode.
    tau: Vec<usize>,
    /// The memory code of `tau` (0 without memory).
    code: usize,
    /// Memory values the options policy tells apart (1 without memory).
    values: usize,
    /// The goals of a task that is not persistent, when it has some.
    goals: Option<StateGoals>,
    /// Progress codes the options policy tells apart (`2^goals`; 1 without goals).
    codes: usize,
    /// The running episode's states so far and the goals it has met.
    tracker: GoalTracker,
    /// The suffix rewards under another progress code (a buffer).
    other_rewards: Vec<f64>,
    /// `gamma_powers[i]`: the options gamma to the power `i`, grown on demand.
    gamma_powers: Vec<f64>,
    /// Every state by index, so that a step does not rebuild its state from the index.
    states: Vec<E::State>,
    /// The first primitive step from which the flat epsilon is at its floor, if any.
    flat_floor: Option<u64>,
    /// With `plan: model`: the planner and the transitions seen so far.
    planning: Option<(Plans, Model)>,
    /// With `plan: model`, after training: the learned flat and options values, which
    /// training continues from (the planned ones are in `q`).
    learned: Option<(Vec<Vec<f64>>, Vec<f64>)>,
}

/// What `plan: model` plans: the options level of a persistent task, or the legs of a reach
/// task.
#[derive(Clone, Debug)]
enum Plans {
    Options(Planner),
    Reach(ReachPlanner),
}

/// The learned values, enough to continue training.
#[derive(Clone, Debug, PartialEq)]
pub struct QTables {
    /// `flat[p][s * actions + a]`: primitive `p`'s Q-value of action `a` in state `s`.
    pub flat: Vec<Vec<f64>>,
    /// `options[obs * n_options + o]`: the value of choosing option `o` on observing `obs`.
    pub options: Vec<f64>,
    /// Primitive steps taken so far (drives the flat epsilon).
    pub steps: u64,
    /// Option choices made so far (drives the options epsilon).
    pub choices: u64,
}

/// The result of [`Learner::train`].
#[derive(Clone, Debug, PartialEq)]
pub struct Trained {
    /// The learning curve: per episode, the sum of the rewards of its options.
    pub curve: Vec<f64>,
    /// Primitive steps taken in this call.
    pub steps: u64,
}

/// The counters' dynamics laid out for the inner loop: one row of region membership per
/// state, and each bucket already multiplied by its digit's weight.
#[derive(Clone, Debug)]
struct Counters {
    /// `inside[s * k + j]`: region `j` holds in state `s`.
    inside: Vec<bool>,
    horizons: Vec<usize>,
    /// `digit[j][tau]`: the bucket of `tau` times `(B + 1)^(k - 1 - j)`; all 0 when `B = 0`.
    digit: Vec<Vec<usize>>,
}

impl Counters {
    fn new(m: &Memory) -> Counters {
        let k = m.len();
        let inside = (0..m.states()).flat_map(|s| (0..k).map(move |j| m.holds(j, s))).collect();
        let digit = (0..k)
            .map(|j| {
                let weight =
                    if m.buckets == 0 { 0 } else { (m.buckets + 1).pow((k - 1 - j) as u32) };
                (0..=m.horizons[j]).map(|t| m.bucket(j, t) * weight).collect()
            })
            .collect();
        Counters { inside, horizons: m.horizons.clone(), digit }
    }

    /// The code of `tau`.
    fn code(&self, tau: &[usize]) -> usize {
        tau.iter().zip(&self.digit).map(|(&t, d)| d[t]).sum()
    }

    /// Moves the counters on to state `next`; returns `psi` and the new code.
    #[inline]
    fn step(&self, next: usize, tau: &mut [usize]) -> (bool, usize) {
        let k = tau.len();
        let row = &self.inside[next * k..][..k];
        let (mut kept, mut code) = (true, 0);
        for (j, t) in tau.iter_mut().enumerate() {
            let n = self.horizons[j];
            *t = if row[j] { 0 } else { (*t + 1).min(n) };
            kept &= *t < n;
            code += self.digit[j][*t];
        }
        (kept, code)
    }
}

/// How an option execution and its suffixes are rewarded.
#[derive(Clone, Debug)]
enum Reward {
    /// The task's robustness over the segment (the paper's); with goals, one scorer per
    /// progress code, of the conjuncts still open (`None`: nothing is left).
    Segment(Vec<Option<TabularScorer>>),
    /// The discounted count of steps whose windows are kept.
    Window,
}

/// The trajectory of one option execution.
#[derive(Clone, Debug, Default)]
struct Run {
    /// `s_0 .. s_k`.
    states: Vec<usize>,
    /// Position in `states` where each leg starts.
    leg_starts: Vec<usize>,
    /// The options policy's observation at each position (the state without memory).
    obs: Vec<usize>,
    /// `psi` at each position (empty without counters).
    psi: Vec<bool>,
    /// The goals met at each position (empty without goals).
    met: Vec<usize>,
    /// The environment ended its episode during the option ([`Env::episode_ended`]).
    ended: bool,
}

impl<'e, E: Env> Learner<'e, E> {
    /// A learner with zeroed Q-tables. Fails when the spec is invalid, does not fit `env`,
    /// or some state has no available option.
    pub fn new(spec: &TaskSpec, env: &'e E) -> Result<Learner<'e, E>, Error> {
        let tables = Tables::new(spec, env)?;
        let memory = Memory::of_spec(spec, env)?;
        let values = memory.as_ref().map_or(1, Memory::values);
        let goals = if spec.regions.is_empty() {
            StateGoals::of_task(&spec.task, &tables.trace)
        } else {
            None
        };
        if let Some(g) = &goals {
            // `policy.json` writes the goals out: refused before training when too long.
            g.progress.goal_texts()?;
        }
        let codes = goals.as_ref().map_or(1, StateGoals::codes);
        let size = tables
            .states
            .checked_mul(values)
            .and_then(|v| v.checked_mul(codes))
            .and_then(|v| v.checked_mul(tables.legs.len()))
            .filter(|&v| v <= MAX_OPTION_VALUES);
        let Some(size) = size else {
            return Err(Error::Config(format!(
                "{} states with {values} memory values, {codes} goal codes and {} options need \
                 more than {MAX_OPTION_VALUES} options Q-values; lower memory",
                tables.states,
                tables.legs.len()
            )));
        };
        let q = QTables {
            flat: vec![vec![0.0; tables.states * tables.actions]; tables.reach.len()],
            options: vec![0.0; size],
            steps: 0,
            choices: 0,
        };
        let reward = match spec.learn.reward {
            RewardKind::Segment => Reward::Segment(match &goals {
                Some(g) => (0..g.codes())
                    .map(|mask| g.progress.rest(mask).map(|f| TabularScorer::new(f, &tables.trace)))
                    .collect(),
                None => vec![Some(TabularScorer::new(&spec.task, &tables.trace))],
            }),
            RewardKind::Window => Reward::Window,
        };
        let states = (0..tables.states).filter_map(|s| env.state(s)).collect();
        let planning = match (spec.learn.plan, &memory) {
            (Plan::Off, _) => None,
            (Plan::Model, Some(m)) => Some((
                Plans::Options(Planner::new(&tables, m, &spec.learn)?),
                Model::new(tables.states, tables.actions),
            )),
            (Plan::Model, None) => match ReachPlanner::new(spec, env, &tables)? {
                Some(p) => Some((Plans::Reach(p), Model::new(tables.states, tables.actions))),
                None => {
                    return Err(Error::Config(
                        "plan: model needs a persistent task with `memory` and `reward: window`, \
                         or a reach task `eventually[0..=T] Goal && always !R`"
                            .into(),
                    ));
                }
            },
        };
        Ok(Learner {
            env,
            spec: spec.clone(),
            tables,
            counters: memory.as_ref().map(Counters::new),
            memory,
            reward,
            q,
            tau: Vec::new(),
            code: 0,
            values,
            goals,
            codes,
            tracker: GoalTracker::default(),
            other_rewards: Vec::new(),
            gamma_powers: vec![1.0],
            states,
            flat_floor: floor_from(&spec.learn.flat),
            planning,
            learned: None,
        })
    }

    /// Continues from earlier Q-tables (for instance from a loaded `policy.json`).
    pub fn with_tables(mut self, q: QTables) -> Result<Learner<'e, E>, Error> {
        let flat_ok = q.flat.len() == self.q.flat.len()
            && q.flat.iter().all(|t| t.len() == self.tables.states * self.tables.actions);
        if !flat_ok || q.options.len() != self.q.options.len() {
            return Err(Error::Config(
                "the Q-tables do not have the shape of this spec and environment".into(),
            ));
        }
        self.q = q;
        self.learned = None;
        Ok(self)
    }

    /// The spec being learned.
    pub fn spec(&self) -> &TaskSpec {
        &self.spec
    }

    /// The environment.
    pub fn env(&self) -> &'e E {
        self.env
    }

    /// The current Q-tables.
    pub fn q(&self) -> &QTables {
        &self.q
    }

    /// The memory the options policy observes, when the spec sets `memory: B > 0`.
    pub fn memory(&self) -> Option<&Memory> {
        self.memory.as_ref().filter(|m| m.buckets > 0)
    }

    /// The greedy policies of the current Q-tables.
    pub fn agent(&self) -> crate::Agent {
        let l = &self.spec.learn;
        crate::Agent::from_q(
            &self.tables,
            &self.q,
            l.max_steps,
            self.memory(),
            self.goals.as_ref(),
            l.switch,
        )
    }

    /// The learner's per-state tables (crate-internal).
    pub(crate) fn tables(&self) -> &Tables {
        &self.tables
    }

    /// Runs `learn.episodes` episodes, calling `progress(episode, reward)` after each.
    pub fn train(&mut self, rng: &mut Rng, mut progress: impl FnMut(usize, f64)) -> Trained {
        self.train_until(rng, |episode, reward| {
            progress(episode, reward);
            ControlFlow::Continue(())
        })
    }

    /// [`Learner::train`], stopped after the episode for which `progress` breaks (a caller
    /// that was interrupted, or whose environment failed). The episodes run are those
    /// [`Learner::train`] runs, draw for draw; the curve holds the episodes done.
    pub fn train_until(
        &mut self,
        rng: &mut Rng,
        mut progress: impl FnMut(usize, f64) -> ControlFlow<()>,
    ) -> Trained {
        if let Some((flat, options)) = self.learned.take() {
            self.q.flat = flat;
            self.q.options = options;
        }
        let steps_before = self.q.steps;
        let mut run = Run::default();
        let mut rewards = Vec::new();
        let curve = train_episodes(
            self.spec.learn.episodes,
            || self.episode(rng, &mut run, &mut rewards),
            &mut progress,
        );
        self.plan();
        Trained { curve, steps: self.q.steps - steps_before }
    }

    /// With `plan: model`: the legs and the options values planned from what training has
    /// seen so far replace the learned ones, which are kept for training to continue from.
    fn plan(&mut self) {
        let Some((plans, model)) = &self.planning else { return };
        let moves = model.moves();
        let (flat, options) = match (plans, &self.memory) {
            (Plans::Options(planner), Some(memory)) => {
                let gamma = self.spec.learn.options.gamma;
                let flat = planner.quickest_legs(&self.tables, memory, &self.q.flat, &moves);
                let options = planner.options_values(&self.tables, memory, &flat, &moves, gamma);
                (flat, options)
            }
            (Plans::Reach(planner), _) => {
                let flat = planner.legs(&self.tables, &self.q.flat, &moves, model.starts());
                match &self.goals {
                    Some(g) => {
                        let layout = OptionsLayout {
                            values: self.values,
                            codes: self.codes,
                            all_met: g.progress.all_met(),
                        };
                        planner.hierarchy(
                            &self.tables,
                            &self.q.flat,
                            flat,
                            &moves,
                            model.starts(),
                            &self.q.options,
                            layout,
                        )
                    }
                    None => (flat, self.q.options.clone()),
                }
            }
            (Plans::Options(_), None) => return,
        };
        let flat = std::mem::replace(&mut self.q.flat, flat);
        self.learned = Some((flat, std::mem::replace(&mut self.q.options, options)));
    }

    fn episode(&mut self, rng: &mut Rng, run: &mut Run, rewards: &mut Vec<f64>) -> f64 {
        let start = self.env.reset(rng);
        let mut s = self.env.index(&start);
        if let Some((_, model)) = &mut self.planning {
            model.start(s);
        }
        self.begin(s);
        let mut total = 0.0;
        let choices = Choices::new(
            self.spec.learn.choices,
            self.goals.as_ref().map(|g| g.progress.all_met()),
            self.tables.legs.len(),
            &self.spec.task,
        );
        let mut steps = 0;
        for choice in 0.. {
            if !choices.go_on(choice, self.tracker.met(), steps) {
                break;
            }
            let o = self.choose_option(s, rng);
            self.run_option(o, s, rng, run);
            self.suffix_rewards(run, rewards);
            total += rewards[0];
            self.update_options(o, run, rewards);
            if self.spec.learn.counterfactual > 0 {
                self.counterfactual_updates(o, run, rng);
            }
            steps += run.states.len() - 1;
            s = *run.states.last().unwrap_or(&s);
            if run.ended {
                // The environment's episode is over: the next episode resets it.
                break;
            }
        }
        total
    }

    /// Starts an episode in state `s`: the counters take their start values, and the goals
    /// met in `s` are read.
    fn begin(&mut self, s: usize) {
        if let (Some(m), Some(c)) = (&self.memory, &self.counters) {
            m.start(s, &mut self.tau);
            self.code = c.code(&self.tau);
        }
        if let Some(g) = &self.goals {
            g.start(&mut self.tracker, s);
        }
    }

    /// What the options policy observes in state `s` with the current counters and goals.
    #[inline]
    fn observe(&self, s: usize) -> usize {
        (s * self.values + self.code) * self.codes + self.tracker.met()
    }

    fn choose_option(&mut self, s: usize, rng: &mut Rng) -> usize {
        let explore = explores(&self.spec.learn.options, None, &mut self.q.choices, rng);
        let available = &self.tables.available[s];
        if explore {
            return available[rng.random_range(0..available.len())];
        }
        let n = self.tables.legs.len();
        let row = &self.q.options[self.observe(s) * n..][..n];
        best_of(available, row)
    }

    fn run_option(&mut self, o: usize, mut s: usize, rng: &mut Rng, run: &mut Run) {
        let LearnParams { max_steps, flat, .. } = self.spec.learn;
        let Learner {
            env,
            tables,
            memory,
            q,
            counters,
            tau,
            code,
            values,
            goals,
            codes,
            tracker,
            states,
            flat_floor,
            planning,
            ..
        } = self;
        let (actions, values, codes) = (tables.actions, *values, *codes);
        run.states.clear();
        run.leg_starts.clear();
        run.obs.clear();
        run.psi.clear();
        run.met.clear();
        run.ended = false;
        run.states.push(s);
        run.obs.push((s * values + *code) * codes + tracker.met());
        if goals.is_some() {
            run.met.push(tracker.met());
        }
        if let Some(m) = memory {
            run.psi.push(m.kept(tau));
        }
        // The discounted count of the steps of a leg spent in one state: `sum gamma^k`
        // over `k < max_steps`.
        let stay_factor = if flat.gamma < 1.0 {
            (1.0 - flat.gamma.powi(max_steps.min(i32::MAX as usize) as i32)) / (1.0 - flat.gamma)
        } else {
            max_steps as f64
        };
        'legs: for &p in &tables.legs[o] {
            run.leg_starts.push(run.states.len() - 1);
            let term = &tables.term[p];
            for _ in 0..max_steps {
                let a = if explores(&flat, *flat_floor, &mut q.steps, rng) {
                    rng.random_range(0..actions)
                } else {
                    argmax(&q.flat[p][s * actions..][..actions])
                };
                let next = match states.get(s) {
                    Some(state) => env.index(&env.step(state, a, rng)),
                    None => s,
                };
                if let Some((_, model)) = planning {
                    model.record(s, a, next);
                }
                let end = env.episode_end();
                // A terminal state is one the robot would stay in for the rest of the leg.
                let stay = (end == Some(EpisodeEnd::Terminated)).then_some(stay_factor);
                update_flat(
                    &mut q.flat,
                    &tables.reach,
                    &tables.ends,
                    flat,
                    actions,
                    s * actions + a,
                    next,
                    stay,
                );
                run.states.push(next);
                if let Some(c) = counters {
                    let (kept, new_code) = c.step(next, tau);
                    *code = new_code;
                    run.psi.push(kept);
                }
                run.obs.push((next * values + *code) * codes + tracker.met());
                if let Some(g) = goals {
                    g.push(tracker, next);
                    run.met.push(tracker.met());
                }
                s = next;
                if end.is_some() {
                    run.ended = true;
                    break;
                }
                if term[next] {
                    break;
                }
            }
            // A leg ends where a goal's region is entered: the observation from here on
            // says so.
            if let Some(g) = goals {
                let met = tracker.read(&g.progress);
                if let (Some(m), Some(obs)) = (run.met.last_mut(), run.obs.last_mut()) {
                    *m = met;
                    *obs = (s * values + *code) * codes + met;
                }
            }
            if run.ended {
                break 'legs;
            }
        }
    }

    /// The counterfactual updates after option `o` ran along `run`: for
    /// `learn.counterfactual` memory values drawn at random (a bucket per region, then a
    /// counter value inside it; 0 for a region the start state satisfies), the counters
    /// are run along the same states, and the options value of that start observation is
    /// updated with the window reward the run would have earned from it.
    fn counterfactual_updates(&mut self, o: usize, run: &Run, rng: &mut Rng) {
        let (Some(m), Some(c)) = (&self.memory, &self.counters) else { return };
        let n = self.tables.legs.len();
        let params = self.spec.learn.options;
        let (s0, end) = (run.states[0], run.states[run.states.len() - 1]);
        let b = m.buckets;
        let mut tau = Vec::with_capacity(m.len());
        'samples: for _ in 0..self.spec.learn.counterfactual {
            tau.clear();
            for j in 0..m.len() {
                let horizon = m.horizons[j];
                if m.holds(j, s0) {
                    tau.push(0);
                    continue;
                }
                let bucket = rng.random_range(0..=b);
                if bucket == b {
                    tau.push(horizon);
                    continue;
                }
                // The counter values of the bucket, from 1: outside its region tau > 0.
                let lo = (bucket * horizon).div_ceil(b).max(1);
                let hi = ((bucket + 1) * horizon).div_ceil(b);
                if lo >= hi {
                    continue 'samples;
                }
                tau.push(rng.random_range(lo..hi));
            }
            let met = (run.met.first().copied().unwrap_or(0), run.met.last().copied().unwrap_or(0));
            let start = (s0 * self.values + c.code(&tau)) * self.codes + met.0;
            let (mut reward, mut discount, mut code) = (0.0, 1.0, 0);
            for &s in &run.states[1..] {
                let (kept, next_code) = c.step(s, &mut tau);
                if kept {
                    reward += discount;
                }
                discount *= params.gamma;
                code = next_code;
            }
            let end_row = ((end * self.values + code) * self.codes + met.1) * n;
            let best = self.tables.available[end]
                .iter()
                .map(|&a| self.q.options[end_row + a])
                .fold(f64::NEG_INFINITY, f64::max);
            let cell = &mut self.q.options[start * n + o];
            *cell += params.alpha * (reward + discount * best - *cell);
        }
    }

    fn update_options(&mut self, o: usize, run: &Run, rewards: &[f64]) {
        let n = self.tables.legs.len();
        let params = self.spec.learn.options;
        let k = run.states.len() - 1;
        let end = run.states[k];
        let end_row = run.obs[k] * n;
        // Every suffix bootstraps from the same end state, read before any update so that
        // the order of the updates below changes only their shared cells.
        let best = self.tables.available[end]
            .iter()
            .map(|&b| self.q.options[end_row + b])
            .fold(f64::NEG_INFINITY, f64::max);
        gamma_powers_to(&mut self.gamma_powers, params.gamma, k);
        let remaining = self.spec.learn.intra == Intra::Remaining;
        let mut leg = 0;
        for (j, (&s, &reward)) in run.states[..k].iter().zip(rewards).enumerate() {
            let credited = if j == 0 || !remaining {
                Some(o)
            } else {
                while leg + 1 < run.leg_starts.len() && run.leg_starts[leg + 1] <= j {
                    leg += 1;
                }
                self.tables.remaining[o][leg].filter(|r| self.tables.available[s].contains(r))
            };
            // A NaN reward: a suffix the scorer's budget left unscored.
            let Some(c) = credited.filter(|_| !reward.is_nan()) else { continue };
            let target = reward + self.gamma_powers[k - j] * best;
            let cell = &mut self.q.options[run.obs[j] * n + c];
            *cell += params.alpha * (target - *cell);
        }
    }
}

impl<E: Env> Learner<'_, E> {
    /// `out[j]`: the reward of the suffix of `run` from position `j` (`out[k] = 0` for the
    /// window reward).
    fn suffix_rewards(&mut self, run: &Run, out: &mut Vec<f64>) {
        match &mut self.reward {
            Reward::Segment(scorers) => {
                let k = run.states.len() - 1;
                let mut score = |met: usize, into: &mut Vec<f64>| match scorers.get_mut(met) {
                    Some(Some(scorer)) => scorer.suffix_rewards(&run.states, into),
                    _ => {
                        into.clear();
                        into.resize(k + 1, 0.0);
                    }
                };
                // Goals met along the run: the positions after score against the rest.
                let mut other = std::mem::take(&mut self.other_rewards);
                episode::goal_suffix_rewards(&run.met, k, out, &mut other, &mut score);
                self.other_rewards = other;
            }
            Reward::Window => {
                episode::window_suffix_rewards(&run.psi, self.spec.learn.options.gamma, out);
            }
        }
    }
}

/// The flat update of every primitive after the step from cell `cell` (state times
/// actions plus action) into state `next`: each table bootstraps from its own best value at
/// `next`, with reward `reach_p[next]`; a primitive whose avoided region holds `next` does
/// not bootstrap: its reward there is already the whole value of entering. `stay`: `next`
/// is a terminal state of the environment, where the robot would stay, each step earning
/// `reach_p[next]`; its value is that reward times `stay` (the discounted steps left).
#[inline]
#[allow(clippy::too_many_arguments)]
fn update_flat(
    tables: &mut [Vec<f64>],
    reach: &[Vec<f64>],
    ends: &[Option<Vec<bool>>],
    flat: LevelParams,
    actions: usize,
    cell: usize,
    next: usize,
    stay: Option<f64>,
) {
    for ((q, reach), ends) in tables.iter_mut().zip(reach).zip(ends) {
        let ends = ends.as_ref().is_some_and(|a| a[next]);
        let best = match stay {
            _ if ends => 0.0,
            Some(stay) => reach[next] * stay,
            None => max_of(&q[next * actions..][..actions]),
        };
        let cell = &mut q[cell];
        *cell += flat.alpha * (reach[next] + flat.gamma * best - *cell);
    }
}

#[cfg(test)]
mod tests {
    use hstl_robustness::{Bound, CmpOp, Expr, Formula, Interval};

    use super::*;
    use crate::spec::{CombinedOption, LevelParams, PrimitiveOption, StateVar, Terminate};
    use crate::{GridWorld, seeded_rng};

    /// `x op c` on the one-row grids below.
    fn x(op: CmpOp, c: f64) -> Formula {
        Formula::cmp(Expr::var(0), op, Expr::constant(c))
    }

    /// A 5 x 1 deterministic line: P1 reaches `x > 1` (stops there), P2 reaches `x > 3`
    /// (stops at the argmax x = 4); options [P1, P2] and [P2]; task
    /// `!always[0..10] x >= 1` (`eventually[0..10] x < 1` written without a goal, so that
    /// the options table is the state's alone), so the suffix from `x_j` on a rightward run
    /// earns `1 - x_j`.
    fn line(intra: Intra, max_steps: usize, p2_terminate: Terminate) -> TaskSpec {
        let prim = |name: &str, reach: Formula, terminate| PrimitiveOption {
            name: name.into(),
            reach,
            init: Formula::bool(true),
            terminate,
            avoid: None,
        };
        TaskSpec {
            name: "Line".into(),
            state_vars: vec![
                StateVar { name: "x".into(), domain: Some(0..=4) },
                StateVar { name: "y".into(), domain: Some(0..=0) },
            ],
            task: Formula::not(Formula::always(
                Interval { start: 0, end: Bound::Exclusive(10) },
                x(CmpOp::Ge, 1.0),
            )),
            primitives: vec![
                prim("P1", x(CmpOp::Gt, 1.0), Terminate::Formula(x(CmpOp::Gt, 1.0))),
                prim("P2", x(CmpOp::Gt, 3.0), p2_terminate),
            ],
            options: vec![
                CombinedOption { name: "P1P2".into(), sequence: vec![0, 1] },
                CombinedOption { name: "P2".into(), sequence: vec![1] },
            ],
            learn: LearnParams {
                max_steps,
                intra,
                flat: LevelParams { epsilon: 0.0, min_epsilon: 0.0, ..LevelParams::FLAT },
                options: LevelParams { epsilon: 0.0, min_epsilon: 0.0, ..LevelParams::OPTIONS },
                ..LearnParams::default()
            },
            regions: vec![],
        }
    }

    /// A learner on the line whose flat policies all go Right (action 3), with
    /// `Q(x=4, [P2]) = 2` so that the bootstrap is not zero.
    fn rightward<'e>(spec: &TaskSpec, env: &'e GridWorld) -> Learner<'e, GridWorld> {
        let learner = Learner::new(spec, env).unwrap();
        let mut q = learner.q().clone();
        for t in &mut q.flat {
            for s in 0..5 {
                t[s * 4 + 3] = 1.0;
            }
        }
        q.options[4 * 2 + 1] = 2.0;
        learner.with_tables(q).unwrap()
    }

    fn run(learner: &mut Learner<'_, GridWorld>, o: usize, s: usize) -> (Run, Vec<f64>) {
        let mut rng = seeded_rng(0);
        let mut run = Run::default();
        let mut rewards = Vec::new();
        learner.begin(s);
        learner.run_option(o, s, &mut rng, &mut run);
        learner.suffix_rewards(&run, &mut rewards);
        learner.update_options(o, &run, &rewards);
        (run, rewards)
    }

    #[test]
    fn intra_option_updates_match_a_hand_computed_example() {
        let env = GridWorld::new(5, 1, 1.0).unwrap();
        // (intra, the option credited for the suffix from x_j, j = 0..4)
        let cases = [(Intra::Paper, [0, 0, 0, 0]), (Intra::Remaining, [0, 0, 1, 1])];
        for (intra, credited) in cases {
            let spec = line(intra, 500, Terminate::Argmax);
            let mut learner = rightward(&spec, &env);
            let (run, rewards) = run(&mut learner, 0, 0);
            assert_eq!(run.states, [0, 1, 2, 3, 4]);
            assert_eq!(run.leg_starts, [0, 2]);
            assert_eq!(rewards[..4], [1.0, 0.0, -1.0, -2.0]);
            for j in 0..4 {
                // alpha (r_j + gamma^(4-j) * max_o Q(x=4, o) - 0), max = 2.
                let want = 0.5 * ((1.0 - j as f64) + 0.9f64.powi(4 - j as i32) * 2.0);
                let q = &learner.q().options;
                // `powi` may round differently where the optimiser folds it (release).
                let got = q[j * 2 + credited[j]];
                assert!((got - want).abs() <= 1e-12 * want.abs(), "{intra:?} suffix {j}: {got}");
                assert_eq!(q[j * 2 + 1 - credited[j]], 0.0, "{intra:?} suffix {j}");
            }
        }
    }

    /// The line again with a persistent task `always[0..] (eventually[0..6] x < 1 &&
    /// eventually[0..6] x > 3)`, `memory: 2`, `reward: window`, options gamma 0.5 and alpha
    /// 0.5; options Right (reach and stop at `x > 3`, start where `x < 4`) and Left (reach
    /// and stop at `x < 1`, start where `x > 0`).
    fn persistent_line() -> TaskSpec {
        let (r1, r2) = (x(CmpOp::Lt, 1.0), x(CmpOp::Gt, 3.0));
        let window = Interval { start: 0, end: Bound::Exclusive(6) };
        let ev = |r: &Formula| Formula::eventually(window, r.clone());
        let prim = |name: &str, reach: &Formula, init| PrimitiveOption {
            name: name.into(),
            reach: reach.clone(),
            init,
            terminate: Terminate::Formula(reach.clone()),
            avoid: None,
        };
        let mut spec = line(Intra::Paper, 500, Terminate::Argmax);
        spec.task = Formula::always(Interval::ALL, Formula::and(vec![ev(&r1), ev(&r2)]));
        spec.primitives =
            vec![prim("Right", &r2, x(CmpOp::Lt, 4.0)), prim("Left", &r1, x(CmpOp::Gt, 0.0))];
        spec.options = vec![
            CombinedOption { name: "Right".into(), sequence: vec![0] },
            CombinedOption { name: "Left".into(), sequence: vec![1] },
        ];
        spec.regions = spec.regions_from_task().unwrap();
        spec.learn.memory = 2;
        spec.learn.reward = RewardKind::Window;
        spec.learn.options.gamma = 0.5;
        spec
    }

    #[test]
    fn window_rewards_and_memory_updates_match_a_hand_computed_example() {
        let env = GridWorld::new(5, 1, 1.0).unwrap();
        let spec = persistent_line();
        let learner = Learner::new(&spec, &env).unwrap();
        // Right's flat policy goes Right (3), Left's goes Left (2); Q(obs 1, Right) = 2:
        // the bootstrap at the end of the second run below (x = 0, b = [0, 1]).
        let mut q = learner.q().clone();
        for s in 0..5 {
            q.flat[0][s * 4 + 3] = 10.0;
            q.flat[1][s * 4 + 2] = 10.0;
        }
        q.options[2] = 2.0;
        let mut learner = learner.with_tables(q).unwrap();
        let mut rng = seeded_rng(0);
        let (mut run, mut rewards) = (Run::default(), Vec::new());
        // Run 1: Right from x = 0, where R1 holds: tau = (0, N) = (0, 6).
        learner.begin(0);
        learner.run_option(0, 0, &mut rng, &mut run);
        learner.suffix_rewards(&run, &mut rewards);
        assert_eq!(run.states, [0, 1, 2, 3, 4]);
        // tau: (0,6) (1,6) (2,6) (3,6) (4,0); buckets floor(2 tau / 6), 2 when expired:
        // (0,2) (0,2) (0,2) (1,2) (1,0); obs = x * 9 + 3 b_1 + b_2.
        assert_eq!(run.obs, [2, 11, 20, 32, 39]);
        assert_eq!(run.psi, [false, false, false, false, true]);
        // R_j = sum_{m=1..4-j} 0.5^(m-1) psi(j + m).
        assert_eq!(rewards, [0.125, 0.25, 0.5, 1.0, 0.0]);
        learner.update_options(0, &run, &rewards);
        // Q(39, Left) = 0 at the end (only Left can start at x = 4): alpha R_j.
        for (j, &obs) in run.obs[..4].iter().enumerate() {
            assert_eq!(learner.q().options[obs * 2], 0.5 * rewards[j], "run 1, suffix {j}");
        }
        // Run 2: Left from x = 4, the memory carried over: tau (4,0) (5,1) (6,2) (6,3) (0,4).
        learner.run_option(1, 4, &mut rng, &mut run);
        learner.suffix_rewards(&run, &mut rewards);
        assert_eq!(run.states, [4, 3, 2, 1, 0]);
        assert_eq!(run.obs, [39, 30, 24, 16, 1]);
        assert_eq!(run.psi, [true, true, false, false, true]);
        assert_eq!(rewards, [1.125, 0.25, 0.5, 1.0, 0.0]);
        learner.update_options(1, &run, &rewards);
        // Each suffix from its own state and memory, bootstrapping from (x = 0, b = [0, 1]):
        // alpha (R_j + 0.5^(4-j) * 2).
        let want = [0.625, 0.25, 0.5, 1.0];
        for (j, &obs) in run.obs[..4].iter().enumerate() {
            assert_eq!(learner.q().options[obs * 2 + 1], want[j], "run 2, suffix {j}");
        }
        // The greedy agent sees the same observations.
        let agent = learner.agent();
        assert_eq!(agent.options.len(), 5 * 9);
        assert_eq!(agent.options[39], 1);
        // Inside R1 (x = 0) b_1 is 0: codes with b_1 > 0 cannot occur there.
        assert_eq!(agent.options[3], usize::MAX);
    }

    /// A counterfactual update starts the counters of the unvisited region from a drawn
    /// bucket and scores the same run from there. On the line, Right from x = 0 (R1 holds
    /// there, so tau_1 = 0) to x = 4 (R2), with tau_2 drawn as t: psi at the four steps is
    /// tau_2 = t + 1, t + 2, t + 3 below 6, then R2 holds. By hand, with gamma 0.5: t in
    /// 1..3 (bucket 0) earns 1.875; t = 3, 4, 5 (bucket 1) 1.625, 1.125, 0.125; expired
    /// (bucket 2) 0.125. The Q-values start at 0: the cell becomes alpha times that.
    #[test]
    fn counterfactual_updates_score_the_run_from_a_drawn_memory() {
        let env = GridWorld::new(5, 1, 1.0).unwrap();
        let mut spec = persistent_line();
        spec.learn.counterfactual = 1;
        let learner = Learner::new(&spec, &env).unwrap();
        let mut q = learner.q().clone();
        for s in 0..5 {
            q.flat[0][s * 4 + 3] = 10.0;
        }
        let zero = learner.with_tables(q).unwrap();
        let allowed = [vec![1.875], vec![1.625, 1.125, 0.125], vec![0.125]];
        let mut seen = [false; 3];
        let mut rng = seeded_rng(7);
        for _ in 0..40 {
            let mut learner = zero.clone();
            let mut run = Run::default();
            learner.begin(0);
            learner.run_option(0, 0, &mut rng, &mut run);
            learner.counterfactual_updates(0, &run, &mut rng);
            // Only the options of state 0 (observations 0..9) with b_1 = 0 may change, and
            // only option Right (column 0).
            let changed: Vec<usize> =
                (0..learner.q().options.len()).filter(|&i| learner.q().options[i] != 0.0).collect();
            assert_eq!(changed.len(), 1, "{changed:?}");
            let (obs, o) = (changed[0] / 2, changed[0] % 2);
            assert_eq!(o, 0);
            assert!(obs < 3, "state 0 with b_1 = 0: {obs}");
            let value = learner.q().options[changed[0]] / 0.5;
            assert!(allowed[obs].contains(&value), "bucket {obs}: {value}");
            seen[obs] = true;
        }
        assert_eq!(seen, [true; 3], "every bucket is drawn");
    }

    #[test]
    fn without_memory_the_window_reward_sees_the_state_alone() {
        let env = GridWorld::new(5, 1, 1.0).unwrap();
        let mut spec = persistent_line();
        spec.learn.memory = 0;
        let mut learner = Learner::new(&spec, &env).unwrap();
        assert_eq!(learner.q().options.len(), 5 * 2);
        assert!(learner.memory().is_none());
        let mut q = learner.q().clone();
        for s in 0..5 {
            q.flat[0][s * 4 + 3] = 10.0;
        }
        learner = learner.with_tables(q).unwrap();
        let (mut run, mut rewards) = (Run::default(), Vec::new());
        learner.begin(0);
        learner.run_option(0, 0, &mut seeded_rng(0), &mut run);
        learner.suffix_rewards(&run, &mut rewards);
        assert_eq!(run.obs, [0, 1, 2, 3, 4]);
        assert_eq!(rewards, [0.125, 0.25, 0.5, 1.0, 0.0]);
    }

    /// `avoid` on the line: P2 (reach `x > 3`, stop at x = 4) avoids `1.5 < x < 2.5`, the
    /// cell x = 2. Its flat reward elsewhere is `min(rho(x > 3), -rho(avoid))`, inside it the
    /// worst of those less one, forever: (-3 - 1) / (1 - 0.9) = -40; the leg stops there and
    /// the flat update into it does not bootstrap. P1 is left as it was.
    #[test]
    fn avoid_shapes_the_flat_reward_and_stops_the_leg() {
        let env = GridWorld::new(5, 1, 1.0).unwrap();
        let mut spec = line(Intra::Paper, 500, Terminate::Argmax);
        let band = Formula::and(vec![x(CmpOp::Gt, 1.5), x(CmpOp::Lt, 2.5)]);
        spec.primitives[1].avoid = Some(band);
        let learner = Learner::new(&spec, &env).unwrap();
        let t = learner.tables();
        let penalty = -4.0 * (1.0 / (1.0 - 0.9));
        assert_eq!(t.reach[1], [-3.0, -2.0, penalty, 0.0, 1.0]);
        assert_eq!(t.term[1], [false, false, true, false, true]);
        assert_eq!(t.ends[1].as_deref(), Some(&[false, false, true, false, false][..]));
        assert_eq!(t.reach[0], [-1.0, 0.0, 1.0, 2.0, 3.0]);
        assert!(t.ends[0].is_none());
        // Bootstrapping values at x = 2 that the update into it must not read.
        let mut q = learner.q().clone();
        for table in &mut q.flat {
            table[2 * 4..3 * 4].fill(5.0);
        }
        let mut learner = learner.with_tables(q).unwrap();
        let mut run = Run::default();
        learner.begin(1);
        // P2's option from x = 1 goes Right (ties go to the lowest action, Up, which stays:
        // make Right the best).
        let mut q = learner.q().clone();
        q.flat[1][4 + 3] = 1.0;
        learner = learner.with_tables(q).unwrap();
        learner.run_option(1, 1, &mut seeded_rng(0), &mut run);
        assert_eq!(run.states, [1, 2], "the leg stops on entering the avoided cell");
        // P2: 1 + 0.2 (-40 + 0 - 1); P1: 0 + 0.2 (1 + 0.9 * 5 - 0).
        assert_eq!(learner.q().flat[1][4 + 3], 1.0 + 0.2 * (penalty - 1.0));
        assert_eq!(learner.q().flat[0][4 + 3], 0.2 * (1.0 + 0.9 * 5.0));
    }

    #[test]
    fn options_run_at_least_one_step_and_are_cut_off() {
        let env = GridWorld::new(5, 1, 1.0).unwrap();
        // Starting in P2's termination set still takes a step (Right at x = 4 stays).
        let spec = line(Intra::Paper, 500, Terminate::Argmax);
        let mut learner = rightward(&spec, &env);
        assert_eq!(run(&mut learner, 1, 4).0.states, [4, 4]);
        // A leg that never terminates is cut off after max_steps steps, then the next runs.
        let spec = line(Intra::Paper, 3, Terminate::Formula(Formula::bool(false)));
        let mut learner = rightward(&spec, &env);
        let (r, _) = run(&mut learner, 1, 0);
        assert_eq!(r.states, [0, 1, 2, 3]);
        let (r, _) = run(&mut learner, 0, 0);
        assert_eq!(r.states, [0, 1, 2, 3, 4, 4]);
        assert_eq!(r.leg_starts, [0, 2]);
    }

    /// From `floor_from` on, `epsilon_at` is `min_epsilon`; just before, it is above.
    #[test]
    fn the_epsilon_floor_starts_where_epsilon_at_reaches_it() {
        let level = |epsilon, min_epsilon, decay| LevelParams {
            epsilon,
            min_epsilon,
            decay,
            ..LevelParams::FLAT
        };
        // (level, the floor when it is known exactly; `Some(None)`: there is none)
        let cases = [
            (LevelParams::FLAT, None),
            (LevelParams::OPTIONS, None),
            (level(0.9, 0.1, 1.0 / 3.0), None),
            (level(0.3, 0.3, 1e-3), Some(Some(0))),
            (level(0.5, 0.0, 0.0), Some(None)),
            (level(1.0, 0.1, 1e300), Some(Some(1))),
        ];
        for (level, want) in cases {
            let floor = floor_from(&level);
            assert_eq!(floor.is_none(), want == Some(None), "{level:?}");
            if let Some(want) = want {
                assert_eq!(floor, want, "{level:?}");
            }
            if let Some(f) = floor {
                for n in [f, f + 1, f + 1000, u64::MAX] {
                    assert_eq!(level.epsilon_at(n), level.min_epsilon, "{level:?} at {n}");
                }
                if f > 0 {
                    assert!(level.epsilon_at(f - 1) > level.min_epsilon, "{level:?}");
                }
            }
        }
    }

    #[test]
    fn only_available_options_are_chosen() {
        let env = GridWorld::new(5, 1, 1.0).unwrap();
        let mut spec = line(Intra::Paper, 500, Terminate::Argmax);
        // [P1, P2] may start only where x < 2.
        spec.primitives[0].init = x(CmpOp::Lt, 2.0);
        spec.learn.options = LevelParams { epsilon: 1.0, min_epsilon: 1.0, ..LevelParams::OPTIONS };
        let mut learner = Learner::new(&spec, &env).unwrap();
        let mut rng = seeded_rng(3);
        for s in 0..5 {
            let chosen: Vec<usize> = (0..200).map(|_| learner.choose_option(s, &mut rng)).collect();
            assert_eq!(chosen.contains(&0), s < 2, "state {s}");
            assert!(chosen.contains(&1));
        }
        // An option set with a state where nothing may start is rejected up front.
        spec.primitives[1].init = x(CmpOp::Lt, 2.0);
        let err = Learner::new(&spec, &env).unwrap_err();
        assert!(err.to_string().contains("no option of the set can start"), "{err}");
    }

    /// The persistent line with `plan: model`, exploring enough to try every move.
    fn planned_line(episodes: usize) -> TaskSpec {
        let mut spec = persistent_line();
        spec.learn.plan = Plan::Model;
        spec.learn.episodes = episodes;
        spec.learn.choices = 20;
        spec.learn.flat = LevelParams { epsilon: 0.5, min_epsilon: 0.5, ..LevelParams::FLAT };
        spec.learn.options =
            LevelParams { epsilon: 0.5, min_epsilon: 0.5, gamma: 0.5, ..LevelParams::OPTIONS };
        spec
    }

    #[test]
    fn planning_gives_the_quickest_legs_and_the_options_values_of_the_counters() {
        // Deterministic: Right (x > 3, x = 4) is 4 - x steps away by action 3 (Right).
        let env = GridWorld::new(5, 1, 1.0).unwrap();
        let spec = planned_line(50);
        let mut learner = Learner::new(&spec, &env).unwrap();
        learner.train(&mut seeded_rng(3), |_, _| {});
        let right = &learner.q().flat[0];
        for x in 0..4 {
            let row = &right[x * 4..][..4];
            let steps = (4 - x) as f64;
            // Up and Down stay, Left moves away (or stays at x = 0).
            let left = if x == 0 { steps + 1.0 } else { steps + 2.0 };
            assert_eq!(row, [-(steps + 1.0), -(steps + 1.0), -left, -steps], "x = {x}");
        }
        // From x = 0 each leg takes 4 steps and psi(m) = [tau_2 + m < 6 or m = 4] (gamma
        // 0.5, windows of 6). At arrival the other counter is 4, from where the next leg
        // earns 1 + 0.125 and then the same again: v = 1.125 + 0.5^4 v, v = 1.2. Memory
        // B = 2 values tau_2 by the middle of its bucket: 2 in bucket 0, 4 in bucket 1, 6 (expired).
        let values = 9;
        let q = &learner.q().options;
        let want = [(0, 1.875 + 0.0625 * 1.2), (1, 1.2), (2, 0.125 + 0.0625 * 1.2)];
        for (bucket, v) in want {
            let got = q[bucket * 2];
            assert!((got - v).abs() < 1e-4, "bucket {bucket}: {got} against {v}");
        }
        assert_eq!(q.len(), 5 * values * 2);
    }

    #[test]
    fn planned_training_in_chunks_equals_training_whole() {
        let env = GridWorld::new(5, 1, 0.8).unwrap();
        let mut whole = Learner::new(&planned_line(40), &env).unwrap();
        whole.train(&mut seeded_rng(11), |_, _| {});
        let mut chunks = Learner::new(&planned_line(20), &env).unwrap();
        let mut rng = seeded_rng(11);
        chunks.train(&mut rng, |_, _| {});
        chunks.train(&mut rng, |_, _| {});
        assert_eq!(whole.q(), chunks.q());
        // And the planned tables differ from the learned ones.
        let mut off = planned_line(40);
        off.learn.plan = Plan::Off;
        let mut learned = Learner::new(&off, &env).unwrap();
        learned.train(&mut seeded_rng(11), |_, _| {});
        assert_eq!(learned.q().steps, whole.q().steps);
        assert_ne!(learned.q().options, whole.q().options);
    }

    #[test]
    fn plan_refuses_options_it_cannot_plan() {
        let env = GridWorld::new(5, 1, 1.0).unwrap();
        let mut spec = planned_line(10);
        spec.options.push(CombinedOption { name: "RightLeft".into(), sequence: vec![0, 1] });
        let err = Learner::new(&spec, &env).unwrap_err().to_string();
        assert!(err.contains("plan: model needs every option to be one leg"), "{err}");
        let mut spec = planned_line(10);
        spec.learn.options.gamma = 1.0;
        let err = Learner::new(&spec, &env).unwrap_err().to_string();
        assert!(err.contains("options gamma below 1"), "{err}");
        let mut spec = planned_line(10);
        spec.learn.memory = 0;
        let err = Learner::new(&spec, &env).unwrap_err().to_string();
        assert!(err.contains("plan: model needs a memory"), "{err}");
    }

    #[test]
    fn plan_refuses_a_world_too_large_to_plan_before_training() {
        // Two regions of 20,000 cells each, windows of 500 steps: far past the budget.
        let env = GridWorld::new(400, 100, 1.0).unwrap();
        let mut spec = planned_line(10);
        spec.state_vars[0].domain = Some(0..=399);
        spec.state_vars[1].domain = Some(0..=99);
        let (r1, r2) = (x(CmpOp::Lt, 200.0), x(CmpOp::Gt, 199.0));
        let window = Interval { start: 0, end: Bound::Exclusive(500) };
        spec.task = Formula::always(
            Interval::ALL,
            Formula::and(vec![
                Formula::eventually(window, r1.clone()),
                Formula::eventually(window, r2.clone()),
            ]),
        );
        for (p, (r, other)) in spec.primitives.iter_mut().zip([(&r2, &r1), (&r1, &r2)]) {
            p.reach = r.clone();
            p.terminate = Terminate::Formula(r.clone());
            p.init = other.clone();
        }
        spec.regions = spec.regions_from_task().unwrap();
        let err = Learner::new(&spec, &env).unwrap_err().to_string();
        assert!(err.contains("plan: model over 40000 states"), "{err}");
        assert!(err.contains("`plan: off`"), "{err}");
    }
}
