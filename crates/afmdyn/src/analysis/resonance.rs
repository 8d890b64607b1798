//! Resonance curves of tapping mode: amplitude and phase against the drive frequency Ω near a
//! natural frequency, swept up and down in steps (each value continued from the previous end
//! state) with the periodic-orbit branches continued in Ω and their folds located, so the
//! multivalued, bent resonance curves of the intermittent contact (e.g. Lee, Howell & Raman,
//! *Phys. Rev. B* 66 (2002) 115409) are traced whole. The driver is [`super::stepped`].

use super::stepped::{grid, Spacing, SteppedSpec};
use crate::eigen::spectrum;
use crate::error::SimError;
use crate::params::{Params, SweepParam, OMEGA_MAX, OMEGA_MIN};

/// The default frequency band around the k-th natural frequency ω_k (k ≥ 1) of the free
/// cantilever (eqs. 19–23; 1 for the point-mass model): ω_k (1 ± w) with the half-width
/// w = max(6/Q_k, 0.02), at most 0.5, Q_k = |λ_k|/(2|Re λ_k|) from the damped eigenvalue λ_k
/// (undamped: w = 0.02), clamped to the allowed Ω range.
///
/// # Errors
/// [`SimError::OutOfRange`] for k outside 1..=N; [`SimError::Params`] for invalid parameters.
pub(crate) fn mode_band(params: &Params, k: usize) -> Result<(f64, f64), SimError> {
    let (omega, q) = mode_resonance(params, k)?;
    let w = (6.0 / q).clamp(0.02, 0.5);
    Ok((
        (omega * (1.0 - w)).max(OMEGA_MIN),
        (omega * (1.0 + w)).min(OMEGA_MAX),
    ))
}

/// The k-th natural frequency ω_k (k ≥ 1) of the free cantilever and its quality factor
/// Q_k = |λ_k|/(2|Re λ_k|) from the damped eigenvalue λ_k (∞ undamped): the linewidth ω_k/Q_k
/// sets [`mode_band`] and the finest default grid of a resonance curve.
///
/// # Errors
/// [`SimError::OutOfRange`] for k outside 1..=N; [`SimError::Params`] for invalid parameters.
pub(crate) fn mode_resonance(params: &Params, k: usize) -> Result<(f64, f64), SimError> {
    let (free, _) = spectrum(params)?;
    if k == 0 || k > free.omega.len() {
        return Err(SimError::out_of_range(
            "mode",
            k,
            "must be in 1..=N (the number of modes)",
        ));
    }
    let omega = free.omega[k - 1];
    let q = free
        .eigenvalues
        .iter()
        .filter(|e| e.im > 0.0)
        .nth(k - 1)
        .map_or(f64::INFINITY, |e| 0.5 / e.zeta.max(1e-300));
    Ok((omega, q))
}

/// The stepped-sweep spec of an up-sweep from the smaller to the larger of `from` and `to`
/// (dimensionless Ω) with the given spacing, then the down-sweep.
///
/// # Errors
/// As [`grid`].
pub(crate) fn resonance_spec(
    base: Params,
    from: f64,
    to: f64,
    spacing: Spacing,
) -> Result<SteppedSpec, SimError> {
    let values = grid(from.min(to), from.max(to), spacing)?;
    Ok(SteppedSpec::new(base, SweepParam::Omega, values))
}
