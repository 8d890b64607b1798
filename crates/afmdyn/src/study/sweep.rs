//! A bifurcation sweep as a [`Study`] ([`SweepStudy`]): a task is one point (a value reached
//! one way), its record the point's rows ([`SweepRecord`]), what a resume skips the stored
//! points with the chains' last states ([`Resume`]); the request layer's checkpoints
//! ([`Checkpoint`]: in memory, or a directory with the `files` feature) are its stores.

use super::{Opened, Store, Study};
use crate::analysis::bifurcation::{run_sweep_cancellable, Resume, SweepPoint, SweepSpec};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::request::checkpoint::{
    open, point_count, Checkpoint, CheckpointError, MemoryCheckpoint,
};
use crate::request::costs::{state_bytes, steady_periods, MODEL_BYTES};
use crate::request::limits::Cost;
use crate::request::run::{Analysis, Resolved};
use crate::request::sweep::{records, SweepRecord};
use crate::request::BifurcationRequest;
use serde_json::Value;
use std::sync::atomic::AtomicBool;

/// A bifurcation sweep as a [`Study`]: its spec and fingerprint. A task is one point (a
/// value reached one way), stored as its records; a resume skips the stored points and goes on
/// along each chain from its last stored state.
#[derive(Debug, Clone)]
pub struct SweepStudy {
    /// The validated sweep.
    pub spec: SweepSpec,
    /// What a resumed sweep must match (`crate::request::sweep::fingerprint`).
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

/// A bifurcation sweep through the one door ([`crate::request::run()`]): its cost checked
/// before any work, its records computed in memory (`super::execute_in_memory`) and put in
/// the one order (`crate::request::sweep::order_key`). A front end that runs the sweep
/// resumably into a store of its own (`afmdyn bifurcation --out DIR`) checks the same cost
/// first ([`crate::request::run::admit`]) and runs the [`SweepStudy`] itself.
impl Analysis for BifurcationRequest {
    type Output = Vec<SweepRecord>;
    fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        self.spec(&model.params).map(|_| ())
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError> {
        let study = SweepStudy::new(self, self.spec(&model.params)?);
        let mut records: Vec<SweepRecord> =
            super::execute_in_memory(&study, self.threads, progress)?
                .into_iter()
                .flatten()
                .collect();
        records.sort_by_key(crate::request::sweep::order_key);
        Ok(records)
    }
    fn name(&self) -> &'static str {
        "bifurcation"
    }
    fn cost(&self, model: &Resolved) -> Result<Cost, SimError> {
        // every point (each value reached forward, backward and from each random start) and
        // each continued branch's coarse pass over its chunks (at most one point a value):
        // the steady-state search to its transient cap, then the recorded periods (one cycle
        // of up to max_period, or nonperiodic_record), whose Poincaré points are the records
        let spec = self.spec(&model.params)?;
        let p = &spec.base;
        let values = spec.values.len() as f64;
        let points = crate::request::checkpoint::point_count(&spec) as f64;
        let coarse = if spec.continuation { 2.0 * values } else { 0.0 };
        let recorded = spec.steady.max_period.max(spec.steady.nonperiodic_record) as f64;
        // the transient cap at the range's ends (a model's decay, and with it the cap, moves
        // monotonically with one parameter)
        let (lo, hi) = (spec.values.iter()).fold((f64::INFINITY, f64::NEG_INFINITY), |b, &v| {
            (b.0.min(v), b.1.max(v))
        });
        let cap = steady_periods(&spec.steady, &p.with(spec.param, lo))?
            .max(steady_periods(&spec.steady, &p.with(spec.param, hi))?);
        let record = std::mem::size_of::<SweepRecord>() as f64 + state_bytes(p) + 64.0;
        Ok(Cost {
            bytes: MODEL_BYTES + points * recorded * record,
            work: (points + coarse) * (cap + recorded) * p.modes as f64,
        })
    }
    fn report(&self, model: &Resolved, records: &Self::Output) -> Result<Value, SimError> {
        let spec = self.spec(&model.params)?;
        let mut tally = crate::report::present::sweeps::SweepTally::default();
        for r in records {
            tally.add(r);
        }
        Ok(tally.document(&model.params, self.param, spec.values.len()))
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
