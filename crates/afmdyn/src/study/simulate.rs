//! The running of `simulate` held whole in memory (`request::simulate`): the run recorded at
//! once (`SimulateRequest::record_whole`), for Python's arrays and the browser's series.

use crate::error::SimError;
use crate::integrate::build;
use crate::model::CantileverModel;
use crate::request::analyses::initial_state;
use crate::request::simulate::{SimulateRequest, SimulateSpan};
use crate::trajectory::{record, RecordSpec, Trajectory};

impl SimulateRequest {
    /// Record the run of `model` over `span` (validated, [`SimulateRequest::validate_in_memory`])
    /// whole in memory ([`crate::trajectory::record`]: samples, switchings, sections, the energy
    /// balance per period when asked and the body-contact check), from the request's initial state (rest
    /// when none): the trajectory and the integrator's name.
    ///
    /// # Errors
    /// The initial state's ([`initial_state`]), the integrator's.
    pub fn record_whole(
        &self,
        model: &CantileverModel,
        span: &SimulateSpan,
    ) -> Result<(Trajectory, &'static str), SimError> {
        let z0 = initial_state(model, self.initial.as_deref())?;
        let mut integ = build(model, self.integrator_options()?, 0.0, &z0)?;
        let spec = RecordSpec {
            transient_periods: self.transient,
            record_tau: span.record_tau,
            samples_per_period: self.samples_per_period,
            energy: self.energy_balance,
            body_contact: true,
        };
        let tr = record(integ.as_mut(), &spec)?;
        Ok((tr, integ.name()))
    }
}
