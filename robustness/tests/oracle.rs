//! The rtamt cases (tests/data/rtamt-cases.jsonl, computed with rtamt 0.4.10): every
//! evaluator must give rtamt's robustness and full signal on every case.

mod common;

use common::{check_all, parse, same, trace_xy};
use hstl_robustness::offline;
use serde_json::Value;

fn number(v: &Value) -> f64 {
    match v {
        Value::String(s) if s == "inf" => f64::INFINITY,
        Value::String(s) if s == "-inf" => f64::NEG_INFINITY,
        v => v.as_f64().unwrap_or_else(|| panic!("not a number: {v}")),
    }
}

fn column(v: &Value) -> Vec<f64> {
    v.as_array().expect("a column").iter().map(number).collect()
}

#[test]
fn rtamt_cases() {
    let data = include_str!("data/rtamt-cases.jsonl");
    let mut cases = 0;
    for line in data.lines().filter(|l| !l.trim().is_empty()) {
        let case: Value = serde_json::from_str(line).expect("one JSON object a line");
        let task = case["task"].as_str().expect("a task");
        let f = parse(task);
        let trace = trace_xy(&column(&case["trace"]["x"]), &column(&case["trace"]["y"]));
        let want = column(&case["signal"]);
        let rho = number(&case["robustness"]);
        let got = offline::robustness(&f, &trace);
        assert!(same(got, rho), "case {}: {task}: robustness {got}, rtamt {rho}", case["id"]);
        check_all(&f, &trace, &want);
        cases += 1;
    }
    assert_eq!(cases, 100, "the data file holds 100 cases");
}

/// The past-time cases (tests/data/rtamt-past-cases.jsonl, computed with rtamt 0.4.10 by
/// bench/oracle/past_time.py): `once`, `historically`, `since`, `prev` and `next` mixed
/// with the future operators. Past-time operators are often `+inf` or `-inf` at step 0, so
/// every evaluator is held to rtamt's full signal.
#[test]
fn rtamt_past_time_cases() {
    let data = include_str!("data/rtamt-past-cases.jsonl");
    let mut cases = 0;
    for line in data.lines().filter(|l| !l.trim().is_empty()) {
        let case: Value = serde_json::from_str(line).expect("one JSON object a line");
        let task = case["task"].as_str().expect("a task");
        let f = parse(task);
        let trace = trace_xy(&column(&case["trace"]["x"]), &column(&case["trace"]["y"]));
        let want = column(&case["signal"]);
        assert_eq!(want.len(), trace.len(), "case {}: {task}", case["id"]);
        let got = offline::signal(&f, &trace);
        assert!(
            got.iter().zip(&want).all(|(g, w)| same(*g, *w)),
            "case {}: {task}: {got:?}, rtamt {want:?}",
            case["id"]
        );
        check_all(&f, &trace, &want);
        cases += 1;
    }
    assert_eq!(cases, 1500, "the data file holds 1,500 cases");
}
