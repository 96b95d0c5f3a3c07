//! MountainCar against gymnasium: the state sequences gymnasium 1.4 computed (recorded by
//! `data/mountain_car_reference.py`), bit for bit. Gymnasium keeps its state in float64
//! and steps it with the same operations in the same order; its `cos` is the platform's,
//! as ours is, so the bits agree on the machine that recorded them (and on any whose `cos`
//! rounds alike, as glibc's does everywhere it runs).

use hstl_runtime::{CarState, MountainCar, World, seeded_rng};
use serde_json::Value;

const REFERENCE: &str = include_str!("data/mountain_car_reference.json");

fn parse(v: &Value) -> f64 {
    v.as_str().and_then(|s| s.parse().ok()).expect("a number written with repr")
}

#[test]
fn every_state_equals_gymnasiums_bit_for_bit() {
    let reference: Value = serde_json::from_str(REFERENCE).unwrap();
    let cases = reference["cases"].as_object().unwrap();
    assert_eq!(cases.len(), 6);
    let (mut walls, mut past_goal, mut steps) = (0, 0, 0);
    let car = MountainCar;
    let mut rng = seeded_rng(0);
    for (name, case) in cases {
        let start = case["start"].as_array().unwrap();
        let mut s = CarState { x: parse(&start[0]), v: parse(&start[1]) };
        let actions = case["actions"].as_str().unwrap();
        let states = case["states"].as_array().unwrap();
        assert_eq!(actions.len(), states.len());
        for (t, (a, want)) in actions.bytes().zip(states).enumerate() {
            s = car.step(&s, usize::from(a - b'0'), &mut rng);
            let want = CarState { x: parse(&want[0]), v: parse(&want[1]) };
            assert_eq!(
                (s.x.to_bits(), s.v.to_bits()),
                (want.x.to_bits(), want.v.to_bits()),
                "{name}, step {t}: {s:?}, gymnasium {want:?}"
            );
            walls += usize::from(s.x == MountainCar::MIN_POSITION && s.v == 0.0);
            past_goal += usize::from(s.x >= MountainCar::GOAL_POSITION);
            steps += 1;
        }
    }
    // The reference covers what the dynamics single out.
    assert!(steps >= 1500, "{steps}");
    assert!(walls >= 3, "the left wall is hit {walls} times");
    assert!(past_goal >= 100, "{past_goal} states past the goal");
}

#[test]
fn the_car_keeps_to_its_bounds_and_resets_in_the_valley() {
    let car = MountainCar;
    assert_eq!(car.state_vars(), ["x", "v"]);
    assert_eq!(car.actions(), ["left", "none", "right"]);
    let mut rng = seeded_rng(5);
    for _ in 0..200 {
        let mut s = car.reset(&mut rng);
        assert!((-0.6..=-0.4).contains(&s.x) && s.v == 0.0, "{s:?}");
        for t in 0..300 {
            let a = if t % 7 < 3 { 0 } else { 2 };
            s = car.step(&s, a, &mut rng);
            assert!((-1.2..=0.6).contains(&s.x) && (-0.07..=0.07).contains(&s.v), "{s:?}");
        }
    }
    // No termination: past the goal the car steps on; an unknown action changes nothing.
    let at_goal = CarState { x: 0.55, v: 0.01 };
    assert_ne!(car.step(&at_goal, 1, &mut rng), at_goal);
    assert_eq!(car.step(&at_goal, 3, &mut rng), at_goal);
    assert_eq!(MountainCar::from_params(&car.params()), Ok(MountainCar));
    assert!(MountainCar::from_params(&serde_json::json!({ "kind": "plane" })).is_err());
}
