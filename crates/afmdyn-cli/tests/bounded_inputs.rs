//! Every file a command line option names is read through the library's one bounded reader
//! (`afmdyn::io::input`, a cap per kind): `/dev/zero` (no end, no line end) and a 2 GiB sparse
//! file (a regular file larger than every cap, refused from its length) are refused with exit
//! code 2 and one line naming the option, the file and the cap, for `--probe`, `--config`,
//! `--overlay`, `--sample` and a sample map's `height_map` (CSV and NPY), `reconstruct
//! --fm` and `--am`, and `fit --data`; and a `--resume` whose store's ledger, rows or records are `/dev/zero` or
//! a 2 GiB sparse file is refused naming the file and the cap, the store left as it was. (How
//! long a refusal takes is measured by `scripts/bounded-inputs.sh`, not asserted: a loaded
//! machine would make such an assertion race.)

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .current_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .output()
        .expect("run afmdyn")
}

/// `args` exit 2 with one line on stderr mentioning every one of `needles`, and no stdout.
fn refused(args: &[&str], needles: &[&str]) {
    let out = afmdyn(args);
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{args:?}: one line: {err}"
    );
    for needle in needles {
        assert!(
            err.contains(needle),
            "{args:?}: '{err}' should mention '{needle}'"
        );
    }
    assert!(
        out.stdout.is_empty(),
        "{args:?}: no output presented as a result"
    );
}

/// A sparse file of 2 GiB (no blocks written) named `name` in `dir`.
fn sparse(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    let f = std::fs::File::create(&path).unwrap();
    f.set_len(2 << 30).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 2 << 30);
    path
}

/// `/dev/zero` under the name `name` in `dir` (a symbolic link: a height map's kind is its
/// extension).
fn zero(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    std::os::unix::fs::symlink("/dev/zero", &path).unwrap();
    path
}

const PROBE: &str = "examples/probe-point-mass-dmt.toml";
const TEXT_CAP: &str = "larger than 1048576 bytes";
const CSV_CAP: &str = "larger than 268435456 bytes";
const LINE_CAP: &str = "larger than 1048576 bytes in one line";

#[test]
fn probe_and_config_files_are_refused_past_their_cap() {
    let dir = tempfile::tempdir().unwrap();
    let big = sparse(dir.path(), "big.toml");
    for file in ["/dev/zero", big.to_str().unwrap()] {
        refused(
            &["modes", "--probe", file],
            &["--probe", file, TEXT_CAP, "a probe file"],
        );
        refused(
            &["modes", "--config", file],
            &["--config", file, TEXT_CAP, "a config file"],
        );
        refused(
            &["units", "--config", file],
            &["--config", file, TEXT_CAP, "a config file"],
        );
        refused(
            &["units", "--probe", file],
            &["probe", file, TEXT_CAP, "a probe file"],
        );
        refused(
            &[
                "image",
                "--probe",
                file,
                "--sample",
                "examples/sample-blend.toml",
                "--setpoint",
                "0.7",
            ],
            &["--probe", file, TEXT_CAP, "a probe file"],
        );
    }
}

#[test]
fn an_overlay_is_refused_past_its_cap_or_its_line_cap() {
    let dir = tempfile::tempdir().unwrap();
    let big = sparse(dir.path(), "big.csv");
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let continuation = |file: &str| {
        [
            "continue",
            "--from",
            "3",
            "--to",
            "2.9",
            "--overlay",
            file,
            "--out",
            o,
        ]
        .map(String::from)
    };
    let run = |file: &str, needles: &[&str]| {
        let args = continuation(file);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&args, needles);
    };
    run(
        "/dev/zero",
        &["--overlay", "/dev/zero", LINE_CAP, "an overlay CSV"],
    );
    let b = big.to_str().unwrap();
    run(b, &["--overlay", b, CSV_CAP, "an overlay CSV"]);
}

#[test]
fn a_sample_map_and_its_height_maps_are_refused_past_their_caps() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let image = |sample: &Path| {
        [
            "image",
            "--probe",
            PROBE,
            "--sample",
            sample.to_str().unwrap(),
            "--setpoint",
            "0.7",
        ]
        .map(String::from)
    };
    let run = |sample: &Path, needles: &[&str]| {
        let args = image(sample);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        refused(&args, needles);
    };
    for sample in [PathBuf::from("/dev/zero"), sparse(d, "big.toml")] {
        let s = sample.to_str().unwrap().to_string();
        run(&sample, &["--sample", &s, TEXT_CAP, "a sample map"]);
    }
    // the height map files beside a sample map: /dev/zero as CSV and as NPY, and sparse files
    // larger than the caps of both formats
    zero(d, "zero.csv");
    zero(d, "zero.npy");
    sparse(d, "big.csv");
    sparse(d, "big.npy");
    let cases = [
        (
            "zero.csv",
            "a line longer than 1048576 bytes: not a CSV height map",
        ),
        ("zero.npy", "not an NPY file"),
        ("big.csv", "larger than 536870912 bytes"),
        ("big.npy", "larger than 134283276 bytes"),
    ];
    for (file, needle) in cases {
        let sample = d.join(format!("{file}.toml"));
        std::fs::write(
            &sample,
            format!("size = [1e-6, 0]\nheight_map = \"{file}\"\n"),
        )
        .unwrap();
        run(&sample, &["--sample", "height_map", file, needle]);
    }
}

#[test]
fn reconstruct_curves_are_refused_past_their_caps() {
    let dir = tempfile::tempdir().unwrap();
    let big = sparse(dir.path(), "big.json");
    let b = big.to_str().unwrap();
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    // /dev/zero is not JSON (its first byte is 0), so --fm reads it as a CSV: its line cap
    refused(
        &["reconstruct", "--fm", "/dev/zero", "--out", o],
        &["--fm", "/dev/zero", LINE_CAP, "a curve CSV"],
    );
    refused(
        &["reconstruct", "--am", "/dev/zero", "--out", o],
        &["--am", "/dev/zero", "not a JSON document"],
    );
    for option in ["--fm", "--am"] {
        refused(
            &["reconstruct", option, b, "--out", o],
            &[option, b, CSV_CAP, "a curve document"],
        );
    }
}

#[test]
fn a_force_curve_to_fit_is_refused_past_its_caps() {
    let dir = tempfile::tempdir().unwrap();
    let big = sparse(dir.path(), "big.csv");
    let b = big.to_str().unwrap();
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    let fit = |data: &str| {
        [
            "fit",
            "--probe",
            "examples/probe-fit-hertz.toml",
            "--data",
            data,
            "--out",
            o,
        ]
        .map(String::from)
    };
    let args = fit("/dev/zero");
    refused(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        &["data", "/dev/zero", LINE_CAP, "a curve CSV"],
    );
    let args = fit(b);
    refused(
        &args.iter().map(String::as_str).collect::<Vec<_>>(),
        &["data", b, CSV_CAP],
    );
}

/// Every file of `dir` but its lock (which a run rewrites with its process id): name, and the
/// target of a symbolic link or the length and bytes of a small file (a sparse one by its
/// length alone).
fn snapshot(dir: &Path) -> Vec<(String, String)> {
    let mut files: Vec<(String, String)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| !p.ends_with(".afmdyn.lock"))
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            let meta = std::fs::symlink_metadata(&p).unwrap();
            let what = if meta.file_type().is_symlink() {
                format!("-> {}", std::fs::read_link(&p).unwrap().display())
            } else if meta.len() > 1 << 20 {
                format!("{} bytes", meta.len())
            } else if meta.is_dir() {
                "dir".to_string()
            } else {
                format!("{:?}", std::fs::read(&p).unwrap())
            };
            (name, what)
        })
        .collect();
    files.sort();
    files
}

/// Replace the store file `name` in `store` by /dev/zero and then by a 2 GiB sparse file: each
/// time `resume` (the run's arguments with `--resume`) exits 2 with one line naming the file
/// and `cap`, and leaves every file of the store as it was.
fn refused_resumes(store: &Path, name: &str, cap: &str, resume: &[&str]) {
    let path = store.join(name);
    let _ = std::fs::remove_file(&path);
    for sparse_file in [false, true] {
        if sparse_file {
            std::fs::remove_file(&path).unwrap();
            sparse(store, name);
        } else {
            zero(store, name);
        }
        let before = snapshot(store);
        let p = path.to_str().unwrap();
        refused(resume, &[p, cap]);
        assert_eq!(
            snapshot(store),
            before,
            "{p}: the refused resume changed the store"
        );
    }
    std::fs::remove_file(&path).unwrap();
}

const LEDGER_CAP: &str = "537919488 bytes";
const STORE_CAP: &str = "137438953472 bytes";

#[test]
fn a_sweeps_store_is_refused_past_its_caps_and_left_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("sweep");
    let s = store.to_str().unwrap();
    let args = [
        "bifurcation",
        "--from",
        "2.4",
        "--to",
        "2.9",
        "--steps",
        "2",
        "--starts",
        "0",
        "--max-periods",
        "100",
        "--threads",
        "1",
        "--out",
        s,
    ];
    let made = afmdyn(&args);
    assert!(made.status.success(), "{made:?}");
    let mut resume = args.to_vec();
    resume.push("--resume");
    // the finished rows, their ledger, and an unfinished sweep's rows
    let ledger = std::fs::read(store.join(".bifurcation.run.json")).unwrap();
    refused_resumes(&store, ".bifurcation.run.json", LEDGER_CAP, &resume);
    std::fs::write(store.join(".bifurcation.run.json"), &ledger).unwrap();
    let rows = std::fs::read(store.join("bifurcation.csv")).unwrap();
    refused_resumes(&store, "bifurcation.csv", STORE_CAP, &resume);
    std::fs::write(store.join("bifurcation.csv"), &rows).unwrap();
    refused_resumes(&store, ".bifurcation.partial.csv", STORE_CAP, &resume);
}

#[test]
fn a_studys_store_is_refused_past_its_caps_and_left_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let store = dir.path().join("chart");
    let s = store.to_str().unwrap();
    let args = [
        "chart",
        "--x-steps",
        "2",
        "--y-steps",
        "1",
        "--starts",
        "1",
        "--tile",
        "1",
        "--lyapunov-periods",
        "20",
        "--out",
        s,
    ];
    let made = afmdyn(&args);
    assert!(made.status.success(), "{made:?}");
    let mut resume = args.to_vec();
    resume.push("--resume");
    let ledger = std::fs::read(store.join(".chart.run.json")).unwrap();
    refused_resumes(&store, ".chart.run.json", LEDGER_CAP, &resume);
    std::fs::write(store.join(".chart.run.json"), &ledger).unwrap();
    refused_resumes(&store, ".chart.tiles.jsonl", STORE_CAP, &resume);
}
