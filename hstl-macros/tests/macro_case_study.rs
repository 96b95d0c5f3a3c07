//! The case study through the macro: the generated API, against the runtime.
#![deny(warnings)]

use hstl::robustness::{Trace, offline, reference};
use hstl_macros::hstl;

hstl! { include "specs/case_study.hstl" }

hstl! {
    /// The same task written inline, with a temporal let.
    spec Inline {
        state {
            /// Column.
            x: int in 0..=14,
            /// Row.
            y: int in 0..=14,
        }
        let A = x > 3 && x < 9 && y > 10 && y < 14;
        let B = x > 1 && x < 5 && y > 1 && y < 5;
        let Soon = eventually[0..40] A;
        task always[0..] (Soon && eventually[0..=39] B);
        option A;
        option B { reach: B, init: !B, terminate: B }
        options { A, [A, B] }
    }
}

fn walk(len: usize) -> Vec<surveillance::State> {
    // A deterministic walk over the grid that passes through A, B and C.
    (0..len)
        .map(|i| surveillance::State { x: (i * 7 % 15) as i64, y: (i * 5 % 15) as i64 })
        .collect()
}

fn trace_of(states: &[surveillance::State]) -> Trace {
    let mut t = Trace::new(surveillance::State::VARS);
    for s in states {
        t.push(&s.values()).expect("rows have VARS values");
    }
    t
}

#[test]
fn enums_know_names_and_sequences() {
    use surveillance::{Options, Primitive};
    assert_eq!(Primitive::ALL.map(Primitive::name), ["A", "B", "C"]);
    assert_eq!(Options::ALL.map(Options::name), ["A", "B", "C", "AB", "AC", "BC", "ABC"]);
    assert_eq!(Options::ABC.sequence(), &[Primitive::A, Primitive::B, Primitive::C]);
    let spec = surveillance::Surveillance::task_spec();
    for o in Options::ALL {
        let data = &spec.options[o.index()];
        assert_eq!(data.name, o.name());
        let seq: Vec<usize> = o.sequence().iter().map(|p| p.index()).collect();
        assert_eq!(data.sequence, seq);
    }
    assert_eq!(inline::Options::ALL.map(inline::Options::name), ["A", "AB"]);
}

#[test]
fn monitors_agree_with_the_runtime() {
    for len in [0, 1, 5, 39, 40, 41, 120] {
        let states = walk(len);
        let trace = trace_of(&states);
        let f = surveillance::task::formula();
        let expected = reference::signal(&f, &trace);
        let got = surveillance::task::signal(&states);
        assert_eq!(got, offline::signal(&f, &trace), "len {len}");
        assert_eq!(got, expected, "len {len}");
        let r0 = reference::robustness(&f, &trace, 0);
        let r = surveillance::task::robustness(&states);
        assert!(r == r0 || (r.is_nan() && r0.is_nan()), "len {len}: {r} vs {r0}");
        let a = surveillance::lets::a::formula();
        for (t, s) in states.iter().enumerate() {
            assert_eq!(surveillance::lets::a::at(s), reference::robustness(&a, &trace, t));
        }
        let inline_states: Vec<inline::State> =
            states.iter().map(|s| inline::State { x: s.x, y: s.y }).collect();
        let g = inline::task::formula();
        assert_eq!(
            inline::task::signal(&inline_states),
            reference::signal(&g, &trace),
            "len {len}"
        );
    }
}

#[test]
fn online_monitor_gives_the_offline_signal() {
    let states: Vec<inline::State> =
        walk(100).iter().map(|s| inline::State { x: s.x, y: s.y }).collect();
    let mut m = inline::lets::soon::Online::new();
    let mut verdicts: Vec<_> = states.iter().filter_map(|s| m.push(s)).collect();
    verdicts.extend(m.finish());
    let values: Vec<f64> = verdicts.iter().map(|v| v.value).collect();
    assert_eq!(values, inline::lets::soon::signal(&states));
}

#[test]
fn spec_trait_gives_a_valid_task_spec() {
    use hstl::runtime::Spec;
    let spec = surveillance::Surveillance.task_spec();
    spec.validate().expect("the case study is a valid runtime spec");
    assert_eq!(spec.name, "Surveillance");
    assert_eq!(spec.regions.iter().map(|r| r.name.as_str()).collect::<Vec<_>>(), ["A", "B", "C"]);
    assert!(spec.regions.iter().all(|r| r.horizon == 40));
    assert_eq!(spec.learn, hstl::runtime::LearnParams::default());
    let inline = inline::Inline.task_spec();
    inline.validate().expect("the inline spec is a valid runtime spec");
}

#[test]
fn training_the_case_study_takes_a_few_lines() {
    use hstl::runtime::{GridWorld, Learner, Spec, seeded_rng};
    let mut spec = surveillance::Surveillance.task_spec();
    spec.learn.episodes = 3;
    spec.learn.choices = 5;
    let env = GridWorld::default();
    let train = |seed| {
        let mut learner = Learner::new(&spec, &env).expect("the case study fits the grid world");
        let trained = learner.train(&mut seeded_rng(seed), |_, _| {});
        (trained.curve, learner.q().clone())
    };
    let (curve, q) = train(7);
    assert_eq!(curve.len(), 3);
    // The same seed gives the same tables, bit for bit.
    assert_eq!((curve, q), train(7));
}

hstl! {
    /// Names that could clash with generated items or Rust keywords.
    spec State {
        state { type: int in 0..=1, s: int in 0..=3, t: int in 0..=2 }
        let fn = r#type > 0 && s < 2;
        let Lets = eventually[0..3] fn;
        task always[0..] (Lets || t > 1);
        option fn;
    }
}

#[test]
fn awkward_names_still_compile() {
    use hstl::runtime::Spec;
    let states = [state::State { r#type: 1, s: 1, t: 0 }, state::State { r#type: 0, s: 3, t: 2 }];
    assert_eq!(state::lets::r#fn::at(&states[0]), 1.0);
    let f = state::task::formula();
    let trace = trace_from(&states.map(|s| s.values().to_vec()));
    assert_eq!(state::task::signal(&states), reference::signal(&f, &trace));
    assert_eq!(state::StateSpec.task_spec().name, "State");
    assert_eq!(state::Primitive::ALL.map(state::Primitive::name), ["fn"]);
}

fn trace_from(rows: &[Vec<f64>]) -> Trace {
    let mut t = Trace::new(rows.first().map_or(0, Vec::len));
    for r in rows {
        t.push(r).expect("rows have the same width");
    }
    t
}
