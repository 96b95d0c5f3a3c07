//! Hostile input on the entry points for continuous worlds (issue 30, item 6): plane world
//! files, the `world` item, a learned function's `policy.json` and `eval` on it. Each case
//! is one that misbehaved in the campaign (BENCHMARKS.md, "Hostile round 2 on the
//! continuous entry points"); every input is generated here.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{Value, json};

/// What a run of `hstlc` gave.
struct Run {
    status: Option<i32>,
    stdout: String,
    stderr: String,
}

/// Runs `hstlc` in `dir`, killed (and the test failed) if it runs past `limit`.
fn hstlc_within(dir: &Path, args: &[&str], limit: Duration) -> Run {
    let mut child = Command::new(env!("CARGO_BIN_EXE_hstlc"))
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("hstlc starts");
    let start = Instant::now();
    while child.try_wait().expect("hstlc runs").is_none() {
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("hstlc {args:?} still ran after {limit:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("hstlc ends");
    Run {
        status: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

fn hstlc(dir: &Path, args: &[&str]) -> Run {
    hstlc_within(dir, args, Duration::from_secs(300))
}

fn write(dir: &Path, name: &str, text: impl AsRef<[u8]>) {
    std::fs::write(dir.join(name), text).expect("test file written");
}

/// A plane world file with `extra` lines after the required keys.
fn plane(x: &str, step: &str, extra: &str) -> String {
    format!("kind = \"plane\"\nx = {x}\ny = [0.0, 14.0]\nstep = {step}\nheadings = 4\n{extra}")
}

/// A patrol of two corners on the plane world `world`, over `x` in `x_range`.
fn spec(world: &str, x_range: &str) -> String {
    format!(
        "spec P {{
    world \"{world}\";
    state {{ x: float in {x_range}, y: float in 0..=14 }}
    let A = x < 3 && y > 11;
    let B = x > 11 && y < 3;
    task always[0..] (eventually[0..40] A && eventually[0..40] B);
    option A;
    option B;
    learn {{ preset: auto, episodes: 2, choices: 3 }}
}}
"
    )
}

/// No error message ends with a period or shows a Rust `Debug` value.
fn well_worded(stderr: &str) {
    for line in stderr.lines().filter(|l| l.starts_with("error:")) {
        assert!(!line.ends_with('.'), "{line}");
        assert!(!line.contains("Some(") && !line.contains("\\u{"), "{line}");
    }
}

/// A spec's `world "pipe.toml";` that names a named pipe made `check` (and the language
/// server, which reads the same file on every keystroke) wait for a writer forever.
#[cfg(unix)]
#[test]
fn a_world_item_naming_a_pipe_is_refused_not_waited_on() {
    let dir = tempfile::tempdir().expect("temp dir");
    let pipe = std::ffi::CString::new(dir.path().join("pipe.toml").to_str().expect("utf-8"))
        .expect("no NUL");
    // SAFETY: `pipe` is a NUL-terminated path; mkfifo reads it and nothing else.
    assert_eq!(unsafe { libc::mkfifo(pipe.as_ptr(), 0o600) }, 0, "mkfifo");
    write(dir.path(), "s.hstl", spec("pipe.toml", "0..=14"));
    let run = hstlc_within(
        dir.path(),
        &["check", "--format", "concise", "s.hstl"],
        Duration::from_secs(20),
    );
    assert_eq!(run.status, Some(1), "{}", run.stderr);
    assert!(
        run.stdout.contains(
            "s.hstl:2:11: HSTL034 error: `pipe.toml` is a named pipe, not a regular file"
        ),
        "{}",
        run.stdout
    );
    let run = hstlc_within(
        dir.path(),
        &["train", "s.hstl", "--world", "pipe.toml", "--out", "out"],
        Duration::from_secs(20),
    );
    assert_eq!(run.status, Some(2), "{}", run.stderr);
    assert!(run.stderr.contains("is a named pipe, not a regular file"), "{}", run.stderr);
    assert!(run.stderr.contains("help: a world file is read only from a regular file"));
    assert!(!dir.path().join("out").exists());
}

/// World files: sizes past their budget refused before parsing, at a place; names and
/// numbers shown so that a terminal can show them.
#[test]
fn hostile_plane_world_files_end_in_a_placed_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "s.hstl", spec("w.toml", "0..=14"));
    let check = |world: &str| {
        write(d, "w.toml", world);
        let run = hstlc(d, &["check", "--format", "concise", "s.hstl"]);
        well_worded(&run.stdout);
        run
    };
    // 400,000 obstacles fit in 8 MiB, and the TOML parser took 796 MB for them.
    let many = plane(
        "[0.0, 14.0]",
        "1.0",
        &format!("obstacles = [\n{}]\n", "{circle=[1,1,1]},\n".repeat(400_000)),
    );
    let run = check(&many);
    assert_eq!(run.status, Some(1), "{}", run.stderr);
    assert!(
        run.stdout.contains(
            "HSTL034 error: w.toml:10927:1: the world file holds more than 65,536 values"
        ),
        "{}",
        run.stdout
    );
    // A dotted key past the parser's depth: "recursion limit", with no line.
    let dotted = plane("[0.0, 14.0]", "1.0", &format!("[{}]\nb = 1\n", vec!["a"; 100].join(".")));
    let run = check(&dotted);
    assert!(
        run.stdout.contains("w.toml:6:1: a key has more than 79 dotted parts"),
        "{}",
        run.stdout
    );
    // A name with an escape sequence reached the terminal raw.
    let run = check(&plane("[0.0, 14.0]", "1.0", "name = \"a\\u001b[31mred\"\n"));
    assert!(
        run.stdout.contains("w.toml:6:8: the world's name holds the control character U+001B"),
        "{}",
        run.stdout
    );
    assert!(!run.stdout.contains('\u{1b}'), "{}", run.stdout);
    // Finite bounds whose width overflows: accepted, trained in one tile, and refused only
    // when the pictures were drawn, with the bounds in 309 digits.
    let run = check(&plane("[-1.7976931348623157e308, 1.7976931348623157e308]", "1.0", ""));
    assert!(
        run.stdout.contains(
            "w.toml:2:5: x = [-1.7976931348623157e308, 1.7976931348623157e308]: the extent is \
             wider than the largest number"
        ),
        "{}",
        run.stdout
    );
    // A wide world: its range was spelt out in 300 digits.
    let run = check(&plane("[-1e300, 1e300]", "1.0", ""));
    assert!(
        run.stdout.contains("HSTL030 error: state variable `x` must be `float in -1e300..=1e300`"),
        "{}",
        run.stdout
    );
    assert!(run.stdout.len() < 2_000, "{}", run.stdout);
}

/// A world 2e300 wide and a step of 1e-300 train; their summaries and robustness figures
/// were printed in hundreds of digits (and the width as `inf`).
#[test]
fn extreme_plane_worlds_train_and_are_described_in_short_numbers() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "wide.toml", plane("[-1e300, 1e300]", "1.0", ""));
    write(d, "wide.hstl", spec("wide.toml", "-1e300..=1e300"));
    let run = hstlc(d, &["train", "wide.hstl", "--out", "wide"]);
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert!(run.stdout.contains("plane 2e300 x 14, step 1,"), "{}", run.stdout);
    let run = hstlc(d, &["eval", "wide/policy.json", "--starts", "2", "--steps", "150"]);
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert!(run.stdout.contains("e299"), "{}", run.stdout);
    assert!(run.stdout.len() < 1_500, "{}", run.stdout);
    write(d, "tiny.toml", plane("[0.0, 14.0]", "1e-300", ""));
    write(d, "tiny.hstl", spec("tiny.toml", "0..=14"));
    let run = hstlc(d, &["train", "tiny.hstl", "--out", "tiny", "--episodes", "1"]);
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert!(run.stdout.contains("plane 14 x 14, step 1e-300, 4 headings"), "{}", run.stdout);
    // The planned reference's lattice: its point count overflowed past 2^64 points (a panic
    // in a debug build, a lattice of no points in a release one), and half of a step of
    // 5e-324 is 0, which no doubling thins out (a loop without end).
    write(d, "least.toml", plane("[0.0, 14.0]", "5e-324", ""));
    write(d, "least.hstl", spec("least.toml", "0..=14"));
    let run = hstlc(d, &["train", "least.hstl", "--out", "least", "--episodes", "1"]);
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let args = ["eval", "least/policy.json", "--starts", "2", "--steps", "150"];
    let run = hstlc_within(d, &args, Duration::from_secs(120));
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    assert!(run.stdout.contains("planned reference: window rate"), "{}", run.stdout);
}

/// An edit of a document.
type Edit = Box<dyn Fn(&mut Value)>;

/// Hand-edited learned functions: every entry the spec and world determine is checked,
/// duplicates are refused, and nothing a document holds besides its weights takes more
/// memory than a budget.
#[test]
fn hand_edited_learned_policies_are_refused_in_words() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "w.toml", plane("[0.0, 14.0]", "1.0", ""));
    write(d, "s.hstl", spec("w.toml", "0..=14"));
    let run = hstlc(d, &["train", "s.hstl", "--out", "out", "--seed", "1"]);
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let text = std::fs::read_to_string(d.join("out/policy.json")).expect("policy.json");
    let doc: Value = serde_json::from_str(&text).expect("JSON");
    let eval = |name: &str, body: &str| {
        write(d, name, body);
        let run = hstlc(d, &["eval", name, "--starts", "1", "--steps", "50", "--burn-in", "0"]);
        well_worded(&run.stderr);
        run
    };
    assert_eq!(eval("ok.json", &text).status, Some(0));
    let edits: Vec<(&str, Edit, &str)> = vec![
        ("actions", Box::new(|d| d["actions"][0] = json!("Z")), "its `actions` is not what"),
        (
            "state_vars",
            Box::new(|d| d["state_vars"] = json!(["y", "x"])),
            "its `state_vars` is not what",
        ),
        (
            "options",
            Box::new(|d| d["options"].as_array_mut().expect("list").reverse()),
            "its `options` is not what",
        ),
        ("memory", Box::new(|d| d["memory"]["buckets"] = json!(3)), "its `memory` is not what"),
        ("switch", Box::new(|d| d["switch"] = json!("never")), "its `switch` is not what"),
        ("steps", Box::new(|d| d["steps"] = json!(-5)), "its `steps` is not a whole number"),
        (
            "builtin",
            Box::new(|d| d["env"]["name"] = json!("paper-plane")),
            "the world is named `paper-plane`, a built-in world, but its parameters are not",
        ),
        (
            "control",
            Box::new(|d| d["env"]["name"] = json!("a\u{1b}[31mred")),
            "the world's name holds the control character U+001B",
        ),
        (
            "long_name",
            Box::new(|d| d["env"]["name"] = json!("a".repeat(100_000))),
            "the world's name must hold 1 to 200 characters",
        ),
        (
            "env_extra",
            Box::new(|d| d["env"]["params"]["pad"] = json!([1, 2, 3])),
            "its `env` is not the world as `hstlc train` writes it",
        ),
    ];
    for (name, edit, expected) in &edits {
        let mut edited = doc.clone();
        edit(&mut edited);
        let run = eval(&format!("{name}.json"), &serde_json::to_string(&edited).expect("JSON"));
        assert_eq!(run.status, Some(2), "{name}: {}{}", run.stdout, run.stderr);
        assert!(run.stderr.contains(expected), "{name}: {}", run.stderr);
        assert!(!run.stderr.contains('\u{1b}'), "{name}: {}", run.stderr);
        assert!(run.stderr.len() < 1_000, "{name}: {}", run.stderr);
    }
    // A key given twice: the second was read and the first dropped.
    let twice = format!("{}, \"learner\": \"tiles\"}}", text.trim_end().trim_end_matches('}'));
    let run = eval("twice.json", &twice);
    assert_eq!(run.status, Some(2));
    assert!(run.stderr.contains("the entry `learner` is given twice"), "{}", run.stderr);
    // Padding in the world or the tiling was read as a generic document, 16 to 32 bytes
    // of memory a byte (1.3 GB for 40 MB); now it is refused at its budget as it is read.
    let pad = format!("[{}0]", "0,".repeat(1 << 20));
    let padded =
        text.replacen("\"obstacles\": []", &format!("\"obstacles\": [], \"pad\": {pad}"), 1);
    assert_ne!(padded, text);
    let run = eval("padded.json", &padded);
    assert_eq!(run.status, Some(2));
    assert!(
        run.stderr
            .contains("the document holds more values than a policy.json `hstlc train` writes"),
        "{}",
        run.stderr
    );
    // Padding under a key no policy has is skipped, not kept.
    let unknown = format!("{}, \"pad\": {pad}}}", text.trim_end().trim_end_matches('}'));
    assert_eq!(eval("unknown.json", &unknown).status, Some(0));
    // A learned function cut short was read as a table ("missing field `states`").
    let run = eval("cut.json", &text[..text.len() / 2]);
    assert_eq!(run.status, Some(2));
    assert!(run.stderr.contains("not a valid policy.json: EOF while parsing"), "{}", run.stderr);
}

/// Issue 30: a learned function's document holds its world whole (slip and noise
/// included) and its weights, and an edit every check lets through (the slip, one weight's
/// value) was evaluated as written. The document's `checksum` refuses both; the document
/// as written, reformatted, still evaluates.
#[test]
fn an_edited_slip_or_weight_of_a_learned_function_is_refused() {
    let dir = tempfile::tempdir().expect("temp dir");
    let d = dir.path();
    write(d, "w.toml", plane("[0.0, 14.0]", "1.0", "slip = 0.2\n"));
    write(d, "s.hstl", spec("w.toml", "0..=14"));
    let run = hstlc(d, &["train", "s.hstl", "--out", "out", "--seed", "1"]);
    assert_eq!(run.status, Some(0), "{}", run.stderr);
    let text = std::fs::read_to_string(d.join("out/policy.json")).expect("policy.json");
    let doc: Value = serde_json::from_str(&text).expect("JSON");
    assert_eq!(doc["env"]["params"]["slip"], json!(0.2));
    let eval = |name: &str, doc: &Value| {
        write(d, name, serde_json::to_string(doc).expect("JSON"));
        hstlc(d, &["eval", name, "--starts", "1", "--steps", "50", "--burn-in", "0"])
    };
    assert_eq!(eval("compact.json", &doc).status, Some(0));
    let mut slip = doc.clone();
    slip["env"]["params"]["slip"] = json!(0.0);
    let mut weight = doc.clone();
    let first = weight["weights"]["flat"]["A"][0][1].as_str().expect("hex").to_string();
    let other = f64::from_bits(u64::from_str_radix(&first, 16).expect("hex")) + 1.0;
    weight["weights"]["flat"]["A"][0][1] = json!(format!("{:016x}", other.to_bits()));
    for (name, edited) in [("slip", slip), ("weight", weight)] {
        let run = eval(&format!("{name}.json"), &edited);
        assert_eq!(run.status, Some(2), "{name}: {}{}", run.stdout, run.stderr);
        assert!(
            run.stderr.contains("the document was changed after it was written"),
            "{name}: {}",
            run.stderr
        );
    }
}
