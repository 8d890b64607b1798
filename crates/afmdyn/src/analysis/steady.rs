//! Steady state on the stroboscopic Poincaré map τ = 2πk/Ω (drive phase 0) and its statistics.

use super::period::{detect_period, minimal_divisor, MAX_PERIOD, MERGE_FACTOR};
use crate::error::SimError;
use crate::galerkin::Region;
use crate::integrate::exact::ExactBatch;
use crate::integrate::{advance, advance_dyn, Integrator, Step};
use crate::model::BodyContactCheck;
use crate::roots::extremum;
use nalgebra::DVector;
use serde::Serialize;
use std::collections::VecDeque;

/// Options of the steady-state search.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyOptions {
    /// Relative tolerance for two returns to coincide.
    pub tol: f64,
    /// Cap on the transient, in drive periods.
    pub max_periods: usize,
    /// Largest period searched (≤ 64).
    pub max_period: usize,
    /// Periods recorded for a motion classified nonperiodic.
    pub nonperiodic_record: usize,
}

impl Default for SteadyOptions {
    fn default() -> Self {
        SteadyOptions {
            tol: 1e-8,
            max_periods: 1500,
            max_period: MAX_PERIOD,
            nonperiodic_record: 64,
        }
    }
}

/// Classification of a steady state.
#[derive(Debug, Clone, PartialEq, Serialize)]
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
#[derive(Debug, Clone, PartialEq)]
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
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct OrbitStats {
    /// X_max: the largest tip displacement W(1,τ).
    pub x_max: f64,
    /// Smallest W(1,τ).
    pub x_min: f64,
    /// Smallest V_T (deepest indentation when negative).
    pub v_t_min: f64,
    /// Fraction of time in contact.
    pub contact_fraction: f64,
    /// Contacts (entries into region II) per drive period.
    pub contacts_per_period: f64,
    /// Whether a beam point other than the tip reached the substrate at a step end (the
    /// paper's Fig. 2f assumption is violated).
    pub body_contact: bool,
}

/// A steady state reached from one initial condition.
#[derive(Debug, Clone, PartialEq)]
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

/// Accumulates [`OrbitStats`] step by step, locating interior extrema of W(1,τ) and V_T on the
/// integrator's dense output.
#[derive(Debug, Clone)]
pub struct StatsObserver {
    x_max: f64,
    x_min: f64,
    v_min: f64,
    contact_time: f64,
    contacts: usize,
    time: f64,
    body: Option<BodyContactCheck>,
    body_contact: bool,
    /// The end of the last step observed: τ1, the state there and its [`EndValues`], for the
    /// start of the next step (the same τ and state unless an event moved the state).
    last_end: Option<(f64, Vec<f64>, EndValues)>,
}

/// Whether two states are the same bit for bit.
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// W(1,τ), Ẇ(1,τ), V_T and dV_T/dτ at one end of a step.
#[derive(Debug, Clone, Copy)]
struct EndValues {
    w: f64,
    w_dot: f64,
    v_t: f64,
    v_t_dot: f64,
}

impl EndValues {
    /// At (τ, z): [`CantileverModel::w_tip`], [`CantileverModel::w_tip_dot`], and V_T with its
    /// τ-derivative from one sin/cos Ωτ ([`CantileverModel::v_t_from_tip`], eq. 8).
    fn at(model: &crate::model::CantileverModel, tau: f64, z: &DVector<f64>) -> Self {
        let (w, w_dot) = (model.w_tip(z), model.w_tip_dot(z));
        let [v_t, v_t_dot, _] = model.v_t_from_tip(tau, [w, w_dot, 0.0]);
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
            last_end: None,
        }
    }
}

impl StatsObserver {
    /// Account for one step; `before` is the state at `step.tau0`.
    pub fn observe(&mut self, integ: &mut dyn Integrator, step: &Step, before: &DVector<f64>) {
        let len = step.tau1 - step.tau0;
        if len <= 0.0 {
            return;
        }
        self.time += len;
        if step.region == Region::Contact {
            self.contact_time += len;
        }
        if matches!(&step.event, Some(e) if e.to == Region::Contact) {
            self.contacts += 1;
        }
        // end-point values first (borrowing the model), then the dense-output searches; a step
        // that ends at an event ends at the state before its jump. The start's values are the
        // end's of the step before when τ and the state are the same, bit for bit.
        let (e0, e1) = {
            let model = integ.model();
            let z1 = match &step.event {
                Some(e) => &e.state,
                None => integ.state(),
            };
            let body = self
                .body
                .get_or_insert_with(|| BodyContactCheck::new(model, 32));
            self.body_contact |= body.touches(model, step.tau1, z1);
            let e0 = self.start_values(model, step.tau0, before);
            let e1 = EndValues::at(model, step.tau1, z1);
            let mut z = self.last_end.take().map(|(_, z, _)| z).unwrap_or_default();
            z.clear();
            z.extend_from_slice(z1.as_slice());
            self.last_end = Some((step.tau1, z, e1));
            (e0, e1)
        };
        let ((w0, w1), (d0, d1), (v0, v1), (vd0, vd1)) = (
            (e0.w, e1.w),
            (e0.w_dot, e1.w_dot),
            (e0.v_t, e1.v_t),
            (e0.v_t_dot, e1.v_t_dot),
        );
        self.x_max = self.x_max.max(w0).max(w1);
        self.x_min = self.x_min.min(w0).min(w1);
        if (d0 > 0.0) != (d1 > 0.0) {
            let t = extremum(step.tau0, step.tau1, d0, &mut |t| integ.dense_tip(t));
            let w = integ.dense_tip(t)[0];
            self.x_max = self.x_max.max(w);
            self.x_min = self.x_min.min(w);
        }
        self.v_min = self.v_min.min(v0).min(v1);
        if vd0 < 0.0 && vd1 > 0.0 {
            let mut vt = |t: f64| integ.dense_v_t(t);
            let t = extremum(step.tau0, step.tau1, vd0, &mut vt);
            self.v_min = self.v_min.min(vt(t)[0]);
        }
    }

    /// The values at the start (τ0, z0) of a step: those at the end of the step observed before
    /// when τ and the state are the same bit for bit, formed otherwise.
    fn start_values(
        &self,
        model: &crate::model::CantileverModel,
        tau0: f64,
        z0: &DVector<f64>,
    ) -> EndValues {
        match &self.last_end {
            Some((tau, z, e)) if *tau == tau0 && same_bits(z, z0.as_slice()) => *e,
            _ => EndValues::at(model, tau0, z0),
        }
    }

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
    let target = section_after(integ.tau(), integ.model().period());
    match stats {
        // nothing observed per step: the state only at events and the end
        None => advance(integ, target),
        Some(obs) => advance_dyn(integ, target, &mut |it, st, before| {
            obs.observe(it, st, before);
            Ok(())
        }),
    }
}

fn point(integ: &dyn Integrator) -> PoincarePoint {
    let m = integ.model();
    let z = integ.state();
    PoincarePoint {
        tau: integ.tau(),
        v_t: m.v_t(integ.tau(), z),
        w_tip: m.w_tip(z),
        state: z.clone(),
    }
}

/// The period search of [`steady_state`] on the stroboscopic returns, fed one return at a
/// time (shared by the one-trajectory and the batched search).
struct ReturnHistory {
    history: VecDeque<DVector<f64>>,
    confirm: Vec<usize>,
    /// Returns pushed (periods of transient so far).
    k: usize,
}

impl ReturnHistory {
    fn new(opts: &SteadyOptions, first: &DVector<f64>) -> Self {
        let mut history = VecDeque::with_capacity(3 * opts.max_period + 2);
        history.push_back(first.clone());
        ReturnHistory {
            history,
            confirm: Vec::new(),
            k: 0,
        }
    }

    /// Whether the transient cap is reached.
    fn exhausted(&self, opts: &SteadyOptions) -> bool {
        self.k >= opts.max_periods
    }

    /// Account for the next return; `Some(n)` once a period n is confirmed.
    fn push(&mut self, z: &DVector<f64>, opts: &SteadyOptions) -> Option<usize> {
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

fn check_options(opts: &SteadyOptions) -> Result<(), SimError> {
    if !(opts.tol.is_finite() && opts.tol > 0.0) {
        return Err(SimError::out_of_range(
            "tolerance",
            opts.tol,
            "must be finite and > 0",
        ));
    }
    if opts.max_period == 0 || opts.max_period > MAX_PERIOD {
        return Err(SimError::out_of_range(
            "max period",
            opts.max_period,
            "must be in 1..=64",
        ));
    }
    Ok(())
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

/// Iterate the stroboscopic map from the integrator's current state until the returns repeat
/// with some period n ≤ `max_period` (then record one cycle) or the cap is reached (then record
/// `nonperiodic_record` periods as a nonperiodic motion).
///
/// # Errors
/// [`SimError`] from the integrator (divergence, chattering) or for invalid options.
pub fn steady_state(
    integ: &mut dyn Integrator,
    opts: &SteadyOptions,
) -> Result<SteadyState, SimError> {
    check_options(opts)?;
    // align on the section
    if !on_section(integ.tau(), integ.model().period()) {
        next_section(integ, None)?;
    }
    let mut returns = ReturnHistory::new(opts, integ.state());
    let mut found = None;
    while !returns.exhausted(opts) {
        next_section(integ, None)?;
        found = returns.push(integ.state(), opts);
        if found.is_some() {
            break;
        }
    }
    record(integ, found, returns.k, opts)
}

/// [`steady_state`] for every lane of a batch of exact-propagator trajectories at one
/// parameter set: the transients of all lanes still searching are advanced together
/// ([`ExactBatch::advance_to`], section by section), each lane's returns go through the same
/// period search, and a lane that has found its period (or reached the cap) records its cycle
/// alone. The results are those of [`steady_state`] on each lane alone, bit for bit.
///
/// # Errors
/// The outer error for invalid options; the inner ones per lane, as [`steady_state`]'s.
pub fn steady_states(
    batch: &mut ExactBatch,
    opts: &SteadyOptions,
) -> Result<Vec<Result<SteadyState, SimError>>, SimError> {
    check_options(opts)?;
    let lanes = batch.len();
    let mut out: Vec<Option<Result<SteadyState, SimError>>> = (0..lanes).map(|_| None).collect();
    let mut returns = Vec::with_capacity(lanes);
    for (i, slot) in out.iter_mut().enumerate() {
        let lane = batch.lane_mut(i);
        let period = lane.model().period();
        if !on_section(lane.tau(), period) {
            if let Err(e) = next_section(lane, None) {
                *slot = Some(Err(e));
            }
        }
        returns.push(ReturnHistory::new(opts, batch.lane(i).state()));
    }
    loop {
        let active: Vec<bool> = out.iter().map(Option::is_none).collect();
        let Some(tau) = (0..lanes)
            .filter(|&i| active[i])
            .map(|i| batch.lane(i).tau())
            .min_by(f64::total_cmp)
        else {
            break;
        };
        // the lanes on the earliest section go on together (all of them when they started
        // together)
        let period = batch.lane(0).model().period();
        let target = section_after(tau, period);
        let go: Vec<bool> = (0..lanes)
            .map(|i| active[i] && section_after(batch.lane(i).tau(), period) == target)
            .collect();
        let results = batch.advance_to(target, &go)?;
        for (i, r) in results.into_iter().enumerate() {
            if !go[i] {
                continue;
            }
            if let Err(e) = r {
                out[i] = Some(Err(e));
                continue;
            }
            let found = returns[i].push(batch.lane(i).state(), opts);
            if found.is_some() || returns[i].exhausted(opts) {
                out[i] = Some(record(batch.lane_mut(i), found, returns[i].k, opts));
            }
        }
    }
    Ok(out
        .into_iter()
        .map(|r| r.expect("every lane ends with a result"))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::bifurcation::random_state;
    use crate::integrate::{build, IntegratorOptions};
    use crate::model::CantileverModel;
    use crate::params::Params;
    use crate::LawKind;

    /// Reusing a step's end values for the next step's start changes nothing: every start's
    /// values equal, bit for bit, those formed at the start, and so do the statistics of an
    /// observer that forms both ends of every step — for the exact propagator (linear law,
    /// N = 3 and 10) and for the impact law, whose restitution moves the state at an impact
    /// (the start then differs from the end before it, and its values must be formed).
    #[test]
    fn end_values_carried_over_equal_end_values_formed() {
        for (law, modes) in [("linear", 3), ("linear", 10), ("impact", 3)] {
            let law: LawKind = law.parse().unwrap();
            let p = Params {
                modes,
                contact_law: law.with_groups(None, None, None),
                ..Params::default()
            };
            let model = CantileverModel::new(&p).unwrap();
            let z0 = random_state(&model, 3, 1);
            let mut it = build(&model, IntegratorOptions::default(), 0.0, &z0).unwrap();
            advance(it.as_mut(), 20.0 * p.period()).unwrap();
            let (mut carried, mut formed) = (StatsObserver::default(), StatsObserver::default());
            let (mut events, mut moved) = (0, 0);
            let mut prev_end: Option<(f64, DVector<f64>)> = None;
            advance_dyn(it.as_mut(), 30.0 * p.period(), &mut |it, st, before| {
                let (got, want) = (
                    carried.start_values(it.model(), st.tau0, before),
                    EndValues::at(it.model(), st.tau0, before),
                );
                assert_eq!(
                    format!("{got:?}"),
                    format!("{want:?}"),
                    "at τ = {}",
                    st.tau0
                );
                carried.observe(it, st, before);
                formed.last_end = None;
                formed.observe(it, st, before);
                events += usize::from(st.event.is_some());
                moved += usize::from(matches!(&prev_end, Some((_, z)) if z != before));
                let z1 = st.event.as_ref().map_or(it.state(), |e| &e.state);
                prev_end = Some((st.tau1, z1.clone()));
                Ok(())
            })
            .unwrap();
            let (a, b) = (carried.finish(10), formed.finish(10));
            assert_eq!(format!("{a:?}"), format!("{b:?}"), "{law:?}, N = {modes}");
            assert!(events > 0, "{law:?}: the tip taps");
            if law == LawKind::Impact {
                // (N = 3: 35 impacts, each moving the state)
                assert!(
                    moved > events / 2,
                    "impacts move the state: {moved} of {events}"
                );
            }
        }
    }
}
