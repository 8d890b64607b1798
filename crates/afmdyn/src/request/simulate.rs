//! The `simulate` request ([`SimulateRequest`]): one trajectory recorded after a transient,
//! its span and its budget by where the series goes ([`SeriesStore`], [`SimulateSpan`]).

use super::analyses::{check_samples_per_period, IntegratorRequest};
use super::limits::*;
use crate::error::SimError;
use crate::integrate::exact::noise::holding_samples;
use crate::integrate::exact::{ThermalExact, ThermalForce};
use crate::integrate::{Integrator, IntegratorKind, IntegratorOptions};
use crate::model::CantileverModel;
use crate::params::Params;
use crate::probe::Probe;
use nalgebra::DVector;

/// Where a recorded time series goes, which sets its budget.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeriesStore {
    /// Streamed to files in chunks: `MAX_SERIES_BYTES` on disk.
    Files,
    /// Held whole in memory (a Python call): `MAX_SERIES_MEMORY_BYTES`.
    Memory,
    /// Not kept (only the summary).
    Nothing,
}

request! {
    /// `simulate`: one trajectory recorded after a transient.
    pub struct SimulateRequest {
        /// Drive periods recorded after the transient (> 0); default 50 when `tau_end` is not
        /// given either.
        pub periods: Option<f64>,
        /// End time τ of the run, instead of `periods`.
        pub tau_end: Option<f64>,
        /// Drive periods discarded before recording, >= 0.
        pub transient: f64 = 0.0,
        /// The initial state (2N values); `None`: rest.
        pub initial: Option<Vec<f64>>,
        /// Samples per drive period, 1..=[`MAX_SAMPLES_PER_PERIOD`].
        constants(MAX_SAMPLES_PER_PERIOD)
        pub samples_per_period: usize = 200,
        /// Audit the energy balance of every drive period (`energy.csv`, the series' `energy_*`
        /// variables and the summary's `energy_residual`, whose residual checks the integration);
        /// off by default, as it takes a quarter to a half of the run's time
        /// (`docs/performance/recording.md`).
        #[cfg_attr(feature = "schema", schemars(extend("default" = false)))]
        pub energy_balance: bool = false,
        /// The temperature T of the thermal force (K, > 0 and ≤ 1500; outside 200–500 K it warns,
        /// a value in °C?); `None` (the default): no thermal noise, the deterministic run. Each
        /// mode's equation then carries the white force the fluctuation–dissipation theorem gives
        /// for its damping (the lever's, the medium's, in contact the linear law's dashpot, SLS's
        /// on its dashpot's extension), advanced by the exact stochastic step of the linear law,
        /// SLS and the impact law (its impacts on the bridge, its sticking holding the tip
        /// against the force's part at it), or the exponential Euler step of Hertz, DMT, the
        /// electrostatic law, JKR and the capillary meniscus (their region the run's own;
        /// `crate::integrate::exact::noise`). Needs the probe's SI units (`--probe`); not with
        /// `energy_balance`. Under a
        /// multifrequency drive each further component adds its particular solution.
        pub temperature: Option<f64>,
        /// The seed of the thermal force's random stream (with `temperature`; default 0): a run is
        /// a function of its seed, whatever the threads.
        #[cfg_attr(feature = "schema", schemars(extend("default" = 0)))]
        pub seed: u64 = 0;
        flatten integrator: IntegratorRequest,
    }
}

/// The time span of a validated [`SimulateRequest`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimulateSpan {
    /// τ at which recording starts (the transient).
    pub transient_tau: f64,
    /// Length of the recording in τ.
    pub record_tau: f64,
    /// Drive periods in all, transient included.
    pub total_periods: f64,
    /// Samples of the recorded series (ends included).
    pub rows: f64,
}

impl SimulateRequest {
    /// The integrator options of the recording: the samples come from the steps' dense output
    /// ([`crate::trajectory::record`]), so the exact grid is the one the physics needs, not a
    /// multiple of the samples per period (both front ends record with these options, so the
    /// command line's files and Python's arrays are the same numbers).
    ///
    /// # Errors
    /// As [`super::analyses::IntegratorRequest::options`].
    pub(crate) fn integrator_options(&self) -> Result<IntegratorOptions, SimError> {
        self.integrator.options(1)
    }

    /// Check every option for `params` and return the span; `columns` values of
    /// `bytes_per_value` bytes per sample are kept in `store`.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the option, [`SimError::Budget`] for a series beyond
    /// the store's budget.
    pub fn validate(
        &self,
        params: &Params,
        store: SeriesStore,
        columns: usize,
        bytes_per_value: f64,
    ) -> Result<SimulateSpan, SimError> {
        check_samples_per_period(self.samples_per_period)?;
        let (t, why) = (self.transient, "must be finite and >= 0");
        crate::error::within("transient", t, 0.0..f64::INFINITY, why)?;
        let period = params.period();
        let transient_tau = self.transient * period;
        let record_tau = match (self.periods, self.tau_end) {
            (Some(n), Some(t)) => {
                return Err(SimError::out_of_range(
                    "periods",
                    format!("{n} with tau_end = {t}"),
                    "give periods or tau_end, not both",
                ))
            }
            (Some(n), None) if n.is_finite() && n > 0.0 => n * period,
            (Some(n), None) => {
                return Err(SimError::out_of_range(
                    "periods",
                    n,
                    "must be finite and > 0",
                ))
            }
            (None, Some(t)) if t.is_finite() && t > transient_tau => t - transient_tau,
            (None, Some(t)) => {
                return Err(SimError::out_of_range(
                    "tau_end",
                    format!("{t} (the transient ends at τ = {transient_tau})"),
                    "must be finite and > the end of the transient",
                ))
            }
            (None, None) => 50.0 * period,
        };
        let total_periods = self.transient + record_tau / period;
        if total_periods > MAX_RUN_PERIODS {
            return Err(SimError::out_of_range(
                "periods",
                format!("{total_periods:e} with the transient"),
                "a run may span at most 1e8 drive periods (beyond, τ no longer resolves the \
                 integration grid)",
            ));
        }
        let rows = (record_tau / period * self.samples_per_period as f64).floor() + 1.0;
        let budget = match store {
            SeriesStore::Files => MAX_SERIES_BYTES,
            SeriesStore::Memory => MAX_SERIES_MEMORY_BYTES,
            SeriesStore::Nothing => f64::INFINITY,
        };
        let bytes = rows * columns as f64 * bytes_per_value;
        if bytes > budget {
            return Err(SimError::Budget {
                what: "the time series",
                needed: format!(
                    "{:.1} GB ({rows:.3e} samples × {columns} columns)",
                    bytes / 1e9
                ),
                budget: format!("{:.0} GiB", budget / super::limits::GIB),
                hint: "lower periods or samples_per_period, or keep no time series",
            });
        }
        Ok(SimulateSpan {
            transient_tau,
            record_tau,
            total_periods,
            rows,
        })
    }

    /// The thermal force of the run: `None` without a temperature; with one, its range checked
    /// ([`super::limits::check_temperature`]) and k_B T in the units of `probe`.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `temperature` (out of range, or without a probe: the
    /// dimensionless model has no k_B T) or `energy_balance` (the audit assumes no random
    /// force).
    pub fn thermal(&self, probe: Option<&Probe>) -> Result<Option<ThermalForce>, SimError> {
        let Some(t) = self.temperature else {
            return Ok(None);
        };
        let force = super::limits::thermal_force(t, self.seed, probe)?;
        if self.energy_balance {
            return Err(SimError::out_of_range(
                "energy_balance",
                "true with temperature",
                "the energy audit's balance has no random force: drop energy_balance or \
                 temperature",
            ));
        }
        Ok(Some(force))
    }

    /// The warnings of the request: a temperature outside the laboratory's range.
    pub fn warnings(&self) -> Vec<String> {
        (self.temperature.map(super::limits::temperature_warnings)).unwrap_or_default()
    }

    /// The integrator of the run of `model` from `z0` at τ = 0: [`crate::integrate::build`]'s,
    /// or with a temperature the exact stochastic step ([`ThermalExact`]) on a grid that is a
    /// multiple of the samples per period, holding them (the samples are its drawn points).
    ///
    /// # Errors
    /// As [`SimulateRequest::thermal`], [`crate::integrate::build`] and [`ThermalExact::new`];
    /// [`SimError::OutOfRange`] naming `integrator` for a temperature with an integrator other
    /// than `auto` or `exact`.
    pub fn integrator(
        &self,
        model: &CantileverModel,
        probe: Option<&Probe>,
        z0: &DVector<f64>,
    ) -> Result<Box<dyn Integrator>, SimError> {
        let mut opts = self.integrator_options()?;
        let Some(force) = self.thermal(probe)? else {
            return crate::integrate::build(model, opts, 0.0, z0);
        };
        if !matches!(opts.kind, IntegratorKind::Auto | IntegratorKind::Exact) {
            return Err(SimError::out_of_range(
                "integrator",
                format!("{:?} with temperature", opts.kind).to_lowercase(),
                "thermal noise is advanced by the exact stochastic step: auto or exact",
            ));
        }
        opts.steps_per_period = holding_samples(opts.steps_per_period, self.samples_per_period);
        let mut it = ThermalExact::new(model, &opts, force)?.holding(self.samples_per_period);
        it.reset(0.0, z0)?;
        Ok(Box::new(it))
    }

    /// [`SimulateRequest::validate`] for a series held whole in memory ([`SeriesStore::Memory`],
    /// `SimulateRequest::record_whole`: τ, V_T, V̇_T, W, Ẇ, contact, force and the state's
    /// entries per sample, 8 bytes each; Python's arrays, the browser's series).
    ///
    /// # Errors
    /// As [`SimulateRequest::validate`].
    pub fn validate_in_memory(&self, params: &Params) -> Result<SimulateSpan, SimError> {
        self.validate(params, SeriesStore::Memory, 7 + params.state_dim(), 8.0)
    }
    /// What a recording held whole in memory costs: its samples as
    /// [`crate::trajectory::record`] grows them (`request::costs::recorded_sample_bytes` ×
    /// `TRACE_GROWTH`) and their columns, and its drive periods × modes.
    ///
    /// # Errors
    /// As [`SimulateRequest::validate_in_memory`].
    pub fn in_memory_cost(&self, params: &Params) -> Result<Cost, SimError> {
        use super::costs::{recorded_sample_bytes, MODEL_BYTES, TRACE_GROWTH};
        let span = self.validate_in_memory(params)?;
        let columns = (7 + params.state_dim()) as f64 * 8.0;
        Ok(Cost {
            bytes: MODEL_BYTES
                + span.rows * (TRACE_GROWTH * recorded_sample_bytes(params) + columns),
            work: span.total_periods * params.modes as f64,
        })
    }
}
