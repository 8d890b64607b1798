//! `reconstruct`: the force and potential behind a frequency-modulation curve
//! ([`crate::analysis::reconstruct`], the Sader–Jarvis inversion, or
//! [`crate::analysis::reconstruct_exact`], its exact correction: [`FmInversion`]) — the request that the
//! command line (`afmdyn reconstruct --fm FILE`) and Python (`afmdyn.reconstruct`) share: the
//! curve, the cantilever's constants, their ranges and checks, and the declared cost. SI throughout: distances and the amplitude in m, frequencies in Hz, the
//! spring constant in N/m; the force in N, the potential in J.
//!
//! **Ranges.** Each constant has a physical range outside which it is refused and a typical
//! range outside which the document warns of a likely unit slip (`CONSTANTS`):
//!
//! | constant | refused outside | typical (else a warning) |
//! |---|---|---|
//! | `amplitude` A | 1 pm – 10 µm | 10 pm – 1 µm |
//! | `resonance_frequency` f0 | 1 kHz – 10 GHz | 1 kHz – 10 MHz |
//! | `spring_constant` k | 10⁻⁶ – 10⁹ N/m | 0.005 – 10⁶ N/m |
//!
//! They are the probe's ranges of the same quantities (`[drive] free_amplitude`,
//! `[cantilever] resonance_frequency`, `spring_constant`), declared once in
//! [`crate::probe::ranges`].
//!
//! Typical: FM-AFM amplitudes run from the ~20 pm of qPlus sensors at sub-Ångström
//! resolution to the tens of nm of Si cantilevers in ultra-high vacuum (1 µm leaves room for
//! large-amplitude work); resonances from the few kHz of soft levers in liquid and the ~30 kHz
//! of a qPlus sensor to the 1 MHz of a length-extension resonator (10 MHz for the
//! high-frequency levers); spring constants from the 0.01 N/m of soft contact levers through
//! 40 N/m (tapping levers) and 1.8 kN/m (qPlus) to the 540 kN/m of a length-extension
//! resonator. A value a factor 10³ off (nm given as m, kHz as Hz) falls outside. Physical: no
//! lever oscillates by more than 10 µm (a thousand times the tapping amplitudes) or by less
//! than a picometre (its thermal motion), resonates below 1 kHz or above 10 GHz, or has a stiffness outside 10⁻⁶–10⁹ N/m.

use super::costs::{MODEL_BYTES, OPERATION_WORK};
use super::limits::Cost;
use crate::analysis::reconstruct::{Method, ShiftCurve, NEAR_FIELD};
use crate::analysis::reconstruct_am::AmCurve;
use crate::analysis::reconstruct_exact::{check_exact, exact_weights, EXACT_MAX_ITERATIONS};
use crate::error::{number, SimError};
use serde::{Deserialize, Serialize};
use serde_json::Value;

request! {
    /// `reconstruct`: a frequency-shift curve Δf against the distance of closest approach d (or
    /// the rest distance z_c, d = z_c − A), with the cantilever's k, f0 and A.
    pub struct ReconstructRequest {
        /// Distances of closest approach d (m), monotonic (either order); or give `z_c`.
        pub distance: Option<Vec<f64>>,
        /// Rest distances z_c (m) instead of `distance`: d = z_c − A (the lower turning point of
        /// an oscillation of amplitude A without static deflection).
        pub z_c: Option<Vec<f64>>,
        /// Frequency shifts Δf = f − f0 (Hz), one per distance.
        pub frequency_shift: Vec<f64>,
        /// Spring constant k (N/m), > 0.
        pub spring_constant: f64,
        /// Free resonance frequency f0 (Hz), > 0.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "frequency")))]
        pub resonance_frequency: f64,
        /// Oscillation amplitude A (m), > 0.
        #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
        pub amplitude: f64,
        /// The model's force at each distance (N), when the curve came from a model (an `fm`
        /// document's `curve.law_force`): reported beside the reconstruction for comparison.
        #[serde(skip_serializing_if = "Option::is_none")]
        pub law_force: Option<Vec<f64>>,
        /// The inversion: `"sader-jarvis"` (the default) or `"exact"` ([`FmInversion`]).
        pub inversion: FmInversion,
    }
}

/// How `reconstruct` inverts a frequency-shift curve.
///
/// The default is Sader–Jarvis: on noisy data it is the more robust (measured in
/// tests/reconstruct_exact.rs, the van der Waals curve at A = 1 nm with uniform noise of
/// 10⁻⁴–10⁻² of the largest |Δf|: the exact inversion's largest force error is 1.06–2.8
/// times Sader–Jarvis's), while on clean data the exact inversion removes Sader–Jarvis's few
/// per cent at intermediate amplitudes (2.2 % → 7·10⁻⁵ at A/d = 0.4–1).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(rename_all = "kebab-case")]
pub enum FmInversion {
    /// Sader and Jarvis's formula (Appl. Phys. Lett. 84, 1801 (2004);
    /// [`crate::analysis::reconstruct::sader_jarvis`]): within a few per cent at any amplitude.
    #[default]
    SaderJarvis,
    /// Its estimate corrected through Giessibl's forward relation until the two agree
    /// ([`crate::analysis::reconstruct_exact`]): exact for the first-order relation, up to
    /// the force's interpolation between the distances.
    Exact,
}

impl FmInversion {
    /// The request's word: `"sader-jarvis"` or `"exact"`.
    pub(crate) fn word(self) -> &'static str {
        match self {
            FmInversion::SaderJarvis => "sader-jarvis",
            FmInversion::Exact => "exact",
        }
    }
}

/// The probe quantities of the constants `amplitude`, `resonance_frequency`,
/// `spring_constant` (in that order): their ranges are the probe's, declared once in
/// [`crate::probe::ranges`].
pub(crate) const CONSTANTS: [(&str, (&str, &str)); 3] = [
    ("amplitude", ("drive", "free_amplitude")),
    ("resonance_frequency", ("cantilever", "resonance_frequency")),
    ("spring_constant", ("cantilever", "spring_constant")),
];

/// The share of its extreme that |Δf| may keep at the largest distance without the truncation
/// warning: the inversion integrates Δf beyond each distance and stops at the data's end.
pub(crate) const DECAYED: f64 = 0.01;

/// A frequency-shift curve's columns held against the probe (issue 77 item 4): the distances'
/// span against the range of a tip–sample distance (10 pm to 10 µm), the largest |Δf|
/// against the resonance f₀ (from 10⁻⁶ f₀ to half of it).
pub(crate) fn shift_curve_slips(distance: &[f64], shift: &[f64], f0: f64) -> Vec<String> {
    use super::quantity::{shift_slip, span, unit_slip, Dim};
    [
        unit_slip(
            "distance",
            "the span",
            span(distance),
            Dim::Length,
            (1e-11, 1e-5),
        ),
        shift_slip(shift, f0),
    ]
    .into_iter()
    .flatten()
    .collect()
}

impl ReconstructRequest {
    /// The curve to invert, in increasing distance.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming the field: a constant outside its physical range
    /// (`CONSTANTS`), neither or both of `distance` and `z_c`, and as [`ShiftCurve::validate`]
    /// (distances not monotonic among them).
    pub fn curve(&self) -> Result<ShiftCurve, SimError> {
        // the constants first: a wrong unit would otherwise show as distances out of order
        for ((name, range), v) in CONSTANTS.iter().zip(self.constants()) {
            super::limits::positive(name, v, "must be finite and > 0")?;
            crate::probe::ranges::refuse(name, *range, v)?;
        }
        let distance: Vec<f64> =
            match (&self.distance, &self.z_c) {
                (Some(d), None) => d.clone(),
                (None, Some(z)) => z.iter().map(|z| z - self.amplitude).collect(),
                (given, _) => return Err(SimError::out_of_range(
                    "distance",
                    if given.is_some() {
                        "given with z_c"
                    } else {
                        "missing"
                    },
                    "give the distances of closest approach or the rest distances z_c, one of them",
                )),
            };
        let mut curve = ShiftCurve {
            distance,
            frequency_shift: self.frequency_shift.clone(),
            spring_constant: self.spring_constant,
            resonance_frequency: self.resonance_frequency,
            amplitude: self.amplitude,
        };
        // an approach curve runs towards the sample: invert it in increasing distance
        if curve.distance.len() >= 2 && curve.distance[0] > curve.distance[1] {
            curve.distance.reverse();
            curve.frequency_shift.reverse();
        }
        curve.validate()?;
        if let Some(l) = &self.law_force {
            if l.len() != self.frequency_shift.len() {
                return Err(SimError::out_of_range(
                    "law_force",
                    format!("{} values", l.len()),
                    "must hold one force per frequency shift",
                ));
            }
        }
        Ok(curve)
    }

    /// `amplitude`, `resonance_frequency`, `spring_constant` (the order of [`CONSTANTS`]).
    fn constants(&self) -> [f64; 3] {
        [
            self.amplitude,
            self.resonance_frequency,
            self.spring_constant,
        ]
    }

    /// The document's warnings on the request: a constant outside its typical range (a likely
    /// unit slip, `CONSTANTS`); data that end before the shift has decayed (|Δf| at the largest
    /// distance above `DECAYED` of its extreme).
    pub fn warnings(&self) -> Vec<String> {
        let mut warnings: Vec<String> = CONSTANTS
            .iter()
            .zip(self.constants())
            .filter_map(|(&(name, range), v)| crate::probe::ranges::warn(name, range, v))
            .collect();
        if let Ok(c) = self.curve() {
            warnings.extend(shift_curve_slips(
                &c.distance,
                &c.frequency_shift,
                c.resonance_frequency,
            ));
            let n = c.distance.len();
            let far = c.frequency_shift[n - 1];
            let (at, extreme) = c
                .frequency_shift
                .iter()
                .enumerate()
                .max_by(|x, y| x.1.abs().total_cmp(&y.1.abs()))
                .map_or((0, 0.0), |(i, v)| (i, *v));
            if far.abs() > DECAYED * extreme.abs() {
                warnings.push(warning!(
                    "reconstruct.undecayed",
                    "Take data out to where the shift has decayed; until then, read the \
                     force within about an amplitude of the data's end as not \
                     reconstructed.",
                    "the frequency shift at the largest distance (d = {} m) is still {} % of its \
                     extreme ({} Hz at d = {} m): the force there and within about an amplitude \
                     of it is not reconstructed (the inversion integrates the shift beyond each \
                     distance, and the data end there); take data out to where the shift has \
                     decayed below {} % of its extreme",
                    number(c.distance[n - 1]),
                    number(100.0 * far.abs() / extreme.abs()),
                    number(extreme),
                    number(c.distance[at]),
                    number(100.0 * DECAYED),
                ));
            }
        }
        warnings
    }

    /// `law_force` in the order of [`Self::curve`] (increasing distance).
    pub(crate) fn law_in_order(&self) -> Option<Vec<f64>> {
        let mut law = self.law_force.clone()?;
        let d = self.distance.as_ref().or(self.z_c.as_ref())?;
        if d.len() >= 2 && d[0] > d[1] {
            law.reverse();
        }
        Some(law)
    }

    /// The request of an `afmdyn fm` document in SI (the `fm` curve's document): the distances
    /// of closest approach `curve.min_distance` (the lower turning points, static deflection
    /// included), `curve.frequency_shift`, and the document's `spring_constant`,
    /// `resonance_frequency` and `amplitude` — each of the three replaced by the value given.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `fm` for a document that is not an SI `fm` document (no
    /// `curve`, or the model's units: run `fm` with a probe), naming `spring_constant` when the
    /// document has none (a mode other than 1) and none is given.
    pub fn from_fm_document(
        doc: &Value,
        spring_constant: Option<f64>,
        resonance_frequency: Option<f64>,
        amplitude: Option<f64>,
    ) -> Result<Self, SimError> {
        let numbers = |name: &str| -> Option<Vec<f64>> {
            doc["curve"][name]
                .as_array()?
                .iter()
                .map(Value::as_f64)
                .collect()
        };
        let (Some(distance), Some(frequency_shift)) =
            (numbers("min_distance"), numbers("frequency_shift"))
        else {
            return Err(SimError::out_of_range(
                "fm",
                "a document without curve.min_distance and curve.frequency_shift",
                "must be the JSON document of afmdyn fm (fm.json, or --json's output)",
            ));
        };
        if doc["units"]["z_c"].as_str() != Some("m") {
            return Err(SimError::out_of_range(
                "fm",
                "a document in the model's units",
                "must be in SI: run afmdyn fm with --probe (or give the curve as a CSV with \
                 k, f0 and A)",
            ));
        }
        let constant = |given: Option<f64>, key: &'static str| -> Result<f64, SimError> {
            given.or_else(|| doc[key].as_f64()).ok_or_else(|| {
                SimError::out_of_range(key, "missing", "the fm document has none: give it")
            })
        };
        Ok(ReconstructRequest {
            inversion: FmInversion::default(),
            distance: Some(distance),
            z_c: None,
            law_force: numbers("law_force"),
            frequency_shift,
            spring_constant: constant(spring_constant, "spring_constant")?,
            resonance_frequency: constant(resonance_frequency, "resonance_frequency")?,
            amplitude: constant(amplitude, "amplitude")?,
        })
    }
}

impl_request! {
    ReconstructRequest, "reconstruct", advice = "give fewer distances";
    validate |r, _| {
        let curve = r.curve()?;
        match r.inversion {
            FmInversion::SaderJarvis => curve.method().map(|_| ()),
            FmInversion::Exact => check_exact(&curve),
        }
    };
    cost |r, _| {
        // no integration; memory bounded by the method's own limit (ShiftCurve::method): the
        // FFT's three buffers of 16 bytes × the next power of two ≥ 2n, or the direct sum's
        // O(n) rows; the curve's columns (distance, shift, force, potential, law) and the
        // document's and the front end's, six of 32-byte JSON values (at 2·10⁶ points the
        // library's run peaked at 464 MB, Sader–Jarvis, and 681 MB, exact, 91 B a point above
        // the columns alone; the command line's resident set at 537 MB and 763 MB)
        // the work: the operations (OPERATION_WORK) of the FFTs' m log₂ m butterflies, m the
        // next power of two ≥ 2n, and the near field, or the direct sum's pairs
        let n = r.frequency_shift.len();
        let (curve, m) = (r.curve()?, (2 * n).next_power_of_two() as f64);
        let fft = m * m.log2();
        let (mut work_bytes, mut ops) = match curve.method()? {
            Method::Fft { .. } => (3.0 * 16.0 * m, 3.0 * fft + (NEAR_FIELD * n) as f64),
            Method::Direct => (8.0 * n as f64, (n * n) as f64 / 2.0),
        };
        if r.inversion == FmInversion::Exact {
            // the forward relation's kernel and buffer (FFT of at most the next power of two
            // ≥ 2n) or its rows' weights, and the iterate's five columns; at every step
            let weights = exact_weights(&curve) as f64;
            work_bytes += 2.0 * 16.0 * m + 8.0 * weights + 5.0 * 8.0 * n as f64;
            ops += EXACT_MAX_ITERATIONS as f64 * (2.0 * fft + weights);
        }
        Ok(Cost {
            bytes: MODEL_BYTES + work_bytes + (5.0 * 8.0 + 6.0 * 32.0) * n as f64,
            work: OPERATION_WORK * ops,
        })
    }
}

/// `reconstruct --am`: the AM matrix inversion of an `afmdyn approach --probe` document of
/// the point mass (`am_curve_from_approach`).
#[derive(Debug, Clone)]
pub struct AmReconstruction(pub Value);

impl_request! {
    AmReconstruction, "reconstruct";
    validate |r, _| am_curve_from_approach(&r.0).map(|_| ());
    // no integration; the curve's and the inversion's columns (its weights are summed row by
    // row, at most one a pair of points)
    cost |r, _| {
        let n = am_curve_from_approach(&r.0)?.z_c.len() as f64;
        Ok(Cost {
            bytes: MODEL_BYTES + 12.0 * 8.0 * n,
            work: OPERATION_WORK * n * n,
        })
    }
}

/// The AM curve of an `afmdyn approach --probe` document of the point-mass model (`reconstruct
/// --am`, [`crate::analysis::reconstruct_am`]): the approach sweep's leading attractive run —
/// from its first point while the phase lag stays above 90° (the repulsive regime, where the
/// first-harmonic balance still holds but the branch jumps, is left out) — with k of
/// `si.calibration`, f₀ and Q of `si.medium` for a lever in a fluid (else of
/// `si.calibration`), the drive frequency `si.drive_frequency_hz` and the free amplitude
/// `si.free_amplitude_m`.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `am` for a document that is not such a document (no
/// `approach` or `si`, another model: the inversion's balance is the point mass's, force-driven
/// equation), or with fewer than 3 attractive points.
pub(crate) fn am_curve_from_approach(doc: &Value) -> Result<AmCurve, SimError> {
    let bad = |what: &'static str| {
        SimError::out_of_range(
            "am",
            what,
            "must be the JSON document of afmdyn approach --probe on the point-mass model \
             (approach.json, or --json's output)",
        )
    };
    if doc["params"]["structure"].as_str() != Some("point-mass") {
        return Err(bad("a document of another model than the point mass"));
    }
    let column = |name: &str| -> Option<Vec<Option<f64>>> {
        Some(
            doc["approach"][name]
                .as_array()?
                .iter()
                .map(Value::as_f64)
                .collect(),
        )
    };
    let (Some(z), Some(a), Some(p), Some(m)) = (
        column("z_c"),
        column("amplitude"),
        column("phase_deg"),
        column("mean_deflection"),
    ) else {
        return Err(bad(
            "a document without the approach's z_c, amplitude, phase_deg, mean_deflection",
        ));
    };
    let si = &doc["si"];
    fn resonance<'v>(si: &'v Value, key: &str) -> &'v Value {
        match si.get("medium") {
            Some(m) if m.is_object() => &m[key],
            _ => &si["calibration"][key],
        }
    }
    let number = |v: &Value| {
        v.as_f64()
            .ok_or_else(|| bad("a document without its si block"))
    };
    let mut curve = AmCurve {
        z_c: Vec::new(),
        amplitude: Vec::new(),
        phase: Vec::new(),
        mean_deflection: Some(Vec::new()),
        spring_constant: number(&si["calibration"]["spring_constant"])?,
        // in a fluid the lever's resonance and Q are the medium's, not the calibration's (air)
        resonance_frequency: number(resonance(si, "resonance_frequency"))?,
        quality_factor: number(resonance(si, "quality_factor"))?,
        drive_frequency: number(&si["drive_frequency_hz"])?,
        free_amplitude: number(&si["free_amplitude_m"])?,
    };
    for i in 0..z.len() {
        let (Some(z), Some(a), Some(p), Some(m)) = (z[i], a[i], p[i], m[i]) else {
            break;
        };
        if p <= 90.0 {
            break;
        }
        curve.z_c.push(z);
        curve.amplitude.push(a);
        curve.phase.push(p.to_radians());
        if let Some(md) = &mut curve.mean_deflection {
            md.push(m);
        }
    }
    if curve.z_c.len() < 3 {
        return Err(SimError::out_of_range(
            "am",
            format!("{} attractive points", curve.z_c.len()),
            "needs at least 3 points of the approach with the phase lag above 90°",
        ));
    }
    Ok(curve)
}
