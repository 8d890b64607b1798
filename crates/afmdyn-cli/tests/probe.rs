//! `--probe FILE` on the subcommands: the model comes from the SI probe, flags override single
//! parameters, JSON gains the "si" block, and a bad probe exits 2 with every problem on one line.

use std::path::Path;

use crate::common;
use common::{column, json, refused, repo, run};

/// The probe's parameters reach the model: `modes` reports the first free frequency f₀ of the
/// probe in Hz (the calibration it was built from), and `orbit` the probe's α's.
#[test]
fn probe_sets_the_model_and_si_block() {
    let probe = "examples/probe-beam-dmt.toml";
    let modes = json(&["modes", "--probe", probe, "--json"]);
    let f1 = modes["si"]["free_frequencies_hz"][0].as_f64().unwrap();
    assert!((f1 - 300e3).abs() < 1e-6 * 300e3, "f1 = {f1}");
    assert_eq!(modes["params"]["structure"], "beam");
    assert_eq!(modes["params"]["contact_law"]["law"], "dmt");
    let resolved = afmdyn::probe::Probe::load(&repo().join(probe)).unwrap();
    // (serde_json's default float parsing is within 1 ulp)
    let a2 = modes["params"]["alpha2"].as_f64().unwrap();
    assert!((a2 - resolved.params.alpha2).abs() < 1e-15 * a2);
    assert_eq!(modes["si"]["scales"]["length_m"].as_f64().unwrap(), 10e-9);
    // a flag overrides one parameter of the probe
    let m2 = json(&["modes", "--probe", probe, "--modes", "2", "--json"]);
    assert_eq!(m2["params"]["modes"], 2);
    assert_eq!(m2["params"]["alpha3"], modes["params"]["alpha3"]);
}

/// The point-mass probe: the orbit's JSON carries the SI block with z_c and the drive in Hz.
#[test]
fn point_mass_orbit_reports_si() {
    let doc = json(&[
        "orbit",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--json",
    ]);
    assert_eq!(doc["params"]["structure"], "point-mass");
    let si = &doc["si"];
    assert!((si["z_c_m"].as_f64().unwrap() - 8e-9).abs() < 1e-20);
    assert!((si["drive_frequency_hz"].as_f64().unwrap() - 300e3).abs() < 1e-6);
    assert!(si["poincare_v_t_m"][0].as_f64().is_some());
}

/// Bad probes: exit 2, one line naming the file and every problem; --probe with --config is
/// refused.
#[test]
fn bad_probe_exits_2_with_all_problems() {
    let dir = std::env::temp_dir().join(format!("afmdyn-probe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        "model = \"beam\"\nextra = 1\n[sample]\nlaw = \"hertz\"\n",
    )
    .unwrap();
    let out = run(&[
        "simulate",
        "--probe",
        bad.to_str().unwrap(),
        "--files",
        "none",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    for needle in [
        "bad.toml",
        "unknown key extra",
        "missing key modes",
        "missing table [cantilever]",
        "missing table [drive]",
        "missing key [sample].youngs_modulus",
    ] {
        assert!(err.contains(needle), "'{needle}' not in {err}");
    }
    let both = run(&[
        "orbit",
        "--probe",
        "examples/probe-beam-dmt.toml",
        "--config",
        "examples/fig5.toml",
    ]);
    assert_eq!(both.status.code(), Some(2));
    let units = json(&[
        "units",
        "--probe",
        "examples/probe-geometry-hertz.toml",
        "--json",
    ]);
    assert!(
        units["si"]["calibration"]["static_spring_constant"]
            .as_f64()
            .unwrap()
            > 0.0
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// SI inputs with a probe: --z-c (m) sets α5 through the rest distance (DMT: z_c = (α5 + ã₀)A₀)
/// and --drive-frequency (Hz) sets Ω = f/f₀ for the point mass; without a probe they are refused.
#[test]
fn si_inputs_need_the_probe() {
    let doc = json(&[
        "orbit",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--z-c",
        "6e-9",
        "--drive-frequency",
        "299e3",
        "--json",
    ]);
    let a5 = doc["params"]["alpha5"].as_f64().unwrap();
    assert!((a5 - (0.6 - 0.0165)).abs() < 1e-12, "alpha5 = {a5}");
    let om = doc["params"]["omega"].as_f64().unwrap();
    assert!((om - 299.0 / 300.0).abs() < 1e-12, "omega = {om}");
    assert!((doc["si"]["z_c_m"].as_f64().unwrap() - 6e-9).abs() < 1e-21);
    let out = run(&["orbit", "--z-c", "6e-9"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--probe"));
}

/// The cantilever library: `afmdyn cantilevers --json` lists it with sources, and
/// `--cantilever NAME` with a file of [sample] and [drive] only gives the model of the probe
/// file written out with the library's values (k, f0, Q, tip radius, silicon tip); an unknown
/// name exits 2 naming the near ones.
#[test]
fn cantilever_library_composes_with_a_sample_file() {
    let lib = json(&["cantilevers", "--json"]);
    let all = lib["cantilevers"].as_array().unwrap();
    assert!(all.len() >= 12);
    let ac160 = all.iter().find(|c| c["name"] == "AC160TS-R3").unwrap();
    assert_eq!(ac160["spring_constant"], 26.0);
    assert!(ac160["source"].as_str().unwrap().starts_with("https://"));
    let dir = tempfile::tempdir().unwrap();
    let sample = "[sample]\nlaw = \"hertz\"\nyoungs_modulus = 1e9\npoisson_ratio = 0.3\n\
                  z_c = 12e-9\n[drive]\nfree_amplitude = 15e-9\n";
    let full = format!(
        "model = \"point-mass\"\n[cantilever]\nspring_constant = 26.0\n\
         resonance_frequency = 300e3\nquality_factor = 500\n[tip]\nradius = 7e-9\n\
         youngs_modulus = 130e9\npoisson_ratio = 0.27\n{sample}"
    );
    let (s, f) = (dir.path().join("sample.toml"), dir.path().join("full.toml"));
    std::fs::write(&s, sample).unwrap();
    std::fs::write(&f, full).unwrap();
    let (s, f) = (s.to_str().unwrap(), f.to_str().unwrap());
    let a = json(&[
        "units",
        "--probe",
        s,
        "--cantilever",
        "ac160ts_r3",
        "--json",
    ]);
    let b = json(&["units", "--probe", f, "--json"]);
    assert_eq!(a["params"], b["params"]);
    let a = json(&[
        "orbit",
        "--probe",
        s,
        "--cantilever",
        "AC160TS-R3",
        "--json",
    ]);
    let b = json(&["orbit", "--probe", f, "--json"]);
    assert_eq!(a["params"], b["params"]);
    assert_eq!(a["period"], b["period"]);
    let out = run(&["orbit", "--probe", s, "--cantilever", "ac160"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("not in the cantilever library") && err.contains("AC160TS-R3"),
        "{err}"
    );
    // without a cantilever the sample file says where k, f0 and Q may come from
    let out = run(&["orbit", "--probe", s]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("--cantilever NAME"));
}

/// Numbers as users write them: SI units on the SI flags with a probe (`--z-c 7nm`,
/// `--drive-frequency 299kHz`, `--from 12nm`, `--step 0.5nm`, resonance `--from 295kHz`) give
/// the same runs as the plain numbers; a unit of the other kind, a unit without a probe and a
/// length meant in nm but written in m are refused (exit 2) with a hint; a closed pipe ends a
/// run quietly.
#[test]
fn si_flags_take_units_and_hint_at_misplaced_scales() {
    let pm = "examples/probe-point-mass-dmt.toml";
    let a = json(&[
        "orbit",
        "--probe",
        pm,
        "--z-c",
        "7nm",
        "--drive-frequency",
        "299kHz",
        "--json",
    ]);
    let b = json(&[
        "orbit",
        "--probe",
        pm,
        "--z-c",
        "7e-9",
        "--drive-frequency",
        "299e3",
        "--json",
    ]);
    assert_eq!(a["params"], b["params"]);
    let a = json(&[
        "approach",
        "--probe",
        pm,
        "--from",
        "12nm",
        "--to",
        "5 nm",
        "--step",
        "0.5nm",
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    let b = json(&[
        "approach",
        "--probe",
        pm,
        "--from",
        "12e-9",
        "--to",
        "5e-9",
        "--step",
        "0.5e-9",
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    assert_eq!(a["approach"]["z_c"], b["approach"]["z_c"]);
    let a = json(&[
        "resonance",
        "--probe",
        pm,
        "--from",
        "295kHz",
        "--to",
        "0.305MHz",
        "--points",
        "3",
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    assert_eq!(a["up"]["frequency_hz"][0], 295e3);
    for (args, needle) in [
        (
            vec!["approach", "--from", "12nm"],
            "--from: a value with a unit needs --probe",
        ),
        (
            vec!["approach", "--probe", pm, "--from", "12kHz"],
            "takes a length (m)",
        ),
        (
            vec!["orbit", "--probe", pm, "--z-c", "8"],
            "z-c = 8 m: must lie within ±1e-4 m",
        ),
        (
            vec!["approach", "--probe", pm, "--from", "20", "--to", "2"],
            "from = 20 m",
        ),
        (
            vec!["orbit", "--probe", pm, "--drive-frequency", "300"],
            "300kHz",
        ),
        (
            vec!["orbit", "--probe", pm, "--z-c", "7xx"],
            "optionally with a unit",
        ),
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(needle) && err.lines().count() == 1,
            "{args:?}: {err}"
        );
    }
}

fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// Issue 28 item 1: `simulate --probe` wrote τ and g₀; its time series is now in SI (s, m,
/// m/s, N; units in the `.npy.json`) and equals the dimensionless run of the same parameters
/// (written out as a config file) times the probe's scales.
#[test]
fn simulate_with_a_probe_writes_si_time_series() {
    let dir = std::env::temp_dir().join(format!("afmdyn-sim-si-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let probe = "examples/probe-beam-dmt.toml";
    let units = json(&["units", "--probe", probe, "--json"]);
    let p = &units["params"];
    let law = &p["contact_law"];
    let config = format!(
        "modes = 3\nalpha1 = {:?}\nalpha2 = {:?}\nalpha3 = {:?}\n\
         alpha4 = {:?}\nalpha5 = {:?}\nalpha6 = {:?}\nomega = {:?}\ncontact_law = \"dmt\"\n\
         hamaker = {:?}\nintermolecular_distance = {:?}\n",
        p["alpha1"].as_f64().unwrap(),
        p["alpha2"].as_f64().unwrap(),
        p["alpha3"].as_f64().unwrap(),
        p["alpha4"].as_f64().unwrap(),
        p["alpha5"].as_f64().unwrap(),
        p["alpha6"].as_f64().unwrap(),
        p["omega"].as_f64().unwrap(),
        law["hamaker"].as_f64().unwrap(),
        law["intermolecular_distance"].as_f64().unwrap(),
    );
    let cfg = dir.join("params.toml");
    std::fs::write(&cfg, config).unwrap();
    let (si_dir, plain_dir) = (dir.join("si"), dir.join("plain"));
    let common = [
        "--periods",
        "500",
        "--samples-per-period",
        "20",
        "--csv",
        "--files",
        "data",
    ];
    let mut a = vec![
        "simulate",
        "--probe",
        probe,
        "--out",
        si_dir.to_str().unwrap(),
    ];
    a.extend(common);
    json(&[a.as_slice(), &["--json"]].concat());
    let mut b = vec!["simulate", "--config", cfg.to_str().unwrap(), "--out"];
    b.push(plain_dir.to_str().unwrap());
    b.extend(common);
    json(&[b.as_slice(), &["--json"]].concat());
    let (hs, si) = read_csv(&si_dir.join("timeseries.csv"));
    let (hp, plain) = read_csv(&plain_dir.join("timeseries.csv"));
    assert_eq!(
        &hs[..6],
        &[
            "t",
            "v_t",
            "w_tip",
            "w_tip_dot",
            "in_contact",
            "contact_force"
        ]
    );
    assert_eq!(hp[0], "tau");
    let s = &units["si"]["scales"];
    let (ts, xs, fs) = (
        s["time_s"].as_f64().unwrap(),
        s["length_m"].as_f64().unwrap(),
        s["force_n"].as_f64().unwrap(),
    );
    let v = xs / ts;
    let scale = [ts, xs, xs, v, 1.0, fs, xs, xs, xs, v, v, v];
    assert_eq!(si.len(), plain.len());
    let mut contact = 0;
    for (r, q) in si.iter().zip(&plain) {
        for (k, (a, b)) in r.iter().zip(q).enumerate() {
            let want = b * scale[k];
            assert!(
                (a - want).abs() <= 1e-14 * want.abs(),
                "{}: {a} vs {want}",
                hs[k]
            );
        }
        contact += usize::from(r[4] == 1.0);
    }
    assert!(contact > 0, "the run taps the sample");
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(si_dir.join("timeseries.npy.json")).unwrap())
            .unwrap();
    let units: Vec<&str> = meta["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["unit"].as_str().unwrap())
        .collect();
    assert_eq!(
        units,
        ["s", "m", "m", "m/s", "0/1", "N", "m", "m", "m", "m/s", "m/s", "m/s"]
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// The issue-42 lever: RTESPA-300 from the cantilever library (k 40 N/m, f0 300 kHz, Q 500)
/// over polystyrene (DMT, E 2.5 GPa, H 6.6e-20 J, η 10 Pa s), A0 = 15 nm.
const RTESPA_PS: &str = "[cantilever]\nname = \"RTESPA-300\"\nspring_constant = 40.0\n\
    resonance_frequency = 300e3\nquality_factor = 500\n[sample]\nlaw = \"dmt\"\n\
    youngs_modulus = 2.5e9\npoisson_ratio = 0.33\nhamaker = 6.6e-20\nviscosity = 10.0\n\
    [drive]\nfree_amplitude = 15e-9\n";

fn probe_file(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// A dimensionless model flag under a probe is refused naming the SI key or flag to use
/// (issue 42: `--hamaker 6.6e-20` ran as H̃ and moved the peak force from 7.27 to 5.76 nN;
/// `--drive-amplitude 20e-9` ran with no drive); the same flags run without a probe.
#[test]
fn dimensionless_flags_under_a_probe_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let ps = probe_file(dir.path(), "ps.toml", RTESPA_PS);
    let p = ps.as_str();
    refused(
        &[
            "approach",
            "--probe",
            p,
            "--hamaker",
            "6.6e-20",
            "--files",
            "none",
        ],
        &["hamaker = 6.6e-20", "[sample] hamaker (J)"],
    );
    refused(
        &[
            "approach",
            "--probe",
            p,
            "--drive-amplitude",
            "20e-9",
            "--files",
            "none",
        ],
        &["drive-amplitude = 2e-8", "[drive] free_amplitude (m)"],
    );
    refused(
        &["orbit", "--probe", p, "--gap", "1"],
        &["gap = 1", "--z-c"],
    );
    refused(
        &["orbit", "--probe", p, "--alpha5", "1"],
        &["gap = 1", "--z-c"],
    );
    refused(
        &["orbit", "--probe", p, "--omega", "1"],
        &["omega = 1", "--drive-frequency"],
    );
    refused(
        &["orbit", "--probe", p, "--beam-damping", "0.002"],
        &["beam-damping", "quality_factor"],
    );
    refused(
        &["orbit", "--probe", p, "--contact-law", "hertz"],
        &["contact-law = hertz", "[sample] law"],
    );
    // without a probe they are the paper's dimensionless values
    json(&[
        "orbit",
        "--drive-amplitude",
        "0.12",
        "--omega",
        "2.7",
        "--json",
    ]);
    // what a probe leaves open: N and the SI values
    json(&["orbit", "--probe", p, "--z-c", "14.3nm", "--json"]);
}

/// Negative SI values with units (`--z-c -5nm` was read as an unknown flag `-5`) and units on
/// a chart's SI axes (`--x z-c --x-from 5nm` was refused) read as the plain numbers do; a unit
/// on a dimensionless axis is refused.
#[test]
fn negative_values_and_chart_axes_take_units() {
    let pm = "examples/probe-point-mass-dmt.toml";
    let a = json(&["orbit", "--probe", pm, "--z-c", "-0.1nm", "--json"]);
    let b = json(&["orbit", "--probe", pm, "--z-c=-0.1e-9", "--json"]);
    assert_eq!(a["params"], b["params"]);
    assert!((a["si"]["z_c_m"].as_f64().unwrap() + 0.1e-9).abs() < 1e-22);
    let dir = tempfile::tempdir().unwrap();
    let chart = |x: [&str; 2], y: [&str; 2]| {
        json(&[
            "chart",
            "--probe",
            pm,
            "--x",
            "z-c",
            "--x-from",
            x[0],
            "--x-to",
            x[1],
            "--x-steps",
            "2",
            "--y",
            "drive-frequency",
            "--y-from",
            y[0],
            "--y-to",
            y[1],
            "--y-steps",
            "1",
            "--starts",
            "1",
            "--lyapunov-periods",
            "0",
            "--json",
            "--out",
            dir.path().to_str().unwrap(),
        ])
    };
    let a = chart(["5nm", "6nm"], ["299kHz", "300kHz"]);
    assert_eq!(a["x"]["values"], serde_json::json!([5e-9, 6e-9]));
    assert_eq!(a["y"]["values"], serde_json::json!([299e3]));
    let b = chart(["5e-9", "6e-9"], ["299e3", "300e3"]);
    assert_eq!(a["cells"], b["cells"]);
    refused(
        &[
            "chart",
            "--x",
            "omega",
            "--x-from",
            "2nm",
            "--out",
            dir.path().to_str().unwrap(),
        ],
        &["--x-from", "plain number"],
    );
    refused(
        &[
            "chart",
            "--probe",
            pm,
            "--x",
            "z-c",
            "--x-from",
            "5kHz",
            "--out",
            dir.path().to_str().unwrap(),
        ],
        &["--x-from", "takes a length (m)"],
    );
}

/// Messages in the user's units: a z_c beyond the model's reach on a 10 pm probe names z_c in
/// m and the range in m (was `alpha5 = 4.999983500000001e6`), a resonance end below the model's
/// Ω range names the frequency and the range in Hz (was Ω = 1.17e-5).
#[test]
fn out_of_range_si_values_are_named_in_si() {
    let dir = tempfile::tempdir().unwrap();
    let small = probe_file(
        dir.path(),
        "small.toml",
        &RTESPA_PS.replace("free_amplitude = 15e-9", "free_amplitude = 10e-12"),
    );
    refused(
        &["orbit", "--probe", &small, "--z-c", "50um"],
        &[
            "z-c = 5e-5 m (this probe allows [-9.99",
            "e-6, 1.00",
            "e-5] m",
        ],
    );
    let out = run(&["orbit", "--probe", &small, "--z-c", "50um"]);
    assert!(!String::from_utf8_lossy(&out.stderr).contains("alpha5"));
    let ps = probe_file(dir.path(), "ps.toml", RTESPA_PS);
    refused(
        &[
            "resonance",
            "--probe",
            &ps,
            "--from",
            "1Hz",
            "--files",
            "none",
        ],
        &["from = 1 Hz (this probe allows [", "] Hz)"],
    );
    let out = run(&[
        "resonance",
        "--probe",
        &ps,
        "--from",
        "1Hz",
        "--files",
        "none",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !err.contains("omega") && !err.starts_with("afmdyn: Ω"),
        "{err}"
    );
}

/// `resonance` under a probe is by default the free resonance — the tip 10 free amplitudes
/// away (the file's z_c, A0 by default, is in contact at resonance) — on a grid no coarser
/// than f0/(10 Q) = 60 Hz for the RTESPA-300 (was 100.8 Hz for a 600 Hz linewidth); its
/// amplitude peaks at the free amplitude A0 = 15 nm near f0. A user's step and z_c still win.
#[test]
fn resonance_under_a_probe_is_the_free_resonance_on_a_fine_grid() {
    let dir = tempfile::tempdir().unwrap();
    let ps = probe_file(dir.path(), "ps.toml", RTESPA_PS);
    let doc = json(&[
        "resonance",
        "--probe",
        &ps,
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    let f: Vec<f64> = doc["up"]["frequency_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let step = f[1] - f[0];
    assert!(
        step <= 300e3 / (10.0 * 500.0) * (1.0 + 1e-9),
        "step {step} Hz"
    );
    assert!(f[0] < 299.4e3 && *f.last().unwrap() > 300.6e3, "{f:?}");
    let z_c = doc["si"]["z_c_m"].as_f64().unwrap();
    assert!(z_c >= 10.0 * 15e-9 * 0.99, "z_c = {z_c} m");
    let amp: Vec<f64> = doc["up"]["amplitude"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let (i, peak) =
        amp.iter()
            .copied()
            .enumerate()
            .fold((0, 0.0), |m, (i, a)| if a > m.1 { (i, a) } else { m });
    // the driven harmonic oscillator's peak, A0 at f0 (the drive is at f0): the grid point
    // nearest f0 is at most step/2 away, where the response is A0/√(1 + (Q step/f0)²)
    // (Lorentzian); within 1e-3 of those bounds (van der Waals at 10 A0)
    let lo = 15e-9 / (1.0 + (500.0 * step / 300e3).powi(2)).sqrt();
    assert!(
        peak > lo * (1.0 - 1e-3) && peak < 15e-9 * (1.0 + 1e-3),
        "peak {peak} m"
    );
    assert!((f[i] - 300e3).abs() <= step, "peak at {} Hz", f[i]);
    assert!(doc["up"]["contact_fraction"]
        .as_array()
        .unwrap()
        .iter()
        .all(|c| c.as_f64() == Some(0.0)));
    // a user's step and rest distance win
    let user = json(&[
        "resonance",
        "--probe",
        &ps,
        "--step",
        "500Hz",
        "--z-c",
        "20nm",
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    let g = user["up"]["frequency_hz"].as_array().unwrap();
    assert!((g[1].as_f64().unwrap() - g[0].as_f64().unwrap() - 500.0).abs() < 1e-6);
    assert!((user["si"]["z_c_m"].as_f64().unwrap() - 20e-9).abs() < 1e-20);
    // a probe file's own [sample] z_c is a given rest distance too
    let file = json(&[
        "resonance",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--points",
        "3",
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    assert!((file["si"]["z_c_m"].as_f64().unwrap() - 8e-9).abs() < 1e-20);
}

/// A Q = 500 lever (`examples/probe-rtespa300-polystyrene.toml`) at z_c = 14.3 nm: at its
/// defaults `attractors` finds the two period-1 orbits (before the transient cap followed Q it
/// reported eight "nonperiodic" attractors and no warning, issue 42) with the cap in the
/// document; cut off at 300 periods, it warns on stderr and in the JSON.
#[test]
fn attractors_of_a_high_q_lever_settle_at_defaults_and_warn_when_cut_short() {
    let probe = "examples/probe-rtespa300-polystyrene.toml";
    let dir = std::env::temp_dir().join(format!("afmdyn-highq-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let doc = json(&[
        "attractors",
        "--probe",
        probe,
        "--z-c",
        "14.3nm",
        "--samples",
        "8",
        "--json",
        "--out",
        out,
    ]);
    let periods: Vec<_> = doc["attractors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["period"].as_u64())
        .collect();
    assert!(
        !periods.is_empty() && periods.iter().all(|p| *p == Some(1)),
        "{periods:?}"
    );
    assert!(doc["transient_cap"].as_u64().unwrap() > 17_000);
    assert_eq!(doc["warnings"], serde_json::json!([]));
    let cut = run(&[
        "attractors",
        "--probe",
        probe,
        "--z-c",
        "14.3nm",
        "--samples",
        "4",
        "--max-periods",
        "300",
        "--out",
        out,
    ]);
    assert!(cut.status.success());
    let err = String::from_utf8_lossy(&cut.stderr);
    assert!(
        err.contains("afmdyn: warning:") && err.contains("300 drive periods"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 42 §4: `contact_force` was documented as negative when pushing the tip away and 0 in
/// free flight, while the data are positive at the deepest indentation and negative (van der
/// Waals) in DMT's free flight. The data follow F_c > 0 repulsive: the `.npy.json`, the
/// approach's columns and docs/outputs.md now say so, and the data are checked against it.
#[test]
fn contact_force_sign_in_data_matches_its_documentation() {
    let dir = std::env::temp_dir().join(format!("afmdyn-force-sign-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = dir.to_str().unwrap();
    json(&[
        "simulate",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--periods",
        "20",
        "--transient",
        "300",
        "--csv",
        "--files",
        "data",
        "--out",
        out,
        "--json",
    ]);
    let (h, rows) = read_csv(&dir.join("timeseries.csv"));
    assert_eq!(
        (h[1].as_str(), h[4].as_str(), h[5].as_str()),
        ("v_t", "in_contact", "contact_force")
    );
    let deepest = rows.iter().min_by(|a, b| a[1].total_cmp(&b[1])).unwrap();
    assert!(
        deepest[1] < 0.0 && deepest[4] == 1.0,
        "the run indents the sample"
    );
    assert!(
        deepest[5] > 0.0,
        "F_c at the deepest indentation: {}",
        deepest[5]
    );
    let free: Vec<f64> = rows.iter().filter(|r| r[4] == 0.0).map(|r| r[5]).collect();
    assert!(
        !free.is_empty() && free.iter().all(|&f| f < 0.0),
        "DMT attracts in free flight"
    );

    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("timeseries.npy.json")).unwrap())
            .unwrap();
    let meaning = meta["columns"][5]["meaning"].as_str().unwrap();
    assert!(meaning.contains(afmdyn::contact::FORCE_SIGN), "{meaning}");
    assert!(afmdyn::contact::FORCE_SIGN.starts_with("positive when the sample pushes the tip away"));
    // the outputs page states the sign; the CSV page's row is the layout's meaning
    let doc = include_str!("../../../docs/outputs.md").replace('\n', " ");
    assert!(doc.contains("F_c > 0 pushes the tip away"));
    assert!(!doc.contains("F_c < 0 pushes"));
    let csv = include_str!("../../../docs/reference/csv-files/dynamics.md");
    let row = (csv.lines())
        .find(|l| l.starts_with("| `contact_force` |"))
        .unwrap();
    assert!(row.contains(afmdyn::contact::FORCE_SIGN), "{row}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every example probe file (`examples/probe-*.toml`) loads, and the adhesive-hysteresis examples run an approach curve
/// from the file as they stand: the JKR polymer and the capillary meniscus lose energy on the
/// taps (E_dis > 0 somewhere) and pull with their closed-form forces (the JKR pull-off
/// (3/2)πWR = 2.36 nN, the meniscus's 4πRγcosθ = 8.50 nN as the most attractive force), and
/// `si.contact_hysteresis` reports their cycles as the closed forms give them.
#[test]
fn every_example_probe_loads_and_the_hysteretic_ones_approach() {
    let mut n = 0;
    for entry in std::fs::read_dir(repo().join("examples")).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        // (examples/probe.toml is the `units --config` format, not a probe file)
        if name.starts_with("probe-") && name.ends_with(".toml") {
            afmdyn::probe::Probe::load(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
            n += 1;
        }
    }
    assert!(n >= 9, "{n} probe files");
    let pi = std::f64::consts::PI;
    for (file, law, pull) in [
        (
            "examples/probe-jkr-polymer.toml",
            "jkr",
            1.5 * pi * 0.05 * 10e-9,
        ),
        (
            "examples/probe-capillary-humid.toml",
            "capillary",
            4.0 * pi * 10e-9 * 0.072 * 20f64.to_radians().cos(),
        ),
    ] {
        let doc = json(&[
            "approach",
            "--probe",
            file,
            "--points",
            "16",
            "--no-branches",
            "--files",
            "none",
            "--json",
        ]);
        assert_eq!(doc["params"]["contact_law"]["law"], law);
        let col = |k: &str| column(&doc, "approach", k);
        assert!(
            col("energy_dissipated").iter().any(|&e| e > 1e-19),
            "{file}"
        );
        let most = col("min_force").into_iter().fold(0.0f64, f64::min);
        assert!(
            (most / -pull - 1.0).abs() < 1e-3,
            "{file}: {most} vs {}",
            -pull
        );
        let h = &doc["si"]["contact_hysteresis"];
        let got = h["pull_off_force_n"].as_f64().unwrap();
        assert!((got / pull - 1.0).abs() < 1e-12, "{file}: {got} vs {pull}");
    }
    // the cycles in SI against the closed forms: JKR (Johnson 1985 §5.5) δ_f =
    // (3/4)(π²W²R/E*²)^{1/3}, E_hys ≈ 7.09 (W⁵R⁴/E*²)^{1/3} (the branch cut 1e-3 short of its
    // end: 2e-6 less); the meniscus D_r = (1 + θ/2)V^{1/3}, E_cap = F(D_r + h − √(D_r² + h²))
    let (w, r) = (0.05, 10e-9);
    let e_star = 1.0 / ((1.0 - 0.27f64.powi(2)) / 130e9 + (1.0 - 0.4f64.powi(2)) / 50e6);
    let jkr = &json(&[
        "units",
        "--probe",
        "examples/probe-jkr-polymer.toml",
        "--json",
    ])["si"]["contact_hysteresis"];
    let rel = |v: &serde_json::Value, want: f64| (v.as_f64().unwrap() / want - 1.0).abs();
    let release = 0.75 * (pi * pi * w * w * r / (e_star * e_star)).cbrt();
    assert!(rel(&jkr["release_distance_m"], release) < 3e-6, "{jkr}");
    let coeff = (0.6 + 0.1 / 4f64.cbrt()) * 2f64.powf(2.0 / 3.0) * pi.powf(5.0 / 3.0);
    let e_hys = coeff * (w.powi(5) * r.powi(4) / (e_star * e_star)).cbrt();
    assert!(rel(&jkr["energy_per_tap_j"], e_hys) < 3e-6, "{jkr}");
    let cap = &json(&[
        "units",
        "--probe",
        "examples/probe-capillary-humid.toml",
        "--json",
    ])["si"]["contact_hysteresis"];
    let (v, theta) = (1e-25f64, 20f64.to_radians());
    let d_r = (1.0 + 0.5 * theta) * v.cbrt();
    assert!(rel(&cap["release_distance_m"], d_r) < 1e-12, "{cap}");
    let h = (v / (pi * r)).sqrt();
    let f = 4.0 * pi * r * 0.072 * theta.cos();
    let e_cap = f * (d_r + h - d_r.hypot(h));
    assert!(rel(&cap["energy_per_tap_j"], e_cap) < 1e-12, "{cap}");
}

/// The standard linear solid in water (`examples/probe-water-sls.toml`, a beam of three modes
/// at Q₁ ≈ 2.4) runs an approach curve from the file as it stands: the taps dissipate energy in
/// the sample's dashpot, the sample never pulls the tip (its force vanishes where the tip leaves;
/// round-off allowed), and the higher modes' share of the motion grows from its free value as
/// the tip taps harder (Basak & Raman, APL 91 (2007) 064107: the higher modes are excited at
/// every tap in liquid).
#[test]
fn a_viscoelastic_sample_in_water_approaches_from_its_probe_file() {
    let doc = json(&[
        "approach",
        "--probe",
        "examples/probe-water-sls.toml",
        "--points",
        "24",
        "--no-branches",
        "--files",
        "none",
        "--json",
    ]);
    assert_eq!(doc["params"]["contact_law"]["law"], "sls");
    let col = |k: &str| column(&doc, "approach", k);
    let (e, fmin, fmax, share) = (
        col("energy_dissipated"),
        col("min_force"),
        col("peak_force"),
        col("higher_mode_fraction"),
    );
    assert!(e.iter().any(|&x| x > 1e-19), "{e:?}");
    let peak = fmax.iter().copied().fold(0.0, f64::max);
    assert!(peak > 1e-10, "{peak}");
    assert!(fmin.iter().all(|&f| f > -1e-8 * peak), "{fmin:?}");
    let (free, tapping) = (share[0], share.iter().copied().fold(0.0, f64::max));
    assert!(tapping > 3.0 * free, "{free} → {tapping}");
}

/// The soft lever of `examples/probe-water-beam.toml` (k ≈ 0.19 N/m, N = 3) over a stiff
/// sample (E = 60 GPa, mica-like): in water it taps two, three, four times per drive period as
/// z_c falls — the "drum roll" of soft levers in liquid that Melcher, Xu & Raman reported
/// (Appl. Phys. Lett. 93 (2008) 091903: sequential transitions between single, double and
/// triple impacts, traced to the momentary excitation of the second mode at each tap; Xu,
/// Melcher, Basak & Raman, Phys. Rev. Lett. 102 (2009) 060801) — while in air (`--medium air`,
/// Q ≈ 40) the same lever taps once per period at every z_c.
#[test]
fn a_soft_lever_in_water_drum_rolls_on_a_stiff_sample() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(repo().join("examples/probe-water-beam.toml")).unwrap();
    let stiff = text.replace("youngs_modulus = 50e6 ", "youngs_modulus = 60e9 ");
    assert_ne!(stiff, text);
    let probe = dir.path().join("stiff.toml");
    std::fs::write(&probe, stiff).unwrap();
    let probe = probe.to_str().unwrap();
    let taps = |z: &str, medium: &[&str]| {
        let mut args = vec!["orbit", "--probe", probe, "--z-c", z, "--json"];
        args.extend(medium);
        let doc = json(&args);
        doc["switchings"].as_u64().unwrap() / 2
    };
    let water: Vec<u64> = ["9e-9", "7e-9", "5e-9"]
        .iter()
        .map(|z| taps(z, &[]))
        .collect();
    assert!(water[0] >= 2, "{water:?}");
    assert!(
        water.windows(2).all(|w| w[1] >= w[0]) && water[2] > water[0],
        "{water:?}"
    );
    for z in ["9e-9", "7e-9", "5e-9"] {
        assert_eq!(taps(z, &["--medium", "air"]), 1, "air at z_c = {z}");
    }
}
