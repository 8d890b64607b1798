//! Limits and files, end to end (issue 9): extreme inputs fail at once, long runs stream or are
//! refused with their size, resume only the same run, a locked output directory, usable
//! outputs, readable errors.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn command(args: &[&str], cwd: &Path) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_afmdyn"));
    c.args(args).current_dir(cwd);
    c
}

/// Wait for `child` at most `secs` seconds, reading its output meanwhile: a hang fails.
fn wait_within(mut child: Child, secs: u64, what: &str) -> Output {
    let mut out = child.stdout.take().expect("piped");
    let mut err = child.stderr.take().expect("piped");
    let t_out = std::thread::spawn(move || {
        let mut b = Vec::new();
        out.read_to_end(&mut b).ok();
        b
    });
    let t_err = std::thread::spawn(move || {
        let mut b = Vec::new();
        err.read_to_end(&mut b).ok();
        b
    });
    let deadline = Instant::now() + Duration::from_secs(secs);
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > deadline {
            child.kill().ok();
            panic!("{what}: no answer within {secs} s (a hang)");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Output {
        status,
        stdout: t_out.join().unwrap(),
        stderr: t_err.join().unwrap(),
    }
}

fn run_in(args: &[&str], cwd: &Path, secs: u64) -> Output {
    let child = command(args, cwd)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run afmdyn");
    wait_within(child, secs, &format!("afmdyn {args:?}"))
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).to_string()
}

/// Exit 2, one line naming `needle`, nothing on stdout.
fn refused(o: &Output, args: &[&str], needle: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{args:?}: one line: {err}"
    );
    assert!(
        err.contains(needle),
        "{args:?}: '{err}' should name '{needle}'"
    );
    assert!(o.stdout.is_empty(), "{args:?}");
}

fn json(o: &Output) -> serde_json::Value {
    assert!(o.status.success(), "{}", stderr(o));
    serde_json::from_slice(&o.stdout).expect("one JSON document")
}

/// A finished run (exit 0) whose JSON `warnings` and stderr carry `needle`.
fn warns(o: &Output, needle: &str) -> serde_json::Value {
    let doc = json(o);
    let w = doc["warnings"].as_array().expect("warnings");
    assert!(
        w.iter().any(|x| x.as_str().unwrap().contains(needle)),
        "{doc}"
    );
    assert!(stderr(o).contains("afmdyn: warning: ") && stderr(o).contains(needle));
    doc
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn extreme_inputs_fail_at_once_with_one_line_naming_the_field() {
    // the panics (101), aborts (134), endless loops and silent wrong answers
    let dir = tempfile::tempdir().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["simulate", "--periods", "2", "--alpha4", "1e300"],
            "alpha4",
        ),
        (
            &["simulate", "--periods", "2", "--alpha1", "1e300"],
            "alpha1",
        ),
        (&["bifurcation", "--steps", "18446744073709551615"], "steps"),
        (&["bifurcation", "--steps", "100000000"], "steps"),
        (
            &["bifurcation", "--steps", "1000", "--starts", "4000"],
            "sweep points",
        ),
        (&["simulate", "--periods", "2", "--omega", "1e-9"], "omega"),
        (&["simulate", "--periods", "2", "--omega", "1e-5"], "omega"),
        (&["simulate", "--periods", "2", "--omega", "1e9"], "omega"),
        (
            &["simulate", "--periods", "2", "--alpha2", "1e300"],
            "alpha2",
        ),
        (
            &["simulate", "--periods", "2", "--alpha3", "1e300"],
            "alpha3",
        ),
        (&["simulate", "--periods", "2", "--gap", "-1e300"], "alpha5"),
        (
            &[
                "simulate",
                "--periods",
                "2",
                "--initial-modal",
                "1e300,0,0;0,0,0",
            ],
            "--initial-modal",
        ),
        (&["modes", "--alpha4", "1e308", "--json"], "alpha4"),
        (
            &[
                "simulate",
                "--periods",
                "2",
                "--omega",
                "1e-3",
                "--modes",
                "20",
            ],
            "exceeds the budget of 128 MiB",
        ),
        (
            &["simulate", "--omega", "1e-3", "--integrator", "adaptive"],
            "budget",
        ),
        (&["bifurcation", "--threads", "1000000"], "threads"),
        (&["attractors", "--samples", "100000000"], "samples"),
        (
            &["lyapunov", "--periods", "18446744073709551615"],
            "periods",
        ),
        (
            &["converge", "--periods", "18446744073709551615"],
            "periods",
        ),
        (
            &["bifurcation", "--max-periods", "18446744073709551615"],
            "max-periods",
        ),
    ];
    for (args, needle) in cases {
        let o = run_in(args, dir.path(), 10);
        refused(&o, args, needle);
    }
}

#[test]
fn long_simulations_are_refused_up_front_with_their_size() {
    let dir = tempfile::tempdir().unwrap();
    // 1e9 periods grew memory without bound and wrote nothing
    let o = run_in(&["simulate", "--periods", "1e9"], dir.path(), 10);
    refused(&o, &["--periods 1e9"], "1e8");
    let o = run_in(&["simulate", "--periods", "1e6"], dir.path(), 10);
    refused(&o, &["--periods 1e6"], "GB");
    assert!(stderr(&o).contains("--files none"), "{}", stderr(&o));
    assert!(!dir.path().join("afmdyn-out").exists(), "nothing written");
}

#[test]
fn a_chunked_simulation_equals_one_held_in_memory() {
    // the run is streamed in chunks of periods; the files do not depend on the chunk size
    let dir = tempfile::tempdir().unwrap();
    let go = |out: &Path, extra: &[&str]| {
        let mut a = vec![
            "simulate",
            "--periods",
            "7",
            "--transient",
            "2.5",
            "--samples-per-period",
            "50",
            "--files",
            "data",
            "--csv",
            "--energy-balance",
            "--json",
            "--out",
            s(out),
        ];
        a.extend_from_slice(extra);
        json(&run_in(&a, dir.path(), 30))
    };
    let (one, many) = (dir.path().join("one"), dir.path().join("many"));
    let d1 = go(&one, &[]);
    let d2 = go(&many, &["--chunk-periods", "1"]);
    assert_eq!(d1["switchings"], d2["switchings"]);
    assert_eq!(d1["poincare_points"], d2["poincare_points"]);
    let w = |d: &serde_json::Value| d["final"]["w_tip"].as_f64().unwrap();
    assert!((w(&d1) - w(&d2)).abs() < 1e-10);
    for file in ["timeseries.csv", "poincare.csv", "energy.csv", "events.csv"] {
        let read = |d: &Path| -> Vec<Vec<f64>> {
            std::fs::read_to_string(d.join(file))
                .unwrap()
                .lines()
                .skip(1)
                .map(|l| l.split(',').filter_map(|c| c.parse().ok()).collect())
                .collect()
        };
        let (a, b) = (read(&one), read(&many));
        assert_eq!(a.len(), b.len(), "{file}: same rows");
        for (ra, rb) in a.iter().zip(&b) {
            for (x, y) in ra.iter().zip(rb) {
                assert!(
                    (x - y).abs() <= 1e-9 * (1.0 + x.abs()),
                    "{file}: {ra:?} vs {rb:?}"
                );
            }
        }
    }
    let rows = std::fs::read_to_string(one.join("timeseries.csv"))
        .unwrap()
        .lines()
        .count();
    assert_eq!(rows, 1 + 7 * 50 + 1);
}

#[test]
fn files_none_data_all_and_a_self_describing_npy() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("all");
    let doc = json(&run_in(
        &["simulate", "--periods", "3", "--json", "--out", s(&out)],
        dir.path(),
        30,
    ));
    assert_eq!(doc["files"], "all");
    assert!(!out.join("timeseries.csv").exists(), "CSV only on request");
    for f in [
        "timeseries.npy",
        "timeseries.npy.json",
        "tip.png",
        "tip.svg",
        "spectrum.csv",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let header: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("timeseries.npy.json")).unwrap())
            .unwrap();
    let names: Vec<&str> = header["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(
        names.join(","),
        "tau,v_t,w_tip,w_tip_dot,in_contact,contact_force,a_1,a_2,a_3,a_dot_1,a_dot_2,a_dot_3"
    );
    assert!(header["columns"]
        .as_array()
        .unwrap()
        .iter()
        .all(|c| !c["unit"].as_str().unwrap().is_empty()));
    let bytes = std::fs::read(out.join("timeseries.npy")).unwrap();
    let npy = npyz::NpyFile::new(&bytes[..]).unwrap();
    assert_eq!(npy.shape(), &[3 * 200 + 1, 12]);
    assert_eq!(header["shape"], serde_json::json!([601, 12]));
    let data: Vec<f64> = npy.into_vec().unwrap();
    assert!(data
        .chunks(12)
        .map(|r| r[0])
        .collect::<Vec<_>>()
        .windows(2)
        .all(|w| w[0] < w[1]));

    let data_dir = dir.path().join("data");
    json(&run_in(
        &[
            "simulate",
            "--periods",
            "2",
            "--files",
            "data",
            "--json",
            "--out",
            s(&data_dir),
        ],
        dir.path(),
        30,
    ));
    assert!(data_dir.join("timeseries.npy").exists());
    assert!(std::fs::read_dir(&data_dir).unwrap().all(|e| {
        let n = e.unwrap().file_name().to_string_lossy().to_string();
        !n.ends_with(".png") && !n.ends_with(".svg")
    }));

    let none = dir.path().join("none");
    let doc = json(&run_in(
        &[
            "simulate",
            "--periods",
            "2",
            "--files",
            "none",
            "--json",
            "--out",
            s(&none),
        ],
        dir.path(),
        30,
    ));
    assert!(!none.exists(), "--files none writes nothing");
    assert!(doc["switchings"].as_u64().unwrap() > 0);
}

#[test]
fn plots_of_long_runs_are_decimated() {
    // 120 001 samples: every point in the SVG polylines made tip.svg 66 MB at 20 000 periods
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("long");
    json(&run_in(
        &[
            "simulate",
            "--periods",
            "300",
            "--samples-per-period",
            "400",
            "--json",
            "--out",
            s(&out),
        ],
        dir.path(),
        60,
    ));
    let size = |f: &str| std::fs::metadata(out.join(f)).unwrap().len();
    assert!(
        size("tip.svg") < 200_000,
        "tip.svg {} bytes",
        size("tip.svg")
    );
    assert!(
        size("spectrum.svg") < 200_000,
        "spectrum.svg {}",
        size("spectrum.svg")
    );
    assert!(
        size("phase.svg") < 1_500_000,
        "phase.svg {}",
        size("phase.svg")
    );
    assert!(size("tip.png") < 1_000_000);
}

#[test]
fn an_inaccurate_run_carries_a_warning() {
    // the paper's RK4 choosing the region per stage, at a coarse step: the per-period energy
    // balance fails; the summary says so (stderr and the JSON's warnings)
    let dir = tempfile::tempdir().unwrap();
    let o = run_in(
        &[
            "simulate",
            "--periods",
            "4",
            "--integrator",
            "rk4-naive",
            "--steps-per-period",
            "60",
            "--energy-balance",
            "--files",
            "none",
            "--json",
        ],
        dir.path(),
        30,
    );
    let doc = warns(&o, "energy balance");
    assert!(doc["energy_residual"]["max_relative"].as_f64().unwrap() > 1e-6);
}

fn wait_for(path: &Path, what: impl Fn(&str) -> bool) {
    let deadline = Instant::now() + Duration::from_secs(20);
    while !std::fs::read_to_string(path)
        .map(|t| what(&t))
        .unwrap_or(false)
    {
        assert!(Instant::now() < deadline, "waited for {}", path.display());
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_second_run_on_a_locked_directory_fails_at_once_and_a_killed_run_leaves_no_lock() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("shared");
    let holder = command(
        &[
            "simulate",
            "--periods",
            "1e7",
            "--samples-per-period",
            "1",
            "--files",
            "data",
            "--out",
            s(&out),
        ],
        dir.path(),
    )
    .stdout(Stdio::null())
    .stderr(Stdio::null())
    .spawn()
    .unwrap();
    let pid = holder.id().to_string();
    let mut holder = holder;
    wait_for(&out.join(".afmdyn.lock"), |t| t.starts_with(&pid));
    let t = Instant::now();
    let args = ["bifurcation", "--steps", "3", "--out", s(&out)];
    let o = run_in(&args, dir.path(), 10);
    refused(&o, &args, s(&out));
    assert!(stderr(&o).contains(&pid) && stderr(&o).contains("in use"));
    assert!(t.elapsed() < Duration::from_secs(5), "at once");
    assert!(!out.join("bifurcation.csv").exists());
    // kill the holder: the kernel drops its lock, the next run goes ahead
    holder.kill().unwrap();
    holder.wait().unwrap();
    json(&run_in(
        &["simulate", "--periods", "1", "--json", "--out", s(&out)],
        dir.path(),
        30,
    ));
}

/// A small sweep; a flag in `extra` replaces the default value of the same flag.
fn sweep(out: &Path, extra: &[&str], cwd: &Path) -> Output {
    let defaults = [
        ("--from", "2.4"),
        ("--to", "2.9"),
        ("--steps", "12"),
        ("--max-periods", "300"),
    ];
    let mut a = vec!["bifurcation", "--out", s(out)];
    for (flag, value) in defaults {
        if !extra.contains(&flag) {
            a.extend([flag, value]);
        }
    }
    a.extend_from_slice(extra);
    run_in(&a, cwd, 60)
}

#[test]
fn resume_refuses_a_run_made_with_other_arguments() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let killed = sweep(&out, &["--abort-after", "5"], dir.path());
    assert!(!killed.status.success());
    let partial = out.join(".bifurcation.partial.csv");
    let before = std::fs::read_to_string(&partial).unwrap();
    for (extra, needle) in [
        (
            &["--resume", "--steps", "400"][..],
            "--resume: steps = 12 in the interrupted run, 400 now;",
        ),
        (
            &["--resume", "--alpha4", "30"][..],
            "--resume: alpha4 = 20.0 in the interrupted run, 30.0 now;",
        ),
        (
            &["--resume", "--starts", "1"][..],
            "--resume: starts = 0 in the interrupted run, 1 now;",
        ),
        (
            &["--resume", "--max-periods", "200"][..],
            "--resume: max-periods = 300 in the interrupted run, 200 now;",
        ),
    ] {
        let o = sweep(&out, extra, dir.path());
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(
            err.contains(needle) && err.contains("--resume"),
            "{extra:?}: {err}"
        );
        assert_eq!(
            std::fs::read_to_string(&partial).unwrap(),
            before,
            "untouched"
        );
    }
    // the same arguments complete it; a finished sweep is not resumed with others either
    assert!(sweep(&out, &["--resume"], dir.path()).status.success());
    let o = sweep(&out, &["--resume", "--to", "3.0"], dir.path());
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("to = 2.9 in the interrupted run, 3.0 now"),
        "{}",
        stderr(&o)
    );
    assert!(sweep(&out, &["--resume"], dir.path()).status.success());
    // results without a record of their arguments are not resumed
    std::fs::remove_file(out.join(".bifurcation.run.json")).unwrap();
    let o = sweep(&out, &["--resume"], dir.path());
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("no record"), "{}", stderr(&o));
}

#[test]
fn sweep_outputs_are_identical_across_runs_and_in_a_stable_order() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    for out in [&a, &b] {
        let o = sweep(out, &["--starts", "2", "--threads", "2"], dir.path());
        assert!(o.status.success(), "{}", stderr(&o));
    }
    for f in [
        "bifurcation.csv",
        "bifurcation.npy",
        "bifurcation.png",
        "bifurcation.svg",
    ] {
        assert!(
            std::fs::read(a.join(f)).unwrap() == std::fs::read(b.join(f)).unwrap(),
            "{f} differs between two identical runs"
        );
    }
    // rows by value index, then forward, backward, start-0, start-1
    let text = std::fs::read_to_string(a.join("bifurcation.csv")).unwrap();
    let keys: Vec<(usize, String)> = text
        .lines()
        .skip(1)
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[2].parse().unwrap(), c[3].to_string())
        })
        .collect();
    let rank = |b: &str| match b {
        "forward" => 0,
        "backward" => 1,
        s => 2 + s.trim_start_matches("start-").parse::<usize>().unwrap(),
    };
    assert!(keys
        .windows(2)
        .all(|w| (w[0].0, rank(&w[0].1)) <= (w[1].0, rank(&w[1].1))));
    assert_eq!(keys[0], (0, "forward".to_string()));
}

#[test]
fn branches_plot_names_only_the_branches_it_has_and_legends_sit_outside_the_data() {
    let dir = tempfile::tempdir().unwrap();
    let (plain, starts) = (dir.path().join("plain"), dir.path().join("starts"));
    assert!(sweep(&plain, &[], dir.path()).status.success());
    assert!(sweep(&starts, &["--starts", "1"], dir.path())
        .status
        .success());
    let svg = |d: &Path, f: &str| std::fs::read_to_string(d.join(f)).unwrap();
    assert!(!svg(&plain, "bifurcation-branches.svg").contains("random starts"));
    assert!(svg(&starts, "bifurcation-branches.svg").contains("random starts"));
    // the legend text lies right of every grid line of the data area
    let text = svg(&plain, "bifurcation.svg");
    let attr = |tag: &str, name: &str| -> f64 {
        let k = tag.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        tag[k..].split('"').next().unwrap().parse().unwrap()
    };
    let right = text
        .split("<line")
        .skip(1)
        .map(|t| attr(t, "x1").max(attr(t, "x2")))
        .fold(0.0, f64::max);
    let legend = text
        .split("<text")
        .skip(1)
        .find(|t| {
            t.split('>')
                .nth(1)
                .is_some_and(|c| c.trim().starts_with("nonperiodic"))
        })
        .expect("legend entry");
    assert!(
        attr(legend, "x") > right,
        "legend at {} inside {right}",
        attr(legend, "x")
    );
}

#[test]
fn io_errors_name_their_path() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let out = file.join("sub");
    let o = run_in(
        &["simulate", "--periods", "1", "--out", s(&out)],
        dir.path(),
        30,
    );
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains(s(&out)), "{}", stderr(&o));
    assert_eq!(stderr(&o).trim_end().lines().count(), 1);
}

#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_reads_as_one_line_naming_the_file() {
    // a file-size limit (with SIGXFSZ ignored) fails writes like a full disk does
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("full");
    let o = wait_within(
        Command::new("sh")
            .args([
                "-c",
                "trap '' XFSZ; ulimit -f 64; exec \"$0\" \"$@\"",
                env!("CARGO_BIN_EXE_afmdyn"),
                "simulate",
                "--periods",
                "40",
                "--out",
                s(&out),
            ])
            .current_dir(dir.path())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap(),
        30,
        "simulate on a full disk",
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains(s(&out)) && err.contains("File too large"),
        "{err}"
    );
    assert!(
        !err.contains("Os {") && !err.contains("kind:"),
        "no debug dump: {err}"
    );
}

#[test]
fn continue_checks_its_overlay_before_computing() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.csv");
    let t = Instant::now();
    let args = ["continue", "--overlay", s(&missing)];
    let o = run_in(&args, dir.path(), 20);
    refused(&o, &args, s(&missing));
    assert!(
        t.elapsed() < Duration::from_secs(3),
        "before the branch is computed"
    );
    let not_csv = dir.path().join("other.csv");
    std::fs::write(&not_csv, "a,b\n1,2\n").unwrap();
    let args = ["continue", "--overlay", s(&not_csv)];
    refused(&run_in(&args, dir.path(), 20), &args, "bifurcation.csv");
}

#[test]
fn continue_ends_a_switched_branch_at_the_period_doubling_it_returns_to() {
    // the period-2 window between the period doublings at Ω ≈ 1.887 and 1.700: the switched
    // branch used to run through the junction at 1.700 (labelled "Fold") and list every event
    // of the window twice
    let dir = tempfile::tempdir().unwrap();
    let doc = json(&run_in(
        &[
            "continue",
            "--from",
            "1.95",
            "--to",
            "1.65",
            "--switch",
            "--json",
            "--out",
            s(&dir.path().join("c")),
        ],
        dir.path(),
        60,
    ));
    let events: Vec<(String, u64, f64)> = doc["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| {
            (
                e["event"].as_str().unwrap().to_string(),
                e["period"].as_u64().unwrap(),
                e["value"].as_f64().unwrap(),
            )
        })
        .collect();
    for (i, a) in events.iter().enumerate() {
        for b in &events[i + 1..] {
            assert!(
                !(a.0 == b.0 && a.1 == b.1 && (a.2 - b.2).abs() < 1e-4),
                "listed twice: {a:?}"
            );
        }
    }
    let pd1: Vec<f64> = events
        .iter()
        .filter(|e| e.0 == "period-doubling" && e.1 == 1)
        .map(|e| e.2)
        .collect();
    assert!(pd1.iter().any(|v| (v - 1.7).abs() < 1e-3), "{events:?}");
    assert!(
        !events
            .iter()
            .any(|e| e.0 == "fold" && e.1 == 2 && pd1.iter().any(|v| (v - e.2).abs() < 1e-3)),
        "the junction with the period-1 branch is not a fold: {events:?}"
    );
    assert!(events
        .iter()
        .any(|e| e.0 == "period-doubling" && e.1 == 2 && (e.2 - 1.7).abs() < 1e-3));
}

#[test]
fn a_short_lyapunov_run_says_it_is_too_short() {
    let dir = tempfile::tempdir().unwrap();
    let o = run_in(
        &[
            "lyapunov",
            "--periods",
            "3",
            "--blocks",
            "3",
            "--transient",
            "0",
            "--json",
        ],
        dir.path(),
        30,
    );
    warns(&o, "only 3 periods");
}

/// Write the fuzz test's config file.
fn config(dir: &Path, text: &str) -> PathBuf {
    let p = dir.join("fuzz.toml");
    std::fs::write(&p, text).unwrap();
    p
}

mod fuzz {
    use super::*;
    use proptest::prelude::*;

    fn number() -> impl Strategy<Value = String> {
        prop_oneof![
            (-330.0..330.0f64, any::<bool>()).prop_map(|(e, neg)| {
                format!("{}{:e}", if neg { "-" } else { "" }, 10f64.powf(e))
            }),
            (-10.0..10.0f64).prop_map(|v| v.to_string()),
            prop::sample::select(vec![
                "0",
                "-0",
                "nan",
                "inf",
                "-inf",
                "1e308",
                "1e-320",
                "",
                "x",
                "1,2",
                "0x10",
                "18446744073709551616",
                "1e",
            ])
            .prop_map(String::from),
        ]
    }

    /// A value inside the allowed range of `flag` (log-spread over the decades).
    fn valid(flag: &'static str) -> BoxedStrategy<String> {
        let max: f64 = match flag {
            "--modes" => return (1usize..=20).prop_map(|n| n.to_string()).boxed(),
            "--alpha1" | "--alpha3" | "--alpha6" => 1e4,
            "--alpha2" | "--alpha5" => 1e6,
            "--contact-stiffness" => 1e8,
            "--omega" => {
                return (-3.0..=5.0f64)
                    .prop_map(|e| format!("{:e}", 10f64.powf(e).clamp(1e-3, 1e5)))
                    .boxed()
            }
            _ => return (0.0..1.0f64).prop_map(|x| x.to_string()).boxed(),
        };
        let negative = flag == "--alpha5";
        (-6.0..=max.log10(), any::<bool>())
            .prop_map(move |(e, neg)| {
                let v = 10f64.powf(e).min(max);
                format!("{}{v:e}", if negative && neg { "-" } else { "" })
            })
            .boxed()
    }

    fn flag_value() -> impl Strategy<Value = (&'static str, String)> {
        prop::sample::select(vec![
            "--modes",
            "--alpha1",
            "--alpha2",
            "--alpha3",
            "--contact-stiffness",
            "--alpha5",
            "--alpha6",
            "--omega",
            "--transient",
            "--periods",
        ])
        .prop_flat_map(|f| (Just(f), prop_oneof![3 => valid(f), 1 => number()]))
    }

    const KEYS: [&str; 10] = [
        "modes",
        "alpha1",
        "drive_amplitude",
        "beam_damping",
        "alpha4",
        "gap",
        "contact_damping",
        "omega",
        "tip_mass_ratio",
        "bogus",
    ];

    fn toml_text() -> impl Strategy<Value = String> {
        proptest::collection::vec(
            (prop::sample::select(KEYS.to_vec()), number(), 0..4u8),
            0..5,
        )
        .prop_map(|lines| {
            lines
                .into_iter()
                .map(|(k, v, form)| match form {
                    0 => format!("{k} = {v}"),
                    1 => format!("{k} = \"{v}\""),
                    2 => format!("[{k}]"),
                    _ => format!("{k} = {v} = {v}"),
                })
                .collect::<Vec<_>>()
                .join("\n")
        })
    }

    fn modal() -> impl Strategy<Value = String> {
        let entry = || {
            prop_oneof![
                3 => (-8.0..12.0f64, any::<bool>())
                    .prop_map(|(e, neg)| format!("{}{:e}", if neg { "-" } else { "" }, 10f64.powf(e))),
                1 => number(),
            ]
        };
        prop_oneof![
            // three modes (the default N), mostly in range
            2 => (proptest::collection::vec(entry(), 3), proptest::collection::vec(entry(), 3))
                .prop_map(|(a, b)| format!("{};{}", a.join(","), b.join(","))),
            1 => (
                proptest::collection::vec(number(), 0..5),
                proptest::collection::vec(number(), 0..5),
                any::<bool>(),
            )
                .prop_map(|(a, b, semi)| {
                    format!("{}{}{}", a.join(","), if semi { ";" } else { "" }, b.join(","))
                }),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, .. ProptestConfig::default() })]

        /// Parameters, a TOML config and --initial-modal from anywhere: the binary answers in
        /// bounded time with a finite result (exit 0), bad input (exit 2) or a computation's
        /// own one-line failure (exit 1: diverged, chattering); never a panic or an abort.
        #[test]
        fn any_input_gives_an_answer_in_bounded_time(
            flags in proptest::collection::vec(flag_value(), 0..5),
            cfg in proptest::option::weighted(0.3, toml_text()),
            start in proptest::option::weighted(0.4, modal()),
        ) {
            let dir = tempfile::tempdir().unwrap();
            let mut args: Vec<String> = vec![
                "simulate".into(), "--files".into(), "none".into(), "--json".into(),
                "--samples-per-period".into(), "8".into(),
            ];
            let mut periods = false;
            let mut seen = std::collections::HashSet::new();
            for (f, v) in flags.iter().filter(|(f, _)| seen.insert(*f)) {
                // bounded work: the run length is fuzzed below one period
                let v = if *f == "--periods" || *f == "--transient" {
                    periods |= *f == "--periods";
                    match v.parse::<f64>() {
                        Ok(x) if x.is_finite() => format!("{}", x.abs().fract()),
                        _ => v.clone(),
                    }
                } else {
                    v.clone()
                };
                args.push(format!("{f}={v}"));
            }
            if !periods {
                args.push("--periods=0.5".into());
            }
            if let Some(text) = &cfg {
                args.push("--config".into());
                args.push(s(&config(dir.path(), text)).to_string());
            }
            if let Some(m) = &start {
                args.push(format!("--initial-modal={m}"));
            }
            let a: Vec<&str> = args.iter().map(String::as_str).collect();
            let o = run_in(&a, dir.path(), 60);
            let err = stderr(&o);
            prop_assert!(!err.contains("panicked"), "{a:?}: {err}");
            match o.status.code() {
                Some(0) => {
                    let doc: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
                    for k in ["w_tip", "w_tip_dot", "v_t"] {
                        prop_assert!(doc["final"][k].as_f64().is_some_and(f64::is_finite), "{a:?}: {doc}");
                    }
                }
                Some(1) | Some(2) => {
                    prop_assert_eq!(err.trim_end().lines().count(), 1, "{:?}: {}", a, err);
                    prop_assert!(err.starts_with("afmdyn: "), "{a:?}: {err}");
                    prop_assert!(o.stdout.is_empty());
                }
                c => prop_assert!(false, "{a:?}: exit {c:?}: {err}"),
            }
        }
    }
}
