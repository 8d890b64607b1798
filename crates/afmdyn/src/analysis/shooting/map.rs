//! Shooting on any [`DiscreteMap`]: the period-n orbits (n iterates of the map) that
//! [`shoot`] finds, on the stroboscopic map of an integrator as on any other, written against
//! the trait so that every map runs through the same code (`tests/maps.rs`: an affine map with
//! a closed-form fixed point, and the stroboscopic map of the paper's linear model).

use super::{
    floquet_stability, proper_period, Guess, PeriodicOrbit, ShootingOptions, ShootingStrategy,
    GRAZING_TOL, LINE_SEARCH_MIN_STEP, SECTION_STARTS, VARIATIONAL_SLACK,
};
use crate::error::SimError;
use crate::maps::flow::FlowMap;
use crate::maps::DiscreteMap;
use nalgebra::{DMatrix, DVector};
use std::borrow::Cow;

/// A period-n orbit (n = [`ShootingOptions::period`] iterates of the map `dmap`) from `guess`,
/// a zero of F(z) = Pⁿ(z) − z, solved by [`ShootingOptions::strategy`]. On an integrator, on
/// its period-1 [`StroboscopicMap`]: `shoot(&mut StroboscopicMap::new(integ, 1), guess, opts)`.
///
/// # Errors
/// [`SimError::NoConvergence`] when the solve fails (as the strategy says), or after
/// `opts.max_iter` iterations; [`SimError::OutOfRange`] for n = 0 and as [`Guess`] says;
/// [`SimError::Cancelled`] and [`SimError`] from the map.
///
/// [`StroboscopicMap`]: crate::maps::StroboscopicMap
pub fn shoot<'a>(
    dmap: &mut dyn DiscreteMap,
    guess: impl Into<Guess<'a>>,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    match guess.into() {
        Guess::State(z) => solve(dmap, z, None, opts),
        Guess::Estimated { state, monodromy } => solve(dmap, state, Some(monodromy), opts),
        Guess::Section(section) => from_section(dmap, section, opts),
    }
}

/// [`shoot`] from the state `z`, with `estimate` of the monodromy matrix for Broyden's first
/// Jacobian.
fn solve(
    dmap: &mut dyn DiscreteMap,
    z: &DVector<f64>,
    estimate: Option<&DMatrix<f64>>,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    let n = opts.period;
    let dim = z.len();
    match opts.strategy {
        ShootingStrategy::Newton => finished(dmap, z, opts, Damping::Halve),
        ShootingStrategy::Globalised => finished(dmap, z, opts, Damping::LineSearch),
        ShootingStrategy::Undamped => {
            let (state, map, residuals) = newton(dmap, z, n, opts, Damping::Stop)?;
            closes_in_its_region(dmap, &state, n, &residuals)?;
            Ok(orbit(state, None, n, map, residuals, f64::NAN))
        }
        ShootingStrategy::Broyden => {
            let m0 = estimate.map_or_else(|| Cow::Owned(DMatrix::zeros(dim, dim)), Cow::Borrowed);
            let (state, map, residuals) = broyden(dmap, z, n, opts, &m0)?;
            Ok(orbit(state, None, n, map, residuals, f64::NAN))
        }
        ShootingStrategy::BroydenFromZero => {
            if n == 1 {
                let first = ShootingOptions {
                    max_iter: (2 * dim + 2).min(opts.max_iter),
                    ..*opts
                };
                match broyden(dmap, z, n, &first, &DMatrix::zeros(dim, dim)) {
                    Ok((state, map, residuals)) => {
                        return Ok(orbit(state, None, 1, map, residuals, f64::NAN));
                    }
                    Err(SimError::Cancelled) => return Err(SimError::Cancelled),
                    // Newton from the guess
                    Err(_) => {}
                }
            }
            finished(dmap, z, opts, Damping::Halve)
        }
    }
}

/// [`newton`] with `damping`, then [`finish`]: the finished strategies.
fn finished(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    opts: &ShootingOptions,
    damping: Damping,
) -> Result<PeriodicOrbit, SimError> {
    let (z, map, residuals) = newton(dmap, guess, opts.period, opts, damping)?;
    finish(dmap, z, opts.period, map, residuals, opts)
}

/// [`shoot`] from the close returns of an attractor's section points ([`Guess::Section`]).
fn from_section(
    dmap: &mut dyn DiscreteMap,
    section: &[DVector<f64>],
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    let n = opts.period;
    if n == 0 || section.len() <= n {
        return Err(SimError::out_of_range(
            "section points",
            section.len(),
            "must exceed the period n >= 1",
        ));
    }
    let mut returns: Vec<(f64, usize)> = (0..section.len() - n)
        .map(|k| ((&section[k + n] - &section[k]).norm(), k))
        .filter(|(r, _)| r.is_finite())
        .collect();
    returns.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best: Option<SimError> = None;
    for &(_, k) in returns.iter().take(SECTION_STARTS) {
        match solve(dmap, &section[k], None, opts) {
            Ok(orbit) => return Ok(orbit),
            Err(SimError::Cancelled) => return Err(SimError::Cancelled),
            Err(e) => {
                let better = match (&e, &best) {
                    (_, None) => true,
                    (
                        SimError::NoConvergence { residual: a, .. },
                        Some(SimError::NoConvergence { residual: b, .. }),
                    ) => a < b,
                    (SimError::NoConvergence { .. }, Some(_)) => true,
                    _ => false,
                };
                if better {
                    best = Some(e);
                }
            }
        }
    }
    Err(match best {
        Some(SimError::NoConvergence {
            iterations,
            residual,
            ..
        }) => SimError::NoConvergence {
            what: "shooting from the closest returns of the attractor's section points",
            iterations,
            residual,
        },
        Some(e) => e,
        None => SimError::NoConvergence {
            what: "shooting from the attractor's section points (none finite)",
            iterations: 0,
            residual: f64::NAN,
        },
    })
}

/// The orbit through `state` (period n, its `map`'s monodromy matrix and switchings, the
/// solve's `residuals`): its multipliers formed, with its `section` points (`None`: an
/// unfinished orbit, `[state]`) and `grazing_distance`.
fn orbit(
    state: DVector<f64>,
    section: Option<Vec<DVector<f64>>>,
    n: usize,
    map: FlowMap,
    residuals: Vec<f64>,
    grazing_distance: f64,
) -> PeriodicOrbit {
    let (multipliers, stable, critical) = floquet_stability(&map.jacobian);
    PeriodicOrbit {
        period: n,
        section: section.unwrap_or_else(|| vec![state.clone()]),
        state,
        monodromy: map.jacobian,
        multipliers,
        stable,
        critical,
        grazing: grazing_distance < GRAZING_TOL,
        grazing_distance,
        switchings: map.switchings,
        residuals,
    }
}

/// The fixed point z = Pⁿ(z) is refused where it is no orbit of the system the map comes from
/// ([`DiscreteMap::closes`]): for a hysteretic system
/// ([`crate::tip_sample::TipSampleSystem::is_hysteretic`]) the flow must end in the region a
/// start at z is given ([`crate::system::HybridSystem::mode_at`]'s rule in the neck's band);
/// where it does not, the map restarts in the other region than the motion is in (one extra
/// flow, for such systems only).
///
/// # Errors
/// [`SimError::NoConvergence`] naming the mismatch; the map's errors.
fn closes_in_its_region(
    dmap: &mut dyn DiscreteMap,
    z: &DVector<f64>,
    n: usize,
    residuals: &[f64],
) -> Result<(), SimError> {
    if dmap.closes(z, n)? {
        return Ok(());
    }
    Err(SimError::NoConvergence {
        what: "shooting (the fixed point crosses the section in the contact's neck, 0 < V_T < \
               |δ_b|, in the other region than a start there is given: no orbit of the \
               hysteretic law)",
        iterations: residuals.len(),
        residual: residuals.last().copied().unwrap_or(f64::NAN),
    })
}

/// The iteration of [`ShootingStrategy::Broyden`] from `m0`: the converged z (closed in its
/// region), its map (the variational flow's) and the residuals.
fn broyden(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
    m0: &DMatrix<f64>,
) -> Result<(DVector<f64>, FlowMap, Vec<f64>), SimError> {
    if n == 0 {
        return Err(SimError::out_of_range("period", n, "must be >= 1"));
    }
    dmap.check_state("initial guess", guess)?;
    let dim = guess.len();
    if m0.shape() != (dim, dim) {
        let (r, c) = m0.shape();
        return Err(SimError::out_of_range(
            "monodromy estimate",
            format!("{r}x{c}"),
            "must be 2N x 2N, N the model's mode count",
        ));
    }
    let mut z = guess.clone();
    let mut f = dmap.iterate(&z, n)? - &z;
    let mut jac = m0 - DMatrix::identity(dim, dim);
    let mut residuals = Vec::new();
    let mut res = f.norm();
    for _ in 0..opts.max_iter {
        residuals.push(res);
        if res <= opts.tol * (1.0 + z.norm()) {
            break;
        }
        let delta = jac
            .clone()
            .lu()
            .solve(&(-&f))
            .ok_or(SimError::NoConvergence {
                what: "shooting (singular M − I)",
                iterations: residuals.len(),
                residual: res,
            })?;
        let trial = &z + &delta;
        let f_new = dmap.iterate(&trial, n)? - &trial;
        let res_new = f_new.norm();
        // a NaN residual fails too
        if res_new.partial_cmp(&res) != Some(std::cmp::Ordering::Less) {
            return Err(SimError::NoConvergence {
                what: "shooting (a Broyden step did not lower the residual)",
                iterations: residuals.len(),
                residual: res,
            });
        }
        // J ← J + (ΔF − J δ) δᵀ / δᵀδ
        let u = (&f_new - &f) - &jac * &delta;
        jac.ger(1.0 / delta.norm_squared(), &u, &delta, 1.0);
        z = trial;
        f = f_new;
        res = res_new;
    }
    if res > opts.tol * (1.0 + z.norm()) {
        return Err(SimError::NoConvergence {
            what: "shooting",
            iterations: opts.max_iter,
            residual: res,
        });
    }
    // the converged orbit's monodromy matrix, from a flow whose map differs from the plain
    // flows' by the integration error (their steps differ): a residual within
    // VARIATIONAL_SLACK tolerances is that error, a larger one calls for Newton steps
    let map = dmap.linearise(&z, n, false)?;
    let res_var = (&map.state - &z).norm();
    if res_var <= VARIATIONAL_SLACK * opts.tol * (1.0 + z.norm()) {
        residuals.push(res_var);
        closes_in_its_region(dmap, &z, n, &residuals)?;
        return Ok((z, map, residuals));
    }
    let (state, map, more) = newton(dmap, &z, n, opts, Damping::Stop)?;
    residuals.extend(more);
    closes_in_its_region(dmap, &state, n, &residuals)?;
    Ok((state, map, residuals))
}

/// What [`newton`] does with a full step that does not lower ‖F‖.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Damping {
    /// Halve it until ‖F‖ drops, down to 1e-3 of the step.
    Halve,
    /// Stop: the solve fails.
    Stop,
    /// Backtrack along the Newton direction until f = ½‖F‖² decreases sufficiently (Armijo),
    /// see [`line_search`]; the solve fails when the step falls below [`LINE_SEARCH_MIN_STEP`].
    LineSearch,
}

/// Armijo's constant c in f(z + λp) ≤ f(z) + c λ ∇fᵀp (Dennis & Schnabel, *Numerical Methods
/// for Unconstrained Optimization and Nonlinear Equations*, SIAM 1996, §6.3.1: α = 1e-4).
const ARMIJO: f64 = 1e-4;

/// A backtracking line search for Newton's step `delta` from `z` (residual `res` = ‖F(z)‖) on
/// the merit function f = ½‖F‖²: the first λ = 1, ρ₁λ, … with f(z + λδ) ≤ f(z) + c λ ∇fᵀδ,
/// where ∇fᵀδ = Fᵀ(M − I)δ = −‖F‖² for the Newton direction (a descent direction of f), each
/// backtrack the minimiser of the quadratic through f(z), its slope and f(z + λδ), safeguarded
/// to [0.1 λ, 0.5 λ] (Dennis & Schnabel 1996, Algorithm A6.3.1; Nocedal & Wright, *Numerical
/// Optimization*, 2nd ed., Springer 2006, §3.5 and §11.2). A trial the map cannot start from
/// (e.g. inside a rigid sample) is a failed trial. `Ok(None)` when λ falls below
/// [`LINE_SEARCH_MIN_STEP`].
fn line_search(
    dmap: &mut dyn DiscreteMap,
    z: &DVector<f64>,
    delta: &DVector<f64>,
    res: f64,
    n: usize,
) -> Result<Option<(DVector<f64>, FlowMap, f64)>, SimError> {
    let f0 = 0.5 * res * res;
    let slope = -res * res;
    let mut lambda = 1.0_f64;
    while lambda >= LINE_SEARCH_MIN_STEP {
        let trial = z + delta * lambda;
        let f_trial = match dmap.linearise(&trial, n, false) {
            Ok(tmap) => {
                let tres = (&tmap.state - &trial).norm();
                let f1 = 0.5 * tres * tres;
                if f1 <= f0 + ARMIJO * lambda * slope {
                    return Ok(Some((trial, tmap, tres)));
                }
                f1
            }
            Err(SimError::Cancelled) => return Err(SimError::Cancelled),
            Err(_) => f64::NAN,
        };
        // the quadratic q(t) = f0 + slope t + (f_trial − f0 − slope λ) t²/λ² has its minimum at
        // −slope λ² / (2 (f_trial − f0 − slope λ)); a NaN trial halves
        let curv = f_trial - f0 - slope * lambda;
        let next = if curv.is_finite() && curv > 0.0 {
            -slope * lambda * lambda / (2.0 * curv)
        } else {
            0.5 * lambda
        };
        lambda = next.clamp(0.1 * lambda, 0.5 * lambda);
    }
    Ok(None)
}

/// The Newton iteration of [`shoot`] (and of [`minimal`]): the converged z, its map
/// (unwatched: no grazing searches) and the residuals.
fn newton(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
    damping: Damping,
) -> Result<(DVector<f64>, FlowMap, Vec<f64>), SimError> {
    if n == 0 {
        return Err(SimError::out_of_range("period", n, "must be >= 1"));
    }
    dmap.check_state("initial guess", guess)?;
    let dim = guess.len();
    let mut z = guess.clone();
    let mut residuals = Vec::new();
    // the iterates without the grazing searches (`finish` gives the converged orbit its
    // distance to grazing)
    let mut map = dmap.linearise(&z, n, false)?;
    let mut res = (&map.state - &z).norm();
    for _ in 0..opts.max_iter {
        residuals.push(res);
        if res <= opts.tol * (1.0 + z.norm()) {
            return Ok((z, map, residuals));
        }
        let a = &map.jacobian - DMatrix::identity(dim, dim);
        let delta = a
            .lu()
            .solve(&(&z - &map.state))
            .ok_or(SimError::NoConvergence {
                what: "shooting (singular M − I)",
                iterations: residuals.len(),
                residual: res,
            })?;
        if damping == Damping::LineSearch {
            match line_search(dmap, &z, &delta, res, n)? {
                Some((trial, tmap, tres)) => {
                    z = trial;
                    map = tmap;
                    res = tres;
                    continue;
                }
                None => {
                    return Err(SimError::NoConvergence {
                        what: "shooting (the line search found no decrease of the residual \
                               along the Newton direction)",
                        iterations: residuals.len(),
                        residual: res,
                    })
                }
            }
        }
        // damped Newton: halve the step while the residual grows
        let mut lambda = 1.0;
        loop {
            let trial = &z + &delta * lambda;
            // a trial the map cannot start from (e.g. inside a rigid sample) is a failed trial
            let last = lambda < 1e-3 || damping == Damping::Stop;
            match dmap.linearise(&trial, n, false) {
                Ok(tmap) => {
                    let tres = (&tmap.state - &trial).norm();
                    if tres < res || lambda < 1e-3 {
                        z = trial;
                        map = tmap;
                        res = tres;
                        break;
                    }
                    if last {
                        return Err(SimError::NoConvergence {
                            what: "shooting (a full Newton step did not lower the residual)",
                            iterations: residuals.len(),
                            residual: res,
                        });
                    }
                }
                Err(e) if last => return Err(e),
                Err(_) => {}
            }
            lambda *= 0.5;
        }
    }
    residuals.push(res);
    if res <= opts.tol * (1.0 + z.norm()) {
        return Ok((z, map, residuals));
    }
    Err(SimError::NoConvergence {
        what: "shooting",
        iterations: opts.max_iter,
        residual: res,
    })
}

/// The n section states z, P(z), …, Pⁿ⁻¹(z) of a period-n orbit (each image with its
/// Jacobian and distance to grazing, [`DiscreteMap::linearise`], as the stroboscopic map
/// always took them).
///
/// # Errors
/// [`SimError`] from the map.
pub fn map_section_points(
    dmap: &mut dyn DiscreteMap,
    z: &DVector<f64>,
    n: usize,
) -> Result<Vec<DVector<f64>>, SimError> {
    let mut section = vec![z.clone()];
    for _ in 1..n {
        let next = dmap
            .linearise(section.last().expect("non-empty"), 1, true)?
            .state;
        section.push(next);
    }
    Ok(section)
}

/// The period-n orbit through `z` (converged to `opts.tol`) reduced to its minimal period:
/// the orbit shot again at the `proper_period` of its section, which must converge there
/// (else n stands), finished with `opts`' grazing watch. `Ok(None)` when n is minimal (costs
/// n − 1 plain flows of one period).
///
/// # Errors
/// [`SimError`] from the map.
pub fn reduce_map_period(
    dmap: &mut dyn DiscreteMap,
    z: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<Option<PeriodicOrbit>, SimError> {
    if n < 2 {
        return Ok(None);
    }
    let section = map_section_points(dmap, z, n)?;
    minimal(dmap, &section, opts)
}

/// [`reduce_map_period`] on the orbit's section points.
fn minimal(
    dmap: &mut dyn DiscreteMap,
    section: &[DVector<f64>],
    opts: &ShootingOptions,
) -> Result<Option<PeriodicOrbit>, SimError> {
    let Some(d) = proper_period(section, opts.tol) else {
        return Ok(None);
    };
    match newton(dmap, &section[0], d, opts, Damping::Stop) {
        Ok((z, map, residuals)) => finish(dmap, z, d, map, residuals, opts).map(Some),
        Err(SimError::Cancelled) => Err(SimError::Cancelled),
        // not an orbit of period d after all: n stands
        Err(_) => Ok(None),
    }
}

/// The converged orbit of a Newton solve, finished ([`ShootingStrategy`]): refused where it
/// does not close in its region, reduced to its minimal period, with its section points,
/// multipliers and (watched, [`ShootingOptions::watch_grazing`]) its distance to grazing.
fn finish(
    dmap: &mut dyn DiscreteMap,
    z: DVector<f64>,
    n: usize,
    map: FlowMap,
    residuals: Vec<f64>,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    closes_in_its_region(dmap, &z, n, &residuals)?;
    let section = map_section_points(dmap, &z, n)?;
    // the minimal period: an orbit found as period n may repeat after a divisor of n
    if let Some(o) = minimal(dmap, &section, opts)? {
        return Ok(o);
    }
    let grazing_distance = if opts.watch_grazing {
        dmap.grazing_distance(&z, n)?
    } else {
        f64::NAN
    };
    Ok(orbit(z, Some(section), n, map, residuals, grazing_distance))
}
