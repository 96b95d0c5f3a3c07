//! Grid worlds with walls and start cells: the contract's moves, states and starts, and
//! `policy.json`'s copy of the world.

use hstl_runtime::env::{Cell, Env};
use hstl_runtime::{GridWorld, seeded_rng};

const ROOMS: &str =
    "name = \"rooms\"\nslip = 0.0\nmap = \"\"\"\n#####\n#S#.#\n#...#\n#####\n\"\"\"\n";

#[test]
fn walls_stop_moves_and_are_not_states() {
    let world = GridWorld::from_toml(ROOMS, "ignored").unwrap();
    assert_eq!(world.world_name(), "rooms");
    assert_eq!((world.width(), world.height(), world.num_states()), (5, 4, 5));
    // States are the free cells, row by row from the bottom.
    let cells: Vec<Cell> = (0..5).map(|s| world.state(s).unwrap()).collect();
    let want = [(1, 1), (2, 1), (3, 1), (1, 2), (3, 2)];
    assert_eq!(cells, want.map(|(x, y)| Cell { x, y }));
    for (s, c) in cells.iter().enumerate() {
        assert_eq!(world.index(c), s);
    }
    assert_eq!(world.state(5), None);
    // No slip: the chosen action is always taken, walls and edges keep the robot in place.
    let mut rng = seeded_rng(0);
    let cases = [
        ((1, 1), 0, (1, 2)), // Up into the free cell above
        ((1, 2), 0, (1, 2)), // Up into the top wall
        ((1, 2), 3, (1, 2)), // Right into the wall between the rooms
        ((2, 1), 0, (2, 1)), // Up into that wall
        ((2, 1), 3, (3, 1)),
        ((3, 1), 1, (3, 1)), // Down into the bottom wall
    ];
    for ((x, y), a, (tx, ty)) in cases {
        assert_eq!(world.step(&Cell { x, y }, a, &mut rng), Cell { x: tx, y: ty }, "{x},{y} {a}");
        assert_eq!(world.intended(Cell { x, y }, a), Cell { x: tx, y: ty });
    }
}

#[test]
fn episodes_start_on_start_cells_only() {
    let world = GridWorld::from_toml(ROOMS, "rooms").unwrap();
    assert!(world.has_start_cells());
    assert_eq!(world.starts(), vec![3]);
    let mut rng = seeded_rng(4);
    for _ in 0..50 {
        assert_eq!(world.reset(&mut rng), Cell { x: 1, y: 2 });
    }
    // Without `S`, every free cell is a start, each about equally often.
    let open = GridWorld::from_toml("map = '''\n#..\n...\n'''\n", "open").unwrap();
    let mut seen = vec![0usize; open.num_states()];
    for _ in 0..5000 {
        seen[open.index(&open.reset(&mut rng))] += 1;
    }
    assert!(seen.iter().all(|&n| (900..1100).contains(&n)), "{seen:?}");
}

#[test]
fn the_paper_world_draws_as_the_open_grid_did() {
    // Same size, same p, and the same draws for resets and steps as `GridWorld::new`.
    let paper = GridWorld::default();
    let open = GridWorld::new(15, 15, 0.7).unwrap();
    let (mut a, mut b) = (seeded_rng(11), seeded_rng(11));
    let (mut s, mut t) = (paper.reset(&mut a), open.reset(&mut b));
    for i in 0..10_000 {
        assert_eq!(s, t);
        s = paper.step(&s, i % 4, &mut a);
        t = open.step(&t, i % 4, &mut b);
    }
}

#[test]
fn reachability_and_distances_go_around_walls() {
    let text = "slip = 0.3\nmap = '''\nS.#..\n..#..\n'''\n";
    let world = GridWorld::from_toml(text, "split").unwrap();
    // The right part is cut off from the only start.
    let reach = world.reachable();
    let right: Vec<bool> = (0..world.num_states())
        .filter(|&s| world.state(s).unwrap().x > 2)
        .map(|s| reach[s])
        .collect();
    assert_eq!(right, vec![false; 4]);
    // Around a wall: from (0, 0) to (0, 2) in a U-shaped room is 6 moves, not 2.
    let u = GridWorld::from_toml("map = '''\n...\n##.\n...\n'''\n", "u").unwrap();
    let to = u.index(&Cell { x: 0, y: 2 });
    assert_eq!(u.distances_to(to)[u.index(&Cell { x: 0, y: 0 })], 6);
}

#[test]
fn params_hold_the_world_whole() {
    let world = GridWorld::from_toml(ROOMS, "rooms").unwrap();
    let params = world.params();
    assert_eq!(params["slip"], 0.0);
    assert_eq!(params["map"], serde_json::json!(["#####", "#S#.#", "#...#", "#####"]));
    let back = GridWorld::from_params("rooms", &params).unwrap();
    assert_eq!(back, world);
    // A document written before worlds is the open grid it was.
    let legacy = serde_json::json!({ "width": 15, "height": 15, "p": 0.7 });
    let old = GridWorld::from_params("gridworld", &legacy).unwrap();
    assert_eq!(old, GridWorld::new(15, 15, 0.7).unwrap());
    // Hostile parameters are errors, not allocations.
    for bad in [
        serde_json::json!({ "slip": 0.1, "map": ["..", "x."] }),
        serde_json::json!({ "slip": 2.0, "map": [".."] }),
        serde_json::json!({ "slip": 0.1, "map": [".", ".."] }),
        serde_json::json!({ "slip": 0.1, "map": "..." }),
        serde_json::json!({ "width": 65536, "height": 65535, "p": 0.7 }),
        serde_json::json!({ "slip": 0.1, "map": ["#"] }),
    ] {
        assert!(GridWorld::from_params("w", &bad).is_err(), "{bad}");
    }
}
