//! What the command line prints under a probe: text summaries in SI with the prefixes of
//! `--units`, and the chart's CSV lengths in metres (issue 42).

use crate::common;
use common::{json, text};

/// The text summaries of `orbit`, `modes`, `lyapunov` and `continue` speak SI under a probe,
/// with the prefixes of `--units` (issue 42: they printed Ω = 1, g0 and τ): the drive in kHz,
/// z_c and the tip deflection in nm, natural frequencies in kHz, Lyapunov exponents in 1/s —
/// the same numbers as the JSON document's `si` block; without a probe the model's units.
#[test]
fn text_summaries_speak_si_under_a_probe() {
    let pm = "examples/probe-point-mass-dmt.toml";
    let orbit = text(&["orbit", "--probe", pm]);
    assert!(
        orbit.starts_with("period-1 orbit at f = 300.000 kHz, z_c = 8.00000 nm ("),
        "{orbit}"
    );
    assert!(orbit.contains("section 0: tip deflection = ") && orbit.contains(" nm\n"));
    assert!(
        !orbit.contains("Ω =") && !orbit.contains("W(1,τ)"),
        "{orbit}"
    );
    let doc = json(&["orbit", "--probe", pm, "--json"]);
    let v_t = doc["si"]["poincare_v_t_m"][0].as_f64().unwrap();
    let shown: f64 = orbit
        .split("tip deflection = ")
        .nth(1)
        .unwrap()
        .split(" nm")
        .next()
        .unwrap()
        .parse()
        .unwrap();
    // V_T = W(1) + α5 and α5 g0 = z_c − a0 under DMT (a0 = 0.165 nm in the file)
    let z_c = doc["si"]["z_c_m"].as_f64().unwrap();
    assert!(
        (shown * 1e-9 - (v_t - z_c + 0.165e-9)).abs() < 1e-5 * 1e-9,
        "{shown} nm"
    );
    let modes = text(&["modes", "--probe", pm]);
    assert!(modes.contains("300.000 kHz"), "{modes}");
    assert!(!modes.contains("ω (undamped)"), "{modes}");
    let args = [
        "lyapunov",
        "--probe",
        pm,
        "--transient",
        "10",
        "--periods",
        "20",
        "--blocks",
        "2",
    ];
    let lya = text(&args);
    assert!(
        lya.starts_with("Lyapunov exponents (1/s) over 20 periods at f = 300.000 kHz:"),
        "{lya}"
    );
    let first: f64 = lya
        .lines()
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let doc = json(&[&args[..], &["--json"]].concat());
    let want = doc["si"]["exponents_per_s"][0].as_f64().unwrap();
    assert!(
        (first - want).abs() <= 1e-6 * want.abs(),
        "{first} against {want}"
    );
    // without a probe: the model's units, as before
    let plain = text(&["orbit", "--omega", "2.8"]);
    assert!(plain.starts_with("period-2 orbit at Ω = 2.8 ("), "{plain}");
}

/// `attractors` under a probe prints the drive in kHz, z_c and each attractor's X_max in nm
/// (issue 42: Ω = 1 and g0), X_max equal to the JSON document's `si.attractors_x_max_m`.
#[test]
fn attractors_text_speaks_si_under_a_probe() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let pm = "examples/probe-point-mass-dmt.toml";
    let args = [
        "attractors",
        "--probe",
        pm,
        "--samples",
        "2",
        "--max-periods",
        "300",
        "--out",
        out,
    ];
    let t = text(&args);
    assert!(t.contains("at f = 300.000 kHz, z_c = 8.00000 nm:"), "{t}");
    assert!(!t.contains("Ω ="), "{t}");
    let shown: f64 = t
        .split("X_max = ")
        .nth(1)
        .unwrap()
        .split(" nm")
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let doc = json(&[&args[..], &["--json"]].concat());
    let want = doc["si"]["attractors_x_max_m"][0].as_f64().unwrap();
    assert!(
        (shown * 1e-9 - want).abs() <= 1e-5 * want,
        "{shown} nm against {want} m"
    );
}

/// `chart.csv` under a probe has its lengths in m, each row in its cell's length unit: along a
/// free-amplitude axis A0 (the length unit g0) changes from cell to cell (issue 42: the column
/// was in g0, a different length per row); the JSON cells stay in g0 with the axis value.
#[test]
fn chart_csv_lengths_are_in_metres_under_a_probe() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let doc = json(&[
        "chart",
        "--probe",
        "examples/probe-point-mass-dmt.toml",
        "--x",
        "free-amplitude",
        "--x-from",
        "8nm",
        "--x-to",
        "12nm",
        "--x-steps",
        "2",
        "--y",
        "sample-modulus",
        "--y-from",
        "2e9",
        "--y-to",
        "2e9",
        "--y-steps",
        "1",
        "--starts",
        "1",
        "--lyapunov-periods",
        "0",
        "--max-periods",
        "6000",
        "--json",
        "--out",
        out,
    ]);
    // (text columns, status and origin, read as NaN)
    let text = std::fs::read_to_string(dir.path().join("chart.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (ix, x_max, v_t_min) = (col("ix"), col("x_max"), col("v_t_min"));
    let a0 = [8e-9, 12e-9];
    for r in &rows {
        let i = r[ix] as usize;
        let cell = doc["cells"]
            .as_array()
            .unwrap()
            .iter()
            .find(|c| c["ix"] == i)
            .unwrap();
        let g0 = cell["attractors"][0]["x_max"].as_f64().unwrap();
        assert!(
            (r[x_max] - g0 * a0[i]).abs() <= 1e-12 * r[x_max].abs(),
            "{r:?}"
        );
        let v = cell["attractors"][0]["v_t_min"].as_f64().unwrap();
        assert!((r[v_t_min] - v * a0[i]).abs() <= 1e-12 * r[v_t_min].abs().max(1e-30));
        // a tapping amplitude, nanometres
        assert!((1e-9..1e-7).contains(&r[x_max]), "{r:?}");
    }
    assert_eq!(rows.len(), 2);
}
