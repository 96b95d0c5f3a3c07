//! Plane worlds: the motion contract (headings, slips, noise, blocked moves, starts), the
//! seeded reproducibility of runs, and `policy.json`'s copy of the world.

use std::f64::consts::{FRAC_1_SQRT_2, PI};

use hstl_runtime::world::AnyWorld;
use hstl_runtime::{Obstacle, PlaneConfig, PlaneWorld, Point, World, seeded_rng};

const YARD: &str = include_str!("data/yard.toml");
const MAZE: &str = include_str!("data/maze.toml");

fn open(headings: usize, slip: f64, noise: f64) -> PlaneConfig {
    PlaneConfig {
        x: [-1000.0, 1000.0],
        y: [-1000.0, 1000.0],
        step: 1.0,
        headings,
        slip,
        noise,
        obstacles: Vec::new(),
        start: None,
    }
}

fn world(config: PlaneConfig) -> PlaneWorld {
    PlaneWorld::new("test", config).unwrap()
}

fn bits(p: Point) -> (u64, u64) {
    (p.x.to_bits(), p.y.to_bits())
}

#[test]
fn headings_are_named_and_the_axes_are_exact() {
    let four = world(open(4, 0.0, 0.0));
    assert_eq!(four.actions(), ["E", "N", "W", "S"]);
    let axes = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)];
    for (k, want) in axes.iter().enumerate() {
        assert_eq!(four.heading(k), Some(*want));
    }
    assert_eq!(four.heading(4), None);
    let eight = world(open(8, 0.0, 0.0));
    assert_eq!(eight.actions(), ["E", "NE", "N", "NW", "W", "SW", "S", "SE"]);
    let h = FRAC_1_SQRT_2;
    let want =
        [(1.0, 0.0), (h, h), (0.0, 1.0), (-h, h), (-1.0, 0.0), (-h, -h), (0.0, -1.0), (h, -h)];
    for (k, want) in want.iter().enumerate() {
        assert_eq!(eight.heading(k), Some(*want), "heading {k}");
    }
    assert_eq!(world(open(5, 0.0, 0.0)).actions(), ["H0", "H1", "H2", "H3", "H4"]);
    for n in 3..=64 {
        let w = world(open(n, 0.0, 0.0));
        for k in 0..n {
            let (ux, uy) = w.heading(k).unwrap();
            // Against the platform's cos and sin of the whole angle, which are off by up to
            // a few 1e-16 at angles near 2 pi.
            let angle = 2.0 * PI * k as f64 / n as f64;
            assert!(
                (ux - angle.cos()).abs() < 4e-15 && (uy - angle.sin()).abs() < 4e-15,
                "{n}: {k} is ({ux}, {uy}), not ({}, {})",
                angle.cos(),
                angle.sin()
            );
            if (4 * k) % n == 0 {
                // Along an axis: one component exactly 0 (not -0), the other exactly +-1.
                assert!(ux == 0.0 || uy == 0.0, "{n}: {k} is ({ux}, {uy})");
                assert!(ux.to_bits() != (-0.0f64).to_bits() && uy.to_bits() != (-0.0f64).to_bits());
                assert_eq!(ux.abs() + uy.abs(), 1.0);
            }
        }
    }
    // A move along an axis changes one coordinate by exactly the step.
    let w = world(PlaneConfig { step: 0.7, ..open(4, 0.0, 0.0) });
    let mut rng = seeded_rng(1);
    let from = Point { x: 3.3, y: 4.7 };
    assert_eq!(bits(w.step(&from, 0, &mut rng)), bits(Point { x: 3.3 + 0.7, y: 4.7 }));
    assert_eq!(bits(w.step(&from, 3, &mut rng)), bits(Point { x: 3.3, y: 4.7 - 0.7 }));
    // An action outside the set leaves the state as it is and draws nothing.
    let mut a = seeded_rng(9);
    let b = seeded_rng(9);
    assert_eq!(w.step(&from, 4, &mut a), from);
    assert_eq!(a, b);
}

#[test]
fn blocked_moves_leave_the_state_bit_identical() {
    let config = PlaneConfig {
        x: [0.0, 14.0],
        y: [0.0, 14.0],
        obstacles: vec![
            Obstacle::Rect { x0: 4.0, y0: 0.0, x1: 5.0, y1: 6.0 },
            Obstacle::Circle { cx: 10.0, cy: 10.0, r: 1.0 },
        ],
        ..open(4, 0.0, 0.0)
    };
    let w = world(config);
    let mut rng = seeded_rng(2);
    let cases = [
        // Onto the rectangle's edge: touching it blocks.
        (Point { x: 3.0, y: 2.0 }, 0, None),
        // Short of it: moves.
        (Point { x: 2.9, y: 2.0 }, 0, Some(Point { x: 3.9, y: 2.0 })),
        // Past the extent: blocked; onto its edge: moves (the edge is inside).
        (Point { x: 13.5, y: 3.0 }, 0, None),
        (Point { x: 13.0, y: 3.0 }, 0, Some(Point { x: 14.0, y: 3.0 })),
        (Point { x: 0.0, y: 0.0 }, 3, None),
        // Tangent to the circle at (10, 9), moving along y = 9: blocked.
        (Point { x: 9.5, y: 9.0 }, 0, None),
        // Just below the tangent: moves.
        (Point { x: 9.5, y: 8.999_999 }, 0, Some(Point { x: 10.5, y: 8.999_999 })),
        // Over the rectangle's top corner at (5, 6), along y = 6: blocked.
        (Point { x: 5.5, y: 6.0 }, 2, None),
    ];
    for (from, action, to) in cases {
        let got = w.step(&from, action, &mut rng);
        assert_eq!(bits(got), bits(to.unwrap_or(from)), "{from:?} heading {action}");
    }
    // With noise, every blocked move returns the very same bits.
    let noisy = world(PlaneConfig { noise: 0.3, ..w.config().clone() });
    let at = Point { x: 3.5, y: 2.0 };
    let mut blocked = 0;
    for _ in 0..2000 {
        let to = noisy.step(&at, 0, &mut rng);
        if to == at {
            assert_eq!(bits(to), bits(at));
            blocked += 1;
        } else {
            assert!(noisy.segment_is_free(at, to));
        }
    }
    assert!(blocked > 500, "{blocked}");
}

#[test]
fn segments_touching_obstacles_and_the_extent_edge() {
    let w = world(PlaneConfig {
        x: [0.0, 10.0],
        y: [0.0, 10.0],
        obstacles: vec![Obstacle::Rect { x0: 4.0, y0: 4.0, x1: 6.0, y1: 6.0 }],
        ..open(4, 0.0, 0.0)
    });
    let p = |x, y| Point { x, y };
    // Along the extent's edge: inside.
    assert!(w.segment_is_free(p(0.0, 0.0), p(0.0, 10.0)));
    // One ulp past it: out.
    assert!(!w.segment_is_free(p(0.0, 1.0), p(-f64::from_bits(1), 1.0)));
    // Along the obstacle's edge, through its corner, or wholly inside it: blocked.
    assert!(!w.segment_is_free(p(4.0, 1.0), p(4.0, 9.0)));
    assert!(!w.segment_is_free(p(3.0, 7.0), p(5.0, 5.0)));
    assert!(!w.segment_is_free(p(3.0, 5.0), p(4.5, 6.5)));
    assert!(!w.segment_is_free(p(4.5, 4.5), p(5.5, 5.5)));
    // A zero-length segment is its point.
    assert!(w.segment_is_free(p(1.0, 1.0), p(1.0, 1.0)));
    assert!(!w.segment_is_free(p(6.0, 6.0), p(6.0, 6.0)));
    assert!(w.is_free(p(10.0, 10.0)) && !w.is_free(p(4.0, 5.0)) && !w.is_free(p(10.5, 1.0)));
    let circle = Obstacle::Circle { cx: 5.0, cy: 5.0, r: 1.0 };
    assert!(circle.contains(p(6.0, 5.0)) && !circle.contains(p(6.000_001, 5.0)));
    assert!(circle.touches_segment(p(3.0, 4.0), p(7.0, 4.0)));
    assert!(!circle.touches_segment(p(0.0, 0.0), p(3.0, 3.0)));
}

/// Whether `n` draws with `k` hits are within `z` standard deviations of probability `p`.
fn near(k: usize, n: usize, p: f64, z: f64) -> bool {
    let sd = (n as f64 * p * (1.0 - p)).sqrt();
    (k as f64 - n as f64 * p).abs() <= z * sd
}

#[test]
fn slips_take_each_other_heading_equally_often() {
    for (headings, slip) in [(4, 0.3), (8, 0.3), (5, 1.0), (8, 0.0)] {
        let w = world(open(headings, slip, 0.0));
        let mut rng = seeded_rng(headings as u64);
        let from = Point { x: 0.0, y: 0.0 };
        let chosen = 1;
        let n = 100_000;
        let mut taken = vec![0usize; headings];
        for _ in 0..n {
            let to = w.step(&from, chosen, &mut rng);
            let k = (0..headings)
                .find(|&k| {
                    let (ux, uy) = w.heading(k).unwrap();
                    to.x == from.x + ux && to.y == from.y + uy
                })
                .expect("a move along one of the headings");
            taken[k] += 1;
        }
        assert!(near(taken[chosen], n, 1.0 - slip, 5.0), "{headings} {slip}: {taken:?}");
        let other = slip / (headings - 1) as f64;
        for (k, &t) in taken.iter().enumerate().filter(|&(k, _)| k != chosen) {
            assert!(near(t, n, other, 5.0), "{headings} {slip}: heading {k}, {taken:?}");
        }
    }
}

#[test]
fn noise_is_gaussian_with_the_given_deviation_on_each_coordinate() {
    let noise = 0.5;
    let w = world(open(4, 0.0, noise));
    let mut rng = seeded_rng(3);
    let from = Point { x: 0.0, y: 0.0 };
    let n = 200_000;
    let (mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut within = 0;
    for _ in 0..n {
        let to = w.step(&from, 0, &mut rng);
        let (ex, ey) = (to.x - 1.0, to.y);
        sx += ex;
        sy += ey;
        sxx += ex * ex;
        syy += ey * ey;
        sxy += ex * ey;
        within += usize::from(ex.abs() <= noise);
    }
    let n_f = n as f64;
    // The mean is within 5 standard errors of 0; the variance within 5 of its own.
    let se_mean = noise / n_f.sqrt();
    assert!((sx / n_f).abs() < 5.0 * se_mean && (sy / n_f).abs() < 5.0 * se_mean);
    let se_var = noise * noise * (2.0 / n_f).sqrt();
    for s in [sxx, syy] {
        assert!((s / n_f - noise * noise).abs() < 5.0 * se_var, "{}", s / n_f);
    }
    assert!((sxy / n_f).abs() < 5.0 * se_var, "correlated: {}", sxy / n_f);
    // About 68.27% within one standard deviation, as a normal distribution has.
    assert!(near(within, n, 0.682_689_492, 5.0), "{within}");
}

#[test]
fn starts_are_uniform_over_the_free_part_of_the_clipped_rectangle() {
    let w = world(PlaneConfig {
        x: [0.0, 10.0],
        y: [0.0, 10.0],
        obstacles: vec![Obstacle::Rect { x0: -1.0, y0: -1.0, x1: 2.0, y1: 2.0 }],
        start: Some([-5.0, -5.0, 4.0, 4.0]),
        ..open(4, 0.0, 0.0)
    });
    assert_eq!(w.start(), [0.0, 0.0, 4.0, 4.0]);
    let mut rng = seeded_rng(4);
    // A 4 x 4 histogram of unit cells; the lower-left 2 x 2 are covered.
    let mut cells = [[0usize; 4]; 4];
    let n = 60_000;
    for _ in 0..n {
        let p = w.reset(&mut rng);
        assert!((0.0..=4.0).contains(&p.x) && (0.0..=4.0).contains(&p.y), "{p:?}");
        assert!(w.is_free(p) && !(p.x <= 2.0 && p.y <= 2.0), "{p:?}");
        cells[(p.y as usize).min(3)][(p.x as usize).min(3)] += 1;
    }
    for (y, row) in cells.iter().enumerate() {
        for (x, &count) in row.iter().enumerate() {
            if x < 2 && y < 2 {
                assert_eq!(count, 0);
            } else {
                assert!(near(count, n, 1.0 / 12.0, 5.0), "cell ({x}, {y}): {count}");
            }
        }
    }
    // Without a start rectangle, the whole extent; a point start is that point.
    let whole = world(open(4, 0.0, 0.0));
    assert_eq!(whole.start(), [-1000.0, -1000.0, 1000.0, 1000.0]);
    assert_eq!(whole.start_attempts(), 50);
    let point = world(PlaneConfig { start: Some([3.0, 4.0, 3.0, 4.0]), ..open(4, 0.0, 0.0) });
    assert_eq!(point.reset(&mut rng), Point { x: 3.0, y: 4.0 });
    // A quarter covered: the free share found is at least 3/4, and a reset draws enough.
    // (Boxes that touch the obstacle's edge are not free, so the bound is a little below.)
    assert!((0.749..=0.75).contains(&w.start_free_share()), "{}", w.start_free_share());
    assert!(w.start_attempts() <= 67, "{}", w.start_attempts());
}

#[test]
fn the_same_seed_gives_the_same_run_bit_for_bit() {
    let w = PlaneWorld::from_toml(MAZE, "maze").unwrap();
    let run = |seed| {
        let mut rng = seeded_rng(seed);
        let mut s = w.reset(&mut rng);
        let mut out = vec![bits(s)];
        for t in 0..5000 {
            s = w.step(&s, t % 6, &mut rng);
            assert!(w.is_free(s), "{s:?}");
            out.push(bits(s));
        }
        out
    };
    assert_eq!(run(7), run(7));
    assert_ne!(run(7), run(8));
}

#[test]
fn the_paper_plane_draws_as_pinned() {
    // The draws (uniforms from ChaCha8, the polar method over basic IEEE operations) are
    // the same on every platform and every release: a change here changes every run.
    let w = PlaneWorld::builtin("paper-plane").unwrap();
    let mut rng = seeded_rng(2016);
    let mut s = w.reset(&mut rng);
    let mut got = vec![bits(s)];
    for a in [0, 1, 1, 2, 3, 0] {
        s = w.step(&s, a, &mut rng);
        got.push(bits(s));
    }
    let want: Vec<(u64, u64)> = PINNED.to_vec();
    assert_eq!(
        got,
        want,
        "{:?}",
        got.iter().map(|&(x, y)| (f64::from_bits(x), f64::from_bits(y))).collect::<Vec<_>>()
    );
}

const PINNED: [(u64, u64); 7] = [
    (4619777716394271724, 4617355939665882265),
    (4620859876984924851, 4617589669809530023),
    (4620864590711952990, 4618684674774595888),
    (4621368375372564047, 4618646076043103324),
    (4620841301197014131, 4618458827095464346),
    (4620842592585859960, 4617264495996681549),
    (4621410894284684840, 4617296189687915355),
];

#[test]
fn the_paper_plane_is_the_papers_case_study() {
    let Some(AnyWorld::Plane(w)) = AnyWorld::builtin("paper-plane") else { panic!() };
    assert_eq!(w.name(), "paper-plane");
    assert_eq!(w.extent(), ([0.0, 14.0], [0.0, 14.0]));
    assert_eq!((w.step_length(), w.headings(), w.slip(), w.noise()), (1.0, 4, 0.3, 0.1));
    assert!(w.obstacles().is_empty());
    assert_eq!(w.state_vars(), ["x", "y"]);
    assert_eq!(w.actions(), ["E", "N", "W", "S"]);
    let mut out = Vec::new();
    w.valuation(&Point { x: 1.5, y: 2.5 }, &mut out);
    assert_eq!(out, [1.5, 2.5]);
}

#[test]
fn params_hold_the_world_whole() {
    for (text, name) in [(YARD, "yard"), (MAZE, "maze")] {
        let w = PlaneWorld::from_toml(text, name).unwrap();
        let params = w.params();
        assert_eq!(params["kind"], "plane");
        let back = PlaneWorld::from_params(w.name(), &params).unwrap();
        assert_eq!(back, w);
        // Through JSON text, as policy.json stores it.
        let text = serde_json::to_string(&params).unwrap();
        let again: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(AnyWorld::from_params(w.name(), &again).unwrap(), AnyWorld::Plane(w));
    }
    let yard = PlaneWorld::from_toml(YARD, "x").unwrap();
    assert_eq!(
        yard.params(),
        serde_json::json!({
            "kind": "plane", "x": [0.0, 20.0], "y": [0.0, 10.0], "step": 0.5, "headings": 8,
            "slip": 0.1, "noise": 0.05,
            "obstacles": [{ "circle": [10.0, 5.0, 1.5] }, { "rect": [4.0, 0.0, 5.0, 6.0] }],
            "start": [0.0, 0.0, 2.0, 2.0],
        })
    );
    // Grids still read back from their own params.
    let grid = AnyWorld::builtin("four-rooms").unwrap();
    assert_eq!(AnyWorld::from_params("four-rooms", &grid.params()).unwrap(), grid);
    // Hostile parameters are errors, not panics or allocations.
    let mut many = yard.params();
    many["obstacles"] =
        serde_json::Value::Array(vec![serde_json::json!({ "circle": [1, 1, 1] }); 5000]);
    let mut two_keys = yard.params();
    two_keys["obstacles"] = serde_json::json!([{ "circle": [1, 1, 1], "rect": [0, 0, 1, 1] }]);
    let mut no_step = yard.params();
    no_step.as_object_mut().unwrap().remove("step");
    let mut bad_slip = yard.params();
    bad_slip["slip"] = serde_json::json!(2.0);
    let mut negative_headings = yard.params();
    negative_headings["headings"] = serde_json::json!(-4);
    for bad in
        [many, two_keys, no_step, bad_slip, negative_headings, serde_json::json!({ "kind": 3 })]
    {
        assert!(AnyWorld::from_params("w", &bad).is_err(), "{bad}");
    }
}
