//! Task specs as plain data: what a checked hstl spec lowers into.
//!
//! Formulas refer to state variables by index, in declaration order. Nothing here depends
//! on the language front end: the facade builds a [`TaskSpec`] from a checked spec, and
//! generated code implements [`Spec`].

use std::ops::RangeInclusive;

use hstl_robustness::{Bound, Formula, Interval, Node, NodeId};

use crate::Error;

/// A task with its options and learning parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskSpec {
    /// The spec's name.
    pub name: String,
    /// The state variables, in declaration order; formulas use these indices.
    pub state_vars: Vec<StateVar>,
    /// The task the learner pursues.
    pub task: Formula,
    /// The primitive options, one per reached region.
    pub primitives: Vec<PrimitiveOption>,
    /// The options set the options policy chooses among.
    pub options: Vec<CombinedOption>,
    /// Learning parameters.
    pub learn: LearnParams,
    /// The regions of a task `always[0..] (eventually[0..N1] R1 && ...)`, in conjunct
    /// order; empty for a task of any other form.
    pub regions: Vec<Region>,
}

/// A state variable and its domain.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StateVar {
    /// The variable's name, as the environment names it.
    pub name: String,
    /// The declared `int` range; `None` for a variable without a finite `int` range,
    /// which options cannot use.
    pub domain: Option<RangeInclusive<i64>>,
}

/// A primitive option: reach a region.
#[derive(Clone, Debug, PartialEq)]
pub struct PrimitiveOption {
    /// The option's name.
    pub name: String,
    /// The state formula whose robustness at `s'` rewards each step.
    pub reach: Formula,
    /// Where the option may start (`rho > 0`).
    pub init: Formula,
    /// Where it stops.
    pub terminate: Terminate,
    /// A region the leg must stay out of (`avoid: R`): its flat reward also sees
    /// `rho(!R, s')`, entering it costs as much as the worst state forever, and the leg
    /// stops there. `None` (the paper's) leaves the leg alone.
    pub avoid: Option<Formula>,
}

/// Where a primitive option terminates.
#[derive(Clone, Debug, PartialEq)]
pub enum Terminate {
    /// In the states where the reach robustness is largest over the domain.
    Argmax,
    /// In the states where this state formula holds (`rho > 0`).
    Formula(Formula),
}

/// A member of the options set: one or more primitive options run in turn.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CombinedOption {
    /// The option's name, such as `AB`.
    pub name: String,
    /// Indices into [`TaskSpec::primitives`], in execution order.
    pub sequence: Vec<usize>,
}

/// A region of a persistent task: `eventually[0..horizon] formula`.
#[derive(Clone, Debug, PartialEq)]
pub struct Region {
    /// The region's name (the `let` it comes from).
    pub name: String,
    /// The region's state formula.
    pub formula: Formula,
    /// `N_j`: the number of steps in its window.
    pub horizon: usize,
}

/// Learning parameters, with the paper's Table II as [`Default`].
#[derive(Clone, Debug, PartialEq)]
pub struct LearnParams {
    /// Training episodes.
    pub episodes: usize,
    /// Option choices per episode.
    pub choices: usize,
    /// Steps after which a leg of an option is cut off.
    pub max_steps: usize,
    /// Memory buckets of the options state (0: off, as in the paper).
    pub memory: usize,
    /// Which option intra-option updates credit.
    pub intra: Intra,
    /// How an option execution is rewarded.
    pub reward: RewardKind,
    /// Counterfactual memory values per option execution (0: off, as in the paper): with
    /// `memory` and `reward: window`, each execution also updates the options value of this
    /// many other memory values it could have started with, drawn at random, as
    /// counterfactual reward machines do.
    pub counterfactual: usize,
    /// When a greedy run of the policy chooses an option.
    pub switch: Switch,
    /// Whether the options values are planned over a model of the legs instead of
    /// Q-learned (needs a persistent task, `memory`, `reward: window` and one option per
    /// region).
    pub plan: Plan,
    /// The flat (primitive) level; epsilon decays per primitive step.
    pub flat: LevelParams,
    /// The options level; epsilon decays per option choice.
    pub options: LevelParams,
    /// The tile coding of the approximate learner ([`crate::approx`]); `None`: the
    /// tabular learner.
    pub tiles: Option<TileParams>,
}

/// The tile coding of a continuous state (see [`crate::approx::tiles`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TileParams {
    /// Offset tilings of the flat levels (8); the options level has half as many, each
    /// tile twice as wide.
    pub tilings: usize,
    /// Tiles along each state variable, in the spec's order.
    pub bins: Vec<usize>,
    /// Each state variable's lower bound (the domain's).
    pub lo: Vec<f64>,
    /// Each state variable's upper bound.
    pub hi: Vec<f64>,
}

/// Q-learning parameters of one level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelParams {
    /// Discount per step.
    pub gamma: f64,
    /// Learning rate.
    pub alpha: f64,
    /// Initial exploration rate.
    pub epsilon: f64,
    /// Exploration floor.
    pub min_epsilon: f64,
    /// Linear decay of epsilon per step or choice.
    pub decay: f64,
}

/// Which option an intra-option update credits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Intra {
    /// Every suffix to the executed option, as in the paper.
    #[default]
    Paper,
    /// A suffix to the option made of the remaining legs, when it is in the set.
    Remaining,
}

/// When a greedy run of the learned policy (evaluation, pictures, `Policy.act`) chooses an
/// option. Training runs every option to termination either way.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Switch {
    /// When the running option terminates, as in the paper.
    #[default]
    Termination,
    /// At every step: the option the options policy picks in the current state (and memory)
    /// replaces the running one when they differ, the interruption of Sutton, Precup and
    /// Singh (1999), which is never worse for exact values.
    Step,
}

impl Switch {
    /// Whether this is the paper's [`Switch::Termination`] (left out of `policy.json`).
    pub fn is_termination(&self) -> bool {
        *self == Switch::Termination
    }

    /// The word a spec writes for it (`switch: step`), as in `policy.json`.
    pub fn word(self) -> &'static str {
        match self {
            Switch::Termination => "termination",
            Switch::Step => "step",
        }
    }
}

/// How the options values of a trained policy are obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Plan {
    /// Q-learned, as in the paper.
    #[default]
    Off,
    /// Planned after training: value iteration over the task's memory counters and a
    /// model of the learned legs (how long each takes from each state, where it arrives),
    /// estimated from the transitions seen in training. Training itself is unchanged.
    Model,
}

/// How the options level rewards an option execution.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum RewardKind {
    /// The task's robustness over the segment, as in the paper.
    #[default]
    Segment,
    /// The discounted count of kept windows (needs `memory`).
    Window,
}

/// What generated code implements: a spec that can hand its data to the runtime.
pub trait Spec {
    /// The spec as plain data.
    fn task_spec(&self) -> TaskSpec;
}

impl Default for LearnParams {
    fn default() -> LearnParams {
        LearnParams {
            episodes: 1200,
            choices: 200,
            max_steps: 500,
            memory: 0,
            intra: Intra::Paper,
            reward: RewardKind::Segment,
            counterfactual: 0,
            switch: Switch::Termination,
            plan: Plan::Off,
            flat: LevelParams::FLAT,
            options: LevelParams::OPTIONS,
            tiles: None,
        }
    }
}

impl LevelParams {
    /// The paper's flat level: gamma 0.9, alpha 0.2, epsilon 0.8 down to 0.1 by 1e-6.
    pub const FLAT: LevelParams =
        LevelParams { gamma: 0.9, alpha: 0.2, epsilon: 0.8, min_epsilon: 0.1, decay: 1e-6 };
    /// The paper's options level: gamma 0.9, alpha 0.5, epsilon 0.8 down to 0.1 by 1e-4.
    pub const OPTIONS: LevelParams =
        LevelParams { gamma: 0.9, alpha: 0.5, epsilon: 0.8, min_epsilon: 0.1, decay: 1e-4 };

    /// The exploration rate after `n` decay steps.
    pub fn epsilon_at(&self, n: u64) -> f64 {
        (self.epsilon - self.decay * n as f64).max(self.min_epsilon)
    }

    fn validate(&self, level: &str) -> Result<(), Error> {
        let bad = |what: &str| Err(Error::Spec(format!("{level} {what}")));
        if !(self.gamma > 0.0 && self.gamma <= 1.0) {
            return bad(&format!("gamma {} is not in (0, 1]", self.gamma));
        }
        if !(self.alpha > 0.0 && self.alpha <= 1.0) {
            return bad(&format!("alpha {} is not in (0, 1]", self.alpha));
        }
        if !(0.0 <= self.min_epsilon && self.min_epsilon <= self.epsilon && self.epsilon <= 1.0) {
            return bad(&format!(
                "epsilon {} and min_epsilon {} break 0 <= min_epsilon <= epsilon <= 1",
                self.epsilon, self.min_epsilon
            ));
        }
        if !(self.decay >= 0.0 && self.decay.is_finite()) {
            return bad(&format!("decay {} is not a finite number >= 0", self.decay));
        }
        Ok(())
    }
}

impl Spec for TaskSpec {
    fn task_spec(&self) -> TaskSpec {
        self.clone()
    }
}

impl TaskSpec {
    /// Checks the spec on its own: names, indices, domains, state formulas, parameters and
    /// regions. Fitting it to an environment is checked when training starts.
    pub fn validate(&self) -> Result<(), Error> {
        let err = |m: String| Err(Error::Spec(m));
        if self.state_vars.is_empty() {
            return err("the spec has no state variable".into());
        }
        if let Some(t) = &self.learn.tiles {
            let n = self.state_vars.len();
            if t.bins.len() != n || t.lo.len() != n || t.hi.len() != n {
                return err(format!(
                    "the tiling has bounds for other than the {n} state variables"
                ));
            }
        }
        for v in &self.state_vars {
            match &v.domain {
                // The approximate learner covers a continuous variable with its tiling.
                None if self.learn.tiles.is_some() => {}
                None => return err(format!("state variable {} has no finite int range", v.name)),
                Some(d) if d.is_empty() => {
                    return err(format!(
                        "state variable {} has an empty range {}..={}",
                        v.name,
                        d.start(),
                        d.end()
                    ));
                }
                Some(_) => {}
            }
        }
        let vars = self.state_vars.len();
        let reads_known = |f: &Formula| f.max_var().is_none_or(|i| i < vars);
        if !reads_known(&self.task) {
            return err("the task reads a state variable the spec does not declare".into());
        }
        if self.primitives.is_empty() {
            return err("the spec declares no primitive option".into());
        }
        for p in &self.primitives {
            let mut formulas = vec![("reach", &p.reach), ("init", &p.init)];
            if let Terminate::Formula(f) = &p.terminate {
                formulas.push(("terminate", f));
            }
            if let Some(f) = &p.avoid {
                formulas.push(("avoid", f));
            }
            for (part, f) in formulas {
                if !f.is_state_formula() {
                    return err(format!("the {part} formula of option {} is temporal", p.name));
                }
                if !reads_known(f) {
                    return err(format!(
                        "the {part} formula of option {} reads an undeclared variable",
                        p.name
                    ));
                }
            }
        }
        if self.options.is_empty() {
            return err("the options set is empty".into());
        }
        for o in &self.options {
            if o.sequence.is_empty() {
                return err(format!("option {} has an empty sequence", o.name));
            }
            if let Some(&i) = o.sequence.iter().find(|&&i| i >= self.primitives.len()) {
                return err(format!("option {} names primitive {i}, which does not exist", o.name));
            }
        }
        for (i, o) in self.options.iter().enumerate() {
            if self.options[..i].iter().any(|p| p.name == o.name) {
                return err(format!("two options are named {}", o.name));
            }
        }
        let l = &self.learn;
        for (name, value) in
            [("episodes", l.episodes), ("choices", l.choices), ("max_steps", l.max_steps)]
        {
            if value == 0 {
                return err(format!("{name} must be > 0"));
            }
        }
        l.flat.validate("flat")?;
        l.options.validate("options")?;
        if !self.regions.is_empty() {
            let Some(found) = persistent_regions(&self.task) else {
                return err("regions are given, but the task is not of the form always[0..] \
                            (eventually[0..N1] R1 && ...)"
                    .into());
            };
            let same = found.len() == self.regions.len()
                && found
                    .iter()
                    .zip(&self.regions)
                    .all(|((f, n), r)| *f == r.formula && *n == r.horizon);
            if !same {
                return err("the regions do not match the task's conjuncts".into());
            }
        }
        if l.counterfactual > 0 && (l.memory == 0 || l.reward != RewardKind::Window) {
            return err("counterfactual updates need memory and reward: window".into());
        }
        if (l.memory > 0 || l.reward == RewardKind::Window) && self.regions.is_empty() {
            return err("memory and reward: window need a task of the form always[0..] \
                        (eventually[0..N1] R1 && ...) and its regions"
                .into());
        }
        Ok(())
    }

    /// The regions of the task read off its form, named `R1`, `R2`, ..., or `None` when
    /// the task is not `always[0..] (eventually[0..N1] R1 && ...)`.
    pub fn regions_from_task(&self) -> Option<Vec<Region>> {
        let found = persistent_regions(&self.task)?;
        Some(
            found
                .into_iter()
                .enumerate()
                .map(|(i, (formula, horizon))| Region {
                    name: format!("R{}", i + 1),
                    formula,
                    horizon,
                })
                .collect(),
        )
    }
}

/// The conjuncts `(R_j, N_j)` of a task `always[0..] (eventually[0..N1] R1 && ...)` whose
/// `R_j` are state formulas, or `None` for a task of another form. Safety conjuncts
/// `always[0..] !S` (`S` a state formula) may stand beside it at the top level: each adds
/// `(!S, 1)` after the others, since `always[0..] (P) && always[0..] !S` is `always[0..]
/// (P && eventually[0..1] !S)`: its windows are kept at a step where `S` does not hold.
pub fn persistent_regions(task: &Formula) -> Option<Vec<(Formula, usize)>> {
    let root = task.root_node();
    let Node::And(parts) = root else { return persistent_part(task, task.root()) };
    let mut persistent = parts.iter().filter(|&&p| persistent_part(task, p).is_some());
    let (Some(&p), None) = (persistent.next(), persistent.next()) else {
        return persistent_part(task, task.root());
    };
    let mut out = persistent_part(task, p)?;
    for &c in parts.iter().filter(|&&c| c != p) {
        let Node::Always(i, body) = &task[c] else { return None };
        let Node::Not(s) = &task[*body] else { return None };
        if *i != Interval::ALL || !task.is_state(*s) {
            return None;
        }
        out.push((task.sub(*body), 1));
    }
    Some(out)
}

/// [`persistent_regions`] of the sub-formula at `at`, which must be `always[0..] (...)`.
fn persistent_part(task: &Formula, at: NodeId) -> Option<Vec<(Formula, usize)>> {
    let Node::Always(outer, body) = &task[at] else { return None };
    if *outer != Interval::ALL {
        return None;
    }
    let conjuncts: Vec<NodeId> = match &task[*body] {
        Node::And(fs) => fs.clone(),
        _ => vec![*body],
    };
    let mut out = Vec::with_capacity(conjuncts.len());
    for c in conjuncts {
        let Node::Eventually(i, r) = &task[c] else { return None };
        if i.start != 0 || !task.is_state(*r) {
            return None;
        }
        let n = match i.end {
            Bound::Exclusive(b) => b,
            Bound::Inclusive(b) => b.checked_add(1)?,
            Bound::Unbounded => return None,
        };
        if n == 0 {
            return None;
        }
        out.push((task.sub(*r), n));
    }
    if out.is_empty() { None } else { Some(out) }
}
