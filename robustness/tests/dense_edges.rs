//! Dense time, case by case: DENSE-TIME.md's worked example, the places where hstl follows
//! the definition and rtamt does not (docs/DENSE-TIME-DEVIATIONS.md), whole-number stamps,
//! the online monitor's memory, and the errors.

mod dense_common;

use dense_common::{read_csv, reference};
use hstl_robustness::dense::{
    DenseError, DenseFormula, DenseMonitor, DenseTrace, DenseTraceBuilder, DenseTraceError,
    TimeScale,
};
use hstl_robustness::{Bound, CmpOp, Expr, Formula, Interval};

const EXAMPLE: &str = "t,x,y\n0,1,5\n1,2,\n1.5,,6\n2,3,\n3.5,0.5,\n4,,-1\n5,4,\n";

fn gt(var: usize, c: f64) -> Formula {
    Formula::cmp(Expr::var(var), CmpOp::Gt, Expr::constant(c))
}

/// `[a..=b]` in tenths.
fn iv(a: usize, b: Option<usize>) -> Interval {
    Interval { start: a, end: b.map_or(Bound::Unbounded, Bound::Inclusive) }
}

fn rows(f: &Formula, csv: &str) -> Vec<(f64, f64)> {
    let (_, trace) = read_csv(csv);
    let df = DenseFormula::new(f, TimeScale::decimals(1)).expect("a dense formula");
    let sig = df.signal(&trace).expect("a signal");
    // The reference agrees on every one of these (their numbers are exact in binary).
    let want = reference::signal(f, TimeScale::decimals(1), &trace);
    assert_eq!(sig, want, "{f}");
    sig.until(trace.t_last()).collect()
}

#[test]
fn the_worked_example_of_dense_time() {
    let (x, y) = (gt(0, 1.0), gt(1, 5.0));
    let inf = f64::INFINITY;
    let cases: Vec<(Formula, Vec<(f64, f64)>)> = vec![
        (
            Formula::eventually(iv(0, Some(10)), x.clone()),
            vec![(0.0, 1.0), (1.0, 2.0), (3.5, -0.5), (4.0, 3.0)],
        ),
        (
            Formula::eventually(iv(10, Some(20)), x.clone()),
            vec![(0.0, 2.0), (2.5, -0.5), (3.0, 3.0)],
        ),
        (
            Formula::always(iv(5, Some(15)), x.clone()),
            vec![(0.0, 0.0), (0.5, 1.0), (1.5, 2.0), (2.0, -0.5), (4.5, 3.0)],
        ),
        (Formula::always(iv(0, None), x.clone()), vec![(0.0, -0.5), (5.0, 3.0)]),
        (Formula::eventually(iv(5, None), x.clone()), vec![(0.0, 3.0)]),
        (
            Formula::until(iv(0, Some(10)), x.clone(), y.clone()),
            vec![(0.0, 0.0), (1.0, 1.0), (3.5, -0.5), (4.0, -6.0)],
        ),
        (
            Formula::once(iv(10, Some(20)), x.clone()),
            vec![(0.0, -inf), (1.0, 0.0), (2.0, 1.0), (3.0, 2.0)],
        ),
        (
            Formula::historically(iv(0, Some(10)), x.clone()),
            vec![(0.0, 0.0), (2.0, 1.0), (3.0, 2.0), (3.5, -0.5)],
        ),
        (
            Formula::since(iv(0, Some(10)), x.clone(), y.clone()),
            vec![(0.0, 0.0), (1.5, 1.0), (3.5, -0.5), (5.0, -6.0)],
        ),
        (
            Formula::since(iv(0, None), x.clone(), y.clone()),
            vec![(0.0, 0.0), (1.5, 1.0), (3.5, -0.5)],
        ),
    ];
    for (f, want) in cases {
        assert_eq!(rows(&f, EXAMPLE), want, "{f}");
    }
}

#[test]
fn decimal_breakpoints_are_one_subtraction_each() {
    // DENSE-TIME.md: pieces 1, -1, 2, -3 from 0, 0.2, 0.7, 1 under eventually[0.1..=0.3].
    let csv = "t,x\n0,1\n0.2,-1\n0.7,2\n1,-3\n";
    let (_, trace) = read_csv(csv);
    let f = Formula::eventually(iv(1, Some(3)), gt(0, 0.0));
    let sig = DenseFormula::new(&f, TimeScale::decimals(1)).unwrap().signal(&trace).unwrap();
    let times: Vec<f64> = sig.times().to_vec();
    assert_eq!(times, vec![0.0, 0.1, 0.7 - 0.3, 0.9]);
    assert_eq!(0.7 - 0.3, 0.39999999999999997);
}

/// rtamt defect 1: `since` drops a leading `-inf`. By the table `(x > 0) since (once[1..=2]
/// y > 0)` is `-inf` on `[0, 1)`, and `always[0..=1]` of it is `-inf` at 0; rtamt says 2.
#[test]
fn a_since_that_starts_at_minus_infinity_keeps_it() {
    let s = Formula::since(iv(0, None), gt(0, 0.0), Formula::once(iv(10, Some(20)), gt(1, 0.0)));
    let r = rows(&s, EXAMPLE);
    assert_eq!(r[0], (0.0, f64::NEG_INFINITY));
    assert_eq!(r[1].0, 1.0);
    let g = Formula::always(iv(0, Some(10)), s);
    assert_eq!(rows(&g, EXAMPLE)[0], (0.0, f64::NEG_INFINITY));
}

/// rtamt defect 2: on a trace that starts after 0, timed past operators fill their empty
/// windows from time 0. By the table (windows clipped at `t0 = 10`)
/// `once[1..=1] (historically[1..=1] x > 0)` is `-inf` at 10; rtamt says `+inf`.
#[test]
fn past_windows_are_clipped_at_the_first_stamp() {
    let f = Formula::once(iv(10, Some(10)), Formula::historically(iv(10, Some(10)), gt(0, 0.0)));
    let r = rows(&f, "t,x\n10,1\n11,2\n13,-1\n");
    assert_eq!(r[0], (10.0, f64::NEG_INFINITY));
    assert_eq!(r[1], (11.0, f64::INFINITY));
}

/// rtamt defect 3: a piece one ulp long can map to an empty interval (`0.5 + 0.75` and
/// `next_up(0.5) + 0.75` are one double). rtamt lists two points at one time and then
/// fails in a binary operator; hstl skips the empty piece (the later value holds).
#[test]
fn a_piece_that_rounds_to_nothing_is_skipped() {
    let s = 0.5f64.next_up();
    assert_eq!(s + 0.75, 0.5 + 0.75);
    let trace = DenseTrace::from_samples(&[vec![(0.5, 1.0), (s, 5.0), (2.0, 2.0)]]).unwrap();
    let once = Formula::once(iv(75, Some(75)), gt(0, 0.0));
    let f = Formula::and(vec![once.clone(), gt(0, 0.0)]);
    let sig = DenseFormula::new(&once, TimeScale::decimals(2)).unwrap().signal(&trace).unwrap();
    assert_eq!(
        sig.points().collect::<Vec<_>>(),
        vec![(0.5, f64::NEG_INFINITY), (1.25, 5.0), (2.75, 2.0)]
    );
    assert!(DenseFormula::new(&f, TimeScale::decimals(2)).unwrap().signal(&trace).is_ok());
}

/// rtamt defect 4: its constants start at time 0, so a trace from -2 loses what comes
/// before 0. The table is defined there.
#[test]
fn negative_stamps_are_times_like_any_other() {
    let r = rows(&Formula::eventually(iv(0, Some(10)), gt(0, 1.0)), "t,x\n-2,0\n-0.5,3\n1,1\n");
    assert_eq!(r, vec![(-2.0, -1.0), (-1.5, 2.0), (1.0, 0.0)]);
}

#[test]
fn nothing_is_clipped_at_the_end_of_the_trace() {
    // eventually[5..=6] x > 0 on a trace ending at 2 reads the held last value.
    let csv = "t,x\n0,-1\n1,3\n2,2\n";
    assert_eq!(rows(&Formula::eventually(iv(50, Some(60)), gt(0, 0.0)), csv), vec![(0.0, 2.0)]);
    assert_eq!(rows(&Formula::always(iv(20, Some(30)), gt(0, 0.0)), csv), vec![(0.0, 2.0)]);
}

#[test]
fn until_asks_its_left_operand_at_the_witness_too() {
    // rtamt issue #210: x steps from 0 to 1 at 0.5; (x < 0.5) until[0..=1] (x >= 0.5) at 0
    // is -0.5 (the discrete reading would give +0.5). The mirror `since` is -0.5 too.
    let csv = "t,x\n0,0\n0.5,1\n";
    let lt = Formula::cmp(Expr::var(0), CmpOp::Lt, Expr::constant(0.5));
    let ge = Formula::cmp(Expr::var(0), CmpOp::Ge, Expr::constant(0.5));
    assert_eq!(rows(&Formula::until(iv(0, Some(10)), lt.clone(), ge.clone()), csv)[0].1, -0.5);
    let csv = "t,x\n0,1\n0.5,0\n";
    let r = rows(&Formula::since(iv(0, None), ge, lt), csv);
    // At 0.5 the witness 0.5 itself needs `x >= 0.5` there: -0.5 (and -0.5 before).
    assert_eq!(r, vec![(0.0, -0.5)]);
}

#[test]
fn whole_number_stamps_are_relative_and_exact() {
    // ROS 2 nanoseconds: far beyond 2^53, one nanosecond apart.
    let base: i64 = 1_700_000_000_123_456_789;
    let trace =
        DenseTrace::from_int_samples(&[vec![(base, 1.0), (base + 1, -1.0), (base + 3, 2.0)]])
            .unwrap();
    assert_eq!(trace.origin(), Some(i128::from(base)));
    assert_eq!(trace.times(), &[0.0, 1.0, 3.0]);
    let f = Formula::eventually(iv(0, Some(1)), gt(0, 0.0));
    let sig = DenseFormula::new(&f, TimeScale::WHOLE).unwrap().signal(&trace).unwrap();
    assert_eq!(sig.points().collect::<Vec<_>>(), vec![(0.0, 1.0), (1.0, -1.0), (2.0, 2.0)]);
    // u64 too, up to 2^64 - 1.
    let top = u64::MAX;
    let t = DenseTrace::from_int_samples(&[vec![(top - 2, 1.0), (top, 2.0)]]).unwrap();
    assert_eq!(t.times(), &[0.0, 2.0]);
    // 2^53 + 1 units after the first stamp: no double holds it.
    let e =
        DenseTrace::from_int_samples(&[vec![(0i64, 1.0), ((1i64 << 53) + 1, 2.0)]]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "row 1: the time stamp 9007199254740993 is 9007199254740993 units after the first stamp 0, \
         more than a double holds exactly (exact up to 2^53 = 9007199254740992 units)"
    );
    // 2^54 is on the doubles' grid: exact, so accepted.
    assert!(DenseTrace::from_int_samples(&[vec![(0i64, 1.0), (1i64 << 54, 2.0)]]).is_ok());
    let mut b = DenseTraceBuilder::new(1);
    b.push_int(base, &[Some(1.0)]).unwrap();
    b.push_int(base + 10, &[None]).unwrap();
    assert_eq!(b.push(3.0, &[Some(1.0)]).unwrap_err(), DenseTraceError::MixedStamps { row: 2 });
    assert_eq!(b.build().unwrap().times(), &[0.0, 10.0]);
}

#[test]
fn bad_traces_are_errors_with_clear_messages() {
    let mut b = DenseTraceBuilder::new(2);
    let e = b.push(0.0, &[Some(1.0), None]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "variable 1 has no sample at the first time stamp, 0 (no value exists before it)"
    );
    b.push(0.0, &[Some(1.0), Some(2.0)]).unwrap();
    let e = b.push(0.0, &[Some(1.0), None]).unwrap_err();
    assert_eq!(
        e.to_string(),
        "row 1: the time stamp 0 does not come after the previous one, 0 (stamps must strictly increase)"
    );
    let e = b.push(f64::NAN, &[None, None]).unwrap_err();
    assert_eq!(e.to_string(), "row 1: the time stamp NaN is not a finite number");
    let e = b.push(1.0, &[Some(f64::NAN), None]).unwrap_err();
    assert_eq!(e.to_string(), "row 1: variable 0 is NaN");
    let e = b.push(1.0, &[None]).unwrap_err();
    assert_eq!(e.to_string(), "a row has 1 cells for 2 variables");
    assert_eq!(
        DenseTraceBuilder::new(1).build().unwrap_err().to_string(),
        "the trace has no sample"
    );
    let e = DenseTrace::from_samples(&[vec![(0.0, 1.0)], vec![(0.5, 1.0)]]).unwrap_err();
    assert_eq!(e, DenseTraceError::MissingFirst { var: 1, t0: "0".into() });
    let e = DenseTrace::from_samples(&[vec![(0.0, 1.0), (2.0, 1.0), (1.0, 3.0)]]).unwrap_err();
    assert!(matches!(e, DenseTraceError::NotIncreasing { row: 2, .. }));
    assert!(!e.to_string().ends_with('.'));
}

#[test]
fn formulas_without_a_dense_meaning_are_errors() {
    let x = gt(0, 0.0);
    let s = TimeScale::decimals(1);
    let e = DenseFormula::new(&Formula::prev(x.clone()), s).unwrap_err();
    assert_eq!(e, DenseError::NoDenseMeaning { op: "prev" });
    let e = DenseFormula::new(&Formula::next(x.clone()), s).unwrap_err();
    assert!(e.to_string().starts_with("`next` has no dense-time meaning"));
    let half = Interval { start: 0, end: Bound::Exclusive(25) };
    let e = DenseFormula::new(&Formula::eventually(half, x.clone()), s).unwrap_err();
    assert_eq!(
        e.to_string(),
        "the half-open interval `[0..2.5]` has no dense-time meaning; write `[a..=b]`"
    );
    let e = DenseFormula::new(&Formula::always(iv(20, Some(10)), x.clone()), s).unwrap_err();
    assert_eq!(e.to_string(), "the interval `[2..=1]` ends before it starts");
    let (_, trace) = read_csv("t,x\n0,1\n");
    let e = DenseFormula::new(&gt(1, 0.0), s).unwrap().signal(&trace).unwrap_err();
    assert_eq!(e.to_string(), "the formula reads variable 1, but the trace has 1 variable");
    let nan = Formula::cmp(Expr::sub(Expr::var(0), Expr::var(0)), CmpOp::Gt, Expr::constant(0.0));
    let (_, trace) = read_csv("t,x\n0,1\n2,inf\n");
    let e = DenseFormula::new(&nan, s).unwrap().signal(&trace).unwrap_err();
    assert_eq!(e.to_string(), "the comparison `v0 - v0 > 0` computes NaN at time 2");
}

#[test]
fn time_scales_read_decimals_as_the_nearest_double() {
    assert_eq!(TimeScale::decimals(1).bound(3), 0.3);
    assert_ne!(3.0 * 0.1, 0.3);
    assert_eq!(TimeScale::decimals(2).bound(250), 2.5);
    assert_eq!(TimeScale::decimals(3).text(2500), "2.5");
    assert_eq!(TimeScale::decimals(2).text(5), "0.05");
    assert_eq!(TimeScale::parse_decimal("2.50"), Some((25, 1)));
    assert_eq!(TimeScale::parse_decimal("10"), Some((10, 0)));
    assert_eq!(TimeScale::parse_decimal("1e-3"), Some((1, 3)));
    assert_eq!(TimeScale::parse_decimal("1.5e2"), Some((150, 0)));
    assert_eq!(TimeScale::parse_decimal("0.0"), Some((0, 0)));
    assert_eq!(TimeScale::parse_decimal("-1"), None);
    assert_eq!(TimeScale::parse_decimal("x"), None);
}

#[test]
fn the_online_monitor_decides_early_and_keeps_only_its_window() {
    // always[0..=10] x > 0 over 0.1-spaced stamps: a window of about 100 rows.
    let f = Formula::always(iv(100, Some(100)), gt(0, 0.0));
    let df = DenseFormula::new(&f, TimeScale::decimals(1)).unwrap();
    let mut m = DenseMonitor::new(&df, 1).unwrap();
    let mut b = DenseTraceBuilder::new(1);
    let mut online = Vec::new();
    let mut most = 0;
    for k in 0..20_000 {
        let t = f64::from(k) * 0.1;
        let v = if k % 37 < 20 { 1.0 } else { -1.0 };
        let r = m.push(t, &[Some(v)]).unwrap();
        if k > 200 && k % 37 == 0 {
            assert!(!online.is_empty(), "verdicts before the end");
        }
        online.extend(r);
        b.push(t, &[Some(v)]).unwrap();
        most = most.max(m.kept());
    }
    assert!(most <= 250, "kept {most} rows");
    online.extend(m.finish().unwrap());
    let trace = b.build().unwrap();
    let want: Vec<(f64, f64)> = df.signal(&trace).unwrap().until(trace.t_last()).collect();
    assert_eq!(online, want);
}

/// Windows thousands of rows long (40 s over stamps 1 to 20 ms apart, as the bench's), for
/// every kind of operator: the online monitor equals offline, and what it keeps stays
/// within a window (not the trace).
#[test]
fn the_online_monitor_streams_long_windows() {
    let x = |c: f64| gt(0, c);
    let y = |c: f64| Formula::cmp(Expr::var(1), CmpOp::Lt, Expr::constant(c));
    let ms = |a: usize, b: Option<usize>| iv(a, b);
    let cases = [
        Formula::always(ms(0, Some(40_000)), Formula::and(vec![x(-3.0), y(3.0)])),
        Formula::eventually(ms(1_000, Some(40_000)), x(2.0)),
        Formula::historically(ms(0, Some(40_000)), Formula::or(vec![x(-2.0), y(0.5)])),
        Formula::once(ms(500, Some(40_000)), x(2.5)),
        Formula::once(ms(500, None), x(2.5)),
        Formula::since(ms(100, Some(40_000)), x(-2.0), y(-1.0)),
        Formula::since(ms(0, None), x(-2.5), y(-1.0)),
        Formula::until(ms(0, Some(2_000)), x(-2.0), y(-1.0)),
        Formula::until(ms(0, Some(40_000)), x(-2.5), y(-2.0)),
        Formula::until(ms(1_500, Some(40_000)), x(-2.8), Formula::or(vec![y(-2.5), x(2.5)])),
        Formula::until(ms(20_000, Some(20_000)), x(-2.9), y(-1.5)),
        Formula::always(
            ms(0, Some(10_000)),
            Formula::until(ms(500, Some(30_000)), Formula::not(y(-2.9)), x(2.0)),
        ),
        Formula::always(
            ms(0, Some(40_000)),
            Formula::implies(x(1.0), Formula::eventually(ms(100, Some(3_000)), y(0.0))),
        ),
        Formula::not(Formula::historically(
            ms(0, Some(10_000)),
            Formula::once(ms(0, Some(20_000)), x(2.9)),
        )),
    ];
    // A deterministic walk with irregular stamps (whole milliseconds, in seconds) and
    // empty cells.
    let mut rows: Vec<(f64, Vec<Option<f64>>)> = Vec::new();
    let (mut ms_total, mut state) = (0u64, 0x9e37_79b9_7f4a_7c15u64);
    let mut next = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let (mut xv, mut yv) = (0.0f64, 0.0f64);
    for k in 0..30_000 {
        xv = (xv + (next() % 5) as f64 * 0.1 - 0.2).clamp(-3.0, 3.0);
        yv = (yv + (next() % 5) as f64 * 0.1 - 0.2).clamp(-3.0, 3.0);
        let cells = if k == 0 {
            vec![Some(xv), Some(yv)]
        } else {
            vec![(next() % 4 != 0).then_some(xv), (next() % 3 != 0).then_some(yv)]
        };
        rows.push((ms_total as f64 / 1000.0, cells));
        ms_total += 1 + next() % 20;
    }
    let mut b = DenseTraceBuilder::new(2);
    for (t, cells) in &rows {
        b.push(*t, cells).unwrap();
    }
    let trace = b.build().unwrap();
    for f in cases {
        let df = DenseFormula::new(&f, TimeScale::decimals(3)).unwrap();
        let want: Vec<(f64, f64)> = df.signal(&trace).unwrap().until(trace.t_last()).collect();
        let mut m = DenseMonitor::new(&df, 2).unwrap();
        let (mut got, mut most) = (Vec::new(), 0);
        for (t, cells) in &rows {
            got.extend(m.push(*t, cells).unwrap());
            most = most.max(m.kept());
        }
        // Bounded formulas decide as they go: only the last horizon's points wait for the
        // end.
        let early = got.len();
        if df.future_reach().is_finite() {
            let late = want.iter().filter(|p| p.0 > trace.t_last() - df.future_reach() - 1.0);
            assert!(early + late.count() >= want.len(), "{f}: {early} of {} early", want.len());
        }
        got.extend(m.finish().unwrap());
        assert_eq!(got.len(), want.len(), "{f}");
        assert!(
            got.iter().zip(&want).all(|(g, w)| g.0 == w.0 && g.1.to_bits() == w.1.to_bits()),
            "{f}"
        );
        // A 40 s window spans about 3,800 rows; the trace has 30,000.
        assert!(most < 12_000, "{f}: kept {most}");
    }
}

/// Complete windows: a time counts only if its windows lie inside the trace; a bounded
/// operator's value there is the ordinary one, an unbounded one ranges over its operand's
/// complete part.
#[test]
fn complete_windows_cut_each_node_at_its_complete_end() {
    let (_, trace) = read_csv(EXAMPLE);
    let x = gt(0, 1.0);
    let complete = |f: &Formula| {
        let df = DenseFormula::new(f, TimeScale::decimals(1)).expect("a dense formula");
        let (sig, end) = df.complete_signal(&trace).expect("a signal");
        (sig.points().collect::<Vec<_>>(), end, df.signal(&trace).expect("a signal"))
    };
    // `always[0.5..=1.5] x > 1`: complete up to 5 - 1.5; there the ordinary values.
    let (got, end, ordinary) = complete(&Formula::always(iv(5, Some(15)), x.clone()));
    assert_eq!(end, 3.5);
    assert_eq!(got, [(0.0, 0.0), (0.5, 1.0), (1.5, 2.0), (2.0, -0.5)]);
    assert_eq!(got, ordinary.until(end).collect::<Vec<_>>());
    // A comparison and a past operator are complete up to the last stamp.
    let (got, end, ordinary) = complete(&Formula::once(iv(10, Some(20)), x.clone()));
    assert_eq!(end, 5.0);
    assert_eq!(got, ordinary.until(5.0).collect::<Vec<_>>());
    // `always (eventually[0..=1] x > 1)`: the ordinary value reads `eventually` past the
    // last stamp (the held 0.5 at 3.5 .. 5 is seen at 3.5 whichever way); complete windows
    // read it up to 4 only, as if the trace ended there.
    let nested = Formula::always(iv(0, None), Formula::eventually(iv(0, Some(10)), x.clone()));
    let (got, end, _) = complete(&nested);
    assert_eq!(end, 4.0);
    assert_eq!(got, [(0.0, -0.5), (4.0, 3.0)]);
    // Over a trace whose last sample dips, the difference shows at t0.
    let (_, dip) = read_csv("t,x\n0,2\n1,2\n2,0.5\n");
    let df = DenseFormula::new(&nested, TimeScale::decimals(1)).expect("a dense formula");
    assert_eq!(df.signal(&dip).expect("a signal").first(), -0.5);
    let (sig, end) = df.complete_signal(&dip).expect("a signal");
    assert_eq!((sig.first(), end), (1.0, 1.0));
    // Windows longer than the trace: nothing is complete.
    let long = Formula::eventually(iv(0, Some(60)), x);
    let (_, end, _) = complete(&long);
    assert!(end < trace.t0());
}

#[test]
fn the_complete_end_without_a_trace_is_the_complete_signals() {
    let (x, y) = (gt(0, 1.0), gt(1, 5.0));
    let formulas = [
        x.clone(),
        Formula::eventually(iv(3, Some(7)), x.clone()),
        Formula::always(iv(0, None), Formula::eventually(iv(1, Some(13)), y.clone())),
        Formula::until(iv(2, Some(9)), x.clone(), Formula::always(iv(0, Some(3)), y.clone())),
        Formula::and(vec![
            Formula::eventually(iv(0, Some(10)), x.clone()),
            Formula::once(iv(10, Some(20)), y),
        ]),
    ];
    let (_, trace) = read_csv(EXAMPLE);
    for f in &formulas {
        let df = DenseFormula::new(f, TimeScale::decimals(1)).expect("a dense formula");
        let (_, end) = df.complete_signal(&trace).expect("a signal");
        assert_eq!(df.complete_end(trace.t_last()).to_bits(), end.to_bits(), "{f}");
    }
}
