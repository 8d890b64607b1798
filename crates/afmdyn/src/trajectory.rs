//! Trajectories: sampled time series, switching events, the stroboscopic Poincaré section,
//! per-period energy bookkeeping and the body-contact check; `chunked`: a long run recorded in
//! chunks of whole periods.

#[cfg(feature = "files")]
pub(crate) mod chunked;

use crate::error::{finite, SimError};
use crate::galerkin::Region;
use crate::integrate::{advance, Integrator, Observed, Step, SwitchEvent};
use crate::model::{weighted_displacement, BodyContactCheck, CantileverModel};
use crate::system::EventKind;
use gauss_quad::legendre::GaussLegendre;
use nalgebra::DVector;
use std::num::NonZeroUsize;

/// One sample of the time series.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// τ.
    pub tau: f64,
    /// V_T (eq. 8).
    pub v_t: f64,
    /// W(1,τ).
    pub w_tip: f64,
    /// ∂W(1,τ)/∂τ.
    pub w_tip_dot: f64,
    /// Region at the sample.
    pub region: Region,
    /// Tip–sample force F_c (repulsive positive; α4 δ + α6 δ̇ for the linear law in contact).
    pub contact_force: f64,
    /// State (a, ȧ) and the law's internal states, shape `[2N + m]`.
    pub state: DVector<f64>,
}

impl Sample {
    /// Sample of `model` at (τ, z) in region `r`.
    pub fn new(model: &CantileverModel, r: Region, tau: f64, z: &DVector<f64>) -> Self {
        Sample {
            tau,
            v_t: model.v_t(tau, z),
            w_tip: model.w_tip(z),
            w_tip_dot: model.w_tip_dot(z),
            region: r,
            contact_force: model.contact_force(r, tau, z),
            state: z.clone(),
        }
    }
}

/// Energy balance of one drive period: ΔE = W_base − D_beam − D_contact (+ residual).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergyBalance {
    /// Start of the period.
    pub tau0: f64,
    /// Stored energy at the start.
    pub e_start: f64,
    /// Stored energy at the end.
    pub e_end: f64,
    /// ∫ P_base dτ.
    pub base_work: f64,
    /// ∫ α3 ẊᵀẊ dτ.
    pub beam_dissipation: f64,
    /// ∫ α6 V̇_T² dτ over contact.
    pub contact_dissipation: f64,
}

impl EnergyBalance {
    /// The balance of a period that starts at `tau0` with the stored energy `e_start`.
    fn open(tau0: f64, e_start: f64) -> Self {
        EnergyBalance {
            tau0,
            e_start,
            e_end: 0.0,
            base_work: 0.0,
            beam_dissipation: 0.0,
            contact_dissipation: 0.0,
        }
    }

    /// (e_end − e_start) − (base_work − beam_dissipation − contact_dissipation).
    pub(crate) fn residual(&self) -> f64 {
        (self.e_end - self.e_start)
            - (self.base_work - self.beam_dissipation - self.contact_dissipation)
    }
}

/// Largest per-period residual of an energy balance ([`EnergyBalance::residual`]):
/// (absolute, relative to the period's largest term). The relative residual is +∞ for a nonzero
/// (or NaN) residual of a period whose terms are all 0.
pub(crate) fn energy_residual(energy: &[EnergyBalance]) -> (f64, f64) {
    let (mut abs, mut rel) = (0.0f64, 0.0f64);
    for e in energy {
        let r = e.residual().abs();
        let scale = [
            e.e_start,
            e.e_end,
            e.base_work,
            e.beam_dissipation,
            e.contact_dissipation,
        ]
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()));
        abs = abs.max(r);
        if scale > 0.0 {
            rel = rel.max(r / scale);
        } else if r > 0.0 || r.is_nan() {
            rel = f64::INFINITY;
        }
    }
    (abs, rel)
}

/// What to record along a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordSpec {
    /// Periods to run and discard before recording (transient).
    pub transient_periods: f64,
    /// Length of the recorded part, in τ.
    pub record_tau: f64,
    /// Samples per drive period in the recorded part (0: none).
    pub samples_per_period: usize,
    /// Integrate the energy balance per period (Gauss–Legendre on the dense output).
    pub energy: bool,
    /// Check the body-contact condition (Fig. 2f) at every step of the recorded part.
    pub body_contact: bool,
}

/// A recorded run.
#[derive(Debug, Clone, Default)]
pub struct Trajectory {
    /// Samples of the recorded part.
    pub samples: Vec<Sample>,
    /// Switchings of the recorded part.
    pub events: Vec<SwitchEvent>,
    /// Stroboscopic section τ = 2πk/Ω (drive phase 0) in the recorded part: (τ, z).
    pub poincare: Vec<(f64, DVector<f64>)>,
    /// Energy balance per complete period of the recorded part.
    pub energy: Vec<EnergyBalance>,
    /// Whether any beam point other than the tip reached the substrate (Fig. 2f).
    pub body_contact: bool,
    /// Final time.
    pub tau_end: f64,
    /// Final state.
    pub final_state: DVector<f64>,
    /// Final region.
    pub final_region: Region,
}

/// The samples of a recording in one flat buffer, a row of [`SampleRows::width`] = 6 + 2N
/// values per sample: τ, V_T, W(1,τ), ∂W(1,τ)/∂τ, in contact (1) or not (0), F_c, a_1..a_N,
/// ȧ_1..ȧ_N — the columns of `afmdyn simulate`'s time series, with no allocation per sample.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct SampleRows {
    width: usize,
    data: Vec<f64>,
}

impl SampleRows {
    /// The values of a row before the state.
    pub(crate) const LEADING: usize = 6;

    /// Empty rows for states of `dim` = 2N values.
    pub(crate) fn new(dim: usize) -> Self {
        SampleRows {
            width: Self::LEADING + dim,
            data: Vec::new(),
        }
    }

    /// Values per row, 6 + 2N.
    #[cfg(feature = "files")]
    pub(crate) fn width(&self) -> usize {
        self.width
    }

    /// Number of samples.
    pub(crate) fn len(&self) -> usize {
        self.data.len().checked_div(self.width).unwrap_or(0)
    }

    /// All rows, one after the other.
    #[cfg(feature = "files")]
    pub(crate) fn as_slice(&self) -> &[f64] {
        &self.data
    }

    /// Row `i`.
    pub(crate) fn row(&self, i: usize) -> &[f64] {
        &self.data[i * self.width..(i + 1) * self.width]
    }

    /// Sample `i` as a [`Sample`].
    pub(crate) fn sample(&self, i: usize) -> Sample {
        Sample::from_row(self.row(i))
    }

    fn clear(&mut self) {
        self.data.clear();
    }

    /// Append the row of the state `z` at τ in region `r`, given (sin Ωτ, cos Ωτ).
    fn push(&mut self, model: &CantileverModel, r: Region, tau: f64, sc: (f64, f64), z: &[f64]) {
        let [v_t, w, wd, force] = model.sample_values(r, tau, sc, z);
        let contact = f64::from(u8::from(r == Region::Contact));
        self.data
            .extend_from_slice(&[tau, v_t, w, wd, contact, force]);
        self.data.extend_from_slice(z);
    }
}

impl Sample {
    /// The sample of a row of [`SampleRows`].
    pub(crate) fn from_row(row: &[f64]) -> Self {
        Sample {
            tau: row[0],
            v_t: row[1],
            w_tip: row[2],
            w_tip_dot: row[3],
            region: if row[4] != 0.0 {
                Region::Contact
            } else {
                Region::Free
            },
            contact_force: row[5],
            state: DVector::from_column_slice(&row[SampleRows::LEADING..]),
        }
    }
}

/// Samples whose drive phase (sin Ωτ_i, cos Ωτ_i) is advanced by the rotation of one sample
/// interval before it is formed again from τ_i (see [`SamplePhase`]).
const PHASE_REANCHOR: u64 = 256;

/// The drive phase at the sample times τ_i = start + i·dt: sin and cos of Ωτ_i formed at the
/// first sample and every [`PHASE_REANCHOR`] samples, and turned by (sin Ω dt, cos Ω dt) in
/// between (about an ulp of rounding per turn: ≤ 256 ε, below the ulp of Ωτ_i itself at
/// τ ≳ 10⁻¹), instead of a sine and a cosine per sample.
struct SamplePhase {
    omega: f64,
    rot: (f64, f64),
    at: Option<(u64, u64, (f64, f64))>,
}

impl SamplePhase {
    fn new(omega: f64, dt: f64) -> Self {
        SamplePhase {
            omega,
            rot: (omega * dt).sin_cos(),
            at: None,
        }
    }

    /// (sin Ωτ_i, cos Ωτ_i) at τ_i = `tau`, sample `i`.
    fn at(&mut self, i: u64, tau: f64) -> (f64, f64) {
        let sc = match self.at {
            Some((j, anchor, (s, c))) if i == j + 1 && i - anchor < PHASE_REANCHOR => {
                let (sd, cd) = self.rot;
                self.at = Some((i, anchor, (s * cd + c * sd, c * cd - s * sd)));
                return self.at.map_or((0.0, 1.0), |a| a.2);
            }
            _ => (self.omega * tau).sin_cos(),
        };
        self.at = Some((i, i, sc));
        sc
    }
}

/// Samples formed at once from the last step's dense output (a buffer of states).
const SAMPLE_BATCH: usize = 64;

/// Whether the beam body touches the substrate at the end of the last step of `integ`:
/// [`BodyContactCheck::touches_observed`], the state formed only where the integrator's bound
/// does not already keep every station off the substrate.
fn step_touches(b: &BodyContactCheck, integ: &mut dyn Integrator) -> bool {
    b.touches_observed(&mut Observed::new(integ))
}

/// [`BodyContactCheck::touches`] at a sample (τ, z): the bound held against the lowest base
/// first (no sine), then the stations.
fn sample_touches(b: &BodyContactCheck, tau: f64, z: &[f64]) -> bool {
    let a = &z[..b.reach.len()];
    let lowest = b.lowest_base() - 4.0 * f64::EPSILON;
    if BodyContactCheck::spared(weighted_displacement(&b.reach, a), lowest) {
        return false;
    }
    b.touches_at(b.base(tau), a)
}

/// Run `integ` from its current state: a transient, then the recorded part.
///
/// # Errors
/// [`SimError`] for negative or non-finite lengths, or a failure of the integrator.
pub fn record(integ: &mut dyn Integrator, spec: &RecordSpec) -> Result<Trajectory, SimError> {
    let mut rows = SampleRows::default();
    let mut out = record_rows(integ, spec, &mut rows)?;
    out.samples = (0..rows.len()).map(|i| rows.sample(i)).collect();
    Ok(out)
}

/// [`record`] with the samples written into `rows` (cleared first) instead of
/// [`Trajectory::samples`], which stays empty: no allocation per sample.
///
/// The integrator takes its own steps, in spans ([`crate::integrate::Spans::step_span`]: the exact
/// propagator's natural grid, a span ending only at the drive-period sections, the end,
/// switchings, and where its bound of the beam's displacement does not keep the body off the
/// substrate), and the samples τ_i = start + i·T/S inside each span are formed from its dense
/// output ([`Integrator::dense_states_into`]; for the exact propagator in closed form), not by
/// ending a step at every sample. The energy balance is integrated over those spans (closed
/// forms where the integrator has them, [`Integrator::last_step_rate_integrals`]: for the
/// exact propagator over a whole stint piece at once); the plain state is formed only at the
/// sections, the energy cuts, the events and where the body-contact bound does not decide. A sample at the end of a step that ended at an event, and the last
/// one where it falls beyond the end by less than 1e-12 (1 + |τ|), are the integrator's state
/// there (after the event's jump).
///
/// # Errors
/// As [`record`].
pub(crate) fn record_rows(
    integ: &mut dyn Integrator,
    spec: &RecordSpec,
    rows: &mut SampleRows,
) -> Result<Trajectory, SimError> {
    check_lengths(spec)?;
    let model =
        crate::tip_sample::require_cantilever(integ.system(), "the recorded trajectory")?.clone();
    let period = model.period();
    let start = integ.tau() + spec.transient_periods * period;
    advance(integ, start)?;
    let end = start + spec.record_tau;
    let dim = integ.state().len();
    *rows = SampleRows::new(dim);
    rows.clear();
    let mut out = Trajectory::default();
    let body = spec.body_contact.then(|| BodyContactCheck::new(&model, 64));
    let spp = spec.samples_per_period;
    let dt = if spp > 0 {
        period / spp as f64
    } else {
        f64::INFINITY
    };
    let mut sampler = Sampler {
        start,
        dt,
        end,
        next: 0,
        phase: SamplePhase::new(model.omega(), dt),
        states: vec![0.0; SAMPLE_BATCH * dim],
    };
    let mut k_period = (start / period).ceil() as i64;
    if spp > 0 {
        let sc = sampler.phase.at(0, integ.tau());
        let (tau, r) = (integ.tau(), integ.region());
        rows.push(&model, r, tau, sc, integ.state().as_slice());
        sampler.next = 1;
    }
    let record_section = |tau: f64, z: &DVector<f64>, out: &mut Trajectory, k_period: &mut i64| {
        out.poincare.push((tau, z.clone()));
        *k_period += 1;
    };
    let at_section = |tau: f64, k_period: i64| {
        let t_sec = k_period as f64 * period;
        tau == t_sec || (tau - t_sec).abs() <= round_off(tau)
    };
    if at_section(integ.tau(), k_period) {
        let tau = integ.tau();
        record_section(tau, integ.state(), &mut out, &mut k_period);
    }
    let mut balance = Balance::new(&model, integ, (k_period as f64) * period);
    while integ.tau() < end {
        crate::error::cancelled()?;
        let next_section = k_period as f64 * period;
        // a span proven free of body contact is checked at its end only
        let step = crate::integrate::step_span(integ, end.min(next_section), body.as_ref())?;
        if spec.energy && step.tau1 > step.tau0 {
            balance.add_step(&model, integ, &step);
        }
        if spp > 0 {
            out.body_contact |= sampler.samples_in(&model, integ, &step, rows, body.as_ref());
        }
        let tau = integ.tau();
        if let Some(b) = &body {
            out.body_contact |= step_touches(b, integ);
        }
        if let Some(e) = step.event {
            if spec.energy {
                balance.add_event(&model, &e);
            }
            out.events.push(e);
        }
        let cut = balance.next_cut;
        if spec.energy && (tau >= cut || (tau - cut).abs() <= round_off(tau)) {
            balance.cut(&model, integ, step.region, period, &mut out.energy);
        }
        if at_section(tau, k_period) {
            crate::integrate::form_state(integ);
            record_section(tau, integ.state(), &mut out, &mut k_period);
        }
    }
    crate::integrate::form_state(integ);
    out.tau_end = integ.tau();
    out.final_state = integ.state().clone();
    out.final_region = integ.region();
    Ok(out)
}

/// The round-off tolerance 1e-12 (1 + |τ|) of a time τ of the recording.
#[inline]
fn round_off(tau: f64) -> f64 {
    1e-12 * (1.0 + tau.abs())
}

/// The transient and the recorded length of `spec`: both finite, then both ≥ 0.
fn check_lengths(spec: &RecordSpec) -> Result<(), SimError> {
    let lengths = [
        ("transient_periods", spec.transient_periods),
        ("record_tau", spec.record_tau),
    ];
    for (name, v) in lengths {
        finite(name, v)?;
    }
    match lengths.into_iter().find(|&(_, v)| v < 0.0) {
        Some((name, v)) => Err(SimError::out_of_range(name, v, "must be >= 0")),
        None => Ok(()),
    }
}

/// The samples τ_i = start + i·dt of a recording that ends at `end`: the next one's index and
/// what forms them.
struct Sampler {
    start: f64,
    dt: f64,
    end: f64,
    /// The next sample's index.
    next: u64,
    phase: SamplePhase,
    /// A batch of states (of the state's dimension) formed from a step's dense output.
    states: Vec<f64>,
}

impl Sampler {
    /// The samples inside `step`, just taken by `integ`, into `rows`, from its dense output; at
    /// its end after an event, and beyond the end of the recording by round-off, the state
    /// there. Whether a sample's beam body touches the substrate (`body`).
    #[inline]
    fn samples_in(
        &mut self,
        model: &CantileverModel,
        integ: &mut dyn Integrator,
        step: &Step,
        rows: &mut SampleRows,
        body: Option<&BodyContactCheck>,
    ) -> bool {
        let (start, dt, dim) = (self.start, self.dt, self.states.len() / SAMPLE_BATCH);
        let tau1 = step.tau1;
        let limit = if tau1 >= self.end {
            tau1 + round_off(tau1)
        } else {
            tau1
        };
        let mut touches = false;
        loop {
            let mut count = 0usize;
            while count < SAMPLE_BATCH {
                let t = start + (self.next + count as u64) as f64 * dt;
                let dense = t < tau1 || (t == tau1 && step.event.is_none());
                if !dense {
                    break;
                }
                count += 1;
            }
            if count > 0 {
                let buf = &mut self.states[..count * dim];
                integ.dense_states_into(start, dt, self.next, buf);
                for (j, z) in buf.chunks_exact(dim).enumerate() {
                    let i = self.next + j as u64;
                    let t = start + i as f64 * dt;
                    let sc = self.phase.at(i, t);
                    rows.push(model, step.region, t, sc, z);
                    if let Some(b) = body {
                        touches |= sample_touches(b, t, z);
                    }
                }
                self.next += count as u64;
            }
            if count < SAMPLE_BATCH {
                break;
            }
        }
        let t = start + self.next as f64 * dt;
        if t <= limit {
            // at the step's end (after an event), or beyond the end by round-off: the
            // state there
            crate::integrate::form_state(integ);
            let sc = (model.omega() * tau1).sin_cos();
            rows.push(model, integ.region(), tau1, sc, integ.state().as_slice());
            self.next += 1;
        }
        touches
    }
}

/// The energy balance of the drive period under way: its terms so far, where it ends, and the
/// quadrature of a step without closed forms.
struct Balance {
    acc: EnergyBalance,
    next_cut: f64,
    gl: GaussLegendre,
}

impl Balance {
    /// The balance of the period from `integ`'s state, cut first at the section `section` (or
    /// a period on, when the state is there already).
    fn new(model: &CantileverModel, integ: &dyn Integrator, section: f64) -> Self {
        let tau = integ.tau();
        let e_start = model.energy(integ.region(), tau, integ.state());
        let period = model.period();
        Balance {
            acc: EnergyBalance::open(tau, e_start),
            next_cut: if section <= tau {
                section + period
            } else {
                section
            },
            gl: GaussLegendre::new(NonZeroUsize::new(12).expect("nonzero")),
        }
    }

    /// The base work and the losses over `step`, just taken by `integ`: the integrator's closed
    /// forms ([`Integrator::last_step_rate_integrals`]), else Gauss–Legendre on its dense
    /// output.
    #[inline]
    fn add_step(&mut self, model: &CantileverModel, integ: &mut dyn Integrator, step: &Step) {
        let acc = &mut self.acc;
        if let Some([pb, db, dc]) = integ.last_step_rate_integrals() {
            acc.base_work += pb;
            acc.beam_dissipation += db;
            acc.contact_dissipation += dc;
            return;
        }
        let r = step.region;
        let (mut pb, mut db, mut dc) = (0.0, 0.0, 0.0);
        for (x, w) in self.gl.iter() {
            let tau = 0.5 * (step.tau1 - step.tau0) * (x + 1.0) + step.tau0;
            let z = integ.dense_state(tau);
            let p = model.power(r, tau, &z);
            pb += w * p.base;
            db += w * p.beam_dissipation;
            dc += w * p.contact_dissipation;
        }
        let half = 0.5 * (step.tau1 - step.tau0);
        acc.base_work += half * pb;
        acc.beam_dissipation += half * db;
        acc.contact_dissipation += half * dc;
    }

    /// The energy of the switching `e`: an impact's impulse (the loss in the sample and the
    /// work done on the clamped frame), a hysteretic law's drop of potential where the contact
    /// forms (JKR's neck).
    fn add_event(&mut self, model: &CantileverModel, e: &SwitchEvent) {
        let r = match e.kind {
            EventKind::Impact => model.law().restitution(),
            EventKind::Stick => Some(0.0),
            _ => None,
        };
        if let Some(r) = r {
            let (loss, base) = model.impact_energy(e.tau, e.v_t_dot, r);
            self.acc.contact_dissipation += loss;
            self.acc.base_work += base;
        }
        if e.kind == EventKind::Switching {
            self.acc.contact_dissipation += model.switching_loss(e.from, e.to, e.tau, &e.state);
        }
    }

    /// The period's balance closed at `integ`'s time (the step's end, in `region` until then)
    /// into `energy`, and the next period's opened.
    fn cut(
        &mut self,
        model: &CantileverModel,
        integ: &mut dyn Integrator,
        region: Region,
        period: f64,
        energy: &mut Vec<EnergyBalance>,
    ) {
        crate::integrate::form_state(integ);
        let (tau, z) = (integ.tau(), integ.state());
        self.acc.e_end = model.energy(region, tau, z);
        energy.push(self.acc);
        // the same state and region: the same energy
        let e_start = if integ.region() == region {
            self.acc.e_end
        } else {
            model.energy(integ.region(), tau, z)
        };
        self.acc = EnergyBalance::open(tau, e_start);
        self.next_cut += period;
    }
}
