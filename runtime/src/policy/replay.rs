//! A greedy agent from a `policy.json` document: the document checked whole against the
//! spec and environment it claims, and its per-state tables filled from the entries.

use super::*;

impl Policy {
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
