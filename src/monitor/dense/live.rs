//! A dense-time monitor fed rows as they arrive ([`DenseLive`]), and its state as plain data
//! ([`DenseLiveState`]) to save and restore.

use super::*;

impl Dense {
    /// An online monitor that takes stamps as given (whole numbers or doubles, read by
    /// [`StampRules`]), refuses a gap larger than `gap`, gives its change points over
    /// `windows` (over complete windows, each once it also lies before the complete end of
    /// the rows so far), holds at most [`MAX_ONLINE_VALUES`] values, and words its errors
    /// for `front`. Complete windows need bounded future operators: an unbounded one
    /// decides nothing before the trace ends.
    pub fn live(
        &self,
        gap: Option<MaxGap>,
        windows: Windows,
        front: Front,
    ) -> Result<DenseLive, DenseProblem> {
        if windows == Windows::Complete && !self.formula.future_reach().is_finite() {
            // Over complete windows an unbounded operator reads up to its operand's own
            // complete end, which only the whole trace gives.
            return Err(DenseProblem {
                message: format!(
                    "{} needs bounded future operators, and {} has an unbounded one (such as \
                     `always`): no value is final before the input ends",
                    front.online_complete(),
                    self.what
                ),
                help: Some(format!(
                    "{}: the trace is scored whole, over complete windows, with the same result",
                    front.whole_complete()
                )),
                row: None,
                var: None,
                time: None,
            });
        }
        Ok(DenseLive {
            monitor: self.online()?,
            rules: StampRules::new(gap, front),
            windows,
            relative: false,
            limit: MAX_ONLINE_VALUES,
            rows: 0,
            t0: 0.0,
            held: Vec::new(),
            stopped: None,
        })
    }
}

/// A dense-time monitor fed rows as they arrive ([`Dense::live`]): stamps read by
/// [`StampRules`], gaps checked, change points given over clipped or complete windows,
/// memory bounded by [`MAX_ONLINE_VALUES`]. What `hstlc monitor --online` and Python's
/// `OnlineMonitor` run for a dense-time spec.
#[derive(Clone, Debug)]
pub struct DenseLive {
    monitor: DenseMonitor,
    rules: StampRules,
    windows: Windows,
    /// Times relative to the first stamp.
    relative: bool,
    /// The most values held.
    limit: usize,
    rows: usize,
    /// The first stamp, when stamps are doubles.
    t0: f64,
    /// Over complete windows: decided change points not yet known to lie before the
    /// complete end.
    held: Vec<(f64, f64)>,
    /// The row where a comparison computed NaN: the trace cannot go on.
    stopped: Option<usize>,
}

impl DenseLive {
    /// The same monitor with its times relative to the first stamp (`relative`) or in the
    /// time column's scale.
    pub fn relative(mut self, relative: bool) -> DenseLive {
        self.relative = relative;
        self
    }

    /// The same monitor holding at most `limit` values (at most [`MAX_ONLINE_VALUES`]).
    pub fn with_limit(mut self, limit: usize) -> DenseLive {
        self.limit = limit.min(MAX_ONLINE_VALUES);
        self
    }

    /// The most values the monitor holds.
    pub fn limit(&self) -> usize {
        self.limit
    }

    /// Appends a row (`None`: no new sample of that variable) and returns the change points
    /// it decided, `(t, value)`, times relative to [`DenseLive::origin`] when set. A row
    /// refused for its stamp or its cells changes nothing; a row on which a comparison
    /// computes NaN stops the trace (until [`DenseLive::finish`]). Errors name the row
    /// counted from 0 ([`DenseLive::push_at`] for rows found elsewhere).
    pub fn push(
        &mut self,
        dense: &Dense,
        stamp: Stamp,
        cells: &[Option<f64>],
    ) -> Result<Vec<(f64, f64)>, DenseProblem> {
        self.push_at(dense, stamp, cells, Place::Row(self.rows))
    }

    /// [`DenseLive::push`] of a row the reader found at `at` (a file's line, say), which a
    /// later row's gap error names.
    pub fn push_at(
        &mut self,
        dense: &Dense,
        stamp: Stamp,
        cells: &[Option<f64>],
        at: Place,
    ) -> Result<Vec<(f64, f64)>, DenseProblem> {
        let row = self.rows;
        if let Some(stop) = self.stopped {
            return Err(DenseProblem {
                message: format!(
                    "the trace stopped at row {stop}, where a comparison computed NaN"
                ),
                help: Some("call `finish()` to start a new trace".to_string()),
                row: Some(row),
                var: None,
                time: None,
            });
        }
        let stamp = self.rules.check(dense, stamp, row)?;
        let width = dense.vars.len() + 1;
        if self.monitor.kept().saturating_add(1).saturating_mul(width) > self.limit {
            let why = if dense.formula.future_reach().is_finite() {
                "its windows read"
            } else {
                "until the trace ends (it has an unbounded future operator, such as `always`)"
            };
            let front = self.rules.front();
            return Err(DenseProblem {
                message: format!(
                    "the monitor holds more than {} values, and {} keeps every row {why}",
                    self.limit, dense.what
                ),
                help: Some(format!(
                    "monitor a formula with bounded windows ({} with a `let`), or {}",
                    front.formula(),
                    front.end_sooner()
                )),
                row: Some(row),
                var: None,
                time: None,
            });
        }
        // The core checks the cells before it takes the row: a refused row changes nothing.
        let decided = match stamp {
            Stamp::Int(s) => self.monitor.push_int(s, cells),
            Stamp::Real(t) => self.monitor.push(t, cells),
        }
        .map_err(|e| {
            if matches!(e, DenseError::Nan { .. }) {
                self.stopped = Some(row);
            }
            let mut p = dense.problem(e);
            p.row = p.row.map(|_| row);
            p
        })?;
        if row == 0
            && let Stamp::Real(t) = stamp
        {
            self.t0 = t;
        }
        self.rules.take(stamp, at);
        self.rows += 1;
        if self.windows == Windows::Clipped {
            return Ok(decided);
        }
        self.held.extend(decided);
        let end = self.complete_end(dense).unwrap_or(f64::NEG_INFINITY);
        let before = self.held.partition_point(|&(t, _)| t < end);
        Ok(self.held.drain(..before).collect())
    }

    /// Over complete windows, the time up to which the rows so far determine the signal
    /// (`None` over clipped windows, or before the first row).
    pub fn complete_end(&self, dense: &Dense) -> Option<f64> {
        let (_, last) = self.monitor.span()?;
        (self.windows == Windows::Complete).then(|| dense.formula.complete_end(last))
    }

    /// Ends the trace: the change points not returned yet, up to the last stamp; over
    /// complete windows, those before the complete end and then, if the complete end comes
    /// before the last stamp, a point at it (or at the first stamp, if it comes before)
    /// with the value NaN: the times from it on are undetermined. The monitor then starts
    /// a new trace.
    pub fn finish(&mut self, dense: &Dense) -> Result<Vec<(f64, f64)>, DenseProblem> {
        let span = self.monitor.span();
        let end = self.complete_end(dense);
        let rest = self.monitor.finish().map_err(|e| dense.problem(e));
        let mut held = std::mem::take(&mut self.held);
        self.rules.restart();
        self.rows = 0;
        self.t0 = 0.0;
        if self.stopped.take().is_some() {
            // The operators stopped halfway through a row: start afresh.
            self.monitor = dense.online()?;
            return Ok(Vec::new());
        }
        let rest = rest?;
        let (Some(end), Some((t0, last))) = (end, span) else { return Ok(rest) };
        held.extend(rest);
        if end < last {
            held.truncate(held.partition_point(|&(t, _)| t < end));
            held.push((end.max(t0), f64::NAN));
        }
        Ok(held)
    }

    /// The rows given since creation or the last [`DenseLive::finish`].
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// The first whole-number stamp, when stamps are whole numbers beyond 2^53.
    pub fn origin(&self) -> Option<i128> {
        self.monitor.origin()
    }

    /// How this trace's times are written: relative to the first stamp (`relative`) or in
    /// the column's scale.
    pub fn axis(&self, relative: bool) -> TimeAxis {
        TimeAxis { relative, origin: self.origin(), t0: self.t0 }
    }

    /// How this trace's times are written, as the monitor was set ([`DenseLive::relative`]).
    pub fn times(&self) -> TimeAxis {
        self.axis(self.relative)
    }

    /// Whether times are relative to the first stamp.
    pub fn is_relative(&self) -> bool {
        self.relative
    }

    /// The windows the change points are given over.
    pub fn windows(&self) -> Windows {
        self.windows
    }

    /// The gap bound, if any.
    pub fn max_gap(&self) -> Option<&MaxGap> {
        self.rules.gap()
    }
}

/// A [`DenseLive`] monitor's state as plain data ([`DenseLive::snapshot`]): its settings,
/// the stamp of its last row, the change points it holds back, and its operators' state
/// ([`DenseMonitor::save`]'s bytes). [`DenseLive::restore`] checks every field.
#[derive(Clone, Debug, PartialEq)]
pub struct DenseLiveState {
    /// The windows change points are given over.
    pub windows: Windows,
    /// Whether times are relative to the first stamp.
    pub relative: bool,
    /// The gap bound as written, if any.
    pub max_gap: Option<String>,
    /// The most values the monitor holds.
    pub limit: usize,
    /// The rows given since the trace began.
    pub rows: usize,
    /// The last row's stamp as the trace took it (a whole number for stamps beyond 2^53).
    pub last: Option<Stamp>,
    /// The first stamp, when stamps are doubles (0 otherwise).
    pub t0: f64,
    /// Over complete windows: decided change points not yet known to lie before the
    /// complete end.
    pub held: Vec<(f64, f64)>,
    /// The row where a comparison computed NaN, if one did.
    pub stopped: Option<usize>,
    /// The operators' state: [`DenseMonitor::save`]'s bytes.
    pub monitor: Vec<u8>,
}

impl DenseLive {
    /// The monitor's state as plain data, from which [`DenseLive::restore`] continues
    /// exactly (the same change points, bit for bit, and the same errors).
    pub fn snapshot(&self) -> DenseLiveState {
        DenseLiveState {
            windows: self.windows,
            relative: self.relative,
            max_gap: self.rules.gap().map(|g| g.text().to_string()),
            limit: self.limit,
            rows: self.rows,
            last: self.rules.last(),
            t0: self.t0,
            held: self.held.clone(),
            stopped: self.stopped,
            monitor: self.monitor.save(),
        }
    }

    /// The monitor `state` describes, for `dense` (the monitor's formula), worded for
    /// `front`. Every field is checked against the others and the operators' state: a
    /// state that no monitor of this formula could have reached is refused, saying what
    /// does not fit.
    pub fn restore(
        dense: &Dense,
        state: &DenseLiveState,
        front: Front,
    ) -> Result<DenseLive, DenseProblem> {
        let bad = |what: String| DenseProblem {
            message: format!("the saved monitor state is damaged: {what}"),
            help: Some(
                "save the monitor again from a running one (pickle it); a state changed by \
                 hand, cut short or saved by another formula is refused"
                    .to_string(),
            ),
            row: None,
            var: None,
            time: None,
        };
        let gap = match &state.max_gap {
            Some(text) => Some(
                MaxGap::parse(text, front.max_gap())
                    .map_err(|p| bad(format!("its gap bound: {}", p.message)))?,
            ),
            None => None,
        };
        if !(1..=MAX_ONLINE_VALUES).contains(&state.limit) {
            return Err(bad(format!(
                "its budget is {} values, and a monitor holds 1 to {MAX_ONLINE_VALUES}",
                state.limit
            )));
        }
        if state.windows == Windows::Complete && !dense.formula.future_reach().is_finite() {
            return Err(bad(format!(
                "it is over complete windows, and {} has an unbounded future operator",
                dense.what
            )));
        }
        let monitor = DenseMonitor::load(&dense.formula, dense.vars.len(), &state.monitor)
            .map_err(|e| bad(format!("its operators: {e}")))?;
        let rows = state.rows;
        if state.stopped.is_some_and(|s| s != rows) {
            return Err(bad(format!(
                "it stopped at row {}, and it has {rows} rows",
                state.stopped.unwrap_or(0)
            )));
        }
        if (rows == 0) != state.last.is_none() {
            let last = state.last.map_or_else(|| "none".to_string(), |s| s.to_string());
            return Err(bad(format!("it has {rows} rows, and its last stamp is {last}")));
        }
        if !(state.t0.is_finite() && (rows > 0 || state.t0 == 0.0)) {
            return Err(bad(format!("its first stamp is {}", state.t0)));
        }
        if state.stopped.is_none() {
            if monitor.rows() != rows {
                return Err(bad(format!(
                    "it has {rows} rows, and its operators have taken {}",
                    monitor.rows()
                )));
            }
            // The last stamp as the operators hold it: relative to the first whole-number
            // stamp, or the double itself.
            let fits = match (state.last, monitor.span(), monitor.origin()) {
                (None, None, _) => true,
                (Some(Stamp::Int(s)), Some((t0, x)), Some(o)) => {
                    let rel = s.checked_sub(o).filter(|&d| d >= 0);
                    state.t0 == 0.0
                        && t0 == 0.0
                        && rel.is_some_and(|d| d as f64 == x && (d as f64) as i128 == d)
                }
                (Some(Stamp::Real(t)), Some((t0, x)), None) => t == x && state.t0 == t0,
                _ => false,
            };
            if !fits {
                return Err(bad(
                    "its stamps (the first and the last row's) do not agree with its operators'"
                        .to_string(),
                ));
            }
        }
        // Held points: decided, so at or before the last stamp, after the complete end (of
        // the rows before a row that stopped the trace, whose operators stopped halfway).
        let span = monitor.span();
        let end = span.map(|(_, x)| dense.formula.complete_end(x));
        let mut prev = f64::NEG_INFINITY;
        for &(t, v) in &state.held {
            let inside = state.stopped.is_some()
                || span.is_some_and(|(_, x)| t <= x) && end.is_some_and(|e| t >= e);
            if !(t.is_finite() && t > prev && !v.is_nan() && inside) {
                return Err(bad(format!(
                    "a change point it holds back, ({t}, {v}), is not a decided point after the \
                     complete end, in order"
                )));
            }
            prev = t;
        }
        if state.windows == Windows::Clipped && !state.held.is_empty() {
            return Err(bad("it holds change points back over clipped windows".to_string()));
        }
        let prev_at = rows.checked_sub(1).map(Place::Row);
        Ok(DenseLive {
            monitor,
            rules: StampRules::resume(gap, front, state.last, prev_at),
            windows: state.windows,
            relative: state.relative,
            limit: state.limit,
            rows,
            t0: state.t0,
            held: state.held.clone(),
            stopped: state.stopped,
        })
    }
}
