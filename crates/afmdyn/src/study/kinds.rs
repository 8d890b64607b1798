//! The two kinds of study every analysis of many tasks is made of (a bifurcation sweep, whose
//! branches continue across its points, is the third: [`super::sweep`]):
//!
//! - [`Tasks`]: independent tasks `0..n`, each computing its record from its number alone, run
//!   in parallel (one task a work item), the stored ones skipped — a chart's tiles
//!   ([`crate::request::chart::Chart::tasks`]), an image's lines (PI-scanned, PeakForce). A
//!   resume reads only the numbers stored.
//! - [`Chain`]: tasks whose later ones start from the earlier ones' records — a stepped curve's
//!   points, a global continuation's values, a PeakForce sweep's taps, a basin map's passes. A
//!   resume reads the stored records back (`D`: [`Prefix`], the first unbroken ones; or
//!   `Vec<R>`, every one) and the chain goes on from them.
//!
//! Each former study is a constructor of one of them: its data, and a task function (a
//! [`Tasks`]) or the run of its chain (a [`Chain`]). The parallel loop, the cancellation, the
//! units and the handling of the stored tasks are written here once. Every task depends only
//! on the request and its number (or, in a chain, on the records before it), so results do not
//! depend on the thread count.

use super::{Prefix, Study};
use crate::error::SimError;
use serde_json::Value;
use std::collections::HashSet;
use std::sync::atomic::AtomicBool;

/// A task of a [`Tasks`] study: its record, or `None` (cut short, not sent).
type Task<'a, R> = Box<dyn Fn(usize, &AtomicBool) -> Result<Option<R>, SimError> + Sync + 'a>;

/// A study of independent tasks `0..n` (see the module doc).
pub(crate) struct Tasks<'a, R> {
    fingerprint: &'a Value,
    count: usize,
    units: Box<dyn Fn(usize) -> u64 + Sync + 'a>,
    task: Task<'a, R>,
}

impl<'a, R> Tasks<'a, R> {
    /// The study of `count` tasks, `task(t, cancel)` computing task `t` (one progress unit
    /// each), fingerprinted `fingerprint`.
    pub(crate) fn new(
        fingerprint: &'a Value,
        count: usize,
        task: impl Fn(usize, &AtomicBool) -> Result<Option<R>, SimError> + Sync + 'a,
    ) -> Tasks<'a, R> {
        Tasks {
            fingerprint,
            count,
            units: Box::new(|_| 1),
            task: Box::new(task),
        }
    }

    /// The study with `units(t)` progress units in task `t` (a chart tile's cells).
    pub(crate) fn weighted(self, units: impl Fn(usize) -> u64 + Sync + 'a) -> Tasks<'a, R> {
        Tasks {
            units: Box::new(units),
            ..self
        }
    }
}

impl<R: Send> Study for Tasks<'_, R> {
    /// A task's number and its record.
    type Record = (usize, R);
    /// The tasks stored.
    type Done = HashSet<usize>;

    fn fingerprint(&self) -> &Value {
        self.fingerprint
    }

    fn units(&self) -> u64 {
        (0..self.count).map(&self.units).sum()
    }

    fn done_units(&self, done: &HashSet<usize>) -> u64 {
        done.iter().map(|&t| (self.units)(t)).sum()
    }

    fn record_units(&self, record: &(usize, R)) -> u64 {
        (self.units)(record.0)
    }

    fn run(
        &self,
        done: &HashSet<usize>,
        sink: &(dyn Fn((usize, R)) + Sync),
        cancel: &AtomicBool,
    ) -> Result<(), SimError> {
        crate::analysis::tasks::run_independent(
            self.count,
            done,
            &|t| (self.task)(t, cancel),
            &|t, r| sink((t, r)),
            cancel,
        )
    }
}

/// The run of a [`Chain`]: from the stored records, every task after them, each handed to the
/// sink with its number as it finishes.
type Run<'a, R> =
    Box<dyn Fn(&[R], &(dyn Fn(usize, R) + Sync), &AtomicBool) -> Result<(), SimError> + Sync + 'a>;

/// A study whose tasks start from the records before them (see the module doc); `D` is what
/// a resume reads back: [`Prefix`] (the first unbroken records) or `Vec<R>` (every one).
pub(crate) struct Chain<'a, R, D = Prefix<R>> {
    fingerprint: &'a Value,
    units: u64,
    unit: Box<dyn Fn(&R) -> u64 + Sync + 'a>,
    run: Run<'a, R>,
    done: std::marker::PhantomData<fn() -> D>,
}

impl<'a, R, D> Chain<'a, R, D> {
    /// The chain of `tasks` tasks (one progress unit each), fingerprinted `fingerprint`, that
    /// `run(stored, sink, cancel)` computes after the `stored` records.
    pub(crate) fn new<F>(fingerprint: &'a Value, tasks: usize, run: F) -> Chain<'a, R, D>
    where
        F: Fn(&[R], &(dyn Fn(usize, R) + Sync), &AtomicBool) -> Result<(), SimError> + Sync + 'a,
    {
        Chain {
            fingerprint,
            units: tasks as u64,
            unit: Box::new(|_| 1),
            run: Box::new(run),
            done: std::marker::PhantomData,
        }
    }

    /// The chain counted in `units` progress units, `unit(record)` in each record (a basin
    /// row's cells, a continuation value's random starts).
    pub(crate) fn weighted(
        self,
        units: u64,
        unit: impl Fn(&R) -> u64 + Sync + 'a,
    ) -> Chain<'a, R, D> {
        Chain {
            units,
            unit: Box::new(unit),
            ..self
        }
    }
}

impl<R: Send, D: AsRef<[R]> + Default + Send + Sync> Study for Chain<'_, R, D> {
    /// A task's number and its record.
    type Record = (usize, R);
    /// The stored records a resume starts from.
    type Done = D;

    fn fingerprint(&self) -> &Value {
        self.fingerprint
    }

    fn units(&self) -> u64 {
        self.units
    }

    fn done_units(&self, done: &D) -> u64 {
        done.as_ref().iter().map(&self.unit).sum()
    }

    fn record_units(&self, record: &(usize, R)) -> u64 {
        (self.unit)(&record.1)
    }

    fn run(
        &self,
        done: &D,
        sink: &(dyn Fn((usize, R)) + Sync),
        cancel: &AtomicBool,
    ) -> Result<(), SimError> {
        (self.run)(done.as_ref(), &|t, r| sink((t, r)), cancel)
    }
}

/// The records of a finished study of `tasks` tasks (in any order), in the order of the tasks.
///
/// # Errors
/// [`SimError::Cancelled`] when a task is missing (a run cut short).
pub(crate) fn in_order<R>(mut records: Vec<(usize, R)>, tasks: usize) -> Result<Vec<R>, SimError> {
    records.sort_by_key(|(t, _)| *t);
    if records.len() != tasks || records.iter().enumerate().any(|(i, (t, _))| *t != i) {
        return Err(SimError::Cancelled);
    }
    Ok(records.into_iter().map(|(_, r)| r).collect())
}

impl<R> AsRef<[R]> for Prefix<R> {
    fn as_ref(&self) -> &[R] {
        &self.0
    }
}
