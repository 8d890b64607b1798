//! The model part of every request: the parameter values a user gave, by name, and the one
//! table of those names ([`MODEL_PARAMETERS`]) that the command line's flags and help, the TOML
//! config keys, the Python keywords, their docstrings and type stubs are checked against.
//!
//! Precedence, the same for every front end: the defaults of the analysis (the paper's
//! Figs. 5–14 set, [`Params::default`]) ← a probe file in SI ([`crate::probe::Probe`]) ← the
//! single values of [`ModelSpec`] ← the SI overrides `z_c` (sets α5) and `drive_frequency`
//! (sets Ω), which need the probe's scales.

use crate::contact::{ContactLaw, LawGroups, LawKind};
use crate::error::SimError;
use crate::params::{Excitation, Params};
use crate::probe::Probe;
use serde::{Deserialize, Serialize};

/// What kind of value a model parameter takes (for the front ends' type checks and stubs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ValueKind {
    /// A non-negative integer.
    Integer,
    /// A real number.
    Real,
    /// One of `linear`, `hertz`, `dmt`, `electrostatic`, `impact`.
    Law,
    /// One of `base`, `tip`.
    Excitation,
}

/// One model parameter: its library name, the paper's alias, symbol, unit, range and help.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ParamInfo {
    /// The library's name (snake_case): the TOML key, the Python keyword; the flag is the same
    /// in kebab-case (`tip_mass_ratio` → `--tip-mass-ratio`).
    pub name: &'static str,
    /// The paper's name (`alpha1` … `alpha6`), accepted everywhere as well; `None` when the
    /// name is the paper's.
    pub alias: Option<&'static str>,
    /// The symbol as the paper writes it.
    pub symbol: &'static str,
    /// The unit: `1` (dimensionless, eq. 5 and 7), `m` or `Hz` (SI, with a probe).
    pub unit: &'static str,
    /// The allowed range in words (the limits of [`crate::params`]).
    pub range: &'static str,
    /// The default in words.
    pub default: &'static str,
    /// One line of help.
    pub help: &'static str,
    /// Integer, real or law name.
    pub kind: ValueKind,
}

/// Every model parameter a request takes, in the order the front ends list them. The ranges
/// are those [`Params::validate`] and [`ContactLaw::validate`] enforce; `z_c` and
/// `drive_frequency` are SI values that need a probe file.
pub const MODEL_PARAMETERS: [ParamInfo; 22] = [
    ParamInfo {
        name: "modes",
        alias: None,
        symbol: "N",
        unit: "1",
        range: "1..=20",
        default: "3",
        help: "number of Galerkin modes N (eq. 9)",
        kind: ValueKind::Integer,
    },
    ParamInfo {
        name: "tip_mass_ratio",
        alias: Some("alpha1"),
        symbol: "α1",
        unit: "1",
        range: "0..=1e4",
        default: "0.1",
        help: "tip-mass ratio α1 = M/(mL)",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "drive_amplitude",
        alias: Some("alpha2"),
        symbol: "α2",
        unit: "1",
        range: "0..=1e6",
        default: "0.1",
        help: "base-drive amplitude α2 = f/g0",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "beam_damping",
        alias: Some("alpha3"),
        symbol: "α3",
        unit: "1",
        range: "0..=1e4",
        default: "0.1",
        help: "beam damping α3",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "contact_stiffness",
        alias: Some("alpha4"),
        symbol: "α4",
        unit: "1",
        range: "0..=1e8",
        default: "20",
        help: "contact stiffness α4 = K1 L³/(EI)",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "gap",
        alias: Some("alpha5"),
        symbol: "α5",
        unit: "1",
        range: "-1e6..=1e6",
        default: "0",
        help: "tip–sample gap α5 = g1/g0 (may be negative)",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "contact_damping",
        alias: Some("alpha6"),
        symbol: "α6",
        unit: "1",
        range: "0..=1e4",
        default: "0.2",
        help: "contact damping α6",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "omega",
        alias: None,
        symbol: "Ω",
        unit: "1",
        range: "1e-3..=1e5",
        default: "2.6",
        help: "dimensionless drive frequency Ω",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "contact_law",
        alias: None,
        symbol: "F_c",
        unit: "1",
        range: crate::contact::LawKind::EXPECTED,
        default: "linear",
        help:
            "tip–sample law: linear (α4 δ + α6 δ̇), hertz (α4 δ^1.5 + α6 δ̇), dmt (van der Waals + \
         adhesion + Hertz + α6 √δ δ̇), electrostatic (dmt + a biased tip), jkr (adhesive Hertz \
         contact with a neck, formed at δ = 0, broken at δ_f < 0), capillary (a meniscus formed \
         at contact, ruptured at V_T = D_r, over a Hertz sample), sls (standard linear solid: \
         α4 in parallel with a Maxwell arm κ, α6, whose surface recovers after the tip leaves) \
         or impact (rigid sample, restitution r)",
        kind: ValueKind::Law,
    },
    ParamInfo {
        name: "excitation",
        alias: None,
        symbol: "—",
        unit: "1",
        range: "base or tip",
        default: "base",
        help: "where the drive acts on the beam: base (α2 sin Ωτ, the paper; acoustic) or tip (a \
         force α2 cos Ωτ at the tip: magnetic, photothermal)",
        kind: ValueKind::Excitation,
    },
    ParamInfo {
        name: "restitution",
        alias: None,
        symbol: "r",
        unit: "1",
        range: "0..=1",
        default: "0.8",
        help: "impact law: coefficient of restitution r",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "hamaker",
        alias: None,
        symbol: "H̃",
        unit: "1",
        range: ">= 0",
        default: "1e-5",
        help: "DMT: van der Waals group H̃ = H R L³/(6 EI g0³)",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "intermolecular_distance",
        alias: None,
        symbol: "ã0",
        unit: "1",
        range: "> 0",
        default: "0.01",
        help: "DMT: intermolecular distance ã0 = a0/g0, the contact threshold",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "electrostatic",
        alias: None,
        symbol: "Ẽ",
        unit: "1",
        range: ">= 0",
        default: "1e-3",
        help: "electrostatic law: group Ẽ = πε0 V²/F of the biased tip, F_es = -Ẽ R̃²/(d(d + R̃))",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "tip_radius",
        alias: None,
        symbol: "R̃",
        unit: "1",
        range: "> 0",
        default: "1",
        help: "electrostatic law: tip radius R̃ = R/g0",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "adhesion",
        alias: None,
        symbol: "P̃",
        unit: "1",
        range: "> 0",
        default: "0.05",
        help: "jkr law: adhesion group P̃ = πWR/F (W the work of adhesion): pull-off (3/2)P̃",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "capillary",
        alias: None,
        symbol: "F̃_cap",
        unit: "1",
        range: "> 0",
        default: "0.1",
        help: "capillary law: the meniscus's force at contact F̃_cap = 4πRγcosθ/F",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "meniscus",
        alias: None,
        symbol: "h̃",
        unit: "1",
        range: "1e-9..=1e6",
        default: "0.01",
        help: "capillary law: the meniscus's immersion at contact h̃ = √(V/(πR))/g0 (V its volume)",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "rupture",
        alias: None,
        symbol: "D̃_r",
        unit: "1",
        range: "1e-9..=1e6",
        default: "0.05",
        help: "capillary law: the rupture distance D̃_r = (1 + θ/2)V^(1/3)/g0 (Lian et al. 1993)",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "maxwell_stiffness",
        alias: None,
        symbol: "κ",
        unit: "1",
        range: "(0, 1e12]",
        default: "20",
        help:
            "sls law: the Maxwell arm's spring κ (in series with the dashpot α6; relaxation time \
         α6/κ, instantaneous stiffness α4 + κ)",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "z_c",
        alias: None,
        symbol: "z_c",
        unit: "m",
        range: "finite",
        default: "the probe's",
        help: "with a probe: the rest tip–sample distance z_c in metres (sets α5)",
        kind: ValueKind::Real,
    },
    ParamInfo {
        name: "drive_frequency",
        alias: None,
        symbol: "f",
        unit: "Hz",
        range: "> 0",
        default: "the probe's",
        help:
            "with a probe: the drive frequency in Hz (sets Ω; the drive force or base amplitude is \
         kept)",
        kind: ValueKind::Real,
    },
];

/// The entry of [`MODEL_PARAMETERS`] named `key` (its name or its alias).
pub fn parameter(key: &str) -> Option<&'static ParamInfo> {
    MODEL_PARAMETERS
        .iter()
        .find(|p| p.name == key || p.alias == Some(key))
}

/// The model parameter name (or alias) closest to a misspelt `key` — Jaro–Winkler similarity
/// ≥ 0.85 (`omgea` → `omega`, `beam_dampnig` → `beam_damping`) — for a "did you mean" hint.
pub(crate) fn closest_parameter(key: &str) -> Option<&'static str> {
    MODEL_PARAMETERS
        .iter()
        .flat_map(|p| std::iter::once(p.name).chain(p.alias))
        .map(|name| (strsim::jaro_winkler(key, name), name))
        .filter(|(score, _)| *score >= 0.85)
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, name)| name)
}

/// The model values of a request, each optional (a missing one keeps the value below it in the
/// precedence of this module). Serialised with the names of [`MODEL_PARAMETERS`]; the paper's
/// `alpha1` … `alpha6` are accepted as aliases; unknown keys are refused (this is also the
/// schema of a `--config FILE.toml`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    /// N.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub modes: Option<usize>,
    /// α1.
    #[serde(alias = "alpha1", skip_serializing_if = "Option::is_none")]
    pub tip_mass_ratio: Option<f64>,
    /// α2.
    #[serde(alias = "alpha2", skip_serializing_if = "Option::is_none")]
    pub drive_amplitude: Option<f64>,
    /// α3.
    #[serde(alias = "alpha3", skip_serializing_if = "Option::is_none")]
    pub beam_damping: Option<f64>,
    /// α4.
    #[serde(alias = "alpha4", skip_serializing_if = "Option::is_none")]
    pub contact_stiffness: Option<f64>,
    /// α5.
    #[serde(alias = "alpha5", skip_serializing_if = "Option::is_none")]
    pub gap: Option<f64>,
    /// α6.
    #[serde(alias = "alpha6", skip_serializing_if = "Option::is_none")]
    pub contact_damping: Option<f64>,
    /// Ω.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub omega: Option<f64>,
    /// The tip–sample law.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_law: Option<LawKind>,
    /// Where the drive acts (beam).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub excitation: Option<Excitation>,
    /// Impact law: r.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub restitution: Option<f64>,
    /// DMT: H̃.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hamaker: Option<f64>,
    /// DMT: ã0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intermolecular_distance: Option<f64>,
    /// Electrostatic law: Ẽ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub electrostatic: Option<f64>,
    /// Electrostatic law: R̃.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tip_radius: Option<f64>,
    /// JKR law: P̃.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub adhesion: Option<f64>,
    /// Capillary law: F̃_cap.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capillary: Option<f64>,
    /// Capillary law: h̃.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub meniscus: Option<f64>,
    /// Capillary law: D̃_r.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rupture: Option<f64>,
    /// SLS law: κ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub maxwell_stiffness: Option<f64>,
    /// With a probe: z_c in m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub z_c: Option<f64>,
    /// With a probe: the drive frequency in Hz.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drive_frequency: Option<f64>,
}

impl ModelSpec {
    /// `self`'s values, and `lower`'s where `self` has none (flags over a config file).
    pub fn over(self, lower: ModelSpec) -> ModelSpec {
        ModelSpec {
            modes: self.modes.or(lower.modes),
            tip_mass_ratio: self.tip_mass_ratio.or(lower.tip_mass_ratio),
            drive_amplitude: self.drive_amplitude.or(lower.drive_amplitude),
            beam_damping: self.beam_damping.or(lower.beam_damping),
            contact_stiffness: self.contact_stiffness.or(lower.contact_stiffness),
            gap: self.gap.or(lower.gap),
            contact_damping: self.contact_damping.or(lower.contact_damping),
            omega: self.omega.or(lower.omega),
            contact_law: self.contact_law.or(lower.contact_law),
            excitation: self.excitation.or(lower.excitation),
            restitution: self.restitution.or(lower.restitution),
            hamaker: self.hamaker.or(lower.hamaker),
            intermolecular_distance: self
                .intermolecular_distance
                .or(lower.intermolecular_distance),
            electrostatic: self.electrostatic.or(lower.electrostatic),
            tip_radius: self.tip_radius.or(lower.tip_radius),
            adhesion: self.adhesion.or(lower.adhesion),
            capillary: self.capillary.or(lower.capillary),
            meniscus: self.meniscus.or(lower.meniscus),
            rupture: self.rupture.or(lower.rupture),
            maxwell_stiffness: self.maxwell_stiffness.or(lower.maxwell_stiffness),
            z_c: self.z_c.or(lower.z_c),
            drive_frequency: self.drive_frequency.or(lower.drive_frequency),
        }
    }

    /// Every given value is a finite number. A chart carries its model values through JSON to
    /// set one per cell, where a NaN or an infinity would become `null` and silently the
    /// default; the other analyses refuse them through [`ModelSpec::resolve`] alike.
    ///
    /// # Errors
    /// [`SimError::NotFinite`] naming the first value that is not finite by its request name
    /// (`contact_stiffness`, `z_c`, …).
    pub fn check_finite(&self) -> Result<(), SimError> {
        for (name, v) in self.reals() {
            if let Some(x) = v {
                crate::error::finite(name, x)?;
            }
        }
        Ok(())
    }

    /// The real values by their names, in the order of [`MODEL_PARAMETERS`].
    fn reals(&self) -> [(&'static str, Option<f64>); 19] {
        [
            ("tip_mass_ratio", self.tip_mass_ratio),
            ("drive_amplitude", self.drive_amplitude),
            ("beam_damping", self.beam_damping),
            ("contact_stiffness", self.contact_stiffness),
            ("gap", self.gap),
            ("contact_damping", self.contact_damping),
            ("omega", self.omega),
            ("restitution", self.restitution),
            ("hamaker", self.hamaker),
            ("intermolecular_distance", self.intermolecular_distance),
            ("electrostatic", self.electrostatic),
            ("tip_radius", self.tip_radius),
            ("adhesion", self.adhesion),
            ("capillary", self.capillary),
            ("meniscus", self.meniscus),
            ("rupture", self.rupture),
            ("maxwell_stiffness", self.maxwell_stiffness),
            ("z_c", self.z_c),
            ("drive_frequency", self.drive_frequency),
        ]
    }

    /// The parameter set: `defaults`, or the probe's set when a probe is given, with this
    /// spec's values applied, then `z_c` (α5 = [`Params::alpha5_for_rest_distance`] of z_c in
    /// units of the probe's length scale) and `drive_frequency` (Ω from the probe's time
    /// scale), validated.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `z_c` or `drive_frequency` when given without a probe or
    /// not finite (not positive); [`SimError::Params`] for a law group of another law or a
    /// value out of range ([`Params::validate`]).
    pub fn resolve(&self, defaults: Params, probe: Option<&Probe>) -> Result<Params, SimError> {
        if let Some(pr) = probe {
            self.refuse_dimensionless_under_probe()?;
            self.check_probe_modes(pr)?;
        }
        let base = probe.map_or(defaults, |p| p.params);
        let contact_law = ContactLaw::from_parts(
            self.contact_law,
            LawGroups {
                hamaker: self.hamaker,
                intermolecular_distance: self.intermolecular_distance,
                restitution: self.restitution,
                electrostatic: self.electrostatic,
                tip_radius: self.tip_radius,
                adhesion: self.adhesion,
                capillary: self.capillary,
                meniscus: self.meniscus,
                rupture: self.rupture,
                maxwell_stiffness: self.maxwell_stiffness,
            },
            base.contact_law,
        )?;
        let mut p = Params {
            contact_law,
            modes: self.modes.unwrap_or(base.modes),
            alpha1: self.tip_mass_ratio.unwrap_or(base.alpha1),
            alpha2: self.drive_amplitude.unwrap_or(base.alpha2),
            alpha3: self.beam_damping.unwrap_or(base.alpha3),
            alpha4: self.contact_stiffness.unwrap_or(base.alpha4),
            alpha5: self.gap.unwrap_or(base.alpha5),
            alpha6: self.contact_damping.unwrap_or(base.alpha6),
            omega: self.omega.unwrap_or(base.omega),
            excitation: self.excitation.unwrap_or(base.excitation),
            ..base
        };
        // a lever in a fluid with another N: every mode loaded as the probe's were
        if let Some(pr) = probe {
            if let (Some(m), true) = (&pr.medium, p.modes != pr.params.modes) {
                m.reload(&mut p, pr.scales.time_s)
                    .map_err(SimError::Probe)?;
            }
        }
        if let Some(z) = self.z_c {
            p.alpha5 = alpha5_of_rest_distance(z, &p, probe)?;
        }
        if let Some(f) = self.drive_frequency {
            p.omega = omega_of_drive_frequency(f, probe)?;
        }
        p.validate_fields().map_err(SimError::from)?;
        Ok(p)
    }

    /// One meaning of N everywhere: a lumped model's modes are the probe's (the point mass has
    /// one, the eigenmode model one per entry of [cantilever].spring_constant), as the probe
    /// file's own `modes` key is checked; a larger N would repeat mode 1.
    fn check_probe_modes(&self, pr: &Probe) -> Result<(), SimError> {
        if let (Some(n), true) = (self.modes, pr.params.structure.is_lumped()) {
            if n != pr.params.modes {
                return Err(SimError::out_of_range(
                    "modes",
                    format!(
                        "{n} (this probe's {} model has {} mode(s))",
                        pr.params.structure.name(),
                        pr.params.modes
                    ),
                    "must equal the probe's number of modes: the point-mass model has \
                     one mode and the eigenmode model one per entry of [cantilever] \
                     spring_constant (omit modes, or edit the probe's arrays)",
                ));
            }
        }
        Ok(())
    }
}

/// α5 of `p` for the rest distance `z` (m, the request's `z_c`): z in units of the probe's
/// length scale ([`Params::alpha5_for_rest_distance`]), within the model's range.
fn alpha5_of_rest_distance(z: f64, p: &Params, probe: Option<&Probe>) -> Result<f64, SimError> {
    let probe = probe
        .ok_or_else(|| SimError::out_of_range("z_c", z, "needs a probe file (z_c is in m, SI)"))?;
    if !z.is_finite() {
        return Err(SimError::out_of_range(
            "z_c",
            z,
            "must be a finite distance in m",
        ));
    }
    super::limits::si_distance("z_c", z)?;
    let alpha5 = p.alpha5_for_rest_distance(z / probe.scales.length_m);
    if alpha5.is_nan() || alpha5.abs() > crate::params::DISPLACEMENT_MAX {
        // the model's range of α5 in the user's unit: z_c in m for this probe's A0
        let edge = |a5: f64| Params { alpha5: a5, ..*p }.rest_distance() * probe.scales.length_m;
        return Err(SimError::out_of_range(
            "z_c",
            format!(
                "{} m (this probe allows [{}, {}] m: ±1e6 × its length unit A0 = {} m)",
                crate::error::number(z),
                crate::error::number(edge(-crate::params::DISPLACEMENT_MAX)),
                crate::error::number(edge(crate::params::DISPLACEMENT_MAX)),
                crate::error::number(probe.scales.length_m)
            ),
            "must lie within the probe's range: the model takes rest distances up to \
             1e6 free amplitudes A0 from the sample",
        ));
    }
    Ok(alpha5)
}

/// Ω of the drive frequency `f` (Hz, the request's `drive_frequency`) under the probe's time
/// scale, within [`super::limits::SI_FREQUENCY_RATIO`] of the probe's drive frequency.
fn omega_of_drive_frequency(f: f64, probe: Option<&Probe>) -> Result<f64, SimError> {
    let probe = probe.ok_or_else(|| {
        SimError::out_of_range(
            "drive_frequency",
            f,
            "needs a probe file (drive_frequency is in Hz, SI)",
        )
    })?;
    if !(f.is_finite() && f > 0.0) {
        return Err(SimError::out_of_range(
            "drive_frequency",
            f,
            "must be finite and > 0 (Hz)",
        ));
    }
    let (lo, hi) = super::limits::SI_FREQUENCY_RATIO;
    let ratio = f / probe.drive_frequency;
    if !(lo..=hi).contains(&ratio) {
        return Err(SimError::out_of_range(
            "drive_frequency",
            format!(
                "{} Hz ({} × the probe's {} Hz)",
                crate::error::number(f),
                crate::error::number(ratio),
                crate::error::number(probe.drive_frequency)
            ),
            "must be within [0.01, 1e4] × the probe's drive frequency: frequencies are \
             in Hz (300 kHz is 300e3, or 300kHz on the command line)",
        ));
    }
    Ok(probe.scales.omega(f))
}

/// The model values a probe file sets in SI, refused as dimensionless values when a probe is
/// given (its scales would not apply to them: `hamaker = 6.6e-20` taken as H̃ is not the
/// Hamaker constant in J): the value's name and what to give instead. `modes` and
/// `restitution` (pure numbers, the same in SI) and the SI values `z_c` and `drive_frequency`
/// are taken with a probe.
pub const PROBE_SETS: [(&str, &str); 18] = [
    (
        "tip_mass_ratio",
        "is the dimensionless α1 and a probe sets it: give it in the probe file's [cantilever] \
         tip_mass_ratio (beam)",
    ),
    (
        "drive_amplitude",
        "is the dimensionless α2 and a probe sets it: give the free amplitude in the probe \
         file's [drive] free_amplitude (m)",
    ),
    (
        "beam_damping",
        "is the dimensionless α3 and a probe sets it: give the quality factor in the probe \
         file's [cantilever] quality_factor",
    ),
    (
        "contact_stiffness",
        "is the dimensionless α4 and a probe sets it: give the sample in the probe file's \
         [sample] youngs_modulus (Pa; linear law: stiffness in N/m)",
    ),
    (
        "gap",
        "is the dimensionless α5 and a probe sets it: give the rest distance z_c in m instead \
         (--z-c 8nm on the command line, z_c=8e-9 in Python)",
    ),
    (
        "contact_damping",
        "is the dimensionless α6 and a probe sets it: give it in the probe file's [sample] \
         viscosity (Pa s, DMT) or damping (N s/m, linear and Hertz)",
    ),
    (
        "omega",
        "is the dimensionless Ω and a probe sets it: give the drive frequency in Hz instead \
         (--drive-frequency 300kHz on the command line, drive_frequency=300e3 in Python)",
    ),
    (
        "contact_law",
        "is set by the probe file's [sample] law (its constants are SI keys of that section): \
         change the law there",
    ),
    (
        "hamaker",
        "is the dimensionless H̃ and a probe sets it: give the Hamaker constant in the probe \
         file's [sample] hamaker (J)",
    ),
    (
        "intermolecular_distance",
        "is the dimensionless ã0 and a probe sets it: give a0 in the probe file's [sample] \
         intermolecular_distance (m)",
    ),
    (
        "electrostatic",
        "is the dimensionless Ẽ and a probe sets it: give the voltage in the probe file's \
         [sample] bias_voltage (V, law = \"electrostatic\")",
    ),
    (
        "tip_radius",
        "is the dimensionless R̃ and a probe sets it: give the radius in the probe file's \
         [tip] radius (m)",
    ),
    (
        "excitation",
        "is set by the probe file's [drive] excitation (its drive amplitude is calibrated for \
         it): change it there",
    ),
    (
        "adhesion",
        "is the dimensionless P̃ and a probe sets it: give the work of adhesion in the probe \
         file's [sample] adhesion_energy (J/m², law = \"jkr\")",
    ),
    (
        "capillary",
        "is the dimensionless F̃_cap and a probe sets it: give the probe file's [sample] \
         surface_tension (N/m) and contact_angle (degrees) (law = \"capillary\")",
    ),
    (
        "meniscus",
        "is the dimensionless h̃ and a probe sets it: give the probe file's [sample] \
         meniscus_volume (m³, law = \"capillary\")",
    ),
    (
        "rupture",
        "is the dimensionless D̃_r and a probe sets it: give the probe file's [sample] \
         meniscus_volume (m³) and contact_angle (degrees) (law = \"capillary\")",
    ),
    (
        "maxwell_stiffness",
        "is the dimensionless κ and a probe sets it: give the probe file's [sample] \
         maxwell_stiffness (N/m, law = \"sls\")",
    ),
];

impl ModelSpec {
    /// Refuse the values a probe sets in SI ([`PROBE_SETS`]): the first one given, named.
    fn refuse_dimensionless_under_probe(&self) -> Result<(), SimError> {
        for (name, value) in self.reals() {
            let set = PROBE_SETS.iter().find(|(key, _)| *key == name);
            if let (Some(v), Some(&(key, allowed))) = (value, set) {
                return Err(SimError::out_of_range(
                    key,
                    crate::error::number(v),
                    allowed,
                ));
            }
        }
        if let Some(law) = self.contact_law {
            return Err(SimError::out_of_range(
                "contact_law",
                law.name(),
                PROBE_SETS[7].1,
            ));
        }
        if let Some(e) = self.excitation {
            return Err(SimError::out_of_range(
                "excitation",
                e.name(),
                PROBE_SETS[12].1,
            ));
        }
        Ok(())
    }
}

/// A model spec that could not be read (a config file's text): the parser's message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct ModelSpecError(pub String);

impl ModelSpec {
    /// Read a config file's text (TOML, the keys of [`MODEL_PARAMETERS`]); the error is one
    /// line: `line L, column C: message`.
    ///
    /// # Errors
    /// [`ModelSpecError`] for a syntax error, an unknown key or a value of the wrong type.
    pub fn from_toml(text: &str) -> Result<ModelSpec, ModelSpecError> {
        parse_toml(text).map_err(ModelSpecError)
    }
}

/// Parse TOML text into `T`; the error is one line: "line L, column C: message" (for a
/// duplicate key, the key).
pub fn parse_toml<T: for<'de> Deserialize<'de>>(text: &str) -> Result<T, String> {
    toml::from_str(text).map_err(|e| {
        let mut msg = e.message().trim().replace('\n', " ");
        let Some(span) = e.span() else { return msg };
        let start = span.start.min(text.len());
        let before = &text[..start];
        let line = before.matches('\n').count() + 1;
        let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        if msg.starts_with("duplicate key") {
            let key = text.get(span.clone()).unwrap_or("").trim();
            if !key.is_empty() && !msg.contains(key) {
                msg = format!("duplicate key `{key}`");
            }
        }
        format!("line {line}, column {column}: {msg}")
    })
}

#[cfg(test)]
mod tests;
