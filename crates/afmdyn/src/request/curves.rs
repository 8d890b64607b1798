//! The request of a stepped curve (`approach`, `resonance`): its ends, step or number of points
//! and tolerance as a front end takes them, in the front end's unit of the swept quantity, and
//! the [`SteppedSpec`] they give ([`approach_request`], [`resonance_request`]).

use crate::analysis::approach::{approach_spec, default_range};
use crate::analysis::observables::free_response;
use crate::analysis::resonance::{mode_band, mode_resonance, resonance_spec};
use crate::analysis::stepped::average::AverageOptions;
use crate::analysis::stepped::{
    Spacing, SteppedSpec, DEFAULT_CURVE_POINTS, DEFAULT_TOLERANCE, MAX_CURVE_POINTS,
};
use crate::error::{within, SimError};
use crate::model::CantileverModel;
use crate::params::{Params, OMEGA_MAX, OMEGA_MIN};

request! {
    /// A stepped-curve request as a front end takes it (`afmdyn approach` / `resonance` flags, the
    /// Python keywords): the ends and the step in the front end's unit of the swept quantity (one
    /// dimensionless unit = `unit` of them: g₀ in m, or Hz per unit Ω), `None` for the command's
    /// default range; [`approach_request`] and
    /// [`resonance_request`] turn it into a
    /// [`SteppedSpec`].
    #[derive(Copy)]
    pub struct CurveRequest {
        /// First end of the swept quantity (front-end unit): the rest distance z_c where the
        /// approach starts (m with a probe, else g₀; default 1.2 × the free amplitude A₀, the sum of
        /// the components' under a multifrequency drive), or the start of the resonance band (Hz
        /// with a probe, else Ω; default ω_k (1 − w), w = max(6/Q_k, 0.02)).
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "swept")))]
        pub from: Option<f64>,
        /// Other end (front-end unit): z_c where the approach ends and the retract starts (default
        /// 0.1 × A₀), or the end of the resonance band (default ω_k (1 + w)).
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "swept")))]
        pub to: Option<f64>,
        /// Grid step (front-end unit, that of `from` and `to`); excludes `points`.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "swept")))]
        pub step: Option<f64>,
        /// Number of grid values, ends included, 2..=[`MAX_CURVE_POINTS`] (default
        /// [`DEFAULT_CURVE_POINTS`]; a resonance curve with a probe takes more where a tenth of
        /// the linewidth needs them ([`crate::request::curves::linewidth_points`])).
        constants(MAX_CURVE_POINTS, DEFAULT_CURVE_POINTS)
        pub points: Option<usize>,
        /// Continue the periodic-orbit branches.
        pub branches: bool = true,
        /// Tolerance of the adaptive integrator, in (0, 1e-3).
        pub tolerance: f64 = DEFAULT_TOLERANCE,
        /// Record one steady-state cycle per point of the first sweep with this many samples per
        /// drive period (2..=10000; [`crate::analysis::traces`]); `None`: no traces.
        pub traces: Option<usize>,
    }
    /// The defaults of `afmdyn approach` / `resonance` and the Python functions: the command's
    /// range, [`DEFAULT_CURVE_POINTS`] values, branches continued, `DEFAULT_TOLERANCE`.
    impl Default;
}

/// The worst-case memory of the traces of a curve of `points` points at `samples` samples per
/// drive period, in bytes: every trace over
/// [`crate::analysis::traces::MAX_TRACE_PERIODS`] periods of
/// [`super::limits::TRACE_BYTES_PER_SAMPLE`] bytes a sample (held against
/// [`super::limits::MAX_TRACE_BYTES`], and part of the curve's [`super::limits::Cost`]).
pub(crate) fn trace_bytes(points: usize, samples: usize) -> f64 {
    points as f64
        * (crate::analysis::traces::MAX_TRACE_PERIODS * samples) as f64
        * super::limits::TRACE_BYTES_PER_SAMPLE
}

impl CurveRequest {
    /// The given ends and step are finite numbers (a NaN end was reported as the other one).
    ///
    /// # Errors
    /// [`SimError::NotFinite`] naming `from`, `to` or `step`.
    pub(crate) fn check_finite(&self) -> Result<(), SimError> {
        self.given()
            .try_for_each(|(name, v)| crate::error::finite(name, v).map(|_| ()))
    }

    /// The given ends and step, by name.
    fn given(&self) -> impl Iterator<Item = (&'static str, f64)> {
        let named = [("from", self.from), ("to", self.to), ("step", self.step)];
        named.into_iter().filter_map(|(name, v)| Some((name, v?)))
    }

    /// The given ends and step as distances in m ([`super::limits::si_distance`]).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `from`, `to` or `step`.
    pub(crate) fn check_si_distances(&self) -> Result<(), SimError> {
        self.given()
            .try_for_each(|(name, v)| super::limits::si_distance(name, v))
    }

    /// The ends in dimensionless units: the requested ones divided by `unit`, else `default`.
    pub(crate) fn ends(&self, default: (f64, f64), unit: f64) -> (f64, f64) {
        (
            self.from.map_or(default.0, |v| v / unit),
            self.to.map_or(default.1, |v| v / unit),
        )
    }

    /// The grid spacing in dimensionless units.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] when both a step and a count are given.
    pub(crate) fn spacing(&self, unit: f64) -> Result<Spacing, SimError> {
        match (self.step, self.points) {
            (Some(h), Some(_)) => Err(SimError::out_of_range(
                "step",
                h,
                "give step or points, not both",
            )),
            (Some(h), None) => Ok(Spacing::Step(h / unit)),
            (None, n) => Ok(Spacing::Points(n.unwrap_or(DEFAULT_CURVE_POINTS))),
        }
    }

    /// Set the tolerance and branch option of `spec` and check the parameters at both ends of
    /// its grid (before any work or output).
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] for a tolerance outside (0, 1e-3) or traces samples outside
    /// 2..=10000; [`SimError::Budget`] for traces beyond [`super::limits::MAX_TRACE_BYTES`];
    /// [`SimError::Params`] for parameters invalid at an end of the grid.
    pub(crate) fn configure(&self, mut spec: SteppedSpec) -> Result<SteppedSpec, SimError> {
        super::limits::tolerance("tolerance", self.tolerance)?;
        for v in [spec.values[0], spec.values[spec.values.len() - 1]] {
            let p = spec.base.with(spec.param, v);
            match spec.average {
                Some(_) => p.validate_fields()?,
                None => p.validate()?,
            }
        }
        spec.integrator.tolerance = self.tolerance;
        // the time average follows the motion in time: no periodic orbits to continue
        spec.branches = self.branches && spec.average.is_none();
        if let Some(n) = self.traces {
            within(
                "traces",
                n,
                2..=crate::analysis::traces::MAX_TRACE_SAMPLES,
                "must be in 2..=10000 samples per drive period",
            )?;
            // the worst case up front: every trace over MAX_TRACE_PERIODS periods
            let bytes = trace_bytes(spec.values.len(), n);
            if bytes > super::limits::MAX_TRACE_BYTES {
                return Err(SimError::Budget {
                    what: "traces",
                    needed: format!(
                        "{} points × {n} samples per period × up to {} periods: up to {:.1} GiB",
                        spec.values.len(),
                        crate::analysis::traces::MAX_TRACE_PERIODS,
                        bytes / super::limits::GIB
                    ),
                    budget: "1 GiB".into(),
                    hint: "fewer points or fewer traces samples per period",
                });
            }
            spec.trace_samples = n;
        }
        Ok(spec)
    }
}

/// The approach spec of a front end's request, z_c in units of `length` (m per g₀, or 1):
/// [`default_range`] for missing ends, [`approach_spec`], with `average` the time average of
/// every point ([`AverageOptions::for_model`]), then `CurveRequest::configure`.
///
/// # Errors
/// As those three.
pub fn approach_request(
    base: Params,
    request: &CurveRequest,
    length: f64,
    average: bool,
) -> Result<SteppedSpec, SimError> {
    request.check_finite()?;
    if length != 1.0 {
        request.check_si_distances()?;
    }
    let (from, to) = request.ends(default_range(&base)?, length);
    let mut spec =
        approach_spec(base, from, to, request.spacing(length)?).map_err(|e| in_units(e, length))?;
    if average {
        spec.average = Some(AverageOptions::for_model(&CantileverModel::quasiperiodic(
            &base,
        )?));
    }
    request.configure(spec)
}

/// The check of a bimodal (multifrequency) approach curve (`afmdyn bimodal`, Python's
/// `bimodal`): the drive must have at least two components
/// ([`Params::drive_components`]); the curve is then the approach curve of that model, its
/// document with the per-component columns (`crate::report::component_columns`).
///
/// # Errors
/// [`SimError::OutOfRange`] naming the probe's `[drive]` arrays for a single-frequency drive.
pub fn check_bimodal(base: &Params) -> Result<(), SimError> {
    if base.is_multifrequency() {
        Ok(())
    } else {
        Err(SimError::out_of_range(
            "[drive].free_amplitude",
            "one drive component",
            "must be an array of two or more free amplitudes (with frequency = [f1, f2, …] or \
             each at its mode's resonance) for a multifrequency drive, e.g. free_amplitude = \
             [10e-9, 1e-9]",
        ))
    }
}

/// Refuse a multifrequency drive in an analysis that moves the drive frequency (`what`: the
/// resonance curve, FM-AFM): the further components' frequencies are fixed fractions of Ω
/// ([`crate::params::DriveComponent`]), so they would move with it — not what an instrument
/// does, and not what the analysis means.
///
/// # Errors
/// [`SimError::OutOfRange`] naming the probe's `[drive].frequency`.
pub(crate) fn check_single_frequency(base: &Params, what: &'static str) -> Result<(), SimError> {
    if !base.is_multifrequency() {
        return Ok(());
    }
    let moves = if what == "fm" {
        "follow the PLL"
    } else {
        "sweep with it"
    };
    Err(SimError::out_of_range(
        "[drive].frequency",
        format!("{} components", 1 + base.components().count()),
        format!(
            "must be one frequency for {what}: the further components' frequencies are fixed \
             fractions of the first and would {moves} (use bimodal for a multifrequency AM curve)"
        ),
    ))
}

/// The resonance spec of a front end's request near mode `mode`, Ω in units of `hz` (Hz per
/// unit Ω, or 1): `mode_band` for missing ends, `resonance_spec`, then
/// `CurveRequest::configure`.
///
/// # Errors
/// As those three.
///
/// In SI (`hz` ≠ 1, a probe) an end outside the model's Ω range is refused naming it in Hz with
/// the probe's range in Hz, and without a step or count the grid is no coarser than a tenth of
/// the mode's linewidth f_k/Q_k ([`linewidth_points`]).
pub fn resonance_request(
    base: Params,
    mode: usize,
    request: &CurveRequest,
    hz: f64,
) -> Result<SteppedSpec, SimError> {
    check_single_frequency(&base, "resonance")?;
    request.check_finite()?;
    if hz != 1.0 {
        for (name, v) in [("from", request.from), ("to", request.to)] {
            match v {
                Some(f) if !(OMEGA_MIN..=OMEGA_MAX).contains(&(f / hz)) => {
                    return Err(SimError::out_of_range(
                        name,
                        format!(
                            "{} Hz (this probe allows [{}, {}] Hz)",
                            crate::error::number(f),
                            crate::error::number(OMEGA_MIN * hz),
                            crate::error::number(OMEGA_MAX * hz)
                        ),
                        "must lie within the model's drive frequencies (Ω in [1e-3, 1e5] of \
                         the probe's time unit): frequencies are in Hz (300 kHz is 300e3, or \
                         300kHz on the command line)",
                    ))
                }
                _ => {}
            }
        }
    }
    let (from, to) = request.ends(mode_band(&base, mode)?, hz);
    let mut spacing = request.spacing(hz)?;
    if hz != 1.0 && request.step.is_none() && request.points.is_none() {
        spacing = Spacing::Points(linewidth_points(&base, mode, from, to)?);
    }
    let spec = resonance_spec(base, from, to, spacing);
    request.configure(spec.map_err(|e| in_units(e, hz))?)
}

/// The default number of points of a resonance curve over [`from`, `to`] (Ω) near mode
/// `mode` with a probe: a step no coarser than a tenth of the linewidth ω_k/Q_k
/// (`mode_resonance`; 60 Hz for f₀ = 300 kHz, Q = 500), at least [`DEFAULT_CURVE_POINTS`],
/// at most [`crate::analysis::stepped::MAX_CURVE_POINTS`].
///
/// # Errors
/// As `mode_resonance`.
pub fn linewidth_points(base: &Params, mode: usize, from: f64, to: f64) -> Result<usize, SimError> {
    let (omega, q) = mode_resonance(base, mode)?;
    let step = omega / (10.0 * q);
    let needed = if step > 0.0 && step.is_finite() {
        ((to - from).abs() / step).ceil() + 1.0
    } else {
        0.0
    };
    Ok((needed.min(MAX_CURVE_POINTS as f64) as usize).max(DEFAULT_CURVE_POINTS))
}

/// The model of a resonance curve under a probe that gives no rest distance (no `[sample] z_c`
/// in the file, z_c left at its default A₀ — touching the sample at resonance): the tip moved
/// away, to 10 × the free amplitude at the mode's resonance, for the free resonance as an
/// instrument's tune records it. Without a probe, with the file's `z_c`, or with a `--z-c` /
/// `z_c=` other than A₀ (which moves α5 off the probe's), `base`.
///
/// # Errors
/// As [`mode_resonance`] and [`free_response`].
pub(crate) fn free_resonance_base(
    base: Params,
    probe: Option<&crate::probe::Probe>,
    mode: usize,
) -> Result<Params, SimError> {
    let Some(probe) = probe else {
        return Ok(base);
    };
    if probe.z_c_in_file || base.alpha5 != probe.params.alpha5 {
        return Ok(base);
    }
    let (omega, _) = mode_resonance(&base, mode)?;
    let at_peak = Params { omega, ..base };
    // (an undamped mode has no finite peak: the free amplitude at the drive then)
    let peak = free_response(&CantileverModel::new(&at_peak)?)
        .or_else(|_| free_response(&CantileverModel::new(&base)?))?
        .amplitude;
    let far = 10.0 * peak.max(1.0);
    Ok(Params {
        alpha5: base.alpha5_for_rest_distance(far),
        ..base
    })
}

/// An error of the grid ([`crate::analysis::stepped::grid`], in dimensionless units) about
/// `from`, `to` or `step` with the value in the request's units (`unit` per dimensionless
/// unit: m per g₀ or Hz per unit Ω with a probe), as the user wrote it.
pub(crate) fn in_units(e: SimError, unit: f64) -> SimError {
    match e {
        SimError::OutOfRange {
            name: name @ ("from" | "to" | "step"),
            value,
            allowed,
        } => {
            let value = value
                .parse()
                .map_or(value, |v: f64| crate::error::number(v * unit));
            SimError::OutOfRange {
                name,
                value,
                allowed,
            }
        }
        e => e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::SweepParam;

    fn request() -> CurveRequest {
        CurveRequest {
            from: None,
            to: None,
            step: None,
            points: None,
            branches: false,
            tolerance: 1e-9,
            traces: None,
        }
    }

    fn out_of_range_name(e: SimError) -> &'static str {
        match e {
            SimError::OutOfRange { name, .. } => name,
            other => panic!("not OutOfRange: {other:?}"),
        }
    }

    /// The ends and the step are converted from the front end's unit (one dimensionless unit =
    /// `unit`), missing ends take the command's default, a missing spacing the default count.
    #[test]
    fn curve_request_converts_units_and_takes_defaults() {
        let unit = 2.5e-9;
        assert_eq!(request().ends((1.0, 3.0), unit), (1.0, 3.0));
        let r = CurveRequest {
            from: Some(5e-9),
            step: Some(1e-10),
            ..request()
        };
        let (from, to) = r.ends((1.0, 3.0), unit);
        assert_eq!((from, to), (5e-9 / unit, 3.0));
        assert_eq!(r.spacing(unit).unwrap(), Spacing::Step(1e-10 / unit));
        assert_eq!(
            request().spacing(unit).unwrap(),
            Spacing::Points(DEFAULT_CURVE_POINTS)
        );
        let r = CurveRequest {
            points: Some(7),
            ..request()
        };
        assert_eq!(r.spacing(unit).unwrap(), Spacing::Points(7));
        // both a step and a count: refused, naming the step
        let r = CurveRequest {
            step: Some(1e-10),
            points: Some(7),
            ..request()
        };
        assert_eq!(out_of_range_name(r.spacing(unit).unwrap_err()), "step");
    }

    /// `configure` sets the tolerance and the branch option, refuses a tolerance outside
    /// (0, 1e-3) and parameters invalid at an end of the grid, before any work.
    #[test]
    fn curve_request_configures_the_spec() {
        let base = Params::default();
        let spec = SteppedSpec::new(base, SweepParam::Omega, vec![2.0, 2.5, 3.0]);
        let r = CurveRequest {
            branches: true,
            tolerance: 1e-8,
            ..request()
        };
        let done = r.configure(spec.clone()).unwrap();
        assert_eq!(done.integrator.tolerance, 1e-8);
        assert!(done.branches);
        assert_eq!(done.values, spec.values);
        for tol in [0.0, -1e-9, 1e-3, f64::NAN, f64::INFINITY] {
            let r = CurveRequest {
                tolerance: tol,
                ..request()
            };
            let e = r.configure(spec.clone()).unwrap_err();
            assert_eq!(out_of_range_name(e), "tolerance", "tolerance {tol}");
        }
        // Ω ≤ 0 at the last value of the grid: a parameter error
        let bad = SteppedSpec::new(base, SweepParam::Omega, vec![1.0, 0.0, -1.0]);
        assert!(matches!(request().configure(bad), Err(SimError::Params(_))));
    }
}
