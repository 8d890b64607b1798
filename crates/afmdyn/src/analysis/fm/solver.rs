//! The solver of the FM loop at one height ([`super::fm_curve`]): the augmented Newton
//! iteration on (orbit, Ω) with the phase condition, its differences and backtracking, and
//! the predictor along the curve (module docs of [`super`]).

use super::*;

/// An orbit at one (α5, Ω, α2) with its loop residual.
pub(super) struct Locked {
    pub(super) x: Vector2<f64>,
    /// ‖P(z) − z‖ of the orbit.
    pub(super) fixed_point: f64,
    pub(super) orbit: PeriodicOrbit,
    pub(super) residual: Vector2<f64>,
}

pub(super) struct Solver<'a> {
    pub(super) spec: &'a FmSpec,
    pub(super) reference: FmReference,
}

impl Solver<'_> {
    /// The loop residual accepted for the orbit `at` once Newton stops gaining: the
    /// tolerance, or the orbit's own error Q_K (10³ × the integrator's tolerance + 10 × its
    /// fixed-point residual) ([`NOISE_FLOOR_FACTOR`], [`ORBIT_FLOOR_FACTOR`]), never above
    /// [`MAX_LOOP_RESIDUAL`].
    pub(super) fn floor(&self, at: &Locked) -> f64 {
        let q = self.reference.quality_factor.min(1e12);
        let noise = q
            * (NOISE_FLOOR_FACTOR * self.spec.integrator.tolerance
                + ORBIT_FLOOR_FACTOR * at.fixed_point);
        self.spec.tolerance.max(noise.min(MAX_LOOP_RESIDUAL))
    }

    /// The periodic orbit at (α5, x = (Ω, α2)) from `guess`, and g = (A₁/A − 1, φ₁ − φ_set).
    pub(super) fn orbit(
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
        // Newton's full steps; where they stall (near a grazing orbit, whose map has a
        // square-root singularity) Newton with a line search; at the map's round-off floor a
        // looser tolerance
        let map = &mut StroboscopicMap::build(&model, self.spec.integrator.clone(), guess, 1)?;
        let newton = self.spec.newton.with_period(1);
        let globalised = ShootingOptions {
            strategy: ShootingStrategy::Globalised,
            ..newton
        };
        let orbit = match shoot(map, guess, &newton) {
            Err(SimError::NoConvergence { .. }) => match shoot(map, guess, &globalised) {
                Err(SimError::NoConvergence { residual, .. }) if residual <= ROUND_OFF_LIMIT => {
                    let looser = ShootingOptions {
                        tol: ROUND_OFF_RETRY * residual,
                        ..globalised
                    };
                    shoot(map, guess, &looser)?
                }
                r => r?,
            },
            r => r?,
        };
        let fixed_point = orbit.residuals.last().copied().unwrap_or(0.0);
        let observables = observe_orbit(&model, self.spec.integrator.clone(), &orbit, 1)?;
        let residual = Vector2::new(
            observables.amplitude / self.spec.amplitude - 1.0,
            phase_error(observables.phase, self.reference.phase),
        );
        Ok(Locked {
            x,
            fixed_point,
            orbit,
            residual,
        })
    }

    /// The forward-difference Jacobian of g at `at`.
    pub(super) fn jacobian(&self, alpha5: f64, at: &Locked) -> Result<Matrix2<f64>, SimError> {
        let mut j = Matrix2::zeros();
        let r = &self.reference;
        let steps = [
            DIFFERENCE_STEP * r.omega * (0.5 / r.quality_factor).min(1.0),
            DIFFERENCE_STEP * at.x[1].abs().max(1e-12),
        ];
        for (c, h) in steps.into_iter().enumerate() {
            let mut x = at.x;
            x[c] += h;
            let moved = self.orbit(alpha5, x, &at.orbit.state)?;
            j.set_column(c, &((moved.residual - at.residual) / h));
        }
        Ok(j)
    }

    /// The residual of the augmented system at y = (z, Ω, α2): (P(z) − z, A₁/A − 1,
    /// φ₁ − φ_set), with A₁ and φ₁ demodulated over the period from z (one flow gives both:
    /// the observables' window ends at P(z)).
    pub(super) fn augmented_residual(
        &self,
        alpha5: f64,
        y: &DVector<f64>,
    ) -> Result<DVector<f64>, SimError> {
        let d = y.len() - 2;
        let z = y.rows(0, d).into_owned();
        let p = self
            .spec
            .base
            .with(SweepParam::Alpha5, alpha5)
            .with(SweepParam::Omega, y[d])
            .with(SweepParam::Alpha2, y[d + 1]);
        p.validate()?;
        let model = CantileverModel::new(&p)?;
        let mut integ = build(&model, self.spec.integrator.clone(), 0.0, &z)?;
        let o = observe(
            integ.as_mut(),
            &ObservableOptions {
                periods: 1,
                harmonics: 1,
            },
        )?;
        let mut r = DVector::zeros(d + 2);
        r.rows_mut(0, d).copy_from(&(integ.state() - &z));
        r[d] = o.amplitude / self.spec.amplitude - 1.0;
        r[d + 1] = phase_error(o.phase, self.reference.phase);
        Ok(r)
    }

    /// The orbit and the loop conditions solved together: Newton's method on the augmented
    /// system (P(z) − z, A₁/A − 1, φ₁ − φ_set) = 0 in y = (z, Ω, α2) (the shooting of an
    /// orbit of unknown frequency and forcing: Seydel, *Practical Bifurcation and Stability
    /// Analysis*, Springer 2010, §7.3), its (d + 2)-square Jacobian by forward differences
    /// (z on the state's scale, Ω on the linewidth's, α2 relative), each step backtracked on
    /// the largest residual. At high Q the orbit's M − I is nearly singular (multipliers within
    /// π/Q of 1), its near-null directions the oscillation's amplitude and phase — exactly what
    /// the two loop conditions fix, so the augmented Jacobian stays well conditioned where the
    /// nested solve ([`Self::lock`]) stalls (measured: at Q = 10⁴ where the lower turning point
    /// reaches the DMT edge).
    pub(super) fn lock_augmented(
        &self,
        alpha5: f64,
        x0: Vector2<f64>,
        guess: &DVector<f64>,
    ) -> Result<(Locked, usize), SimError> {
        let d = guess.len();
        let mut y = DVector::zeros(d + 2);
        y.rows_mut(0, d).copy_from(guess);
        y[d] = x0[0];
        y[d + 1] = x0[1];
        let mut r = self.augmented_residual(alpha5, &y)?;
        let r_ = &self.reference;
        let fixed_tol = |y: &DVector<f64>| self.spec.newton.tol * (1.0 + y.rows(0, d).norm());
        let met = |r: &DVector<f64>, y: &DVector<f64>| {
            r.rows(0, d).norm() <= fixed_tol(y)
                && r[d].abs().max(r[d + 1].abs()) <= self.spec.tolerance
        };
        let mut it = 0;
        while !met(&r, &y) {
            if it == MAX_LOOP_ITERATIONS {
                return Err(SimError::NoConvergence {
                    what: "the FM orbit and loop conditions together (augmented Newton)",
                    iterations: it,
                    residual: r.amax(),
                });
            }
            it += 1;
            let mut jac = nalgebra::DMatrix::zeros(d + 2, d + 2);
            for c in 0..d + 2 {
                let h = if c < d {
                    AUGMENTED_STATE_STEP * (1.0 + y.rows(0, d).amax())
                } else if c == d {
                    DIFFERENCE_STEP * r_.omega * (0.5 / r_.quality_factor).min(1.0)
                } else {
                    DIFFERENCE_STEP * y[d + 1].abs().max(1e-12)
                };
                let mut yh = y.clone();
                yh[c] += h;
                let rh = self.augmented_residual(alpha5, &yh)?;
                jac.set_column(c, &((rh - &r) / h));
            }
            let step = jac.lu().solve(&(-&r)).ok_or(SimError::NoConvergence {
                what: "the FM orbit and loop conditions together (singular Jacobian)",
                iterations: it,
                residual: r.amax(),
            })?;
            let mut t = 1.0;
            let mut accepted = None;
            for _ in 0..BACKTRACKS {
                let trial = &y + &step * t;
                if let Ok(rt) = self.augmented_residual(alpha5, &trial) {
                    if rt.amax() < r.amax() {
                        accepted = Some((trial, rt));
                        break;
                    }
                }
                t *= 0.5;
            }
            let Some((ny, nr)) = accepted else {
                break;
            };
            y = ny;
            r = nr;
        }
        // the orbit at the solution, for its monodromy matrix and multipliers: shooting from a
        // fixed point returns it at once
        let x = Vector2::new(y[d], y[d + 1]);
        let z = y.rows(0, d).into_owned();
        let spec = self.spec;
        let loose = Solver {
            spec: &FmSpec {
                newton: ShootingOptions {
                    tol: spec
                        .newton
                        .tol
                        .max(2.0 * r.rows(0, d).norm() / (1.0 + z.norm())),
                    ..spec.newton
                },
                ..spec.clone()
            },
            reference: self.reference,
        };
        let locked = loose.orbit(alpha5, x, &z)?;
        if locked.residual.amax() <= self.floor(&locked) {
            Ok((locked, it))
        } else {
            Err(SimError::NoConvergence {
                what: "the FM orbit and loop conditions together (augmented Newton)",
                iterations: it,
                residual: locked.residual.amax(),
            })
        }
    }

    /// The orbit at (α5, Ω) with α2 set so that A₁ = A: α2 ← α2 A/A₁ (A₁ is nearly linear in
    /// α2 at fixed Ω, exactly so without a sample), from `alpha2` and `guess`.
    pub(super) fn hold_amplitude(
        &self,
        alpha5: f64,
        omega: f64,
        alpha2: f64,
        guess: &DVector<f64>,
        evaluations: &mut usize,
    ) -> Result<Locked, SimError> {
        let mut cur = self.orbit(alpha5, Vector2::new(omega, alpha2), guess)?;
        *evaluations += 1;
        for _ in 0..MAX_LOOP_ITERATIONS {
            let r = cur.residual[0].abs();
            if r <= self.spec.tolerance {
                break;
            }
            let next = self.orbit(
                alpha5,
                Vector2::new(omega, cur.x[1] / (1.0 + cur.residual[0])),
                &cur.orbit.state,
            )?;
            *evaluations += 1;
            if next.residual[0].abs() >= r {
                break;
            }
            cur = next;
        }
        Ok(cur)
    }

    /// The loop conditions met by bracketing, where Newton's method fails (a kink of A₁ and
    /// φ₁ in (Ω, α2) where the lower turning point crosses the edge of a contact law whose
    /// force gradient jumps there, as DMT's at d = a₀): at each Ω the amplitude is held
    /// ([`Self::hold_amplitude`]), and φ₁(Ω) − φ_set, increasing in Ω (the lag grows through
    /// a resonance), is bracketed from `x0` by steps growing from 10⁻³ of the half linewidth,
    /// then reduced by the Illinois variant of regula falsi (Dowell & Jarratt, *BIT* 11 (1971)
    /// 168), which converges superlinearly on a smooth function and never leaves the bracket.
    pub(super) fn lock_bracketed(
        &self,
        alpha5: f64,
        x0: Vector2<f64>,
        guess: &DVector<f64>,
    ) -> Result<(Locked, usize), SimError> {
        let mut n = 0;
        let at = |omega: f64, alpha2: f64, guess: &DVector<f64>, n: &mut usize| {
            self.hold_amplitude(alpha5, omega, alpha2, guess, n)
        };
        let done = |l: &Locked| {
            let r = l.residual.amax();
            r <= self.spec.tolerance
        };
        let mut a = at(x0[0], x0[1], guess, &mut n)?;
        if done(&a) {
            return Ok((a, n));
        }
        let r = &self.reference;
        let mut h = 1e-3 * r.omega * (0.5 / r.quality_factor).min(1.0);
        let dir = if a.residual[1] > 0.0 { -1.0 } else { 1.0 };
        let mut b = loop {
            let state = a.orbit.state.clone();
            let next = at(a.x[0] + dir * h, a.x[1], &state, &mut n)?;
            if next.residual[1].signum() != a.residual[1].signum() || done(&next) {
                break next;
            }
            a = next;
            h *= 2.0;
            if h > 0.5 * r.omega {
                return Err(SimError::NoConvergence {
                    what: "bracketing the FM phase condition in Ω",
                    iterations: n,
                    residual: a.residual.amax(),
                });
            }
        };
        // Illinois: (a, b) bracket the zero of the phase residual
        let mut side = 0i8;
        for _ in 0..4 * MAX_LOOP_ITERATIONS {
            if done(&b) {
                return Ok((b, n));
            }
            let (fa, fb) = (a.residual[1], b.residual[1]);
            let mut wa = 1.0;
            let mut wb = 1.0;
            if side == 1 {
                wa = 0.5;
            } else if side == -1 {
                wb = 0.5;
            }
            let (fa_w, fb_w) = (wa * fa, wb * fb);
            let omega = (a.x[0] * fb_w - b.x[0] * fa_w) / (fb_w - fa_w);
            let width = (b.x[0] - a.x[0]).abs();
            if !(omega.is_finite()) || width <= 4.0 * f64::EPSILON * r.omega {
                break;
            }
            let alpha2 = 0.5 * (a.x[1] + b.x[1]);
            let state = b.orbit.state.clone();
            let c = at(omega, alpha2, &state, &mut n)?;
            if c.residual[1].signum() == fb.signum() {
                b = c;
                side = if side == 1 { 2 } else { 1 };
            } else {
                a = b;
                b = c;
                side = -1;
            }
            if side == 2 {
                side = 1;
            }
        }
        let best = if a.residual.amax() < b.residual.amax() {
            a
        } else {
            b
        };
        if best.residual.amax() <= self.floor(&best) {
            return Ok((best, n));
        }
        Err(SimError::NoConvergence {
            what: "the FM loop conditions by bracketing in Ω",
            iterations: n,
            residual: best.residual.amax(),
        })
    }

    /// Newton on (Ω, α2) at α5 from `x0` with the orbit guess `guess` and a Jacobian estimate.
    pub(super) fn lock(
        &self,
        alpha5: f64,
        x0: Vector2<f64>,
        guess: &DVector<f64>,
        jac: &mut Option<Matrix2<f64>>,
    ) -> Result<(Locked, usize), SimError> {
        let tol = self.spec.tolerance;
        let floor = |at: &Locked| self.floor(at);
        let mut stalled = 0;
        let mut cur = self.orbit(alpha5, x0, guess)?;
        let mut j = match jac {
            Some(j) => *j,
            None => self.jacobian(alpha5, &cur)?,
        };
        let mut fresh = jac.is_none();
        for it in 0..MAX_LOOP_ITERATIONS {
            let r = cur.residual.amax();
            if r <= tol || (r <= floor(&cur) && stalled >= 2) {
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
            // backtrack on the loop residual (and on orbits that are not found)
            let mut next: Option<Locked> = None;
            let mut step = dx;
            for _ in 0..BACKTRACKS {
                match self.orbit(alpha5, cur.x + step, &cur.orbit.state) {
                    Ok(n) if n.residual.amax() < cur.residual.amax() => {
                        next = Some(n);
                        break;
                    }
                    Ok(n) => {
                        next.get_or_insert(n);
                        step *= 0.5;
                    }
                    Err(SimError::Cancelled) => return Err(SimError::Cancelled),
                    Err(_) => step *= 0.5,
                }
            }
            let Some(next) = next else {
                break;
            };
            if next.residual.amax() >= cur.residual.amax() {
                // no decrease along the step: at the orbit's round-off floor the point is
                // found; else a fresh Jacobian, unless it is one already
                if cur.residual.amax() <= floor(&cur) {
                    *jac = Some(j);
                    return Ok((cur, it));
                }
                if fresh {
                    break;
                }
                j = self.jacobian(alpha5, &cur)?;
                fresh = true;
                stalled += 1;
                continue;
            }
            let step = next.x - cur.x;
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

/// The start of the loop's Newton iteration at `value`: the secant through the last two points
/// (their (Ω, α2) and orbit states), the last point alone, or the free reference from `rest`.
pub(super) fn predict(
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
