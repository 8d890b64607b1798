//! Probe files: a real cantilever, tip, sample and drive in SI units → the model's
//! dimensionless set (α1 … α6, Ω and the law's groups) and the scales back to SI.
//!
//! ```toml
//! model = "beam"                 # "beam" (N Galerkin modes, the paper), "point-mass" or
//!                                # "eigenmodes" (per-mode k, f0, Q as arrays: see below)
//! modes = 3                      # beam only
//! [cantilever]                   # calibrated values ...
//! spring_constant = 40.0         # k (N/m), first-mode equivalent stiffness at the tip
//! resonance_frequency = 300e3    # f₀ (Hz), first free resonance (tip mass included)
//! quality_factor = 400           # Q₁; optional quality_factors = [...] per mode
//! tip_mass_ratio = 0.0           # optional α1 = M/(mL) of the beam (default 0)
//! # ... or geometry: length, width, thickness, youngs_modulus, density, tip_mass (+ quality_factor)
//! [tip]
//! radius = 10e-9                 # R (m)
//! youngs_modulus = 130e9         # E_t (Pa), default 130e9 (silicon, Hopcroft et al. 2010)
//! poisson_ratio = 0.27           # ν_t, default 0.27 (silicon, units::SILICON_TIP)
//! # shape = "paraboloid"         # the indenter of `afmdyn fit` (contact::indenter): paraboloid
//! #                              # (default) | sphere | flat-punch (with radius) | cone |
//! #                              # pyramid-4 (half_angle, degrees) | pyramid-3 (face_angle,
//! #                              # degrees); the dynamic analyses take the paraboloid only
//! [sample]
//! law = "dmt"                    # linear | hertz | dmt | electrostatic | jkr | capillary | sls
//!                                # | impact
//! youngs_modulus = 4e9           # E_s (Pa)            (hertz, dmt)
//! poisson_ratio = 0.33           # ν_s                 (hertz, dmt)
//! hamaker = 6.6e-20              # H (J)               (dmt; jkr: W = H/(12πa₀²) if no
//!                                #                      adhesion_energy)
//! # adhesion_energy = 0.05       # W (J/m²), work of adhesion (jkr)
//! # meniscus_volume = 1e-25      # V (m³), the water meniscus (capillary; with
//! # surface_tension = 0.072      #   γ (N/m), default water's, and
//! # contact_angle = 20           #   θ (degrees), default 0)
//! intermolecular_distance = 0.165e-9  # a₀ (m), default 0.165e-9 (Israelachvili) (dmt)
//! viscosity = 0.0                # η (Pa·s), Kelvin–Voigt −η√(R(a₀ − d))·ḋ (dmt)
//! # hertz: damping (N·s/m); linear: stiffness (N/m), damping (N·s/m); impact: restitution
//! # sls: stiffness (N/m, the relaxed spring k₁), maxwell_stiffness (N/m, k₂) and
//! #      relaxation_time (s, τ_r = η/k₂ of the Maxwell arm)
//! z_c = 8e-9                     # optional rest tip–sample distance (m), default A₀
//! [drive]
//! free_amplitude = 10e-9         # A₀ (m) at the drive frequency, far from the sample
//! frequency = 300e3              # f (Hz), default f₀
//! # multifrequency (bimodal): arrays, one entry per component, at most 4
//! # free_amplitude = [10e-9, 1e-9]   # A₀ᵢ (m)
//! # frequency = [300e3, 1.875e6]     # fᵢ (Hz), default each at its mode's free resonance
//! excitation = "base"            # base (acoustic, piezo: eq. 6) | tip (magnetic, photothermal)
//! # off-resonance (PeakForce) tapping instead of the above:
//! # mode = "off-resonance"
//! # modulation_frequency = 2e3   # f_m (Hz)
//! # modulation_amplitude = 100e-9 # A_m (m): the length unit g₀, α2 = 1
//! # modulated = "sample"         # sample (default: the lever's frame at rest) | base (beam:
//! #                              #   the base's inertial and drag terms of eq. 14)
//! [medium]                       # optional: the lever in a fluid (module `medium`)
//! name = "water"                 # water | air, or density (kg/m³) and viscosity (Pa s)
//! calibrated_in = "air"          # where f₀ and Q were measured: air (default) | vacuum
//! ```
//!
//! With `[medium]` and calibrated values, `[cantilever]` also takes the lever's `length` and
//! `width` (m), which the fluid loading needs; the drive frequency then defaults to the first
//! mode's natural frequency in the fluid.
//!
//! **Scales.** Lengths are measured in g₀ = A₀, so the dimensionless free amplitude is 1 and
//! A/A₀ is read directly. Time: τ = ω̃₁ · 2πf₀ t, where ω̃₁ is the dimensionless first natural
//! frequency of the model *with* the tip mass (1 for the point mass): t_s = ω̃₁/(2πf₀) seconds per
//! unit τ. Force: the unit F_s = k g₀/k̃₁, where k̃₁ is the dimensionless first-mode stiffness at
//! the tip.
//!
//! **Modal vs static stiffness (beam).** A calibrated k (thermal noise, Sader) is the stiffness
//! of the first mode at the tip, k₁ = ω₁² m₁ with the modal mass referred to the tip
//! m₁ = x₁ᵀ M x₁/(φ(1)ᵀx₁)² (Meirovitch, *Fundamentals of Vibrations*, McGraw-Hill 2001, §7.4;
//! Butt & Jaschke, *Nanotechnology* 6 (1995) 1). In the units of eq. 5 that is
//! k̃₁ = ω̃₁² x₁ᵀ M x₁/(φ(1)ᵀx₁)² times EI/L³: 3.09 for the bare beam (β₁⁴/4 = 3.0906, against the
//! static 3EI/L³: the modal value is 3 % stiffer), so EI/L³ = k/k̃₁.
//!
//! **Damping.** α3 gives mode 1 the quality factor Q₁: with C^I = α3 diag(s) (eq. 12
//! generalised, [`crate::Params::damping_profile`]), α3 = ω̃₁ x₁ᵀMx₁/(Q₁ x₁ᵀ diag(s) x₁) for the
//! undamped mode x₁ (modal damping ratio 1/(2Q₁), Meirovitch §7.16). Per-mode quality factors
//! set s_j = (β_j²/β₁²)(Q₁/Q_j), exact for the bare beam (α1 = 0), where mode j's damping
//! ratio is α3 s_j/(2β_j²); with a tip mass the modes mix and the achieved Q_j (reported by
//! `afmdyn modes`) differ slightly.
//!
//! **Drive.** The beam is base-driven (eq. 14), or with `excitation = "tip"` driven by a force
//! at the tip ([`crate::params::Excitation`]); α2 is chosen so that the free tip deflection
//! amplitude at Ω is A₀: α2 = 1/|H(Ω)|, H the tip response per unit α2 of the linear free system
//! ([`crate::CantileverModel::free_tip_response`]). The point mass is force-driven:
//! α2 = F₀/(k A₀) = √((1 − Ω²)² + (Ω/Q)²) (the harmonic oscillator's response).
//! A multifrequency drive (`[drive]` arrays) adds, for every model, components F̃ᵢ cos(ωᵢτ) at
//! the tip ([`crate::params::DriveComponent`]): ωᵢ/Ω is the fraction p/q with the smallest
//! q ≤ 1000 within 1e-6 of fᵢ/f₁ (`rational_ratio`: a periodic drive), else the convergent
//! of fᵢ/f₁ with q ≤ 10⁶ (`convergent`: a quasi-periodic drive, within about 1e-12, whose
//! response the time average measures); the frequency used is reported; and
//! F̃ᵢ = A₀ᵢ/(g₀|Hᵢ|) from the free tip response Hᵢ to a unit tip force at ωᵢ
//! ([`crate::CantileverModel::free_force_response`]).
//!
//! **Sample** (force unit F_s, length g₀, time t_s; E* from 1/E* = (1 − ν_t²)/E_t +
//! (1 − ν_s²)/E_s, Johnson, *Contact Mechanics*, CUP 1985, eq. 4.22):
//! * linear: α4 = K g₀/F_s, α6 = c g₀/(t_s F_s);
//! * hertz: F = (4/3)E*√R δ^{3/2} (Johnson eq. 4.23): α4 = (4/3)E*√R g₀^{3/2}/F_s, α6 as linear;
//! * dmt (Derjaguin, Muller & Toporov 1975; García & San Paulo, *Phys. Rev. B* 60 (1999) 4961):
//!   α4 as hertz, H̃ = H R/(6 g₀² F_s), ã₀ = a₀/g₀, α6 = η √(R g₀) g₀/(t_s F_s) (the
//!   Kelvin–Voigt term η√(Rδ) δ̇);
//! * electrostatic (DMT plus a biased tip, Hudlet et al., *Eur. Phys. J. B* 2 (1998) 5): the
//!   DMT groups, and from `bias_voltage` V_b and `contact_potential` V_cpd (default 0) the group
//!   Ẽ = πε₀(V_b − V_cpd)²/F_s and R̃ = R/g₀ of F_es = −πε₀V²R²/(d(d + R));
//! * jkr (Johnson, Kendall & Roberts, *Proc. R. Soc. Lond. A* 324 (1971) 301): α4 as hertz,
//!   P̃ = πWR/F_s from the work of adhesion W (`adhesion_energy`, or H/(12πa₀²) from `hamaker`
//!   and `intermolecular_distance`, Israelachvili 2011 §13.6), α6 as DMT's (the Kelvin–Voigt
//!   term η a δ̇ with the contact radius a);
//! * capillary (a meniscus formed at contact, ruptured at D_r; Zitzler, Herminghaus & Mugele,
//!   *Phys. Rev. B* 66 (2002) 155436; [`crate::contact`]): α4 and α6 as DMT's, from
//!   `meniscus_volume` V, `surface_tension` γ (default 0.072 N/m, water at 25 °C) and
//!   `contact_angle` θ (degrees, default 0) F̃_cap = 4πRγcosθ/F_s, h̃ = √(V/(πR))/g₀ and
//!   D̃_r = (1 + θ/2)V^{1/3}/g₀ (Lian, Thornton & Adams 1993);
//! * impact: the restitution r.
//!
//! The rest distance z_c sets α5 = z_c/g₀ − ã₀ (DMT) or z_c/g₀ ([`crate::Params::rest_distance`]).
//!
//! **Errors.** Every problem of a file is collected: unknown keys, missing keys (named with their
//! section), values out of range and values 1e3–1e12 off any probe's scale (a radius of 10 m,
//! a modulus of 4 Pa, a resonance at 300 Hz: read as a unit slip, with the reading meant), all
//! listed in one [`ProbeError::Invalid`].

pub mod defaults;
mod medium;
pub mod ranges;
mod reader;
pub(crate) use medium::MediumReport;
use reader::*;

pub use crate::contact::VACUUM_PERMITTIVITY;

/// The radius (m) a probe of a sharp indenter (`[tip] shape` a cone or a pyramid) without
/// `[tip] radius` resolves its dimensionless Hertz group with: no analysis that takes such a
/// shape reads it (the force-curve fit uses the angle; the dynamic analyses refuse the shape).
pub(crate) const SHAPE_STAND_IN_RADIUS: f64 = 10e-9;

/// The intermolecular distance a₀ of the DMT law when a probe file omits it, m
/// (Israelachvili 2011, §13.6).
pub(crate) const DEFAULT_INTERMOLECULAR_DISTANCE: f64 = 0.165e-9;

use crate::contact::indenter::TipShape;
use crate::contact::ContactLaw;
use crate::galerkin::{Galerkin, Region};
use crate::model::CantileverModel;
/// The convergent of `r` with the largest denominator ≤ `max_q` (defined with the ratio limits in
/// [`crate::params`], where the time average of a stepped curve also finds it).
pub(crate) use crate::params::convergent_within;
use crate::params::{
    DriveComponent, Excitation, Params, Structure, MAX_DRIVE_COMPONENTS, MAX_MODES,
    MAX_RATIO_DENOMINATOR,
};
use serde::Serialize;
use std::f64::consts::TAU;
#[cfg(feature = "files")]
use std::path::Path;
use thiserror::Error;

/// A probe file that cannot be used.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ProbeError {
    /// The file could not be read.
    #[error("{path}: {message}")]
    Io {
        /// The path.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// The file could not be read, is larger than
    /// [`crate::io::MAX_INPUT_TEXT_BYTES`] or is not UTF-8 text.
    #[error(transparent)]
    File(crate::io::InputFileError),
    /// Not TOML (with line and column from the parser).
    #[error("{path}: {message}")]
    Syntax {
        /// The path, or `<string>`.
        path: String,
        /// The parser's message.
        message: String,
    },
    /// Unknown, missing or out-of-range keys, all of them.
    #[error("{path}: {}", .problems.join("; "))]
    Invalid {
        /// The path, or `<string>`.
        path: String,
        /// One entry per problem, each naming the key with its section.
        problems: Vec<String>,
    },
}

/// The largest quality factor a probe may give: 1e7, beyond the Q of cantilevers and quartz
/// sensors in vacuum (1e4–1e6); a larger one leaves the beam's damping α3 and the drive
/// amplitude α2 = A₀/Q-scaled below the double's resolution (Q = 1e308 made α2 NaN).
pub(crate) const MAX_QUALITY_FACTOR: f64 = 1e7;

/// A refusal of a dimensionless group derived from the probe's keys, with the keys it was
/// derived from: the user wrote those, not the group (a tiny `free_amplitude` was refused as
/// "alpha5 = 7.8e21").
fn derived(message: String) -> String {
    let group = message.split([' ', '(']).next().unwrap_or("");
    let keys = match group {
        "alpha1" => "[tip] mass, [cantilever] spring_constant and resonance_frequency",
        "alpha2" => "[drive] free_amplitude and frequency",
        "alpha3" => "[cantilever] quality_factor or quality_factors",
        "alpha4" => {
            "[sample] youngs_modulus, poisson_ratio or stiffness, [tip] radius and modulus, \
             [cantilever] spring_constant and [drive] free_amplitude"
        }
        "alpha5" => "[sample] z_c and [drive] free_amplitude, lengths in units of A₀",
        "alpha6" => {
            "[sample] damping or viscosity (sls: maxwell_stiffness × relaxation_time, the \
             dashpot) and [cantilever] resonance_frequency"
        }
        "maxwell_stiffness" => {
            "[sample] maxwell_stiffness (sls), [cantilever] spring_constant and [drive] \
             free_amplitude"
        }
        "omega" => "[drive] frequency and [cantilever] resonance_frequency",
        "hamaker" => "[sample] hamaker, [tip] radius and [drive] free_amplitude",
        "intermolecular_distance" => {
            "[sample] intermolecular_distance and hamaker, and [drive] free_amplitude"
        }
        _ => return message,
    };
    format!("from {keys}: {message}")
}

/// Scales from the dimensionless model back to SI.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Scales {
    /// Metres per unit length (g₀ = A₀).
    pub length_m: f64,
    /// Seconds per unit τ.
    pub time_s: f64,
    /// Newtons per unit force.
    pub force_n: f64,
}

impl Scales {
    /// Joules per unit energy (force × length).
    pub(crate) fn energy_j(&self) -> f64 {
        self.force_n * self.length_m
    }
    /// Watts per unit power.
    pub(crate) fn power_w(&self) -> f64 {
        self.energy_j() / self.time_s
    }
    /// Frequency in Hz of a dimensionless angular frequency Ω.
    pub(crate) fn frequency_hz(&self, omega: f64) -> f64 {
        omega / (TAU * self.time_s)
    }
    /// Dimensionless Ω of a frequency in Hz.
    pub fn omega(&self, hz: f64) -> f64 {
        TAU * hz * self.time_s
    }
}

/// The calibrated first-mode values of a probe (given, or derived from the geometry).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Calibration {
    /// k (N/m), the first-mode stiffness at the tip.
    pub spring_constant: f64,
    /// f₀ (Hz), the first free resonance with the tip mass.
    pub resonance_frequency: f64,
    /// Q₁.
    pub quality_factor: f64,
    /// Q_j per mode when given (beam).
    pub quality_factors: Option<Vec<f64>>,
    /// α1, tip-mass ratio of the beam (0 for the point mass).
    pub tip_mass_ratio: f64,
    /// The static stiffness (N/m): the beam's 3EI/L³ (from the geometry, or from a calibrated
    /// k as 3k/k̃₁, k̃₁ the Galerkin beam's modal stiffness at the tip in EI/L³; for comparison
    /// with k), the point mass's its spring k.
    pub static_spring_constant: f64,
}

/// A resolved probe: the model's parameters and the scales to SI.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Probe {
    /// The dimensionless set (α's, Ω, law, structure).
    pub params: Params,
    /// Scales back to SI.
    pub scales: Scales,
    /// The cantilever's first-mode calibration.
    pub calibration: Calibration,
    /// A₀ (m).
    pub free_amplitude: f64,
    /// Drive frequency f (Hz).
    pub drive_frequency: f64,
    /// The further components of a multifrequency drive, in SI (empty for one frequency).
    pub components: Vec<DriveComponentSi>,
    /// Rest tip–sample distance z_c (m).
    pub z_c: f64,
    /// Whether the file gives `[sample] z_c` (else z_c is its default A₀; a resonance curve
    /// then defaults to the free resonance, `crate::request::curves::free_resonance_base`).
    #[serde(skip)]
    pub z_c_in_file: bool,
    /// The fluid of `[medium]` and each mode's loading (`None` without the section).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub medium: Option<MediumReport>,
    /// The Tabor parameter μ of a DMT, electrostatic or JKR sample (`tabor_parameter`; `None`
    /// for the other laws).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tabor_parameter: Option<f64>,
    /// Values of the file outside the range AFM probes and samples typically take (inside
    /// their physical range, which the reader enforces): each a warning naming the likely
    /// unit slip, carried by [`Probe::warnings`].
    #[serde(skip)]
    pub input_warnings: Vec<String>,
    /// The tip radius R (m) of a law whose contact is Hertz's paraboloid (hertz, dmt,
    /// electrostatic, jkr, capillary; `None` for the others: linear and SLS springs, impact):
    /// what `Probe::indentation_warnings` holds an indentation against.
    #[serde(skip)]
    pub tip_radius: Option<f64>,
    /// Whether `[drive] mode = "off-resonance"` (PeakForce tapping): then
    /// [`Probe::free_amplitude`] is the modulation amplitude A_m (m, the length unit g₀),
    /// [`Probe::drive_frequency`] the modulation frequency f_m (Hz), α2 = 1 and the drive is
    /// [`Excitation::Sample`] (or, with `modulated = "base"`, the beam's base drive).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub off_resonance: bool,
    /// The sample's and tip's SI inputs as the file gives them (resolved defaults included):
    /// what `fit` starts its parameters from, by their probe keys.
    #[serde(skip)]
    pub sample_inputs: SampleInputs,
    /// The keys a quasi-static read ([`ProbeNeeds::Static`]) stood in for because the file
    /// omits them (`[cantilever].quality_factor`, `[drive]`, …): values no quasi-static
    /// analysis reads, which an analysis of the oscillating lever refuses. Empty otherwise.
    #[serde(skip)]
    pub assumed: Vec<String>,
    /// The lever's plan, length L and width b (m), where the file gives it (the geometry, or
    /// `[cantilever] length` and `width` with calibrated values): what Sader's method needs.
    #[serde(skip)]
    pub plan: Option<(f64, f64)>,
}

/// What a request uses of a probe ([`crate::request::run::Request::probe_needs`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ProbeNeeds {
    /// The oscillating lever: `model`, the cantilever's resonance and Q, and `[drive]`, as
    /// every dynamic analysis does.
    #[default]
    Oscillation,
    /// Tapping: the lever driven near a resonance at its free amplitude A₀ (an approach
    /// curve, FM, bimodal, an AM image), which a probe of `[drive] mode = "off-resonance"`
    /// (PeakForce tapping) does not have (`Probe::serves`).
    Tapping,
    /// A quasi-static force curve: the spring constant, the tip and the sample only. The
    /// resonance, Q, `model` and `[drive]` a file omits are stood in for by
    /// `STATIC_STAND_INS` and named in [`Probe::assumed`].
    Static,
}

/// The values a quasi-static read ([`ProbeNeeds::Static`]) puts where the file omits them:
/// key (`section.key`, `model` at the root) and TOML value. Nothing quasi-static reads them;
/// they are typical values (a 50 kHz point-mass lever of Q 100 at 10 nm) only so that the
/// probe resolves.
pub(crate) const STATIC_STAND_INS: [(&str, f64); 3] = [
    ("cantilever.resonance_frequency", 50e3),
    ("cantilever.quality_factor", 100.0),
    ("drive.free_amplitude", 10e-9),
];

/// The sample's and tip's SI inputs of a probe file by their keys (`None` where the law takes
/// none): the start values of `fit`'s parameters (the request `fit`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SampleInputs {
    /// `[sample] youngs_modulus` (Pa).
    pub youngs_modulus: Option<f64>,
    /// `[sample] poisson_ratio`.
    pub poisson_ratio: Option<f64>,
    /// `[tip] youngs_modulus` (Pa; silicon's when omitted).
    pub tip_youngs_modulus: Option<f64>,
    /// `[tip] poisson_ratio` (silicon's when omitted).
    pub tip_poisson_ratio: Option<f64>,
    /// `[tip] radius` (m).
    pub radius: Option<f64>,
    /// `[sample] adhesion_energy` (J/m²; JKR's W, from H/(12πa₀²) when the file gives hamaker).
    pub adhesion_energy: Option<f64>,
    /// `[sample] hamaker` (J).
    pub hamaker: Option<f64>,
    /// `[sample] intermolecular_distance` (m).
    pub intermolecular_distance: Option<f64>,
    /// `[sample] stiffness` (N/m): the linear, Kelvin–Voigt and SLS laws' spring (SLS: the
    /// relaxed spring k₁).
    pub stiffness: Option<f64>,
    /// `[sample] maxwell_stiffness` (N/m, the SLS Maxwell arm's k₂).
    pub maxwell_stiffness: Option<f64>,
    /// `[sample] relaxation_time` (s, the SLS Maxwell arm's τ_r = η/k₂).
    pub relaxation_time: Option<f64>,
    /// `[tip] shape` with its angle (the paraboloid when omitted).
    pub(crate) tip_shape: TipShape,
}

/// The indentation, as a fraction of the tip radius, beyond which the paraboloid contact of
/// Hertz, DMT and JKR no longer describes a spherical tip: the paraboloid approximates the
/// sphere for contact radii a = √(Rδ) ≪ R (Johnson, *Contact Mechanics*, 1985, §4.2), and at
/// δ = R/2 the contact radius is already 0.7 R (and a real tip's apex turns conical).
pub(crate) const INDENTATION_VALIDITY: f64 = 0.5;

/// Above this Tabor parameter the contact is JKR's (Johnson & Greenwood, *J. Colloid Interface
/// Sci.* 192 (1997) 326, adhesion map: DMT below 0.1, the transition between, JKR above 5).
pub(crate) const TABOR_JKR: f64 = 5.0;

/// Below this Tabor parameter the contact is DMT's (Johnson & Greenwood 1997).
pub(crate) const TABOR_DMT: f64 = 0.1;

/// The surface tension of water at 25 °C, 0.07197 N/m (CRC Handbook of Chemistry and Physics,
/// 97th ed. 2016, "Surface tension of common liquids"): the capillary law's default.
pub(crate) const WATER_SURFACE_TENSION: f64 = 0.07197;

/// The work of adhesion W = H/(12πz₀²) (J/m²) from the Hamaker constant H (J) at the
/// equilibrium separation z₀ (m) (Israelachvili, *Intermolecular and Surface Forces*, 3rd ed.
/// 2011, §13.6).
pub(crate) fn work_of_adhesion(hamaker: f64, z0: f64) -> f64 {
    hamaker / (12.0 * std::f64::consts::PI * z0 * z0)
}

/// The Tabor parameter μ = (R W²/(E*² z₀³))^{1/3} (Tabor, *J. Colloid Interface Sci.* 58 (1977)
/// 2; Johnson & Greenwood 1997) of a sphere of radius R (m) on a sample with reduced modulus
/// E* (Pa) and work of adhesion W (J/m², e.g. [`work_of_adhesion`]) at the equilibrium
/// separation z₀ (m): which contact model applies — DMT (stiff, weakly adhesive, small tips)
/// below [`TABOR_DMT`], JKR (compliant, adhesive, large tips) above [`TABOR_JKR`].
pub(crate) fn tabor_parameter(radius: f64, e_star: f64, work: f64, z0: f64) -> f64 {
    (radius * work * work / (e_star * e_star * z0 * z0 * z0)).cbrt()
}

impl Probe {
    /// A result's validity against the contact law's assumptions: a warning when its largest
    /// indentation `indentation` (m) exceeds [`INDENTATION_VALIDITY`] × the tip radius of a
    /// paraboloid (Hertz-family) contact.
    pub(crate) fn indentation_warnings(&self, indentation: f64) -> Vec<String> {
        match self.tip_radius {
            Some(r) if indentation > INDENTATION_VALIDITY * r => vec![warning!(
                "probe.deep-indentation",
                "Keep the tip shallower: a smaller amplitude, a larger setpoint A/A₀ or a \
                 smaller peak-force setpoint (or a stiffer sample).",
                "the largest indentation, {} m, exceeds half the tip radius R = {} m: the \
                 {} law's paraboloid contact holds for indentations well below R (contact \
                 radius √(Rδ) ≪ R; Johnson 1985, §4.2), so forces and indentations there are \
                 outside the law's validity (a stiffer sample or a lighter touch keeps the tip \
                 shallower: a smaller amplitude, a larger AM setpoint A/A₀, a smaller peak-force \
                 setpoint)",
                crate::error::number(indentation),
                crate::error::number(r),
                self.params.contact_law.name()
            )],
            _ => Vec::new(),
        }
    }

    /// The probe's own warnings, which every document of it carries
    /// (`crate::report::with_si`): a DMT or electrostatic sample in JKR's regime (Tabor
    /// parameter above `TABOR_JKR`), where DMT misses the contact's neck and the adhesion
    /// hysteresis.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = self.input_warnings.clone();
        let jkr = matches!(self.params.contact_law, ContactLaw::Jkr { .. });
        if let Some(mu) = self.tabor_parameter.filter(|&mu| jkr && mu < TABOR_DMT) {
            w.push(warning!(
                "probe.tabor-dmt",
                "Give law = 'dmt' in [sample].",
                "the sample's Tabor parameter is {mu:.3} (< {TABOR_DMT}: a stiff, weakly \
                 adhesive contact, DMT's regime; Johnson & Greenwood 1997): JKR's neck is then an \
                 overestimate, law = \"dmt\" applies"
            ));
        }
        if let Some(mu) = self.tabor_parameter.filter(|&mu| !jkr && mu > TABOR_JKR) {
            w.push(warning!(
                "probe.tabor-jkr",
                "Give law = 'jkr' in [sample].",
                "the sample's Tabor parameter is {mu:.3} (> {TABOR_JKR}: a compliant, adhesive \
                 contact, JKR's regime; Johnson & Greenwood 1997): DMT misses the contact's neck \
                 and the adhesion hysteresis of each tap, so adhesion and dissipation are \
                 underestimated; law = \"jkr\" applies"
            ));
        }
        w
    }
}

/// A further drive component of a probe ([`Params::drive_components`]) in SI.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DriveComponentSi {
    /// A₀ᵢ (m), the free amplitude of the tip at this component's frequency.
    pub free_amplitude: f64,
    /// fᵢ (Hz), the frequency used: the first component's times p/q.
    pub frequency: f64,
    /// [p, q], the ratio to the first component's frequency.
    pub ratio: [u32; 2],
}

/// The fraction p/q (p ≤ 10⁶) with the smallest q ≤ 1000 within 1e-6 (relative) of `r` > 0, `None`
/// when there is none. A frequency moved by 1e-6 of itself moves the response of a mode of
/// quality factor Q by 2Q·1e-6 rad in phase (2e-3 rad at Q = 1000); the frequency used is
/// reported ([`DriveComponentSi::frequency`]).
pub(crate) fn rational_ratio(r: f64) -> Option<(u32, u32)> {
    if !(r.is_finite() && r > 0.0 && r < 1e6) {
        return None;
    }
    (1..=1000u32).find_map(|q| {
        let p = (r * f64::from(q)).round();
        let close = (1.0..=1e6).contains(&p) && ((p / f64::from(q)) - r).abs() <= 1e-6 * r;
        close.then_some((p as u32, q))
    })
}

/// The convergent p/q of the continued fraction of `r` > 0 with the largest q ≤
/// [`MAX_RATIO_DENOMINATOR`] (and p ≤ [`crate::params::MAX_RATIO_NUMERATOR`]): the best rational approximation
/// with such a denominator, |r − p/q| < 1/(q q′) with q′ > 10⁶ the next convergent's
/// denominator (Khinchin, *Continued Fractions*, 1964, Thm. 9), so within about 1e-12 of r
/// unless r itself has a small denominator. `None` for r outside (0, 10⁶) or not finite.
pub(crate) fn convergent(r: f64) -> Option<(u32, u32)> {
    convergent_within(r, MAX_RATIO_DENOMINATOR)
}

/// The lever of the cantilever section, before the model is known.
#[derive(Debug, Clone, Copy)]
enum Beam {
    Calibrated {
        k: f64,
        f0: f64,
        alpha1: f64,
        /// Length and width (m) when given (what `[medium]` needs).
        plan: Option<(f64, f64)>,
    },
    /// The beam's width b (m, what `[medium]` needs) and the beam in SI.
    Geometry {
        width: f64,
        si: crate::units::BeamSi,
    },
}

impl Beam {
    /// The lever's plan (L, b) (m), where known.
    fn plan(&self) -> Option<(f64, f64)> {
        match self {
            Beam::Calibrated { plan, .. } => *plan,
            Beam::Geometry { width, si } => Some((si.length, *width)),
        }
    }
    /// The beam's tip-mass ratio α1: given, or from the geometry.
    fn tip_mass_ratio(&self) -> f64 {
        match self {
            Beam::Calibrated { alpha1, .. } => *alpha1,
            Beam::Geometry { si, .. } => si.tip_mass_ratio(),
        }
    }
}

/// The cantilever section in SI: the lever, Q₁ as given, the per-mode Q_j when given, and the
/// eigenmode model's per-mode k_j (N/m) and f_j (Hz).
struct Cantilever {
    beam: Beam,
    q1: f64,
    qs: Option<Vec<f64>>,
    eigen: Option<(Vec<f64>, Vec<f64>)>,
}

/// The drive section in SI: the first component's A₀ (m) and f (Hz, `None`: f₀), and the
/// further components' (A₀ᵢ, fᵢ) (fᵢ NaN: the mode's free resonance).
struct Drive {
    free_amplitude: f64,
    frequency: Option<f64>,
    components: Vec<(f64, f64)>,
    excitation: Excitation,
    /// `[drive] mode = "off-resonance"`: A₀ is the modulation amplitude A_m, f the modulation
    /// frequency f_m, and α2 = 1 (the modulation's amplitude in units of g₀ = A_m).
    off_resonance: bool,
}

/// The sample section in SI: the law's name, the values its [`crate::contact::Law::from_si`]
/// reads (the scales g₀, F_s and t_s are the probe's, set when it is resolved), z_c, and the
/// elastic constants as given: sample E (Pa) and ν, tip E (Pa) and ν.
struct Sample {
    law: String,
    si: crate::contact::SampleSi,
    z_c: Option<f64>,
    elastic: Option<[f64; 4]>,
    /// `[tip] shape`.
    shape: TipShape,
}

/// A probe as a front end receives it: a file (the command line's `--probe FILE`, Python's
/// `probe=path`), TOML text (`probe="[cantilever]\n…"`) or its table (Python's `probe={…}`).
#[derive(Debug, Clone, Copy)]
pub enum ProbeSource<'a> {
    /// A probe file.
    #[cfg(feature = "files")]
    Path(&'a Path),
    /// TOML text.
    Text(&'a str),
    /// A parsed TOML table (the sections `cantilever`, `tip`, `sample`, `drive` as tables).
    Table(&'a toml::Table),
}

impl<'a> ProbeSource<'a> {
    /// A front end's string argument: TOML text when it holds a line break or `=` (a key =
    /// value line; no probe text is without one), else the path of a probe file.
    #[cfg(feature = "files")]
    pub fn of_str(s: &'a str) -> Self {
        if s.contains(['\n', '=']) {
            ProbeSource::Text(s)
        } else {
            ProbeSource::Path(Path::new(s))
        }
    }

    /// How errors name the source: the path, `<string>` or `<table>`.
    pub(crate) fn origin(&self) -> String {
        match self {
            #[cfg(feature = "files")]
            ProbeSource::Path(p) => p.display().to_string(),
            ProbeSource::Text(_) => "<string>".into(),
            ProbeSource::Table(_) => "<table>".into(),
        }
    }
}

impl Probe {
    /// The TOML text of the probe `source` with `[cantilever].name` set to `cantilever` when
    /// given (the command line's `--cantilever NAME`, Python's `cantilever=`, which win over a
    /// name in the probe: [`crate::cantilevers::with_name`]) and its fluid set to `medium`
    /// (`--medium NAME`, `medium=`: [`crate::hydro::with_medium`]), checked by resolving it,
    /// so that every later [`Probe::parse_for`] of the text for `needs` succeeds; with the
    /// resolved probe.
    ///
    /// # Errors
    /// [`ProbeError::Io`] for a file that cannot be read; as [`Probe::parse`], naming the
    /// source (`ProbeSource::origin`); [`ProbeError::Invalid`] for a cantilever name that is
    /// not in the library or a `cantilever` key that is not a table.
    pub fn source_text(
        source: ProbeSource<'_>,
        (cantilever, medium): (Option<&str>, Option<&str>),
        needs: ProbeNeeds,
    ) -> Result<(String, Probe), ProbeError> {
        let origin = source.origin();
        let syntax = |message| ProbeError::Syntax {
            path: origin.clone(),
            message,
        };
        let text = match source {
            #[cfg(feature = "files")]
            ProbeSource::Path(path) => Self::read_file(path)?,
            ProbeSource::Text(t) => t.to_string(),
            ProbeSource::Table(t) => toml::to_string(t).map_err(|e| syntax(e.to_string()))?,
        };
        let text = match cantilever {
            None => text,
            Some(name) => crate::cantilevers::with_name(&text, name).map_err(syntax)?,
        };
        let text = match medium {
            None => text,
            Some(name) => crate::hydro::with_medium(&text, name).map_err(syntax)?,
        };
        let probe = Self::parse_for(&text, &origin, needs)?;
        Ok((text, probe))
    }
}

impl Probe {
    /// Read and resolve a probe file.
    ///
    /// # Errors
    /// [`ProbeError`] naming the path and every problem; [`ProbeError::File`] for a file that
    /// cannot be read, is larger than [`crate::io::MAX_INPUT_TEXT_BYTES`] or is
    /// not UTF-8 text.
    #[cfg(feature = "files")]
    pub fn load(path: &Path) -> Result<Probe, ProbeError> {
        let text = Self::read_file(path)?;
        Self::parse(&text, &path.display().to_string())
    }

    /// The text of a probe file, bounded: the one reader of [`Probe::load`] and
    /// [`Probe::source_text`] (a `/dev/zero` is refused after
    /// [`crate::io::MAX_INPUT_TEXT_BYTES`], not read until memory runs out).
    ///
    /// # Errors
    /// As [`Probe::load`].
    #[cfg(feature = "files")]
    fn read_file(path: &Path) -> Result<String, ProbeError> {
        use crate::io::{read_text, InputFileError, InputKind};
        read_text(path, InputKind::Probe).map_err(|e| match e {
            InputFileError::Io { path, message } => ProbeError::Io { path, message },
            e => ProbeError::File(e),
        })
    }

    /// Resolve a probe from TOML text; `origin` names it in errors.
    ///
    /// # Errors
    /// [`ProbeError::Syntax`] for invalid TOML, [`ProbeError::Invalid`] listing every unknown,
    /// missing or out-of-range key.
    pub fn parse(text: &str, origin: &str) -> Result<Probe, ProbeError> {
        Self::parse_for(text, origin, ProbeNeeds::Oscillation)
    }

    /// As [`Probe::parse`], for a request that uses what `needs` says
    /// (`Probe::from_table_for`).
    ///
    /// # Errors
    /// As [`Probe::parse`].
    pub fn parse_for(text: &str, origin: &str, needs: ProbeNeeds) -> Result<Probe, ProbeError> {
        Self::from_table_for(&Self::table(text, origin)?, origin, needs)
    }

    /// A probe file's TOML text as its table, unresolved (an image reads each domain's sample
    /// over it, [`crate::request::image`]); `origin` names it in errors.
    ///
    /// # Errors
    /// [`ProbeError::Syntax`] for invalid TOML (the parser's message on one line).
    pub fn table(text: &str, origin: &str) -> Result<toml::Table, ProbeError> {
        text.parse()
            .map_err(|e: toml::de::Error| ProbeError::Syntax {
                path: origin.to_string(),
                message: e.to_string().replace('\n', " "),
            })
    }

    /// Resolve a probe from its parsed TOML table (a chart sets one of its values per cell,
    /// [`crate::request::chart`]); `origin` names it in errors.
    ///
    /// # Errors
    /// As [`Probe::parse`], but for the syntax.
    pub(crate) fn from_table(root: &toml::Table, origin: &str) -> Result<Probe, ProbeError> {
        Self::from_table_for(root, origin, ProbeNeeds::Oscillation)
    }

    /// As [`Probe::from_table`], for a request that uses what `needs` says: with
    /// [`ProbeNeeds::Static`], the keys of [`STATIC_STAND_INS`] (and `model = "point-mass"`) a
    /// file omits are stood in for and named in [`Probe::assumed`].
    ///
    /// # Errors
    /// As [`Probe::from_table`].
    pub(crate) fn from_table_for(
        root: &toml::Table,
        origin: &str,
        needs: ProbeNeeds,
    ) -> Result<Probe, ProbeError> {
        // a cantilever of the library fills the keys the file leaves out
        let original = root;
        let mut root = crate::cantilevers::fill(root).map_err(|e| ProbeError::Invalid {
            path: origin.to_string(),
            problems: vec![e],
        })?;
        let assumed = match needs {
            ProbeNeeds::Static => stand_in(&mut root),
            ProbeNeeds::Oscillation | ProbeNeeds::Tapping => Vec::new(),
        };
        let mut problems = Vec::new();
        let probe = Self::read(&root, &mut problems);
        // the dynamic analyses' laws are the paraboloid's (contact::indenter)
        let shape = probe.as_ref().map(|p| p.sample_inputs.tip_shape);
        if let Some(shape) =
            shape.filter(|s| needs != ProbeNeeds::Static && *s != TipShape::Paraboloid)
        {
            problems.push(format!(
                "[tip].shape = \"{}\": the dynamic analyses take the paraboloid (the contact \
                 laws' Hertz contact); the other shapes are afmdyn fit's, on force curves",
                shape.name()
            ));
        }
        match probe {
            Some(mut p) if problems.is_empty() => {
                p.input_warnings
                    .extend(crate::cantilevers::calibration_warnings(original));
                p.assumed = assumed;
                Ok(p)
            }
            _ => {
                if problems.is_empty() {
                    problems.push("invalid probe".into());
                }
                Err(ProbeError::Invalid {
                    path: origin.to_string(),
                    problems,
                })
            }
        }
    }

    /// Whether this probe serves request `name`, which uses what `needs` says: a tapping
    /// request refuses an off-resonance (PeakForce) drive, naming `drive.mode` and what to
    /// do instead.
    ///
    /// # Errors
    /// [`crate::error::SimError::OutOfRange`] naming `drive.mode`.
    pub(crate) fn serves(
        &self,
        name: &str,
        needs: ProbeNeeds,
    ) -> Result<(), crate::error::SimError> {
        if needs == ProbeNeeds::Tapping && self.off_resonance {
            return Err(crate::error::SimError::out_of_range(
                "drive.mode",
                "off-resonance",
                format!(
                    "{name} taps near a resonance at the free amplitude A0, which a PeakForce \
                     (off-resonance) drive does not have: give the probe a tapping drive \
                     ([drive] free_amplitude and frequency), or use afmdyn peakforce or \
                     image --mode peakforce"
                ),
            ));
        }
        Ok(())
    }

    /// The rest distance z_c (m) of a parameter set under these scales.
    pub(crate) fn z_c_of(&self, params: &Params) -> f64 {
        params.rest_distance() * self.scales.length_m
    }
}

/// Stand in for the keys of [`STATIC_STAND_INS`] and the root's `model` that `root` omits,
/// for a calibrated lever (a `[cantilever]` with its `spring_constant`; a geometry, eigenmodes
/// or a missing section are left to the reader's messages): the keys stood in for.
fn stand_in(root: &mut toml::Table) -> Vec<String> {
    let calibrated = root
        .get("cantilever")
        .and_then(toml::Value::as_table)
        .is_some_and(|c| c.contains_key("spring_constant") && !c.contains_key("length"));
    if !calibrated
        || root
            .get("model")
            .is_some_and(|m| m.as_str() == Some("eigenmodes"))
    {
        return Vec::new();
    }
    let mut assumed = Vec::new();
    if !root.contains_key("model") {
        root.insert("model".into(), "point-mass".into());
        assumed.push("model".to_string());
    }
    let has_q = |c: &toml::Table| c.contains_key("quality_factors");
    for (key, value) in STATIC_STAND_INS {
        let (section, name) = key.split_once('.').expect("section.key");
        let table = root
            .entry(section)
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        let Some(t) = table.as_table_mut() else {
            continue;
        };
        let given = t.contains_key(name)
            || (name == "quality_factor" && has_q(t))
            || (section == "drive" && !t.is_empty());
        if !given {
            t.insert(name.into(), value.into());
            assumed.push(format!("[{section}].{name}"));
        }
    }
    assumed
}

type DVectorF = nalgebra::DVector<f64>;

/// ω̃₁, the mass-normalised undamped mode x₁ and k̃₁ of a parameter set
/// ([`crate::eigen::first_mode_at_tip`]).
fn first_mode(p: &Params) -> Result<(f64, DVectorF, f64), crate::ParamError> {
    let g = Galerkin::new(p)?;
    Ok(crate::eigen::first_mode_at_tip(
        g.region(Region::Free),
        g.tip(),
    ))
}

mod resolve;
mod sections;
