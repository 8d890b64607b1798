//! Progress and cancellation of a long analysis, shared between the run and its caller.
//!
//! The analysis counts the units of work it finishes (random starts, curve points, continuation
//! points, drive periods, mode counts) and checks the cancel flag between units; a front end
//! reads the count from another thread — the command line's progress bar, Python's poll loop,
//! later a Dask worker's heartbeat — and sets the flag to stop the run, which then returns
//! [`SimError::Cancelled`]. Everything is an atomic: a parallel analysis ticks from every
//! worker without a lock, and the results never depend on when (or whether) anyone reads.
//!
//! A cancel reaches every loop that integrates, not only those that take the flag: the door
//! runs an analysis under `Progress::watch`, which makes the flag this thread's watched one,
//! and [`crate::integrate::advance`], the steady-state search, Newton's chunks from the
//! transient and the recording of a trajectory end with [`SimError::Cancelled`] at their next
//! step once it is set (`crate::error::cancelled`). A study's executor carries the watched flag
//! onto its pool (`crate::error::watched`, `watching`) and stores nothing after a cancel, so
//! that a task cut short is never kept as a result.

use crate::error::{watching, SimError};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

/// The progress counter and cancel flag of one run (see the module docs).
#[derive(Debug, Default)]
pub struct Progress {
    done: AtomicUsize,
    total: AtomicUsize,
    cancel: Arc<AtomicBool>,
}

impl Progress {
    /// A counter at 0 of an unknown total, not cancelled.
    pub fn new() -> Self {
        Self::default()
    }
    /// Add `n` units to the expected total (a run that learns its size as it goes adds more).
    pub(crate) fn add_total(&self, n: usize) {
        self.total.fetch_add(n, Ordering::Relaxed);
    }
    /// Units expected, when known.
    pub fn total(&self) -> Option<usize> {
        match self.total.load(Ordering::Relaxed) {
            0 => None,
            n => Some(n),
        }
    }
    /// Count `n` units done.
    pub(crate) fn advance(&self, n: usize) {
        self.done.fetch_add(n, Ordering::Relaxed);
    }
    /// Count one unit done.
    pub fn tick(&self) {
        self.advance(1);
    }
    /// Units done so far.
    pub fn done(&self) -> usize {
        self.done.load(Ordering::Relaxed)
    }
    /// Ask the run to stop at its next check.
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
    /// Whether the run was asked to stop.
    pub(crate) fn is_cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
    /// The cancel flag itself, for the analyses that take one
    /// ([`crate::analysis::bifurcation::run_sweep_cancellable`]).
    pub(crate) fn cancel_flag(&self) -> &AtomicBool {
        &self.cancel
    }
    /// Run `f` with this run's cancel flag watched on this thread (`crate::error::cancelled`).
    pub(crate) fn watch<T>(&self, f: impl FnOnce() -> T) -> T {
        watching(Some(self.cancel.clone()), f)
    }
    /// `Ok` while the run may go on.
    ///
    /// # Errors
    /// [`SimError::Cancelled`] once [`Progress::cancel`] was called.
    pub fn check(&self) -> Result<(), SimError> {
        if self.is_cancelled() {
            Err(SimError::Cancelled)
        } else {
            Ok(())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_and_cancels() {
        let p = Progress::new();
        assert_eq!((p.done(), p.total()), (0, None));
        p.add_total(3);
        p.tick();
        p.advance(2);
        assert_eq!((p.done(), p.total()), (3, Some(3)));
        assert!(p.check().is_ok());
        p.cancel();
        assert!(matches!(p.check(), Err(SimError::Cancelled)));
    }
}
