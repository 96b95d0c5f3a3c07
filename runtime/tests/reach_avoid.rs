//! The reach-avoid optimum against closed forms on a corridor and against simulation of its
//! own optimal controller.

use hstl_runtime::env::{Cell, Env};
use hstl_runtime::eval::rollout;
use hstl_runtime::moves::Moves;
use hstl_runtime::reach_avoid::{ReachAvoid, solve_reach_avoid};
use hstl_runtime::robustness::{Bound, Expr, Formula, Interval};
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
    let task = ReachAvoid { goal, avoid, reach_by, avoid_through, also: vec![] };
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
    let bounded = ReachAvoid {
        goal: goal.clone(),
        avoid: avoid.clone(),
        reach_by: 4,
        avoid_through: 4,
        also: vec![],
    };
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
        also: vec![],
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
    let short = ReachAvoid {
        goal: vec![true; 3],
        avoid: avoid.clone(),
        reach_by: 3,
        avoid_through: 3,
        also: vec![],
    };
    assert!(matches!(solve_reach_avoid(&moves, &short, BUDGET), Err(Error::Config(_))));
    // A deadline of a billion steps is refused before its table is allocated.
    let long = ReachAvoid { goal, avoid, reach_by: 1_000_000_000, avoid_through: 3, also: vec![] };
    let Err(Error::Config(message)) = solve_reach_avoid(&moves, &long, BUDGET) else {
        panic!("a billion steps were solved");
    };
    assert!(message.contains("10000000010 states") && message.contains("limit of 16777216"));
}

/// `x op c` on the grid.
fn cmp(var: usize, op: hstl_runtime::robustness::CmpOp, c: f64) -> Formula {
    Formula::cmp(Expr::var(var), op, Expr::constant(c))
}

/// The reach-avoid form is read off a task: one bounded `eventually` of a state formula and
/// `always !R` conjuncts sharing one window; anything else is not of the form.
#[test]
fn the_reach_avoid_form_is_read_off_the_task() {
    use hstl_runtime::reach_avoid::reach_avoid_form;
    use hstl_runtime::robustness::CmpOp::{Gt, Lt};
    let (goal, pit, pond) = (cmp(0, Gt, 11.0), cmp(1, Lt, 2.0), cmp(0, Lt, 2.0));
    let ev = |end| Formula::eventually(Interval { start: 0, end }, goal.clone());
    let avoid =
        |end, r: &Formula| Formula::always(Interval { start: 0, end }, Formula::not(r.clone()));
    let task = Formula::and(vec![
        ev(Bound::Inclusive(30)),
        avoid(Bound::Unbounded, &pit),
        avoid(Bound::Unbounded, &pond),
    ]);
    let form = reach_avoid_form(&task).expect("reach-avoid");
    assert_eq!((form.reach_by, form.avoid_through), (30, None));
    assert_eq!(form.avoid, [pit.clone(), pond.clone()]);
    // `[0..30]` ends at step 29; a bounded avoid is kept.
    let task = Formula::and(vec![ev(Bound::Exclusive(30)), avoid(Bound::Exclusive(41), &pit)]);
    let form = reach_avoid_form(&task).expect("reach-avoid");
    assert_eq!((form.reach_by, form.avoid_through), (29, Some(40)));
    let not_of_the_form = [
        // No avoided region, or no goal.
        Formula::and(vec![ev(Bound::Inclusive(30))]),
        Formula::and(vec![avoid(Bound::Unbounded, &pit)]),
        // An unbounded goal, two windows for the avoided regions, a later start.
        Formula::and(vec![ev(Bound::Unbounded), avoid(Bound::Unbounded, &pit)]),
        Formula::and(vec![
            ev(Bound::Inclusive(30)),
            avoid(Bound::Unbounded, &pit),
            avoid(Bound::Inclusive(9), &pond),
        ]),
        Formula::and(vec![
            Formula::eventually(Interval { start: 2, end: Bound::Inclusive(30) }, goal.clone()),
            avoid(Bound::Unbounded, &pit),
        ]),
        // `always R` without the negation.
        Formula::and(vec![ev(Bound::Inclusive(30)), Formula::always(Interval::ALL, pit.clone())]),
    ];
    for task in not_of_the_form {
        assert!(reach_avoid_form(&task).is_none(), "{task:?}");
    }
}

/// `ReachAvoid::of_spec` on the corridor: the goal where its robustness is above 0, the
/// avoided cells where theirs is 0 or more (the boundary too); the satisfaction rate of the
/// optimal controller is the optimum, within five standard deviations.
#[test]
fn a_spec_gives_its_reach_avoid_task_and_its_satisfaction_rate() {
    use hstl_runtime::robustness::CmpOp::{Gt, Lt};
    use hstl_runtime::{
        CombinedOption, LearnParams, PrimitiveOption, StateVar, TaskSpec, Terminate,
    };
    let env = GridWorld::new(5, 1, 0.7).unwrap();
    let goal = cmp(0, Gt, 3.0);
    // x < 1 has robustness 0 at x = 1: x = 0 and x = 1 are avoided.
    let pit = cmp(0, Lt, 1.0);
    let task = Formula::and(vec![
        Formula::eventually(Interval { start: 0, end: Bound::Inclusive(6) }, goal.clone()),
        Formula::always(Interval::ALL, Formula::not(pit)),
    ]);
    let spec = TaskSpec {
        name: "Corridor".into(),
        state_vars: vec![
            StateVar { name: "x".into(), domain: Some(0..=4) },
            StateVar { name: "y".into(), domain: Some(0..=0) },
        ],
        task,
        primitives: vec![PrimitiveOption {
            name: "Goal".into(),
            reach: goal.clone(),
            init: Formula::bool(true),
            terminate: Terminate::Formula(goal),
            avoid: None,
        }],
        options: vec![CombinedOption { name: "Goal".into(), sequence: vec![0] }],
        learn: LearnParams::default(),
        regions: vec![],
    };
    let task = ReachAvoid::of_spec(&spec, &env, 20).unwrap().expect("reach-avoid");
    assert_eq!(task.goal, [false, false, false, false, true]);
    assert_eq!(task.avoid, [true, true, false, false, false]);
    assert_eq!((task.reach_by, task.avoid_through, task.run_len()), (6, 19, 20));
    let o = solve_reach_avoid(&Moves::of(&env), &task, BUDGET).unwrap();
    let runs = 20_000;
    let rate = task.satisfaction_rate(&env, &mut o.controller(), runs, &mut seeded_rng(3));
    let sd = (o.probability * (1.0 - o.probability) / runs as f64).sqrt();
    assert!((rate - o.probability).abs() < 5.0 * sd, "{rate} vs {}", o.probability);
    // A task of another form has none.
    let mut other = spec.clone();
    other.task = Formula::eventually(Interval::ALL, cmp(0, Gt, 3.0));
    assert!(ReachAvoid::of_spec(&other, &env, 20).unwrap().is_none());
}

/// Several goals, each by its own deadline: on the corridor every way to `x = 4` passes
/// `x = 3`, so adding `x = 3` by the same deadline changes nothing, and `x = 3` by step 2
/// then `x = 4` by step 3 leaves no step to lose: `p^3`. The optimal controller's rate
/// matches the optimum.
#[test]
fn several_goals_each_by_its_deadline() {
    let (moves, goal, avoid) = corridor(0.7);
    let p: f64 = 0.7;
    let q = (1.0 - p) / 3.0;
    let at = |x: usize| (0..5).map(|c| c == x).collect::<Vec<bool>>();
    let solve = |task: &ReachAvoid| solve_reach_avoid(&moves, task, BUDGET).unwrap().probability;
    let task = ReachAvoid {
        goal: goal.clone(),
        avoid: avoid.clone(),
        reach_by: 4,
        avoid_through: 4,
        also: vec![(at(3), 4)],
    };
    assert!((solve(&task) - p.powi(3) * (1.0 + 6.0 * q)).abs() < 1e-12);
    let task = ReachAvoid {
        goal: at(3),
        avoid: avoid.clone(),
        reach_by: 2,
        avoid_through: 3,
        also: vec![(goal.clone(), 3)],
    };
    assert!((solve(&task) - p.powi(3)).abs() < 1e-12);
    // Back to x = 2 after x = 4, both by step 5: right three times, then left twice.
    let task = ReachAvoid { goal, avoid, reach_by: 3, avoid_through: 5, also: vec![(at(2), 5)] };
    let want = solve(&task);
    let o = solve_reach_avoid(&moves, &task, BUDGET).unwrap();
    let env = GridWorld::new(5, 1, 0.7).unwrap();
    let runs = 20_000;
    let mut kept = 0;
    let mut rng = seeded_rng(5);
    for _ in 0..runs {
        let states: Vec<usize> = rollout(&env, &mut o.controller(), 1, task.run_len(), &mut rng)
            .iter()
            .map(|s| s.state)
            .collect();
        kept += usize::from(task.satisfied(&states));
    }
    let rate = kept as f64 / runs as f64;
    let sd = (want * (1.0 - want) / runs as f64).sqrt();
    assert!(want > 0.1 && (rate - want).abs() < 5.0 * sd, "{rate} vs {want}");
}

/// `eventually[0..=T1] A && eventually[0..=T2] B && always !R` is of the form, with the
/// second goal in `also`.
#[test]
fn a_sequenced_reach_is_of_the_form() {
    use hstl_runtime::reach_avoid::reach_avoid_form;
    use hstl_runtime::robustness::CmpOp::{Gt, Lt};
    let (a, b, pit) = (cmp(0, Gt, 11.0), cmp(0, Lt, 3.0), cmp(1, Lt, 2.0));
    let ev = |t, g: &Formula| {
        Formula::eventually(Interval { start: 0, end: Bound::Inclusive(t) }, g.clone())
    };
    let task = Formula::and(vec![
        ev(20, &a),
        ev(45, &b),
        Formula::always(Interval::ALL, Formula::not(pit.clone())),
    ]);
    let form = reach_avoid_form(&task).expect("reach-avoid");
    assert_eq!((form.reach_by, form.avoid_through), (20, None));
    assert_eq!(form.also, [(b, 45)]);
}
