//! Runs one side of the `monitors` bench a few times, for load-independent instruction
//! counts under callgrind (`setup` runs the setup alone, to subtract):
//!
//! ```text
//! cargo build --release -p hstl-macros --example monitor_counts
//! valgrind --tool=callgrind target/release/examples/monitor_counts F2/generated
//! ```
//!
//! A second argument sets the number of runs (3 by default).

#[path = "../benches/data/mod.rs"]
mod data;

use data::{Data, f1, f2};
use hstl::robustness::Evaluator;
use std::hint::black_box;

fn main() {
    let which = std::env::args().nth(1).unwrap_or_default();
    let runs: usize = std::env::args().nth(2).and_then(|r| r.parse().ok()).unwrap_or(3);
    let Data { trace, s1, s2 } = Data::default();
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
