//! Ctrl-C on the command line (issue 77 item 2): every request kind of the library's registry
//! ([`afmdyn::request::named::NAMES`]) started by its subcommand at a size that runs for
//! seconds (the long sizes of crates/afmdyn/tests/door.rs's `case()`), sent SIGINT 100 ms
//! later, ends within 1 s of the signal, as an interrupted run: `simulate` catches it, stops at
//! its next chunk, removes its partial files and exits 130; every other subcommand dies by the
//! default handler (its resumable store, where it keeps one, stays for `--resume`). Either
//! way the output directory is left unlocked (the kernel drops the advisory lock with the
//! process) and holds no final file, whole or partial.

#![cfg(unix)]

use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// How a request kind is run from the command line.
enum Case {
    /// `afmdyn ARGS` runs it for seconds; `out`: the subcommand takes `--out`. `{fit}`, `{fm}`,
    /// `{map}` and `{psd}` stand for the data files [`data_files`] writes.
    Long {
        args: &'static [&'static str],
        out: bool,
    },
    /// Too short to cancel (door.rs gives it no long size either).
    Short(&'static str),
    /// No subcommand runs it (Python and the browser only).
    NoSubcommand,
}

/// The case of every registry name; a name missing here fails
/// [`every_request_kind_has_its_interrupt_case`].
fn case(name: &str) -> Option<Case> {
    use Case::*;
    const DMT: &str = "examples/probe-point-mass-dmt.toml";
    Some(match name {
        "modes" => Short("modes"),
        "simulate" => Long {
            args: &["simulate", "--periods", "5e6", "--samples-per-period", "1"],
            out: true,
        },
        // (door.rs's size, 10 modes and 1 sample per period, ends within 0.4 s at the command
        // line's Ω = 4.1)
        "converge" => Long {
            args: &[
                "converge",
                "--max-modes",
                "20",
                "--periods",
                "10000",
                "--samples-per-period",
                "10",
            ],
            out: true,
        },
        "attractors" => Long {
            args: &["attractors", "--samples", "5000"],
            out: true,
        },
        "global_continuation" => Long {
            args: &[
                "attractors",
                "--sweep",
                "omega",
                "--from",
                "1.5",
                "--to",
                "3",
                "--samples",
                "64",
                "--steps",
                "400",
            ],
            out: true,
        },
        // an undamped lever far from the sample: the steady-state search runs to its cap
        "orbit" => Long {
            args: &[
                "orbit",
                "--beam-damping",
                "0",
                "--gap",
                "10",
                "--max-periods",
                "10000000",
            ],
            out: false,
        },
        // (3 modes without --switch end within 0.5 s)
        "continuation" => Long {
            args: &[
                "continue", "--from", "5.0", "--to", "0.05", "--switch", "--modes", "6",
            ],
            out: true,
        },
        "lyapunov" => Long {
            args: &["lyapunov", "--periods", "10000000", "--blocks", "10"],
            out: false,
        },
        "observe" => NoSubcommand,
        "approach" => Long {
            args: &["approach", "--points", "5000"],
            out: true,
        },
        "bimodal" => Long {
            args: &[
                "bimodal",
                "--probe",
                "examples/probe-bimodal.toml",
                "--points",
                "5000",
            ],
            out: true,
        },
        "resonance" => Long {
            args: &["resonance", "--points", "5000"],
            out: true,
        },
        "basins" => Long {
            args: &["basins", "--x-steps", "400", "--y-steps", "400"],
            out: true,
        },
        "fm" => Long {
            args: &["fm", "--probe", DMT, "--points", "100000"],
            out: true,
        },
        "reconstruct" => Long {
            args: &[
                "reconstruct",
                "--fm",
                "{fm}",
                "--spring-constant",
                "40",
                "--resonance-frequency",
                "300e3",
                "--amplitude",
                "1e-9",
                "--inversion",
                "exact",
            ],
            out: true,
        },
        // 2000 values of z_c from 18 nm in steps of 1 pm
        "peakforce" => Long {
            args: &[
                "peakforce",
                "--probe",
                "examples/probe-peakforce-amo-garcia.toml",
                "--sweep",
                "z_c",
                "--from",
                "18e-9",
                "--to",
                "16.001e-9",
                "--step",
                "1e-12",
            ],
            out: true,
        },
        "fit" => Long {
            args: &[
                "fit",
                "--probe",
                "examples/probe-fit-hertz.toml",
                "--data",
                "{fit}",
                "--profiles",
            ],
            out: true,
        },
        "fit_map" => Long {
            args: &[
                "fit-map",
                "--probe",
                "examples/probe-fit-hertz.toml",
                "--data",
                "{map}",
            ],
            out: true,
        },
        "thermal" => Long {
            args: &[
                "thermal",
                "--probe",
                "examples/probe-beam-dmt.toml",
                "--modes",
                "20",
                "--points",
                "1000000",
            ],
            out: true,
        },
        "calibrate" => Long {
            args: &[
                "calibrate",
                "--probe",
                "examples/probe-beam-dmt.toml",
                "--psd",
                "{psd}",
            ],
            out: true,
        },
        _ => return None,
    })
}

/// Every name of the registry has its case here, and the subcommand of every long case
/// exists: a new request kind cannot go untested.
#[test]
fn every_request_kind_has_its_interrupt_case() {
    let help = crate::common::text(&["--help"]);
    for name in afmdyn::request::named::NAMES {
        match case(name) {
            None => panic!("{name}: give it its case in tests/interrupt.rs's case()"),
            Some(Case::Long { args, .. }) => assert!(
                help.lines().any(|l| l.trim_start().starts_with(args[0])),
                "{name}: no subcommand {}",
                args[0]
            ),
            Some(Case::Short(cmd)) => {
                // it ends at once: there is nothing to interrupt
                let t = Instant::now();
                crate::common::text(&[cmd, "--json"]);
                assert!(t.elapsed() < Duration::from_secs(5), "{name}");
            }
            Some(Case::NoSubcommand) => assert!(
                !help.lines().any(|l| l.trim_start().starts_with(name)),
                "{name}: a subcommand runs it now; give it its long case"
            ),
        }
    }
}

/// The two data files of the cases, in `dir`: `fit.csv`, a quasi-static Hertz approach of a
/// million rows on the probe of examples/probe-fit-hertz.toml, and `fm.csv`, an evenly spaced
/// frequency-shift curve of a million distances from 0.3 to 10 nm (door.rs's `hertz_curve`
/// and `shift_curve`): each runs for seconds.
fn data_files(dir: &Path) {
    use std::fmt::Write;
    let rows = 1_000_000;
    let (k, r, e_star) = (0.05, 5e-6, 10e3 / 0.75);
    let (mut fit, mut fm) = (
        String::from("height,force\n"),
        String::from("distance,frequency_shift\n"),
    );
    for i in 0..rows {
        let x = 1e-6 - 2.5e-6 * i as f64 / (rows - 1) as f64;
        let f = 4.0 / 3.0 * e_star * f64::sqrt(r) * (-x).max(0.0).powf(1.5);
        writeln!(fit, "{:e},{:e}", x - f / k, f).unwrap();
        let d = 0.3e-9 + 9.7e-9 * i as f64 / (rows - 1) as f64;
        writeln!(fm, "{:e},{:e}", d, -10.0 * (1e-9 / d).powf(1.5)).unwrap();
    }
    std::fs::write(dir.join("fit.csv"), fit).unwrap();
    std::fs::write(dir.join("fm.csv"), fm).unwrap();
    // a force map of 50 × 50 such curves of 600 rows (a second of fitting)
    let mut map = String::from("x,y,height,force\n");
    for c in 0..2500 {
        for i in 0..600 {
            let x = 1e-6 - 2.5e-6 * i as f64 / 599.0;
            let f = 4.0 / 3.0 * e_star * f64::sqrt(r) * (-x).max(0.0).powf(1.5);
            writeln!(map, "{}e-6,{}e-6,{:e},{:e}", c % 50, c / 50, x - f / k, f).unwrap();
        }
    }
    std::fs::write(dir.join("map.csv"), map).unwrap();
    // a thermal spectrum of a million rows: the oscillator of Q = 2 at the beam's 300 kHz
    let mut psd = String::from("frequency,psd\n");
    for i in 0..rows {
        let f = 10e3 + 730e3 * i as f64 / rows as f64;
        let r = f / 300e3;
        let s = 1e-27 / ((1.0 - r * r).powi(2) + r * r / 4.0) + 1e-30;
        writeln!(psd, "{f:e},{s:e}").unwrap();
    }
    std::fs::write(dir.join("psd.csv"), psd).unwrap();
}

/// `afmdyn` with SIGINT at its default action in the child, whatever this process inherited
/// (a test run started in the background by a non-interactive shell ignores SIGINT, and the
/// commands it starts would too: Ctrl-C is then not theirs to answer).
fn afmdyn_command() -> Command {
    use std::os::unix::process::CommandExt;
    let mut command = Command::new(env!("CARGO_BIN_EXE_afmdyn"));
    // SAFETY: signal(2) is async-signal-safe, and runs in the child between fork and exec
    unsafe {
        command.pre_exec(|| {
            libc::signal(libc::SIGINT, libc::SIG_DFL);
            Ok(())
        });
    }
    command
}

/// SIGINT to `child`; the time just before it was sent (a latency from it includes the start
/// of `kill` itself: an upper bound).
fn interrupt(child: &Child) -> Instant {
    let before = Instant::now();
    let sent = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(sent.success(), "kill -INT {}", child.id());
    before
}

/// `child`'s exit status and how long after `sent` it ended (at most `limit`: then killed).
fn exit_after(child: &mut Child, sent: Instant, limit: Duration, what: &str) -> (ExitStatus, f64) {
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            return (status, sent.elapsed().as_secs_f64());
        }
        if sent.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            panic!("{what}: still running {limit:?} after SIGINT");
        }
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// What an interrupted run left in `out`: nothing wrong, or what is.
fn leftovers(out: &Path, name: &str) -> Vec<String> {
    let mut wrong = Vec::new();
    if !out.exists() {
        return wrong; // interrupted before it locked the directory
    }
    match afmdyn::request::DirLock::acquire(out) {
        Ok(_) => {}
        Err(e) => wrong.push(format!("{name}: the lock is still held: {e}")),
    }
    for entry in std::fs::read_dir(out).unwrap() {
        let file = entry.unwrap().file_name().into_string().unwrap();
        // the final files are written as `.NAME.partial.EXT` and renamed into place at the
        // end; a store's own files (`.curve.points.jsonl`, …) are dot files, and the
        // temporary siblings of those begin with two dots (`..curve.run.partial.json`)
        let final_file = !file.starts_with('.');
        let partial_final = file.contains(".partial") && !file.starts_with("..");
        if final_file || partial_final {
            wrong.push(format!("{name}: {file} left in {}", out.display()));
        }
    }
    wrong
}

/// Every request kind's subcommand at its long size, sent SIGINT 100 ms after it started:
/// it ends within 1 s of the signal, interrupted (`simulate`: exit 130 and its message;
/// any other: killed by the signal), its output directory unlocked and without final files.
#[test]
fn ctrl_c_ends_every_request_kind_within_a_second() {
    let dir = tempfile::tempdir().unwrap();
    data_files(dir.path());
    let (fit, fm) = (dir.path().join("fit.csv"), dir.path().join("fm.csv"));
    let map = dir.path().join("map.csv");
    let mut wrong = Vec::new();
    for name in afmdyn::request::named::NAMES {
        let Some(Case::Long { args, out }) = case(name) else {
            continue;
        };
        let mut args: Vec<String> = args
            .iter()
            .map(|a| match *a {
                "{fit}" => fit.display().to_string(),
                "{fm}" => fm.display().to_string(),
                "{map}" => map.display().to_string(),
                "{psd}" => dir.path().join("psd.csv").display().to_string(),
                a => a.to_string(),
            })
            .collect();
        let dest = dir.path().join(format!("out-{name}"));
        if out {
            args.extend(["--out".to_string(), dest.display().to_string()]);
        }
        let mut child = afmdyn_command()
            .args(&args)
            .current_dir(crate::common::repo())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run afmdyn");
        std::thread::sleep(Duration::from_millis(100));
        let sent = interrupt(&child);
        let (status, took) = exit_after(&mut child, sent, Duration::from_secs(30), name);
        let mut err = String::new();
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
        println!("{name}: ended {took:.3} s after SIGINT ({status})");
        if took > 1.0 {
            wrong.push(format!("{name}: ended {took:.2} s after SIGINT"));
        }
        let interrupted = if name == "simulate" {
            // (a signal before its handler is installed, at its start, kills it before it
            // created its directory)
            (status.code() == Some(130)
                && err.trim() == "afmdyn: interrupted; the partial files of this run were removed")
                || (status.signal() == Some(2) && !dest.exists())
        } else {
            status.signal() == Some(2)
        };
        if !interrupted {
            wrong.push(format!("{name}: {status}, not interrupted: {err}"));
        }
        wrong.extend(leftovers(&dest, name));
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// `simulate`, the subcommand that catches SIGINT, interrupted once it streams its series to
/// its partial files: it stops within 1 s, removes them and exits 130, leaving the directory
/// unlocked with its lock file alone.
#[test]
fn ctrl_c_stops_a_streaming_simulate_within_a_second() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sim");
    let mut child = afmdyn_command()
        .args(["simulate", "--periods", "5e6", "--samples-per-period", "1"])
        .arg("--out")
        .arg(&out)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run afmdyn");
    let started = Instant::now();
    let streaming = || {
        std::fs::read_dir(&out).is_ok_and(|d| {
            d.flatten()
                .any(|e| e.file_name().to_string_lossy().contains(".partial"))
        })
    };
    while !streaming() {
        assert!(
            started.elapsed() < Duration::from_secs(30),
            "simulate wrote no partial file within 30 s"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    std::thread::sleep(Duration::from_millis(100));
    let sent = interrupt(&child);
    let (status, took) = exit_after(&mut child, sent, Duration::from_secs(30), "simulate");
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    println!("simulate (streaming): ended {took:.3} s after SIGINT");
    assert_eq!(status.code(), Some(130), "{err}");
    assert!(took < 1.0, "ended {took:.2} s after SIGINT");
    let left: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(left, [".afmdyn.lock"]);
    assert!(leftovers(&out, "simulate").is_empty());
}
