//! Rewards of option executions: the task's robustness over a segment of states, and
//! over every suffix of a segment.
//!
//! The semantics are those of [`reference::segment_reward`](crate::reference::segment_reward).

use crate::{Formula, Trace, reference};

/// Scores segments of a trace against one task, reusing its buffers between calls.
#[derive(Clone, Debug)]
pub struct SegmentScorer {
    task: Formula,
    suffix: Trace,
}

impl SegmentScorer {
    /// A scorer for `task`.
    pub fn new(task: &Formula) -> SegmentScorer {
        SegmentScorer { task: task.clone(), suffix: Trace::default() }
    }

    /// The reward of one option execution whose states are `segment`.
    pub fn reward(&mut self, segment: &Trace) -> f64 {
        reference::segment_reward(&self.task, segment)
    }

    /// `out[i]` becomes the reward of the suffix `segment[i..]`, for every `i`.
    pub fn suffix_rewards(&mut self, segment: &Trace, out: &mut Vec<f64>) {
        out.clear();
        let mut row = Vec::new();
        for i in 0..segment.len() {
            self.suffix = Trace::new(segment.vars());
            for t in i..segment.len() {
                segment.row_into(t, &mut row);
                self.suffix.push(&row).expect("rows come from a trace of the same width");
            }
            out.push(reference::segment_reward(&self.task, &self.suffix));
        }
    }
}

/// Scores segments given as indices into a fixed table of states, as tabular learners
/// see them. Per-state values are computed once, in [`TabularScorer::new`].
#[derive(Clone, Debug)]
pub struct TabularScorer {
    states: Trace,
    inner: SegmentScorer,
    segment: Trace,
}

impl TabularScorer {
    /// A scorer for `task` over `states`, whose row `i` is the state with index `i`.
    pub fn new(task: &Formula, states: &Trace) -> TabularScorer {
        TabularScorer {
            states: states.clone(),
            inner: SegmentScorer::new(task),
            segment: Trace::new(states.vars()),
        }
    }

    /// The reward of the option execution through the states `segment`.
    pub fn reward(&mut self, segment: &[usize]) -> f64 {
        self.load(segment);
        self.inner.reward(&self.segment)
    }

    /// `out[i]` becomes the reward of the suffix `segment[i..]`, for every `i`.
    pub fn suffix_rewards(&mut self, segment: &[usize], out: &mut Vec<f64>) {
        self.load(segment);
        self.inner.suffix_rewards(&self.segment, out);
    }

    fn load(&mut self, segment: &[usize]) {
        self.segment.clear();
        let mut row = Vec::new();
        for &s in segment {
            self.states.row_into(s, &mut row);
            self.segment.push(&row).expect("rows come from the state table");
        }
    }
}
