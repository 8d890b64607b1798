//! One point of a stepped sweep: the transient settled from the previous value's state
//! ([`settle`]), the orbit continued by a predicted Newton solve with substeps where it fails,
//! and the trend of the branch the predictor follows (module docs of [`super`]).

use super::contraction::{ContractionWait, Spread};
use super::*;
use crate::analysis::observables::observe_tapered;
use crate::analysis::settle::minimal_period;
use crate::analysis::shooting::floquet_stability;
use crate::analysis::steady::ReturnHistory;
use crate::integrate::advance;
use crate::maps::DiscreteMap;

/// Relative tolerance of a point settled by its time average ([`settle`]): two successive
/// windows' phasors A e^{iφ} and mean deflections differ by at most this fraction of the
/// window's amplitude A. On the JKR sample of issue 60 (40 N/m, Q = 400, E_s = 100 MPa,
/// W = 0.05 J/m²) the irregular tapping's approach and retract amplitudes differ by up to
/// 1e-4 A₀ after 20 000 periods, and windows of 64 periods fluctuate about as much: 1e-5 was
/// not reached within the cap, 1e-3 (an amplitude to 0.1 %, what a lock-in resolves) is.
pub const AVERAGE_TOL: f64 = 1e-3;

/// Successive agreements of the windows ([`AVERAGE_TOL`]) that settle a point by its time
/// average: two, so that one chance agreement of a slow beat does not.
pub const AVERAGE_AGREEMENTS: usize = 2;

/// Fewest drive periods in a window of [`settle`]'s time average; at most
/// `super::average::MAX_DEFAULT_WINDOW`.
pub const AVERAGE_MIN_WINDOW: usize = 16;

/// What [`settle`] reached.
#[derive(Debug, Clone, PartialEq)]
pub struct Settled {
    /// The orbit (period n), or for a motion without a period n ≤ `spec.steady.max_period`
    /// (`period` `None`) the state where it was left, at τ ≡ 0 (mod T).
    pub found: Found,
    /// The observables of the last window of a motion settled by its time average (no short
    /// period found, its windows' averages agreeing to [`AVERAGE_TOL`]); `None` for an orbit
    /// or a motion that did not settle within the cap.
    pub averaged: Option<Observables>,
    /// The motion was settled by its time average only at the end of the free decay's wait,
    /// which runs of returns whose contraction could not be measured kept where its windows
    /// had agreed earlier (`super::contraction`): right, only slower.
    pub free_decay_wait: bool,
}

/// Periods per window of [`settle`]'s time average on `system`: half the slowest free mode's
/// decay time 1/λ in drive periods (so the transient changes between windows by e^{−1/2}; at
/// Q = 400, 64 periods), within [[`AVERAGE_MIN_WINDOW`], [`super::average::MAX_DEFAULT_WINDOW`]]
/// (the floor without a decay rate).
fn average_window(system: &dyn TipSampleSystem) -> usize {
    let periods = system
        .free_decay_rate()
        .map_or(0.0, |l| 0.5 / (l * system.period()));
    if periods.is_finite() {
        (periods.ceil() as usize).clamp(AVERAGE_MIN_WINDOW, super::average::MAX_DEFAULT_WINDOW)
    } else {
        AVERAGE_MIN_WINDOW
    }
}

/// Integrate from `z0` (τ = 0) at the integrator's parameters until the motion settles:
/// Newton shooting for a period-`n` orbit from the transient every `spec.chunk_periods`
/// periods, for at most `NEWTON_CHUNKS` chunks, until the trajectory is seen to go to a
/// stable orbit (`newton_from_transient`); otherwise, over the periods of the point's
/// `transient_cap` not yet spent, in windows (half the slowest free decay time, at least
/// [`AVERAGE_MIN_WINDOW`] periods) of the stroboscopic
/// returns' period test (`spec.steady`: a period-m orbit, polished by Newton; each run of
/// returns at least 4 `max_period` + 2 periods, to confirm any period) alternating with
/// windows of the motion's time average (`observe_tapered`, the Hann² window), whichever
/// decides first: the motion is settled by its time average once [`AVERAGE_AGREEMENTS`]
/// successive windows' phasors A e^{iφ} and mean deflections agree to [`AVERAGE_TOL`] of A (as
/// the time average of a multifrequency drive settles, [`super::average`]), and not before
/// the slowest free mode has decayed by the period test's tolerance (`decay_periods`: an
/// orbit whose transient decays as fast has shown its period by then) — unless the returns'
/// measured contraction ends that wait earlier (`spec.settle_wait`, [`SettleWait`]): in
/// [`STALLED_RUNS`] successive runs no lag m ≤ `max_period` of the returns' differences
/// contracted fast enough to reach the period test's tolerance before the free decay's wait
/// ends (a geometric projection from the ratio between runs, `super::contraction`). A
/// tapping orbit
/// whose returns spiral in too slowly for a short period to show (JKR's neck: its period test
/// ran to the cap of 20 000 periods) is so settled in a few hundred. A motion that neither
/// repeats nor averages out within the cap is left nonperiodic.
///
/// # Errors
/// [`SimError`] from the integrator.
pub fn settle(
    integ: &mut dyn Integrator,
    z0: &DVector<f64>,
    n: usize,
    spec: &SteppedSpec,
) -> Result<Settled, SimError> {
    let cap = transient_cap(integ.system(), spec);
    let chunk = spec.chunk_periods.max(1);
    let opts = SettleOptions {
        newton: spec.newton,
        chunk_periods: chunk,
        max_period: spec.steady.max_period,
        max_wait: usize::MAX,
        settled: SETTLED,
        linear: true,
    };
    let budget = cap.min(NEWTON_CHUNKS * chunk);
    let s = newton_from_transient(integ, z0, Some(n), &opts, budget, &mut |_| false)?;
    if let Some(found) = s.found {
        return Ok(Settled {
            found,
            averaged: None,
            free_decay_wait: false,
        });
    }
    // no settling on a period-n orbit: the returns' test and the time average
    integ.set_variational(false);
    let period = integ.system().period();
    let w = average_window(integ.system());
    // each run of returns long enough to confirm any period ≤ max_period (detected over 2n
    // returns, confirmed over 2n more), and no average before the free decay to the period
    // test's tolerance: an orbit whose transient decays as fast shows its period as before
    let run = w.max(4 * spec.steady.max_period + 2);
    let least = decay_periods(integ.system(), spec.steady.tol).map_or(0.0, f64::ceil) as usize;
    let window = ObservableOptions {
        periods: w,
        harmonics: spec.observables.harmonics,
    };
    let mut z = s.state;
    let mut spent = s.periods;
    let mut last: Option<(Complex<f64>, f64)> = None;
    let mut agreed = 0;
    // the runs' measured contraction (module docs of `contraction`)
    let mut wait = ContractionWait::default();
    while spent < cap {
        integ.reset(0.0, &z)?;
        let mut returns = ReturnHistory::new(&spec.steady, &z);
        let mut spread = Spread::new(spec.steady.max_period, &z);
        for k in 1..=run.min(cap - spent) {
            advance(integ, k as f64 * period)?;
            spread.push(integ.state());
            let Some(m) = returns.push(integ.state(), &spec.steady) else {
                continue;
            };
            let (tau, here) = (integ.tau(), integ.state().clone());
            let map = &mut StroboscopicMap::new(integ, 1);
            if let Ok(o) = shoot(map, &here, &spec.newton.with_period(m)) {
                if o.stable {
                    return Ok(Settled {
                        found: Found {
                            period: Some(m),
                            state: o.state,
                            multipliers: o.multipliers,
                            monodromy: Some(o.monodromy),
                            stable: true,
                        },
                        averaged: None,
                        free_decay_wait: false,
                    });
                }
            }
            // not a stable orbit there: the window goes on from the return
            integ.set_variational(false);
            integ.reset(tau, &here)?;
            returns = ReturnHistory::new(&spec.steady, &here);
        }
        spent += run;
        if spent >= cap {
            z = integ.state().clone();
            break;
        }
        let measure = spec.settle_wait == SettleWait::Contraction;
        let left = least.saturating_sub(spent) as f64;
        // D: from the last run's start to this one's
        let d = (run + w) as f64;
        wait.run(spread.spreads().to_vec(), measure, d, spec.steady.tol, left);
        let o = observe_tapered(integ, &window)?;
        spent += w;
        // the drive is periodic: the window's end is the state at τ ≡ 0
        z = integ.state().clone();
        let now = (Complex::from_polar(o.amplitude, o.phase), o.mean_deflection);
        if let Some((p, d)) = last {
            let close = (now.0 - p).norm().max((now.1 - d).abs()) <= AVERAGE_TOL * o.amplitude;
            agreed = if close { agreed + 1 } else { 0 };
            if agreed >= AVERAGE_AGREEMENTS {
                if spent >= least || wait.over() {
                    return Ok(Settled {
                        found: nonperiodic(z),
                        averaged: Some(o),
                        free_decay_wait: wait.held(),
                    });
                }
                wait.agreed();
            }
        }
        last = Some(now);
    }
    Ok(Settled {
        found: nonperiodic(z),
        averaged: None,
        free_decay_wait: false,
    })
}

/// A motion without a period n, left at `state` (τ ≡ 0).
fn nonperiodic(state: DVector<f64>) -> Found {
    Found {
        period: None,
        state,
        multipliers: Vec::new(),
        monodromy: None,
        stable: true,
    }
}

/// The orbit `found` (period n > 1, from shooting) at its minimal period d | n when its d-fold
/// map returns its state to `spec.steady.tol` ([`minimal_period`], by plain integration), with
/// the monodromy of d periods (one flow of the variational equations): the period a transient's
/// rotating returns suggested, or one carried along the sweep, is not the orbit's period when
/// Newton at d does not converge ([`crate::analysis::shooting::reduce_period`] keeps n then).
/// `found` when n is minimal or a flow fails.
fn minimal_orbit(integ: &mut dyn Integrator, found: Found, spec: &SteppedSpec) -> Found {
    let Some(n) = found.period.filter(|&n| n > 1) else {
        return found;
    };
    let mut map = StroboscopicMap::new(integ, 1);
    let d = minimal_period(&mut map, &found.state, n, spec.steady.tol);
    if d == n {
        return found;
    }
    let Ok(lin) = map.linearise(&found.state, d, false) else {
        return found;
    };
    let (multipliers, stable, _) = floquet_stability(&lin.jacobian);
    Found {
        period: Some(d),
        state: found.state,
        multipliers,
        monodromy: Some(lin.jacobian),
        stable,
    }
}

/// The period-1 map at one parameter value over its own integrator, started at `z` (τ = 0).
pub(super) fn map_at(
    spec: &SteppedSpec,
    value: f64,
    z: &DVector<f64>,
) -> Result<StroboscopicMap<'static>, SimError> {
    let model = CantileverModel::new(&spec.base.with(spec.param, value))?;
    StroboscopicMap::build(&model, spec.integrator.clone(), z, 1)
}

/// The stable orbit a step of the sweep follows: its value v0 and state z0, the secant slope
/// that predicts it along the branch, its monodromy matrix and trend ([`Trend`]), its period n.
struct Followed<'a> {
    value: f64,
    state: &'a DVector<f64>,
    slope: Option<&'a DVector<f64>>,
    trend: Option<&'a Trend>,
    period: usize,
}

/// The longer step a halved one is part of: the distance to the stable orbit Newton found over
/// it, and the halvings in a row so far that did not shrink that distance.
#[derive(Debug, Clone, Copy)]
struct LongerStep {
    gap: f64,
    unshrunk: usize,
}

/// Follow the stable orbit `from` (period n, at v0) to `v1` by Newton (from the secant
/// prediction `z0 + slope (v1 − v0)`, then from `z0`; undamped,
/// [`ShootingStrategy::Undamped`]: a full step that does not lower the residual means the orbit
/// is not near, and halving the parameter step is the remedy; where the integrator integrates
/// the variational equations step by step ([`broyden_pays`]), first
/// [`ShootingStrategy::Broyden`] with the trend's estimate at `v1` as the first Jacobian):
/// accepted when stable and within `jump_tol` of `z0`. Otherwise the step is halved (up to
/// `depth` times) and each half continued in turn — a quasi-static sweep — unless three
/// halvings in a row did not shrink the distance to the stable orbit Newton found below 0.95
/// of the distance over the longer step (`whole`): a jump, not a steep piece of branch (across
/// a resonance much sharper than the step the distance shrinks slowly, but it shrinks). `None`
/// when the orbit cannot be followed (it vanished or lost stability).
fn continue_orbit(
    spec: &SteppedSpec,
    from: &Followed,
    v1: f64,
    depth: usize,
    whole: Option<LongerStep>,
) -> Result<Option<PeriodicOrbit>, SimError> {
    let (v0, z0) = (from.value, from.state);
    let model = CantileverModel::new(&spec.base.with(spec.param, v1))?;
    let map = &mut StroboscopicMap::build(&model, spec.integrator.clone(), z0, 1)?;
    let m1 = from
        .trend
        .filter(|_| broyden_pays(spec.integrator.clone(), &model))
        .map(|t| t.at(v1 - v0));
    let mut guesses = Vec::with_capacity(2);
    if let Some(s) = from.slope {
        guesses.push(z0 + s * (v1 - v0));
    }
    guesses.push(z0.clone());
    let undamped = ShootingOptions {
        period: from.period,
        strategy: ShootingStrategy::Undamped,
        ..spec.newton
    };
    let broyden = ShootingOptions {
        strategy: ShootingStrategy::Broyden,
        ..undamped
    };
    let mut gap: Option<f64> = None;
    for g in &guesses {
        let shot = match &m1 {
            Some(m) => shoot(
                map,
                Guess::Estimated {
                    state: g,
                    monodromy: m,
                },
                &broyden,
            )
            .or_else(|_| shoot(map, g, &undamped)),
            None => shoot(map, g, &undamped),
        };
        if let Ok(o) = shot {
            if o.stable {
                let d = relative_gap(&o.state, z0);
                if d <= spec.jump_tol {
                    return Ok(Some(o));
                }
                gap = Some(gap.map_or(d, |x: f64| x.min(d)));
            }
        }
    }
    // halvings in a row that did not shrink the distance
    let unshrunk = match (gap, whole) {
        (Some(g), Some(w)) if g > 0.95 * w.gap => w.unshrunk + 1,
        _ => 0,
    };
    if depth == 0 || unshrunk >= 3 {
        return Ok(None);
    }
    let mid = 0.5 * (v0 + v1);
    let first = gap.map(|gap| LongerStep { gap, unshrunk });
    let Some(om) = continue_orbit(spec, from, mid, depth - 1, first)? else {
        return Ok(None);
    };
    let half_slope = (&om.state - z0) / (mid - v0);
    let trend = from
        .trend
        .map(|t| Trend::through(&t.m, &om.monodromy, mid - v0));
    let half = Followed {
        value: mid,
        state: &om.state,
        slope: Some(&half_slope),
        trend: trend.as_ref(),
        period: from.period,
    };
    continue_orbit(spec, &half, v1, depth - 1, None)
}

/// The monodromy matrix M of the orbit followed at v0 and, when the orbit before it is on the
/// same branch, its rate of change along the sweep: the first Jacobian of
/// [`ShootingStrategy::Broyden`] at
/// v is M + (v − v0) dM/dv (linear extrapolation, the monodromy's counterpart of
/// [`prediction_slope`]).
#[derive(Debug, Clone)]
pub(super) struct Trend {
    m: DMatrix<f64>,
    rate: Option<DMatrix<f64>>,
}

impl Trend {
    /// From M(v0 − dv) = `before` to M(v0) = `m`.
    pub(super) fn through(before: &DMatrix<f64>, m: &DMatrix<f64>, dv: f64) -> Self {
        Trend {
            m: m.clone(),
            rate: Some((m - before) / dv),
        }
    }

    /// The estimate dv after v0.
    pub(super) fn at(&self, dv: f64) -> DMatrix<f64> {
        match &self.rate {
            Some(r) => &self.m + r * dv,
            None => self.m.clone(),
        }
    }

    /// The trend of the last point of `history`: its monodromy matrix, with the secant through
    /// the point before when both are on one branch (the same period, the last not reached by
    /// settling, distinct values).
    pub(super) fn of(history: &[CurvePoint]) -> Option<Self> {
        let k = history.len();
        let last = history.last()?;
        let m = last.monodromy.as_ref()?;
        let before = (k >= 2)
            .then(|| &history[k - 2])
            .filter(|b| {
                b.period == last.period && !last.reached.by_transient() && b.value != last.value
            })
            .and_then(|b| b.monodromy.as_ref().map(|mb| (mb, last.value - b.value)));
        Some(match before {
            Some((mb, dv)) => Trend::through(mb, m, dv),
            None => Trend {
                m: m.clone(),
                rate: None,
            },
        })
    }
}

/// The slope s with which `z_last + s (value − v_last)` predicts the orbit at `value` from the
/// previous points of the same branch (same period, none reached by settling after the first):
/// the quadratic (Lagrange) extrapolation through the last three, else the secant through the
/// last two, else none.
pub(super) fn prediction_slope(history: &[CurvePoint], value: f64) -> Option<DVector<f64>> {
    let k = history.len();
    let last = history.last()?;
    // the longest tail of the same branch, at most three points
    let mut m = 1;
    while m < k.min(3) {
        let (a, b) = (&history[k - m - 1], &history[k - m]);
        if a.period != b.period || b.reached.by_transient() || a.value == b.value {
            break;
        }
        m += 1;
    }
    let pts = &history[k - m..];
    let dv = value - last.value;
    match pts {
        [b, a] => Some((&a.state - &b.state) / (a.value - b.value)),
        [c, b, a] if c.value != a.value => {
            let (x0, x1, x2) = (c.value, b.value, a.value);
            let l0 = (value - x1) * (value - x2) / ((x0 - x1) * (x0 - x2));
            let l1 = (value - x0) * (value - x2) / ((x1 - x0) * (x1 - x2));
            let l2 = (value - x0) * (value - x1) / ((x2 - x0) * (x2 - x1));
            let pred = &c.state * l0 + &b.state * l1 + &a.state * l2;
            (dv != 0.0).then(|| (pred - &a.state) / dv)
        }
        _ => None,
    }
}

/// The steady state at `value` reached from the last point of `history` (or from rest), the
/// previous points of its branch giving the predictor ([`prediction_slope`]).
pub(super) fn step_point(
    spec: &SteppedSpec,
    value: f64,
    history: &[CurvePoint],
) -> Result<CurvePoint, SimError> {
    let prev = history.last();
    if let Some(opts) = &spec.average {
        return average_point(spec, opts, value, prev);
    }
    if let Some(opts) = &spec.torus {
        return torus_point(spec, opts, value, history);
    }
    orbit_point(spec, value, history)
}

/// The periodic orbit at `value` continued from the last point of `history` (or found from
/// rest), settled by the transient where it cannot be followed.
pub(super) fn orbit_point(
    spec: &SteppedSpec,
    value: f64,
    history: &[CurvePoint],
) -> Result<CurvePoint, SimError> {
    let prev = history.last();
    let model = CantileverModel::new(&spec.base.with(spec.param, value))?;
    let last = prev.map_or_else(|| model.rest(), |p| p.state.clone());
    let n = prev.and_then(|p| p.period).unwrap_or(1);
    let mut integ = build(&model, spec.integrator.clone(), 0.0, &last)?;
    let slope = prediction_slope(history, value);
    let newton = spec.newton.with_period(n);
    let continued = match prev {
        Some(p) => continue_orbit(
            spec,
            &Followed {
                value: p.value,
                state: &last,
                slope: slope.as_ref(),
                trend: Trend::of(history).as_ref(),
                period: n,
            },
            value,
            SUBSTEP_DEPTH,
            None,
        )?
        .map(|o| (o.state, o.multipliers, o.monodromy)),
        None => shoot(&mut StroboscopicMap::new(integ.as_mut(), 1), &last, &newton)
            .ok()
            .filter(|o| o.stable)
            .map(|o| (o.state, o.multipliers, o.monodromy)),
    };
    let first = if prev.is_some() {
        Reached::Continued
    } else {
        Reached::Start
    };
    let (mut averaged, mut free_decay_wait) = (None, false);
    let (found, reached) = match continued {
        Some((state, multipliers, monodromy)) => (
            Found {
                period: Some(n),
                state,
                multipliers,
                monodromy: Some(monodromy),
                stable: true,
            },
            first,
        ),
        None => {
            let s = settle(integ.as_mut(), &last, n, spec)?;
            (averaged, free_decay_wait) = (s.averaged, s.free_decay_wait);
            let reached = match (prev, &averaged) {
                (_, Some(_)) => Reached::Averaged,
                (Some(_), None) => Reached::Settled,
                (None, None) => Reached::Start,
            };
            (s.found, reached)
        }
    };
    // the minimal period: a period carried along the sweep (or a transient's guess) finds a
    // period-1 orbit as a fixed point of Pⁿ as readily as a period-n one
    let found = match found.period {
        Some(n) if n > 1 => {
            match crate::analysis::shooting::reduce_period(
                integ.as_mut(),
                &found.state,
                n,
                &spec.newton,
            )? {
                Some(o) => Found {
                    period: Some(o.period),
                    state: o.state,
                    multipliers: o.multipliers,
                    monodromy: Some(o.monodromy),
                    stable: o.stable,
                },
                None => minimal_orbit(integ.as_mut(), found, spec),
            }
        }
        _ => found,
    };
    let periods = found.period.unwrap_or(spec.steady.nonperiodic_record);
    let observables = match averaged {
        Some(o) => o,
        None => measure(integ.as_mut(), &found.state, periods, &spec.observables)?,
    };
    Ok(CurvePoint {
        value,
        period: found.period,
        state: found.state,
        multipliers: found.multipliers,
        monodromy: found.monodromy,
        stable: found.stable,
        reached,
        observables,
        tau: 0.0,
        average: None,
        circle: None,
        fallback: None,
        free_decay_wait,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A period-1 orbit handed on as period 6 (a transient's rotating returns, or a period
    /// carried along a sweep) is reported at its minimal period 1, with the multipliers of the
    /// period-1 shooting (the d-fold map's, to round-off); a period-1 orbit stays as it is.
    #[test]
    fn an_orbit_is_reported_at_its_minimal_period() {
        // a point mass (Q = 42) oscillating far from the sample: one attracting period-1 orbit
        let p = Params {
            structure: crate::params::Structure::PointMass,
            modes: 1,
            alpha1: 0.0,
            alpha3: 1.0 / 42.0,
            omega: 1.0,
            alpha5: 10.0,
            ..Params::default()
        };
        let spec = SteppedSpec::new(p, SweepParam::Alpha5, vec![p.alpha5, p.alpha5 + 0.01]);
        let model = CantileverModel::new(&p).unwrap();
        let mut integ = build(&model, spec.integrator.clone(), 0.0, &model.rest()).unwrap();
        let mut map = StroboscopicMap::new(integ.as_mut(), 1);
        let one = shoot(&mut map, &model.rest(), &spec.newton).unwrap();
        assert_eq!(one.period, 1);
        let as_six = Found {
            period: Some(6),
            state: one.state.clone(),
            multipliers: Vec::new(),
            monodromy: None,
            stable: true,
        };
        let got = minimal_orbit(integ.as_mut(), as_six, &spec);
        assert_eq!(got.period, Some(1));
        assert_eq!(got.state, one.state);
        assert_eq!(got.stable, one.stable);
        for (a, b) in got.multipliers.iter().zip(&one.multipliers) {
            assert!((a - b).norm() <= 1e-8, "{a} vs {b}");
        }
        let as_one = Found {
            period: Some(1),
            ..got.clone()
        };
        assert_eq!(minimal_orbit(integ.as_mut(), as_one.clone(), &spec), as_one);
    }
}
