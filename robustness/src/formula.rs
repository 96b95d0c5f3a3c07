//! The runtime's formula representation.

use std::fmt;

/// An arithmetic expression over the state variables of one sample.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// A constant.
    Const(f64),
    /// The state variable with this column index in the trace.
    Var(usize),
    /// `-e`.
    Neg(Box<Expr>),
    /// `a + b`.
    Add(Box<Expr>, Box<Expr>),
    /// `a - b`.
    Sub(Box<Expr>, Box<Expr>),
    /// `a * b`.
    Mul(Box<Expr>, Box<Expr>),
    /// `a / b`.
    Div(Box<Expr>, Box<Expr>),
    /// `abs(e)`.
    Abs(Box<Expr>),
    /// `sqrt(e)`.
    Sqrt(Box<Expr>),
}

/// A comparison operator. Robustness does not distinguish strict from non-strict.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CmpOp {
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
}

/// The end of an [`Interval`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Bound {
    /// `[a..]`: to the end of the trace.
    Unbounded,
    /// `[a..b]`: up to `b`, exclusive.
    Exclusive(usize),
    /// `[a..=b]`: up to `b`, inclusive.
    Inclusive(usize),
}

/// A time interval relative to the current step, as in `always[a..=b]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Interval {
    /// The first offset in the window.
    pub start: usize,
    /// Where the window ends.
    pub end: Bound,
}

/// An STL formula whose robustness is computed over a trace.
#[derive(Clone, Debug, PartialEq)]
pub enum Formula {
    /// Robustness `+inf`.
    True,
    /// Robustness `-inf`.
    False,
    /// `lhs op rhs`; robustness `rhs - lhs` for `<`/`<=`, `lhs - rhs` for `>`/`>=`.
    Cmp {
        /// Left operand.
        lhs: Expr,
        /// The comparison.
        op: CmpOp,
        /// Right operand.
        rhs: Expr,
    },
    /// `!f`: the negated robustness.
    Not(Box<Formula>),
    /// `f1 && f2 && ...`: the minimum. Empty means `true`.
    And(Vec<Formula>),
    /// `f1 || f2 || ...`: the maximum. Empty means `false`.
    Or(Vec<Formula>),
    /// `f -> g`, that is `!f || g`.
    Implies(Box<Formula>, Box<Formula>),
    /// `always[I] f`: the minimum over the window.
    Always(Interval, Box<Formula>),
    /// `eventually[I] f`: the maximum over the window.
    Eventually(Interval, Box<Formula>),
    /// `f until[I] g`.
    Until(Interval, Box<Formula>, Box<Formula>),
}

impl Expr {
    /// The value of the expression on one sample, `state[i]` being variable `i`.
    ///
    /// A variable index outside `state` reads as NaN; [`Formula::max_var`] lets callers
    /// validate a formula against their trace once instead.
    pub fn eval(&self, state: &[f64]) -> f64 {
        match self {
            Expr::Const(c) => *c,
            Expr::Var(i) => state.get(*i).copied().unwrap_or(f64::NAN),
            Expr::Neg(e) => -e.eval(state),
            Expr::Add(a, b) => a.eval(state) + b.eval(state),
            Expr::Sub(a, b) => a.eval(state) - b.eval(state),
            Expr::Mul(a, b) => a.eval(state) * b.eval(state),
            Expr::Div(a, b) => a.eval(state) / b.eval(state),
            Expr::Abs(e) => e.eval(state).abs(),
            Expr::Sqrt(e) => e.eval(state).sqrt(),
        }
    }

    fn max_var(&self) -> Option<usize> {
        match self {
            Expr::Const(_) => None,
            Expr::Var(i) => Some(*i),
            Expr::Neg(e) | Expr::Abs(e) | Expr::Sqrt(e) => e.max_var(),
            Expr::Add(a, b) | Expr::Sub(a, b) | Expr::Mul(a, b) | Expr::Div(a, b) => {
                a.max_var().max(b.max_var())
            }
        }
    }
}

impl CmpOp {
    /// The robustness of `lhs op rhs` given the two operand values.
    pub fn robustness(self, lhs: f64, rhs: f64) -> f64 {
        match self {
            CmpOp::Lt | CmpOp::Le => rhs - lhs,
            CmpOp::Gt | CmpOp::Ge => lhs - rhs,
        }
    }
}

impl Interval {
    /// `[0..]`, the interval of an operator written without one.
    pub const ALL: Interval = Interval { start: 0, end: Bound::Unbounded };

    /// The last offset in the window, or `None` when the window is unbounded.
    ///
    /// An empty bounded interval (`[3..3]`) has no last offset either; the checker rejects
    /// it, and evaluators treat its windows as empty.
    pub fn last_offset(&self) -> Option<usize> {
        match self.end {
            Bound::Unbounded => None,
            Bound::Exclusive(b) => b.checked_sub(1),
            Bound::Inclusive(b) => Some(b),
        }
    }

    /// Whether no step can ever lie in the window.
    pub fn is_empty(&self) -> bool {
        match self.end {
            Bound::Unbounded => false,
            Bound::Exclusive(b) => b <= self.start,
            Bound::Inclusive(b) => b < self.start,
        }
    }

    /// The steps of the window at step `t` on a trace of `n` steps, clipped to the trace.
    pub fn window(&self, t: usize, n: usize) -> std::ops::Range<usize> {
        let lo = t.saturating_add(self.start).min(n);
        let hi = match self.end {
            Bound::Unbounded => n,
            Bound::Exclusive(b) => t.saturating_add(b).min(n),
            Bound::Inclusive(b) => t.saturating_add(b).saturating_add(1).min(n),
        };
        lo..hi.max(lo)
    }
}

impl Formula {
    /// The formula's horizon: how many steps past `t` its robustness at `t` may read.
    /// `None` means infinite.
    pub fn horizon(&self) -> Option<usize> {
        match self {
            Formula::True | Formula::False | Formula::Cmp { .. } => Some(0),
            Formula::Not(f) => f.horizon(),
            Formula::And(fs) | Formula::Or(fs) => {
                fs.iter().try_fold(0, |acc, f| f.horizon().map(|h| acc.max(h)))
            }
            Formula::Implies(f, g) => Some(f.horizon()?.max(g.horizon()?)),
            Formula::Always(i, f) | Formula::Eventually(i, f) => {
                window_end(i)?.checked_add(f.horizon()?)
            }
            Formula::Until(i, f, g) => window_end(i)?.checked_add(f.horizon()?.max(g.horizon()?)),
        }
    }

    /// The largest state-variable index the formula reads, if it reads any.
    pub fn max_var(&self) -> Option<usize> {
        match self {
            Formula::True | Formula::False => None,
            Formula::Cmp { lhs, rhs, .. } => lhs.max_var().max(rhs.max_var()),
            Formula::Not(f) | Formula::Always(_, f) | Formula::Eventually(_, f) => f.max_var(),
            Formula::And(fs) | Formula::Or(fs) => fs.iter().filter_map(Formula::max_var).max(),
            Formula::Implies(f, g) | Formula::Until(_, f, g) => f.max_var().max(g.max_var()),
        }
    }

    /// Whether the formula has no temporal operator: its robustness at `t` reads `s_t` only.
    pub fn is_state_formula(&self) -> bool {
        match self {
            Formula::True | Formula::False | Formula::Cmp { .. } => true,
            Formula::Not(f) => f.is_state_formula(),
            Formula::And(fs) | Formula::Or(fs) => fs.iter().all(Formula::is_state_formula),
            Formula::Implies(f, g) => f.is_state_formula() && g.is_state_formula(),
            Formula::Always(..) | Formula::Eventually(..) | Formula::Until(..) => false,
        }
    }
}

/// The horizon contribution of an interval: `b - 1` for `[a..b]`, `b` for `[a..=b]`.
fn window_end(i: &Interval) -> Option<usize> {
    match i.end {
        Bound::Unbounded => None,
        Bound::Exclusive(b) => Some(b.saturating_sub(1)),
        Bound::Inclusive(b) => Some(b),
    }
}

impl fmt::Display for Interval {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.end {
            Bound::Unbounded => write!(f, "[{}..]", self.start),
            Bound::Exclusive(b) => write!(f, "[{}..{}]", self.start, b),
            Bound::Inclusive(b) => write!(f, "[{}..={}]", self.start, b),
        }
    }
}
