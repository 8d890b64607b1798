//! [`Integrator`], [`Spans`] and [`AffineRegions`] for [`ExactPropagator`].

use super::forcing::modal_tip;
use super::step::Form;
use super::ExactPropagator;
use crate::error::SimError;
use crate::integrate::{AffineRegions, Integrator, Spans, Step};
use crate::model::BodyContactCheck;
use crate::params::SweepParam;
use crate::system::Region;
use crate::tip_sample::TipSampleSystem;
use nalgebra::{DMatrix, DVector};

impl Integrator for ExactPropagator {
    current_fields!();
    fn name(&self) -> &'static str {
        "exact"
    }

    fn reset_in(&mut self, tau: f64, z: &DVector<f64>, region: Region) -> Result<(), SimError> {
        self.model.check_time_state(tau, z)?;
        self.restart_in(tau, z.as_slice(), region, false);
        Ok(())
    }

    fn step(&mut self, tau_max: f64) -> Result<Step, SimError> {
        self.step_impl(tau_max, Form::All)
    }

    fn dense_tip(&mut self, tau: f64) -> [f64; 3] {
        self.poly_for_last(tau - self.last.tau0);
        self.poly.w(tau - self.poly.tau0)
    }

    /// From the tip series of the last step, whose coefficients include the harmonic part of
    /// V_T (eq. 8): no sine per call, unlike the default through [`Integrator::dense_tip`].
    fn dense_v_t(&mut self, tau: f64) -> [f64; 3] {
        self.poly_for_last(tau - self.last.tau0);
        self.poly.v_t(tau - self.poly.tau0)
    }

    fn dense_state(&mut self, tau: f64) -> DVector<f64> {
        let mut out = DVector::zeros(self.z.len());
        self.dense_state_into(tau, out.as_mut_slice());
        out
    }

    fn dense_state_into(&mut self, tau: f64, out: &mut [f64]) {
        self.state_in_last(tau - self.last.tau0, out);
    }

    fn dense_state_at(&mut self, tau: f64, sc: (f64, f64), out: &mut [f64]) {
        let t = tau - self.last.tau0;
        // `state_in_last` takes sin, cos of Ω(τ0 + t): the caller's where that is τ
        if self.last.tau0 + t == tau {
            self.state_in_last_at(t, sc, out);
        } else {
            self.state_in_last(t, out);
        }
    }

    // the sample sequence and its accuracy: `sample.rs`
    fn dense_states_into(&mut self, t0: f64, dt: f64, first: u64, out: &mut [f64]) {
        self.dense_states_impl(t0, dt, first, out);
    }

    // the tables and their derivation: `energy.rs`
    fn last_step_rate_integrals(&mut self) -> Option<[f64; 3]> {
        self.last_step_rate_integrals_impl()
    }

    fn last_step_jacobian(&mut self) -> Result<DMatrix<f64>, SimError> {
        Ok(self.step_transition())
    }

    fn last_step_jacobian_into(&mut self, out: &mut DMatrix<f64>) -> Result<(), SimError> {
        self.step_transition_into(out);
        Ok(())
    }

    fn affine(&mut self) -> Option<&mut dyn AffineRegions> {
        Some(self)
    }

    fn spans(&mut self) -> Option<&mut dyn Spans> {
        Some(self)
    }
}

impl Spans for ExactPropagator {
    fn step_deferred(&mut self, tau_max: f64) -> Result<Step, SimError> {
        self.step_impl(tau_max, Form::Events)
    }
    fn form_state(&mut self) {
        self.materialize();
    }
    // spans and what they change: `span.rs`
    fn step_span(
        &mut self,
        tau_max: f64,
        body: Option<&BodyContactCheck>,
    ) -> Result<Step, SimError> {
        self.step_span_impl(tau_max, body)
    }
    /// V_T and dV_T/dτ of the switching test at the end of the last step; W and ∂W/∂τ from the
    /// plain state, or, while it lags behind, from the modal coordinates: Σ_k Re(w_k c̃ᵀv_k q_k)
    /// (and with λ_k; as the last step returned them, else `ModalExp::tip_of`) plus the
    /// particular part (`modal_tip`).
    fn tip_values(&self) -> [f64; 4] {
        let (v, vd) = self.vt;
        let ri = self.region.index();
        let (w, wd) = match (&self.spec[ri].modal, self.stale) {
            (Some(me), true) => modal_tip(
                self.model.omega(),
                &self.forced[ri],
                self.tip_hom.unwrap_or_else(|| me.tip_of(&self.q)),
                self.trig_now(),
            ),
            _ => (self.model.w_tip(&self.z), self.model.w_tip_dot(&self.z)),
        };
        [w, wd, v, vd]
    }
    // the bound and its proof: `bound.rs`
    fn displacement_bound(&mut self, weights: &[f64], enough: f64) -> f64 {
        self.displacement_bound_impl(weights, enough)
    }
    fn advance_to(&mut self, tau_end: f64) -> Result<(), SimError> {
        let mut out = Ok(());
        while self.tau < tau_end {
            // the certified whole grid steps in one tight loop, the next step (a possible
            // switching, or a partial step) by step_impl
            let step = self.grid_run(tau_end).and_then(|()| {
                if self.tau < tau_end {
                    self.step_impl(tau_end, Form::Nothing)?;
                }
                Ok(())
            });
            if let Err(e) = step {
                out = Err(e);
                break;
            }
        }
        self.materialize();
        out
    }
}

impl AffineRegions for ExactPropagator {
    // the derivative and its derivation: `sensitivity.rs`
    fn last_step_param_derivative_into(
        &mut self,
        param: SweepParam,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError> {
        self.last_step_param_derivative_impl(param, out)
    }
    fn region_particular_param_derivative_into(
        &mut self,
        param: SweepParam,
        r: Region,
        tau: f64,
        out: &mut DVector<f64>,
    ) -> Result<bool, SimError> {
        let Some(d) = self.particular_derivative_for(param, out)? else {
            return Ok(false);
        };
        let ri = r.index();
        let sc = (self.model.omega() * tau).sin_cos();
        Self::zpp_into(&d[ri], &self.forced[ri], tau, sc, out.as_mut_slice());
        Ok(true)
    }
    fn has_region_transition(&self, r: Region) -> bool {
        self.spec[r.index()].modal.is_some()
    }
    /// T⁻¹ V e^{Λt} V⁻¹ T from the eigendecomposition (accurate for any t ≥ 0: Re λ_k ≤ 0 and
    /// the basis is well conditioned, `modal::MAX_MODAL_CONDITION`).
    fn region_transition_into(&self, r: Region, t: f64, out: &mut DMatrix<f64>) -> bool {
        let Some(me) = &self.spec[r.index()].modal else {
            return false;
        };
        let dim = self.z.len();
        if out.shape() != (dim, dim) {
            *out = DMatrix::zeros(dim, dim);
        }
        me.transition_plain_into(t, out);
        true
    }
}
