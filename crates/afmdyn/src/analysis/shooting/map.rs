//! Newton shooting on any [`DiscreteMap`]: the period-n orbits (n iterates of the map) that
//! [`super`]'s functions find on the stroboscopic map of an integrator, written against the
//! trait so that every map runs through the same code (`tests/maps.rs`: an affine map with a
//! closed-form fixed point, and the stroboscopic map of the paper's linear model).

use super::{
    floquet_stability, proper_period, PeriodicOrbit, ShootingOptions, ShootingStrategy, ShotOrbit,
    GRAZING_TOL, LINE_SEARCH_MIN_STEP, SECTION_STARTS, VARIATIONAL_SLACK,
};
use crate::error::SimError;
use crate::maps::flow::FlowMap;
use crate::maps::DiscreteMap;
use nalgebra::{DMatrix, DVector};

/// Newton iteration for F(z) = Pⁿ(z) − z from `guess` on the map `dmap` (n iterates of it: a
/// period-n orbit of the map), damped by halving a step that does not lower ‖F‖.
///
/// # Errors
/// [`SimError::NoConvergence`] when Newton fails; [`SimError`] from the map.
pub fn shoot_map(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    shoot_damped(dmap, guess, n, opts, Watch::Grazing)
}

/// [`shoot_map`] without the distance to grazing: the same iterates, orbit, section points and
/// multipliers, but no flow to measure [`PeriodicOrbit::grazing_distance`] (NaN, and
/// [`PeriodicOrbit::grazing`] `false`), for a caller that does not report it — the steady tap
/// of [`crate::analysis::peakforce`], where that flow (with the variational equations, as
/// [`DiscreteMap::grazing_distance`] takes it) was a fifth of the N = 3 beam's tap.
///
/// # Errors
/// As [`shoot_map`].
pub fn shoot_map_unwatched(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    shoot_damped(dmap, guess, n, opts, Watch::None)
}

/// [`shoot_map_unwatched`] by `strategy` ([`ShootingStrategy`]). With
/// [`ShootingStrategy::BroydenFromZero`] a period-1 orbit (n = 1) is first sought by Broyden's
/// updates from the monodromy estimate M ≈ 0 ([`shoot_map_broyden`] with `m0` = 0) within
/// 2d + 2 iterates (d the state's dimension; at most `opts.max_iter`): Broyden's method
/// reaches the zero of an affine F in at most 2d steps (Gay, *SIAM J. Numer. Anal.* 16 (1979)
/// 623), and the residual of the last is checked in one more. Where those updates fail (no
/// convergence within the cap, a step that does not lower the residual, a singular M − I or
/// a fixed point that does not close in its region), [`shoot_map_unwatched`] solves from
/// `guess` as with [`ShootingStrategy::Newton`]; so it does for n > 1, whose minimal period
/// only Newton's solve checks. The orbit of the Broyden solve has no distance to grazing (NaN),
/// as [`shoot_map_unwatched`]'s.
///
/// # Errors
/// As [`shoot_map_unwatched`]; [`SimError::Cancelled`] from the Broyden solve.
pub fn shoot_map_unwatched_by(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
    strategy: ShootingStrategy,
) -> Result<PeriodicOrbit, SimError> {
    if n == 1 && strategy == ShootingStrategy::BroydenFromZero {
        let dim = guess.len();
        let first = ShootingOptions {
            max_iter: (2 * dim + 2).min(opts.max_iter),
            ..*opts
        };
        match broyden(dmap, guess, n, &first, &DMatrix::zeros(dim, dim)) {
            Ok((z, map, residuals)) => {
                // a period-1 orbit: its section is its state, its minimal period 1
                let (multipliers, stable, critical) = floquet_stability(&map.jacobian);
                return Ok(PeriodicOrbit {
                    period: 1,
                    section: vec![z.clone()],
                    state: z,
                    monodromy: map.jacobian,
                    multipliers,
                    stable,
                    critical,
                    grazing_distance: f64::NAN,
                    grazing: false,
                    switchings: map.switchings,
                    residuals,
                });
            }
            Err(SimError::Cancelled) => return Err(SimError::Cancelled),
            // Newton from the guess
            Err(_) => {}
        }
    }
    shoot_map_unwatched(dmap, guess, n, opts)
}

/// [`newton`] with halved steps, then [`finish`]: [`shoot_map`] and [`shoot_map_unwatched`].
fn shoot_damped(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
    watch: Watch,
) -> Result<PeriodicOrbit, SimError> {
    let (z, map, residuals) = newton(dmap, guess, n, opts, Damping::Halve)?;
    finish(dmap, z, n, map, residuals, opts, watch)
}

/// Whether [`finish`] measures the converged orbit's distance to grazing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Watch {
    /// [`DiscreteMap::grazing_distance`] at the orbit (one more flow).
    Grazing,
    /// No: NaN.
    None,
}

/// [`shoot_map`] globalised: each Newton step is backtracked by a line search on ½‖F‖²
/// with Armijo's sufficient-decrease condition ([`LINE_SEARCH_MIN_STEP`]; Dennis & Schnabel,
/// *Numerical Methods for Unconstrained Optimization and Nonlinear Equations*, SIAM 1996,
/// §6.3 and Algorithm A6.3.1), so that a guess farther from the orbit than Newton's basin of
/// quadratic convergence — a point of a chaotic attractor near one of its unstable periodic
/// orbits — still reaches it where ‖F‖ decreases towards it. Steps that the map accepts whole
/// are [`shoot_map`]'s.
///
/// # Errors
/// [`SimError::NoConvergence`] when the line search stalls or after `opts.max_iter`
/// iterations; [`SimError`] from the map.
pub fn shoot_map_globalised(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    let (z, map, residuals) = newton(dmap, guess, n, opts, Damping::LineSearch)?;
    finish(dmap, z, n, map, residuals, opts, Watch::Grazing)
}

/// A period-n orbit near a recorded stretch of an attractor's stroboscopic section
/// (`section[k]` = z(kT) of consecutive drive periods, e.g. the points a nonperiodic
/// [`crate::analysis::steady::SteadyState`] recorded): the points whose n-period return
/// ‖z_{k+n} − z_k‖ is smallest (close returns: a chaotic orbit shadows the unstable periodic
/// orbits embedded in it, and passes close to a period-n one where it nearly repeats after n
/// periods; Auerbach, Cvitanović, Eckmann, Gunaratne & Procaccia, *Phys. Rev. Lett.* 58 (1987)
/// 2387; Lathrop & Kostelich, *Phys. Rev. A* 40 (1989) 4028), up to [`SECTION_STARTS`] of them
/// in increasing order of that return, each start polished by [`shoot_map_globalised`]; the first
/// orbit reached is returned.
///
/// # Errors
/// [`SimError::OutOfRange`] when `section` has fewer than n + 1 points or n = 0;
/// [`SimError::NoConvergence`] (the smallest residual reached) when no start converges;
/// [`SimError::Cancelled`] and the map's errors other than a failed start.
pub fn shoot_map_from_section(
    dmap: &mut dyn DiscreteMap,
    section: &[DVector<f64>],
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
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
        match shoot_map_globalised(dmap, &section[k], n, opts) {
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

/// Newton for F(z) = Pⁿ(z) − z from a guess close to the orbit (a predictor along a branch),
/// without damping: a full Newton step that does not lower ‖F‖ ends the solve with
/// [`SimError::NoConvergence`] at once — from a close guess it means the orbit is not there
/// (it vanished at a fold between the guess's parameter and this one), and a caller that
/// halves its parameter step gains nothing from the 10 halvings of a damped step (each a
/// flow). Only the multipliers of the converged orbit are formed: no section points and no
/// distance to grazing (the flows of [`shoot_map`]'s `finish`). The iterates and the
/// converged orbit are those of [`shoot_map`] from the same guess whenever it takes full
/// steps.
///
/// # Errors
/// [`SimError::NoConvergence`] as above or after `opts.max_iter` iterations; [`SimError`] from
/// the map.
pub fn shoot_map_undamped(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<ShotOrbit, SimError> {
    let (state, map, residuals) = newton(dmap, guess, n, opts, Damping::Stop)?;
    closes_in_its_region(dmap, &state, n, &residuals)?;
    Ok(ShotOrbit::new(state, map.jacobian, residuals))
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

/// [`shoot_map_undamped`] with `m0`, an estimate of the monodromy matrix (the previous orbit's
/// along a sweep), for the first Jacobian: the iterates take flows without the variational
/// equations ([`DiscreteMap::iterate`]; for the adaptive integrator at N = 3 a seventh of a variational
/// flow's work), the Jacobian M − I of F updated after each step δ by Broyden's rank-one secant
/// update J ← J + (ΔF − J δ) δᵀ/(δᵀδ) (Broyden, *Math. Comp.* 19 (1965) 577; Dennis & Schnabel,
/// *Numerical Methods for Unconstrained Optimization and Nonlinear Equations*, SIAM 1996,
/// §8.1), and the converged orbit takes one variational flow for its monodromy matrix — whose
/// residual must be within [`VARIATIONAL_SLACK`] tolerances (the two kinds of flow take different
/// steps), else Newton steps follow from it as in [`shoot_map_undamped`]. A step that does not lower
/// ‖F‖ ends the solve, as there.
///
/// # Errors
/// As [`shoot_map_undamped`]; [`SimError::OutOfRange`] for an `m0` that is not d×d.
pub fn shoot_map_broyden(
    dmap: &mut dyn DiscreteMap,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
    m0: &DMatrix<f64>,
) -> Result<ShotOrbit, SimError> {
    let (state, map, residuals) = broyden(dmap, guess, n, opts, m0)?;
    Ok(ShotOrbit::new(state, map.jacobian, residuals))
}

/// The iteration of [`shoot_map_broyden`]: the converged z (closed in its region), its map
/// (the variational flow's) and the residuals.
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

/// The Newton iteration of [`shoot_map`] and [`shoot_map_undamped`]: the converged z, its map
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
    // the iterates without the grazing searches (`shoot_map`'s `finish` gives the converged
    // orbit its distance to grazing)
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
/// the orbit shot again at the [`proper_period`] of its section, which must converge there
/// (else n stands). `Ok(None)` when n is minimal (costs n − 1 plain flows of one period).
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
    minimal(dmap, &section, opts, Watch::Grazing)
}

/// [`reduce_map_period`] on the orbit's section points.
fn minimal(
    dmap: &mut dyn DiscreteMap,
    section: &[DVector<f64>],
    opts: &ShootingOptions,
    watch: Watch,
) -> Result<Option<PeriodicOrbit>, SimError> {
    let Some(d) = proper_period(section, opts.tol) else {
        return Ok(None);
    };
    match newton(dmap, &section[0], d, opts, Damping::Stop) {
        Ok((z, map, residuals)) => finish(dmap, z, d, map, residuals, opts, watch).map(Some),
        Err(SimError::Cancelled) => Err(SimError::Cancelled),
        // not an orbit of period d after all: n stands
        Err(_) => Ok(None),
    }
}

/// The converged orbit of a Newton solve: refused where it does not close in its region,
/// reduced to its minimal period, with its section points, multipliers and (with
/// [`Watch::Grazing`]) its distance to grazing.
fn finish(
    dmap: &mut dyn DiscreteMap,
    z: DVector<f64>,
    n: usize,
    map: FlowMap,
    residuals: Vec<f64>,
    opts: &ShootingOptions,
    watch: Watch,
) -> Result<PeriodicOrbit, SimError> {
    closes_in_its_region(dmap, &z, n, &residuals)?;
    let section = map_section_points(dmap, &z, n)?;
    // the minimal period: an orbit found as period n may repeat after a divisor of n
    if let Some(o) = minimal(dmap, &section, opts, watch)? {
        return Ok(o);
    }
    let grazing_distance = match watch {
        Watch::Grazing => dmap.grazing_distance(&z, n)?,
        Watch::None => f64::NAN,
    };
    let (multipliers, stable, critical) = floquet_stability(&map.jacobian);
    Ok(PeriodicOrbit {
        period: n,
        state: z,
        section,
        monodromy: map.jacobian,
        stable,
        critical,
        multipliers,
        grazing: grazing_distance < GRAZING_TOL,
        grazing_distance,
        switchings: map.switchings,
        residuals,
    })
}
