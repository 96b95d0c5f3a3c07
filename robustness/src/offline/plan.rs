//! How a formula is evaluated offline: its nodes cut into groups ([`Plan`]), made once
//! when the formula is built (see the module docs of [`super`]).

use crate::formula::Node;

/// No group: a leaf, or not yet decided.
pub(super) const NONE: u32 = u32::MAX;
/// Reached from more than one group: the node gets a group of its own.
const MANY: u32 = u32::MAX - 1;

/// How a node's values are held while its group is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Role {
    /// A variable or a constant: read in place, never stored.
    Leaf,
    /// An atom over leaves that all its readers fold in directly (`x > 3` in
    /// `x > 3 && y < 2`): never stored.
    Fused,
    /// A state node that only state nodes of its group read: a chunk buffer at a time.
    Chunk,
    /// A temporal node, a state node a temporal node reads, or a group's root: a buffer
    /// over the whole piece.
    Piece,
}

/// Nodes evaluated together over the same pieces of the trace.
#[derive(Clone, Debug, Default)]
pub(crate) struct Group {
    /// The node whose signal the group produces (the largest index in it).
    pub(super) root: usize,
    /// The state members that are stored (role `Chunk` or `Piece`), in index order.
    pub(super) state: Vec<usize>,
    /// The temporal members, in index order.
    pub(super) temporal: Vec<usize>,
}

/// How a formula is evaluated: its nodes cut into groups, computed in order.
///
/// Every node belongs to one group. A group's root is the formula's root, an unbounded
/// temporal node (computed over the whole trace at once), a node one of those reads, or a
/// node read from two groups; the other nodes join the group of their readers. A bounded
/// group is computed in pieces of `max(8192, 16 H)` steps, each with the `H` steps after
/// it, so its buffers stay in cache: `rho(t)` reads only `t ..= t + H`, so the overlap
/// gives the exact values. Other groups read a group's root from its whole signal. No node
/// is computed twice for one piece, so the cost is linear in the formula's size.
#[derive(Clone, Debug, Default)]
pub(crate) struct Plan {
    pub(super) groups: Vec<Group>,
    pub(super) role: Vec<Role>,
    /// The root of each node's group; `NONE` for leaves.
    pub(super) owner: Vec<u32>,
    /// Reads of each node by state nodes of its own group.
    pub(super) state_reads: Vec<u32>,
    /// Reads of each node by temporal nodes of its own group.
    pub(super) temporal_reads: Vec<u32>,
    /// Reads of a group's root by other groups, and one for the caller at the root.
    pub(super) ext_reads: Vec<u32>,
}

fn is_leaf(node: &Node) -> bool {
    matches!(node, Node::Var(_) | Node::Const(_))
}

impl Plan {
    /// The plan of canonical nodes with their horizons and state flags.
    pub(crate) fn new(
        nodes: &[Node],
        root: usize,
        horizon: &[Option<usize>],
        state: &[bool],
    ) -> Plan {
        let n = nodes.len();
        // Groups, from the root down: a node joins its readers' group when they agree.
        let mut cand = vec![NONE; n];
        let mut owner = vec![NONE; n];
        for v in (0..n).rev() {
            if is_leaf(&nodes[v]) {
                continue;
            }
            // A past-time node reads back to step 0, so it cannot run in pieces: like an
            // unbounded node it is a group of its own over whole signals.
            let whole = horizon[v].is_none() || nodes[v].is_past();
            let own = v == root || whole || cand[v] == MANY || cand[v] == NONE;
            owner[v] = if own { v as u32 } else { cand[v] };
            // A node that reads whole signals: each operand heads a group.
            let give = if whole { MANY } else { owner[v] };
            for c in nodes[v].children() {
                if !is_leaf(&nodes[c]) {
                    cand[c] = match cand[c] {
                        NONE => give,
                        x if x == give => x,
                        _ => MANY,
                    };
                }
            }
        }
        let mut state_reads = vec![0u32; n];
        let mut temporal_reads = vec![0u32; n];
        let mut ext_reads = vec![0u32; n];
        // Read whole by a state node (not folded in as an atom).
        let mut slice_read = vec![false; n];
        for v in 0..n {
            if is_leaf(&nodes[v]) {
                continue;
            }
            let folds = matches!(nodes[v], Node::And(_) | Node::Or(_));
            for c in nodes[v].children() {
                if is_leaf(&nodes[c]) {
                    continue;
                }
                if owner[c] != owner[v] {
                    ext_reads[c] += 1;
                } else if state[v] {
                    state_reads[c] += 1;
                    slice_read[c] |= !folds;
                } else {
                    temporal_reads[c] += 1;
                }
            }
        }
        ext_reads[root] += 1;
        let role: Vec<Role> = (0..n)
            .map(|v| {
                let node = &nodes[v];
                if is_leaf(node) {
                    Role::Leaf
                } else if owner[v] as usize == v || temporal_reads[v] > 0 || !state[v] {
                    Role::Piece
                } else if !slice_read[v] && fused_atom(nodes, v) {
                    Role::Fused
                } else {
                    Role::Chunk
                }
            })
            .collect();
        let mut group_of = vec![NONE; n];
        let mut groups = Vec::new();
        for v in 0..n {
            if owner[v] as usize == v {
                group_of[v] = groups.len() as u32;
                groups.push(Group { root: v, state: Vec::new(), temporal: Vec::new() });
            }
        }
        for v in 0..n {
            if matches!(role[v], Role::Leaf | Role::Fused) {
                continue;
            }
            let g = &mut groups[group_of[owner[v] as usize] as usize];
            if state[v] { g.state.push(v) } else { g.temporal.push(v) }
        }
        Plan { groups, role, owner, state_reads, temporal_reads, ext_reads }
    }
}

/// Whether node `v` is a comparison of two leaves (`x > 3`).
fn fused_atom(nodes: &[Node], v: usize) -> bool {
    match &nodes[v] {
        Node::Cmp { lhs, rhs, .. } => is_leaf(&nodes[lhs.index()]) && is_leaf(&nodes[rhs.index()]),
        _ => false,
    }
}
