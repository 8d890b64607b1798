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
pub type EachSample<'a> = dyn FnMut(usize, f64, &[f64]) -> Result<(), SimError> + 'a;

/// How [`sample_dense`] advances an integrator with spans ([`Integrator::spans`]: the exact
/// propagator, the split integrator).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpanSampling {
    /// Advanced to each sample in turn ([`advance`]), its steps cut there (the lock-in's
    /// demodulation, whose samples were always taken so).
    Cut,
    /// Stepped by spans ([`step_span`]) as every other integrator is by steps, each sample
    /// inside a span read from its dense output (the PeakForce cycle's 4 096 samples and the
    /// fit's 20 000, [`crate::analysis::peakforce`]).
    Dense,
}

/// Advance `integ` from its time τ₀ to τ_n = `time(n)`, calling `each(j, τ_j, z(τ_j))` for
/// j = 1, …, `n` in order, τ_j = `time(j)` increasing with τ₁ > τ₀ (nothing for n = 0).
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
pub fn sample_dense(
    integ: &mut dyn Integrator,
    n: usize,
    time: &dyn Fn(usize) -> f64,
    spans: SpanSampling,
    each: &mut EachSample<'_>,
) -> Result<(), SimError> {
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
