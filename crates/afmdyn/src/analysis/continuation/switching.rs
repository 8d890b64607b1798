//! Branch switching at a period doubling: the starts of the period-2n branches born there and
//! the continuation of the whole period-doubling cascade ([`continue_with_switching`]).
//! Shapes, units and sources as in [`super`].

use super::{continue_branch, Branch, BranchEvent, BranchPoint, ContinuationSpec};
use crate::analysis::progress::Progress;
use crate::analysis::shooting::shoot;
use crate::error::SimError;
use crate::maps::{DiscreteMap, StroboscopicMap};
use crate::model::CantileverModel;
use nalgebra::{DMatrix, DVector};

/// Start of the period-2n branch at a located period-doubling point: shoot a period-2n orbit
/// from the point displaced along the eigenvector of the multiplier nearest −1, at parameter
/// values on either side. Returns (parameter, period-2n orbit state) for the first orbit found
/// that is not the period-n orbit itself ([`period_doubling_starts`] gives one per side).
pub fn switch_at_period_doubling(
    spec: &ContinuationSpec,
    pd: &BranchPoint,
) -> Option<(f64, DVector<f64>)> {
    period_doubling_starts(spec, pd).into_iter().next()
}

/// Starts of period-2n branches at a period doubling, at most one on each side of the
/// parameter (the side the continuation goes to first). In a non-smooth system both sides can
/// carry a period-2n orbit (e.g. a branch bounded by a grazing-induced fold).
pub fn period_doubling_starts(
    spec: &ContinuationSpec,
    pd: &BranchPoint,
) -> Vec<(f64, DVector<f64>)> {
    let z = pd.section[0].clone();
    let dim = z.len();
    let Some(v) = (|| {
        let model = CantileverModel::new(&spec.base.with(spec.param, pd.value)).ok()?;
        let m = StroboscopicMap::build(&model, spec.integrator.clone(), &model.rest(), pd.period)
            .ok()?
            .apply(&z)
            .ok()?
            .jacobian;
        // eigenvector of μ ≈ −1 by inverse iteration on M + (1 − 1e-8) I
        let lu = (&m + DMatrix::identity(dim, dim) * (1.0 - 1e-8)).lu();
        let mut v = DVector::from_element(dim, 1.0);
        for _ in 0..4 {
            v = lu.solve(&v)?.normalize();
        }
        Some(v)
    })() else {
        return Vec::new();
    };
    // the period-2n orbit bifurcates like √|Δp|: try a few parameter offsets, each with a
    // displacement of the matching size, and both signs of the eigenvector (deep in a cascade
    // the windows are narrow: the smallest offsets first)
    let ahead = if spec.to >= spec.from { 1.0 } else { -1.0 };
    let mut starts = Vec::new();
    for sign_p in [ahead, -ahead] {
        'side: for (rel, k) in [(1e-4, 3.0), (1e-3, 1.0), (1e-3, 3.0), (1e-2, 3.0)] {
            let dp = rel * pd.value.abs().max(1.0);
            let eps = k * f64::sqrt(rel) * (1.0 + z.norm());
            let p = pd.value + sign_p * dp;
            let Ok(model) = CantileverModel::new(&spec.base.with(spec.param, p)) else {
                continue;
            };
            let rest = model.rest();
            let Ok(map) = &mut StroboscopicMap::build(&model, spec.integrator.clone(), &rest, 1)
            else {
                continue;
            };
            for sign_v in [1.0, -1.0] {
                let guess = &z + &v * (sign_v * eps);
                let Ok(o) = shoot(map, &guess, &spec.newton.with_period(2 * pd.period)) else {
                    continue;
                };
                // the map of n periods, as one flow over them
                let Ok(half) = map.linearise(&o.state, pd.period, true) else {
                    continue;
                };
                if (&half.state - &o.state).norm() > 1e-6 * (1.0 + o.state.norm()) {
                    starts.push((p, o.state));
                    break 'side;
                }
            }
        }
    }
    starts
}

/// Continue the branch of `spec` from `guess` and, recursively, the period-2n branches born at
/// its period doublings ([`switch_at_period_doubling`]) up to period `max_period`: the
/// period-doubling cascade. A branch reached again from the other end of its window (same
/// bifurcations at the same parameter values) is kept once. Returns the branches, the first
/// being the one of `spec`.
///
/// It counts every branch point in `progress` and stops when it is cancelled.
///
/// # Errors
/// As [`super::continue_branch`] for the first branch; a sub-branch that fails is skipped;
/// [`SimError::Cancelled`] once `progress` is cancelled (also inside a sub-branch, whose other
/// failures are skipped).
pub fn continue_with_switching(
    spec: &ContinuationSpec,
    guess: &DVector<f64>,
    max_period: usize,
    progress: &Progress,
) -> Result<Vec<Branch>, SimError> {
    let mut branches = vec![continue_branch(spec, guess, progress)?];
    let mut next = 0;
    while next < branches.len() {
        let pds: Vec<BranchPoint> = branches[next]
            .iter()
            .filter(|b| b.event == Some(BranchEvent::PeriodDoubling))
            .cloned()
            .collect();
        next += 1;
        for pd in pds {
            // a period-2n branch born here needs a multiplier at −1 (not the +1 of a junction
            // with the parent branch)
            let flips = pd.multipliers.iter().any(|m| (m + 1.0).norm() < 0.05);
            if 2 * pd.period > max_period || !flips {
                continue;
            }
            for (value, z) in period_doubling_starts(spec, &pd) {
                // the two period doublings that bound a window start the same period-2n branch
                let known = branches.iter().flatten().any(|b| {
                    b.period == 2 * pd.period
                        && (b.value - value).abs() < 1e-2
                        && b.section
                            .iter()
                            .any(|q| (q - &z).norm() < 1e-3 * (1.0 + z.norm()))
                });
                if known {
                    continue;
                }
                let parent = &branches[next - 1];
                // leave the junction: towards `to` on that side, else away from it, within the
                // whole range
                let (lo, hi) = spec
                    .range
                    .unwrap_or((spec.from.min(spec.to), spec.from.max(spec.to)));
                let away = if value >= pd.value { hi } else { lo };
                let sub = ContinuationSpec {
                    from: value,
                    to: away,
                    range: Some((lo, hi)),
                    period: 2 * pd.period,
                    junctions: parent
                        .iter()
                        .filter(|b| b.event == Some(BranchEvent::PeriodDoubling))
                        .map(|b| b.value)
                        .collect(),
                    ..spec.clone()
                };
                let b = match continue_branch(&sub, &z, progress) {
                    Ok(b) => b,
                    Err(SimError::Cancelled) => return Err(SimError::Cancelled),
                    Err(_) => continue,
                };
                let marks = |br: &[BranchPoint]| -> Vec<(BranchEvent, f64)> {
                    br.iter()
                        .filter_map(|x| x.event.map(|e| (e, x.value)))
                        .collect()
                };
                let new = marks(&b);
                let duplicate = branches.iter().any(|old| {
                    let old = marks(old);
                    !new.is_empty()
                        && new.iter().all(|(e, v)| {
                            old.iter().any(|(oe, ov)| oe == e && (ov - v).abs() < 1e-6)
                        })
                });
                if !duplicate {
                    branches.push(b);
                }
            }
        }
    }
    // a bifurcation reached from both ends of a window is located on two branches of the same
    // period: keep the first
    let mut seen: Vec<(BranchEvent, usize, f64)> = Vec::new();
    for b in branches.iter_mut().flatten() {
        let Some(e) = b.event else { continue };
        let tol = 1e-4 * (1.0 + b.value.abs());
        if seen
            .iter()
            .any(|&(se, sp, sv)| se == e && sp == b.period && (sv - b.value).abs() < tol)
        {
            b.event = None;
        } else {
            seen.push((e, b.period, b.value));
        }
    }
    Ok(branches)
}
