//! Pseudo-arclength continuation of period-n orbits of the stroboscopic map in Ω or any α, with
//! detection and location of folds, period doublings, Neimark–Sacker and grazing points, and
//! branch switching at a period doubling onto the period-2n branch.
//!
//! Unknowns y = (z, p) ∈ R^{2N+1}; F(z, p) = Pⁿ(z; p) − z = 0 augmented by the arclength
//! condition tᵀ(y − y_pred) = 0 (Keller 1977; Seydel, *Practical Bifurcation and Stability
//! Analysis*, 3rd ed., Springer 2010, ch. 4). ∂F/∂z = M − I with M the monodromy matrix;
//! ∂F/∂p from the parameter sensitivity along the same flow where the integrator provides it
//! (the exact propagator for Ω, α2, α5: `StroboscopicMap::with_param_derivative`), else by central
//! differences of the map, by flows without the variational equations. Test functions
//! between accepted points: dp/ds (fold), det(M + I) (period doubling), the number of complex
//! multipliers outside the unit circle (Neimark–Sacker) and the number of switchings per cycle
//! (grazing); each sign change is located on the arclength step, by bisection for the counts
//! and by the Illinois secant for the two smooth test functions.

use crate::analysis::progress::Progress;
use crate::analysis::shooting::{
    floquet_stability, section_points, shoot, Instability, ShootingOptions,
};
use crate::error::SimError;
use crate::integrate::{build, Integrator, IntegratorOptions};
use crate::maps::flow::FlowMap;
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

mod switching;
pub use switching::{continue_with_switching, period_doubling_starts, switch_at_period_doubling};

mod events;
mod solver;
pub(crate) use events::MAX_MULTIPLIER_STEP;
use events::{changed, chord_passes, locate, multiplier_shift, point, tests};
use solver::Solver;

/// A continuation run.
#[derive(Debug, Clone, PartialEq)]
pub struct ContinuationSpec {
    /// Parameters (the continued one is overwritten).
    pub base: Params,
    /// Continued parameter.
    pub param: SweepParam,
    /// Start value.
    pub from: f64,
    /// The run stops when the parameter leaves [min(from, to), max(from, to)].
    pub to: f64,
    /// Period n of the orbit.
    pub period: usize,
    /// Initial arclength step.
    pub ds: f64,
    /// Smallest step before giving up.
    pub ds_min: f64,
    /// Largest step.
    pub ds_max: f64,
    /// Cap on the number of points.
    pub max_points: usize,
    /// Work budget of one branch: adaptive integrator steps ([`Integrator::work`]) over all its
    /// flows (corrector, ∂F/∂p, event location); the exact propagator's steps are not counted.
    /// The branch ends with [`BranchEnd::Budget`] once it is spent.
    pub max_work: u64,
    /// Newton options (also for the corrector); the orbit's period is [`Self::period`].
    pub newton: ShootingOptions,
    /// Integrator of the stroboscopic map (default: auto, exact for the linear law).
    pub integrator: IntegratorOptions,
    /// Parameter values of the parent branch's period doublings (a period-2n branch): a fold
    /// located at one of them, where the half-cycles nearly coincide, is the pitchfork junction
    /// with the parent — the branch is labelled a period doubling there and ends.
    pub junctions: Vec<f64>,
    /// The parameter range the branch may visit (default: between `from` and `to`); the branch
    /// starts towards `to`.
    pub range: Option<(f64, f64)>,
}

impl ContinuationSpec {
    /// Defaults for a run from `from` to `to`.
    pub fn new(base: Params, param: SweepParam, from: f64, to: f64, period: usize) -> Self {
        let span = (to - from).abs().max(1e-6);
        ContinuationSpec {
            base,
            param,
            from,
            to,
            period,
            ds: span / 200.0,
            ds_min: span * 1e-9,
            ds_max: span / 50.0,
            max_points: 5000,
            max_work: WORK_BUDGET,
            newton: ShootingOptions::default(),
            integrator: IntegratorOptions::default(),
            junctions: Vec::new(),
            range: None,
        }
    }
}

/// Default [`ContinuationSpec::max_work`]: 10⁸ adaptive steps per branch. The default
/// three-mode branches from Ω = 5 to 1 take 1.4·10⁷ (Hertz, 1340 points) and 3.0·10⁷ (DMT,
/// 2295 points); the budget ends a branch that winds on without end (an undamped beam, say)
/// after a bounded, reproducible amount of work, with a warning naming where it stopped.
pub(crate) const WORK_BUDGET: u64 = 100_000_000;

/// Why a branch ended.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "kebab-case", tag = "reason")]
pub enum BranchEnd {
    /// The parameter left the range: the branch is complete.
    Range,
    /// The branch closed on its first point (an isola).
    Closed,
    /// A period-2n branch merged into its period-n parent.
    Merged,
    /// The corrector failed down to the smallest arclength step at this parameter value (a
    /// singular point the predictor cannot pass, or the orbit ceased to exist).
    StepFloor {
        /// Parameter value of the last point.
        value: f64,
    },
    /// [`ContinuationSpec::max_points`] points.
    MaxPoints {
        /// Parameter value of the last point.
        value: f64,
    },
    /// [`ContinuationSpec::max_work`] adaptive steps spent.
    Budget {
        /// Parameter value of the last point.
        value: f64,
        /// Steps spent.
        steps: u64,
    },
}

impl BranchEnd {
    /// Why an early end came, as a clause ("its work budget of adaptive steps", …); `None` for
    /// a complete branch.
    pub(crate) fn cause(&self) -> Option<&'static str> {
        match self {
            BranchEnd::Range | BranchEnd::Closed | BranchEnd::Merged => None,
            BranchEnd::StepFloor { .. } => Some(
                "the corrector failed down to the smallest arclength step (a singular point, \
                 or the orbit ceases to exist there)",
            ),
            BranchEnd::MaxPoints { .. } => Some("its cap of points"),
            BranchEnd::Budget { .. } => Some("its work budget of adaptive steps"),
        }
    }

    /// A one-line warning for a branch that ended early, naming the parameter `param` at which
    /// it stopped, the `BranchEnd::cause` and what to change; `None` for a complete branch.
    pub(crate) fn warning(&self, param: SweepParam, period: usize) -> Option<String> {
        let cause = self.cause()?;
        let p = param.name();
        let at = |x: f64| {
            format!(
                "the period-{period} branch ended at {p} = {}",
                crate::error::number(x)
            )
        };
        Some(match *self {
            BranchEnd::Budget { value, steps } => warning!(
                "continuation.budget",
                "Narrow --from/--to, or continue from the value where the branch ended \
                 with --from.",
                "{} after {steps} adaptive steps ({cause}); narrow --from/--to, or continue from \
                 there with --from",
                at(value)
            ),
            BranchEnd::MaxPoints { value } => {
                warning!(
                    "continuation.max-points",
                    "Continue from the value where the branch ended with --from.",
                    "{} after {cause}; continue from there with --from",
                    at(value)
                )
            }
            BranchEnd::StepFloor { value } => warning!(
                "continuation.step-floor",
                "Look at the orbit near that value (orbit, simulate): a fold or a \
                 bifurcation ends the branch there; continue past it from a start beyond \
                 it (--from).",
                "{}: {cause}",
                at(value)
            ),
            BranchEnd::Range | BranchEnd::Closed | BranchEnd::Merged => unreachable!("complete"),
        })
    }
}

/// A continued branch: its points in arclength order and why it ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// The points, located bifurcations labelled.
    pub points: Vec<BranchPoint>,
    /// Why the branch ended.
    pub end: BranchEnd,
}

impl std::ops::Deref for Branch {
    type Target = Vec<BranchPoint>;
    fn deref(&self) -> &Vec<BranchPoint> {
        &self.points
    }
}

impl std::ops::DerefMut for Branch {
    fn deref_mut(&mut self) -> &mut Vec<BranchPoint> {
        &mut self.points
    }
}

impl<'a> IntoIterator for &'a Branch {
    type Item = &'a BranchPoint;
    type IntoIter = std::slice::Iter<'a, BranchPoint>;
    fn into_iter(self) -> Self::IntoIter {
        self.points.iter()
    }
}

impl<'a> IntoIterator for &'a mut Branch {
    type Item = &'a mut BranchPoint;
    type IntoIter = std::slice::IterMut<'a, BranchPoint>;
    fn into_iter(self) -> Self::IntoIter {
        self.points.iter_mut()
    }
}

/// A labelled point of a branch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BranchEvent {
    /// Fold (limit point): dp/ds changes sign.
    Fold,
    /// Period doubling: a multiplier through −1.
    PeriodDoubling,
    /// Neimark–Sacker: a complex pair through the unit circle.
    NeimarkSacker,
    /// Grazing: the number of switchings per cycle changes.
    Grazing,
}

impl BranchEvent {
    /// Its name in every output (JSON, CSV, Python): `fold`, `period-doubling`,
    /// `neimark-sacker`, `grazing`.
    pub fn name(self) -> &'static str {
        match self {
            BranchEvent::Fold => "fold",
            BranchEvent::PeriodDoubling => "period-doubling",
            BranchEvent::NeimarkSacker => "neimark-sacker",
            BranchEvent::Grazing => "grazing",
        }
    }
}

/// One point of a branch.
#[derive(Debug, Clone, PartialEq)]
pub struct BranchPoint {
    /// Arclength.
    pub s: f64,
    /// Parameter value.
    pub value: f64,
    /// Period n.
    pub period: usize,
    /// States at the n section points (τ = kT).
    pub section: Vec<DVector<f64>>,
    /// Floquet multipliers, decreasing modulus.
    pub multipliers: Vec<Complex<f64>>,
    /// Stable.
    pub stable: bool,
    /// Type of the critical multiplier.
    pub critical: Instability,
    /// Switchings per cycle.
    pub switchings: usize,
    /// Distance to grazing.
    pub grazing_distance: f64,
    /// Label when this point locates a bifurcation.
    pub event: Option<BranchEvent>,
}

/// Continue the period-n branch through the orbit found by shooting from `guess` at `from`.
/// Points are returned in arclength order; located bifurcations carry their label.
///
/// It counts every branch point in `progress` (a branch's length is not known ahead: the total
/// is left as it is) and stops when it is cancelled.
///
/// # Errors
/// [`SimError`] when the first orbit cannot be found or the parameters are invalid;
/// [`SimError::Cancelled`] once `progress` is cancelled.
pub fn continue_branch(
    spec: &ContinuationSpec,
    guess: &DVector<f64>,
    progress: &Progress,
) -> Result<Branch, SimError> {
    spec.base.with(spec.param, spec.from).validate()?;
    spec.base.with(spec.param, spec.to).validate()?;
    let mut solver = Solver::new(spec)?;
    let orbit = shoot(
        &mut StroboscopicMap::new(solver.at(spec.from)?, 1),
        guess,
        &spec.newton.with_period(spec.period),
    )?;
    let (mut y, mut t, map) = start(&mut solver, &orbit.state)?;
    let dim = orbit.state.len();
    let (lo, hi) = spec
        .range
        .unwrap_or((spec.from.min(spec.to), spec.from.max(spec.to)));
    let mut s = 0.0;
    let mut ds = spec.ds;
    let mut out = vec![point(&mut solver, s, &y, &map)?];
    let mut tf = tests(&t, &map.jacobian, &out[0].multipliers, map.switchings);
    let mut mu_prev = out[0].multipliers.clone();
    let mut widest = 0.0f64;
    let first = y.clone();
    progress.tick();
    let end = loop {
        if out.len() >= spec.max_points {
            break BranchEnd::MaxPoints { value: y[dim] };
        }
        progress.check()?;
        let steps = solver.work();
        if steps > spec.max_work {
            break BranchEnd::Budget {
                value: y[dim],
                steps,
            };
        }
        let y_pred = &y + &t * ds;
        let (y_new, map_new, iters, fp_new) = match solver.correct(&y_pred, &t) {
            Ok(r) => r,
            Err(_) => {
                ds *= 0.5;
                if ds < spec.ds_min {
                    break BranchEnd::StepFloor { value: y[dim] };
                }
                continue;
            }
        };
        let t_new = Solver::tangent(&map_new.jacobian, &fp_new, &t)?;
        let mut pt = point(&mut solver, s + ds, &y_new, &map_new)?;
        let mu = &pt.multipliers;
        let tf_new = tests(&t_new, &map_new.jacobian, mu, map_new.switchings);
        // step control on the multipliers: a step may not move any multiplier by more than
        // MAX_MULTIPLIER_STEP, nor change the number of unstable multipliers without a located
        // event — else two crossings (of −1, say) could cancel in the test functions
        let event = changed(&tf, &tf_new);
        let unstable = |mu: &[Complex<f64>]| mu.iter().filter(|m| m.norm() > 1.0).count();
        if (multiplier_shift(&mu_prev, mu) > MAX_MULTIPLIER_STEP
            || (event.is_none() && unstable(&mu_prev) != unstable(mu)))
            && ds > 16.0 * spec.ds_min
        {
            ds *= 0.5;
            continue;
        }
        if let Some(ev) = event {
            let best = locate(&mut solver, ev, (s, ds), (&y, &t), &tf, &tf_new)?;
            // a genuine fold has a multiplier +1; a sign change of dp/ds without one is the
            // tangent flipping across a non-smooth (grazing) point: retry with a smaller step
            let spurious_fold = ev == BranchEvent::Fold
                && best
                    .as_ref()
                    .is_none_or(|bp| bp.multipliers.iter().all(|m| (m - 1.0).norm() > 1e-2));
            if spurious_fold && ds > 16.0 * spec.ds_min {
                ds *= 0.25;
                continue;
            }
            if let Some(bp) = best.filter(|bp| !located_again(&out, bp)) {
                out.push(bp);
                progress.tick();
            }
        }
        if !(lo..=hi).contains(&y_new[dim]) {
            break BranchEnd::Range;
        }
        // stop when the branch closes on itself (an isola back at its first point), or when a
        // period-2n branch has merged into a period-n orbit (its half-cycle repeats): beyond that
        // it would trace the period-n branch again
        let closed = out.len() > 10 && chord_passes(&y, &y_new, &first);
        let merged = merges(spec, &mut out, &pt, &mut widest);
        s += ds;
        pt.s = s;
        out.push(pt);
        progress.tick();
        if closed {
            break BranchEnd::Closed;
        }
        if merged {
            break BranchEnd::Merged;
        }
        mu_prev = out.last().expect("a point").multipliers.clone();
        y = y_new;
        t = t_new;
        tf = tf_new;
        ds = if iters <= 2 {
            (ds * 1.5).min(spec.ds_max)
        } else if iters >= 5 {
            ds * 0.5
        } else {
            ds
        };
    };
    Ok(Branch { points: out, end })
}

/// The start of a branch at the orbit `state` at `spec.from`: y = (z, p), the unit tangent
/// towards `spec.to`, and the map there.
///
/// # Errors
/// As [`Solver::map`], [`Solver::dp_of`] and [`Solver::tangent`].
fn start(
    solver: &mut Solver,
    state: &DVector<f64>,
) -> Result<(DVector<f64>, DVector<f64>, FlowMap), SimError> {
    let (from, to) = (solver.spec.from, solver.spec.to);
    let dim = state.len();
    let mut y = DVector::zeros(dim + 1);
    y.rows_mut(0, dim).copy_from(state);
    y[dim] = from;
    let dir = if to >= from { 1.0 } else { -1.0 };
    let mut t0 = DVector::zeros(dim + 1);
    t0[dim] = dir;
    let map = solver.map(state, from, true)?;
    let fp0 = solver.dp_of(&map, state, from)?;
    let mut t = Solver::tangent(&map.jacobian, &fp0, &t0)?;
    if t[dim] * dir < 0.0 {
        t = -t;
    }
    Ok((y, t, map))
}

/// Whether the event point `bp` is the last event of `out` located again, within the
/// resolution of the location (next to a junction the test function can change sign twice
/// within 1e-4).
fn located_again(out: &[BranchPoint], bp: &BranchPoint) -> bool {
    out.iter()
        .rev()
        .find(|b| b.event.is_some())
        .is_some_and(|b| {
            b.event == bp.event && (b.value - bp.value).abs() < 1e-4 * (1.0 + b.value.abs())
        })
}

/// Whether a period-2n branch has merged into its period-n parent at the new point `pt`
/// after the points `out`: its half-cycle repeats, or the last point is the pitchfork junction
/// with the parent (then labelled its period doubling). `widest` is the widest half-cycle gap
/// met so far.
fn merges(
    spec: &ContinuationSpec,
    out: &mut [BranchPoint],
    pt: &BranchPoint,
    widest: &mut f64,
) -> bool {
    let half = spec.period / 2;
    let half_gap =
        |b: &BranchPoint| (&b.section[half] - &b.section[0]).norm() / (1.0 + b.section[0].norm());
    // a fold at a parent's period doubling where the half-cycle nearly repeats is the tip of
    // the pitchfork at which the period-2n branch meets its parent (the gap closes like
    // √|Δp|): beyond it the branch is its own phase-shifted copy
    *widest = widest.max(half_gap(pt));
    let at_parent = out.last().is_some_and(|b| {
        b.event == Some(BranchEvent::Fold)
            && half_gap(b) < 0.05 * *widest
            && spec
                .junctions
                .iter()
                .any(|j| (j - b.value).abs() <= 1e-4 * (1.0 + j.abs()))
    });
    let merged =
        spec.period.is_multiple_of(2) && out.len() > 3 && (half_gap(pt) < 1e-6 || at_parent);
    if merged && at_parent {
        // the junction is the parent's period doubling, seen from the period-2n branch; a
        // period doubling located within 1e-4 before it is the same point
        let k = out.len() - 1;
        let at = out[k].value;
        out[k].event = Some(BranchEvent::PeriodDoubling);
        for b in out[..k].iter_mut().rev().take(4) {
            if b.event == Some(BranchEvent::PeriodDoubling)
                && (b.value - at).abs() < 1e-4 * (1.0 + at.abs())
            {
                b.event = None;
            }
        }
    }
    merged
}

#[cfg(test)]
mod tests {
    use super::events::{chord_passes, Bracket};
    use nalgebra::DVector;

    /// Shrink a bracket of [0, w] on f to `tol` as the continuation does; the evaluations and
    /// the final bracket.
    fn locate(f: impl Fn(f64) -> f64, w: f64, secant: bool, tol: f64) -> (usize, f64, f64) {
        let mut br = Bracket::new(w, f(0.0), f(w), secant);
        let mut evals = 0;
        while br.width() > tol && evals < 200 {
            let x = br.next();
            assert!(x > br.a && x < br.b, "{x} outside ({}, {})", br.a, br.b);
            br.update(x, f(x));
            evals += 1;
        }
        (evals, br.a, br.b)
    }

    /// The Illinois bracket holds the root of a smooth function, cos s − 0.3 on [0, 2] (root
    /// acos 0.3), and a fold-like quadratic zero-crossing t_p ∝ s* − s, within 1e-7 in far
    /// fewer evaluations than the 25 of bisection; on a jump (the sign change of dp/ds at a
    /// non-smooth point) it needs at most twice bisection's.
    #[test]
    fn the_illinois_bracket_converges_and_keeps_the_root() {
        let root = 0.3f64.acos();
        let (n, a, b) = locate(|s| s.cos() - 0.3, 2.0, true, 1e-7);
        assert!(a <= root && root <= b, "[{a}, {b}] misses {root}");
        assert!(n <= 10, "{n} evaluations");
        let (n, a, b) = locate(|s| (0.731 - s) * (1.0 + s * s), 1.0, true, 1e-7);
        assert!(a <= 0.731 && 0.731 <= b, "[{a}, {b}]");
        assert!(n <= 10, "{n} evaluations");
        let (bisect, _, _) = locate(|s| if s < 0.3 { 1.0 } else { -1.0 }, 2.0, false, 1e-7);
        let (n, a, b) = locate(|s| if s < 0.3 { 1.0 } else { -1.0 }, 2.0, true, 1e-7);
        assert!(a < 0.3 && 0.3 <= b, "[{a}, {b}]");
        assert!(n <= 2 * bisect, "{n} evaluations, bisection {bisect}");
    }

    /// The isola's first point at the origin, the last two steps of the loop ending 0.4 before
    /// it (a step of 0.5) and 0.6 after it (a step of 1): each end is more than half its own
    /// step away, the chord passes through it. A chord that passes 0.6 step lengths away, or
    /// whose ends both lie on one side beyond it, does not close.
    #[test]
    fn closure_on_the_chord() {
        let v = |x: f64, y: f64| DVector::from_vec(vec![x, y]);
        let first = v(0.0, 0.0);
        assert!(chord_passes(&v(-0.4, 0.0), &v(0.6, 0.0), &first));
        assert!(!chord_passes(&v(-0.4, 0.6), &v(0.6, 0.6), &first));
        assert!(!chord_passes(&v(0.6, 0.0), &v(1.6, 0.0), &first));
    }
}
