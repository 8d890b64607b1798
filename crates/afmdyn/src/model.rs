//! The switched model (paper eqs. 8 and 10) in first-order form, with its observables.
//!
//! State `z: [f64; 2N]` = (a, ȧ): modal coordinates a_j and their τ-derivatives. In region s,
//! ż = A_s z + b_s(τ) with A_s = [[0, I], [−M⁻¹K_s, −M⁻¹C_s]] and
//! b_s(τ) = (0, M⁻¹F_s(τ)), F_s = constant + sin·sin Ωτ + cos·cos Ωτ.

use crate::error::{ParamError, SimError};
use crate::galerkin::{Galerkin, Region};
use crate::params::Params;
use nalgebra::{DMatrix, DVector};

/// First-order dynamics of one region: ż = A z + b_const + b_sin sin Ωτ + b_cos cos Ωτ.
#[derive(Debug, Clone, PartialEq)]
pub struct RegionDynamics {
    /// State matrix A_s, 2N×2N.
    pub a: DMatrix<f64>,
    /// Constant input, shape `[2N]`.
    pub b_const: DVector<f64>,
    /// Coefficient of sin Ωτ, shape `[2N]`.
    pub b_sin: DVector<f64>,
    /// Coefficient of cos Ωτ, shape `[2N]`.
    pub b_cos: DVector<f64>,
}

/// Rates of the energy balance dE/dτ = P_base − D_beam − D_contact (see [`CantileverModel::energy`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PowerTerms {
    /// Power of the base motion: ẊᵀF^I(τ) (inertial drive in the clamped frame, eq. 14) plus,
    /// in contact, α2 Ω cos Ωτ · F_c (the sample moves with the base in these coordinates).
    pub base: f64,
    /// Beam damping dissipation α3 ẊᵀẊ (eq. 12).
    pub beam_dissipation: f64,
    /// Contact damper dissipation α6 V̇_T² (in contact only).
    pub contact_dissipation: f64,
}

/// The paper's cantilever–sample model for one parameter set.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverModel {
    params: Params,
    galerkin: Galerkin,
    regions: [RegionDynamics; 2],
}

impl CantileverModel {
    /// Assemble the model.
    ///
    /// # Errors
    /// [`ParamError`] if `params` is invalid.
    pub fn new(params: &Params) -> Result<Self, ParamError> {
        let galerkin = Galerkin::new(params)?;
        let build = |r: Region| {
            let m = galerkin.region(r);
            let n = params.modes;
            let minv = m.mass.clone().cholesky().expect("M is SPD").inverse();
            let mut a = DMatrix::zeros(2 * n, 2 * n);
            a.view_mut((0, n), (n, n)).fill_with_identity();
            a.view_mut((n, 0), (n, n))
                .copy_from(&(-&minv * &m.stiffness));
            a.view_mut((n, n), (n, n)).copy_from(&(-&minv * &m.damping));
            let lift = |f: &DVector<f64>| {
                let mut v = DVector::zeros(2 * n);
                v.rows_mut(n, n).copy_from(&(&minv * f));
                v
            };
            RegionDynamics {
                a,
                b_const: lift(&m.forcing.constant),
                b_sin: lift(&m.forcing.sin),
                b_cos: lift(&m.forcing.cos),
            }
        };
        let regions = [build(Region::Free), build(Region::Contact)];
        Ok(CantileverModel {
            params: *params,
            galerkin,
            regions,
        })
    }

    /// Parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }
    /// Number of modes N.
    pub fn modes(&self) -> usize {
        self.params.modes
    }
    /// State dimension 2N.
    pub fn dim(&self) -> usize {
        2 * self.params.modes
    }
    /// Drive frequency Ω.
    pub fn omega(&self) -> f64 {
        self.params.omega
    }
    /// Drive period T = 2π/Ω.
    pub fn period(&self) -> f64 {
        self.params.period()
    }
    /// The Galerkin matrices.
    pub fn galerkin(&self) -> &Galerkin {
        &self.galerkin
    }
    /// Tip values φ_j(1), shape `[N]`.
    pub fn tip(&self) -> &DVector<f64> {
        self.galerkin.tip()
    }
    /// First-order dynamics of a region.
    pub fn dynamics(&self, r: Region) -> &RegionDynamics {
        &self.regions[r.index()]
    }

    /// ż = A_s z + b_s(τ) written into `dz` (eq. 10 in first-order form). No allocation.
    pub fn rhs(&self, r: Region, tau: f64, z: &DVector<f64>, dz: &mut DVector<f64>) {
        let d = &self.regions[r.index()];
        let (s, c) = (self.params.omega * tau).sin_cos();
        dz.copy_from(&d.b_const);
        dz.axpy(s, &d.b_sin, 1.0);
        dz.axpy(c, &d.b_cos, 1.0);
        dz.gemv(1.0, &d.a, z, 1.0);
    }

    /// Tip deflection W(1,τ) = Σ a_j φ_j(1) (eq. 9 at ξ = 1).
    pub fn w_tip(&self, z: &DVector<f64>) -> f64 {
        let n = self.modes();
        self.tip().dot(&z.rows(0, n))
    }
    /// Tip velocity ∂W(1,τ)/∂τ.
    pub fn w_tip_dot(&self, z: &DVector<f64>) -> f64 {
        let n = self.modes();
        self.tip().dot(&z.rows(n, n))
    }
    /// Switching function V_T = W(1,τ) + α2 sin Ωτ + α5 (eq. 8).
    pub fn v_t(&self, tau: f64, z: &DVector<f64>) -> f64 {
        self.v_t_from_tip(tau, [self.w_tip(z), 0.0, 0.0])[0]
    }
    /// [V_T, dV_T/dτ, d²V_T/dτ²] at τ from the tip deflection and its derivatives
    /// [W(1,τ), W', W''] (eq. 8 differentiated twice).
    pub fn v_t_from_tip(&self, tau: f64, w: [f64; 3]) -> [f64; 3] {
        let p = &self.params;
        let (s, c) = (p.omega * tau).sin_cos();
        [
            w[0] + p.alpha2 * s + p.alpha5,
            w[1] + p.alpha2 * p.omega * c,
            w[2] - p.alpha2 * p.omega * p.omega * s,
        ]
    }
    /// dV_T/dτ = ∂W(1,τ)/∂τ + α2 Ω cos Ωτ.
    pub fn v_t_dot(&self, tau: f64, z: &DVector<f64>) -> f64 {
        self.v_t_from_tip(tau, [0.0, self.w_tip_dot(z), 0.0])[1]
    }
    /// Region of a state: contact when V_T ≤ 0 (eq. 10).
    pub fn region_at(&self, tau: f64, z: &DVector<f64>) -> Region {
        Region::of_v_t(self.v_t(tau, z))
    }
    /// Contact force F_c = α4 V_T + α6 V̇_T in region II, 0 in region I. The beam feels
    /// −F_c δ(ξ−1) (eq. 6), so F_c < 0 (tip pressed into the sample) pushes the tip away.
    pub fn contact_force(&self, r: Region, tau: f64, z: &DVector<f64>) -> f64 {
        match r {
            Region::Free => 0.0,
            Region::Contact => {
                self.params.alpha4 * self.v_t(tau, z) + self.params.alpha6 * self.v_t_dot(tau, z)
            }
        }
    }
    /// Beam deflection W(ξ,τ) = Σ a_j φ_j(ξ) (eq. 9).
    pub fn deflection(&self, xi: f64, z: &DVector<f64>) -> f64 {
        let phi = self.galerkin.shapes().values(xi);
        phi.iter().zip(z.iter()).map(|(p, a)| p * a).sum()
    }

    /// Stored energy E = ½ȦᵀMȦ + ½XᵀK^I X, plus ½α4 V_T² in contact (continuous across a
    /// switching because V_T = 0 there).
    pub fn energy(&self, r: Region, tau: f64, z: &DVector<f64>) -> f64 {
        let n = self.modes();
        let g = self.galerkin.region(Region::Free);
        let x = z.rows(0, n);
        let v = z.rows(n, n);
        let kinetic = 0.5 * (g.mass.clone() * v).dot(&v);
        let bending = 0.5 * (g.stiffness.clone() * x).dot(&x);
        let spring = match r {
            Region::Free => 0.0,
            Region::Contact => 0.5 * self.params.alpha4 * self.v_t(tau, z).powi(2),
        };
        kinetic + bending + spring
    }

    /// The rates of the energy balance at (τ, z) in region r. Multiplying eq. 10 by Ẋᵀ gives
    /// dE/dτ = P_base − D_beam − D_contact exactly.
    pub fn power(&self, r: Region, tau: f64, z: &DVector<f64>) -> PowerTerms {
        let n = self.modes();
        let p = &self.params;
        let g = self.galerkin.region(Region::Free);
        let v = z.rows(n, n);
        let (s, c) = (p.omega * tau).sin_cos();
        let drive = g.forcing.sin.dot(&v) * s + g.forcing.cos.dot(&v) * c;
        let beam = p.alpha3 * v.dot(&v);
        match r {
            Region::Free => PowerTerms {
                base: drive,
                beam_dissipation: beam,
                contact_dissipation: 0.0,
            },
            Region::Contact => {
                let vd = self.v_t_dot(tau, z);
                let fc = self.contact_force(r, tau, z);
                PowerTerms {
                    base: drive + p.alpha2 * p.omega * c * fc,
                    beam_dissipation: beam,
                    contact_dissipation: p.alpha6 * vd * vd,
                }
            }
        }
    }

    /// Saltation (jump) matrix of the flow's Jacobian at a switching from region `from` to `to`
    /// at (τ, z) on V_T = 0 (eq. 8):
    ///
    /// S = I + (f⁺ − f⁻) ∇_zV_Tᵀ / (dV_T/dτ)⁻,  (dV_T/dτ)⁻ = ∇_zV_T · f⁻ + ∂V_T/∂τ,
    ///
    /// with ∇_zV_T = (φ(1), 0) and ∂V_T/∂τ = α2 Ω cos Ωτ (the sample moves with the base in these
    /// coordinates). f⁺ − f⁻ = ∓(0, M⁻¹φ(1)(α4 V_T + α6 V̇_T)) is the contact force switched on or
    /// off; on V_T = 0 only the damper term α6 V̇_T remains, so S ≠ I whenever α6 > 0.
    /// Source: Leine & Nijmeijer, *Dynamics and Bifurcations of Non-Smooth Mechanical Systems*
    /// (Springer 2004), ch. 7; Müller, *Lyapunov exponents of dynamical systems with jumps* (1995).
    ///
    /// Returns the 2N×2N identity when dV_T/dτ = 0 (grazing: the saltation is unbounded there).
    pub fn saltation(&self, from: Region, to: Region, tau: f64, z: &DVector<f64>) -> DMatrix<f64> {
        let dim = self.dim();
        let n = self.modes();
        let mut f_minus = DVector::zeros(dim);
        let mut f_plus = DVector::zeros(dim);
        self.rhs(from, tau, z, &mut f_minus);
        self.rhs(to, tau, z, &mut f_plus);
        let mut grad = DVector::zeros(dim);
        grad.rows_mut(0, n).copy_from(self.tip());
        let p = &self.params;
        let rate = grad.dot(&f_minus) + p.alpha2 * p.omega * (p.omega * tau).cos();
        let mut s = DMatrix::identity(dim, dim);
        if rate != 0.0 {
            s += (f_plus - f_minus) * grad.transpose() / rate;
        }
        s
    }

    /// Check a state: length 2N and finite components.
    ///
    /// # Errors
    /// [`SimError::StateLength`] or [`SimError::NotFinite`].
    pub fn check_state(&self, name: &'static str, z: &DVector<f64>) -> Result<(), SimError> {
        if z.len() != self.dim() {
            return Err(SimError::StateLength {
                name,
                expected: self.dim(),
                got: z.len(),
            });
        }
        if let Some(v) = z.iter().find(|v| !v.is_finite()) {
            return Err(SimError::NotFinite { name, value: *v });
        }
        Ok(())
    }

    /// The state at rest (a = ȧ = 0).
    pub fn rest(&self) -> DVector<f64> {
        DVector::zeros(self.dim())
    }

    /// Build a state from modal displacements `a` and velocities `a_dot` (each of length N).
    ///
    /// # Errors
    /// [`SimError::StateLength`] / [`SimError::NotFinite`].
    pub fn state_from(&self, a: &[f64], a_dot: &[f64]) -> Result<DVector<f64>, SimError> {
        let n = self.modes();
        for (name, v) in [
            ("initial modal displacements", a),
            ("initial modal velocities", a_dot),
        ] {
            if v.len() != n {
                return Err(SimError::StateLength {
                    name,
                    expected: n,
                    got: v.len(),
                });
            }
        }
        let z = DVector::from_iterator(2 * n, a.iter().chain(a_dot).copied());
        self.check_state("initial state", &z)?;
        Ok(z)
    }
}

/// Body-contact check (the paper's Fig. 2f assumption): true when some point ξ < 1 of the
/// beam reaches the substrate, V(ξ,τ) = W(ξ,τ) + α2 sin Ωτ + 1 ≤ 0.
#[derive(Debug, Clone)]
pub struct BodyContactCheck {
    phi: DMatrix<f64>,
}

impl BodyContactCheck {
    /// Sample the beam at `points` interior stations ξ_i = 0.99 i / points, i = 1..=points.
    pub fn new(model: &CantileverModel, points: usize) -> Self {
        let n = model.modes();
        let shapes = model.galerkin().shapes();
        let mut phi = DMatrix::zeros(points, n);
        for i in 0..points {
            let xi = 0.99 * (i + 1) as f64 / points as f64;
            for (j, v) in shapes.values(xi).into_iter().enumerate() {
                phi[(i, j)] = v;
            }
        }
        BodyContactCheck { phi }
    }

    /// Whether any station touches the substrate at (τ, z).
    pub fn touches(&self, model: &CantileverModel, tau: f64, z: &DVector<f64>) -> bool {
        let p = model.params();
        let base = p.alpha2 * (p.omega * tau).sin() + 1.0;
        let n = model.modes();
        let w = &self.phi * z.rows(0, n);
        w.iter().any(|wi| wi + base <= 0.0)
    }
}
