//! The live dense-time monitor (`hstl::monitor::DenseLive`) as plain data: a snapshot taken
//! after any row and restored continues exactly (the same change points, bit for bit, as the
//! monitor never interrupted), over clipped and complete windows, decimal and nanosecond
//! stamps, with a gap bound and relative times; a state that does not fit together is
//! refused in words.

use hstl::monitor::{Dense, DenseLive, DenseLiveState, Front, MaxGap, Stamp, Windows, time_text};

const SPEC: &str = "spec Log {
    state { t: time, x: float, y: float }
    let P = x > 0.5;
    let Q = y < -0.2;
    let W = always[0..=0.3] (eventually[0.2..=0.5] P || Q);
    let U = P until[0.1..=0.4] Q;
    let H = historically[0..=0.25] P || once[0.1..] Q;
    let S = P since[0.05..=0.3] Q;
    let F = eventually (P && Q);
    task always[0..=0.7] eventually[0..=0.6] (P && !Q);
}";

fn dense(formula: Option<&str>) -> Dense {
    let checked = hstl::lang::check(SPEC);
    Dense::new(&checked.specs[0], formula).expect("a dense-time spec")
}

/// Irregular rows with empty cells: `(stamp, cells)`, stamps `origin + k * unit` in whole
/// numbers for nanoseconds or decimals read as doubles.
fn rows(n: usize, nanos: bool) -> Vec<(Stamp, Vec<Option<f64>>)> {
    let mut out = Vec::new();
    let mut k: i128 = 0;
    for j in 0..n {
        let jf = j as f64;
        k += 1 + ((j * 7) % 5) as i128;
        let stamp = if nanos {
            // Near 2^62 nanoseconds, 10 ms steps.
            Stamp::Int((1i128 << 62) + k * 10_000_000)
        } else {
            Stamp::Real(format!("{}", k as f64 * 0.01).parse().expect("a decimal"))
        };
        let x = (j % 3 != 1 || j == 0).then(|| (jf * 0.37).sin());
        let y = (j % 4 != 2 || j == 0).then(|| (jf * 0.11).cos() * 0.6);
        out.push((stamp, vec![x, y]));
    }
    out
}

/// Every change point as the output would write it, and how the trace ended.
fn run(
    d: &Dense,
    live: &mut DenseLive,
    rows: &[(Stamp, Vec<Option<f64>>)],
    out: &mut Vec<String>,
) -> Result<(), String> {
    for (stamp, cells) in rows {
        let points = live.push(d, *stamp, cells).map_err(|p| p.message)?;
        let times = live.times();
        out.extend(
            points.into_iter().map(|(t, v)| format!("{}={:016x}", times.text(t), v.to_bits())),
        );
    }
    Ok(())
}

fn finish(d: &Dense, live: &mut DenseLive, out: &mut Vec<String>) {
    let times = live.times();
    let rest = live.finish(d).expect("the end");
    out.extend(rest.into_iter().map(|(t, v)| format!("{}={:016x}", times.text(t), v.to_bits())));
}

/// For every row `cut`: the monitor snapshotted after `cut` rows and restored gives the
/// rest of the change points exactly as the monitor that went on, and its own snapshot is
/// the one it was restored from.
fn round_trips(formula: Option<&str>, windows: Windows, nanos: bool, relative: bool) {
    let d = dense(formula);
    let rows = rows(120, nanos);
    let gap = if nanos { "500000000" } else { "0.5" };
    let live = || {
        let gap = MaxGap::parse(gap, "max_gap=").expect("a gap");
        d.live(Some(gap), windows, Front::Python).expect("a live monitor").relative(relative)
    };
    let mut whole = live();
    let mut want = Vec::new();
    run(&d, &mut whole, &rows, &mut want).expect("every row");
    finish(&d, &mut whole, &mut want);
    assert!(want.len() > 3, "{formula:?}: {want:?}");
    for cut in (0..=rows.len()).step_by(7) {
        let mut first = live();
        let mut got = Vec::new();
        run(&d, &mut first, &rows[..cut], &mut got).expect("the first rows");
        let state = first.snapshot();
        let mut restored = DenseLive::restore(&d, &state, Front::Python).expect("it restores");
        assert_eq!(restored.snapshot(), state, "{formula:?} at {cut}");
        run(&d, &mut restored, &rows[cut..], &mut got).expect("the other rows");
        finish(&d, &mut restored, &mut got);
        assert_eq!(got, want, "{formula:?}, {windows:?}, cut after {cut} rows");
    }
}

#[test]
fn snapshots_continue_exactly_over_clipped_windows() {
    for f in [None, Some("W"), Some("U"), Some("H"), Some("S"), Some("F"), Some("P")] {
        round_trips(f, Windows::Clipped, false, false);
    }
}

#[test]
fn snapshots_continue_exactly_over_complete_windows() {
    for f in [None, Some("W"), Some("U"), Some("H"), Some("S")] {
        round_trips(f, Windows::Complete, false, true);
    }
}

#[test]
fn snapshots_continue_exactly_on_nanosecond_stamps_near_2_pow_62() {
    for f in [None, Some("U"), Some("H")] {
        round_trips(f, Windows::Clipped, true, false);
        round_trips(f, Windows::Complete, true, true);
    }
    // The times are written exactly in the column's scale.
    let d = dense(Some("P"));
    let mut live = d.live(None, Windows::Clipped, Front::Python).expect("a live monitor");
    let stamp = (1i128 << 62) + 1;
    let points = live.push(&d, Stamp::Int(stamp), &[Some(1.0), Some(0.0)]).expect("a row");
    let state = live.snapshot();
    assert_eq!(state.last, Some(Stamp::Int(stamp)));
    let restored = DenseLive::restore(&d, &state, Front::Python).expect("it restores");
    assert_eq!(time_text(restored.origin(), points[0].0), stamp.to_string());
}

/// A gap bound and the row numbers of errors carry over: the restored monitor refuses the
/// same row with the same words.
#[test]
fn restored_monitors_refuse_what_the_original_refuses() {
    let d = dense(Some("W"));
    let gap = MaxGap::parse("0.1", "max_gap=").expect("a gap");
    let mut live = d.live(Some(gap), Windows::Clipped, Front::Python).expect("a live monitor");
    for (t, x) in [(0.0, 1.0), (0.05, 0.0)] {
        live.push(&d, Stamp::Real(t), &[Some(x), Some(0.0)]).expect("a row");
    }
    let mut restored =
        DenseLive::restore(&d, &live.snapshot(), Front::Python).expect("it restores");
    let cells = [Some(1.0), None];
    for bad in [Stamp::Real(0.5), Stamp::Real(0.05), Stamp::Real(f64::NAN)] {
        let want = live.push(&d, bad, &cells).expect_err("refused");
        let got = restored.push(&d, bad, &cells).expect_err("refused");
        assert_eq!(got, want);
    }
    // The budget too, at the same row, snapshot or not.
    let d = dense(Some("F"));
    let row = |k: usize| (Stamp::Real(k as f64), [Some((k % 2) as f64), Some(-1.0)]);
    let until_refused = |live: &mut DenseLive, from: usize| {
        (from..10_000)
            .find_map(|k| {
                let (t, cells) = row(k);
                live.push(&d, t, &cells).err().map(|p| (k, p))
            })
            .expect("the budget runs out")
    };
    let fresh =
        || d.live(None, Windows::Clipped, Front::Python).expect("a monitor").with_limit(400);
    let (k, p) = until_refused(&mut fresh(), 0);
    assert!(p.message.starts_with("the monitor holds more than 400 values"), "{p}");
    assert_eq!(p.row, Some(k));
    let mut first = fresh();
    for j in 0..k / 2 {
        let (t, cells) = row(j);
        first.push(&d, t, &cells).expect("a row");
    }
    let mut restored = DenseLive::restore(&d, &first.snapshot(), Front::Python).expect("restores");
    assert_eq!(until_refused(&mut restored, k / 2), (k, p));
}

/// What a changed state looks like, and that it is refused in words (no Rust `Some(..)`).
fn refused(d: &Dense, state: &DenseLiveState, says: &str) {
    let p = DenseLive::restore(d, state, Front::Python).expect_err("a damaged state");
    assert!(p.message.starts_with("the saved monitor state is damaged: "), "{}", p.message);
    assert!(p.message.contains(says), "{} does not say {says}", p.message);
    assert!(!p.message.contains("Some(") && !p.message.ends_with('.'), "{}", p.message);
    assert!(p.help.is_some());
}

#[test]
fn damaged_states_are_refused_in_words() {
    let d = dense(Some("P"));
    let gap = MaxGap::parse("0.5", "max_gap=").expect("a gap");
    let mut live = d.live(Some(gap), Windows::Complete, Front::Python).expect("a monitor");
    // A state that holds change points back: over complete windows a comparison's point
    // at the last stamp waits for the next row.
    let mut good = None;
    for (stamp, cells) in rows(60, false) {
        live.push(&d, stamp, &cells).expect("a row");
        let s = live.snapshot();
        if !s.held.is_empty() {
            good = Some(s);
            break;
        }
    }
    let good = good.expect("a state holding points back");
    let with = |f: &dyn Fn(&mut DenseLiveState)| {
        let mut s = good.clone();
        f(&mut s);
        s
    };
    refused(&d, &with(&|s| s.monitor.truncate(s.monitor.len() - 9)), "checksum");
    refused(&d, &with(&|s| s.monitor.clear()), "no saved dense-time monitor");
    refused(&d, &with(&|s| s.monitor[100] ^= 1), "checksum");
    // Changed on purpose and summed again: the structural checks.
    let resummed = |at: usize, word: u64| {
        with(&move |s| {
            s.monitor[at..at + 8].copy_from_slice(&word.to_le_bytes());
            hstl::robustness::dense::resum(&mut s.monitor);
        })
    };
    // Word 7 is the row count, words 5 and 6 the first and last stamps.
    refused(&d, &resummed(7 * 8, u64::MAX), "the row count");
    refused(&d, &resummed(5 * 8, f64::NAN.to_bits()), "not finite stamps in order");
    refused(&d, &resummed(6 * 8, (-1.0f64).to_bits()), "not finite stamps in order");
    refused(&d, &resummed(2 * 8, 12345), "another formula");
    refused(&d, &with(&|s| s.rows += 1), "rows");
    refused(&d, &with(&|s| s.last = Some(Stamp::Real(-3.0))), "stamps");
    refused(&d, &with(&|s| s.last = None), "last stamp is none");
    refused(&d, &with(&|s| s.t0 = f64::NAN), "first stamp is NaN");
    refused(&d, &with(&|s| s.limit = usize::MAX), "budget");
    refused(&d, &with(&|s| s.max_gap = Some("soon".to_string())), "gap bound");
    refused(&d, &with(&|s| s.stopped = Some(3)), "stopped at row 3");
    refused(&d, &with(&|s| s.held.push(s.held[0])), "in order");
    refused(&d, &with(&|s| s.held[0].1 = f64::NAN), "in order");
    refused(&d, &with(&|s| s.windows = Windows::Clipped), "clipped");
    // A state of another formula's monitor.
    let other = dense(Some("U"));
    refused(&other, &good, "another formula");
    // The untouched state restores.
    DenseLive::restore(&d, &good, Front::Python).expect("the good state restores");
}

/// A monitor stopped by a comparison that computed NaN restores stopped: it refuses rows
/// until `finish()`, then monitors a new trace, over complete windows too.
#[test]
fn stopped_monitors_restore_stopped() {
    let src = "spec S { state { t: time, x: float } task eventually[0..=1] sqrt(x) > 1; }";
    let checked = hstl::lang::check(src);
    let d = Dense::new(&checked.specs[0], None).expect("a dense-time spec");
    for windows in [Windows::Clipped, Windows::Complete] {
        let mut live = d.live(None, windows, Front::Python).expect("a monitor");
        for (t, x) in [(0.0, 4.0), (0.5, 0.0), (2.0, 9.0)] {
            live.push(&d, Stamp::Real(t), &[Some(x)]).expect("a row");
        }
        let nan = live.push(&d, Stamp::Real(2.5), &[Some(-1.0)]).expect_err("NaN");
        assert!(nan.message.contains("computes NaN"), "{nan}");
        let mut restored =
            DenseLive::restore(&d, &live.snapshot(), Front::Python).expect("restores");
        let want = live.push(&d, Stamp::Real(3.0), &[Some(4.0)]).expect_err("stopped");
        let got = restored.push(&d, Stamp::Real(3.0), &[Some(4.0)]).expect_err("stopped");
        assert_eq!(got, want);
        assert!(got.message.starts_with("the trace stopped at row 3"), "{got}");
        assert_eq!(restored.finish(&d).expect("the end"), Vec::<(f64, f64)>::new());
        // A new trace, as the original's.
        assert_eq!(live.finish(&d).expect("the end"), Vec::<(f64, f64)>::new());
        for (t, x) in [(0.0, 4.0), (2.0, 0.0)] {
            let want = live.push(&d, Stamp::Real(t), &[Some(x)]).expect("a row");
            assert_eq!(restored.push(&d, Stamp::Real(t), &[Some(x)]).expect("a row"), want);
        }
    }
}
