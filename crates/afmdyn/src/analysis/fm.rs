//! Frequency-modulation AFM (FM-AFM) at constant amplitude: the steady state of a cantilever
//! driven by an ideal phase-locked loop and an ideal amplitude controller, as an exact periodic
//! orbit, over the rest distance z_c (issue 44 item 3).
//!
//! **The loop.** An FM-AFM instrument drives the cantilever at the frequency where the tip's
//! first harmonic lags the excitation by the phase of the free lever at its resonance (90° for
//! the point mass: the PLL keeps the excitation in quadrature with the motion), with the
//! excitation amplitude adjusted so that the first-harmonic amplitude stays at its setpoint A
//! (Albrecht, Grütter, Horne & Rugar, *J. Appl. Phys.* 69 (1991) 668; Giessibl, *Rev. Mod.
//! Phys.* 75 (2003) 949, §III). With both loops ideal (infinitely fast and exact) the steady
//! state is a periodic orbit of the forced model whose drive frequency Ω and amplitude α2 are
//! unknowns, fixed by two conditions on the orbit:
//!
//! A₁(Ω, α2) = A,  φ₁(Ω, α2) = φ_set,
//!
//! with A₁ and φ₁ the first-harmonic amplitude and lag of the tip deflection behind the drive
//! ([`super::observables`], its conventions) and φ_set the lag of the free linear response at
//! the natural frequency ω_K of the tracked mode K (`super::resonance::mode_resonance`;
//! [`FmReference`]). The orbit is found by Newton shooting on the stroboscopic map at each
//! (Ω, α2) ([`super::shooting`]), and (Ω, α2) by Newton's method on the two conditions, its
//! 2×2 Jacobian by forward differences and then Broyden's secant update (Broyden, *Math.
//! Comp.* 19 (1965) 577) — the orbit's own accuracy is the shooting's, the conditions are met
//! to [`FmSpec::tolerance`]. Where that nested solve fails — at high Q, where M − I is nearly
//! singular (the multipliers e^{−πΩ/Q ± iθ} lie within π/Q of 1: ‖(I − M)⁻¹‖ ≈ Q/π), and the
//! lower turning point crosses the DMT edge, whose force gradient jumps, so that shooting
//! stalls — the orbit and the conditions are solved together by Newton's method on the
//! augmented system in (z, Ω, α2) (`Solver::lock_augmented`), and as a last
//! resort the phase condition is bracketed in Ω (`Solver::lock_bracketed`). The curve is
//! followed in z_c by natural-parameter continuation with a secant predictor; a value that does
//! not converge is approached in halved steps.
//!
//! **Reported.** The frequency shift Δω = Ω − ω_K, the excitation relative to the free one
//! (α2 over the α2 that holds amplitude A at ω_K without a sample), and the observables of the
//! orbit. The energy the drive puts in per cycle is π α2 A₁ sin φ₁ times the drive's gain
//! (point mass: exactly; [`super::observables`], the exact period balances), so the excitation
//! grows by the energy the sample takes: for the point mass at φ₁ = 90°,
//! π α2 A = (π/Q) Ω (A² + Σ_{n≥2} n²Aₙ²) + E_dis.
//!
//! **Stability.** `stable` is the Floquet stability of the orbit under the locked drive: what
//! loops much slower than the cantilever's response (bandwidths below ω_K/Q) see. With fast
//! loops the closed loop's stability differs and is not modelled.
//!
//! **Folds.** A fold of the curve in z_c is where the conditions' Jacobian ∂(A₁, φ₁)/∂(Ω, α2)
//! is singular; [`FmCurve::folds`] lists the values between which its determinant changes sign.
//! The curve cannot be continued through a fold by natural-parameter continuation; it ends
//! there with a warning.

use super::observables::{free_response, observe, observe_orbit, ObservableOptions, Observables};
use super::progress::Progress;
use super::resonance::mode_resonance;
use super::shooting::{shoot, PeriodicOrbit, ShootingOptions, ShootingStrategy};
use crate::contact::{TipSample, TipSampleLaw};
use crate::error::SimError;
use crate::integrate::{build, IntegratorOptions};
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::{Complex, DVector, Matrix2, Vector2};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};

pub mod noise;
mod solver;
use solver::{predict, Locked, Solver};

/// The FM loops' gains and limits: the time-domain loop's ([`super::fm_loop`]) and the closed
/// loop's of the noise's linear response ([`noise`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LoopSpec {
    /// g_φ: the PLL's gain per cycle ([`super::fm_loop`]).
    pub phase_gain: f64,
    /// g_A: the amplitude controller's gain per cycle.
    pub amplitude_gain: f64,
    /// Most cycles per value.
    pub max_cycles: usize,
    /// Settling tolerance of |A₁/A − 1| and |φ₁ − φ_set| (rad).
    pub tolerance: f64,
}

impl LoopSpec {
    /// Gains a third of the stability bound π/Q_K (and at most 0.3), at most 200 Q_K cycles per
    /// value, tolerance 1e-7.
    pub fn new(quality_factor: f64) -> Self {
        let g = (std::f64::consts::PI / (3.0 * quality_factor)).min(0.3);
        LoopSpec {
            phase_gain: g,
            amplitude_gain: g,
            max_cycles: (200.0 * quality_factor).clamp(1e3, 1e7) as usize,
            tolerance: 1e-7,
        }
    }
}

/// Default tolerance of the two loop conditions: |A₁/A − 1| and |φ₁ − φ_set| (rad).
pub(crate) const DEFAULT_LOOP_TOLERANCE: f64 = 1e-9;
/// Default tolerance of the integrator of the orbits ([`FmSpec::new`]).
pub(crate) const DEFAULT_ORBIT_TOLERANCE: f64 = 1e-13;
/// The loop conditions are met to the tolerance, or, where the orbit's own error bounds them
/// (module docs, [`FmSpec::new`]), to this many times Q_K × the integrator's tolerance once
/// Newton stops gaining.
pub(crate) const NOISE_FLOOR_FACTOR: f64 = 1e3;
/// A shooting that stops above its tolerance at a residual r ≤ [`ROUND_OFF_LIMIT`] (the map's
/// round-off floor) is taken again to this many times r.
pub(crate) const ROUND_OFF_RETRY: f64 = 4.0;
/// The largest fixed-point residual taken as the map's round-off.
pub(crate) const ROUND_OFF_LIMIT: f64 = 1e-7;
/// … plus this many times Q_K × the orbit's fixed-point residual (an orbit error δz moves
/// the first harmonic by up to Q δz/π).
pub(crate) const ORBIT_FLOOR_FACTOR: f64 = 10.0;
/// The largest loop residual accepted at the orbit's round-off floor (1e-6 rad of phase: at
/// Q = 10⁴ and f0 = 300 kHz, 2e-5 Hz of frequency shift).
pub(crate) const MAX_LOOP_RESIDUAL: f64 = 1e-6;
/// Most Newton iterations on (Ω, α2) per value.
pub(crate) const MAX_LOOP_ITERATIONS: usize = 30;
/// Most failures (each halving the step in z_c) on the way to one value.
pub(crate) const MAX_HALVINGS: usize = 6;
/// Step of the forward differences of the loop Jacobian: relative in α2; in Ω relative to the
/// half linewidth ω_K/(2Q_K) (across which the phase turns by about 1 rad), so that the phase
/// moves by about this many rad, well above its round-off and well inside its linear range.
const DIFFERENCE_STEP: f64 = 1e-5;
/// Step of the forward differences in the state of the augmented Newton, times 1 + max|z|.
const AUGMENTED_STATE_STEP: f64 = 1e-7;
/// Most halvings of a Newton step on (Ω, α2) that does not lower the loop residual.
const BACKTRACKS: usize = 10;

/// What to compute: an FM curve over the gap values `values` (α5, approach order).
#[derive(Debug, Clone, PartialEq)]
pub struct FmSpec {
    /// The model; α5, Ω and α2 are overwritten.
    pub base: Params,
    /// α5 values in the order they are visited, at least 1.
    pub values: Vec<f64>,
    /// The amplitude setpoint A of the first harmonic (units of g₀), > 0.
    pub amplitude: f64,
    /// The tracked mode K (1-based).
    pub mode: usize,
    /// Integrator of the orbits and observables.
    pub integrator: IntegratorOptions,
    /// Newton shooting of the (period-1) orbit at each (Ω, α2); globalised where Newton stalls.
    pub newton: ShootingOptions,
    /// Tolerance of the loop conditions (relative amplitude, phase in rad), in (0, 1e-3).
    pub tolerance: f64,
}

impl FmSpec {
    /// Defaults: mode 1, tolerance `DEFAULT_LOOP_TOLERANCE`, the integrator's tolerance
    /// `DEFAULT_ORBIT_TOLERANCE`, shooting to 1e-12 in at most 20 Newton
    /// iterations, or, where the map's round-off is above that (a viscous √δ δ̇ contact: near
    /// 1e-10), to `ROUND_OFF_RETRY` × the residual reached
    ///
    /// The orbit must be tighter than an AM curve's: near resonance the fixed point of the
    /// stroboscopic map amplifies an error ε of the map by ‖(I − M)⁻¹‖ ≈ Q/π, and the phase
    /// condition sees it (measured at Q = 10⁴: a loop residual floor of 6e-8 at ε = 1e-11).
    pub fn new(base: Params, values: Vec<f64>, amplitude: f64) -> Self {
        let integrator = IntegratorOptions {
            tolerance: DEFAULT_ORBIT_TOLERANCE,
            ..IntegratorOptions::default()
        };
        FmSpec {
            base,
            values,
            amplitude,
            mode: 1,
            integrator,
            newton: ShootingOptions {
                tol: 1e-12,
                max_iter: 20,
                ..ShootingOptions::default()
            },
            tolerance: DEFAULT_LOOP_TOLERANCE,
        }
    }

    fn check(&self) -> Result<(), SimError> {
        if self.values.is_empty() {
            return Err(SimError::out_of_range(
                "values",
                0,
                "must hold at least one rest distance",
            ));
        }
        if let Some(v) = self.values.iter().find(|v| !v.is_finite()) {
            return Err(SimError::NotFinite {
                name: "z_c",
                value: *v,
            });
        }
        if !(self.amplitude.is_finite() && self.amplitude > 0.0) {
            return Err(SimError::out_of_range(
                "amplitude",
                self.amplitude,
                "must be a positive, finite oscillation amplitude",
            ));
        }
        super::tolerance("tolerance", self.tolerance)?;
        self.base.validate()?;
        Ok(())
    }
}

/// The free lever's operating point that the loops are set up on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FmReference {
    /// ω_K: natural frequency of the tracked mode (units of the τ scale).
    pub omega: f64,
    /// Q_K of the tracked mode.
    pub quality_factor: f64,
    /// φ_set: lag of the free response behind the drive at ω_K, rad (π/2 for the point mass).
    pub phase: f64,
    /// α2 that holds the first-harmonic amplitude at A at ω_K without a sample.
    pub excitation: f64,
    /// k̃_K: the tracked mode's stiffness at the tip (F̃/g₀; `crate::eigen::mode_at_tip`, 1
    /// for the point mass): the k of Giessibl's and Sader–Jarvis's formulas for this mode.
    pub stiffness: f64,
}

/// The reference of `base` for the tracked mode `mode` at amplitude `amplitude` (g₀): ω_K,
/// Q_K, and the free response's lag and excitation there (a far gap, so that no sample acts).
///
/// # Errors
/// As [`mode_resonance`] and [`free_response`].
pub(crate) fn fm_reference(
    base: &Params,
    mode: usize,
    amplitude: f64,
) -> Result<FmReference, SimError> {
    let (omega, q) = mode_resonance(base, mode)?;
    let at = base.with(SweepParam::Omega, omega);
    let model = CantileverModel::new(&at)?;
    let free = free_response(&model)?;
    let g = model.galerkin();
    let (_, _, stiffness) =
        crate::eigen::mode_at_tip(g.region(crate::galerkin::Region::Free), g.tip(), mode - 1);
    Ok(FmReference {
        omega,
        quality_factor: q,
        phase: free.phase,
        excitation: at.alpha2 * amplitude / free.amplitude,
        stiffness,
    })
}

/// One point of an FM curve: the locked orbit at one rest distance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FmPoint {
    /// α5 (the gap).
    pub alpha5: f64,
    /// Ω: the drive frequency the PLL locks at.
    pub omega: f64,
    /// α2: the excitation the amplitude controller sets.
    pub alpha2: f64,
    /// The orbit's state at τ = 0, shape `[2N]` (N = 1 for the point mass).
    pub state: DVector<f64>,
    /// Floquet multipliers under the locked drive, decreasing modulus.
    pub multipliers: Vec<Complex<f64>>,
    /// All multipliers inside the unit circle (module docs, **Stability**).
    pub stable: bool,
    /// det ∂(A₁/A, φ₁)/∂(Ω, α2) at the solution (its secant estimate; NaN where the bracketing
    /// fallback found the point): a sign change between two values, confirmed by forward
    /// differences, is a fold.
    pub loop_determinant: f64,
    /// Newton iterations on (Ω, α2).
    pub iterations: usize,
    /// max(|A₁/A − 1|, |φ₁ − φ_set|) reached.
    pub loop_residual: f64,
    /// The law's conservative force at the lower turning point's distance (F̃; at rest, the
    /// damping off): the force a reconstruction from this curve should give back there.
    pub law_force: f64,
    /// The orbit's observables (harmonics, forces, E_dis, virial, …).
    pub observables: Observables,
    /// The loops' thermal noise here ([`noise`]), with a temperature.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub noise: Option<noise::FmNoise>,
}

/// A fold of the FM curve: between the values of points `index` and `index + 1`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FmFold {
    /// Index of the point before the sign change.
    pub index: usize,
    /// α5 of that point.
    pub alpha5: f64,
}

/// An FM curve.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FmCurve {
    /// The free lever's operating point.
    pub reference: FmReference,
    /// The amplitude setpoint A (g₀).
    pub amplitude: f64,
    /// One point per value reached, in the order of the values.
    pub points: Vec<FmPoint>,
    /// Where the loop Jacobian's determinant changes sign.
    pub folds: Vec<FmFold>,
    /// The first value not reached, where the curve ends (the values after it are not tried).
    pub unreached: Option<Unreached>,
}

/// The value where an FM curve ends early.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Unreached {
    /// α5 of the value.
    pub alpha5: f64,
    /// Why: the error of the last attempt.
    pub reason: String,
}

/// The FM curve of `spec` ([`FmSpec`]; module docs), counting one unit per value in `progress`.
///
/// # Errors
/// [`SimError::OutOfRange`] / [`SimError::NotFinite`] for a bad spec; [`SimError::Params`]
/// for invalid parameters; [`SimError::NoConvergence`] when the first value (far from the
/// sample) cannot be locked; [`SimError::Cancelled`]. A later value that cannot be reached ends
/// the curve with a warning.
pub fn fm_curve(spec: &FmSpec, progress: &Progress) -> Result<FmCurve, SimError> {
    followed(spec, progress.cancel_flag(), Some(progress))
}

/// [`fm_curve`] stopped at the next value once `cancel` is set (the dynamic fit's evaluation
/// of a Δf curve, [`crate::analysis::fit::fm_curve`], which counts its own units).
///
/// # Errors
/// As [`fm_curve`].
pub(crate) fn fm_curve_cancellable(
    spec: &FmSpec,
    cancel: &AtomicBool,
) -> Result<FmCurve, SimError> {
    followed(spec, cancel, None)
}

/// [`fm_curve`] checking `cancel` before every value and counting them in `progress`.
fn followed(
    spec: &FmSpec,
    cancel: &AtomicBool,
    progress: Option<&Progress>,
) -> Result<FmCurve, SimError> {
    let check = || {
        if cancel.load(Ordering::Relaxed) {
            Err(SimError::Cancelled)
        } else {
            Ok(())
        }
    };
    spec.check()?;
    let reference = fm_reference(&spec.base, spec.mode, spec.amplitude)?;
    let solver = Solver { spec, reference };
    if let Some(p) = progress {
        p.add_total(spec.values.len());
    }
    let mut points: Vec<FmPoint> = Vec::with_capacity(spec.values.len());
    let mut unreached = None;
    // the free orbit at the reference from rest (Newton on the free flight's affine map)
    let start = CantileverModel::new(&spec.base.with(SweepParam::Alpha5, spec.values[0]))?.rest();
    let mut walk = Walk::default();
    for &target in &spec.values {
        check()?;
        let (locked, iterations) = match walk.reach(&solver, target, &start, &check)? {
            Ok(reached) => reached,
            Err(e) if points.is_empty() => return Err(e),
            Err(e) => {
                unreached = Some(Unreached {
                    alpha5: target,
                    reason: e.to_string(),
                });
                break;
            }
        };
        let p = spec
            .base
            .with(SweepParam::Alpha5, target)
            .with(SweepParam::Omega, locked.x[0])
            .with(SweepParam::Alpha2, locked.x[1]);
        let model = CantileverModel::new(&p)?;
        let observables = observe_orbit(&model, spec.integrator.clone(), &locked.orbit, 10)?;
        points.push(FmPoint {
            alpha5: target,
            omega: locked.x[0],
            alpha2: locked.x[1],
            state: locked.orbit.state.clone(),
            multipliers: locked.orbit.multipliers.clone(),
            stable: locked.orbit.stable,
            loop_determinant: walk.jac.map_or(f64::NAN, |j| j.determinant()),
            iterations,
            loop_residual: locked.residual.amax(),
            law_force: law_force(&p, observables.min_distance),
            observables,
            noise: None,
        });
        if let Some(p) = progress {
            p.tick();
        }
    }
    Ok(FmCurve {
        reference,
        amplitude: spec.amplitude,
        folds: folds(&solver, &points)?,
        points,
        unreached,
    })
}

/// A value reached by the loops: (α5, (Ω, α2), the orbit's state at τ = 0).
type Anchor = (f64, Vector2<f64>, DVector<f64>);

/// Where an FM curve stands: the last value reached, the one before it, and the loop
/// Jacobian's secant estimate at the last.
#[derive(Default)]
struct Walk {
    last: Option<Anchor>,
    before: Option<Anchor>,
    jac: Option<Matrix2<f64>>,
}

impl Walk {
    /// The loops locked at `target`, stepping from the last value reached: the step halved
    /// after a failure (at most [`MAX_HALVINGS`] times for this target), doubled back after a
    /// success; the first value has no earlier point to step from (it starts from the free
    /// orbit `start`). Reaching `target` moves the walk there. `Ok(Err)`: the last failure.
    ///
    /// # Errors
    /// [`SimError::Cancelled`] once `check` says so.
    fn reach(
        &mut self,
        solver: &Solver,
        target: f64,
        start: &DVector<f64>,
        check: &dyn Fn() -> Result<(), SimError>,
    ) -> Result<Result<(Locked, usize), SimError>, SimError> {
        let (mut from, mut prev, mut trial_jac) =
            (self.last.clone(), self.before.clone(), self.jac);
        let (mut fraction, mut failures) = (1.0f64, 0);
        loop {
            let value = match &from {
                Some((a, ..)) if fraction < 1.0 => a + (target - a) * fraction,
                _ => target,
            };
            let (x0, guess) = predict(&from, &prev, value, &solver.reference, start);
            let locked = match solver.lock(value, x0, &guess, &mut trial_jac) {
                Err(SimError::Cancelled) => Err(SimError::Cancelled),
                Err(_) => {
                    trial_jac = None;
                    solver
                        .lock_augmented(value, x0, &guess)
                        .or_else(|_| solver.lock_bracketed(value, x0, &guess))
                }
                ok => ok,
            };
            match locked {
                Ok((locked, it)) => {
                    prev = from;
                    from = Some((value, locked.x, locked.orbit.state.clone()));
                    if value == target {
                        (self.jac, self.before, self.last) = (trial_jac, prev, from);
                        return Ok(Ok((locked, it)));
                    }
                    fraction = (2.0 * fraction).min(1.0);
                }
                Err(SimError::Cancelled) => return Err(SimError::Cancelled),
                Err(e) => {
                    failures += 1;
                    if from.is_none() || failures > MAX_HALVINGS {
                        return Ok(Err(e));
                    }
                    fraction *= 0.5;
                }
            }
            check()?;
        }
    }
}

/// The folds of the FM curve `points`: a sign change of the secant estimates of the loop
/// Jacobian's determinant, confirmed by forward differences at both ends.
///
/// # Errors
/// As [`Solver::orbit`] and [`Solver::jacobian`].
fn folds(solver: &Solver, points: &[FmPoint]) -> Result<Vec<FmFold>, SimError> {
    let mut folds = Vec::new();
    for index in 0..points.len().saturating_sub(1) {
        let (a, b) = (&points[index], &points[index + 1]);
        if a.loop_determinant * b.loop_determinant < 0.0 {
            let fresh = |q: &FmPoint| -> Result<f64, SimError> {
                let at = solver.orbit(q.alpha5, Vector2::new(q.omega, q.alpha2), &q.state)?;
                Ok(solver.jacobian(q.alpha5, &at)?.determinant())
            };
            if fresh(a)? * fresh(b)? < 0.0 {
                folds.push(FmFold {
                    index,
                    alpha5: a.alpha5,
                });
            }
        }
    }
    Ok(folds)
}

/// The lag error φ₁ − φ_set wrapped into (−π, π] (the lags are reported in (−π/2, 3π/2]: a
/// higher mode's free lag, near 270°, sits at the wrap).
pub(crate) fn phase_error(phase: f64, set: f64) -> f64 {
    let e = (phase - set).rem_euclid(std::f64::consts::TAU);
    if e > std::f64::consts::PI {
        e - std::f64::consts::TAU
    } else {
        e
    }
}

/// The conservative tip–sample force F̃ of `params`' law at the tip–sample distance `d` (units
/// of g₀; d = V_T + [`crate::ContactLaw::distance_offset`], contact where V_T ≤ 0), at rest.
pub(crate) fn law_force(params: &Params, d: f64) -> f64 {
    let law = TipSample {
        law: params.contact_law,
        stiffness: params.alpha4,
        damping: params.alpha6,
    };
    let delta = params.contact_law.distance_offset() - d;
    law.force(delta >= 0.0, delta, 0.0).force
}
