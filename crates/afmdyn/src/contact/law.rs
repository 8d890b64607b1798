//! The [`Law`] trait every contact law implements, and the descriptors ([`LawInfo`],
//! [`Param`]) the registry ([`super::LAWS`]) hands to the front ends (schema, CLI help, Python,
//! docs, conformance suite).

use super::{ForceEval, Hysteresis, PreparedForce, Zener};
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
    /// The probe file's SI keys (`[sample]` table) the group is derived from.
    pub si_keys: &'static [&'static str],
    /// Where a probe file sets the group, for the message refusing it as a dimensionless
    /// value under a probe (`give the Hamaker constant in the probe file's [sample] hamaker
    /// (J)`); `None` for a group a request may give with a probe (a pure number, as the
    /// impact law's `restitution`).
    pub under_probe: Option<&'static str>,
}

impl Param {
    /// A placeholder (no name), to fill tables built at compile time.
    pub(crate) const EMPTY: Param = Param {
        name: "",
        symbol: "",
        unit: "",
        range: "",
        default: 0.0,
        doc: "",
        si_keys: &[],
        under_probe: None,
    };
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
    /// The keys a probe file's `[sample]` table may hold for it ([`Law::SAMPLE_KEYS`]).
    pub sample_keys: &'static [&'static str],
    /// Whether its contact is Hertz's sphere of the tip's radius ([`Law::TIP_RADIUS`]).
    pub tip_radius: bool,
}

/// A probe file's sample in SI (`[sample]` and `[tip]`, read by [`crate::probe`]) and the probe's
/// scales: what a law's [`Law::from_si`] converts into its groups and α4, α6. A value the law
/// does not read is `None`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SampleSi {
    /// The length scale g₀ (m).
    pub g0: f64,
    /// The force scale F_s (N): the unit of the scaled force.
    pub force: f64,
    /// The time scale t_s (s).
    pub time: f64,
    /// The effective modulus E* (Pa) of tip and sample (Johnson, eq. 4.22).
    pub e_star: Option<f64>,
    /// The tip radius R (m).
    pub radius: Option<f64>,
    /// The Hamaker constant H (J).
    pub hamaker: Option<f64>,
    /// The intermolecular distance a₀ (m).
    pub a0: Option<f64>,
    /// The sample's viscosity η (Pa s).
    pub viscosity: Option<f64>,
    /// A linear sample's stiffness (N/m).
    pub stiffness: Option<f64>,
    /// A linear or Hertz sample's damper (N s/m).
    pub damping: Option<f64>,
    /// The coefficient of restitution.
    pub restitution: Option<f64>,
    /// The voltage across the gap, bias − contact potential (V).
    pub voltage: Option<f64>,
    /// The work of adhesion W (J/m²).
    pub adhesion_energy: Option<f64>,
    /// The capillary meniscus: volume V (m³), surface tension γ (N/m), contact angle θ (rad).
    pub meniscus: Option<(f64, f64, f64)>,
    /// The SLS sample's Maxwell arm: spring k₂ (N/m) and relaxation time τ_r = η/k₂ (s).
    pub maxwell: Option<(f64, f64)>,
}

/// The reduced (effective) modulus of two elastic bodies in contact,
/// E* = 1/((1 − ν_t²)/E_t + (1 − ν_s²)/E_s) (Pa; Johnson, *Contact Mechanics*, eq. 4.22), of the
/// tip (E_t, ν_t) and the sample (E_s, ν_s).
pub fn reduced_modulus(e_tip: f64, nu_tip: f64, e_sample: f64, nu_sample: f64) -> f64 {
    1.0 / ((1.0 - nu_tip * nu_tip) / e_tip + (1.0 - nu_sample * nu_sample) / e_sample)
}

impl SampleSi {
    /// The Hertz group α4 = (4/3) E* √R g₀^{3/2}/F_s (Johnson, *Contact Mechanics*, §4.2).
    pub(crate) fn hertz_alpha4(&self) -> f64 {
        let (e, rr) = (self.e_star.unwrap_or(0.0), self.radius.unwrap_or(0.0));
        4.0 / 3.0 * e * rr.sqrt() * self.g0.powf(1.5) / self.force
    }
    /// The Kelvin–Voigt group α6 = η √(R g₀) g₀/(t_s F_s): the damper η a δ̇ with the contact
    /// radius a = √(Rδ).
    pub(crate) fn kelvin_voigt_alpha6(&self) -> f64 {
        let rr = self.radius.unwrap_or(0.0);
        self.viscosity.unwrap_or(0.0) * (rr * self.g0).sqrt() * self.g0 / (self.time * self.force)
    }
    /// A viscous damper's α6 = c g₀/(t_s F_s) of `damping` c (N s/m).
    pub(crate) fn damper_alpha6(&self) -> f64 {
        self.damping.unwrap_or(0.0) * self.g0 / (self.time * self.force)
    }
}

/// A tip–sample law: a struct of its dimensionless groups (all `f64`, named and ordered as its
/// [`Law::PARAMS`], whose defaults fill the groups a front end does not give), registered by
/// one line in [`super`]'s `laws!` registry.
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
    /// The keys a probe file's `[sample]` table may hold for the law ([`crate::probe`]).
    const SAMPLE_KEYS: &'static [&'static str] = &["law", "z_c"];
    /// Whether the law's contact is Hertz's sphere of the tip's radius, α4 its Hertz group
    /// (4/3)E*√R g₀^{3/2}/F_s (`SampleSi::hertz_alpha4`): a probe's tip radius and sample
    /// modulus set it, and a fitted α4 is a modulus.
    const TIP_RADIUS: bool = false;

    /// The law's constants, derived once from its groups and α4, α6 ([`Law::prepare`]);
    /// `super::AsGiven` for a law that derives nothing worth keeping.
    type Prepared: PreparedForce + Copy + std::fmt::Debug + PartialEq;

    /// The prepare step: the law's groups with α4 = `k` and α6 = `c` turned into the constants
    /// its force needs, once per model (`super::PreparedLaw`). Evaluating the result is
    /// [`Law::force`], [`Law::potential`] and [`Law::dissipative`] bit for bit (the same
    /// operations in the same order).
    fn prepare(&self, k: f64, c: f64) -> Self::Prepared;
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
    /// The law's groups and α4, α6 from a probe file's sample in SI.
    ///
    /// # Errors
    /// A message naming the `[sample]` key whose value the law cannot take; for a law a probe
    /// file cannot give (the default), a message saying so.
    fn from_si(_si: &SampleSi) -> Result<(Self, f64, f64), String> {
        Err("a probe file cannot give this law (it has no conversion from SI keys)".into())
    }
    /// Why the law does not apply in a liquid medium, if it does not.
    fn not_in_liquid(&self) -> Option<&'static str> {
        None
    }
    /// Why the Taylor integrator refuses the law (when [`Law::jet`] is `None`).
    fn taylor_hint(&self) -> &'static str {
        "this law's force is not in the Taylor recurrences (the electrostatic \
         1/(d(d + R)), JKR's implicit contact radius, the capillary meniscus's \
         √(D² + h²)): use integrator = \"auto\" (or \"adaptive\")"
    }
}
