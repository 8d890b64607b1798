//! `electrostatic` — DMT with the electrostatic attraction of a biased tip: the sphere–plane
//! capacitor force F_es = −πε₀V²R²/(d(d + R)) (Hudlet, Saint Jean, Guthmann & Berger,
//! *Eur. Phys. J. B* 2 (1998) 5, the sphere's term; −πε₀V²R/d for d ≪ R), V the bias minus
//! the contact potential difference, in units Ẽ = πε₀V²/F̃-unit and R̃ = R/g₀:
//! F_c = −H/d² − ẼR̃²/(d(d + R̃)) outside contact, and both long-range forces at d = a₀ plus
//! Hertz and Kelvin–Voigt in contact, as DMT (continuous at δ = 0).

use super::dmt::{
    dmt_family, van_der_waals, DmtLaw, PreparedDmt,
};
use super::{ForceEval, Law, Param, PreparedForce, SampleSi};
use crate::error::ParamError;

/// ε₀, the vacuum permittivity (F/m; CODATA 2018).
pub const VACUUM_PERMITTIVITY: f64 = 8.854_187_812_8e-12;

/// Default electrostatic group Ẽ: with R̃ = 1 and ã₀ = 0.01 the electrostatic force at contact
/// is ẼR̃²/(ã₀(ã₀ + R̃)) ≈ 0.099, about DMT's default adhesion (a few volts on a 10 nm tip give
/// nanonewtons, as van der Waals does), and it decays as 1/d, not 1/d².
pub const ELECTROSTATIC_DEFAULT: f64 = 1e-3;
/// Default tip radius R̃ = R/g₀ of the electrostatic law.
pub const ELECTROSTATIC_DEFAULT_RADIUS: f64 = 1.0;

/// The electrostatic law's groups: DMT's and the biased sphere's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ElectrostaticLaw {
    /// H̃ ≥ 0, as DMT's.
    pub hamaker: f64,
    /// ã₀ > 0, as DMT's: the contact threshold.
    pub intermolecular_distance: f64,
    /// Ẽ = πε₀(V_bias − V_cpd)²/F_unit ≥ 0: F_es = −ẼR̃²/(d(d + R̃)).
    pub electrostatic: f64,
    /// R̃ = R/g₀ > 0: the tip radius.
    pub tip_radius: f64,
}

impl Law for ElectrostaticLaw {
    const TIP_RADIUS: bool = true;
    const DOC: &'static str =
        "DMT plus the electrostatic force of a biased spherical tip (Hudlet et al. 1998)";
    const SAMPLE_KEYS: &'static [&'static str] = &["law", "youngs_modulus", "poisson_ratio", "hamaker", "intermolecular_distance", "viscosity", "z_c", "bias_voltage", "contact_potential"];
    const PARAMS: &'static [Param] = &[
        super::dmt::PARAMS[0],
        super::dmt::PARAMS[1],
        Param {
            name: "electrostatic",
            symbol: "Ẽ",
            unit: "1",
            range: "0 ≤ Ẽ ≤ 1e12, ẼR̃²/(ã₀(ã₀ + R̃)) ≤ 1e12",
            default: ELECTROSTATIC_DEFAULT,
            doc: "group Ẽ = πε0 V²/F of the biased tip, F_es = -Ẽ R̃²/(d(d + R̃))",
            si_keys: &["voltage", "contact_potential"],
            under_probe: Some("give the voltage in the probe file's [sample] bias_voltage (V, law = \"electrostatic\")"),
        },
        Param {
            name: "tip_radius",
            symbol: "R̃",
            unit: "1",
            range: "0 < R̃ ≤ 1e6",
            default: ELECTROSTATIC_DEFAULT_RADIUS,
            doc: "tip radius R̃ = R/g0",
            si_keys: &["radius"],
            under_probe: Some("give the radius in the probe file's [tip] radius (m)"),
        },
    ];

    fn validate(&self) -> Result<(), ParamError> {
        let bad = |name: &'static str, value: f64, range: &'static str| {
            Err(ParamError::Law { name, value, range })
        };
        DmtLaw {
            hamaker: self.hamaker,
            intermolecular_distance: self.intermolecular_distance,
        }
        .validate()?;
        let (electrostatic, tip_radius) = (self.electrostatic, self.tip_radius);
        if !(electrostatic.is_finite() && (0.0..=1e12).contains(&electrostatic)) {
            return bad("electrostatic (group Ẽ)", electrostatic, "0 ≤ Ẽ ≤ 1e12");
        }
        if !(tip_radius.is_finite() && tip_radius > 0.0 && tip_radius <= 1e6) {
            return bad("tip_radius (R̃ = R/g₀)", tip_radius, "0 < R̃ ≤ 1e6");
        }
        let a0 = self.intermolecular_distance;
        let at_contact = electrostatic * tip_radius * tip_radius / (a0 * (a0 + tip_radius));
        if !(at_contact.is_finite() && at_contact <= 1e12) {
            return bad(
                "electrostatic (group Ẽ)",
                electrostatic,
                "ẼR̃²/(ã₀(ã₀ + R̃)) ≤ 1e12 (the electrostatic force at contact)",
            );
        }
        Ok(())
    }
    fn from_si(si: &SampleSi) -> Result<(Self, f64, f64), String> {
        let (dmt, alpha4, alpha6) = DmtLaw::from_si(si)?;
        let (rr, v) = (si.radius.unwrap_or(0.0), si.voltage.unwrap_or(0.0));
        // Hudlet et al. 1998: F = −πε₀V²R²/(d(d + R)), Ẽ = πε₀V²/F_s, R̃ = R/g₀
        let law = ElectrostaticLaw {
            hamaker: dmt.hamaker,
            intermolecular_distance: dmt.intermolecular_distance,
            electrostatic: std::f64::consts::PI * VACUUM_PERMITTIVITY * v * v
                / si.force,
            tip_radius: rr / si.g0,
        };
        Ok((law, alpha4, alpha6))
    }
    fn not_in_liquid(&self) -> Option<&'static str> {
        Some(
            "the sphere–plane force across vacuum (ε₀) ignores the liquid's permittivity and \
             ionic screening",
        )
    }
    dmt_family!();
    /// DMT's van der Waals and the biased sphere over the plane −ẼR̃²/(d(d + R̃))
    /// (Hudlet et al. 1998; U = −ẼR̃ ln((d + R̃)/d)).
    fn long_range(&self, d: f64) -> [f64; 3] {
        let (e, r) = (self.electrostatic, self.tip_radius);
        let mut out = van_der_waals(self.hamaker, d);
        let dr = d + r;
        out[0] -= e * r * r / (d * dr);
        out[1] += e * r * r * (2.0 * d + r) / (d * d * dr * dr);
        out[2] -= e * r * (dr / d).ln();
        out
    }
    fn kelvin_voigt(&self) -> bool {
        true
    }
}
