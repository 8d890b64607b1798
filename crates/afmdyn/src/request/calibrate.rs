//! `calibrate`: a lever's spring constant from its measured thermal spectrum, by the thermal
//! method and by Sader's — the request the command line (`afmdyn calibrate --probe P.toml
//! --psd FILE.csv`) and Python (`afmdyn.calibrate`) share: its options, their ranges and its
//! declared cost ([`crate::analysis::calibration`] computes it).

use super::costs::{MODEL_BYTES, OPERATION_WORK};
use super::fit::MAX_FIT_ROWS;
use super::limits::Cost;
use super::thermal::{check_thermal, DEFAULT_TEMPERATURE};
use crate::analysis::calibration::Signal;
use crate::error::SimError;

request! {
    /// `calibrate`: the measured spectrum (a CSV file `psd`, or the columns `frequency` and
    /// `spectral_density`), what it measures, the temperature, the bands of the peaks, and a force
    /// curve for the inverse optical lever sensitivity. Needs a probe (its modes, their correction
    /// factors, and for Sader's method its plan and fluid).
    pub struct CalibrateRequest {
        /// A CSV file with the columns `frequency` (Hz, increasing) and `psd` (the one-sided power
        /// spectral density, m²/Hz, or V²/Hz with `volts`), read through the bounded reader
        /// (instead of the columns `frequency` and `spectral_density`).
        pub psd: Option<String>,
        /// The frequencies (Hz, > 0, increasing), when no `psd` file is given.
        pub frequency: Vec<f64>,
        /// The one-sided PSD at them (m²/Hz, or V²/Hz with `volts`; > 0), as many as `frequency`.
        pub spectral_density: Vec<f64>,
        /// What the spectrum measures: `apparent-deflection` (an optical lever's, the default) or
        /// `deflection` (the tip's, an interferometer's).
        pub signal: Option<Signal>,
        /// Whether the PSD is the detector's, in V²/Hz: converted with `invols`, or with the
        /// InvOLS of `force_curve`.
        pub volts: bool,
        /// The inverse optical lever sensitivity (m/V, > 0) that converts a PSD in V²/Hz.
        pub invols: Option<f64>,
        /// A force curve on a hard surface: a CSV with the columns `height` (m, the piezo height,
        /// decreasing into the surface) and `deflection` (V), whose contact slope gives the InvOLS.
        pub force_curve: Option<String>,
        /// The temperature T (K, > 0 and ≤ 1500; default 295 K). Outside 200–500 K it warns (a
        /// value in °C?).
        pub temperature: f64 = DEFAULT_TEMPERATURE,
        /// The optical lever's laser spot ξ_s, a fraction of the length from the base (0 < ξ_s ≤
        /// 1; default 1): the correction factors are the model's there.
        pub spot: f64 = 1.0,
        /// The number of peaks fitted, the modes from the first (1 to the probe's number of modes;
        /// default every mode of the probe whose peak lies in the spectrum).
        pub peaks: Option<usize>,
        /// The frequency bands searched for the modes' peaks, a pair lo, hi (Hz) per mode from the
        /// first: `[lo1, hi1, lo2, hi2, …]`; default from half to twice the probe's f_k, bounded by
        /// the geometric means with the neighbouring modes.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "frequency")))]
        pub bands: Vec<f64>,
    }
}

impl CalibrateRequest {
    /// What the spectrum measures.
    pub fn signal(&self) -> Signal {
        self.signal.unwrap_or(Signal::ApparentDeflection)
    }

    /// The bands searched, a pair [lo, hi] (Hz) per mode.
    pub fn bands(&self) -> Vec<[f64; 2]> {
        self.bands.chunks_exact(2).map(|b| [b[0], b[1]]).collect()
    }

    /// The rows of the spectrum: the columns', or the most a file may have.
    fn rows(&self) -> usize {
        match self.psd {
            Some(_) => MAX_FIT_ROWS,
            None => self.frequency.len(),
        }
    }

    /// The checks of the spectrum's columns `f` and `s`: as many, 16 to 10⁶ rows, f > 0 and
    /// increasing, S > 0 and finite.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `psd`.
    pub fn check_spectrum(f: &[f64], s: &[f64]) -> Result<(), SimError> {
        let bad = |v: String, why: &'static str| SimError::out_of_range("psd", v, why);
        if f.len() != s.len() || !(16..=MAX_FIT_ROWS).contains(&f.len()) {
            return Err(bad(
                format!("{} frequencies, {} values", f.len(), s.len()),
                "a spectrum of 16 to 1000000 rows, a value at each frequency",
            ));
        }
        if let Some(i) = (0..f.len()).find(|&i| !(f[i] > 0.0 && (i == 0 || f[i] > f[i - 1]))) {
            return Err(bad(
                format!("frequency {} in row {}", crate::error::number(f[i]), i + 1),
                "the frequencies must be > 0 and increasing (Hz)",
            ));
        }
        if let Some(i) = (0..s.len()).find(|&i| !(s[i].is_finite() && s[i] > 0.0)) {
            return Err(bad(
                format!("{} in row {}", crate::error::number(s[i]), i + 1),
                "a power spectral density is finite and > 0",
            ));
        }
        Ok(())
    }
}

impl_request! {
    CalibrateRequest, "calibrate", advice = "give a shorter spectrum";
    validate |r, model| {
        check_thermal(model, r.temperature, r.spot)?;
        let n = model.params.modes;
        let refuse = |name, value: String, why| Err(SimError::out_of_range(name, value, why));
        match (&r.psd, r.frequency.is_empty() && r.spectral_density.is_empty()) {
            (Some(_), false) => return refuse("psd", "given with the columns".into(), "give either a psd file or the columns frequency and spectral_density"),
            (None, true) => return refuse("psd", "missing".into(), "a measured spectrum is needed: a CSV file (columns frequency, psd) or the columns frequency and spectral_density"),
            (None, false) => Self::check_spectrum(&r.frequency, &r.spectral_density)?,
            (Some(_), true) => {}
        }
        if let Some(m) = r.peaks.filter(|m| !(1..=n).contains(m)) {
            return refuse("peaks", m.to_string(), "1 to the probe's number of modes");
        }
        let pairs = r.bands.chunks(2);
        if let Some(b) = pairs
            .clone()
            .find(|b| !matches!(b, [lo, hi] if *lo >= 0.0 && hi > lo && hi.is_finite()))
        {
            return refuse(
                "bands",
                format!("{b:?}"),
                "a pair lo, hi per mode with 0 ≤ lo < hi (Hz)",
            );
        }
        if let Some(s) = r.invols {
            super::limits::positive("invols", s, "the InvOLS is finite and > 0 (m/V)")?;
        }
        match (
            r.volts,
            r.invols.is_some(),
            r.force_curve.is_some(),
        ) {
            (true, false, false) => refuse(
                "volts",
                "true".into(),
                "a PSD in V²/Hz needs the invols (m/V) or a force_curve to convert it",
            ),
            (true, true, true) => refuse(
                "invols",
                "given with a force_curve".into(),
                "give the InvOLS or the force curve that measures it, not both",
            ),
            (false, true, _) => refuse(
                "invols",
                "given with a PSD in m²/Hz".into(),
                "the InvOLS converts a PSD in V²/Hz: set volts",
            ),
            _ => Ok(()),
        }
    };
    // Per mode two fits of four parameters over at most the whole spectrum; the columns, the
    // fitted curve, the layouts' copies and the document's numbers (200 bytes a row).
    cost |r, model| {
        let rows = r.rows() as f64;
        let modes = r.peaks.unwrap_or(model.params.modes) as f64;
        let fits = 2.0 * super::fit_dynamic::fit_evaluations(4, None);
        Ok(Cost {
            bytes: MODEL_BYTES + rows * 200.0,
            work: rows * OPERATION_WORK * modes * fits,
        })
    }
}
