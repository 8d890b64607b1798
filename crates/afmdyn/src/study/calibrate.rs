//! `calibrate`'s running ([`crate::request::calibrate`] is the request): the spectrum read and
//! converted to m²/Hz, the probe's modes and correction factors, its plan and fluid handed to
//! [`crate::analysis::calibration::calibrate`], the InvOLS of a force curve; its document,
//! layouts and presentation.

use crate::analysis::calibration::{calibrate, invols, Calibration, Measured, ModeCalibration};
use crate::analysis::progress::Progress;
use crate::analysis::thermal::thermal_spectrum;
use crate::error::SimError;
use crate::hydro::Medium;
use crate::report::{self, Convergence};
use crate::request::calibrate::CalibrateRequest;
use crate::request::run::{Analysis, Resolved};
use serde_json::{json, Map, Value};

/// The columns `names` of the CSV `path` (`field` in errors), read through the bounded reader.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `field`: refused by the reader, not a CSV, a missing column.
#[cfg(feature = "files")]
fn read_columns<const N: usize>(
    field: &'static str,
    path: &str,
    names: [&str; N],
) -> Result<[Vec<f64>; N], SimError> {
    use crate::io::curve_file::{read_curve_file, CurveFile};
    let bad = |m: String| SimError::out_of_range(field, path, m);
    match read_curve_file(std::path::Path::new(path)).map_err(|e| bad(e.to_string()))? {
        CurveFile::Document(_) => Err(bad(format!(
            "a JSON document; a CSV with the columns {}",
            names.join(", ")
        ))),
        CurveFile::Columns(have, cols) => {
            let col = |n: &str| match have.iter().position(|c| c == n) {
                Some(i) => Ok(cols[i].clone()),
                None => Err(bad(format!("no column {n} among {}", have.join(", ")))),
            };
            let out: Vec<Vec<f64>> = names.iter().map(|n| col(n)).collect::<Result<_, _>>()?;
            Ok(out.try_into().expect("N columns"))
        }
    }
}

#[cfg(not(feature = "files"))]
fn read_columns<const N: usize>(
    field: &'static str,
    _: &str,
    _: [&str; N],
) -> Result<[Vec<f64>; N], SimError> {
    Err(SimError::out_of_range(
        field,
        "a file",
        "this build reads no files: give the columns",
    ))
}

impl CalibrateRequest {
    /// The spectrum's frequencies (Hz) and PSD: the file's or the request's, checked.
    fn spectrum(&self) -> Result<(Vec<f64>, Vec<f64>), SimError> {
        let (f, s) = match &self.psd {
            Some(path) => {
                let [f, s] = read_columns("psd", path, ["frequency", "psd"])?;
                (f, s)
            }
            None => (self.frequency.clone(), self.spectral_density.clone()),
        };
        CalibrateRequest::check_spectrum(&f, &s)?;
        Ok((f, s))
    }

    /// The InvOLS of the force curve, when one is given.
    fn force_curve_invols(&self) -> Result<Option<Measured>, SimError> {
        let Some(path) = &self.force_curve else {
            return Ok(None);
        };
        let [z, d] = read_columns("force_curve", path, ["height", "deflection"])?;
        invols(&z, &d).map(Some)
    }
}

/// Sader's estimates of the mode `m` of a lever of `plan` (L, b) in `medium`, from its fitted
/// f₀ and Q ([`crate::hydro::sader`]).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `reynolds` where Re leaves Sader's range.
fn sader_of(m: &mut ModeCalibration, plan: (f64, f64), medium: &Medium) -> Result<(), SimError> {
    let pair = |v: Measured| (v.value, v.standard_error);
    let (f0, q) = (pair(m.frequency), pair(m.quality_factor));
    let [s, eff] = crate::hydro::sader(
        plan,
        medium,
        m.mode,
        (f0, q),
        m.frequency_quality_correlation,
    )?;
    let measured = |(value, standard_error)| Measured {
        value,
        standard_error,
    };
    m.static_spring_constant_sader = Some(measured(s));
    m.spring_constant_sader = Some(measured(eff));
    Ok(())
}

impl Analysis for CalibrateRequest {
    type Output = Calibration;
    fn convergence(&self, c: &Calibration) -> Convergence {
        Convergence::count("peak fits", &c.modes, |m| m.converged)
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<Calibration, SimError> {
        let probe = model.probe.as_ref().expect("validated: a probe");
        let (mut f_psd, measured) = (self.spectrum()?, self.force_curve_invols()?);
        let sensitivity = self.invols.or(measured.map(|m| m.value));
        if self.volts {
            let s = sensitivity.expect("validated: an InvOLS with volts");
            f_psd.1.iter_mut().for_each(|v| *v *= s * s);
        }
        let units = super::model_units(&probe.scales);
        let t = self.temperature;
        let spectrum = thermal_spectrum(&model.params, units, t, self.spot, &[], progress)?;
        let modes = &spectrum.modes[..self.peaks.unwrap_or(spectrum.modes.len())];
        let medium = probe.medium.as_ref().map_or(Medium::AIR, |m| Medium {
            density: m.density,
            viscosity: m.viscosity,
        });
        let (f, s) = (&f_psd.0[..], &f_psd.1[..]);
        let mut c = calibrate((f, s), modes, &self.bands(), (self.signal(), t), progress)?;
        if let Some(plan) = probe.plan {
            for m in &mut c.modes {
                sader_of(m, plan, &medium)?;
            }
        }
        c.invols = measured;
        c.warnings = crate::request::limits::temperature_warnings(self.temperature);
        if probe.plan.is_none() {
            c.warnings.push(warning!(
                "calibrate.no-plan",
                "Give [cantilever] length and width (m) in the probe for Sader's method.",
                "no Sader estimate: the probe does not give the lever's plan ([cantilever] \
                 length and width, m)"
            ));
        } else if probe.calibration.tip_mass_ratio > 0.0 {
            c.warnings.push(warning!(
                "calibrate.sader-tip-mass",
                "Read Sader's estimate as approximate; the thermal method's holds the tip mass.",
                "Sader's method assumes a lever without a tip mass; the probe's is {} of the \
                 beam's",
                crate::error::number(probe.calibration.tip_mass_ratio)
            ));
        }
        Ok(c)
    }
    fn report(&self, _: &Resolved, c: &Calibration) -> Result<Value, SimError> {
        Ok(document(c))
    }
    fn present(
        &self,
        c: &Calibration,
        at: crate::request::Presenting<'_>,
    ) -> Result<report::Presentation, SimError> {
        Ok(crate::report::present::calibrate::calibrate(c, at.document))
    }
}

impl super::named::Datasets for CalibrateRequest {
    /// `spectrum` over `frequency` (the PSD and the fitted oscillators); `modes` over `mode`.
    fn datasets(&self, _: &Resolved, c: &Calibration) -> Result<super::named::Arrays, SimError> {
        let mut facts = Map::new();
        facts.insert("temperature".into(), json!(c.temperature));
        Ok((crate::report::present::calibrate::layouts(c), facts))
    }
}

/// A measured value as `name` and `name_standard_error` into `into`.
fn put(into: &mut Map<String, Value>, name: &str, m: Option<Measured>) {
    into.insert(name.into(), json!(m.map(|m| m.value)));
    into.insert(
        format!("{name}_standard_error"),
        json!(m.map(|m| m.standard_error)),
    );
}

/// Sader's estimate over the thermal one and their difference in combined standard errors.
fn agreement(thermal: Measured, sader: Option<Measured>) -> Value {
    sader.map_or(Value::Null, |s| {
        let se = thermal.standard_error.hypot(s.standard_error);
        json!({"sader_over_thermal": s.value / thermal.value,
               "difference_in_standard_errors": (s.value - thermal.value) / se})
    })
}

/// The document (`afmdyn calibrate --json`, Python's `summary`): `temperature` (K), `signal`,
/// `spring_constant` (the static one from the first mode fitted: `thermal`, `sader` with their
/// standard errors, N/m, and their `agreement`), `modes` (each mode's `mode`, `band` (Hz),
/// `points`, `frequency` (Hz), `quality_factor`, `zero_frequency_psd` and `floor` (m²/Hz),
/// `mean_square` (m²), `spring_constant_thermal` and `spring_constant_sader` (the mode's
/// effective spring constant at the tip, N/m), `static_spring_constant_thermal` and
/// `static_spring_constant_sader` (N/m), each with its `_standard_error`, `agreement`,
/// `correction_factor`, `relative_scatter`, `converged`, `warnings`), `invols` (m/V, from the
/// force curve), `units`, `method` and `warnings`.
pub(crate) fn document(c: &Calibration) -> Value {
    let modes: Vec<Value> = (c.modes.iter())
        .map(|m| {
            let mut o = Map::new();
            o.insert("mode".into(), json!(m.mode));
            o.insert("band".into(), json!(m.band));
            o.insert("points".into(), json!(m.points));
            for (name, v) in [
                ("frequency", Some(m.frequency)),
                ("quality_factor", Some(m.quality_factor)),
                ("zero_frequency_psd", Some(m.zero_frequency_psd)),
                ("floor", Some(m.floor)),
                ("mean_square", Some(m.mean_square)),
                ("spring_constant_thermal", Some(m.spring_constant_thermal)),
                ("spring_constant_sader", m.spring_constant_sader),
                (
                    "static_spring_constant_thermal",
                    Some(m.static_spring_constant_thermal),
                ),
                (
                    "static_spring_constant_sader",
                    m.static_spring_constant_sader,
                ),
            ] {
                put(&mut o, name, v);
            }
            o.insert(
                "agreement".into(),
                agreement(m.spring_constant_thermal, m.spring_constant_sader),
            );
            o.insert("correction_factor".into(), json!(m.correction_factor));
            o.insert("relative_scatter".into(), json!(m.relative_scatter));
            o.insert("converged".into(), json!(m.converged));
            o.insert("warnings".into(), json!(m.warnings));
            Value::Object(o)
        })
        .collect();
    let first = &c.modes[0];
    let mut k = Map::new();
    put(
        &mut k,
        "thermal",
        Some(first.static_spring_constant_thermal),
    );
    put(&mut k, "sader", first.static_spring_constant_sader);
    k.insert("mode".into(), json!(first.mode));
    k.insert(
        "agreement".into(),
        agreement(
            first.static_spring_constant_thermal,
            first.static_spring_constant_sader,
        ),
    );
    let mut warnings = c.warnings.clone();
    warnings.extend(c.modes.iter().flat_map(|m| m.warnings.iter().cloned()));
    json!({
        "temperature": c.temperature,
        "signal": c.signal,
        "spring_constant": k,
        "modes": modes,
        "invols": c.invols.map(|m| json!({"value": m.value, "standard_error": m.standard_error})),
        "units": {"temperature": "K", "frequency": "Hz", "spring_constant": "N/m",
                  "zero_frequency_psd": "m^2/Hz", "floor": "m^2/Hz", "mean_square": "m^2",
                  "invols": "m/V", "band": "Hz"},
        "method": "each mode's peak fitted by a simple harmonic oscillator on a white floor \
                   (relative residuals); the thermal method k_s = χ_k k_B T/⟨s_k²⟩ with the \
                   model's correction factor χ_k (Butt & Jaschke 1995); Sader's method \
                   k_s = (3/β_k⁴)(π/4) ρ b² L Q_k Γ_i ω_k² (Sader et al. 1999; Lozano et al. \
                   2010); InvOLS from the contact slope (crate::analysis::calibration)",
        "warnings": warnings,
    })
}
