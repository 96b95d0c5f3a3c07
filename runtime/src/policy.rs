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

use std::collections::{BTreeMap, HashMap};

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

use crate::learn::{argmax, best_of};
use crate::tables::Tables;
use crate::{Env, Error, Learner, QTables};

/// Greedy policies over state indices: what a rollout follows.
#[derive(Clone, Debug, PartialEq)]
pub struct Agent {
    /// `legs[o]`: the primitives option `o` runs, in order.
    pub legs: Vec<Vec<usize>>,
    /// `options[s]`: the option the options policy picks in state `s`.
    pub options: Vec<usize>,
    /// `flat[p][s]`: the action primitive `p` takes in state `s`.
    pub flat: Vec<Vec<usize>>,
    /// `terminate[p][s]`: primitive `p` stops on reaching `s`.
    pub terminate: Vec<Vec<bool>>,
    /// Steps after which a leg is cut off.
    pub max_steps: usize,
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
    /// The greedy option in every state.
    pub options_policy: Vec<Entry>,
    /// For every primitive option, the greedy action in every state.
    pub flat_policies: BTreeMap<String, Vec<Entry>>,
    /// Steps after which a leg is cut off.
    pub max_steps: usize,
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
    pub terminate: Vec<Map<String, Value>>,
}

/// One row of a policy table: in `state`, choose `choice`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Entry {
    /// The state, as a map from variable name to value.
    pub state: Map<String, Value>,
    /// The chosen option or action.
    pub choice: String,
}

/// The Q-tables in `policy.json`; each value is the 16 hex digits of its `f64` bits.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct QTablesDoc {
    /// Per primitive option, its table in state-major order (`s * actions + a`).
    pub flat: BTreeMap<String, Vec<String>>,
    /// The options table in observation-major order (`obs * options + o`).
    pub options: Vec<String>,
    /// Primitive steps taken.
    pub steps: u64,
    /// Option choices made.
    pub choices: u64,
}

impl Agent {
    pub(crate) fn from_q(tables: &Tables, q: &QTables, max_steps: usize) -> Agent {
        let (n, a) = (tables.legs.len(), tables.actions);
        let options = (0..tables.states)
            .map(|s| best_of(&tables.available[s], &q.options[s * n..][..n]))
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
        }
    }
}

impl Policy {
    /// The document of a learner's current greedy policies and Q-tables.
    pub fn new<E: Env>(learner: &Learner<'_, E>) -> Policy {
        let env = learner.env();
        let spec = learner.spec();
        let agent = learner.agent();
        let q = learner.q();
        let vars = env.state_vars();
        let actions = env.actions();
        let states: Vec<Map<String, Value>> =
            (0..env.num_states()).map(|s| state_map(env, &vars, s)).collect();
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
        let options_policy = agent
            .options
            .iter()
            .enumerate()
            .map(|(s, &o)| Entry { state: states[s].clone(), choice: spec.options[o].name.clone() })
            .collect();
        let flat_policies = agent
            .flat
            .iter()
            .enumerate()
            .map(|(p, row)| {
                let entries = row
                    .iter()
                    .enumerate()
                    .map(|(s, &a)| Entry { state: states[s].clone(), choice: actions[a].clone() })
                    .collect();
                (prim(p), entries)
            })
            .collect();
        let hex = |t: &[f64]| t.iter().map(|v| format!("{:016x}", v.to_bits())).collect();
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
            options_policy,
            flat_policies,
            max_steps: agent.max_steps,
            q_tables,
        }
    }

    /// The document as pretty-printed JSON.
    pub fn to_json(&self) -> Result<String, Error> {
        serde_json::to_string_pretty(self).map_err(|e| Error::Policy(e.to_string()))
    }

    /// Reads a document; the error says what is wrong and where.
    pub fn from_json(text: &str) -> Result<Policy, Error> {
        serde_json::from_str(text).map_err(|e| Error::Policy(e.to_string()))
    }

    /// The stored Q-tables, in the primitive order of [`Policy::primitives`].
    pub fn q_tables(&self) -> Result<QTables, Error> {
        let flat = self
            .primitives
            .iter()
            .map(|p| {
                let t = self.q_tables.flat.get(&p.name).ok_or_else(|| {
                    Error::Policy(format!("q_tables.flat has no table for option {}", p.name))
                })?;
                unhex(t, &format!("q_tables.flat.{}", p.name))
            })
            .collect::<Result<_, _>>()?;
        Ok(QTables {
            flat,
            options: unhex(&self.q_tables.options, "q_tables.options")?,
            steps: self.q_tables.steps,
            choices: self.q_tables.choices,
        })
    }

    /// The greedy policies on `env`'s state indices. Fails when the document does not fit
    /// `env`: another environment, a state it does not cover, an unknown name.
    pub fn agent<E: Env>(&self, env: &E) -> Result<Agent, Error> {
        let err = |m: String| Err(Error::Policy(m));
        if self.env.name != env.name() || self.env.params != env.params() {
            return err(format!(
                "the policy was trained on {} {}, not on {} {}",
                self.env.name,
                self.env.params,
                env.name(),
                env.params()
            ));
        }
        if self.state_vars != env.state_vars() || self.actions != env.actions() {
            return err("state_vars or actions differ from the environment's".into());
        }
        let n = env.num_states();
        let mut index = HashMap::with_capacity(n);
        for s in 0..n {
            index.insert(key(&state_map(env, &self.state_vars, s)), s);
        }
        let lookup = |state: &Map<String, Value>, what: &str| {
            index.get(&key(state)).copied().ok_or_else(|| {
                Error::Policy(format!(
                    "{what} names state {}, which the environment lacks",
                    Value::Object(state.clone())
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
        let options = fill(n, &self.options_policy, "options_policy", &lookup, |c| {
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
        Ok(Agent { legs, options, flat, terminate, max_steps: self.max_steps })
    }
}

/// The state with index `s` as a `{VAR: value}` map; integral values are written as integers.
fn state_map<E: Env>(env: &E, vars: &[String], s: usize) -> Map<String, Value> {
    let mut values = Vec::new();
    if let Some(state) = env.state(s) {
        env.valuation(&state, &mut values);
    }
    vars.iter()
        .zip(values)
        .map(|(name, v)| {
            let value = if v.fract() == 0.0 && v.abs() < 9.0e15 {
                Value::from(v as i64)
            } else {
                serde_json::Number::from_f64(v).map_or(Value::Null, Value::Number)
            };
            (name.clone(), value)
        })
        .collect()
}

/// A hashable key of a state map: its values as `f64` bits, in key order.
fn key(state: &Map<String, Value>) -> Vec<(String, u64)> {
    state
        .iter()
        .map(|(k, v)| (k.clone(), v.as_f64().map_or(u64::MAX, |f| (f + 0.0).to_bits())))
        .collect()
}

/// A per-state table from policy entries; every state must be covered exactly once.
fn fill(
    n: usize,
    entries: &[Entry],
    what: &str,
    lookup: &impl Fn(&Map<String, Value>, &str) -> Result<usize, Error>,
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

fn unhex(values: &[String], what: &str) -> Result<Vec<f64>, Error> {
    values
        .iter()
        .map(|h| {
            u64::from_str_radix(h, 16)
                .ok()
                .filter(|_| h.len() == 16)
                .map(f64::from_bits)
                .ok_or_else(|| {
                    Error::Policy(format!("{what} holds {h:?}, not 16 hex digits of f64 bits"))
                })
        })
        .collect()
}
