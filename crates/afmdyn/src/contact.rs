//! Tip–sample force laws F_c(δ, δ̇), in the paper's dimensionless units.
//!
//! δ = −V_T is the indentation (V_T of eq. 8) and δ̇ = −dV_T/dτ its rate. F_c is **repulsive
//! positive** (it pushes the tip away from the sample) and enters the modal equations as the tip
//! force φ(1)·F_c:
//!
//! M ä + C ȧ + K a = F^I(τ) + φ(1) F_c(δ, δ̇)   (eqs. 11–14 with the contact at ξ = 1).
//!
//! For the linear law F_c = α4 δ + α6 δ̇ this is exactly eqs. 15–18 (K^II = K^I + α4 φφᵀ,
//! C^II = C^I + α6 φφᵀ, F^II = F^I − φ(α4(α2 sin Ωτ + α5) + α6 α2 Ω cos Ωτ)).
//! A force is the scaled force F̃ = F L³/(EI g₀), the unit of α4 V_T.
//!
//! Laws ([`ContactLaw`]):
//! * `linear` — the paper: F_c = α4 δ + α6 δ̇ while δ ≥ 0 (eqs. 16–18).
//! * `hertz` — F_c = α4 δ^{3/2} + α6 δ̇ while δ ≥ 0 (Hertz 1882; Johnson, *Contact Mechanics*,
//!   CUP 1985, §4.2: F = (4/3) E* √R δ^{3/2}, so α4 = (4/3) E* √(R g₀) L³/(EI)).
//! * `dmt` — Derjaguin, Muller & Toporov, *J. Colloid Interface Sci.* 53 (1975) 314: with the
//!   tip–sample distance d = V_T + a₀ (contact at d ≤ a₀, i.e. V_T ≤ 0),
//!   F_c = −H/(a₀ + V_T)² outside contact (van der Waals, sphere–plane, H = H_amaker R/6 scaled:
//!   H̃ = H_amaker R L³/(6 EI g₀³)), and
//!   F_c = −H/a₀² + α4 δ^{3/2} + α6 √δ δ̇ in contact (constant DMT adhesion, Hertz repulsion,
//!   Kelvin–Voigt damping ∝ contact radius √(Rδ); see García & San Paulo, *Phys. Rev. B* 60
//!   (1999) 4961 and Garcia, *Amplitude Modulation AFM*, Wiley 2010, ch. 3). The force is
//!   continuous at δ = 0, so the free flight is nonlinear but the switching has no force jump.
//! * `electrostatic` — DMT with the electrostatic attraction of a biased tip: the sphere–plane
//!   capacitor force F_es = −πε₀V²R²/(d(d + R)) (Hudlet, Saint Jean, Guthmann & Berger,
//!   *Eur. Phys. J. B* 2 (1998) 5, the sphere's term; −πε₀V²R/d for d ≪ R), V the bias minus
//!   the contact potential difference, in units Ẽ = πε₀V²/F̃-unit and R̃ = R/g₀:
//!   F_c = −H/d² − ẼR̃²/(d(d + R̃)) outside contact, and both long-range forces at d = a₀ plus
//!   Hertz and Kelvin–Voigt in contact, as DMT (continuous at δ = 0).
//! * `jkr` — Johnson, Kendall & Roberts, *Proc. R. Soc. Lond. A* 324 (1971) 301: a compliant,
//!   adhesive sphere–flat contact with a neck. No force outside contact. In contact the contact
//!   radius a sets both the force and the indentation (Johnson, *Contact Mechanics*, CUP 1985,
//!   §5.5): F = 4E*a³/(3R) − √(8πWE*a³), δ = a²/R − √(2πWa/E*). With h = a²/R (the Hertz
//!   indentation of that radius), q = h^{1/4}, the Hertz group α4 = (4/3)E*√(R g₀) L³/(EI) and
//!   the adhesion group P̃ = πWR/F̃-unit this is, exactly,
//!   F_c = α4 q⁶ − √(6P̃α4) q³ + α6 q² δ̇,  δ = q⁴ − c q,  c = √(8P̃/(3α4)),
//!   the damper α6 q² δ̇ = α6 √h δ̇ being Kelvin–Voigt's ∝ the contact radius a = √(Rh), as
//!   DMT's. The contact forms at δ = 0 on approach (the force jumps to −(4/3)P̃, a₀³ = 2πWR²/E*),
//!   and breaks on retraction where the branch ends, dδ/da = 0: δ_f = −3 q_f⁴, q_f³ = c/4
//!   (−(3/4)(π²W²R/E*²)^{1/3} in SI, the pull-off under fixed grips, force −(5/6)P̃). The
//!   load-controlled pull-off, min F = −(3/2)P̃ = −(3/2)πWR, lies on the branch. Each tap loses
//!   the hysteresis E_hys = ∫_{δ_f}^0 |F| dδ = (3/5 + 4^{−1/3}/10) P̃ c^{4/3}
//!   = (3/5 + 4^{−1/3}/10) 2^{2/3} π^{5/3} (W⁵R⁴/E*²)^{1/3} ≈ 7.09 (W⁵R⁴/E*²)^{1/3} (from
//!   the potential below). The region is hysteretic: contact persists while δ > δ_f.
//! * `capillary` — a water meniscus between tip and sample (the tapping-mode mechanism of
//!   Zitzler, Herminghaus & Mugele, *Phys. Rev. B* 66 (2002) 155436: formed on contact,
//!   ruptured on retraction at a distance set by its volume, so each tap loses the work of the
//!   meniscus). A sphere of radius R at distance D from a flat, a meniscus of volume V wetting
//!   both with contact angle θ: the liquid fills the gap D + r²/(2R) out to r₁² = 2Rd (d the
//!   sphere's immersion), V = πR(d² + 2dD), and the Laplace pressure 2γcosθ/(D + d) of the
//!   meniscus's meridional curvature (r₁ ≫ D + d; the circular approximation of Butt & Kappl,
//!   *Adv. Colloid Interface Sci.* 146 (2009) 48, §3.1) acting over πr₁² gives
//!   F = −4πRγcosθ d/(D + d) = −F_cap (1 − D/√(D² + h²)), h = √(V/(πR)) the immersion at
//!   contact; at D = 0 the classic −4πRγcosθ (Israelachvili, *Intermolecular and Surface
//!   Forces*, 3rd ed. 2011, §17.7). The meniscus ruptures at D_r = (1 + θ/2)V^{1/3} (Lian,
//!   Thornton & Adams, *J. Colloid Interface Sci.* 161 (1993) 138). In the groups F̃_cap,
//!   h̃ = h/g₀, D̃_r = D_r/g₀: no force in free flight; with the meniscus (the contact region)
//!   F_c = −F̃_cap + α4 δ^{3/2} + α6 √δ δ̇ for δ ≥ 0 (Hertz and Kelvin–Voigt as DMT's) and
//!   F_c = −F̃_cap(1 − D/√(D² + h̃²)), D = −δ, for 0 < D < D̃_r. The region is hysteretic as
//!   JKR's: formed at V_T = 0, left at V_T = D̃_r; each tap loses
//!   E_cap = F̃_cap(D̃_r + h̃ − √(D̃_r² + h̃²)). The force is continuous at D = 0 with a kink
//!   (dF/dD = F̃_cap/h̃ on the meniscus side, 0 on the contact side), inside the region
//!   ([`Meniscus`]).
//! * `sls` — the standard linear solid (Zener) sample with surface memory (López-Guerra &
//!   Solares, *Beilstein J. Nanotechnol.* 5 (2014) 2149, §2; Zener, *Elasticity and Anelasticity
//!   of Metals*, Chicago 1948): the relaxed spring α4 in parallel with a Maxwell arm, the spring
//!   κ in series with the dashpot α6. Its internal state is the dashpot's extension u (units of
//!   g₀, the state's last entry). In contact the sample's surface follows the tip, δ = −V_T, and
//!   F_c = α4 δ + κ(δ − u), u̇ = (κ/α6)(δ − u); the force never pulls: the tip leaves the
//!   surface where F_c falls to 0. Free of the tip, the massless surface sits where its springs
//!   balance, at the depression s(u) = κu/(α4 + κ), and recovers as u̇ = −α4κ u/(α6(α4 + κ));
//!   the tip touches it again where V_T = −s(u). Both guards are therefore σ(V_T + s(u)), the
//!   contact's being F_c/(α4 + κ). The energy stored in the sample is
//!   U = ½α4 δ_s² + ½κ(δ_s − u)² (δ_s the surface's depression), continuous at the switchings,
//!   and the dashpot dissipates α6 u̇² in and out of contact. Under a prescribed indentation
//!   δ₀ sin ωτ held in contact it dissipates πκωτ_r δ₀²/(1 + ω²τ_r²) per cycle, τ_r = α6/κ
//!   (the loss of a Maxwell element, e.g. Lakes, *Viscoelastic Materials*, CUP 2009, §2.7). κ → 0
//!   is the linear law without damper; κ → ∞ a Kelvin–Voigt solid α4, α6 whose surface lags
//!   the tip. ([`Zener`]; the model carries u, [`crate::CantileverModel`].)
//! * `impact` — the impact oscillator of the paper's Fig. 1b: a rigid sample at V_T = 0 with
//!   Newton's coefficient of restitution r: dV_T/dτ⁺ = −r dV_T/dτ⁻ (Shaw & Holmes, *J. Sound Vib.*
//!   90 (1983) 129; Nordmark, *J. Sound Vib.* 145 (1991) 279). No force acts in free flight; the
//!   impulse and the sticking phase are handled by the model ([`crate::model`]).

/// The sign convention of every tip–sample force afmdyn outputs (the `contact_force` column of
/// `simulate`, the approach's `peak_force`, `min_force`, `max_abs_force` and force traces,
/// Python's `contact_force`): F_c is the force the sample exerts on the tip along the outward
/// normal of the sample, the law's F_c(δ, δ̇) with δ = −V_T.
pub const FORCE_SIGN: &str = "positive when the sample pushes the tip away (repulsion, e.g. at \
    the deepest indentation), negative when it pulls the tip towards it (attraction, e.g. DMT's \
    van der Waals force in free flight)";

use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// A tip–sample law and its own dimensionless groups. The stiffness α4 and damping α6 of
/// [`crate::Params`] are shared by the linear, Hertz and DMT laws.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "law", rename_all = "lowercase")]
pub enum ContactLaw {
    /// The paper's spring–damper: F_c = α4 δ + α6 δ̇ (eqs. 16–18).
    #[default]
    Linear,
    /// Hertz sphere–flat repulsion with a viscous damper: F_c = α4 δ^{3/2} + α6 δ̇.
    Hertz,
    /// DMT: van der Waals attraction outside contact, adhesion + Hertz + Kelvin–Voigt inside.
    Dmt {
        /// H̃ = H_amaker R L³/(6 EI g₀³) ≥ 0: F_vdW = −H̃/d² with d = a₀ + V_T.
        hamaker: f64,
        /// ã₀ = a₀/g₀ > 0: intermolecular distance, the contact threshold.
        intermolecular_distance: f64,
    },
    /// DMT plus the electrostatic force of a biased spherical tip (Hudlet et al. 1998).
    Electrostatic {
        /// H̃ ≥ 0, as DMT's.
        hamaker: f64,
        /// ã₀ > 0, as DMT's: the contact threshold.
        intermolecular_distance: f64,
        /// Ẽ = πε₀(V_bias − V_cpd)²/F_unit ≥ 0: F_es = −ẼR̃²/(d(d + R̃)).
        electrostatic: f64,
        /// R̃ = R/g₀ > 0: the tip radius.
        tip_radius: f64,
    },
    /// JKR: adhesive Hertz contact with a neck, formed at δ = 0, broken at δ_f < 0
    /// (Johnson, Kendall & Roberts 1971; module docs).
    Jkr {
        /// P̃ = πWR/F̃-unit > 0 (W the work of adhesion): the load-controlled pull-off force is
        /// (3/2)P̃.
        adhesion: f64,
    },
    /// Capillary meniscus over a Hertz sample: formed at contact, ruptured at V_T = D̃_r
    /// (Zitzler, Herminghaus & Mugele 2002; module docs).
    Capillary {
        /// F̃_cap = 4πRγcosθ/F̃-unit > 0: the meniscus's force at contact.
        capillary: f64,
        /// h̃ = √(V/(πR))/g₀ > 0: the meniscus's immersion at contact (V its volume).
        meniscus: f64,
        /// D̃_r = (1 + θ/2)V^{1/3}/g₀ > 0: the rupture distance.
        rupture: f64,
    },
    /// Standard linear solid (Zener) sample with surface memory: the relaxed spring α4 in
    /// parallel with a Maxwell arm (spring κ, dashpot α6), one internal state (module docs).
    Sls {
        /// κ ≥ 0: the Maxwell arm's spring (units of α4); the instantaneous stiffness is α4 + κ
        /// and the relaxation time α6/κ.
        maxwell_stiffness: f64,
    },
    /// Rigid sample with coefficient of restitution r ∈ [0, 1] (impact oscillator, Fig. 1b).
    Impact {
        /// Newton's coefficient of restitution r.
        restitution: f64,
    },
}

impl ContactLaw {
    /// Distance d − V_T between tip–sample distance and switching function: ã₀ for DMT
    /// (d = a₀ + V_T, contact at d ≤ a₀), 0 for the other laws (contact at d = V_T ≤ 0).
    pub fn distance_offset(&self) -> f64 {
        match self {
            ContactLaw::Dmt {
                intermolecular_distance,
                ..
            }
            | ContactLaw::Electrostatic {
                intermolecular_distance,
                ..
            } => *intermolecular_distance,
            _ => 0.0,
        }
    }

    /// The law's name: `linear`, `hertz`, `dmt`, `electrostatic`, `jkr`, `capillary`, `sls` or
    /// `impact`.
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }

    /// How far beyond the contact threshold (V_T = 0) the contact persists on retraction: the
    /// contact region is left where V_T rises to this value. |δ_f| = 3q_f⁴ for JKR (the neck,
    /// [`Jkr::release`]), the rupture distance D̃_r for the capillary meniscus, 0 for the other
    /// laws. A law with a positive value is **hysteretic**:
    /// for 0 < V_T < |δ_f| the region depends on the history, and [`crate::CantileverModel`]
    /// takes a start there as in contact when the tip moves away from the sample (leaving
    /// through its neck) and free when it moves towards it (approaching).
    pub fn release_distance(&self, alpha4: f64) -> f64 {
        self.hysteresis(alpha4).map_or(0.0, |h| h.release_distance)
    }

    /// A hysteretic law's cycle ([`ContactLaw::release_distance`] > 0) in the law's units, with
    /// Hertz group `alpha4`: where the contact is left, the largest pull and the energy each tap
    /// loses to the hysteresis; `None` for the other laws.
    pub fn hysteresis(&self, alpha4: f64) -> Option<Hysteresis> {
        match *self {
            ContactLaw::Jkr { adhesion } => {
                let jkr = Jkr::new(alpha4, adhesion);
                Some(Hysteresis {
                    release_distance: -jkr.release(),
                    // the load-controlled pull-off, min F = −(3/2)P̃, on the branch
                    pull_off_force: 1.5 * adhesion,
                    energy_per_tap: jkr.hysteresis(),
                })
            }
            ContactLaw::Capillary {
                capillary,
                meniscus,
                rupture,
            } => Some(Hysteresis {
                release_distance: rupture,
                pull_off_force: capillary,
                energy_per_tap: Meniscus::new(capillary, meniscus, rupture).hysteresis(),
            }),
            _ => None,
        }
    }

    /// The number m of internal states the law adds to the state `z: [f64; 2N + m]` after
    /// (a, ȧ): 1 for SLS (the dashpot's extension u, [`Zener`]), 0 for the other laws.
    pub fn internal_states(&self) -> usize {
        usize::from(matches!(self, ContactLaw::Sls { .. }))
    }

    /// Whether each region is affine in the state (the exact propagator applies).
    pub fn is_affine(&self) -> bool {
        matches!(self, ContactLaw::Linear)
    }

    /// Coefficient of restitution of the impact law.
    pub fn restitution(&self) -> Option<f64> {
        match self {
            ContactLaw::Impact { restitution } => Some(*restitution),
            _ => None,
        }
    }

    /// Check the law's own groups: DMT H̃ ≥ 0 finite, 0 < ã₀ ≤ 1e6; electrostatic those and
    /// 0 ≤ Ẽ ≤ 1e12, 0 < R̃ ≤ 1e6; JKR 0 < P̃ ≤ 1e12; capillary 0 < F̃_cap ≤ 1e12,
    /// 1e-9 ≤ h̃ ≤ 1e6, 1e-9 ≤ D̃_r ≤ 1e6; impact 0 ≤ r ≤ 1.
    ///
    /// # Errors
    /// [`crate::error::ParamError::Law`] naming the group and its allowed range.
    pub fn validate(&self) -> Result<(), crate::error::ParamError> {
        let bad = |name: &'static str, value: f64, range: &'static str| {
            Err(crate::error::ParamError::Law { name, value, range })
        };
        match *self {
            ContactLaw::Linear | ContactLaw::Hertz => Ok(()),
            ContactLaw::Sls { maxwell_stiffness } => {
                // κ = 0 leaves u without dynamics (a neutral direction of every monodromy):
                // that sample is the linear law with α6 = 0
                if !(maxwell_stiffness.is_finite()
                    && maxwell_stiffness > 0.0
                    && maxwell_stiffness <= 1e12)
                {
                    return bad(
                        "maxwell_stiffness (SLS Maxwell arm κ)",
                        maxwell_stiffness,
                        "0 < κ ≤ 1e12 (κ = 0 is the linear law with α6 = 0)",
                    );
                }
                Ok(())
            }
            ContactLaw::Jkr { adhesion } => {
                // P̃ = 0 is Hertz (use `hertz`); the neck's scale P̃/α4 must stay resolvable
                if !(adhesion.is_finite() && adhesion > 0.0 && adhesion <= 1e12) {
                    return bad("adhesion (JKR group P̃ = πWR)", adhesion, "0 < P̃ ≤ 1e12");
                }
                Ok(())
            }
            ContactLaw::Capillary {
                capillary,
                meniscus,
                rupture,
            } => {
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
            ContactLaw::Electrostatic {
                hamaker,
                intermolecular_distance,
                electrostatic,
                tip_radius,
            } => {
                ContactLaw::Dmt {
                    hamaker,
                    intermolecular_distance,
                }
                .validate()?;
                if !(electrostatic.is_finite() && (0.0..=1e12).contains(&electrostatic)) {
                    return bad("electrostatic (group Ẽ)", electrostatic, "0 ≤ Ẽ ≤ 1e12");
                }
                if !(tip_radius.is_finite() && tip_radius > 0.0 && tip_radius <= 1e6) {
                    return bad("tip_radius (R̃ = R/g₀)", tip_radius, "0 < R̃ ≤ 1e6");
                }
                let a0 = intermolecular_distance;
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
            ContactLaw::Dmt {
                hamaker,
                intermolecular_distance,
            } => {
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
                // the adhesion force at contact, H̃/ã₀² (the force law below): beyond 1e12 the
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
            ContactLaw::Impact { restitution } => {
                if !(restitution.is_finite() && (0.0..=1.0).contains(&restitution)) {
                    return bad("restitution (impact r)", restitution, "0 ≤ r ≤ 1");
                }
                Ok(())
            }
        }
    }
}

impl fmt::Display for ContactLaw {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The kind of a law without its groups, parsed from
/// `linear|hertz|dmt|electrostatic|jkr|capillary|sls|impact`.
///
/// One parser for every front end: the name is taken in any case (`"HERTZ"`, `"DMT"` as the
/// literature writes it) on the command line, in a `--config` file, a probe file and from
/// Python ([`FromStr`], which [`Deserialize`] calls).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum LawKind {
    /// [`ContactLaw::Linear`].
    #[default]
    Linear,
    /// [`ContactLaw::Hertz`].
    Hertz,
    /// [`ContactLaw::Dmt`].
    Dmt,
    /// [`ContactLaw::Electrostatic`].
    Electrostatic,
    /// [`ContactLaw::Jkr`].
    Jkr,
    /// [`ContactLaw::Capillary`].
    Capillary,
    /// [`ContactLaw::Sls`].
    Sls,
    /// [`ContactLaw::Impact`].
    Impact,
}

impl FromStr for LawKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "linear" => Ok(LawKind::Linear),
            "hertz" => Ok(LawKind::Hertz),
            "dmt" => Ok(LawKind::Dmt),
            "electrostatic" => Ok(LawKind::Electrostatic),
            "jkr" => Ok(LawKind::Jkr),
            "capillary" => Ok(LawKind::Capillary),
            "sls" | "zener" => Ok(LawKind::Sls),
            "impact" => Ok(LawKind::Impact),
            _ => Err(format!("contact law '{s}': expected {}", LawKind::EXPECTED)),
        }
    }
}

impl<'de> Deserialize<'de> for LawKind {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        s.parse().map_err(serde::de::Error::custom)
    }
}

/// Default DMT groups: H̃ = 1e-5, ã₀ = 0.01, an adhesion force H̃/ã₀² = 0.1, about 5 % of the
/// largest repulsive force of the default tapping motion (α4 δ^{3/2} ≈ 2 at δ ≈ 0.1), as for a
/// silicon tip on a polymer (F_ad ≈ 4 nN against k A₀ ≈ 400 nN).
pub const DMT_DEFAULT_HAMAKER: f64 = 1e-5;
/// Default DMT intermolecular distance ã₀.
pub const DMT_DEFAULT_A0: f64 = 0.01;
/// Default electrostatic group Ẽ: with R̃ = 1 and ã₀ = 0.01 the electrostatic force at contact
/// is ẼR̃²/(ã₀(ã₀ + R̃)) ≈ 0.099, about DMT's default adhesion (a few volts on a 10 nm tip give
/// nanonewtons, as van der Waals does), and it decays as 1/d, not 1/d².
pub const ELECTROSTATIC_DEFAULT: f64 = 1e-3;
/// Default tip radius R̃ = R/g₀ of the electrostatic law.
pub const ELECTROSTATIC_DEFAULT_RADIUS: f64 = 1.0;
/// Default JKR adhesion group P̃ = πWR = 0.05: the work of adhesion of DMT's defaults (whose
/// pull-off 2πRW is H̃/ã₀² = 0.1), so the JKR pull-off (3/2)P̃ = 0.075 is ¾ of DMT's, as the
/// two theories give for one W.
pub const JKR_DEFAULT_ADHESION: f64 = 0.05;
/// Default capillary force at contact F̃_cap = 0.1: DMT's default adhesion (a water meniscus
/// on a 10 nm tip, 4πRγcosθ ≈ 9 nN, is of the order of van der Waals' pull-off).
pub const CAPILLARY_DEFAULT_FORCE: f64 = 0.1;
/// Default immersion at contact h̃ = 0.01 (DMT's ã₀: a meniscus of the nanometre scale).
pub const CAPILLARY_DEFAULT_MENISCUS: f64 = 0.01;
/// Default rupture distance D̃_r = 0.05: a few nanometres under the default tapping amplitude,
/// as Zitzler et al. (2002) find for the menisci of humid air.
pub const CAPILLARY_DEFAULT_RUPTURE: f64 = 0.05;
/// Default Maxwell arm κ = 20 of the SLS law: the sample twice as stiff at the onset of a tap
/// (α4 + κ = 40 with the default α4 = 20) as at rest, with a relaxation time α6/κ = 0.01 (the
/// default α6 = 0.2) between the contact's time scale 1/√(α4 + κ) and the drive period, so the
/// Maxwell arm both stiffens and damps the tap.
pub const SLS_DEFAULT_MAXWELL: f64 = 20.0;
/// Default coefficient of restitution of the impact law.
pub const IMPACT_DEFAULT_RESTITUTION: f64 = 0.8;

impl LawKind {
    /// Build the law, filling groups that are not given with the defaults above.
    pub fn with_groups(self, groups: LawGroups) -> ContactLaw {
        let LawGroups {
            hamaker,
            intermolecular_distance,
            restitution,
            electrostatic,
            tip_radius,
            adhesion,
            capillary,
            meniscus,
            rupture,
            maxwell_stiffness,
        } = groups;
        match self {
            LawKind::Linear => ContactLaw::Linear,
            LawKind::Hertz => ContactLaw::Hertz,
            LawKind::Dmt => ContactLaw::Dmt {
                hamaker: hamaker.unwrap_or(DMT_DEFAULT_HAMAKER),
                intermolecular_distance: intermolecular_distance.unwrap_or(DMT_DEFAULT_A0),
            },
            LawKind::Electrostatic => ContactLaw::Electrostatic {
                hamaker: hamaker.unwrap_or(DMT_DEFAULT_HAMAKER),
                intermolecular_distance: intermolecular_distance.unwrap_or(DMT_DEFAULT_A0),
                electrostatic: electrostatic.unwrap_or(ELECTROSTATIC_DEFAULT),
                tip_radius: tip_radius.unwrap_or(ELECTROSTATIC_DEFAULT_RADIUS),
            },
            LawKind::Jkr => ContactLaw::Jkr {
                adhesion: adhesion.unwrap_or(JKR_DEFAULT_ADHESION),
            },
            LawKind::Capillary => ContactLaw::Capillary {
                capillary: capillary.unwrap_or(CAPILLARY_DEFAULT_FORCE),
                meniscus: meniscus.unwrap_or(CAPILLARY_DEFAULT_MENISCUS),
                rupture: rupture.unwrap_or(CAPILLARY_DEFAULT_RUPTURE),
            },
            LawKind::Sls => ContactLaw::Sls {
                maxwell_stiffness: maxwell_stiffness.unwrap_or(SLS_DEFAULT_MAXWELL),
            },
            LawKind::Impact => ContactLaw::Impact {
                restitution: restitution.unwrap_or(IMPACT_DEFAULT_RESTITUTION),
            },
        }
    }
}

/// The law groups a front end may give (each `None` when not given): the one argument of
/// [`LawKind::with_groups`] and [`ContactLaw::from_parts`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct LawGroups {
    /// DMT and electrostatic: H̃.
    pub hamaker: Option<f64>,
    /// DMT and electrostatic: ã₀.
    pub intermolecular_distance: Option<f64>,
    /// Impact: r.
    pub restitution: Option<f64>,
    /// Electrostatic: Ẽ.
    pub electrostatic: Option<f64>,
    /// Electrostatic: R̃.
    pub tip_radius: Option<f64>,
    /// JKR: P̃.
    pub adhesion: Option<f64>,
    /// Capillary: F̃_cap.
    pub capillary: Option<f64>,
    /// Capillary: h̃.
    pub meniscus: Option<f64>,
    /// Capillary: D̃_r.
    pub rupture: Option<f64>,
    /// SLS: κ.
    pub maxwell_stiffness: Option<f64>,
}

impl LawGroups {
    /// The groups of `law` (those it has), e.g. to keep them when another group is changed.
    pub fn of(law: ContactLaw) -> LawGroups {
        match law {
            ContactLaw::Dmt {
                hamaker,
                intermolecular_distance,
            } => LawGroups {
                hamaker: Some(hamaker),
                intermolecular_distance: Some(intermolecular_distance),
                ..LawGroups::default()
            },
            ContactLaw::Electrostatic {
                hamaker,
                intermolecular_distance,
                electrostatic,
                tip_radius,
            } => LawGroups {
                hamaker: Some(hamaker),
                intermolecular_distance: Some(intermolecular_distance),
                electrostatic: Some(electrostatic),
                tip_radius: Some(tip_radius),
                ..LawGroups::default()
            },
            ContactLaw::Jkr { adhesion } => LawGroups {
                adhesion: Some(adhesion),
                ..LawGroups::default()
            },
            ContactLaw::Capillary {
                capillary,
                meniscus,
                rupture,
            } => LawGroups {
                capillary: Some(capillary),
                meniscus: Some(meniscus),
                rupture: Some(rupture),
                ..LawGroups::default()
            },
            ContactLaw::Impact { restitution } => LawGroups {
                restitution: Some(restitution),
                ..LawGroups::default()
            },
            ContactLaw::Sls { maxwell_stiffness } => LawGroups {
                maxwell_stiffness: Some(maxwell_stiffness),
                ..LawGroups::default()
            },
            ContactLaw::Linear | ContactLaw::Hertz => LawGroups::default(),
        }
    }

    /// Each group of `self`, or `other`'s where `self` has none.
    pub fn or(self, other: LawGroups) -> LawGroups {
        LawGroups {
            hamaker: self.hamaker.or(other.hamaker),
            intermolecular_distance: self
                .intermolecular_distance
                .or(other.intermolecular_distance),
            restitution: self.restitution.or(other.restitution),
            electrostatic: self.electrostatic.or(other.electrostatic),
            tip_radius: self.tip_radius.or(other.tip_radius),
            adhesion: self.adhesion.or(other.adhesion),
            capillary: self.capillary.or(other.capillary),
            meniscus: self.meniscus.or(other.meniscus),
            rupture: self.rupture.or(other.rupture),
            maxwell_stiffness: self.maxwell_stiffness.or(other.maxwell_stiffness),
        }
    }
}

impl ContactLaw {
    /// The law a front end asks for: its kind (or `base`'s when not given) and the groups it
    /// sets, the others kept from `base` when it is of that kind, else the defaults. One place
    /// for the CLI flags, the TOML keys and the Python keywords.
    ///
    /// # Errors
    /// [`crate::error::ParamError::Group`] for a group of another law (e.g. `restitution` with
    /// `contact_law = hertz`); the groups' ranges are checked by [`ContactLaw::validate`].
    pub fn from_parts(
        kind: Option<LawKind>,
        groups: LawGroups,
        base: ContactLaw,
    ) -> Result<ContactLaw, crate::error::ParamError> {
        let kind = kind.unwrap_or(base.kind());
        const DMT: &[LawKind] = &[LawKind::Dmt, LawKind::Electrostatic];
        const ES: &[LawKind] = &[LawKind::Electrostatic];
        const CAP: &[LawKind] = &[LawKind::Capillary];
        for (given, group, owners, owner) in [
            (
                groups.restitution.is_some(),
                "restitution",
                &[LawKind::Impact][..],
                "impact",
            ),
            (
                groups.hamaker.is_some(),
                "hamaker",
                DMT,
                "dmt or electrostatic",
            ),
            (
                groups.intermolecular_distance.is_some(),
                "intermolecular_distance",
                DMT,
                "dmt or electrostatic",
            ),
            (
                groups.electrostatic.is_some(),
                "electrostatic",
                ES,
                "electrostatic",
            ),
            (
                groups.tip_radius.is_some(),
                "tip_radius",
                ES,
                "electrostatic",
            ),
            (
                groups.adhesion.is_some(),
                "adhesion",
                &[LawKind::Jkr][..],
                "jkr",
            ),
            (groups.capillary.is_some(), "capillary", CAP, "capillary"),
            (groups.meniscus.is_some(), "meniscus", CAP, "capillary"),
            (groups.rupture.is_some(), "rupture", CAP, "capillary"),
            (
                groups.maxwell_stiffness.is_some(),
                "maxwell_stiffness",
                &[LawKind::Sls][..],
                "sls",
            ),
        ] {
            if given && !owners.contains(&kind) {
                return Err(crate::error::ParamError::Group {
                    group,
                    owner,
                    law: kind.name(),
                });
            }
        }
        // groups not given keep base's when base has them
        Ok(kind.with_groups(groups.or(LawGroups::of(base))))
    }

    /// The law's kind without its groups.
    pub fn kind(&self) -> LawKind {
        match self {
            ContactLaw::Linear => LawKind::Linear,
            ContactLaw::Hertz => LawKind::Hertz,
            ContactLaw::Dmt { .. } => LawKind::Dmt,
            ContactLaw::Electrostatic { .. } => LawKind::Electrostatic,
            ContactLaw::Jkr { .. } => LawKind::Jkr,
            ContactLaw::Capillary { .. } => LawKind::Capillary,
            ContactLaw::Sls { .. } => LawKind::Sls,
            ContactLaw::Impact { .. } => LawKind::Impact,
        }
    }
}

impl LawKind {
    /// The names a front end accepts, for messages.
    pub const EXPECTED: &'static str =
        "linear, hertz, dmt, electrostatic, jkr, capillary, sls or impact";

    /// The kind's name: `linear`, `hertz`, `dmt`, `electrostatic`, `jkr`, `capillary`, `sls` or
    /// `impact`.
    pub fn name(self) -> &'static str {
        match self {
            LawKind::Linear => "linear",
            LawKind::Hertz => "hertz",
            LawKind::Dmt => "dmt",
            LawKind::Electrostatic => "electrostatic",
            LawKind::Jkr => "jkr",
            LawKind::Capillary => "capillary",
            LawKind::Sls => "sls",
            LawKind::Impact => "impact",
        }
    }
}

/// F_c and its partial derivatives at (δ, δ̇).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ForceEval {
    /// F_c (repulsive positive).
    pub force: f64,
    /// ∂F_c/∂δ.
    pub d_delta: f64,
    /// ∂F_c/∂δ̇.
    pub d_rate: f64,
}

/// A tip–sample force law: the force in and out of contact with its partial derivatives, the
/// conservative potential (for the energy) and the dissipative part (for the dissipation rate).
pub trait TipSampleLaw {
    /// F_c(δ, δ̇) with partials; `contact` is the region (δ ≥ 0 in contact for a smooth law).
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval;
    /// Potential U(δ) of the conservative part, with −dU/dV_T = dU/dδ = F_cons (0 at δ = 0 for
    /// the linear and Hertz laws; continuous across δ = 0).
    fn potential(&self, contact: bool, delta: f64) -> f64;
    /// Dissipative part F_d of F_c: the dissipation rate is F_d δ̇ ≥ 0.
    fn dissipative(&self, contact: bool, delta: f64, rate: f64) -> f64;
    /// Whether the law acts outside contact (δ < 0).
    fn acts_outside(&self) -> bool;
}

/// A law with its stiffness α4 and damping α6: what the model evaluates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TipSample {
    /// The law.
    pub law: ContactLaw,
    /// α4: stiffness of the linear law, Hertz group of the Hertz and DMT laws.
    pub stiffness: f64,
    /// α6: damper of the linear and Hertz laws, Kelvin–Voigt group of DMT.
    pub damping: f64,
}

impl TipSampleLaw for TipSample {
    fn force(&self, contact: bool, delta: f64, rate: f64) -> ForceEval {
        let (k, c) = (self.stiffness, self.damping);
        match self.law {
            ContactLaw::Linear if contact => ForceEval {
                force: k * delta + c * rate,
                d_delta: k,
                d_rate: c,
            },
            // the relaxed (equilibrium) force: the Maxwell arm's force depends on the state u,
            // which the model evaluates ([`Zener`]); this is the quasi-static law
            ContactLaw::Sls { .. } if contact => ForceEval {
                force: k * delta,
                d_delta: k,
                d_rate: 0.0,
            },
            ContactLaw::Hertz if contact => {
                let d = delta.max(0.0);
                let s = d.sqrt();
                ForceEval {
                    force: k * d * s + c * rate,
                    d_delta: 1.5 * k * s,
                    d_rate: c,
                }
            }
            ContactLaw::Jkr { adhesion } if contact => {
                let jkr = Jkr::new(k, adhesion);
                let q = jkr.radius_variable(delta);
                let (f, df_dq) = jkr.elastic(q);
                let q2 = q * q;
                // dq/dδ = 1/(4q³ − c), large but finite at the break q_b ([`JKR_BREAK_CUT`]);
                // beyond it, where an integrator's stage may look across the guard, q stays at
                // q_b and the force at its break value
                let dq = if delta > jkr.release() {
                    1.0 / (4.0 * q2 * q - jkr.c)
                } else {
                    0.0
                };
                ForceEval {
                    force: f + c * q2 * rate,
                    d_delta: (df_dq + 2.0 * c * q * rate) * dq,
                    d_rate: c * q2,
                }
            }
            ContactLaw::Capillary {
                capillary,
                meniscus,
                rupture,
            } if contact => {
                // the meniscus's pull at D = −δ (∂/∂δ = −∂/∂D), with Hertz and Kelvin–Voigt
                // while indenting
                let (adh, d_adh) = Meniscus::new(capillary, meniscus, rupture).force(-delta);
                let d = delta.max(0.0);
                let s = d.sqrt();
                let visc_d = if s > 0.0 { 0.5 * c * rate / s } else { 0.0 };
                ForceEval {
                    force: adh + k * d * s + c * s * rate,
                    d_delta: -d_adh + 1.5 * k * s + visc_d,
                    d_rate: c * s,
                }
            }
            ContactLaw::Dmt { .. } | ContactLaw::Electrostatic { .. } => {
                let a0 = self.law.distance_offset();
                if contact {
                    let d = delta.max(0.0);
                    let s = d.sqrt();
                    // ∂(√δ δ̇)/∂δ = δ̇/(2√δ): integrable singularity at δ = 0, 0 there
                    let visc_d = if s > 0.0 { 0.5 * c * rate / s } else { 0.0 };
                    ForceEval {
                        force: self.long_range(a0)[0] + k * d * s + c * s * rate,
                        d_delta: 1.5 * k * s + visc_d,
                        d_rate: c * s,
                    }
                } else {
                    // d = a₀ + V_T = a₀ − δ > a₀; ∂/∂δ = −∂/∂d
                    let [force, d_d, _] = self.long_range(a0 - delta);
                    ForceEval {
                        force,
                        d_delta: -d_d,
                        d_rate: 0.0,
                    }
                }
            }
            _ => ForceEval::default(),
        }
    }

    fn potential(&self, contact: bool, delta: f64) -> f64 {
        let k = self.stiffness;
        match self.law {
            ContactLaw::Linear | ContactLaw::Sls { .. } if contact => 0.5 * k * delta * delta,
            ContactLaw::Hertz if contact => 0.4 * k * delta.max(0.0).powf(2.5),
            ContactLaw::Jkr { adhesion } if contact => {
                let jkr = Jkr::new(k, adhesion);
                jkr.potential(jkr.radius_variable(delta))
            }
            ContactLaw::Capillary {
                capillary,
                meniscus,
                rupture,
            } if contact => {
                // U = ∫_{−D̃_r}^{δ} F dδ: 0 where the meniscus ruptures
                Meniscus::new(capillary, meniscus, rupture).potential(-delta)
                    + 0.4 * k * delta.max(0.0).powf(2.5)
            }
            ContactLaw::Dmt { .. } | ContactLaw::Electrostatic { .. } => {
                let a0 = self.law.distance_offset();
                if contact {
                    let [f0, _, u0] = self.long_range(a0);
                    u0 + f0 * delta + 0.4 * k * delta.max(0.0).powf(2.5)
                } else {
                    self.long_range(a0 - delta)[2]
                }
            }
            _ => 0.0,
        }
    }

    fn dissipative(&self, contact: bool, delta: f64, rate: f64) -> f64 {
        if !contact {
            return 0.0;
        }
        match self.law {
            ContactLaw::Linear | ContactLaw::Hertz => self.damping * rate,
            ContactLaw::Dmt { .. }
            | ContactLaw::Electrostatic { .. }
            | ContactLaw::Capillary { .. } => self.damping * delta.max(0.0).sqrt() * rate,
            ContactLaw::Jkr { adhesion } => {
                let q = Jkr::new(self.stiffness, adhesion).radius_variable(delta);
                self.damping * q * q * rate
            }
            ContactLaw::Impact { .. } | ContactLaw::Sls { .. } => 0.0,
        }
    }

    fn acts_outside(&self) -> bool {
        matches!(
            self.law,
            ContactLaw::Dmt { .. } | ContactLaw::Electrostatic { .. }
        )
    }
}

/// A hysteretic law's cycle ([`ContactLaw::hysteresis`]), in the law's units (lengths in g₀,
/// forces in F̃, energies in F̃·g₀).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Hysteresis {
    /// V_T where the contact is left on retraction: JKR's |δ_b|, the meniscus's D̃_r.
    pub release_distance: f64,
    /// The largest pull of the contact (a positive magnitude): JKR's load-controlled pull-off
    /// (3/2)P̃ = (3/2)πWR, the meniscus's F̃_cap = 4πRγcosθ.
    pub pull_off_force: f64,
    /// The energy each tap loses to the hysteresis (formed, then left): JKR's E_hys, the
    /// meniscus's E_cap.
    pub energy_per_tap: f64,
}

/// The standard linear solid with surface memory ([`ContactLaw::Sls`], module docs): the
/// relaxed spring α4, the Maxwell arm's spring κ and dashpot α6, in the law's units. The state u
/// is the dashpot's extension (g₀), δ = −V_T the tip's indentation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Zener {
    /// α4: the relaxed spring.
    pub relaxed: f64,
    /// κ: the Maxwell arm's spring.
    pub maxwell: f64,
    /// α6: the Maxwell arm's dashpot.
    pub dashpot: f64,
}

impl Zener {
    /// The SLS of the model's α4, α6 and the law's κ.
    pub fn new(alpha4: f64, maxwell: f64, alpha6: f64) -> Zener {
        Zener {
            relaxed: alpha4,
            maxwell,
            dashpot: alpha6,
        }
    }
    /// κ/(α4 + κ): the free surface's depression per unit u (0 for κ = 0, 1 for α4 = 0).
    pub fn surface_gain(&self) -> f64 {
        let k = self.relaxed + self.maxwell;
        if k > 0.0 {
            self.maxwell / k
        } else {
            0.0
        }
    }
    /// s(u) = κu/(α4 + κ): where the free surface sits (a depression, g₀), balanced between
    /// its springs. The switching function is V_T + s(u) in both regions.
    pub fn surface(&self, u: f64) -> f64 {
        self.surface_gain() * u
    }
    /// The surface's depression δ_s: the indentation δ in contact, s(u) free.
    pub fn depression(&self, contact: bool, delta: f64, u: f64) -> f64 {
        if contact {
            delta
        } else {
            self.surface(u)
        }
    }
    /// κ/α6: the Maxwell arm's relaxation rate 1/τ_r (0 for κ = 0).
    pub fn relaxation_rate(&self) -> f64 {
        if self.maxwell == 0.0 {
            0.0
        } else {
            self.maxwell / self.dashpot
        }
    }
    /// F_c = α4 δ + κ(δ − u) in contact (repulsive positive), 0 free.
    pub fn force(&self, contact: bool, delta: f64, u: f64) -> f64 {
        if contact {
            self.relaxed * delta + self.maxwell * (delta - u)
        } else {
            0.0
        }
    }
    /// u̇ = (κ/α6)(δ_s − u): the dashpot's rate, in contact and free.
    pub fn rate(&self, contact: bool, delta: f64, u: f64) -> f64 {
        self.relaxation_rate() * (self.depression(contact, delta, u) - u)
    }
    /// U = ½α4 δ_s² + ½κ(δ_s − u)²: the energy stored in the sample's springs.
    pub fn potential(&self, contact: bool, delta: f64, u: f64) -> f64 {
        let ds = self.depression(contact, delta, u);
        0.5 * self.relaxed * ds * ds + 0.5 * self.maxwell * (ds - u) * (ds - u)
    }
    /// α6 u̇²: the dashpot's dissipation rate (≥ 0).
    pub fn dissipation(&self, contact: bool, delta: f64, u: f64) -> f64 {
        let r = self.rate(contact, delta, u);
        self.dashpot * r * r
    }
    /// The energy the Maxwell arm dissipates per cycle of a prescribed harmonic indentation
    /// δ = δ̄ + δ₀ sin ωτ held in contact, at the periodic steady state:
    /// πκ ωτ_r δ₀²/(1 + ω²τ_r²), τ_r = α6/κ (the loss modulus of a Maxwell element, e.g.
    /// Lakes, *Viscoelastic Materials*, CUP 2009, §2.7; the relaxed spring stores only).
    pub fn cycle_dissipation(&self, omega: f64, amplitude: f64) -> f64 {
        let rate = self.relaxation_rate();
        if rate == 0.0 {
            return 0.0;
        }
        let wt = omega / rate;
        std::f64::consts::PI * self.maxwell * wt * amplitude * amplitude / (1.0 + wt * wt)
    }
}

/// The JKR contact in the law's units (module docs): Hertz group α4, adhesion P̃ = πWR, and
/// the contact-radius variable q = h^{1/4} = (a²/R)^{1/4} on the stable branch q ≥ q_f.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jkr {
    /// α4.
    pub alpha4: f64,
    /// P̃.
    pub adhesion: f64,
    /// c = √(8P̃/(3α4)): δ = q⁴ − c q.
    pub c: f64,
    /// b = √(6P̃α4): F = α4 q⁶ − b q³.
    pub b: f64,
    /// q_f = (c/4)^{1/3}: the end of the branch (dδ/dq = 0).
    pub q_end: f64,
    /// q_b = (1 + [`JKR_BREAK_CUT`]) q_f, where the contact breaks, just before the end of the
    /// branch.
    pub q_break: f64,
}

/// The JKR branch is cut just before its end: the contact breaks at q_b = (1 + 1e-3) q_f,
/// δ_b = δ_f (1 − 2.0e-6). At the end dF/dδ ∝ 1/√(δ − δ_f) is unbounded, and the variational
/// equations (orbits, multipliers, shooting) stall on it (steps of 1e-17 measured); at the cut
/// it is finite (1/(4q_b³ − c) = 1/(3.0e-3 c)). The break force is (5/6)P̃(1 + 2.4e-3) and
/// E_hys is 1.2e-6 lower, relatively ([`Jkr::hysteresis`] is that of the cut branch,
/// [`Jkr::hysteresis_uncut`] the closed form).
pub const JKR_BREAK_CUT: f64 = 1e-3;

impl Jkr {
    /// The contact of Hertz group `alpha4` > 0 and adhesion `adhesion` = P̃ > 0.
    pub fn new(alpha4: f64, adhesion: f64) -> Jkr {
        let c = (8.0 * adhesion / (3.0 * alpha4)).sqrt();
        let q_end = (0.25 * c).cbrt();
        Jkr {
            alpha4,
            adhesion,
            c,
            b: (6.0 * adhesion * alpha4).sqrt(),
            q_end,
            q_break: (1.0 + JKR_BREAK_CUT) * q_end,
        }
    }

    /// δ(q) = q⁴ − c q.
    pub fn indentation(&self, q: f64) -> f64 {
        let q2 = q * q;
        q2 * q2 - self.c * q
    }

    /// The indentation where the contact breaks, δ_b = δ(q_b) < 0 ([`JKR_BREAK_CUT`]), with
    /// δ_f = −3q_f⁴ the end of the branch (the fixed-grips pull-off, −(3/4)(π²W²R/E*²)^{1/3}
    /// in SI).
    pub fn release(&self) -> f64 {
        self.indentation(self.q_break)
    }

    /// q = c^{1/3} where the contact forms on approach (δ = 0).
    pub fn q_contact(&self) -> f64 {
        self.c.cbrt()
    }

    /// The elastic–adhesive force F(q) = α4 q⁶ − b q³ and dF/dq.
    pub fn elastic(&self, q: f64) -> (f64, f64) {
        let q3 = q * q * q;
        (
            self.alpha4 * q3 * q3 - self.b * q3,
            6.0 * self.alpha4 * q3 * q * q - 3.0 * self.b * q * q,
        )
    }

    /// U(q) = ∫_{δ_b}^{δ(q)} F dδ = G(q) − G(q_b), with
    /// G(q) = (2/5)α4 q¹⁰ − ((α4c + 4b)/7) q⁷ + (bc/4) q⁴ the integral of
    /// F(q) δ′(q) = (α4q⁶ − bq³)(4q³ − c): 0 at the break, so the potential is continuous there
    /// and drops by E_hys = −U(q_contact) where the contact forms.
    pub fn potential(&self, q: f64) -> f64 {
        let g = |q: f64| {
            let q2 = q * q;
            let q4 = q2 * q2;
            let q7 = q4 * q2 * q;
            0.4 * self.alpha4 * q7 * q2 * q - (self.alpha4 * self.c + 4.0 * self.b) / 7.0 * q7
                + 0.25 * self.b * self.c * q4
        };
        g(q) - g(self.q_break)
    }

    /// The energy lost per contact cycle (formed at δ = 0, broken at δ_b) by the
    /// elastic–adhesive force alone: E_hys = −U(q_contact).
    pub fn hysteresis(&self) -> f64 {
        -self.potential(self.q_contact())
    }

    /// The closed form of the uncut branch (broken at δ_f): E_hys = (3/5 + 4^{−1/3}/10) P̃
    /// c^{4/3} (module docs), 1.2e-6 above [`Jkr::hysteresis`] relatively.
    pub fn hysteresis_uncut(&self) -> f64 {
        (0.6 + 0.1 / 4f64.cbrt()) * self.adhesion * self.c.powf(4.0 / 3.0)
    }

    /// q(δ) on the stable branch: the root q ≥ q_f of q⁴ − c q = δ (q_b for δ ≤ δ_b: beyond
    /// the break, where an integrator's stage may look across the guard). Newton's
    /// iteration on the convex, increasing δ(q) from a start right of the root converges
    /// monotonically; the start is the smaller of two upper bounds, max((2δ)^{1/4}, (2c)^{1/3})
    /// (where q⁴/2 bounds both δ and c q) and q_f + √((δ − δ_f)/(6q_f²)) (δ(q) − δ_f ≥
    /// 6q_f²(q − q_f)²), the second exact to leading order at the break, where δ′(q_f) = 0.
    pub fn radius_variable(&self, delta: f64) -> f64 {
        if delta.is_nan() || delta <= self.indentation(self.q_break) {
            return self.q_break;
        }
        let qf = self.q_end;
        let above = delta - self.indentation(qf);
        // (2c)^{1/3} = 2 q_f, since q_f³ = c/4
        let far = (2.0 * delta.max(0.0)).sqrt().sqrt().max(2.0 * qf);
        let near = qf + (above / (6.0 * qf * qf)).sqrt();
        let mut q = far.min(near).max(qf);
        for _ in 0..100 {
            let q2 = q * q;
            let f = q2 * q2 - self.c * q - delta;
            let d = 4.0 * q2 * q - self.c;
            if !(f > 0.0 && d > 0.0) {
                break;
            }
            let next = q - f / d;
            if next.is_nan() || next >= q || next <= qf {
                q = next.max(qf);
                break;
            }
            q = next;
        }
        q
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
    pub fn new(capillary: f64, meniscus: f64, rupture: f64) -> Meniscus {
        Meniscus {
            capillary,
            meniscus,
            rupture,
        }
    }

    /// The pull and dF/dD: F = −F̃_cap(1 − D/√(D² + h̃²)), dF/dD = F̃_cap h̃²/(D² + h̃²)^{3/2}
    /// for D > 0; −F̃_cap and 0 in contact (D ≤ 0).
    pub fn force(&self, d: f64) -> (f64, f64) {
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
    pub fn potential(&self, d: f64) -> f64 {
        let g = |d: f64| d - d.hypot(self.meniscus);
        -self.capillary * (g(self.rupture) - g(d.max(0.0))) + self.capillary * d.min(0.0)
    }

    /// The energy the meniscus takes per tap (formed at contact, ruptured at D̃_r):
    /// E_cap = −U(0) = ∫_0^{D̃_r} |F| dD = F̃_cap(D̃_r + h̃ − √(D̃_r² + h̃²)) (module docs).
    pub fn hysteresis(&self) -> f64 {
        self.capillary * (self.rupture + self.meniscus - self.rupture.hypot(self.meniscus))
    }
}

impl TipSample {
    /// The long-range attraction at tip–sample distance d > 0: [F(d), dF/dd, U(d)] with
    /// F = −dU/dd — DMT's van der Waals −H̃/d² (U = −H̃/d), and for the electrostatic law also
    /// the biased sphere over the plane −ẼR̃²/(d(d + R̃)) (Hudlet et al. 1998;
    /// U = −ẼR̃ ln((d + R̃)/d)); zeros for the other laws.
    pub fn long_range(&self, d: f64) -> [f64; 3] {
        let (h, es) = match self.law {
            ContactLaw::Dmt { hamaker, .. } => (hamaker, None),
            ContactLaw::Electrostatic {
                hamaker,
                electrostatic,
                tip_radius,
                ..
            } => (hamaker, Some((electrostatic, tip_radius))),
            _ => return [0.0; 3],
        };
        let mut out = [-h / (d * d), 2.0 * h / (d * d * d), -h / d];
        if let Some((e, r)) = es {
            let dr = d + r;
            out[0] -= e * r * r / (d * dr);
            out[1] += e * r * r * (2.0 * d + r) / (d * d * dr * dr);
            out[2] -= e * r * (dr / d).ln();
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn laws() -> Vec<TipSample> {
        [
            ContactLaw::Linear,
            ContactLaw::Hertz,
            ContactLaw::Dmt {
                hamaker: 0.3,
                intermolecular_distance: 0.02,
            },
            ContactLaw::Electrostatic {
                hamaker: 0.3,
                intermolecular_distance: 0.02,
                electrostatic: 0.05,
                tip_radius: 0.7,
            },
            ContactLaw::Jkr { adhesion: 0.05 },
            ContactLaw::Capillary {
                capillary: 0.1,
                meniscus: 0.02,
                rupture: 0.06,
            },
        ]
        .into_iter()
        .map(|law| TipSample {
            law,
            stiffness: 20.0,
            damping: 0.2,
        })
        .collect()
    }

    /// The partial derivatives are those of the force (central differences), and the
    /// conservative part is −dU/dV_T = dU/dδ (definition of the potential).
    #[test]
    fn partials_and_potential_are_consistent() {
        for ts in laws() {
            // and a hysteretic law's contact region beyond V_T = 0: JKR's neck (δ_b = −0.0167
            // here), the capillary meniscus (D̃_r = 0.06)
            let band: &[(bool, f64, f64)] = match ts.law {
                ContactLaw::Jkr { .. } => &[(true, -0.01, 0.3), (true, -0.002, -0.5)],
                // and next to the kink at D = 0, on both sides
                ContactLaw::Capillary { .. } => &[
                    (true, -0.03, 0.3),
                    (true, -0.055, -0.5),
                    (true, -1e-5, 0.0),
                    (true, 1.2e-5, 0.0),
                ],
                _ => &[],
            };
            for &(contact, delta, rate) in [
                (true, 0.07, 0.3),
                (true, 0.5, -1.2),
                (false, -0.05, 0.4),
                (false, -0.8, -2.0),
            ]
            .iter()
            .chain(band)
            {
                let f = ts.force(contact, delta, rate);
                // a step that stays on the kink's side where δ is that small
                let h = 1e-6f64.min(1e-3 * delta.abs());
                let fd = (ts.force(contact, delta + h, rate).force
                    - ts.force(contact, delta - h, rate).force)
                    / (2.0 * h);
                let fr = (ts.force(contact, delta, rate + h).force
                    - ts.force(contact, delta, rate - h).force)
                    / (2.0 * h);
                assert!((f.d_delta - fd).abs() < 1e-6 * (1.0 + fd.abs()), "{ts:?}");
                assert!((f.d_rate - fr).abs() < 1e-6 * (1.0 + fr.abs()), "{ts:?}");
                let du = (ts.potential(contact, delta + h) - ts.potential(contact, delta - h))
                    / (2.0 * h);
                let cons = f.force - ts.dissipative(contact, delta, rate);
                assert!((du - cons).abs() < 1e-6 * (1.0 + du.abs()), "{ts:?}");
            }
        }
    }

    /// DMT is continuous at the contact threshold (force and potential), the DMT adhesion
    /// force is H̃/ã₀² there; the electrostatic law too, with the sphere–plane force
    /// ẼR̃²/(ã₀(ã₀ + R̃)) added.
    #[test]
    fn dmt_is_continuous_at_contact() {
        for (ts, adhesion) in [
            (laws()[2], 0.3 / (0.02 * 0.02)),
            (
                laws()[3],
                0.3 / (0.02 * 0.02) + 0.05 * 0.7 * 0.7 / (0.02 * 0.72),
            ),
        ] {
            let (inside, outside) = (ts.force(true, 0.0, 0.0), ts.force(false, 0.0, 0.0));
            assert!((inside.force - outside.force).abs() < 1e-12);
            assert!((inside.force + adhesion).abs() < 1e-9 * adhesion);
            assert!((ts.potential(true, 0.0) - ts.potential(false, 0.0)).abs() < 1e-12);
        }
    }

    /// The electrostatic force is Hudlet's sphere term: −πε₀V²R/d for d ≪ R (the parallel
    /// plate limit of the sphere, Hudlet et al. 1998) and −πε₀V²R²/d² for d ≫ R (a point
    /// charge's image force), in the law's units Ẽ = πε₀V², R̃.
    #[test]
    fn electrostatic_force_has_its_limits() {
        let ts = TipSample {
            law: ContactLaw::Electrostatic {
                hamaker: 0.0,
                intermolecular_distance: 1e-3,
                electrostatic: 2.0,
                tip_radius: 5.0,
            },
            stiffness: 0.0,
            damping: 0.0,
        };
        let near = ts.long_range(1e-4)[0];
        assert!((near / (-2.0 * 5.0 / 1e-4) - 1.0).abs() < 1e-4, "{near}");
        let far = ts.long_range(1e5)[0];
        assert!((far / (-2.0 * 25.0 / 1e10) - 1.0).abs() < 1e-4, "{far}");
    }
}
