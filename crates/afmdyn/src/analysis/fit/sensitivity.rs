//! Exact parametric sensitivities of a periodic orbit and of its first harmonic (issue 62 §1):
//! ∂z*/∂p, ∂A/∂p and ∂φ/∂p for the gap α5 (the rest distance, so `z_offset`), the Hertz group
//! α4 (∝ E*), DMT's van der Waals group H̃ (∝ H), the Hertz law's damper α6 and DMT's
//! Kelvin–Voigt group α6, for the Hertz and DMT laws (and JKR's groups, below).
//!
//! # Method
//! The model's state z (2N) is extended by the two Fourier integrals of the tip deflection
//! W(1,τ) = φᵀa against the drive, q_s' = W sin θ, q_c' = W cos θ (θ = Ωτ + ψ, ψ the drive's
//! phase, `crate::params::Params::drive_phase`), and by the parameters p with p' = 0. The
//! extended system's Jacobian has the parameter columns ∂f/∂p = (0, M⁻¹φ ∂F_c/∂p), with ∂F_c/∂p
//! in closed form from the law (F_c the law's force at δ = −V_T, δ̇ = −V̇_T, `d_force`):
//! * α5 enters through the gap, V_T = W(1,τ) + α2 sin Ωτ + α5 (eq. 8), so ∂F_c/∂α5 =
//!   −∂F_c/∂δ;
//! * both laws are linear in α4 (Hertz 1882; Johnson, *Contact Mechanics*, 1985, eq. 4.23: the
//!   repulsion α4 δ^{3/2} in contact), so ∂F_c/∂α4 = δ^{3/2} in contact, 0 outside;
//! * DMT is linear in H̃ (Derjaguin, Muller & Toporov, *J. Colloid Interface Sci.* 53 (1975)
//!   314: −H̃/(ã₀ + V_T)² outside contact, −H̃/ã₀² in it), so ∂F_c/∂H̃ is that force at H̃ = 1;
//! * the Hertz law's damper is linear in α6 (F_c = α4 δ^{3/2} + α6 δ̇ in contact,
//!   [`crate::contact::HertzLaw`]: a Kelvin–Voigt dashpot beside the Hertz spring), so
//!   ∂F_c/∂α6 = δ̇ in contact, 0 outside;
//! * DMT's Kelvin–Voigt term is linear in α6 (F_c = −H̃/ã₀² + α4 δ^{3/2} + α6 √δ δ̇ in contact,
//!   the damper ∝ the contact radius √(Rδ); García & San Paulo, *Phys. Rev. B* 60 (1999) 4961),
//!   so ∂F_c/∂α6 = √δ δ̇ in contact, 0 outside. Its ∂F_c/∂δ = (3/2)α4 √δ + α6 δ̇/(2√δ) is
//!   unbounded at contact onset (an integrable singularity, δ ≈ δ̇₀ t there): the force itself is
//!   continuous (f⁺ = f⁻, no saltation jump), and the variational equations converge at a reduced
//!   order in the tolerance (measured against fourth-order differences of the orbits on the
//!   RTESPA-300 point mass and the N = 3 beam, η > 0: α6's column within 6e-6 relative at the
//!   fit's tolerance 1e-9, within 2e-7 at 1e-11; the gap's and α4's within 1.5e-7 at 1e-9). The
//!   adaptive integrator cannot pass the onset at 1e-12 (1000 rejected steps): it says so.
//!
//! # The drive
//! The FM loop's unknowns (`super::fm_curve`) are the drive's α2 and Ω:
//! * α2 enters the forcing b(τ) = b₀ + b_s sin Ωτ + b_c cos Ωτ linearly
//!   (`CantileverModel::forcing_derivative`) and, on the base-driven beam, the tip force
//!   through V_T = W + α2 sin Ωτ + α5 and V̇_T = W' + α2 Ω cos Ωτ (eq. 8), so its column is
//!   ∂b/∂α2 + M⁻¹φ (−∂F_c/∂δ sin Ωτ − ∂F_c/∂δ̇ Ω cos Ωτ) there (the point mass's V_T has no
//!   drive term); the guard σV_T moves by σ sin Ωτ.
//! * Ω moves the period T = 2π/Ω. Rescaling time to the phase s = Ωτ fixes the period at 2π
//!   (the normalisation of a periodic orbit of unknown period: Seydel, *Practical Bifurcation
//!   and Stability Analysis*, Springer 2010, ch. 7): dz/ds = f(s/Ω, z; Ω)/Ω, with f depending
//!   on τ through Ωτ alone. Differentiating at fixed s and returning to τ, y = ∂z/∂Ω|_s obeys
//!   y' = J y − f/Ω + ∂f/∂Ω|_{Ωτ} over τ ∈ [0, T]: the column is −f/Ω plus the forcing
//!   coefficients' ∂b/∂Ω and the tip force's through V̇_T's α2 Ω cos Ωτ (−∂F_c/∂δ̇ α2 cos Ωτ);
//!   the guard does not move with Ω at fixed s. The Fourier coefficients c_s =
//!   (1/π)∫₀^{2π} W sin(s + ψ) ds then change by (2/T)∫₀^T (∂W/∂Ω|_s) sin θ dτ: the Fourier
//!   rows take no column of their own for Ω, and dc = (2/T) dq holds for every parameter.
//!
//! # The lever's damping
//! α3 sets the lever's damping matrix C^I = α3 diag(s) (eq. 12; s the damping profile, 1 in
//! the paper) and, on the base-driven beam, the forcing's base-velocity term −α2 α3 s_i ∫φ_i
//! cos Ωτ (eq. 14). The state's rate (ȧ, M⁻¹(F − C ȧ − K a + φ F_c)) is affine in α3, so its
//! column is (0, M⁻¹(∂F/∂α3(τ) − diag(s) ȧ)) (`CantileverModel::damping_derivative`); the
//! law's force, the guard σV_T and the saltation's jump do not move with α3.
//!
//! The adaptive integrator's variational equations of the extended system
//! ([`crate::integrate::adaptive`]; Hairer, Nørsett & Wanner, *Solving ODEs I*, §I.14: with
//! p as a state, the parameter columns of Φ obey d/dτ(∂x/∂p) = J ∂x/∂p + ∂f/∂p from 0) and the
//! saltation matrix of each switching of the extended system ([`crate::system::saltation`];
//! Leine & Nijmeijer 2004, §7.1: the guard σV_T moves with α5, ∂g/∂α5 = σ, so the parameter
//! column gains w ∂g/∂α5) give over one period the monodromy matrix of the extended map,
//! [[M, ∂P/∂p], [∂q/∂z, ∂q/∂p], [0, I]]. Hertz and DMT switch without a jump of the state
//! (R = I). Without damping their force is continuous at V_T = 0 (Hertz's is 0 at δ = 0;
//! DMT's is −H̃/ã₀² on both sides), so f⁺ = f⁻ there, the shift w is zero and the saltation
//! matrix is the identity. The Hertz damper's α6 δ̇ is not 0 at δ = 0: with α6 > 0 the vector
//! field jumps by M⁻¹φ α6 δ̇ at the switching, w ≠ 0 and S = I + w ∇gᵀ moves every column
//! (the state's, α5's and α2's through ∂g/∂p, the others through S alone). The guard σV_T does
//! not move with α6, α4 or H̃ (∂g/∂α6 = 0), so their columns take no w ∂g/∂p term of their
//! own. The saltation is applied at every switching, as the monodromy matrix of
//! [`crate::maps::flow`] applies it (`crate::system::saltation_parts`, with f⁺ and f⁻ of
//! the extended system), so nothing more is needed for α6.
//!
//! By the implicit function theorem on the shooting equations P(z*, p) = z*,
//! ∂z*/∂p = (I − M)⁻¹ ∂P/∂p, and the Fourier integrals' total derivatives are
//! dq/dp = ∂q/∂z · ∂z*/∂p + ∂q/∂p. With c_s = (2/T) q_s = A cos φ and c_c = (2/T) q_c =
//! −A sin φ (the harmonic A sin(θ − φ) of [`crate::analysis::observables`]),
//! dA = (c_s dc_s + c_c dc_c)/A and dφ = (c_c dc_s − c_s dc_c)/A².
//!
//! # Where it breaks
//! At a fold, I − M is singular (a multiplier at +1) and ∂z*/∂p is unbounded; at grazing, the
//! map is not differentiable. Both are reported as `SensitivityWarning`s, with their
//! measures: the smallest singular value of I − M against `fold_threshold` (`FOLD_TOL`, or
//! less for a high-Q lever whose free multipliers lie near +1), and the grazing distance
//! of the flow ([`crate::maps::flow::FlowMap::grazing_distance`]) against
//! `crate::analysis::shooting::GRAZING_TOL`.
//!
//! Units are the model's (lengths in g₀, τ, forces F̃). Only period-1 orbits; only the laws
//! `hertz` (with or without its damper α6 δ̇), `dmt` (with or without its Kelvin–Voigt term
//! α6 √δ δ̇) and `jkr` (below).
//!
//! # JKR
//! The law `jkr` takes α5, α4, its adhesion group P̃ (`OrbitParam::Adhesion`) and its
//! Kelvin–Voigt group α6 (the damper α6 q² δ̇):
//! its force at fixed δ moves through the root q(δ) of the contact radius, its contact guard
//! |δ_b| − V_T moves with α4 and P̃, and its force jumps where the contact forms and breaks, so
//! the saltation is not the identity there (`super::sensitivity_jkr` for the derivatives).

use crate::analysis::shooting::{shoot, ShootingOptions, GRAZING_TOL};
use crate::contact::{ContactLaw, DmtLaw, HertzLaw, Law, TipSample, TipSampleLaw};
use crate::error::SimError;
use crate::integrate::adaptive::Adaptive;
use crate::maps::flow::flow;
use crate::maps::StroboscopicMap;
use crate::model::{CantileverModel, DampingDerivative, ForcingDerivative};
use crate::params::{Params, SweepParam};
use crate::system::{Guard, HybridSystem, Jump, Region};
use crate::tip_sample::TipSampleSystem;
use nalgebra::{DMatrix, DVector};
use serde::Serialize;
use std::f64::consts::{PI, TAU};

pub(crate) use super::orbit_param::OrbitParam;

/// The smallest singular value of I − M below which an orbit counts as near a fold: there
/// (I − M)⁻¹ amplifies by more than 10³ and the sensitivities lose three digits.
pub(crate) const FOLD_TOL: f64 = 1e-3;

/// The smallest singular value of I − M below which an orbit of `model` over `period` counts
/// as near a fold: [`FOLD_TOL`], or a fifth of the free lever's own distance of a multiplier
/// from +1, min_k |1 − e^{λ_k T}| over the free structure's damped eigenvalues λ_k
/// ([`crate::eigen::damped_eigenvalues`]), when that is smaller. A lever driven at its
/// resonance has multipliers e^{λT} within ~π/Q of +1 without any fold (the free oscillation's
/// slow decay): at Q = 20 000, 1.6e-4, which [`FOLD_TOL`] alone would flag on every row.
pub(crate) fn fold_threshold(model: &CantileverModel, period: f64) -> f64 {
    let free = crate::eigen::damped_eigenvalues(model.galerkin().region(Region::Free));
    let scale = free
        .iter()
        .map(|l| {
            let decay = (l.re * period).exp();
            let turn = l.im * period;
            // |1 − e^{(re + i im)T}|
            (1.0 - decay * turn.cos()).hypot(decay * turn.sin())
        })
        .fold(f64::INFINITY, f64::min);
    FOLD_TOL.min(0.2 * scale)
}

/// Why a sensitivity is not to be trusted.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub(crate) enum SensitivityWarning {
    /// I − M is near singular (a multiplier near +1: a fold of the branch).
    NearFold {
        /// The smallest singular value of I − M.
        sigma_min: f64,
        /// The threshold it fell below ([`fold_threshold`]).
        threshold: f64,
    },
    /// The orbit (nearly) grazes the sample: the map is not differentiable there.
    Grazing {
        /// The flow's distance to grazing (units of g₀).
        distance: f64,
    },
}

impl std::fmt::Display for SensitivityWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SensitivityWarning::NearFold {
                sigma_min,
                threshold,
            } => f.write_str(&warning!(
                "fit.near-fold",
                "Leave the rows near the fold out of the fit (range), or take the \
                 intervals from the profile likelihood (profiles).",
                "near a fold: the smallest singular value of I − M is {sigma_min:.3e} \
                 (< {threshold:.3e}); the sensitivities (I − M)⁻¹ ∂P/∂p are unreliable there"
            )),
            SensitivityWarning::Grazing { distance } => f.write_str(&warning!(
                "fit.grazing",
                "Leave the rows where the tip first touches out of the fit (range), or \
                 take the intervals from the profile likelihood (profiles).",
                "a grazing orbit (distance {distance:.3e} < {GRAZING_TOL:e} g₀): the \
                 stroboscopic map is not differentiable there, so the sensitivities of this \
                 row, and the standard errors drawn from them, are unreliable; leave the rows \
                 where the tip first touches out of the fit (`range`) or take the intervals \
                 from the profile likelihood (`profiles`), which needs no derivative"
            )),
        }
    }
}

/// A period-1 orbit with its first harmonic and their exact parameter sensitivities.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct OrbitSensitivity {
    /// z* at τ = 0, shape `[2N]`.
    pub state: DVector<f64>,
    /// A₁ of the tip deflection (g₀), from the Fourier integrals of the extended flow.
    pub amplitude: f64,
    /// φ₁, the lag behind the drive (rad, in (−π/2, 3π/2]).
    pub phase: f64,
    /// ∂z*/∂p, 2N × k (k the parameters asked for, in their order).
    pub d_state: DMatrix<f64>,
    /// ∂A/∂p, shape `[k]`.
    pub d_amplitude: Vec<f64>,
    /// ∂φ/∂p (rad per unit p), shape `[k]`.
    pub d_phase: Vec<f64>,
    /// The monodromy matrix M, 2N×2N.
    pub monodromy: DMatrix<f64>,
    /// ∂P/∂p at fixed z, 2N × k.
    pub d_map: DMatrix<f64>,
    /// The smallest singular value of I − M.
    pub sigma_min: f64,
    /// The flow's distance to grazing (g₀).
    pub grazing_distance: f64,
    /// Near a fold or grazing.
    pub warnings: Vec<SensitivityWarning>,
    /// The harmonic of the tip deflection at a further drive component's frequency, when asked
    /// for ([`orbit_sensitivity`]: a bimodal drive's A₂, φ₂).
    pub component: Option<Harmonic>,
}

/// A harmonic A sin(ω_c τ + ψ_c − φ) of the tip deflection over the orbit's period, with its
/// exact parameter sensitivities.
#[derive(Debug, Clone, PartialEq)]
pub struct Harmonic {
    /// A (g₀).
    pub amplitude: f64,
    /// φ, the lag behind the component's drive (rad, in (−π/2, 3π/2]).
    pub phase: f64,
    /// ∂A/∂p, shape `[k]`.
    pub d_amplitude: Vec<f64>,
    /// ∂φ/∂p (rad per unit p), shape `[k]`.
    pub d_phase: Vec<f64>,
}

/// The harmonic of the Fourier integrals (q_s, q_c) over the period `period` and of their total
/// derivatives `dq` (2 × k): c_s = (2/T) q_s = A cos φ, c_c = (2/T) q_c = −A sin φ (module
/// docs).
fn harmonic(q: (f64, f64), dq: &DMatrix<f64>, period: f64) -> Harmonic {
    let scale = 2.0 / period;
    let (cs, cc) = (scale * q.0, scale * q.1);
    let amplitude = cs.hypot(cc);
    let mut phase = (-cc).atan2(cs);
    if phase <= -0.5 * PI {
        phase += TAU;
    }
    let a2 = amplitude * amplitude;
    let k = dq.ncols();
    let (mut d_amplitude, mut d_phase) = (Vec::with_capacity(k), Vec::with_capacity(k));
    for j in 0..k {
        let (dcs, dcc) = (scale * dq[(0, j)], scale * dq[(1, j)]);
        d_amplitude.push((cs * dcs + cc * dcc) / amplitude);
        d_phase.push((cc * dcs - cs * dcc) / a2);
    }
    Harmonic {
        amplitude,
        phase,
        d_amplitude,
        d_phase,
    }
}

/// ∂F_c/∂p of the law of `law` (groups α4 = `stiffness`, α6 = `damping`) at indentation δ =
/// `delta`, rate δ̇ = `rate`, in or out of contact (module docs). `None` for a law other than
/// Hertz, DMT and JKR, for H̃ of Hertz and JKR, and for the parameters that do not enter the
/// law: the drive's α2 and Ω (which move δ and δ̇ with the drive's phase), the lever's α3 and
/// the component force F̃₁ (the extended system forms their columns).
pub(crate) fn d_force(
    law: &ContactLaw,
    stiffness: f64,
    damping: f64,
    param: OrbitParam,
    contact: bool,
    delta: f64,
    rate: f64,
) -> Option<f64> {
    if let ContactLaw::Jkr { adhesion } = *law {
        // JKR's at fixed (δ, δ̇) through the root q(δ)
        return super::sensitivity_jkr::d_force(
            stiffness, adhesion, damping, param, contact, delta, rate,
        );
    }
    let a0 = match *law {
        ContactLaw::Hertz => None,
        ContactLaw::Dmt {
            intermolecular_distance,
            ..
        } => Some(intermolecular_distance),
        _ => return None,
    };
    Some(match param {
        OrbitParam::Gap => {
            let law = TipSample {
                law: *law,
                stiffness,
                damping,
            };
            -law.force(contact, delta, rate).d_delta
        }
        OrbitParam::ContactStiffness => HertzLaw.force(1.0, 0.0, contact, delta, 0.0).force,
        OrbitParam::Hamaker => {
            let a0 = a0?;
            DmtLaw {
                hamaker: 1.0,
                intermolecular_distance: a0,
            }
            .force(0.0, 0.0, contact, delta, 0.0)
            .force
        }
        OrbitParam::Damping => match a0 {
            // DMT's α6 √δ δ̇ at α6 = 1 (and α4 = H̃ = 0): √δ δ̇ in contact, 0 outside
            Some(a0) => {
                DmtLaw {
                    hamaker: 0.0,
                    intermolecular_distance: a0,
                }
                .force(0.0, 1.0, contact, delta, rate)
                .force
            }
            // Hertz's α6 δ̇ at α6 = 1 (and α4 = 0): δ̇ in contact, 0 outside
            None => HertzLaw.force(0.0, 1.0, contact, delta, rate).force,
        },
        OrbitParam::DriveAmplitude
        | OrbitParam::DriveFrequency
        | OrbitParam::LeverDamping
        | OrbitParam::ComponentForce => return None,
        OrbitParam::Adhesion => return None,
    })
}

/// The model extended by the Fourier integrals and the parameters (module docs): state
/// (z, q_s, q_c, p), dimension 2N + 2 + k.
#[derive(Debug, Clone)]
struct Extended {
    model: CantileverModel,
    params: Vec<OrbitParam>,
    /// ∂b/∂α2 and ∂b/∂Ω of the free region's forcing (the one Hertz and DMT integrate, their
    /// tip force added), `None` when no drive parameter is asked for.
    forcing: [Option<ForcingDerivative>; 2],
    /// ∂f/∂α3 of the free region, when α3 is asked for.
    lever: Option<DampingDerivative>,
    /// The harmonics demodulated, (ω, ψ) each, the drive's first: the Fourier rows 2h, 2h + 1
    /// after the model's state integrate W sin(ωτ + ψ) and W cos(ωτ + ψ).
    harmonics: Vec<(f64, f64)>,
}

impl Extended {
    fn base(&self) -> usize {
        self.model.dim()
    }
    /// The first parameter's row: after the model's state and the Fourier rows.
    fn first_param(&self) -> usize {
        self.base() + 2 * self.harmonics.len()
    }
    fn plain(&self, z: &DVector<f64>) -> DVector<f64> {
        z.rows(0, self.base()).into_owned()
    }
    /// W(1,τ) = φᵀa and W' = φᵀȧ of the model's state `z`.
    fn tip_pair(&self, z: &[f64]) -> (f64, f64) {
        let n = self.model.modes();
        let tip = self.model.tip();
        let dot = |x: &[f64]| tip.iter().zip(x).map(|(a, b)| a * b).sum::<f64>();
        (dot(&z[..n]), dot(&z[n..2 * n]))
    }
    /// The column ∂f/∂p_k of the model's rows (2N) at (τ, z) in `mode`: M⁻¹φ ∂F_c/∂p for the
    /// law's parameters; for the drive's, the forcing's derivative plus the tip force's through
    /// V_T and V̇_T, and for Ω at a fixed phase also −f/Ω (module docs, *The drive*).
    fn param_column(&self, mode: Region, tau: f64, z: &[f64], k: usize, out: &mut [f64]) {
        let m = &self.model;
        let n = m.modes();
        out.fill(0.0);
        let param = self.params[k];
        let df = match param {
            OrbitParam::DriveAmplitude | OrbitParam::DriveFrequency => {
                let p = m.params();
                let om = m.omega();
                let (s, c) = (om * tau).sin_cos();
                let fd = &self.forcing[usize::from(param == OrbitParam::DriveFrequency)];
                if let Some(fd) = fd {
                    for (i, o) in out.iter_mut().enumerate() {
                        *o = fd.b_const[i] + s * fd.b_sin[i] + c * fd.b_cos[i];
                    }
                }
                let (w, wd) = self.tip_pair(z);
                let [v, vd, _] = m.v_t_from_tip(tau, [w, wd, 0.0]);
                let law = TipSample {
                    law: p.contact_law,
                    stiffness: p.alpha4,
                    damping: p.alpha6,
                };
                let f = law.force(mode == Region::Contact, -v, -vd);
                // δ = −V_T, δ̇ = −V̇_T with V_T = W + b sin Ωτ + α5 and V̇_T = W' + b Ω cos Ωτ
                // (b = α2 on the base-driven beam, 0 under a tip force)
                let unit = p.with(SweepParam::Alpha2, 1.0).base_amplitude();
                if param == OrbitParam::DriveAmplitude {
                    -f.d_delta * unit * s - f.d_rate * unit * om * c
                } else {
                    let mut rhs = vec![0.0; m.dim()];
                    m.rhs_slice(mode, tau, z, &mut rhs);
                    for (o, r) in out.iter_mut().zip(&rhs) {
                        *o -= r / om;
                    }
                    -f.d_rate * p.base_amplitude() * c
                }
            }
            // the first further component's tip force F̃₁ cos(ω₁τ + θ₁) (Params::component_force)
            OrbitParam::ComponentForce => m
                .params()
                .components()
                .next()
                .map_or(0.0, |c| (c.ratio() * m.omega() * tau + c.phase).cos()),
            OrbitParam::LeverDamping => {
                if let Some(ld) = &self.lever {
                    let (s, c) = (m.omega() * tau).sin_cos();
                    let fd = &ld.forcing;
                    for (i, o) in out.iter_mut().enumerate() {
                        *o = fd.b_const[i] + s * fd.b_sin[i] + c * fd.b_cos[i];
                    }
                    let rate = &z[n..2 * n];
                    for i in 0..n {
                        out[n + i] += (0..n).map(|j| ld.velocity[(i, j)] * rate[j]).sum::<f64>();
                    }
                }
                0.0
            }
            _ => self.d_force(mode, tau, z, k),
        };
        for (o, mob) in out[n..].iter_mut().zip(m.tip_mobility().iter()) {
            *o += mob * df;
        }
    }

    /// ∂F_c/∂p_k at (τ, z) in `mode`.
    fn d_force(&self, mode: Region, tau: f64, z: &[f64], k: usize) -> f64 {
        let m = &self.model;
        let p = m.params();
        let (w, wd) = self.tip_pair(z);
        let [v, vd, _] = m.v_t_from_tip(tau, [w, wd, 0.0]);
        d_force(
            &p.contact_law,
            p.alpha4,
            p.alpha6,
            self.params[k],
            mode == Region::Contact,
            -v,
            -vd,
        )
        .unwrap_or(0.0)
    }
}

impl HybridSystem for Extended {
    fn dim(&self) -> usize {
        self.first_param() + self.params.len()
    }
    fn period(&self) -> f64 {
        HybridSystem::period(&self.model)
    }
    fn mode_at(&self, tau: f64, z: &[f64]) -> Region {
        self.model.mode_at(tau, &z[..self.base()])
    }
    fn rhs(&self, mode: Region, tau: f64, z: &[f64], dz: &mut [f64]) {
        let d = self.base();
        self.model.rhs_slice(mode, tau, &z[..d], &mut dz[..d]);
        let (w, _) = self.tip_pair(z);
        for (h, (om, psi)) in self.harmonics.iter().enumerate() {
            let (s, c) = (om * tau + psi).sin_cos();
            dz[d + 2 * h] = w * s;
            dz[d + 2 * h + 1] = w * c;
        }
        dz[self.first_param()..].fill(0.0);
    }
    fn jacobian(&self, mode: Region, tau: f64, z: &[f64], jac: &mut DMatrix<f64>) {
        let d = self.base();
        // the model's own (2N×2N) block, written by the model into the top-left corner of the
        // larger matrix after zeroing it (its jacobian of a larger matrix)
        self.model.jacobian(mode, tau, &z[..d], jac);
        for (h, (om, psi)) in self.harmonics.iter().enumerate() {
            let (s, c) = (om * tau + psi).sin_cos();
            for (j, t) in self.model.tip().iter().enumerate() {
                jac[(d + 2 * h, j)] = t * s;
                jac[(d + 2 * h + 1, j)] = t * c;
            }
        }
        let first = self.first_param();
        let mut col = vec![0.0; d];
        for k in 0..self.params.len() {
            self.param_column(mode, tau, &z[..d], k, &mut col);
            for (i, v) in col.iter().enumerate() {
                jac[(i, first + k)] = *v;
            }
        }
    }
    fn guard(&self, mode: Region, tau: f64, z: &[f64]) -> Guard {
        let d = self.base();
        let g = self.model.guard(mode, tau, &z[..d]);
        let mut grad = DVector::zeros(self.dim());
        grad.rows_mut(0, d).copy_from(&g.grad);
        for (k, p) in self.params.iter().enumerate() {
            // the guard σV_T moves with α5 and, on the base-driven beam, with α2; at a fixed
            // phase Ωτ it does not move with Ω
            let sweep = match p {
                OrbitParam::Gap => SweepParam::Alpha5,
                OrbitParam::DriveAmplitude => SweepParam::Alpha2,
                _ => continue,
            };
            grad[self.first_param() + k] = self
                .model
                .guard_param_derivative(mode, sweep, tau)
                .unwrap_or(0.0);
        }
        if let ContactLaw::Jkr { adhesion } = self.model.params().contact_law {
            // JKR's contact guard |δ_b| − V_T moves with α4 and P̃ (sensitivity_jkr)
            let alpha4 = self.model.params().alpha4;
            for (k, &p) in self.params.iter().enumerate() {
                if let Some(dg) = super::sensitivity_jkr::d_guard(alpha4, adhesion, mode, p) {
                    grad[self.first_param() + k] = dg;
                }
            }
        }
        Guard {
            value: g.value,
            grad,
            d_tau: g.d_tau,
        }
    }
    fn guard_value(&self, mode: Region, tau: f64, z: &[f64]) -> f64 {
        self.model.guard_value(mode, tau, &z[..self.base()])
    }
    fn guard_tolerance(&self, mode: Region, tau: f64, z: &[f64]) -> f64 {
        self.model.guard_tolerance(mode, tau, &z[..self.base()])
    }
    fn jump(&self, from: Region, tau: f64, z: &[f64]) -> Jump {
        // Hertz and DMT switch without a jump of the state (R = I): the model's region after
        let to = self.model.jump(from, tau, &z[..self.base()]).to;
        Jump::switching(to, z)
    }
    fn is_affine(&self) -> bool {
        false
    }
}

impl TipSampleSystem for Extended {
    fn modes(&self) -> usize {
        self.model.modes()
    }
    fn omega(&self) -> f64 {
        self.model.omega()
    }
    fn tip(&self) -> &DVector<f64> {
        self.model.tip()
    }
    fn v_t_from_tip(&self, tau: f64, w: [f64; 3]) -> [f64; 3] {
        self.model.v_t_from_tip(tau, w)
    }
    fn tip_values(&self, tau: f64, z: &DVector<f64>) -> [f64; 4] {
        self.model.tip_values(tau, &self.plain(z))
    }
    fn law_name(&self) -> &'static str {
        self.model.law().name()
    }
}

/// The period-1 orbit of `model` near `guess` (polished by Newton, `newton`, on the adaptive
/// integrator of tolerance `tol`; `None`: `guess` is taken as the orbit, as a stepped sweep
/// converged it with its own integrator), its first harmonic and their exact sensitivities to
/// `params` (module docs); with `component` = Some(c) also the harmonic of the tip
/// deflection at the further drive component c's frequency (1-based among
/// [`crate::params::Params::components`]: the bimodal drive's second, c = 1), ω_c = (p/q) Ω
/// with ψ_c = θ_c + π/2 (its force F̃ cos(ω_c τ + θ_c) = F̃ sin(ω_c τ + ψ_c)), demodulated over
/// the drive's common period (a whole number of the component's periods), as
/// [`crate::analysis::observables::ComponentObservables`] does: A₂, φ₂ and their sensitivities
/// from a second pair of Fourier integrals of the same extended flow.
///
/// # Errors
/// [`SimError::Unsupported`] for a law other than Hertz, DMT and JKR, for H̃ under Hertz or
/// JKR, and for P̃ ([`OrbitParam::Adhesion`]) under another law;
/// [`SimError::NoConvergence`] from the Newton solve; [`SimError::OutOfRange`] naming
/// `component` when the drive has no such component; [`SimError`] from the integrator.
pub(crate) fn orbit_sensitivity(
    model: &CantileverModel,
    tol: f64,
    guess: &DVector<f64>,
    params: &[OrbitParam],
    newton: Option<&ShootingOptions>,
    component: Option<usize>,
) -> Result<OrbitSensitivity, SimError> {
    let harmonics = demodulated(model.params(), component)?;
    check_law(model, params)?;
    let (state, shot_grazing) = match newton {
        Some(newton) => {
            let mut plain = Adaptive::new(model, tol);
            let newton = newton.with_period(1);
            let orbit = shoot(&mut StroboscopicMap::new(&mut plain, 1), guess, &newton)?;
            (orbit.state, orbit.grazing_distance)
        }
        None => (guess.clone(), f64::INFINITY),
    };
    let ext = extended(model, params, harmonics)?;
    let first = ext.first_param();
    let (d, k) = (model.dim(), params.len());
    let mut y0 = DVector::zeros(ext.dim());
    y0.rows_mut(0, d).copy_from(&state);
    let mut integ = Adaptive::new(&ext, tol);
    let period = HybridSystem::period(model);
    let flow = flow(&mut integ, 0.0, &y0, period, None, true)?;
    let big = &flow.jacobian;
    let m = big.view((0, 0), (d, d)).into_owned();
    let d_map = big.view((0, first), (d, k)).into_owned();
    // the Fourier integrals' total derivatives dq/dp = ∂q/∂z ∂z*/∂p + ∂q/∂p, pair h at rows
    // d + 2h
    let dq_of = |h: usize, d_state: &DMatrix<f64>| {
        let dq_dz = big.view((d + 2 * h, 0), (2, d)).into_owned();
        let dq_dp = big.view((d + 2 * h, first), (2, k)).into_owned();
        dq_dz * d_state + dq_dp
    };
    let i_m = DMatrix::identity(d, d) - &m;
    let sigma_min = i_m
        .clone()
        .singular_values()
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let d_state = i_m.lu().solve(&d_map).ok_or(SimError::NoConvergence {
        what: "orbit sensitivity: I − M is singular (a fold)",
        iterations: 0,
        residual: sigma_min,
    })?;
    let pair = |h: usize| (flow.state[d + 2 * h], flow.state[d + 2 * h + 1]);
    let Harmonic {
        amplitude,
        phase,
        d_amplitude,
        d_phase,
    } = harmonic(pair(0), &dq_of(0, &d_state), period);
    let component = (component.is_some()).then(|| harmonic(pair(1), &dq_of(1, &d_state), period));
    let mut warnings = Vec::new();
    let threshold = fold_threshold(model, period);
    if sigma_min < threshold {
        warnings.push(SensitivityWarning::NearFold {
            sigma_min,
            threshold,
        });
    }
    let grazing_distance = flow.grazing_distance.min(shot_grazing);
    if grazing_distance < GRAZING_TOL {
        warnings.push(SensitivityWarning::Grazing {
            distance: grazing_distance,
        });
    }
    Ok(OrbitSensitivity {
        state,
        amplitude,
        phase,
        d_state,
        d_amplitude,
        d_phase,
        monodromy: m,
        d_map,
        sigma_min,
        grazing_distance,
        warnings,
        component,
    })
}

/// The harmonics demodulated, (ω, ψ): the drive's, and with `component` = Some(c) the further
/// component c's (1-based) at ω_c = (p/q) Ω with ψ_c = θ_c + π/2.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `component` when the drive has no such component.
fn demodulated(p: &Params, component: Option<usize>) -> Result<Vec<(f64, f64)>, SimError> {
    let mut harmonics = vec![(p.omega, p.drive_phase())];
    if let Some(c) = component {
        let comp = c
            .checked_sub(1)
            .and_then(|i| p.components().nth(i))
            .ok_or_else(|| {
                SimError::out_of_range(
                    "component",
                    c,
                    format!(
                        "1..={}, the further components of the drive",
                        p.components().count()
                    ),
                )
            })?;
        harmonics.push((
            comp.ratio() * p.omega,
            comp.phase + std::f64::consts::FRAC_PI_2,
        ));
    }
    Ok(harmonics)
}

/// The sensitivities to `params` are not taken under `model`'s law: `hint` says why.
fn unsupported(model: &CantileverModel, hint: &'static str) -> SimError {
    SimError::Unsupported {
        integrator: "adaptive",
        law: model.law().name(),
        hint,
    }
}

/// `model`'s law has sensitivities to `params`: Hertz, DMT or JKR, H̃ DMT's and P̃ JKR's.
///
/// # Errors
/// [`SimError::Unsupported`] saying which is not.
fn check_law(model: &CantileverModel, params: &[OrbitParam]) -> Result<(), SimError> {
    let law = model.params().contact_law;
    match law {
        ContactLaw::Hertz => {
            if params.contains(&OrbitParam::Hamaker) {
                return Err(unsupported(model, "the Hertz law has no Hamaker group"));
            }
        }
        ContactLaw::Dmt { .. } => {}
        ContactLaw::Jkr { .. } => {
            if params.contains(&OrbitParam::Hamaker) {
                return Err(unsupported(model, "the JKR law has no Hamaker group"));
            }
        }
        _ => {
            return Err(unsupported(
                model,
                "exact orbit sensitivities are implemented for the hertz, dmt and jkr laws",
            ))
        }
    }
    if !matches!(law, ContactLaw::Jkr { .. }) && params.contains(&OrbitParam::Adhesion) {
        return Err(unsupported(model, "the adhesion group P̃ is the jkr law's"));
    }
    Ok(())
}

/// The flow of `model` extended by the sensitivities to `params` and the Fourier integrals of
/// the `harmonics`, with the derivatives of the free region's forcing by α2 and Ω and of the
/// lever's damping that `params` ask for.
///
/// # Errors
/// [`SimError::Unsupported`] for the component force without a further drive component or
/// the drive frequency under a multifrequency drive; [`SimError::NoConvergence`] where the
/// mass matrix is not positive definite (the damping's derivative).
fn extended(
    model: &CantileverModel,
    params: &[OrbitParam],
    harmonics: Vec<(f64, f64)>,
) -> Result<Extended, SimError> {
    let p = model.params();
    if params.contains(&OrbitParam::ComponentForce) && p.components().next().is_none() {
        return Err(unsupported(
            model,
            "the component force's sensitivity needs a drive with a further component",
        ));
    }
    let drive = [OrbitParam::DriveAmplitude, OrbitParam::DriveFrequency];
    // the further components' forces do not move with α2 (the primary's), but their phases
    // move with Ω
    if p.is_multifrequency() && params.contains(&OrbitParam::DriveFrequency) {
        return Err(unsupported(
            model,
            "the drive frequency's sensitivity is taken for a single-frequency drive",
        ));
    }
    // the free region's forcing derivatives (Hertz and DMT integrate region I's dynamics)
    let forcing = [SweepParam::Alpha2, SweepParam::Omega].map(|q| {
        let asked = params.contains(&drive[usize::from(q == SweepParam::Omega)]);
        asked
            .then(|| model.forcing_derivative(q))
            .flatten()
            .map(|[free, _]| free)
    });
    let lever = if params.contains(&OrbitParam::LeverDamping) {
        Some(model.damping_derivative().ok_or(SimError::NoConvergence {
            what: "orbit sensitivity: the mass matrix is not positive definite",
            iterations: 0,
            residual: f64::NAN,
        })?)
    } else {
        None
    };
    Ok(Extended {
        model: model.clone(),
        params: params.to_vec(),
        forcing,
        lever,
        harmonics,
    })
}
