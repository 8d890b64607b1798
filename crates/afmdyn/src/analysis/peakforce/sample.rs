//! Samples of a flow at given increasing times from the integrator's dense output: the
//! integrator takes its own steps ([`crate::integrate::step_span`]) and every sample inside a
//! step is formed from the step's dense output ([`Integrator::dense_state`]), as the recorded
//! trajectories are ([`crate::trajectory::record_rows`]), instead of ending a step at every
//! sample: the cycle's 4 096 samples and the fit's 20 000 would otherwise cut the lever's
//! natural steps (a few per lever period) into hundreds of short ones.

use crate::error::SimError;
use crate::integrate::{advance, form_state, step_span, Integrator};
use nalgebra::DVector;

/// What [`sample_times`] hands each sample: its index k, τ_k and the state there.
pub type EachSample<'a> = dyn FnMut(usize, f64, &DVector<f64>) -> Result<(), SimError> + 'a;

/// Call `each(k, τ_k, z(τ_k))` for k = 0, 1, …, `n` − 1 in order, τ_k = `time(k)` increasing
/// (the first at or after the integrator's time), advancing `integ` to τ_{n−1}. The first
/// sample is the state there (the integrator advanced to it exactly); a sample inside a step
/// comes from its dense output; one at the end of a step that ended at a switching, the state
/// after it (the step's region is the one before the switching).
///
/// # Errors
/// [`SimError`] from the integrator or from `each`.
pub fn sample_times(
    integ: &mut dyn Integrator,
    n: usize,
    time: &dyn Fn(usize) -> f64,
    each: &mut EachSample<'_>,
) -> Result<(), SimError> {
    if n == 0 {
        return Ok(());
    }
    advance(integ, time(0))?;
    form_state(integ);
    each(0, integ.tau(), integ.state())?;
    let end = time(n - 1);
    let mut k = 1;
    while k < n {
        let step = step_span(integ, end, None)?;
        let tau1 = step.tau1;
        while k < n {
            let t = time(k);
            let inside = t < tau1 || (t == tau1 && step.event.is_none());
            if !inside {
                break;
            }
            let z = integ.dense_state(t);
            each(k, t, &z)?;
            k += 1;
        }
        if k < n && time(k) <= tau1 {
            // at the step's end after a switching: the state there
            form_state(integ);
            each(k, tau1, integ.state())?;
            k += 1;
        }
    }
    form_state(integ);
    Ok(())
}
