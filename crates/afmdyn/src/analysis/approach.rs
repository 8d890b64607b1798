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

/// The default z_c range of an approach (units of g₀): from 1.2 A₀ above the contact
/// threshold, A₀ the free amplitude of `base` (`free_response`; under a multifrequency drive
/// the sum of the components' free amplitudes), where the sample is out of reach, down to
/// 0.1 A₀ above it — deep in the repulsive regime of a stiff sample — or, on a soft sample,
/// to 0.4 A₀ − δ_k (`soft_indentation`): a rigid sample holds the amplitude at A/A₀ = 0.5
/// near z_c = 0.5 A₀, and a compliant one lets the tip sink by about the indentation δ_k at
/// which it pushes back with the peak force of tapping at that setpoint, so the curve reaches
/// A/A₀ ≤ 0.5 (issue 60 item 12: a 0.09 N/m lever on 1 MPa in water never got below
/// A/A₀ = 0.995 on 0.1 A₀). The two agree while δ_k ≤ 0.3 A₀: on every sample stiff for its
/// lever and Q.
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
    let near = (0.1 * a0).min(0.4 * a0 - soft_indentation(&model, a0));
    Ok((1.2 * a0 + offset, near + offset))
}

/// The quasi-static indentation δ_k (units of g₀) at which the sample's contact force (its
/// relaxed law, no rate) reaches F_k = min(1, 3/Q₁) k_s A₀: an estimate of the peak force of
/// tapping at A/A₀ = 0.5. The virial of a tapping lever is at most k A A₀/(2Q) in magnitude
/// (San Paulo & García, *Phys. Rev. B* 64 (2001) 193411; García & Pérez, *Surf. Sci. Rep.* 47
/// (2002) 197, eq. 27), and a force acting over about a sixth of the cycle near the lower
/// turning point reaches it with F ≈ 3kA₀/Q; it never exceeds the lever's force at its free
/// amplitude k_s A₀. k_s = 1/(φᵀK⁻¹φ) is the lever's static stiffness at the tip (K the free
/// stiffness matrix, φ the tip's mode shapes: 1 for the point mass, 1/Σ(1/k_j) for the
/// eigenmode model), Q₁ = 1/(2ζ₁) of its first damped free mode. At most 3 A₀ (a sample that
/// never pushes back so hard gives that bound; a rigid one, whose law has no force of its
/// own, 0).
pub(crate) fn soft_indentation(model: &CantileverModel, a0: f64) -> f64 {
    use crate::contact::{TipSample, TipSampleLaw};
    use crate::galerkin::Region;
    let p = model.params();
    if matches!(p.contact_law, crate::contact::ContactLaw::Impact { .. })
        || a0.is_nan()
        || a0 <= 0.0
    {
        return 0.0;
    }
    let free = model.galerkin().region(Region::Free);
    let tip = model.tip();
    let Some(k_inv) = free.stiffness.clone().try_inverse() else {
        return 0.0;
    };
    let k_s = 1.0 / tip.dot(&(&k_inv * tip));
    let law = TipSample {
        law: p.contact_law,
        stiffness: p.alpha4,
        damping: 0.0,
    };
    let q1 = crate::eigen::damped_eigenvalues(free)
        .first()
        .map_or(f64::INFINITY, |e| 0.5 / e.zeta);
    let target = (3.0 / q1).min(1.0) * k_s * a0;
    let pushes = |d: f64| law.force(true, d, 0.0).force >= target;
    let cap = 3.0 * a0;
    if !pushes(cap) {
        return cap;
    }
    // the first doubling of 1e-6 A₀ that pushes back hard enough, then bisection
    let (mut lo, mut hi) = (0.0, 1e-6 * a0);
    while !pushes(hi) {
        lo = hi;
        hi *= 2.0;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if pushes(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// The stepped-sweep spec of an approach from the larger to the smaller of `z_from` and `z_to`
/// (units of g₀) with the given spacing of z_c, then the retract; the swept parameter is α5.
///
/// # Errors
/// As `grid`: non-finite or equal ends, a bad step, more than 100 000 points.
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
pub(crate) fn rest_distance(base: &Params, alpha5: f64) -> f64 {
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
