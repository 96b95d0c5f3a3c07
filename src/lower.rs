//! Lowering: a checked spec from [`hstl_lang`] becomes the runtime's plain data.
//!
//! This is the interpreter's path (the CLI, tools, tests); the `hstl!` macro emits the same
//! data as Rust code. `tests/lower_vs_macro.rs` holds the two paths against each other.
//! `let`s are inlined: the runtime's formulas are trees without names.

use std::fmt;

use hstl_lang::{
    Bound, CExpr, CExprKind, CFormula, CFormulaKind, CheckedSpec, CmpOp, Domain, Intra, Reward,
    Terminate,
};
use hstl_robustness as rob;
use hstl_runtime as rt;

/// Why a checked spec could not be lowered.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LowerError {
    /// The spec, or the part asked for, did not check: its diagnostics say why.
    Invalid {
        /// The spec's name.
        spec: String,
    },
    /// The spec has no `let` of this name.
    UnknownLet {
        /// The spec's name.
        spec: String,
        /// The name asked for.
        name: String,
        /// The lets the spec has, in declaration order.
        known: Vec<String>,
    },
}

impl fmt::Display for LowerError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LowerError::Invalid { spec } => {
                write!(f, "spec `{spec}` has errors; run `hstlc check` to see them")
            }
            LowerError::UnknownLet { spec, name, known } if known.is_empty() => {
                write!(f, "spec `{spec}` has no `let` named `{name}` (it has no lets)")
            }
            LowerError::UnknownLet { spec, name, known } => write!(
                f,
                "spec `{spec}` has no `let` named `{name}`; its lets are {}",
                known.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", ")
            ),
        }
    }
}

impl std::error::Error for LowerError {}

/// The whole spec as the runtime's [`TaskSpec`](rt::TaskSpec). `src` is the text the
/// spec was checked from (region names quote it where a region is written inline).
pub fn task_spec(spec: &CheckedSpec, src: &str) -> Result<rt::TaskSpec, LowerError> {
    let invalid = || LowerError::Invalid { spec: spec.name.clone() };
    let task = spec.task.as_ref().ok_or_else(invalid)?;
    let lower = Lowerer { spec };
    let task = lower.formula(&task.formula).ok_or_else(invalid)?;
    let state_vars = spec
        .state_vars
        .iter()
        .map(|v| rt::StateVar {
            name: v.name.clone(),
            domain: match v.domain {
                Domain::Int { lo, hi } => Some(lo..=hi),
                Domain::Unbounded | Domain::Float { .. } => None,
            },
        })
        .collect();
    let primitives = spec
        .primitives
        .iter()
        .map(|p| {
            Some(rt::PrimitiveOption {
                name: p.name.clone(),
                reach: lower.formula(&p.reach)?,
                init: lower.formula(&p.init)?,
                terminate: match &p.terminate {
                    Terminate::Argmax => rt::Terminate::Argmax,
                    Terminate::Formula(f) => rt::Terminate::Formula(lower.formula(f)?),
                },
                avoid: match &p.avoid {
                    Some(f) => Some(lower.formula(f)?),
                    None => None,
                },
            })
        })
        .collect::<Option<Vec<_>>>()
        .ok_or_else(invalid)?;
    let options = spec
        .options
        .iter()
        .map(|o| rt::CombinedOption { name: o.name.clone(), sequence: o.sequence.clone() })
        .collect();
    let regions = spec
        .persistent_conjuncts(src)
        .unwrap_or_default()
        .into_iter()
        .map(|c| {
            Some(rt::Region {
                name: c.name,
                formula: lower.formula(&c.region)?,
                horizon: usize::try_from(c.steps).ok()?,
            })
        })
        .collect::<Option<Vec<_>>>()
        .ok_or_else(invalid)?;
    let l = &spec.learn;
    let size = |n: u64| usize::try_from(n).map_err(|_| invalid());
    let level = |q: &hstl_lang::QParams| rt::LevelParams {
        gamma: q.gamma,
        alpha: q.alpha,
        epsilon: q.epsilon,
        min_epsilon: q.min_epsilon,
        decay: q.decay,
    };
    let learn = rt::LearnParams {
        episodes: size(l.episodes)?,
        choices: size(l.choices)?,
        max_steps: size(l.max_steps)?,
        memory: size(l.memory)?,
        intra: match l.intra {
            Intra::Paper => rt::Intra::Paper,
            Intra::Remaining => rt::Intra::Remaining,
        },
        reward: match l.reward {
            Reward::Segment => rt::RewardKind::Segment,
            Reward::Window => rt::RewardKind::Window,
        },
        counterfactual: size(l.counterfactual)?,
        flat: level(&l.flat),
        options: level(&l.options),
    };
    Ok(rt::TaskSpec {
        name: spec.name.clone(),
        state_vars,
        task,
        primitives,
        options,
        learn,
        regions,
    })
}

/// The task's formula.
pub fn task(spec: &CheckedSpec) -> Result<rob::Formula, LowerError> {
    spec.task
        .as_ref()
        .and_then(|t| Lowerer { spec }.formula(&t.formula))
        .ok_or_else(|| LowerError::Invalid { spec: spec.name.clone() })
}

/// The formula of the `let` called `name`.
pub fn let_formula(spec: &CheckedSpec, name: &str) -> Result<rob::Formula, LowerError> {
    let Some(l) = spec.lets.iter().find(|l| l.name == name) else {
        return Err(LowerError::UnknownLet {
            spec: spec.name.clone(),
            name: name.to_string(),
            known: spec.lets.iter().map(|l| l.name.clone()).collect(),
        });
    };
    Lowerer { spec }
        .formula(&l.formula)
        .ok_or_else(|| LowerError::Invalid { spec: spec.name.clone() })
}

/// Any checked formula of `spec`; `None` when part of it did not check.
pub fn formula(spec: &CheckedSpec, f: &CFormula) -> Option<rob::Formula> {
    Lowerer { spec }.formula(f)
}

/// Any checked expression; `None` when part of it did not check.
pub fn expr(e: &CExpr) -> Option<rob::Expr> {
    let boxed = |a: &CExpr| expr(a).map(Box::new);
    Some(match &e.kind {
        CExprKind::Const(c) => rob::Expr::Const(*c),
        CExprKind::Var(i) => rob::Expr::Var(*i),
        CExprKind::Neg(a) => rob::Expr::Neg(boxed(a)?),
        CExprKind::Abs(a) => rob::Expr::Abs(boxed(a)?),
        CExprKind::Sqrt(a) => rob::Expr::Sqrt(boxed(a)?),
        CExprKind::Add(a, b) => rob::Expr::Add(boxed(a)?, boxed(b)?),
        CExprKind::Sub(a, b) => rob::Expr::Sub(boxed(a)?, boxed(b)?),
        CExprKind::Mul(a, b) => rob::Expr::Mul(boxed(a)?, boxed(b)?),
        CExprKind::Div(a, b) => rob::Expr::Div(boxed(a)?, boxed(b)?),
        CExprKind::Invalid => return None,
    })
}

/// The interval in the runtime's terms.
pub fn interval(iv: &hstl_lang::Interval) -> rob::Interval {
    // Steps beyond usize::MAX (32-bit targets only) are as good as unbounded.
    let steps = |n: u64| usize::try_from(n).unwrap_or(usize::MAX);
    rob::Interval {
        start: steps(iv.start),
        end: match iv.end {
            Bound::Unbounded => rob::Bound::Unbounded,
            Bound::Exclusive(b) => rob::Bound::Exclusive(steps(b)),
            Bound::Inclusive(b) => rob::Bound::Inclusive(steps(b)),
        },
    }
}

/// The longest chain of lets inlined into one formula.
pub const MAX_LET_DEPTH: usize = 256;

struct Lowerer<'a> {
    spec: &'a CheckedSpec,
}

impl Lowerer<'_> {
    fn formula(&self, f: &CFormula) -> Option<rob::Formula> {
        self.formula_at(f, 0)
    }

    /// `depth` counts inlined lets: a chain longer than [`MAX_LET_DEPTH`] is refused rather
    /// than risking the stack here or in the evaluators' recursion.
    fn formula_at(&self, f: &CFormula, depth: usize) -> Option<rob::Formula> {
        let boxed = |g: &CFormula| self.formula_at(g, depth).map(Box::new);
        let all = |v: &[CFormula]| {
            v.iter().map(|g| self.formula_at(g, depth)).collect::<Option<Vec<_>>>()
        };
        Some(match &f.kind {
            CFormulaKind::True => rob::Formula::True,
            CFormulaKind::False => rob::Formula::False,
            // `let_order` leaves out the lets on a cycle, so this recursion ends.
            CFormulaKind::Let(i) if depth < MAX_LET_DEPTH && self.spec.let_order.contains(i) => {
                self.formula_at(&self.spec.lets.get(*i)?.formula, depth + 1)?
            }
            CFormulaKind::Let(_) => return None,
            CFormulaKind::Cmp(op, a, b) => rob::Formula::Cmp {
                lhs: expr(a)?,
                op: match op {
                    CmpOp::Lt => rob::CmpOp::Lt,
                    CmpOp::Le => rob::CmpOp::Le,
                    CmpOp::Gt => rob::CmpOp::Gt,
                    CmpOp::Ge => rob::CmpOp::Ge,
                },
                rhs: expr(b)?,
            },
            CFormulaKind::Not(a) => rob::Formula::Not(boxed(a)?),
            CFormulaKind::And(v) => rob::Formula::And(all(v)?),
            CFormulaKind::Or(v) => rob::Formula::Or(all(v)?),
            CFormulaKind::Implies(a, b) => rob::Formula::Implies(boxed(a)?, boxed(b)?),
            CFormulaKind::Always(iv, a) => rob::Formula::Always(interval(iv), boxed(a)?),
            CFormulaKind::Eventually(iv, a) => rob::Formula::Eventually(interval(iv), boxed(a)?),
            CFormulaKind::Until(iv, a, b) => {
                rob::Formula::Until(interval(iv), boxed(a)?, boxed(b)?)
            }
            CFormulaKind::Invalid => return None,
        })
    }
}
