//! The dynamic fit's running ([`crate::request::fit_dynamic`] reads and checks its data): a
//! measured AM, FM or bimodal curve fitted with the stepped approach of the probe's model and
//! the exact sensitivities of its orbits ([`crate::analysis::fit::am_curve`],
//! [`crate::analysis::fit::fm_curve`], [`crate::analysis::fit::bimodal_curve`]), and its
//! document, of the force-curve fit's shape ([`super::fit::document`]).

use super::fit_result::{bounds, intervals_method, DynamicFit, FitResult};
use crate::analysis::fit::am_curve::{AmCurveModel, AmParam, AmProbe};
use crate::analysis::fit::bimodal_curve::BimodalCurveModel;
use crate::analysis::fit::fm_curve::FmCurveModel;
use crate::analysis::fit::profile::{ProfileWalk, MAX_SECANT_STEPS};
use crate::analysis::fit::start::{grid_start, z_offset_grid};
use crate::analysis::fit::{fit_cancellable, CurveModel, Observations, Parameter};
use crate::analysis::progress::Progress;
use crate::contact::LawKind;
use crate::error::SimError;
use crate::request::fit_dynamic::{
    am_probe, bad, check_data, fitted_names, law_refusal, lever_refusal, AmData,
};
use crate::request::run::Resolved;
use serde_json::{json, Value};

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
            "fit needs a probe file (start values and held parameters in SI)",
        )
    })?;
    let law_name = probe.params.contact_law.name();
    let law = Some(probe.params.contact_law.kind())
        .filter(|l| matches!(l, LawKind::Hertz | LawKind::Dmt | LawKind::Jkr))
        .ok_or_else(|| {
            bad(
                "law",
                law_name,
                "the dynamic fit takes the probe's [sample].law = hertz, dmt or jkr",
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
             component ([drive] frequency = [f1, f2], free_amplitude = [A1, A2])",
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
    outcome
        .warnings
        .extend(data.unit_slips(probe.free_amplitude, probe.calibration.resonance_frequency));
    if fm && (data.amplitude.is_some() || data.phase.is_some()) {
        outcome.warnings.push(warning!(
            "fit.fm-columns",
            "Nothing, for an FM curve; without the frequency_shift column the \
                 amplitude and phase are fitted as an AM curve.",
            "the data have a frequency_shift column: fitted as an FM curve (the loop holds the \
             probe's free amplitude); their amplitude and phase columns are not fitted"
        ));
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
        data_warnings: Vec::new(),
        thermal_sigma: None,
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
                 cantilever.quality_factor, drive.free_amplitude and z_offset",
            )
        })?;
        law_refusal(p, law_name).map_or(Ok(()), |why| Err(bad("fit", n, why)))?;
        if am.contains(&p) {
            return Err(bad("fit", n, "named twice"));
        }
        lever_refusal(p, probe, data).map_or(Ok(()), |why| Err(bad("fit", n, why)))?;
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
            "weighted least squares by Levenberg–Marquardt (MINPACK lmder, rust-cv levenberg-marquardt) of the FM curve the instrument recorded (an ideal PLL and amplitude controller: each row's orbit at the drive frequency and excitation that hold the first harmonic at the probe's free amplitude and the free lever's phase at resonance, followed from row to row as afmdyn fm does, z_c = z + z_offset; Δf = Ω − ω₁), with exact sensitivities: the implicit function theorem on the loop conditions, d(Ω, α2)/dp = −[∂g/∂(Ω, α2)]⁻¹ ∂g/∂p, from the orbits' sensitivities (variational equations extended by the parameters and the drive's α2 and Ω, time rescaled to a fixed phase; ∂x*/∂p = (I − M)⁻¹ ∂P/∂p) (docs/tutorials/fitting-dynamic-curves.md)",
        )
    } else {
        (
            "am",
            "none: z, amplitude and phase as measured; z_c = z + z_offset",
            "weighted least squares by Levenberg–Marquardt (MINPACK lmder, rust-cv levenberg-marquardt) of the stepped approach the instrument did (each row's periodic orbit continued from the previous one, z_c = z + z_offset), with the exact sensitivities of the orbits: the variational equations extended by the parameter columns, saltation at the switchings, ∂x*/∂p = (I − M)⁻¹ ∂P/∂p (docs/tutorials/fitting-dynamic-curves.md)",
        )
    };
    let method = format!("{}{walk}; {least_squares}", intervals_method(o));
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
