//! `image` as data ([`ImageJob`]): the probe file's table, the sample map, the request, the
//! feedback (ideal, or a PI scan with its settings) and the setpoint study; its run as an
//! [`super::run::Analysis`] (cost, execution, document and presentation) is the study layer's
//! (`crate::study::image`), and so is its PI scan's run resumably into a store
//! (`crate::study::stored::Resumable`, its study `ImageJob::scan_study`).

use super::image::{background_probe, Image, ImageRequest, SampleMap, SetpointStudy};
use super::image_options::GivenOptions;
use super::image_scan::{PiImage, PiScan};
#[cfg(feature = "files")]
use super::image_scan::{ScanRecipe, ScanStudy};
use super::named::Outcome;
use super::run::Resolved;
use crate::error::SimError;
use crate::report::image::PeakForceImage;
use serde::{Deserialize, Serialize};

pub use super::image_options::ImageMode;

/// An image request with its inputs ([module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct ImageJob {
    /// The imaging mode (AM: the request's setpoint is A_sp/A₀; PeakForce: the peak force in
    /// N).
    pub mode: ImageMode,
    /// The probe file's table (SI): the lever, tip, drive and the background sample.
    pub probe: toml::Table,
    /// The sample map.
    pub sample: SampleMap,
    /// The image request.
    pub request: ImageRequest,
    /// `None`: the ideal feedback; else a PI scan with these settings.
    pub feedback: Option<PiScan>,
    /// The setpoint study's ratios (the ideal feedback only).
    pub study: Option<Vec<f64>>,
    /// A PI scan's worker threads (`None`: all cores).
    pub threads: Option<usize>,
}

/// An [`ImageJob`]'s result.
// one value a run, its bulk on the heap: the variants' sizes do not matter
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum ImageOutput {
    /// An ideal-feedback image and its setpoint study.
    Ideal {
        /// The image.
        image: Image,
        /// The setpoint study, when one was asked for.
        study: Option<SetpointStudy>,
    },
    /// A PI-scanned image.
    Pi(PiImage),
    /// A PeakForce image (ideal peak-force feedback).
    PeakForce(PeakForceImage),
}

impl ImageJob {
    /// The model the job runs on: the background probe's parameters, without the SI block
    /// (the image's documents are in SI already).
    ///
    /// # Errors
    /// As the background probe's reading: a probe the format refuses, a multifrequency drive.
    pub fn model(&self) -> Result<Resolved, SimError> {
        Ok(Resolved::plain(background_probe(&self.probe)?.params))
    }

    /// The PI scan's study (its materials' approach curves computed), for a front end that
    /// runs it into a store of its own; `None` for the ideal feedback.
    ///
    /// # Errors
    /// As [`ScanStudy::new`].
    #[cfg(feature = "files")]
    pub(crate) fn scan_study(&self) -> Result<Option<ScanStudy>, SimError> {
        self.feedback
            .as_ref()
            .map(|scan| ScanStudy::new(&self.probe, &self.sample, &self.request, scan))
            .transpose()
    }
}

/// An image as a front end that knows it by name gives it (Python's `afmdyn.image`, and
/// the lines of its PI scan on a cluster): the sample map and the options beside the request's
/// keywords; the probe file's text comes apart ([`ImageKeywords::job`]).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageKeywords {
    /// The sample map: its TOML text or path (`SampleMap::read`).
    pub sample: String,
    /// Setpoint: the ratio A_sp/A₀ in (0, 1) (AM), the peak force in N (PeakForce).
    pub setpoint: f64,
    /// The imaging mode (`None`: AM).
    pub mode: Option<ImageMode>,
    /// Pixels per line (`None`: [`ImageRequest::at`]'s).
    pub pixels: Option<usize>,
    /// Lines (`None`: [`ImageRequest::lines`]).
    pub lines: Option<usize>,
    /// Points of each material's approach curve (`None`: [`ImageRequest::at`]'s).
    pub curve_points: Option<usize>,
    /// Heights (m), `[row][column]`, replacing the map's height map.
    pub height_map: Option<Vec<Vec<f64>>>,
    /// `None`: the ideal feedback; else a PI scan with these settings.
    pub feedback: Option<PiScan>,
    /// A PI scan's worker threads (`None`: all cores).
    pub threads: Option<usize>,
    /// The options as the front end was given them, with what else it was given, checked
    /// together ([`GivenOptions::check`]) before the job or the scan is built (`None`: the
    /// front end checked them itself, as the command line does with its flags).
    pub options: Option<GivenOptions>,
}

impl ImageKeywords {
    /// The probe's table (from its TOML text) and the sample map, its height map replaced by
    /// [`ImageKeywords::height_map`] when given.
    ///
    /// # Errors
    /// [`SimError::Probe`] for a probe text that is not TOML; the sample map's errors.
    #[cfg(feature = "files")] // (a sample map may name a file)
    pub fn inputs(&self, probe: &str) -> Result<(toml::Table, SampleMap), SimError> {
        let table = crate::probe::Probe::table(probe, "probe")
            .map_err(|e| SimError::Probe(format!("probe {e}")))?;
        let mut map = SampleMap::read(&self.sample)?;
        if let Some(rows) = &self.height_map {
            map = map.with_height_map(rows.clone())?;
        }
        Ok((table, map))
    }

    /// The options' check ([`ImageKeywords::options`]), when given.
    ///
    /// # Errors
    /// As [`GivenOptions::check`].
    pub fn check(&self) -> Result<(), SimError> {
        self.options.as_ref().map_or(Ok(()), GivenOptions::check)
    }

    /// The image request of the keywords (its setpoint as given: A_sp/A₀, or N with
    /// [`ImageMode::Peakforce`]).
    pub fn request(&self) -> ImageRequest {
        ImageRequest::with(self.setpoint, self.pixels, self.lines, self.curve_points)
    }

    /// The job of the probe file's text `probe` (the ideal image, or the PI scan).
    ///
    /// # Errors
    /// As [`ImageKeywords::check`] and [`ImageKeywords::inputs`].
    #[cfg(feature = "files")] // (a sample map may name a file)
    pub fn job(self, probe: &str) -> Result<ImageJob, SimError> {
        self.check()?;
        let (probe, sample) = self.inputs(probe)?;
        Ok(ImageJob {
            mode: self.mode.unwrap_or_default(),
            probe,
            sample,
            request: self.request(),
            feedback: self.feedback,
            study: None,
            threads: self.threads,
        })
    }

    /// The recipe of the PI scan (the default settings without [`ImageKeywords::feedback`]).
    ///
    /// # Errors
    /// As [`ImageKeywords::check`] and [`ImageKeywords::inputs`].
    #[cfg(feature = "files")] // (a sample map may name a file)
    pub fn scan(self, probe: &str) -> Result<ScanRecipe, SimError> {
        self.check()?;
        let (probe, map) = self.inputs(probe)?;
        Ok(ScanRecipe {
            probe,
            map,
            request: self.request(),
            scan: self.feedback.unwrap_or_default(),
        })
    }
}

impl ImageOutput {
    /// The outcome the one door gives: the per-pixel document, the image's layout (`image`:
    /// `image.nc`'s variables, `super::image_layout`) and, as the fact `summary`, the
    /// command line's `image.json` ([`crate::report::present::image`]).
    pub fn outcome(&self, setpoint: f64) -> Outcome {
        use crate::report::image_layout::{layout, peakforce_layout, scan_layout};
        use crate::report::present::image::{ideal_summary, peakforce_summary, pi_summary};
        let (document, layout, summary) = match self {
            ImageOutput::Ideal { image, study } => (
                image.document(setpoint),
                layout(image, setpoint),
                ideal_summary(image, setpoint, study.as_ref()),
            ),
            ImageOutput::Pi(img) => (
                img.document(setpoint),
                scan_layout(img, setpoint),
                pi_summary(img, setpoint),
            ),
            ImageOutput::PeakForce(img) => (
                img.document(),
                peakforce_layout(img),
                peakforce_summary(img),
            ),
        };
        let mut facts = serde_json::Map::new();
        facts.insert("summary".into(), summary);
        Outcome {
            document,
            datasets: vec![("image".into(), layout)],
            facts,
        }
    }
}
