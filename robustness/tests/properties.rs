//! Random formulas with every operator and interval form, on random traces with ±inf and
//! NaN samples: every evaluator agrees with the reference, and `Display` parses back.

mod common;

use common::{check_all, parse};
use hstl_robustness::{Bound, CmpOp, Expr, Formula, Interval, Trace, reference};
use proptest::prelude::*;

fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => (-6i32..=6).prop_map(f64::from),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => (-60i32..=60).prop_map(|v| f64::from(v) / 8.0),
    ]
}

fn trace(vars: usize, nan: bool) -> impl Strategy<Value = Trace> {
    trace_up_to(vars, nan, 30)
}

fn trace_up_to(vars: usize, nan: bool, max_len: usize) -> impl Strategy<Value = Trace> {
    let v =
        if nan { prop_oneof![15 => value(), 1 => Just(f64::NAN)].boxed() } else { value().boxed() };
    (0usize..=max_len).prop_flat_map(move |n| {
        proptest::collection::vec(proptest::collection::vec(v.clone(), n), vars)
            .prop_map(|cols| Trace::from_columns(cols).expect("equal lengths"))
    })
}

fn interval() -> impl Strategy<Value = Interval> {
    let end = prop_oneof![
        1 => Just(Bound::Unbounded),
        2 => (0usize..9).prop_map(Bound::Exclusive),
        2 => (0usize..9).prop_map(Bound::Inclusive),
    ];
    (0usize..5, end).prop_map(|(start, end)| Interval { start, end })
}

fn expr() -> impl Strategy<Value = Expr> {
    let leaf = prop_oneof![
        3 => (0usize..2).prop_map(Expr::var),
        2 => (-4i32..=4).prop_map(|c| Expr::constant(f64::from(c))),
    ];
    leaf.prop_recursive(2, 6, 2, |e| {
        prop_oneof![
            (e.clone(), e.clone()).prop_map(|(a, b)| Expr::add(a, b)),
            (e.clone(), e.clone()).prop_map(|(a, b)| Expr::sub(a, b)),
            (e.clone(), e.clone()).prop_map(|(a, b)| Expr::mul(a, b)),
            (e.clone(), e.clone()).prop_map(|(a, b)| Expr::div(a, b)),
            e.clone().prop_map(Expr::neg),
            e.clone().prop_map(Expr::abs),
            e.prop_map(Expr::sqrt),
        ]
    })
}

fn cmp_op() -> impl Strategy<Value = CmpOp> {
    prop_oneof![Just(CmpOp::Lt), Just(CmpOp::Le), Just(CmpOp::Gt), Just(CmpOp::Ge)]
}

/// Formulas over `x` and `y`; `min_kids` is the least number of `&&`/`||` operands.
fn formula(min_kids: usize) -> impl Strategy<Value = Formula> {
    let simple = (0usize..2, cmp_op(), -4i32..=4)
        .prop_map(|(v, op, c)| Formula::cmp(Expr::var(v), op, Expr::constant(f64::from(c))));
    let general = (expr(), cmp_op(), expr()).prop_map(|(lhs, op, rhs)| Formula::cmp(lhs, op, rhs));
    let leaf = prop_oneof![
        6 => simple,
        2 => general,
        1 => Just(Formula::bool(true)),
        1 => Just(Formula::bool(false)),
    ];
    leaf.prop_recursive(4, 24, 3, move |f| {
        let kids = proptest::collection::vec(f.clone(), min_kids..=3);
        prop_oneof![
            f.clone().prop_map(Formula::not),
            kids.clone().prop_map(Formula::and),
            kids.prop_map(Formula::or),
            (f.clone(), f.clone()).prop_map(|(g, h)| Formula::implies(g, h)),
            (interval(), f.clone()).prop_map(|(i, g)| Formula::always(i, g)),
            (interval(), f.clone()).prop_map(|(i, g)| Formula::eventually(i, g)),
            (interval(), f.clone(), f.clone()).prop_map(|(i, g, h)| Formula::until(i, g, h)),
            (interval(), f).prop_map(|(i, g)| Formula::always(i, g)),
        ]
    })
}

/// A persistent task `always[0..] f`, the shape whose segment reward cuts the horizon.
fn persistent() -> impl Strategy<Value = Formula> {
    formula(0).prop_map(|f| Formula::always(Interval::ALL, f))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 2000, ..ProptestConfig::default() })]

    #[test]
    fn evaluators_agree(f in formula(0), t in trace(2, false)) {
        let want = reference::signal(&f, &t);
        check_all(&f, &t, &want);
    }

    #[test]
    fn evaluators_agree_with_nan(f in formula(0), t in trace(2, true)) {
        let want = reference::signal(&f, &t);
        check_all(&f, &t, &want);
    }

    #[test]
    fn persistent_segment_rewards(f in persistent(), t in trace(2, false)) {
        let want = reference::signal(&f, &t);
        check_all(&f, &t, &want);
    }

    #[test]
    fn display_parses_back(f in formula(2), t in trace(2, false)) {
        let text = f.display_with(&common::VARS).to_string();
        let back = parse(&text);
        prop_assert_eq!(back.display_with(&common::VARS).to_string(), text.clone());
        common::assert_same(&text, &reference::signal(&back, &t), &reference::signal(&f, &t));
    }
}

proptest! {
    // The reference evaluator is cubic in the trace length on nested until: fewer cases.
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// Longer traces: many van Herk blocks per window length.
    #[test]
    fn evaluators_agree_on_long_traces(f in formula(0), t in trace_up_to(2, true, 80)) {
        let want = reference::signal(&f, &t);
        check_all(&f, &t, &want);
    }
}

/// A variable the trace lacks reads as NaN everywhere, never a panic.
#[test]
fn missing_variable_is_nan() {
    let f = Formula::cmp(Expr::var(5), CmpOp::Gt, Expr::constant(0.0));
    let t = common::trace_xy(&[1.0, 2.0], &[3.0, 4.0]);
    check_all(&f, &t, &reference::signal(&f, &t));
    assert!(reference::signal(&f, &t).iter().all(|v| v.is_nan()));
}
