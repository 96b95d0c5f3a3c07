//! Any `policy.json` replayed, whatever it was trained on, with the lookups a caller that
//! runs it one step at a time needs: what the Python package's `hstl.Policy` holds.
//! [`Replayed::read`] picks the replay from the document (a grid world it holds whole, a
//! gymnasium environment it lists the states of, a learned function in a continuous world
//! or a gymnasium `Box` environment); [`Replayed::state_index`] finds a tabular policy's
//! state by its values, [`Replayed::observation_index`] by a gymnasium observation.

use std::collections::HashMap;

use hstl_runtime::approx::ApproxAgent;
use hstl_runtime::world::AnyWorld;
use hstl_runtime::{Agent, Env, GridWorld, TaskSpec, Value};

use crate::Problem;
use crate::continuous;
use crate::evaluate::{self, Replay};
use crate::outside::{Listed, Spaces, state_key};

/// A `policy.json` replayed in the environment the document describes.
pub enum Replayed {
    /// A grid world: `env` holds it whole.
    Grid(Replay<GridWorld>),
    /// A gymnasium environment, which the document cannot rebuild: its states as listed.
    Listed(Replay<Listed>, Spaces),
    /// A learned function in a continuous world (a plane, `mountain-car`) it holds whole.
    Tiles(Box<continuous::Replay>),
    /// A learned function in a gymnasium environment with a `Box` observation space, which
    /// the document describes.
    GymTiles(Box<continuous::GymReplay>),
}

impl Replayed {
    /// Replays the document `text`: a grid world policy, a gymnasium one against the
    /// states it lists, or a learned function.
    pub fn read(text: &str) -> Result<Replayed, Problem> {
        if continuous::is_learned_function_text(text) {
            return Ok(match continuous::replay_text_any(text)? {
                continuous::AnyReplay::World(r) => Replayed::Tiles(Box::new(r)),
                continuous::AnyReplay::Gym(r) => Replayed::GymTiles(Box::new(r)),
            });
        }
        // One typed pass over the document; the world it names decides the replay.
        let document = evaluate::read(text)?;
        let params = &document.policy.env.params;
        let gymnasium = params.get("gymnasium").and_then(Value::as_bool) == Some(true);
        if !gymnasium {
            return evaluate::replay_grid(document).map(Replayed::Grid);
        }
        let params = params.clone();
        let replay = evaluate::replay_document(document, |p| Listed::of(p))?;
        let spaces = Spaces::from_params(&replay.policy.env.name, &params)?;
        Ok(Replayed::Listed(replay, spaces))
    }

    /// The tabular agent; None for a learned function.
    pub fn agent(&self) -> Option<&Agent> {
        match self {
            Replayed::Grid(r) => Some(&r.agent),
            Replayed::Listed(r, _) => Some(&r.agent),
            Replayed::Tiles(_) | Replayed::GymTiles(_) => None,
        }
    }

    /// The spec it was trained on.
    pub fn spec(&self) -> &TaskSpec {
        match self {
            Replayed::Grid(r) => &r.spec,
            Replayed::Listed(r, _) => &r.spec,
            Replayed::Tiles(r) => &r.spec,
            Replayed::GymTiles(r) => &r.spec,
        }
    }

    /// The tabular document; None for a learned function.
    pub fn document(&self) -> Option<&hstl_runtime::Policy> {
        match self {
            Replayed::Grid(r) => Some(&r.policy),
            Replayed::Listed(r, _) => Some(&r.policy),
            Replayed::Tiles(_) | Replayed::GymTiles(_) => None,
        }
    }

    /// The text of the spec file it was trained on.
    pub fn source(&self) -> &str {
        match self {
            Replayed::Grid(r) => &r.source,
            Replayed::Listed(r, _) => &r.source,
            Replayed::Tiles(r) => &r.source,
            Replayed::GymTiles(r) => &r.source,
        }
    }

    /// The seed it was trained from, when the document records one.
    pub fn seed(&self) -> Option<u64> {
        match self {
            Replayed::Grid(r) => r.seed,
            Replayed::Listed(r, _) => r.seed,
            Replayed::Tiles(r) => r.seed,
            Replayed::GymTiles(r) => r.seed,
        }
    }

    /// The environment's name: the world's, or the gymnasium environment's id.
    pub fn env_name(&self) -> String {
        match self {
            Replayed::Tiles(r) => r.world.name().to_string(),
            Replayed::GymTiles(r) => r.env.name.clone(),
            _ => self.document().map_or(String::new(), |d| d.env.name.clone()),
        }
    }

    /// The state variables, in the order a state's values are given.
    pub fn state_vars(&self) -> Vec<String> {
        match self {
            Replayed::Tiles(r) => r.agent.model.vars.clone(),
            Replayed::GymTiles(r) => r.agent.model.vars.clone(),
            _ => self.document().map_or(Vec::new(), |d| d.state_vars.clone()),
        }
    }

    /// The action names, in index order.
    pub fn actions(&self) -> Vec<String> {
        match self {
            Replayed::Tiles(r) => world_actions(&r.world),
            Replayed::GymTiles(r) => hstl_runtime::World::actions(&r.env),
            _ => self.document().map_or(Vec::new(), |d| d.actions.clone()),
        }
    }

    /// The environment's own number of the first action (a gymnasium space's start; 0
    /// for a world).
    pub fn action_start(&self) -> i64 {
        match self {
            Replayed::Listed(_, spaces) => spaces.action_start,
            Replayed::GymTiles(r) => r.env.action_start,
            Replayed::Grid(_) | Replayed::Tiles(_) => 0,
        }
    }

    /// A learned function's agent; None for Q-tables.
    pub fn tiles(&self) -> Option<&ApproxAgent> {
        match self {
            Replayed::Tiles(r) => Some(&r.agent),
            Replayed::GymTiles(r) => Some(&r.agent),
            _ => None,
        }
    }

    /// For a learned function, the actions the state `values` blocks, after checking it:
    /// in the world the document holds (a state outside it is refused), or in the ranges
    /// the spec declares (the tiling's) for a gymnasium environment, which blocks none.
    pub fn blocked(&self, values: &[f64]) -> Result<Vec<bool>, Problem> {
        match self {
            Replayed::Tiles(r) => {
                crate::gym::start(&r.world, values).map(|_| crate::gym::blocked(&r.world, values))
            }
            _ => {
                in_ranges(self.spec(), &self.state_vars(), values)?;
                Ok(Vec::new())
            }
        }
    }

    /// The index of the tabular state whose values are `values`, or how to give one.
    pub fn state_index(&self, index: &StateIndex, values: &[f64]) -> Result<usize, Problem> {
        index.states.get(&state_key(values)).copied().ok_or_else(|| {
            let vars = self.state_vars();
            let shown: Vec<String> =
                vars.iter().zip(values).map(|(v, x)| format!("{v} = {x}")).collect();
            Problem::new(
                format!("the policy has no state {}", shown.join(", ")),
                match self {
                    Replayed::Grid(r) => {
                        format!("give a free cell of {}", crate::world::label(&r.env, None))
                    }
                    _ => "give an observation of the environment".to_string(),
                },
            )
        })
    }

    /// The state index of the gymnasium observation `obs`, for a policy trained on a
    /// gymnasium environment with `Discrete` observations (None for another policy).
    pub fn observation_index(&self, obs: i64) -> Option<Result<usize, Problem>> {
        let Replayed::Listed(r, spaces) = self else { return None };
        let n = r.env.num_states();
        Some(
            obs.checked_sub(spaces.observation_start)
                .and_then(|i| usize::try_from(i).ok())
                .filter(|&i| i < n)
                .ok_or_else(|| {
                    Problem::new(
                        format!(
                            "observation {obs} is outside Discrete({n}, start={})",
                            spaces.observation_start
                        ),
                        None,
                    )
                }),
        )
    }

    /// Refuses a gymnasium `Box` environment `given` to run a learned function in unless its
    /// spaces are those the policy was trained with: for a world the document holds, the
    /// world's bounds and actions; else the recorded spaces.
    pub fn check_box_env(&self, given: &crate::gym::Described) -> Result<(), Problem> {
        let fits = match self {
            Replayed::Tiles(r) => {
                let bounds = crate::gym::bounds(&r.world);
                let n = world_actions(&r.world).len();
                let same =
                    bounds.as_ref().is_some_and(|(lo, hi)| *lo == given.low && *hi == given.high);
                if same && n == given.actions && given.action_start == 0 {
                    return Ok(());
                }
                format!(
                    "world `{}` (a Box of {} components, Discrete({n}))",
                    r.world.name(),
                    bounds.map_or(0, |b| b.0.len())
                )
            }
            Replayed::GymTiles(r) => {
                if r.env.name == given.name && r.env.params() == given.params() {
                    return Ok(());
                }
                r.env.describe()
            }
            _ => return Ok(()),
        };
        Err(Problem::new(
            format!("the policy was trained on {fits}; `env` is {}", given.describe()),
            "pass the environment it was trained in (the same spaces and bounds)".to_string(),
        ))
    }
}

/// Every tabular state's values (in `state_vars` order, as `f64` bits) to its index: how a
/// state given by its values is found ([`Replayed::state_index`]). Empty for a learned
/// function.
#[derive(Clone, Debug, Default)]
pub struct StateIndex {
    states: HashMap<Vec<u64>, usize>,
}

impl StateIndex {
    /// The index of `replayed`'s states.
    pub fn of(replayed: &Replayed) -> StateIndex {
        let mut states = HashMap::new();
        let mut row = Vec::new();
        let mut index = |valuation: &dyn Fn(usize, &mut Vec<f64>), n: usize| {
            for s in 0..n {
                valuation(s, &mut row);
                states.insert(state_key(&row), s);
            }
        };
        match replayed {
            Replayed::Grid(r) => index(
                &|s, out| {
                    if let Some(c) = r.env.state(s) {
                        r.env.valuation(&c, out)
                    }
                },
                r.env.num_states(),
            ),
            Replayed::Listed(r, _) => index(&|s, out| r.env.valuation(&s, out), r.env.num_states()),
            Replayed::Tiles(_) | Replayed::GymTiles(_) => {}
        }
        StateIndex { states }
    }
}

/// The actions of a continuous world (none for a grid, whose policies are tabular).
pub fn world_actions(world: &AnyWorld) -> Vec<String> {
    match world {
        AnyWorld::Plane(p) => hstl_runtime::World::actions(p),
        AnyWorld::MountainCar(c) => hstl_runtime::World::actions(c),
        AnyWorld::Grid(_) => Vec::new(),
    }
}

/// Checks a learned function's state against the ranges its spec declares (the tiling's).
fn in_ranges(spec: &TaskSpec, vars: &[String], values: &[f64]) -> Result<(), Problem> {
    if values.len() != vars.len() {
        return Err(Problem::new(
            format!(
                "a state of the policy has {} numbers ({}), not {}",
                vars.len(),
                vars.join(", "),
                values.len()
            ),
            "give the state variables' values in order, or a dict of them".to_string(),
        ));
    }
    let Some(t) = &spec.learn.tiles else { return Ok(()) };
    for (i, &x) in values.iter().enumerate() {
        let (Some(&lo), Some(&hi)) = (t.lo.get(i), t.hi.get(i)) else { continue };
        if !(x >= lo && x <= hi) {
            let num = hstl_runtime::plane::num;
            return Err(Problem::new(
                format!(
                    "`{}` = {} is outside its declared range {}..={}",
                    vars[i],
                    num(x),
                    num(lo),
                    num(hi)
                ),
                "give a state the policy was trained on".to_string(),
            ));
        }
    }
    Ok(())
}
