//! Time stamps of dense-time traces, read alike by `hstlc monitor` (from CSV text) and the
//! Python package (from numpy columns): which stamps are whole numbers kept exact, the
//! order they must come in, `--max-gap` / `max_gap=`, and how the output's times are
//! written (in the time column's scale, or relative to the first stamp).

use std::fmt;

use crate::Problem;
use hstl_robustness::dense::{DenseSignal, DenseTraceBuilder, DenseTraceError, TimeScale};

/// A row's time stamp as given: a whole number (digits in a CSV cell, an integer numpy
/// column) or a double.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Stamp {
    /// A whole number: nanoseconds since the epoch, say.
    Int(i128),
    /// A double.
    Real(f64),
}

impl Stamp {
    /// Appends a row with this stamp (as [`StampOrder::next`] returned it) to `builder`.
    pub fn push(
        self,
        builder: &mut DenseTraceBuilder,
        cells: &[Option<f64>],
    ) -> Result<(), DenseTraceError> {
        match self {
            Stamp::Int(s) => builder.push_int(s, cells),
            Stamp::Real(t) => builder.push(t, cells),
        }
    }
}

impl fmt::Display for Stamp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Stamp::Int(n) => write!(f, "{n}"),
            Stamp::Real(t) => write!(f, "{t}"),
        }
    }
}

/// 2^53: every whole number of smaller magnitude is a double.
const EXACT: i128 = 1 << 53;

/// Reads a trace's stamps in one of two ways, decided by the first: a whole number of
/// magnitude 2^53 or more (nanoseconds since the epoch, say) starts integer stamps, which
/// must all be whole numbers and are taken relative to the first in integer arithmetic;
/// any other first stamp starts double stamps, each the nearest double (a whole number that
/// no double holds exactly is an error, never rounded). Stamps must strictly increase.
#[derive(Clone, Debug, Default)]
pub struct StampOrder {
    last: Option<Stamp>,
}

/// A stamp [`StampOrder`] refuses.
#[derive(Clone, Debug, PartialEq)]
pub enum StampError {
    /// A decimal after whole-number stamps beyond 2^53.
    Decimal,
    /// A whole number no double holds, among double stamps.
    NotExact {
        /// The stamp.
        stamp: i128,
    },
    /// A stamp not after the previous one.
    NotIncreasing {
        /// The previous stamp, as written.
        previous: String,
        /// The stamp, as written.
        stamp: String,
    },
    /// A stamp that is NaN or infinite.
    NotFinite {
        /// The stamp.
        stamp: f64,
    },
}

impl StampError {
    /// What is wrong, about the stamp in the time column `time`.
    pub fn message(&self, time: &str) -> String {
        match self {
            StampError::Decimal => format!(
                "the time stamp in column `{time}` is a decimal, but the trace's stamps are \
                 whole numbers (its first is beyond 2^53)"
            ),
            StampError::NotExact { stamp } => format!(
                "the time stamp {stamp} in column `{time}` is not exactly a double, and the \
                 trace's stamps are read as doubles (its first is below 2^53)"
            ),
            StampError::NotIncreasing { previous, stamp } => {
                let how = if previous == stamp { "repeats" } else { "goes back from" };
                format!(
                    "the time stamp {stamp} in column `{time}` {how} the previous one, {previous}"
                )
            }
            StampError::NotFinite { stamp } => {
                format!("the time stamp {stamp} in column `{time}` is not a finite number")
            }
        }
    }

    /// How to fix it.
    pub fn help(&self) -> String {
        match self {
            StampError::Decimal => {
                "write every stamp as a whole number (such as nanoseconds since the epoch)"
            }
            StampError::NotExact { .. } => {
                "stamps are taken relative to the first in integer arithmetic only when the \
                 first is a whole number of 2^53 or more: write the stamps in a unit that keeps \
                 them below 2^53, or all as such whole numbers"
            }
            StampError::NotIncreasing { .. } => {
                "time stamps must strictly increase: sort the rows, and merge the rows of one \
                 stamp into one (an empty cell keeps a variable's value)"
            }
            StampError::NotFinite { .. } => {
                "every row needs a time stamp: drop the rows without one (a variable's missing \
                 sample is an empty cell or NaN in its own column)"
            }
        }
        .to_string()
    }
}

impl StampOrder {
    /// The next row's stamp as the trace takes it, or what is wrong with it.
    pub fn next(&mut self, given: Stamp) -> Result<Stamp, StampError> {
        let stamp = match (self.last, given) {
            (_, Stamp::Real(t)) if !t.is_finite() => {
                return Err(StampError::NotFinite { stamp: t });
            }
            (None, Stamp::Int(n)) if n.abs() >= EXACT => Stamp::Int(n),
            (Some(Stamp::Int(_)), Stamp::Int(n)) => Stamp::Int(n),
            (Some(Stamp::Int(_)), Stamp::Real(_)) => return Err(StampError::Decimal),
            (_, Stamp::Int(n)) => {
                let t = n as f64;
                if t as i128 != n {
                    return Err(StampError::NotExact { stamp: n });
                }
                Stamp::Real(t)
            }
            (_, Stamp::Real(t)) => Stamp::Real(t),
        };
        let order = match (self.last, stamp) {
            (Some(Stamp::Int(p)), Stamp::Int(s)) if s <= p => Some((p.to_string(), s.to_string())),
            (Some(Stamp::Real(p)), Stamp::Real(s)) if s <= p => {
                Some((p.to_string(), s.to_string()))
            }
            _ => None,
        };
        if let Some((previous, stamp)) = order {
            return Err(StampError::NotIncreasing { previous, stamp });
        }
        self.last = Some(stamp);
        Ok(stamp)
    }

    /// The first stamp as taken, once one was.
    pub fn last(&self) -> Option<Stamp> {
        self.last
    }
}

/// Which front end a message is for: how it names its settings (`--max-gap ` or
/// `max_gap=`, `--formula` or `formula=`) and how a user ends a stream.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Front {
    /// `hstlc monitor`.
    Cli,
    /// The Python package.
    Python,
}

impl Front {
    /// The gap setting, as errors quote it before its value (`--max-gap 0.5`, `max_gap=0.5`).
    pub fn max_gap(self) -> &'static str {
        match self {
            Front::Cli => "--max-gap ",
            Front::Python => "max_gap=",
        }
    }

    /// The setting that picks a `let` to monitor.
    pub fn formula(self) -> &'static str {
        match self {
            Front::Cli => "`--formula`",
            Front::Python => "`formula=`",
        }
    }

    /// How a user ends a stream early.
    pub fn end_sooner(self) -> &'static str {
        match self {
            Front::Cli => "end the stream sooner",
            Front::Python => "call `finish()` sooner",
        }
    }

    /// Online monitoring over complete windows, as the user asked for it.
    pub fn online_complete(self) -> &'static str {
        match self {
            Front::Cli => "`--online` with `--windows complete`",
            Front::Python => "`online(windows=\"complete\")`",
        }
    }

    /// How to score a whole trace over complete windows instead.
    pub fn whole_complete(self) -> &'static str {
        match self {
            Front::Cli => "leave out `--online`",
            Front::Python => "score the whole trace with `signal(trace, windows=\"complete\")`",
        }
    }
}

/// Where a row is, as the front end counts: a row of a table (counted from 0) or a line of
/// a file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    /// A row, counted from 0.
    Row(usize),
    /// A line of a file, counted from 1.
    Line(usize),
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Place::Row(r) => write!(f, "row {r}"),
            Place::Line(l) => write!(f, "line {l}"),
        }
    }
}

/// The rules a dense-time trace's rows are read by, one row at a time, for every reader
/// (a CSV file, numpy columns, rows pushed online): each stamp as [`StampOrder`] takes it,
/// and a gap larger than `--max-gap` / `max_gap=` refused, naming the previous row.
#[derive(Clone, Debug)]
pub struct StampRules {
    pub(super) order: StampOrder,
    pub(super) gap: Option<MaxGap>,
    pub(super) front: Front,
    /// Where the previous row is.
    pub(super) prev_at: Option<Place>,
}

impl StampRules {
    /// Rules with at most `gap` between consecutive stamps, worded for `front`.
    pub fn new(gap: Option<MaxGap>, front: Front) -> StampRules {
        StampRules { order: StampOrder::default(), gap, front, prev_at: None }
    }

    /// Rules that continue a trace whose last row, at `prev_at`, had the stamp `last` (as
    /// [`StampOrder`] took it).
    pub fn resume(
        gap: Option<MaxGap>,
        front: Front,
        last: Option<Stamp>,
        prev_at: Option<Place>,
    ) -> StampRules {
        StampRules { order: StampOrder { last }, gap, front, prev_at }
    }

    /// Takes `stamp` (as [`StampRules::check`] returned it) as the row at `at`.
    pub fn take(&mut self, stamp: Stamp, at: Place) {
        // `check` accepted it: the order takes it again without fail.
        let _ = self.order.next(stamp);
        self.prev_at = Some(at);
    }

    /// The last stamp taken, if any.
    pub fn last(&self) -> Option<Stamp> {
        self.order.last()
    }

    /// The gap bound, if any.
    pub fn gap(&self) -> Option<&MaxGap> {
        self.gap.as_ref()
    }

    /// The front end the messages are worded for.
    pub fn front(&self) -> Front {
        self.front
    }

    /// Starts a new trace (the settings kept).
    pub fn restart(&mut self) {
        self.order = StampOrder::default();
        self.prev_at = None;
    }
}

/// The largest gap allowed between consecutive stamps (`hstlc monitor --max-gap`,
/// `max_gap=`): the bound exactly as written (`digits / 10^decimals`) and as the nearest
/// double, compared exactly with each gap.
#[derive(Clone, Debug)]
pub struct MaxGap {
    text: String,
    digits: u128,
    decimals: u32,
    bound: f64,
}

impl MaxGap {
    /// The bound written `text` (`0.5`, `500000000`); `flag` names the setting in the
    /// error (`--max-gap`, `max_gap=`).
    pub fn parse(text: &str, flag: &str) -> Result<MaxGap, Problem> {
        let bad = || {
            Problem::new(
                format!("`{flag}{text}` is not a time: give a number of 0 or more"),
                Some(
                    "the gap is in the time column's unit, such as `0.5` for stamps in \
                     seconds or `500000000` for nanoseconds"
                        .to_string(),
                ),
            )
        };
        let bound: f64 = text.trim().parse().map_err(|_| bad())?;
        if !(bound.is_finite() && bound >= 0.0) {
            return Err(bad());
        }
        // A number, but one whose exact value has more digits than the exact comparison of
        // gaps holds (`1e300`, 39 digits and more).
        let (digits, decimals) = TimeScale::parse_decimal(text).ok_or_else(|| {
            Problem::new(
                format!(
                    "`{flag}{text}` has more digits than a gap is compared with exactly: at \
                     most 38 in all, with the zeros an exponent stands for"
                ),
                Some(format!(
                    "write the gap with at most 38 digits, such as `1e37`, or leave `{}` out",
                    flag.trim_end_matches(['=', ' '])
                )),
            )
        })?;
        Ok(MaxGap { text: text.trim().to_string(), digits, decimals, bound })
    }

    /// The bound as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The gap from `prev` to `now` as written, when it is larger than the bound (compared
    /// exactly).
    pub fn exceeded(&self, prev: Stamp, now: Stamp) -> Option<String> {
        match (prev, now) {
            (Stamp::Int(p), Stamp::Int(s)) => {
                let gap = u128::try_from(s - p).unwrap_or(0);
                // gap > digits / 10^decimals, with no rounding (an overflow is larger).
                let scaled = 10u128.checked_pow(self.decimals).and_then(|m| gap.checked_mul(m));
                scaled.is_none_or(|g| g > self.digits).then(|| gap.to_string())
            }
            (Stamp::Real(p), Stamp::Real(s)) => {
                // `d` is `s - p` rounded and `err` the rounding error (Knuth's two-sum):
                // rounding is monotone, so the exact gap exceeds the bound exactly when
                // `d` does, or `d` equals it and the error is positive.
                let d = s - p;
                let sv = d + p;
                let err = (s - sv) + (-p - (d - sv));
                (d > self.bound || d == self.bound && err > 0.0)
                    .then(|| decimal_difference(&s.to_string(), &p.to_string()))
            }
            // A trace's stamps are all of one kind (`StampOrder`).
            _ => None,
        }
    }

    /// The message for a gap `width` (as [`MaxGap::exceeded`] gives it) from `prev`
    /// (where `prev_at` says, such as ` (line 3)`) to `stamp` in column `time`, `flag` as
    /// for [`MaxGap::parse`]; and its hint.
    pub fn problem(
        &self,
        width: &str,
        (prev, prev_at): (Stamp, &str),
        stamp: Stamp,
        time: &str,
        flag: &str,
    ) -> Problem {
        Problem::new(
            format!(
                "the time stamp {stamp} in column `{time}` comes {width} after the previous \
                 one, {prev}{prev_at}: more than `{flag}{}`",
                self.text
            ),
            Some(format!(
                "each variable would keep its value across the gap: fill the gap with samples, \
                 monitor the parts before and after it separately, or raise `{}`",
                flag.trim_end_matches(['=', ' '])
            )),
        )
    }
}

/// How a signal's times are written: in the time column's scale, or relative to the first
/// stamp.
#[derive(Clone, Copy, Debug)]
pub struct TimeAxis {
    /// Relative to the first stamp.
    pub relative: bool,
    /// The first whole-number stamp, when stamps are whole numbers beyond 2^53 (the
    /// signal's times are then relative to it already, computed in integer arithmetic).
    pub origin: Option<i128>,
    /// The first stamp, when stamps are doubles.
    pub t0: f64,
}

impl TimeAxis {
    /// Time `t` of a signal, written as `hstlc monitor` prints it: in the column's scale
    /// (exactly, in integer arithmetic for whole-number stamps), or relative to the first
    /// stamp (exactly: the difference of the printed times in decimal arithmetic).
    pub fn text(&self, t: f64) -> String {
        match (self.relative, self.origin) {
            (false, origin) => time_text(origin, t),
            (true, Some(_)) => t.to_string(),
            (true, None) => decimal_difference(&t.to_string(), &self.t0.to_string()),
        }
    }

    /// Time `t` as a double: the nearest double to [`TimeAxis::text`] (the same double as
    /// `t` itself in the column's scale for double stamps).
    pub fn double(&self, t: f64) -> f64 {
        match (self.relative, self.origin) {
            (false, None) | (true, Some(_)) => t,
            _ => self.text(t).parse().unwrap_or(f64::NAN),
        }
    }

    /// Time `t` as a whole number in the column's scale (whole-number stamps only); `None`
    /// when it falls between two whole numbers.
    pub fn whole(&self, t: f64) -> Option<i128> {
        let origin = self.origin?;
        (t.is_finite() && t.fract() == 0.0 && t.abs() < 1.7e38).then(|| origin + t as i128)
    }
}

/// The rows `hstlc monitor --signal` prints for a signal of a trace from `t0` to `t_last`:
/// each change point with its value, and over complete windows (`end` given: the signal is
/// determined on `[t0, end]`) the change points before `end` then, if `end` comes before
/// `t_last`, a row at `end` with no value (the times from `end` on are undetermined: rows
/// give values over intervals, so the value at the single instant `end` is not shown).
pub fn signal_rows(
    signal: &DenseSignal,
    t0: f64,
    t_last: f64,
    end: Option<f64>,
) -> Vec<(f64, Option<f64>)> {
    match end {
        Some(end) if end < t_last => {
            let mut rows: Vec<(f64, Option<f64>)> =
                signal.points().take_while(|&(t, _)| t < end).map(|(t, v)| (t, Some(v))).collect();
            rows.push((end.max(t0), None));
            rows
        }
        _ => signal.until(t_last).map(|(t, v)| (t, Some(v))).collect(),
    }
}

/// `a - b` for two decimals as Rust prints doubles (`-12.5`, `0.001`: no exponent),
/// exactly, printed the same way.
pub fn decimal_difference(a: &str, b: &str) -> String {
    fn parts(x: &str) -> (bool, &str, &str) {
        let (neg, x) = x.strip_prefix('-').map_or((false, x), |r| (true, r));
        let (int, frac) = x.split_once('.').unwrap_or((x, ""));
        (neg, int, frac)
    }
    let ((na, ia, fa), (nb, ib, fb)) = (parts(a), parts(b));
    let scale = fa.len().max(fb.len());
    // One more integer digit than either, for a carry.
    let width = ia.len().max(ib.len()) + 1;
    let digits = |int: &str, frac: &str| {
        let mut v = vec![0u8; width - int.len()];
        v.extend(int.bytes().chain(frac.bytes()).map(|c| c.wrapping_sub(b'0')));
        v.resize(width + scale, 0);
        v
    };
    let (da, db) = (digits(ia, fa), digits(ib, fb));
    // `a - b` is `±(|a| + |b|)` for opposite signs, `±(|a| - |b|)` otherwise.
    let (neg, mag) = if na != nb {
        (na, add_digits(&da, &db))
    } else if da >= db {
        (na, sub_digits(&da, &db))
    } else {
        (!na, sub_digits(&db, &da))
    };
    let text = |d: &[u8]| d.iter().map(|&c| char::from(b'0' + c)).collect::<String>();
    let int = text(&mag[..width]);
    let int = int.trim_start_matches('0');
    let frac = text(&mag[width..]);
    let frac = frac.trim_end_matches('0');
    if int.is_empty() && frac.is_empty() {
        return "0".to_string();
    }
    let sign = if neg { "-" } else { "" };
    let int = if int.is_empty() { "0" } else { int };
    if frac.is_empty() { format!("{sign}{int}") } else { format!("{sign}{int}.{frac}") }
}

/// The sum of two equally long digit strings (most significant first; no overflow out of
/// the first digit).
fn add_digits(a: &[u8], b: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; a.len()];
    let mut carry = 0u8;
    for k in (0..a.len()).rev() {
        let s = a[k] + b[k] + carry;
        out[k] = s % 10;
        carry = s / 10;
    }
    out
}

/// `a - b` for two equally long digit strings with `a >= b`.
fn sub_digits(a: &[u8], b: &[u8]) -> Vec<u8> {
    let mut out = vec![0u8; a.len()];
    let mut borrow = 0u8;
    for k in (0..a.len()).rev() {
        let (d, sub) = (a[k], b[k] + borrow);
        if d >= sub {
            out[k] = d - sub;
            borrow = 0;
        } else {
            out[k] = d + 10 - sub;
            borrow = 1;
        }
    }
    out
}

/// A time of a signal as the trace's time column writes it: `t` itself for decimal
/// stamps, `origin + t` for whole-number stamps (exactly, in integer arithmetic for the
/// whole part: nanoseconds since the epoch stay exact).
pub fn time_text(origin: Option<i128>, t: f64) -> String {
    let Some(origin) = origin else { return t.to_string() };
    if !t.is_finite() || t < 0.0 {
        return t.to_string();
    }
    let whole = t.trunc();
    // Every double at or above 2^53 is whole; below it the cast is exact.
    let Some(w) = (whole < 1.7e38).then_some(whole as i128) else { return t.to_string() };
    let int = origin + w;
    if whole == t {
        return int.to_string();
    }
    // `t` has a fraction, so it is below 2^53: its shortest decimal's digits after the point.
    let shortest = t.to_string();
    match shortest.split_once('.') {
        Some((_, frac)) => format!("{int}.{frac}"),
        None => shortest,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimal_differences_are_exact() {
        assert_eq!(decimal_difference("0.3", "0.1"), "0.2");
        assert_eq!(decimal_difference("1700000000.4", "1700000000"), "0.4");
        assert_eq!(decimal_difference("5", "-2.25"), "7.25");
        assert_eq!(decimal_difference("-2.25", "5"), "-7.25");
        assert_eq!(decimal_difference("-1", "-3.5"), "2.5");
        assert_eq!(decimal_difference("0.1", "0.3"), "-0.2");
        assert_eq!(decimal_difference("99.99", "0.01"), "99.98");
        assert_eq!(decimal_difference("99.99", "-0.01"), "100");
        assert_eq!(decimal_difference("2", "2"), "0");
        assert_eq!(decimal_difference("-0", "0"), "0");
        assert_eq!(decimal_difference("0.30000000000000004", "0"), "0.30000000000000004");
    }

    #[test]
    fn gaps_compare_exactly() {
        let g = MaxGap::parse("0.1", "--max-gap ").expect("a time");
        // 0.3 - 0.2 (as doubles) is exactly 0.0999999999999999778: below the double 0.1.
        assert!(g.exceeded(Stamp::Real(0.2), Stamp::Real(0.3)).is_none());
        assert!(g.exceeded(Stamp::Real(0.0), Stamp::Real(0.1)).is_none());
        assert_eq!(g.exceeded(Stamp::Real(0.0), Stamp::Real(0.25)).as_deref(), Some("0.25"));
        let ns = MaxGap::parse("0.5", "--max-gap ").expect("a time");
        let t = 1_700_000_000_000_000_000i128;
        assert!(ns.exceeded(Stamp::Int(t), Stamp::Int(t + 1)).is_some());
        let ns = MaxGap::parse("500000000", "--max-gap ").expect("a time");
        assert!(ns.exceeded(Stamp::Int(t), Stamp::Int(t + 500_000_000)).is_none());
        assert_eq!(
            ns.exceeded(Stamp::Int(t), Stamp::Int(t + 500_000_001)).as_deref(),
            Some("500000001")
        );
        assert!(MaxGap::parse("-1", "--max-gap ").is_err());
        assert!(MaxGap::parse("inf", "--max-gap ").is_err());
    }

    #[test]
    fn stamps_beyond_2_pow_53_stay_whole_numbers() {
        let mut order = StampOrder::default();
        let t = 1i128 << 62;
        assert_eq!(order.next(Stamp::Int(t)), Ok(Stamp::Int(t)));
        assert_eq!(order.next(Stamp::Int(t + 1)), Ok(Stamp::Int(t + 1)));
        assert_eq!(order.next(Stamp::Real(1.5)), Err(StampError::Decimal));
        let e = order.next(Stamp::Int(t + 1)).expect_err("a repeat");
        assert!(e.message("t").contains("repeats"), "{}", e.message("t"));
        let mut order = StampOrder::default();
        assert_eq!(order.next(Stamp::Int(3)), Ok(Stamp::Real(3.0)));
        assert_eq!(
            order.next(Stamp::Int((1 << 53) + 1)),
            Err(StampError::NotExact { stamp: (1 << 53) + 1 })
        );
        assert!(matches!(order.next(Stamp::Real(f64::NAN)), Err(StampError::NotFinite { .. })));
        let e = order.next(Stamp::Real(2.0)).expect_err("backwards");
        assert_eq!(
            e.message("t"),
            "the time stamp 2 in column `t` goes back from the previous one, 3"
        );
    }

    #[test]
    fn complete_rows_end_with_an_undetermined_row() {
        let s = DenseSignal::from_points(&[(0.0, 1.0), (2.0, 3.0), (3.0, 4.0)]).expect("points");
        assert_eq!(signal_rows(&s, 0.0, 5.0, None).len(), 3);
        assert_eq!(
            signal_rows(&s, 0.0, 5.0, Some(3.0)),
            [(0.0, Some(1.0)), (2.0, Some(3.0)), (3.0, None)]
        );
        assert_eq!(signal_rows(&s, 0.0, 5.0, Some(-1.0)), [(0.0, None)]);
        assert_eq!(signal_rows(&s, 0.0, 5.0, Some(5.0)).len(), 3);
    }
}
