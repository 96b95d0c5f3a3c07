//! Per-state tables computed once before training: valuations, reach robustness,
//! initiation and termination sets.

use hstl_robustness::{Formula, Trace, reference};

use crate::spec::Terminate;
use crate::{Env, Error, TaskSpec};

/// Everything the learner and the evaluator look up per state index.
#[derive(Clone, Debug)]
pub(crate) struct Tables {
    /// Number of states.
    pub states: usize,
    /// Number of actions.
    pub actions: usize,
    /// Row `s` holds state `s`'s values in the spec's variable order.
    pub trace: Trace,
    /// `reach[p][s]`: robustness of primitive `p`'s reach formula at `s`.
    pub reach: Vec<Vec<f64>>,
    /// `term[p][s]`: primitive `p` stops at `s` (also where it enters its avoided region).
    pub term: Vec<Vec<bool>>,
    /// `ends[p][s]`: state `s` lies in primitive `p`'s avoided region (`avoid: R`,
    /// `rho(R, s) >= 0`, as `always !R` fails there); `None` for a primitive without one.
    /// Entering it ends the flat level's episode: `reach[p][s]` is then the whole value.
    pub ends: Vec<Option<Vec<bool>>>,
    /// `legs[o]`: the primitives option `o` runs, in order.
    pub legs: Vec<Vec<usize>>,
    /// `available[s]`: the options whose first leg may start at `s`, in set order.
    pub available: Vec<Vec<usize>>,
    /// `remaining[o][l]`: the option made of legs `l..` of option `o`, if in the set.
    pub remaining: Vec<Vec<Option<usize>>>,
}

impl Tables {
    /// The tables of `spec` over the states of `env`. Fails when the spec does not fit the
    /// environment or some state has no available option.
    pub fn new<E: Env>(spec: &TaskSpec, env: &E) -> Result<Tables, Error> {
        spec.validate()?;
        let trace = valuations(spec, env)?;
        let states = trace.len();
        let actions = env.actions().len();
        if actions == 0 {
            return Err(Error::Env(format!("environment {} has no action", env.name())));
        }
        let signal = |f: &Formula| -> Vec<f64> {
            (0..states).map(|s| reference::robustness(f, &trace, s)).collect()
        };
        let holds = |f: &Formula| -> Vec<bool> { signal(f).into_iter().map(|r| r > 0.0).collect() };
        let mut reach = Vec::new();
        let mut init = Vec::new();
        let mut term = Vec::new();
        // The termination sets of the formulas alone: a leg stopped by its avoided region
        // hands over to the next leg wherever that is (the sequence check is about these).
        let mut planned = Vec::new();
        let mut ends = Vec::new();
        let gamma = spec.learn.flat.gamma;
        for p in &spec.primitives {
            let mut r = signal(&p.reach);
            let mut stops: Vec<bool> = match &p.terminate {
                Terminate::Argmax => {
                    let max = r.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                    r.iter().map(|&v| v == max).collect()
                }
                Terminate::Formula(f) => holds(f),
            };
            planned.push(stops.clone());
            let inside = p.avoid.as_ref().map(|f| shape_avoid(&mut r, &signal(f), gamma, spec));
            if let Some(inside) = &inside {
                for (t, &a) in stops.iter_mut().zip(inside) {
                    *t |= a;
                }
            }
            term.push(stops);
            ends.push(inside);
            init.push(holds(&p.init));
            reach.push(r);
        }
        let legs: Vec<Vec<usize>> = spec.options.iter().map(|o| o.sequence.clone()).collect();
        let available: Vec<Vec<usize>> = (0..states)
            .map(|s| {
                legs.iter().enumerate().filter(|(_, l)| init[l[0]][s]).map(|(o, _)| o).collect()
            })
            .collect();
        if let Some(s) = available.iter().position(Vec::is_empty) {
            let mut row = Vec::new();
            trace.row_into(s, &mut row);
            let state: Vec<String> = spec
                .state_vars
                .iter()
                .zip(&row)
                .map(|(v, x)| format!("{} = {x}", v.name))
                .collect();
            return Err(Error::Spec(format!(
                "no option of the set can start in the state {}",
                state.join(", ")
            )));
        }
        for (o, seq) in spec.options.iter().zip(&legs) {
            for pair in seq.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                if (0..states).any(|s| planned[a][s] && !init[b][s]) {
                    return Err(Error::Spec(format!(
                        "in option {}, {} can terminate outside the initiation set of {}",
                        o.name, spec.primitives[a].name, spec.primitives[b].name
                    )));
                }
            }
        }
        let remaining = legs
            .iter()
            .map(|seq| {
                (0..seq.len())
                    .map(|l| legs.iter().position(|other| other[..] == seq[l..]))
                    .collect()
            })
            .collect();
        Ok(Tables { states, actions, trace, reach, term, ends, legs, available, remaining })
    }
}

/// Shapes a leg's flat reward `r` by its avoided region, whose robustness per state is
/// `avoid`, and returns the states inside it (`rho >= 0`). Outside, the reward is
/// `min(rho(reach), rho(!R))`: the leg keeps a margin. Inside, it is the worst reward of any
/// state outside, less one, earned forever (`/ (1 - gamma)`; `max_steps` times when gamma
/// is 1): entering is worse than any path that stays out.
fn shape_avoid(r: &mut [f64], avoid: &[f64], gamma: f64, spec: &TaskSpec) -> Vec<bool> {
    let inside: Vec<bool> = avoid.iter().map(|&a| a >= 0.0).collect();
    for (v, &a) in r.iter_mut().zip(avoid) {
        *v = v.min(-a);
    }
    let worst = r
        .iter()
        .zip(&inside)
        .filter(|(v, i)| !**i && v.is_finite())
        .map(|(v, _)| *v)
        .fold(0.0f64, f64::min);
    let forever = if gamma < 1.0 { 1.0 / (1.0 - gamma) } else { spec.learn.max_steps as f64 };
    let penalty = (worst - 1.0) * forever;
    for (v, &i) in r.iter_mut().zip(&inside) {
        if i {
            *v = penalty;
        }
    }
    inside
}

/// Row `s`: the values of state `s` of `env` in the spec's variable order. Fails when a
/// spec variable is missing from the environment or a value lies outside its domain.
pub(crate) fn valuations<E: Env>(spec: &TaskSpec, env: &E) -> Result<Trace, Error> {
    let env_vars = env.state_vars();
    let mut columns = Vec::with_capacity(spec.state_vars.len());
    for v in &spec.state_vars {
        let Some(i) = env_vars.iter().position(|e| *e == v.name) else {
            return Err(Error::Spec(format!(
                "state variable {} is not a variable of environment {} ({})",
                v.name,
                env.name(),
                env_vars.join(", ")
            )));
        };
        columns.push(i);
    }
    let states = env.num_states();
    if states == 0 {
        return Err(Error::Env(format!("environment {} has no state", env.name())));
    }
    let mut trace = Trace::new(spec.state_vars.len());
    let (mut env_row, mut row) = (Vec::new(), Vec::new());
    for s in 0..states {
        let state = env
            .state(s)
            .ok_or_else(|| Error::Env(format!("state index {s} of {} has no state", env.name())))?;
        env.valuation(&state, &mut env_row);
        row.clear();
        for (v, &c) in spec.state_vars.iter().zip(&columns) {
            let value = env_row.get(c).copied().unwrap_or(f64::NAN);
            let in_domain = v.domain.as_ref().is_some_and(|d| {
                value.fract() == 0.0 && value >= *d.start() as f64 && value <= *d.end() as f64
            });
            if !in_domain {
                let cell: Vec<String> =
                    env_vars.iter().zip(&env_row).map(|(n, x)| format!("{n} = {x}")).collect();
                let range = v
                    .domain
                    .as_ref()
                    .map_or(String::from("none"), |d| format!("{}..={}", d.start(), d.end()));
                return Err(Error::Spec(format!(
                    "the state {} of environment {} gives {} = {value}, outside its declared \
                     domain ({range})",
                    cell.join(", "),
                    env.name(),
                    v.name
                )));
            }
            row.push(value);
        }
        trace.push(&row).map_err(|e| Error::Env(e.to_string()))?;
    }
    Ok(trace)
}
