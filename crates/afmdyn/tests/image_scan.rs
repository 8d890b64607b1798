//! The time-domain PI scan of an image (issue 46, [`afmdyn::request::image_scan`] over
//! [`afmdyn::analysis::am_loop`]): the lock-in demodulates a free lever's first harmonic as the
//! linear oscillator's closed form gives it and filters as a first-order low-pass does; the PI
//! controller is the position form with conditional integration; scanned slowly, the image
//! converges to the ideal-feedback image (the exact operating points of `approach
//! --setpoint`); scanned faster, the tracking error grows with the scan rate and the tip
//! parachutes off a step down; the image does not depend on the thread count; bad settings are
//! refused by name.

use afmdyn::analysis::am_loop::{
    demodulate_period, demodulate_period_stepped, FeedbackGains, LockIn, PiController,
};
use afmdyn::analysis::observables::free_response;
use afmdyn::analysis::progress::Progress;
use afmdyn::integrate::{build, IntegratorOptions};
use afmdyn::model::CantileverModel;
use afmdyn::params::SweepParam;
use afmdyn::probe::Probe;
use afmdyn::request::image::{ImageRequest, SampleMap};
use afmdyn::request::image_scan::PiScan;
use afmdyn::study::scan::pi_image;
use afmdyn::SimError;
use nalgebra::DVector;
use serde_json::Value;

fn repo(path: &str) -> String {
    std::fs::read_to_string(format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// The point-mass probe over polystyrene with quality factor `q`.
fn probe(q: f64) -> toml::Table {
    let mut p: toml::Table = repo("examples/probe-point-mass-dmt.toml").parse().unwrap();
    p["cantilever"]["quality_factor"] = toml::Value::Float(q);
    p
}

/// A row of the document's `image` block (`retrace` for `dir` 1), in nm where `nm`.
fn row(doc: &Value, dir: usize, key: &str, scale: f64) -> Vec<f64> {
    let block = if dir == 0 {
        &doc["image"]
    } else {
        &doc["image"]["retrace"]
    };
    block[key][0]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap_or(f64::NAN) * scale)
        .collect()
}

/// The lock-in's demodulation of one period of the free point mass far from the sample equals
/// the linear oscillator's steady state z = A sin(Ωτ + π/2 − φ) (A, φ from the free response
/// |H|, −arg H): the deflection has its first harmonic only, which the rectangle rule over M
/// samples integrates exactly; the low-pass answers a unit step as 1 − e^{−kT/τ_L}.
#[test]
fn lock_in_demodulates_the_free_lever_and_filters_as_a_first_order_low_pass() {
    let p = Probe::from_table(&probe(400.0), "probe").unwrap().params;
    // 1000 g0 away: the van der Waals force is 1e-13 of the drive's there
    let p = p.with(SweepParam::Alpha5, 1000.0);
    let model = CantileverModel::new(&p).unwrap();
    let free = free_response(&model).unwrap();
    let (a, phi) = (free.amplitude, free.phase);
    let z0 = DVector::from_vec(vec![a * phi.cos(), a * p.omega * phi.sin()]);
    for samples in [8, 32] {
        let mut integ = build(&model, IntegratorOptions::default(), 0.0, &z0).unwrap();
        let (am, ph) = demodulate_period(integ.as_mut(), &model, samples).unwrap();
        assert!((am / a - 1.0).abs() < 1e-10, "{samples}: {am} vs {a}");
        assert!((ph - phi).abs() < 1e-10, "{samples}: {ph} vs {phi}");
        // and the state came back: one period of the steady state
        assert!((integ.state() - &z0).norm() < 1e-10 * z0.norm());
    }
    let (period, tau_l) = (2.0, 7.0);
    let mut lock = LockIn::new(tau_l, period, 0.0, 0.0);
    for k in 1..=20 {
        lock.update(1.0, 0.3);
        let expected = 1.0 - (-(k as f64) * period / tau_l).exp();
        assert!((lock.amplitude() - expected).abs() < 1e-14);
        assert!((lock.phase() - 0.3).abs() < 1e-14);
    }
    // τ_L = 0: the period's own value
    let mut lock = LockIn::new(0.0, period, 0.5, 0.0);
    lock.update(0.8, 2.0);
    assert!((lock.amplitude() - 0.8).abs() < 1e-15 && (lock.phase() - 2.0).abs() < 1e-15);
}

/// z_{k} = z_origin + K_P e + K_I T k e for a constant error; held at the range's limit, an
/// error driving it further out is not integrated, one driving it back is; the default gains
/// damp the loop critically (K_I (τ_c + τ_L) = 1/4).
#[test]
fn pi_controller_is_the_position_form_with_conditional_integration() {
    let g = FeedbackGains {
        proportional: 0.5,
        integral: 0.01,
        time_constant: 0.0,
    };
    let mut pi = PiController::new(&g, 2.0, 1.0);
    for k in 1..=5 {
        let (z, sat) = pi.output(0.1, (-10.0, 10.0));
        assert!((z - (1.0 + 0.5 * 0.1 + 0.01 * 2.0 * k as f64 * 0.1)).abs() < 1e-15);
        assert!(!sat);
    }
    // a range ending just above: saturated, the error pushing out is not integrated
    let (z, sat) = pi.output(0.1, (-10.0, 1.0));
    assert!(sat && z == 1.0);
    let (z, sat) = pi.output(-0.1, (-10.0, 10.0));
    // the sum holds the 5 integrated errors and this one: 5 × 0.1 − 0.1
    assert!(!sat && (z - (1.0 - 0.05 + 0.02 * 0.4)).abs() < 1e-15, "{z}");
    let d = FeedbackGains::for_lever(400.0, 1.0);
    let tau_c = 800.0;
    assert!((d.time_constant - tau_c / 4.0).abs() < 1e-12);
    assert!((d.integral * (tau_c + d.time_constant) - 0.25).abs() < 1e-15);
    assert_eq!(d.proportional, 0.0);
}

/// `afmdyn image --feedback pi` on `probe` over `map` at setpoint 0.7, 10 pixels.
fn scan(probe: &toml::Table, map: &str, scan: PiScan, threads: usize) -> Value {
    let map = SampleMap::parse(map, "<test>").unwrap();
    let req = ImageRequest {
        pixels: 10,
        ..ImageRequest::at(0.7)
    };
    pi_image(probe, &map, &req, &scan, Some(threads), &Progress::new())
        .unwrap()
        .document(0.7)
}

/// PS | a 1 GPa polymer | PS | PS 10 nm higher, one line of 1 µm (the domains' edges on pixel
/// edges at 10 pixels).
const MAP: &str = r#"
size = [1.0e-6, 0.0]
[[domain]]
name = "polymer"
x = [0.3e-6, 0.5e-6]
[domain.sample]
law = "dmt"
youngs_modulus = 1e9
poisson_ratio = 0.4
hamaker = 6.6e-20
intermolecular_distance = 0.165e-9
[[domain]]
name = "step"
x = [0.7e-6, 1.0e-6]
height = 10e-9
"#;

/// [`scan`] of [`MAP`] at `rate` (Hz), the other settings the lever's defaults, one thread.
fn at_rate(p: &toml::Table, rate: f64) -> Value {
    scan(
        p,
        MAP,
        PiScan {
            scan_rate: Some(rate),
            ..PiScan::default()
        },
        1,
    )
}

/// The pixels of a direction whose predecessor in the scan (left in the trace, right in the
/// retrace) has the same ideal height: those the slow loop has settled on.
fn settled(ideal: &[f64], dir: usize) -> Vec<usize> {
    (0..ideal.len())
        .filter(|&i| {
            let prev = if dir == 0 {
                i.checked_sub(1)
            } else {
                Some(i + 1)
            };
            prev.and_then(|k| ideal.get(k))
                .is_some_and(|h| (h - ideal[i]).abs() < 1e-3)
        })
        .collect()
}

/// Scanned slowly (2 Hz: 7500 drive periods, 13 loop time constants 1/K_I per pixel), every
/// pixel the loop has settled on records the ideal image's height (to 0.01 nm), phase (to
/// 0.05°) and amplitude (the setpoint, to 1e-3); the pixels after an edge lag behind it, and
/// the RMS height error grows with the scan rate as the dwell shrinks (∝ the scan rate: the
/// lag's share of a pixel), while the error image's RMS grows too.
#[test]
fn slow_scan_converges_to_the_ideal_image_and_the_error_grows_with_the_scan_rate() {
    let p = probe(100.0);
    let at = |rate: f64| at_rate(&p, rate);
    let slow = at(2.0);
    let ideal = row(&slow, 0, "ideal_height", 1e9);
    // the ideal image's own phases (`image --feedback ideal`)
    let m = SampleMap::parse(MAP, "<test>").unwrap();
    let req = ImageRequest {
        pixels: 10,
        ..ImageRequest::at(0.7)
    };
    let ideal_doc = afmdyn::study::image_ideal::image(&p, &m, &req)
        .unwrap()
        .document(0.7);
    assert_eq!(row(&ideal_doc, 0, "height", 1e9), ideal);
    let ideal_phase = row(&ideal_doc, 0, "phase_deg", 1.0);
    for dir in [0, 1] {
        let h = row(&slow, dir, "height", 1e9);
        let ph = row(&slow, dir, "phase_deg", 1.0);
        let amp = row(&slow, dir, "amplitude", 1e9);
        let idx = settled(&ideal, dir);
        assert!(idx.len() >= 6, "{idx:?}");
        for &i in &idx {
            assert!(
                (h[i] - ideal[i]).abs() < 0.01,
                "{dir} {i}: {} vs {}",
                h[i],
                ideal[i]
            );
            assert!(
                (ph[i] - ideal_phase[i]).abs() < 0.05,
                "{dir} {i}: {}",
                ph[i]
            );
            assert!((amp[i] / 7.0 - 1.0).abs() < 1e-3, "{dir} {i}: {}", amp[i]);
        }
    }
    let rms = |d: &Value, k: &str| d["artefacts"]["trace"][k].as_f64().unwrap();
    let docs: Vec<Value> = [8.0, 30.0].into_iter().map(at).collect();
    let e: Vec<f64> = std::iter::once(&slow)
        .chain(&docs)
        .map(|d| rms(d, "height_rms_error"))
        .collect();
    let t: Vec<f64> = std::iter::once(&slow)
        .chain(&docs)
        .map(|d| rms(d, "tracking_error_rms"))
        .collect();
    assert!(e[0] < e[1] && e[1] < e[2], "{e:?}");
    assert!(t[0] < t[1] && t[1] < t[2], "{t:?}");
    // the lag's share of a pixel: ∝ the scan rate while it is short against the pixel
    assert!((3.0..5.0).contains(&(e[1] / e[0])), "{e:?}");
    assert!(e[0] < 0.1e-9, "{e:?}");
}

/// Every pixel's last drive period closes the per-mode energy balance (ΔE_j = drive − damping −
/// sample − coupling, [`afmdyn::analysis::observables`]) to 1e-9 of the drive's work, settled
/// or not: at 2 Hz and at 100 Hz, where the tip parachutes.
#[test]
fn every_pixel_closes_its_energy_balance() {
    let p = probe(100.0);
    let m = SampleMap::parse(MAP, "<test>").unwrap();
    let req = ImageRequest {
        pixels: 10,
        ..ImageRequest::at(0.7)
    };
    for rate in [2.0, 100.0] {
        let s = PiScan {
            scan_rate: Some(rate),
            ..PiScan::default()
        };
        let img = pi_image(&p, &m, &req, &s, Some(2), &Progress::new()).unwrap();
        for px in img.lines[0].trace.iter().chain(&img.lines[0].retrace) {
            assert!(px.energy_residual < 1e-9, "{rate}: {}", px.energy_residual);
        }
    }
}

/// Scanned fast (100 Hz: 150 drive periods per pixel), the retrace falls off the 10 nm step
/// faster than the loop lowers the tip: the tip leaves the sample and its amplitude rises
/// toward the free amplitude (parachuting), reported per pixel and as a warning; the trace
/// climbs the step and never loses contact, and at 2 Hz neither does.
#[test]
fn fast_scan_parachutes_off_a_step_down() {
    let p = probe(100.0);
    let at = |rate: f64| at_rate(&p, rate);
    let flags = |d: &Value, dir: usize| -> Vec<bool> {
        let b = if dir == 0 {
            &d["image"]
        } else {
            &d["image"]["retrace"]
        };
        b["lost_contact"][0]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_bool().unwrap())
            .collect()
    };
    let fast = at(100.0);
    let back = flags(&fast, 1);
    // the pixels just left of the step (x < 0.7 µm), where the retrace arrives from above
    assert!(back[6], "{back:?}");
    assert!(back[7..].iter().all(|b| !b), "{back:?}");
    assert!(flags(&fast, 0).iter().all(|b| !b));
    assert_eq!(
        fast["artefacts"]["retrace"]["lost_contact_pixels"].as_u64(),
        Some(back.iter().filter(|b| **b).count() as u64)
    );
    assert!(fast["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .any(|w| w.as_str().unwrap().contains("parachuting")));
    let slow = at(2.0);
    assert!(flags(&slow, 0).iter().chain(&flags(&slow, 1)).all(|b| !b));
}

/// An image's lines are tasks that depend only on the request and their number: 1 and 2
/// threads give the same document, and two lines over a map without y-structure are equal.
#[test]
fn the_scan_does_not_depend_on_the_thread_count() {
    let p = probe(100.0);
    let map2d = MAP.replace("size = [1.0e-6, 0.0]", "size = [1.0e-6, 0.2e-6]");
    let m = SampleMap::parse(&map2d, "<test>").unwrap();
    let req = ImageRequest {
        pixels: 10,
        lines: Some(2),
        ..ImageRequest::at(0.7)
    };
    let s = PiScan {
        scan_rate: Some(30.0),
        ..PiScan::default()
    };
    let run = |threads| {
        pi_image(&p, &m, &req, &s, Some(threads), &Progress::new())
            .unwrap()
            .document(0.7)
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one, two);
    let h = &one["image"]["height"];
    assert_eq!(h[0], h[1]);
}

/// A real lever (RTESPA-300 from the cantilever library over polystyrene, Q = 500 at 300 kHz;
/// `examples/probe-rtespa300-polystyrene.toml`) at the default settings (a pixel 5/K_I long,
/// K_I from its τ_c = 2Q/ω₀): the settled pixels record the ideal heights within 0.05 nm.
#[test]
fn real_lever_at_the_default_settings_records_the_ideal_heights() {
    let p: toml::Table = repo("examples/probe-rtespa300-polystyrene.toml")
        .parse()
        .unwrap();
    let d = scan(&p, MAP, PiScan::default(), 2);
    let q = Probe::from_table(&p, "probe").unwrap().calibration;
    let tau_c = 2.0 * q.quality_factor / (std::f64::consts::TAU * q.resonance_frequency);
    let ki = d["scan"]["integral_gain"].as_f64().unwrap();
    assert!((ki * 1.25 * tau_c * 4.0 - 1.0).abs() < 1e-12);
    let pixel = d["scan"]["pixel_time"].as_f64().unwrap();
    assert!((pixel * ki / 5.0 - 1.0).abs() < 1e-3, "{pixel} {ki}");
    let ideal = row(&d, 0, "ideal_height", 1e9);
    assert!(ideal.iter().all(|h| h.is_finite()), "{ideal:?}");
    for dir in [0, 1] {
        let h = row(&d, dir, "height", 1e9);
        for i in settled(&ideal, dir) {
            assert!(
                (h[i] - ideal[i]).abs() < 0.05,
                "{dir} {i}: {} vs {}",
                h[i],
                ideal[i]
            );
        }
    }
}

/// Settings out of range are refused naming them.
#[test]
fn bad_settings_are_refused_by_name() {
    let p = probe(100.0);
    let m = SampleMap::parse(MAP, "<test>").unwrap();
    let req = ImageRequest {
        pixels: 10,
        ..ImageRequest::at(0.7)
    };
    let name = |s: PiScan| match pi_image(&p, &m, &req, &s, Some(1), &Progress::new()) {
        Err(SimError::OutOfRange { name, .. }) => name,
        other => panic!("{:?}", other.map(|_| ())),
    };
    let rate = |r: f64| PiScan {
        scan_rate: Some(r),
        ..PiScan::default()
    };
    // faster than a drive period per pixel; so slow it needs more than 1e9 periods; not a rate
    for r in [20e3, 1e-4, 0.0, -1.0, f64::NAN] {
        assert_eq!(name(rate(r)), "scan_rate", "{r}");
    }
    for g in [(-1.0, 10.0), (0.0, 0.0), (0.1, f64::INFINITY)] {
        let s = PiScan {
            gains: Some(g),
            ..PiScan::default()
        };
        assert_eq!(name(s), "gains", "{g:?}");
    }
    // issue 60 D: 1e300 s (and anything above 1000 s) is beyond any lock-in
    for t in [-1e-6, f64::NAN, 1e300, 2e3] {
        let s = PiScan {
            time_constant: Some(t),
            ..PiScan::default()
        };
        assert_eq!(name(s), "time_constant", "{t}");
    }
}

/// The scan moves one model and its Taylor integrator to each period's gap in place
/// ([`CantileverModel::set_gap`], [`afmdyn::integrate::Integrator::set_gap`]) instead of
/// assembling them every period: the model equals the assembled one field for field, and a
/// period integrated after the move equals one of a freshly built integrator bit for bit, on the
/// point mass and on the beam (DMT: the Taylor integrator), into contact and far from it.
#[test]
fn a_model_moved_to_a_gap_equals_the_model_built_there() {
    for file in ["probe-point-mass-dmt.toml", "probe-beam-dmt.toml"] {
        let t: toml::Table = repo(&format!("examples/{file}")).parse().unwrap();
        let p = Probe::from_table(&t, "probe").unwrap().params;
        let opts = IntegratorOptions::default();
        let mut moved = CantileverModel::new(&p.with(SweepParam::Alpha5, 5.0)).unwrap();
        let z0 = moved.rest();
        let mut integ = build(&moved, opts.clone(), 0.0, &z0).unwrap();
        let mut z = z0.clone();
        // far, near the sample, far again
        for a5 in [3.0, 0.6, 0.2, 0.45, 40.0] {
            let built = CantileverModel::new(&p.with(SweepParam::Alpha5, a5)).unwrap();
            moved.set_gap(a5).unwrap();
            assert_eq!(moved, built, "{file} α5 = {a5}");
            assert!(
                integ.set_gap(a5),
                "{file}: the Taylor integrator moves in place"
            );
            integ.reset(0.0, &z).unwrap();
            let mut fresh = build(&built, opts.clone(), 0.0, &z).unwrap();
            let a = demodulate_period(integ.as_mut(), &moved, 32).unwrap();
            let b = demodulate_period(fresh.as_mut(), &built, 32).unwrap();
            assert_eq!(a, b, "{file} α5 = {a5}");
            assert_eq!(integ.state(), fresh.state(), "{file} α5 = {a5}");
            assert_eq!(integ.tau(), fresh.tau());
            z = integ.state().clone();
        }
        // an α5 the parameters refuse leaves the model as it was
        let before = moved.clone();
        assert!(moved.set_gap(f64::NAN).is_err());
        assert_eq!(moved, before);
        assert!(!integ.set_gap(f64::NAN));
    }
}

/// The lock-in reads its samples from the Taylor integrator's dense output instead of cutting
/// its steps at each ([`demodulate_period`] against [`demodulate_period_stepped`]): over 40
/// tapping periods of the point mass (DMT), started on the free orbit with the sample at 0.7 A0
/// and each period from the same state, the first harmonic and the state at the period's end
/// agree to 1e-9 of the amplitude (the integrator's tolerance 1e-12 relative to max(1, ‖z‖)
/// per step, some tens of steps), and the dense sampling takes fewer steps.
#[test]
fn dense_and_stepped_demodulation_agree() {
    let p = Probe::from_table(&probe(400.0), "probe").unwrap().params;
    let far = CantileverModel::new(&p.with(SweepParam::Alpha5, 1000.0)).unwrap();
    let free = free_response(&far).unwrap();
    let (a0, phi) = (free.amplitude, free.phase);
    let z0 = DVector::from_vec(vec![a0 * phi.cos(), a0 * p.omega * phi.sin()]);
    let model = CantileverModel::new(&p.with(SweepParam::Alpha5, 0.7 * a0)).unwrap();
    let opts = IntegratorOptions::default();
    let mut a = build(&model, opts.clone(), 0.0, &z0).unwrap();
    let mut tapped = 0;
    for k in 0..40 {
        let mut b = build(&model, opts.clone(), a.tau(), a.state()).unwrap();
        let (steps_a, steps_b) = (a.work(), b.work());
        let dense = demodulate_period(a.as_mut(), &model, 32).unwrap();
        let stepped = demodulate_period_stepped(b.as_mut(), &model, 32).unwrap();
        assert!(
            (dense.0 - stepped.0).abs() <= 1e-9 * a0,
            "{k}: {dense:?} {stepped:?}"
        );
        assert!(
            (dense.1 - stepped.1).abs() <= 1e-9,
            "{k}: {dense:?} {stepped:?}"
        );
        assert_eq!(a.tau(), b.tau());
        let dz = (a.state() - b.state()).amax();
        assert!(dz <= 1e-9 * a0.max(1.0), "{k}: {dz:e}");
        assert!(a.work() - steps_a < b.work() - steps_b, "{k}");
        tapped += usize::from(dense.0 < 0.9 * a0);
    }
    assert!(tapped >= 20, "the periods tap: {tapped}");
}

/// A distributed scan's worker rebuilds the plan from its recipe without the study (no
/// approach curves) and scans its lines from the stage's start (the study's line job): the
/// same lines, bit for bit (the results' text equal), as the planning process's own study.
#[test]
#[cfg(feature = "files")] // (the plans are the files feature's: stores and ledgers)
fn a_worker_scans_the_lines_of_the_start_bit_for_bit() {
    use afmdyn::request::image_scan::ScanRecipe;
    use afmdyn::study::plan::{plan, rebuild, Recipe};
    let map2d = MAP.replace("size = [1.0e-6, 0.0]", "size = [1.0e-6, 0.2e-6]");
    let scan = ScanRecipe {
        probe: probe(100.0),
        map: SampleMap::parse(&map2d, "<test>").unwrap(),
        request: ImageRequest {
            pixels: 6,
            lines: Some(2),
            ..ImageRequest::at(0.7)
        },
        scan: PiScan {
            scan_rate: Some(40.0),
            ..PiScan::default()
        },
    };
    let here = plan(Recipe::Image { scan }).unwrap();
    let stage = here.stage(0, &[]).unwrap();
    assert_eq!(stage.tasks, vec![0, 1]);
    let worker = rebuild(here.recipe()).unwrap();
    let cancel = std::sync::atomic::AtomicBool::new(false);
    for t in stage.tasks {
        let remote = worker.run(&stage.start, t, &cancel).unwrap();
        assert_eq!(remote, here.run("", t, &cancel).unwrap(), "line {t}");
    }
    assert!(worker.run("not a start", 0, &cancel).is_err());
}

/// examples/probe-water-beam.toml (three modes in water, Q₁ ≈ 2.3) over a linear sample.
fn water_linear() -> toml::Table {
    let mut p: toml::Table = repo("examples/probe-water-beam.toml").parse().unwrap();
    p["sample"] = toml::toml! { law = "linear" stiffness = 1.0 }.into();
    p
}

/// With a temperature the scan is a function of its seed: 1 and 2 threads give the same
/// document, another seed another one; the thermal force moves every pixel (the heights of a
/// flat sample spread, where without it they are one value), by far less than the free
/// amplitude; its energy residual is not given; a law other than the linear one is refused
/// naming it.
#[test]
fn a_thermal_scan_is_its_seeds() {
    let p = water_linear();
    let m = SampleMap::parse("size = [1.0e-6, 0.2e-6]\n", "<test>").unwrap();
    let req = ImageRequest {
        pixels: 8,
        lines: Some(2),
        ..ImageRequest::at(0.7)
    };
    let run = |temperature: Option<f64>, seed: u64, threads: usize| {
        let s = PiScan {
            temperature,
            seed,
            ..PiScan::default()
        };
        pi_image(&p, &m, &req, &s, Some(threads), &Progress::new())
            .unwrap()
            .document(0.7)
    };
    let one = run(Some(295.0), 1, 1);
    assert_eq!(one, run(Some(295.0), 1, 2));
    let other = run(Some(295.0), 2, 1);
    assert_ne!(one["image"]["height"], other["image"]["height"]);
    let spread = |d: &Value| {
        let h: Vec<f64> = (0..2).flat_map(|dir| row(d, dir, "height", 1e9)).collect();
        let mean = h.iter().sum::<f64>() / h.len() as f64;
        (h.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / h.len() as f64).sqrt()
    };
    let cold = run(None, 1, 1);
    // the energy balance has no random work: its residual is not given under the thermal force
    for dir in ["trace", "retrace"] {
        assert!(one["artefacts"][dir]["energy_residual_max"].is_null());
        assert!(
            cold["artefacts"][dir]["energy_residual_max"]
                .as_f64()
                .unwrap()
                < 1e-9
        );
    }
    let (hot, still) = (spread(&one), spread(&cold));
    println!("height spread: {hot:.4} nm with the thermal force, {still:.2e} nm without");
    assert!(still < 1e-6, "{still}");
    assert!(hot > 1e-3 && hot < 1.0, "{hot}");
    // the lines' streams differ: two lines over a map without y-structure are not equal
    assert_ne!(one["image"]["height"][0], one["image"]["height"][1]);
    // DMT by the exponential Euler step: at T → 0 its heights are the deterministic scan's
    // within the step's own error (1.4 pm measured; docs/tutorials/thermal.md)
    let dmt = probe(100.0);
    let flat = SampleMap::parse("size = [1.0e-6, 0.0]\n", "<test>").unwrap();
    let short = ImageRequest {
        pixels: 4,
        ..ImageRequest::at(0.7)
    };
    let heights = |map: &SampleMap, temperature: Option<f64>| {
        let s = PiScan {
            temperature,
            ..PiScan::default()
        };
        let d = (pi_image(&dmt, map, &short, &s, Some(1), &Progress::new()))
            .unwrap()
            .document(0.7);
        // the scheme's own error is said (thermal.scheme-error), once
        let said = (d["warnings"].as_array().into_iter().flatten())
            .filter(|w| w.as_str().unwrap_or("").contains("exponential Euler"))
            .count();
        assert_eq!(
            said,
            usize::from(temperature.is_some()),
            "{}",
            d["warnings"]
        );
        row(&d, 0, "height", 1e12)
    };
    let bias = |map: &SampleMap| {
        let (cold, hot) = (heights(map, None), heights(map, Some(1e-3)));
        (cold.iter().zip(&hot))
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    let dmt_bias = bias(&flat);
    println!("DMT at T → 0: heights {dmt_bias:.3} pm from the deterministic scan's");
    assert!(dmt_bias < 5.0, "{dmt_bias} pm");
    // an SLS domain (its dashpot's extension a state of the step, exact in each region): at
    // T → 0 its pixels are the deterministic scan's within the DMT background's error
    let stripe = |sample: &str| {
        let text = format!(
            "size = [1e-6, 0]\n[[domain]]\nname = \"j\"\nx = [4e-7, 1e-6]\n[domain.sample]\n{sample}"
        );
        SampleMap::parse(&text, "<test>").unwrap()
    };
    let sls =
        stripe("law = \"sls\"\nstiffness = 2.0\nmaxwell_stiffness = 3.0\nrelaxation_time = 1e-6\n");
    let sls_bias = bias(&sls);
    println!("SLS at T → 0: heights {sls_bias:.3} pm from the deterministic scan's");
    assert!(sls_bias < 5.0, "{sls_bias} pm");
    // an impact domain (its impacts and sticking the step's events): at T → 0 its pixels are
    // the deterministic scan's within the DMT background's error
    let impact = stripe("law = \"impact\"\nrestitution = 0.5\n");
    let impact_bias = bias(&impact);
    println!("impact at T → 0: heights {impact_bias:.3} pm from the deterministic scan's");
    assert!(impact_bias < 5.0, "{impact_bias} pm");
}
