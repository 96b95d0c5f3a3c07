//! Stopping an offline evaluation that nobody waits for any more (a call the user
//! interrupted): a flag raised from another thread, looked at by the evaluator on this
//! thread between the groups and pieces it computes, and within a long group between
//! chunks of 512 steps of its state members and between its temporal ones (the dense and
//! the complete-window evaluators: between the formula's nodes), so that no single piece
//! of work runs long after it. An evaluation stopped so returns NaN at every step: its result
//! means nothing, so only a caller that will drop it raises the flag. Evaluations on
//! threads without a flag are never stopped.

use std::cell::RefCell;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

thread_local! {
    static FLAG: RefCell<Option<Arc<AtomicBool>>> = const { RefCell::new(None) };
}

/// While alive, the offline evaluations on this thread stop once `flag` is raised; the
/// thread's flag before is restored when it is dropped.
#[must_use = "the flag is watched only while the guard lives"]
pub struct StopOnFlag {
    previous: Option<Arc<AtomicBool>>,
}

/// Watches `flag` for the offline evaluations on this thread (see the module docs).
pub fn stop_on(flag: Arc<AtomicBool>) -> StopOnFlag {
    let previous = FLAG.with(|f| f.borrow_mut().replace(flag));
    StopOnFlag { previous }
}

impl Drop for StopOnFlag {
    fn drop(&mut self) {
        let previous = self.previous.take();
        FLAG.with(|f| *f.borrow_mut() = previous);
    }
}

/// This thread's flag, for the threads it starts to watch too.
pub fn current() -> Option<Arc<AtomicBool>> {
    FLAG.with(|f| f.borrow().clone())
}

/// Whether this thread's flag is raised: for work outside the evaluator that a stopped
/// evaluation makes pointless (the facade's scan of a trace for NaN comparisons).
pub fn requested() -> bool {
    FLAG.with(|f| f.borrow().as_ref().is_some_and(|flag| flag.load(Ordering::Relaxed)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Bound, CmpOp, Evaluator, Expr, Formula, Interval, Trace};

    #[test]
    fn a_raised_flag_stops_the_evaluation_on_its_thread_only() {
        let x = Formula::cmp(Expr::var(0), CmpOp::Gt, Expr::constant(0.5));
        let f = Formula::eventually(Interval { start: 0, end: Bound::Inclusive(3) }, x);
        let trace = Trace::from_columns(vec![vec![0.0, 1.0, 0.0, 0.0, 0.0, 1.0]]).unwrap();
        let want = Evaluator::new().signal(&f, &trace).to_vec();
        let flag = Arc::new(AtomicBool::new(false));
        {
            let _watch = stop_on(Arc::clone(&flag));
            assert_eq!(Evaluator::new().signal(&f, &trace), &want[..], "not raised yet");
            flag.store(true, Ordering::Relaxed);
            let stopped = Evaluator::new().signal(&f, &trace).to_vec();
            assert_eq!(stopped.len(), want.len());
            assert!(stopped.iter().all(|v| v.is_nan()), "{stopped:?}");
            // Another thread has no flag.
            let other = std::thread::scope(|s| {
                s.spawn(|| Evaluator::new().signal(&f, &trace).to_vec()).join().unwrap()
            });
            assert_eq!(other, want);
        }
        // The guard gone, the thread is watched no more.
        assert_eq!(Evaluator::new().signal(&f, &trace), &want[..]);
    }

    #[test]
    fn a_raised_flag_stops_a_dense_evaluation() {
        use crate::dense::{DenseFormula, DenseTrace, TimeScale};
        let x = Formula::cmp(Expr::var(0), CmpOp::Gt, Expr::constant(0.5));
        let f = Formula::eventually(Interval { start: 0, end: Bound::Inclusive(3) }, x);
        let df = DenseFormula::new(&f, TimeScale::decimals(2)).unwrap();
        let trace = DenseTrace::from_samples(&[vec![(0.0, 0.0), (1.5, 1.0), (4.0, 0.0)]]).unwrap();
        let want = df.signal(&trace).unwrap();
        assert!(want.points().all(|(_, v)| !v.is_nan()));
        let flag = Arc::new(AtomicBool::new(true));
        let _watch = stop_on(flag);
        let stopped = df.signal(&trace).unwrap();
        assert!(
            stopped.points().all(|(_, v)| v.is_nan()),
            "{:?}",
            stopped.points().collect::<Vec<_>>()
        );
    }
}
