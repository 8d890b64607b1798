//! The running of the model's own requests (`request::modes`): `modes`, its Fig. 3 sweep,
//! `units` and `cantilevers` — their [`Analysis`] (execution, document, presentation).

use crate::analysis::progress::Progress;
use crate::eigen::{fig3_sweep, spectrum, Fig3Point, RegionSpectrum};
use crate::error::SimError;
use crate::params::Params;
use crate::report::{self, Convergence};
use crate::request::modes::{CantileversRequest, Fig3Request, ModesRequest, UnitsRequest};
use crate::request::run::{Analysis, Resolved};
use crate::units::Scales;
use serde_json::{json, Value};

impl Analysis for ModesRequest {
    type Output = (RegionSpectrum, RegionSpectrum);
    fn convergence(&self, _: &Self::Output) -> Convergence {
        Convergence::exact("eigenproblem")
    }
    fn execute(&self, model: &Resolved, _: &Progress) -> Result<Self::Output, SimError> {
        Ok(spectrum(&model.params)?)
    }
    fn report(&self, model: &Resolved, (free, contact): &Self::Output) -> Result<Value, SimError> {
        Ok(report::modes(&model.params, free, contact))
    }
    fn present(
        &self,
        (free, contact): &Self::Output,
        at: crate::request::Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        Ok(crate::report::present::modes::modes(
            &at.model.params,
            free,
            contact,
            at.units,
        ))
    }
}

impl Analysis for Fig3Request {
    type Output = Vec<Fig3Point>;
    fn convergence(&self, _: &Self::Output) -> Convergence {
        Convergence::exact("eigenproblems")
    }
    fn execute(&self, model: &Resolved, _: &Progress) -> Result<Self::Output, SimError> {
        let (alpha1, alpha4) = (
            crate::report::present::modes::fig3_alpha1(),
            crate::report::present::modes::fig3_alpha4(),
        );
        Ok(fig3_sweep(model.params.modes, &alpha1, &alpha4)?)
    }
    fn report(&self, model: &Resolved, points: &Self::Output) -> Result<Value, SimError> {
        Ok(json!({ "params": model.params, "points": points, "out": self.out }))
    }
    fn present(
        &self,
        points: &Self::Output,
        at: crate::request::Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        #[cfg(feature = "files")]
        let mut shown = crate::report::present::modes::fig3(at.model.params.modes, points);
        #[cfg(not(feature = "files"))]
        let mut shown = report::Presentation::default();
        let _ = at.model;
        shown.summary = vec![format!("wrote {} points to", points.len())];
        shown.outputs_note = report::OutputsNote::Named;
        Ok(shown)
    }
}

impl Analysis for UnitsRequest {
    /// The physical model's dimensionless set and scales (`None`: the probe's model).
    type Output = Option<(Params, Scales)>;
    fn convergence(&self, _: &Self::Output) -> Convergence {
        Convergence::NOTHING // a unit conversion
    }
    fn execute(&self, _: &Resolved, _: &Progress) -> Result<Self::Output, SimError> {
        match &self.physical {
            Some(m) => Ok(Some((m.to_params()?, m.scales()))),
            None => Ok(None),
        }
    }
    fn report(&self, model: &Resolved, output: &Self::Output) -> Result<Value, SimError> {
        Ok(match output {
            Some((p, s)) => json!({ "params": p, "scales": s, "physical": self.physical }),
            None => match &self.probe {
                Some(pr) => {
                    json!({ "params": pr.params, "si": report::si(pr, &pr.params, &json!({})) })
                }
                None => json!({ "params": model.params }),
            },
        })
    }
    fn present(
        &self,
        output: &Self::Output,
        at: crate::request::Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        Ok(match (&self.physical, output) {
            (Some(m), Some((p, s))) => crate::report::present::modes::units(m, p, s),
            _ => {
                let mut shown = report::Presentation::default();
                shown.line(
                    serde_json::to_string_pretty(at.document).expect("a document serialises"),
                );
                shown
            }
        })
    }
}

impl Analysis for CantileversRequest {
    type Output = ();
    fn convergence(&self, _: &()) -> Convergence {
        Convergence::NOTHING // the lever library
    }
    fn execute(&self, _: &Resolved, _: &Progress) -> Result<(), SimError> {
        Ok(())
    }
    fn report(&self, _: &Resolved, _: &()) -> Result<Value, SimError> {
        Ok(crate::cantilevers::document())
    }
    fn present(
        &self,
        _: &(),
        _: crate::request::Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        Ok(crate::report::present::modes::cantilevers())
    }
}
