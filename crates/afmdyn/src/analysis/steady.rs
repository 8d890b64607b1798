//! Steady state on the stroboscopic Poincaré map τ = 2πk/Ω (drive phase 0) and its statistics.

use super::period::{detect_period, minimal_divisor, MAX_PERIOD, MERGE_FACTOR};
use super::settle::{minimal_period, newton_from_transient, SettleOptions, CENSUS_SETTLED};
use super::shooting::{shoot, ShootingOptions};
use crate::error::{in_range, within, SimError};
use crate::galerkin::Region;
use crate::integrate::{
    advance, advance_observed, build, Integrator, IntegratorOptions, Observed, Observer, Step,
};
use crate::maps::StroboscopicMap;
use crate::model::{BodyContactCheck, CantileverModel};
use crate::roots::extremum;
use crate::system::EventKind;
use crate::tip_sample::TipSampleSystem;
use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Options of the steady-state search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyOptions {
    /// Relative tolerance for two returns to coincide.
    pub tol: f64,
    /// Cap on the transient, in drive periods; `None`: derived from the model's slowest free
    /// decay (`SteadyOptions::cap`, [`default_transient_cap`]).
    pub max_periods: Option<usize>,
    /// Largest period searched (≤ 64).
    pub max_period: usize,
    /// Periods recorded for a motion classified nonperiodic.
    pub nonperiodic_record: usize,
    /// On a slowly decaying model (one whose slowest free mode takes more than
    /// `NEWTON_DECAY_PERIODS` to decay by `tol`: Q above ~170 at resonance), decide by Newton
    /// shooting from the transient as soon as the motion is seen to go to a stable orbit
    /// ([`super::settle`]) instead of waiting for its returns to repeat to `tol`.
    pub newton: bool,
}

impl Default for SteadyOptions {
    fn default() -> Self {
        SteadyOptions {
            tol: 1e-8,
            max_periods: None,
            max_period: MAX_PERIOD,
            nonperiodic_record: 64,
            newton: true,
        }
    }
}

/// Fewest drive periods of a derived transient cap ([`default_transient_cap`]): the cap that
/// settles the paper's beam (Q ≈ 42, its slowest mode decaying by 1e-8 in 248 periods).
pub(crate) const MIN_TRANSIENT_PERIODS: usize = 1_500;

/// Drive periods of free decay by the tolerance ([`decay_periods`]) above which a search
/// decides by Newton from the transient ([`SteadyOptions::newton`]). Below, the returns repeat
/// within a few hundred periods, which Newton's attempts — each some six flows with the
/// variational equations, every 100 periods — would not shorten: the paper's beam decays in
/// 248 periods at Ω = 2.6 and 477 at Ω = 5, the RTESPA-300 (Q = 500) in 2 932.
pub(crate) const NEWTON_DECAY_PERIODS: f64 = 1_000.0;

/// Decay times ([`decay_periods`]) of the slowest free mode in a derived transient cap: a
/// nonlinear orbit's leading Floquet multiplier may lie closer to the unit circle than the
/// free decay e^{−π/Q} (near a fold); six times covers the margins measured on the
/// RTESPA-300 probe (Q = 500), whose returns repeat to 1e-8 within 3 000 – 12 000 periods.
pub(crate) const TRANSIENT_DECAY_TIMES: f64 = 6.0;

/// Drive periods the slowest free mode of the cantilever takes to decay by the factor `tol`:
/// ln(1/tol)/(|Re λ| T), λ the damped eigenvalue with the smallest |Re λ| (eqs. 20–21) and T
/// the drive period — ≈ Q ln(1/tol)/π for a lever of quality factor Q driven at resonance.
/// `None` for a system without a free decay rate ([`TipSampleSystem::free_decay_rate`]) or an
/// undamped one.
pub(crate) fn decay_periods(system: &dyn TipSampleSystem, tol: f64) -> Option<f64> {
    let slowest = system.free_decay_rate()?;
    let decay = (1.0 / tol).ln() / (slowest * system.period());
    (decay.is_finite() && decay > 0.0).then_some(decay)
}

/// The default cap on a steady-state search's transient, the one rule of every analysis that
/// waits for a steady state: `TRANSIENT_DECAY_TIMES` × `decay_periods`, within
/// [`MIN_TRANSIENT_PERIODS`, [`MAX_STEADY_PERIODS`]] (the floor for a system without a
/// decay rate). The paper's beam keeps 1 500 periods; the RTESPA-300 (Q = 500) gets 17 600.
pub fn default_transient_cap(system: &dyn TipSampleSystem, tol: f64) -> usize {
    let Some(decay) = decay_periods(system, tol) else {
        return MIN_TRANSIENT_PERIODS;
    };
    (TRANSIENT_DECAY_TIMES * decay)
        .ceil()
        .clamp(MIN_TRANSIENT_PERIODS as f64, MAX_STEADY_PERIODS as f64) as usize
}

impl SteadyOptions {
    /// The transient cap on `system`: `max_periods` when given, else
    /// [`default_transient_cap`].
    pub(crate) fn cap(&self, system: &dyn TipSampleSystem) -> usize {
        self.max_periods
            .unwrap_or_else(|| default_transient_cap(system, self.tol))
    }

    /// Whether the search decides by Newton from the transient on `system` (see
    /// [`SteadyOptions::newton`]).
    pub(crate) fn newton_on(&self, system: &dyn TipSampleSystem) -> bool {
        self.newton && decay_periods(system, self.tol).is_some_and(|d| d > NEWTON_DECAY_PERIODS)
    }
}

/// Classification of a steady state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", tag = "kind")]
pub enum Motion {
    /// Period-n orbit of the stroboscopic map.
    Periodic {
        /// n.
        period: usize,
    },
    /// No return within tolerance before the cap.
    Nonperiodic,
}

/// One point of the stroboscopic section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoincarePoint {
    /// τ = 2πk/Ω.
    pub tau: f64,
    /// V_T at the section.
    pub v_t: f64,
    /// W(1,τ) at the section.
    pub w_tip: f64,
    /// State (a, ȧ), shape `[2N]`.
    pub state: DVector<f64>,
}

/// Statistics of the recorded steady-state periods.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct OrbitStats {
    /// X_max: the largest tip displacement W(1,τ).
    pub x_max: f64,
    /// Smallest W(1,τ).
    pub x_min: f64,
    /// Smallest V_T (deepest indentation when negative).
    pub v_t_min: f64,
    /// Fraction of time in contact.
    pub contact_fraction: f64,
    /// Contacts per drive period: entries into region II, and impacts on a rigid sample (the
    /// impact law's contacts, which leave the tip in free flight).
    pub contacts_per_period: f64,
    /// Whether a beam point other than the tip reached the substrate at a step end (the
    /// paper's Fig. 2f assumption is violated).
    pub body_contact: bool,
}

/// A steady state reached from one initial condition (serialized for the stores of the studies
/// whose later tasks start from it: a basin map's passes).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SteadyState {
    /// Period-n or nonperiodic.
    pub motion: Motion,
    /// Periods of transient before recording.
    pub transient_periods: usize,
    /// Section points of the recorded cycle (n for period-n, `nonperiodic_record` otherwise).
    pub poincare: Vec<PoincarePoint>,
    /// Statistics over the recorded periods.
    pub stats: OrbitStats,
}

impl SteadyState {
    /// n for a period-n orbit.
    pub fn period(&self) -> Option<usize> {
        match self.motion {
            Motion::Periodic { period } => Some(period),
            Motion::Nonperiodic => None,
        }
    }
    /// The state at the last section point (to continue from).
    pub fn end_state(&self) -> &DVector<f64> {
        &self.poincare.last().expect("at least one point").state
    }
}

/// Accumulates [`OrbitStats`] step by step ([`Observer`] of [`advance_observed`]), locating
/// interior extrema of W(1,τ) and V_T on the integrator's dense output. The values at a step's
/// ends are the integrator's [`crate::integrate::Spans::tip_values`] (the exact propagator's from its modal
/// coordinates: the plain state is formed only where the body-contact bound does not hold).
#[derive(Debug, Clone)]
pub struct StatsObserver {
    x_max: f64,
    x_min: f64,
    v_min: f64,
    contact_time: f64,
    contacts: usize,
    time: f64,
    body: Option<Option<BodyContactCheck>>,
    body_contact: bool,
    /// The [`EndValues`] of the integrator's state where the next step starts (the end of the
    /// last step, after the jump of an event; the start of the run).
    next_start: Option<EndValues>,
}

/// W(1,τ), Ẇ(1,τ), V_T and dV_T/dτ at one end of a step.
#[derive(Debug, Clone, Copy)]
struct EndValues {
    w: f64,
    w_dot: f64,
    v_t: f64,
    v_t_dot: f64,
}

impl From<[f64; 4]> for EndValues {
    /// From [W, Ẇ, V_T, V̇_T] ([`Integrator::tip_values`], [`CantileverModel::tip_values`]).
    fn from([w, w_dot, v_t, v_t_dot]: [f64; 4]) -> Self {
        EndValues {
            w,
            w_dot,
            v_t,
            v_t_dot,
        }
    }
}

impl Default for StatsObserver {
    fn default() -> Self {
        StatsObserver {
            x_max: f64::NEG_INFINITY,
            x_min: f64::INFINITY,
            v_min: f64::INFINITY,
            contact_time: 0.0,
            contacts: 0,
            time: 0.0,
            body: None,
            body_contact: false,
            next_start: None,
        }
    }
}

impl Observer for StatsObserver {
    fn start(&mut self, it: &mut Observed<'_>) -> Result<(), SimError> {
        self.next_start = Some(it.tip_values().into());
        Ok(())
    }

    /// Account for one step. A step that ends at an event ends at the state before its jump
    /// (the event's, whose values are formed); the next step starts after it.
    fn step(&mut self, it: &mut Observed<'_>, step: &Step) -> Result<(), SimError> {
        let len = step.tau1 - step.tau0;
        let after: EndValues = it.tip_values().into();
        let start = self.next_start.replace(after);
        if len <= 0.0 {
            return Ok(());
        }
        self.time += len;
        if step.region == Region::Contact {
            self.contact_time += len;
        }
        if matches!(&step.event, Some(e) if e.to == Region::Contact || e.kind == EventKind::Impact)
        {
            self.contacts += 1;
        }
        // the beam's body: of the cantilever only (another system has no body to check)
        let body = self
            .body
            .get_or_insert_with(|| it.system().body_contact_check(32));
        let e1 = match &step.event {
            Some(e) => {
                if let Some(body) = body {
                    self.body_contact |= body.touches(step.tau1, &e.state);
                }
                it.system().tip_values(step.tau1, &e.state).into()
            }
            None => {
                if let Some(body) = body {
                    self.body_contact |= body.touches_observed(it);
                }
                after
            }
        };
        // the start's values: those of the integrator's state where the step began (set by
        // `start` or the step before, as `advance_observed` drives every observer)
        let e0 = start.unwrap_or(e1);
        let ((w0, w1), (d0, d1), (v0, v1), (vd0, vd1)) = (
            (e0.w, e1.w),
            (e0.w_dot, e1.w_dot),
            (e0.v_t, e1.v_t),
            (e0.v_t_dot, e1.v_t_dot),
        );
        self.x_max = self.x_max.max(w0).max(w1);
        self.x_min = self.x_min.min(w0).min(w1);
        if (d0 > 0.0) != (d1 > 0.0) {
            let t = extremum(step.tau0, step.tau1, d0, &mut |t| it.dense_tip(t));
            let w = it.dense_tip(t)[0];
            self.x_max = self.x_max.max(w);
            self.x_min = self.x_min.min(w);
        }
        self.v_min = self.v_min.min(v0).min(v1);
        if vd0 < 0.0 && vd1 > 0.0 {
            let mut vt = |t: f64| it.dense_v_t(t);
            let t = extremum(step.tau0, step.tau1, vd0, &mut vt);
            self.v_min = self.v_min.min(vt(t)[0]);
        }
        Ok(())
    }
}

impl StatsObserver {
    /// The statistics, with `periods` the number of drive periods observed.
    pub fn finish(&self, periods: usize) -> OrbitStats {
        OrbitStats {
            x_max: self.x_max,
            x_min: self.x_min,
            v_t_min: self.v_min,
            contact_fraction: if self.time > 0.0 {
                self.contact_time / self.time
            } else {
                0.0
            },
            contacts_per_period: self.contacts as f64 / periods.max(1) as f64,
            body_contact: self.body_contact,
        }
    }
}

/// Advance one drive period to the next section point τ = 2πk/Ω.
fn next_section(
    integ: &mut dyn Integrator,
    stats: Option<&mut StatsObserver>,
) -> Result<(), SimError> {
    let target = section_after(integ.tau(), integ.system().period());
    match stats {
        // nothing observed per step: the state only at events and the end
        None => advance(integ, target),
        Some(obs) => advance_observed(integ, target, obs),
    }
}

fn point(integ: &dyn Integrator) -> PoincarePoint {
    let z = integ.state();
    let [w_tip, _, v_t, _] = integ.system().tip_values(integ.tau(), z);
    PoincarePoint {
        tau: integ.tau(),
        v_t,
        w_tip,
        state: z.clone(),
    }
}

/// The period search of [`steady_state`] on the stroboscopic returns, fed one return at a
/// time (shared by the one-trajectory and the batched search, and the stepped sweeps' settling,
/// [`super::stepped::settle`]).
pub(crate) struct ReturnHistory {
    history: VecDeque<DVector<f64>>,
    confirm: Vec<usize>,
    /// Returns pushed (periods of transient so far).
    k: usize,
}

impl ReturnHistory {
    pub(crate) fn new(opts: &SteadyOptions, first: &DVector<f64>) -> Self {
        let mut history = VecDeque::with_capacity(3 * opts.max_period + 2);
        history.push_back(first.clone());
        ReturnHistory {
            history,
            confirm: Vec::new(),
            k: 0,
        }
    }

    /// Account for the next return; `Some(n)` once a period n is confirmed.
    pub(crate) fn push(&mut self, z: &DVector<f64>, opts: &SteadyOptions) -> Option<usize> {
        self.k += 1;
        if self.history.len() == 3 * opts.max_period + 1 {
            self.history.pop_front();
        }
        self.history.push_back(z.clone());
        if let Some(n) = detect_period(self.history.make_contiguous(), opts.tol, opts.max_period) {
            self.confirm.push(n);
            // a candidate must hold for two more cycles, then be reduced to its smallest
            // divisor within the merge tolerance (see `minimal_divisor`)
            if self.confirm.len() > 2 * n {
                let h = self.history.make_contiguous();
                return Some(minimal_divisor(h, n, opts.tol * MERGE_FACTOR));
            }
        } else {
            self.confirm.clear();
        }
        None
    }
}

/// Smallest tolerance of the return test: returns of a map computed to round-off (~1e-15
/// relative) coincide no closer.
pub(crate) const MIN_TOL: f64 = 1e-14;
/// Largest tolerance of the return test: beyond it a slowly converging transient or a
/// chaotic motion is taken for a period-n orbit.
pub(crate) const MAX_TOL: f64 = 1e-3;

/// Largest transient cap of a steady-state search, in drive periods.
pub const MAX_STEADY_PERIODS: usize = 10_000_000;

impl SteadyOptions {
    /// Check the options (the one place of their limits; the request layer calls it).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `tol` ([`MIN_TOL`, `MAX_TOL`]), `max_period`
    /// (1..=64) or `max_periods` (1..=[`MAX_STEADY_PERIODS`]).
    pub fn validate(&self) -> Result<(), SimError> {
        within(
            "tol",
            self.tol,
            MIN_TOL..=MAX_TOL,
            "must be in [1e-14, 1e-3]",
        )?;
        in_range("max_period", self.max_period, 1..=MAX_PERIOD)?;
        if let Some(m) = self.max_periods {
            in_range("max_periods", m, 1..=MAX_STEADY_PERIODS)?;
        }
        Ok(())
    }
}

/// The next section time τ = 2πk/Ω after `tau`.
fn section_after(tau: f64, period: f64) -> f64 {
    ((tau / period + 1e-9).floor() + 1.0) * period
}

/// Whether `tau` is on the section (to 1e-9 of a period).
fn on_section(tau: f64, period: f64) -> bool {
    let phase = tau / period;
    (phase - phase.round()).abs() <= 1e-9
}

/// Record one cycle (period n = `found`) or `nonperiodic_record` periods after a transient of
/// `transient` periods.
fn record(
    integ: &mut dyn Integrator,
    found: Option<usize>,
    transient: usize,
    opts: &SteadyOptions,
) -> Result<SteadyState, SimError> {
    let record = found.unwrap_or(opts.nonperiodic_record.max(1));
    let mut obs = StatsObserver::default();
    let mut poincare = Vec::with_capacity(record);
    for _ in 0..record {
        next_section(integ, Some(&mut obs))?;
        poincare.push(point(integ));
    }
    Ok(SteadyState {
        motion: match found {
            Some(period) => Motion::Periodic { period },
            None => Motion::Nonperiodic,
        },
        transient_periods: transient,
        poincare,
        stats: obs.finish(record),
    })
}

/// The steady state from the integrator's current state: iterate the stroboscopic map until
/// the returns repeat with some period n ≤ `max_period` (then record one cycle) or the
/// transient cap `SteadyOptions::cap` is reached (then record `nonperiodic_record` periods as
/// a nonperiodic motion). On a slowly decaying model (`SteadyOptions::newton_on`) Newton
/// shooting from the transient is tried beside the returns' test ([`super::settle`], within
/// the cap), and whichever decides first ends the search: a motion seen to go to a stable
/// period-n orbit is recorded on the orbit (its Poincaré points the orbit's to the shooting
/// tolerance); returns that repeat first end it as above — Newton can only shorten a search,
/// not lengthen it (the paper's Figs. 15–17 beam at Ω = 20, whose orbits contract far faster
/// than its free decay, took 5 023 periods per start when Newton alone decided, 414 before).
///
/// # Errors
/// [`SimError`] from the integrator (divergence, chattering) or for invalid options.
pub fn steady_state(
    integ: &mut dyn Integrator,
    opts: &SteadyOptions,
) -> Result<SteadyState, SimError> {
    opts.validate()?;
    // align on the section
    let period = integ.system().period();
    if !on_section(integ.tau(), period) {
        next_section(integ, None)?;
    }
    let cap = opts.cap(integ.system());
    let mut returns = ReturnHistory::new(opts, integ.state());
    let mut found = None;
    // periods spent before `returns` was last restarted
    let mut before = 0;
    if opts.newton_on(integ.system()) {
        let tau0 = integ.tau();
        let mut z = integ.state().clone();
        let settle = SettleOptions {
            newton: ShootingOptions {
                tol: (opts.tol * 1e-2).max(1e-12),
                max_iter: 6,
                ..ShootingOptions::default()
            },
            chunk_periods: SETTLE_CHUNK,
            max_period: opts.max_period,
            max_wait: 4,
            settled: CENSUS_SETTLED,
            linear: false,
        };
        loop {
            // the returns keep their own test: whichever decides first
            let mut on_return = |z: &DVector<f64>| {
                found = returns.push(z, opts);
                found.is_some()
            };
            let budget = cap.saturating_sub(before);
            let s = newton_from_transient(integ, &z, None, &settle, budget, &mut on_return)?;
            let spent = before + s.periods;
            integ.set_variational(false);
            if let Some(orbit) = s.found {
                let n = orbit.period.unwrap_or(1);
                let n = minimal_period(
                    &mut StroboscopicMap::new(&mut *integ, 1),
                    &orbit.state,
                    n,
                    opts.tol,
                );
                integ.reset(tau0 + spent as f64 * period, &orbit.state)?;
                return record(integ, Some(n), spent, opts);
            }
            // returns that repeat near an unstable orbit (a start near its stable manifold
            // lingers there: |μ₁| = 1.0035 on the RTESPA-300 probe's saddle) are a passage,
            // not the steady state: the transient goes on
            let passage = match found {
                Some(n) if spent < cap => {
                    let map = &mut StroboscopicMap::new(&mut *integ, 1);
                    shoot(map, &s.state, &settle.newton.with_period(n)).is_ok_and(|o| !o.stable)
                }
                _ => false,
            };
            integ.reset(tau0 + spent as f64 * period, &s.state)?;
            if !passage {
                break;
            }
            found = None;
            before = spent;
            returns = ReturnHistory::new(opts, &s.state);
            z = s.state;
        }
    }
    while found.is_none() && before + returns.k < cap {
        next_section(integ, None)?;
        found = returns.push(integ.state(), opts);
    }
    record(integ, found, before + returns.k, opts)
}

/// [`steady_state`] from (τ = 0, `z0`) on a new integrator of `model` built with `integrator`
/// ([`crate::integrate::build`]): the set-up every start of a census or sweep repeats.
///
/// # Errors
/// As [`crate::integrate::build`] and [`steady_state`].
pub(crate) fn steady_state_of(
    model: &CantileverModel,
    integrator: IntegratorOptions,
    z0: &DVector<f64>,
    opts: &SteadyOptions,
) -> Result<SteadyState, SimError> {
    steady_state(build(model, integrator, 0.0, z0)?.as_mut(), opts)
}

/// Drive periods between the Newton attempts of [`steady_state`] on a slowly decaying model
/// (the stepped sweeps' chunk).
pub(crate) const SETTLE_CHUNK: usize = 25;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::bifurcation::random_state;
    use crate::integrate::{build, IntegratorOptions};
    use crate::model::CantileverModel;
    use crate::params::Params;
    use crate::LawKind;

    /// Relative difference |a − b| / (1 + |b|).
    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / (1.0 + b.abs())
    }

    /// [`StatsObserver`] fed with the plain state formed after every step (so the tip values
    /// and the body-contact bound come from it, as before observers saw the modal
    /// coordinates), checking at each step that the values carried over from the step before
    /// equal those formed from the state where the step began.
    struct Formed {
        inner: StatsObserver,
        before: Option<(f64, DVector<f64>)>,
        worst_start: f64,
        events: usize,
    }

    impl Observer for Formed {
        fn start(&mut self, it: &mut Observed<'_>) -> Result<(), SimError> {
            self.before = Some((it.tau(), it.state().clone()));
            self.inner.start(it)
        }
        fn step(&mut self, it: &mut Observed<'_>, st: &Step) -> Result<(), SimError> {
            let z = it.state().clone();
            let (tau0, z0) = self.before.take().expect("started");
            assert_eq!(tau0, st.tau0);
            let got = self.inner.next_start.expect("started");
            let want = it.system().tip_values(tau0, &z0);
            let got = [got.w, got.w_dot, got.v_t, got.v_t_dot];
            for (g, w) in got.iter().zip(want) {
                self.worst_start = self.worst_start.max(rel(*g, w));
            }
            self.events += usize::from(st.event.is_some());
            self.inner.step(it, st)?;
            self.before = Some((it.tau(), z));
            Ok(())
        }
    }

    /// The statistics observed on the integrator's tip values and displacement bound (the
    /// exact propagator's modal coordinates, the plain state formed only where the bound does
    /// not spare the body-contact stations) equal those observed on the plain state formed
    /// after every step: contacts and contact time exactly, body contact the same, the extrema
    /// of W and V_T to round-off; and every step's start values, carried over from the step
    /// before, equal those formed at its start. Exact propagator N = 1, 3, 10, 20 on the
    /// attractor, N = 3 from a large start whose beam body touches the substrate, and the
    /// impact law (split integrator: exact free flight in modal coordinates between impacts;
    /// the statistics bit for bit), whose restitution moves the state at every impact (the
    /// start after it is the state after the jump).
    #[test]
    fn stats_from_modal_coordinates_equal_stats_from_the_state() {
        for (law, modes, scale, body) in [
            ("linear", 1, 1.0, false),
            ("linear", 3, 1.0, false),
            ("linear", 10, 1.0, false),
            ("linear", 20, 1.0, false),
            ("linear", 3, 40.0, true),
            ("impact", 3, 1.0, false),
        ] {
            let law: LawKind = law.parse().unwrap();
            let p = Params {
                modes,
                contact_law: law.with_groups(Default::default()),
                ..Params::default()
            };
            let model = CantileverModel::new(&p).unwrap();
            let z0 = random_state(&model, 3, 1) * scale;
            let (t0, t1) = if body {
                (0.0, 3.0 * p.period())
            } else {
                (20.0 * p.period(), 30.0 * p.period())
            };
            let run = |obs: &mut dyn Observer| {
                let mut it = build(&model, IntegratorOptions::default(), 0.0, &z0).unwrap();
                advance(it.as_mut(), t0).unwrap();
                advance_observed(it.as_mut(), t1, obs).unwrap();
                it.state().clone()
            };
            let mut lazy = StatsObserver::default();
            let mut formed = Formed {
                inner: StatsObserver::default(),
                before: None,
                worst_start: 0.0,
                events: 0,
            };
            // the same trajectory bit for bit: forming the state changes nothing
            assert_eq!(run(&mut lazy), run(&mut formed), "{law:?}, N = {modes}");
            let at = format!("{law:?}, N = {modes}, scale {scale}");
            let (a, b) = (lazy.finish(10), formed.inner.finish(10));
            assert!(formed.events > 0, "{at}: the tip taps");
            assert_eq!(a.contacts_per_period, b.contacts_per_period, "{at}");
            assert_eq!(a.contact_fraction, b.contact_fraction, "{at}");
            assert_eq!((a.body_contact, b.body_contact), (body, body), "{at}");
            for (x, y) in [
                (a.x_max, b.x_max),
                (a.x_min, b.x_min),
                (a.v_t_min, b.v_t_min),
            ] {
                assert!(rel(x, y) <= 1e-12, "{at}: {x} vs {y}");
            }
            assert!(
                formed.worst_start <= 1e-12,
                "{at}: start values {}",
                formed.worst_start
            );
            if law == LawKind::Impact {
                assert_eq!(format!("{a:?}"), format!("{b:?}"), "{at}");
            }
        }
    }
}
