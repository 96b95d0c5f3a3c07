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

/// A [`Formula`] or [`Expr`] printed in hstl syntax with the given variable names.
///
/// Made by [`Formula::display_with`] and [`Expr::display_with`]. A variable without a name
/// prints as `v<index>`. Parentheses appear where precedence needs them and around nested
/// operators of the same level, so the text parses back to the same tree. Infinite
/// constants print as `1e999` (which reads back as infinity) and NaN as `(0 / 0)`.
#[derive(Clone, Copy, Debug)]
pub struct Display<'a, T> {
    item: &'a T,
    names: &'a [&'a str],
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

impl Formula {
    /// The formula in hstl syntax, `names[i]` naming variable `i`.
    pub fn display_with<'a>(&'a self, names: &'a [&'a str]) -> Display<'a, Formula> {
        Display { item: self, names }
    }

    /// Binding strength, loosest first: `->`, `||`, `&&`, `until`, prefix, atoms.
    fn level(&self) -> u8 {
        match self {
            Formula::Implies(..) => 0,
            Formula::Or(gs) | Formula::And(gs) if gs.len() == 1 => gs[0].level(),
            Formula::Or(gs) if !gs.is_empty() => 1,
            Formula::And(gs) if !gs.is_empty() => 2,
            Formula::Until(..) => 3,
            Formula::Not(_) | Formula::Always(..) | Formula::Eventually(..) => 4,
            _ => 5,
        }
    }

    fn write(&self, f: &mut fmt::Formatter<'_>, names: &[&str]) -> fmt::Result {
        // Operands tighter than `min` print bare; others get parentheses.
        let operand = |f: &mut fmt::Formatter<'_>, g: &Formula, min: u8| {
            if g.level() >= min {
                g.write(f, names)
            } else {
                write!(f, "(")?;
                g.write(f, names)?;
                write!(f, ")")
            }
        };
        match self {
            Formula::True => write!(f, "true"),
            Formula::False => write!(f, "false"),
            Formula::Cmp { lhs, op, rhs } => {
                lhs.write(f, names, 0)?;
                write!(f, " {op} ")?;
                rhs.write(f, names, 0)
            }
            Formula::Not(g) => {
                write!(f, "!")?;
                operand(f, g, 4)
            }
            Formula::Always(i, g) | Formula::Eventually(i, g) => {
                let kw = if matches!(self, Formula::Always(..)) { "always" } else { "eventually" };
                write!(f, "{kw}{i} ")?;
                operand(f, g, 4)
            }
            Formula::Until(i, g, h) => {
                operand(f, g, 4)?;
                write!(f, " until{i} ")?;
                operand(f, h, 4)
            }
            Formula::And(gs) | Formula::Or(gs) => {
                let (sep, level, empty) = match self {
                    Formula::And(_) => (" && ", 2, "true"),
                    _ => (" || ", 1, "false"),
                };
                match gs.as_slice() {
                    [] => write!(f, "{empty}"),
                    [g] => g.write(f, names),
                    _ => {
                        for (k, g) in gs.iter().enumerate() {
                            if k > 0 {
                                write!(f, "{sep}")?;
                            }
                            operand(f, g, level + 1)?;
                        }
                        Ok(())
                    }
                }
            }
            Formula::Implies(g, h) => {
                operand(f, g, 1)?;
                write!(f, " -> ")?;
                operand(f, h, 0)
            }
        }
    }
}

impl Expr {
    /// The expression in hstl syntax, `names[i]` naming variable `i`.
    pub fn display_with<'a>(&'a self, names: &'a [&'a str]) -> Display<'a, Expr> {
        Display { item: self, names }
    }

    /// Binding strength: sums, products, factors.
    fn level(&self) -> u8 {
        match self {
            Expr::Add(..) | Expr::Sub(..) => 0,
            Expr::Mul(..) | Expr::Div(..) => 1,
            _ => 2,
        }
    }

    fn write(&self, f: &mut fmt::Formatter<'_>, names: &[&str], min: u8) -> fmt::Result {
        if self.level() < min {
            write!(f, "(")?;
            self.write(f, names, 0)?;
            return write!(f, ")");
        }
        match self {
            Expr::Const(c) if c.is_nan() => write!(f, "(0 / 0)"),
            Expr::Const(c) if c.is_infinite() => {
                write!(f, "{}1e999", if *c < 0.0 { "-" } else { "" })
            }
            Expr::Const(c) => write!(f, "{c}"),
            Expr::Var(i) => match names.get(*i) {
                Some(name) => write!(f, "{name}"),
                None => write!(f, "v{i}"),
            },
            Expr::Neg(e) => {
                write!(f, "-")?;
                e.write(f, names, 2)
            }
            Expr::Abs(e) | Expr::Sqrt(e) => {
                write!(f, "{}(", if matches!(self, Expr::Abs(_)) { "abs" } else { "sqrt" })?;
                e.write(f, names, 0)?;
                write!(f, ")")
            }
            Expr::Add(a, b) | Expr::Sub(a, b) | Expr::Mul(a, b) | Expr::Div(a, b) => {
                let (op, level) = match self {
                    Expr::Add(..) => ("+", 0),
                    Expr::Sub(..) => ("-", 0),
                    Expr::Mul(..) => ("*", 1),
                    _ => ("/", 1),
                };
                // Left-associative: the right operand of the same level needs parentheses.
                a.write(f, names, level)?;
                write!(f, " {op} ")?;
                b.write(f, names, level + 1)
            }
        }
    }
}

impl fmt::Display for CmpOp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            CmpOp::Lt => "<",
            CmpOp::Le => "<=",
            CmpOp::Gt => ">",
            CmpOp::Ge => ">=",
        })
    }
}

impl fmt::Display for Display<'_, Formula> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.item.write(f, self.names)
    }
}

impl fmt::Display for Display<'_, Expr> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.item.write(f, self.names, 0)
    }
}

/// Prints in hstl syntax, variable `i` as `v<i>`; [`Formula::display_with`] names them.
impl fmt::Display for Formula {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, &[])
    }
}

/// Prints in hstl syntax, variable `i` as `v<i>`; [`Expr::display_with`] names them.
impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f, &[], 0)
    }
}
