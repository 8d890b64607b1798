//! The free lever's thermal motion: its power spectral density and each mode's share, from the
//! fluctuation–dissipation theorem applied to the model's dynamic compliance.
//!
//! # The spectrum
//! The free region obeys M Ẍ + C Ẋ + K X = F (eq. 10, every Galerkin mode, the tip mass in M,
//! the medium's added mass and damping per mode where the probe has one). An observable
//! y = cᵀX (the tip's deflection: c = φ(1); the optical lever's apparent deflection: c the
//! slopes φ'(ξ_s) at the laser spot times the static factor below) has the compliance
//! h(ω) = cᵀ(K − ω²M + iωC)⁻¹c to its conjugate force, and its one-sided thermal power
//! spectral density is S_y(f) = (4 k_B T/ω) |Im h(ω)|, ω = 2πf (the fluctuation–dissipation
//! theorem: Callen & Welton, *Phys. Rev.* 83 (1951) 34; for the lever, Butt & Jaschke,
//! *Nanotechnology* 6 (1995) 1, and Hutter & Bechhoefer, *Rev. Sci. Instrum.* 64 (1993)
//! 1868). It is evaluated by an LU factorisation of the N × N complex matrix at each
//! frequency.
//!
//! # Each mode's share
//! In thermal equilibrium the potential energy ½XᵀKX is Boltzmann-distributed whatever the
//! damping, so ⟨XXᵀ⟩ = k_B T K⁻¹: in the undamped modes x_k (K x = ω² M x, xᵀMx = 1) the
//! modal coordinates are independent with ⟨η_k²⟩ = k_B T/ω_k², and the tip's
//! ⟨x_tip,k²⟩ = k_B T/k_k, k_k = ω_k²/(φ(1)ᵀx_k)² the mode's effective spring constant at the
//! tip; summed over the modes, ⟨x_tip²⟩ = k_B T φ(1)ᵀK⁻¹φ(1), the model's static compliance
//! (equipartition), which is the beam's 1/k_s = L³/(3EI) but for the modes beyond N
//! (Σ_{k>N} 12/β_k⁴ of it without a tip mass). The optical lever's apparent deflection reads the slope at the
//! spot ξ_s converted with the static end-loaded shape W(ξ) = W(1)(3ξ² − ξ³)/2, so
//! z* = W'(ξ_s) · 2/(3ξ_s(2 − ξ_s)) (2L/3 × the slope at the tip, Butt & Jaschke 1995). A
//! mode's correction factor is what the thermal method multiplies k_B T/⟨z_k²⟩ by to give
//! k_s: χ_k = k_s⟨z_k²⟩/(k_B T), for the deflection 12/β_k⁴ (0.971 for the first mode of a
//! uniform beam) and for the optical lever 0.817 for the first (Butt & Jaschke 1995; Proksch
//! et al., *Nanotechnology* 15 (2004) 1344), here from the model: the tip mass and the spot
//! move them. The point-mass and eigenmode models have no slope: their optical lever reads the
//! deflection.
//!
//! Units: the model's (`length` m per unit W, `force` N per unit force, `time` s per unit τ,
//! from the probe's scales); the results in SI.

use crate::analysis::progress::Progress;
use crate::beam::ModeShapes;
use crate::eigen::{natural_modes, quality_factors};
use crate::error::SimError;
use crate::galerkin::{Galerkin, Region};
use crate::params::{Params, Structure};
use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;
use std::f64::consts::TAU;

/// The frequencies between two looks at the cancellation flag.
const CHECK_EVERY: usize = 4096;

/// Boltzmann's constant k_B (J/K, exact in the SI since 2019).
pub const BOLTZMANN: f64 = 1.380_649e-23;

/// The model's units in SI: metres, newtons and seconds per unit length, force and τ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelUnits {
    /// Metres per unit W.
    pub length_m: f64,
    /// Newtons per unit force.
    pub force_n: f64,
    /// Seconds per unit τ.
    pub time_s: f64,
}

/// One mode's thermal share (SI).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ThermalMode {
    /// The mode's number, from 1.
    pub mode: usize,
    /// Its undamped natural frequency f_k (Hz).
    pub frequency: f64,
    /// Its quality factor Q_k (`None`: overdamped).
    pub quality_factor: Option<f64>,
    /// Its effective spring constant at the tip k_k = ω_k²/(φ(1)ᵀx_k)² (N/m).
    pub effective_spring_constant: f64,
    /// ⟨x_tip,k²⟩ = k_B T/k_k (m²).
    pub mean_square_deflection: f64,
    /// ⟨z*_k²⟩, the optical lever's apparent deflection (m²).
    pub mean_square_apparent_deflection: f64,
    /// χ_k = k_s⟨x_k²⟩/(k_B T): the thermal method's factor for the deflection.
    pub deflection_factor: f64,
    /// χ*_k = k_s⟨z*_k²⟩/(k_B T): the thermal method's factor for the optical lever.
    pub optical_lever_factor: f64,
}

/// The free lever's thermal spectrum (SI).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ThermalSpectrum {
    /// The temperature T (K).
    pub temperature: f64,
    /// The static stiffness at the tip k_s (N/m).
    pub spring_constant: f64,
    /// The laser spot ξ_s (a fraction of the length from the base).
    pub spot: f64,
    /// Whether the optical lever reads the beam's slope (`false`: a model without one, which
    /// reads the deflection).
    pub reads_slope: bool,
    /// Each mode's share, shape `[N]`.
    pub modes: Vec<ThermalMode>,
    /// ⟨x_tip²⟩ over the model's modes (m²): k_B T/k_s but for the modes beyond N (the
    /// PSD's integral).
    pub mean_square_deflection: f64,
    /// The frequencies (Hz), shape `[F]`.
    pub frequency: Vec<f64>,
    /// S_x(f), the tip's deflection (m²/Hz), shape `[F]`.
    pub deflection: Vec<f64>,
    /// S_z*(f), the optical lever's apparent deflection (m²/Hz), shape `[F]`.
    pub apparent_deflection: Vec<f64>,
}

/// The observables' vectors: the tip's deflection φ(1) and the optical lever's apparent
/// deflection (module docs), shape `[N]` each; and whether the latter reads a slope.
fn observables(params: &Params, g: &Galerkin, spot: f64) -> (DVector<f64>, DVector<f64>, bool) {
    let tip = g.tip().clone();
    if params.structure != Structure::Beam {
        return (tip.clone(), tip, false);
    }
    let shapes: &ModeShapes = g.shapes();
    let factor = 2.0 / (3.0 * spot * (2.0 - spot));
    let slope = DVector::from_iterator(
        tip.len(),
        (shapes.modes().iter()).map(|m| factor * m.derivative(1, spot)),
    );
    (tip, slope, true)
}

/// The thermal spectrum of `params`' free lever at `temperature` (K) read at the laser `spot`
/// (a fraction of the length, (0, 1]) at the `frequencies` (Hz, > 0), in `units`, counting
/// the frequencies in `progress`.
///
/// # Errors
/// The model's parameter errors; [`SimError::NotFinite`] naming `spring_constant` for a
/// model without a static stiffness; [`SimError::Cancelled`].
pub fn thermal_spectrum(
    params: &Params,
    units: ModelUnits,
    temperature: f64,
    spot: f64,
    frequencies: &[f64],
    progress: &Progress,
) -> Result<ThermalSpectrum, SimError> {
    let g = Galerkin::new(params)?;
    let m = g.region(Region::Free);
    let (tip, apparent, reads_slope) = observables(params, &g, spot);
    let kt = BOLTZMANN * temperature;
    // SI compliance per unit of the model's: metres per newton
    let compliance = units.length_m / units.force_n;
    // the beam's static stiffness is 3EI/L³, 3 in the model's units (K = diag β⁴ in EI/L³;
    // its N modes hold all but Σ_{k>N} 12/β_k⁴ of the compliance); the point mass's and the
    // eigenmodes' that of their coordinates, K's own
    let spring_constant = match params.structure {
        Structure::Beam => 3.0 / compliance,
        _ => match m.stiffness.clone().lu().solve(&tip) {
            Some(u) => 1.0 / (tip.dot(&u) * compliance),
            None => f64::NAN,
        },
    };
    if !(spring_constant.is_finite() && spring_constant > 0.0) {
        return Err(SimError::NotFinite {
            name: "spring_constant",
            value: spring_constant,
        });
    }
    let natural = natural_modes(m);
    let q = quality_factors(m);
    let modes = (natural.omega.iter().enumerate())
        .map(|(k, &w)| {
            let x = natural.vectors.column(k);
            let (at_tip, read) = (tip.dot(&x), apparent.dot(&x));
            let mean_square = |c: f64| kt * c * c / (w * w) * compliance;
            let msd = mean_square(at_tip);
            let msa = mean_square(read);
            ThermalMode {
                mode: k + 1,
                frequency: w / (TAU * units.time_s),
                quality_factor: q[k],
                effective_spring_constant: kt / msd,
                mean_square_deflection: msd,
                mean_square_apparent_deflection: msa,
                deflection_factor: spring_constant * msd / kt,
                optical_lever_factor: spring_constant * msa / kt,
            }
        })
        .collect::<Vec<ThermalMode>>();
    let mean_square_deflection = modes.iter().map(|m| m.mean_square_deflection).sum();
    let mut deflection = Vec::with_capacity(frequencies.len());
    let mut apparent_psd = Vec::with_capacity(frequencies.len());
    let mut lu = ComplexLu::new(tip.len());
    for chunk in frequencies.chunks(CHECK_EVERY) {
        progress.check()?;
        for &f in chunk {
            let omega = TAU * f * units.time_s;
            lu.factor(&m.mass, &m.damping, &m.stiffness, omega);
            // S = (4 k_B T/ω_SI) |Im h| (m/N)
            let scale = 4.0 * kt / (TAU * f) * compliance;
            deflection.push(scale * lu.compliance(&tip).im.abs());
            apparent_psd.push(scale * lu.compliance(&apparent).im.abs());
        }
        progress.advance(chunk.len());
    }
    Ok(ThermalSpectrum {
        temperature,
        spring_constant,
        spot,
        reads_slope,
        modes,
        mean_square_deflection,
        frequency: frequencies.to_vec(),
        deflection,
        apparent_deflection: apparent_psd,
    })
}

/// The LU factors (partial pivoting) of Z = K − Ω²M + iΩC, N × N, kept between frequencies
/// so that a spectrum of 10⁵ frequencies allocates once.
struct ComplexLu {
    n: usize,
    /// Z, then its factors, row-major.
    a: Vec<Complex<f64>>,
    /// The row exchanged at each step.
    pivot: Vec<usize>,
    /// A right-hand side, then the solution.
    y: Vec<Complex<f64>>,
}

impl ComplexLu {
    fn new(n: usize) -> ComplexLu {
        ComplexLu {
            n,
            a: vec![Complex::new(0.0, 0.0); n * n],
            pivot: vec![0; n],
            y: vec![Complex::new(0.0, 0.0); n],
        }
    }

    /// Factor Z at the model's angular frequency `omega`.
    fn factor(&mut self, m: &DMatrix<f64>, c: &DMatrix<f64>, k: &DMatrix<f64>, omega: f64) {
        let n = self.n;
        for i in 0..n {
            for j in 0..n {
                let re = k[(i, j)] - omega * omega * m[(i, j)];
                self.a[i * n + j] = Complex::new(re, omega * c[(i, j)]);
            }
        }
        for col in 0..n {
            let p = (col..n)
                .max_by(|&r, &s| {
                    self.a[r * n + col]
                        .norm_sqr()
                        .total_cmp(&self.a[s * n + col].norm_sqr())
                })
                .unwrap_or(col);
            self.pivot[col] = p;
            if p != col {
                for j in 0..n {
                    self.a.swap(p * n + j, col * n + j);
                }
            }
            let d = self.a[col * n + col];
            for r in col + 1..n {
                let l = self.a[r * n + col] / d;
                self.a[r * n + col] = l;
                for j in col + 1..n {
                    let u = self.a[col * n + j];
                    self.a[r * n + j] -= l * u;
                }
            }
        }
    }

    /// cᵀZ⁻¹c of the factored Z.
    fn compliance(&mut self, c: &DVector<f64>) -> Complex<f64> {
        let n = self.n;
        for i in 0..n {
            self.y[i] = Complex::new(c[i], 0.0);
        }
        // the rows were exchanged whole (the multipliers with them): P first, then L
        for col in 0..n {
            self.y.swap(col, self.pivot[col]);
        }
        for col in 0..n {
            for r in col + 1..n {
                let l = self.a[r * n + col];
                let v = self.y[col];
                self.y[r] -= l * v;
            }
        }
        for i in (0..n).rev() {
            let mut s = self.y[i];
            for j in i + 1..n {
                s -= self.a[i * n + j] * self.y[j];
            }
            self.y[i] = s / self.a[i * n + i];
        }
        (0..n).map(|i| self.y[i] * c[i]).sum()
    }
}

/// The fraction of a mode's thermal motion below r = f/f_k: its oscillator's PSD
/// ∝ 1/((1 − r²)² + r²/Q²) integrated from 0 to `r` over its integral to ∞, πQ/2 (an
/// overdamped mode, `q` `None`, as Q = 1/2). In closed form: the denominator is
/// (r² + pr + 1)(r² − pr + 1), p² = 4 − 1/Q², whose partial fractions integrate to
/// I(r) = ln((r² + pr + 1)/(r² − pr + 1))/(4p) + (Q/2) atan2(r, Q(1 − r²)) (the two arctangents
/// of the quadratics summed into one); for p² < 0 (Q < 1/2) the logarithm's term is
/// atan(|p|r/(r² + 1))/(2|p|), at p = 0 its limit r/(2(1 + r²)).
pub fn band_fraction(q: Option<f64>, r: f64) -> f64 {
    let q = q.unwrap_or(0.5);
    let p2 = 4.0 - 1.0 / (q * q);
    let log_term = if p2 > 1e-8 {
        let p = p2.sqrt();
        (2.0 * p * r / (r * r - p * r + 1.0)).ln_1p() / (4.0 * p)
    } else if p2 < -1e-8 {
        let t = (-p2).sqrt();
        (t * r).atan2(r * r + 1.0) / (2.0 * t)
    } else {
        r / (2.0 * (1.0 + r * r))
    };
    let integral = log_term + 0.5 * q * r.atan2(q * (1.0 - r * r));
    (integral / (std::f64::consts::FRAC_PI_2 * q)).clamp(0.0, 1.0)
}

/// The optical lever's apparent mean-square deflection (m²) of the `modes` below `bandwidth`
/// (Hz): each mode's ⟨z*_k²⟩ times its [`band_fraction`] (each mode taken as its oscillator).
pub fn apparent_mean_square_in_band(modes: &[ThermalMode], bandwidth: f64) -> f64 {
    (modes.iter())
        .map(|m| {
            m.mean_square_apparent_deflection
                * band_fraction(m.quality_factor, bandwidth / m.frequency)
        })
        .sum()
}

#[cfg(test)]
mod tests;
