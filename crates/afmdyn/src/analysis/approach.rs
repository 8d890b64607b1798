//! The amplitude-modulation approach–retract curve: the steady state against the rest
//! distance z_c between tip and sample ([`Params::rest_distance`]), stepped towards the sample
//! and back, with the periodic-orbit branches continued in the gap α5 = z_c − offset
//! ([`Params::alpha5_for_rest_distance`]). The attractive (low) and repulsive (high) states of
//! tapping mode, the unstable branch between them, the bistable range bounded by folds and the
//! jumps of the stepped curves (García & San Paulo, *Phys. Rev. B* 60 (1999) 4961; Guzman,
//! Garcia & Garcia, *Beilstein J. Nanotechnol.* 6 (2015) 369) come from the shared driver
//! [`super::stepped`].

use super::observables::free_response;
use super::stepped::{grid, stepped_sweep, Spacing, SteppedCurve, SteppedSpec};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};

/// The default z_c range of an approach (units of g₀): from 1.2 A₀ to 0.1 A₀ above the contact
/// threshold, A₀ the free amplitude of `base` ([`free_response`]; under a multifrequency drive
/// the sum of the components' free amplitudes): from where the sample is out
/// of reach to deep in the repulsive regime.
///
/// # Errors
/// [`SimError`] for invalid parameters or an undamped drive at resonance (no finite A₀).
pub fn default_range(base: &Params) -> Result<(f64, f64), SimError> {
    // the free responses only: any drive, quasi-periodic ones too
    let model = CantileverModel::quasiperiodic(base)?;
    // a multifrequency drive: the free amplitudes of all components add up at the sample
    let mut a0 = free_response(&model)?.amplitude;
    for c in base.components() {
        a0 += c.force * model.free_force_response(c.ratio() * base.omega)?.norm();
    }
    let offset = base.contact_law.distance_offset();
    Ok((1.2 * a0 + offset, 0.1 * a0 + offset))
}

/// The stepped-sweep spec of an approach from the larger to the smaller of `z_from` and `z_to`
/// (units of g₀) with the given spacing of z_c, then the retract; the swept parameter is α5.
///
/// # Errors
/// As [`grid`]: non-finite or equal ends, a bad step, more than 100 000 points.
pub fn approach_spec(
    base: Params,
    z_from: f64,
    z_to: f64,
    spacing: Spacing,
) -> Result<SteppedSpec, SimError> {
    let (far, near) = (z_from.max(z_to), z_from.min(z_to));
    let z_c = grid(far, near, spacing)?;
    let values = z_c
        .iter()
        .map(|&z| base.alpha5_for_rest_distance(z))
        .collect();
    Ok(SteppedSpec::new(base, SweepParam::Alpha5, values))
}

/// The rest distance z_c of the gap value α5 = `alpha5` under `base`'s contact law.
pub fn rest_distance(base: &Params, alpha5: f64) -> f64 {
    base.with(SweepParam::Alpha5, alpha5).rest_distance()
}

/// Run the approach (the first sweep of the result), the retract (the second) and the branch
/// continuation of `spec` (from [`approach_spec`]).
///
/// # Errors
/// As [`stepped_sweep`].
pub fn approach_retract(spec: &SteppedSpec) -> Result<SteppedCurve, SimError> {
    stepped_sweep(spec)
}
