//! End to end in a real editor: Neovim, headless, runs `tests/nvim/e2e.lua`, which starts
//! `hstlc lsp` on a malformed spec, checks the diagnostic's range and code, fixes the
//! buffer, waits for the diagnostics to clear, and asks for hover and formatting.
//!
//! Without `nvim` on the PATH the test is skipped with a note, unless `CI` is set: then
//! it fails (CI installs Debian's `neovim`).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use hstl::lang::LineIndex;

const MALFORMED: &str = "/// A patrol between two corners.
spec Patrol {
    state { x: int in 0..=9, y: int in 0..=9 }
    let A = x > 3 && y < 2
    let B = x < 2;
    task always[0..] (eventually[0..20] A && eventually[0..20] B);
}
";

const FIX_LINE: usize = 3;
const FIX_TEXT: &str = "    let A = x > 3 && y < 2;";

fn nvim_available() -> bool {
    Command::new("nvim")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

#[test]
fn neovim_drives_the_language_server() {
    if !nvim_available() {
        let ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "false" && v != "0");
        assert!(!ci, "CI is set but `nvim` is not installed (apt-get install -y neovim)");
        eprintln!("note: `nvim` is not installed; skipping the Neovim end-to-end test");
        return;
    }
    // What the editor must see, from the front end itself.
    let first = hstl::lang::check(MALFORMED).diagnostics.into_iter().next().expect("a diagnostic");
    assert_eq!(first.code, "HSTL001");
    let start = LineIndex::new(MALFORMED).position(MALFORMED, first.range.start);
    let mut lines: Vec<&str> = MALFORMED.lines().collect();
    lines[FIX_LINE] = FIX_TEXT;
    let fixed = lines.join("\n") + "\n";
    assert!(hstl::lang::check(&fixed).diagnostics.is_empty());
    let formatted = hstl::lang::format(&fixed).expect("the fixed spec formats");
    assert_ne!(formatted, fixed, "the spec must need formatting for the test to mean anything");
    let always = fixed.find("always").expect("always");
    let hover = LineIndex::new(&fixed).position(&fixed, always + 2);

    let dir = tempfile::tempdir().expect("temporary directory");
    let spec = dir.path().join("patrol.hstl");
    std::fs::write(&spec, MALFORMED).expect("write spec");
    let expected = dir.path().join("formatted.hstl");
    std::fs::write(&expected, &formatted).expect("write expected");
    let result = dir.path().join("result.txt");
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/nvim/e2e.lua");

    let mut child = Command::new("nvim")
        .args(["--headless", "--clean", "-n", "-u", "NONE", "-i", "NONE", "-c"])
        .arg(format!("luafile {}", script.display()))
        .env("HSTLC", env!("CARGO_BIN_EXE_hstlc"))
        .env("SPEC", &spec)
        .env("EXPECT_CODE", first.code)
        .env("EXPECT_LINE", (start.line - 1).to_string())
        .env("EXPECT_COL", start.utf16_column.to_string())
        .env("FIX_LINE", FIX_LINE.to_string())
        .env("FIX_TEXT", FIX_TEXT)
        .env("HOVER_LINE", (hover.line - 1).to_string())
        .env("HOVER_COL", hover.utf16_column.to_string())
        .env("FORMATTED", &expected)
        .env("RESULT", &result)
        .env("XDG_STATE_HOME", dir.path())
        .env("XDG_DATA_HOME", dir.path())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start nvim");
    let deadline = Instant::now() + Duration::from_secs(90);
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for nvim") {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let out = child.wait_with_output().expect("nvim output");
            panic!("nvim did not finish in 90 s:\n{}", String::from_utf8_lossy(&out.stderr));
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let out = child.wait_with_output().expect("nvim output");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(status.success(), "nvim failed ({status}):\n{stderr}");
    let verdict = std::fs::read_to_string(&result).unwrap_or_default();
    assert_eq!(verdict, "OK\n", "the script did not finish:\n{stderr}");
}
