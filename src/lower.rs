//! Lowering: a checked spec from [`hstl_lang`] becomes the runtime's plain data.
//!
//! This is the interpreter's path (the CLI, tools, tests); the `hstl!` macro emits the same
//! data as Rust code. `tests/lower_vs_macro.rs` holds the two paths against each other.
//! The runtime's formulas are DAGs without names: each `let` is lowered once into one node
//! that every use shares, so a formula's size is that of the spec, however the lets nest.
//! The lets a formula needs are found with an explicit stack and lowered in dependency
//! order; only one let's own body is walked recursively, and the parser bounds its height
//! ([`hstl_lang::parser::MAX_HEIGHT`]), so no chain of lets can exhaust the stack.

use std::fmt;

use hstl_lang::{
    Bound, CExpr, CExprKind, CFormula, CFormulaKind, CheckedSpec, CmpOp, Domain, Intra, Plan,
    Reward, Switch, Terminate,
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
    /// A dense-time spec (one with a `time` variable) asked for a discrete-time monitor,
    /// or a discrete-time spec for a dense-time one.
    TimeModel {
        /// The spec's name.
        spec: String,
        /// Whether the spec is the dense-time one.
        dense: bool,
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
            LowerError::TimeModel { spec, dense: true } => write!(
                f,
                "spec `{spec}` is a dense-time spec (it has a `time` variable): monitor it over \
                 time stamps, not steps"
            ),
            LowerError::TimeModel { spec, dense: false } => write!(
                f,
                "spec `{spec}` is a discrete-time spec (it has no `time` variable): its \
                 intervals count steps"
            ),
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
    let mut lower = Lowerer::new(spec);
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
        switch: match l.switch {
            Switch::Termination => rt::Switch::Termination,
            Switch::Step => rt::Switch::Step,
        },
        plan: match l.plan {
            Plan::Off => rt::Plan::Off,
            Plan::Model => rt::Plan::Model,
        },
        flat: level(&l.flat),
        options: level(&l.options),
        tiles: match &l.tiles {
            Some(_) => Some(tiles(spec).ok_or_else(invalid)?),
            None => None,
        },
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

/// The spec's tile coding as the runtime's data ([`CheckedSpec::tile_box`]).
pub fn tiles(spec: &CheckedSpec) -> Option<rt::TileParams> {
    let b = spec.tile_box()?;
    let bins = b.bins.iter().map(|&n| usize::try_from(n).ok()).collect::<Option<Vec<_>>>()?;
    Some(rt::TileParams { tilings: usize::try_from(b.tilings).ok()?, bins, lo: b.lo, hi: b.hi })
}

/// The task's formula.
pub fn task(spec: &CheckedSpec) -> Result<rob::Formula, LowerError> {
    spec.task
        .as_ref()
        .and_then(|t| Lowerer::new(spec).formula(&t.formula))
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
    Lowerer::new(spec)
        .formula(&l.formula)
        .ok_or_else(|| LowerError::Invalid { spec: spec.name.clone() })
}

/// Any checked formula of `spec`; `None` when part of it did not check.
pub fn formula(spec: &CheckedSpec, f: &CFormula) -> Option<rob::Formula> {
    Lowerer::new(spec).formula(f)
}

/// Any checked expression; `None` when part of it did not check.
pub fn expr(e: &CExpr) -> Option<rob::Expr> {
    let mut b = rob::FormulaBuilder::new();
    let id = lower_expr(&mut b, e)?;
    Some(b.build_expr(id))
}

/// `e` into `b`; recursive, but an expression is never taller than the parser's limit.
fn lower_expr(b: &mut rob::FormulaBuilder, e: &CExpr) -> Option<rob::ExprId> {
    Some(match &e.kind {
        CExprKind::Const(c) => b.constant(*c),
        CExprKind::Var(i) => b.var(*i),
        CExprKind::Neg(a) => {
            let a = lower_expr(b, a)?;
            b.neg(a)
        }
        CExprKind::Abs(a) => {
            let a = lower_expr(b, a)?;
            b.abs(a)
        }
        CExprKind::Sqrt(a) => {
            let a = lower_expr(b, a)?;
            b.sqrt(a)
        }
        CExprKind::Add(x, y)
        | CExprKind::Sub(x, y)
        | CExprKind::Mul(x, y)
        | CExprKind::Div(x, y) => {
            let (x, y) = (lower_expr(b, x)?, lower_expr(b, y)?);
            match e.kind {
                CExprKind::Add(..) => b.add_expr(x, y),
                CExprKind::Sub(..) => b.sub_expr(x, y),
                CExprKind::Mul(..) => b.mul_expr(x, y),
                _ => b.div_expr(x, y),
            }
        }
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

/// Lowers formulas of one spec into one builder, each `let` once.
struct Lowerer<'a> {
    spec: &'a CheckedSpec,
    b: rob::FormulaBuilder,
    /// The node of each lowered let; `None` when not lowered yet, on a cycle, or invalid.
    lets: Vec<Option<rob::NodeId>>,
    /// Whether each let was tried.
    tried: Vec<bool>,
}

impl<'a> Lowerer<'a> {
    fn new(spec: &'a CheckedSpec) -> Lowerer<'a> {
        let n = spec.lets.len();
        Lowerer { spec, b: rob::FormulaBuilder::new(), lets: vec![None; n], tried: vec![false; n] }
    }

    /// `f` as the runtime's formula; `None` when part of it (or of a let it uses) did not
    /// check.
    fn formula(&mut self, f: &CFormula) -> Option<rob::Formula> {
        self.prepare(f);
        let root = self.lower(f)?;
        Some(self.b.build(root))
    }

    /// Lowers every let `f` needs, directly or not, in dependency order: an explicit stack
    /// finds them, so a chain of lets as long as the spec costs no stack.
    fn prepare(&mut self, f: &CFormula) {
        let spec = self.spec;
        let mut need = vec![false; spec.lets.len()];
        let mut stack = vec![f];
        while let Some(g) = stack.pop() {
            hstl_lang::visit_lets(g, &mut |i| {
                if i < need.len() && !need[i] && !self.tried[i] {
                    need[i] = true;
                    stack.push(&spec.lets[i].formula);
                }
            });
        }
        // `let_order` leaves out the lets on a cycle: they stay `None`.
        for &i in &spec.let_order {
            if need.get(i).copied().unwrap_or(false) {
                self.tried[i] = true;
                self.lets[i] = self.lower(&spec.lets[i].formula);
            }
        }
    }

    /// `f` into the builder, its lets already lowered. Recursive over one formula only,
    /// whose height the parser bounds.
    fn lower(&mut self, f: &CFormula) -> Option<rob::NodeId> {
        let b = |s: &mut Self, g: &CFormula| s.lower(g);
        Some(match &f.kind {
            CFormulaKind::True => self.b.bool(true),
            CFormulaKind::False => self.b.bool(false),
            CFormulaKind::Let(i) => self.lets.get(*i).copied().flatten()?,
            CFormulaKind::Cmp(op, x, y) => {
                let (x, y) = (lower_expr(&mut self.b, x)?, lower_expr(&mut self.b, y)?);
                let op = match op {
                    CmpOp::Lt => rob::CmpOp::Lt,
                    CmpOp::Le => rob::CmpOp::Le,
                    CmpOp::Gt => rob::CmpOp::Gt,
                    CmpOp::Ge => rob::CmpOp::Ge,
                };
                self.b.cmp(x, op, y)
            }
            CFormulaKind::Not(a) => {
                let a = b(self, a)?;
                self.b.not(a)
            }
            CFormulaKind::And(v) | CFormulaKind::Or(v) => {
                let ids = v.iter().map(|g| self.lower(g)).collect::<Option<Vec<_>>>()?;
                if matches!(f.kind, CFormulaKind::And(_)) {
                    self.b.and(ids)
                } else {
                    self.b.or(ids)
                }
            }
            CFormulaKind::Implies(x, y) => {
                let (x, y) = (b(self, x)?, b(self, y)?);
                self.b.implies(x, y)
            }
            CFormulaKind::Always(iv, a) => {
                let a = b(self, a)?;
                self.b.always(interval(iv), a)
            }
            CFormulaKind::Eventually(iv, a) => {
                let a = b(self, a)?;
                self.b.eventually(interval(iv), a)
            }
            CFormulaKind::Until(iv, x, y) => {
                let (x, y) = (b(self, x)?, b(self, y)?);
                self.b.until(interval(iv), x, y)
            }
            CFormulaKind::Once(iv, a) => {
                let a = b(self, a)?;
                self.b.once(interval(iv), a)
            }
            CFormulaKind::Historically(iv, a) => {
                let a = b(self, a)?;
                self.b.historically(interval(iv), a)
            }
            CFormulaKind::Since(iv, x, y) => {
                let (x, y) = (b(self, x)?, b(self, y)?);
                self.b.since(interval(iv), x, y)
            }
            CFormulaKind::Prev(a) => {
                let a = b(self, a)?;
                self.b.prev(a)
            }
            CFormulaKind::Next(a) => {
                let a = b(self, a)?;
                self.b.next(a)
            }
            CFormulaKind::Invalid => return None,
        })
    }
}
