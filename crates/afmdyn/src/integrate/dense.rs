//! A stretch of the motion sampled at given times from the integrator's dense output inside
//! the steps it takes ([`sample_dense`]), so that the samples do not cut its steps: the Taylor
//! integrator's free-flight step spans up to a quarter of a drive period, and stopping it at
//! each of the lock-in's 32 samples per period ([`crate::analysis::am_loop`]) formed 32 or more
//! series per period. The dense output is the step's solution to the integrator's tolerance,
//! so a sample differs from the state the integrator reaches when stopped there by about the
//! tolerance (relative to max(1, ‖z‖)).

use super::{advance, form_state, step_span, Integrator};
use crate::error::SimError;
use crate::params::MAX_STATE;

/// What [`sample_dense`] hands each sample: its number j, τ_j and the state z(τ_j) (shape
/// `[dim]`, the integrator's state); an error it returns ends the sampling.
pub(crate) type EachSample<'a> = dyn FnMut(usize, f64, &[f64]) -> Result<(), SimError> + 'a;

/// How [`sample_dense`] advances an integrator with spans ([`Integrator::spans`]: the exact
/// propagator, the split integrator).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SpanSampling {
    /// Advanced to each sample in turn ([`advance`]), its steps cut there (the lock-in's
    /// demodulation, whose samples were always taken so).
    Cut,
    /// Stepped by spans ([`step_span`]) as every other integrator is by steps, each sample
    /// inside a span read from its dense output (the PeakForce cycle's 4 096 samples and the
    /// fit's 20 000, [`crate::analysis::peakforce`]).
    Dense,
}

/// Whether [`sample_dense`] samples its start τ₀ too.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum StartSample {
    /// No: τ₀ is the integrator's time, the samples are j = 1, …, n (the lock-in's
    /// demodulation, [`crate::analysis::am_loop`]).
    Excluded,
    /// Yes: τ₀ = `time(0)`, at or after the integrator's time; the integrator is first advanced
    /// to it ([`advance`], a step ended there) and j = 0 is its state there (the PeakForce cycle
    /// and the retract branch of its fit, [`crate::analysis::peakforce`]).
    Included,
}

/// Advance `integ` from τ₀ to τ_n = `time(n)`, calling `each(j, τ_j, z(τ_j))` for
/// j = 1, …, `n` in order, τ_j = `time(j)` increasing with τ₁ > τ₀ (nothing for n = 0); τ₀ is
/// the integrator's time, or with [`StartSample::Included`] `time(0)`, which the integrator is
/// first advanced to and sampled at (j = 0, before the others; then n = 0 samples it alone).
///
/// The integrator steps towards τ_n; a sample inside a step is read from its dense output
/// ([`Integrator::dense_state_into`], no allocation per sample for states of at most
/// [`MAX_STATE`] values), one at a step's end is the state there (after a switching that ends
/// the step, the state after it). An integrator with spans ([`Integrator::spans`]: the exact
/// propagator, the split integrator) is advanced to each sample in turn ([`advance`]), its
/// steps cut there, with [`SpanSampling::Cut`]; with [`SpanSampling::Dense`] it takes its spans
/// ([`step_span`]) and is read as the others, its plain state formed at the end.
///
/// # Errors
/// As the integrator, or what `each` returns.
pub(crate) fn sample_dense(
    integ: &mut dyn Integrator,
    n: usize,
    time: &dyn Fn(usize) -> f64,
    spans: SpanSampling,
    start: StartSample,
    each: &mut EachSample<'_>,
) -> Result<(), SimError> {
    if start == StartSample::Included {
        advance(integ, time(0))?;
        form_state(integ);
        each(0, integ.tau(), integ.state().as_slice())?;
    }
    if n == 0 {
        return Ok(());
    }
    let has_spans = integ.spans().is_some();
    if has_spans && spans == SpanSampling::Cut {
        for j in 1..=n {
            let tau = time(j);
            advance(integ, tau)?;
            each(j, tau, integ.state().as_slice())?;
        }
        return Ok(());
    }
    let dim = integ.state().len();
    let mut stack = [0.0; MAX_STATE];
    let mut heap = Vec::new();
    let z: &mut [f64] = if dim <= MAX_STATE {
        &mut stack[..dim]
    } else {
        heap.resize(dim, 0.0);
        &mut heap
    };
    let end = time(n);
    let mut j = 1;
    while j <= n {
        // one step, or a span of them ([`step_span`]: `Integrator::step` without spans)
        let step = step_span(integ, end, None)?;
        let tau1 = if has_spans { step.tau1 } else { integ.tau() };
        while j <= n {
            let tau = time(j);
            if tau > tau1 {
                break;
            }
            if tau == tau1 {
                form_state(integ);
                each(j, tau, integ.state().as_slice())?;
            } else {
                integ.dense_state_into(tau, z);
                each(j, tau, z)?;
            }
            j += 1;
        }
    }
    if has_spans {
        form_state(integ);
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrate::{build, IntegratorKind, IntegratorOptions};
    use crate::model::CantileverModel;
    use crate::params::Params;

    /// The samples of `sample_dense` from `time(0)` on: (j, τ_j, z(τ_j)).
    type Samples = Vec<(usize, f64, Vec<f64>)>;

    /// Sampling with the start included is, bit for bit, the integrator advanced to
    /// τ₀ = `time(0)` ([`advance`]), its state there the sample j = 0, then sampled without its
    /// start: the defining identity of [`StartSample::Included`], for an integrator with spans
    /// (the exact propagator) and one without (the adaptive one), both span samplings.
    #[test]
    fn the_start_sample_is_the_state_advanced_to_it() {
        let p = Params::default();
        let model = CantileverModel::new(&p).unwrap();
        let t = p.period();
        let time = |j: usize| 0.3 * t + t * j as f64 / 50.0;
        for kind in [IntegratorKind::Adaptive, IntegratorKind::Exact] {
            for spans in [SpanSampling::Cut, SpanSampling::Dense] {
                let opts = IntegratorOptions {
                    kind,
                    ..IntegratorOptions::default()
                };
                let mut a = build(&model, opts.clone(), 0.0, &model.rest()).unwrap();
                let mut got: Samples = Vec::new();
                sample_dense(
                    a.as_mut(),
                    50,
                    &time,
                    spans,
                    StartSample::Included,
                    &mut |j, tau, z| {
                        got.push((j, tau, z.to_vec()));
                        Ok(())
                    },
                )
                .unwrap();
                let mut b = build(&model, opts, 0.0, &model.rest()).unwrap();
                advance(b.as_mut(), time(0)).unwrap();
                form_state(b.as_mut());
                let mut want: Samples = vec![(0, b.tau(), b.state().as_slice().to_vec())];
                sample_dense(
                    b.as_mut(),
                    50,
                    &time,
                    spans,
                    StartSample::Excluded,
                    &mut |j, tau, z| {
                        want.push((j, tau, z.to_vec()));
                        Ok(())
                    },
                )
                .unwrap();
                assert_eq!(got.len(), 51, "{kind:?}, {spans:?}");
                assert_eq!(got, want, "{kind:?}, {spans:?}");
                assert_eq!((a.tau(), a.state()), (b.tau(), b.state()));
                // the start is where the samples begin: τ₀ = time(0) to the step's rounding
                assert!((got[0].1 - time(0)).abs() <= 1e-12 * t, "{kind:?}");
            }
        }
    }
}
