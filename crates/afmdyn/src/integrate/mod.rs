//! Integrators of the switched model behind one interface, [`Integrator`], which hands out the
//! system it integrates as a [`TipSampleSystem`] ([`Integrator::system`]): the analyses written
//! against `Integrator` never see the cantilever.
//!
//! * [`exact::ExactPropagator`] — exact piecewise-linear propagation (matrix exponential on a
//!   fixed grid aligned with the drive period) with rigorously located switchings. Default. The
//!   cantilever's own: it needs the affine regions of the linear law.
//! * [`rk4::Rk4`] — the paper's fixed-step fourth-order Runge–Kutta, with located switchings
//!   or, as in the paper, with the region chosen per stage from the sign of V_T. Generic over
//!   the [`TipSampleSystem`] (`Rk4<S>`, the cantilever by default).
//! * [`adaptive::Adaptive`] — DOP853 (our allocation-free stepper, `integrate/dop853.rs`) driven step by step,
//!   generic over the [`TipSampleSystem`] (`Adaptive<S>`) and written against
//!   [`crate::system::HybridSystem`]: any contact law, located events with jumps (impacts,
//!   sticking), and the variational equations for step Jacobians. The default for DMT and the
//!   independent oracle of every other integrator; in the exponential frame
//!   ([`adaptive::Adaptive::exponential`], Lawson's transformation, `exact/lawson.rs`; opt-in,
//!   see docs/performance.md for why it is not the default) it integrates only the deviation
//!   from the exact free flight.
//! * [`split::Split`] — the exact free flight, and in contact the Taylor integrator (Hertz) or
//!   the adaptive one (the impact law's sticking): the default for Hertz and impact.
//! * [`taylor::Taylor`] — a high-order Taylor series method, the free flight in τ and the
//!   contact in a regularising time σ (dτ = 2√δ dσ) in which the δ^{3/2} force is a
//!   polynomial: the default for DMT, whose van der Waals force acts in free flight.
//!
//! [`IntegratorKind::Auto`] (the default) chooses the exact propagator for the linear law, the
//! split integrator for Hertz and impact, and the Taylor integrator for DMT
//! ([`IntegratorKind::resolve`]).
//!
//! A driver calls [`Integrator::step`] until the target time; each step ends at a grid point,
//! at `tau_max`, or at an event (switching, impact, sticking, release), which it reports as a
//! [`SwitchEvent`].

pub mod adaptive;
mod dop853;
pub mod exact;
pub mod grid;
pub mod rk4;
pub mod split;
pub mod taylor;

use crate::error::SimError;
use crate::model::{BodyContactCheck, CantileverModel};
use crate::params::SweepParam;
use crate::system::EventKind;
use crate::system::Region;
use crate::tip_sample::TipSampleSystem;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::str::FromStr;

/// A located event: a switching between the free and contact regions, an impact, the start of
/// sticking or a release.
#[derive(Debug, Clone, PartialEq)]
pub struct SwitchEvent {
    /// Time of the event (dimensionless τ).
    pub tau: f64,
    /// Region before.
    pub from: Region,
    /// Region after.
    pub to: Region,
    /// What happened.
    pub kind: EventKind,
    /// dV_T/dτ just before the event (the impact velocity when entering contact).
    pub v_t_dot: f64,
    /// State z⁻ = (a, ȧ) just before the event, shape `[2N]` (the state after it is the
    /// integrator's state).
    pub state: DVector<f64>,
}

impl Step {
    /// A step over [τ₀, τ₁] in `region` that ends without an event (τ₁ = τ₀: no step taken).
    pub fn plain(tau0: f64, tau1: f64, region: Region) -> Step {
        Step {
            tau0,
            tau1,
            region,
            event: None,
        }
    }

    /// A step of `model` in region `from` that ends at a plain switching at (τ_s, z_s).
    pub fn switched<S: TipSampleSystem + ?Sized>(
        model: &S,
        tau0: f64,
        from: Region,
        tau_s: f64,
        z_s: &DVector<f64>,
    ) -> Step {
        Self::with_event(
            model,
            tau0,
            from,
            tau_s,
            z_s,
            from.other(),
            EventKind::Switching,
        )
    }

    /// A step of `model` in region `from` that ends at an event of `kind` at (τ_s, z⁻) into
    /// region `to`.
    pub fn with_event<S: TipSampleSystem + ?Sized>(
        model: &S,
        tau0: f64,
        from: Region,
        tau_s: f64,
        z_minus: &DVector<f64>,
        to: Region,
        kind: EventKind,
    ) -> Step {
        Step {
            tau0,
            tau1: tau_s,
            region: from,
            event: Some(SwitchEvent {
                tau: tau_s,
                from,
                to,
                kind,
                v_t_dot: model.v_t_dot(tau_s, z_minus),
                state: z_minus.clone(),
            }),
        }
    }
}

/// What one call of [`Integrator::step`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// Start time.
    pub tau0: f64,
    /// End time.
    pub tau1: f64,
    /// Region in force during the step.
    pub region: Region,
    /// The switching that ended the step, if any.
    pub event: Option<SwitchEvent>,
}

/// Callback after every step: `(integrator, step, state before the step)`.
pub type StepObserver<'a> =
    dyn FnMut(&mut dyn Integrator, &Step, &DVector<f64>) -> Result<(), SimError> + 'a;

/// A time integrator of a [`TipSampleSystem`] (the cantilever model of the paper, or another).
pub trait Integrator: Send {
    /// The system integrated.
    fn system(&self) -> &dyn TipSampleSystem;
    /// Current time τ.
    fn tau(&self) -> f64;
    /// Current state z = (a, ȧ), shape `[2N]`.
    fn state(&self) -> &DVector<f64>;
    /// Region in force at the current state.
    fn region(&self) -> Region;
    /// Restart from (τ, z); the region is taken from the sign of V_T (eq. 8).
    ///
    /// # Errors
    /// [`SimError`] for a non-finite τ or a state of the wrong length or with non-finite entries.
    fn reset(&mut self, tau: f64, z: &DVector<f64>) -> Result<(), SimError>;
    /// Advance by one step, never past `tau_max` (the exact propagator ends on its grid point
    /// when `tau_max` is within 4 ulps short of it).
    ///
    /// # Errors
    /// [`SimError::Chattering`], [`SimError::Diverged`] or an integrator failure.
    fn step(&mut self, tau_max: f64) -> Result<Step, SimError>;
    /// Tip deflection W(1,τ) and its first two τ-derivatives at `tau` inside the last step.
    fn dense_tip(&mut self, tau: f64) -> [f64; 3];
    /// Full state at `tau` inside the last step, shape `[2N]`.
    fn dense_state(&mut self, tau: f64) -> DVector<f64>;
    /// The states at the sample times τ_i = t0 + i·dt, i = `first`, `first` + 1, …, all inside
    /// the last step, into `out` (one row of 2N values per sample, `out.len()` a multiple of
    /// 2N): [`Integrator::dense_state`] at each (the default). The exact propagator advances its
    /// modal coordinates from one sample to the next (`integrate/exact/sample.rs`).
    fn dense_states_into(&mut self, t0: f64, dt: f64, first: u64, out: &mut [f64]) {
        let dim = self.state().len();
        for (j, row) in out.chunks_exact_mut(dim).enumerate() {
            let tau = t0 + (first + j as u64) as f64 * dt;
            row.copy_from_slice(self.dense_state(tau).as_slice());
        }
    }
    /// [V_T, dV_T/dτ, d²V_T/dτ²] at `tau` inside the last step (from [`Integrator::dense_tip`]).
    fn dense_v_t(&mut self, tau: f64) -> [f64; 3] {
        let w = self.dense_tip(tau);
        self.system().v_t_from_tip(tau, w)
    }
    /// Jacobian ∂z(τ1)/∂z(τ0) of the flow over the last step [τ0, τ1] inside its region,
    /// 2N×2N, without the saltation of an event that ends it.
    ///
    /// # Errors
    /// [`SimError::Unsupported`] for an integrator without step Jacobians (RK4), and for the
    /// adaptive integrator unless [`Integrator::set_variational`] was switched on before the step.
    fn last_step_jacobian(&mut self) -> Result<DMatrix<f64>, SimError>;
    /// [`Integrator::last_step_jacobian`] written into `out` (resized to 2N×2N if needed), so
    /// that a caller multiplying the step Jacobians of many steps allocates nothing per step
    /// where the integrator can avoid it. The default calls
    /// [`Integrator::last_step_jacobian`].
    ///
    /// # Errors
    /// As [`Integrator::last_step_jacobian`].
    fn last_step_jacobian_into(&mut self, out: &mut DMatrix<f64>) -> Result<(), SimError> {
        *out = self.last_step_jacobian()?;
        Ok(())
    }
    /// Whether [`Integrator::region_transition_into`] gives the transition matrix of region `r`
    /// (the default: no).
    fn has_region_transition(&self, r: Region) -> bool {
        let _ = r;
        false
    }
    /// Transition matrix e^{A_r t} = ∂z(τ + t)/∂z(τ) of the flow that stays in region `r` for a
    /// time t ≥ 0, any number of steps long, written into `out` (resized to 2N×2N): for an
    /// affine region ż = A_r z + b_r(τ) it does not depend on τ or z, so the Jacobian of a
    /// whole stint between two events is one matrix instead of the product of its step
    /// Jacobians. `false`, with `out` untouched, where the integrator does not provide it (the
    /// default; the exact propagator provides it for a region with an eigendecomposition,
    /// [`Integrator::has_region_transition`]).
    fn region_transition_into(&self, r: Region, t: f64, out: &mut DMatrix<f64>) -> bool {
        let _ = (r, t, out);
        false
    }
    /// ∂z(τ1)/∂p of the last step [τ0, τ1] inside its region, at fixed z(τ0), τ0 and τ1, written
    /// into `out` (resized to `[2N]`), for a parameter p that enters the forcing only (Ω, α2,
    /// α5; [`CantileverModel::forcing_derivative`]). With the step Jacobians J and the event
    /// shifts of [`crate::system::saltation_with_shift`] it gives the parameter sensitivity of
    /// a flow, s ← J s + this (see [`crate::analysis::monodromy::flow_with_param_derivative`]).
    /// `Ok(false)`, with `out` untouched, where the integrator does not provide it (the default;
    /// the exact propagator provides it for Ω, α2 and α5).
    ///
    /// # Errors
    /// As [`Integrator::last_step_jacobian`].
    fn last_step_param_derivative_into(
        &mut self,
        param: SweepParam,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError> {
        let _ = (param, out);
        Ok(false)
    }
    /// ∂z_p/∂p(τ) of the periodic particular solution z_p of region `r` (eq. 10), written into
    /// `out` (resized to `[2N]`), for a parameter p that enters the forcing only (Ω, α2, α5;
    /// [`CantileverModel::forcing_derivative`]). In a region with a transition matrix
    /// ([`Integrator::has_region_transition`]) the flow is z(τ) = z_p(τ) + e^{A_r t}(z(τ0) −
    /// z_p(τ0)) with A_r independent of p, so over a whole stint the parameter sensitivity
    /// telescopes to s(τ) = e^{A_r t}(s(τ0) − ∂z_p/∂p(τ0)) + ∂z_p/∂p(τ) — one product per stint
    /// instead of one per step ([`crate::analysis::monodromy::flow_with_param_derivative`]).
    /// `Ok(false)`, with `out` untouched, where the integrator does not provide it (the
    /// default; the exact propagator provides it for Ω, α2 and α5).
    ///
    /// # Errors
    /// As [`Integrator::last_step_param_derivative_into`].
    fn region_particular_param_derivative_into(
        &mut self,
        param: SweepParam,
        r: Region,
        tau: f64,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError> {
        let _ = (param, r, tau, out);
        Ok(false)
    }
    /// The integrals over the last step of the energy-balance rates of
    /// [`CantileverModel::power`] — [base work, beam dissipation, sample dissipation] — where the
    /// integrator has them in closed form; `None` (the default) where the caller integrates
    /// them by quadrature of the dense output. The exact propagator has them for whole grid
    /// steps (`integrate/exact/energy.rs`).
    fn last_step_rate_integrals(&mut self) -> Option<[f64; 3]> {
        None
    }
    /// The last step's own smooth time over a piece [a, b] of it: τ(u) and dτ/du for
    /// u ∈ [0, 1], τ(0) = a, τ(1) = b, along a variable in which the solution is smooth, so
    /// that a quadrature over the piece in u converges as for a smooth integrand (∫_a^b f dτ =
    /// ∫_0^1 f(τ(u)) τ′(u) du). The default is τ itself, a + u(b − a); the Taylor
    /// integrator's contact steps are smooth in their regularising time σ (τ − τ_c ∝ σ² at the
    /// contact onset, where the Hertz force ∝ (τ − τ_c)^{3/2} is not smooth in τ).
    fn smooth_time(&mut self, a: f64, b: f64, u: f64) -> (f64, f64) {
        (a + u * (b - a), b - a)
    }
    /// Whether [`Integrator::smooth_time`] is τ itself over the last step (the default; not in
    /// the Taylor integrator's σ steps).
    fn smooth_time_is_tau(&self) -> bool {
        true
    }
    /// Integrate the variational equations along with the state (needed by
    /// [`Integrator::last_step_jacobian`] of the adaptive integrator; free for the exact one).
    fn set_variational(&mut self, on: bool) {
        let _ = on;
    }
    /// Integrator name.
    fn name(&self) -> &'static str;
    /// Steps of an adaptive method taken since the integrator was built, accepted and rejected
    /// (0 for the exact propagator, whose grid steps cost little): the unit of the work budgets
    /// of the analyses that run many flows, such as [`crate::analysis::continuation`].
    fn work(&self) -> u64 {
        0
    }
    /// [W(1,τ), ∂W(1,τ)/∂τ, V_T, dV_T/dτ] at the current state. The default forms them from
    /// [`Integrator::state`] ([`TipSampleSystem::tip_values`], where the equations are); the exact
    /// propagator takes V_T from its switching test and W from its modal coordinates, without
    /// forming the plain state (equal to round-off).
    fn tip_values(&self) -> [f64; 4] {
        self.system().tip_values(self.tau(), self.state())
    }
    /// An upper bound of Σ_j c_j |a_j| at the current state (`weights` c_j ≥ 0, shape `[N]`, a
    /// the modal displacements), for a caller that needs to know whether the sum is below
    /// `enough`: an integrator may return a cheaper, looser bound when it is below `enough`,
    /// and otherwise returns its tightest (pass 0 for the tightest). The default forms the sum
    /// from [`Integrator::state`] ([`crate::model::weighted_displacement`]); the exact
    /// propagator bounds it from its modal coordinates without forming the plain state.
    fn displacement_bound(&mut self, weights: &[f64], enough: f64) -> f64 {
        let _ = enough;
        crate::model::weighted_displacement(weights, self.state().as_slice())
    }
    /// One step as [`Integrator::step`], after which the plain state may lag behind the
    /// integrator's own representation until [`Integrator::form_state`]: [`Integrator::state`]
    /// is then not the current state. The default is `step` (the state always formed). Called
    /// by [`advance_observed`], whose observers see the integrator through [`Observed`], which
    /// forms the state before handing it out.
    ///
    /// # Errors
    /// As [`Integrator::step`].
    fn step_deferred(&mut self, tau_max: f64) -> Result<Step, SimError> {
        self.step(tau_max)
    }
    /// Form the plain state after [`Integrator::step_deferred`] (the default: nothing to do).
    fn form_state(&mut self) {}
    /// One or more of the steps [`Integrator::step_deferred`] takes, reported as one step over
    /// all of them, from the first one's start (a *span*): the span goes on while no step ends
    /// at `tau_max` or at an event, and — given a body-contact check `body` — only while the
    /// integrator shows, without forming the state, that no station of the beam body reaches
    /// the substrate at any time of the span (so that a caller testing
    /// [`BodyContactCheck::touches`] after every step tests the span's end only). After it,
    /// the last step of the dense output, [`Integrator::last_step_rate_integrals`] and
    /// [`Integrator::last_step_jacobian`] is the whole span. The default takes one step; the
    /// exact propagator runs the steps of a stint in one loop (`integrate/exact/span.rs`), so
    /// that a recorder ([`crate::trajectory::record_rows`]) works once per span instead of
    /// once per grid step.
    ///
    /// # Errors
    /// As [`Integrator::step`].
    fn step_span(
        &mut self,
        tau_max: f64,
        body: Option<&BodyContactCheck>,
    ) -> Result<Step, SimError> {
        let _ = body;
        self.step_deferred(tau_max)
    }
    /// Advance to exactly `tau_end` without observing the steps: the same steps and events as
    /// calling [`Integrator::step`] until `tau_end`, but an integrator may keep its state in an
    /// internal representation in between (the exact propagator's modal coordinates).
    ///
    /// # Errors
    /// As [`Integrator::step`].
    fn advance_to(&mut self, tau_end: f64) -> Result<(), SimError> {
        while self.tau() < tau_end {
            self.step(tau_end)?;
        }
        Ok(())
    }
}

/// Advance `integ` to exactly `tau_end` ([`Integrator::advance_to`]); use it instead of
/// [`advance_dyn`] with an observer that does nothing.
///
/// # Errors
/// As [`Integrator::step`]; [`SimError::NotFinite`] for a non-finite `tau_end`.
pub fn advance(integ: &mut dyn Integrator, tau_end: f64) -> Result<(), SimError> {
    crate::error::finite("tau_end", tau_end)?;
    integ.advance_to(tau_end)
}

/// Advance `integ` to exactly `tau_end`, calling `on_step(integ, step, z_before)` after every
/// step.
///
/// # Errors
/// As [`Integrator::step`], or what `on_step` returns.
pub fn advance_dyn(
    integ: &mut dyn Integrator,
    tau_end: f64,
    on_step: &mut StepObserver<'_>,
) -> Result<(), SimError> {
    crate::error::finite("tau_end", tau_end)?;
    let mut before = integ.state().clone();
    while integ.tau() < tau_end {
        before
            .as_mut_slice()
            .copy_from_slice(integ.state().as_slice());
        let step = integ.step(tau_end)?;
        on_step(integ, &step, &before)?;
    }
    Ok(())
}

/// The integrator as an observer of [`advance_observed`] sees it after a step: time, region,
/// the tip values and the displacement bound at the current state (cheap), dense output over
/// the last step, and the plain state, formed on request.
pub struct Observed<'a> {
    integ: &'a mut dyn Integrator,
}

impl<'a> Observed<'a> {
    /// The integrator `integ` as its observers see it.
    pub(crate) fn new(integ: &'a mut dyn Integrator) -> Self {
        Observed { integ }
    }
    /// The system integrated.
    pub fn system(&self) -> &dyn TipSampleSystem {
        self.integ.system()
    }
    /// Current time τ.
    pub fn tau(&self) -> f64 {
        self.integ.tau()
    }
    /// Region in force at the current state.
    pub fn region(&self) -> Region {
        self.integ.region()
    }
    /// [W(1,τ), ∂W(1,τ)/∂τ, V_T, dV_T/dτ] at the current state ([`Integrator::tip_values`]).
    pub fn tip_values(&self) -> [f64; 4] {
        self.integ.tip_values()
    }
    /// An upper bound of Σ_j c_j |a_j| at the current state, possibly a looser one below
    /// `enough` ([`Integrator::displacement_bound`]).
    pub fn displacement_bound(&mut self, weights: &[f64], enough: f64) -> f64 {
        self.integ.displacement_bound(weights, enough)
    }
    /// The current state z = (a, ȧ), shape `[2N]`, formed if it lags behind.
    pub fn state(&mut self) -> &DVector<f64> {
        self.integ.form_state();
        self.integ.state()
    }
    /// [`Integrator::dense_tip`] inside the last step.
    pub fn dense_tip(&mut self, tau: f64) -> [f64; 3] {
        self.integ.dense_tip(tau)
    }
    /// [`Integrator::dense_v_t`] inside the last step.
    pub fn dense_v_t(&mut self, tau: f64) -> [f64; 3] {
        self.integ.dense_v_t(tau)
    }
}

// the body-contact check of an observed step: here, beside `Observed`, so that the model does
// not depend on the integrators
impl BodyContactCheck {
    /// [`BodyContactCheck::touches`] at the state an observer of
    /// [`crate::integrate::advance_observed`] sees, without forming it where the integrator's
    /// bound ([`Observed::displacement_bound`], ≥ Σ_j reach_j |a_j|) already spares the
    /// stations: the same answer as `touches` on the formed state. The bound is held first
    /// against the lowest base 1 − |α2| ≤ α2 sin Ωτ + 1 (less 4 ulp for its rounding), which
    /// needs no sine and spares most steps away from the sample (about 19 of 20 on the
    /// default attractor at N = 10), then against the base at τ.
    pub fn touches_observed(&self, it: &mut Observed<'_>) -> bool {
        let lowest = self.lowest_base() - 4.0 * f64::EPSILON;
        let bound = it.displacement_bound(&self.reach, lowest / (1.0 + 1e-9));
        if Self::spared(bound, lowest) {
            return false;
        }
        let base = self.base(it.tau());
        if Self::spared(
            it.displacement_bound(&self.reach, base / (1.0 + 1e-9)),
            base,
        ) {
            return false;
        }
        let n = self.reach.len();
        self.touches_at(base, &it.state().as_slice()[..n])
    }
}

/// An observer of the steps of [`advance_observed`].
pub trait Observer {
    /// At the start of an [`advance_observed`] call, before its first step (the default does
    /// nothing).
    ///
    /// # Errors
    /// What the observer returns; it ends the run.
    fn start(&mut self, it: &mut Observed<'_>) -> Result<(), SimError> {
        let _ = it;
        Ok(())
    }
    /// After every step; `it` is at the step's end (after the jump of an event that ends it;
    /// the state before the event is the event's).
    ///
    /// # Errors
    /// What the observer returns; it ends the run.
    fn step(&mut self, it: &mut Observed<'_>, step: &Step) -> Result<(), SimError>;
}

/// Advance `integ` to exactly `tau_end`, calling `obs` after every step: the same steps, events
/// and final state as [`advance_dyn`] (bit for bit), but the plain state is formed only where
/// the observer asks for it ([`Observed::state`]) and at the end — the observer sees what the
/// exact propagator has at hand in modal coordinates (tip values, displacement bound, dense
/// output) instead of a state formed after every step ((2N)² work, the cost of the observed
/// path at large N: `docs/performance.md`).
///
/// # Errors
/// As [`Integrator::step`], or what `obs` returns; [`SimError::NotFinite`] for a non-finite
/// `tau_end`. The plain state is formed also when a step or the observer fails.
pub fn advance_observed(
    integ: &mut dyn Integrator,
    tau_end: f64,
    obs: &mut dyn Observer,
) -> Result<(), SimError> {
    crate::error::finite("tau_end", tau_end)?;
    let mut run = || -> Result<(), SimError> {
        obs.start(&mut Observed { integ: &mut *integ })?;
        while integ.tau() < tau_end {
            let step = integ.step_deferred(tau_end)?;
            obs.step(&mut Observed { integ: &mut *integ }, &step)?;
        }
        Ok(())
    };
    let out = run();
    integ.form_state();
    out
}

/// Which integrator to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorKind {
    /// The exact propagator for the linear law, the split integrator for Hertz and impact, the
    /// Taylor integrator for DMT (default; [`IntegratorKind::resolve`]).
    #[default]
    Auto,
    /// Exact piecewise-linear propagation (linear law only).
    Exact,
    /// Fixed-step RK4 with located switchings.
    Rk4,
    /// Fixed-step RK4 choosing the region per stage from sign(V_T), as in the paper.
    Rk4Naive,
    /// Adaptive DOP853 oracle with terminal events.
    Adaptive,
    /// Exact free flight; in contact the Taylor integrator (Hertz) or adaptive DOP853 (the
    /// linear law, the impact law's sticking) ([`split::Split`]; every law but DMT).
    Split,
    /// Adaptive DOP853 of the deviation from the exact free flight (Lawson's exponential frame,
    /// [`adaptive::Adaptive::exponential`]): for DMT, whose van der Waals force acts in free
    /// flight. Opt-in: fewer steps, but its dense output costs an exponential and two sines per
    /// evaluation, so recorded runs are slower (docs/performance.md).
    Exponential,
    /// A Taylor series method of high order ([`taylor::Taylor`]): DMT's free flight in τ, the
    /// Hertz and DMT contact in a regularising time σ (dτ = 2√δ dσ) in which the δ^{3/2} force
    /// is a polynomial; Hertz and DMT only.
    Taylor,
}

impl FromStr for IntegratorKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "auto" => Ok(IntegratorKind::Auto),
            "exact" => Ok(IntegratorKind::Exact),
            "rk4" => Ok(IntegratorKind::Rk4),
            "rk4-naive" | "rk4_naive" => Ok(IntegratorKind::Rk4Naive),
            "adaptive" | "dop853" => Ok(IntegratorKind::Adaptive),
            "split" => Ok(IntegratorKind::Split),
            "exponential" | "lawson" => Ok(IntegratorKind::Exponential),
            "taylor" => Ok(IntegratorKind::Taylor),
            _ => Err(format!(
                "integrator '{s}': expected auto, exact, rk4, rk4-naive, adaptive, split, \
                 exponential or taylor"
            )),
        }
    }
}

/// The range of an integrator tolerance ([`IntegratorOptions::tolerance`]), checked by
/// [`build`] for every integrator, those that ignore it (the exact propagator, RK4) included:
/// below 1e-16 a relative tolerance is beneath a double's resolution (the steps would shrink
/// without end), above 1e-3 it is no longer an accuracy.
pub const TOLERANCE_RANGE: (f64, f64) = (1e-16, 1e-3);

/// Check `tol` against [`TOLERANCE_RANGE`].
///
/// # Errors
/// [`SimError::OutOfRange`] naming `tolerance`.
pub fn check_tolerance(tol: f64) -> Result<(), SimError> {
    if tol.is_finite() && (TOLERANCE_RANGE.0..=TOLERANCE_RANGE.1).contains(&tol) {
        Ok(())
    } else {
        Err(SimError::out_of_range(
            "tolerance",
            crate::error::number(tol),
            "must be in [1e-16, 1e-3] (the integrator's relative and absolute tolerance)",
        ))
    }
}

/// Options shared by the integrators.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntegratorOptions {
    /// Which integrator.
    pub kind: IntegratorKind,
    /// Steps per drive period: a lower bound for `exact` (its grid is refined to resolve the
    /// fastest mode, and made a multiple of this value), the fixed step for `rk4`.
    pub steps_per_period: usize,
    /// Relative and absolute tolerance of the adaptive oracle.
    pub tolerance: f64,
}

impl IntegratorKind {
    /// The concrete integrator for `model`: [`IntegratorKind::Auto`] resolves to `Exact` for an
    /// affine (linear-law) model, to `Split` for a law without force in free flight (Hertz,
    /// impact with r > 0), to `Adaptive` for the plastic impact law r = 0 (whose free flights
    /// all start tangentially) and to `Taylor` for DMT; other kinds are returned as given.
    /// ([`build`] falls back from `Split` to `Adaptive` for `Auto` where the exact free flight
    /// cannot be built: Ω at an undamped resonance of the free beam, or a grid beyond its
    /// budget.)
    pub fn resolve(self, model: &CantileverModel) -> IntegratorKind {
        match self {
            IntegratorKind::Auto if model.law().is_affine() => IntegratorKind::Exact,
            // a plastic impact law (r = 0): every free flight starts tangentially (V̇_T⁺ = 0),
            // which the split integrator hands to the adaptive half anyway
            IntegratorKind::Auto if model.law().restitution() == Some(0.0) => {
                IntegratorKind::Adaptive
            }
            IntegratorKind::Auto if split::Split::applies(model) => IntegratorKind::Split,
            // DMT: its van der Waals force acts in free flight
            IntegratorKind::Auto => IntegratorKind::Taylor,
            k => k,
        }
    }
}

impl Default for IntegratorOptions {
    fn default() -> Self {
        IntegratorOptions {
            kind: IntegratorKind::Auto,
            steps_per_period: 1,
            tolerance: 1e-12,
        }
    }
}

/// Check that an integrator of `opts` can be built for `params` at the rest state — [`build`]'s
/// up-front budgets and support checks (the adaptive stepper's steps per drive period, RK4
/// with impacts, the exact propagator's limits) — without integrating. Studies of many runs
/// (attractor censuses, basin maps, sweeps) call it in their validation, so that a refusal is
/// one input error rather than every run failing alike.
///
/// # Errors
/// As [`CantileverModel::new`] and [`build`].
pub fn check_buildable(params: &crate::Params, opts: IntegratorOptions) -> Result<(), SimError> {
    let model = CantileverModel::new(params)?;
    build(&model, opts, 0.0, &DVector::zeros(2 * params.modes)).map(|_| ())
}

/// [`check_buildable`] at the smallest and the largest of `values` of `param` over `base` (the
/// adaptive step budget grows as Ω falls and as the stiffness grows, so the ends of a sweep
/// bound it).
///
/// # Errors
/// As [`check_buildable`].
pub fn check_buildable_over(
    base: &crate::Params,
    param: SweepParam,
    values: &[f64],
    opts: IntegratorOptions,
) -> Result<(), SimError> {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    for v in [lo, hi] {
        if v.is_finite() {
            check_buildable(&base.with(param, v), opts)?;
        }
    }
    Ok(())
}

/// Build an integrator of `model` starting at (τ, z) ([`IntegratorKind::Auto`] resolved by
/// [`IntegratorKind::resolve`]).
///
/// # Errors
/// [`SimError`] for invalid options (a tolerance outside [`TOLERANCE_RANGE`] whatever the
/// integrator) or initial state; [`SimError::Unsupported`] for the exact
/// propagator with a nonlinear law, or RK4 with the impact law.
pub fn build(
    model: &CantileverModel,
    opts: IntegratorOptions,
    tau: f64,
    z: &DVector<f64>,
) -> Result<Box<dyn Integrator>, SimError> {
    check_steps_per_period(opts.steps_per_period)?;
    check_tolerance(opts.tolerance)?;
    // up-front budgets: a start at or beyond the divergence threshold, and (adaptive) a period
    // that would need more steps than the budget, are refused before any work is done
    check_start(z)?;
    let kind = opts.kind.resolve(model);
    if matches!(
        kind,
        IntegratorKind::Adaptive
            | IntegratorKind::Split
            | IntegratorKind::Exponential
            | IntegratorKind::Taylor
    ) {
        let rate = [Region::Free, Region::Contact]
            .iter()
            .map(|&r| model.dynamics(r).a.norm())
            .fold(0.0, f64::max);
        let steps = rate * model.period();
        if steps.is_nan() || steps > crate::params::ADAPTIVE_STEPS_BUDGET {
            return Err(SimError::Budget {
                what: match kind {
                    IntegratorKind::Taylor => "taylor integrator",
                    IntegratorKind::Split => "split integrator",
                    _ => "adaptive integrator",
                },
                needed: format!("about {steps:.2e} steps per drive period"),
                budget: "1e7".into(),
                hint: "use the exact integrator, or a larger Ω or softer contact",
            });
        }
    }
    if matches!(kind, IntegratorKind::Rk4 | IntegratorKind::Rk4Naive)
        && model.law().restitution().is_some()
    {
        return Err(SimError::Unsupported {
            integrator: "rk4",
            law: model.law().name(),
            hint: "impacts need located events with jumps: use integrator = \"adaptive\" (or \"auto\")",
        });
    }
    let mut integ: Box<dyn Integrator> = match kind {
        IntegratorKind::Auto | IntegratorKind::Exact => Box::new(exact::ExactPropagator::try_new(
            model,
            opts.steps_per_period,
        )?),
        IntegratorKind::Rk4 => Box::new(rk4::Rk4::new(model, opts.steps_per_period, true)),
        IntegratorKind::Rk4Naive => Box::new(rk4::Rk4::new(model, opts.steps_per_period, false)),
        IntegratorKind::Taylor => Box::new(taylor::Taylor::new(model, opts.tolerance)?),
        IntegratorKind::Adaptive | IntegratorKind::Split | IntegratorKind::Exponential => {
            if !(opts.tolerance.is_finite() && opts.tolerance > 0.0 && opts.tolerance < 1.0) {
                return Err(SimError::out_of_range(
                    "tolerance",
                    opts.tolerance,
                    "must be in (0, 1)",
                ));
            }
            let adaptive = || Box::new(adaptive::Adaptive::new(model, opts.tolerance));
            if kind == IntegratorKind::Adaptive {
                adaptive()
            } else if kind == IntegratorKind::Exponential {
                // the frame's field is the law's force F_c(δ, δ̇) on the velocity rows: not the
                // impact law's sticking constraint
                let unsupported = |hint| SimError::Unsupported {
                    integrator: "exponential",
                    law: model.law().name(),
                    hint,
                };
                if model.law().restitution().is_some() {
                    return Err(unsupported(
                        "impacts need the jump map of the adaptive or split integrator: use \
                         integrator = \"auto\"",
                    ));
                }
                if model.law().is_affine() {
                    return Err(unsupported(
                        "the linear law is propagated exactly: use integrator = \"exact\" (or \
                         \"auto\")",
                    ));
                }
                match adaptive::Adaptive::exponential(model, opts.tolerance)? {
                    Some(e) => Box::new(e),
                    None => {
                        return Err(unsupported(
                            "the free flight has no well-conditioned modal basis here: use \
                             integrator = \"adaptive\" (or \"auto\")",
                        ))
                    }
                }
            } else {
                match split::Split::try_new(model, opts.steps_per_period, opts.tolerance) {
                    Ok(s) => Box::new(s),
                    Err(SimError::OutOfRange { .. } | SimError::Budget { .. })
                        if opts.kind == IntegratorKind::Auto =>
                    {
                        adaptive()
                    }
                    Err(e) => return Err(e),
                }
            }
        }
    };
    integ.reset(tau, z)?;
    Ok(integ)
}

/// Refuse a start at or beyond the divergence threshold of the integrators (|z| ≥ 1e12,
/// [`crate::params::STATE_NORM_MAX`]), as [`build`] does before any work.
///
/// # Errors
/// [`SimError::OutOfRange`] naming the initial state.
pub fn check_start(z: &DVector<f64>) -> Result<(), SimError> {
    let norm = z.norm(); // +∞ when the squares overflow; NaN entries are rejected by reset
    if z.iter().all(|v| v.is_finite()) && norm >= crate::params::STATE_NORM_MAX {
        return Err(SimError::out_of_range(
            "initial state",
            if norm.is_finite() {
                format!("|z| = {norm:e}")
            } else {
                "|z| > 1e154".to_string()
            },
            "must be < 1e12 (the divergence threshold of the integrators)",
        ));
    }
    Ok(())
}

fn check_steps_per_period(steps: usize) -> Result<(), SimError> {
    if steps == 0 || steps > 10_000_000 {
        return Err(SimError::out_of_range(
            "steps_per_period",
            steps,
            "must be in 1..=10000000",
        ));
    }
    Ok(())
}

/// The chattering test of an integrator: `count` events within `window` of the latest one are
/// reported as [`SimError::Chattering`] (an accumulation of switchings or impacts that the event
/// loop would otherwise follow forever).
#[derive(Debug, Clone)]
pub(crate) struct ChatterWindow {
    count: usize,
    window: f64,
    recent: std::collections::VecDeque<f64>,
}

impl ChatterWindow {
    /// `count` events within a time `window`.
    pub(crate) fn new(count: usize, window: f64) -> Self {
        ChatterWindow {
            count,
            window,
            recent: std::collections::VecDeque::with_capacity(count + 1),
        }
    }

    /// Record an event at `tau`.
    ///
    /// # Errors
    /// [`SimError::Chattering`] when it is the `count`-th within the window.
    pub(crate) fn record(&mut self, tau: f64) -> Result<(), SimError> {
        // an event earlier than the last one belongs to a new run (a restart back in time):
        // the window counts the events of one run only
        if self.recent.back().is_some_and(|&t| tau < t) {
            self.recent.clear();
        }
        self.recent.push_back(tau);
        while self.recent.len() > self.count {
            self.recent.pop_front();
        }
        if self.recent.len() == self.count {
            let window = tau - self.recent[0];
            if window < self.window {
                return Err(SimError::Chattering {
                    tau,
                    count: self.count,
                    window,
                });
            }
        }
        Ok(())
    }

    /// Forget the recorded events (a new start).
    pub(crate) fn clear(&mut self) {
        self.recent.clear();
    }
}

/// The steps of an integrator that chooses its own steps (adaptive DOP853, Taylor): the work
/// since construction ([`Integrator::work`]) and the budget of one drive period
/// ([`crate::params::ADAPTIVE_STEPS_PER_PERIOD`] steps within ⌊τ/T⌋, accepted and rejected).
/// Interior mutability, so that the `&self` step loops can count.
#[derive(Debug, Clone)]
pub(crate) struct StepBudget {
    what: &'static str,
    period: f64,
    /// The drive period counted and the steps taken in it.
    current: std::cell::Cell<(i64, usize)>,
    work: std::cell::Cell<u64>,
}

impl StepBudget {
    /// A budget of the integrator named `what` (in its error) over drive periods of `period`.
    pub(crate) fn new(what: &'static str, period: f64) -> Self {
        StepBudget {
            what,
            period,
            current: std::cell::Cell::new((i64::MIN, 0)),
            work: std::cell::Cell::new(0),
        }
    }

    /// Count one step taken at `tau`.
    ///
    /// # Errors
    /// [`SimError::Budget`] beyond [`crate::params::ADAPTIVE_STEPS_PER_PERIOD`] steps in one
    /// drive period.
    pub(crate) fn count(&self, tau: f64) -> Result<(), SimError> {
        let k = (tau / self.period).floor() as i64;
        self.work.set(self.work.get() + 1);
        let (at, n) = self.current.get();
        let n = if at == k { n + 1 } else { 1 };
        self.current.set((k, n));
        let cap = crate::params::ADAPTIVE_STEPS_PER_PERIOD;
        if n > cap {
            let cap = cap as f64;
            return Err(SimError::Budget {
                what: self.what,
                needed: format!(
                    "more than {cap:e} steps within the drive period from τ = {:.6e}",
                    k as f64 * self.period
                ),
                budget: format!("{cap:e} steps per drive period"),
                hint: "the tip–sample force grew too stiff to resolve where the motion went: \
                       soften the law (contact_stiffness, hamaker), check the gap (alpha5), \
                       or use a larger Ω",
            });
        }
        Ok(())
    }

    /// Forget the count of the current drive period (a new run).
    pub(crate) fn forget(&self) {
        self.current.set((i64::MIN, 0));
    }

    /// Steps taken since construction.
    pub(crate) fn work(&self) -> u64 {
        self.work.get()
    }
}

/// End points of the last step of a Runge–Kutta integrator, for Hermite dense output:
/// (τ0, z0, ż0) and (τ1, z1, ż1).
#[derive(Debug, Clone)]
pub(crate) struct HermiteStep {
    t0: f64,
    z0: DVector<f64>,
    f0: DVector<f64>,
    t1: f64,
    z1: DVector<f64>,
    f1: DVector<f64>,
}

impl HermiteStep {
    pub(crate) fn new(dim: usize) -> Self {
        let z = DVector::zeros(dim);
        HermiteStep {
            t0: 0.0,
            z0: z.clone(),
            f0: z.clone(),
            t1: 0.0,
            z1: z.clone(),
            f1: z,
        }
    }

    /// Record a step of `model` in region `r` from (t0, z0) to (t1, z1).
    pub(crate) fn record<S: TipSampleSystem + ?Sized>(
        &mut self,
        model: &S,
        r: Region,
        t0: f64,
        z0: &DVector<f64>,
        t1: f64,
        z1: &DVector<f64>,
    ) {
        self.t0 = t0;
        self.z0.copy_from(z0);
        model.rhs(r, t0, z0.as_slice(), self.f0.as_mut_slice());
        self.t1 = t1;
        self.z1.copy_from(z1);
        model.rhs(r, t1, z1.as_slice(), self.f1.as_mut_slice());
    }

    /// [W, W', W''] of the tip at τ.
    pub(crate) fn tip<S: TipSampleSystem + ?Sized>(&self, model: &S, tau: f64) -> [f64; 3] {
        let n = model.modes();
        let tip = model.tip();
        let w0 = [tip.dot(&self.z0.rows(0, n)), tip.dot(&self.f0.rows(0, n))];
        let w1 = [tip.dot(&self.z1.rows(0, n)), tip.dot(&self.f1.rows(0, n))];
        hermite_tip(self.t0, w0, self.t1, w1, tau)
    }

    /// Full state at τ.
    pub(crate) fn state(&self, tau: f64) -> DVector<f64> {
        DVector::from_iterator(
            self.z0.len(),
            (0..self.z0.len()).map(|i| {
                hermite_tip(
                    self.t0,
                    [self.z0[i], self.f0[i]],
                    self.t1,
                    [self.z1[i], self.f1[i]],
                    tau,
                )[0]
            }),
        )
    }
}

/// Cubic Hermite interpolation of the tip deflection inside a step from its end values
/// (W, W') — the dense output of the Runge–Kutta integrators. Returns [W, W', W''] at `tau`.
pub(crate) fn hermite_tip(t0: f64, w0: [f64; 2], t1: f64, w1: [f64; 2], tau: f64) -> [f64; 3] {
    let h = t1 - t0;
    if h <= 0.0 {
        return [w1[0], w1[1], 0.0];
    }
    let s = (tau - t0) / h;
    let (p0, m0, p1, m1) = (w0[0], w0[1] * h, w1[0], w1[1] * h);
    let h00 = 2.0 * s.powi(3) - 3.0 * s * s + 1.0;
    let h10 = s.powi(3) - 2.0 * s * s + s;
    let h01 = -2.0 * s.powi(3) + 3.0 * s * s;
    let h11 = s.powi(3) - s * s;
    let d00 = 6.0 * s * s - 6.0 * s;
    let d10 = 3.0 * s * s - 4.0 * s + 1.0;
    let d01 = -6.0 * s * s + 6.0 * s;
    let d11 = 3.0 * s * s - 2.0 * s;
    let e00 = 12.0 * s - 6.0;
    let e10 = 6.0 * s - 4.0;
    let e01 = -12.0 * s + 6.0;
    let e11 = 6.0 * s - 2.0;
    [
        h00 * p0 + h10 * m0 + h01 * p1 + h11 * m1,
        (d00 * p0 + d10 * m0 + d01 * p1 + d11 * m1) / h,
        (e00 * p0 + e10 * m0 + e01 * p1 + e11 * m1) / (h * h),
    ]
}
