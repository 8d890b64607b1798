//! `linear` — the paper's spring–damper: F_c = α4 δ + α6 δ̇ while δ ≥ 0 (eqs. 16–18). Each
//! region is affine in the state, so the exact propagator applies.

use super::{ForceEval, Law, SampleSi};

/// The linear law: no groups of its own (α4, α6 are [`crate::Params`]').
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LinearLaw;

impl Law for LinearLaw {
    const DOC: &'static str = "the paper's spring–damper F_c = α4 δ + α6 δ̇ in contact (eqs. 16–18)";
    const SAMPLE_KEYS: &'static [&'static str] = &["law", "stiffness", "damping", "z_c"];

    super::prepared::as_given!();
    fn from_si(si: &SampleSi) -> Result<(Self, f64, f64), String> {
        let alpha4 = si.stiffness.unwrap_or(0.0) * si.g0 / si.force;
        Ok((LinearLaw, alpha4, si.damper_alpha6()))
    }
    fn force(&self, k: f64, c: f64, contact: bool, delta: f64, rate: f64) -> ForceEval {
        if !contact {
            return ForceEval::default();
        }
        ForceEval {
            force: k * delta + c * rate,
            d_delta: k,
            d_rate: c,
        }
    }
    fn potential(&self, k: f64, contact: bool, delta: f64) -> f64 {
        if contact {
            0.5 * k * delta * delta
        } else {
            0.0
        }
    }
    fn dissipative(&self, _k: f64, c: f64, _delta: f64, rate: f64) -> f64 {
        c * rate
    }
    fn is_affine(&self) -> bool {
        true
    }
    fn taylor_hint(&self) -> &'static str {
        "the linear law is propagated exactly: use integrator = \"exact\" (or \"auto\")"
    }
}
