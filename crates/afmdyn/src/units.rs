//! Physical units ↔ the dimensionless set (paper eqs. 5 and 7, Hertz contact of §4).
//!
//! Eq. 7 prints α3 = C √(L⁴/EI) and α6 = (C1/L) √(L⁴/EI); non-dimensionalising eq. 3 with the
//! time scale of eq. 5 gives α3 = C L² / √(EI m) and α6 = C1 L / √(EI m). The two agree only when
//! m = 1 in the chosen units, so the dimensionally consistent forms are implemented here.

use crate::eigen::natural_modes;
use crate::error::UnitsError;
use crate::galerkin::{Galerkin, Region};
use crate::params::Params;
use serde::{Deserialize, Serialize};

/// An isotropic elastic material: Young's modulus (Pa) and Poisson ratio.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Young's modulus E (Pa).
    pub youngs_modulus: f64,
    /// Poisson ratio ν.
    pub poisson_ratio: f64,
}

/// The paper's silicon tip (§4, from its ref. 44): E₁ = 130 GPa, ν₁ = 0.27.
pub(crate) const SILICON_TIP: Material = Material {
    youngs_modulus: 130e9,
    poisson_ratio: 0.27,
};

/// Named sample materials: (name, material). Sources per entry.
pub(crate) const SAMPLE_MATERIALS: &[(&str, Material)] = &[
    // E: the paper §4 ("polystyrene (E2 = 4 GPa)", from its ref. [44]).
    // ν: 0.34, J.E. Mark (ed.), Physical Properties of Polymers Handbook, 2nd ed., Springer 2007.
    (
        "polystyrene",
        Material {
            youngs_modulus: 4e9,
            poisson_ratio: 0.34,
        },
    ),
    // E: the paper §4 ("highly oriented pyrolytic graphite (E2 = 5 GPa)", from its ref. [44]).
    // ν: 0.2, an assumed typical value for graphite (not given in the paper).
    (
        "hopg",
        Material {
            youngs_modulus: 5e9,
            poisson_ratio: 0.2,
        },
    ),
    // E: 1.32 MPa, Sylgard 184 cured at 25 °C, Johnston et al., J. Micromech. Microeng. 24
    // (2014) 035017; ν: 0.49 (near-incompressible elastomer), same source.
    (
        "pdms",
        Material {
            youngs_modulus: 1.32e6,
            poisson_ratio: 0.49,
        },
    ),
    // Muscovite mica, in-plane: E ≈ 178 GPa, ν ≈ 0.25 from the elastic constants of
    // McNeil & Grimsditch, J. Phys.: Condens. Matter 5 (1993) 1681.
    (
        "mica",
        Material {
            youngs_modulus: 178e9,
            poisson_ratio: 0.25,
        },
    ),
    // Silicon ⟨100⟩: E = 130 GPa, ν = 0.27 as the paper's tip (§4); Hopcroft, Nix & Kenny,
    // J. Microelectromech. Syst. 19 (2010) 229 give E⟨100⟩ = 130 GPa.
    ("silicon", SILICON_TIP),
];

/// Look up a sample material by name (case-insensitive).
///
/// # Errors
/// [`UnitsError::Choice`] listing the known names.
pub(crate) fn material(name: &str) -> Result<Material, UnitsError> {
    preset(SAMPLE_MATERIALS, name, "sample", "material")
}

/// The entry of `table` named `name` (case-insensitive, trimmed); else [`UnitsError::Choice`]
/// "`key` = 'name': unknown `what`, expected one of …" listing the names.
pub(crate) fn preset<T: Copy>(
    table: &[(&str, T)],
    name: &str,
    key: &str,
    what: &str,
) -> Result<T, UnitsError> {
    let wanted = name.trim().to_ascii_lowercase();
    table
        .iter()
        .find(|(n, _)| *n == wanted)
        .map(|(_, m)| *m)
        .ok_or_else(|| {
            let names: Vec<&str> = table.iter().map(|(n, _)| *n).collect();
            UnitsError::Choice(format!(
                "{key} = '{name}': unknown {what}, expected one of {}",
                names.join(", ")
            ))
        })
}

/// Hertz contact stiffness K₁ = 2E*√(RΔ) (paper §4), E* of tip and sample
/// (`crate::contact::reduced_modulus`). N/m.
pub(crate) fn hertz_stiffness(
    tip: Material,
    sample: Material,
    radius: f64,
    indentation: f64,
) -> f64 {
    let (t, s) = (tip, sample);
    let e_star = crate::contact::reduced_modulus(
        t.youngs_modulus,
        t.poisson_ratio,
        s.youngs_modulus,
        s.poisson_ratio,
    );
    2.0 * e_star * (radius * indentation).sqrt()
}

/// A rectangular cantilever: geometry and material (SI).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Cantilever {
    /// Length L (m).
    pub length: f64,
    /// Width b (m).
    pub width: f64,
    /// Thickness h (m).
    pub thickness: f64,
    /// Young's modulus E (Pa).
    pub youngs_modulus: f64,
    /// Density ρ (kg/m³).
    pub density: f64,
}

impl Cantilever {
    /// Check every field is finite and > 0.
    ///
    /// # Errors
    /// [`UnitsError::Positive`] naming the field.
    pub fn validate(&self) -> Result<(), UnitsError> {
        for (name, value, unit) in [
            ("length", self.length, "m"),
            ("width", self.width, "m"),
            ("thickness", self.thickness, "m"),
            ("youngs_modulus", self.youngs_modulus, "Pa"),
            ("density", self.density, "kg/m^3"),
        ] {
            positive(name, value, unit)?;
        }
        Ok(())
    }
    /// Second moment of area I = b h³ / 12 (m⁴).
    pub(crate) fn inertia(&self) -> f64 {
        self.width * self.thickness.powi(3) / 12.0
    }
    /// Bending stiffness EI (N m²).
    pub(crate) fn bending_stiffness(&self) -> f64 {
        self.youngs_modulus * self.inertia()
    }
    /// Mass per unit length m = ρ b h (kg/m).
    pub(crate) fn mass_per_length(&self) -> f64 {
        self.density * self.width * self.thickness
    }
    /// Static spring constant K_c = 3EI/L³ (N/m), paper §4.
    pub fn spring_constant(&self) -> f64 {
        3.0 * self.bending_stiffness() / self.length.powi(3)
    }
    /// Seconds per unit of dimensionless time (the time scale of the beam without a tip mass).
    pub(crate) fn time_scale(&self) -> f64 {
        self.with_tip(0.0).time_scale()
    }
    /// The beam of eq. 3 this cantilever makes with a tip mass M (kg).
    pub(crate) fn with_tip(&self, tip_mass: f64) -> BeamSi {
        BeamSi {
            length: self.length,
            bending_stiffness: self.bending_stiffness(),
            mass_per_length: self.mass_per_length(),
            tip_mass,
        }
    }
    /// First natural frequency of the bare cantilever f₁ = β₁² √(EI/(mL⁴)) / 2π (Hz).
    pub(crate) fn first_frequency_hz(&self) -> f64 {
        crate::beam::beta_root(1).powi(2) / self.time_scale() / std::f64::consts::TAU
    }
}

/// The beam of eq. 3 in SI — length L, bending stiffness EI, mass per unit length m, tip mass M —
/// and what the model's groups take from it: the one route from a cantilever's SI values to the
/// tip-mass ratio, the time scale and the stiffness unit, for `units`
/// ([`PhysicalModel::to_params`]) and for a probe file given by its geometry (`crate::probe`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BeamSi {
    /// Length L (m).
    pub length: f64,
    /// Bending stiffness EI (N m²).
    pub bending_stiffness: f64,
    /// Mass per unit length m (kg/m).
    pub mass_per_length: f64,
    /// Tip mass M (kg).
    pub tip_mass: f64,
}

impl BeamSi {
    /// The tip-mass ratio α1 = M/(mL) (eq. 7).
    pub(crate) fn tip_mass_ratio(&self) -> f64 {
        self.tip_mass / (self.mass_per_length * self.length)
    }
    /// Seconds per unit of dimensionless time: t = τ √(mL⁴/EI) (eq. 5).
    pub(crate) fn time_scale(&self) -> f64 {
        (self.mass_per_length * self.length.powi(4) / self.bending_stiffness).sqrt()
    }
    /// The stiffness unit EI/L³ (N/m), in which α4 measures the contact stiffness K₁.
    pub(crate) fn stiffness_unit(&self) -> f64 {
        self.bending_stiffness / self.length.powi(3)
    }
}

/// The resolved physical model in SI units (the dimensional counterpart of [`Params`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PhysicalModel {
    /// The cantilever.
    pub cantilever: Cantilever,
    /// Number of Galerkin modes N.
    pub modes: usize,
    /// Tip mass M (kg).
    pub tip_mass: f64,
    /// Beam viscous damping per unit length C (N s/m²).
    pub beam_damping: f64,
    /// Contact stiffness K₁ (N/m).
    pub contact_stiffness: f64,
    /// Contact damping C₁ (N s/m).
    pub contact_damping: f64,
    /// Base-drive amplitude f (m).
    pub drive_amplitude: f64,
    /// Beam–substrate gap g₀ (m), the length scale of W (eq. 5).
    pub beam_gap: f64,
    /// Tip–sample gap g₁ (m).
    pub tip_gap: f64,
    /// Drive frequency (Hz).
    pub drive_frequency_hz: f64,
}

/// Scales that turn dimensionless results back into SI.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Scales {
    /// Seconds per unit τ (eq. 5).
    pub time_s: f64,
    /// Metres per unit W (= g₀, eq. 5).
    pub length_m: f64,
    /// Static spring constant K_c = 3EI/L³ (N/m).
    pub spring_constant: f64,
    /// First natural frequency with the tip mass (Hz): ω₁ of K x = ω² M x with M of eq. 11
    /// (what a resonance measurement of the probe gives).
    pub first_frequency_hz: f64,
    /// First natural frequency of the bare cantilever without the tip mass (Hz),
    /// β₁² √(EI/(mL⁴))/2π.
    pub bare_first_frequency_hz: f64,
}

impl PhysicalModel {
    /// Validate every field.
    ///
    /// # Errors
    /// [`UnitsError`] naming the field and its range.
    pub fn validate(&self) -> Result<(), UnitsError> {
        self.cantilever.validate()?;
        for (name, value, unit) in [
            ("tip_mass", self.tip_mass, "kg"),
            ("beam_damping", self.beam_damping, "N s/m^2"),
            ("contact_stiffness", self.contact_stiffness, "N/m"),
            ("contact_damping", self.contact_damping, "N s/m"),
            ("drive_amplitude", self.drive_amplitude, "m"),
        ] {
            non_negative(name, value, unit)?;
        }
        positive("beam_gap", self.beam_gap, "m")?;
        positive("drive_frequency_hz", self.drive_frequency_hz, "Hz")?;
        if !self.tip_gap.is_finite() {
            return Err(UnitsError::Finite {
                name: "tip_gap",
                value: self.tip_gap,
                unit: "m",
            });
        }
        Ok(())
    }

    /// The dimensionless set (eq. 7; α3 and α6 in the consistent form of the module docs) and
    /// Ω = ω √(mL⁴/EI) (eq. 5).
    ///
    /// # Errors
    /// [`UnitsError`] for invalid physical input.
    pub fn to_params(&self) -> Result<Params, UnitsError> {
        self.validate()?;
        let beam = self.cantilever.with_tip(self.tip_mass);
        let (l, m, ei) = (beam.length, beam.mass_per_length, beam.bending_stiffness);
        let root = (ei * m).sqrt();
        let p = Params {
            contact_law: Default::default(),
            modes: self.modes,
            alpha1: beam.tip_mass_ratio(),
            alpha2: self.drive_amplitude / self.beam_gap,
            alpha3: self.beam_damping * l * l / root,
            alpha4: self.contact_stiffness * l.powi(3) / ei,
            alpha5: self.tip_gap / self.beam_gap,
            alpha6: self.contact_damping * l / root,
            omega: std::f64::consts::TAU * self.drive_frequency_hz * beam.time_scale(),
            ..Params::default()
        };
        p.validate()?;
        Ok(p)
    }

    /// The inverse map: physical values from a dimensionless set, a cantilever and g₀.
    ///
    /// # Errors
    /// [`UnitsError`] for an invalid cantilever, g₀ or parameter set.
    pub fn from_params(
        cantilever: Cantilever,
        p: &Params,
        beam_gap: f64,
    ) -> Result<Self, UnitsError> {
        cantilever.validate()?;
        positive("beam_gap", beam_gap, "m")?;
        p.validate()?;
        let beam = cantilever.with_tip(0.0);
        let (l, m, ei) = (beam.length, beam.mass_per_length, beam.bending_stiffness);
        let root = (ei * m).sqrt();
        Ok(PhysicalModel {
            cantilever,
            modes: p.modes,
            tip_mass: p.alpha1 * m * l,
            beam_damping: p.alpha3 * root / (l * l),
            contact_stiffness: p.alpha4 * ei / l.powi(3),
            contact_damping: p.alpha6 * root / l,
            drive_amplitude: p.alpha2 * beam_gap,
            beam_gap,
            tip_gap: p.alpha5 * beam_gap,
            drive_frequency_hz: p.omega / cantilever.time_scale() / std::f64::consts::TAU,
        })
    }

    /// Time and length scales.
    pub(crate) fn scales(&self) -> Scales {
        let bare = self.cantilever.first_frequency_hz();
        // with the tip mass: the first eigenvalue of the Galerkin system (eq. 11)
        let with_tip = self
            .to_params()
            .ok()
            .and_then(|p| Galerkin::new(&p).ok())
            .map(|g| natural_modes(g.region(Region::Free)).omega[0])
            .map_or(bare, |w| {
                w / self.cantilever.time_scale() / std::f64::consts::TAU
            });
        Scales {
            time_s: self.cantilever.time_scale(),
            length_m: self.beam_gap,
            spring_constant: self.cantilever.spring_constant(),
            first_frequency_hz: with_tip,
            bare_first_frequency_hz: bare,
        }
    }
}

/// Contact stiffness given directly (N/m) or by the Hertz model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum ContactStiffness {
    /// K₁ in N/m.
    Direct(f64),
    /// K₁ = 2E*√(RΔ).
    Hertz {
        /// Tip material.
        tip: Material,
        /// Sample material.
        sample: Material,
        /// Tip radius R (m).
        radius: f64,
        /// Indentation Δ (m).
        indentation: f64,
    },
}

/// Resolve a damping given as Q₁ into C: α3 = ω₁ / (Q₁ x₁ᵀx₁) for the first mass-normalised
/// free mode x₁ (C^I = α3·I, eq. 12), then C = α3 √(EI m)/L².
///
/// # Errors
/// [`UnitsError`] for Q₁ ≤ 0 or an invalid model.
pub(crate) fn beam_damping_from_q(model: &PhysicalModel, q1: f64) -> Result<f64, UnitsError> {
    positive("quality_factor", q1, "1")?;
    let mut undamped = *model;
    undamped.beam_damping = 0.0;
    let p = undamped.to_params()?;
    let g = Galerkin::new(&p)?;
    let modes = natural_modes(g.region(Region::Free));
    let x1 = modes.vectors.column(0).into_owned();
    let alpha3 = crate::eigen::beam_damping_for_q(modes.omega[0], &x1, q1, None);
    let c = &model.cantilever;
    Ok(alpha3 * (c.bending_stiffness() * c.mass_per_length()).sqrt() / c.length.powi(2))
}

/// Resolve a Hertz or direct contact stiffness into K₁ (N/m).
///
/// # Errors
/// [`UnitsError`] for a non-positive radius/indentation/modulus or a Poisson ratio out of range.
pub(crate) fn contact_stiffness(k: ContactStiffness) -> Result<f64, UnitsError> {
    match k {
        ContactStiffness::Direct(k1) => non_negative("contact_stiffness", k1, "N/m"),
        ContactStiffness::Hertz {
            tip,
            sample,
            radius,
            indentation,
        } => {
            positive("tip_radius", radius, "m")?;
            non_negative("indentation", indentation, "m")?;
            for (m, modulus, poisson) in [
                (tip, "tip_youngs_modulus", "tip_poisson_ratio"),
                (sample, "sample_youngs_modulus", "sample_poisson_ratio"),
            ] {
                positive(modulus, m.youngs_modulus, "Pa")?;
                if !(m.poisson_ratio > -1.0 && m.poisson_ratio <= 0.5) {
                    return Err(UnitsError::Poisson {
                        name: poisson,
                        value: m.poisson_ratio,
                    });
                }
            }
            Ok(hertz_stiffness(tip, sample, radius, indentation))
        }
    }
}

/// `value` if finite and > 0, else [`UnitsError::Positive`] naming `name` and its `unit`.
pub(crate) fn positive(
    name: &'static str,
    value: f64,
    unit: &'static str,
) -> Result<f64, UnitsError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(UnitsError::Positive { name, value, unit })
    }
}

fn non_negative(name: &'static str, value: f64, unit: &'static str) -> Result<f64, UnitsError> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(UnitsError::NonNegative { name, value, unit })
    }
}

/// The physical-model file of `afmdyn units --config` (`examples/probe.toml`): the paper's
/// model in SI — the beam's geometry and material, the tip mass, the beam damping C or Q₁,
/// the contact stiffness K₁ (given, or from Hertz at an indentation), the contact damping, the
/// base drive, the gaps g₀ and g₁ and the drive frequency. [`PhysicalFile::resolve`] gives the
/// [`PhysicalModel`].
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhysicalFile {
    /// Galerkin modes N (default 3).
    pub modes: Option<usize>,
    /// Beam length L (m).
    pub length: f64,
    /// Beam width b (m).
    pub width: f64,
    /// Beam thickness h (m).
    pub thickness: f64,
    /// Young's modulus E (Pa).
    pub youngs_modulus: f64,
    /// Density ρ (kg/m³).
    pub density: f64,
    /// Tip mass M (kg).
    pub tip_mass: f64,
    /// Beam damping per unit length C (N s/m²); exclusive with `quality_factor`.
    pub beam_damping: Option<f64>,
    /// Quality factor Q₁ of the first mode; exclusive with `beam_damping`.
    pub quality_factor: Option<f64>,
    /// Contact stiffness K₁ (N/m); exclusive with `[hertz]`.
    pub contact_stiffness: Option<f64>,
    /// K₁ from the Hertz contact at an indentation; exclusive with `contact_stiffness`.
    pub hertz: Option<HertzFile>,
    /// Contact damping C₁ (N s/m).
    pub contact_damping: f64,
    /// Base-drive amplitude f (m).
    pub drive_amplitude: f64,
    /// Beam–substrate gap g₀ (m).
    pub beam_gap: f64,
    /// Tip–sample gap g₁ (m).
    pub tip_gap: f64,
    /// Drive frequency (Hz).
    pub drive_frequency_hz: f64,
}

/// The `[hertz]` table of a [`PhysicalFile`]: K₁ as the Hertz contact's tangent stiffness at
/// an indentation (`ContactStiffness::Hertz`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HertzFile {
    /// Tip radius R (m).
    pub tip_radius: f64,
    /// Indentation δ (m) at which K₁ is taken.
    pub indentation: f64,
    /// Tip Young's modulus (Pa), default silicon (`SILICON_TIP`).
    pub tip_youngs_modulus: Option<f64>,
    /// Tip Poisson ratio, default silicon.
    pub tip_poisson_ratio: Option<f64>,
    /// A sample material by name (`material`); exclusive with the two moduli below.
    pub sample: Option<String>,
    /// Sample Young's modulus (Pa).
    pub sample_youngs_modulus: Option<f64>,
    /// Sample Poisson ratio.
    pub sample_poisson_ratio: Option<f64>,
}

impl PhysicalFile {
    /// The physical model of the file: K₁ from `contact_stiffness` or `[hertz]`, C from
    /// `beam_damping` or Q₁ (`beam_damping_from_q`).
    ///
    /// # Errors
    /// [`UnitsError::Choice`] when both or neither of an exclusive pair are given; the range
    /// errors of `contact_stiffness`, `material` and `beam_damping_from_q`.
    pub fn resolve(&self) -> Result<PhysicalModel, UnitsError> {
        let choice = |m: &str| UnitsError::Choice(m.into());
        let k1 = match (self.contact_stiffness, &self.hertz) {
            (Some(k), None) => contact_stiffness(ContactStiffness::Direct(k))?,
            (None, Some(h)) => {
                let sample =
                    match (&h.sample, h.sample_youngs_modulus, h.sample_poisson_ratio) {
                        (Some(name), None, None) => material(name)?,
                        (None, Some(e), Some(nu)) => Material {
                            youngs_modulus: e,
                            poisson_ratio: nu,
                        },
                        _ => return Err(choice(
                            "hertz: give either sample = \"name\" or both sample_youngs_modulus \
                             and sample_poisson_ratio",
                        )),
                    };
                let tip = Material {
                    youngs_modulus: h.tip_youngs_modulus.unwrap_or(SILICON_TIP.youngs_modulus),
                    poisson_ratio: h.tip_poisson_ratio.unwrap_or(SILICON_TIP.poisson_ratio),
                };
                contact_stiffness(ContactStiffness::Hertz {
                    tip,
                    sample,
                    radius: h.tip_radius,
                    indentation: h.indentation,
                })?
            }
            _ => return Err(choice("give exactly one of contact_stiffness or [hertz]")),
        };
        let mut model = PhysicalModel {
            cantilever: Cantilever {
                length: self.length,
                width: self.width,
                thickness: self.thickness,
                youngs_modulus: self.youngs_modulus,
                density: self.density,
            },
            modes: self.modes.unwrap_or(3),
            tip_mass: self.tip_mass,
            beam_damping: 0.0,
            contact_stiffness: k1,
            contact_damping: self.contact_damping,
            drive_amplitude: self.drive_amplitude,
            beam_gap: self.beam_gap,
            tip_gap: self.tip_gap,
            drive_frequency_hz: self.drive_frequency_hz,
        };
        model.beam_damping = match (self.beam_damping, self.quality_factor) {
            (Some(c), None) => c,
            (None, Some(q)) => beam_damping_from_q(&model, q)?,
            _ => return Err(choice("give exactly one of beam_damping or quality_factor")),
        };
        Ok(model)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// examples/probe.toml resolves; K₁ given directly is kept; both or neither of an exclusive
    /// pair is refused with the choice named; Q₁ gives the C whose first-mode Q is Q₁.
    #[test]
    fn a_physical_file_resolves_its_choices() {
        let text = include_str!("../../../examples/probe.toml");
        let file: PhysicalFile = toml::from_str(text).unwrap();
        let m = file.resolve().unwrap();
        assert!(m.contact_stiffness > 0.0 && m.beam_damping > 0.0);
        let direct = PhysicalFile {
            contact_stiffness: Some(5.0),
            hertz: None,
            ..file.clone()
        };
        assert_eq!(direct.resolve().unwrap().contact_stiffness, 5.0);
        let both = PhysicalFile {
            contact_stiffness: Some(5.0),
            hertz: Some(HertzFile {
                tip_radius: 1e-8,
                indentation: 1e-9,
                tip_youngs_modulus: None,
                tip_poisson_ratio: None,
                sample: Some("polystyrene".into()),
                sample_youngs_modulus: None,
                sample_poisson_ratio: None,
            }),
            ..file.clone()
        };
        assert_eq!(
            both.resolve().unwrap_err().to_string(),
            "give exactly one of contact_stiffness or [hertz]"
        );
        let q = PhysicalFile {
            beam_damping: Some(1e-3),
            quality_factor: Some(100.0),
            ..direct.clone()
        };
        assert_eq!(
            q.resolve().unwrap_err().to_string(),
            "give exactly one of beam_damping or quality_factor"
        );
        let by_q = PhysicalFile {
            beam_damping: None,
            quality_factor: Some(100.0),
            ..direct
        };
        let c = by_q.resolve().unwrap().beam_damping;
        let model = PhysicalModel {
            beam_damping: 0.0,
            ..by_q.resolve().unwrap()
        };
        assert_eq!(c, beam_damping_from_q(&model, 100.0).unwrap());
    }
}
