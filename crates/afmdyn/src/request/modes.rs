//! The requests of the model itself, without integration: `modes` (natural frequencies and
//! damped eigenvalues, eqs. 19–23), its Fig. 3 sweep, `units` (the dimensionless set and the SI
//! scales) and `cantilevers` (the lever library).

use super::costs::MODEL_BYTES;
use super::limits::Cost;
use super::run::{Analysis, Request, Resolved};
use crate::analysis::progress::Progress;
use crate::eigen::{fig3_sweep, spectrum, Fig3Point, RegionSpectrum};
use crate::error::SimError;
use crate::params::Params;
use crate::report;
use crate::units::{PhysicalModel, Scales};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// The cost of a request that integrates nothing: the model's memory.
const NO_WORK: Cost = Cost {
    bytes: MODEL_BYTES,
    work: 0.0,
};

/// `modes`: natural frequencies and damped eigenvalues of the free and contact systems
/// (eqs. 19–23). No options.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct ModesRequest {}

impl Request for ModesRequest {
    fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        Ok(model.params.validate_fields()?)
    }
    fn name(&self) -> &'static str {
        "modes"
    }
    fn cost(&self, _: &Resolved) -> Result<Cost, SimError> {
        // two eigenproblems of 2N × 2N: no integration
        Ok(NO_WORK)
    }
}

impl Analysis for ModesRequest {
    type Output = (RegionSpectrum, RegionSpectrum);
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

/// `modes --sweep fig3`: the paper's Fig. 3 maps, ω₁/ω₀₁ and ω₂/ω₀₂ of the contact system
/// over the α1 × α4 grid (`crate::report::present::modes::fig3_alpha1` ×
/// `crate::report::present::modes::fig3_alpha4`) at the model's N (`crate::eigen::fig3_sweep`).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fig3Request {
    /// The directory the maps are written to, as the document names it (`out`).
    pub out: String,
}

impl Request for Fig3Request {
    fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        Ok(model.params.validate_fields()?)
    }
    fn name(&self) -> &'static str {
        "modes"
    }
    fn cost(&self, _: &Resolved) -> Result<Cost, SimError> {
        // 11 × 101 eigenproblems of 2N × 2N: no integration
        Ok(NO_WORK)
    }
}

impl Analysis for Fig3Request {
    type Output = Vec<Fig3Point>;
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

/// `units`: a model's dimensionless set and its SI scales — of a probe file (`probe`:
/// `{params, si}`, the probe's conversion alone, without the warnings a run's document
/// carries), or of a physical model in the paper's terms (`physical`, eqs. 5, 7:
/// `{params, scales, physical}`). Run on a plain model ([`Resolved::plain`]).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UnitsRequest {
    /// The probe whose dimensionless set and scales are shown.
    pub probe: Option<crate::probe::Probe>,
    /// The physical model (SI), instead of a probe.
    pub physical: Option<PhysicalModel>,
}

impl Request for UnitsRequest {
    fn validate(&self, _: &Resolved) -> Result<(), SimError> {
        Ok(())
    }
    fn name(&self) -> &'static str {
        "units"
    }
    fn cost(&self, _: &Resolved) -> Result<Cost, SimError> {
        Ok(NO_WORK)
    }
}

impl Analysis for UnitsRequest {
    /// The physical model's dimensionless set and scales (`None`: the probe's model).
    type Output = Option<(Params, Scales)>;
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

/// `cantilevers`: the lever library (nominal k, f₀, Q and tip radius, with their sources;
/// [`crate::cantilevers`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CantileversRequest {}

impl Request for CantileversRequest {
    fn validate(&self, _: &Resolved) -> Result<(), SimError> {
        Ok(())
    }
    fn name(&self) -> &'static str {
        "cantilevers"
    }
    fn cost(&self, _: &Resolved) -> Result<Cost, SimError> {
        Ok(NO_WORK)
    }
}

impl Analysis for CantileversRequest {
    type Output = ();
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
