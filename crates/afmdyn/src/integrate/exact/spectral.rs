//! The parts of a propagator build that depend only on the region matrices, and their reuse.
//!
//! The energy transforms, Ã_s, ‖Ã_s‖₂, the eigendecomposition, the tip moment rows and the LU
//! factorization of A_s depend on A_s, M and K_s only — not on Ω, α2 or α5 — and the grid
//! exponential Φ_s = e^{A_s h} on those and h. Both are kept in the caller's
//! [`PropagatorCache`] (when it gives one) keyed by the exact bits of the matrices (and of h),
//! so the repeated builds of shooting at one parameter set reuse everything and a continuation
//! step in Ω reuses the spectral data and redoes only Φ_s and the particular solution. A hit
//! returns the very values a rebuild would compute (the build is deterministic); the cache
//! states its keys and bounds ([`super::cache`]).

use super::modal::ModalExp;
use super::K;
use crate::error::SimError;
use crate::linalg::{matmul, matmul_into};
use crate::model::CantileverModel;
use crate::system::Region;
use nalgebra::linalg::LU;
use nalgebra::{DMatrix, DVector, Dyn};

/// Build-time data of one region that depends on A_s, M and K_s only.
#[derive(Debug, Clone)]
pub(super) struct Spectral {
    /// Energy transform T_s (2N×2N, block diagonal) and its inverse.
    pub(super) t: DMatrix<f64>,
    pub(super) tinv: DMatrix<f64>,
    /// Ã_s = T A T⁻¹.
    pub(super) at: DMatrix<f64>,
    /// ‖Ã_s‖₂.
    pub(super) rho: f64,
    /// e^{Ã t} by eigendecomposition, when well conditioned.
    pub(super) modal: Option<ModalExp>,
    /// Rows c̃ᵀ Ãⁿ, n = 0..=K+2, (K+3)×2N: tip-deflection moments of the homogeneous part.
    pub(super) rows: DMatrix<f64>,
    /// ‖c̃ᵀÃ²‖₂.
    pub(super) kappa2: f64,
    /// ‖c̃‖₂.
    pub(super) ct_norm: f64,
    /// LU factorization of A_s (for the constant part of the particular solution).
    pub(super) a_lu: LU<f64, Dyn, Dyn>,
}

/// Φ_s of the free and the contact region.
pub(super) type GridExp = [DMatrix<f64>; 2];

/// The exact bits of A_s, M and K_s of both regions: the key of the spectral data.
pub(super) fn matrix_key(model: &CantileverModel) -> Vec<u64> {
    let mut key = vec![model.dim() as u64];
    for r in [Region::Free, Region::Contact] {
        let g = model.galerkin().region(r);
        for m in [&model.dynamics(r).a, &g.mass, &g.stiffness] {
            key.extend(m.iter().map(|x| x.to_bits()));
        }
    }
    key
}

/// The spectral data of both regions (what a [`super::PropagatorCache`] keeps under
/// [`matrix_key`]).
///
/// # Errors
/// [`SimError::OutOfRange`] when M or K_s is not positive definite.
pub(super) fn spectral(model: &CantileverModel) -> Result<[Spectral; 2], SimError> {
    Ok([
        region_spectral(model, Region::Free)?,
        region_spectral(model, Region::Contact)?,
    ])
}

/// e^{X}, X = Ã h with ‖Ã‖₂ = ρ, by scaling and squaring with a truncated Taylor series
/// (Moler & Van Loan, "Nineteen dubious ways to compute the exponential of a matrix, twenty-five
/// years later", SIAM Rev. 45 (2003) 3, §3 and method 3): X/2^s with ‖X‖/2^s ≤ 1/2, the Taylor
/// polynomial of degree 14 (truncation ≤ 0.5¹⁵/15! ≈ 2e-17 relative) by the Paterson–Stockmeyer
/// scheme in blocks of 4 (Higham, *Functions of Matrices*, SIAM 2008, §4.2: X², X³, X⁴ and three
/// Horner steps in X⁴), then s squarings. In energy coordinates ‖e^{Ãt}‖₂ ≤ 1 for t ≥ 0, so the
/// squarings do not amplify the rounding errors. 6 + s products.
pub(super) fn expm(at: &DMatrix<f64>, h: f64, rho: f64) -> DMatrix<f64> {
    const DEGREE: usize = 14;
    let dim = at.nrows();
    let norm = rho * h.abs();
    let s = if norm > 0.5 {
        (norm / 0.5).log2().ceil().min(1000.0) as i32
    } else {
        0
    };
    let x = at * (h / 2f64.powi(s));
    let x2 = matmul(&x, &x);
    let powers = [
        DMatrix::<f64>::identity(dim, dim),
        x.clone(),
        x2.clone(),
        matmul(&x2, &x),
    ];
    let x4 = matmul(&x2, &x2);
    // B_j = Σ_{i<4} X^i / (4j + i)!, P = ((B_3 X⁴ + B_2) X⁴ + B_1) X⁴ + B_0
    let block = |j: usize, out: &mut DMatrix<f64>| {
        for (i, xi) in powers.iter().enumerate() {
            if 4 * j + i <= DEGREE {
                let c = super::INV_FACT[4 * j + i];
                for (o, v) in out.as_mut_slice().iter_mut().zip(xi.as_slice()) {
                    *o += c * v;
                }
            }
        }
    };
    let mut p = DMatrix::<f64>::zeros(dim, dim);
    block(3, &mut p);
    let mut tmp = DMatrix::<f64>::zeros(dim, dim);
    for j in (0..3).rev() {
        matmul_into(&p, &x4, 1.0, &mut tmp);
        block(j, &mut tmp);
        std::mem::swap(&mut p, &mut tmp);
    }
    for _ in 0..s {
        matmul_into(&p, &p, 1.0, &mut tmp);
        std::mem::swap(&mut p, &mut tmp);
    }
    p
}

/// Φ_s = T⁻¹ e^{Ã_s h} T of both regions ([`expm`]; what a [`super::PropagatorCache`] keeps
/// under [`matrix_key`] and the bits of h).
pub(super) fn grid_exp(spec: &[Spectral; 2], h: f64) -> GridExp {
    std::array::from_fn(|i| {
        let s = &spec[i];
        matmul(&matmul(&s.tinv, &expm(&s.at, h, s.rho)), &s.t)
    })
}

fn energy_transform(
    model: &CantileverModel,
    r: Region,
) -> Result<(DMatrix<f64>, DMatrix<f64>), SimError> {
    let n = model.modes();
    let g = model.galerkin().region(r);
    let singular = |what: &'static str| {
        SimError::out_of_range(what, "not positive definite", "needs validated parameters")
    };
    // the Cholesky factor L of an SPD matrix (K = L_K L_Kᵀ, M = L_M L_Mᵀ)
    let factor = |m: &DMatrix<f64>, what| -> Result<DMatrix<f64>, SimError> {
        Ok(m.clone().cholesky().ok_or_else(|| singular(what))?.l())
    };
    let lk = factor(&g.stiffness, "stiffness matrix K")?;
    let lm = factor(&g.mass, "mass matrix M")?;
    let mut t = DMatrix::zeros(2 * n, 2 * n);
    t.view_mut((0, 0), (n, n)).copy_from(&lk.transpose());
    t.view_mut((n, n), (n, n)).copy_from(&lm.transpose());
    let tinv = t
        .clone()
        .try_inverse()
        .ok_or_else(|| singular("energy transform T"))?;
    Ok((t, tinv))
}

/// Spectral norm (largest singular value).
fn norm2(a: &DMatrix<f64>) -> f64 {
    a.clone().svd(false, false).singular_values.max()
}

fn region_spectral(model: &CantileverModel, r: Region) -> Result<Spectral, SimError> {
    let n = model.modes();
    let dim = 2 * n;
    let (t, tinv) = energy_transform(model, r)?;
    let at = &t * &model.dynamics(r).a * &tinv;
    // c̃ = T⁻ᵀ c with c = (φ(1), 0); rows c̃ᵀ Ãⁿ
    let mut c = DVector::zeros(dim);
    c.rows_mut(0, n).copy_from(model.tip());
    let ct = tinv.transpose() * c;
    let mut row = ct.clone();
    let mut rows = DMatrix::zeros(K + 3, dim);
    for k in 0..K + 3 {
        rows.set_row(k, &row.transpose());
        row = at.transpose() * row;
    }
    let kappa2 = rows.row(2).norm();
    let ct_norm = ct.norm();
    let modal = ModalExp::new(&at, ct.as_slice(), &tinv);
    Ok(Spectral {
        rho: norm2(&at),
        t,
        tinv,
        at,
        modal,
        rows,
        kappa2,
        ct_norm,
        a_lu: model.dynamics(r).a.clone().lu(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Taylor scaling-and-squaring exponential agrees with nalgebra's Padé one (an
    /// independent method) to 1e-14 for Ã of both regions at the grid step and at steps 1/7 and
    /// 3× as long, N = 1, 3, 10.
    #[test]
    fn taylor_exponential_matches_pade() {
        for modes in [1usize, 3, 10] {
            let p = crate::params::Params {
                modes,
                ..crate::params::Params::default()
            };
            let m = CantileverModel::new(&p).unwrap();
            for r in [Region::Free, Region::Contact] {
                let s = region_spectral(&m, r).unwrap();
                let h = super::super::THETA / s.rho;
                for t in [h, h / 7.0, 3.0 * h] {
                    let want = (&s.at * t).exp();
                    let got = expm(&s.at, t, s.rho);
                    let err = (&got - &want).amax() / want.amax();
                    assert!(err < 1e-14, "N = {modes}, {r:?}, t = {t}: {err:e}");
                }
            }
        }
    }
}
