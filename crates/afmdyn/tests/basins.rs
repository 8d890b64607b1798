//! Basin maps (issue 30): the labels of the early-stopping map against running every start to
//! its steady state (brute force, the census's way), thread independence, and the measures of
//! the map.

use afmdyn::analysis::attractors::same_attractor;
use afmdyn::analysis::basin_entropy::basin_entropy;
use afmdyn::analysis::basins::{
    basins, BasinSpec, Decided, StateCoord, DEFAULT_BASIN_HITS, DEFAULT_CELL,
    DEFAULT_DISCOVER_AFTER, DEFAULT_NEAR_TOL, DEFAULT_STRIDE,
};
use afmdyn::analysis::bifurcation::SweepSpec;
use afmdyn::analysis::steady::{steady_state, SteadyOptions};
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::{CantileverModel, ContactLaw, Params};
use nalgebra::DVector;

/// The impact oscillator N = 1, r = 0.8, Ω = 2.0: two coexisting period-1 orbits (the census of
/// 64 random starts finds them with basin fractions 0.92 and 0.08).
fn impact() -> Params {
    Params {
        modes: 1,
        omega: 2.0,
        contact_law: ContactLaw::Impact { restitution: 0.8 },
        ..Params::default()
    }
}

fn spec(p: Params, steps: usize) -> BasinSpec {
    BasinSpec {
        params: p,
        x: StateCoord::A(1),
        xs: SweepSpec::linspace(-0.6, 0.6, steps).unwrap(),
        y: StateCoord::ADot(1),
        ys: SweepSpec::linspace(-1.2, 1.2, steps).unwrap(),
        base: DVector::zeros(2 * p.modes),
        near_tol: DEFAULT_NEAR_TOL,
        cell: DEFAULT_CELL,
        basin_hits: DEFAULT_BASIN_HITS,
        discover_after: DEFAULT_DISCOVER_AFTER,
        stride: DEFAULT_STRIDE,
        steady: SteadyOptions::default(),
        cluster_tol: 1e-5,
        integrator: IntegratorOptions::default(),
    }
}

/// Every cell's label against the steady state its start reaches when run to convergence (the
/// transient cap and detection of `steady_state`, as the attractor census runs each start),
/// matched to the map's attractors: at least 99.5 % agree, both attractors have a basin, and
/// most cells were decided before the steady-state search. One pass at 30 × 30.
#[test]
fn labels_agree_with_running_every_start_to_convergence() {
    let map = agree_with_brute_force(&BasinSpec {
        stride: 1,
        ..spec(impact(), 30)
    });
    assert!(map.cells.iter().all(|c| c.decided != Decided::Grid));
}

/// As above at 60 × 60 in two passes (the automatic stride 2: a 30 × 30 first grid): most
/// cells of the second pass are decided by the first pass's grid.
#[test]
fn two_passes_agree_with_running_every_start_to_convergence() {
    let s = spec(impact(), 60);
    assert_eq!(s.first_stride(), 2);
    let map = agree_with_brute_force(&s);
    let grid = map
        .cells
        .iter()
        .filter(|c| c.decided == Decided::Grid)
        .count();
    assert!(
        grid * 2 > map.cells.len(),
        "{grid} cells decided by the grid"
    );
}

fn agree_with_brute_force(s: &BasinSpec) -> afmdyn::analysis::basins::BasinMap {
    let map = basins(s).unwrap();
    assert_eq!(map.attractors.len(), 2, "the two period-1 orbits");
    let model = CantileverModel::new(&s.params).unwrap();
    let (mut agree, mut total, mut early) = (0, 0, 0);
    for (k, cell) in map.cells.iter().enumerate() {
        let (ix, iy) = (k % s.xs.len(), k / s.xs.len());
        let mut z0 = s.base.clone();
        s.x.set(&model, &mut z0, s.xs[ix]);
        s.y.set(&model, &mut z0, s.ys[iy]);
        let mut it = build(&model, s.integrator.clone(), 0.0, &z0).unwrap();
        let brute = steady_state(it.as_mut(), &SteadyOptions::default())
            .ok()
            .and_then(|st| {
                map.attractors
                    .iter()
                    .position(|a| same_attractor(a, &st, 1e-4))
            })
            .map_or(-2, |i| i as i64);
        total += 1;
        agree += usize::from(brute == cell.label);
        early += usize::from(cell.decided != Decided::Steady);
    }
    let share = agree as f64 / total as f64;
    assert!(share >= 0.995, "{agree} of {total} labels agree");
    // an attractor is stable: both orbits, polished by shooting, have every |μ| < 1
    for o in &map.orbits {
        let o = o.as_ref().expect("a periodic orbit, polished");
        assert!(
            o.stable && o.multipliers.iter().all(|m| m.norm() < 1.0),
            "{o:?}"
        );
    }
    let labels = map.labels();
    for a in 0..2 {
        assert!(labels.contains(&a), "attractor {a} has a basin");
    }
    assert!(early * 2 > total, "{early} of {total} decided early");
    // a map with a basin boundary has boundary boxes
    let e = basin_entropy(&labels, s.xs.len(), 5).unwrap();
    assert!(e.boundary_boxes > 0 && e.basin_entropy > 0.0, "{e:?}");
    map
}

/// The automatic stride keeps at least 25 nodes per axis in the first grid.
#[test]
fn the_automatic_stride_keeps_a_fine_enough_first_grid() {
    for (n, stride) in [(10, 1), (49, 1), (50, 2), (100, 4), (199, 4), (200, 8)] {
        assert_eq!(spec(impact(), n).first_stride(), stride, "{n} steps");
    }
    let s = BasinSpec {
        stride: 3,
        ..spec(impact(), 100)
    };
    assert_eq!(s.first_stride(), 3);
}

/// The map does not depend on the thread count (rows are pure tasks, attractors matched in row
/// order), in three passes (strides 4, 2, 1).
#[test]
fn the_map_does_not_depend_on_threads() {
    let s = BasinSpec {
        stride: 4,
        ..spec(impact(), 14)
    };
    let run = |t: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(t)
            .build()
            .unwrap()
            .install(|| basins(&s).unwrap())
    };
    assert_eq!(format!("{:?}", run(1)), format!("{:?}", run(2)));
}

#[test]
fn coordinates_parse_and_set_the_state() {
    assert_eq!("a2".parse::<StateCoord>().unwrap(), StateCoord::A(2));
    assert_eq!("ADOT1".parse::<StateCoord>().unwrap(), StateCoord::ADot(1));
    assert_eq!("wdot".parse::<StateCoord>().unwrap(), StateCoord::WDot);
    assert!("a0".parse::<StateCoord>().is_err() && "b1".parse::<StateCoord>().is_err());
    // the tip deflection is set through mode 1, the other modes kept
    let p = Params::default();
    let m = CantileverModel::new(&p).unwrap();
    let mut z = DVector::zeros(6);
    z[1] = 0.01;
    StateCoord::W.set(&m, &mut z, 0.3);
    assert!((m.w_tip(&z) - 0.3).abs() < 1e-15 && z[1] == 0.01);
    StateCoord::WDot.set(&m, &mut z, -0.2);
    assert!((m.w_tip_dot(&z) + 0.2).abs() < 1e-15);
    let bad = BasinSpec {
        x: StateCoord::A(4),
        ..spec(p, 3)
    };
    assert!(basins(&bad).is_err());
}

/// Labels against long brute-force runs: on cells away from basin boundaries (the 3 × 3 cells
/// around them share the label) of the 60 × 60 two-pass map, 12 cells of each basin are run for
/// 1 500 drive periods with the integrator alone, and its last return is nearest to a section
/// point of the attractor the map labels it with (and within 1e-6 of it: converged).
#[test]
fn interior_labels_agree_with_1500_period_runs() {
    let s = spec(impact(), 60);
    let map = basins(&s).unwrap();
    let model = CantileverModel::new(&s.params).unwrap();
    let (nx, ny) = (s.xs.len(), s.ys.len());
    let labels = map.labels();
    let interior: Vec<usize> = (0..nx * ny)
        .filter(|&k| {
            let (ix, iy) = (k % nx, k / nx);
            ix > 0
                && iy > 0
                && ix + 1 < nx
                && iy + 1 < ny
                && (iy - 1..=iy + 1)
                    .all(|j| (ix - 1..=ix + 1).all(|i| labels[j * nx + i] == labels[k]))
        })
        .collect();
    // 12 cells of each basin's interior, evenly spread over it
    let picked: Vec<usize> = (0..2i64)
        .flat_map(|l| {
            let own: Vec<usize> = interior
                .iter()
                .copied()
                .filter(|&k| labels[k] == l)
                .collect();
            let step = (own.len() / 12).max(1);
            own.into_iter().step_by(step).take(12).collect::<Vec<_>>()
        })
        .collect();
    assert!(picked.len() >= 20, "{} interior cells", interior.len());
    let mut seen = [false; 2];
    for k in picked {
        let (ix, iy) = (k % nx, k / nx);
        let mut z0 = s.base.clone();
        s.x.set(&model, &mut z0, s.xs[ix]);
        s.y.set(&model, &mut z0, s.ys[iy]);
        let mut it = build(&model, s.integrator.clone(), 0.0, &z0).unwrap();
        afmdyn::integrate::advance(it.as_mut(), 1500.0 * model.period()).unwrap();
        let z = &it.state().clone();
        let (id, d) = map
            .attractors
            .iter()
            .enumerate()
            .flat_map(|(i, a)| a.poincare.iter().map(move |p| (i, (z - &p.state).norm())))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap();
        assert_eq!(id as i64, labels[k], "cell ({ix}, {iy})");
        assert!(
            d < 1e-6,
            "cell ({ix}, {iy}): {d} from its attractor after 1500 periods"
        );
        seen[id] = true;
    }
    assert!(seen[0] && seen[1], "both basins sampled");
}

/// The map assembled from the rows a run showed, handed over in any order (as a store would
/// give them back), is the run's own map: the same labels, decisions and attractors, in two
/// passes (the automatic stride at 60 × 60). Rows missing (a run cut short) are refused.
#[test]
fn the_map_of_stored_rows_is_the_runs_map() {
    use afmdyn::analysis::basins::{basin_map, basins, run_passes};
    use std::sync::atomic::AtomicBool;
    use std::sync::Mutex;
    let s = spec(impact(), 60);
    let model = CantileverModel::new(&s.params).unwrap();
    let rows = Mutex::new(Vec::new());
    run_passes(
        &s,
        &model,
        &[],
        &|r| rows.lock().unwrap().push(r.clone()),
        &AtomicBool::new(false),
    )
    .unwrap();
    let mut rows = rows.into_inner().unwrap();
    assert!(rows.iter().any(|r| r.pass > 0), "two passes");
    rows.reverse();
    let stored = basin_map(&s, rows.clone()).unwrap();
    let run = basins(&s).unwrap();
    assert_eq!(stored.cells, run.cells);
    assert_eq!(stored.attractors.len(), run.attractors.len());
    for (a, b) in stored.attractors.iter().zip(&run.attractors) {
        assert_eq!(a.poincare.len(), b.poincare.len());
        assert_eq!(a.end_state(), b.end_state());
    }
    rows.pop();
    assert!(matches!(
        basin_map(&s, rows),
        Err(afmdyn::SimError::Cancelled)
    ));
}
