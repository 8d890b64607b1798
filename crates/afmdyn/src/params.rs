//! The dimensionless parameter set of the paper (eq. 7) with validation.

use crate::contact::ContactLaw;
use crate::error::ParamError;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Largest number of Galerkin modes supported (the mode shapes are accurate to ~1e-13 up to i = 20).
pub(crate) const MAX_MODES: usize = 20;

/// Largest state dimension 2N + m: [`MAX_MODES`] modes and the internal states of a law
/// ([`crate::ContactLaw::internal_states`], at most 1).
pub(crate) const MAX_STATE: usize = 2 * MAX_MODES + 1;

const _: () = assert!(
    MAX_MODES == 20,
    "Params::damping_profile has MAX_MODES entries"
);

/// Largest tip-mass ratio α1: the mass matrix I + α1 φ(1)φ(1)ᵀ has condition number ≈ 4Nα1, and
/// beyond 10⁴ beam masses its Cholesky factor (used by every integrator) loses too many digits.
pub(crate) const ALPHA1_MAX: f64 = 1e4;
/// Largest drive amplitude α2 and gap |α5|: displacements scale with them, and the integrators
/// stop as diverged at a state norm of `STATE_NORM_MAX`; beyond 10⁶ products such as the
/// squared gap in the contact energy leave the range where the switching search is reliable.
pub(crate) const DISPLACEMENT_MAX: f64 = 1e6;
pub(crate) use crate::contact::DAMPING_MAX;
/// Largest contact stiffness α4: contact frequencies grow as √(4Nα4); beyond 10⁸ the contact
/// system is both stiff and ill-conditioned.
pub(crate) const ALPHA4_MAX: f64 = 1e8;
/// Smallest drive frequency Ω: below it one drive period spans more than ~10⁴ oscillations of
/// the first mode, a grid far beyond `GRID_BUDGET_BYTES` for any N > 1.
pub(crate) const OMEGA_MIN: f64 = 1e-3;
/// Smallest modulation frequency Ω = f_m/f₀ of a moving sample ([`Excitation::Sample`],
/// off-resonance tapping): f₀/f_m up to 10⁵ is physical (a 300 kHz lever under a 1–8 kHz
/// PeakForce modulation is 40–300; a 2 MHz lever at 250 Hz is 8 000), and the modulation
/// does not set the integrators' steps (they follow the lever's modes, the switching search
/// its contact), so its period costs ~1/Ω lever periods of work, bounded at run time by
/// [`ADAPTIVE_STEPS_PER_PERIOD`] and up front by [`ADAPTIVE_STEPS_BUDGET`] and
/// [`GRID_BUDGET_BYTES`]. The resonant drives keep [`OMEGA_MIN`].
pub(crate) const OMEGA_MIN_MODULATED: f64 = 1e-5;
/// Largest drive frequency Ω: above it the inertial drive α2Ω² is so much larger than the
/// response that the result is round-off (the per-period energy balance fails, 1e-7 relative at
/// Ω = 1e8), and Ω is far above the highest Galerkin mode the model resolves (N ≤ 20).
pub(crate) const OMEGA_MAX: f64 = 1e5;
/// States with ‖z‖₂ at or above this are treated as diverged by the integrators; an initial
/// state must lie below it.
pub(crate) const STATE_NORM_MAX: f64 = 1e12;
/// Memory budget of the exact propagator's period grid: (2N + 2)(m + 1) values of 8 bytes for
/// m sub-steps per drive period. A parameter set whose grid would exceed it is refused before
/// anything is allocated (Ω very small, or very stiff or heavily damped contact).
pub(crate) const GRID_BUDGET_BYTES: f64 = 128.0 * 1024.0 * 1024.0;
/// Budget of the adaptive oracle: the estimated number of steps per drive period, T‖A‖_F (the
/// Frobenius norm bounds the fastest rate of the system), may not exceed this.
pub(crate) const ADAPTIVE_STEPS_BUDGET: f64 = 1e7;
/// Budget of the adaptive integrator while it runs: the DOP853 steps (accepted and rejected)
/// it may take within one drive period. The estimate of `ADAPTIVE_STEPS_BUDGET` sees the
/// linear part only; a nonlinear law can grow far stiffer where the motion goes (a tip captured
/// by a strong DMT adhesion needs ~3e5 steps per period, ~2 s, where the default Hertz orbit
/// needs ~200). 1e5 steps (~1 s at N = 3) is 500× the default's; beyond, the run ends with
/// [`crate::SimError::Budget`] naming what to change, rather than running for hours.
pub(crate) const ADAPTIVE_STEPS_PER_PERIOD: usize = 100_000;

/// Dimensionless model parameters (paper eq. 7), all in the units of eq. 5.
///
/// | field | symbol | meaning | allowed |
/// |---|---|---|---|
/// | `modes` | N | number of Galerkin modes (eq. 9) | 1..=20 |
/// | `alpha1` | α1 = M/(mL) | tip-mass ratio | 0 ..= 1e4 |
/// | `alpha2` | α2 = f/g0 | base-drive amplitude | 0 ..= 1e6 |
/// | `alpha3` | α3 | beam (viscous) damping | 0 ..= 1e4 |
/// | `alpha4` | α4 = K1 L³/(EI) | contact stiffness | 0 ..= 1e8 |
/// | `alpha5` | α5 = g1/g0 | tip–sample gap | −1e6 ..= 1e6 |
/// | `alpha6` | α6 | contact damping | 0 ..= 1e4 |
/// | `omega` | Ω | drive frequency (dimensionless) | 1e-3 ..= 1e5 |
/// | `contact_law` | F_c(δ, δ̇) | tip–sample law and its groups ([`ContactLaw`]) | see the law |
///
/// The upper limits are where the numerics stop being meaningful (see `ALPHA1_MAX` and the
/// other constants of this module for the reason of each).
///
/// α4 and α6 are the stiffness and damping groups of whichever law is chosen (the Hertz group
/// and the Kelvin–Voigt group for `hertz`/`dmt`, see [`crate::contact`]).
/// The fields are public for convenience; every constructor of a model calls [`Params::validate`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Params {
    /// Number of Galerkin modes N.
    pub modes: usize,
    /// α1, tip-mass ratio M/(mL).
    pub alpha1: f64,
    /// α2, drive amplitude f/g0.
    pub alpha2: f64,
    /// α3, beam damping.
    pub alpha3: f64,
    /// α4, contact stiffness K1 L³/(EI).
    pub alpha4: f64,
    /// α5, gap g1/g0.
    pub alpha5: f64,
    /// α6, contact damping.
    pub alpha6: f64,
    /// Ω, dimensionless drive frequency.
    pub omega: f64,
    /// The tip–sample force law (default: the paper's linear spring–damper).
    #[serde(default)]
    pub contact_law: ContactLaw,
    /// The structural model: the paper's beam (default) or the point-mass model of the AFM
    /// literature ([`Structure`]).
    #[serde(default)]
    pub structure: Structure,
    /// Per-mode damping profile s_j of the beam, C^I = α3 diag(s_1 … s_N) (`None`: s_j = 1,
    /// eq. 12). Only the first N entries are used; set from per-mode quality factors by
    /// [`crate::probe`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    // 20 = MAX_MODES, written as a literal: with the named constant, clippy-driver 1.95 stops
    // with an internal compiler error on closures that capture a Params (tests/stability.rs)
    pub damping_profile: Option<[f64; 20]>,
    /// The eigenmode model's modes ([`Structure::Eigenmodes`]; `None` for the other models).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eigenmodes: Option<Eigenmodes>,
    /// Further components of a multifrequency drive ([`DriveComponent`]; multifrequency AFM,
    /// García & Proksch, *Eur. Polym. J.* 49 (2013) 1897): forces at the tip beside the
    /// primary drive (α2 at Ω). `None` entries are absent; the default has none.
    // 3 = MAX_DRIVE_COMPONENTS as a literal (the named constant in a field's array length
    // makes rustc 1.95 stop with an internal compiler error, as for damping_profile)
    #[serde(default, skip_serializing_if = "no_components")]
    pub drive_components: [Option<DriveComponent>; 3],
    /// Where the primary drive α2 acts ([`Excitation`]): at the base (the paper, the default
    /// for the beam) or as a force at the tip. The lumped models are always force-driven.
    #[serde(default, skip_serializing_if = "Excitation::is_base")]
    pub excitation: Excitation,
    /// Each mode's hydrodynamic loading in a liquid or gas ([`Hydrodynamic`], set from a
    /// probe's `[medium]` by [`crate::probe`]; `None`: none, as in the paper).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hydrodynamic: Option<Hydrodynamic>,
}

/// Where the primary drive acts on the beam.
///
/// * `Base` — the paper's base displacement α2 sin Ωτ (acoustic or piezo excitation at the
///   chip, eq. 6): V_T moves with the base (eq. 8).
/// * `Tip` — a force α2 cos Ωτ at the tip (magnetic excitation of a coated lever, or
///   photothermal excitation modelled at the tip; Xu, Melcher, Basak & Raman, *Phys. Rev.
///   Lett.* 102 (2009) 060801 drive magnetically in liquid): modal forcing φ_j(1) α2 cos Ωτ,
///   the base does not move, V_T = W(1,τ) + α5, in the force unit of α4 V_T.
///
/// * `Sample` — the sample moves by α2 sin Ωτ (off-resonance tapping, PeakForce / PF-QNM, with
///   the z-modulation on the sample): V_T = W(1,τ) + α5 + α2 sin Ωτ as for the base drive
///   (eq. 8, the tip–sample distance sees the same sinusoid), but the lever's frame does not
///   move, so the modal forcing is zero (no inertial or drag term of eq. 14). It works on
///   every structure, the lumped models included.
///
/// The lumped models ([`Structure::is_lumped`]) are force-driven unless this is `Sample`. The
/// fluid-borne excitation of an acoustic drive in liquid (the "forest of peaks", Schäffer,
/// Cleveland, Ohnesorge, Walters & Hansma, *Ultramicroscopy* 63 (1996) 149) is not modelled:
/// the liquid is at rest far from the lever.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "lowercase")]
pub enum Excitation {
    /// Base displacement α2 sin Ωτ (the paper).
    #[default]
    Base,
    /// Force α2 cos Ωτ at the tip.
    Tip,
    /// The sample moves by α2 sin Ωτ; the lever's frame is at rest (off-resonance tapping).
    Sample,
}

impl Excitation {
    /// Whether this is the base drive (the default).
    pub(crate) fn is_base(&self) -> bool {
        *self == Excitation::Base
    }
    /// `base` or `tip`.
    pub fn name(self) -> &'static str {
        match self {
            Excitation::Base => "base",
            Excitation::Tip => "tip",
            Excitation::Sample => "sample",
        }
    }
}

impl FromStr for Excitation {
    type Err = String;
    /// `base` (or `acoustic`, `piezo`), `tip` (or `magnetic`, `photothermal`), in any case.
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "base" | "acoustic" | "piezo" => Ok(Excitation::Base),
            "tip" | "magnetic" | "photothermal" => Ok(Excitation::Tip),
            _ => Err(format!(
                "excitation '{s}': expected base (acoustic, piezo) or tip (magnetic, \
                 photothermal)"
            )),
        }
    }
}

/// The hydrodynamic loading of each mode by the surrounding fluid, in the model's units
/// (mass of the bare beam mL = 1, or mode 1's modal mass for the lumped models; time τ):
/// mode j gains the added mass `added_mass[j]` on the diagonal of M and the damping
/// `damping[j]` on the diagonal of C^I (and of C^II). For the beam base drive the fluid acts
/// on the absolute motion, so the forcing gains α2Ω² m_a,j ∫φ_j sin Ωτ − α2Ω c_j ∫φ_j cos Ωτ.
///
/// From Sader's hydrodynamic function evaluated at each mode's frequency in the fluid
/// ([`crate::hydro`]; Sader, *J. Appl. Phys.* 84 (1998) 64): m_a,j = m_j T Γ_r(ω_j),
/// c_j = m_j T Γ_i(ω_j) ω_j, with T = πρb²/(4μ) and m_j the mode's mass (1 for the beam's
/// orthonormal modes). Evaluating Γ at each mode's own frequency keeps M and C diagonal in
/// the modes (the approximation of Basak, Raman & Garoff, *J. Appl. Phys.* 99 (2006) 114906
/// and of VEDA's liquid model); only the first N entries are used.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Hydrodynamic {
    /// m_a,j ≥ 0, the added modal mass of mode j.
    pub added_mass: [f64; 20],
    /// c_j ≥ 0, the hydrodynamic modal damping of mode j (per unit τ).
    pub damping: [f64; 20],
}

/// Check a coefficient that must be finite, ≥ 0 and ≤ `max` (`range` as written, `reason` why).
/// Why a tip mass (or a mode's added mass) is bounded.
const TIP_MASS: &str = "the mass matrix becomes ill-conditioned";
/// Why displacements (α2, α5, a component's force) are bounded.
const DISPLACEMENT: &str = "displacements scale with it and overflow the switching search";
/// Why damping (α3, α6, a mode's damping) is bounded.
const DAMPING: &str = "the system becomes too stiff for the integration grid";

fn bounded(
    name: &'static str,
    value: f64,
    max: f64,
    range: &'static str,
    reason: &'static str,
) -> Result<(), ParamError> {
    if !(value.is_finite() && value >= 0.0) {
        return Err(ParamError::NonNegative { name, value });
    }
    if value > max {
        return Err(ParamError::Magnitude {
            name,
            value,
            range,
            reason,
        });
    }
    Ok(())
}

/// Most further drive components beside the primary one ([`Params::drive_components`]).
pub(crate) const MAX_DRIVE_COMPONENTS: usize = 3;
/// Largest common period of a multifrequency drive, in periods 2π/Ω of the primary drive:
/// the orbit, the stroboscopic map and the observables' window span this many periods.
pub(crate) const MAX_COMMON_PERIODS: u64 = 1000;
/// Largest q of a component's ratio p/q: with q up to 10⁶ every frequency ratio is given to
/// about 1e-12 (a continued fraction's convergent), so an incommensurate ratio is represented
/// to round-off of a window's phase; such a drive is quasi-periodic ([`Params::is_quasiperiodic`]).
pub(crate) const MAX_RATIO_DENOMINATOR: u32 = 1_000_000;
/// Largest p of a component's ratio p/q.
pub(crate) const MAX_RATIO_NUMERATOR: u32 = 1_000_000_000;

/// The convergent p/q of the continued fraction of `r` > 0 with the largest q ≤ `max_q` (and
/// p ≤ [`MAX_RATIO_NUMERATOR`]), as [`crate::probe::convergent`]: the best rational
/// approximation of `r` with a denominator that small. `None` for r outside (0, 10⁶) or not
/// finite.
pub(crate) fn convergent_within(r: f64, max_q: u32) -> Option<(u32, u32)> {
    if !(r.is_finite() && r > 0.0 && r < 1e6) {
        return None;
    }
    let (max_p, max_q) = (f64::from(MAX_RATIO_NUMERATOR), f64::from(max_q));
    // h_n/k_n from the partial quotients a_n: h_n = a_n h_{n−1} + h_{n−2}, likewise k_n
    let (mut h, mut h1, mut k, mut k1) = (1.0f64, 0.0f64, 0.0f64, 1.0f64);
    let mut x = r;
    let mut best = None;
    for _ in 0..64 {
        let a = x.floor();
        let (hn, kn) = (a * h + h1, a * k + k1);
        if hn > max_p || kn > max_q {
            break;
        }
        if hn >= 1.0 {
            best = Some((hn as u32, kn as u32));
        }
        (h1, h, k1, k) = (h, hn, k, kn);
        let frac = x - a;
        if frac <= 1e-15 * x.max(1.0) {
            break;
        }
        x = 1.0 / frac;
    }
    best
}

const _: () = assert!(
    MAX_DRIVE_COMPONENTS == 3,
    "Params::drive_components has MAX_DRIVE_COMPONENTS entries"
);

fn no_components(c: &[Option<DriveComponent>; 3]) -> bool {
    c.iter().all(Option::is_none)
}

/// One further component of a multifrequency drive: the force F̃ cos(p/q Ω τ + θ) at the tip,
/// in the model's force unit (that of the contact force F_c: k g₀ for the lumped models, the
/// unit of α4 V_T for the beam). It enters every model as the tip force does, through
/// φ(1)F̃ (paper eq. 8 with F_c → F_c + F̃ cos(…)): for the eigenmode model each mode is
/// driven by every component (García & Proksch 2013, eq. 1); for the beam it is a force drive
/// at the tip (magnetic or photothermal) beside the base drive, which does not move V_T.
/// The frequency ratio p/q is rational, so the drive is periodic with the common period
/// 2πq/Ω for p/q in lowest terms ([`Params::common_periods`]); a common period beyond
/// `MAX_COMMON_PERIODS` makes the drive quasi-periodic ([`Params::is_quasiperiodic`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriveComponent {
    /// F̃ ≥ 0, the force amplitude at the tip (model units, above).
    pub force: f64,
    /// [p, q], p in 1..=`MAX_RATIO_NUMERATOR` and q in 1..=`MAX_RATIO_DENOMINATOR`: the
    /// frequency is p/q times Ω (q sets the common period, [`Params::common_periods`]; above
    /// `MAX_COMMON_PERIODS` the drive is quasi-periodic).
    pub ratio: [u32; 2],
    /// θ, the phase of the component (rad).
    pub phase: f64,
}

impl DriveComponent {
    /// The component's frequency ratio p/q to Ω.
    pub(crate) fn ratio(&self) -> f64 {
        f64::from(self.ratio[0]) / f64::from(self.ratio[1])
    }
    /// The component's period in periods 2π/Ω: q/gcd(p, q).
    pub fn periods(&self) -> u64 {
        let [p, q] = self.ratio.map(u64::from);
        q / gcd(p, q)
    }
}

/// Greatest common divisor (Euclid).
pub(crate) fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

impl Default for Params {
    /// The paper's set for Figs. 5–14 (eq. 26 with α1 = 0.1, N = 3) at Ω = 2.6.
    fn default() -> Self {
        Params {
            modes: 3,
            alpha1: 0.1,
            alpha2: 0.1,
            alpha3: 0.1,
            alpha4: 20.0,
            alpha5: 0.0,
            alpha6: 0.2,
            omega: 2.6,
            contact_law: ContactLaw::Linear,
            structure: Structure::Beam,
            damping_profile: None,
            eigenmodes: None,
            drive_components: [None; MAX_DRIVE_COMPONENTS],
            excitation: Excitation::Base,
            hydrodynamic: None,
        }
    }
}

impl Params {
    /// The paper's eq. 24 set (α1 = α2 = 0.1, α3 = α5 = α6 = 0, α4 = 20) at Ω = 4.1 (Fig. 4).
    pub fn paper_eq24() -> Self {
        Params {
            alpha3: 0.0,
            alpha6: 0.0,
            omega: 4.1,
            ..Params::default()
        }
    }

    /// Check every field against its allowed range, and that the drive is periodic with a
    /// common period of at most `MAX_COMMON_PERIODS` drive periods (what periodic orbits,
    /// stroboscopic maps and every analysis but the time average need).
    ///
    /// # Errors
    /// [`ParamError`] naming the first field out of range.
    pub fn validate(&self) -> Result<(), ParamError> {
        self.validate_fields()?;
        if self.is_quasiperiodic() {
            return Err(ParamError::Structure {
                name: "drive_components.ratio (the common period, lcm of the q's, at most 1000 \
                       drive periods: a drive this close to incommensurate is averaged in time by \
                       bimodal, not shot as an orbit)",
                value: self.common_periods() as f64,
            });
        }
        Ok(())
    }

    /// Whether the drive's common period exceeds `MAX_COMMON_PERIODS`: a ratio p/q given to
    /// within 1e-12 by a q up to 10⁶, incommensurate in all but name, whose response is
    /// measured by the time average ([`crate::analysis::stepped::average`]).
    pub fn is_quasiperiodic(&self) -> bool {
        self.common_periods() > MAX_COMMON_PERIODS
    }

    /// [`Params::validate`] without the limit on the common period: the fields a model needs,
    /// for the time average of a quasi-periodic drive ([`crate::analysis::stepped::average`]).
    ///
    /// # Errors
    /// [`ParamError`] naming the first field out of range.
    pub(crate) fn validate_fields(&self) -> Result<(), ParamError> {
        self.validate_groups()?;
        self.contact_law.validate()?;
        // the law's groups against the shared α4, α6 (JKR's neck scale P̃/α4, the SLS
        // relaxation rate κ/α6)
        self.contact_law.validate_shared(self.alpha4, self.alpha6)?;
        if let Some(profile) = &self.damping_profile {
            for &s in &profile[..self.modes] {
                if !(s.is_finite() && s >= 0.0) {
                    return Err(ParamError::NonNegative {
                        name: "damping_profile (per-mode damping s_j)",
                        value: s,
                    });
                }
                if s * self.alpha3 > DAMPING_MAX {
                    return Err(ParamError::Magnitude {
                        name: "damping_profile (per-mode damping α3 s_j)",
                        value: s * self.alpha3,
                        range: "[0, 1e4]",
                        reason: DAMPING,
                    });
                }
            }
        }
        self.validate_eigenmodes()?;
        self.validate_components()?;
        if let Some(h) = &self.hydrodynamic {
            for j in 0..self.modes {
                bounded(
                    "hydrodynamic.added_mass (mode's added mass)",
                    h.added_mass[j],
                    ALPHA1_MAX,
                    "[0, 1e4]",
                    TIP_MASS,
                )?;
                bounded(
                    "hydrodynamic.damping (mode's hydrodynamic damping)",
                    h.damping[j],
                    DAMPING_MAX,
                    "[0, 1e4]",
                    DAMPING,
                )?;
            }
        }
        if self.structure == Structure::PointMass {
            for (name, bad, value) in [
                (
                    "modes (point-mass model: exactly 1)",
                    self.modes != 1,
                    self.modes as f64,
                ),
                (
                    "alpha1 (point-mass model: no tip mass, 0)",
                    self.alpha1 != 0.0,
                    self.alpha1,
                ),
                (
                    "damping_profile (point-mass model: one mode, use alpha3 = 1/Q)",
                    self.damping_profile.is_some(),
                    f64::NAN,
                ),
            ] {
                if bad {
                    return Err(ParamError::Structure { name, value });
                }
            }
        }
        Ok(())
    }

    /// N, the groups α1 … α6 and Ω against their ranges.
    fn validate_groups(&self) -> Result<(), ParamError> {
        if !(1..=MAX_MODES).contains(&self.modes) {
            return Err(ParamError::Modes(self.modes));
        }
        for (name, value, max, range, reason) in [
            (
                "alpha1 (tip-mass ratio α1)",
                self.alpha1,
                ALPHA1_MAX,
                "[0, 1e4]",
                TIP_MASS,
            ),
            (
                "alpha2 (drive amplitude α2)",
                self.alpha2,
                DISPLACEMENT_MAX,
                "[0, 1e6]",
                DISPLACEMENT,
            ),
            (
                "alpha3 (beam damping α3)",
                self.alpha3,
                DAMPING_MAX,
                "[0, 1e4]",
                DAMPING,
            ),
            (
                "alpha4 (contact stiffness α4)",
                self.alpha4,
                ALPHA4_MAX,
                "[0, 1e8]",
                "the contact system becomes too stiff and ill-conditioned",
            ),
            (
                "alpha6 (contact damping α6)",
                self.alpha6,
                DAMPING_MAX,
                "[0, 1e4]",
                DAMPING,
            ),
        ] {
            bounded(name, value, max, range, reason)?;
        }
        if !self.alpha5.is_finite() {
            return Err(ParamError::Gap(self.alpha5));
        }
        if self.alpha5.abs() > DISPLACEMENT_MAX {
            return Err(ParamError::Magnitude {
                name: "alpha5 (gap α5)",
                value: self.alpha5,
                range: "[-1e6, 1e6]",
                reason: DISPLACEMENT,
            });
        }
        if !(self.omega.is_finite() && self.omega > 0.0) {
            return Err(ParamError::Omega(self.omega));
        }
        // a moving sample (off-resonance modulation) has its own lower bound
        let (lowest, range) = if self.excitation == Excitation::Sample {
            (OMEGA_MIN_MODULATED, "[1e-5, 1e5] (a modulated sample)")
        } else {
            (OMEGA_MIN, "[1e-3, 1e5]")
        };
        if !(lowest..=OMEGA_MAX).contains(&self.omega) {
            return Err(ParamError::Magnitude {
                name: "omega (drive frequency Ω)",
                value: self.omega,
                range,
                reason: if self.omega < lowest {
                    "one drive period would need too many integration steps"
                } else {
                    "the drive swamps the response in round-off, far above the highest mode"
                },
            });
        }
        Ok(())
    }

    /// The eigenmode model's modes, given for it and only for it: no tip mass, mode 1's
    /// stiffness and frequency 1, the others' ratios in range.
    fn validate_eigenmodes(&self) -> Result<(), ParamError> {
        match (self.structure, &self.eigenmodes) {
            (Structure::Eigenmodes, None) => Err(ParamError::Structure {
                name: "eigenmodes (eigenmode model: the modes' stiffnesses and frequencies)",
                value: f64::NAN,
            }),
            (Structure::Eigenmodes, Some(e)) => {
                if self.alpha1 != 0.0 {
                    return Err(ParamError::Structure {
                        name: "alpha1 (eigenmode model: no tip mass, 0)",
                        value: self.alpha1,
                    });
                }
                for j in 0..self.modes {
                    let (k, w) = (e.stiffness[j], e.frequency[j]);
                    let first = j == 0 && (k != 1.0 || w != 1.0);
                    if first || !(k.is_finite() && k > 0.0 && k <= 1e12) {
                        return Err(ParamError::Structure {
                            name: "eigenmodes.stiffness (k_j/k_1: 1 for mode 1, in (0, 1e12])",
                            value: k,
                        });
                    }
                    if !(w.is_finite() && w > 0.0 && w <= 1e4) {
                        return Err(ParamError::Structure {
                            name: "eigenmodes.frequency (ω_j/ω_1: 1 for mode 1, in (0, 1e4])",
                            value: w,
                        });
                    }
                }
                Ok(())
            }
            (_, Some(_)) => Err(ParamError::Structure {
                name: "eigenmodes (only for the eigenmode model)",
                value: f64::NAN,
            }),
            _ => Ok(()),
        }
    }

    /// The further drive components' forces, ratios and phases.
    fn validate_components(&self) -> Result<(), ParamError> {
        for c in self.components() {
            if !(c.force.is_finite() && (0.0..=DISPLACEMENT_MAX).contains(&c.force)) {
                return Err(ParamError::Structure {
                    name: "drive_components.force (the component's force at the tip, in [0, 1e6])",
                    value: c.force,
                });
            }
            if !(1..=MAX_RATIO_NUMERATOR).contains(&c.ratio[0])
                || !(1..=MAX_RATIO_DENOMINATOR).contains(&c.ratio[1])
            {
                return Err(ParamError::Structure {
                    name: "drive_components.ratio ([p, q], p in 1..=1000000000, q in 1..=1000000)",
                    value: f64::from(c.ratio[0]) / f64::from(c.ratio[1].max(1)),
                });
            }
            if !c.phase.is_finite() {
                return Err(ParamError::Structure {
                    name: "drive_components.phase (rad, finite)",
                    value: c.phase,
                });
            }
        }
        Ok(())
    }

    /// Amplitude of the base displacement in V_T (eq. 8): α2 for the base-driven beam and for a
    /// moving sample ([`Excitation::Sample`], any structure: the tip–sample distance carries
    /// the same sinusoid), 0 for a force drive (`Params::is_force_driven`: the lumped models,
    /// the beam with [`Excitation::Tip`]), whose base does not move. Every V_T formula uses this.
    pub(crate) fn base_amplitude(&self) -> f64 {
        if self.is_force_driven() {
            0.0
        } else {
            self.alpha2
        }
    }

    /// Whether the primary drive is a force at the tip: the lumped models, and the beam with
    /// [`Excitation::Tip`] (never with [`Excitation::Sample`]).
    pub(crate) fn is_force_driven(&self) -> bool {
        self.excitation != Excitation::Sample
            && (self.structure.is_lumped() || self.excitation == Excitation::Tip)
    }

    /// Whether the sample moves and the lever's frame is at rest ([`Excitation::Sample`]): V_T
    /// carries α2 sin Ωτ, the modal forcing is zero.
    pub(crate) fn is_sample_modulated(&self) -> bool {
        self.excitation == Excitation::Sample
    }

    /// Phase ψ of the drive: the drive is ∝ sin(Ωτ + ψ), ψ = 0 for the base drive (base
    /// displacement α2 sin Ωτ) and π/2 for a force drive (force α2 cos Ωτ). Phases of the response
    /// are measured as lags behind it.
    pub(crate) fn drive_phase(&self) -> f64 {
        if self.is_force_driven() {
            std::f64::consts::FRAC_PI_2
        } else {
            0.0
        }
    }

    /// The rest distance z_c between tip and sample (units of g₀): the tip–sample distance
    /// d = V_T + ã₀ (DMT, [`ContactLaw::distance_offset`]) or d = V_T (other laws) with the
    /// cantilever at rest, V_T = α5. The approach curve's abscissa.
    pub fn rest_distance(&self) -> f64 {
        self.alpha5 + self.contact_law.distance_offset()
    }

    /// α5 that gives the rest distance `z_c` (inverse of [`Params::rest_distance`]).
    pub fn alpha5_for_rest_distance(&self, z_c: f64) -> f64 {
        z_c - self.contact_law.distance_offset()
    }

    /// The state dimension 2N + m of the model of these parameters: N modes and the law's m
    /// internal states ([`crate::ContactLaw::internal_states`]).
    pub(crate) fn state_dim(&self) -> usize {
        2 * self.modes + self.contact_law.internal_states()
    }

    /// The drive period T = 2π/Ω, or for a multifrequency drive its common period
    /// 2π/Ω × [`Params::common_periods`]: the period of the forced system, of its stroboscopic
    /// map and of its periodic orbits.
    pub fn period(&self) -> f64 {
        std::f64::consts::TAU / self.omega * self.common_periods() as f64
    }

    /// The further drive components present ([`Params::drive_components`]).
    pub fn components(&self) -> impl Iterator<Item = &DriveComponent> {
        self.drive_components.iter().flatten()
    }

    /// Whether the drive has further components ([`Params::drive_components`]).
    pub(crate) fn is_multifrequency(&self) -> bool {
        self.components().next().is_some()
    }

    /// The drive's common period in periods 2π/Ω: the least common multiple of the
    /// components' [`DriveComponent::periods`] (1 for a single-frequency drive).
    pub fn common_periods(&self) -> u64 {
        self.components().fold(1, |l, c| {
            let q = c.periods();
            l / gcd(l, q) * q
        })
    }

    /// Σ F̃_i cos(p_i/q_i Ω τ + θ_i), the further components' tip force at τ (0 without them).
    pub(crate) fn component_force(&self, tau: f64) -> f64 {
        self.components()
            .map(|c| c.force * (c.ratio() * self.omega * tau + c.phase).cos())
            .sum()
    }

    /// The drive's components as a lock-in demodulates each: (ω_c, ψ_c), the frequency (per τ)
    /// and the phase of its drive ∝ sin(ω_c τ + ψ_c), the primary first (ψ of
    /// [`Params::drive_phase`]; θ + π/2 for a further component's F̃ cos(ω_c τ + θ)). One entry
    /// for a single-frequency drive.
    pub(crate) fn demodulated(&self) -> Vec<(f64, f64)> {
        let further = self.components().map(|c| {
            let phase = c.phase + std::f64::consts::FRAC_PI_2;
            (c.ratio() * self.omega, phase)
        });
        std::iter::once((self.omega, self.drive_phase()))
            .chain(further)
            .collect()
    }

    /// d/dτ of [`Params::component_force`].
    pub(crate) fn component_force_rate(&self, tau: f64) -> f64 {
        self.components()
            .map(|c| {
                let w = c.ratio() * self.omega;
                -c.force * w * (w * tau + c.phase).sin()
            })
            .sum()
    }

    /// Value of one sweepable parameter.
    pub fn get(&self, p: SweepParam) -> f64 {
        match p {
            SweepParam::Omega => self.omega,
            SweepParam::Alpha1 => self.alpha1,
            SweepParam::Alpha2 => self.alpha2,
            SweepParam::Alpha3 => self.alpha3,
            SweepParam::Alpha4 => self.alpha4,
            SweepParam::Alpha5 => self.alpha5,
            SweepParam::Alpha6 => self.alpha6,
        }
    }

    /// A copy with one sweepable parameter replaced (not validated: call [`Params::validate`]).
    pub fn with(&self, p: SweepParam, value: f64) -> Params {
        let mut q = *self;
        match p {
            SweepParam::Omega => q.omega = value,
            SweepParam::Alpha1 => q.alpha1 = value,
            SweepParam::Alpha2 => q.alpha2 = value,
            SweepParam::Alpha3 => q.alpha3 = value,
            SweepParam::Alpha4 => q.alpha4 = value,
            SweepParam::Alpha5 => q.alpha5 = value,
            SweepParam::Alpha6 => q.alpha6 = value,
        }
        q
    }
}

mod structure;
mod sweep;
pub use structure::{Eigenmodes, Structure};
pub use sweep::SweepParam;
