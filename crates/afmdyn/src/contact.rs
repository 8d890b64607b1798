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

    /// The law's name: `linear`, `hertz`, `dmt`, `electrostatic` or `impact`.
    pub fn name(&self) -> &'static str {
        match self {
            ContactLaw::Linear => "linear",
            ContactLaw::Hertz => "hertz",
            ContactLaw::Dmt { .. } => "dmt",
            ContactLaw::Electrostatic { .. } => "electrostatic",
            ContactLaw::Impact { .. } => "impact",
        }
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
    /// 0 ≤ Ẽ ≤ 1e12, 0 < R̃ ≤ 1e6; impact 0 ≤ r ≤ 1.
    ///
    /// # Errors
    /// [`crate::ParamError::Law`] naming the group and its allowed range.
    pub fn validate(&self) -> Result<(), crate::ParamError> {
        let bad = |name: &'static str, value: f64, range: &'static str| {
            Err(crate::ParamError::Law { name, value, range })
        };
        match *self {
            ContactLaw::Linear | ContactLaw::Hertz => Ok(()),
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

/// The kind of a law without its groups, parsed from `linear|hertz|dmt|electrostatic|impact`.
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
            "impact" => Ok(LawKind::Impact),
            _ => Err(format!(
                "contact law '{s}': expected linear, hertz, dmt, electrostatic or impact"
            )),
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
/// Default coefficient of restitution of the impact law.
pub const IMPACT_DEFAULT_RESTITUTION: f64 = 0.8;

impl LawKind {
    /// Build the law, filling groups that are not given with the defaults above.
    pub fn with_groups(
        self,
        hamaker: Option<f64>,
        intermolecular_distance: Option<f64>,
        restitution: Option<f64>,
        electrostatic: Option<f64>,
        tip_radius: Option<f64>,
    ) -> ContactLaw {
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
            LawKind::Impact => ContactLaw::Impact {
                restitution: restitution.unwrap_or(IMPACT_DEFAULT_RESTITUTION),
            },
        }
    }
}

impl ContactLaw {
    /// The law a front end asks for: its kind (or `base`'s when not given) and the groups it
    /// sets, the others kept from `base` when it is of that kind, else the defaults. One place
    /// for the CLI flags, the TOML keys and the Python keywords.
    ///
    /// # Errors
    /// [`crate::ParamError::Group`] for a group of another law (e.g. `restitution` with
    /// `contact_law = hertz`); the groups' ranges are checked by [`ContactLaw::validate`].
    #[allow(clippy::too_many_arguments)]
    pub fn from_parts(
        kind: Option<LawKind>,
        hamaker: Option<f64>,
        intermolecular_distance: Option<f64>,
        restitution: Option<f64>,
        electrostatic: Option<f64>,
        tip_radius: Option<f64>,
        base: ContactLaw,
    ) -> Result<ContactLaw, crate::ParamError> {
        let kind = kind.unwrap_or(base.kind());
        const DMT: &[LawKind] = &[LawKind::Dmt, LawKind::Electrostatic];
        const ES: &[LawKind] = &[LawKind::Electrostatic];
        for (given, group, owners, owner) in [
            (
                restitution.is_some(),
                "restitution",
                &[LawKind::Impact][..],
                "impact",
            ),
            (hamaker.is_some(), "hamaker", DMT, "dmt or electrostatic"),
            (
                intermolecular_distance.is_some(),
                "intermolecular_distance",
                DMT,
                "dmt or electrostatic",
            ),
            (
                electrostatic.is_some(),
                "electrostatic",
                ES,
                "electrostatic",
            ),
            (tip_radius.is_some(), "tip_radius", ES, "electrostatic"),
        ] {
            if given && !owners.contains(&kind) {
                return Err(crate::ParamError::Group {
                    group,
                    owner,
                    law: kind.name(),
                });
            }
        }
        // groups not given keep base's when base has them
        let (h0, a0, r0, e0, t0) = match base {
            ContactLaw::Dmt {
                hamaker,
                intermolecular_distance,
            } => (
                Some(hamaker),
                Some(intermolecular_distance),
                None,
                None,
                None,
            ),
            ContactLaw::Electrostatic {
                hamaker,
                intermolecular_distance,
                electrostatic,
                tip_radius,
            } => (
                Some(hamaker),
                Some(intermolecular_distance),
                None,
                Some(electrostatic),
                Some(tip_radius),
            ),
            ContactLaw::Impact { restitution } => (None, None, Some(restitution), None, None),
            _ => (None, None, None, None, None),
        };
        Ok(kind.with_groups(
            hamaker.or(h0),
            intermolecular_distance.or(a0),
            restitution.or(r0),
            electrostatic.or(e0),
            tip_radius.or(t0),
        ))
    }

    /// The law's kind without its groups.
    pub fn kind(&self) -> LawKind {
        match self {
            ContactLaw::Linear => LawKind::Linear,
            ContactLaw::Hertz => LawKind::Hertz,
            ContactLaw::Dmt { .. } => LawKind::Dmt,
            ContactLaw::Electrostatic { .. } => LawKind::Electrostatic,
            ContactLaw::Impact { .. } => LawKind::Impact,
        }
    }
}

impl LawKind {
    /// The kind's name: `linear`, `hertz`, `dmt`, `electrostatic` or `impact`.
    pub fn name(self) -> &'static str {
        match self {
            LawKind::Linear => "linear",
            LawKind::Hertz => "hertz",
            LawKind::Dmt => "dmt",
            LawKind::Electrostatic => "electrostatic",
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
            ContactLaw::Hertz if contact => {
                let d = delta.max(0.0);
                let s = d.sqrt();
                ForceEval {
                    force: k * d * s + c * rate,
                    d_delta: 1.5 * k * s,
                    d_rate: c,
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
            ContactLaw::Linear if contact => 0.5 * k * delta * delta,
            ContactLaw::Hertz if contact => 0.4 * k * delta.max(0.0).powf(2.5),
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
            ContactLaw::Dmt { .. } | ContactLaw::Electrostatic { .. } => {
                self.damping * delta.max(0.0).sqrt() * rate
            }
            ContactLaw::Impact { .. } => 0.0,
        }
    }

    fn acts_outside(&self) -> bool {
        matches!(
            self.law,
            ContactLaw::Dmt { .. } | ContactLaw::Electrostatic { .. }
        )
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
            for &(contact, delta, rate) in &[
                (true, 0.07, 0.3),
                (true, 0.5, -1.2),
                (false, -0.05, 0.4),
                (false, -0.8, -2.0),
            ] {
                let f = ts.force(contact, delta, rate);
                let h = 1e-6;
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
