//! Plane worlds: the cost of a step (slip, noise, the segment tests against every obstacle)
//! with no obstacles, with the maze's seven and with 1,024 (the most a world may have), and
//! of building a world (the start analysis) with 1,024 obstacles; and the approximate
//! learner's training on `paper-plane`: the case study with the preset's settings (entry
//! options A, B, C, `memory: 8`, the window reward, 8 tilings of 14 x 14), 1200 episodes of
//! 200 choices, seed 1, in primitive steps per second.
//!
//! `cargo bench -p hstl-runtime --bench plane -- --warm-up-time 1 --measurement-time 5`

use std::hint::black_box;

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use hstl_runtime::approx::ApproxLearner;
use hstl_runtime::{
    Obstacle, PlaneConfig, PlaneWorld, RngExt, Terminate, TileParams, World, seeded_rng,
};

/// 1,024 circles and rectangles scattered over a 100 x 100 plane.
fn crowded() -> PlaneConfig {
    let mut rng = seeded_rng(1);
    let obstacles = (0..1024)
        .map(|i| {
            let (x, y) = (rng.random_range(0.0..100.0), rng.random_range(0.0..100.0));
            if i % 2 == 0 {
                Obstacle::Circle { cx: x, cy: y, r: rng.random_range(0.1..2.0) }
            } else {
                let (w, h) = (rng.random_range(0.1..3.0), rng.random_range(0.1..3.0));
                Obstacle::Rect { x0: x, y0: y, x1: x + w, y1: y + h }
            }
        })
        .collect();
    PlaneConfig {
        x: [0.0, 100.0],
        y: [0.0, 100.0],
        step: 0.5,
        headings: 8,
        slip: 0.1,
        noise: 0.05,
        obstacles,
        start: None,
    }
}

fn plane(c: &mut Criterion) {
    let mut group = c.benchmark_group("plane");
    let worlds = [
        ("open", PlaneWorld::builtin("paper-plane").expect("built in")),
        (
            "maze",
            PlaneWorld::from_toml(include_str!("../tests/data/maze.toml"), "maze").expect("valid"),
        ),
        ("1024 obstacles", PlaneWorld::new("crowded", crowded()).expect("valid")),
    ];
    for (name, world) in &worlds {
        let mut rng = seeded_rng(2);
        let mut s = world.reset(&mut rng);
        let mut k = 0;
        group.bench_function(format!("step, {name}"), |b| {
            b.iter(|| {
                k = (k + 1) % world.headings();
                s = world.step(black_box(&s), k, &mut rng);
                s
            })
        });
    }
    group.sample_size(10);
    group.bench_function("build, 1024 obstacles", |b| {
        b.iter(|| PlaneWorld::new("crowded", black_box(crowded())).expect("valid"))
    });
    group.finish();
}

/// The case study as `preset: auto` writes it on `paper-plane`.
fn case_study_plane() -> hstl_runtime::TaskSpec {
    let mut spec = common::case_study_memory();
    for p in &mut spec.primitives {
        p.terminate = Terminate::Formula(p.reach.clone());
    }
    for v in &mut spec.state_vars {
        v.domain = None;
    }
    spec.learn.switch = hstl_runtime::Switch::Step;
    spec.learn.flat.gamma = 0.99;
    spec.learn.flat.alpha = 0.1;
    spec.learn.tiles =
        Some(TileParams { tilings: 8, bins: vec![14, 14], lo: vec![0.0; 2], hi: vec![14.0; 2] });
    spec
}

fn approx(c: &mut Criterion) {
    let world = PlaneWorld::builtin("paper-plane").expect("built in");
    let spec = case_study_plane();
    let mut group = c.benchmark_group("approx");
    group.sample_size(10);
    let train = || {
        let mut learner = ApproxLearner::new(&spec, &world).expect("a valid spec");
        learner.train(&mut seeded_rng(1), |_, _| {}).steps
    };
    group.throughput(Throughput::Elements(train()));
    group.bench_function("train, case study on paper-plane", |b| b.iter(train));
    group.finish();
}

criterion_group!(benches, plane, approx);
criterion_main!(benches);
