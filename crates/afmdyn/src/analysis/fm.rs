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
//! the natural frequency ω_K of the tracked mode K ([`super::resonance::mode_resonance`];
//! [`FmReference`]). The orbit is found by Newton shooting on the stroboscopic map at each
//! (Ω, α2) ([`super::shooting`]), and (Ω, α2) by Newton's method on the two conditions, its
//! 2×2 Jacobian by forward differences and then Broyden's secant update (Broyden, *Math.
//! Comp.* 19 (1965) 577) — the orbit's own accuracy is the shooting's, the conditions are met
//! to [`FmSpec::tolerance`]. The curve is followed in z_c by natural-parameter continuation
//! with a secant predictor; a value that does not converge is approached in halved steps.
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

use super::observables::{free_response, observe_orbit, Observables};
use super::progress::Progress;
use super::resonance::mode_resonance;
use super::shooting::{shoot_with, PeriodicOrbit, ShootingOptions};
use crate::error::SimError;
use crate::integrate::{build, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::{Complex, DVector, Matrix2, Vector2};
use serde::{Deserialize, Serialize};

/// Default tolerance of the two loop conditions: |A₁/A − 1| and |φ₁ − φ_set| (rad).
pub const DEFAULT_LOOP_TOLERANCE: f64 = 1e-9;
/// Default tolerance of the integrator of the orbits ([`FmSpec::new`]).
pub const DEFAULT_ORBIT_TOLERANCE: f64 = 1e-13;
/// The loop conditions are met to the tolerance, or, where the orbit's own error bounds them
/// (module docs, [`FmSpec::new`]), to this many times Q_K × the integrator's tolerance once
/// Newton stops gaining.
pub const NOISE_FLOOR_FACTOR: f64 = 1e3;
/// Most Newton iterations on (Ω, α2) per value.
pub const MAX_LOOP_ITERATIONS: usize = 30;
/// Most halvings of the step in z_c towards a value that does not converge.
pub const MAX_HALVINGS: usize = 6;
/// Relative step of the forward differences of the loop Jacobian.
const DIFFERENCE_STEP: f64 = 1e-6;

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
    /// Newton shooting of the orbit at each (Ω, α2).
    pub newton: ShootingOptions,
    /// Tolerance of the loop conditions (relative amplitude, phase in rad), in (0, 1e-3).
    pub tolerance: f64,
}

impl FmSpec {
    /// Defaults: mode 1, tolerance [`DEFAULT_LOOP_TOLERANCE`], the integrator's tolerance
    /// [`DEFAULT_ORBIT_TOLERANCE`], shooting to 1e-12.
    ///
    /// The orbit must be tighter than an AM curve's: near resonance the fixed point of the
    /// stroboscopic map amplifies an error ε of the map by ‖(I − M)⁻¹‖ ≈ Q/π, and the phase
    /// condition sees it (measured at Q = 10⁴: a loop residual floor of 6e-8 at ε = 1e-11).
    pub fn new(base: Params, values: Vec<f64>, amplitude: f64) -> Self {
        let mut integrator = IntegratorOptions::default();
        integrator.tolerance = DEFAULT_ORBIT_TOLERANCE;
        FmSpec {
            base,
            values,
            amplitude,
            mode: 1,
            integrator,
            newton: ShootingOptions {
                tol: 1e-12,
                max_iter: 20,
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
        if !(self.tolerance.is_finite() && self.tolerance > 0.0 && self.tolerance < 1e-3) {
            return Err(SimError::out_of_range(
                "tolerance",
                self.tolerance,
                "must be in (0, 1e-3)",
            ));
        }
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
}

/// The reference of `base` for the tracked mode `mode` at amplitude `amplitude` (g₀): ω_K,
/// Q_K, and the free response's lag and excitation there (a far gap, so that no sample acts).
///
/// # Errors
/// As [`mode_resonance`] and [`free_response`].
pub fn fm_reference(base: &Params, mode: usize, amplitude: f64) -> Result<FmReference, SimError> {
    let (omega, q) = mode_resonance(base, mode)?;
    let at = base.with(SweepParam::Omega, omega);
    let free = free_response(&CantileverModel::new(&at)?)?;
    Ok(FmReference {
        omega,
        quality_factor: q,
        phase: free.phase,
        excitation: at.alpha2 * amplitude / free.amplitude,
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
    /// det ∂(A₁/A, φ₁)/∂(Ω, α2) at the solution (its secant estimate): a sign change between two
    /// values is a fold.
    pub loop_determinant: f64,
    /// Newton iterations on (Ω, α2).
    pub iterations: usize,
    /// max(|A₁/A − 1|, |φ₁ − φ_set|) reached.
    pub loop_residual: f64,
    /// The orbit's observables (harmonics, forces, E_dis, virial, …).
    pub observables: Observables,
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
    /// Values not reached and why.
    pub warnings: Vec<String>,
}

/// An orbit at one (α5, Ω, α2) with its loop residual.
struct Locked {
    x: Vector2<f64>,
    orbit: PeriodicOrbit,
    observables: Observables,
    residual: Vector2<f64>,
}

struct Solver<'a> {
    spec: &'a FmSpec,
    reference: FmReference,
}

impl Solver<'_> {
    /// The periodic orbit at (α5, x = (Ω, α2)) from `guess`, and g = (A₁/A − 1, φ₁ − φ_set).
    fn orbit(
        &self,
        alpha5: f64,
        x: Vector2<f64>,
        guess: &DVector<f64>,
    ) -> Result<Locked, SimError> {
        let p = self
            .spec
            .base
            .with(SweepParam::Alpha5, alpha5)
            .with(SweepParam::Omega, x[0])
            .with(SweepParam::Alpha2, x[1]);
        p.validate()?;
        let model = CantileverModel::new(&p)?;
        let mut integ = build(&model, self.spec.integrator.clone(), 0.0, guess)?;
        let orbit = shoot_with(integ.as_mut(), guess, 1, &self.spec.newton)?;
        let observables = observe_orbit(&model, self.spec.integrator.clone(), &orbit, 1)?;
        let residual = Vector2::new(
            observables.amplitude / self.spec.amplitude - 1.0,
            observables.phase - self.reference.phase,
        );
        Ok(Locked {
            x,
            orbit,
            observables,
            residual,
        })
    }

    /// The forward-difference Jacobian of g at `at`.
    fn jacobian(&self, alpha5: f64, at: &Locked) -> Result<Matrix2<f64>, SimError> {
        let mut j = Matrix2::zeros();
        for c in 0..2 {
            let h = DIFFERENCE_STEP * at.x[c].abs().max(1e-12);
            let mut x = at.x;
            x[c] += h;
            let moved = self.orbit(alpha5, x, &at.orbit.state)?;
            j.set_column(c, &((moved.residual - at.residual) / h));
        }
        Ok(j)
    }

    /// Newton on (Ω, α2) at α5 from `x0` with the orbit guess `guess` and a Jacobian estimate.
    fn lock(
        &self,
        alpha5: f64,
        x0: Vector2<f64>,
        guess: &DVector<f64>,
        jac: &mut Option<Matrix2<f64>>,
    ) -> Result<(Locked, usize), SimError> {
        let tol = self.spec.tolerance;
        let floor = tol.max(
            NOISE_FLOOR_FACTOR
                * self.reference.quality_factor.min(1e12)
                * self.spec.integrator.tolerance,
        );
        let mut stalled = 0;
        let mut cur = self.orbit(alpha5, x0, guess)?;
        let mut j = match jac {
            Some(j) => *j,
            None => self.jacobian(alpha5, &cur)?,
        };
        let mut fresh = jac.is_none();
        for it in 0..MAX_LOOP_ITERATIONS {
            let r = cur.residual.amax();
            if r <= tol || (r <= floor && stalled >= 2) {
                *jac = Some(j);
                return Ok((cur, it));
            }
            let Some(inv) = j.try_inverse().filter(|m| m.iter().all(|v| v.is_finite())) else {
                if fresh {
                    break;
                }
                j = self.jacobian(alpha5, &cur)?;
                fresh = true;
                continue;
            };
            let mut dx = -(inv * cur.residual);
            // keep the drive frequency within a tenth of ω_K per step and α2 positive
            let cap = 0.1 * self.reference.omega;
            if dx[0].abs() > cap {
                dx *= cap / dx[0].abs();
            }
            if cur.x[1] + dx[1] <= 0.0 {
                dx *= 0.5 * cur.x[1] / dx[1].abs();
            }
            let mut next = None;
            let mut step = dx;
            for _ in 0..8 {
                match self.orbit(alpha5, cur.x + step, &cur.orbit.state) {
                    Ok(n) => {
                        next = Some(n);
                        break;
                    }
                    Err(SimError::Cancelled) => return Err(SimError::Cancelled),
                    Err(_) => step *= 0.5,
                }
            }
            let Some(next) = next else {
                break;
            };
            let dg = next.residual - cur.residual;
            let good = next.residual.amax() < 0.5 * cur.residual.amax();
            // Broyden: J ← J + (Δg − J δ) δᵀ / (δᵀδ)
            let dd = step.dot(&step);
            if dd > 0.0 {
                j += (dg - j * step) * step.transpose() / dd;
            }
            cur = next;
            stalled = if good { 0 } else { stalled + 1 };
            if !good {
                j = self.jacobian(alpha5, &cur)?;
                fresh = true;
            } else {
                fresh = false;
            }
        }
        Err(SimError::NoConvergence {
            what: "the FM loop conditions (amplitude and phase) on (Ω, α2)",
            iterations: MAX_LOOP_ITERATIONS,
            residual: cur.residual.amax(),
        })
    }
}

/// The FM curve of `spec` ([`FmSpec`]; module docs), counting one unit per value in `progress`.
///
/// # Errors
/// [`SimError::OutOfRange`] / [`SimError::NotFinite`] for a bad spec; [`SimError::Params`]
/// for invalid parameters; [`SimError::NoConvergence`] when the first value (far from the
/// sample) cannot be locked; [`SimError::Cancelled`]. A later value that cannot be reached ends
/// the curve with a warning.
pub fn fm_curve(spec: &FmSpec, progress: &Progress) -> Result<FmCurve, SimError> {
    spec.check()?;
    let reference = fm_reference(&spec.base, spec.mode, spec.amplitude)?;
    let solver = Solver { spec, reference };
    progress.add_total(spec.values.len());
    let mut points: Vec<FmPoint> = Vec::with_capacity(spec.values.len());
    let mut warnings = Vec::new();
    let mut jac: Option<Matrix2<f64>> = None;
    // the free orbit at the reference from rest (Newton on the free flight's affine map)
    let start = CantileverModel::new(&spec.base.with(SweepParam::Alpha5, spec.values[0]))?.rest();
    let mut last: Option<(f64, Vector2<f64>, DVector<f64>)> = None;
    let mut before: Option<(f64, Vector2<f64>, DVector<f64>)> = None;
    for &target in &spec.values {
        progress.check()?;
        let mut reached: Option<(Locked, usize)> = None;
        let mut failure: Option<SimError> = None;
        // the first value has no earlier point to halve from
        let most = if last.is_some() { MAX_HALVINGS } else { 0 };
        for halvings in 0..=most {
            let pieces = 1usize << halvings;
            let (mut from, mut prev, mut trial_jac) = (last.clone(), before.clone(), jac);
            for k in 1..=pieces {
                let value = match &from {
                    Some((a, ..)) if k < pieces => a + (target - a) / (pieces + 1 - k) as f64,
                    _ => target,
                };
                let (x0, guess) = predict(&from, &prev, value, &reference, &start);
                match solver.lock(value, x0, &guess, &mut trial_jac) {
                    Ok((locked, it)) => {
                        prev = from;
                        from = Some((value, locked.x, locked.orbit.state.clone()));
                        if k == pieces {
                            reached = Some((locked, it));
                        }
                    }
                    Err(SimError::Cancelled) => return Err(SimError::Cancelled),
                    Err(e) => {
                        failure = Some(e);
                        break;
                    }
                }
            }
            if reached.is_some() {
                (jac, before, last) = (trial_jac, prev, from);
                break;
            }
        }
        let Some((locked, iterations)) = reached else {
            let e = failure.unwrap_or(SimError::NoConvergence {
                what: "the FM loop",
                iterations: 0,
                residual: f64::NAN,
            });
            if points.is_empty() {
                return Err(e);
            }
            warnings.push(format!(
                "the FM steady state was not found at α5 = {target} and beyond ({e}); the \
                 curve ends at the previous value"
            ));
            break;
        };
        let p = spec
            .base
            .with(SweepParam::Alpha5, target)
            .with(SweepParam::Omega, locked.x[0])
            .with(SweepParam::Alpha2, locked.x[1]);
        let model = CantileverModel::new(&p)?;
        let observables = observe_orbit(&model, spec.integrator.clone(), &locked.orbit, 10)?;
        debug_assert!((observables.amplitude - locked.observables.amplitude).abs() < 1e-9);
        points.push(FmPoint {
            alpha5: target,
            omega: locked.x[0],
            alpha2: locked.x[1],
            state: locked.orbit.state.clone(),
            multipliers: locked.orbit.multipliers.clone(),
            stable: locked.orbit.stable,
            loop_determinant: jac.map_or(f64::NAN, |j| j.determinant()),
            iterations,
            loop_residual: locked.residual.amax(),
            observables,
        });
        progress.tick();
    }
    let folds = points
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0].loop_determinant * w[1].loop_determinant < 0.0)
        .map(|(index, w)| FmFold {
            index,
            alpha5: w[0].alpha5,
        })
        .collect();
    Ok(FmCurve {
        reference,
        amplitude: spec.amplitude,
        points,
        folds,
        warnings,
    })
}

/// The start of the loop's Newton iteration at `value`: the secant through the last two points
/// (their (Ω, α2) and orbit states), the last point alone, or the free reference from `rest`.
fn predict(
    last: &Option<(f64, Vector2<f64>, DVector<f64>)>,
    before: &Option<(f64, Vector2<f64>, DVector<f64>)>,
    value: f64,
    reference: &FmReference,
    rest: &DVector<f64>,
) -> (Vector2<f64>, DVector<f64>) {
    match (last, before) {
        (Some((v1, x1, z1)), Some((v0, x0, z0))) if v1 != v0 => {
            let s = (value - v1) / (v1 - v0);
            (x1 + (x1 - x0) * s, z1 + (z1 - z0) * s)
        }
        (Some((_, x1, z1)), _) => (*x1, z1.clone()),
        _ => (
            Vector2::new(reference.omega, reference.excitation),
            rest.clone(),
        ),
    }
}
