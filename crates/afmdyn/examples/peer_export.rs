//! Export the linear-law model for the peer benchmark (`scripts/peers/`): the first-order
//! dynamics ż = A_s z + b_const + b_sin sin Ωτ + b_cos cos Ωτ of both regions, the tip vector
//! φ(1), α2, α5 and Ω (so the peers integrate exactly the model afmdyn integrates), a start state
//! on the attractor (the state 100 periods from rest, taken as the state at τ_start = 0),
//! afmdyn's exact state at τ = 40, and
//! afmdyn's wall time per forcing period from that start (exact propagator, best of 5 runs).
//!
//! Default parameter set (paper eq. 26 with α1 = 0.1, Ω = 2.6), linear law, N modes.
//!
//! `cargo run --release -p afmdyn --example peer_export -- <N> <out.json> [periods]`
//! (`periods`: the timed run; default: as many as take about 0.2 s, at least 10.)

use afmdyn::integrate::{
    advance, advance_dyn, build, Integrator, IntegratorKind, IntegratorOptions,
};
use afmdyn::{CantileverModel, Params, Region};
use nalgebra::{DMatrix, DVector};
use serde_json::{json, Value};

/// The horizon of the accuracy check, in τ.
const HORIZON: f64 = 40.0;
/// Transient from rest onto the attractor, in forcing periods.
const TRANSIENT_PERIODS: f64 = 100.0;

fn exact() -> IntegratorOptions {
    IntegratorOptions {
        kind: IntegratorKind::Exact,
        steps_per_period: 1,
        tolerance: 0.0,
        ..IntegratorOptions::default()
    }
}

fn vector(v: &DVector<f64>) -> Value {
    json!(v.iter().copied().collect::<Vec<f64>>())
}

fn matrix(m: &DMatrix<f64>) -> Value {
    json!((0..m.nrows())
        .map(|i| m.row(i).iter().copied().collect::<Vec<f64>>())
        .collect::<Vec<_>>())
}

/// Wall time of `periods` forcing periods from (τ0, z0), in seconds, and the switchings
/// counted. The timed run is `integrate::advance` — the final state only, as the peers
/// deliver — and the switchings are counted in a separate, untimed run.
fn timed(
    it: &mut dyn Integrator,
    t0: f64,
    z0: &DVector<f64>,
    periods: f64,
    period: f64,
) -> Result<(f64, usize), Box<dyn std::error::Error>> {
    it.reset(t0, z0)?;
    let start = std::time::Instant::now();
    advance(it, t0 + periods * period)?;
    let wall = start.elapsed().as_secs_f64();
    std::hint::black_box(it.state()[0]);
    it.reset(t0, z0)?;
    let mut events = 0usize;
    advance_dyn(it, t0 + periods * period, &mut |_, s, _| {
        events += usize::from(s.event.is_some());
        Ok(())
    })?;
    Ok((wall, events))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let modes: usize = args.next().map_or(Ok(3), |s| s.parse())?;
    let out = args
        .next()
        .unwrap_or_else(|| format!("peer-model-n{modes}.json"));
    let periods: Option<f64> = args.next().map(|s| s.parse()).transpose()?;
    let p = Params {
        modes,
        ..Params::default()
    };
    let m = CantileverModel::new(&p)?;
    let period = p.period();

    // start on the attractor: the state after the transient, restarted at τ = 0 (the forcing
    // is T-periodic), so that no integrator pays the round-off of large τ
    let mut it = build(&m, exact(), 0.0, &m.rest())?;
    advance_dyn(it.as_mut(), TRANSIENT_PERIODS * period, &mut |_, _, _| {
        Ok(())
    })?;
    let z0 = it.state().clone();
    let t0 = 0.0;
    it.reset(t0, &z0)?;

    // reference: the exact state HORIZON later, and the switchings on the way
    let mut switchings = 0usize;
    advance_dyn(it.as_mut(), t0 + HORIZON, &mut |_, s, _| {
        switchings += usize::from(s.event.is_some());
        Ok(())
    })?;
    let z_ref = it.state().clone();

    // timing: best of 5 runs of the same periods from the same start
    let periods = match periods {
        Some(k) => k,
        None => {
            let (w, _) = timed(it.as_mut(), t0, &z0, 10.0, period)?;
            (0.2 / (w / 10.0)).clamp(10.0, 20_000.0).round()
        }
    };
    let mut best = f64::INFINITY;
    let mut events = 0;
    for _ in 0..5 {
        let (w, e) = timed(it.as_mut(), t0, &z0, periods, period)?;
        best = best.min(w);
        events = e;
    }
    let us_per_period = best * 1e6 / periods;

    let region = |r: Region| {
        let d = m.dynamics(r);
        json!({
            "a": matrix(&d.a),
            "b_const": vector(&d.b_const),
            "b_sin": vector(&d.b_sin),
            "b_cos": vector(&d.b_cos),
        })
    };
    let doc = json!({
        "n": modes,
        "params": p,
        "omega": p.omega,
        "alpha2": p.alpha2,
        "alpha5": p.alpha5,
        "tip": vector(m.tip()),
        "free": region(Region::Free),
        "contact": region(Region::Contact),
        "tau_start": t0,
        "z_start": vector(&z0),
        "horizon": HORIZON,
        "z_ref": vector(&z_ref),
        "switchings_in_horizon": switchings,
        "afmdyn": {
            "integrator": it.name(),
            "us_per_period": us_per_period,
            "timed_periods": periods,
            "switchings_per_period": events as f64 / periods,
        },
    });
    std::fs::write(&out, serde_json::to_string_pretty(&doc)?)?;
    println!(
        "N = {modes}: {out}; afmdyn {} {us_per_period:.2} µs per period ({periods} periods, \
         best of 5); {switchings} switchings in τ_start + [0, {HORIZON}]",
        it.name()
    );
    Ok(())
}
