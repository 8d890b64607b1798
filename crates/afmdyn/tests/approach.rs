//! The approach–retract curve and its branches (`analysis::approach`, `analysis::stepped`):
//! identities that hold for any correct stepped sweep and continuation.
//!
//! The case is the example probe `examples/probe-point-mass-dmt.toml` (point-mass model, DMT
//! contact, Q = 400, A0 = 10 nm, lengths in units of A0): tapping mode with coexisting
//! attractive and repulsive states (García & San Paulo, *Phys. Rev. B* 60 (1999) 4961), so the
//! approach and the retract jump at the two folds bounding the bistable range.

use afmdyn::analysis::approach::{approach_retract, approach_spec, rest_distance};
use afmdyn::analysis::continuation::BranchEvent;
use afmdyn::analysis::resonance::{mode_band, resonance_spec};
use afmdyn::analysis::stepped::stepped_sweep;
use afmdyn::analysis::stepped::{
    grid, is_fixed_point, BranchSample, Reached, Spacing, SteppedCurve, SteppedSpec, Sweep,
};
use afmdyn::probe::Probe;
use afmdyn::{Params, SimError};
use std::path::Path;
use std::sync::OnceLock;

const POINTS: usize = 41;

fn probe_params() -> Params {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml");
    Probe::load(&path).expect("example probe").params
}

/// The curve from z_c = 1.2 A0 to 0.2 A0 in 40 steps (0.025 A0), computed once.
fn curve() -> &'static (SteppedSpec, SteppedCurve) {
    static CURVE: OnceLock<(SteppedSpec, SteppedCurve)> = OnceLock::new();
    CURVE.get_or_init(|| {
        let base = probe_params();
        let spec = approach_spec(base, 1.2, 0.2, Spacing::Points(POINTS)).expect("spec");
        let c = approach_retract(&spec).expect("approach");
        (spec, c)
    })
}

fn step() -> f64 {
    let (spec, _) = curve();
    (spec.values[1] - spec.values[0]).abs()
}

/// The stable branch sample pair around `value` whose interpolated section state is nearest
/// to `z`, with the interpolated amplitude: (relative state gap, amplitude).
fn nearest_on_branches(
    branches: &[Vec<BranchSample>],
    value: f64,
    z: &nalgebra::DVector<f64>,
) -> Option<(f64, f64)> {
    let mut best: Option<(f64, f64)> = None;
    for b in branches {
        for w in b.windows(2) {
            let (p, q) = (&w[0], &w[1]);
            let (lo, hi) = (
                p.point.value.min(q.point.value),
                p.point.value.max(q.point.value),
            );
            if !(p.point.stable && q.point.stable && (lo..=hi).contains(&value)) || lo == hi {
                continue;
            }
            let t = (value - p.point.value) / (q.point.value - p.point.value);
            let zi = &p.point.section[0] + (&q.point.section[0] - &p.point.section[0]) * t;
            let gap = (&zi - z).norm() / (1.0 + z.norm());
            let amp =
                p.observables.amplitude + (q.observables.amplitude - p.observables.amplitude) * t;
            if best.is_none_or(|(g, _)| gap < g) {
                best = Some((gap, amp));
            }
        }
    }
    best
}

#[test]
fn every_stable_point_is_a_fixed_point_of_the_map() {
    let (spec, c) = curve();
    let mut checked = 0;
    for p in c.first.iter().chain(&c.second) {
        let n = p.period.expect("period-1 orbits throughout this curve");
        assert!(p.stable);
        assert!(
            is_fixed_point(spec, p.value, &p.state, n, 1e-8).unwrap(),
            "sweep point at α5 = {}",
            p.value
        );
        checked += 1;
    }
    for s in c.branches.iter().flatten().filter(|s| s.point.stable) {
        assert!(
            is_fixed_point(
                spec,
                s.point.value,
                &s.point.section[0],
                s.point.period,
                1e-8
            )
            .unwrap(),
            "branch point at α5 = {}",
            s.point.value
        );
        checked += 1;
    }
    assert!(checked > 2 * POINTS);
}

#[test]
fn stepped_sweeps_lie_on_stable_branches() {
    let (_, c) = curve();
    assert!(!c.branches.is_empty(), "warnings: {:?}", c.warnings);
    let mut checked = 0;
    for p in c.first.iter().chain(&c.second) {
        // a branch ends at its last point inside the range: the sweep's end values may lie
        // beyond it
        let Some((gap, amp)) = nearest_on_branches(&c.branches, p.value, &p.state) else {
            continue;
        };
        checked += 1;
        // interpolation between branch points (arclength steps ≤ range/25) is the only error
        assert!(gap < 5e-3, "α5 = {}: state gap {gap:e}", p.value);
        assert!(
            (amp - p.observables.amplitude).abs() < 5e-3,
            "α5 = {}: A = {} on the sweep, {amp} on the branch",
            p.value,
            p.observables.amplitude
        );
    }
    assert!(checked >= 2 * POINTS - 4, "{checked} points on branches");
}

#[test]
fn the_bistable_range_is_bounded_by_two_folds() {
    let (_, c) = curve();
    assert_eq!(c.folds.len(), 2, "folds {:?}", c.folds);
    assert_eq!(c.bistable.len(), 1, "bistable {:?}", c.bistable);
    let (lo, hi) = c.bistable[0];
    assert_eq!((lo, hi), (c.folds[0], c.folds[1]));
    // approach and retract differ exactly inside the bistable range (up to one grid step)
    let h = step();
    for (a, r) in c.first.iter().zip(c.second.iter().rev()) {
        assert_eq!(a.value, r.value);
        let differ = (&a.state - &r.state).norm() > 1e-3 * (1.0 + a.state.norm());
        let inside = a.value > lo + h && a.value < hi - h;
        let outside = a.value < lo - h || a.value > hi + h;
        if inside {
            assert!(differ, "α5 = {} inside [{lo}, {hi}]: one state", a.value);
        }
        if outside {
            assert!(!differ, "α5 = {} outside [{lo}, {hi}]: two states", a.value);
        }
    }
    // the unstable branch between the folds: every fold joins a stable and an unstable part
    let br = &c.branches[0];
    for (i, s) in br.iter().enumerate() {
        if s.point.event == Some(BranchEvent::Fold) {
            let before = br[..i].iter().rev().find(|x| x.point.event.is_none());
            let after = br[i + 1..].iter().find(|x| x.point.event.is_none());
            let (b, a) = (before.expect("point before"), after.expect("point after"));
            assert_ne!(b.point.stable, a.point.stable, "fold at {}", s.point.value);
        }
    }
}

#[test]
fn each_sweep_jumps_once_at_a_fold_within_one_step() {
    let (spec, c) = curve();
    let h = step();
    for (sweep, fold) in [(Sweep::First, c.folds[0]), (Sweep::Second, c.folds[1])] {
        let jumps: Vec<_> = c.jumps.iter().filter(|j| j.sweep == sweep).collect();
        assert_eq!(jumps.len(), 1, "{sweep:?}: {jumps:?}");
        let j = jumps[0];
        assert_eq!(j.fold, Some(fold));
        assert!(
            (j.from - fold).abs() <= h && (j.to - fold).abs() <= h,
            "{j:?}"
        );
        // the approach jumps towards the sample from the attractive to the repulsive state
        let pts = match sweep {
            Sweep::First => &c.first,
            Sweep::Second => &c.second,
        };
        assert_eq!(pts[j.index].reached, Reached::Settled);
        let (before, after) = (&pts[j.index - 1], &pts[j.index]);
        let ninety = std::f64::consts::FRAC_PI_2;
        match sweep {
            Sweep::First => {
                assert!(before.observables.phase > ninety && after.observables.phase < ninety)
            }
            Sweep::Second => {
                assert!(before.observables.phase < ninety && after.observables.phase > ninety)
            }
        }
    }
    // in z_c: the approach jumps at the lower fold, the retract at the upper one
    let zc = |a5| rest_distance(&spec.base, a5);
    assert!(zc(c.folds[0]) < zc(c.folds[1]));
}

#[test]
fn far_from_the_sample_the_resonance_curve_is_the_linear_one() {
    // the free oscillator (the sample 1e3 A0 away): every point of the up- and down-sweep has
    // the closed-form free amplitude A0(Ω) = α2/√((1 − Ω²)² + (α3 Ω)²) (point mass)
    let base = Params {
        alpha5: 1e3,
        ..probe_params()
    };
    let (lo, hi) = mode_band(&base, 1).unwrap();
    let mut spec = resonance_spec(base, lo, hi, Spacing::Points(9)).unwrap();
    spec.branches = false;
    let c = stepped_sweep(&spec).unwrap();
    assert!(c.jumps.is_empty());
    for p in c.first.iter().chain(&c.second) {
        let om = p.value;
        let a0 = base.alpha2 / f64::hypot(1.0 - om * om, base.alpha3 * om);
        assert!(
            (p.observables.amplitude - a0).abs() <= 1e-6 * a0,
            "Ω = {om}: A = {}, closed form {a0}",
            p.observables.amplitude
        );
    }
}

#[test]
fn bad_grids_are_refused_with_the_field_named() {
    let named = |r: Result<Vec<f64>, SimError>, field: &str| match r {
        Err(SimError::OutOfRange { name, .. }) => assert_eq!(name, field),
        other => panic!("expected an error naming {field}, got {other:?}"),
    };
    named(grid(1.0, 0.0, Spacing::Points(1)), "points");
    named(grid(1.0, 0.0, Spacing::Points(100_001)), "points");
    named(grid(1.0, 0.0, Spacing::Step(0.0)), "step");
    named(grid(1.0, 0.0, Spacing::Step(-1.0)), "step");
    named(grid(1.0, 0.0, Spacing::Step(1e-9)), "step");
    named(grid(1.0, 0.0, Spacing::Step(2.0)), "step");
    named(grid(1.0, 1.0, Spacing::Points(10)), "to");
    assert!(matches!(
        grid(f64::NAN, 0.0, Spacing::Points(10)),
        Err(SimError::NotFinite { name: "from", .. })
    ));
    assert_eq!(grid(1.0, 0.0, Spacing::Step(0.25)).unwrap().len(), 5);
    let base = probe_params();
    assert!(matches!(
        mode_band(&base, 2),
        Err(SimError::OutOfRange { name: "mode", .. })
    ));
}

/// The setpoint's operating points (`analysis::setpoint`): at A/A₀ = 0.85 the curve has one
/// on the attractive and one on the repulsive branch (phase above and below 90°: García & San
/// Paulo 2000); each lies on a stable stretch; and the orbit found by Newton shooting at the
/// point's z_c, from the branch states interpolated there, has A/A₀ within 2e-4 of the setpoint
/// (measured 3.5e-5 and 1.3e-7: the interpolation's error at this spacing).
#[test]
fn setpoint_points_are_orbits_with_the_setpoint_amplitude() {
    use afmdyn::analysis::observables::observe_orbit;
    use afmdyn::analysis::setpoint::{setpoint_crossings, Source};
    use afmdyn::analysis::shooting::{shoot, ShootingOptions};
    use afmdyn::integrate::{build, IntegratorOptions};
    use afmdyn::maps::StroboscopicMap;
    use afmdyn::{CantileverModel, SweepParam};
    let (spec, c) = curve();
    let ratio = 0.85;
    let found = setpoint_crossings(c, ratio);
    assert_eq!(found.len(), 2, "{found:?}");
    let mut phases = Vec::new();
    for k in &found {
        let Source::Branch(j) = k.source else {
            panic!("branches were continued: {k:?}");
        };
        let (a, b) = (&c.branches[j][k.index], &c.branches[j][k.index + 1]);
        assert!(a.point.stable && b.point.stable);
        let z = &a.point.section[0] * (1.0 - k.t) + &b.point.section[0] * k.t;
        let p = spec.base.with(SweepParam::Alpha5, k.value);
        let model = CantileverModel::new(&p).unwrap();
        let integ = IntegratorOptions::default();
        let mut it = build(&model, integ.clone(), 0.0, &z).unwrap();
        let map = &mut StroboscopicMap::new(it.as_mut(), 1);
        let orbit = shoot(map, &z, &ShootingOptions::default()).unwrap();
        assert!(orbit.stable);
        let o = observe_orbit(&model, integ, &orbit, 4).unwrap();
        let r = o.amplitude / o.closed_form.free_amplitude;
        assert!(
            (r - ratio).abs() < 2e-4,
            "A/A0 = {r} at z_c = {}",
            rest_distance(&p, k.value)
        );
        phases.push(o.phase.to_degrees());
    }
    phases.sort_by(f64::total_cmp);
    assert!(phases[0] < 90.0 && phases[1] > 90.0, "{phases:?}");
}

/// The per-point traces (`analysis::traces`): one trace per point of the approach on one time
/// axis; each starts at its point's state (W(1,0) of the stored state); for the point mass the
/// distance V_T and the deflection W differ by the constant gap at every sample; the largest
/// sampled force approaches the observables' peak force from below (400 samples per period:
/// within 3 %), and the sampled mean deflection equals the observables' ⟨W⟩ to 1e-3 of A₀.
#[test]
fn traces_are_the_steady_cycles_of_the_curve() {
    use afmdyn::analysis::traces::traces;
    use afmdyn::CantileverModel;
    let (spec, c) = curve();
    let points: Vec<_> = c
        .first
        .iter()
        .map(|p| (p.value, &p.state, p.period))
        .collect();
    let t = traces(
        &spec.base,
        spec.param,
        spec.integrator.clone(),
        &points,
        400,
    )
    .unwrap();
    let n = t.time.len();
    assert_eq!(t.values.len(), c.first.len());
    assert_eq!(n, t.periods * 400);
    for (i, p) in c.first.iter().enumerate() {
        let row = |v: &[f64]| v[i * n..(i + 1) * n].to_vec();
        let (w, d, f) = (row(&t.deflection), row(&t.distance), row(&t.force));
        let model = CantileverModel::new(&spec.base.with(spec.param, p.value)).unwrap();
        assert!((w[0] - model.w_tip(&p.state)).abs() < 1e-12);
        let gap = d[0] - w[0];
        assert!(d.iter().zip(&w).all(|(d, w)| (d - w - gap).abs() < 1e-12));
        let peak = f.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let o = &p.observables;
        if o.peak_force > 1e-6 {
            assert!(
                peak <= o.peak_force * (1.0 + 1e-9) && peak >= 0.97 * o.peak_force,
                "z_c {}: sampled {peak}, observed {}",
                i,
                o.peak_force
            );
        }
        if p.period == Some(1) {
            let mean = w.iter().sum::<f64>() / n as f64;
            assert!(
                (mean - o.mean_deflection).abs() < 1e-3,
                "{mean} vs {}",
                o.mean_deflection
            );
        }
    }
}

/// `approach` with a temperature (the RTESPA-300 over polystyrene, a DMT sample): the
/// sweeps gain σ_A and σ_φ at every point (`amplitude_noise`, `phase_noise_deg`), and the
/// document a `"thermal"` block with the lock-in's time constant. Far from the sample the
/// lever is free, and with Q ≫ 1 at resonance σ_A² = (k_BT/k) τ_c/(τ_c + τ_L), τ_c = 2Q/ω₀ (the
/// slow amplitude's first-order response behind the lock-in's first-order filter; equipartition
/// k_BT/k at τ_L → 0): within 1 % (its 1/Q corrections), at the default τ_L = τ_c/4 and at a
/// given τ_L = 1 ms. In the repulsive regime the sample stiffens the amplitude, so σ_A falls
/// below the free lever's. Points within 5 thermal standard deviations of the surface are
/// said to be beyond the linear response. At a setpoint the operating points carry the noise of
/// their orbits; an impacting orbit's (the impact law) is below the free lever's. Refused:
/// without a probe, a time constant without a temperature.
#[test]
fn a_temperature_gives_the_lock_ins_thermal_noise() {
    use afmdyn::analysis::progress::Progress;
    use afmdyn::request::{run, ApproachRequest, CurveRequest, Resolved};
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples/probe-rtespa300-polystyrene.toml");
    let probe = Probe::load(&path).expect("example probe");
    let model = Resolved {
        params: probe.params,
        probe: Some(probe.clone()),
    };
    let (k, q, f0) = (
        probe.calibration.spring_constant,
        probe.calibration.quality_factor,
        probe.calibration.resonance_frequency,
    );
    let tau_c = 2.0 * q / (std::f64::consts::TAU * f0);
    let kt = 1.380_649e-23 * 295.0;
    // an approach of `points` points without branches at 295 K, the lock-in's τ_L `tc`
    let hot = |points: usize, tc: Option<f64>| ApproachRequest {
        curve: CurveRequest {
            points: Some(points),
            branches: false,
            ..CurveRequest::default()
        },
        temperature: Some(295.0),
        time_constant: tc,
        ..ApproachRequest::default()
    };
    for (tc, tl) in [(None, tau_c / 4.0), (Some(1e-3), 1e-3)] {
        let request = hot(12, tc);
        let doc = run(&request, &model, &Progress::new()).unwrap().json;
        let t = &doc["thermal"];
        assert!((t["time_constant"].as_f64().unwrap() / tl - 1.0).abs() < 1e-9);
        let sigma: Vec<f64> = doc["approach"]["amplitude_noise"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        assert_eq!(sigma.len(), 12);
        assert_eq!(
            doc["retract"]["amplitude_noise"].as_array().unwrap().len(),
            12
        );
        let free = (kt / k * tau_c / (tau_c + tl)).sqrt();
        assert!(
            (sigma[0] / free - 1.0).abs() < 0.01,
            "{} vs {free}",
            sigma[0]
        );
        // the last point is deep in the repulsive regime
        assert!(sigma[11] < 0.5 * free, "{} vs {free}", sigma[11]);
        let phase = doc["approach"]["phase_noise_deg"][0].as_f64().unwrap();
        let a = doc["approach"]["amplitude"][0].as_f64().unwrap();
        // free: the phase quadrature carries the same noise, σ_φ = σ/A
        assert!((phase.to_radians() * a / free - 1.0).abs() < 0.01);
    }
    // 40 points put two of them at the attractive–repulsive transition, within 5σ of the
    // surface: their noise is said to be beyond the linear response
    let fine = hot(40, None);
    let doc = run(&fine, &model, &Progress::new()).unwrap().json;
    let offset = probe.params.contact_law.distance_offset() * probe.scales.length_m;
    let sigma = (kt / k).sqrt();
    let near = (doc["approach"]["min_distance"].as_array().unwrap().iter())
        .chain(doc["retract"]["min_distance"].as_array().unwrap())
        .filter(|d| (d.as_f64().unwrap() - offset).abs() < 5.0 * sigma)
        .count();
    let said = doc["warnings"].to_string();
    assert!(
        near > 0 && said.contains(&format!("{near} point(s) pass within 5 thermal")),
        "{near}: {said}"
    );
    // at a setpoint equal to a sweep point's A/A0 the operating point is that orbit: its
    // lock-in noise in the setpoint block is the sweep's there
    let sweep = &doc["approach"];
    let i = 30;
    let ratio = sweep["amplitude_ratio"][i].as_f64().unwrap();
    let at = ApproachRequest {
        setpoint: Some(ratio),
        ..fine.clone()
    };
    let doc = run(&at, &model, &Progress::new()).unwrap().json;
    let z_c = sweep["z_c"][i].as_f64().unwrap();
    let op = (doc["setpoint"]["points"].as_array().unwrap().iter())
        .find(|p| {
            p["source"] == "approach" && (p["z_c"].as_f64().unwrap() / z_c - 1.0).abs() < 1e-6
        })
        .expect("the operating point at the sweep's point");
    for key in ["amplitude_noise", "phase_noise_deg"] {
        let (o, s) = (op[key].as_f64().unwrap(), sweep[key][i].as_f64().unwrap());
        assert!((o / s - 1.0).abs() < 1e-4, "{key}: {o} vs {s}");
    }
    let refused = |model: &Resolved, request: ApproachRequest| {
        run(&request, model, &Progress::new()).unwrap_err()
    };
    let e = refused(&Resolved::plain(probe.params), hot(2, None));
    assert!(
        matches!(&e, SimError::OutOfRange { name, .. } if *name == "temperature"),
        "{e}"
    );
    let e = refused(
        &model,
        ApproachRequest {
            time_constant: Some(1e-3),
            ..ApproachRequest::default()
        },
    );
    assert!(
        matches!(&e, SimError::OutOfRange { name, .. } if *name == "time_constant"),
        "{e}"
    );
    // the impact law's jumps and sticking are carried (`analysis::orbit_noise`): the free end's
    // σ_A is the free lever's, the impacting end's below it
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-jkr-polymer.toml");
    let jkr = std::fs::read_to_string(path).unwrap();
    let (head, tail) = jkr.split_at(jkr.find("[sample]").unwrap());
    let sample = "[sample]\nlaw = \"impact\"\nrestitution = 0.5\nz_c = 8e-9\n";
    let text = format!("{head}{sample}{}", &tail[tail.find("[drive]").unwrap()..]);
    let impact = super::common::resolved(&text, "impact");
    let doc = run(&hot(6, None), &impact, &Progress::new()).unwrap().json;
    let sigma = |i: usize| doc["approach"]["amplitude_noise"][i].as_f64().unwrap();
    let p = impact.probe.as_ref().unwrap();
    let (k, q, f0) = (
        p.calibration.spring_constant,
        p.calibration.quality_factor,
        p.calibration.resonance_frequency,
    );
    let tau_c = 2.0 * q / (std::f64::consts::TAU * f0);
    let free = (kt / k * tau_c / (tau_c + tau_c / 4.0)).sqrt();
    assert!(
        (sigma(0) / free - 1.0).abs() < 0.01,
        "{} vs {free}",
        sigma(0)
    );
    assert!(sigma(5) < 0.9 * free, "{} vs {free}", sigma(5));
}

/// `approach --temperature` over an SLS sample (issue 79: its memory is the state's internal
/// entry): as the Maxwell arm κ → 0 the sample is the linear law's spring α4 without a damper
/// (`crate::contact::Zener`; the arm's dashpot and its thermal force decouple from the tip), so
/// the lock-in's σ_A and σ_φ at every point, free and in contact, equal the linear law's within
/// 10⁻⁶ (a 40 N/m, 300 kHz, Q = 400 lever over 5 N/m, κ = 10⁻⁹ N/m, τ_r = 0.1 µs).
#[test]
fn an_sls_approach_under_a_temperature_tends_to_the_linear_laws() {
    use afmdyn::analysis::progress::Progress;
    use afmdyn::request::{run, ApproachRequest, CurveRequest, Resolved};
    let lever = "model = \"point-mass\"\n[cantilever]\nspring_constant = 40\n\
                 resonance_frequency = 300e3\nquality_factor = 400\n[tip]\nradius = 10e-9\n\
                 [drive]\nfree_amplitude = 10e-9\n[sample]\nstiffness = 5.0\n";
    let noise = |sample: &str| -> Vec<[f64; 2]> {
        let probe = Probe::parse(&format!("{lever}{sample}"), "sls").unwrap();
        let model = Resolved {
            params: probe.params,
            probe: Some(probe),
        };
        let request = ApproachRequest {
            curve: CurveRequest {
                points: Some(8),
                branches: false,
                ..CurveRequest::default()
            },
            temperature: Some(295.0),
            ..ApproachRequest::default()
        };
        let doc = run(&request, &model, &Progress::new()).unwrap().json;
        let column = |k: &str| doc["approach"][k].as_array().unwrap().clone();
        let (a, p) = (column("amplitude_noise"), column("phase_noise_deg"));
        (a.iter().zip(&p))
            .map(|(a, p)| [a.as_f64().unwrap(), p.as_f64().unwrap()])
            .collect()
    };
    let linear = noise("law = \"linear\"\n");
    let tends = noise("law = \"sls\"\nmaxwell_stiffness = 1e-9\nrelaxation_time = 1e-7\n");
    for (i, (l, t)) in linear.iter().zip(&tends).enumerate() {
        for c in 0..2 {
            assert!(
                (t[c] / l[c] - 1.0).abs() < 1e-6,
                "point {i}: {t:?} vs {l:?}"
            );
        }
    }
    // the first two points are free, the others in contact (σ_A below the free lever's)
    assert!(linear[7][0] < 0.5 * linear[0][0], "{linear:?}");
}
