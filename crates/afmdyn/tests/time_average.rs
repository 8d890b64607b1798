//! The time average of a multifrequency drive (`afmdyn bimodal --average`, and every drive
//! whose ratio is incommensurate): the tapered window's identities, the commensurate orbit
//! against the time average where both apply, and the free response of an incommensurate drive
//! against its closed form.

use afmdyn::analysis::approach::{approach_spec, default_range};
use afmdyn::analysis::observables::{observe, observe_tapered, ObservableOptions};
use afmdyn::analysis::shooting::{shoot, ShootingOptions};
use afmdyn::analysis::stepped::average::{slowest_beat, AverageOptions};
use afmdyn::analysis::stepped::{stepped_sweep, Spacing};
use afmdyn::integrate::{build, IntegratorKind, IntegratorOptions};
use afmdyn::maps::StroboscopicMap;
use afmdyn::probe::{rational_ratio, Probe};
use afmdyn::request::{run, Analysis, ApproachRequest, CurveRequest, Resolved};
use afmdyn::CantileverModel;

use super::common;
use common::opts;

/// The eigenmode model of a 40 N/m lever (as `examples/probe-bimodal.toml`) at lower quality
/// factors, so that a point settles in a few hundred periods; the second component at `f2` (Hz).
fn probe(f2: &str) -> String {
    common::bimodal_lever("1.875e6", "60, 300", f2)
}

/// On a periodic orbit, the tapered (Hann²) window over m ≥ 3 common periods gives the
/// rectangular window's averages: the window's harmonics 1/L and 2/L meet none of the
/// orbit's k/T_c (km = 1 or 2 has no solution for m ≥ 3), so every weighted integral of a
/// periodic integrand equals the unweighted one; and the per-mode balance with
/// energy_change = −∫w′E_j closes to round-off.
#[test]
fn tapered_window_on_an_orbit_is_the_rectangular_one() {
    let probe = Probe::parse(&probe("1.875e6"), "test").unwrap();
    let p = probe.params;
    assert_eq!(p.common_periods(), 4);
    let model = CantileverModel::new(&p).unwrap();
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
    let map = &mut StroboscopicMap::new(it.as_mut(), 1);
    let orbit = shoot(
        map,
        &nalgebra::DVector::zeros(4),
        &ShootingOptions::default(),
    )
    .unwrap();
    assert!(orbit.stable);
    let integ = opts(IntegratorKind::Auto, 1e-12);
    let rect = {
        let mut it = build(&model, integ.clone(), 0.0, &orbit.state).unwrap();
        observe(
            it.as_mut(),
            &ObservableOptions {
                periods: 3,
                harmonics: 3,
            },
        )
        .unwrap()
    };
    let tapered = {
        let mut it = build(&model, integ, 0.0, &orbit.state).unwrap();
        observe_tapered(
            it.as_mut(),
            &ObservableOptions {
                periods: 12,
                harmonics: 3,
            },
        )
        .unwrap()
    };
    assert!(rect.contact_fraction > 0.0, "the orbit taps");
    for (a, b) in rect.components.iter().zip(&tapered.components) {
        assert!(
            (a.amplitude - b.amplitude).abs() < 1e-9 * a.free_amplitude,
            "{a:?} {b:?}"
        );
        assert!((a.phase - b.phase).abs() < 1e-8, "{a:?} {b:?}");
        assert!((a.virial - b.virial).abs() < 1e-8 * a.virial.abs().max(1e-6));
        assert!(
            (a.energy_dissipated - b.energy_dissipated).abs()
                < 1e-8 * a.energy_dissipated.abs().max(1e-6)
        );
    }
    let scale = rect.mean_force.abs().max(rect.peak_force);
    assert!((rect.mean_deflection - tapered.mean_deflection).abs() < 1e-9);
    assert!((rect.energy_dissipated - tapered.energy_dissipated).abs() < 1e-9 * scale);
    assert!((rect.virial - tapered.virial).abs() < 1e-9 * scale);
    assert!((rect.contact_fraction - tapered.contact_fraction).abs() < 1e-9);
    assert_eq!(rect.peak_force, rect.peak_force.max(tapered.peak_force));
    for m in &tapered.mode_balance {
        let size = m.drive.abs().max(m.beam_damping.abs()).max(m.sample.abs());
        assert!(m.residual.abs() < 1e-9 * size, "{m:?}");
        assert!(m.energy_change.abs() < 1e-8 * size, "{m:?}");
    }
}

/// The tapered window off the orbit's period (7 primary periods of a drive repeating every 4):
/// each mode's weighted balance, drive − damping − sample − coupling = −∫w′E_j, closes to
/// round-off although the window is not a period.
#[test]
fn tapered_balance_closes_off_the_period() {
    let probe = Probe::parse(&probe("1.875e6"), "test").unwrap();
    let model = CantileverModel::new(&probe.params).unwrap();
    let mut it = build(&model, IntegratorOptions::default(), 0.0, &model.rest()).unwrap();
    let map = &mut StroboscopicMap::new(it.as_mut(), 1);
    let orbit = shoot(
        map,
        &nalgebra::DVector::zeros(4),
        &ShootingOptions::default(),
    )
    .unwrap();
    let mut it = build(&model, opts(IntegratorKind::Auto, 1e-12), 0.3, &orbit.state).unwrap();
    let o = observe_tapered(
        it.as_mut(),
        &ObservableOptions {
            periods: 7,
            harmonics: 2,
        },
    )
    .unwrap();
    for m in &o.mode_balance {
        let size = m.drive.abs().max(m.beam_damping.abs()).max(m.sample.abs());
        assert!(m.residual.abs() < 1e-8 * size, "{m:?}");
    }
}

/// Commensurate and incommensurate agree where both apply: at f₂ = 6.25 f₁ the approach
/// curve's exact orbits of the common period (4 drive periods) and the time average of the
/// same drive (`average`) give each component's amplitude and phase within the time
/// average's own error estimate (plus 1e-6 of the free amplitude for the orbits' tolerance),
/// out of contact and tapping; every averaged point settled.
#[test]
fn commensurate_orbits_and_time_average_agree() {
    let probe = Probe::parse(&probe("1.875e6"), "test").unwrap();
    let p = probe.params;
    let (far, near) = default_range(&p).unwrap();
    let spec = {
        let mut s = approach_spec(p, far, 0.5 * (far + near), Spacing::Points(5)).unwrap();
        s.branches = false;
        s
    };
    let exact = stepped_sweep(&spec).unwrap();
    let request = ApproachRequest {
        curve: CurveRequest {
            from: Some(far),
            to: Some(0.5 * (far + near)),
            points: Some(5),
            branches: false,
            ..CurveRequest::default()
        },
        setpoint: None,
        average: true,
        exact: false,
        ..ApproachRequest::default()
    };
    let model = Resolved {
        params: p,
        probe: None,
    };
    let averaged = request.execute(&model, &Default::default()).unwrap();
    let opts = averaged.average.expect("measured by the time average");
    assert!(opts.window_periods >= 16);
    let mut tapping = 0;
    for (e, a) in exact.first.iter().zip(&averaged.first) {
        assert_eq!(e.value, a.value);
        let est = a.average.as_ref().expect("an estimate per point");
        assert!(est.settled, "{est:?}");
        tapping += usize::from(e.observables.contact_fraction > 0.0);
        for (i, (ce, ca)) in e
            .observables
            .components
            .iter()
            .zip(&a.observables.components)
            .enumerate()
        {
            let allowed = est.amplitude_error[i] + 1e-6 * ce.free_amplitude;
            assert!((ce.amplitude - ca.amplitude).abs() <= allowed);
            assert!((ce.phase - ca.phase).abs() <= allowed / ce.amplitude);
        }
    }
    assert!(tapping >= 2, "the range reaches the sample");
}

/// An incommensurate ratio — no fraction p/q with q ≤ 1000 within 1e-6 — becomes the
/// convergent with q ≤ 10⁶ (within 1e-12): the drive is quasi-periodic, every periodic
/// analysis refuses it naming the ratio, and the approach curve measures it by the time
/// average without being asked; far from the sample each component's amplitude and phase are
/// the free response's (the closed form of the linear system, `free_force_response`) within
/// the estimate.
#[test]
fn incommensurate_drive_is_averaged() {
    let f2 = 300e3 * (6.25 + std::f64::consts::SQRT_2 * 1e-2);
    assert!(rational_ratio(f2 / 300e3).is_none());
    let probe = Probe::parse(&probe(&format!("{f2:.6}")), "test").unwrap();
    let p = probe.params;
    assert!(p.is_quasiperiodic());
    let used = probe.components[0].frequency;
    assert!((used / f2 - 1.0).abs() < 1e-11, "{used} {f2}");
    let e = CantileverModel::new(&p).unwrap_err().to_string();
    assert!(e.contains("drive_components.ratio"), "{e}");
    let model = Resolved {
        params: p,
        probe: None,
    };
    let (far, _) = default_range(&p).unwrap();
    let request = ApproachRequest {
        curve: CurveRequest {
            from: Some(far * 100.0),
            to: Some(far * 99.0),
            points: Some(2),
            ..CurveRequest::default()
        },
        ..ApproachRequest::default()
    };
    let done = run(&request, &model, &Default::default()).unwrap();
    let (curve, doc) = (done.output, done.json);
    assert!(curve.average.is_some());
    assert!(curve.branches.is_empty());
    assert!(doc["time_average"]["approach"]["settled"][0]
        .as_bool()
        .unwrap());
    for pt in curve.first.iter().chain(&curve.second) {
        let est = pt.average.as_ref().unwrap();
        assert!(est.settled);
        for (i, c) in pt.observables.components.iter().enumerate() {
            assert!(c.ratio > 1.0 || i == 0);
            assert!(
                (c.amplitude - c.free_amplitude).abs()
                    <= est.amplitude_error[i] + 1e-9 * c.free_amplitude,
                "{c:?} {est:?}"
            );
            assert!(est.amplitude_error[i] < 1e-4 * c.free_amplitude, "{est:?}");
            assert!((c.phase - c.free_phase).abs() <= est.phase_error[i] + 1e-9);
        }
    }
}

/// The slowest beat of the combination tones: at f₂ = 1761/281 f₁ (mode 2 at 1.88007 MHz) the
/// best fraction with q ≤ 32 is 94/15, 1/4215 away, so the tone 15 f₂ − 94 f₁ beats every
/// 1/(15 · 1/4215) = 281 primary periods — the common period; the default settling window
/// holds four such beats. At 25/4 exactly there is no beat.
#[test]
fn slowest_beat_of_a_near_commensurate_ratio() {
    let p = Probe::parse(&probe("1.88007e6"), "test").unwrap().params;
    assert_eq!(p.common_periods(), 281);
    let (a, b, r, beat) = slowest_beat(&p).expect("a beat");
    assert_eq!((a, b), (94, 15));
    assert!((r - 1761.0 / 281.0).abs() < 1e-12, "{r}");
    assert!((beat - 281.0).abs() < 1e-6, "{beat}");
    let opts = AverageOptions::for_model(&CantileverModel::new(&p).unwrap());
    assert!(opts.window_periods >= 4 * 281, "{opts:?}");
    let p = Probe::parse(&probe("1.875e6"), "test").unwrap().params;
    assert!(slowest_beat(&p).is_none());
}
