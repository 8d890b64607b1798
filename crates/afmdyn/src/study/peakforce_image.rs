//! A PeakForce image as a study ([`PeakForceImageStudy`]: one task per line) and its local run
//! ([`peakforce_image`]); the image itself is [`crate::request::image_peakforce`].

use super::Study;
use crate::error::SimError;
use crate::request::image::{ImageRequest, SampleMap};
use crate::request::image_peakforce::{LinePixel, PeakForceImage, PeakForceImageStudy};
use serde_json::Value;
use std::collections::HashSet;
use std::sync::atomic::AtomicBool;

impl Study for PeakForceImageStudy {
    /// A line's number and its pixels.
    type Record = (usize, Vec<LinePixel>);
    /// The lines stored.
    type Done = HashSet<usize>;

    fn fingerprint(&self) -> &Value {
        &self.fingerprint
    }

    fn units(&self) -> u64 {
        self.lines() as u64
    }

    fn done_units(&self, done: &HashSet<usize>) -> u64 {
        done.len() as u64
    }

    fn record_units(&self, _: &(usize, Vec<LinePixel>)) -> u64 {
        1
    }

    fn run(
        &self,
        done: &HashSet<usize>,
        sink: &(dyn Fn((usize, Vec<LinePixel>)) + Sync),
        cancel: &AtomicBool,
    ) -> Result<(), SimError> {
        crate::analysis::tasks::run_independent(
            self.lines(),
            done,
            &|t| self.line(t).map(Some),
            &|t, l| sink((t, l)),
            cancel,
        )
    }
}

/// The PeakForce image of `map` under `probe_table` at the peak force `req.setpoint` (N)
/// ([`crate::request::image_peakforce`]), its lines on `threads` worker threads (`None`: all
/// cores) with progress and cancellation in `observer`.
///
/// # Errors
/// As [`PeakForceImageStudy::new`] and the lines; [`SimError::Cancelled`].
pub fn peakforce_image(
    probe_table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
    threads: Option<usize>,
    observer: &dyn super::Observer,
) -> Result<PeakForceImage, SimError> {
    let study = PeakForceImageStudy::new(probe_table, map, req)?;
    let records = super::execute_in_memory(&study, threads, observer)?;
    study.assemble(records)
}
