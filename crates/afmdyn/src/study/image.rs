//! `image` run ([`ImageJob`] as an [`Analysis`]): the request's data (`crate::request::image_job`)
//! held against the budgets before any work (`Request::cost`: the materials' approach curves,
//! the pixels' memory and a scan's drive periods), run (the ideal feedback's image and setpoint
//! study, [`super::scan::pi_image`], `super::peakforce_image::peakforce_image`) into an
//! [`ImageOutput`] and presented (`crate::report::present::image`).

use super::image_ideal::{image, setpoint_study};
use super::scan::PiImage;
#[cfg(feature = "files")]
use super::scan::ScanStudy;
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::report::image::PeakForceImage;
use crate::report::{Convergence, Presentation};
use crate::request::image::{Image, SetpointStudy};
use crate::request::image_job::{ImageJob, ImageMode};
use crate::request::run::{Analysis, Request, Resolved};
use crate::study::named::Outcome;
use serde_json::Value;

impl ImageJob {
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

impl Analysis for ImageJob {
    type Output = ImageOutput;
    fn convergence(&self, output: &ImageOutput) -> Convergence {
        output.convergence()
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<ImageOutput, SimError> {
        self.validate(model)?;
        if self.mode == ImageMode::Peakforce {
            return super::peakforce_image::peakforce_image(
                &self.probe,
                &self.sample,
                &self.request,
                self.threads,
                progress,
            )
            .map(ImageOutput::PeakForce);
        }
        match &self.feedback {
            Some(scan) => super::scan::pi_image(
                &self.probe,
                &self.sample,
                &self.request,
                scan,
                self.threads,
                progress,
            )
            .map(ImageOutput::Pi),
            None => {
                let image = image(&self.probe, &self.sample, &self.request)?;
                let study = match &self.study {
                    Some(r) => Some(setpoint_study(
                        &self.probe,
                        &self.sample,
                        r,
                        self.request.curve_points,
                    )?),
                    None => None,
                };
                Ok(ImageOutput::Ideal { image, study })
            }
        }
    }

    fn report(&self, _model: &Resolved, output: &ImageOutput) -> Result<Value, SimError> {
        let setpoint = self.request.setpoint;
        Ok(match output {
            ImageOutput::Ideal { image, study } => {
                crate::report::present::image::ideal_summary(image, setpoint, study.as_ref())
            }
            ImageOutput::Pi(img) => crate::report::present::image::pi_summary(img, setpoint),
            ImageOutput::PeakForce(img) => crate::report::present::image::peakforce_summary(img),
        })
    }

    fn present(
        &self,
        output: &ImageOutput,
        at: crate::request::Presenting<'_>,
    ) -> Result<Presentation, SimError> {
        let setpoint = self.request.setpoint;
        Ok(match output {
            ImageOutput::Ideal { image, study } => crate::report::present::image::ideal(
                image,
                setpoint,
                study.as_ref(),
                at.document,
                at.units,
            ),
            ImageOutput::Pi(img) => {
                crate::report::present::image::pi(img, setpoint, at.document, at.units)
            }
            ImageOutput::PeakForce(img) => {
                crate::report::present::image::peakforce(img, at.document, at.units)
            }
        })
    }
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

impl ImageOutput {
    /// Its pixels that converged: those with an operating point (ideal, and the PI scan's
    /// reference image), or a steady tap at the setpoint (PeakForce).
    fn convergence(&self) -> Convergence {
        let pixels = |image: &Image| -> Convergence {
            let rows = image.pixels.iter().flatten().collect::<Vec<_>>();
            Convergence::count("pixels", &rows, |p| p.point.is_some())
        };
        match self {
            ImageOutput::Ideal { image, .. } => pixels(image),
            ImageOutput::Pi(pi) => pixels(&pi.ideal),
            ImageOutput::PeakForce(pf) => {
                let rows = pf.pixels.iter().flatten().collect::<Vec<_>>();
                Convergence::count("pixels", &rows, |p| p.tap.is_some())
            }
        }
    }

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
        // the summary is the command line's document: with its convergence, as the door's
        let mut summary = summary;
        self.convergence().write_into(&mut summary);
        let mut facts = serde_json::Map::new();
        facts.insert("summary".into(), summary);
        Outcome {
            document,
            datasets: vec![("image".into(), layout)],
            facts,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::image_ideal::image;
    use super::super::scan::ScanStudy;
    use crate::request::costs::tests::refused_as;
    use crate::request::image::{ImageRequest, SampleMap};
    use crate::request::image_scan::PiScan;

    /// An image whose pixels fit the pixel check but not with its approach curves' memory is
    /// refused before the first curve, ideal and PI alike, naming the image.
    #[test]
    fn an_image_beyond_the_budget_is_refused_before_any_work() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/probe-point-mass-dmt.toml"
        );
        let table: toml::Table = std::fs::read_to_string(path).unwrap().parse().unwrap();
        let map = SampleMap {
            size: (1e-6, 1e-6),
            domains: vec![],
            height_map: vec![],
        };
        // 1100 × 1072 pixels: 1.1792e9 B, within the pixels' own check (1.1 GiB)
        let req = ImageRequest {
            pixels: 1100,
            lines: Some(1072),
            ..ImageRequest::at(0.8)
        };
        req.validate(&map).unwrap();
        let started = std::time::Instant::now();
        refused_as(image(&table, &map, &req).unwrap_err(), "image");
        // the fastest scan: a drive period per pixel
        let probe = crate::probe::Probe::from_table(&table, "probe").unwrap();
        let scan = PiScan {
            scan_rate: Some(probe.drive_frequency / 2200.0),
            ..PiScan::default()
        };
        match ScanStudy::new(&table, &map, &req, &scan) {
            Err(e) => refused_as(e, "image"),
            Ok(_) => panic!("a scan beyond the budget was accepted"),
        }
        // no curve ran: a curve of 120 points takes far longer in a debug build
        assert!(started.elapsed().as_secs_f64() < 5.0);
    }
}
