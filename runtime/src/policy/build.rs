//! The `policy.json` document of a learner: its greedy policies and Q-tables, every state
//! listed (see the module docs of [`super`]).

use super::*;

impl Policy {
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
}
