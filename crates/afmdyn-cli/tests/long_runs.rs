//! Long runs (issue 42 §3): stale `.partial` files of a killed `simulate` are removed by the
//! next run on its directory.

use std::process::{Command, Output};

fn afmdyn(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_afmdyn"))
        .args(args)
        .output()
        .expect("run afmdyn")
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
