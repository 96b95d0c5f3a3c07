//! Monitors compiled through the macro against rtamt: the first 40 past-time cases of the
//! oracle file (robustness/tests/data/rtamt-past-cases.jsonl), each task a `let` of
//! `specs/past_oracle.hstl`, give rtamt's full signal through `signal`, `robustness` and
//! the generated online monitor.
#![deny(warnings)]

use hstl::runtime::Value;
use hstl_macros::hstl;

hstl! { include "tests/specs/past_oracle.hstl" }

type Signal = fn(&[past_oracle::State]) -> Vec<f64>;
type Robustness = fn(&[past_oracle::State]) -> f64;

macro_rules! monitors {
    ($($name:ident),* $(,)?) => {
        vec![$((
            stringify!($name),
            past_oracle::lets::$name::signal as Signal,
            past_oracle::lets::$name::robustness as Robustness,
            (|| Box::new(past_oracle::lets::$name::Online::new()) as Box<dyn Push>) as fn() -> Box<dyn Push>,
        )),*]
    };
}

/// The generated online monitors, one type per let, behind one trait.
trait Push {
    fn push(&mut self, s: &past_oracle::State) -> Option<f64>;
    fn finish(&mut self) -> Vec<f64>;
}

macro_rules! push_impls {
    ($($name:ident),* $(,)?) => {
        $(impl Push for past_oracle::lets::$name::Online {
            fn push(&mut self, s: &past_oracle::State) -> Option<f64> {
                past_oracle::lets::$name::Online::push(self, s).map(|v| v.value)
            }
            fn finish(&mut self) -> Vec<f64> {
                past_oracle::lets::$name::Online::finish(self).iter().map(|v| v.value).collect()
            }
        })*
    };
}

push_impls![
    p0, p1, p2, p3, p4, p5, p6, p7, p8, p9, p10, p11, p12, p13, p14, p15, p16, p17, p18, p19, p20,
    p21, p22, p23, p24, p25, p26, p27, p28, p29, p30, p31, p32, p33, p34, p35, p36, p37, p38, p39,
];

fn number(v: &Value) -> f64 {
    match v.as_str() {
        Some("inf") => f64::INFINITY,
        Some("-inf") => f64::NEG_INFINITY,
        _ => v.as_f64().unwrap_or_else(|| panic!("not a number: {v}")),
    }
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().expect("an array").iter().map(number).collect()
}

#[test]
fn generated_monitors_give_rtamts_signals() {
    let monitors = monitors![
        p0, p1, p2, p3, p4, p5, p6, p7, p8, p9, p10, p11, p12, p13, p14, p15, p16, p17, p18, p19,
        p20, p21, p22, p23, p24, p25, p26, p27, p28, p29, p30, p31, p32, p33, p34, p35, p36, p37,
        p38, p39,
    ];
    let data = include_str!("../../robustness/tests/data/rtamt-past-cases.jsonl");
    let cases: Vec<Value> = data
        .lines()
        .take(monitors.len())
        .map(|l| l.parse().expect("one JSON object a line"))
        .collect();
    for ((name, signal, robustness, online), case) in monitors.iter().zip(&cases) {
        assert_eq!(format!("p{}", case["id"]), *name, "one let per case, in order");
        let (x, y) = (numbers(&case["trace"]["x"]), numbers(&case["trace"]["y"]));
        let states: Vec<past_oracle::State> =
            x.iter().zip(&y).map(|(&x, &y)| past_oracle::State { x, y }).collect();
        let want = numbers(&case["signal"]);
        let task = case["task"].as_str().unwrap_or("");
        assert_eq!(signal(&states), want, "{name}: {task}");
        assert_eq!(robustness(&states), want[0], "{name}: {task} at step 0");
        let mut m = online();
        let mut got: Vec<f64> = states.iter().filter_map(|s| m.push(s)).collect();
        got.extend(m.finish());
        assert_eq!(got, want, "{name}: {task} online");
    }
}
