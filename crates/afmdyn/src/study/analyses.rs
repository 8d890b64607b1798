//! The running of the one-value analyses of `request::analyses` (`orbit`, `continuation`,
//! `lyapunov`, `attractors`, `observe`, `converge`): each request's `run` on its parameters
//! and its [`Analysis`] (execution, document, presentation); and [`advance_from_rest`], the
//! engine's cost per forcing period that a front end times.

use crate::analysis::attractors::{find_attractors, AttractorReport};
use crate::analysis::continuation::{
    continue_branch, continue_with_switching, Branch, ContinuationSpec,
};
use crate::analysis::converge::{mode_convergence, ConvergenceRun};
use crate::analysis::lyapunov::{lyapunov_spectrum_with, resolved, LyapunovSpectrum, MIN_PERIODS};
use crate::analysis::observables::{observe_from, ObservableOptions};
use crate::analysis::progress::Progress;
use crate::analysis::shooting::{shoot, Guess, PeriodicOrbit, ShootingOptions, ShootingStrategy};
use crate::analysis::steady::{default_transient_cap, steady_state, SteadyOptions};
use crate::error::{in_range, SimError};
use crate::integrate::{build, IntegratorOptions};
use crate::maps::StroboscopicMap;
use crate::model::CantileverModel;
use crate::params::Params;
use crate::report::{self, Convergence, CurveUnits};
use crate::request::analyses::{
    initial_state, AttractorsRequest, ContinuationRequest, ConvergeRequest, LyapunovRequest,
    ObserveRequest, ObserveResult, OrbitRequest, StartRequest,
};
use crate::request::limits::CASCADE_FACTOR;
use crate::request::run::{Analysis, Presenting, Resolved};
use nalgebra::DVector;
use serde_json::Value;

/// [`StartRequest::guess_with_section`]: the guess, the period found, the recorded section
/// points (each of shape `[2N]`).
pub(crate) type GuessWithSection = (DVector<f64>, Option<usize>, Vec<DVector<f64>>);

impl StartRequest {
    /// The guess and, when a steady state was searched, its period.
    ///
    /// # Errors
    /// As [`initial_state`], [`crate::request::analyses::SteadyRequest::options`] and [`steady_state`].
    pub(crate) fn guess(
        &self,
        model: &CantileverModel,
    ) -> Result<(DVector<f64>, Option<usize>), SimError> {
        let (z, found, _) = self.guess_with_section(model)?;
        Ok((z, found))
    }

    /// [`Self::guess`] with the section points the steady-state search recorded (z(kT) of
    /// consecutive drive periods, the last one the guess; empty for a given `initial`): the
    /// starts of [`crate::analysis::shooting::Guess::Section`] when Newton from the guess fails.
    ///
    /// # Errors
    /// As [`Self::guess`].
    pub(crate) fn guess_with_section(
        &self,
        model: &CantileverModel,
    ) -> Result<GuessWithSection, SimError> {
        let steady = self.steady.options()?;
        let z0 = initial_state(model, self.initial.as_deref())?;
        if self.initial.is_some() {
            return Ok((z0, None, Vec::new()));
        }
        let mut integ = build(model, IntegratorOptions::default(), 0.0, &z0)?;
        let s = steady_state(integ.as_mut(), &steady)?;
        let section = s.poincare.iter().map(|p| p.state.clone()).collect();
        Ok((s.end_state().clone(), s.period(), section))
    }
}

impl OrbitRequest {
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

impl ContinuationRequest {
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

impl LyapunovRequest {
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

impl AttractorsRequest {
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

impl ObserveRequest {
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

impl ConvergeRequest {
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
    in_range("periods", periods, 1..=MAX_ADVANCE_PERIODS)?;
    let m = CantileverModel::new(params)?;
    let mut integ = build(&m, IntegratorOptions::default(), 0.0, &m.rest())?;
    crate::integrate::advance(integ.as_mut(), periods as f64 * m.period())?;
    Ok(integ.state().as_slice().to_vec())
}

impl Analysis for OrbitRequest {
    type Output = PeriodicOrbit;
    fn convergence(&self, _: &PeriodicOrbit) -> Convergence {
        Convergence::exact("orbit") // Newton's failure is an error
    }
    fn execute(&self, model: &Resolved, _: &Progress) -> Result<PeriodicOrbit, SimError> {
        self.run(&model.params)
    }
    fn report(&self, model: &Resolved, o: &PeriodicOrbit) -> Result<Value, SimError> {
        Ok(report::orbit(&CantileverModel::new(&model.params)?, o))
    }
    fn present(
        &self,
        output: &Self::Output,
        at: Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        crate::report::present::orbits::orbit(&at.model.params, output, at.units)
    }
}

impl Analysis for ContinuationRequest {
    type Output = Vec<Branch>;
    fn convergence(&self, branches: &Self::Output) -> Convergence {
        Convergence::count("branches", branches, |b| {
            b.end.warning(self.param, 1).is_none()
        })
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError> {
        self.run(&model.params, progress)
    }
    fn report(&self, model: &Resolved, branches: &Self::Output) -> Result<Value, SimError> {
        Ok(report::continuation(&model.params, self.param, branches))
    }
    #[cfg(feature = "files")]
    fn present(
        &self,
        branches: &Self::Output,
        at: Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        crate::report::present::continuation::continuation(
            &at.model.params,
            self.param,
            self.from,
            branches,
            at.units,
        )
    }
}

impl Analysis for LyapunovRequest {
    type Output = LyapunovSpectrum;
    fn convergence(&self, l: &Self::Output) -> Convergence {
        // an exponent not resolved from zero has not converged to its sign, nor has any of a
        // run shorter than its minimum (the spectrum's own warnings)
        let errors = l.uncertainty.iter().zip(&l.convergence);
        let settled = l.exponents.iter().zip(errors);
        let settled = settled
            .filter(|(e, (u, c))| resolved(**e, **u, **c))
            .count();
        let settled = if l.periods < MIN_PERIODS { 0 } else { settled };
        Convergence::of("exponents", settled, l.exponents.len())
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError> {
        self.run(&model.params, progress)
    }
    fn report(&self, model: &Resolved, l: &Self::Output) -> Result<Value, SimError> {
        Ok(report::lyapunov(&model.params, l))
    }
    fn present(
        &self,
        output: &Self::Output,
        at: Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        Ok(crate::report::present::orbits::lyapunov(
            &at.model.params,
            output,
            at.units,
        ))
    }
}

impl Analysis for AttractorsRequest {
    type Output = AttractorReport;
    fn convergence(&self, r: &Self::Output) -> Convergence {
        let settled = r.attractors.iter().map(|a| a.count).sum();
        Convergence::of("random starts", settled, self.samples)
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError> {
        self.run(&model.params, progress)
    }
    fn report(&self, model: &Resolved, r: &Self::Output) -> Result<Value, SimError> {
        Ok(report::attractors(&model.params, self.samples, r))
    }
    #[cfg(feature = "files")]
    fn present(
        &self,
        r: &Self::Output,
        at: Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        let spec = self.spec(&at.model.params)?;
        let mut shown =
            crate::report::present::census::attractors(&spec, r, at.document, at.units)?;
        shown
            .warnings
            .extend(crate::report::present::census::failed_starts(
                r,
                self.samples,
            ));
        Ok(shown)
    }
}

impl Analysis for ObserveRequest {
    type Output = ObserveResult;
    fn convergence(&self, o: &Self::Output) -> Convergence {
        // the steady state's end point is observed as it is where Newton found no orbit
        Convergence::of("periodic orbit", usize::from(o.period.is_some()), 1)
    }
    fn execute(&self, model: &Resolved, _: &Progress) -> Result<Self::Output, SimError> {
        self.run(&model.params)
    }
    fn report(&self, model: &Resolved, o: &Self::Output) -> Result<Value, SimError> {
        let units = CurveUnits::of(model.probe.as_ref(), false);
        let mut doc = report::observables(&o.observables);
        doc["reported"] = report::observed(&o.observables, &units);
        Ok(doc)
    }
}

impl Analysis for ConvergeRequest {
    type Output = Vec<ConvergenceRun>;
    fn convergence(&self, runs: &Self::Output) -> Convergence {
        Convergence::count("mode counts' steady states", runs, |r| r.period.is_some())
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Self::Output, SimError> {
        self.run(&model.params, progress)
    }
    fn report(&self, model: &Resolved, runs: &Self::Output) -> Result<Value, SimError> {
        Ok(report::converge(&model.params, runs))
    }
    #[cfg(feature = "files")]
    fn present(
        &self,
        runs: &Self::Output,
        at: Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        let mut shown = crate::report::present::converge::converge(&at.model.params, runs);
        // the printed document names the output directory
        if let Some(dir) = at.to.dir {
            let mut document = at.document.clone();
            document["out"] = serde_json::json!(dir);
            shown.document = Some(document);
        }
        Ok(shown)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::request::analyses::{AttractorsRequest, LyapunovRequest, OrbitRequest};
    use crate::request::run::run;

    /// The document of `run` is the report of the typed result with its convergence, and a
    /// cancelled progress stops a run before it starts.
    #[test]
    fn run_builds_the_reports_document_and_honours_cancel() {
        let model = Resolved::plain(Params {
            omega: 2.8,
            ..Params::default()
        });
        let request = OrbitRequest::default();
        let progress = Progress::new();
        let doc = run(&request, &model, &progress).unwrap();
        let mut want = report::orbit(&CantileverModel::new(&model.params).unwrap(), &doc.output);
        Convergence::exact("orbit").write_into(&mut want);
        assert_eq!(doc.json, want);
        assert_eq!(doc.output.period, 2);
        progress.cancel();
        assert!(matches!(
            run(&request, &model, &progress),
            Err(SimError::Cancelled)
        ));
    }

    /// Counted analyses count: the attractor census ticks once per random start, and a
    /// cancel between starts ends it with `Cancelled`.
    #[test]
    fn attractors_count_their_starts() {
        let model = Resolved::plain(Params::default());
        let request = AttractorsRequest {
            samples: 6,
            ..AttractorsRequest::default()
        };
        let progress = Progress::new();
        let doc = run(&request, &model, &progress).unwrap();
        assert_eq!((progress.done(), progress.total()), (6, Some(6)));
        assert_eq!(doc.json["samples"], 6);
        // cancelled before the starts: every start is refused and the census with it
        let cancelled = Progress::new();
        cancelled.cancel();
        let err = request.execute(&model, &cancelled).unwrap_err();
        assert!(matches!(err, SimError::Cancelled), "{err}");
        assert_eq!(cancelled.done(), 6);
        // every start that reached an attractor converged (the census's own counts)
        let counted: usize = doc.output.attractors.iter().map(|a| a.count).sum();
        assert_eq!(doc.json["converged"]["settled"], counted);
        assert_eq!(doc.json["converged"]["of"], 6);
    }

    /// A Lyapunov run shorter than its minimum of 200 periods has not converged to the
    /// exponents' signs (`run_warnings` says so): none of its 2N exponents is counted settled,
    /// and the door's first warning says how many did not converge.
    #[test]
    fn a_short_lyapunov_run_is_no_converged_spectrum() {
        let model = Resolved::plain(Params::default());
        let request = LyapunovRequest {
            periods: 50,
            blocks: 2,
            ..LyapunovRequest::default()
        };
        let doc = run(&request, &model, &Progress::new()).unwrap();
        let n = doc.output.exponents.len();
        assert_eq!(n, 2 * model.params.modes);
        let c = &doc.json["converged"];
        assert_eq!(
            (c["settled"].as_u64(), c["of"].as_u64()),
            (Some(0), Some(n as u64))
        );
        assert_eq!(c["all"], false);
        let first = doc.json["warnings"][0].as_str().unwrap();
        let says = format!("convergence: {n} of {n} exponents did not converge");
        assert!(first.starts_with(&says), "{first}");
        // the spectrum's own warning is still there, after it
        let own = doc.json["warnings"].as_array().unwrap().iter();
        assert!(own
            .skip(1)
            .any(|w| w.as_str().unwrap().starts_with("only 50 periods")));
    }
}
