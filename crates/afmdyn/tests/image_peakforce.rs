//! PeakForce images (issue 61 §3, [`afmdyn::request::image_peakforce`]): every pixel's peak
//! force is the setpoint to the feedback's tolerance; a pixel is the standalone `peakforce
//! --setpoint` tap of its material (exactly where the line engages on it, to a stated
//! tolerance where the feedback continues into it from another material); a two-material
//! sample gives the two materials' channels; the image does not depend on the thread count;
//! the door gives it (`afmdyn image --mode peakforce`) and refuses an AM probe by name; a
//! change of material at every pixel costs one tap each.

use afmdyn::analysis::peakforce::SETPOINT_TOL;
use afmdyn::analysis::progress::Progress;
use afmdyn::probe::Probe;
use afmdyn::request::image::{ImageRequest, SampleMap};
use afmdyn::request::image_job::{ImageJob, ImageMode};
use afmdyn::request::{PeakForceRequest, Resolved};
use afmdyn::study::image::ImageOutput;
use afmdyn::study::peakforce_image::peakforce_image;
use afmdyn::study::peakforce_image::PeakForceImage;

/// The setpoint (N).
const SETPOINT: f64 = 2e-9;

fn repo(path: &str) -> String {
    std::fs::read_to_string(format!("{}/../../{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// The point-mass probe of Amo & Garcia 2016 (E* = 1 GPa) at f₀/f_m = 100 (f_m = 1.5 kHz).
fn probe() -> toml::Table {
    let mut p: toml::Table = repo("examples/probe-peakforce-amo-garcia.toml")
        .parse()
        .unwrap();
    p["drive"]["modulation_frequency"] = toml::Value::Float(1.5e3);
    p
}

/// The two-material map: background, a stiffer less adhesive domain, a 5 nm terrace.
fn map() -> SampleMap {
    SampleMap::parse(&repo("examples/sample-peakforce-blend.toml"), "map").unwrap()
}

fn request(pixels: usize, lines: usize) -> ImageRequest {
    ImageRequest::with(SETPOINT, Some(pixels), Some(lines), None)
}

fn image(pixels: usize, lines: usize, threads: usize) -> PeakForceImage {
    peakforce_image(
        &probe(),
        &map(),
        &request(pixels, lines),
        Some(threads),
        &Progress::new(),
    )
    .unwrap()
}

/// The standalone `peakforce --setpoint` tap of the probe with `sample` as its `[sample]`
/// (`None`: the probe's own) at `temperature` (K; `None`: none): its document.
fn standalone(sample: Option<&toml::Table>, temperature: Option<f64>) -> serde_json::Value {
    let mut table = probe();
    if let Some(s) = sample {
        table.insert("sample".into(), toml::Value::Table(s.clone()));
    }
    let pr = Probe::from_table(&table, "probe").unwrap();
    let model = Resolved {
        params: pr.params,
        probe: Some(pr),
    };
    let request = PeakForceRequest {
        setpoint: Some(SETPOINT),
        temperature,
        ..PeakForceRequest::default()
    };
    afmdyn::request::run::run(&request, &model, &Progress::new())
        .unwrap()
        .json
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs())
}

#[test]
fn every_pixel_holds_the_setpoint_and_a_two_material_sample_gives_both_materials() {
    let img = image(8, 6, 2);
    assert_eq!(img.materials.len(), 2, "background and the stiff domain");
    // at f₀/f_m = 100 the DMT fit reads each material ~1.5 × its E* (the sample file's
    // comment): said per material, as a single tap says it, and nothing else
    assert_eq!(img.warnings.len(), 2, "{:?}", img.warnings);
    for (w, m) in img.warnings.iter().zip(["background", "stiff"]) {
        assert!(w.starts_with(&format!("{m}: modulus_dmt reads ")), "{w}");
    }
    let mut seen = [0usize; 2];
    for j in 0..img.y.len() {
        for i in 0..img.x.len() {
            let t = img.tap(j, i).expect("every pixel reaches the setpoint");
            // the feedback's tolerance
            assert!(
                (t.peak_force - SETPOINT).abs() <= SETPOINT_TOL * SETPOINT,
                "pixel ({j}, {i}): peak force {} against {SETPOINT}",
                t.peak_force
            );
            let m = img.material[j][i];
            seen[m] += 1;
            // each material's channels: its engaged operating point, to the continuation's
            // tolerance where the line enters it from the other material
            let e = img.materials[m].engaged.unwrap();
            for (a, b, what) in [
                (t.z_c, e.z_c, "z_c"),
                (t.modulus_dmt, e.modulus_dmt, "modulus_dmt"),
                (t.adhesion, e.adhesion, "adhesion"),
                (t.deformation, e.deformation, "deformation"),
            ] {
                assert!(
                    close(a, b, 1e-4),
                    "pixel ({j}, {i}) {what}: {a} against {b}"
                );
            }
        }
    }
    assert!(seen[0] > 0 && seen[1] > 0, "{seen:?}");
    let (bg, stiff) = (
        img.materials[0].engaged.unwrap(),
        img.materials[1].engaged.unwrap(),
    );
    // the stiffer, less adhesive domain: a larger modulus, less adhesion (H R/(6 a0²): 1.25
    // against 1.67 nN), less deformation
    assert!(stiff.modulus_dmt > 2.0 * bg.modulus_dmt, "{stiff:?} {bg:?}");
    assert!(close(stiff.adhesion, -1.25e-9, 1e-6), "{stiff:?}");
    assert!(close(bg.adhesion, -5e-9 / 3.0, 1e-6), "{bg:?}");
    assert!(stiff.deformation < bg.deformation, "{stiff:?} {bg:?}");
    // the true moduli of the two materials (E* = 1 GPa and 3 GPa; the tip of 1e15 Pa)
    assert!(close(img.materials[0].true_modulus, 1e9, 1e-5));
    assert!(close(img.materials[1].true_modulus, 3e9, 1e-5));
    // the apparent height: 0 on the background, its z_c's difference on the domain, the 5 nm
    // terrace at its true height
    for j in 0..img.y.len() {
        for i in 0..img.x.len() {
            let h = img.value("height", j, i);
            let expected = img.true_height[j][i] + img.tap(j, i).unwrap().z_c - img.reference;
            assert!((h - expected).abs() < 1e-18);
        }
    }
    let terrace = img.y.iter().position(|&y| y > 0.7e-6).unwrap();
    assert!((img.value("height", terrace, 0) - 5e-9).abs() < 1e-15);
}

#[test]
fn a_pixel_is_the_standalone_setpoint_tap_of_its_material() {
    let img = image(8, 6, 2);
    let doc = map();
    let stiff = doc.domains[0].sample.as_ref().unwrap();
    for (m, sample) in [(0usize, None), (1, Some(stiff))] {
        let d = standalone(sample, None);
        let ch = &d["channels"];
        let e = img.materials[m].engaged.unwrap();
        // the engage is the standalone search itself: equal bit for bit
        assert_eq!(e.z_c, d["z_c"].as_f64().unwrap(), "material {m}");
        assert_eq!(e.peak_force, ch["peak_force"].as_f64().unwrap());
        assert_eq!(e.modulus_dmt, ch["modulus_dmt"].as_f64().unwrap());
        assert_eq!(e.adhesion, ch["adhesion"].as_f64().unwrap());
        assert_eq!(e.deformation, ch["deformation"].as_f64().unwrap());
        assert_eq!(e.dissipation, ch["dissipation"].as_f64().unwrap());
        // a pixel the feedback continued into from the other material: the same periodic orbit
        // at the same setpoint, to the feedback's tolerance (peak force 1e-6 relative: z_c
        // and the fitted channels to 1e-4)
        let continued = (0..img.y.len())
            .flat_map(|j| (0..img.x.len()).map(move |i| (j, i)))
            .find(|&(j, i)| img.material[j][i] == m && img.pixels[j][i].evaluations > 0);
        if let Some((j, i)) = continued {
            let t = img.tap(j, i).unwrap();
            assert!(close(t.z_c, e.z_c, 1e-4), "{} {}", t.z_c, e.z_c);
            assert!(close(t.modulus_dmt, e.modulus_dmt, 1e-4));
            assert!(close(t.adhesion, e.adhesion, 1e-4));
            assert!(close(t.deformation, e.deformation, 1e-4));
        }
    }
    // the stiff domain is entered from the background along its lines
    assert!(img.pixels.iter().flatten().any(|p| p.evaluations > 0));
}

#[test]
fn the_image_does_not_depend_on_the_thread_count() {
    let one = image(6, 6, 1);
    let two = image(6, 6, 2);
    assert_eq!(one, two, "bit for bit");
}

#[test]
fn the_door_gives_the_image_and_refuses_an_am_probe() {
    let job = |probe: toml::Table| ImageJob {
        mode: ImageMode::Peakforce,
        probe,
        sample: map(),
        request: request(4, 2),
        feedback: None,
        study: None,
        threads: Some(1),
    };
    let j = job(probe());
    let model = j.model().unwrap();
    let d = afmdyn::request::run::run(&j, &model, &Progress::new()).unwrap();
    let ImageOutput::PeakForce(img) = &d.output else {
        panic!("a PeakForce image")
    };
    assert_eq!(img.x.len(), 4);
    let outcome = d.output.outcome(SETPOINT);
    let doc = &outcome.document;
    assert_eq!(doc["mode"], "peakforce");
    for k in [
        "height",
        "modulus_dmt",
        "adhesion",
        "deformation",
        "dissipation",
    ] {
        assert_eq!(doc["image"][k].as_array().unwrap().len(), 2, "{k}");
    }
    assert_eq!(outcome.datasets[0].0, "image");
    // the command line's document: a summary, per material its pixels' statistics
    let summary = &outcome.facts["summary"];
    assert_eq!(summary["image"]["pixels"], 4);
    let materials = summary["materials"].as_array().unwrap();
    let pixels: u64 = materials
        .iter()
        .map(|m| m["pixels"].as_u64().unwrap())
        .sum();
    assert_eq!(pixels, 8);
    for m in materials.iter().filter(|m| m["pixels"].as_u64() > Some(0)) {
        let pf = &m["maps"]["peak_force"];
        assert_eq!(pf["units"], "N");
        assert_eq!(pf["finite"], m["pixels"]);
        assert!((pf["mean"].as_f64().unwrap() - SETPOINT).abs() <= SETPOINT_TOL * SETPOINT);
    }
    assert_eq!(summary["taps"], doc["taps"]);
    let am: toml::Table = repo("examples/probe-point-mass-dmt.toml").parse().unwrap();
    let bad = job(am);
    let err = afmdyn::request::run::run(&bad, &bad.model().unwrap(), &Progress::new())
        .err()
        .unwrap();
    assert!(err.to_string().contains("off-resonance"), "{err}");
}

#[test]
#[cfg(feature = "files")] // (the plans are the files feature's: stores and ledgers)
fn the_plan_of_engages_and_lines_is_the_image_bit_for_bit() {
    use afmdyn::study::plan::{plan, rebuild, Recipe};
    use std::sync::atomic::AtomicBool;
    // with a temperature too: the engages' noise travels with them to the lines
    for temperature in [None, Some(295.0)] {
        let request = ImageRequest {
            temperature,
            ..request(6, 4)
        };
        let recipe = Recipe::PeakForceImage {
            probe: probe(),
            map: map(),
            request,
        };
        let p = plan(recipe).unwrap();
        // as Dask does: every task in a plan rebuilt from its recipe's text
        let worker = rebuild(p.recipe()).unwrap();
        let cancel = AtomicBool::new(false);
        let mut results = Vec::new();
        for stage in 0..p.stages() {
            let st = p.stage(stage, &results).unwrap();
            for t in st.tasks.into_iter().rev() {
                results.push(worker.run(&st.start, t, &cancel).unwrap());
            }
        }
        let out = p.outcome(&results).unwrap();
        let img = peakforce_image(&probe(), &map(), &request, Some(2), &Progress::new());
        let direct = ImageOutput::PeakForce(img.unwrap()).outcome(SETPOINT);
        assert_eq!(out.document, direct.document, "{temperature:?}");
        assert_eq!(out.document.get("thermal").is_some(), temperature.is_some());
    }
}

/// Stripes one pixel wide at 8 pixels a line: the material changes at every pixel.
fn stripes() -> SampleMap {
    let mut text = String::from("size = [1.0e-6, 1.0e-6]\n");
    for k in (1..8).step_by(2) {
        let (a, b) = (
            k as f64 / 8.0 * 1e-6 + 1e-12,
            (k + 1) as f64 / 8.0 * 1e-6 - 1e-12,
        );
        text += &format!(
            "[[domain]]\nname = \"s{k}\"\nx = [{a:e}, {b:e}]\n[domain.sample]\nlaw = \"dmt\"\n\
             youngs_modulus = 3e9\npoisson_ratio = 0\nhamaker = 6e-20\n\
             intermolecular_distance = 0.2e-9\n"
        );
    }
    SampleMap::parse(&text, "map").unwrap()
}

#[test]
fn a_change_of_material_at_every_pixel_costs_one_tap_and_holds_the_setpoint() {
    let img = |threads| {
        peakforce_image(
            &probe(),
            &stripes(),
            &request(8, 2),
            Some(threads),
            &Progress::new(),
        )
        .unwrap()
    };
    let one = img(1);
    assert_eq!(one, img(2), "bit for bit on 1 and 2 threads");
    let biased = |w: &String| w.contains(": modulus_dmt reads "); // as above
    assert!(one.warnings.iter().all(biased), "{:?}", one.warnings);
    for j in 0..2 {
        for i in 0..8 {
            let m = one.material[j][i];
            assert_eq!(m != 0, i % 2 == 1, "the stripes: ({j}, {i})");
            let t = one.tap(j, i).unwrap();
            assert!(
                (t.peak_force - SETPOINT).abs() <= SETPOINT_TOL * SETPOINT,
                "pixel ({j}, {i}): peak force {}",
                t.peak_force
            );
            // the secant starts from the material's engaged z_c and orbit: one tap, at the
            // engaged operating point
            let p = &one.pixels[j][i];
            assert_eq!(p.evaluations, usize::from(i > 0), "({j}, {i})");
            assert!(!p.reengaged);
            let e = one.materials[m].engaged.unwrap();
            assert!(close(t.z_c, e.z_c, 1e-9), "{} {}", t.z_c, e.z_c);
            assert!(close(t.modulus_dmt, e.modulus_dmt, 1e-6));
        }
    }
}

/// The standalone tap's σ of the peak force (N) and the deformation (m) at 295 K
/// ([`standalone`]).
fn standalone_noise(sample: Option<&toml::Table>) -> (f64, f64) {
    let doc = standalone(sample, Some(295.0));
    let sigma = |k: &str| doc["thermal"][k].as_f64().unwrap();
    (sigma("peak_force_noise"), sigma("deformation_noise"))
}

/// With a temperature every pixel carries its material's tap noise at the setpoint: the
/// standalone `peakforce --temperature` tap's σ (its own setpoint search and noise), where the
/// line engages on the material and where the feedback continues into it from another (the
/// stripes: a change at every pixel), in the maps `peak_force_noise` and `deformation_noise`
/// and a `thermal` block; without one the maps are not there.
#[test]
fn a_temperature_gives_every_pixel_its_materials_tap_noise() {
    let req = ImageRequest {
        temperature: Some(295.0),
        ..request(8, 1)
    };
    let img = peakforce_image(&probe(), &stripes(), &req, Some(2), &Progress::new()).unwrap();
    let stripe = stripes().domains[0].sample.clone();
    let expected = [standalone_noise(None), standalone_noise(stripe.as_ref())];
    assert!(expected[0].0 > 0.0 && expected[1].1 > 0.0, "{expected:?}");
    for i in 0..8 {
        let (m, t) = (img.material[0][i], img.tap(0, i).unwrap());
        let n = t.noise.unwrap();
        let (f, d) = expected[usize::from(m != 0)];
        assert!(
            close(n.peak_force, f, 1e-6),
            "pixel {i}: {} {f}",
            n.peak_force
        );
        assert!(
            close(n.deformation, d, 1e-6),
            "pixel {i}: {} {d}",
            n.deformation
        );
        assert_eq!(img.value("peak_force_noise", 0, i), n.peak_force);
        assert_eq!(img.value("deformation_noise", 0, i), n.deformation);
        // every stripe after the first pixel is continued into, not engaged
        assert_eq!(img.pixels[0][i].evaluations, usize::from(i > 0), "{i}");
    }
    let doc = img.document();
    assert_eq!(doc["thermal"]["temperature"], 295.0);
    assert_eq!(
        doc["image"]["peak_force_noise"][0]
            .as_array()
            .unwrap()
            .len(),
        8
    );
    let plain = image(2, 1, 1).document();
    assert!(plain.get("thermal").is_none() && plain["image"].get("peak_force_noise").is_none());
}
