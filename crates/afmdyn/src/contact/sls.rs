//! `sls` — the standard linear solid (Zener) sample with surface memory (López-Guerra &
//! Solares, *Beilstein J. Nanotechnol.* 5 (2014) 2149, §2; Zener, *Elasticity and Anelasticity
//! of Metals*, Chicago 1948): the relaxed spring α4 in parallel with a Maxwell arm, the spring
//! κ in series with the dashpot α6. Its internal state is the dashpot's extension u (units of
//! g₀, the state's last entry). In contact the sample's surface follows the tip, δ = −V_T, and
//! F_c = α4 δ + κ(δ − u), u̇ = (κ/α6)(δ − u); the force never pulls: the tip leaves the
//! surface where F_c falls to 0. Free of the tip, the massless surface sits where its springs
//! balance, at the depression s(u) = κu/(α4 + κ), and recovers as u̇ = −α4κ u/(α6(α4 + κ));
//! the tip touches it again where V_T = −s(u). Both guards are therefore σ(V_T + s(u)), the
//! contact's being F_c/(α4 + κ). The energy stored in the sample is
//! U = ½α4 δ_s² + ½κ(δ_s − u)² (δ_s the surface's depression), continuous at the switchings,
//! and the dashpot dissipates α6 u̇² in and out of contact. Under a prescribed indentation
//! δ₀ sin ωτ held in contact it dissipates πκωτ_r δ₀²/(1 + ω²τ_r²) per cycle, τ_r = α6/κ
//! (the loss of a Maxwell element, e.g. Lakes, *Viscoelastic Materials*, CUP 2009, §2.7). κ → 0
//! is the linear law without damper; κ → ∞ a Kelvin–Voigt solid α4, α6 whose surface lags
//! the tip. ([`Zener`]; the model carries u, [`crate::CantileverModel`].)

use super::{ForceEval, Law, Param, SampleSi};
use crate::error::ParamError;

/// Default Maxwell arm κ = 20 of the SLS law: the sample twice as stiff at the onset of a tap
/// (α4 + κ = 40 with the default α4 = 20) as at rest, with a relaxation time α6/κ = 0.01 (the
/// default α6 = 0.2) between the contact's time scale 1/√(α4 + κ) and the drive period, so the
/// Maxwell arm both stiffens and damps the tap.
pub const SLS_DEFAULT_MAXWELL: f64 = 20.0;

/// The SLS law's group.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SlsLaw {
    /// κ ≥ 0: the Maxwell arm's spring (units of α4); the instantaneous stiffness is α4 + κ
    /// and the relaxation time α6/κ.
    pub maxwell_stiffness: f64,
}

impl Law for SlsLaw {
    const DOC: &'static str = "standard linear solid (Zener) sample with surface memory: the relaxed spring α4 in parallel with a Maxwell arm (spring κ, dashpot α6), one internal state";
    const ALIASES: &'static [&'static str] = &["zener"];
    const SAMPLE_KEYS: &'static [&'static str] = &["law", "stiffness", "maxwell_stiffness", "relaxation_time", "z_c"];
    const PARAMS: &'static [Param] = &[Param {
        name: "maxwell_stiffness",
        symbol: "κ",
        unit: "1",
        range: "0 < κ ≤ 1e12",
        default: SLS_DEFAULT_MAXWELL,
        doc: "the Maxwell arm's spring κ (in series with the dashpot α6; relaxation time α6/κ, instantaneous stiffness α4 + κ)",
        si_keys: &["maxwell_stiffness", "relaxation_time"],
        under_probe: Some("give the probe file's [sample] maxwell_stiffness (N/m, law = \"sls\")"),
    }];

    super::prepared::as_given!();
    fn validate(&self) -> Result<(), ParamError> {
        let maxwell_stiffness = self.maxwell_stiffness;
        // κ = 0 leaves u without dynamics (a neutral direction of every monodromy):
        // that sample is the linear law with α6 = 0
        if !(maxwell_stiffness.is_finite() && maxwell_stiffness > 0.0 && maxwell_stiffness <= 1e12)
        {
            return Err(ParamError::Law {
                name: "maxwell_stiffness (SLS Maxwell arm κ)",
                value: maxwell_stiffness,
                range: "0 < κ ≤ 1e12 (κ = 0 is the linear law with α6 = 0)",
            });
        }
        Ok(())
    }
    fn validate_shared(&self, alpha4: f64, alpha6: f64) -> Result<(), ParamError> {
        // the Maxwell arm relaxes at κ/α6: a dashpot is needed (α6 = 0 would relax it
        // instantly), and its rate must stay within the integrators' reach
        let rate = self.maxwell_stiffness / alpha6;
        if !(alpha6 > 0.0 && rate <= 1e12) {
            return Err(ParamError::Law {
                name: "alpha6 (the SLS Maxwell arm's dashpot α6)",
                value: alpha6,
                range: "α6 > 0 with κ/α6 ≤ 1e12 (the relaxation rate)",
            });
        }
        // the relaxed spring brings the surface back after a tap (α4 = 0, a Maxwell
        // fluid, keeps every dent)
        if alpha4 <= 0.0 || alpha4.is_nan() {
            return Err(ParamError::Law {
                name: "alpha4 (the SLS relaxed spring α4)",
                value: alpha4,
                range: "α4 > 0 (the spring that brings the surface back after a tap)",
            });
        }
        Ok(())
    }
    fn from_si(si: &SampleSi) -> Result<(Self, f64, f64), String> {
        // springs in units of F_s/g₀; the dashpot η = k₂τ_r (N·s/m) as the linear
        // law's damper: α6 = η g₀/(t_s F_s) = κ τ_r/t_s
        let (k2, tau_r) = si.maxwell.unwrap_or((0.0, 0.0));
        let alpha4 = si.stiffness.unwrap_or(0.0) * si.g0 / si.force;
        let maxwell_stiffness = k2 * si.g0 / si.force;
        let alpha6 = maxwell_stiffness * tau_r / si.time;
        // the dashpot's group is the model's α6: name the SI keys that make it, not α6
        if alpha6 > super::DAMPING_MAX {
            return Err(format!(
                "[sample].maxwell_stiffness = {k2:e} N/m with relaxation_time = {tau_r:e} s: \
                 the dashpot η = k2·τ_r gives α6 = {alpha6:.3e}, beyond {:e} (too stiff a \
                 dashpot for the integration grid; check the units, N/m and s)",
                super::DAMPING_MAX
            ));
        }
        Ok((SlsLaw { maxwell_stiffness }, alpha4, alpha6))
    }
    /// The relaxed (equilibrium) force: the Maxwell arm's force depends on the state u,
    /// which the model evaluates ([`Zener`]); this is the quasi-static law.
    fn force(&self, k: f64, _c: f64, contact: bool, delta: f64, _rate: f64) -> ForceEval {
        if !contact {
            return ForceEval::default();
        }
        ForceEval {
            force: k * delta,
            d_delta: k,
            d_rate: 0.0,
        }
    }
    fn potential(&self, k: f64, contact: bool, delta: f64) -> f64 {
        if contact {
            0.5 * k * delta * delta
        } else {
            0.0
        }
    }
    fn internal_states(&self) -> usize {
        1
    }
    fn zener(&self, alpha4: f64, alpha6: f64) -> Option<Zener> {
        Some(Zener::new(alpha4, self.maxwell_stiffness, alpha6))
    }
}

/// The standard linear solid with surface memory ([`super::ContactLaw::Sls`], module docs): the
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
    pub(crate) fn new(alpha4: f64, maxwell: f64, alpha6: f64) -> Zener {
        Zener {
            relaxed: alpha4,
            maxwell,
            dashpot: alpha6,
        }
    }
    /// κ/(α4 + κ): the free surface's depression per unit u (0 for κ = 0, 1 for α4 = 0).
    pub(crate) fn surface_gain(&self) -> f64 {
        let k = self.relaxed + self.maxwell;
        if k > 0.0 {
            self.maxwell / k
        } else {
            0.0
        }
    }
    /// s(u) = κu/(α4 + κ): where the free surface sits (a depression, g₀), balanced between
    /// its springs. The switching function is V_T + s(u) in both regions.
    pub(crate) fn surface(&self, u: f64) -> f64 {
        self.surface_gain() * u
    }
    /// The surface's depression δ_s: the indentation δ in contact, s(u) free.
    pub(crate) fn depression(&self, contact: bool, delta: f64, u: f64) -> f64 {
        if contact {
            delta
        } else {
            self.surface(u)
        }
    }
    /// κ/α6: the Maxwell arm's relaxation rate 1/τ_r (0 for κ = 0).
    pub(crate) fn relaxation_rate(&self) -> f64 {
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
    pub(crate) fn rate(&self, contact: bool, delta: f64, u: f64) -> f64 {
        self.relaxation_rate() * (self.depression(contact, delta, u) - u)
    }
    /// U = ½α4 δ_s² + ½κ(δ_s − u)²: the energy stored in the sample's springs.
    pub fn potential(&self, contact: bool, delta: f64, u: f64) -> f64 {
        let ds = self.depression(contact, delta, u);
        0.5 * self.relaxed * ds * ds + 0.5 * self.maxwell * (ds - u) * (ds - u)
    }
    /// α6 u̇²: the dashpot's dissipation rate (≥ 0).
    pub(crate) fn dissipation(&self, contact: bool, delta: f64, u: f64) -> f64 {
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
