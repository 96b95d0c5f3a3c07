//! Monitors compiled through the macro agree exactly with the runtime's offline evaluator
//! and the reference evaluator, on random traces, for formulas covering every operator
//! and interval form. The formulas are also lowered here independently, from the checked
//! spec, to hold the generated `formula()` data against.
#![deny(warnings)]

use hstl::lang::{
    Bound as LBound, CExpr, CExprKind, CFormula, CFormulaKind, CheckedSpec, CmpOp as LCmp,
};
use hstl::robustness::{Bound, CmpOp, Expr, Formula, Interval, Trace, offline, reference};
use hstl_macros::hstl;
use rand::RngExt;

hstl! { include "tests/specs/differential.hstl" }

type Monitor = (fn() -> Formula, fn(&[diff::State]) -> Vec<f64>, fn(&[diff::State]) -> f64);

macro_rules! monitors {
    ($($name:ident),* $(,)?) => {
        vec![$((stringify!($name), monitor(diff::lets::$name::formula, diff::lets::$name::signal, diff::lets::$name::robustness))),*]
    };
}

fn monitor(
    formula: fn() -> Formula,
    signal: fn(&[diff::State]) -> Vec<f64>,
    robustness: fn(&[diff::State]) -> f64,
) -> Monitor {
    (formula, signal, robustness)
}

fn all_monitors() -> Vec<(&'static str, Monitor)> {
    let mut m = monitors![
        f0, f1, f2, f3, f4, f5, f6, f7, f8, f9, f10, f11, f12, f13, f14, f15, f16, f17, f18, f19,
        f20, f21, f22, f23, f24, f25, f26, f27, f28, f29, f30, f31, f32, f33, f34, f35, f36, f37,
        f38, f39, f40, f41, f42, f43, f44, f45, f46, f47, f48, f49, f50, f51, f52, f53, f54, f55,
        f56, f57, f58, f59, f60, f61, f62, f63, f64, f65, f66, f67, f68, f69, f70, f71,
    ];
    m.push(("task", monitor(diff::task::formula, diff::task::signal, diff::task::robustness)));
    m
}

fn random_trace(rng: &mut hstl::runtime::Rng, len: usize) -> Vec<diff::State> {
    (0..len)
        .map(|_| diff::State {
            x: rng.random_range(-1.5..1.5),
            y: rng.random_range(-1.0..2.0),
            k: rng.random_range(0..=10),
        })
        .collect()
}

fn to_trace(states: &[diff::State]) -> Trace {
    let mut t = Trace::new(diff::State::VARS);
    for s in states {
        t.push(&s.values()).expect("rows have VARS values");
    }
    t
}

fn same(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

fn same_signal(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| same(*x, *y))
}

fn lower_expr(e: &CExpr) -> Expr {
    let b = |a: &CExpr| lower_expr(a);
    match &e.kind {
        CExprKind::Const(c) => Expr::constant(*c),
        CExprKind::Var(i) => Expr::var(*i),
        CExprKind::Neg(a) => Expr::neg(b(a)),
        CExprKind::Add(x, y) => Expr::add(b(x), b(y)),
        CExprKind::Sub(x, y) => Expr::sub(b(x), b(y)),
        CExprKind::Mul(x, y) => Expr::mul(b(x), b(y)),
        CExprKind::Div(x, y) => Expr::div(b(x), b(y)),
        CExprKind::Abs(a) => Expr::abs(b(a)),
        CExprKind::Sqrt(a) => Expr::sqrt(b(a)),
        CExprKind::Invalid => panic!("the differential spec checks"),
    }
}

fn lower(spec: &CheckedSpec, f: &CFormula) -> Formula {
    let b = |g: &CFormula| lower(spec, g);
    let iv = |i: &hstl::lang::Interval| Interval {
        start: i.start as usize,
        end: match i.end {
            LBound::Unbounded => Bound::Unbounded,
            LBound::Exclusive(e) => Bound::Exclusive(e as usize),
            LBound::Inclusive(e) => Bound::Inclusive(e as usize),
        },
    };
    match &f.kind {
        CFormulaKind::True => Formula::bool(true),
        CFormulaKind::False => Formula::bool(false),
        CFormulaKind::Let(i) => lower(spec, &spec.lets[*i].formula),
        CFormulaKind::Cmp(op, l, r) => Formula::cmp(
            lower_expr(l),
            match op {
                LCmp::Lt => CmpOp::Lt,
                LCmp::Le => CmpOp::Le,
                LCmp::Gt => CmpOp::Gt,
                LCmp::Ge => CmpOp::Ge,
            },
            lower_expr(r),
        ),
        CFormulaKind::Not(a) => Formula::not(b(a)),
        CFormulaKind::And(v) => Formula::and(v.iter().map(|g| lower(spec, g)).collect()),
        CFormulaKind::Or(v) => Formula::or(v.iter().map(|g| lower(spec, g)).collect()),
        CFormulaKind::Implies(x, y) => Formula::implies(b(x), b(y)),
        CFormulaKind::Always(i, a) => Formula::always(iv(i), b(a)),
        CFormulaKind::Eventually(i, a) => Formula::eventually(iv(i), b(a)),
        CFormulaKind::Until(i, x, y) => Formula::until(iv(i), b(x), b(y)),
        CFormulaKind::Once(i, a) => Formula::once(iv(i), b(a)),
        CFormulaKind::Historically(i, a) => Formula::historically(iv(i), b(a)),
        CFormulaKind::Since(i, x, y) => Formula::since(iv(i), b(x), b(y)),
        CFormulaKind::Prev(a) => Formula::prev(b(a)),
        CFormulaKind::Next(a) => Formula::next(b(a)),
        CFormulaKind::Invalid => panic!("the differential spec checks"),
    }
}

#[test]
fn generated_formulas_are_the_checked_formulas() {
    let checked = hstl::lang::check(include_str!("specs/differential.hstl"));
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics);
    let spec = &checked.specs[0];
    let monitors = all_monitors();
    assert_eq!(monitors.len(), spec.lets.len() + 1, "every let has a monitor under test");
    for (name, (formula, _, _)) in &monitors {
        let source = if *name == "task" {
            &spec.task.as_ref().expect("the spec has a task").formula
        } else {
            let i: usize = name[1..].parse().expect("lets are named F<n>");
            assert_eq!(spec.lets[i].name, name.to_uppercase());
            &spec.lets[i].formula
        };
        assert_eq!(formula(), lower(spec, source), "{name}");
    }
}

#[test]
fn generated_monitors_agree_with_both_evaluators() {
    let mut rng = hstl::runtime::seeded_rng(0x5eed);
    let monitors = all_monitors();
    let mut traces: Vec<Vec<diff::State>> = (0..12).map(|i| random_trace(&mut rng, i)).collect();
    traces.extend((0..8).map(|_| {
        let len = rng.random_range(12..60);
        random_trace(&mut rng, len)
    }));
    for (name, (formula, signal, robustness)) in &monitors {
        let f = formula();
        for states in &traces {
            let trace = to_trace(states);
            let got = signal(states);
            let want = reference::signal(&f, &trace);
            assert!(
                same_signal(&got, &want),
                "{name} on {} steps:\n{got:?}\n{want:?}",
                states.len()
            );
            let fast = offline::signal(&f, &trace);
            assert!(
                same_signal(&got, &fast),
                "{name} vs offline on {} steps:\n{got:?}\n{fast:?}",
                states.len()
            );
            let r0 = reference::robustness(&f, &trace, 0);
            assert!(same(robustness(states), r0), "{name} at step 0 on {} steps", states.len());
        }
    }
}

/// Traces long enough that bounded formulas are evaluated piece by piece (pieces of at
/// least 8192 steps, on traces over twice that), against the offline evaluator alone (the
/// reference evaluator takes quadratic time on unbounded windows).
#[test]
fn generated_monitors_agree_with_the_offline_evaluator_on_long_traces() {
    let mut rng = hstl::runtime::seeded_rng(0x10_2016);
    let monitors = all_monitors();
    let traces: Vec<Vec<diff::State>> =
        [16_385, 20_000, 50_003].iter().map(|&n| random_trace(&mut rng, n)).collect();
    for states in &traces {
        let trace = to_trace(states);
        for (name, (formula, signal, robustness)) in &monitors {
            let f = formula();
            let got = signal(states);
            let fast = offline::signal(&f, &trace);
            assert!(
                same_signal(&got, &fast),
                "{name} vs offline on {} steps: first difference at step {:?}",
                states.len(),
                got.iter().zip(&fast).position(|(a, b)| !same(*a, *b))
            );
            assert!(
                same(robustness(states), offline::robustness(&f, &trace)),
                "{name} at step 0 on {} steps",
                states.len()
            );
        }
    }
}
