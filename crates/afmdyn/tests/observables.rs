//! Observables of a steady state (`analysis::observables`): closed-form free response, exact
//! period balances of the point-mass model, the per-mode energy balance of the beam.

use afmdyn::analysis::observables::{observe_from, ObservableOptions};
use afmdyn::integrate::IntegratorOptions;
use afmdyn::{CantileverModel, Params, Structure};

#[test]
fn smoke() {
    let params = Params {
        structure: Structure::PointMass,
        modes: 1,
        alpha1: 0.0,
        alpha2: 0.01,
        alpha3: 0.01,
        alpha5: 100.0,
        omega: 1.0,
        ..Params::default()
    };
    let model = CantileverModel::new(&params).unwrap();
    let z0 = model.state_from(&[0.0], &[0.0]).unwrap();
    let o = observe_from(
        &model,
        IntegratorOptions::default(),
        0.0,
        &z0,
        &ObservableOptions::default(),
    )
    .unwrap();
    println!("{o:#?}");
}
