//! The tip–sample system: what the integrators and the analyses need of a probe over a sample,
//! beyond the [`HybridSystem`] interface.
//!
//! A [`TipSampleSystem`] is a periodically forced hybrid system whose state `z: [f64; 2N]` is
//! (a, ȧ), N modal coordinates and their τ-derivatives, with a tip deflection
//! W(1,τ) = φᵀa (`φ` = [`TipSampleSystem::tip`], shape `[N]`) and a switching function V_T
//! formed from it (eq. 8 of the paper: V_T = W(1,τ) + α2 sin Ωτ + α5 for the cantilever); the
//! regions are those of [`Region`] (free while V_T > 0, eq. 10). Every integrator
//! ([`crate::integrate::Integrator::system`]) and every analysis written against
//! [`crate::integrate::Integrator`] (steady state, monodromy with saltation, shooting,
//! continuation, Lyapunov exponents) sees the system through this trait only.
//! [`CantileverModel`] is the system of the paper; `tests/tip_sample.rs` runs the generic
//! integrators and analyses on a second one (a forced oscillator against a rigid wall) and
//! checks them against its closed forms.
//!
//! What the steady-state searches need beyond the flow is asked of the trait by purpose: the
//! slowest free decay rate for their transient caps ([`TipSampleSystem::free_decay_rate`]) and
//! the check that the probe's body touches the sample
//! ([`TipSampleSystem::body_contact_check`]); a system without them gets the floors and no
//! check. The two analyses that need the cantilever's Galerkin structure itself — the AFM
//! observables (energy balance, virial over the modes, SI scales) and the recorded trajectory
//! with its energy quadrature — ask for it with `require_cantilever` and refuse another
//! system with [`SimError::NotCantilever`].

use crate::eigen::damped_eigenvalues;
use crate::error::SimError;
use crate::model::{BodyContactCheck, CantileverModel};
use crate::params::SweepParam;
use crate::system::{HybridSystem, Region};
use nalgebra::{DMatrix, DVector};

/// A [`HybridSystem`] of a driven probe tip over a sample, in modal coordinates
/// `z: [f64; 2N]` = (a, ȧ) (see the module docs).
pub trait TipSampleSystem: HybridSystem {
    /// Number of modal coordinates N (the state has 2N entries).
    fn modes(&self) -> usize {
        self.dim() / 2
    }
    /// Drive frequency Ω (dimensionless, of the drive α2 sin Ωτ); the period is 2π/Ω.
    fn omega(&self) -> f64;
    /// Tip row φ, shape `[N]`: W(1,τ) = φᵀa.
    fn tip(&self) -> &DVector<f64>;
    /// [V_T, dV_T/dτ, d²V_T/dτ²] at τ from [W(1,τ), W', W''] (eq. 8 and its derivatives for
    /// the cantilever).
    fn v_t_from_tip(&self, tau: f64, w: [f64; 3]) -> [f64; 3];
    /// [W(1,τ), ∂W(1,τ)/∂τ, V_T, dV_T/dτ] at (τ, z).
    fn tip_values(&self, tau: f64, z: &DVector<f64>) -> [f64; 4];
    /// V_T at (τ, z).
    fn v_t(&self, tau: f64, z: &DVector<f64>) -> f64 {
        self.tip_values(tau, z)[2]
    }
    /// dV_T/dτ at (τ, z).
    fn v_t_dot(&self, tau: f64, z: &DVector<f64>) -> f64 {
        self.tip_values(tau, z)[3]
    }
    /// Region by the sign of V_T: contact when V_T ≤ 0 (eq. 10).
    fn region_at(&self, tau: f64, z: &DVector<f64>) -> Region {
        Region::of_v_t(self.v_t(tau, z))
    }
    /// Check a state: length 2N, finite entries, ‖z‖ below the integrators' divergence
    /// threshold `crate::params::STATE_NORM_MAX` (`crate::system::check_state`).
    ///
    /// # Errors
    /// [`SimError::StateLength`], [`SimError::NotFinite`] or [`SimError::OutOfRange`], naming
    /// `name`.
    fn check_state(&self, name: &'static str, z: &DVector<f64>) -> Result<(), SimError> {
        crate::system::check_state(name, self.dim(), z)
    }
    /// A start (τ, z) the system moves to before integrating, with its Jacobian (2N×2N), or
    /// `None` to start at z (the default). The cantilever with the impact law brings a start
    /// inside the rigid sample to its surface (`CantileverModel::start_projection`).
    fn start_projection(&self, tau: f64, z: &DVector<f64>) -> Option<(DVector<f64>, DMatrix<f64>)> {
        let _ = (tau, z);
        None
    }
    /// Check a start (τ, z): a finite τ, then [`TipSampleSystem::check_state`].
    ///
    /// # Errors
    /// [`SimError::NotFinite`], [`SimError::StateLength`] or [`SimError::OutOfRange`].
    fn check_time_state(&self, tau: f64, z: &DVector<f64>) -> Result<(), SimError> {
        crate::error::finite("initial time", tau)?;
        self.check_state("initial state", z)
    }
    /// Check a start (τ, z) and return its region and the state to start from:
    /// [`TipSampleSystem::check_state`], a finite τ, then
    /// [`TipSampleSystem::start_projection`] and [`HybridSystem::mode_at`].
    ///
    /// # Errors
    /// [`SimError::NotFinite`], [`SimError::StateLength`] or [`SimError::OutOfRange`].
    fn checked_start(
        &self,
        tau: f64,
        z: &DVector<f64>,
    ) -> Result<(Region, DVector<f64>), SimError> {
        self.check_time_state(tau, z)?;
        let z = match self.start_projection(tau, z) {
            Some((projected, _)) => projected,
            None => z.clone(),
        };
        Ok((self.mode_at(tau, z.as_slice()), z))
    }
    /// ∂g/∂p of the guard of `mode` at fixed (τ, z) for a parameter p of the forcing (Ω, α2,
    /// α5), or `None` where the system does not provide it (the default): the parameter
    /// sensitivity of a flow then is not available
    /// (`crate::maps::flow::flow`).
    fn guard_param_derivative(&self, mode: Region, param: SweepParam, tau: f64) -> Option<f64> {
        let _ = (mode, param, tau);
        None
    }
    /// Name of the tip–sample law ("linear", "hertz", "dmt", "impact", or the system's own).
    fn law_name(&self) -> &'static str;
    /// Whether the region of a state depends on its history as well (a hysteretic law: JKR's
    /// neck, `crate::contact::ContactLaw::release_distance`), so that [`HybridSystem::mode_at`]
    /// decides a start in the band by a rule and a periodic orbit must be checked to end in the
    /// region it starts in ([`crate::analysis::shooting`]). `false` (the default) for a system
    /// whose region follows from the state.
    fn is_hysteretic(&self) -> bool {
        false
    }
    /// The slowest decay rate of free motion, min |Re λ| over the damped eigenvalues λ of the
    /// free region (eqs. 20–21 for the cantilever), per unit τ: what the derived transient caps
    /// of the steady-state searches scale with
    /// (`crate::analysis::steady::decay_periods`). `None` (the default) for a system
    /// without one; the caps then take their floors.
    fn free_decay_rate(&self) -> Option<f64> {
        None
    }
    /// The check that the probe's body (beam stations away from the tip, sampled at `points`
    /// stations) touches the sample; `None` (the default) for a system without a body.
    fn body_contact_check(&self, points: usize) -> Option<BodyContactCheck> {
        let _ = points;
        None
    }
    /// The cantilever model, for the analyses that need its Galerkin structure (see the module
    /// docs); `None` for another system (the default).
    fn cantilever(&self) -> Option<&CantileverModel> {
        None
    }
}

/// The cantilever of an analysis that needs its Galerkin structure.
///
/// # Errors
/// [`SimError::NotCantilever`] naming `analysis` for a system that is not a
/// [`CantileverModel`].
pub(crate) fn require_cantilever<'a>(
    system: &'a dyn TipSampleSystem,
    analysis: &'static str,
) -> Result<&'a CantileverModel, SimError> {
    system
        .cantilever()
        .ok_or(SimError::NotCantilever { analysis })
}

/// The paper's system (eqs. 8–18): every method is the model's own.
impl TipSampleSystem for CantileverModel {
    fn modes(&self) -> usize {
        CantileverModel::modes(self)
    }
    fn omega(&self) -> f64 {
        CantileverModel::omega(self)
    }
    fn tip(&self) -> &DVector<f64> {
        CantileverModel::tip(self)
    }
    fn v_t_from_tip(&self, tau: f64, w: [f64; 3]) -> [f64; 3] {
        CantileverModel::v_t_from_tip(self, tau, w)
    }
    fn tip_values(&self, tau: f64, z: &DVector<f64>) -> [f64; 4] {
        CantileverModel::tip_values(self, tau, z)
    }
    fn v_t(&self, tau: f64, z: &DVector<f64>) -> f64 {
        CantileverModel::v_t(self, tau, z)
    }
    fn v_t_dot(&self, tau: f64, z: &DVector<f64>) -> f64 {
        CantileverModel::v_t_dot(self, tau, z)
    }
    fn region_at(&self, tau: f64, z: &DVector<f64>) -> Region {
        CantileverModel::region_at(self, tau, z)
    }
    fn start_projection(&self, tau: f64, z: &DVector<f64>) -> Option<(DVector<f64>, DMatrix<f64>)> {
        CantileverModel::start_projection(self, tau, z)
    }
    fn guard_param_derivative(&self, mode: Region, param: SweepParam, tau: f64) -> Option<f64> {
        CantileverModel::guard_param_derivative(self, mode, param, tau)
    }
    fn law_name(&self) -> &'static str {
        self.law().name()
    }
    fn is_hysteretic(&self) -> bool {
        self.release_distance() > 0.0
    }
    fn free_decay_rate(&self) -> Option<f64> {
        // the SLS surface's recovery, α4κ/(α6(α4 + κ)), is a free decay too
        let surface = self
            .zener()
            .map(|zn| zn.relaxation_rate() * (1.0 - zn.surface_gain()));
        damped_eigenvalues(self.galerkin().region(Region::Free))
            .iter()
            .map(|e| e.re.abs())
            .chain(surface)
            .reduce(f64::min)
    }
    fn body_contact_check(&self, points: usize) -> Option<BodyContactCheck> {
        Some(BodyContactCheck::new(self, points))
    }
    fn cantilever(&self) -> Option<&CantileverModel> {
        Some(self)
    }
}
