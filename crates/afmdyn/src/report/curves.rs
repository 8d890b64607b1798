//! The documents of the stepped curves (`approach`, `resonance`, the setpoint, `observe`'s
//! reported block): the [`CURVE_COLUMNS`] of each point in its [`CurveUnits`].

use super::*;
use crate::analysis::lock_in_noise::LockInNoise;

/// The [`CURVE_COLUMNS`] of one orbit's observables in `u`'s units: A, A/A₀ (A₀ the free
/// amplitude at the same drive), φ in degrees, ⟨W⟩, max F_c, min F_c, indentation, contact
/// fraction, min distance, E_dis, virial, THD, the higher modes' participation
/// √(Σ_{k≥2} A_k²)/A_1 from [`Observables::mode_amplitudes`].
pub(crate) fn curve_row(o: &Observables, u: &CurveUnits) -> [f64; 13] {
    [
        o.amplitude * u.length,
        o.amplitude / o.closed_form.free_amplitude,
        o.phase.to_degrees(),
        o.mean_deflection * u.length,
        o.peak_force * u.force,
        o.min_force * u.force,
        o.indentation * u.length,
        o.contact_fraction,
        o.min_distance * u.length,
        o.energy_dissipated * u.energy,
        o.virial * u.energy,
        o.thd,
        higher_mode_fraction(&o.mode_amplitudes),
    ]
}

/// √(Σ_{k≥2} A_k²)/A_1 of the eigenmodes' amplitudes A_k (0 for one mode; NaN without any).
pub(crate) fn higher_mode_fraction(amplitudes: &[f64]) -> f64 {
    match amplitudes.split_first() {
        Some((a1, rest)) => rest.iter().fold(0.0, |s, a| s + a * a).sqrt() / a1,
        None => f64::NAN,
    }
}

/// The observables of one steady state in `u`'s units — SI for a probe's model (m, N, J, s),
/// the model's own otherwise (g₀, F̃, F̃·g₀, τ) — with phases in degrees: the [`CURVE_COLUMNS`]
/// (as [`curve_row`]), then `contact_time`, `mean_force`, `impacts_per_period`, `impact_loss`,
/// `mode_amplitudes` (per eigenmode, [`Observables::mode_amplitudes`]), `harmonics` (arrays `n`, `amplitude`, `phase_deg`), `mode_balance` (arrays `mode`, `drive`,
/// `beam_damping`, `sample`, `coupling`, `energy_change`, `residual`; energies per drive period)
/// `units` (the names) and, under a multifrequency drive, `components` (arrays over the drive
/// components, the first first: `ratio`, `amplitude`, `phase_deg`, `free_amplitude`,
/// `free_phase_deg`, `virial`, `energy_dissipated` per cycle of the component, their closed
/// forms `closed_virial`, `closed_energy_dissipated`, and the `mode` those use (0-based, as
/// `mode_balance`);
/// [`crate::analysis::observables::ComponentObservables`]). The `"reported"` block of
/// `observe`'s document, which Python's dataset is built from.
pub(crate) fn observed(o: &Observables, u: &CurveUnits) -> Value {
    let mut m = serde_json::Map::new();
    for (c, v) in CURVE_COLUMNS.iter().zip(curve_row(o, u)) {
        m.insert(c.name.into(), json!(v));
    }
    m.insert("contact_time".into(), json!(o.contact_time * u.time));
    m.insert("mean_force".into(), json!(o.mean_force * u.force));
    m.insert("impacts_per_period".into(), json!(o.impacts_per_period));
    m.insert("impact_loss".into(), json!(o.impact_loss * u.energy));
    m.insert(
        "mode_amplitudes".into(),
        json!(o
            .mode_amplitudes
            .iter()
            .map(|a| a * u.length)
            .collect::<Vec<_>>()),
    );
    let h = &o.harmonics;
    m.insert(
        "harmonics".into(),
        json!({
            "n": h.iter().map(|h| h.n).collect::<Vec<_>>(),
            "amplitude": h.iter().map(|h| h.amplitude * u.length).collect::<Vec<_>>(),
            "phase_deg": h.iter().map(|h| h.phase.to_degrees()).collect::<Vec<_>>(),
        }),
    );
    let b = &o.mode_balance;
    let energies =
        |f: fn(&ModeBalance) -> f64| -> Vec<f64> { b.iter().map(|x| f(x) * u.energy).collect() };
    m.insert(
        "mode_balance".into(),
        json!({
            "mode": b.iter().map(|x| x.mode).collect::<Vec<_>>(),
            "drive": energies(|x| x.drive),
            "beam_damping": energies(|x| x.beam_damping),
            "sample": energies(|x| x.sample),
            "coupling": energies(|x| x.coupling),
            "energy_change": energies(|x| x.energy_change),
            "residual": energies(|x| x.residual),
        }),
    );
    if !o.components.is_empty() {
        let c = &o.components;
        let list =
            |f: &dyn Fn(&ComponentObservables) -> f64| -> Vec<f64> { c.iter().map(f).collect() };
        m.insert(
            "components".into(),
            json!({
                "ratio": list(&|x| x.ratio),
                "amplitude": list(&|x| x.amplitude * u.length),
                "phase_deg": list(&|x| x.phase.to_degrees()),
                "free_amplitude": list(&|x| x.free_amplitude * u.length),
                "free_phase_deg": list(&|x| x.free_phase.to_degrees()),
                "virial": list(&|x| x.virial * u.energy),
                "energy_dissipated": list(&|x| x.energy_dissipated * u.energy),
                "closed_virial": list(&|x| x.closed_virial * u.energy),
                "closed_energy_dissipated": list(&|x| x.closed_energy_dissipated * u.energy),
                "mode": c.iter().map(|x| x.mode).collect::<Vec<_>>(),
            }),
        );
    }
    let mut units = u.names();
    units["time"] = json!(if u.si { "s" } else { "τ" });
    m.insert("units".into(), units);
    Value::Object(m)
}

/// The abscissa of a stepped curve: (key, value of the swept parameter → reported value).
type Abscissa<'a> = (&'static str, &'a dyn Fn(f64) -> f64);

fn columns<'a>(
    x: &Abscissa<'_>,
    rows: impl Iterator<Item = (f64, &'a Observables, bool)>,
    u: &CurveUnits,
) -> serde_json::Map<String, Value> {
    let mut xs = Vec::new();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); CURVE_COLUMNS.len()];
    // the per-component columns of a multifrequency drive (as many on every point)
    let mut comp: Vec<Vec<f64>> = Vec::new();
    let mut stable = Vec::new();
    for (v, o, s) in rows {
        xs.push((x.1)(v));
        for (c, val) in cols.iter_mut().zip(curve_row(o, u)) {
            c.push(val);
        }
        let row = component_row(o, u);
        comp.resize(row.len().max(comp.len()), Vec::new());
        for (c, val) in comp.iter_mut().zip(row) {
            c.push(val);
        }
        stable.push(s);
    }
    let mut m = serde_json::Map::new();
    m.insert(x.0.into(), json!(xs));
    for (col, c) in CURVE_COLUMNS.iter().zip(cols) {
        m.insert(col.name.into(), json!(c));
    }
    for ((name, _, _), c) in component_columns(comp.len() / 4).into_iter().zip(comp) {
        m.insert(name, json!(c));
    }
    m.insert("stable".into(), json!(stable));
    m
}

fn sweep_doc(
    x: &Abscissa<'_>,
    points: &[CurvePoint],
    noise: Option<&[LockInNoise]>,
    u: &CurveUnits,
) -> Value {
    let mut m = columns(
        x,
        points.iter().map(|p| (p.value, &p.observables, p.stable)),
        u,
    );
    if let Some(n) = noise {
        // the first component's σ_A, σ_φ, then each further component's
        let count = points.first().map_or(1, |p| p.observables.components.len());
        let rows: Vec<_> = n.iter().map(|s| noise_row(Some(s), count, u)).collect();
        for (k, (name, _)) in rows.first().into_iter().flatten().enumerate() {
            m.insert(
                name.clone(),
                json!(rows.iter().map(|r| r[k].1).collect::<Vec<_>>()),
            );
        }
    }
    m.insert(
        "period".into(),
        json!(points.iter().map(|p| p.period).collect::<Vec<_>>()),
    );
    m.insert(
        "reached".into(),
        json!(points.iter().map(|p| p.reached).collect::<Vec<_>>()),
    );
    Value::Object(m)
}

fn curve_doc(
    params: &Params,
    c: &SteppedCurve,
    x: Abscissa<'_>,
    names: (&str, &str),
    u: &CurveUnits,
) -> Value {
    let branches: Vec<Value> = c
        .branches
        .iter()
        .map(|b| {
            let mut m = columns(
                &x,
                b.iter()
                    .map(|s| (s.point.value, &s.observables, s.point.stable)),
                u,
            );
            m.insert(
                "period".into(),
                json!(b.iter().map(|s| s.point.period).collect::<Vec<_>>()),
            );
            m.insert(
                "event".into(),
                json!(b.iter().map(|s| s.point.event).collect::<Vec<_>>()),
            );
            Value::Object(m)
        })
        .collect();
    let sweep_name = |s: Sweep| match s {
        Sweep::First => names.0,
        Sweep::Second => names.1,
    };
    let jumps: Vec<Value> = c
        .jumps
        .iter()
        .map(|j| {
            json!({
                "sweep": sweep_name(j.sweep),
                "from": (x.1)(j.from),
                "to": (x.1)(j.to),
                "fold": j.fold.map(|f| (x.1)(f)),
            })
        })
        .collect();
    let free = c
        .first
        .first()
        .map(|p| p.observables.closed_form.free_amplitude * u.length);
    let traces = c.traces.as_ref().map(|t| {
        let n = t.time.len().max(1);
        let rows = |v: &[f64], scale: f64| -> Vec<Vec<f64>> {
            v.chunks(n)
                .map(|r| r.iter().map(|x| x * scale).collect())
                .collect()
        };
        json!({
            "sweep": names.0,
            "periods": t.periods,
            "samples_per_period": t.samples_per_period,
            x.0: t.values.iter().map(|&v| (x.1)(v)).collect::<Vec<_>>(),
            "time_periods": t.time,
            "deflection": rows(&t.deflection, u.length),
            "distance": rows(&t.distance, u.length),
            "force": rows(&t.force, u.force),
        })
    });
    let mut doc = json!({
        "params": params,
        "units": u.names(),
        "scales": {"length": u.length, "force": u.force, "energy": u.energy, "time": u.time,
                   "hz_per_omega": u.hz_per_omega},
        names.0: sweep_doc(&x, &c.first, c.noise.as_ref().map(|n| &n[0][..]), u),
        names.1: sweep_doc(&x, &c.second, c.noise.as_ref().map(|n| &n[1][..]), u),
        "branches": branches,
        "folds": c.folds.iter().map(|&f| (x.1)(f)).collect::<Vec<_>>(),
        "bistable": c.bistable.iter().map(|&(a, b)| {
            let (p, q) = ((x.1)(a), (x.1)(b));
            [p.min(q), p.max(q)]
        }).collect::<Vec<_>>(),
        "jumps": jumps,
        "free_amplitude": free,
        "warnings": c.warnings,
        "traces": traces,
    });
    if let Some(d) = drive_components(params, c, u) {
        doc["drive_components"] = d;
    }
    if let Some(a) = &c.average {
        doc["time_average"] = time_average(a, names, c, u);
    }
    if c.first
        .iter()
        .chain(&c.second)
        .any(|p| p.circle.is_some() || p.fallback.is_some())
    {
        doc["invariant_circle"] = invariant_circle(names, c);
    }
    doc
}

/// The `"invariant_circle"` block of a curve measured on invariant circles
/// ([`crate::analysis::stepped::torus`]): per sweep and point the circle's nodes (0 for the
/// exact orbit), the contraction of its linearisation per drive period (null for the exact
/// orbit), and why a point is the exact orbit instead (`not-found`, `not-smooth`, `unstable`,
/// `jump`, `skipped`; null on the circle).
fn invariant_circle(names: (&str, &str), c: &SteppedCurve) -> Value {
    // the circle of a point measured on it
    fn on(p: &CurvePoint) -> Option<&crate::analysis::stepped::torus::CirclePoint> {
        p.circle.as_ref().filter(|_| p.fallback.is_none())
    }
    let sweep = |points: &[CurvePoint]| {
        json!({
            "nodes": points.iter().map(|p| on(p).map_or(0, |c| c.nodes)).collect::<Vec<_>>(),
            "contraction": points.iter().map(|p| on(p).map(|c| c.contraction)).collect::<Vec<_>>(),
            "fallback": points.iter().map(|p| p.fallback.map(|f| f.name())).collect::<Vec<_>>(),
        })
    };
    json!({
        names.0: sweep(&c.first),
        names.1: sweep(&c.second),
    })
}

/// The `"time_average"` block of a curve measured by the time average
/// ([`crate::analysis::stepped::average`]): its options, and per sweep and point the periods
/// integrated, whether it settled, and per component (the primary first) the error estimates
/// of the amplitude (`u`'s length) and of the phase (degrees).
fn time_average(
    a: &crate::analysis::stepped::average::AverageOptions,
    names: (&str, &str),
    c: &SteppedCurve,
    u: &CurveUnits,
) -> Value {
    let sweep = |points: &[CurvePoint]| {
        let est: Vec<_> = points.iter().filter_map(|p| p.average.as_ref()).collect();
        json!({
            "periods": est.iter().map(|e| e.periods).collect::<Vec<_>>(),
            "settled": est.iter().map(|e| e.settled).collect::<Vec<_>>(),
            "amplitude_error": est
                .iter()
                .map(|e| e.amplitude_error.iter().map(|x| x * u.length).collect::<Vec<_>>())
                .collect::<Vec<_>>(),
            "phase_error_deg": est
                .iter()
                .map(|e| e.phase_error.iter().map(|x| x.to_degrees()).collect::<Vec<_>>())
                .collect::<Vec<_>>(),
        })
    };
    json!({
        "window_periods": a.window_periods,
        "windows": a.windows,
        "tolerance": a.tol,
        names.0: sweep(&c.first),
        names.1: sweep(&c.second),
    })
}

/// The `"drive_components"` block of a curve under a multifrequency drive (`None` for one
/// frequency): per component (the primary first) `ratio` (ω_c/Ω at the curve's first point),
/// `frequency` (Hz with a probe's scales, else Ω units), `free_amplitude` (`u`'s length) and
/// the `columns` [name, kind of unit or null, meaning] of [`component_columns`].
fn drive_components(params: &Params, c: &SteppedCurve, u: &CurveUnits) -> Option<Value> {
    let o = &c.first.first()?.observables;
    if o.components.is_empty() {
        return None;
    }
    let omega = params.with(c.param, c.first[0].value).omega;
    let noise = c.noise.is_some();
    // Hz in SI (τ = t / u.time), else Ω units
    let freq = |r: f64| {
        if u.si {
            r * omega / (std::f64::consts::TAU * u.time)
        } else {
            r * omega
        }
    };
    Some(json!({
        "ratio": o.components.iter().map(|c| c.ratio).collect::<Vec<_>>(),
        "frequency": o.components.iter().map(|c| freq(c.ratio)).collect::<Vec<_>>(),
        "free_amplitude": o.components.iter().map(|c| c.free_amplitude * u.length).collect::<Vec<_>>(),
        // with a temperature, the further components' lock-in noise too
        "columns": component_columns(o.components.len())
            .into_iter()
            .chain(component_noise_columns(o.components.len()).into_iter().filter(|_| noise))
            .map(|(n, k, l)| json!([n, k.key(), l]))
            .collect::<Vec<_>>(),
    }))
}

/// `doc` with the [`si`] block of `probe` added (built from `doc` itself, so its headline values
/// appear in SI), when the model came from a probe file; `doc` unchanged otherwise. Every front
/// end adds the block through this one function. The probe's own warnings
/// ([`crate::probe::Probe::warnings`]) join the document's `warnings` (made for them when the
/// document has none).
pub(crate) fn with_si(
    mut doc: Value,
    probe: Option<&crate::probe::Probe>,
    params: &Params,
) -> Value {
    if let Some(p) = probe {
        doc["si"] = si(p, params, &doc);
        if !p.assumed.is_empty() {
            // a quasi-static read's stand-ins: in the SI block, but not the file's
            doc["si"]["assumed"] = Value::from(p.assumed.clone());
        }
        // the probe's own warnings (a sample outside its law's regime, a value outside its
        // typical range) in every document: joined to its warnings, or as its warnings
        let own = p.warnings();
        if let Some(w) = doc.get_mut("warnings").and_then(Value::as_array_mut) {
            w.extend(own.into_iter().map(Value::from));
        } else if !own.is_empty() && doc.is_object() {
            doc["warnings"] = Value::from(own);
        }
    }
    doc
}

/// The keys whose `null` is a documented state, not a missing value: a nonperiodic motion's
/// `period` and `multipliers`, a periodic one's `lyapunov`, an exponent no cell gave.
const NULL_BY_DESIGN: [&str; 7] = [
    // a fitted map's curves: a curve's missing estimate is its flag's (`fit-map`)
    "curves",
    "period",
    "multipliers",
    "lyapunov",
    "lyapunov_error",
    "uncertainty_exponent",
    "event",
];

/// The door's audit of a result's document (issue 77 item 3): every array of numbers in it
/// (outside `si`, `units`, `params`, the messages and the keys whose null is a state,
/// [`NULL_BY_DESIGN`])
/// with missing values — NaN or a part not computed, written as `null` — is named in a warning
/// with how many are missing, so that no NaN is written as a value unsaid; a document whose
/// every such array is missing throughout is no result.
///
/// # Errors
/// [`crate::SimError::NoFiniteValue`] naming `what` and its arrays when none holds a number.
pub(crate) fn audit_missing(doc: &mut Value, what: &'static str) -> Result<(), crate::SimError> {
    fn walk(v: &Value, path: &str, found: &mut Vec<(String, usize, usize)>) {
        match v {
            Value::Object(m) => {
                for (k, x) in m {
                    let skip = ["si", "units", "params", "warnings", "scales", "message"];
                    if !skip.contains(&k.as_str()) && !NULL_BY_DESIGN.contains(&k.as_str()) {
                        let p = if path.is_empty() {
                            k.clone()
                        } else {
                            format!("{path}.{k}")
                        };
                        walk(x, &p, found);
                    }
                }
            }
            Value::Array(a) => {
                let numbers = a.iter().filter(|x| x.is_number()).count();
                let nulls = a.iter().filter(|x| x.is_null()).count();
                if numbers + nulls == a.len() && !a.is_empty() {
                    found.push((path.to_string(), nulls, a.len()));
                } else {
                    for x in a {
                        walk(x, &format!("{path}[]"), found);
                    }
                }
            }
            _ => {}
        }
    }
    let mut found = Vec::new();
    walk(doc, "", &mut found);
    let empty: Vec<&str> = found
        .iter()
        .filter(|(_, nulls, n)| nulls == n)
        .map(|(p, _, _)| p.as_str())
        .collect();
    if !found.is_empty() && empty.len() == found.len() {
        return Err(crate::SimError::NoFiniteValue {
            what,
            arrays: empty.join(", "),
        });
    }
    let said: Vec<Value> = found
        .iter()
        .filter(|(_, nulls, _)| *nulls > 0)
        .map(|(path, nulls, n)| {
            Value::from(format!(
                "{path}: {nulls} of {n} values are missing (null here, NaN in the tables and \
                 arrays): those parts were not computed; the other warnings say why"
            ))
        })
        .collect();
    if !said.is_empty() && doc.is_object() {
        if !doc["warnings"].is_array() {
            doc["warnings"] = Value::Array(Vec::new());
        }
        if let Some(w) = doc["warnings"].as_array_mut() {
            w.extend(said);
        }
    }
    Ok(())
}

/// `afmdyn approach --json`: `{"approach": {...}, "retract": {...}, "branches": [...], …}`.
/// `approach` and `retract` hold equal-length arrays `z_c` (rest distance,
/// [`Params::rest_distance`]) and the `CURVE_COLUMNS`, plus `stable`, `period` (null when not
/// period-n) and `reached` ([`crate::analysis::stepped::Reached`]); each branch the same
/// columns with `stable`, `period` and `event` (null, "fold", "grazing", …). Also `folds` and
/// `bistable` ([lo, hi] ranges of z_c between two folds), `jumps` ({sweep, from, to, fold}),
/// `free_amplitude`, `units` (names), `scales` (the [`CurveUnits`] factors), `params` and
/// `warnings`.
pub(crate) fn approach(params: &Params, c: &SteppedCurve, u: &CurveUnits) -> Value {
    let x = z_c_of(params, u);
    curve_doc(params, c, ("z_c", &x), ("approach", "retract"), u)
}

/// The `"thermal"` block of `afmdyn approach --temperature T --json`
/// ([`crate::analysis::lock_in_noise`]; the sweeps' [`NOISE_COLUMNS`] carry σ_A and σ_φ):
/// `temperature` (K), `time_constant` (the lock-in's τ_L, in `u`'s time), `bandwidth` (its
/// noise-equivalent bandwidth (f_d/2) β/(2 − β), β = 1 − e^{−T/τ_L}, T = 1/f_d the (first)
/// drive's period; Hz with a probe, else per unit τ) and `method`.
pub(crate) fn thermal_noise(
    params: &Params,
    temperature: f64,
    time_constant: f64,
    u: &CurveUnits,
) -> Value {
    // the lock-ins low-pass once per drive period (crate::analysis::lock_in_noise)
    let period = std::f64::consts::TAU / params.omega;
    let beta = crate::analysis::am_loop::lock_in_beta(time_constant, period);
    json!({
        "temperature": temperature,
        "time_constant": time_constant * u.time,
        "bandwidth": 0.5 / (period * u.time) * beta / (2.0 - beta),
        "method": "the lock-in's amplitude and phase noise by linear response about each \
                   orbit: the variational flow with its saltations, the fluctuation–dissipation \
                   theorem's white force and the lock-ins' filters (one per drive component, \
                   each low-passed once per drive period) as one linear chain over the drive's \
                   (common) period, its stationary covariance (crate::analysis::lock_in_noise)",
        "columns": noise_row(None, params.demodulated().len(), u)
            .into_iter()
            .map(|c| c.0)
            .collect::<Vec<_>>(),
    })
}

/// The abscissa of an approach document: z_c ([`crate::analysis::approach::rest_distance`]) of
/// the gap α5, in `u`'s length.
fn z_c_of<'a>(params: &'a Params, u: &'a CurveUnits) -> impl Fn(f64) -> f64 + 'a {
    move |a5| crate::analysis::approach::rest_distance(params, a5) * u.length
}

/// The regime of a steady state from its mean deflection ⟨W⟩ (any length unit):
/// `"attractive"` where the mean tip–sample force, k⟨W⟩ for the point mass, is negative, else
/// `"repulsive"` (García & San Paulo, *Phys. Rev. B* 61 (2000) R13381).
pub(crate) fn regime(mean_deflection: f64) -> &'static str {
    if mean_deflection < 0.0 {
        "attractive"
    } else {
        "repulsive"
    }
}

/// The `"setpoint"` block of `afmdyn approach --setpoint S --json`: the ratio A_sp/A₀, the
/// amplitude it means (in `u`'s length), and per operating point of the curve at the setpoint
/// (`points`, [`crate::analysis::setpoint::operating_points`]) its `source` (`"branch k"`,
/// `"approach"`, `"retract"`), `z_c`, `regime` (`"attractive"` where the mean tip–sample force,
/// k⟨W⟩ for the point mass, is negative, else `"repulsive"`; García & San Paulo 2000) and the
/// `CURVE_COLUMNS` of its orbit (interpolated between two time-averaged motions).
pub(crate) fn setpoint(
    params: &Params,
    c: &SteppedCurve,
    (points, dropped): (
        &[crate::analysis::setpoint::OperatingPoint],
        &[crate::analysis::setpoint::Crossing],
    ),
    ratio: f64,
    u: &CurveUnits,
) -> Value {
    let x = z_c_of(params, u);
    let points: Vec<Value> = points
        .iter()
        .map(|op| {
            let k = &op.crossing;
            let (name, [(_, a), (_, b)]) = around(c, k);
            // the orbit's own observables; two averaged motions' interpolated
            let mix = |p: &[f64], q: &[f64]| -> Vec<f64> {
                p.iter()
                    .zip(q)
                    .map(|(p, q)| (1.0 - k.t) * p + k.t * q)
                    .collect()
            };
            let (row, comps) = match &op.exact {
                Some(o) => (curve_row(o, u).to_vec(), component_row(o, u)),
                None => (
                    mix(&curve_row(a, u), &curve_row(b, u)),
                    mix(&component_row(a, u), &component_row(b, u)),
                ),
            };
            let mut m = serde_json::Map::new();
            m.insert("source".into(), json!(name));
            m.insert("z_c".into(), json!(x(k.value)));
            m.insert("regime".into(), json!(regime(row[3])));
            for (c, v) in CURVE_COLUMNS.iter().zip(row) {
                m.insert(c.name.into(), json!(v));
            }
            // with a temperature: the lock-ins' noise of the operating orbit
            if let Some(n) = &op.noise {
                for (name, v) in noise_row(Some(n), comps.len() / 4, u) {
                    m.insert(name, json!(v));
                }
            }
            // a multifrequency drive: each component's amplitude, phase, virial and E_dis there
            let names = component_columns(comps.len() / 4);
            for ((name, _, _), v) in names.into_iter().zip(comps) {
                m.insert(name, json!(v));
            }
            Value::Object(m)
        })
        .collect();
    let a0 = c
        .first
        .first()
        .map(|p| p.observables.closed_form.free_amplitude * u.length);
    let mut doc = json!({
        "ratio": ratio,
        "amplitude": a0.map(|a| a * ratio),
        "points": points,
    });
    if !dropped.is_empty() {
        doc["warnings"] = json!(setpoint_gaps(params, c, dropped, ratio, u));
    }
    doc
}

/// The warnings of the setpoint's crossings that hold no operating point
/// ([`crate::analysis::setpoint::operating_points`]: no continuous stable orbit across the
/// bracket, where the curve jumps), so that a crossing left out is said.
fn setpoint_gaps(
    params: &Params,
    c: &SteppedCurve,
    dropped: &[crate::analysis::setpoint::Crossing],
    ratio: f64,
    u: &CurveUnits,
) -> Vec<String> {
    let x = z_c_of(params, u);
    let unit = if u.si { "m" } else { "g0" };
    dropped
        .iter()
        .map(|k| {
            let (name, [(v0, _), (v1, _)]) = around(c, k);
            format!(
                "the setpoint A/A0 = {ratio} falls between z_c = {} {unit} and {} {unit} on the \
                 {name}, where no stable orbit runs continuously from one to the other (the \
                 curve jumps there): no operating point is listed for that crossing",
                crate::error::number(x(v0)),
                crate::error::number(x(v1)),
            )
        })
        .collect()
}

/// The curve of crossing `k` (`approach`, `retract` or `branch j`) and its two points around
/// the crossing: (swept value, observables).
fn around<'a>(
    c: &'a SteppedCurve,
    k: &crate::analysis::setpoint::Crossing,
) -> (String, [(f64, &'a Observables); 2]) {
    use crate::analysis::setpoint::Source;
    let [i, j] = [k.index, k.index + 1];
    match k.source {
        Source::Branch(b) => {
            let at = |i: usize| (c.branches[b][i].point.value, &c.branches[b][i].observables);
            (format!("branch {b}"), [at(i), at(j)])
        }
        Source::Sweep(s) => {
            let (name, pts) = match s {
                Sweep::First => ("approach", &c.first),
                Sweep::Second => ("retract", &c.second),
            };
            let at = |i: usize| (pts[i].value, &pts[i].observables);
            (name.into(), [at(i), at(j)])
        }
    }
}

/// `afmdyn resonance --json`: as [`approach`] with the abscissa `omega` (dimensionless Ω) or
/// `frequency_hz` (with [`CurveUnits::hz_per_omega`]) and the sweeps `up` and `down`.
pub fn resonance(params: &Params, c: &SteppedCurve, u: &CurveUnits) -> Value {
    let scale = u.hz_per_omega.unwrap_or(1.0);
    let key = if u.hz_per_omega.is_some() {
        "frequency_hz"
    } else {
        "omega"
    };
    let x = move |om: f64| om * scale;
    curve_doc(params, c, (key, &x), ("up", "down"), u)
}
