//! Periodic orbits of the stroboscopic map by Newton shooting, with Floquet multipliers.
//!
//! A period-n orbit is a zero of F(z) = Pⁿ(z) − z. Newton's step solves (M − I) δ = −F with M the
//! monodromy matrix of Pⁿ ([`crate::maps::flow`]); it converges quadratically to stable and
//! unstable orbits alike. The Floquet multipliers are the eigenvalues of M.
//!
//! The one solver, [`shoot`], is written against [`DiscreteMap`] (as are
//! [`map_section_points`] and [`reduce_map_period`]: a period-n orbit is n iterates of the map
//! given); on an [`Integrator`] it runs on the integrator's period-1 [`StroboscopicMap`]. Its
//! [`ShootingOptions`] say how it solves ([`ShootingStrategy`]), for which period and whether it
//! watches the orbit's distance to grazing; its [`Guess`] where it starts.
//!
//! [`DiscreteMap`]: crate::maps::DiscreteMap

mod map;

pub use map::{map_section_points, reduce_map_period, shoot};

use super::period::{close, MERGE_FACTOR};
use crate::error::SimError;
use crate::integrate::{Integrator, IntegratorKind, IntegratorOptions};
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use nalgebra::{Complex, DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// What [`shoot`] solves for and how: [`ShootingOptions::default`] is damped Newton for a
/// period-1 orbit, watched for grazing, to 1e-11 within 40 iterations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShootingOptions {
    /// Converged when ‖Pⁿ(z) − z‖ ≤ tol (1 + ‖z‖).
    pub tol: f64,
    /// Iteration cap.
    pub max_iter: usize,
    /// n: the orbit's period in iterates of the map (≥ 1).
    pub period: usize,
    /// How the orbit is solved for.
    pub strategy: ShootingStrategy,
    /// Whether a finished orbit takes its distance to grazing
    /// ([`DiscreteMap::grazing_distance`]: one more flow, with the variational equations); else
    /// [`PeriodicOrbit::grazing_distance`] is NaN and [`PeriodicOrbit::grazing`] `false`, for a
    /// caller that does not report it — the steady tap of [`crate::analysis::peakforce`], where
    /// that flow was a fifth of the N = 3 beam's tap. The iterates, orbit, section points and
    /// multipliers are the same either way.
    ///
    /// [`DiscreteMap::grazing_distance`]: crate::maps::DiscreteMap::grazing_distance
    pub watch_grazing: bool,
}

impl Default for ShootingOptions {
    fn default() -> Self {
        ShootingOptions {
            tol: 1e-11,
            max_iter: 40,
            period: 1,
            strategy: ShootingStrategy::Newton,
            watch_grazing: true,
        }
    }
}

impl ShootingOptions {
    /// These options for a period-`n` orbit.
    #[must_use]
    pub(crate) fn with_period(self, n: usize) -> Self {
        ShootingOptions { period: n, ..self }
    }
}

/// How [`shoot`] solves for an orbit, and what it forms of the orbit it finds. A *finished*
/// orbit is refused where it does not close in its region ([`DiscreteMap::closes`]), reduced to
/// its minimal period (an orbit found as period n may repeat after a divisor of n,
/// `proper_period`), and has its n section points and, watched
/// ([`ShootingOptions::watch_grazing`]), its distance to grazing; an *unfinished* one is refused
/// as well where it does not close, but has only its multipliers formed (no section points but
/// its state, no minimal period, no distance to grazing: the flows a finished orbit takes).
///
/// [`DiscreteMap::closes`]: crate::maps::DiscreteMap::closes
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShootingStrategy {
    /// Newton from the guess, damped by halving a step that does not lower ‖F‖ (down to 1e-3
    /// of the step): a flow with the variational equations (the monodromy matrix) per iterate.
    /// The orbit is finished.
    #[default]
    Newton,
    /// Newton from a guess close to the orbit (a predictor along a branch), without damping: a
    /// full Newton step that does not lower ‖F‖ ends the solve with
    /// [`SimError::NoConvergence`] at once — from a close guess it means the orbit is not there
    /// (it vanished at a fold between the guess's parameter and this one), and a caller that
    /// halves its parameter step gains nothing from the 10 halvings of a damped step (each a
    /// flow). The orbit is unfinished. The iterates and the converged orbit are
    /// [`ShootingStrategy::Newton`]'s from the same guess whenever it takes full steps.
    Undamped,
    /// Newton globalised: each step is backtracked by a line search on ½‖F‖² with Armijo's
    /// sufficient-decrease condition (`LINE_SEARCH_MIN_STEP`; Dennis & Schnabel, *Numerical
    /// Methods for Unconstrained Optimization and Nonlinear Equations*, SIAM 1996, §6.3 and
    /// Algorithm A6.3.1), so that a guess farther from the orbit than Newton's basin of
    /// quadratic convergence — a point of a chaotic attractor near one of its unstable periodic
    /// orbits — still reaches it where ‖F‖ decreases towards it; the solve fails when the line
    /// search stalls. Steps that the map accepts whole are [`ShootingStrategy::Newton`]'s. The
    /// orbit is finished.
    Globalised,
    /// Broyden's updates from an estimate of the monodromy matrix (the guess's,
    /// [`Guess::Estimated`]: the previous orbit's along a sweep; M ≈ 0 for a guess without
    /// one) for the first Jacobian: the iterates take flows without the variational equations
    /// ([`DiscreteMap::iterate`]; for the adaptive integrator at N = 3 a seventh of a
    /// variational flow's work), the Jacobian M − I of F updated after each step δ by
    /// Broyden's rank-one secant update J ← J + (ΔF − J δ) δᵀ/(δᵀδ) (Broyden, *Math. Comp.* 19
    /// (1965) 577; Dennis & Schnabel 1996, §8.1), and the converged orbit takes one variational
    /// flow for its monodromy matrix — whose residual must be within `VARIATIONAL_SLACK`
    /// tolerances (the two kinds of flow take different steps), else undamped Newton steps
    /// follow from it. A step that does not lower ‖F‖ ends the solve, as undamped Newton's; an
    /// estimate that is not d×d is refused ([`SimError::OutOfRange`]). The orbit is unfinished.
    ///
    /// [`DiscreteMap::iterate`]: crate::maps::DiscreteMap::iterate
    Broyden,
    /// For a period-1 orbit, Broyden's updates from the estimate M ≈ 0 first
    /// ([`ShootingStrategy::Broyden`]), within 2d + 2 iterates (d the state's dimension; at
    /// most [`ShootingOptions::max_iter`]): Broyden's method reaches the zero of an affine F in
    /// at most 2d steps (Gay, *SIAM J. Numer. Anal.* 16 (1979) 623), and the residual of the
    /// last is checked in one more. Where those updates fail (no convergence within the cap, a
    /// step that does not lower the residual, a singular M − I or a fixed point that does not
    /// close in its region), [`ShootingStrategy::Newton`] from the guess; so for a period
    /// n > 1, whose minimal period only Newton's solve checks. The orbit of the Broyden solve
    /// is unfinished (period 1, its state its one section point), Newton's finished.
    ///
    /// It pays for a strongly contracting map whose monodromy matrix costs variational
    /// equations step by step (`broyden_pays`): there the multipliers are small (2–3e-2 on
    /// the steady PeakForce tap of a ScanAsyst-Air-like probe at f₀/f_m = 100, whose ringing
    /// after each tap decays over the cycle's lever periods), so M − I ≈ −I makes the first
    /// step the map's own iterate — the transient continued — after which the secant updates
    /// learn M − I from flows without the variational equations (at N = 3, 6 components a step
    /// instead of 42), and one variational flow at the converged orbit gives its monodromy
    /// matrix. The orbit agrees with Newton's to the tolerance ([`ShootingOptions::tol`]; the
    /// two solves' flows differ in their steps only). Not for a hysteretic law (JKR,
    /// capillary: [`crate::tip_sample::TipSampleSystem::is_hysteretic`]), whose orbits at
    /// Newton's tolerance are sensitive to the flows' steps: there
    /// [`crate::analysis::peakforce`] asks for Newton.
    BroydenFromZero,
}

/// Where [`shoot`] starts (a `&DVector` converts into [`Guess::State`]).
#[derive(Debug, Clone, Copy)]
pub enum Guess<'a> {
    /// A state near the orbit (at τ = 0), `[2N]`.
    State(&'a DVector<f64>),
    /// A state near the orbit and an estimate of its monodromy matrix (d×d, e.g. the previous
    /// orbit's along a sweep): [`ShootingStrategy::Broyden`]'s first Jacobian (the other
    /// strategies start from the state alone).
    Estimated {
        /// The state, `[2N]`.
        state: &'a DVector<f64>,
        /// The estimate of the monodromy matrix.
        monodromy: &'a DMatrix<f64>,
    },
    /// A recorded stretch of an attractor's stroboscopic section (`section[k]` = z(kT) of
    /// consecutive drive periods, e.g. the points a nonperiodic
    /// [`crate::analysis::steady::SteadyState`] recorded): the points whose n-period return
    /// ‖z_{k+n} − z_k‖ is smallest (close returns: a chaotic orbit shadows the unstable
    /// periodic orbits embedded in it, and passes close to a period-n one where it nearly
    /// repeats after n periods; Auerbach, Cvitanović, Eckmann, Gunaratne & Procaccia, *Phys.
    /// Rev. Lett.* 58 (1987) 2387; Lathrop & Kostelich, *Phys. Rev. A* 40 (1989) 4028) are the
    /// starts, up to `SECTION_STARTS` of them in increasing order of that return, each solved
    /// by the strategy (for a chaotic attractor [`ShootingStrategy::Globalised`]); the first
    /// orbit reached is the solve's. [`SimError::OutOfRange`] when the section has fewer than
    /// n + 1 points; [`SimError::NoConvergence`] (the smallest residual reached) when no start
    /// converges.
    Section(&'a [DVector<f64>]),
}

impl<'a> From<&'a DVector<f64>> for Guess<'a> {
    fn from(state: &'a DVector<f64>) -> Self {
        Guess::State(state)
    }
}

/// Distance to grazing below which an orbit is flagged as grazing: a local extremum of V_T
/// within 1e-3 gap units of the sample, or a switching with |dV_T/dτ|/Ω below 1e-3.
pub(crate) const GRAZING_TOL: f64 = 1e-3;

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
    /// States at the n section points τ = kT, k = 0..n; `[state]` alone for an unfinished
    /// orbit ([`ShootingStrategy`]).
    pub section: Vec<DVector<f64>>,
    /// Monodromy matrix of Pⁿ at the orbit.
    pub monodromy: DMatrix<f64>,
    /// Floquet multipliers, sorted by decreasing modulus.
    pub multipliers: Vec<Complex<f64>>,
    /// All multipliers inside the unit circle.
    pub stable: bool,
    /// Type of the critical multiplier.
    pub critical: Instability,
    /// Distance to grazing (see [`crate::maps::flow::FlowMap::grazing_distance`]); NaN where
    /// it is not measured (unwatched, [`ShootingOptions::watch_grazing`], or unfinished).
    pub grazing_distance: f64,
    /// The orbit is (near) grazing: `grazing_distance` < `GRAZING_TOL`.
    pub grazing: bool,
    /// Switchings per cycle.
    pub switchings: usize,
    /// ‖F‖ after each Newton iteration.
    pub residuals: Vec<f64>,
}

/// Eigenvalues of a monodromy matrix, sorted by decreasing modulus.
pub(crate) fn floquet_multipliers(m: &DMatrix<f64>) -> Vec<Complex<f64>> {
    let mut mu: Vec<Complex<f64>> = m.complex_eigenvalues().iter().copied().collect();
    mu.sort_by(|a, b| b.norm().total_cmp(&a.norm()));
    mu
}

/// How many section points of an attractor [`shoot`] tries as starts at most ([`Guess::Section`]).
pub(crate) const SECTION_STARTS: usize = 16;

/// Whether Newton solves with the integrator of `opts` for `model` gain from starting with
/// Broyden's updates and flows without the variational equations ([`ShootingStrategy::Broyden`]):
/// where the integrator takes the monodromy matrix from variational equations integrated step by
/// step (the adaptive integrator, also in the split integrator's contact stints: at N = 3 a
/// variational step integrates 42 components instead of 6; a variational flow of the beam DMT
/// approach costs 7.6 plain ones, of the point-mass one 4.1; and the Taylor integrator, whose
/// variational series cost as much per component: its beam DMT approach 0.49 s with Broyden against
/// 0.56 s without, farm-bench medians of 7 pairs, the point mass's 0.137 against 0.139 s), so that
/// iterates by flows without them and one variational flow at the converged orbit cost less than a
/// variational flow per iterate. Not with the exact propagator, whose monodromy matrix is a product
/// of stint transitions at about the cost of the flow itself: there Broyden's extra iterations
/// would cost more than they save.
pub(crate) fn broyden_pays(opts: IntegratorOptions, model: &CantileverModel) -> bool {
    opts.kind.resolve(model) != IntegratorKind::Exact
}

/// How many Newton tolerances the map of the variational flow from an orbit that
/// [`ShootingStrategy::Broyden`] converged on flows without them may miss it by: the two flows'
/// steps differ, so their maps differ by the integration error (measured 1e-10 to 4e-10 at the
/// adaptive integrator's tolerance 1e-10, point-mass DMT; nothing for the exact propagator).
pub(crate) const VARIATIONAL_SLACK: f64 = 10.0;

/// The smallest step fraction λ the line search of [`ShootingStrategy::Globalised`] tries: below it
/// the Newton direction no longer lowers ‖F‖ (a local minimum of ‖F‖ that is not a zero, or a kink
/// of the map at a switching) and the solve fails.
pub(crate) const LINE_SEARCH_MIN_STEP: f64 = 1e-8;

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
pub(crate) fn proper_period(section: &[DVector<f64>], tol: f64) -> Option<usize> {
    let n = section.len();
    (1..n)
        .filter(|&d| n.is_multiple_of(d))
        .find(|&d| close(&section[d], &section[0], MERGE_FACTOR * tol))
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
