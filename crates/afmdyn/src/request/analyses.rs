//! One request per analysis: its options with their defaults (those of `afmdyn <command>
//! --help` and of the Python functions), `validate()` holding every limit ([`super::limits`]);
//! where the analysis is one library call, its `run(params)` is the study layer's. Errors name the library's
//! parameters (`samples_per_period`, `max_period`); a front end spells them its own way
//! ([`SimError::spelled`]).
//!
//! Model values are not part of these requests: they resolve first, through
//! [`super::ModelSpec::resolve`], into the [`Params`] every `validate` and `run` takes.

use super::costs::{
    census_cost, newton_work, recorded_sample_bytes, state_bytes, steady_periods, MODEL_BYTES,
};
use super::limits::*;
use super::sweep::SweepRecord;
use crate::analysis::attractors::AttractorSpec;
use crate::analysis::bifurcation::SweepSpec;
use crate::analysis::continuation::ContinuationSpec;
use crate::analysis::global_continuation::{
    GlobalContinuationSpec, DEFAULT_MATCH_TOL, MAX_CONTINUATION_VALUES,
};
use crate::analysis::lyapunov::LyapunovOptions;
use crate::analysis::observables::Observables;
use crate::analysis::period::MAX_PERIOD;
use crate::analysis::shooting::ShootingOptions;
use crate::analysis::steady::SteadyOptions;
use crate::error::{in_range, within, SimError};
use crate::integrate::{IntegratorKind, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::DVector;
use serde_json::{json, Value};

mod start;
pub use start::{initial_state, IntegratorRequest, StartRequest, SteadyRequest};

fn check_period(period: Option<usize>) -> Result<(), SimError> {
    period.map_or(Ok(()), |n| in_range("period", n, 1..=MAX_PERIOD))
}

request! {
    /// `orbit`: a period-n orbit by Newton shooting, with its Floquet multipliers.
    pub struct OrbitRequest {
        /// The period n (1..=64); `None`: the period of the steady state reached, else 1.
        pub period: Option<usize>;
        flatten start: StartRequest,
    }
}

impl OrbitRequest {
    /// Check every option.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option.
    pub fn validate(&self) -> Result<(), SimError> {
        check_period(self.period)?;
        self.start.steady.options().map(|_| ())
    }
}

request! {
    /// `continuation`: pseudo-arclength continuation of a period-n branch in one parameter, and
    /// with `switch` the period-doubling cascade to [`CASCADE_FACTOR`] n.
    pub struct ContinuationRequest {
        /// The continued parameter: `omega` or `alpha1`..`alpha6` (or their names,
        /// `tip-mass-ratio`, …).
        pub param: SweepParam = SweepParam::Omega,
        /// The value where the continuation starts.
        pub from: f64 = 5.0,
        /// The end of the range.
        pub to: f64 = 1.0,
        /// The period n (1..=64); `None`: the period of the steady state reached at `from`, else 1.
        pub period: Option<usize>,
        /// At each period doubling, switch to the period-2n branch and continue it too,
        /// recursively up to period 8n (the period-doubling cascade).
        pub switch: bool = false;
        flatten start: StartRequest,
    }
}

impl ContinuationRequest {
    /// Check every option against `base`: both ends must be valid parameter sets.
    ///
    /// # Errors
    /// [`SimError::Params`] for an end out of range, [`SimError::OutOfRange`] naming the option.
    pub fn validate(&self, base: &Params) -> Result<(), SimError> {
        base.with(self.param, self.from).validate()?;
        base.with(self.param, self.to).validate()?;
        check_period(self.period)?;
        self.start.steady.options().map(|_| ())
    }
}

request! {
    /// `lyapunov`: the Lyapunov spectrum with saltation matrices and the 0–1 test.
    pub struct LyapunovRequest {
        /// The initial state (2N values); `None`: rest.
        pub initial: Option<Vec<f64>>,
        /// Drive periods discarded first; `None` (default): the model's derived transient cap
        /// ([`crate::analysis::steady::default_transient_cap`] at tol = 1e-8: 1 500 for the
        /// paper's beam, ≈ 1.9 Q ln(1e8) for a lever of quality factor Q).
        pub transient: Option<usize>,
        /// Drive periods averaged; transient + periods ≤ [`MAX_RUN_PERIODS`].
        constants(MAX_RUN_PERIODS)
        pub periods: usize = LyapunovOptions::default().periods,
        /// Blocks for the uncertainty, 2..=periods.
        pub blocks: usize = LyapunovOptions::default().blocks,
    }
}

impl LyapunovRequest {
    /// Check every option.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `periods` or `blocks` (`LyapunovOptions::validate`).
    pub fn validate(&self) -> Result<(), SimError> {
        let transient = self.transient.unwrap_or(MAX_STEADY_PERIODS);
        if transient as f64 + self.periods as f64 > MAX_RUN_PERIODS {
            return Err(SimError::out_of_range(
                "periods",
                format!("{} with transient = {transient}", self.periods),
                "a run may span at most 1e8 drive periods, transient included",
            ));
        }
        self.options(0).validate()
    }

    /// The options, the transient `derived` where none is given.
    pub(crate) fn options(&self, derived: usize) -> LyapunovOptions {
        LyapunovOptions {
            transient_periods: self.transient.unwrap_or(derived),
            periods: self.periods,
            blocks: self.blocks,
            ..LyapunovOptions::default()
        }
    }
}

request! {
    /// `attractors`: the coexisting attractors and their basin fractions from random starts.
    #[derive(Copy)]
    pub struct AttractorsRequest {
        /// Random initial states, 1..=[`MAX_ATTRACTOR_SAMPLES`].
        constants(MAX_ATTRACTOR_SAMPLES)
        pub samples: usize = 64,
        /// Seed of the initial states.
        pub seed: u64 = super::DEFAULT_SEED,
        /// Relative tolerance for two Poincaré point sets to be the same attractor, > 0.
        pub cluster_tol: f64 = super::DEFAULT_CLUSTER_TOL;
        flatten steady: SteadyRequest, integrator: IntegratorRequest,
    }
}

impl AttractorsRequest {
    /// The validated census of `params` ([`AttractorSpec::validate`]; the integrator built for
    /// `ATTRACTOR_SAMPLES_PER_PERIOD`).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `samples`, `cluster_tol` or a steady-state option.
    pub fn spec(&self, params: &Params) -> Result<AttractorSpec, SimError> {
        let spec = AttractorSpec {
            params: *params,
            samples: self.samples,
            seed: self.seed,
            cluster_tol: self.cluster_tol,
            steady: self.steady.options()?,
            integrator: self.integrator.options(ATTRACTOR_SAMPLES_PER_PERIOD)?,
        };
        spec.validate()?;
        Ok(spec)
    }
}

request! {
    /// `attractors` continued over a parameter (`afmdyn attractors --sweep`): a census at every
    /// value seeded from the previous value's attractors, matched to them by set distance
    /// ([`crate::analysis::global_continuation`]).
    pub struct GlobalContinuationRequest {
        /// The continued parameter.
        pub param: SweepParam = SweepParam::Omega,
        /// Explicit values (in the order continued) instead of `from`, `to`, `steps`.
        pub values: Option<Vec<f64>>,
        /// First value.
        pub from: f64 = 1.5,
        /// Last value.
        pub to: f64 = 3.0,
        /// Number of values, 1..=[`MAX_CONTINUATION_VALUES`].
        constants(MAX_CONTINUATION_VALUES)
        pub steps: usize = 16,
        /// Largest relative set distance of two attractors at consecutive values that are one, ≥ 0.
        pub match_tol: f64 = DEFAULT_MATCH_TOL,
        /// Random starts per value, 1..=[`MAX_ATTRACTOR_SAMPLES`].
        constants(MAX_ATTRACTOR_SAMPLES)
        pub samples: usize = 16,
        /// Seed of the random starts (keyed by value and start, as a sweep's).
        pub seed: u64 = super::DEFAULT_SEED,
        /// Relative tolerance for two Poincaré point sets at one value to be one attractor, > 0.
        pub cluster_tol: f64 = super::DEFAULT_CLUSTER_TOL;
        flatten steady: SteadyRequest, integrator: IntegratorRequest,
    }
}

impl GlobalContinuationRequest {
    /// The validated continuation of `base` ([`GlobalContinuationSpec::validate`]).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option, [`SimError::Params`] for a value out of the
    /// parameter's range.
    pub fn spec(&self, base: &Params) -> Result<GlobalContinuationSpec, SimError> {
        let values = match &self.values {
            Some(v) => v.clone(),
            None => {
                within(
                    "steps",
                    self.steps,
                    ..=MAX_CONTINUATION_VALUES,
                    "must be in 1..=10000",
                )?;
                SweepSpec::linspace(self.from, self.to, self.steps)?
            }
        };
        let census = AttractorsRequest {
            samples: self.samples,
            seed: self.seed,
            cluster_tol: self.cluster_tol,
            steady: self.steady,
            integrator: self.integrator,
        };
        let spec = GlobalContinuationSpec {
            census: census.spec(base)?,
            param: self.param,
            values,
            match_tol: self.match_tol,
        };
        spec.validate()?;
        Ok(spec)
    }
}

request! {
    /// `observe`: the observables of the steady state reached from a start (polished by Newton
    /// shooting when periodic).
    pub struct ObserveRequest {
        /// Orbit periods integrated, 1..=[`MAX_OBSERVE_PERIODS`].
        constants(MAX_OBSERVE_PERIODS)
        pub periods: usize = 1,
        /// Highest harmonic reported.
        pub harmonics: usize = 10;
        flatten start: StartRequest,
    }
}

/// The result of [`ObserveRequest::run`].
#[derive(Debug, Clone)]
pub struct ObserveResult {
    /// The observables.
    pub observables: Observables,
    /// The state at τ = 0 they were integrated from (Newton-polished when periodic).
    pub state: DVector<f64>,
    /// The period n of the motion, when it is periodic.
    pub period: Option<usize>,
}

impl ObserveRequest {
    /// Check every option.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `periods` or a steady-state option.
    pub fn validate(&self) -> Result<(), SimError> {
        in_range("periods", self.periods, 1..=MAX_OBSERVE_PERIODS)?;
        self.start.steady.options().map(|_| ())
    }
}

request! {
    /// `converge`: the steady tip motion for N = 1..=`max_modes` (paper Fig. 4).
    #[derive(Copy)]
    pub struct ConvergeRequest {
        /// Largest number of modes, 1..=20.
        pub max_modes: usize = 4,
        /// Drive periods of steady state compared, 1..=[`MAX_CONVERGE_PERIODS`].
        constants(MAX_CONVERGE_PERIODS)
        pub periods: usize = 1,
        /// Samples per drive period, 1..=[`MAX_SAMPLES_PER_PERIOD`];
        /// periods × samples_per_period ≤ [`MAX_CONVERGE_SAMPLES`].
        constants(MAX_SAMPLES_PER_PERIOD, MAX_CONVERGE_SAMPLES)
        pub samples_per_period: usize = 200;
        flatten integrator: IntegratorRequest,
    }
}

/// The defaults of `converge`: the paper's Fig. 4 is eq. 24 at Ω = 4.1, here with the damping
/// of eq. 26 (α3 = 0.1, α6 = 0.2) so that a steady state exists (`beam_damping = 0`,
/// `contact_damping = 0` restore eq. 24 exactly).
pub fn converge_defaults() -> Params {
    Params {
        omega: 4.1,
        ..Params::default()
    }
}

impl ConvergeRequest {
    /// Check every option.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option.
    pub fn validate(&self) -> Result<(), SimError> {
        in_range("max_modes", self.max_modes, 1..=crate::params::MAX_MODES)?;
        check_samples_per_period(self.samples_per_period)?;
        if !(1..=MAX_CONVERGE_PERIODS).contains(&self.periods)
            || self.periods * self.samples_per_period > MAX_CONVERGE_SAMPLES
        {
            return Err(SimError::out_of_range(
                "periods",
                self.periods,
                "must be in 1..=10000, with at most 1e7 samples in all (periods × samples per period)",
            ));
        }
        Ok(())
    }
}

pub(super) fn check_samples_per_period(spp: usize) -> Result<(), SimError> {
    in_range("samples_per_period", spp, 1..=MAX_SAMPLES_PER_PERIOD)
}

request! {
    /// `bifurcation`: the steady state over a grid of one parameter, continued forward and
    /// backward and from seeded random starts.
    pub struct BifurcationRequest {
        /// The swept parameter: `omega` or `alpha1`..`alpha6` (or their names,
        /// `tip-mass-ratio`, …).
        pub param: SweepParam = SweepParam::Omega,
        /// Explicit values instead of `from`, `to`, `steps`.
        pub values: Option<Vec<f64>>,
        /// First value.
        pub from: f64 = 1.0,
        /// Last value.
        pub to: f64 = 5.0,
        /// Number of values.
        pub steps: usize = 400,
        /// Random initial states per value (besides continuation).
        pub starts: u32 = 0,
        /// Seed of the random initial states.
        pub seed: u64 = super::DEFAULT_SEED,
        /// Forward and backward continuation.
        pub continuation: bool = true,
        /// Worker threads, 1..=[`MAX_THREADS`]; `None`: all cores.
        constants(MAX_THREADS)
        pub threads: Option<usize>;
        flatten steady: SteadyRequest, integrator: IntegratorRequest,
    }
}

impl BifurcationRequest {
    /// The validated sweep of `base`.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option, [`SimError::Params`] for a value out of
    /// the parameter's range.
    pub fn spec(&self, base: &Params) -> Result<SweepSpec, SimError> {
        super::limits::check_threads(self.threads)?;
        let values = match &self.values {
            Some(v) if v.is_empty() => {
                return Err(SimError::out_of_range(
                    "values",
                    "[]",
                    "must hold at least one value",
                ))
            }
            Some(v) => v.clone(),
            None => SweepSpec::linspace(self.from, self.to, self.steps)?,
        };
        let spec = SweepSpec {
            base: *base,
            param: self.param,
            values,
            continuation: self.continuation,
            starts: self.starts,
            seed: self.seed,
            steady: self.steady.options()?,
            integrator: self.integrator.options(1)?,
        };
        spec.validate()?;
        Ok(spec)
    }
}

impl_request! {
    BifurcationRequest, "bifurcation";
    validate |r, model| r.spec(&model.params).map(|_| ());
    cost |r, model| {
        // every point (each value reached forward, backward and from each random start) and
        // each continued branch's coarse pass over its chunks (at most one point a value):
        // the steady-state search to its transient cap, then the recorded periods (one cycle
        // of up to max_period, or nonperiodic_record), whose Poincaré points are the records
        let spec = r.spec(&model.params)?;
        let p = &spec.base;
        let values = spec.values.len() as f64;
        let points = super::sweep::point_count(&spec) as f64;
        let coarse = if spec.continuation { 2.0 * values } else { 0.0 };
        let recorded = spec.steady.max_period.max(spec.steady.nonperiodic_record) as f64;
        // the transient cap at the range's ends (a model's decay, and with it the cap, moves
        // monotonically with one parameter)
        let (lo, hi) = super::quantity::extent(&spec.values);
        let cap = steady_periods(&spec.steady, &p.with(spec.param, lo))?
            .max(steady_periods(&spec.steady, &p.with(spec.param, hi))?);
        let record = std::mem::size_of::<SweepRecord>() as f64 + state_bytes(p) + 64.0;
        Ok(Cost {
            bytes: MODEL_BYTES + points * recorded * record,
            work: (points + coarse) * (cap + recorded) * p.modes as f64,
        })
    }
}

impl_request! {
    GlobalContinuationRequest, "attractors --sweep",
    advice = "ask for fewer steps or samples (random starts), or a shorter transient (max_periods)";
    validate |r, model| r.spec(&model.params).map(|_| ());
    // one census per value
    cost |r, model| {
        let spec = r.spec(&model.params)?;
        census_cost(&spec.census, spec.values.len())
    }
}

pub use super::simulate::{SeriesStore, SimulateRequest, SimulateSpan};

impl_request! {
    OrbitRequest, "orbit",
    advice = "ask for a shorter transient (max_periods) or a lower max_period";
    validate |r, _| OrbitRequest::validate(r);
    // the steady state from rest (without an initial state), then Newton on the period asked
    // for or the largest one searched
    cost |r, model| {
        let p = &model.params;
        let (search, steady) = start_work(&r.start, p)?;
        let period = r.period.unwrap_or(steady.max_period);
        Ok(Cost {
            bytes: MODEL_BYTES,
            work: search + newton_work(p, period, &ShootingOptions::default()),
        })
    }
}

impl_request! {
    ContinuationRequest, "continuation",
    advice = "ask for a shorter range (from, to) or a shorter transient (max_periods)";
    validate |r, model| ContinuationRequest::validate(r, &model.params);
    // the start's steady state, then up to max_points Newton solves per branch (the cascade:
    // branches of periods n, 2n, 4n, 8n with switching), each point's state and monodromy kept
    cost |r, model| {
        let p = &model.params;
        let (search, steady) = start_work(&r.start, &p.with(r.param, r.from))?;
        let n = r.period.unwrap_or(steady.max_period);
        let points = ContinuationSpec::new(*p, r.param, r.from, r.to, n).max_points;
        let (branches, top) = match r.switch {
            true => (4.0, CASCADE_FACTOR * n),
            false => (1.0, n),
        };
        let point = (p.state_dim() * (p.state_dim() + 4)) as f64 * 8.0;
        Ok(Cost {
            bytes: MODEL_BYTES + branches * points as f64 * point,
            work: search
                + branches * points as f64 * newton_work(p, top, &ShootingOptions::default()),
        })
    }
}

impl_request! {
    LyapunovRequest, "lyapunov", advice = "ask for fewer periods or a shorter transient";
    validate |r, _| LyapunovRequest::validate(r);
    // the transient and the averaged periods of the state and its tangent space (one column
    // per state dimension); one value per block and exponent kept
    cost |r, model| {
        let p = &model.params;
        let transient = match r.transient {
            Some(t) => t as f64,
            None => steady_periods(&SteadyOptions::default(), p)?,
        };
        let dim = p.state_dim() as f64;
        Ok(Cost {
            bytes: MODEL_BYTES + r.blocks as f64 * state_bytes(p),
            work: (transient + r.periods as f64) * (dim + 1.0) * p.modes as f64,
        })
    }
}

impl_request! {
    AttractorsRequest, "attractors",
    advice = "ask for fewer samples (random starts) or a shorter transient (max_periods)";
    validate |r, model| r.spec(&model.params).map(|_| ());
    cost |r, model| census_cost(&r.spec(&model.params)?, 1)
}

impl_request! {
    ObserveRequest, "observe",
    advice = "ask for fewer periods or harmonics, or a shorter transient (max_periods)";
    validate |r, _| ObserveRequest::validate(r);
    // the start's steady state, Newton on its period (at most the largest searched), then
    // `periods` of that period; the harmonics' amplitudes and phases kept
    cost |r, model| {
        let p = &model.params;
        let (search, steady) = start_work(&r.start, p)?;
        let n = steady.max_period;
        let newton = ShootingOptions {
            tol: 1e-12,
            ..ShootingOptions::default()
        };
        Ok(Cost {
            bytes: MODEL_BYTES + r.harmonics as f64 * 32.0,
            work: search + newton_work(p, n, &newton) + (r.periods * n) as f64 * p.modes as f64,
        })
    }
}

impl_request! {
    ConvergeRequest, "converge", advice = "ask for fewer max_modes, periods or samples_per_period";
    validate |r, _| ConvergeRequest::validate(r);
    cost |r, model| converge_cost(r, &model.params)
}

/// The mode-periods of the steady-state search of a start on `params` (none when it gives its
/// initial state), and the search's options.
///
/// # Errors
/// As [`super::SteadyRequest::options`]; [`SimError::Params`] when the model cannot be built.
pub(crate) fn start_work(
    start: &StartRequest,
    params: &Params,
) -> Result<(f64, SteadyOptions), SimError> {
    let steady = start.steady.options()?;
    let search = match start.initial {
        Some(_) => 0.0,
        None => steady_periods(&steady, params)? * params.modes as f64,
    };
    Ok((search, steady))
}

/// The cost of `converge` on `params`: for N = 1..=`max_modes`, the steady state (the default
/// search, its cap at `max_modes` modes) and `periods` sampled; every run's samples kept (τ,
/// W_tip and V_T: 24 bytes a sample) and the last run's trajectory recorded whole
/// ([`recorded_sample_bytes`]) while they are taken from it.
///
/// # Errors
/// [`SimError::Params`] when the model cannot be built.
pub(crate) fn converge_cost(req: &ConvergeRequest, params: &Params) -> Result<Cost, SimError> {
    let top = Params {
        modes: req.max_modes,
        ..*params
    };
    let cap = steady_periods(&SteadyOptions::default(), &top)?;
    // Σ N over N = 1..=max_modes
    let modes = (req.max_modes * (req.max_modes + 1) / 2) as f64;
    let run = req.periods as f64 * req.samples_per_period as f64;
    Ok(Cost {
        bytes: MODEL_BYTES + req.max_modes as f64 * run * 24.0 + run * recorded_sample_bytes(&top),
        work: modes * (cap + req.periods as f64),
    })
}

/// The fingerprint of a sweep: everything that determines its rows (the library's version,
/// the resolved parameters, the swept parameter and its values, every sweep option); a sweep
/// is resumed only with the same fingerprint. The worker threads are not part of it.
///
/// The values are `from`, `to`, `steps`, or `values` when the request lists them.
pub(crate) fn fingerprint(request: &BifurcationRequest, spec: &SweepSpec) -> Value {
    let mut doc = json!({
        "afmdyn": env!("CARGO_PKG_VERSION"),
        // how the sweep is cut into tasks and its starts keyed (issue 29): a store written by
        // the two sequential chains of before is not resumed with segments
        "plan": super::sweep::PLAN,
        "params": spec.base,
        "param": spec.param.name(),
        "continuation": spec.continuation,
        "starts": spec.starts,
        "seed": spec.seed,
        "tol": spec.steady.tol,
        "max_periods": spec.steady.max_periods,
        "max_period": spec.steady.max_period,
        "integrator": spec.integrator.kind,
        "steps_per_period": spec.integrator.steps_per_period,
        "tolerance": spec.integrator.tolerance,
    });
    let range = match &request.values {
        Some(v) => json!({ "values": v }),
        None => json!({ "from": request.from, "to": request.to, "steps": request.steps }),
    };
    if let (Some(map), Value::Object(range)) = (doc.as_object_mut(), range) {
        map.extend(range);
    }
    doc
}

#[cfg(test)]
mod tests;
