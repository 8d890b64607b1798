//! `image`'s options beside its request ([`super::image::ImageRequest`]) and its PI scan's
//! settings ([`super::image_scan::PiScan`]): the imaging mode, the feedback, the worker threads
//! and a setpoint study — declared once here (the command line's `--mode`, `--feedback`,
//! `--threads` and `--setpoint-study` are generated from this type's schema), with the one
//! check of how they combine with each other and with what else a front end was given
//! ([`ImageOptions::check`]).

use super::image::{study_ratios, ImageMode};
use crate::error::SimError;
use serde::{Deserialize, Serialize};

/// How the image holds the amplitude (or the peak force) at its setpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum ImageFeedback {
    /// An operating point of the local material at every pixel (an ideal, infinitely fast
    /// feedback).
    #[default]
    Ideal,
    /// A time-domain scan, trace and retrace, under a lock-in and a PI z controller
    /// ([`super::image_scan::PiScan`]'s settings).
    Pi,
}

request! {
    /// `image`'s options beside its request: the imaging mode, the feedback, the worker threads and
    /// a setpoint study (module docs).
    pub struct ImageOptions {
        /// Imaging mode: `am` (amplitude-modulation tapping) or `peakforce` (off-resonance tapping
        /// with an ideal peak-force feedback; a probe with `[drive] mode = "off-resonance"`): maps
        /// of height, modulus_dmt, adhesion, deformation and dissipation.
        pub mode: ImageMode,
        /// Feedback: `ideal` (an operating point of the local material at every pixel) or `pi` (a
        /// time-domain scan, trace and retrace, under a lock-in and a PI z controller).
        pub feedback: ImageFeedback,
        /// PI scan or PeakForce image: worker threads, one line per task (default: all cores).
        pub threads: Option<usize>,
        /// Also the setpoint study FROM:TO:N (e.g. 0.2:0.95:16): every domain's apparent height,
        /// phase and E_dis at N setpoints, as a line engaged on the background meets it (the
        /// contrast inversion); "setpoint_study" in the document and two plots.
        pub setpoint_study: Option<String>,
    }
}

impl ImageOptions {
    /// Check the options together and with the other settings the front end was given:
    /// `given` names each (the PI scan's `scan_rate`, `gains` and `time_constant`, the
    /// request's `curve_points`, a run's `resume`) with its value as text. PeakForce takes
    /// neither the PI feedback, nor a setpoint study, nor a curve-points count (its ideal
    /// peak-force feedback finds each material's setpoint itself); the ideal feedback takes no
    /// loop settings, no resume and, in AM, no threads; the PI scan no setpoint study.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the first option that does not combine, its value and
    /// why.
    pub fn check(&self, given: &[(&'static str, String)]) -> Result<(), SimError> {
        let value = |name: &str| given.iter().find(|(k, _)| *k == name).map(|(_, v)| v);
        if self.mode == ImageMode::Peakforce {
            let not = "not with mode = peakforce (its ideal peak-force feedback finds each \
                       material's setpoint itself)";
            if self.feedback == ImageFeedback::Pi {
                return Err(SimError::out_of_range("feedback", "pi", not));
            }
            if let Some(s) = &self.setpoint_study {
                return Err(SimError::out_of_range("setpoint_study", s.clone(), not));
            }
            if let Some(v) = value("curve_points") {
                return Err(SimError::out_of_range("curve_points", v.clone(), not));
            }
        }
        match self.feedback {
            ImageFeedback::Ideal => {
                let only = "only with feedback = pi (the ideal feedback has no loop)";
                // every setting given but the curves' is the PI scan's (and with PeakForce the
                // temperature: its noise maps)
                let pf = self.mode == ImageMode::Peakforce;
                let own = ["curve_points", if pf { "temperature" } else { "" }];
                for name in GIVEN.into_iter().filter(|n| !own.contains(n)) {
                    if let Some(v) = value(name) {
                        return Err(SimError::out_of_range(name, v.clone(), only));
                    }
                }
                if let (Some(t), ImageMode::Am) = (self.threads, self.mode) {
                    return Err(SimError::out_of_range("threads", t, only));
                }
            }
            ImageFeedback::Pi => {
                if let Some(s) = &self.setpoint_study {
                    return Err(SimError::out_of_range(
                        "setpoint_study",
                        s.clone(),
                        "only with feedback = ideal (a study of exact operating points)",
                    ));
                }
            }
        }
        Ok(())
    }

    /// The setpoint study's ratios A_sp/A₀ ([`study_ratios`] of `setpoint_study`), when asked.
    ///
    /// # Errors
    /// As [`study_ratios`].
    pub fn study(&self) -> Result<Option<Vec<f64>>, SimError> {
        self.setpoint_study.as_deref().map(study_ratios).transpose()
    }
}

/// The names [`ImageOptions::check`] knows of the other settings a front end was given.
const GIVEN: [&str; 7] = [
    "scan_rate",
    "gains",
    "time_constant",
    "temperature",
    "seed",
    "curve_points",
    "resume",
];

/// [`ImageOptions`] with what else a front end was given, by name and value as text, for a
/// front end that passes them with an image's keywords (Python's `afmdyn.image`,
/// [`super::image_job::ImageKeywords::options`]).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GivenOptions {
    /// The options.
    pub options: ImageOptions,
    /// The other settings given: `[name, value]` pairs, names among `scan_rate`, `gains`,
    /// `time_constant`, `temperature`, `seed`, `curve_points` and `resume`.
    pub given: Vec<(String, String)>,
}

impl GivenOptions {
    /// [`ImageOptions::check`] of the options with the settings given.
    ///
    /// # Errors
    /// As [`ImageOptions::check`]; [`SimError::OutOfRange`] naming `given` for a name it does
    /// not know.
    pub fn check(&self) -> Result<(), SimError> {
        let mut given = Vec::with_capacity(self.given.len());
        for (name, value) in &self.given {
            let known = GIVEN.iter().find(|k| **k == name.as_str()).ok_or_else(|| {
                SimError::out_of_range(
                    "given",
                    name.clone(),
                    format!("names one of {}", GIVEN.join(", ")),
                )
            })?;
            given.push((*known, value.clone()));
        }
        self.options.check(&given)
    }
}
