//! The checked spec: names resolved to indices, defaults filled in, the options set
//! expanded. Formula and expression nodes keep their byte ranges.

use std::ops::Range;

pub use crate::syntax::VarType;

/// A checked formula node.
#[derive(Clone, Debug, PartialEq)]
pub struct CFormula {
    /// What it is.
    pub kind: CFormulaKind,
    /// Byte range in the source.
    pub range: Range<usize>,
}

/// A comparison operator (`==` and `!=` are rejected before this point).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CmpOp {
    /// `<`.
    Lt,
    /// `<=`.
    Le,
    /// `>`.
    Gt,
    /// `>=`.
    Ge,
}

/// The end of a time interval.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// `[a..]`.
    Unbounded,
    /// `[a..b]`: b itself is excluded.
    Exclusive(u64),
    /// `[a..=b]`: b itself is included.
    Inclusive(u64),
}

/// A checked time interval (non-empty).
#[derive(Clone, Debug, PartialEq)]
pub struct Interval {
    /// First step offset.
    pub start: u64,
    /// End bound.
    pub end: Bound,
    /// Byte range of `[...]`; `None` when the interval was omitted (`[0..]`).
    pub range: Option<Range<usize>>,
}

/// The kinds of checked formula.
#[derive(Clone, Debug, PartialEq)]
pub enum CFormulaKind {
    /// `true`.
    True,
    /// `false`.
    False,
    /// A reference to the `let` with this index.
    Let(usize),
    /// `lhs op rhs` (a chained comparison becomes an `And` of these).
    Cmp(CmpOp, CExpr, CExpr),
    /// `!f`.
    Not(Box<CFormula>),
    /// Conjunction of two or more formulas.
    And(Vec<CFormula>),
    /// Disjunction of two or more formulas.
    Or(Vec<CFormula>),
    /// `f -> g`.
    Implies(Box<CFormula>, Box<CFormula>),
    /// `always[I] f`.
    Always(Interval, Box<CFormula>),
    /// `eventually[I] f`.
    Eventually(Interval, Box<CFormula>),
    /// `f until[I] g`.
    Until(Interval, Box<CFormula>, Box<CFormula>),
    /// `once[I] f`: the maximum over the past window.
    Once(Interval, Box<CFormula>),
    /// `historically[I] f`: the minimum over the past window.
    Historically(Interval, Box<CFormula>),
    /// `f since[I] g`.
    Since(Interval, Box<CFormula>, Box<CFormula>),
    /// `prev f`: `f` one step back, `+inf` at the first step.
    Prev(Box<CFormula>),
    /// `next f`: `f` one step ahead, `+inf` at the last step.
    Next(Box<CFormula>),
    /// Stands for a part that did not check; only present when an error was reported.
    Invalid,
}

impl CFormulaKind {
    /// Whether this node is a temporal operator (future or past), which needs a trace.
    pub fn is_temporal(&self) -> bool {
        matches!(
            self,
            CFormulaKind::Always(..)
                | CFormulaKind::Eventually(..)
                | CFormulaKind::Until(..)
                | CFormulaKind::Once(..)
                | CFormulaKind::Historically(..)
                | CFormulaKind::Since(..)
                | CFormulaKind::Prev(..)
                | CFormulaKind::Next(..)
        )
    }
}

/// A checked expression node.
#[derive(Clone, Debug, PartialEq)]
pub struct CExpr {
    /// What it is.
    pub kind: CExprKind,
    /// Byte range in the source.
    pub range: Range<usize>,
}

/// The kinds of checked expression.
#[derive(Clone, Debug, PartialEq)]
pub enum CExprKind {
    /// A constant.
    Const(f64),
    /// The state variable with this index.
    Var(usize),
    /// `-e`.
    Neg(Box<CExpr>),
    /// `a + b`.
    Add(Box<CExpr>, Box<CExpr>),
    /// `a - b`.
    Sub(Box<CExpr>, Box<CExpr>),
    /// `a * b`.
    Mul(Box<CExpr>, Box<CExpr>),
    /// `a / b`.
    Div(Box<CExpr>, Box<CExpr>),
    /// `abs(e)`.
    Abs(Box<CExpr>),
    /// `sqrt(e)`.
    Sqrt(Box<CExpr>),
    /// Stands for a part that did not check; only present when an error was reported.
    Invalid,
}

/// The set of values a state variable ranges over.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Domain {
    /// No range declared.
    Unbounded,
    /// `int in lo..=hi` (a `lo..hi` range is stored as `lo..=hi-1`); never empty.
    Int {
        /// Smallest value.
        lo: i64,
        /// Largest value.
        hi: i64,
    },
    /// `float in lo..hi` or `lo..=hi`.
    Float {
        /// Lower bound.
        lo: f64,
        /// Upper bound.
        hi: f64,
        /// Whether `hi` is included.
        inclusive: bool,
    },
}

/// A state variable.
#[derive(Clone, Debug, PartialEq)]
pub struct StateVarInfo {
    /// Name.
    pub name: String,
    /// Declared type.
    pub ty: VarType,
    /// Declared domain.
    pub domain: Domain,
    /// Doc comment text.
    pub doc: Option<String>,
    /// Byte range of the name.
    pub name_range: Range<usize>,
    /// Byte range of the declaration.
    pub range: Range<usize>,
}

/// Whether a `let` is evaluated on one state or on a trace.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LetKind {
    /// No temporal operator, also not through other lets: usable as a region.
    State,
    /// Contains a temporal operator, future or past (directly or through other lets).
    Temporal,
}

/// A `let`.
#[derive(Clone, Debug, PartialEq)]
pub struct LetInfo {
    /// Name.
    pub name: String,
    /// The resolved definition.
    pub formula: CFormula,
    /// State formula or temporal.
    pub kind: LetKind,
    /// Whether the task or an option uses it (directly or through used lets).
    pub used: bool,
    /// Doc comment text.
    pub doc: Option<String>,
    /// Byte range of the name.
    pub name_range: Range<usize>,
    /// Byte range of the item.
    pub range: Range<usize>,
}

/// The task.
#[derive(Clone, Debug, PartialEq)]
pub struct TaskInfo {
    /// The resolved formula.
    pub formula: CFormula,
    /// Doc comment text.
    pub doc: Option<String>,
    /// Byte range of the item.
    pub range: Range<usize>,
}

/// Where a primitive option stops.
#[derive(Clone, Debug, PartialEq)]
pub enum Terminate {
    /// In the states where `rho(reach, s)` is largest over the declared domain.
    Argmax,
    /// In the states that satisfy this formula.
    Formula(CFormula),
}

/// A primitive option.
#[derive(Clone, Debug, PartialEq)]
pub struct PrimitiveOption {
    /// Name.
    pub name: String,
    /// The state formula whose robustness is the flat reward.
    pub reach: CFormula,
    /// Where the option may start (`true` by default).
    pub init: CFormula,
    /// Where it stops (`argmax` by default).
    pub terminate: Terminate,
    /// A region the leg must stay out of (`avoid: R`): its flat reward sees `rho(!R)` and it
    /// stops on entering `R`. `None` by default.
    pub avoid: Option<CFormula>,
    /// Doc comment text.
    pub doc: Option<String>,
    /// Byte range of the name.
    pub name_range: Range<usize>,
    /// Byte range of the item.
    pub range: Range<usize>,
}

/// A member of the options set: a sequence of primitive options.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CombinedOption {
    /// The concatenated leg names, such as `AB`.
    pub name: String,
    /// Indices into [`CheckedSpec::primitives`], in running order.
    pub sequence: Vec<usize>,
    /// Byte range of the source that produced it (the list entry, or the `options` item).
    pub range: Range<usize>,
}

/// How intra-option updates credit suffixes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Intra {
    /// Every suffix to the executed option (the paper).
    Paper,
    /// A suffix to the option made of the remaining legs, when it is in the set.
    Remaining,
}

/// When a greedy run of the learned policy chooses an option.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Switch {
    /// When the running option terminates (the paper).
    Termination,
    /// At every step: the options policy's pick replaces a different running option.
    Step,
}

/// How a trained policy's options values are obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plan {
    /// Q-learned (the paper).
    Off,
    /// Planned after training over the memory's counters and a model of the learned legs.
    Model,
}

/// The options-level reward.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reward {
    /// Robustness of the task over the option's segment (the paper).
    Segment,
    /// Discounted count of kept windows.
    Window,
}

/// The configuration a `learn { preset: ... }` starts from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Preset {
    /// The paper's settings (the default): nothing is filled in.
    #[default]
    Paper,
    /// The recommended settings for the task's form (LANGUAGE.md, "Presets").
    Auto,
}

/// Q-learning parameters of one level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QParams {
    /// Discount factor, in (0, 1].
    pub gamma: f64,
    /// Learning rate, in (0, 1].
    pub alpha: f64,
    /// Initial exploration rate.
    pub epsilon: f64,
    /// Exploration floor.
    pub min_epsilon: f64,
    /// Linear decay of epsilon per step (flat) or per choice (options).
    pub decay: f64,
}

/// Learning parameters with the paper's defaults filled in.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LearnParams {
    /// The preset the parameters start from (`paper`).
    pub preset: Preset,
    /// Episodes (1200).
    pub episodes: u64,
    /// Option choices per episode (200).
    pub choices: u64,
    /// Steps after which a running option is cut off (500).
    pub max_steps: u64,
    /// Memory buckets, 0 = off (0).
    pub memory: u64,
    /// Intra-option credit (`paper`).
    pub intra: Intra,
    /// Options-level reward (`segment`).
    pub reward: Reward,
    /// Counterfactual memory values per option execution, 0 = off (0).
    pub counterfactual: u64,
    /// When a greedy run chooses an option (`termination`).
    pub switch: Switch,
    /// How the options values are obtained (`off`: Q-learned).
    pub plan: Plan,
    /// Flat level (gamma 0.9, alpha 0.2, epsilon 0.8, min_epsilon 0.1, decay 1e-6).
    pub flat: QParams,
    /// Options level (gamma 0.9, alpha 0.5, epsilon 0.8, min_epsilon 0.1, decay 1e-4).
    pub options: QParams,
    /// The tile coding of a continuous state (`tiles: { ... }`); `None`: tables. A spec
    /// with options over a `float` state always has one.
    pub tiles: Option<Tiles>,
}

/// `learn { tiles: { tilings: 8, bins: 14 } }`: the approximate learner's tile coding.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tiles {
    /// Offset tilings (8).
    pub tilings: u64,
    /// Tiles along every state variable; `None`: from the world (a tile about one step
    /// wide on a plane world), else 10.
    pub bins: Option<u64>,
}

/// A [`Tiles`] laid over the spec's domain box: what the approximate learner codes.
#[derive(Clone, Debug, PartialEq)]
pub struct TileBox {
    /// Offset tilings.
    pub tilings: u64,
    /// Tiles along each state variable, in declaration order.
    pub bins: Vec<u64>,
    /// Each variable's lower bound.
    pub lo: Vec<f64>,
    /// Each variable's upper bound.
    pub hi: Vec<f64>,
}

/// Tiles along a `float` variable when neither the spec nor the world says how many.
pub const DEFAULT_BINS: u64 = 10;

impl Default for Tiles {
    fn default() -> Tiles {
        Tiles { tilings: 8, bins: None }
    }
}

impl Default for LearnParams {
    fn default() -> Self {
        LearnParams {
            preset: Preset::Paper,
            episodes: 1200,
            choices: 200,
            max_steps: 500,
            memory: 0,
            intra: Intra::Paper,
            reward: Reward::Segment,
            counterfactual: 0,
            switch: Switch::Termination,
            plan: Plan::Off,
            flat: QParams { gamma: 0.9, alpha: 0.2, epsilon: 0.8, min_epsilon: 0.1, decay: 1e-6 },
            options: QParams {
                gamma: 0.9,
                alpha: 0.5,
                epsilon: 0.8,
                min_epsilon: 0.1,
                decay: 1e-4,
            },
            tiles: None,
        }
    }
}

/// One spec after checking.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckedSpec {
    /// Name.
    pub name: String,
    /// Doc comment text.
    pub doc: Option<String>,
    /// Byte range of the name.
    pub name_range: Range<usize>,
    /// Byte range of the spec.
    pub range: Range<usize>,
    /// State variables, in declaration order (a valuation lists values in this order).
    pub state_vars: Vec<StateVarInfo>,
    /// Lets, in declaration order.
    pub lets: Vec<LetInfo>,
    /// Let indices in an order where every let comes after the lets it uses (lets in a
    /// cycle are left out).
    pub let_order: Vec<usize>,
    /// The task; `None` only when an error was reported.
    pub task: Option<TaskInfo>,
    /// Primitive options, in declaration order.
    pub primitives: Vec<PrimitiveOption>,
    /// The expanded options set.
    pub options: Vec<CombinedOption>,
    /// Learning parameters.
    pub learn: LearnParams,
    /// What `learn { preset: auto }` filled in, as hstl text (one line per option, the
    /// options set and the `learn` values), for `hstlc check` and the editor's hover;
    /// `None` for the paper's preset.
    pub preset_expansion: Option<String>,
    /// The world the spec names with `world "...";`, if any.
    pub world: Option<WorldRef>,
    /// The time variable (`t: time`), which makes the spec a dense-time spec; `None` for a
    /// discrete-time spec. It is not one of [`CheckedSpec::state_vars`]: its trace column
    /// holds the time stamps, and no formula reads it.
    pub time: Option<TimeVarInfo>,
    /// How the intervals' bounds read as times in a dense-time spec: every bound of
    /// [`Interval`] counts `10^-time_decimals` of the time column's unit (with one decimal,
    /// `[0..=2.5]` is stored as `[0..=25]`). The largest number of decimals any bound is
    /// written with; always 0 in a discrete-time spec.
    pub time_decimals: u32,
}

/// The time variable of a dense-time spec (`t: time`).
#[derive(Clone, Debug, PartialEq)]
pub struct TimeVarInfo {
    /// Name: the trace column that holds the time stamps.
    pub name: String,
    /// Doc comment text.
    pub doc: Option<String>,
    /// Byte range of the name.
    pub name_range: Range<usize>,
    /// Byte range of the declaration.
    pub range: Range<usize>,
}

/// The world a spec names: `world "four-rooms";` or `world "maps/yard.toml";`.
#[derive(Clone, Debug, PartialEq)]
pub struct WorldRef {
    /// A built-in world's name, or a world file's path relative to the spec file.
    pub name: String,
    /// Byte range of the string, quotes included.
    pub range: Range<usize>,
}

/// One conjunct `eventually[0..N] R` of a persistent task.
#[derive(Clone, Debug, PartialEq)]
pub struct PersistentConjunct {
    /// The region's name: the `let` name, or the source text of the formula.
    pub name: String,
    /// The `let` it names, if it is a plain reference.
    pub let_index: Option<usize>,
    /// The region formula.
    pub region: CFormula,
    /// Steps in the window: 40 for `[0..40]`, 41 for `[0..=40]`.
    pub steps: u64,
    /// A safety conjunct `always[0..] !R` beside the persistent part, as the region `!R`
    /// with a window of one step: it holds at a step exactly when `R` does not.
    pub safety: bool,
}

impl CheckedSpec {
    /// Whether the spec is a dense-time spec: it declares a time variable (`t: time`), its
    /// traces are time-stamped and its intervals are in the time column's unit.
    pub fn is_dense(&self) -> bool {
        self.time.is_some()
    }

    /// The time an interval bound stands for in a dense-time spec, as written (`25` with
    /// one decimal is `"2.5"`); the bound itself in a discrete-time spec.
    pub fn bound_text(&self, n: u64) -> String {
        let d = self.time_decimals as usize;
        if d == 0 {
            return n.to_string();
        }
        let digits = format!("{n:0>width$}", width = d + 1);
        let (int, frac) = digits.split_at(digits.len() - d);
        let frac = frac.trim_end_matches('0');
        if frac.is_empty() { int.to_string() } else { format!("{int}.{frac}") }
    }

    /// The spec's tile coding over its domain box: `bins` tiles along every variable when
    /// given; else one tile per value of an `int` variable (at most 64) and
    /// [`DEFAULT_BINS`] along a `float` one (training narrows that to the world's step).
    /// `None` without `tiles` or with an unbounded variable.
    pub fn tile_box(&self) -> Option<TileBox> {
        self.tile_box_of(self.learn.tiles?)
    }

    /// [`CheckedSpec::tile_box`] with the tile coding `t`.
    pub fn tile_box_of(&self, t: Tiles) -> Option<TileBox> {
        let mut b =
            TileBox { tilings: t.tilings, bins: Vec::new(), lo: Vec::new(), hi: Vec::new() };
        for v in &self.state_vars {
            let (lo, hi, n) = match v.domain {
                Domain::Int { lo, hi } => (lo as f64, hi as f64, (hi - lo).clamp(1, 64) as u64),
                Domain::Float { lo, hi, .. } => (lo, hi, DEFAULT_BINS),
                Domain::Unbounded => return None,
            };
            b.lo.push(lo);
            b.hi.push(hi);
            b.bins.push(t.bins.unwrap_or(n));
        }
        Some(b)
    }

    /// Whether some state variable is a `float`: the state is continuous, and options over
    /// it are learned with tilings.
    pub fn is_continuous(&self) -> bool {
        self.state_vars.iter().any(|v| v.ty == VarType::Float)
    }

    /// For a task `always[0..] (eventually[0..N1] R1 && ... && eventually[0..Nk] Rk)` with
    /// state formulas Rj, the conjuncts in order; `None` for any other task. Beside it, at
    /// the top level, safety conjuncts `always[0..] !S` with `S` a state formula may stand
    /// (`always[0..] (...) && always[0..] !S`, which is `always[0..] (... && !S)`): each is
    /// one more conjunct, the region `!S` with a window of one step, after the others.
    pub fn persistent_conjuncts(&self, src: &str) -> Option<Vec<PersistentConjunct>> {
        let task = self.task.as_ref()?;
        let (persistent, safety) = match &task.formula.kind {
            CFormulaKind::And(parts) => {
                let is_persistent = |f: &CFormula| self.persistent_part(f, src).is_some();
                let mut found = parts.iter().filter(|f| is_persistent(f));
                let (Some(p), None) = (found.next(), found.next()) else { return None };
                let rest: Vec<&CFormula> = parts.iter().filter(|f| !std::ptr::eq(*f, p)).collect();
                (p, rest)
            }
            _ => (&task.formula, Vec::new()),
        };
        let mut out = self.persistent_part(persistent, src)?;
        for c in safety {
            let CFormulaKind::Always(iv, body) = &c.kind else { return None };
            let CFormulaKind::Not(r) = &body.kind else { return None };
            if iv.start != 0 || iv.end != Bound::Unbounded || !self.is_state_formula(r) {
                return None;
            }
            let name = src.get(body.range.clone()).unwrap_or("").trim().to_string();
            out.push(PersistentConjunct {
                name,
                let_index: None,
                region: (**body).clone(),
                steps: 1,
                safety: true,
            });
        }
        Some(out)
    }

    /// The conjuncts of `always[0..] (eventually[0..N1] R1 && ...)`, or `None`.
    fn persistent_part(&self, f: &CFormula, src: &str) -> Option<Vec<PersistentConjunct>> {
        let CFormulaKind::Always(iv, body) = &f.kind else { return None };
        if iv.start != 0 || iv.end != Bound::Unbounded {
            return None;
        }
        let parts: Vec<&CFormula> = match &body.kind {
            CFormulaKind::And(parts) => parts.iter().collect(),
            _ => vec![body.as_ref()],
        };
        let mut out = Vec::new();
        for part in parts {
            let CFormulaKind::Eventually(iv, region) = &part.kind else { return None };
            let steps = match iv.end {
                Bound::Exclusive(b) => b,
                Bound::Inclusive(b) => b.checked_add(1)?,
                Bound::Unbounded => return None,
            };
            if iv.start != 0 || steps == 0 || !self.is_state_formula(region) {
                return None;
            }
            let (name, let_index) = match region.kind {
                CFormulaKind::Let(i) => (self.lets.get(i)?.name.clone(), Some(i)),
                _ => (src.get(region.range.clone()).unwrap_or("").trim().to_string(), None),
            };
            out.push(PersistentConjunct {
                name,
                let_index,
                region: (**region).clone(),
                steps,
                safety: false,
            });
        }
        Some(out)
    }

    /// Whether a formula has no temporal operator, also not through lets.
    pub fn is_state_formula(&self, f: &CFormula) -> bool {
        match &f.kind {
            kind if kind.is_temporal() => false,
            CFormulaKind::Invalid => false,
            CFormulaKind::Let(i) => self.lets.get(*i).is_some_and(|l| l.kind == LetKind::State),
            // `true`, `false` and comparisons have no operands: state formulas.
            _ => f.operands().into_iter().all(|g| self.is_state_formula(g)),
        }
    }

    /// Robustness of a state formula on one valuation (values in the order of
    /// [`CheckedSpec::state_vars`]); `None` for a temporal formula or a short valuation.
    pub fn state_robustness(&self, f: &CFormula, valuation: &[f64]) -> Option<f64> {
        if !self.is_state_formula(f) || valuation.len() < self.state_vars.len() {
            return None;
        }
        let mut ev = StateEvaluator::new(self, &[f]);
        ev.load(valuation);
        Some(ev.robustness(f, valuation))
    }

    /// The number of states of the declared domain, if every variable is a finite `int`
    /// (saturating at `u64::MAX`).
    pub fn domain_size(&self) -> Option<u64> {
        let mut n: u64 = 1;
        for v in &self.state_vars {
            let Domain::Int { lo, hi } = v.domain else { return None };
            let width = (hi as i128 - lo as i128 + 1).clamp(0, u64::MAX as i128) as u64;
            n = n.saturating_mul(width);
        }
        Some(n)
    }
}

/// Evaluates state formulas on one valuation at a time. The lets the given formulas
/// need are computed once per valuation, in dependency order, so evaluation never
/// recurses through chains of lets.
#[derive(Clone, Debug)]
pub struct StateEvaluator<'a> {
    spec: &'a CheckedSpec,
    needed: Vec<usize>,
    values: Vec<f64>,
}

impl<'a> StateEvaluator<'a> {
    /// Prepares to evaluate `formulas` (and any formula using only the lets they use).
    pub fn new(spec: &'a CheckedSpec, formulas: &[&CFormula]) -> Self {
        let mut mark = vec![false; spec.lets.len()];
        let mut stack: Vec<&CFormula> = formulas.to_vec();
        while let Some(f) = stack.pop() {
            visit_lets(f, &mut |i| {
                if i < mark.len() && !mark[i] {
                    mark[i] = true;
                    stack.push(&spec.lets[i].formula);
                }
            });
        }
        let needed = spec.let_order.iter().copied().filter(|&i| mark[i]).collect();
        StateEvaluator { spec, needed, values: vec![f64::NAN; spec.lets.len()] }
    }

    /// How many lets [`StateEvaluator::load`] computes per valuation.
    pub fn needed_lets(&self) -> usize {
        self.needed.len()
    }

    /// Computes the needed lets on `valuation`.
    pub fn load(&mut self, valuation: &[f64]) {
        for k in 0..self.needed.len() {
            let i = self.needed[k];
            let v = eval_formula(&self.spec.lets[i].formula, &self.values, valuation);
            self.values[i] = v;
        }
    }

    /// Robustness of `f` on the valuation last passed to [`StateEvaluator::load`].
    /// Temporal operators and invalid parts give NaN.
    pub fn robustness(&self, f: &CFormula, valuation: &[f64]) -> f64 {
        eval_formula(f, &self.values, valuation)
    }
}

impl CFormula {
    /// The formula's operands, in order (none for an atom or a `let` reference), so that
    /// a walk over formulas need not name every kind.
    pub fn operands(&self) -> Vec<&CFormula> {
        match &self.kind {
            CFormulaKind::Not(a)
            | CFormulaKind::Always(_, a)
            | CFormulaKind::Eventually(_, a)
            | CFormulaKind::Once(_, a)
            | CFormulaKind::Historically(_, a)
            | CFormulaKind::Prev(a)
            | CFormulaKind::Next(a) => vec![a],
            CFormulaKind::And(v) | CFormulaKind::Or(v) => v.iter().collect(),
            CFormulaKind::Implies(a, b)
            | CFormulaKind::Until(_, a, b)
            | CFormulaKind::Since(_, a, b) => vec![a, b],
            CFormulaKind::True
            | CFormulaKind::False
            | CFormulaKind::Let(_)
            | CFormulaKind::Cmp(..)
            | CFormulaKind::Invalid => Vec::new(),
        }
    }
}

/// Calls `visit` with every let index that `f` refers to directly.
pub fn visit_lets(f: &CFormula, visit: &mut dyn FnMut(usize)) {
    match &f.kind {
        CFormulaKind::Let(i) => visit(*i),
        _ => f.operands().into_iter().for_each(|g| visit_lets(g, visit)),
    }
}

fn eval_formula(f: &CFormula, lets: &[f64], s: &[f64]) -> f64 {
    match &f.kind {
        CFormulaKind::True => f64::INFINITY,
        CFormulaKind::False => f64::NEG_INFINITY,
        CFormulaKind::Let(i) => lets.get(*i).copied().unwrap_or(f64::NAN),
        CFormulaKind::Cmp(op, a, b) => {
            let (a, b) = (eval_expr(a, s), eval_expr(b, s));
            match op {
                CmpOp::Lt | CmpOp::Le => b - a,
                CmpOp::Gt | CmpOp::Ge => a - b,
            }
        }
        CFormulaKind::Not(a) => -eval_formula(a, lets, s),
        CFormulaKind::And(v) => {
            v.iter().map(|g| eval_formula(g, lets, s)).fold(f64::INFINITY, f64::min)
        }
        CFormulaKind::Or(v) => {
            v.iter().map(|g| eval_formula(g, lets, s)).fold(f64::NEG_INFINITY, f64::max)
        }
        CFormulaKind::Implies(a, b) => (-eval_formula(a, lets, s)).max(eval_formula(b, lets, s)),
        CFormulaKind::Always(..)
        | CFormulaKind::Eventually(..)
        | CFormulaKind::Until(..)
        | CFormulaKind::Once(..)
        | CFormulaKind::Historically(..)
        | CFormulaKind::Since(..)
        | CFormulaKind::Prev(..)
        | CFormulaKind::Next(..)
        | CFormulaKind::Invalid => f64::NAN,
    }
}

/// Value of an expression on one valuation (NaN for an invalid part or a missing value).
pub fn eval_expr(e: &CExpr, s: &[f64]) -> f64 {
    match &e.kind {
        CExprKind::Const(c) => *c,
        CExprKind::Var(i) => s.get(*i).copied().unwrap_or(f64::NAN),
        CExprKind::Neg(a) => -eval_expr(a, s),
        CExprKind::Add(a, b) => eval_expr(a, s) + eval_expr(b, s),
        CExprKind::Sub(a, b) => eval_expr(a, s) - eval_expr(b, s),
        CExprKind::Mul(a, b) => eval_expr(a, s) * eval_expr(b, s),
        CExprKind::Div(a, b) => eval_expr(a, s) / eval_expr(b, s),
        CExprKind::Abs(a) => eval_expr(a, s).abs(),
        CExprKind::Sqrt(a) => eval_expr(a, s).sqrt(),
        CExprKind::Invalid => f64::NAN,
    }
}
