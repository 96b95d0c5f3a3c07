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

    /// The document of a learner's current greedy policies and Q-tables.
    pub fn new<E: Env>(learner: &Learner<'_, E>) -> Policy {
        let env = learner.env();
        let spec = learner.spec();
        let agent = learner.agent();
        let q = learner.q();
        let vars = env.state_vars();
        let actions = env.actions();
        let states: Vec<State> = (0..env.num_states()).map(|s| state_of(env, &vars, s)).collect();
        let prim = |p: usize| spec.primitives[p].name.clone();
        let options = spec
            .options
            .iter()
            .map(|o| OptionInfo {
                name: o.name.clone(),
                sequence: o.sequence.iter().map(|&p| prim(p)).collect(),
            })
            .collect();
        let primitives = spec
            .primitives
            .iter()
            .enumerate()
            .map(|(p, info)| PrimitiveInfo {
                name: info.name.clone(),
                terminate: (0..states.len())
                    .filter(|&s| learner.tables().term[p][s])
                    .map(|s| states[s].clone())
                    .collect(),
            })
            .collect();
        let memory = agent.memory.as_ref();
        let values = memory.map_or(1, Memory::values);
        let goals = agent.goals.as_ref();
        let codes = goals.map_or(1, StateGoals::codes);
        let options_policy = agent
            .options
            .iter()
            .enumerate()
            .filter(|&(_, &o)| o != usize::MAX)
            .map(|(obs, &o)| Entry {
                state: states[obs / (values * codes)].clone(),
                memory: memory.map(|m| m.decode(obs / codes % values)),
                goals_met: goals.map(|g| g.progress.decode(obs % codes)),
                choice: spec.options[o].name.clone(),
            })
            .collect();
        // The learner refused goals too long to write out: this does not fail.
        let goals = goals.map(|g| g.progress.goal_texts().unwrap_or_default());
        let memory = memory.map(|m| MemoryDoc {
            regions: m.regions.clone(),
            horizons: m.horizons.clone(),
            buckets: m.buckets,
            states: m
                .holds
                .iter()
                .map(|h| (0..states.len()).filter(|&s| h[s]).map(|s| states[s].clone()).collect())
                .collect(),
        });
        let flat_policies = agent
            .flat
            .iter()
            .enumerate()
            .map(|(p, row)| {
                let entries = row
                    .iter()
                    .enumerate()
                    .map(|(s, &a)| Entry {
                        state: states[s].clone(),
                        memory: None,
                        goals_met: None,
                        choice: actions[a].clone(),
                    })
                    .collect();
                (prim(p), entries)
            })
            .collect();
        let hex = |t: &[f64]| HexTable(t.to_vec());
        let q_tables = QTablesDoc {
            flat: q.flat.iter().enumerate().map(|(p, t)| (prim(p), hex(t))).collect(),
            options: hex(&q.options),
            steps: q.steps,
            choices: q.choices,
        };
        Policy {
            spec: spec.name.clone(),
            env: EnvInfo { name: env.name().to_string(), params: env.params() },
            state_vars: vars,
            actions,
            options,
            primitives,
            memory,
            goals,
            options_policy,
            flat_policies,
            max_steps: agent.max_steps,
            switch: agent.switch,
            q_tables,
        }
    }

    /// The document as JSON, indented down to the entries of its lists and maps; each
    /// entry (a policy row, a state, a Q-table) is written on one line.
    pub fn to_json(&self) -> Result<String, Error> {
        let mut out = Vec::new();
        let mut ser = serde_json::Serializer::with_formatter(&mut out, Shallow::default());
        self.serialize(&mut ser).map_err(|e| Error::Policy(e.to_string()))?;
        String::from_utf8(out).map_err(|e| Error::Policy(e.to_string()))
    }

    /// The document as [`Policy::to_json`] writes it, with `extra` fields (such as the spec's
    /// source) after the document's own; an extra field may not reuse a document field's
    /// name.
    pub fn to_json_with(&self, extra: &[(&str, Value)]) -> Result<String, Error> {
        #[derive(Serialize)]
        struct WithExtra<'a> {
            #[serde(flatten)]
            policy: &'a Policy,
            #[serde(flatten)]
            extra: Map<String, Value>,
        }
        let mut fields = Map::new();
        for (name, value) in extra {
            if Policy::FIELDS.contains(name) || fields.contains_key(*name) {
                return Err(Error::Policy(format!(
                    "the extra field {name} is already in the document; give it another name"
                )));
            }
            fields.insert((*name).to_string(), value.clone());
        }
        let mut out = Vec::new();
        let mut ser = serde_json::Serializer::with_formatter(&mut out, Shallow::default());
        WithExtra { policy: self, extra: fields }
            .serialize(&mut ser)
            .map_err(|e| Error::Policy(e.to_string()))?;
        String::from_utf8(out).map_err(|e| Error::Policy(e.to_string()))
    }

    /// Reads a document; the error says what is wrong and where.
    pub fn from_json(text: &str) -> Result<Policy, Error> {
        Policy::from_json_with(text, &[]).map(|(policy, _)| policy)
    }

    /// Reads a document and the `extra` fields among those beyond the document's own (as
    /// [`Policy::to_json_with`] writes them), in one typed pass: every field is read into
    /// its type as it comes, a field the document does not know and `extra` does not name
    /// is skipped without being kept, and a field given twice is an error. The error says
    /// what is wrong and where (line and column).
    pub fn from_json_with(
        text: &str,
        extra: &[&str],
    ) -> Result<(Policy, Map<String, Value>), Error> {
        let mut de = serde_json::Deserializer::from_str(text);
        let read = serde::Deserializer::deserialize_map(&mut de, DocumentVisitor { extra })
            .and_then(|doc| de.end().map(|()| doc));
        read.map_err(|e| Error::Policy(e.to_string()))
    }

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

    /// Checks the document whole against the spec and environment it claims: its Q-tables
    /// have the spec's shape and hold no NaN, and every other entry (options, termination
    /// sets, greedy choices, memory, goals) is what those Q-tables give for this spec on
    /// `env`, each state listed once (with goals, once per set of goals met). A document
    /// edited by hand, truncated or paired with another spec fails. The greedy policies are
    /// compared as tables over observations (state, memory value and goals met), so the
    /// check costs what the document's numbers do, not a second document. Returns the
    /// document's greedy agent on `env` ([`Policy::agent_for`]).
    pub fn check_against<E: Env>(&self, spec: &TaskSpec, env: &E) -> Result<Agent, Error> {
        let err = |m: String| Err(Error::Policy(m));
        let q = self.q_tables()?;
        let tables =
            q.flat.iter().zip(&self.primitives).map(|(t, p)| (format!("flat table {}", p.name), t));
        let all = tables.chain(std::iter::once(("the options table".to_string(), &q.options)));
        for (what, table) in all {
            if let Some(i) = table.iter().position(|v| v.is_nan()) {
                return err(format!("{what} holds NaN at entry {i}"));
            }
        }
        let learner = Learner::new(spec, env)?.with_tables(q)?;
        if spec.name != self.spec {
            return err(format!("it names spec `{}`, not `{}`", self.spec, spec.name));
        }
        let theirs = learner.agent();
        if theirs.switch != self.switch {
            return err(format!(
                "its `switch` is `{}`, but the spec it was trained on has `switch: {}`",
                self.switch.word(),
                theirs.switch.word()
            ));
        }
        let differs = |part: &str| {
            Err(Error::Policy(format!(
                "its `{part}` is not what its `q_tables` give for the spec it was trained on"
            )))
        };
        let prim = |p: usize| spec.primitives[p].name.as_str();
        let options_same = self.options.len() == spec.options.len()
            && self.options.iter().zip(&spec.options).all(|(mine, o)| {
                mine.name == o.name
                    && mine
                        .sequence
                        .iter()
                        .map(String::as_str)
                        .eq(o.sequence.iter().map(|&p| prim(p)))
            });
        if !options_same {
            return differs("options");
        }
        let names_same = self.primitives.len() == spec.primitives.len()
            && self.primitives.iter().zip(&spec.primitives).all(|(a, b)| a.name == b.name);
        if !names_same {
            return differs("primitives");
        }
        let header = |m: &MemoryDoc| (m.regions.clone(), m.horizons.clone(), m.buckets);
        let memory_same = match (&self.memory, &theirs.memory) {
            (None, None) => true,
            (Some(doc), Some(m)) => {
                header(doc) == (m.regions.clone(), m.horizons.clone(), m.buckets)
            }
            _ => false,
        };
        if !memory_same {
            return differs("memory");
        }
        let goals = theirs.goals.as_ref().map(|g| g.progress.goal_texts()).transpose()?;
        if goals != self.goals {
            return differs("goals");
        }
        if self.max_steps != theirs.max_steps {
            return differs("max_steps");
        }
        let mine = self.agent_for(spec, env)?;
        let count = |t: &[bool]| t.iter().filter(|&&b| b).count();
        let terminate_same = mine.terminate == theirs.terminate
            && self
                .primitives
                .iter()
                .zip(&theirs.terminate)
                .all(|(p, t)| p.terminate.len() == count(t));
        if !terminate_same {
            return differs("primitives");
        }
        if let (Some(doc), Some(m)) = (&self.memory, &theirs.memory) {
            let holds_same = mine.memory.as_ref().is_some_and(|mm| mm.holds == m.holds)
                && doc.states.iter().zip(&m.holds).all(|(s, h)| s.len() == count(h));
            if !holds_same {
                return differs("memory");
            }
        }
        let n = env.num_states();
        let flat_same = mine.flat == theirs.flat
            && self.flat_policies.len() == self.primitives.len()
            && self.flat_policies.values().all(|t| t.len() == n);
        if !flat_same {
            return differs("flat_policies");
        }
        let observed = theirs.options.iter().filter(|&&o| o != usize::MAX).count();
        if mine.options != theirs.options || self.options_policy.len() != observed {
            return differs("options_policy");
        }
        Ok(mine)
    }

    /// The greedy policies on `env`'s state indices. Fails when the document does not fit
    /// `env`: another environment, a state it does not cover, an unknown name; and for a
    /// policy whose options level reads the task's goals, which [`Policy::agent_for`]
    /// replays.
    pub fn agent<E: Env>(&self, env: &E) -> Result<Agent, Error> {
        if self.goals.is_some() {
            return Err(Error::Policy(
                "the policy's options level reads the task's goals, which a replay takes from \
                 the spec (Policy::agent_for)"
                    .into(),
            ));
        }
        self.agent_with(env, None)
    }

    /// [`Policy::agent`] with the spec it was trained on, which gives the task's goals; fails
    /// as [`Policy::agent`] does, and when the document's goals are not the spec's.
    pub fn agent_for<E: Env>(&self, spec: &TaskSpec, env: &E) -> Result<Agent, Error> {
        let goals = if spec.regions.is_empty() {
            StateGoals::of_task(&spec.task, &crate::tables::valuations(spec, env)?)
        } else {
            None
        };
        let texts = goals.as_ref().map(|g| g.progress.goal_texts()).transpose()?;
        if texts != self.goals {
            return Err(Error::Policy(
                "the document's `goals` are not the goals of the spec it was trained on".into(),
            ));
        }
        self.agent_with(env, goals)
    }

    fn agent_with<E: Env>(&self, env: &E, goals: Option<StateGoals>) -> Result<Agent, Error> {
        let err = |m: String| Err(Error::Policy(m));
        if self.env.name != env.name() {
            return err(format!(
                "the policy was trained on `{}`, not on `{}`",
                self.env.name,
                env.name()
            ));
        }
        if self.env.params != env.params() {
            return err(format!(
                "the policy was trained on another `{}` (its parameters differ)",
                env.name()
            ));
        }
        if self.state_vars != env.state_vars() || self.actions != env.actions() {
            return err("state_vars or actions differ from the environment's".into());
        }
        let n = env.num_states();
        let mut index = HashMap::with_capacity(n);
        let mut names = Vec::new();
        for s in 0..n {
            let state = state_of(env, &self.state_vars, s);
            if s == 0 {
                names = state.names().to_vec();
            }
            index.insert(state.bits(), s);
        }
        let lookup = |state: &State, what: &str| {
            (state.names() == names.as_slice())
                .then(|| index.get(&state.bits()).copied())
                .flatten()
                .ok_or_else(|| {
                    Error::Policy(format!(
                        "{what} names state {state}, which the environment lacks"
                    ))
                })
        };
        let prim_index = |name: &str| {
            self.primitives.iter().position(|p| p.name == name).ok_or_else(|| {
                Error::Policy(format!("option sequence names unknown primitive {name}"))
            })
        };
        let legs = self
            .options
            .iter()
            .map(|o| {
                if o.sequence.is_empty() {
                    return Err(Error::Policy(format!("option {} has an empty sequence", o.name)));
                }
                o.sequence.iter().map(|p| prim_index(p)).collect::<Result<Vec<usize>, Error>>()
            })
            .collect::<Result<Vec<Vec<usize>>, _>>()?;
        let memory = match &self.memory {
            None => None,
            Some(doc) => Some(self.memory_of(doc, n, &lookup)?),
        };
        let options =
            fill_options(n, memory.as_ref(), goals.as_ref(), &self.options_policy, &lookup, |c| {
                self.options.iter().position(|o| o.name == c)
            })?;
        let mut flat = Vec::new();
        let mut terminate = Vec::new();
        for p in &self.primitives {
            let Some(entries) = self.flat_policies.get(&p.name) else {
                return err(format!("flat_policies has no table for option {}", p.name));
            };
            let what = format!("flat_policies.{}", p.name);
            flat.push(fill(n, entries, &what, &lookup, |c| {
                self.actions.iter().position(|a| a == c)
            })?);
            let mut t = vec![false; n];
            for state in &p.terminate {
                t[lookup(state, &format!("the terminate set of {}", p.name))?] = true;
            }
            terminate.push(t);
        }
        let (max_steps, switch) = (self.max_steps, self.switch);
        let options_q = match switch {
            Switch::Step => self.q_tables.options.0.clone(),
            Switch::Termination => Vec::new(),
        };
        if switch == Switch::Step && options_q.len() != options.len() * legs.len() {
            return err(format!(
                "q_tables.options holds {} values, not {} (observations times options)",
                options_q.len(),
                options.len() * legs.len()
            ));
        }
        Ok(Agent { legs, options, flat, terminate, max_steps, memory, goals, switch, options_q })
    }

    /// The memory of the document's `memory` part.
    fn memory_of(
        &self,
        doc: &MemoryDoc,
        n: usize,
        lookup: &impl Fn(&State, &str) -> Result<usize, Error>,
    ) -> Result<Memory, Error> {
        if doc.buckets == 0 {
            return Err(Error::Policy("memory.buckets is 0; a memory policy has B > 0".into()));
        }
        if doc.states.len() != doc.regions.len() {
            return Err(Error::Policy(format!(
                "memory names {} regions but lists the states of {}",
                doc.regions.len(),
                doc.states.len()
            )));
        }
        let mut holds = Vec::with_capacity(doc.states.len());
        for (name, states) in doc.regions.iter().zip(&doc.states) {
            let mut h = vec![false; n];
            for state in states {
                h[lookup(state, &format!("memory.states of region {name}"))?] = true;
            }
            holds.push(h);
        }
        Memory::new(doc.regions.clone(), doc.horizons.clone(), doc.buckets, holds)
            .map_err(|e| Error::Policy(format!("memory: {e}")))
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

/// The one pass over a document that [`Policy::from_json_with`] makes.
struct DocumentVisitor<'a> {
    extra: &'a [&'a str],
}

impl<'de> serde::de::Visitor<'de> for DocumentVisitor<'_> {
    type Value = (Policy, Map<String, Value>);

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a policy.json document, an object")
    }

    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        use serde::de::{Error as _, IgnoredAny};
        fn set<T, E: serde::de::Error>(
            slot: &mut Option<T>,
            value: T,
            name: &str,
        ) -> Result<(), E> {
            if slot.is_some() {
                return Err(E::custom(format!("the field `{name}` is given twice")));
            }
            *slot = Some(value);
            Ok(())
        }
        let (mut spec, mut env, mut state_vars, mut actions, mut options) =
            (None, None, None, None, None);
        let (mut primitives, mut memory, mut options_policy, mut flat_policies) =
            (None, None, None, None);
        let (mut goals, mut max_steps, mut switch, mut q_tables) = (None, None, None, None);
        let mut extras = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            match key.as_str() {
                "spec" => set(&mut spec, map.next_value()?, &key)?,
                "env" => set(&mut env, map.next_value()?, &key)?,
                "state_vars" => set(&mut state_vars, map.next_value()?, &key)?,
                "actions" => set(&mut actions, map.next_value()?, &key)?,
                "options" => set(&mut options, map.next_value()?, &key)?,
                "primitives" => set(&mut primitives, map.next_value()?, &key)?,
                "memory" => set(&mut memory, map.next_value::<Option<MemoryDoc>>()?, &key)?,
                "goals" => set(&mut goals, map.next_value::<Option<Vec<String>>>()?, &key)?,
                "options_policy" => set(&mut options_policy, map.next_value()?, &key)?,
                "flat_policies" => set(&mut flat_policies, map.next_value()?, &key)?,
                "max_steps" => set(&mut max_steps, map.next_value()?, &key)?,
                "switch" => set(&mut switch, map.next_value()?, &key)?,
                "q_tables" => set(&mut q_tables, map.next_value()?, &key)?,
                k if self.extra.contains(&k) => {
                    if extras.contains_key(k) {
                        return Err(A::Error::custom(format!("the field `{k}` is given twice")));
                    }
                    let value: Value = map.next_value()?;
                    extras.insert(key, value);
                }
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        let policy = Policy {
            spec: spec.ok_or_else(|| A::Error::missing_field("spec"))?,
            env: env.ok_or_else(|| A::Error::missing_field("env"))?,
            state_vars: state_vars.ok_or_else(|| A::Error::missing_field("state_vars"))?,
            actions: actions.ok_or_else(|| A::Error::missing_field("actions"))?,
            options: options.ok_or_else(|| A::Error::missing_field("options"))?,
            primitives: primitives.ok_or_else(|| A::Error::missing_field("primitives"))?,
            memory: memory.flatten(),
            goals: goals.flatten(),
            options_policy: options_policy
                .ok_or_else(|| A::Error::missing_field("options_policy"))?,
            flat_policies: flat_policies.ok_or_else(|| A::Error::missing_field("flat_policies"))?,
            max_steps: max_steps.ok_or_else(|| A::Error::missing_field("max_steps"))?,
            switch: switch.unwrap_or_default(),
            q_tables: q_tables.ok_or_else(|| A::Error::missing_field("q_tables"))?,
        };
        Ok((policy, extras))
    }
}

/// A JSON formatter that indents like `serde_json`'s pretty printer down to depth 2 and
/// writes anything deeper on one line, with a space after each `,` and `:`.
#[derive(Default)]
struct Shallow {
    depth: usize,
    has_value: bool,
}

impl Shallow {
    const INDENTED: usize = 2;

    fn open<W: ?Sized + std::io::Write>(&mut self, w: &mut W, c: &[u8]) -> std::io::Result<()> {
        self.depth += 1;
        self.has_value = false;
        w.write_all(c)
    }

    fn close<W: ?Sized + std::io::Write>(&mut self, w: &mut W, c: &[u8]) -> std::io::Result<()> {
        self.depth -= 1;
        if self.has_value && self.depth < Self::INDENTED {
            self.newline(w)?;
        }
        w.write_all(c)
    }

    fn item<W: ?Sized + std::io::Write>(&mut self, w: &mut W, first: bool) -> std::io::Result<()> {
        if self.depth <= Self::INDENTED {
            w.write_all(if first { b"" } else { b"," })?;
            self.newline(w)
        } else {
            w.write_all(if first { b"" } else { b", " })
        }
    }

    fn newline<W: ?Sized + std::io::Write>(&self, w: &mut W) -> std::io::Result<()> {
        w.write_all(b"\n")?;
        for _ in 0..self.depth {
            w.write_all(b"  ")?;
        }
        Ok(())
    }
}

impl serde_json::ser::Formatter for Shallow {
    fn begin_array<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.open(w, b"[")
    }

    fn end_array<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.close(w, b"]")
    }

    fn begin_array_value<W: ?Sized + std::io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        self.item(w, first)
    }

    fn end_array_value<W: ?Sized + std::io::Write>(&mut self, _: &mut W) -> std::io::Result<()> {
        self.has_value = true;
        Ok(())
    }

    fn begin_object<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.open(w, b"{")
    }

    fn end_object<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        self.close(w, b"}")
    }

    fn begin_object_key<W: ?Sized + std::io::Write>(
        &mut self,
        w: &mut W,
        first: bool,
    ) -> std::io::Result<()> {
        self.item(w, first)
    }

    fn begin_object_value<W: ?Sized + std::io::Write>(&mut self, w: &mut W) -> std::io::Result<()> {
        w.write_all(b": ")
    }

    fn end_object_value<W: ?Sized + std::io::Write>(&mut self, _: &mut W) -> std::io::Result<()> {
        self.has_value = true;
        Ok(())
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

/// The options table from policy entries, indexed by observation: every state (with
/// every memory value that can occur there, and every set of goals met) must be covered.
fn fill_options(
    n: usize,
    memory: Option<&Memory>,
    goals: Option<&StateGoals>,
    entries: &[Entry],
    lookup: &impl Fn(&State, &str) -> Result<usize, Error>,
    choice: impl Fn(&str) -> Option<usize>,
) -> Result<Vec<usize>, Error> {
    let err = |m: String| Err(Error::Policy(m));
    if memory.is_none() && goals.is_none() {
        if entries.iter().any(|e| e.memory.is_some()) {
            return err(
                "options_policy has an entry with memory, but the document has no memory part"
                    .into(),
            );
        }
        if entries.iter().any(|e| e.goals_met.is_some()) {
            return err(
                "options_policy has an entry with goals_met, but the document has no goals".into(),
            );
        }
        return fill(n, entries, "options_policy", lookup, choice);
    }
    let values = memory.map_or(1, Memory::values);
    let codes = goals.map_or(1, StateGoals::codes);
    let mut out = vec![usize::MAX; n * values * codes];
    for e in entries {
        let s = lookup(&e.state, "options_policy")?;
        let code = match (memory, &e.memory) {
            (None, None) => 0,
            (None, Some(_)) => {
                return err(
                    "options_policy has an entry with memory, but the document has no memory \
                     part"
                        .into(),
                );
            }
            (Some(_), None) => {
                return err(format!(
                    "options_policy has an entry for state {} without memory; a memory policy \
                     gives [b_1, ...] in each entry",
                    e.state
                ));
            }
            (Some(m), Some(b)) => {
                m.code_of_buckets(b).filter(|&c| m.consistent(s, c)).ok_or_else(|| {
                    Error::Policy(format!(
                        "options_policy gives state {} the memory {}, which is not {} \
                         buckets in 0..={} with 0 for the regions the state lies in",
                        e.state,
                        json_list(b),
                        m.len(),
                        m.buckets
                    ))
                })?
            }
        };
        let met = match (goals, &e.goals_met) {
            (None, None) => 0,
            (None, Some(_)) => {
                return err(
                    "options_policy has an entry with goals_met, but the document has no goals"
                        .into(),
                );
            }
            (Some(_), None) => {
                return err(format!(
                    "options_policy has an entry for state {} without goals_met; a policy with \
                     goals gives the goals met in each entry",
                    e.state
                ));
            }
            (Some(g), Some(list)) => g.progress.encode(list).ok_or_else(|| {
                Error::Policy(format!(
                    "options_policy gives state {} the goals met {}, which are not \
                     indices of its {} goals",
                    e.state,
                    json_list(list),
                    g.progress.goals()
                ))
            })?,
        };
        out[(s * values + code) * codes + met] = choice(&e.choice)
            .ok_or_else(|| Error::Policy(format!("options_policy chooses unknown {}", e.choice)))?;
    }
    let possible = |obs: usize| {
        memory.is_none_or(|m| m.consistent(obs / (values * codes), obs / codes % values))
    };
    if let Some(obs) = (0..out.len()).find(|&obs| out[obs] == usize::MAX && possible(obs)) {
        let memory =
            memory.map(|m| format!(" with memory {}", json_list(&m.decode(obs / codes % values))));
        let goals = goals
            .map(|g| format!(" with goals met {}", json_list(&g.progress.decode(obs % codes))));
        return err(format!(
            "options_policy does not cover state index {}{}{}",
            obs / (values * codes),
            memory.unwrap_or_default(),
            goals.unwrap_or_default()
        ));
    }
    Ok(out)
}

/// A per-state table from policy entries; every state must be covered exactly once.
fn fill(
    n: usize,
    entries: &[Entry],
    what: &str,
    lookup: &impl Fn(&State, &str) -> Result<usize, Error>,
    choice: impl Fn(&str) -> Option<usize>,
) -> Result<Vec<usize>, Error> {
    let mut out = vec![usize::MAX; n];
    for e in entries {
        let s = lookup(&e.state, what)?;
        out[s] = choice(&e.choice)
            .ok_or_else(|| Error::Policy(format!("{what} chooses unknown {}", e.choice)))?;
    }
    if let Some(s) = out.iter().position(|&c| c == usize::MAX) {
        return Err(Error::Policy(format!("{what} does not cover state index {s}")));
    }
    Ok(out)
}

/// Numbers as `policy.json` writes a list of them: `[0, 3, 1]`.
fn json_list<T: std::fmt::Display>(values: &[T]) -> String {
    let parts: Vec<String> = values.iter().map(ToString::to_string).collect();
    format!("[{}]", parts.join(", "))
}
