//! Issue 60, part D: a refusal names what the user gave and can change, and a damaged store is
//! recovered, not reported as a cancellation.

use crate::common;
use common::{json, refused, run};

/// `image --feedback pi --gains 0,1e12` without `--scan-rate` blamed "scan-rate = 1.25e10",
/// a flag never given: the default scan rate follows K_I (a pixel lasts 5/K_I), so K_I is what
/// to change, and its largest value here is named: the fastest scan, 300 kHz over 2 × 8
/// pixels, times 2 × 8 pixels × 5 loop times, 1.5e6 1/s.
#[test]
fn a_pi_gain_that_sets_too_fast_a_scan_blames_the_gain() {
    refused(
        &[
            "image",
            "--probe",
            "examples/probe-point-mass-dmt.toml",
            "--sample",
            "examples/sample-stripe.toml",
            "--feedback",
            "pi",
            "--gains",
            "0,1e12",
            "--pixels",
            "8",
            "--lines",
            "1",
            "--setpoint",
            "0.8",
            "--out",
            temp_dir("pi-gain").join("out").to_str().unwrap(),
        ],
        &["gains", "K_I = 1e12", "at most 1.500000e6", "scan"],
    );
}

/// A fresh temporary directory for one test.
fn temp_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("afmdyn-messages-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A probe with only its sample and drive: the lever comes from `--cantilever`.
const SAMPLE_ONLY: &str = r#"
model = "point-mass"
[sample]
law = "dmt"
youngs_modulus = 4e9
poisson_ratio = 0.33
hamaker = 6.6e-20
intermolecular_distance = 0.165e-9
z_c = 8e-9
[drive]
free_amplitude = 10e-9
"#;

/// Issue 59: `image` refused `--cantilever`, which every other command taking `--probe` takes.
/// Now the library's ARROW-NCR (k 42 N/m, f0 285 kHz, Q 450, R 10 nm: `afmdyn cantilevers`)
/// fills the probe's lever, and the image equals the one of the same constants written into
/// the file.
#[test]
fn image_takes_the_cantilever_library_as_every_command_does() {
    let dir = temp_dir("image-cantilever");
    let named = dir.join("named.toml");
    let written = dir.join("written.toml");
    std::fs::write(&named, SAMPLE_ONLY).unwrap();
    std::fs::write(
        &written,
        format!(
            "{SAMPLE_ONLY}[cantilever]\nspring_constant = 42.0\nresonance_frequency = 285e3\n\
             quality_factor = 450\n[tip]\nradius = 10e-9\n"
        ),
    )
    .unwrap();
    let image = |probe: &std::path::Path, extra: &[&str], out: &str| {
        let out = dir.join(out);
        let mut args = vec![
            "image",
            "--probe",
            probe.to_str().unwrap(),
            "--sample",
            "examples/sample-stripe.toml",
            "--setpoint",
            "0.8",
            "--pixels",
            "4",
            "--lines",
            "1",
            "--curve-points",
            "20",
            "--json",
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        serde_json::from_slice::<serde_json::Value>(&o.stdout).unwrap()
    };
    let a = image(&named, &["--cantilever", "ARROW-NCR"], "a");
    let b = image(&written, &[], "b");
    assert_eq!(a["image"], b["image"]);
    assert_eq!(a["materials"], b["materials"]);
    // a fluid needs the lever's plan, which neither probe has: the medium reaches the probe
    let o = run(&[
        "image",
        "--probe",
        named.to_str().unwrap(),
        "--cantilever",
        "ARROW-NCR",
        "--medium",
        "water",
        "--sample",
        "examples/sample-stripe.toml",
        "--setpoint",
        "0.8",
        "--out",
        dir.join("c").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("[medium]"));
}

/// Issue 60 item 17: `fm` and `reconstruct` refused `--files`, which the other curve commands
/// take. With `--files none` they write nothing (not even the locked directory) and print the
/// summary; with `--files data` the data without the plots.
#[test]
fn fm_and_reconstruct_take_files() {
    let dir = temp_dir("files");
    let none = dir.join("none");
    let o = run(&[
        "fm",
        "--points",
        "6",
        "--files",
        "none",
        "--out",
        none.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("no files written"));
    assert!(!none.exists());
    let data = dir.join("data");
    let o = run(&[
        "fm",
        "--points",
        "6",
        "--files",
        "data",
        "--out",
        data.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(data.join("fm.csv").exists() && data.join("fm.json").exists());
    assert!(!data.join("fm-frequency-shift.png").exists());
    let rec = dir.join("rec");
    let o = run(&[
        "reconstruct",
        "--fm",
        "examples/fm-vdw.csv",
        "--spring-constant",
        "40",
        "--resonance-frequency",
        "3e5",
        "--amplitude",
        "10nm",
        "--files",
        "none",
        "--out",
        rec.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("no files written"));
    assert!(!rec.exists());
}

/// Issue 60 part D: an SLS sample whose dashpot is out of reach blamed "[medium]: alpha6
/// (contact damping α6)", a group the user never wrote, under a section that was not at
/// fault; now the two `[sample]` keys that make it are named, with their units.
#[test]
fn an_sls_dashpot_out_of_reach_names_its_sample_keys() {
    let dir = temp_dir("sls");
    let text =
        std::fs::read_to_string(common::repo().join("examples/probe-water-sls.toml")).unwrap();
    assert!(text.contains("relaxation_time = 20e-6"));
    let probe = dir.join("sls.toml");
    std::fs::write(
        &probe,
        text.replace("relaxation_time = 20e-6", "relaxation_time = 1e30"),
    )
    .unwrap();
    refused(
        &["orbit", "--probe", probe.to_str().unwrap()],
        &[
            "[sample].maxwell_stiffness = 1.5e0 N/m",
            "relaxation_time = 1e30 s",
            "α6",
        ],
    );
    let err = String::from_utf8_lossy(&run(&["orbit", "--probe", probe.to_str().unwrap()]).stderr)
        .to_string();
    assert!(!err.contains("[medium]"), "{err}");
}

/// Issue 60 part D: resuming a finished curve store with one point's line removed exited 1
/// with "cancelled". The points from the gap on are run again (each starts from the one
/// before it), and the curve equals the uninterrupted one, byte for byte.
#[test]
fn a_finished_store_with_a_line_removed_is_completed_on_resume() {
    let dir = temp_dir("resume-gap");
    let (whole, cut) = (dir.join("whole"), dir.join("cut"));
    let approach = |out: &std::path::Path, resume: bool| {
        let mut args = vec![
            "approach",
            "--probe",
            "examples/probe-point-mass-dmt.toml",
            "--points",
            "30",
            "--files",
            "data",
            "--json",
            "--out",
            out.to_str().unwrap(),
        ];
        if resume {
            args.push("--resume");
        }
        let o = run(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        o.stdout
    };
    let first = approach(&whole, false);
    std::fs::create_dir_all(&cut).unwrap();
    let records = std::fs::read_to_string(whole.join(".curve.points.jsonl")).unwrap();
    let lines: Vec<&str> = records.lines().collect();
    assert_eq!(lines.len(), 60);
    let gap: String = lines
        .iter()
        .enumerate()
        .filter(|(k, _)| *k != 20)
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    std::fs::write(cut.join(".curve.points.jsonl"), gap).unwrap();
    std::fs::copy(whole.join(".curve.run.json"), cut.join(".curve.run.json")).unwrap();
    let again = approach(&cut, true);
    assert_eq!(
        String::from_utf8_lossy(&first),
        String::from_utf8_lossy(&again).replace(cut.to_str().unwrap(), whole.to_str().unwrap())
    );
}

/// `fit --range` takes LO,HI as its help says: one value, or three, is refused naming the flag
/// (a range of one value used to take the next flag as its second value).
#[test]
fn a_fit_range_of_the_wrong_length_is_refused_by_name() {
    for range in ["--range=1e-9", "--range=1e-9,2e-9,3e-9"] {
        refused(
            &[
                "fit",
                "--probe",
                "examples/probe-fit-hertz.toml",
                "--data",
                "examples/force-curve-hertz.csv",
                range,
                "--json",
                "--out",
                temp_dir("fit-range").join("out").to_str().unwrap(),
            ],
            &["--range", "must be two, LO,HI"],
        );
    }
}

/// An instrument's binary file given to `fit --data` is named as such, with where it is read
/// (issue 77: "CSV parse error: record 0 … invalid utf-8" on a JPK `.jpk-force`).
#[test]
fn an_instrument_file_for_fit_says_where_it_is_read() {
    refused(
        &[
            "fit",
            "--probe",
            "examples/probe-fit-spot3.toml",
            "--data",
            "examples/force-curve-jpk-spot3-0192.jpk-force",
        ],
        &[
            "a binary file",
            "through afmformats (afmdyn.fit(data=PATH))",
        ],
    );
}

/// `fit` of a force curve asks only for what it uses (issue 77 §10): a probe of the spring
/// constant, the tip and the sample gives the full example probe's estimates, naming the
/// stand-ins in its SI block; `approach` on the same file still names what it misses.
#[test]
fn a_force_curve_fit_takes_a_probe_of_k_tip_and_sample() {
    let dir = temp_dir("fit-k-tip-sample");
    let probe = dir.join("probe.toml");
    std::fs::write(
        &probe,
        "[cantilever]\nspring_constant = 0.05\n[tip]\nradius = 5e-6\n[sample]\n\
         law = \"hertz\"\nyoungs_modulus = 10e3\npoisson_ratio = 0.5\n",
    )
    .unwrap();
    let fit = |p: &str| {
        json(&[
            "fit",
            "--probe",
            p,
            "--data",
            "examples/force-curve-hertz.csv",
            "--json",
            "--files",
            "none",
        ])
    };
    let ours = fit(probe.to_str().unwrap());
    let full = fit("examples/probe-fit-hertz.toml");
    assert_eq!(ours["estimates"], full["estimates"]);
    assert_eq!(ours["si"]["assumed"][0], "model");
    refused(
        &["approach", "--probe", probe.to_str().unwrap(), "--json"],
        &[
            "missing key [cantilever].resonance_frequency",
            "missing table [drive]",
        ],
    );
}

/// A tapping request on a PeakForce (off-resonance) probe is refused naming `drive.mode` and
/// what to use instead (issue 77 §9: "to = 2e-10: must differ from the start of the sweep" for
/// `image --mode am`, "alpha2 = inf" for `fm`).
#[test]
fn a_tapping_request_on_an_off_resonance_probe_names_the_drive_mode() {
    let probe = "examples/probe-peakforce-air.toml";
    for args in [
        &["approach", "--probe", probe][..],
        &["fm", "--probe", probe],
        &["bimodal", "--probe", probe],
        &[
            "image",
            "--probe",
            probe,
            "--sample",
            "examples/sample-stripe.toml",
            "--setpoint",
            "0.7",
            "--mode",
            "am",
        ],
    ] {
        let mut args = args.to_vec();
        args.extend(["--files", "none"]);
        refused(
            &args,
            &[
                "drive.mode = off-resonance",
                "taps near a resonance",
                "afmdyn peakforce or image --mode peakforce",
            ],
        );
    }
}
