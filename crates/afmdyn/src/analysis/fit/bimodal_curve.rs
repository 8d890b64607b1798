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

use super::am_curve::{AmParam, AmProbe, Channels, SteppedCurveModel};
use crate::error::SimError;

/// The model of a measured bimodal curve (module docs).
pub(crate) type BimodalCurveModel = SteppedCurveModel<[bool; 4]>;

/// (A₁, φ₁, A₂, φ₂), the second ones the harmonic of the drive's further component: under a
/// probe whose drive has one.
impl Channels for [bool; 4] {
    const COMPONENT: Option<usize> = Some(1);
    fn fitted(&self) -> [bool; 4] {
        *self
    }
    fn check(probe: &AmProbe, params: &[AmParam]) -> Result<(), SimError> {
        if !probe.params.is_multifrequency() {
            return Err(SimError::out_of_range(
                "drive",
                "one frequency",
                "the bimodal channels need a probe whose drive has a second component",
            ));
        }
        if params.contains(&AmParam::QualityFactor) && probe.params.components().count() > 1 {
            // the chain follows one further component's force (F̃₁ = A₀₁/(g₀|H₁|))
            return Err(SimError::out_of_range(
                "fit",
                AmParam::QualityFactor.name(),
                "Q is fitted under a drive of at most two components",
            ));
        }
        Ok(())
    }
}
