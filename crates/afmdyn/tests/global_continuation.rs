//! Global continuation of attractors (issue 30): ids follow the attractors across values, the
//! seeds find attractors the random starts miss without counting in the basin fractions, the
//! fractions are those of the random starts run to their steady states one by one, and the
//! result does not depend on the thread count.

use afmdyn::analysis::attractors::{same_attractor, AttractorSpec};
use afmdyn::analysis::bifurcation::start_state;
use afmdyn::analysis::global_continuation::{
    global_continuation, set_distance, ContinuationStep, GlobalContinuationSpec, DEFAULT_MATCH_TOL,
};
use afmdyn::analysis::progress::Progress;
use afmdyn::analysis::steady::{steady_state, SteadyOptions};
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::{CantileverModel, ContactLaw, Params, SweepParam};

/// The impact oscillator N = 1, r = 0.8: two coexisting period-1 orbits near Ω = 2.0.
fn spec(values: Vec<f64>, samples: usize) -> GlobalContinuationSpec {
    GlobalContinuationSpec {
        census: AttractorSpec {
            params: Params {
                modes: 1,
                omega: 2.0,
                contact_law: ContactLaw::Impact { restitution: 0.8 },
                ..Params::default()
            },
            samples,
            seed: 7,
            cluster_tol: 1e-5,
            steady: SteadyOptions::default(),
            integrator: IntegratorOptions::default(),
        },
        param: SweepParam::Omega,
        values,
        match_tol: DEFAULT_MATCH_TOL,
    }
}

fn run(s: &GlobalContinuationSpec) -> Vec<ContinuationStep> {
    global_continuation(s, &Progress::new()).unwrap()
}

/// Over Ω = 1.98 … 2.06 both period-1 orbits are found, and an id is one orbit followed
/// continuously: wherever an id appears at consecutive values its two Poincaré sets lie within
/// the matching distance and X_max moves by less than 0.01 per step of 0.01, and the two ids
/// never swap (the orbit with the larger X_max keeps its id).
#[test]
fn ids_follow_the_two_period_one_orbits() {
    let values: Vec<f64> = (0..9).map(|i| 1.98 + 0.01 * i as f64).collect();
    let steps = run(&spec(values, 48));
    let at_2 = &steps[2];
    assert_eq!(at_2.attractors.len(), 2, "two period-1 orbits at Ω = 2.0");
    for s in &steps {
        for (_, a) in &s.attractors {
            assert_eq!(a.steady.period(), Some(1), "Ω = {}", s.value);
        }
    }
    let high = |s: &ContinuationStep| {
        s.attractors
            .iter()
            .max_by(|a, b| a.1.steady.stats.x_max.total_cmp(&b.1.steady.stats.x_max))
            .map(|(id, _)| *id)
    };
    let mut both = 0;
    for w in steps.windows(2) {
        for (id, a) in &w[1].attractors {
            if let Some((_, b)) = w[0].attractors.iter().find(|(i, _)| i == id) {
                assert!(set_distance(&a.steady, &b.steady) <= DEFAULT_MATCH_TOL);
                let dx = (a.steady.stats.x_max - b.steady.stats.x_max).abs();
                assert!(
                    dx < 0.01,
                    "id {id}: X_max jumps by {dx} at Ω = {}",
                    w[1].value
                );
            }
        }
        if w[0].attractors.len() == 2 && w[1].attractors.len() == 2 {
            assert_eq!(
                high(&w[0]),
                high(&w[1]),
                "ids swapped at Ω = {}",
                w[1].value
            );
            both += 1;
        }
    }
    assert!(both >= 2, "the two orbits coexist over several steps");
}

/// The fractions are the random starts' alone: each random start run to its steady state one
/// by one (`steady_state`, as the census does) and matched to the value's attractors gives the
/// same counts; seeds add attractors but no counts.
#[test]
fn fractions_count_the_random_starts_only() {
    let s = spec(vec![2.04, 2.0], 24);
    let steps = run(&s);
    for step in &steps {
        let params = s.census.params.with(s.param, step.value);
        let model = CantileverModel::new(&params).unwrap();
        let mut counts = vec![0usize; step.attractors.len()];
        for k in 0..s.census.samples {
            let z0 = start_state(&model, s.census.seed, step.value, k as u32);
            let mut it = build(&model, s.census.integrator.clone(), 0.0, &z0).unwrap();
            let st = steady_state(it.as_mut(), &s.census.steady).unwrap();
            let i = step
                .attractors
                .iter()
                .position(|(_, a)| same_attractor(&a.steady, &st, 1e-4))
                .expect("every start reaches one of the value's attractors");
            counts[i] += 1;
        }
        for ((_, a), c) in step.attractors.iter().zip(&counts) {
            assert_eq!(a.count, *c, "Ω = {}", step.value);
            assert!((a.basin_fraction - *c as f64 / s.census.samples as f64).abs() < 1e-15);
        }
    }
    // the layout (attractors-sweep.nc, Python's dataset) holds the document's fractions table
    let layout = afmdyn::report::global_continuation_layout(s.param, &steps);
    assert_eq!(layout.check(), Ok(()));
    let doc = afmdyn::report::global_continuation(&s.census.params, s.param, 24, &steps);
    let table: Vec<f64> = doc["fractions"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|row| row.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()))
        .collect();
    match &layout.variable("basin_fraction").unwrap().values {
        afmdyn::layout::Values::F64(v) => assert_eq!(v, &table),
        v => panic!("basin_fraction: {v:?}"),
    }
}

/// Seeds keep an attractor the random starts miss: at Ω = 2.0 the small-basin orbit (about 3 %
/// of random starts) is not among the steady states of 8 random starts, but continued from
/// Ω = 2.05 (where both orbits are found) it is kept, with count and fraction 0, while the
/// other orbit's count is that of the 8 starts alone.
#[test]
fn seeds_keep_an_attractor_the_random_starts_miss() {
    let seeded = |values: Vec<f64>| {
        let mut s = spec(values, 8);
        s.census.seed = 1;
        run(&s)
    };
    let alone = seeded(vec![2.0]);
    assert_eq!(
        alone[0].attractors.len(),
        1,
        "8 random starts find one orbit"
    );
    let steps = seeded(vec![2.05, 2.0]);
    assert_eq!(steps[0].attractors.len(), 2, "both orbits at Ω = 2.05");
    let at_2 = &steps[1].attractors;
    assert_eq!(at_2.len(), 2, "the seeds keep both orbits at Ω = 2.0");
    let ids: Vec<usize> = at_2.iter().map(|(id, _)| *id).collect();
    let mut before: Vec<usize> = steps[0].attractors.iter().map(|(id, _)| *id).collect();
    let mut after = ids.clone();
    before.sort_unstable();
    after.sort_unstable();
    assert_eq!(before, after, "both continued with their ids");
    let seeded = at_2
        .iter()
        .find(|(_, a)| a.count == 0)
        .expect("one found by a seed only");
    assert_eq!(seeded.1.basin_fraction, 0.0);
    let counted = at_2.iter().find(|(_, a)| a.count > 0).unwrap();
    assert_eq!(counted.1.count, alone[0].attractors[0].1.count);
    assert!(same_attractor(
        &counted.1.steady,
        &alone[0].attractors[0].1.steady,
        1e-6
    ));
}

/// One thread or two: the same continuation, attractor for attractor.
#[test]
fn result_does_not_depend_on_the_thread_count() {
    let s = spec(vec![2.0, 2.03, 2.06], 12);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| run(&s))
    };
    assert_eq!(on(1), on(2));
}
