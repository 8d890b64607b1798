//! The split integrator: exact propagation of the free flight, the adaptive integrator only in
//! contact — for the laws that exert no force outside contact (linear, Hertz, JKR, capillary,
//! impact).
//!
//! While V_T > 0 the Hertz and impact laws, like the linear one, exert no force, so the free
//! flight is region I of eq. 10, ż = A_I z + b_I(τ), and [`ExactPropagator`] propagates it
//! exactly, with its certified switching test (a grazing dip between grid points is not
//! missed) and its located switchings. At the switching into contact the split integrator
//! applies the law's event: a plain switching into the law's contact flow (Hertz, linear),
//! or the impact map (Newton's restitution, ending in sticking when the bounce would not rise;
//! [`crate::model`]). The contact flow is integrated until it ends in a switching or release,
//! where the exact free flight takes over again: the Hertz force α4 δ^{3/2} + α6 δ̇ by the
//! Taylor integrator ([`Taylor`], in the regularising time of the contact, where the force is a
//! polynomial), the linear law's, JKR's (left at the neck's break, V_T = |δ_f|) and the
//! capillary meniscus's contact (left where it ruptures, V_T = D̃_r) and
//! the impact law's sticking by [`Adaptive`] (DOP853 with events and the variational
//! equations).
//!
//! Both halves share the free flight's dead band (the model's guard tolerance), so the split
//! integrator leaves free flight where the adaptive integrator alone would; it is its oracle
//! in the tests. Step Jacobians: the exact transition e^{A_I t} over free steps (and over whole
//! free stints, [`AffineRegions::region_transition_into`]), the variational equations in contact;
//! the saltation at the events is the analyses' ([`crate::system::saltation`]). DMT is not
//! split: its van der Waals force acts in free flight.

use super::adaptive::Adaptive;
use super::exact::ExactPropagator;
use super::taylor::Taylor;
use super::{AffineRegions, ChatterWindow, Integrator, SmoothTime, Spans, Step};
use crate::error::SimError;
use crate::model::CantileverModel;
use crate::params::SweepParam;
use crate::system::{EventKind, HybridSystem, Region};
use crate::tip_sample::TipSampleSystem;
use nalgebra::{DMatrix, DVector};

/// Events within this many drive periods' ten-millionth that count as chattering (the
/// adaptive integrator's test, over the events of both halves).
const CHATTER_COUNT: usize = 4096;

/// Which half of the split integrator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Half {
    /// The exact propagator (free flight).
    Exact,
    /// The contact integrator (contact, sticking).
    Adaptive,
}

/// The integrator of the contact half: Taylor for the Hertz law, adaptive DOP853 for the others
/// (the linear law's contact, the impact law's sticking and its tangential free flights).
#[derive(Debug, Clone)]
enum ContactHalf {
    Adaptive(Box<Adaptive>),
    Taylor(Box<Taylor>),
}

impl ContactHalf {
    fn new(model: &CantileverModel, tol: f64) -> Result<Self, SimError> {
        // a law with a piece of the Taylor jet (Hertz: DMT's force acts in free flight, where
        // the split does not apply)
        let p = model.params();
        Ok(if model.law().jet(p.alpha4, p.alpha6).is_some() {
            ContactHalf::Taylor(Box::new(Taylor::new(model, tol)?))
        } else {
            ContactHalf::Adaptive(Box::new(Adaptive::new(model, tol)))
        })
    }
    fn integ(&self) -> &dyn Integrator {
        match self {
            ContactHalf::Adaptive(a) => a.as_ref(),
            ContactHalf::Taylor(t) => t.as_ref(),
        }
    }
    fn integ_mut(&mut self) -> &mut dyn Integrator {
        match self {
            ContactHalf::Adaptive(a) => a.as_mut(),
            ContactHalf::Taylor(t) => t.as_mut(),
        }
    }
    fn restart_in(&mut self, tau: f64, z: &[f64], region: Region) {
        match self {
            ContactHalf::Adaptive(a) => a.restart_in(tau, z, region),
            ContactHalf::Taylor(t) => t.restart_in(tau, z, region),
        }
    }
    fn forget_events(&mut self) {
        match self {
            ContactHalf::Adaptive(a) => a.forget_events(),
            ContactHalf::Taylor(t) => t.forget_events(),
        }
    }
}

/// Exact free flight and adaptive contact (see the module docs).
#[derive(Debug, Clone)]
pub struct Split {
    model: CantileverModel,
    exact: ExactPropagator,
    adaptive: ContactHalf,
    /// The half at the current state.
    active: Half,
    /// The half that made the last step (its dense output and Jacobian).
    last: Half,
    chatter: ChatterWindow,
}

impl Split {
    /// The split integrator of `model`: the exact free flight on a grid with a multiple of
    /// `min_steps_per_period` sub-steps per period, the adaptive integrator with tolerance
    /// `tol` in contact, the free flight built through `cache` (the exact propagator's
    /// [`crate::integrate::PropagatorCache`]; `None`: computed afresh). Start with
    /// [`Integrator::reset`].
    ///
    /// # Errors
    /// [`SimError::Unsupported`] for the DMT law (a force in free flight);
    /// [`SimError::OutOfRange`] for Ω at an undamped resonance of the free beam and
    /// [`SimError::Budget`] for a free-flight grid beyond its budget (as
    /// [`ExactPropagator::try_new`]).
    pub(crate) fn try_new(
        model: &CantileverModel,
        min_steps_per_period: usize,
        tol: f64,
        cache: Option<crate::integrate::PropagatorCache>,
    ) -> Result<Self, SimError> {
        if !Self::applies(model) {
            return Err(SimError::Unsupported {
                integrator: "split",
                law: model.law().name(),
                hint:
                    "the DMT law acts in free flight: use integrator = \"adaptive\" (or \"auto\")",
            });
        }
        Ok(Split {
            model: model.clone(),
            exact: ExactPropagator::free_flight(model, min_steps_per_period, cache)?,
            adaptive: ContactHalf::new(model, tol)?,
            active: Half::Exact,
            last: Half::Exact,
            chatter: ChatterWindow::new(CHATTER_COUNT, 1e-7 * model.period()),
        })
    }

    /// Whether `model`'s law exerts no force in free flight (linear, Hertz, impact; not DMT or
    /// the electrostatic law).
    pub(crate) fn applies(model: &CantileverModel) -> bool {
        model.law().internal_states() == 0 && !model.law().acts_outside()
    }

    fn integ(&self, h: Half) -> &dyn Integrator {
        match h {
            Half::Exact => &self.exact,
            Half::Adaptive => self.adaptive.integ(),
        }
    }

    fn integ_mut(&mut self, h: Half) -> &mut dyn Integrator {
        match h {
            Half::Exact => &mut self.exact,
            Half::Adaptive => self.adaptive.integ_mut(),
        }
    }

    /// Start the half for `region` at (τ, z) after an event of `kind` at τ (the last step is
    /// kept). Free flight is exact, except after a plastic impact (V̇_T⁺ = 0) or a release from
    /// sticking: the tip leaves the sample tangentially (g = g′ = 0), which the exact
    /// propagator's no-re-trigger rule (g′ > 0 after a switching) does not cover; the adaptive
    /// integrator scans for the first rise there ([`Adaptive`]'s event search) and flies to the
    /// next event.
    fn hand_over(&mut self, tau: f64, z: &[f64], region: Region, kind: EventKind) {
        let tangential = match kind {
            EventKind::Release => true,
            EventKind::Impact => self.model.v_t_dot(tau, &DVector::from_column_slice(z)) <= 0.0,
            EventKind::Switching | EventKind::Stick => false,
        };
        if region == Region::Free && !tangential {
            self.exact.restart_in(tau, z, Region::Free, true);
            self.active = Half::Exact;
        } else if self.active == Half::Adaptive {
            // the adaptive half's own event: it is in `region` at (τ, z) already
            debug_assert_eq!(self.adaptive.integ().region(), region);
        } else {
            self.adaptive.restart_in(tau, z, region);
            self.active = Half::Adaptive;
        }
    }

    /// One step of the active half ([`Integrator::step`], or with `deferred`
    /// [`Integrator::step_deferred`]: the exact half's plain state may then lag behind).
    fn step_with(&mut self, tau_max: f64, deferred: bool) -> Result<Step, SimError> {
        match self.active {
            Half::Exact => {
                let s = if deferred {
                    self.exact.step_deferred(tau_max)?
                } else {
                    self.exact.step(tau_max)?
                };
                self.after_exact(s)
            }
            Half::Adaptive => {
                let s = self.adaptive.integ_mut().step(tau_max)?;
                self.after_adaptive(s)
            }
        }
    }

    /// After a step of the exact half: at its switching into contact, the law's event (module
    /// docs) and the hand-over; the step as the model sees it.
    fn after_exact(&mut self, mut step: Step) -> Result<Step, SimError> {
        self.last = Half::Exact;
        let Some(e) = step.event.as_mut() else {
            return Ok(step);
        };
        let tau = e.tau;
        self.chatter.record(tau)?;
        if self.model.law().restitution().is_some() {
            let jump = self.model.jump(Region::Free, tau, e.state.as_slice());
            e.to = jump.to;
            e.kind = jump.kind;
            self.hand_over(tau, jump.state.as_slice(), jump.to, jump.kind);
        } else {
            let z = e.state.clone();
            self.hand_over(tau, z.as_slice(), Region::Contact, EventKind::Switching);
        }
        Ok(step)
    }

    /// After a step of the adaptive half: at an event that ends contact, the hand-over to the
    /// exact free flight.
    fn after_adaptive(&mut self, step: Step) -> Result<Step, SimError> {
        self.last = Half::Adaptive;
        if let Some(e) = &step.event {
            self.chatter.record(e.tau)?;
            if self.adaptive.integ().region() == Region::Free {
                let z = self.adaptive.integ().state().clone();
                self.hand_over(e.tau, z.as_slice(), Region::Free, e.kind);
            }
        }
        Ok(step)
    }
}

impl Integrator for Split {
    fn system(&self) -> &dyn TipSampleSystem {
        &self.model
    }
    fn tau(&self) -> f64 {
        self.integ(self.active).tau()
    }
    fn state(&self) -> &DVector<f64> {
        self.integ(self.active).state()
    }
    fn region(&self) -> Region {
        match self.active {
            Half::Exact => Region::Free,
            Half::Adaptive => self.adaptive.integ().region(),
        }
    }
    fn name(&self) -> &'static str {
        "split"
    }
    fn work(&self) -> u64 {
        self.adaptive.integ().work()
    }
    fn set_variational(&mut self, on: bool) {
        self.adaptive.integ_mut().set_variational(on);
    }

    fn reset_in(&mut self, tau: f64, z: &DVector<f64>, region: Region) -> Result<(), SimError> {
        self.model.check_time_state(tau, z)?;
        self.chatter.clear();
        // a new run: neither half counts the events of the last one (a chattering window
        // holding events of an earlier run, later in τ, would see a negative time span)
        self.adaptive.forget_events();
        match region {
            Region::Free => {
                self.exact
                    .restart_in(tau, z.as_slice(), Region::Free, false);
                self.active = Half::Exact;
            }
            Region::Contact => {
                self.adaptive.integ_mut().reset_in(tau, z, region)?;
                self.active = Half::Adaptive;
            }
        }
        self.last = self.active;
        Ok(())
    }

    fn step(&mut self, tau_max: f64) -> Result<Step, SimError> {
        self.step_with(tau_max, false)
    }

    fn dense_tip(&mut self, tau: f64) -> [f64; 3] {
        self.integ_mut(self.last).dense_tip(tau)
    }

    fn dense_v_t(&mut self, tau: f64) -> [f64; 3] {
        self.integ_mut(self.last).dense_v_t(tau)
    }

    fn dense_state(&mut self, tau: f64) -> DVector<f64> {
        self.integ_mut(self.last).dense_state(tau)
    }

    fn dense_state_into(&mut self, tau: f64, out: &mut [f64]) {
        self.integ_mut(self.last).dense_state_into(tau, out);
    }

    fn dense_state_at(&mut self, tau: f64, sc: (f64, f64), out: &mut [f64]) {
        self.integ_mut(self.last).dense_state_at(tau, sc, out);
    }

    /// The exact half's closed form over its whole grid steps of free flight (where the
    /// model's rates are those of the linear law's region I: no tip force), the Taylor
    /// contact's from its series.
    fn last_step_rate_integrals(&mut self) -> Option<[f64; 3]> {
        match self.last {
            Half::Exact => self.exact.last_step_rate_integrals(),
            Half::Adaptive => self.adaptive.integ_mut().last_step_rate_integrals(),
        }
    }

    fn last_step_jacobian(&mut self) -> Result<DMatrix<f64>, SimError> {
        self.integ_mut(self.last).last_step_jacobian()
    }

    fn last_step_jacobian_into(&mut self, out: &mut DMatrix<f64>) -> Result<(), SimError> {
        self.integ_mut(self.last).last_step_jacobian_into(out)
    }

    fn smooth_time(&mut self) -> Option<&mut dyn SmoothTime> {
        self.integ_mut(self.last).smooth_time()
    }

    fn affine(&mut self) -> Option<&mut dyn AffineRegions> {
        Some(self)
    }

    fn spans(&mut self) -> Option<&mut dyn Spans> {
        Some(self)
    }
}

impl Spans for Split {
    fn step_deferred(&mut self, tau_max: f64) -> Result<Step, SimError> {
        self.step_with(tau_max, true)
    }
    fn form_state(&mut self) {
        if self.active == Half::Exact {
            self.exact.form_state();
        }
    }
    /// The exact half's free flight in its fast loop ([`ExactPropagator`]'s certified grid
    /// runs) until its switching, the adaptive half step by step.
    fn advance_to(&mut self, tau_end: f64) -> Result<(), SimError> {
        let mut run = || -> Result<(), SimError> {
            while self.tau() < tau_end {
                match self.active {
                    Half::Exact => {
                        if let Some(s) = self.exact.run_to_switching(tau_end)? {
                            self.after_exact(s)?;
                        }
                        self.last = Half::Exact;
                    }
                    Half::Adaptive => {
                        let s = self.adaptive.integ_mut().step(tau_end)?;
                        self.after_adaptive(s)?;
                    }
                }
            }
            Ok(())
        };
        let out = run();
        self.form_state();
        out
    }
    fn tip_values(&self) -> [f64; 4] {
        match self.active {
            Half::Exact => self.exact.tip_values(),
            Half::Adaptive => self.model.tip_values(self.tau(), self.state()),
        }
    }
    fn displacement_bound(&mut self, weights: &[f64], enough: f64) -> f64 {
        match self.active {
            Half::Exact => self.exact.displacement_bound(weights, enough),
            Half::Adaptive => crate::model::weighted_displacement(weights, self.state().as_slice()),
        }
    }
}

/// The exact half's affine free flight; the per-step parameter derivative of whichever half
/// took the last step.
impl AffineRegions for Split {
    fn has_region_transition(&self, r: Region) -> bool {
        r == Region::Free && self.exact.has_region_transition(Region::Free)
    }
    fn region_transition_into(&self, r: Region, t: f64, out: &mut DMatrix<f64>) -> bool {
        r == Region::Free && self.exact.region_transition_into(Region::Free, t, out)
    }
    fn last_step_param_derivative_into(
        &mut self,
        param: SweepParam,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError> {
        match self.integ_mut(self.last).affine() {
            Some(a) => a.last_step_param_derivative_into(param, out),
            None => Ok(false),
        }
    }
    fn region_particular_param_derivative_into(
        &mut self,
        param: SweepParam,
        r: Region,
        tau: f64,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError> {
        if r != Region::Free {
            return Ok(false);
        }
        self.exact
            .region_particular_param_derivative_into(param, r, tau, out)
    }
}
