//! Eigen-analysis of the free and contact systems (paper eqs. 19–23) and the Fig. 3 maps.

use crate::error::ParamError;
use crate::galerkin::{Galerkin, Region, RegionMatrices};
use crate::params::Params;
use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

/// Undamped natural frequencies of one region: K x = ω² M x (homogeneous eq. 19 with C = 0).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct NaturalModes {
    /// ω_i ascending, shape `[N]` (dimensionless, eq. 5 time scale).
    pub omega: Vec<f64>,
    /// Mode vectors as columns (N×N), mass-normalised: xᵀ M x = 1.
    pub vectors: DMatrix<f64>,
}

/// Solve the generalised symmetric problem K x = ω² M x through the Cholesky factor of M
/// (M = L Lᵀ, symmetric eigenproblem of L⁻¹ K L⁻ᵀ). The defining identity K x = ω² M x is
/// what the tests assert.
pub(crate) fn natural_modes(m: &RegionMatrices) -> NaturalModes {
    let chol = m
        .mass
        .clone()
        .cholesky()
        .expect("mass matrix is positive definite");
    let l = chol.l();
    let linv = l
        .clone()
        .try_inverse()
        .expect("Cholesky factor is invertible");
    let mut s = &linv * &m.stiffness * linv.transpose();
    s = (&s + s.transpose()) * 0.5;
    let eig = s.symmetric_eigen();
    let mut order: Vec<usize> = (0..eig.eigenvalues.len()).collect();
    order.sort_by(|&a, &b| eig.eigenvalues[a].total_cmp(&eig.eigenvalues[b]));
    let n = order.len();
    let mut vectors = DMatrix::zeros(n, n);
    let mut omega = Vec::with_capacity(n);
    for (col, &k) in order.iter().enumerate() {
        omega.push(eig.eigenvalues[k].max(0.0).sqrt());
        let x = linv.transpose() * eig.eigenvectors.column(k);
        vectors.set_column(col, &x);
    }
    NaturalModes { omega, vectors }
}

/// The first free mode referred to the tip: ω̃₁ (undamped), its mass-normalised vector x₁
/// (x₁ᵀMx₁ = 1) and the first-mode stiffness at the tip k̃₁ = ω̃₁²/(φ(1)ᵀx₁)², the modal
/// stiffness of the mode with its amplitude measured at the tip (Butt & Jaschke,
/// *Nanotechnology* 6 (1995) 1; Melcher, Hu & Raman, *Appl. Phys. Lett.* 91 (2007) 053101), in
/// units of EI/L³ (the paper) or k (the point mass, where it is 1). β₁⁴/4 = 3.09 for the bare
/// beam against the static 3EI/L³. One place for the calibration of probes and the closed forms
/// of the observables.
pub(crate) fn first_mode_at_tip(
    m: &RegionMatrices,
    tip: &DVector<f64>,
) -> (f64, DVector<f64>, f64) {
    mode_at_tip(m, tip, 0)
}

/// The paper's beam damping α3 (C^I = α3·I, eq. 12; per mode α3 s_j with a damping profile
/// s) that gives the first mode the quality factor `q1`: the first mode's modal damping
/// x₁ᵀ C x₁ = α3 x₁ᵀ diag(s) x₁ equals 2ζ₁ω̃₁ = ω̃₁/Q₁ for the mass-normalised undamped mode
/// x₁ (x₁ᵀMx₁ = 1) of frequency ω̃₁ (modal damping of a lightly damped mode, Q = 1/(2ζ);
/// Meirovitch, *Fundamentals of Vibrations*, 2001, §7.15). The one place α3 is derived from Q;
/// `profile` is s (None: uniform).
pub(crate) fn beam_damping_for_q(
    omega1: f64,
    x1: &DVector<f64>,
    q1: f64,
    profile: Option<&[f64]>,
) -> f64 {
    let s_x1: f64 = x1
        .iter()
        .enumerate()
        .map(|(j, x)| x * x * profile.map_or(1.0, |s| s[j]))
        .sum();
    omega1 / (q1 * s_x1)
}

/// `first_mode_at_tip` for mode `k` (0-based, k < N): ω̃_k, the mass-normalised undamped
/// mode x_k and the stiffness k̃_k = ω̃_k²/(φᵀx_k)² of the equivalent point mass of that mode
/// at the tip (Melcher, Hu & Raman, *Appl. Phys. Lett.* 91 (2007) 053101).
///
/// # Panics
/// For k ≥ N.
pub(crate) fn mode_at_tip(
    m: &RegionMatrices,
    tip: &DVector<f64>,
    k: usize,
) -> (f64, DVector<f64>, f64) {
    let modes = natural_modes(m);
    let x: DVector<f64> = modes.vectors.column(k).into_owned();
    let w = modes.omega[k];
    let t = tip.dot(&x);
    (w, x, w * w / (t * t))
}

/// The first-order state matrix of eqs. 20–21: with Q = (Ẋ, X), M* Q̇ + K* Q = 0 where
/// M* = [[M, 0], [0, −K]] and K* = [[C, K], [K, 0]], so Q̇ = −M*⁻¹ K* Q. Shape 2N×2N.
pub(crate) fn state_matrix_eq21(m: &RegionMatrices) -> DMatrix<f64> {
    let n = m.mass.nrows();
    let mut mstar = DMatrix::zeros(2 * n, 2 * n);
    mstar.view_mut((0, 0), (n, n)).copy_from(&m.mass);
    mstar.view_mut((n, n), (n, n)).copy_from(&(-&m.stiffness));
    let mut kstar = DMatrix::zeros(2 * n, 2 * n);
    kstar.view_mut((0, 0), (n, n)).copy_from(&m.damping);
    kstar.view_mut((0, n), (n, n)).copy_from(&m.stiffness);
    kstar.view_mut((n, 0), (n, n)).copy_from(&m.stiffness);
    let lu = mstar.lu();
    -lu.solve(&kstar)
        .expect("M* is invertible (M and K positive definite)")
}

/// One damped eigenvalue λ = re + i·im of eqs. 20–21 with its damping ratio ζ = −re/|λ|.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DampedEigenvalue {
    /// Real part (decay rate, ≤ 0 for α's ≥ 0).
    pub re: f64,
    /// Imaginary part (damped natural frequency).
    pub im: f64,
    /// Damping ratio ζ = −re/|λ|.
    pub zeta: f64,
}

/// Damped state-space eigenvalues (eqs. 20–21) with Im ≥ 0, sorted by Im (then Re).
///
/// Each underdamped mode appears once (its Im > 0 member of the conjugate pair); an overdamped
/// mode contributes its two real eigenvalues (Im = 0), listed first.
pub(crate) fn damped_eigenvalues(m: &RegionMatrices) -> Vec<DampedEigenvalue> {
    let a = state_matrix_eq21(m);
    let scale = a.norm().max(1.0);
    let ev: DVector<Complex<f64>> = a.complex_eigenvalues();
    let mut out: Vec<DampedEigenvalue> = ev
        .iter()
        .filter(|l| l.im >= -1e-12 * scale)
        .map(|l| {
            let im = if l.im.abs() <= 1e-12 * scale {
                0.0
            } else {
                l.im
            };
            let modulus = (l.re * l.re + im * im).sqrt();
            DampedEigenvalue {
                re: l.re,
                im,
                zeta: if modulus > 0.0 { -l.re / modulus } else { 0.0 },
            }
        })
        .collect();
    out.sort_by(|a, b| a.im.total_cmp(&b.im).then(a.re.total_cmp(&b.re)));
    out
}

/// Each mode's quality factor Q_k = 1/(2ζ_k) in region `m`, shape `[N]`: for the natural
/// frequency ω̃_k ([`natural_modes`]) the underdamped damped eigenvalue λ (eqs. 20–21) whose
/// modulus is nearest it (|λ| = ω̃_k for modal damping); `None` for an overdamped mode (Q < 1/2:
/// no underdamped eigenvalue within ω̃_k/2 of it).
pub(crate) fn quality_factors(m: &RegionMatrices) -> Vec<Option<f64>> {
    let eig: Vec<DampedEigenvalue> = damped_eigenvalues(m)
        .into_iter()
        .filter(|e| e.im > 0.0)
        .collect();
    let modulus = |e: &DampedEigenvalue| e.re.hypot(e.im);
    natural_modes(m)
        .omega
        .iter()
        .map(|&w| {
            let e = eig
                .iter()
                .min_by(|a, b| (modulus(a) - w).abs().total_cmp(&(modulus(b) - w).abs()))?;
            ((modulus(e) - w).abs() <= 0.5 * w && e.zeta > 0.0).then(|| 0.5 / e.zeta)
        })
        .collect()
}

/// Natural frequencies and damped eigenvalues of one region.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionSpectrum {
    /// Undamped natural frequencies, ascending.
    pub omega: Vec<f64>,
    /// Damped eigenvalues, Im ≥ 0, sorted by Im.
    pub eigenvalues: Vec<DampedEigenvalue>,
}

/// Spectrum of both regions of `params`.
///
/// # Errors
/// [`ParamError`] if `params` is invalid.
pub(crate) fn spectrum(params: &Params) -> Result<(RegionSpectrum, RegionSpectrum), ParamError> {
    let g = Galerkin::new(params)?;
    let one = |r| {
        let m = g.region(r);
        RegionSpectrum {
            omega: natural_modes(m).omega,
            eigenvalues: damped_eigenvalues(m),
        }
    };
    Ok((one(Region::Free), one(Region::Contact)))
}

/// One point of the Fig. 3 maps: contact-system natural frequencies (α3 = α6 = 0) relative to the
/// uniform cantilever's ω_{0i} = β_i² (eqs. 22–23).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Fig3Point {
    /// Tip-mass ratio α1.
    pub alpha1: f64,
    /// Contact stiffness α4.
    pub alpha4: f64,
    /// ω₁ / ω₀₁.
    pub ratio1: f64,
    /// ω₂ / ω₀₂ (NaN for N = 1).
    pub ratio2: f64,
}

/// The Fig. 3 sweep: ω₁/ω₀₁ and ω₂/ω₀₂ of the contact system over an α1 × α4 grid
/// (row-major: α1 outer, α4 inner), with `modes` Galerkin modes.
///
/// # Errors
/// [`ParamError`] if a grid value is invalid (negative α's, N out of range).
pub(crate) fn fig3_sweep(
    modes: usize,
    alpha1: &[f64],
    alpha4: &[f64],
) -> Result<Vec<Fig3Point>, ParamError> {
    let b1 = crate::beam::beta_root(1).powi(2);
    let b2 = crate::beam::beta_root(2).powi(2);
    let mut out = Vec::with_capacity(alpha1.len() * alpha4.len());
    for &a1 in alpha1 {
        for &a4 in alpha4 {
            let p = Params {
                modes,
                alpha1: a1,
                alpha3: 0.0,
                alpha4: a4,
                alpha6: 0.0,
                ..Params::default()
            };
            let g = Galerkin::new(&p)?;
            let w = natural_modes(g.region(Region::Contact)).omega;
            out.push(Fig3Point {
                alpha1: a1,
                alpha4: a4,
                ratio1: w[0] / b1,
                ratio2: w.get(1).map_or(f64::NAN, |w2| w2 / b2),
            });
        }
    }
    Ok(out)
}
