//! The requests of the model itself, without integration: `modes` (natural frequencies and
//! damped eigenvalues, eqs. 19–23), its Fig. 3 sweep, `units` (the dimensionless set and the SI
//! scales) and `cantilevers` (the lever library).

use super::costs::MODEL_BYTES;
use super::limits::Cost;
use crate::units::PhysicalModel;
use serde::{Deserialize, Serialize};

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

/// `modes --sweep fig3`: the paper's Fig. 3 maps, ω₁/ω₀₁ and ω₂/ω₀₂ of the contact system
/// over the α1 × α4 grid (`crate::report::present::modes::fig3_alpha1` ×
/// `crate::report::present::modes::fig3_alpha4`) at the model's N (`crate::eigen::fig3_sweep`).
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Fig3Request {
    /// The directory the maps are written to, as the document names it (`out`).
    pub out: String,
}

// two eigenproblems of 2N × 2N, and the figure's 11 × 101: no integration
impl_request! {
    [ModesRequest, "modes"; Fig3Request, "modes"]
    validate |_, model| Ok(model.params.validate_fields()?);
    cost |_, _| Ok(NO_WORK)
}

/// `units`: a model's dimensionless set and its SI scales — of a probe file (`probe`:
/// `{params, si}`, the probe's conversion alone, without the warnings a run's document
/// carries), or of a physical model in the paper's terms (`physical`, eqs. 5, 7:
/// `{params, scales, physical}`). Run on a plain model
/// ([`Resolved::plain`](super::run::Resolved::plain)).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UnitsRequest {
    /// The probe whose dimensionless set and scales are shown.
    pub probe: Option<crate::probe::Probe>,
    /// The physical model (SI), instead of a probe.
    pub physical: Option<PhysicalModel>,
}

/// `cantilevers`: the lever library (nominal k, f₀, Q and tip radius, with their sources;
/// [`crate::cantilevers`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CantileversRequest {}

impl_request! {
    [UnitsRequest, "units"; CantileversRequest, "cantilevers"]
    validate |_, _| Ok(());
    cost |_, _| Ok(NO_WORK)
}
