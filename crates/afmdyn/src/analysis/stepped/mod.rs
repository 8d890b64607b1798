//! Stepped sweeps of the steady state with branch continuation: the driver shared by the
//! approach–retract curve ([`super::approach`], the rest distance z_c) and the resonance curve
//! ([`super::resonance`], the drive frequency Ω).
//!
//! **Stepped sweeps.** As in an experiment and in the stepped approach of VEDA and dForce
//! (Guzman, Garcia & Garcia, *Beilstein J. Nanotechnol.* 6 (2015) 369), the parameter is
//! stepped through a grid and at each value the steady state is the one reached from the
//! previous value's end state; then the sweep runs back (retract, or down-sweep). Instead of
//! integrating ~Q/π periods of transient per value, the previous orbit is followed by Newton
//! shooting ([`super::shooting`]) from a secant prediction (where the integrator integrates the
//! variational equations step by step, Broyden's method from the previous orbits' monodromy
//! matrix, [`super::shooting::ShootingStrategy::Broyden`]): a stable orbit near the previous
//! one is its continuation, the state the motion settles on; a step the orbit moves too far in
//! is halved (quasi-static sub-steps, `SUBSTEP_DEPTH`) as long as halving brings the orbits
//! closer. When the orbit cannot be followed — Newton fails or lands on an unstable orbit, or
//! the distance does not shrink with the step: the attractor vanished at a fold, a jump — the
//! motion is integrated from the previous end state in chunks of drive periods, Newton being
//! retried from the transient until the trajectory is seen to approach a stable orbit
//! ([`settle`]); a motion that never settles on a period-n orbit is watched by the returns'
//! period test and by its windowed time average, within the point's `transient_cap`: a
//! period found is polished by Newton, and a motion whose windows agree first is reported
//! `averaged` (no short period found, [`Reached::Averaged`], with a warning).
//!
//! **Branches.** The periodic-orbit branches through both ends of the range — the two sweeps'
//! first orbits, and at each end the orbit Newton finds from the other end's (the other regime,
//! e.g. the repulsive state of a disconnected branch) — are continued in the parameter by
//! pseudo-arclength continuation ([`super::continuation`]; Keller 1977, Seydel 2010 ch. 4) with
//! Floquet stability, folds (saddle-nodes: the edges of the bistable ranges) and grazing points.
//! A start already on a computed branch is skipped.
//!
//! Every recorded orbit carries its [`Observables`] ([`super::observables`]).
//!
//! A two-frequency drive with a long common period can be measured on invariant circles
//! instead ([`torus`], [`SteppedSpec::torus`]; the exact orbit where a circle is not smooth),
//! and any multifrequency drive by the time average ([`average`]).

use crate::analysis::am_loop::LOCK_IN_SAMPLES;
use crate::analysis::bifurcation::SweepSpec;
use crate::analysis::continuation::{BranchEvent, BranchPoint};
use crate::analysis::lock_in_noise::{lock_in_noise, LockInNoise, ThermalLockIn};
use crate::analysis::observables::{observe, ObservableOptions, Observables};
use crate::analysis::orbit_noise::{grazing, NOISE_GRAZING};
use crate::analysis::progress::Progress;
pub use crate::analysis::settle::Found;
use crate::analysis::settle::{newton_from_transient, SettleOptions, NEWTON_CHUNKS, SETTLED};
use crate::analysis::shooting::{
    broyden_pays, shoot, Guess, PeriodicOrbit, ShootingOptions, ShootingStrategy,
};
use crate::analysis::steady::{decay_periods, SteadyOptions};
use crate::error::{in_range, within, SimError};
use crate::integrate::{build, Integrator, IntegratorOptions};
use crate::maps::{DiscreteMap, StroboscopicMap};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::tip_sample::TipSampleSystem;
use nalgebra::{Complex, DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};

pub mod average;
mod branches;
pub mod contraction;
pub use contraction::{SettleWait, STALLED_RUNS};
pub mod torus;
use average::{average_point, AverageEstimate, AverageOptions};
use branches::{branch, branch_starts, jumps_of, on_branch, unstable_between_folds};
use torus::{torus_point, CirclePoint, Fallback, TorusOptions};

mod point;
use point::{map_at, step_point};
pub use point::{settle, Settled, AVERAGE_AGREEMENTS, AVERAGE_MIN_WINDOW, AVERAGE_TOL};

/// Largest number of values of a stepped sweep (each is a steady-state computation, twice).
pub const MAX_CURVE_POINTS: usize = 100_000;

/// Default tolerance of the adaptive integrator in stepped sweeps: 1e-10 instead of the
/// library's 1e-12 makes a map ~3× cheaper, and changes A and φ of the point-mass DMT
/// approach curve (Q = 400) by < 5e-8 (relative to A₀, and rad) — below the 1e-6 agreement
/// with an independent integrator that the tests require.
pub(crate) const DEFAULT_TOLERANCE: f64 = 1e-10;

/// How the grid of a stepped sweep is spaced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Spacing {
    /// A fixed step (> 0, in the units of the swept value); the last value is the last grid
    /// point not beyond the end.
    Step(f64),
    /// This many evenly spaced values, ends included (2..=[`MAX_CURVE_POINTS`]).
    Points(usize),
}

/// A multifrequency drive whose common period spans more drive periods than this gets a
/// warning on its curves: each orbit costs that many periods (the example's 25/4 takes 4).
pub(crate) const SLOW_COMMON_PERIODS: u64 = 32;

/// Grid points of a curve request that gives neither a step nor a count.
pub const DEFAULT_CURVE_POINTS: usize = 120;

/// The values of a stepped sweep from `from` to `to` (in that order).
///
/// # Errors
/// [`SimError::OutOfRange`] for non-finite or equal ends, a step that is not finite and > 0,
/// or more than [`MAX_CURVE_POINTS`] values.
pub(crate) fn grid(from: f64, to: f64, spacing: Spacing) -> Result<Vec<f64>, SimError> {
    crate::error::finite("from", from)?;
    crate::error::finite("to", to)?;
    if from == to {
        return Err(SimError::out_of_range(
            "to",
            to,
            "must differ from the start of the sweep",
        ));
    }
    let points = match spacing {
        Spacing::Points(n) => {
            in_range("points", n, 2..=MAX_CURVE_POINTS)?;
            n
        }
        Spacing::Step(h) => {
            if !(h.is_finite() && h > 0.0) {
                return Err(SimError::out_of_range("step", h, "must be finite and > 0"));
            }
            let intervals = ((to - from).abs() / h * (1.0 + 1e-12)).floor();
            if intervals + 1.0 > MAX_CURVE_POINTS as f64 {
                return Err(SimError::out_of_range(
                    "step",
                    h,
                    "gives more than 100000 points over the range: use a larger step",
                ));
            }
            if intervals < 1.0 {
                return Err(SimError::out_of_range(
                    "step",
                    h,
                    "is longer than the range: no second point",
                ));
            }
            let n = intervals as usize + 1;
            let last = from + (to - from).signum() * h * intervals;
            return SweepSpec::linspace(from, last, n);
        }
    };
    SweepSpec::linspace(from, to, points)
}

/// A stepped sweep with branch continuation.
#[derive(Debug, Clone, PartialEq)]
pub struct SteppedSpec {
    /// Parameters held fixed (the swept one is overwritten).
    pub base: Params,
    /// The swept parameter.
    pub param: SweepParam,
    /// Its values in the order of the first sweep (the second runs back), at least 2.
    pub values: Vec<f64>,
    /// Integrator of every orbit and observable (default: auto with tolerance
    /// `DEFAULT_TOLERANCE`).
    pub integrator: IntegratorOptions,
    /// Newton shooting from the previous orbit (default: tolerance 1e-10, at most 6 iterations:
    /// from the secant prediction Newton converges in ~3; one that has not converged by 6 is
    /// stalled at a non-smooth point or far from the orbit, and a halved step is cheaper); the
    /// period is the orbit's, the strategy undamped or Broyden's where an orbit is followed.
    pub newton: ShootingOptions,
    /// Classification of a motion that does not settle on an orbit; `max_periods` is the most
    /// drive periods of transient a point may take, [`settle`] and classification together
    /// (less where the damping is strong: `transient_cap`).
    pub steady: SteadyOptions,
    /// Drive periods between Newton attempts while settling.
    pub chunk_periods: usize,
    /// An orbit found by Newton farther than this from the previous one (relative to
    /// 1 + ‖z‖) is checked by integrating the transient (a possible jump).
    pub jump_tol: f64,
    /// Observables of every orbit (`periods` is set to the orbit's period).
    pub observables: ObservableOptions,
    /// Continue the periodic-orbit branches.
    pub branches: bool,
    /// Cap on the points of one branch.
    pub max_branch_points: usize,
    /// Samples per drive period of the per-point traces of the first sweep
    /// ([`super::traces`]); 0: none.
    pub trace_samples: usize,
    /// Measure every point by the time average ([`average`]) instead of the periodic orbit:
    /// what a quasi-periodic drive needs ([`Params::is_quasiperiodic`]); no branches, traces
    /// or Floquet multipliers then.
    pub average: Option<AverageOptions>,
    /// Measure every point on the invariant circle of a two-frequency drive ([`torus`])
    /// instead of the exact orbit of its common period, which it falls back on where the
    /// circle is not found or not smooth; no branches then.
    pub torus: Option<TorusOptions>,
    /// How long [`settle`] waits before a motion is settled by its time average.
    pub settle_wait: SettleWait,
    /// The lock-in's thermal noise at every stable period-1 point of the two sweeps
    /// ([`crate::analysis::lock_in_noise`]); `None`: none.
    pub noise: Option<ThermalLockIn>,
}

impl SteppedSpec {
    /// Defaults for a sweep of `param` through `values`.
    pub(crate) fn new(base: Params, param: SweepParam, values: Vec<f64>) -> Self {
        SteppedSpec {
            base,
            param,
            values,
            integrator: IntegratorOptions {
                tolerance: DEFAULT_TOLERANCE,
                ..IntegratorOptions::default()
            },
            newton: ShootingOptions {
                tol: 1e-10,
                max_iter: 6,
                ..ShootingOptions::default()
            },
            steady: SteadyOptions {
                tol: 1e-8,
                max_periods: Some(20_000),
                max_period: 16,
                nonperiodic_record: 16,
                newton: false,
            },
            chunk_periods: 25,
            jump_tol: 0.1,
            observables: ObservableOptions::default(),
            branches: true,
            max_branch_points: 2000,
            trace_samples: 0,
            average: None,
            torus: None,
            settle_wait: SettleWait::default(),
            noise: None,
        }
    }
}

/// How the steady state of a sweep point was reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Reached {
    /// The first point: Newton from rest (or from the transient from rest).
    Start,
    /// Newton from the previous orbit converged to a stable orbit near it.
    Continued,
    /// The transient from the previous end state was integrated until it settled.
    Settled,
    /// Averaged (no short period found): the transient from the previous end state was
    /// integrated until its windowed time averages agreed ([`AVERAGE_TOL`]); the
    /// observables are those of the last window ([`settle`]).
    Averaged,
}

impl Reached {
    /// Whether the point was reached by integrating the transient ([`Reached::Settled`],
    /// [`Reached::Averaged`]): not on the branch of the point before.
    pub(crate) fn by_transient(self) -> bool {
        matches!(self, Reached::Settled | Reached::Averaged)
    }
}

/// One point of a stepped sweep (serialized for its study's store: the next point starts from
/// it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CurvePoint {
    /// Value of the swept parameter.
    pub value: f64,
    /// Period n of the orbit (in drive periods), `None` for a motion that is not period-n.
    pub period: Option<usize>,
    /// State at drive phase 0 (τ = 0 mod T), shape `[2N]`; the last recorded state for a
    /// non-periodic motion.
    pub state: DVector<f64>,
    /// Floquet multipliers of the orbit, decreasing modulus (empty for a non-periodic motion).
    pub multipliers: Vec<Complex<f64>>,
    /// Monodromy matrix of the orbit's period-n map, 2N×2N (`None` for a non-periodic motion):
    /// the first Jacobian of the Newton solve at the next value.
    pub monodromy: Option<DMatrix<f64>>,
    /// Stable: all multipliers inside the unit circle (a non-periodic motion reached by
    /// integration is an attractor and counts as stable).
    pub stable: bool,
    /// How it was reached.
    pub reached: Reached,
    /// Observables over one cycle (n periods; `steady.nonperiodic_record` periods otherwise;
    /// the measured Hann window of a time-averaged point).
    pub observables: Observables,
    /// τ of `state`: 0 but for a time-averaged point, whose state is where its window ended
    /// (the next point goes on from it).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub tau: f64,
    /// The convergence estimate of a time-averaged point ([`average`]); `None` for an orbit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub average: Option<AverageEstimate>,
    /// The invariant circle found at a point of a curve measured on circles ([`torus`]; also
    /// where it fell back on the exact orbit, when a circle converged); `None` otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circle: Option<CirclePoint>,
    /// Why a point of a curve measured on invariant circles ([`SteppedSpec::torus`]) is the
    /// exact orbit instead; `None` otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<Fallback>,
    /// Settled by its time average only after the free decay's wait, which its returns'
    /// unmeasurable contraction kept ([`Settled::free_decay_wait`]; the curve warns).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub free_decay_wait: bool,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl CurvePoint {
    /// A stable period-1 orbit, whose lock-in noise [`SteppedSpec::noise`] asks for: not
    /// time-averaged, not on an invariant circle, not of a longer period.
    fn noise_orbit(&self) -> bool {
        self.period == Some(1)
            && self.stable
            && self.average.is_none()
            && (self.circle.is_none() || self.fallback.is_some())
    }

    /// A time-averaged point whose windows still differed at its transient cap ([`average`]):
    /// not converged (the curve's warnings count them).
    pub(crate) fn unsettled(&self) -> bool {
        self.average.as_ref().is_some_and(|a| !a.settled)
    }
}

/// One point of a continued branch with its observables.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchSample {
    /// The branch point (parameter value, section states, multipliers, stability, event).
    pub point: BranchPoint,
    /// Observables over one cycle of the orbit.
    pub observables: Observables,
}

/// Which sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Sweep {
    /// The first sweep, through `values` in order (approach, up-sweep).
    First,
    /// The sweep back (retract, down-sweep).
    Second,
}

/// A jump of a stepped sweep: the attractor followed so far vanished (or lost stability)
/// between two grid values and the motion settled on another one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Jump {
    /// Which sweep.
    pub sweep: Sweep,
    /// Index of the point after the jump in that sweep.
    pub index: usize,
    /// Value before the jump.
    pub from: f64,
    /// Value after the jump.
    pub to: f64,
    /// The fold (saddle-node) of a continued branch within one grid step of the jump, if any:
    /// the located parameter value of the vanishing attractor.
    pub fold: Option<f64>,
}

/// The result of [`stepped_sweep`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteppedCurve {
    /// The swept parameter.
    pub param: SweepParam,
    /// The first sweep, in the order of `values`.
    pub first: Vec<CurvePoint>,
    /// The sweep back, in the reverse order (its first point is the first sweep's last).
    pub second: Vec<CurvePoint>,
    /// Continued periodic-orbit branches, each in arclength order.
    pub branches: Vec<Vec<BranchSample>>,
    /// Jumps of both sweeps.
    pub jumps: Vec<Jump>,
    /// Parameter values of the located folds, ascending.
    pub folds: Vec<f64>,
    /// Ranges [lo, hi] of the unstable stretches of the branches that run from a fold to a
    /// fold: where a branch has three orbits (two stable ones and the unstable one between
    /// them), the bistable ranges.
    pub bistable: Vec<(f64, f64)>,
    /// What could not be computed (e.g. a branch whose start failed).
    pub warnings: Vec<String>,
    /// One steady-state cycle per point of the first sweep, when
    /// [`SteppedSpec::trace_samples`] > 0.
    pub traces: Option<super::traces::Traces>,
    /// The time average's options when the points were measured by it ([`average`]; each
    /// point's estimate is its [`CurvePoint::average`]).
    pub average: Option<AverageOptions>,
    /// The lock-in's thermal noise per point of `first` and `second`
    /// ([`SteppedSpec::noise`]); [`LockInNoise::NONE`] where a point is not a stable period-1
    /// orbit.
    pub noise: Option<[Vec<LockInNoise>; 2]>,
}

impl SteppedCurve {
    /// The largest indentation max(−V_T, 0) of the curve's operating points, both sweeps (in
    /// the model's length unit; 0 for a curve that never touches).
    pub fn largest_indentation(&self) -> f64 {
        self.first
            .iter()
            .chain(&self.second)
            .map(|p| p.observables.indentation)
            .filter(|d| d.is_finite())
            .fold(0.0, f64::max)
    }

    /// The number of drive components its points demodulate (0 for a single-frequency drive:
    /// [`crate::analysis::observables::Observables::components`]).
    pub(crate) fn components(&self) -> usize {
        let first = self.first.first();
        first.map_or(0, |p| p.observables.components.len())
    }
}

/// Why a time average may not settle ([`average::slowest_beat`]): the clause for the
/// warning when the slowest beat of the combination tones is longer than the settling window,
/// or empty.
fn slow_beat(base: &Params, window_periods: usize) -> String {
    match average::slowest_beat(base) {
        Some((p, q, r, beat)) if average::BEATS_PER_WINDOW * beat > window_periods as f64 => {
            format!(
                "; f/f1 = {} lies {:.1e} from {p}/{q}: the motion beats every {beat:.0} drive \
                 periods, and the settling window of {window_periods} holds fewer than {} beats \
                 (a frequency ratio of exactly {p}/{q} gives the periodic orbit)",
                crate::error::number(r),
                (r - f64::from(p) / f64::from(q)).abs(),
                average::BEATS_PER_WINDOW,
            )
        }
        _ => String::new(),
    }
}

/// Observables of a period-n orbit (or `record` periods of a motion) from `z` at τ = 0.
fn measure(
    integ: &mut dyn Integrator,
    z: &DVector<f64>,
    periods: usize,
    opts: &ObservableOptions,
) -> Result<Observables, SimError> {
    integ.set_variational(false);
    integ.reset(0.0, z)?;
    observe(
        integ,
        &ObservableOptions {
            periods: periods.max(1),
            ..*opts
        },
    )
}

fn relative_gap(a: &DVector<f64>, b: &DVector<f64>) -> f64 {
    (a - b).norm() / (1.0 + b.norm())
}

/// Fewest drive periods of transient a point of a stepped sweep may take ([`transient_cap`]).
pub(crate) const POINT_MIN_PERIODS: usize = 5_000;

/// Decay times of the slowest free mode in a point's transient cap ([`transient_cap`]).
pub(crate) const POINT_DECAY_TIMES: f64 = 9.0;

/// The drive periods of transient a point of a stepped sweep may take, [`settle`]'s Newton
/// attempts, period test and time average together: [`POINT_DECAY_TIMES`] times the periods
/// the slowest free mode of the cantilever (damped eigenvalue λ with the smallest |Re λ|,
/// eqs. 20–21) takes to decay by the period search's tolerance, ln(1/tol)/(|Re λ| T), within
/// [[`POINT_MIN_PERIODS`], `spec.steady.max_periods`]; `spec.steady.max_periods` for a
/// system without a free decay rate ([`TipSampleSystem::free_decay_rate`]). At Q = 400 (ln(1e8) Q/π = 2 345 periods) it is
/// `max_periods` (20 000 by default), as before; a model with strong damping, whose transients
/// onto an orbit take a few hundred periods (the default beam, Q ≈ 42: 248), has the floor.
/// A motion still unsettled after the cap is classified nonperiodic: near the edge of a
/// periodic window in a chaotic band that is a matter of the start state — the default
/// resonance curve's classification there changes with round-off-level changes of its start
/// — which no cap removes, while each nonperiodic point costs the whole cap.
pub(crate) fn transient_cap(system: &dyn TipSampleSystem, spec: &SteppedSpec) -> usize {
    let cap = spec.steady.cap(system);
    let Some(decay) = decay_periods(system, spec.steady.tol) else {
        return cap;
    };
    let periods = (POINT_DECAY_TIMES * decay).ceil();
    (periods.min(cap as f64) as usize).max(POINT_MIN_PERIODS.min(cap))
}

/// Halvings of a grid step tried by the sweep's orbit continuation (quasi-static sub-steps, see
/// the module docs) before it falls back on the transient (at most 2^depth sub-steps).
pub(crate) const SUBSTEP_DEPTH: usize = 8;

/// The points of both sweeps after the `stored` ones (a run that was cut short handed them to
/// `sink`, in order: the first sweep's through `spec.values`, then the sweep back's; none for
/// a new run), each stepped from the points before it as an uninterrupted run steps them, and
/// handed to `sink` with its place (0..2n) as it is done. Starts no point once `cancel` is
/// set. Returns the two sweeps ([`SteppedCurve::first`], [`SteppedCurve::second`]).
///
/// # Errors
/// [`SimError::Cancelled`] once `cancel` is set; [`SimError`] from the model or the
/// integrator.
pub(crate) fn sweep_points(
    spec: &SteppedSpec,
    stored: &[CurvePoint],
    cancel: &AtomicBool,
    sink: &dyn Fn(usize, &CurvePoint),
) -> Result<(Vec<CurvePoint>, Vec<CurvePoint>), SimError> {
    let n = spec.values.len();
    let back: Vec<f64> = spec.values.iter().rev().copied().collect();
    let mut first: Vec<CurvePoint> = stored.iter().take(n).cloned().collect();
    let mut second: Vec<CurvePoint> = stored.iter().skip(n).take(n).cloned().collect();
    for k in stored.len().min(2 * n)..2 * n {
        if cancel.load(Ordering::Relaxed) {
            return Err(SimError::Cancelled);
        }
        let p = if k < n {
            let m = first.len();
            step_point(spec, spec.values[k], &first[m.saturating_sub(3)..])?
        } else if k == n {
            // the sweep back starts where the first sweep ended
            first[n - 1].clone()
        } else {
            let m = second.len();
            step_point(spec, back[k - n], &second[m.saturating_sub(3)..])?
        };
        sink(k, &p);
        if k < n {
            first.push(p);
        } else {
            second.push(p);
        }
    }
    Ok((first, second))
}

/// Check the values of a stepped sweep: 2..=[`MAX_CURVE_POINTS`] of them, finite, the ends'
/// parameters valid.
///
/// # Errors
/// [`SimError::OutOfRange`], [`SimError::NotFinite`], [`SimError::Params`].
pub(crate) fn check_values(spec: &SteppedSpec) -> Result<(), SimError> {
    within(
        "points",
        spec.values.len(),
        2..=MAX_CURVE_POINTS,
        "a stepped sweep needs 2..=100000 values",
    )?;
    for &v in &spec.values {
        crate::error::finite("sweep value", v)?;
    }
    for &v in [spec.values[0], spec.values[spec.values.len() - 1]].iter() {
        let p = spec.base.with(spec.param, v);
        match spec.average {
            Some(_) => p.validate_fields()?,
            None => p.validate()?,
        }
    }
    if let Some(a) = &spec.average {
        a.check()?;
        if !spec.base.is_multifrequency() {
            return Err(SimError::out_of_range(
                "average",
                "one drive component",
                "the time average is for a multifrequency drive; a single-frequency curve is \
                 measured on its exact periodic orbits",
            ));
        }
        if spec.branches || spec.trace_samples > 0 {
            return Err(SimError::out_of_range(
                if spec.branches { "branches" } else { "traces" },
                true,
                "not with the time average, which follows the motion in time (no periodic \
                 orbits to continue or to trace)",
            ));
        }
    } else if let Some(t) = &spec.torus {
        t.check()?;
        torus::rotation_of(&spec.base)?;
    } else if spec.base.is_quasiperiodic() {
        return Err(SimError::out_of_range(
            "average",
            false,
            "a quasi-periodic drive (common period beyond 1000 drive periods) has no periodic \
             orbit: measure it by the time average",
        ));
    }
    Ok(())
}

/// Run the stepped sweep through `spec.values` and back, then (with `spec.branches`) continue
/// the periodic-orbit branches through both sweeps' first points.
///
/// # Errors
/// [`SimError::OutOfRange`] for fewer than 2 or more than [`MAX_CURVE_POINTS`] values or
/// non-finite ones; [`SimError::Params`] when a value is outside its parameter's range;
/// [`SimError`] from the integrator. A branch that cannot be continued is a warning.
pub fn stepped_sweep(spec: &SteppedSpec) -> Result<SteppedCurve, SimError> {
    check_values(spec)?;
    // a run of its own, never cancelled
    let progress = Progress::new();
    let (first, second) = sweep_points(spec, &[], progress.cancel_flag(), &|_, _| ())?;
    finish_curve(spec, first, second, &progress)
}

/// The curve of the two sweeps ([`sweep_points`]): with `spec.branches` the periodic-orbit
/// branches through both sweeps' first points continued (their points counted in
/// `progress`), the folds, bistable ranges and jumps, and the traces.
///
/// # Errors
/// [`SimError::Cancelled`] once `progress` is cancelled; [`SimError`] from the traces' model
/// or integrator. A branch that cannot be continued is a warning.
pub(crate) fn finish_curve(
    spec: &SteppedSpec,
    first: Vec<CurvePoint>,
    second: Vec<CurvePoint>,
    progress: &Progress,
) -> Result<SteppedCurve, SimError> {
    let mut warnings = curve_warnings(spec, &first, &second);
    let branches = if spec.branches && spec.torus.is_none() {
        continued_branches(spec, (&first, &second), progress, &mut warnings)?
    } else {
        Vec::new()
    };
    let mut folds: Vec<f64> = Vec::new();
    let mut bistable = Vec::new();
    for br in &branches {
        folds.extend(
            br.iter()
                .filter(|s| s.point.event == Some(BranchEvent::Fold))
                .map(|s| s.point.value),
        );
        bistable.extend(unstable_between_folds(br));
    }
    folds.sort_by(f64::total_cmp);
    folds.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * (1.0 + b.abs()));
    let mut jumps = jumps_of(Sweep::First, &first, &folds, spec.jump_tol);
    jumps.extend(jumps_of(Sweep::Second, &second, &folds, spec.jump_tol));
    let traces = match spec.trace_samples {
        0 => None,
        n => {
            let points: Vec<super::traces::TracePoint<'_>> = first
                .iter()
                .map(|p| (p.value, &p.state, p.period))
                .collect();
            Some(super::traces::traces(
                &spec.base,
                spec.param,
                spec.integrator.clone(),
                &points,
                n,
            )?)
        }
    };
    let noise = curve_noise(spec, [&first, &second], progress, &mut warnings)?;
    Ok(SteppedCurve {
        param: spec.param,
        first,
        second,
        branches,
        jumps,
        folds,
        bistable,
        warnings,
        traces,
        average: spec.average,
        noise,
    })
}

/// The lock-in's thermal noise of [`SteppedSpec::noise`] at each point of the two sweeps:
/// [`LockInNoise::NONE`] at a point that is not a stable period-1 orbit (time-averaged,
/// on an invariant circle, unstable or of a longer period).
///
/// Warns in `warnings` of the points whose lowest point passes within [`NOISE_GRAZING`]
/// thermal standard deviations of the surface ([`grazing`]).
///
/// # Errors
/// [`SimError::Cancelled`] once `progress` is cancelled; as [`lock_in_noise`].
fn curve_noise(
    spec: &SteppedSpec,
    sweeps: [&[CurvePoint]; 2],
    progress: &Progress,
    warnings: &mut Vec<String>,
) -> Result<Option<[Vec<LockInNoise>; 2]>, SimError> {
    let Some(n) = spec.noise else {
        return Ok(None);
    };
    let orbits = (sweeps.iter().flat_map(|s| s.iter())).filter(|p| p.noise_orbit());
    let near = grazing(&spec.base, n.kt, orbits.map(|p| &p.observables))?;
    if near > 0 {
        warnings.push(warning!(
            "thermal.noise-grazing",
            "Read their amplitude_noise and phase_noise_deg as estimates only; a time-domain \
             run measures the noise there (image --feedback pi --temperature).",
            "{near} point(s) pass within {NOISE_GRAZING} thermal standard deviations √(k_BT/k) of \
             the surface, above or inside it, where the noise adds or removes contacts from period \
             to period: their lock-in noise is beyond the linear response"
        ));
    }
    let all = || sweeps.iter().flat_map(|s| s.iter());
    let on_circle = |p: &&CurvePoint| p.circle.is_some() && p.fallback.is_none();
    let averaged = |p: &&CurvePoint| p.average.is_some() || p.reached == Reached::Averaged;
    let unmeasured = all().filter(|p| averaged(p) || on_circle(p)).count();
    let circles = all().any(|p| on_circle(&p));
    if unmeasured > 0 {
        warnings.push(warning!(
            "thermal.no-orbit",
            "Exact orbits carry the noise: bimodal --exact instead of invariant circles, no \
             --average (a quasi-periodic drive has none).",
            "{unmeasured} point(s) are {} and have no lock-in noise (null): the noise is \
             computed about exact periodic orbits only",
            if circles {
                "on invariant circles"
            } else {
                "time averages"
            }
        ));
    }
    let sweep = |points: &[CurvePoint]| -> Result<Vec<LockInNoise>, SimError> {
        points
            .iter()
            .map(|p| {
                progress.check()?;
                if !p.noise_orbit() {
                    return Ok(LockInNoise::NONE);
                }
                let model = CantileverModel::new(&spec.base.with(spec.param, p.value))?;
                lock_in_noise(&model, &p.state, n.kt, n.time_constant, LOCK_IN_SAMPLES)
            })
            .collect()
    };
    Ok(Some([sweep(sweeps[0])?, sweep(sweeps[1])?]))
}

/// The warnings on the two sweeps' points (averaged or unsettled ones, a free decay) and on
/// the drive (quasi-periodic, on invariant circles, a slow common period).
fn curve_warnings(spec: &SteppedSpec, first: &[CurvePoint], second: &[CurvePoint]) -> Vec<String> {
    let mut warnings = Vec::new();
    let q = spec.base.common_periods();
    let averaged = first
        .iter()
        .chain(second)
        .filter(|p| p.reached == Reached::Averaged)
        .count();
    if averaged > 0 {
        warnings.push(warning!(
            "curve.averaged",
            "Read those points as time averages (no Floquet multipliers); raise \
             max_period if their motion has a longer period.",
            "{averaged} point(s) averaged (no short period found): their motion did not repeat \
             with a period of at most {} drive periods, and was measured by its time average \
             once {AVERAGE_AGREEMENTS} successive windows agreed to {AVERAGE_TOL:e} of the \
             amplitude (reached = \"averaged\"; no Floquet multipliers)",
            spec.steady.max_period
        ));
    }
    warnings.extend(contraction::free_decay_warning(first.iter().chain(second)));
    let unsettled = first.iter().chain(second).filter(|p| p.unsettled()).count();
    if unsettled > 0 {
        warnings.push(warning!(
            "curve.average-unsettled",
            "Raise max_periods (a lever settles over ~Q periods), or read those points' \
             error estimates in time_average.",
            "{unsettled} time-averaged point(s) did not settle within their transient cap (their \
             components' windows still differed by more than the tolerance): their values and \
             error estimates are those of the last windows{}",
            spec.average
                .as_ref()
                .map(|a| slow_beat(&spec.base, a.window_periods))
                .unwrap_or_default()
        ));
    }
    // the components' ratios p/q, for the warnings
    let ratios = spec
        .base
        .components()
        .map(|c| format!("{}/{}", c.ratio[0], c.ratio[1]))
        .collect::<Vec<_>>()
        .join(", ");
    if spec.average.is_some() && spec.base.is_quasiperiodic() {
        warnings.push(warning!(
            "curve.quasi-periodic-drive",
            "Give the second drive a frequency at a ratio p/q with a small q for exact \
             orbits; else read each point's error estimate in time_average.",
            "the drive's frequency ratio ({ratios}) repeats only after more than {} drive \
             periods (quasi-periodic): every point is a time average, with its error estimate \
             in time_average",
            crate::params::MAX_COMMON_PERIODS
        ));
    }
    if let Some(t) = &spec.torus {
        let m = first
            .iter()
            .chain(second)
            .find_map(|p| p.circle.as_ref().map(|c| c.nodes));
        warnings.push(warning!(
            "curve.invariant-circle",
            "Nothing: invariant_circle says where the circle was used; a ratio with a \
             smaller q gives exact orbits.",
            "the drive repeats only every {q} drive periods (its frequency ratio {ratios}): the \
             points are measured on the invariant circle of the stroboscopic map ({} nodes, \
             asked {}), the exact orbit where the circle is not smooth or not found{}",
            m.map_or_else(|| "no".to_string(), |m| m.to_string()),
            t.nodes,
            if spec.branches {
                "; the branches and their folds are not continued on circles (exact orbits: \
                 bimodal --exact)"
            } else {
                ""
            }
        ));
        let all: Vec<&CurvePoint> = first.iter().chain(second).collect();
        warnings.extend(torus::fallback_warning(&all));
    }
    if q > SLOW_COMMON_PERIODS && spec.average.is_none() && spec.torus.is_none() {
        warnings.push(warning!(
            "curve.long-period-drive",
            "Give a ratio with a smaller q, or take the time average (bimodal --average), \
             which does not depend on q.",
            "the multifrequency drive repeats only every {q} drive periods (its frequency ratio \
             {ratios}): every orbit spans them all; a ratio p/q with a small q (e.g. f2 = 6.25 \
             f1) is as many times faster, and the time average (bimodal --average) does not \
             depend on q"
        ));
    }
    warnings
}

/// The periodic-orbit branches through the sweeps' (`first`, `second`) first points, each
/// continued once (their points counted in `progress`); a branch that ends early or cannot be
/// continued is a warning into `warnings`.
///
/// # Errors
/// [`SimError::Cancelled`] once `progress` is cancelled.
fn continued_branches(
    spec: &SteppedSpec,
    (first, second): (&[CurvePoint], &[CurvePoint]),
    progress: &Progress,
    warnings: &mut Vec<String>,
) -> Result<Vec<Vec<BranchSample>>, SimError> {
    let mut branches: Vec<Vec<BranchSample>> = Vec::new();
    for start in branch_starts(spec, first, second) {
        if branches
            .iter()
            .any(|b| on_branch(b, start.value, &start.state))
        {
            continue;
        }
        let (lo, hi) = (spec.values[0], spec.values[spec.values.len() - 1]);
        let to = if start.value == lo { hi } else { lo };
        match branch(spec, &start, to, progress) {
            Ok((br, end)) => {
                if let Some(why) = end.cause() {
                    // the curve's parameter is reported in the user's units by the front
                    // end: the warning names the cause, not the internal value
                    warnings.push(warning!(
                        "curve.branch-ended",
                        "Continue the branch from where it ended (continue --from) to \
                         locate the folds beyond it.",
                        "a period-{} branch ended before the end of the range ({why}); \
                         folds beyond it are not located",
                        start.period.unwrap_or(1)
                    ));
                }
                branches.push(br);
            }
            Err(SimError::Cancelled) => return Err(SimError::Cancelled),
            Err(e) => warnings.push(format!(
                "branch from {} = {}: {e}",
                spec.param.name(),
                start.value
            )),
        }
    }
    Ok(branches)
}

/// Whether `z` is a fixed point of the period-n stroboscopic map at `value` to `tol`
/// (‖Pⁿ(z) − z‖ ≤ tol (1 + ‖z‖)): the check that a recorded orbit is a steady state.
///
/// # Errors
/// [`SimError`] from the model or the integrator.
pub fn is_fixed_point(
    spec: &SteppedSpec,
    value: f64,
    z: &DVector<f64>,
    n: usize,
    tol: f64,
) -> Result<bool, SimError> {
    // the map of n periods, as one flow over them
    let m = map_at(spec, value, z)?.linearise(z, n, true)?;
    Ok((&m.state - z).norm() <= tol * (1.0 + z.norm()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Structure;

    /// The transient cap of the point-mass model z'' + α3 z' + z = … (damped eigenvalue
    /// −α3/2 ± i√(1 − α3²/4)) against its closed form 9 ln(1/tol)/((α3/2) 2π/Ω), within
    /// [5 000, max_periods]: Q = 400 takes the old cap of 20 000, Q = 200 the closed form,
    /// Q = 42 the floor; a cap below the floor is kept.
    #[test]
    fn the_transient_cap_is_nine_decay_times_of_the_slowest_mode() {
        for (q, omega) in [(400.0, 1.0), (200.0, 1.0), (200.0, 1.3), (42.0, 1.0)] {
            let p = Params {
                structure: Structure::PointMass,
                modes: 1,
                alpha1: 0.0,
                alpha3: 1.0 / q,
                omega,
                ..Params::default()
            };
            let spec = SteppedSpec::new(p, SweepParam::Alpha5, vec![0.0, 0.1]);
            let model = CantileverModel::new(&p).unwrap();
            let integ = build(&model, spec.integrator.clone(), 0.0, &model.rest()).unwrap();
            let decay = (1e8f64).ln() / (0.5 / q * std::f64::consts::TAU / omega);
            let want = (9.0 * decay).ceil().clamp(5000.0, 20_000.0);
            let got = transient_cap(integ.system(), &spec) as f64;
            assert!(
                (got - want).abs() <= 1.0,
                "Q = {q}, Ω = {omega}: {got} vs {want}"
            );
            let low = SteppedSpec {
                steady: SteadyOptions {
                    max_periods: Some(3000),
                    ..spec.steady
                },
                ..spec.clone()
            };
            assert_eq!(transient_cap(integ.system(), &low), 3000);
        }
    }
}
