//! Observables of a steady state: harmonics and phase of the tip deflection, forces, contact
//! statistics, the energy dissipated in the sample, the virial, a per-mode energy balance, and
//! the closed forms of the AFM literature beside the direct integrals.
//!
//! Everything is computed from the integrator's dense output over an integer number of drive
//! periods: on every smooth piece (between steps and events, further cut so that each piece is
//! at most one period of the highest harmonic long and short against the fastest eigenvalue) a
//! 16-point Gauss–Legendre rule integrates each Fourier coefficient and each integral — an
//! 8-point rule on a piece so short that a product of two factors has |c| ≤ 1 below, for which
//! it errs by at most 2.2e-18 (the short steps of the adaptive integrator) — so the results are
//! exact to round-off for the exact propagator and to the interpolant's accuracy otherwise. A
//! Taylor contact step takes its nodes in its own regularising time σ (dτ = 2w dσ, in which the
//! contact force is smooth up to the contact edge; [`crate::integrate::Integrator::smooth_time`]), always with
//! the 16-point rule (the stretch dτ/dσ varies over the step, so the |c| ≤ 1 test in τ does not
//! carry over). (For an
//! integrand analytic in the Bernstein ellipse E_ρ, bounded by M there, the
//! n-point rule errs by at most (64/15) M ρ^{−2n}/(ρ² − 1) relative to the half-length
//! (Trefethen, *Approximation Theory and Approximation Practice*, SIAM 2013, Thm. 19.3). With
//! |λ|h ≤ π for e^{λτ} on a piece of half-length h, and the highest harmonic's Hh ≤ π, every
//! integrand — a product of two such factors — is e^{cx} on [−1, 1] with |c| ≤ 2π, for which
//! ρ = 10.9 and n = 16 bound the error by 2.3e-20 (2.7e-22 of the integral; the rule's error on
//! cos 2πx is 7e-20, in 50-digit arithmetic).) The adaptive integrator's
//! dense output limits the accuracy to about 10³ × its tolerance (measured on the free point
//! mass: 1.2e-9 relative amplitude at 1e-12, 4e-11 at 1e-14). No uniform sampling. Extrema
//! (peak force, minimum distance) are located on the dense output by a
//! safeguarded Newton iteration (`crate::roots`), not taken over quadrature nodes.
//!
//! Units are the model's: time τ (eq. 5), lengths in g₀, forces F̃ of [`crate::contact`] (the
//! unit of α4 V_T; k g₀ for the point-mass model), energies F̃·g₀.
//!
//! # Conventions
//! * **Harmonics.** W(1,τ) ≈ ⟨W⟩ + Σₙ Aₙ sin(n(Ωτ + ψ) − φₙ), ψ = `Params::drive_phase`
//!   (drive ∝ sin(Ωτ + ψ)), so φ = φ₁ is the lag of the deflection behind the drive: 90° at the
//!   free resonance, > 90° in the attractive and < 90° in the repulsive regime (García & San
//!   Paulo, *Phys. Rev. B* 60 (1999) 4961). Phases are reported in (−π/2, 3π/2], so lags near 0
//!   and near π do not wrap.
//! * **Sample dissipation.** E_dis = −∮ F_c ḋ dτ per period, d the tip–sample distance
//!   (ḋ = V̇_T; for the point mass ḋ = ż), plus the kinetic-energy losses of impacts
//!   (`CantileverModel::impact_energy`). Conservative parts of F_c integrate to zero over a
//!   closed orbit, so E_dis > 0 is the energy the sample takes per cycle.
//! * **Virial.** V = (1/T)∫ F_c W(1,τ) dτ (with the impulses P W(τ_k) of impacts), F_c repulsive
//!   positive and W positive away from the sample: V < 0 in the repulsive regime (φ < 90°),
//!   V > 0 in the attractive one (φ > 90°), the sign convention of San Paulo & García, *Phys.
//!   Rev. B* 64 (2001) 193411, where V_cf = −(k A A₀/(2Q)) cos φ.
//!
//! # Exact period balances (point-mass model)
//! With z'' + (1/Q) z' + z = F₀ cos Ωτ + F_c (k = 1, ω₀ = 1, [`crate::params::Structure`]) and
//! z = ⟨z⟩ + Σ Aₙ cos(nΩτ − φₙ) on a periodic orbit:
//! * multiplying by z' and integrating over a period (∮ z''z' = ∮ z z' = 0, and
//!   ∮ z'² = πΩ Σ n²Aₙ² by Parseval):
//!   E_dis = −∮ F_c z' = π F₀ A₁ sin φ − (π/Q) Ω Σₙ n²Aₙ²;
//! * multiplying by z and averaging (⟨z''z⟩ = −⟨z'²⟩, ⟨z z'⟩ = 0, Parseval):
//!   V = ⟨F_c z⟩ = ⟨z⟩² + ½ Σₙ (1 − n²Ω²) Aₙ² − ½ F₀ A₁ cos φ.
//!
//! At the drive frequency of the AFM literature, ω = ω₀, the free amplitude is A₀ = Q F₀/k, and
//! these become the closed forms of Cleveland et al. (*Appl. Phys. Lett.* 72 (1998) 2613) and
//! Anczykowski et al. (*Appl. Surf. Sci.* 140 (1999) 376),
//! E_cf = (π k A²/Q)[(A₀/A) sin φ − ω/ω₀], and of San Paulo & García (2001), V_cf, plus the
//! terms they neglect:
//! E_cf − E_dis = (π k/Q)(ω/ω₀) Σ_{n≥2} n²Aₙ²,   V − V_cf = k⟨z⟩² + (k/2) Σ_{n≥2}(1 − n²ω²/ω₀²)Aₙ².
//! Off resonance, with A₀ the free amplitude at ω (what [`ClosedForms`] uses, F₀ ≠ kA₀/Q),
//! E_cf − E_dis gains π A sin φ (kA₀/Q − F₀) and V − V_cf gains
//! (k/2)(1 − ω²/ω₀²)A² − ½ A cos φ (F₀ − kA₀/Q).
//! The sums over all n ≥ 2 are exact here through Parseval ([`Observables::higher_sq`],
//! [`Observables::higher_n2_sq`]), not truncated at [`ObservableOptions::harmonics`].
//!
//! # Per-mode energy balance
//! Row j of M ä + C ȧ + K a = F^I(τ) + φ F_c (free-region matrices, eqs. 11–14; the contact
//! enters through F_c only) times ȧ_j, integrated over the window:
//! ΔE_j = drive_j − beam_damping_j − sample_j − coupling_j, E_j = ½M_jj ȧ_j² + ½K_jj a_j²,
//! drive_j = ∫F^I_j ȧ_j, beam_damping_j = ∫(Cȧ)_j ȧ_j, sample_j = −∫φ_j F_c ȧ_j (with the
//! impulse P φ_j (ȧ_j⁻ + ȧ_j⁺)/2 of an impact), coupling_j = ∫ȧ_j Σ_{k≠j}(M_jk ä_k + K_jk a_k)
//! (the tip mass α1 couples the modes through M). Σ_j coupling_j is the change of
//! ½ȧᵀM_off ȧ + ½aᵀK_off a: zero over a period of a periodic orbit. Σ_j sample_j = −∮F_c Ẇ
//! differs from E_dis by the work of F_c on the moving base, ∮F_c α2Ω cos Ωτ (beam only).

use super::shooting::PeriodicOrbit;
use crate::contact::{PreparedLaw, TipSample, TipSampleLaw};
use crate::eigen::damped_eigenvalues;
use crate::error::SimError;
use crate::galerkin::{Region, RegionMatrices};
use crate::integrate::{build, Integrator, IntegratorOptions, SwitchEvent};
use crate::model::CantileverModel;
use crate::params::Params;
use crate::roots::{extremum, safeguarded_newton};
use crate::system::EventKind;
use gauss_quad::legendre::GaussLegendre;
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::f64::consts::{PI, TAU};
use std::num::NonZeroUsize;

mod closed;
mod window;
use closed::EquivalentMode;
pub(crate) use closed::{closed_forms, free_response};
use window::{observe_window, Weighting};

/// Largest accepted [`ObservableOptions::periods`].
pub(crate) const MAX_PERIODS: usize = 1_000_000;
/// Largest accepted [`ObservableOptions::harmonics`].
pub(crate) const MAX_HARMONICS: usize = 10_000;
/// Gauss–Legendre nodes per smooth piece.
const GL_NODES: usize = 16;
/// Gauss–Legendre nodes per short smooth piece (module docs).
const GL_NODES_SHORT: usize = 8;
/// 2/3: the Hann² window (2/3)(1 − cos x)² has mean 1 ([`observe_tapered`]).
const TAPER_NORM: f64 = 2.0 / 3.0;

/// What to compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ObservableOptions {
    /// Number of drive periods T = 2π/Ω to integrate over, in 1..=`MAX_PERIODS` (a multiple of
    /// the orbit's period for a period-n orbit).
    pub periods: usize,
    /// Highest harmonic n reported in [`Observables::harmonics`], in 1..=`MAX_HARMONICS`
    /// (default 10).
    pub harmonics: usize,
}

impl Default for ObservableOptions {
    fn default() -> Self {
        ObservableOptions {
            periods: 1,
            harmonics: 10,
        }
    }
}

/// One harmonic of the tip deflection: A_n sin(n(Ωτ + ψ) − φ_n).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Harmonic {
    /// Order n ≥ 1 (multiple of the drive frequency Ω).
    pub n: usize,
    /// Amplitude A_n ≥ 0 (units of g₀).
    pub amplitude: f64,
    /// Lag φ_n behind n(Ωτ + ψ), n times the drive's phase, rad, in (−π/2, 3π/2].
    pub phase: f64,
}

/// Energy balance of one mode, per drive period (energies F̃·g₀; module docs):
/// energy_change = drive − beam_damping − sample − coupling + residual.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModeBalance {
    /// Mode index j (0-based).
    pub mode: usize,
    /// ∫F^I_j ȧ_j dτ: work of the drive (eq. 14) on mode j.
    pub drive: f64,
    /// ∫(C^I ȧ)_j ȧ_j dτ: beam damping (eq. 12).
    pub beam_damping: f64,
    /// −∫φ_j F_c ȧ_j dτ (with impulses): energy mode j gives to the tip–sample force.
    pub sample: f64,
    /// ∫ȧ_j Σ_{k≠j}(M_jk ä_k + K_jk a_k) dτ: energy mode j passes to the other modes.
    pub coupling: f64,
    /// Change of E_j = ½M_jj ȧ_j² + ½K_jj a_j² over the window (0 on a periodic orbit).
    pub energy_change: f64,
    /// energy_change − (drive − beam_damping − sample − coupling): round-off.
    pub residual: f64,
}

/// The free linear response of the tip at the drive frequency: W = A₀ sin(Ωτ + ψ − φ₀).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct FreeResponse {
    /// Free amplitude A₀ = |φᵀ(K − Ω²M + iΩC)⁻¹(F_s + iF_c)| (units of g₀).
    pub amplitude: f64,
    /// Lag φ₀ behind the drive, rad, in (−π/2, 3π/2].
    pub phase: f64,
}

/// The closed forms of the AFM literature from (A, φ, A₀, Q, k), evaluated for the
/// mode-1 equivalent point mass (module docs). Exact balances only for the point-mass model at
/// ω = ω₀; elsewhere an approximation, reported to show how far it is off.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ClosedForms {
    /// A₀: free tip amplitude at Ω from the linear free response (`free_response`), g₀.
    pub free_amplitude: f64,
    /// Lag of the free response behind the drive, rad.
    pub free_phase: f64,
    /// Q of mode 1, 1/(2ζ₁) from its damped eigenvalue (eqs. 20–21); 1/α3 for the point mass.
    pub quality_factor: f64,
    /// ω₀: undamped natural frequency of mode 1 (units of the τ scale; 1 for the point mass).
    pub natural_frequency: f64,
    /// k̃ = ω₁²/(φᵀx₁)², x₁ the mass-normalised mode 1: the stiffness of the equivalent point
    /// mass at the tip (Melcher, Hu & Raman, *Appl. Phys. Lett.* 91 (2007) 053101); 1 for the
    /// point mass. Units F̃/g₀.
    pub stiffness: f64,
    /// F₀ = k̃ A₀ √((1 − Ω²/ω₀²)² + (Ω/(ω₀Q))²): the harmonic force that gives A₀ in the
    /// equivalent oscillator (α2 for the point mass).
    pub drive_force: f64,
    /// Cleveland/Anczykowski E_cf = (π k A²/Q)[(A₀/A) sin φ − Ω/ω₀] per period.
    pub energy_dissipated: f64,
    /// San Paulo & García V_cf = −(k A A₀/(2Q)) cos φ.
    pub virial: f64,
}

/// Observables of a steady state over an integer number of drive periods. Lengths in g₀, time
/// τ, forces F̃, energies F̃·g₀ (module docs for conventions and sources).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Observables {
    /// Number of drive periods integrated over.
    pub periods: usize,
    /// A₁: first-harmonic amplitude of the tip deflection W(1,τ) (point mass: z).
    pub amplitude: f64,
    /// φ = φ₁: lag of the deflection behind the drive, rad, in (−π/2, 3π/2]; in [0, π] for a
    /// driven damped response.
    pub phase: f64,
    /// Harmonics n = 1..=[`ObservableOptions::harmonics`].
    pub harmonics: Vec<Harmonic>,
    /// Total harmonic distortion √(Σ_{n≥2} A_n²)/A₁ over all n (Parseval, [`Self::higher_sq`];
    /// NaN when A₁ = 0).
    pub thd: f64,
    /// ⟨W⟩: mean deflection.
    pub mean_deflection: f64,
    /// Σ_{n≥2} A_n² over all n = 2(⟨W²⟩ − ⟨W⟩²) − A₁² (Parseval).
    pub higher_sq: f64,
    /// Σ_{n≥2} n² A_n² over all n = 2⟨Ẇ²⟩/Ω² − A₁² (Parseval; ⟨Ẇ⟩ = 0 on a periodic orbit).
    pub higher_n2_sq: f64,
    /// ⟨F_c⟩: time-averaged tip–sample force (with impulses); for the point mass the static
    /// balance gives ⟨z⟩ = ⟨F_c⟩/k on a periodic orbit.
    pub mean_force: f64,
    /// Largest finite F_c (repulsive positive; impulses of the impact law excluded).
    pub peak_force: f64,
    /// Smallest F_c (the largest attraction when negative).
    pub min_force: f64,
    /// Largest indentation max(−V_T, 0).
    pub indentation: f64,
    /// Fraction of the time in contact (V_T ≤ 0; sticking for the impact law).
    pub contact_fraction: f64,
    /// Time in contact per drive period, τ.
    pub contact_time: f64,
    /// Minimum tip–sample distance d = V_T + [`crate::ContactLaw::distance_offset`].
    pub min_distance: f64,
    /// Entries into contact per period (smooth laws), or impacts per period including the
    /// plastic one that starts sticking (impact law).
    pub impacts_per_period: f64,
    /// E_dis = −∮F_c ḋ dτ + impact losses, per period.
    pub energy_dissipated: f64,
    /// Of which the kinetic-energy losses of impacts, per period.
    pub impact_loss: f64,
    /// V = (1/T)∫F_c W(1,τ) dτ (with impulses).
    pub virial: f64,
    /// Per-mode energy balance, per period, one entry per mode.
    pub mode_balance: Vec<ModeBalance>,
    /// Per eigenmode k of the free cantilever (ascending frequency), the amplitude of the tip
    /// deflection it carries, w_k = (φᵀx_k) x_kᵀM a (x_k mass-normalised, Σ_k w_k = W): the
    /// RMS amplitude √(2(⟨w_k²⟩ − ⟨w_k⟩²)), which is A for w_k = A sin(…). The participation
    /// of the higher modes in tapping, strongest in liquid where every tap excites them
    /// (Basak & Raman, *Appl. Phys. Lett.* 91 (2007) 064107); one entry per mode.
    #[serde(default)]
    pub mode_amplitudes: Vec<f64>,
    /// The closed forms from (A, φ, A₀, Q, k).
    pub closed_form: ClosedForms,
    /// Per drive component of a multifrequency drive, the primary first (empty for a
    /// single-frequency drive; [`crate::params::Params::drive_components`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub components: Vec<ComponentObservables>,
}

/// The observables of one component of a multifrequency drive (frequency ω_c = r Ω, drive
/// ∝ sin(ω_c τ + ψ_c): ψ_c = ψ for the primary, θ + π/2 for a further component's
/// F̃ cos(ω_c τ + θ)). The tip's motion at ω_c, demodulated over the window (an integer number
/// of periods of every component), is z_c(τ) = A_c sin(ω_c τ + ψ_c − φ_c); the component's
/// virial and dissipated energy are those of the tip–sample force on that motion,
/// V_c = ⟨F_c z_c⟩ and E_c = −∮F_c ż_c dτ per cycle of the component — the per-mode virial
/// and dissipation of bimodal AFM (Lozano & García, *Phys. Rev. Lett.* 100 (2008) 076102;
/// García & Proksch, *Eur. Polym. J.* 49 (2013) 1897), each mode moving at its own drive
/// frequency. Their closed forms, from the equivalent point mass of the mode whose natural
/// frequency is nearest ω_c (k̃, Q, ω₀) and the component's free amplitude A₀c:
/// E_cf = (π k̃ A_c²/Q)[(A₀c/A_c) sin φ_c − ω_c/ω₀], V_cf = −(k̃ A_c A₀c/(2Q)) cos φ_c, which
/// for the point mass at ω_c = ω₀ are exact balances (projecting z'' + z'/Q + z = F + F_c on
/// ż_c and z_c), elsewhere approximations reported beside the direct integrals.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ComponentObservables {
    /// ω_c/Ω (p/q; 1 for the primary).
    pub ratio: f64,
    /// A_c (g₀).
    pub amplitude: f64,
    /// φ_c, the lag behind the component's drive, rad, in (−π/2, 3π/2].
    pub phase: f64,
    /// A₀c, the free amplitude at ω_c (g₀).
    pub free_amplitude: f64,
    /// The free response's lag at ω_c, rad.
    pub free_phase: f64,
    /// V_c = ⟨F_c z_c⟩ (F̃·g₀), impulses included.
    pub virial: f64,
    /// E_c = −∮F_c ż_c per cycle of the component (F̃·g₀), impulses included.
    pub energy_dissipated: f64,
    /// The mode (0-based) whose equivalent point mass the closed forms use.
    pub mode: usize,
    /// V_cf = −(k̃ A_c A₀c/(2Q)) cos φ_c.
    pub closed_virial: f64,
    /// E_cf = (π k̃ A_c²/Q)[(A₀c/A_c) sin φ_c − ω_c/ω₀] per cycle.
    pub closed_energy_dissipated: f64,
}

/// A phase in (−π/2, 3π/2].
pub(crate) fn wrap_phase(p: f64) -> f64 {
    let mut x = p.rem_euclid(TAU);
    if x > 1.5 * PI {
        x -= TAU;
    }
    x
}

/// Observables over `opts.periods` drive periods starting at the integrator's current (τ, z),
/// assumed on the steady state; τ need not be a multiple of T. The integrator is left at the
/// end of the window.
///
/// # Errors
/// [`SimError::OutOfRange`] for `periods` outside 1..=`MAX_PERIODS` or `harmonics` outside
/// 1..=`MAX_HARMONICS`, or from [`free_response`]; [`SimError`] from the integrator.
pub(crate) fn observe(
    integ: &mut dyn Integrator,
    opts: &ObservableOptions,
) -> Result<Observables, SimError> {
    observe_window(integ, opts, Weighting::Flat)
}

/// Observables over `opts.periods` primary drive periods 2π/Ω from the integrator's current
/// (τ₀, z), every integral weighted by the Hann² window w(τ) = (2/3)(1 − cos x)², x =
/// 2π(τ − τ₀)/L over the window's length L (the cos⁴ window of Harris, *Proc. IEEE* 66 (1978)
/// 51, §5.1, α = 4; mean 1, so the averages keep their meaning): the time average of a motion
/// that is not periodic over the window — a quasi-periodic drive
/// ([`crate::params::Params::is_quasiperiodic`]), or a window that is no multiple of a
/// multifrequency drive's common period. A component Δω away from a demodulated frequency
/// leaks into it as (ΔωL)⁻⁵ (w and its first three derivatives vanish at the ends) instead of
/// the rectangular window's (ΔωL)⁻¹: a component 10× the demodulated one and 84 bins (ΔωL/2π)
/// away leaks 2.4e-9 of it, where the Hann window's (ΔωL)⁻³ leaked 4.3e-6 (the windows'
/// transforms, evaluated numerically). Extremes (peak force,
/// indentation, minimum distance) and the count of impacts are over the window, unweighted;
/// the per-mode balance stays exact, with [`ModeBalance::energy_change`] = ∫w dE_j =
/// −∫w′E_j dτ (0 on a steady state). Per-period quantities are per primary period.
///
/// # Errors
/// As [`observe`].
pub(crate) fn observe_tapered(
    integ: &mut dyn Integrator,
    opts: &ObservableOptions,
) -> Result<Observables, SimError> {
    observe_window(integ, opts, Weighting::Hann)
}

/// Observables over `opts.periods` = M primary drive periods 2π/Ω from the integrator's current
/// (τ₀, z), the integrals over period k weighted by M·`weights[k]` (weights summing to 1): the
/// average over an invariant circle from the M periods of its collocation segment, with the
/// circle's quadrature weights q_k ([`crate::maps::circle::CircleNodes::quadrature`]; each
/// integrand's average over the torus is Σ_k q_k times its average over period k, the change
/// of variables (θ₁, θ₂) = (Ωτ, θ_k + rΩτ) having a unit Jacobian). The per-mode balance's
/// energy change is Σ_k M q_k (E_j(end of k) − E_j(start of k)), 0 on the circle up to its
/// quadrature's error; extremes are over the M periods, unweighted.
///
/// # Errors
/// As [`observe`]; [`SimError::OutOfRange`] when `weights` is not one finite weight per period.
pub(crate) fn observe_weighted(
    integ: &mut dyn Integrator,
    opts: &ObservableOptions,
    weights: &[f64],
) -> Result<Observables, SimError> {
    let m = weights.len() as f64;
    observe_window(
        integ,
        opts,
        Weighting::Steps(weights.iter().map(|w| w * m).collect()),
    )
}

/// [`observe`] from a start state: builds the integrator of `model` with `integ` at (τ₀, z₀).
///
/// # Errors
/// As [`build`] and [`observe`].
pub(crate) fn observe_from(
    model: &CantileverModel,
    integ: IntegratorOptions,
    tau0: f64,
    z0: &DVector<f64>,
    opts: &ObservableOptions,
) -> Result<Observables, SimError> {
    let mut it = build(model, integ, tau0, z0)?;
    observe(it.as_mut(), opts)
}

/// `observe_from` on a periodic orbit found by shooting ([`super::shooting`]): from its state
/// at τ = 0 over its n drive periods, harmonics up to `harmonics`.
///
/// # Errors
/// As `observe_from`.
pub fn observe_orbit(
    model: &CantileverModel,
    integ: IntegratorOptions,
    orbit: &PeriodicOrbit,
    harmonics: usize,
) -> Result<Observables, SimError> {
    let opts = ObservableOptions {
        periods: orbit.period,
        harmonics,
    };
    observe_from(model, integ, 0.0, &orbit.state, &opts)
}
