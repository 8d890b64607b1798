//! The frequency-shift noise of FM-AFM under the thermal force, by linear response of the
//! closed loop: what an FM-AFM at an operating point of the curve reads as σ of its frequency
//! shift and of its excitation, at the loop's bandwidth.
//!
//! **The loop** is the time-domain loop of [`crate::analysis::fm_loop`], with the first
//! harmonic demodulated from `samples` equally spaced samples of the tip deflection per cycle
//! (the lock-in of [`crate::analysis::am_loop`] at τ_L = 0, X + iY = A₁ e^{iφ₁}):
//! every cycle k runs one drive period at (Ω_k, α2_k) from the state the last one ended in,
//! and then
//!
//! Ω_{k+1} = Ω_k − g_φ (ω_K / 2Q_K)(φ₁ − φ_set),  α2_{k+1} = α2_k (1 − g_A (A₁/A − 1)).
//!
//! **The chain.** Linearised about the FM steady state (z*, Ω*, α2*), a cycle maps
//! y = (δz, δΩ, δα2) to M y + ξ: the δz columns of the orbit's chain over the period
//! (`crate::analysis::orbit_noise`: the flow's Jacobians, saltation matrices and the thermal
//! noise of every part, with the demodulator's sums), the δΩ and δα2 columns by central
//! differences of the deterministic cycle (a change of Ω changes the drive and the cycle's
//! length), and the two controllers' rows through the gradients of A₁ = |X + iY| and
//! φ₁ = arg(X + iY). The stationary covariance of y (Smith's doubling, as there) gives
//! σ_Ω and σ_α2 at the start of a cycle, where the instrument reads them.
//!
//! **The bandwidth.** The PLL is a first-order loop of pole 1 − g at one update per cycle: its
//! equivalent noise bandwidth is B = f g / (2(2 − g)), f = Ω/2π the update rate (white input of
//! one-sided density 2σ²/f gives the output variance σ² Σ_k g²(1 − g)^{2k} = σ² g/(2 − g)). For a free
//! lever and a loop slow against the lever (g ≪ π/Q) the chain reduces to Albrecht's thermal
//! frequency noise, σ_f² = f₀ k_BT B / (π k Q A²) (T. R. Albrecht, P. Grütter, D. Horne and
//! D. Rugar, *J. Appl. Phys.* 69 (1991) 668, eq. 11; the test
//! `slow_loop_gives_albrechts_frequency_noise`).
//!
//! This holds while σ stays small against the orbit's distance to grazing, as every linear
//! response does, and only for a stable closed loop (NaN otherwise). Units are the model's: Ω
//! in units of the τ scale, lengths in g₀, k_B T in the model's energy unit.

use super::{FmCurve, FmPoint, FmReference, LoopSpec};
use crate::analysis::am_loop::demodulate_period_stepped;
use crate::analysis::lock_in_noise::period_chain;
use crate::analysis::orbit_noise::Chain;
use crate::error::SimError;
use crate::integrate::{build, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// The demodulator's samples per cycle.
pub const DEMODULATOR_SAMPLES: usize = 64;

/// Central differences' step of the loop's parameters: in Ω relative to the half linewidth
/// ω_K/(2Q_K), in α2 relative to α2.
const STEP: f64 = 1e-5;

/// The loop's standard deviations at an operating point (model units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FmNoise {
    /// σ_Ω, the drive frequency's (units of the τ scale); NaN for an unstable loop.
    pub frequency: f64,
    /// σ_α2, the excitation's.
    pub excitation: f64,
}

/// The largest gain per cycle of the loops: a first-order loop of pole 1 − g settles in one
/// cycle at g = 1 and overshoots beyond (and diverges at g = 2); below it, π/Q_K bounds it
/// where the lever answers more slowly ([`crate::analysis::fm_loop`]).
pub const MAX_LOOP_GAIN: f64 = 1.0;

/// The equivalent noise bandwidth of the PLL of gain `g` per cycle at the update rate `rate`,
/// in the rate's unit (module docs).
pub fn loop_bandwidth(g: f64, rate: f64) -> f64 {
    rate * g / (2.0 * (2.0 - g))
}

/// The gain per cycle of the PLL of bandwidth `bandwidth` at the update rate `rate`: the
/// inverse of [`loop_bandwidth`].
pub fn loop_gain(bandwidth: f64, rate: f64) -> f64 {
    4.0 * bandwidth / (rate + 2.0 * bandwidth)
}

/// The loop's noise (module docs) at the FM steady state `point` of `base` (`reference` the
/// free lever's operating point, `amplitude` the setpoint A in g₀) under the thermal energy
/// `kt` (k_B T in the model's energy unit), the loop's gains `gains`.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `kt`; the model's, the integrator's and the flow's errors.
pub fn fm_noise(
    base: &Params,
    point: &FmPoint,
    reference: &FmReference,
    amplitude: f64,
    gains: &LoopSpec,
    kt: f64,
) -> Result<FmNoise, SimError> {
    let at = |omega: f64, alpha2: f64| {
        let p = base
            .with(SweepParam::Alpha5, point.alpha5)
            .with(SweepParam::Omega, omega)
            .with(SweepParam::Alpha2, alpha2);
        CantileverModel::new(&p)
    };
    let model = at(point.omega, point.alpha2)?;
    let (chain, _) = period_chain(&model, &point.state, kt, 0.0, DEMODULATOR_SAMPLES)?;
    let dim = point.state.len();
    let (x, y) = {
        let c = cycle(&model, &point.state)?;
        (c[dim], c[dim + 1])
    };
    let a2 = x * x + y * y;
    // the gradients of A₁ and φ₁ on (X, Y) (module docs)
    let (grad_a, grad_phi) = ([x / a2.sqrt(), y / a2.sqrt()], [-y / a2, x / a2]);
    // the cycle's deviation (δz′, δX, δY) per unit δz, δΩ, δα2: (dim + 2) × (dim + 2)
    let mut d = DMatrix::zeros(dim + 2, dim + 2);
    let rows = [(0..dim).collect::<Vec<_>>(), vec![dim + 2, dim + 3]].concat();
    for (i, &r) in rows.iter().enumerate() {
        for j in 0..dim {
            d[(i, j)] = chain.f[(r, j)];
        }
    }
    let h = [
        STEP * reference.omega / (2.0 * reference.quality_factor),
        STEP * point.alpha2,
    ];
    for (k, h) in h.into_iter().enumerate() {
        let e = |s: f64| {
            let (o, a) = (point.omega, point.alpha2);
            let m = at(o + s * h * f64::from(k == 0), a + s * h * f64::from(k == 1))?;
            cycle(&m, &point.state)
        };
        let column = (e(1.0)? - e(-1.0)?) / (2.0 * h);
        d.column_mut(dim + k).copy_from(&column);
    }
    // the controllers' rows on the demodulated (δX, δY): L maps (δz′, δX, δY) to y′
    let c_phi = gains.phase_gain * reference.omega / (2.0 * reference.quality_factor);
    let c_amp = gains.amplitude_gain * point.alpha2 / amplitude;
    let mut l = DMatrix::zeros(dim + 2, dim + 2);
    l.view_mut((0, 0), (dim, dim)).fill_with_identity();
    for j in 0..2 {
        l[(dim, dim + j)] = -c_phi * grad_phi[j];
        l[(dim + 1, dim + j)] = -c_amp * grad_a[j];
    }
    let mut f = &l * &d;
    f[(dim, dim)] += 1.0;
    f[(dim + 1, dim + 1)] += 1.0;
    let w = chain.w.select_rows(&rows).select_columns(&rows);
    let loop_chain = Chain {
        f,
        w: &l * w * l.transpose(),
    };
    Ok(match loop_chain.stationary() {
        Some(s) => FmNoise {
            frequency: s[(dim, dim)].max(0.0).sqrt(),
            excitation: s[(dim + 1, dim + 1)].max(0.0).sqrt(),
        },
        None => FmNoise {
            frequency: f64::NAN,
            excitation: f64::NAN,
        },
    })
}

/// Every point's noise ([`fm_noise`]) of `curve` on `base` under `kt` with `gains`, checking
/// for cancellation before each.
///
/// # Errors
/// As [`fm_noise`]; [`SimError::Cancelled`].
pub fn curve_noise(
    base: &Params,
    curve: &mut FmCurve,
    gains: &LoopSpec,
    kt: f64,
) -> Result<(), SimError> {
    for i in 0..curve.points.len() {
        crate::error::cancelled()?;
        let (q, r) = (&curve.points[i], &curve.reference);
        curve.points[i].noise = Some(fm_noise(base, q, r, curve.amplitude, gains, kt)?);
    }
    Ok(())
}

/// One deterministic cycle of the loop on `model` from `z` at τ = 0: (z at the period's end,
/// X, Y) of the demodulator (module docs), shape `[2N + 2]`.
fn cycle(model: &CantileverModel, z: &DVector<f64>) -> Result<DVector<f64>, SimError> {
    let opts = IntegratorOptions {
        tolerance: super::DEFAULT_ORBIT_TOLERANCE,
        ..IntegratorOptions::default()
    };
    let mut integ = build(model, opts, 0.0, z)?;
    let (a, phi) = demodulate_period_stepped(integ.as_mut(), model, DEMODULATOR_SAMPLES)?;
    let dim = z.len();
    let mut out = DVector::zeros(dim + 2);
    out.rows_mut(0, dim).copy_from(integ.state());
    (out[dim], out[dim + 1]) = (a * phi.cos(), a * phi.sin());
    Ok(out)
}

#[cfg(test)]
mod tests;
