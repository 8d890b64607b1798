//! `impact` — the impact oscillator of the paper's Fig. 1b: a rigid sample at V_T = 0 with
//! Newton's coefficient of restitution r: dV_T/dτ⁺ = −r dV_T/dτ⁻ (Shaw & Holmes, *J. Sound Vib.*
//! 90 (1983) 129; Nordmark, *J. Sound Vib.* 145 (1991) 279). No force acts in free flight; the
//! impulse and the sticking phase are handled by the model ([`crate::model`]).


use super::{Law, Param, SampleSi};
use crate::error::ParamError;

/// Default coefficient of restitution of the impact law.
pub(crate) const IMPACT_DEFAULT_RESTITUTION: f64 = 0.8;

/// The impact law's group.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactLaw {
    /// Newton's coefficient of restitution r.
    pub restitution: f64,
}

impl Law for ImpactLaw {
    const DOC: &'static str =
        "rigid sample with coefficient of restitution r ∈ [0, 1] (impact oscillator, Fig. 1b)";
    const SAMPLE_KEYS: &'static [&'static str] = &["law", "restitution", "z_c"];
    const PARAMS: &'static [Param] = &[Param {
        name: "restitution",
        symbol: "r",
        unit: "1",
        range: "0 ≤ r ≤ 1",
        default: IMPACT_DEFAULT_RESTITUTION,
        doc: "coefficient of restitution r",
        si_keys: &["restitution"],
        under_probe: None,
    }];

    super::prepared::as_given!();
    fn validate(&self) -> Result<(), ParamError> {
        let restitution = self.restitution;
        if !(restitution.is_finite() && (0.0..=1.0).contains(&restitution)) {
            return Err(ParamError::Law {
                name: "restitution (impact r)",
                value: restitution,
                range: "0 ≤ r ≤ 1",
            });
        }
        Ok(())
    }
    fn from_si(si: &SampleSi) -> Result<(Self, f64, f64), String> {
        let law = ImpactLaw {
            restitution: si.restitution.unwrap_or(0.0),
        };
        Ok((law, 0.0, 0.0))
    }
    fn restitution(&self) -> Option<f64> {
        Some(self.restitution)
    }
    fn taylor_hint(&self) -> &'static str {
        "impacts need the jump map of the adaptive or split integrator: use integrator = \"auto\""
    }
}
