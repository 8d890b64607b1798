//! End-to-end tests of the `afmdyn` binary: the README's promises, the JSON contracts, bad input,
//! atomic outputs, and resuming an interrupted sweep.

use std::path::Path;
use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .output()
        .expect("run afmdyn")
}

fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "stderr: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("one JSON document")
}

fn bad_input(args: &[&str], needle: &str) {
    let out = afmdyn(args);
    assert_eq!(out.status.code(), Some(2), "{args:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: '{err}' should mention '{needle}'"
    );
    assert!(out.stdout.is_empty(), "no output presented as a result");
}

#[test]
fn modes_json_reproduces_eq25_with_five_modes() {
    let doc = json(&afmdyn(&[
        "modes", "--json", "--modes", "5", "--alpha3", "0", "--alpha6", "0",
    ]));
    let w: Vec<f64> = doc["contact"]["omega"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for (got, printed) in w.iter().zip([7.79, 20.33, 55.81]) {
        assert_eq!((got * 100.0).round() / 100.0, printed, "paper eq. 25");
    }
    // undamped: eigenvalues are ±iω, we list Im ≥ 0 sorted by Im, matching omega
    let ev = doc["contact"]["eigenvalues"].as_array().unwrap();
    assert_eq!(ev.len(), 5);
    for (e, wi) in ev.iter().zip(&w) {
        assert!((e[1].as_f64().unwrap() - wi).abs() < 1e-9 * wi);
        assert!(e[0].as_f64().unwrap().abs() < 1e-9 * wi);
    }
    assert_eq!(doc["params"]["modes"], 5);
    assert!(doc["free"]["omega"].as_array().unwrap().len() == 5);
}

#[test]
fn config_file_and_flags() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("m.toml");
    std::fs::write(
        &cfg,
        "modes = 4\nalpha1 = 0.2\ncontact_stiffness = 30.0\nomega = 3.0\n",
    )
    .unwrap();
    let doc = json(&afmdyn(&[
        "modes",
        "--json",
        "--config",
        cfg.to_str().unwrap(),
        "--omega",
        "3.5",
    ]));
    assert_eq!(doc["params"]["modes"], 4);
    assert_eq!(doc["params"]["alpha1"], 0.2);
    assert_eq!(doc["params"]["alpha4"], 30.0);
    assert_eq!(doc["params"]["omega"], 3.5, "flags override the file");
    std::fs::write(&cfg, "modes = 4\nstiffnes = 3.0\n").unwrap();
    bad_input(
        &["modes", "--config", cfg.to_str().unwrap()],
        "unknown field",
    );
    std::fs::write(&cfg, "modes = \"three\"\n").unwrap();
    bad_input(
        &["modes", "--config", cfg.to_str().unwrap()],
        "invalid type",
    );
    bad_input(&["modes", "--config", "/nonexistent/x.toml"], "x.toml");
}

#[test]
fn bad_parameters_exit_2_with_one_line() {
    bad_input(&["modes", "--modes", "0"], "1..=20");
    bad_input(&["modes", "--modes", "21"], "1..=20");
    bad_input(&["modes", "--alpha4", "-1"], "alpha4");
    bad_input(&["modes", "--tip-mass-ratio", "-0.5"], "alpha1");
    bad_input(&["modes", "--omega", "0"], "omega");
    bad_input(&["modes", "--omega", "nan"], "omega");
    bad_input(&["modes", "--gap", "inf"], "alpha5");
    bad_input(&["modes", "--bogus"], "--bogus");
    bad_input(&["simulate", "--periods", "-3"], "periods");
    bad_input(&["simulate", "--periods", "nan"], "periods");
    bad_input(
        &["simulate", "--initial-modal", "0.1,0.2;0,0,0"],
        "expected 3",
    );
    bad_input(&["simulate", "--initial-modal", "nan,0,0;0,0,0"], "finite");
    bad_input(
        &["simulate", "--initial-modal", "0.1,0,0"],
        "--initial-modal",
    );
    bad_input(&["bifurcation", "--param", "beta"], "beta");
    bad_input(
        &[
            "bifurcation",
            "--param",
            "alpha4",
            "--from",
            "-1",
            "--to",
            "5",
        ],
        "alpha4",
    );
    bad_input(&["simulate", "--integrator", "euler"], "euler");
}

#[test]
fn simulate_writes_series_events_section_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sim");
    let doc = json(&afmdyn(&[
        "simulate",
        "--periods",
        "6",
        "--transient",
        "2",
        "--samples-per-period",
        "50",
        "--csv",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!(doc["switchings"].as_u64().unwrap() >= 6);
    assert_eq!(doc["warnings"], serde_json::json!([]), "an accurate run");
    // the energy balance is audited only when asked for (`--energy-balance`)
    assert!(doc["energy_residual"].is_null());
    assert!(!out.join("energy.csv").exists());
    assert_eq!(doc["body_contact"], false);
    assert_eq!(doc["final"]["a"].as_array().unwrap().len(), 3);
    let t = doc["tau_end"].as_f64().unwrap();
    assert!((t - 8.0 * std::f64::consts::TAU / 2.6).abs() < 1e-9);
    // V_T = W + α2 sin Ωτ + α5 (eq. 8) in the summary
    let (w, v) = (
        doc["final"]["w_tip"].as_f64().unwrap(),
        doc["final"]["v_t"].as_f64().unwrap(),
    );
    assert!((v - (w + 0.1 * (2.6 * t).sin())).abs() < 1e-12);
    for f in [
        "timeseries.csv",
        "timeseries.npy",
        "events.csv",
        "poincare.csv",
        "tip.png",
        "tip.svg",
        "phase.png",
        "spectrum.svg",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let ts = std::fs::read_to_string(out.join("timeseries.csv")).unwrap();
    let header = ts.lines().next().unwrap();
    assert_eq!(
        header,
        "tau,v_t,w_tip,w_tip_dot,in_contact,contact_force,a_1,a_2,a_3,a_dot_1,a_dot_2,a_dot_3"
    );
    assert_eq!(ts.lines().count(), 1 + 6 * 50 + 1);
    let poincare = std::fs::read_to_string(out.join("poincare.csv")).unwrap();
    assert_eq!(
        poincare.lines().count(),
        1 + 7,
        "sections at τ = 2πk/Ω, k = 2..=8"
    );
    // no temporary file is left behind
    assert!(std::fs::read_dir(&out).unwrap().all(|e| !e
        .unwrap()
        .file_name()
        .to_string_lossy()
        .contains("partial")));
    // the same run with the oracle integrator ends at the same state
    let doc2 = json(&afmdyn(&[
        "simulate",
        "--periods",
        "6",
        "--transient",
        "2",
        "--samples-per-period",
        "50",
        "--json",
        "--integrator",
        "adaptive",
        "--tolerance",
        "1e-13",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert!((doc2["final"]["w_tip"].as_f64().unwrap() - w).abs() < 1e-8);
}

#[test]
fn units_example_probe() {
    let probe = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/probe.toml");
    let doc = json(&afmdyn(&[
        "units",
        "--json",
        "--config",
        probe.to_str().unwrap(),
    ]));
    let k = doc["scales"]["spring_constant"].as_f64().unwrap();
    assert!((k - 43.83).abs() < 0.1, "3EI/L³ of the 125 µm probe: {k}");
    assert!(doc["params"]["alpha4"].as_f64().unwrap() > 0.0);
}

fn rows(path: &Path) -> Vec<String> {
    let mut r: Vec<String> = std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(String::from)
        .collect();
    r.sort();
    r
}

#[test]
fn bifurcation_resumes_after_a_kill_without_lost_or_duplicated_rows() {
    let dir = tempfile::tempdir().unwrap();
    let (full, cut) = (dir.path().join("full"), dir.path().join("cut"));
    let args = |out: &Path| {
        vec![
            "bifurcation".to_string(),
            "--from".into(),
            "2.4".into(),
            "--to".into(),
            "2.9".into(),
            "--steps".into(),
            "12".into(),
            "--starts".into(),
            "1".into(),
            "--max-periods".into(),
            "300".into(),
            "--out".into(),
            out.to_str().unwrap().into(),
        ]
    };
    let run = |extra: &[&str], out: &Path| {
        let mut a: Vec<String> = args(out);
        a.extend(extra.iter().map(|s| s.to_string()));
        afmdyn(&a.iter().map(String::as_str).collect::<Vec<_>>())
    };
    assert!(run(&[], &full).status.success());
    let reference = rows(&full.join("bifurcation.csv"));
    assert!(!reference.is_empty());
    // a killed run (aborted after 20 of its 36 points) leaves a partial file; a row cut in the
    // middle is appended as a kill during a write would leave it
    let killed = run(&["--abort-after", "20"], &cut);
    assert!(!killed.status.success(), "the run was killed");
    let partial = cut.join(".bifurcation.partial.csv");
    let text = std::fs::read_to_string(&partial).unwrap();
    assert!(
        text.lines().count() > 20,
        "rows of the killed run were kept"
    );
    std::fs::write(&partial, text + "omega,2.5,5,start-0,peri").unwrap();
    assert!(!cut.join("bifurcation.csv").exists());
    let out = run(&["--resume"], &cut);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let resumed = rows(&cut.join("bifurcation.csv"));
    assert_eq!(resumed.len(), reference.len(), "no lost or duplicated rows");
    assert_eq!(
        resumed, reference,
        "the resumed sweep equals the uninterrupted one"
    );
    assert!(!partial.exists());
    assert!(cut.join("bifurcation.npy").exists() && cut.join("bifurcation.png").exists());
}

#[test]
fn default_bifurcation_run_completes_and_writes_plot_and_data() {
    let dir = tempfile::tempdir().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .arg("bifurcation")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let o = dir.path().join("afmdyn-out");
    for f in [
        "bifurcation.csv",
        "bifurcation.npy",
        "bifurcation.png",
        "bifurcation.svg",
        "bifurcation-xmax.png",
        "bifurcation-branches.svg",
    ] {
        assert!(
            o.join(f).metadata().map(|m| m.len() > 0).unwrap_or(false),
            "{f}"
        );
    }
    let text = std::fs::read_to_string(o.join("bifurcation.csv")).unwrap();
    let mut keys: Vec<(String, String)> = text
        .lines()
        .skip(1)
        .filter(|l| l.split(',').nth(6) == Some("0"))
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[2].to_string(), c[3].to_string())
        })
        .collect();
    keys.sort();
    keys.dedup();
    assert_eq!(keys.len(), 800, "400 values × forward and backward");
    // the paper's Fig. 5 set over Ω ∈ [1, 5]
    let first = text.lines().nth(1).unwrap();
    assert!(first.starts_with("omega,"));
}

#[test]
fn attractors_json_contract() {
    let dir = tempfile::tempdir().unwrap();
    let doc = json(&afmdyn(&[
        "attractors",
        "--omega",
        "3.2",
        "--samples",
        "6",
        "--json",
        "--out",
        dir.path().to_str().unwrap(),
    ]));
    let atts = doc["attractors"].as_array().unwrap();
    assert!(!atts.is_empty());
    let total: f64 = atts
        .iter()
        .map(|a| a["basin_fraction"].as_f64().unwrap())
        .sum();
    assert!((total - 1.0).abs() < 1e-12);
    for a in atts {
        let n = a["period"].as_u64().unwrap_or(0) as usize;
        if n > 0 {
            assert_eq!(a["poincare"]["v_t"].as_array().unwrap().len(), n);
            assert_eq!(a["poincare"]["w_tip"].as_array().unwrap().len(), n);
        }
        // at drive phase 0, V_T = W_tip + α5 (eq. 8 with sin 0 = 0)
        for (v, w) in a["poincare"]["v_t"]
            .as_array()
            .unwrap()
            .iter()
            .zip(a["poincare"]["w_tip"].as_array().unwrap())
        {
            assert!((v.as_f64().unwrap() - w.as_f64().unwrap()).abs() < 1e-12);
        }
        assert!(a["x_max"].as_f64().unwrap() >= a["poincare"]["w_tip"][0].as_f64().unwrap());
    }
    assert!(dir.path().join("attractor-1-phase.png").exists());
}

#[test]
fn orbit_json_contract_and_attractor_handoff() {
    let dir = tempfile::tempdir().unwrap();
    let att = json(&afmdyn(&[
        "attractors",
        "--omega",
        "2.8",
        "--samples",
        "4",
        "--json",
        "--out",
        dir.path().to_str().unwrap(),
    ]));
    let a = &att["attractors"][0];
    assert_eq!(a["period"], 2);
    let start = a["initial_modal"].as_str().unwrap().to_string();
    let doc = json(&afmdyn(&[
        "orbit",
        "--omega",
        "2.8",
        "--period",
        "2",
        "--initial-modal",
        &start,
        "--json",
    ]));
    assert_eq!(doc["period"], 2);
    assert_eq!(doc["stable"], true);
    assert_eq!(
        doc["grazing"],
        doc["grazing_distance"].as_f64().unwrap() < 1e-3
    );
    assert_eq!(doc["multipliers"].as_array().unwrap().len(), 6);
    assert_eq!(doc["poincare"]["v_t"].as_array().unwrap().len(), 2);
    // the orbit found by shooting is the attractor: same section points (in some order)
    let w: Vec<f64> = doc["poincare"]["w_tip"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let wa: Vec<f64> = a["poincare"]["w_tip"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for x in &w {
        assert!(wa.iter().any(|y| (x - y).abs() < 1e-6), "{w:?} vs {wa:?}");
    }
    for m in doc["multipliers"].as_array().unwrap() {
        assert!(m[0].as_f64().unwrap().hypot(m[1].as_f64().unwrap()) < 1.0);
    }
    bad_input(&["orbit", "--period", "0"], "period");
}

#[test]
fn lyapunov_json_contract() {
    let doc = json(&afmdyn(&[
        "lyapunov",
        "--omega",
        "3.5",
        "--transient",
        "100",
        "--periods",
        "300",
        "--blocks",
        "3",
        "--json",
    ]));
    let e: Vec<f64> = doc["exponents"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let u = doc["uncertainty"].as_array().unwrap();
    assert_eq!(e.len(), 6);
    assert_eq!(u.len(), 6);
    assert!(e.windows(2).all(|w| w[0] >= w[1]), "sorted");
    assert!(e[0] < 0.0, "a stable period-1 orbit at Ω = 3.5");
    assert!((e.iter().sum::<f64>() - doc["volume_rate"].as_f64().unwrap()).abs() < 1e-9);
    assert_eq!(doc["verdict"], "periodic");
    bad_input(&["lyapunov", "--periods", "1", "--blocks", "10"], "periods");
}

#[test]
fn continue_writes_branch_csv_and_overlay_plot() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("c");
    let doc = json(&afmdyn(&[
        "continue",
        "--from",
        "3.2",
        "--to",
        "2.8",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]));
    let events = doc["events"].as_array().unwrap();
    assert!(
        events.iter().any(|e| e["event"] == "period-doubling"),
        "{events:?}"
    );
    let csv = std::fs::read_to_string(out.join("continuation.csv")).unwrap();
    assert!(csv.starts_with("branch,period,s,value,stable,max_multiplier,critical,w_tip_section,switchings,grazing_distance,event"));
    assert!(csv.lines().count() > 10);
    assert!(out.join("continuation.png").exists() && out.join("continuation.svg").exists());
}

/// A negative number with an exponent is a flag's value (clap's lexer alone read `-5e-1` as
/// short flags: "unexpected argument '-5' found"), on every numeric flag alike.
#[test]
fn negative_numbers_with_exponents_are_values() {
    let written = json(&afmdyn(&["orbit", "--json", "--gap", "-5e-1"]));
    let plain = json(&afmdyn(&["orbit", "--json", "--gap=-0.5"]));
    assert_eq!(written, plain);
    assert_eq!(written["params"]["alpha5"], -0.5);
    // a negative value where only positive ones are valid reaches the range check
    bad_input(
        &["orbit", "--omega", "-1e-3"],
        "omega (drive frequency Ω) = -0.001",
    );
    // a boolean flag takes no value, negative or not
    bad_input(&["orbit", "--json", "-1e-3"], "--json");
}

/// The exit-code rule (docs/outputs.md): an attractor census whose every start failed has no
/// answer — exit 1 with the count and the first error (it exited 0 with `"attractors": []`
/// and nothing on stderr; issue 27). The adaptive integrator fails every start of a tip 1e6 g₀
/// deep in the sample (the default integrator resolves that motion).
#[test]
fn an_attractor_census_whose_every_start_failed_exits_1() {
    let dir = std::env::temp_dir().join(format!("afmdyn-cli-att-{}", std::process::id()));
    let out = afmdyn(&[
        "attractors",
        "--contact-law",
        "hertz",
        "--integrator",
        "adaptive",
        "--gap",
        "-1e6",
        "--samples",
        "4",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with(
            "afmdyn: every one of the 4 random starts failed; the first: adaptive integrator: \
             more than 1e5 steps"
        ),
        "{err}"
    );
    assert_eq!(err.lines().count(), 1, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `tip.png` shows at most the last 10 drive periods (readable); a longer record is drawn whole
/// in `tip-all.png`, which a short one does not write.
#[test]
fn the_tip_plot_shows_the_last_periods_of_a_long_record() {
    let dir = tempfile::tempdir().unwrap();
    for (periods, all) in [("5", false), ("20", true)] {
        let out = dir.path().join(periods);
        let o = out.to_str().unwrap();
        let run = afmdyn(&["simulate", "--periods", periods, "--out", o]);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        assert!(out.join("tip.png").exists());
        assert_eq!(out.join("tip-all.png").exists(), all, "{periods} periods");
        let svg = std::fs::read_to_string(out.join("tip.svg")).unwrap();
        assert_eq!(svg.contains("last 10 of 20 periods"), all);
    }
}

/// An orbit search whose start shows no period says so when Newton fails (the impact
/// oscillator at Ω = 5 with r = 0.7 is nonperiodic from rest): exit 1, one line.
#[test]
fn a_failed_orbit_search_says_the_start_was_nonperiodic() {
    // orbit, and the issue's continuation (which ended with a bare "shooting did not
    // converge"); with the period given, Newton's failure is reported as it is
    let dir = std::env::temp_dir().join(format!("afmdyn-cont-start-{}", std::process::id()));
    let out_dir = dir.to_str().unwrap();
    let law = ["--contact-law", "impact", "--restitution", "0.7"];
    let orbit = [&["orbit"][..], &law, &["--omega", "5"]].concat();
    let cont = [
        &["continue"][..],
        &law,
        &["--from", "5", "--to", "1", "--switch", "--out", out_dir],
    ]
    .concat();
    // `orbit` without a period tries Newton from the last state, the line-searched Newton from
    // it and from the section's closest returns (issue 42 §4); from this start's section (the
    // transient cap derived from the beam's decay at Ω = 5: 2 862 periods) none converges, and
    // the failure says that no period up to max_period was found (the typed NoPeriod, issue
    // 60 item 10); with period 7 given it is Newton's failure as it is
    for (args, explained) in [
        (orbit.clone(), true),
        (cont.clone(), true),
        ([&orbit[..], &["--period", "7"]].concat(), false),
    ] {
        let out = afmdyn(&args);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            err.contains("no periodic orbit found")
                && err.contains("with a period of at most 64 drive periods")
                && err.contains("not periodic within max_period")
                && err.contains("`simulate`"),
            explained,
            "{args:?}: {err}"
        );
        assert_eq!(err.contains("did not converge"), !explained, "{err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 27 item 2, one meaning per exit code (docs/outputs.md, "Exit codes and warnings"):
/// the adaptive stepper's up-front budget (Ω = 1e-3 with the Hertz law needs ~2e7 steps per
/// period) is bad input — exit 2, one line naming the budget, nothing on stdout — in every
/// analysis, the studies of many runs included (`attractors` exited 1 with "every one of the 4
/// random starts failed", and before that 0 with `"attractors": []`).
#[test]
fn a_budget_refusal_exits_2_in_every_analysis() {
    let dir = std::env::temp_dir().join(format!("afmdyn-budget-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let law = ["--contact-law", "hertz", "--omega", "1e-3"];
    let cases: [&[&str]; 8] = [
        &["orbit"],
        &["continue", "--from", "1e-3", "--to", "2e-3", "--out", out],
        &["lyapunov", "--periods", "200"],
        &["attractors", "--samples", "4", "--json"],
        &[
            "bifurcation",
            "--from",
            "1e-3",
            "--to",
            "1",
            "--steps",
            "3",
            "--out",
            out,
        ],
        &["basins", "--x-steps", "3", "--y-steps", "3", "--out", out],
        &[
            "attractors",
            "--sweep",
            "omega",
            "--from",
            "1e-3",
            "--to",
            "2e-3",
            "--steps",
            "2",
        ],
        &[
            "simulate",
            "--periods",
            "2",
            "--integrator",
            "adaptive",
            "--out",
            out,
        ],
    ];
    for case in cases {
        let args = [case, &law].concat();
        bad_input(&args, "exceeds the budget of 1e7");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn help_shows_the_defaults_and_errors_keep_the_hint() {
    let o = afmdyn(&["simulate", "--help"]);
    assert!(o.status.success());
    let help = String::from_utf8_lossy(&o.stdout)
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ");
    let d = afmdyn::Params::default();
    for (flag, text) in [
        ("--modes", format!("[default: {}]", d.modes)),
        ("--tip-mass-ratio", format!("[default: {}]", d.alpha1)),
        ("--drive-amplitude", format!("[default: {}]", d.alpha2)),
        ("--beam-damping", format!("[default: {}]", d.alpha3)),
        ("--contact-stiffness", format!("[default: {}]", d.alpha4)),
        ("--gap", format!("[default: {}]", d.alpha5)),
        ("--contact-damping", format!("[default: {}]", d.alpha6)),
        ("--omega", format!("[default: {}", d.omega)),
        // the request's description (docs/schema/requests/simulate.json)
        ("--periods", "default 50".to_string()),
    ] {
        let at = help
            .find(&format!("{flag} <"))
            .unwrap_or_else(|| panic!("{flag} in {help}"));
        let next = help[at + 2..]
            .find(" --")
            .map_or(help.len(), |k| at + 2 + k);
        assert!(
            help[at..next].contains(&text),
            "{flag}: {}",
            &help[at..next]
        );
    }
    bad_input(&["simulate", "--omgea", "3"], "--omega");
}

#[test]
fn toml_errors_give_the_line_and_name_a_duplicate_key() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = dir.path().join("m.toml");
    std::fs::write(&cfg, "modes = 3\nomega = 2.0\nomega = 3.0\n").unwrap();
    let args = ["modes", "--config", cfg.to_str().unwrap()];
    bad_input(&args, "line 3");
    bad_input(&args, "duplicate key `omega`");
    std::fs::write(&cfg, "modes = 3\n\nalpha1 = = 2\n").unwrap();
    bad_input(&args, "line 3");
    std::fs::write(&cfg, "modes = 3\nstiffnes = 3.0\n").unwrap();
    bad_input(&args, "line 2");
}
