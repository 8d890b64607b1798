//! The lock-in's amplitude and phase noise on a periodic orbit under the thermal force, by
//! linear response: what an AM-AFM at that operating point measures as σ_A and σ_φ at the
//! lock-in's bandwidth.
//!
//! **The chain.** Small deviations δz from the period-1 orbit z*(τ) obey the variational
//! equations with the saltation matrix at each switching (Leine & Nijmeijer 2004, ch. 7), driven
//! by the fluctuation–dissipation theorem's white force, the diffusion D = GGᵀ of the
//! stochastic step ([`crate::integrate::exact::noise`]; the region's damping under the linear
//! law, the lever's and the medium's under a nonlinear one). The lock-in of [`super::am_loop`]
//! is linear in W(1,τ): over a drive period it sums X = (2/M) Σ_j W_j sin θ_j and
//! Y = −(2/M) Σ_j W_j cos θ_j at M equal parts, then low-passes them once per period,
//! X̄ ← X̄ + β(X − X̄), β = 1 − e^{−T/τ_L}. The deviation y = (δz, δX, δY, δX̄, δȲ) of the whole
//! chain is then a linear system in discrete time: over one period y ↦ F y + ξ, ξ Gaussian with
//! covariance W. F is the product of the flow's Jacobians over M·[`SUBSTEPS`] equal parts of the
//! period ([`crate::maps::flow`]: the step Jacobians and the saltation matrices) and of the
//! lock-in's linear maps; W accumulates the noise injected over each part (τ_a, τ_b) of length
//! h, ∫ Φ(τ_b,s) D Φ(τ_b,s)ᵀ ds by the trapezoid rule h/2 (Φ D_a Φᵀ + D_b), Φ = Φ(τ_b,τ_a)
//! (relative error (ωh)²/12 ≈ 10⁻⁵ for the first mode at 512 parts per period), carried
//! through every later map. The stationary covariance Y = F Y Fᵀ + W
//! (the discrete Lyapunov equation) is summed by doubling, Y = Σ_k F^k W F^kᵀ (Smith 1968),
//! and σ_A² = gᵀYg, σ_φ² = hᵀYh with g = (X̄, Ȳ)/A and h = (−Ȳ, X̄)/A² on (δX̄, δȲ): the
//! gradients of A = |(X̄, Ȳ)| and φ = arg(X̄ + iȲ) at the orbit's first harmonic.
//!
//! This is the linear response of the measurement itself: the noise within a period, which
//! reaches that period's (X, Y) directly, is in it as much as the noise carried over in δz. It
//! holds while σ stays small against the orbit's distance to grazing (a switching that the
//! noise can remove or add is outside any linearisation), and only for a stable orbit (an
//! unstable one has no stationary covariance: NaN). On the free lever at resonance with
//! Q ≫ 1 it reduces to the spectrum's σ_A² = S_x(f₀)/(2(τ_c + τ_L)), τ_c = 2Q/ω₀ (the slow
//! amplitude's first-order response in series with the lock-in's; the test
//! `free_lever_matches_the_spectrum`), which is k_BT/k at τ_L = 0 (equipartition).
//!
//! Units are the model's: τ (eq. 5), lengths in g₀, k_B T in the model's energy unit.

use crate::error::SimError;
use crate::galerkin::Region;
use crate::integrate::exact::noise::{admits_model, diffusion, linear_part};
use crate::integrate::{build, IntegratorOptions};
use crate::maps::flow::flow;
use crate::model::CantileverModel;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Parts of the period between two of the lock-in's samples over which the noise is summed by
/// the trapezoid rule (module docs).
pub const SUBSTEPS: usize = 16;

/// The doubling's iterations at most: F^(2^k) has gone below 10⁻¹⁵ of the unit for any stable
/// chain whose slowest decay per period is 1 − 10⁻¹⁵ or faster.
const DOUBLINGS: usize = 64;

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
}

impl LockInNoise {
    /// No estimate (an orbit that is not period 1, or unstable).
    pub const NONE: LockInNoise = LockInNoise {
        amplitude: f64::NAN,
        phase: f64::NAN,
    };
}

/// The lock-in's noise (module docs) on the period-1 orbit of `model` through `z` at τ = 0,
/// under the thermal energy `kt` (k_B T in the model's energy unit), with the lock-in's
/// `samples` per period and time constant `time_constant` (τ_L ≥ 0, units of τ).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `samples` (0), `kt` or `time_constant` (negative or not
/// finite); [`SimError::Unsupported`] for a law with memory ([`admits_model`]); the integrator's and
/// the flow's errors; [`SimError::OutOfRange`] naming `drive` for a multifrequency drive.
pub fn lock_in_noise(
    model: &CantileverModel,
    z: &DVector<f64>,
    kt: f64,
    time_constant: f64,
    samples: usize,
) -> Result<LockInNoise, SimError> {
    crate::error::within("samples", samples, 1..=usize::MAX, "must be at least 1")?;
    for (name, v) in [("kt", kt), ("time_constant", time_constant)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(SimError::out_of_range(
                name,
                v,
                "must be a finite number ≥ 0",
            ));
        }
    }
    admits_model(model.params())?;
    let lin = linear_part(model)?;
    let d = [Region::Free, Region::Contact].map(|r| diffusion(&lin, r, kt));
    let chain = period_chain(model, z, &d, time_constant, samples)?;
    let Some(y) = stationary(&chain.f, &chain.w) else {
        return Ok(LockInNoise::NONE);
    };
    let (x, yy) = chain.harmonic;
    let a2 = x * x + yy * yy;
    let n = chain.f.nrows();
    let quad = |g: [f64; 2]| {
        let (i, j) = (n - 2, n - 1);
        (g[0] * g[0] * y[(i, i)] + 2.0 * g[0] * g[1] * y[(i, j)] + g[1] * g[1] * y[(j, j)]).sqrt()
    };
    let a = a2.sqrt();
    Ok(LockInNoise {
        amplitude: quad([x / a, yy / a]),
        phase: quad([-yy / a2, x / a2]),
    })
}

/// The chain over one period (module docs).
struct Chain {
    /// The period map F, (2N + 4)², the lock-in's four states last: X, Y, X̄, Ȳ.
    f: DMatrix<f64>,
    /// The noise covariance W injected over the period, carried to its end.
    w: DMatrix<f64>,
    /// The orbit's first harmonic (X, Y).
    harmonic: (f64, f64),
}

/// The chain of the orbit through (0, `z`) over one period.
fn period_chain(
    model: &CantileverModel,
    z: &DVector<f64>,
    d: &[DMatrix<f64>; 2],
    time_constant: f64,
    samples: usize,
) -> Result<Chain, SimError> {
    let dim = z.len();
    let n = dim + 4;
    let (ix, iy, ixb, iyb) = (dim, dim + 1, dim + 2, dim + 3);
    let p = model.params();
    let period = model.period();
    let mut integ = build(model, IntegratorOptions::default(), 0.0, z)?;
    let mut tip = DVector::zeros(dim);
    tip.rows_mut(0, model.modes()).copy_from(model.tip());
    let (mut f, mut w) = (DMatrix::identity(n, n), DMatrix::zeros(n, n));
    let (mut state, mut tau) = (z.clone(), 0.0);
    let mut d_a = &d[model.region_at(0.0, z).index()];
    let (mut x, mut y) = (0.0, 0.0);
    let parts = samples * SUBSTEPS;
    let mut m = DMatrix::identity(n, n);
    for k in 1..=parts {
        let t1 = period * k as f64 / parts as f64;
        let fl = flow(integ.as_mut(), tau, &state, t1, None, false)?;
        let d_b = &d[model.region_at(t1, &fl.state).index()];
        let h = t1 - tau;
        let jac = &fl.jacobian;
        let q = (jac * d_a * jac.transpose() + d_b) * (0.5 * h);
        m.fill_with_identity();
        m.view_mut((0, 0), (dim, dim)).copy_from(jac);
        apply(&m, &mut f, &mut w);
        let mut top = w.view_mut((0, 0), (dim, dim));
        top += &q;
        (state, tau, d_a) = (fl.state, t1, d_b);
        if k % SUBSTEPS == 0 {
            // the lock-in's sample j = k / SUBSTEPS at θ_j = Ωτ_j + ψ
            let (s, c) = (p.omega * t1 + p.drive_phase()).sin_cos();
            let wt = tip.dot(&state);
            let scale = 2.0 / samples as f64;
            x += scale * wt * s;
            y -= scale * wt * c;
            m.fill_with_identity();
            for j in 0..dim {
                m[(ix, j)] = scale * s * tip[j];
                m[(iy, j)] = -scale * c * tip[j];
            }
            apply(&m, &mut f, &mut w);
        }
    }
    // the period's end: X̄ ← (1 − β) X̄ + β X, then the sums start again
    let beta = crate::analysis::am_loop::lock_in_beta(time_constant, period);
    m.fill_with_identity();
    for (i, from) in [(ixb, ix), (iyb, iy)] {
        m[(i, i)] = 1.0 - beta;
        m[(i, from)] = beta;
    }
    for i in [ix, iy] {
        m[(i, i)] = 0.0;
    }
    apply(&m, &mut f, &mut w);
    Ok(Chain {
        f,
        w,
        harmonic: (x, y),
    })
}

/// F ← M F, W ← M W Mᵀ.
fn apply(m: &DMatrix<f64>, f: &mut DMatrix<f64>, w: &mut DMatrix<f64>) {
    *f = m * &*f;
    *w = m * &*w * m.transpose();
}

/// The stationary covariance Y = F Y Fᵀ + W by doubling (module docs): `None` where F^(2^k)
/// does not go to zero (an unstable or marginal chain).
fn stationary(f: &DMatrix<f64>, w: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let (mut a, mut y) = (f.clone(), w.clone());
    for _ in 0..DOUBLINGS {
        y += &a * &y * a.transpose();
        a = &a * &a;
        let size = a.amax();
        if !size.is_finite() || size > 1e12 {
            return None;
        }
        if size < 1e-15 {
            return Some(0.5 * (&y + y.transpose()));
        }
    }
    None
}

#[cfg(test)]
pub(crate) mod tests;
