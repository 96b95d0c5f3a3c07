//! Hostile input to the front end, generated in the tests (issue 11): byte order marks and
//! old Mac line ends, tens of thousands of errors, huge names. `check` stays exact, and its
//! diagnostics stay few enough to print.

use hstl_lang::{LineIndex, Severity, check};

/// `(line, column, code)` of each diagnostic.
fn places(src: &str) -> Vec<(usize, usize, &'static str)> {
    let index = LineIndex::new(src);
    check(src)
        .diagnostics
        .iter()
        .map(|d| {
            let p = index.position(src, d.range.start);
            (p.line, p.column, d.code)
        })
        .collect()
}

const SPEC: &str = "spec S {
    state { x: int in 0..=9 }
    // A comment.
    let A = x > 3;
    task eventually[0..5] Missing;
}
";

#[test]
fn byte_order_marks_and_every_line_end_read_alike() {
    let want = vec![(5, 27, "HSTL002")];
    assert_eq!(places(SPEC), want);
    assert_eq!(places(&SPEC.replace('\n', "\r\n")), want);
    // Old Mac files end lines with a lone `\r`: the comment ends there too.
    assert_eq!(places(&SPEC.replace('\n', "\r")), want);
    let with_bom = format!("\u{feff}{SPEC}");
    assert_eq!(places(&with_bom), want);
    assert!(!check(&with_bom.replace("Missing", "A")).has_errors());
}

#[test]
fn many_syntax_errors_are_capped_with_one_summary() {
    let cap = hstl_lang::check::MAX_DIAGNOSTICS;
    // The bench `hostile` times 40,000 and 400,000; the count does not matter here.
    let errors = 3_000;
    let mut src = String::from("spec S { state { x: int in 0..=9 }\n");
    for _ in 0..errors {
        src.push_str("let A = x > ;\n");
    }
    src.push_str("task x > 1; }\n");
    let diagnostics = check(&src).diagnostics;
    assert_eq!(diagnostics.len(), cap + 1);
    assert!(diagnostics[..cap].iter().all(|d| d.code == "HSTL001"));
    let last = &diagnostics[cap];
    assert_eq!((last.code, last.severity), ("HSTL024", Severity::Error));
    assert!(last.message.starts_with(&format!("{} more diagnostics", errors - cap)));
    // The first error still says what was expected.
    assert_eq!(diagnostics[0].message, "expected an expression, found `;`");
}

#[test]
fn a_huge_misspelt_name_gets_no_suggestion_but_an_answer() {
    let name = "a".repeat(100_000);
    let typo = format!("b{}", &name[1..]);
    let src = format!("spec S {{ state {{ x: int in 0..=9 }} let {name} = x > 1; task {typo}; }}");
    let diagnostics = check(&src).diagnostics;
    let unknown = diagnostics.iter().find(|d| d.code == "HSTL002").expect("an unknown name");
    assert_eq!(unknown.help.as_deref(), Some(format!("declare it: `let {typo} = ...;`").as_str()));
    // Both names are also too long to be names.
    assert_eq!(diagnostics.iter().filter(|d| d.code == "HSTL051").count(), 1);
}

#[test]
fn many_unknown_names_among_many_lets_still_suggest_first() {
    let mut src = String::from("spec S { state { x: int in 0..=9 }\n");
    for i in 0..3_000 {
        src.push_str(&format!("let L{i} = x > 1;\nlet M{i} = Z{i} && x < 3;\n"));
    }
    src.push_str("task L0; }\n");
    let diagnostics = check(&src).diagnostics;
    assert_eq!(diagnostics.len(), hstl_lang::check::MAX_DIAGNOSTICS + 1);
    // The first reported ones get their suggestion: Z0 is one letter off L0 and M0.
    assert_eq!(diagnostics[0].help.as_deref(), Some("did you mean `L0`?"));
}

/// A domain too costly to enumerate is not counted, so `preset: auto` cannot know that
/// planning fits in its budget: it Q-learns rather than leave `train` to refuse the plan.
#[test]
fn the_preset_q_learns_where_the_domain_is_not_counted() {
    let mut src = String::from("spec Big {\n    state { x: int in 0..=399, y: int in 0..=499 }\n");
    src.push_str("    let L0 = x > 3;\n");
    for k in 1..120 {
        src.push_str(&format!("    let L{k} = L{} && y > 3;\n", k - 1));
    }
    src.push_str(
        "    let A = L119 && x < 300;\n    task always[0..] eventually[0..40] A;\n    option A;\n    learn { preset: auto }\n}\n",
    );
    let checked = check(&src);
    assert!(checked.diagnostics.iter().any(|d| d.code == "HSTL022"), "the domain is counted");
    assert!(checked.diagnostics.iter().all(|d| d.severity != Severity::Error));
    let spec = &checked.specs[0];
    assert_eq!(spec.learn.plan, hstl_lang::Plan::Off);
    let expansion = spec.preset_expansion.as_deref().unwrap_or_default();
    assert!(expansion.contains("learn {") && !expansion.contains("plan: model"), "{expansion}");
}

/// Issue 30: `preset: auto` on a 400 x 400 grid failed on its own choice (HSTL033: its
/// memory and the window reward over windows it could not plan). The preset now sizes the
/// memory within the memory budget: no error, only the note of what the run will take.
#[test]
fn the_preset_on_a_400_by_400_grid_passes_its_own_check() {
    let src = "spec Big {
        state { x: int in 0..=399, y: int in 0..=399 }
        let A = x < 20 && y < 20;
        let B = x > 379 && y > 379;
        let C = x > 379 && y < 20;
        task always[0..] (eventually[0..400] A && eventually[0..400] B && eventually[0..400] C);
        option A; option B; option C;
        learn { preset: auto }
    }";
    let checked = check(src);
    let errors: Vec<&str> = checked
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .map(|d| d.code)
        .collect();
    assert!(errors.is_empty(), "{errors:?}");
    // What it chose is what `check` says the run takes: no more than the note.
    assert!(checked.diagnostics.iter().all(|d| d.code == "HSTL180"), "{:?}", checked.diagnostics);
}

/// Issue 30: specs `check` passed that then took gigabytes: `memory: 20` over three regions
/// (2.7 GB to train, 6.6 GB to evaluate) and a 1024 x 1024 world (4.1 GB to train two
/// episodes). Both are HSTL084 now, over the memory budget.
#[test]
fn specs_that_blew_up_at_run_time_are_refused_by_check() {
    let three = "spec M {
        state { x: int in 0..=14, y: int in 0..=14 }
        let A = x > 3 && x < 9 && y > 10 && y < 14;
        let B = x > 1 && x < 5 && y > 1 && y < 5;
        let C = 9 < x < 13 && 1 < y < 7;
        task always[0..] (eventually[0..40] A && eventually[0..40] B && eventually[0..40] C);
        option A { reach: A, init: !A, terminate: A }
        option B { reach: B, init: !B, terminate: B }
        option C { reach: C, init: !C, terminate: C }
        options { A, B, C }
        learn { episodes: 2, choices: 5, memory: 20, reward: window }
    }";
    let huge = "spec H {
        state { x: int in 0..=1023, y: int in 0..=1023 }
        let A = x < 3 && y < 3;
        let B = x > 1020 && y > 1020;
        task always[0..] (eventually[0..4000] A && eventually[0..4000] B);
        option A { reach: A, init: !A, terminate: A }
        option B { reach: B, init: !B, terminate: B }
        options { A, B }
        learn { episodes: 2, choices: 5 }
    }";
    for src in [three, huge] {
        let codes: Vec<&str> = check(src).diagnostics.iter().map(|d| d.code).collect();
        assert!(codes.contains(&"HSTL084"), "{codes:?}");
    }
}
