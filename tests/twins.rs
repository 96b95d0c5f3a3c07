//! Twins held equal: where two crates must each keep a copy of one computation, a test
//! draws inputs and holds the copies to one answer (as `tests/limits.rs` does for the plan
//! budget).

use hstl::load::load;
use hstl::monitor::{Monitor, Samples};

/// The domain of the drawn specs: `x` in `X`, `y` in `Y`, both `int`.
const X: (i64, i64) = (-2, 2);
const Y: (i64, i64) = (-1, 2);

/// A small linear congruential generator: the draws are the same on every run.
struct Draw(u64);

impl Draw {
    fn below(&mut self, n: u64) -> u64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 33) % n
    }

    /// An expression over `x` and `y` of at most `depth` operators.
    fn expr(&mut self, depth: u32) -> String {
        let leaf = depth == 0 || self.below(4) == 0;
        if leaf {
            return ["x", "y", "0", "1", "2", "3"][self.below(6) as usize].to_string();
        }
        match self.below(7) {
            0 => format!("sqrt({})", self.expr(depth - 1)),
            1 => format!("abs({})", self.expr(depth - 1)),
            2 => format!("-({})", self.expr(depth - 1)),
            k => {
                let (a, b) = (self.expr(depth - 1), self.expr(depth - 1));
                let op = ["+", "-", "*", "/"][k as usize - 3];
                format!("({a} {op} {b})")
            }
        }
    }
}

/// The front end's lint (`HSTL060`, `hstl_lang::lints`) and the monitors' refusal
/// (`hstl_robustness::nan`) each search a comparison for the expression that makes a NaN:
/// on every drawn comparison, over the whole `int` domain, both find the same first state,
/// the same expression and the same operation, or both find none.
#[test]
fn the_front_end_and_the_monitor_find_the_same_nan_culprit() {
    let mut draw = Draw(29);
    let states: Vec<(f64, f64)> =
        (X.0..=X.1).flat_map(|x| (Y.0..=Y.1).map(move |y| (x as f64, y as f64))).collect();
    let xs: Vec<f64> = states.iter().map(|s| s.0).collect();
    let ys: Vec<f64> = states.iter().map(|s| s.1).collect();
    let (mut found, mut checked) = (0, 0);
    for _ in 0..1500 {
        let cmp = format!("{} > {}", draw.expr(3), draw.expr(3));
        let spec = |domain: &str| {
            format!("spec T {{ state {{ x: {domain}, y: {domain} }} task always[0..] ({cmp}); }}")
        };
        let int = format!(
            "spec T {{ state {{ x: int in {}..={}, y: int in {}..={} }} task always[0..] ({cmp}); }}",
            X.0, X.1, Y.0, Y.1
        );
        let checked_spec = hstl::lang::check::check(&int);
        let lint: Vec<String> = checked_spec
            .diagnostics
            .iter()
            .filter(|d| d.code == "HSTL060")
            .map(|d| d.message.clone())
            .collect();
        let Ok(loaded) = load(&spec("float"), None) else { continue };
        let Ok(monitor) = Monitor::new(&loaded.spec, None) else { continue };
        checked += 1;
        let refused = monitor.signal(&Samples::Columns(vec![&xs, &ys])).err().map(|e| {
            // "`text` is NaN at step k: operation", with step k the k-th state.
            let message = e.to_string();
            let (head, rest) = message.split_once(" is NaN at step ").expect(&message);
            let (step, operation) = rest.split_once(": ").expect(&message);
            let (x, y) = states[step.parse::<usize>().expect(&message)];
            format!("{head} is NaN at x = {x}, y = {y}: {operation}")
        });
        // The lint quotes the source, the monitor prints the expression (with the
        // parentheses it needs): the same expression, state and operation.
        let bare = |m: &String| m.replace(['(', ')', ' '], "");
        assert_eq!(
            lint.iter().map(bare).collect::<Vec<_>>(),
            refused.iter().map(bare).collect::<Vec<_>>(),
            "{cmp}: {lint:?} {refused:?}"
        );
        found += usize::from(refused.is_some());
    }
    assert!(checked > 1000, "{checked} of 1500 drawn specs loaded");
    assert!(found > 100 && found < checked - 100, "{found} of {checked} found a NaN");
}

/// The shells' file reader (`hstl-files`, which knows nothing of the language) words a
/// file that is not UTF-8 at the line and column of its first bad byte; the language's
/// `LineIndex` counts lines and columns for every diagnostic. Over drawn texts of line
/// breaks (`\n`, `\r\n`, a lone `\r`), ASCII and multi-byte characters, they agree.
#[test]
fn the_file_reader_and_the_language_count_lines_alike() {
    let pieces = ["\n", "\r\n", "\r", "a", "é", "€", "𝄞", " ", "\r\r", "\n\r"];
    let mut draw = Draw(29);
    for _ in 0..2000 {
        let n = draw.below(12);
        let text: String =
            (0..n).map(|_| pieces[draw.below(pieces.len() as u64) as usize]).collect();
        let p = hstl::lang::LineIndex::new(&text).position(&text, text.len());
        assert_eq!(hstl_files::read::end_position(&text), (p.line, p.column), "{text:?}");
    }
}
