//! Cost of a basin map against running every start to convergence one by one (the census's
//! way), on one thread, with the share of identical labels:
//!
//! `cargo run --release -p afmdyn --example basin_cost -- <impact|beam> <steps>`
//!
//! `impact`: N = 1, r = 0.8, Ω = 2.0 over (a1, ȧ1) ∈ [−0.6, 0.6] × [−1.2, 1.2]; `beam`: the
//! default N = 3 linear-law beam at Ω = 2.8 over the same plane; `beam2`: the paper's Figs. 15–17
//! beam (N = 3, α1 = 0, Ω = 20; a period-1 and a period-4 attractor) over [−1, 1] × [−20, 20]. Prints seconds of both, their
//! ratio, the cells decided early, the agreement, the disagreements by how they were decided,
//! and the mean drive periods per start of both. `NEAR`, `CELL`, `HITS` in the environment
//! override the map's defaults.

use afmdyn::analysis::attractors::same_attractor;
use afmdyn::analysis::basins::{
    basins, BasinSpec, Decided, StateCoord, DEFAULT_BASIN_HITS, DEFAULT_CELL,
    DEFAULT_DISCOVER_AFTER, DEFAULT_NEAR_TOL, DEFAULT_STRIDE,
};
use afmdyn::analysis::bifurcation::SweepSpec;
use afmdyn::analysis::steady::{steady_state, SteadyOptions};
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::{CantileverModel, ContactLaw, Params};
use nalgebra::DVector;
use std::time::Instant;

/// `$name` parsed, or `default` (the options of the map, varied by hand when measuring).
fn env<T: std::str::FromStr>(name: &str, default: T) -> T {
    std::env::var(name)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(default)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let case = args.next().unwrap_or_else(|| "impact".into());
    let steps: usize = args.next().map_or(Ok(100), |s| s.parse())?;
    let p = match case.as_str() {
        "beam" => Params {
            omega: 2.8,
            ..Params::default()
        },
        // the paper's Figs. 15–17 (captions): period-1 and period-4 coexist
        "beam2" => Params {
            modes: 3,
            alpha1: 0.0,
            alpha2: 0.1,
            alpha3: 0.1,
            alpha4: 20.0,
            alpha5: 0.0,
            alpha6: 0.2,
            omega: 20.0,
            ..Params::default()
        },
        _ => Params {
            modes: 1,
            omega: 2.0,
            contact_law: ContactLaw::Impact { restitution: 0.8 },
            ..Params::default()
        },
    };
    // the plane: (a1, ȧ1) ∈ [−0.6, 0.6] × [−1.2, 1.2], for beam2 [−1, 1] × [−20, 20]
    let scale = if case == "beam2" {
        (1.0 / 0.6, 20.0 / 1.2)
    } else {
        (1.0, 1.0)
    };
    let spec = BasinSpec {
        params: p,
        x: StateCoord::A(1),
        xs: SweepSpec::linspace(-0.6 * scale.0, 0.6 * scale.0, steps)?,
        y: StateCoord::ADot(1),
        ys: SweepSpec::linspace(-1.2 * scale.1, 1.2 * scale.1, steps)?,
        base: DVector::zeros(2 * p.modes),
        near_tol: env("NEAR", DEFAULT_NEAR_TOL),
        cell: env("CELL", DEFAULT_CELL),
        basin_hits: env("HITS", DEFAULT_BASIN_HITS),
        discover_after: DEFAULT_DISCOVER_AFTER,
        stride: env("STRIDE", DEFAULT_STRIDE),
        steady: SteadyOptions::default(),
        cluster_tol: 1e-5,
        integrator: IntegratorOptions::default(),
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let t = Instant::now();
    let map = pool.install(|| basins(&spec))?;
    let t_map = t.elapsed().as_secs_f64();
    let model = CantileverModel::new(&p)?;
    let t = Instant::now();
    let mut brute = Vec::with_capacity(map.cells.len());
    for iy in 0..steps {
        for ix in 0..steps {
            let mut z0 = spec.base.clone();
            spec.x.set(&model, &mut z0, spec.xs[ix]);
            spec.y.set(&model, &mut z0, spec.ys[iy]);
            let mut it = build(&model, spec.integrator.clone(), 0.0, &z0)?;
            brute.push(steady_state(it.as_mut(), &spec.steady).ok());
        }
    }
    let t_brute = t.elapsed().as_secs_f64();
    let agree = map
        .cells
        .iter()
        .zip(&brute)
        .filter(|(c, b)| {
            let id = b.as_ref().and_then(|s| {
                map.attractors
                    .iter()
                    .position(|a| same_attractor(a, s, 1e-4))
            });
            id.map_or(-2, |i| i as i64) == c.label
        })
        .count();
    let mut wrong = std::collections::BTreeMap::new();
    for (c, b) in map.cells.iter().zip(&brute) {
        let id = b.as_ref().and_then(|s| {
            map.attractors
                .iter()
                .position(|a| same_attractor(a, s, 1e-4))
        });
        let id = id.map_or(-2, |i| i as i64);
        if id != c.label {
            *wrong.entry((c.decided.name(), c.label, id)).or_insert(0) += 1;
        }
    }
    println!("disagreements (how decided, map label, brute label): {wrong:?}");
    let mean_map = map.cells.iter().map(|c| c.periods as f64).sum::<f64>() / map.cells.len() as f64;
    let mean_brute = brute
        .iter()
        .flatten()
        .map(|s| (s.transient_periods + s.poincare.len()) as f64)
        .sum::<f64>()
        / brute.len() as f64;
    let near = map
        .cells
        .iter()
        .filter(|c| c.decided == Decided::Near)
        .count();
    let grid = map
        .cells
        .iter()
        .filter(|c| c.decided == Decided::Grid)
        .count();
    println!(
        "periods per start: map {mean_map:.1}, one by one {mean_brute:.1} (transient + recorded); near {near}, grid {grid}"
    );
    let early = map
        .cells
        .iter()
        .filter(|c| {
            matches!(
                c.decided,
                Decided::Near | Decided::Recurrence | Decided::Grid
            )
        })
        .count();
    let n = map.cells.len();
    println!(
        "{case} {steps}x{steps}: map {t_map:.2} s, one by one {t_brute:.2} s, ratio {:.3}; \
         {} attractors; decided early {:.1} %; labels identical {:.2} %",
        t_map / t_brute,
        map.attractors.len(),
        100.0 * early as f64 / n as f64,
        100.0 * agree as f64 / n as f64
    );
    Ok(())
}
