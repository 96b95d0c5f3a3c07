//! Piecewise-constant signals given by their change points.

/// A right-continuous step function of time, given by its change points.
///
/// Point `k` says the signal is `values[k]` from `times[k]` until `times[k + 1]`; the last
/// value holds forever. Times strictly increase; the first is the trace's first stamp, where
/// the signal starts. Consecutive values differ (`0.0` and `-0.0` count as equal).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DenseSignal {
    pub(crate) times: Vec<f64>,
    pub(crate) values: Vec<f64>,
}

impl DenseSignal {
    /// A signal from change points; consecutive equal values are merged.
    ///
    /// Returns `None` unless the times strictly increase and no value is NaN.
    pub fn from_points(points: &[(f64, f64)]) -> Option<DenseSignal> {
        let mut s = DenseSignal::default();
        for &(t, v) in points {
            if v.is_nan() || t.is_nan() || s.times.last().is_some_and(|&p| t <= p) {
                return None;
            }
            s.push(t, v);
        }
        Some(s)
    }

    pub(crate) fn with_capacity(n: usize) -> DenseSignal {
        DenseSignal { times: Vec::with_capacity(n), values: Vec::with_capacity(n) }
    }

    /// Appends a change point unless it repeats the last value. `t` must exceed the last
    /// time.
    #[inline]
    pub(crate) fn push(&mut self, t: f64, v: f64) {
        if self.values.last() != Some(&v) {
            self.times.push(t);
            self.values.push(v);
        }
    }

    /// Keeps the change points at or before `end` (the first one whatever `end`): the
    /// signal then holds its value at `end` after it.
    pub(crate) fn cut(&mut self, end: f64) {
        let n = self.times.partition_point(|&s| s <= end).max(1.min(self.len()));
        self.times.truncate(n);
        self.values.truncate(n);
    }

    /// The change points' times.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The value from each change point on.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// The number of change points (the first included).
    pub fn len(&self) -> usize {
        self.times.len()
    }

    /// Whether the signal has no point (only a default-constructed one).
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }

    /// The change points as `(time, value)` pairs.
    pub fn points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.times.iter().copied().zip(self.values.iter().copied())
    }

    /// The value at the signal's start (the robustness at the first stamp); NaN if empty.
    pub fn first(&self) -> f64 {
        self.values.first().copied().unwrap_or(f64::NAN)
    }

    /// The value at time `t`; NaN before the signal's start.
    pub fn value_at(&self, t: f64) -> f64 {
        let k = self.times.partition_point(|&s| s <= t);
        if k == 0 { f64::NAN } else { self.values[k - 1] }
    }

    /// The change points up to `t_last` (inclusive): what `hstlc monitor --signal` prints
    /// for a trace whose last stamp is `t_last`.
    pub fn until(&self, t_last: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let n = self.times.partition_point(|&s| s <= t_last).max(1.min(self.len()));
        self.points().take(n)
    }
}
