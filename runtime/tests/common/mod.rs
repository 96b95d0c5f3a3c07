//! The paper's case study, built by hand (no hstl-lang): shared by the tests, the
//! benchmark and the sweep example.
#![allow(dead_code)]

use hstl_runtime::robustness::{Bound, CmpOp, Expr, Formula, Interval};
use hstl_runtime::{
    CombinedOption, LearnParams, PrimitiveOption, Region, StateVar, TaskSpec, Terminate,
};

/// `var op c` for the case study's integer variables (`x` is 0, `y` is 1).
pub fn cmp(var: usize, op: CmpOp, c: f64) -> Formula {
    Formula::cmp(Expr::var(var), op, Expr::constant(c))
}

/// `lo < var < hi` for `x` (0) and `y` (1), as the conjunction of its four comparisons.
pub fn rect(x: (f64, f64), y: (f64, f64)) -> Formula {
    Formula::and(vec![
        cmp(0, CmpOp::Gt, x.0),
        cmp(0, CmpOp::Lt, x.1),
        cmp(1, CmpOp::Gt, y.0),
        cmp(1, CmpOp::Lt, y.1),
    ])
}

/// The regions A, B and C of the paper's layout.
pub fn regions() -> Vec<(&'static str, Formula)> {
    vec![
        ("A", rect((3.0, 9.0), (10.0, 14.0))),
        ("B", rect((1.0, 5.0), (1.0, 5.0))),
        ("C", rect((9.0, 13.0), (1.0, 7.0))),
    ]
}

/// Every non-empty subsequence of `0..n` in order (`sequences`), or every ordering of
/// every non-empty subset (`permutations`), shortest first.
pub fn option_set(n: usize, permutations: bool) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    for size in 1..=n {
        let mut seqs: Vec<Vec<usize>> = Vec::new();
        for mask in 0u32..(1 << n) {
            if mask.count_ones() as usize != size {
                continue;
            }
            let subset: Vec<usize> = (0..n).filter(|i| mask & (1 << i) != 0).collect();
            if permutations {
                permute(&subset, &mut Vec::new(), &mut seqs);
            } else {
                seqs.push(subset);
            }
        }
        seqs.sort();
        out.extend(seqs);
    }
    out
}

fn permute(rest: &[usize], prefix: &mut Vec<usize>, out: &mut Vec<Vec<usize>>) {
    if rest.is_empty() {
        out.push(prefix.clone());
        return;
    }
    for i in 0..rest.len() {
        prefix.push(rest[i]);
        let others: Vec<usize> =
            rest.iter().enumerate().filter(|&(j, _)| j != i).map(|(_, &v)| v).collect();
        permute(&others, prefix, out);
        prefix.pop();
    }
}

/// The case study: `always[0..] (eventually[0..40] A && eventually[0..40] B &&
/// eventually[0..40] C)` on a 15 x 15 grid, with the options set O_T1 (`sequences`) or
/// O_T2 (`permutations`), argmax or entry (`terminate: A`) termination, Table II params.
pub fn case_study(permutations: bool, entry: bool) -> TaskSpec {
    let regions = regions();
    let window = Interval { start: 0, end: Bound::Exclusive(40) };
    let task = Formula::always(
        Interval::ALL,
        Formula::and(regions.iter().map(|(_, f)| Formula::eventually(window, f.clone())).collect()),
    );
    let primitives = regions
        .iter()
        .map(|(name, f)| PrimitiveOption {
            name: name.to_string(),
            reach: f.clone(),
            init: Formula::bool(true),
            terminate: if entry { Terminate::Formula(f.clone()) } else { Terminate::Argmax },
            avoid: None,
        })
        .collect();
    let options = option_set(3, permutations)
        .into_iter()
        .map(|seq| CombinedOption {
            name: seq.iter().map(|&i| regions[i].0).collect(),
            sequence: seq,
        })
        .collect();
    TaskSpec {
        name: "Surveillance".into(),
        state_vars: vec![
            StateVar { name: "x".into(), domain: Some(0..=14) },
            StateVar { name: "y".into(), domain: Some(0..=14) },
        ],
        task,
        primitives,
        options,
        learn: LearnParams::default(),
        regions: regions
            .iter()
            .map(|(name, f)| Region { name: name.to_string(), formula: f.clone(), horizon: 40 })
            .collect(),
    }
}

/// The fourth variant, beyond the paper (LANGUAGE.md, "Persistent tasks beyond the
/// paper"): options `{A, B, C}`, each with `init: !R` and `terminate: R`, `memory: 8`,
/// `reward: window`, options `{gamma: 0.98, alpha: 0.1}`, the rest as in Table II.
pub fn case_study_memory() -> TaskSpec {
    let mut spec = case_study(false, true);
    for p in &mut spec.primitives {
        p.init = Formula::not(p.reach.clone());
    }
    spec.options = spec
        .primitives
        .iter()
        .enumerate()
        .map(|(i, p)| CombinedOption { name: p.name.clone(), sequence: vec![i] })
        .collect();
    spec.name = "SurveillanceMemory".into();
    spec.learn.memory = 8;
    spec.learn.reward = hstl_runtime::RewardKind::Window;
    spec.learn.options.gamma = 0.98;
    spec.learn.options.alpha = 0.1;
    spec
}
