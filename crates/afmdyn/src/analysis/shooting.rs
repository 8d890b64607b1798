//! Periodic orbits of the stroboscopic map by Newton shooting, with Floquet multipliers.
//!
//! A period-n orbit is a zero of F(z) = Pⁿ(z) − z. Newton's step solves (M − I) δ = −F with M the
//! monodromy matrix of Pⁿ ([`crate::maps::flow`]); it converges quadratically to stable and
//! unstable orbits alike. The Floquet multipliers are the eigenvalues of M.
//!
//! The solvers are written against [`DiscreteMap`] (`shoot_map*`, [`map_section_points`],
//! [`reduce_map_period`]: a period-n orbit is n iterates of the map given); the functions on
//! an [`Integrator`] ([`shoot_with`], [`shoot_undamped`], …) run them on its period-1
//! [`StroboscopicMap`].
//!
//! [`DiscreteMap`]: crate::maps::DiscreteMap

mod map;

pub use map::{
    map_section_points, reduce_map_period, shoot_map, shoot_map_broyden, shoot_map_from_section,
    shoot_map_globalised, shoot_map_undamped, shoot_map_unwatched, shoot_map_unwatched_by,
};

use super::period::{close, MERGE_FACTOR};
use crate::error::SimError;
use crate::integrate::{build, Integrator, IntegratorKind, IntegratorOptions};
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

/// How [`shoot_map_unwatched_by`] (and [`shoot_unwatched`] on an integrator) solves for an
/// orbit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShootingStrategy {
    /// Damped Newton from the guess ([`shoot_map_unwatched`]): a flow with the variational
    /// equations (the monodromy matrix) per iterate.
    #[default]
    Newton,
    /// For a period-1 orbit, Broyden's updates from the estimate M ≈ 0 first
    /// ([`shoot_map_broyden`]; Broyden, *Math. Comp.* 19 (1965) 577), Newton from the guess
    /// where they fail. It pays for a strongly contracting map whose monodromy matrix costs
    /// variational equations step by step ([`broyden_pays`]): there the multipliers are small
    /// (2–3e-2 on the steady PeakForce tap of a ScanAsyst-Air-like probe at f₀/f_m = 100, whose
    /// ringing after each tap decays over the cycle's lever periods), so M − I ≈ −I makes the
    /// first step the map's own iterate — the transient continued — after which the secant
    /// updates learn M − I from flows without the variational equations (at N = 3, 6
    /// components a step instead of 42), and one variational flow at the converged orbit
    /// gives its monodromy matrix. The orbit agrees with Newton's to the tolerance
    /// ([`ShootingOptions::tol`]; the two solves' flows differ in their steps only). Capped at
    /// 2d + 2 iterates (d the state's dimension: Gay's bound for an affine map,
    /// [`shoot_map_unwatched_by`]); not for a period n > 1 (Newton's solve checks the minimal
    /// period) nor, on an integrator ([`shoot_unwatched`]), for a hysteretic law (JKR,
    /// capillary: whose orbits at Newton's tolerance are sensitive to the flows' steps).
    BroydenFromZero,
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
pub(crate) fn critical_multiplier(mu: &[Complex<f64>]) -> (Complex<f64>, Instability) {
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
    /// Distance to grazing (see [`crate::maps::flow::FlowMap::grazing_distance`]); NaN from
    /// [`shoot_map_unwatched`], which does not measure it.
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

/// How many section points of an attractor [`shoot_from_section`] tries as starts at most.
pub const SECTION_STARTS: usize = 16;

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

/// The smallest step fraction λ the line search of [`shoot_globalised`] tries: below it the Newton direction no longer
/// lowers ‖F‖ (a local minimum of ‖F‖ that is not a zero, or a kink of the map at a switching)
/// and the solve fails.
pub const LINE_SEARCH_MIN_STEP: f64 = 1e-8;

/// Floquet multipliers of a monodromy matrix (decreasing modulus), whether all lie inside the
/// unit circle, and the type of the critical one.
pub(crate) fn floquet_stability(m: &DMatrix<f64>) -> (Vec<Complex<f64>>, bool, Instability) {
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

/// [`shoot_map`] on the period-1 stroboscopic map of `integ`: Newton for F(z) = Pⁿ(z) − z from
/// `guess`, reusing `integ`.
///
/// # Errors
/// [`SimError::NoConvergence`] when Newton fails; [`SimError`] from the propagator.
pub fn shoot_with(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    shoot_map(&mut StroboscopicMap::new(integ, 1), guess, n, opts)
}

/// [`shoot_map_globalised`] (Newton with a line search) on the period-1 stroboscopic map of
/// `integ`.
///
/// # Errors
/// As [`shoot_map_globalised`].
pub fn shoot_globalised(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    shoot_map_globalised(&mut StroboscopicMap::new(integ, 1), guess, n, opts)
}

/// [`shoot_map_from_section`] (a period-n orbit near the close returns of an attractor's
/// section points) on the period-1 stroboscopic map of `integ`.
///
/// # Errors
/// As [`shoot_map_from_section`].
pub fn shoot_from_section(
    integ: &mut dyn Integrator,
    section: &[DVector<f64>],
    n: usize,
    opts: &ShootingOptions,
) -> Result<PeriodicOrbit, SimError> {
    shoot_map_from_section(&mut StroboscopicMap::new(integ, 1), section, n, opts)
}

/// [`shoot_map_undamped`] (Newton from a close guess, without damping) on the period-1
/// stroboscopic map of `integ`.
///
/// # Errors
/// As [`shoot_map_undamped`].
pub fn shoot_undamped(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<ShotOrbit, SimError> {
    shoot_map_undamped(&mut StroboscopicMap::new(integ, 1), guess, n, opts)
}

/// [`shoot_map_broyden`] (Broyden's updates from the monodromy estimate `m0`, 2N×2N) on the
/// period-1 stroboscopic map of `integ`.
///
/// # Errors
/// As [`shoot_map_broyden`].
pub fn shoot_broyden(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
    m0: &DMatrix<f64>,
) -> Result<ShotOrbit, SimError> {
    shoot_map_broyden(&mut StroboscopicMap::new(integ, 1), guess, n, opts, m0)
}

/// [`shoot_map_unwatched_by`] on the period-1 stroboscopic map of `integ`: the orbit without
/// its distance to grazing, solved by `strategy`, which falls back on
/// [`ShootingStrategy::Newton`] for a hysteretic system
/// ([`crate::tip_sample::TipSampleSystem::is_hysteretic`]).
///
/// # Errors
/// As [`shoot_map_unwatched_by`].
pub fn shoot_unwatched(
    integ: &mut dyn Integrator,
    guess: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
    strategy: ShootingStrategy,
) -> Result<PeriodicOrbit, SimError> {
    let strategy = if integ.system().is_hysteretic() {
        ShootingStrategy::Newton
    } else {
        strategy
    };
    shoot_map_unwatched_by(
        &mut StroboscopicMap::new(integ, 1),
        guess,
        n,
        opts,
        strategy,
    )
}

/// The n section states z, P(z), …, Pⁿ⁻¹(z) of a period-n orbit of the stroboscopic map of
/// `integ` ([`map_section_points`]).
///
/// # Errors
/// [`SimError`] from the propagator.
pub(crate) fn section_points(
    integ: &mut dyn Integrator,
    z: &DVector<f64>,
    n: usize,
) -> Result<Vec<DVector<f64>>, SimError> {
    map_section_points(&mut StroboscopicMap::new(integ, 1), z, n)
}

/// [`reduce_map_period`] (the orbit through `z` at its minimal period, `None` when n is
/// minimal) on the period-1 stroboscopic map of `integ`.
///
/// # Errors
/// [`SimError`] from the propagator.
pub(crate) fn reduce_period(
    integ: &mut dyn Integrator,
    z: &DVector<f64>,
    n: usize,
    opts: &ShootingOptions,
) -> Result<Option<PeriodicOrbit>, SimError> {
    reduce_map_period(&mut StroboscopicMap::new(integ, 1), z, n, opts)
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
