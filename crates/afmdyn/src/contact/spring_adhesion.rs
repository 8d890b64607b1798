//! `spring_adhesion` — a toy law, compiled only with the `toy-law` feature (it does not ship):
//! a linear spring with a constant adhesion force in contact, F_c = α4 δ + α6 δ̇ − F̃_ad for
//! δ ≥ 0, no force outside contact. It exists to show (and test, `tests/toy_law.rs`) that a law
//! is this one file plus one line of the registry ([`super`]).
//!
//! The force jumps by −F̃_ad where the contact forms and back where it ends (a step at the
//! guard, as the impact law's); its potential U = ½α4 δ² − F̃_ad δ is continuous there.

use super::{ForceEval, Law, Param};
use crate::error::ParamError;

/// The toy law's group, its own (no other law has it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpringAdhesionLaw {
    /// F̃_ad ≥ 0: the constant adhesion force in contact.
    pub toy_adhesion: f64,
}

impl Law for SpringAdhesionLaw {
    const DOC: &'static str =
        "toy law: a linear spring with a constant adhesion force, F_c = α4 δ + α6 δ̇ − F̃_ad";
    const PARAMS: &'static [Param] = &[Param {
        name: "toy_adhesion",
        symbol: "F̃_ad",
        unit: "1",
        range: "0 ≤ F̃_ad ≤ 1e12",
        default: 0.1,
        doc: "the constant adhesion force in contact F̃_ad",
        si_keys: &[],
        under_probe: None,
    }];

    super::prepared::as_given!();
    fn validate(&self) -> Result<(), ParamError> {
        if !(self.toy_adhesion.is_finite() && (0.0..=1e12).contains(&self.toy_adhesion)) {
            return Err(ParamError::Law {
                name: "toy_adhesion (spring_adhesion F̃_ad)",
                value: self.toy_adhesion,
                range: "0 ≤ F̃_ad ≤ 1e12",
            });
        }
        Ok(())
    }
    fn force(&self, k: f64, c: f64, contact: bool, delta: f64, rate: f64) -> ForceEval {
        if !contact {
            return ForceEval::default();
        }
        ForceEval {
            force: k * delta + c * rate - self.toy_adhesion,
            d_delta: k,
            d_rate: c,
        }
    }
    fn potential(&self, k: f64, contact: bool, delta: f64) -> f64 {
        if contact {
            0.5 * k * delta * delta - self.toy_adhesion * delta
        } else {
            0.0
        }
    }
    fn dissipative(&self, _k: f64, c: f64, _delta: f64, rate: f64) -> f64 {
        c * rate
    }
}
