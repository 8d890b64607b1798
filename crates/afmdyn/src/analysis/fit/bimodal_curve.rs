//! The dynamic fit's model of a measured bimodal AM curve (issue 62 §1, "the bimodal
//! channels"): under a probe whose drive has a second component at a commensurate ratio
//! ([`crate::params::Params::drive_components`]), the first harmonic's A₁, φ₁ and the second
//! component's A₂ (m), φ₂ (deg) against the piezo position z (m), as the stepped approach the
//! instrument did (as [`super::am_curve`]: each row's orbit continued from the previous one).
//! A₂ and φ₂ are the harmonic of the tip deflection at the component's frequency over the
//! drive's common period, with their exact sensitivities from a second pair of Fourier
//! integrals of the extended flow ([`super::sensitivity::orbit_sensitivity`]); the
//! parameters map onto the model's as in [`super::am_curve`].
//!
//! The model's values are, for the channels fitted, the rows' A₁ g₀, then φ₁, A₂ g₀, φ₂ (m and
//! deg); rows off a stable period-1 orbit (of the common period) keep the stepped sweep's
//! observables without a Jacobian row, and the warnings say so, as at folds and grazing.

use super::am_curve::CheckedModel;
use super::am_curve::{AmParam, AmProbe, SteppedRows, SENSITIVITY_TOLERANCE};
use crate::analysis::stepped::SteppedSpec;
use crate::error::SimError;
use crate::params::SweepParam;
use std::sync::atomic::AtomicBool;
use std::sync::Mutex;

/// The model of a measured bimodal curve (module docs).
#[derive(Debug)]
pub struct BimodalCurveModel {
    /// The probe (its drive with a second component).
    pub probe: AmProbe,
    /// The piezo positions z (m) of the rows, in the order the instrument stepped.
    pub z: Vec<f64>,
    /// Which of (A₁, φ₁, A₂, φ₂) are fitted, in that order of the values.
    pub channels: [bool; 4],
    /// The model's parameters, in the fit's order.
    pub params: Vec<AmParam>,
    /// The stepped sweep's settings (its values are overwritten by the rows').
    pub spec: SteppedSpec,
    /// The adaptive integrator's tolerance of the sensitivities.
    pub tolerance: f64,
    warnings: Mutex<Vec<String>>,
}

impl BimodalCurveModel {
    /// A model of the rows `z` (m) under `probe`, with parameters `params` and the channels
    /// (A₁, φ₁, A₂, φ₂).
    pub fn new(probe: AmProbe, z: Vec<f64>, channels: [bool; 4], params: Vec<AmParam>) -> Self {
        let mut spec = SteppedSpec::new(probe.params, SweepParam::Alpha5, Vec::new());
        spec.branches = false;
        BimodalCurveModel {
            probe,
            z,
            channels,
            params,
            spec,
            tolerance: SENSITIVITY_TOLERANCE,
            warnings: Mutex::new(Vec::new()),
        }
    }

    /// The last evaluation's warnings (folds, grazing, rows off a period-1 orbit).
    pub fn warnings(&self) -> Vec<String> {
        self.warnings.lock().map(|w| w.clone()).unwrap_or_default()
    }
}

impl CheckedModel for BimodalCurveModel {
    fn rows(&self) -> usize {
        self.z.len() * self.channels.iter().filter(|c| **c).count()
    }
    fn kept(&self) -> &Mutex<Vec<String>> {
        &self.warnings
    }
    /// Stops at the next row of the curve, or of its sensitivities, once `cancel` is set.
    fn evaluate_checked(
        &self,
        p: &[f64],
        values: &mut [f64],
        jacobian: Option<&mut [f64]>,
        cancel: &AtomicBool,
    ) -> Result<Vec<String>, SimError> {
        if !self.probe.params.is_multifrequency() {
            return Err(SimError::out_of_range(
                "drive",
                "one frequency",
                "the bimodal channels need a probe whose drive has a second component",
            ));
        }
        if self.params.contains(&AmParam::QualityFactor)
            && self.probe.params.components().count() > 1
        {
            // the chain follows one further component's force (F̃₁ = A₀₁/(g₀|H₁|))
            return Err(SimError::out_of_range(
                "fit",
                AmParam::QualityFactor.name(),
                "Q is fitted under a drive of at most two components",
            ));
        }
        let rows = SteppedRows {
            probe: &self.probe,
            z: &self.z,
            params: &self.params,
            spec: &self.spec,
            tolerance: self.tolerance,
            channels: self.channels,
            component: Some(1),
        };
        rows.evaluate(p, values, jacobian, cancel)
    }
}
