//! Greedy rollouts, sample runs, and the window rate of persistent tasks.
//!
//! **Window rate.** For a task `always[0..] (eventually[0..N1] R1 && ... && eventually[0..Nk]
//! Rk)`, step `t` of a rollout keeps its windows when, for every region `j`, `R_j` held at
//! some step of the `N_j`-step window `t-N_j+1 ..= t` ending at `t`; regions with
//! different `N_j` are each checked over their own window, and step `t` counts once. This
//! is `psi(t)` of LANGUAGE.md: `tau_j` (steps since `R_j` last held) starts at `N_j`, or 0
//! when the start state satisfies `R_j`. The rate is the share of the steps
//! `burn_in..steps` with `psi(t) = 1`, pooled over all rollouts.

use hstl_robustness::{Trace, complete, offline, reference};

use crate::progress::GoalTracker;
use crate::{Agent, Env, Error, Rng, Switch, TaskSpec};

/// Decides actions step by step: a greedy [`Agent`] or a hand-written controller.
pub trait Controller {
    /// Forgets any execution in progress; the next step starts afresh.
    fn reset(&mut self);
    /// The decision in state `s` (a state index).
    fn act(&mut self, s: usize) -> Decision;
    /// Sees the state the last action led to.
    fn observe(&mut self, next: usize);
}

/// One decision of a [`Controller`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Decision {
    /// The action taken.
    pub action: usize,
    /// The running option (or phase, for a hand-written controller).
    pub option: usize,
    /// The leg of that option.
    pub leg: usize,
}

/// One step of a rollout: the state, what was decided there, and where it led.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    /// The state index.
    pub state: usize,
    /// The decision taken in it.
    pub decision: Decision,
    /// The state the decision's action led to (the next step's state); comparing it with
    /// where the action leads without slipping shows the slips.
    pub next: usize,
}

/// How the window rate is measured.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct WindowConfig {
    /// Rollouts, each from a random start (`env.reset`).
    pub starts: usize,
    /// Steps per rollout.
    pub steps: usize,
    /// Steps at the start of each rollout that are not counted.
    pub burn_in: usize,
}

/// The window rate of a controller, with the task's robustness over each rollout.
#[derive(Clone, Debug, PartialEq)]
pub struct WindowReport {
    /// The share of counted steps whose windows all visit their region.
    pub rate: f64,
    /// The window rate of each rollout.
    pub per_rollout: Vec<f64>,
    /// The task's robustness `rho(task, 0)` over each whole rollout, windows clipped at
    /// its end.
    pub robustness: Vec<f64>,
    /// The same over complete windows ([`hstl_robustness::complete`]): `None` for a
    /// rollout too short for any.
    pub complete: Vec<Option<f64>>,
    /// For a task `always[0..] f`: the share of each rollout's complete steps where `f`
    /// holds (robustness above 0), the task kept window by window; `None` for a rollout
    /// too short for a complete window.
    pub kept: Vec<Option<f64>>,
}

/// Region membership per state index, for the window rate.
#[derive(Clone, Debug, PartialEq)]
pub struct RegionTable {
    /// `holds[j][s]`: region `j` holds in state `s`.
    pub holds: Vec<Vec<bool>>,
    /// `N_j` of each region.
    pub horizons: Vec<usize>,
    /// Row `s`: state `s`'s values in the spec's variable order.
    trace: Trace,
    task: hstl_robustness::Formula,
    /// `f` of a task `always[0..] f`.
    body: Option<hstl_robustness::Formula>,
}

/// A greedy [`Agent`] executing options: the options policy picks an option where none
/// runs, its legs follow their flat policies greedily. An agent with memory has its
/// counters tracked along the run (from the first state after each reset), and picks on
/// the state and buckets; an agent with goals reads the goals the run has met where a leg
/// ends, as the learner does.
#[derive(Clone, Debug)]
pub struct AgentController<'a> {
    agent: &'a Agent,
    running: Option<(usize, usize, usize)>,
    tau: Vec<usize>,
    goals: GoalTracker,
    fresh: bool,
}

/// The learned legs driven through a fixed cycle of primitive options: run the flat
/// policy of each primitive in turn until it terminates (or is cut off), then the next.
/// With the nearest-cell [`EntryCycle`] it separates how good the legs are from how good
/// the options policy's choices are.
#[derive(Clone, Debug)]
pub struct LegCycle<'a> {
    agent: &'a Agent,
    cycle: Vec<usize>,
    phase: usize,
    steps: usize,
}

/// The hand-written "nearest-cell entry cycle" on a [`crate::GridWorld`]: visit the regions in
/// turn; in each phase head for the nearest cell of the current region (by shortest path
/// around the walls; the first such cell, row by row from the bottom, on a tie), along a
/// shortest path that moves along x first where it can, and switch to the next region on
/// entering it. On a map without walls the paths are the Manhattan moves.
#[derive(Clone, Debug)]
pub struct EntryCycle {
    /// Per region, its cells' states and each one's distance from every state.
    targets: Vec<Vec<(usize, Vec<u32>)>>,
    holds: Vec<Vec<bool>>,
    /// Per state and action, the state it leads to without slipping.
    dest: Vec<[usize; 4]>,
    phase: usize,
}

/// At most this many distances (region cells times states) for an [`EntryCycle`].
pub const MAX_ENTRY_CYCLE_DISTANCES: usize = 1 << 26;

impl Default for WindowConfig {
    /// 100 rollouts of 2000 steps, the first 100 not counted.
    fn default() -> WindowConfig {
        WindowConfig { starts: 100, steps: crate::progress::UNBOUNDED_RUN_STEPS, burn_in: 100 }
    }
}

impl RegionTable {
    /// The regions of `spec` over `env`'s states. Fails when the task has no regions or the
    /// spec does not fit the environment.
    pub fn new<E: Env>(spec: &TaskSpec, env: &E) -> Result<RegionTable, Error> {
        if spec.regions.is_empty() {
            return Err(Error::Config(
                "the window rate needs a task of the form always[0..] (eventually[0..N1] R1 \
                 && ...) and its regions"
                    .into(),
            ));
        }
        let trace = crate::tables::valuations(spec, env)?;
        let holds = spec
            .regions
            .iter()
            .map(|r| {
                (0..trace.len())
                    .map(|s| reference::robustness(&r.formula, &trace, s) > 0.0)
                    .collect()
            })
            .collect();
        let horizons = spec.regions.iter().map(|r| r.horizon).collect();
        let body = reference::persistent_body(&spec.task).map(|(b, _)| spec.task.sub(b));
        Ok(RegionTable { holds, horizons, trace, task: spec.task.clone(), body })
    }

    /// The task's robustness over the states of a rollout (by the offline evaluator, which
    /// gives the reference evaluator's values in linear time).
    pub fn robustness(&self, states: &[usize]) -> f64 {
        self.rollout_trace(states).map_or(f64::NAN, |t| offline::robustness(&self.task, &t))
    }

    /// The task's robustness over a rollout, over complete windows: `None` when the
    /// rollout is too short for step 0's windows.
    pub fn complete_robustness(&self, states: &[usize]) -> Option<f64> {
        complete::robustness(&self.task, &self.rollout_trace(states)?)
    }

    /// For a task `always[0..] f`, the share of the rollout's complete steps where `f`
    /// holds; `None` for another task or a rollout too short for a complete window.
    pub fn kept_share(&self, states: &[usize]) -> Option<f64> {
        let signal = complete::signal(self.body.as_ref()?, &self.rollout_trace(states)?);
        let kept = signal.iter().filter(|&&v| v > 0.0).count();
        (!signal.is_empty()).then(|| kept as f64 / signal.len() as f64)
    }

    fn rollout_trace(&self, states: &[usize]) -> Option<Trace> {
        let mut t = Trace::new(self.trace.vars());
        let mut row = Vec::new();
        for &s in states {
            self.trace.row_into(s, &mut row);
            t.push(&row).ok()?;
        }
        Some(t)
    }

    /// `psi(t)` for every step of a rollout through `states` (an index past the table
    /// lies in no region).
    pub fn psi(&self, states: &[usize]) -> Vec<bool> {
        let mut tau = self.horizons.clone();
        states
            .iter()
            .map(|&s| {
                let mut kept = true;
                for (j, t) in tau.iter_mut().enumerate() {
                    *t = if self.holds[j].get(s).copied().unwrap_or(false) {
                        0
                    } else {
                        (*t + 1).min(self.horizons[j])
                    };
                    kept &= *t < self.horizons[j];
                }
                kept
            })
            .collect()
    }
}

/// Where an [`AgentController`] is in its execution (the running option, its leg, the
/// memory counters, the run so far and the goals it met), apart from the agent: the owner
/// of an agent pauses a controller into this and resumes it later, step by step (the
/// Python package's `Policy.act`).
#[derive(Clone, Debug, PartialEq)]
pub struct AgentProgress {
    running: Option<(usize, usize, usize)>,
    tau: Vec<usize>,
    goals: GoalTracker,
    fresh: bool,
}

impl Default for AgentProgress {
    /// Nothing running: the next step starts afresh, as after [`Controller::reset`].
    fn default() -> AgentProgress {
        AgentProgress { running: None, tau: Vec::new(), goals: GoalTracker::default(), fresh: true }
    }
}

impl<'a> AgentController<'a> {
    /// A controller following `agent`.
    pub fn new(agent: &'a Agent) -> AgentController<'a> {
        AgentController::resume(agent, AgentProgress::default())
    }

    /// A controller following `agent` from where `progress` left off.
    pub fn resume(agent: &'a Agent, progress: AgentProgress) -> AgentController<'a> {
        let AgentProgress { running, tau, goals, fresh } = progress;
        AgentController { agent, running, tau, goals, fresh }
    }

    /// Where the controller is, to [`AgentController::resume`] it later with the same agent.
    pub fn pause(self) -> AgentProgress {
        AgentProgress { running: self.running, tau: self.tau, goals: self.goals, fresh: self.fresh }
    }

    /// The counters `tau_j` of an agent with memory, as of the last state seen (empty
    /// without memory or before the first step).
    pub fn tau(&self) -> &[usize] {
        &self.tau
    }
}

impl Controller for AgentController<'_> {
    fn reset(&mut self) {
        self.running = None;
        self.fresh = true;
        self.tau.clear();
    }

    fn act(&mut self, s: usize) -> Decision {
        let agent = self.agent;
        if self.fresh {
            if let Some(m) = &agent.memory {
                m.start(s, &mut self.tau);
            }
            if let Some(g) = &agent.goals {
                g.start(&mut self.goals, s);
            }
            self.fresh = false;
        }
        // Interruption: the options policy's pick here replaces a running option of
        // strictly lower value (on a tie, as where neither was ever tried, it runs on).
        if agent.switch == Switch::Step
            && let Some((o, ..)) = self.running
        {
            let obs = agent.observation(s, &self.tau, self.goals.met());
            let row = agent.options_q.get(obs * agent.legs.len()..).unwrap_or(&[]);
            if let Some(&c) = agent.options.get(obs)
                && let (Some(q_c), Some(q_o)) = (row.get(c), row.get(o))
                && q_c > q_o
            {
                self.running = Some((c, 0, 0));
            }
        }
        let (o, leg, _) = match self.running {
            Some(r) => r,
            None => {
                let obs = agent.observation(s, &self.tau, self.goals.met());
                *self.running.insert((agent.options.get(obs).copied().unwrap_or(0), 0, 0))
            }
        };
        // An agent that does not fit the state (hand-built, or another environment) takes
        // no valid action, which leaves the state unchanged, instead of panicking.
        let action = agent
            .legs
            .get(o)
            .and_then(|l| l.get(leg))
            .and_then(|&p| agent.flat.get(p)?.get(s).copied())
            .unwrap_or(usize::MAX);
        Decision { action, option: o, leg }
    }

    fn observe(&mut self, next: usize) {
        let agent = self.agent;
        if let Some(m) = &agent.memory
            && !self.fresh
        {
            m.step(next, &mut self.tau);
        }
        if let Some(g) = &agent.goals
            && !self.fresh
        {
            g.push(&mut self.goals, next);
        }
        let Some((o, leg, steps)) = self.running else { return };
        let legs = agent.legs.get(o).map_or(0, Vec::len);
        let done = agent
            .legs
            .get(o)
            .and_then(|l| l.get(leg))
            .and_then(|&p| agent.terminate.get(p)?.get(next).copied())
            .unwrap_or(true);
        self.running = if done || steps + 1 >= agent.max_steps {
            // A leg ends where a goal's region is entered: the next pick sees it.
            if let Some(g) = &agent.goals {
                self.goals.read(&g.progress);
            }
            (leg + 1 < legs).then_some((o, leg + 1, 0))
        } else {
            Some((o, leg, steps + 1))
        };
    }
}

impl<'a> LegCycle<'a> {
    /// The cycle through the primitive options `cycle` (indices into `agent.flat`), in
    /// order, starting with the first after each reset. Fails for an empty cycle or an
    /// index the agent lacks.
    pub fn new(agent: &'a Agent, cycle: Vec<usize>) -> Result<LegCycle<'a>, Error> {
        if cycle.is_empty() || cycle.iter().any(|&p| p >= agent.flat.len()) {
            return Err(Error::Config(format!(
                "a leg cycle needs one or more primitive indices below {}, not {}",
                agent.flat.len(),
                if cycle.is_empty() {
                    "none".to_string()
                } else {
                    crate::words::and_list(
                        &cycle.iter().map(ToString::to_string).collect::<Vec<_>>(),
                    )
                }
            )));
        }
        Ok(LegCycle { agent, cycle, phase: 0, steps: 0 })
    }
}

impl Controller for LegCycle<'_> {
    fn reset(&mut self) {
        self.phase = 0;
        self.steps = 0;
    }

    fn act(&mut self, s: usize) -> Decision {
        let p = self.cycle[self.phase];
        let action = self.agent.flat[p].get(s).copied().unwrap_or(usize::MAX);
        Decision { action, option: p, leg: 0 }
    }

    fn observe(&mut self, next: usize) {
        let p = self.cycle[self.phase];
        self.steps += 1;
        let done = self.agent.terminate[p].get(next).copied().unwrap_or(true);
        if done || self.steps >= self.agent.max_steps {
            self.phase = (self.phase + 1) % self.cycle.len();
            self.steps = 0;
        }
    }
}

impl EntryCycle {
    /// The cycle through `regions` on `grid`, in region order. Fails when a region holds in
    /// no state of the grid, or the distance tables would be too large.
    pub fn new(grid: &crate::GridWorld, regions: &RegionTable) -> Result<EntryCycle, Error> {
        let n = grid.num_states();
        if regions.holds.iter().any(|h| h.len() != n) {
            return Err(Error::Config("the regions were not computed on this grid".into()));
        }
        let cells: usize = regions.holds.iter().map(|h| h.iter().filter(|&&b| b).count()).sum();
        if cells.saturating_mul(n) > MAX_ENTRY_CYCLE_DISTANCES {
            return Err(Error::Config(format!(
                "the entry cycle needs {cells} region cells x {n} states of distances, more than {MAX_ENTRY_CYCLE_DISTANCES}"
            )));
        }
        let targets: Vec<Vec<(usize, Vec<u32>)>> = regions
            .holds
            .iter()
            .map(|h| (0..n).filter(|&s| h[s]).map(|s| (s, grid.distances_to(s))).collect())
            .collect();
        if targets.iter().any(Vec::is_empty) {
            return Err(Error::Config("a region holds in no cell of the grid".into()));
        }
        let dest = (0..n).map(|s| std::array::from_fn(|a| grid.dest(s, a))).collect();
        Ok(EntryCycle { targets, holds: regions.holds.clone(), dest, phase: 0 })
    }
}

impl Controller for EntryCycle {
    fn reset(&mut self) {
        self.phase = 0;
    }

    fn act(&mut self, s: usize) -> Decision {
        let targets = &self.targets[self.phase];
        let at = |d: &Vec<u32>, s: usize| d.get(s).copied().unwrap_or(u32::MAX);
        // The first nearest cell: `min_by_key` keeps the first of equal keys.
        let target = targets.iter().min_by_key(|(_, d)| at(d, s));
        // Right, Left, Up, Down: along x first.
        const ORDER: [usize; 4] = [3, 2, 0, 1];
        let action = target
            .and_then(|(_, d)| {
                let here = at(d, s);
                let dest = self.dest.get(s)?;
                ORDER.into_iter().find(|&a| at(d, dest[a]) < here)
            })
            .unwrap_or(1);
        Decision { action, option: self.phase, leg: 0 }
    }

    fn observe(&mut self, next: usize) {
        if self.holds[self.phase].get(next).copied().unwrap_or(false) {
            self.phase = (self.phase + 1) % self.holds.len();
        }
    }
}

/// A rollout of `steps` states from `start` (a state index): the state, the decision and the
/// state it led to at each step.
pub fn rollout<E: Env, C: Controller>(
    env: &E,
    controller: &mut C,
    start: usize,
    steps: usize,
    rng: &mut Rng,
) -> Vec<Step> {
    controller.reset();
    let mut out = Vec::with_capacity(steps);
    let mut s = start;
    for _ in 0..steps {
        let decision = controller.act(s);
        let next =
            env.state(s).map_or(s, |state| env.index(&env.step(&state, decision.action, rng)));
        out.push(Step { state: s, decision, next });
        controller.observe(next);
        s = next;
    }
    out
}

/// `runs` rollouts of `steps` states from random starts, for pictures.
pub fn sample_runs<E: Env, C: Controller>(
    env: &E,
    controller: &mut C,
    runs: usize,
    steps: usize,
    rng: &mut Rng,
) -> Vec<Vec<Step>> {
    (0..runs)
        .map(|_| {
            let start = env.index(&env.reset(rng));
            rollout(env, controller, start, steps, rng)
        })
        .collect()
}

/// The window rate of `controller` (see the module docs), with the task's robustness
/// over each rollout.
pub fn window_rate<E: Env, C: Controller>(
    env: &E,
    controller: &mut C,
    regions: &RegionTable,
    config: WindowConfig,
    rng: &mut Rng,
) -> Result<WindowReport, Error> {
    if config.starts == 0 || config.burn_in >= config.steps {
        return Err(Error::Config(format!(
            "the window rate needs starts > 0 and burn_in < steps, not starts = {}, steps = {}, \
             burn_in = {}",
            config.starts, config.steps, config.burn_in
        )));
    }
    if regions.holds.iter().any(|h| h.len() != env.num_states()) {
        return Err(Error::Config(format!(
            "the regions were not computed on this {} environment",
            env.name()
        )));
    }
    let mut per_rollout = Vec::with_capacity(config.starts);
    let mut robustness = Vec::with_capacity(config.starts);
    let mut complete = Vec::with_capacity(config.starts);
    let mut kept_share = Vec::with_capacity(config.starts);
    let mut kept = 0usize;
    for _ in 0..config.starts {
        let start = env.index(&env.reset(rng));
        let states: Vec<usize> =
            rollout(env, controller, start, config.steps, rng).iter().map(|s| s.state).collect();
        let here = regions.psi(&states)[config.burn_in..].iter().filter(|&&k| k).count();
        kept += here;
        per_rollout.push(here as f64 / (config.steps - config.burn_in) as f64);
        robustness.push(regions.robustness(&states));
        complete.push(regions.complete_robustness(&states));
        kept_share.push(regions.kept_share(&states));
    }
    let rate = kept as f64 / (config.starts * (config.steps - config.burn_in)) as f64;
    Ok(WindowReport { rate, per_rollout, robustness, complete, kept: kept_share })
}
