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

/// One approach at (ix, iy) as CSV lines: tip positions from 1 µm above the surface to 1.5 µm
/// below; the last curve of the first line `flat` (never reaching the sample).
fn curve(text: &mut String, ix: usize, iy: usize, rng: &mut ChaCha8Rng, flat: bool) {
    let e_star = 1.0
        / ((1.0 - 0.27 * 0.27) / afmdyn::cantilevers::SILICON_YOUNGS_MODULUS
            + (1.0 - NU * NU) / modulus(ix, iy));
    let kh = 4.0 / 3.0 * e_star * R.sqrt();
    let cp = surface(ix, iy);
    let (x0, y0) = (ix as f64 * PITCH, iy as f64 * PITCH);
    for i in 0..ROWS {
        let depth = if flat { 0.5e-6 } else { 2.5e-6 };
        let x = cp + 1e-6 - depth * i as f64 / (ROWS - 1) as f64;
        let f = kh * (cp - x).max(0.0).powf(1.5);
        let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
        let noise = SIGMA * (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos();
        writeln!(text, "{x0:e},{y0:e},{:e},{:e}", x - f / K, f + noise).unwrap();
    }
}

/// The synthetic map written to a fresh directory: its CSV's path.
fn map(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("afmdyn-fit-map-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(78);
    let mut text = String::from("x,y,height,force\n");
    for iy in 0..N {
        for ix in 0..N {
            curve(&mut text, ix, iy, &mut rng, iy == 0 && ix == N - 1);
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
