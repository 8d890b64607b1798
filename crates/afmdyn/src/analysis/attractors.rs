//! Coexisting attractors at fixed parameters: sample initial states, classify each steady
//! state, cluster the distinct attractors and estimate their basin fractions. Every periodic
//! attractor is then polished by Newton shooting ([`super::shooting`]), so its Poincaré points
//! are the orbit's to the shooting tolerance (not the last transient iterate, which is off by
//! ~ tol/(1 − |μ₁|) for slowly contracting orbits) and its Floquet multipliers are reported.

use super::bifurcation::random_state;
use super::lyapunov::largest_exponent;
use super::period::close;
#[cfg(not(feature = "parallel"))]
use super::sequential::*;
use super::shooting::{shoot, PeriodicOrbit, ShootingOptions};
use super::steady::{steady_state_of, PoincarePoint, SteadyOptions, SteadyState};
use crate::analysis::progress::Progress;
use crate::error::{in_range, SimError};
use crate::integrate::{IntegratorKind, IntegratorOptions};
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use crate::params::Params;
use nalgebra::DVector;
#[cfg(feature = "parallel")]
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// An attractor search.
#[derive(Debug, Clone, PartialEq)]
pub struct AttractorSpec {
    /// Parameters.
    pub params: Params,
    /// Number of random initial states.
    pub samples: usize,
    /// Seed of the initial states.
    pub seed: u64,
    /// Relative tolerance for two section point sets to be the same attractor.
    pub cluster_tol: f64,
    /// Steady-state options.
    pub steady: SteadyOptions,
    /// Integrator.
    pub integrator: IntegratorOptions,
}

/// Largest number of random initial states of a census (each is a steady-state search kept in
/// memory with its Poincaré points).
pub const MAX_ATTRACTOR_SAMPLES: usize = 100_000;
/// Samples per drive period at which attractors are recorded (their plots and files); the
/// integrator of the census is built for this rate, so the same request gives the same
/// attractors in every front end.
pub(crate) const ATTRACTOR_SAMPLES_PER_PERIOD: usize = 200;

impl AttractorSpec {
    /// Check the census's options (the one place of their limits).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `samples` (1..=[`MAX_ATTRACTOR_SAMPLES`]) or
    /// `cluster_tol` (finite, > 0), or a steady-state option ([`SteadyOptions::validate`]);
    /// an integrator that cannot be built for the parameters
    /// ([`crate::integrate::check_buildable`]).
    pub fn validate(&self) -> Result<(), SimError> {
        in_range("samples", self.samples, 1..=MAX_ATTRACTOR_SAMPLES)?;
        if !(self.cluster_tol.is_finite() && self.cluster_tol > 0.0) {
            return Err(SimError::out_of_range(
                "cluster_tol",
                self.cluster_tol,
                "must be finite and > 0",
            ));
        }
        self.steady.validate()?;
        crate::integrate::check_buildable(&self.params, self.integrator.clone())
    }
}

/// One attractor with its basin estimate.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Attractor {
    /// The steady state found from the first member start.
    pub steady: SteadyState,
    /// An initial state that reaches it.
    pub initial: DVector<f64>,
    /// Number of starts that reached it.
    pub count: usize,
    /// count / (number of successful starts).
    pub basin_fraction: f64,
    /// The periodic orbit polished by shooting, with its Floquet multipliers and stability
    /// (`None` for a nonperiodic motion, for an integrator without step Jacobians — RK4 — or when
    /// Newton's method did not converge).
    pub orbit: Option<PeriodicOrbit>,
    /// The largest Lyapunov exponent λ₁ (per unit τ) of a nonperiodic motion and its error,
    /// over `CENSUS_LYAPUNOV_PERIODS` drive periods from its last section point (`None` for
    /// a periodic one, or when the estimate failed).
    pub lyapunov: Option<(f64, f64)>,
}

impl Attractor {
    /// A nonperiodic end whose λ₁ is below −2 × its error: a motion still converging (to an
    /// orbit the transient cap did not reach, or of a period above the largest searched), not
    /// an attractor.
    pub fn unsettled(&self) -> bool {
        self.steady.period().is_none() && matches!(self.lyapunov, Some((l, e)) if l < -2.0 * e)
    }
}

/// Drive periods of the λ₁ estimate of a census's nonperiodic ends: a basin map's
/// (as the basin map's, [`super::basins::LYAPUNOV_PERIODS`], and a chart's default).
pub(crate) const CENSUS_LYAPUNOV_PERIODS: usize = 500;

/// The result of an attractor search.
#[derive(Debug, Clone, PartialEq)]
pub struct AttractorReport {
    /// Attractors, most frequent first.
    pub attractors: Vec<Attractor>,
    /// Ends that had not settled within the transient cap ([`Attractor::unsettled`]), grouped
    /// as the attractors are; not attractors, and not counted in the basin fractions.
    pub unsettled: Vec<Attractor>,
    /// The transient cap of the runs, in drive periods (`SteadyOptions::cap`).
    pub transient_cap: usize,
    /// Starts that failed (error messages).
    pub failures: Vec<String>,
}

/// Same attractor: same period and every section point of `a` matches one of `b` (the cycle
/// may be entered at a different phase). Nonperiodic motions are grouped when X_max and
/// min V_T agree to 5 %.
pub fn same_attractor(a: &SteadyState, b: &SteadyState, tol: f64) -> bool {
    match (a.period(), b.period()) {
        (Some(n), Some(m)) if n == m => a
            .poincare
            .iter()
            .all(|p| b.poincare.iter().any(|q| close(&p.state, &q.state, tol))),
        (None, None) => {
            let rel = |x: f64, y: f64| (x - y).abs() <= 0.05 * x.abs().max(y.abs()).max(1e-3);
            rel(a.stats.x_max, b.stats.x_max) && rel(a.stats.v_t_min, b.stats.v_t_min)
        }
        _ => false,
    }
}

/// Run the search in parallel over samples.
///
/// It counts the random starts done in `progress` (its total grows by `samples`) and stops when
/// it is cancelled.
///
/// # Errors
/// [`SimError`] for invalid parameters or options (individual failing starts are reported in
/// [`AttractorReport::failures`]); [`SimError::Cancelled`] once `progress` is cancelled.
pub fn find_attractors(
    spec: &AttractorSpec,
    progress: &Progress,
) -> Result<AttractorReport, SimError> {
    spec.validate()?;
    let model = CantileverModel::new(&spec.params)?;
    let starts: Vec<DVector<f64>> = (0..spec.samples)
        .map(|i| random_state(&model, spec.seed, i as u64))
        .collect();
    progress.add_total(starts.len());
    census(&model, spec, starts, &[], progress.cancel_flag(), &|| {
        progress.tick()
    })
}

/// The attractors reached from the random `starts` and from `seeds` (states not counted in the
/// basin fractions: the previous value's attractors of a global continuation), every run in
/// parallel, clustered with [`same_attractor`] in the order starts then seeds, the periodic
/// ones polished by shooting. Calls `tick` as each run ends; starts no run once `cancel` is set.
///
/// # Errors
/// [`SimError::Cancelled`] once `cancel` is set (failing runs are reported in
/// [`AttractorReport::failures`]: the failures of seeds among them).
pub(crate) fn census(
    model: &CantileverModel,
    spec: &AttractorSpec,
    starts: Vec<DVector<f64>>,
    seeds: &[DVector<f64>],
    cancel: &AtomicBool,
    tick: &(dyn Fn() + Sync),
) -> Result<AttractorReport, SimError> {
    let random = starts.len();
    let mut all = starts;
    all.extend(seeds.iter().cloned());
    let results = steady_states_of_starts(model, spec, all, cancel, tick);
    if cancel.load(Ordering::Relaxed) {
        return Err(SimError::Cancelled);
    }
    let mut attractors: Vec<Attractor> = Vec::new();
    let mut failures = Vec::new();
    for (k, (z0, r)) in results.into_iter().enumerate() {
        let counted = usize::from(k < random);
        match r {
            Err(e) => failures.push(e.to_string()),
            Ok(s) => match attractors
                .iter_mut()
                .find(|a| same_attractor(&a.steady, &s, spec.cluster_tol))
            {
                Some(a) => a.count += counted,
                None => attractors.push(Attractor {
                    steady: s,
                    initial: z0,
                    count: counted,
                    basin_fraction: 0.0,
                    orbit: None,
                    lyapunov: None,
                }),
            },
        }
    }
    // each polish under this run's cancel flag (not a flag of the thread that runs it)
    let watched = crate::error::watched();
    attractors.par_iter_mut().with_max_len(1).for_each(|a| {
        crate::error::watching(watched.clone(), || {
            polish(model, spec.integrator.clone(), a)
        })
    });
    let (unsettled, attractors): (Vec<Attractor>, Vec<Attractor>) =
        merge_polished(attractors, spec.cluster_tol)
            .into_iter()
            .partition(Attractor::unsettled);
    let mut attractors = attractors;
    let ok: usize = attractors.iter().map(|a| a.count).sum();
    for a in &mut attractors {
        a.basin_fraction = a.count as f64 / ok.max(1) as f64;
    }
    // most frequent first (a stable sort: ties keep the order found)
    attractors.sort_by_key(|a| std::cmp::Reverse(a.count));
    Ok(AttractorReport {
        attractors,
        unsettled,
        transient_cap: spec.steady.cap(model),
        failures,
    })
}

impl AttractorReport {
    /// The caveats of the census (the `warnings` of its document): starts that ended unsettled.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        let undecided: usize = self
            .attractors
            .iter()
            .filter(|a| matches!(a.lyapunov, Some((l, e)) if l.abs() <= 2.0 * e))
            .map(|a| a.count)
            .sum();
        if undecided > 0 {
            w.push(warning!(
                "attractors.undecided",
                "Raise max_periods (a lever of quality factor Q settles over ~Q periods): \
                 λ₁ then tells a quasi-periodic motion (≈ 0) from one still settling (< \
                 0).",
                "{undecided} start(s) ended on a nonperiodic motion with λ₁ ≈ 0 (within twice \
                 its error) after the transient cap of {} drive periods: quasi-periodic, or \
                 still settling; raise max_periods to tell (a lever of quality factor Q \
                 settles over ~Q periods)",
                self.transient_cap
            ));
        }
        let ends: usize = self.unsettled.iter().map(|a| a.count).sum();
        if ends == 0 {
            return w;
        }
        let worst = self
            .unsettled
            .iter()
            .filter_map(|a| a.lyapunov.map(|l| l.0))
            .fold(f64::NEG_INFINITY, f64::max);
        w.push(warning!(
            "attractors.unsettled",
            "Raise max_periods until every start settles on an attractor.",
            "{ends} start(s) had not settled after the transient cap of {} drive periods \
             (nonperiodic with λ₁ ≤ {worst:.3e} < 0: still converging; not counted as \
             attractors): raise max_periods",
            self.transient_cap
        ));
        w
    }
}

/// Two steady states, each with whether Newton polished it onto its orbit, are one orbit: both
/// polished and [`same_attractor`] (the rule of the census's and the basin map's merges).
pub(crate) fn same_orbit(a: (&SteadyState, bool), b: (&SteadyState, bool), tol: f64) -> bool {
    a.1 && b.1 && same_attractor(a.0, b.0, tol)
}

/// One orbit, one attractor: clusters whose polished orbits coincide ([`same_attractor`] on
/// the orbits' section points, which Newton put within its tolerance of the orbit) are merged
/// into the first, their counts added. Runs are clustered on their last returns, which lie
/// off the orbit by up to tol/(1 − |μ₁|) — more than the clustering tolerance for a slowly
/// contracting orbit (|μ₁| ≈ 0.994 at Q = 500) — so two clusters can hold one orbit.
fn merge_polished(attractors: Vec<Attractor>, tol: f64) -> Vec<Attractor> {
    let mut merged: Vec<Attractor> = Vec::with_capacity(attractors.len());
    for a in attractors {
        let same = |b: &&mut Attractor| {
            same_orbit(
                (&b.steady, b.orbit.is_some()),
                (&a.steady, a.orbit.is_some()),
                tol,
            )
        };
        match merged.iter_mut().find(same) {
            Some(b) => b.count += a.count,
            None => merged.push(a),
        }
    }
    merged
}

/// A start and the steady state it reaches.
type StartResult = (DVector<f64>, Result<SteadyState, SimError>);

/// The steady state from every start, one by one in parallel. (A batched exact
/// propagator, lanes advanced together, measured 0.74–1.0× of one by one at N = 3 and kept one
/// core busy where the starts spread over all of them; it was removed, issue 30.)
fn steady_states_of_starts(
    model: &CantileverModel,
    spec: &AttractorSpec,
    starts: Vec<DVector<f64>>,
    cancel: &AtomicBool,
    tick: &(dyn Fn() + Sync),
) -> Vec<StartResult> {
    // each start watches the caller's cancel flag too (`crate::analysis::progress`)
    let watched = crate::error::watched();
    starts
        .into_par_iter()
        .with_max_len(1)
        .map(|z0| {
            let r = if cancel.load(Ordering::Relaxed) {
                Err(SimError::Cancelled)
            } else {
                crate::error::watching(watched.clone(), || {
                    steady_state_of(model, spec.integrator.clone(), &z0, &spec.steady)
                })
            };
            tick();
            (z0, r)
        })
        .collect()
}

/// Polish a periodic attractor by shooting from its last section point and replace its
/// Poincaré points with the orbit's (the cycle keeps its phase: the point after the last one
/// recorded is the first).
/// A nonperiodic one gets its λ₁ estimate instead ([`Attractor::lyapunov`]).
fn polish(model: &CantileverModel, integrator: IntegratorOptions, a: &mut Attractor) {
    a.orbit = polish_steady(model, integrator.clone(), &mut a.steady);
    if a.steady.period().is_none() {
        a.lyapunov = largest_exponent(
            model,
            a.steady.end_state(),
            CENSUS_LYAPUNOV_PERIODS,
            integrator,
        );
    }
}

/// Polish a periodic steady state by Newton shooting: its Poincaré points become the orbit's
/// (to the shooting tolerance) and the orbit (multipliers, stability) is returned; `None` for
/// a nonperiodic state, an integrator without step Jacobians, or shooting that fails (the
/// state is left as it was).
pub(crate) fn polish_steady(
    model: &CantileverModel,
    integrator: IntegratorOptions,
    steady: &mut SteadyState,
) -> Option<PeriodicOrbit> {
    let n = steady.period()?;
    if !matches!(
        integrator.kind.resolve(model),
        IntegratorKind::Exact
            | IntegratorKind::Adaptive
            | IntegratorKind::Split
            | IntegratorKind::Taylor
    ) {
        return None;
    }
    let guess = steady.end_state().clone();
    let map = &mut StroboscopicMap::build(model, integrator, &guess, 1).ok()?;
    let orbit = shoot(map, &guess, &ShootingOptions::default().with_period(n)).ok()?;
    // section = [z*, P(z*), …]; z* replaces the last recorded point p_n, P(z*) the first
    let k = steady.poincare.len();
    if k == n {
        for (i, p) in steady.poincare.iter_mut().enumerate() {
            let z = &orbit.section[(i + 1) % n];
            *p = PoincarePoint {
                tau: p.tau,
                v_t: model.v_t(p.tau, z),
                w_tip: model.w_tip(z),
                state: z.clone(),
            };
        }
    }
    Some(orbit)
}
