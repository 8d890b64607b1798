//! Lyapunov exponents of the switched system and the 0–1 test for chaos.
//!
//! The tangent dynamics are propagated with the integrator's step Jacobians (exact e^{A_s t}, or
//! the variational equations) and the saltation matrix at every event
//! ([`crate::system::saltation`]); the tangent basis
//! is re-orthonormalised by a QR factorisation once per drive period (Benettin et al.,
//! Meccanica 15 (1980) 9; for jumps: Müller, Chaos Solitons Fractals 5 (1995) 1671). The
//! uncertainty is the standard error of the exponent over equal blocks of the run.
//!
//! The 0–1 test (Gottwald & Melbourne, SIAM J. Appl. Dyn. Syst. 8 (2009) 129, correlation
//! method) is computed on V_T at the stroboscopic section: K ≈ 0 for regular, ≈ 1 for chaotic
//! motion. It uses no derivative information, so it checks the exponents independently.

use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::integrate::Integrator;
use crate::integrate::{advance, build, IntegratorOptions};
use crate::maps::flow::flow;
use crate::model::CantileverModel;
use nalgebra::{DMatrix, DVector};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

/// Options of the Lyapunov computation.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct LyapunovOptions {
    /// Drive periods discarded first.
    pub transient_periods: usize,
    /// Drive periods averaged.
    pub periods: usize,
    /// Blocks for the uncertainty estimate.
    pub blocks: usize,
    /// Integrator (default: auto, exact for the linear law; it must provide step Jacobians).
    pub integrator: IntegratorOptions,
}

impl Default for LyapunovOptions {
    fn default() -> Self {
        LyapunovOptions {
            transient_periods: 500,
            periods: 4000,
            blocks: 10,
            integrator: IntegratorOptions::default(),
        }
    }
}

impl LyapunovOptions {
    /// Check the options (the one place of their limits).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `blocks` unless periods ≥ blocks ≥ 2.
    pub(crate) fn validate(&self) -> Result<(), SimError> {
        if self.blocks < 2 || self.periods < self.blocks {
            return Err(SimError::out_of_range(
                "blocks",
                format!("{} with periods = {}", self.blocks, self.periods),
                "need periods >= blocks >= 2",
            ));
        }
        Ok(())
    }
}

/// Verdict from the exponents and the 0–1 test.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// Largest exponent significantly negative: the motion converges to a periodic orbit.
    Periodic,
    /// Largest exponent zero within its uncertainty and K ≈ 0: quasi-periodic.
    Quasiperiodic,
    /// Largest exponent significantly positive and K ≈ 1.
    Chaotic,
    /// The two indicators disagree or are inconclusive.
    Undecided,
}

/// Result of `lyapunov_spectrum`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LyapunovSpectrum {
    /// Exponents per unit τ, in decreasing order (2N of them).
    pub exponents: Vec<f64>,
    /// Standard error of each exponent over the blocks.
    pub uncertainty: Vec<f64>,
    /// Convergence estimate of each exponent, |λ_i(T) − λ_i(T/2)|: finite-time exponents
    /// converge like c/T (the non-normal transient and the rotation within a complex pair do not
    /// average out), and for that rate the difference to the half-run estimate is the error.
    /// The error of λ_i is within `uncertainty` + `convergence`.
    pub convergence: Vec<f64>,
    /// Mean phase-volume contraction rate (Σ trace A_s · time + Σ log|det S|) / time; equals the
    /// sum of the exponents (Liouville).
    pub volume_rate: f64,
    /// 0–1 test statistic K on V_T at the section.
    pub zero_one: f64,
    /// Periods averaged.
    pub periods: usize,
    /// What limits the run's reliability: too few periods, blocks too short for independent
    /// uncertainties, exponents not resolved from zero (|λ| ≤ 2 × (uncertainty + convergence)).
    pub warnings: Vec<String>,
    /// Verdict.
    pub verdict: Verdict,
}

/// The largest exponent λ₁ of the motion from `z0` (a state on an attractor, at τ = 0) over
/// `periods` drive periods without transient, in 10 blocks (fewer for a short run), and its
/// error (uncertainty plus convergence estimate, as [`LyapunovSpectrum`] reports them);
/// `None` when the run fails or is shorter than 2 periods. What a chart's or a basin map's
/// nonperiodic attractor records.
pub(crate) fn largest_exponent(
    model: &CantileverModel,
    z0: &DVector<f64>,
    periods: usize,
    integrator: IntegratorOptions,
) -> Option<(f64, f64)> {
    let opts = LyapunovOptions {
        transient_periods: 0,
        periods,
        blocks: 10.min(periods),
        integrator,
    };
    let l = lyapunov_spectrum(model, z0, &opts).ok()?;
    Some((
        *l.exponents.first()?,
        l.uncertainty.first()? + l.convergence.first()?,
    ))
}

/// Lyapunov spectrum from the state `z0` at τ = 0.
///
/// # Errors
/// [`SimError`] for invalid options or a failing run.
pub(crate) fn lyapunov_spectrum(
    model: &CantileverModel,
    z0: &DVector<f64>,
    opts: &LyapunovOptions,
) -> Result<LyapunovSpectrum, SimError> {
    opts.validate()?;
    let mut integ = build(model, opts.integrator.clone(), 0.0, z0)?;
    lyapunov_spectrum_with(integ.as_mut(), opts, &Progress::new())
}

/// [`lyapunov_spectrum`] with a given integrator of any [`crate::TipSampleSystem`], from its
/// current state (moved to τ = 0 if it is not there; `opts.integrator` is not used), counting
/// the drive periods done in `progress` (transient and recorded) and stopping when it is
/// cancelled (checked before and after the transient, then every period).
///
/// # Errors
/// As [`lyapunov_spectrum`]; [`SimError::Cancelled`] once `progress` is cancelled.
pub(crate) fn lyapunov_spectrum_with(
    integ: &mut dyn Integrator,
    opts: &LyapunovOptions,
    progress: &Progress,
) -> Result<LyapunovSpectrum, SimError> {
    opts.validate()?;
    let period = integ.system().period();
    let dim = integ.system().dim();
    if integ.tau() != 0.0 {
        let z0 = integ.state().clone();
        integ.reset(0.0, &z0)?;
    }
    let t0 = opts.transient_periods as f64 * period;
    let per_block = opts.periods / opts.blocks;
    progress.add_total(opts.transient_periods + per_block * opts.blocks);
    // the transient in one call (slicing it would change the adaptive integrator's steps):
    // a cancel is seen after it, then every period
    progress.check()?;
    advance(&mut *integ, t0)?;
    progress.advance(opts.transient_periods);
    let mut z = integ.state().clone();
    let mut q = DMatrix::<f64>::identity(dim, dim);
    let mut block_sums = vec![vec![0.0; dim]; opts.blocks];
    let mut log_volume = 0.0;
    let mut section = Vec::with_capacity(opts.periods);
    let total_periods = per_block * opts.blocks;
    for k in 0..total_periods {
        progress.check()?;
        // one period of the flow with its Jacobian (step propagators × saltation matrices)
        let (ta, tb) = (t0 + k as f64 * period, t0 + (k + 1) as f64 * period);
        let map = flow(&mut *integ, ta, &z, tb, None, true)?;
        log_volume += map.log_volume;
        q = map.jacobian * q;
        z = map.state;
        let qr = q.clone().qr();
        let r = qr.r();
        for (i, acc) in block_sums[k / per_block].iter_mut().enumerate() {
            *acc += r[(i, i)].abs().ln();
        }
        q = qr.q();
        section.push(integ.system().v_t(tb, &z));
        progress.tick();
    }
    let block_time = per_block as f64 * period;
    let half = opts.blocks / 2;
    let mut exponents = vec![0.0; dim];
    let mut uncertainty = vec![0.0; dim];
    let mut convergence = vec![0.0; dim];
    for i in 0..dim {
        let rates: Vec<f64> = block_sums.iter().map(|b| b[i] / block_time).collect();
        let mean = rates.iter().sum::<f64>() / rates.len() as f64;
        let var = rates.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (rates.len() - 1) as f64;
        exponents[i] = mean;
        uncertainty[i] = (var / rates.len() as f64).sqrt();
        let first_half = rates[..half].iter().sum::<f64>() / half as f64;
        convergence[i] = (mean - first_half).abs();
    }
    // QR orders the exponents only asymptotically: sort the finite-time estimates
    let mut order: Vec<usize> = (0..dim).collect();
    order.sort_by(|&a, &b| exponents[b].total_cmp(&exponents[a]));
    let exponents: Vec<f64> = order.iter().map(|&i| exponents[i]).collect();
    let uncertainty: Vec<f64> = order.iter().map(|&i| uncertainty[i]).collect();
    let convergence: Vec<f64> = order.iter().map(|&i| convergence[i]).collect();
    let zero_one = zero_one_test(&section, 0x5eed);
    let (l1, s1) = (exponents[0], uncertainty[0]);
    let tol = 3.0 * s1 + convergence[0] + 1e-4;
    let verdict = if l1 < -tol {
        Verdict::Periodic
    } else if l1 > tol && zero_one > 0.5 {
        Verdict::Chaotic
    } else if l1.abs() <= tol && zero_one < 0.5 {
        Verdict::Quasiperiodic
    } else {
        Verdict::Undecided
    };
    let warnings = run_warnings(
        &exponents,
        &uncertainty,
        &convergence,
        total_periods,
        opts.blocks,
    );
    Ok(LyapunovSpectrum {
        exponents,
        uncertainty,
        convergence,
        volume_rate: log_volume / (total_periods as f64 * period),
        zero_one,
        periods: total_periods,
        verdict,
        warnings,
    })
}

/// Fewest periods averaged for exponents whose signs are reliable (the default is 4000).
pub(crate) const MIN_PERIODS: usize = 200;

/// The warnings of [`LyapunovSpectrum::warnings`].
/// Whether an exponent `e` is resolved from zero: |λ| > 2 × (uncertainty `u` + convergence
/// `c`), its sign settled (the run's warnings name those that are not).
pub(crate) fn resolved(e: f64, u: f64, c: f64) -> bool {
    e.abs() > 2.0 * (u + c)
}

fn run_warnings(
    exponents: &[f64],
    uncertainty: &[f64],
    convergence: &[f64],
    periods: usize,
    blocks: usize,
) -> Vec<String> {
    let mut w = vec![];
    if periods < MIN_PERIODS {
        w.push(warning!(
            "lyapunov.short",
            "Run at least the recommended number of periods (the default is 4000).",
            "only {periods} periods averaged (at least {MIN_PERIODS} recommended, default \
             4000): the exponents have not converged and their signs are not reliable"
        ));
    }
    if periods / blocks.max(1) < 20 {
        w.push(warning!(
            "lyapunov.blocks",
            "Run more periods, or fewer blocks, so that each block holds at least 20 \
             periods.",
            "{} periods per block: the uncertainties are estimated from blocks too short to be \
             independent",
            periods / blocks.max(1)
        ));
    }
    let unresolved: Vec<String> = exponents
        .iter()
        .zip(uncertainty.iter().zip(convergence))
        .enumerate()
        .filter(|(_, (e, (u, c)))| !resolved(**e, **u, **c))
        .map(|(k, _)| (k + 1).to_string())
        .collect();
    if !unresolved.is_empty() {
        w.push(warning!(
            "lyapunov.unresolved",
            "Run more periods, until the exponents' uncertainty is small against their \
             size.",
            "exponent(s) {} not resolved from zero (|λ| ≤ 2 × (uncertainty + convergence)): run \
             more periods",
            unresolved.join(", ")
        ));
    }
    w
}

/// The 0–1 test for chaos (correlation method) on a scalar series φ_j: K = median over 100
/// frequencies c ∈ (π/5, 4π/5) of corr(n, D_c(n)), n ≤ len/10, with
/// D_c(n) = M_c(n) − ⟨φ⟩² (1 − cos nc)/(1 − cos c) and M_c the mean square displacement of
/// p_c(n) = Σ φ_j cos jc, q_c(n) = Σ φ_j sin jc. Returns NaN for fewer than 100 points and 0
/// for a series constant to 1e-9 (a period-1 orbit seen on its section).
pub(crate) fn zero_one_test(phi: &[f64], seed: u64) -> f64 {
    let len = phi.len();
    if len < 100 {
        return f64::NAN;
    }
    let ncut = len / 10;
    let mean = phi.iter().sum::<f64>() / len as f64;
    // a series that has settled on a fixed point of the section carries no information: regular
    let spread = phi.iter().map(|v| (v - mean).abs()).fold(0.0, f64::max);
    if spread <= 1e-9 * (1.0 + mean.abs()) {
        return 0.0;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut ks: Vec<f64> = (0..100)
        .map(|_| {
            let c: f64 =
                rng.random_range(std::f64::consts::PI / 5.0..4.0 * std::f64::consts::PI / 5.0);
            let (mut p, mut q) = (Vec::with_capacity(len), Vec::with_capacity(len));
            let (mut ps, mut qs) = (0.0, 0.0);
            for (j, v) in phi.iter().enumerate() {
                let a = (j + 1) as f64 * c;
                ps += v * a.cos();
                qs += v * a.sin();
                p.push(ps);
                q.push(qs);
            }
            let d: Vec<f64> = (1..=ncut)
                .map(|n| {
                    let m = (0..len - n)
                        .map(|j| (p[j + n] - p[j]).powi(2) + (q[j + n] - q[j]).powi(2))
                        .sum::<f64>()
                        / (len - n) as f64;
                    m - mean * mean * (1.0 - (n as f64 * c).cos()) / (1.0 - c.cos())
                })
                .collect();
            correlation(&(1..=ncut).map(|n| n as f64).collect::<Vec<_>>(), &d)
        })
        .filter(|k| k.is_finite())
        .collect();
    if ks.is_empty() {
        return 0.0;
    }
    ks.sort_by(f64::total_cmp);
    ks[ks.len() / 2]
}

fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let cov: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let vx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    let vy: f64 = y.iter().map(|b| (b - my).powi(2)).sum();
    cov / (vx * vy).sqrt()
}
