//! The rates of the energy balance of an affine (linear-law) region as quadratic forms in the
//! state, for integrals in closed form over exact steps (`integrate/exact/energy.rs`).
//!
//! With V_T = φᵀa + b sin Ωτ + α5 (eq. 8, b the base amplitude α2, 0 for the point mass),
//! V̇_T = φᵀȧ + bΩ cos Ωτ and, in contact, F_c = α4 δ + α6 δ̇ = −α4 V_T − α6 V̇_T (eqs. 16–18),
//! the three rates of [`CantileverModel::power`] are
//!
//! * base power ȧᵀ(F_s sin Ωτ + F_c cos Ωτ) − bΩ cos Ωτ · F_c: linear in z;
//! * beam dissipation α3 ȧᵀȧ: quadratic;
//! * sample dissipation α6 V̇_T² in contact: quadratic.
//!
//! Each is zᵀQz + (l₀ + l_s sin Ωτ + l_c cos Ωτ)ᵀz + k(τ) with Q constant and k a polynomial of
//! degree 2 in (sin Ωτ, cos Ωτ) ([`RateForm`]); `tests` check them against `power` pointwise.

use super::CantileverModel;
use crate::system::Region;
use nalgebra::{DMatrix, DVector};

/// One rate of the energy balance as zᵀQz + (l₀ + l_s s + l_c c)ᵀz + k₀ + k_s s + k_c c +
/// k_ss s² + k_sc s c + k_cc c², with (s, c) = (sin Ωτ, cos Ωτ) and z = (a, ȧ) of length 2N.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RateForm {
    /// Q, 2N×2N, symmetric.
    pub q: DMatrix<f64>,
    /// l₀, l_s, l_c, each shape `[2N]`.
    pub l: [DVector<f64>; 3],
    /// k₀, k_s, k_c, k_ss, k_sc, k_cc.
    pub k: [f64; 6],
}

impl RateForm {
    fn zero(dim: usize) -> Self {
        let v = DVector::zeros(dim);
        RateForm {
            q: DMatrix::zeros(dim, dim),
            l: [v.clone(), v.clone(), v],
            k: [0.0; 6],
        }
    }

    /// The linear coefficient l(τ) = l₀ + l_s s + l_c c into `out` (shape `[2N]`).
    pub(crate) fn linear_at(&self, (s, c): (f64, f64), out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate() {
            *o = self.l[0][i] + s * self.l[1][i] + c * self.l[2][i];
        }
    }

    /// The state-independent part k(τ).
    pub(crate) fn constant_at(&self, (s, c): (f64, f64)) -> f64 {
        let k = &self.k;
        k[0] + k[1] * s + k[2] * c + k[3] * s * s + k[4] * s * c + k[5] * c * c
    }

    /// The rate at (sin Ωτ, cos Ωτ) = `sc` and z.
    #[cfg(test)]
    fn eval(&self, sc: (f64, f64), z: &[f64]) -> f64 {
        let zv = DVector::from_column_slice(z);
        let mut l = vec![0.0; z.len()];
        self.linear_at(sc, &mut l);
        (&self.q * &zv).dot(&zv)
            + l.iter().zip(z).map(|(a, b)| a * b).sum::<f64>()
            + self.constant_at(sc)
    }
}

impl CantileverModel {
    /// The rates [base power, beam dissipation, sample dissipation] of region `r` as quadratic
    /// forms (module docs), or `None` for a law that is not affine (only the linear law is).
    pub(crate) fn rate_forms(&self, r: Region) -> Option<[RateForm; 3]> {
        // the forms hold one harmonic drive (a multifrequency drive's power is not in them)
        if !self.law().is_affine() || self.params().is_multifrequency() {
            return None;
        }
        let p = self.params();
        let n = self.modes();
        let dim = 2 * n;
        let (b, om) = (p.base_amplitude(), p.omega);
        let tip = self.tip();
        let forcing = &self.galerkin().region(Region::Free).forcing;
        let mut base = RateForm::zero(dim);
        base.l[1].rows_mut(n, n).copy_from(&forcing.sin);
        base.l[2].rows_mut(n, n).copy_from(&forcing.cos);
        let mut beam = RateForm::zero(dim);
        beam.q
            .view_mut((n, n), (n, n))
            .copy_from(&self.galerkin().region(Region::Free).damping);
        let mut sample = RateForm::zero(dim);
        if r == Region::Contact {
            let (a4, a6) = (p.alpha4, p.alpha6);
            // −bΩc F_c = bΩc [α4 (φᵀa + b s + α5) + α6 (φᵀȧ + bΩc)]
            for j in 0..n {
                base.l[2][j] += b * om * a4 * tip[j];
                base.l[2][n + j] += b * om * a6 * tip[j];
            }
            base.k[2] += b * om * a4 * p.alpha5;
            base.k[4] += b * om * a4 * b;
            base.k[5] += b * om * a6 * b * om;
            // α6 V̇_T² = α6 (φᵀȧ + bΩc)²
            sample.q.view_mut((n, n), (n, n)).ger(a6, tip, tip, 0.0);
            for j in 0..n {
                sample.l[2][n + j] = 2.0 * a6 * b * om * tip[j];
            }
            sample.k[5] = a6 * b * b * om * om;
        }
        Some([base, beam, sample])
    }
}

#[cfg(test)]
mod tests {
    use crate::analysis::bifurcation::random_state;
    use crate::{CantileverModel, Params, Region, Structure};

    /// The quadratic forms equal [`CantileverModel::power`] at random states and times, in both
    /// regions, for the beam (with and without a per-mode damping profile) and the point mass
    /// (whose base does not move), to round-off.
    #[test]
    fn rate_forms_equal_the_power_terms() {
        for (structure, profile) in [
            (Structure::Beam, false),
            (Structure::Beam, true),
            (Structure::PointMass, false),
        ] {
            let mut s = [1.0; 20];
            s[1] = 0.3;
            s[2] = 2.5;
            let p = Params {
                damping_profile: profile.then_some(s),
                modes: if structure == Structure::Beam { 3 } else { 1 },
                alpha1: if structure == Structure::Beam {
                    0.1
                } else {
                    0.0
                },
                structure,
                alpha5: 0.3,
                ..Params::default()
            };
            let m = CantileverModel::new(&p).unwrap();
            for seed in 0..20u64 {
                let z = random_state(&m, seed, 1) * 2.0;
                let tau = 0.37 * seed as f64;
                let sc = (p.omega * tau).sin_cos();
                for r in [Region::Free, Region::Contact] {
                    let f = m.rate_forms(r).unwrap();
                    let pw = m.power(r, tau, &z);
                    for (form, want) in
                        f.iter()
                            .zip([pw.base, pw.beam_dissipation, pw.contact_dissipation])
                    {
                        let got = form.eval(sc, z.as_slice());
                        assert!(
                            (got - want).abs() <= 1e-13 * (1.0 + want.abs()),
                            "{structure:?} {r:?}: {got} vs {want}"
                        );
                    }
                }
            }
        }
    }
}
