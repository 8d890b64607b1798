//! From a request to its document in one call: [`run`]`(analysis, model, progress)` →
//! [`Document`], the typed result together with the JSON document that `--json` prints and
//! Python's `to_dict()` returns (with the `"si"` block when the model came from a probe file).
//!
//! Every analysis whose result is one value implements [`Analysis`]: `modes`, `orbit`,
//! `continuation`, `lyapunov`, `attractors`, `observe`, `converge`, `approach`, `resonance`,
//! and the studies that run in memory here and resumably in a front end's store — `basins`,
//! `attractors --sweep`, `approach` and `resonance`. What a request is ([`Request`]: its
//! checks and declared cost) is here, beside the requests; how it runs (every `Analysis`
//! implementation) is the study layer's (`crate::study`). The two whose results are streams
//! enter through it too: `simulate` streamed to files
//! ([`crate::request::simulate_stream::SimulateStream`]: recorded in chunks by
//! `crate::trajectory::chunked::record_chunked`, its series' bytes held against the files'
//! budget, [`crate::request::analyses::SimulateSpan`]), and `bifurcation`, whose `execute` is
//! the in-memory sweep; a front end that runs the sweep resumably into a store of its own
//! (the sweep's study into its checkpoint) checks its cost first by [`admit`].
//!
//! [`Progress`] is the sink of the run's progress and its cancel flag: the analyses count
//! their units of work in it (random starts, curve and branch points, drive periods, mode
//! counts) and stop with [`SimError::Cancelled`] when it is cancelled. `modes`, `orbit` and
//! `observe` are one short computation each and neither count nor check it.

use super::costs::{check_cost_advising, stepped_cost};
use super::curves::{approach_request, resonance_request, CurveRequest};
use super::limits::Cost;
use crate::analysis::lock_in_noise::ThermalLockIn;
use crate::analysis::progress::Progress;
use crate::analysis::stepped::torus::{uses_torus, TorusOptions};
use crate::analysis::stepped::SteppedSpec;
use crate::error::SimError;
use crate::params::Params;
use crate::probe::Probe;
use crate::report::{self, CurveUnits};
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// The model of a run: the resolved parameters and the probe file they came from, if any
/// (the SI scales of the document; [`crate::request::ModelSpec::resolve`] gives both).
#[derive(Debug, Clone)]
pub struct Resolved {
    /// The dimensionless parameters (α1…α6, Ω, N, the law).
    pub params: Params,
    /// The probe, when the model was built from one.
    pub probe: Option<Probe>,
}

impl Resolved {
    /// A model given by its parameters alone (no SI block in the documents).
    pub fn plain(params: Params) -> Self {
        Resolved {
            params,
            probe: None,
        }
    }

    /// The units of a curve's or a tap's document: SI (m, N, J, and with `hz` frequencies in
    /// Hz: a resonance's, FM's and PeakForce's) with a probe, else the model's.
    pub(crate) fn units(&self, hz: bool) -> CurveUnits {
        CurveUnits::of(self.probe.as_ref(), hz)
    }
}

/// A typed result and its JSON document.
#[derive(Debug, Clone)]
pub struct Document<T> {
    /// The result.
    pub output: T,
    /// The document (`--json`, Python's `to_dict()`), with `"si"` for a probe's model.
    pub json: Value,
}

/// What a user asks, before any work: its name, its checks on the model and its declared cost
/// ([`admit`]), and what it uses of a probe. Every [`Analysis`] is one.
pub trait Request {
    /// Check every option on `model` without computing (a front end calls it before its side
    /// effects, such as locking an output directory; [`run`] calls it first).
    ///
    /// # Errors
    /// The request's validation errors, naming the parameter and its range.
    fn validate(&self, model: &Resolved) -> Result<(), SimError>;
    /// The request's name in its refusals (`"attractors"`).
    fn name(&self) -> &'static str;
    /// What the request uses of a probe, which a front end reads it for
    /// ([`crate::probe::Probe::parse_for`]): the oscillating lever by default.
    fn probe_needs(&self) -> crate::probe::ProbeNeeds {
        crate::probe::ProbeNeeds::Oscillation
    }
    /// What the request costs on `model` — peak memory and work in mode-periods
    /// (`super::costs`) — estimated for the worst case its options allow, before any work;
    /// [`run`] refuses it beyond `super::limits::MAX_REQUEST_BYTES` or
    /// `super::limits::MAX_REQUEST_WORK`. Called after [`Request::validate`].
    ///
    /// # Errors
    /// As the analysis' validation.
    fn cost(&self, model: &Resolved) -> Result<Cost, SimError>;
    /// What a refusal over the budget advises: the fields whose size drives the cost
    /// ([`Request::cost`]), named as the request names them.
    const COST_ADVICE: &'static str =
        "ask for fewer points, samples, cells or periods, or a shorter transient (max_periods)";
    /// The parameters the result was computed at, for the SI block: `model.params`, unless
    /// the analysis moves them (a resonance curve under a probe is the free resonance,
    /// `super::curves::free_resonance_base`).
    ///
    /// # Errors
    /// As the analysis' validation.
    fn computed_at(&self, model: &Resolved) -> Result<Params, SimError> {
        Ok(model.params)
    }
}

/// A [`Request`] that [`run`] takes from its model to its [`Document`]: its execution, its
/// document and its presentation (implemented beside the studies, `crate::study`).
pub trait Analysis: Request {
    /// The typed result.
    type Output;
    /// Compute the result on `model` (validated and admitted), counting in `progress`.
    ///
    /// # Errors
    /// The analysis' failures; [`SimError::Cancelled`] when `progress` is cancelled.
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError>;
    /// The document of a result, without the SI block ([`run`] adds it).
    ///
    /// # Errors
    /// [`SimError`] where the document needs the model built again (an invalid `params`).
    fn report(&self, model: &Resolved, output: &Self::Output) -> Result<Value, SimError>;
    /// How many of `output`'s parts converged, which [`document`] writes into every document
    /// and warns of where one did not (no default: every result states it).
    fn convergence(&self, output: &Self::Output) -> report::Convergence;
    /// The parameters `output` holds, for its SI block ([`document`]): [`Request::computed_at`],
    /// unless the result found one of them (a PeakForce setpoint's rest distance z_c).
    ///
    /// # Errors
    /// As [`Request::computed_at`].
    fn found_at(&self, model: &Resolved, _output: &Self::Output) -> Result<Params, SimError> {
        self.computed_at(model)
    }
    /// The largest indentation max(−V_T, 0) of a result that has operating points in contact
    /// (in the model's length unit), which [`document`] holds against the contact law's
    /// validity under a probe (`crate::probe::Probe::indentation_warnings`); `None` (the
    /// default) for a result without one.
    fn largest_indentation(&self, _output: &Self::Output) -> Option<f64> {
        None
    }
    /// What the result shows besides its document ([`report::Presentation`]): the text
    /// summary in the [`Presenting`] units, its tables, datasets and figures as data, for every
    /// front end to write where it says (a front end keeps only the files `to.files` says:
    /// [`Destination::keep`]). A result whose files or document name the
    /// directory (`"csv"`: its path) adds them here, the document as printed in
    /// [`report::Presentation::document`]. Empty by default.
    ///
    /// # Errors
    /// [`SimError`] where the presentation needs the model built again (an invalid `params`).
    fn present(
        &self,
        _output: &Self::Output,
        _: Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        Ok(report::Presentation::default())
    }
}

pub use crate::report::present::Destination;

/// What a result is presented with ([`Analysis::present`]), besides the result itself.
#[derive(Clone, Copy)]
pub struct Presenting<'a> {
    /// The model the result was computed on.
    pub model: &'a Resolved,
    /// The result's JSON ([`run`]'s).
    pub document: &'a Value,
    /// The units of the text summary.
    pub units: report::TextUnits,
    /// Where a front end writes the result's files.
    pub to: Destination<'a>,
}

/// What a refusal of a stepped curve (approach, resonance, bimodal) advises.
const CURVE_ADVICE: &str = "ask for fewer points or trace samples (traces), or branches = false";

/// Run `analysis` on `model`: [`Request::validate`], its [`Request::cost`] held against the
/// budgets (`check_cost`), [`Analysis::execute`], then its document with the SI block of the
/// probe (`report::with_si`).
///
/// # Errors
/// As [`Analysis::execute`] and [`Analysis::report`]; [`SimError::Budget`] naming the request,
/// its cost and the budget, before any work; [`SimError::Cancelled`] when `progress` is
/// cancelled before the start.
pub fn run<A: Analysis + ?Sized>(
    analysis: &A,
    model: &Resolved,
    progress: &Progress,
) -> Result<Document<A::Output>, SimError> {
    progress.check()?;
    admit(analysis, model)?;
    run_admitted(analysis, model, progress)
}

/// [`run`] after [`admit`]: [`Analysis::execute`] and the document, for a front end that
/// admitted the request itself before its side effects (locking its output directory), so
/// that a request is admitted once per run.
///
/// # Errors
/// As [`run`], less the admission's.
pub fn run_admitted<A: Analysis + ?Sized>(
    analysis: &A,
    model: &Resolved,
    progress: &Progress,
) -> Result<Document<A::Output>, SimError> {
    progress.check()?;
    // the document too: a report may refine what it lists (a setpoint's operating points)
    let (output, json) = progress.watch(|| {
        let output = analysis.execute(model, progress)?;
        let json = document(analysis, model, &output)?;
        Ok::<_, SimError>((output, json))
    })?;
    // a run cancelled midway may have turned the cancel into failed parts: never a result
    progress.check()?;
    Ok(Document { json, output })
}

/// Admit `analysis` on `model` before any work: [`Request::validate`], then its
/// [`Request::cost`] held against the budgets (`check_cost`) — [`run`]'s first step, and a
/// front end's for a request it runs itself (a study into its store, a run streamed to files).
///
/// # Errors
/// A probe that does not serve the request (`crate::probe::Probe::serves`); the request's
/// validation errors; [`SimError::Budget`] naming the request, its cost and the budget.
pub fn admit<A: Analysis + ?Sized>(analysis: &A, model: &Resolved) -> Result<(), SimError> {
    validate(analysis, model)?;
    let advice = A::COST_ADVICE;
    check_cost_advising(analysis.name(), analysis.cost(model)?, advice, advice)
}

/// [`admit`] without the cost: the probe held against what the request uses of it
/// ([`crate::probe::Probe::serves`]), then [`Request::validate`] — what a front end checks
/// before its side effects.
///
/// # Errors
/// As [`admit`], less the budget's.
pub(crate) fn validate<A: Request + ?Sized>(
    analysis: &A,
    model: &Resolved,
) -> Result<(), SimError> {
    if let Some(p) = &model.probe {
        p.serves(analysis.name(), analysis.probe_needs())?;
    }
    analysis.validate(model)
}

/// The document of `analysis`'s `output` on `model`: [`Analysis::report`] with the SI block of
/// the probe (`report::with_si`) — [`run`]'s, and a front end's for a study it ran into a
/// store of its own.
///
/// # Errors
/// As [`Analysis::report`] and [`Request::computed_at`].
pub fn document<A: Analysis + ?Sized>(
    analysis: &A,
    model: &Resolved,
    output: &A::Output,
) -> Result<Value, SimError> {
    let doc = analysis.report(model, output)?;
    let mut doc = report::with_si(
        doc,
        model.probe.as_ref(),
        &analysis.found_at(model, output)?,
    );
    // the result's validity against the law's assumptions, in every document of a probe
    if let (Some(p), Some(d)) = (&model.probe, analysis.largest_indentation(output)) {
        if let Some(w) = doc.get_mut("warnings").and_then(Value::as_array_mut) {
            let warnings = p.indentation_warnings(d * p.scales.length_m);
            w.extend(warnings.into_iter().map(Value::from));
        }
    }
    analysis.convergence(output).write_into(&mut doc);
    // no missing value unsaid, and no document of missing values only
    report::audit_missing(&mut doc, analysis.name())?;
    Ok(doc)
}

request! {
    /// `approach`: the approach–retract curve over the rest distance z_c with its branches
    /// ([`crate::analysis::approach`]); `from`/`to`/`step` in metres with a probe, else in g₀.
    #[cfg_attr(feature = "schema", schemars(extend("x-swept" = "length")))]
    pub struct ApproachRequest {
        /// The curve's range and options.
        #[serde(flatten)]
        pub curve: CurveRequest,
        /// The amplitude setpoint A_sp/A₀ in (0, 1] (under a multifrequency drive A₁/A₀₁, of the
        /// first component, the one the feedback holds): the document gains a `"setpoint"` block
        /// with the operating points where the curve's amplitude equals it on each stable branch
        /// ([`crate::analysis::setpoint`]).
        pub setpoint: Option<f64>,
        /// Measure every point by the time average of a multifrequency drive
        /// ([`crate::analysis::stepped::average`]) instead of its periodic orbit; always so for a
        /// quasi-periodic drive ([`Params::is_quasiperiodic`]). No branches then.
        #[serde(skip_serializing_if = "std::ops::Not::not")]
        #[cfg_attr(feature = "schema", schemars(extend("default" = false)))]
        pub average: bool,
        /// Measure every point on the exact periodic orbit of the drive's common period even where
        /// a two-frequency drive repeats only after more than
        /// [`crate::analysis::stepped::torus::TORUS_PERIODS`] drive periods, whose points are
        /// otherwise measured on invariant circles ([`crate::analysis::stepped::torus`]; with
        /// branches and folds).
        #[serde(skip_serializing_if = "std::ops::Not::not")]
        #[cfg_attr(feature = "schema", schemars(extend("default" = false)))]
        constants(TORUS_PERIODS in crate::analysis::stepped::torus)
        pub exact: bool,
        /// The temperature T of the thermal force (K, > 0 and ≤ 1500; outside 200–500 K it warns,
        /// a value in °C?); `None` (the default): no noise. With one the document gains a
        /// `"thermal"` block: at every stable period-1 point of both sweeps the standard
        /// deviations of the lock-in's amplitude and phase under the lever's thermal force, by
        /// linear response about the orbit, noise within each period, switchings and the
        /// lock-in's filter included ([`crate::analysis::lock_in_noise`]); under a
        /// multifrequency drive (bimodal) each component's lock-in's too, on the exact orbits of
        /// the common period (none on time averages or invariant circles). Needs the probe's SI
        /// units; every law (the impact law's sticking holds the tip against the thermal force's
        /// part at it; SLS's dashpot adds its own).
        #[serde(skip_serializing_if = "Option::is_none")]
        pub temperature: Option<f64>,
        /// The lock-in's low-pass time constant τ_L (s; with `temperature`), ≥ 0 and at most
        /// 1 000 s; `None`: τ_c/4, τ_c = 2Q/ω₀ the lever's amplitude time (the PI scan's
        /// default). Its noise-equivalent bandwidth is about 1/(4τ_L).
        #[serde(skip_serializing_if = "Option::is_none")]
        pub time_constant: Option<f64>,
    }
}

impl ApproachRequest {
    /// The stepped sweep of `model` ([`approach_request`]).
    ///
    /// # Errors
    /// As [`approach_request`].
    pub fn spec(&self, model: &Resolved) -> Result<SteppedSpec, SimError> {
        if let Some(s) = self.setpoint {
            let (open, one) = (
                std::ops::Bound::Excluded(0.0),
                std::ops::Bound::Included(1.0),
            );
            let why = "must be in (0, 1]: the amplitude setpoint A_sp/A0";
            crate::error::within("setpoint", s, (open, one), why)?;
        }
        let average = self.average || model.params.is_quasiperiodic();
        let mut spec = approach_request(
            model.params,
            &self.curve,
            model.units(false).length,
            average,
        )?;
        if !average && !self.exact && uses_torus(&model.params) {
            spec.torus = Some(TorusOptions::default());
        }
        spec.noise = self.thermal(model)?;
        Ok(spec)
    }

    /// The thermal force and lock-in of the `"thermal"` block (model units): `None` without a
    /// temperature.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `temperature` (out of range, without a probe) or
    /// `time_constant` (out of range, or without a temperature).
    fn thermal(&self, model: &Resolved) -> Result<Option<ThermalLockIn>, SimError> {
        let needs = [("time_constant", self.time_constant)];
        let Some(kt) = super::limits::optional_kt(self.temperature, &needs, model)? else {
            return Ok(None);
        };
        let probe = model.probe.as_ref().expect("thermal_force checked it");
        let tc = super::image_scan::lock_in_time_constant(probe, self.time_constant)?;
        Ok(Some(ThermalLockIn {
            kt,
            time_constant: tc / probe.scales.time_s,
        }))
    }
}

request! {
    /// `resonance`: the resonance curve near mode `mode` with its branches
    /// ([`crate::analysis::resonance`]); `from`/`to`/`step` in Hz with a probe, else in Ω.
    #[cfg_attr(feature = "schema", schemars(extend("x-swept" = "frequency")))]
    pub struct ResonanceRequest {
        /// The mode k (1-based) whose resonance is swept.
        pub mode: usize = 1;
        flatten curve: CurveRequest,
    }
}

impl ResonanceRequest {
    /// The stepped sweep of `model` ([`resonance_request`]).
    ///
    /// # Errors
    /// As [`resonance_request`].
    pub fn spec(&self, model: &Resolved) -> Result<SteppedSpec, SimError> {
        let hz = model.units(true).hz_per_omega.unwrap_or(1.0);
        resonance_request(self.computed_at(model)?, self.mode, &self.curve, hz)
    }
}

/// `bimodal`: the approach curve of a drive with two or more components
/// (`super::curves::check_bimodal`), its files named `bimodal`; its refusals name
/// the approach curve it is.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Bimodal(pub ApproachRequest);

impl_request! {
    ApproachRequest, "approach", advice = CURVE_ADVICE, needs = Tapping;
    validate |r, model| r.spec(model).map(|_| ());
    cost |r, model| stepped_cost(&r.spec(model)?)
}

impl_request! {
    ResonanceRequest, "resonance", advice = CURVE_ADVICE;
    validate |r, model| r.spec(model).map(|_| ());
    cost |r, model| stepped_cost(&r.spec(model)?);
    computed_at |r, model| {
        crate::request::curves::free_resonance_base(model.params, model.probe.as_ref(), r.mode)
    }
}

impl_request! {
    Bimodal, "bimodal", advice = CURVE_ADVICE, needs = Tapping;
    validate |r, model| {
        crate::request::curves::check_bimodal(&model.params)?;
        r.0.validate(model)
    };
    cost |r, model| r.0.cost(model)
}
