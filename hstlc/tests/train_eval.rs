//! `hstlc train` and `hstlc eval` end to end on a small spec: the files of the contract,
//! determinism, and all-or-nothing output.

use std::path::Path;
use std::process::{Command, Output};

fn hstlc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cli"))
        .output()
        .expect("hstlc runs")
}

fn train(out: &Path, seed: &str) -> Output {
    hstlc(&["train", "small.hstl", "--seed", seed, "--out", out.to_str().expect("utf-8 path")])
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn train_writes_the_contract_files_and_eval_replays_them() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("run");
    let o = train(&out, "3");
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("20 episodes"), "{stdout}");

    let policy: serde_json::Value =
        serde_json::from_str(&read(&out.join("policy.json"))).expect("policy.json is JSON");
    for key in [
        "spec",
        "env",
        "state_vars",
        "actions",
        "options",
        "options_policy",
        "flat_policies",
        "primitives",
    ] {
        assert!(policy.get(key).is_some(), "policy.json lacks `{key}`");
    }
    assert_eq!(policy["spec"], "Small");
    assert_eq!(policy["state_vars"], serde_json::json!(["x", "y"]));
    // Every state has a flat choice for each primitive option.
    for p in ["A", "B"] {
        assert_eq!(policy["flat_policies"][p].as_array().map(Vec::len), Some(225), "{p}");
    }
    let entry = &policy["options_policy"][0];
    assert!(entry["state"]["x"].is_number() && entry["choice"].is_string(), "{entry}");

    let curve = read(&out.join("curve.csv"));
    let lines: Vec<&str> = curve.lines().collect();
    assert_eq!(lines[0], "episode,reward");
    assert_eq!(lines.len(), 21);
    assert!(
        lines[1..].iter().all(|l| l.split(',').nth(1).is_some_and(|r| r.parse::<f64>().is_ok()))
    );

    for svg in ["flat_A.svg", "flat_B.svg", "options.svg", "run_1.svg", "run_2.svg", "curve.svg"] {
        assert!(read(&out.join(svg)).contains("<svg"), "{svg} is not an SVG");
    }

    let policy_path = out.join("policy.json");
    let e = hstlc(&[
        "eval",
        policy_path.to_str().expect("utf-8"),
        "--starts",
        "5",
        "--steps",
        "300",
        "--no-optimum",
    ]);
    assert_eq!(e.status.code(), Some(0), "{}", String::from_utf8_lossy(&e.stderr));
    let report = String::from_utf8_lossy(&e.stdout);
    assert!(report.contains("window rate") && report.contains("task robustness"), "{report}");
}

#[test]
fn the_same_seed_gives_the_same_files() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (a, b, c) = (dir.path().join("a"), dir.path().join("b"), dir.path().join("c"));
    for (out, seed) in [(&a, "7"), (&b, "7"), (&c, "8")] {
        assert_eq!(train(out, seed).status.code(), Some(0));
    }
    for file in ["policy.json", "curve.csv", "options.svg", "run_1.svg"] {
        assert_eq!(read(&a.join(file)), read(&b.join(file)), "{file} differs between two runs");
    }
    assert_ne!(read(&a.join("policy.json")), read(&c.join("policy.json")), "seeds 7 and 8 agree");
}

#[test]
fn an_unwritable_output_folder_is_an_error_and_nothing_is_written() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A file where a folder should be: the folder cannot be created.
    let blocker = dir.path().join("file");
    std::fs::write(&blocker, "not a folder").expect("write");
    let o = train(&blocker.join("out"), "1");
    assert_eq!(o.status.code(), Some(2));
    assert!(o.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("cannot write") && stderr.contains("file/out"), "{stderr}");

    // A folder where one output file should go: nothing at all is written.
    let out = dir.path().join("partly");
    std::fs::create_dir_all(out.join("curve.svg")).expect("mkdir");
    let o = train(&out, "1");
    assert_eq!(o.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("curve.svg"), "{stderr}");
    let left: Vec<String> = std::fs::read_dir(&out)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(left, ["curve.svg"], "files were left behind");
}

#[test]
fn eval_scores_other_tasks_by_their_robustness() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("reach");
    let o = hstlc(&["train", "reach.hstl", "--out", out.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let policy = out.join("policy.json");
    let e = hstlc(&["eval", policy.to_str().expect("utf-8"), "--starts", "4", "--steps", "60"]);
    assert_eq!(e.status.code(), Some(0), "{}", String::from_utf8_lossy(&e.stderr));
    let report = String::from_utf8_lossy(&e.stdout);
    assert!(report.contains("task robustness over each run"), "{report}");
    assert!(!report.contains("window rate"), "{report}");
}

/// An SVG without its texts: what a picture draws, whatever its titles say.
fn drawing(svg: &str) -> String {
    let mut out = String::new();
    let mut rest = svg;
    while let Some(start) = rest.find("<text") {
        out.push_str(&rest[..start]);
        let end = rest[start..].find("</text>").map_or(rest.len(), |e| start + e + "</text>".len());
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

/// `study` writes each spec's policy and pictures from its median seed by window rate (the
/// lower seed on a tie), says which in `policy.json` and under the pictures' titles, and
/// they are what `train --seed` of that seed draws.
#[test]
fn study_writes_the_median_seed_as_train_does() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (study, single) = (dir.path().join("study"), dir.path().join("single"));
    let s = hstlc(&[
        "study",
        "small.hstl",
        "--seeds",
        "3",
        "--no-optimum",
        "--out",
        study.to_str().expect("utf-8"),
    ]);
    assert_eq!(s.status.code(), Some(0), "{}", String::from_utf8_lossy(&s.stderr));
    let seeds = read(&study.join("small/seeds.csv"));
    assert_eq!(seeds.lines().count(), 4, "{seeds}");
    let mut by_window: Vec<(f64, u64)> = seeds
        .lines()
        .skip(1)
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            (fields[4].parse().expect("a window rate"), fields[0].parse().expect("a seed"))
        })
        .collect();
    by_window.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let (w, median) = by_window[1];
    let policy: serde_json::Value =
        serde_json::from_str(&read(&study.join("small/policy.json"))).expect("JSON");
    assert_eq!(policy["seed"], median, "{seeds}");
    assert_eq!(train(&single, &median.to_string()).status.code(), Some(0));
    for file in ["policy.json", "curve.csv"] {
        assert_eq!(read(&study.join("small").join(file)), read(&single.join(file)), "{file}");
    }
    for file in ["flat_A.svg", "options.svg", "run_1.svg", "run_2.svg"] {
        let (a, b) = (read(&study.join("small").join(file)), read(&single.join(file)));
        assert_eq!(drawing(&a), drawing(&b), "{file}");
    }
    let run = read(&study.join("small/run_1.svg"));
    let note = format!("seed {median}, the median of 3 seeds by window rate (W = {w:.3})");
    assert!(run.contains("small.hstl: sample run 1"), "{run}");
    assert!(run.contains(&note), "{note} is not in {run}");
    assert!(read(&single.join("run_1.svg")).contains(&format!("seed {median}; 120 steps")));
}

/// `study` on two specs draws their curves in one figure, one mean line each, and writes
/// every seed's rewards in `curves.csv`.
#[test]
fn study_overlays_the_curves_of_every_spec_and_writes_every_seed() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("study");
    let s = hstlc(&[
        "study",
        "small.hstl",
        "small_other.hstl",
        "--seeds",
        "2",
        "--episodes",
        "7",
        "--no-optimum",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(s.status.code(), Some(0), "{}", String::from_utf8_lossy(&s.stderr));
    let csv = read(&out.join("curves.csv"));
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines[0], "spec,seed,episode,reward");
    assert_eq!(lines.len(), 1 + 2 * 2 * 7, "{csv}");
    for (spec, folder) in [("small.hstl", "small"), ("small_other.hstl", "small_other")] {
        for seed in 0..2 {
            let rows: Vec<&str> = lines
                .iter()
                .filter(|l| l.starts_with(&format!("{spec},{seed},")))
                .copied()
                .collect();
            let episodes: Vec<String> =
                rows.iter().map(|l| l.split(',').nth(2).unwrap_or("").to_owned()).collect();
            assert_eq!(episodes, (1..=7).map(|e| e.to_string()).collect::<Vec<_>>());
            // The rewards are the spec's own: its median seed's match its curve.csv.
            let policy: serde_json::Value =
                serde_json::from_str(&read(&out.join(folder).join("policy.json"))).expect("JSON");
            if policy["seed"] == seed {
                let own: Vec<String> = read(&out.join(folder).join("curve.csv"))
                    .lines()
                    .skip(1)
                    .map(|l| l.split(',').nth(1).unwrap_or("").to_owned())
                    .collect();
                let here: Vec<String> =
                    rows.iter().map(|l| l.split(',').nth(3).unwrap_or("").to_owned()).collect();
                assert_eq!(here, own, "{spec} seed {seed}");
            }
        }
    }
    let svg = read(&out.join("curves.svg"));
    let doc = roxmltree::Document::parse(&svg).expect("SVG parses");
    let texts: Vec<String> = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .map(|n| n.text().unwrap_or("").trim().to_owned())
        .collect();
    for wanted in
        ["small.hstl (2 seeds)", "small_other.hstl (2 seeds)", "Learning curves of 2 specs"]
    {
        assert!(texts.iter().any(|t| t == wanted), "{wanted:?} not in {texts:?}");
    }
    // One mean line of 7 points per spec, in two colours.
    let lines: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("polyline"))
        .filter(|n| n.attribute("points").is_some_and(|p| p.split_whitespace().count() == 7))
        .filter_map(|n| n.attribute("stroke"))
        .collect();
    assert_eq!(lines.len(), 2, "{lines:?}");
    assert_ne!(lines[0], lines[1]);
}

/// The sample runs mark every slip of the rollout they draw: replaying it from
/// `policy.json` with the pictures' generator finds as many slips as the picture counts.
#[test]
fn sample_runs_count_the_slips_of_their_rollout() {
    use hstl::runtime::eval::{AgentController, sample_runs};
    use hstl::runtime::{GridWorld, Policy, seeded_rng};
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("run");
    assert_eq!(train(&out, "5").status.code(), Some(0));
    let policy = Policy::from_json(&read(&out.join("policy.json"))).expect("a policy");
    let env = GridWorld::from_params(&policy.env.name, &policy.env.params).expect("its world");
    let agent = policy.agent(&env).expect("its agent");
    let mut rng = seeded_rng(5 ^ hstl::train::PICTURE_SEED);
    let runs = sample_runs(&env, &mut AgentController::new(&agent), 2, 120, &mut rng);
    for (i, run) in runs.iter().enumerate() {
        let slips = run.iter().filter(|s| s.next != env.dest(s.state, s.decision.action)).count();
        let svg = read(&out.join(format!("run_{}.svg", i + 1)));
        assert!(
            svg.contains(&format!("120 moves, {slips} slip")),
            "run {}: {slips} slips, but the picture says otherwise",
            i + 1
        );
        assert!(slips > 0, "slip 0.3 over 120 steps");
    }
}

/// A world file with walls and start cells: `train --world` obeys it, `policy.json` holds
/// it whole, `eval` replays it from `policy.json` alone, and the pictures draw the walls.
#[test]
fn a_world_file_trains_and_eval_replays_it_from_the_policy() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("nook");
    let o = hstlc(&[
        "train",
        "nook.hstl",
        "--world",
        "worlds/nook.toml",
        "--out",
        out.to_str().expect("utf-8 path"),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains("world `nook` (worlds/nook.toml; 5 x 4, 15 walls, slip 0.1)"),
        "{stdout}"
    );
    let policy: serde_json::Value =
        serde_json::from_str(&read(&out.join("policy.json"))).expect("policy.json is JSON");
    assert_eq!(policy["env"]["name"], "nook");
    assert_eq!(policy["env"]["params"]["slip"], 0.1);
    assert_eq!(
        policy["env"]["params"]["map"],
        serde_json::json!(["#####", "#S#.#", "#...#", "#####"])
    );
    // Only the five free cells are states; the walls are not.
    assert_eq!(policy["flat_policies"]["Corner"].as_array().map(Vec::len), Some(5));
    let svg = read(&out.join("flat_Corner.svg"));
    assert!(
        svg.contains("wall") && svg.contains("start cell"),
        "the legend names walls and starts"
    );
    // The world travels in policy.json: eval needs no world file, from any folder.
    let e = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(["eval", out.join("policy.json").to_str().expect("utf-8"), "--starts", "3"])
        .args(["--steps", "200", "--no-optimum"])
        .current_dir(dir.path())
        .output()
        .expect("hstlc runs");
    assert_eq!(e.status.code(), Some(0), "{}", String::from_utf8_lossy(&e.stderr));
    let report = String::from_utf8_lossy(&e.stdout);
    assert!(report.contains("world `nook` (5 x 4, 15 walls, slip 0.1)"), "{report}");
}

/// A `policy.json` written before world files (`env` `gridworld` with `width`, `height`
/// and `p`) still replays, as the open grid it was, with the same figures.
#[test]
fn a_policy_from_before_worlds_still_replays() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("run");
    let o = train(&out, "1");
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let path = out.join("policy.json");
    let mut doc: serde_json::Value = serde_json::from_str(&read(&path)).expect("JSON");
    doc["env"] = serde_json::json!({ "name": "gridworld", "params": { "width": 15, "height": 15, "p": 0.7 } });
    // Written before worlds, it was written before checksums too.
    doc.as_object_mut().expect("an object").remove("checksum");
    let old = dir.path().join("old.json");
    std::fs::write(&old, doc.to_string()).expect("write");
    let eval = |p: &Path| {
        let e = hstlc(&[
            "eval",
            p.to_str().expect("utf-8"),
            "--starts",
            "5",
            "--steps",
            "300",
            "--no-optimum",
        ]);
        assert_eq!(e.status.code(), Some(0), "{}", String::from_utf8_lossy(&e.stderr));
        String::from_utf8_lossy(&e.stdout).into_owned()
    };
    let (new, old) = (eval(&path), eval(&old));
    assert!(old.contains("world `gridworld` (15 x 15, slip 0.3)"), "{old}");
    // Everything after the first line (the world's name) is the same.
    let tail = |s: &str| s.lines().skip(1).collect::<Vec<_>>().join("\n");
    assert_eq!(tail(&new), tail(&old));
}

/// `eval` validates a policy whole before using it: a document edited by hand, damaged or
/// paired with another spec of the same name is an error (exit 2) that says what is wrong.
#[test]
fn eval_refuses_tampered_policies() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("run");
    let o = train(&out, "2");
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let mut good: serde_json::Value =
        serde_json::from_str(&read(&out.join("policy.json"))).expect("JSON");
    // Without its checksum (which refuses any edit first, `hostile.rs`), each edit meets the
    // check of its own field.
    good.as_object_mut().expect("an object").remove("checksum");
    type Edit = fn(&mut serde_json::Value);
    let cases: [(&str, Edit); 5] = [
        ("holds NaN", |d| d["q_tables"]["options"][3] = "7ff8000000000001".into()),
        ("not 16 hex digits", |d| d["q_tables"]["flat"]["A"][5] = "garbage".into()),
        ("shape", |d| {
            d["q_tables"]["options"].as_array_mut().expect("a list").pop();
        }),
        ("`flat_policies` is not what its `q_tables` give", |d| {
            let choice = &mut d["flat_policies"]["A"][40]["choice"];
            *choice = if choice == "Up" { "Down".into() } else { "Up".into() };
        }),
        // Same name, other regions: the termination sets no longer match.
        ("`primitives` is not what its `q_tables` give", |d| {
            let src = d["spec_source"].as_str().expect("source").replace("x < 3", "x < 4");
            d["spec_source"] = src.into();
        }),
    ];
    for (want, edit) in cases {
        let mut doc = good.clone();
        edit(&mut doc);
        let path = dir.path().join("edited.json");
        std::fs::write(&path, doc.to_string()).expect("write");
        let e = hstlc(&["eval", path.to_str().expect("utf-8"), "--no-optimum"]);
        let stderr = String::from_utf8_lossy(&e.stderr);
        assert_eq!(e.status.code(), Some(2), "{want}: {stderr}");
        assert!(e.stdout.is_empty(), "{want}: printed before failing");
        assert!(stderr.contains(want), "{want}: {stderr}");
    }
}

/// A world too large to draw still trains: the policy and curve are written, the grid
/// pictures are left out, and the summary says why.
#[test]
fn a_world_too_large_to_draw_trains_without_grid_pictures() {
    let dir = tempfile::tempdir().expect("temp dir");
    let row = ".".repeat(300);
    let world = format!("name = \"strip\"\nslip = 0.1\nmap = \"\"\"\n{row}\n{row}\n\"\"\"\n");
    std::fs::write(dir.path().join("strip.toml"), world).expect("write the world");
    let spec = "spec Strip {\n    state { x: int in 0..=299, y: int in 0..=1 }\n    let A = x < 3;\n    \
                let B = x > 296;\n    task always[0..] (eventually[0..400] A && eventually[0..400] B);\n    \
                option A;\n    option B;\n    learn { episodes: 2, choices: 3 }\n}\n";
    std::fs::write(dir.path().join("strip.hstl"), spec).expect("write the spec");
    let out = dir.path().join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(["train", "strip.hstl", "--world", "strip.toml", "--out"])
        .arg(&out)
        .current_dir(dir.path())
        .output()
        .expect("hstlc runs");
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(
        stdout.contains(
            "no grid pictures: the world is 300 x 2 cells, and pictures are drawn up to 256 a side"
        ),
        "{stdout}"
    );
    let mut written: Vec<String> = std::fs::read_dir(&out)
        .expect("out")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    written.sort();
    assert_eq!(written, [".hstlc-run", "curve.csv", "curve.svg", "policy.json"]);
}

/// `check` says what `preset: auto` stands for (after the diagnostics, in the human formats
/// only); `study` measures a reach-avoid task against its exact optimum and writes
/// `summary.csv`; `eval` reports the same measure for the policy.
#[test]
fn a_reach_avoid_preset_is_noted_studied_and_evaluated() {
    let check = hstlc(&["check", "reach_avoid.hstl"]);
    assert_eq!(check.status.code(), Some(0));
    let text = String::from_utf8_lossy(&check.stdout);
    assert!(
        text.contains(
            "`preset: auto` stands for\n    option Goal { terminate: Goal, avoid: Band }"
        ),
        "{text}"
    );
    assert!(
        text.contains("learn { episodes: 300, choices: 10, plan: model, flat: { alpha: 0.05 } }"),
        "{text}"
    );
    let json = hstlc(&["check", "reach_avoid.hstl", "--format", "json"]);
    assert_eq!(String::from_utf8_lossy(&json.stdout).trim(), "[]");

    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("study");
    let s = hstlc(&[
        "study",
        "reach_avoid.hstl",
        "--seeds",
        "2",
        "--out",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(s.status.code(), Some(0), "{}", String::from_utf8_lossy(&s.stderr));
    let stdout = String::from_utf8_lossy(&s.stdout);
    assert!(stdout.contains("satisfaction rate P") && stdout.contains("P/P* (P* = "), "{stdout}");
    let summary = read(&out.join("summary.csv"));
    let row: Vec<&str> = summary.lines().nth(1).expect("a row").split(',').collect();
    assert_eq!(row[..2], ["reach_avoid.hstl", "P/P*"], "{summary}");
    let (best, ratio): (f64, f64) = (row[2].parse().expect("P*"), row[3].parse().expect("mean"));
    assert!(best > 0.0 && best <= 1.0 && ratio >= 0.0, "{summary}");
    let seeds = read(&out.join("reach_avoid/seeds.csv"));
    assert!(
        seeds.starts_with("seed,train_secs,steps,reward_last_100,window_rate,satisfaction_rate\n")
    );

    let e = hstlc(&["eval", out.join("reach_avoid/policy.json").to_str().expect("utf-8")]);
    assert_eq!(e.status.code(), Some(0), "{}", String::from_utf8_lossy(&e.stderr));
    let stdout = String::from_utf8_lossy(&e.stdout);
    assert!(
        stdout.contains("reach-avoid: satisfied in")
            && stdout.contains("of 1000 runs of 31 states"),
        "{stdout}"
    );
    assert!(stdout.contains(&format!("P* = {best:.4}")), "{stdout} vs {summary}");
}

/// `train` on a plane world writes the pictures a grid's folder holds, under the same
/// names: each primitive option's arrows, the options policy (with memory, a map per
/// memory slice in the one `options.svg`), two sample runs and the learning curve, each a
/// parsing SVG that draws the world's extent, obstacles and regions.
#[test]
fn train_on_a_plane_world_writes_the_grid_s_pictures() {
    let dir = tempfile::tempdir().expect("temp dir");
    let train_into = |out: &Path| {
        let o = hstlc(&[
            "train",
            "plane_patrol.hstl",
            "--world",
            "yard.toml",
            "--episodes",
            "4",
            "--seed",
            "2",
            "--out",
            out.to_str().expect("utf-8 path"),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let out = dir.path().join("run");
    let stdout = train_into(&out);
    let pictures =
        ["flat_A.svg", "flat_B.svg", "options.svg", "run_1.svg", "run_2.svg", "curve.svg"];
    for name in pictures {
        assert!(stdout.contains(name), "the summary does not name {name}: {stdout}");
        let svg = read(&out.join(name));
        let doc = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg", "{name}");
        let texts: Vec<&str> = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .filter_map(|n| n.text().map(str::trim))
            .collect();
        assert!(texts.iter().any(|t| t.starts_with("plane_patrol.hstl: ")), "{name}: {texts:?}");
        assert!(texts.iter().any(|t| t.starts_with("seed 2")), "{name}: {texts:?}");
        if name != "curve.svg" {
            // The regions, the world's obstacles and start area, the extent's axes.
            for wanted in ["A", "B", "x", "y", "14", "obstacle", "start area"] {
                assert!(texts.contains(&wanted), "{name} lacks `{wanted}`: {texts:?}");
            }
        }
    }
    let options = read(&out.join("options.svg"));
    assert!(options.contains("one step after A") && options.contains("one step after B"));
    let flat = read(&out.join("flat_A.svg"));
    assert!(flat.contains("flat policy of option A") && flat.contains("greedy action"));
    // One arrow per step of the world, 14 x 14, but none on the 8 points inside the pond
    // and the wall; and the legend's.
    let arrows = roxmltree::Document::parse(&flat)
        .expect("parses")
        .descendants()
        .filter(|n| n.has_tag_name("polygon") && n.attribute("fill") == Some("#222222"))
        .filter(|n| n.attribute("points").is_some_and(|p| p.split_whitespace().count() == 7))
        .count();
    assert_eq!(arrows, 14 * 14 - 8 + 1);
    // Twice the task's window, at least 120 steps as on a grid.
    assert!(read(&out.join("run_1.svg")).contains("120 moves"), "the run's length");
    // The same seed draws the same pictures.
    let again = dir.path().join("again");
    train_into(&again);
    for name in pictures {
        assert!(read(&out.join(name)) == read(&again.join(name)), "{name} differs");
    }
}
