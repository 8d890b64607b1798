//! The running of `simulate` held whole in memory (`request::simulate`): the run recorded at
//! once (`SimulateRequest::record_whole`), for Python's arrays and the browser's series.

use crate::error::SimError;
use crate::model::CantileverModel;
use crate::probe::Probe;
use crate::request::analyses::initial_state;
use crate::request::simulate::{SimulateRequest, SimulateSpan};
use crate::trajectory::{record, RecordSpec, Trajectory};
use serde_json::{json, Value};

impl SimulateRequest {
    /// Record the run of `model` over `span` (validated, [`SimulateRequest::validate_in_memory`])
    /// whole in memory ([`crate::trajectory::record`]: samples, switchings, sections, the energy
    /// balance per period when asked and the body-contact check), from the request's initial state (rest
    /// when none), with the thermal force at a temperature (in the units of `probe`,
    /// [`SimulateRequest::integrator`]): the trajectory and the integrator's name.
    ///
    /// # Errors
    /// The initial state's ([`initial_state`]), the integrator's.
    pub fn record_whole(
        &self,
        model: &CantileverModel,
        probe: Option<&Probe>,
        span: &SimulateSpan,
    ) -> Result<(Trajectory, &'static str), SimError> {
        let z0 = initial_state(model, self.initial.as_deref())?;
        let mut integ = self.integrator(model, probe, &z0)?;
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

    /// With a temperature, write into the run's `doc` of a model of `law` its `thermal` block
    /// (`temperature` K, `seed`, `method`) and the temperature's and the scheme's warnings
    /// ([`crate::integrate::exact::noise::thermal_method`]); without one leave it as it is.
    pub(crate) fn thermal_into(&self, doc: &mut Value, law: &crate::contact::ContactLaw) {
        let Some(t) = self.temperature else {
            return;
        };
        let (method, scheme) = crate::integrate::exact::noise::thermal_method(law);
        doc["thermal"] = json!({
            "temperature": t,
            "seed": self.seed,
            "method": method,
        });
        for w in self.warnings().into_iter().chain(scheme) {
            match doc.get_mut("warnings").and_then(Value::as_array_mut) {
                Some(list) => list.push(Value::from(w)),
                None => doc["warnings"] = Value::from(vec![w]),
            }
        }
    }
}
