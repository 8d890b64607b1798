//! Result documents shared by the front ends: the JSON that `afmdyn … --json` prints and that
//! the Python package's `to_dict()` returns. One place builds each document, so the command
//! line and Python cannot drift apart; a front end adds only its own keys (output paths).
//!
//! Every function returns a [`serde_json::Value`] object; serialised with
//! `serde_json::to_string` it is byte for byte what the command line prints.

use crate::analysis::attractors::AttractorReport;
use crate::analysis::continuation::BranchPoint;
use crate::analysis::converge::ConvergenceRun;
use crate::analysis::lyapunov::LyapunovSpectrum;
use crate::analysis::shooting::PeriodicOrbit;
use crate::analysis::steady::SteadyState;
use crate::eigen::RegionSpectrum;
use crate::model::CantileverModel;
use crate::params::{Params, SweepParam};
use crate::trajectory::Trajectory;
use nalgebra::DVector;
use serde_json::{json, Value};

/// One region of `afmdyn modes --json`: `{"omega": [ω_i], "eigenvalues": [[re, im], …]}`.
pub fn region_spectrum(r: &RegionSpectrum) -> Value {
    json!({
        "omega": r.omega,
        "eigenvalues": r.eigenvalues.iter().map(|e| [e.re, e.im]).collect::<Vec<_>>(),
    })
}

/// `afmdyn modes --json`: the parameters and the free and contact spectra (eqs. 19–23).
pub fn modes(params: &Params, free: &RegionSpectrum, contact: &RegionSpectrum) -> Value {
    json!({ "params": params, "free": region_spectrum(free), "contact": region_spectrum(contact) })
}

/// `afmdyn simulate --json`: final time and state, switchings, body contact.
pub fn simulate(model: &CantileverModel, tr: &Trajectory) -> Value {
    let zf = &tr.final_state;
    let n = model.modes();
    json!({
        "params": model.params(),
        "tau_end": tr.tau_end,
        "final": {
            "w_tip": model.w_tip(zf),
            "w_tip_dot": model.w_tip_dot(zf),
            "v_t": model.v_t(tr.tau_end, zf),
            "a": zf.rows(0, n).iter().collect::<Vec<_>>(),
            "a_dot": zf.rows(n, n).iter().collect::<Vec<_>>(),
        },
        "switchings": tr.events.len(),
        "body_contact": tr.body_contact,
    })
}

/// `afmdyn converge --json` without the output directory: the parameters and, per N, the
/// period and the RMS change of the tip motion against N − 1.
pub fn converge(params: &Params, runs: &[ConvergenceRun]) -> Value {
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

/// One attractor of `afmdyn attractors --json`.
pub fn attractor(s: &SteadyState, basin: f64) -> Value {
    json!({
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
pub fn attractors(params: &Params, samples: usize, report: &AttractorReport) -> Value {
    json!({
        "params": params,
        "samples": samples,
        "failures": report.failures.len(),
        "attractors": report
            .attractors
            .iter()
            .map(|x| attractor(&x.steady, x.basin_fraction))
            .collect::<Vec<_>>(),
    })
}

/// `afmdyn orbit --json`: a period-n orbit of `model` with its Floquet multipliers.
pub fn orbit(model: &CantileverModel, o: &PeriodicOrbit) -> Value {
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
pub fn continuation(base: &Params, param: SweepParam, branches: &[Vec<BranchPoint>]) -> Value {
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
        "points": branches.iter().map(Vec::len).sum::<usize>(),
        "events": events,
    })
}

/// `afmdyn lyapunov --json`: the Lyapunov spectrum and the 0–1 test at `params` (every field of
/// [`LyapunovSpectrum`], so a field added there reaches both front ends).
pub fn lyapunov(params: &Params, l: &LyapunovSpectrum) -> Value {
    let mut doc = serde_json::to_value(l).expect("a Lyapunov spectrum serialises");
    doc["params"] = json!(params);
    doc
}
