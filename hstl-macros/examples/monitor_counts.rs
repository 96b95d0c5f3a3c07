//! Runs one side of the `monitors` bench a few times, for load-independent instruction
//! counts under callgrind (`setup` runs the setup alone, to subtract):
//!
//! ```text
//! cargo build --release -p hstl-macros --example monitor_counts
//! valgrind --tool=callgrind target/release/examples/monitor_counts F2/generated
//! ```
//!
//! A second argument sets the number of runs (3 by default).

use hstl::robustness::{Evaluator, Trace};
use hstl_macros::hstl;
use std::hint::black_box;

hstl! {
    /// F1: a 41-step always over region A.
    spec F1 {
        state { x: int in 0..=14, y: int in 0..=14 }
        task always[0..=40] (x > 3 && x < 9 && y > 10 && y < 14);
    }
    /// F2: the case study's persistent task.
    spec F2 {
        state { x: int in 0..=14, y: int in 0..=14 }
        let A = x > 3 && x < 9 && y > 10 && y < 14;
        let B = x > 1 && x < 5 && y > 1 && y < 5;
        let C = 9 < x < 13 && 1 < y < 7;
        task always[0..] (eventually[0..40] A && eventually[0..40] B && eventually[0..40] C);
    }
}

const STEPS: usize = 1_000_000;

/// The bench's walk: from (7, 7) on the 15 x 15 grid, moves drawn by splitmix64.
fn walk() -> Vec<(i64, i64)> {
    let mut state: u64 = 0x5eed_2016;
    let (mut x, mut y) = (7i64, 7i64);
    let mut out = Vec::with_capacity(STEPS);
    for _ in 0..STEPS {
        out.push((x, y));
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        let (dx, dy) = match (z ^ (z >> 31)) % 4 {
            0 => (0, 1),
            1 => (0, -1),
            2 => (-1, 0),
            _ => (1, 0),
        };
        if (0..=14).contains(&(x + dx)) && (0..=14).contains(&(y + dy)) {
            x += dx;
            y += dy;
        }
    }
    out
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_default();
    let runs: usize = std::env::args().nth(2).and_then(|r| r.parse().ok()).unwrap_or(3);
    let cells = walk();
    let trace = Trace::from_columns(vec![
        cells.iter().map(|c| c.0 as f64).collect(),
        cells.iter().map(|c| c.1 as f64).collect(),
    ])
    .expect("two columns of equal length");
    let s1: Vec<f1::State> = cells.iter().map(|&(x, y)| f1::State { x, y }).collect();
    let s2: Vec<f2::State> = cells.iter().map(|&(x, y)| f2::State { x, y }).collect();
    let (g1, g2) = (f1::task::formula(), f2::task::formula());
    let mut ev = Evaluator::new();
    let mut sum = 0.0;
    for _ in 0..runs {
        sum += match which.as_str() {
            "F1/generated" => f1::task::signal(black_box(&s1))[0],
            "F1/interpreter" => ev.signal(&g1, black_box(&trace))[0],
            "F2/generated" => f2::task::signal(black_box(&s2))[0],
            "F2/interpreter" => ev.signal(&g2, black_box(&trace))[0],
            "setup" => 0.0,
            _ => {
                eprintln!(
                    "error: unknown side `{which}`; give one of F1/generated, F1/interpreter, \
                     F2/generated, F2/interpreter, setup"
                );
                std::process::exit(2);
            }
        };
    }
    black_box(sum);
}
