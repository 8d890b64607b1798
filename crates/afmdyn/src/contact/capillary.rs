//! `capillary` — a water meniscus between tip and sample (the tapping-mode mechanism of
//! Zitzler, Herminghaus & Mugele, *Phys. Rev. B* 66 (2002) 155436: formed on contact,
//! ruptured on retraction at a distance set by its volume, so each tap loses the work of the
//! meniscus). A sphere of radius R at distance D from a flat, a meniscus of volume V wetting
//! both with contact angle θ: the liquid fills the gap D + r²/(2R) out to r₁² = 2Rd (d the
//! sphere's immersion), V = πR(d² + 2dD), and the Laplace pressure 2γcosθ/(D + d) of the
//! meniscus's meridional curvature (r₁ ≫ D + d; the circular approximation of Butt & Kappl,
//! *Adv. Colloid Interface Sci.* 146 (2009) 48, §3.1) acting over πr₁² gives
//! F = −4πRγcosθ d/(D + d) = −F_cap (1 − D/√(D² + h²)), h = √(V/(πR)) the immersion at
//! contact; at D = 0 the classic −4πRγcosθ (Israelachvili, *Intermolecular and Surface
//! Forces*, 3rd ed. 2011, §17.7). The meniscus ruptures at D_r = (1 + θ/2)V^{1/3} (Lian,
//! Thornton & Adams, *J. Colloid Interface Sci.* 161 (1993) 138). In the groups F̃_cap,
//! h̃ = h/g₀, D̃_r = D_r/g₀: no force in free flight; with the meniscus (the contact region)
//! F_c = −F̃_cap + α4 δ^{3/2} + α6 √δ δ̇ for δ ≥ 0 (Hertz and Kelvin–Voigt as DMT's) and
//! F_c = −F̃_cap(1 − D/√(D² + h̃²)), D = −δ, for 0 < D < D̃_r. The region is hysteretic as
//! JKR's: formed at V_T = 0, left at V_T = D̃_r; each tap loses
//! E_cap = F̃_cap(D̃_r + h̃ − √(D̃_r² + h̃²)). The force is continuous at D = 0 with a kink
//! (dF/dD = F̃_cap/h̃ on the meniscus side, 0 on the contact side), inside the region
//! ([`Meniscus`]).

use super::{ForceEval, Hysteresis, Law, Param, SampleSi};
use crate::error::ParamError;

/// Default capillary force at contact F̃_cap = 0.1: DMT's default adhesion (a water meniscus
/// on a 10 nm tip, 4πRγcosθ ≈ 9 nN, is of the order of van der Waals' pull-off).
pub const CAPILLARY_DEFAULT_FORCE: f64 = 0.1;
/// Default immersion at contact h̃ = 0.01 (DMT's ã₀: a meniscus of the nanometre scale).
pub const CAPILLARY_DEFAULT_MENISCUS: f64 = 0.01;
/// Default rupture distance D̃_r = 0.05: a few nanometres under the default tapping amplitude,
/// as Zitzler et al. (2002) find for the menisci of humid air.
pub const CAPILLARY_DEFAULT_RUPTURE: f64 = 0.05;

/// The capillary law's groups.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CapillaryLaw {
    /// F̃_cap = 4πRγcosθ/F̃-unit > 0: the meniscus's force at contact.
    pub capillary: f64,
    /// h̃ = √(V/(πR))/g₀ > 0: the meniscus's immersion at contact (V its volume).
    pub meniscus: f64,
    /// D̃_r = (1 + θ/2)V^{1/3}/g₀ > 0: the rupture distance.
    pub rupture: f64,
}

impl CapillaryLaw {
    fn meniscus_of(&self) -> Meniscus {
        Meniscus::new(self.capillary, self.meniscus, self.rupture)
    }
}

impl Law for CapillaryLaw {
    const TIP_RADIUS: bool = true;
    const DOC: &'static str = "capillary meniscus over a Hertz sample: formed at contact, ruptured at V_T = D̃_r (Zitzler, Herminghaus & Mugele 2002)";
    const SAMPLE_KEYS: &'static [&'static str] = &["law", "youngs_modulus", "poisson_ratio", "viscosity", "meniscus_volume", "surface_tension", "contact_angle", "z_c"];
    const PARAMS: &'static [Param] = &[
        Param {
            name: "capillary",
            symbol: "F̃_cap",
            unit: "1",
            range: "0 < F̃_cap ≤ 1e12",
            default: CAPILLARY_DEFAULT_FORCE,
            doc: "the meniscus's force at contact F̃_cap = 4πRγcosθ/F",
            si_keys: &["surface_tension", "contact_angle", "radius"],
            under_probe: Some("give the probe file's [sample] surface_tension (N/m) and contact_angle (degrees) (law = \"capillary\")"),
        },
        Param {
            name: "meniscus",
            symbol: "h̃",
            unit: "1",
            range: "1e-9 ≤ h̃ ≤ 1e6",
            default: CAPILLARY_DEFAULT_MENISCUS,
            doc: "the meniscus's immersion at contact h̃ = √(V/(πR))/g0 (V its volume)",
            si_keys: &["meniscus_volume", "radius"],
            under_probe: Some("give the probe file's [sample] meniscus_volume (m³, law = \"capillary\")"),
        },
        Param {
            name: "rupture",
            symbol: "D̃_r",
            unit: "1",
            range: "1e-9 ≤ D̃_r ≤ 1e6",
            default: CAPILLARY_DEFAULT_RUPTURE,
            doc: "the rupture distance D̃_r = (1 + θ/2)V^(1/3)/g0 (Lian et al. 1993)",
            si_keys: &["meniscus_volume", "contact_angle"],
            under_probe: Some("give the probe file's [sample] meniscus_volume (m³) and contact_angle (degrees) (law = \"capillary\")"),
        },
    ];

    super::prepared::as_given!();
    fn validate(&self) -> Result<(), ParamError> {
        let bad = |name: &'static str, value: f64, range: &'static str| {
            Err(ParamError::Law { name, value, range })
        };
        let (capillary, meniscus, rupture) = (self.capillary, self.meniscus, self.rupture);
        if !(capillary.is_finite() && capillary > 0.0 && capillary <= 1e12) {
            return bad(
                "capillary (group F̃_cap = 4πRγcosθ)",
                capillary,
                "0 < F̃_cap ≤ 1e12",
            );
        }
        // the meniscus's lengths in units of the gap: resolvable, and inside it
        if !(meniscus.is_finite() && (1e-9..=1e6).contains(&meniscus)) {
            return bad(
                "meniscus (immersion h̃ = √(V/(πR))/g₀)",
                meniscus,
                "1e-9 ≤ h̃ ≤ 1e6",
            );
        }
        if !(rupture.is_finite() && (1e-9..=1e6).contains(&rupture)) {
            return bad(
                "rupture (distance D̃_r = (1 + θ/2)V^(1/3)/g₀)",
                rupture,
                "1e-9 ≤ D̃_r ≤ 1e6",
            );
        }
        Ok(())
    }
    fn from_si(si: &SampleSi) -> Result<(Self, f64, f64), String> {
        let (rr, g0) = (si.radius.unwrap_or(0.0), si.g0);
        let (v, gamma, theta) = si.meniscus.unwrap_or((0.0, 0.0, 0.0));
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
        let law = CapillaryLaw {
            capillary: 4.0 * std::f64::consts::PI * rr * gamma * theta.cos() / si.force,
            meniscus: h / g0,
            rupture: (1.0 + 0.5 * theta) * v.cbrt() / g0,
        };
        Ok((law, si.hertz_alpha4(), si.kelvin_voigt_alpha6()))
    }
    fn not_in_liquid(&self) -> Option<&'static str> {
        Some("the meniscus of humid air does not form under a liquid")
    }
    fn force(&self, k: f64, c: f64, contact: bool, delta: f64, rate: f64) -> ForceEval {
        if !contact {
            return ForceEval::default();
        }
        // the meniscus's pull at D = −δ (∂/∂δ = −∂/∂D), with Hertz and Kelvin–Voigt
        // while indenting
        let (adh, d_adh) = self.meniscus_of().force(-delta);
        let d = delta.max(0.0);
        let s = d.sqrt();
        let visc_d = if s > 0.0 { 0.5 * c * rate / s } else { 0.0 };
        ForceEval {
            force: adh + k * d * s + c * s * rate,
            d_delta: -d_adh + 1.5 * k * s + visc_d,
            d_rate: c * s,
        }
    }
    fn potential(&self, k: f64, contact: bool, delta: f64) -> f64 {
        if !contact {
            return 0.0;
        }
        // U = ∫_{−D̃_r}^{δ} F dδ: 0 where the meniscus ruptures
        self.meniscus_of().potential(-delta) + 0.4 * k * delta.max(0.0).powf(2.5)
    }
    fn dissipative(&self, _k: f64, c: f64, delta: f64, rate: f64) -> f64 {
        c * delta.max(0.0).sqrt() * rate
    }
    fn hysteresis(&self, _alpha4: f64) -> Option<Hysteresis> {
        Some(Hysteresis {
            release_distance: self.rupture,
            pull_off_force: self.capillary,
            energy_per_tap: self.meniscus_of().hysteresis(),
        })
    }
    fn kelvin_voigt(&self) -> bool {
        true
    }
}

/// The capillary meniscus in the law's units (module docs) as a function of the distance
/// D = V_T = −δ: F̃_cap, h̃ and D̃_r. Its pull has a kink at D = 0 — dF/dD = F̃_cap/h̃ on the
/// meniscus's side, 0 in contact, where the constant-volume meniscus pulls with 4πRγcosθ
/// whatever the indentation (its height above the flat stays h) — inside the contact region;
/// the force is continuous there, so the flow and its Jacobian are too, and the adaptive
/// integrator's error control steps through it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Meniscus {
    /// F̃_cap.
    pub capillary: f64,
    /// h̃.
    pub meniscus: f64,
    /// D̃_r.
    pub rupture: f64,
}

impl Meniscus {
    /// The meniscus of force F̃_cap = `capillary`, immersion h̃ = `meniscus` and rupture distance
    /// D̃_r = `rupture` (each > 0).
    pub(crate) fn new(capillary: f64, meniscus: f64, rupture: f64) -> Meniscus {
        Meniscus {
            capillary,
            meniscus,
            rupture,
        }
    }

    /// The pull and dF/dD: F = −F̃_cap(1 − D/√(D² + h̃²)), dF/dD = F̃_cap h̃²/(D² + h̃²)^{3/2}
    /// for D > 0; −F̃_cap and 0 in contact (D ≤ 0).
    pub(crate) fn force(&self, d: f64) -> (f64, f64) {
        if d <= 0.0 {
            return (-self.capillary, 0.0);
        }
        let s = d.hypot(self.meniscus);
        (
            -self.capillary * (1.0 - d / s),
            self.capillary * self.meniscus * self.meniscus / (s * s * s),
        )
    }

    /// The potential ∫_D^{D̃_r} F dD′ (0 at rupture, F = −dU/dD): −F̃_cap(G(D̃_r) − G(D)),
    /// G(D) = D − √(D² + h̃²), for D ≥ 0, and F̃_cap D more in contact (D < 0).
    pub(crate) fn potential(&self, d: f64) -> f64 {
        let g = |d: f64| d - d.hypot(self.meniscus);
        -self.capillary * (g(self.rupture) - g(d.max(0.0))) + self.capillary * d.min(0.0)
    }

    /// The energy the meniscus takes per tap (formed at contact, ruptured at D̃_r):
    /// E_cap = −U(0) = ∫_0^{D̃_r} |F| dD = F̃_cap(D̃_r + h̃ − √(D̃_r² + h̃²)) (module docs).
    pub(crate) fn hysteresis(&self) -> f64 {
        self.capillary * (self.rupture + self.meniscus - self.rupture.hypot(self.meniscus))
    }
}
