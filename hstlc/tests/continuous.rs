//! `hstlc` on continuous worlds, end to end: every example spec checks against the world it
//! names, and `train`, `eval --runs` and `study` work on a plane world file and on
//! `mountain-car`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/specs")
}

fn hstlc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(args)
        .current_dir(examples())
        .output()
        .expect("hstlc runs")
}

fn ok(o: &Output) -> String {
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    assert_eq!(
        o.status.code(),
        Some(0),
        "stdout:\n{stdout}\nstderr:\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    stdout
}

fn path(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

#[test]
fn every_example_spec_checks_against_the_world_it_names() {
    let mut specs: Vec<String> = std::fs::read_dir(examples())
        .expect("examples/specs")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".hstl"))
        .collect();
    specs.sort();
    assert!(specs.len() >= 15, "{specs:?}");
    let mut args = vec!["check", "--format", "concise"];
    args.extend(specs.iter().map(String::as_str));
    let out = ok(&hstlc(&args));
    assert!(out.contains(&format!("checked {} files: no problems", specs.len())), "{out}");
}

#[test]
fn a_plane_world_file_trains_evaluates_and_writes_its_runs() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("harbour");
    let stdout = ok(&hstlc(&[
        "train",
        "harbour_reach.hstl",
        "--episodes",
        "300",
        "--seed",
        "4",
        "--out",
        path(&out),
    ]));
    assert!(stdout.contains("world `harbour` (../worlds/harbour.toml; plane 10 x 10"), "{stdout}");
    assert!(stdout.contains("no exact optimum on a continuous world"), "{stdout}");
    let policy: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("policy.json")).expect("policy"))
            .expect("policy.json is JSON");
    assert_eq!(policy["env"]["name"], "harbour");
    assert_eq!(policy["state_vars"], serde_json::json!(["x", "y"]));

    let runs = dir.path().join("runs");
    let report = ok(&hstlc(&[
        "eval",
        path(&out.join("policy.json")),
        "--starts",
        "3",
        "--runs",
        path(&runs),
    ]));
    assert!(report.contains("satisfied in"), "{report}");
    assert!(report.contains("planned reference: satisfied in"), "{report}");
    for k in 1..=3 {
        let csv = std::fs::read_to_string(runs.join(format!("run_{k}.csv"))).expect("a run");
        let rows: Vec<&str> = csv.lines().collect();
        assert_eq!(rows[0], "t,x,y,action,option");
        // `[0..60]` ends before 60, so the task looks 59 steps ahead: a run of 60 actions
        // decides it, 61 states and the header.
        assert_eq!(rows.len(), 62, "{csv}");
        assert!(rows.last().is_some_and(|r| r.ends_with(",,")), "{csv}");
        assert!(rows[1..rows.len() - 1].iter().all(|r| {
            let cells: Vec<&str> = r.split(',').collect();
            cells.len() == 5 && ["E", "N", "W", "S"].contains(&cells[3])
        }));
    }
}

#[test]
fn mountain_car_trains_and_studies_with_its_planned_reference() {
    let dir = tempfile::tempdir().expect("temp dir");
    let stdout = ok(&hstlc(&[
        "study",
        "mountain_car_patrol.hstl",
        "--seeds",
        "1",
        "--episodes",
        "20",
        "--out",
        path(dir.path()),
    ]));
    assert!(stdout.contains("window rate W"), "{stdout}");
    assert!(stdout.contains("planned reference W"), "{stdout}");
    for picture in ["flat_left.svg", "flat_right.svg", "options.svg", "run_1.svg"] {
        let svg = std::fs::read_to_string(dir.path().join("mountain_car_patrol").join(picture))
            .unwrap_or_else(|e| panic!("{picture}: {e}"));
        assert!(svg.contains("<svg"), "{picture}");
    }
    let policy = dir.path().join("mountain_car_patrol/policy.json");
    let report = ok(&hstlc(&["eval", path(&policy), "--starts", "2", "--steps", "400"]));
    assert!(report.contains("window rate"), "{report}");
    assert!(report.contains("mountain-car"), "{report}");
}
