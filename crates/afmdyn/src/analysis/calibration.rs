//! Spring-constant calibration from a measured thermal spectrum: each mode's peak fitted by a
//! simple harmonic oscillator on a white floor, its spring constant by the thermal method with
//! the model's correction factor, and the inverse optical lever sensitivity from a force
//! curve's contact slope.
//!
//! # The peak
//! Near its resonance a mode's one-sided PSD is that of a damped harmonic oscillator on the
//! detector's white floor,
//!
//! S(f) = P f₀⁴ / ((f² − f₀²)² + f² f₀²/Q²) + B,
//!
//! whose area above the floor is ⟨s²⟩ = ∫₀^∞ (S − B) df = (π/2) P f₀ Q (Hutter & Bechhoefer,
//! *Rev. Sci. Instrum.* 64 (1993) 1868; the SHO fit of Cook et al., *Nanotechnology* 17 (2006)
//! 2135). The fit is a least-squares fit ([`crate::analysis::fit`]) over a band about the
//! peak of relative residuals, as a spectrum averaged over n records scatters by σᵢ/Sᵢ = 1/√n:
//! first relative to the data, σᵢ ∝ yᵢ, then relative to that first fit's model,
//! σᵢ ∝ S(fᵢ; p̂), so that the weights hold no noise of the data (which biases a fit weighted
//! by the data low); the factor is estimated from the residuals, and the standard errors are
//! those of the scatter.
//!
//! # The thermal method
//! With χ_k the model's correction factor of the mode for the signal read
//! ([`crate::analysis::thermal`]: k_s⟨s_k²⟩/(k_B T), 0.817 for the optical lever and 0.971 for
//! the deflection of a uniform lever's first mode), the static spring constant at the tip is
//! k_s = χ_k k_B T/⟨s_k²⟩ and the mode's own effective spring constant k_k = k_s/χ_x,k
//! (χ_x,k the deflection's factor: k_k = k_B T/⟨x_k²⟩).
//!
//! # Sader's method
//! Where the caller knows the lever's plan and fluid, it adds Sader's estimates from each
//! peak's f₀ and Q (`crate::hydro::sader`, SI physics of the probe).
//!
//! # The inverse optical lever sensitivity
//! On a hard surface the deflection follows the piezo one to one once in contact: the
//! deflection signal d (V) against the piezo height z (m) has the contact slope |∂d/∂z|, and
//! InvOLS = 1/|∂d/∂z| (m/V). The slope is a least-squares line over the approach's rows whose
//! deflection lies between 20 % and 90 % of its rise above the baseline (the median of the
//! approach's first fifth), below the kink at contact and above the detector's saturation.
//!
//! Units: SI throughout (Hz, m²/Hz or the signal's units², K, N/m, m/V).

use crate::analysis::fit::{fit_cancellable, CurveModel, FitOutcome, Observations, Parameter};
use crate::analysis::progress::Progress;
use crate::analysis::thermal::{ThermalMode, BOLTZMANN};
use crate::error::SimError;
use serde::Serialize;
use std::f64::consts::FRAC_PI_2;

/// The fewest frequencies a peak's band may hold (four parameters and their scatter).
const MIN_BAND_POINTS: usize = 16;
/// The band about a peak in its full widths at half maximum f₀/Q, on each side.
const BAND_WIDTHS: f64 = 6.0;

/// A value with its standard error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Measured {
    /// The value.
    pub value: f64,
    /// Its standard error (NaN where the fit does not fix it).
    pub standard_error: f64,
}

/// What a spectrum measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "kebab-case")]
pub enum Signal {
    /// An optical lever's apparent deflection (the slope at the spot, read as a deflection).
    ApparentDeflection,
    /// The tip's deflection itself (an interferometer).
    Deflection,
}

/// One mode calibrated from its peak.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeCalibration {
    /// The mode's number, from 1.
    pub mode: usize,
    /// The band fitted [lo, hi] (Hz).
    pub band: [f64; 2],
    /// The frequencies in the band.
    pub points: usize,
    /// The resonance f₀ (Hz).
    pub frequency: Measured,
    /// The quality factor Q.
    pub quality_factor: Measured,
    /// P, the oscillator's PSD at zero frequency (the signal's units²/Hz).
    pub zero_frequency_psd: Measured,
    /// B, the white floor (the signal's units²/Hz).
    pub floor: Measured,
    /// ⟨s²⟩ = (π/2) P f₀ Q, the peak's area above the floor (the signal's units²).
    pub mean_square: Measured,
    /// The static spring constant at the tip from this peak by the thermal method (N/m).
    pub static_spring_constant_thermal: Measured,
    /// The mode's effective spring constant at the tip by the thermal method (N/m).
    pub spring_constant_thermal: Measured,
    /// The static spring constant by Sader's method (N/m; `None` without a plan; set by the
    /// caller).
    pub static_spring_constant_sader: Option<Measured>,
    /// The mode's effective spring constant by Sader's method (N/m; `None` without a plan; set
    /// by the caller).
    pub spring_constant_sader: Option<Measured>,
    /// The correlation of the estimates of f₀ and Q.
    pub frequency_quality_correlation: f64,
    /// The correction factor χ_k used by the thermal method (the model's, for the signal).
    pub correction_factor: f64,
    /// The scatter of the spectrum about the fit relative to it, √(χ²/dof) of the relative
    /// residuals (1/√n for a spectrum averaged over n records).
    pub relative_scatter: f64,
    /// Whether the minimiser reports convergence.
    pub converged: bool,
    /// What may be wrong with this peak, in words.
    pub warnings: Vec<String>,
}

/// A calibration from a measured spectrum.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Calibration {
    /// The temperature T (K).
    pub temperature: f64,
    /// What the spectrum measures.
    pub signal: Signal,
    /// Each mode fitted.
    pub modes: Vec<ModeCalibration>,
    /// The spectrum's frequencies (Hz), shape `[F]`.
    pub frequency: Vec<f64>,
    /// The spectrum (the signal's units²/Hz), shape `[F]`.
    pub psd: Vec<f64>,
    /// The oscillators fitted, summed where their bands lie, on the spectrum's frequencies
    /// (NaN outside every band), shape `[F]`.
    pub fitted: Vec<f64>,
    /// The InvOLS (m/V) from a force curve, when one was given (set by the caller).
    pub invols: Option<Measured>,
    /// What may be wrong beyond the peaks, in words (set by the caller).
    pub warnings: Vec<String>,
}

/// The oscillator on its floor over the frequencies `f` (module docs): parameters
/// (P, f₀, Q, B).
struct Oscillator<'a> {
    f: &'a [f64],
}

impl Oscillator<'_> {
    /// S(f) and its derivatives in (P, f₀, Q, B) at one frequency.
    fn at(f: f64, p: &[f64]) -> (f64, [f64; 4]) {
        let (pz, f0, q, b) = (p[0], p[1], p[2], p[3]);
        let (f2, f02) = (f * f, f0 * f0);
        let d = (f2 - f02).powi(2) + f2 * f02 / (q * q);
        let (f04, d2) = (f02 * f02, d * d);
        let dd_df0 = -4.0 * f0 * (f2 - f02) + 2.0 * f2 * f0 / (q * q);
        let grad = [
            f04 / d,
            pz * (4.0 * f0 * f02 * d - f04 * dd_df0) / d2,
            2.0 * pz * f04 * f02 * f2 / (q * q * q * d2),
            1.0,
        ];
        (pz * f04 / d + b, grad)
    }
}

impl CurveModel for Oscillator<'_> {
    fn points(&self) -> usize {
        self.f.len()
    }
    fn evaluate(&self, p: &[f64], values: &mut [f64], mut jacobian: Option<&mut [f64]>) {
        for (i, &f) in self.f.iter().enumerate() {
            let (s, g) = Oscillator::at(f, p);
            values[i] = s;
            if let Some(j) = jacobian.as_deref_mut() {
                j[4 * i..4 * i + 4].copy_from_slice(&g);
            }
        }
    }
}

/// The peak's start: its frequency, height above the floor, Q from its half-power width (the
/// model's `q_model` where a side does not fall to half), and the floor, in the search range
/// `[lo, hi)` of indices of the spectrum `s` (a five-bin running mean).
fn start(f: &[f64], s: &[f64], (lo, hi): (usize, usize), q_model: f64) -> [f64; 4] {
    let mean = |i: usize| {
        let (a, b) = (i.saturating_sub(2).max(lo), (i + 3).min(hi));
        s[a..b].iter().sum::<f64>() / (b - a) as f64
    };
    let smooth: Vec<f64> = (lo..hi).map(mean).collect();
    let (k, &top) = (smooth.iter().enumerate())
        .max_by(|a, b| a.1.total_cmp(b.1))
        .expect("a non-empty range");
    let floor = smooth
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min)
        .min(top);
    let half = floor + 0.5 * (top - floor);
    let left = (0..k).rev().find(|&j| smooth[j] < half);
    let right = (k + 1..smooth.len()).find(|&j| smooth[j] < half);
    let f0 = f[lo + k];
    let q = match (left, right) {
        (Some(a), Some(b)) => f0 / (f[lo + b] - f[lo + a]).max(f64::MIN_POSITIVE),
        _ => q_model,
    }
    .clamp(0.5, 1e7);
    [(top - floor) / (q * q), f0, q, floor]
}

/// The indices `[a, b)` of the frequencies `f` within `[lo, hi]`.
fn indices(f: &[f64], lo: f64, hi: f64) -> (usize, usize) {
    (
        f.partition_point(|&x| x < lo),
        f.partition_point(|&x| x <= hi),
    )
}

/// The band fitted about a peak whose start is `p0` within the search range `[lo, hi)`:
/// [`BAND_WIDTHS`] widths f₀/Q on each side, within the range, at least [`MIN_BAND_POINTS`].
fn band(f: &[f64], p0: &[f64; 4], (lo, hi): (usize, usize)) -> (usize, usize) {
    let w = BAND_WIDTHS * p0[1] / p0[2];
    let (mut a, mut b) = indices(f, p0[1] - w, p0[1] + w);
    (a, b) = (a.max(lo), b.min(hi));
    while b - a < MIN_BAND_POINTS && (a > lo || b < hi) {
        (a, b) = (a.saturating_sub(1).max(lo), (b + 1).min(hi));
    }
    (a, b)
}

/// The oscillator relative to `scale`: S(fᵢ)/scaleᵢ, so that a fit of yᵢ/scaleᵢ with the noise
/// estimated from its residuals weighs each point by 1/scaleᵢ (module docs).
struct Relative<'a> {
    oscillator: Oscillator<'a>,
    scale: &'a [f64],
}

impl CurveModel for Relative<'_> {
    fn points(&self) -> usize {
        self.scale.len()
    }
    fn evaluate(&self, p: &[f64], values: &mut [f64], mut jacobian: Option<&mut [f64]>) {
        self.oscillator.evaluate(p, values, jacobian.as_deref_mut());
        for (i, s) in self.scale.iter().enumerate() {
            values[i] /= s;
            if let Some(j) = jacobian.as_deref_mut() {
                j[4 * i..4 * i + 4].iter_mut().for_each(|x| *x /= s);
            }
        }
    }
}

/// The fit of the oscillator to `s` at `f` from `start`, each point relative to `scale`
/// (its standard deviation ∝ scaleᵢ, the factor estimated from the residuals); the fitted
/// curve in the spectrum's units.
fn fit_peak(
    (f, s): (&[f64], &[f64]),
    scale: &[f64],
    start: [f64; 4],
    progress: &Progress,
) -> Result<FitOutcome, SimError> {
    let [pz, f0, q, b] = start;
    let (f_lo, f_hi) = (f[0], f[f.len() - 1]);
    let params = [
        ("zero_frequency_psd", pz, 0.0, f64::INFINITY, pz),
        ("frequency", f0, f_lo, f_hi, f0 / q),
        ("quality_factor", q, 0.0, f64::INFINITY, q),
        ("floor", b, 0.0, f64::INFINITY, b.max(1e-3 * pz * q * q)),
    ]
    .map(|(name, start, lower, upper, scale)| Parameter {
        name: name.into(),
        start,
        lower,
        upper,
        scale,
    });
    let y: Vec<f64> = s.iter().zip(scale).map(|(y, c)| y / c).collect();
    let obs = Observations { y: &y, sigma: None };
    let model = Relative {
        oscillator: Oscillator { f },
        scale,
    };
    let mut o = fit_cancellable(&model, &obs, &params, &[None; 4], None, progress)?;
    o.fitted.iter_mut().zip(scale).for_each(|(v, c)| *v *= c);
    Ok(o)
}

/// The covariance of the fitted parameters i and j of `o`.
fn covariance(o: &FitOutcome, i: usize, j: usize) -> f64 {
    o.correlation[i][j] * o.estimates[i].standard_error * o.estimates[j].standard_error
}

/// The value and standard error of g(p) with gradient `grad` over the four parameters of `o`.
fn propagate(o: &FitOutcome, value: f64, grad: [f64; 4]) -> Measured {
    let var: f64 = (0..4)
        .flat_map(|i| (0..4).map(move |j| (i, j)))
        .map(|(i, j)| grad[i] * grad[j] * covariance(o, i, j))
        .sum();
    Measured {
        value,
        standard_error: var.sqrt(),
    }
}

/// The mode `m`'s peak in the spectrum (`f`, `s`) searched in `range` (indices), calibrated.
fn calibrate_mode(
    (f, s): (&[f64], &[f64]),
    m: &ThermalMode,
    range: (usize, usize),
    (signal, temperature): (Signal, f64),
    progress: &Progress,
) -> Result<(ModeCalibration, FitOutcome, (usize, usize)), SimError> {
    let p0 = start(f, s, range, m.quality_factor.unwrap_or(0.5));
    let (a, b) = band(f, &p0, range);
    let (fb, sb) = (&f[a..b], &s[a..b]);
    let first = fit_peak((fb, sb), sb, p0, progress)?;
    let p1: [f64; 4] = std::array::from_fn(|i| first.values[i]);
    let o = fit_peak((fb, sb), &first.fitted, p1, progress)?;
    let [pz, f0, q, floor] = std::array::from_fn(|i| o.values[i]);
    let at = |i: usize| Measured {
        value: o.values[i],
        standard_error: o.estimates[i].standard_error,
    };
    let area = propagate(
        &o,
        FRAC_PI_2 * pz * f0 * q,
        [
            FRAC_PI_2 * f0 * q,
            FRAC_PI_2 * pz * q,
            FRAC_PI_2 * pz * f0,
            0.0,
        ],
    );
    let chi = match signal {
        Signal::ApparentDeflection => m.optical_lever_factor,
        Signal::Deflection => m.deflection_factor,
    };
    let kt = BOLTZMANN * temperature;
    let relative = area.standard_error / area.value;
    let k_static = chi * kt / area.value;
    let scaled = |k: f64| Measured {
        value: k,
        standard_error: k * relative,
    };
    // the scatter is estimated by design (`relative_scatter`): the fit's note of it goes
    let mut warnings: Vec<String> = (o.warnings.iter())
        .filter(|w| !w.starts_with("noise estimated from residuals"))
        .cloned()
        .collect();
    warnings.extend(peak_warnings(fb, &o, m, floor, pz * q * q));
    let calibration = ModeCalibration {
        mode: m.mode,
        band: [fb[0], fb[fb.len() - 1]],
        points: fb.len(),
        frequency: at(1),
        quality_factor: at(2),
        zero_frequency_psd: at(0),
        floor: at(3),
        mean_square: area,
        static_spring_constant_thermal: scaled(k_static),
        spring_constant_thermal: scaled(k_static / m.deflection_factor),
        static_spring_constant_sader: None,
        spring_constant_sader: None,
        frequency_quality_correlation: o.correlation[1][2],
        correction_factor: chi,
        relative_scatter: o.chi2_dof.sqrt(),
        converged: o.converged,
        warnings,
    };
    Ok((calibration, o, (a, b)))
}

/// What may be wrong with a fitted peak: unresolved, weak above its floor, or far from the
/// model's mode.
fn peak_warnings(f: &[f64], o: &FitOutcome, m: &ThermalMode, floor: f64, top: f64) -> Vec<String> {
    let (f0, q) = (o.values[1], o.values[2]);
    let spacing = (f[f.len() - 1] - f[0]) / (f.len() - 1) as f64;
    let mut w = Vec::new();
    if f0 / q < 3.0 * spacing {
        w.push(warning!(
            "calibrate.unresolved-peak",
            "Record a finer spectrum (a longer time record), or average more records.",
            "mode {}: the peak's width f0/Q = {} Hz is less than 3 frequency bins ({} Hz): Q and \
             the area are not resolved (a finer spectrum, or a longer record)",
            m.mode,
            crate::error::number(f0 / q),
            crate::error::number(spacing)
        ));
    }
    if top < 3.0 * floor {
        w.push(warning!(
            "calibrate.weak-peak",
            "Average more records, or check the detector's floor and the spot on the lever.",
            "mode {}: the peak rises only {:.2}× above its floor: the area is uncertain",
            m.mode,
            top / floor
        ));
    }
    if (f0 / m.frequency - 1.0).abs() > 0.3 {
        w.push(warning!(
            "calibrate.peak-far-from-mode",
            "Check that the probe is the lever measured, or give the bands where each peak is.",
            "mode {}: the peak at {} Hz is more than 30 % from the probe's mode at {} Hz: is it \
             this mode's peak?",
            m.mode,
            crate::error::number(f0),
            crate::error::number(m.frequency)
        ));
    }
    w
}

/// The search ranges of the modes `modes` (frequencies `f_k`, Hz) in the spectrum's
/// frequencies `f`: from half to twice f_k, bounded by the geometric means with the
/// neighbouring modes, or `bands` where given (one per mode, Hz). `None` for a mode outside the
/// spectrum.
fn search_ranges(
    f: &[f64],
    modes: &[ThermalMode],
    bands: &[[f64; 2]],
) -> Vec<Option<(usize, usize)>> {
    let fk: Vec<f64> = modes.iter().map(|m| m.frequency).collect();
    (0..modes.len())
        .map(|k| {
            let [lo, hi] = bands.get(k).copied().unwrap_or_else(|| {
                let below = k.checked_sub(1).map_or(0.0, |j| (fk[j] * fk[k]).sqrt());
                let above = fk.get(k + 1).map_or(f64::INFINITY, |g| (g * fk[k]).sqrt());
                [(0.5 * fk[k]).max(below), (2.0 * fk[k]).min(above)]
            });
            let (a, b) = indices(f, lo, hi);
            (b >= a + MIN_BAND_POINTS).then_some((a, b))
        })
        .collect()
}

/// The calibration from the spectrum `psd` (the `signal`'s units²/Hz) at the frequencies
/// `frequency` (Hz, increasing), shape `[F]` each: the peaks of the model's `modes` (their
/// frequencies, Q and correction factors, [`crate::analysis::thermal`]) at `temperature` (K),
/// searched in `bands` (Hz, one per mode; default about each mode). A mode whose search range
/// holds fewer than 16 frequencies is not fitted.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `psd` when no mode lies in the spectrum;
/// [`SimError::Cancelled`].
pub fn calibrate(
    (frequency, psd): (&[f64], &[f64]),
    modes: &[ThermalMode],
    bands: &[[f64; 2]],
    (signal, temperature): (Signal, f64),
    progress: &Progress,
) -> Result<Calibration, SimError> {
    let mut fitted = vec![f64::NAN; frequency.len()];
    let mut out = Vec::new();
    let ranges = search_ranges(frequency, modes, bands);
    for (m, range) in modes.iter().zip(ranges) {
        let Some(range) = range else { continue };
        let (c, o, (a, b)) =
            calibrate_mode((frequency, psd), m, range, (signal, temperature), progress)?;
        for (i, v) in (a..b).zip(&o.fitted) {
            fitted[i] = if fitted[i].is_nan() {
                *v
            } else {
                fitted[i] + v
            };
        }
        out.push(c);
    }
    if out.is_empty() {
        return Err(SimError::out_of_range(
            "psd",
            format!(
                "{}..{} Hz",
                crate::error::number(frequency[0]),
                crate::error::number(frequency[frequency.len() - 1])
            ),
            "no mode of the probe lies in the spectrum with 16 frequencies about it: is it the \
             probe's spectrum (its f0), or give the bands",
        ));
    }
    Ok(Calibration {
        temperature,
        signal,
        modes: out,
        frequency: frequency.to_vec(),
        psd: psd.to_vec(),
        fitted,
        invols: None,
        warnings: Vec::new(),
    })
}

/// The inverse optical lever sensitivity (m/V) from a force curve on a hard surface: the
/// piezo heights `height` (m, decreasing into the surface on the approach) and the deflection
/// signal `deflection` (V), shape `[R]` each (module docs): the approach's rows up to the
/// lowest height.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `force_curve` when the contact holds fewer than 5 rows or
/// has no slope.
pub fn invols(height: &[f64], deflection: &[f64]) -> Result<Measured, SimError> {
    let bad = |why: &'static str| SimError::out_of_range("force_curve", "the contact", why);
    let end = (height.iter().enumerate())
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(i, _)| i + 1);
    let (z, d) = (&height[..end], &deflection[..end]);
    let mut head: Vec<f64> = d[..(end / 5).max(1)].to_vec();
    head.sort_by(f64::total_cmp);
    let base = head[head.len() / 2];
    let top = d.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if top.partial_cmp(&base) != Some(std::cmp::Ordering::Greater) {
        return Err(bad(
            "the deflection does not rise above its baseline on the approach",
        ));
    }
    let (lo, hi) = (base + 0.2 * (top - base), base + 0.9 * (top - base));
    let rows: Vec<(f64, f64)> = (z.iter().zip(d))
        .filter(|(_, &v)| v >= lo && v <= hi)
        .map(|(&z, &v)| (z, v))
        .collect();
    if rows.len() < 5 {
        return Err(bad(
            "fewer than 5 rows between 20 % and 90 % of the deflection's rise: a curve on a \
             hard surface, its approach into contact",
        ));
    }
    let n = rows.len() as f64;
    let (mz, md) = rows
        .iter()
        .fold((0.0, 0.0), |(a, b), (z, d)| (a + z / n, b + d / n));
    let (sxx, sxy) = rows.iter().fold((0.0, 0.0), |(a, b), (z, d)| {
        (a + (z - mz).powi(2), b + (z - mz) * (d - md))
    });
    let slope = sxy / sxx;
    if !(slope.is_finite() && slope != 0.0) {
        return Err(bad(
            "the deflection does not change with the height in contact",
        ));
    }
    let rss: f64 = rows
        .iter()
        .map(|(z, d)| (d - md - slope * (z - mz)).powi(2))
        .sum();
    let se_slope = (rss / (n - 2.0) / sxx).sqrt();
    Ok(Measured {
        value: 1.0 / slope.abs(),
        standard_error: se_slope / (slope * slope),
    })
}

#[cfg(test)]
mod tests;
