//! The samples of a recording formed from the steps' dense output (`trajectory::record_rows`:
//! the integrator takes its own steps, `Integrator::dense_states_into` forms the samples inside
//! them; for the exact propagator a sequence of modal products, `integrate/exact/sample.rs`)
//! against the samples of the path before it: a step ended at every sample time and the
//! integrator's state there (`Integrator::step` up to τ_i, then `Sample::new` from the state).
//! Both with the exact propagator (modal and dense propagation) and with the adaptive
//! integrator; and the energy balance of the recording closes.

use afmdyn::integrate::exact::{ExactOptions, ExactPropagator, Propagation};
use afmdyn::integrate::{advance, build, Integrator, IntegratorKind, IntegratorOptions};
use afmdyn::trajectory::{energy_residual, record, RecordSpec, Sample};
use afmdyn::{CantileverModel, Params};

/// The samples τ_i = start + i·T/S, i = 0..=count, of a step ended at each (the reference).
fn samples_by_ending_steps(
    integ: &mut dyn Integrator,
    model: &CantileverModel,
    transient: f64,
    spp: usize,
    count: usize,
) -> Vec<Sample> {
    let period = model.period();
    let start = integ.tau() + transient * period;
    advance(integ, start).unwrap();
    let dt = period / spp as f64;
    (0..=count)
        .map(|i| {
            let t = start + i as f64 * dt;
            while integ.tau() < t && (t - integ.tau()) > 1e-12 * (1.0 + t) {
                integ.step(t).unwrap();
            }
            Sample::new(model, integ.region(), integ.tau(), integ.state())
        })
        .collect()
}

/// Largest difference of the samples' values (τ, V_T, W, Ẇ, F_c, state) relative to each
/// quantity's largest magnitude over the run (the state's entries to the largest entry, the tip
/// values at least to the largest sum of the magnitudes of their terms); the regions must agree.
fn worst_difference(m: &CantileverModel, got: &[Sample], expected: &[Sample]) -> f64 {
    assert_eq!(got.len(), expected.len());
    let values = |s: &Sample| {
        let mut v = vec![s.tau, s.v_t, s.w_tip, s.w_tip_dot, s.contact_force];
        v.extend(s.state.iter());
        v
    };
    let width = values(&expected[0]).len();
    let mut scale: Vec<f64> = (0..width)
        .map(|j| {
            expected
                .iter()
                .map(|s| values(s)[j].abs())
                .fold(1e-300, f64::max)
        })
        .collect();
    // the state's entries relative to the state's size (a fast mode's own amplitude is small);
    // the tip values (sums Σ φ_j(1) a_j) at least relative to the size of their terms
    let n = m.modes();
    let terms = |offset: usize| -> f64 {
        let tip = m.tip();
        (0..n).map(|j| tip[j].abs() * scale[5 + offset + j]).sum()
    };
    let (w_terms, wd_terms) = (terms(0), terms(n));
    let p = m.params();
    scale[1] = scale[1].max(w_terms);
    scale[2] = scale[2].max(w_terms);
    scale[3] = scale[3].max(wd_terms);
    scale[4] = scale[4].max(p.alpha4.abs() * w_terms + p.alpha6.abs() * wd_terms);
    let state = scale[5..].iter().copied().fold(0.0, f64::max);
    scale[5..].fill(state);
    let mut worst = 0.0f64;
    for (g, e) in got.iter().zip(expected) {
        // a sample at V_T = 0 to round-off may fall on either side
        if e.v_t.abs() > 1e-9 {
            assert_eq!(g.region, e.region, "at τ = {}", e.tau);
        }
        for (j, (a, b)) in values(g).iter().zip(values(e)).enumerate() {
            let d = if j == 0 {
                // the time: within ulps of τ
                (a - b).abs() / (1.0 + b.abs()) * 1e3
            } else if j == 4 && e.v_t.abs() <= 1e-9 {
                0.0
            } else {
                (a - b).abs() / scale[j]
            };
            worst = worst.max(d);
        }
    }
    worst
}

fn model(omega: f64, modes: usize) -> CantileverModel {
    CantileverModel::new(&Params {
        modes,
        omega,
        ..Params::default()
    })
    .unwrap()
}

fn exact(m: &CantileverModel, propagation: Propagation) -> ExactPropagator {
    ExactPropagator::try_with(
        m,
        ExactOptions {
            propagation,
            ..ExactOptions::default()
        },
    )
    .unwrap()
}

/// The exact propagator's dense samples equal the states of steps ended at the sample times to
/// ≤ 1e-12 of each quantity's scale: N = 1, 3, 10, the chaotic default attractor (Ω = 2.6, a
/// few periods, before round-off grows) and periodic ones (Ω = 3.5, 5), sample counts that
/// divide the grid and that do not (200, 7, 333), modal and dense propagation (3e-12 for the
/// dense one at N = 10); the energy balance closes to ≤ 1e-9 relative.
#[test]
fn dense_samples_equal_the_states_of_steps_ended_there() {
    for (omega, modes, periods) in [
        (2.6, 3, 3.0),
        (3.5, 3, 20.0),
        (5.0, 1, 20.0),
        (5.0, 10, 5.0),
        (2.6, 10, 1.0),
    ] {
        let m = model(omega, modes);
        for propagation in [Propagation::Auto, Propagation::Dense] {
            for spp in [200usize, 7, 333] {
                let count = (periods * spp as f64).round() as usize;
                let spec = RecordSpec {
                    transient_periods: 2.0,
                    record_tau: periods * m.period(),
                    samples_per_period: spp,
                    energy: true,
                    body_contact: true,
                };
                let mut a = exact(&m, propagation);
                a.reset(0.0, &m.rest()).unwrap();
                let tr = record(&mut a, &spec).unwrap();
                let mut b = exact(&m, propagation);
                b.reset(0.0, &m.rest()).unwrap();
                let reference = samples_by_ending_steps(&mut b, &m, 2.0, spp, count);
                let worst = worst_difference(&m, &tr.samples, &reference);
                let case = format!("Ω = {omega}, N = {modes}, {propagation:?}, {spp} per period");
                // a dense grid step's dense output goes through the eigenbasis (the projection
                // of δz, as `Integrator::dense_state` has always done): its condition number
                // (up to 1e4 at N = 10) adds to the round-off there
                let bound = match propagation {
                    Propagation::Dense if modes > 3 => 3e-12,
                    _ => 1e-12,
                };
                assert!(worst <= bound, "{case}: {worst:e}");
                let (_, rel) = energy_residual(&tr.energy);
                assert!(rel <= 1e-9, "{case}: energy residual {rel:e}");
                assert_eq!(tr.energy.len(), periods as usize, "{case}");
            }
        }
    }
}

/// The other integrators record through the same path (their own dense output): the adaptive
/// integrator's samples against its steps ended at the sample times (to its tolerance), and
/// against the exact propagator's samples.
#[test]
fn adaptive_dense_samples_equal_its_steps_and_the_exact_samples() {
    let m = model(3.5, 3);
    let spec = RecordSpec {
        transient_periods: 1.0,
        record_tau: 5.0 * m.period(),
        samples_per_period: 50,
        energy: true,
        body_contact: true,
    };
    let opts = IntegratorOptions {
        kind: IntegratorKind::Adaptive,
        tolerance: 1e-12,
        ..IntegratorOptions::default()
    };
    let mut a = build(&m, opts.clone(), 0.0, &m.rest()).unwrap();
    let tr = record(a.as_mut(), &spec).unwrap();
    let mut b = build(&m, opts, 0.0, &m.rest()).unwrap();
    let reference = samples_by_ending_steps(b.as_mut(), &m, 1.0, 50, 250);
    let worst = worst_difference(&m, &tr.samples, &reference);
    assert!(worst <= 1e-9, "adaptive: {worst:e}");
    let mut e = exact(&m, Propagation::Auto);
    e.reset(0.0, &m.rest()).unwrap();
    let exact_tr = record(&mut e, &spec).unwrap();
    let worst = worst_difference(&m, &tr.samples, &exact_tr.samples);
    assert!(worst <= 1e-8, "adaptive against exact: {worst:e}");
    let (_, rel) = energy_residual(&tr.energy);
    assert!(rel <= 1e-8, "adaptive energy residual {rel:e}");
}
