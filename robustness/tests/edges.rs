//! Edge cases per operator, with signals worked out by hand from the semantics table of
//! the language reference; every evaluator must give them.

mod common;

use common::{check_all, parse, trace_xy};
use hstl_robustness::{Formula, Trace, offline, reference};

const INF: f64 = f64::INFINITY;
const NEG: f64 = f64::NEG_INFINITY;

/// A formula, the `x` and `y` columns, and the expected signal.
type Case = (&'static str, &'static [f64], &'static [f64], &'static [f64]);

const CASES: &[Case] = &[
    // Empty windows: `[3..3]` and `[3..=2]` hold no step.
    ("always[3..3] (x > 0)", &[1.0, 2.0], &[0.0, 0.0], &[INF, INF]),
    ("eventually[3..=2] (x > 0)", &[1.0, 2.0], &[0.0, 0.0], &[NEG, NEG]),
    ("(x > 0) until[2..2] (y > 0)", &[1.0, 2.0], &[5.0, 5.0], &[NEG, NEG]),
    // Windows clipped by the end of the trace, and windows starting past it.
    ("always[0..=5] (x > 0)", &[3.0, 1.0, 2.0], &[0.0; 3], &[1.0, 1.0, 2.0]),
    ("always[2..=5] (x > 0)", &[3.0, 1.0, 2.0], &[0.0; 3], &[2.0, INF, INF]),
    ("eventually[1..] (x > 0)", &[3.0, 1.0, 2.0], &[0.0; 3], &[2.0, 2.0, NEG]),
    ("eventually[0..] (x > 0)", &[3.0, 1.0, 2.0], &[0.0; 3], &[3.0, 2.0, 2.0]),
    // `[a..b]` excludes `b`, `[a..=b]` includes it.
    ("always[0..2] (x > 0)", &[5.0, 4.0, 1.0, 6.0], &[0.0; 4], &[4.0, 1.0, 1.0, 6.0]),
    ("always[0..=2] (x > 0)", &[5.0, 4.0, 1.0, 6.0], &[0.0; 4], &[1.0, 1.0, 1.0, 6.0]),
    ("eventually[1..3] (x > 0)", &[5.0, 4.0, 1.0, 6.0], &[0.0; 4], &[4.0, 6.0, 6.0, NEG]),
    ("eventually[1..=3] (x > 0)", &[5.0, 4.0, 1.0, 6.0], &[0.0; 4], &[6.0, 6.0, 6.0, NEG]),
    // Until needs its left operand on [t, t'): at t' = t it is not read at all.
    ("(x > 0) until[0..=0] (y > 0)", &[-9.0, -9.0], &[2.0, 3.0], &[2.0, 3.0]),
    ("(x > 0) until (y > 0)", &[4.0, -1.0, 7.0], &[-5.0, -6.0, 9.0], &[-1.0, -1.0, 9.0]),
    // A lower bound above 0: the left operand must hold from t up to t'.
    (
        "(x > 0) until[2..=3] (y > 0)",
        &[1.0, 5.0, 5.0, 5.0],
        &[0.0, 0.0, 9.0, 9.0],
        &[1.0, 5.0, NEG, NEG],
    ),
    ("(x > 0) until[1..] (y > 0)", &[2.0, -3.0, 4.0], &[0.0, 1.0, 8.0], &[1.0, -3.0, NEG]),
    // true and false, alone and inside temporal operators.
    ("true", &[1.0, 2.0], &[0.0, 0.0], &[INF, INF]),
    ("false", &[1.0, 2.0], &[0.0, 0.0], &[NEG, NEG]),
    ("always[0..] false", &[1.0, 2.0], &[0.0, 0.0], &[NEG, NEG]),
    ("eventually[0..=1] true", &[1.0, 2.0], &[0.0, 0.0], &[INF, INF]),
    ("true until[1..=1] (x > 0)", &[1.0, 2.0], &[0.0, 0.0], &[2.0, NEG]),
    // Infinite samples stay exact: `x > 3` with x = inf is inf.
    ("always[0..=1] (x > 3)", &[INF, INF, NEG], &[0.0; 3], &[INF, NEG, NEG]),
    ("!(x > 3) -> y < 1", &[INF, 0.0], &[NEG, 5.0], &[INF, -3.0]),
    // Past windows are clipped at the start of the trace: empty while `t < a`.
    ("once[2..=5] (x > 0)", &[1.0, 2.0, 3.0, 4.0], &[0.0; 4], &[NEG, NEG, 1.0, 2.0]),
    ("once[0..2] (x > 0)", &[1.0, 5.0, 3.0, 2.0], &[0.0; 4], &[1.0, 5.0, 5.0, 3.0]),
    ("historically[1..] (x > 0)", &[3.0, 1.0, 2.0], &[0.0; 3], &[INF, 3.0, 1.0]),
    ("historically (x > 0)", &[3.0, 1.0, 2.0], &[0.0; 3], &[3.0, 1.0, 1.0]),
    // `prev` and `next` are weak: `+inf` where the step does not exist.
    ("prev (x > 0)", &[3.0, 1.0, 2.0], &[0.0; 3], &[INF, 3.0, 1.0]),
    ("next (x > 0)", &[3.0, 1.0, 2.0], &[0.0; 3], &[1.0, 2.0, INF]),
    ("prev (x > 0)", &[-3.0], &[0.0], &[INF]),
    ("next (x > 0)", &[-3.0], &[0.0], &[INF]),
    // Since needs its left operand after the witness, not at it.
    ("(x > 0) since (y > 0)", &[-9.0, 4.0, 5.0], &[2.0, -1.0, -1.0], &[2.0, 2.0, 2.0]),
    ("(x > 0) since (y > 0)", &[-9.0, 4.0, -5.0], &[2.0, -1.0, -1.0], &[2.0, 2.0, -1.0]),
    (
        "(x > 0) since[1..=2] (y > 0)",
        &[1.0, 5.0, -2.0, 7.0],
        &[9.0, 0.0, 0.0, 0.0],
        &[NEG, 5.0, -2.0, 0.0],
    ),
    // Bounds up to 2^61 - 2 saturate back to step 0, or leave the window empty.
    ("once[0..=2305843009213693950] (x > 0)", &[1.0, 3.0, 2.0], &[0.0; 3], &[1.0, 3.0, 3.0]),
    ("historically[2305843009213693950..] (x > 0)", &[1.0, 3.0], &[0.0; 2], &[INF, INF]),
    ("(x > 0) since[2305843009213693950..] (y > 0)", &[1.0, 3.0], &[0.0; 2], &[NEG, NEG]),
];

#[test]
fn hand_worked_signals() {
    for (src, x, y, want) in CASES {
        check_all(&parse(src), &trace_xy(x, y), want);
    }
}

/// On the empty trace the signal is empty and step 0 sees empty windows everywhere.
#[test]
fn empty_trace() {
    let empty = Trace::new(2);
    let cases: &[(&str, f64)] = &[
        ("always[0..=3] (x > 0)", INF),
        ("eventually (x > 0)", NEG),
        ("(x > 0) until (y > 0)", NEG),
        ("true", INF),
        ("!always[0..] (x > 0)", NEG),
        ("always[0..] (x > 0) && eventually (y > 1)", NEG),
    ];
    for (src, want) in cases {
        let f = parse(src);
        check_all(&f, &empty, &[]);
        assert_eq!(offline::robustness(&f, &empty), *want, "{src}");
        assert_eq!(reference::robustness(&f, &empty, 0), *want, "{src}");
    }
    // An atom at a step the trace does not have is NaN in every evaluator.
    assert!(offline::robustness(&parse("x > 0"), &empty).is_nan());
}

/// Step 0 of a bounded formula reads only the horizon: the samples after it change nothing.
#[test]
fn step_zero_reads_the_horizon_only() {
    let f: Formula = parse("always[0..=3] eventually[1..=2] (x > 2)");
    let h = f.horizon().expect("bounded");
    let x: Vec<f64> = (0..50).map(|t| f64::from(t % 7)).collect();
    let mut poisoned = x.clone();
    poisoned[h + 1..].fill(f64::NAN);
    let t = trace_xy(&x, &x);
    let p = trace_xy(&poisoned, &poisoned);
    assert_eq!(offline::robustness(&f, &p), reference::robustness(&f, &t, 0));
}

/// Bounds near `usize::MAX` behave as very long windows: no overflow, no panic.
#[test]
fn huge_bounds() {
    let x = [3.0, -1.0, 4.0, 1.0, -5.0];
    let t = trace_xy(&x, &x);
    let m = usize::MAX;
    for src in [
        format!("always[0..={m}] (x > 0)"),
        format!("eventually[2..={m}] (x > 0)"),
        format!("(y > -2) until[1..={m}] (x > 3)"),
        format!("(y > -2) until[{m}..={m}] (x > 3)"),
        format!("always[{m}..] (x > 0)"),
        format!("always[0..{m}] (x > 0) && eventually[1..={}] (y < 0)", m - 1),
    ] {
        let f = parse(&src);
        check_all(&f, &t, &reference::signal(&f, &t));
    }
}

#[test]
fn borrowed_slices_give_the_trace_values_or_a_length_error() {
    let f = parse("always[0..=1] (x > 1) || y > 3");
    let (x, y) = ([1.0, 2.0, 3.0, 0.5], [4.0, 0.0, 0.0, 9.0]);
    let trace = trace_xy(&x, &y);
    let mut ev = hstl_robustness::Evaluator::new();
    assert_eq!(offline::signal_of_slices(&f, &[&x, &y]).unwrap(), offline::signal(&f, &trace));
    assert_eq!(ev.signal_of_slices(&f, &[&x, &y]).unwrap(), &offline::signal(&f, &trace)[..]);
    assert_eq!(ev.robustness_of_slices(&f, &[&x, &y]).unwrap(), offline::robustness(&f, &trace));
    let ragged = hstl_robustness::TraceError::Ragged { column: 1, expected: 4, found: 2 };
    assert_eq!(offline::signal_of_slices(&f, &[&x, &y[..2]]).unwrap_err(), ragged);
    assert_eq!(ev.robustness_of_slices(&f, &[&x, &y[..2]]).unwrap_err(), ragged);
}
