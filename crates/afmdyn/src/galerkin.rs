//! Galerkin matrices and modal forcing of the free (I) and contact (II) regions,
//! paper eqs. 10–18.
//!
//! With W(ξ,τ) = Σ a_j φ_j(ξ) (eq. 9) and X = (a_1 … a_N)ᵀ, each region obeys
//! M Ẍ + C_s Ẋ + K_s X = F_s(τ) (eq. 10). All matrices are N×N, symmetric; M is positive
//! definite, K_s positive definite, C_s positive semi-definite for α's ≥ 0.

use crate::beam::ModeShapes;
use crate::error::ParamError;
use crate::params::{Params, Structure, SweepParam};
use nalgebra::{DMatrix, DVector};

/// The two regions (the modes of the hybrid system), defined with it in [`crate::system`].
pub(crate) use crate::system::Region;

/// Modal forcing F_s(τ) = `constant` + `sin` · sin Ωτ + `cos` · cos Ωτ, each of shape `[N]`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Forcing {
    /// Constant part.
    pub constant: DVector<f64>,
    /// Coefficient of sin Ωτ.
    pub sin: DVector<f64>,
    /// Coefficient of cos Ωτ.
    pub cos: DVector<f64>,
}

/// Galerkin matrices of one region (eq. 10): mass, damping, stiffness (N×N) and forcing.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct RegionMatrices {
    /// Mass matrix M (eq. 11 / eq. 15).
    pub mass: DMatrix<f64>,
    /// Damping matrix C_s (eq. 12 or eq. 16).
    pub damping: DMatrix<f64>,
    /// Stiffness matrix K_s (eq. 13 or eq. 17).
    pub stiffness: DMatrix<f64>,
    /// Forcing F_s (eq. 14 or eq. 18).
    pub forcing: Forcing,
}

/// The Galerkin discretisation of the paper's model for one parameter set.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Galerkin {
    params: Params,
    shapes: ModeShapes,
    tip: DVector<f64>,
    integrals: DVector<f64>,
    free: RegionMatrices,
    contact: RegionMatrices,
}

impl Galerkin {
    /// Assemble both regions' matrices.
    ///
    /// # Errors
    /// [`ParamError`] if `params` fails validation (`Params::validate_fields`: the matrices do
    /// not depend on the drive's common period).
    pub(crate) fn new(params: &Params) -> Result<Self, ParamError> {
        params.validate_fields()?;
        let n = params.modes;
        let shapes = ModeShapes::new(n);
        // the point-mass model (params::Structure): one coordinate z = V_T − α5 with φ(1) = 1,
        // unit mass and stiffness, no distributed inertia (∫φ = 0) and a force drive
        // the eigenmode model: N such coordinates z_j (V_T = Σ z_j + α5, φ_j(1) = 1), stiffness
        // k_j/k_1 and mass (k_j/k_1)/(ω_j/ω_1)², each driven by the tip force
        let (tip, integrals, k_diag) = match (params.structure, &params.eigenmodes) {
            (Structure::PointMass, _) => {
                (DVector::from_element(1, 1.0), DVector::zeros(1), vec![1.0])
            }
            (Structure::Eigenmodes, Some(e)) => (
                DVector::from_element(n, 1.0),
                DVector::zeros(n),
                e.stiffness[..n].to_vec(),
            ),
            _ => (
                DVector::from_vec(shapes.tip()),
                DVector::from_vec(shapes.integrals()),
                shapes.beta4(),
            ),
        };
        let outer = &tip * tip.transpose();
        let mut mass = match &params.eigenmodes {
            Some(e) => DMatrix::from_diagonal(&DVector::from_fn(n, |j, _| e.mass(j))),
            None => mass_matrix(params, &outer),
        };
        if let Some(h) = &params.hydrodynamic {
            for j in 0..n {
                mass[(j, j)] += h.added_mass[j];
            }
        }
        let k_free = DMatrix::from_diagonal(&DVector::from_vec(k_diag));
        let free = RegionMatrices {
            mass: mass.clone(),
            damping: damping_free(params, n),
            stiffness: k_free.clone(),
            forcing: forcing_free(params, &tip, &integrals),
        };
        let contact = RegionMatrices {
            mass,
            damping: damping_contact(params, n, &outer),
            stiffness: stiffness_contact(params, &k_free, &outer),
            forcing: forcing_contact(params, &tip, &free.forcing),
        };
        Ok(Galerkin {
            params: *params,
            shapes,
            tip,
            integrals,
            free,
            contact,
        })
    }

    /// Move the sample to the gap α5 = `alpha5` in place: α5 enters only eq. 18's constant
    /// forcing (−α4 α5 φ_i(1)), rewritten by the same formula, so the result equals
    /// [`Galerkin::new`] of the parameters with α5 replaced bit for bit, without allocating.
    /// The caller validates `alpha5` ([`crate::model::CantileverModel::set_gap`]).
    pub(crate) fn set_gap(&mut self, alpha5: f64) {
        self.params.alpha5 = alpha5;
        contact_constant_into(&self.params, &self.tip, &mut self.contact.forcing.constant);
    }

    /// The clamped–free mode shapes.
    pub(crate) fn shapes(&self) -> &ModeShapes {
        &self.shapes
    }

    /// Tip values φ_i(1), shape `[N]`.
    pub(crate) fn tip(&self) -> &DVector<f64> {
        &self.tip
    }

    /// Matrices of one region.
    pub(crate) fn region(&self, r: Region) -> &RegionMatrices {
        match r {
            Region::Free => &self.free,
            Region::Contact => &self.contact,
        }
    }

    /// ∂F_s/∂p of the free and the contact region (in that order) for a parameter that enters
    /// the forcing only — Ω, α2, α5, on which M, C_s and K_s (eq. 11, 12, 13, 15–17) do not
    /// depend; `None` for α1, α3, α4, α6, which change the matrices.
    ///
    /// The forcing of eq. 14 and eq. 18 is a polynomial of degree ≤ 2 in each of Ω, α2 and α5
    /// (α2 Ω², α2 α6 Ω, α2, α4 α5), and for such a polynomial the central difference
    /// (F(p + δ) − F(p − δ)) / 2δ is the derivative exactly, for any δ; the same formulas are
    /// evaluated at p ± δ with δ = 1 + |p|, so the derivative is exact up to round-off and the
    /// formulas exist once.
    pub(crate) fn forcing_derivative(&self, param: SweepParam) -> Option<[Forcing; 2]> {
        let p0 = self.params;
        let value = match param {
            SweepParam::Omega => p0.omega,
            SweepParam::Alpha2 => p0.alpha2,
            SweepParam::Alpha5 => p0.alpha5,
            SweepParam::Alpha1 | SweepParam::Alpha3 | SweepParam::Alpha4 | SweepParam::Alpha6 => {
                return None
            }
        };
        Some(self.forcing_difference(param, value))
    }

    /// The lever's damping α3's derivatives (eq. 12, eq. 14, eq. 16, eq. 18): ∂C_s/∂α3 =
    /// diag(s_1 … s_N) in both regions (shape `[N]`, the damping profile; the fluid's and the
    /// sample's damping do not move with α3), and ∂F_s/∂α3 of the free and the contact region
    /// (the base velocity's −α2 α3 s_i ∫φ_i cos Ωτ of eq. 14; 0 under a force drive), linear in
    /// α3, so the central difference of [`Galerkin::forcing_derivative`] is exact.
    pub(crate) fn damping_derivative(&self) -> (DVector<f64>, [Forcing; 2]) {
        let p = &self.params;
        (
            self.damping_profile(),
            self.forcing_difference(SweepParam::Alpha3, p.alpha3),
        )
    }

    /// ∂C_s/∂α3 = diag(s_1 … s_N), the damping profile (shape `[N]`; 1 in the paper, eq. 12).
    pub(crate) fn damping_profile(&self) -> DVector<f64> {
        let p = &self.params;
        DVector::from_fn(p.modes, |j, _| profile(p, j))
    }

    /// (F(p + δ) − F(p − δ)) / 2δ of both regions' forcing in `param` at `value`, δ = 1 + |p|:
    /// the derivative, exactly up to round-off, for a forcing polynomial of degree ≤ 2 in p.
    fn forcing_difference(&self, param: SweepParam, value: f64) -> [Forcing; 2] {
        let p0 = self.params;
        let delta = 1.0 + value.abs();
        let at = |v: f64| {
            let p = p0.with(param, v);
            let free = forcing_free(&p, &self.tip, &self.integrals);
            let contact = forcing_contact(&p, &self.tip, &free);
            [free, contact]
        };
        let (plus, minus) = (at(value + delta), at(value - delta));
        let diff = |a: &DVector<f64>, b: &DVector<f64>| (a - b) / (2.0 * delta);
        let region = |i: usize| Forcing {
            constant: diff(&plus[i].constant, &minus[i].constant),
            sin: diff(&plus[i].sin, &minus[i].sin),
            cos: diff(&plus[i].cos, &minus[i].cos),
        };
        [region(0), region(1)]
    }
}

/// Eq. 11 (and eq. 15, M^II = M^I): M_ij = α1 φ_i(1) φ_j(1) + δ_ij ∫φ_i φ_j dξ, with ∫φ_i² = 1.
fn mass_matrix(p: &Params, outer: &DMatrix<f64>) -> DMatrix<f64> {
    DMatrix::identity(p.modes, p.modes) + outer * p.alpha1
}

/// Eq. 12: C^I_ij = δ_ij α3 ∫φ_i φ_j dξ = α3 δ_ij, generalised to modal damping
/// C^I = α3 diag(s_1 … s_N) with the profile s_j of [`Params::damping_profile`] (s_j = 1 in the
/// paper); s_j = (β_j²/β_1²)(Q_1/Q_j) gives mode j of the bare beam the quality factor Q_j.
/// A fluid adds its hydrodynamic damping c_j on the diagonal ([`crate::params::Hydrodynamic`]).
fn damping_free(p: &Params, n: usize) -> DMatrix<f64> {
    DMatrix::from_diagonal(&DVector::from_fn(n, |j, _| {
        p.alpha3 * profile(p, j) + fluid(p, j).1
    }))
}

/// The fluid's added mass m_a,j and damping c_j of mode j ((0, 0) without a fluid).
fn fluid(p: &Params, j: usize) -> (f64, f64) {
    p.hydrodynamic
        .map_or((0.0, 0.0), |h| (h.added_mass[j], h.damping[j]))
}

/// s_j of the damping profile (1 without one).
fn profile(p: &Params, j: usize) -> f64 {
    p.damping_profile.map_or(1.0, |s| s[j])
}

/// Eq. 16: C^II_ij = α3 δ_ij + α6 φ_i(1) φ_j(1).
fn damping_contact(p: &Params, n: usize, outer: &DMatrix<f64>) -> DMatrix<f64> {
    damping_free(p, n) + outer * p.alpha6
}

/// Eq. 17: K^II_ij = δ_ij β_i⁴ + α4 φ_i(1) φ_j(1); the diagonal β_i⁴ = ∫φ_i φ_i'''' dξ is eq. 13.
fn stiffness_contact(p: &Params, k_free: &DMatrix<f64>, outer: &DMatrix<f64>) -> DMatrix<f64> {
    k_free + outer * p.alpha4
}

/// Eq. 14: F^I_i = α2 Ω² [α1 φ_i(1) + ∫φ_i] sin Ωτ − α2 α3 s_i ∫φ_i cos Ωτ (s_i of the damping
/// profile, 1 in the paper). A fluid at rest acts on the absolute motion, so its added mass
/// m_a,i and damping c_i add α2 Ω² m_a,i ∫φ_i sin Ωτ − α2 Ω c_i ∫φ_i cos Ωτ (the base's
/// acceleration −α2Ω² sin Ωτ and velocity α2Ω cos Ωτ; [`crate::params::Hydrodynamic`]).
/// (Eq. 14 as printed has α2 α3 without the Ω of the base velocity that eq. 6 carries; afmdyn
/// keeps eq. 14 for the paper's α3, whose term is ~1/Q of the drive for a real lever.)
/// A force drive ([`Params::is_force_driven`]: the point-mass and eigenmode models, every
/// mode's tip value 1, and the beam with [`crate::params::Excitation::Tip`]) has
/// F^I_i = α2 φ_i(1) cos Ωτ instead. A moving sample ([`crate::params::Excitation::Sample`])
/// has F^I = 0: the lever's frame is at rest, the drive enters through V_T only (eq. 18).
fn forcing_free(p: &Params, tip: &DVector<f64>, integrals: &DVector<f64>) -> Forcing {
    let n = tip.len();
    if p.is_sample_modulated() {
        return Forcing {
            constant: DVector::zeros(n),
            sin: DVector::zeros(n),
            cos: DVector::zeros(n),
        };
    }
    if p.is_force_driven() {
        return Forcing {
            constant: DVector::zeros(n),
            sin: DVector::zeros(n),
            cos: tip * p.alpha2,
        };
    }
    let added: DVector<f64> = DVector::from_fn(n, |i, _| fluid(p, i).0 * integrals[i]);
    Forcing {
        constant: DVector::zeros(n),
        sin: (tip * p.alpha1 + integrals + added) * (p.alpha2 * p.omega * p.omega),
        cos: DVector::from_fn(n, |i, _| {
            -p.alpha2 * p.alpha3 * profile(p, i) * integrals[i]
                - p.alpha2 * p.omega * fluid(p, i).1 * integrals[i]
        }),
    }
}

/// Eq. 18: F^II_i = F^I_i − α2 α4 φ_i(1) sin Ωτ − α4 α5 φ_i(1) − α2 α6 Ω φ_i(1) cos Ωτ, the
/// base terms with the base amplitude of V_T ([`Params::base_amplitude`], 0 for the point mass).
fn forcing_contact(p: &Params, tip: &DVector<f64>, free: &Forcing) -> Forcing {
    let b = p.base_amplitude();
    let mut constant = DVector::zeros(tip.len());
    contact_constant_into(p, tip, &mut constant);
    Forcing {
        constant,
        sin: &free.sin - tip * (b * p.alpha4),
        cos: &free.cos - tip * (b * p.alpha6 * p.omega),
    }
}

/// Eq. 18's constant forcing −α4 α5 φ_i(1) written into `out` (shape `[N]`), elementwise
/// φ_i(1) · (−α4 α5) as `tip * (−α4 α5)` forms it.
fn contact_constant_into(p: &Params, tip: &DVector<f64>, out: &mut DVector<f64>) {
    let c = -p.alpha4 * p.alpha5;
    for (o, t) in out.iter_mut().zip(tip.iter()) {
        *o = t * c;
    }
}
