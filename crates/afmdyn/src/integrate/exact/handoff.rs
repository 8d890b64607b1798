//! The exact propagator as the free-flight half of [`crate::integrate::split::Split`]: built for
//! the free flight of a law that exerts no force outside contact, restarted in a given region
//! after an event the split integrator handled, and run until its next switching.

use super::tip::tip_v_t;
use super::ExactPropagator;
use crate::contact::ContactLaw;
use crate::error::SimError;
use crate::integrate::Step;
use crate::model::CantileverModel;
use crate::params::Params;
use crate::system::Region;

impl ExactPropagator {
    /// The exact propagator of the free flight of `model` (region I of eq. 10, the linear law's
    /// free region, which every law but DMT shares: Hertz and impact exert no force while
    /// V_T > 0): built for the linear law with α4 = α6 = 0, so both of its regions are the free
    /// flight and its grid resolves the free modes only. Its dead band is `model`'s guard
    /// tolerance in free flight, the adaptive integrator's (so that the two halves of a split
    /// integrator leave free flight at the same V_T).
    ///
    /// # Errors
    /// As [`ExactPropagator::try_new`] (Ω at an undamped resonance of the free beam, the grid
    /// budget).
    pub(crate) fn free_flight(
        model: &CantileverModel,
        min_steps_per_period: usize,
        cache: Option<super::PropagatorCache>,
    ) -> Result<Self, SimError> {
        let p = Params {
            contact_law: ContactLaw::Linear,
            alpha4: 0.0,
            alpha6: 0.0,
            ..*model.params()
        };
        let twin = CantileverModel::new(&p).map_err(SimError::from)?;
        let opts = super::ExactOptions {
            min_steps_per_period,
            cache,
            ..super::ExactOptions::default()
        };
        Self::try_with(&twin, opts)
    }

    /// Restart at (τ, z) in `region`, as [`crate::integrate::Integrator::reset`] but with the
    /// region given (a state on the switching surface after an event belongs to the region the
    /// event enters, whatever the sign of V_T's round-off) and without checking z (the caller
    /// did). With `keep_last` the last step is kept for dense output and its Jacobian, and the
    /// chattering test goes on (a hand-over after an event inside that step).
    pub(crate) fn restart_in(&mut self, tau: f64, z: &[f64], region: Region, keep_last: bool) {
        self.region = region;
        self.tau = tau;
        self.z.as_mut_slice().copy_from_slice(z);
        self.stale = false;
        let j = self.grid.next_index(tau) - 1;
        let m = self.grid.m as i64;
        self.on_grid =
            (self.grid.tau(j) == tau).then_some((j.div_euclid(m), j.rem_euclid(m) as usize));
        self.between = None;
        self.sampler.clear();
        let sc = (self.model.omega() * tau).sin_cos();
        self.entry_trig = (tau, sc);
        self.enter_stint(region, sc);
        self.just_switched = true;
        self.vt = tip_v_t(&self.model, z, sc);
        if keep_last {
            return;
        }
        self.chatter.clear();
        self.last.tau0 = tau;
        self.last.region = region;
        self.last.dz0.fill(0.0);
        *self.last.q0 = super::modal::Modes::ZERO;
        self.last.modal = false;
        self.last.full = false;
        self.last.span = false;
        self.poly_built = false;
        self.param_end = None;
    }

    /// Advance towards `tau_end` until the first switching: the certified whole grid steps in
    /// one loop, the others by `step_impl`, as [`crate::integrate::Integrator::advance_to`]
    /// does; returns the step that ends at a switching (with its event record and the plain
    /// state formed), or `None` at `tau_end` (the plain state may lag behind: `form_state`).
    ///
    /// # Errors
    /// As [`crate::integrate::Integrator::step`].
    pub(crate) fn run_to_switching(&mut self, tau_end: f64) -> Result<Option<Step>, SimError> {
        self.run_span(tau_end, f64::INFINITY)
    }
}
