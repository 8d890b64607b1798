//! The PI scan of an image as a study ([`ScanStudy`]: one task per line) and its local run
//! ([`pi_image`]); the scan itself is [`crate::request::image_scan`].

use super::Study;
use crate::analysis::am_loop::{scan_lines, ScanLine};
use crate::error::SimError;
use crate::request::image::{ImageRequest, SampleMap};
use crate::request::image_scan::{PiImage, PiScan, ScanStudy};
use serde_json::Value;
use std::collections::HashSet;
use std::sync::atomic::AtomicBool;

impl Study for ScanStudy {
    /// A line's number and its trace and retrace.
    type Record = (usize, ScanLine);
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

    fn record_units(&self, _: &(usize, ScanLine)) -> u64 {
        1
    }

    fn run(
        &self,
        done: &HashSet<usize>,
        sink: &(dyn Fn((usize, ScanLine)) + Sync),
        cancel: &AtomicBool,
    ) -> Result<(), SimError> {
        scan_lines(
            self.lines(),
            done,
            &|t| self.line(t, cancel),
            &|t, l| sink((t, l)),
            cancel,
        )
    }
}

/// The PI-scanned image of `map` under `probe_table` ([`crate::request::image_scan`]), its lines on
/// `threads` worker threads (`None`: all cores) with progress and cancellation in `observer`.
///
/// # Errors
/// As `ScanStudy::new` and the lines; [`SimError::Cancelled`].
pub fn pi_image(
    probe_table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
    scan: &PiScan,
    threads: Option<usize>,
    observer: &dyn super::Observer,
) -> Result<PiImage, SimError> {
    let study = ScanStudy::new(probe_table, map, req, scan)?;
    let mut store = super::MemoryStore::default();
    match super::execute(&study, &mut store, false, threads, observer) {
        Ok(super::Outcome::Cancelled) => return Err(SimError::Cancelled),
        Ok(_) => {}
        Err(super::StudyError::Sim(e)) => return Err(e),
        Err(super::StudyError::Store(e)) => {
            return Err(SimError::Probe(format!("the scan's store: {e}")))
        }
    }
    study.assemble(store.records)
}
