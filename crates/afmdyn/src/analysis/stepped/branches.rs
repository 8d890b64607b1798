//! The branches of a stepped sweep: their continuation with observables at every point, the
//! orbits they start from, whether an orbit lies on one, the bistable stretches between folds
//! and the jumps of a sweep. Shapes, units and sources as in [`super`].

use super::{
    map_at, measure, relative_gap, BranchSample, CurvePoint, Jump, Reached, SteppedSpec, Sweep,
};
use crate::analysis::continuation::{
    continue_branch, Branch, BranchEnd, BranchEvent, ContinuationSpec,
};
use crate::analysis::progress::Progress;
use crate::analysis::shooting::shoot;
use crate::error::SimError;
use nalgebra::{Complex, DVector};

/// Continue the branch through `from` (a stable orbit of a sweep) towards `to`, with
/// observables at every point.
pub(super) fn branch(
    spec: &SteppedSpec,
    from: &CurvePoint,
    to: f64,
    progress: &Progress,
) -> Result<(Vec<BranchSample>, BranchEnd), SimError> {
    let n = from.period.ok_or(SimError::out_of_range(
        "branch start",
        from.value,
        "the motion there is not period-n: no branch to continue",
    ))?;
    let (lo, hi) = spec
        .values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    let mut cs = ContinuationSpec::new(spec.base, spec.param, from.value, to, n);
    cs.integrator = spec.integrator.clone();
    cs.max_points = spec.max_branch_points;
    cs.range = Some((lo, hi));
    // arclength runs in (z, p): scale the steps by the larger of the range and the orbit
    let scale = (hi - lo).max(from.state.norm());
    cs.ds = scale / 100.0;
    cs.ds_max = scale / 25.0;
    // the branch's points were counted as they came; its length is known only now
    let Branch { points, end } = continue_branch(&cs, &from.state, progress)?;
    progress.add_total(points.len());
    let mut out = Vec::with_capacity(points.len());
    for p in points {
        progress.check()?;
        let mut map = map_at(spec, p.value, &p.section[0])?;
        let observables = measure(map.integrator(), &p.section[0], p.period, &spec.observables)?;
        out.push(BranchSample {
            point: p,
            observables,
        });
    }
    Ok((out, end))
}

/// Whether the orbit `z` at `value` lies on the branch: within 1e-2 (relative) of the branch's
/// section state interpolated linearly between the two branch points around `value` (or
/// extrapolated by up to one segment beyond the branch's ends).
pub(super) fn on_branch(br: &[BranchSample], value: f64, z: &DVector<f64>) -> bool {
    let last = br.len().saturating_sub(2);
    br.windows(2).enumerate().any(|(i, w)| {
        let (a, b) = (&w[0].point, &w[1].point);
        if b.value == a.value {
            return false;
        }
        // inside the segment, or up to one segment beyond an end of the branch (which stops
        // at its last point inside the range)
        let t = (value - a.value) / (b.value - a.value);
        let (t_lo, t_hi) = (
            if i == 0 { -1.0 } else { 0.0 },
            if i == last { 2.0 } else { 1.0 },
        );
        if !(t_lo..=t_hi).contains(&t) {
            return false;
        }
        let zi = &a.section[0] + (&b.section[0] - &a.section[0]) * t;
        relative_gap(&zi, z) < 1e-2
    })
}

/// Orbits to continue branches from: the two sweeps' first points (both ends of the range) and,
/// at each end, the orbit Newton finds from the other end's orbit (a state of the other
/// regime, e.g. the free oscillation of the far end started near the sample), when it differs
/// from the sweep's.
pub(super) fn branch_starts(
    spec: &SteppedSpec,
    first: &[CurvePoint],
    second: &[CurvePoint],
) -> Vec<CurvePoint> {
    let (a, b) = (&first[0], &second[0]);
    let mut starts = vec![a.clone(), b.clone()];
    for (at, from) in [(b, a), (a, b)] {
        let (Some(n), Some(_)) = (from.period, at.period) else {
            continue;
        };
        let Ok(map) = &mut map_at(spec, at.value, &from.state) else {
            continue;
        };
        let Ok(o) = shoot(map, &from.state, &spec.newton.with_period(n)) else {
            continue;
        };
        if relative_gap(&o.state, &at.state) < 1e-3 {
            continue;
        }
        let periods = n;
        let Ok(observables) = measure(map.integrator(), &o.state, periods, &spec.observables)
        else {
            continue;
        };
        starts.push(CurvePoint {
            value: at.value,
            period: Some(n),
            state: o.state,
            stable: o.stable,
            multipliers: o.multipliers,
            monodromy: Some(o.monodromy),
            reached: Reached::Start,
            observables,
            tau: 0.0,
            average: None,
            circle: None,
            fallback: None,
            free_decay_wait: false,
        });
    }
    starts
}

/// The parameter ranges of the unstable stretches of a branch that run from a fold to a fold:
/// where the branch folds back over itself (an S), three orbits coexist, two of them stable.
pub(super) fn unstable_between_folds(br: &[BranchSample]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut start: Option<usize> = None;
    for (i, s) in br.iter().enumerate() {
        if s.point.event == Some(BranchEvent::Fold) {
            if let Some(a) = start {
                // a fold closing an unstable stretch opened at a fold
                let run = &br[a..=i];
                if run[1..run.len() - 1].iter().all(|x| !x.point.stable) && run.len() > 2 {
                    let (lo, hi) = run
                        .iter()
                        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| {
                            (l.min(x.point.value), h.max(x.point.value))
                        });
                    out.push((lo, hi));
                }
            }
            start = Some(i);
        } else if s.point.stable && start.is_some_and(|a| i > a) {
            start = None;
        }
    }
    out
}

/// How far apart two successive points of a sweep are: their states' relative gap, or for
/// time-averaged points (whose states are at different τ) the largest change of a component's
/// phasor A_i e^{iφ_i} relative to its free amplitude.
fn point_gap(a: &CurvePoint, b: &CurvePoint) -> f64 {
    if a.average.is_none() || b.average.is_none() {
        return relative_gap(&b.state, &a.state);
    }
    a.observables
        .components
        .iter()
        .zip(&b.observables.components)
        .map(|(x, y)| {
            let d = Complex::from_polar(x.amplitude, x.phase)
                - Complex::from_polar(y.amplitude, y.phase);
            d.norm() / x.free_amplitude
        })
        .fold(0.0, f64::max)
}

/// Jumps of one sweep: points reached by settling on an orbit away from the previous one.
pub(super) fn jumps_of(
    which: Sweep,
    points: &[CurvePoint],
    folds: &[f64],
    jump_tol: f64,
) -> Vec<Jump> {
    let mut out = Vec::new();
    let gaps: Vec<f64> = (1..points.len())
        .map(|i| point_gap(&points[i - 1], &points[i]))
        .collect();
    for i in 1..points.len() {
        let (a, b) = (&points[i - 1], &points[i]);
        let gap = gaps[i - 1];
        if !b.reached.by_transient() || gap <= jump_tol {
            continue;
        }
        // every time-averaged point is reached by settling: a jump is a step that stands out
        // from its neighbours' (the motion's smooth change over one grid step is not; a sweep
        // of two points has no neighbour to tell them apart)
        if b.average.is_some() {
            let next = gaps.get(i).copied();
            let before = (i >= 2).then(|| gaps[i - 2]);
            let neighbour = next
                .into_iter()
                .chain(before)
                .fold(None, |m: Option<f64>, g| Some(m.map_or(g, |m| m.max(g))));
            if neighbour.is_none_or(|n| gap <= 2.0 * n) {
                continue;
            }
        }
        let step = (b.value - a.value).abs();
        let (lo, hi) = (a.value.min(b.value) - step, a.value.max(b.value) + step);
        let mid = 0.5 * (a.value + b.value);
        let fold = folds
            .iter()
            .copied()
            .filter(|f| (lo..=hi).contains(f))
            .min_by(|x, y| (x - mid).abs().total_cmp(&(y - mid).abs()));
        out.push(Jump {
            sweep: which,
            index: i,
            from: a.value,
            to: b.value,
            fold,
        });
    }
    out
}
