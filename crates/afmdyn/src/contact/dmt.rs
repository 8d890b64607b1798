//! `dmt` — Derjaguin, Muller & Toporov, *J. Colloid Interface Sci.* 53 (1975) 314: with the
//! tip–sample distance d = V_T + a₀ (contact at d ≤ a₀, i.e. V_T ≤ 0),
//! F_c = −H/(a₀ + V_T)² outside contact (van der Waals, sphere–plane, H = H_amaker R/6 scaled:
//! H̃ = H_amaker R L³/(6 EI g₀³)), and
//! F_c = −H/a₀² + α4 δ^{3/2} + α6 √δ δ̇ in contact (constant DMT adhesion, Hertz repulsion,
//! Kelvin–Voigt damping ∝ contact radius √(Rδ); see García & San Paulo, *Phys. Rev. B* 60
//! (1999) 4961 and Garcia, *Amplitude Modulation AFM*, Wiley 2010, ch. 3). The force is
//! continuous at δ = 0, so the free flight is nonlinear but the switching has no force jump.

use super::{ForceEval, JetLaw, Law, Param, PreparedForce, SampleSi};
use crate::error::ParamError;

/// Default DMT groups: H̃ = 1e-5, ã₀ = 0.01, an adhesion force H̃/ã₀² = 0.1, about 5 % of the
/// largest repulsive force of the default tapping motion (α4 δ^{3/2} ≈ 2 at δ ≈ 0.1), as for a
/// silicon tip on a polymer (F_ad ≈ 4 nN against k A₀ ≈ 400 nN).
pub const DMT_DEFAULT_HAMAKER: f64 = 1e-5;
/// Default DMT intermolecular distance ã₀.
pub const DMT_DEFAULT_A0: f64 = 0.01;

/// The DMT groups' descriptors (shared with the electrostatic law).
pub(crate) const PARAMS: [Param; 2] = [
    Param {
        name: "hamaker",
        symbol: "H̃",
        unit: "1",
        range: "0 ≤ H̃ ≤ 1e12",
        default: DMT_DEFAULT_HAMAKER,
        doc: "van der Waals group H̃ = H R L³/(6 EI g0³)",
        si_keys: &["hamaker", "radius"],
        under_probe: Some("give the Hamaker constant in the probe file's [sample] hamaker (J)"),
    },
    Param {
        name: "intermolecular_distance",
        symbol: "ã0",
        unit: "1",
        range: "0 < ã₀ ≤ 1e6, H̃/ã₀² ≤ 1e12",
        default: DMT_DEFAULT_A0,
        doc: "intermolecular distance ã0 = a0/g0, the contact threshold",
        si_keys: &["intermolecular_distance"],
        under_probe: Some("give a0 in the probe file's [sample] intermolecular_distance (m)"),
    },
];

/// The DMT law's groups.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DmtLaw {
    /// H̃ = H_amaker R L³/(6 EI g₀³) ≥ 0: F_vdW = −H̃/d² with d = a₀ + V_T.
    pub hamaker: f64,
    /// ã₀ = a₀/g₀ > 0: intermolecular distance, the contact threshold.
    pub intermolecular_distance: f64,
}

/// The van der Waals attraction −H̃/d² at distance d > 0: [F, dF/dd, U], U = −H̃/d.
pub(crate) fn van_der_waals(h: f64, d: f64) -> [f64; 3] {
    [-h / (d * d), 2.0 * h / (d * d * d), -h / d]
}

/// DMT's (and the electrostatic law's) prepare step (`Law::prepare`): the law with α4, α6,
/// ã₀ and its long-range force at contact, [F, dF/dd, U] at d = ã₀ (DMT's adhesion
/// F = −H̃/ã₀²), computed once. Outside contact the long-range attraction at d = ã₀ − δ > ã₀;
/// in contact the adhesion at d = ã₀ plus Hertz and Kelvin–Voigt (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PreparedDmt<L> {
    /// The law's groups (its long-range force).
    pub law: L,
    /// α4.
    pub k: f64,
    /// α6.
    pub c: f64,
    /// ã₀.
    pub a0: f64,
    /// The long-range [F, dF/dd, U] at d = ã₀.
    pub at_contact: [f64; 3],
}

impl<L: Law> PreparedDmt<L> {
    /// `law` (with ã₀ its [`Law::distance_offset`]) with α4 = `k`, α6 = `c`.
    pub(crate) fn new(law: L, k: f64, c: f64) -> Self {
        let a0 = law.distance_offset();
        PreparedDmt {
            law,
            k,
            c,
            a0,
            at_contact: law.long_range(a0),
        }
    }
}

impl<L: Law> PreparedForce for PreparedDmt<L> {
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval {
        let (k, c) = (self.k, self.c);
        if contact {
            let d = delta.max(0.0);
            let s = d.sqrt();
            // ∂(√δ δ̇)/∂δ = δ̇/(2√δ): integrable singularity at δ = 0, 0 there
            let visc_d = if s > 0.0 { 0.5 * c * rate / s } else { 0.0 };
            ForceEval {
                force: self.at_contact[0] + k * d * s + c * s * rate,
                d_delta: 1.5 * k * s + visc_d,
                d_rate: c * s,
            }
        } else {
            // d = a₀ + V_T = a₀ − δ > a₀; ∂/∂δ = −∂/∂d
            let [force, d_d, _] = self.law.long_range(self.a0 - delta);
            ForceEval {
                force,
                d_delta: -d_d,
                d_rate: 0.0,
            }
        }
    }

    /// The long-range potential outside contact, continued by the adhesion and Hertz inside.
    fn potential(&self, contact: bool, delta: f64) -> f64 {
        if contact {
            let [f0, _, u0] = self.at_contact;
            u0 + f0 * delta + 0.4 * self.k * delta.max(0.0).powf(2.5)
        } else {
            self.law.long_range(self.a0 - delta)[2]
        }
    }

    /// The Kelvin–Voigt part α6 √δ δ̇.
    fn dissipative(&self, delta: f64, rate: f64) -> f64 {
        self.c * delta.max(0.0).sqrt() * rate
    }
}

/// The methods DMT and the electrostatic law share (their long-range force aside): the prepare
/// step [`PreparedDmt`], whose force, potential and dissipation (the Kelvin–Voigt α6 √δ δ̇) are
/// the law's, the force outside contact and the offset ã₀.
macro_rules! dmt_family {
    () => {
        type Prepared = PreparedDmt<Self>;
        fn prepare(&self, k: f64, c: f64) -> PreparedDmt<Self> {
            PreparedDmt::new(*self, k, c)
        }
        fn force(&self, k: f64, c: f64, contact: bool, delta: f64, rate: f64) -> ForceEval {
            self.prepare(k, c).force(contact, delta, rate)
        }
        fn potential(&self, k: f64, contact: bool, delta: f64) -> f64 {
            self.prepare(k, 0.0).potential(contact, delta)
        }
        fn dissipative(&self, k: f64, c: f64, delta: f64, rate: f64) -> f64 {
            self.prepare(k, c).dissipative(delta, rate)
        }
        fn acts_outside(&self) -> bool {
            true
        }
        fn distance_offset(&self) -> f64 {
            self.intermolecular_distance
        }
    };
}
pub(crate) use dmt_family;

impl Law for DmtLaw {
    const TIP_RADIUS: bool = true;
    const DOC: &'static str =
        "DMT: van der Waals attraction outside contact, adhesion + Hertz + Kelvin–Voigt inside";
    const PARAMS: &'static [Param] = &PARAMS;
    const SAMPLE_KEYS: &'static [&'static str] = &["law", "youngs_modulus", "poisson_ratio", "hamaker", "intermolecular_distance", "viscosity", "z_c"];

    fn validate(&self) -> Result<(), ParamError> {
        let (hamaker, intermolecular_distance) = (self.hamaker, self.intermolecular_distance);
        let bad = |name: &'static str, value: f64, range: &'static str| {
            Err(ParamError::Law { name, value, range })
        };
        if !(hamaker.is_finite() && (0.0..=1e12).contains(&hamaker)) {
            return bad("hamaker (DMT group H̃)", hamaker, "0 ≤ H̃ ≤ 1e12");
        }
        if !(intermolecular_distance.is_finite()
            && intermolecular_distance > 0.0
            && intermolecular_distance <= 1e6)
        {
            return bad(
                "intermolecular_distance (DMT ã₀)",
                intermolecular_distance,
                "0 < ã₀ ≤ 1e6",
            );
        }
        // the adhesion force at contact, H̃/ã₀² (the force law above): beyond 1e12 the
        // force, its derivative 2H̃/ã₀³ and the step sizes leave floating point
        let adhesion = hamaker / (intermolecular_distance * intermolecular_distance);
        if !(adhesion.is_finite() && adhesion <= 1e12) {
            return bad(
                "intermolecular_distance (DMT ã₀)",
                intermolecular_distance,
                "H̃/ã₀² ≤ 1e12 (the adhesion force at contact; raise ã₀ or lower H̃)",
            );
        }
        Ok(())
    }
    fn from_si(si: &SampleSi) -> Result<(Self, f64, f64), String> {
        let (rr, g0) = (si.radius.unwrap_or(0.0), si.g0);
        let law = DmtLaw {
            hamaker: si.hamaker.unwrap_or(0.0) * rr / (6.0 * g0 * g0 * si.force),
            intermolecular_distance: si.a0.unwrap_or(0.0) / g0,
        };
        Ok((law, si.hertz_alpha4(), si.kelvin_voigt_alpha6()))
    }
    dmt_family!();
    fn long_range(&self, d: f64) -> [f64; 3] {
        van_der_waals(self.hamaker, d)
    }
    fn kelvin_voigt(&self) -> bool {
        true
    }
    fn jet(&self, k: f64, c: f64) -> Option<JetLaw> {
        Some(JetLaw::Dmt {
            h: self.hamaker,
            a0: self.intermolecular_distance,
            k,
            c,
        })
    }
}
