//! `fit-map` (issue 78) against a synthetic map of known moduli: an 8 × 8 map of Hertz curves
//! (Sneddon 1965, eq. 6.9: F = (4/3) E/(1 − ν²) √R δ^{3/2} of a rigid paraboloid; the probe's
//! silicon tip changes E* by 4e-8) with a soft inclusion and seeded Gaussian noise, written as
//! the long-format CSV the command line reads: every curve's E recovered within its 95 %
//! interval at that coverage, the map's grid and topography as written, a curve that never
//! touches the sample flagged rather than fitted, results independent of the thread count, a
//! resumed map identical, and malformed maps refused naming the file.

use afmdyn::analysis::progress::Progress;
use afmdyn::request::{run, FitMapRequest, Resolved};
use afmdyn::study::fit_map::{CurveFlag, FitMap};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;

/// The lever (N/m), the sample's ν and the tip (m) of examples/probe-fit-hertz.toml.
const K: f64 = 0.05;
const NU: f64 = 0.5;
const R: f64 = 5e-6;
/// The map's pitch (m), its size, the matrix's and the inclusion's moduli (Pa).
const PITCH: f64 = 1e-6;
const N: usize = 8;
const E_MATRIX: f64 = 5e3;
const E_SOFT: f64 = 800.0;
/// The force noise (N) and the rows per curve.
const SIGMA: f64 = 2e-11;
const ROWS: usize = 300;

fn probe() -> Resolved {
    super::common::fit_hertz_probe()
}

/// The true modulus at (ix, iy): the soft inclusion a disc of radius 2 pitches about (5, 5).
fn modulus(ix: usize, iy: usize) -> f64 {
    let d2 = (ix as f64 - 5.0).powi(2) + (iy as f64 - 5.0).powi(2);
    if d2 <= 4.0 {
        E_SOFT
    } else {
        E_MATRIX
    }
}

/// The contact's piezo height (m) at (ix, iy): a tilted surface, the topography.
fn surface(ix: usize, iy: usize) -> f64 {
    50e-9 * ix as f64 + 20e-9 * iy as f64
}

/// Dimitriadis et al.'s bottom-effect factor of a paraboloid on a layer `h` thick bonded to
/// its substrate at ν = 0.5 (*Biophys. J.* 82 (2002) 2798, eq. 11 with its α₀ and β₀; written
/// here for the test) at the indentation `d`.
fn dimitriadis_bonded(d: f64, h: f64) -> f64 {
    let pi = std::f64::consts::PI;
    let a0 = -(1.2876 - 1.4678 * NU + 1.3442 * NU * NU) / (1.0 - NU);
    let b0 = (0.6387 - 1.0277 * NU + 1.5164 * NU * NU) / (1.0 - NU);
    let x = (R * d).sqrt() / h;
    1.0 - 2.0 * a0 / pi * x + 4.0 * a0 * a0 / (pi * pi) * x * x
        - 8.0 / pi.powi(3) * (a0.powi(3) + 4.0 * pi * pi / 15.0 * b0) * x.powi(3)
        + 16.0 * a0 / pi.powi(4) * (a0.powi(3) + 3.0 * pi * pi / 5.0 * b0) * x.powi(4)
}

/// One approach at (ix, iy) as CSV lines: tip positions from 1 µm above the surface to 1.5 µm
/// below; the last curve of the first line `flat` (never reaching the sample); on a layer
/// bonded to a substrate at the piezo height `substrate` when given.
fn layer_curve(
    text: &mut String,
    ix: usize,
    iy: usize,
    rng: &mut ChaCha8Rng,
    flat: bool,
    substrate: Option<f64>,
) {
    let e_star = 1.0
        / ((1.0 - 0.27 * 0.27) / afmdyn::cantilevers::SILICON_YOUNGS_MODULUS
            + (1.0 - NU * NU) / modulus(ix, iy));
    let kh = 4.0 / 3.0 * e_star * R.sqrt();
    let cp = surface(ix, iy);
    let (x0, y0) = (ix as f64 * PITCH, iy as f64 * PITCH);
    for i in 0..ROWS {
        let depth = if flat { 0.5e-6 } else { 2.5e-6 };
        let x = cp + 1e-6 - depth * i as f64 / (ROWS - 1) as f64;
        let d = (cp - x).max(0.0);
        let c = substrate.map_or(1.0, |z| dimitriadis_bonded(d, cp - z));
        let f = kh * d.powf(1.5) * c;
        let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        let noise = SIGMA * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        writeln!(text, "{x0:e},{y0:e},{:e},{:e}", x - f / K, f + noise).unwrap();
    }
}

/// The synthetic map written to a fresh directory: its CSV's path.
fn map(name: &str) -> std::path::PathBuf {
    layer_map(name, None)
}

/// The synthetic map, on a layer bonded to a substrate at the piezo height `substrate` when
/// given.
fn layer_map(name: &str, substrate: Option<f64>) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("afmdyn-fit-map-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(78);
    let mut text = String::from("x,y,height,force\n");
    for iy in 0..N {
        for ix in 0..N {
            let flat = iy == 0 && ix == N - 1;
            layer_curve(&mut text, ix, iy, &mut rng, flat, substrate);
        }
    }
    let path = dir.join("map.csv");
    std::fs::write(&path, text).unwrap();
    path
}

fn request(path: &std::path::Path, threads: usize) -> FitMapRequest {
    FitMapRequest {
        data: Some(path.display().to_string()),
        threads: Some(threads),
        ..FitMapRequest::default()
    }
}

fn fitted(path: &std::path::Path, threads: usize) -> FitMap {
    run(&request(path, threads), &probe(), &Progress::default())
        .expect("fit-map")
        .output
}

#[test]
fn a_synthetic_map_gives_back_its_moduli_within_their_intervals() {
    let path = map("moduli");
    let m = fitted(&path, 2);
    assert_eq!((m.xs.len(), m.ys.len(), m.curves.len()), (N, N, N * N));
    assert_eq!(m.names[0], "sample.youngs_modulus");
    let mut inside = 0;
    let mut fits = 0;
    for c in &m.curves {
        assert_eq!((c.x, c.y), (c.ix as f64 * PITCH, c.iy as f64 * PITCH));
        if c.iy == 0 && c.ix == N - 1 {
            // never indented: flagged, not fitted
            assert!(
                matches!(
                    c.flag,
                    CurveFlag::TooFewContactRows | CurveFlag::NotConstrained | CurveFlag::Failed
                ),
                "{:?}: {:?}",
                c.flag,
                c.reason
            );
            assert!(c.reason.is_some());
            continue;
        }
        assert_eq!(
            c.flag,
            CurveFlag::Fitted,
            "({}, {}): {:?}",
            c.ix,
            c.iy,
            c.reason
        );
        let truth = modulus(c.ix, c.iy);
        let [lo, hi] = c.intervals[0];
        inside += usize::from(lo.unwrap() <= truth && truth <= hi.unwrap());
        fits += 1;
        // the topography: the contact's piezo height, within 5 nm of the surface written
        let h = c.contact_height.unwrap();
        assert!(
            (h - surface(c.ix, c.iy)).abs() < 5e-9,
            "{h} vs {}",
            surface(c.ix, c.iy)
        );
    }
    // 95 % intervals over 63 curves: at least 54 cover the truth (binomial, p < 0.01 below)
    assert!(inside >= 54 && fits == N * N - 1, "{inside} of {fits}");
    let doc = afmdyn::report::fit_map::document(&m);
    assert_eq!(doc["counts"]["fitted"], 63);
    let median = doc["summary"]["sample.youngs_modulus"]["median"]
        .as_f64()
        .unwrap();
    assert!((median / E_MATRIX - 1.0).abs() < 0.02, "{median}");
}

#[test]
fn a_map_does_not_depend_on_the_thread_count_and_resumes_to_the_same_map() {
    let path = map("threads");
    let one = fitted(&path, 1);
    let two = fitted(&path, 2);
    assert_eq!(one.curves, two.curves);
    // into a store, then resumed: the finished store computes nothing and gives the same map
    use afmdyn::study::stored::{Resumable, Storage};
    let dir = path.parent().unwrap().join("out");
    let lock = afmdyn::request::DirLock::acquire(&dir).expect("lock");
    let r = request(&path, 2);
    let model = probe();
    let study = r.study(&model).unwrap();
    let storage = |resume| Storage {
        lock: Some(&lock),
        resume,
        abort_after: None,
    };
    let first = r
        .resume(&study, &model, storage(false), &Progress::default())
        .unwrap();
    assert_eq!(first.curves, one.curves);
    let progress = Progress::default();
    let again = r.resume(&study, &model, storage(true), &progress).unwrap();
    assert_eq!(again.curves, one.curves);
    // a resume of another request on the same store is refused
    let other = FitMapRequest {
        fit: vec!["sample.youngs_modulus".into(), "contact_point".into()],
        ..request(&path, 2)
    };
    let study = other.study(&model).unwrap();
    assert!(other
        .resume(&study, &model, storage(true), &progress)
        .is_err());
}

#[test]
fn malformed_maps_are_refused_naming_the_file() {
    let dir = std::env::temp_dir().join(format!("afmdyn-fit-map-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rows = String::new();
    for i in 0..20 {
        writeln!(rows, "{},0,{},0", i / 10, -(i as f64) * 1e-8).unwrap();
    }
    let cases = [
        (
            "no-force",
            "x,y,height\n0,0,1\n".to_string(),
            "no column force",
        ),
        (
            "text",
            "x,y,height,force\n0,0,a,1\n".to_string(),
            "is not a number",
        ),
        (
            "split",
            format!("x,y,height,force\n{rows}0,0,1e-9,0\n"),
            "not consecutive",
        ),
    ];
    for (name, text, says) in cases {
        let path = dir.join(format!("{name}.csv"));
        std::fs::write(&path, text).unwrap();
        let e = run(&request(&path, 1), &probe(), &Progress::default())
            .err()
            .unwrap_or_else(|| panic!("{name}: accepted"));
        let msg = e.to_string();
        assert!(
            msg.contains(&format!("{name}.csv")) && msg.contains(says),
            "{name}: {msg}"
        );
    }
    // a NetCDF signature with a header cut short: said in words, not the reader's Debug
    let path = dir.join("cut.nc");
    std::fs::write(&path, b"CDF\x01\x00\x00\x00\x05\x00\x00").unwrap();
    let msg = run(&request(&path, 1), &probe(), &Progress::default())
        .expect_err("a cut NetCDF header was accepted")
        .to_string();
    assert!(
        msg.contains("cut.nc")
            && msg.contains("not a NetCDF-3 map: its header")
            && !msg.contains("ParseHeader"),
        "{msg}"
    );
}

/// A map fitted with another lever's probe (RTESPA-300, k ≈ 40 N/m, against the map's
/// 0.05 N/m: forces 10⁻⁴ of what its deflection allows over the heights' span) says, in the
/// map's warnings, that its curves' data look off against the probe; the map's own probe does
/// not.
#[test]
fn a_map_fitted_with_another_levers_probe_says_its_data_look_off() {
    let path = map("lever");
    let text = include_str!("../../../examples/probe-rtespa300-polystyrene.toml");
    let p = afmdyn::probe::Probe::parse(text, "rtespa300").expect("probe");
    let other = Resolved {
        params: p.params,
        probe: Some(p),
    };
    let says = |model: &Resolved| -> bool {
        let doc = run(&request(&path, 2), model, &Progress::default())
            .expect("fit-map")
            .json;
        doc["warnings"].as_array().unwrap().iter().any(|w| {
            w.as_str()
                .unwrap()
                .contains("data look off against the probe")
        })
    };
    assert!(says(&other));
    assert!(!says(&probe()));
}

/// A cell-like layer on glass: the map's curves indent a layer bonded to a substrate 4 µm
/// below the surface (χ = √(Rδ)/h up to 0.7), fitted with `substrate_height`: each curve's
/// thickness is its topography above it (within 10 nm of the layer written), every E is recovered within its
/// interval at the stated coverage, and the same map fitted as infinitely thick reads a
/// stiffer sample; `thickness` with `substrate_height`, or a substrate above the sample, is
/// refused naming `substrate_height`.
#[test]
fn a_thin_layer_is_fitted_with_its_thickness_from_the_topography() {
    let z = -4e-6;
    let path = layer_map("layer", Some(z));
    let with = FitMapRequest {
        substrate_height: Some(z),
        ..request(&path, 2)
    };
    let m = run(&with, &probe(), &Progress::default())
        .expect("fit-map")
        .output;
    let thick = fitted(&path, 2);
    let (mut inside, mut fits, mut stiffer) = (0, 0, 0);
    for (c, t) in m.curves.iter().zip(&thick.curves) {
        if c.flag != CurveFlag::Fitted {
            continue;
        }
        let h = c.thickness.expect("thickness");
        // the fitted topography above the substrate (to the refits' tolerance), within 10 nm of the layer written (the soft inclusion's contact point is
        // the least constrained)
        let want = surface(c.ix, c.iy) - z;
        assert!(
            (h - want).abs() < 10e-9,
            "({}, {}): {h} vs {want}",
            c.ix,
            c.iy
        );
        let topography = c.contact_height.unwrap() - z;
        assert!((h - topography).abs() < 1e-4 * h, "{h} vs {topography}");
        let truth = modulus(c.ix, c.iy);
        let [lo, hi] = c.intervals[0];
        inside += usize::from(lo.unwrap() <= truth && truth <= hi.unwrap());
        fits += 1;
        stiffer += usize::from(t.values[0].unwrap() > 1.3 * truth);
    }
    assert!(inside >= 54 && fits == N * N - 1, "{inside} of {fits}");
    assert_eq!(stiffer, fits);
    let doc = afmdyn::report::fit_map::document(&m);
    assert!(doc["preprocessing"]["bottom_effect"]
        .as_str()
        .unwrap()
        .contains("above the substrate"));
    let refused = |r: FitMapRequest| match run(&r, &probe(), &Progress::default()) {
        Err(afmdyn::SimError::OutOfRange { name, .. }) => name,
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("accepted"),
    };
    let both = FitMapRequest {
        thickness: Some(1e-6),
        ..with.clone()
    };
    assert_eq!(refused(both), "substrate_height");
    let above = FitMapRequest {
        substrate_height: Some(3e-6),
        ..with
    };
    let e = run(&above, &probe(), &Progress::default()).err().unwrap();
    assert!(e.to_string().contains("substrate_height"), "{e}");
}
