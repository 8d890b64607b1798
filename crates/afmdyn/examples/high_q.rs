//! A real lever at its defaults (issue 42, section 1): the cantilever library's RTESPA-300
//! (k = 40 N/m, f0 = 300 kHz, Q = 500; point-mass model) tapping polystyrene in air (DMT,
//! E = 2.5 GPa, H = 6.6e-20 J, η = 10 Pa s, A0 = 15 nm) at z_c = 14.3 nm, where a period-1
//! orbit of the attractive regime and one of the repulsive regime coexist.
//!
//! `cargo run --release -p afmdyn --example high_q -- <census|basins> [SAMPLES|STEPS] [STRIDE]`
//!
//! - `census [SAMPLES=64]`: the attractor census at its defaults (the transient cap derived
//!   from Q, Newton from the transient), timed, against the same starts run to a plain
//!   20 000-period transient (returns repeating to 1e-8, no Newton): the attractors, their
//!   periods and basin fractions, and the largest difference of the fractions.
//! - `basins [STEPS=100] [STRIDE=1]`: the basin map of the plane (a1, ȧ1) ∈ [−1.5, 1.5]² at its
//!   defaults, timed, against every STRIDE-th cell (in x and y) run to a plain 20 000-period
//!   transient: the share of identical labels.
//!
//! Prints one line of figures per case (read by `scripts/perf-high-q.sh`).

use afmdyn::analysis::attractors::{find_attractors, same_attractor, AttractorSpec};
use afmdyn::analysis::basins::{
    basins, BasinSpec, StateCoord, DEFAULT_BASIN_HITS, DEFAULT_CELL, DEFAULT_DISCOVER_AFTER,
    DEFAULT_NEAR_TOL, DEFAULT_STRIDE,
};
use afmdyn::analysis::bifurcation::SweepSpec;
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::steady::{steady_state, SteadyOptions};
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::probe::Probe;
use afmdyn::request::ModelSpec;
use afmdyn::{CantileverModel, Params};
use nalgebra::DVector;
use rayon::prelude::*;
use std::time::Instant;

/// The probe of the report (`examples/probe-rtespa300-polystyrene.toml`).
pub const PROBE: &str = include_str!("../../../examples/probe-rtespa300-polystyrene.toml");

/// The reference: a plain transient of 20 000 drive periods, returns repeating to 1e-8.
fn reference() -> SteadyOptions {
    SteadyOptions {
        max_periods: Some(20_000),
        newton: false,
        ..SteadyOptions::default()
    }
}

fn params(z_c: f64) -> Result<Params, Box<dyn std::error::Error>> {
    let probe = Probe::parse(PROBE, "RTESPA-300 over polystyrene")?;
    let spec = ModelSpec {
        z_c: Some(z_c),
        ..ModelSpec::default()
    };
    Ok(spec.resolve(Params::default(), Some(&probe))?)
}

fn census(samples: usize) -> Result<(), Box<dyn std::error::Error>> {
    let p = params(14.3e-9)?;
    let spec = AttractorSpec {
        params: p,
        samples,
        seed: 1,
        cluster_tol: 1e-5,
        steady: SteadyOptions::default(),
        integrator: IntegratorOptions::default(),
    };
    let t = Instant::now();
    let fast = find_attractors(&spec, &Progress::new())?;
    let t_fast = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let slow = find_attractors(
        &AttractorSpec {
            steady: reference(),
            ..spec.clone()
        },
        &Progress::new(),
    )?;
    let t_slow = t.elapsed().as_secs_f64();
    let describe = |r: &afmdyn::analysis::attractors::AttractorReport| {
        r.attractors
            .iter()
            .map(|a| {
                format!(
                    "{} {:.3}",
                    a.steady
                        .period()
                        .map_or("nonperiodic".into(), |n| format!("P{n}")),
                    a.basin_fraction
                )
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    // the largest difference of the basin fractions of the same attractor
    let mut worst: f64 = 0.0;
    for a in &fast.attractors {
        let b = slow
            .attractors
            .iter()
            .find(|b| same_attractor(&a.steady, &b.steady, 1e-4));
        worst = worst.max((a.basin_fraction - b.map_or(0.0, |b| b.basin_fraction)).abs());
    }
    for b in &slow.attractors {
        if !fast
            .attractors
            .iter()
            .any(|a| same_attractor(&a.steady, &b.steady, 1e-4))
        {
            worst = worst.max(b.basin_fraction);
        }
    }
    println!(
        "census {samples} starts: defaults {t_fast:.2} s ({} attractors: {}; unsettled {}; cap {}), \
         20000-period reference {t_slow:.2} s ({} attractors: {}); largest fraction difference {worst:.3}",
        fast.attractors.len(),
        describe(&fast),
        fast.unsettled.iter().map(|a| a.count).sum::<usize>(),
        fast.transient_cap,
        slow.attractors.len(),
        describe(&slow),
    );
    Ok(())
}

fn basin_map(steps: usize, stride: usize) -> Result<(), Box<dyn std::error::Error>> {
    let p = params(14.3e-9)?;
    let spec = BasinSpec {
        params: p,
        x: StateCoord::A(1),
        xs: SweepSpec::linspace(-1.5, 1.5, steps)?,
        y: StateCoord::ADot(1),
        ys: SweepSpec::linspace(-1.5, 1.5, steps)?,
        base: DVector::zeros(2 * p.modes),
        near_tol: DEFAULT_NEAR_TOL,
        cell: DEFAULT_CELL,
        basin_hits: DEFAULT_BASIN_HITS,
        discover_after: DEFAULT_DISCOVER_AFTER,
        stride: DEFAULT_STRIDE,
        steady: SteadyOptions::default(),
        cluster_tol: 1e-5,
        integrator: IntegratorOptions::default(),
    };
    let t = Instant::now();
    let map = basins(&spec)?;
    let t_map = t.elapsed().as_secs_f64();
    let model = CantileverModel::new(&p)?;
    let cells: Vec<(usize, usize)> = (0..steps)
        .step_by(stride.max(1))
        .flat_map(|iy| (0..steps).step_by(stride.max(1)).map(move |ix| (iy, ix)))
        .collect();
    let t = Instant::now();
    let labels: Vec<i64> = cells
        .par_iter()
        .with_max_len(1)
        .map(|&(iy, ix)| {
            let mut z0 = spec.base.clone();
            spec.x.set(&model, &mut z0, spec.xs[ix]);
            spec.y.set(&model, &mut z0, spec.ys[iy]);
            let s = build(&model, spec.integrator.clone(), 0.0, &z0)
                .and_then(|mut it| steady_state(it.as_mut(), &reference()));
            s.ok()
                .and_then(|s| {
                    map.attractors
                        .iter()
                        .position(|a| same_attractor(a, &s, 1e-4))
                })
                .map_or(-1, |i| i as i64)
        })
        .collect();
    let t_ref = t.elapsed().as_secs_f64();
    let same = cells
        .iter()
        .zip(&labels)
        .filter(|(&(iy, ix), &l)| map.cells[iy * steps + ix].label == l)
        .count();
    println!(
        "basins {steps}x{steps}: map {t_map:.2} s ({} attractors, fractions {:?}); reference \
         {} cells {t_ref:.1} s; labels identical {:.2} % ({same} of {})",
        map.attractors.len(),
        map.attractors
            .iter()
            .enumerate()
            .map(|(i, _)| {
                let n = map.cells.iter().filter(|c| c.label == i as i64).count();
                format!("{:.3}", n as f64 / map.cells.len() as f64)
            })
            .collect::<Vec<_>>(),
        cells.len(),
        100.0 * same as f64 / cells.len() as f64,
        cells.len(),
    );
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let case = args.next().unwrap_or_else(|| "census".into());
    let n: Option<usize> = args.next().map(|s| s.parse()).transpose()?;
    let stride: usize = args.next().map_or(Ok(1), |s| s.parse())?;
    match case.as_str() {
        "basins" => basin_map(n.unwrap_or(100), stride),
        _ => census(n.unwrap_or(64)),
    }
}
