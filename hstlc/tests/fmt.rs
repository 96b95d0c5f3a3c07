//! `hstlc fmt`: printing, standard input, `--check`, `--write`, syntax errors and
//! unreadable input.

use std::io::Write as _;
use std::process::{Command, Output, Stdio};

const MESSY: &str = "spec S{state{x:int in 0..=4}let A=x>1; // keep me\ntask always A;}\n";

fn hstlc() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hstlc"))
}

fn canonical() -> String {
    hstl::lang::format(MESSY).expect("formats")
}

/// Runs `hstlc` with `stdin` as standard input.
fn with_stdin(args: &[&str], stdin: &str) -> Output {
    let mut child = hstlc()
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start hstlc");
    child.stdin.take().expect("stdin").write_all(stdin.as_bytes()).expect("write stdin");
    child.wait_with_output().expect("hstlc output")
}

#[test]
fn prints_the_canonical_layout() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("s.hstl");
    std::fs::write(&file, MESSY).unwrap();
    let out = hstlc().arg("fmt").arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(String::from_utf8_lossy(&out.stdout), canonical());
    assert!(canonical().contains("let A = x > 1; // keep me\n"));
    // The file itself is left alone.
    assert_eq!(std::fs::read_to_string(&file).unwrap(), MESSY);
}

#[test]
fn reads_standard_input() {
    let out = with_stdin(&["fmt", "-"], MESSY);
    assert_eq!(out.status.code(), Some(0));
    assert_eq!(String::from_utf8_lossy(&out.stdout), canonical());
}

#[test]
fn check_lists_files_that_would_change() {
    let dir = tempfile::tempdir().unwrap();
    let messy = dir.path().join("messy.hstl");
    let tidy = dir.path().join("tidy.hstl");
    std::fs::write(&messy, MESSY).unwrap();
    std::fs::write(&tidy, canonical()).unwrap();
    let out = hstlc().args(["fmt", "--check"]).arg(&tidy).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stdout.is_empty());
    let out = hstlc().args(["fmt", "--check"]).arg(&tidy).arg(&messy).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(String::from_utf8_lossy(&out.stdout), format!("{}\n", messy.display()));
    assert_eq!(std::fs::read_to_string(&messy).unwrap(), MESSY);
}

#[test]
fn write_rewrites_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("s.hstl");
    std::fs::write(&file, MESSY).unwrap();
    let out = hstlc().args(["fmt", "--write"]).arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
    assert!(out.stdout.is_empty());
    assert_eq!(std::fs::read_to_string(&file).unwrap(), canonical());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 1, "temporary files left behind");
    let out = hstlc().args(["fmt", "--check"]).arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn syntax_errors_are_reported_and_the_file_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    let broken = dir.path().join("broken.hstl");
    let text = "spec S {\n    let A = x >;\n}\n";
    std::fs::write(&broken, text).unwrap();
    let messy = dir.path().join("messy.hstl");
    std::fs::write(&messy, MESSY).unwrap();
    let out = hstlc().args(["fmt", "--write"]).arg(&broken).arg(&messy).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("HSTL001"), "{stderr}");
    assert!(stderr.contains("broken.hstl"), "{stderr}");
    assert_eq!(std::fs::read_to_string(&broken).unwrap(), text);
    // The other file is still formatted.
    assert_eq!(std::fs::read_to_string(&messy).unwrap(), canonical());
}

#[test]
fn unreadable_input_exits_2_before_printing() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("s.hstl");
    std::fs::write(&file, MESSY).unwrap();
    let out = hstlc().arg("fmt").arg(&file).arg(dir.path().join("missing.hstl")).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    assert!(String::from_utf8_lossy(&out.stderr).contains("missing.hstl"));
}
