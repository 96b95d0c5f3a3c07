//! `rho(f, 0)` kept up to date as an episode grows by one state at a time ([`Running`]):
//! the formula's boolean skeleton as parts, each updated by the cheapest rule its shape
//! allows (see the module docs of [`super`]), and the states kept as columns.

use hstl_robustness::{
    Bound, Evaluator, Formula, FormulaBuilder, Interval, Node, NodeId, OnlineMonitor, WindowStream,
};

use super::program::Program;

/// `rho(f, 0)` over a trace that grows by one state at a time: the formula's boolean
/// skeleton as a list of parts, each reading earlier ones (a shared subformula is one
/// part), so a push is one forward pass.
#[derive(Clone, Debug)]
pub(super) struct Running {
    parts: Vec<Part>,
    /// Each part's value after the last push.
    values: Vec<f64>,
}

/// One part of a [`Running`]; the combinators name earlier parts by index.
#[derive(Clone, Debug)]
enum Part {
    /// A part evaluated over the states so far, fixed once its horizon has passed.
    Whole {
        formula: Formula,
        horizon: Option<usize>,
        states: Columns,
        fixed: Option<f64>,
    },
    /// `always[I] f` (`min`) or `eventually[I] f` (`max`) with `f` of finite horizon `h`:
    /// `f`'s online monitor gives its value at a position once final, folded in then, and
    /// the values of the last `h` positions as if the trace ended now, `O(h |f|)` a step.
    /// A past-time operator in `f` reads the earlier states from what its streams keep.
    Window {
        always: bool,
        interval: Interval,
        horizon: usize,
        /// `f`'s online monitor.
        monitor: Box<OnlineMonitor>,
        /// The fold of the final values of `f` in the window.
        settled: f64,
    },
    /// `always[I] f` (`min`) or `eventually[I] f` (`max`) with `f` a state formula: the
    /// value of `f` at a position is final when its state arrives, so the fold of those in
    /// the window is the value, `O(|f|)` a step and nothing kept.
    Fold {
        always: bool,
        /// The positions the window holds in a trace of any length.
        window: std::ops::Range<usize>,
        /// The slot of `f` on the last state, as the offline evaluator computes it.
        body: usize,
        /// The fold of `f` over the positions so far in the window.
        settled: f64,
    },
    /// `always[c..] g` (`min`) or `eventually[c..] g` (`max`), `g` being
    /// `eventually[I] f` or `always[I] f` (the other operator) with `f` a state formula:
    /// the persistent task's shape, `O(1)` amortised a step. The positions whose value of
    /// `g` is final come from the sliding window of `g` over the values of `f` (the online
    /// monitor's stream of `g`); every other position's window is clipped at the end of
    /// the trace to a suffix of it, and of those suffixes the latest position's (`g` on the
    /// last state alone) is the least for `always` over `eventually` (the greatest for the
    /// dual), so it alone stands for them. With `I` unbounded (`always[0..] eventually[0..]
    /// f`, "infinitely often") no position's value is ever final, and the latest stands
    /// for all: `O(1)` a step, nothing kept.
    Stream {
        always: bool,
        /// The outer operator's first offset `c`.
        from: usize,
        /// The slot of `g` on the last state alone.
        body: usize,
        /// The slot of `f` on the last state.
        inner: usize,
        /// `g`'s final values, in order; `None` when `I` is unbounded (none is final).
        window: Option<WindowStream>,
        /// The fold of the final values of `g` at positions from `c` on.
        settled: f64,
    },
    Not(usize),
    And(Vec<usize>),
    Or(Vec<usize>),
    Implies(usize, usize),
}

/// States kept as columns, the oldest dropped from the front in amortised `O(1)`.
#[derive(Clone, Debug)]
pub(super) struct Columns {
    columns: Vec<Vec<f64>>,
    /// Index of the first live state in every column.
    start: usize,
}

impl Running {
    /// The parts of `f`: its `!`, `&&`, `||` and `->` (and `always` over `&&`, `eventually`
    /// over `||`, which distribute) split down to the parts [`Part::leaf`] shapes, with an
    /// explicit stack, each distinct subformula once.
    pub(super) fn new(f: &Formula, vars: usize, slots: &mut Vec<(Formula, bool)>) -> Running {
        let mut b = FormulaBuilder::new();
        let root = b.formula(f);
        let mut index: std::collections::HashMap<NodeId, usize> = Default::default();
        let mut parts: Vec<Part> = Vec::new();
        // (node, whether its operands are done)
        let mut stack = vec![(root, false)];
        while let Some((v, ready)) = stack.pop() {
            if index.contains_key(&v) {
                continue;
            }
            let ops = operands(&mut b, v);
            if !ready {
                stack.push((v, true));
                for &g in ops.iter().flatten().rev() {
                    if !index.contains_key(&g) {
                        stack.push((g, false));
                    }
                }
                continue;
            }
            let at = |g: &NodeId| index[g];
            let part = match (b.node(v), ops) {
                (Node::Not(_), Some(gs)) => Part::Not(at(&gs[0])),
                (Node::Implies(..), Some(gs)) => Part::Implies(at(&gs[0]), at(&gs[1])),
                (Node::And(_) | Node::Always(..), Some(gs)) => {
                    Part::And(gs.iter().map(at).collect())
                }
                (Node::Or(_) | Node::Eventually(..), Some(gs)) => {
                    Part::Or(gs.iter().map(at).collect())
                }
                _ => Part::leaf(&b.build(v), vars, slots),
            };
            index.insert(v, parts.len());
            parts.push(part);
        }
        let values = vec![f64::NAN; parts.len()];
        Running { parts, values }
    }

    pub(super) fn reset(&mut self) {
        self.parts.iter_mut().for_each(Part::reset);
    }

    /// Takes state number `n - 1` (so `n` states are in) and gives `rho(f, 0)` over them.
    pub(super) fn push(&mut self, state: &[f64], n: usize, ctx: &mut Context<'_>) -> f64 {
        for k in 0..self.parts.len() {
            let v = self.parts[k].push(state, n, ctx, &self.values);
            self.values[k] = v;
        }
        self.values.last().copied().unwrap_or(f64::NAN)
    }
}

/// The nodes `v` splits into for [`Running`] (`None`: `v` is a leaf part). `always[I]` over
/// `&&` becomes the `&&` of `always[I]` over each conjunct (and `eventually[I]` over `||`
/// the `||`), new nodes added to `b`.
fn operands(b: &mut FormulaBuilder, v: NodeId) -> Option<Vec<NodeId>> {
    match b.node(v).clone() {
        Node::Not(g) => Some(vec![g]),
        Node::And(gs) | Node::Or(gs) => Some(gs),
        Node::Implies(g, h) => Some(vec![g, h]),
        Node::Always(i, body) | Node::Eventually(i, body) => {
            let always = matches!(b.node(v), Node::Always(..));
            let gs = match (b.node(body), always) {
                (Node::And(gs), true) | (Node::Or(gs), false) => gs.clone(),
                _ => return None,
            };
            let ids = gs
                .into_iter()
                .map(|g| if always { b.always(i, g) } else { b.eventually(i, g) })
                .collect();
            Some(ids)
        }
        _ => None,
    }
}

impl Part {
    /// The leaf part of `f`, the cheapest shape its form allows.
    pub(super) fn leaf(f: &Formula, vars: usize, slots: &mut Vec<(Formula, bool)>) -> Part {
        let whole = || Part::Whole {
            formula: f.clone(),
            horizon: f.horizon(),
            states: Columns::new(vars),
            fixed: None,
        };
        match f.root_node() {
            Node::Always(interval, body) | Node::Eventually(interval, body)
                if interval.end == Bound::Unbounded && is_dual_over_state(f) =>
            {
                let always = matches!(f.root_node(), Node::Always(..));
                let body = f.sub(*body);
                let (inner_always, j, inner) = match body.root_node() {
                    Node::Always(j, g) => (true, *j, body.sub(*g)),
                    Node::Eventually(j, g) => (false, *j, body.sub(*g)),
                    _ => return whole(),
                };
                let window = WindowStream::new(inner_always, &j);
                slots.push((body, false));
                slots.push((inner, false));
                Part::Stream {
                    always,
                    from: interval.start,
                    body: slots.len() - 2,
                    inner: slots.len() - 1,
                    window,
                    settled: identity(always),
                }
            }
            // A state formula's value at a position is final at once.
            Node::Always(interval, body) | Node::Eventually(interval, body)
                if f.is_state(*body) && !f.has_past() =>
            {
                let always = matches!(f.root_node(), Node::Always(..));
                slots.push((f.sub(*body), true));
                Part::Fold {
                    always,
                    window: interval.window(0, usize::MAX),
                    body: slots.len() - 1,
                    settled: identity(always),
                }
            }
            Node::Always(interval, body) | Node::Eventually(interval, body) => {
                match f.horizon_of(*body) {
                    Some(horizon) => Part::Window {
                        always: matches!(f.root_node(), Node::Always(..)),
                        interval: *interval,
                        horizon,
                        // The episode keeps every state anyway; the monitor keeps the last
                        // `h` and what its past windows need, no more.
                        monitor: Box::new(
                            OnlineMonitor::new(&f.sub(*body), vars).with_limit(usize::MAX),
                        ),
                        settled: identity(matches!(f.root_node(), Node::Always(..))),
                    },
                    None => whole(),
                }
            }
            _ => whole(),
        }
    }

    pub(super) fn reset(&mut self) {
        match self {
            Part::Whole { states, fixed, .. } => {
                states.clear();
                *fixed = None;
            }
            Part::Window { always, settled, monitor, .. } => {
                *settled = identity(*always);
                monitor.reset();
            }
            Part::Fold { always, settled, .. } => *settled = identity(*always),
            Part::Stream { always, window, settled, .. } => {
                if let Some(window) = window {
                    window.clear();
                }
                *settled = identity(*always);
            }
            Part::Not(_) | Part::And(_) | Part::Or(_) | Part::Implies(..) => {}
        }
    }

    /// Takes state number `n - 1` (so `n` states are in) and gives `rho(f, 0)` over them,
    /// as the reference evaluator combines it; `values` holds the earlier parts' values.
    pub(super) fn push(
        &mut self,
        state: &[f64],
        n: usize,
        ctx: &mut Context<'_>,
        values: &[f64],
    ) -> f64 {
        let eval = &mut *ctx.eval;
        match self {
            Part::Whole { formula, horizon, states, fixed } => {
                if let Some(v) = fixed {
                    return *v;
                }
                states.push(state);
                let value =
                    eval.robustness_of_slices(formula, &states.slices()).unwrap_or(f64::NAN);
                if horizon.is_some_and(|h| n > h) {
                    // Every state the value can read has arrived.
                    *fixed = Some(value);
                    states.clear();
                }
                value
            }
            Part::Window { always, interval, horizon, monitor, settled } => {
                let fold = |a: f64, b: f64| if *always { a.min(b) } else { a.max(b) };
                // The state has the monitor's width (checked by the caller) and the monitor
                // no limit: it gives no error.
                if let Ok(Some(verdict)) = monitor.push(state)
                    && interval.window(0, usize::MAX).contains(&verdict.step)
                {
                    *settled = fold(*settled, verdict.value);
                }
                // The positions without a final value, clipped at the trace's end.
                let open = n.saturating_sub(*horizon)..n;
                let now = interval.window(0, n);
                let mut value = *settled;
                if now.start < open.end && open.start < now.end {
                    for (i, v) in monitor.open_values().into_iter().enumerate() {
                        if now.contains(&(open.start + i)) {
                            value = fold(value, v);
                        }
                    }
                }
                value
            }
            Part::Fold { always, window, body, settled } => {
                if window.contains(&(n - 1)) {
                    let v = ctx.program.value(*body);
                    *settled = if *always { settled.min(v) } else { settled.max(v) };
                }
                *settled
            }
            Part::Stream { always, from, body, inner, window, settled } => {
                let fold = |a: f64, b: f64| if *always { a.min(b) } else { a.max(b) };
                // The state has no NaN (checked by the caller).
                if let Some(verdict) =
                    window.as_mut().and_then(|w| w.push(ctx.program.value(*inner)))
                    && verdict.step >= *from
                {
                    *settled = fold(*settled, verdict.value);
                }
                if n <= *from {
                    // No position of the outer window has arrived.
                    return *settled;
                }
                fold(*settled, ctx.program.value(*body))
            }
            Part::Not(g) => -values[*g],
            Part::And(gs) => gs.iter().map(|g| values[*g]).fold(f64::INFINITY, f64::min),
            Part::Or(gs) => gs.iter().map(|g| values[*g]).fold(f64::NEG_INFINITY, f64::max),
            Part::Implies(g, h) => (-values[*g]).max(values[*h]),
        }
    }
}

/// What a part's push reads besides the state: the program's values on it, and the
/// evaluator of the parts evaluated over the states so far.
pub(super) struct Context<'a> {
    pub(super) program: &'a Program,
    pub(super) eval: &'a mut Evaluator,
}

/// Whether `f` is `always[I] eventually[J] g` or `eventually[I] always[J] g` with `g` a
/// state formula (no temporal operator): what [`Part::Stream`] takes.
fn is_dual_over_state(f: &Formula) -> bool {
    let inner = match f.root_node() {
        Node::Always(_, body) => match &f[*body] {
            Node::Eventually(j, g) => Some((j, g)),
            _ => None,
        },
        Node::Eventually(_, body) => match &f[*body] {
            Node::Always(j, g) => Some((j, g)),
            _ => None,
        },
        _ => None,
    };
    inner.is_some_and(|(_, g)| f.is_state(*g))
}

/// The value of an empty window: `+inf` for `always`, `-inf` for `eventually`.
fn identity(always: bool) -> f64 {
    if always { f64::INFINITY } else { f64::NEG_INFINITY }
}

impl Columns {
    pub(super) fn new(vars: usize) -> Columns {
        Columns { columns: vec![Vec::new(); vars], start: 0 }
    }

    pub(super) fn push(&mut self, state: &[f64]) {
        for (column, &v) in self.columns.iter_mut().zip(state) {
            column.push(v);
        }
    }

    pub(super) fn pop_front(&mut self) {
        self.start += 1;
        let len = self.columns.first().map_or(0, Vec::len);
        // Drop the dead front once it is as long as the live part: amortised O(1).
        if self.start * 2 >= len && self.start > 0 {
            for column in &mut self.columns {
                column.drain(..self.start);
            }
            self.start = 0;
        }
    }

    pub(super) fn clear(&mut self) {
        self.columns.iter_mut().for_each(Vec::clear);
        self.start = 0;
    }

    /// The number of live states.
    pub(super) fn len(&self) -> usize {
        self.columns.first().map_or(0, |c| c.len() - self.start)
    }

    pub(super) fn slices(&self) -> Vec<&[f64]> {
        self.columns.iter().map(|c| &c[self.start..]).collect()
    }
}
