//! Helpers of the command line's test files: the binary run in the repository's root.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository's root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `afmdyn ARGS` run in the repository's root.
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .current_dir(repo())
        .output()
        .expect("runs")
}

/// The JSON document `afmdyn ARGS` prints (it must succeed).
pub fn json(args: &[&str]) -> serde_json::Value {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("json")
}

/// The text `afmdyn ARGS` prints (it must succeed).
pub fn text(args: &[&str]) -> String {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// The numbers of `doc[block][k]` (an array of a curve document).
pub fn column(doc: &serde_json::Value, block: &str, k: &str) -> Vec<f64> {
    doc[block][k]
        .as_array()
        .unwrap_or_else(|| panic!("{block}.{k}"))
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect()
}

/// `afmdyn ARGS` must fail with exit 2 and one stderr line holding every `needles`.
pub fn refused(args: &[&str], needles: &[&str]) {
    let out = run(args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {err}");
    assert_eq!(err.trim().lines().count(), 1, "{args:?}: {err}");
    for n in needles {
        assert!(err.contains(n), "{args:?}: {n:?} not in {err}");
    }
}

/// A flat sample map of 1 µm × 1 µm (no height map, one material) written in `dir`: the
/// `--sample` of an image test that is about the probe, not the topography.
pub fn flat_sample(dir: &Path) -> PathBuf {
    let sample = dir.join("flat.toml");
    std::fs::write(&sample, "size = [1.0e-6, 1.0e-6]\n").unwrap();
    sample
}
