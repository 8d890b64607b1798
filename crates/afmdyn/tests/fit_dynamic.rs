//! Fitting dynamic AM curves (issue 62 §1): the exact parametric sensitivities of the periodic
//! orbits and of their first harmonic (`analysis::fit::sensitivity`) against central finite
//! differences of the shooting solution, on the point mass and the N = 3 beam, Hertz and DMT,
//! attractive and repulsive points of an AM approach (the example probes
//! `examples/probe-point-mass-dmt.toml` and `examples/probe-beam-dmt.toml`), and the Hertz
//! damper α6 (`sample.damping`) of a damped Hertz sample.

use afmdyn::analysis::fit::sensitivity::OrbitParam;
use afmdyn::contact::ContactLaw;
use afmdyn::probe::Probe;
use std::path::Path;

use super::common;
use common::orbit_check::{approach, check_first, Regime};
use common::orbit_params::probe;

/// One case of the sensitivity check: a probe (its law, or Hertz over it), the points of its
/// approach, the parameters differentiated and the regimes checked.
struct Case {
    /// Named in every failure message, with the regime.
    name: &'static str,
    probe: &'static str,
    hertz: bool,
    points: usize,
    params: &'static [OrbitParam],
    regimes: &'static [Regime],
}

const DMT_PARAMS: &[OrbitParam] = &[
    OrbitParam::Gap,
    OrbitParam::ContactStiffness,
    OrbitParam::Hamaker,
];
const HERTZ_PARAMS: &[OrbitParam] = &[OrbitParam::Gap, OrbitParam::ContactStiffness];
/// The drive's α2 and Ω (the FM loop's unknowns): their columns, Ω's by the rescaling of time
/// to a fixed phase; the N = 3 beam's base drive also moves V_T.
const DRIVE_PARAMS: &[OrbitParam] = &[OrbitParam::DriveAmplitude, OrbitParam::DriveFrequency];

/// The point mass and the N = 3 beam, DMT (attractive and repulsive) and Hertz (repulsive, and
/// the point mass's light touch); then the drive's parameters on the same four.
const CASES: [Case; 8] = [
    Case {
        name: "point mass DMT",
        probe: "probe-point-mass-dmt.toml",
        hertz: false,
        points: 41,
        params: DMT_PARAMS,
        regimes: &[Regime::Attractive, Regime::Repulsive],
    },
    Case {
        name: "point mass Hertz",
        probe: "probe-point-mass-dmt.toml",
        hertz: true,
        points: 41,
        params: HERTZ_PARAMS,
        regimes: &[Regime::Repulsive, Regime::LightTouch],
    },
    Case {
        name: "N = 3 beam DMT",
        probe: "probe-beam-dmt.toml",
        hertz: false,
        points: 21,
        params: DMT_PARAMS,
        regimes: &[Regime::Attractive, Regime::Repulsive],
    },
    Case {
        name: "N = 3 beam Hertz",
        probe: "probe-beam-dmt.toml",
        hertz: true,
        points: 21,
        params: HERTZ_PARAMS,
        regimes: &[Regime::Repulsive],
    },
    Case {
        name: "point mass DMT, drive",
        probe: "probe-point-mass-dmt.toml",
        hertz: false,
        points: 41,
        params: DRIVE_PARAMS,
        regimes: &[Regime::Attractive, Regime::Repulsive],
    },
    Case {
        name: "point mass Hertz, drive",
        probe: "probe-point-mass-dmt.toml",
        hertz: true,
        points: 41,
        params: DRIVE_PARAMS,
        regimes: &[Regime::Repulsive],
    },
    Case {
        name: "N = 3 beam DMT, drive",
        probe: "probe-beam-dmt.toml",
        hertz: false,
        points: 21,
        params: DRIVE_PARAMS,
        regimes: &[Regime::Attractive, Regime::Repulsive],
    },
    Case {
        name: "N = 3 beam Hertz, drive",
        probe: "probe-beam-dmt.toml",
        hertz: true,
        points: 21,
        params: DRIVE_PARAMS,
        regimes: &[Regime::Repulsive],
    },
];

/// The exact sensitivities of every case ([`CASES`]) against the fourth-order central
/// differences ([`check_point`], [`AGREE`]) at the first point of each regime away from folds
/// and grazing.
#[test]
fn sensitivities_are_the_finite_differences() {
    for case in &CASES {
        let mut base = probe(case.probe);
        if case.hertz {
            base.contact_law = ContactLaw::Hertz;
        }
        let curve = approach(base, case.points);
        for &r in case.regimes {
            let what = format!("{}, {}", case.name, r.name());
            check_first(&base, &r.points(&curve), case.params, &what);
        }
    }
}

/// The Hertz damper α6 of the damped cases (α6 δ̇ in contact): 0.05, twenty times the point
/// mass's own damping 1/Q = 0.0025, so the contact's dissipation moves the phase by degrees.
const HERTZ_ALPHA6: f64 = 0.05;

/// ∂(A, φ, z*)/∂α6 of the Hertz law's damper, with the gap and α4 at the same points, against
/// the fourth-order central differences ([`check_point`], [`AGREE`]) on the point mass
/// (repulsive and light touch) and the N = 3 beam (repulsive), Hertz with α6 = 0.05: the
/// vector field jumps by α6 δ̇ at each switching there, so this also checks the saltation of
/// the state's and the gap's columns (module docs of `analysis::fit::sensitivity`).
#[test]
fn damped_hertz_sensitivities_are_the_finite_differences() {
    const DAMPED: &[OrbitParam] = &[
        OrbitParam::Damping,
        OrbitParam::Gap,
        OrbitParam::ContactStiffness,
    ];
    let cases: [(&str, &str, usize, &[Regime]); 2] = [
        (
            "point mass Hertz, damped",
            "probe-point-mass-dmt.toml",
            41,
            &[Regime::Repulsive, Regime::LightTouch],
        ),
        (
            "N = 3 beam Hertz, damped",
            "probe-beam-dmt.toml",
            21,
            &[Regime::Repulsive],
        ),
    ];
    for (name, file, points, regimes) in cases {
        let mut base = probe(file);
        base.contact_law = ContactLaw::Hertz;
        base.alpha6 = HERTZ_ALPHA6;
        let curve = approach(base, points);
        for &r in regimes {
            let what = format!("{name}, {}", r.name());
            check_first(&base, &r.points(&curve), DAMPED, &what);
        }
    }
}

// ---- the dynamic fit (`analysis::fit::am_curve`) ----

use afmdyn::analysis::fit::am_curve::{AmCurveModel, AmParam, AmProbe};
use afmdyn::analysis::fit::{fit_with, CurveModel, FitOutcome, Observations};
use common::am_synthetic::{
    am_probe, assert_recovered, door, interval, jacobian_gaps, parameters, run_fit, synthetic,
    synthetic_of,
};

#[test]
fn a_noisy_point_mass_am_curve_gives_back_e_h_and_the_offset() {
    // the repulsive branch below the approach's fold (z_c = 7.5 → 3 nm): one branch, so the
    // model's rows stay on it wherever the start puts the parameters (through the bistable
    // range a start 1 nm off moves the jump by rows, and the fit stalls in a local minimum)
    let ps = vec![AmParam::YoungsModulus, AmParam::Hamaker, AmParam::ZOffset];
    let (model, y, sigma, truth) = synthetic(
        "probe-point-mass-dmt.toml",
        100,
        (0.75, 0.3),
        ps,
        (true, true),
        62,
    );
    let p0: Vec<f64> = parameters(&model.probe, &model.params)
        .iter()
        .map(|p| p.start)
        .collect();
    let mut v = vec![0.0; model.points()];
    let mut jac = vec![0.0; model.points() * p0.len()];
    let t0 = std::time::Instant::now();
    model.evaluate(&p0, &mut v, None);
    let t1 = std::time::Instant::now();
    model.evaluate(&p0, &mut v, Some(&mut jac));
    eprintln!(
        "one evaluation: values {:.3} s, with the Jacobian {:.3} s",
        (t1 - t0).as_secs_f64(),
        t1.elapsed().as_secs_f64()
    );
    let t0 = std::time::Instant::now();
    let out = run_fit(&model, &y, &sigma);
    eprintln!("{:.2} s", t0.elapsed().as_secs_f64());
    assert_recovered(&out, &truth, "E, H, z_offset, 100 rows", None, 0.5..2.0);
    // the χ²/dof warning (estimates::CHI2_SIGMAS): χ² of a model that describes its data is
    // χ²(dof), mean dof and standard deviation √(2 dof); with the true σ it stays within 4 of
    // them, with σ 10× too small χ²/dof is ~100 and warns (the same minimum: every weight
    // scaled alike; refitted from the estimates)
    let chi2_warning = |w: &[String]| w.iter().any(|w| w.contains("does not describe the data"));
    assert!(!chi2_warning(&out.warnings), "{:?}", out.warnings);
    let small: Vec<f64> = sigma.iter().map(|s| s / 10.0).collect();
    let mut params = parameters(&model.probe, &model.params);
    for (p, v) in params.iter_mut().zip(&out.values) {
        p.start = *v;
    }
    let obs = Observations {
        y: &y,
        sigma: Some(&small),
    };
    let tight = fit_with(&model, &obs, &params, &[None; 3], false);
    eprintln!("σ / 10: χ²/dof {:.2}, {:?}", tight.chi2_dof, tight.warnings);
    assert!(tight.chi2_dof > 50.0, "χ²/dof {}", tight.chi2_dof);
    assert!(chi2_warning(&tight.warnings), "{:?}", tight.warnings);
}

/// The fit of E and R to 40 amplitude rows of the attractive regime from `(from, to)` (z_c in
/// A₀), started at the truth (so at the minimum the data make, not a local one): the outcome
/// and the truth.
fn e_and_r_from_the_attractive_amplitude(from: f64, to: f64) -> (FitOutcome, Vec<f64>) {
    let ps = vec![AmParam::YoungsModulus, AmParam::TipRadius];
    let (model, y, sigma, truth) = synthetic(
        "probe-point-mass-dmt.toml",
        40,
        (from, to),
        ps,
        (true, false),
        7,
    );
    let mut params = parameters(&model.probe, &model.params);
    for (p, t) in params.iter_mut().zip(&truth) {
        p.start = *t;
    }
    let obs = Observations {
        y: &y,
        sigma: Some(&sigma),
    };
    let out = fit_with(&model, &obs, &params, &[None; 2], false);
    eprintln!(
        "E and R, attractive amplitude, z_c {from} → {to} A₀: χ²/dof {:.3}, (value, SE) {:?}, \
         r {:.3}, {:?}",
        out.chi2_dof,
        out.estimates
            .iter()
            .map(|e| (e.value, e.standard_error))
            .collect::<Vec<_>>(),
        out.correlation[0][1],
        out.warnings
    );
    (out, truth)
}

/// Issue 62's non-identifiable case, E and R from the amplitude alone in the attractive
/// regime. Where the tip never touches (z_c = 1.3 → 1.0 A₀) the orbits do not feel E (its
/// sensitivity is 0 out of contact) and the fit says E is not constrained, while R (through
/// the van der Waals force, H known) is. Where it touches lightly (1.1 → 0.9 A₀) the same
/// 40 rows at σ = 0.02 nm do fix both (E 4.05 ± 0.20 GPa, R 10.05 ± 0.07 nm, r = 0.68, no
/// warning): the warning is the data's, not the regime's name. (Started at the probe's
/// E × 0.6, R × 1.3 that light-touch fit stops in a local minimum, R at its lower bound and
/// χ²/dof ≈ 217, which the χ²/dof warning names.)
#[test]
fn e_and_r_from_the_attractive_amplitude_alone_are_not_identifiable() {
    let (none, _) = e_and_r_from_the_attractive_amplitude(1.3, 1.0);
    assert!(none.chi2_dof < 2.0, "χ²/dof {}", none.chi2_dof);
    let unconstrained = |o: &FitOutcome, name: &str| {
        o.warnings
            .iter()
            .any(|w| w.starts_with(name) && w.contains("not constrained"))
    };
    assert!(
        unconstrained(&none, "sample.youngs_modulus"),
        "{:?}",
        none.warnings
    );
    assert!(!unconstrained(&none, "tip.radius"), "{:?}", none.warnings);
    let (light, truth) = e_and_r_from_the_attractive_amplitude(1.1, 0.9);
    assert!(light.chi2_dof < 2.0, "χ²/dof {}", light.chi2_dof);
    assert!(light.warnings.is_empty(), "{:?}", light.warnings);
    for (e, t) in light.estimates.iter().zip(truth) {
        assert!(
            (e.interval[0]..=e.interval[1]).contains(&t),
            "{}: [{:e}, {:e}] misses {t:e}",
            e.name,
            e.interval[0],
            e.interval[1]
        );
    }
}

/// The synthetic curve `y` (σ `sigma`, the model's rows and channels) written as the door's
/// CSV (`z`, then `amplitude`, `phase`, `sigma_amplitude`, `sigma_phase` for the channels
/// fitted) to a fresh temporary directory named by `tag`, and fitted through the door
/// (`afmdyn fit`'s request) for the parameters `fit` under the example point-mass probe: the
/// fit's document.
fn fit_through_the_door(
    model: &AmCurveModel,
    y: &[f64],
    sigma: &[f64],
    fit: &[&str],
    tag: &str,
) -> serde_json::Value {
    let p = Probe::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml"),
    )
    .expect("probe");
    door(p, model, y, sigma, fit, tag).expect("fit")
}

/// Through the door from the probe's own starts (E and H the truth's, z_offset 0, 1 nm off —
/// where the model's first rows follow another branch than the data's and Levenberg–Marquardt
/// alone stopped at χ²/dof ≈ 100 with E = 2.3 GPa): z_offset's start grid puts the fit in
/// the right minimum, and E, H and z_offset come back within their intervals at χ²/dof near 1
/// (the 100 rows, channels and noise of scripts/perf-fit-dynamic.sh).
#[test]
fn the_door_starts_z_offset_on_a_grid_and_recovers_e_h_and_the_offset() {
    let ps = vec![AmParam::YoungsModulus, AmParam::Hamaker, AmParam::ZOffset];
    let (model, y, sigma, truth) = synthetic(
        "probe-point-mass-dmt.toml",
        100,
        (0.75, 0.3),
        ps,
        (true, true),
        62,
    );
    let names = ["sample.youngs_modulus", "sample.hamaker", "z_offset"];
    let doc = fit_through_the_door(&model, &y, &sigma, &names, "fit-grid");
    let chi2_dof = doc["chi2_dof"].as_f64().unwrap();
    assert!(chi2_dof < 1.5, "χ²/dof = {chi2_dof}: {}", doc["warnings"]);
    for (name, t) in names.iter().zip(&truth) {
        let [lo, hi] = interval(&doc, name);
        assert!(
            lo <= *t && *t <= hi,
            "{name}: truth {t} outside [{lo}, {hi}]"
        );
    }
}

#[test]
fn an_am_csv_goes_through_the_fit_door() {
    let (model, y, sigma, _) = synthetic(
        "probe-point-mass-dmt.toml",
        20,
        (1.1, 0.5),
        vec![AmParam::ZOffset],
        (true, false),
        3,
    );
    let doc = fit_through_the_door(&model, &y, &sigma, &["z_offset"], "fit-dynamic");
    assert_eq!(doc["kind"], "am");
    let [lo, hi] = interval(&doc, "z_offset");
    assert!(lo <= 1e-9 && 1e-9 <= hi, "z_offset interval [{lo}, {hi}]");
    assert_eq!(
        doc["curve"]["amplitude_fit"].as_array().map(Vec::len),
        Some(20)
    );
    assert!(doc["curve"]["phase"].is_null());
}

#[test]
fn the_am_models_jacobian_is_its_finite_differences() {
    let ps = vec![AmParam::YoungsModulus, AmParam::Hamaker, AmParam::ZOffset];
    let (model, _, _, truth) = synthetic(
        "probe-point-mass-dmt.toml",
        12,
        (0.75, 0.3),
        ps,
        (true, true),
        1,
    );
    for (name, worst, _) in jacobian_gaps(&model, &truth) {
        assert!(worst < 1e-3, "{name}: worst relative gap {worst:.2e}");
    }
}

// ---- the Hertz damper `sample.damping` in the AM model ----

/// The point-mass example as a damped Hertz sample: the law Hertz (no Hamaker), α6 =
/// [`HERTZ_ALPHA6`], so `[sample] damping` c = α6 / (g₀/(t_s F_s)).
fn damped_hertz_probe() -> AmProbe {
    let mut probe = am_probe("probe-point-mass-dmt.toml");
    probe.params.contact_law = ContactLaw::Hertz;
    probe.params.alpha6 = HERTZ_ALPHA6;
    probe.hamaker = 0.0;
    probe
}

/// The AM model's Jacobian columns of `sample.damping`, E, z_offset and R (R's chain moves
/// α4 alone: the dashpot does not depend on the contact area) against central differences of
/// its values (the stepped sweep's observables), on 12 rows of a damped Hertz approach,
/// amplitude and phase: 1e-3 relative, as the DMT case above.
#[test]
fn the_damped_am_models_jacobian_is_its_finite_differences() {
    let ps = vec![
        AmParam::Damping,
        AmParam::YoungsModulus,
        AmParam::ZOffset,
        AmParam::TipRadius,
    ];
    let (model, _, _, truth) =
        synthetic_of(damped_hertz_probe(), 12, (0.75, 0.3), ps, (true, true), 1);
    for (name, worst, phase_max) in jacobian_gaps(&model, &truth) {
        // the phase rows feel the damper: a column of zeros would pass the relative test
        assert!(phase_max > 0.0, "{name}: no phase sensitivity");
        assert!(worst < 1e-3, "{name}: worst relative gap {worst:.2e}");
    }
}

/// A noisy synthetic AM curve of a damped Hertz sample (100 rows z_c = 10 → 5 nm, from the
/// first touch to A ≈ A₀/2; amplitude σ 0.02 nm and phase σ 0.1°; made by the library's
/// stepped approach at the known c, E and z_offset = 1 nm) fitted for c, E and z_offset from
/// c × 0.7, E × 0.6, z_offset 0.8 nm: each comes back inside its 95 % interval, c to a few
/// per cent, at χ²/dof near 1. (Over seeds 1–20 of this curve the intervals of c all held the
/// truth, the pulls (ĉ − c)/SE within ±1.7. Deeper rows alone, z_c = 7.5 → 3 nm, leave c and E
/// correlated at 0.9999 and c to ±30 %: the phase of the light touch separates the dashpot
/// from the spring.)
#[test]
fn a_noisy_damped_hertz_am_curve_gives_back_the_damping() {
    let ps = vec![AmParam::Damping, AmParam::YoungsModulus, AmParam::ZOffset];
    let (model, y, sigma, truth) =
        synthetic_of(damped_hertz_probe(), 100, (1.0, 0.5), ps, (true, true), 6);
    let out = run_fit(&model, &y, &sigma);
    assert_recovered(&out, &truth, "damped Hertz", Some(0.1), 0.5..2.0);
}

/// The point-mass example's text as a Hertz sample with `[sample] damping` = `damping`
/// (N s/m; `None`: no damping key), through `Probe::parse`.
fn hertz_probe_text(damping: Option<f64>) -> Probe {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml");
    let text = std::fs::read_to_string(&path).expect("example probe");
    let mut out = String::new();
    for line in text.lines() {
        let key = line.split('=').next().unwrap_or("").trim();
        match key {
            "hamaker" | "intermolecular_distance" | "viscosity" => continue,
            "law" => out += "law = \"hertz\"\n",
            _ => out += &format!("{line}\n"),
        }
    }
    if let Some(c) = damping {
        out = out.replace(
            "law = \"hertz\"\n",
            &format!("law = \"hertz\"\ndamping = {c:?}\n"),
        );
    }
    Probe::parse(&out, "hertz-damped").expect("hertz probe")
}

/// Through the door: `sample.damping` of a Hertz probe, from the probe's c (the truth) and from
/// an undamped probe's c = 0 (scaled by the c whose α6 is 1 % of α4), comes back inside its
/// 95 % interval with E and z_offset (z_offset from its start grid); the document gives its
/// unit. `sample.viscosity` (DMT's η) and the damper of a DMT probe are refused, naming
/// `sample.damping`.
#[test]
fn the_door_fits_the_hertz_damping() {
    let ps = vec![AmParam::Damping, AmParam::YoungsModulus, AmParam::ZOffset];
    let (model, y, sigma, truth) =
        synthetic_of(damped_hertz_probe(), 100, (1.0, 0.5), ps, (true, true), 6);
    let names = ["sample.damping", "sample.youngs_modulus", "z_offset"];
    let c = truth[0];
    let damped = hertz_probe_text(Some(c));
    assert!(
        (damped.params.alpha6 - HERTZ_ALPHA6).abs() <= 1e-12 * HERTZ_ALPHA6,
        "the probe's α6 {} (c = {c:e} N s/m)",
        damped.params.alpha6
    );
    for (what, probe) in [("from c", damped), ("from 0", hertz_probe_text(None))] {
        let doc = door(probe, &model, &y, &sigma, &names, "fit-damping").expect("fit");
        let chi2_dof = doc["chi2_dof"].as_f64().unwrap();
        eprintln!(
            "{what}: χ²/dof {chi2_dof:.3}, {}",
            doc["estimates"]["sample.damping"]
        );
        assert!(
            chi2_dof < 1.5,
            "{what}: χ²/dof = {chi2_dof}: {}",
            doc["warnings"]
        );
        for (name, t) in names.iter().zip(&truth) {
            let [lo, hi] = interval(&doc, name);
            assert!(
                lo <= *t && *t <= hi,
                "{what} {name}: {t} outside [{lo}, {hi}]"
            );
        }
        assert_eq!(doc["units"]["sample.damping"], "N s/m");
    }
    let refused = |p: Probe, fit: &str| {
        let e = door(p, &model, &y, &sigma, &[fit], "fit-damping-refused")
            .expect_err("refused")
            .to_string();
        assert!(e.contains("sample.damping"), "{fit}: {e}");
    };
    refused(hertz_probe_text(Some(c)), "sample.viscosity");
    let dmt = Probe::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe-point-mass-dmt.toml"),
    )
    .expect("probe");
    refused(dmt, "sample.damping");
}
