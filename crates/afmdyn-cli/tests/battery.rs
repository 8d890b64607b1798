//! The defects the outside battery of issue 42 (section 3) found in bad input, input files,
//! budgets, exit codes and messages, each run on the built binary: bad input exits 2 with one
//! line naming the field and its range; a failed write exits 1 naming it.

use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .output()
        .expect("run afmdyn")
}

/// `args` exit 2 with one line on stderr mentioning every one of `needles`, and no stdout.
fn bad_input(args: &[&str], needles: &[&str]) -> String {
    let out = afmdyn(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    for needle in needles {
        assert!(
            err.contains(needle),
            "{args:?}: '{err}' should mention '{needle}'"
        );
    }
    assert!(out.stdout.is_empty(), "no output presented as a result");
    err
}

fn tmp(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("afmdyn-battery-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

const CHART: [&str; 13] = [
    "chart",
    "--x",
    "omega",
    "--x-from",
    "2.6",
    "--x-to",
    "3.0",
    "--x-steps",
    "2",
    "--y",
    "drive-amplitude",
    "--y-from",
    "0.1",
];

/// A chart's model values are refused when not finite, as every other analysis refuses them
/// (they reached the cells through JSON as `null`, and the cells ran the default α4 = 20).
#[test]
fn chart_refuses_non_finite_model_values() {
    let out = tmp("chart-nan");
    let o = out.to_str().unwrap();
    for (flag, v) in [("--contact-stiffness", "inf"), ("--contact-damping", "nan")] {
        let mut args = CHART.to_vec();
        args.extend(["--y-to", "0.12", "--y-steps", "2", flag, v, "--out", o]);
        bad_input(&args, &[&flag[2..], "must be a finite number"]);
    }
    // the same value in attractors: refused alike
    bad_input(
        &["attractors", "--contact-stiffness", "inf", "--out", o],
        &["contact stiffness", "= inf", "finite"],
    );
}

/// Every integrator tolerance has a range, whatever the law and integrator (the exact
/// propagator of the linear law ignores it but a NaN, 0 or −1 is still not a tolerance).
#[test]
fn integrator_tolerance_has_a_range_for_every_law() {
    let out = tmp("tolerance");
    let o = out.to_str().unwrap();
    for t in ["nan", "0", "-1", "1", "1e300", "1e-300"] {
        bad_input(
            &["attractors", "--tolerance", t, "--samples", "2", "--out", o],
            &["tolerance", "[1e-16, 1e-3]"],
        );
    }
    bad_input(
        &[
            "simulate",
            "--contact-law",
            "hertz",
            "--tolerance",
            "0.5",
            "--periods",
            "1",
            "--files",
            "none",
            "--out",
            o,
        ],
        &["tolerance", "[1e-16, 1e-3]"],
    );
}

/// Input files are read with a size bound: a device without end is refused within seconds,
/// naming the file, without reading on; a non-UTF-8 file is refused naming it.
#[test]
fn input_files_are_bounded_and_text() {
    let out = tmp("files");
    let o = out.to_str().unwrap();
    let cases: [&[&str]; 4] = [
        &["modes", "--probe", "/dev/zero"],
        &["modes", "--config", "/dev/zero"],
        &["units", "--probe", "/dev/zero"],
        &[
            "continue",
            "--from",
            "3",
            "--to",
            "2.9",
            "--overlay",
            "/dev/zero",
            "--out",
            o,
        ],
    ];
    for args in cases {
        let start = Instant::now();
        bad_input(args, &["/dev/zero", "larger than"]);
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "{args:?} took {:?}",
            start.elapsed()
        );
    }
    let binary = out.join("binary.toml");
    std::fs::write(&binary, [b'a', b' ', b'=', b' ', 0xff, 0xfe, b'\n']).unwrap();
    let b = binary.to_str().unwrap();
    bad_input(&["modes", "--config", b], &[b, "not UTF-8"]);
    bad_input(&["modes", "--probe", b], &[b, "not UTF-8"]);
    let start = Instant::now();
    bad_input(&["modes", "--config", "/dev/urandom"], &["/dev/urandom"]);
    assert!(start.elapsed() < Duration::from_secs(10));
}

/// An unreadable overlay is bad input (exit 2) naming the file, as an unreadable probe is.
#[test]
fn unreadable_overlay_is_bad_input() {
    let out = tmp("overlay");
    let o = out.to_str().unwrap();
    let missing = out.join("missing.csv");
    let m = missing.to_str().unwrap();
    bad_input(
        &[
            "continue",
            "--from",
            "3",
            "--to",
            "2.9",
            "--overlay",
            m,
            "--out",
            o,
        ],
        &["--overlay", m],
    );
}

/// The traces of a stepped curve have a memory budget, checked before any work:
/// 1000 points × 10000 samples × up to 16 periods × 24 bytes = 3.6 GiB > 1 GiB.
#[test]
fn approach_traces_have_a_memory_budget() {
    let out = tmp("traces");
    let o = out.to_str().unwrap();
    let start = Instant::now();
    bad_input(
        &[
            "approach", "--points", "1000", "--traces", "10000", "--files", "none", "--out", o,
        ],
        &["traces", "3.6 GiB", "exceeds the budget of 1 GiB"],
    );
    assert!(start.elapsed() < Duration::from_secs(10));
}

/// A failed write to standard output is exit 1 naming it and the cause, not a panic (101).
#[test]
fn failed_write_to_stdout_is_exit_1() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return; // no /dev/full on this system
    };
    for args in [&["modes"][..], &["modes", "--json"], &["cantilevers"]] {
        let out = Command::new(env!("CARGO_BIN_EXE_afmdyn"))
            .args(args)
            .stdout(Stdio::from(full.try_clone().unwrap()))
            .output()
            .expect("run afmdyn");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert_eq!(
            err.trim_end(),
            "afmdyn: cannot write to standard output: No space left on device",
            "{args:?}"
        );
    }
}

/// One meaning per exit code: an integrator beyond its budget is bad input (exit 2) in a chart
/// as in the attractor census, before any cell runs.
#[test]
fn budgets_are_bad_input_in_chart_as_in_attractors() {
    let out = tmp("budget");
    let o = out.to_str().unwrap();
    let stiff = ["--contact-law", "hertz", "--contact-stiffness", "1e8"];
    let mut args = CHART.to_vec();
    args.extend(["--y-to", "0.12", "--y-steps", "2", "--out", o]);
    args.extend(stiff);
    let chart = bad_input(&args, &["exceeds the budget"]);
    let mut args = vec!["attractors", "--samples", "2", "--out", o];
    args.extend(stiff);
    let census = bad_input(&args, &["exceeds the budget"]);
    assert_eq!(chart, census, "the same refusal");
}

/// The contact law's name is taken in any case everywhere: on the command line, in a config
/// file and in a probe file (a config file refused "HERTZ").
#[test]
fn contact_law_is_case_insensitive_in_config_files() {
    let out = tmp("law");
    let cfg = out.join("hertz.toml");
    std::fs::write(&cfg, "contact_law = \"HERTZ\"\n").unwrap();
    let file = afmdyn(&["modes", "--json", "--config", cfg.to_str().unwrap()]);
    assert!(
        file.status.success(),
        "{}",
        String::from_utf8_lossy(&file.stderr)
    );
    let flag = afmdyn(&["modes", "--json", "--contact-law", "Hertz"]);
    assert!(flag.status.success());
    let lower = afmdyn(&["modes", "--json", "--contact-law", "hertz"]);
    assert_eq!(file.stdout, lower.stdout);
    assert_eq!(flag.stdout, lower.stdout);
    let doc: serde_json::Value = serde_json::from_slice(&file.stdout).unwrap();
    assert_eq!(doc["params"]["contact_law"]["law"], "hertz", "{doc}");
}

/// Numbers in messages have at most 6 significant digits: no 300-digit integers for 1e300, no
/// 16-digit round-off.
#[test]
fn messages_print_short_numbers() {
    let out = tmp("numbers");
    let o = out.to_str().unwrap();
    let err = bad_input(
        &[
            "simulate",
            "--periods",
            "1e300",
            "--files",
            "none",
            "--out",
            o,
        ],
        &["periods", "1e300"],
    );
    let longest = err
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(longest <= 6, "a number of {longest} digits: {err}");
}

/// Q = 1e308 is refused naming quality_factor and its range (it reached the model as
/// α2 = NaN, and the message blamed the [drive] keys).
#[test]
fn huge_quality_factor_is_refused_by_name() {
    let out = tmp("q");
    let probe = out.join("q.toml");
    let example = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/probe-point-mass-dmt.toml"
    );
    let text = std::fs::read_to_string(example).unwrap();
    assert!(text.contains("quality_factor = 400 "));
    std::fs::write(
        &probe,
        text.replace("quality_factor = 400 ", "quality_factor = 1e308 "),
    )
    .unwrap();
    let err = bad_input(
        &["modes", "--probe", probe.to_str().unwrap()],
        &["[cantilever].quality_factor = 1e308", "(0, 1e7]"],
    );
    assert!(!err.contains("NaN"), "{err}");
}
