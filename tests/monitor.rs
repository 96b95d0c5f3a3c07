//! The facade's monitors (`hstl::monitor`) and spec loading (`hstl::load`): what `hstlc
//! monitor` and the Python package share. Values are held against the rtamt cases (the
//! oracle file of hstl-robustness) and against the evaluators they wrap; every refused
//! input against its message.

use hstl::load::{LoadError, load};
use hstl::monitor::{BatchError, Monitor, Samples, TraceError, Windows};
use hstl::robustness::{Trace, offline};
use serde_json::Value;

const ORACLE: &str = include_str!("../robustness/tests/data/rtamt-cases.jsonl");
/// The past-time cases: `once`, `historically`, `since`, `prev`, `next` (no `robustness`
/// field: it is the signal's first value).
const PAST: &str = include_str!("../robustness/tests/data/rtamt-past-cases.jsonl");

struct Case {
    id: u64,
    task: String,
    x: Vec<f64>,
    y: Vec<f64>,
    signal: Vec<f64>,
    robustness: f64,
}

fn number(v: &Value) -> f64 {
    match v.as_str() {
        Some("inf") => f64::INFINITY,
        Some("-inf") => f64::NEG_INFINITY,
        _ => v.as_f64().unwrap_or_else(|| panic!("not a number: {v}")),
    }
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().expect("an array").iter().map(number).collect()
}

fn cases() -> Vec<Case> {
    cases_of(ORACLE)
}

fn cases_of(data: &str) -> Vec<Case> {
    data.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|line| {
            let c: Value = serde_json::from_str(line).expect("one JSON object a line");
            let signal = numbers(&c["signal"]);
            let robustness = match c.get("robustness") {
                Some(r) => number(r),
                None => signal[0],
            };
            Case {
                id: c["id"].as_u64().expect("an id"),
                task: c["task"].as_str().expect("a task").to_string(),
                x: numbers(&c["trace"]["x"]),
                y: numbers(&c["trace"]["y"]),
                signal,
                robustness,
            }
        })
        .collect()
}

fn monitor(src: &str, formula: Option<&str>) -> Monitor {
    let loaded = load(src, None).unwrap_or_else(|e| panic!("{src}: {e}"));
    Monitor::new(&loaded.spec, formula).unwrap_or_else(|e| panic!("{src}: {e}"))
}

fn case_monitor(task: &str) -> Monitor {
    monitor(&format!("spec T {{ state {{ x: float, y: float }} task {task}; }}"), None)
}

/// `x`, `y` as row-major data with a column the spec does not name in between.
fn rows(x: &[f64], y: &[f64]) -> Vec<f64> {
    x.iter().zip(y).flat_map(|(&x, &y)| [y, -7.0, x]).collect()
}

fn rows_of(data: &[f64]) -> Samples<'_> {
    Samples::Rows { data, width: 3, picks: vec![2, 0] }
}

/// Equal, so `0 == -0`; the oracle has no NaN.
fn assert_signal(what: &str, got: &[f64], want: &[f64]) {
    assert_eq!(got, want, "{what}");
}

#[test]
fn oracle_cases_through_columns_rows_batches_and_online() {
    let cases = cases();
    assert_eq!(cases.len(), 100, "the oracle file holds 100 cases");
    check_cases(&cases);
}

#[test]
fn past_time_oracle_cases_through_columns_rows_batches_and_online() {
    let cases = cases_of(PAST);
    assert_eq!(cases.len(), 1500, "the past-time oracle file holds 1,500 cases");
    check_cases(&cases);
}

fn check_cases(cases: &[Case]) {
    for c in cases {
        let m = case_monitor(&c.task);
        let label = format!("case {}: {}", c.id, c.task);
        let columns = Samples::Columns(vec![&c.x, &c.y]);
        let data = rows(&c.x, &c.y);
        assert_signal(&label, &m.signal(&columns).unwrap(), &c.signal);
        assert_signal(&format!("{label} (rows)"), &m.signal(&rows_of(&data)).unwrap(), &c.signal);
        assert_eq!(m.robustness(&columns).unwrap(), c.robustness, "{label}");
        assert_eq!(m.robustness(&rows_of(&data)).unwrap(), c.robustness, "{label} (rows)");

        // What the CLI computes from its CSV reader's trace, bit for bit.
        let trace = Trace::from_columns(vec![c.x.clone(), c.y.clone()]).unwrap();
        let cli = m.signal_of_trace(&trace).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&m.signal(&columns).unwrap()), bits(&cli), "{label}");
        assert_eq!(
            m.robustness_of_trace(&trace).unwrap().to_bits(),
            c.robustness.to_bits(),
            "{label}"
        );

        for threads in [1, 2, 3] {
            let batch = [columns.clone(), rows_of(&data), columns.clone()];
            let (out, steps) = m.signal_batch(&batch, threads).unwrap();
            assert_eq!(steps, c.x.len());
            for row in out.chunks(steps) {
                assert_signal(&format!("{label} (batch, {threads} threads)"), row, &c.signal);
            }
        }

        let mut online = m.online();
        let mut verdicts = Vec::new();
        for (x, y) in c.x.iter().zip(&c.y) {
            verdicts.extend(online.push(&[*x, *y]).unwrap());
        }
        verdicts.extend(online.finish());
        let steps: Vec<usize> = verdicts.iter().map(|v| v.step).collect();
        assert_eq!(steps, (0..c.x.len()).collect::<Vec<_>>(), "{label} (online)");
        let values: Vec<f64> = verdicts.iter().map(|v| v.value).collect();
        assert_signal(&format!("{label} (online)"), &values, &c.signal);
    }
}

#[test]
fn a_batch_of_many_traces_on_several_threads_equals_each_signal() {
    let cases = cases();
    let m =
        case_monitor("always[0..=3] eventually[1..=2] (x >= 4) || (x > 0) until[0..=2] (y > 4)");
    // Every case's trace cut to the shortest length, so they make one batch.
    let steps = cases.iter().map(|c| c.x.len()).min().unwrap();
    let batch: Vec<Samples<'_>> =
        cases.iter().map(|c| Samples::Columns(vec![&c.x[..steps], &c.y[..steps]])).collect();
    for threads in [1, 2, 7, 100, 1000] {
        let (out, got_steps) = m.signal_batch(&batch, threads).unwrap();
        assert_eq!((out.len(), got_steps), (cases.len() * steps, steps));
        for (samples, row) in batch.iter().zip(out.chunks(steps)) {
            assert_signal(&format!("{threads} threads"), row, &m.signal(samples).unwrap());
        }
    }
    assert_eq!(m.signal_batch(&[], 2).unwrap(), (Vec::new(), 0));
}

#[test]
fn robustness_reads_only_the_horizon() {
    let m = case_monitor("always[0..=2] (x > 1)");
    assert_eq!(m.horizon(), Some(2));
    assert_eq!((m.samples_read(10), m.samples_read(2)), (3, 2));
    let x = [5.0, 4.0, 3.0, f64::NAN, 9.0];
    let y = [0.0; 5];
    let columns = Samples::Columns(vec![&x, &y]);
    // The NaN at step 3 is past what step 0 reads: the value is the whole trace's.
    assert_eq!(m.robustness(&columns).unwrap(), 2.0);
    assert_eq!(m.robustness(&rows_of(&rows(&x, &y))).unwrap(), 2.0);
    let nan = TraceError::NotANumber { var: "x".into(), step: 3 };
    assert_eq!(m.signal(&columns).unwrap_err(), nan);
    assert_eq!(m.signal(&rows_of(&rows(&x, &y))).unwrap_err(), nan);
    // An unbounded formula reads the whole trace.
    let unbounded = case_monitor("always[0..] (x > 1)");
    assert_eq!(unbounded.robustness(&columns).unwrap_err(), nan);
}

/// One refused trace: the error's message and help.
fn check(got: Result<impl std::fmt::Debug, TraceError>, message: &str, help: Option<&str>) {
    let e = got.expect_err(message);
    assert_eq!((e.to_string().as_str(), e.help().as_deref()), (message, help));
}

#[test]
fn bad_traces_are_refused_with_their_message() {
    let m = monitor(
        "spec S { state { x: int in 0..=9, y: float } let A = x > 3; task eventually[0..5] A; }",
        None,
    );
    let (x, short) = ([1.0, 2.0, 3.0], [0.0, 0.0]);
    let nan_help = "robustness has no meaning for NaN: drop the step or give it a number \
                    (`inf` and `-inf` are allowed)";
    check(
        m.signal(&Samples::Columns(vec![&x, &short])),
        "state variable `y` has 2 samples, but `x` has 3 samples",
        Some("give every state variable one sample per step"),
    );
    check(
        m.signal(&Samples::Columns(vec![&[], &[]])),
        "the trace has no samples",
        Some("give every state variable at least one sample"),
    );
    check(
        m.robustness(&Samples::Columns(vec![&x, &[0.0, f64::NAN, 1.0]])),
        "`y` is NaN at step 1",
        Some(nan_help),
    );
    check(
        m.signal(&Samples::Columns(vec![&x])),
        "the state has 1 value, the spec has 2 state variables",
        Some("give one value per state variable, in the order `x`, `y`"),
    );
    check(
        m.picks(&["t", "x"]),
        "missing state variable `y`",
        Some("the trace has `t`, `x`; the spec's state variables are `x`, `y`"),
    );
    assert_eq!(m.picks(&["y", "t", "x"]).unwrap(), vec![2, 0]);
    let data = [1.0, 2.0, 3.0, 4.0, 5.0];
    check(
        m.signal(&Samples::Rows { data: &data, width: 2, picks: vec![0, 1] }),
        "5 samples do not make whole rows of 2",
        None,
    );
    check(
        m.signal(&Samples::Rows { data: &data[..4], width: 2, picks: vec![0, 2] }),
        "4 samples do not make whole rows of 2",
        None,
    );
    let nan_rows = [1.0, 0.0, 2.0, f64::NAN];
    check(
        m.signal(&Samples::Rows { data: &nan_rows, width: 2, picks: vec![0, 1] }),
        "`y` is NaN at step 1",
        Some(nan_help),
    );
    // A NaN in a column no state variable reads is not the trace's.
    let ignored = [1.0, 0.0, f64::NAN, 2.0, 0.0, f64::NAN];
    assert!(m.signal(&Samples::Rows { data: &ignored, width: 3, picks: vec![0, 1] }).is_ok());

    let mut online = m.online();
    assert_eq!(online.push(&[1.0, 2.0]).unwrap(), None);
    check(online.push(&[f64::NAN, 2.0]), "`x` is NaN at step 1", Some(nan_help));
    check(
        online.push(&[1.0]),
        "the state has 1 value, the spec has 2 state variables",
        Some("give one value per state variable, in the order `x`, `y`"),
    );
    assert_eq!(online.steps(), 1, "a refused state changes nothing");
}

#[test]
fn a_nan_computed_by_an_expression_is_refused_naming_the_step_and_the_expression() {
    let undefined_help = "robustness has no meaning for NaN: write the expression so that it \
                          is defined on every state the trace can hold (for example \
                          `sqrt(abs(x))`), or fix the trace";
    // The example: a min over the window would skip the NaN and give 1.
    let m = monitor("spec S { state { x: float } task always[0..=2] (sqrt(x) > 1); }", None);
    let x = [4.0, -1.0, 9.0];
    let columns = Samples::Columns(vec![&x]);
    for got in [m.signal(&columns).map(|_| ()), m.robustness(&columns).map(|_| ())] {
        check(got, "`sqrt(x)` is NaN at step 1: the square root of -1", Some(undefined_help));
    }
    check(
        m.signal(&Samples::Rows { data: &x, width: 1, picks: vec![0] }),
        "`sqrt(x)` is NaN at step 1: the square root of -1",
        Some(undefined_help),
    );
    let fine = [4.0, 4.0, 4.0];
    let batch = m.signal_batch(&[Samples::Columns(vec![&fine]), columns.clone()], 2);
    assert_eq!(
        batch.unwrap_err().to_string(),
        "trace 1: `sqrt(x)` is NaN at step 1: the square root of -1"
    );
    let mut online = m.online();
    assert!(online.push(&[4.0]).is_ok());
    check(
        online.push(&[-1.0]),
        "`sqrt(x)` is NaN at step 1: the square root of -1",
        Some(undefined_help),
    );
    assert_eq!(online.steps(), 1, "a refused state changes nothing");
    // Only the steps the value at step 0 reads are checked.
    let m = monitor("spec S { state { x: float } task sqrt(x) > 1; }", None);
    assert_eq!(m.robustness(&columns).unwrap(), 1.0);

    // The innermost operation is named: a division of zeros, the comparison of infinities.
    let m = monitor("spec S { state { x: float, y: float } task x / y + 1 > 0 || y < x; }", None);
    let (zeros, infs) = ([1.0, 0.0], [1.0, f64::INFINITY]);
    check(
        m.signal(&Samples::Columns(vec![&zeros, &zeros])),
        "`x / y` is NaN at step 1: 0 / 0",
        Some(undefined_help),
    );
    check(
        m.signal(&Samples::Columns(vec![&infs, &infs])),
        "`x / y` is NaN at step 1: inf / inf",
        Some(undefined_help),
    );
    let m = monitor("spec S { state { x: float, y: float } task y < x; }", None);
    check(
        m.signal(&Samples::Columns(vec![&infs, &infs])),
        "`y < x` is NaN at step 1: the comparison of inf with inf",
        Some(undefined_help),
    );
}

#[test]
fn bad_batches_name_the_first_bad_trace() {
    let m = case_monitor("eventually[0..=1] (x > 1)");
    let (a, b, nan) = ([1.0, 2.0, 3.0], [1.0, 2.0], [1.0, f64::NAN, 3.0]);
    let good = Samples::Columns(vec![&a, &a]);
    let e = m.signal_batch(&[good.clone(), Samples::Columns(vec![&b, &b])], 2).unwrap_err();
    assert_eq!(e, BatchError::Steps { trace: 1, steps: 2, first_steps: 3 });
    assert_eq!(e.to_string(), "trace 1 has 2 steps, but trace 0 has 3");
    let mut batch = vec![good.clone(); 9];
    batch[7] = Samples::Columns(vec![&a, &nan]);
    batch[4] = Samples::Columns(vec![&nan, &a]);
    for threads in [1, 2, 3, 9] {
        let e = m.signal_batch(&batch, threads).unwrap_err();
        assert_eq!(e.to_string(), "trace 4: `x` is NaN at step 1", "{threads} threads");
    }
}

#[test]
fn a_let_is_scored_alone_and_unknown_names_are_refused() {
    let src = "spec S { state { x: int in 0..=9 } let A = x > 3; let B = x < 2; \
               task eventually[0..5] A; }";
    let x = [1.0, 5.0];
    let a = monitor(src, Some("A"));
    assert_eq!(a.signal(&Samples::Columns(vec![&x])).unwrap(), vec![-2.0, 2.0]);
    assert_eq!(a.horizon(), Some(0));
    let spec = load(src, None).unwrap().spec;
    let e = Monitor::new(&spec, Some("Z")).unwrap_err();
    assert_eq!(e.to_string(), "spec `S` has no `let` named `Z`; its lets are `A`, `B`");
}

#[test]
fn loading_picks_one_spec_or_says_why_not() {
    let two = "spec First { state { x: int in 0..=9 } let Hi = x > 5; task eventually[0..3] Hi; }\n\
               spec Second { state { x: int in 0..=9 } let Lo = x < 2; task always[0..3] Lo; }";
    assert_eq!(load(two, Some("Second")).unwrap().spec.name, "Second");
    let cases: [(&str, Option<&str>, &str, Option<&str>); 4] = [
        (
            two,
            None,
            "the file holds 2 specs",
            Some("pick one with `--spec NAME`: `First`, `Second`"),
        ),
        (two, Some("Third"), "no spec named `Third`", Some("the file holds `First`, `Second`")),
        ("// nothing\n", None, "the file holds no spec", Some("write `spec Name { ... }` in it")),
        ("spec S { state { x: int in 0..=9 } }", None, "the file has 1 error", None),
    ];
    for (src, wanted, message, help) in cases {
        let e = load(src, wanted).unwrap_err();
        assert_eq!((e.to_string().as_str(), e.help("`--spec NAME`").as_deref()), (message, help));
    }
    let LoadError::Invalid(diagnostics) =
        load("spec S { state { x: int in 0..=9 } }", None).unwrap_err()
    else {
        panic!("a spec without a task does not load")
    };
    assert_eq!(diagnostics[0].code, "HSTL015");
    // Warnings do not stop a spec; they come with it.
    let warned = load(
        "spec S { state { x: int in 0..=9 } let U = x > 1; let A = x > 3; \
                       task eventually[0..5] A; }",
        None,
    )
    .unwrap();
    assert!(!warned.diagnostics.is_empty() && warned.diagnostics.iter().all(|d| !d.is_error()));
}

#[test]
fn io_errors_read_as_the_cli_prints_them() {
    let e = std::io::Error::from(std::io::ErrorKind::NotFound);
    let os = std::fs::read_to_string("/nonexistent/spec.hstl").unwrap_err();
    assert_eq!(
        hstl::load::read_error(std::path::Path::new("/nonexistent/spec.hstl"), &os),
        "cannot read `/nonexistent/spec.hstl`: no such file or directory"
    );
    assert_eq!(hstl::load::io_reason(&e), "entity not found");
    // The offline evaluator on a Trace and on borrowed slices agree bit for bit.
    let x = [1.0, 2.0, 3.0];
    let f = hstl::lower::task(
        &load("spec S { state { x: float } task eventually[0..=1] (x > 2); }", None).unwrap().spec,
    )
    .unwrap();
    let trace = Trace::from_columns(vec![x.to_vec()]).unwrap();
    assert_eq!(offline::signal_of_slices(&f, &[&x]).unwrap(), offline::signal(&f, &trace));
}

#[test]
fn complete_windows_agree_offline_and_online_and_leave_the_end_undetermined() {
    let m = monitor(
        "spec S { state { x: float, y: float } \
         task always[0..] (eventually[0..=4] x > 0 && eventually[0..=4] y > 0); }",
        None,
    );
    let x: Vec<f64> = (0..12).map(|t| if t % 3 == 0 { 1.0 } else { -1.0 }).collect();
    let y: Vec<f64> = (0..12).map(|t| if t % 3 == 1 { 1.0 } else { -1.0 }).collect();
    let samples = Samples::Columns(vec![&x, &y]);
    // Clipped, the last windows fail; complete, steps 8 to 11 are undetermined.
    assert_eq!(m.robustness(&samples).unwrap(), -1.0);
    let complete = m.complete_signal(&samples).unwrap();
    assert_eq!(complete, vec![1.0; 8]);
    let mut online = m.online();
    for t in 0..12 {
        assert_eq!(online.push(&[x[t], y[t]]).unwrap(), None, "unbounded: no verdict yet");
    }
    let verdicts: Vec<f64> = online.finish_complete().iter().map(|v| v.value).collect();
    assert_eq!(verdicts, complete);
    assert_eq!(online.steps(), 0, "finishing starts a new trace");
    // A NaN is refused over complete windows too.
    let m = monitor("spec S { state { x: float } task always[0..=1] (sqrt(x) > 1); }", None);
    let bad = [4.0, -1.0, 9.0];
    assert!(m.complete_signal(&Samples::Columns(vec![&bad])).is_err());
}

/// An online monitor restored from its snapshot after every prefix continues exactly as
/// the original: the same verdicts, numbered from the trace's start.
fn check_snapshots(cases: &[Case]) {
    for c in cases {
        let m = case_monitor(&c.task);
        let label = format!("case {}: {}", c.id, c.task);
        let mut whole = m.online();
        let mut want = Vec::new();
        for (x, y) in c.x.iter().zip(&c.y) {
            want.extend(whole.push(&[*x, *y]).unwrap());
        }
        want.extend(whole.finish());
        for cut in 0..=c.x.len() {
            let mut first = m.online();
            let mut got = Vec::new();
            for t in 0..cut {
                got.extend(first.push(&[c.x[t], c.y[t]]).unwrap());
            }
            let snapshot = first.snapshot();
            let mut back = m.online();
            back.restore(&snapshot).unwrap();
            assert_eq!(back.steps(), cut, "{label}, cut {cut}");
            assert_eq!(back.snapshot(), snapshot, "{label}, cut {cut}");
            for t in cut..c.x.len() {
                got.extend(back.push(&[c.x[t], c.y[t]]).unwrap());
            }
            got.extend(back.finish());
            assert_eq!(got, want, "{label}, cut {cut}");
            assert_eq!(back.steps(), 0, "a new trace after finish");
        }
    }
}

#[test]
fn online_monitors_restored_from_snapshots_continue_exactly() {
    check_snapshots(&cases());
    let past = cases_of(PAST);
    check_snapshots(&past[..200]);
}

#[test]
fn a_bounded_monitors_snapshot_holds_at_most_its_horizon() {
    let m = case_monitor("always[0..=3] (x > 1)");
    let mut online = m.online();
    for t in 0..100 {
        online.push(&[f64::from(t), 0.0]).unwrap();
    }
    let snapshot = online.snapshot();
    assert_eq!((snapshot.skipped, snapshot.states.len()), (97, 3 * 2));
    let mut back = m.online();
    let e = back.restore(&hstl::monitor::OnlineState { skipped: 0, states: vec![1.0, f64::NAN] });
    assert_eq!(e.unwrap_err().to_string(), "`y` is NaN at step 0");
    assert_eq!(back.steps(), 0);
}

#[test]
fn windows_complete_pads_the_undetermined_steps_with_nan_alone_and_in_batches() {
    let m = monitor(
        "spec S { state { x: float, y: float } \
         task always[0..] (eventually[0..=4] x > 0 && eventually[0..=4] y > 0); }",
        None,
    );
    let x: Vec<f64> = (0..12).map(|t| if t % 3 == 0 { 1.0 } else { -1.0 }).collect();
    let y: Vec<f64> = (0..12).map(|t| if t % 3 == 1 { 1.0 } else { -1.0 }).collect();
    let samples = Samples::Columns(vec![&x, &y]);
    let signal = m.signal_in(&samples, Windows::Complete).unwrap();
    assert_eq!(signal.len(), 12);
    assert_eq!(signal[..8], [1.0; 8]);
    assert!(signal[8..].iter().all(|v| v.is_nan()));
    assert_eq!(m.robustness_in(&samples, Windows::Complete).unwrap(), 1.0);
    assert_eq!(m.robustness_in(&samples, Windows::Clipped).unwrap(), -1.0);
    assert_eq!(m.signal_in(&samples, Windows::Clipped).unwrap(), m.signal(&samples).unwrap());
    let short = Samples::Columns(vec![&x[..3], &y[..3]]);
    assert!(m.robustness_in(&short, Windows::Complete).unwrap().is_nan(), "undetermined");
    let batch = [Samples::Columns(vec![&x, &y]), Samples::Columns(vec![&y, &x])];
    let (out, steps) = m.signal_batch_in(&batch, 2, Windows::Complete).unwrap();
    assert_eq!(steps, 12);
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&out[..12]), bits(&signal));
    let alone = m.signal_in(&batch[1], Windows::Complete).unwrap();
    assert_eq!(bits(&out[12..]), bits(&alone));
    assert_eq!(Windows::parse("complete"), Ok(Windows::Complete));
    let e = Windows::parse("full").unwrap_err();
    assert_eq!(e.to_string(), "unknown windows `full`");
    assert!(e.help().contains("\"clipped\""));
}

#[test]
fn a_past_time_monitors_snapshot_holds_only_what_its_past_windows_read() {
    let tasks = [
        "once[0..=4] (x > 6) && historically[1..=3] (y >= 0)",
        "always[0..=3] once[2..=5] (x > 6)",
        "(x > 2) since[0..=6] (y > 7) || prev (x < 3)",
        "eventually[0..=2] historically[0..=3] (x > 1)",
        "once[0..] (x > 13)",
    ];
    let mut draws = 17u64;
    let mut next = || {
        draws = draws.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        ((draws >> 33) % 15) as f64
    };
    let x: Vec<f64> = (0..400).map(|_| next()).collect();
    let y: Vec<f64> = (0..400).map(|_| next()).collect();
    for task in tasks {
        let m = case_monitor(task);
        let mut whole = m.online();
        let mut want = Vec::new();
        for t in 0..x.len() {
            want.extend(whole.push(&[x[t], y[t]]).unwrap());
        }
        want.extend(whole.finish());
        for cut in [0, 1, 5, 63, 64, 65, 200, 399, 400] {
            let mut first = m.online();
            let mut got = Vec::new();
            for t in 0..cut {
                got.extend(first.push(&[x[t], y[t]]).unwrap());
            }
            let snapshot = first.snapshot();
            if !task.contains("[0..]") {
                assert!(snapshot.states.len() <= 2 * 64 * 2, "{task}: {}", snapshot.states.len());
            }
            // A copy of a copy, so the restored monitor's own snapshot is checked too.
            let mut back = m.online();
            back.restore(&snapshot).unwrap();
            let mut again = m.online();
            again.restore(&back.snapshot()).unwrap();
            assert_eq!(again.steps(), cut, "{task}, cut {cut}");
            for t in cut..x.len() {
                got.extend(again.push(&[x[t], y[t]]).unwrap());
            }
            got.extend(again.finish());
            assert_eq!(got, want, "{task}, cut {cut}");
        }
    }
}
