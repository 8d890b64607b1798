//! Batched exact propagation (issue 11, item 3): [`ExactBatch`] must give, lane by lane, the
//! states, regions, times and errors of advancing each lane alone with
//! [`Integrator::advance_to`] — bit for bit, since every lane's arithmetic is the scalar
//! propagator's — on the dense kernel (N = 3, fixed size; N = 8 forced dense, dynamic size),
//! the modal path (N = 8), the point mass (N = 1), from starts on and off the grid, with
//! inactive lanes and end times on and off the grid. The chaotic attractor at Ω = 2.6 is used
//! on purpose: any difference of one ulp in any lane would grow to O(1) within the run.

use afmdyn::analysis::bifurcation::random_state;
use afmdyn::integrate::exact::{ExactBatch, ExactOptions, ExactPropagator, Propagation};
use afmdyn::integrate::Integrator;
use afmdyn::{CantileverModel, Params, Structure};

fn check(p: &Params, propagation: Propagation, lanes: usize, off_grid: bool) -> usize {
    let model = CantileverModel::new(p).unwrap();
    let proto = ExactPropagator::try_with(
        &model,
        ExactOptions {
            propagation,
            ..ExactOptions::default()
        },
    )
    .unwrap();
    let period = model.period();
    let mut batch = ExactBatch::new(&proto);
    let mut alone = Vec::new();
    for i in 0..lanes {
        let z0 = random_state(&model, 11, i as u64);
        let tau0 = if off_grid { 0.137 * i as f64 } else { 0.0 };
        assert_eq!(batch.push(tau0, &z0).unwrap(), i);
        let mut s = proto.clone();
        s.reset(tau0, &z0).unwrap();
        alone.push(s);
    }
    // every third lane sits out the second leg
    let all = vec![true; lanes];
    let some: Vec<bool> = (0..lanes).map(|i| i % 3 != 1).collect();
    let legs = [
        (0.37 * period, &all),
        (20.0 * period, &some),
        (20.5 * period + 0.01, &all),
        (60.0 * period, &all),
    ];
    let mut events = 0;
    for (tau_end, active) in legs {
        let results = batch.advance_to(tau_end, active).unwrap();
        for (i, single) in alone.iter_mut().enumerate() {
            let want = if active[i] {
                single.advance_to(tau_end).map_err(|e| e.to_string())
            } else {
                Ok(())
            };
            let got = results[i].as_ref().map_err(|e| e.to_string());
            assert_eq!(got.cloned(), want, "lane {i} to {tau_end}");
            let lane = batch.lane(i);
            assert_eq!(lane.tau(), single.tau(), "lane {i} τ at {tau_end}");
            assert_eq!(lane.region(), single.region(), "lane {i} region");
            assert_eq!(
                lane.state().as_slice(),
                single.state().as_slice(),
                "lane {i} state at {tau_end}"
            );
        }
    }
    // the lanes went through switchings (else the test would only exercise grid steps)
    for single in &mut alone {
        let tau = single.tau();
        let mut before = single.region();
        while single.tau() < tau + 5.0 * period {
            let step = single.step(tau + 5.0 * period).unwrap();
            if step.region != before || step.event.is_some() {
                events += 1;
            }
            before = single.region();
        }
    }
    events
}

#[test]
fn batch_equals_lanes_alone_dense_fixed_kernel() {
    let n = check(&Params::default(), Propagation::Dense, 9, false);
    assert!(n > 0);
}

#[test]
fn batch_equals_lanes_alone_from_off_grid_starts() {
    check(&Params::default(), Propagation::Auto, 7, true);
    check(&Params::default(), Propagation::Dense, 5, true);
}

#[test]
fn batch_equals_lanes_alone_modal() {
    let p = Params {
        modes: 8,
        ..Params::default()
    };
    check(&p, Propagation::Auto, 6, false);
    check(&p, Propagation::Auto, 5, true);
    check(&Params::default(), Propagation::Auto, 6, false);
}

#[test]
fn batch_equals_lanes_alone_dense_dynamic_kernel() {
    let p = Params {
        modes: 8,
        ..Params::default()
    };
    check(&p, Propagation::Dense, 5, false);
}

#[test]
fn batch_equals_lanes_alone_point_mass() {
    let p = Params {
        modes: 1,
        structure: Structure::PointMass,
        alpha1: 0.0,
        alpha2: 0.1,
        alpha3: 0.1,
        alpha4: 10.0,
        alpha5: 0.5,
        omega: 1.0,
        ..Params::default()
    };
    check(&p, Propagation::Auto, 6, true);
}

#[test]
fn batch_rejects_bad_arguments() {
    let model = CantileverModel::new(&Params::default()).unwrap();
    let proto = ExactPropagator::try_new(&model, 1).unwrap();
    let mut batch = ExactBatch::new(&proto);
    let z0 = random_state(&model, 1, 0);
    batch.push(0.0, &z0).unwrap();
    let e = batch.advance_to(f64::NAN, &[true]).unwrap_err().to_string();
    assert!(e.contains("tau_end"), "{e}");
    let e = batch
        .advance_to(1.0, &[true, true])
        .unwrap_err()
        .to_string();
    assert!(e.contains("active lanes"), "{e}");
    let bad = nalgebra::DVector::from_element(5, 0.0);
    assert!(batch.push(0.0, &bad).is_err());
    assert_eq!(batch.len(), 1);
}

/// The batched steady-state search gives each lane's [`steady_state`] alone, bit for bit
/// (transient length, classification, section points, statistics), on the chaotic attractor
/// and on a periodic one (Ω = 3.5), with a lane started off the section.
#[test]
fn batched_steady_states_equal_lanes_alone() {
    use afmdyn::analysis::steady::{steady_state, steady_states, SteadyOptions};
    for omega in [2.6, 3.5] {
        let p = Params {
            omega,
            ..Params::default()
        };
        let model = CantileverModel::new(&p).unwrap();
        let proto = ExactPropagator::try_new(&model, 1).unwrap();
        let opts = SteadyOptions {
            max_periods: 300,
            nonperiodic_record: 8,
            ..SteadyOptions::default()
        };
        let mut batch = ExactBatch::new(&proto);
        let mut alone = Vec::new();
        for i in 0..6 {
            let z0 = random_state(&model, 5, i);
            let tau0 = if i == 4 { 0.3 } else { 0.0 };
            batch.push(tau0, &z0).unwrap();
            let mut s = proto.clone();
            s.reset(tau0, &z0).unwrap();
            alone.push(steady_state(&mut s, &opts).map_err(|e| e.to_string()));
        }
        let got: Vec<_> = steady_states(&mut batch, &opts)
            .unwrap()
            .into_iter()
            .map(|r| r.map_err(|e| e.to_string()))
            .collect();
        assert_eq!(got, alone, "Ω = {omega}");
        if omega == 3.5 {
            assert!(got
                .iter()
                .all(|r| r.as_ref().is_ok_and(|s| s.period() == Some(1))));
        }
    }
}
