//! The greedy policy of learned weights, and how well it keeps the task: greedy runs as
//! data, the window rate of a persistent task and the satisfaction rate of another, on any
//! [`World`].
//!
//! A greedy run chooses the best available option (its memory code and the goals met
//! included, the goals read where a leg ends, as in training), runs each of its legs with
//! the leg's greedy action until the leg stops or `max_steps` pass, then chooses again; with `switch: step` the options policy's pick at every step replaces a
//! running option of strictly lower value, as the tabular agent does.

use hstl_robustness::{StateEval, Trace};

use super::model::{Model, Weights};
use crate::progress::GoalTracker;
use crate::spec::Switch;
use crate::{Error, Rng, TaskSpec, World};

/// A greedy agent over learned weights.
#[derive(Clone, Debug)]
pub struct ApproxAgent {
    /// The codings, formulas and memory the weights are read with.
    pub model: Model,
    /// The learned weights.
    pub weights: Weights,
    /// When a greedy run chooses an option.
    pub switch: Switch,
}

/// One greedy run: the state at every step, the action taken there and the option running.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GreedyRun {
    /// Valuations, one row of the spec's variables per step; one row more than actions
    /// (the state after the last action).
    pub values: Vec<f64>,
    /// The action taken at each step.
    pub actions: Vec<usize>,
    /// The option running at each step.
    pub options: Vec<usize>,
}

/// Where a greedy run driven from outside is ([`ApproxAgent::stepper`]): each
/// [`Stepper::act`] is told the state the previous action led to, and the actions are those
/// [`ApproxAgent::run`] takes through the same states.
#[derive(Clone, Debug, Default)]
pub struct Stepper {
    cur: Cursor,
    eval: StateEval,
    started: bool,
}

impl Stepper {
    /// The greedy action in the state of valuation `x` and the option running it; `blocked`
    /// says which actions the world blocks there (empty: none). The first call starts the
    /// run at `x`; each later one takes `x` as the state the previous action led to.
    pub fn act(&mut self, agent: &ApproxAgent, x: &[f64], blocked: &[bool]) -> (usize, usize) {
        let Stepper { cur, eval, started } = self;
        if *started {
            let leg_ended = agent.observe(eval, cur, x);
            agent.record(cur, x, leg_ended);
        } else {
            agent.model.start_counters(eval, x, &mut cur.tau);
            cur.goals.start(x);
            if let Some(progress) = &agent.model.progress {
                cur.goals.read(progress);
            }
            *started = true;
        }
        cur.blocked.clear();
        cur.blocked
            .extend((0..agent.model.actions).map(|a| blocked.get(a).copied().unwrap_or(false)));
        agent.act(eval, cur, x)
    }
}

/// How well a greedy agent keeps a persistent task.
#[derive(Clone, Debug, PartialEq)]
pub struct WindowSummary {
    /// The share of counted steps whose windows all visit their region.
    pub rate: f64,
    /// The window rate of each run.
    pub per_run: Vec<f64>,
    /// The task's robustness over each whole run, windows clipped at its end.
    pub robustness: Vec<f64>,
}

/// Where a greedy run is: the running option, its leg and the steps the leg has taken, and
/// the memory's counters.
#[derive(Clone, Debug, Default)]
struct Cursor {
    running: Option<(usize, usize, usize)>,
    tau: Vec<usize>,
    /// The run so far and the goals it has met (for a task with goals).
    goals: GoalTracker,
    f: Vec<usize>,
    g: Vec<usize>,
    q: Vec<f64>,
    available: Vec<usize>,
    /// The actions the world blocks in the current state.
    blocked: Vec<bool>,
}

impl ApproxAgent {
    /// The agent of `weights` for `spec` in `world`.
    pub fn new<W: World>(
        spec: &TaskSpec,
        world: &W,
        weights: Weights,
    ) -> Result<ApproxAgent, Error> {
        let model = Model::new(spec, world)?;
        if !model.fits(&weights) {
            return Err(Error::Config(
                "the weights do not have the shape of this spec and world".into(),
            ));
        }
        Ok(ApproxAgent { model, weights, switch: spec.learn.switch })
    }

    /// A greedy run of `steps` actions from `start`.
    pub fn run<W: World>(
        &self,
        world: &W,
        start: W::State,
        steps: usize,
        rng: &mut Rng,
    ) -> GreedyRun {
        let vars = self.model.vars.len();
        let mut eval = StateEval::new();
        let mut cur = Cursor::default();
        let mut out = GreedyRun::default();
        let mut state = start;
        let mut x = Vec::with_capacity(vars);
        world.valuation(&state, &mut x);
        self.model.start_counters(&mut eval, &x, &mut cur.tau);
        cur.goals.start(&x);
        if let Some(progress) = &self.model.progress {
            cur.goals.read(progress);
        }
        out.values.extend_from_slice(&x);
        for _ in 0..steps {
            self.model.blocked(world, &state, &mut cur.blocked);
            let (action, option) = self.act(&mut eval, &mut cur, &x);
            state = world.step(&state, action, rng);
            world.valuation(&state, &mut x);
            let leg_ended = self.observe(&mut eval, &mut cur, &x);
            self.record(&mut cur, &x, leg_ended);
            out.values.extend_from_slice(&x);
            out.actions.push(action);
            out.options.push(option);
        }
        out
    }

    /// A greedy run one step at a time, for a caller that steps the world itself (a
    /// gymnasium environment): see [`Stepper`].
    pub fn stepper(&self) -> Stepper {
        Stepper::default()
    }

    fn act(&self, eval: &mut StateEval, cur: &mut Cursor, x: &[f64]) -> (usize, usize) {
        let m = &self.model;
        let pick = |cur: &mut Cursor, eval: &mut StateEval| {
            m.available(eval, x, &mut cur.available);
            m.options_coder.features(x, &mut cur.g);
            let code = m.code(&cur.tau, cur.goals.met());
            (m.best_option(&self.weights, code, &cur.g, &cur.available), code)
        };
        if self.switch == Switch::Step
            && let Some((o, ..)) = cur.running
        {
            let (c, code) = pick(cur, eval);
            if m.option_value(&self.weights, code, c, &cur.g)
                > m.option_value(&self.weights, code, o, &cur.g)
            {
                cur.running = Some((c, 0, 0));
            }
        }
        let (o, leg, _) = match cur.running {
            Some(r) => r,
            None => {
                let o = pick(cur, eval).0;
                *cur.running.insert((o, 0, 0))
            }
        };
        let p = m.legs[o][leg];
        m.flat_coder.features(x, &mut cur.f);
        (m.greedy_action(&self.weights, p, &cur.f, &cur.blocked, &mut cur.q), o)
    }

    /// Moves the memory and the running option on to `next`; returns whether a leg ended.
    fn observe(&self, eval: &mut StateEval, cur: &mut Cursor, next: &[f64]) -> bool {
        let m = &self.model;
        if m.is_persistent() {
            m.step_counters(eval, next, &mut cur.tau);
        }
        let Some((o, leg, steps)) = cur.running else { return false };
        let done = m.stops(eval, m.legs[o][leg], next);
        let ended = done || steps + 1 >= m.max_steps;
        cur.running = if ended {
            (leg + 1 < m.legs[o].len()).then_some((o, leg + 1, 0))
        } else {
            Some((o, leg, steps + 1))
        };
        ended
    }

    /// Appends `x` to the run so far and, where a leg ended, reads the goals met.
    fn record(&self, cur: &mut Cursor, x: &[f64], leg_ended: bool) {
        let Some(progress) = &self.model.progress else { return };
        cur.goals.push(x);
        if leg_ended {
            cur.goals.read(progress);
        }
    }

    /// The window rate over `runs` greedy runs of `steps` actions from the world's starts,
    /// the first `burn_in` steps of each not counted, with the task's robustness over each.
    pub fn window_rate<W: World>(
        &self,
        world: &W,
        spec: &TaskSpec,
        runs: usize,
        steps: usize,
        burn_in: usize,
        rng: &mut Rng,
    ) -> Result<WindowSummary, Error> {
        if runs == 0 || burn_in >= steps {
            return Err(Error::Config(format!(
                "the window rate needs runs > 0 and burn_in < steps, not runs = {runs}, steps = \
                 {steps}, burn_in = {burn_in}"
            )));
        }
        if !self.model.is_persistent() {
            return Err(Error::Spec("the window rate is defined for a persistent task".into()));
        }
        let vars = self.model.vars.len();
        let mut eval = StateEval::new();
        let (mut kept, mut per_run, mut robustness) = (0usize, Vec::new(), Vec::new());
        let mut tau = Vec::new();
        for _ in 0..runs {
            let start = world.reset(rng);
            let run = self.run(world, start, steps, rng);
            // `psi` of each visited state as the tabular evaluation counts it: the counters
            // start expired and move on at every state, the first included.
            tau.clear();
            tau.extend(self.model.horizons());
            let mut here = 0;
            for (t, x) in run.values.chunks(vars).take(steps).enumerate() {
                let ok = self.model.step_counters(&mut eval, x, &mut tau);
                if ok && t >= burn_in {
                    here += 1;
                }
            }
            kept += here;
            per_run.push(here as f64 / (steps - burn_in) as f64);
            robustness.push(task_robustness(spec, &run.values[..steps * vars], vars));
        }
        let rate = kept as f64 / (runs * (steps - burn_in)) as f64;
        Ok(WindowSummary { rate, per_run, robustness })
    }

    /// The share of `runs` greedy runs of `steps` actions (from the world's starts) whose
    /// trace satisfies the task (robustness above 0 at step 0).
    pub fn satisfaction<W: World>(
        &self,
        world: &W,
        spec: &TaskSpec,
        runs: usize,
        steps: usize,
        rng: &mut Rng,
    ) -> f64 {
        let vars = self.model.vars.len();
        let mut ok = 0usize;
        for _ in 0..runs {
            let start = world.reset(rng);
            let run = self.run(world, start, steps, rng);
            if task_robustness(spec, &run.values, vars) > 0.0 {
                ok += 1;
            }
        }
        ok as f64 / runs.max(1) as f64
    }
}

/// `rho(task, 0)` over row-major valuations of `vars` variables (NaN for ragged ones).
pub fn task_robustness(spec: &TaskSpec, values: &[f64], vars: usize) -> f64 {
    let columns =
        (0..vars).map(|d| values.iter().skip(d).step_by(vars).copied().collect()).collect();
    match Trace::from_columns(columns) {
        Ok(trace) => hstl_robustness::offline::robustness(&spec.task, &trace),
        Err(_) => f64::NAN,
    }
}
