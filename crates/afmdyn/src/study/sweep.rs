//! A bifurcation sweep as a [`Study`] ([`SweepStudy`]): a task is one point (a value reached
//! one way), its record the point's rows ([`SweepRecord`]), what a resume skips the stored
//! points with the chains' last states ([`Resume`]). Its stores are every study's: in memory
//! ([`super::MemoryStore`]), or with the `files` feature its checkpoint's CSV in a directory
//! (a `TaskStore` written by `SweepRows`).

use super::{Resumes, Study};
use crate::analysis::bifurcation::{run_sweep_cancellable, Branch, Resume, SweepPoint, SweepSpec};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::report::sweep::PointStatus;
use crate::report::Convergence;
use crate::request::run::{Analysis, Resolved};
use crate::request::sweep::point_count;
use crate::request::sweep::{records, SweepRecord};
use crate::request::BifurcationRequest;
use crate::study::checkpoint::end_state;
use serde_json::Value;
use std::sync::atomic::AtomicBool;

/// A bifurcation sweep as a [`Study`]: its spec and fingerprint. A task is one point (a
/// value reached one way), stored as its records; a resume skips the stored points and goes on
/// along each chain from its last stored state.
#[derive(Debug, Clone)]
pub struct SweepStudy {
    /// The validated sweep.
    pub spec: SweepSpec,
    /// What a resumed sweep must match (`crate::request::analyses::fingerprint`).
    pub fingerprint: Value,
}

impl SweepStudy {
    /// The study of `spec`, validated from `request`.
    pub fn new(request: &crate::request::BifurcationRequest, spec: SweepSpec) -> SweepStudy {
        let fingerprint = crate::request::analyses::fingerprint(request, &spec);
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

    fn order(&self, points: &mut [Vec<SweepRecord>]) {
        points.sort_by_key(|p| p.first().map(|r| (r.index, r.branch)));
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
    fn convergence(&self, records: &Self::Output) -> Convergence {
        Convergence::count("points", records, |r| r.status != PointStatus::Error)
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
    fn report(&self, model: &Resolved, records: &Self::Output) -> Result<Value, SimError> {
        let spec = self.spec(&model.params)?;
        let mut tally = crate::report::present::sweeps::SweepTally::default();
        for r in records {
            tally.add(r);
        }
        Ok(tally.document(&model.params, self.param, spec.values.len()))
    }
}

/// A resumed sweep skips its stored points and goes on along each continued branch from the
/// state of its last stored point that did not fail.
impl Resumes<Vec<SweepRecord>> for Resume {
    type Gathered = Resume;
    fn gather(resume: &mut Resume, point: &Vec<SweepRecord>) {
        let Some(first) = point.first() else { return };
        let key = (first.index, first.branch);
        resume.done.insert(key);
        if let Some(z) = end_state(point) {
            if matches!(first.branch, Branch::Forward | Branch::Backward) {
                resume.chain.insert(key, z);
            }
        }
    }
    fn done(resume: Resume) -> Resume {
        resume
    }
}

/// The codec of a sweep's checkpoint (the directory's `.bifurcation.run.json` and
/// `.bifurcation.partial.csv`, its rows put in the one order in `bifurcation.csv` when the
/// sweep finishes: `crate::study::checkpoint_file`), a point's rows stored together.
#[cfg(feature = "files")]
#[derive(Debug, Clone, Copy)]
pub(crate) struct SweepRows;

#[cfg(feature = "files")]
impl super::task_store::Codec for SweepRows {
    type Record = Vec<SweepRecord>;

    fn layout(&self) -> super::task_store::Layout {
        use crate::study::checkpoint_file::{FINAL_CSV, LEDGER, PARTIAL_CSV};
        super::task_store::Layout {
            ledger: LEDGER,
            records: PARTIAL_CSV,
            prefix: "",
            format: None,
            finished: Some(FINAL_CSV),
            ledger_by_path: true,
        }
    }

    fn header(&self) -> Option<String> {
        Some(crate::study::checkpoint_file::partial_header())
    }

    fn encode(&self, point: &Vec<SweepRecord>) -> Result<String, String> {
        let seal = |r: &SweepRecord| crate::study::checkpoint_file::sealed(&r.csv_line()) + "\n";
        Ok(point.iter().map(seal).collect())
    }

    fn read(
        &self,
        path: &std::path::Path,
        each: &mut dyn FnMut(Vec<SweepRecord>),
    ) -> Result<(), crate::study::checkpoint::CheckpointError> {
        crate::study::checkpoint_file::read_points(path, each)
    }

    fn finish(
        &self,
        dir: &std::path::Path,
    ) -> Result<(), crate::study::checkpoint::CheckpointError> {
        crate::study::checkpoint_file::sort_into_final(dir)
    }
}

/// A sweep's checkpoint in the directory a lock holds.
#[cfg(feature = "files")]
pub(crate) type SweepCheckpoint<'a> = super::task_store::TaskStore<'a, SweepRows>;

/// The sweep's checkpoint in the directory `lock` holds.
#[cfg(feature = "files")]
pub(crate) fn sweep_checkpoint(lock: &crate::io::dir_lock::DirLock) -> SweepCheckpoint<'_> {
    super::task_store::TaskStore::new(lock, SweepRows)
}

#[cfg(test)]
mod tests;
