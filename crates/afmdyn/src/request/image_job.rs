//! `image` as data ([`ImageJob`]): the probe file's table, the sample map, the request, the
//! feedback (ideal, or a PI scan with its settings) and the setpoint study, with its checks
//! and declared cost ([`super::run::Request`]); its run (execution, document and presentation,
//! and a PI scan's run resumably into a store) is the study layer's.

use super::image::{background_probe, curves_cost, ImageRequest, SampleMap};
use super::image_options::GivenOptions;
use super::image_peakforce::{peakforce_cost, peakforce_probe};
use super::image_scan::resolve;
use super::image_scan::PiScan;
#[cfg(feature = "files")]
use super::image_scan::ScanRecipe;
use super::limits::{check_threads, Cost};
use super::run::Resolved;
use crate::error::SimError;
use serde::{Deserialize, Serialize};

pub use super::image::ImageMode;

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

impl ImageJob {
    /// The model the job runs on: the background probe's parameters, without the SI block
    /// (the image's documents are in SI already).
    ///
    /// # Errors
    /// As the background probe's reading: a probe the format refuses, a multifrequency drive.
    pub fn model(&self) -> Result<Resolved, SimError> {
        Ok(Resolved::plain(background_probe(&self.probe)?.params))
    }

    /// [`Request::validate`] of a PeakForce image: the grid, an off-resonance probe, a
    /// setpoint force > 0, no PI feedback and no setpoint study (a temperature and the
    /// materials' laws are checked with its cost, which reads them).
    fn validate_peakforce(&self) -> Result<(), SimError> {
        if self.feedback.is_some() || self.study.is_some() {
            return Err(SimError::out_of_range(
                "mode",
                "peakforce",
                "a PeakForce image has the ideal peak-force feedback only (no PI scan, no \
                 setpoint study)",
            ));
        }
        self.request.validate_grid(&self.sample)?;
        peakforce_probe(&self.probe, self.request.setpoint).map(|_| ())
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
    /// `None`: the ideal feedback; else a PI scan with these settings (with
    /// [`ImageMode::Peakforce`], whose feedback is ideal, only their temperature).
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
    /// [`ImageMode::Peakforce`], whose temperature is [`ImageKeywords::feedback`]'s).
    pub fn request(&self) -> ImageRequest {
        let t = self.feedback.and_then(|f| f.temperature);
        ImageRequest::with(self.setpoint, self.pixels, self.lines, self.curve_points)
            .with_temperature(self.mode.unwrap_or_default(), t)
    }

    /// The job of the probe file's text `probe` (the ideal image, or the PI scan).
    ///
    /// # Errors
    /// As [`ImageKeywords::check`] and [`ImageKeywords::inputs`].
    #[cfg(feature = "files")] // (a sample map may name a file)
    pub fn job(self, probe: &str) -> Result<ImageJob, SimError> {
        self.check()?;
        let (probe, sample) = self.inputs(probe)?;
        let mode = self.mode.unwrap_or_default();
        Ok(ImageJob {
            mode,
            probe,
            sample,
            request: self.request(),
            feedback: self.feedback.filter(|_| mode == ImageMode::Am),
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

impl_request! {
    ImageJob, "image";
    validate |r, _| {
        check_threads(r.threads)?;
        if r.mode == ImageMode::Peakforce {
            return r.validate_peakforce();
        }
        r.request.validate(&r.sample)?;
        let background = background_probe(&r.probe)?;
        background.serves("image --mode am", crate::probe::ProbeNeeds::Tapping)?;
        match (&r.feedback, &r.study) {
            (Some(_), Some(_)) => Err(SimError::out_of_range(
                "setpoint_study",
                "a study with the PI feedback",
                "only with the ideal feedback (a study of exact operating points)",
            )),
            (Some(scan), None) => {
                resolve(&background, &r.sample, &r.request, scan).map(|_| ())
            }
            (None, _) => Ok(()),
        }
    };
    cost |r, _| {
        if r.mode == ImageMode::Peakforce {
            return peakforce_cost(&r.probe, &r.sample, &r.request);
        }
        let background = background_probe(&r.probe)?;
        let (map, req) = (&r.sample, &r.request);
        let periods = match &r.feedback {
            Some(scan) => resolve(&background, map, req, scan)?.2,
            None => 0.0,
        };
        let extra = Cost {
            bytes: req.pixel_bytes(map),
            work: periods,
        };
        let mut cost = curves_cost(&background, map, req.curve_points, extra)?;
        if r.study.is_some() {
            // the study computes the materials' curves once more
            let none = Cost {
                bytes: 0.0,
                work: 0.0,
            };
            cost.work += curves_cost(&background, map, req.curve_points, none)?.work;
        }
        Ok(cost)
    }
}
