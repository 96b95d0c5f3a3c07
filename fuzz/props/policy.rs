//! `policy.json` on any bytes, as `hstlc eval` and `hstl.Policy.load` read it: never a
//! panic; a refusal has a message and a help without a trailing period; a policy that
//! loads replays a few short greedy runs without a panic, its figures in range.
use hstl::evaluate::{Evaluation, Runs, evaluate, replay};

/// The property; panics when it fails.
pub fn check(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else { return };
    match replay(text) {
        Ok(loaded) => {
            let runs = Runs { starts: 2, steps: 30, burn_in: 5, seed: 7 };
            match evaluate(&loaded, runs) {
                Ok(Evaluation::Window { report }) => {
                    assert!((0.0..=1.0).contains(&report.rate), "{}", report.rate);
                }
                Ok(Evaluation::Robustness { values, complete }) => {
                    assert_eq!((values.len(), complete.len()), (2, 2));
                }
                Err(p) => assert!(!p.message.is_empty() && !p.message.ends_with('.')),
            }
        }
        Err(p) => {
            assert!(!p.message.is_empty() && !p.message.ends_with('.'), "{}", p.message);
            assert!(p.help.as_deref().is_none_or(|h| !h.ends_with('.')), "{:?}", p.help);
        }
    }
}
