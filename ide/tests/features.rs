//! The editor features on plain offsets, without the protocol: hover words and
//! completion.

use hstl::lang::WorldProblem;
use hstl_ide::{Analysis, WorldCache, completion, hover};

/// A cache that reads no world (these documents name none).
fn no_worlds() -> WorldCache {
    WorldCache::new(|name, _| {
        Err(WorldProblem { message: format!("no world `{name}` here"), help: String::new() })
    })
}

/// The hover text at the `nth` occurrence of `word` in `text`.
fn hover_at(text: &str, word: &str, nth: usize) -> String {
    let a = Analysis::new(text.to_string(), &mut no_worlds(), None);
    let at = text.match_indices(word).nth(nth).map(|(i, _)| i).expect("the word");
    match hover(&a, at + 1) {
        Some((_, text)) => text,
        None => panic!("no hover at `{word}`"),
    }
}

#[test]
fn the_time_variable_and_dense_windows_hover_as_dense_time() {
    let text = "spec S {
state { t: time, x: float }
let P = once[0.5..=1] x > 0;
task eventually[0..=2.5] P;
}
";
    let t = hover_at(text, "t:", 0);
    assert!(t.contains("time variable (dense time)"), "{t}");
    let e = hover_at(text, "eventually", 0);
    assert!(e.contains("the times `t+0` to `t+2.5`"), "{e}");
    let o = hover_at(text, "once", 0);
    assert!(o.contains("`t-1` to `t-0.5`") && o.contains("first time stamp"), "{o}");
}

/// Each past-time operator's hover: its meaning, and its window counted back from now.
#[test]
fn past_operators_hover_with_their_past_window() {
    let text = "spec S {
state { x: float, y: float }
let P = once[2..5] x > 0 || historically[0..=3] y > 0;
let Q = x > 0 since[1..] y > 0;
let R = prev x > 0 && next y > 0 && historically x > 0;
task P && Q && R;
}
";
    let cases: [(&str, usize, &[&str]); 6] = [
        (
            "once",
            0,
            &[
                "**once**",
                "maximum",
                "past window",
                "`t-4` to step `t-2` (3 steps; step `t-5` excluded), clipped at the start",
            ],
        ),
        (
            "historically",
            0,
            &[
                "**historically**",
                "minimum",
                "`t-3` to the current step `t`, both included (4 steps)",
            ],
        ),
        (
            "since",
            0,
            &[
                "**since**",
                "after `t'`",
                "`[1..]`: the window runs from the start of the trace to step `t-1`",
            ],
        ),
        ("prev", 0, &["**prev**", "one step back", "`+inf` at the first step"]),
        ("next", 0, &["**next**", "one step ahead", "`+inf` at the last step"]),
        (
            "historically",
            1,
            &[
                "No interval, so `[0..]`: the window runs from the start of the trace to the current step",
            ],
        ),
    ];
    for (word, nth, want) in cases {
        let got = hover_at(text, word, nth);
        for w in want {
            assert!(got.contains(w), "`{word}` #{nth}: {w:?} not in {got:?}");
        }
    }
    // The future operators' windows still count forward.
    let text = "spec S { state { x: float } task eventually[2..5] x > 0; }";
    let got = hover_at(text, "eventually", 0);
    assert!(
        got.contains("step `t+2` to step `t+4` (3 steps; step `t+5` excluded), clipped at the end"),
        "{got}"
    );
}

/// Completion offers the past-time keywords with the others.
#[test]
fn completion_offers_past_operators() {
    let text = "spec S { state { x: float } task x > 0; }";
    let a = Analysis::new(text.to_string(), &mut no_worlds(), None);
    let labels: Vec<String> = completion(&a, 30).into_iter().map(|i| i.label).collect();
    for k in ["once", "historically", "since", "prev", "next"] {
        assert!(labels.iter().any(|l| l == k), "{k} missing from {labels:?}");
    }
}
