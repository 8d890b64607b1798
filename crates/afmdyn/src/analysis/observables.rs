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
//! safeguarded Newton iteration ([`crate::roots`]), not taken over quadrature nodes.
//!
//! Units are the model's: time τ (eq. 5), lengths in g₀, forces F̃ of [`crate::contact`] (the
//! unit of α4 V_T; k g₀ for the point-mass model), energies F̃·g₀.
//!
//! # Conventions
//! * **Harmonics.** W(1,τ) ≈ ⟨W⟩ + Σₙ Aₙ sin(n(Ωτ + ψ) − φₙ), ψ = [`Params::drive_phase`]
//!   (drive ∝ sin(Ωτ + ψ)), so φ = φ₁ is the lag of the deflection behind the drive: 90° at the
//!   free resonance, > 90° in the attractive and < 90° in the repulsive regime (García & San
//!   Paulo, *Phys. Rev. B* 60 (1999) 4961). Phases are reported in (−π/2, 3π/2], so lags near 0
//!   and near π do not wrap.
//! * **Sample dissipation.** E_dis = −∮ F_c ḋ dτ per period, d the tip–sample distance
//!   (ḋ = V̇_T; for the point mass ḋ = ż), plus the kinetic-energy losses of impacts
//!   ([`CantileverModel::impact_energy`]). Conservative parts of F_c integrate to zero over a
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
use crate::contact::{TipSample, TipSampleLaw};
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

/// Largest accepted [`ObservableOptions::periods`].
pub const MAX_PERIODS: usize = 1_000_000;
/// Largest accepted [`ObservableOptions::harmonics`].
pub const MAX_HARMONICS: usize = 10_000;
/// Gauss–Legendre nodes per smooth piece.
const GL_NODES: usize = 16;
/// Gauss–Legendre nodes per short smooth piece (module docs).
const GL_NODES_SHORT: usize = 8;
/// 2/3: the Hann² window (2/3)(1 − cos x)² has mean 1 ([`observe_tapered`]).
const TAPER_NORM: f64 = 2.0 / 3.0;

/// What to compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ObservableOptions {
    /// Number of drive periods T = 2π/Ω to integrate over, in 1..=[`MAX_PERIODS`] (a multiple of
    /// the orbit's period for a period-n orbit).
    pub periods: usize,
    /// Highest harmonic n reported in [`Observables::harmonics`], in 1..=[`MAX_HARMONICS`]
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
pub struct FreeResponse {
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
    /// A₀: free tip amplitude at Ω from the linear free response ([`free_response`]), g₀.
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

/// The free linear response of the tip at the drive frequency Ω, from the model's complex
/// amplitude H ([`CantileverModel::free_tip_response`], W(1,τ) = Im(H e^{i(Ωτ + ψ)})):
/// A₀ = |H|, lag φ₀ = −arg H. The one place the free amplitude of the closed forms comes from.
///
/// # Errors
/// [`SimError::OutOfRange`] when Ω is at an undamped natural frequency (no steady state).
pub fn free_response(model: &CantileverModel) -> Result<FreeResponse, SimError> {
    let h = model.free_tip_response()?;
    Ok(FreeResponse {
        amplitude: h.norm(),
        phase: wrap_phase(-h.arg()),
    })
}

/// The closed forms of `model` for a first-harmonic tip amplitude `a` (g₀) and lag `phase`
/// (rad) (see [`ClosedForms`]; k̃, Q, ω₀ and A₀ depend on the model only).
///
/// # Errors
/// As [`free_response`].
pub fn closed_forms(model: &CantileverModel, a: f64, phase: f64) -> Result<ClosedForms, SimError> {
    let free = free_response(model)?;
    let m = EquivalentMode::of(model, 0);
    let (k, q) = (m.stiffness, m.quality_factor);
    let r = model.omega() / m.natural_frequency;
    let a0 = free.amplitude;
    Ok(ClosedForms {
        free_amplitude: a0,
        free_phase: free.phase,
        quality_factor: q,
        natural_frequency: m.natural_frequency,
        stiffness: k,
        drive_force: k * a0 * ((1.0 - r * r).powi(2) + (r / q).powi(2)).sqrt(),
        energy_dissipated: m.energy_dissipated(a, a0, phase, model.omega()),
        virial: m.virial(a, a0, phase),
    })
}

/// The equivalent point mass of one mode at the tip: ω₀, k̃ ([`crate::eigen::mode_at_tip`]) and
/// Q = 1/(2ζ) of its damped eigenvalue — what the closed forms of the AFM literature take.
struct EquivalentMode {
    natural_frequency: f64,
    stiffness: f64,
    quality_factor: f64,
}

impl EquivalentMode {
    /// Mode `mode` (0-based) of `model`; Q from the mode-th underdamped eigenvalue (for mode 1
    /// the first eigenvalue when none is underdamped; ∞ without one).
    fn of(model: &CantileverModel, mode: usize) -> Self {
        let g = model.galerkin().region(Region::Free);
        let (w0, _, k) = crate::eigen::mode_at_tip(g, model.tip(), mode);
        let eig = damped_eigenvalues(g);
        let under = eig.iter().filter(|e| e.im > 0.0).nth(mode);
        let e = if mode == 0 {
            under.or(eig.first())
        } else {
            under
        };
        EquivalentMode {
            natural_frequency: w0,
            stiffness: k,
            quality_factor: e.map_or(f64::INFINITY, |e| 0.5 / e.zeta),
        }
    }

    /// Cleveland/Anczykowski E_cf = (π k A²/Q)[(A₀/A) sin φ − ω/ω₀] per cycle at frequency ω
    /// (module docs).
    fn energy_dissipated(&self, a: f64, a0: f64, phase: f64, omega: f64) -> f64 {
        let r = omega / self.natural_frequency;
        PI * self.stiffness / self.quality_factor * (a * a0 * phase.sin() - r * a * a)
    }

    /// San Paulo & García V_cf = −(k A A₀/(2Q)) cos φ (module docs).
    fn virial(&self, a: f64, a0: f64, phase: f64) -> f64 {
        -self.stiffness * a * a0 / (2.0 * self.quality_factor) * phase.cos()
    }
}

/// A phase in (−π/2, 3π/2].
pub(crate) fn wrap_phase(p: f64) -> f64 {
    let mut x = p.rem_euclid(TAU);
    if x > 1.5 * PI {
        x -= TAU;
    }
    x
}

/// Values of the dense output at one τ of a smooth piece.
struct Node {
    /// τ.
    tau: f64,
    /// State (a, ȧ), shape `[2N]`.
    z: DVector<f64>,
    /// Its vector field (ȧ, ä), shape `[2N]`.
    dz: DVector<f64>,
    /// W(1,τ) and ∂W/∂τ.
    w: f64,
    wd: f64,
    /// [V_T, V̇_T, V̈_T].
    v: [f64; 3],
    /// F_c.
    f: f64,
    /// (sin Ωτ, cos Ωτ).
    sc: (f64, f64),
}

/// What [`observe`] needs of the model, computed once.
struct Ctx {
    model: CantileverModel,
    law: TipSample,
    free: RegionMatrices,
    tip: DVector<f64>,
    /// Row k: (φᵀx_k) x_kᵀM, the tip deflection carried by eigenmode k of the free region
    /// (x_k mass-normalised, [`crate::eigen::natural_modes`]) at modal coordinates a; the rows
    /// sum to φᵀ (Σ_k x_k x_kᵀ M = I).
    participation: DMatrix<f64>,
    omega: f64,
    /// (sin ψ, cos ψ) of the drive phase ψ.
    psi: (f64, f64),
    /// The drive components of a multifrequency drive, the primary first: (ω_c, ψ_c) (empty
    /// for one frequency; [`ComponentObservables`]).
    components: Vec<(f64, f64)>,
    /// Gauss–Legendre nodes and weights on [−1, 1], ascending: [`GL_NODES`] of them, and
    /// [`GL_NODES_SHORT`].
    gl: [Vec<(f64, f64)>; 2],
    /// Longest smooth piece in each region (free, contact).
    h_max: [f64; 2],
    /// |c| per unit half-length of a product of two integrand factors in each region,
    /// ρ + max(ρ, HΩ) with ρ the region's fastest |λ| and H the highest harmonic.
    product_rate: [f64; 2],
    /// The tapered window's start τ₀ and angular rate κ = 2π/L over the window's length L
    /// ([`observe_tapered`]); `None`: every weight 1.
    taper: Option<(f64, f64)>,
}

impl Ctx {
    fn new(model: &CantileverModel, harmonics: usize) -> Self {
        let p = model.params();
        // pieces short against the highest harmonic (one period of it) and the region's fastest
        // eigenvalue (|λ| h ≤ π on the half-length h), so each GL rule integrates to round-off
        // (module docs)
        let rho = [Region::Free, Region::Contact].map(|r| {
            model
                .dynamics(r)
                .a
                .complex_eigenvalues()
                .iter()
                .fold(0.0f64, |m, l| m.max(l.norm()))
        });
        let components: Vec<(f64, f64)> = if p.is_multifrequency() {
            std::iter::once((p.omega, p.drive_phase()))
                .chain(
                    p.components()
                        .map(|c| (c.ratio() * p.omega, c.phase + std::f64::consts::FRAC_PI_2)),
                )
                .collect()
        } else {
            Vec::new()
        };
        // the highest frequency: the highest harmonic of Ω, or a faster drive component
        let top = components
            .iter()
            .fold(harmonics as f64 * p.omega, |m, c| m.max(c.0));
        let h_max = rho.map(|rho| (TAU / top).min(TAU / rho.max(1e-300)));
        let product_rate = rho.map(|rho| rho + rho.max(top));
        let gl = [GL_NODES, GL_NODES_SHORT].map(|n| {
            let mut gl: Vec<(f64, f64)> = GaussLegendre::new(NonZeroUsize::new(n).expect("> 0"))
                .iter()
                .map(|(x, w)| (*x, *w))
                .collect();
            gl.sort_by(|a, b| a.0.total_cmp(&b.0));
            gl
        });
        Ctx {
            model: model.clone(),
            law: TipSample {
                law: p.contact_law,
                stiffness: p.alpha4,
                damping: p.alpha6,
            },
            free: model.galerkin().region(Region::Free).clone(),
            tip: model.tip().clone(),
            participation: {
                let free = model.galerkin().region(Region::Free);
                let x = crate::eigen::natural_modes(free).vectors;
                let scale = model.tip().transpose() * &x;
                DMatrix::from_diagonal(&scale.transpose()) * x.transpose() * &free.mass
            },
            omega: p.omega,
            psi: p.drive_phase().sin_cos(),
            components,
            gl,
            h_max,
            product_rate,
            taper: None,
        }
    }

    /// The window's weight w(τ): 1, or the Hann² window (2/3)(1 − cos x)², x = κ(τ − τ₀)
    /// (mean 1 over the window; it and its first three derivatives vanish at the ends).
    fn weight(&self, tau: f64) -> f64 {
        match self.taper {
            Some((t0, k)) => {
                let c = 1.0 - (k * (tau - t0)).cos();
                TAPER_NORM * c * c
            }
            None => 1.0,
        }
    }

    /// dw/dτ (0 without a window): (4/3)κ(1 − cos x) sin x.
    fn weight_rate(&self, tau: f64) -> f64 {
        match self.taper {
            Some((t0, k)) => {
                let (s, c) = (k * (tau - t0)).sin_cos();
                2.0 * TAPER_NORM * k * (1.0 - c) * s
            }
            None => 0.0,
        }
    }

    /// ∫ₐᵇ w dτ, in closed form: (2/3)∫(1 − cos x)² dx = x − (4/3) sin x + (1/6) sin 2x over κ.
    fn weighted_length(&self, a: f64, b: f64) -> f64 {
        match self.taper {
            Some((t0, k)) => {
                let f = |t: f64| {
                    let x = k * (t - t0);
                    x - 4.0 / 3.0 * x.sin() + (2.0 * x).sin() / 6.0
                };
                (f(b) - f(a)) / k
            }
            None => b - a,
        }
    }

    /// The dense output of the last step (region `r`) at τ: V_T, W and F_c from one sine and
    /// cosine of Ωτ, which the harmonics and the drive's work reuse.
    fn node(&self, integ: &mut dyn Integrator, r: Region, tau: f64) -> Node {
        let n = self.model.modes();
        let z = integ.dense_state(tau);
        let mut dz = DVector::zeros(z.len());
        self.model.rhs(r, tau, &z, &mut dz);
        let sc = (self.omega * tau).sin_cos();
        let [_, w, wd, f] = self.model.sample_values(r, tau, sc, z.as_slice());
        let wdd = self.tip.dot(&dz.rows(n, n));
        let v = self.model.v_t_at(sc, [w, wd, wdd]);
        Node {
            tau,
            z,
            dz,
            w,
            wd,
            v,
            f,
            sc,
        }
    }

    /// dF_c/dτ at `nd` (τ = `t` in the piece [lo, hi]): analytic for the smooth laws
    /// ([`force_rate`]) and the SLS sample ((α4 + κ)δ̇ − κu̇ in contact), a central difference
    /// inside the piece for the sticking force of the impact law (only the extremum's location
    /// depends on it, its value to second order).
    fn rate(
        &self,
        integ: &mut dyn Integrator,
        r: Region,
        t: f64,
        nd: &Node,
        lo: f64,
        hi: f64,
    ) -> f64 {
        if let Some(zn) = self.model.zener() {
            // F = (α4 + κ)δ − κu: its rate from δ̇ = −V̇_T and u̇ (the state's last rate)
            return if r == Region::Contact {
                let u_dot = nd.dz[nd.dz.len() - 1];
                -(zn.relaxed + zn.maxwell) * nd.v[1] - zn.maxwell * u_dot
            } else {
                0.0
            };
        }
        if r != Region::Contact || self.law.law.restitution().is_none() {
            return force_rate(&self.law, r, nd);
        }
        let h = 1e-5 * (hi - lo);
        let (tm, tp) = ((t - h).max(lo), (t + h).min(hi));
        (self.node(integ, r, tp).f - self.node(integ, r, tm).f) / (tp - tm)
    }
}

/// Σ_{k≠j} m_jk x_k.
fn off_diagonal(m: &DMatrix<f64>, j: usize, x: &[f64]) -> f64 {
    m.row(j).iter().zip(x).map(|(a, b)| a * b).sum::<f64>() - m[(j, j)] * x[j]
}

/// Buffers of [`Acc::piece`]: the drive F^I at a node, the scan of a piece's nodes, and the
/// last piece's end node (τ, dF_c/dτ, dV_T/dτ), which starts the next piece of the same step.
struct Scratch {
    fi: DVector<f64>,
    scan: Vec<(f64, f64, f64)>,
    start: Option<(f64, f64, f64)>,
}

/// Running integrals of [`observe`] (over the whole window; divided at the end).
struct Acc {
    mean: f64,
    w2: f64,
    wd2: f64,
    cos: Vec<f64>,
    sin: Vec<f64>,
    e_dis: f64,
    impact_loss: f64,
    virial: f64,
    force: f64,
    contact_time: f64,
    impacts: usize,
    drive: Vec<f64>,
    damp: Vec<f64>,
    sample: Vec<f64>,
    coupling: Vec<f64>,
    f_max: f64,
    f_min: f64,
    v_min: f64,
    /// Per drive component: ∫W sin θ_c, ∫W cos θ_c, ∫F_c sin θ_c, ∫F_c cos θ_c with
    /// θ_c = ω_c τ + ψ_c (impulses P sin θ_c, P cos θ_c in the force's).
    comp: Vec<[f64; 4]>,
    /// Per mode, ∫w′E_j dτ under a window (E_j of [`ModeBalance::energy_change`]).
    energy_rate: Vec<f64>,
    /// Per eigenmode k, ∫w_k and ∫w_k² (w_k its tip deflection, `Ctx::participation`).
    eigen_mean: Vec<f64>,
    eigen_sq: Vec<f64>,
}

impl Acc {
    fn new(modes: usize, harmonics: usize) -> Self {
        Acc {
            mean: 0.0,
            w2: 0.0,
            wd2: 0.0,
            cos: vec![0.0; harmonics],
            sin: vec![0.0; harmonics],
            e_dis: 0.0,
            impact_loss: 0.0,
            virial: 0.0,
            force: 0.0,
            contact_time: 0.0,
            impacts: 0,
            drive: vec![0.0; modes],
            damp: vec![0.0; modes],
            sample: vec![0.0; modes],
            coupling: vec![0.0; modes],
            f_max: f64::NEG_INFINITY,
            f_min: f64::INFINITY,
            v_min: f64::INFINITY,
            comp: Vec::new(),
            energy_rate: vec![0.0; modes],
            eigen_mean: vec![0.0; modes],
            eigen_sq: vec![0.0; modes],
        }
    }

    /// Extremes over a point of the dense output.
    fn extremes(&mut self, f: f64, v_t: f64) {
        self.f_max = self.f_max.max(f);
        self.f_min = self.f_min.min(f);
        self.v_min = self.v_min.min(v_t);
    }

    /// One quadrature node at τ with weight `wq` (every integrand of the module docs).
    fn quadrature(&mut self, ctx: &Ctx, wq: f64, nd: &Node, fi: &mut DVector<f64>) {
        let n = ctx.tip.len();
        if ctx.taper.is_some() {
            // ∫w dE_j = −∫w′E_j for w vanishing at the window's ends (module docs)
            let wr = wq * ctx.weight_rate(nd.tau);
            let z = nd.z.as_slice();
            for (j, acc) in self.energy_rate.iter_mut().enumerate() {
                let e = 0.5 * ctx.free.mass[(j, j)] * z[n + j] * z[n + j]
                    + 0.5 * ctx.free.stiffness[(j, j)] * z[j] * z[j];
                *acc += wr * e;
            }
        }
        let wq = wq * ctx.weight(nd.tau);
        self.mean += wq * nd.w;
        self.w2 += wq * nd.w * nd.w;
        self.wd2 += wq * nd.wd * nd.wd;
        // sin and cos of h(Ωτ + ψ), h = 1, 2, …: the angle sum from those of Ωτ and ψ, then
        // the rotation by Ωτ + ψ (its error grows like h ulps, as the argument h(Ωτ + ψ)'s own)
        let ((s, c), (sp, cp)) = (nd.sc, ctx.psi);
        let (s1, c1) = (s * cp + c * sp, c * cp - s * sp);
        let (mut sh, mut ch) = (s1, c1);
        for (sin, cos) in self.sin.iter_mut().zip(self.cos.iter_mut()) {
            *sin += wq * nd.w * sh;
            *cos += wq * nd.w * ch;
            (sh, ch) = (sh * c1 + ch * s1, ch * c1 - sh * s1);
        }
        let a_now = nd.z.rows(0, n);
        for k in 0..n {
            let wk = ctx.participation.row(k).dot(&a_now.transpose());
            self.eigen_mean[k] += wq * wk;
            self.eigen_sq[k] += wq * wk * wk;
        }
        self.e_dis -= wq * nd.f * nd.v[1];
        self.virial += wq * nd.f * nd.w;
        self.force += wq * nd.f;
        for (acc, &(om, psi)) in self.comp.iter_mut().zip(&ctx.components) {
            let (st, ct) = (om * nd.tau + psi).sin_cos();
            acc[0] += wq * nd.w * st;
            acc[1] += wq * nd.w * ct;
            acc[2] += wq * nd.f * st;
            acc[3] += wq * nd.f * ct;
        }
        // the drive F^I(τ) (eq. 14) from the node's sin and cos of Ωτ, and the further drive
        // components' force at the tip
        let forcing = &ctx.free.forcing;
        let tip_force = ctx.model.params().component_force(nd.tau);
        for (j, o) in fi.iter_mut().enumerate() {
            *o = forcing.constant[j]
                + s * forcing.sin[j]
                + c * forcing.cos[j]
                + tip_force * ctx.tip[j];
        }
        let (a, ad, add) = (
            &nd.z.as_slice()[..n],
            &nd.z.as_slice()[n..2 * n],
            &nd.dz.as_slice()[n..2 * n],
        );
        for j in 0..n {
            let aj = ad[j];
            self.drive[j] += wq * fi[j] * aj;
            self.damp[j] += wq
                * ctx
                    .free
                    .damping
                    .row(j)
                    .iter()
                    .zip(ad)
                    .map(|(c, v)| c * v)
                    .sum::<f64>()
                * aj;
            self.sample[j] -= wq * ctx.tip[j] * nd.f * aj;
            let c = off_diagonal(&ctx.free.mass, j, add) + off_diagonal(&ctx.free.stiffness, j, a);
            self.coupling[j] += wq * aj * c;
        }
    }

    /// The smooth piece [a, b] of the last step (region `r`): quadrature, and the extremes of
    /// F_c and V_T at its ends, its nodes and the interior extrema located between them. The
    /// node at a is the end node of the piece before when it ended there (`scratch.start`).
    fn piece(
        &mut self,
        ctx: &Ctx,
        integ: &mut dyn Integrator,
        r: Region,
        (a, b): (f64, f64),
        scratch: &mut Scratch,
    ) {
        let half = 0.5 * (b - a);
        // (τ, dF_c/dτ, dV_T/dτ) at the ends and the GL nodes, in order; the nodes in the
        // step's own smooth time ([`crate::integrate::Integrator::smooth_time`]; τ itself but for the Taylor
        // integrator's contact steps)
        let scan = &mut scratch.scan;
        scan.clear();
        match scratch.start.take() {
            Some(start) if start.0 == a => scan.push(start),
            _ => {
                let nd = ctx.node(integ, r, a);
                self.extremes(nd.f, nd.v[0]);
                scan.push((a, ctx.rate(integ, r, a, &nd, a, b), nd.v[1]));
            }
        }
        // the short rule where a product of two factors has |c| ≤ 1 on the piece (module docs),
        // τ being the smooth time: a regularising time stretches the piece's rates unevenly
        let short = integ.smooth_time().is_none() && half * ctx.product_rate[r.index()] <= 1.0;
        for &(x, wx) in &ctx.gl[usize::from(short)] {
            let (tau, dtau) = crate::integrate::smooth_time(integ, a, b, 0.5 * (x + 1.0));
            let nd = ctx.node(integ, r, tau);
            self.quadrature(ctx, 0.5 * wx * dtau, &nd, &mut scratch.fi);
            self.extremes(nd.f, nd.v[0]);
            scan.push((tau, ctx.rate(integ, r, tau, &nd, a, b), nd.v[1]));
        }
        let nd = ctx.node(integ, r, b);
        self.extremes(nd.f, nd.v[0]);
        scan.push((b, ctx.rate(integ, r, b, &nd, a, b), nd.v[1]));
        scratch.start = scan.last().copied();
        for pair in scan.windows(2) {
            let ((ta, fda, vda), (tb, fdb, vdb)) = (pair[0], pair[1]);
            if (fda > 0.0) != (fdb > 0.0) {
                let mut g = |t: f64| {
                    let nd = ctx.node(integ, r, t);
                    ctx.rate(integ, r, t, &nd, a, b)
                };
                let t = root_of(ta, fda, tb, fdb, &mut g);
                let nd = ctx.node(integ, r, t);
                self.extremes(nd.f, nd.v[0]);
            }
            if vda < 0.0 && vdb > 0.0 {
                let mut vt = |t: f64| integ.dense_v_t(t);
                let t = extremum(ta, tb, vda, &mut vt);
                self.v_min = self.v_min.min(vt(t)[0]);
            }
        }
    }

    /// An event, with `after` the state after it: entries into contact and impacts counted;
    /// an impact's impulse P φ at the tip, P = −(1 + r) m_eff V̇_T⁻ (model docs), enters E_dis
    /// (its loss), the virial (P W), ⟨F_c⟩ and each mode's balance.
    fn event(&mut self, ctx: &Ctx, e: &SwitchEvent, after: &DVector<f64>) {
        let model = &ctx.model;
        let n = model.modes();
        if match e.kind {
            EventKind::Switching => e.to == Region::Contact,
            EventKind::Impact | EventKind::Stick => true,
            EventKind::Release => false,
        } {
            self.impacts += 1;
        }
        let restitution = match e.kind {
            EventKind::Impact => model.law().restitution(),
            EventKind::Stick => Some(0.0),
            _ => None,
        };
        let Some(rc) = restitution else {
            return;
        };
        // the window's weight at the event multiplies each of its contributions
        let wt = ctx.weight(e.tau);
        let (loss, _) = model.impact_energy(e.tau, e.v_t_dot, rc);
        self.e_dis += wt * loss;
        self.impact_loss += wt * loss;
        let imp = -(1.0 + rc) * model.effective_mass() * e.v_t_dot * wt;
        self.virial += imp * model.w_tip(&e.state);
        self.force += imp;
        for (acc, &(om, psi)) in self.comp.iter_mut().zip(&ctx.components) {
            let (st, ct) = (om * e.tau + psi).sin_cos();
            acc[2] += imp * st;
            acc[3] += imp * ct;
        }
        let jump: Vec<f64> = (0..n).map(|k| after[n + k] - e.state[n + k]).collect();
        for j in 0..n {
            // the impulse's work on mode j and on the others, at the mean velocity
            let avg = 0.5 * (e.state[n + j] + after[n + j]);
            self.sample[j] -= imp * ctx.tip[j] * avg;
            self.coupling[j] += wt * off_diagonal(&ctx.free.mass, j, &jump) * avg;
        }
    }
}

/// Observables over `opts.periods` drive periods starting at the integrator's current (τ, z),
/// assumed on the steady state; τ need not be a multiple of T. The integrator is left at the
/// end of the window.
///
/// # Errors
/// [`SimError::OutOfRange`] for `periods` outside 1..=[`MAX_PERIODS`] or `harmonics` outside
/// 1..=[`MAX_HARMONICS`], or from [`free_response`]; [`SimError`] from the integrator.
pub fn observe(
    integ: &mut dyn Integrator,
    opts: &ObservableOptions,
) -> Result<Observables, SimError> {
    observe_window(integ, opts, false)
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
pub fn observe_tapered(
    integ: &mut dyn Integrator,
    opts: &ObservableOptions,
) -> Result<Observables, SimError> {
    observe_window(integ, opts, true)
}

/// [`observe`] (`taper` false: over `opts.periods` periods of the system, unweighted) or
/// [`observe_tapered`].
fn observe_window(
    integ: &mut dyn Integrator,
    opts: &ObservableOptions,
    taper: bool,
) -> Result<Observables, SimError> {
    if !(1..=MAX_PERIODS).contains(&opts.periods) {
        return Err(SimError::out_of_range(
            "periods",
            opts.periods,
            "must be in 1..=1000000 (an integer number of drive periods)",
        ));
    }
    if !(1..=MAX_HARMONICS).contains(&opts.harmonics) {
        return Err(SimError::out_of_range(
            "harmonics",
            opts.harmonics,
            "must be in 1..=10000 (the highest harmonic reported)",
        ));
    }
    let model = crate::tip_sample::require_cantilever(integ.system(), "the AFM observables")?;
    let mut ctx = Ctx::new(model, opts.harmonics);
    let p: Params = *ctx.model.params();
    let (n, nh, om) = (ctx.model.modes(), opts.harmonics, p.omega);
    let tau_start = integ.tau();
    // the window: periods of the system, or (tapered) primary drive periods
    let (window, per) = if taper {
        (opts.periods as f64 * TAU / om, opts.periods as f64)
    } else {
        (
            opts.periods as f64 * ctx.model.period(),
            // per drive period 2π/Ω (a multifrequency drive's common period spans several)
            opts.periods as f64 * p.common_periods() as f64,
        )
    };
    if taper {
        ctx.taper = Some((tau_start, TAU / window));
    }
    let (model, free) = (&ctx.model, &ctx.free);
    let end = tau_start + window;
    let z_start = integ.state().clone();
    let mut acc = Acc::new(n, nh);
    acc.comp = vec![[0.0; 4]; ctx.components.len()];
    let mut scratch = Scratch {
        fi: DVector::zeros(n),
        scan: Vec::with_capacity(GL_NODES + 2),
        start: None,
    };
    while integ.tau() < end {
        let step = integ.step(end)?;
        let (r, t0, t1) = (step.region, step.tau0, step.tau1);
        if t1 > t0 {
            if r == Region::Contact {
                acc.contact_time += ctx.weighted_length(t0, t1);
            }
            let pieces = ((t1 - t0) / ctx.h_max[r.index()]).ceil().max(1.0) as usize;
            let hp = (t1 - t0) / pieces as f64;
            // pieces of one step share their end nodes; a step starts afresh
            scratch.start = None;
            for k in 0..pieces {
                let a = t0 + k as f64 * hp;
                let b = if k + 1 == pieces {
                    t1
                } else {
                    t0 + (k + 1) as f64 * hp
                };
                acc.piece(&ctx, integ, r, (a, b), &mut scratch);
            }
        }
        if let Some(e) = &step.event {
            acc.event(&ctx, e, integ.state());
        }
    }
    let z_end = integ.state().clone();
    let t_tot = integ.tau() - tau_start;
    let harmonics: Vec<Harmonic> = (0..nh)
        .map(|h| {
            let s = 2.0 * acc.sin[h] / t_tot;
            let c = 2.0 * acc.cos[h] / t_tot;
            Harmonic {
                n: h + 1,
                amplitude: s.hypot(c),
                phase: wrap_phase((-c).atan2(s)),
            }
        })
        .collect();
    let mean = acc.mean / t_tot;
    let a1 = harmonics[0].amplitude;
    let higher_sq = 2.0 * (acc.w2 / t_tot - mean * mean) - a1 * a1;
    let higher_n2_sq = 2.0 * acc.wd2 / t_tot / (om * om) - a1 * a1;
    let mode_energy = |z: &DVector<f64>, j: usize| {
        0.5 * free.mass[(j, j)] * z[n + j] * z[n + j] + 0.5 * free.stiffness[(j, j)] * z[j] * z[j]
    };
    let mode_balance = (0..n)
        .map(|j| {
            let de = if taper {
                -acc.energy_rate[j]
            } else {
                mode_energy(&z_end, j) - mode_energy(&z_start, j)
            };
            let (d, b, s, c) = (acc.drive[j], acc.damp[j], acc.sample[j], acc.coupling[j]);
            ModeBalance {
                mode: j,
                drive: d / per,
                beam_damping: b / per,
                sample: s / per,
                coupling: c / per,
                energy_change: de / per,
                residual: (de - (d - b - s - c)) / per,
            }
        })
        .collect();
    let mode_amplitudes = (0..n)
        .map(|k| {
            let m = acc.eigen_mean[k] / t_tot;
            (2.0 * (acc.eigen_sq[k] / t_tot - m * m)).max(0.0).sqrt()
        })
        .collect();
    let phase = harmonics[0].phase;
    let closed_form = closed_forms(model, a1, phase)?;
    let components = ctx
        .components
        .iter()
        .zip(&acc.comp)
        .enumerate()
        .map(|(i, (&(om, _), sums))| component(model, i, om, sums, t_tot))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Observables {
        periods: opts.periods,
        amplitude: a1,
        phase,
        thd: higher_sq.max(0.0).sqrt() / a1,
        harmonics,
        mean_deflection: mean,
        higher_sq,
        higher_n2_sq,
        mean_force: acc.force / t_tot,
        peak_force: acc.f_max,
        min_force: acc.f_min,
        indentation: (-acc.v_min).max(0.0),
        contact_fraction: acc.contact_time / t_tot,
        contact_time: acc.contact_time / per,
        min_distance: acc.v_min + p.contact_law.distance_offset(),
        impacts_per_period: acc.impacts as f64 / per,
        energy_dissipated: acc.e_dis / per,
        impact_loss: acc.impact_loss / per,
        virial: acc.virial / t_tot,
        mode_balance,
        mode_amplitudes,
        closed_form,
        components,
    })
}

/// [`ComponentObservables`] of component `i` (0: the primary) at ω_c = `om` from its window
/// sums (`sums`: ∫W sin θ, ∫W cos θ, ∫F_c sin θ, ∫F_c cos θ over `t_tot`, θ = ω_c τ + ψ_c).
/// With z_c = A sin(θ − φ): V_c = (A/T)(Fs cos φ − Fc sin φ) and
/// ∮F_c ż_c = Aω_c(Fc cos φ + Fs sin φ).
fn component(
    model: &CantileverModel,
    i: usize,
    om: f64,
    sums: &[f64; 4],
    t_tot: f64,
) -> Result<ComponentObservables, SimError> {
    let [ws, wc, fs, fc] = *sums;
    let (s, c) = (2.0 * ws / t_tot, 2.0 * wc / t_tot);
    let a = s.hypot(c);
    let phase = wrap_phase((-c).atan2(s));
    let (sp, cp) = phase.sin_cos();
    let virial = a * (fs * cp - fc * sp) / t_tot;
    let cycles = om * t_tot / TAU;
    let e_dis = -a * om * (fc * cp + fs * sp) / cycles;
    let p = model.params();
    let (free_amplitude, free_phase) = if i == 0 {
        let f = free_response(model)?;
        (f.amplitude, f.phase)
    } else {
        let d = p.components().nth(i - 1).expect("component i exists");
        let h = model.free_force_response(om)?;
        (d.force * h.norm(), wrap_phase(-h.arg()))
    };
    // the equivalent point mass of the mode nearest ω_c
    let natural = crate::eigen::natural_modes(model.galerkin().region(Region::Free));
    let mode = (0..model.modes())
        .min_by(|&x, &y| {
            (natural.omega[x] - om)
                .abs()
                .total_cmp(&(natural.omega[y] - om).abs())
        })
        .unwrap_or(0);
    let m = EquivalentMode::of(model, mode);
    Ok(ComponentObservables {
        ratio: om / p.omega,
        amplitude: a,
        phase,
        free_amplitude,
        free_phase,
        virial,
        energy_dissipated: e_dis,
        mode,
        closed_virial: m.virial(a, free_amplitude, phase),
        closed_energy_dissipated: m.energy_dissipated(a, free_amplitude, phase, om),
    })
}

/// dF_c/dτ at a node: ∂F/∂δ δ̇ + ∂F/∂δ̇ δ̈ for the smooth laws (δ = −V_T, partials of
/// [`TipSampleLaw::force`]); 0 where no force acts.
fn force_rate(law: &TipSample, r: Region, nd: &Node) -> f64 {
    let contact = r == Region::Contact;
    if !contact && !law.acts_outside() {
        return 0.0;
    }
    let e = law.force(contact, -nd.v[0], -nd.v[1]);
    -e.d_delta * nd.v[1] - e.d_rate * nd.v[2]
}

/// Zero of g on [a, b] between values of opposite signs, by the safeguarded Newton iteration
/// with a central-difference slope (the extremum's value is second-order in the location).
fn root_of(a: f64, ga: f64, b: f64, gb: f64, g: &mut dyn FnMut(f64) -> f64) -> f64 {
    let s = if ga > 0.0 { 1.0 } else { -1.0 };
    let h = 1e-6 * (b - a);
    safeguarded_newton(a, s * ga, b, s * gb, 0.0, &mut |t| {
        let v = s * g(t);
        let d = s * (g((t + h).min(b)) - g((t - h).max(a))) / ((t + h).min(b) - (t - h).max(a));
        (v, d)
    })
}

/// [`observe`] from a start state: builds the integrator of `model` with `integ` at (τ₀, z₀).
///
/// # Errors
/// As [`build`] and [`observe`].
pub fn observe_from(
    model: &CantileverModel,
    integ: IntegratorOptions,
    tau0: f64,
    z0: &DVector<f64>,
    opts: &ObservableOptions,
) -> Result<Observables, SimError> {
    let mut it = build(model, integ, tau0, z0)?;
    observe(it.as_mut(), opts)
}

/// [`observe_from`] on a periodic orbit found by shooting ([`super::shooting`]): from its state
/// at τ = 0 over its n drive periods, harmonics up to `harmonics`.
///
/// # Errors
/// As [`observe_from`].
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
