//! Traces long enough that the offline evaluator cuts bounded formulas into pieces: the
//! pieces must join without a seam, and the online monitor must agree over many steps.

mod common;

use common::{assert_same, parse, trace_xy};
use hstl_robustness::{Evaluator, OnlineMonitor, Trace, reference};

/// A seeded random walk on a 15 x 15 grid with occasional infinite samples.
fn walk(n: usize, mut seed: u64) -> Trace {
    let mut next = move || {
        seed = seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = seed;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    };
    let (mut x, mut y) = (7.0f64, 7.0f64);
    let (mut xs, mut ys) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for _ in 0..n {
        let r = next();
        match r % 4 {
            0 => y = (y + 1.0).min(14.0),
            1 => y = (y - 1.0).max(0.0),
            2 => x = (x - 1.0).max(0.0),
            _ => x = (x + 1.0).min(14.0),
        }
        let inf = if (r >> 8) % 997 == 0 { f64::INFINITY } else { 0.0 };
        xs.push(x + inf);
        ys.push(y);
    }
    trace_xy(&xs, &ys)
}

#[test]
fn pieces_join_without_a_seam() {
    let t = walk(25_000, 7);
    let formulas = [
        "always[0..=40] (x > 3 && x < 9 && y > 10 && y < 14)",
        "eventually[0..40] (x > 3 && x < 9) && eventually[0..40] (y < 5)",
        "(x > 5) until[0..=20] (y > 10)",
        "(x > 2) until[3..9] eventually[2..=5] (y < 3)",
        "eventually[5..=700] (x < 1) || !always[1..4] (y >= 2)",
        "always[0..=3] ((x > 5) until[0..=3] (y > 10)) -> eventually[0..=50] (x + y > 20)",
        // Past-time operators read back to step 0: their groups run whole, inside pieces.
        "(x > 5) since[0..=20] (y > 10)",
        "(x > 2) since[3..9] once[2..=5] (y < 3)",
        "once[0..40] (x < 1) && eventually[0..=30] (y > 12)",
        "always[0..=10] historically[2..=300] (x > 1 || y > 2)",
        "prev (x > 3) until[0..=5] next (y < 4)",
        "historically[0..=3000] (x < 15) && (x > 1) since[0..=50] (y < 2)",
    ];
    let mut ev = Evaluator::new();
    for src in formulas {
        let f = parse(src);
        let want = reference::signal(&f, &t);
        assert_same(src, ev.signal(&f, &t), &want);
        assert_eq!(ev.robustness(&f, &t), want[0], "{src}: step 0");
        let mut m = OnlineMonitor::new(&f, 2);
        let mut got = Vec::with_capacity(t.len());
        let mut row = Vec::new();
        for i in 0..t.len() {
            t.row_into(i, &mut row);
            got.extend(m.push(&row).expect("two variables").map(|v| v.value));
        }
        got.extend(m.finish().iter().map(|v| v.value));
        assert_same(&format!("online {src}"), &got, &want);
    }
}

/// A window longer than any trace (`eventually[0..10^12]`) or an unbounded operator holds
/// every state back: the monitor stops at its budget with an error that names the window,
/// instead of growing without end (an unlimited one took 2.2 GB at 40M rows).
#[test]
fn the_online_monitor_stops_at_its_memory_budget() {
    for (text, horizon) in
        [("eventually[0..1000000000000] x > 3", Some(999_999_999_999)), ("always[0..] x > 3", None)]
    {
        let f = parse(text);
        let limit = 1000;
        let mut m = OnlineMonitor::new(&f, 2).with_limit(limit);
        let per_state = 2 + f.nodes().len();
        let fits = limit / per_state;
        for _ in 0..fits {
            m.push(&[1.0, 2.0]).expect("within the budget");
        }
        let e = m.push(&[1.0, 2.0]).expect_err("past the budget");
        assert_eq!(
            e,
            hstl_robustness::TraceError::Budget { steps: fits, horizon, limit },
            "{text}"
        );
        assert!(e.to_string().contains("budget of 1000 values"), "{e}");
        // What was kept still finishes.
        assert_eq!(m.finish().len(), fits);
    }
    // A short window never comes near it: its decided states are dropped as it goes.
    let mut m = OnlineMonitor::new(&parse("eventually[0..10] x > 3"), 2).with_limit(1000);
    for _ in 0..100_000 {
        m.push(&[1.0, 2.0]).expect("a short window stays small");
    }
}
