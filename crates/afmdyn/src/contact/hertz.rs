//! `hertz` — F_c = α4 δ^{3/2} + α6 δ̇ while δ ≥ 0 (Hertz 1882; Johnson, *Contact Mechanics*,
//! CUP 1985, §4.2: F = (4/3) E* √R δ^{3/2}, so α4 = (4/3) E* √(R g₀) L³/(EI)).

use super::{ForceEval, JetLaw, Law, SampleSi};

/// The Hertz law: no groups of its own (α4 is the Hertz group, α6 the damper).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HertzLaw;

impl Law for HertzLaw {
    const TIP_RADIUS: bool = true;
    const DOC: &'static str =
        "Hertz sphere–flat repulsion with a viscous damper: F_c = α4 δ^{3/2} + α6 δ̇";
    const SAMPLE_KEYS: &'static [&'static str] = &["law", "youngs_modulus", "poisson_ratio", "damping", "z_c"];

    super::prepared::as_given!();
    fn from_si(si: &SampleSi) -> Result<(Self, f64, f64), String> {
        Ok((HertzLaw, si.hertz_alpha4(), si.damper_alpha6()))
    }
    fn force(&self, k: f64, c: f64, contact: bool, delta: f64, rate: f64) -> ForceEval {
        if !contact {
            return ForceEval::default();
        }
        let d = delta.max(0.0);
        let s = d.sqrt();
        ForceEval {
            force: k * d * s + c * rate,
            d_delta: 1.5 * k * s,
            d_rate: c,
        }
    }
    fn potential(&self, k: f64, contact: bool, delta: f64) -> f64 {
        if contact {
            0.4 * k * delta.max(0.0).powf(2.5)
        } else {
            0.0
        }
    }
    fn dissipative(&self, _k: f64, c: f64, _delta: f64, rate: f64) -> f64 {
        c * rate
    }
    fn jet(&self, k: f64, c: f64) -> Option<JetLaw> {
        Some(JetLaw::Hertz { k, c })
    }
}
