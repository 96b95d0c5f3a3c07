//! A policy whose options level reads the task's goals (`"goals"`, and `"goals_met"` in each
//! options entry) through the typed one-pass `policy.json` reader: it replays to the agent
//! that was trained, so `hstlc eval` reports what the trained policy does; hand edits of
//! the goals are refused; a goal too long to write out is refused before anything runs.

use hstl::evaluate::{self, Runs};
use hstl::runtime::{Env, GridWorld, Learner};
use serde_json::Value;

/// Reach the corner within 40 steps and never enter the band: `preset: auto` adds
/// `keep_clear`, and the options level tracks one goal.
const REACH_KEEP: &str = "spec ReachKeep {
    state { x: int in 0..=14, y: int in 0..=14 }
    let Goal = x < 3 && y > 11;
    let Band = 2 < x && 6 < y < 9;
    task eventually[0..=40] Goal && always !Band;
    option Goal;
    learn { preset: auto, episodes: 200 }
}
";

fn trained(seed: u64) -> (hstl::runtime::TaskSpec, hstl::train::Trained, String) {
    let loaded = hstl::load::load(REACH_KEEP, None).expect("checks");
    let task = hstl::train::trainable(&loaded.spec, REACH_KEEP, "s.hstl").expect("trainable");
    let world = GridWorld::builtin("paper").expect("paper");
    let trained = hstl::train::train(&task, &world, seed, |_, _| {}).expect("trains");
    let text = hstl::train::policy_json(&trained.policy, REACH_KEEP, seed).expect("writes");
    (task, trained, text)
}

#[test]
fn a_goals_policy_read_back_is_the_policy_trained_and_evaluates_the_same() {
    for seed in [1, 3] {
        let (task, trained, text) = trained(seed);
        assert!(task.options.iter().any(|o| o.name == "keep_clear"), "the preset's hold");
        let goals = trained.agent.goals.as_ref().expect("the options level tracks the goal");
        let codes = goals.codes();
        assert_eq!(codes, 2);
        let replay = evaluate::replay(&text).expect("replays");
        // The document lists the goal, and an options entry per state and goals met.
        assert_eq!(replay.policy.goals.as_ref().map(Vec::len), Some(1));
        let states = replay.env.num_states();
        assert_eq!(replay.policy.options_policy.len(), states * codes);
        assert!(replay.policy.options_policy.iter().all(|e| e.goals_met.is_some()));
        // The agent read back is the one trained, bit for bit, so every figure is.
        assert_eq!(replay.agent, trained.agent, "seed {seed}");
        let world = GridWorld::builtin("paper").expect("paper");
        let read = hstl::train::reach_avoid_summary(&replay.spec, &replay.env, &replay.agent, 0)
            .expect("evaluates")
            .expect("a reach-avoid task");
        let kept = hstl::train::reach_avoid_summary(&task, &world, &trained.agent, 0)
            .expect("evaluates")
            .expect("a reach-avoid task");
        assert_eq!(read, kept, "seed {seed}");
        let runs = Runs { starts: 20, ..Runs::default() };
        let in_memory = evaluate::Replay {
            policy: trained.policy.clone(),
            spec: task.clone(),
            env: world,
            agent: trained.agent.clone(),
            source: REACH_KEEP.to_string(),
            seed: Some(seed),
        };
        assert_eq!(
            evaluate::evaluate(&replay, runs).expect("evaluates"),
            evaluate::evaluate(&in_memory, runs).expect("evaluates"),
            "seed {seed}"
        );
        // Written again, the document is the same text.
        let again = hstl::train::policy_json(&replay.policy, REACH_KEEP, seed).expect("writes");
        assert_eq!(again, text);
    }
}

/// Edits of the goals, each as a change to the document and what the refusal names.
type Edit = fn(&mut Value);

#[test]
fn edited_goals_are_refused_with_their_reason() {
    let (_, _, text) = trained(1);
    let cases: [(&str, Edit, &str); 6] = [
        (
            "goals removed",
            |d| {
                d.as_object_mut().expect("object").remove("goals");
            },
            "`goals`",
        ),
        ("another goal", |d| d["goals"][0] = Value::from("eventually[0..=41] v0 < 3"), "`goals`"),
        ("goals not a list", |d| d["goals"] = Value::from("x"), "invalid type"),
        (
            "a goal index past the goals",
            |d| d["options_policy"][0]["goals_met"] = Value::from(vec![5]),
            "not indices of its 1 goals",
        ),
        (
            "goals met not a list",
            |d| d["options_policy"][0]["goals_met"] = Value::from("all"),
            "invalid type",
        ),
        (
            "an entry without goals met",
            |d| {
                d["options_policy"][0].as_object_mut().expect("entry").remove("goals_met");
            },
            "without goals_met",
        ),
    ];
    for (what, edit, want) in cases {
        let mut doc: Value = serde_json::from_str(&text).expect("JSON");
        unsummed(&mut doc);
        edit(&mut doc);
        let edited = serde_json::to_string(&doc).expect("JSON");
        let e = evaluate::replay(&edited).err().unwrap_or_else(|| panic!("{what}: accepted"));
        assert!(e.message.contains(want), "{what}: {}", e.message);
    }
    // An entry moved to the other set of goals met: that observation is then listed twice
    // and the one it left is missing.
    let mut doc: Value = serde_json::from_str(&text).expect("JSON");
    unsummed(&mut doc);
    let all = doc["options_policy"].as_array().expect("entries");
    let first = all.iter().position(|e| e["goals_met"] == Value::from(Vec::<usize>::new()));
    let i = first.expect("an entry with no goal met");
    doc["options_policy"][i]["goals_met"] = Value::from(vec![0]);
    let Err(e) = evaluate::replay(&serde_json::to_string(&doc).expect("JSON")) else {
        panic!("a moved entry is accepted")
    };
    assert!(e.message.contains("options_policy"), "{}", e.message);
    // The field twice, as text.
    let twice = text.replacen("\"goals\":", "\"goals\": [], \"goals\":", 1);
    let Err(e) = evaluate::replay(&twice) else { panic!("a field twice is accepted") };
    assert!(e.message.contains("given twice"), "{}", e.message);
}

/// A goal of nested lets, each using the one before twice: 2^depth copies written out.
fn nested(depth: usize) -> String {
    let mut lets = vec!["let a0 = x > 7 && y < 2;".to_string()];
    for k in 1..=depth {
        lets.push(format!("let a{k} = (a{} || y > {k}) && (a{} || x > {k});", k - 1, k - 1));
    }
    format!(
        "spec Deep {{
    state {{ x: int in 0..=14, y: int in 0..=14 }}
    {}
    let O = x > 2 && x < 7 && y > 2 && y < 7;
    task eventually[0..=25] a{depth} && always[0..=100] !O;
    option G {{ reach: x > 7 && y < 2 }}
    learn {{ preset: auto, episodes: 20 }}
}}
",
        lets.join("\n    ")
    )
}

#[test]
fn a_goal_too_long_to_write_out_is_refused_before_anything_runs() {
    // Written out, the goal doubles with each let: 40 of them made `train` hang, writing
    // a `policy.json` without end.
    for depth in [16, 40] {
        let src = nested(depth);
        let checked = hstl::lang::check(&src);
        let d = checked
            .diagnostics
            .iter()
            .find(|d| d.code == "HSTL084")
            .unwrap_or_else(|| panic!("depth {depth}: accepted"));
        assert!(d.message.contains("more than the 1.0 MiB a goal may"), "{}", d.message);
        assert_eq!(&src[d.range.clone()], format!("eventually[0..=25] a{depth}"));
        // Past the checker, the learner refuses it without writing it out.
        let task = hstl::lower::task_spec(&checked.specs[0], &src).expect("lowers");
        let world = GridWorld::builtin("paper").expect("paper");
        let Err(e) = Learner::new(&task, &world) else { panic!("depth {depth}: trains") };
        let e = e.to_string();
        assert!(e.contains("goal 1 of the task is longer than 1048576 bytes"), "{e}");
    }
    // A shallower one checks, trains and writes its goal whole.
    let src = nested(8);
    let loaded = hstl::load::load(&src, None).expect("checks");
    let task = hstl::train::trainable(&loaded.spec, &src, "s.hstl").expect("trainable");
    let world = GridWorld::builtin("paper").expect("paper");
    let trained = hstl::train::train(&task, &world, 0, |_, _| {}).expect("trains");
    let goals = trained.policy.goals.expect("a goal");
    assert_eq!(goals.len(), 1);
    assert!(goals[0].len() > 1 << 8, "the lets written out: {} bytes", goals[0].len());
}

/// Takes out the document's checksum, which refuses any edit before the fields' own checks
/// (held in `hstlc/tests/hostile.rs`): each edit here meets the check of its field.
fn unsummed(doc: &mut Value) {
    doc.as_object_mut().expect("an object").remove("checksum");
}
