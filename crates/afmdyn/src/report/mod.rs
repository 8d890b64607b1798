//! Result documents shared by the front ends: the JSON that `afmdyn … --json` prints and that
//! the Python package's `to_dict()` returns. One place builds each document, so the command
//! line and Python cannot drift apart; a front end adds only its own keys (output paths).
//!
//! Every function returns a [`serde_json::Value`] object; serialised with
//! `serde_json::to_string` it is byte for byte what the command line prints.

use crate::analysis::attractors::{Attractor, AttractorReport};
use crate::analysis::continuation::Branch;
use crate::analysis::converge::ConvergenceRun;
use crate::analysis::global_continuation::ContinuationStep;
use crate::analysis::lyapunov::LyapunovSpectrum;
use crate::analysis::observables::{ComponentObservables, ModeBalance, Observables};
use crate::analysis::shooting::PeriodicOrbit;
use crate::analysis::steady::SteadyState;
use crate::analysis::stepped::{CurvePoint, SteppedCurve, Sweep};
use crate::eigen::RegionSpectrum;
use crate::layout::{Layout, Variable};
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::trajectory::Trajectory;
use nalgebra::DVector;
use serde_json::{json, Value};

/// One region of `afmdyn modes --json`: `{"omega": [ω_i], "eigenvalues": [[re, im], …]}`.
pub(crate) fn region_spectrum(r: &RegionSpectrum) -> Value {
    json!({
        "omega": r.omega,
        "eigenvalues": r.eigenvalues.iter().map(|e| [e.re, e.im]).collect::<Vec<_>>(),
    })
}

/// `afmdyn modes --json`: the parameters and the free and contact spectra (eqs. 19–23).
pub(crate) fn modes(params: &Params, free: &RegionSpectrum, contact: &RegionSpectrum) -> Value {
    json!({ "params": params, "free": region_spectrum(free), "contact": region_spectrum(contact) })
}

pub(crate) use crate::trajectory::energy_residual;

/// What `afmdyn simulate --json` reports of a run (the front ends add their own keys, e.g. the
/// files written and warnings).
#[derive(Debug, Clone, PartialEq)]
pub struct SimulateSummary {
    /// Final τ.
    pub tau_end: f64,
    /// Final state, shape `[2N]`.
    pub final_state: DVector<f64>,
    /// Number of events.
    pub switchings: usize,
    /// Whether the beam body touched the substrate.
    pub body_contact: bool,
    /// Stroboscopic section points recorded.
    pub poincare_points: usize,
    /// `energy_residual` of the run; `None` where its energy balance was not audited.
    pub energy_residual: Option<(f64, f64)>,
}

/// Relative per-period energy residual above which a run is reported as inaccurate (normal runs
/// close to ~1e-10 with the exact propagator and with the adaptive integrator's dense output).
pub(crate) const ENERGY_TOLERANCE: f64 = 1e-6;

/// The run's own accuracy checks that failed: the energy balance beyond [`ENERGY_TOLERANCE`],
/// and the beam body reaching the substrate (outside the paper's model, Fig. 2f).
pub(crate) fn simulate_warnings(s: &SimulateSummary) -> Vec<String> {
    let mut w = vec![];
    let relative = s.energy_residual.map_or(0.0, |r| r.1);
    if relative.is_nan() || relative > ENERGY_TOLERANCE {
        w.push(warning!(
            "simulate.energy",
            "Integrate more finely (more steps per period, or an adaptive integrator with \
             a smaller tolerance), or keep the parameters inside the valid range.",
            "energy balance violated: a per-period residual of {relative:.1e} relative \
             (tolerance 1e-6); the trajectory is not accurate (integrator too coarse, or \
             parameters at the edge of the valid range)"
        ));
    }
    if s.body_contact {
        w.push(warning!(
            "simulate.body-contact",
            "Raise the gap (z_c) or lower the amplitude: the model assumes that only the \
             tip touches.",
            "a point of the beam other than the tip reached the substrate (paper Fig. 2f): \
             outside the model's assumption"
        ));
    }
    w
}

/// `afmdyn simulate --json`: final time and state, events, body contact, section points, the
/// energy-balance residual and [`simulate_warnings`].
pub(crate) fn simulate_summary(model: &CantileverModel, s: &SimulateSummary) -> Value {
    let zf = &s.final_state;
    let n = model.modes();
    json!({
        "params": model.params(),
        "tau_end": s.tau_end,
        "final": {
            "w_tip": model.w_tip(zf),
            "w_tip_dot": model.w_tip_dot(zf),
            "v_t": model.v_t(s.tau_end, zf),
            "a": zf.rows(0, n).iter().collect::<Vec<_>>(),
            "a_dot": zf.rows(n, n).iter().collect::<Vec<_>>(),
        },
        "switchings": s.switchings,
        "body_contact": s.body_contact,
        "poincare_points": s.poincare_points,
        "energy_residual": s.energy_residual.map(|(a, r)| json!({ "max_abs": a, "max_relative": r })),
        "warnings": simulate_warnings(s),
    })
}

/// `simulate_summary` of a whole [`Trajectory`], its energy balance audited or not (`energy`).
pub(crate) fn simulate(model: &CantileverModel, tr: &Trajectory, energy: bool) -> Value {
    simulate_summary(
        model,
        &SimulateSummary {
            tau_end: tr.tau_end,
            final_state: tr.final_state.clone(),
            switchings: tr.events.len(),
            body_contact: tr.body_contact,
            poincare_points: tr.poincare.len(),
            energy_residual: energy.then(|| energy_residual(&tr.energy)),
        },
    )
}

/// `afmdyn converge --json` without the output directory: the parameters and, per N, the
/// period and the RMS change of the tip motion against N − 1.
pub(crate) fn converge(params: &Params, runs: &[ConvergenceRun]) -> Value {
    let rows: Vec<_> = runs
        .iter()
        .map(|r| json!({ "modes": r.modes, "period": r.period, "rms_change": r.rms_change }))
        .collect();
    json!({ "params": params, "runs": rows })
}

/// A section state as the `--initial-modal` string "a1,..,aN;adot1,..,adotN" (at drive phase 0),
/// so that `afmdyn orbit --initial-modal` can start from an attractor; empty for `None`.
pub fn initial_modal(z: Option<&DVector<f64>>) -> String {
    let Some(z) = z else { return String::new() };
    let n = z.len() / 2;
    let join = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(",")
    };
    format!("{};{}", join(&z.as_slice()[..n]), join(&z.as_slice()[n..]))
}

/// One attractor of `afmdyn attractors --json`; `multipliers` ([re, im] pairs) and `stable` of
/// the shooting-polished orbit, null for a nonperiodic motion.
pub(crate) fn attractor(s: &SteadyState, basin: f64, orbit: Option<&PeriodicOrbit>) -> Value {
    json!({
        "multipliers": orbit.map(|o| o.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>()),
        "stable": orbit.map(|o| o.stable),
        "period": s.period(),
        "poincare": {
            "v_t": s.poincare.iter().map(|p| p.v_t).collect::<Vec<_>>(),
            "w_tip": s.poincare.iter().map(|p| p.w_tip).collect::<Vec<_>>(),
        },
        "x_max": s.stats.x_max,
        "v_t_min": s.stats.v_t_min,
        "contact_fraction": s.stats.contact_fraction,
        "contacts_per_period": s.stats.contacts_per_period,
        "body_contact": s.stats.body_contact,
        "basin_fraction": basin,
        "initial_modal": initial_modal(s.poincare.first().map(|q| &q.state)),
    })
}

/// `afmdyn attractors --json` (also written to `attractors.json`): `samples` starts at `params`.
pub(crate) fn attractors(params: &Params, samples: usize, report: &AttractorReport) -> Value {
    json!({
        "params": params,
        "samples": samples,
        "failures": report.failures.len(),
        "transient_cap": report.transient_cap,
        "attractors": report
            .attractors
            .iter()
            .map(|x| census_entry(x, x.basin_fraction))
            .collect::<Vec<_>>(),
        "unsettled": report
            .unsettled
            .iter()
            .map(|x| {
                let mut d = census_entry(x, 0.0);
                d["count"] = json!(x.count);
                d
            })
            .collect::<Vec<_>>(),
        "warnings": report.warnings(),
    })
}

/// One attractor of a census: [`attractor`] with λ₁ and its error for a nonperiodic one.
fn census_entry(x: &Attractor, basin: f64) -> Value {
    let mut d = attractor(&x.steady, basin, x.orbit.as_ref());
    if let Some((l, e)) = x.lyapunov {
        d["lyapunov"] = json!(l);
        d["lyapunov_error"] = json!(e);
    }
    d
}

/// The number of attractor ids of a global continuation (its largest id + 1).
fn continuation_ids(steps: &[ContinuationStep]) -> usize {
    steps
        .iter()
        .flat_map(|s| s.attractors.iter().map(|(id, _)| id + 1))
        .max()
        .unwrap_or(0)
}

/// The layout of a global continuation (the command line's `attractors-sweep.nc`, Python's
/// dataset): coordinates `value` (named by the parameter) and `id`; over (value, id)
/// `basin_fraction` (0 where the id has no attractor), `period` (−1 nonperiodic, 0 absent),
/// `x_max`, `v_t_min` (g0; NaN absent), `stable` (1/0 from the orbit's Floquet multipliers,
/// NaN otherwise); over value `failures` (runs that failed).
pub(crate) fn global_continuation_layout(param: SweepParam, steps: &[ContinuationStep]) -> Layout {
    let (nv, ni) = (steps.len(), continuation_ids(steps));
    let mut fraction = vec![0.0; nv * ni];
    let mut period = vec![0; nv * ni];
    let (mut x_max, mut v_t_min, mut stable) = (
        vec![f64::NAN; nv * ni],
        vec![f64::NAN; nv * ni],
        vec![f64::NAN; nv * ni],
    );
    for (i, s) in steps.iter().enumerate() {
        for (id, a) in &s.attractors {
            let k = i * ni + id;
            fraction[k] = a.basin_fraction;
            period[k] = a.steady.period().map_or(-1, |n| n as i32);
            x_max[k] = a.steady.stats.x_max;
            v_t_min[k] = a.steady.stats.v_t_min;
            if let Some(o) = &a.orbit {
                stable[k] = f64::from(u8::from(o.stable));
            }
        }
    }
    let grid: &[&str] = &["value", "id"];
    let values: Vec<f64> = steps.iter().map(|s| s.value).collect();
    let ids: Vec<i32> = (0..ni).map(|i| i as i32).collect();
    let failures: Vec<i32> = steps.iter().map(|s| s.failures.len() as i32).collect();
    Layout::new(
        format!(
            "afmdyn global continuation of the attractors over {}",
            param.name()
        ),
        &[("value", nv), ("id", ni)],
        vec![
            Variable::f64("value", &["value"], "1", param.name(), &values),
            Variable::i32("id", &["id"], "1", "attractor id", &ids),
            Variable::f64(
                "basin_fraction",
                grid,
                "1",
                "share of the random starts (0: none)",
                &fraction,
            ),
            Variable::i32(
                "period",
                grid,
                "drive periods",
                "period n (-1 nonperiodic, 0 absent)",
                &period,
            ),
            Variable::f64("x_max", grid, "g0", "X_max", &x_max),
            Variable::f64("v_t_min", grid, "g0", "min V_T", &v_t_min),
            Variable::f64(
                "stable",
                grid,
                "1",
                "1 stable periodic orbit (shooting), 0 unstable, NaN otherwise",
                &stable,
            ),
            Variable::i32("failures", &["value"], "1", "runs that failed", &failures),
        ],
    )
}

/// `afmdyn attractors --sweep --json`: the attractors at every value with their ids, and the
/// basin fractions as a values × ids table (0 where an id has no attractor).
pub(crate) fn global_continuation(
    base: &Params,
    param: SweepParam,
    samples: usize,
    steps: &[ContinuationStep],
) -> Value {
    let ids = continuation_ids(steps);
    let fractions: Vec<Vec<f64>> = steps
        .iter()
        .map(|s| {
            let mut row = vec![0.0; ids];
            for (id, a) in &s.attractors {
                row[*id] = a.basin_fraction;
            }
            row
        })
        .collect();
    let mut warnings: Vec<String> = steps
        .iter()
        .filter(|s| s.attractors.is_empty())
        .map(|s| {
            format!(
                "{} = {}: every run failed ({})",
                param.name(),
                s.value,
                s.failures.first().map_or("", String::as_str)
            )
        })
        .collect();
    for s in steps {
        for w in &s.warnings {
            warnings.push(format!("{} = {}: {w}", param.name(), s.value));
        }
    }
    json!({
        "params": base,
        "param": param.name(),
        "samples": samples,
        "values": steps.iter().map(|s| s.value).collect::<Vec<_>>(),
        "ids": ids,
        "fractions": fractions,
        "steps": steps.iter().map(|s| json!({
            "value": s.value,
            "failures": s.failures.len(),
            "attractors": s.attractors.iter().map(|(id, a)| {
                let mut d = attractor(&a.steady, a.basin_fraction, a.orbit.as_ref());
                d["id"] = json!(id);
                d
            }).collect::<Vec<_>>(),
        })).collect::<Vec<_>>(),
        "warnings": warnings,
    })
}

/// `afmdyn orbit --json`: a period-n orbit of `model` with its Floquet multipliers.
pub(crate) fn orbit(model: &CantileverModel, o: &PeriodicOrbit) -> Value {
    let mut doc = json!({
        "period": o.period,
        "poincare": {
            "v_t": o.section.iter().map(|z| model.v_t(0.0, z)).collect::<Vec<_>>(),
            "w_tip": o.section.iter().map(|z| model.w_tip(z)).collect::<Vec<_>>(),
        },
        "multipliers": o.multipliers.iter().map(|m| [m.re, m.im]).collect::<Vec<_>>(),
        "stable": o.stable,
        "critical": o.critical,
        "grazing": o.grazing,
        "grazing_distance": o.grazing_distance,
        "switchings": o.switchings,
        "newton_residuals": o.residuals,
        "state": o.state.iter().collect::<Vec<_>>(),
    });
    doc["params"] = json!(model.params());
    doc
}

/// `afmdyn continue --json` without the output directory: the branches' sizes and their
/// located bifurcations.
pub(crate) fn continuation(base: &Params, param: SweepParam, branches: &[Branch]) -> Value {
    let events: Vec<_> = branches
        .iter()
        .flatten()
        .filter(|b| b.event.is_some())
        .map(|b| json!({ "event": b.event, "value": b.value, "period": b.period, "stable": b.stable }))
        .collect();
    json!({
        "params": base,
        "param": param.name(),
        "branches": branches.len(),
        "points": branches.iter().map(|b| b.len()).sum::<usize>(),
        "events": events,
        "ends": branches.iter().map(|b| b.end).collect::<Vec<_>>(),
        "warnings": continuation_warnings(param, branches),
    })
}

/// One line for every branch that ended before covering what was asked
/// ([`crate::analysis::continuation::BranchEnd::warning`]).
pub(crate) fn continuation_warnings(param: SweepParam, branches: &[Branch]) -> Vec<String> {
    branches
        .iter()
        .filter_map(|b| b.end.warning(param, b.first().map_or(1, |p| p.period)))
        .collect()
}

pub(crate) mod basins;
mod branches;
pub(crate) mod chart_layout;
mod convergence;
pub mod csv_columns;
pub(crate) mod curve_layout;
#[cfg(feature = "files")]
mod curve_table;
mod curves;
mod documents;
pub mod fit_map;
pub mod image;
pub(crate) mod image_layout;
pub mod present;
mod series;
#[cfg(feature = "files")]
pub(crate) mod simulate_files;
pub(crate) mod sweep;
mod units;
pub(crate) use branches::*;
pub use convergence::Convergence;
#[cfg(feature = "files")]
pub(crate) use curve_table::*;
pub(crate) use curves::*;
pub use documents::*;
pub use series::*;
pub use units::*;

/// `afmdyn lyapunov --json`: the Lyapunov spectrum and the 0–1 test at `params` (every field of
/// [`LyapunovSpectrum`], so a field added there reaches both front ends).
pub(crate) fn lyapunov(params: &Params, l: &LyapunovSpectrum) -> Value {
    let mut doc = serde_json::to_value(l).expect("a Lyapunov spectrum serialises");
    doc["params"] = json!(params);
    doc
}

/// The `"si"` block a front end adds to any document when the model came from a probe file
/// ([`crate::probe`]): the scales back to SI (every dimensionless value of the document converts
/// with them: lengths × `length_m`, τ × `time_s`, forces × `force_n`, energies × `energy_j`,
/// Ω → Hz), the probe's drive, free amplitude and rest distance, and the headline quantities of
/// the document in SI: natural frequencies in Hz (`modes`), X_max and V_T in m (`simulate`,
/// `attractors`, `orbit`), the swept parameter (Ω in Hz, α5 as z_c in m; `continue`), Lyapunov
/// exponents in 1/s (`lyapunov`).
pub fn si(probe: &crate::probe::Probe, params: &Params, doc: &Value) -> Value {
    let s = &probe.scales;
    let hz = |om: &Value| om.as_f64().map(|w| s.frequency_hz(w));
    let metres = |v: &Value| v.as_f64().map(|x| x * s.length_m);
    let mut out = json!({
        "scales": {
            "length_m": s.length_m,
            "time_s": s.time_s,
            "force_n": s.force_n,
            "energy_j": s.energy_j(),
            "power_w": s.power_w(),
        },
        "calibration": probe.calibration,
        "drive_frequency_hz": s.frequency_hz(params.omega),
        // a quasi-periodic drive has no common period: its primary period 2π/Ω
        "period_s": if params.is_quasiperiodic() {
            std::f64::consts::TAU / params.omega
        } else {
            params.period()
        } * s.time_s,
        "free_amplitude_m": probe.free_amplitude,
        "z_c_m": probe.z_c_of(params),
    });
    if !probe.components.is_empty() {
        out["drive_components"] = json!(probe.components);
    }
    let map_array = |v: &Value, f: &dyn Fn(&Value) -> Option<f64>| -> Value {
        v.as_array()
            .map(|a| Value::from(a.iter().map(f).collect::<Vec<_>>()))
            .unwrap_or(Value::Null)
    };
    for region in ["free", "contact"] {
        if let Some(om) = doc.get(region).and_then(|r| r.get("omega")) {
            out[format!("{region}_frequencies_hz")] = map_array(om, &hz);
        }
    }
    if doc.get("free").is_some() {
        if let Ok(g) = crate::galerkin::Galerkin::new(params) {
            out["quality_factors"] = json!(crate::eigen::quality_factors(
                g.region(crate::galerkin::Region::Free)
            ));
        }
    }
    if let Some(m) = &probe.medium {
        out["medium"] = json!(m);
    }
    if let Some(mu) = probe.tabor_parameter {
        out["tabor_parameter"] = json!(mu);
    }
    if let Some(h) = params.contact_law.hysteresis(params.alpha4) {
        out["contact_hysteresis"] = json!({
            "release_distance_m": h.release_distance * s.length_m,
            "pull_off_force_n": h.pull_off_force * s.force_n,
            "energy_per_tap_j": h.energy_per_tap * s.energy_j(),
        });
    }
    if let Some(x) = doc.get("x_max") {
        out["x_max_m"] = json!(metres(x));
    }
    if let Some(p) = doc.get("poincare").and_then(|p| p.get("v_t")) {
        out["poincare_v_t_m"] = map_array(p, &metres);
    }
    if let Some(att) = doc.get("attractors").and_then(Value::as_array) {
        out["attractors_x_max_m"] =
            Value::from(att.iter().map(|a| metres(&a["x_max"])).collect::<Vec<_>>());
    }
    if let Some(ex) = doc.get("exponents") {
        out["exponents_per_s"] = map_array(ex, &|v| v.as_f64().map(|l| l / s.time_s));
    }
    if let (Some(param), Some(events)) = (
        doc.get("param").and_then(Value::as_str),
        doc.get("events").and_then(Value::as_array),
    ) {
        let convert = |v: &Value| -> Option<f64> {
            let x = v.as_f64()?;
            match param {
                "omega" => Some(s.frequency_hz(x)),
                "alpha5" => Some(params.with(SweepParam::Alpha5, x).rest_distance() * s.length_m),
                _ => None,
            }
        };
        let unit = match param {
            "omega" => "hz",
            "alpha5" => "z_c_m",
            _ => "",
        };
        if !unit.is_empty() {
            out[format!("event_values_{unit}")] = Value::from(
                events
                    .iter()
                    .map(|e| convert(&e["value"]))
                    .collect::<Vec<_>>(),
            );
        }
    }
    out
}

/// The observables of a steady state ([`Observables`], every field, so a field added there
/// reaches both front ends): dimensionless units of the model (lengths g₀, time τ, forces F̃,
/// energies F̃·g₀); phases in radians. Non-finite values (e.g. Q = ∞ without damping) become
/// `null`.
pub(crate) fn observables(o: &Observables) -> Value {
    serde_json::to_value(o).expect("observables serialise")
}
