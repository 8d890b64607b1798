//! The probe's `[medium]`: the fluid around the lever, the lever's values brought to vacuum,
//! and each mode's hydrodynamic loading ([`crate::params::Hydrodynamic`]) from Sader's
//! hydrodynamic function ([`crate::hydro`]).
//!
//! ```toml
//! [medium]
//! name = "water"             # water | air (presets), or give density and viscosity
//! density = 997.05           # ρ (kg/m³), overrides the preset's
//! viscosity = 8.9e-4         # η (Pa s), overrides the preset's
//! calibrated_in = "air"      # where [cantilever]'s f₀ and Q were measured: air (default) | vacuum
//! ```
//!
//! The fluid needs the lever's width b and its mass per unit length μ: from the geometry, or
//! with calibrated values from `[cantilever] length` and `width` (m) through
//! μ = k ω̃₁²/(k̃₁ ω₁² L) (the modal stiffness k = k̃₁ EI/L³ and ω₁ = ω̃₁ √(EI/(μL⁴)), module docs
//! of [`crate::probe`]; for the lumped models the uniform beam's ω̃₁²/k̃₁ = 4).
//!
//! **Calibrated in air.** A datasheet's or a thermal tune's f₀ and Q are the lever's in air.
//! The vacuum frequency is f_vac = f_air √(1 + T Γ_r(f_air)) (Sader 1998; the inverse of the
//! wet mode, closed form), and the lever's own loss (support, material) is kept as a damping
//! coefficient: 1/Q_air = 1/(Q_int √(1 + TΓ_r)) + 1/Q_fluid,air, so
//! Q_int = 1/((1/Q_air − 1/Q_fluid,air) √(1 + TΓ_r)), refused when Q_air exceeds what air alone
//! allows. With a calibrated k, μ depends on f_vac: the two are iterated to a fixed point (T
//! in air is ~1e-3, so 8 iterations reach round-off).
//!
//! **The loading.** Each mode j of the model (its vacuum natural frequency) is put in the
//! fluid by [`crate::hydro::wet_mode_of`]: m_a,j = m_j TΓ_r(ω_j), c_j = m_j TΓ_i(ω_j) ω_j at its
//! wet frequency ω_j, m_j = 1 for the beam's orthonormal modes and the point mass, the modal
//! mass for the eigenmode model.

use super::reader::Reader;
use super::{Beam, Calibration};
use crate::eigen::natural_modes;
use crate::galerkin::{Galerkin, Region};
use crate::hydro::{wet_mode_of, Medium, Section};
use crate::params::{Eigenmodes, Hydrodynamic, Params, Structure};
use serde::Serialize;
use std::f64::consts::TAU;

/// Where a probe's f₀ and Q were measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CalibratedIn {
    /// In air (datasheets, a thermal tune in air): the default.
    Air,
    /// In vacuum (or the lever's own values).
    Vacuum,
}

/// The `[medium]` section as read.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct MediumSpec {
    name: Option<String>,
    medium: Medium,
    calibrated_in: CalibratedIn,
}

impl MediumSpec {
    /// Whether the medium is a liquid ([`Medium::is_liquid`]).
    pub(super) fn is_liquid(&self) -> bool {
        self.medium.is_liquid()
    }
}

/// One mode in the medium.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FluidMode {
    /// The mode's vacuum natural frequency (Hz).
    pub vacuum_frequency_hz: f64,
    /// Its frequency in the fluid by Sader's wet-mode equation (Hz; the model's own natural
    /// frequency, with the tip mass, is in `free_frequencies_hz`).
    pub frequency_hz: f64,
    /// Re = ρωb²/(4η) at that frequency.
    pub reynolds: f64,
    /// Γ_rect(Re) as [Γ_r, Γ_i].
    pub gamma: [f64; 2],
    /// The added mass per beam mass, TΓ_r.
    pub added_mass_ratio: f64,
    /// Q from the fluid alone, (1/T + Γ_r)/Γ_i.
    pub fluid_quality_factor: f64,
}

/// What a probe's `[medium]` did (the `"medium"` of the `"si"` block).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MediumReport {
    /// The preset's name, when one was named.
    pub name: Option<String>,
    /// ρ (kg/m³).
    pub density: f64,
    /// η (Pa s).
    pub viscosity: f64,
    /// Where the file's f₀ and Q were measured.
    pub calibrated_in: CalibratedIn,
    /// The lever's width b (m).
    pub width: f64,
    /// Its mass per unit length μ (kg/m).
    pub mass_per_length: f64,
    /// T = πρb²/(4μ).
    pub mass_ratio: f64,
    /// The lever's first vacuum frequency (Hz).
    pub vacuum_resonance_frequency: f64,
    /// Its own quality factor per mode (support and material losses, in vacuum): mode 1's, or
    /// one per mode where the file gives quality_factors.
    pub intrinsic_quality_factors: Vec<f64>,
    /// The first mode's natural frequency in the medium (Hz), as the model has it.
    pub resonance_frequency: f64,
    /// The first mode's quality factor in the medium, 1/(2ζ) of the model's damped eigenvalue
    /// (`crate::eigen::quality_factors`; `None` when it is overdamped).
    pub quality_factor: Option<f64>,
    /// Each mode of the model in the fluid.
    pub modes: Vec<FluidMode>,
}

/// Read `[medium]`.
pub(super) fn read(r: &mut Reader<'_>, t: &toml::Table) -> Option<MediumSpec> {
    const S: &str = "medium";
    r.unknown(t, S, &["name", "density", "viscosity", "calibrated_in"]);
    let preset = match r.string(t, S, "name") {
        Some(n) => match crate::units::preset(&crate::hydro::MEDIA, n, "name", "medium") {
            Ok(m) => Some((n.trim().to_ascii_lowercase(), m)),
            Err(e) => {
                r.problems.push(format!("[medium].{e}"));
                return None;
            }
        },
        None => None,
    };
    let density = r.optional(t, S, "density", "kg/m^3", super::POSITIVE);
    let viscosity = r.optional(t, S, "viscosity", "Pa s", super::POSITIVE);
    let calibrated_in = match r.string(t, S, "calibrated_in") {
        None => CalibratedIn::Air,
        Some(s) => match s.trim().to_ascii_lowercase().as_str() {
            "air" => CalibratedIn::Air,
            "vacuum" => CalibratedIn::Vacuum,
            _ => {
                r.problems.push(format!(
                    "[medium].calibrated_in = '{s}': expected air or vacuum (where \
                     [cantilever]'s resonance_frequency and quality_factor were measured)"
                ));
                return None;
            }
        },
    };
    let (name, medium) = match (preset, density, viscosity) {
        (Some((n, m)), d, v) => (
            Some(n),
            Medium {
                density: d.unwrap_or(m.density),
                viscosity: v.unwrap_or(m.viscosity),
            },
        ),
        (None, Some(d), Some(v)) => (
            None,
            Medium {
                density: d,
                viscosity: v,
            },
        ),
        (None, _, _) => {
            if !(t.contains_key("density") && t.contains_key("viscosity")) {
                r.problems.push(
                    "[medium]: give name = \"water\" or \"air\", or density (kg/m^3) and \
                     viscosity (Pa s)"
                        .into(),
                );
            }
            return None;
        }
    };
    Some(MediumSpec {
        name,
        medium,
        calibrated_in,
    })
}

/// The cantilever's values brought to vacuum, and what the loading needs.
pub(super) struct Vacuum {
    /// f₀ in vacuum (Hz).
    pub f0: f64,
    /// Q₁ and the per-mode Q_j (when given), intrinsic.
    pub q1: f64,
    pub qs: Option<Vec<f64>>,
    /// The eigenmode model's frequencies in vacuum (Hz).
    pub eigen_frequencies: Option<Vec<f64>>,
    section: Section,
    /// What the conversion assumed ([`intrinsic`]), for the probe's warnings.
    pub warnings: Vec<String>,
}

/// `1/(1/Q − 1/Q_f)/√(1 + TΓ_r)` (module docs). A calibrated Q at or above what air damping
/// alone allows for the lever's plan (Sader's estimate, which assumes a long lever, L ≫ b) is
/// data, not an error: the lever's own loss is then taken as nil (Q_int =
/// [`super::MAX_QUALITY_FACTOR`]), its fluid loading from the plan, and `warnings` says so.
fn intrinsic(q: f64, mode: &crate::hydro::WetMode, key: &str, warnings: &mut Vec<String>) -> f64 {
    let inv = 1.0 / q - 1.0 / mode.quality_factor;
    if inv <= 0.0 {
        warnings.push(warning!(
            "probe.q-above-air",
            "If the quality factor was measured in vacuum, say so: [medium] calibrated_in \
             = 'vacuum'.",
            "[cantilever].{key} = {}: at or above {}, the quality factor air damping alone \
             allows this lever's plan at {} Hz (Sader 1998, for a long lever, L ≫ b): the \
             lever's own loss is taken as nil and its fluid loading from the plan (a short or \
             wide lever, or a Q measured in vacuum: give [medium] calibrated_in = \"vacuum\")",
            crate::error::number(q),
            crate::error::number(mode.quality_factor),
            crate::error::number(mode.frequency_hz)
        ));
        return super::MAX_QUALITY_FACTOR;
    }
    1.0 / (inv * (1.0 + mode.added_mass_ratio).sqrt())
}

/// The lever's values in vacuum (module docs): the `calibration` brought to vacuum. `w1_k1` is
/// ω̃₁²/k̃₁ of the structure's bare first mode (4 for the lumped models: the uniform beam's);
/// `eigen_f` the eigenmode model's frequencies as given; `beam_frequencies` the vacuum
/// frequencies of the beam's modes per unit f₀ (for per-mode Q of the beam).
pub(super) fn to_vacuum(
    spec: &MediumSpec,
    beam: &Beam,
    calibration: &Calibration,
    eigen_f: Option<&[f64]>,
    w1_k1: f64,
    beam_frequencies: &[f64],
) -> Result<Vacuum, String> {
    let (f0, q1, qs) = (
        calibration.resonance_frequency,
        calibration.quality_factor,
        calibration.quality_factors.as_deref(),
    );
    let air = Medium::AIR;
    let (section, f_vac) = section(spec, beam, calibration.spring_constant, f0, w1_k1)?;
    let vacuum = |f_air: f64| -> Result<(crate::hydro::WetMode, f64), String> {
        section.mode_at(f_air, &air).map_err(in_medium)
    };
    if spec.calibrated_in == CalibratedIn::Vacuum {
        return Ok(Vacuum {
            f0: f_vac,
            q1,
            qs: qs.map(<[f64]>::to_vec),
            eigen_frequencies: eigen_f.map(<[f64]>::to_vec),
            section,
            warnings: Vec::new(),
        });
    }
    // the geometry's f₀ is a vacuum frequency: its mode in air from the wet-mode equation
    let air_mode = |f_vacuum: f64| wet_mode_of(f_vacuum, &section, &air).map_err(in_medium);
    let (f_air1, f_vac1) = match beam {
        Beam::Geometry { .. } => (air_mode(f0)?.frequency_hz, f0),
        Beam::Calibrated { .. } => (f0, f_vac),
    };
    let eigen_frequencies = eigen_f
        .map(|f| f.iter().map(|&x| vacuum(x).map(|m| m.1)).collect())
        .transpose()?;
    // mode j's frequency in air: the eigenmode model's as given; the beam's from its vacuum
    // frequency (f₀ times the Galerkin ratio)
    let air_frequency = |j: usize| -> Result<f64, String> {
        match (eigen_f, beam) {
            (Some(f), _) => Ok(f[j]),
            (None, _) if j == 0 => Ok(f_air1),
            (None, _) => Ok(air_mode(f_vac1 * beam_frequencies[j])?.frequency_hz),
        }
    };
    let mut warnings = Vec::new();
    let q1_int = intrinsic(
        q1,
        &vacuum(air_frequency(0)?)?.0,
        "quality_factor",
        &mut warnings,
    );
    // the eigenmode model's array is quality_factor, the beam's quality_factors
    let key = if eigen_f.is_some() {
        "quality_factor"
    } else {
        "quality_factors"
    };
    let mut intrinsic_j = |j: usize, qj: f64| -> Result<f64, String> {
        let mode = vacuum(air_frequency(j)?)?.0;
        Ok(intrinsic(qj, &mode, &format!("{key}[{j}]"), &mut warnings))
    };
    let qs = qs
        .map(|q| {
            q.iter()
                .enumerate()
                .map(|(j, &qj)| intrinsic_j(j, qj))
                .collect()
        })
        .transpose()?;
    Ok(Vacuum {
        f0: f_vac1,
        q1: q1_int,
        qs,
        eigen_frequencies,
        section,
        warnings,
    })
}

/// An error of the fluid's loading as a problem of `[medium]`.
fn in_medium(x: impl std::fmt::Display) -> String {
    format!("[medium]: {x}")
}

/// The lever's section in the fluid, and its f₀ in vacuum (module docs): the geometry's own
/// (its f₀ is a vacuum frequency); a calibrated lever's from its plan, with μ from the spring
/// constant `k` and, calibrated in air, f₀ in vacuum and μ iterated to a fixed point.
fn section(
    spec: &MediumSpec,
    beam: &Beam,
    k: f64,
    f0: f64,
    w1_k1: f64,
) -> Result<(Section, f64), String> {
    let (width, mass_per_length, f_vac) = match *beam {
        Beam::Geometry { width, si } => (width, si.mass_per_length, f0),
        Beam::Calibrated {
            plan: Some((length, width)),
            ..
        } => {
            let mu = |f: f64| k * w1_k1 / ((TAU * f).powi(2) * length);
            let mut f = f0;
            if spec.calibrated_in == CalibratedIn::Air {
                for _ in 0..8 {
                    let s = Section {
                        width,
                        mass_per_length: mu(f),
                    };
                    f = s.mode_at(f0, &Medium::AIR).map_err(in_medium)?.1;
                }
            }
            (width, mu(f), f)
        }
        Beam::Calibrated { plan: None, .. } => {
            return Err(
                "[medium] needs the lever's plan: give [cantilever] length and width (m)".into(),
            )
        }
    };
    let section = Section {
        width,
        mass_per_length,
    };
    Ok((section, f_vac))
}

impl Vacuum {
    /// The eigenmode model's modes `e` with the frequency ratios in vacuum.
    pub(super) fn ratios(&self, mut e: Eigenmodes) -> Eigenmodes {
        if let Some(fv) = &self.eigen_frequencies {
            for (j, f) in fv.iter().enumerate() {
                e.frequency[j] = f / fv[0];
            }
        }
        e
    }
}

/// Load every mode of `params` (vacuum values, time scale `time_s`) with the fluid: sets
/// [`Params::hydrodynamic`] and returns the report.
pub(super) fn load(
    spec: &MediumSpec,
    vacuum: &Vacuum,
    params: &mut Params,
    time_s: f64,
) -> Result<MediumReport, String> {
    let modes = loading(&spec.medium, &vacuum.section, params, time_s)?;
    let t = vacuum.section.mass_ratio(&spec.medium);
    let loaded = Galerkin::new(params).map_err(in_medium)?;
    let region = loaded.region(Region::Free);
    let w1 = natural_modes(region).omega[0];
    Ok(MediumReport {
        name: spec.name.clone(),
        density: spec.medium.density,
        viscosity: spec.medium.viscosity,
        calibrated_in: spec.calibrated_in,
        width: vacuum.section.width,
        mass_per_length: vacuum.section.mass_per_length,
        mass_ratio: t,
        vacuum_resonance_frequency: vacuum.f0,
        intrinsic_quality_factors: vacuum.qs.clone().unwrap_or_else(|| vec![vacuum.q1]),
        resonance_frequency: w1 / (TAU * time_s),
        quality_factor: crate::eigen::quality_factors(region)[0],
        modes,
    })
}

/// Set [`Params::hydrodynamic`] of `params` (the lever's vacuum values, time scale `time_s`
/// seconds per unit τ): every mode of the model put in `medium` at its own wet frequency
/// (module docs); with what each mode gets.
fn loading(
    medium: &Medium,
    section: &Section,
    params: &mut Params,
    time_s: f64,
) -> Result<Vec<FluidMode>, String> {
    let bare = Galerkin::new(&Params {
        hydrodynamic: None,
        ..*params
    })
    .map_err(in_medium)?;
    let natural = natural_modes(bare.region(Region::Free));
    let n = params.modes;
    let mut h = Hydrodynamic {
        added_mass: [0.0; 20],
        damping: [0.0; 20],
    };
    let mut modes = Vec::with_capacity(n);
    let t = section.mass_ratio(medium);
    for j in 0..n {
        // the eigenmode model's modal mass; 1 for the orthonormal beam modes and the point mass
        let m_j = match (&params.eigenmodes, params.structure) {
            (Some(em), Structure::Eigenmodes) => em.mass(j),
            _ => 1.0,
        };
        let f_vac = natural.omega[j] / (TAU * time_s);
        let wet = wet_mode_of(f_vac, section, medium).map_err(|x| {
            format!(
                "[medium]: mode {} ({} Hz in vacuum): {x} (fewer modes keep within it)",
                j + 1,
                crate::error::number(f_vac)
            )
        })?;
        h.added_mass[j] = m_j * wet.added_mass_ratio;
        h.damping[j] = m_j * t * wet.gamma.im * TAU * wet.frequency_hz * time_s;
        modes.push(FluidMode {
            vacuum_frequency_hz: f_vac,
            frequency_hz: wet.frequency_hz,
            reynolds: wet.reynolds,
            gamma: [wet.gamma.re, wet.gamma.im],
            added_mass_ratio: wet.added_mass_ratio,
            fluid_quality_factor: wet.quality_factor,
        });
    }
    params.hydrodynamic = Some(h);
    Ok(modes)
}

impl MediumReport {
    /// Load `params` — the probe's set with another number of modes N (`--modes`, Python's
    /// `modes=`) — with this medium, every mode at its own wet frequency as the probe's were:
    /// without it the modes beyond the probe's N would be left dry.
    ///
    /// # Errors
    /// A message naming `[medium]` when a mode's Reynolds number leaves Sader's range or the
    /// set is invalid.
    pub(crate) fn reload(&self, params: &mut Params, time_s: f64) -> Result<(), String> {
        let medium = Medium {
            density: self.density,
            viscosity: self.viscosity,
        };
        let section = Section {
            width: self.width,
            mass_per_length: self.mass_per_length,
        };
        loading(&medium, &section, params, time_s).map(|_| ())
    }
}
