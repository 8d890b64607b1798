//! The shared result documents (`afmdyn::report`) and the cancellation hook of the sweep.

use afmdyn::analysis::bifurcation::{run_sweep_cancellable, Resume, SweepSpec};
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::steady::{steady_state, SteadyOptions};
use afmdyn::eigen::spectrum;
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::{report, CantileverModel, Params, SweepParam};
use nalgebra::DVector;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

fn sweep(steps: usize) -> SweepSpec {
    SweepSpec {
        base: Params::default(),
        param: SweepParam::Omega,
        values: SweepSpec::linspace(2.0, 4.0, steps).unwrap(),
        continuation: true,
        starts: 1,
        seed: 1,
        steady: SteadyOptions::default(),
        integrator: IntegratorOptions::default(),
    }
}

#[test]
fn a_cancelled_sweep_starts_no_point() {
    let count = AtomicUsize::new(0);
    let cancel = AtomicBool::new(true);
    run_sweep_cancellable(
        &sweep(8),
        &Resume::default(),
        &|_| {
            count.fetch_add(1, Ordering::Relaxed);
        },
        &cancel,
    );
    assert_eq!(count.load(Ordering::Relaxed), 0);
}

#[test]
fn cancelling_mid_sweep_stops_it_early() {
    // 40 values × (forward + backward + 1 start) = 120 points when run to the end
    let spec = sweep(40);
    let count = AtomicUsize::new(0);
    let cancel = AtomicBool::new(false);
    run_sweep_cancellable(
        &spec,
        &Resume::default(),
        &|_| {
            if count.fetch_add(1, Ordering::Relaxed) + 1 >= 3 {
                cancel.store(true, Ordering::Relaxed);
            }
        },
        &cancel,
    );
    let n = count.load(Ordering::Relaxed);
    // at most one point per worker thread is still running when the flag is set
    #[cfg(feature = "parallel")]
    let workers = rayon::current_num_threads();
    #[cfg(not(feature = "parallel"))]
    let workers = 1;
    assert!(
        (3..3 + workers + 1).contains(&n),
        "{n} points with {workers} workers"
    );
}

#[test]
fn orbit_document_carries_the_orbit_and_its_parameters() {
    let p = Params {
        omega: 2.8,
        ..Params::default()
    };
    let model = CantileverModel::new(&p).unwrap();
    let mut integ = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
    let s = steady_state(integ.as_mut(), &SteadyOptions::default()).unwrap();
    let mut fresh = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
    let two = ShootingOptions::default().with_period(2);
    let map = &mut StroboscopicMap::new(fresh.as_mut(), 1);
    let o = shoot(map, s.end_state(), &two).unwrap();
    let doc = report::orbit(&model, &o);
    assert_eq!(doc["period"], 2);
    assert_eq!(doc["params"]["omega"], 2.8);
    assert_eq!(doc["multipliers"].as_array().unwrap().len(), 6);
    assert_eq!(doc["stable"], o.stable);
    let w = doc["poincare"]["w_tip"].as_array().unwrap();
    assert_eq!(w[1].as_f64().unwrap(), model.w_tip(&o.section[1]));
    let state: Vec<f64> = doc["state"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert_eq!(state, o.state.as_slice());
}

#[test]
fn modes_document_lists_both_regions() {
    let p = Params::default();
    let (free, contact) = spectrum(&p).unwrap();
    let doc = report::modes(&p, &free, &contact);
    assert_eq!(doc["params"]["modes"], 3);
    let w = doc["contact"]["omega"].as_array().unwrap();
    assert_eq!(w.len(), 3);
    assert_eq!(w[0].as_f64().unwrap(), contact.omega[0]);
    assert_eq!(
        doc["free"]["eigenvalues"][2][1].as_f64().unwrap(),
        free.eigenvalues[2].im
    );
}

#[test]
fn initial_modal_is_displacements_then_velocities() {
    let z = DVector::from_vec(vec![0.5, -1.25, 3.0, 1e-20]);
    assert_eq!(
        report::initial_modal(Some(&z)),
        "0.5,-1.25;3,0.00000000000000000001"
    );
    assert_eq!(report::initial_modal(None), "");
}

/// Issue 77 item 3: the door's audit of a document names every result array with missing
/// values (NaN written as null) and how many, leaves the nulls that are a state (a
/// nonperiodic `period`), the SI block and the messages alone, and refuses a document whose
/// every result array is missing throughout.
#[test]
fn the_door_names_missing_values_and_refuses_a_document_of_none() {
    use afmdyn::report::audit_missing;
    use serde_json::json;
    let mut doc = json!({
        "curve": {"force": [1.0, null, 3.0], "distance": [1.0, 2.0, 3.0], "period": [1, null, 2]},
        "si": {"x": [null]},
        "message": [null, null, null],
        "warnings": []
    });
    audit_missing(&mut doc, "test").unwrap();
    let w = doc["warnings"].as_array().unwrap();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0]
        .as_str()
        .unwrap()
        .starts_with("curve.force: 1 of 3 values are missing"));
    let mut none = json!({"image": {"height": [null, null], "phase": [[null], [null]]}});
    let e = audit_missing(&mut none, "image").unwrap_err();
    assert!(matches!(e, afmdyn::SimError::NoFiniteValue { .. }), "{e}");
    assert!(e.to_string().contains("image.height"), "{e}");
    // a document of scalars only is not audited
    let mut scalars = json!({"period": 1, "stable": true});
    audit_missing(&mut scalars, "orbit").unwrap();
}
