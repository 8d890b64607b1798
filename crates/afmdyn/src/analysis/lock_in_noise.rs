//! The lock-in's amplitude and phase noise on a periodic orbit under the thermal force, by
//! linear response: what an AM-AFM at that operating point measures as σ_A and σ_φ at the
//! lock-in's bandwidth, and under a multifrequency drive (bimodal AFM) what each component's
//! lock-in measures.
//!
//! **The chain** (`crate::analysis::orbit_noise`): the deviation δz from the orbit, extended by
//! the lock-ins' states. The lock-in of [`super::am_loop`] is linear in W(1,τ): over a drive
//! period it sums X = (2/M) Σ_j W_j sin θ_j and Y = −(2/M) Σ_j W_j cos θ_j at M equal parts,
//! then low-passes them once per period, X̄ ← X̄ + β(X − X̄), β = 1 − e^{−T/τ_L}. The deviation
//! y = (δz, δX, δY, δX̄, δȲ) of the whole chain is then a linear system in discrete time: over
//! one period y ↦ F y + ξ, the orbit walked in M·[`SUBSTEPS`] equal parts (ΩT/(M·SUBSTEPS) =
//! `orbit_noise::ETA` at resonance) and the lock-in's linear maps at its samples.
//! From the stationary covariance Y, σ_A² = gᵀYg, σ_φ² = hᵀYh with g = (X̄, Ȳ)/A and
//! h = (−Ȳ, X̄)/A² on (δX̄, δȲ): the gradients of A = |(X̄, Ȳ)| and φ = arg(X̄ + iȲ) at the
//! orbit's first harmonic.
//!
//! **A multifrequency drive** repeats over its common period T_c = qT
//! ([`crate::params::Params::common_periods`]): the chain is walked over T_c, with one lock-in
//! per component c, each the lock-in above at its own reference: summing X_c, Y_c at
//! θ_j = ω_c τ_j + ψ_c (`Params::demodulated`, the phases the orbit's component observables
//! are demodulated with) over each drive period T and low-passing them once per drive period,
//! β = 1 − e^{−T/τ_L} (one τ_L for every lock-in), q times over T_c. Its bandwidth is then
//! τ_L's, as in the single-frequency case, whatever q; the sums over a drive period holding a
//! non-integer number of cycles of ω_c (6.25 at f₂ = 25/4 f₁) carry a ripple that the
//! low-pass averages and that the chain, periodic over T_c, holds exactly. The forms g and h
//! take the orbit's exact harmonic over T_c (its component amplitude and phase).
//!
//! This is the linear response of the measurement itself: the noise within a period, which
//! reaches that period's (X, Y) directly, is in it as much as the noise carried over in δz. It
//! holds while σ stays small against the orbit's distance to grazing, and only for a stable
//! orbit (an unstable one has no stationary covariance: NaN). On the free lever at resonance with
//! Q ≫ 1 it reduces to the spectrum's σ_A² = S_x(f₀)/(2(τ_c + τ_L)), τ_c = 2Q/ω₀ (the slow
//! amplitude's first-order response in series with the lock-in's; the test
//! `free_lever_matches_the_spectrum`), which is k_BT/k at τ_L = 0 (equipartition).
//!
//! Units are the model's: τ (eq. 5), lengths in g₀, k_B T in the model's energy unit.

use super::orbit_noise::Walk;
use crate::error::SimError;
use crate::integrate::IntegratorOptions;
use crate::model::CantileverModel;
use crate::params::MAX_DRIVE_COMPONENTS;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Parts of the period between two of the lock-in's samples over which the noise is summed by
/// the trapezoid rule (module docs).
pub const SUBSTEPS: usize = 16;

/// The thermal force and the lock-in of a noise estimate (model units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ThermalLockIn {
    /// k_B T in the model's energy unit.
    pub kt: f64,
    /// The lock-in's time constant τ_L ≥ 0 (units of τ).
    pub time_constant: f64,
}

/// The lock-in's outputs' standard deviations at an operating point (model units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LockInNoise {
    /// σ_A, the amplitude's (g₀); NaN where there is no stationary noise (module docs).
    pub amplitude: f64,
    /// σ_φ, the phase's (rad).
    pub phase: f64,
    /// Under a multifrequency drive, (σ_A, σ_φ) (g₀, rad) of the lock-in of each further
    /// component in the order of [`crate::params::Params::drive_components`]; NaN past the
    /// drive's components.
    #[serde(default = "no_further")]
    pub further: [[f64; 2]; MAX_DRIVE_COMPONENTS],
}

/// No further components' noise.
fn no_further() -> [[f64; 2]; MAX_DRIVE_COMPONENTS] {
    [[f64::NAN; 2]; MAX_DRIVE_COMPONENTS]
}

impl LockInNoise {
    /// No estimate (an orbit that is not period 1, or unstable).
    pub const NONE: LockInNoise = LockInNoise {
        amplitude: f64::NAN,
        phase: f64::NAN,
        further: [[f64::NAN; 2]; MAX_DRIVE_COMPONENTS],
    };
}

/// The lock-ins' noise (module docs) on the periodic orbit of `model` through `z` at τ = 0 (its
/// common period under a multifrequency drive), under the thermal energy `kt` (k_B T in the
/// model's energy unit), with the lock-in's `samples` per drive period and time constant
/// `time_constant` (τ_L ≥ 0, units of τ).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `samples` (0), `kt` or `time_constant` (negative or not
/// finite); the integrator's and the flow's errors.
pub fn lock_in_noise(
    model: &CantileverModel,
    z: &DVector<f64>,
    kt: f64,
    time_constant: f64,
    samples: usize,
) -> Result<LockInNoise, SimError> {
    crate::error::within("samples", samples, 1..=usize::MAX, "must be at least 1")?;
    if !(time_constant.is_finite() && time_constant >= 0.0) {
        return Err(SimError::out_of_range(
            "time_constant",
            time_constant,
            "must be a finite number ≥ 0",
        ));
    }
    let (chain, harmonics) = period_chain(model, z, kt, time_constant, samples)?;
    let Some(y) = chain.stationary() else {
        return Ok(LockInNoise::NONE);
    };
    let n = chain.f.nrows();
    let dim = n - 4 * harmonics.len();
    // σ of lock-in c's (A, φ): the forms g, h on its (δX̄, δȲ)
    let sigma = |c: usize, (x, yy): (f64, f64)| {
        let a = x.hypot(yy);
        let form = |g: [f64; 2]| {
            let mut v = DVector::zeros(n);
            (v[dim + 4 * c + 2], v[dim + 4 * c + 3]) = (g[0], g[1]);
            v.dot(&(&y * &v)).max(0.0).sqrt()
        };
        [form([x / a, yy / a]), form([-yy / (a * a), x / (a * a)])]
    };
    let mut out = LockInNoise::NONE;
    for (c, &h) in harmonics.iter().enumerate() {
        match c {
            0 => [out.amplitude, out.phase] = sigma(0, h),
            _ => out.further[c - 1] = sigma(c, h),
        }
    }
    Ok(out)
}

/// The chain of the orbit through (0, `z`) over one (common) period, each lock-in's four
/// states X_c, Y_c, X̄_c, Ȳ_c after the deviation (at dim + 4c..), and the orbit's first
/// harmonic (X_c, Y_c) at each component (module docs; one for a single-frequency drive).
pub(crate) fn period_chain(
    model: &CantileverModel,
    z: &DVector<f64>,
    kt: f64,
    time_constant: f64,
    samples: usize,
) -> Result<(super::orbit_noise::Chain, Vec<(f64, f64)>), SimError> {
    let references = model.params().demodulated();
    let dim = z.len();
    let n = dim + 4 * references.len();
    let period = model.period();
    let mut walk = Walk::new(model, z, kt, n - dim, IntegratorOptions::default())?;
    let mut tip = DVector::zeros(dim);
    tip.rows_mut(0, model.modes()).copy_from(model.tip());
    let mut harmonics = vec![(0.0, 0.0); references.len()];
    // `samples` per drive period, over the q drive periods of the common period
    let q = model.params().common_periods() as usize;
    let (per_period, scale) = (samples * SUBSTEPS, 2.0 / samples as f64);
    // each drive period's end: X̄ ← (1 − β) X̄ + β X, then the sums start again
    let beta = crate::analysis::am_loop::lock_in_beta(time_constant, period / q as f64);
    let mut filter = DMatrix::identity(n, n);
    for c in 0..references.len() {
        let (ix, iy) = (dim + 4 * c, dim + 4 * c + 1);
        for (i, from) in [(ix + 2, ix), (iy + 2, iy)] {
            filter[(i, i)] = 1.0 - beta;
            filter[(i, from)] = beta;
        }
        for i in [ix, iy] {
            filter[(i, i)] = 0.0;
        }
    }
    let mut m = DMatrix::identity(n, n);
    for k in 1..=q * per_period {
        let t1 = period * k as f64 / (q * per_period) as f64;
        walk.part(t1)?;
        if k % SUBSTEPS == 0 {
            // the lock-ins' sample at θ_j = ω_c τ_j + ψ_c; the harmonic over the common period
            let wt = tip.dot(&walk.state);
            m.fill_with_identity();
            for (c, &(omega, psi)) in references.iter().enumerate() {
                let (s, co) = (omega * t1 + psi).sin_cos();
                harmonics[c].0 += scale / q as f64 * wt * s;
                harmonics[c].1 -= scale / q as f64 * wt * co;
                let (ix, iy) = (dim + 4 * c, dim + 4 * c + 1);
                for j in 0..dim {
                    m[(ix, j)] = scale * s * tip[j];
                    m[(iy, j)] = -scale * co * tip[j];
                }
            }
            walk.chain.apply(&m);
        }
        if k % per_period == 0 {
            walk.chain.apply(&filter);
        }
    }
    Ok((walk.chain, harmonics))
}

#[cfg(test)]
pub(crate) mod tests;
