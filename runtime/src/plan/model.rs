//! The transitions seen in training, the tabular model the planner reads.

/// The transitions seen in training: for each state and action, the states it led to and
/// how often.
#[derive(Clone, Debug)]
pub(crate) struct Model {
    actions: usize,
    /// `next[s * actions + a]`: (next state, count).
    next: Vec<Vec<(usize, u32)>>,
    /// `starts[s]`: the episodes that started in `s`.
    starts: Vec<u32>,
}

impl Model {
    /// An empty model of `states` states and `actions` actions.
    pub fn new(states: usize, actions: usize) -> Model {
        Model { actions, next: vec![Vec::new(); states * actions], starts: vec![0; states] }
    }

    /// Counts an episode that starts in `s`.
    pub fn start(&mut self, s: usize) {
        if let Some(c) = self.starts.get_mut(s) {
            *c = c.saturating_add(1);
        }
    }

    /// `starts()[s]`: the episodes counted as starting in `s`.
    pub fn starts(&self) -> &[u32] {
        &self.starts
    }

    /// Counts one step `s -a-> next`.
    #[inline]
    pub fn record(&mut self, s: usize, a: usize, next: usize) {
        let row = &mut self.next[s * self.actions + a];
        match row.iter_mut().find(|(n, _)| *n == next) {
            Some((_, c)) => *c = c.saturating_add(1),
            None => row.push((next, 1)),
        }
    }

    /// `moves[s * actions + a]`: the estimated distribution of the state after `a` in `s`
    /// (empty if never tried), which both of the planner's steps read.
    pub fn moves(&self) -> Vec<Vec<(usize, f64)>> {
        self.next
            .iter()
            .map(|row| {
                let total: f64 = row.iter().map(|&(_, c)| f64::from(c)).sum();
                row.iter().map(|&(n, c)| (n, f64::from(c) / total)).collect()
            })
            .collect()
    }
}
