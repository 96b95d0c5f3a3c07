//! The exact optimum `W*` against closed forms on corridors, an independent reference solver
//! on small random worlds, and its budgets.

#[path = "common/world_map.rs"]
mod world_map;

use hstl_runtime::moves::Moves;
use hstl_runtime::optimum::{Optimum, SolveConfig, solve_windows};
use hstl_runtime::{Error, seeded_rng};
use rand::RngExt;
use world_map::{FOUR_ROOMS, MapWorld};

/// A region's cells, as a predicate on `(x, y)`.
type Cells = fn(usize, usize) -> bool;

/// A task on a map: the map, `p`, each region's cells and window.
struct Case {
    name: &'static str,
    map: &'static str,
    p: f64,
    regions: Vec<(Cells, usize)>,
}

impl Case {
    fn solve(&self, config: SolveConfig) -> Result<Optimum, Error> {
        let world = MapWorld::new(self.map, self.p);
        let holds: Vec<Vec<bool>> = self.regions.iter().map(|(f, _)| world.region(f)).collect();
        let windows: Vec<usize> = self.regions.iter().map(|&(_, n)| n).collect();
        solve_windows(&world.moves, &holds, &windows, config)
    }
}

/// `W*` of `case` is `want`: inside the converged bracket, which is narrower than the
/// tolerance.
fn check(case: &Case, want: f64) {
    let o = case.solve(SolveConfig::default()).unwrap_or_else(|e| panic!("{}: {e}", case.name));
    assert!(o.converged, "{}: not converged, [{}, {}]", case.name, o.lower, o.upper);
    assert!(o.upper - o.lower < 1e-4, "{}: [{}, {}]", case.name, o.lower, o.upper);
    let slack = 1e-9;
    assert!(
        o.lower - slack <= want && want <= o.upper + slack,
        "{}: W* = {want} is not in [{}, {}]",
        case.name,
        o.lower,
        o.upper
    );
}

fn left(x: usize, _: usize) -> bool {
    x == 0
}

fn right_of_two(x: usize, _: usize) -> bool {
    x == 1
}

fn right_of_three(x: usize, _: usize) -> bool {
    x == 2
}

/// The 3-cell corridor with a region at each end and 3-step windows, in closed form.
///
/// A step keeps both windows only when it arrives at one end having left the other end two
/// steps before: a traversal without a slip. Under the natural policy (head for the other
/// end) there are three situations. `E`: at an end. The move towards the middle succeeds
/// with probability `p` (-> `M1`); every slip stays put (walls), so `E -> E` with `1 - p`.
/// `M1`: in the middle, having left an end one step ago. The move on succeeds with `p` (a
/// kept step, -> `E`); a slip back (`q = (1 - p) / 3`) reaches an end without keeping
/// (-> `E`); a slip into a wall (`2q`) -> `M2`. `M2`: in the middle, too late to keep the
/// next step. Heading for either end reaches an end with `p + q`, since the slip towards the
/// other end does too (-> `E`); else `M2` (`2q`). Stationary: `pi_M1 = p pi_E`, `pi_M2 =
/// 2q pi_M1 / (1 - 2q)`, so `W* = p pi_M1 = p^2 / (1 + p + 2 p q / (1 - 2q))`. No other
/// action does better: each would only lower the probability of the next useful move.
fn three_cell_corridor(p: f64) -> f64 {
    let q = (1.0 - p) / 3.0;
    p * p / (1.0 + p + 2.0 * p * q / (1.0 - 2.0 * q))
}

#[test]
fn corridors_match_their_closed_forms() {
    // Two cells, windows 2: a step keeps both windows exactly when it moves, which the best
    // action does with max(p, q) (pushing into a wall moves only by slipping).
    for p in [0.7, 0.5, 0.1, 1.0] {
        let case =
            Case { name: "two cells", map: "..", p, regions: vec![(left, 2), (right_of_two, 2)] };
        check(&case, p.max((1.0 - p) / 3.0));
    }
    for p in [0.7, 0.5, 0.9] {
        let regions = vec![(left as Cells, 3), (right_of_three, 3)];
        check(&Case { name: "three cells", map: "...", p, regions }, three_cell_corridor(p));
    }
    // Windows one step too short: the ends are two steps apart, so no step keeps both.
    let regions = vec![(left as Cells, 2), (right_of_three, 2)];
    check(&Case { name: "too short", map: "...", p: 0.7, regions }, 0.0);
    // A bent corridor behaves as the straight one: walls only keep the robot in place.
    let bent = "..\n#.";
    let corner = |x: usize, y: usize| x == 0 && y == 1;
    let foot = |x: usize, y: usize| x == 1 && y == 0;
    let regions = vec![(corner as Cells, 3), (foot, 3)];
    check(&Case { name: "bent", map: bent, p: 0.7, regions }, three_cell_corridor(0.7));
}

#[test]
fn each_component_is_solved_apart_and_weighted_by_its_starts() {
    let g = three_cell_corridor(0.7);
    let ends = |x: usize, _: usize| x == 0 || x == 4;
    let far_ends = |x: usize, _: usize| x == 2 || x == 6;
    // Two corridors apart, each with both regions: W* as one corridor.
    let regions = vec![(ends as Cells, 3), (far_ends, 3)];
    check(&Case { name: "both", map: "...#...", p: 0.7, regions }, g);
    // Only the left corridor has the regions: half of the starts can keep no window.
    let regions = vec![(left as Cells, 3), (right_of_three, 3)];
    check(&Case { name: "one", map: "...#...", p: 0.7, regions }, g / 2.0);
    // Starts (`S`) in the left corridor only, then in the right one only.
    let regions = vec![(left as Cells, 3), (right_of_three, 3)];
    check(&Case { name: "left starts", map: "S..#...", p: 0.7, regions }, g);
    let regions = vec![(left as Cells, 3), (right_of_three, 3)];
    check(&Case { name: "right starts", map: "...#S..", p: 0.7, regions }, 0.0);
}

/// The gain of the task by the textbook method, for comparison: relative value iteration on
/// every `(cell, tau_1, .., tau_k)` with `tau_j` in `0..=N_j`, damped, in `f64`, until
/// `max(T V - V) - min(T V - V) < 1e-9`. Returns that bracket.
fn reference_gain(moves: &Moves, holds: &[Vec<bool>], windows: &[usize]) -> (f64, f64) {
    let cells = moves.dest.len();
    let per_cell: usize = windows.iter().map(|n| n + 1).product();
    let decode = |i: usize| {
        let mut r = i % per_cell;
        let mut tau = vec![0; windows.len()];
        for j in (0..windows.len()).rev() {
            tau[j] = r % (windows[j] + 1);
            r /= windows[j] + 1;
        }
        (i / per_cell, tau)
    };
    let encode = |c: usize, tau: &[usize]| {
        c * per_cell + tau.iter().zip(windows).fold(0, |a, (t, n)| a * (n + 1) + t)
    };
    let p = moves.p;
    let q = (1.0 - p) / 3.0;
    let mut v = vec![0.0f64; cells * per_cell];
    for _ in 0..200_000 {
        let mut next = v.clone();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for (i, out) in next.iter_mut().enumerate() {
            let (c, tau) = decode(i);
            let w: Vec<f64> = (0..4)
                .map(|a| {
                    let to = moves.dest[c][a] as usize;
                    let nt: Vec<usize> = (0..windows.len())
                        .map(|j| if holds[j][to] { 0 } else { (tau[j] + 1).min(windows[j]) })
                        .collect();
                    let kept = nt.iter().zip(windows).all(|(t, n)| t < n);
                    f64::from(u8::from(kept)) + v[encode(to, &nt)]
                })
                .collect();
            let sum: f64 = w.iter().sum();
            let best = (0..4).map(|a| p * w[a] + q * (sum - w[a])).fold(f64::MIN, f64::max);
            lo = lo.min(best - v[i]);
            hi = hi.max(best - v[i]);
            *out = v[i] + 0.5 * (best - v[i]);
        }
        let shift = next[0];
        v = next.into_iter().map(|x| x - shift).collect();
        if hi - lo < 1e-9 {
            return (lo, hi);
        }
    }
    panic!("the reference solver did not converge")
}

#[test]
fn small_random_worlds_match_the_reference_solver() {
    let mut rng = seeded_rng(11);
    let mut solved = 0;
    while solved < 60 {
        let (w, h) = (rng.random_range(1..=4usize), rng.random_range(1..=3usize));
        let map: String = (0..h)
            .map(|_| (0..w).map(|_| if rng.random_bool(0.2) { '#' } else { '.' }).collect())
            .collect::<Vec<String>>()
            .join("\n");
        if !map.contains('.') {
            continue;
        }
        let p = [0.1, 0.25, 0.5, 0.7, 0.9, 1.0][rng.random_range(0..6)];
        let world = MapWorld::new(&map, p);
        let cells = world.cells.len();
        // Connected worlds only: the reference solver assumes one component.
        let mut seen = vec![false; cells];
        let mut stack = vec![0usize];
        seen[0] = true;
        while let Some(s) = stack.pop() {
            for &t in &world.moves.dest[s] {
                if !std::mem::replace(&mut seen[t as usize], true) {
                    stack.push(t as usize);
                }
            }
        }
        if seen.contains(&false) {
            continue;
        }
        let k = rng.random_range(1..=3usize);
        let holds: Vec<Vec<bool>> = (0..k)
            .map(|_| {
                let mut r: Vec<bool> = (0..cells).map(|_| rng.random_bool(0.3)).collect();
                let one = rng.random_range(0..cells);
                r[one] = true;
                r
            })
            .collect();
        let windows: Vec<usize> = (0..k).map(|_| rng.random_range(1..=5usize)).collect();
        let want = reference_gain(&world.moves, &holds, &windows);
        // Nearly deterministic worlds with two equally good places mix slowly: allow the
        // sweeps the reference solver needs too.
        let config =
            SolveConfig { tolerance: 1e-6, max_iterations: 20_000, ..SolveConfig::default() };
        let o = solve_windows(&world.moves, &holds, &windows, config).unwrap();
        let what = format!("map {map:?}, p {p}, windows {windows:?}, regions {holds:?}");
        assert!(o.lower <= want.1 + 1e-9 && want.0 - 1e-9 <= o.upper, "{what}: {o:?} vs {want:?}");
        assert!(o.converged, "{what}: not converged, [{}, {}]", o.lower, o.upper);
        solved += 1;
    }
}

#[test]
fn an_unconverged_bracket_still_holds_the_optimum() {
    let world = MapWorld::new(FOUR_ROOMS, 0.8);
    let holds = vec![
        world.region(|x, y| x <= 2 && y >= 9),
        world.region(|x, y| x >= 10 && y >= 9),
        world.region(|x, y| x >= 10 && y <= 3),
    ];
    let windows = [30, 30, 30];
    let full = solve_windows(&world.moves, &holds, &windows, SolveConfig::default()).unwrap();
    assert!(full.converged && full.gain > 0.1, "{full:?}");
    for sweeps in [1, 3, 10] {
        let config = SolveConfig { max_iterations: sweeps, ..SolveConfig::default() };
        let cut = solve_windows(&world.moves, &holds, &windows, config).unwrap();
        assert!(!cut.converged && cut.iterations == sweeps, "{sweeps}: {cut:?}");
        assert!(cut.lower <= full.upper && full.lower <= cut.upper, "{sweeps}: {cut:?}");
    }
}

#[test]
fn oversized_tasks_are_refused_before_they_are_allocated() {
    let world = MapWorld::new(&vec![".".repeat(15); 15].join("\n"), 0.7);
    let holds = vec![world.region(|x, y| x < 3 && y < 3), world.region(|x, y| x > 11 && y > 11)];
    let refused = |windows: &[usize], max_states: usize| {
        let config = SolveConfig { max_states, ..SolveConfig::default() };
        match solve_windows(&world.moves, &holds, windows, config) {
            Err(Error::Config(message)) => message,
            other => panic!("{windows:?}: {other:?}"),
        }
    };
    // Two windows of 1333 steps: 225 x 1333 x 1333 states, nearly all of them reachable,
    // refused while the reachable ones are counted.
    let message = refused(&[1333, 1333], SolveConfig::default().max_states);
    assert!(message.contains("more than 16777216 reachable states"), "{message}");
    assert!(message.contains("225 cells x windows 1333 x 1333"), "{message}");
    assert!(message.contains("fewer regions or shorter windows"), "{message}");
    // A state space too large to search at all is refused before anything is allocated.
    let message = refused(&[20, 20], 1000);
    assert!(message.contains("has 90000 states (225 cells x windows 20 x 20)"), "{message}");
    assert!(message.contains("the limit is 32000"), "{message}");
    // With windows of 1 and 2 steps every row holds one or two states, whose tables take
    // more than 64 bytes each: a budget of exactly the states needed refuses them.
    let holds3 = vec![holds[0].clone(), holds[1].clone(), world.region(|x, _| x == 7)];
    let windows = [1, 1, 2];
    let needed = solve_windows(&world.moves, &holds3, &windows, SolveConfig::default()).unwrap();
    let config = SolveConfig { max_states: needed.states, ..SolveConfig::default() };
    let e = solve_windows(&world.moves, &holds3, &windows, config);
    let Err(Error::Config(message)) = e else { panic!("{} states: {e:?}", needed.states) };
    assert!(message.contains("MiB of tables for"), "{message}");
    let config = SolveConfig { max_states: 90_000, ..SolveConfig::default() };
    assert!(solve_windows(&world.moves, &holds, &[20, 20], config).is_ok());
}

#[test]
fn bad_worlds_and_regions_are_errors() {
    let world = MapWorld::new("...", 0.7);
    let holds = vec![world.region(left), world.region(right_of_three)];
    let bad_moves = [
        Moves { dest: vec![[0, 0, 0, 3]], p: 0.7, starts: vec![0] },
        Moves { dest: vec![[0; 4]], p: 1.5, starts: vec![0] },
        Moves { dest: vec![[0; 4]], p: 0.7, starts: vec![] },
        Moves { dest: vec![[0; 4]], p: 0.7, starts: vec![2] },
        // A move from 0 to 1 with none back.
        Moves { dest: vec![[1, 0, 0, 0], [1; 4]], p: 0.7, starts: vec![0] },
    ];
    for moves in &bad_moves {
        let n = moves.dest.len();
        let holds = vec![vec![true; n]];
        let e = solve_windows(moves, &holds, &[2], SolveConfig::default());
        assert!(matches!(e, Err(Error::Env(_))), "{moves:?}: {e:?}");
    }
    let bad_regions: [(Vec<Vec<bool>>, Vec<usize>); 4] = [
        (vec![], vec![]),
        (holds.clone(), vec![3]),
        (holds.clone(), vec![3, 0]),
        (vec![vec![true; 2], vec![true; 2]], vec![3, 3]),
    ];
    for (holds, windows) in &bad_regions {
        let e = solve_windows(&world.moves, holds, windows, SolveConfig::default());
        assert!(matches!(e, Err(Error::Config(_))), "{windows:?}: {e:?}");
    }
}

/// A generated task (`scripts/gen-tasks --seed 3`, g12): two rooms joined by two doors,
/// slip 0.3, windows 46 and 56. The Newton step on the gain overshot here and the drift
/// grew without bound (`W*` reported as 3.9e16, not converged); the gain is held in [0, 1].
const TWO_DOORS: &str = "\
###################
#.....#...........#
#.....#...........#
#.....#...........#
#.................#
#.................#
#..#####..#########
#.................#
#.....#...........#
#.....#...........#
#.....#...........#
#.....#...........#
#.....#...........#
#.....#...........#
#.....#...........#
###################";

fn g12_a(x: usize, y: usize) -> bool {
    (15..=17).contains(&x) && y == 8
}

fn g12_b(x: usize, y: usize) -> bool {
    x == 2 && y == 4
}

#[test]
fn a_slow_world_converges_to_a_gain_between_0_and_1() {
    let case =
        Case { name: "g12", map: TWO_DOORS, p: 0.7, regions: vec![(g12_a, 46), (g12_b, 56)] };
    let o = case.solve(SolveConfig::default()).expect("solves");
    assert!(o.converged, "not converged: [{}, {}]", o.lower, o.upper);
    assert!(0.0 <= o.lower && o.upper <= 1.0, "[{}, {}]", o.lower, o.upper);
}
