//! Random dense-time formulas (every operator dense time has) on random traces with
//! per-variable sampling: the offline evaluator equals the literal reference, and the
//! online monitor equals the offline evaluator.
//!
//! Stamps and bounds are multiples of 1/4 (exact in binary), so no breakpoint rounds and
//! the reference's literal reading of the table is exact; rounding is covered by the rtamt
//! oracle (`dense_oracle.rs`) and, for online against offline, by decimal stamps below.

mod dense_common;

use dense_common::{points, reference, same_points};
use hstl_robustness::dense::{
    DenseFormula, DenseMonitor, DenseTrace, DenseTraceBuilder, TimeScale,
};
use hstl_robustness::{Bound, CmpOp, Expr, Formula, Interval};
use proptest::prelude::*;

fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        8 => (-6i32..=6).prop_map(f64::from),
        1 => Just(f64::INFINITY),
        1 => Just(f64::NEG_INFINITY),
        1 => (-60i32..=60).prop_map(|v| f64::from(v) / 8.0),
    ]
}

/// Rows: a start stamp, then gaps (in units of `unit`), each cell filled or empty.
fn rows(unit: f64, max_len: usize) -> impl Strategy<Value = Vec<(f64, Vec<Option<f64>>)>> {
    let row = (1u32..=8, proptest::collection::vec(proptest::option::weighted(0.6, value()), 2));
    (-8i32..=8, proptest::collection::vec(value(), 2), proptest::collection::vec(row, 0..max_len))
        .prop_map(move |(start, first, rest)| {
            let mut t = f64::from(start) * unit * 2.0;
            let mut out = vec![(t, first.into_iter().map(Some).collect())];
            let mut k = f64::from(start) * 2.0;
            for (gap, cells) in rest {
                k += f64::from(gap);
                // One operation from a whole number: the stamp is the nearest double.
                t = k * unit;
                out.push((t, cells));
            }
            out
        })
}

fn build(rows: &[(f64, Vec<Option<f64>>)]) -> DenseTrace {
    let mut b = DenseTraceBuilder::new(2);
    for (t, cells) in rows {
        b.push(*t, cells).expect("increasing stamps");
    }
    b.build().expect("a trace")
}

/// Bounds in hundredths (`TimeScale::decimals(2)`): multiples of 0.25 or of 0.1.
fn interval(step: usize) -> impl Strategy<Value = Interval> {
    let end = prop_oneof![
        1 => Just(None),
        3 => (0usize..=8).prop_map(Some),
    ];
    (0usize..=6, end).prop_map(move |(a, d)| Interval {
        start: a * step,
        end: d.map_or(Bound::Unbounded, |d| Bound::Inclusive((a + d) * step)),
    })
}

fn formula(step: usize) -> impl Strategy<Value = Formula> {
    let cmp = prop_oneof![Just(CmpOp::Lt), Just(CmpOp::Le), Just(CmpOp::Gt), Just(CmpOp::Ge)];
    let simple = (0usize..2, cmp.clone(), -4i32..=4)
        .prop_map(|(v, op, c)| Formula::cmp(Expr::var(v), op, Expr::constant(f64::from(c))));
    let diff = (cmp, -2i32..=2).prop_map(|(op, c)| {
        Formula::cmp(Expr::sub(Expr::var(0), Expr::var(1)), op, Expr::constant(f64::from(c)))
    });
    let leaf = prop_oneof![
        6 => simple,
        1 => diff,
        1 => Just(Formula::bool(true)),
        1 => Just(Formula::bool(false)),
    ];
    leaf.prop_recursive(4, 24, 3, move |f| {
        let kids = proptest::collection::vec(f.clone(), 0..=3);
        let i = || interval(step);
        prop_oneof![
            f.clone().prop_map(Formula::not),
            kids.clone().prop_map(Formula::and),
            kids.prop_map(Formula::or),
            (f.clone(), f.clone()).prop_map(|(g, h)| Formula::implies(g, h)),
            (i(), f.clone()).prop_map(|(i, g)| Formula::always(i, g)),
            (i(), f.clone()).prop_map(|(i, g)| Formula::eventually(i, g)),
            (i(), f.clone(), f.clone()).prop_map(|(i, g, h)| Formula::until(i, g, h)),
            (i(), f.clone()).prop_map(|(i, g)| Formula::once(i, g)),
            (i(), f.clone()).prop_map(|(i, g)| Formula::historically(i, g)),
            (i(), f.clone(), f).prop_map(|(i, g, h)| Formula::since(i, g, h)),
        ]
    })
}

fn scale() -> TimeScale {
    TimeScale::decimals(2)
}

fn online(df: &DenseFormula, rows: &[(f64, Vec<Option<f64>>)], batch: usize) -> Vec<(f64, f64)> {
    let mut m = DenseMonitor::new(df, 2).expect("a monitor");
    m.set_batch(batch);
    let mut got = Vec::new();
    for (t, cells) in rows {
        got.extend(m.push(*t, cells).expect("a push"));
    }
    got.extend(m.finish().expect("the end"));
    got
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, ..ProptestConfig::default() })]

    #[test]
    fn offline_equals_reference(f in formula(25), rows in rows(0.25, 12)) {
        let trace = build(&rows);
        let df = DenseFormula::new(&f, scale()).expect("a dense formula");
        // `inf - inf`: NaN is an error, tested elsewhere.
        let Ok(got) = df.signal(&trace) else { return Ok(()) };
        let want = reference::signal(&f, scale(), &trace);
        // The whole signals, past the last stamp too.
        prop_assert!(
            same_points(&got.points().collect::<Vec<_>>(), &want.points().collect::<Vec<_>>()),
            "{}\n got  {:?}\n want {:?}", f, got, want
        );
    }

    #[test]
    fn online_equals_offline(f in formula(25), rows in rows(0.25, 16), batch in 1usize..4) {
        let trace = build(&rows);
        let df = DenseFormula::new(&f, scale()).expect("a dense formula");
        let Ok(want) = df.signal(&trace) else { return Ok(()) };
        let want = points(&want, trace.t_last());
        let got = online(&df, &rows, batch);
        prop_assert!(same_points(&got, &want), "{}\n online  {:?}\n offline {:?}", f, got, want);
    }

    /// Decimal stamps and bounds (multiples of 0.1): breakpoints round, and online still
    /// gives offline's change points bit for bit.
    #[test]
    fn online_equals_offline_with_rounding(f in formula(10), rows in rows(0.1, 16), batch in 1usize..4) {
        let trace = build(&rows);
        let df = DenseFormula::new(&f, scale()).expect("a dense formula");
        let Ok(want) = df.signal(&trace) else { return Ok(()) };
        let want = points(&want, trace.t_last());
        let got = online(&df, &rows, batch);
        prop_assert!(same_points(&got, &want), "{}\n online  {:?}\n offline {:?}", f, got, want);
    }

    /// Long traces (up to 400 rows, gaps of 0.01 to 0.08) under windows of up to 1.4, so a
    /// window spans tens of rows and the streaming operators drop and refill their deques.
    #[test]
    fn online_equals_offline_on_long_windows(f in formula(10), rows in rows(0.01, 400)) {
        let trace = build(&rows);
        let df = DenseFormula::new(&f, scale()).expect("a dense formula");
        let Ok(want) = df.signal(&trace) else { return Ok(()) };
        let want = points(&want, trace.t_last());
        let got = online(&df, &rows, 1);
        prop_assert!(same_points(&got, &want), "{}\n online  {:?}\n offline {:?}", f, got, want);
    }

    /// Bounded `until` (streamed by a sweep over pieces) with windows of up to 4.5, about a
    /// hundred rows, over random operands, at the root or under a window operator: online
    /// equals offline, and offline equals the literal reference.
    #[test]
    fn until_with_long_windows(
        f in formula(10),
        g in formula(10),
        a in 0usize..=150,
        len in 0usize..=300,
        outer in 0usize..3,
        rows in rows(0.01, 400),
    ) {
        let u = Formula::until(Interval { start: a, end: Bound::Inclusive(a + len) }, f, g);
        let u = match outer {
            0 => u,
            1 => Formula::always(Interval { start: 0, end: Bound::Inclusive(50) }, u),
            _ => Formula::not(Formula::eventually(Interval { start: 10, end: Bound::Inclusive(70) }, u)),
        };
        let trace = build(&rows);
        let df = DenseFormula::new(&u, scale()).expect("a dense formula");
        let Ok(want) = df.signal(&trace) else { return Ok(()) };
        let want = points(&want, trace.t_last());
        let got = online(&df, &rows, 1);
        prop_assert!(same_points(&got, &want), "{}\n online  {:?}\n offline {:?}", u, got, want);
    }

    /// The same on quarters, where the reference's literal reading is exact (hundredths
    /// round, which the reference does not follow): windows up to 15 over gaps of 0.25 to 2.
    #[test]
    fn until_with_long_windows_equals_reference(
        f in formula(25),
        g in formula(25),
        a in 0usize..=20,
        len in 0usize..=40,
        rows in rows(0.25, 60),
    ) {
        let u = Formula::until(Interval { start: a * 25, end: Bound::Inclusive((a + len) * 25) }, f, g);
        let trace = build(&rows);
        let df = DenseFormula::new(&u, scale()).expect("a dense formula");
        let Ok(got) = df.signal(&trace) else { return Ok(()) };
        let want = reference::signal(&u, scale(), &trace);
        prop_assert!(
            same_points(&got.points().collect::<Vec<_>>(), &want.points().collect::<Vec<_>>()),
            "{}\n got  {:?}\n want {:?}", u, got, want
        );
        let got = points(&got, trace.t_last());
        prop_assert!(same_points(&online(&df, &rows, 1), &got), "{}", u);
    }

    /// Per-variable sample lists merge into the rows a CSV with empty cells gives.
    #[test]
    fn per_variable_samples_merge_like_rows(rows in rows(0.25, 12)) {
        let trace = build(&rows);
        let per_var: Vec<Vec<(f64, f64)>> = (0..2)
            .map(|i| rows.iter().filter_map(|(t, c)| c[i].map(|v| (*t, v))).collect())
            .collect();
        let merged = DenseTrace::from_samples(&per_var).expect("a trace");
        // Rows whose cells are all empty add a stamp and no change: same functions.
        let x = Formula::cmp(Expr::var(0), CmpOp::Gt, Expr::constant(0.0));
        let y = Formula::cmp(Expr::var(1), CmpOp::Lt, Expr::constant(1.0));
        let f = Formula::and(vec![x, Formula::always(Interval { start: 0, end: Bound::Inclusive(1) }, y)]);
        let df = DenseFormula::new(&f, TimeScale::WHOLE).expect("a dense formula");
        let (a, b) = (df.signal(&trace).expect("a"), df.signal(&merged).expect("b"));
        prop_assert!(same_points(&a.points().collect::<Vec<_>>(), &b.points().collect::<Vec<_>>()));
    }
}

/// The monitor over `rows`, saved after `cut` rows and loaded back: the rest of the rows
/// give the same change points, bit for bit, as the monitor that was never saved; saving
/// the loaded monitor gives the same bytes; and every prefix of the bytes is refused.
fn saved_and_continued(df: &DenseFormula, rows: &[(f64, Vec<Option<f64>>)], cut: usize) {
    let mut whole = DenseMonitor::new(df, 2).expect("a monitor");
    let mut want = Vec::new();
    let mut got = Vec::new();
    let cut = cut.min(rows.len());
    for (t, cells) in &rows[..cut] {
        let Ok(p) = whole.push(*t, cells) else { return };
        want.extend(p.iter().copied());
        got.extend(p);
    }
    let bytes = whole.save();
    let mut loaded = DenseMonitor::load(df, 2, &bytes).expect("the saved state loads");
    assert_eq!(loaded.save(), bytes, "{df:?}: saving the loaded monitor changes the bytes");
    for end in (0..bytes.len()).step_by(7) {
        assert!(DenseMonitor::load(df, 2, &bytes[..end]).is_err(), "a prefix of {end} loads");
    }
    for (t, cells) in &rows[cut..] {
        let Ok(p) = whole.push(*t, cells) else { return };
        want.extend(p);
        got.extend(loaded.push(*t, cells).expect("the loaded monitor takes the row"));
    }
    let (Ok(w), Ok(g)) = (whole.finish(), loaded.finish()) else { return };
    want.extend(w);
    got.extend(g);
    assert!(same_points(&got, &want), "{df:?} cut at {cut}\n loaded {got:?}\n whole  {want:?}");
}

/// Every word of a saved state replaced by values a tampered state might hold (0, all
/// ones, NaN, infinities, a huge count, the word plus one): refused for its checksum, and
/// summed again, refused or taken as a monitor that runs the rest of the rows without
/// panicking.
fn tampered_states_never_panic(df: &DenseFormula, rows: &[(f64, Vec<Option<f64>>)], cut: usize) {
    let mut m = DenseMonitor::new(df, 2).expect("a monitor");
    let cut = cut.min(rows.len());
    for (t, cells) in &rows[..cut] {
        if m.push(*t, cells).is_err() {
            return;
        }
    }
    let bytes = m.save();
    for at in (0..bytes.len()).step_by(8) {
        let word = u64::from_le_bytes(bytes[at..at + 8].try_into().expect("a word"));
        let values = [
            0,
            u64::MAX,
            f64::NAN.to_bits(),
            f64::INFINITY.to_bits(),
            f64::NEG_INFINITY.to_bits(),
            1 << 40,
            word.wrapping_add(1),
            word.wrapping_sub(1),
        ];
        for v in values.into_iter().filter(|&v| v != word) {
            let mut tampered = bytes.clone();
            tampered[at..at + 8].copy_from_slice(&v.to_le_bytes());
            assert!(DenseMonitor::load(df, 2, &tampered).is_err(), "a changed word at {at}");
            // Summed again, the structural checks read it.
            hstl_robustness::dense::resum(&mut tampered);
            let Ok(mut loaded) = DenseMonitor::load(df, 2, &tampered) else { continue };
            for (t, cells) in &rows[cut..] {
                let _ = loaded.push(*t, cells);
            }
            let _ = loaded.finish();
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 800, ..ProptestConfig::default() })]

    /// A monitor saved mid-trace and loaded back continues exactly, on every operator.
    #[test]
    fn saved_monitors_continue_exactly(f in formula(10), rows in rows(0.1, 40), cut in 0usize..40) {
        let df = DenseFormula::new(&f, scale()).expect("a dense formula");
        saved_and_continued(&df, &rows, cut);
    }

    /// A saved state with any one word changed never makes the monitor panic.
    #[test]
    fn tampered_saved_monitors_never_panic(f in formula(10), rows in rows(0.1, 20), cut in 0usize..20) {
        let df = DenseFormula::new(&f, scale()).expect("a dense formula");
        tampered_states_never_panic(&df, &rows, cut);
    }

    /// The same with long windows over many rows, where the deques drop and refill.
    #[test]
    fn saved_monitors_continue_exactly_on_long_windows(
        f in formula(10),
        rows in rows(0.01, 300),
        cut in 0usize..300,
    ) {
        let df = DenseFormula::new(&f, scale()).expect("a dense formula");
        saved_and_continued(&df, &rows, cut);
    }
}
