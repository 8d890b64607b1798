//! The body-contact check of the beam (the paper's Fig. 2f assumption: only the tip touches
//! the sample), and the weighted sum of modal displacements that bounds it.

use super::CantileverModel;
use nalgebra::{DMatrix, DVector};

/// Body-contact check (the paper's Fig. 2f assumption): true when some point ξ < 1 of the
/// beam reaches the substrate, V(ξ,τ) = W(ξ,τ) + α2 sin Ωτ + 1 ≤ 0.
#[derive(Debug, Clone)]
pub struct BodyContactCheck {
    phi: DMatrix<f64>,
    /// max_i |φ_j(ξ_i)| per mode j, shape `[N]`: |W(ξ_i)| ≤ Σ_j reach_j |a_j| at every station.
    pub(crate) reach: Vec<f64>,
    /// The base drive's amplitude (α2, or 0 for the point mass) and Ω.
    drive: (f64, f64),
}

impl BodyContactCheck {
    /// Sample the beam at `points` interior stations ξ_i = 0.99 i / points, i = 1..=points.
    pub(crate) fn new(model: &CantileverModel, points: usize) -> Self {
        let n = model.modes();
        let shapes = model.galerkin().shapes();
        // the point-mass and eigenmode models have no beam body
        let points = if model.params().structure.is_lumped() {
            0
        } else {
            points
        };
        let mut phi = DMatrix::zeros(points, n);
        for i in 0..points {
            let xi = 0.99 * (i + 1) as f64 / points as f64;
            for (j, v) in shapes.values(xi).into_iter().enumerate() {
                phi[(i, j)] = v;
            }
        }
        let reach = (0..n)
            .map(|j| phi.column(j).iter().fold(0.0f64, |m, v| m.max(v.abs())))
            .collect();
        let p = model.params();
        BodyContactCheck {
            phi,
            reach,
            drive: (p.base_amplitude(), p.omega),
        }
    }

    /// Whether any station touches the substrate at (τ, z).
    ///
    /// Every station's W(ξ_i) = Σ_j φ_j(ξ_i) a_j is bounded by Σ_j reach_j |a_j|; while that
    /// bound, widened by 1e-9 (far beyond the ≤ 2N ulp by which the computed sums can exceed
    /// it), stays below α2 sin Ωτ + 1, no station can touch and none is formed — the common
    /// case away from the sample. Otherwise the stations are formed one by one, each sum in
    /// the order of the matrix–vector product (mode 0 first), without allocating.
    /// `z: [f64; 2N]` as (a, ȧ), of the model the check was built for.
    pub(crate) fn touches(&self, tau: f64, z: &DVector<f64>) -> bool {
        self.touches_at(self.base(tau), &z.as_slice()[..self.reach.len()])
    }

    /// [`BodyContactCheck::touches`] given the base α2 sin Ωτ + 1 and the displacements a.
    pub(crate) fn touches_at(&self, base: f64, a: &[f64]) -> bool {
        if Self::spared(weighted_displacement(&self.reach, a), base) {
            return false;
        }
        (0..self.phi.nrows()).any(|i| {
            let w = a
                .iter()
                .enumerate()
                .skip(1)
                .fold(self.phi[(i, 0)] * a[0], |w, (j, x)| {
                    w + self.phi[(i, j)] * x
                });
            w + base <= 0.0
        })
    }

    /// α2 sin Ωτ + 1: a station touches when W(ξ_i, τ) + this ≤ 0.
    pub(crate) fn base(&self, tau: f64) -> f64 {
        let (amplitude, omega) = self.drive;
        amplitude * (omega * tau).sin() + 1.0
    }

    /// The lowest base over a period, 1 − |α2| (or 1 for the point mass).
    pub(crate) fn lowest_base(&self) -> f64 {
        1.0 - self.drive.0.abs()
    }

    /// The base drive's amplitude (α2, or 0 for the point mass) and Ω: the base is
    /// amplitude · sin Ωτ + 1.
    pub(crate) fn drive(&self) -> (f64, f64) {
        self.drive
    }

    /// Whether a bound of Σ_j reach_j |a_j|, widened by 1e-9 (see [`BodyContactCheck::touches`]),
    /// keeps every station off the substrate.
    pub(crate) fn spared(bound: f64, base: f64) -> bool {
        bound * (1.0 + 1e-9) < base
    }
}

/// Σ_j c_j |a_j| over `weights` c (≥ 0) and the leading entries of `a` (the modal
/// displacements of a state (a, ȧ)), in index order.
pub(crate) fn weighted_displacement(weights: &[f64], a: &[f64]) -> f64 {
    weights.iter().zip(a).map(|(c, x)| c * x.abs()).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::bifurcation::random_state;
    use crate::params::Params;

    /// The bound that spares forming the stations never changes the answer: on states scaled
    /// from far inside to far beyond the substrate (where the bound fails and stations touch),
    /// `touches` agrees with every station formed by the matrix–vector product, V(ξ_i) ≤ 0.
    #[test]
    fn body_contact_bound_never_changes_the_answer() {
        for modes in [1, 3, 10] {
            let model = CantileverModel::new(&Params {
                modes,
                ..Params::default()
            })
            .unwrap();
            let check = BodyContactCheck::new(&model, 32);
            let p = model.params();
            let (mut touched, mut spared) = (0, 0);
            for k in 0..400u64 {
                let scale = 0.05 * (k % 80) as f64;
                let z = random_state(&model, 7, k) * scale;
                let tau = 0.37 * k as f64;
                let base = p.base_amplitude() * (p.omega * tau).sin() + 1.0;
                let w = &check.phi * z.rows(0, modes);
                let reference = w.iter().any(|wi| wi + base <= 0.0);
                assert_eq!(check.touches(tau, &z), reference, "N = {modes}, k = {k}");
                touched += usize::from(reference);
                let bound = weighted_displacement(&check.reach, z.as_slice());
                spared += usize::from(BodyContactCheck::spared(bound, base));
            }
            // both outcomes and both paths are exercised
            assert!(
                touched > 0 && touched < 400,
                "N = {modes}: {touched} touching"
            );
            assert!(spared > 0 && spared < 400, "N = {modes}: {spared} spared");
        }
    }
}
