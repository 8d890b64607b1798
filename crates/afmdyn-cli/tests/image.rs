//! `afmdyn image` end to end: the 2D blend example (`examples/sample-blend.toml` over
//! `examples/probe-point-mass-dmt.toml`) writes its document and maps, with the terrace 5 nm
//! up at its true height and the rubber domain at its own operating point; bad input exits 2
//! with one line naming the field; `--out` writes `image.nc`; `--feedback pi` writes the library's
//! scan document and its maps.

use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .expect("run afmdyn")
}

#[test]
fn the_blend_example_images_at_a_setpoint() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let out = afmdyn(&[
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        "examples/sample-blend.toml",
        "--setpoint",
        "0.7",
        "--pixels",
        "16",
        "--json",
        "--out",
        d,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // the document summarises the maps; the maps are image.nc's
    let path = dir.path().join("image.nc");
    summarises(&doc["image"], &path);
    assert_eq!(doc["image"]["pixels"], 16);
    assert_eq!(doc["image"]["lines"], 16);
    let mut nc = netcdf3::FileReader::open(&path).unwrap();
    let height = nc.read_var_f64("height").unwrap();
    let z_c = nc.read_var_f64("z_c").unwrap();
    let domain = words(&path, "domain");
    assert_eq!(height.len(), 16 * 16);
    let r = doc["reference_z_c"].as_f64().unwrap();
    for k in 0..16 * 16 {
        let h = height[k];
        match domain[k].as_str() {
            "terrace" => assert!((h - 5e-9).abs() < 1e-18, "{h}"),
            "background" => assert_eq!(h, 0.0),
            "rubber" => assert!((h - (z_c[k] - r)).abs() < 1e-18),
            other => panic!("{other}"),
        }
    }
    for f in [
        "image.json",
        "image.nc",
        "image-height.png",
        "image-phase.png",
        "image-dissipation.png",
        "image-profile.png",
    ] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
}

#[test]
fn bad_input_exits_2_naming_the_field() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().to_str().unwrap();
    let bad_map = dir.path().join("bad.toml");
    std::fs::write(
        &bad_map,
        "size = [1e-6, 0]\n[[domain]]\nname = \"d\"\nx = [5e-7, 1e-7]\n",
    )
    .unwrap();
    for (extra, want) in [
        (vec!["--setpoint", "1.5"], "setpoint"),
        (vec!["--setpoint", "0.7", "--feedback", "pid"], "feedback"),
        // the library's one check of the image's options (ImageOptions::check)
        (
            vec!["--setpoint", "0.7", "--scan-rate", "2"],
            "scan-rate = 2: only with feedback = pi",
        ),
        (
            vec![
                "--setpoint",
                "0.7",
                "--mode",
                "peakforce",
                "--feedback",
                "pi",
            ],
            "feedback = pi: not with mode = peakforce",
        ),
        (
            vec![
                "--setpoint",
                "0.7",
                "--feedback",
                "pi",
                "--setpoint-study",
                "0.3:0.9:3",
            ],
            "setpoint-study = 0.3:0.9:3: only with feedback = ideal",
        ),
        (
            vec!["--setpoint", "0.7", "--threads", "2"],
            "threads = 2: only with feedback = pi",
        ),
        (
            vec!["--setpoint", "0.7", "--temperature", "295"],
            "temperature = 295: only with feedback = pi",
        ),
        (
            vec![
                "--setpoint",
                "0.7",
                "--feedback",
                "pi",
                "--temperature",
                "0",
            ],
            "temperature = 0",
        ),
        (
            vec!["--setpoint", "0.7", "--feedback", "pi", "--gains", "-1,10"],
            "gains",
        ),
        (
            vec!["--setpoint", "0.7", "--feedback", "pi", "--gains", "1"],
            "--gains",
        ),
        (
            vec![
                "--setpoint",
                "0.7",
                "--feedback",
                "pi",
                "--scan-rate",
                "1e9",
            ],
            "scan",
        ),
        (vec!["--setpoint", "0.7", "--lines", "4"], "lines"),
        // the one executor's thread rule (issue 60 D: 0 and 1025 were accepted here)
        (
            vec!["--setpoint", "0.7", "--feedback", "pi", "--threads", "0"],
            "threads",
        ),
        (
            vec!["--setpoint", "0.7", "--feedback", "pi", "--threads", "1025"],
            "threads",
        ),
    ] {
        let mut args = vec![
            "image",
            "--probe",
            "examples/probe-point-mass-dmt.toml",
            "--sample",
            "examples/sample-stripe.toml",
            "--out",
            d,
        ];
        args.extend(extra);
        let out = afmdyn(&args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains(want) && err.trim().lines().count() == 1,
            "{err}"
        );
    }
    // an impact stripe: its impacts and sticking are the stochastic step's events; the run
    // warns that their number depends on the grid
    let impact = dir.path().join("impact.toml");
    std::fs::write(
        &impact,
        "size = [1e-6, 0]\n[[domain]]\nname = \"j\"\nx = [3e-7, 5e-7]\n[domain.sample]\n\
         law = \"impact\"\nrestitution = 0.5\n",
    )
    .unwrap();
    let out = afmdyn(&[
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        impact.to_str().unwrap(),
        "--setpoint",
        "0.7",
        "--feedback",
        "pi",
        "--temperature",
        "295",
        "--pixels",
        "4",
        "--out",
        dir.path().join("impact-out").to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("afmdyn: warning:") && err.contains("impact law's thermal run"),
        "{err}"
    );
    let out = afmdyn(&[
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        bad_map.to_str().unwrap(),
        "--setpoint",
        "0.7",
        "--out",
        d,
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("domain 'd' x"), "{err}");
    // issue 60 item 6: 2048 × 2048 pixels (4.2e6 at about 1 kB each) aborted on allocation;
    // the image's memory is checked against its budget before any work
    let out = afmdyn(&[
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        "examples/sample-blend.toml",
        "--setpoint",
        "0.7",
        "--pixels",
        "2048",
        "--out",
        d,
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("image") && err.contains("2048 × 2048 pixels") && err.contains("3.9 GiB"),
        "{err}"
    );
}

/// The words of the code map `name` of the dataset `path`: each pixel's code as its CF flag
/// meaning (the codes 0, 1, …).
fn words(path: &std::path::Path, name: &str) -> Vec<String> {
    let (ds, _) = netcdf3::FileReader::open(path).unwrap().close();
    let v = ds.get_var(name).unwrap();
    let meanings: Vec<String> = v
        .get_attr_as_string("flag_meanings")
        .unwrap()
        .split(' ')
        .map(str::to_string)
        .collect();
    let codes = v.get_attr_i32("flag_values").unwrap().to_vec();
    assert_eq!(codes, (0..codes.len() as i32).collect::<Vec<_>>(), "{name}");
    let mut nc = netcdf3::FileReader::open(path).unwrap();
    nc.read_var_i32(name)
        .unwrap()
        .iter()
        .map(|&c| meanings[c as usize].clone())
        .collect()
}

/// The document's `image` block summarises every map of the dataset `path` over (y, x): a
/// float map's units, min, max and mean over its finite values and their number, computed
/// here from the file; a code map's pixels per meaning; the first and last x and y.
fn summarises(img: &serde_json::Value, path: &std::path::Path) {
    let (ds, _) = netcdf3::FileReader::open(path).unwrap().close();
    let mut nc = netcdf3::FileReader::open(path).unwrap();
    let maps = img["maps"].as_object().unwrap();
    let mut seen = 0;
    for var in ds.get_vars() {
        if var.dim_names() != vec!["y", "x"] {
            continue;
        }
        let name = var.name();
        let m = &maps[name];
        seen += 1;
        if var.get_attr("flag_meanings").is_some() {
            let mut counts = std::collections::BTreeMap::<String, u64>::new();
            for w in words(path, name) {
                *counts.entry(w).or_default() += 1;
            }
            let got: std::collections::BTreeMap<String, u64> =
                serde_json::from_value(m["counts"].clone()).unwrap();
            assert_eq!(got, counts, "{name}");
            continue;
        }
        if let Ok(flags) = nc.read_var_i8(name) {
            let set = flags.iter().filter(|&&b| b != 0).count();
            assert_eq!(m["counts"]["true"], set, "{name}");
            assert_eq!(m["counts"]["false"], flags.len() - set, "{name}");
            continue;
        }
        let values: Vec<f64> = nc
            .read_var_f64(name)
            .unwrap()
            .into_iter()
            .filter(|v| v.is_finite())
            .collect();
        assert_eq!(
            m["units"].as_str(),
            var.get_attr_as_string("units").as_deref(),
            "{name}"
        );
        assert_eq!(m["finite"], values.len(), "{name}");
        if values.is_empty() {
            assert!(m["min"].is_null() && m["max"].is_null() && m["mean"].is_null());
            continue;
        }
        let min = values.iter().copied().fold(f64::INFINITY, f64::min);
        let max = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        assert_eq!(m["min"].as_f64(), Some(min), "{name}");
        assert_eq!(m["max"].as_f64(), Some(max), "{name}");
        let got = m["mean"].as_f64().unwrap();
        assert!(
            (got - mean).abs() <= 1e-12 * mean.abs().max(1e-300),
            "{name}: {got} {mean}"
        );
    }
    assert_eq!(seen, maps.len(), "a summary for every map and no other");
    let x = nc.read_var_f64("x").unwrap();
    let y = nc.read_var_f64("y").unwrap();
    assert_eq!(img["x"], serde_json::json!([x[0], x[x.len() - 1]]));
    assert_eq!(img["y"], serde_json::json!([y[0], y[y.len() - 1]]));
    assert_eq!(img["pixels"], x.len());
    assert_eq!(img["lines"], y.len());
}

/// `image.nc` holds the maps (every numeric one over (y, x) with its units; the regime,
/// material and domain as codes with CF flag meanings) and `image.json` their summary, not
/// every pixel.
#[test]
fn image_json_summarises_the_maps_of_image_nc() {
    let dir = tempfile::tempdir().unwrap();
    let out = afmdyn(&[
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        "examples/sample-blend.toml",
        "--setpoint",
        "0.7",
        "--pixels",
        "12",
        "--lines",
        "9",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("image.json")).unwrap()).unwrap();
    let img = &doc["image"];
    let path = dir.path().join("image.nc");
    let (ds, _) = netcdf3::FileReader::open(&path).unwrap().close();
    let mut nc = netcdf3::FileReader::open(&path).unwrap();
    assert_eq!(ds.dim_size("y"), Some(9));
    assert_eq!(ds.dim_size("x"), Some(12));
    for (name, units) in [
        ("height", "m"),
        ("true_height", "m"),
        ("z_c", "m"),
        ("amplitude", "m"),
        ("phase_deg", "degree"),
        ("energy_dissipated", "J"),
        ("virial", "J"),
        ("peak_force", "N"),
        ("indentation", "m"),
    ] {
        let var = ds.get_var(name).unwrap();
        assert_eq!(var.dim_names(), vec!["y", "x"], "{name}");
        assert_eq!(var.get_attr_as_string("units").as_deref(), Some(units));
        // no pixel grids in the document
        assert!(
            img["maps"][name]["min"].is_number() && img[name].is_null(),
            "{name}"
        );
    }
    summarises(img, &path);
    // the apparent height: 0 on the background, the terrace's 5 nm, the rubber's z_c shift
    let height = nc.read_var_f64("height").unwrap();
    assert!(height.contains(&0.0) && height.iter().any(|h| (h - 5e-9).abs() < 1e-18));
    let top = img["maps"]["height"]["max"].as_f64().unwrap();
    assert!((top - 5e-9).abs() < 1e-18, "{top}");
    let domains = words(&path, "domain");
    assert!(domains.iter().any(|w| w == "rubber") && domains.iter().any(|w| w == "terrace"));
    assert_eq!(
        words(&path, "material")
            .iter()
            .filter(|w| *w == "rubber")
            .count(),
        domains.iter().filter(|w| *w == "rubber").count()
    );
    assert_eq!(nc.read_var_f64("setpoint").unwrap(), vec![0.7]);
    assert_eq!(
        nc.read_var_f64("reference_z_c").unwrap(),
        vec![doc["reference_z_c"].as_f64().unwrap()]
    );
    // the document's size stays small: a summary, not 108 pixels of 13 maps
    assert!(
        std::fs::metadata(dir.path().join("image.json"))
            .unwrap()
            .len()
            < 20_000
    );
}

/// A sample map's `height_map = "h.csv"` is read from the sample file's directory (the command
/// runs elsewhere); over one material the image records it exactly: with two columns the true
/// height is the straight line between them, h(x) = h₀ + (h₁ − h₀) x / Lx, on every line.
#[test]
fn a_height_map_csv_beside_the_sample_file_is_imaged() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("h.csv"), "0, 4e-9\n0, 4e-9\n").unwrap();
    let sample = dir.path().join("s.toml");
    std::fs::write(&sample, "size = [1e-6, 1e-6]\nheight_map = \"h.csv\"\n").unwrap();
    let out_dir = dir.path().join("out");
    let out = afmdyn(&[
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        sample.to_str().unwrap(),
        "--setpoint",
        "0.7",
        "--pixels",
        "8",
        "--lines",
        "2",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut nc = netcdf3::FileReader::open(out_dir.join("image.nc")).unwrap();
    let x = nc.read_var_f64("x").unwrap();
    let truth = nc.read_var_f64("true_height").unwrap();
    let height = nc.read_var_f64("height").unwrap();
    for (k, (&t, &h)) in truth.iter().zip(&height).enumerate() {
        let want = 4e-9 * x[k % 8] / 1e-6;
        assert!((t - want).abs() < 1e-20, "pixel {k}: {t} against {want}");
        assert!((h - t).abs() < 1e-20, "pixel {k}: apparent {h}, true {t}");
    }
    // a missing file is refused naming height_map and the file, exit 2
    std::fs::write(&sample, "size = [1e-6, 1e-6]\nheight_map = \"gone.npy\"\n").unwrap();
    let out = afmdyn(&[
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        sample.to_str().unwrap(),
        "--setpoint",
        "0.7",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("height_map = \"gone.npy\"") && err.contains("gone.npy)"),
        "{err}"
    );
}

/// `examples/probe-point-mass-dmt.toml` with Q = 100 (a short loop time: a quick scan),
/// written into `dir`: its path and text.
fn q100_probe(dir: &std::path::Path) -> (std::path::PathBuf, String) {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../");
    let text = std::fs::read_to_string(format!("{root}examples/probe-point-mass-dmt.toml"))
        .unwrap()
        .replace("quality_factor = 400", "quality_factor = 100");
    assert!(
        text.contains("quality_factor = 100"),
        "the example's Q changed"
    );
    let probe = dir.join("probe.toml");
    std::fs::write(&probe, &text).unwrap();
    (probe, text)
}

/// `--feedback pi --json` prints the library's document of the same scan (lines on 2 threads
/// here, 1 in the library) and writes the maps of the recorded height, the error image, the
/// phase and E_dis, and the profile.
#[test]
fn the_pi_scan_writes_the_libraries_document_and_maps() {
    use afmdyn::analysis::progress::Progress;
    use afmdyn::request::image::{ImageRequest, SampleMap};
    use afmdyn::request::image_scan::PiScan;
    use afmdyn::study::scan::pi_image;
    let dir = tempfile::tempdir().unwrap();
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../");
    let (probe, text) = q100_probe(dir.path());
    let out = afmdyn(&[
        "image",
        "--probe",
        probe.to_str().unwrap(),
        "--sample",
        "examples/sample-stripe.toml",
        "--setpoint",
        "0.5",
        "--feedback",
        "pi",
        "--pixels",
        "8",
        "--scan-rate",
        "40",
        "--gains",
        "0.1,2000",
        "--time-constant",
        "20e-6",
        "--threads",
        "2",
        "--json",
        "--out",
        dir.path().join("out").to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // the door's convergence state: every pixel of the reference image has its point
    let converged = doc.as_object_mut().unwrap().remove("converged").unwrap();
    assert_eq!(converged["all"], true, "{converged}");
    assert_eq!(converged["of"], 8, "{converged}"); // a line map of 8 pixels
    let table: toml::Table = text.parse().unwrap();
    let map = SampleMap::load(std::path::Path::new(&format!(
        "{root}examples/sample-stripe.toml"
    )))
    .unwrap();
    let req = ImageRequest {
        pixels: 8,
        ..ImageRequest::at(0.5)
    };
    let scan = PiScan {
        scan_rate: Some(40.0),
        gains: Some((0.1, 2000.0)),
        time_constant: Some(20e-6),
        ..PiScan::default()
    };
    let lib = pi_image(&table, &map, &req, &scan, Some(1), &Progress::new()).unwrap();
    let lib = afmdyn::report::present::image::pi_summary(&lib, 0.5);
    assert_eq!(doc, lib);
    summarises(&doc["image"], &dir.path().join("out").join("image.nc"));
    assert_eq!(doc["feedback"], "pi");
    assert_eq!(doc["scan"]["proportional_gain"], 0.1);
    for f in [
        "image.json",
        "image.nc",
        "image-height.png",
        "image-error.png",
        "image-phase.png",
        "image-dissipation.png",
        "image-profile.png",
    ] {
        assert!(dir.path().join("out").join(f).exists(), "{f}");
    }
}

/// `afmdyn image --feedback pi` of a 2-line map under the Q = 100 point mass, in `dir`.
fn two_line_scan(dir: &std::path::Path, extra: &[&str]) -> Output {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../");
    let (probe, _) = q100_probe(dir);
    let map = std::fs::read_to_string(format!("{root}examples/sample-stripe.toml"))
        .unwrap()
        .replace("size = [1.0e-6, 0.0]", "size = [1.0e-6, 0.2e-6]");
    let sample = dir.join("sample.toml");
    std::fs::write(&sample, map).unwrap();
    let out = dir.join("out");
    let mut args = vec![
        "image",
        "--probe",
        probe.to_str().unwrap(),
        "--sample",
        sample.to_str().unwrap(),
        "--setpoint",
        "0.5",
        "--feedback",
        "pi",
        "--pixels",
        "6",
        "--lines",
        "2",
        "--scan-rate",
        "50",
        "--threads",
        "1",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    afmdyn(&args)
}

/// A PI scan killed after its first line resumes to the uninterrupted run's files (the stored
/// line read back bit for bit); a finished store computes nothing on `--resume`; another
/// request is refused naming the first field that differs.
#[test]
fn a_killed_pi_scan_resumes_to_the_uninterrupted_files() {
    let full = tempfile::tempdir().unwrap();
    let cut = tempfile::tempdir().unwrap();
    let ok = two_line_scan(full.path(), &[]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let killed = two_line_scan(cut.path(), &["--abort-after", "1"]);
    assert!(!killed.status.success(), "the run was killed");
    let lines = cut.path().join("out/.image.lines.jsonl");
    assert_eq!(std::fs::read_to_string(&lines).unwrap().lines().count(), 1);
    let resumed = two_line_scan(cut.path(), &["--resume"]);
    assert!(
        resumed.status.success(),
        "{}",
        String::from_utf8_lossy(&resumed.stderr)
    );
    for f in ["image.json", "image.nc"] {
        assert_eq!(
            std::fs::read(full.path().join("out").join(f)).unwrap(),
            std::fs::read(cut.path().join("out").join(f)).unwrap(),
            "{f}"
        );
    }
    let stored = std::fs::read_to_string(&lines).unwrap();
    assert_eq!(stored.lines().count(), 2);
    assert!(two_line_scan(cut.path(), &["--resume"]).status.success());
    assert_eq!(std::fs::read_to_string(&lines).unwrap(), stored);
    let other = two_line_scan(cut.path(), &["--resume", "--gains", "0,3000"]);
    assert_eq!(other.status.code(), Some(2));
    let err = String::from_utf8_lossy(&other.stderr);
    assert!(err.contains("gains") && err.contains("3000"), "{err}");
}

/// The refusal of `args`: exit 2, one line on stderr, nothing written to `dir`.
fn refused(args: &[&str], dir: &std::path::Path) -> String {
    let out = afmdyn(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(!dir.exists(), "{err}: {} was created", dir.display());
    err
}

/// Issue 60: `image` goes through the door — held to the budgets before its directory is
/// made (2048 × 2048 pixels refused naming the image's budget), its threads refused as
/// every command's (0, 1025), a default scan rate's K_I blamed as gains.
#[test]
fn image_is_refused_before_its_directory() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let base = [
        "image",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--sample",
        "examples/sample-blend.toml",
        "--setpoint",
        "0.7",
        "--out",
        o,
    ];
    let with = |extra: &[&str]| -> Vec<String> {
        base.iter().chain(extra).map(|s| s.to_string()).collect()
    };
    let run = |extra: &[&str]| {
        let args = with(extra);
        refused(&args.iter().map(String::as_str).collect::<Vec<_>>(), &out)
    };
    let err = run(&["--pixels", "2048"]);
    assert!(
        err.contains("image: 2048 × 2048 pixels") && err.contains("exceeds the budget"),
        "{err}"
    );
    for t in ["0", "1025"] {
        let err = run(&["--feedback", "pi", "--threads", t]);
        assert!(
            err.contains(&format!("threads = {t}: must be in 1..=1024")),
            "{err}"
        );
    }
    let err = run(&["--feedback", "pi", "--gains", "0,1e12"]);
    assert!(
        err.contains("gains = K_I = 1e12") && !err.contains("scan_rate ="),
        "{err}"
    );
    // a multifrequency probe (one further component, examples/probe-bimodal.toml): an image is
    // recorded with one drive frequency
    let mut args = with(&["--feedback", "pi"]);
    args[2] = "examples/probe-bimodal.toml".into();
    let err = refused(&args.iter().map(String::as_str).collect::<Vec<_>>(), &out);
    assert!(
        err.contains("probe = a multifrequency drive") && err.contains("one drive frequency"),
        "{err}"
    );
}

/// `image --files`: `data` writes the document and the dataset without figures, `none`
/// writes nothing (no directory) and prints the summary; `--resume` needs a store.
#[test]
fn image_takes_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let args = |files: &'static str| {
        vec![
            "image".to_string(),
            "--probe".into(),
            "examples/probe-point-mass-dmt.toml".into(),
            "--sample".into(),
            "examples/sample-stripe.toml".into(),
            "--setpoint".into(),
            "0.8".into(),
            "--pixels".into(),
            "6".into(),
            "--curve-points".into(),
            "20".into(),
            "--files".into(),
            files.into(),
            "--out".into(),
            out.to_str().unwrap().into(),
        ]
    };
    let run = |a: Vec<String>| afmdyn(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let o = run(args("none"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.exists());
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.starts_with("ideal-feedback image, 6 × 1 pixels"),
        "{text}"
    );
    assert!(!text.contains("outputs in"), "{text}");
    let o = run(args("data"));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mut names: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| !n.starts_with('.'))
        .collect();
    names.sort();
    assert_eq!(names, ["image.json", "image.nc"]);
    let mut a = args("none");
    a.extend(["--feedback".into(), "pi".into(), "--resume".into()]);
    let o = run(a);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("--resume: --files none keeps no store"),
        "{err}"
    );
}

/// `--feedback pi --temperature 295 --seed 3` over a linear sample (the water beam): the scan
/// runs, its document records the temperature and the seed, and the same seed repeats the
/// scan's height errors bit for bit while another seed gives others.
#[test]
fn a_pi_scan_with_a_temperature_is_its_seeds() {
    let dir = tempfile::tempdir().unwrap();
    let water = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/probe-water-beam.toml"
    ))
    .unwrap();
    let (head, rest) = water.split_at(water.find("[sample]").unwrap());
    let tail = &rest[rest.find("[drive]").unwrap()..];
    let probe = dir.path().join("water-linear.toml");
    std::fs::write(
        &probe,
        format!("{head}[sample]\nlaw = \"linear\"\nstiffness = 1.0\n{tail}"),
    )
    .unwrap();
    let map = dir.path().join("flat.toml");
    std::fs::write(&map, "size = [1e-6, 0]\n").unwrap();
    let run = |seed: &str| {
        let out = afmdyn(&[
            "image",
            "--probe",
            probe.to_str().unwrap(),
            "--sample",
            map.to_str().unwrap(),
            "--setpoint",
            "0.7",
            "--pixels",
            "6",
            "--feedback",
            "pi",
            "--temperature",
            "295",
            "--seed",
            seed,
            "--files",
            "none",
            "--json",
            "--out",
            dir.path().join(format!("out-{seed}")).to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let doc = run("3");
    assert_eq!(doc["scan"]["temperature"], 295.0);
    assert_eq!(doc["scan"]["seed"], 3);
    assert_eq!(doc["artefacts"], run("3")["artefacts"]);
    assert_ne!(doc["artefacts"], run("4")["artefacts"]);
}
