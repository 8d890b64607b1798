//! Periodic orbits of the stroboscopic map by Newton shooting, with Floquet multipliers.
//!
//! A period-n orbit is a zero of F(z) = Pⁿ(z) − z. Newton's step solves (M − I) δ = −F with M the
//! monodromy matrix of Pⁿ ([`crate::maps::flow`]); it converges quadratically to stable and
//! unstable orbits alike. The Floquet multipliers are the eigenvalues of M.

use super::period::{close, MERGE_FACTOR};
use crate::error::SimError;
use crate::integrate::{build, Integrator, IntegratorKind, IntegratorOptions};
use crate::maps::flow::FlowMap;
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use nalgebra::{Complex, DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Newton options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShootingOptions {
    /// Converged when ‖Pⁿ(z) − z‖ ≤ tol (1 + ‖z‖).
    pub tol: f64,
    /// Iteration cap.
    pub max_iter: usize,
}

impl Default for ShootingOptions {
    fn default() -> Self {
        ShootingOptions {
            tol: 1e-11,
            max_iter: 40,
        }
    }
}

/// Distance to grazing below which an orbit is flagged as grazing: a local extremum of V_T
/// within 1e-3 gap units of the sample, or a switching with |dV_T/dτ|/Ω below 1e-3.
pub const GRAZING_TOL: f64 = 1e-3;

/// How an orbit is (or would become) unstable, from the multiplier of largest modulus.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Instability {
    /// A real multiplier through +1 (fold / saddle-node).
    Fold,
    /// A real multiplier through −1 (period doubling / flip).
    PeriodDoubling,
    /// A complex pair through the unit circle (Neimark–Sacker).
    NeimarkSacker,
}

impl Instability {
    /// Its name in every output (JSON, CSV, Python): `fold`, `period-doubling`,
    /// `neimark-sacker`.
    pub fn name(self) -> &'static str {
        match self {
            Instability::Fold => "fold",
            Instability::PeriodDoubling => "period-doubling",
            Instability::NeimarkSacker => "neimark-sacker",
        }
    }
}

/// The critical multiplier: the one of largest modulus, and its type.
pub fn critical_multiplier(mu: &[Complex<f64>]) -> (Complex<f64>, Instability) {
    let m = *mu
        .iter()
        .max_by(|a, b| a.norm().total_cmp(&b.norm()))
        .expect("multipliers");
    let kind = if m.im.abs() > 1e-9 * m.norm().max(1.0) {
        Instability::NeimarkSacker
    } else if m.re > 0.0 {
        Instability::Fold
    } else {
        Instability::PeriodDoubling
    };
    (m, kind)
}

/// A period-n orbit of the stroboscopic map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PeriodicOrbit {
    /// n.
    pub period: usize,
    /// State at τ = 0 (drive phase 0), shape `[2N]`.
    pub state: DVector<f64>,
    /// States at the n section points τ = kT, k = 0..n.
    pub section: Vec<DVector<f64>>,
    /// Monodromy matrix of Pⁿ at the orbit.
    pub monodromy: DMatrix<f64>,
    /// Floquet multipliers, sorted by decreasing modulus.
    pub multipliers: Vec<Complex<f64>>,
    /// All multipliers inside the unit circle.
    pub stable: bool,
    /// Type of the critical multiplier.
    pub critical: Instability,
    /// Distance to grazing (see [`FlowMap::grazing_distance`]).
    pub grazing_distance: f64,
    /// The orbit is (near) grazing: `grazing_distance` < [`GRAZING_TOL`].
    pub grazing: bool,
    /// Switchings per cycle.
    pub switchings: usize,
    /// ‖F‖ after each Newton iteration.
    pub residuals: Vec<f64>,
}

/// Eigenvalues of a monodromy matrix, sorted by decreasing modulus.
pub fn floquet_multipliers(m: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let mut mu: Vec<Complex<f64>> = m.complex_eigenvalues().iter().copied().collect();
    mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    mu
}

/// Newton iteration for F(z) = Pⁿ(z) − z from `guess`, reusing `prop`.
///
/// # Errors
/// [`SimError::NoConvergence`] when Newton fails; [`SimError`] from the propagator.
pub fn shoot_with(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    let (z, map, residuals) = newton(integ, guess, n, opts, Damping::Halve)?;
    finish(integ, z, n, map, residuals, opts)
}

/// [`shoot_with`] globalised: each Newton step is backtracked by a line search on ½‖F‖²
/// with Armijo's sufficient-decrease condition ([`LINE_SEARCH_MIN_STEP`]; Dennis & Schnabel,
/// *Numerical Methods for Unconstrained Optimization and Nonlinear Equations*, SIAM 1996,
/// §6.3 and Algorithm A6.3.1), so that a guess farther from the orbit than Newton's basin of
/// quadratic convergence — a point of a chaotic attractor near one of its unstable periodic
/// orbits — still reaches it where ‖F‖ decreases towards it. Steps that the map accepts whole
/// are [`shoot_with`]'s.
///
/// # Errors
/// [`SimError::NoConvergence`] when the line search stalls or after `opts.max_iter`
/// iterations; [`SimError`] from the propagator.
pub fn shoot_globalised(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    let (z, map, residuals) = newton(integ, guess, n, opts, Damping::LineSearch)?;
    finish(integ, z, n, map, residuals, opts)
}

/// How many section points of an attractor [`shoot_from_section`] tries as starts at most.
pub const SECTION_STARTS: usize = 16;

/// A period-n orbit near a recorded stretch of an attractor's stroboscopic section
/// (`section[k]` = z(kT) of consecutive drive periods, e.g. the points a nonperiodic
/// [`super::steady::SteadyState`] recorded): the points whose n-period return
/// ‖z_{k+n} − z_k‖ is smallest (close returns: a chaotic orbit shadows the unstable periodic
/// orbits embedded in it, and passes close to a period-n one where it nearly repeats after n
/// periods; Auerbach, Cvitanović, Eckmann, Gunaratne & Procaccia, *Phys. Rev. Lett.* 58 (1987)
/// 2387; Lathrop & Kostelich, *Phys. Rev. A* 40 (1989) 4028), up to [`SECTION_STARTS`] of them
/// in increasing order of that return, each start polished by [`shoot_globalised`]; the first
/// orbit reached is returned.
///
/// # Errors
/// [`SimError::OutOfRange`] when `section` has fewer than n + 1 points or n = 0;
/// [`SimError::NoConvergence`] (the smallest residual reached) when no start converges;
/// [`SimError::Cancelled`] and the propagator's errors other than a failed start.
pub fn shoot_from_section(
    integ: &mut dyn Integrator,
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
        match shoot_globalised(integ, &section[k], n, opts) {
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

/// A period-n orbit from [`shoot_undamped`]: what a stepped sweep keeps of it.
#[derive(Debug, Clone, PartialEq)]
pub struct ShotOrbit {
    /// State at τ = 0 (drive phase 0), shape `[2N]`.
    pub state: DVector<f64>,
    /// Monodromy matrix of Pⁿ at the orbit.
    pub monodromy: DMatrix<f64>,
    /// Floquet multipliers, sorted by decreasing modulus.
    pub multipliers: Vec<Complex<f64>>,
    /// All multipliers inside the unit circle.
    pub stable: bool,
    /// ‖F‖ after each Newton iteration.
    pub residuals: Vec<f64>,
}

impl ShotOrbit {
    fn new(state: DVector<f64>, monodromy: DMatrix<f64>, residuals: Vec<f64>) -> Self {
        let (multipliers, stable, _) = floquet_stability(&monodromy);
        ShotOrbit {
            state,
            monodromy,
            multipliers,
            stable,
            residuals,
        }
    }
}

/// Newton for F(z) = Pⁿ(z) − z from a guess close to the orbit (a predictor along a branch),
/// without damping: a full Newton step that does not lower ‖F‖ ends the solve with
/// [`SimError::NoConvergence`] at once — from a close guess it means the orbit is not there
/// (it vanished at a fold between the guess's parameter and this one), and a caller that
/// halves its parameter step gains nothing from the 10 halvings of a damped step (each a
/// flow). Only the multipliers of the converged orbit are formed: no section points and no
/// distance to grazing (the flows of [`shoot_with`]'s `finish`). The iterates and the
/// converged orbit are those of [`shoot_with`] from the same guess whenever it takes full
/// steps.
///
/// # Errors
/// [`SimError::NoConvergence`] as above or after `opts.max_iter` iterations; [`SimError`] from
/// the propagator.
pub fn shoot_undamped(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<ShotOrbit, SimError> {
    let (state, map, residuals) = newton(integ, guess, n, opts, Damping::Stop)?;
    closes_in_its_region(integ, &state, n, &residuals)?;
    Ok(ShotOrbit::new(state, map.jacobian, residuals))
}

/// For a hysteretic system ([`crate::tip_sample::TipSampleSystem::is_hysteretic`]): the
/// fixed point z = Pⁿ(z) is an orbit only if the flow ends in the region a start at z is given
/// ([`crate::system::HybridSystem::mode_at`]'s rule in the neck's band). Where it does not, the
/// map restarts in the other region than the motion is in: the point is no orbit of the hybrid
/// system, and it is refused rather than reported (one extra flow, for such systems only).
///
/// # Errors
/// [`SimError::NoConvergence`] naming the mismatch; the integrator's errors.
fn closes_in_its_region(
    integ: &mut dyn Integrator,
    z: &DVector<f64>,
    n: usize,
    residuals: &[f64],
) -> Result<(), SimError> {
    if !integ.system().is_hysteretic() {
        return Ok(());
    }
    let start = integ.system().mode_at(0.0, z.as_slice());
    StroboscopicMap::new(&mut *integ, n).image(z)?;
    if integ.region() == start {
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

/// [`shoot_undamped`] with `m0`, an estimate of the monodromy matrix (the previous orbit's
/// along a sweep), for the first Jacobian: the iterates take flows without the variational
/// equations ([`StroboscopicMap::image`]; for the adaptive integrator at N = 3 a seventh of a variational
/// flow's work), the Jacobian M − I of F updated after each step δ by Broyden's rank-one secant
/// update J ← J + (ΔF − J δ) δᵀ/(δᵀδ) (Broyden, *Math. Comp.* 19 (1965) 577; Dennis & Schnabel,
/// *Numerical Methods for Unconstrained Optimization and Nonlinear Equations*, SIAM 1996,
/// §8.1), and the converged orbit takes one variational flow for its monodromy matrix — whose
/// residual must be within [`VARIATIONAL_SLACK`] tolerances (the two kinds of flow take different
/// steps), else Newton steps follow from it as in [`shoot_undamped`]. A step that does not lower
/// ‖F‖ ends the solve, as there.
///
/// # Errors
/// As [`shoot_undamped`]; [`SimError::OutOfRange`] for an `m0` that is not 2N×2N.
pub fn shoot_broyden(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
    m0: &DMatrix<f64>,
) -> Result<ShotOrbit, SimError> {
    if n == 0 {
        return Err(SimError::out_of_range("period", n, "must be >= 1"));
    }
    integ.system().check_state("initial guess", guess)?;
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
    let mut f = StroboscopicMap::new(&mut *integ, n).image(&z)? - &z;
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
        let f_new = StroboscopicMap::new(&mut *integ, n).image(&trial)? - &trial;
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
    let map = StroboscopicMap::new(&mut *integ, n)
        .watch_grazing(false)
        .apply(&z)?;
    let res_var = (&map.state - &z).norm();
    if res_var <= VARIATIONAL_SLACK * opts.tol * (1.0 + z.norm()) {
        residuals.push(res_var);
        closes_in_its_region(integ, &z, n, &residuals)?;
        return Ok(ShotOrbit::new(z, map.jacobian, residuals));
    }
    let (state, map, more) = newton(integ, &z, n, opts, Damping::Stop)?;
    residuals.extend(more);
    closes_in_its_region(integ, &state, n, &residuals)?;
    Ok(ShotOrbit::new(state, map.jacobian, residuals))
}

/// Whether Newton solves with the integrator of `opts` for `model` gain from starting with
/// Broyden's updates and flows without the variational equations ([`shoot_broyden`]): where the
/// integrator takes the monodromy matrix from variational equations integrated step by step
/// (the adaptive integrator, also in the split integrator's contact stints: at N = 3 a
/// variational step integrates 42 components instead of 6; a variational flow of the beam DMT
/// approach costs 7.6 plain ones, of the point-mass one 4.1; and the Taylor integrator, whose
/// variational series cost as much per component: its beam DMT approach 0.49 s with Broyden
/// against 0.56 s without, farm-bench medians of 7 pairs, the point mass's 0.137 against
/// 0.139 s), so that iterates by flows without them and one variational flow at the converged
/// orbit cost less than a variational flow per iterate. Not with the exact propagator, whose monodromy matrix is a product of stint
/// transitions at about the cost of the flow itself: there Broyden's extra iterations would
/// cost more than they save.
pub fn broyden_pays(opts: IntegratorOptions, model: &CantileverModel) -> bool {
    opts.kind.resolve(model) != IntegratorKind::Exact
}

/// How many Newton tolerances the map of the variational flow from an orbit that
/// [`shoot_broyden`] converged on flows without them may miss it by: the two flows' steps
/// differ, so their maps differ by the integration error (measured 1e-10 to 4e-10 at the
/// adaptive integrator's tolerance 1e-10, point-mass DMT; nothing for the exact propagator).
pub const VARIATIONAL_SLACK: f64 = 10.0;

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

/// The smallest step fraction λ the line search of [`shoot_globalised`] tries: below it the Newton direction no longer
/// lowers ‖F‖ (a local minimum of ‖F‖ that is not a zero, or a kink of the map at a switching)
/// and the solve fails.
pub const LINE_SEARCH_MIN_STEP: f64 = 1e-8;

/// A backtracking line search for Newton's step `delta` from `z` (residual `res` = ‖F(z)‖) on
/// the merit function f = ½‖F‖²: the first λ = 1, ρ₁λ, … with f(z + λδ) ≤ f(z) + c λ ∇fᵀδ,
/// where ∇fᵀδ = Fᵀ(M − I)δ = −‖F‖² for the Newton direction (a descent direction of f), each
/// backtrack the minimiser of the quadratic through f(z), its slope and f(z + λδ), safeguarded
/// to [0.1 λ, 0.5 λ] (Dennis & Schnabel 1996, Algorithm A6.3.1; Nocedal & Wright, *Numerical
/// Optimization*, 2nd ed., Springer 2006, §3.5 and §11.2). A trial the map cannot start from
/// (e.g. inside a rigid sample) is a failed trial. `Ok(None)` when λ falls below
/// [`LINE_SEARCH_MIN_STEP`].
fn line_search(
    integ: &mut dyn Integrator,
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
        let f_trial = match StroboscopicMap::new(&mut *integ, n)
            .watch_grazing(false)
            .apply(&trial)
        {
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

/// The Newton iteration of [`shoot_with`] and [`shoot_undamped`]: the converged z, its map
/// (unwatched: no grazing searches) and the residuals.
fn newton(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
    damping: Damping,
) -> Result<(DVector<f64>, FlowMap, Vec<f64>), SimError> {
    if n == 0 {
        return Err(SimError::out_of_range("period", n, "must be >= 1"));
    }
    integ.system().check_state("initial guess", guess)?;
    let dim = guess.len();
    let mut z = guess.clone();
    let mut residuals = Vec::new();
    // the iterates without the grazing searches (`shoot_with`'s `finish` gives the converged
    // orbit its distance to grazing)
    let mut map = StroboscopicMap::new(&mut *integ, n)
        .watch_grazing(false)
        .apply(&z)?;
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
            match line_search(integ, &z, &delta, res, n)? {
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
            match StroboscopicMap::new(&mut *integ, n)
                .watch_grazing(false)
                .apply(&trial)
            {
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

/// The n section states z, P(z), …, Pⁿ⁻¹(z) of a period-n orbit.
///
/// # Errors
/// [`SimError`] from the propagator.
pub fn section_points(
    integ: &mut dyn Integrator,
    z: &DVector<f64>,
    n: usize,
) -> Result<Vec<DVector<f64>>, SimError> {
    let mut section = vec![z.clone()];
    for _ in 1..n {
        let next = StroboscopicMap::new(&mut *integ, 1)
            .apply(section.last().expect("non-empty"))?
            .state;
        section.push(next);
    }
    Ok(section)
}

/// Floquet multipliers of a monodromy matrix (decreasing modulus), whether all lie inside the
/// unit circle, and the type of the critical one.
pub fn floquet_stability(m: &DMatrix<f64>) -> (Vec<Complex<f64>>, bool, Instability) {
    let multipliers = floquet_multipliers(m);
    let (crit, critical) = critical_multiplier(&multipliers);
    (multipliers, crit.norm() < 1.0, critical)
}

/// The smallest proper divisor d of n = `section.len()` whose return P^d(z) comes back to the
/// orbit's start z = `section[0]` within [`MERGE_FACTOR`] × `tol` (1 + ‖z‖): the candidate
/// minimal period of a period-n orbit. A period-1 orbit is a fixed point of Pⁿ too, and a
/// Newton solve for Pⁿ(z) = z from a guess (a period carried along a sweep, a transient's
/// guess) converges to it as readily as to a true period-n orbit; the orbit's own returns tell
/// them apart. `None` when no proper divisor returns (n is the minimal period).
pub fn proper_period(section: &[DVector<f64>], tol: f64) -> Option<usize> {
    let n = section.len();
    (1..n)
        .filter(|&d| n.is_multiple_of(d))
        .find(|&d| close(&section[d], &section[0], MERGE_FACTOR * tol))
}

/// The period-n orbit through `z` (converged to `opts.tol`) reduced to its minimal period:
/// the orbit shot again at the [`proper_period`] of its section, which must converge there
/// (else n stands). `Ok(None)` when n is minimal (costs n − 1 plain flows of one period).
///
/// # Errors
/// [`SimError`] from the propagator.
pub fn reduce_period(
    integ: &mut dyn Integrator,
    z: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<Option<PeriodicOrbit>, SimError> {
    if n < 2 {
        return Ok(None);
    }
    let section = section_points(integ, z, n)?;
    minimal(integ, &section, opts)
}

/// [`reduce_period`] on the orbit's section points.
fn minimal(
    integ: &mut dyn Integrator,
    section: &[DVector<f64>],
    opts: &ShootingOptions,
) -> Result<Option<PeriodicOrbit>, SimError> {
    let Some(d) = proper_period(section, opts.tol) else {
        return Ok(None);
    };
    match newton(integ, &section[0], d, opts, Damping::Stop) {
        Ok((z, map, residuals)) => finish(integ, z, d, map, residuals, opts).map(Some),
        Err(SimError::Cancelled) => Err(SimError::Cancelled),
        // not an orbit of period d after all: n stands
        Err(_) => Ok(None),
    }
}

fn finish(
    integ: &mut dyn Integrator,
    z: DVector<f64>,
    n: usize,
    map: FlowMap,
    residuals: Vec<f64>,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    closes_in_its_region(integ, &z, n, &residuals)?;
    let section = section_points(integ, &z, n)?;
    // the minimal period: an orbit found as period n may repeat after a divisor of n
    if let Some(o) = minimal(integ, &section, opts)? {
        return Ok(o);
    }
    let grazing_distance = StroboscopicMap::new(&mut *integ, n).grazing_distance(&z)?;
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

/// Find a period-n orbit of `model` near `guess`, on an integrator built for this solve
/// alone (its own propagator cache): for repeated solves build the integrator once, or share
/// one [`IntegratorOptions`] (and so its cache), and call [`shoot_with`].
///
/// # Errors
/// As [`shoot_with`].
pub fn shoot(
    model: &CantileverModel,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    let mut integ = build(model, IntegratorOptions::default(), 0.0, &model.rest())?;
    shoot_with(integ.as_mut(), guess, n, opts)
}
