//! Operating points at an amplitude setpoint (issue 28): where an approach curve's amplitude
//! ratio A/A₀ equals the setpoint A_sp/A₀ that an instrument's feedback holds while it images.
//! On every stable stretch of every continued branch (or, without branches, of the approach and
//! retract sweeps) each crossing of the setpoint is first located by linear interpolation
//! between the two curve points around it (`setpoint_crossings`). Between two periodic
//! orbits, the crossing is then the exact orbit whose A/A₀ is the setpoint (`operating_points`:
//! regula falsi with the Illinois modification on the swept value, each value's orbit found by
//! shooting from the state interpolated between the bracket's orbits), and its observables —
//! phase, peak force, indentation, minimum distance, dissipated energy: the quantities of a
//! phase image — are that orbit's: interpolated observables of two orbits mix a free and a
//! touching cycle, or two orbits across a gap of the curve (issue 77: an "attractive" point
//! with a positive minimum distance and an indentation). A crossing whose bracket holds no
//! continuous orbit (the curve jumps there) is no operating point. Between motions measured
//! by their time average (no orbit), the observables stay interpolated ([`Crossing`] gives the
//! two points and the weight). In the bistable range there is one crossing on the attractive
//! and one on the repulsive branch: which one the instrument holds depends on its history
//! (García & San Paulo, Phys. Rev. B 61, R13381 (2000)).

use super::am_loop::LOCK_IN_SAMPLES;
use super::lock_in_noise::{lock_in_noise, LockInNoise};
use super::observables::{observe, ObservableOptions, Observables};
use super::shooting::shoot;
use super::stepped::{SteppedCurve, SteppedSpec, Sweep};
use crate::error::SimError;
use crate::integrate::build;
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use nalgebra::DVector;

/// Which curve a crossing lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// Continued branch k.
    Branch(usize),
    /// A stepped sweep (the approach or the retract).
    Sweep(Sweep),
}

/// A crossing of the setpoint between points `index` and `index + 1` of its curve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// The curve.
    pub source: Source,
    /// The first of the two points around the crossing.
    pub index: usize,
    /// The weight of the second point: a quantity q at the setpoint is
    /// `(1 − t)·q[index] + t·q[index + 1]`.
    pub t: f64,
    /// The swept parameter (α5 for an approach) at the setpoint.
    pub value: f64,
}

/// A point of a curve: (swept value, A/A₀, stable).
type Point = (f64, f64, bool);

fn crossings_of(points: &[Point], source: Source, ratio: f64, out: &mut Vec<Crossing>) {
    for (i, w) in points.windows(2).enumerate() {
        let ((v0, r0, s0), (v1, r1, s1)) = (w[0], w[1]);
        if !(s0 && s1 && r0.is_finite() && r1.is_finite()) || r0 == r1 {
            continue;
        }
        // a crossing in [r0, r1) (half-open, so a point exactly at the setpoint counts once)
        let (lo, hi) = (r0.min(r1), r0.max(r1));
        if ratio >= lo && ratio < hi || (ratio == hi && i + 2 == points.len()) {
            let t = (ratio - r0) / (r1 - r0);
            out.push(Crossing {
                source,
                index: i,
                t,
                value: v0 + t * (v1 - v0),
            });
        }
    }
}

/// Every crossing of A/A₀ = `ratio` on the stable stretches of `curve`'s branches, or of its
/// two sweeps when it has no branches.
pub(crate) fn setpoint_crossings(curve: &SteppedCurve, ratio: f64) -> Vec<Crossing> {
    let ratio_of = |o: &super::observables::Observables| o.amplitude / o.closed_form.free_amplitude;
    let mut out = Vec::new();
    if curve.branches.is_empty() {
        for (sweep, pts) in [(Sweep::First, &curve.first), (Sweep::Second, &curve.second)] {
            let points: Vec<Point> = pts
                .iter()
                .map(|p| (p.value, ratio_of(&p.observables), p.stable))
                .collect();
            crossings_of(&points, Source::Sweep(sweep), ratio, &mut out);
        }
    } else {
        for (k, b) in curve.branches.iter().enumerate() {
            let points: Vec<Point> = b
                .iter()
                .map(|s| (s.point.value, ratio_of(&s.observables), s.point.stable))
                .collect();
            crossings_of(&points, Source::Branch(k), ratio, &mut out);
        }
    }
    out
}

/// An operating point at the setpoint: its crossing (`value` the swept value found) and the
/// observables of the exact orbit there; `None` between two time-averaged motions, whose
/// observables are interpolated by the crossing's weight.
#[derive(Debug, Clone, PartialEq)]
pub struct OperatingPoint {
    /// The crossing; its `value` is the operating point's.
    pub crossing: Crossing,
    /// The observables of the orbit there (`None`: interpolate between the crossing's points).
    pub exact: Option<Observables>,
    /// The lock-in's thermal noise of the period-1 orbit there, with [`SteppedSpec::noise`]
    /// ([`crate::analysis::lock_in_noise`]); `None` otherwise.
    pub noise: Option<LockInNoise>,
}

/// Iterations of the regula falsi on one crossing.
const REFINE_ITERATIONS: usize = 12;
/// |A/A₀ − setpoint| at which a crossing's orbit is accepted.
const REFINE_TOL: f64 = 1e-9;
/// Relative distance in the swept value, phase (rad) and amplitude below which two operating
/// points of one curve are one orbit.
const SAME_ORBIT: f64 = 1e-6;

/// A periodic orbit of the curve at a swept value: (value, state at τ = 0, A/A₀ − setpoint).
type Bracketed = (f64, DVector<f64>, f64);

/// The operating points of `curve` (computed with `spec`) at A/A₀ = `ratio` (module docs):
/// every crossing of [`setpoint_crossings`] between two periodic orbits of one period refined
/// to the exact orbit at the setpoint; a crossing with no continuous orbit across its bracket
/// dropped (returned apart, for the result to say so); a crossing between time-averaged
/// motions interpolated.
///
/// # Errors
/// [`SimError`] from the model of a swept value (the curve's own values are valid).
pub(crate) fn operating_points(
    spec: &SteppedSpec,
    curve: &SteppedCurve,
    ratio: f64,
) -> Result<(Vec<OperatingPoint>, Vec<Crossing>), SimError> {
    let (mut out, mut dropped) = (Vec::new(), Vec::new());
    for k in setpoint_crossings(curve, ratio) {
        let (a, b) = ends(curve, &k);
        match (a.period.zip(a.state), b.period.zip(b.state)) {
            (Some((na, za)), Some((nb, zb))) if na == nb => {
                let lo = (a.value, za.clone(), a.ratio - ratio);
                let hi = (b.value, zb.clone(), b.ratio - ratio);
                let Some((value, o, z)) = refine(spec, na, ratio, lo, hi)? else {
                    dropped.push(k);
                    continue;
                };
                // a branch that passes the same orbit again (its stretches traced twice) gives
                // it once
                let seen = out.iter().any(|p: &OperatingPoint| {
                    p.crossing.source == k.source
                        && (p.crossing.value - value).abs() <= SAME_ORBIT * (1.0 + value.abs())
                        && p.exact.as_ref().is_some_and(|e| {
                            (e.phase - o.phase).abs() <= SAME_ORBIT
                                && (e.amplitude - o.amplitude).abs()
                                    <= SAME_ORBIT * o.amplitude.abs()
                        })
                });
                if !seen {
                    let noise = match spec.noise.filter(|_| na == 1) {
                        Some(n) => Some(lock_in_noise(
                            &CantileverModel::new(&spec.base.with(spec.param, value))?,
                            &z,
                            n.kt,
                            n.time_constant,
                            LOCK_IN_SAMPLES,
                        )?),
                        None => None,
                    };
                    out.push(OperatingPoint {
                        crossing: Crossing { value, ..k },
                        exact: Some(o),
                        noise,
                    });
                }
            }
            _ => out.push(OperatingPoint {
                crossing: k,
                exact: None,
                noise: None,
            }),
        }
    }
    Ok((out, dropped))
}

/// A curve point around a crossing.
struct End<'a> {
    value: f64,
    ratio: f64,
    period: Option<usize>,
    state: Option<&'a DVector<f64>>,
}

/// The two curve points around crossing `k`.
fn ends<'a>(curve: &'a SteppedCurve, k: &Crossing) -> (End<'a>, End<'a>) {
    let ratio = |o: &Observables| o.amplitude / o.closed_form.free_amplitude;
    let at = |i: usize| match k.source {
        Source::Branch(j) => {
            let s = &curve.branches[j][i];
            End {
                value: s.point.value,
                ratio: ratio(&s.observables),
                period: Some(s.point.period),
                state: s.point.section.first(),
            }
        }
        Source::Sweep(w) => {
            let p = match w {
                Sweep::First => &curve.first[i],
                Sweep::Second => &curve.second[i],
            };
            End {
                value: p.value,
                ratio: ratio(&p.observables),
                period: p.period,
                state: Some(&p.state),
            }
        }
    };
    (at(k.index), at(k.index + 1))
}

/// The orbit of period `n` at A/A₀ = `ratio` between the bracket's orbits `lo` and `hi` (their
/// residuals of opposite signs, or one zero): regula falsi with the Illinois modification on
/// the swept value (Dowell & Jarratt, BIT 11, 168 (1971)), each trial orbit shot from the state
/// interpolated between the bracket's and accepted only when it stays within the curve's jump
/// tolerance of that state (a continuous piece of curve): (value, observables, state at τ = 0);
/// `None` where it does not (the curve jumps inside the bracket) or shooting fails.
fn refine(
    spec: &SteppedSpec,
    n: usize,
    ratio: f64,
    mut lo: Bracketed,
    mut hi: Bracketed,
) -> Result<Option<(f64, Observables, DVector<f64>)>, SimError> {
    let opts = ObservableOptions {
        periods: n,
        ..spec.observables
    };
    let mut side = 0i8;
    let mut best: Option<(f64, Observables, f64, DVector<f64>)> = None;
    for _ in 0..REFINE_ITERATIONS {
        let (g_lo, g_hi) = (lo.2, hi.2);
        let t = if g_hi == g_lo {
            0.5
        } else {
            g_lo / (g_lo - g_hi)
        };
        let t = if t.is_finite() {
            t.clamp(0.0, 1.0)
        } else {
            0.5
        };
        let value = lo.0 + t * (hi.0 - lo.0);
        let guess = &lo.1 + (&hi.1 - &lo.1) * t;
        let model = CantileverModel::new(&spec.base.with(spec.param, value))?;
        let mut integ = build(&model, spec.integrator.clone(), 0.0, &guess)?;
        let newton = spec.newton.with_period(n);
        let Ok(o) = shoot(
            &mut StroboscopicMap::new(integ.as_mut(), 1),
            &guess,
            &newton,
        ) else {
            return Ok(None);
        };
        let gap = (&o.state - &guess).norm() / (1.0 + guess.norm());
        if !o.stable || gap > spec.jump_tol {
            return Ok(None);
        }
        integ.set_variational(false);
        integ.reset(0.0, &o.state)?;
        let obs = observe(integ.as_mut(), &opts)?;
        let g = obs.amplitude / obs.closed_form.free_amplitude - ratio;
        if best.as_ref().is_none_or(|b| g.abs() < b.2.abs()) {
            best = Some((value, obs, g, o.state.clone()));
        }
        if g.abs() <= REFINE_TOL {
            break;
        }
        // Illinois: the end kept twice in a row has its residual halved
        if (g < 0.0) == (g_lo < 0.0) {
            lo = (value, o.state, g);
            if side == -1 {
                hi.2 *= 0.5;
            }
            side = -1;
        } else {
            hi = (value, o.state, g);
            if side == 1 {
                lo.2 *= 0.5;
            }
            side = 1;
        }
    }
    Ok(best.map(|(v, o, _, z)| (v, o, z)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossings_are_interpolated_on_stable_segments_only() {
        let pts = [
            (1.0, 1.0, true),
            (0.8, 0.8, true),
            (0.6, 0.6, false),
            (0.4, 0.4, true),
            (0.2, 0.2, true),
        ];
        let mut out = Vec::new();
        crossings_of(&pts, Source::Branch(0), 0.9, &mut out);
        assert_eq!(out.len(), 1);
        assert!((out[0].t - 0.5).abs() < 1e-15 && (out[0].value - 0.9).abs() < 1e-15);
        // 0.7 lies on an unstable segment: none
        out.clear();
        crossings_of(&pts, Source::Branch(0), 0.7, &mut out);
        assert!(out.is_empty());
        // a non-monotone curve crosses twice
        let pts = [(0.0, 0.2, true), (1.0, 0.9, true), (2.0, 0.3, true)];
        out.clear();
        crossings_of(&pts, Source::Branch(1), 0.5, &mut out);
        assert_eq!(out.len(), 2);
        assert_eq!(out[1].index, 1);
    }
}
