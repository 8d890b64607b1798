//! The thermally driven lever: the exact stochastic step of the piecewise-linear model, of SLS
//! and of the impact law ([`ThermalExact`]), the exponential Euler step of the other laws, with
//! the switchings and impacts the noise makes between two steps located on the path's Gaussian
//! bridge.
//!
//! # The stochastic system
//! In each region s the state z = (a, ȧ) obeys dz = (A_s z + f(τ)) dτ + G dW, the thermal force
//! ξ on the modal coordinates white with ⟨ξ(τ)ξ(τ')ᵀ⟩ = 2 k_B T C_s δ(τ − τ') by the
//! fluctuation–dissipation theorem (C_s the region's modal damping: the lever's, the medium's
//! per mode and, in contact, the sample's dashpot; Callen & Welton, *Phys. Rev.* 83 (1951) 34),
//! so GGᵀ = [[0, 0], [0, M⁻¹ 2k_BT C_s M⁻¹]]. k_B T is in the model's energy unit, force × length
//! ([`ThermalForce::new`]), so that the stationary covariance is P = diag(k_BT K⁻¹, k_BT M⁻¹)
//! (A P + P Aᵀ + GGᵀ = 0), the equipartition `crate::analysis::thermal` reports.
//!
//! # The exact step
//! With δz = z − z_p(τ) (z_p the region's periodic particular solution: the deterministic
//! propagator's of the primary drive, [`super::ExactPropagator`], plus that of each further
//! component of a multifrequency drive, a tip force F̃ cos(ωτ + θ) answered the same way) the
//! step of length ℓ is
//! δz(τ + ℓ) = Φ(ℓ) δz(τ) + w, w ~ N(0, Q(ℓ)), Φ(ℓ) = e^{A_s ℓ}, Q(ℓ) = ∫₀^ℓ e^{A_s u} GGᵀ
//! e^{A_sᵀ u} du, exact at any ℓ (the free lever's thermal motion is exact whatever the grid).
//! Φ and Q come from one block exponential, exp([[−A, GGᵀ], [0, Aᵀ]] ℓ) = [[·, F₁₂], [0, F₂₂]]:
//! Φ = F₂₂ᵀ, Q = F₂₂ᵀ F₁₂ (C. F. Van Loan, "Computing integrals involving the matrix
//! exponential", *IEEE Trans. Autom. Control* 23 (1978) 395–404, Theorem 1). w is drawn as S ζ,
//! S = V Λ^{1/2} (Q = V Λ Vᵀ; Q is semi-definite), ζ standard normal (`rand_distr`'s
//! `StandardNormal`, the ziggurat method) from a ChaCha8 stream seeded by the seed alone: a run
//! is a function of its seed, whatever the threads.
//!
//! # Switchings between two steps: the bridge
//! Given δz at the ends a, b of an interval of length ℓ the path inside is a Gaussian bridge;
//! at the midpoint it is normal with mean Φ(ℓ/2) δz_a + B (δz_b − Φ(ℓ) δz_a) and covariance
//! Q(ℓ/2) − B Φ(ℓ/2) Q(ℓ/2), B = Q(ℓ/2) Φ(ℓ/2)ᵀ Q(ℓ)⁺ (the conditional of a Gaussian vector).
//! The grid step h is the top of a dyadic ladder ℓ_k = h/2^k, k = 0..=[`LEVELS`], whose Φ, Q
//! and bridge gains are tabulated per region. An interval is refined — its midpoint drawn from
//! the bridge, the left half searched first — when the gap g = ±V_T at its right end is ≤ 0 or
//! the gap of the bridge's mean at its midpoint is within [`KAPPA`] standard deviations of the
//! surface (g's bridge standard deviation is fixed per level; the mean's gap is a linear form in
//! the ends' δz, its two rows tabulated per rung, so that the test costs two dot products and
//! no draw); at level [`LEVELS`] the first
//! point with g ≤ 0 is the switching. **Error**: the switching time is located to within
//! h/2^LEVELS (h/4096) and the state there is the path's (its gap past the surface by at most
//! |ġ| h/4096); an excursion across the surface is missed only where every tested midpoint of
//! its interval is κ = 6 standard deviations clear of the surface by the bridge (a probability
//! below 10⁻⁹ per test for the noise) and the deterministic part dips across between points
//! h/4096 apart while its mean at their midpoint stays clear (a dip shallower than
//! |g''| (h/8192)²/2). After a switching the rest of the grid step is taken in the new region
//! by the dyadic pieces of the ladder, each searched the same way, so the path stays on the
//! ladder; a piece to a time off it (the run's end) has its own ladder, built on demand.
//!
//! # SLS: the dashpot's extension in the state
//! The standard linear solid's sample (`crate::contact::sls`) is affine in each region in the
//! state z = (a, ȧ, u), u the Maxwell arm's dashpot's extension: A_s is the model's Jacobian
//! (constant in a region) and the forcing its right-hand side at z = 0, so the step above is
//! exact in 2N + 1 dimensions about that system's own particular solution. The dashpot's
//! thermal force ξ_d, white with 2 k_BT α6, enters α6 u̇ = κ(δ_s − u) + ξ_d: D_uu = 2 k_BT/α6
//! (`state_diffusion`); the lever's is as above, and the sample adds no damping at the tip.
//! The switching is where the tip meets the recovering surface, V_T + s(u) = 0
//! (`crate::contact::Zener::surface`), in both regions: the bridge's tested row is
//! g = (φ(1), 0, κ/(α4 + κ)) in place of the tip's. The grid resolves the contact at its
//! instantaneous stiffness α4 + κ (`grid_model`), as the linear law's does its own. The
//! free-flight certificate below is not used (the surface moves); every step is searched.
//! The massless surface's depression s(u) takes the dashpot's white force itself, so the
//! switching row is rough (a diffusion, not a C¹ path as V_T is): near a release the tip meets
//! the surface again down to the bridge's h/4096, and the number of switchings depends on the
//! grid (the run warns, `thermal.sls-chatter`) while the time in contact and the forces do not.
//!
//! # The impact law: impacts, sticking and release
//! The rigid sample (`crate::contact::impact`) leaves the lever linear in both of its regions:
//! free flight, and sticking, where the constraint force λ holds V_T = 0 and the motion is
//! affine with the sticking field's Jacobian (the constraint held by its Baumgarte terms,
//! `crate::model`), its particular solution the region's own. While the tip sticks the
//! constraint takes the thermal force's part at the tip (`state_diffusion`: no noise on V_T),
//! so both regions' steps are exact. An impact is the free flight's switching, found on the
//! bridge as above to δ = h/4096: its state is moved by Newton's law about the crossing,
//! carried to the located point to second order in δ (`ThermalExact::impact`); the sticking
//! is left where λ, affine in the state (its switching row ∂λ/∂z), falls to 0.
//! Under white noise a tip hitting a wall with restitution r does not stick as the
//! deterministic tip does: below r_c = e^{−π/√3} ≈ 0.163 it comes to rest after infinitely
//! many impacts in finite time (inelastic collapse), above it it never comes to rest, but
//! hovers against a pressing force g within heights of order D²/g³ over times D/g², D the
//! tip rate's diffusion (H. P. McKean, *J. Math. Kyoto Univ.* 2 (1963) 227; S. J. Cornell,
//! M. R. Swift & A. J. Bray, *Phys. Rev. Lett.* 81 (1998) 1142; S. N. Kotsev & T. W.
//! Burkhardt, *Phys. Rev. E* 73 (2006) 046121). The step takes both as sticking where the next
//! bounce would be shorter than δ (2 r|v_c| m_eff/λ ≤ δ): a lever tapping in air at 10 nm
//! hovers within 10⁻²⁵ m over 10⁻⁹ of a period, far beneath the resolution, a soft lever in
//! water within 10⁻¹⁵ m. The number of impacts and the time stuck therefore depend on the grid
//! while the motion does not (the run warns, `thermal.impact-chatter`). At T → 0 the step is
//! the deterministic run's (impact map, chattering ending in sticking, release at λ = 0), but
//! for a grazing impact that dips across the surface between the bridge's test points deeper
//! than the noise's κσ band there (at T → 0, any): where the tip moves faster than the grid
//! (higher modes ringing after an impact, a fast drive component) a finer grid finds it (a
//! simulation's grid holds its samples: more samples per period).
//!
//! # Nonlinear laws: the exponential Euler step
//! For a law that is not piecewise linear but whose force is one of the state in each region
//! (Hertz, DMT, the electrostatic law: a force F_c(δ, δ̇), the contact where V_T ≤ 0; JKR and
//! the capillary meniscus too, whose contact, formed at V_T = 0, is left at V_T = |δ_f| > 0,
//! the gap in contact being |δ_f| − V_T and the region the run's own) the step is the
//! exponential Euler scheme over the exact linear part: on each piece the tip force is taken as its value
//! at the piece's start and the drift's rate of it there, F(τ₀ + s) ≈ F₀ + F₁ s
//! (F₁ = ∂F_c/∂δ δ̇ + ∂F_c/∂δ̇ δ̈, δ̈ the drift's), so that the piece is the free lever's linear
//! stochastic system with an affine force at the tip, advanced exactly as above about its
//! particular solution z_p + (F₀ + F₁ s) z_F + F₁ A⁻¹ z_F (z_F = −A⁻¹ (0, M⁻¹φ), the static
//! response to a unit tip force), its switchings found on the same bridge. (The force affine in
//! time makes the deterministic part second order, as in exponential time differencing, S. M.
//! Cox & P. C. Matthews, *J. Comput. Phys.* 176 (2002) 430, whose ETD2 takes the rate from the
//! last step instead; a law whose ∂F_c/∂δ is singular at the onset, Kelvin–Voigt's, takes
//! F₁ = 0 there.) With additive noise and a smooth force the scheme has strong order 1
//! (A. Jentzen & P. E. Kloeden, "Overcoming the order barrier in the numerical
//! approximation of stochastic partial differential equations with additive space–time noise",
//! *Proc. R. Soc. A* 465 (2009) 649–667, whose finite-dimensional case this is); where the
//! force has a kink (Hertz's δ^{3/2} at the surface) the order is lower at the crossing. In
//! contact the piece is cut to ℓ ≤ [`STIFF_ETA`]/ω_c, ω_c = (|∂F_c/∂δ|/m_eff)^{1/2} +
//! |∂F_c/∂δ̇|/m_eff at the piece's start, a rung of the same ladder. The thermal force is the
//! lever's and the medium's (their damping's, by the fluctuation–dissipation theorem); the
//! sample's own dissipation adds none here (a force of the state, its noise is not modelled).
//!
//! # Free flight: steps longer than the grid
//! Where the surface is far the path needs no search, and the step may be as long as the drawn
//! points allow (to the next held sample, [`ThermalExact::holding`]; Φ and Q are exact at any
//! length). In free flight V(δz) = δzᵀ P⁻¹ δz, P = diag(k_BT K⁻¹, k_BT M⁻¹) the stationary
//! covariance, does not grow along the drift (dV/dτ = −δzᵀ P⁻¹ GGᵀ P⁻¹ δz ≤ 0, from
//! A P + P Aᵀ + GGᵀ = 0), so by Cauchy–Schwarz the drift's tip deflection stays within
//! σ_∞ V(δz_a)^{1/2} of the particular solution's, σ_∞² = k_BT tipᵀ K⁻¹ tip the tip's stationary
//! variance. The noise's part w(τ) ~ N(0, Q) has Q ≤ P. A step from a grid point is certified
//! when the particular solution's V_T over it, less σ_∞ (V(δz_a)^{1/2} + [`FAR_KAPPA`]), stays
//! above the surface; the chance that the noise's part reaches κσ_∞ within the step is then, by
//! Rice's formula for a stationary Gaussian process (S. O. Rice, *Bell Syst. Tech. J.* 23 (1944)
//! 282, §3.3), about Φ̄(κ) + ℓ ν e^{−κ²/2}, ν = σ_Ẇ/(2π σ_∞) (σ_Ẇ² = k_BT tipᵀ M⁻¹ tip): at
//! κ = 8, 6·10⁻¹⁶ + 1.3·10⁻¹⁴ ℓν. The certificate is checked only where the Lyapunov equation
//! holds for the model's matrices (to 10⁻⁸); otherwise the grid is kept.
//!
//! The path between recorded points (dense output) is drawn from the bridge between the nearest
//! points already drawn, by a second stream of the seed, so that the path at the grid points
//! does not depend on the samples asked for.

use super::forcing::{harmonic_response, Forced};
use super::{ExactOptions, ExactPropagator};
use crate::error::SimError;
use crate::integrate::{Integrator, IntegratorOptions, Step};
use crate::model::CantileverModel;
use crate::system::{EventKind, HybridSystem, Region};
use crate::tip_sample::TipSampleSystem;
use nalgebra::{DMatrix, DVector};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use std::sync::Arc;

/// The levels of the dyadic ladder below a grid step: a switching is located to h/2^LEVELS.
pub const LEVELS: usize = 12;
/// An interval is refined where its bridge's mean gap at the midpoint is within KAPPA standard
/// deviations of the surface.
pub const KAPPA: f64 = 6.0;
/// A piece under a nonlinear law's force is at most STIFF_ETA/ω_c long, ω_c the contact's rate
/// at the piece's start (module docs): about 600 pieces per period of the contact's
/// oscillation. (A PI scan of the point-mass DMT lever at T → 0 puts its heights 15 pm from
/// the deterministic scan's at 0.1, 4 pm at 0.03, 1.4 pm at 0.01; the cost of 0.01 is 1.5× that
/// of 0.1.)
pub const STIFF_ETA: f64 = 0.01;
/// A free-flight step is certified where the drift's bound clears the surface by FAR_KAPPA
/// stationary standard deviations of the tip (module docs).
pub const FAR_KAPPA: f64 = 8.0;
/// The second stream's seed offset (dense output between the drawn points).
const DENSE_STREAM: u64 = 0x9e37_79b9_7f4a_7c15;

/// The thermal force of a run: k_B T in the model's energy unit and the seed of its stream.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct ThermalForce {
    /// k_B T / (force × length unit): the model's k_B T.
    pub kt: f64,
    /// The seed of the random stream.
    pub seed: u64,
    /// The ChaCha stream of the seed (its 64-bit nonce): 0 for one run; a scan draws each
    /// line's and material's force from a stream of its own ([`ThermalForce::stream`]), so
    /// that they are independent and each a function of the seed and its index alone.
    pub stream: u64,
}

impl ThermalForce {
    /// The force of the thermal energy `kt`, k_B T in the model's energy unit (k_B T/(F₀ L₀),
    /// F₀ and L₀ the newtons and metres per unit force and length, the caller's SI scales:
    /// the integrator is dimensionless), drawn from the stream of `seed`.
    pub fn new(kt: f64, seed: u64) -> ThermalForce {
        ThermalForce {
            kt,
            seed,
            stream: 0,
        }
    }

    /// The same force drawn from stream `stream` of the seed.
    pub fn stream(self, stream: u64) -> ThermalForce {
        ThermalForce { stream, ..self }
    }
}

/// The least multiple of `steps` grid steps per period (at least 1) that holds `samples`
/// equally spaced samples per period as grid points (also at least 1), where the stochastic
/// step has its drawn points (a sample between them is drawn from the bridge).
pub(crate) fn holding_samples(steps: usize, samples: usize) -> usize {
    let (a, s) = (steps.max(1), samples.max(1));
    a / crate::params::gcd(a as u64, s as u64) as usize * s
}

/// The drive periods 2π/Ω in the system's period [`CantileverModel::period`], which the grid
/// spans: 1, or a multifrequency drive's common period ([`crate::params::Params::common_periods`];
/// 1 for a quasi-periodic one).
pub(crate) fn drive_periods(model: &CantileverModel) -> usize {
    let t = std::f64::consts::TAU / model.omega();
    ((model.period() / t).round() as usize).max(1)
}

/// Whether the stochastic step advances `law` exactly: affine in each region (the linear law,
/// SLS with its dashpot's extension in the state, and the impact law's free flight and
/// sticking); the other laws by the exponential Euler step (module docs).
fn stepped_exactly(law: &crate::contact::ContactLaw) -> bool {
    law.is_affine() || law.internal_states() > 0 || law.restitution().is_some()
}

/// Whether region `r` of `model` is the impact law's sticking: the tip held on the surface by
/// the constraint force λ (module docs).
fn sticking(model: &CantileverModel, r: Region) -> bool {
    r == Region::Contact && model.law().restitution().is_some()
}

/// A further drive component's particular solution in one region of the linear part: its tip
/// force F̃ cos(ωτ + θ) ([`crate::params::Params::component_force`], ω = p/q Ω), the forcing
/// e F̃ (cos θ cos ωτ − sin θ sin ωτ), e = (0, M⁻¹φ), has the periodic response
/// z = ps sin ωτ + pc cos ωτ ([`harmonic_response`], as the primary drive's). The system is
/// linear, so the particular solution of the whole drive is the primary's ([`Forced`]) plus
/// every component's.
#[derive(Debug, Clone)]
struct Component {
    omega: f64,
    /// ps and pc (each `[2N]`).
    ps: DVector<f64>,
    pc: DVector<f64>,
    /// Their switching rows' values (g·ps, g·pc: the tip's deflections, with SLS's s(u)).
    tip: (f64, f64),
}

impl Component {
    /// The further components of the drive of `p` in the region's system `sys`, their tip
    /// force on the state through `e` = (0, M⁻¹φ) (none for a single-frequency drive).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `drive_components.ratio` where ω is an undamped natural
    /// frequency of the region (no periodic response).
    fn of(
        p: &crate::params::Params,
        sys: &Affine,
        e: &DVector<f64>,
    ) -> Result<Vec<Component>, SimError> {
        p.components()
            .map(|c| {
                let omega = c.ratio() * p.omega;
                let (s, co) = c.phase.sin_cos();
                let b = (e * (-c.force * s), e * (c.force * co));
                let (ps, pc, _) =
                    harmonic_response(&sys.a, omega, (&b.0, &b.1)).ok_or_else(|| {
                        SimError::out_of_range(
                            "drive_components.ratio",
                            c.ratio(),
                            "puts a component at an undamped natural frequency: no periodic \
                             forced response (add damping)",
                        )
                    })?;
                let tip = (sys.switching.dot(&ps), sys.switching.dot(&pc));
                Ok(Component { omega, ps, pc, tip })
            })
            .collect()
    }

    /// (sin, cos) ωτ.
    fn angle(&self, tau: f64) -> (f64, f64) {
        (self.omega * tau).sin_cos()
    }
}

/// How a thermally driven run of `law` is integrated (a document's `thermal.method`), and the
/// warnings of its scheme: a nonlinear law's own error, which is not zero, and SLS's and the
/// impact law's number of switchings, which depends on the grid (module docs): the run's
/// document and the PI scan's warnings.
pub fn thermal_method(law: &crate::contact::ContactLaw) -> (&'static str, Vec<String>) {
    if law.restitution().is_some() {
        let chatter = warning!(
            "thermal.impact-chatter",
            "Read the tip's motion and the forces' averages, not the number of impacts or the \
             time stuck.",
            "the impact law's thermal run takes the bounces shorter than its resolution \
             (h/4096) as sticking and resolves the thermal force's micro-impacts near each \
             release down to it: its number of impacts and its time stuck depend on its grid \
             (28 to 81 events per period and 3.4 % to 3.2 % of the time stuck for a beam in \
             water from 36 to 256 steps per period, its mean and rms V_T the same within 0.2 %)"
        );
        return (
            "the fluctuation–dissipation theorem's white force on every mode (2 k_B T C_s; while \
             the tip sticks, its part at the tip taken by the constraint), advanced by the exact \
             stochastic step (Van Loan 1978), impacts located on the Gaussian bridge to h/4096 \
             with Newton's restitution, sticking where the next bounce would be shorter than \
             that, released where the constraint force falls to 0 \
             (crate::integrate::exact::noise)",
            vec![chatter],
        );
    }
    if law.internal_states() > 0 {
        let chatter = warning!(
            "thermal.sls-chatter",
            "Read the time in contact, the forces and the tip's motion, not the number of \
             switchings.",
            "the SLS surface's depression s(u) carries its dashpot's white thermal force itself \
             (a massless surface), so its height is rough and the tip meets it again and again \
             near each release, down to the step's resolution (h/4096): the run's number of \
             switchings depends on its grid (2.0 to 2.5 per period on a 40 N/m lever from 8 to \
             128 steps per period, its time in contact the same within 0.5 %)"
        );
        return (
            "the fluctuation–dissipation theorem's white force on every mode (2 k_B T C_s) and \
             on the SLS dashpot's extension (2 k_B T/α6), advanced by the exact stochastic step \
             in 2N + 1 dimensions (Van Loan 1978), switchings onto the recovering surface \
             located on the Gaussian bridge to h/4096 (crate::integrate::exact::noise)",
            vec![chatter],
        );
    }
    if stepped_exactly(law) {
        return (
            "the fluctuation–dissipation theorem's white force on every mode (2 k_B T C_s), \
             advanced by the exact stochastic step (Van Loan 1978), switchings between grid \
             points located on the Gaussian bridge to h/4096 (crate::integrate::exact::noise)",
            Vec::new(),
        );
    }
    let warning = warning!(
        "thermal.scheme-error",
        "Compare with the same run at T → 0 (temperature = 0.001) before reading differences of \
         that size as thermal.",
        "the {} law's thermal run is integrated by the exponential Euler step, first order in its \
         pieces: at T → 0 it departs from the deterministic run by about 10⁻³ of the state (1.4 pm \
         of height in a PI scan of the point-mass DMT lever), which can exceed the thermal effect",
        law.name()
    );
    (
        "the fluctuation–dissipation theorem's white force on the lever's and the medium's \
         damping, advanced by the exponential Euler step over the exact linear part (the tip \
         force affine in time over each piece; Jentzen & Kloeden 2009), switchings located on the \
         Gaussian bridge (crate::integrate::exact::noise)",
        vec![warning],
    )
}

/// The lever of `model` without the sample (α4 = α6 = 0 under the linear law): the linear part
/// the stochastic step advances exactly under a nonlinear law; `model` itself under the linear
/// law.
pub(crate) fn linear_part(model: &CantileverModel) -> Result<CantileverModel, SimError> {
    if model.law().is_affine() {
        return Ok(model.clone());
    }
    let p = crate::params::Params {
        contact_law: crate::contact::ContactLaw::Linear,
        alpha4: 0.0,
        alpha6: 0.0,
        ..*model.params()
    };
    Ok(CantileverModel::new(&p)?)
}

/// The model whose exact propagator gives the stochastic step's grid: the linear part `lin`, or
/// over SLS the lever on a linear sample of the instantaneous stiffness α4 + κ, so that the
/// grid resolves the contact's fastest oscillation as under the linear law (‖A‖₂ h ≤ θ:
/// a contact lasts longer than half a grid step, so that the bridge's test points, h/2 apart,
/// meet it as T → 0).
fn grid_model(model: &CantileverModel, lin: &CantileverModel) -> Result<CantileverModel, SimError> {
    let Some(zn) = model.zener() else {
        return Ok(lin.clone());
    };
    let p = crate::params::Params {
        contact_law: crate::contact::ContactLaw::Linear,
        alpha4: zn.relaxed + zn.maxwell,
        alpha6: 0.0,
        ..*model.params()
    };
    Ok(CantileverModel::new(&p)?)
}

/// The contact's rate ω_c = (|∂F_c/∂δ|/m_eff)^{1/2} + |∂F_c/∂δ̇|/m_eff of the tip force `e`
/// (module docs): the spring's natural frequency and the dashpot's decay rate at the tip.
pub(crate) fn rate_of(e: &crate::contact::ForceEval, m_eff: f64) -> f64 {
    (e.d_delta.abs() / m_eff).sqrt() + e.d_rate.abs() / m_eff
}

/// How far apart, in ulps of τ, a target time and the lattice point it names may be rounded
/// (a sample time start + k·T/S against the lattice's p·T + k·h).
const ROUNDING_ULPS: f64 = 8.0;

/// ChaCha8 from `seed` on `stream`.
fn seeded(seed: u64, stream: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(stream);
    rng
}

/// The diffusion GGᵀ = [[0, 0], [0, M⁻¹ 2k_BT C_s M⁻¹]] of region `r` of `model` (2N × 2N).
pub(crate) fn diffusion(model: &CantileverModel, r: Region, kt: f64) -> DMatrix<f64> {
    let g = model.galerkin();
    let n = model.modes();
    let minv = (g.region(Region::Free).mass.clone().try_inverse()).unwrap_or(DMatrix::zeros(n, n));
    let c = &g.region(r).damping;
    let mut d = DMatrix::zeros(2 * n, 2 * n);
    let block = &minv * c * minv.transpose() * (2.0 * kt);
    d.view_mut((n, n), (n, n))
        .copy_from(&(0.5 * (&block + block.transpose())));
    d
}

/// GGᵀ of region `r` of `model` in the state's dimension: the lever's and the medium's (those of
/// its linear part `lin`, [`diffusion`]) and under SLS its dashpot's own force, white with
/// 2 k_BT α6 by the fluctuation–dissipation theorem, on the extension u:
/// α6 u̇ = κ(δ_s − u) + ξ_d gives D_uu = 2 k_BT/α6 (the free sample's u then has
/// k_BT/k_s, k_s = α4κ/(α4 + κ) its springs in series: equipartition). While the impact law's
/// tip sticks, the constraint's reaction takes the thermal force's part at the tip: from
/// M ä = f + ξ + φλ with φᵀä = 0 the velocity block is P D_vv Pᵀ, P = I − m_eff M⁻¹φ φᵀ
/// (φᵀP = 0: no tip acceleration).
pub(crate) fn state_diffusion(
    model: &CantileverModel,
    lin: &CantileverModel,
    r: Region,
    kt: f64,
) -> DMatrix<f64> {
    let (dim, n) = (model.dim(), 2 * model.modes());
    let mut d = DMatrix::zeros(dim, dim);
    d.view_mut((0, 0), (n, n)).copy_from(&diffusion(lin, r, kt));
    if model.zener().is_some() {
        d[(n, n)] = 2.0 * kt / model.params().alpha6;
    }
    if sticking(model, r) {
        let (m, p) = (model.modes(), model.tip_projector());
        let vv = &p * d.view((m, m), (m, m)) * p.transpose();
        d.view_mut((m, m), (m, m))
            .copy_from(&(0.5 * (&vv + vv.transpose())));
    }
    d
}

/// Φ(ℓ) = e^{Aℓ} and Q(ℓ) = ∫₀^ℓ e^{Au} D e^{Aᵀu} du by Van Loan's block exponential (module
/// docs).
pub(crate) fn van_loan(a: &DMatrix<f64>, d: &DMatrix<f64>, l: f64) -> (DMatrix<f64>, DMatrix<f64>) {
    let n = a.nrows();
    let mut big = DMatrix::zeros(2 * n, 2 * n);
    big.view_mut((0, 0), (n, n)).copy_from(&(-a * l));
    big.view_mut((0, n), (n, n)).copy_from(&(d * l));
    big.view_mut((n, n), (n, n)).copy_from(&(a.transpose() * l));
    let e = big.exp();
    let phi = e.view((n, n), (n, n)).transpose();
    let q = &phi * e.view((0, n), (n, n));
    let q = 0.5 * (&q + q.transpose());
    (phi, q)
}

/// A square root S (S Sᵀ = Q) of a symmetric semi-definite Q: V Λ^{1/2}, negative round-off
/// eigenvalues clamped to zero.
fn root(q: &DMatrix<f64>) -> DMatrix<f64> {
    let e = q.clone().symmetric_eigen();
    let mut s = e.eigenvectors;
    for (j, l) in e.eigenvalues.iter().enumerate() {
        s.column_mut(j).scale_mut(l.max(0.0).sqrt());
    }
    s
}

/// The pseudo-inverse of a symmetric semi-definite Q (eigenvalues below 10⁻¹³ of the largest
/// dropped: the directions the noise does not reach).
fn pinv(q: &DMatrix<f64>) -> DMatrix<f64> {
    let e = q.clone().symmetric_eigen();
    let top = e.eigenvalues.iter().fold(0.0_f64, |m, l| m.max(l.abs()));
    let mut v = e.eigenvectors.clone();
    for (j, &l) in e.eigenvalues.iter().enumerate() {
        v.column_mut(j)
            .scale_mut(if l > 1e-13 * top { 1.0 / l } else { 0.0 });
    }
    v * e.eigenvectors.transpose()
}

/// What certifies a free-flight step (module docs): P⁻¹ of the free region and σ_∞.
#[derive(Debug, Clone)]
struct Far {
    /// P⁻¹ = diag(K, M)/k_BT (2N × 2N).
    p_inv: DMatrix<f64>,
    /// The tip's stationary standard deviation σ_∞ = (k_BT tipᵀ K⁻¹ tip)^{1/2}.
    sd: f64,
}

impl Far {
    /// The certificate of `model`'s free region under the diffusion `d`, where
    /// P = diag(k_BT K⁻¹, k_BT M⁻¹) solves A P + P Aᵀ + GGᵀ = 0 to 10⁻⁸ (`None` otherwise: a
    /// zero temperature, matrices that are not symmetric positive definite).
    fn new(model: &CantileverModel, d: &DMatrix<f64>, kt: f64) -> Option<Far> {
        let g = model.galerkin().region(Region::Free);
        let n = model.modes();
        let (k_inv, m_inv) = (
            g.stiffness.clone().cholesky()?.inverse(),
            g.mass.clone().cholesky()?.inverse(),
        );
        let mut p = DMatrix::zeros(2 * n, 2 * n);
        p.view_mut((0, 0), (n, n)).copy_from(&(k_inv * kt));
        p.view_mut((n, n), (n, n)).copy_from(&(m_inv * kt));
        let a = &model.dynamics(Region::Free).a;
        let residual = (a * &p + &p * a.transpose() + d).norm();
        if !(kt > 0.0 && residual <= 1e-8 * d.norm()) {
            return None;
        }
        let mut p_inv = DMatrix::zeros(2 * n, 2 * n);
        p_inv
            .view_mut((0, 0), (n, n))
            .copy_from(&(&g.stiffness / kt));
        p_inv.view_mut((n, n), (n, n)).copy_from(&(&g.mass / kt));
        let tip = model.tip();
        let sd = (tip.transpose() * p.view((0, 0), (n, n)) * tip)[0].sqrt();
        Some(Far { p_inv, sd })
    }
}

/// z_F = −A⁻¹ e and A⁻¹ z_F of the free region's system `free`, e = (0, M⁻¹φ), each with its
/// switching row's value (module docs).
fn unit_response(free: &Affine, e: &DVector<f64>) -> Result<[(DVector<f64>, f64); 2], SimError> {
    let lu = free.a.clone().lu();
    let singular = || SimError::out_of_range("stiffness matrix", "singular", "K must be SPD");
    let z = lu.solve(&(-e)).ok_or_else(singular)?;
    let z2 = lu.solve(&z).ok_or_else(singular)?;
    let tip = |z: DVector<f64>| {
        let w = free.switching.dot(&z);
        (z, w)
    };
    Ok([tip(z), tip(z2)])
}

/// A region's affine system ż = A z + b₀ + b_s sin Ωτ + b_c cos Ωτ (a multifrequency drive's
/// further components aside, [`Component`]), its periodic particular solution
/// z_p = p0 + ps sin Ωτ + pc cos Ωτ (A p0 = −b₀, [`harmonic_response`] for ps, pc) and the
/// switching row g (`[dim]`): g·z is the tip's deflection W(1, τ), and under SLS W + s(u), the
/// tip's height over the recovering surface less the base's and the gap's part of V_T
/// ([`crate::contact::Zener::surface`]); in the impact law's sticking ∂λ/∂z, λ the constraint
/// force (affine in z, [`ThermalExact::gap`]).
#[derive(Debug, Clone)]
struct Affine {
    /// A (dim × dim).
    a: DMatrix<f64>,
    p0: DVector<f64>,
    ps: DVector<f64>,
    pc: DVector<f64>,
    /// g·p0, g·ps, g·pc.
    wp: [f64; 3],
    switching: DVector<f64>,
}

impl Affine {
    /// Region `r` of `model`: its linear part `lin` with the deterministic propagator's
    /// particular solution `det`, or under SLS and in the impact law's sticking the model's own
    /// system (in 2N + 1 dimensions under SLS), A its Jacobian (constant in a region) and b its
    /// right-hand side at z = 0 less the further components' force (which the sticking
    /// constraint takes itself).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `omega` at an undamped natural frequency of that
    /// system (no periodic response).
    fn of(
        model: &CantileverModel,
        lin: &CantileverModel,
        det: &ExactPropagator,
        r: Region,
    ) -> Result<Affine, SimError> {
        let (n, dim) = (model.modes(), model.dim());
        let mut switching = DVector::zeros(dim);
        switching.rows_mut(0, n).copy_from(model.tip());
        let (stuck, zero) = (sticking(model, r), vec![0.0; dim]);
        if let Some(zn) = model.zener() {
            switching[2 * n] = zn.surface_gain();
        } else if stuck {
            switching = model.guard(r, 0.0, &zero).grad;
        } else {
            let f: &Forced = &det.forced[r.index()];
            let parts = (f.p0.clone(), f.ps.clone(), f.pc.clone());
            return Ok(Self::with(lin.dynamics(r).a.clone(), parts, switching));
        }
        let p = model.params();
        let mut a = DMatrix::zeros(dim, dim);
        model.jacobian_into(r, 0.0, &zero, &mut a);
        // the right-hand side at Ωτ = θ: the further components' force taken out (the sticking
        // constraint cancels it itself)
        let b = |(theta, sc): (f64, (f64, f64))| {
            let tau = theta / p.omega;
            let mut out = DVector::zeros(dim);
            model.rhs_slice_at(r, tau, sc, &zero, out.as_mut_slice());
            if p.is_multifrequency() && !stuck {
                let fd = p.component_force(tau);
                out.rows_mut(n, n).axpy(-fd, model.tip_mobility(), 1.0);
            }
            out
        };
        let half = std::f64::consts::FRAC_PI_2;
        let (up, down) = (b((0.0, (0.0, 1.0))), b((2.0 * half, (0.0, -1.0))));
        let b0 = 0.5 * (&up + &down);
        let bc = 0.5 * (up - down);
        let bs = b((half, (1.0, 0.0))) - &b0;
        let resonance = || {
            SimError::out_of_range(
                "omega",
                p.omega,
                "is an undamped natural frequency of the lever on the sample (SLS, or held on \
                 it): no periodic forced response (add damping)",
            )
        };
        let p0 = a.clone().lu().solve(&(-b0)).ok_or_else(resonance)?;
        let (ps, pc, _) = harmonic_response(&a, p.omega, (&bs, &bc)).ok_or_else(resonance)?;
        Ok(Self::with(a, (p0, ps, pc), switching))
    }

    fn with(
        a: DMatrix<f64>,
        (p0, ps, pc): (DVector<f64>, DVector<f64>, DVector<f64>),
        switching: DVector<f64>,
    ) -> Affine {
        let wp = [&p0, &ps, &pc].map(|p| switching.dot(p));
        Affine {
            a,
            p0,
            ps,
            pc,
            wp,
            switching,
        }
    }

    /// Both regions' ([`Affine::of`]).
    fn both(
        model: &CantileverModel,
        lin: &CantileverModel,
        det: &ExactPropagator,
    ) -> Result<[Affine; 2], SimError> {
        Ok([
            Self::of(model, lin, det, Region::Free)?,
            Self::of(model, lin, det, Region::Contact)?,
        ])
    }
}

/// The least of c₀ + R sin θ over θ ∈ [θ₀, θ₁].
fn least_of_sine(c0: f64, r: f64, theta0: f64, theta1: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, TAU};
    // the first minimum (θ = 3π/2 mod 2π) at or after θ₀
    let next_min = theta0 + (3.0 * FRAC_PI_2 - theta0).rem_euclid(TAU);
    if next_min <= theta1 {
        return c0 - r;
    }
    c0 + r * theta0.sin().min(theta1.sin())
}

/// The bridge to a point inside an interval: δz = Φ₁ δz_a + B (δz_b − Φ δz_a) + S ζ.
#[derive(Debug, Clone)]
struct Bridge {
    phi1: DMatrix<f64>,
    gain: DMatrix<f64>,
    phi: DMatrix<f64>,
    root: DMatrix<f64>,
    /// The standard deviation of the tip's deflection at the point.
    tip_sd: f64,
    /// The rows u, v of the tip's deflection of the mean, tip·(Φ₁ δz_a + B (δz_b − Φ δz_a))
    /// = u·δz_a + v·δz_b (each `[2N]`).
    rows: [DVector<f64>; 2],
}

impl Bridge {
    /// The bridge at u₁ after a of an interval of u₁ + u₂ in region (`a`, `d`), the tip vector
    /// `tip` (shape `[N]`).
    fn new(a: &DMatrix<f64>, d: &DMatrix<f64>, u1: f64, u2: f64, tip: &DVector<f64>) -> Bridge {
        let (phi1, q1) = van_loan(a, d, u1);
        let (phi2, _) = van_loan(a, d, u2);
        let (phi, q) = van_loan(a, d, u1 + u2);
        Self::from_parts(phi1, q1, &phi2, phi, &q, tip)
    }

    fn from_parts(
        phi1: DMatrix<f64>,
        q1: DMatrix<f64>,
        phi2: &DMatrix<f64>,
        phi: DMatrix<f64>,
        q: &DMatrix<f64>,
        tip: &DVector<f64>,
    ) -> Bridge {
        let gain = &q1 * phi2.transpose() * pinv(q);
        let cov = &q1 - &gain * phi2 * &q1;
        let root = root(&(0.5 * (&cov + cov.transpose())));
        let tip_sd = (root.transpose() * tip).norm();
        let v = gain.transpose() * tip;
        let u = phi1.transpose() * tip - phi.transpose() * &v;
        Bridge {
            phi1,
            gain,
            phi,
            root,
            tip_sd,
            rows: [u, v],
        }
    }

    /// The bridge's mean at the point given δz at the ends.
    fn mean(&self, da: &DVector<f64>, db: &DVector<f64>) -> DVector<f64> {
        &self.phi1 * da + &self.gain * (db - &self.phi * da)
    }
}

/// One rung of a ladder: the step of length ℓ_k (Φ and Q's root), the bridge to its middle and
/// (sin, cos) Ωℓ_k/2, the turn of the drive's phase to it.
#[derive(Debug, Clone)]
struct Rung {
    phi: DMatrix<f64>,
    root: DMatrix<f64>,
    mid: Bridge,
    half_turn: (f64, f64),
}

/// The ladder of region (`a`, `d`) from a step of `len` at drive frequency `omega`: rungs
/// k = 0..=LEVELS of ℓ_k = len/2^k.
fn ladder(
    a: &DMatrix<f64>,
    d: &DMatrix<f64>,
    len: f64,
    tip: &DVector<f64>,
    omega: f64,
) -> Arc<[Rung]> {
    let steps: Vec<(DMatrix<f64>, DMatrix<f64>)> = (0..=LEVELS + 1)
        .map(|k| van_loan(a, d, len / (1u64 << k) as f64))
        .collect();
    (0..=LEVELS)
        .map(|k| {
            let (phi, q) = &steps[k];
            let (phi_half, q_half) = &steps[k + 1];
            let mid = Bridge::from_parts(
                phi_half.clone(),
                q_half.clone(),
                phi_half,
                phi.clone(),
                q,
                tip,
            );
            Rung {
                phi: phi.clone(),
                root: root(q),
                mid,
                half_turn: (0.5 * omega * len / (1u64 << k) as f64).sin_cos(),
            }
        })
        .collect()
}

/// Φ and the root of Q of a free-flight step.
type Flight = (DMatrix<f64>, DMatrix<f64>);

/// The tip force over a piece, F₀ + F₁ (τ − τ₀): [F₀, F₁, τ₀] (module docs).
type Frozen = [f64; 3];

/// A point of the path: τ, z and the tip force over the piece it lies in (0 under the linear
/// law).
type Point = (f64, DVector<f64>, Frozen);

/// A point of a piece being searched: τ, (sin, cos) Ωτ, z, its offset in units of h/2^LEVELS.
type Probe = (f64, (f64, f64), DVector<f64>, u64);

/// (sin, cos) of θ + φ from (sin, cos) θ and (sin, cos) φ.
fn turn((s, c): (f64, f64), (sp, cp): (f64, f64)) -> (f64, f64) {
    (s * cp + c * sp, c * cp - s * sp)
}

/// The exact stochastic step of the piecewise-linear model (module docs), an [`Integrator`]
/// whose state carries the thermal force.
#[derive(Debug, Clone)]
pub struct ThermalExact {
    /// The deterministic propagator: the model, the grid and the particular solutions.
    det: ExactPropagator,
    /// Its build options (rebuilt at a new gap, [`Integrator::set_gap`]).
    exact: ExactOptions,
    /// The model (its law's force and regions; [`Integrator::system`]).
    model: CantileverModel,
    /// Its linear part, which the steps advance exactly: the model under the linear law, the
    /// lever without the sample under a nonlinear one ([`linear_part`]).
    lin: CantileverModel,
    /// Both regions' affine systems and particular solutions (the primary drive's).
    affine: [Affine; 2],
    /// z_F = −A⁻¹ (0, M⁻¹φ) and A⁻¹ z_F (each `[2N]`) and their tip deflections: the free
    /// lever's response to a unit tip force and to a unit rate of it (module docs).
    unit: [(DVector<f64>, f64); 2],
    /// The further drive components' particular solutions in both regions (empty under one
    /// harmonic drive).
    components: [Vec<Component>; 2],
    /// The tip force over the piece under way, F₀ + F₁ (τ − τ₀): [F₀, F₁, τ₀] (0 under the
    /// linear law).
    frozen: Frozen,
    force: ThermalForce,
    /// GGᵀ of both regions.
    diffusion: [DMatrix<f64>; 2],
    /// The ladders of the grid step of both regions.
    ladders: [Arc<[Rung]>; 2],
    /// The last ladder built for a piece off the grid: its region, length and rungs.
    odd: Option<(Region, f64, Arc<[Rung]>)>,
    /// The free-flight certificate (`None`: every step on the grid and searched).
    far: Option<Far>,
    /// Grid steps between held points (the samples'; 1: every grid point), which a free-flight
    /// step does not cross.
    hold: i64,
    /// Free-flight steps built: their grid steps, Φ and the root of Q.
    flights: Vec<(i64, Arc<Flight>)>,
    rng: ChaCha8Rng,
    dense_rng: ChaCha8Rng,
    tau: f64,
    /// (sin, cos) Ωτ at `tau`.
    sc: (f64, f64),
    z: DVector<f64>,
    /// Scratch of a piece: δz at its start, ζ, δz at its end (each `[2N]`).
    scratch: [DVector<f64>; 3],
    region: Region,
    /// The position on the ladder: grid step j and the offset i in units of h/2^LEVELS
    /// (`None` off it).
    at: Option<(i64, u64)>,
    /// The points drawn in the last step, in τ order, and its region.
    points: Vec<Point>,
    last_region: Region,
}

/// Where a piece ends: its length, its rung (0 a grid step), its ladder position at the end.
type Piece = (f64, usize, Option<(i64, u64)>, Option<Arc<[Rung]>>);

impl ThermalExact {
    /// Build for `model` with `force`, the grid of the exact propagator for `opts` (a multiple
    /// of its steps per drive period 2π/Ω over each of the system's `drive_periods`, refined
    /// to resolve the fastest mode).
    ///
    /// # Errors
    /// The exact propagator's;
    /// [`SimError::OutOfRange`] naming `omega` or `drive_components.ratio` at an undamped
    /// natural frequency.
    pub fn new(
        model: &CantileverModel,
        opts: &IntegratorOptions,
        force: ThermalForce,
    ) -> Result<ThermalExact, SimError> {
        // steps per drive period 2π/Ω; the grid spans the system's period
        let exact = ExactOptions {
            min_steps_per_period: opts.steps_per_period * drive_periods(model),
            cache: Some(opts.cache.clone()),
            ..ExactOptions::default()
        };
        let lin = linear_part(model)?;
        let det = ExactPropagator::try_with(&grid_model(model, &lin)?, exact.clone())?;
        let affine = Affine::both(model, &lin, &det)?;
        let regions = [Region::Free, Region::Contact];
        let diffusion = regions.map(|r| state_diffusion(model, &lin, r, force.kt));
        let (h, omega) = (det.grid.h, model.omega());
        let ladders = regions.map(|r| {
            let sys = &affine[r.index()];
            ladder(&sys.a, &diffusion[r.index()], h, &sys.switching, omega)
        });
        let n = model.dim();
        // (none over SLS, whose recovering surface is a state of its own)
        let far = (!model.law().acts_outside() && model.zener().is_none())
            .then(|| Far::new(&lin, &diffusion[Region::Free.index()], force.kt))
            .flatten();
        let mut e = DVector::zeros(n);
        e.rows_mut(model.modes(), model.modes())
            .copy_from(model.tip_mobility());
        let unit = unit_response(&affine[0], &e)?;
        let components = [
            Component::of(model.params(), &affine[0], &e)?,
            // (none in the impact law's sticking: the constraint takes the tip's force)
            if sticking(model, Region::Contact) {
                Vec::new()
            } else {
                Component::of(model.params(), &affine[1], &e)?
            },
        ];
        Ok(ThermalExact {
            det,
            exact,
            model: model.clone(),
            lin,
            affine,
            unit,
            components,
            frozen: [0.0; 3],
            force,
            diffusion,
            ladders,
            odd: None,
            far,
            hold: 1,
            flights: Vec::new(),
            rng: seeded(force.seed, force.stream),
            dense_rng: seeded(force.seed ^ DENSE_STREAM, force.stream),
            tau: 0.0,
            sc: (0.0, 1.0),
            z: DVector::zeros(n),
            scratch: [0, 1, 2].map(|_| DVector::zeros(n)),
            region: Region::Free,
            at: Some((0, 0)),
            points: Vec::new(),
            last_region: Region::Free,
        })
    }

    /// Hold `samples` equally spaced points per drive period 2π/Ω (the recording's or the
    /// lock-in's): a free-flight step ends at the next of them at the latest, so that they are
    /// drawn points, not bridges. Without it, or where the grid does not hold them (a grid of a
    /// multiple of `samples` steps per period does; the grid spans the system's period,
    /// `drive_periods` drive periods), every grid point is held.
    pub fn holding(mut self, samples: usize) -> ThermalExact {
        let m = self.det.grid.m;
        let samples = samples * drive_periods(&self.model);
        self.hold = if samples > 0 && m.is_multiple_of(samples) {
            (m / samples) as i64
        } else {
            1
        };
        self
    }

    /// The thermal force.
    pub fn force(&self) -> ThermalForce {
        self.force
    }

    /// The grid's sub-steps per period of the system ([`CantileverModel::period`]: the drive
    /// period, or a multifrequency drive's common period).
    pub fn steps_per_period(&self) -> usize {
        self.det.grid.m
    }

    fn model(&self) -> &CantileverModel {
        &self.model
    }

    /// ζ, standard normals from stream `s` (0 the path's, 1 the dense output's).
    fn normals(&mut self, s: usize, zeta: &mut DVector<f64>) {
        let rng = if s == 0 {
            &mut self.rng
        } else {
            &mut self.dense_rng
        };
        zeta.iter_mut()
            .for_each(|x| *x = rng.sample(StandardNormal));
    }

    /// S ζ for a root S (2N × 2N) from stream `s`.
    fn draw(&mut self, root: &DMatrix<f64>, s: usize) -> DVector<f64> {
        let mut zeta = DVector::zeros(root.ncols());
        self.normals(s, &mut zeta);
        root * zeta
    }

    /// z_p(τ) of region `r` at (sin, cos) Ωτ = `sc`: the primary drive's and the further
    /// components'.
    fn zp(&self, r: Region, tau: f64, (s, c): (f64, f64)) -> DVector<f64> {
        let f = &self.affine[r.index()];
        let mut z = f.p0.clone();
        z.axpy(s, &f.ps, 1.0);
        z.axpy(c, &f.pc, 1.0);
        self.add_components(r, tau, 1.0, &mut z);
        z
    }

    /// z += `sign` × the further components' particular solution in region `r` at `tau`.
    fn add_components(&self, r: Region, tau: f64, sign: f64, z: &mut DVector<f64>) {
        for k in &self.components[r.index()] {
            let (s, c) = k.angle(tau);
            z.axpy(sign * s, &k.ps, 1.0);
            z.axpy(sign * c, &k.pc, 1.0);
        }
    }

    /// The further components' tip deflection in region `r` at `tau`.
    fn components_tip(&self, r: Region, tau: f64) -> f64 {
        let tip = |k: &Component| {
            let (s, c) = k.angle(tau);
            k.tip.0 * s + k.tip.1 * c
        };
        self.components[r.index()].iter().map(tip).sum()
    }

    /// The weights (F₀ + F₁ (τ − τ₀), F₁) of z_F and A⁻¹ z_F in the particular solution of the
    /// piece under way at `tau` (module docs).
    fn shift(&self, tau: f64) -> [f64; 2] {
        let [f0, f1, t0] = self.frozen;
        [f0 + f1 * (tau - t0), f1]
    }

    /// The particular solution of the piece under way at `tau`, (sin, cos) Ωτ = `sc`: z_p of
    /// region `r` and the response to its tip force.
    fn zs(&self, r: Region, tau: f64, sc: (f64, f64)) -> DVector<f64> {
        let mut z = self.zp(r, tau, sc);
        for (w, (u, _)) in self.shift(tau).into_iter().zip(&self.unit) {
            if w != 0.0 {
                z.axpy(w, u, 1.0);
            }
        }
        z
    }

    /// z less the particular solution of the piece under way at `tau` ([`ThermalExact::zs`]),
    /// (sin, cos) Ωτ = `sc`, into `out`.
    fn dz_into(
        &self,
        r: Region,
        tau: f64,
        (s, c): (f64, f64),
        z: &DVector<f64>,
        out: &mut DVector<f64>,
    ) {
        let f = &self.affine[r.index()];
        out.copy_from(z);
        *out -= &f.p0;
        out.axpy(-s, &f.ps, 1.0);
        out.axpy(-c, &f.pc, 1.0);
        self.add_components(r, tau, -1.0, out);
        for (w, (u, _)) in self.shift(tau).into_iter().zip(&self.unit) {
            if w != 0.0 {
                out.axpy(-w, u, 1.0);
            }
        }
    }

    /// The gap of z in region `r` at τ, (sin, cos) Ωτ = `sc`: V_T in free flight, −V_T in
    /// contact, |δ_f| − V_T there under a hysteretic law (JKR's neck, the capillary meniscus:
    /// left at V_T = |δ_f|, [`crate::contact::ContactLaw::release_distance`]), the constraint
    /// force λ in the impact law's sticking (left where λ falls to 0).
    fn gap(&self, r: Region, tau: f64, sc: (f64, f64), z: &DVector<f64>) -> f64 {
        self.gap_at(r, tau, sc, self.affine[r.index()].switching.dot(z))
    }

    /// [`ThermalExact::gap`] of a state whose switching row's value is `w`.
    fn gap_at(&self, r: Region, tau: f64, sc: (f64, f64), w: f64) -> f64 {
        let m = self.model();
        if sticking(m, r) {
            // λ(z, τ) = ∂λ/∂z·z + λ(0, τ)
            let zero = [0.0; crate::params::MAX_STATE];
            return w + m.guard_value(r, tau, &zero[..m.dim()]);
        }
        let v = m.v_t_at(sc, [w, 0.0, 0.0])[0];
        match r {
            Region::Free => v,
            Region::Contact => m.release_distance() - v,
        }
    }

    /// The gap of the bridge's mean at the middle of an interval of rung `rung` of region `r`
    /// from δz at its ends, (sin, cos) Ω of the middle `scm`: the mean's tip deflection
    /// u·δz_a + v·δz_b over z_p's W_p (module docs).
    fn mid_gap(
        &self,
        r: Region,
        rung: &Rung,
        tm: f64,
        scm: (f64, f64),
        da: &DVector<f64>,
        db: &DVector<f64>,
    ) -> f64 {
        let [w0, ws, wc] = self.affine[r.index()].wp;
        let [u, v] = &rung.mid.rows;
        let [c1, c2] = self.shift(tm);
        let forced = c1 * self.unit[0].1 + c2 * self.unit[1].1 + self.components_tip(r, tm);
        let w = w0 + ws * scm.0 + wc * scm.1 + forced + u.dot(da) + v.dot(db);
        self.gap_at(r, tm, scm, w)
    }

    /// How near to a time `t` a lattice point is taken for it: 1e-9 h, or [`ROUNDING_ULPS`]
    /// ulps of `t` where they are more.
    fn slack(&self, t: f64) -> f64 {
        (1e-9 * self.det.grid.h).max(ROUNDING_ULPS * f64::EPSILON * t.abs())
    }

    /// Whether a piece ending at `t` is within `tau_max`: at or before it, or past it by at
    /// most [`ThermalExact::slack`], as the exact propagator's step ends on its grid point
    /// (a piece to it stays a tabulated one, not one of an ulp with a ladder of its own).
    fn short_of(&self, t: f64, tau_max: f64) -> bool {
        t <= tau_max + self.slack(tau_max)
    }

    /// δ = h/2^[`LEVELS`], the ladder's finest piece: the resolution of a switching's time.
    fn resolution(&self) -> f64 {
        self.det.grid.h / (1u64 << LEVELS) as f64
    }

    /// τ of ladder position (j, i).
    fn lattice_tau(&self, (j, i): (i64, u64)) -> f64 {
        self.det.grid.tau(j) + i as f64 * self.resolution()
    }

    /// The next piece from the current state towards `tau_max`.
    fn next_piece(&mut self, tau_max: f64) -> Piece {
        let top = 1u64 << LEVELS;
        // the piece's force (under a nonlinear law) and the rung it allows
        let (frozen, stiff) = self.piece_force();
        self.frozen = frozen;
        if let Some((j, i)) = self.at {
            let k = if i == 0 {
                0
            } else {
                LEVELS - i.trailing_zeros() as usize
            }
            .max(stiff);
            let i1 = i + (top >> k);
            let end = if i1 == top { (j + 1, 0) } else { (j, i1) };
            let len = self.det.grid.h / (1u64 << k) as f64;
            if self.short_of(self.lattice_tau(end), tau_max) {
                return (len, k, Some(end), None);
            }
        }
        // off the ladder, or past tau_max: a piece with its own ladder to the next grid point
        // or to tau_max
        let jn = self.det.grid.next_index(self.tau);
        let t_grid = self.det.grid.tau(jn);
        let (t1, at) = if self.short_of(t_grid, tau_max) {
            (t_grid, Some((jn, 0)))
        } else {
            (tau_max, None)
        };
        let len = t1 - self.tau;
        let rungs = match &self.odd {
            Some((r, l, rungs)) if *r == self.region && *l == len => rungs.clone(),
            _ => {
                let r = self.region;
                let (sys, d) = (&self.affine[r.index()], &self.diffusion[r.index()]);
                let rungs = ladder(&sys.a, d, len, &sys.switching, self.model.omega());
                self.odd = Some((r, len, rungs.clone()));
                rungs
            }
        };
        let at = at.filter(|_| stiff == 0);
        (len / (1u64 << stiff) as f64, stiff, at, Some(rungs))
    }

    /// The tip force of the piece starting at the state, under a nonlinear law (module docs):
    /// [F₀, F₁, τ] with F₁ = ∂F_c/∂δ δ̇ + ∂F_c/∂δ̇ δ̈ (δ̈ the drift's: the linear part's and
    /// F₀ M⁻¹φ's, tip·M⁻¹φ = 1/m_eff; F₁ = 0 where not finite, a Kelvin–Voigt law's onset), and
    /// the piece's rung, ℓ ≤ [`STIFF_ETA`]/ω_c (h/2^[`LEVELS`] at the finest). One evaluation
    /// of the law per piece; under the linear law no force and rung 0.
    fn piece_force(&self) -> (Frozen, usize) {
        let (r, tau, sc, z) = (self.region, self.tau, self.sc, &self.z);
        if !self.nonlinear() {
            return ([0.0, 0.0, tau], 0);
        }
        let m = &self.model;
        let e = m.tip_force_eval(r, sc, z.as_slice());
        if e.force == 0.0 && e.d_delta == 0.0 && e.d_rate == 0.0 {
            return ([0.0, 0.0, tau], 0);
        }
        let (n, m_eff) = (m.modes(), m.effective_mass());
        let mut rate = DVector::zeros(z.len());
        self.lin.rhs(r, tau, z, &mut rate);
        let tip = m.tip();
        let w = [tip.dot(&z.rows(0, n)), tip.dot(&z.rows(n, n))];
        let wdd = tip.dot(&rate.rows(n, n)) + e.force / m_eff;
        let [_, vd, vdd] = m.v_t_at(sc, [w[0], w[1], wdd]);
        let f1 = -(e.d_delta * vd + e.d_rate * vdd);
        let omega_c = rate_of(&e, m_eff);
        let need = (self.det.grid.h * omega_c / STIFF_ETA).log2().ceil();
        let rung = if need.is_nan() || need <= 0.0 {
            0
        } else {
            (need as usize).min(LEVELS)
        };
        ([e.force, if f1.is_finite() { f1 } else { 0.0 }, tau], rung)
    }

    /// Whether the law is nonlinear (the exponential Euler step, module docs).
    fn nonlinear(&self) -> bool {
        !stepped_exactly(self.model.law())
    }

    /// Take `piece` in the current region: draw its end, search it for a switching; the first
    /// point across (τ, z, its offset in units of h/2^LEVELS from the piece's start) if any.
    fn take_piece(&mut self, piece: &Piece) -> Option<(f64, DVector<f64>, u64)> {
        let (len, k, at_end, odd) = piece;
        let rungs = odd
            .clone()
            .unwrap_or_else(|| self.ladders[self.region.index()].clone());
        let rung = &rungs[*k];
        let r = self.region;
        let (t0, sc0) = (self.tau, self.sc);
        let t1 = at_end.map_or(t0 + len, |e| self.lattice_tau(e));
        let sc1 = (self.model().omega() * t1).sin_cos();
        // δz₁ = Φ δz₀ + S ζ, z₁ = z_p(t₁) + δz₁
        let [mut dz0, mut zeta, mut dz1] = std::mem::take(&mut self.scratch);
        self.dz_into(r, t0, sc0, &self.z, &mut dz0);
        self.normals(0, &mut zeta);
        dz1.gemv(1.0, &rung.root, &zeta, 0.0);
        dz1.gemv(1.0, &rung.phi, &dz0, 1.0);
        let mut z1 = self.zs(r, t1, sc1);
        z1 += &dz1;
        let clear = self.gap(r, t1, sc1, &z1) > 0.0
            && self.mid_gap(
                r,
                rung,
                0.5 * (t0 + t1),
                turn(sc0, rung.half_turn),
                &dz0,
                &dz1,
            ) > KAPPA * rung.mid.tip_sd;
        self.scratch = [dz0, zeta, dz1];
        self.points.push((t1, z1.clone(), self.frozen));
        let span = (1u64 << LEVELS) >> k;
        let found = if clear {
            None
        } else {
            let a = (t0, sc0, self.z.clone(), 0);
            self.first_crossing(&rungs, *k, a, (t1, sc1, z1.clone(), span))
        };
        if found.is_none() {
            self.tau = t1;
            self.sc = sc1;
            self.z = z1;
            self.at = *at_end;
        }
        found
    }

    /// The event at the first point `z` across the surface from region `from` at `tau`: its
    /// region after, kind and the state after where it moves: a switching (the state
    /// unchanged), or under the impact law a release from sticking (unchanged) or an impact
    /// ([`ThermalExact::impact`]).
    fn event_at(
        &self,
        from: Region,
        tau: f64,
        z: &DVector<f64>,
    ) -> (Region, EventKind, Option<DVector<f64>>) {
        match (self.model.law().restitution(), from) {
            (None, _) => (from.other(), EventKind::Switching, None),
            (Some(_), Region::Contact) => (Region::Free, EventKind::Release, None),
            (Some(r), Region::Free) => {
                let (to, kind, after) = self.impact(r, tau, z);
                (to, kind, Some(after))
            }
        }
    }

    /// The impact at the first point `z` past the surface, located to δ = h/2^[`LEVELS`]
    /// (module docs): V_T = g ≤ 0, dV_T/dτ = v there, the drift's tip acceleration a. The
    /// surface was crossed Δ = g/v ∈ [0, δ] before (0 where v ≥ 0: a crossing the noise has
    /// already turned back) at the rate v_c = v − aΔ. The tip sticks (V_T = dV_T/dτ = 0) where
    /// the constraint force λ there is > 0 and the bounce b = −r v_c (v itself where v ≥ 0)
    /// would last 2 b m_eff/λ ≤ δ, beneath the resolution; else it bounces by Newton's law,
    /// dV_T/dτ⁺ = −r v_c, and is carried on to the point under a:
    /// V_T = Δ(−r v_c + aΔ/2), dV_T/dτ = −r v_c + aΔ (second order in δ). The change is
    /// m_eff M⁻¹φ times the change of V_T and of its rate: the least one in the kinetic metric
    /// ([`CantileverModel::start_projection`]'s).
    fn impact(&self, r: f64, tau: f64, z: &DVector<f64>) -> (Region, EventKind, DVector<f64>) {
        let m = &self.model;
        let (n, k, mobility) = (m.modes(), m.effective_mass(), m.tip_mobility());
        let delta = self.resolution();
        let (g, v) = (m.v_t(tau, z), m.v_t_dot(tau, z));
        let mut rate = DVector::zeros(z.len());
        m.rhs(Region::Free, tau, z, &mut rate);
        let sc = (m.omega() * tau).sin_cos();
        let wdd = m.tip().dot(&rate.rows(n, n));
        let a = m.v_t_at(sc, [0.0, 0.0, wdd])[2];
        let dt = if v < 0.0 {
            (g / v).clamp(0.0, delta)
        } else {
            0.0
        };
        let vc = (v - a * dt).min(0.0);
        let moved = |to: [f64; 2]| {
            let mut out = z.clone();
            out.rows_mut(0, n).axpy(k * (to[0] - g), mobility, 1.0);
            out.rows_mut(n, n).axpy(k * (to[1] - v), mobility, 1.0);
            out
        };
        let stuck = moved([0.0, 0.0]);
        let lambda = m.guard_value(Region::Contact, tau, stuck.as_slice());
        let bounce = if v < 0.0 { -r * vc } else { v };
        if lambda > 0.0 && 2.0 * bounce * k <= lambda * delta {
            return (Region::Contact, EventKind::Stick, stuck);
        }
        let after = if v < 0.0 {
            [dt * (bounce + 0.5 * a * dt), bounce + a * dt]
        } else {
            [0.0, v]
        };
        (Region::Free, EventKind::Impact, moved(after))
    }

    /// Whether a free-flight step from τ₀ to τ₁ is certified from δz at τ₀ (module docs).
    fn certified(&self, far: &Far, t0: f64, t1: f64, dz0: &DVector<f64>) -> bool {
        let b = super::tip::base_amp(self.model().params());
        let [w0, ws, wc] = self.affine[Region::Free.index()].wp;
        let (c0, r) = (self.model().params().alpha5 + w0, (ws + b).hypot(wc));
        let phase = wc.atan2(ws + b);
        let omega = self.model().omega();
        // the further components' tip deflection, bounded by its amplitudes
        let further: f64 = self.components[Region::Free.index()]
            .iter()
            .map(|k| k.tip.0.hypot(k.tip.1))
            .sum();
        let least = least_of_sine(c0, r, omega * t0 + phase, omega * t1 + phase) - further;
        let v = dz0.dot(&(&far.p_inv * dz0));
        least > far.sd * (v.sqrt() + FAR_KAPPA)
    }

    /// Φ and the root of Q of `c` grid steps of free flight (built once).
    fn flight(&mut self, c: i64) -> Arc<Flight> {
        if let Some((_, f)) = self.flights.iter().find(|(k, _)| *k == c) {
            return f.clone();
        }
        let a = &self.affine[Region::Free.index()].a;
        let d = &self.diffusion[Region::Free.index()];
        let (phi, q) = van_loan(a, d, c as f64 * self.det.grid.h);
        let f = Arc::new((phi, root(&q)));
        self.flights.push((c, f.clone()));
        f
    }

    /// A free-flight step from the grid point the state is on, towards `tau_max` and the next
    /// held point, if one is certified (module docs): `hold` grid steps from a held point, else
    /// the greatest power of two that fits, two grid steps at least; whether it was taken.
    fn free_flight(&mut self, tau_max: f64) -> bool {
        let (Some((j, 0)), Region::Free, Some(far)) = (self.at, self.region, self.far.as_ref())
        else {
            return false;
        };
        let grid = &self.det.grid;
        let last = grid.next_index(tau_max + self.slack(tau_max)) - 1;
        let room = ((j.div_euclid(self.hold) + 1) * self.hold).min(last) - j;
        if room < 2 {
            // one grid step: the searched step's test costs less than the certificate
            return false;
        }
        let c = if room == self.hold {
            room
        } else {
            1 << room.ilog2()
        };
        let (t0, t1) = (self.tau, grid.tau(j + c));
        // (a law that acts outside contact has no free flight: no force here)
        self.frozen = [0.0; 3];
        let [mut dz0, mut zeta, mut dz1] = std::mem::take(&mut self.scratch);
        self.dz_into(Region::Free, t0, self.sc, &self.z, &mut dz0);
        let ok = self.certified(far, t0, t1, &dz0);
        if ok {
            let f = self.flight(c);
            self.normals(0, &mut zeta);
            dz1.gemv(1.0, &f.1, &zeta, 0.0);
            dz1.gemv(1.0, &f.0, &dz0, 1.0);
            let sc1 = (self.model().omega() * t1).sin_cos();
            let mut z1 = self.zs(Region::Free, t1, sc1);
            z1 += &dz1;
            self.points.push((t1, z1.clone(), [0.0; 3]));
            (self.tau, self.sc, self.z, self.at) = (t1, sc1, z1, Some((j + c, 0)));
        }
        self.scratch = [dz0, zeta, dz1];
        ok
    }

    /// The first point at or past the surface in (a, b] on rung `k` of `rungs` (module docs).
    fn first_crossing(
        &mut self,
        rungs: &[Rung],
        k: usize,
        a: Probe,
        b: Probe,
    ) -> Option<(f64, DVector<f64>, u64)> {
        let r = self.region;
        let gb = self.gap(r, b.0, b.1, &b.2);
        if k >= LEVELS {
            return (gb <= 0.0).then_some((b.0, b.2, b.3));
        }
        let (tm, scm) = (0.5 * (a.0 + b.0), turn(a.1, rungs[k].half_turn));
        let mid = &rungs[k].mid;
        let (mut da, mut db) = (DVector::zeros(a.2.len()), DVector::zeros(b.2.len()));
        self.dz_into(r, a.0, a.1, &a.2, &mut da);
        self.dz_into(r, b.0, b.1, &b.2, &mut db);
        if gb > 0.0 && self.mid_gap(r, &rungs[k], tm, scm, &da, &db) > KAPPA * mid.tip_sd {
            return None;
        }
        let zm = self.zs(r, tm, scm) + mid.mean(&da, &db) + self.draw(&mid.root, 0);
        let im = (a.3 + b.3) / 2;
        let pos = self.points.partition_point(|p| p.0 < tm);
        self.points.insert(pos, (tm, zm.clone(), self.frozen));
        let m = (tm, scm, zm, im);
        if let Some(x) = self.first_crossing(rungs, k + 1, a, m.clone()) {
            return Some(x);
        }
        self.first_crossing(rungs, k + 1, m, b)
    }
}

impl Integrator for ThermalExact {
    current_fields!();
    /// `exact-thermal` under the linear law and SLS; `exponential-euler-thermal` under a
    /// nonlinear one (the step is then first order in its pieces, module docs).
    fn name(&self) -> &'static str {
        if self.nonlinear() {
            "exponential-euler-thermal"
        } else {
            "exact-thermal"
        }
    }

    /// The sample moved to α5 = `alpha5`: the model's constant forcing and the propagator's
    /// particular solutions rebuilt; Φ, Q and the bridges do not depend on the gap, and the
    /// random stream goes on (a scan's thermal force is one stream over its line, not one
    /// restarted every drive period).
    fn set_gap(&mut self, alpha5: f64) -> bool {
        let (mut model, mut lin) = (self.model.clone(), self.lin.clone());
        if model.set_gap(alpha5).is_err() || lin.set_gap(alpha5).is_err() {
            return false;
        }
        // (over SLS the grid's propagator does not depend on the gap: kept)
        if model.zener().is_none() {
            let Ok(det) = ExactPropagator::try_with(&lin, self.exact.clone()) else {
                return false;
            };
            self.det = det;
        }
        let Ok(affine) = Affine::both(&model, &lin, &self.det) else {
            return false;
        };
        (self.model, self.lin, self.affine) = (model, lin, affine);
        true
    }

    fn reset_in(&mut self, tau: f64, z: &DVector<f64>, region: Region) -> Result<(), SimError> {
        self.model.check_time_state(tau, z)?;
        let j = self.det.grid.next_index(tau) - 1;
        self.at = (self.det.grid.tau(j) == tau).then_some((j, 0));
        self.tau = tau;
        self.sc = (self.model.omega() * tau).sin_cos();
        self.z = z.clone();
        self.region = region;
        self.points.clear();
        Ok(())
    }

    /// Pieces of the ladder up to the next grid point or `tau_max`, or to the first switching.
    fn step(&mut self, tau_max: f64) -> Result<Step, SimError> {
        let (tau0, from) = (self.tau, self.region);
        self.points.clear();
        self.points.push((tau0, self.z.clone(), self.frozen));
        self.last_region = from;
        while self.tau < tau_max {
            if self.short_of(tau_max, self.tau) {
                // a target rounded a little past the point just reached is that point: the
                // state is kept (no piece of an ulp with a ladder of its own), its lattice
                // position too
                self.tau = tau_max;
                self.sc = (self.model().omega() * tau_max).sin_cos();
                break;
            }
            if self.free_flight(tau_max) {
                break;
            }
            let piece = self.next_piece(tau_max);
            let start = self.at;
            if let Some((tc, zc, off)) = self.take_piece(&piece) {
                // the path beyond the switching was drawn in the region it left
                self.points.retain(|p| p.0 <= tc);
                self.at = start.map(|(j, i)| {
                    let i1 = i + off;
                    if i1 == 1u64 << LEVELS {
                        (j + 1, 0)
                    } else {
                        (j, i1)
                    }
                });
                self.at = self.at.filter(|_| piece.3.is_none());
                let (to, kind, moved) = self.event_at(from, tc, &zc);
                let step = Step::with_event(self.model(), tau0, from, tc, &zc, to, kind);
                self.tau = tc;
                self.sc = (self.model().omega() * tc).sin_cos();
                self.z = moved.unwrap_or(zc);
                self.region = to;
                return Ok(step);
            }
            if self.at.is_some_and(|(_, i)| i == 0) || self.at.is_none() {
                break;
            }
        }
        crate::error::finite("thermal state", self.z.norm())?;
        Ok(Step::plain(tau0, self.tau, from))
    }

    /// [W, Ẇ, Ẅ] of the dense state; Ẅ is the drift's, the law's force at the point included
    /// (the thermal force has no value at a point).
    fn dense_tip(&mut self, tau: f64) -> [f64; 3] {
        let z = self.dense_state(tau);
        let m = self.model();
        let n = m.modes();
        let mut rate = DVector::zeros(z.len());
        m.rhs(self.last_region, tau, &z, &mut rate);
        let tip = m.tip();
        [
            tip.dot(&z.rows(0, n)),
            tip.dot(&z.rows(n, n)),
            tip.dot(&rate.rows(n, n)),
        ]
    }

    /// The drawn point at `tau`, else a draw from the bridge between the nearest drawn points
    /// of the last step (the second stream), kept so that later draws are conditioned on it.
    fn dense_state(&mut self, tau: f64) -> DVector<f64> {
        let tol = self.slack(tau);
        let pos = self.points.partition_point(|p| p.0 < tau - tol);
        if let Some(p) = self.points.get(pos).filter(|p| (p.0 - tau).abs() <= tol) {
            return p.1.clone();
        }
        if pos == 0 || pos == self.points.len() {
            // outside the last step: its nearest end
            let p = &self.points[pos.min(self.points.len() - 1)];
            return p.1.clone();
        }
        let ((ta, za, _), (tb, zb, fb)) = (&self.points[pos - 1], &self.points[pos]);
        let (ta, tb, za, zb, fb) = (*ta, *tb, za.clone(), zb.clone(), *fb);
        let r = self.last_region;
        // the bridge of the piece the point lies in: its frozen force, b's
        let frozen: Frozen = std::mem::replace(&mut self.frozen, fb);
        let sys = &self.affine[r.index()];
        let d = &self.diffusion[r.index()];
        let bridge = Bridge::new(&sys.a, d, tau - ta, tb - tau, &sys.switching);
        let omega = self.model.omega();
        let [sa, st, sb] = [ta, tau, tb].map(|t| (omega * t).sin_cos());
        let (mut da, mut db) = (DVector::zeros(za.len()), DVector::zeros(zb.len()));
        self.dz_into(r, ta, sa, &za, &mut da);
        self.dz_into(r, tb, sb, &zb, &mut db);
        let z = self.zs(r, tau, st) + bridge.mean(&da, &db) + self.draw(&bridge.root, 1);
        self.frozen = frozen;
        self.points.insert(pos, (tau, z.clone(), fb));
        z
    }

    fn last_step_jacobian(&mut self) -> Result<DMatrix<f64>, SimError> {
        Err(SimError::Unsupported {
            integrator: "exact-thermal",
            law: self.model.law_name(),
            hint: "a thermally driven run has no step Jacobian: drop temperature",
        })
    }
}

#[cfg(test)]
mod tests;
