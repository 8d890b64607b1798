//! Spans of steps ([`Spans::step_span`]): in a modal region the steps of a stint up to the
//! next event (or the caller's limit) in one run — the certified whole grid steps by
//! `grid_run`, the others by `step_impl`, as [`Spans::advance_to`] takes them, so the same
//! steps, events and states bit for bit — and then the span as the last step.
//!
//! **The span as the last step.** Along a stint the homogeneous part is δz(τ0 + t) =
//! T⁻¹V e^{Λt} q(τ0) for any t ≥ 0 (eq. 10 in modal coordinates, `modal.rs`; accurate at any t,
//! Re λ_k ≤ 0 and the basis well conditioned), so the span's start q(τ0) is all the dense
//! output needs: the dense state, the samples of `sample.rs` and the closed-form energy
//! integrals of `energy.rs` (the modal form, for a step of any length) cover the whole span,
//! and its transition matrix is e^{A t} (`sensitivity.rs`). The tip series, whose Taylor
//! expansion converges over about a grid step (‖Ã h‖ ≤ θ), is built around the time asked for
//! instead (`series.rs`, `poly_for_last`). The values at the span's end are those of its last
//! step; the dense output at a time inside the span agrees with that of the step it lies in to
//! round-off (`tests/exact_paths.rs`, `spans_are_the_steps_of_step_deferred`).
//!
//! **The body-contact guard.** Given a body-contact check, every step of the span must end
//! where `bound.rs`'s `StepGuard` shows without the plain state that every station is off the
//! substrate — the displacement bound of [`Spans::displacement_bound`] against the base at
//! the step's grid point, from a table per grid point and the homogeneous part's bound at the
//! span's start (O(1) a step; |q_k| does not grow along a stint), else at the current q — the
//! test by which `touches_observed` spares a step's end; the span ends after the first step it
//! does not spare, whose end the caller then checks. The span is at most the window of the
//! start's bound long (a period, at most 10⁵ grid steps: the rounding of the products can grow
//! a computed |q_k| by a few ulp a step, which the bound's widening by 1e-10 covers).
//!
//! [`Spans::displacement_bound`]: crate::integrate::Spans::displacement_bound
//!
//! [`Spans::step_span`]: crate::integrate::Spans::step_span
//! [`Spans::advance_to`]: crate::integrate::Spans::advance_to

use super::step::Form;
use super::ExactPropagator;
use crate::error::SimError;
use crate::integrate::Step;
use crate::model::BodyContactCheck;

impl ExactPropagator {
    /// [`crate::integrate::Integrator::step_span`] (module docs).
    pub(super) fn step_span_impl(
        &mut self,
        tau_max: f64,
        body: Option<&BodyContactCheck>,
    ) -> Result<Step, SimError> {
        let ri = self.region.index();
        let r = match &self.spec[ri].modal {
            Some(me) if self.modal[ri] && self.tau < tau_max => me.len(),
            _ => return self.step_impl(tau_max, Form::Events),
        };
        // the body-contact guard and how far its bound holds
        let (guard, until) = match body.map(|b| self.prepare_guard(b)) {
            None => (None, f64::INFINITY),
            Some(Some((stint, window))) => (Some(stint), self.tau + window),
            Some(None) => return self.step_impl(tau_max, Form::Events),
        };
        let (tau0, region) = (self.tau, self.region);
        self.span_q0.copy_prefix(&self.q, r);
        // sin, cos Ωτ0 from the grid's table or the switching the stint started at
        let trig0 = match self.on_grid {
            Some((_, k)) => self.trig[k],
            None => self.trig_at(tau0),
        };
        self.span_guard = guard;
        self.guard_stopped = false;
        let ran = self.run_span(tau_max, until);
        self.span_guard = None;
        let step = ran?;
        let event = step.and_then(|s| s.event);
        // more than one step: the span is the last step, with its ends (module docs)
        if self.last.tau0 != tau0 {
            std::mem::swap(&mut self.last.q0, &mut self.span_q0);
            if event.is_some() {
                // the end in the region left: kept by the switching step
                std::mem::swap(&mut self.last.q1, &mut self.q_switch);
            } else {
                self.last.q1.copy_prefix(&self.q, r);
            }
            self.last.trig0 = trig0;
            // after a switching τ is the entry time of the stint, with its sin and cos
            self.last.trig1 = self.trig_now();
            self.last.tau0 = tau0;
            self.last.region = region;
            self.last.modal = true;
            self.last.full = false;
            self.last.span = true;
            self.last.k = 0;
            self.poly_built = false;
        }
        Ok(Step {
            tau0,
            tau1: self.tau,
            region,
            event,
        })
    }

    /// The steps of a stint towards `tau_end` until the first that ends at an event: the
    /// certified whole grid steps in one loop (`grid_run`), the others by `step_impl`, as
    /// [`crate::integrate::Integrator::advance_to`] takes them; without a step that would end
    /// beyond `until` (≥ the next grid point after τ; ∞: no such limit). Returns the step that
    /// ended at an event (with its event record and the plain state formed), or `None` (the
    /// plain state may lag behind: `form_state`).
    ///
    /// # Errors
    /// As [`crate::integrate::Integrator::step`].
    pub(super) fn run_span(&mut self, tau_end: f64, until: f64) -> Result<Option<Step>, SimError> {
        while self.tau < tau_end {
            self.grid_run(tau_end.min(until))?;
            if self.tau >= tau_end
                || self.guard_stopped
                || (until < tau_end && self.grid.next(self.tau) > until)
            {
                break;
            }
            let step = self.step_impl(tau_end, Form::Events)?;
            if step.event.is_some() {
                return Ok(Some(step));
            }
            // the guard at the step's end (on the grid, unless the run ends here anyway)
            if let (Some(stint), Some((_, k))) = (self.span_guard, self.on_grid) {
                if !self.guard_spares(stint, k) {
                    self.guard_stopped = true;
                    break;
                }
            }
        }
        Ok(None)
    }
}
