//! Integrators of the switched model behind one interface, [`Integrator`], which hands out the
//! system it integrates as a [`TipSampleSystem`] ([`Integrator::system`]): the analyses written
//! against `Integrator` never see the cantilever.
//!
//! * [`exact::ExactPropagator`] — exact piecewise-linear propagation (matrix exponential on a
//!   fixed grid aligned with the drive period) with rigorously located switchings: the default
//!   for the linear law. The cantilever's own: it needs the affine regions of the linear law.
//! * [`rk4::Rk4`] — the paper's fixed-step fourth-order Runge–Kutta, with located switchings
//!   or, as in the paper, with the region chosen per stage from the sign of V_T. Generic over
//!   the [`TipSampleSystem`] (`Rk4<S>`, the cantilever by default).
//! * [`adaptive::Adaptive`] — DOP853 (our allocation-free stepper, `integrate/dop853.rs`) driven step by step,
//!   generic over the [`TipSampleSystem`] (`Adaptive<S>`) and written against
//!   [`crate::system::HybridSystem`]: any contact law, located events with jumps (impacts,
//!   sticking), and the variational equations for step Jacobians. The default for the plastic
//!   impact law (r = 0) and where the split integrator's exact free flight cannot be built,
//!   and the independent oracle of every other integrator.
//! * [`split::Split`] — the exact free flight, and in contact the Taylor integrator (Hertz) or
//!   the adaptive one (the impact law's sticking): the default for Hertz and for impact with
//!   r > 0.
//! * [`taylor::Taylor`] — a high-order Taylor series method, the free flight in τ and the
//!   contact in a regularising time σ (dτ = 2√δ dσ) in which the δ^{3/2} force is a
//!   polynomial: the default for DMT, whose van der Waals force acts in free flight.
//!
//! [`IntegratorKind::Auto`] (the default) chooses the exact propagator for the linear law, the
//! split integrator for Hertz and for impact with r > 0, the adaptive one for the plastic
//! impact law r = 0, and the Taylor integrator for DMT ([`IntegratorKind::resolve`]; [`build`]
//! falls back from split to adaptive where the exact free flight cannot be built). The factory
//! ([`build`], [`IntegratorKind`], [`IntegratorOptions`]) is in `integrate/factory.rs`, the
//! pieces the implementations share in `integrate/support.rs`.
//!
//! A driver calls [`Integrator::step`] until the target time; each step ends at a grid point,
//! at `tau_max`, or at an event (switching, impact, sticking, release), which it reports as a
//! [`SwitchEvent`].

/// The accessors [`Integrator::system`], [`Integrator::tau`], [`Integrator::state`] and
/// [`Integrator::region`] of an integrator that keeps them in its fields `model`, `tau`, `z` and
/// `region`.
macro_rules! current_fields {
    () => {
        fn system(&self) -> &dyn TipSampleSystem {
            &self.model
        }
        fn tau(&self) -> f64 {
            self.tau
        }
        fn state(&self) -> &DVector<f64> {
            &self.z
        }
        fn region(&self) -> Region {
            self.region
        }
    };
}

/// What the adaptive and the Taylor integrators share beyond `current_fields!`: the name, the
/// step budget's work (field `budget`), the switch of the variational equations (field
/// `variational`), the reset (their `restart_in` and `forget_events`), and the last step's
/// Jacobian (field `last.jacobian`, there only with the variational equations switched on).
macro_rules! variational_fields {
    ($name:literal) => {
        fn name(&self) -> &'static str {
            $name
        }
        fn work(&self) -> u64 {
            self.budget.work()
        }
        fn set_variational(&mut self, on: bool) {
            self.variational = on;
        }
        fn reset_in(&mut self, tau: f64, z: &DVector<f64>, region: Region) -> Result<(), SimError> {
            self.model.check_time_state(tau, z)?;
            self.restart_in(tau, z.as_slice(), region);
            self.forget_events();
            Ok(())
        }
        fn last_step_jacobian(&mut self) -> Result<DMatrix<f64>, SimError> {
            self.last.jacobian.clone().ok_or(SimError::Unsupported {
                integrator: $name,
                law: self.model.law_name(),
                hint: "switch on the variational equations (Integrator::set_variational) first",
            })
        }
        fn last_step_jacobian_into(&mut self, out: &mut DMatrix<f64>) -> Result<(), SimError> {
            match &self.last.jacobian {
                Some(j) => {
                    if out.shape() != j.shape() {
                        *out = j.clone();
                    } else {
                        out.copy_from(j);
                    }
                    Ok(())
                }
                None => self.last_step_jacobian().map(|_| ()),
            }
        }
    };
}

pub mod adaptive;
pub(crate) mod dense;
mod dop853;
pub mod exact;
mod factory;
pub mod grid;
pub mod rk4;
pub mod split;
mod support;
pub mod taylor;

pub use exact::PropagatorCache;
pub(crate) use factory::steps_per_period;
pub use factory::{
    build, check_buildable, check_buildable_over, check_start, check_tolerance, IntegratorKind,
    IntegratorOptions, TOLERANCE_RANGE,
};
pub(crate) use support::{ChatterWindow, HermiteStep, StepBudget};

use crate::error::SimError;
use crate::model::BodyContactCheck;
use crate::params::SweepParam;
use crate::system::EventKind;
use crate::system::Region;
use crate::tip_sample::TipSampleSystem;
use nalgebra::{DMatrix, DVector};

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
    pub(crate) fn plain(tau0: f64, tau1: f64, region: Region) -> Step {
        Step {
            tau0,
            tau1,
            region,
            event: None,
        }
    }

    /// A step of `model` in region `from` that ends at a plain switching at (τ_s, z_s).
    pub(crate) fn switched<S: TipSampleSystem + ?Sized>(
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
    pub(crate) fn with_event<S: TipSampleSystem + ?Sized>(
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
pub(crate) type StepObserver<'a> =
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
    /// Restart from (τ, z) ([`TipSampleSystem::checked_start`]: projected first where the
    /// system does so, in the region [`crate::system::HybridSystem::mode_at`] gives, the sign
    /// of V_T (eq. 8) but in a hysteretic law's band). An adaptive integrator keeps its last step
    /// size as the first guess (a warm start), so its replay of a flow agrees to round-off
    /// rather than bit for bit; a fixed-step one replays exactly.
    ///
    /// # Errors
    /// [`SimError`] for a non-finite τ or a state of the wrong length or with non-finite entries.
    fn reset(&mut self, tau: f64, z: &DVector<f64>) -> Result<(), SimError> {
        let (region, z) = self.system().checked_start(tau, z)?;
        self.reset_in(tau, &z, region)
    }
    /// Restart from (τ, z) in `region` as given, not projected: a run's own region where the
    /// state alone does not tell it (a hysteretic law's neck or meniscus,
    /// [`TipSampleSystem::is_hysteretic`]), as a flow continued in parts needs it.
    ///
    /// # Errors
    /// As [`Integrator::reset`].
    fn reset_in(&mut self, tau: f64, z: &DVector<f64>, region: Region) -> Result<(), SimError>;
    /// Advance by one step, never past `tau_max` (the exact propagators end on their grid point
    /// when `tau_max` is a few ulps short of it: 4 for the deterministic one; the stochastic
    /// step within 1e-9 of its step or 8 ulps).
    ///
    /// # Errors
    /// [`SimError::Chattering`], [`SimError::Diverged`] or an integrator failure.
    fn step(&mut self, tau_max: f64) -> Result<Step, SimError>;
    /// Tip deflection W(1,τ) and its first two τ-derivatives at `tau` inside the last step.
    fn dense_tip(&mut self, tau: f64) -> [f64; 3];
    /// Full state at `tau` inside the last step, shape `[2N]`.
    fn dense_state(&mut self, tau: f64) -> DVector<f64>;
    /// [`Integrator::dense_state`] written into `out` (shape `[2N]`, the state's length), bit
    /// for bit: the default copies it; the Taylor, exact and adaptive integrators allocate
    /// nothing (the lock-in's 32 samples per drive period, `dense::sample_dense`; the nodes
    /// of the observables' quadrature).
    fn dense_state_into(&mut self, tau: f64, out: &mut [f64]) {
        out.copy_from_slice(self.dense_state(tau).as_slice());
    }
    /// [`Integrator::dense_state_into`] given `sc` = (sin Ωτ, cos Ωτ) at `tau`, which the
    /// caller holds, bit for bit: the default ignores it; the exact propagator's forced part
    /// takes it instead of its own where its step's local time gives τ back exactly.
    fn dense_state_at(&mut self, tau: f64, sc: (f64, f64), out: &mut [f64]) {
        let _ = sc;
        self.dense_state_into(tau, out);
    }
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
    /// The integrals over the last step of the energy-balance rates of
    /// `crate::model::CantileverModel::power` — [base work, beam dissipation, sample
    /// dissipation] — where the integrator has them in closed form; `None` (the default) where
    /// the caller integrates them by quadrature of the dense output. The exact propagator has
    /// them for whole grid steps (`integrate/exact/energy.rs`), the Taylor integrator from its
    /// series.
    fn last_step_rate_integrals(&mut self) -> Option<[f64; 3]> {
        None
    }
    /// Integrate the variational equations along with the state (needed by
    /// [`Integrator::last_step_jacobian`] of the adaptive integrator; free for the exact one).
    fn set_variational(&mut self, on: bool) {
        let _ = on;
    }
    /// Move the sample to the gap α5 = `alpha5` in place, everything else of the model kept (a
    /// scan's piezo between drive periods, `crate::analysis::am_loop::scan_line`), so that
    /// after [`Integrator::reset`] the integrator steps as one built by
    /// [`crate::integrate::build`] for the changed model, bit for bit
    /// (`crate::model::CantileverModel::set_gap`). `false` (the default, and for an α5 the
    /// model refuses) where it cannot: the caller then builds an integrator of the changed
    /// model. The Taylor integrator can.
    fn set_gap(&mut self, alpha5: f64) -> bool {
        let _ = alpha5;
        false
    }
    /// Integrator name.
    fn name(&self) -> &'static str;
    /// Steps of an adaptive method taken since the integrator was built, accepted and rejected
    /// (0 for the exact propagator, whose grid steps cost little): the unit of the work budgets
    /// of the analyses that run many flows, such as [`crate::analysis::continuation`].
    fn work(&self) -> u64 {
        0
    }
    /// The affine regions' transition matrices and parameter derivatives, where the integrator
    /// has them ([`AffineRegions`]: the exact propagator, the split integrator's free flight);
    /// `None` (the default) otherwise.
    fn affine(&mut self) -> Option<&mut dyn AffineRegions> {
        None
    }
    /// Steps whose plain state is formed on demand, and spans of them ([`Spans`]: the exact
    /// propagator's modal coordinates, the split integrator); `None` (the default) where every
    /// step forms its state ([`Integrator::step`] is then the only way to step).
    fn spans(&mut self) -> Option<&mut dyn Spans> {
        None
    }
    /// The last step's own smooth time ([`SmoothTime`]) where it is not τ itself (the Taylor
    /// integrator's contact steps in their regularising time σ); `None` (the default) where
    /// τ is the step's smooth time.
    fn smooth_time(&mut self) -> Option<&mut dyn SmoothTime> {
        None
    }
}

/// The capability of an integrator of affine regions ż = A_r z + b_r(τ) ([`Integrator::affine`]):
/// the transition matrix of a whole stint in a region, and the derivatives of a step and of a
/// region's particular solution with respect to a parameter that enters the forcing only.
pub trait AffineRegions {
    /// Whether [`AffineRegions::region_transition_into`] gives the transition matrix of region
    /// `r`.
    fn has_region_transition(&self, r: Region) -> bool;
    /// Transition matrix e^{A_r t} = ∂z(τ + t)/∂z(τ) of the flow that stays in region `r` for a
    /// time t ≥ 0, any number of steps long, written into `out` (resized to 2N×2N): for an
    /// affine region ż = A_r z + b_r(τ) it does not depend on τ or z, so the Jacobian of a
    /// whole stint between two events is one matrix instead of the product of its step
    /// Jacobians. `false`, with `out` untouched, where the integrator does not provide it for
    /// `r` (the exact propagator provides it for a region with an eigendecomposition,
    /// [`AffineRegions::has_region_transition`]).
    fn region_transition_into(&self, r: Region, t: f64, out: &mut DMatrix<f64>) -> bool;
    /// ∂z(τ1)/∂p of the last step [τ0, τ1] inside its region, at fixed z(τ0), τ0 and τ1, written
    /// into `out` (resized to `[2N]`), for a parameter p that enters the forcing only (Ω, α2,
    /// α5; `crate::model::CantileverModel::forcing_derivative`). With the step Jacobians J
    /// and the event shifts of `crate::system::saltation_with_shift` it gives the parameter
    /// sensitivity of a flow, s ← J s + this (see
    /// `crate::maps::flow::flow`). `Ok(false)`, with `out`
    /// untouched, where the integrator does not provide it for this step or parameter (the
    /// exact propagator provides it for Ω, α2 and α5).
    ///
    /// # Errors
    /// As [`Integrator::last_step_jacobian`].
    fn last_step_param_derivative_into(
        &mut self,
        param: SweepParam,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError>;
    /// ∂z_p/∂p(τ) of the periodic particular solution z_p of region `r` (eq. 10), written into
    /// `out` (resized to `[2N]`), for a parameter p that enters the forcing only (Ω, α2, α5;
    /// `crate::model::CantileverModel::forcing_derivative`). In a region with a transition
    /// matrix ([`AffineRegions::has_region_transition`]) the flow is z(τ) = z_p(τ) +
    /// e^{A_r t}(z(τ0) − z_p(τ0)) with A_r independent of p, so over a whole stint the
    /// parameter sensitivity telescopes to s(τ) = e^{A_r t}(s(τ0) − ∂z_p/∂p(τ0)) + ∂z_p/∂p(τ)
    /// — one product per stint instead of one per step
    /// (`crate::maps::flow::flow`). `Ok(false)`, with `out`
    /// untouched, where the integrator does not provide it (the exact propagator provides it
    /// for Ω, α2 and α5).
    ///
    /// # Errors
    /// As [`AffineRegions::last_step_param_derivative_into`].
    fn region_particular_param_derivative_into(
        &mut self,
        param: SweepParam,
        r: Region,
        tau: f64,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError>;
}

/// The capability of an integrator that keeps its state in its own representation between
/// steps ([`Integrator::spans`]; the exact propagator's modal coordinates): steps after which
/// the plain state is formed on demand, spans of several steps, an unobserved advance, and the
/// tip values and a displacement bound without the plain state. Bit for bit the steps, events
/// and states of [`Integrator::step`]; a measured optimisation of the observed and recorded
/// runs at large N (docs/performance.md).
pub trait Spans {
    /// One step as [`Integrator::step`], after which the plain state may lag behind the
    /// integrator's own representation until [`Spans::form_state`]: [`Integrator::state`] is
    /// then not the current state. Called by [`advance_observed`], whose observers see the
    /// integrator through [`Observed`], which forms the state before handing it out.
    ///
    /// # Errors
    /// As [`Integrator::step`].
    fn step_deferred(&mut self, tau_max: f64) -> Result<Step, SimError>;
    /// Form the plain state after [`Spans::step_deferred`].
    fn form_state(&mut self);
    /// One or more of the steps [`Spans::step_deferred`] takes, reported as one step over all
    /// of them, from the first one's start (a *span*): the span goes on while no step ends at
    /// `tau_max` or at an event, and — given a body-contact check `body` — only while the
    /// integrator shows, without forming the state, that no station of the beam body reaches
    /// the substrate at any time of the span (so that a caller testing
    /// `BodyContactCheck::touches` after every step tests the span's end only). After it,
    /// the last step of the dense output, [`Integrator::last_step_rate_integrals`] and
    /// [`Integrator::last_step_jacobian`] is the whole span. The default takes one step; the
    /// exact propagator runs the steps of a stint in one loop (`integrate/exact/span.rs`), so
    /// that a recorder (`crate::trajectory::record_rows`) works once per span instead of
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
    /// calling [`Integrator::step`] until `tau_end`, the state kept in the integrator's own
    /// representation in between and formed at the end.
    ///
    /// # Errors
    /// As [`Integrator::step`].
    fn advance_to(&mut self, tau_end: f64) -> Result<(), SimError>;
    /// [W(1,τ), ∂W(1,τ)/∂τ, V_T, dV_T/dτ] at the current state, without forming the plain
    /// state (equal to round-off to [`TipSampleSystem::tip_values`] of the formed state; the
    /// exact propagator takes V_T from its switching test and W from its modal coordinates).
    fn tip_values(&self) -> [f64; 4];
    /// An upper bound of Σ_j c_j |a_j| at the current state (`weights` c_j ≥ 0, shape `[N]`, a
    /// the modal displacements), for a caller that needs to know whether the sum is below
    /// `enough`: a cheaper, looser bound when it is below `enough`, and otherwise the tightest
    /// (pass 0 for the tightest), without forming the plain state.
    fn displacement_bound(&mut self, weights: &[f64], enough: f64) -> f64;
}

/// The capability of an integrator whose last step is smooth in another time than τ
/// ([`Integrator::smooth_time`]; the Taylor integrator's contact steps in their regularising
/// time σ, τ − τ_c ∝ σ² at the contact onset, where the Hertz force ∝ (τ − τ_c)^{3/2} is not
/// smooth in τ).
pub trait SmoothTime {
    /// The last step's own smooth time over a piece [a, b] of it: τ(u) and dτ/du for
    /// u ∈ [0, 1], τ(0) = a, τ(1) = b, so that a quadrature over the piece in u converges as
    /// for a smooth integrand (∫_a^b f dτ = ∫_0^1 f(τ(u)) τ′(u) du).
    fn tau_of(&mut self, a: f64, b: f64, u: f64) -> (f64, f64);
}

/// The last step's smooth time over a piece [a, b] of it ([`SmoothTime::tau_of`]), τ itself,
/// a + u(b − a), where the integrator has no other ([`Integrator::smooth_time`]).
pub(crate) fn smooth_time(integ: &mut dyn Integrator, a: f64, b: f64, u: f64) -> (f64, f64) {
    match integ.smooth_time() {
        Some(s) => s.tau_of(a, b, u),
        None => (a + u * (b - a), b - a),
    }
}

/// One step, or a span of steps where the integrator has them ([`Spans::step_span`]; otherwise
/// [`Integrator::step`]).
///
/// # Errors
/// As [`Integrator::step`].
pub(crate) fn step_span(
    integ: &mut dyn Integrator,
    tau_max: f64,
    body: Option<&BodyContactCheck>,
) -> Result<Step, SimError> {
    match integ.spans() {
        Some(s) => s.step_span(tau_max, body),
        None => integ.step(tau_max),
    }
}

/// Form the plain state after [`Spans::step_deferred`] or [`step_span`] (nothing to do for an
/// integrator without [`Spans`]).
pub(crate) fn form_state(integ: &mut dyn Integrator) {
    if let Some(s) = integ.spans() {
        s.form_state();
    }
}

/// [`Spans::tip_values`] where the integrator has spans, else [`TipSampleSystem::tip_values`]
/// of its state.
pub(crate) fn tip_values(integ: &mut dyn Integrator) -> [f64; 4] {
    match integ.spans() {
        Some(s) => s.tip_values(),
        None => integ.system().tip_values(integ.tau(), integ.state()),
    }
}

/// Advance `integ` to exactly `tau_end` ([`Spans::advance_to`] where the integrator has spans,
/// else [`Integrator::step`] until there); use it instead of
/// [`advance_dyn`] with an observer that does nothing.
///
/// # Errors
/// As [`Integrator::step`]; [`SimError::NotFinite`] for a non-finite `tau_end`.
pub fn advance(integ: &mut dyn Integrator, tau_end: f64) -> Result<(), SimError> {
    crate::error::finite("tau_end", tau_end)?;
    crate::error::cancelled()?;
    if let Some(s) = integ.spans() {
        return s.advance_to(tau_end);
    }
    while integ.tau() < tau_end {
        integ.step(tau_end)?;
        crate::error::cancelled()?;
    }
    Ok(())
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
        crate::error::cancelled()?;
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
    pub(crate) fn system(&self) -> &dyn TipSampleSystem {
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
    /// [W(1,τ), ∂W(1,τ)/∂τ, V_T, dV_T/dτ] at the current state (`tip_values`).
    pub(crate) fn tip_values(&mut self) -> [f64; 4] {
        tip_values(self.integ)
    }
    /// An upper bound of Σ_j c_j |a_j| at the current state, possibly a looser one below
    /// `enough` ([`Spans::displacement_bound`] where the integrator has spans, else the sum
    /// formed from the state, [`crate::model::weighted_displacement`]).
    pub(crate) fn displacement_bound(&mut self, weights: &[f64], enough: f64) -> f64 {
        match self.integ.spans() {
            Some(s) => s.displacement_bound(weights, enough),
            None => crate::model::weighted_displacement(weights, self.integ.state().as_slice()),
        }
    }
    /// The current state z = (a, ȧ), shape `[2N]`, formed if it lags behind.
    pub fn state(&mut self) -> &DVector<f64> {
        form_state(self.integ);
        self.integ.state()
    }
    /// [`Integrator::dense_tip`] inside the last step.
    pub(crate) fn dense_tip(&mut self, tau: f64) -> [f64; 3] {
        self.integ.dense_tip(tau)
    }
    /// [`Integrator::dense_v_t`] inside the last step.
    pub(crate) fn dense_v_t(&mut self, tau: f64) -> [f64; 3] {
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
    pub(crate) fn touches_observed(&self, it: &mut Observed<'_>) -> bool {
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
            let step = match integ.spans() {
                Some(s) => s.step_deferred(tau_end)?,
                None => integ.step(tau_end)?,
            };
            obs.step(&mut Observed { integ: &mut *integ }, &step)?;
            crate::error::cancelled()?;
        }
        Ok(())
    };
    let out = run();
    form_state(integ);
    out
}
