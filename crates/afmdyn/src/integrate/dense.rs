//! A stretch of the motion sampled at given times from the integrator's dense output inside
//! the steps it takes ([`sample_dense`]), so that the samples do not cut its steps: the Taylor
//! integrator's free-flight step spans up to a quarter of a drive period, and stopping it at
//! each of the lock-in's 32 samples per period ([`crate::analysis::am_loop`]) formed 32 or more
//! series per period. The dense output is the step's solution to the integrator's tolerance,
//! so a sample differs from the state the integrator reaches when stopped there by about the
//! tolerance (relative to max(1, ‖z‖)).

use super::{advance, Integrator};
use crate::error::SimError;
use crate::params::MAX_STATE;

/// What [`sample_dense`] hands each sample: its number j, τ_j and the state z(τ_j) (shape
/// `[dim]`, the integrator's state).
pub type EachSample<'a> = dyn FnMut(usize, f64, &[f64]) + 'a;

/// Advance `integ` from its time τ₀ to τ_n = `time(n)`, calling `each(j, τ_j, z(τ_j))` for
/// j = 1, …, `n` in order, τ_j = `time(j)` increasing with τ₁ > τ₀ (nothing for n = 0).
///
/// The integrator steps towards τ_n; a sample inside a step is read from its dense output
/// ([`Integrator::dense_state_into`], no allocation per sample for states of at most
/// [`MAX_STATE`] values), one at a step's end is the state there (after a switching that ends
/// the step, the state after it). An integrator with spans ([`Integrator::spans`]: the exact
/// propagator, the split integrator) is advanced to each sample in turn ([`advance`]), its
/// steps cut there.
///
/// # Errors
/// As the integrator.
pub fn sample_dense(
    integ: &mut dyn Integrator,
    n: usize,
    time: &dyn Fn(usize) -> f64,
    each: &mut EachSample<'_>,
) -> Result<(), SimError> {
    if n == 0 {
        return Ok(());
    }
    if integ.spans().is_some() {
        for j in 1..=n {
            let tau = time(j);
            advance(integ, tau)?;
            each(j, tau, integ.state().as_slice());
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
        integ.step(end)?;
        let tau1 = integ.tau();
        while j <= n {
            let tau = time(j);
            if tau > tau1 {
                break;
            }
            if tau == tau1 {
                each(j, tau, integ.state().as_slice());
            } else {
                integ.dense_state_into(tau, z);
                each(j, tau, z);
            }
            j += 1;
        }
    }
    Ok(())
}
