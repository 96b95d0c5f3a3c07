//! Random formulas with every operator (past-time ones included) and interval form, on
//! random traces with ±inf and NaN samples: every evaluator agrees with the reference, and
//! `Display` parses back.

mod common;

use common::{check_all, parse};
use hstl_robustness::{Bound, CmpOp, Expr, Formula, Interval, Node, Trace, complete, reference};
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
            (interval(), f.clone()).prop_map(|(i, g)| Formula::always(i, g)),
            (interval(), f.clone()).prop_map(|(i, g)| Formula::once(i, g)),
            (interval(), f.clone()).prop_map(|(i, g)| Formula::historically(i, g)),
            (interval(), f.clone(), f.clone()).prop_map(|(i, g, h)| Formula::since(i, g, h)),
            f.clone().prop_map(Formula::prev),
            f.prop_map(Formula::next),
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

/// Complete windows read literally: `(complete steps, rho(f, t))` where every operator's
/// window is cut at its operands' complete prefix (the table in `complete`'s docs).
fn complete_reference(f: &Formula, trace: &Trace) -> (usize, Vec<f64>) {
    complete_at(f, f.root().index(), trace)
}

fn complete_at(f: &Formula, id: usize, trace: &Trace) -> (usize, Vec<f64>) {
    let n = trace.len();
    let node = &f.nodes()[id];
    let sub = |k: usize| {
        let (c, v) = complete_at(f, k, trace);
        v[..c].to_vec()
    };
    let fold = |vals: &mut dyn Iterator<Item = f64>, min: bool| {
        vals.fold(if min { f64::INFINITY } else { f64::NEG_INFINITY }, |a, b| {
            if min { a.min(b) } else { a.max(b) }
        })
    };
    let own = |i: &Interval, m: usize| match i.end {
        Bound::Unbounded => m.saturating_sub(i.start),
        _ => m.saturating_sub(i.last_offset().unwrap_or(0)),
    };
    match node {
        Node::Not(g) => {
            let g = sub(g.index());
            (g.len(), g.iter().map(|v| -v).collect())
        }
        Node::And(gs) | Node::Or(gs) => {
            let kids: Vec<Vec<f64>> = gs.iter().map(|g| sub(g.index())).collect();
            let m = kids.iter().map(Vec::len).min().unwrap_or(n);
            let min = matches!(node, Node::And(_));
            (m, (0..m).map(|t| fold(&mut kids.iter().map(|k| k[t]), min)).collect())
        }
        Node::Implies(g, h) => {
            let (g, h) = (sub(g.index()), sub(h.index()));
            let m = g.len().min(h.len());
            (m, (0..m).map(|t| (-g[t]).max(h[t])).collect())
        }
        Node::Always(i, g) | Node::Eventually(i, g) => {
            let g = sub(g.index());
            let m = g.len();
            let min = matches!(node, Node::Always(..));
            let v = (0..m).map(|t| fold(&mut i.window(t, m).map(|u| g[u]), min)).collect();
            (own(i, m), v)
        }
        Node::Until(i, g, h) => {
            let (g, h) = (sub(g.index()), sub(h.index()));
            let m = g.len().min(h.len());
            let v = (0..m)
                .map(|t| {
                    let mut candidates =
                        i.window(t, m).map(|u| h[u].min(fold(&mut (t..u).map(|w| g[w]), true)));
                    fold(&mut candidates, false)
                })
                .collect();
            (own(i, m), v)
        }
        Node::Once(i, g) | Node::Historically(i, g) => {
            let g = sub(g.index());
            let m = g.len();
            let min = matches!(node, Node::Historically(..));
            (m, (0..m).map(|t| fold(&mut i.past_window(t).map(|u| g[u]), min)).collect())
        }
        Node::Since(i, g, h) => {
            let (g, h) = (sub(g.index()), sub(h.index()));
            let m = g.len().min(h.len());
            let v = (0..m)
                .map(|t| {
                    let mut candidates = i
                        .past_window(t)
                        .map(|u| h[u].min(fold(&mut (u + 1..=t).map(|w| g[w]), true)));
                    fold(&mut candidates, false)
                })
                .collect();
            (m, v)
        }
        Node::Prev(g) => {
            let g = sub(g.index());
            let v = (0..g.len())
                .map(|t| if t == 0 { f64::INFINITY } else { f64::INFINITY.min(g[t - 1]) });
            (g.len(), v.collect())
        }
        Node::Next(g) => {
            let g = sub(g.index());
            let m = g.len();
            let v =
                (0..m).map(|t| if t + 1 < m { f64::INFINITY.min(g[t + 1]) } else { f64::INFINITY });
            (m.saturating_sub(1), v.collect())
        }
        Node::True => (n, vec![f64::INFINITY; n]),
        Node::False => (n, vec![f64::NEG_INFINITY; n]),
        Node::Cmp { lhs, op, rhs } => {
            let (lhs, rhs) = (f.expr_at(*lhs), f.expr_at(*rhs));
            let mut row = Vec::new();
            let v = (0..n)
                .map(|t| {
                    trace.row_into(t, &mut row);
                    op.robustness(lhs.eval(&row), rhs.eval(&row))
                })
                .collect();
            (n, v)
        }
        _ => unreachable!("an expression node is no formula's operand"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1000, ..ProptestConfig::default() })]

    /// The complete-window evaluator against its literal reading, and against the clipped
    /// signal wherever no unbounded operator cuts a prefix.
    #[test]
    fn complete_windows_agree_with_their_reference(f in formula(0), t in trace(2, false)) {
        let (c, want) = complete_reference(&f, &t);
        prop_assert_eq!(complete::complete_len(&f, t.len()), c);
        let got = complete::signal(&f, &t);
        common::assert_same("complete", &got, &want[..c]);
        if let Some(h) = f.horizon() {
            prop_assert_eq!(c, t.len().saturating_sub(h));
            common::assert_same("bounded", &got, &reference::signal(&f, &t)[..c]);
        }
    }
}

/// The example: a perfect A -> B -> C cycle keeps the persistent task over every
/// complete window, though clipped windows make it negative at the trace's end.
#[test]
fn a_perfect_cycle_keeps_the_persistent_task_over_complete_windows() {
    let f = parse("always[0..] (eventually[0..=4] x > 0 && eventually[0..=4] y > 0)");
    // x holds every 3 steps, y every 3 steps shifted by one; the trace ends on neither.
    let x: Vec<f64> = (0..31).map(|t| if t % 3 == 0 && t < 30 { 1.0 } else { -1.0 }).collect();
    let y: Vec<f64> = (0..31).map(|t| if t % 3 == 1 && t < 29 { 1.0 } else { -1.0 }).collect();
    let t = common::trace_xy(&x, &y);
    assert!(reference::robustness(&f, &t, 0) < 0.0, "clipped windows fail at the end");
    assert_eq!(complete::complete_len(&f, 31), 27);
    assert_eq!(complete::robustness(&f, &t), Some(1.0));
    // Too short a trace leaves step 0 undetermined.
    assert_eq!(complete::robustness(&f, &common::trace_xy(&x[..4], &y[..4])), None);
}

proptest! {
    /// An expression over a whole trace (in chunks of 512 steps) is its value row by row,
    /// bit for bit; a variable the trace lacks is NaN in both.
    #[test]
    fn expressions_over_a_trace_agree_with_row_by_row(
        e in expr(),
        vars in 1usize..=2,
        t in trace_up_to(2, true, 1300),
    ) {
        let cols: Vec<Vec<f64>> = (0..vars).map(|i| t.column(i).to_vec()).collect();
        let t = Trace::from_columns(cols).expect("equal lengths");
        let got = e.eval_trace(&t);
        prop_assert_eq!(got.len(), t.len());
        let mut row = Vec::new();
        for (step, v) in got.iter().enumerate() {
            t.row_into(step, &mut row);
            let want = e.eval(&row);
            prop_assert!(v.to_bits() == want.to_bits(), "step {}: {} against {}", step, v, want);
        }
    }
}
