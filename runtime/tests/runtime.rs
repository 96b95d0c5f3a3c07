//! Integration tests: determinism, the grid world, policy.json, evaluation, the optimum
//! and configuration errors.

mod common;

use std::collections::HashMap;

use hstl_runtime::env::{Cell, Env};
use hstl_runtime::eval::{
    AgentController, AgentProgress, Controller, RegionTable, WindowConfig, rollout, window_rate,
};
use hstl_runtime::moves::Moves;
use hstl_runtime::optimum::{SolveConfig, solve};
use hstl_runtime::robustness::Formula;
use hstl_runtime::{Error, GridWorld, Learner, Policy, QTables, TaskSpec, seeded_rng};

/// The case study cut down so that a debug build trains it in a moment.
fn small(permutations: bool, entry: bool) -> TaskSpec {
    let mut spec = common::case_study(permutations, entry);
    spec.learn.episodes = 6;
    spec.learn.choices = 20;
    spec
}

fn train(spec: &TaskSpec, env: &GridWorld, seed: u64) -> QTables {
    let mut learner = Learner::new(spec, env).unwrap();
    learner.train(&mut seeded_rng(seed), |_, _| {});
    learner.q().clone()
}

fn bits(q: &QTables) -> Vec<u64> {
    q.flat.iter().flatten().chain(&q.options).map(|v| v.to_bits()).collect()
}

#[test]
fn same_seed_same_bits_other_seed_other_bits() {
    let env = GridWorld::default();
    for (permutations, entry) in [(false, false), (true, true)] {
        let spec = small(permutations, entry);
        let a = train(&spec, &env, 7);
        assert_eq!(bits(&a), bits(&train(&spec, &env, 7)));
        assert_eq!((a.steps, a.choices), (train(&spec, &env, 7).steps, 120));
        assert_ne!(bits(&a), bits(&train(&spec, &env, 8)));
    }
}

#[test]
fn progress_reports_every_episode_and_the_curve() {
    let env = GridWorld::default();
    let spec = small(false, true);
    let mut learner = Learner::new(&spec, &env).unwrap();
    let mut seen = Vec::new();
    let trained = learner.train(&mut seeded_rng(1), |e, r| seen.push((e, r)));
    let want: Vec<(usize, f64)> = trained.curve.iter().copied().enumerate().collect();
    assert_eq!(seen, want);
    assert_eq!(trained.steps, learner.q().steps);
}

#[test]
fn training_stopped_after_k_episodes_is_training_k_episodes() {
    let env = GridWorld::default();
    let spec = small(false, true);
    let mut stopped = Learner::new(&spec, &env).unwrap();
    let trained = stopped.train_until(&mut seeded_rng(5), |episode, _| {
        if episode == 3 {
            std::ops::ControlFlow::Break(())
        } else {
            std::ops::ControlFlow::Continue(())
        }
    });
    assert_eq!(trained.curve.len(), 4);
    let mut four = spec.clone();
    four.learn.episodes = 4;
    assert_eq!(bits(stopped.q()), bits(&train(&four, &env, 5)));
    assert_eq!(trained.steps, stopped.q().steps);
}

#[test]
fn grid_world_slips_to_each_other_action_equally() {
    let env = GridWorld::default();
    let mut rng = seeded_rng(42);
    let centre = Cell { x: 7, y: 7 };
    let n = 100_000;
    for action in 0..4 {
        let mut counts: HashMap<usize, usize> = HashMap::new();
        for _ in 0..n {
            let to = env.step(&centre, action, &mut rng);
            let moved = (0..4).find(|&d| env.intended(centre, d) == to).unwrap();
            *counts.entry(moved).or_default() += 1;
        }
        for d in 0..4 {
            let want = if d == action { 0.7 } else { 0.1 };
            let got = counts.get(&d).copied().unwrap_or(0) as f64 / n as f64;
            // About seven standard deviations of a binomial share at n = 1e5.
            assert!((got - want).abs() < 0.01, "action {action} moved {d}: {got}");
        }
    }
}

#[test]
fn grid_world_follows_the_contract() {
    let env = GridWorld::new(3, 2, 1.0).unwrap();
    let mut rng = seeded_rng(0);
    // (from, action, to): x left to right, y bottom to top, off the grid stays.
    let cases = [
        ((0, 0), 0, (0, 1)),
        ((0, 1), 0, (0, 1)),
        ((0, 1), 1, (0, 0)),
        ((0, 0), 1, (0, 0)),
        ((1, 0), 2, (0, 0)),
        ((0, 0), 2, (0, 0)),
        ((1, 0), 3, (2, 0)),
        ((2, 0), 3, (2, 0)),
    ];
    for ((x, y), a, (tx, ty)) in cases {
        assert_eq!(env.step(&Cell { x, y }, a, &mut rng), Cell { x: tx, y: ty }, "{x},{y} {a}");
    }
    for s in 0..env.num_states() {
        assert_eq!(env.index(&env.state(s).unwrap()), s);
    }
    assert_eq!(env.state(6), None);
}

#[test]
fn bad_environments_are_errors() {
    for (w, h, p) in [(0, 15, 0.7), (15, 0, 0.7), (15, 15, 1.5), (15, 15, -0.1), (15, 15, f64::NAN)]
    {
        assert!(matches!(GridWorld::new(w, h, p), Err(Error::Env(_))), "{w} {h} {p}");
    }
    let params = serde_json::json!({ "width": 15, "height": "15", "p": 0.7 });
    assert!(GridWorld::from_params("gridworld", &params).is_err());
    // Evaluation and value-iteration settings.
    let env = GridWorld::default();
    let spec = small(false, false);
    let table = RegionTable::new(&spec, &env).unwrap();
    let agent = Learner::new(&spec, &env).unwrap().agent();
    for config in [
        WindowConfig { starts: 0, ..WindowConfig::default() },
        WindowConfig { burn_in: 2000, ..WindowConfig::default() },
    ] {
        let mut c = AgentController::new(&agent);
        assert!(window_rate(&env, &mut c, &table, config, &mut seeded_rng(0)).is_err());
    }
    let other = GridWorld::new(5, 5, 0.7).unwrap();
    let mut c = AgentController::new(&agent);
    assert!(
        window_rate(&other, &mut c, &table, WindowConfig::default(), &mut seeded_rng(0)).is_err()
    );
    for config in [
        SolveConfig { tolerance: 0.0, ..SolveConfig::default() },
        SolveConfig { tolerance: f64::NAN, ..SolveConfig::default() },
    ] {
        assert!(solve(&Moves::of(&env), &table, config).is_err());
    }
    assert!(solve(&Moves::of(&other), &table, SolveConfig::default()).is_err());
    let mut no_regions = spec.clone();
    no_regions.regions.clear();
    assert!(RegionTable::new(&no_regions, &env).is_err());
}

#[test]
fn bad_specs_are_errors() {
    type Break = fn(&mut TaskSpec);
    let cases: [(&str, Break); 10] = [
        ("is not a variable of environment", |s| s.state_vars[0].name = "z".into()),
        ("no finite int range", |s| s.state_vars[1].domain = None),
        ("outside its declared domain", |s| s.state_vars[0].domain = Some(0..=9)),
        ("the options set is empty", |s| s.options.clear()),
        ("no primitive option", |s| s.primitives.clear()),
        ("no option of the set can start", |s| {
            s.primitives.iter_mut().for_each(|p| p.init = Formula::bool(false))
        }),
        ("flat gamma", |s| s.learn.flat.gamma = 1.5),
        ("episodes must be > 0", |s| s.learn.episodes = 0),
        ("the regions do not match", |s| s.regions[0].horizon = 30),
        ("A can terminate outside the initiation set of B", |s| {
            s.primitives[1].init = common::cmp(0, hstl_runtime::robustness::CmpOp::Gt, 7.0)
        }),
    ];
    let env = GridWorld::default();
    for (want, change) in cases {
        let mut spec = small(false, false);
        change(&mut spec);
        let err = Learner::new(&spec, &env).map(|_| ()).unwrap_err();
        assert!(err.to_string().contains(want), "{want}: {err}");
    }
}

#[test]
fn policy_json_round_trips_bit_for_bit() {
    let env = GridWorld::default();
    let spec = small(false, true);
    let mut learner = Learner::new(&spec, &env).unwrap();
    learner.train(&mut seeded_rng(5), |_, _| {});
    // Non-finite values must survive too.
    let mut q = learner.q().clone();
    q.flat[0][0] = f64::INFINITY;
    q.flat[1][1] = f64::NEG_INFINITY;
    q.options[2] = f64::from_bits(0x7ff8_0000_dead_beef);
    q.options[3] = -0.0;
    let learner = learner.with_tables(q.clone()).unwrap();
    let policy = Policy::new(&learner);
    let text = policy.to_json().unwrap();
    let back = Policy::from_json(&text).unwrap();
    assert_eq!(back, policy);
    assert_eq!(bits(&back.q_tables().unwrap()), bits(&q));
    assert_eq!(back.agent(&env).unwrap(), learner.agent());
    // The contract's fields, as scripts read them.
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(doc["spec"], "Surveillance");
    assert_eq!(doc["env"]["name"], "paper");
    assert_eq!(doc["env"]["params"]["slip"], 0.3);
    assert_eq!(doc["env"]["params"]["map"][14], "...............");
    assert_eq!(doc["state_vars"], serde_json::json!(["x", "y"]));
    assert_eq!(doc["actions"], serde_json::json!(["Up", "Down", "Left", "Right"]));
    assert_eq!(
        doc["options"][6],
        serde_json::json!({ "name": "ABC", "sequence": ["A", "B", "C"] })
    );
    assert_eq!(doc["options_policy"].as_array().unwrap().len(), 225);
    assert_eq!(doc["flat_policies"]["B"].as_array().unwrap().len(), 225);
    assert_eq!(doc["flat_policies"]["B"][16]["state"], serde_json::json!({ "x": 1, "y": 1 }));
    // Entry termination for A: 5 x 3 cells.
    assert_eq!(doc["primitives"][0]["terminate"].as_array().unwrap().len(), 15);
    // Training continues from the reloaded tables.
    let resumed = Learner::new(&spec, &env).unwrap().with_tables(back.q_tables().unwrap()).unwrap();
    assert_eq!(bits(resumed.q()), bits(&q));
}

#[test]
fn bad_policy_documents_say_what_is_wrong() {
    let env = GridWorld::default();
    let learner = Learner::new(&small(false, false), &env).unwrap();
    let summed: serde_json::Value =
        serde_json::from_str(&Policy::new(&learner).to_json().unwrap()).unwrap();
    // Without its checksum (as written before checksums), so that each field's own check
    // is what refuses it.
    let good = unsummed(summed.clone());
    type Break = fn(&mut serde_json::Value);
    let cases: [(&str, Break); 7] = [
        ("missing field `spec`", |d| {
            d.as_object_mut().unwrap().remove("spec");
        }),
        ("not 16 hex digits", |d| d["q_tables"]["options"][0] = "xyz".into()),
        ("does not cover state index", |d| {
            d["options_policy"].as_array_mut().unwrap().pop();
        }),
        ("chooses unknown", |d| d["flat_policies"]["A"][0]["choice"] = "Jump".into()),
        ("which the environment lacks", |d| d["options_policy"][0]["state"]["x"] = 99.into()),
        ("trained on another `paper`", |d| d["env"]["params"]["slip"] = 0.1.into()),
        ("trained on `office`", |d| d["env"]["name"] = "office".into()),
    ];
    for (want, change) in cases {
        let mut doc = good.clone();
        change(&mut doc);
        let err = Policy::from_json(&doc.to_string())
            .and_then(|p| p.q_tables().and_then(|_| p.agent(&env)))
            .unwrap_err();
        assert!(err.to_string().contains(want), "{want}: {err}");
        // With the checksum, any edit that still parses is refused by it.
        let mut doc = summed.clone();
        change(&mut doc);
        if let Err(err) = Policy::from_json(&doc.to_string()) {
            let err = err.to_string();
            let parse = want.starts_with("missing field") || want.starts_with("not 16 hex");
            assert!(parse || err.contains("was changed after it was written"), "{want}: {err}");
        } else {
            panic!("{want}: an edited document with its checksum was read");
        }
    }
    // The document as written, reformatted, reads back: the checksum is of its fields.
    let pretty = serde_json::to_string_pretty(&summed).unwrap();
    assert_eq!(Policy::from_json(&pretty).unwrap(), Policy::new(&learner));
    assert!(Policy::from_json("{").unwrap_err().to_string().contains("EOF"));
}

/// A document without its `checksum` field.
fn unsummed(mut doc: serde_json::Value) -> serde_json::Value {
    doc.as_object_mut().expect("an object").remove("checksum").expect("a checksum");
    doc
}

#[test]
fn window_rate_counts_each_region_over_its_own_window() {
    let env = GridWorld::new(4, 1, 1.0).unwrap();
    let mut spec = small(false, false);
    spec.state_vars[0].domain = Some(0..=3);
    spec.state_vars[1].domain = Some(0..=0);
    // R1: x < 1 within 3 steps; R2: x > 2 within 5 steps.
    let r1 = common::cmp(0, hstl_runtime::robustness::CmpOp::Lt, 1.0);
    let r2 = common::cmp(0, hstl_runtime::robustness::CmpOp::Gt, 2.0);
    spec.regions = vec![
        hstl_runtime::Region { name: "R1".into(), formula: r1, horizon: 3 },
        hstl_runtime::Region { name: "R2".into(), formula: r2, horizon: 5 },
    ];
    let table = RegionTable::new(&spec, &env).unwrap();
    let states = [0, 1, 2, 3, 2, 1, 0, 1, 2, 3, 3, 3];
    // tau_1: 0 1 2 3 3 3 0 1 2 3 3 3  (kept while < 3)
    // tau_2: 5 5 5 0 1 2 3 4 5 0 0 0  (kept while < 5)
    let want = [false, false, false, false, false, false, true, true, false, false, false, false];
    assert_eq!(table.psi(&states), want);
}

#[test]
fn the_optimum_matches_its_greedy_policy_in_simulation() {
    let env = GridWorld::new(6, 6, 0.7).unwrap();
    let mut spec = small(false, false);
    spec.state_vars[0].domain = Some(0..=5);
    spec.state_vars[1].domain = Some(0..=5);
    let corner = |x: (f64, f64), y: (f64, f64)| common::rect(x, y);
    spec.regions = vec![
        hstl_runtime::Region {
            name: "L".into(),
            formula: corner((-1.0, 1.0), (-1.0, 1.0)),
            horizon: 12,
        },
        hstl_runtime::Region {
            name: "R".into(),
            formula: corner((4.0, 6.0), (4.0, 6.0)),
            horizon: 14,
        },
    ];
    let table = RegionTable::new(&spec, &env).unwrap();
    let optimum = solve(&Moves::of(&env), &table, SolveConfig::default()).unwrap();
    assert!(optimum.converged && optimum.upper - optimum.lower < 1e-4);
    assert!(optimum.gain > 0.0 && optimum.gain < 1.0, "{}", optimum.gain);
    let config = WindowConfig { starts: 40, steps: 3000, burn_in: 100 };
    let report =
        window_rate(&env, &mut optimum.controller(), &table, config, &mut seeded_rng(9)).unwrap();
    // 116k counted steps; correlated, so allow a few hundredths.
    assert!((report.rate - optimum.gain).abs() < 0.03, "{} vs {}", report.rate, optimum.gain);
}

#[test]
fn greedy_rollouts_follow_option_legs() {
    let env = GridWorld::default();
    let spec = small(false, false);
    let mut learner = Learner::new(&spec, &env).unwrap();
    learner.train(&mut seeded_rng(2), |_, _| {});
    let agent = learner.agent();
    let steps = rollout(&env, &mut AgentController::new(&agent), 0, 300, &mut seeded_rng(3));
    assert_eq!(steps.len(), 300);
    for w in steps.windows(2) {
        let (a, b) = (w[0].decision, w[1].decision);
        let p = agent.legs[a.option][a.leg];
        assert_eq!(a.action, agent.flat[p][w[0].state]);
        if agent.terminate[p][w[1].state] {
            // The leg ends on reaching its termination set: the next leg or a new choice.
            assert!(b.option != a.option || b.leg == a.leg + 1 || b.leg == 0);
        } else {
            assert_eq!((b.option, b.leg), (a.option, a.leg));
        }
    }
}

/// Each step records where its action led: the next step's state, and for the last step
/// the state after it. A step leaves the cell its action leads to without slipping only
/// when the grid's one draw for it slipped (`u >= p`), which replaying the draws shows.
#[test]
fn rollout_steps_record_where_each_action_led() {
    use hstl_runtime::RngExt;
    let env = GridWorld::default();
    let spec = small(false, false);
    let mut learner = Learner::new(&spec, &env).unwrap();
    learner.train(&mut seeded_rng(2), |_, _| {});
    let agent = learner.agent();
    let steps = rollout(&env, &mut AgentController::new(&agent), 0, 300, &mut seeded_rng(3));
    for w in steps.windows(2) {
        assert_eq!(w[0].next, w[1].state);
    }
    // The greedy agent draws nothing: the rollout's draws are the grid's, one per step.
    let mut draws = seeded_rng(3);
    let mut slips = 0;
    for step in &steps {
        let slipped = draws.random::<f64>() >= env.p();
        let off_course = step.next != env.dest(step.state, step.decision.action);
        assert!(!off_course || slipped, "{step:?} left its course without a slip");
        slips += usize::from(off_course);
    }
    assert!(slips > 0, "300 steps with slip 0.3 slip somewhere");
    let last = steps.last().unwrap();
    let again = rollout(&env, &mut AgentController::new(&agent), 0, 301, &mut seeded_rng(3));
    assert_eq!(again[300].state, last.next);
}

#[test]
fn a_paused_controller_resumes_where_it_was() {
    let env = GridWorld::default();
    for spec in [small(false, false), small_memory()] {
        let mut learner = Learner::new(&spec, &env).unwrap();
        learner.train(&mut seeded_rng(2), |_, _| {});
        let agent = learner.agent();
        let whole = rollout(&env, &mut AgentController::new(&agent), 17, 300, &mut seeded_rng(3));
        // The same run, with the controller paused and resumed around every call.
        let (mut rng, mut progress) = (seeded_rng(3), AgentProgress::default());
        let mut s = 17;
        for step in &whole {
            let mut c = AgentController::resume(&agent, progress);
            let decision = c.act(s);
            assert_eq!((s, decision), (step.state, step.decision));
            let next = env.index(&env.step(&env.state(s).unwrap(), decision.action, &mut rng));
            c.observe(next);
            progress = c.pause();
            s = next;
        }
    }
}

#[test]
fn persistent_regions_are_read_off_the_task() {
    use hstl_runtime::robustness::{Bound, CmpOp, Interval};
    use hstl_runtime::spec::persistent_regions;
    let r = common::cmp(0, CmpOp::Gt, 3.0);
    let ev = |start, end| Formula::eventually(Interval { start, end }, r.clone());
    let always = |f: Formula| Formula::always(Interval::ALL, f);
    // (task, the N_j read off it, or None when the task has another form)
    let cases = [
        (always(ev(0, Bound::Exclusive(40))), Some(vec![40])),
        (always(ev(0, Bound::Inclusive(40))), Some(vec![41])),
        (
            always(Formula::and(vec![ev(0, Bound::Exclusive(5)), ev(0, Bound::Inclusive(7))])),
            Some(vec![5, 8]),
        ),
        (always(ev(1, Bound::Exclusive(40))), None),
        (always(ev(0, Bound::Unbounded)), None),
        (always(Formula::or(vec![ev(0, Bound::Exclusive(5))])), None),
        (ev(0, Bound::Exclusive(40)), None),
        (
            Formula::always(
                Interval { start: 0, end: Bound::Exclusive(9) },
                ev(0, Bound::Exclusive(4)),
            ),
            None,
        ),
        // Safety conjuncts `always[0..] !S` beside it: each a one-step window of `!S`.
        (
            Formula::and(vec![
                always(ev(0, Bound::Exclusive(40))),
                always(Formula::not(common::cmp(1, CmpOp::Lt, 2.0))),
                always(Formula::not(common::cmp(0, CmpOp::Lt, 1.0))),
            ]),
            Some(vec![40, 1, 1]),
        ),
        // ... but not bounded ones, nor two persistent parts, nor anything else beside it.
        (
            Formula::and(vec![
                always(ev(0, Bound::Exclusive(40))),
                Formula::always(
                    Interval { start: 0, end: Bound::Exclusive(9) },
                    Formula::not(common::cmp(1, CmpOp::Lt, 2.0)),
                ),
            ]),
            None,
        ),
        (
            Formula::and(vec![
                always(ev(0, Bound::Exclusive(40))),
                always(ev(0, Bound::Exclusive(9))),
            ]),
            None,
        ),
        (Formula::and(vec![always(ev(0, Bound::Exclusive(40))), r.clone()]), None),
    ];
    for (task, want) in cases {
        let got =
            persistent_regions(&task).map(|rs| rs.into_iter().map(|(_, n)| n).collect::<Vec<_>>());
        assert_eq!(got, want, "{task:?}");
    }
}

#[test]
fn option_rewards_follow_the_reference_segment_semantics() {
    use hstl_runtime::robustness::Trace;
    use hstl_runtime::robustness::reference::segment_reward;
    use hstl_runtime::robustness::segment::TabularScorer;
    // The learner's rewards come from the fast scorer; hold it against the reference on
    // random walks of the case study, short (under the horizon) and long (past it).
    let env = GridWorld::default();
    let spec = common::case_study(false, false);
    let mut states = Trace::new(2);
    for s in 0..env.num_states() {
        let c = env.state(s).unwrap();
        states.push(&[c.x as f64, c.y as f64]).unwrap();
    }
    let mut scorer = TabularScorer::new(&spec.task, &states);
    let mut rng = seeded_rng(11);
    let mut out = Vec::new();
    for len in [2, 7, 39, 40, 41, 90] {
        let mut walk = vec![env.index(&env.reset(&mut rng))];
        while walk.len() < len {
            let c = env.state(*walk.last().unwrap()).unwrap();
            walk.push(env.index(&env.step(&c, (walk.len() * 7) % 4, &mut rng)));
        }
        scorer.suffix_rewards(&walk, &mut out);
        assert_eq!(out.len(), len);
        for (j, &got) in out.iter().enumerate() {
            let mut seg = Trace::new(2);
            for &s in &walk[j..] {
                let c = env.state(s).unwrap();
                seg.push(&[c.x as f64, c.y as f64]).unwrap();
            }
            assert_eq!(got, segment_reward(&spec.task, &seg), "length {len}, suffix {j}");
        }
        assert_eq!(scorer.reward(&walk), out[0]);
    }
}

/// The memory variant (options {A, B, C}, `memory: 8`, `reward: window`), cut down.
fn small_memory() -> TaskSpec {
    let mut spec = common::case_study_memory();
    spec.learn.episodes = 6;
    spec.learn.choices = 20;
    spec
}

#[test]
fn memory_training_is_deterministic() {
    let env = GridWorld::default();
    let spec = small_memory();
    let a = train(&spec, &env, 7);
    assert_eq!(a.options.len(), 225 * 729 * 3);
    assert_eq!(bits(&a), bits(&train(&spec, &env, 7)));
    assert_ne!(bits(&a), bits(&train(&spec, &env, 8)));
    // The memory changes what is learned: without it the options table is per state.
    let mut flat = spec.clone();
    flat.learn.memory = 0;
    assert_eq!(train(&flat, &env, 7).options.len(), 225 * 3);
    // Memory with the paper's segment reward: the options table is per state and memory.
    let mut segment = spec.clone();
    segment.learn.reward = hstl_runtime::RewardKind::Segment;
    segment.learn.memory = 2;
    let q = train(&segment, &env, 7);
    assert_eq!(q.options.len(), 225 * 27 * 3);
    assert_eq!(bits(&q), bits(&train(&segment, &env, 7)));
    // The window reward is never negative; the segment reward of a region far away is.
    assert!(a.options.iter().all(|&v| v >= 0.0));
    assert!(q.options.iter().any(|&v| v < 0.0));
}

#[test]
fn memory_policy_json_round_trips_bit_for_bit() {
    let env = GridWorld::default();
    let spec = small_memory();
    let mut learner = Learner::new(&spec, &env).unwrap();
    learner.train(&mut seeded_rng(5), |_, _| {});
    let policy = Policy::new(&learner);
    let text = policy.to_json().unwrap();
    let back = Policy::from_json(&text).unwrap();
    assert_eq!(back, policy);
    assert_eq!(bits(&back.q_tables().unwrap()), bits(learner.q()));
    let agent = back.agent(&env).unwrap();
    assert_eq!(agent, learner.agent());
    assert_eq!(agent.memory.as_ref().map(|m| m.buckets), Some(8));
    // The contract: the memory part, and one entry per state and memory value that can
    // occur there (b_j = 0 inside region j: A and C have 15 cells, B 9).
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(doc["memory"]["regions"], serde_json::json!(["A", "B", "C"]));
    assert_eq!(doc["memory"]["horizons"], serde_json::json!([40, 40, 40]));
    assert_eq!(doc["memory"]["buckets"], 8);
    let entries = doc["options_policy"].as_array().unwrap();
    assert_eq!(entries.len(), (225 - 39) * 729 + 39 * 81);
    let in_a =
        entries.iter().find(|e| e["state"] == serde_json::json!({ "x": 5, "y": 12 })).unwrap();
    assert_eq!(in_a["memory"][0], 0);
    assert!(entries.iter().all(|e| e["memory"].as_array().is_some_and(|m| m.len() == 3)));
    // With `init: !A`, no entry chooses the region the state lies in.
    assert!(entries.iter().filter(|e| e["memory"][0] == 0).all(|e| {
        let (x, y) = (e["state"]["x"].as_i64().unwrap(), e["state"]["y"].as_i64().unwrap());
        !(3 < x && x < 9 && 10 < y && y < 14) || e["choice"] != "A"
    }));
    // Flat policies carry no memory.
    assert!(doc["flat_policies"]["A"][0].get("memory").is_none());
    // Each entry on one line.
    assert!(text.contains(r#"{"state": {"x": 0, "y": 0}, "memory": [8, 8, 8], "choice": "#));
    // Extra fields go after the document's own, and read back as the same document.
    let with = policy.to_json_with(&[("seed", 5.into()), ("spec_source", "spec S {}".into())]);
    let with = with.unwrap();
    assert!(
        with.ends_with("\"seed\": 5,\n  \"spec_source\": \"spec S {}\"\n}"),
        "{}",
        &with[with.len() - 80..]
    );
    assert_eq!(Policy::from_json(&with).unwrap(), policy);
    let clash = policy.to_json_with(&[("memory", 1.into())]).unwrap_err().to_string();
    assert!(clash.contains("the extra field memory is already in the document"), "{clash}");
    // Training continues from the reloaded tables.
    let resumed = Learner::new(&spec, &env).unwrap().with_tables(back.q_tables().unwrap()).unwrap();
    assert_eq!(bits(resumed.q()), bits(learner.q()));
}

#[test]
fn memory_slices_pick_one_entry_per_state() {
    let env = GridWorld::default();
    let mut spec = small_memory();
    spec.learn.memory = 2;
    let learner = Learner::new(&spec, &env).unwrap();
    let policy = Policy::new(&learner);
    let slices = policy.memory_slices();
    assert_eq!(slices.len(), 3);
    assert_eq!(slices[2], ("b = [2, 2, 2]".to_string(), vec![2, 2, 2]));
    for (_, b) in &slices {
        let slice = policy.options_slice(b).unwrap();
        assert_eq!(slice.len(), 225, "{b:?}");
        let inside_b = slice
            .iter()
            .find(|e| e.state.get("x") == Some(3.0) && e.state.get("y") == Some(3.0))
            .unwrap();
        assert_eq!(inside_b.memory, Some(vec![b[0], 0, b[2]]));
    }
    let err = policy.options_slice(&[3, 0, 0]).unwrap_err().to_string();
    assert!(err.contains("one bucket in 0..=2 for each of the regions A, B and C"), "{err}");
    // Without memory the one slice is the whole options policy.
    let plain = Policy::new(&Learner::new(&small(false, false), &env).unwrap());
    assert_eq!(plain.memory_slices(), [(String::new(), vec![])]);
    assert_eq!(plain.options_slice(&[]).unwrap(), plain.options_policy);
    assert!(plain.options_slice(&[1]).is_err());
}

#[test]
fn bad_memory_policy_documents_say_what_is_wrong() {
    let env = GridWorld::default();
    let mut spec = small_memory();
    spec.learn.memory = 2;
    let learner = Learner::new(&spec, &env).unwrap();
    let good = unsummed(serde_json::from_str(&Policy::new(&learner).to_json().unwrap()).unwrap());
    type Break = fn(&mut serde_json::Value);
    let cases: [(&str, Break); 7] = [
        ("without memory; a memory policy gives", |d| {
            d["options_policy"][0].as_object_mut().unwrap().remove("memory");
        }),
        ("which is not 3 buckets in 0..=2", |d| d["options_policy"][0]["memory"][1] = 3.into()),
        ("which is not 3 buckets in 0..=2", |d| {
            d["options_policy"][0]["memory"].as_array_mut().unwrap().pop();
        }),
        ("does not cover state index 0 with memory [0, 0, 0]", |d| {
            d["options_policy"].as_array_mut().unwrap().remove(0);
        }),
        ("memory.buckets is 0", |d| d["memory"]["buckets"] = 0.into()),
        ("memory names 3 regions but lists the states of 2", |d| {
            d["memory"]["states"].as_array_mut().unwrap().pop();
        }),
        ("entry with memory, but the document has no memory part", |d| {
            d.as_object_mut().unwrap().remove("memory");
        }),
    ];
    for (want, change) in cases {
        let mut doc = good.clone();
        change(&mut doc);
        let err = Policy::from_json(&doc.to_string()).and_then(|p| p.agent(&env)).unwrap_err();
        assert!(err.to_string().contains(want), "{want}: {err}");
    }
}

#[test]
fn memory_agents_replay_their_counters() {
    use hstl_runtime::eval::Controller;
    let env = GridWorld::default();
    let spec = small_memory();
    let mut learner = Learner::new(&spec, &env).unwrap();
    learner.train(&mut seeded_rng(4), |_, _| {});
    let agent = learner.agent();
    let memory = agent.memory.clone().unwrap();
    let mut controller = AgentController::new(&agent);
    let steps = rollout(&env, &mut controller, 7 * 15 + 5, 400, &mut seeded_rng(6));
    // Replay the counters by hand: every new option is the greedy one on (state, buckets).
    let mut tau = Vec::new();
    memory.start(steps[0].state, &mut tau);
    let mut new_option = true;
    for (i, step) in steps.iter().enumerate() {
        if i > 0 {
            memory.step(step.state, &mut tau);
            let prev = steps[i - 1].decision;
            let p = agent.legs[prev.option][prev.leg];
            new_option = agent.terminate[p][step.state];
        }
        if new_option {
            assert_eq!(step.decision.option, agent.options[memory.observation(step.state, &tau)]);
        }
    }
    // Reset forgets the counters.
    assert_eq!(controller.tau().len(), 3);
    controller.reset();
    assert!(controller.tau().is_empty());
    // The window rate of a reloaded memory policy is the learner's, draw for draw.
    let regions = RegionTable::new(&spec, &env).unwrap();
    let config = WindowConfig { starts: 3, steps: 300, burn_in: 50 };
    let rate = |a: &hstl_runtime::Agent| {
        window_rate(&env, &mut AgentController::new(a), &regions, config, &mut seeded_rng(1))
            .unwrap()
    };
    let back = Policy::from_json(&Policy::new(&learner).to_json().unwrap()).unwrap();
    assert_eq!(rate(&back.agent(&env).unwrap()), rate(&agent));
}

#[test]
fn leg_cycles_run_each_primitive_to_termination_in_turn() {
    use hstl_runtime::eval::LegCycle;
    // A deterministic 5 x 1 line: primitive 0 goes Right and stops at x = 4, primitive 1
    // goes Left and stops at x = 0, primitive 2 stays (Up) and never stops.
    let env = GridWorld::new(5, 1, 1.0).unwrap();
    let agent = hstl_runtime::Agent {
        legs: vec![vec![0], vec![1], vec![2]],
        options: vec![0; 5],
        flat: vec![vec![3; 5], vec![2; 5], vec![0; 5]],
        terminate: vec![
            (0..5).map(|x| x == 4).collect(),
            (0..5).map(|x| x == 0).collect(),
            vec![false; 5],
        ],
        max_steps: 3,
        memory: None,
        goals: None,
        switch: hstl_runtime::Switch::Termination,
        options_q: Vec::new(),
    };
    let mut cycle = LegCycle::new(&agent, vec![0, 1, 2]).unwrap();
    let steps = rollout(&env, &mut cycle, 2, 14, &mut seeded_rng(0));
    let states: Vec<usize> = steps.iter().map(|s| s.state).collect();
    let legs: Vec<usize> = steps.iter().map(|s| s.decision.option).collect();
    // Right until x = 4; Left cut off after 3 steps at x = 1 (max_steps); the stuck leg cut
    // off after 3 steps; Right again until x = 4, then Left.
    assert_eq!(states, [2, 3, 4, 3, 2, 1, 1, 1, 1, 2, 3, 4, 3, 2]);
    assert_eq!(legs, [0, 0, 1, 1, 1, 2, 2, 2, 0, 0, 0, 1, 1, 1]);
    assert!(LegCycle::new(&agent, vec![]).is_err());
    assert!(LegCycle::new(&agent, vec![3]).is_err());
}

#[test]
fn switch_step_interrupts_a_leg_only_for_a_strictly_better_option() {
    use hstl_runtime::Switch;
    // A deterministic 5 x 1 line: option 0 goes Right and stops at x = 4, option 1 goes
    // Left and stops at x = 0. The options policy picks 0 at x = 2 (a tie there) and 1 at
    // x = 3, where option 1 is worth strictly more.
    let env = GridWorld::new(5, 1, 1.0).unwrap();
    let mut q = vec![0.0; 10];
    q[2 * 2..2 * 2 + 2].copy_from_slice(&[1.0, 1.0]);
    q[3 * 2..3 * 2 + 2].copy_from_slice(&[0.0, 1.0]);
    let agent = |switch: Switch| hstl_runtime::Agent {
        legs: vec![vec![0], vec![1]],
        options: vec![0, 0, 0, 1, 0],
        flat: vec![vec![3; 5], vec![2; 5]],
        terminate: vec![(0..5).map(|x| x == 4).collect(), (0..5).map(|x| x == 0).collect()],
        max_steps: 10,
        memory: None,
        goals: None,
        switch,
        options_q: if switch == Switch::Step { q.clone() } else { Vec::new() },
    };
    let run = |switch: Switch| {
        let agent = agent(switch);
        let steps = rollout(&env, &mut AgentController::new(&agent), 2, 6, &mut seeded_rng(0));
        let states: Vec<usize> = steps.iter().map(|s| s.state).collect();
        let options: Vec<usize> = steps.iter().map(|s| s.decision.option).collect();
        (states, options)
    };
    // The paper's runs: option 0 to x = 4, then the options policy's pick there.
    assert_eq!(run(Switch::Termination), (vec![2, 3, 4, 4, 4, 4], vec![0, 0, 0, 0, 0, 0]));
    // At x = 3 option 1 takes over; back at x = 2 the tie keeps it running until it
    // terminates at x = 0, where the options policy picks option 0 again.
    assert_eq!(run(Switch::Step), (vec![2, 3, 2, 1, 0, 1], vec![0, 1, 1, 1, 0, 0]));
}

#[test]
fn switch_step_is_kept_in_policy_json_and_checked_against_the_spec() {
    let env = GridWorld::default();
    let mut spec = small_memory();
    spec.learn.switch = hstl_runtime::Switch::Step;
    let mut learner = Learner::new(&spec, &env).unwrap();
    learner.train(&mut seeded_rng(5), |_, _| {});
    let text = Policy::new(&learner).to_json().unwrap();
    assert!(text.contains("\n  \"switch\": \"step\",\n"), "{}", &text[..200]);
    let back = Policy::from_json(&text).unwrap();
    // With memory and `switch` the document has every field but `goals` (a persistent task
    // has none), in `Policy::FIELDS`' order (`to_json_with` refuses extra fields of these
    // names).
    let fields: Vec<String> = match serde_json::to_value(&back).unwrap() {
        serde_json::Value::Object(m) => m.keys().cloned().collect(),
        other => panic!("not an object: {other}"),
    };
    let written: Vec<&str> = Policy::FIELDS.into_iter().filter(|&f| f != "goals").collect();
    let mut sorted: Vec<String> = written.iter().map(|f| f.to_string()).collect();
    sorted.sort();
    assert_eq!(fields, sorted);
    let at: Vec<usize> =
        written.iter().map(|f| text.find(&format!("\n  \"{f}\": ")).unwrap()).collect();
    assert!(at.is_sorted(), "{at:?}");
    back.check_against(&spec, &env).unwrap();
    let agent = back.agent(&env).unwrap();
    assert_eq!(agent, learner.agent());
    assert_eq!(agent.options_q.len(), 225 * 729 * 3);
    // The paper's settings write no `switch`, so their policies stay as they were.
    let paper = small_memory();
    let mut plain = Learner::new(&paper, &env).unwrap();
    plain.train(&mut seeded_rng(5), |_, _| {});
    let plain_text = Policy::new(&plain).to_json().unwrap();
    assert!(!plain_text.contains("switch"));
    assert!(plain.agent().options_q.is_empty());
    // Training is the same either way: only greedy runs differ.
    assert_eq!(bits(learner.q()), bits(plain.q()));
    // A document stripped of its `switch` no longer matches the spec it names.
    let stripped = text.replace("\n  \"switch\": \"step\",", "");
    let stripped = unsummed(serde_json::from_str(&stripped).unwrap()).to_string();
    let stripped = Policy::from_json(&stripped).unwrap();
    let err = stripped.check_against(&spec, &env).unwrap_err().to_string();
    assert_eq!(
        err,
        "invalid policy: its `switch` is `termination`, but the spec it was trained on has `switch: step`"
    );
    // The words of the error are the document's.
    for w in [hstl_runtime::Switch::Termination, hstl_runtime::Switch::Step] {
        assert_eq!(serde_json::to_string(&w).unwrap(), format!("\"{}\"", w.word()));
    }
    // An unknown value is refused when the document is read.
    assert!(
        Policy::from_json(&text.replace("\"switch\": \"step\"", "\"switch\": \"often\"")).is_err()
    );
}

#[test]
fn a_generator_restored_from_its_state_draws_what_it_would_have_drawn() {
    use hstl_runtime::{RngExt, rng_from_state, rng_state};
    let mut rng = seeded_rng(42);
    for _ in 0..37 {
        rng.random::<u32>();
    }
    let (key, stream, pos) = rng_state(&rng);
    let mut back = rng_from_state(key, stream, pos);
    let ahead: Vec<u64> = (0..100).map(|_| rng.random::<u64>()).collect();
    let again: Vec<u64> = (0..100).map(|_| back.random::<u64>()).collect();
    assert_eq!(ahead, again);
}
