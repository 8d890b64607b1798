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
//! data's columns choose the kind: `z` makes it dynamic); its document has the force-curve
//! fit's shape (estimates with value, standard error and interval, correlation, χ²/dof, the
//! curve beside the data with its residuals, warnings).

use super::fit_result::{bounds, probe_value, FitResult, MIN_FIT_ROWS};
pub(crate) use super::fit_result::{AmData, DynamicFit};
use super::run::Resolved;
use crate::analysis::fit::am_curve::{AmCurveModel, AmParam, AmProbe, Z_OFFSET};
use crate::analysis::fit::bimodal_curve::BimodalCurveModel;
use crate::analysis::fit::fm_curve::FmCurveModel;
use crate::analysis::fit::profile::{ProfileWalk, MAX_SECANT_STEPS};
use crate::analysis::fit::start::{grid_start, z_offset_grid};
use crate::analysis::fit::{fit_cancellable, CurveModel, Observations, Parameter};
use crate::analysis::progress::Progress;
use crate::contact::LawKind;
use crate::error::SimError;
use serde_json::{json, Value};

fn bad(name: &'static str, value: impl std::fmt::Display, allowed: String) -> SimError {
    SimError::out_of_range(name, value, allowed)
}

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

fn check_data(d: &AmData) -> Result<(), SimError> {
    let m = d.z.len();
    let bimodal = d.amplitude_2.is_some() || d.phase_2.is_some();
    if d.amplitude.is_none() && d.phase.is_none() && d.frequency_shift.is_none() && !bimodal {
        return Err(bad(
            "data",
            "no amplitude, phase or frequency_shift column",
            "an AM curve has the column z (m) and amplitude (m) and/or phase (deg); an FM \
             curve z (m) and frequency_shift (Hz)"
                .into(),
        ));
    }
    if !(MIN_FIT_ROWS..=crate::analysis::stepped::MAX_CURVE_POINTS).contains(&m) {
        return Err(bad(
            "data",
            format!("{m} rows"),
            format!("a dynamic curve has {MIN_FIT_ROWS}..=100000 rows"),
        ));
    }
    let all = [
        &Some(d.z.clone()),
        &d.amplitude,
        &d.phase,
        &d.sigma_amplitude,
        &d.sigma_phase,
        &d.frequency_shift,
        &d.sigma_frequency_shift,
        &d.amplitude_2,
        &d.phase_2,
        &d.sigma_amplitude_2,
        &d.sigma_phase_2,
    ];
    for c in all.into_iter().flatten() {
        if c.len() != m || c.iter().any(|x| !x.is_finite()) {
            return Err(bad(
                "data",
                "a column",
                "every column must have one finite value per row".into(),
            ));
        }
    }
    let sigmas = [
        &d.sigma_amplitude,
        &d.sigma_phase,
        &d.sigma_frequency_shift,
        &d.sigma_amplitude_2,
        &d.sigma_phase_2,
    ];
    for s in sigmas.into_iter().flatten() {
        if s.iter().any(|x| *x <= 0.0) {
            return Err(bad("sigma", "≤ 0", "σ must be > 0".into()));
        }
    }
    if bimodal && d.frequency_shift.is_some() {
        return Err(bad(
            "data",
            "frequency_shift with amplitude_2 or phase_2",
            "a curve is an FM curve (frequency_shift) or an AM one (amplitude, phase and the \
             bimodal amplitude_2, phase_2), not both"
                .into(),
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
             differ)"
                .into(),
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
             sigma_amplitude and sigma_phase (the two channels' units differ)"
                .into(),
        ));
    }
    Ok(())
}

/// Run the dynamic fit of the parameters `fit` (the default when `default_fit`, `fitted_names`:
/// E, with H on DMT and W on JKR; z_offset always) on `data` under `model`'s probe, with the
/// profile-likelihood intervals when `profiles` (the secant walk,
/// [`ProfileWalk::Secant`] with [`MAX_SECANT_STEPS`] refits a side; else the Wald intervals).
/// Every model evaluation is counted in `progress` and checks its cancel flag, between the
/// rows of its stepped approach too.
///
/// # Errors
/// [`SimError::OutOfRange`] for bad data, parameter names, a probe without a Hertz, DMT or JKR
/// sample; [`SimError::Cancelled`].
pub(crate) fn execute(
    fit: &[String],
    default_fit: bool,
    profiles: bool,
    model: &Resolved,
    data: AmData,
    progress: &Progress,
) -> Result<FitResult, SimError> {
    check_data(&data)?;
    let probe = model.probe.as_ref().ok_or_else(|| {
        bad(
            "probe",
            "missing",
            "fit needs a probe file (start values and held parameters in SI)".into(),
        )
    })?;
    let law_name = probe.params.contact_law.name();
    let law = Some(probe.params.contact_law.kind())
        .filter(|l| matches!(l, LawKind::Hertz | LawKind::Dmt | LawKind::Jkr))
        .ok_or_else(|| {
            bad(
                "law",
                law_name,
                "the dynamic fit takes the probe's [sample].law = hertz, dmt or jkr".into(),
            )
        })?;
    let am_probe = am_probe(probe)?;
    let names = fitted_names(fit, default_fit, law_name);
    let (am, mut params) = parameters(&names, probe, &am_probe, &data)?;
    // z and frequency_shift make an FM curve (its amplitude and phase columns not fitted)
    let fm = data.frequency_shift.is_some();
    let channels = if fm {
        (false, false)
    } else {
        (data.amplitude.is_some(), data.phase.is_some())
    };
    let second = (data.amplitude_2.is_some(), data.phase_2.is_some());
    if (second.0 || second.1) && !probe.params.is_multifrequency() {
        return Err(bad(
            "probe",
            "a single-frequency drive",
            "the bimodal channels amplitude_2 and phase_2 need a probe whose drive has a second \
             component ([drive] frequency = [f1, f2], free_amplitude = [A1, A2])"
                .into(),
        ));
    }
    let z_index = am.iter().position(|&p| p == AmParam::ZOffset);
    let hz = probe.scales.frequency_hz(1.0);
    let curve = DynamicModel::new(am_probe, &data, channels, second, am, hz);
    let (y, sigma) = observations(&data);
    progress.check()?;
    let obs = Observations {
        y: &y,
        sigma: sigma.as_deref(),
    };
    let fixed = vec![None; params.len()];
    // z_offset's start: the best χ² on a grid (the model's first rows otherwise follow another
    // branch than the data's, and Levenberg–Marquardt stops in that local minimum)
    if let Some(k) = z_index {
        let grid = z_offset_grid(am_probe.length_m);
        params[k].start = grid_start(curve.curve(), &obs, &params, k, grid, progress)?;
    }
    // each profile point a refit of stepped approaches (FM curves): the secant walk, when
    // asked for
    let walk = profiles.then_some(ProfileWalk::Secant {
        max_steps: MAX_SECANT_STEPS,
    });
    let mut outcome = fit_cancellable(curve.curve(), &obs, &params, &fixed, walk, progress)?;
    let model_warnings = curve.warnings();
    outcome.warnings.extend(model_warnings.iter().cloned());
    if fm && (data.amplitude.is_some() || data.phase.is_some()) {
        outcome.warnings.push(
            "the data have a frequency_shift column: fitted as an FM curve (the loop holds the \
             probe's free amplitude); their amplitude and phase columns are not fitted"
                .into(),
        );
    }
    let names: Vec<&'static str> = params
        .iter()
        .map(|p| AmParam::from_name(&p.name).map_or("", AmParam::name))
        .collect();
    Ok(FitResult {
        law,
        spring_constant: probe.calibration.spring_constant,
        curve: crate::analysis::fit::force_curve::preprocess(&[], &[], 1.0),
        rows: Vec::new(),
        fitted: vec![true; names.len()],
        names,
        outcome,
        dynamic: Some(DynamicFit {
            data,
            channels,
            frequency_shift: fm,
            second,
            model_warnings,
        }),
    })
}

/// The parameters `names` of the dynamic fit on `data` under `probe` (its SI values
/// `am_probe`): each one's [`AmParam`] and its start, scale and range.
///
/// # Errors
/// [`SimError::OutOfRange`] naming `fit` for an unknown parameter, one of another law, one
/// named twice or one the lever or drive cannot fit ([`lever_refusal`]).
fn parameters(
    names: &[String],
    probe: &crate::probe::Probe,
    am_probe: &AmProbe,
    data: &AmData,
) -> Result<(Vec<AmParam>, Vec<Parameter>), SimError> {
    let law_name = probe.params.contact_law.name();
    let mut params = Vec::new();
    let mut am = Vec::new();
    for n in names {
        let p = AmParam::from_name(n).ok_or_else(|| {
            bad(
                "fit",
                n,
                "the dynamic fit's parameters are sample.youngs_modulus, sample.hamaker (dmt), \
                 sample.viscosity (dmt, jkr), sample.damping (hertz), sample.adhesion_energy (jkr), \
                 tip.radius, \
                 cantilever.quality_factor, drive.free_amplitude and z_offset"
                    .into(),
            )
        })?;
        law_refusal(p, law_name).map_or(Ok(()), |why| Err(bad("fit", n, why.into())))?;
        if am.contains(&p) {
            return Err(bad("fit", n, "named twice".into()));
        }
        lever_refusal(p, probe, data).map_or(Ok(()), |why| Err(bad("fit", n, why.into())))?;
        let (start, scale) = start_and_scale(p, am_probe);
        // the physical range's lower end only: MINUIT's sine map of a two-sided range squashes
        // a value near its lower end (a modulus of GPa in a range to TPa), where the
        // one-sided map keeps its scale
        let (lower, upper) = match p {
            AmParam::ZOffset => (-am_probe.length_m * 10.0, am_probe.length_m * 10.0),
            _ => (bounds(n).0, f64::INFINITY),
        };
        am.push(p);
        params.push(Parameter {
            name: n.clone(),
            start,
            lower,
            upper,
            scale,
        });
    }
    Ok((am, params))
}

/// Why `p` is not a parameter of the contact law `law_name`, if so.
fn law_refusal(p: AmParam, law_name: &str) -> Option<&'static str> {
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

/// The start value of `p` (the probe's, z_offset 0) and its scale.
fn start_and_scale(p: AmParam, am_probe: &AmProbe) -> (f64, f64) {
    match p {
        AmParam::YoungsModulus => (am_probe.youngs_modulus, am_probe.youngs_modulus),
        AmParam::Hamaker => (am_probe.hamaker, am_probe.hamaker.max(1e-21)),
        AmParam::TipRadius => (am_probe.radius, am_probe.radius),
        AmParam::ZOffset => (0.0, 0.1 * am_probe.length_m),
        AmParam::QualityFactor => (am_probe.quality_factor, am_probe.quality_factor),
        AmParam::FreeAmplitude => (am_probe.length_m, am_probe.length_m),
        // the probe's c; its scale c itself, or (c = 0, an undamped start) the c whose
        // α6 is 1 % of α4 (a dashpot force α6 δ̇ at the rate g₀/t_s of 1 % of the Hertz
        // force at δ = g₀)
        AmParam::Damping => {
            let c = am_probe.params.alpha6 / am_probe.damping_unit;
            let typical = 0.01 * am_probe.params.alpha4 / am_probe.damping_unit;
            (c, if c > 0.0 { c } else { typical })
        }
        // the probe's η; its scale η itself, or (η = 0) the η whose α6 is 1 % of α4, as
        // the hertz damper's
        AmParam::Viscosity => {
            let eta = am_probe.viscosity();
            let unit = am_probe.viscosity_unit(am_probe.radius);
            let typical = 0.01 * am_probe.params.alpha4 / unit;
            (eta, if eta > 0.0 { eta } else { typical })
        }
        // the probe's W (J/m²), its own scale (JKR's P̃ > 0, so W > 0)
        AmParam::AdhesionEnergy => {
            let w = am_probe.adhesion_energy();
            (w, w)
        }
    }
}

/// The values fitted and their σ (when every channel has its σ column): the frequency shift of
/// an FM curve, else the amplitude, phase, A₂ and φ₂ columns given, in that order.
fn observations(data: &AmData) -> (Vec<f64>, Option<Vec<f64>>) {
    let mut y = Vec::new();
    let mut sigma = Vec::new();
    let fm_columns = [(&data.frequency_shift, &data.sigma_frequency_shift)];
    let am_columns = [
        (&data.amplitude, &data.sigma_amplitude),
        (&data.phase, &data.sigma_phase),
        (&data.amplitude_2, &data.sigma_amplitude_2),
        (&data.phase_2, &data.sigma_phase_2),
    ];
    let fm = data.frequency_shift.is_some();
    for (c, sg) in if fm { &fm_columns[..] } else { &am_columns[..] } {
        if let Some(c) = c {
            y.extend_from_slice(c);
            if let Some(sg) = sg {
                sigma.extend_from_slice(sg);
            }
        }
    }
    let sigma = (sigma.len() == y.len()).then_some(sigma);
    (y, sigma)
}

/// The model of a dynamic curve: an FM curve's, a bimodal one's or an AM one's.
enum DynamicModel {
    Fm(FmCurveModel),
    Bimodal(BimodalCurveModel),
    Am(AmCurveModel),
}

impl DynamicModel {
    /// The model of `data` (an FM curve when it has a frequency shift, else bimodal when a
    /// `second` channel is fitted, else AM with its `channels`) in the parameters `am`.
    fn new(
        am_probe: AmProbe,
        data: &AmData,
        channels: (bool, bool),
        second: (bool, bool),
        am: Vec<AmParam>,
        hz: f64,
    ) -> Self {
        let z = data.z.clone();
        if data.frequency_shift.is_some() {
            DynamicModel::Fm(FmCurveModel::new(am_probe, z, am, hz))
        } else if second.0 || second.1 {
            let on = [channels.0, channels.1, second.0, second.1];
            DynamicModel::Bimodal(BimodalCurveModel::new(am_probe, z, on, am))
        } else {
            DynamicModel::Am(AmCurveModel::new(am_probe, z, channels, am))
        }
    }

    /// The model fitted.
    fn curve(&self) -> &dyn CurveModel {
        match self {
            DynamicModel::Fm(m) => m,
            DynamicModel::Bimodal(m) => m,
            DynamicModel::Am(m) => m,
        }
    }

    /// Its last evaluation's warnings.
    fn warnings(&self) -> Vec<String> {
        match self {
            DynamicModel::Fm(m) => m.warnings(),
            DynamicModel::Bimodal(m) => m.warnings(),
            DynamicModel::Am(m) => m.warnings(),
        }
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
fn lever_refusal(p: AmParam, probe: &crate::probe::Probe, data: &AmData) -> Option<&'static str> {
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
    use crate::analysis::fit::estimates::MAX_PROFILED;
    use crate::analysis::fit::least_squares::{max_evaluations, PATIENCE};
    use crate::analysis::fit::profile::REFIT_PATIENCE;
    use crate::analysis::fit::start::Z_OFFSET_GRID;
    let mut spec =
        crate::analysis::stepped::SteppedSpec::new(*params, crate::params::SweepParam::Alpha5, {
            vec![params.alpha5; rows.max(2)]
        });
    spec.branches = false;
    let approach = super::costs::stepped_cost(&spec)?;
    let grid = (2 * Z_OFFSET_GRID + 1) as f64;
    let mut evaluations = grid + max_evaluations(fitted, PATIENCE) as f64 + 2.0;
    if profiles {
        let refits = (fitted.min(MAX_PROFILED) * 2 * MAX_SECANT_STEPS) as f64;
        evaluations += refits * max_evaluations(fitted.saturating_sub(1), REFIT_PATIENCE) as f64;
    }
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

/// The document of a dynamic fit (the force-curve fit's shape, [`super::fit::document`]):
/// `estimates`, `parameters`, `correlation`, `chi2`, `dof`, `chi2_dof`, `noise`, `curve` (z and,
/// per channel, the data, the fit and the residual: `amplitude`, `amplitude_fit`,
/// `amplitude_residual`, `phase`, …, or `frequency_shift`, `frequency_shift_fit`,
/// `frequency_shift_residual` (Hz)), `preprocessing` (none; the lever's `spring_constant`),
/// `kind` = `"am"` or `"fm"`, `law`, `units`, `method`, `warnings`.
pub(crate) fn document(
    r: &FitResult,
    d: &DynamicFit,
    estimates: Value,
    correlation: Value,
) -> Value {
    let o = &r.outcome;
    let m = d.data.z.len();
    let mut curve = serde_json::Map::new();
    curve.insert("z".into(), json!(d.data.z));
    let mut off = 0;
    for (name, col, on) in [
        ("amplitude", &d.data.amplitude, d.channels.0),
        ("phase", &d.data.phase, d.channels.1),
        ("amplitude_2", &d.data.amplitude_2, d.second.0),
        ("phase_2", &d.data.phase_2, d.second.1),
        (
            "frequency_shift",
            &d.data.frequency_shift,
            d.frequency_shift,
        ),
    ] {
        if !on {
            continue;
        }
        curve.insert(name.into(), json!(col));
        curve.insert(format!("{name}_fit"), json!(&o.fitted[off..off + m]));
        curve.insert(
            format!("{name}_residual"),
            json!(&o.residuals[off..off + m]),
        );
        off += m;
    }
    let mut parameters = serde_json::Map::new();
    for (i, n) in r.names.iter().enumerate() {
        parameters.insert((*n).into(), json!({"value": o.values[i], "fitted": true}));
    }
    let walk = if o.estimates.iter().any(|e| e.profile.is_some()) {
        " (walked by secants on √Δχ² from 1 SE, at most 6 refits a side, each started from its \
         neighbour)"
    } else {
        ""
    };
    let fm = d.frequency_shift;
    let (kind, steps, least_squares) = if fm {
        (
            "fm",
            "none: z and the frequency shift as measured; z_c = z + z_offset; the amplitude setpoint the probe's free amplitude",
            "weighted least squares by Levenberg–Marquardt (MINPACK lmder, rust-cv levenberg-marquardt) of the FM curve the instrument recorded (an ideal PLL and amplitude controller: each row's orbit at the drive frequency and excitation that hold the first harmonic at the probe's free amplitude and the free lever's phase at resonance, followed from row to row as afmdyn fm does, z_c = z + z_offset; Δf = Ω − ω₁), with exact sensitivities: the implicit function theorem on the loop conditions, d(Ω, α2)/dp = −[∂g/∂(Ω, α2)]⁻¹ ∂g/∂p, from the orbits' sensitivities (variational equations extended by the parameters and the drive's α2 and Ω, time rescaled to a fixed phase; ∂x*/∂p = (I − M)⁻¹ ∂P/∂p) (docs/afm-workflow.md, From data to properties)",
        )
    } else {
        (
            "am",
            "none: z, amplitude and phase as measured; z_c = z + z_offset",
            "weighted least squares by Levenberg–Marquardt (MINPACK lmder, rust-cv levenberg-marquardt) of the stepped approach the instrument did (each row's periodic orbit continued from the previous one, z_c = z + z_offset), with the exact sensitivities of the orbits: the variational equations extended by the parameter columns, saltation at the switchings, ∂x*/∂p = (I − M)⁻¹ ∂P/∂p (docs/afm-workflow.md, From data to properties)",
        )
    };
    let method = format!(
        "{}{walk}; {least_squares}",
        super::fit_result::intervals_method(o)
    );
    json!({
        "kind": kind,
        "estimates": estimates,
        "parameters": parameters,
        "correlation": correlation,
        "chi2": o.chi2,
        "dof": o.dof,
        "chi2_dof": o.chi2_dof,
        "noise": if o.noise_estimated { "noise estimated from residuals (no sigma column)" } else { "the sigma columns (χ² in units of σ)" },
        "curve": curve,
        "preprocessing": {
            "steps": [steps],
            "spring_constant": r.spring_constant,
        },
        "law": r.law.name(),
        "rows_fitted": m,
        "evaluations": o.evaluations,
        "termination": o.termination,
        "units": {"sample.youngs_modulus": "Pa", "tip.radius": "m", "sample.hamaker": "J", "z_offset": "m", "sample.damping": "N s/m", "cantilever.quality_factor": "1", "drive.free_amplitude": "m",
                  "sample.adhesion_energy": "J/m^2", "sample.viscosity": "Pa s",
                  "z": "m", "amplitude": "m", "phase": "deg", "frequency_shift": "Hz",
                  "amplitude_2": "m", "phase_2": "deg"},
        "method": method,
        "warnings": o.warnings,
    })
}
