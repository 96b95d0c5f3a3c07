//! Environments stepped from outside Rust, one call a step: an environment with `Discrete`
//! observations and actions (a gymnasium environment, which the Python package calls) as
//! the tabular learner's [`Env`] ([`DiscreteEnv`]), and the states a `policy.json` trained
//! on one lists ([`Listed`]), which its replay is checked against when the environment
//! itself is not given. The caller supplies only the two calls ([`Calls`]: `reset` with a
//! seed, `step` with an action) and each observation's valuation; everything else (the
//! spaces' limits, the valuations checked against the spec's domains, an observation
//! outside its space, the state the learner steps from) is decided here.
//!
//! The learner (and a replay) only ever steps from the state the environment is in, after
//! `reset`. Each `reset` seeds the environment with a seed drawn from the learner's one
//! generator, so the same seed gives the same episodes and the same Q-tables whatever the
//! environment did before. A step that reports `terminated` or `truncated` ends the
//! learner's episode there ([`Env::episode_end`]): the next one starts with a reset, so
//! every step the learner counts is a call of `step`; a terminal state is valued as one
//! the robot stays in, a truncated one as usual. (A replay that steps on leaves the robot
//! in that state, without a call, until it resets.) The first failure (a call's error, or
//! an observation refused) stops the run: every later call returns at once, and the caller
//! stops at the end of the episode and takes it ([`DiscreteEnv::take_error`]).

use std::cell::{Cell, RefCell};
use std::collections::HashMap;

use hstl_runtime::{Env, EpisodeEnd, Rng, RngExt, TaskSpec, Value, json};

use crate::Problem;

/// The most observations an environment may have for tabular learning (the largest grid
/// world's cells).
pub const MAX_OBSERVATIONS: usize = hstl_runtime::env::MAX_GRID_CELLS;
/// The most Q-values of one flat table, observations times actions (the largest grid
/// world's).
pub const MAX_FLAT_VALUES: usize = 4 * MAX_OBSERVATIONS;

/// An environment's `Discrete` spaces, as `policy.json`'s `env` records them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Spaces {
    /// The environment's id (gymnasium's `spec.id`), or its class name.
    pub name: String,
    /// The number of observations (`observation_space.n`).
    pub observations: usize,
    /// The first observation (`observation_space.start`).
    pub observation_start: i64,
    /// The number of actions (`action_space.n`).
    pub actions: usize,
    /// The first action (`action_space.start`).
    pub action_start: i64,
}

impl Spaces {
    /// ``` `FrozenLake-v1` (Discrete(16) observations, Discrete(4) actions) ```.
    pub fn describe(&self) -> String {
        let space = |n: usize, start: i64| match start {
            0 => format!("Discrete({n})"),
            s => format!("Discrete({n}, start={s})"),
        };
        format!(
            "`{}` ({} observations, {} actions)",
            self.name,
            space(self.observations, self.observation_start),
            space(self.actions, self.action_start)
        )
    }

    /// `policy.json`'s `env.params` for an environment with these spaces.
    pub fn params(&self) -> Value {
        json!({
            "gymnasium": true,
            "observations": self.observations,
            "observation_start": self.observation_start,
            "actions": self.actions,
            "action_start": self.action_start,
        })
    }

    /// The spaces `env.params` (written by [`Spaces::params`]) records for the environment
    /// `name`, or why they cannot be read.
    pub fn from_params(name: &str, params: &Value) -> Result<Spaces, Problem> {
        let count = |key: &str| {
            params.get(key).and_then(Value::as_u64).and_then(|n| usize::try_from(n).ok())
        };
        let start = |key: &str| params.get(key).and_then(Value::as_i64);
        match (
            count("observations"),
            start("observation_start"),
            count("actions"),
            start("action_start"),
        ) {
            (Some(observations), Some(observation_start), Some(actions), Some(action_start)) => {
                Ok(Spaces {
                    name: name.to_string(),
                    observations,
                    observation_start,
                    actions,
                    action_start,
                })
            }
            _ => Err(Problem::new(
                "its `env.params` lack the spaces of its gymnasium environment",
                "pass the policy.json that `hstl.train` wrote".to_string(),
            )),
        }
    }

    /// Refuses `given`, the spaces of an environment a policy trained on these is to run
    /// in, when they differ.
    pub fn check_same(&self, given: &Spaces) -> Result<(), Problem> {
        if given.name != self.name || given.params() != self.params() {
            return Err(Problem::new(
                format!(
                    "the policy was trained on {}; `env` is {}",
                    self.describe(),
                    given.describe()
                ),
                "pass the environment it was trained in".to_string(),
            ));
        }
        Ok(())
    }

    /// The observation `obs` that the call `call` (`reset`, `step`) gave, as a state index.
    fn index(&self, obs: i64, call: &str) -> Result<usize, Problem> {
        let (n, start) = (self.observations, self.observation_start);
        obs.checked_sub(start).and_then(|i| usize::try_from(i).ok()).filter(|&i| i < n).ok_or_else(
            || {
                Problem::new(
                    format!("env.{call} gave the observation {obs}, outside Discrete({n}, start={start})"),
                    None,
                )
            },
        )
    }
}

/// The two calls of an environment stepped from outside.
pub trait Calls {
    /// The calls' own error (a Python exception).
    type Error;
    /// Resets the environment with `seed`; its first observation.
    fn reset(&self, seed: u64) -> Result<i64, Self::Error>;
    /// Takes the environment's action `action` (its own number, the space's start
    /// included); the next observation, and whether the step terminated or truncated the
    /// episode.
    fn step(&self, action: i64) -> Result<(i64, Option<EpisodeEnd>), Self::Error>;
}

/// Why a run in an outside environment stopped.
#[derive(Debug)]
pub enum Failure<E> {
    /// A call (or the valuation) failed with its own error.
    Call(E),
    /// What the environment gave is refused.
    Refused(Problem),
}

/// The first failure of a run, kept until taken.
struct FirstFailure<E>(RefCell<Option<Failure<E>>>);

impl<E> FirstFailure<E> {
    fn take(&self) -> Option<Failure<E>> {
        self.0.borrow_mut().take()
    }

    fn failed(&self) -> bool {
        self.0.borrow().is_some()
    }

    /// Keeps `e` unless a failure is kept already.
    fn keep(&self, e: Failure<E>) {
        let mut slot = self.0.borrow_mut();
        if slot.is_none() {
            *slot = Some(e);
        }
    }
}

impl<E> From<Problem> for Failure<E> {
    fn from(p: Problem) -> Self {
        Failure::Refused(p)
    }
}

/// An environment with `Discrete` spaces, stepped through [`Calls`], as the learner's
/// [`Env`] (see the module). A state is the index of an observation in its space.
pub struct DiscreteEnv<C: Calls> {
    calls: C,
    spaces: Spaces,
    vars: Vec<String>,
    /// `values[s * vars + i]`: state variable `i` in observation `start + s`.
    values: Vec<f64>,
    current: Cell<usize>,
    /// The last step terminated or truncated: stay until the next reset.
    absorbed: Cell<bool>,
    /// How the last step ended the episode, if it did.
    end: Cell<Option<EpisodeEnd>>,
    error: FirstFailure<C::Error>,
}

impl<C: Calls> DiscreteEnv<C> {
    /// The environment `calls` with `spaces`, whose observation `o` has the state
    /// `valuation(o)` (the spec's state variables' values, in order). Calls `valuation`
    /// once per observation, and checks every value against the spec's domain and that no
    /// two observations share a valuation (`policy.json` names states by their values).
    pub fn new(
        calls: C,
        spaces: Spaces,
        spec: &TaskSpec,
        mut valuation: impl FnMut(i64) -> Result<Vec<f64>, C::Error>,
    ) -> Result<DiscreteEnv<C>, Failure<C::Error>> {
        let n = spaces.observations;
        if n == 0 || n > MAX_OBSERVATIONS {
            return Err(Problem::new(
                format!(
                    "the environment has {n} observations; the learner's tables take 1 to {MAX_OBSERVATIONS}"
                ),
                "give the environment a smaller `Discrete` observation space".to_string(),
            )
            .into());
        }
        if spaces.actions == 0 || n.saturating_mul(spaces.actions) > MAX_FLAT_VALUES {
            return Err(Problem::new(
                format!(
                    "{n} observations and {} actions are more than the {MAX_FLAT_VALUES} Q-values a flat table may have",
                    spaces.actions
                ),
                "give the environment fewer observations or actions".to_string(),
            )
            .into());
        }
        let vars: Vec<String> = spec.state_vars.iter().map(|v| v.name.clone()).collect();
        let mut values = Vec::with_capacity(n * vars.len());
        let mut seen: HashMap<Vec<u64>, i64> = HashMap::with_capacity(n);
        for s in 0..n {
            let obs = spaces.observation_start + s as i64;
            let row = valuation(obs).map_err(Failure::Call)?;
            if row.len() != vars.len() {
                return Err(Problem::new(
                    format!(
                        "valuation({obs}) gives {} values; the spec has {} state variables",
                        row.len(),
                        vars.len()
                    ),
                    format!("return a dict of {}", vars.join(", ")),
                )
                .into());
            }
            for (v, &x) in spec.state_vars.iter().zip(&row) {
                let fits = v.domain.as_ref().is_some_and(|d| {
                    x.fract() == 0.0 && x >= *d.start() as f64 && x <= *d.end() as f64
                });
                if !fits {
                    let domain = v
                        .domain
                        .as_ref()
                        .map_or("no range".to_string(), |d| format!("{}..={}", d.start(), d.end()));
                    return Err(Problem::new(
                        format!(
                            "valuation({obs}) gives `{}` = {x}, outside its declared domain {domain}",
                            v.name
                        ),
                        "declare the range the valuation gives, or fix the valuation".to_string(),
                    )
                    .into());
                }
            }
            if let Some(other) = seen.insert(state_key(&row), obs) {
                return Err(Problem::new(
                    format!("observations {other} and {obs} have the same valuation"),
                    "policy.json names states by their values: give each observation its own, \
                     such as a state variable `s: int` that is the observation itself"
                        .to_string(),
                )
                .into());
            }
            values.extend(row);
        }
        Ok(DiscreteEnv {
            calls,
            spaces,
            vars,
            values,
            current: Cell::new(0),
            absorbed: Cell::new(false),
            end: Cell::new(None),
            error: FirstFailure(RefCell::new(None)),
        })
    }

    /// The calls.
    pub fn calls(&self) -> &C {
        &self.calls
    }

    /// The spaces.
    pub fn spaces(&self) -> &Spaces {
        &self.spaces
    }

    /// The first failure of the run, if any (taken: a later call sees none).
    pub fn take_error(&self) -> Option<Failure<C::Error>> {
        self.error.take()
    }

    /// Whether a failure stopped the run.
    pub fn failed(&self) -> bool {
        self.error.failed()
    }

    fn fail(&self, e: Failure<C::Error>) {
        self.error.keep(e)
    }

    fn call_reset(&self, seed: u64) -> Result<usize, Failure<C::Error>> {
        let obs = self.calls.reset(seed).map_err(Failure::Call)?;
        Ok(self.spaces.index(obs, "reset")?)
    }

    fn call_step(&self, action: usize) -> Result<(usize, Option<EpisodeEnd>), Failure<C::Error>> {
        let action = self.spaces.action_start + action as i64;
        let (obs, end) = self.calls.step(action).map_err(Failure::Call)?;
        Ok((self.spaces.index(obs, "step")?, end))
    }
}

impl<C: Calls> Env for DiscreteEnv<C> {
    type State = usize;

    fn name(&self) -> &str {
        &self.spaces.name
    }

    fn params(&self) -> Value {
        self.spaces.params()
    }

    fn state_vars(&self) -> Vec<String> {
        self.vars.clone()
    }

    fn actions(&self) -> Vec<String> {
        (0..self.spaces.actions)
            .map(|a| (self.spaces.action_start + a as i64).to_string())
            .collect()
    }

    fn num_states(&self) -> usize {
        self.spaces.observations
    }

    fn index(&self, state: &usize) -> usize {
        *state
    }

    fn state(&self, index: usize) -> Option<usize> {
        (index < self.spaces.observations).then_some(index)
    }

    fn valuation(&self, state: &usize, out: &mut Vec<f64>) {
        row(&self.values, self.vars.len(), *state, out)
    }

    fn reset(&self, rng: &mut Rng) -> usize {
        // Drawn even after a failure, so that the generator's draws do not depend on it.
        let seed: u64 = rng.random();
        if self.failed() {
            return self.current.get();
        }
        match self.call_reset(seed) {
            Ok(s) => {
                self.current.set(s);
                self.absorbed.set(false);
                self.end.set(None);
            }
            Err(e) => self.fail(e),
        }
        self.current.get()
    }

    fn episode_end(&self) -> Option<EpisodeEnd> {
        self.end.get()
    }

    fn step(&self, state: &usize, action: usize, _rng: &mut Rng) -> usize {
        if self.failed() || self.absorbed.get() || action >= self.spaces.actions {
            return *state;
        }
        if *state != self.current.get() {
            self.fail(Failure::Refused(Problem::new(
                format!(
                    "the learner stepped from state {state}, but the environment is in state {}",
                    self.current.get()
                ),
                None,
            )));
            return *state;
        }
        match self.call_step(action) {
            Ok((next, end)) => {
                self.current.set(next);
                self.absorbed.set(end.is_some());
                self.end.set(end);
            }
            Err(e) => self.fail(e),
        }
        self.current.get()
    }
}

/// The calls of an environment with a bounded `Box` observation space and `Discrete`
/// actions, stepped from outside.
pub trait BoxCalls {
    /// The calls' own error (a Python exception).
    type Error;
    /// The caller's own form of an observation, which [`BoxCalls::valuation`] reads.
    type Obs;
    /// Resets the environment with `seed`: its first observation, and the observation's
    /// numbers (flattened). `call` names the call in messages.
    fn reset(&self, seed: u64, call: &str) -> Result<(Self::Obs, Vec<f64>), Self::Error>;
    /// Takes the environment's action `action` (its own number): the next observation, its
    /// numbers, and whether the step terminated or truncated the episode.
    fn step(&self, action: i64, call: &str) -> Result<(Self::Obs, Vec<f64>, bool), Self::Error>;
    /// The state variables' values of `obs` by the caller's valuation, or None when there
    /// is none (the state is then the observation's numbers, in order).
    fn valuation(&self, obs: &Self::Obs, call: &str) -> Option<Result<Vec<f64>, Self::Error>>;
}

/// An environment with a bounded `Box` observation space and `Discrete` actions, stepped
/// through [`BoxCalls`], as a [`World`](hstl_runtime::World) of the approximate learner:
/// its state is the valuation of the last observation.
///
/// Each `reset` seeds the environment with a seed drawn from the learner's one generator.
/// Every observation is checked: its size, that each number is inside the `Box`, and that
/// the valuation gives each state variable a finite value inside the range the spec
/// declares (the tiling's). A step that reports `terminated` or `truncated` leaves the
/// robot in that state, without a call, until the learner's next episode resets it. The
/// first failure stops the run: later calls return at once, and the caller takes it.
pub struct BoxEnv<C: BoxCalls> {
    calls: C,
    described: crate::gym::Described,
    /// The spec's declared range of each state variable.
    lo: Vec<f64>,
    hi: Vec<f64>,
    current: RefCell<Vec<f64>>,
    absorbed: Cell<bool>,
    /// `step` calls so far, for messages.
    steps: Cell<u64>,
    error: FirstFailure<C::Error>,
}

impl<C: BoxCalls> BoxEnv<C> {
    /// The environment `calls` (its spaces as `described` records them) for `spec`;
    /// `valued` says whether the calls have a valuation (without one, the observation's
    /// numbers are the state variables' values in order, so their counts must agree).
    pub fn new(
        calls: C,
        valued: bool,
        described: crate::gym::Described,
        spec: &TaskSpec,
    ) -> Result<BoxEnv<C>, Problem> {
        let vars = &described.vars;
        if !valued && described.low.len() != vars.len() {
            return Err(Problem::new(
                format!(
                    "the observation has {} components and spec `{}` {} state variables ({}), so \
                     they cannot be read in order",
                    described.low.len(),
                    spec.name,
                    vars.len(),
                    vars.join(", ")
                ),
                format!(
                    "pass valuation=, a function from an observation to the state variables, \
                     such as `lambda o: {{{}}}`",
                    vars.iter()
                        .enumerate()
                        .map(|(i, v)| format!("\"{v}\": o[{i}]"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        let (lo, hi) = match &spec.learn.tiles {
            Some(t) => (t.lo.clone(), t.hi.clone()),
            None => (vec![f64::NEG_INFINITY; vars.len()], vec![f64::INFINITY; vars.len()]),
        };
        Ok(BoxEnv {
            calls,
            described,
            lo,
            hi,
            current: RefCell::new(Vec::new()),
            absorbed: Cell::new(false),
            steps: Cell::new(0),
            error: FirstFailure(RefCell::new(None)),
        })
    }

    /// The spaces as `policy.json` records them.
    pub fn described(&self) -> &crate::gym::Described {
        &self.described
    }

    /// The first failure of the run, if any (taken: a later call sees none).
    pub fn take_error(&self) -> Option<Failure<C::Error>> {
        self.error.take()
    }

    /// Whether a failure stopped the run.
    pub fn failed(&self) -> bool {
        self.error.failed()
    }

    fn fail(&self, e: Failure<C::Error>) {
        self.error.keep(e)
    }

    /// The state of the observation `obs` with the numbers `values`, every number checked;
    /// `call` names where it came from.
    fn state_of(
        &self,
        obs: &C::Obs,
        values: Vec<f64>,
        call: &str,
    ) -> Result<Vec<f64>, Failure<C::Error>> {
        let d = &self.described;
        let num = hstl_runtime::plane::num;
        if values.len() != d.low.len() {
            return Err(Problem::new(
                format!(
                    "{call} gave an observation of {} components; its `Box` has {}",
                    values.len(),
                    d.low.len()
                ),
                "give the environment an observation space that its observations fit".to_string(),
            )
            .into());
        }
        for (i, &v) in values.iter().enumerate() {
            if !(v >= d.low[i] && v <= d.high[i]) {
                return Err(Problem::new(
                    format!(
                        "{call} gave an observation whose component {i} is {}, outside its `Box` \
                         [{}, {}]",
                        num(v),
                        num(d.low[i]),
                        num(d.high[i])
                    ),
                    "the learner tiles the `Box`: bound the observation space so that it \
                     holds every observation (or clip the observations)"
                        .to_string(),
                )
                .into());
            }
        }
        let state = match self.calls.valuation(obs, call) {
            None => values,
            Some(row) => {
                let row = row.map_err(Failure::Call)?;
                if row.len() != d.vars.len() {
                    return Err(Problem::new(
                        format!(
                            "valuation gives {} values; the spec has {} state variables",
                            row.len(),
                            d.vars.len()
                        ),
                        format!("return a dict of {}", d.vars.join(", ")),
                    )
                    .into());
                }
                row
            }
        };
        for (i, &x) in state.iter().enumerate() {
            if !(x >= self.lo[i] && x <= self.hi[i]) {
                return Err(Problem::new(
                    format!(
                        "after {call}, `{}` = {} is outside its declared range {}..={}",
                        d.vars[i],
                        num(x),
                        num(self.lo[i]),
                        num(self.hi[i])
                    ),
                    "declare the range the observations take, or fix the valuation".to_string(),
                )
                .into());
            }
        }
        Ok(state)
    }

    fn call_reset(&self, seed: u64) -> Result<Vec<f64>, Failure<C::Error>> {
        let call = "env.reset";
        let (obs, values) = self.calls.reset(seed, call).map_err(Failure::Call)?;
        self.state_of(&obs, values, call)
    }

    fn call_step(&self, action: usize) -> Result<(Vec<f64>, bool), Failure<C::Error>> {
        let action = self.described.action_start + action as i64;
        let call = format!("env.step (call {})", self.steps.get() + 1);
        let (obs, values, ended) = self.calls.step(action, &call).map_err(Failure::Call)?;
        self.steps.set(self.steps.get() + 1);
        Ok((self.state_of(&obs, values, &call)?, ended))
    }

    /// The current state; zeros inside the ranges before the first reset succeeded.
    fn current_or_zeros(&self) -> Vec<f64> {
        let current = self.current.borrow();
        if current.len() == self.described.vars.len() {
            current.clone()
        } else {
            self.lo.iter().map(|&l| if l.is_finite() { l } else { 0.0 }).collect()
        }
    }
}

impl<C: BoxCalls> hstl_runtime::World for BoxEnv<C> {
    type State = Vec<f64>;

    fn name(&self) -> &str {
        &self.described.name
    }

    fn params(&self) -> Value {
        self.described.params()
    }

    fn state_vars(&self) -> Vec<String> {
        self.described.vars.clone()
    }

    fn actions(&self) -> Vec<String> {
        hstl_runtime::World::actions(&self.described)
    }

    fn valuation(&self, state: &Vec<f64>, out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(state);
    }

    fn reset(&self, rng: &mut Rng) -> Vec<f64> {
        // Drawn even after a failure, so that the generator's draws do not depend on it.
        let seed: u64 = rng.random();
        if !self.failed() {
            match self.call_reset(seed) {
                Ok(s) => {
                    *self.current.borrow_mut() = s;
                    self.absorbed.set(false);
                }
                Err(e) => self.fail(e),
            }
        }
        self.current_or_zeros()
    }

    fn step(&self, state: &Vec<f64>, action: usize, _rng: &mut Rng) -> Vec<f64> {
        if self.failed() || self.absorbed.get() || action >= self.described.actions {
            return state.clone();
        }
        if *state != *self.current.borrow() {
            self.fail(Failure::Refused(Problem::new(
                "the learner stepped from a state the environment is not in",
                None,
            )));
            return state.clone();
        }
        match self.call_step(action) {
            Ok((next, ended)) => {
                *self.current.borrow_mut() = next;
                self.absorbed.set(ended);
            }
            Err(e) => self.fail(e),
        }
        self.current_or_zeros()
    }
}

/// The states a `policy.json` lists (those of its first flat policy, in index order), as
/// an environment: what a policy trained on a gymnasium environment is checked against.
/// It cannot move: a replay that steps needs the environment itself.
#[derive(Clone, Debug)]
pub struct Listed {
    name: String,
    params: Value,
    vars: Vec<String>,
    actions: Vec<String>,
    values: Vec<f64>,
    states: usize,
}

impl Listed {
    /// The states `policy` lists, or why it lists none.
    pub fn of(policy: &hstl_runtime::Policy) -> Result<Listed, Problem> {
        let bad =
            |m: String| Problem::new(m, "pass the policy.json that `hstl.train` wrote".to_string());
        let entries = policy
            .flat_policies
            .values()
            .next()
            .ok_or_else(|| bad("it has no flat policy to list its states".into()))?;
        let mut values = Vec::with_capacity(entries.len() * policy.state_vars.len());
        for (s, e) in entries.iter().enumerate() {
            for var in &policy.state_vars {
                let v = e.state.get(var).ok_or_else(|| {
                    bad(format!("state {s} of its flat policies has no number for `{var}`"))
                })?;
                values.push(v);
            }
        }
        Ok(Listed {
            name: policy.env.name.clone(),
            params: policy.env.params.clone(),
            vars: policy.state_vars.clone(),
            actions: policy.actions.clone(),
            values,
            states: entries.len(),
        })
    }
}

impl Env for Listed {
    type State = usize;

    fn name(&self) -> &str {
        &self.name
    }

    fn params(&self) -> Value {
        self.params.clone()
    }

    fn state_vars(&self) -> Vec<String> {
        self.vars.clone()
    }

    fn actions(&self) -> Vec<String> {
        self.actions.clone()
    }

    fn num_states(&self) -> usize {
        self.states
    }

    fn index(&self, state: &usize) -> usize {
        *state
    }

    fn state(&self, index: usize) -> Option<usize> {
        (index < self.states).then_some(index)
    }

    fn valuation(&self, state: &usize, out: &mut Vec<f64>) {
        row(&self.values, self.vars.len(), *state, out)
    }

    fn reset(&self, _rng: &mut Rng) -> usize {
        0
    }

    fn step(&self, state: &usize, _action: usize, _rng: &mut Rng) -> usize {
        *state
    }
}

/// Row `state` of a table of `k` values a state into `out` (empty past the end).
fn row(values: &[f64], k: usize, state: usize, out: &mut Vec<f64>) {
    out.clear();
    if let Some(row) = values.get(state * k..(state + 1) * k) {
        out.extend_from_slice(row);
    }
}

/// A state's values as a lookup key (`-0` read as `0`).
pub fn state_key(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| (v + 0.0).to_bits()).collect()
}
