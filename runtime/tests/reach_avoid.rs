//! The reach-avoid optimum against closed forms on a corridor and against simulation of its
//! own optimal controller.

use hstl_runtime::env::{Cell, Env};
use hstl_runtime::eval::rollout;
use hstl_runtime::optimum::Moves;
use hstl_runtime::reach_avoid::{ReachAvoid, solve_reach_avoid};
use hstl_runtime::{Error, GridWorld, seeded_rng};

const BUDGET: usize = 1 << 24;

/// The corridor `x = 0..=4` (one row, so Up and Down push into walls), starting at `x = 1`:
/// the goal is `x = 4`, three steps right, and `x = 0` is avoided.
fn corridor(p: f64) -> (Moves, Vec<bool>, Vec<bool>) {
    let mut moves = Moves::of(&GridWorld::new(5, 1, p).unwrap());
    moves.starts = vec![1];
    let goal = (0..5).map(|x| x == 4).collect();
    let avoid = (0..5).map(|x| x == 0).collect();
    (moves, goal, avoid)
}

/// The best probability of reaching the goal by step `reach_by`, avoiding `x = 0` through
/// step `avoid_through`, is `want`.
fn check(p: f64, reach_by: usize, avoid_through: usize, want: f64) {
    let (moves, goal, avoid) = corridor(p);
    let task = ReachAvoid { goal, avoid, reach_by, avoid_through };
    let o = solve_reach_avoid(&moves, &task, BUDGET).unwrap();
    assert!(
        (o.probability - want).abs() < 1e-12,
        "p {p}, T {reach_by}, T_avoid {avoid_through}: {} vs {want}",
        o.probability
    );
}

/// Three steps right in `T` steps. Right is the best action everywhere: it alone moves right
/// with `p`, and it moves left (a slip) no more often than any other. With `T = 3` every
/// step must advance: `p^3`. With `T = 4` one step may be lost to a slip into a wall (`2q`,
/// at any of the first three steps) but none to a slip left: from `x = 1` that enters the
/// avoided cell, and from further right it costs two steps. So `p^3 (1 + 3 * 2q)`. With
/// `T = 2` the goal is out of reach.
#[test]
fn a_corridor_matches_its_closed_forms() {
    for p in [0.7, 0.9, 0.5] {
        let q = (1.0 - p) / 3.0;
        check(p, 3, 3, p.powi(3));
        check(p, 4, 4, p.powi(3) * (1.0 + 6.0 * q));
        check(p, 2, 2, 0.0);
        // After the goal, the avoided cell is four steps away: two more steps cannot fail.
        check(p, 3, 5, p.powi(3));
    }
}

#[test]
fn an_unbounded_avoid_over_a_run_is_the_bounded_task() {
    let (moves, goal, avoid) = corridor(0.7);
    let solve = |task: ReachAvoid| solve_reach_avoid(&moves, &task, BUDGET).unwrap().probability;
    let bounded =
        ReachAvoid { goal: goal.clone(), avoid: avoid.clone(), reach_by: 4, avoid_through: 4 };
    let run = ReachAvoid::over_run(goal.clone(), avoid.clone(), 4, 5).unwrap();
    assert_eq!(run, bounded);
    assert_eq!(solve(run), solve(bounded));
    // A run of 4 states clips the goal's window to step 3.
    let short = ReachAvoid::over_run(goal.clone(), avoid.clone(), 4, 4).unwrap();
    assert!((solve(short) - 0.7f64.powi(3)).abs() < 1e-12);
    assert!(ReachAvoid::over_run(goal, avoid, 4, 0).is_err());
}

/// Whether a run satisfies the task, from the definition.
fn satisfies(task: &ReachAvoid, states: &[usize]) -> bool {
    let reaches = states.iter().take(task.reach_by + 1).any(|&s| task.goal[s]);
    let avoids = states.iter().take(task.avoid_through + 1).all(|&s| !task.avoid[s]);
    reaches && avoids
}

#[test]
fn the_optimal_controller_achieves_the_optimum_in_simulation() {
    let env = GridWorld::default();
    let moves = Moves::of(&env);
    let cells: Vec<Cell> = (0..env.num_states()).filter_map(|s| env.state(s)).collect();
    // Reach the top-right corner within 20 steps, around a block in the middle, staying off
    // it for 25 steps.
    let task = ReachAvoid {
        goal: cells.iter().map(|c| c.x >= 12 && c.y >= 12).collect(),
        avoid: cells.iter().map(|c| (5..=9).contains(&c.x) && (5..=9).contains(&c.y)).collect(),
        reach_by: 20,
        avoid_through: 25,
    };
    let o = solve_reach_avoid(&moves, &task, BUDGET).unwrap();
    assert!(o.probability > 0.2 && o.probability < 0.9, "{}", o.probability);
    let runs = 20_000;
    let mut rng = seeded_rng(5);
    let mut controller = o.controller();
    let mut met = 0;
    for _ in 0..runs {
        let start = env.index(&env.reset(&mut rng));
        let states: Vec<usize> = rollout(&env, &mut controller, start, o.last_step() + 1, &mut rng)
            .iter()
            .map(|s| s.state)
            .collect();
        assert_eq!(satisfies(&task, &states), o.satisfied(&states));
        met += usize::from(satisfies(&task, &states));
    }
    let rate = met as f64 / runs as f64;
    // Five standard deviations of the share of `runs` independent runs.
    let sd = (o.probability * (1.0 - o.probability) / runs as f64).sqrt();
    assert!((rate - o.probability).abs() < 5.0 * sd, "{rate} vs {}", o.probability);
}

#[test]
fn bad_tasks_are_errors() {
    let (moves, goal, avoid) = corridor(0.7);
    let short =
        ReachAvoid { goal: vec![true; 3], avoid: avoid.clone(), reach_by: 3, avoid_through: 3 };
    assert!(matches!(solve_reach_avoid(&moves, &short, BUDGET), Err(Error::Config(_))));
    // A deadline of a billion steps is refused before its table is allocated.
    let long = ReachAvoid { goal, avoid, reach_by: 1_000_000_000, avoid_through: 3 };
    let Err(Error::Config(message)) = solve_reach_avoid(&moves, &long, BUDGET) else {
        panic!("a billion steps were solved");
    };
    assert!(message.contains("10000000010 states") && message.contains("limit of 16777216"));
}
