//! A PeakForce image as a study (`PeakForceImageStudy::tasks`: one task per line) and its local run
//! ([`peakforce_image`]); the image itself is [`crate::request::image_peakforce`].

use super::Tasks;
use crate::error::SimError;
use crate::request::image::{ImageRequest, SampleMap};
use crate::request::image_peakforce::{LinePixel, PeakForceImage, PeakForceImageStudy};

impl PeakForceImageStudy {
    /// The image as a `Tasks` study: one task per line (its pixels).
    pub(crate) fn tasks(&self) -> Tasks<'_, Vec<LinePixel>> {
        Tasks::new(&self.fingerprint, self.lines(), |t, _| {
            self.line(t).map(Some)
        })
    }
}

/// The PeakForce image of `map` under `probe_table` at the peak force `req.setpoint` (N)
/// ([`crate::request::image_peakforce`]), its lines on `threads` worker threads (`None`: all
/// cores) with progress and cancellation in `observer`.
///
/// # Errors
/// As [`PeakForceImageStudy::new`] and the lines; [`SimError::Cancelled`].
pub(crate) fn peakforce_image(
    probe_table: &toml::Table,
    map: &SampleMap,
    req: &ImageRequest,
    threads: Option<usize>,
    observer: &dyn super::Observer,
) -> Result<PeakForceImage, SimError> {
    let study = PeakForceImageStudy::new(probe_table, map, req)?;
    let records = super::execute_in_memory(&study.tasks(), threads, observer)?;
    study.assemble(records)
}
