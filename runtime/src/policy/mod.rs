//! Greedy policies, and the `policy.json` document.
//!
//! **contract** (DESIGN.md, `hstlc train`): `spec`, `env` `{name, params}`,
//! `state_vars`, `actions`, `options` `[{name, sequence}]`, `options_policy` and
//! `flat_policies` as lists of `{"state": {VAR: value}, "choice": NAME}` covering every
//! state, `primitives` with each one's `terminate` set as a list of states. Beyond the
//! contract the document holds `max_steps` and `q_tables`, so that training can continue:
//! every Q-value is stored as the 16 hex digits of its IEEE-754 bits, which reload bit for
//! bit, infinities and NaNs included. Readers ignore fields they do not know, as "at
//! least" in the contract asks.
//!
//! **contract, with `memory: B`**: the document also holds `"memory": {"regions": [NAME...],
//! "horizons": [N...], "buckets": B}`, and each `options_policy` entry holds `"memory":
//! [b_1, ...]` beside `"state"`: one entry per state and memory value that can be observed
//! there (inside region `j`, `b_j` is 0). Beyond the contract, `memory.states` lists the
//! states of each region, so that a replay can track the counters without the spec.
//!
//! **Beyond the contract, with goals** (a task that is not persistent, see
//! [`crate::progress`]): the document also holds `"goals": [TEXT...]`, the task's goals in
//! conjunct order as formulas, and each `options_policy` entry holds `"goals_met": [j...]`,
//! the indices of the goals met: one entry per state, memory value and set of goals met.
//! A replay reads the goals from the spec ([`Policy::agent_for`]).
//!
//! The JSON is indented down to the entries; each entry, state and table is on one line.

use std::collections::{BTreeMap, HashMap};

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

pub use crate::policy_parts::{HexTable, State};

use crate::greedy::{argmax, best_of};
use crate::memory::Memory;
use crate::progress::StateGoals;
use crate::tables::Tables;
use crate::{Env, Error, Learner, QTables, Switch, TaskSpec};

mod build;
mod document;
mod replay;

/// Greedy policies over state indices: what a rollout follows.
#[derive(Clone, Debug, PartialEq)]
pub struct Agent {
    /// `legs[o]`: the primitives option `o` runs, in order.
    pub legs: Vec<Vec<usize>>,
    /// `options[obs]`: the option the options policy picks on observing `obs`:
    /// `(s * memory.values() + code) * goals.codes() + met` (the state index without
    /// memory and goals). An observation that cannot occur (a bucket other than 0 inside
    /// its region) holds `usize::MAX`.
    pub options: Vec<usize>,
    /// `flat[p][s]`: the action primitive `p` takes in state `s`.
    pub flat: Vec<Vec<usize>>,
    /// `terminate[p][s]`: primitive `p` stops on reaching `s`.
    pub terminate: Vec<Vec<bool>>,
    /// Steps after which a leg is cut off.
    pub max_steps: usize,
    /// The memory the options policy observes (`memory: B > 0`), or `None`.
    pub memory: Option<Memory>,
    /// The goals the options policy observes (a task that is not persistent), or `None`.
    pub goals: Option<StateGoals>,
    /// When a run chooses an option: on termination, or at every step.
    pub switch: Switch,
    /// With [`Switch::Step`], the options Q-table (`obs * options + o`): a running option
    /// gives way only to one of strictly greater value. Empty otherwise.
    pub options_q: Vec<f64>,
}

/// The `policy.json` document.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Policy {
    /// The spec's name.
    pub spec: String,
    /// The environment the policy was trained on.
    pub env: EnvInfo,
    /// The environment's state variables, in order.
    pub state_vars: Vec<String>,
    /// The environment's actions, in order.
    pub actions: Vec<String>,
    /// The options set.
    pub options: Vec<OptionInfo>,
    /// The primitive options and their termination sets.
    pub primitives: Vec<PrimitiveInfo>,
    /// The memory the options policy observes, for a spec with `memory: B > 0`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub memory: Option<MemoryDoc>,
    /// The goals the options policy observes, as formulas, for a task with goals.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goals: Option<Vec<String>>,
    /// The greedy option in every state (and every memory value there, with memory).
    pub options_policy: Vec<Entry>,
    /// For every primitive option, the greedy action in every state.
    pub flat_policies: BTreeMap<String, Vec<Entry>>,
    /// Steps after which a leg is cut off.
    pub max_steps: usize,
    /// When a run chooses an option (`"step"` for [`Switch::Step`]; absent, as in every
    /// policy of the paper's settings, for [`Switch::Termination`]).
    #[serde(default, skip_serializing_if = "Switch::is_termination")]
    pub switch: Switch,
    /// The Q-tables, bit for bit.
    pub q_tables: QTablesDoc,
}

/// The environment part of `policy.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EnvInfo {
    /// The environment's name.
    pub name: String,
    /// Its parameters.
    pub params: Value,
}

/// A member of the options set in `policy.json`.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct OptionInfo {
    /// The option's name.
    pub name: String,
    /// The names of its primitive options, in order.
    pub sequence: Vec<String>,
}

/// A primitive option in `policy.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PrimitiveInfo {
    /// The option's name.
    pub name: String,
    /// The states where it terminates.
    pub terminate: Vec<State>,
}

/// The memory part of `policy.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MemoryDoc {
    /// The region names, in conjunct order.
    pub regions: Vec<String>,
    /// `N_j` of each region.
    pub horizons: Vec<usize>,
    /// `B`.
    pub buckets: usize,
    /// The states where each region holds.
    pub states: Vec<Vec<State>>,
}

/// One row of a policy table: in `state` (with `memory`), choose `choice`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// The state, `{VAR: value, ...}`.
    pub state: State,
    /// The buckets `[b_1, ...]` of an options-policy entry with memory.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub memory: Option<Vec<usize>>,
    /// The goals met (indices into the document's `goals`) of an options-policy entry of a
    /// task with goals.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub goals_met: Option<Vec<usize>>,
    /// The chosen option or action.
    pub choice: String,
}

/// The Q-tables in `policy.json`; each value is the 16 hex digits of its `f64` bits.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct QTablesDoc {
    /// Per primitive option, its table in state-major order (`s * actions + a`).
    pub flat: BTreeMap<String, HexTable>,
    /// The options table in observation-major order (`obs * options + o`).
    pub options: HexTable,
    /// Primitive steps taken.
    pub steps: u64,
    /// Option choices made.
    pub choices: u64,
}

impl Agent {
    pub(crate) fn from_q(
        tables: &Tables,
        q: &QTables,
        max_steps: usize,
        memory: Option<&Memory>,
        goals: Option<&StateGoals>,
        switch: Switch,
    ) -> Agent {
        let (n, a) = (tables.legs.len(), tables.actions);
        let values = memory.map_or(1, Memory::values);
        let codes = goals.map_or(1, StateGoals::codes);
        let options = (0..tables.states * values * codes)
            .map(|obs| {
                let s = obs / (values * codes);
                if memory.is_some_and(|m| !m.consistent(s, obs / codes % values)) {
                    usize::MAX
                } else {
                    best_of(&tables.available[s], &q.options[obs * n..][..n])
                }
            })
            .collect();
        let flat = q
            .flat
            .iter()
            .map(|t| (0..tables.states).map(|s| argmax(&t[s * a..][..a])).collect())
            .collect();
        Agent {
            legs: tables.legs.clone(),
            options,
            flat,
            terminate: tables.term.clone(),
            max_steps,
            memory: memory.cloned(),
            goals: goals.cloned(),
            switch,
            options_q: if switch == Switch::Step { q.options.clone() } else { Vec::new() },
        }
    }

    /// The observation of state `s` with counters `tau` (ignored without memory) and the
    /// goals `met` (ignored without goals).
    pub fn observation(&self, s: usize, tau: &[usize], met: usize) -> usize {
        let obs = self.memory.as_ref().map_or(s, |m| m.observation(s, tau));
        match &self.goals {
            Some(g) => obs * g.codes() + met,
            None => obs,
        }
    }
}

impl Policy {
    /// The document's own field names, in the order it writes them (an optional field
    /// counts even where it is absent: a reader would take an extra field of its name for
    /// it).
    pub const FIELDS: [&str; 13] = [
        "spec",
        "env",
        "state_vars",
        "actions",
        "options",
        "primitives",
        "memory",
        "goals",
        "options_policy",
        "flat_policies",
        "max_steps",
        "switch",
        "q_tables",
    ];

    /// The stored Q-tables, in the primitive order of [`Policy::primitives`].
    pub fn q_tables(&self) -> Result<QTables, Error> {
        if let Some(extra) =
            self.q_tables.flat.keys().find(|k| !self.primitives.iter().any(|p| &p.name == *k))
        {
            return Err(Error::Policy(format!(
                "q_tables.flat has a table for `{}`, which is no primitive option of the document",
                extra.escape_debug()
            )));
        }
        let flat = self
            .primitives
            .iter()
            .map(|p| {
                let t = self.q_tables.flat.get(&p.name).ok_or_else(|| {
                    Error::Policy(format!("q_tables.flat has no table for option {}", p.name))
                })?;
                Ok(t.0.clone())
            })
            .collect::<Result<_, Error>>()?;
        Ok(QTables {
            flat,
            options: self.q_tables.options.0.clone(),
            steps: self.q_tables.steps,
            choices: self.q_tables.choices,
        })
    }
    /// The options-policy entries of one memory slice, one per state: in each state, the
    /// entry whose buckets are `memory`, with `b_j` read as 0 in the states of region `j`
    /// (where no other value occurs). Without memory, `memory` must be empty and the
    /// slice is the whole options policy. Fails when `memory` does not have one bucket in
    /// `0..=B` per region.
    pub fn options_slice(&self, memory: &[usize]) -> Result<Vec<Entry>, Error> {
        let Some(doc) = &self.memory else {
            if memory.is_empty() {
                return Ok(self.options_policy.clone());
            }
            return Err(Error::Config(
                "the policy has no memory; ask for the slice [] instead".into(),
            ));
        };
        if memory.len() != doc.regions.len() || memory.iter().any(|&b| b > doc.buckets) {
            return Err(Error::Config(format!(
                "the memory slice {} needs one bucket in 0..={} for each of the regions {}",
                json_list(memory),
                doc.buckets,
                crate::words::and_list(&doc.regions)
            )));
        }
        let inside: Vec<std::collections::HashSet<Vec<u64>>> =
            doc.states.iter().map(|states| states.iter().map(State::bits).collect()).collect();
        Ok(self
            .options_policy
            .iter()
            .filter(|e| {
                let k = e.state.bits();
                let want = memory
                    .iter()
                    .zip(&inside)
                    .map(|(&b, set)| if set.contains(&k) { 0 } else { b });
                e.memory.as_ref().is_some_and(|m| m.iter().copied().eq(want))
            })
            .cloned()
            .collect())
    }

    /// The slices to draw a memory policy by (see [`Policy::options_slice`]): one per
    /// memory value `v` in `0..=B`, every region's bucket set to `v`, labelled as
    /// `"b = [v, v, ...]"`; without memory, the one slice `[]` labelled `""`.
    pub fn memory_slices(&self) -> Vec<(String, Vec<usize>)> {
        match &self.memory {
            None => vec![(String::new(), Vec::new())],
            Some(doc) => (0..=doc.buckets)
                .map(|v| {
                    let b = vec![v; doc.regions.len()];
                    (format!("b = {}", json_list(&b)), b)
                })
                .collect(),
        }
    }
}

/// The state with index `s` of `env` as the document writes it.
fn state_of<E: Env>(env: &E, vars: &[String], s: usize) -> State {
    let mut values = Vec::new();
    if let Some(state) = env.state(s) {
        env.valuation(&state, &mut values);
    }
    values.resize(vars.len(), f64::NAN);
    State::new(vars, &values)
}

/// Numbers as `policy.json` writes a list of them: `[0, 3, 1]`.
fn json_list<T: std::fmt::Display>(values: &[T]) -> String {
    let parts: Vec<String> = values.iter().map(ToString::to_string).collect();
    format!("[{}]", parts.join(", "))
}
