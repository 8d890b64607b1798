//! Hydrodynamic loading of a rectangular cantilever in a viscous fluid: Sader's hydrodynamic
//! function (J. E. Sader, *J. Appl. Phys.* 84, 64 (1998)) and the wet resonance frequency and
//! quality factor of each flexural mode it gives.
//!
//! A beam of width b vibrating at angular frequency ω in a fluid of density ρ and viscosity η
//! feels, per unit length, the force −(π/4)ρb²ω² Γ(ω) W(ω) on its deflection W: an added mass
//! (π/4)ρb² Γ_r and a damping (π/4)ρb²ω Γ_i per unit length. Γ depends on ω only through the
//! Reynolds number Re = ρωb²/(4η) (Sader 1998). For a beam of circular cross-section of
//! diameter b it is exact (Sader 1998, after Rosenhead's oscillating cylinder):
//!
//! Γ_circ(Re) = 1 + 4 K₁(z) / (z K₀(z)),  z = −i √(i Re),
//!
//! with K₀, K₁ the modified Bessel functions of the second kind (`complex_bessel`, Amos'
//! algorithm, ACM TOMS 644); for the rectangular section, Γ_rect = Ω(Re) Γ_circ(Re) with the
//! rational fits Ω_r, Ω_i in τ = log₁₀ Re of Sader 1998 (accurate to 0.1 % against his
//! boundary-integral results over 1e-6 ≤ Re ≤ 1e4, the range accepted here).
//!
//! **Wet modes** (Sader 1998, for Q ≫ 1, as used by Chon, Mulvaney & Sader,
//! *J. Appl. Phys.* 87, 3978 (2000)): a mode of vacuum angular frequency ω_vac resonates in
//! the fluid at ω_f with
//!
//! ω_f = ω_vac (1 + T Γ_r(Re(ω_f)))^{−1/2},  T = πρb / (4ρ_c h),
//!
//! (ρ_c, h the beam's density and thickness) and quality factor
//! Q = (1/T + Γ_r(ω_f)) / Γ_i(ω_f). The equation for ω_f is solved by bisection in ln ω:
//! ω²(1 + TΓ_r) grows with ω (Γ_r falls more slowly than 1/ω), so its root is unique.
//!
//! A probe's `[medium]` loads every mode of the model with its added mass and damping at its
//! own wet frequency ([`crate::params::Hydrodynamic`], set by the probe reader's `medium`
//! part); `Section::mode_at` inverts the wet mode in closed form, which brings a lever's
//! values measured in air back to vacuum.

use crate::error::{SimError, UnitsError};
use crate::units::{positive, Cantilever};
use nalgebra::Complex;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Smallest Reynolds number of Sader's fit Ω (module docs).
pub(crate) const MIN_REYNOLDS: f64 = 1e-6;
/// Largest Reynolds number of Sader's fit Ω.
pub(crate) const MAX_REYNOLDS: f64 = 1e4;

/// A Newtonian fluid around the cantilever.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Medium {
    /// Density ρ (kg/m³), > 0.
    pub density: f64,
    /// Dynamic viscosity η (Pa s), > 0.
    pub viscosity: f64,
}

/// The density (kg/m³) from which a medium counts as a liquid ([`Medium::is_liquid`]).
pub(crate) const LIQUID_DENSITY: f64 = 100.0;

impl Medium {
    /// Water at 25 °C: ρ = 997.05 kg/m³, η = 0.890 mPa s (CRC Handbook of Chemistry and
    /// Physics, 97th ed., 2016, §6, "Properties of water in the range 0–100 °C" and
    /// "Viscosity of liquids").
    pub(crate) const WATER: Medium = Medium {
        density: 997.05,
        viscosity: 8.90e-4,
    };
    /// Dry air at 25 °C and 101.325 kPa: ρ = 1.184 kg/m³, η = 18.49 µPa s (CRC Handbook, 97th
    /// ed., §6, "Properties of air" and "Viscosity of gases").
    pub(crate) const AIR: Medium = Medium {
        density: 1.184,
        viscosity: 1.849e-5,
    };

    /// Whether the medium is a liquid: a density of [`LIQUID_DENSITY`] or more (gases at
    /// ambient conditions are below 10 kg/m³, liquids above 500).
    pub(crate) fn is_liquid(&self) -> bool {
        self.density >= LIQUID_DENSITY
    }

    /// Check that density and viscosity are finite and positive.
    ///
    /// # Errors
    /// [`UnitsError::Positive`] naming the field.
    pub(crate) fn validate(&self) -> Result<(), UnitsError> {
        positive("medium.density", self.density, "kg/m^3")?;
        positive("medium.viscosity", self.viscosity, "Pa s")?;
        Ok(())
    }

    /// The Reynolds number Re = ρωb²/(4η) of a beam of width `width` (m) vibrating at angular
    /// frequency `omega` (rad/s) (module docs).
    pub(crate) fn reynolds(&self, omega: f64, width: f64) -> f64 {
        self.density * omega * width * width / (4.0 * self.viscosity)
    }
}

/// A probe's TOML text with its `[medium]` set to the preset `name` (the command line's
/// `--medium NAME`, Python's `medium=`, which win over the file's fluid: its `density` and
/// `viscosity` go, `calibrated_in` stays), or without `[medium]` for `name = "none"` (the lever
/// as in the paper, no fluid). The name is checked when the probe is read.
///
/// # Errors
/// The TOML parser's message, or `medium must be a table`.
pub fn with_medium(text: &str, name: &str) -> Result<String, String> {
    let mut root: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| e.to_string().replace('\n', " "))?;
    if name.trim().eq_ignore_ascii_case("none") {
        root.remove("medium");
    } else {
        let m = root
            .entry("medium")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .ok_or("medium must be a table ([medium])")?;
        m.remove("density");
        m.remove("viscosity");
        m.insert("name".into(), toml::Value::String(name.into()));
    }
    Ok(toml::to_string(&root).expect("a TOML table serialises"))
}

/// The media by name: `water`, `air` ([`Medium::WATER`], [`Medium::AIR`]).
pub(crate) const MEDIA: [(&str, Medium); 2] = [("water", Medium::WATER), ("air", Medium::AIR)];

/// Check that `re` lies in Sader's range [[`MIN_REYNOLDS`], [`MAX_REYNOLDS`]].
fn check_reynolds(re: f64) -> Result<f64, SimError> {
    if (MIN_REYNOLDS..=MAX_REYNOLDS).contains(&re) {
        Ok(re)
    } else {
        Err(SimError::out_of_range(
            "reynolds",
            re,
            "must be in [1e-6, 1e4], the range of Sader's hydrodynamic function (Re = ρωb²/(4η))",
        ))
    }
}

/// Γ_circ(Re) = 1 + 4K₁(z)/(zK₀(z)), z = −i√(iRe): the hydrodynamic function of a circular
/// cylinder (module docs).
///
/// # Errors
/// [`SimError::OutOfRange`] for Re outside [`MIN_REYNOLDS`, `MAX_REYNOLDS`] (or not
/// finite); [`SimError::OutOfRange`] naming `bessel` should the Bessel functions fail.
pub(crate) fn gamma_circular(re: f64) -> Result<Complex<f64>, SimError> {
    let re = check_reynolds(re)?;
    let i = Complex::<f64>::i();
    let z = -i * (i * re).sqrt();
    let k = |nu: f64| {
        complex_bessel::besselk(nu, z)
            .map_err(|_| SimError::out_of_range("bessel", re, "K_0, K_1 of −i√(iRe) failed"))
    };
    let (k0, k1) = (k(0.0)?, k(1.0)?);
    Ok(Complex::new(1.0, 0.0) + 4.0 * k1 / (z * k0))
}

/// Ω(Re): Sader's rational fits (1998, module docs) of the rectangular section's correction to
/// Γ_circ, in τ = log₁₀ Re.
///
/// # Errors
/// [`SimError::OutOfRange`] for Re outside [[`MIN_REYNOLDS`], [`MAX_REYNOLDS`]].
pub(crate) fn rectangular_correction(re: f64) -> Result<Complex<f64>, SimError> {
    let tau = check_reynolds(re)?.log10();
    // Horner's rule on coefficients in ascending powers of τ
    let poly = |c: &[f64]| c.iter().rev().fold(0.0, |acc, &a| acc * tau + a);
    let real = poly(&[
        0.91324, -0.48274, 0.46842, -0.12886, 0.044055, -0.0035117, 0.00069085,
    ]) / poly(&[
        1.0, -0.56964, 0.48690, -0.13444, 0.045155, -0.0035862, 0.00069085,
    ]);
    let imag = poly(&[
        -0.024134,
        -0.029256,
        0.016294,
        -0.00010961,
        0.000064577,
        -0.000044510,
    ]) / poly(&[
        1.0, -0.59702, 0.55182, -0.18357, 0.079156, -0.014369, 0.0028361,
    ]);
    Ok(Complex::new(real, imag))
}

/// Γ_rect(Re) = Ω(Re) Γ_circ(Re): the hydrodynamic function of a thin rectangular beam
/// (module docs). Γ_r (added mass) and Γ_i (damping) are both positive.
///
/// # Errors
/// As [`gamma_circular`].
pub(crate) fn gamma_rectangular(re: f64) -> Result<Complex<f64>, SimError> {
    Ok(rectangular_correction(re)? * gamma_circular(re)?)
}

/// One flexural mode in the fluid (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WetMode {
    /// Resonance frequency in the fluid f_f = ω_f/2π (Hz).
    pub frequency_hz: f64,
    /// Quality factor Q = (1/T + Γ_r)/Γ_i from the fluid alone (a lever's internal and
    /// support losses come on top).
    pub quality_factor: f64,
    /// The added mass relative to the beam's, T Γ_r(ω_f): f_f = f_vac/√(1 + this).
    pub added_mass_ratio: f64,
    /// Re at ω_f.
    pub reynolds: f64,
    /// Γ_rect(Re) at ω_f.
    pub gamma: Complex<f64>,
}

/// The cross-section of a beam as the fluid sees it: its width b (m) and mass per unit length
/// μ = ρ_c b h (kg/m). T = πρb²/(4μ) is the mass of fluid in the cylinder of diameter b per
/// beam mass (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Section {
    /// Width b (m), > 0.
    pub width: f64,
    /// Mass per unit length μ (kg/m), > 0.
    pub mass_per_length: f64,
}

impl Section {
    /// The section of a rectangular beam (its width, thickness and density).
    pub fn of(beam: &Cantilever) -> Section {
        Section {
            width: beam.width,
            mass_per_length: beam.mass_per_length(),
        }
    }

    /// Check that width and mass per length are finite and positive.
    ///
    /// # Errors
    /// [`UnitsError::Positive`] naming the field.
    pub fn validate(&self) -> Result<(), UnitsError> {
        positive("cantilever.width", self.width, "m")?;
        positive("cantilever.mass_per_length", self.mass_per_length, "kg/m")?;
        Ok(())
    }

    /// T = πρb²/(4μ) in `medium`.
    pub(crate) fn mass_ratio(&self, medium: &Medium) -> f64 {
        PI * medium.density * self.width * self.width / (4.0 * self.mass_per_length)
    }

    /// The mode of this section resonating at `frequency_hz` in `medium`: its quality factor
    /// Q = (1/T + Γ_r)/Γ_i and added mass TΓ_r at that frequency, and the vacuum frequency
    /// f_vac = f √(1 + TΓ_r) it comes from (the inverse of `wet_mode_of`, closed form).
    ///
    /// # Errors
    /// As `wet_mode_of`.
    pub(crate) fn mode_at(
        &self,
        frequency_hz: f64,
        medium: &Medium,
    ) -> Result<(WetMode, f64), SimError> {
        self.validate()?;
        medium.validate()?;
        positive("frequency_hz", frequency_hz, "Hz")?;
        let omega = 2.0 * PI * frequency_hz;
        let t = self.mass_ratio(medium);
        let re = medium.reynolds(omega, self.width);
        let gamma = gamma_rectangular(re)?;
        let mode = WetMode {
            frequency_hz,
            quality_factor: (1.0 / t + gamma.re) / gamma.im,
            added_mass_ratio: t * gamma.re,
            reynolds: re,
            gamma,
        };
        Ok((mode, frequency_hz * (1.0 + t * gamma.re).sqrt()))
    }
}

/// The mode of vacuum frequency `vacuum_frequency_hz` of the rectangular beam `beam` (its
/// width, thickness and density) in `medium`: the wet frequency, quality factor and added mass
/// (module docs). `wet_mode_of` of its [`Section`].
///
/// # Errors
/// [`SimError::Units`] naming the field for an invalid beam, medium or frequency;
/// [`SimError::OutOfRange`] naming `reynolds` when the wet mode's Re leaves Sader's range.
pub fn wet_mode(
    vacuum_frequency_hz: f64,
    beam: &Cantilever,
    medium: &Medium,
) -> Result<WetMode, SimError> {
    beam.validate()?;
    wet_mode_of(vacuum_frequency_hz, &Section::of(beam), medium)
}

/// The mode of vacuum frequency `vacuum_frequency_hz` of a beam of cross-section `section` in
/// `medium`: ω_f from ω_f²(1 + TΓ_r(Re(ω_f))) = ω_vac² by bisection in ln ω (module docs).
///
/// # Errors
/// [`SimError::Units`] naming the field for an invalid section, medium or frequency;
/// [`SimError::OutOfRange`] naming `reynolds` when the wet mode's Re leaves Sader's range.
pub(crate) fn wet_mode_of(
    vacuum_frequency_hz: f64,
    section: &Section,
    medium: &Medium,
) -> Result<WetMode, SimError> {
    section.validate()?;
    medium.validate()?;
    positive("vacuum_frequency_hz", vacuum_frequency_hz, "Hz")?;
    let omega_vac = 2.0 * PI * vacuum_frequency_hz;
    let t = section.mass_ratio(medium);
    let b = section.width;
    // g(ω) = ω²(1 + TΓ_r) − ω_vac², increasing in ω; g(ω_vac) ≥ 0 since Γ_r > 0
    let g = |omega: f64| -> Result<f64, SimError> {
        let gr = gamma_rectangular(medium.reynolds(omega, b))?.re;
        Ok(omega * omega * (1.0 + t * gr) - omega_vac * omega_vac)
    };
    // the bracket: down from ω_vac by factors of 2 until g < 0 (Re stays in range or errs)
    let mut hi = omega_vac;
    let mut lo = 0.5 * omega_vac;
    let mut found = false;
    for _ in 0..60 {
        if g(lo)? < 0.0 {
            found = true;
            break;
        }
        hi = lo;
        lo *= 0.5;
    }
    if !found {
        return Err(SimError::out_of_range(
            "medium",
            medium.density,
            "no wet resonance within 60 octaves below the vacuum frequency",
        ));
    }
    // bisection in ln ω to round-off
    let (mut a, mut c) = (lo.ln(), hi.ln());
    for _ in 0..200 {
        let m = 0.5 * (a + c);
        if m <= a || m >= c {
            break;
        }
        if g(m.exp())? < 0.0 {
            a = m;
        } else {
            c = m;
        }
    }
    let omega = (0.5 * (a + c)).exp();
    let re = medium.reynolds(omega, b);
    let gamma = gamma_rectangular(re)?;
    Ok(WetMode {
        frequency_hz: omega / (2.0 * PI),
        quality_factor: (1.0 / t + gamma.re) / gamma.im,
        added_mass_ratio: t * gamma.re,
        reynolds: re,
        gamma,
    })
}

/// A value and its standard error (SI).
pub(crate) type WithError = (f64, f64);

/// Sader's method: the static spring constant k_s and mode `k`'s effective spring constant at
/// the tip k_k of a rectangular lever of plan `length` × `width` (m) in `medium`, from the
/// mode's resonance `f0` (Hz) and quality factor `q` in the fluid, each with its standard
/// error, correlated by `rho`:
///
/// k_s = (3/β_k⁴)(π/4) ρ b² L Q Γ_i(Re) ω²,  k_k = k_s β_k⁴/12,  Re = ρωb²/(4η),
///
/// the added mass and damping of Γ (module docs) in the mode's energy balance; for the first
/// mode 3/β₁⁴ · π/4 = 0.1906 (Sader, Chon & Mulvaney, *Rev. Sci. Instrum.* 70 (1999) 3967,
/// eq. 4), for the higher ones with the mode's own β_k (Lozano, Kiracofe, Melcher, García &
/// Raman, *Nanotechnology* 21 (2010) 465502). It assumes a uniform lever without a tip mass,
/// L ≫ b and Q ≫ 1. The standard errors follow from d ln k = d ln Q + (2 + d ln Γ_i/d ln ω)
/// d ln f₀.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `reynolds` where Re leaves Sader's range.
pub(crate) fn sader(
    (length, width): (f64, f64),
    medium: &Medium,
    k: usize,
    (f0, q): (WithError, WithError),
    rho: f64,
) -> Result<[WithError; 2], SimError> {
    let gi = |f: f64| -> Result<f64, SimError> {
        Ok(gamma_rectangular(medium.reynolds(2.0 * PI * f, width))?.im)
    };
    let beta4 = crate::beam::beta_root(k).powi(4);
    let omega = 2.0 * PI * f0.0;
    let k_static = 3.0 / beta4 * PI / 4.0
        * medium.density
        * width
        * width
        * length
        * q.0
        * gi(f0.0)?
        * omega
        * omega;
    let h = 1e-4;
    let slope = (gi(f0.0 * (1.0 + h))?.ln() - gi(f0.0 * (1.0 - h))?.ln()) / (2.0 * h);
    let (a, c, e) = (q.1 / q.0, f0.1 / f0.0, 2.0 + slope);
    let relative = (a * a + e * e * c * c + 2.0 * rho * a * e * c)
        .max(0.0)
        .sqrt();
    let with = |k: f64| (k, k * relative);
    Ok([with(k_static), with(k_static * beta4 / 12.0)])
}

#[cfg(test)]
mod tests;
