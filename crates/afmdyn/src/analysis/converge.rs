//! Mode-number convergence (paper Fig. 4): the steady-state tip motion for N = 1..N_max.

use super::progress::Progress;
use super::steady::{steady_state, SteadyOptions};
use crate::error::SimError;
use crate::integrate::{build, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::Params;
use crate::trajectory::{record, RecordSpec};

/// The steady tip motion for one N.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceRun {
    /// Number of modes N.
    pub modes: usize,
    /// Period of the steady state (None: nonperiodic).
    pub period: Option<usize>,
    /// τ of the samples (starting at a section point).
    pub tau: Vec<f64>,
    /// W(1,τ) at the samples.
    pub w_tip: Vec<f64>,
    /// V_T at the samples.
    pub v_t: Vec<f64>,
    /// RMS of W_tip(N) − W_tip(N−1) over the samples (None for N = 1).
    pub rms_change: Option<f64>,
}

/// Steady-state tip motion for N = 1..=`max_modes` at `params` (its N is ignored), sampled at
/// `samples_per_period` over `periods` drive periods from a section point, counting the runs
/// done (N = 1..=`max_modes`) in `progress` and stopping when it is cancelled.
///
/// # Errors
/// [`SimError`] for invalid parameters or a failing run; [`SimError::Cancelled`] once
/// `progress` is cancelled.
pub(crate) fn mode_convergence(
    params: &Params,
    max_modes: usize,
    periods: usize,
    samples_per_period: usize,
    steady: &SteadyOptions,
    integrator: IntegratorOptions,
    progress: &Progress,
) -> Result<Vec<ConvergenceRun>, SimError> {
    if periods == 0 || samples_per_period == 0 {
        return Err(SimError::out_of_range(
            "periods / samples per period",
            0,
            "must be >= 1",
        ));
    }
    let mut runs: Vec<ConvergenceRun> = Vec::with_capacity(max_modes);
    progress.add_total(max_modes);
    for n in 1..=max_modes {
        progress.check()?;
        let p = Params {
            modes: n,
            ..*params
        };
        let model = CantileverModel::new(&p)?;
        let mut integ = build(
            &model,
            IntegratorOptions {
                steps_per_period: samples_per_period,
                ..integrator.clone()
            },
            0.0,
            &model.rest(),
        )?;
        let s = steady_state(integ.as_mut(), steady)?;
        let tr = record(
            integ.as_mut(),
            &RecordSpec {
                transient_periods: 0.0,
                record_tau: periods as f64 * p.period(),
                samples_per_period,
                energy: false,
                body_contact: false,
            },
        )?;
        let w_tip: Vec<f64> = tr.samples.iter().map(|s| s.w_tip).collect();
        let rms_change = runs.last().map(|prev| {
            let k = prev.w_tip.len().min(w_tip.len());
            (prev
                .w_tip
                .iter()
                .zip(&w_tip)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                / k as f64)
                .sqrt()
        });
        runs.push(ConvergenceRun {
            modes: n,
            period: s.period(),
            tau: tr.samples.iter().map(|s| s.tau).collect(),
            v_t: tr.samples.iter().map(|s| s.v_t).collect(),
            w_tip,
            rms_change,
        });
        progress.tick();
    }
    Ok(runs)
}
