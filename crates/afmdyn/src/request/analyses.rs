//! One request per analysis: its options with their defaults (those of `afmdyn <command>
//! --help` and of the Python functions), `validate()` holding every limit ([`super::limits`]),
//! and, where the analysis is one library call, `run(params)`. Errors name the library's
//! parameters (`samples_per_period`, `max_period`); a front end spells them its own way
//! ([`SimError::spelled`]).
//!
//! Model values are not part of these requests: they resolve first, through
//! [`super::ModelSpec::resolve`], into the [`Params`] every `validate` and `run` takes.

use super::limits::*;
use crate::analysis::attractors::{find_attractors, AttractorReport, AttractorSpec};
use crate::analysis::bifurcation::SweepSpec;
use crate::analysis::continuation::{
    continue_branch, continue_with_switching, Branch, ContinuationSpec,
};
use crate::analysis::converge::{mode_convergence, ConvergenceRun};
use crate::analysis::global_continuation::{
    GlobalContinuationSpec, DEFAULT_MATCH_TOL, MAX_CONTINUATION_VALUES,
};
use crate::analysis::lyapunov::{lyapunov_spectrum_with, LyapunovOptions, LyapunovSpectrum};
use crate::analysis::observables::{observe_from, ObservableOptions, Observables};
use crate::analysis::period::MAX_PERIOD;
use crate::analysis::progress::Progress;
use crate::analysis::shooting::{shoot, Guess, PeriodicOrbit, ShootingOptions, ShootingStrategy};
use crate::analysis::steady::{default_transient_cap, steady_state, SteadyOptions};
use crate::error::SimError;
use crate::integrate::{build, IntegratorKind, IntegratorOptions};
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use nalgebra::DVector;
use serde::{Deserialize, Serialize};

mod start;
pub use start::{initial_state, IntegratorRequest, StartRequest, SteadyRequest};

fn check_period(period: Option<usize>) -> Result<(), SimError> {
    match period {
        Some(n) if !(1..=MAX_PERIOD).contains(&n) => {
            Err(SimError::out_of_range("period", n, "must be in 1..=64"))
        }
        _ => Ok(()),
    }
}

/// `orbit`: a period-n orbit by Newton shooting, with its Floquet multipliers.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct OrbitRequest {
    /// The period n (1..=64); `None`: the period of the steady state reached, else 1.
    pub period: Option<usize>,
    /// The start.
    #[serde(flatten)]
    pub start: StartRequest,
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

    /// The orbit of `params`: Newton shooting ([`shoot`]) from the guess; when that fails to
    /// converge, the globalised Newton ([`ShootingStrategy::Globalised`]: a line search on
    /// ½‖F‖²) from the guess, then from the closest returns among the section points the
    /// steady-state search recorded ([`Guess::Section`]) — so that a chaotic attractor yields
    /// an unstable periodic orbit embedded in it.
    ///
    /// # Errors
    /// As [`Self::validate`], `StartRequest::guess` and [`shoot`]; the
    /// [`SimError::NoConvergence`] of the last search tried when none converges, or
    /// [`SimError::NoPeriod`] when the period was not given and the steady-state search from
    /// the start found none.
    pub fn run(&self, params: &Params) -> Result<PeriodicOrbit, SimError> {
        self.validate()?;
        let model = CantileverModel::new(params)?;
        let (guess, found, section) = self.start.guess_with_section(&model)?;
        let n = self.period.or(found).unwrap_or(1);
        let opts = ShootingOptions::default().with_period(n);
        let integ = || build(&model, IntegratorOptions::default(), 0.0, &model.rest());
        let first = integ()
            .and_then(|mut i| shoot(&mut StroboscopicMap::new(i.as_mut(), 1), &guess, &opts));
        let r = match first {
            Err(SimError::NoConvergence { .. }) => {
                let mut integ = integ()?;
                let map = &mut StroboscopicMap::new(integ.as_mut(), 1);
                let globalised = ShootingOptions {
                    strategy: ShootingStrategy::Globalised,
                    ..opts
                };
                match shoot(map, &guess, &globalised) {
                    Err(SimError::NoConvergence { .. }) if section.len() > n => {
                        shoot(map, Guess::Section(&section), &globalised)
                    }
                    r => r,
                }
            }
            r => r,
        };
        explain_start(r, self.period, found, self.start.searched(&model)?)
    }
}

/// `r` with a Newton failure explained when the period was guessed: the user gave none and
/// the steady-state search from the start (`searched`: its `max_period` and transient cap,
/// `None` for a given initial state, which is not searched) showed none, so Newton started
/// from the last state of a motion not periodic within `max_period`: [`SimError::NoPeriod`]
/// (issue 28: every early end says why; issue 60 item 10: the grazing JKR orbit). The one
/// place orbit searches and continuations say so.
fn explain_start<T>(
    r: Result<T, SimError>,
    period: Option<usize>,
    found: Option<usize>,
    searched: Option<(usize, usize)>,
) -> Result<T, SimError> {
    match (r, searched) {
        (Err(SimError::NoConvergence { residual, .. }), Some((max_period, periods)))
            if period.is_none() && found.is_none() =>
        {
            Err(SimError::NoPeriod {
                max_period,
                periods,
                residual,
            })
        }
        (r, _) => r,
    }
}

/// `continuation`: pseudo-arclength continuation of a period-n branch in one parameter, and
/// with `switch` the period-doubling cascade to [`CASCADE_FACTOR`] n.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct ContinuationRequest {
    /// The continued parameter: `omega` or `alpha1`..`alpha6` (or their names,
    /// `tip-mass-ratio`, …).
    pub param: SweepParam,
    /// The value where the continuation starts.
    pub from: f64,
    /// The end of the range.
    pub to: f64,
    /// The period n (1..=64); `None`: the period of the steady state reached at `from`, else 1.
    pub period: Option<usize>,
    /// At each period doubling, switch to the period-2n branch and continue it too,
    /// recursively up to period 8n (the period-doubling cascade).
    pub switch: bool,
    /// The start at `from`.
    #[serde(flatten)]
    pub start: StartRequest,
}

impl Default for ContinuationRequest {
    fn default() -> Self {
        ContinuationRequest {
            param: SweepParam::Omega,
            from: 5.0,
            to: 1.0,
            period: None,
            switch: false,
            start: StartRequest::default(),
        }
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

    /// The branches: one without `switch`, the cascade with it.
    ///
    /// # Errors
    /// As [`Self::validate`], `StartRequest::guess`, [`crate::analysis::continuation::continue_branch`] and
    /// [`crate::analysis::continuation::continue_with_switching`].
    /// Every branch point is counted in `progress`, which also cancels the run.
    pub fn run(&self, base: &Params, progress: &Progress) -> Result<Vec<Branch>, SimError> {
        self.validate(base)?;
        let model = CantileverModel::new(&base.with(self.param, self.from))?;
        let (guess, found) = self.start.guess(&model)?;
        let n = self.period.or(found).unwrap_or(1);
        let spec = ContinuationSpec::new(*base, self.param, self.from, self.to, n);
        let r = if self.switch {
            continue_with_switching(&spec, &guess, CASCADE_FACTOR * n, progress)
        } else {
            continue_branch(&spec, &guess, progress).map(|b| vec![b])
        };
        explain_start(r, self.period, found, self.start.searched(&model)?)
    }
}

/// `lyapunov`: the Lyapunov spectrum with saltation matrices and the 0–1 test.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct LyapunovRequest {
    /// The initial state (2N values); `None`: rest.
    pub initial: Option<Vec<f64>>,
    /// Drive periods discarded first; `None` (default): the model's derived transient cap
    /// ([`crate::analysis::steady::default_transient_cap`] at tol = 1e-8: 1 500 for the
    /// paper's beam, ≈ 1.9 Q ln(1e8) for a lever of quality factor Q).
    pub transient: Option<usize>,
    /// Drive periods averaged; transient + periods ≤ [`MAX_RUN_PERIODS`].
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = { "MAX_RUN_PERIODS": MAX_RUN_PERIODS }))
    )]
    pub periods: usize,
    /// Blocks for the uncertainty, 2..=periods.
    pub blocks: usize,
}

impl Default for LyapunovRequest {
    fn default() -> Self {
        let d = LyapunovOptions::default();
        LyapunovRequest {
            initial: None,
            transient: None,
            periods: d.periods,
            blocks: d.blocks,
        }
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
    fn options(&self, derived: usize) -> LyapunovOptions {
        LyapunovOptions {
            transient_periods: self.transient.unwrap_or(derived),
            periods: self.periods,
            blocks: self.blocks,
            ..LyapunovOptions::default()
        }
    }

    /// The spectrum of `params` from the initial state, the drive periods counted in
    /// `progress`, which also cancels the run.
    ///
    /// # Errors
    /// As [`Self::validate`], [`initial_state`] and `lyapunov_spectrum_with`.
    pub fn run(&self, params: &Params, progress: &Progress) -> Result<LyapunovSpectrum, SimError> {
        self.validate()?;
        let model = CantileverModel::new(params)?;
        let z0 = initial_state(&model, self.initial.as_deref())?;
        let opts = self.options(default_transient_cap(&model, SteadyOptions::default().tol));
        let mut integ = build(&model, opts.integrator.clone(), 0.0, &z0)?;
        lyapunov_spectrum_with(integ.as_mut(), &opts, progress)
    }
}

/// `attractors`: the coexisting attractors and their basin fractions from random starts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct AttractorsRequest {
    /// Random initial states, 1..=[`MAX_ATTRACTOR_SAMPLES`].
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = { "MAX_ATTRACTOR_SAMPLES": crate::analysis::attractors::MAX_ATTRACTOR_SAMPLES }))
    )]
    pub samples: usize,
    /// Seed of the initial states.
    pub seed: u64,
    /// Relative tolerance for two Poincaré point sets to be the same attractor, > 0.
    pub cluster_tol: f64,
    /// The steady-state search of every start.
    #[serde(flatten)]
    pub steady: SteadyRequest,
    /// The integrator.
    #[serde(flatten)]
    pub integrator: IntegratorRequest,
}

impl Default for AttractorsRequest {
    fn default() -> Self {
        AttractorsRequest {
            samples: 64,
            seed: super::DEFAULT_SEED,
            cluster_tol: super::DEFAULT_CLUSTER_TOL,
            steady: SteadyRequest::default(),
            integrator: IntegratorRequest::default(),
        }
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

    /// The census of `params`, the random starts counted in `progress`, which also cancels
    /// the run. Starts that fail are listed in [`AttractorReport::failures`].
    ///
    /// # Errors
    /// As [`Self::spec`] and [`find_attractors`]; [`SimError::EveryRunFailed`] when every
    /// start failed (there is no attractor to report).
    pub fn run(&self, params: &Params, progress: &Progress) -> Result<AttractorReport, SimError> {
        let report = find_attractors(&self.spec(params)?, progress)?;
        if report.attractors.is_empty() {
            if let Some(first) = report.failures.first() {
                return Err(SimError::EveryRunFailed {
                    what: "random starts",
                    runs: report.failures.len(),
                    first: first.clone(),
                });
            }
        }
        Ok(report)
    }
}

/// `attractors` continued over a parameter (`afmdyn attractors --sweep`): a census at every
/// value seeded from the previous value's attractors, matched to them by set distance
/// ([`crate::analysis::global_continuation`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct GlobalContinuationRequest {
    /// The continued parameter.
    pub param: SweepParam,
    /// Explicit values (in the order continued) instead of `from`, `to`, `steps`.
    pub values: Option<Vec<f64>>,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values, 1..=[`MAX_CONTINUATION_VALUES`].
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = { "MAX_CONTINUATION_VALUES": MAX_CONTINUATION_VALUES }))
    )]
    pub steps: usize,
    /// Largest relative set distance of two attractors at consecutive values that are one, ≥ 0.
    pub match_tol: f64,
    /// Random starts per value, 1..=[`MAX_ATTRACTOR_SAMPLES`].
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = { "MAX_ATTRACTOR_SAMPLES": crate::analysis::attractors::MAX_ATTRACTOR_SAMPLES }))
    )]
    pub samples: usize,
    /// Seed of the random starts (keyed by value and start, as a sweep's).
    pub seed: u64,
    /// Relative tolerance for two Poincaré point sets at one value to be one attractor, > 0.
    pub cluster_tol: f64,
    /// The steady-state search of every start.
    #[serde(flatten)]
    pub steady: SteadyRequest,
    /// The integrator.
    #[serde(flatten)]
    pub integrator: IntegratorRequest,
}

impl Default for GlobalContinuationRequest {
    fn default() -> Self {
        GlobalContinuationRequest {
            param: SweepParam::Omega,
            values: None,
            from: 1.5,
            to: 3.0,
            steps: 16,
            match_tol: DEFAULT_MATCH_TOL,
            samples: 16,
            seed: super::DEFAULT_SEED,
            cluster_tol: super::DEFAULT_CLUSTER_TOL,
            steady: SteadyRequest::default(),
            integrator: IntegratorRequest::default(),
        }
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
                if self.steps > MAX_CONTINUATION_VALUES {
                    return Err(SimError::out_of_range(
                        "steps",
                        self.steps,
                        "must be in 1..=10000",
                    ));
                }
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

/// `observe`: the observables of the steady state reached from a start (polished by Newton
/// shooting when periodic).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct ObserveRequest {
    /// Orbit periods integrated, 1..=[`MAX_OBSERVE_PERIODS`].
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = { "MAX_OBSERVE_PERIODS": MAX_OBSERVE_PERIODS }))
    )]
    pub periods: usize,
    /// Highest harmonic reported.
    pub harmonics: usize,
    /// The start.
    #[serde(flatten)]
    pub start: StartRequest,
}

impl Default for ObserveRequest {
    fn default() -> Self {
        ObserveRequest {
            periods: 1,
            harmonics: 10,
            start: StartRequest::default(),
        }
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
        if !(1..=MAX_OBSERVE_PERIODS).contains(&self.periods) {
            return Err(SimError::out_of_range(
                "periods",
                self.periods,
                "must be in 1..=1000000",
            ));
        }
        self.start.steady.options().map(|_| ())
    }

    /// The observables of `params`: the steady state from the start, polished by Newton
    /// shooting to 1e-12 when periodic (a transient that has not settled is tried as period 1;
    /// when Newton fails the steady state's end point is used as it is), integrated over
    /// `periods` of its periods.
    ///
    /// # Errors
    /// As [`Self::validate`], `StartRequest::guess` and `observe_from`.
    pub fn run(&self, params: &Params) -> Result<ObserveResult, SimError> {
        self.validate()?;
        let model = CantileverModel::new(params)?;
        let (z, found) = self.start.guess(&model)?;
        let n = found.unwrap_or(1);
        let newton = ShootingOptions {
            tol: 1e-12,
            ..ShootingOptions::default()
        }
        .with_period(n);
        let orbit = build(&model, IntegratorOptions::default(), 0.0, &model.rest())
            .and_then(|mut i| shoot(&mut StroboscopicMap::new(i.as_mut(), 1), &z, &newton));
        let (state, period) = match orbit {
            Ok(o) => (o.state, Some(n)),
            Err(_) => (z, found),
        };
        let observables = observe_from(
            &model,
            IntegratorOptions::default(),
            0.0,
            &state,
            &ObservableOptions {
                periods: self.periods * n,
                harmonics: self.harmonics,
            },
        )?;
        Ok(ObserveResult {
            observables,
            state,
            period,
        })
    }
}

/// `converge`: the steady tip motion for N = 1..=`max_modes` (paper Fig. 4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct ConvergeRequest {
    /// Largest number of modes, 1..=20.
    pub max_modes: usize,
    /// Drive periods of steady state compared, 1..=[`MAX_CONVERGE_PERIODS`].
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = { "MAX_CONVERGE_PERIODS": MAX_CONVERGE_PERIODS }))
    )]
    pub periods: usize,
    /// Samples per drive period, 1..=[`MAX_SAMPLES_PER_PERIOD`];
    /// periods × samples_per_period ≤ [`MAX_CONVERGE_SAMPLES`].
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = {
            "MAX_SAMPLES_PER_PERIOD": MAX_SAMPLES_PER_PERIOD,
            "MAX_CONVERGE_SAMPLES": MAX_CONVERGE_SAMPLES
        }))
    )]
    pub samples_per_period: usize,
    /// The integrator.
    #[serde(flatten)]
    pub integrator: IntegratorRequest,
}

impl Default for ConvergeRequest {
    fn default() -> Self {
        ConvergeRequest {
            max_modes: 4,
            periods: 1,
            samples_per_period: 200,
            integrator: IntegratorRequest::default(),
        }
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
        if !(1..=crate::params::MAX_MODES).contains(&self.max_modes) {
            return Err(SimError::out_of_range(
                "max_modes",
                self.max_modes,
                "must be in 1..=20",
            ));
        }
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

    /// The runs N = 1..=max_modes of `params` (its own N is replaced).
    ///
    /// # Errors
    /// As [`Self::validate`] and `crate::analysis::converge::mode_convergence`.
    /// Each run is counted in `progress`, which also cancels the whole.
    pub fn run(
        &self,
        params: &Params,
        progress: &Progress,
    ) -> Result<Vec<ConvergenceRun>, SimError> {
        self.validate()?;
        mode_convergence(
            params,
            self.max_modes,
            self.periods,
            self.samples_per_period,
            &SteadyOptions::default(),
            self.integrator.options(self.samples_per_period)?,
            progress,
        )
    }
}

pub(super) fn check_samples_per_period(spp: usize) -> Result<(), SimError> {
    if !(1..=MAX_SAMPLES_PER_PERIOD).contains(&spp) {
        return Err(SimError::out_of_range(
            "samples_per_period",
            spp,
            "must be in 1..=100000",
        ));
    }
    Ok(())
}

/// `bifurcation`: the steady state over a grid of one parameter, continued forward and
/// backward and from seeded random starts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct BifurcationRequest {
    /// The swept parameter: `omega` or `alpha1`..`alpha6` (or their names,
    /// `tip-mass-ratio`, …).
    pub param: SweepParam,
    /// Explicit values instead of `from`, `to`, `steps`.
    pub values: Option<Vec<f64>>,
    /// First value.
    pub from: f64,
    /// Last value.
    pub to: f64,
    /// Number of values.
    pub steps: usize,
    /// Random initial states per value (besides continuation).
    pub starts: u32,
    /// Seed of the random initial states.
    pub seed: u64,
    /// Forward and backward continuation.
    pub continuation: bool,
    /// Worker threads, 1..=[`MAX_THREADS`]; `None`: all cores.
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = { "MAX_THREADS": super::limits::MAX_THREADS }))
    )]
    pub threads: Option<usize>,
    /// The steady-state search of every point.
    #[serde(flatten)]
    pub steady: SteadyRequest,
    /// The integrator.
    #[serde(flatten)]
    pub integrator: IntegratorRequest,
}

impl Default for BifurcationRequest {
    fn default() -> Self {
        BifurcationRequest {
            param: SweepParam::Omega,
            values: None,
            from: 1.0,
            to: 5.0,
            steps: 400,
            starts: 0,
            seed: super::DEFAULT_SEED,
            continuation: true,
            threads: None,
            steady: SteadyRequest::default(),
            integrator: IntegratorRequest::default(),
        }
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

pub use super::simulate::{SeriesStore, SimulateRequest, SimulateSpan};

#[cfg(test)]
mod tests;

/// Most drive periods [`advance_from_rest`] integrates.
pub(crate) const MAX_ADVANCE_PERIODS: usize = 1_000_000;

/// The state `z` (shape `[2N]`, (a, ȧ)) after `periods` drive periods from rest, with the
/// default (`auto`) integrator: the engine's cost per forcing period, which a front end times
/// (the browser against the native build, `scripts/perf-wasm.sh`).
///
/// # Errors
/// [`SimError::OutOfRange`] for `periods` outside 1..=`MAX_ADVANCE_PERIODS`; the model's
/// and the integrator's errors.
pub fn advance_from_rest(params: &Params, periods: usize) -> Result<Vec<f64>, SimError> {
    if !(1..=MAX_ADVANCE_PERIODS).contains(&periods) {
        return Err(SimError::out_of_range(
            "periods",
            periods,
            "must be in 1..=1000000",
        ));
    }
    let m = CantileverModel::new(params)?;
    let mut integ = build(&m, IntegratorOptions::default(), 0.0, &m.rest())?;
    crate::integrate::advance(integ.as_mut(), periods as f64 * m.period())?;
    Ok(integ.state().as_slice().to_vec())
}
