//! What every analysis that starts from a transient shares: the steady-state search
//! ([`SteadyRequest`]), the integrator ([`IntegratorRequest`]) and the initial state
//! ([`StartRequest`], [`initial_state`]).

use super::*;

request! {
    /// The steady-state search of every analysis that starts from a transient.
    #[derive(Copy)]
    pub struct SteadyRequest {
        /// Relative tolerance for two returns of the stroboscopic map to coincide, in
        /// [1e-14, 1e-3].
        pub tol: f64 = SteadyOptions::default().tol,
        /// Cap on the transient, in drive periods, 1..=[`MAX_STEADY_PERIODS`]; `None` (default):
        /// derived from the model's slowest free decay, six times the periods it takes to decay by
        /// `tol` and at least 1 500 (≈ 1.9 Q ln(1/tol) for a lever of quality factor Q:
        /// [`crate::analysis::steady::default_transient_cap`]).
        constants(MAX_STEADY_PERIODS)
        pub max_periods: Option<usize> = SteadyOptions::default().max_periods,
        /// Largest period searched, 1..=[`MAX_PERIOD`].
        constants(MAX_PERIOD)
        pub max_period: usize = SteadyOptions::default().max_period,
    }
}

impl SteadyRequest {
    /// The validated options ([`SteadyOptions::validate`]).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `tol`, `max_period` or `max_periods`.
    pub fn options(&self) -> Result<SteadyOptions, SimError> {
        let opts = SteadyOptions {
            tol: self.tol,
            max_periods: self.max_periods,
            max_period: self.max_period,
            ..SteadyOptions::default()
        };
        opts.validate()?;
        Ok(opts)
    }
}

request! {
    /// The integrator of an analysis that lets the user choose it.
    #[derive(Copy)]
    pub struct IntegratorRequest {
        /// The time integrator: `auto` (the exact propagator for the linear law, the split
        /// integrator for Hertz and the impact law with r > 0, adaptive DOP853 for the plastic
        /// impact law r = 0, the Taylor integrator for DMT; split falls back to adaptive where its
        /// exact free flight cannot be built), `exact`, `rk4`, `rk4-naive`, `adaptive`, `split` or
        /// `taylor`.
        pub integrator: IntegratorKind = IntegratorKind::Auto,
        /// Fixed steps per drive period of `rk4` / `rk4-naive` (default 2000).
        pub steps_per_period: Option<usize>,
        /// Relative and absolute tolerance of the adaptive integrator.
        pub tolerance: f64 = 1e-12,
    }
}

impl IntegratorRequest {
    /// The options: `exact` (and `auto`, which picks it for the linear law) refines its own
    /// grid from `samples_per_period` so that samples land on grid points; `rk4` takes
    /// `steps_per_period` (default 2000); `adaptive` chooses its steps. With a new exact
    /// propagator's cache, which every build of the request shares.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `steps_per_period` when it is given to an integrator
    /// that chooses its own steps (only `rk4` and `rk4-naive` take it: it was ignored).
    pub fn options(&self, samples_per_period: usize) -> Result<IntegratorOptions, SimError> {
        if let (Some(n), false) = (
            self.steps_per_period,
            matches!(
                self.integrator,
                IntegratorKind::Rk4 | IntegratorKind::Rk4Naive
            ),
        ) {
            return Err(SimError::out_of_range(
                "steps_per_period",
                n,
                "is taken by the fixed-step integrators rk4 and rk4-naive only (the others \
                 choose their own steps): give integrator = rk4, or omit it",
            ));
        }
        let steps = match self.integrator {
            IntegratorKind::Auto | IntegratorKind::Exact | IntegratorKind::Split => {
                samples_per_period.max(1)
            }
            IntegratorKind::Rk4 | IntegratorKind::Rk4Naive => self.steps_per_period.unwrap_or(2000),
            IntegratorKind::Adaptive | IntegratorKind::Taylor => 1,
        };
        Ok(IntegratorOptions {
            kind: self.integrator,
            steps_per_period: steps,
            tolerance: self.tolerance,
            ..IntegratorOptions::default()
        })
    }
}

/// The initial state `z = (a, ȧ)` (2N values) of `model`, or rest when `None`.
///
/// # Errors
/// [`SimError::StateLength`] for a length other than 2N, [`SimError::OutOfRange`] naming
/// `initial` for an entry not finite or at or above `MAX_INITIAL_ENTRY`.
pub fn initial_state(
    model: &CantileverModel,
    initial: Option<&[f64]>,
) -> Result<DVector<f64>, SimError> {
    let Some(z) = initial else {
        return Ok(model.rest());
    };
    let n = model.modes();
    // (a, ȧ) with the law's internal states at rest, or the whole state (an orbit's, fed back)
    if z.len() != 2 * n && z.len() != model.dim() {
        return Err(SimError::StateLength {
            name: "initial (a1..aN, adot1..adotN)",
            expected: 2 * n,
            got: z.len(),
        });
    }
    // the first entry that is not finite, else the largest in magnitude
    let worst = z
        .iter()
        .copied()
        .find(|v| !v.is_finite())
        .unwrap_or_else(|| z.iter().fold(0.0f64, |m, v| m.max(v.abs())));
    if !worst.is_finite() || worst >= MAX_INITIAL_ENTRY {
        return Err(SimError::out_of_range(
            "initial",
            if worst.is_finite() {
                format!("largest entry {worst:e}")
            } else {
                format!("an entry {worst}")
            },
            "every entry must be finite and below 1e11 (states of norm 1e12 count as diverged)",
        ));
    }
    let mut state = model.state_from(&z[..n], &z[n..2 * n])?;
    state.as_mut_slice()[2 * n..].copy_from_slice(&z[2 * n..]);
    Ok(state)
}

request! {
    /// Where an orbit analysis starts: a given state, or the steady state reached from rest.
    pub struct StartRequest {
        /// The initial state (2N values a1..aN, ȧ1..ȧN) used as the guess as it is; `None`: the
        /// end of the steady state reached from rest.
        pub initial: Option<Vec<f64>>,
        /// The steady-state search from rest.
        pub steady: SteadyRequest,
    }
}

impl StartRequest {
    /// The longest period and the transient cap (drive periods) of the steady-state search
    /// [`Self::guess`] runs from this start on `model`; `None` for a given `initial` state
    /// (not searched).
    ///
    /// # Errors
    /// As [`SteadyRequest::options`].
    pub(crate) fn searched(
        &self,
        model: &CantileverModel,
    ) -> Result<Option<(usize, usize)>, SimError> {
        let steady = self.steady.options()?;
        Ok(self
            .initial
            .is_none()
            .then(|| (steady.max_period, steady.cap(model))))
    }
}
