//! `image` run ([`ImageJob`] as an [`Analysis`]): the request's data (`crate::request::image_job`)
//! held against the budgets before any work ([`Request::cost`]: the materials' approach curves,
//! the pixels' memory and a scan's drive periods), run (the ideal feedback's image and setpoint
//! study, [`super::scan::pi_image`], [`super::peakforce_image::peakforce_image`]) and presented
//! (`crate::report::present::image`).

use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::report::Presentation;
use crate::request::image::{background_probe, curves_cost, image, setpoint_study};
use crate::request::image_job::{ImageJob, ImageMode, ImageOutput};
use crate::request::image_peakforce::{peakforce_cost, peakforce_probe};
use crate::request::image_scan::resolve;
use crate::request::limits::{check_threads, Cost};
use crate::request::run::{Analysis, Request, Resolved};
use serde_json::Value;

impl ImageJob {
    /// [`Request::validate`] of a PeakForce image: the grid, an off-resonance probe, a
    /// setpoint force > 0, no PI feedback and no setpoint study.
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

impl Request for ImageJob {
    fn validate(&self, _model: &Resolved) -> Result<(), SimError> {
        self.request.validate(&self.sample)?;
        check_threads(self.threads)?;
        if self.mode == ImageMode::Peakforce {
            return self.validate_peakforce();
        }
        let background = background_probe(&self.probe)?;
        background.serves("image --mode am", crate::probe::ProbeNeeds::Tapping)?;
        match (&self.feedback, &self.study) {
            (Some(_), Some(_)) => Err(SimError::out_of_range(
                "setpoint_study",
                "a study with the PI feedback",
                "only with the ideal feedback (a study of exact operating points)",
            )),
            (Some(scan), None) => {
                resolve(&background, &self.sample, &self.request, scan).map(|_| ())
            }
            (None, _) => Ok(()),
        }
    }

    fn name(&self) -> &'static str {
        "image"
    }

    fn cost(&self, _model: &Resolved) -> Result<Cost, SimError> {
        if self.mode == ImageMode::Peakforce {
            return peakforce_cost(&self.probe, &self.sample, &self.request);
        }
        let background = background_probe(&self.probe)?;
        let (map, req) = (&self.sample, &self.request);
        let periods = match &self.feedback {
            Some(scan) => resolve(&background, map, req, scan)?.2,
            None => 0.0,
        };
        let extra = Cost {
            bytes: req.pixel_bytes(map),
            work: periods,
        };
        let mut cost = curves_cost(&background, map, req.curve_points, extra)?;
        if self.study.is_some() {
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

impl Analysis for ImageJob {
    type Output = ImageOutput;

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
