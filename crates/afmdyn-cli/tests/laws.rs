//! Every subcommand with every tip–sample law (`--contact-law`), the law and its groups under
//! `params` in the JSON documents, and the law flags' errors.

use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .output()
        .expect("run afmdyn")
}

fn ok(args: &[&str]) -> Output {
    let out = afmdyn(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

fn json(args: &[&str]) -> serde_json::Value {
    serde_json::from_slice(&ok(args).stdout).expect("one JSON document")
}

/// (law flags, model flags giving a periodic orbit at the chosen Ω, Ω).
const LAWS: [(&[&str], &[&str], &str); 8] = [
    (&["--contact-law", "linear"], &["--modes", "2"], "2.8"),
    (&["--contact-law", "hertz"], &["--modes", "2"], "2.8"),
    (
        &[
            "--contact-law",
            "dmt",
            "--hamaker",
            "1e-5",
            "--intermolecular-distance",
            "0.01",
        ],
        &["--modes", "2"],
        "2.8",
    ),
    (
        &["--contact-law", "impact", "--restitution", "0.5"],
        &["--modes", "1", "--gap", "0.05"],
        "3.0",
    ),
    // the documented defaults: `--contact-law electrostatic` runs as it stands
    (
        &["--contact-law", "electrostatic"],
        &["--modes", "2"],
        "2.8",
    ),
    // and `--contact-law jkr`: a hysteretic contact (the neck) through every subcommand
    (&["--contact-law", "jkr"], &["--modes", "2"], "2.8"),
    // and `--contact-law capillary`: a meniscus formed at contact, ruptured at V_T = D̃_r
    (
        &["--contact-law", "capillary", "--rupture", "0.04"],
        &["--modes", "2"],
        "2.8",
    ),
    // and `--contact-law sls`: an internal state (the Maxwell dashpot) and a recovering surface
    (&["--contact-law", "sls"], &["--modes", "2"], "3.0"),
];

fn as_refs(v: Vec<String>) -> Output {
    ok(&v.iter().map(String::as_str).collect::<Vec<_>>())
}

#[test]
fn every_subcommand_runs_every_law() {
    let dir = tempfile::tempdir().unwrap();
    for (law, model, omega) in LAWS {
        let name = law[1];
        let mut base: Vec<&str> = law.to_vec();
        base.extend_from_slice(model);
        base.extend_from_slice(&["--omega", omega]);
        let out = |sub: &str| dir.path().join(format!("{name}-{sub}"));
        let run = |sub: &str, extra: &[&str]| {
            let o = out(sub);
            let mut args = vec![sub];
            args.extend_from_slice(&base);
            args.extend_from_slice(extra);
            args.extend_from_slice(&["--out", o.to_str().unwrap()]);
            args.into_iter().map(String::from).collect::<Vec<_>>()
        };
        // simulate: the series and events, the law named in the JSON
        let doc: serde_json::Value = serde_json::from_slice(
            &as_refs(run(
                "simulate",
                &["--periods", "3", "--transient", "5", "--json"],
            ))
            .stdout,
        )
        .unwrap();
        assert_eq!(doc["params"]["contact_law"]["law"], name, "{doc}");
        // orbit: the JSON contract holds for every law
        let mut args: Vec<&str> = vec!["orbit"];
        args.extend_from_slice(&base);
        args.push("--json");
        let doc = json(&args);
        assert_eq!(doc["params"]["contact_law"]["law"], name);
        assert!(doc["stable"].as_bool().unwrap(), "{name}: {doc}");
        assert_eq!(
            doc["poincare"]["v_t"].as_array().unwrap().len(),
            doc["period"].as_u64().unwrap() as usize
        );
        assert!(doc["multipliers"][0].as_array().unwrap().len() == 2);
        // the analyses over a short range
        (as_refs(run(
            "bifurcation",
            &[
                "--steps",
                "3",
                "--from",
                omega,
                "--to",
                &format!("{}", omega.parse::<f64>().unwrap() + 0.02),
                "--max-periods",
                "200",
                "--threads",
                "1",
            ],
        )));
        (as_refs(run(
            "attractors",
            &["--samples", "2", "--max-periods", "200"],
        )));
        let to = format!("{}", omega.parse::<f64>().unwrap() + 0.02);
        (as_refs(run("continue", &["--from", omega, "--to", &to])));
        let mut args: Vec<&str> = vec!["lyapunov"];
        args.extend_from_slice(&base);
        args.extend_from_slice(&[
            "--transient",
            "10",
            "--periods",
            "40",
            "--blocks",
            "4",
            "--json",
        ]);
        let doc = json(&args);
        assert!(doc["exponents"][0].as_f64().unwrap() < 0.0, "{name}: {doc}");
        (as_refs(run("converge", &["--max-modes", "2", "--periods", "2"])));
    }
}

#[test]
fn law_flags_are_checked() {
    for (args, needle) in [
        (vec!["orbit", "--contact-law", "elastic"], "contact law"),
        (vec!["orbit", "--restitution", "0.5"], "contact_law"),
        (
            vec!["orbit", "--contact-law", "hertz", "--restitution", "0.5"],
            "restitution",
        ),
        (
            vec!["orbit", "--contact-law", "impact", "--restitution", "1.5"],
            "restitution",
        ),
        (
            vec!["orbit", "--contact-law", "dmt", "--hamaker", "-1"],
            "hamaker",
        ),
        (
            vec!["orbit", "--contact-law", "dmt", "--electrostatic", "1e-3"],
            "electrostatic",
        ),
        (
            vec!["orbit", "--contact-law", "hertz", "--adhesion", "0.1"],
            "adhesion",
        ),
        (
            vec!["orbit", "--contact-law", "jkr", "--adhesion", "0"],
            "adhesion",
        ),
        (
            vec!["orbit", "--contact-law", "jkr", "--contact-stiffness", "0"],
            "alpha4",
        ),
        (
            vec!["orbit", "--contact-law", "dmt", "--meniscus", "0.01"],
            "meniscus is a group of the capillary law",
        ),
        (
            vec!["orbit", "--contact-law", "capillary", "--rupture", "0"],
            "rupture",
        ),
        (
            vec!["orbit", "--contact-law", "capillary", "--capillary", "-1"],
            "capillary",
        ),
        (
            vec!["simulate", "--contact-law", "jkr", "--integrator", "rk4"],
            "neck",
        ),
        (
            vec!["simulate", "--contact-law", "jkr", "--integrator", "taylor"],
            "taylor",
        ),
        (
            vec!["orbit", "--contact-law", "sls", "--maxwell-stiffness", "0"],
            "maxwell_stiffness",
        ),
        (
            vec!["orbit", "--contact-law", "sls", "--contact-damping", "0"],
            "alpha6",
        ),
        (
            vec!["simulate", "--contact-law", "sls", "--integrator", "split"],
            "split",
        ),
        (vec!["orbit", "--excitation", "laser"], "excitation 'laser'"),
        (
            vec![
                "orbit",
                "--probe",
                concat!(
                    env!("CARGO_MANIFEST_DIR"),
                    "/../../examples/probe-beam-dmt.toml"
                ),
                "--excitation",
                "tip",
            ],
            "[drive] excitation",
        ),
        (
            vec![
                "orbit",
                "--contact-law",
                "electrostatic",
                "--tip-radius",
                "0",
            ],
            "tip_radius",
        ),
        (
            vec![
                "simulate",
                "--contact-law",
                "electrostatic",
                "--integrator",
                "taylor",
            ],
            "taylor",
        ),
        (
            vec![
                "simulate",
                "--contact-law",
                "hertz",
                "--integrator",
                "exact",
            ],
            "exact",
        ),
        (
            vec!["simulate", "--contact-law", "impact", "--integrator", "rk4"],
            "rk4",
        ),
    ] {
        let out = afmdyn(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}
