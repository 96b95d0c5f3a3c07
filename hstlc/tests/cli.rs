//! The command line's contract, one snapshot per case: exit status, standard output and
//! standard error of `hstlc` run in `tests/cli/` on the fixtures there.

use std::io::Write;
use std::process::{Command, Stdio};

/// A case: its snapshot name, the arguments, and what standard input holds.
struct Case {
    name: &'static str,
    args: &'static [&'static str],
    stdin: &'static str,
}

const fn case(name: &'static str, args: &'static [&'static str]) -> Case {
    Case { name, args, stdin: "" }
}

const CASES: &[Case] = &[
    // check
    case("check_clean", &["check", "surveillance.hstl"]),
    case("check_warnings_exit_0", &["check", "warnings.hstl"]),
    case("check_errors_full", &["check", "errors.hstl"]),
    case("check_errors_concise", &["check", "--format", "concise", "errors.hstl"]),
    case("check_errors_json", &["check", "--format", "json", "errors.hstl"]),
    case("check_errors_sarif", &["check", "--format", "sarif", "errors.hstl"]),
    case("check_many_files", &["check", "--format", "concise", "warnings.hstl", "errors.hstl"]),
    Case {
        name: "check_stdin",
        args: &["check", "--format", "concise", "--stdin-filename", "piped.hstl", "-"],
        stdin: "spec S { state { x: int in 0..=3 } task x > ; }",
    },
    case("check_missing_file", &["check", "surveillance.hstl", "nowhere.hstl"]),
    case("check_bad_format", &["check", "--format", "xml", "errors.hstl"]),
    case("check_no_files", &["check"]),
    case("check_plane_notes", &["check", "--format", "concise", "plane_patrol.hstl"]),
    // explain
    case("explain_code", &["explain", "HSTL003"]),
    case("explain_lowercase", &["explain", "hstl101"]),
    case("explain_unknown", &["explain", "HSTL999"]),
    // monitor
    case("monitor_task", &["monitor", "surveillance.hstl", "--trace", "trace.csv"]),
    case("monitor_signal", &["monitor", "surveillance.hstl", "--trace", "trace.csv", "--signal"]),
    case(
        "monitor_let_signal",
        &["monitor", "surveillance.hstl", "--trace", "trace.csv", "--formula", "A", "--signal"],
    ),
    case("monitor_infinite", &["monitor", "reals.hstl", "--trace", "infinite.csv"]),
    case("monitor_int_not_whole", &["monitor", "surveillance.hstl", "--trace", "infinite.csv"]),
    case(
        "monitor_unknown_formula",
        &["monitor", "surveillance.hstl", "--trace", "trace.csv", "--formula", "Nope"],
    ),
    case(
        "monitor_missing_column",
        &["monitor", "surveillance.hstl", "--trace", "missing_column.csv"],
    ),
    case("monitor_not_a_number", &["monitor", "surveillance.hstl", "--trace", "not_a_number.csv"]),
    case("monitor_nan_expression", &["monitor", "sqrt.hstl", "--trace", "sqrt.csv", "--signal"]),
    Case {
        name: "monitor_nan_expression_online",
        args: &["monitor", "sqrt.hstl", "--online", "--trace", "-"],
        stdin: "x\n4\n-1\n9\n",
    },
    case("monitor_windows_clipped", &["monitor", "patrol.hstl", "--trace", "cycle.csv"]),
    case(
        "monitor_windows_complete",
        &["monitor", "patrol.hstl", "--trace", "cycle.csv", "--windows", "complete"],
    ),
    case(
        "monitor_windows_complete_signal",
        &["monitor", "patrol.hstl", "--trace", "cycle.csv", "--windows", "complete", "--signal"],
    ),
    case(
        "monitor_windows_complete_undetermined",
        &["monitor", "patrol.hstl", "--trace", "cycle_short.csv", "--windows", "complete"],
    ),
    case(
        "monitor_windows_complete_batch",
        &[
            "monitor",
            "patrol.hstl",
            "--trace",
            "cycle.csv",
            "--trace",
            "cycle_short.csv",
            "--windows",
            "complete",
        ],
    ),
    case(
        "monitor_windows_complete_bounded_online",
        &[
            "monitor",
            "patrol.hstl",
            "--formula",
            "SoonA",
            "--trace",
            "cycle.csv",
            "--online",
            "--windows",
            "complete",
        ],
    ),
    case("monitor_ragged_row", &["monitor", "surveillance.hstl", "--trace", "ragged.csv"]),
    case("monitor_empty_file", &["monitor", "surveillance.hstl", "--trace", "empty.csv"]),
    case("monitor_header_only", &["monitor", "surveillance.hstl", "--trace", "header_only.csv"]),
    case("monitor_missing_trace", &["monitor", "surveillance.hstl", "--trace", "nowhere.csv"]),
    case("monitor_spec_errors", &["monitor", "errors.hstl", "--trace", "trace.csv"]),
    case("monitor_two_specs", &["monitor", "two_specs.hstl", "--trace", "x.csv"]),
    case(
        "monitor_pick_spec",
        &["monitor", "two_specs.hstl", "--spec", "Second", "--trace", "x.csv"],
    ),
    case(
        "monitor_unknown_spec",
        &["monitor", "two_specs.hstl", "--spec", "Third", "--trace", "x.csv"],
    ),
    Case {
        name: "monitor_trace_on_stdin",
        args: &["monitor", "two_specs.hstl", "--spec", "First", "--trace", "-", "--signal"],
        stdin: "x\n0\n9\n1\n",
    },
    // many traces: one row each, in the order given (a folder: its `.csv` files by name)
    case(
        "monitor_batch",
        &["monitor", "surveillance.hstl", "--trace", "trace.csv", "--trace", "traces"],
    ),
    case(
        "monitor_batch_signal",
        &["monitor", "surveillance.hstl", "--trace", "traces", "--formula", "A", "--signal"],
    ),
    case(
        "monitor_batch_bad_trace",
        &["monitor", "surveillance.hstl", "--trace", "traces", "--trace", "missing_column.csv"],
    ),
    case("monitor_batch_empty_folder", &["monitor", "surveillance.hstl", "--trace", "worlds"]),
    case("monitor_stdin_twice", &["monitor", "surveillance.hstl", "--trace", "-", "--trace", "-"]),
    // a stream: `t,robustness` rows as soon as they are final
    Case {
        name: "monitor_online_let",
        args: &["monitor", "surveillance.hstl", "--trace", "-", "--online", "--formula", "A"],
        stdin: "x,y\n5,12\n0,0\n6,11\n",
    },
    case(
        "monitor_online_unbounded",
        &["monitor", "surveillance.hstl", "--trace", "trace.csv", "--online"],
    ),
    case(
        "monitor_online_batch",
        &["monitor", "surveillance.hstl", "--trace", "traces", "--online"],
    ),
    // dense time: a `time` variable; stamps, empty cells, change points
    case("monitor_dense_task", &["monitor", "dense.hstl", "--trace", "dense.csv"]),
    case("monitor_dense_signal", &["monitor", "dense.hstl", "--trace", "dense.csv", "--signal"]),
    case(
        "monitor_dense_let_signal",
        &["monitor", "dense.hstl", "--trace", "dense.csv", "--formula", "Soon", "--signal"],
    ),
    case(
        "monitor_dense_irregular",
        &["monitor", "dense.hstl", "--trace", "dense_irregular.csv", "--signal"],
    ),
    case(
        "monitor_dense_nanoseconds",
        &["monitor", "dense_ns.hstl", "--trace", "dense_ns.csv", "--signal"],
    ),
    Case {
        name: "monitor_dense_online",
        args: &["monitor", "dense.hstl", "--trace", "-", "--online", "--formula", "Soon"],
        stdin: "t,x,y\n0,1,5\n1,2,\n1.5,,6\n2,3,\n3.5,0.5,\n4,,-1\n5,4,\n",
    },
    case(
        "monitor_dense_batch",
        &["monitor", "dense.hstl", "--trace", "dense.csv", "--trace", "dense_irregular.csv"],
    ),
    // `--max-gap`: a gap larger than the bound is an error naming both stamps
    case(
        "monitor_dense_max_gap",
        &["monitor", "dense.hstl", "--trace", "dense_irregular.csv", "--max-gap", "0.1"],
    ),
    case(
        "monitor_dense_max_gap_held",
        &["monitor", "dense.hstl", "--trace", "dense.csv", "--max-gap", "1.5", "--signal"],
    ),
    case(
        "monitor_dense_max_gap_nanoseconds",
        &["monitor", "dense_ns.hstl", "--trace", "dense_ns.csv", "--max-gap", "1000000000"],
    ),
    Case {
        name: "monitor_dense_max_gap_online",
        args: &["monitor", "dense.hstl", "--trace", "-", "--online", "--max-gap", "1"],
        stdin: "t,x,y\n0,1,5\n0.5,2,\n1,,6\n1.25,3,\n2.5,0.5,\n3,,-1\n",
    },
    case(
        "monitor_dense_max_gap_not_a_time",
        &["monitor", "dense.hstl", "--trace", "dense.csv", "--max-gap", "soon"],
    ),
    case(
        "monitor_max_gap_discrete",
        &["monitor", "surveillance.hstl", "--trace", "trace.csv", "--max-gap", "1"],
    ),
    // `--relative`: times from the first stamp, exactly
    case(
        "monitor_dense_relative",
        &["monitor", "dense.hstl", "--trace", "dense_offset.csv", "--signal", "--relative"],
    ),
    case(
        "monitor_dense_relative_nanoseconds",
        &["monitor", "dense_ns.hstl", "--trace", "dense_ns.csv", "--signal", "--relative"],
    ),
    case(
        "monitor_dense_offset",
        &["monitor", "dense.hstl", "--trace", "dense_offset.csv", "--signal"],
    ),
    Case {
        name: "monitor_dense_relative_online",
        args: &[
            "monitor",
            "dense.hstl",
            "--trace",
            "-",
            "--online",
            "--relative",
            "--formula",
            "Soon",
        ],
        stdin: "t,x,y\n-1.5,1,5\n-0.5,2,\n0,,6\n0.5,3,\n2,0.5,\n2.5,,-1\n3.5,4,\n",
    },
    // issue 30's campaign: stamps 2^64 units apart (no help before), a gap with an exponent
    // (refused as "not a number of 0 or more" before)
    case(
        "monitor_dense_stamp_span",
        &["monitor", "dense_ns.hstl", "--trace", "dense_stamp_span.csv", "--signal"],
    ),
    case(
        "monitor_dense_max_gap_exponent",
        &["monitor", "dense.hstl", "--trace", "dense.csv", "--max-gap", "1e300"],
    ),
    case("monitor_dense_bad_stamp", &["monitor", "dense.hstl", "--trace", "dense_bad_stamp.csv"]),
    case("monitor_dense_bad_cell", &["monitor", "dense.hstl", "--trace", "dense_bad_cell.csv"]),
    case(
        "monitor_dense_missing_column",
        &["monitor", "dense.hstl", "--trace", "missing_column.csv"],
    ),
    case(
        "monitor_dense_windows_complete",
        &["monitor", "dense.hstl", "--trace", "dense.csv", "--windows", "complete", "--signal"],
    ),
    case(
        "monitor_dense_windows_complete_value",
        &["monitor", "dense_complete.hstl", "--trace", "dense_dip.csv", "--windows", "complete"],
    ),
    case(
        "monitor_dense_windows_clipped_value",
        &["monitor", "dense_complete.hstl", "--trace", "dense_dip.csv", "--signal"],
    ),
    case(
        "monitor_dense_windows_complete_batch",
        &[
            "monitor",
            "dense.hstl",
            "--trace",
            "dense.csv",
            "--trace",
            "dense_irregular.csv",
            "--windows",
            "complete",
        ],
    ),
    case(
        "monitor_dense_windows_complete_nanoseconds",
        &[
            "monitor",
            "dense_ns.hstl",
            "--trace",
            "dense_ns.csv",
            "--signal",
            "--windows",
            "complete",
        ],
    ),
    case(
        "monitor_dense_windows_complete_online",
        &["monitor", "dense.hstl", "--trace", "dense.csv", "--windows", "complete", "--online"],
    ),
    case(
        "monitor_decimal_bound_discrete",
        &["monitor", "dense_decimal_discrete.hstl", "--trace", "dense.csv"],
    ),
    // `--online` over nanosecond stamps, backwards stamps, a gap in nanoseconds, NaN
    Case {
        name: "monitor_dense_nanoseconds_online",
        args: &["monitor", "dense_ns.hstl", "--trace", "dense_ns.csv", "--online"],
        stdin: "",
    },
    Case {
        name: "monitor_dense_nanoseconds_relative_online",
        args: &["monitor", "dense_ns.hstl", "--trace", "dense_ns.csv", "--online", "--relative"],
        stdin: "",
    },
    Case {
        name: "monitor_dense_nanoseconds_complete_online",
        args: &[
            "monitor",
            "dense_ns.hstl",
            "--trace",
            "dense_ns.csv",
            "--online",
            "--windows",
            "complete",
        ],
        stdin: "",
    },
    Case {
        name: "monitor_dense_max_gap_nanoseconds_online",
        args: &[
            "monitor",
            "dense_ns.hstl",
            "--trace",
            "dense_ns.csv",
            "--online",
            "--max-gap",
            "1000000000",
        ],
        stdin: "",
    },
    Case {
        name: "monitor_dense_bad_stamp_online",
        args: &["monitor", "dense.hstl", "--trace", "-", "--online", "--formula", "Soon"],
        stdin: "t,x,y\n0,1,5\n0.5,2,\n0.25,3,\n",
    },
    Case {
        name: "monitor_dense_mixed_stamps_online",
        args: &["monitor", "dense_ns.hstl", "--trace", "-", "--online"],
        stdin: "t,x,y\n1700000000000000000,1,5\n1700000000000000000.5,2,\n",
    },
    Case {
        name: "monitor_dense_nan_online",
        args: &["monitor", "dense_sqrt.hstl", "--trace", "-", "--online"],
        stdin: "t,x\n0,4\n0.5,9\n1.25,-1\n2,4\n",
    },
    Case {
        name: "monitor_dense_unbounded_online",
        args: &["monitor", "dense_complete.hstl", "--trace", "-", "--online"],
        stdin: "t,x\n0,4\n0.5,0\n1.25,2\n",
    },
    Case {
        name: "monitor_dense_unbounded_complete_online",
        args: &[
            "monitor",
            "dense_complete.hstl",
            "--trace",
            "-",
            "--online",
            "--windows",
            "complete",
        ],
        stdin: "t,x\n0,4\n",
    },
    case("explain_dense_code", &["explain", "HSTL082"]),
    // train and eval: the errors (successful runs are in tests/train_eval.rs)
    case("train_no_options", &["train", "no_options.hstl", "--out", "unused"]),
    case("train_float_state", &["train", "float_state.hstl", "--out", "unused"]),
    case("train_unknown_world", &["train", "small.hstl", "--world", "mars", "--out", "unused"]),
    case(
        "train_missing_world_file",
        &["train", "small.hstl", "--world", "mars.toml", "--out", "unused"],
    ),
    // worlds: the spec against the map (world file errors are in `world_file_errors`)
    case("check_world_mismatch", &["check", "--world", "four-rooms", "surveillance.hstl"]),
    case("check_world_file", &["check", "--world", "worlds/nook.toml", "nook.hstl"]),
    // a spec that names no world is checked alone (a custom environment's spec)
    case("check_no_world_alone", &["check", "nook.hstl"]),
    // a spec names its world: a file relative to the spec, `--world` overrides it with a note
    case("check_named_world_file", &["check", "nook_named.hstl"]),
    case("check_named_world_override", &["check", "--world", "paper", "nook_named.hstl"]),
    case("check_named_world_mismatch_and_more", &["check", "nook_wrong_world.hstl"]),
    case("check_named_world_missing", &["check", "--format", "concise", "nook_missing_world.hstl"]),
    // a task with a constant robustness: a warning; monitor computes it; train refuses it
    case("check_constant_task", &["check", "--format", "concise", "constant.hstl"]),
    case("monitor_constant_task", &["monitor", "constant.hstl", "--trace", "trace.csv"]),
    case("train_constant_task", &["train", "constant.hstl", "--out", "unused"]),
    case("train_zero_episodes", &["train", "small.hstl", "--episodes", "0", "--out", "unused"]),
    case("train_spec_errors", &["train", "errors.hstl", "--out", "unused"]),
    case("eval_not_a_policy", &["eval", "not_a_policy.json"]),
    case("eval_missing_file", &["eval", "nowhere.json"]),
    case("study_no_seeds", &["study", "small.hstl", "--seeds", "0"]),
    // sizes a user controls are checked before anything is allocated (issue 11, class 5)
    case("train_huge_episodes", &["train", "small.hstl", "--episodes", "4611686018427387904"]),
    case("train_episodes_not_a_count", &["train", "small.hstl", "--episodes", "1e12"]),
    case("eval_huge_steps", &["eval", "nowhere.json", "--steps", "18446744073709551615"]),
    case(
        "eval_too_many_steps_in_all",
        &["eval", "nowhere.json", "--starts", "100000", "--steps", "1000000"],
    ),
    case("study_too_many_threads", &["study", "small.hstl", "--threads", "5000"]),
];

#[test]
fn cli_cases() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cli");
    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path("snapshots/cli");
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| {
        for case in CASES {
            let mut child = Command::new(env!("CARGO_BIN_EXE_hstlc"))
                .args(case.args)
                .current_dir(dir)
                .env_remove("NO_COLOR")
                .env_remove("CLICOLOR_FORCE")
                .stdin(Stdio::piped())
                .stdout(Stdio::piped())
                .stderr(Stdio::piped())
                .spawn()
                .expect("hstlc starts");
            child.stdin.take().expect("piped").write_all(case.stdin.as_bytes()).expect("stdin");
            let out = child.wait_with_output().expect("hstlc ends");
            let status = out.status.code().map_or("killed".to_string(), |c| c.to_string());
            let stdout = String::from_utf8_lossy(&out.stdout);
            let stderr = String::from_utf8_lossy(&out.stderr);
            insta::assert_snapshot!(
                case.name,
                format!(
                    "$ hstlc {}\nexit: {status}\n--- stdout\n{stdout}--- stderr\n{stderr}",
                    case.args.join(" ")
                )
            );
        }
    });
}

/// Every malformed world file in `tests/cli/worlds/invalid` is an error at its file, line
/// and column, with a help, exit status 2 and nothing on standard output.
#[test]
fn world_file_errors() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cli");
    let mut files: Vec<_> = std::fs::read_dir(format!("{dir}/worlds/invalid"))
        .expect("the fixtures")
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert!(files.len() >= 8, "{files:?}");
    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path("snapshots/cli");
    settings.set_prepend_module_to_snapshot(false);
    settings.bind(|| {
        for file in files {
            let world = format!("worlds/invalid/{file}");
            let out = Command::new(env!("CARGO_BIN_EXE_hstlc"))
                .args(["check", "small.hstl", "--world", &world])
                .current_dir(dir)
                .output()
                .expect("hstlc runs");
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{file}: {stderr}");
            assert!(out.stdout.is_empty(), "{file}");
            assert!(stderr.starts_with(&format!("error: {world}:")), "{file}: {stderr}");
            assert!(stderr.contains("\n  help: "), "{file}: {stderr}");
            insta::assert_snapshot!(format!("world_{}", file.trim_end_matches(".toml")), stderr);
        }
    });
}

/// Colour codes belong on terminals only: piped output has none.
#[test]
fn piped_output_has_no_colour() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cli");
    let out = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(["check", "errors.hstl"])
        .current_dir(dir)
        .output()
        .expect("hstlc runs");
    assert!(!out.stdout.contains(&0x1b), "escape codes in piped output");
    assert_eq!(out.status.code(), Some(1));
}

/// The machine formats parse, and hold the fields the contract names.
#[test]
fn json_and_sarif_are_valid() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cli");
    let run = |format: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_hstlc"))
            .args(["check", "--format", format, "errors.hstl", "warnings.hstl"])
            .current_dir(dir)
            .output()
            .expect("hstlc runs");
        serde_json::from_slice::<serde_json::Value>(&out.stdout).expect("valid JSON")
    };
    let json = run("json");
    let items = json.as_array().expect("an array");
    assert!(items.len() >= 4);
    for item in items {
        for key in [
            "file",
            "severity",
            "code",
            "message",
            "line",
            "column",
            "end_line",
            "end_column",
            "help",
        ] {
            assert!(item.get(key).is_some(), "missing `{key}` in {item}");
        }
        assert!(matches!(item["severity"].as_str(), Some("error" | "warning")));
    }
    let sarif = run("sarif");
    assert_eq!(sarif["version"], "2.1.0");
    assert_eq!(sarif["runs"][0]["results"].as_array().map(Vec::len), Some(items.len()));
}

/// `monitor --online` prints a step's row as soon as its value is final: the first rows
/// arrive while the input is still open (a pipe from a live system).
#[test]
fn online_rows_arrive_before_the_input_ends() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/cli");
    let mut child = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(["monitor", "surveillance.hstl", "--trace", "-", "--online", "--formula", "A"])
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("hstlc starts");
    let mut stdin = child.stdin.take().expect("piped");
    let stdout = child.stdout.take().expect("piped");
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        use std::io::BufRead;
        for line in std::io::BufReader::new(stdout).lines() {
            if tx.send(line.expect("utf-8")).is_err() {
                break;
            }
        }
    });
    let wait = std::time::Duration::from_secs(60);
    stdin.write_all(b"x,y\n5,12\n").expect("write");
    stdin.flush().expect("flush");
    assert_eq!(rx.recv_timeout(wait).expect("the header while the input is open"), "t,robustness");
    assert_eq!(rx.recv_timeout(wait).expect("step 0 while the input is open"), "0,2");
    stdin.write_all(b"0,0\n").expect("write");
    stdin.flush().expect("flush");
    assert_eq!(rx.recv_timeout(wait).expect("step 1 while the input is open"), "1,-10");
    drop(stdin);
    assert_eq!(child.wait().expect("ends").code(), Some(0));
}

/// `--online` prints exactly the rows of `--signal`, for bounded and unbounded formulas,
/// `until` and nested windows, on a trace longer than every window.
#[test]
fn online_rows_are_the_signal() {
    let dir = tempfile::tempdir().expect("temp dir");
    let spec = "spec S {
        state { x: float, y: float }
        let P = x > 0.5;
        let Q = y < -0.2;
        let W = always[0..=3] (eventually[2..=5] P || Q);
        let U = P until[1..=4] Q;
        let F = eventually[0..] (P && Q);
        task always[0..] eventually[0..=6] (P && !Q);
    }";
    std::fs::write(dir.path().join("s.hstl"), spec).expect("write spec");
    // A deterministic wiggle: no random numbers needed.
    let mut csv = String::from("x,y\n");
    for t in 0..200u32 {
        let t = f64::from(t);
        csv.push_str(&format!("{},{}\n", (t * 0.37).sin(), (t * 0.11).cos() * 0.6));
    }
    std::fs::write(dir.path().join("t.csv"), &csv).expect("write trace");
    let run = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_hstlc"))
            .args(["monitor", "s.hstl", "--trace", "t.csv"])
            .args(extra)
            .current_dir(dir.path())
            .output()
            .expect("hstlc runs");
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).expect("utf-8")
    };
    for formula in [None, Some("W"), Some("U"), Some("F"), Some("P")] {
        let pick: Vec<&str> = formula.map_or(vec![], |f| vec!["--formula", f]);
        let signal = run(&[pick.as_slice(), &["--signal"]].concat());
        let online = run(&[pick.as_slice(), &["--online"]].concat());
        assert_eq!(online, signal, "{formula:?}");
        assert_eq!(signal.lines().count(), 201);
    }
}

/// A dense-time spec's `--online` rows are its `--signal` rows, on an irregular trace with
/// empty cells, for bounded, unbounded, past and `until` formulas with decimal bounds, over
/// clipped windows and (bounded future operators) over complete ones.
#[test]
fn dense_online_rows_are_the_signal() {
    let dir = tempfile::tempdir().expect("temp dir");
    let spec = "spec S {
        state { t: time, x: float, y: float }
        let P = x > 0.5;
        let Q = y < -0.2;
        let W = always[0..=0.3] (eventually[0.2..=0.5] P || Q);
        let U = P until[0.1..=0.4] Q;
        let H = historically[0..=0.25] P || once[0.1..] Q;
        let F = eventually (P && Q);
        task always[0..=0.7] eventually[0..=0.6] (P && !Q);
    }";
    std::fs::write(dir.path().join("s.hstl"), spec).expect("write spec");
    // Irregular stamps and empty cells, deterministic.
    let mut csv = String::from("t,x,y\n");
    let mut t = 0.0f64;
    for k in 0..300u32 {
        let kf = f64::from(k);
        t += 0.01 + 0.04 * ((kf * 0.7).sin() + 1.0) / 2.0;
        let x = if k % 3 == 1 { String::new() } else { format!("{}", (kf * 0.37).sin()) };
        let y = if k % 4 == 2 { String::new() } else { format!("{}", (kf * 0.11).cos() * 0.6) };
        let (x, y) = if k == 0 { ("0".to_string(), "0".to_string()) } else { (x, y) };
        csv.push_str(&format!("{t},{x},{y}\n"));
    }
    std::fs::write(dir.path().join("t.csv"), &csv).expect("write trace");
    let run = |extra: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_hstlc"))
            .args(["monitor", "s.hstl", "--trace", "t.csv"])
            .args(extra)
            .current_dir(dir.path())
            .output()
            .expect("hstlc runs");
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).expect("utf-8")
    };
    for formula in [None, Some("W"), Some("U"), Some("H"), Some("F"), Some("P")] {
        let pick: Vec<&str> = formula.map_or(vec![], |f| vec!["--formula", f]);
        let signal = run(&[pick.as_slice(), &["--signal"]].concat());
        let online = run(&[pick.as_slice(), &["--online"]].concat());
        assert_eq!(online, signal, "{formula:?}");
        assert!(signal.lines().count() > 3, "{formula:?}: {signal}");
        // Over complete windows too, where every future operator is bounded.
        let complete = ["--windows", "complete"];
        if formula == Some("F") {
            let refused = Command::new(env!("CARGO_BIN_EXE_hstlc"))
                .args(["monitor", "s.hstl", "--trace", "t.csv", "--formula", "F", "--online"])
                .args(complete)
                .current_dir(dir.path())
                .output()
                .expect("hstlc runs");
            assert_eq!(refused.status.code(), Some(2));
            assert!(String::from_utf8_lossy(&refused.stderr).contains("leave out `--online`"));
            continue;
        }
        let signal = run(&[pick.as_slice(), &["--signal"], &complete].concat());
        let online = run(&[pick.as_slice(), &["--online"], &complete].concat());
        assert_eq!(online, signal, "{formula:?}, complete windows");
    }
}

/// `--online` on a dense-time spec runs out of the facade's budget
/// (`hstl::robustness::MAX_ONLINE_VALUES`, values held times the trace's columns) at the
/// row where the facade's live monitor does, and says so at that row's line: 600 variables
/// under unbounded `always`, every one changing at every row, keep 600 pieces a row.
#[test]
fn dense_online_budget_error_comes_at_the_facade_row() {
    use hstl::monitor::{Dense, Front, Stamp, Windows};
    let n = 600;
    let vars: Vec<String> = (0..n).map(|i| format!("x{i}")).collect();
    let spec = format!(
        "spec B {{ state {{ t: time, {} }} task {}; }}",
        vars.iter().map(|v| format!("{v}: float")).collect::<Vec<_>>().join(", "),
        vars.iter().map(|v| format!("always ({v} > 0)")).collect::<Vec<_>>().join(" && ")
    );
    let value = |k: usize| if k % 2 == 1 { 1.0 } else { -1.0 };
    // The facade's row.
    let checked = hstl::lang::check(&spec);
    let dense = Dense::new(&checked.specs[0], None).expect("a dense spec");
    let mut live = dense.live(None, Windows::Clipped, Front::Cli).expect("a live monitor");
    let (row, problem) = (0..100_000)
        .find_map(|k| {
            let cells = vec![Some(value(k)); n];
            live.push(&dense, Stamp::Int(k as i128), &cells).err().map(|p| (k, p))
        })
        .expect("the budget runs out");
    // The command line on the same rows, one more than it takes.
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::write(dir.path().join("s.hstl"), &spec).expect("write spec");
    let mut csv = format!("t,{}\n", vars.join(","));
    for k in 0..=row {
        let v = value(k).to_string();
        csv.push_str(&format!("{k},{}\n", vec![v.as_str(); n].join(",")));
    }
    std::fs::write(dir.path().join("t.csv"), &csv).expect("write trace");
    let out = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(["monitor", "s.hstl", "--trace", "t.csv", "--online"])
        .current_dir(dir.path())
        .output()
        .expect("hstlc runs");
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(String::from_utf8_lossy(&out.stdout), "t,robustness\n");
    let stderr = String::from_utf8_lossy(&out.stderr);
    // The header is line 1, row 0 is line 2.
    let want = format!("error: t.csv:{}:1: {}\n", row + 2, problem.message);
    assert!(stderr.contains(&want), "{stderr}\nwants {want}");
    assert!(problem.message.contains(&hstl::robustness::MAX_ONLINE_VALUES.to_string()));
    assert!(stderr.contains("help: monitor a formula with bounded windows (`--formula` with a `let`), or end the stream sooner"));
}
