//! What every store of a study shares (its stores, beside it here: in memory, or with
//! the `files` feature a directory): its errors ([`CheckpointError`]), its ledger ([`Ledger`]:
//! the fingerprint of the request that made it — a resume of another request is refused,
//! naming the first field that differs — and whether it finished), and of a bifurcation
//! sweep's checkpoint the state a stored point's chain goes on
//! from.

use crate::request::sweep::{first_difference, SweepRecord};
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

/// The fingerprint a store holds and whether its study finished.
#[derive(Debug, Clone, PartialEq)]
pub struct Ledger {
    /// The fingerprint of the request that made the store.
    pub fingerprint: Value,
    /// The study finished and its records are in the one order.
    pub finished: bool,
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

/// The continuation state of a stored point: the state of its last record, unless it failed.
pub(crate) fn end_state(point: &[SweepRecord]) -> Option<DVector<f64>> {
    point
        .last()
        .filter(|r| r.status != crate::request::sweep::PointStatus::Error && !r.state.is_empty())
        .map(|r| DVector::from_vec(r.state.clone()))
}
