//! Continuous worlds stepped from outside, one call a step: what the Python package's
//! gymnasium environments (`hstl.PlaneEnv`, `hstl.MountainCarEnv`) run. A state is the
//! world's valuation (`x, y` for a plane, `x, v` for `mountain-car`), so it crosses to
//! Python and back as plain doubles, bit for bit; every draw comes from the caller's one
//! generator, as the learner's do, so that a seed gives the same run from Rust and Python.
//!
//! ```
//! use hstl::gym;
//! use hstl::world::AnyWorld;
//! let world = AnyWorld::builtin("mountain-car").unwrap();
//! let mut rng = hstl::runtime::seeded_rng(7);
//! let start = gym::reset(&world, &mut rng).unwrap();
//! let next = gym::step(&world, &start, 2, &mut rng).unwrap();
//! assert!(next[1] > 0.0); // pushed right from rest
//! ```

use hstl_runtime::world::AnyWorld;
use hstl_runtime::{CarState, MountainCar, Point, Rng, Value, World, json};

use crate::Problem;

/// The lower and upper bounds of each state variable of a continuous world, in valuation
/// order: a plane's extent, `mountain-car`'s position and speed limits. `None` for a grid.
pub fn bounds(world: &AnyWorld) -> Option<(Vec<f64>, Vec<f64>)> {
    match world {
        AnyWorld::Plane(p) => {
            let ([x0, x1], [y0, y1]) = p.extent();
            Some((vec![x0, y0], vec![x1, y1]))
        }
        AnyWorld::MountainCar(_) => Some((
            vec![MountainCar::MIN_POSITION, -MountainCar::MAX_SPEED],
            vec![MountainCar::MAX_POSITION, MountainCar::MAX_SPEED],
        )),
        AnyWorld::Grid(_) => None,
    }
}

/// A start state drawn from `rng`, as the learner's episodes start.
pub fn reset(world: &AnyWorld, rng: &mut Rng) -> Result<Vec<f64>, Problem> {
    let mut out = Vec::with_capacity(2);
    match world {
        AnyWorld::Plane(p) => p.valuation(&p.reset(rng), &mut out),
        AnyWorld::MountainCar(c) => c.valuation(&c.reset(rng), &mut out),
        AnyWorld::Grid(_) => return Err(grid_problem()),
    }
    Ok(out)
}

/// The state after `action` from `state` (a valuation [`reset`], [`step`] or [`start`]
/// gave), drawn from `rng` as the world's own step draws. An action outside the world's
/// set, or a state that is not one of the world's, is refused.
pub fn step(
    world: &AnyWorld,
    state: &[f64],
    action: usize,
    rng: &mut Rng,
) -> Result<Vec<f64>, Problem> {
    let actions = match world {
        AnyWorld::Plane(p) => p.actions().len(),
        AnyWorld::MountainCar(c) => c.actions().len(),
        AnyWorld::Grid(_) => return Err(grid_problem()),
    };
    if action >= actions {
        return Err(Problem::new(
            format!("action {action} is not one of world `{}`'s {actions} actions", world.name()),
            format!("give an action from 0 to {}", actions - 1),
        ));
    }
    if let Some(p) = outside(world, state) {
        return Err(p);
    }
    let mut out = Vec::with_capacity(2);
    match world {
        AnyWorld::Plane(p) => {
            p.valuation(&p.step(&Point { x: state[0], y: state[1] }, action, rng), &mut out)
        }
        AnyWorld::MountainCar(c) => {
            c.valuation(&c.step(&CarState { x: state[0], v: state[1] }, action, rng), &mut out)
        }
        AnyWorld::Grid(_) => return Err(grid_problem()),
    }
    Ok(out)
}

/// Which of the world's actions its state `values` blocks (see
/// [`World::blocked`]): what a greedy agent never chooses.
pub fn blocked(world: &AnyWorld, values: &[f64]) -> Vec<bool> {
    match world {
        AnyWorld::Plane(p) if values.len() == 2 => {
            let at = Point { x: values[0], y: values[1] };
            (0..p.headings()).map(|a| p.blocked(&at, a)).collect()
        }
        _ => Vec::new(),
    }
}

/// `values` as a start state: checked to be a state of the world (two finite numbers within
/// its bounds, and for a plane a position no obstacle covers).
pub fn start(world: &AnyWorld, values: &[f64]) -> Result<Vec<f64>, Problem> {
    match outside(world, values) {
        Some(p) => Err(p),
        None => Ok(values.to_vec()),
    }
}

/// Why `values` is no state of `world`, if it is not.
fn outside(world: &AnyWorld, values: &[f64]) -> Option<Problem> {
    let Some((lo, hi)) = bounds(world) else { return Some(grid_problem()) };
    let vars = match world {
        AnyWorld::Plane(p) => p.state_vars(),
        _ => MountainCar.state_vars(),
    };
    let help = || {
        let ranges: Vec<String> = vars
            .iter()
            .zip(lo.iter().zip(&hi))
            .map(|(v, (a, b))| {
                format!(
                    "`{v}` in [{}, {}]",
                    hstl_runtime::plane::num(*a),
                    hstl_runtime::plane::num(*b)
                )
            })
            .collect();
        format!("give {} numbers: {}", vars.len(), ranges.join(", "))
    };
    if values.len() != vars.len() {
        return Some(Problem::new(
            format!(
                "a state of world `{}` has {} numbers ({}), not {}",
                world.name(),
                vars.len(),
                vars.join(", "),
                values.len()
            ),
            help(),
        ));
    }
    for (((v, &x), a), b) in vars.iter().zip(values).zip(&lo).zip(&hi) {
        if !(x >= *a && x <= *b) {
            return Some(Problem::new(
                format!(
                    "`{v}` = {} is outside world `{}`",
                    hstl_runtime::plane::num(x),
                    world.name()
                ),
                help(),
            ));
        }
    }
    if let AnyWorld::Plane(p) = world
        && !p.is_free(Point { x: values[0], y: values[1] })
    {
        return Some(Problem::new(
            format!(
                "({}, {}) is inside an obstacle of world `{}`",
                hstl_runtime::plane::num(values[0]),
                hstl_runtime::plane::num(values[1]),
                world.name()
            ),
            "give a position no obstacle covers".to_string(),
        ));
    }
    None
}

fn grid_problem() -> Problem {
    Problem::new(
        "a grid world is stepped by cells, not by continuous states",
        "use a plane world or `mountain-car` here (a grid world has its own environment)"
            .to_string(),
    )
}

/// The least and greatest window of [`mountain_car_patrol`].
pub const PATROL_WINDOWS: std::ops::RangeInclusive<i64> = 1..=1_000_000;

/// The spec source of the MountainCar patrol with window `window`: visit both hill tops
/// (`x < -1.0`, `x > 0.4`) within every `window` steps, on `mountain-car`, with
/// `learn { preset: auto }` (`examples/specs/mountain_car_patrol.hstl` is `window` 200).
pub fn mountain_car_patrol(window: i64) -> Result<String, Problem> {
    if !PATROL_WINDOWS.contains(&window) {
        return Err(Problem::new(
            format!(
                "the patrol's window must be {} to {} steps; got {window}",
                PATROL_WINDOWS.start(),
                PATROL_WINDOWS.end()
            ),
            "give the steps within which each hill top is visited, such as 200".to_string(),
        ));
    }
    Ok(format!(
        "/// MountainCar as a persistent task: visit both hill tops within every {window} steps, with
/// gymnasium's MountainCar-v0 dynamics (the goal does not end the episode).
spec MountainCarPatrol {{
    world \"mountain-car\";
    state {{
        x: float in -1.2..=0.6,
        v: float in -0.07..=0.07,
    }}
    let left = x < -1.0;
    let right = x > 0.4;
    task always[0..] (eventually[0..{window}] left && eventually[0..{window}] right);
    option left;
    option right;
    learn {{ preset: auto }}
}}
"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use hstl_runtime::seeded_rng;

    #[test]
    fn the_patrol_of_window_200_is_the_example_spec() {
        let example =
            include_str!("../examples/specs/mountain_car_patrol.hstl").replace("\r\n", "\n");
        assert_eq!(mountain_car_patrol(200).unwrap(), example);
        for bad in [0, -3, 1_000_001] {
            let e = mountain_car_patrol(bad).unwrap_err();
            assert!(e.message.contains(&bad.to_string()), "{e:?}");
        }
    }

    #[test]
    fn stepping_from_outside_is_the_world_s_own_run() {
        for name in ["paper-plane", "mountain-car"] {
            let world = AnyWorld::builtin(name).unwrap();
            let (mut a, mut b) = (seeded_rng(3), seeded_rng(3));
            let mut state = reset(&world, &mut a).unwrap();
            let mut values = Vec::new();
            match &world {
                AnyWorld::Plane(p) => {
                    let mut s = p.reset(&mut b);
                    for t in 0..500 {
                        s = p.step(&s, t % 4, &mut b);
                        state = step(&world, &state, t % 4, &mut a).unwrap();
                        p.valuation(&s, &mut values);
                        assert_eq!(state, values);
                    }
                }
                AnyWorld::MountainCar(c) => {
                    let mut s = c.reset(&mut b);
                    for t in 0..500 {
                        s = c.step(&s, (t / 40) % 3, &mut b);
                        state = step(&world, &state, (t / 40) % 3, &mut a).unwrap();
                        c.valuation(&s, &mut values);
                        assert_eq!(state, values);
                    }
                }
                AnyWorld::Grid(_) => unreachable!(),
            }
        }
    }

    #[test]
    fn states_and_actions_that_are_not_the_world_s_are_refused_in_words() {
        let plane = AnyWorld::builtin("paper-plane").unwrap();
        let car = AnyWorld::builtin("mountain-car").unwrap();
        let mut rng = seeded_rng(0);
        let cases: [(&AnyWorld, Vec<f64>, usize, &str); 6] = [
            (&plane, vec![1.0, 1.0], 4, "action 4 is not one of world `paper-plane`'s 4 actions"),
            (&plane, vec![f64::NAN, 1.0], 0, "`x` = NaN is outside world `paper-plane`"),
            (&plane, vec![1.0, 15.0], 0, "`y` = 15 is outside world `paper-plane`"),
            (&plane, vec![1.0], 0, "has 2 numbers (x, y), not 1"),
            (&car, vec![0.0, 0.08], 1, "`v` = 0.08 is outside world `mountain-car`"),
            (&car, vec![-0.5, f64::INFINITY], 1, "`v` = inf is outside"),
        ];
        for (world, state, action, want) in cases {
            let e = step(world, &state, action, &mut rng).unwrap_err();
            assert!(e.message.contains(want), "{} does not hold {want}", e.message);
            assert!(e.help.is_some() && !e.message.ends_with('.'));
        }
        let grid = AnyWorld::builtin("paper").unwrap();
        assert!(reset(&grid, &mut rng).is_err() && bounds(&grid).is_none());
    }
}

/// The most components a gymnasium `Box` observation space may have for
/// [`Described`] (its bounds are written into `policy.json`).
pub const MAX_BOX_COMPONENTS: usize = 1 << 12;

/// A gymnasium environment with a bounded `Box` observation space and `Discrete` actions,
/// as a learned function's `policy.json` describes it: what the Python package trains in
/// through a valuation, and what a policy trained there is checked against. Its
/// `env.params` are `{"gymnasium": true, "observation": {"low": [...], "high": [...]},
/// "action_start": S}`, its actions are named by their values (`"S"`, `"S+1"`, ...) and
/// its state variables are the spec's. It cannot move ([`World::reset`] gives zeros and
/// [`World::step`] stays), so a replay that steps needs the environment itself.
#[derive(Clone, Debug, PartialEq)]
pub struct Described {
    /// The environment's id (`spec.id`), or its class name.
    pub name: String,
    /// The spec's state variables, which a valuation gives.
    pub vars: Vec<String>,
    /// The observation space's bounds, flattened.
    pub low: Vec<f64>,
    /// The observation space's upper bounds, flattened.
    pub high: Vec<f64>,
    /// `action_space.n`.
    pub actions: usize,
    /// `action_space.start`.
    pub action_start: i64,
}

impl Described {
    /// The environment of bounds `low` and `high` and `actions` actions from
    /// `action_start`, checked: finite bounds, `low <= high`, at most
    /// [`MAX_BOX_COMPONENTS`] components, at least one action.
    pub fn new(
        name: &str,
        vars: Vec<String>,
        low: Vec<f64>,
        high: Vec<f64>,
        actions: usize,
        action_start: i64,
    ) -> Result<Described, Problem> {
        if low.len() != high.len() || low.is_empty() || low.len() > MAX_BOX_COMPONENTS {
            return Err(Problem::new(
                format!(
                    "the observation space has {} components (low) and {} (high); the learner \
                     takes 1 to {MAX_BOX_COMPONENTS}",
                    low.len(),
                    high.len()
                ),
                "wrap the environment so that its observation is a small `Box`".to_string(),
            ));
        }
        if let Some(i) = (0..low.len()).find(|&i| !low[i].is_finite() || !high[i].is_finite()) {
            return Err(Problem::new(
                format!(
                    "the observation space is unbounded: component {i} lies in [{}, {}]",
                    hstl_runtime::plane::num(low[i]),
                    hstl_runtime::plane::num(high[i])
                ),
                "bound it: give the environment a `Box` with finite `low` and `high` (such as \
                 gymnasium's `TransformObservation` with a bounded `observation_space`), \
                 matching the ranges the spec declares"
                    .to_string(),
            ));
        }
        if let Some(i) = (0..low.len()).find(|&i| low[i] > high[i]) {
            return Err(Problem::new(
                format!("the observation space's component {i} has low above high"),
                "give a `Box` with `low <= high`".to_string(),
            ));
        }
        if actions == 0 || actions > MAX_BOX_COMPONENTS {
            return Err(Problem::new(
                format!(
                    "the environment has {actions} actions; the learner takes 1 to {MAX_BOX_COMPONENTS}"
                ),
                "give the environment a `Discrete` action space".to_string(),
            ));
        }
        Ok(Described { name: name.to_string(), vars, low, high, actions, action_start })
    }

    /// The environment a `policy.json`'s `env` (`name`, `params`) and `state_vars` give.
    pub fn from_params(
        name: &str,
        vars: Vec<String>,
        params: &Value,
    ) -> Result<Described, Problem> {
        let bad = || {
            Problem::new(
                "its `env.params` are not a gymnasium environment's as `hstl.train` writes them",
                "the file was edited or damaged: train the policy again".to_string(),
            )
        };
        let numbers = |key: &str| -> Option<Vec<f64>> {
            let list = params.get("observation")?.get(key)?.as_array()?;
            if list.len() > MAX_BOX_COMPONENTS {
                return None;
            }
            list.iter().map(Value::as_f64).collect()
        };
        let (Some(low), Some(high)) = (numbers("low"), numbers("high")) else { return Err(bad()) };
        let actions = params.get("actions").and_then(Value::as_u64).ok_or_else(bad)?;
        let start = params.get("action_start").and_then(Value::as_i64).ok_or_else(bad)?;
        let actions = usize::try_from(actions).map_err(|_| bad())?;
        Described::new(name, vars, low, high, actions, start).map_err(|_| bad())
    }

    /// Whether a `policy.json`'s `env.params` are a gymnasium environment's.
    pub fn is_gymnasium(params: &Value) -> bool {
        params.get("gymnasium").and_then(Value::as_bool) == Some(true)
    }

    /// `env.params` (see the type's docs), as written and read back: a document's and a
    /// live environment's compare equal exactly when they describe the same spaces.
    pub fn params(&self) -> Value {
        let v = json!({
            "gymnasium": true,
            "observation": {"low": self.low, "high": self.high},
            "actions": self.actions,
            "action_start": self.action_start,
        });
        // Through its text, as a document read back holds it.
        v.to_string().parse().unwrap_or(v)
    }

    /// ``` `MountainCar-v0` (Box of 2 components, Discrete(3)) ```.
    pub fn describe(&self) -> String {
        let actions = match self.action_start {
            0 => format!("Discrete({})", self.actions),
            s => format!("Discrete({}, start={s})", self.actions),
        };
        format!("`{}` (Box of {} components, {actions})", self.name, self.low.len())
    }
}

impl World for Described {
    type State = Vec<f64>;

    fn name(&self) -> &str {
        &self.name
    }

    fn params(&self) -> Value {
        Described::params(self)
    }

    fn state_vars(&self) -> Vec<String> {
        self.vars.clone()
    }

    fn actions(&self) -> Vec<String> {
        (0..self.actions).map(|a| (self.action_start + a as i64).to_string()).collect()
    }

    fn valuation(&self, state: &Vec<f64>, out: &mut Vec<f64>) {
        out.clear();
        out.extend_from_slice(state);
    }

    fn reset(&self, _rng: &mut Rng) -> Vec<f64> {
        vec![0.0; self.vars.len()]
    }

    fn step(&self, state: &Vec<f64>, _action: usize, _rng: &mut Rng) -> Vec<f64> {
        state.clone()
    }
}
