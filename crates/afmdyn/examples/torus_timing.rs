//! Cost of one step of a bimodal approach at the lever's true mode ratio (issue 63): on
//! `examples/probe-bimodal.toml` with mode 2 and its drive at 6.27 f₁ (627/100: the drive
//! repeats every 100 periods) against 6.25 f₁ (25/4: every 4), the steady state at z_c − 0.1 nm
//! from the one at z_c by Newton: the exact periodic orbit of the common period
//! ([`afmdyn::analysis::shooting::shoot`]) and the invariant circle
//! ([`afmdyn::analysis::torus::invariant_circle`]) on 11, 26 and 37 nodes, with the largest
//! difference of the components' amplitudes from the exact orbit's (over each free amplitude).
//!
//! ```sh
//! cargo run --release -p afmdyn --example torus_timing
//! ```
//!
//! Prints one line of JSON per regime (z_c = 8 nm, no contact at A₀₂ = 0.3 nm; z_c = 5 nm,
//! repulsive): milliseconds of each solve (the fastest of 3), and the errors.

use afmdyn::analysis::observables::{observe_orbit, Observables};
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::torus::{continue_circle, invariant_circle, observe_circle, CircleOptions};
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::maps::flow::flow_state;
use afmdyn::maps::StroboscopicMap;
use afmdyn::probe::Probe;
use afmdyn::{CantileverModel, Params};
use nalgebra::DVector;
use std::path::Path;
use std::time::Instant;

fn params(f2: &str, zc_nm: f64) -> Params {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-bimodal.toml");
    let text = std::fs::read_to_string(path)
        .expect("example probe")
        .replace("1.875e6]", &format!("{f2}]"))
        .replace("[10e-9, 1e-9]", "[10e-9, 0.3e-9]");
    let mut p = Probe::parse(&text, "bimodal").expect("probe").params;
    p.alpha5 = zc_nm * 1e-9 / 10e-9;
    p
}

fn settled(model: &CantileverModel, periods: usize) -> DVector<f64> {
    let mut it = build(model, IntegratorOptions::default(), 0.0, &model.rest()).expect("build");
    let t = periods as f64 * std::f64::consts::TAU / model.omega();
    flow_state(it.as_mut(), 0.0, &model.rest(), t).expect("transient")
}

fn best_of_3<T>(mut f: impl FnMut() -> T) -> (f64, T) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..3 {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
        out = Some(r);
    }
    (best, out.expect("ran"))
}

fn amplitude_error(a: &Observables, b: &Observables) -> f64 {
    a.components
        .iter()
        .zip(&b.components)
        .map(|(x, y)| (x.amplitude - y.amplitude).abs() / x.free_amplitude)
        .fold(0.0, f64::max)
}

fn main() {
    let integ = IntegratorOptions::default();
    for zc in [8.0, 5.0] {
        let mut line = vec![format!("\"z_c_nm\": {zc}")];
        for (name, f2) in [("6.25", "1.875e6"), ("6.27", "1.881e6")] {
            // the state at z_c + 0.1 nm (settled, then polished), the start of the step
            let before = CantileverModel::new(&params(f2, zc + 0.1)).expect("model");
            let guess = settled(&before, 4000);
            let mut it = build(&before, integ.clone(), 0.0, &guess).expect("build");
            let map = &mut StroboscopicMap::new(it.as_mut(), 1);
            let start = shoot(map, &guess, &ShootingOptions::default())
                .expect("orbit before")
                .state;
            let model = CantileverModel::new(&params(f2, zc)).expect("model");
            let (t_orbit, orbit) = best_of_3(|| {
                let mut it = build(&model, integ.clone(), 0.0, &start).expect("build");
                let map = &mut StroboscopicMap::new(it.as_mut(), 1);
                shoot(map, &start, &ShootingOptions::default()).expect("orbit")
            });
            line.push(format!(
                "\"orbit_{name}_ms\": {t_orbit:.1}, \"orbit_{name}_periods\": {}",
                model.params().common_periods()
            ));
            if name == "6.25" {
                continue;
            }
            let exact = observe_orbit(&model, integ.clone(), &orbit, 2).expect("observe");
            for nodes in [11, 26, 37] {
                let opts = CircleOptions {
                    nodes,
                    ..Default::default()
                };
                let (t_circle, circle) = best_of_3(|| {
                    invariant_circle(&model, integ.clone(), &start, &opts).expect("circle")
                });
                // continued from the circle at z_c + 0.1 nm (Broyden from its Jacobian)
                let previous =
                    invariant_circle(&before, integ.clone(), &start, &opts).expect("circle");
                let (t_cont, continued) = best_of_3(|| {
                    continue_circle(
                        &model,
                        integ.clone(),
                        &previous.states[0],
                        &previous.jacobian,
                        &opts,
                    )
                    .expect("continued")
                });
                let torus = observe_circle(&model, integ.clone(), &circle, 2).expect("observe");
                let torus_c =
                    observe_circle(&model, integ.clone(), &continued, 2).expect("observe");
                line.push(format!(
                    "\"circle_{nodes}_ms\": {t_circle:.1}, \"circle_{nodes}_continued_ms\": \
                     {t_cont:.1}, \"circle_{nodes}_error\": {:.2e}, \
                     \"circle_{nodes}_continued_error\": {:.2e}, \"circle_{nodes}_smooth\": {}",
                    amplitude_error(&exact, &torus),
                    amplitude_error(&exact, &torus_c),
                    circle.smooth
                ));
            }
        }
        println!("{{{}}}", line.join(", "));
    }
}
