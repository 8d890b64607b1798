//! Checkpoints of a bifurcation sweep: a sweep writes each finished point to a store, and an
//! interrupted sweep resumes from it, computing exactly the points not yet stored — only when
//! the request is the one that made the store (its `fingerprint`).
//!
//! A store implements [`Checkpoint`]; [`MemoryCheckpoint`] keeps the records in memory, and
//! with the `files` feature `super::checkpoint_file::FileCheckpoint` keeps them in a
//! directory (the command line's `--out` with `--resume`, Python's `store=`).
//!
//! [`open`] decides where a sweep stands in its store; the sweep is a study
//! ([`crate::study::sweep::SweepStudy`]) that [`crate::study::execute`] computes into it, and
//! [`Checkpoint::finish`] puts the rows in the one order (`super::sweep::order_key`).

use super::sweep::{first_difference, SweepRecord};
use crate::analysis::bifurcation::{Branch, Resume, SweepSpec};
use nalgebra::DVector;
use serde_json::Value;
use thiserror::Error;

/// What can go wrong with a checkpoint.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CheckpointError {
    /// A resume with another request than the one that made the store: the first field that
    /// differs (a request field, or a model parameter such as `alpha4`) and its two values.
    #[error("{field} = {then} in the interrupted run, {now} now")]
    Mismatch {
        /// The field (`steps`, `alpha4`, `contact_law.kind`, …).
        field: String,
        /// Its value in the stored run.
        then: String,
        /// Its value in this request.
        now: String,
    },
    /// The store holds records but no fingerprint of the request that made them.
    #[error("{store} has sweep results but no record of the request that made them ({ledger} is missing)")]
    Unrecorded {
        /// The store (its directory).
        store: String,
        /// Where the fingerprint should be.
        ledger: String,
    },
    /// A file of the store cannot be read or written.
    #[error("cannot {action} {path}: {message}")]
    Io {
        /// What was being done (`read`, `write`, `remove`, …).
        action: &'static str,
        /// The file.
        path: String,
        /// The system's message.
        message: String,
    },
    /// A file of the store is not what the store wrote.
    #[error("{path}: {message}")]
    Corrupt {
        /// The file.
        path: String,
        /// What is wrong.
        message: String,
    },
}

/// The fingerprint a store holds and whether its sweep finished.
#[derive(Debug, Clone, PartialEq)]
pub struct Ledger {
    /// The fingerprint of the request that made the store.
    pub fingerprint: Value,
    /// The sweep finished and its rows are in the one order.
    pub finished: bool,
}

/// What a store holds.
#[derive(Debug, Clone, PartialEq)]
pub struct StoreStatus {
    /// Its ledger (`None`: none recorded).
    pub ledger: Option<Ledger>,
    /// It holds the records of an unfinished sweep.
    pub partial: bool,
    /// It holds the records of a finished sweep.
    pub complete: bool,
}

/// A point already stored: its key and, for a continuation point that did not fail, the
/// modal state of its last row (where the chain goes on).
#[derive(Debug, Clone, PartialEq)]
pub struct DonePoint {
    /// Index of the value.
    pub index: usize,
    /// How it was reached.
    pub branch: Branch,
    /// The end state of a continuation point (`None` for a failed point or a random start).
    pub state: Option<DVector<f64>>,
}

/// What a store of a sweep must do. The store owns its layout; the rows are
/// [`SweepRecord`]s, stored point by point (the records of one point together).
pub trait Checkpoint: Send {
    /// What the store holds.
    ///
    /// # Errors
    /// [`CheckpointError::Io`], or [`CheckpointError::Corrupt`] for an unreadable ledger.
    fn status(&mut self) -> Result<StoreStatus, CheckpointError>;

    /// Start a new sweep: drop every record, record `fingerprint` as unfinished.
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    fn begin(&mut self, fingerprint: &Value) -> Result<(), CheckpointError>;

    /// The points of the unfinished sweep stored completely, in the order they were stored;
    /// a point stored in part (an interrupted write) is dropped from the store.
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    fn done(&mut self) -> Result<Vec<DonePoint>, CheckpointError>;

    /// Store the records of one finished point (all of them, at once).
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    fn append(&mut self, point: &[SweepRecord]) -> Result<(), CheckpointError>;

    /// Put the records in the one order and mark the sweep of `fingerprint` finished.
    ///
    /// # Errors
    /// [`CheckpointError::Io`].
    fn finish(&mut self, fingerprint: &Value) -> Result<(), CheckpointError>;

    /// The store and where it keeps its ledger, as messages name them.
    fn names(&self) -> (String, String) {
        ("the store".into(), "its ledger".into())
    }
}

/// What is done from the stored points: their keys, and the end state of every stored
/// continuation point that did not fail (where its chain segment goes on).
pub(crate) fn resume_of(done: Vec<DonePoint>) -> Resume {
    let mut resume = Resume::default();
    for d in done {
        resume.done.insert((d.index, d.branch));
        if let Some(z) = d.state {
            if matches!(d.branch, Branch::Forward | Branch::Backward) {
                resume.chain.insert((d.index, d.branch), z);
            }
        }
    }
    resume
}

/// Where a sweep stands in `store`, before it runs. Without `resume` a new sweep begins (the
/// store's records are dropped). With `resume`: an empty store begins; a store of another
/// request is refused; an unfinished sweep resumes after its stored points; a finished one
/// needs nothing (`Ok(None)`).
///
/// # Errors
/// [`CheckpointError::Mismatch`] naming the first field that differs,
/// [`CheckpointError::Unrecorded`] for records without a ledger, and the store's errors.
pub fn open<C: Checkpoint + ?Sized>(
    store: &mut C,
    fingerprint: &Value,
    resume: bool,
) -> Result<Option<Resume>, CheckpointError> {
    if resume {
        let status = store.status()?;
        match status.ledger {
            None if status.partial || status.complete => {
                let (store, ledger) = store.names();
                return Err(CheckpointError::Unrecorded { store, ledger });
            }
            None => {}
            Some(ledger) => {
                same_request(&ledger.fingerprint, fingerprint, "")?;
                if status.partial {
                    return Ok(Some(resume_of(store.done()?)));
                }
                if ledger.finished && status.complete {
                    return Ok(None);
                }
            }
        }
    }
    store.begin(fingerprint)?;
    Ok(Some(Resume::default()))
}

/// Refuse a resume of the store whose ledger holds `stored` by the request of `fingerprint`
/// when they differ: [`CheckpointError::Mismatch`] naming the first field that differs
/// (without `prefix`, the study's own key, `"chart."`).
pub(crate) fn same_request(
    stored: &Value,
    fingerprint: &Value,
    prefix: &str,
) -> Result<(), CheckpointError> {
    // the stored fingerprint went through JSON text: so does this one, so that numbers
    // compare as they read back
    let now: Value =
        serde_json::from_str(&fingerprint.to_string()).unwrap_or_else(|_| fingerprint.clone());
    match first_difference(stored, &now) {
        Some((field, then, now)) => Err(CheckpointError::Mismatch {
            field: field.strip_prefix(prefix).unwrap_or(&field).to_string(),
            then,
            now,
        }),
        None => Ok(()),
    }
}

/// The number of points of a sweep: values × (2 with continuation + random starts).
pub fn point_count(spec: &SweepSpec) -> usize {
    spec.values.len() * (usize::from(spec.continuation) * 2 + spec.starts as usize)
}

/// A store in memory (for a sweep that needs no files, and as a test double).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MemoryCheckpoint {
    /// The ledger.
    pub ledger: Option<Ledger>,
    /// The stored points, each its records, in the order stored (after
    /// [`Checkpoint::finish`]: in the one order).
    pub points: Vec<Vec<SweepRecord>>,
}

impl MemoryCheckpoint {
    /// The records, point after point.
    #[cfg(any(test, feature = "files"))]
    pub(crate) fn into_records(self) -> Vec<SweepRecord> {
        self.points.into_iter().flatten().collect()
    }
}

/// The continuation state of a stored point: the state of its last record, unless it failed.
pub(crate) fn end_state(point: &[SweepRecord]) -> Option<DVector<f64>> {
    point
        .last()
        .filter(|r| r.status != super::sweep::PointStatus::Error && !r.state.is_empty())
        .map(|r| DVector::from_vec(r.state.clone()))
}

impl Checkpoint for MemoryCheckpoint {
    fn status(&mut self) -> Result<StoreStatus, CheckpointError> {
        let finished = self.ledger.as_ref().is_some_and(|l| l.finished);
        Ok(StoreStatus {
            ledger: self.ledger.clone(),
            partial: !finished && (self.ledger.is_some() || !self.points.is_empty()),
            complete: finished,
        })
    }

    fn begin(&mut self, fingerprint: &Value) -> Result<(), CheckpointError> {
        self.points.clear();
        self.ledger = Some(Ledger {
            fingerprint: fingerprint.clone(),
            finished: false,
        });
        Ok(())
    }

    fn done(&mut self) -> Result<Vec<DonePoint>, CheckpointError> {
        Ok(self
            .points
            .iter()
            .filter_map(|p| {
                let first = p.first()?;
                Some(DonePoint {
                    index: first.index,
                    branch: first.branch,
                    state: end_state(p),
                })
            })
            .collect())
    }

    fn append(&mut self, point: &[SweepRecord]) -> Result<(), CheckpointError> {
        self.points.push(point.to_vec());
        Ok(())
    }

    fn finish(&mut self, fingerprint: &Value) -> Result<(), CheckpointError> {
        self.points
            .sort_by_key(|p| p.first().map(|r| (r.index, r.branch)));
        self.ledger = Some(Ledger {
            fingerprint: fingerprint.clone(),
            finished: true,
        });
        Ok(())
    }
}
