//! Shared helpers of the dense-time tests: reading the rtamt oracle's cases, and a
//! reference evaluator that follows DENSE-TIME.md's table literally.
#![allow(dead_code)]

pub mod reference;

use hstl_robustness::dense::{DenseSignal, DenseTrace, DenseTraceBuilder, TimeScale};
use hstl_robustness::{Bound, CmpOp, Expr, Formula, Interval};
use serde_json::Value;

/// One line of `rtamt-dense-sample.jsonl`.
pub struct Case {
    pub id: u64,
    pub task: String,
    pub trace: DenseTrace,
    pub formula: Formula,
    pub scale: TimeScale,
    /// rtamt's output list `[[t, v], ...]`, numbers read with `str::parse` (exact).
    pub rtamt: Vec<(f64, f64)>,
    pub vars: Vec<String>,
}

/// A number as the oracle writes it: a JSON number or `"inf"` / `"-inf"`.
fn number(text: &str) -> f64 {
    match text.trim().trim_matches('"') {
        "inf" => f64::INFINITY,
        "-inf" => f64::NEG_INFINITY,
        t => t.parse().unwrap_or_else(|_| panic!("not a number: {t}")),
    }
}

/// The `[[t, v], ...]` list of field `field` read from the raw JSON line, so that every
/// number goes through `str::parse::<f64>` (correctly rounded) rather than serde_json.
fn raw_pairs(line: &str, field: &str) -> Vec<(f64, f64)> {
    let key = format!("\"{field}\":");
    let start = line.find(&key).expect("field") + key.len();
    let rest = &line[start..];
    let mut depth = 0;
    let mut end = 0;
    for (k, c) in rest.char_indices() {
        match c {
            '[' => depth += 1,
            ']' => {
                depth -= 1;
                if depth == 0 {
                    end = k;
                    break;
                }
            }
            _ => {}
        }
    }
    let body = &rest[1..end];
    body.split(']')
        .filter_map(|p| {
            let p = p.trim_start_matches([',', ' ']).trim_start_matches('[');
            let (t, v) = p.split_once(',')?;
            Some((number(t), number(v)))
        })
        .collect()
}

/// A CSV with a time column first; an empty cell is no new sample.
pub fn read_csv(csv: &str) -> (Vec<String>, DenseTrace) {
    let mut lines = csv.lines();
    let header: Vec<String> = lines.next().expect("header").split(',').map(String::from).collect();
    let vars = header[1..].to_vec();
    let mut b = DenseTraceBuilder::new(vars.len());
    for line in lines.filter(|l| !l.is_empty()) {
        let cells: Vec<&str> = line.split(',').collect();
        let t: f64 = cells[0].parse().expect("stamp");
        let row: Vec<Option<f64>> =
            cells[1..].iter().map(|c| if c.is_empty() { None } else { Some(number(c)) }).collect();
        b.push(t, &row).expect("a valid row");
    }
    (vars, b.build().expect("a trace"))
}

fn bounds(ast: &Value, out: &mut Vec<String>) {
    if let Value::Array(a) = ast {
        if let Some(Value::String(op)) = a.first()
            && matches!(
                op.as_str(),
                "always" | "eventually" | "once" | "historically" | "until" | "since"
            )
        {
            for b in &a[1..3] {
                if let Value::String(s) = b {
                    out.push(s.clone());
                }
            }
        }
        for x in a {
            bounds(x, out);
        }
    }
}

fn scaled(text: &str, decimals: u32) -> usize {
    let (n, d) = TimeScale::parse_decimal(text).expect("a bound");
    (n * 10u128.pow(decimals - d)) as usize
}

fn expr(ast: &Value, vars: &[String]) -> Expr {
    let a = ast.as_array().expect("an array");
    let s = |k: usize| a[k].as_str().expect("a string");
    match s(0) {
        "var" => Expr::var(vars.iter().position(|v| v == s(1)).expect("a known variable")),
        "num" => Expr::constant(number(s(1))),
        "add" => Expr::add(expr(&a[1], vars), expr(&a[2], vars)),
        "sub" => Expr::sub(expr(&a[1], vars), expr(&a[2], vars)),
        "mul" => Expr::mul(expr(&a[1], vars), expr(&a[2], vars)),
        "div" => Expr::div(expr(&a[1], vars), expr(&a[2], vars)),
        "neg" => Expr::neg(expr(&a[1], vars)),
        "abs" => Expr::abs(expr(&a[1], vars)),
        op => panic!("unknown expression {op}"),
    }
}

fn formula(ast: &Value, vars: &[String], decimals: u32) -> Formula {
    let a = ast.as_array().expect("an array");
    let s = |k: usize| a[k].as_str().expect("a string");
    let f = |k: usize| formula(&a[k], vars, decimals);
    let interval = || Interval {
        start: scaled(s(1), decimals),
        end: match &a[2] {
            Value::String(b) => Bound::Inclusive(scaled(b, decimals)),
            _ => Bound::Unbounded,
        },
    };
    match s(0) {
        "cmp" => {
            let op = match s(1) {
                "<" => CmpOp::Lt,
                "<=" => CmpOp::Le,
                ">" => CmpOp::Gt,
                ">=" => CmpOp::Ge,
                o => panic!("unknown comparison {o}"),
            };
            Formula::cmp(expr(&a[2], vars), op, expr(&a[3], vars))
        }
        "not" => Formula::not(f(1)),
        "and" => Formula::and(vec![f(1), f(2)]),
        "or" => Formula::or(vec![f(1), f(2)]),
        "implies" => Formula::implies(f(1), f(2)),
        "always" => Formula::always(interval(), f(3)),
        "eventually" => Formula::eventually(interval(), f(3)),
        "once" => Formula::once(interval(), f(3)),
        "historically" => Formula::historically(interval(), f(3)),
        "until" => Formula::until(interval(), f(3), f(4)),
        "since" => Formula::since(interval(), f(3), f(4)),
        op => panic!("unknown operator {op}"),
    }
}

/// Every case of the oracle file.
pub fn cases() -> Vec<Case> {
    let text = include_str!("../data/rtamt-dense-sample.jsonl");
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let v: Value = serde_json::from_str(line).expect("JSON");
            let (vars, trace) = read_csv(v["csv"].as_str().expect("csv"));
            let mut bs = Vec::new();
            bounds(&v["formula_ast"], &mut bs);
            let decimals = bs
                .iter()
                .map(|b| TimeScale::parse_decimal(b).expect("a bound").1)
                .max()
                .unwrap_or(0);
            Case {
                id: v["id"].as_u64().expect("id"),
                task: v["task"].as_str().expect("task").to_string(),
                formula: formula(&v["formula_ast"], &vars, decimals),
                scale: TimeScale::decimals(decimals),
                rtamt: raw_pairs(line, "signal"),
                trace,
                vars,
            }
        })
        .collect()
}

/// rtamt's list read as a function on `[t0, t_last]`, as change points: the value at `t0`
/// (that of the last point at or before it), then each point in `(t0, t_last]` that
/// changes the value. `None` at `t0` when rtamt's list starts after it.
pub fn rtamt_points(list: &[(f64, f64)], t0: f64, t_last: f64) -> Vec<(f64, Option<f64>)> {
    let k = list.partition_point(|p| p.0 <= t0);
    let mut out = vec![(t0, if k == 0 { None } else { Some(list[k - 1].1) })];
    for &(t, v) in &list[k..] {
        if t > t_last {
            break;
        }
        if out.last().expect("t0").1 != Some(v) {
            out.push((t, Some(v)));
        }
    }
    out
}

/// The change points of `sig` up to `t_last`.
pub fn points(sig: &DenseSignal, t_last: f64) -> Vec<(f64, f64)> {
    sig.until(t_last).collect()
}

/// Whether two lists of change points are equal, times bit for bit, values with `==`
/// (`0.0 == -0.0`: the sign of a zero is not pinned).
pub fn same_points(a: &[(f64, f64)], b: &[(f64, f64)]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.0.to_bits() == y.0.to_bits() && x.1 == y.1)
}
