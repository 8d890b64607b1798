//! `fit` of a measured amplitude-modulation curve (issue 62 §1): a CSV `data` file with the
//! column `z` (m, the piezo position, in the order the instrument stepped) and any of
//! `amplitude` (m) and `phase` (deg), with optional `sigma_amplitude` (m) and `sigma_phase`
//! (deg), fitted with the stepped approach of the probe's model and the exact sensitivities of
//! its orbits ([`crate::analysis::fit::am_curve`]); or of a frequency-modulation curve: the
//! columns `z` and `frequency_shift` (Hz), optional `sigma_frequency_shift` (Hz), fitted with
//! the FM loop's steady states at the probe's free amplitude
//! ([`crate::analysis::fit::fm_curve`]; the amplitude and phase columns of such a file are
//! not fitted); or of a bimodal curve: the columns `amplitude_2` (m) and/or `phase_2` (deg) of
//! the drive's second component (optional `sigma_amplitude_2`, `sigma_phase_2`), with or
//! without `amplitude` and `phase`, under a probe whose drive has a second component
//! ([`crate::analysis::fit::bimodal_curve`]). The request is [`super::FitRequest`] (the
//! data's columns choose the kind: `z` makes it dynamic). Here its data are read and checked,
//! the parameters a law, lever or drive refuses named, and its cost declared.

pub(crate) use super::fit_result::AmData;
use super::fit_result::{probe_value, MIN_FIT_ROWS};
use crate::analysis::fit::am_curve::{AmParam, AmProbe, Z_OFFSET};
use crate::analysis::fit::profile::MAX_SECANT_STEPS;
use crate::error::SimError;

/// A refusal naming `name` (the force-curve fit's).
pub(crate) use super::fit::bad;

/// The AM and FM columns of a CSV file's `names` and `cols`, `None` without a `z` column.
#[cfg(feature = "files")]
pub(crate) fn am_columns(names: &[String], cols: &[Vec<f64>]) -> Option<AmData> {
    let col = |n: &str| names.iter().position(|c| c == n).map(|i| cols[i].clone());
    Some(AmData {
        z: col("z")?,
        amplitude: col("amplitude"),
        phase: col("phase"),
        sigma_amplitude: col("sigma_amplitude"),
        sigma_phase: col("sigma_phase"),
        frequency_shift: col("frequency_shift"),
        sigma_frequency_shift: col("sigma_frequency_shift"),
        amplitude_2: col("amplitude_2"),
        phase_2: col("phase_2"),
        sigma_amplitude_2: col("sigma_amplitude_2"),
        sigma_phase_2: col("sigma_phase_2"),
    })
}

/// The AM data of the request's `data` file, `None` when it is not one (no `z` column, or no
/// file).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `data` where the file cannot be read.
pub(crate) fn read_am_data(data: Option<&str>) -> Result<Option<AmData>, SimError> {
    #[cfg(feature = "files")]
    {
        if let Some(path) = data {
            use crate::io::curve_file::{read_curve_file, CurveFile};
            let path = std::path::Path::new(path);
            let file =
                read_curve_file(path).map_err(|e| bad("data", path.display(), e.to_string()))?;
            return Ok(match file {
                CurveFile::Columns(names, cols) => am_columns(&names, &cols),
                CurveFile::Document(_) => None,
            });
        }
    }
    let _ = data;
    Ok(None)
}

/// Check an AM, FM or bimodal curve's columns: one channel at least, their rows, finite values,
/// σ > 0 and the σ columns that channels fitted together need.
pub(crate) fn check_data(d: &AmData) -> Result<(), SimError> {
    let m = d.z.len();
    let bimodal = d.amplitude_2.is_some() || d.phase_2.is_some();
    if d.amplitude.is_none() && d.phase.is_none() && d.frequency_shift.is_none() && !bimodal {
        return Err(bad(
            "data",
            "no amplitude, phase or frequency_shift column",
            "an AM curve has the column z (m) and amplitude (m) and/or phase (deg); an FM \
             curve z (m) and frequency_shift (Hz)",
        ));
    }
    if !(MIN_FIT_ROWS..=crate::analysis::stepped::MAX_CURVE_POINTS).contains(&m) {
        return Err(bad(
            "data",
            format!("{m} rows"),
            format!("a dynamic curve has {MIN_FIT_ROWS}..=100000 rows"),
        ));
    }
    for (name, c) in d.named() {
        if c.len() != m {
            return Err(bad(
                name,
                format!("{} rows", c.len()),
                format!("every column must have one value per row ({m} values of z)"),
            ));
        }
        if let Some(i) = c.iter().position(|x| !x.is_finite()) {
            return Err(bad(
                name,
                format!("row {}: {}", i + 1, c[i]),
                "every value must be finite",
            ));
        }
        let sigma = name.starts_with("sigma_");
        if let Some(i) = c.iter().position(|x| sigma && *x <= 0.0) {
            return Err(bad(
                name,
                format!("row {}: {}", i + 1, c[i]),
                "a standard deviation must be > 0",
            ));
        }
    }
    if bimodal && d.frequency_shift.is_some() {
        return Err(bad(
            "data",
            "frequency_shift with amplitude_2 or phase_2",
            "a curve is an FM curve (frequency_shift) or an AM one (amplitude, phase and the \
             bimodal amplitude_2, phase_2), not both",
        ));
    }
    let channels = [
        (&d.amplitude, &d.sigma_amplitude),
        (&d.phase, &d.sigma_phase),
        (&d.amplitude_2, &d.sigma_amplitude_2),
        (&d.phase_2, &d.sigma_phase_2),
    ];
    let fitted = channels.iter().filter(|(c, _)| c.is_some()).count();
    if bimodal && fitted > 1 && channels.iter().any(|(c, s)| c.is_some() && s.is_none()) {
        return Err(bad(
            "sigma",
            "missing",
            "fitting several bimodal channels together needs the σ column of each \
             (sigma_amplitude, sigma_phase, sigma_amplitude_2, sigma_phase_2: their units \
             differ)",
        ));
    }
    if d.frequency_shift.is_none()
        && d.amplitude.is_some()
        && d.phase.is_some()
        && (d.sigma_amplitude.is_none() || d.sigma_phase.is_none())
    {
        return Err(bad(
            "sigma",
            "missing",
            "fitting amplitude (m) and phase (deg) together needs their σ columns \
             sigma_amplitude and sigma_phase (the two channels' units differ)",
        ));
    }
    Ok(())
}

/// Why `p` is not a parameter of the contact law `law_name`, if so.
pub(crate) fn law_refusal(p: AmParam, law_name: &str) -> Option<&'static str> {
    match p {
        AmParam::Hamaker if law_name != "dmt" => Some("sample.hamaker is DMT's"),
        AmParam::Damping if law_name != "hertz" => Some(
            "sample.damping is the hertz law's damper (the Kelvin–Voigt term of dmt and \
             jkr is sample.viscosity, Pa s)",
        ),
        // η (Pa s) is DMT's and JKR's Kelvin–Voigt term; the hertz law's dashpot is its
        // damping c (N s/m)
        AmParam::Viscosity if law_name == "hertz" => Some(
            "sample.viscosity is the Kelvin–Voigt term of dmt and jkr; the hertz law's \
             damper is sample.damping (N s/m)",
        ),
        AmParam::AdhesionEnergy if law_name != "jkr" => Some(
            "sample.adhesion_energy is the jkr law's work of adhesion (DMT's adhesion is \
             its sample.hamaker)",
        ),
        _ => None,
    }
}

/// The SI values of `probe` the dynamic fit's models scale from ([`AmProbe`]).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `probe` and the keys a quasi-static read stood in for
/// ([`crate::probe::Probe::assumed`]: a dynamic curve needs the lever's resonance, Q and
/// drive), or the first of E_s, ν_s, E_t, ν_t and R the probe lacks.
pub(crate) fn am_probe(probe: &crate::probe::Probe) -> Result<AmProbe, SimError> {
    if !probe.assumed.is_empty() {
        return Err(SimError::out_of_range(
            "probe",
            format!("without {}", probe.assumed.join(", ")),
            "an AM, FM or bimodal curve is fitted with the oscillating lever's model: give \
             the model, the cantilever's resonance_frequency and quality_factor, and [drive]",
        ));
    }
    let s = probe.sample_inputs;
    if s.tip_shape != crate::contact::indenter::TipShape::Paraboloid {
        return Err(SimError::out_of_range(
            "tip.shape",
            s.tip_shape.name(),
            "an AM, FM or bimodal curve is fitted with the oscillating lever's model, whose \
             contact laws take the paraboloid (shape = \"paraboloid\", the default); the other \
             shapes are the force-curve fit's",
        ));
    }
    Ok(AmProbe {
        params: probe.params,
        length_m: probe.scales.length_m,
        youngs_modulus: probe_value(s.youngs_modulus, "sample.youngs_modulus")?,
        poisson_ratio: probe_value(s.poisson_ratio, "sample.poisson_ratio")?,
        tip: (
            probe_value(s.tip_youngs_modulus, "tip.youngs_modulus")?,
            probe_value(s.tip_poisson_ratio, "tip.poisson_ratio")?,
        ),
        hamaker: s.hamaker.unwrap_or(0.0),
        radius: probe_value(s.radius, "tip.radius")?,
        damping_unit: probe.scales.length_m / (probe.scales.time_s * probe.scales.force_n),
        quality_factor: probe.calibration.quality_factor,
    })
}

/// Why the lever's Q₁ or the free amplitude A₀ (`p`) cannot be fitted on `data` under `probe`,
/// if so (analysis::fit::am_curve, `lever_and_drive`): Q₁ moves the lever's damping α3 with
/// the drive α2 holding A₀ (and a bimodal drive's second force holding A₀₁), which holds for
/// the AM and bimodal curves of a drive of at most two components in air or vacuum. An FM
/// curve's Δf does not constrain Q₁ (the loop locks the phase at resonance; Q₁ shows in the
/// drive it needs, which the fit does not take); in a `[medium]`, Q₁ is the fluid's, made of the
/// medium's hydrodynamic damping and the lever's. Off resonance, the drive is the sample's
/// modulation, not a free amplitude.
pub(crate) fn lever_refusal(
    p: AmParam,
    probe: &crate::probe::Probe,
    data: &AmData,
) -> Option<&'static str> {
    let fm = data.frequency_shift.is_some();
    match p {
        AmParam::QualityFactor if fm => Some(
            "an FM curve's frequency shift does not constrain Q (the loop holds the phase at \
             resonance; Q shows in the drive it needs, which the fit does not take)",
        ),
        AmParam::QualityFactor if probe.params.components().count() > 1 => Some(
            "Q is fitted under a drive of at most two components (the further component's \
             force follows Q to hold its free amplitude)",
        ),
        AmParam::QualityFactor if probe.medium.is_some() => Some(
            "in a [medium], Q is the fluid's, made of the medium's damping and the lever's: \
             fit it on a probe without [medium] whose quality_factor is the measured one",
        ),
        AmParam::QualityFactor | AmParam::FreeAmplitude if probe.off_resonance => Some(
            "an off-resonance (PeakForce) drive is the sample's modulation, with no free \
             amplitude or resonance to fit",
        ),
        _ => None,
    }
}

/// The names of the parameters fitted: `fit`, or the default (the force curve's, when
/// `default_fit`) E, with H on DMT (`law_name` "dmt"); z_offset always, last unless named.
/// The names of the parameters fitted: `fit`, or the default (when `default_fit`) E, with H on
/// DMT (`law_name` "dmt") and the work of adhesion W (`sample.adhesion_energy`) on JKR
/// (`law_name` "jkr"); z_offset always, last unless named.
pub(crate) fn fitted_names(fit: &[String], default_fit: bool, law_name: &str) -> Vec<String> {
    let mut names: Vec<String> = if default_fit {
        let mut v = vec!["sample.youngs_modulus".to_string()];
        if law_name == "dmt" {
            v.push("sample.hamaker".into());
        }
        if law_name == "jkr" {
            v.push("sample.adhesion_energy".into());
        }
        v
    } else {
        fit.to_vec()
    };
    if !names.iter().any(|n| n == Z_OFFSET) {
        names.push(Z_OFFSET.into());
    }
    names
}

/// The most model evaluations of a fit of `fitted` parameters: the minimiser's
/// ([`crate::analysis::fit::least_squares::max_evaluations`]), the final χ² and Jacobian, and
/// with profiles walked by at most `refits` refits a side (of up to `MAX_PROFILED` parameters)
/// each refit's (at `REFIT_PATIENCE`).
pub(crate) fn fit_evaluations(fitted: usize, refits: Option<usize>) -> f64 {
    use crate::analysis::fit::estimates::MAX_PROFILED;
    use crate::analysis::fit::least_squares::{max_evaluations, PATIENCE};
    use crate::analysis::fit::profile::REFIT_PATIENCE;
    let refits = (fitted.min(MAX_PROFILED) * 2 * refits.unwrap_or(0)) as f64;
    let refit = max_evaluations(fitted.saturating_sub(1), REFIT_PATIENCE) as f64;
    max_evaluations(fitted, PATIENCE) as f64 + 2.0 + refits * refit
}

/// The declared cost of a dynamic fit of `rows` rows fitting `fitted` parameters on
/// `params` (the probe's model), with profiles when `profiles`: the worst case of its
/// evaluations, each one stepped approach of the rows (`super::costs::stepped_cost`, one
/// way), z_offset's start grid, the minimiser's most evaluations
/// ([`crate::analysis::fit::least_squares::max_evaluations`]) and, with profiles (up to
/// `crate::analysis::fit::estimates::MAX_PROFILED` parameters), 2 × [`MAX_SECANT_STEPS`]
/// refits per parameter of the other parameters, each at most
/// [`crate::analysis::fit::profile::REFIT_PATIENCE`]'s evaluations. (The sensitivities of a Jacobian add one
/// period of 2N + 4 columns per row, small beside a row's steady-state cap.)
///
/// # Errors
/// [`SimError::Params`] when the model cannot be built; [`SimError::Budget`] beyond the request
/// budget, advising fewer rows or parameters, or no profiles.
pub(crate) fn cost(
    rows: usize,
    fitted: usize,
    profiles: bool,
    params: &crate::params::Params,
) -> Result<super::limits::Cost, SimError> {
    use crate::analysis::fit::start::Z_OFFSET_GRID;
    let mut spec =
        crate::analysis::stepped::SteppedSpec::new(*params, crate::params::SweepParam::Alpha5, {
            vec![params.alpha5; rows.max(2)]
        });
    spec.branches = false;
    let approach = super::costs::stepped_cost(&spec)?;
    let grid = (2 * Z_OFFSET_GRID + 1) as f64;
    let evaluations = grid + fit_evaluations(fitted, profiles.then_some(MAX_SECANT_STEPS));
    let cost = super::limits::Cost {
        bytes: approach.bytes + rows as f64 * 8.0 * 64.0,
        work: evaluations * approach.work,
    };
    // every model evaluation steps the approach through every row: the advice names them
    let advice = if profiles {
        "fit fewer rows or parameters, or without profiles (each profile point refits the curve)"
    } else {
        "fit fewer rows or parameters (each model evaluation steps the approach through every row)"
    };
    super::costs::check_cost_advising("fit", cost, advice, advice)?;
    Ok(cost)
}
