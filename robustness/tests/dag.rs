//! Formulas whose nodes are shared (a `let` used twice) or nested far deeper than any
//! recursion could go: every evaluator gives the reference's values, in time and memory
//! linear in the formula's size.

mod common;

use common::{check_all, trace_xy};
use hstl_robustness::{
    Bound, CmpOp, Formula, FormulaBuilder, Interval, NodeId, OnlineMonitor, Trace, offline,
    reference,
};

fn window(a: usize, b: usize) -> Interval {
    Interval { start: a, end: Bound::Inclusive(b) }
}

/// `x > c` in `b`.
fn x_gt(b: &mut FormulaBuilder, c: f64) -> NodeId {
    let (x, c) = (b.var(0), b.constant(c));
    b.cmp(x, CmpOp::Gt, c)
}

fn walk(n: usize) -> Trace {
    let x: Vec<f64> = (0..n).map(|t| ((t * 7919) % 23) as f64 - 5.0).collect();
    let y: Vec<f64> = (0..n).map(|t| ((t * 104_729) % 17) as f64).collect();
    trace_xy(&x, &y)
}

/// `L0 = x > 3`, `Lk = L(k-1) && L(k-1)`: a tree of `2^(k-1)` atoms, `k + 3` nodes.
#[test]
fn a_doubling_chain_is_linear() {
    let mut b = FormulaBuilder::new();
    let mut l = x_gt(&mut b, 3.0);
    for _ in 1..30 {
        l = b.and(vec![l, l]);
    }
    let root = b.always(window(0, 5), l);
    let f = b.build(root);
    assert_eq!(f.len(), 33);
    let plain = {
        let mut b = FormulaBuilder::new();
        let a = x_gt(&mut b, 3.0);
        let r = b.always(window(0, 5), a);
        b.build(r)
    };
    let trace = walk(60);
    check_all(&f, &trace, &reference::signal(&plain, &trace));
}

/// A temporal doubling chain: each level reads the one below twice, through different
/// operators, so the DAG shares every level.
#[test]
fn a_temporal_doubling_chain_is_linear() {
    let mut b = FormulaBuilder::new();
    let mut l = x_gt(&mut b, 0.0);
    for k in 0..24 {
        let e = b.eventually(window(0, 1), l);
        let a = b.always(window(k % 2, 1), l);
        l = b.or(vec![e, a]);
    }
    let f = b.build(l);
    assert_eq!(f.len(), 3 + 3 * 24);
    let trace = walk(80);
    let want = reference::signal(&f, &trace);
    check_all(&f, &trace, &want);
}

/// A chain of 100,000 operators (`!` and `||` alternating, then windows): nothing
/// recurses, and memory holds a few signals, not one per node.
#[test]
fn a_deep_chain_runs_without_recursion() {
    let mut b = FormulaBuilder::new();
    let atom = x_gt(&mut b, 2.0);
    let mut f = b.always(window(0, 1), atom);
    for k in 0..50_000 {
        let g = b.not(f);
        f = if k % 1000 == 999 { b.eventually(window(0, 0), g) } else { b.or(vec![g, atom]) };
    }
    let f = b.build(f);
    let trace = walk(40);
    let want = reference::signal(&f, &trace);
    check_all(&f, &trace, &want);
    // Its state part alone, 100,000 nodes deep.
    let mut b = FormulaBuilder::new();
    let atom = x_gt(&mut b, 2.0);
    let mut g = atom;
    for _ in 0..50_000 {
        let n = b.not(g);
        g = b.and(vec![n, atom]);
    }
    let g = b.build(g);
    assert!(g.is_state_formula());
    check_all(&g, &trace, &reference::signal(&g, &trace));
}

/// Nodes shared between a bounded group and unbounded readers, on a trace long enough to
/// be cut in pieces: the pieces give the whole trace's values.
#[test]
fn shared_nodes_across_groups_and_pieces() {
    let mut b = FormulaBuilder::new();
    let (x3, y9) = (x_gt(&mut b, 3.0), {
        let (y, c) = (b.var(1), b.constant(9.0));
        b.cmp(y, CmpOp::Lt, c)
    });
    let region = b.and(vec![x3, y9]);
    let ev = b.eventually(window(0, 40), region);
    let al = b.always(window(2, 7), region);
    let body = b.and(vec![ev, al, region]);
    let unbounded = b.always(Interval::ALL, body);
    let reach = b.eventually(Interval { start: 3, end: Bound::Unbounded }, ev);
    let until = b.until(window(1, 30), al, ev);
    let root = b.or(vec![unbounded, reach, until, body]);
    let f = b.build(root);
    let trace = walk(40_000);
    let got = offline::signal(&f, &trace);
    // The same formula as separate trees (no node shared between the parts).
    let parts: Vec<Formula> =
        [unbounded, reach, until, body].iter().map(|&id| b.build(id)).collect();
    let signals: Vec<Vec<f64>> = parts.iter().map(|p| offline::signal(p, &trace)).collect();
    for (t, v) in got.iter().enumerate() {
        let want = signals.iter().map(|s| s[t]).fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(*v, want, "step {t}");
    }
    // The bounded part against the reference, near the pieces' seams.
    let bounded = b.build(body);
    let sig = offline::signal(&bounded, &trace);
    for t in [0, 8191, 8192, 8193, 16_383, 16_384, 39_950, 39_999] {
        assert_eq!(sig[t], reference::robustness(&bounded, &trace, t), "step {t}");
    }
    let mut online = OnlineMonitor::new(&bounded, 2);
    let mut row = Vec::new();
    let mut values = Vec::new();
    for t in 0..trace.len() {
        trace.row_into(t, &mut row);
        values.extend(online.push(&row).expect("two columns").map(|v| v.value));
    }
    values.extend(online.finish().iter().map(|v| v.value));
    assert_eq!(values, sig);
}
