//! `hstlc eval --runs DIR` on a grid world (DESIGN.md, "greedy runs as data"): the runs it
//! scores, as CSV, for a reach task and a persistent one.

use std::path::Path;
use std::process::{Command, Output};

fn hstlc(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .output()
        .expect("hstlc runs")
}

fn ok(o: &Output) -> String {
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout.clone()).expect("UTF-8")
}

fn path(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 path")
}

#[test]
fn eval_writes_the_greedy_runs_of_a_grid_policy() {
    for spec in ["examples/suite/paper_reach_avoid.hstl", "examples/specs/surveillance_ot1.hstl"] {
        let dir = tempfile::tempdir().expect("temp dir");
        let out = dir.path().join("trained");
        ok(&hstlc(&["train", spec, "--episodes", "5", "--seed", "1", "--out", path(&out)]));
        let runs = dir.path().join("runs");
        let policy = out.join("policy.json");
        let args = ["eval", path(&policy), "--starts", "3", "--steps", "150", "--no-optimum"];
        let report = ok(&hstlc(&[&args[..], &["--runs", path(&runs)]].concat()));
        assert!(report.contains("wrote 3 greedy runs"), "{spec}: {report}");
        for k in 1..=3 {
            let csv = std::fs::read_to_string(runs.join(format!("run_{k}.csv"))).expect("a run");
            let rows: Vec<&str> = csv.lines().collect();
            assert_eq!(rows[0], "t,x,y,action,option", "{spec}");
            // 150 actions: 151 states and the header.
            assert_eq!(rows.len(), 152, "{spec}: {csv}");
            assert!(rows.last().is_some_and(|r| r.starts_with("150,") && r.ends_with(",,")));
            for (t, row) in rows[1..rows.len() - 1].iter().enumerate() {
                let cells: Vec<&str> = row.split(',').collect();
                assert_eq!(cells.len(), 5, "{row}");
                assert_eq!(cells[0], t.to_string());
                assert!(["Up", "Down", "Left", "Right"].contains(&cells[3]), "{row}");
                assert!(!cells[4].is_empty(), "{row}");
            }
        }
        // The same runs again: the same files.
        let again = dir.path().join("again");
        ok(&hstlc(&[&args[..], &["--runs", path(&again)]].concat()));
        for k in 1..=3 {
            let name = format!("run_{k}.csv");
            assert_eq!(
                std::fs::read(runs.join(&name)).expect("first"),
                std::fs::read(again.join(&name)).expect("second")
            );
        }
        // A folder of the user's own files is not overwritten unasked.
        let mine = dir.path().join("mine");
        std::fs::create_dir(&mine).expect("a folder");
        std::fs::write(mine.join("notes.txt"), "mine").expect("a file");
        let refused = hstlc(&[&args[..], &["--runs", path(&mine)]].concat());
        assert_eq!(refused.status.code(), Some(2), "{spec}");
        assert!(refused.stdout.is_empty(), "decided before printing");
        assert_eq!(std::fs::read_to_string(mine.join("notes.txt")).expect("kept"), "mine");
        // Runs too large to write are refused before anything runs or is printed.
        let huge = dir.path().join("huge");
        let big = ["eval", path(&policy), "--starts", "1000", "--steps", "100000", "--no-optimum"];
        let refused = hstlc(&[&big[..], &["--runs", path(&huge)]].concat());
        assert_eq!(refused.status.code(), Some(2), "{spec}");
        assert!(String::from_utf8_lossy(&refused.stderr).contains("lower --starts or --steps"));
        assert!(refused.stdout.is_empty() && !huge.exists());
    }
}
