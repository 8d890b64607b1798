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
//! q ≤ 1000 within 1e-6 of fᵢ/f₁ ([`rational_ratio`]: a periodic drive), else the convergent
//! of fᵢ/f₁ with q ≤ 10⁶ ([`convergent`]: a quasi-periodic drive, within about 1e-12, whose
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

mod medium;
mod reader;
pub use medium::{CalibratedIn, FluidMode, MediumReport};
use reader::*;

/// ε₀, the vacuum permittivity (F/m; CODATA 2018).
pub const VACUUM_PERMITTIVITY: f64 = 8.854_187_812_8e-12;

/// The intermolecular distance a₀ of the DMT law when a probe file omits it, m
/// (Israelachvili 2011, §13.6).
pub const DEFAULT_INTERMOLECULAR_DISTANCE: f64 = 0.165e-9;

use crate::contact::ContactLaw;
use crate::galerkin::{Galerkin, Region};
use crate::model::CantileverModel;
/// The convergent of `r` with the largest denominator ≤ `max_q` (defined with the ratio limits in
/// [`crate::params`], where the time average of a stepped curve also finds it).
pub use crate::params::convergent_within;
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
pub const MAX_QUALITY_FACTOR: f64 = 1e7;

/// The largest free amplitude A₀ a probe may give (m): 10 µm, a thousand times the tapping-mode
/// amplitudes (1–100 nm). Lengths are in units of A₀, so beyond it the tip–sample lengths
/// vanish against it.
pub const MAX_FREE_AMPLITUDE: f64 = 1e-5;

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
    pub fn energy_j(&self) -> f64 {
        self.force_n * self.length_m
    }
    /// Watts per unit power.
    pub fn power_w(&self) -> f64 {
        self.energy_j() / self.time_s
    }
    /// Frequency in Hz of a dimensionless angular frequency Ω.
    pub fn frequency_hz(&self, omega: f64) -> f64 {
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
    /// then defaults to the free resonance, [`crate::request::curves::free_resonance_base`]).
    #[serde(skip)]
    pub z_c_in_file: bool,
    /// The fluid of `[medium]` and each mode's loading (`None` without the section).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub medium: Option<MediumReport>,
    /// The Tabor parameter μ of a DMT, electrostatic or JKR sample ([`tabor_parameter`]; `None`
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
    /// what [`Probe::indentation_warnings`] holds an indentation against.
    #[serde(skip)]
    pub tip_radius: Option<f64>,
}

/// The indentation, as a fraction of the tip radius, beyond which the paraboloid contact of
/// Hertz, DMT and JKR no longer describes a spherical tip: the paraboloid approximates the
/// sphere for contact radii a = √(Rδ) ≪ R (Johnson, *Contact Mechanics*, 1985, §4.2), and at
/// δ = R/2 the contact radius is already 0.7 R (and a real tip's apex turns conical).
pub const INDENTATION_VALIDITY: f64 = 0.5;

/// Above this Tabor parameter the contact is JKR's (Johnson & Greenwood, *J. Colloid Interface
/// Sci.* 192 (1997) 326, adhesion map: DMT below 0.1, the transition between, JKR above 5).
pub const TABOR_JKR: f64 = 5.0;

/// Below this Tabor parameter the contact is DMT's (Johnson & Greenwood 1997).
pub const TABOR_DMT: f64 = 0.1;

/// The surface tension of water at 25 °C, 0.07197 N/m (CRC Handbook of Chemistry and Physics,
/// 97th ed. 2016, "Surface tension of common liquids"): the capillary law's default.
pub const WATER_SURFACE_TENSION: f64 = 0.07197;

/// The work of adhesion W = H/(12πz₀²) (J/m²) from the Hamaker constant H (J) at the
/// equilibrium separation z₀ (m) (Israelachvili, *Intermolecular and Surface Forces*, 3rd ed.
/// 2011, §13.6).
pub fn work_of_adhesion(hamaker: f64, z0: f64) -> f64 {
    hamaker / (12.0 * std::f64::consts::PI * z0 * z0)
}

/// The Tabor parameter μ = (R W²/(E*² z₀³))^{1/3} (Tabor, *J. Colloid Interface Sci.* 58 (1977)
/// 2; Johnson & Greenwood 1997) of a sphere of radius R (m) on a sample with reduced modulus
/// E* (Pa) and work of adhesion W (J/m², e.g. [`work_of_adhesion`]) at the equilibrium
/// separation z₀ (m): which contact model applies — DMT (stiff, weakly adhesive, small tips)
/// below [`TABOR_DMT`], JKR (compliant, adhesive, large tips) above [`TABOR_JKR`].
pub fn tabor_parameter(radius: f64, e_star: f64, work: f64, z0: f64) -> f64 {
    (radius * work * work / (e_star * e_star * z0 * z0 * z0)).cbrt()
}

impl Probe {
    /// A result's validity against the contact law's assumptions: a warning when its largest
    /// indentation `indentation` (m) exceeds [`INDENTATION_VALIDITY`] × the tip radius of a
    /// paraboloid (Hertz-family) contact.
    pub fn indentation_warnings(&self, indentation: f64) -> Vec<String> {
        match self.tip_radius {
            Some(r) if indentation > INDENTATION_VALIDITY * r => vec![format!(
                "the largest indentation, {} m, exceeds half the tip radius R = {} m: the \
                 {} law's paraboloid contact holds for indentations well below R (contact \
                 radius √(Rδ) ≪ R; Johnson 1985, §4.2), so forces and indentations there are \
                 outside the law's validity (a stiffer sample, a smaller amplitude or a larger \
                 setpoint keeps the tip shallower)",
                crate::error::number(indentation),
                crate::error::number(r),
                self.params.contact_law.name()
            )],
            _ => Vec::new(),
        }
    }

    /// The probe's own warnings, which every document of it carries
    /// ([`crate::report::with_si`]): a DMT or electrostatic sample in JKR's regime (Tabor
    /// parameter above [`TABOR_JKR`]), where DMT misses the contact's neck and the adhesion
    /// hysteresis.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = self.input_warnings.clone();
        let jkr = matches!(self.params.contact_law, ContactLaw::Jkr { .. });
        if let Some(mu) = self.tabor_parameter.filter(|&mu| jkr && mu < TABOR_DMT) {
            w.push(format!(
                "the sample's Tabor parameter is {mu:.3} (< {TABOR_DMT}: a stiff, weakly \
                 adhesive contact, DMT's regime; Johnson & Greenwood 1997): JKR's neck is then an \
                 overestimate, law = \"dmt\" applies"
            ));
        }
        if let Some(mu) = self.tabor_parameter.filter(|&mu| !jkr && mu > TABOR_JKR) {
            w.push(format!(
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
pub fn rational_ratio(r: f64) -> Option<(u32, u32)> {
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
pub fn convergent(r: f64) -> Option<(u32, u32)> {
    convergent_within(r, MAX_RATIO_DENOMINATOR)
}

/// The cantilever section, before the model is known.
#[derive(Debug, Clone, Copy)]
enum Beam {
    Calibrated {
        k: f64,
        f0: f64,
        alpha1: f64,
        /// Length and width (m) when given (what `[medium]` needs).
        plan: Option<(f64, f64)>,
    },
    Geometry {
        length: f64,
        width: f64,
        ei: f64,
        mass_per_length: f64,
        tip_mass: f64,
    },
}

/// The drive section in SI: the first component's A₀ (m) and f (Hz, `None`: f₀), and the
/// further components' (A₀ᵢ, fᵢ) (fᵢ NaN: the mode's free resonance).
struct Drive {
    free_amplitude: f64,
    frequency: Option<f64>,
    components: Vec<(f64, f64)>,
    excitation: Excitation,
}

/// The sample section in SI.
struct Sample {
    law: String,
    e_star: Option<f64>,
    radius: Option<f64>,
    hamaker: Option<f64>,
    a0: Option<f64>,
    viscosity: Option<f64>,
    stiffness: Option<f64>,
    damping: Option<f64>,
    restitution: Option<f64>,
    /// The electrostatic law's voltage across the gap, bias − contact potential (V).
    voltage: Option<f64>,
    /// JKR's work of adhesion W (J/m²).
    adhesion_energy: Option<f64>,
    /// The capillary meniscus: volume V (m³), surface tension γ (N/m), contact angle θ (rad).
    meniscus: Option<(f64, f64, f64)>,
    /// The SLS sample's Maxwell arm: spring k₂ (N/m) and relaxation time τ_r = η/k₂ (s).
    maxwell: Option<(f64, f64)>,
    z_c: Option<f64>,
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
    pub fn origin(&self) -> String {
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
    /// so that every later [`Probe::parse`] of the text succeeds; with the resolved probe.
    ///
    /// # Errors
    /// [`ProbeError::Io`] for a file that cannot be read; as [`Probe::parse`], naming the
    /// source ([`ProbeSource::origin`]); [`ProbeError::Invalid`] for a cantilever name that is
    /// not in the library or a `cantilever` key that is not a table.
    pub fn source_text(
        source: ProbeSource<'_>,
        cantilever: Option<&str>,
        medium: Option<&str>,
    ) -> Result<(String, Probe), ProbeError> {
        let origin = source.origin();
        let text = match source {
            #[cfg(feature = "files")]
            ProbeSource::Path(path) => Self::read_file(path)?,
            ProbeSource::Text(t) => t.to_string(),
            ProbeSource::Table(t) => toml::to_string(t).map_err(|e| ProbeError::Syntax {
                path: origin.clone(),
                message: e.to_string(),
            })?,
        };
        let text = match cantilever {
            None => text,
            Some(name) => crate::cantilevers::with_name(&text, name).map_err(|message| {
                ProbeError::Syntax {
                    path: origin.clone(),
                    message,
                }
            })?,
        };
        let text = match medium {
            None => text,
            Some(name) => {
                crate::hydro::with_medium(&text, name).map_err(|message| ProbeError::Syntax {
                    path: origin.clone(),
                    message,
                })?
            }
        };
        let probe = Self::parse(&text, &origin)?;
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
        Self::from_table(&Self::table(text, origin)?, origin)
    }

    /// A probe file's TOML text as its table, unresolved (an image reads each domain's sample
    /// over it, [`crate::request::image::image`]); `origin` names it in errors.
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
    pub fn from_table(root: &toml::Table, origin: &str) -> Result<Probe, ProbeError> {
        // a cantilever of the library fills the keys the file leaves out
        let root = crate::cantilevers::fill(root).map_err(|e| ProbeError::Invalid {
            path: origin.to_string(),
            problems: vec![e],
        })?;
        let mut problems = Vec::new();
        let probe = Self::read(&root, &mut problems);
        match probe {
            Some(p) if problems.is_empty() => Ok(p),
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

    fn read(root: &toml::Table, problems: &mut Vec<String>) -> Option<Probe> {
        let mut r = Reader {
            problems,
            warnings: Vec::new(),
        };
        r.unknown(
            root,
            "",
            &[
                "model",
                "modes",
                "cantilever",
                "tip",
                "sample",
                "drive",
                "medium",
            ],
        );
        let structure = match r.string(root, "", "model") {
            None if !root.contains_key("model") => {
                r.problems
                    .push("missing key model (\"beam\", \"point-mass\" or \"eigenmodes\")".into());
                None
            }
            None => None,
            Some(s) => match s.parse::<Structure>() {
                Ok(x) => Some(x),
                Err(e) => {
                    r.problems.push(e);
                    None
                }
            },
        };
        let modes = match root.get("modes") {
            None => None,
            Some(toml::Value::Integer(i)) if (1..=MAX_MODES as i64).contains(i) => {
                Some(*i as usize)
            }
            Some(v) => {
                r.problems
                    .push(format!("modes = {v}: must be an integer in 1..=20"));
                None
            }
        };
        let modes = match (structure, modes) {
            (Some(Structure::PointMass), Some(n)) if n != 1 => {
                r.problems.push(format!(
                    "modes = {n}: the point-mass model has one mode (omit modes)"
                ));
                None
            }
            (Some(Structure::PointMass), _) => Some(1),
            // the eigenmode model: one mode per entry of the cantilever's arrays
            (Some(Structure::Eigenmodes), n) => {
                let len = root
                    .get("cantilever")
                    .and_then(|c| c.get("spring_constant"))
                    .and_then(toml::Value::as_array)
                    .map(Vec::len);
                match (n, len) {
                    (Some(n), Some(len)) if n != len => {
                        r.problems.push(format!(
                            "modes = {n}: the eigenmode model has one mode per entry of \
                             [cantilever].spring_constant ({len}; omit modes)"
                        ));
                        None
                    }
                    (_, Some(len)) if (1..=MAX_MODES).contains(&len) => Some(len),
                    (_, Some(len)) => {
                        r.problems.push(format!(
                            "[cantilever].spring_constant has {len} values: give 1..=20"
                        ));
                        None
                    }
                    (_, None) => None,
                }
            }
            // (a modes key that is present but invalid was reported above)
            (Some(Structure::Beam), None) if !root.contains_key("modes") => {
                r.problems
                    .push("missing key modes (number of Galerkin modes, 1..=20)".into());
                None
            }
            (_, n) => n,
        };

        // [cantilever]
        let cant = r.table(root, "cantilever", true);
        let mut eigen = None;
        let (beam, q1, qs) = match (cant, structure) {
            (Some(c), Some(Structure::Eigenmodes)) => match Self::read_eigenmodes(&mut r, c) {
                Some((k, f, q)) => {
                    let beam = Beam::Calibrated {
                        k: k[0],
                        f0: f[0],
                        alpha1: 0.0,
                        plan: Self::read_plan(&mut r, c),
                    };
                    let q1 = q[0];
                    eigen = Some((k, f));
                    (Some(beam), Some(q1), Some(q))
                }
                None => (None, None, None),
            },
            (Some(c), _) => Self::read_cantilever(&mut r, c),
            (None, _) => (None, None, None),
        };
        // [tip]
        let tip = r.table(root, "tip", false);
        let mut tip_e = None;
        let mut tip_nu = None;
        let mut radius = None;
        if let Some(t) = tip {
            r.unknown(t, "tip", &["radius", "youngs_modulus", "poisson_ratio"]);
            radius = r.optional(t, "tip", "radius", "m", POSITIVE);
            tip_e = r.optional(t, "tip", "youngs_modulus", "Pa", POSITIVE);
            tip_nu = r.optional(t, "tip", "poisson_ratio", "1", POISSON);
            // a silicon tip where the section omits its elastic constants (the one materials
            // table, crate::units::SILICON_TIP)
            if !t.contains_key("youngs_modulus") {
                tip_e = Some(crate::cantilevers::SILICON_YOUNGS_MODULUS);
            }
            if !t.contains_key("poisson_ratio") {
                tip_nu = Some(crate::cantilevers::SILICON_POISSON_RATIO);
            }
        }
        // [sample]
        let sample = r
            .table(root, "sample", true)
            .and_then(|s| Self::read_sample(&mut r, s, tip, radius, tip_e, tip_nu));
        // [drive]
        let drive = r.table(root, "drive", true);
        let mut excitation = Excitation::Base;
        let (a0, freq, extra) = match drive {
            Some(d) => {
                r.unknown(d, "drive", &["free_amplitude", "frequency", "excitation"]);
                if let Some(e) = r.string(d, "drive", "excitation") {
                    match e.parse::<Excitation>() {
                        Ok(x) => excitation = x,
                        Err(m) => r.problems.push(format!("[drive].{m}")),
                    }
                }
                Self::read_drive(&mut r, d)
            }
            None => (None, None, Vec::new()),
        };
        if excitation == Excitation::Tip && structure.is_some_and(Structure::is_lumped) {
            r.problems.push(
                "[drive].excitation = \"tip\": the point-mass and eigenmode models are always \
                 driven by a force at the tip (omit excitation)"
                    .into(),
            );
        }
        // [medium]
        let medium = r
            .table(root, "medium", false)
            .and_then(|t| medium::read(&mut r, t));
        let medium_given = root.contains_key("medium");
        // lengths are in units of A₀: an amplitude of metres makes every other length vanish
        // and the motion unresolvable (a probe with A₀ = 1 m ran for minutes; issue 27)
        if extra.iter().any(|&(a, _)| a > MAX_FREE_AMPLITUDE) {
            r.problems.push(
                "[drive].free_amplitude: each component must be ≤ 1e-5 m (10 µm; tapping-mode \
                 amplitudes are nanometres)"
                    .into(),
            );
        }
        let a0 = match a0 {
            Some(a) if a > MAX_FREE_AMPLITUDE => {
                r.problems.push(format!(
                    "[drive].free_amplitude = {} m: must be ≤ 1e-5 m (10 µm; tapping-mode \
                     amplitudes are nanometres)",
                    crate::error::number(a)
                ));
                None
            }
            a => a,
        };
        if let (Some(Structure::PointMass), Some(_)) = (structure, &qs) {
            r.problems.push(
                "[cantilever].quality_factors: the point-mass model has one mode (use quality_factor)"
                    .into(),
            );
        }
        // the count as written (an entry refused above is still one value)
        let written = match cant.and_then(|c| c.get("quality_factors")) {
            Some(toml::Value::Array(a)) => Some(a.len()),
            _ => None,
        };
        if let (Some(n), Some(len)) = (modes, written) {
            if len != n {
                r.problems.push(format!(
                    "[cantilever].quality_factors has {len} values: give one per mode (modes = {n})"
                ));
            }
        }
        if !r.problems.is_empty() || (medium_given && medium.is_none()) {
            return None;
        }
        let (structure, modes, beam, q1, sample, a0) =
            (structure?, modes?, beam?, q1?, sample?, a0?);
        let drive = Drive {
            free_amplitude: a0,
            frequency: freq,
            components: extra,
            excitation,
        };
        match Self::resolve(structure, modes, beam, q1, qs, eigen, sample, drive, medium) {
            Ok(p) => Some(Probe {
                input_warnings: [std::mem::take(&mut r.warnings), p.input_warnings.clone()]
                    .concat(),
                ..p
            }),
            Err(e) => {
                r.problems.push(e);
                None
            }
        }
    }

    /// `[drive]`: `free_amplitude` (m) and `frequency` (Hz) as numbers (one component), or as
    /// arrays of equal length (a multifrequency drive, at most 1 + [`MAX_DRIVE_COMPONENTS`]
    /// components; `frequency` may be omitted, each component then at its mode's free
    /// resonance). Returns A₀ and f of the first component and (A₀ᵢ, fᵢ) of the others (fᵢ NaN
    /// where omitted).
    #[allow(clippy::type_complexity)]
    fn read_drive(
        r: &mut Reader<'_>,
        d: &toml::Table,
    ) -> (Option<f64>, Option<f64>, Vec<(f64, f64)>) {
        const S: &str = "drive";
        let arrays = matches!(d.get("free_amplitude"), Some(toml::Value::Array(_)))
            || matches!(d.get("frequency"), Some(toml::Value::Array(_)));
        if !arrays {
            return (
                r.required(d, S, "free_amplitude", "m", POSITIVE),
                r.optional(d, S, "frequency", "Hz", POSITIVE),
                Vec::new(),
            );
        }
        let mut array = |key: &str, unit: &str| -> Option<Vec<f64>> {
            let a = match d.get(key) {
                Some(toml::Value::Array(a)) => a,
                _ => {
                    r.problems.push(format!(
                        "[drive].{key} must be an array ({unit}), one value per component, \
                         when the other key is"
                    ));
                    return None;
                }
            };
            if a.is_empty() || a.len() > 1 + MAX_DRIVE_COMPONENTS {
                r.problems.push(format!(
                    "[drive].{key} has {} values: give 1 to {} components",
                    a.len(),
                    1 + MAX_DRIVE_COMPONENTS
                ));
                return None;
            }
            let mut v = Vec::with_capacity(a.len());
            for (i, x) in a.iter().enumerate() {
                match x.as_float().or(x.as_integer().map(|i| i as f64)) {
                    Some(y) if y.is_finite() && y > 0.0 => {
                        let key_i = format!("{key}[{i}]");
                        if let Some(hint) = scale_hint(S, key, y) {
                            r.problems
                                .push(format!("[drive].{key_i} = {y} ({unit}): {hint}"));
                        } else {
                            v.push(y);
                        }
                    }
                    _ => r.problems.push(format!(
                        "[drive].{key}[{i}] = {x} ({unit}): must be finite and > 0"
                    )),
                }
            }
            (v.len() == a.len()).then_some(v)
        };
        let amplitudes = array("free_amplitude", "m");
        let frequencies = if d.contains_key("frequency") {
            array("frequency", "Hz").map(Some)
        } else {
            Some(None)
        };
        let (Some(amplitudes), Some(frequencies)) = (amplitudes, frequencies) else {
            return (None, None, Vec::new());
        };
        if let Some(f) = &frequencies {
            if f.len() != amplitudes.len() {
                r.problems.push(format!(
                    "[drive]: free_amplitude and frequency have {} and {} values: give one of \
                     each per component",
                    amplitudes.len(),
                    f.len()
                ));
                return (None, None, Vec::new());
            }
        }
        let f = |i: usize| frequencies.as_ref().map_or(f64::NAN, |f| f[i]);
        let extra = (1..amplitudes.len())
            .map(|i| (amplitudes[i], f(i)))
            .collect();
        (
            Some(amplitudes[0]),
            frequencies.as_ref().map(|f| f[0]),
            extra,
        )
    }

    /// The eigenmode model's `[cantilever]`: `spring_constant`, `resonance_frequency` and
    /// `quality_factor` as arrays of equal length, one entry per mode (N/m, Hz, 1), the
    /// frequencies increasing.
    #[allow(clippy::type_complexity)]
    fn read_eigenmodes(
        r: &mut Reader<'_>,
        c: &toml::Table,
    ) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        const S: &str = "cantilever";
        r.unknown(
            c,
            S,
            &[
                "spring_constant",
                "resonance_frequency",
                "quality_factor",
                "length",
                "width",
            ],
        );
        let mut array = |key: &str, max: f64| -> Option<Vec<f64>> {
            let Some(toml::Value::Array(a)) = c.get(key) else {
                r.problems.push(format!(
                    "[cantilever].{key} must be an array, one value per mode (the eigenmode \
                     model)"
                ));
                return None;
            };
            let mut v = Vec::with_capacity(a.len());
            for (i, x) in a.iter().enumerate() {
                match x.as_float().or(x.as_integer().map(|i| i as f64)) {
                    Some(y) if y.is_finite() && y > 0.0 && y <= max => v.push(y),
                    _ => r.problems.push(format!(
                        "[cantilever].{key}[{i}] = {x}: must be a number in (0, {max:e}]"
                    )),
                }
            }
            (v.len() == a.len()).then_some(v)
        };
        let k = array("spring_constant", 1e6);
        let f = array("resonance_frequency", 1e10);
        let q = array("quality_factor", MAX_QUALITY_FACTOR);
        let (k, f, q) = (k?, f?, q?);
        if k.len() != f.len() || k.len() != q.len() {
            r.problems.push(format!(
                "[cantilever]: spring_constant, resonance_frequency and quality_factor have \
                 {}, {} and {} values: give one of each per mode",
                k.len(),
                f.len(),
                q.len()
            ));
            return None;
        }
        if k.is_empty() {
            r.problems
                .push("[cantilever].spring_constant is empty: give one value per mode".into());
            return None;
        }
        if f.windows(2).any(|w| w[1] <= w[0]) {
            r.problems
                .push("[cantilever].resonance_frequency must increase from mode to mode".into());
            return None;
        }
        Some((k, f, q))
    }

    /// A calibrated lever's plan, `[cantilever] length` and `width` (m), both or neither: what
    /// `[medium]` needs.
    fn read_plan(r: &mut Reader<'_>, c: &toml::Table) -> Option<(f64, f64)> {
        const S: &str = "cantilever";
        let length = r.optional(c, S, "length", "m", POSITIVE);
        let width = r.optional(c, S, "width", "m", POSITIVE);
        if c.contains_key("length") != c.contains_key("width") {
            r.problems.push(
                "[cantilever]: give both length and width (m, the lever's plan) or neither".into(),
            );
        }
        length.zip(width)
    }

    #[allow(clippy::type_complexity)]
    fn read_cantilever(
        r: &mut Reader<'_>,
        c: &toml::Table,
    ) -> (Option<Beam>, Option<f64>, Option<Vec<f64>>) {
        const S: &str = "cantilever";
        const CAL: [&str; 3] = ["spring_constant", "resonance_frequency", "tip_mass_ratio"];
        const GEO: [&str; 6] = [
            "length",
            "width",
            "thickness",
            "youngs_modulus",
            "density",
            "tip_mass",
        ];
        let mut known: Vec<&str> = CAL.iter().chain(GEO.iter()).copied().collect();
        known.extend(["quality_factor", "quality_factors"]);
        r.unknown(c, S, &known);
        let has_cal = CAL[..2].iter().any(|k| c.contains_key(*k));
        // length and width may come with calibrated values: the plan `[medium]` needs
        let has_geo = GEO
            .iter()
            .any(|k| c.contains_key(*k) && !(has_cal && matches!(*k, "length" | "width")));
        let beam = match (has_cal, has_geo) {
            (true, true) => {
                r.problems.push(
                    "[cantilever]: give either calibrated values (spring_constant, \
                     resonance_frequency) or the geometry (length, width, thickness, \
                     youngs_modulus, density, tip_mass), not both"
                        .into(),
                );
                None
            }
            (false, true) => {
                let length = r.required(c, S, "length", "m", POSITIVE);
                let width = r.required(c, S, "width", "m", POSITIVE);
                let thickness = r.required(c, S, "thickness", "m", POSITIVE);
                let e = r.required(c, S, "youngs_modulus", "Pa", POSITIVE);
                let rho = r.required(c, S, "density", "kg/m^3", POSITIVE);
                let tip_mass = r.optional(c, S, "tip_mass", "kg", NON_NEGATIVE);
                match (length, width, thickness, e, rho) {
                    (Some(l), Some(b), Some(h), Some(e), Some(rho)) => Some(Beam::Geometry {
                        length: l,
                        width: b,
                        ei: e * b * h.powi(3) / 12.0,
                        mass_per_length: rho * b * h,
                        tip_mass: tip_mass.unwrap_or(0.0),
                    }),
                    _ => None,
                }
            }
            _ => {
                let k = r.required(c, S, "spring_constant", "N/m", POSITIVE);
                let f0 = r.required(c, S, "resonance_frequency", "Hz", POSITIVE);
                let alpha1 = r
                    .optional(c, S, "tip_mass_ratio", "1", NON_NEGATIVE)
                    .unwrap_or(0.0);
                let plan = Self::read_plan(r, c);
                match (k, f0) {
                    (Some(k), Some(f0)) => Some(Beam::Calibrated {
                        k,
                        f0,
                        alpha1,
                        plan,
                    }),
                    _ => None,
                }
            }
        };
        let qs = match c.get("quality_factors") {
            None => None,
            Some(toml::Value::Array(a)) => {
                let mut v = Vec::with_capacity(a.len());
                for (i, x) in a.iter().enumerate() {
                    match x.as_float().or(x.as_integer().map(|i| i as f64)) {
                        Some(q) if q.is_finite() && q > 0.0 && q <= MAX_QUALITY_FACTOR => v.push(q),
                        _ => r.problems.push(format!(
                            "[cantilever].quality_factors[{i}] = {}: must be a number in (0, 1e7]",
                            x.as_float().map_or(x.to_string(), crate::error::number)
                        )),
                    }
                }
                Some(v)
            }
            Some(_) => {
                r.problems
                    .push("[cantilever].quality_factors must be an array of numbers".into());
                None
            }
        };
        let q1 = match (c.contains_key("quality_factor"), &qs) {
            (true, _) => r.required(c, S, "quality_factor", "1", QUALITY),
            (false, Some(q)) => q.first().copied(),
            (false, None) => {
                r.problems
                    .push("missing key [cantilever].quality_factor (Q of mode 1)".into());
                None
            }
        };
        if let (Some(q1), Some(q)) = (q1, &qs) {
            if q.first().is_some_and(|&f| f != q1) {
                r.problems.push(format!(
                    "[cantilever].quality_factor = {} differs from quality_factors[0] = {}",
                    crate::error::number(q1),
                    q[0]
                ));
            }
        }
        (beam, q1, qs)
    }

    fn read_sample(
        r: &mut Reader<'_>,
        s: &toml::Table,
        tip: Option<&toml::Table>,
        radius: Option<f64>,
        tip_e: Option<f64>,
        tip_nu: Option<f64>,
    ) -> Option<Sample> {
        const S: &str = "sample";
        // the law's name in any case ("DMT" as the literature writes it)
        let law = match r
            .string(s, S, "law")
            .map(|l| (l, l.trim().to_ascii_lowercase()))
        {
            // a registered law's name ([`crate::contact::LAWS`])
            Some((_, l)) if crate::contact::LAWS.iter().any(|law| law.name == l) => Some(l),
            Some((l, _)) => {
                r.problems.push(format!(
                    "[sample].law = '{l}': expected {}",
                    crate::contact::LawKind::expected()
                ));
                None
            }
            None => {
                if !s.contains_key("law") {
                    r.problems.push(format!(
                        "missing key [sample].law ({})",
                        crate::contact::LawKind::expected()
                    ));
                }
                None
            }
        }?;
        // the electrostatic law's keys are DMT's and the voltages
        const DMT: [&str; 7] = [
            "law",
            "youngs_modulus",
            "poisson_ratio",
            "hamaker",
            "intermolecular_distance",
            "viscosity",
            "z_c",
        ];
        let electrostatic: Vec<&str> = DMT
            .iter()
            .copied()
            .chain(["bias_voltage", "contact_potential"])
            .collect();
        let jkr: Vec<&str> = DMT.iter().copied().chain(["adhesion_energy"]).collect();
        const CAPILLARY: [&str; 8] = [
            "law",
            "youngs_modulus",
            "poisson_ratio",
            "viscosity",
            "meniscus_volume",
            "surface_tension",
            "contact_angle",
            "z_c",
        ];
        let keys: &[&str] = match law.as_str() {
            "linear" => &["law", "stiffness", "damping", "z_c"],
            "sls" => &[
                "law",
                "stiffness",
                "maxwell_stiffness",
                "relaxation_time",
                "z_c",
            ],
            "hertz" => &["law", "youngs_modulus", "poisson_ratio", "damping", "z_c"],
            "dmt" => &DMT,
            "electrostatic" => &electrostatic,
            "jkr" => &jkr,
            "capillary" => &CAPILLARY,
            _ => &["law", "restitution", "z_c"],
        };
        r.unknown(s, S, keys);
        let z_c = r.optional(s, S, "z_c", "m", ANY);
        let mut out = Sample {
            law: law.clone(),
            e_star: None,
            radius,
            hamaker: None,
            a0: None,
            viscosity: None,
            stiffness: None,
            damping: None,
            restitution: None,
            voltage: None,
            adhesion_energy: None,
            meniscus: None,
            maxwell: None,
            z_c,
        };
        match law.as_str() {
            "linear" => {
                out.stiffness = r.required(s, S, "stiffness", "N/m", NON_NEGATIVE);
                out.damping = r.optional(s, S, "damping", "N s/m", NON_NEGATIVE);
                return out.stiffness.map(|_| out);
            }
            "sls" => {
                out.stiffness = r.required(s, S, "stiffness", "N/m", POSITIVE);
                let k2 = r.required(s, S, "maxwell_stiffness", "N/m", POSITIVE);
                let tau = r.required(s, S, "relaxation_time", "s", POSITIVE);
                out.maxwell = k2.zip(tau);
                return out.stiffness.and(out.maxwell).map(|_| out);
            }
            "impact" => {
                out.restitution = r.required(s, S, "restitution", "1", UNIT_INTERVAL);
                return out.restitution.map(|_| out);
            }
            _ => {}
        }
        // hertz and dmt need the tip (its radius; E and ν default to silicon's)
        if tip.is_none() {
            r.problems.push(format!(
                "missing table [tip] (the {law} law needs the tip radius; youngs_modulus and \
                 poisson_ratio default to silicon's)"
            ));
        } else if radius.is_none() && !tip.is_some_and(|t| t.contains_key("radius")) {
            r.problems.push(format!(
                "missing key [tip].radius (m, needed by the {law} law)"
            ));
        }
        let e_s = r.required(s, S, "youngs_modulus", "Pa", POSITIVE);
        let nu_s = r.required(s, S, "poisson_ratio", "1", POISSON);
        if let (Some(et), Some(nt), Some(es), Some(ns)) = (tip_e, tip_nu, e_s, nu_s) {
            // Johnson, Contact Mechanics, eq. 4.22
            out.e_star = Some(1.0 / ((1.0 - nt * nt) / et + (1.0 - ns * ns) / es));
        }
        if law == "hertz" {
            out.damping = r.optional(s, S, "damping", "N s/m", NON_NEGATIVE);
        } else if law == "capillary" {
            let volume = r.required(s, S, "meniscus_volume", "m^3", POSITIVE);
            let gamma = r
                .optional(s, S, "surface_tension", "N/m", POSITIVE)
                .or(Some(WATER_SURFACE_TENSION));
            let theta = r
                .optional(s, S, "contact_angle", "degree", WETTING_ANGLE)
                .or(Some(0.0));
            out.viscosity = r.optional(s, S, "viscosity", "Pa s", NON_NEGATIVE);
            if let (Some(v), Some(g), Some(t)) = (volume, gamma, theta) {
                out.meniscus = Some((v, g, t.to_radians()));
            }
            out.meniscus?;
        } else {
            // JKR: the work of adhesion W, or H/(12πa₀²) from the Hamaker constant
            out.hamaker = if law == "jkr" {
                out.adhesion_energy = r.optional(s, S, "adhesion_energy", "J/m^2", POSITIVE);
                // (a given but invalid adhesion_energy is reported by its own check, not
                // as missing)
                match (s.contains_key("adhesion_energy"), s.contains_key("hamaker")) {
                    (_, true) => r.optional(s, S, "hamaker", "J", POSITIVE),
                    (true, false) => None,
                    (false, false) => {
                        r.problems.push(
                            "missing key [sample].adhesion_energy (W, J/m², the jkr law's work \
                             of adhesion; or hamaker, J, for W = H/(12πa₀²))"
                                .into(),
                        );
                        None
                    }
                }
            } else {
                r.required(s, S, "hamaker", "J", NON_NEGATIVE)
            };
            // a₀ = 0.165 nm when omitted (Israelachvili, Intermolecular and Surface Forces,
            // 3rd ed., Academic Press 2011, §13.6: the contact separation D₀ that gives
            // surface energies from Hamaker constants; García & San Paulo 1999 use it)
            out.a0 = if s.contains_key("intermolecular_distance") {
                r.optional(s, S, "intermolecular_distance", "m", POSITIVE)
            } else {
                Some(DEFAULT_INTERMOLECULAR_DISTANCE)
            };
            out.viscosity = r.optional(s, S, "viscosity", "Pa s", NON_NEGATIVE);
        }
        if law == "electrostatic" {
            // the voltage across the gap: the bias less the contact potential difference
            let bias = r.required(s, S, "bias_voltage", "V", ANY);
            let cpd = r
                .optional(s, S, "contact_potential", "V", ANY)
                .unwrap_or(0.0);
            out.voltage = bias.map(|b| b - cpd);
            out.voltage?;
        }
        if law == "jkr" {
            if out.adhesion_energy.is_some() && out.hamaker.is_some() {
                r.problems.push(
                    "[sample] gives both adhesion_energy and hamaker: the jkr law takes one work \
                     of adhesion (W, or H/(12πa₀²))"
                        .into(),
                );
                return None;
            }
            if let (None, Some(h), Some(a0)) = (out.adhesion_energy, out.hamaker, out.a0) {
                out.adhesion_energy = Some(work_of_adhesion(h, a0));
            }
            out.adhesion_energy?;
        }
        out.e_star.and(out.radius).map(|_| out)
    }

    /// The mapping of the module docs.
    #[allow(clippy::too_many_arguments)]
    fn resolve(
        structure: Structure,
        modes: usize,
        beam: Beam,
        q1: f64,
        qs: Option<Vec<f64>>,
        eigen: Option<(Vec<f64>, Vec<f64>)>,
        sample: Sample,
        drive: Drive,
        medium: Option<medium::MediumSpec>,
    ) -> Result<Probe, String> {
        let (a0, freq) = (drive.free_amplitude, drive.frequency);
        let q1_file = q1;
        let g0 = a0;
        // tip-mass ratio α1 of the beam, and for the geometry the time scale t = τ √(mL⁴/EI)
        // (eq. 5), the force unit EI/L³ and the static stiffness 3EI/L³
        let (beam_alpha1, geometry) = match beam {
            Beam::Calibrated { alpha1, k, f0, .. } => (alpha1, Err((k, f0))),
            Beam::Geometry {
                length: l,
                ei,
                mass_per_length: m,
                tip_mass,
                ..
            } => (
                tip_mass / (m * l),
                Ok(((m * l.powi(4) / ei).sqrt(), ei / l.powi(3))),
            ),
        };
        let alpha1 = match structure {
            Structure::Beam => beam_alpha1,
            Structure::PointMass | Structure::Eigenmodes => 0.0,
        };
        // the eigenmode model's modes relative to mode 1
        let eigenmodes = eigen.as_ref().map(|(k, f)| {
            let mut e = crate::params::Eigenmodes {
                stiffness: [1.0; MAX_MODES],
                frequency: [1.0; MAX_MODES],
            };
            for j in 0..k.len() {
                e.stiffness[j] = k[j] / k[0];
                e.frequency[j] = f[j] / f[0];
            }
            e
        });
        // undamped structure without drive or sample: ω̃₁ and k̃₁
        let bare = Params {
            modes,
            alpha1,
            alpha2: 0.0,
            alpha3: 0.0,
            alpha4: 0.0,
            alpha5: 1.0,
            alpha6: 0.0,
            omega: 1.0,
            contact_law: ContactLaw::Linear,
            structure,
            damping_profile: None,
            eigenmodes,
            drive_components: [None; MAX_DRIVE_COMPONENTS],
            excitation: drive.excitation,
            hydrodynamic: None,
        };
        let (w1, x1, k1) = first_mode(&bare).map_err(|e| e.to_string())?;
        // k and f0, given or from the geometry (first mode of the beam with its tip mass; the
        // point mass takes the first mode of a 6-mode beam)
        let (k, f0, static_k) = match geometry {
            Err((k, f0)) => (k, f0, 0.0),
            Ok((ts, unit)) => {
                let (bw1, _, bk1) = first_mode(&Params {
                    structure: Structure::Beam,
                    modes: if structure == Structure::Beam {
                        modes
                    } else {
                        6
                    },
                    alpha1: beam_alpha1,
                    ..bare
                })
                .map_err(|e| e.to_string())?;
                (bk1 * unit, bw1 / (TAU * ts), 3.0 * unit)
            }
        };
        // the static stiffness: the point mass's is its spring k; the beam's 3EI/L³, from the
        // geometry or from a calibrated k through the modal stiffness k = k̃₁ EI/L³ (issue 42:
        // it was reported as 0 whenever k was given)
        let static_k = match structure {
            Structure::PointMass => k,
            // the modes' springs in series at the tip (each takes the static force)
            Structure::Eigenmodes => {
                let compliance: f64 =
                    eigenmodes.map_or(1.0, |e| (0..modes).map(|j| 1.0 / e.stiffness[j]).sum());
                k / compliance
            }
            Structure::Beam if geometry.is_ok() => static_k,
            Structure::Beam => 3.0 * k / k1,
        };
        // [medium]: the lever's f₀ and Q in vacuum (medium.rs); the eigenmode model's
        // frequency ratios with them
        let (f0_model, q1_model, qs_model, eigenmodes, vacuum) = match &medium {
            None => (f0, q1, qs.clone(), eigenmodes, None),
            Some(spec) => {
                let (w1_k1, ratios) = if structure == Structure::Beam {
                    let g = Galerkin::new(&bare).map_err(|e| e.to_string())?;
                    let om = crate::eigen::natural_modes(g.region(Region::Free)).omega;
                    (w1 * w1 / k1, om.iter().map(|w| w / om[0]).collect())
                } else {
                    (4.0, vec![1.0])
                };
                let eigen_f = eigen.as_ref().map(|(_, f)| f.as_slice());
                let v = medium::to_vacuum(
                    spec,
                    &beam,
                    k,
                    f0,
                    q1,
                    qs.as_deref(),
                    eigen_f,
                    w1_k1,
                    &ratios,
                )?;
                let eigenmodes = eigenmodes.map(|mut e| {
                    if let Some(fv) = &v.eigen_frequencies {
                        for (j, f) in fv.iter().enumerate() {
                            e.frequency[j] = f / fv[0];
                        }
                    }
                    e
                });
                (v.f0, v.q1, v.qs.clone(), eigenmodes, Some(v))
            }
        };
        let time_s = w1 / (TAU * f0_model);
        let force_n = k * g0 / k1;
        let scales = Scales {
            length_m: g0,
            time_s,
            force_n,
        };
        // damping: profile from per-mode Q, then α3 from Q1
        let (q1, qs_given) = (q1_model, qs);
        let profile = match (&qs_model, structure) {
            // C_jj = m_j ω_j / Q_j = α3 s_j with α3 = 1/Q₁ (mode 1's m and ω are 1)
            (Some(q), Structure::Eigenmodes) => eigenmodes.map(|e| {
                let mut s = [1.0; MAX_MODES];
                for (j, qj) in q.iter().enumerate() {
                    s[j] = e.mass(j) * e.frequency[j] * q1 / qj;
                }
                s
            }),
            (Some(q), Structure::Beam) => {
                let mut s = [1.0; MAX_MODES];
                for (j, qj) in q.iter().enumerate() {
                    let bj = crate::beam::beta_root(j + 1).powi(2);
                    let b1 = crate::beam::beta_root(1).powi(2);
                    s[j] = (bj / b1) * (q1 / qj);
                }
                Some(s)
            }
            _ => None,
        };
        let with_profile = Params {
            damping_profile: profile,
            eigenmodes,
            ..bare
        };
        let alpha3 =
            crate::eigen::beam_damping_for_q(w1, &x1, q1, profile.as_ref().map(|s| &s[..]));
        // sample groups
        let t_s = time_s;
        let mut law = ContactLaw::Linear;
        let (mut alpha4, mut alpha6) = (0.0, 0.0);
        match sample.law.as_str() {
            "linear" => {
                alpha4 = sample.stiffness.unwrap_or(0.0) * g0 / force_n;
                alpha6 = sample.damping.unwrap_or(0.0) * g0 / (t_s * force_n);
            }
            "sls" => {
                // springs in units of F_s/g₀; the dashpot η = k₂τ_r (N·s/m) as the linear
                // law's damper: α6 = η g₀/(t_s F_s) = κ τ_r/t_s
                let (k2, tau_r) = sample.maxwell.unwrap_or((0.0, 0.0));
                alpha4 = sample.stiffness.unwrap_or(0.0) * g0 / force_n;
                let maxwell_stiffness = k2 * g0 / force_n;
                alpha6 = maxwell_stiffness * tau_r / t_s;
                law = ContactLaw::Sls { maxwell_stiffness };
            }
            "hertz" | "dmt" | "electrostatic" | "jkr" | "capillary" => {
                let (e, rr) = (sample.e_star.unwrap_or(0.0), sample.radius.unwrap_or(0.0));
                alpha4 = 4.0 / 3.0 * e * rr.sqrt() * g0.powf(1.5) / force_n;
                if sample.law == "hertz" {
                    law = ContactLaw::Hertz;
                    alpha6 = sample.damping.unwrap_or(0.0) * g0 / (t_s * force_n);
                } else if let Some((v, gamma, theta)) = sample.meniscus {
                    // the meniscus reaches r₁² = 2Rh on the sphere: within its cap, h ≤ R/2
                    let h = (v / (std::f64::consts::PI * rr)).sqrt();
                    if h > 0.5 * rr {
                        return Err(format!(
                            "[sample].meniscus_volume = {v:e} m^3 wets the tip beyond its apex \
                             (immersion √(V/(πR)) = {h:.3e} m > R/2 = {:.3e} m): the sphere–flat \
                             meniscus needs V ≤ πR³/4 = {:.3e} m^3",
                            0.5 * rr,
                            0.25 * std::f64::consts::PI * rr.powi(3)
                        ));
                    }
                    // F̃_cap = 4πRγcosθ/F_s, h̃ = √(V/(πR))/g₀, D̃_r = (1 + θ/2)V^{1/3}/g₀
                    law = ContactLaw::Capillary {
                        capillary: 4.0 * std::f64::consts::PI * rr * gamma * theta.cos() / force_n,
                        meniscus: h / g0,
                        rupture: (1.0 + 0.5 * theta) * v.cbrt() / g0,
                    };
                    alpha6 =
                        sample.viscosity.unwrap_or(0.0) * (rr * g0).sqrt() * g0 / (t_s * force_n);
                } else if sample.law == "jkr" {
                    // P̃ = πWR/F_s; the Kelvin–Voigt term η a δ̇ = η √(Rh) δ̇ as DMT's
                    law = ContactLaw::Jkr {
                        adhesion: std::f64::consts::PI * sample.adhesion_energy.unwrap_or(0.0) * rr
                            / force_n,
                    };
                    alpha6 =
                        sample.viscosity.unwrap_or(0.0) * (rr * g0).sqrt() * g0 / (t_s * force_n);
                } else {
                    let hamaker = sample.hamaker.unwrap_or(0.0) * rr / (6.0 * g0 * g0 * force_n);
                    let intermolecular_distance = sample.a0.unwrap_or(0.0) / g0;
                    law = match sample.voltage {
                        // Hudlet et al. 1998: F = −πε₀V²R²/(d(d + R)), Ẽ = πε₀V²/F_s, R̃ = R/g₀
                        Some(v) => ContactLaw::Electrostatic {
                            hamaker,
                            intermolecular_distance,
                            electrostatic: std::f64::consts::PI * VACUUM_PERMITTIVITY * v * v
                                / force_n,
                            tip_radius: rr / g0,
                        },
                        None => ContactLaw::Dmt {
                            hamaker,
                            intermolecular_distance,
                        },
                    };
                    alpha6 =
                        sample.viscosity.unwrap_or(0.0) * (rr * g0).sqrt() * g0 / (t_s * force_n);
                }
            }
            "impact" => {
                law = ContactLaw::Impact {
                    restitution: sample.restitution.unwrap_or(0.0),
                };
            }
            other => {
                return Err(format!(
                    "[sample].law = \"{other}\": a probe file cannot give this law (it has no \
                     conversion from SI keys)"
                ))
            }
        }
        let work = match (sample.law.as_str(), sample.adhesion_energy, sample.hamaker) {
            ("jkr", Some(w), _) => Some(w),
            ("dmt" | "electrostatic", _, Some(h)) if h > 0.0 => {
                Some(work_of_adhesion(h, sample.a0.unwrap_or(f64::NAN)))
            }
            _ => None,
        };
        let tabor_parameter = work.map(|w| {
            tabor_parameter(
                sample.radius.unwrap_or(0.0),
                sample.e_star.unwrap_or(f64::NAN),
                w,
                sample.a0.unwrap_or(DEFAULT_INTERMOLECULAR_DISTANCE),
            )
        });
        let z_c_in_file = sample.z_c.is_some();
        let z_c = sample.z_c.unwrap_or(a0);
        let mut params = Params {
            alpha3,
            alpha4,
            alpha6,
            contact_law: law,
            alpha2: 1.0,
            ..with_profile
        };
        // the fluid's loading of every mode; the drive then defaults to the first mode's
        // natural frequency in the fluid (f₀ without one)
        // laws of a gas: a meniscus does not form under a liquid, and the electrostatic law is
        // the force across vacuum (ε₀), not across a polar, screening liquid
        let liquid = medium.as_ref().is_some_and(|m| m.is_liquid());
        if liquid
            && matches!(
                law,
                ContactLaw::Capillary { .. } | ContactLaw::Electrostatic { .. }
            )
        {
            let why = if matches!(law, ContactLaw::Capillary { .. }) {
                "the meniscus of humid air does not form under a liquid"
            } else {
                "the sphere–plane force across vacuum (ε₀) ignores the liquid's permittivity and \
                 ionic screening"
            };
            return Err(format!(
                "[sample].law = \"{}\" in a liquid [medium]: {why} (use it in air, or another \
                 law)",
                law.name()
            ));
        }
        let medium_report = match (&medium, &vacuum) {
            (Some(spec), Some(v)) => Some(medium::load(spec, v, &mut params, time_s)?),
            _ => None,
        };
        let drive_hz = freq.unwrap_or(medium_report.as_ref().map_or(f0, |m| m.resonance_frequency));
        params.omega = scales.omega(drive_hz);
        params.alpha5 = params.alpha5_for_rest_distance(z_c / g0);
        // drive amplitude: free tip amplitude A0 (= 1 in units of g0) at Ω
        let unit_response = CantileverModel::new(&params)
            .map_err(|e| derived(e.to_string()))?
            .free_tip_response()
            .map_err(|e| derived(e.to_string()))?
            .norm();
        params.alpha2 = 1.0 / unit_response;
        let components =
            Self::resolve_components(&mut params, &drive.components, drive_hz, &scales)?;
        params
            .validate_fields()
            .map_err(|e| derived(e.to_string()))?;
        Ok(Probe {
            params,
            scales,
            calibration: Calibration {
                spring_constant: k,
                resonance_frequency: f0,
                quality_factor: q1_file,
                quality_factors: qs_given,
                tip_mass_ratio: alpha1,
                static_spring_constant: static_k,
            },
            free_amplitude: a0,
            drive_frequency: drive_hz,
            components,
            z_c,
            z_c_in_file,
            medium: medium_report,
            tabor_parameter,
            input_warnings: vacuum.as_ref().map_or(Vec::new(), |v| v.warnings.clone()),
            tip_radius: sample.radius.filter(|_| {
                matches!(
                    sample.law.as_str(),
                    "hertz" | "dmt" | "electrostatic" | "jkr" | "capillary"
                )
            }),
        })
    }

    /// The further components of a multifrequency drive ([`Params::drive_components`]): each
    /// at the frequency given, or at its mode's free resonance (mode i + 1 for component i,
    /// the undamped natural frequency of the free structure), its ratio to the first
    /// component's frequency the rational p/q ([`rational_ratio`]), its force F̃ᵢ = A₀ᵢ/|Hᵢ|
    /// from the free amplitude through the free response Hᵢ to a tip force at that frequency
    /// ([`CantileverModel::free_force_response`]), phase θ = 0.
    fn resolve_components(
        params: &mut Params,
        given: &[(f64, f64)],
        drive_hz: f64,
        scales: &Scales,
    ) -> Result<Vec<DriveComponentSi>, String> {
        if given.is_empty() {
            return Ok(Vec::new());
        }
        let model = CantileverModel::new(params).map_err(|e| derived(e.to_string()))?;
        let natural = crate::eigen::natural_modes(model.galerkin().region(Region::Free));
        let mut out = Vec::new();
        for (i, &(amp, f)) in given.iter().enumerate() {
            let f = if f.is_nan() {
                let k = i + 1;
                let w = *natural.omega.get(k).ok_or_else(|| {
                    format!(
                        "[drive].frequency: component {} has no mode {} to default to (modes = \
                         {}): give the frequencies",
                        k + 1,
                        k + 1,
                        params.modes
                    )
                })?;
                scales.frequency_hz(w)
            } else {
                f
            };
            let r = f / drive_hz;
            let (p, q) = rational_ratio(r).or_else(|| convergent(r)).ok_or_else(|| {
                format!(
                    "[drive].frequency[{}] = {} Hz: its ratio to the first component's \
                     {} Hz, {}, must be in (0, 1e6)",
                    i + 1,
                    crate::error::number(f),
                    crate::error::number(drive_hz),
                    crate::error::number(r),
                )
            })?;
            // a lock-in at one frequency measures the sum of every component there: two
            // components at one frequency would each be reported with their total amplitude
            let same = (p, q) == (1, 1)
                || out.iter().any(|c: &DriveComponentSi| {
                    u64::from(c.ratio[0]) * u64::from(q) == u64::from(p) * u64::from(c.ratio[1])
                });
            if same {
                return Err(format!(
                    "[drive].frequency[{}] = {} Hz: another component is at this frequency; \
                     a lock-in cannot tell components at one frequency apart, so give them as \
                     one component (their amplitudes added)",
                    i + 1,
                    crate::error::number(f),
                ));
            }
            let ratio = f64::from(p) / f64::from(q);
            let h = model
                .free_force_response(ratio * params.omega)
                .map_err(|e| derived(e.to_string()))?;
            let force = amp / scales.length_m / h.norm();
            params.drive_components[i] = Some(DriveComponent {
                force,
                ratio: [p, q],
                phase: 0.0,
            });
            out.push(DriveComponentSi {
                free_amplitude: amp,
                frequency: drive_hz * ratio,
                ratio: [p, q],
            });
        }
        if out.len() > MAX_DRIVE_COMPONENTS {
            return Err(format!(
                "[drive]: at most {} components",
                1 + MAX_DRIVE_COMPONENTS
            ));
        }
        Ok(out)
    }

    /// The rest distance z_c (m) of a parameter set under these scales.
    pub fn z_c_of(&self, params: &Params) -> f64 {
        params.rest_distance() * self.scales.length_m
    }
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
