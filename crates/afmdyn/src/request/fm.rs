//! `fm`: the frequency-modulation (FM-AFM) curve at constant amplitude over the rest distance
//! z_c ([`crate::analysis::fm`]: ideal PLL and amplitude controller, exact periodic orbits) —
//! the request the command line (`afmdyn fm`) and Python (`afmdyn.fm`) share, and its
//! document. With a probe everything is SI (z_c and A in m, Δf in Hz, E_dis in J, forces in N);
//! without one the model's units (g₀, Ω, F̃).

use super::costs::{newton_work, state_bytes, MODEL_BYTES};
use super::curves::CurveRequest;
use super::limits::Cost;
use super::run::{Analysis, Resolved};
use crate::analysis::approach::approach_spec;
use crate::analysis::fm::{fm_curve, FmCurve, FmSpec, DEFAULT_LOOP_TOLERANCE};
use crate::analysis::fm::{MAX_HALVINGS, MAX_LOOP_ITERATIONS};
use crate::analysis::progress::Progress;
use crate::error::SimError;
use crate::report::CurveUnits;
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};

/// `fm`: an FM curve from `from` to `to` (z_c; m with a probe, else g₀) at the oscillation
/// amplitude `amplitude`, tracking mode `mode`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(schemars::JsonSchema))]
#[serde(default, deny_unknown_fields)]
pub struct FmRequest {
    /// The first-harmonic amplitude A the amplitude controller holds (m with a probe, else g₀),
    /// > 0; default the probe's free amplitude A₀ (1 g₀).
    #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
    pub amplitude: Option<f64>,
    /// The mode K (1-based) the PLL tracks; default 1.
    pub mode: usize,
    /// First z_c of the approach (default: where the frequency shift has decayed to 0.5 % of
    /// its value at `to` ([`crate::request::fm::default_from`]); 2A + a₀, the lower turning point at A, for the
    /// laws without a force before contact).
    #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
    pub from: Option<f64>,
    /// Last z_c (default A + a₀: the lower turning point at the contact distance a₀, 0 for
    /// the laws without attraction).
    #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
    pub to: Option<f64>,
    /// Step of z_c; excludes `points`.
    #[cfg_attr(feature = "schema", schemars(extend("x-dim" = "length")))]
    pub step: Option<f64>,
    /// Number of z_c values, ends included, 2..=[`crate::analysis::stepped::MAX_CURVE_POINTS`]
    /// (default [`crate::analysis::stepped::DEFAULT_CURVE_POINTS`]).
    #[cfg_attr(
        feature = "schema",
        schemars(extend("x-constants" = {
            "MAX_CURVE_POINTS": crate::analysis::stepped::MAX_CURVE_POINTS,
            "DEFAULT_CURVE_POINTS": crate::analysis::stepped::DEFAULT_CURVE_POINTS
        }))
    )]
    pub points: Option<usize>,
    /// Tolerance of the loop conditions, |A₁/A − 1| and |φ₁ − φ_set| (rad), in (0, 1e-3).
    pub tolerance: f64,
}

impl Default for FmRequest {
    fn default() -> Self {
        FmRequest {
            amplitude: None,
            mode: 1,
            from: None,
            to: None,
            step: None,
            points: None,
            tolerance: DEFAULT_LOOP_TOLERANCE,
        }
    }
}

/// The FM amplitude's range in the model's length unit (g₀ = A₀ of a probe): outside it the
/// request is refused, naming `amplitude`.
pub(crate) const FM_AMPLITUDE_RANGE: (f64, f64) = (1e-8, 1e4);

/// The share of the frequency shift at the curve's end (`to`) below which the default FM curve
/// starts: the range runs from where |Δf| has decayed to it down to contact, which is also the
/// range a Sader–Jarvis reconstruction needs (its integrals run to where the shift vanishes).
/// Half of `reconstruct`'s truncation threshold ([`super::reconstruct::DECAYED`]): the
/// default range comes from an estimate of the shift (the cycle mean of [`default_from`]),
/// and the computed curve's first point sits a little above it (1.0033 % where the two were
/// equal), so a default `fm` curve handed to `reconstruct` must start with a margin below
/// the threshold, not on it.
pub const FM_DEFAULT_DECAY: f64 = super::reconstruct::DECAYED / 2.0;

/// The default first z_c of an FM curve at amplitude `a` ending at `to` (units of g₀): the
/// largest z_c whose estimated frequency shift is still [`FM_DEFAULT_DECAY`] of its value at
/// `to` (by bisection to round-off), from Giessibl's first-order shift, which is
/// proportional to the cosine-weighted mean force over a cycle,
/// Δf ∝ −⟨F(z_c + A cos θ) cos θ⟩_θ (Giessibl, *Phys. Rev. B* 56, 16010 (1997), eq. 11;
/// `crate::analysis::fm::law_force` the law's conservative force at distance d, the mean by
/// the midpoint rule over enough phases to resolve the closest approach, 40 across its
/// width √(2 d_min/A)). `None` when the law has no force before contact (the
/// shift at `to` is 0) or it does not decay within 10⁶ g₀.
pub fn default_from(base: &crate::Params, a: f64, to: f64) -> Option<f64> {
    // the integrand peaks at the closest distance d_min = to − A within |θ − π| ≈ √(2 d_min/A):
    // 40 phases across that width (at least 1024, at most 2²⁰ over the cycle)
    let d_min = (to - a)
        .max(base.contact_law.distance_offset())
        .max(1e-9 * a);
    let width = (2.0 * d_min / a).sqrt().min(1.0);
    let phases = ((40.0 * std::f64::consts::TAU / width).ceil() as usize).clamp(1024, 1 << 20);
    let shift = |z: f64| {
        (0..phases)
            .map(|k| {
                let theta = std::f64::consts::TAU * (k as f64 + 0.5) / phases as f64;
                crate::analysis::fm::law_force(base, z + a * theta.cos()) * theta.cos()
            })
            .sum::<f64>()
            / phases as f64
    };
    let target = FM_DEFAULT_DECAY * shift(to).abs();
    if !(target > 0.0 && target.is_finite()) {
        return None;
    }
    // out from `to` by doubling steps until the shift is below the target, then bisect
    let (mut lo, mut step) = (to, 1e-3 * a.max(1e-6));
    while shift(to + step).abs() > target {
        lo = to + step;
        step *= 2.0;
        if step > 1e6 {
            return None;
        }
    }
    let mut hi = to + step;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if shift(mid).abs() > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(hi)
}

impl FmRequest {
    /// The units of the document: SI with a probe (frequencies in Hz), else the model's.
    pub(crate) fn units(model: &Resolved) -> CurveUnits {
        match &model.probe {
            Some(p) => CurveUnits::from_scales(&p.scales, true),
            None => CurveUnits::dimensionless(),
        }
    }

    /// The analysis' spec on `model`: the z_c grid (α5 values, from the far end), the amplitude
    /// in g₀, the mode and the tolerance.
    ///
    /// # Errors
    /// [`SimError::OutOfRange`] naming `amplitude`, `mode`, `tolerance`, `from`, `to`, `step`
    /// or `points` (as an approach curve's); [`SimError::Params`] for a model invalid at an
    /// end of the grid.
    pub fn spec(&self, model: &Resolved) -> Result<FmSpec, SimError> {
        let length = Self::units(model).length;
        let range = CurveRequest {
            from: self.from,
            to: self.to,
            step: self.step,
            points: self.points,
            ..CurveRequest::default()
        };
        range.check_finite()?;
        if let Some(a) = self.amplitude {
            crate::error::finite("amplitude", a)?;
            if a <= 0.0 {
                return Err(SimError::out_of_range(
                    "amplitude",
                    a,
                    "must be > 0: the oscillation amplitude the controller holds",
                ));
            }
            if length != 1.0 {
                // an amplitude's range is the probe's amplitude's ([`crate::probe::ranges`]),
                // not a rest distance's
                if let Some(why) = crate::probe::ranges::refusal("drive", "free_amplitude", a) {
                    return Err(SimError::out_of_range(
                        "amplitude",
                        format!("{} m", crate::error::number(a)),
                        why,
                    ));
                }
            }
            // the model's lengths are in units of its A₀ (g₀): an amplitude 1e8 times smaller
            // or 1e4 times larger leaves nothing of the other length scales
            if !(FM_AMPLITUDE_RANGE.0..=FM_AMPLITUDE_RANGE.1).contains(&(a / length)) {
                return Err(SimError::out_of_range(
                    "amplitude",
                    a,
                    "must be within [1e-8, 1e4] × the model's length unit (A₀ of a probe's \
                     [drive] free_amplitude): amplitudes are in m with a probe (100 pm is \
                     100e-12, or 100pm on the command line)",
                ));
            }
        }
        if length != 1.0 {
            for (name, v) in [("from", self.from), ("to", self.to), ("step", self.step)] {
                if let Some(v) = v {
                    super::limits::si_distance(name, v)?;
                }
            }
        }
        let base = model.params;
        if self.mode == 0 || self.mode > base.modes {
            return Err(SimError::out_of_range(
                "mode",
                self.mode,
                "must be in 1..=N, the number of modes of the model (1 for the point mass)",
            ));
        }
        let tol = self.tolerance;
        super::limits::tolerance("tolerance", tol)?;
        let a = self.amplitude.map_or(1.0, |a| a / length);
        let offset = base.contact_law.distance_offset();
        let to = range.to.map_or(a + offset, |t| t / length);
        let from = match range.from {
            Some(f) => f / length,
            None => default_from(&base, a, to).unwrap_or(2.0 * a + offset),
        };
        let values = approach_spec(base, from, to, range.spacing(length)?)
            .map_err(|e| super::curves::in_units(e, length))?
            .values;
        for v in [values[0], values[values.len() - 1]] {
            base.with(crate::params::SweepParam::Alpha5, v).validate()?;
        }
        let mut spec = FmSpec::new(base, values, a);
        spec.mode = self.mode;
        spec.tolerance = tol;
        Ok(spec)
    }
}

impl Analysis for FmRequest {
    type Output = FmCurve;
    fn validate(&self, model: &Resolved) -> Result<(), SimError> {
        super::curves::check_single_frequency(&model.params, "fm")?;
        self.spec(model).map(|_| ())
    }
    fn execute(&self, model: &Resolved, progress: &Progress) -> Result<FmCurve, SimError> {
        super::curves::check_single_frequency(&model.params, "fm")?;
        fm_curve(&self.spec(model)?, progress)
    }
    fn name(&self) -> &'static str {
        "fm"
    }
    fn cost(&self, model: &Resolved) -> Result<Cost, SimError> {
        // every z_c: up to MAX_LOOP_ITERATIONS × MAX_HALVINGS steps of the phase loop, each a
        // Newton solve of the period-1 orbit; a point's orbit and observables kept
        let spec = self.spec(model)?;
        let p = &spec.base;
        let points = spec.values.len() as f64;
        let steps = (MAX_LOOP_ITERATIONS * MAX_HALVINGS) as f64;
        Ok(Cost {
            bytes: MODEL_BYTES + points * (4.0 * state_bytes(p) + 512.0),
            work: points * steps * newton_work(p, 1, &spec.newton),
        })
    }
    fn report(&self, model: &Resolved, curve: &FmCurve) -> Result<Value, SimError> {
        Ok(document(self, model, curve))
    }
    fn present(
        &self,
        _: &Resolved,
        _: &FmCurve,
        document: &Value,
        units: crate::report::TextUnits,
        to: super::run::Destination<'_>,
    ) -> Result<crate::report::Presentation, SimError> {
        let mut document = document.clone();
        let mut shown = super::present::fm::fm(&mut document, units, to.files, to.dir);
        shown.document = Some(document);
        Ok(shown)
    }
    fn largest_indentation(&self, curve: &FmCurve) -> Option<f64> {
        let d = curve.points.iter().map(|q| q.observables.indentation);
        Some(d.filter(|d| d.is_finite()).fold(0.0, f64::max))
    }
}

/// The document of an FM curve (`afmdyn fm --json`, Python's `to_dict()`): `curve` (one array
/// per quantity, one entry per z_c reached), `folds`, `reference` (the free lever's operating
/// point), the cantilever's constants that [`super::reconstruct`] needs (`spring_constant`,
/// `resonance_frequency`, `amplitude`), `units`, `method`, `warnings`.
pub(crate) fn document(request: &FmRequest, model: &Resolved, curve: &FmCurve) -> Value {
    let u = FmRequest::units(model);
    let hz = u.hz_per_omega.unwrap_or(1.0);
    let p = &curve.points;
    let col = |f: &dyn Fn(&crate::analysis::fm::FmPoint) -> f64| -> Vec<f64> {
        p.iter().map(f).collect()
    };
    let base = model.params;
    let z_c = |a5: f64| {
        base.with(crate::params::SweepParam::Alpha5, a5)
            .rest_distance()
    };
    let u_len = u.length;
    let r = &curve.reference;
    let max_mult =
        |q: &crate::analysis::fm::FmPoint| q.multipliers.first().map_or(f64::NAN, |m| m.norm());
    // the tracked mode's stiffness at the tip (the probe's calibrated k for mode 1)
    let spring_constant = r.stiffness * u.force / u.length;
    let mut warnings: Vec<String> = Vec::new();
    let unit = if model.probe.is_some() { "m" } else { "g0" };
    if let (Some(a), Some(_)) = (request.amplitude, &model.probe) {
        // the amplitude's typical range is the probe's ([`crate::probe::ranges`])
        if let Some(why) = crate::probe::ranges::warning("drive", "free_amplitude", a) {
            warnings.push(format!(
                "amplitude = {} m is {why}",
                crate::error::number(a)
            ));
        }
    }
    if let (Some(from), Some(to)) = (request.from, request.to) {
        if from < to {
            warnings.push(format!(
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
    if let Some(u) = &curve.unreached {
        warnings.push(format!(
            "the FM steady state was not found at z_c = {}{} and beyond ({}); the curve ends at \
             the previous value",
            crate::error::number(z_c(u.alpha5) * u_len),
            if model.probe.is_some() { " m" } else { " g0" },
            u.reason
        ));
    }
    json!({
        "curve": {
            "z_c": col(&|q| z_c(q.alpha5) * u.length),
            "frequency_shift": col(&|q| (q.omega - r.omega) * hz),
            "frequency": col(&|q| q.omega * hz),
            "excitation": col(&|q| q.alpha2 / r.excitation),
            "amplitude": col(&|q| q.observables.amplitude * u.length),
            "phase_deg": col(&|q| q.observables.phase.to_degrees()),
            "energy_dissipated": col(&|q| q.observables.energy_dissipated * u.energy),
            "virial": col(&|q| q.observables.virial * u.energy),
            "mean_deflection": col(&|q| q.observables.mean_deflection * u.length),
            "min_distance": col(&|q| q.observables.min_distance * u.length),
            "peak_force": col(&|q| q.observables.peak_force * u.force),
            "mean_force": col(&|q| q.observables.mean_force * u.force),
            "law_force": col(&|q| q.law_force * u.force),
            "indentation": col(&|q| q.observables.indentation * u.length),
            "max_multiplier": col(&max_mult),
            "stable": p.iter().map(|q| q.stable).collect::<Vec<bool>>(),
            "loop_residual": col(&|q| q.loop_residual),
            "iterations": p.iter().map(|q| q.iterations).collect::<Vec<usize>>(),
        },
        "folds": curve.folds.iter().map(|f| json!({"index": f.index, "z_c": z_c(f.alpha5) * u.length})).collect::<Vec<_>>(),
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
        "units": if u.si {
            json!({"z_c": "m", "frequency_shift": "Hz", "frequency": "Hz", "excitation": "1 (relative to the free lever's at its resonance)",
                   "amplitude": "m", "energy_dissipated": "J", "virial": "J", "min_distance": "m", "peak_force": "N", "spring_constant": "N/m"})
        } else {
            json!({"z_c": "g0", "frequency_shift": "Ω (units of the τ scale)", "frequency": "Ω", "excitation": "1 (relative)",
                   "amplitude": "g0", "energy_dissipated": "F·g0", "virial": "F·g0", "min_distance": "g0", "peak_force": "F"})
        },
        "method": "ideal PLL (the first harmonic locked at the free lever's phase at its resonance) and ideal amplitude controller: exact periodic orbits by shooting, the drive frequency and excitation by Newton's method on the two loop conditions (docs/afm-workflow.md)",
        "warnings": warnings,
    })
}

/// Where a variable of the FM layout takes its unit: the document's `units` under a key, or
/// a unit of its own.
#[derive(Debug, Clone, Copy)]
enum Unit {
    /// `units[key]` of the document ([`document`]): its length, frequency, force, energy.
    Of(&'static str),
    /// A unit the document does not name (`1` a pure number, `""` a flag).
    Is(&'static str),
}

/// The variables of an FM curve's layout ([`layout`]) after `z_c`, in the table's order
/// (`fm.csv`, [`super::present::fm::COLUMNS`]): name, unit, long name.
const FM_VARIABLES: [(&str, Unit, &str); 17] = [
    (
        "frequency_shift",
        Unit::Of("frequency_shift"),
        "frequency shift Δf = f − f_K",
    ),
    (
        "frequency",
        Unit::Of("frequency"),
        "drive frequency the PLL locks at",
    ),
    (
        "excitation",
        Unit::Of("excitation"),
        "excitation relative to the free lever's at its resonance",
    ),
    (
        "amplitude",
        Unit::Of("amplitude"),
        "first-harmonic amplitude A1",
    ),
    (
        "phase_deg",
        Unit::Is("deg"),
        "lag of the first harmonic behind the drive",
    ),
    (
        "energy_dissipated",
        Unit::Of("energy_dissipated"),
        "energy dissipated in the sample per cycle",
    ),
    ("virial", Unit::Of("virial"), "virial ⟨F_c W⟩"),
    ("mean_deflection", Unit::Of("z_c"), "mean deflection"),
    (
        "min_distance",
        Unit::Of("min_distance"),
        "tip–sample distance at the lower turning point",
    ),
    (
        "peak_force",
        Unit::Of("peak_force"),
        "largest tip–sample force",
    ),
    (
        "mean_force",
        Unit::Of("peak_force"),
        "mean tip–sample force",
    ),
    (
        "law_force",
        Unit::Of("peak_force"),
        "the law's conservative force at the lower turning point",
    ),
    ("indentation", Unit::Of("z_c"), "largest indentation"),
    (
        "max_multiplier",
        Unit::Is("1"),
        "largest Floquet multiplier modulus under the locked drive",
    ),
    (
        "stable",
        Unit::Is(""),
        "Floquet-stable under the locked drive",
    ),
    (
        "loop_residual",
        Unit::Is("1"),
        "loop residual max(|A1/A − 1|, |φ1 − φ_set|)",
    ),
    ("iterations", Unit::Is("1"), "Newton iterations on (Ω, α2)"),
];

/// The layout of an FM curve's document `doc` ([`document`]): over `z_c` (the rest distance,
/// its coordinate) every array of its `curve`, in the document's units (SI with a probe, the
/// model's without: `units`; `deg` for the phase, `1` for the pure numbers, the length's and
/// force's units for the mean deflection and indentation, and for the mean and law forces);
/// `stable` flags, `iterations` integers, `null` as NaN. What Python's `afmdyn.fm` returns.
pub(crate) fn layout(doc: &Value) -> crate::layout::Layout {
    use crate::layout::{Layout, Values, Variable};
    let curve = &doc["curve"];
    let list = |name: &str| curve[name].as_array().cloned().unwrap_or_default();
    let numbers = |name: &str| -> Vec<f64> {
        let v = list(name);
        v.iter().map(|x| x.as_f64().unwrap_or(f64::NAN)).collect()
    };
    let unit = |u: Unit| match u {
        Unit::Of(key) => doc["units"][key].as_str().unwrap_or_default().to_string(),
        Unit::Is(u) => u.to_string(),
    };
    let z_c = numbers("z_c");
    let mut variables = vec![Variable::f64(
        "z_c",
        &["z_c"],
        &unit(Unit::Of("z_c")),
        "rest distance z_c",
        &z_c,
    )];
    for (name, u, long_name) in FM_VARIABLES {
        let values = match name {
            "stable" => Values::Bool(
                list(name)
                    .iter()
                    .map(|x| x.as_bool() == Some(true))
                    .collect(),
            ),
            "iterations" => Values::I32(
                list(name)
                    .iter()
                    .map(|x| x.as_i64().map_or(-1, |i| i as i32))
                    .collect(),
            ),
            _ => Values::F64(numbers(name)),
        };
        variables.push(Variable::new(name, &["z_c"], &unit(u), long_name, values));
    }
    Layout::new("fm", &[("z_c", z_c.len())], variables)
}
