//! Hostile input through the command line (issue 11), one test per class, every input
//! generated here: each ends with the right answer or a clear error and its documented exit
//! status, never a panic (exit 101).

use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

/// What a run of `hstlc` gave.
struct Run {
    status: Option<i32>,
    stdout: String,
    stderr: String,
}

/// Runs `hstlc` in `dir` with `stdin`.
fn hstlc_in(dir: &Path, args: &[&str], stdin: &[u8]) -> Run {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("hstlc starts");
    let mut input = child.stdin.take().expect("piped");
    // hstlc may stop reading early (an error): a broken pipe here is no failure.
    let _ = input.write_all(stdin);
    drop(input);
    let out = child.wait_with_output().expect("hstlc ends");
    Run {
        status: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

fn write(dir: &Path, name: &str, text: impl AsRef<[u8]>) {
    std::fs::write(dir.join(name), text).expect("test file written");
}

const SMALL: &str = "spec Small {
    world \"paper\";
    state { x: int in 0..=14, y: int in 0..=14 }
    let A = x < 3 && y < 3;
    let B = x > 11 && y > 11;
    task always[0..] (eventually[0..40] A && eventually[0..40] B);
    option A;
    option B;
    learn { episodes: 5, choices: 5 }
}
";

/// Class 3: an error past column 65,535 (one minified line) is rendered, around its
/// place, by every command that renders diagnostics.
#[test]
fn an_error_on_a_long_line_is_shown_in_a_window() {
    let dir = tempfile::tempdir().expect("temp dir");
    // A syntax error, so that `fmt` reports it too.
    let spec = format!(
        "spec S {{ state {{ x: int in 0..=9 }} let A = x > 1;{} task A &&; option A; }}",
        " ".repeat(100_000)
    );
    write(dir.path(), "long.hstl", &spec);
    write(dir.path(), "t.csv", "x\n1\n");
    let column = spec.find("&&;").expect("&&;") + 3;
    for args in [
        &["check", "long.hstl"][..],
        &["fmt", "long.hstl"],
        &["monitor", "long.hstl", "--trace", "t.csv"],
        &["train", "long.hstl", "--out", "out"],
        &["study", "long.hstl", "--seeds", "1"],
    ] {
        let run = hstlc_in(dir.path(), args, b"");
        let shown = if args[0] == "check" { &run.stdout } else { &run.stderr };
        assert_eq!(run.status, Some(1), "{args:?}: {}", run.stderr);
        assert!(shown.contains(&format!("[long.hstl:1:{column}]")), "{args:?}: {shown}");
        assert!(shown.contains("task A &&; option A; }"), "{args:?}: {shown}");
        // A window of the line, not the whole line.
        assert!(shown.len() < 2_000, "{args:?}: {} bytes", shown.len());
    }
    // The same in a multi-line file with a long line in the middle, and a label far away.
    let spec = format!(
        "spec S {{\n  state {{ x: int in 0..=9 }}\n  let A = x > 1;\n  let B = {}x > 2;\n  let A = x < 3;\n  task A;\n}}\n",
        "x > 0 && ".repeat(20_000)
    );
    write(dir.path(), "mixed.hstl", &spec);
    let run = hstlc_in(dir.path(), &["check", "mixed.hstl"], b"");
    assert_eq!(run.status, Some(1));
    assert!(run.stdout.contains("[mixed.hstl:5:7]"), "{}", run.stdout);
    assert!(run.stdout.contains("first defined here"), "{}", run.stdout);
    assert!(run.stdout.len() < 4_000, "{}", run.stdout);
}

/// Class 10: reads are bounded. An endless input is refused at its limit, quickly, with the
/// size and the limit.
#[test]
fn endless_and_huge_inputs_are_refused_at_a_stated_size() {
    let dir = tempfile::tempdir().expect("temp dir");
    write(dir.path(), "small.hstl", SMALL);
    for device in ["/dev/zero", "/dev/urandom"] {
        if !Path::new(device).exists() {
            continue;
        }
        let run = hstlc_in(dir.path(), &["check", device], b"");
        assert_eq!(run.status, Some(2), "{device}: {}", run.stderr);
        assert!(
            run.stderr.contains(&format!("`{device}` is larger than 64 MiB, the limit for a spec")),
            "{device}: {}",
            run.stderr
        );
        let run = hstlc_in(dir.path(), &["monitor", "small.hstl", "--trace", device], b"");
        assert_eq!(run.status, Some(2), "{device}: {}", run.stderr);
        assert!(run.stderr.starts_with(&format!("error: {device}:1:")), "{}", run.stderr);
    }
    // A spec on standard input past the limit.
    let big = vec![b' '; (64 << 20) + 1];
    let run = hstlc_in(dir.path(), &["check", "-"], &big);
    assert_eq!(run.status, Some(2));
    assert!(run.stderr.contains("`<stdin>` is larger than 64 MiB"), "{}", run.stderr);
    // Not UTF-8: where.
    write(dir.path(), "latin1.hstl", b"spec S {\n  // caf\xe9\n}\n");
    let run = hstlc_in(dir.path(), &["check", "latin1.hstl"], b"");
    assert_eq!(run.status, Some(2));
    assert!(run.stderr.contains("latin1.hstl:2:9: the file is not UTF-8 text"), "{}", run.stderr);
}

/// Class 11: what Excel and old editors write is read; a header naming a column twice, a
/// constant task and an over-long name are errors before anything runs.
#[test]
fn byte_order_marks_line_ends_and_early_errors() {
    let dir = tempfile::tempdir().expect("temp dir");
    write(dir.path(), "bom.hstl", format!("\u{feff}{SMALL}"));
    write(dir.path(), "cr.hstl", SMALL.replace('\n', "\r"));
    write(dir.path(), "trace.csv", "\u{feff}t,x,y\r\n0,1,1\r\n1,2,2\r\n");
    for spec in ["bom.hstl", "cr.hstl"] {
        let run = hstlc_in(dir.path(), &["check", spec], b"");
        assert_eq!((run.status, run.stdout.as_str()), (Some(0), "checked 1 file: no problems\n"));
        let run =
            hstlc_in(dir.path(), &["monitor", spec, "--trace", "trace.csv", "--formula", "A"], b"");
        assert_eq!((run.status, run.stdout.as_str()), (Some(0), "2\n"), "{}", run.stderr);
        assert_eq!(run.stderr, "note: column `t` is not a state variable of `Small`: ignored\n");
    }
    // With CR-only line ends the diagnostics name the right line.
    write(dir.path(), "cr_error.hstl", SMALL.replace('\n', "\r").replace("x < 3", "q < 3"));
    let run = hstlc_in(dir.path(), &["check", "--format", "concise", "cr_error.hstl"], b"");
    assert!(run.stdout.starts_with("cr_error.hstl:4:13: HSTL002"), "{}", run.stdout);
    let run = hstlc_in(dir.path(), &["check", "cr_error.hstl"], b"");
    assert!(run.stdout.contains("[cr_error.hstl:4:13]"), "{}", run.stdout);
    // CSV errors too, after a lone-CR line end.
    write(dir.path(), "cr.csv", "x,y\r1,1\r2,oops\r");
    let run = hstlc_in(dir.path(), &["monitor", "bom.hstl", "--trace", "cr.csv"], b"");
    assert_eq!(run.status, Some(2));
    assert!(run.stderr.starts_with("error: cr.csv:3:3: `oops` in column `y`"), "{}", run.stderr);
    // A header naming a column twice.
    write(dir.path(), "twice.csv", "x,y,x\n1,1,1\n");
    let run = hstlc_in(dir.path(), &["monitor", "bom.hstl", "--trace", "twice.csv"], b"");
    assert_eq!(run.status, Some(2));
    assert!(
        run.stderr.contains("twice.csv:1:5: the header names column `x` twice (first at column 1)"),
        "{}",
        run.stderr
    );
    // A task with nothing to learn: a warning, and `train` refuses it with the code.
    let constant = SMALL
        .replace("task always[0..] (eventually[0..40] A && eventually[0..40] B);", "task true;");
    write(dir.path(), "early.hstl", &constant);
    let run = hstlc_in(dir.path(), &["check", "--format", "concise", "early.hstl"], b"");
    assert_eq!(run.status, Some(0));
    assert!(run.stdout.contains("HSTL104"), "{}", run.stdout);
    let run = hstlc_in(dir.path(), &["train", "early.hstl", "--out", "early"], b"");
    assert_eq!(run.status, Some(2), "{}", run.stderr);
    assert!(run.stderr.contains("HSTL104"), "{}", run.stderr);
    assert!(!dir.path().join("early").exists());
    // An option that reaches a constant and a 300-character option name: `check` says so,
    // `train` does not start.
    let long = format!("O{}", "o".repeat(299));
    for (spec, code) in [
        (SMALL.replace("option A;", "let K = true; option K;"), "HSTL050"),
        (SMALL.replace("option B;", &format!("let {long} = x > 5; option {long};")), "HSTL051"),
    ] {
        write(dir.path(), "early.hstl", &spec);
        let run = hstlc_in(dir.path(), &["check", "--format", "concise", "early.hstl"], b"");
        assert_eq!(run.status, Some(1));
        assert!(run.stdout.contains(code), "{}", run.stdout);
        let run = hstlc_in(dir.path(), &["train", "early.hstl", "--out", "early"], b"");
        assert_eq!(run.status, Some(1), "{}", run.stderr);
        assert!(!dir.path().join("early").exists());
    }
}

/// Class 11: SARIF locations are URIs: percent-encoded, `file:` for absolute paths, relative
/// references from `%SRCROOT%` otherwise.
#[test]
fn sarif_locations_are_uris() {
    let dir = tempfile::tempdir().expect("temp dir");
    std::fs::create_dir(dir.path().join("my specs")).expect("folder");
    write(dir.path(), "my specs/a b#1.hstl", "spec S { state { x: int in 0..=9 } task zz; }");
    let absolute = dir.path().join("my specs/a b#1.hstl");
    let run = hstlc_in(
        dir.path(),
        &["check", "--format", "sarif", "my specs/a b#1.hstl", absolute.to_str().expect("utf-8")],
        b"",
    );
    let sarif: serde_json::Value = serde_json::from_str(&run.stdout).expect("SARIF is JSON");
    let uris: Vec<&serde_json::Value> = sarif["runs"][0]["results"]
        .as_array()
        .expect("results")
        .iter()
        .map(|r| &r["locations"][0]["physicalLocation"]["artifactLocation"])
        .collect();
    assert_eq!(
        uris[0],
        &serde_json::json!({ "uri": "my%20specs/a%20b%231.hstl", "uriBaseId": "%SRCROOT%" })
    );
    let uri = uris[1]["uri"].as_str().expect("a uri");
    assert!(uri.starts_with("file:///") && uri.ends_with("/my%20specs/a%20b%231.hstl"), "{uri}");
    assert!(!uri.contains(' '), "{uri}");
}

/// Class 11: `eval` refuses flags that cannot make a report before printing anything, in
/// words (no Rust value such as `WindowConfig { .. }`).
#[test]
fn eval_checks_its_flags_first() {
    let dir = tempfile::tempdir().expect("temp dir");
    write(dir.path(), "small.hstl", SMALL);
    let run = hstlc_in(dir.path(), &["train", "small.hstl", "--out", "run"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    for (flags, words) in [
        (&["--burn-in", "5000"][..], "burn-in"),
        (&["--starts", "0"], "--starts"),
        (&["--steps", "0"], "--steps"),
    ] {
        let mut args = vec!["eval", "run/policy.json", "--no-optimum"];
        args.extend(flags);
        let run = hstlc_in(dir.path(), &args, b"");
        assert_eq!((run.status, run.stdout.as_str()), (Some(2), ""), "{flags:?}");
        assert!(run.stderr.contains(words), "{flags:?}: {}", run.stderr);
        assert!(!run.stderr.contains("Config"), "{}", run.stderr);
    }
}

/// Class 11: `scripts/case-study --seeds N --out DIR`, its own documented use, works (the
/// flags replace the script's defaults instead of repeating them).
#[test]
fn the_case_study_script_takes_seeds_and_out() {
    let dir = tempfile::tempdir().expect("temp dir");
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../scripts/case-study");
    let out = Command::new("bash")
        .args([script, "--seeds", "1", "--out", "cs", "--episodes", "2", "--no-optimum"])
        .env("HSTLC", env!("CARGO_BIN_EXE_hstlc"))
        .current_dir(dir.path())
        .output()
        .expect("bash runs");
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("7 specs x 1 seeds"), "{stdout}");
    for variant in ["surveillance_ot1", "surveillance_memory_tuned"] {
        let seeds = dir.path().join("cs").join(variant).join("seeds.csv");
        let text = std::fs::read_to_string(&seeds).expect("seeds.csv written under --out");
        assert_eq!(text.lines().count(), 2, "one seed: {text}");
    }
}

/// The files of a folder, sorted (hidden ones too).
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Class 6: an output folder appears whole, replaces an earlier run's whole, and is held by
/// one run at a time; file names are made unique before anything is written.
#[test]
fn output_folders_are_whole_or_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    // Two inline regions whose names both read `x___3` as file names.
    let inline = SMALL
        .replace(
            "task always[0..] (eventually[0..40] A && eventually[0..40] B);",
            "task always[0..] (eventually[0..20] (x > 3) && eventually[0..20] (x < 3));",
        )
        .replace(
            "learn { episodes: 5, choices: 5 }",
            "learn { episodes: 3, choices: 5, memory: 2 }",
        );
    write(d, "inline.hstl", &inline);
    let run = hstlc_in(d, &["train", "inline.hstl", "--out", "run"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let files = listing(&d.join("run"));
    assert!(files.contains(&"options_after_x___3.svg".to_string()), "{files:?}");
    assert!(files.contains(&"options_after_x___3_2.svg".to_string()), "{files:?}");

    // A later run replaces the folder as a whole, and removes what killed runs left.
    write(d, "small.hstl", SMALL);
    std::fs::create_dir(d.join(".run.tmp-99999-0")).expect("a killed run's folder");
    write(d, ".run.tmp-99999-0/policy.json", "half");
    let run = hstlc_in(d, &["train", "small.hstl", "--out", "run", "--seed", "2"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let files = listing(&d.join("run"));
    assert!(!files.iter().any(|f| f.starts_with("options_after")), "old files stayed: {files:?}");
    assert!(files.contains(&"options.svg".to_string()), "{files:?}");
    let siblings: Vec<String> = listing(d).into_iter().filter(|f| f.starts_with(".run")).collect();
    assert!(siblings.is_empty(), "nothing stays beside the folder: {siblings:?}");

    // A folder holding other files is not replaced.
    std::fs::create_dir(d.join("mine")).expect("folder");
    write(d, "mine/notes.txt", "keep me");
    let run = hstlc_in(d, &["train", "small.hstl", "--out", "mine"], b"");
    assert_eq!(run.status, Some(2));
    assert!(run.stderr.contains("holds `notes.txt`, which no hstlc run writes"), "{}", run.stderr);
    assert_eq!(listing(&d.join("mine")), ["notes.txt"]);
    // Hostile round 2: and no lock file lands beside the refused folder.
    assert!(!d.join(".mine.lock").exists(), "a lock beside a refused target");

    // Two runs into one folder: the second is refused while the first holds it; a killed
    // run leaves no lock behind.
    let long = SMALL
        .replace("learn { episodes: 5, choices: 5 }", "learn { episodes: 100000, choices: 20 }");
    write(d, "long.hstl", &long);
    let mut first = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(["train", "long.hstl", "--out", "busy"])
        .current_dir(d)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("hstlc starts");
    let mut refused = None;
    for _ in 0..200 {
        std::thread::sleep(std::time::Duration::from_millis(50));
        let second = hstlc_in(d, &["train", "small.hstl", "--out", "busy"], b"");
        if second.status == Some(2) {
            refused = Some(second.stderr);
            break;
        }
    }
    first.kill().expect("the first run stops");
    let _ = first.wait();
    let refused = refused.expect("the second run was refused while the first ran");
    assert!(refused.contains("is being written by another hstlc run"), "{refused}");
    let run = hstlc_in(d, &["train", "small.hstl", "--out", "busy"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);

    // Two specs of one name in a study get folders of their own.
    for sub in ["a", "b"] {
        std::fs::create_dir(d.join(sub)).expect("folder");
        write(d, &format!("{sub}/spec.hstl"), SMALL);
    }
    let run = hstlc_in(
        d,
        &["study", "a/spec.hstl", "b/spec.hstl", "--seeds", "1", "--no-optimum", "--out", "st"],
        b"",
    );
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert_eq!(
        listing(&d.join("st")),
        [".hstlc-study", "curves.csv", "curves.svg", "spec", "spec-2", "summary.csv"]
    );
    let curves = std::fs::read_to_string(d.join("st/curves.csv")).expect("curves.csv");
    assert!(curves.contains("a/spec.hstl") && curves.contains("b/spec.hstl"), "{curves}");
}

/// Class 7: `fmt --write` rewrites a file whole, as the same file where a rename allows: its
/// permissions, the symbolic link to it and its byte order mark stay; a hard-linked one
/// becomes a file of its own, with a note.
#[cfg(unix)]
#[test]
fn fmt_write_keeps_the_file() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let messy = "spec  S {state{x:int in 0..=9}let A=x>1; task A;}\n";
    let run = hstlc_in(d, &["fmt", "-"], messy.as_bytes());
    let tidy = run.stdout;
    assert_ne!(tidy, messy);
    let fmt_write = |name: &str| {
        let run = hstlc_in(d, &["fmt", "--write", name], b"");
        assert_eq!(run.status, Some(0), "{name}: {}", run.stderr);
    };
    let read = |name: &str| std::fs::read_to_string(d.join(name)).expect("readable");

    // Permissions.
    write(d, "private.hstl", messy);
    std::fs::set_permissions(d.join("private.hstl"), std::fs::Permissions::from_mode(0o600))
        .expect("chmod");
    fmt_write("private.hstl");
    assert_eq!(read("private.hstl"), tidy);
    let mode = std::fs::metadata(d.join("private.hstl")).expect("meta").permissions().mode();
    assert_eq!(mode & 0o777, 0o600);

    // A symbolic link: the target is formatted, the link stays a link.
    std::fs::create_dir(d.join("real")).expect("folder");
    write(d, "real/target.hstl", messy);
    std::os::unix::fs::symlink("real/target.hstl", d.join("link.hstl")).expect("symlink");
    fmt_write("link.hstl");
    assert!(std::fs::symlink_metadata(d.join("link.hstl")).expect("meta").file_type().is_symlink());
    assert_eq!(read("real/target.hstl"), tidy);

    // Hostile round 2: a hard-linked file was rewritten in place, and a run killed mid-write
    // left the new text followed by the old text's tail (the old text only in a hidden
    // backup). Now it is replaced whole, by a rename, like any file: it becomes a file of
    // its own, the other name keeps the old text, and a note says so.
    write(d, "one.hstl", messy);
    std::fs::hard_link(d.join("one.hstl"), d.join("two.hstl")).expect("hard link");
    let inode = std::fs::metadata(d.join("one.hstl")).expect("meta").ino();
    let run = hstlc_in(d, &["fmt", "--write", "one.hstl"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert_eq!(
        run.stderr,
        "note: `one.hstl` had 1 other hard link: it is now a file of its own, and that name \
         keeps the text before formatting (run `hstlc fmt --write` on it too)\n"
    );
    assert_eq!((read("one.hstl"), read("two.hstl")), (tidy.clone(), messy.to_string()));
    let meta = std::fs::metadata(d.join("one.hstl")).expect("meta");
    assert_ne!(meta.ino(), inode, "written in place, not whole");
    let two = std::fs::metadata(d.join("two.hstl")).expect("meta");
    assert_eq!((meta.nlink(), meta.permissions().mode()), (1, two.permissions().mode()));

    // A byte order mark stays; the fixed temporary name of old is left alone.
    write(d, "bom.hstl", format!("\u{feff}{messy}"));
    write(d, ".bom.hstl.hstlc-fmt.tmp", "not mine");
    fmt_write("bom.hstl");
    assert_eq!(read("bom.hstl"), format!("\u{feff}{tidy}"));
    assert_eq!(read(".bom.hstl.hstlc-fmt.tmp"), "not mine");
    let left: Vec<String> = listing(d)
        .into_iter()
        .filter(|f| f.contains("hstlc-fmt") && f != ".bom.hstl.hstlc-fmt.tmp")
        .collect();
    assert!(left.is_empty(), "temporary files left: {left:?}");
}

/// Runs `hstlc` in `dir` with standard output going to `stdout`; status and standard error.
fn hstlc_to(dir: &Path, args: &[&str], stdout: Stdio) -> (Option<i32>, String) {
    let child = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(stdout)
        .stderr(Stdio::piped())
        .spawn()
        .expect("hstlc starts");
    let out = child.wait_with_output().expect("hstlc ends");
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// Class 8: output errors are errors. A full disk (`/dev/full`) stops every command with
/// status 2 and one line; a reader that went away (`| head`) ends it quietly with 141.
#[test]
fn write_errors_are_errors_and_a_closed_pipe_ends_quietly() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "small.hstl", SMALL);
    write(d, "t.csv", "x,y\n1,1\n2,2\n");
    let run = hstlc_in(d, &["train", "small.hstl", "--out", "run"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let commands: [&[&str]; 11] = [
        &["check", "small.hstl"],
        &["check", "--format", "json", "small.hstl"],
        &["explain", "HSTL003"],
        &["fmt", "small.hstl"],
        &["monitor", "small.hstl", "--trace", "t.csv", "--signal"],
        &["train", "small.hstl", "--out", "again"],
        &["eval", "run/policy.json", "--no-optimum", "--starts", "2", "--steps", "200"],
        &["study", "small.hstl", "--seeds", "1", "--no-optimum", "--out", "st"],
        &["--help"],
        &["--version"],
        &["check", "--help"],
    ];
    if Path::new("/dev/full").exists() {
        for args in commands {
            let full =
                std::fs::OpenOptions::new().write(true).open("/dev/full").expect("/dev/full");
            let (status, stderr) = hstlc_to(d, args, Stdio::from(full));
            assert_eq!(status, Some(2), "{args:?}: {stderr}");
            assert_eq!(
                stderr, "error: cannot write `<stdout>`: no space left on device\n",
                "{args:?}"
            );
        }
    }
    // The reader closes its end before hstlc starts.
    write(d, "b.hstl", SMALL);
    write(d, "c.hstl", SMALL);
    for args in
        [&["fmt", "small.hstl", "b.hstl", "c.hstl"][..], &["check", "small.hstl"], &["--help"]]
    {
        let (reader, writer) = std::io::pipe().expect("a pipe");
        drop(reader);
        let (status, stderr) = hstlc_to(d, args, Stdio::from(writer));
        assert_eq!((status, stderr.as_str()), (Some(141), ""), "{args:?}");
    }
}

/// `SMALL` with `lets` added and region `B` replaced by `region`.
fn small_with(lets: &str, region: &str) -> String {
    SMALL.replace("let B = x > 11 && y > 11;", &format!("{lets}let B = {region};")).replace(
        "learn { episodes: 5, choices: 5 }",
        "learn { episodes: 3, choices: 5, memory: 2 }",
    )
}

/// Classes 1 and 2: lets are shared, not inlined, and nothing recurses as deep as a chain
/// of them. A doubling chain of 30 lets (a tree of 2^29 atoms) and 80 lets of 250 `!`
/// each (a chain 20,000 deep) run through `monitor`, `train`, `eval` (the spec read back
/// from `policy.json`) and `study`, with the values of the equivalent small spec; a chain
/// of 300 lets checks clean and monitors.
#[test]
fn shared_and_deep_lets_run_in_linear_time() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let mut doubling = String::from("let L0 = x > 11 && y > 11;\n");
    for k in 1..30 {
        doubling.push_str(&format!("let L{k} = L{} && L{};\n", k - 1, k - 1));
    }
    let mut deep = String::from("let M0 = x > 11 && y > 11;\n");
    for k in 1..=80 {
        deep.push_str(&format!("let M{k} = {}M{};\n", "!".repeat(250), k - 1));
    }
    let mut temporal = String::from("let T0 = x > 11 && y > 11;\n");
    for k in 1..=80 {
        temporal.push_str(&format!("let T{k} = {}T{};\n", "always[0..=0] ".repeat(250), k - 1));
    }
    write(d, "plain.hstl", small_with("", "x > 11 && y > 11"));
    write(
        d,
        "temporal.hstl",
        format!("spec T {{ state {{ x: int in 0..=14, y: int in 0..=14 }} {temporal} task T80; }}"),
    );
    write(d, "doubling.hstl", small_with(&doubling, "L29"));
    write(d, "deep.hstl", small_with(&deep, "M80"));
    let rows: String = (0..200).map(|t| format!("{},{}\n", t % 15, (t * 7) % 15)).collect();
    write(d, "t.csv", format!("x,y\n{rows}"));
    let monitor = |spec: &str, formula: &str| {
        let run = hstlc_in(d, &["monitor", spec, "--trace", "t.csv", "--formula", formula], b"");
        assert_eq!(run.status, Some(0), "{spec}: {}", run.stderr);
        run.stdout
    };
    let want = monitor("plain.hstl", "B");
    assert_eq!(monitor("doubling.hstl", "L29"), want);
    assert_eq!(monitor("deep.hstl", "M80"), want);
    // 20,000 nested windows (no NaN in the trace, so each is the identity), also online.
    assert_eq!(monitor("temporal.hstl", "T80"), want);
    let signal = |args: &[&str]| {
        let run = hstlc_in(d, args, b"");
        assert_eq!(run.status, Some(0), "{args:?}: {}", run.stderr);
        run.stdout
    };
    let base = ["monitor", "temporal.hstl", "--trace", "t.csv", "--formula", "T80", "--signal"];
    let plain = ["monitor", "plain.hstl", "--trace", "t.csv", "--formula", "B", "--signal"];
    assert_eq!(signal(&base), signal(&plain));
    let rows = std::fs::read(d.join("t.csv")).expect("trace");
    let online = hstlc_in(
        d,
        &["monitor", "temporal.hstl", "--trace", "-", "--formula", "T80", "--online"],
        &rows,
    );
    let plain_online = hstlc_in(
        d,
        &["monitor", "plain.hstl", "--trace", "-", "--formula", "B", "--online"],
        &rows,
    );
    assert_eq!(online.status, Some(0), "{}", online.stderr);
    assert_eq!(online.stdout, plain_online.stdout);
    let task = hstlc_in(d, &["monitor", "plain.hstl", "--trace", "t.csv", "--signal"], b"");
    for spec in ["doubling.hstl", "deep.hstl"] {
        let run = hstlc_in(d, &["monitor", spec, "--trace", "t.csv", "--signal"], b"");
        assert_eq!((run.status, &run.stdout), (Some(0), &task.stdout), "{spec}: {}", run.stderr);
        // Training, and the policy replayed from the spec it holds, as the plain spec's.
        let out = format!("run_{spec}");
        let run = hstlc_in(d, &["train", spec, "--out", &out, "--seed", "3"], b"");
        assert_eq!(run.status, Some(0), "{spec}: {}", run.stderr);
        let policy = format!("{out}/policy.json");
        let run = hstlc_in(d, &["eval", &policy, "--no-optimum", "--starts", "2"], b"");
        assert_eq!(run.status, Some(0), "{spec}: {}", run.stderr);
        let study = format!("study_{spec}");
        let run =
            hstlc_in(d, &["study", spec, "--seeds", "1", "--no-optimum", "--out", &study], b"");
        assert_eq!(run.status, Some(0), "{spec}: {}", run.stderr);
    }
    let trained = |spec: &str| {
        let out = format!("same_{spec}");
        let run = hstlc_in(d, &["train", spec, "--out", &out, "--seed", "3"], b"");
        assert_eq!(run.status, Some(0), "{spec}: {}", run.stderr);
        let text = std::fs::read_to_string(d.join(out).join("policy.json")).expect("policy");
        let policy: serde_json::Value = serde_json::from_str(&text).expect("policy is JSON");
        policy["q_tables"].clone()
    };
    // The same task, so the same draws and the same tables, bit for bit.
    assert_eq!(trained("deep.hstl"), trained("plain.hstl"));

    // A chain of 300 lets (the old limit was 256): `check` and `monitor` agree.
    let mut chain = String::from("let C0 = x > 11;\n");
    for k in 1..300 {
        chain.push_str(&format!("let C{k} = C{} && y > 11;\n", k - 1));
    }
    write(d, "chain.hstl", small_with(&chain, "C299"));
    let run = hstlc_in(d, &["check", "chain.hstl"], b"");
    assert_eq!((run.status, run.stdout.as_str()), (Some(0), "checked 1 file: no problems\n"));
    assert_eq!(monitor("chain.hstl", "C299"), want);
}

/// Hostile round 2: `study --out` never replaces a user's own files at the top of its folder
/// without `--force`, and its top files describe every spec folder there: a second study
/// into the folder of another is refused (or, with `--force`, removes the other's folders).
#[test]
fn a_study_keeps_a_users_files_and_describes_every_folder() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "a.hstl", SMALL);
    write(d, "b.hstl", SMALL);
    let study = |spec: &str, out: &str, force: bool| {
        let mut args = vec!["study", spec, "--seeds", "1", "--no-optimum", "--out", out];
        if force {
            args.push("--force");
        }
        hstlc_in(d, &args, b"")
    };
    // A user's own summary.csv and curves.csv: refused before training, left as they were.
    std::fs::create_dir(d.join("mine")).expect("folder");
    write(d, "mine/summary.csv", "my,figures\n");
    write(d, "mine/curves.csv", "my,curves\n");
    write(d, "mine/notes.txt", "keep me");
    let run = study("a.hstl", "mine", false);
    assert_eq!(run.status, Some(2), "{}", run.stderr);
    assert!(
        run.stderr.contains("curves.csv` was not written by a study, and would be replaced"),
        "{}",
        run.stderr
    );
    assert!(run.stderr.contains("--force"), "{}", run.stderr);
    assert!(!run.stdout.contains("study:"), "refused before training: {}", run.stdout);
    assert_eq!(listing(&d.join("mine")), ["curves.csv", "notes.txt", "summary.csv"]);
    assert_eq!(std::fs::read_to_string(d.join("mine/summary.csv")).expect("read"), "my,figures\n");
    assert!(!listing(d).iter().any(|f| f.ends_with(".lock")), "a lock left: {:?}", listing(d));
    // With --force they are replaced; the user's other files stay.
    let run = study("a.hstl", "mine", true);
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let summary = std::fs::read_to_string(d.join("mine/summary.csv")).expect("read");
    assert!(summary.contains("a.hstl"), "{summary}");
    assert_eq!(std::fs::read_to_string(d.join("mine/notes.txt")).expect("read"), "keep me");
    // A study's own files are replaced by the next study of the same specs.
    let run = study("a.hstl", "mine", false);
    assert_eq!(run.status, Some(0), "{}", run.stderr);

    // Two studies into one folder: the second would leave `a` undescribed, and is refused.
    let run = study("b.hstl", "mine", false);
    assert_eq!(run.status, Some(2), "{}", run.stderr);
    assert!(
        run.stderr.contains(
            "holds `a`, another run's folder, which this study's summary would not describe"
        ),
        "{}",
        run.stderr
    );
    assert!(listing(&d.join("mine")).contains(&"a".to_string()));
    // With --force the other study's folder goes, and the summary describes what is there.
    let run = study("b.hstl", "mine", true);
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert_eq!(
        listing(&d.join("mine")),
        [".hstlc-study", "b", "curves.csv", "curves.svg", "notes.txt", "summary.csv"]
    );
    let summary = std::fs::read_to_string(d.join("mine/summary.csv")).expect("read");
    assert_eq!(summary.lines().count(), 2, "{summary}");
    assert!(!summary.contains("a.hstl"), "{summary}");
    // A train run's folder inside the study's folder is another run's folder too.
    let run = hstlc_in(d, &["train", "a.hstl", "--out", "mine/trained"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let run = study("b.hstl", "mine", false);
    assert_eq!(run.status, Some(2), "{}", run.stderr);
    assert!(run.stderr.contains("holds `trained`"), "{}", run.stderr);
    assert!(!listing(d).iter().any(|f| f.starts_with('.')), "left beside: {:?}", listing(d));
}

/// Hostile round 2: when no policy can keep the task (W* = 0, `check` clean), `eval` and
/// `study` say W/W* is undefined in words, and `summary.csv` leaves its cells empty: never
/// NaN or inf.
#[test]
fn w_over_w_star_is_undefined_in_words_when_no_policy_keeps_the_task() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    // Two steps cannot take the agent from one corner to the other and back.
    let zero = SMALL.replace("[0..40]", "[0..2]");
    write(d, "zero.hstl", &zero);
    let run = hstlc_in(d, &["check", "zero.hstl"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stdout);
    let run = hstlc_in(d, &["train", "zero.hstl", "--out", "run"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let undefined = "W/W* undefined (W* = 0: no policy keeps the task)";
    let run = hstlc_in(d, &["eval", "run/policy.json", "--starts", "2", "--steps", "200"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert!(run.stdout.contains(undefined), "{}", run.stdout);
    let run = hstlc_in(d, &["study", "zero.hstl", "zero.hstl", "--seeds", "2", "--out", "st"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert_eq!(run.stdout.matches(undefined).count(), 2, "{}", run.stdout);
    let summary = std::fs::read_to_string(d.join("st/summary.csv")).expect("summary.csv");
    for line in summary.lines().skip(1) {
        assert_eq!(line.split(',').collect::<Vec<_>>()[1..5], ["W/W*", "0", "", ""], "{summary}");
    }
    for text in [&run.stdout, &summary] {
        let lower = text.to_lowercase();
        assert!(!lower.contains("nan") && !lower.contains("inf"), "{text}");
    }
}

/// Hostile round 2: a named pipe called `*.csv` in a batch folder hung `monitor` forever,
/// waiting for a writer. Only regular files are read from a folder; the others are skipped
/// with a note.
#[cfg(unix)]
#[test]
fn a_batch_folder_is_read_for_its_regular_files_only() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "small.hstl", SMALL);
    std::fs::create_dir(d.join("traces")).expect("folder");
    write(d, "traces/a.csv", "x,y\n1,1\n2,2\n");
    let made = Command::new("mkfifo").arg(d.join("traces/b.csv")).status().expect("mkfifo runs");
    assert!(made.success());
    let mut child = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(["monitor", "small.hstl", "--trace", "traces"])
        .current_dir(d)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("hstlc starts");
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(30);
    while child.try_wait().expect("waits").is_none() {
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("monitor hangs on a named pipe in a batch folder");
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("hstlc ends");
    let (stdout, stderr) =
        (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stdout.contains("a.csv") && !stdout.contains("b.csv"), "{stdout}");
    assert!(
        stderr.contains("note: skipped `traces/b.csv`: a named pipe, not a regular file"),
        "{stderr}"
    );
}

/// Hostile round 2: names with control characters (a file name, a CSV column) reached the
/// terminal raw, where an escape sequence can clear the screen or retitle the window. They
/// are shown escaped (`\x1b`) in errors, diagnostics, notes and `fmt --check`'s list.
#[cfg(unix)]
#[test]
fn control_characters_in_names_are_escaped() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let raw = |run: &Run| {
        let all = format!("{}{}", run.stdout, run.stderr);
        all.chars().any(|c| c.is_control() && c != '\n')
    };
    // A spec file whose name clears the screen, with a syntax error and messy layout.
    let evil = "evil\x1b[2J\r.hstl";
    write(d, evil, "spec S { state { x: int in 0..=9 } task x > 1 &&; }");
    for args in [&["check", evil][..], &["fmt", evil], &["train", evil, "--out", "o"]] {
        let run = hstlc_in(d, args, b"");
        assert_eq!(run.status, Some(1), "{args:?}: {}", run.stderr);
        assert!(!raw(&run), "{args:?}: {:?}", run.stderr);
        let shown = format!("{}{}", run.stdout, run.stderr);
        assert!(shown.contains("evil\\x1b[2J\\x0d.hstl"), "{args:?}: {shown}");
    }
    let run = hstlc_in(d, &["check", "--format", "concise", evil], b"");
    assert!(!raw(&run) && run.stdout.contains("evil\\x1b[2J\\x0d.hstl:1:"), "{}", run.stdout);
    // A missing file, and `fmt --check`'s list of files that would change.
    let run = hstlc_in(d, &["check", "gone\x07.hstl"], b"");
    assert_eq!(run.status, Some(2));
    assert!(!raw(&run) && run.stderr.contains("cannot read `gone\\x07.hstl`"), "{}", run.stderr);
    let messy = "messy\x1b]0;owned\x07.hstl";
    write(d, messy, "spec  S {state{x:int in 0..=9} task x>1;}\n");
    let run = hstlc_in(d, &["fmt", "--check", messy], b"");
    assert_eq!(run.status, Some(1), "{}", run.stderr);
    assert_eq!(run.stdout, "messy\\x1b]0;owned\\x07.hstl\n");
    // A trace column the spec does not name.
    write(d, "small.hstl", SMALL);
    write(d, "t.csv", "x,y,\x1b[31mred\n1,1,0\n2,2,0\n");
    let run = hstlc_in(d, &["monitor", "small.hstl", "--trace", "t.csv"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert!(!raw(&run), "{:?}", run.stderr);
    assert!(run.stderr.contains("column `\\x1b[31mred` is not"), "{}", run.stderr);
}

/// Issue 30: file names that are not UTF-8 were shown lossily (every bad byte as U+FFFD),
/// so two files printed under one name. Each bad byte is shown as `\xff`, in diagnostics,
/// `fmt --check`'s list and read errors alike.
#[cfg(unix)]
#[test]
fn file_names_that_are_not_utf8_are_shown_losslessly() {
    use std::ffi::OsStr;
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    let names = [OsStr::from_bytes(b"a\xff.hstl"), OsStr::from_bytes(b"a\xfe.hstl")];
    for n in names {
        std::fs::write(d.join(n), "spec  S {state{x:int in 0..=9} task x>1 &&;}\n").expect("file");
    }
    let run = |args: &[&OsStr]| {
        let out = Command::new(env!("CARGO_BIN_EXE_hstlc"))
            .args(args)
            .current_dir(d)
            .output()
            .expect("hstlc runs");
        let all = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        (out.status.code(), all)
    };
    let (status, shown) = run(&[OsStr::new("check"), names[0], names[1]]);
    assert_eq!(status, Some(1), "{shown}");
    assert!(shown.contains("[a\\xff.hstl:1:"), "{shown}");
    assert!(shown.contains("[a\\xfe.hstl:1:"), "{shown}");
    assert!(!shown.contains('\u{fffd}'), "{shown}");
    let (_, shown) = run(&[OsStr::new("check"), OsStr::from_bytes(b"gone\xff.hstl")]);
    assert!(shown.contains("cannot read `gone\\xff.hstl`"), "{shown}");
}

/// Issue 30: `eval` accepted hand-edited tables' `policy.json` files. Each edit is now
/// refused (exit 2) with what is wrong: a signed hex Q-value, a table for no primitive, a
/// seed written as a string, the built-in world's slip changed, and a built-in world's name
/// on another map.
#[test]
fn hand_edited_policies_are_refused() {
    use serde_json::{Value, json};
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "small.hstl", SMALL);
    let run = hstlc_in(d, &["train", "small.hstl", "--out", "t"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let text = std::fs::read_to_string(d.join("t/policy.json")).expect("policy.json");
    let doc: Value = serde_json::from_str(&text).expect("JSON");
    let eval = |name: &str, doc: &Value| {
        write(d, name, serde_json::to_string(doc).expect("JSON"));
        hstlc_in(d, &["eval", name, "--no-optimum", "--starts", "1", "--steps", "150"], b"")
    };
    assert_eq!(eval("ok.json", &doc).status, Some(0));
    type Edit = Box<dyn Fn(&mut Value)>;
    let first = |d: &mut Value| -> String {
        d["q_tables"]["flat"].as_object().expect("tables").keys().next().expect("one").clone()
    };
    let edits: Vec<(&str, Edit, &str)> = vec![
        (
            "signed",
            Box::new(move |d| {
                let k = first(d);
                let v = d["q_tables"]["flat"][&k][0].as_str().expect("hex").to_string();
                d["q_tables"]["flat"][&k][0] = json!(format!("-{v}"));
            }),
            "not 16 hex digits of an f64's bits",
        ),
        (
            "extra",
            Box::new(move |d| {
                let k = first(d);
                d["q_tables"]["flat"]["Z"] = d["q_tables"]["flat"][&k].clone();
            }),
            "has a table for `Z`, which is no primitive option",
        ),
        ("seed", Box::new(|d| d["seed"] = json!("3")), "its `seed` is \"3\", not a whole number"),
        (
            "slip",
            Box::new(|d| d["env"]["params"]["slip"] = json!(0.5)),
            "the world is named `paper`, a built-in world, but its parameters are not",
        ),
        (
            "name",
            Box::new(|d| d["env"]["name"] = json!("four-rooms")),
            "the world is named `four-rooms`, a built-in world, but its parameters are not",
        ),
    ];
    // Each edit with the document's `checksum` taken out (as a document written before
    // checksums has none): the field's own check says what is wrong.
    for (name, edit, expected) in &edits {
        let mut edited = doc.clone();
        edited.as_object_mut().expect("an object").remove("checksum");
        edit(&mut edited);
        let run = eval(&format!("{name}.json"), &edited);
        assert_eq!(run.status, Some(2), "{name}: {}{}", run.stdout, run.stderr);
        assert!(run.stdout.is_empty(), "{name}: {}", run.stdout);
        assert!(run.stderr.contains(expected), "{name}: {}", run.stderr);
    }
    // With the checksum, an edit of the document's own fields is caught by it first.
    let changed = "the document was changed after it was written";
    for (name, edit, expected) in &edits {
        let mut edited = doc.clone();
        edit(&mut edited);
        let run = eval(&format!("{name}-summed.json"), &edited);
        assert_eq!(run.status, Some(2), "{name}: {}{}", run.stdout, run.stderr);
        // The hex value does not parse, and the seed is no field of the document's own.
        let want = if matches!(*name, "signed" | "seed") { *expected } else { changed };
        assert!(run.stderr.contains(want), "{name}: {}", run.stderr);
    }
}

/// Issue 30: a policy trained on a world from a file holds that world whole, its slip
/// included, and nothing else knew it: an edited slip was evaluated as written. The
/// document's checksum refuses it; without the edit the same document evaluates.
#[test]
fn an_edited_slip_of_a_world_from_a_file_is_refused() {
    use serde_json::{Value, json};
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "room.toml", "map = \"\"\"\nS....\n.....\n.....\n\"\"\"\nslip = 0.2\n");
    write(
        d,
        "room.hstl",
        "spec Room {
    state { x: int in 0..=4, y: int in 0..=2 }
    world \"room.toml\";
    let A = x < 1;
    let B = x > 3;
    task always[0..] (eventually[0..20] A && eventually[0..20] B);
    option A { reach: A, init: !A, terminate: A }
    option B { reach: B, init: !B, terminate: B }
    options { A, B }
    learn { episodes: 5, choices: 5 }
}
",
    );
    let run = hstlc_in(d, &["train", "room.hstl", "--out", "t"], b"");
    assert_eq!(run.status, Some(0), "{}{}", run.stdout, run.stderr);
    let text = std::fs::read_to_string(d.join("t/policy.json")).expect("policy.json");
    let mut doc: Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(doc["env"]["params"]["slip"], json!(0.2), "{}", &text[..300]);
    let args = ["--no-optimum", "--starts", "1", "--steps", "150"];
    let eval = |name: &str, doc: &Value| {
        write(d, name, serde_json::to_string(doc).expect("JSON"));
        let mut all = vec!["eval", name];
        all.extend(args);
        hstlc_in(d, &all, b"")
    };
    assert_eq!(eval("same.json", &doc).status, Some(0));
    doc["env"]["params"]["slip"] = json!(0.0);
    let run = eval("slip.json", &doc);
    assert_eq!(run.status, Some(2), "{}{}", run.stdout, run.stderr);
    assert!(run.stderr.contains("the document was changed after it was written"), "{}", run.stderr);
    assert!(run.stderr.contains("train again"), "{}", run.stderr);
}

/// Issue 30: when the optimum W* was past its budget, `eval` printed its whole report and
/// then exited 2. It decides what it can compute first: the error alone, nothing printed.
#[test]
fn eval_refuses_an_optimum_past_its_budget_before_it_prints() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(
        d,
        "wide.hstl",
        "spec Wide {
    state { x: int in 0..=14, y: int in 0..=14 }
    let A = x < 3 && y < 3;
    let B = x > 11 && y > 11;
    let C = x > 11 && y < 3;
    task always[0..] (eventually[0..600] A && eventually[0..600] B && eventually[0..600] C);
    option A { reach: A, init: !A, terminate: A }
    option B { reach: B, init: !B, terminate: B }
    option C { reach: C, init: !C, terminate: C }
    options { A, B, C }
    learn { episodes: 2, choices: 3, memory: 1, reward: window }
}
",
    );
    let run = hstlc_in(d, &["train", "wide.hstl", "--out", "w"], b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let args = ["eval", "w/policy.json", "--starts", "2", "--steps", "200", "--burn-in", "10"];
    let run = hstlc_in(d, &args, b"");
    assert_eq!(run.status, Some(2), "{}", run.stderr);
    assert_eq!(run.stdout, "", "nothing printed before the error");
    assert!(run.stderr.contains("too many to search"), "{}", run.stderr);
    assert!(run.stderr.contains("--no-optimum"), "{}", run.stderr);
    let mut skip = args.to_vec();
    skip.push("--no-optimum");
    let run = hstlc_in(d, &skip, b"");
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert!(run.stdout.contains("window rate"), "{}", run.stdout);
}

/// Issue 30: world-file errors showed Rust escapes (`\u{e9}` for `é`) and lost their line
/// and column on deeply nested TOML. Letters are shown as they are (control characters
/// escaped), and every error is placed at `FILE:LINE:COL`.
#[test]
fn world_file_errors_show_letters_and_their_place() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "small.hstl", SMALL);
    let cases = [
        (
            "letter.toml",
            "map = \"\"\"\n...............\néééééééééééé\n\"\"\"\n".to_string(),
            "w:3:1:",
        ),
        ("kind.toml", "kind = \"sphère\"\n".to_string(), "w:1:8:"),
        ("deep.toml", format!("a = {}{}\n", "[".repeat(300), "]".repeat(300)), "w:1:"),
    ];
    for (name, text, place) in cases {
        write(d, name, text);
        let run = hstlc_in(d, &["check", "small.hstl", "--world", name], b"");
        assert_eq!(run.status, Some(2), "{name}: {}", run.stderr);
        let place = place.replace("w:", &format!("{name}:"));
        assert!(run.stderr.contains(&place), "{name}: {}", run.stderr);
        assert!(!run.stderr.contains("\\u{"), "{name}: {}", run.stderr);
    }
    let run = hstlc_in(d, &["check", "small.hstl", "--world", "letter.toml"], b"");
    assert!(run.stderr.contains("unknown character `é` in the map"), "{}", run.stderr);
    let run = hstlc_in(d, &["check", "small.hstl", "--world", "kind.toml"], b"");
    assert!(run.stderr.contains("`sphère`"), "{}", run.stderr);
}
