//! Long runs (issue 42 §3): a damaged checkpoint is refused naming its file and line, never
//! resumed into a corrupt result; stale `.partial` files of a killed `simulate` are removed by
//! the next run on its directory.

use std::path::Path;
use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .output()
        .expect("run afmdyn")
}

/// A refusal: exit 2, one line on stderr holding every needle, no result written.
fn refused(out: &Output, needles: &[&str]) {
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "one line: {err}");
    for n in needles {
        assert!(err.contains(n), "'{err}' should mention '{n}'");
    }
}

fn bifurcation(out: &Path, extra: &[&str]) -> Output {
    let mut a = vec![
        "bifurcation",
        "--from",
        "2.4",
        "--to",
        "2.9",
        "--steps",
        "6",
        "--starts",
        "1",
        "--max-periods",
        "300",
        "--threads",
        "1",
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend(extra);
    afmdyn(&a)
}

/// A sweep killed after 10 of its 18 points: its partial file's text.
fn killed_sweep(out: &Path) -> String {
    assert!(!bifurcation(out, &["--abort-after", "10"]).status.success());
    std::fs::read_to_string(out.join(".bifurcation.partial.csv")).unwrap()
}

/// The first digit of the `w_tip` cell (column 10) of data line `line` (1-based, the header
/// is line 1) changed to another digit.
fn change_a_digit(text: &str, line: usize) -> String {
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[line - 1].split(',').map(String::from).collect();
    let w = &mut cells[10];
    let at = w.find(|c: char| c.is_ascii_digit()).unwrap();
    let d = w.as_bytes()[at];
    let other = if d == b'7' { '3' } else { '7' };
    w.replace_range(at..=at, &other.to_string());
    lines[line - 1] = cells.join(",");
    lines.join("\n") + "\n"
}

#[test]
fn a_checkpoint_with_one_digit_changed_is_refused_naming_its_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = killed_sweep(dir.path());
    assert!(text.lines().count() > 5);
    let partial = dir.path().join(".bifurcation.partial.csv");
    std::fs::write(&partial, change_a_digit(&text, 4)).unwrap();
    let out = bifurcation(dir.path(), &["--resume"]);
    refused(&out, &[".bifurcation.partial.csv", "line 4", "checksum"]);
    assert!(!dir.path().join("bifurcation.csv").exists(), "no result");
    // the store is left as it was, for the user to look at; a run without --resume starts over
    assert_eq!(
        std::fs::read_to_string(&partial).unwrap(),
        change_a_digit(&text, 4)
    );
    assert!(bifurcation(dir.path(), &[]).status.success());
}

#[test]
fn a_checkpoint_without_its_header_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let text = killed_sweep(dir.path());
    let partial = dir.path().join(".bifurcation.partial.csv");
    let headless: String = text.lines().skip(1).map(|l| format!("{l}\n")).collect();
    std::fs::write(&partial, headless).unwrap();
    let out = bifurcation(dir.path(), &["--resume"]);
    refused(&out, &[".bifurcation.partial.csv", "line 1", "header"]);
    assert!(!dir.path().join("bifurcation.csv").exists(), "no result");
}

#[test]
fn a_checkpoint_written_by_an_earlier_version_is_refused_naming_the_plan() {
    // the layout before checksums: the CSV header and rows without the crc32 column
    let dir = tempfile::tempdir().unwrap();
    let text = killed_sweep(dir.path());
    let old: String = text
        .lines()
        .map(|l| format!("{}\n", &l[..l.rfind(',').unwrap()]))
        .collect();
    std::fs::write(dir.path().join(".bifurcation.partial.csv"), old).unwrap();
    let out = bifurcation(dir.path(), &["--resume"]);
    refused(
        &out,
        &[
            ".bifurcation.partial.csv",
            "written by an earlier version",
            "rerun without --resume",
        ],
    );
}

#[test]
fn an_undamaged_checkpoint_still_resumes_to_the_uninterrupted_rows() {
    let (full, cut) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    assert!(bifurcation(full.path(), &[]).status.success());
    killed_sweep(cut.path());
    let out = bifurcation(cut.path(), &["--resume"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let csv = |d: &Path| std::fs::read_to_string(d.join("bifurcation.csv")).unwrap();
    assert_eq!(csv(cut.path()), csv(full.path()));
    assert!(
        !csv(cut.path()).contains("crc32"),
        "the checksums stay in the checkpoint"
    );
}

const CHART: [&str; 14] = [
    "chart",
    "--x-steps",
    "4",
    "--y-steps",
    "2",
    "--starts",
    "2",
    "--tile",
    "2",
    "--lyapunov-periods",
    "50",
    "--threads",
    "1",
    "--json",
];

fn chart(out: &Path, extra: &[&str]) -> Output {
    let mut a: Vec<&str> = CHART.to_vec();
    a.extend(["--out", out.to_str().unwrap()]);
    a.extend(extra);
    afmdyn(&a)
}

#[test]
fn a_chart_store_with_one_digit_changed_is_refused_naming_its_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    assert!(!chart(dir.path(), &["--abort-after", "2"]).status.success());
    let tiles = dir.path().join(".chart.tiles.jsonl");
    let text = std::fs::read_to_string(&tiles).unwrap();
    assert_eq!(text.lines().count(), 2);
    // a digit of the second line's first x_max
    let second = text.find('\n').unwrap() + 1;
    let at = second + text[second..].find("\"x_max\":").unwrap() + "\"x_max\":".len();
    let at = at + text[at..].find(|c: char| c.is_ascii_digit()).unwrap();
    let mut bytes = text.into_bytes();
    bytes[at] = if bytes[at] == b'7' { b'3' } else { b'7' };
    std::fs::write(&tiles, &bytes).unwrap();
    let out = chart(dir.path(), &["--resume"]);
    refused(&out, &[".chart.tiles.jsonl", "line 2", "checksum"]);
    assert!(!dir.path().join("chart.csv").exists(), "no result");
}

#[test]
fn a_stale_partial_file_of_a_killed_simulate_is_removed_by_the_next_run() {
    // a double Ctrl-C exits at once and leaves the streams' `.partial` files
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path();
    let stale = [
        ".timeseries.partial.npy",
        ".timeseries.partial.csv",
        ".events.partial.csv",
        ".poincare.partial.csv",
        ".energy.partial.csv",
        ".spectrum.partial.csv",
    ];
    for name in stale {
        std::fs::write(out.join(name), vec![0u8; 4096]).unwrap();
    }
    // not a simulate output: kept (a bifurcation's checkpoint, a file of the user's)
    let others = [".bifurcation.partial.csv", ".notes.partial.txt"];
    for name in others {
        std::fs::write(out.join(name), "keep\n").unwrap();
    }
    let run = afmdyn(&[
        "simulate",
        "--periods",
        "3",
        "--transient",
        "1",
        "--files",
        "data",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    for name in stale {
        assert!(!out.join(name).exists(), "{name} is removed");
    }
    for name in others {
        assert_eq!(std::fs::read_to_string(out.join(name)).unwrap(), "keep\n");
    }
    assert!(out.join("timeseries.npy").exists());
}
