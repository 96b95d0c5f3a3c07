//! The exact optimum: `W*` of the case study (15 x 15 open grid, A, B and C within 40
//! steps, p = 0.7) and of three corners within 30 steps on four-rooms (p = 0.7), and the
//! reach-avoid optimum of reaching a corner within 40 steps around a block on the open grid.
//!
//! `cargo bench -p hstl-runtime --bench optimum -- --warm-up-time 1 --measurement-time 10`

#[path = "../tests/common/mod.rs"]
mod common;
#[path = "../tests/common/world_map.rs"]
mod world_map;

use criterion::{Criterion, criterion_group, criterion_main};
use hstl_runtime::GridWorld;
use hstl_runtime::env::Env;
use hstl_runtime::eval::RegionTable;
use hstl_runtime::moves::Moves;
use hstl_runtime::optimum::{SolveConfig, solve, solve_windows};
use hstl_runtime::reach_avoid::{ReachAvoid, solve_reach_avoid};
use world_map::{FOUR_ROOMS, MapWorld};

fn optimum(c: &mut Criterion) {
    let mut group = c.benchmark_group("optimum");
    group.sample_size(10);
    let env = GridWorld::default();
    let moves = Moves::of(&env);
    let regions = RegionTable::new(&common::case_study(false, false), &env).expect("valid");
    group.bench_function("case study", |b| {
        b.iter(|| solve(&moves, &regions, SolveConfig::default()).expect("solvable").gain)
    });
    let rooms = MapWorld::new(FOUR_ROOMS, 0.7);
    let corners = vec![
        rooms.region(|x, y| x <= 2 && y >= 9),
        rooms.region(|x, y| x >= 10 && y >= 9),
        rooms.region(|x, y| x >= 10 && y <= 3),
    ];
    group.bench_function("four-rooms", |b| {
        b.iter(|| {
            solve_windows(&rooms.moves, &corners, &[30, 30, 30], SolveConfig::default())
                .expect("solvable")
                .gain
        })
    });
    let cells: Vec<_> = (0..env.num_states()).filter_map(|s| env.state(s)).collect();
    let task = ReachAvoid {
        goal: cells.iter().map(|c| c.x >= 12 && c.y >= 12).collect(),
        avoid: cells.iter().map(|c| (5..=9).contains(&c.x) && (5..=9).contains(&c.y)).collect(),
        reach_by: 40,
        avoid_through: 40,
        also: vec![],
    };
    group.bench_function("reach-avoid", |b| {
        b.iter(|| solve_reach_avoid(&moves, &task, 1 << 24).expect("solvable").probability)
    });
    group.finish();
}

criterion_group!(benches, optimum);
criterion_main!(benches);
