//! The force-curve fit (issue 62 §2) against stated sources: its sensitivities against central
//! differences, nanite's preprocessing on an exact Hertz curve, the recovery of a synthetic
//! Hertz curve's E and contact point (Sneddon 1965, eq. 6.9) within their intervals, the
//! intervals' coverage over seeded noise draws, and the correlation warning where only E√R is
//! identifiable.

use afmdyn::analysis::fit::force_curve::{preprocess, ForceCurveModel, Segment, YOUNGS_MODULUS};
use afmdyn::analysis::fit::CurveModel;
use afmdyn::analysis::progress::Progress;
use afmdyn::probe::Probe;
use afmdyn::request::fit::FitRequest;
use afmdyn::request::{run, Resolved};
use afmdyn::LawKind;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The lever (N/m), the sample (Pa, ν) and the tip (m) of examples/probe-fit-hertz.toml.
const K: f64 = 0.05;
const NU: f64 = 0.5;
const R: f64 = 5e-6;
/// The truth: E (Pa) and the contact point's piezo height (m).
const E_TRUE: f64 = 5e3;
const CP_TRUE: f64 = 0.0;

fn probe() -> Resolved {
    super::common::fit_hertz_probe()
}

/// An approach: `rows` piezo heights from +1 µm to −1.5 µm about the contact, the Hertz force
/// of a rigid paraboloid (E* = E/(1 − ν²), as nanite's model; the probe's silicon tip changes
/// E* by 4e-8), with `sigma` Gaussian noise (N) of seed `seed`.
fn synthetic(rows: usize, sigma: f64, seed: u64) -> (Vec<f64>, Vec<f64>) {
    let e_star = 1.0
        / ((1.0 - 0.27 * 0.27) / afmdyn::cantilevers::SILICON_YOUNGS_MODULUS
            + (1.0 - NU * NU) / E_TRUE);
    let kh = 4.0 / 3.0 * e_star * R.sqrt();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut height = Vec::with_capacity(rows);
    let mut force = Vec::with_capacity(rows);
    for i in 0..rows {
        // the tip position x, the true force at it, the piezo height h = x − F/k
        let x = 1e-6 - 2.5e-6 * i as f64 / (rows - 1) as f64;
        let f = kh * (CP_TRUE - x).max(0.0).powf(1.5);
        // Box–Muller
        let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        let noise = sigma * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        height.push(x - f / K);
        force.push(f + noise);
    }
    (height, force)
}

fn request(height: Vec<f64>, force: Vec<f64>, fit: &[&str]) -> FitRequest {
    FitRequest {
        height,
        force,
        fit: fit.iter().map(|s| s.to_string()).collect(),
        ..FitRequest::default()
    }
}

#[test]
fn the_sensitivities_match_central_differences() {
    for (law, p) in [
        (LawKind::Hertz, vec![1e6, 20e-9, 1e-9, 1e-11]),
        (LawKind::Dmt, vec![1e6, 20e-9, 1e-9, 1e-11, 1e-19]),
        (LawKind::Jkr, vec![1e6, 20e-9, 1e-9, 1e-11, 0.05]),
    ] {
        let m = ForceCurveModel {
            law,
            x: (0..200).map(|i| 20e-9 - i as f64 * 0.25e-9).collect(),
            segment: Segment::Approach,
            poisson_ratio: 0.5,
            tip: (1.69e11, 0.27),
            intermolecular_distance: 0.3e-9,
            indenter: Default::default(),
        };
        let (rows, n) = (m.points(), p.len());
        let mut v = vec![0.0; rows];
        let mut jac = vec![0.0; rows * n];
        m.evaluate(&p, &mut v, Some(&mut jac));
        for j in 0..n {
            let h = 1e-5 * p[j].abs();
            let (mut a, mut b) = (p.clone(), p.clone());
            a[j] += h;
            b[j] -= h;
            let (mut va, mut vb) = (vec![0.0; rows], vec![0.0; rows]);
            m.evaluate(&a, &mut va, None);
            m.evaluate(&b, &mut vb, None);
            let scale = (0..rows).map(|i| jac[i * n + j].abs()).fold(0.0, f64::max);
            for i in 0..rows {
                let fd = (va[i] - vb[i]) / (2.0 * h);
                // the kink at δ = 0 (JKR's jump there) lies between the differences' points
                let near_kink = (p[2] - m.x[i]).abs() < 2.0 * h.max(1e-5 * p[2]);
                assert!(
                    near_kink || (fd - jac[i * n + j]).abs() <= 1e-5 * scale,
                    "{law:?} ∂F/∂p{j} at row {i}: {fd} against {}",
                    jac[i * n + j]
                );
            }
        }
    }
}

#[test]
fn the_preprocessing_finds_the_contact_and_removes_the_offsets() {
    let (height, mut force) = synthetic(500, 0.0, 1);
    for f in &mut force {
        *f += 2e-10;
    }
    let p = preprocess(&height, &force, K);
    assert_eq!(p.approach_len, 500);
    assert!((p.force_offset - 2e-10).abs() < 1e-18, "{}", p.force_offset);
    // the first row past the contact (x < 0): row 200 of 500 on 1 µm … −1.5 µm
    let i = p.contact_index.expect("a contact");
    assert!((200..=202).contains(&i), "{i}");
    assert!(p.tip_offset.abs() < 1.5e-8, "{}", p.tip_offset);
}

#[test]
fn a_noisy_hertz_curve_gives_back_its_modulus_within_the_intervals() {
    let (h, f) = synthetic(1000, 50e-12, 7);
    let doc = run(
        &request(h, f, &[YOUNGS_MODULUS, "contact_point", "baseline"]),
        &probe(),
        &Progress::default(),
    )
    .expect("fit");
    let e = &doc.json["estimates"][YOUNGS_MODULUS];
    let value = e["value"].as_f64().unwrap();
    let [lo, hi] = [
        e["interval"][0].as_f64().unwrap(),
        e["interval"][1].as_f64().unwrap(),
    ];
    assert!(lo <= E_TRUE && E_TRUE <= hi, "{lo} {value} {hi}");
    assert!((value / E_TRUE - 1.0).abs() < 0.01, "{value}");
    let cp = &doc.json["estimates"]["contact_point"];
    let tip_offset = doc.json["preprocessing"]["tip_offset"].as_f64().unwrap();
    let [clo, chi] = [
        cp["interval"][0].as_f64().unwrap(),
        cp["interval"][1].as_f64().unwrap(),
    ];
    assert!(
        clo + tip_offset <= CP_TRUE && CP_TRUE <= chi + tip_offset,
        "{clo} {chi} {tip_offset}"
    );
    let warnings = doc.json["warnings"].as_array().unwrap();
    assert!(
        warnings.iter().any(|w| w
            .as_str()
            .unwrap()
            .starts_with("noise estimated from residuals")),
        "{warnings:?}"
    );
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    // χ²/dof is the noise variance: the force's, and its share through the tip position
    // x = h + F/k (σ/k = 1 nm, times the slope where the curve is steep): 1.3 σ here
    let s = doc.json["chi2_dof"].as_f64().unwrap().sqrt();
    assert!((1.0..1.5).contains(&(s / 50e-12)), "{s}");
    for key in ["correlation", "curve", "preprocessing", "parameters"] {
        assert!(doc.json.get(key).is_some(), "{key}");
    }
}

#[test]
fn the_intervals_cover_the_truth_in_90_to_99_percent_of_draws() {
    let model = probe();
    let draws = 100;
    let (mut cover_e, mut cover_cp) = (0, 0);
    for seed in 0..draws {
        let (h, f) = synthetic(300, 100e-12, 1000 + seed);
        let doc = run(
            &request(h, f, &[YOUNGS_MODULUS, "contact_point", "baseline"]),
            &model,
            &Progress::default(),
        )
        .expect("fit");
        let est = &doc.json["estimates"];
        let inside = |name: &str, truth: f64| {
            let i = &est[name]["interval"];
            let (lo, hi) = (i[0].as_f64().unwrap(), i[1].as_f64().unwrap());
            lo <= truth && truth <= hi
        };
        let offset = doc.json["preprocessing"]["tip_offset"].as_f64().unwrap();
        cover_e += inside(YOUNGS_MODULUS, E_TRUE) as usize;
        cover_cp += inside("contact_point", CP_TRUE - offset) as usize;
    }
    for (name, c) in [("E", cover_e), ("contact point", cover_cp)] {
        assert!((90..=99).contains(&c), "{name}: {c} of {draws}");
    }
    eprintln!("coverage of the 95 % intervals: E {cover_e}, contact point {cover_cp} of {draws}");
}

#[test]
fn modulus_and_radius_together_are_not_identifiable() {
    let (h, f) = synthetic(500, 50e-12, 3);
    let doc = run(
        &request(h, f, &[YOUNGS_MODULUS, "tip.radius", "contact_point"]),
        &probe(),
        &Progress::default(),
    )
    .expect("fit");
    let warnings: Vec<&str> = doc.json["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w.as_str().unwrap())
        .collect();
    assert!(
        warnings.iter().any(
            |w| w.contains("sample.youngs_modulus and tip.radius are correlated")
                || w.contains("singular")
        ),
        "{warnings:?}"
    );
}

#[test]
fn the_request_refuses_bad_input_in_one_sentence() {
    let model = probe();
    let (h, f) = synthetic(100, 0.0, 1);
    for (r, what) in [
        (request(h.clone(), f.clone(), &["sample.hamaker"]), "fit"),
        (
            request(h.clone(), f[..50].to_vec(), &[YOUNGS_MODULUS]),
            "force",
        ),
        (request(Vec::new(), Vec::new(), &[YOUNGS_MODULUS]), "data"),
    ] {
        let e = run(&r, &model, &Progress::default())
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(what), "{e}");
        assert!(!e.contains('\n'), "{e}");
    }
}

/// A force curve needs what a force curve uses (issue 77 §10): a probe of the spring constant,
/// the tip and the sample only is read for the fit with stand-ins in place of the resonance,
/// Q, model and drive, which it names, and the fit on it is the full probe's to the bit
/// (nothing quasi-static reads the stand-ins); an analysis of the oscillating lever still
/// refuses the same file, naming the missing keys, and so does an AM curve's fit.
#[test]
fn a_force_curve_fit_needs_only_the_spring_constant_tip_and_sample() {
    use afmdyn::probe::ProbeNeeds;
    let text = "[cantilever]\nspring_constant = 0.05\n[tip]\nradius = 5e-6\n\
                [sample]\nlaw = \"hertz\"\nyoungs_modulus = 10e3\npoisson_ratio = 0.5\n";
    let e = Probe::parse(text, "k-tip-sample").unwrap_err().to_string();
    for missing in [
        "missing key model",
        "missing key [cantilever].resonance_frequency",
        "missing table [drive]",
    ] {
        assert!(e.contains(missing), "{e}");
    }
    let p = Probe::parse_for(text, "k-tip-sample", ProbeNeeds::Static).expect("static read");
    assert_eq!(
        p.assumed,
        [
            "model",
            "[cantilever].resonance_frequency",
            "[cantilever].quality_factor",
            "[drive].free_amplitude"
        ]
    );
    let (h, f) = synthetic(400, 50e-12, 3);
    let req = request(h, f, &[YOUNGS_MODULUS, "contact_point"]);
    assert_eq!(
        afmdyn::request::run::Request::probe_needs(&req),
        ProbeNeeds::Static
    );
    let minimal = Resolved {
        params: p.params,
        probe: Some(p),
    };
    let ours = run(&req, &minimal, &Progress::default()).expect("fit");
    let full = run(&req, &probe(), &Progress::default()).expect("fit");
    assert_eq!(ours.json["estimates"], full.json["estimates"]);
    assert_eq!(ours.json["warnings"], full.json["warnings"]);
    assert_eq!(ours.json["si"]["assumed"].as_array().map(Vec::len), Some(4));
    assert!(full.json["si"].get("assumed").is_none());
    // the full probe is read alike for the fit (nothing stood in for)
    let text_full = include_str!("../../../examples/probe-fit-hertz.toml");
    let same = Probe::parse_for(text_full, "full", ProbeNeeds::Static).expect("full");
    assert!(same.assumed.is_empty());
    // an AM curve's fit on the stand-ins: refused before any work, naming them
    let dir = std::env::temp_dir().join(format!("afmdyn-static-am-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let csv = dir.join("am.csv");
    let rows: String = (0..20)
        .map(|i| format!("{},{}\n", 20e-9 - i as f64 * 1e-9, 8e-9))
        .collect();
    std::fs::write(&csv, format!("z,amplitude\n{rows}")).unwrap();
    let am = FitRequest {
        data: Some(csv.display().to_string()),
        ..FitRequest::default()
    };
    let e = run(&am, &minimal, &Progress::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("probe = without model, [cantilever].resonance_frequency")
            && e.contains("give the model, the cantilever's resonance_frequency and quality_factor, and [drive]"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 77 §12: the grazing warning of a dynamic fit says what to do about it (the rows of the
/// first touch out of `range`, or the profile likelihood's intervals), not only what happened.
#[test]
fn the_grazing_warning_of_a_fit_gives_advice() {
    let w = afmdyn::analysis::fit::sensitivity::SensitivityWarning::Grazing { distance: 1e-9 }
        .to_string();
    assert!(w.contains("grazing orbit") && w.contains("`range`"), "{w}");
    assert!(
        w.contains("`profiles`") && w.contains("standard errors"),
        "{w}"
    );
}

/// Issue 77 item 4: data written in other units than SI are named with their likely unit, and
/// a contact point fitted far outside the heights says the fit did not find the contact — a
/// force curve in nN read as N (its contact point was fitted at metres), and one in nm read as
/// m; the curve in SI has neither warning.
#[test]
fn unit_slips_in_a_force_curve_are_named() {
    let (height, force) = synthetic(400, 0.0, 1);
    let warnings = |h: Vec<f64>, f: Vec<f64>| -> Vec<String> {
        let r = request(h, f, &["sample.youngs_modulus", "contact_point"]);
        let r = FitRequest {
            profiles: Some(false),
            ..r
        };
        run(&r, &probe(), &Progress::default()).unwrap().json["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| w.as_str().unwrap().to_string())
            .collect()
    };
    let clean = warnings(height.clone(), force.clone());
    assert!(
        !clean
            .iter()
            .any(|w| w.contains("written in") || w.contains("contact_point =")),
        "{clean:?}"
    );
    // an instrument's absolute piezo heights (a JPK file's 18–23 µm): the contact point is
    // held against the tip positions after the preprocessing's offset, so no warning
    let absolute: Vec<f64> = height.iter().map(|h| h + 20e-6).collect();
    let w = warnings(absolute, force.clone());
    assert!(!w.iter().any(|w| w.contains("contact_point =")), "{w:?}");
    let nano_newtons: Vec<f64> = force.iter().map(|f| f * 1e9).collect();
    let w = warnings(height.clone(), nano_newtons);
    assert!(
        w.iter()
            .any(|w| w.starts_with("force: ") && w.contains("written in nN?")),
        "{w:?}"
    );
    let nanometres: Vec<f64> = height.iter().map(|h| h * 1e9).collect();
    let w = warnings(nanometres, force);
    assert!(
        w.iter()
            .any(|w| w.starts_with("height: ") && w.contains("written in nm?")),
        "{w:?}"
    );
}

/// Issue 77 item 4: an AM curve's amplitudes written in nm (as metres they were fitted with
/// exit 0, a Hamaker interval of ±1.47 J) are named against the probe's free amplitude A₀ with
/// their likely unit, and an FM curve's shifts written in kHz against f₀; the columns in SI
/// have no such warning.
#[test]
fn unit_slips_in_a_dynamic_curve_are_named() {
    use afmdyn::request::fit_result::AmData;
    let (a0, f0): (f64, f64) = (10e-9, 300e3);
    let z: Vec<f64> = (0..50).map(|i| 11e-9 - 0.16e-9 * i as f64).collect();
    let amplitude: Vec<f64> = z.iter().map(|z| a0.min(*z)).collect();
    let shift: Vec<f64> = z.iter().map(|z| -30.0 * (3e-9 / z).powi(2)).collect();
    let data = |amplitude: &[f64], shift: Option<&[f64]>| AmData {
        z: z.clone(),
        amplitude: Some(amplitude.to_vec()),
        frequency_shift: shift.map(<[f64]>::to_vec),
        ..AmData::default()
    };
    assert!(data(&amplitude, Some(&shift)).unit_slips(a0, f0).is_empty());
    let nm: Vec<f64> = amplitude.iter().map(|a| a * 1e9).collect();
    let w = data(&nm, None).unit_slips(a0, f0);
    assert!(
        w.len() == 1 && w[0].starts_with("amplitude: ") && w[0].contains("written in nm?"),
        "{w:?}"
    );
    let khz: Vec<f64> = shift.iter().map(|f| f / 1e3).collect();
    let w = data(&amplitude, Some(&khz)).unit_slips(a0, f0);
    assert!(
        w.len() == 1 && w[0].starts_with("frequency_shift: ") && w[0].contains("in kHz?"),
        "{w:?}"
    );
}

/// Issue 77 item 5, one reader of columns: a column named twice is refused naming it, a
/// non-finite cell naming its column and row, a curve with no approach without speaking of a
/// `range` nobody gave; `range` applies to a dynamic curve's z (it was ignored there).
#[test]
fn the_columns_are_read_one_way() {
    let dir = std::env::temp_dir().join(format!("afmdyn-columns-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let twice = dir.join("twice.csv");
    std::fs::write(&twice, "height,force,force\n1e-7,1e-9,1e-9\n").unwrap();
    let r = FitRequest {
        data: Some(twice.display().to_string()),
        ..FitRequest::default()
    };
    let e = run(&r, &probe(), &Progress::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("the column \"force\" appears twice (columns 2 and 3)"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();

    let (height, mut force) = synthetic(100, 0.0, 1);
    force[4] = f64::NAN;
    let e = run(
        &request(height, force, &["contact_point"]),
        &probe(),
        &Progress::default(),
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("force = row 5: NaN"), "{e}");

    let flat = request(vec![1e-7; 20], vec![1e-9; 20], &["contact_point"]);
    let e = run(&flat, &probe(), &Progress::default())
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("segment = ") && !e.contains("range"), "{e}");

    use afmdyn::request::fit_result::AmData;
    let data = AmData {
        z: vec![1e-9, 2e-9, 3e-9, 4e-9],
        amplitude: Some(vec![1.0, 2.0, 3.0, 4.0]),
        ..AmData::default()
    }
    .within([1.5e-9, 3.5e-9]);
    assert_eq!(
        (data.z, data.amplitude),
        (vec![2e-9, 3e-9], Some(vec![2.0, 3.0]))
    );
}

/// The Hertz fit's minimum found on the contact rows (`analysis::fit::contact_rows`: the rows
/// above c_hi as one residual of their weighted mean) is the whole curve's: on a noisy
/// synthetic approach of 10⁴ rows (with σ given, so the weighted mean is exercised), started
/// 800 nm above the contact, the estimates, standard errors and χ² equal those of the
/// minimiser run on every row, to 1e-4 of the standard errors (both minimisers stop at a
/// relative χ² change of 1e-10).
#[test]
fn the_contact_rows_minimum_is_the_whole_curves() {
    use afmdyn::analysis::fit::contact_rows::ContactRows;
    use afmdyn::analysis::fit::{fit_cancellable, Observations, Parameter};
    let (height, force) = synthetic(10_000, 20e-12, 7);
    let curve = preprocess(&height, &force, K);
    let rows = curve.rows(Segment::Approach, None);
    let x: Vec<f64> = rows.iter().map(|&i| curve.tip_position[i]).collect();
    let y: Vec<f64> = rows.iter().map(|&i| curve.force[i]).collect();
    let sigma = vec![20e-12; y.len()];
    let model = ForceCurveModel {
        law: LawKind::Hertz,
        x: x.clone(),
        segment: Segment::Approach,
        poisson_ratio: NU,
        tip: (afmdyn::cantilevers::SILICON_YOUNGS_MODULUS, 0.27),
        intermolecular_distance: 0.0,
        indenter: Default::default(),
    };
    let p = |name: &str, start: f64, lower: f64, scale: f64| Parameter {
        name: name.into(),
        start,
        lower,
        upper: f64::INFINITY,
        scale,
    };
    let params = [
        p("sample.youngs_modulus", 2e3, 1.0, 2e3),
        p("tip.radius", R, 1e-10, R),
        p("contact_point", 8e-7, f64::NEG_INFINITY, 2.5e-7),
        p("baseline", 0.0, f64::NEG_INFINITY, 1e-11),
    ];
    let fixed = [None, Some(R), None, None];
    let obs = Observations {
        y: &y,
        sigma: Some(&sigma),
    };
    let progress = Progress::default();
    let whole = fit_cancellable(&model, &obs, &params, &fixed, None, &progress).unwrap();
    let over = |rows: &[usize]| -> Box<dyn CurveModel> {
        let x = rows.iter().map(|&i| model.x[i]).collect();
        Box::new(ForceCurveModel { x, ..model.clone() })
    };
    let reduced = ContactRows {
        x: &x,
        over: &over,
        contact_point: 2,
        baseline: 3,
    }
    .fit(&model, &obs, &params, &fixed, None, &progress)
    .unwrap();
    for (a, b) in whole.estimates.iter().zip(&reduced.estimates) {
        assert!(
            (a.value - b.value).abs() <= 1e-4 * a.standard_error,
            "{}: {} vs {} (± {})",
            a.name,
            a.value,
            b.value,
            a.standard_error
        );
        assert!((a.standard_error / b.standard_error - 1.0).abs() < 1e-6);
    }
    assert!((whole.chi2 / reduced.chi2 - 1.0).abs() < 1e-9);
    assert_eq!(whole.dof, reduced.dof);
}

/// A probe of the lever and sample of examples/probe-fit-hertz.toml with the `[tip]` table
/// `tip` (and the law `law`), read for a force curve.
fn shape_probe(tip: &str, law: &str) -> Resolved {
    let adhesion = match law {
        "dmt" => "hamaker = 1e-20",
        "jkr" => "adhesion_energy = 1e-3",
        _ => "",
    };
    let text = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = {K}\nresonance_frequency = \
         10e3\nquality_factor = 50\n[tip]\n{tip}\n[sample]\nlaw = \"{law}\"\nyoungs_modulus = \
         10e3\npoisson_ratio = {NU}\n{adhesion}\n"
    );
    let p = Probe::parse_for(&text, "shape", afmdyn::probe::ProbeNeeds::Static).expect("probe");
    Resolved {
        params: p.params,
        probe: Some(p),
    }
}

/// E* of the sample E_TRUE, ν = NU, under the probe's silicon tip (Johnson 1985, eq. 4.22).
fn e_star() -> f64 {
    1.0 / ((1.0 - 0.27 * 0.27) / afmdyn::cantilevers::SILICON_YOUNGS_MODULUS
        + (1.0 - NU * NU) / E_TRUE)
}

/// A noise-free approach of `rows` tip positions from +1 µm to −1.5 µm about the contact at 0,
/// with the force `f(δ)` (N) at indentation δ (m): the piezo heights x − F/k and the forces.
fn curve_of(f: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>) {
    let rows = 1000;
    (0..rows)
        .map(|i| {
            let x = 1e-6 - 2.5e-6 * i as f64 / (rows - 1) as f64;
            let force = if x < 0.0 { f(-x) } else { 0.0 };
            (x - force / K, force)
        })
        .unzip()
}

/// The fitted E of `curve` under `probe`, with E, the contact point and the baseline free.
fn fitted_modulus(probe: &Resolved, curve: (Vec<f64>, Vec<f64>), thickness: Option<f64>) -> f64 {
    let req = FitRequest {
        thickness,
        ..request(
            curve.0,
            curve.1,
            &[YOUNGS_MODULUS, "contact_point", "baseline"],
        )
    };
    let doc = run(&req, probe, &Progress::default()).expect("fit");
    doc.json["estimates"][YOUNGS_MODULUS]["value"]
        .as_f64()
        .unwrap()
}

/// Every indenter shape: a noise-free curve of its closed form (written here: Hertz, Sneddon's
/// cone and exact sphere in its parametric form, nanite's `hertz_pyr3s`, Bilodeau's
/// four-sided pyramid, the flat punch) fitted back to its E.
#[test]
fn a_curve_of_each_shape_fits_back_to_its_modulus() {
    let es = e_star();
    let tan = |deg: f64| deg.to_radians().tan();
    // Sneddon's sphere: δ(a) = (a/2) ln((R+a)/(R−a)), F(a) = (E*/2)[(a²+R²) ln(…) − 2aR],
    // inverted by bisection on a
    let sphere = move |delta: f64| {
        let (mut lo, mut hi) = (0.0, R * (1.0 - 1e-12));
        for _ in 0..200 {
            let a = 0.5 * (lo + hi);
            if a / 2.0 * ((R + a) / (R - a)).ln() < delta {
                lo = a;
            } else {
                hi = a;
            }
        }
        let a = 0.5 * (lo + hi);
        let l = ((R + a) / (R - a)).ln();
        es / 2.0 * ((a * a + R * R) * l - 2.0 * a * R)
    };
    type Force = Box<dyn Fn(f64) -> f64>;
    let cases: Vec<(&str, Force)> = vec![
        (
            "radius = 5e-6",
            Box::new(move |d: f64| 4.0 / 3.0 * es * R.sqrt() * d.powf(1.5)),
        ),
        ("shape = \"sphere\"\nradius = 5e-6", Box::new(sphere)),
        (
            "shape = \"cone\"\nhalf_angle = 25",
            Box::new(move |d: f64| 2.0 / std::f64::consts::PI * es * tan(25.0) * d * d),
        ),
        (
            "shape = \"pyramid-3\"\nface_angle = 15",
            Box::new(move |d: f64| 0.8887 * es * tan(15.0) * d * d),
        ),
        (
            "shape = \"pyramid-4\"\nhalf_angle = 35",
            Box::new(move |d: f64| es * tan(35.0) / 2f64.sqrt() * d * d),
        ),
        (
            "shape = \"flat-punch\"\nradius = 1e-6",
            Box::new(move |d: f64| 2.0 * es * 1e-6 * d),
        ),
    ];
    for (tip, f) in cases {
        let e = fitted_modulus(&shape_probe(tip, "hertz"), curve_of(f), None);
        assert!((e / E_TRUE - 1.0).abs() < 1e-6, "{tip}: {e}");
    }
}

/// A thin sample: the paraboloid's curve with Dimitriadis et al.'s bonded series (α₀, β₀ at
/// ν = 0.5, written here) and the cone's with Garcia & Garcia's, fitted back with the
/// `thickness`; and the same curves fitted without it read a stiffer sample.
#[test]
fn a_thin_sample_fits_back_with_its_thickness() {
    let (es, h) = (e_star(), 3e-6);
    let pi = std::f64::consts::PI;
    let a0 = -(1.2876 - 1.4678 * NU + 1.3442 * NU * NU) / (1.0 - NU);
    let b0 = (0.6387 - 1.0277 * NU + 1.5164 * NU * NU) / (1.0 - NU);
    let para = move |d: f64| {
        let x = (R * d).sqrt() / h;
        let c = 1.0 - 2.0 * a0 / pi * x + 4.0 * a0 * a0 / (pi * pi) * x * x
            - 8.0 / pi.powi(3) * (a0.powi(3) + 4.0 * pi * pi / 15.0 * b0) * x.powi(3)
            + 16.0 * a0 / pi.powi(4) * (a0.powi(3) + 3.0 * pi * pi / 5.0 * b0) * x.powi(4);
        4.0 / 3.0 * es * R.sqrt() * d.powf(1.5) * c
    };
    let t = 25f64.to_radians().tan();
    let cone = move |d: f64| {
        let b = d * t / h;
        let c = 1.0 + 0.721 * b + 0.650 * b * b + 0.491 * b.powi(3) + 0.225 * b.powi(4);
        2.0 / pi * es * t * d * d * c
    };
    for (tip, f) in [
        ("radius = 5e-6", Box::new(para) as Box<dyn Fn(f64) -> f64>),
        ("shape = \"cone\"\nhalf_angle = 25", Box::new(cone)),
    ] {
        let probe = shape_probe(tip, "hertz");
        let e = fitted_modulus(&probe, curve_of(&f), Some(h));
        assert!((e / E_TRUE - 1.0).abs() < 1e-6, "{tip}: {e}");
        let e = fitted_modulus(&probe, curve_of(&f), None);
        assert!(e > 1.05 * E_TRUE, "{tip}: {e}");
    }
}

/// The shapes' refusals, each naming its field: an adhesive law with a cone (`tip.shape`), a
/// thickness under DMT (`thickness`), `bonded` without a thickness, a non-bonded cone
/// (`bonded`); the dynamic analyses' read of a cone probe names `[tip].shape`; an angle in
/// radians is read with a warning naming radians.
#[test]
fn the_shapes_refusals_name_their_fields() {
    let (h, f) = synthetic(300, 0.0, 1);
    let name = |probe: &Resolved, req: FitRequest| match run(&req, probe, &Progress::default()) {
        Err(afmdyn::SimError::OutOfRange { name, .. }) => name,
        other => panic!("{:?}", other.map(|d| d.json)),
    };
    let fit = |thickness, bonded| FitRequest {
        thickness,
        bonded,
        ..request(h.clone(), f.clone(), &[YOUNGS_MODULUS, "contact_point"])
    };
    let cone = "shape = \"cone\"\nhalf_angle = 25";
    assert_eq!(
        name(&shape_probe(cone, "dmt"), fit(None, None)),
        "tip.shape"
    );
    assert_eq!(
        name(&shape_probe(cone, "jkr"), fit(None, None)),
        "tip.shape"
    );
    let para = "radius = 5e-6";
    assert_eq!(
        name(&shape_probe(para, "dmt"), fit(Some(1e-6), None)),
        "thickness"
    );
    assert_eq!(
        name(&shape_probe(para, "hertz"), fit(None, Some(false))),
        "bonded"
    );
    assert_eq!(
        name(&shape_probe(para, "hertz"), fit(Some(-1e-6), None)),
        "thickness"
    );
    assert_eq!(
        name(&shape_probe(cone, "hertz"), fit(Some(1e-6), Some(false))),
        "bonded"
    );
    // the cone has no tip.radius to fit
    let radius = request(h.clone(), f.clone(), &[YOUNGS_MODULUS, "tip.radius"]);
    assert_eq!(name(&shape_probe(cone, "hertz"), radius), "fit");
    // the dynamic analyses take the paraboloid only
    let text = include_str!("../../../examples/probe-fit-hertz.toml")
        .replace("radius = 5e-6", "shape = \"pyramid-4\"\nhalf_angle = 35");
    let e = Probe::parse(&text, "p").unwrap_err().to_string();
    assert!(e.contains("[tip].shape = \"pyramid-4\""), "{e}");
    // an angle in radians: read, with a warning naming the slip
    let p = shape_probe("shape = \"cone\"\nhalf_angle = 0.436", "hertz");
    let w = p.probe.unwrap().warnings().join("; ");
    assert!(
        w.contains("[tip].half_angle") && w.contains("radians"),
        "{w}"
    );
    // an angle of another shape, a missing angle, an unknown shape: problems of the file
    for (tip, word) in [
        ("shape = \"cone\"\nface_angle = 15", "[tip].face_angle"),
        ("shape = \"pyramid-3\"", "missing key [tip].face_angle"),
        ("shape = \"wedge\"", "[tip].shape = 'wedge'"),
        ("shape = \"cone\"\nhalf_angle = 90", "[tip].half_angle = 90"),
    ] {
        let text =
            include_str!("../../../examples/probe-fit-hertz.toml").replace("radius = 5e-6", tip);
        let e = Probe::parse_for(&text, "p", afmdyn::probe::ProbeNeeds::Static)
            .unwrap_err()
            .to_string();
        assert!(e.contains(word), "{tip}: {e}");
    }
}

/// The thermal σ (issue 79 item 4): without a σ column and with a `temperature`, each force's
/// σ is the lever's thermal force noise. For this point-mass lever (k = 0.05 N/m, f₀ = 10 kHz,
/// Q = 50) over 1 000 f₀ it is √(k_B T k) (equipartition; the oscillator's tail beyond,
/// 2/(3πQ·10⁹)), over 100 Hz ≪ f₀ it is k √(2 k_B T B/(π k f₀ Q)) (the oscillator's PSD at
/// zero frequency, 1e-4 for the rise to 0.01 f₀). A curve with the first of these noises fits
/// with χ²/dof within 4 of its standard deviations of 1 over its baseline and the first 50 nm
/// of indentation (deeper, the noise of the tip position computed from the force adds
/// (1 + |∂F/∂x|/k)² to the scatter, as on an instrument), and the document names the σ. A
/// bandwidth without a temperature, and a probe without the lever's resonance, are refused.
#[test]
fn a_thermal_sigma_is_the_levers_force_noise() {
    use afmdyn::probe::ProbeNeeds;
    let kt = 1.380_649e-23 * 295.0;
    let full = (kt * K).sqrt();
    let fit = |b: f64, noise: f64| {
        let (h, f) = synthetic(1000, noise, 3);
        let r = FitRequest {
            temperature: Some(295.0),
            bandwidth: Some(b),
            range: Some([-50e-9, 1e-6]),
            ..request(h, f, &[YOUNGS_MODULUS, "contact_point"])
        };
        run(&r, &probe(), &Progress::default()).expect("fit").json
    };
    let doc = fit(1e7, full);
    let sigma = doc["sigma_thermal"].as_f64().unwrap();
    assert!((sigma / full - 1.0).abs() < 1e-6, "{sigma} vs {full}");
    let (chi2, dof) = (
        doc["chi2_dof"].as_f64().unwrap(),
        doc["dof"].as_f64().unwrap(),
    );
    assert!((chi2 - 1.0).abs() < 4.0 * (2.0 / dof).sqrt(), "{chi2}");
    assert!(
        doc["noise"].as_str().unwrap().contains("thermal"),
        "{}",
        doc["noise"]
    );
    let low = fit(100.0, 1e-13)["sigma_thermal"].as_f64().unwrap();
    let want = K * (2.0 * kt * 100.0 / (std::f64::consts::PI * K * 10e3 * 50.0)).sqrt();
    assert!((low / want - 1.0).abs() < 1e-4, "{low} vs {want}");
    // refused: a bandwidth alone; the stand-ins of a quasi-static read
    let (h, f) = synthetic(400, 1e-12, 3);
    let alone = FitRequest {
        bandwidth: Some(1e3),
        ..request(h.clone(), f.clone(), &[YOUNGS_MODULUS])
    };
    let e = run(&alone, &probe(), &Progress::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("bandwidth"), "{e}");
    let text = "[cantilever]\nspring_constant = 0.05\n[tip]\nradius = 5e-6\n\
                [sample]\nlaw = \"hertz\"\nyoungs_modulus = 10e3\npoisson_ratio = 0.5\n";
    let p = Probe::parse_for(text, "k-tip-sample", ProbeNeeds::Static).expect("static read");
    let minimal = Resolved {
        params: p.params,
        probe: Some(p),
    };
    let thermal = FitRequest {
        temperature: Some(295.0),
        bandwidth: Some(1e3),
        ..request(h, f, &[YOUNGS_MODULUS])
    };
    let e = run(&thermal, &minimal, &Progress::default())
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("temperature") && e.contains("resonance_frequency"),
        "{e}"
    );
}
