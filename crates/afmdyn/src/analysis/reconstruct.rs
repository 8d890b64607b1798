//! Force reconstruction from frequency-modulation (FM) AFM data (issue 44 item 4): the
//! tip–sample force F(d) and potential U(d) against the distance of closest approach d, from
//! the frequency shift Δf(d) of a cantilever of stiffness k, free resonance f0 and oscillation
//! amplitude A — the Sader–Jarvis inversion, and the forward relation it inverts.
//!
//! **Forward (Giessibl).** To first order in the force, an oscillation of amplitude A whose
//! lower turning point is at distance d shifts the resonance by
//!
//! Δf(d) = −(f0 / (π k A)) ∫₋₁¹ F(d + A (1 + u)) u / √(1 − u²) du
//!
//! (F. J. Giessibl, Phys. Rev. B 56, 16010 (1997), eq. 13 with the tip at d + A(1 + u);
//! [`giessibl_shift`], by Gauss–Chebyshev quadrature of the first kind). Its small-amplitude
//! limit is −f0 F′(d) / (2k); for a force linear in d it is that limit at every amplitude.
//!
//! **Inverse (Sader & Jarvis).** With Ω(d) = Δf(d) / f0,
//!
//! F(d) = 2k ∫_d^∞ [ (1 + A^{1/2} / (8 √(π (t − d)))) Ω(t) − A^{3/2} / √(2 (t − d)) Ω′(t) ] dt
//!
//! (J. E. Sader and S. P. Jarvis, Appl. Phys. Lett. 84, 1801 (2004), eq. 9: accurate to a few
//! per cent at any amplitude, exact in the small- and large-amplitude limits; its error
//! against the amplitude over the force's decay length, with two minima and a maximum
//! between them: J. Welker, E. Illek and F. J. Giessibl, Beilstein J. Nanotechnol. 3, 238
//! (2012)). Discretised as
//! the paper's authors do (and the published implementations after them): the trapezoidal rule
//! on the grid beyond the next point, and on the first interval [d_j, d_{j+1}] the integral
//! taken exactly with Ω and Ω′ held at their values at d_j — which removes the integrable
//! 1/√(t − d) singularity: Ω_j Δ + (A^{1/2}/(4√π)) Ω_j √Δ − √2 A^{3/2} Ω′_j √Δ. Ω′ by
//! central differences (one-sided at the ends). The integral stops at the last distance given:
//! the data must reach where Δf has decayed (the force at the far end of the grid is not
//! reconstructed well). The potential is U(d) = ∫_d^{d_max} F(t) dt (trapezoidal, U(d_max) = 0).
//!
//! **Cost.** The sum is over every pair of points, O(N²) ([`sader_jarvis_direct`], the
//! reference: 26 to 70 s for 10⁵ points as it was written before the FFT). With the integrand written
//! Ω(t) + g(t)/√(t − d), g = (A^{1/2}/(8√π)) Ω − (A^{3/2}/√2) Ω′, the Ω part of the trapezoid
//! beyond the first interval is a suffix sum (O(N)), and the g part Σ_i w_i g_i / √(d_i − d_j)
//! depends on d_i − d_j only: on a uniform grid it is a correlation with the kernel 1/√(m h),
//! taken by FFT ([`sader_jarvis`] on a grid that `uniform_spacing` accepts: O(N log N)). The
//! FFT takes the kernel at m h for m > `NEAR_FIELD` only; the nearer terms, where a grid's
//! round-off moves the kernel most, are summed directly with the grid's own distances, and the
//! trapezoid weights and the first interval use the grid's own spacings: the result is the
//! direct sum's, to round-off (on an exactly even grid) or to the grid's unevenness (≤
//! `UNIFORM_TOLERANCE` of a spacing, divided by `NEAR_FIELD`) — tests/reconstruct.rs.
//! The size is bounded before the run (`ShiftCurve::method`): at most `MAX_UNIFORM_POINTS`
//! points on a uniform grid (the FFT's buffers: three of 16 bytes × the next power of two ≥
//! 2N, 200 MB at the limit), at most `MAX_DIRECT_POINTS` on another grid (the direct sum's
//! N²/2 pairs, 2·10⁸ at the limit: some 3 s on one core). Both check their
//! [`Progress`]'s cancel flag between chunks of rows.
//!
//! Units: any consistent set (SI: d and A in m, Δf and f0 in Hz, k in N/m → F in N, U in J).

use crate::analysis::progress::Progress;
use crate::error::SimError;
use gauss_quad::chebyshev::GaussChebyshevFirstKind;
use std::num::NonZeroUsize;

/// Default number of Gauss–Chebyshev nodes of [`giessibl_shift`]: exponential convergence for
/// a force analytic on the orbit; 256 nodes resolve a van der Waals force at d/A = 10⁻³.
pub const GIESSIBL_NODES: usize = 256;

/// The frequency shift Δf of an oscillation of amplitude `a` whose lower turning point is at
/// distance `d`, to first order in the force `force(distance)` (Giessibl; module doc), with
/// `nodes` Gauss–Chebyshev nodes (at least 1).
pub fn giessibl_shift(
    force: &dyn Fn(f64) -> f64,
    d: f64,
    k: f64,
    f0: f64,
    a: f64,
    nodes: usize,
) -> f64 {
    let rule =
        GaussChebyshevFirstKind::new(NonZeroUsize::new(nodes.max(1)).unwrap_or(NonZeroUsize::MIN));
    let integral = rule.integrate(-1.0, 1.0, |u| force(d + a * (1.0 + u)) * u);
    -f0 / (std::f64::consts::PI * k * a) * integral
}

/// A frequency-shift curve to invert: distances of closest approach, increasing, and the
/// shift at each, with the cantilever's constants.
#[derive(Debug, Clone, PartialEq)]
pub struct ShiftCurve {
    /// Distances of closest approach d, strictly increasing, ≥ 3 of them.
    pub distance: Vec<f64>,
    /// Frequency shifts Δf(d) (same length).
    pub frequency_shift: Vec<f64>,
    /// Spring constant k, > 0.
    pub spring_constant: f64,
    /// Free resonance frequency f0, > 0.
    pub resonance_frequency: f64,
    /// Oscillation amplitude A, > 0.
    pub amplitude: f64,
}

/// The reconstructed force and potential, at the curve's distances.
#[derive(Debug, Clone, PartialEq)]
pub struct Reconstruction {
    /// Distances of closest approach d (the curve's).
    pub distance: Vec<f64>,
    /// F(d) (attractive < 0).
    pub force: Vec<f64>,
    /// U(d) = ∫_d^{d_max} F dt.
    pub potential: Vec<f64>,
    /// How the exact inversion went ([`crate::analysis::reconstruct_exact`]); `None` for
    /// the Sader–Jarvis and AM inversions.
    pub exact: Option<ExactRecord>,
}

/// How the exact inversion went ([`crate::analysis::reconstruct_exact`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ExactRecord {
    /// Correction steps taken (0: the Sader–Jarvis estimate already met the tolerance).
    pub iterations: usize,
    /// The forward residual ρ of the Sader–Jarvis estimate: max |Δf − G F| over max |Δf|,
    /// every row but the last.
    pub sader_jarvis_residual: f64,
    /// The forward residual ρ of the result.
    pub forward_residual: f64,
    /// ρ ≤ `crate::analysis::reconstruct_exact::EXACT_TOLERANCE` (else the iteration
    /// stalled or reached its cap).
    pub converged: bool,
}

impl ShiftCurve {
    /// Check the curve.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the field: fewer than 3 points, lengths that differ,
    /// distances not strictly increasing, a value not finite, constants not > 0.
    pub fn validate(&self) -> Result<(), SimError> {
        positive_constants(&[
            ("spring_constant", self.spring_constant),
            ("resonance_frequency", self.resonance_frequency),
            ("amplitude", self.amplitude),
        ])?;
        let n = self.distance.len();
        if n < 3 {
            return Err(SimError::out_of_range(
                "distance",
                n,
                "needs at least 3 points",
            ));
        }
        if self.frequency_shift.len() != n {
            return Err(SimError::out_of_range(
                "frequency_shift",
                self.frequency_shift.len(),
                "must have one value per distance",
            ));
        }
        for (name, values) in [
            ("distance", &self.distance),
            ("frequency_shift", &self.frequency_shift),
        ] {
            if let Some(v) = values.iter().find(|v| !v.is_finite()) {
                return Err(SimError::out_of_range(name, v, "must be finite"));
            }
        }
        if let Some(w) = self.distance.windows(2).find(|w| w[1] <= w[0]) {
            return Err(SimError::out_of_range(
                "distance",
                w[1],
                "must increase strictly (sort the curve by distance)",
            ));
        }
        Ok(())
    }
}

/// A grid is uniform when every distance lies within this fraction of a spacing of its place
/// on the even grid d_0 + i h, h = (d_max − d_0)/(N − 1): a grid written as d_0 + i h in
/// floating point (numpy's `linspace`, `arange`) is off by about 10⁻¹⁶ N d_max/(d_max − d_0)
/// spacings, 2·10⁻¹⁰ at the [`MAX_UNIFORM_POINTS`] limit; a grid printed to fewer digits than
/// its spacing needs is not.
pub(crate) const UNIFORM_TOLERANCE: f64 = 1e-9;

/// The most points of a uniform grid ([`UNIFORM_TOLERANCE`]): the FFT's three buffers of 16
/// bytes × the next power of two ≥ 2N take 200 MB at 2·10⁶ points (and the documents of the
/// front ends some 100 bytes a point).
pub(crate) const MAX_UNIFORM_POINTS: usize = 2_000_000;

/// The most points of a grid that is not uniform: the direct sum's N²/2 pairs, 2·10⁸ at
/// 20 000 points, take some 3 s on one core (measured: 0.66 s for 10⁴ points,
/// scripts/perf-reconstruct.sh).
pub(crate) const MAX_DIRECT_POINTS: usize = 20_000;

/// The terms of the g part with i − j ≤ `NEAR_FIELD` are summed directly with the grid's own
/// distances, the rest by FFT with the kernel at (i − j) h (module doc).
pub(crate) const NEAR_FIELD: usize = 32;

/// Rows of the direct sum between two checks of the cancel flag.
const CHUNK: usize = 256;

/// How [`sader_jarvis`] sums a curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Method {
    /// The g part by FFT on a uniform grid of spacing `h` (module doc).
    Fft {
        /// The spacing (d_max − d_0)/(N − 1).
        h: f64,
    },
    /// The direct O(N²) sum ([`sader_jarvis_direct`]).
    Direct,
}

/// The spacing of `d` (increasing, ≥ 2 values) when it is uniform to [`UNIFORM_TOLERANCE`].
pub(crate) fn uniform_spacing(d: &[f64]) -> Option<f64> {
    let n = d.len();
    if n < 2 {
        return None;
    }
    let h = (d[n - 1] - d[0]) / (n - 1) as f64;
    let uniform = d
        .iter()
        .enumerate()
        .all(|(i, &x)| (x - (d[0] + i as f64 * h)).abs() <= UNIFORM_TOLERANCE * h);
    (h > 0.0 && uniform).then_some(h)
}

impl ShiftCurve {
    /// How [`sader_jarvis`] will sum the curve (checked before it runs: the size limits).
    ///
    /// # Errors
    /// As [`ShiftCurve::validate`]; [`SimError::OutOfRange`] naming `distance` for more than
    /// [`MAX_UNIFORM_POINTS`] points on a uniform grid or [`MAX_DIRECT_POINTS`] on another.
    pub(crate) fn method(&self) -> Result<Method, SimError> {
        self.validate()?;
        let n = self.distance.len();
        match uniform_spacing(&self.distance) {
            Some(h) if n <= MAX_UNIFORM_POINTS => Ok(Method::Fft { h }),
            Some(_) => Err(SimError::out_of_range(
                "distance",
                format!("{n} values (an evenly spaced grid)"),
                "must hold at most 2000000 values (the FFT's memory): take every other point \
                 or a shorter range",
            )),
            None if n <= MAX_DIRECT_POINTS => Ok(Method::Direct),
            None => Err(SimError::out_of_range(
                "distance",
                format!("{n} values, not evenly spaced"),
                "must hold at most 20000 values when not evenly spaced (the direct sum's cost \
                 grows as N²): resample the curve onto an even grid (every distance within \
                 1e-9 of a spacing of d0 + i h), which is inverted by FFT up to 2000000 values",
            )),
        }
    }
}

/// Ω = Δf/f0 and Ω′ by central differences (one-sided at the ends) on the curve's grid.
fn omega_and_slope(curve: &ShiftCurve) -> (Vec<f64>, Vec<f64>) {
    let d = &curve.distance;
    let n = d.len();
    let omega: Vec<f64> = curve
        .frequency_shift
        .iter()
        .map(|df| df / curve.resonance_frequency)
        .collect();
    // Ω′ by central differences on the (possibly uneven) grid, one-sided at the ends
    let slope: Vec<f64> = (0..n)
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(1), (i + 1).min(n - 1));
            (omega[hi] - omega[lo]) / (d[hi] - d[lo])
        })
        .collect();
    (omega, slope)
}

/// The integral over the first interval [d_j, d_j + `step`], exactly with Ω, Ω′ held at d_j
/// (the 1/√(t − d) singularity; module doc).
fn first_interval(omega: f64, slope: f64, step: f64, a: f64) -> f64 {
    let (sa, a32) = (a.sqrt(), a.powf(1.5));
    let pi_sqrt = std::f64::consts::PI.sqrt();
    omega * step + sa / (4.0 * pi_sqrt) * omega * step.sqrt()
        - std::f64::consts::SQRT_2 * a32 * slope * step.sqrt()
}

/// The force and potential of `curve` by the Sader–Jarvis inversion (module doc): by FFT on a
/// uniform grid, else by the direct sum (`ShiftCurve::method`).
///
/// It counts the curve's points in `progress` and checks its cancel flag between chunks of
/// rows.
///
/// # Errors
/// As `ShiftCurve::method`; [`SimError::Cancelled`] once `progress` is cancelled.
pub fn sader_jarvis(curve: &ShiftCurve, progress: &Progress) -> Result<Reconstruction, SimError> {
    match curve.method()? {
        Method::Fft { h } => sader_jarvis_fft(curve, h, progress),
        Method::Direct => sader_jarvis_direct(curve, progress),
    }
}

/// The Sader–Jarvis inversion by the direct O(N²) sum, term by term as the module doc writes
/// it: the reference of the FFT, and the method on a grid that is not uniform. No size limit
/// (the caller's: `ShiftCurve::method`).
///
/// # Errors
/// As [`ShiftCurve::validate`]; [`SimError::Cancelled`] once `progress` is cancelled.
pub fn sader_jarvis_direct(
    curve: &ShiftCurve,
    progress: &Progress,
) -> Result<Reconstruction, SimError> {
    curve.validate()?;
    let d = &curve.distance;
    let n = d.len();
    progress.add_total(n);
    let (k, a) = (curve.spring_constant, curve.amplitude);
    let (omega, slope) = omega_and_slope(curve);
    let (sa, a32) = (a.sqrt(), a.powf(1.5));
    let mut force = vec![0.0; n];
    for j in 0..n - 1 {
        if j % CHUNK == 0 {
            progress.check()?;
            progress.advance(CHUNK.min(n - 1 - j));
        }
        let z = d[j];
        let first = first_interval(omega[j], slope[j], d[j + 1] - z, a);
        let integrand = |i: usize| {
            let s = d[i] - z;
            (1.0 + sa / (8.0 * (std::f64::consts::PI * s).sqrt())) * omega[i]
                - a32 / (2.0 * s).sqrt() * slope[i]
        };
        // the trapezoid beyond the first interval, each integrand value computed once
        let mut rest = 0.0;
        if j + 2 < n {
            let mut previous = integrand(j + 1);
            for i in j + 1..n - 1 {
                let next = integrand(i + 1);
                rest += 0.5 * (previous + next) * (d[i + 1] - d[i]);
                previous = next;
            }
        }
        force[j] = 2.0 * k * (first + rest);
    }
    // the last point has no interval beyond it: its force is the end of the data
    force[n - 1] = 0.0;
    progress.advance(1);
    Ok(Reconstruction::of(d.clone(), force, None))
}

/// The Sader–Jarvis inversion on a uniform grid of spacing `h` (module doc: the Ω part by a
/// suffix sum, the g part near the diagonal directly and beyond it by FFT).
///
/// # Errors
/// [`SimError::Cancelled`] once `progress` is cancelled.
fn sader_jarvis_fft(
    curve: &ShiftCurve,
    h: f64,
    progress: &Progress,
) -> Result<Reconstruction, SimError> {
    use rustfft::{num_complex::Complex, FftPlanner};
    let d = &curve.distance;
    let n = d.len();
    progress.add_total(n);
    progress.check()?;
    let (k, a) = (curve.spring_constant, curve.amplitude);
    let (omega, slope) = omega_and_slope(curve);
    let (sa, a32) = (a.sqrt(), a.powf(1.5));
    // the integrand beyond the first interval is Ω_i + g_i / √(d_i − d_j)
    let g: Vec<f64> = (0..n)
        .map(|i| {
            sa / (8.0 * std::f64::consts::PI.sqrt()) * omega[i]
                - a32 / std::f64::consts::SQRT_2 * slope[i]
        })
        .collect();
    let step = |i: usize| if i + 1 < n { d[i + 1] - d[i] } else { 0.0 };
    // trapezoid weights of point i when it is not the first beyond the first interval
    let w: Vec<f64> = (0..n)
        .map(|i| 0.5 * (if i > 0 { step(i - 1) } else { 0.0 } + step(i)))
        .collect();
    // the Ω part: suffix sums of the trapezoid segments, tail[i] = Σ_{i' ≥ i} segments
    let mut tail = vec![0.0; n];
    for i in (0..n - 1).rev() {
        tail[i] = tail[i + 1] + 0.5 * (omega[i] + omega[i + 1]) * step(i);
    }
    // the g part beyond the near field: far[j] = Σ_{m > NEAR_FIELD} w g_{j+m} / √(m h), the
    // correlation of u = w g with the kernel, as the convolution of the kernel with u reversed
    let far: Vec<f64> = if n > NEAR_FIELD + 1 {
        let len = (2 * n - 1).next_power_of_two();
        let mut kernel = vec![Complex::new(0.0, 0.0); len];
        for (m, v) in kernel.iter_mut().enumerate().take(n).skip(NEAR_FIELD + 1) {
            v.re = 1.0 / (m as f64 * h).sqrt();
        }
        let mut data = vec![Complex::new(0.0, 0.0); len];
        for (p, v) in data.iter_mut().enumerate().take(n) {
            let i = n - 1 - p;
            v.re = w[i] * g[i];
        }
        let mut planner = FftPlanner::new();
        let forward = planner.plan_fft_forward(len);
        let mut scratch = vec![Complex::new(0.0, 0.0); forward.get_inplace_scratch_len()];
        forward.process_with_scratch(&mut kernel, &mut scratch);
        progress.check()?;
        forward.process_with_scratch(&mut data, &mut scratch);
        progress.check()?;
        for (x, y) in data.iter_mut().zip(&kernel) {
            *x *= y;
        }
        drop(kernel);
        let inverse = planner.plan_fft_inverse(len);
        scratch.resize(inverse.get_inplace_scratch_len(), Complex::new(0.0, 0.0));
        inverse.process_with_scratch(&mut data, &mut scratch);
        progress.check()?;
        (0..n).map(|j| data[n - 1 - j].re / len as f64).collect()
    } else {
        vec![0.0; n]
    };
    let mut force = vec![0.0; n];
    for j in 0..n - 1 {
        if j % (16 * CHUNK) == 0 {
            progress.check()?;
            progress.advance((16 * CHUNK).min(n - 1 - j));
        }
        let first = first_interval(omega[j], slope[j], step(j), a);
        let mut rest = 0.0;
        if j + 2 < n {
            // the first point beyond the first interval has half its following step only
            let s = d[j + 1] - d[j];
            rest += 0.5 * step(j + 1) * g[j + 1] / s.sqrt();
            for i in j + 2..n.min(j + NEAR_FIELD + 1) {
                rest += w[i] * g[i] / (d[i] - d[j]).sqrt();
            }
            if j + NEAR_FIELD + 1 < n {
                rest += far[j];
            }
            rest += tail[j + 1];
        }
        force[j] = 2.0 * k * (first + rest);
    }
    force[n - 1] = 0.0;
    progress.advance(1);
    Ok(Reconstruction::of(d.clone(), force, None))
}

impl Reconstruction {
    /// The reconstruction of `force` at the increasing distances `d`, its potential
    /// U(d_j) = ∫_{d_j}^{d_max} F dt by the trapezoidal rule (U(d_max) = 0): the end of every
    /// inversion.
    pub(crate) fn of(d: Vec<f64>, force: Vec<f64>, exact: Option<ExactRecord>) -> Reconstruction {
        let n = d.len();
        let mut potential = vec![0.0; n];
        for j in (0..n.saturating_sub(1)).rev() {
            potential[j] = potential[j + 1] + 0.5 * (force[j] + force[j + 1]) * (d[j + 1] - d[j]);
        }
        Reconstruction {
            distance: d,
            force,
            potential,
            exact,
        }
    }
}

/// Each named constant finite and > 0.
///
/// # Errors
/// [`SimError::OutOfRange`] naming the first that is not.
pub(crate) fn positive_constants(constants: &[(&'static str, f64)]) -> Result<(), SimError> {
    for &(name, v) in constants {
        if !(v.is_finite() && v > 0.0) {
            return Err(SimError::out_of_range(
                name,
                v,
                "must be a finite number > 0",
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// I₁(x), the modified Bessel function of the first kind, by its power series
    /// Σ (x/2)^{2m+1} / (m! (m+1)!) (Abramowitz & Stegun 9.6.10).
    fn bessel_i1(x: f64) -> f64 {
        let (mut term, mut sum) = (x / 2.0, 0.0);
        for m in 0..200 {
            sum += term;
            term *= (x / 2.0).powi(2) / ((m + 1) as f64 * (m + 2) as f64);
            if term.abs() < 1e-18 * sum.abs() {
                break;
            }
        }
        sum
    }

    /// Giessibl's relation by quadrature against its closed forms: a force linear in d shifts
    /// by −f0 F′/(2k) at any amplitude; an exponential force F0 e^{−d/λ} by
    /// (f0 F0 / (k A)) e^{−(d+A)/λ} I₁(A/λ) (Giessibl 1997, the exponential case).
    #[test]
    fn the_forward_relation_meets_its_closed_forms() {
        let (k, f0) = (40.0, 300e3);
        for a in [1e-10, 1e-9, 2e-8] {
            // (an offset of the force adds only round-off, amplified by f0/(k A))
            let linear = |d: f64| -1e-9 + 0.5 * d;
            let got = giessibl_shift(&linear, 5e-10, k, f0, a, 8);
            assert!(
                (got / (-f0 * 0.5 / (2.0 * k)) - 1.0).abs() < 1e-9,
                "A = {a}: {got}"
            );
            let (f_0, lambda) = (-2e-9, 3e-10);
            let exp = |d: f64| f_0 * (-d / lambda).exp();
            let d = 4e-10;
            let want = f0 * f_0 / (k * a) * (-(d + a) / lambda).exp() * bessel_i1(a / lambda);
            let got = giessibl_shift(&exp, d, k, f0, a, GIESSIBL_NODES);
            assert!((got / want - 1.0).abs() < 1e-10, "A = {a}: {got} vs {want}");
        }
    }

    /// Sader–Jarvis round trip: the van der Waals force −HR/(6d²) (H = 1e-19 J, R = 10 nm),
    /// shifted by Giessibl's relation at A = 0.1, 1 and 10 nm on 0.3–300 nm (the inversion's
    /// integral stops at the grid's end), is reconstructed on 0.3–5 nm within 0.5 % where
    /// A ≥ d (the large-amplitude limit, where the formula is exact) and within 4 % elsewhere
    /// (intermediate amplitudes, A/d ≈ 0.2–0.5, where Sader & Jarvis's formula itself is off
    /// by a few per cent: the error here is the same on a grid four times finer); the
    /// potential −HR/(6d) within 1 % where A ≥ 5d and 5 % elsewhere.
    #[test]
    fn the_inversion_recovers_a_van_der_waals_force() {
        let (k, f0, hr) = (40.0, 300e3, 1e-19 * 1e-8);
        let force = |d: f64| -hr / (6.0 * d * d);
        let n = 4000;
        let (lo, hi) = (3e-10f64, 3e-7f64);
        // log-spaced: fine near the sample where the force varies fastest
        let distance: Vec<f64> = (0..n)
            .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
            .collect();
        for a in [1e-10, 1e-9, 1e-8] {
            let frequency_shift = distance
                .iter()
                .map(|&d| giessibl_shift(&force, d, k, f0, a, GIESSIBL_NODES))
                .collect();
            let r = sader_jarvis(
                &ShiftCurve {
                    distance: distance.clone(),
                    frequency_shift,
                    spring_constant: k,
                    resonance_frequency: f0,
                    amplitude: a,
                },
                &Progress::new(),
            )
            .unwrap();
            for (i, &d) in distance.iter().enumerate().filter(|(_, &d)| d <= 5e-9) {
                let (want, u) = (force(d), -hr / (6.0 * d) + hr / (6.0 * hi));
                let (ef, eu) = (r.force[i] / want - 1.0, r.potential[i] / u - 1.0);
                let f_tol = if a >= d { 0.005 } else { 0.04 };
                let u_tol = if a >= 5.0 * d { 0.01 } else { 0.05 };
                assert!(ef.abs() < f_tol, "A = {a}, d = {d}: F off by {ef}");
                assert!(eu.abs() < u_tol, "A = {a}, d = {d}: U off by {eu}");
            }
        }
    }

    /// Bad curves are refused naming the field.
    #[test]
    fn bad_curves_name_the_field() {
        let good = ShiftCurve {
            distance: vec![1.0, 2.0, 3.0],
            frequency_shift: vec![-3.0, -2.0, -1.0],
            spring_constant: 1.0,
            resonance_frequency: 1.0,
            amplitude: 1.0,
        };
        assert!(sader_jarvis(&good, &Progress::new()).is_ok());
        for (bad, name) in [
            (
                ShiftCurve {
                    distance: vec![1.0, 3.0, 2.0],
                    ..good.clone()
                },
                "distance",
            ),
            (
                ShiftCurve {
                    frequency_shift: vec![1.0, 2.0],
                    ..good.clone()
                },
                "frequency_shift",
            ),
            (
                ShiftCurve {
                    amplitude: 0.0,
                    ..good.clone()
                },
                "amplitude",
            ),
            (
                ShiftCurve {
                    distance: vec![1.0, f64::NAN, 2.0],
                    ..good.clone()
                },
                "distance",
            ),
        ] {
            let e = sader_jarvis(&bad, &Progress::new())
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(name), "{e}");
        }
    }
}
