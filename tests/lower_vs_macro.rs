//! The two paths from a spec to the runtime agree: the `hstl!` macro (code generated at
//! compile time) and [`hstl::lower`] (the interpreter's path, taken by the command line).
#![deny(warnings)]

use hstl::robustness::{Trace, offline};
use hstl::runtime::{Spec, TaskSpec};

mod ot1 {
    hstl::hstl! { include "examples/specs/surveillance_ot1.hstl" }
}
mod ot2 {
    hstl::hstl! { include "examples/specs/surveillance_ot2.hstl" }
}
mod entry {
    hstl::hstl! { include "examples/specs/surveillance_entry.hstl" }
}
mod assembly {
    hstl::hstl! { include "examples/specs/assembly.hstl" }
}
mod auto {
    hstl::hstl! { include "examples/specs/surveillance_auto.hstl" }
}
mod safe {
    hstl::hstl! { include "examples/specs/surveillance_safe.hstl" }
}
mod reach_avoid {
    hstl::hstl! { include "examples/suite/field_reach_avoid.hstl" }
}

fn lowered(path: &str) -> TaskSpec {
    let full = format!("{}/{path}", env!("CARGO_MANIFEST_DIR"));
    let src = std::fs::read_to_string(&full).expect("example spec exists");
    let checked = hstl::lang::check(&src);
    assert!(
        !checked.has_errors(),
        "{path}:\n{}",
        hstl::lang::render_plain(&src, path, &checked.diagnostics)
    );
    hstl::lower::task_spec(&checked.specs[0], &src).expect("a checked spec lowers")
}

#[test]
fn macro_and_lowering_build_the_same_task_spec() {
    // The preset expands in the checker, so both paths see what it filled in (the entry
    // form, one option per region, memory, `avoid`).
    let cases: [(&str, TaskSpec); 7] = [
        ("examples/specs/surveillance_ot1.hstl", ot1::surveillance::Surveillance.task_spec()),
        ("examples/specs/surveillance_ot2.hstl", ot2::surveillance::Surveillance.task_spec()),
        ("examples/specs/surveillance_entry.hstl", entry::surveillance::Surveillance.task_spec()),
        ("examples/specs/assembly.hstl", assembly::assembly::Assembly.task_spec()),
        (
            "examples/specs/surveillance_auto.hstl",
            auto::surveillance_auto::SurveillanceAuto.task_spec(),
        ),
        (
            "examples/specs/surveillance_safe.hstl",
            safe::surveillance_safe::SurveillanceSafe.task_spec(),
        ),
        (
            "examples/suite/field_reach_avoid.hstl",
            reach_avoid::field_reach_avoid::FieldReachAvoid.task_spec(),
        ),
    ];
    for (path, from_macro) in cases {
        assert_eq!(lowered(path), from_macro, "{path}");
    }
}

#[test]
fn generated_monitor_and_lowered_formula_score_traces_alike() {
    let spec = lowered("examples/specs/surveillance_ot1.hstl");
    // A deterministic walk that sweeps the grid row by row.
    let states: Vec<ot1::surveillance::State> = (0..600)
        .map(|t: i64| {
            let (row, col) = (t / 15 % 15, t % 15);
            ot1::surveillance::State { x: if row % 2 == 0 { col } else { 14 - col }, y: row }
        })
        .collect();
    let trace = Trace::from_columns(vec![
        states.iter().map(|s| s.x as f64).collect(),
        states.iter().map(|s| s.y as f64).collect(),
    ])
    .expect("columns of equal length");
    let interpreted = offline::signal(&spec.task, &trace);
    let generated = ot1::surveillance::task::signal(&states);
    assert_eq!(interpreted.len(), generated.len());
    for (t, (a, b)) in interpreted.iter().zip(&generated).enumerate() {
        assert_eq!(a.to_bits(), b.to_bits(), "step {t}: interpreter {a}, generated {b}");
    }
}
