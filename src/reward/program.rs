//! The formulas a push reads off the newest state alone, in one pass over one flat DAG
//! ([`Program`]).

use hstl_robustness::{Formula, FormulaBuilder, Interval, Node, NodeId};

/// Formulas evaluated on the newest state alone in one pass over one DAG that holds them
/// all, each shared subformula once: a push reads the reward, the regions and the parts'
/// state formulas off it instead of evaluating each formula on its own. The DAG is laid out
/// flat ([`Op`], 16 bytes a node, operands by index), so that a push between two steps of
/// a physics engine, which has the caches to itself, touches few lines.
///
/// A slot is `rho(f, 0)` over the one-state trace `state` (the reference semantics with
/// `n = 1`: a window holds step 0 or nothing), or, when asked, with the offline evaluator's
/// folds (`&&` and `||` keep the running value on a tie of `0` and `-0`), so that a value
/// folded over steps is the offline evaluator's bit for bit: those slots' `&&`, `||`, `!`
/// and `->` nodes are laid out a second time, over the same comparisons.
#[derive(Clone, Debug)]
pub(super) struct Program {
    ops: Vec<Op>,
    /// The operands of the `&&` and `||` ops, each op's in a run.
    args: Vec<u32>,
    /// Each slot's value's index.
    roots: Vec<u32>,
    /// Each op's value on the last state run.
    values: Vec<f64>,
}

/// One node of a [`Program`]; operands are indices of earlier values.
#[derive(Clone, Copy, Debug)]
enum Op {
    Const(f64),
    Var(u32),
    Neg(u32),
    Abs(u32),
    Sqrt(u32),
    Add(u32, u32),
    Sub(u32, u32),
    Mul(u32, u32),
    Div(u32, u32),
    /// A comparison: `a - b` (`b - a` for `<`, as [`hstl_robustness::CmpOp::robustness`]).
    Cmp(u32, u32),
    Not(u32),
    /// `&&` over `args[start..start + len]`, folded as `f64::min` (or the offline
    /// evaluator's fold when `offline`).
    And {
        start: u32,
        len: u32,
        offline: bool,
    },
    Or {
        start: u32,
        len: u32,
        offline: bool,
    },
    Implies(u32, u32),
    /// `+inf.min(v)`: an `always` whose window holds the one step.
    MinInf(u32),
    /// `-inf.max(v)`: an `eventually` (or past `once`) whose window holds the one step.
    MaxNegInf(u32),
    /// `-inf.max(v.min(+inf))`: an `until` or `since` whose window holds the one step.
    UntilNow(u32),
}

impl Program {
    pub(super) fn new(slots: &[(Formula, bool)]) -> Program {
        let mut b = FormulaBuilder::new();
        let ids: Vec<NodeId> = slots.iter().map(|(f, _)| b.formula(f)).collect();
        let root = b.and(ids);
        let formula = b.build(root);
        // `&&` keeps its operands as given, so they are the slots in order.
        let slot_nodes: Vec<usize> = match formula.root_node() {
            Node::And(gs) => gs.iter().map(|g| g.index()).collect(),
            _ => Vec::new(),
        };
        let nodes = formula.nodes();
        let mut ops = Vec::with_capacity(nodes.len());
        let mut args: Vec<u32> = Vec::new();
        let ix = |k: usize| k as u32;
        let holds_now = |i: &Interval| !i.window(0, 1).is_empty();
        let past_now = |i: &Interval| i.past_window(0).contains(&0);
        let fold = |gs: &[NodeId], map: &dyn Fn(usize) -> u32, args: &mut Vec<u32>| {
            let start = ix(args.len());
            args.extend(gs.iter().map(|g| map(g.index())));
            (start, ix(gs.len()))
        };
        for node in nodes {
            let e = |g: &hstl_robustness::ExprId| ix(g.index());
            let v = |g: &NodeId| ix(g.index());
            let op = match node {
                Node::Const(c) => Op::Const(*c),
                Node::Var(i) => Op::Var(ix(*i)),
                Node::Neg(a) => Op::Neg(e(a)),
                Node::Abs(a) => Op::Abs(e(a)),
                Node::Sqrt(a) => Op::Sqrt(e(a)),
                Node::Add(a, c) => Op::Add(e(a), e(c)),
                Node::Sub(a, c) => Op::Sub(e(a), e(c)),
                Node::Mul(a, c) => Op::Mul(e(a), e(c)),
                Node::Div(a, c) => Op::Div(e(a), e(c)),
                Node::True => Op::Const(f64::INFINITY),
                Node::False => Op::Const(f64::NEG_INFINITY),
                Node::Cmp { lhs, op, rhs } => match op {
                    hstl_robustness::CmpOp::Lt | hstl_robustness::CmpOp::Le => {
                        Op::Cmp(e(rhs), e(lhs))
                    }
                    hstl_robustness::CmpOp::Gt | hstl_robustness::CmpOp::Ge => {
                        Op::Cmp(e(lhs), e(rhs))
                    }
                },
                Node::Not(g) => Op::Not(v(g)),
                Node::And(gs) => {
                    let (start, len) = fold(gs, &|k| ix(k), &mut args);
                    Op::And { start, len, offline: false }
                }
                Node::Or(gs) => {
                    let (start, len) = fold(gs, &|k| ix(k), &mut args);
                    Op::Or { start, len, offline: false }
                }
                Node::Implies(g, h) => Op::Implies(v(g), v(h)),
                Node::Always(i, g) if holds_now(i) => Op::MinInf(v(g)),
                Node::Always(..) => Op::Const(f64::INFINITY),
                Node::Eventually(i, g) if holds_now(i) => Op::MaxNegInf(v(g)),
                Node::Eventually(..) => Op::Const(f64::NEG_INFINITY),
                // Nothing comes before step 0, so the left side's minimum is over no step.
                Node::Until(i, _, h) if holds_now(i) => Op::UntilNow(v(h)),
                Node::Until(..) => Op::Const(f64::NEG_INFINITY),
                // Past windows at step 0 hold step 0 when they start there.
                Node::Historically(i, g) if past_now(i) => Op::MinInf(v(g)),
                Node::Historically(..) => Op::Const(f64::INFINITY),
                Node::Once(i, g) if past_now(i) => Op::MaxNegInf(v(g)),
                Node::Once(..) => Op::Const(f64::NEG_INFINITY),
                Node::Since(i, _, h) if past_now(i) => Op::UntilNow(v(h)),
                Node::Since(..) => Op::Const(f64::NEG_INFINITY),
                // Weak: the step before (or after) a one-state trace does not exist.
                Node::Prev(_) | Node::Next(_) => Op::Const(f64::INFINITY),
            };
            ops.push(op);
        }
        // The offline-folded slots (state formulas): their connectives again, over the
        // same atoms, in node order, each once.
        let mut offline: Vec<Option<u32>> = vec![None; nodes.len()];
        let mut wanted = vec![false; nodes.len()];
        for (&k, (_, off)) in slot_nodes.iter().zip(slots) {
            wanted[k] |= *off;
        }
        for k in (0..nodes.len()).rev() {
            if wanted[k] {
                for c in nodes[k].children() {
                    wanted[c] = true;
                }
            }
        }
        for (k, node) in nodes.iter().enumerate() {
            if !wanted[k] {
                continue;
            }
            let map = |c: usize| offline[c].unwrap_or(ix(c));
            let op = match node {
                Node::Not(g) => Op::Not(map(g.index())),
                Node::Implies(g, h) => Op::Implies(map(g.index()), map(h.index())),
                Node::And(gs) => {
                    let (start, len) = fold(gs, &map, &mut args);
                    Op::And { start, len, offline: true }
                }
                Node::Or(gs) => {
                    let (start, len) = fold(gs, &map, &mut args);
                    Op::Or { start, len, offline: true }
                }
                _ => continue,
            };
            offline[k] = Some(ix(ops.len()));
            ops.push(op);
        }
        let roots = slot_nodes
            .iter()
            .zip(slots)
            .map(|(&k, (_, off))| if *off { offline[k].unwrap_or(ix(k)) } else { ix(k) })
            .collect();
        let values = vec![0.0; ops.len()];
        Program { ops, args, roots, values }
    }

    /// Evaluates every slot on `state`; returns whether a comparison is NaN there.
    pub(super) fn run(&mut self, state: &[f64]) -> bool {
        let mut nan = false;
        let (ops, args, vals) = (&self.ops, &self.args, &mut self.values);
        for k in 0..ops.len() {
            let v = |i: u32| vals[i as usize];
            let run = |start: u32, len: u32| &args[start as usize..(start + len) as usize];
            let x = match ops[k] {
                Op::Const(c) => c,
                Op::Var(i) => state.get(i as usize).copied().unwrap_or(f64::NAN),
                Op::Neg(a) => -v(a),
                Op::Abs(a) => v(a).abs(),
                Op::Sqrt(a) => v(a).sqrt(),
                Op::Add(a, b) => v(a) + v(b),
                Op::Sub(a, b) => v(a) - v(b),
                Op::Mul(a, b) => v(a) * v(b),
                Op::Div(a, b) => v(a) / v(b),
                Op::Cmp(a, b) => {
                    let x = v(a) - v(b);
                    nan |= x.is_nan();
                    x
                }
                Op::Not(g) => -v(g),
                Op::And { start, len, offline: false } => {
                    run(start, len).iter().map(|&g| v(g)).fold(f64::INFINITY, f64::min)
                }
                Op::And { start, len, offline: true } => run(start, len)
                    .iter()
                    .map(|&g| v(g))
                    .fold(f64::INFINITY, |a, x| if x < a { x } else { a }),
                Op::Or { start, len, offline: false } => {
                    run(start, len).iter().map(|&g| v(g)).fold(f64::NEG_INFINITY, f64::max)
                }
                Op::Or { start, len, offline: true } => run(start, len)
                    .iter()
                    .map(|&g| v(g))
                    .fold(f64::NEG_INFINITY, |a, x| if x > a { x } else { a }),
                Op::Implies(g, h) => (-v(g)).max(v(h)),
                Op::MinInf(g) => f64::INFINITY.min(v(g)),
                Op::MaxNegInf(g) => f64::NEG_INFINITY.max(v(g)),
                Op::UntilNow(h) => f64::NEG_INFINITY.max(v(h).min(f64::INFINITY)),
            };
            vals[k] = x;
        }
        nan
    }

    /// Slot `slot`'s value on the last state run.
    pub(super) fn value(&self, slot: usize) -> f64 {
        self.values[self.roots[slot] as usize]
    }
}
