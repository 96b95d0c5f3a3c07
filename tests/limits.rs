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
