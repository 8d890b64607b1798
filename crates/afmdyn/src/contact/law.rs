//! The [`Law`] trait every contact law implements, and the descriptors ([`LawInfo`],
//! [`Param`]) the registry ([`super::LAWS`]) hands to the front ends (schema, CLI help, Python,
//! docs, conformance suite).

use super::{ForceEval, Hysteresis, LawGroups, Zener};
use crate::error::ParamError;

/// One dimensionless group of a law: what a front end needs to name, document and check it.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Param {
    /// The group's key in requests, TOML files, CLI flags (with `-` for `_`) and Python
    /// keywords, e.g. `hamaker`.
    pub name: &'static str,
    /// Its symbol, e.g. `H̃`.
    pub symbol: &'static str,
    /// Its unit (`1`: dimensionless).
    pub unit: &'static str,
    /// The physical range [`Law::validate`] accepts, e.g. `0 ≤ H̃ ≤ 1e12`.
    pub range: &'static str,
    /// The default (the typical value), as written in requests.
    pub default: f64,
    /// One line of documentation.
    pub doc: &'static str,
    /// The probe file's SI keys ([sample] table) the group is derived from.
    pub si_keys: &'static [&'static str],
}

/// A registered law's descriptor ([`super::LAWS`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct LawInfo {
    /// The name, as requests and files spell it (`dmt`).
    pub name: &'static str,
    /// Other names the parser accepts (`zener` for `sls`).
    pub aliases: &'static [&'static str],
    /// One line of documentation.
    pub doc: &'static str,
    /// Its own groups (the shared α4, α6 are [`crate::Params`]').
    pub params: &'static [Param],
}

/// A tip–sample law: a struct of its dimensionless groups (all `f64`, named as its
/// [`Law::PARAMS`]), registered by one line in [`super`]'s `laws!` registry.
///
/// Every method has the default of a law with no force, no memory and no special numerics;
/// `k` is α4 (the shared stiffness or Hertz group), `c` is α6 (the shared damper), δ = −V_T the
/// indentation and δ̇ its rate, `contact` the region.
pub trait Law: Copy + Sized {
    /// One line of documentation.
    const DOC: &'static str;
    /// Other names the parser accepts.
    const ALIASES: &'static [&'static str] = &[];
    /// The law's own groups, in the order of its fields.
    const PARAMS: &'static [Param] = &[];

    /// The law from the groups a front end gives, the missing ones at their defaults.
    fn with_groups(groups: &LawGroups) -> Self;
    /// The law's groups (those it has).
    fn groups(&self) -> LawGroups {
        LawGroups::default()
    }
    /// Check the law's own groups.
    ///
    /// # Errors
    /// [`ParamError::Law`] naming the group and its allowed range.
    fn validate(&self) -> Result<(), ParamError> {
        Ok(())
    }
    /// Check the law's groups against the shared α4 (`k`) and α6 (`c`).
    ///
    /// # Errors
    /// [`ParamError::Law`] naming α4 or α6 and the range the law needs.
    fn validate_shared(&self, _k: f64, _c: f64) -> Result<(), ParamError> {
        Ok(())
    }
    /// F_c(δ, δ̇) with its partials (repulsive positive).
    fn force(&self, _k: f64, _c: f64, _contact: bool, _delta: f64, _rate: f64) -> ForceEval {
        ForceEval::default()
    }
    /// The potential U(δ) of the conservative part ([`super::TipSampleLaw::potential`]).
    fn potential(&self, _k: f64, _contact: bool, _delta: f64) -> f64 {
        0.0
    }
    /// The dissipative part F_d of F_c in contact (the dissipation rate is F_d δ̇ ≥ 0).
    fn dissipative(&self, _k: f64, _c: f64, _delta: f64, _rate: f64) -> f64 {
        0.0
    }
    /// Whether the law exerts a force outside contact.
    fn acts_outside(&self) -> bool {
        false
    }
    /// d − V_T: the tip–sample distance's offset from the switching function.
    fn distance_offset(&self) -> f64 {
        0.0
    }
    /// The long-range attraction at distance d: [F(d), dF/dd, U(d)].
    fn long_range(&self, _d: f64) -> [f64; 3] {
        [0.0; 3]
    }
    /// A hysteretic law's cycle with Hertz group `alpha4`.
    fn hysteresis(&self, _alpha4: f64) -> Option<Hysteresis> {
        None
    }
    /// The internal states the law adds to the state.
    fn internal_states(&self) -> usize {
        0
    }
    /// The law's internal state as a Zener solid of α4 = `k`, α6 = `c`, if it has one.
    fn zener(&self, _k: f64, _c: f64) -> Option<Zener> {
        None
    }
    /// Whether each region is affine in the state (the exact propagator applies).
    fn is_affine(&self) -> bool {
        false
    }
    /// The coefficient of restitution of an impact (a rigid constraint) law.
    fn restitution(&self) -> Option<f64> {
        None
    }
    /// Whether the contact damper is Kelvin–Voigt's α6 √δ δ̇ (whose ∂/∂δ is singular at the
    /// contact's onset).
    fn kelvin_voigt(&self) -> bool {
        false
    }
    /// The law's piece of the Taylor jet: its force as the recurrences carry it, or `None`.
    fn jet(&self, _k: f64, _c: f64) -> Option<super::JetLaw> {
        None
    }
    /// Why the Taylor integrator refuses the law (when [`Law::jet`] is `None`).
    fn taylor_hint(&self) -> &'static str {
        "this law's force is not in the Taylor recurrences (the electrostatic \
         1/(d(d + R)), JKR's implicit contact radius, the capillary meniscus's \
         √(D² + h²)): use integrator = \"auto\" (or \"adaptive\")"
    }
}
