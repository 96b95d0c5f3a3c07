//! Dense time against rtamt 0.4.10 (`StlDenseTimeSpecification`): the 150 cases of
//! `data/rtamt-dense-sample.jsonl` (a copy of the shared oracle), compared as functions on
//! `[t0, t_last]`, times bit for bit. None of these cases meets one of rtamt's known
//! defects (docs/DENSE-TIME-DEVIATIONS.md); the tests of those are in `dense_edges.rs`.

mod dense_common;

use dense_common::{cases, points, rtamt_points};
use hstl_robustness::dense::{DenseFormula, DenseMonitor};

#[test]
fn offline_equals_rtamt_on_every_oracle_case() {
    let cases = cases();
    assert_eq!(cases.len(), 150);
    let mut failures = Vec::new();
    for case in &cases {
        let (t0, t_last) = (case.trace.t0(), case.trace.t_last());
        let df = DenseFormula::new(&case.formula, case.scale).expect("a dense formula");
        let sig = df.signal(&case.trace).expect("a signal");
        let got: Vec<(f64, Option<f64>)> =
            points(&sig, t_last).into_iter().map(|(t, v)| (t, Some(v))).collect();
        let want = rtamt_points(&case.rtamt, t0, t_last);
        let same = got.len() == want.len()
            && got.iter().zip(&want).all(|(g, w)| g.0.to_bits() == w.0.to_bits() && g.1 == w.1);
        if !same {
            failures.push(format!(
                "case {} `{}`:\n  got  {got:?}\n  want {want:?}",
                case.id, case.task
            ));
        }
    }
    assert!(failures.is_empty(), "{} of 150 differ:\n{}", failures.len(), failures.join("\n"));
}

#[test]
fn online_equals_offline_on_every_oracle_case() {
    for case in cases() {
        let df = DenseFormula::new(&case.formula, case.scale).expect("a dense formula");
        let want = points(&df.signal(&case.trace).expect("a signal"), case.trace.t_last());
        for batch in [1, 3] {
            let mut m = DenseMonitor::new(&df, case.trace.vars()).expect("a monitor");
            m.set_batch(batch);
            let mut got = Vec::new();
            for (k, &t) in case.trace.times().iter().enumerate() {
                let row: Vec<Option<f64>> =
                    (0..case.trace.vars()).map(|i| Some(case.trace.column(i)[k])).collect();
                got.extend(m.push(t, &row).expect("a push"));
            }
            got.extend(m.finish().expect("the end"));
            assert!(
                dense_common::same_points(&got, &want),
                "case {} `{}` batch {batch}:\n  online  {got:?}\n  offline {want:?}",
                case.id,
                case.task
            );
        }
    }
}
