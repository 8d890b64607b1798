//! `fm`'s running ([`crate::request::fm`] is the request): the frequency-modulation curve
//! ([`crate::analysis::fm`]) and its document, table and layout. With a probe everything is SI
//! (z_c and A in m, Δf in Hz, E_dis in J, forces in N); without one the model's units
//! (g₀, Ω, F̃).

use crate::analysis::fm::noise::{curve_noise, loop_bandwidth, loop_gain, MAX_LOOP_GAIN};
use crate::analysis::fm::LoopSpec;
use crate::analysis::fm::{fm_curve, fm_reference, FmCurve, FmPoint, FmReference, FmSpec};
use crate::analysis::orbit_noise::{grazing, NOISE_GRAZING};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::layout::columns::{self, columns, Column, UnitNames};
use crate::report::{Convergence, CurveUnits};
use crate::request::fm::FmRequest;
use crate::request::run::{Analysis, Resolved};
use crate::study::named::{Arrays, Datasets};
use serde_json::{json, Value};
use std::f64::consts::PI;

impl Analysis for FmRequest {
    type Output = FmCurve;
    fn convergence(&self, curve: &FmCurve) -> Convergence {
        let reached = usize::from(curve.unreached.is_none());
        Convergence::of("curve to the end of its range", reached, 1)
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<FmCurve, SimError> {
        crate::request::curves::check_single_frequency(&model.params, "fm")?;
        let spec = self.spec(model)?;
        let noise = gains(self, model, &spec)?;
        let mut curve = fm_curve(&spec, progress)?;
        if let Some((gains, kt)) = noise {
            curve_noise(&spec.base, &mut curve, &gains, kt)?;
        }
        Ok(curve)
    }
    fn report(&self, model: &Resolved, curve: &FmCurve) -> Result<Value, SimError> {
        Ok(document(self, model, curve))
    }
    fn present(
        &self,
        curve: &FmCurve,
        at: crate::request::Presenting<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        let mut document = at.document.clone();
        let table = table(at.model, curve);
        let mut shown = crate::report::present::fm::fm(&mut document, table, at.units, at.to);
        shown.document = Some(document);
        Ok(shown)
    }
    fn largest_indentation(&self, curve: &FmCurve) -> Option<f64> {
        let d = curve.points.iter().map(|q| q.observables.indentation);
        Some(d.filter(|d| d.is_finite()).fold(0.0, f64::max))
    }
}

/// The loops' gains of `request`'s bandwidth (its default: [`LoopSpec::new`]) and k_B T, with
/// a temperature (`None` without).
///
/// # Errors
/// [`SimError::OutOfRange`] naming `bandwidth` above the lever's (a gain π/Q_K per cycle) or
/// `temperature`; as `fm_reference`.
fn gains(
    request: &FmRequest,
    model: &Resolved,
    spec: &FmSpec,
) -> Result<Option<(LoopSpec, f64)>, SimError> {
    let needs = [("bandwidth", request.bandwidth)];
    let Some(kt) = crate::request::limits::optional_kt(request.temperature, &needs, model)? else {
        return Ok(None);
    };
    let r = fm_reference(&spec.base, spec.mode, spec.amplitude)?;
    let mut gains = LoopSpec::new(r.quality_factor);
    if let Some(b) = request.bandwidth {
        let f_k = r.omega * model.units(true).hz_per_omega.unwrap_or(1.0);
        let most = loop_bandwidth(MAX_LOOP_GAIN.min(PI / r.quality_factor), f_k);
        let why = format!(
            "must be at most {} Hz here, a gain of min(π/Q_K, 1) per cycle: a faster loop \
             outruns the lever",
            crate::error::number(most)
        );
        crate::error::within("bandwidth", b, ..=most, why)?;
        (gains.phase_gain, gains.amplitude_gain) = (loop_gain(b, f_k), loop_gain(b, f_k));
    }
    Ok(Some((gains, kt)))
}

/// What an FM point's columns ([`COLUMNS`]) are read through: the document's units, Hz per
/// unit Ω (1 without a probe), the free lever's operating point and the model (z_c from α5).
struct Frame {
    u: CurveUnits,
    hz: f64,
    reference: FmReference,
    base: crate::Params,
}

impl Frame {
    fn new(model: &Resolved, curve: &FmCurve) -> Frame {
        let u = model.units(true);
        Frame {
            u,
            hz: u.hz_per_omega.unwrap_or(1.0),
            reference: curve.reference,
            base: model.params,
        }
    }

    /// The rest distance at α5 = `a5` in the document's length unit.
    fn z_c(&self, a5: f64) -> f64 {
        self.base
            .with(crate::params::SweepParam::Alpha5, a5)
            .rest_distance()
            * self.u.length
    }
}

/// The columns of an FM curve, one entry per z_c reached: the document's `curve` arrays (and
/// the units its `units` names: those `true`), the layout's variables over `z_c` and the table
/// `fm.csv`, in this order.
const COLUMNS: [Column<Frame, FmPoint>; 18] = columns! {
    "z_c", Length, true, "rest distance z_c", F64(|f, q| f.z_c(q.alpha5));
    "frequency_shift", Own("Hz", "Ω (units of the τ scale)"), true,
        "frequency shift Δf = f − f_K", F64(|f, q| (q.omega - f.reference.omega) * f.hz);
    "frequency", Frequency, true, "drive frequency the PLL locks at", F64(|f, q| q.omega * f.hz);
    "excitation", Own("1 (relative to the free lever's at its resonance)", "1 (relative)"), true,
        "excitation relative to the free lever's at its resonance",
        F64(|f, q| q.alpha2 / f.reference.excitation);
    "amplitude", Length, true, "first-harmonic amplitude A1",
        F64(|f, q| q.observables.amplitude * f.u.length);
    "phase_deg", Fixed("deg"), false, "lag of the first harmonic behind the drive",
        F64(|_, q| q.observables.phase.to_degrees());
    "energy_dissipated", Energy, true, "energy dissipated in the sample per cycle",
        F64(|f, q| q.observables.energy_dissipated * f.u.energy);
    "virial", Energy, true, "virial ⟨F_c W⟩", F64(|f, q| q.observables.virial * f.u.energy);
    "mean_deflection", Length, false, "mean deflection",
        F64(|f, q| q.observables.mean_deflection * f.u.length);
    "min_distance", Length, true, "tip–sample distance at the lower turning point",
        F64(|f, q| q.observables.min_distance * f.u.length);
    "peak_force", Force, true, "largest tip–sample force",
        F64(|f, q| q.observables.peak_force * f.u.force);
    "mean_force", Force, false, "mean tip–sample force",
        F64(|f, q| q.observables.mean_force * f.u.force);
    "law_force", Force, false, "the law's conservative force at the lower turning point",
        F64(|f, q| q.law_force * f.u.force);
    "indentation", Length, false, "largest indentation",
        F64(|f, q| q.observables.indentation * f.u.length);
    "max_multiplier", Fixed("1"), false, "largest Floquet multiplier modulus under the locked drive",
        F64(|_, q| q.multipliers.first().map_or(f64::NAN, |m| m.norm()));
    "stable", Fixed(""), false, "Floquet-stable under the locked drive", Bool(|_, q| q.stable);
    "loop_residual", Fixed("1"), false, "loop residual max(|A1/A − 1|, |φ1 − φ_set|)",
        F64(|_, q| q.loop_residual);
    "iterations", Fixed("1"), false, "Newton iterations on (Ω, α2)", Count(|_, q| q.iterations);
};

/// The columns a curve with a temperature adds after [`COLUMNS`]: the loops' thermal noise
/// (`crate::analysis::fm::noise`).
const NOISE_COLUMNS: [Column<Frame, FmPoint>; 2] = columns! {
    "frequency_shift_noise", Own("Hz", "Ω (units of the τ scale)"), true,
        "thermal noise of the frequency shift (σ)", Opt(|f, q| Some(q.noise?.frequency * f.hz));
    "excitation_noise", Own("1 (relative to the free lever's at its resonance)", "1 (relative)"),
        true, "thermal noise of the excitation (σ)",
        Opt(|f, q| Some(q.noise?.excitation / f.reference.excitation));
};

/// The noise columns of `curve`: [`NOISE_COLUMNS`] with a temperature, none without.
fn noise_columns(curve: &FmCurve) -> &'static [Column<Frame, FmPoint>] {
    let noisy = curve.points.first().is_some_and(|q| q.noise.is_some());
    if noisy {
        &NOISE_COLUMNS
    } else {
        &[]
    }
}

/// The document of an FM curve (`afmdyn fm --json`, Python's `to_dict()`): `curve` (one array
/// per quantity of `COLUMNS`, one entry per z_c reached), `folds`, `reference` (the free
/// lever's operating point), the cantilever's constants that [`super::reconstruct`] needs
/// (`spring_constant`, `resonance_frequency`, `amplitude`), `units` (those of the columns it
/// lists, and with a probe the spring constant's), `method`, `warnings`.
pub(crate) fn document(request: &FmRequest, model: &Resolved, curve: &FmCurve) -> Value {
    let frame = Frame::new(model, curve);
    // the loops' gains and k_B T as the run had them (admitted: no error here)
    let noise = (request.spec(model))
        .and_then(|s| gains(request, model, &s))
        .ok()
        .flatten();
    let (u, hz, r) = (frame.u, frame.hz, &curve.reference);
    // the tracked mode's stiffness at the tip (the probe's calibrated k for mode 1)
    let spring_constant = r.stiffness * u.force / u.length;
    let names = UnitNames::si_or_model(frame.u.si);
    let mut units = columns::units(&COLUMNS, &names);
    units.extend(columns::units(noise_columns(curve), &names));
    if u.si {
        units.insert("spring_constant".into(), "N/m".into());
    }
    let mut arrays = columns::arrays(&COLUMNS, &frame, &curve.points);
    arrays.extend(columns::arrays(noise_columns(curve), &frame, &curve.points));
    json!({
        "curve": arrays,
        "folds": curve.folds.iter().map(|f| json!({"index": f.index, "z_c": frame.z_c(f.alpha5)})).collect::<Vec<_>>(),
        "reference": {
            "resonance_frequency": r.omega * hz,
            "quality_factor": r.quality_factor,
            "phase_deg": r.phase.to_degrees(),
            "excitation": r.excitation,
            "stiffness": spring_constant,
        },
        "mode": request.mode,
        "amplitude": curve.amplitude * u.length,
        "spring_constant": spring_constant,
        "resonance_frequency": r.omega * hz,
        "thermal": thermal(request, noise, model, curve),
        "units": units,
        "method": "ideal PLL (the first harmonic locked at the free lever's phase at its resonance) and ideal amplitude controller: exact periodic orbits by shooting, the drive frequency and excitation by Newton's method on the two loop conditions (docs/tutorials/fm.md)",
        "warnings": warnings(request, noise, model, (&frame, curve)),
    })
}

/// The `"thermal"` block of an FM curve with a temperature (`null` without): `temperature`
/// (K), the loops' `bandwidth` (Hz, [`loop_bandwidth`]) and `gain` per cycle, and the
/// `method`; σ of each point in the curve's [`NOISE_COLUMNS`].
fn thermal(
    request: &FmRequest,
    noise: Option<(LoopSpec, f64)>,
    model: &Resolved,
    curve: &FmCurve,
) -> Value {
    let (Some(t), Some((gains, _))) = (request.temperature, noise) else {
        return Value::Null;
    };
    let hz = model.units(true).hz_per_omega.unwrap_or(1.0);
    json!({
        "temperature": t,
        "bandwidth": loop_bandwidth(gains.phase_gain, curve.reference.omega * hz),
        "gain": gains.phase_gain,
        "columns": columns::names(&NOISE_COLUMNS),
        "method": "linear response of the closed loop (a PLL and an amplitude controller updated once per cycle from the first harmonic of 64 samples) about the FM orbit under the fluctuation-dissipation theorem's thermal force: the orbit's chain over a period, its switchings and the noise within it included, and the stationary covariance of the loop's state (docs/tutorials/thermal.md)",
    })
}

/// The warnings of an FM curve's document: an amplitude outside the probe's typical range, ends
/// given the wrong way round, a steady state not found; with `noise` (the loops' gains and
/// k_B T), the temperature's, points too near grazing for the linear response, an unstable loop.
fn warnings(
    request: &FmRequest,
    noise: Option<(LoopSpec, f64)>,
    model: &Resolved,
    (frame, curve): (&Frame, &FmCurve),
) -> Vec<String> {
    let mut warnings: Vec<String> = Vec::new();
    let unit = if model.probe.is_some() { "m" } else { "g0" };
    if let (Some(a), Some(_)) = (request.amplitude, &model.probe) {
        // the amplitude's typical range is the probe's ([`crate::probe::ranges`])
        warnings.extend(crate::probe::ranges::warn(
            "amplitude",
            ("drive", "free_amplitude"),
            a,
        ));
    }
    if let (Some(from), Some(to)) = (request.from, request.to) {
        if from < to {
            warnings.push(warning!(
                "fm.reversed",
                "Give from > to: an FM curve is taken approaching.",
                "from = {} {unit} is nearer the sample than to = {} {unit}: an FM curve is \
                 taken approaching, so it runs from z_c = {} {unit} down to {} {unit} (give \
                 from > to to say so)",
                crate::error::number(from),
                crate::error::number(to),
                crate::error::number(to),
                crate::error::number(from),
            ));
        }
    }
    if let (Some(t), Some((_, kt))) = (request.temperature, noise) {
        warnings.extend(crate::request::limits::temperature_warnings(t));
        let lowest = curve.points.iter().map(|q| &q.observables);
        if let Ok(near @ 1..) = grazing(&model.params, kt, lowest) {
            warnings.push(warning!(
                "fm.noise-grazing",
                "Read their frequency_shift_noise as an estimate only.",
                "{near} point(s) pass within {NOISE_GRAZING} thermal standard deviations \
                 √(k_BT/k) of the surface, above or inside it, where the noise adds or removes \
                 contacts from cycle to cycle: their loop noise is beyond the linear response"
            ));
        }
        if curve
            .points
            .iter()
            .any(|q| q.noise.is_some_and(|n| n.frequency.is_nan()))
        {
            warnings.push(warning!(
                "fm.noise-unstable",
                "Give a smaller bandwidth.",
                "the closed loop is unstable at some z_c: their frequency_shift_noise is null \
                 (no stationary noise at this bandwidth)"
            ));
        }
    }
    if let Some(u) = &curve.unreached {
        warnings.push(warning!(
            "fm.unreached",
            "Read the reason given; end the range before that z_c (to), or change the \
             amplitude.",
            "the FM steady state was not found at z_c = {}{} and beyond ({}); the curve ends at \
             the previous value",
            crate::error::number(frame.z_c(u.alpha5)),
            if model.probe.is_some() { " m" } else { " g0" },
            u.reason
        ));
    }
    warnings
}

/// The layout of an FM curve: over `z_c` (the rest distance, its coordinate) every column of
/// `COLUMNS`, in the document's units (SI with a probe, the model's without; `deg` for the
/// phase, `1` for the pure numbers); `stable` flags, `iterations` integers. What Python's
/// `afmdyn.fm` returns.
pub(crate) fn layout(model: &Resolved, curve: &FmCurve) -> crate::layout::Layout {
    let frame = Frame::new(model, curve);
    let p = &curve.points;
    let names = UnitNames::si_or_model(frame.u.si);
    let mut variables = columns::variables(&COLUMNS, &frame, p, &["z_c"], &names);
    let noise = noise_columns(curve);
    variables.extend(columns::variables(noise, &frame, p, &["z_c"], &names));
    crate::layout::Layout::new("fm", &[("z_c", p.len())], variables)
}

/// The table of an FM curve (`fm.csv`): the names of `COLUMNS` and one row per z_c reached
/// (`stable` as 1/0).
pub(crate) fn table(model: &Resolved, curve: &FmCurve) -> (Vec<&'static str>, Vec<Vec<f64>>) {
    let frame = Frame::new(model, curve);
    let mut rows = columns::rows(&COLUMNS, &frame, &curve.points);
    let noise = noise_columns(curve);
    for (r, n) in rows
        .iter_mut()
        .zip(columns::rows(noise, &frame, &curve.points))
    {
        r.extend(n);
    }
    let mut names = columns::names(&COLUMNS);
    names.extend(columns::names(noise));
    (names, rows)
}

impl Datasets for FmRequest {
    /// The curve's layout `fm` (`layout`).
    fn datasets(&self, model: &Resolved, curve: &Self::Output) -> Result<Arrays, SimError> {
        Ok((
            vec![("fm".into(), layout(model, curve))],
            serde_json::Map::new(),
        ))
    }
}
