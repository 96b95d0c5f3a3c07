//! The front end refuses what the runtime would: where both hold a limit, it is one number.

#[test]
fn front_end_and_runtime_share_their_limits() {
    assert_eq!(hstl::lang::budget::MAX_WINDOW, hstl::runtime::memory::MAX_WINDOW as u64);
}

/// `plan: model`'s limits are one arithmetic in the front end and the runtime: both refuse
/// the same sizes, on either side of the limits.
#[test]
fn front_end_and_runtime_plan_the_same_sizes() {
    use hstl::lang::budget::{MAX_PLAN_VALUES, MAX_PLAN_WORK, plan_exceeded};
    use hstl::runtime::plan::PlanSize;
    assert_eq!(MAX_PLAN_VALUES, hstl::runtime::plan::MAX_PLAN_VALUES as u64);
    assert_eq!(MAX_PLAN_WORK, hstl::runtime::plan::MAX_PLAN_WORK as u64);
    let mut refused = 0;
    let mut state: u64 = 7;
    let mut draw = |n: u64| {
        state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (state >> 33) % n
    };
    for _ in 0..20_000 {
        let k = 1 + draw(4) as usize;
        let scale = draw(22);
        let states = 1 + draw(1 << scale);
        let cells: Vec<u64> = (0..k).map(|_| draw(states + 1)).collect();
        let horizons: Vec<u64> = (0..k)
            .map(|_| {
                let scale = draw(12);
                1 + draw(1 << scale)
            })
            .collect();
        let (options, buckets, max_steps) = (k as u64, 1 + draw(12), 1 + draw(2000));
        let front = plan_exceeded(states, &cells, &horizons, options, buckets, max_steps);
        let to = |v: &[u64]| v.iter().map(|&x| x as usize).collect::<Vec<_>>();
        let (cells_rt, horizons_rt) = (to(&cells), to(&horizons));
        let size = PlanSize {
            states: states as usize,
            cells: &cells_rt,
            horizons: &horizons_rt,
            options: k,
            buckets: buckets as usize,
            max_steps: max_steps as usize,
        };
        assert_eq!(front.is_some(), size.exceeded().is_some(), "{states} {cells:?} {horizons:?}");
        refused += usize::from(front.is_some());
    }
    assert!(refused > 1000 && refused < 19_000, "{refused} of 20,000 refused");
}

/// `HSTL190`'s count of the suffixes training scores is the scorer's: it warns exactly when
/// the scorer thins a run of `max_steps` steps under `always[0..] once[0..=r] x > 0`, and
/// says about the stride it takes.
#[test]
fn the_thinning_warning_states_the_scorers_stride() {
    use hstl::lang::lints::{SUFFIX_BUDGET, suffix_stride};
    use hstl::runtime::robustness::segment::{self, SegmentScorer};
    use hstl::runtime::robustness::{Bound, CmpOp, Expr, Formula, Interval, Trace};
    assert_eq!(SUFFIX_BUDGET, segment::SUFFIX_BUDGET as u64);
    let ends = [Some(0), Some(100), Some(256), Some(257), Some(300), Some(2000), None];
    for end in ends {
        let window = Interval { start: 0, end: end.map_or(Bound::Unbounded, Bound::Inclusive) };
        let seen =
            Formula::once(window, Formula::cmp(Expr::var(0), CmpOp::Gt, Expr::constant(0.0)));
        let mut scorer = SegmentScorer::new(&Formula::always(Interval::ALL, seen));
        for max_steps in [10usize, 500, 510, 511, 600, 3000, 20_000] {
            let rows = (0..=max_steps).map(|i| (i % 3) as f64 - 1.0).collect();
            let run = Trace::from_columns(vec![rows]).expect("one column");
            let mut rewards = Vec::new();
            scorer.suffix_rewards(&run, &mut rewards);
            let scored = rewards.iter().filter(|r| !r.is_nan()).count();
            let every =
                rewards.iter().skip(1).position(|r| !r.is_nan()).map_or(max_steps + 1, |p| p + 1);
            let said = suffix_stride(end.map(|e| e as u64), max_steps as u64) as usize;
            let label = format!("window end {end:?}, max_steps {max_steps}: {scored} scored");
            assert_eq!(said == 1, every == 1, "{label}, stride {every}, said {said}");
            assert!(
                said <= every && every <= said + 1 + said / 128,
                "{label}: stride {every}, said {said}"
            );
        }
    }
}
