//! The specs and data of the `monitors` bench, shared with the `monitor_counts` example:
//! F1 and F2 through the macro, and the robustness benches' walk (`robustness/benches/
//! walk.rs`) as a trace and as typed states.

#[path = "../../../robustness/benches/walk.rs"]
#[allow(dead_code)]
mod walk;

use hstl::robustness::Trace;
use hstl_macros::hstl;

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

/// Steps in the walk.
pub const STEPS: usize = walk::STEPS;

/// The walk as the interpreter's trace and as each spec's states.
pub struct Data {
    /// Columns `x`, `y`.
    pub trace: Trace,
    /// The walk as F1's states.
    pub s1: Vec<f1::State>,
    /// The walk as F2's states.
    pub s2: Vec<f2::State>,
}

impl Default for Data {
    /// The robustness benches' walk: `STEPS` steps from (7, 7) drawn by splitmix64.
    fn default() -> Data {
        let trace = walk::walk(STEPS, &mut walk::SplitMix64(walk::SEED));
        let cells: Vec<(i64, i64)> = (0..trace.len())
            .map(|t| (trace.column(0)[t] as i64, trace.column(1)[t] as i64))
            .collect();
        let s1 = cells.iter().map(|&(x, y)| f1::State { x, y }).collect();
        let s2 = cells.iter().map(|&(x, y)| f2::State { x, y }).collect();
        Data { trace, s1, s2 }
    }
}
