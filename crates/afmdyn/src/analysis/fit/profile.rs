//! Profile-likelihood intervals: the parameter held at values walked outward from its
//! estimate, the others refitted at each (each refit started from the neighbouring point's
//! values), and the interval where Δχ² = χ²_profile − χ²_min stays at or below
//! `DELTA_CHI2_95` (Venzon & Moolgavkar, *J. R. Stat. Soc. C* 37 (1988) 87; Raue et al.,
//! *Bioinformatics* 25 (2009) 1923, which also names a profile that never rises a
//! *practically non-identifiable* parameter). Without σ the χ² are scaled by the noise
//! variance estimated at the minimum, s² = χ²_min/(m − n).
//!
//! Two walks ([`ProfileWalk`]): a grid of half standard errors refined by bisection, for a
//! model whose evaluations are cheap (the force curve), and a secant walk for one whose every
//! evaluation is costly (the dynamic fit's stepped approach), which finds the crossing in a
//! few refits. The secant walk solves r(x) = √Δχ²(x) = √3.841 = 1.96: for a model linear in
//! its parameters the profile is the parabola Δχ² = ((x − p̂)/SE)² (Bates & Watts 1988, §2.3),
//! so r is linear in x — exactly at the Wald end p̂ ± 1.96 SE — and the secant through two
//! points of r lands on the crossing; for a nonlinear model r is nearly linear near p̂ and a
//! few secant (regula falsi, inside a bracket) steps reach it.

use super::least_squares::{minimize_cancellable, CurveModel, Minimum, Observations, Parameter};
use crate::analysis::progress::Progress;
use crate::error::SimError;

/// The standard normal's 97.5 % quantile: the Wald interval is p̂ ± 1.96 SE.
pub(crate) const Z_95: f64 = 1.959_963_984_540_054;

/// The 95 % quantile of χ² with one degree of freedom, 3.841 (the profile's threshold).
pub(crate) const DELTA_CHI2_95: f64 = 3.841_458_820_694_124;

/// The most grid points walked on each side before the profile is called flat (the grid walk).
pub(crate) const MAX_PROFILE_STEPS: usize = 30;

/// Bisections refining a crossing of [`DELTA_CHI2_95`] between two grid points.
const BISECTIONS: usize = 5;

/// The most refits on each side of the grid walk: its points and a crossing's bisections.
pub(crate) const MAX_GRID_REFITS: usize = MAX_PROFILE_STEPS + BISECTIONS;

/// The most refits on each side of the secant walk of the dynamic fit: with the first step at
/// one standard error and at most doubling, 6 refits reach 32 SE from the estimate before the
/// profile is called flat.
pub(crate) const MAX_SECANT_STEPS: usize = 6;

/// The secant walk ends at a refit whose Δχ² is within this of `DELTA_CHI2_95`: 3.841 ± 0.05,
/// i.e. r = √Δχ² within 1.96 ± 0.013, the end within 0.65 % of the interval's half-width for a
/// parabolic profile; the coverage of χ²₁ at 3.791 … 3.891 is 94.84 … 95.14 %.
pub(crate) const SECANT_TOLERANCE: f64 = 0.05;

/// The relative tolerance of a profile's refits (MINPACK's ftol, xtol, gtol): χ² to 1e-7
/// relative is Δχ² to 1e-4 at χ² = 1000 (m = 1000 points), far inside
/// [`SECANT_TOLERANCE`]; the fit's own minimum keeps [`super::least_squares::TOLERANCE`].
pub(crate) const REFIT_TOLERANCE: f64 = 1e-7;

/// The patience of a profile's refits (the minimiser stops after `REFIT_PATIENCE` × (n + 1)
/// residual evaluations, [`super::least_squares::PATIENCE`]): a refit starts from its
/// neighbour's minimum and converges in a few iterations (~12 evaluations on the dynamic fit of
/// scripts/perf-fit-dynamic.sh); the cap bounds the profiles' declared cost. A refit that meets
/// it is counted ([`Profile::unconverged`]) and warned of.
pub(crate) const REFIT_PATIENCE: usize = 50;

/// How a profile is walked (the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProfileWalk {
    /// Steps of half a standard error, growing by half after 4 SE, up to
    /// `MAX_PROFILE_STEPS` a side; a crossing bisected 5 times and interpolated linearly in
    /// its last bracket (every grid point a refit: for a model whose evaluations are cheap).
    Grid,
    /// The secant walk on √Δχ²: the first refit at one standard error, then the secant through
    /// the last two points (regula falsi once the crossing is bracketed, kept within the
    /// bracket's middle 96 %), each step at most doubling the distance from the estimate (where
    /// Δχ² rises slowly); it ends at a refit within `SECANT_TOLERANCE` of the threshold, or
    /// after `max_steps` refits a side (a flat profile, or the crossing interpolated in its
    /// bracket).
    Secant {
        /// The most refits a side (`MAX_SECANT_STEPS` for the dynamic fit).
        max_steps: usize,
    },
}

/// One side's end of a profile interval.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ProfileEnd {
    /// Δχ² crosses the threshold here.
    Crossing(f64),
    /// The parameter's bound is reached with Δχ² below the threshold.
    Bound(f64),
    /// Δχ² stays below the threshold as far as the walk goes (the last point walked).
    Flat(f64),
    /// A refit failed (the model could not be evaluated there, χ² not finite): the Wald end
    /// p̂ ± 1.96 SE stands in.
    Failed(f64),
}

impl ProfileEnd {
    /// The end's value.
    pub fn value(self) -> f64 {
        match self {
            ProfileEnd::Crossing(x)
            | ProfileEnd::Bound(x)
            | ProfileEnd::Flat(x)
            | ProfileEnd::Failed(x) => x,
        }
    }
}

/// A parameter's profile: its interval's ends and the points walked, (value, Δχ²), in order.
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    /// The lower end.
    pub lower: ProfileEnd,
    /// The upper end.
    pub upper: ProfileEnd,
    /// The points walked, (value, Δχ²), sorted by value.
    pub points: Vec<(f64, f64)>,
    /// The lowest Δχ² met (negative: the profile found a lower χ² than the fit's).
    pub lowest: f64,
    /// Refits made.
    pub refits: usize,
    /// Model evaluations the refits made.
    pub evaluations: usize,
    /// Refits that stopped at `REFIT_PATIENCE` before converging.
    pub unconverged: usize,
}

/// A least-squares fit at its minimum, as a profile walks about it: the model, the
/// observations and the parameters, the minimum `best`, the parameters `fixed` in the fit, and
/// `s2`, which scales χ² (the noise variance, 1 with σ given).
pub(crate) struct Fitted<'a> {
    /// The model fitted.
    pub model: &'a dyn CurveModel,
    /// The observations.
    pub obs: &'a Observations<'a>,
    /// The parameters, in the fit's order.
    pub params: &'a [Parameter],
    /// The minimum.
    pub best: &'a Minimum,
    /// The parameters held fixed in the fit (`Some`: their values).
    pub fixed: &'a [Option<f64>],
    /// The scale of χ².
    pub s2: f64,
}

/// The profile of parameter `j` of `fit` about its minimum, the parameters fixed in the fit
/// held there too, walked as `walk` says from steps of `step` (its standard error, or a
/// fraction of its scale where that is not finite), each refit starting from the neighbouring
/// point's values. Every refit's evaluations are counted in `progress` and check its cancel
/// flag.
///
/// # Errors
/// [`SimError::Cancelled`] when `progress` is cancelled.
pub(crate) fn profile(
    fit: &Fitted,
    j: usize,
    step: f64,
    walk: ProfileWalk,
    progress: &Progress,
) -> Result<Profile, SimError> {
    let centre = fit.best.values[j];
    let mut walker = Walker {
        fit,
        j,
        progress,
        points: vec![(centre, 0.0)],
        refits: 0,
        evaluations: 0,
        unconverged: 0,
        lowest: 0.0,
    };
    let mut ends = [ProfileEnd::Flat(centre); 2];
    for (side, sign) in [-1.0_f64, 1.0].into_iter().enumerate() {
        ends[side] = match walk {
            ProfileWalk::Grid => walker.grid(sign, step)?,
            ProfileWalk::Secant { max_steps } => walker.secant(sign, step, max_steps)?,
        };
    }
    let Walker {
        mut points,
        refits,
        evaluations,
        unconverged,
        lowest,
        ..
    } = walker;
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(Profile {
        lower: ends[0],
        upper: ends[1],
        points,
        lowest,
        refits,
        evaluations,
        unconverged,
    })
}

/// The state of one profile's walk: the fit, the points walked, the refits made.
struct Walker<'a> {
    fit: &'a Fitted<'a>,
    j: usize,
    progress: &'a Progress,
    points: Vec<(f64, f64)>,
    refits: usize,
    evaluations: usize,
    unconverged: usize,
    lowest: f64,
}

impl Walker<'_> {
    /// Δχ² with parameter j held at `x`, the others refitted from `from`, and the refit's
    /// values; the point recorded (a finite Δχ² only).
    fn delta_at(&mut self, x: f64, from: &[f64]) -> Result<(f64, Vec<f64>), SimError> {
        let mut held = self.fit.fixed.to_vec();
        held[self.j] = Some(x);
        let m = minimize_cancellable(
            self.fit.model,
            self.fit.obs,
            self.fit.params,
            from,
            &held,
            (REFIT_TOLERANCE, REFIT_PATIENCE),
            self.progress,
        )?;
        self.refits += 1;
        self.unconverged += usize::from(!m.converged);
        self.evaluations += m.evaluations;
        let d = (m.chi2 - self.fit.best.chi2) / self.fit.s2;
        if d.is_finite() {
            self.points.push((x, d));
            self.lowest = self.lowest.min(d);
        }
        Ok((d, m.values))
    }

    /// The parameter's bound on the side `sign` (−1 lower, +1 upper).
    fn bound(&self, sign: f64) -> f64 {
        let p = &self.fit.params[self.j];
        if sign < 0.0 {
            p.lower
        } else {
            p.upper
        }
    }

    /// The grid walk of one side ([`ProfileWalk::Grid`]).
    fn grid(&mut self, sign: f64, step: f64) -> Result<ProfileEnd, SimError> {
        let centre = self.fit.best.values[self.j];
        let bound = self.bound(sign);
        let (mut prev_x, mut prev_d, mut prev_v) = (centre, 0.0, self.fit.best.values.clone());
        let mut distance = 0.0;
        for i in 1..=MAX_PROFILE_STEPS {
            distance = if i <= 8 {
                0.5 * step * i as f64
            } else {
                distance * 1.5
            };
            let mut x = centre + sign * distance;
            let at_bound = (x - bound) * sign >= 0.0;
            if at_bound {
                x = bound;
            }
            let (d, v) = self.delta_at(x, &prev_v)?;
            if !d.is_finite() {
                return Ok(ProfileEnd::Failed(centre + sign * Z_95 * step));
            }
            if d >= DELTA_CHI2_95 {
                // bisect [prev_x, x], then interpolate linearly inside the last bracket
                let (mut a, mut da, mut b, mut db) = (prev_x, prev_d, x, d);
                for _ in 0..BISECTIONS {
                    let c = 0.5 * (a + b);
                    let (dc, vc) = self.delta_at(c, &prev_v)?;
                    if !dc.is_finite() {
                        break;
                    }
                    if dc >= DELTA_CHI2_95 {
                        (b, db) = (c, dc);
                    } else {
                        (a, da, prev_v) = (c, dc, vc);
                    }
                }
                let t = ((DELTA_CHI2_95 - da) / (db - da)).clamp(0.0, 1.0);
                return Ok(ProfileEnd::Crossing(a + t * (b - a)));
            }
            if at_bound {
                return Ok(ProfileEnd::Bound(x));
            }
            (prev_x, prev_d, prev_v) = (x, d, v);
        }
        Ok(ProfileEnd::Flat(prev_x))
    }

    /// The secant walk of one side ([`ProfileWalk::Secant`]), in the distance δ ≥ 0 from the
    /// estimate and r = √max(Δχ², 0).
    fn secant(&mut self, sign: f64, step: f64, max_steps: usize) -> Result<ProfileEnd, SimError> {
        let centre = self.fit.best.values[self.j];
        let bound = self.bound(sign);
        let target = DELTA_CHI2_95.sqrt();
        // the farthest point below the threshold (δ, r, values), the one before it, and the
        // nearest above
        let mut below = (0.0, 0.0, self.fit.best.values.clone());
        let mut before = (0.0, 0.0);
        let mut above: Option<(f64, f64, Vec<f64>)> = None;
        let mut delta = step;
        for _ in 0..max_steps {
            let mut x = centre + sign * delta;
            let at_bound = (x - bound) * sign >= 0.0;
            if at_bound {
                x = bound;
                delta = (bound - centre).abs();
            }
            // warm start: the nearer of the walked points on either side of δ
            let from = match &above {
                Some(a) if a.0 - delta < delta - below.0 => a.2.clone(),
                _ => below.2.clone(),
            };
            let (d, v) = self.delta_at(x, &from)?;
            if !d.is_finite() {
                return Ok(ProfileEnd::Failed(centre + sign * Z_95 * step));
            }
            if (d - DELTA_CHI2_95).abs() <= SECANT_TOLERANCE {
                return Ok(ProfileEnd::Crossing(x));
            }
            let r = d.max(0.0).sqrt();
            if d < DELTA_CHI2_95 {
                if at_bound {
                    return Ok(ProfileEnd::Bound(x));
                }
                before = (below.0, below.1);
                below = (delta, r, v);
            } else {
                above = Some((delta, r, v));
            }
            delta = match &above {
                // regula falsi on r inside the bracket, kept off its ends
                Some((dh, rh, _)) => {
                    let (dl, rl) = (below.0, below.1);
                    let t = ((target - rl) / (rh - rl)).clamp(0.02, 0.98);
                    dl + t * (dh - dl)
                }
                // the secant through the last two points below, at most doubling δ; from the
                // estimate and the first point aimed at the threshold (exact for a parabola),
                // later at the tolerance band's upper half (r of a profile that bends over
                // rises slower than its secant: aimed at the threshold it stops short of it)
                None => {
                    let (da, ra) = before;
                    let (db, rb) = (below.0, below.1);
                    let most = 2.0 * db;
                    let aim = if da == 0.0 {
                        target
                    } else {
                        (DELTA_CHI2_95 + 0.5 * SECANT_TOLERANCE).sqrt()
                    };
                    if rb > ra {
                        (db + (aim - rb) * (db - da) / (rb - ra)).clamp(1.05 * db, most)
                    } else {
                        most
                    }
                }
            };
        }
        Ok(match above {
            // the crossing interpolated linearly in r inside its bracket
            Some((dh, rh, _)) => {
                let (dl, rl) = (below.0, below.1);
                let t = ((target - rl) / (rh - rl)).clamp(0.0, 1.0);
                ProfileEnd::Crossing(centre + sign * (dl + t * (dh - dl)))
            }
            None => ProfileEnd::Flat(centre + sign * below.0),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::fit::least_squares::minimize;

    /// A fit at `best` with no parameter held and χ² at its scale (σ given).
    fn unfixed<'a>(
        model: &'a Model,
        obs: &'a Observations<'a>,
        params: &'a [Parameter],
        best: &'a Minimum,
        none: &'a [Option<f64>],
    ) -> Fitted<'a> {
        Fitted {
            model,
            obs,
            params,
            best,
            fixed: none,
            s2: 1.0,
        }
    }

    /// f = a + b x (linear in its parameters), or f = p² x (`square`).
    struct Model {
        x: Vec<f64>,
        square: bool,
    }
    impl CurveModel for Model {
        fn points(&self) -> usize {
            self.x.len()
        }
        fn evaluate(&self, p: &[f64], v: &mut [f64], jac: Option<&mut [f64]>) {
            let n = p.len();
            for (i, x) in self.x.iter().enumerate() {
                v[i] = if self.square {
                    p[0] * p[0] * x
                } else {
                    p[0] + p[1] * x
                };
            }
            if let Some(j) = jac {
                for (i, x) in self.x.iter().enumerate() {
                    if self.square {
                        j[i] = 2.0 * p[0] * x;
                    } else {
                        j[i * n..i * n + 2].copy_from_slice(&[1.0, *x]);
                    }
                }
            }
        }
    }

    fn param(name: &str, start: f64) -> Parameter {
        Parameter {
            name: name.into(),
            start,
            lower: f64::NEG_INFINITY,
            upper: f64::INFINITY,
            scale: 1.0,
        }
    }

    /// Data y = 1 + 2x + a deterministic wiggle (σ = 0.1 each).
    fn data(x: &[f64]) -> (Vec<f64>, Vec<f64>) {
        let y = x
            .iter()
            .enumerate()
            .map(|(i, x)| 1.0 + 2.0 * x + 0.1 * (1.7 * i as f64).sin())
            .collect();
        (y, vec![0.1; x.len()])
    }

    /// A model linear in its parameters has the parabola Δχ² = ((x − p̂)/SE)² for a profile:
    /// the secant walk's second refit a side lands on the Wald end p̂ ± 1.96 SE, the crossing,
    /// SE² = ((JᵀWJ)⁻¹)ⱼⱼ here in closed form (the straight line's, Bates & Watts 1988 §2.3).
    #[test]
    fn a_linear_models_profile_ends_are_the_wald_ends() {
        let x: Vec<f64> = (0..20).map(|i| i as f64 * 0.25).collect();
        let (y, s) = data(&x);
        let obs = Observations {
            y: &y,
            sigma: Some(&s),
        };
        let model = Model {
            x: x.clone(),
            square: false,
        };
        let params = [param("a", 0.0), param("b", 0.0)];
        let best = minimize(&model, &obs, &params, &[0.0, 0.0], &[None, None]);
        // (JᵀWJ) = Σ w [1 x; x x²], its inverse's diagonal
        let w = 1.0 / (0.1 * 0.1);
        let (s0, s1, s2) = (
            w * x.len() as f64,
            w * x.iter().sum::<f64>(),
            w * x.iter().map(|v| v * v).sum::<f64>(),
        );
        let det = s0 * s2 - s1 * s1;
        let se = [(s2 / det).sqrt(), (s0 / det).sqrt()];
        let progress = Progress::new();
        let walk = ProfileWalk::Secant {
            max_steps: MAX_SECANT_STEPS,
        };
        for (j, se) in se.into_iter().enumerate() {
            let fit = unfixed(&model, &obs, &params, &best, &[None, None]);
            let pr = profile(&fit, j, se, walk, &progress).unwrap();
            let c = best.values[j];
            for (end, wald) in [(pr.lower, c - Z_95 * se), (pr.upper, c + Z_95 * se)] {
                assert!(matches!(end, ProfileEnd::Crossing(_)), "{end:?}");
                assert!(
                    (end.value() - wald).abs() <= 1e-9 * se,
                    "{j}: {end:?} against {wald}"
                );
            }
            assert_eq!(pr.refits, 4, "{j}: {:?}", pr.points);
        }
    }

    /// f = p² x: χ²(p) − χ²(p̂) = Σ wᵢ xᵢ² (p² − p̂²)² (the residuals at p̂ are orthogonal to
    /// x), so the ends are p = √(p̂² ± √(3.841 / Σ wᵢ xᵢ²)) in closed form; the secant walk's
    /// ends have Δχ² within [`SECANT_TOLERANCE`] of 3.841 by that formula, and the grid walk
    /// (bisections and a linear interpolation) comes close too.
    #[test]
    fn a_nonlinear_models_profile_ends_are_its_closed_form_crossings() {
        let x: Vec<f64> = (1..=12).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = x
            .iter()
            .enumerate()
            .map(|(i, x)| 0.64 * x + 0.05 * (2.3 * i as f64).cos())
            .collect();
        let s = vec![0.05; x.len()];
        let obs = Observations {
            y: &y,
            sigma: Some(&s),
        };
        let model = Model {
            x: x.clone(),
            square: true,
        };
        let params = [param("p", 1.0)];
        let best = minimize(&model, &obs, &params, &[1.0], &[None]);
        let p2 = best.values[0].powi(2);
        let sxx: f64 = x.iter().map(|v| v * v / (0.05 * 0.05)).sum();
        let delta = |p: f64| sxx * (p * p - p2).powi(2);
        let closed = [
            (p2 - (DELTA_CHI2_95 / sxx).sqrt()).sqrt(),
            (p2 + (DELTA_CHI2_95 / sxx).sqrt()).sqrt(),
        ];
        // SE from JᵀWJ = Σ w (2 p x)²
        let se = 1.0 / (2.0 * best.values[0] * sxx.sqrt());
        let progress = Progress::new();
        for (walk, tol) in [
            (
                ProfileWalk::Secant {
                    max_steps: MAX_SECANT_STEPS,
                },
                SECANT_TOLERANCE,
            ),
            (ProfileWalk::Grid, 0.01),
        ] {
            let fit = unfixed(&model, &obs, &params, &best, &[None]);
            let pr = profile(&fit, 0, se, walk, &progress).unwrap();
            for (end, c) in [pr.lower, pr.upper].into_iter().zip(closed) {
                let d = delta(end.value());
                assert!(
                    matches!(end, ProfileEnd::Crossing(_)) && (d - DELTA_CHI2_95).abs() <= tol,
                    "{walk:?}: {end:?} (closed form {c}): Δχ² {d}"
                );
            }
        }
    }

    /// A parameter the model does not depend on: Δχ² stays 0, and after the walk's refits a
    /// side the ends are flat, the last points walked (the step doubling from 1: 32).
    #[test]
    fn a_parameter_the_model_ignores_has_a_flat_profile() {
        let x: Vec<f64> = (0..10).map(|i| i as f64).collect();
        let (y, s) = data(&x);
        let obs = Observations {
            y: &y,
            sigma: Some(&s),
        };
        let model = Model { x, square: true };
        // p[1] is not used by f = p₀² x
        let params = [param("p", 1.0), param("q", 0.0)];
        let best = minimize(&model, &obs, &params, &[1.0, 0.0], &[None, None]);
        let fit = unfixed(&model, &obs, &params, &best, &[None, None]);
        let walk = ProfileWalk::Secant { max_steps: 6 };
        let pr = profile(&fit, 1, 1.0, walk, &Progress::new()).unwrap();
        let c = best.values[1];
        assert_eq!(
            (pr.lower, pr.upper),
            (ProfileEnd::Flat(c - 32.0), ProfileEnd::Flat(c + 32.0))
        );
        assert!(pr.points.iter().all(|&(_, d)| d == 0.0), "{:?}", pr.points);
        assert_eq!(pr.refits, 12);
    }
}
