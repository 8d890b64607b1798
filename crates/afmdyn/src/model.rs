//! The cantilever–sample model (paper eqs. 8–18) in first-order form, for any tip–sample law.
//!
//! State `z: [f64; 2N + m]` = (a, ȧ, internal): modal coordinates a_j, their τ-derivatives,
//! and the m internal states of the law ([`ContactLaw::internal_states`]: the SLS sample's
//! dashpot extension u, m = 1; m = 0 for every other law). In both regions
//!
//! M ä + C ȧ + K a = F^I(τ) + φ(1) F_c(δ, δ̇),  δ = −V_T (eq. 8),
//!
//! with M, C, K, F^I of eqs. 11–14 and the law F_c of [`crate::contact`] (repulsive positive).
//! Region I (free) has F_c = 0 except for the DMT van der Waals attraction; region II is contact
//! (V_T ≤ 0). For the linear law, region s is ż = A_s z + b_s(τ) with
//! A_s = [[0, I], [−M⁻¹K_s, −M⁻¹C_s]] and b_s(τ) = (0, M⁻¹F_s(τ)) (eqs. 15–18): the affine form
//! the exact propagator uses ([`CantileverModel::dynamics`]).
//!
//! **Impact law.** Region I is free flight; an impact at V_T = 0 applies Newton's law
//! dV_T/dτ⁺ = −r dV_T/dτ⁻ through the tip: ȧ⁺ = ȧ⁻ − (1 + r) V̇_T⁻ M⁻¹φ / (φᵀM⁻¹φ), the impulse
//! P φ at the tip that meets the law (Brogliato, *Nonsmooth Mechanics*, 3rd ed., Springer 2016,
//! §4.2; m_eff = 1/(φᵀM⁻¹φ) is the modal mass at the tip). Region II is **sticking**: the tip
//! moves with the sample (V_T ≡ 0) under the constraint force λ = −m_eff V̈_T^free, the force that
//! cancels the free tip acceleration relative to the sample; the tip leaves when λ falls to 0.
//! A chattering sequence (impact velocities decaying as rᵏ) ends in sticking once the next bounce
//! would rise less than `STICK_HEIGHT_TOLERANCES` guard tolerances while λ > 0.

use crate::contact::{ContactLaw, ForceEval, PreparedLaw, TipSample, TipSampleLaw, Zener};
use crate::error::{ParamError, SimError};
use crate::galerkin::Galerkin;
use crate::params::{Params, SweepParam};
use crate::system::{EventKind, Guard, HybridSystem, Jump, Region};
use nalgebra::{DMatrix, DVector};

mod body_contact;
mod rate_form;

pub(crate) use body_contact::{weighted_displacement, BodyContactCheck};
pub(crate) use rate_form::RateForm;

/// A chattering sequence ends in sticking when the next bounce would rise less than this many
/// guard tolerances above the sample (1e3 × 1e-12 (1 + α2 + |α5|) ≈ 1e-9 of the gap g₀). The
/// bounce after an impact at V̇_T⁻ rises h = m_eff (r V̇_T⁻)²/(2λ), λ > 0 the compressive force
/// that would hold the tip on the sample; below this height single bounces are not resolved by
/// the round-off dead band of the event search. The impact velocities decay as rᵏ, so at most
/// ln(h_stick/h₀)/(2 ln r) impacts precede the sticking, and the sticking starts at most
/// 2 r v/(|V̈_T|(1 − r)) before the accumulation point of the unresolved impacts.
pub(crate) const STICK_HEIGHT_TOLERANCES: f64 = 1e3;

/// Baumgarte rate of the sticking constraint, in units of Ω (see the sticking force λ).
pub(crate) const BAUMGARTE_RATE: f64 = 10.0;

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

/// ∂/∂p of the inputs of one region's dynamics ([`RegionDynamics`]) for a parameter p that
/// enters the forcing only (Ω, α2, α5: A_s does not depend on it), see
/// [`CantileverModel::forcing_derivative`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ForcingDerivative {
    /// ∂b_const/∂p, shape `[2N]`.
    pub b_const: DVector<f64>,
    /// ∂b_sin/∂p, shape `[2N]`.
    pub b_sin: DVector<f64>,
    /// ∂b_cos/∂p, shape `[2N]`.
    pub b_cos: DVector<f64>,
    /// ∂Ω/∂p: 1 for p = Ω (the harmonics sin Ωτ, cos Ωτ then depend on p), else 0.
    pub d_omega: f64,
}

/// The free region's derivative in the lever's damping α3
/// ([`CantileverModel::damping_derivative`]): ∂f/∂α3 = b′(τ) + (0, V ȧ).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct DampingDerivative {
    /// ∂b/∂α3 of the forcing (the base velocity's term of eq. 14), lifted to the state.
    pub forcing: ForcingDerivative,
    /// V = −M⁻¹ diag(s), shape N×N: the rate's derivative per unit of ȧ.
    pub velocity: DMatrix<f64>,
}

/// Rates of the energy balance dE/dτ = P_base − D_beam − D_contact (see [`CantileverModel::power`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct PowerTerms {
    /// Power of the base motion: ȦᵀF^I(τ) (inertial drive in the clamped frame, eq. 14) minus
    /// α2 Ω cos Ωτ · F_c (the sample is fixed while the clamped frame moves).
    pub base: f64,
    /// Beam damping dissipation ȦᵀC^IȦ (eq. 12: α3 ȦᵀȦ, or α3 Σ s_j ȧ_j² with a damping
    /// profile).
    pub beam_dissipation: f64,
    /// Sample dissipation F_d δ̇ (α6 V̇_T² for the linear law in contact).
    pub contact_dissipation: f64,
}

/// The cantilever–sample model for one parameter set and tip–sample law.
#[derive(Debug, Clone, PartialEq)]
pub struct CantileverModel {
    params: Params,
    galerkin: Galerkin,
    /// eq. 10 with the linear law (regions I and II); region I is also the free flight of
    /// every law apart from its tip force.
    regions: [RegionDynamics; 2],
    /// The law with α4, α6 and its derived constants (computed once).
    law: PreparedLaw,
    /// M⁻¹φ(1), shape `[N]`.
    mphi: DVector<f64>,
    /// M⁻¹, N×N: kept for [`CantileverModel::set_gap`].
    minv: DMatrix<f64>,
    /// m_eff = 1/(φᵀM⁻¹φ).
    m_eff: f64,
    /// φᵀ[−M⁻¹K, −M⁻¹C], shape `[2N]`: the free tip acceleration per unit z.
    tip_acc: DVector<f64>,
    /// φᵀM⁻¹F^I: constant, sin and cos coefficients of the free tip acceleration.
    tip_acc_forcing: [f64; 3],
    /// The system's period: [`Params::period`], or 2π/Ω for a quasi-periodic drive
    /// ([`CantileverModel::quasiperiodic`]).
    period: f64,
    /// V_T where the contact region is left on retraction ([`ContactLaw::release_distance`]):
    /// the JKR neck's |δ_f|, 0 for the other laws.
    release: f64,
    /// The SLS sample (α4, κ, α6) whose dashpot extension u is the state's entry 2N; `None`
    /// for the laws without an internal state.
    zener: Option<Zener>,
}

impl CantileverModel {
    /// Assemble the model.
    ///
    /// # Errors
    /// [`ParamError`] if `params` is invalid ([`Params::validate`]: a quasi-periodic drive is
    /// refused, it has no period).
    pub fn new(params: &Params) -> Result<Self, ParamError> {
        params.validate()?;
        Self::assemble(params, params.period())
    }

    /// The model of a quasi-periodic drive ([`Params::is_quasiperiodic`]; any drive is
    /// accepted) for the time average ([`crate::analysis::stepped::average`]), the only analysis
    /// that does not need the system's period: its [`HybridSystem::period`] is the primary
    /// drive period 2π/Ω, the scale of the integrators' step budgets, not a period of the
    /// system. Crate-private so that no periodic analysis receives it.
    ///
    /// # Errors
    /// [`ParamError`] if a field is invalid ([`Params::validate_fields`]).
    pub(crate) fn quasiperiodic(params: &Params) -> Result<Self, ParamError> {
        Self::assemble(params, std::f64::consts::TAU / params.omega)
    }

    fn assemble(params: &Params, period: f64) -> Result<Self, ParamError> {
        let galerkin = Galerkin::new(params)?;
        let n = params.modes;
        let minv = galerkin
            .region(Region::Free)
            .mass
            .clone()
            .cholesky()
            .ok_or(ParamError::NonNegative {
                name: "alpha1 (tip-mass ratio α1; mass matrix not positive definite)",
                value: params.alpha1,
            })?
            .inverse();
        let build = |r: Region| {
            let m = galerkin.region(r);
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
        let tip = galerkin.tip().clone();
        let mphi = &minv * &tip;
        let m_eff = 1.0 / tip.dot(&mphi);
        let free = &regions[0];
        let tip_acc = free.a.rows(n, n).transpose() * &tip;
        let tip_acc_forcing = [
            tip.dot(&free.b_const.rows(n, n)),
            tip.dot(&free.b_sin.rows(n, n)),
            tip.dot(&free.b_cos.rows(n, n)),
        ];
        Ok(CantileverModel {
            params: *params,
            law: PreparedLaw::new(TipSample {
                law: params.contact_law,
                stiffness: params.alpha4,
                damping: params.alpha6,
            }),
            galerkin,
            regions,
            mphi,
            minv,
            m_eff,
            tip_acc,
            tip_acc_forcing,
            period,
            release: params.contact_law.release_distance(params.alpha4),
            zener: params.contact_law.zener(params.alpha4, params.alpha6),
        })
    }

    /// The constant of the guard of `mode`: |δ_f| in a hysteretic law's contact, else 0.
    fn guard_offset(&self, mode: Region) -> f64 {
        if mode == Region::Contact {
            self.release
        } else {
            0.0
        }
    }

    /// V_T at which the contact region is left on retraction: |δ_f| > 0 for a hysteretic law
    /// (JKR's neck, [`ContactLaw::release_distance`]), 0 otherwise. The contact guard is
    /// g = release − V_T.
    pub(crate) fn release_distance(&self) -> f64 {
        self.release
    }

    /// The energy the sample takes at an event from `from` to `to` at (τ, z) where the state
    /// is continuous: the drop of the tip–sample potential U_from − U_to (F̃·g₀). 0 for the laws
    /// whose potential is continuous across the switching; for JKR E_hys where the contact
    /// forms (the adhesive neck snaps in) and 0 where it breaks (U = 0 at δ_f).
    pub(crate) fn switching_loss(
        &self,
        from: Region,
        to: Region,
        tau: f64,
        z: &DVector<f64>,
    ) -> f64 {
        if self.release == 0.0 || from == to {
            return 0.0;
        }
        let delta = -self.v_t(tau, z);
        self.law.potential(from == Region::Contact, delta)
            - self.law.potential(to == Region::Contact, delta)
    }

    /// Move the sample to the gap α5 = `alpha5` in place (a scan's piezo between drive
    /// periods): afterwards the model equals [`CantileverModel::new`] of its parameters with
    /// α5 replaced, bit for bit (α5 enters only eq. 18's constant forcing, here rewritten by
    /// the same operations, and V_T, read from the parameters), without assembling it again.
    ///
    /// # Errors
    /// As [`CantileverModel::new`]: `Params::validate_fields` of the changed parameters (the
    /// drive's common period, [`Params::validate`]'s further check, does not depend on α5);
    /// the model is unchanged then.
    pub(crate) fn set_gap(&mut self, alpha5: f64) -> Result<(), ParamError> {
        self.params
            .with(SweepParam::Alpha5, alpha5)
            .validate_fields()?;
        self.params.alpha5 = alpha5;
        self.galerkin.set_gap(alpha5);
        let n = self.params.modes;
        let lower = &self.minv * &self.galerkin.region(Region::Contact).forcing.constant;
        self.regions[Region::Contact.index()]
            .b_const
            .rows_mut(n, n)
            .copy_from(&lower);
        Ok(())
    }

    /// Parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }
    /// The tip–sample law.
    pub(crate) fn law(&self) -> &ContactLaw {
        &self.params.contact_law
    }
    /// Number of modes N.
    pub fn modes(&self) -> usize {
        self.params.modes
    }
    /// State dimension 2N + m (m the law's internal states, [`ContactLaw::internal_states`]).
    pub fn dim(&self) -> usize {
        self.params.state_dim()
    }
    /// The SLS sample whose dashpot extension u is the state's entry 2N (`None` for the other
    /// laws).
    pub(crate) fn zener(&self) -> Option<&Zener> {
        self.zener.as_ref()
    }
    /// The SLS sample's (zener, u) at z, `None` for the other laws.
    fn zener_state(&self, z: &[f64]) -> Option<(&Zener, f64)> {
        self.zener.as_ref().map(|zn| (zn, z[2 * self.modes()]))
    }
    /// The switching function without the guard's sign σ, given V_T: V_T + s(u) for the SLS
    /// sample (the tip's height above the recovering surface, [`Zener::surface`]), V_T for the
    /// other laws.
    fn switching(&self, v_t: f64, z: &[f64]) -> f64 {
        match self.zener_state(z) {
            Some((zn, u)) => v_t + zn.surface(u),
            None => v_t,
        }
    }
    /// Drive frequency Ω.
    pub fn omega(&self) -> f64 {
        self.params.omega
    }
    /// The system's period: the drive period T = 2π/Ω, or a multifrequency drive's common
    /// period ([`Params::period`]); 2π/Ω for the model of a quasi-periodic drive.
    pub fn period(&self) -> f64 {
        self.period
    }
    /// The Galerkin matrices.
    pub(crate) fn galerkin(&self) -> &Galerkin {
        &self.galerkin
    }
    /// Tip values φ_j(1), shape `[N]`.
    pub fn tip(&self) -> &DVector<f64> {
        self.galerkin.tip()
    }
    /// M⁻¹φ(1), shape `[N]`: the modal acceleration per unit tip force.
    pub(crate) fn tip_mobility(&self) -> &DVector<f64> {
        &self.mphi
    }
    /// Modal mass at the tip m_eff = 1/(φᵀM⁻¹φ).
    pub(crate) fn effective_mass(&self) -> f64 {
        self.m_eff
    }
    /// First-order dynamics of a region for the **linear law** (eqs. 10, 15–18): the affine
    /// form used by the exact propagator. Region I is also the free flight of the Hertz and
    /// impact laws.
    pub fn dynamics(&self, r: Region) -> &RegionDynamics {
        &self.regions[r.index()]
    }

    /// ż written into `dz` (eq. 10 in first-order form with the law's tip force). No allocation.
    pub fn rhs(&self, r: Region, tau: f64, z: &DVector<f64>, dz: &mut DVector<f64>) {
        self.rhs_slice(r, tau, z.as_slice(), dz.as_mut_slice());
    }

    /// As [`CantileverModel::rhs`] on slices of length 2N.
    pub(crate) fn rhs_slice(&self, r: Region, tau: f64, z: &[f64], dz: &mut [f64]) {
        self.rhs_slice_at(r, tau, (self.params.omega * tau).sin_cos(), z, dz);
    }

    /// As [`CantileverModel::rhs_slice`] given `(s, c)` = (sin Ωτ, cos Ωτ), which a caller
    /// holding them at τ already need not have computed twice.
    pub(crate) fn rhs_slice_at(
        &self,
        r: Region,
        tau: f64,
        (s, c): (f64, f64),
        z: &[f64],
        dz: &mut [f64],
    ) {
        let n = self.modes();
        let linear = self.law.law().is_affine();
        let d = &self.regions[if linear { r.index() } else { 0 }];
        let (zb, dzb) = (&z[..2 * n], &mut dz[..2 * n]);
        for (i, o) in dzb.iter_mut().enumerate() {
            *o = d.b_const[i] + s * d.b_sin[i] + c * d.b_cos[i];
        }
        crate::linalg::matvec(&d.a, zb, dzb, 1.0, true);
        if let Some((zn, u)) = self.zener_state(z) {
            // the dashpot's rate u̇ (the state's last entry)
            let [v, _, _] = self.v_t_at((s, c), [self.w_tip_slice(z, 0), 0.0, 0.0]);
            dz[2 * n] = zn.rate(r == Region::Contact, -v, u);
        }
        // the further components of a multifrequency drive: a force at the tip
        let fd = if self.params.is_multifrequency() {
            self.params.component_force(tau)
        } else {
            0.0
        };
        if linear && fd == 0.0 {
            return;
        }
        let f = fd
            + if linear {
                0.0
            } else {
                self.tip_force_with(r, tau, (s, c), z)
            };
        let acc = &mut dz[n..];
        if f != 0.0 {
            for (o, m) in acc.iter_mut().zip(self.mphi.iter()) {
                *o += f * m;
            }
        }
    }

    /// Tip force F_c (repulsive positive) in region r at (τ, z): the law's force, or in the
    /// sticking region of the impact law the constraint force λ.
    pub(crate) fn contact_force(&self, r: Region, tau: f64, z: &DVector<f64>) -> f64 {
        let sc = (self.params.omega * tau).sin_cos();
        self.tip_force_with(r, tau, sc, z.as_slice())
    }

    /// [V_T, W(1,τ), ∂W(1,τ)/∂τ, F_c] at (τ, z) in region `r` given (sin Ωτ, cos Ωτ): the
    /// values of a recorded sample (`trajectory`), as [`CantileverModel::v_t`],
    /// [`CantileverModel::w_tip`], [`CantileverModel::w_tip_dot`] and
    /// [`CantileverModel::contact_force`] form them, from the sine and cosine the caller has.
    /// `z: [f64; 2N]`.
    pub(crate) fn sample_values(
        &self,
        r: Region,
        tau: f64,
        (s, c): (f64, f64),
        z: &[f64],
    ) -> [f64; 4] {
        let n = self.modes();
        let (w, wd) = (self.w_tip_slice(z, 0), self.w_tip_slice(z, n));
        let [v, vd, _] = self.v_t_at((s, c), [w, wd, 0.0]);
        [v, w, wd, self.tip_force_from(r, tau, z, || (v, vd))]
    }

    /// F_c at τ given sin/cos of Ωτ.
    fn tip_force_with(&self, r: Region, tau: f64, sc: (f64, f64), z: &[f64]) -> f64 {
        self.tip_force_from(r, tau, z, || {
            let [v, vd, _] = self.v_t_at(
                sc,
                [
                    self.w_tip_slice(z, 0),
                    self.w_tip_slice(z, self.modes()),
                    0.0,
                ],
            );
            (v, vd)
        })
    }

    /// F_c in region r at (τ, z), with V_T and dV_T/dτ from `v_t` where the law needs them
    /// (the impact law's sticking force λ and the laws without force outside contact do not).
    fn tip_force_from(
        &self,
        r: Region,
        tau: f64,
        z: &[f64],
        v_t: impl FnOnce() -> (f64, f64),
    ) -> f64 {
        let contact = r == Region::Contact;
        // a law with an internal state (SLS), a rigid constraint (impact), or a force law
        if self.zener.is_some() {
            match self.zener_state(z) {
                Some((zn, u)) if contact => zn.force(true, -v_t().0, u),
                _ => 0.0,
            }
        } else if self.law.law().restitution().is_some() {
            if contact {
                self.sticking_force_value(tau, z)
            } else {
                0.0
            }
        } else if !contact && !self.law.acts_outside() {
            0.0
        } else {
            let (v, vd) = v_t();
            self.law.force(contact, -v, -vd).force
        }
    }

    /// F_c with its partials ∂F_c/∂δ, ∂F_c/∂δ̇ in region `r` at (sin Ωτ, cos Ωτ) = `sc` of a
    /// law without memory (a force of the state; `z: [f64; 2N]`): zero outside contact for a
    /// law that does not act there. (The thermal step's frozen force and its contact rate,
    /// `crate::integrate::exact::noise`.)
    pub(crate) fn tip_force_eval(&self, r: Region, sc: (f64, f64), z: &[f64]) -> ForceEval {
        let contact = r == Region::Contact;
        if !contact && !self.law.acts_outside() {
            return ForceEval::default();
        }
        let n = self.modes();
        let w = [self.w_tip_slice(z, 0), self.w_tip_slice(z, n), 0.0];
        let [v, vd, _] = self.v_t_at(sc, w);
        self.law.force(contact, -v, -vd)
    }

    /// ∂ż/∂z at (τ, z) in region r into `jac` (2N×2N): A_I plus the rank-one tip-force term
    /// M⁻¹φ (∂F_c/∂z)ᵀ with ∂F_c/∂a = −(∂F_c/∂δ) φ, ∂F_c/∂ȧ = −(∂F_c/∂δ̇) φ; for sticking
    /// ∂λ/∂z of the sticking force. The linear law gives A_s of eqs. 15–18.
    pub(crate) fn jacobian_into(&self, r: Region, tau: f64, z: &[f64], jac: &mut DMatrix<f64>) {
        self.jacobian_parts(r, tau, self.base_trig(tau), z, jac, true);
    }

    /// The Kelvin–Voigt weight w = α6 √δ of DMT (and the electrostatic and capillary laws) in
    /// contact (0 elsewhere): its τ-derivative
    /// α6 δ̇/(2√δ) is the singular part of ∂F_c/∂δ at contact onset.
    fn kelvin_voigt_weight(&self, r: Region, tau: f64, z: &[f64]) -> f64 {
        self.kelvin_voigt_weight_at(r, self.base_trig(tau), z)
    }

    /// [`Self::kelvin_voigt_weight`] given (sin Ωτ, cos Ωτ) = `sc` ([`Self::base_trig`]).
    fn kelvin_voigt_weight_at(&self, r: Region, sc: (f64, f64), z: &[f64]) -> f64 {
        if r != Region::Contact || !self.law.law().kelvin_voigt() {
            return 0.0;
        }
        let [v, _, _] = self.v_t_at(sc, [self.w_tip_slice(z, 0), 0.0, 0.0]);
        self.law.damping() * (-v).max(0.0).sqrt()
    }

    /// [`CantileverModel::jacobian_into`], without the singular Kelvin–Voigt term when
    /// `singular` is false.
    fn jacobian_parts(
        &self,
        r: Region,
        tau: f64,
        sc: (f64, f64),
        z: &[f64],
        jac: &mut DMatrix<f64>,
        singular: bool,
    ) {
        let n = self.modes();
        let linear = self.law.law().is_affine();
        let a = &self.regions[if linear { r.index() } else { 0 }].a;
        if jac.nrows() == a.nrows() {
            jac.copy_from(a);
        } else {
            // a law with internal states: A_I in the top-left block, their rows below
            jac.fill(0.0);
            jac.view_mut((0, 0), (2 * n, 2 * n)).copy_from(a);
        }
        if linear {
            return;
        }
        // the gradient row of the tip force (on the stack), then the rank-one term M⁻¹φ rowᵀ
        // added to the velocity rows
        let mut buf = [0.0; crate::params::MAX_STATE];
        let row = &mut buf[..self.dim()];
        // a law with an internal state (SLS), a rigid constraint (impact), or a force law
        if let Some((zn, _)) = self.zener_state(z) {
            // u̇ = (κ/α6)(δ_s − u): δ_s = δ = −φᵀa − … in contact, s(u) free
            let rate = zn.relaxation_rate();
            if r == Region::Contact {
                for (j, t) in self.tip().iter().enumerate() {
                    jac[(2 * n, j)] = -rate * t;
                }
                jac[(2 * n, 2 * n)] = -rate;
                // F = (α4 + κ)δ − κu
                for (j, t) in self.tip().iter().enumerate() {
                    row[j] = -(zn.relaxed + zn.maxwell) * t;
                }
                row[2 * n] = -zn.maxwell;
            } else {
                jac[(2 * n, 2 * n)] = rate * (zn.surface_gain() - 1.0);
                return;
            }
        } else if self.law.law().restitution().is_some() {
            if r != Region::Contact {
                return;
            }
            row.copy_from_slice(self.sticking_force(tau, z).grad.as_slice());
        } else {
            if r != Region::Contact && !self.law.acts_outside() {
                return;
            }
            let [v, vd, _] = self.v_t_at(sc, [self.w_tip_slice(z, 0), self.w_tip_slice(z, n), 0.0]);
            let f = self.law.force(r == Region::Contact, -v, -vd);
            let w = self.kelvin_voigt_weight_at(r, sc, z);
            let d_delta = if singular || w == 0.0 {
                f.d_delta
            } else {
                // remove α6 δ̇/(2√δ) = α6² δ̇/(2w)
                f.d_delta - 0.5 * self.law.damping() * self.law.damping() * (-vd) / w
            };
            for (j, t) in self.tip().iter().enumerate() {
                row[j] = -d_delta * t;
                row[n + j] = -f.d_rate * t;
            }
        }
        for (c, &rc) in row.iter().enumerate() {
            if rc != 0.0 {
                for i in 0..n {
                    jac[(n + i, c)] += self.mphi[i] * rc;
                }
            }
        }
    }

    /// φ(1)ᵀ of the N values of `z` from `offset`: W(1,τ) at offset 0, ∂W(1,τ)/∂τ at N.
    pub(crate) fn w_tip_slice(&self, z: &[f64], offset: usize) -> f64 {
        let n = self.modes();
        self.tip()
            .as_slice()
            .iter()
            .zip(&z[offset..offset + n])
            .map(|(a, b)| a * b)
            .sum()
    }
    /// Tip deflection W(1,τ) = Σ a_j φ_j(1) (eq. 9 at ξ = 1).
    pub fn w_tip(&self, z: &DVector<f64>) -> f64 {
        self.w_tip_slice(z.as_slice(), 0)
    }
    /// Tip velocity ∂W(1,τ)/∂τ.
    pub(crate) fn w_tip_dot(&self, z: &DVector<f64>) -> f64 {
        self.w_tip_slice(z.as_slice(), self.modes())
    }
    /// Switching function V_T = W(1,τ) + α2 sin Ωτ + α5 (eq. 8).
    pub fn v_t(&self, tau: f64, z: &DVector<f64>) -> f64 {
        self.v_t_from_tip(tau, [self.w_tip(z), 0.0, 0.0])[0]
    }
    /// [V_T, dV_T/dτ, d²V_T/dτ²] at τ from the tip deflection and its derivatives
    /// [W(1,τ), W', W''] (eq. 8 differentiated twice).
    pub(crate) fn v_t_from_tip(&self, tau: f64, w: [f64; 3]) -> [f64; 3] {
        self.v_t_at(self.base_trig(tau), w)
    }
    /// (sin Ωτ, cos Ωτ) as V_T needs them (eq. 8): without the sine and cosine where the base
    /// does not move (the point mass, whose V_T = W + α5), as they are multiplied by 0 there.
    pub(crate) fn base_trig(&self, tau: f64) -> (f64, f64) {
        if self.params.base_amplitude() == 0.0 {
            (0.0, 0.0)
        } else {
            (self.params.omega * tau).sin_cos()
        }
    }
    /// [`CantileverModel::v_t_from_tip`] given (sin Ωτ, cos Ωτ): eq. 8, the one place V_T is
    /// formed from the tip deflection.
    pub(crate) fn v_t_at(&self, (s, c): (f64, f64), w: [f64; 3]) -> [f64; 3] {
        let p = &self.params;
        [
            w[0] + p.base_amplitude() * s + p.alpha5,
            w[1] + p.base_amplitude() * p.omega * c,
            w[2] - p.base_amplitude() * p.omega * p.omega * s,
        ]
    }
    /// [W(1,τ), ∂W(1,τ)/∂τ, V_T, dV_T/dτ] at (τ, z), `z: [f64; 2N]` as (a, ȧ): the tip
    /// deflection and rate (eq. 9 at ξ = 1) and eq. 8 from one sin/cos Ωτ.
    pub(crate) fn tip_values(&self, tau: f64, z: &DVector<f64>) -> [f64; 4] {
        let (w, w_dot) = (self.w_tip(z), self.w_tip_dot(z));
        let [v_t, v_t_dot, _] = self.v_t_from_tip(tau, [w, w_dot, 0.0]);
        [w, w_dot, v_t, v_t_dot]
    }
    /// dV_T/dτ = ∂W(1,τ)/∂τ + α2 Ω cos Ωτ.
    pub(crate) fn v_t_dot(&self, tau: f64, z: &DVector<f64>) -> f64 {
        self.v_t_from_tip(tau, [0.0, self.w_tip_dot(z), 0.0])[1]
    }
    /// Region by the sign of V_T: contact when V_T ≤ 0 (eq. 10; V_T + s(u) ≤ 0 over the SLS
    /// sample's recovering surface). (For the impact law, sticking is tracked by the
    /// integrators; see [`HybridSystem::mode_at`].)
    pub(crate) fn region_at(&self, tau: f64, z: &DVector<f64>) -> Region {
        Region::of_v_t(self.switching(self.v_t(tau, z), z.as_slice()))
    }
    /// Beam deflection W(ξ,τ) = Σ a_j φ_j(ξ) (eq. 9).
    /// For the point-mass and eigenmode models, the tip deflection Σ z_j at every ξ.
    pub fn deflection(&self, xi: f64, z: &DVector<f64>) -> f64 {
        if self.params.structure.is_lumped() {
            return z.rows(0, self.modes()).sum();
        }
        let phi = self.galerkin.shapes().values(xi);
        phi.iter().zip(z.iter()).map(|(p, a)| p * a).sum()
    }

    /// Constraint force λ of sticking (impact law) at (τ, z), with its gradient and τ-rate:
    /// λ = m_eff (α2 Ω² sin Ωτ − φᵀä_free − 2β V̇_T − β² V_T), the force that gives
    /// V̈_T = −2β V̇_T − β² V_T: zero on the constraint V_T = V̇_T = 0, and Baumgarte's
    /// stabilisation of the integration drift off it (Baumgarte, *Comput. Methods Appl. Mech.
    /// Eng.* 1 (1972) 1), with β = [`BAUMGARTE_RATE`] Ω.
    fn sticking_force(&self, tau: f64, z: &[f64]) -> Guard {
        let p = &self.params;
        let n = p.modes;
        let om = p.omega;
        let beta = BAUMGARTE_RATE * om;
        let (s, c) = (om * tau).sin_cos();
        let [_, fs, fc] = self.tip_acc_forcing;
        let mut grad = -self.m_eff * &self.tip_acc;
        for (j, phi) in self.tip().iter().enumerate() {
            grad[j] -= self.m_eff * beta * beta * phi;
            grad[n + j] -= self.m_eff * 2.0 * beta * phi;
        }
        let dv_tau = p.base_amplitude() * om * c;
        let dvd_tau = -p.base_amplitude() * om * om * s;
        Guard {
            value: self.sticking_force_value(tau, z),
            grad,
            d_tau: self.m_eff
                * (p.base_amplitude() * om * om * om * c
                    - om * (fs * c - fc * s)
                    - 2.0 * beta * dvd_tau
                    - beta * beta * dv_tau)
                - p.component_force_rate(tau),
        }
    }

    /// The value of the sticking force λ (see `sticking_force`), without its gradient: the
    /// vector field of sticking calls it at every evaluation.
    fn sticking_force_value(&self, tau: f64, z: &[f64]) -> f64 {
        let p = &self.params;
        let om = p.omega;
        let beta = BAUMGARTE_RATE * om;
        let (s, c) = (om * tau).sin_cos();
        let [f0, fs, fc] = self.tip_acc_forcing;
        let acc =
            self.tip_acc.iter().zip(z).map(|(a, b)| a * b).sum::<f64>() + f0 + fs * s + fc * c;
        let (v, vd) = self.v_t_pair(tau, z);
        // the further drive components' tip force F̃ adds F̃/m_eff to the free tip acceleration
        self.m_eff * (p.base_amplitude() * om * om * s - acc - 2.0 * beta * vd - beta * beta * v)
            - p.component_force(tau)
    }

    /// Impact law, start inside the sample (V_T < 0): the plastic contact that places it on the
    /// surface, a ← a − V_T m_eff M⁻¹φ and, when V̇_T < 0, ȧ ← ȧ − V̇_T m_eff M⁻¹φ (the smallest
    /// change in the kinetic metric with V_T = 0, V̇_T ≥ 0), with its Jacobian (2N×2N). `None`
    /// for every other start and law.
    pub(crate) fn start_projection(
        &self,
        tau: f64,
        z: &DVector<f64>,
    ) -> Option<(DVector<f64>, DMatrix<f64>)> {
        self.law.law().restitution()?;
        let (v, vd) = self.v_t_pair(tau, z.as_slice());
        if v >= 0.0 {
            return None;
        }
        let n = self.modes();
        let k = self.m_eff;
        let mut out = z.clone();
        let mut jac = DMatrix::identity(2 * n, 2 * n);
        let p = self.tip_projector();
        out.rows_mut(0, n).axpy(-k * v, &self.mphi, 1.0);
        jac.view_mut((0, 0), (n, n)).copy_from(&p);
        if vd < 0.0 {
            out.rows_mut(n, n).axpy(-k * vd, &self.mphi, 1.0);
            jac.view_mut((n, n), (n, n)).copy_from(&p);
        }
        Some((out, jac))
    }

    /// P = I − m_eff M⁻¹φ φᵀ, shape `[N, N]`: the least change of the modal coordinates (in the
    /// kinetic metric) that takes out their tip part, φᵀP = 0. The impact law's start on the
    /// surface ([`CantileverModel::start_projection`]) and the thermal force while the tip
    /// sticks (`crate::integrate::exact::noise`) use it.
    pub(crate) fn tip_projector(&self) -> DMatrix<f64> {
        let n = self.modes();
        let mut p = DMatrix::identity(n, n);
        p.ger(-self.m_eff, &self.mphi, self.tip(), 1.0);
        p
    }

    /// The state at rest (a = ȧ = 0).
    pub fn rest(&self) -> DVector<f64> {
        DVector::zeros(self.dim())
    }

    /// Build a state from modal displacements `a` and velocities `a_dot` (each of length N), the
    /// law's internal states at rest (an SLS sample relaxed, u = 0).
    ///
    /// # Errors
    /// [`SimError::StateLength`] / [`SimError::NotFinite`].
    pub(crate) fn state_from(&self, a: &[f64], a_dot: &[f64]) -> Result<DVector<f64>, SimError> {
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
        // the law's internal states at rest (the SLS sample relaxed)
        let mut z = DVector::zeros(self.dim());
        z.rows_mut(0, n).copy_from_slice(a);
        z.rows_mut(n, n).copy_from_slice(a_dot);
        crate::system::check_state("initial state", self.dim(), &z)?;
        Ok(z)
    }

    fn v_t_pair(&self, tau: f64, z: &[f64]) -> (f64, f64) {
        let n = self.modes();
        let [v, vd, _] =
            self.v_t_from_tip(tau, [self.w_tip_slice(z, 0), self.w_tip_slice(z, n), 0.0]);
        (v, vd)
    }
}

mod hybrid;
mod response;
