//! Unit tests of the parser's tree shapes and ranges, the checked formulas, the state
//! evaluator and positions.

use hstl_lang::syntax::{ExprKind, Formula, FormulaKind, Item};
use hstl_lang::{CFormulaKind, LetKind, LineIndex, check, parse};

/// Parses `spec S { state { x: int in 0..=9, y: int in 0..=9 } <items> }` and returns
/// the source with the formula of the `let` named `name`.
fn let_formula(items: &str, name: &str) -> (String, Formula) {
    let src = format!("spec S {{ state {{ x: int in 0..=9, y: int in 0..=9 }} {items} }}");
    let parsed = parse(&src);
    assert!(parsed.diagnostics.is_empty(), "{:?}", parsed.diagnostics);
    let f = parsed.file.specs[0]
        .items
        .iter()
        .find_map(|i| match i {
            Item::Let(l) if l.name.name == name => Some(l.formula.clone()),
            _ => None,
        })
        .expect("the let");
    (src, f)
}

fn text<'a>(src: &'a str, f: &Formula) -> &'a str {
    &src[f.range.clone()]
}

#[test]
fn nested_formula_ranges_cover_exactly_their_text() {
    let (src, f) = let_formula("let A = !(x > 1 && always[0..5] (y < 2)) ;", "A");
    assert_eq!(text(&src, &f), "!(x > 1 && always[0..5] (y < 2))");
    let FormulaKind::Not(inner) = &f.kind else { panic!("{f:?}") };
    assert_eq!(text(&src, inner), "(x > 1 && always[0..5] (y < 2))");
    let FormulaKind::Paren(and) = &inner.kind else { panic!("{inner:?}") };
    let FormulaKind::And(parts) = &and.kind else { panic!("{and:?}") };
    assert_eq!(text(&src, &parts[0]), "x > 1");
    assert_eq!(text(&src, &parts[1]), "always[0..5] (y < 2)");
    let FormulaKind::Always(Some(iv), body) = &parts[1].kind else { panic!("{:?}", parts[1]) };
    assert_eq!(&src[iv.range.clone()], "[0..5]");
    assert_eq!((iv.start.value, iv.end.as_ref().map(|e| e.value)), (0.0, Some(5.0)));
    assert_eq!(text(&src, body), "(y < 2)");
}

#[test]
fn chained_comparison_is_one_node_and_checks_to_a_conjunction() {
    let (src, f) = let_formula("let A = 3 < x < 9; task always[0..] eventually[0..5] A;", "A");
    let FormulaKind::Compare { first, rest } = &f.kind else { panic!("{f:?}") };
    assert_eq!(&src[first.range.clone()], "3");
    assert_eq!(rest.len(), 2);
    let checked = check(&src);
    let CFormulaKind::And(parts) = &checked.specs[0].lets[0].formula.kind else { panic!() };
    let texts: Vec<&str> = parts.iter().map(|p| &src[p.range.clone()]).collect();
    assert_eq!(texts, ["3 < x", "x < 9"]);
}

#[test]
fn until_binds_tighter_than_and() {
    let (src, f) =
        let_formula("let a = x > 1; let b = y > 1; let c = x < 1; let T = a && b until c;", "T");
    let FormulaKind::And(parts) = &f.kind else { panic!("{f:?}") };
    assert_eq!(text(&src, &parts[0]), "a");
    assert!(matches!(parts[1].kind, FormulaKind::Until(..)), "{:?}", parts[1]);
    assert_eq!(text(&src, &parts[1]), "b until c");
}

#[test]
fn prefix_operators_bind_tighter_than_and() {
    let (src, f) = let_formula("let p = x > 1; let q = y > 1; let T = always[0..5] p && q;", "T");
    let FormulaKind::And(parts) = &f.kind else { panic!("{f:?}") };
    assert_eq!(text(&src, &parts[0]), "always[0..5] p");
    assert!(matches!(parts[0].kind, FormulaKind::Always(..)));
    assert_eq!(text(&src, &parts[1]), "q");
}

#[test]
fn implication_is_right_associative_and_loosest() {
    let (src, f) = let_formula("let a = x > 1; let T = a || a -> a && a -> a;", "T");
    let FormulaKind::Implies(l, r) = &f.kind else { panic!("{f:?}") };
    assert_eq!(text(&src, l), "a || a");
    assert_eq!(text(&src, r), "a && a -> a");
    assert!(matches!(r.kind, FormulaKind::Implies(..)));
}

/// The tree of a formula, fully parenthesised, with its leaves as written.
fn shape(src: &str, f: &Formula) -> String {
    let iv = |i: &Option<hstl_lang::syntax::Interval>| {
        i.as_ref().map_or(String::new(), |i| src[i.range.clone()].to_string())
    };
    let join = |v: &[Formula], op: &str| {
        let parts: Vec<String> = v.iter().map(|g| shape(src, g)).collect();
        format!("({})", parts.join(&format!(" {op} ")))
    };
    match &f.kind {
        FormulaKind::True
        | FormulaKind::False
        | FormulaKind::Name(_)
        | FormulaKind::Compare { .. } => text(src, f).to_string(),
        FormulaKind::Paren(g) => shape(src, g),
        FormulaKind::Not(g) => format!("(!{})", shape(src, g)),
        FormulaKind::Always(i, g) => format!("(always{} {})", iv(i), shape(src, g)),
        FormulaKind::Eventually(i, g) => format!("(eventually{} {})", iv(i), shape(src, g)),
        FormulaKind::Once(i, g) => format!("(once{} {})", iv(i), shape(src, g)),
        FormulaKind::Historically(i, g) => format!("(historically{} {})", iv(i), shape(src, g)),
        FormulaKind::Prev(g) => format!("(prev {})", shape(src, g)),
        FormulaKind::Next(g) => format!("(next {})", shape(src, g)),
        FormulaKind::Until(a, i, b) => {
            format!("({} until{} {})", shape(src, a), iv(i), shape(src, b))
        }
        FormulaKind::Since(a, i, b) => {
            format!("({} since{} {})", shape(src, a), iv(i), shape(src, b))
        }
        FormulaKind::And(v) => join(v, "&&"),
        FormulaKind::Or(v) => join(v, "||"),
        FormulaKind::Implies(a, b) => format!("({} -> {})", shape(src, a), shape(src, b)),
    }
}

/// The past-time operators' precedence (PAST-TIME.md): `since` as `until`, below `&&`;
/// `once`, `historically`, `prev` and `next` as the other prefix operators.
#[test]
fn past_operators_bind_as_their_future_mirrors() {
    let cases = [
        ("prev x > 0 && y > 0", "((prev x > 0) && y > 0)"),
        ("next !x > 0", "(next (!x > 0))"),
        ("prev next prev x > 0", "(prev (next (prev x > 0)))"),
        ("once[0..3] x > 1 since y > 1", "((once[0..3] x > 1) since y > 1)"),
        ("x > 1 since[2..=5] y > 1", "(x > 1 since[2..=5] y > 1)"),
        ("a && b since c", "(a && (b since c))"),
        ("a since b || c", "((a since b) || c)"),
        ("a since (b until c)", "(a since (b until c))"),
        ("historically[1..] a -> once a", "((historically[1..] a) -> (once a))"),
        ("always[0..] (once[0..=10] a && prev b)", "(always[0..] ((once[0..=10] a) && (prev b)))"),
        ("historically eventually[0..4] a", "(historically (eventually[0..4] a))"),
    ];
    let lets = "let a = x > 1; let b = y > 1; let c = x < 1;";
    for (formula, want) in cases {
        let (src, f) = let_formula(&format!("{lets} let T = {formula}; task T;"), "T");
        assert_eq!(shape(&src, &f), want, "{formula}");
        let checked = check(&src);
        let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.is_error()).collect();
        assert!(errors.is_empty(), "{formula}: {errors:?}");
        let t = checked.specs[0].lets.iter().find(|l| l.name == "T").expect("T");
        assert_eq!(t.kind, LetKind::Temporal, "{formula}");
    }
}

#[test]
fn parenthesised_expression_is_a_comparison_and_parenthesised_comparison_a_formula() {
    let (src, f) = let_formula("let A = (x + 1) > 3;", "A");
    let FormulaKind::Compare { first, .. } = &f.kind else { panic!("{f:?}") };
    assert!(matches!(first.kind, ExprKind::Paren(_)));
    assert_eq!(&src[first.range.clone()], "(x + 1)");
    let (_, f) = let_formula("let A = (x) > 3;", "A");
    assert!(matches!(f.kind, FormulaKind::Compare { .. }), "{f:?}");
    let (src, f) = let_formula("let A = (x > 1);", "A");
    let FormulaKind::Paren(inner) = &f.kind else { panic!("{f:?}") };
    assert_eq!(text(&src, inner), "x > 1");
}

#[test]
fn ranges_do_not_lex_as_floats_and_macro_spacing_parses() {
    let (src, f) = let_formula("let A = eventually[0..40] x > - 3 && x > 1e-6;", "A");
    let FormulaKind::And(parts) = &f.kind else { panic!("{f:?}") };
    let FormulaKind::Eventually(Some(iv), _) = &parts[0].kind else { panic!() };
    assert_eq!(&src[iv.start.range.clone()], "0");
    assert_eq!(iv.end.as_ref().map(|e| e.text.as_str()), Some("40"));
    let (src2, f2) = let_formula("let A = eventually [ 0 ..= 40 ] x > 3 ;", "A");
    let FormulaKind::Eventually(Some(iv), _) = &f2.kind else { panic!() };
    assert!(iv.inclusive);
    assert_eq!(text(&src2, &f2), "eventually [ 0 ..= 40 ] x > 3");
}

#[test]
fn doc_comments_and_comments_are_kept() {
    let src = "/// The spec.\nspec S { /* block */ state { /// Column.\n x: int in 0..=3 } // line\n //// not a doc\n task true; }";
    let parsed = parse(src);
    assert!(parsed.diagnostics.is_empty(), "{:?}", parsed.diagnostics);
    let spec = &parsed.file.specs[0];
    assert_eq!(spec.doc.as_ref().map(|d| d.text()), Some("The spec.".to_string()));
    let Item::State(b) = &spec.items[0] else { panic!() };
    assert_eq!(b.vars[0].doc.as_ref().map(|d| d.text()), Some("Column.".to_string()));
    let kinds: Vec<_> =
        parsed.file.comments.iter().map(|c| (c.kind, &src[c.range.clone()])).collect();
    use hstl_lang::syntax::CommentKind::*;
    assert_eq!(
        kinds,
        [
            (Doc, "/// The spec."),
            (Block, "/* block */"),
            (Doc, "/// Column."),
            (Line, "// line"),
            (Line, "//// not a doc")
        ]
    );
}

#[test]
fn state_robustness_follows_the_semantics() {
    let src = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/valid/case_study_ot1.hstl"
    ))
    .expect("fixture");
    let checked = check(&src);
    let spec = &checked.specs[0];
    let a = &spec.lets[0];
    assert_eq!(a.kind, LetKind::State);
    for (x, y) in [(5.0, 12.0), (0.0, 0.0), (8.0, 13.0)] {
        let want = [x - 3.0, 9.0 - x, y - 10.0, 14.0 - y].into_iter().fold(f64::INFINITY, f64::min);
        assert_eq!(spec.state_robustness(&a.formula, &[x, y]), Some(want));
    }
    let task = spec.task.as_ref().expect("task");
    assert_eq!(spec.state_robustness(&task.formula, &[1.0, 1.0]), None);
    let conj = spec.persistent_conjuncts(&src).expect("persistent");
    assert_eq!(
        conj.iter().map(|c| (c.name.as_str(), c.steps)).collect::<Vec<_>>(),
        [("A", 40), ("B", 40), ("C", 40)]
    );
    let incl = src.replace("eventually[0..40] C", "eventually[0..=40] C");
    let checked = check(&incl);
    let conj = checked.specs[0].persistent_conjuncts(&incl).expect("persistent");
    assert_eq!(conj[2].steps, 41);
}

#[test]
fn line_index_counts_characters_and_utf16_units() {
    let src = "ab\n// é😀x\nz";
    let idx = LineIndex::new(src);
    let x = src.find('x').expect("x");
    let p = idx.position(src, x);
    assert_eq!((p.line, p.column, p.utf16_column), (2, 6, 6));
    assert_eq!(idx.offset(src, 2, 6), x);
    assert_eq!(idx.offset_utf16(src, 1, 6), x);
    let end = idx.position(src, src.len());
    assert_eq!((end.line, end.column), (3, 2));
    // Inside a multi-byte character: moved back to its start.
    let e = src.find('é').expect("é");
    assert_eq!(idx.position(src, e + 1), idx.position(src, e));
}

#[test]
fn locations_and_the_concise_format_count_characters() {
    // `é😀` takes 6 bytes but 2 columns.
    let src = "\n/* é😀 */ spec S { state { x: int in 0..=9 } let A = x > 3; }\n";
    let checked = check(src);
    let d = &checked.diagnostics[0];
    let at = LineIndex::new(src).location(src, &d.range);
    assert_eq!((at.line, at.column, at.end_line, at.end_column), (2, 15, 2, 16));
    let files = [hstl_lang::FileDiagnostics {
        name: "s.hstl",
        source: src,
        diagnostics: &checked.diagnostics,
    }];
    assert_eq!(
        hstl_lang::render_concise(&files),
        "s.hstl:2:15: HSTL015 error: spec `S` has no `task`\n  \
         help: add the task, such as `task always[0..] eventually[0..40] A;`\n\
         checked 1 file: 1 error, 0 warnings\n"
    );
}

#[test]
fn time_is_a_type_only_after_a_colon_and_makes_a_dense_spec() {
    // `time` stays a valid name: a variable, a let, the time variable itself.
    let src = "spec S { state { time: time, x: float } let tick = x > 1; \
               task eventually[0..=2.5] tick && always[1e-1..=3] x < 9; }";
    let checked = check(src);
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics);
    let spec = &checked.specs[0];
    assert!(spec.is_dense());
    assert_eq!(spec.time.as_ref().map(|t| t.name.as_str()), Some("time"));
    assert_eq!(spec.state_vars.len(), 1, "the time variable is no state variable");
    assert_eq!(spec.time_decimals, 1);
    assert_eq!(spec.bound_text(25), "2.5");
    assert_eq!(spec.bound_text(30), "3");
    // A discrete spec: whole-number bounds, no time variable.
    let discrete = check("spec D { state { time: int in 0..=9 } task eventually[0..3] time > 1; }");
    assert!(!discrete.has_errors(), "{:?}", discrete.diagnostics);
    assert!(!discrete.specs[0].is_dense());
    assert_eq!(discrete.specs[0].time_decimals, 0);
}

#[test]
fn dense_bounds_are_scaled_to_the_longest_fraction() {
    let src = "spec S { state { t: time, x: float } \
               task eventually[0.25..=1] always[2..] x > 0; }";
    let checked = check(src);
    assert!(!checked.has_errors(), "{:?}", checked.diagnostics);
    let spec = &checked.specs[0];
    assert_eq!(spec.time_decimals, 2);
    let Some(task) = &spec.task else { panic!("no task") };
    let CFormulaKind::Eventually(i, inner) = &task.formula.kind else { panic!("{task:?}") };
    assert_eq!((i.start, i.end), (25, hstl_lang::Bound::Inclusive(100)));
    let CFormulaKind::Always(j, _) = &inner.kind else { panic!("{inner:?}") };
    assert_eq!((j.start, j.end), (200, hstl_lang::Bound::Unbounded));
}
