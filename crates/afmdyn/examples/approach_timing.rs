//! Cost of approach–retract curves (`afmdyn approach`), the figures quoted in the issue:
//!
//! ```sh
//! cargo run --release -p afmdyn --example approach_timing            # 120 points, best of 3
//! cargo run --release -p afmdyn --example approach_timing -- 120 1   # points, repeats
//! ```
//!
//! 1. the point-mass model of `examples/probe-point-mass-dmt.toml` (DMT, Q = 400), z_c from
//!    1.2 A0 to 0.2 A0 in 120 values, approach and retract, with and without the branch
//!    continuation;
//! 2. the beam of `examples/probe-beam-dmt.toml` with N = 3 modes (DMT), the same grid, the
//!    stepped sweeps only: the cost per point.
//!
//! Prints one line of JSON: wall and CPU seconds (CPU from /proc/self/schedstat on Linux, the
//! time this process ran, unaffected by other load on the machine), and per point.

use afmdyn::analysis::approach::{approach_retract, approach_spec};
use afmdyn::analysis::stepped::Spacing;
use afmdyn::probe::Probe;
use afmdyn::Params;
use std::path::Path;
use std::time::Instant;

/// Seconds this process has run on a CPU (Linux), if known.
fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/schedstat").ok()?;
    let ns: f64 = s.split_whitespace().next()?.parse().ok()?;
    Some(ns * 1e-9)
}

/// Best (wall, cpu) seconds of `repeats` runs of the curve of `base` with `points` values.
fn time_curve(base: Params, points: usize, branches: bool, repeats: usize) -> (f64, f64) {
    let mut spec = approach_spec(base, 1.2, 0.2, Spacing::Points(points)).expect("grid");
    spec.branches = branches;
    let (mut wall, mut cpu) = (f64::INFINITY, f64::INFINITY);
    for _ in 0..repeats.max(1) {
        let (t0, c0) = (Instant::now(), cpu_seconds());
        let c = approach_retract(&spec).expect("approach");
        assert_eq!(c.first.len(), points);
        wall = wall.min(t0.elapsed().as_secs_f64());
        if let (Some(a), Some(b)) = (c0, cpu_seconds()) {
            cpu = cpu.min(b - a);
        }
    }
    (wall, cpu)
}

fn main() {
    let args: Vec<usize> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let points = args.first().copied().unwrap_or(120);
    let repeats = args.get(1).copied().unwrap_or(3);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let pm = Probe::load(&root.join("probe-point-mass-dmt.toml"))
        .expect("point-mass probe")
        .params;
    let beam = Params {
        modes: 3,
        ..Probe::load(&root.join("probe-beam-dmt.toml"))
            .expect("beam probe")
            .params
    };
    let (pm_wall, pm_cpu) = time_curve(pm, points, false, repeats);
    let (pmb_wall, pmb_cpu) = time_curve(pm, points, true, repeats);
    let (beam_wall, beam_cpu) = time_curve(beam, points, false, 1);
    let per = |t: f64| t / (2 * points) as f64;
    println!(
        "{}",
        serde_json::json!({
            "points": points,
            "point_mass_q400": {
                "stepped": {"wall_s": pm_wall, "cpu_s": pm_cpu},
                "with_branches": {"wall_s": pmb_wall, "cpu_s": pmb_cpu},
            },
            "beam_n3_dmt": {
                "stepped": {"wall_s": beam_wall, "cpu_s": beam_cpu},
                "per_point_cpu_s": per(beam_cpu),
                "per_point_wall_s": per(beam_wall),
            },
        })
    );
}
