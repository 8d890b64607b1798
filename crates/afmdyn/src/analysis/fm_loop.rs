//! The FM-AFM loop in the time domain, for comparison with the exact steady states of
//! [`super::fm`]: the cantilever integrated cycle after cycle while a phase-locked loop and an
//! amplitude controller correct the drive once per cycle, as an instrument's digital loops do
//! (and as VEDA simulates FM-AFM: Kiracofe, Melcher & Raman, *Rev. Sci. Instrum.* 83 (2012)
//! 013702, with continuous-time loops).
//!
//! Each cycle k runs one drive period at (Ω_k, α2_k) from the state the previous one ended in
//! (the drive's phase is continuous: every period starts at phase 0), demodulates the tip's
//! first harmonic over it exactly (`super::observables::observe`), and updates
//!
//! Ω_{k+1} = Ω_k − g_φ (ω_K / 2Q_K) (φ₁ − φ_set),  α2_{k+1} = α2_k (1 − g_A (A₁/A − 1)),
//!
//! two integral controllers (the PLL integrates the phase error into the frequency, the
//! amplitude controller the amplitude error into the excitation), so their fixed point is the
//! exact FM steady state. The phase moves by about 2Q_K/ω_K per unit Ω, so the PLL's loop gain
//! per cycle is g_φ; the cantilever answers within Q_K/π cycles, so gains below π/Q_K keep
//! the loop stable ([`LoopSpec::new`]). A value is settled when both errors stay below the
//! tolerance for `SETTLED_CYCLES` cycles in a row.

use super::fm::{fm_reference, phase_error, FmSpec, LoopSpec};
use super::observables::{observe, ObservableOptions};
use super::progress::Progress;
use crate::error::SimError;
use crate::integrate::build;
use crate::model::CantileverModel;
use crate::params::SweepParam;
use serde::{Deserialize, Serialize};

/// Cycles in a row with both errors below the tolerance for a value to count as settled.
pub(crate) const SETTLED_CYCLES: usize = 10;

/// The loop's state at the end of one value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoopPoint {
    /// α5.
    pub alpha5: f64,
    /// Ω at the end.
    pub omega: f64,
    /// α2 at the end.
    pub alpha2: f64,
    /// Cycles run at this value.
    pub cycles: usize,
    /// Whether the errors settled below the tolerance.
    pub settled: bool,
}

/// The time-domain FM loop over the values of `spec` (module docs), from the free lever's
/// operating point at rest; counts one unit per value in `progress`.
///
/// # Errors
/// As `fm_reference`, the model's and the integrator's; [`SimError::Cancelled`].
pub fn fm_loop(
    spec: &FmSpec,
    gains: &LoopSpec,
    progress: &Progress,
) -> Result<Vec<LoopPoint>, SimError> {
    let r = fm_reference(&spec.base, spec.mode, spec.amplitude)?;
    progress.add_total(spec.values.len());
    let opts = ObservableOptions {
        periods: 1,
        harmonics: 1,
    };
    let (mut omega, mut alpha2) = (r.omega, r.excitation);
    let mut z = CantileverModel::new(&spec.base.with(SweepParam::Alpha5, spec.values[0]))?.rest();
    let mut out = Vec::with_capacity(spec.values.len());
    for &alpha5 in &spec.values {
        let (mut cycles, mut calm) = (0, 0);
        while cycles < gains.max_cycles && calm < SETTLED_CYCLES {
            if cycles % 1024 == 0 {
                progress.check()?;
            }
            let p = spec
                .base
                .with(SweepParam::Alpha5, alpha5)
                .with(SweepParam::Omega, omega)
                .with(SweepParam::Alpha2, alpha2);
            p.validate()?;
            let model = CantileverModel::new(&p)?;
            let mut integ = build(&model, spec.integrator.clone(), 0.0, &z)?;
            let o = observe(integ.as_mut(), &opts)?;
            z = integ.state().clone();
            let (ea, ep) = (
                o.amplitude / spec.amplitude - 1.0,
                phase_error(o.phase, r.phase),
            );
            calm = if ea.abs().max(ep.abs()) <= gains.tolerance {
                calm + 1
            } else {
                0
            };
            omega -= gains.phase_gain * r.omega / (2.0 * r.quality_factor) * ep;
            alpha2 *= 1.0 - gains.amplitude_gain * ea;
            cycles += 1;
        }
        out.push(LoopPoint {
            alpha5,
            omega,
            alpha2,
            cycles,
            settled: calm >= SETTLED_CYCLES,
        });
        progress.tick();
    }
    Ok(out)
}
