//! The PI scan of an image as a study (`ScanStudy::tasks`: one task per line) and its local run
//! ([`pi_image`]); the scan itself is [`crate::request::image_scan`].

use super::Tasks;
use crate::analysis::am_loop::ScanLine;
use crate::error::SimError;
use crate::request::image::{ImageRequest, SampleMap};
use crate::request::image_scan::{PiImage, PiScan, ScanStudy};

impl ScanStudy {
    /// The scan as a `Tasks` study: one task per line (its trace and retrace).
    pub(crate) fn tasks(&self) -> Tasks<'_, ScanLine> {
        Tasks::new(&self.fingerprint, self.lines(), |t, cancel| {
            self.line(t, cancel).map(Some)
        })
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
    let records = super::execute_in_memory(&study.tasks(), threads, observer)?;
    study.assemble(records)
}
