//! A bifurcation sweep as a [`Study`] ([`SweepStudy`]): a task is one point (a value reached
//! one way), its record the point's rows ([`SweepRecord`]), what a resume skips the stored
//! points with the chains' last states ([`Resume`]); the request layer's checkpoints
//! ([`Checkpoint`]: in memory, or a directory with the `files` feature) are its stores.

use super::{Opened, Store, Study};
use crate::analysis::bifurcation::{run_sweep_cancellable, Resume, SweepPoint, SweepSpec};
use crate::request::checkpoint::{
    open, point_count, Checkpoint, CheckpointError, MemoryCheckpoint,
};
use crate::request::sweep::{records, SweepRecord};
use serde_json::Value;
use std::sync::atomic::AtomicBool;

/// A bifurcation sweep as a [`Study`]: its spec and fingerprint. A task is one point (a
/// value reached one way), stored as its records; a resume skips the stored points and goes on
/// along each chain from its last stored state.
#[derive(Debug, Clone)]
pub struct SweepStudy {
    /// The validated sweep.
    pub spec: SweepSpec,
    /// What a resumed sweep must match ([`crate::request::sweep::fingerprint`]).
    pub fingerprint: Value,
}

impl SweepStudy {
    /// The study of `spec`, validated from `request`.
    pub fn new(request: &crate::request::BifurcationRequest, spec: SweepSpec) -> SweepStudy {
        let fingerprint = crate::request::sweep::fingerprint(request, &spec);
        SweepStudy { spec, fingerprint }
    }
}

impl Study for SweepStudy {
    type Record = Vec<SweepRecord>;
    type Done = Resume;

    fn fingerprint(&self) -> &Value {
        &self.fingerprint
    }

    fn units(&self) -> u64 {
        point_count(&self.spec) as u64
    }

    fn done_units(&self, done: &Resume) -> u64 {
        done.done.len() as u64
    }

    fn record_units(&self, _: &Vec<SweepRecord>) -> u64 {
        1
    }

    fn run(
        &self,
        done: &Resume,
        sink: &(dyn Fn(Vec<SweepRecord>) + Sync),
        cancel: &AtomicBool,
    ) -> Result<(), crate::error::SimError> {
        // a point that fails is a row with its status and message: no task fails
        let param = self.spec.param;
        run_sweep_cancellable(
            &self.spec,
            done,
            &|p: SweepPoint| sink(records(param, &p)),
            cancel,
        );
        Ok(())
    }
}

/// [`Store`] of a sweep for a [`Checkpoint`]: [`open`], [`Checkpoint::append`],
/// [`Checkpoint::finish`].
macro_rules! sweep_store {
    ($t:ty) => {
        impl Store<SweepStudy> for $t {
            fn open(
                &mut self,
                study: &SweepStudy,
                resume: bool,
            ) -> Result<Opened<Resume>, CheckpointError> {
                Ok(match open(self, &study.fingerprint, resume)? {
                    Some(r) => Opened::Run(r),
                    None => Opened::Finished,
                })
            }

            fn append(&mut self, record: Vec<SweepRecord>) -> Result<(), CheckpointError> {
                Checkpoint::append(self, &record)
            }

            fn finish(&mut self, study: &SweepStudy) -> Result<(), CheckpointError> {
                Checkpoint::finish(self, &study.fingerprint)
            }
        }
    };
}

sweep_store!(MemoryCheckpoint);
#[cfg(feature = "files")]
sweep_store!(crate::request::checkpoint_file::FileCheckpoint<'_>);

#[cfg(test)]
#[path = "sweep_tests.rs"]
mod tests;
