//! The runtime's formula representation: a DAG of nodes in topological order.
//!
//! A [`Formula`] (and an [`Expr`]) is a list of [`Node`]s, children before parents, with a
//! root. Nodes are built by a [`FormulaBuilder`], which hash-conses them: the same node
//! added twice gets the same id, so a `let` used twice is one node and is computed once.
//! Every walk over a formula is a forward loop over [`Formula::nodes`]; nothing here or in
//! the evaluators recurses in proportion to the formula, however deep it is.
//!
//! One file: the node types, the builder and the walks keep one invariant together (nodes
//! in topological order, each hash-consed once, in a canonical order), which every
//! constructor and every walk here relies on; split, it would be private to none of them.

use std::collections::HashMap;
use std::fmt;
use std::hash::{Hash, Hasher};

/// The id of a formula node within one [`Formula`] or [`FormulaBuilder`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeId(u32);

/// The id of an expression node within one [`Formula`], [`Expr`] or [`FormulaBuilder`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ExprId(u32);

impl NodeId {
    /// The node's position in [`Formula::nodes`].
    pub fn index(self) -> usize {
        self.0 as usize
    }

    pub(crate) fn from_index(i: usize) -> NodeId {
        NodeId(i as u32)
    }
}

impl ExprId {
    /// The node's position in [`Formula::nodes`] (or [`Expr::nodes`]).
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// One node of a formula or expression DAG; its operands are ids of earlier nodes.
///
/// Equality and hashing compare constants by their bits, so `NaN` equals itself and `0`
/// differs from `-0`: equal nodes are interchangeable everywhere.
#[derive(Clone, Debug)]
pub enum Node {
    /// A constant.
    Const(f64),
    /// The state variable with this column index in the trace.
    Var(usize),
    /// `-e`.
    Neg(ExprId),
    /// `a + b`.
    Add(ExprId, ExprId),
    /// `a - b`.
    Sub(ExprId, ExprId),
    /// `a * b`.
    Mul(ExprId, ExprId),
    /// `a / b`.
    Div(ExprId, ExprId),
    /// `abs(e)`.
    Abs(ExprId),
    /// `sqrt(e)`.
    Sqrt(ExprId),
    /// Robustness `+inf`.
    True,
    /// Robustness `-inf`.
    False,
    /// `lhs op rhs`; robustness `rhs - lhs` for `<`/`<=`, `lhs - rhs` for `>`/`>=`.
    Cmp {
        /// Left operand.
        lhs: ExprId,
        /// The comparison.
        op: CmpOp,
        /// Right operand.
        rhs: ExprId,
    },
    /// `!f`: the negated robustness.
    Not(NodeId),
    /// `f1 && f2 && ...`: the minimum. Empty means `true`.
    And(Vec<NodeId>),
    /// `f1 || f2 || ...`: the maximum. Empty means `false`.
    Or(Vec<NodeId>),
    /// `f -> g`, that is `!f || g`.
    Implies(NodeId, NodeId),
    /// `always[I] f`: the minimum over the window.
    Always(Interval, NodeId),
    /// `eventually[I] f`: the maximum over the window.
    Eventually(Interval, NodeId),
    /// `f until[I] g`.
    Until(Interval, NodeId, NodeId),
    /// `once[I] f`: the maximum over the past window (see [`Interval::past_window`]).
    Once(Interval, NodeId),
    /// `historically[I] f`: the minimum over the past window.
    Historically(Interval, NodeId),
    /// `f since[I] g`: the time reversal of `until`.
    Since(Interval, NodeId, NodeId),
    /// `prev f`: `f` one step back, `+inf` at the first step (`historically[1..=1] f`).
    Prev(NodeId),
    /// `next f`: `f` one step ahead, `+inf` at the last step (`always[1..=1] f`).
    Next(NodeId),
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

/// An STL formula whose robustness is computed over a trace: a DAG of [`Node`]s.
///
/// Build one with a [`FormulaBuilder`], or with the constructors ([`Formula::cmp`],
/// [`Formula::and`], [`Formula::always`], ...), which merge their operands' DAGs. The
/// nodes are exactly those reachable from the root, in a canonical order (children
/// before parents, in the order of a depth-first walk from the root), so two formulas
/// are equal exactly when they denote the same formula tree.
///
/// A formula is immutable and shares its nodes: cloning one is cheap.
#[derive(Clone)]
pub struct Formula {
    inner: std::sync::Arc<Inner>,
}

/// A [`Formula`]'s nodes and what the evaluators read off them once.
struct Inner {
    nodes: Vec<Node>,
    root: u32,
    /// `horizon[i]`: the horizon of node `i` (`Some(0)` for expressions).
    horizon: Vec<Option<usize>>,
    /// `state[i]`: node `i` has no temporal operator below it.
    state: Vec<bool>,
    plan: crate::offline::plan::Plan,
}

/// An arithmetic expression over the state variables of one sample: a DAG of expression
/// [`Node`]s, built like a [`Formula`].
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct Expr {
    nodes: Vec<Node>,
    root: u32,
}

/// Builds formulas node by node, sharing equal nodes (and dropping double negations).
///
/// Every method adds (or finds) one node and returns its id; [`FormulaBuilder::build`]
/// then takes the formula under one root. A builder may hold many formulas that share
/// parts (the lets of a spec): each `build` keeps only what its root reaches.
///
/// Ids are only meaningful in the builder that made them: the methods panic on an id past
/// the builder's nodes (a programming error, like an index out of bounds).
#[derive(Clone, Debug, Default)]
pub struct FormulaBuilder {
    nodes: Vec<Node>,
    index: HashMap<Node, u32>,
}

impl FormulaBuilder {
    /// An empty builder.
    pub fn new() -> FormulaBuilder {
        FormulaBuilder::default()
    }

    /// How many distinct nodes the builder holds.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    /// Whether the builder holds no node.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The node with id `id`.
    pub fn node(&self, id: NodeId) -> &Node {
        &self.nodes[id.index()]
    }

    fn add(&mut self, node: Node) -> u32 {
        let n = self.nodes.len();
        for k in node.children() {
            assert!(k < n, "node id {k} is not from this builder (it has {n} nodes)");
        }
        if let Some(&id) = self.index.get(&node) {
            return id;
        }
        let id = u32::try_from(n).expect("fewer than 2^32 formula nodes");
        self.index.insert(node.clone(), id);
        self.nodes.push(node);
        id
    }

    fn e(&mut self, node: Node) -> ExprId {
        ExprId(self.add(node))
    }

    fn f(&mut self, node: Node) -> NodeId {
        NodeId(self.add(node))
    }

    /// A constant.
    pub fn constant(&mut self, c: f64) -> ExprId {
        self.e(Node::Const(c))
    }

    /// The state variable with column index `i`.
    pub fn var(&mut self, i: usize) -> ExprId {
        self.e(Node::Var(i))
    }

    /// `-e`.
    pub fn neg(&mut self, e: ExprId) -> ExprId {
        self.e(Node::Neg(e))
    }

    /// `a + b`.
    pub fn add_expr(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.e(Node::Add(a, b))
    }

    /// `a - b`.
    pub fn sub_expr(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.e(Node::Sub(a, b))
    }

    /// `a * b`.
    pub fn mul_expr(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.e(Node::Mul(a, b))
    }

    /// `a / b`.
    pub fn div_expr(&mut self, a: ExprId, b: ExprId) -> ExprId {
        self.e(Node::Div(a, b))
    }

    /// `abs(e)`.
    pub fn abs(&mut self, e: ExprId) -> ExprId {
        self.e(Node::Abs(e))
    }

    /// `sqrt(e)`.
    pub fn sqrt(&mut self, e: ExprId) -> ExprId {
        self.e(Node::Sqrt(e))
    }

    /// `true` or `false`.
    pub fn bool(&mut self, b: bool) -> NodeId {
        self.f(if b { Node::True } else { Node::False })
    }

    /// `lhs op rhs`.
    pub fn cmp(&mut self, lhs: ExprId, op: CmpOp, rhs: ExprId) -> NodeId {
        self.f(Node::Cmp { lhs, op, rhs })
    }

    /// `!f`. Negation is exact, so `!!g` is `g` itself: a chain of `!` is at most one node.
    pub fn not(&mut self, f: NodeId) -> NodeId {
        if let Some(Node::Not(g)) = self.nodes.get(f.index()) {
            return *g;
        }
        self.f(Node::Not(f))
    }

    /// `f1 && f2 && ...` (`true` when empty).
    pub fn and(&mut self, fs: Vec<NodeId>) -> NodeId {
        self.f(Node::And(fs))
    }

    /// `f1 || f2 || ...` (`false` when empty).
    pub fn or(&mut self, fs: Vec<NodeId>) -> NodeId {
        self.f(Node::Or(fs))
    }

    /// `f -> g`.
    pub fn implies(&mut self, f: NodeId, g: NodeId) -> NodeId {
        self.f(Node::Implies(f, g))
    }

    /// `always[i] f`.
    pub fn always(&mut self, i: Interval, f: NodeId) -> NodeId {
        self.f(Node::Always(i, f))
    }

    /// `eventually[i] f`.
    pub fn eventually(&mut self, i: Interval, f: NodeId) -> NodeId {
        self.f(Node::Eventually(i, f))
    }

    /// `f until[i] g`.
    pub fn until(&mut self, i: Interval, f: NodeId, g: NodeId) -> NodeId {
        self.f(Node::Until(i, f, g))
    }

    /// `once[i] f`.
    pub fn once(&mut self, i: Interval, f: NodeId) -> NodeId {
        self.f(Node::Once(i, f))
    }

    /// `historically[i] f`.
    pub fn historically(&mut self, i: Interval, f: NodeId) -> NodeId {
        self.f(Node::Historically(i, f))
    }

    /// `f since[i] g`.
    pub fn since(&mut self, i: Interval, f: NodeId, g: NodeId) -> NodeId {
        self.f(Node::Since(i, f, g))
    }

    /// `prev f`.
    pub fn prev(&mut self, f: NodeId) -> NodeId {
        self.f(Node::Prev(f))
    }

    /// `next f`.
    pub fn next(&mut self, f: NodeId) -> NodeId {
        self.f(Node::Next(f))
    }

    /// Adds every node of `f`; returns the id of its root.
    pub fn formula(&mut self, f: &Formula) -> NodeId {
        NodeId(self.insert(&f.inner.nodes, f.inner.root))
    }

    /// Adds every node of `e`; returns the id of its root.
    pub fn expr(&mut self, e: &Expr) -> ExprId {
        ExprId(self.insert(&e.nodes, e.root))
    }

    fn insert(&mut self, nodes: &[Node], root: u32) -> u32 {
        self.insert_all(nodes)[root as usize]
    }

    /// Adds every node of `f`; returns each one's id here, in `f`'s node order.
    pub(crate) fn formula_nodes(&mut self, f: &Formula) -> Vec<NodeId> {
        self.insert_all(&f.inner.nodes).into_iter().map(NodeId).collect()
    }

    fn insert_all(&mut self, nodes: &[Node]) -> Vec<u32> {
        let mut map = Vec::with_capacity(nodes.len());
        for node in nodes {
            let node = node.remap(|k| map[k]);
            map.push(self.add(node));
        }
        map
    }

    /// The formula under `root`: the nodes it reaches, in canonical order.
    pub fn build(&self, root: NodeId) -> Formula {
        let (nodes, root) = self.extract(root.0);
        Formula::from_nodes(nodes, root)
    }

    /// The expression under `root`.
    pub fn build_expr(&self, root: ExprId) -> Expr {
        let (nodes, root) = self.extract(root.0);
        Expr { nodes, root }
    }

    /// The nodes `root` reaches, renumbered in the order a depth-first walk from `root`
    /// finishes them (children in operand order): the same tree always gives the same list.
    fn extract(&self, root: u32) -> (Vec<Node>, u32) {
        extract(&self.nodes, root)
    }
}

/// See [`FormulaBuilder::extract`]. `nodes` is hash-consed, so each subtree is one node.
fn extract(nodes: &[Node], root: u32) -> (Vec<Node>, u32) {
    const UNSEEN: u32 = u32::MAX;
    let mut new_id = vec![UNSEEN; nodes.len()];
    let mut out = Vec::new();
    // (node, next child position) pairs: an explicit stack instead of recursion.
    let mut stack: Vec<(u32, usize)> = vec![(root, 0)];
    while let Some(&(v, k)) = stack.last() {
        let node = &nodes[v as usize];
        if let Some(c) = node.child(k) {
            let top = stack.len() - 1;
            stack[top].1 += 1;
            if new_id[c] == UNSEEN {
                stack.push((c as u32, 0));
            }
            continue;
        }
        stack.pop();
        if new_id[v as usize] == UNSEEN {
            new_id[v as usize] = out.len() as u32;
            out.push(node.remap(|c| new_id[c]));
        }
    }
    let root = new_id[root as usize];
    (out, root)
}

impl Node {
    /// The operands' positions, in order.
    pub fn children(&self) -> Children<'_> {
        let (fixed, n, rest): ([u32; 3], usize, &[NodeId]) = match self {
            Node::Const(_) | Node::Var(_) | Node::True | Node::False => ([0; 3], 0, &[]),
            Node::Neg(a) | Node::Abs(a) | Node::Sqrt(a) => ([a.0, 0, 0], 1, &[]),
            Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b) => {
                ([a.0, b.0, 0], 2, &[])
            }
            Node::Cmp { lhs, rhs, .. } => ([lhs.0, rhs.0, 0], 2, &[]),
            Node::Not(a)
            | Node::Always(_, a)
            | Node::Eventually(_, a)
            | Node::Once(_, a)
            | Node::Historically(_, a)
            | Node::Prev(a)
            | Node::Next(a) => ([a.0, 0, 0], 1, &[]),
            Node::Implies(a, b) | Node::Until(_, a, b) | Node::Since(_, a, b) => {
                ([a.0, b.0, 0], 2, &[])
            }
            Node::And(v) | Node::Or(v) => ([0; 3], 0, v.as_slice()),
        };
        Children { fixed, n, rest, k: 0 }
    }

    /// The position of operand `k`, if the node has that many.
    pub fn child(&self, k: usize) -> Option<usize> {
        match self {
            Node::And(v) | Node::Or(v) => v.get(k).map(|id| id.index()),
            _ => self.children().nth(k),
        }
    }

    /// Whether this is an expression node (not a formula).
    pub fn is_expr(&self) -> bool {
        matches!(
            self,
            Node::Const(_)
                | Node::Var(_)
                | Node::Neg(_)
                | Node::Add(..)
                | Node::Sub(..)
                | Node::Mul(..)
                | Node::Div(..)
                | Node::Abs(_)
                | Node::Sqrt(_)
        )
    }

    /// Whether this is a temporal operator: `always`, `eventually`, `until`, or a
    /// past-time one ([`Node::is_past`]), or `next`.
    pub fn is_temporal(&self) -> bool {
        matches!(
            self,
            Node::Always(..)
                | Node::Eventually(..)
                | Node::Until(..)
                | Node::Next(_)
                | Node::Once(..)
                | Node::Historically(..)
                | Node::Since(..)
                | Node::Prev(_)
        )
    }

    /// Whether this is a past-time operator (`once`, `historically`, `since`, `prev`): its
    /// value at `t` reads steps before `t`.
    pub fn is_past(&self) -> bool {
        matches!(self, Node::Once(..) | Node::Historically(..) | Node::Since(..) | Node::Prev(_))
    }

    /// The node with every operand `k` replaced by `map(k)`.
    fn remap(&self, mut map: impl FnMut(usize) -> u32) -> Node {
        let mut e = |a: &ExprId| ExprId(map(a.index()));
        match self {
            Node::Const(c) => Node::Const(*c),
            Node::Var(i) => Node::Var(*i),
            Node::True => Node::True,
            Node::False => Node::False,
            Node::Neg(a) => Node::Neg(e(a)),
            Node::Abs(a) => Node::Abs(e(a)),
            Node::Sqrt(a) => Node::Sqrt(e(a)),
            Node::Add(a, b) => {
                let a = e(a);
                Node::Add(a, e(b))
            }
            Node::Sub(a, b) => {
                let a = e(a);
                Node::Sub(a, e(b))
            }
            Node::Mul(a, b) => {
                let a = e(a);
                Node::Mul(a, e(b))
            }
            Node::Div(a, b) => {
                let a = e(a);
                Node::Div(a, e(b))
            }
            Node::Cmp { lhs, op, rhs } => {
                let lhs = e(lhs);
                Node::Cmp { lhs, op: *op, rhs: e(rhs) }
            }
            Node::Not(a) => Node::Not(NodeId(map(a.index()))),
            Node::Always(i, a) => Node::Always(*i, NodeId(map(a.index()))),
            Node::Eventually(i, a) => Node::Eventually(*i, NodeId(map(a.index()))),
            Node::Implies(a, b) => {
                let a = NodeId(map(a.index()));
                Node::Implies(a, NodeId(map(b.index())))
            }
            Node::Until(i, a, b) => {
                let a = NodeId(map(a.index()));
                Node::Until(*i, a, NodeId(map(b.index())))
            }
            Node::Once(i, a) => Node::Once(*i, NodeId(map(a.index()))),
            Node::Historically(i, a) => Node::Historically(*i, NodeId(map(a.index()))),
            Node::Since(i, a, b) => {
                let a = NodeId(map(a.index()));
                Node::Since(*i, a, NodeId(map(b.index())))
            }
            Node::Prev(a) => Node::Prev(NodeId(map(a.index()))),
            Node::Next(a) => Node::Next(NodeId(map(a.index()))),
            Node::And(v) => Node::And(v.iter().map(|a| NodeId(map(a.index()))).collect()),
            Node::Or(v) => Node::Or(v.iter().map(|a| NodeId(map(a.index()))).collect()),
        }
    }

    fn discriminant(&self) -> u8 {
        match self {
            Node::Const(_) => 0,
            Node::Var(_) => 1,
            Node::Neg(_) => 2,
            Node::Add(..) => 3,
            Node::Sub(..) => 4,
            Node::Mul(..) => 5,
            Node::Div(..) => 6,
            Node::Abs(_) => 7,
            Node::Sqrt(_) => 8,
            Node::True => 9,
            Node::False => 10,
            Node::Cmp { .. } => 11,
            Node::Not(_) => 12,
            Node::And(_) => 13,
            Node::Or(_) => 14,
            Node::Implies(..) => 15,
            Node::Always(..) => 16,
            Node::Eventually(..) => 17,
            Node::Until(..) => 18,
            Node::Once(..) => 19,
            Node::Historically(..) => 20,
            Node::Since(..) => 21,
            Node::Prev(_) => 22,
            Node::Next(_) => 23,
        }
    }

    /// The node's own parameters (not its operands), for equality and hashing.
    fn params(&self) -> (u64, Option<Interval>) {
        match self {
            Node::Const(c) => (c.to_bits(), None),
            Node::Var(i) => (*i as u64, None),
            Node::Cmp { op, .. } => (*op as u64, None),
            Node::Always(i, _)
            | Node::Eventually(i, _)
            | Node::Until(i, ..)
            | Node::Once(i, _)
            | Node::Historically(i, _)
            | Node::Since(i, ..) => (0, Some(*i)),
            _ => (0, None),
        }
    }
}

/// The operands of a [`Node`], as positions in its formula's node list.
#[derive(Clone, Debug)]
pub struct Children<'a> {
    fixed: [u32; 3],
    n: usize,
    rest: &'a [NodeId],
    k: usize,
}

impl Iterator for Children<'_> {
    type Item = usize;

    fn next(&mut self) -> Option<usize> {
        let k = self.k;
        self.k += 1;
        if k < self.n {
            Some(self.fixed[k] as usize)
        } else {
            self.rest.get(k - self.n).map(|id| id.index())
        }
    }
}

impl PartialEq for Node {
    fn eq(&self, other: &Node) -> bool {
        self.discriminant() == other.discriminant()
            && self.params() == other.params()
            && self.children().eq(other.children())
    }
}

impl Eq for Node {}

impl Hash for Node {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.discriminant().hash(state);
        self.params().hash(state);
        for c in self.children() {
            c.hash(state);
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

    /// The steps of the past window at step `t`, `{t' : t-b < t' <= t-a}` for `[a..b]`
    /// (`t-b` included for `[a..=b]`, from step 0 for `[a..]`), clipped at the start of the
    /// trace. Empty when `t < a`; a bound past `t` reaches back to step 0 (no wrap).
    pub fn past_window(&self, t: usize) -> std::ops::Range<usize> {
        let hi = t.saturating_add(1).saturating_sub(self.start);
        let lo = match self.end {
            Bound::Unbounded => 0,
            Bound::Exclusive(b) => t.saturating_add(1).saturating_sub(b),
            Bound::Inclusive(b) => t.saturating_sub(b),
        };
        lo..hi.max(lo)
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

/// The horizon contribution of an interval: `b - 1` for `[a..b]`, `b` for `[a..=b]`.
pub(crate) fn window_end(i: &Interval) -> Option<usize> {
    match i.end {
        Bound::Unbounded => None,
        Bound::Exclusive(b) => Some(b.saturating_sub(1)),
        Bound::Inclusive(b) => Some(b),
    }
}

impl Formula {
    /// Wraps canonical, reachable-only nodes, computing what the evaluators need.
    fn from_nodes(nodes: Vec<Node>, root: u32) -> Formula {
        let mut horizon: Vec<Option<usize>> = Vec::with_capacity(nodes.len());
        let mut state: Vec<bool> = Vec::with_capacity(nodes.len());
        for node in &nodes {
            let kids_h =
                || node.children().try_fold(0usize, |acc, k| horizon[k].map(|h| acc.max(h)));
            let h = match node {
                Node::Always(i, _) | Node::Eventually(i, _) | Node::Until(i, ..) => {
                    kids_h().and_then(|h| window_end(i)?.checked_add(h))
                }
                Node::Next(_) => kids_h().and_then(|h| h.checked_add(1)),
                _ if node.is_expr() => Some(0),
                // Past windows never look forward (`prev`: an upper bound).
                _ => kids_h(),
            };
            let s = !node.is_temporal() && node.children().all(|k| state[k]);
            horizon.push(h);
            state.push(s);
        }
        let plan = crate::offline::plan::Plan::new(&nodes, root as usize, &horizon, &state);
        Formula { inner: std::sync::Arc::new(Inner { nodes, root, horizon, state, plan }) }
    }

    /// The nodes, children before parents; the last one is the root.
    pub fn nodes(&self) -> &[Node] {
        &self.inner.nodes
    }

    /// The root node's id.
    pub fn root(&self) -> NodeId {
        NodeId(self.inner.root)
    }

    /// The root node.
    pub fn root_node(&self) -> &Node {
        &self.inner.nodes[self.inner.root as usize]
    }

    /// The number of distinct nodes (a shared subformula counts once).
    pub fn len(&self) -> usize {
        self.inner.nodes.len()
    }

    /// Always false: a formula has at least its root.
    pub fn is_empty(&self) -> bool {
        self.inner.nodes.is_empty()
    }

    /// The formula under node `id` of this formula.
    pub fn sub(&self, id: NodeId) -> Formula {
        let (nodes, root) = extract(&self.inner.nodes, id.0);
        Formula::from_nodes(nodes, root)
    }

    /// The expression under expression node `id` of this formula.
    pub fn expr_at(&self, id: ExprId) -> Expr {
        let (nodes, root) = extract(&self.inner.nodes, id.0);
        Expr { nodes, root }
    }

    /// The formula's horizon: how many steps past `t` its robustness at `t` may read.
    /// `None` means infinite.
    pub fn horizon(&self) -> Option<usize> {
        self.inner.horizon[self.inner.root as usize]
    }

    /// The horizon of node `id`.
    pub fn horizon_of(&self, id: NodeId) -> Option<usize> {
        self.inner.horizon[id.index()]
    }

    /// The number of nodes of the formula written out as a tree (a shared node counted at
    /// each use), saturating at `u64::MAX`: what [`Formula::display_with`] writes is about
    /// this long. A chain of lets that each use the previous twice doubles it per let.
    pub fn tree_len(&self) -> u64 {
        let mut size: Vec<u64> = Vec::with_capacity(self.inner.nodes.len());
        for node in &self.inner.nodes {
            let s = node.children().fold(1u64, |acc, k| acc.saturating_add(size[k]));
            size.push(s);
        }
        size[self.inner.root as usize]
    }

    /// The largest state-variable index the formula reads, if it reads any.
    pub fn max_var(&self) -> Option<usize> {
        self.inner
            .nodes
            .iter()
            .filter_map(|n| if let Node::Var(i) = n { Some(*i) } else { None })
            .max()
    }

    /// Whether the formula has no temporal operator: its robustness at `t` reads `s_t` only.
    pub fn is_state_formula(&self) -> bool {
        self.inner.state[self.inner.root as usize]
    }

    /// Whether node `id` has no temporal operator below it.
    pub fn is_state(&self, id: NodeId) -> bool {
        self.inner.state[id.index()]
    }

    pub(crate) fn horizons(&self) -> &[Option<usize>] {
        &self.inner.horizon
    }

    pub(crate) fn states(&self) -> &[bool] {
        &self.inner.state
    }

    pub(crate) fn plan(&self) -> &crate::offline::plan::Plan {
        &self.inner.plan
    }

    fn one(node: impl FnOnce(&mut FormulaBuilder) -> NodeId) -> Formula {
        let mut b = FormulaBuilder::new();
        let root = node(&mut b);
        b.build(root)
    }

    /// `true` or `false`.
    pub fn bool(value: bool) -> Formula {
        Formula::one(|b| b.bool(value))
    }

    /// `lhs op rhs`.
    pub fn cmp(lhs: Expr, op: CmpOp, rhs: Expr) -> Formula {
        Formula::one(|b| {
            let (l, r) = (b.expr(&lhs), b.expr(&rhs));
            b.cmp(l, op, r)
        })
    }

    /// `!f`.
    // A constructor named after the operator it builds, not an operator on values.
    #[allow(clippy::should_implement_trait)]
    pub fn not(f: Formula) -> Formula {
        Formula::one(|b| {
            let f = b.formula(&f);
            b.not(f)
        })
    }

    /// `f1 && f2 && ...` (`true` when empty).
    pub fn and(fs: Vec<Formula>) -> Formula {
        Formula::one(|b| {
            let ids = fs.iter().map(|f| b.formula(f)).collect();
            b.and(ids)
        })
    }

    /// `f1 || f2 || ...` (`false` when empty).
    pub fn or(fs: Vec<Formula>) -> Formula {
        Formula::one(|b| {
            let ids = fs.iter().map(|f| b.formula(f)).collect();
            b.or(ids)
        })
    }

    /// `f -> g`.
    pub fn implies(f: Formula, g: Formula) -> Formula {
        Formula::one(|b| {
            let (f, g) = (b.formula(&f), b.formula(&g));
            b.implies(f, g)
        })
    }

    /// `always[i] f`.
    pub fn always(i: Interval, f: Formula) -> Formula {
        Formula::one(|b| {
            let f = b.formula(&f);
            b.always(i, f)
        })
    }

    /// `eventually[i] f`.
    pub fn eventually(i: Interval, f: Formula) -> Formula {
        Formula::one(|b| {
            let f = b.formula(&f);
            b.eventually(i, f)
        })
    }

    /// `f until[i] g`.
    pub fn until(i: Interval, f: Formula, g: Formula) -> Formula {
        Formula::one(|b| {
            let (f, g) = (b.formula(&f), b.formula(&g));
            b.until(i, f, g)
        })
    }

    /// `once[i] f`.
    pub fn once(i: Interval, f: Formula) -> Formula {
        Formula::one(|b| {
            let f = b.formula(&f);
            b.once(i, f)
        })
    }

    /// `historically[i] f`.
    pub fn historically(i: Interval, f: Formula) -> Formula {
        Formula::one(|b| {
            let f = b.formula(&f);
            b.historically(i, f)
        })
    }

    /// `f since[i] g`.
    pub fn since(i: Interval, f: Formula, g: Formula) -> Formula {
        Formula::one(|b| {
            let (f, g) = (b.formula(&f), b.formula(&g));
            b.since(i, f, g)
        })
    }

    /// `prev f`.
    pub fn prev(f: Formula) -> Formula {
        Formula::one(|b| {
            let f = b.formula(&f);
            b.prev(f)
        })
    }

    /// `next f`.
    pub fn next(f: Formula) -> Formula {
        Formula::one(|b| {
            let f = b.formula(&f);
            b.next(f)
        })
    }

    /// Whether some node is a past-time operator: then `rho(f, t)` also reads steps before
    /// `t`, and a suffix of a trace does not give the signal's values.
    pub fn has_past(&self) -> bool {
        self.nodes().iter().any(Node::is_past)
    }
}

impl std::ops::Index<NodeId> for Formula {
    type Output = Node;

    fn index(&self, id: NodeId) -> &Node {
        &self.inner.nodes[id.index()]
    }
}

impl std::ops::Index<ExprId> for Formula {
    type Output = Node;

    fn index(&self, id: ExprId) -> &Node {
        &self.inner.nodes[id.index()]
    }
}

/// Equal when both denote the same formula tree (constants compared by their bits).
impl PartialEq for Formula {
    fn eq(&self, other: &Formula) -> bool {
        self.inner.root == other.inner.root && self.inner.nodes == other.inner.nodes
    }
}

impl fmt::Debug for Formula {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Formula")
            .field("nodes", &self.inner.nodes)
            .field("root", &self.inner.root)
            .finish()
    }
}

impl fmt::Debug for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Expr").field("nodes", &self.nodes).field("root", &self.root).finish()
    }
}

impl Expr {
    fn one(node: impl FnOnce(&mut FormulaBuilder) -> ExprId) -> Expr {
        let mut b = FormulaBuilder::new();
        let root = node(&mut b);
        b.build_expr(root)
    }

    fn unary(self, op: fn(&mut FormulaBuilder, ExprId) -> ExprId) -> Expr {
        Expr::one(|b| {
            let a = b.expr(&self);
            op(b, a)
        })
    }

    fn binary(self, other: Expr, op: fn(&mut FormulaBuilder, ExprId, ExprId) -> ExprId) -> Expr {
        Expr::one(|b| {
            let (x, y) = (b.expr(&self), b.expr(&other));
            op(b, x, y)
        })
    }

    /// A constant.
    pub fn constant(c: f64) -> Expr {
        Expr::one(|b| b.constant(c))
    }

    /// The state variable with column index `i`.
    pub fn var(i: usize) -> Expr {
        Expr::one(|b| b.var(i))
    }

    /// `-e`.
    // A constructor named after the operator it builds, not an operator on values.
    #[allow(clippy::should_implement_trait)]
    pub fn neg(e: Expr) -> Expr {
        e.unary(FormulaBuilder::neg)
    }

    /// `abs(e)`.
    pub fn abs(e: Expr) -> Expr {
        e.unary(FormulaBuilder::abs)
    }

    /// `sqrt(e)`.
    pub fn sqrt(e: Expr) -> Expr {
        e.unary(FormulaBuilder::sqrt)
    }

    /// `a + b`.
    // A constructor named after the operator it builds, not an operator on values.
    #[allow(clippy::should_implement_trait)]
    pub fn add(a: Expr, b: Expr) -> Expr {
        a.binary(b, FormulaBuilder::add_expr)
    }

    /// `a - b`.
    // A constructor named after the operator it builds, not an operator on values.
    #[allow(clippy::should_implement_trait)]
    pub fn sub(a: Expr, b: Expr) -> Expr {
        a.binary(b, FormulaBuilder::sub_expr)
    }

    /// `a * b`.
    // A constructor named after the operator it builds, not an operator on values.
    #[allow(clippy::should_implement_trait)]
    pub fn mul(a: Expr, b: Expr) -> Expr {
        a.binary(b, FormulaBuilder::mul_expr)
    }

    /// `a / b`.
    // A constructor named after the operator it builds, not an operator on values.
    #[allow(clippy::should_implement_trait)]
    pub fn div(a: Expr, b: Expr) -> Expr {
        a.binary(b, FormulaBuilder::div_expr)
    }

    /// The nodes, children before parents; the last one is the root.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// The root node.
    pub fn root_node(&self) -> &Node {
        &self.nodes[self.root as usize]
    }

    /// The expression's value at every step of `trace` (what [`Expr::eval`] gives row by
    /// row), computed node by node over chunks of 512 steps: no allocation per step, and
    /// memory of one chunk per node, however long the trace.
    pub fn eval_trace(&self, trace: &crate::Trace) -> Vec<f64> {
        const CHUNK: usize = 512;
        let n = trace.len();
        let mut out = Vec::with_capacity(n);
        let mut vals: Vec<Vec<f64>> = vec![Vec::with_capacity(CHUNK.min(n)); self.nodes.len()];
        for lo in (0..n).step_by(CHUNK) {
            let hi = (lo + CHUNK).min(n);
            for (i, node) in self.nodes.iter().enumerate() {
                let (done, rest) = vals.split_at_mut(i);
                let col = &mut rest[0];
                col.clear();
                let v = |e: &ExprId| done[e.index()].iter().copied();
                let bin = |a: &ExprId, b: &ExprId, g: fn(f64, f64) -> f64| {
                    v(a).zip(v(b)).map(move |(x, y)| g(x, y))
                };
                match node {
                    Node::Const(c) => col.resize(hi - lo, *c),
                    Node::Var(j) if *j < trace.vars() => {
                        col.extend_from_slice(&trace.column(*j)[lo..hi])
                    }
                    Node::Neg(e) => col.extend(v(e).map(|x| -x)),
                    Node::Abs(e) => col.extend(v(e).map(f64::abs)),
                    Node::Sqrt(e) => col.extend(v(e).map(f64::sqrt)),
                    Node::Add(a, b) => col.extend(bin(a, b, |x, y| x + y)),
                    Node::Sub(a, b) => col.extend(bin(a, b, |x, y| x - y)),
                    Node::Mul(a, b) => col.extend(bin(a, b, |x, y| x * y)),
                    Node::Div(a, b) => col.extend(bin(a, b, |x, y| x / y)),
                    // A variable past the trace, as in `eval`; no other node is an expression.
                    _ => col.resize(hi - lo, f64::NAN),
                }
            }
            out.extend_from_slice(&vals[self.root as usize]);
        }
        out
    }

    /// The value of the expression on one sample, `state[i]` being variable `i`.
    ///
    /// A variable index outside `state` reads as NaN; [`Formula::max_var`] lets callers
    /// validate a formula against their trace once instead.
    pub fn eval(&self, state: &[f64]) -> f64 {
        let mut vals = Vec::with_capacity(self.nodes.len());
        for node in &self.nodes {
            let v = expr_value(node, &vals, state);
            vals.push(v);
        }
        vals[self.root as usize]
    }
}

/// The value of expression node `node` given the values of earlier nodes (`vals`) on the
/// sample `state`; NaN for a formula node.
pub(crate) fn expr_value(node: &Node, vals: &[f64], state: &[f64]) -> f64 {
    let v = |e: &ExprId| vals[e.index()];
    match node {
        Node::Const(c) => *c,
        Node::Var(i) => state.get(*i).copied().unwrap_or(f64::NAN),
        Node::Neg(e) => -v(e),
        Node::Add(a, b) => v(a) + v(b),
        Node::Sub(a, b) => v(a) - v(b),
        Node::Mul(a, b) => v(a) * v(b),
        Node::Div(a, b) => v(a) / v(b),
        Node::Abs(e) => v(e).abs(),
        Node::Sqrt(e) => v(e).sqrt(),
        _ => f64::NAN,
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

/// A [`Formula`] or [`Expr`] printed in hstl syntax with the given variable names.
///
/// Made by [`Formula::display_with`] and [`Expr::display_with`]. A variable without a name
/// prints as `v<index>`. Parentheses appear where precedence needs them and around nested
/// operators of the same level, so the text parses back to the same formula. Infinite
/// constants print as `1e999` (which reads back as infinity) and NaN as `(0 / 0)`. The text
/// is the formula as a tree: a shared node is written out at each of its uses.
#[derive(Clone, Copy, Debug)]
pub struct Display<'a> {
    nodes: &'a [Node],
    root: u32,
    names: &'a [&'a str],
}

impl Formula {
    /// The formula in hstl syntax, `names[i]` naming variable `i`.
    pub fn display_with<'a>(&'a self, names: &'a [&'a str]) -> Display<'a> {
        Display { nodes: &self.inner.nodes, root: self.inner.root, names }
    }
}

impl Expr {
    /// The expression in hstl syntax, `names[i]` naming variable `i`.
    pub fn display_with<'a>(&'a self, names: &'a [&'a str]) -> Display<'a> {
        Display { nodes: &self.nodes, root: self.root, names }
    }
}

/// One piece of output still to write, on [`Display`]'s explicit stack.
enum Piece {
    /// A formula node whose binding strength must be at least `min`, else parenthesised.
    Formula(u32, u8),
    /// An expression node, likewise.
    Expr(u32, u8),
    Text(&'static str),
    Interval(Interval),
    Cmp(CmpOp),
}

impl Display<'_> {
    /// Binding strengths of every node: formulas `->` 0, `||` 1, `&&` 2, `until` and
    /// `since` 3, prefix 4, atoms 5; expressions sums 0, products 1, factors 2.
    fn levels(&self) -> Vec<u8> {
        let mut level: Vec<u8> = Vec::with_capacity(self.nodes.len());
        for node in self.nodes {
            let l = match node {
                Node::Add(..) | Node::Sub(..) => 0,
                Node::Mul(..) | Node::Div(..) => 1,
                _ if node.is_expr() => 2,
                Node::Implies(..) => 0,
                Node::Or(gs) | Node::And(gs) if gs.len() == 1 => level[gs[0].index()],
                Node::Or(gs) if !gs.is_empty() => 1,
                Node::And(gs) if !gs.is_empty() => 2,
                Node::Until(..) | Node::Since(..) => 3,
                Node::Not(_)
                | Node::Always(..)
                | Node::Eventually(..)
                | Node::Once(..)
                | Node::Historically(..)
                | Node::Prev(_)
                | Node::Next(_) => 4,
                _ => 5,
            };
            level.push(l);
        }
        level
    }

    fn write(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let level = self.levels();
        let is_expr = self.nodes[self.root as usize].is_expr();
        let mut stack =
            vec![if is_expr { Piece::Expr(self.root, 0) } else { Piece::Formula(self.root, 0) }];
        while let Some(piece) = stack.pop() {
            match piece {
                Piece::Text(s) => f.write_str(s)?,
                Piece::Interval(i) => write!(f, "{i}")?,
                Piece::Cmp(op) => write!(f, " {op} ")?,
                Piece::Formula(v, min) | Piece::Expr(v, min) if level[v as usize] < min => {
                    // Pushed in reverse: `(`, the node at any level, `)`.
                    stack.push(Piece::Text(")"));
                    stack.push(match piece {
                        Piece::Formula(..) => Piece::Formula(v, 0),
                        _ => Piece::Expr(v, 0),
                    });
                    stack.push(Piece::Text("("));
                }
                Piece::Formula(v, _) => self.formula(v, f, &mut stack)?,
                Piece::Expr(v, _) => self.expr(v, f, &mut stack)?,
            }
        }
        Ok(())
    }

    /// Writes what of formula node `v` comes first; pushes the rest, last part first.
    fn formula(&self, v: u32, f: &mut fmt::Formatter<'_>, stack: &mut Vec<Piece>) -> fmt::Result {
        let id = |n: &NodeId| n.0;
        match &self.nodes[v as usize] {
            Node::True => f.write_str("true"),
            Node::False => f.write_str("false"),
            Node::Cmp { lhs, op, rhs } => {
                stack.push(Piece::Expr(rhs.0, 0));
                stack.push(Piece::Cmp(*op));
                stack.push(Piece::Expr(lhs.0, 0));
                Ok(())
            }
            Node::Not(g) => {
                stack.push(Piece::Formula(id(g), 4));
                f.write_str("!")
            }
            node @ (Node::Always(i, g)
            | Node::Eventually(i, g)
            | Node::Once(i, g)
            | Node::Historically(i, g)) => {
                stack.push(Piece::Formula(id(g), 4));
                stack.push(Piece::Text(" "));
                stack.push(Piece::Interval(*i));
                f.write_str(match node {
                    Node::Always(..) => "always",
                    Node::Eventually(..) => "eventually",
                    Node::Once(..) => "once",
                    _ => "historically",
                })
            }
            Node::Prev(g) | Node::Next(g) => {
                let prev = matches!(self.nodes[v as usize], Node::Prev(_));
                stack.push(Piece::Formula(id(g), 4));
                f.write_str(if prev { "prev " } else { "next " })
            }
            Node::Until(i, g, h) | Node::Since(i, g, h) => {
                let since = matches!(self.nodes[v as usize], Node::Since(..));
                stack.push(Piece::Formula(id(h), 4));
                stack.push(Piece::Text(" "));
                stack.push(Piece::Interval(*i));
                stack.push(Piece::Text(if since { " since" } else { " until" }));
                stack.push(Piece::Formula(id(g), 4));
                Ok(())
            }
            Node::And(gs) | Node::Or(gs) => {
                let and = matches!(self.nodes[v as usize], Node::And(_));
                let (sep, level, empty) =
                    if and { (" && ", 2, "true") } else { (" || ", 1, "false") };
                match gs.as_slice() {
                    [] => f.write_str(empty),
                    [g] => {
                        stack.push(Piece::Formula(id(g), 0));
                        Ok(())
                    }
                    _ => {
                        for (k, g) in gs.iter().enumerate().rev() {
                            stack.push(Piece::Formula(id(g), level + 1));
                            if k > 0 {
                                stack.push(Piece::Text(sep));
                            }
                        }
                        Ok(())
                    }
                }
            }
            Node::Implies(g, h) => {
                stack.push(Piece::Formula(id(h), 0));
                stack.push(Piece::Text(" -> "));
                stack.push(Piece::Formula(id(g), 1));
                Ok(())
            }
            // An expression where a formula belongs: not made by the builder's methods.
            _ => {
                stack.push(Piece::Expr(v, 0));
                Ok(())
            }
        }
    }

    /// Writes what of expression node `v` comes first; pushes the rest, last part first.
    fn expr(&self, v: u32, f: &mut fmt::Formatter<'_>, stack: &mut Vec<Piece>) -> fmt::Result {
        match &self.nodes[v as usize] {
            Node::Const(c) if c.is_nan() => f.write_str("(0 / 0)"),
            Node::Const(c) if c.is_infinite() => {
                write!(f, "{}1e999", if *c < 0.0 { "-" } else { "" })
            }
            Node::Const(c) => write!(f, "{c}"),
            Node::Var(i) => match self.names.get(*i) {
                Some(name) => f.write_str(name),
                None => write!(f, "v{i}"),
            },
            Node::Neg(e) => {
                stack.push(Piece::Expr(e.0, 2));
                f.write_str("-")
            }
            Node::Abs(e) | Node::Sqrt(e) => {
                let abs = matches!(self.nodes[v as usize], Node::Abs(_));
                stack.push(Piece::Text(")"));
                stack.push(Piece::Expr(e.0, 0));
                f.write_str(if abs { "abs(" } else { "sqrt(" })
            }
            node @ (Node::Add(a, b) | Node::Sub(a, b) | Node::Mul(a, b) | Node::Div(a, b)) => {
                let (op, level) = match node {
                    Node::Add(..) => (" + ", 0),
                    Node::Sub(..) => (" - ", 0),
                    Node::Mul(..) => (" * ", 1),
                    _ => (" / ", 1),
                };
                // Left-associative: the right operand of the same level needs parentheses.
                stack.push(Piece::Expr(b.0, level + 1));
                stack.push(Piece::Text(op));
                stack.push(Piece::Expr(a.0, level));
                Ok(())
            }
            // A formula where an expression belongs: not made by the builder's methods.
            _ => {
                stack.push(Piece::Formula(v, 0));
                Ok(())
            }
        }
    }
}

impl fmt::Display for Display<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.write(f)
    }
}

/// Prints in hstl syntax, variable `i` as `v<i>`; [`Formula::display_with`] names them.
impl fmt::Display for Formula {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.display_with(&[]).write(f)
    }
}

/// Prints in hstl syntax, variable `i` as `v<i>`; [`Expr::display_with`] names them.
impl fmt::Display for Expr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.display_with(&[]).write(f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn x_gt(c: f64) -> Formula {
        Formula::cmp(Expr::var(0), CmpOp::Gt, Expr::constant(c))
    }

    #[test]
    fn a_node_added_twice_is_one_node() {
        let mut b = FormulaBuilder::new();
        let (x, three) = (b.var(0), b.constant(3.0));
        let mut l = b.cmp(x, CmpOp::Gt, three);
        for _ in 0..60 {
            l = b.and(vec![l, l]);
        }
        let f = b.build(l);
        // 2^60 leaves as a tree, 63 nodes as a DAG.
        assert_eq!(f.len(), 63);
        assert_eq!(f.horizon(), Some(0));
        assert!(f.is_state_formula());
        assert_eq!(f.max_var(), Some(0));
    }

    #[test]
    fn equal_trees_are_equal_formulas_however_built() {
        let a = Formula::and(vec![x_gt(1.0), Formula::not(x_gt(2.0))]);
        let mut b = FormulaBuilder::new();
        // Built in another order, with an unused node left in the builder.
        let (x, two) = (b.var(0), b.constant(2.0));
        let g = b.cmp(x, CmpOp::Gt, two);
        let not_g = b.not(g);
        let _unused = b.bool(false);
        let one = b.constant(1.0);
        let f = b.cmp(x, CmpOp::Gt, one);
        let root = b.and(vec![f, not_g]);
        assert_eq!(b.build(root), a);
        assert_ne!(Formula::and(vec![Formula::not(x_gt(2.0)), x_gt(1.0)]), a);
    }

    #[test]
    fn a_double_negation_is_the_formula_itself() {
        let f = x_gt(1.0);
        assert_eq!(Formula::not(Formula::not(f.clone())), f);
        assert_eq!(Formula::not(Formula::not(Formula::not(f.clone()))), Formula::not(f));
    }

    #[test]
    fn deep_formulas_display_and_drop_without_recursion() {
        let mut b = FormulaBuilder::new();
        let (x, three) = (b.var(0), b.constant(3.0));
        let atom = b.cmp(x, CmpOp::Gt, three);
        let mut f = atom;
        for _ in 0..100_000 {
            let g = b.not(f);
            f = b.or(vec![g, atom]);
        }
        let i = Interval { start: 0, end: Bound::Inclusive(2) };
        f = b.always(i, f);
        let f = b.build(f);
        assert_eq!(f.len(), 200_004);
        assert_eq!(f.horizon(), Some(2));
        let text = f.to_string();
        assert!(text.starts_with("always[0..=2] (!(!(!("), "{}", &text[..40]);
        assert!(text.ends_with("|| v0 > 3)"), "{}", &text[text.len() - 40..]);
        drop(f);
    }
}
