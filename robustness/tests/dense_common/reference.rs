//! A reference dense-time evaluator that follows DENSE-TIME.md's table literally.
//!
//! Each node's signal is its value at every candidate time where it may change (the
//! operands' change points shifted by the interval's bounds), each value computed straight
//! from the table's row: a max or min over the operand pieces that meet the window, and for
//! `until` / `since` a max over the candidate witnesses `t'` of
//! `min(g(t'), min of f on [t, t'])`. Quadratic or worse; only for tests. On stamps and
//! bounds with few binary digits (multiples of 1/8, say) no operation rounds, so it gives
//! exactly the table's values.

use hstl_robustness::dense::{DenseSignal, DenseTrace, TimeScale};
use hstl_robustness::{Bound, Formula, Node};

type Sig = Vec<(f64, f64)>;

/// The value of `s` at `t` (`t >= t0`).
fn at(s: &Sig, t: f64) -> f64 {
    let k = s.partition_point(|p| p.0 <= t);
    s[k - 1].1
}

/// The values of the pieces of `s` that meet the closed interval `[lo, hi]`.
fn meeting(s: &Sig, lo: f64, hi: f64) -> impl Iterator<Item = f64> + '_ {
    s.iter().enumerate().filter_map(move |(k, &(t, v))| {
        let end = s.get(k + 1).map_or(f64::INFINITY, |p| p.0);
        (t <= hi && end > lo).then_some(v)
    })
}

fn fold_max(it: impl Iterator<Item = f64>) -> f64 {
    it.fold(f64::NEG_INFINITY, |a, b| if b > a { b } else { a })
}

fn fold_min(it: impl Iterator<Item = f64>) -> f64 {
    it.fold(f64::INFINITY, |a, b| if b < a { b } else { a })
}

/// The signal with value `value(c)` at each candidate `c >= t0`, merged.
fn tabulate(t0: f64, mut cands: Vec<f64>, value: impl Fn(f64) -> f64) -> Sig {
    cands.push(t0);
    cands.retain(|&c| c >= t0 && c.is_finite());
    cands.sort_by(f64::total_cmp);
    cands.dedup();
    let mut out: Sig = Vec::new();
    for c in cands {
        let v = value(c);
        if out.last().map(|p| p.1) != Some(v) {
            out.push((c, v));
        }
    }
    out
}

/// `f`'s dense-time signal on `trace`, bounds read through `scale`.
pub fn signal(f: &Formula, scale: TimeScale, trace: &DenseTrace) -> DenseSignal {
    let t0 = trace.t0();
    let times = trace.times();
    let nodes = f.nodes();
    let mut exprs: Vec<Vec<f64>> = Vec::with_capacity(nodes.len());
    let mut sigs: Vec<Sig> = Vec::with_capacity(nodes.len());
    for node in nodes {
        let e = |i: usize| &exprs[i];
        let row_expr: Option<Vec<f64>> = match node {
            Node::Const(c) => Some(vec![*c; times.len()]),
            Node::Var(j) => Some(trace.column(*j).to_vec()),
            Node::Neg(a) => Some(e(a.index()).iter().map(|x| -x).collect()),
            Node::Abs(a) => Some(e(a.index()).iter().map(|x| x.abs()).collect()),
            Node::Sqrt(a) => Some(e(a.index()).iter().map(|x| x.sqrt()).collect()),
            Node::Add(a, b) => {
                Some(e(a.index()).iter().zip(e(b.index())).map(|(x, y)| x + y).collect())
            }
            Node::Sub(a, b) => {
                Some(e(a.index()).iter().zip(e(b.index())).map(|(x, y)| x - y).collect())
            }
            Node::Mul(a, b) => {
                Some(e(a.index()).iter().zip(e(b.index())).map(|(x, y)| x * y).collect())
            }
            Node::Div(a, b) => {
                Some(e(a.index()).iter().zip(e(b.index())).map(|(x, y)| x / y).collect())
            }
            _ => None,
        };
        if let Some(v) = row_expr {
            exprs.push(v);
            sigs.push(Vec::new());
            continue;
        }
        let s = |i: usize| &sigs[i];
        let cps = |ids: &[usize]| -> Vec<f64> {
            ids.iter().flat_map(|&i| sigs[i].iter().map(|p| p.0)).collect()
        };
        let bounds = |i: &hstl_robustness::Interval| {
            let a = scale.bound(i.start);
            let b = match i.end {
                Bound::Inclusive(b) => scale.bound(b),
                Bound::Unbounded => f64::INFINITY,
                Bound::Exclusive(_) => panic!("no half-open intervals in dense time"),
            };
            (a, b)
        };
        let sig: Sig =
            match node {
                Node::True => vec![(t0, f64::INFINITY)],
                Node::False => vec![(t0, f64::NEG_INFINITY)],
                Node::Cmp { lhs, op, rhs } => {
                    let (l, r) = (&exprs[lhs.index()], &exprs[rhs.index()]);
                    tabulate(t0, times.to_vec(), |c| {
                        let k = times.partition_point(|&t| t <= c) - 1;
                        op.robustness(l[k], r[k])
                    })
                }
                Node::Not(a) => tabulate(t0, cps(&[a.index()]), |c| -at(s(a.index()), c)),
                Node::And(gs) | Node::Or(gs) => {
                    let ids: Vec<usize> = gs.iter().map(|g| g.index()).collect();
                    let and = matches!(node, Node::And(_));
                    tabulate(t0, cps(&ids), |c| {
                        let vals = ids.iter().map(|&i| at(s(i), c));
                        if and { fold_min(vals) } else { fold_max(vals) }
                    })
                }
                Node::Implies(a, b) => tabulate(t0, cps(&[a.index(), b.index()]), |c| {
                    fold_max([-at(s(a.index()), c), at(s(b.index()), c)].into_iter())
                }),
                Node::Eventually(i, g) | Node::Always(i, g) => {
                    let (a, b) = bounds(i);
                    let g = s(g.index());
                    let cands = g.iter().flat_map(|p| [p.0 - a, p.0 - b]).collect();
                    let max = matches!(node, Node::Eventually(..));
                    tabulate(t0, cands, |c| {
                        let vals = meeting(g, c + a, c + b);
                        if max { fold_max(vals) } else { fold_min(vals) }
                    })
                }
                Node::Once(i, g) | Node::Historically(i, g) => {
                    let (a, b) = bounds(i);
                    let g = s(g.index());
                    let cands = g.iter().flat_map(|p| [p.0 + a, p.0 + b]).collect();
                    let max = matches!(node, Node::Once(..));
                    tabulate(t0, cands, |c| {
                        let (lo, hi) = ((c - b).max(t0), c - a);
                        let vals = meeting(g, lo, hi).filter(|_| hi >= t0);
                        if max { fold_max(vals) } else { fold_min(vals) }
                    })
                }
                Node::Until(i, f, g) => {
                    let (a, b) = bounds(i);
                    let (fs, gs) = (s(f.index()), s(g.index()));
                    let pts = cps(&[f.index(), g.index()]);
                    let cands = pts.iter().flat_map(|&p| [p, p - a, p - b]).collect();
                    tabulate(t0, cands, |c| {
                        let (lo, hi) = (c + a, c + b);
                        let witnesses = std::iter::once(lo)
                            .chain(pts.iter().copied().filter(|&p| lo < p && p <= hi));
                        fold_max(witnesses.map(|w| {
                            fold_min([at(gs, w), fold_min(meeting(fs, c, w))].into_iter())
                        }))
                    })
                }
                Node::Since(i, f, g) => {
                    let (a, b) = bounds(i);
                    let (fs, gs) = (s(f.index()), s(g.index()));
                    let pts = cps(&[f.index(), g.index()]);
                    let cands = pts.iter().flat_map(|&p| [p, p + a, p + b]).collect();
                    tabulate(t0, cands, |c| {
                        let (lo, hi) = ((c - b).max(t0), c - a);
                        if hi < t0 {
                            return f64::NEG_INFINITY;
                        }
                        let witnesses = std::iter::once(lo)
                            .chain(pts.iter().copied().filter(|&p| lo < p && p <= hi));
                        fold_max(witnesses.map(|w| {
                            fold_min([at(gs, w), fold_min(meeting(fs, w, c))].into_iter())
                        }))
                    })
                }
                Node::Prev(_) | Node::Next(_) => panic!("no prev or next in dense time"),
                _ => unreachable!("expressions are handled above"),
            };
        exprs.push(Vec::new());
        sigs.push(sig);
    }
    DenseSignal::from_points(&sigs[f.root().index()]).expect("a signal")
}
