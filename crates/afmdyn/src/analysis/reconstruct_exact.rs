//! The exact inversion of the first-order FM relation (issue 62 §3): the force whose
//! frequency shift, by Giessibl's relation, is the measured one — Sader and Jarvis's estimate
//! ([`super::reconstruct::sader_jarvis`], a few per cent off at intermediate amplitudes)
//! corrected through the forward relation until the two agree.
//!
//! **Forward relation, discrete.** The force is taken piecewise linear between the curve's
//! distances d_j (hat functions h_j), and 0 from the last distance on (the end of the data,
//! as the Sader–Jarvis integral takes it). Giessibl's relation (Phys. Rev. B 56, 16010
//! (1997), eq. 13; [`super::reconstruct::giessibl_shift`]), Δf = −f0 I / (2kA) with
//! I(d) = (1/π) ∫₀^{2π} F(d + A + A cos θ) cos θ dθ, is then exact in the nodal values:
//! Δf_k = −f0/(2kA) Σ_j w_kj F_j, the hat weights w_kj in closed form — the matrix of
//! Giessibl's matrix method (F. J. Giessibl, Appl. Phys. Lett. 78, 123 (2001)) in its
//! piecewise-linear form (J. Welker, E. Illek and F. J. Giessibl, Beilstein J. Nanotechnol.
//! 3, 238 (2012)), the weights of `super::reconstruct_am` with the amplitude constant.
//! A row sees the nodes within its cycle, [d_k, d_k + 2A]: the matrix is triangular. On a
//! uniform grid (spacing h) w_kj depends on j − k only, and the forward relation is a
//! correlation with M + 1 = ⌈2A/h⌉ + 2 weights: by FFT (O(N log N)) when M >
//! `DIRECT_WEIGHTS`, else summed (O(N·M)). On another grid each row's weights are computed
//! once, at most `MAX_EXACT_WEIGHTS` of them (checked before the run, `exact_weights`).
//!
//! **Inversion (defect correction).** With SJ the Sader–Jarvis operator on the same grid and
//! G the discrete forward relation,
//!
//! F₀ = SJ\[Δf\],  F_{n+1} = F_n + SJ\[Δf − G F_n\]
//!
//! (the residual's last row set to 0: the force at the last distance is the end of the data,
//! 0, as Sader–Jarvis's is). A fixed point has SJ\[Δf − G F\] = 0, hence Δf = G F on every row
//! but the last: the exact solution of the triangular system of the matrix method. SJ is an
//! approximate inverse of G (within a few per cent on smooth curves), so each step shrinks
//! the residual by that factor — the classical defect (residual) correction of an approximate
//! solver (H. J. Stetter, Numer. Math. 29, 425 (1978)), here with the matrix method's exact
//! forward operator and Sader–Jarvis's O(N log N) inverse instead of the triangular solve's
//! O(N·M) back substitution, whose error of one row rings through the next ones with a factor
//! ≈ −0.83 (`super::reconstruct_am`).
//!
//! **Convergence.** The forward residual ρ_n = max_k |Δf_k − (G F_n)_k| / max_k |Δf_k| (all
//! rows but the last) is computed after each step. The iteration stops when ρ ≤
//! `EXACT_TOLERANCE` (the data's round-off: converged), when a step leaves more than
//! `STALL_RATIO` of it (stalled: the step is kept only if it lowered ρ), or after
//! `EXACT_MAX_ITERATIONS` steps. [`ExactRecord`] reports the steps, ρ before and after and
//! whether it converged. Measured on the van der Waals round trip (tests/reconstruct_exact.rs):
//! ρ falls from ~10⁻² (Sader–Jarvis) to ~10⁻⁵ in 3 to 5 steps, the residual of each row
//! below 10⁻⁸ of its own Δf away from the data's end; what is left sits in the rows within
//! 2A of the end, whose cycles reach beyond the data, where Sader–Jarvis's correction (with
//! its end conditions) no longer shrinks it: the iteration stalls there rather than converge
//! to round-off.
//!
//! **Accuracy.** The piecewise-linear force is exact for the discrete relation; against the
//! continuous one its error is the interpolation's, ≈ h² |F″| / 8 (0.75 (h/d)² of a van der
//! Waals force 1/d²). On noisy data the exact inverse follows the noise, as every exact
//! inverse does: tests/reconstruct_exact.rs measures it against Sader–Jarvis.
//!
//! Units: any consistent set (SI: d and A in m, Δf and f0 in Hz, k in N/m → F in N, U in J).

use super::progress::Progress;
pub(crate) use super::reconstruct::ExactRecord;
use super::reconstruct::{sader_jarvis, uniform_spacing, Reconstruction, ShiftCurve};
use super::reconstruct_am::{nodes_within, weight};
use crate::error::SimError;
use rustfft::{num_complex::Complex, Fft, FftPlanner};
use std::sync::Arc;

/// The forward residual (relative to the largest |Δf|) at which the iteration has converged:
/// the round-off of the data and of the forward relation's sums.
pub(crate) const EXACT_TOLERANCE: f64 = 1e-12;

/// A step that leaves more than this share of the forward residual has stalled: the
/// iteration stops.
pub(crate) const STALL_RATIO: f64 = 0.9;

/// The most correction steps.
pub(crate) const EXACT_MAX_ITERATIONS: usize = 50;

/// On a uniform grid, a forward relation with at most this many weights beyond the diagonal
/// is summed directly; with more, by FFT.
pub(crate) const DIRECT_WEIGHTS: usize = 64;

/// The most hat weights of the forward relation on a grid that is not uniform (8 bytes each:
/// 160 MB at the limit), as [`super::reconstruct_am::MAX_AM_WEIGHTS`].
pub(crate) const MAX_EXACT_WEIGHTS: usize = super::reconstruct_am::MAX_AM_WEIGHTS;

/// The discrete forward relation of a curve ([module doc](self)).
enum Forward {
    /// Uniform grid: the weights w_m, m = 0..=M, and the FFT of their correlation.
    Toeplitz {
        weights: Vec<f64>,
        fft: Option<Correlation>,
    },
    /// Another grid: per row, its first node and the weights from it.
    Rows(Vec<(usize, Vec<f64>)>),
}

/// The correlation Σ_m w_m F_{k+m} by FFT: the kernel's transform and the plans.
struct Correlation {
    kernel: Vec<Complex<f64>>,
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
}

/// The hat weights of a uniform grid of `n` points of spacing `h` for amplitude `a`: w_m for
/// the node m spacings beyond a row's own, m = 0..=min(M, n − 1), M = ⌈2a/h⌉ + 1 (the last
/// hat that meets the cycle [0, 2a]).
fn toeplitz_weights(n: usize, h: f64, a: f64) -> Vec<f64> {
    let m_max = ((2.0 * a / h).ceil() as usize + 1).min(n - 1);
    // a grid −h, 0, h, …, (M + 1) h: node m + 1 sits m spacings beyond the cycle's bottom 0
    let x: Vec<f64> = (0..m_max + 3).map(|i| (i as f64 - 1.0) * h).collect();
    (0..=m_max).map(|m| weight(&x, m + 1, a, a)).collect()
}

/// The number of hat weights the forward relation of `curve` needs on a grid that is not
/// uniform (rows 0..N − 1, each its nodes within the cycle), or 0 on a uniform grid.
pub(crate) fn exact_weights(curve: &ShiftCurve) -> usize {
    let d = &curve.distance;
    if uniform_spacing(d).is_some() {
        return 0;
    }
    let a = curve.amplitude;
    (0..d.len())
        .map(|k| nodes_within(d, d[k] + a, a).end.saturating_sub(k))
        .sum()
}

/// Check that the exact inversion can run on `curve`, before any work.
///
/// # Errors
/// As [`ShiftCurve::method`]; [`SimError::OutOfRange`] naming `distance` when a grid that is
/// not uniform needs more than [`MAX_EXACT_WEIGHTS`] weights ([`exact_weights`]).
pub(crate) fn check_exact(curve: &ShiftCurve) -> Result<(), SimError> {
    curve.method()?;
    let weights = exact_weights(curve);
    if weights > MAX_EXACT_WEIGHTS {
        return Err(SimError::out_of_range(
            "distance",
            format!("a grid not evenly spaced whose cycles span {weights} hat weights"),
            "must need at most 20000000 weights for the exact inversion (each cycle spans 2A \
             of the curve): resample the curve onto an even grid, or use the Sader-Jarvis \
             inversion",
        ));
    }
    Ok(())
}

impl Forward {
    /// The forward relation of `curve` (validated).
    fn new(curve: &ShiftCurve) -> Forward {
        let (d, a) = (&curve.distance, curve.amplitude);
        let n = d.len();
        match uniform_spacing(d) {
            Some(h) => {
                let weights = toeplitz_weights(n, h, a);
                let fft = (weights.len() > DIRECT_WEIGHTS + 1).then(|| {
                    let len = (n + weights.len()).next_power_of_two();
                    let mut planner = FftPlanner::new();
                    let forward = planner.plan_fft_forward(len);
                    let inverse = planner.plan_fft_inverse(len);
                    let mut kernel = vec![Complex::new(0.0, 0.0); len];
                    for (v, w) in kernel.iter_mut().zip(&weights) {
                        v.re = *w;
                    }
                    forward.process(&mut kernel);
                    Correlation {
                        kernel,
                        forward,
                        inverse,
                    }
                });
                Forward::Toeplitz { weights, fft }
            }
            None => Forward::Rows(
                (0..n)
                    .map(|k| {
                        let nodes = k..nodes_within(d, d[k] + a, a).end.max(k);
                        let w = nodes.clone().map(|j| weight(d, j, d[k] + a, a)).collect();
                        (k, w)
                    })
                    .collect(),
            ),
        }
    }

    /// The integrals I_k = Σ_j w_kj F_j of the nodal forces `force`.
    fn integrals(&self, force: &[f64]) -> Vec<f64> {
        let n = force.len();
        match self {
            Forward::Toeplitz { fft: Some(c), .. } => {
                // the correlation as the convolution of the kernel with F reversed
                let len = c.kernel.len();
                let mut data = vec![Complex::new(0.0, 0.0); len];
                for (p, v) in data.iter_mut().enumerate().take(n) {
                    v.re = force[n - 1 - p];
                }
                c.forward.process(&mut data);
                for (x, y) in data.iter_mut().zip(&c.kernel) {
                    *x *= y;
                }
                c.inverse.process(&mut data);
                (0..n).map(|k| data[n - 1 - k].re / len as f64).collect()
            }
            Forward::Toeplitz { weights, fft: None } => (0..n)
                .map(|k| weights.iter().zip(&force[k..]).map(|(w, f)| w * f).sum())
                .collect(),
            Forward::Rows(rows) => rows
                .iter()
                .map(|(start, w)| w.iter().zip(&force[*start..]).map(|(w, f)| w * f).sum())
                .collect(),
        }
    }
}

/// The frequency shifts, by the discrete forward relation ([module doc](self)), of the
/// piecewise-linear force with values `force` at the distances of `curve` (0 beyond the
/// last), with its k, f0 and A: Δf_k = −f0/(2kA) Σ_j w_kj F_j.
///
/// # Errors
/// As [`ShiftCurve::validate`] (the curve's own shifts are not used), and `force` of another
/// length naming `force`.
pub fn forward_shift(curve: &ShiftCurve, force: &[f64]) -> Result<Vec<f64>, SimError> {
    curve.validate()?;
    if force.len() != curve.distance.len() {
        return Err(SimError::out_of_range(
            "force",
            force.len(),
            "must have one value per distance",
        ));
    }
    Ok(shifts(&Forward::new(curve), curve, force))
}

/// −f0/(2kA) × the integrals.
fn shifts(forward: &Forward, curve: &ShiftCurve, force: &[f64]) -> Vec<f64> {
    let scale = -curve.resonance_frequency / (2.0 * curve.spring_constant * curve.amplitude);
    forward
        .integrals(force)
        .into_iter()
        .map(|i| scale * i)
        .collect()
}

/// The force and potential of `curve` by the exact inversion ([module doc](self)), with its
/// [`ExactRecord`] (`exact`).
///
/// It counts the Sader–Jarvis estimate's rows in `progress` and checks its cancel flag between
/// steps.
///
/// # Errors
/// As `check_exact`; [`SimError::Cancelled`] once `progress` is cancelled.
pub fn exact_inversion(
    curve: &ShiftCurve,
    progress: &Progress,
) -> Result<Reconstruction, SimError> {
    check_exact(curve)?;
    let forward = Forward::new(curve);
    let n = curve.distance.len();
    let target = &curve.frequency_shift;
    let scale = target.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // the residual of every row but the last (the end of the data), relative to the largest |Δf|
    let residual = |force: &[f64]| -> (Vec<f64>, f64) {
        let mut r: Vec<f64> = target
            .iter()
            .zip(shifts(&forward, curve, force))
            .map(|(t, g)| t - g)
            .collect();
        r[n - 1] = 0.0;
        let worst = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        (r, if scale > 0.0 { worst / scale } else { 0.0 })
    };
    let mut force = sader_jarvis(curve, progress)?.force;
    let (mut r, mut rho) = residual(&force);
    let sader_jarvis_residual = rho;
    let mut iterations = 0;
    while rho > EXACT_TOLERANCE && iterations < EXACT_MAX_ITERATIONS {
        progress.check()?;
        let correction = sader_jarvis(
            &ShiftCurve {
                frequency_shift: r.clone(),
                ..curve.clone()
            },
            &Progress::new(),
        )?
        .force;
        let trial: Vec<f64> = force.iter().zip(&correction).map(|(f, c)| f + c).collect();
        let (r_trial, rho_trial) = residual(&trial);
        iterations += 1;
        let stalled = rho_trial > STALL_RATIO * rho;
        if rho_trial < rho {
            (force, r, rho) = (trial, r_trial, rho_trial);
        }
        if stalled {
            break;
        }
    }
    let record = ExactRecord {
        iterations,
        sader_jarvis_residual,
        forward_residual: rho,
        converged: rho <= EXACT_TOLERANCE,
    };
    Ok(Reconstruction::of(
        curve.distance.clone(),
        force,
        Some(record),
    ))
}
