//! The greedy choices over a row of values that the learner, the planners and the policies
//! share: the best action, the best available option, the largest value. Ties go to the
//! first (so the sign of a zero is kept); NaN values lose unless all are NaN.

/// The index of the largest value; the lowest index among ties, 0 when all are NaN.
#[inline]
pub(crate) fn argmax(row: &[f64]) -> usize {
    // Unless `row[0]` is NaN the running best is never NaN, and NaN values lose every
    // comparison: plain `>` gives the same index. A NaN `row[0]` stays the running best
    // here, which the slow rule below then handles.
    if let [a, b, c, d] = *row {
        // The grid's four actions, unrolled.
        let (mut best, mut top) = (0, a);
        for (i, v) in [(1, b), (2, c), (3, d)] {
            if v > top {
                (best, top) = (i, v);
            }
        }
        return if top.is_nan() { argmax_nan(row) } else { best };
    }
    let (mut best, mut top) = (0, row[0]);
    for (i, &v) in row.iter().enumerate().skip(1) {
        if v > top {
            (best, top) = (i, v);
        }
    }
    if top.is_nan() { argmax_nan(row) } else { best }
}

/// [`argmax`] when `row[0]` is NaN: a NaN best gives way to the first non-NaN value.
#[cold]
fn argmax_nan(row: &[f64]) -> usize {
    let mut best = 0;
    for (i, &v) in row.iter().enumerate().skip(1) {
        if v > row[best] || row[best].is_nan() && !v.is_nan() {
            best = i;
        }
    }
    best
}

/// The candidate with the largest value in `row`; the first among ties.
pub(crate) fn best_of(candidates: &[usize], row: &[f64]) -> usize {
    let mut best = candidates[0];
    for &c in &candidates[1..] {
        if row[c] > row[best] || row[best].is_nan() && !row[c].is_nan() {
            best = c;
        }
    }
    best
}

/// The largest value of a non-empty row; comparisons skip NaN unless all are NaN.
#[inline]
pub(crate) fn max_of(row: &[f64]) -> f64 {
    // As in `argmax`: unless `row[0]` is NaN, plain maxima give the same value (the first
    // of equal values, so the sign of a zero too), one instruction each.
    let mut m = row[0];
    if let [_, b, c, d] = *row {
        // The grid's four actions, unrolled.
        m = if b > m { b } else { m };
        m = if c > m { c } else { m };
        m = if d > m { d } else { m };
    } else {
        for &v in &row[1..] {
            m = if v > m { v } else { m };
        }
    }
    if m.is_nan() { max_of_nan(row) } else { m }
}

/// [`max_of`] when `row[0]` is NaN.
#[cold]
fn max_of_nan(row: &[f64]) -> f64 {
    let mut m = row[0];
    for &v in &row[1..] {
        if v > m || m.is_nan() {
            m = v;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast paths of `argmax` and `max_of` keep the rules of their slow forms: the
    /// first among ties (so the sign of a zero), NaN skipped unless all are NaN, and a NaN
    /// first value replaced by the first non-NaN one.
    #[test]
    fn argmax_and_max_of_keep_ties_and_nan_rules() {
        let nan = f64::NAN;
        let rows: [&[f64]; 9] = [
            &[1.0, 3.0, 3.0, 2.0],
            &[0.0, -0.0, 0.0, -1.0],
            &[-0.0, 0.0, -0.0],
            &[nan, 2.0, 5.0, nan],
            &[nan, nan, -0.0, 0.0],
            &[nan, nan, nan, nan],
            &[2.0, nan, 7.0, nan],
            &[f64::NEG_INFINITY, nan],
            &[4.0],
        ];
        for row in rows {
            assert_eq!(argmax(row), argmax_nan(row), "{row:?}");
            assert_eq!(max_of(row).to_bits(), max_of_nan(row).to_bits(), "{row:?}");
        }
        assert_eq!(argmax(rows[0]), 1);
        assert_eq!(max_of(rows[1]).to_bits(), 0.0f64.to_bits());
        assert_eq!(max_of(rows[2]).to_bits(), (-0.0f64).to_bits());
        assert_eq!((argmax(rows[3]), max_of(rows[3])), (2, 5.0));
        assert_eq!((argmax(rows[4]), max_of(rows[4]).to_bits()), (2, (-0.0f64).to_bits()));
        assert_eq!(argmax(rows[5]), 0);
        assert!(max_of(rows[5]).is_nan());
        assert_eq!((argmax(rows[6]), max_of(rows[6])), (2, 7.0));
    }
}
