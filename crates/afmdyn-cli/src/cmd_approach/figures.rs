//! The figures of a stepped curve (amplitude, phase, peak force, virial, dissipation against the
//! swept quantity, with branches and folds) and its force–distance traces
//! (`STEM-traces.nc`, `STEM-traces` plots).

use super::*;

/// Where a plotted value comes from: a CURVE_COLUMNS index, or an index into the drive
/// components' columns (`component_row`).
#[derive(Clone, Copy)]
enum Key {
    Curve(usize),
    Component(usize),
}

/// One value of the observables.
fn col(o: &Observables, u: &CurveUnits, k: Key) -> f64 {
    match k {
        Key::Curve(k) => curve_row(o, u)[k],
        Key::Component(k) => component_row(o, u).get(k).copied().unwrap_or(f64::NAN),
    }
}

pub(super) fn plots(
    out: &OutDir,
    c: &SteppedCurve,
    x: &dyn Fn(f64) -> f64,
    u: &CurveUnits,
    l: &Labels,
) -> Result<(), CliError> {
    let unit = |base: &str| {
        if u.si {
            base.to_string()
        } else {
            String::new()
        }
    };
    let idx = |name: &str| Key::Curve(curve_column_index(name).expect("column"));
    let mut panels = vec![
        if l.x_name == "z_c" {
            ("amplitude_ratio", "A/A0".to_string(), "amplitude")
        } else {
            (
                "amplitude",
                format!("amplitude A {}", unit("(m)")),
                "amplitude",
            )
        },
        ("phase_deg", "phase lag φ (deg)".to_string(), "phase"),
        (
            "energy_dissipated",
            format!("E_dis per period {}", unit("(J)")),
            "dissipation",
        ),
        ("virial", format!("virial {}", unit("(J)")), "virial"),
        (
            "peak_force",
            format!("peak force {}", unit("(N)")),
            "peak-force",
        ),
    ]
    .into_iter()
    .map(|(name, y, suffix)| (idx(name), name.to_string(), y, suffix.to_string()))
    .collect::<Vec<_>>();
    // a multifrequency drive: A_i and φ_i of each component
    let count = c
        .first
        .first()
        .map_or(0, |p| p.observables.components.len());
    for (k, (name, _, _)) in component_columns(count).into_iter().enumerate() {
        let i = k / 4 + 1;
        match k % 4 {
            0 => panels.push((
                Key::Component(k),
                name,
                format!("amplitude A{i} {}", unit("(m)")),
                format!("amplitude-{i}"),
            )),
            1 => panels.push((
                Key::Component(k),
                name,
                format!("phase lag φ{i} (deg)"),
                format!("phase-{i}"),
            )),
            _ => {}
        }
    }
    // more than one mode: the higher modes' share of the motion (in liquid, every tap rings them)
    let modes = c
        .first
        .first()
        .map_or(0, |p| p.observables.mode_amplitudes.len());
    if modes > 1 {
        panels.push((
            idx("higher_mode_fraction"),
            "higher_mode_fraction".to_string(),
            "higher modes' RMS tip amplitude / mode 1's".to_string(),
            "higher-modes".to_string(),
        ));
    }
    for (k, name, y_label, suffix) in panels {
        let name = name.as_str();
        let mut series = Vec::new();
        // branches first (underneath): each unstable stretch a dotted line, stable points as
        // small dots
        for b in &c.branches {
            let stable: Vec<(f64, f64)> = b
                .iter()
                .filter(|s| s.point.stable)
                .map(|s| (x(s.point.value), col(&s.observables, u, k)))
                .collect();
            for run in b.chunk_by(|p, q| p.point.stable == q.point.stable) {
                if !run[0].point.stable {
                    series.push(Series {
                        label: String::new(),
                        points: run
                            .iter()
                            .map(|s| (x(s.point.value), col(&s.observables, u, k)))
                            .collect(),
                        style: Style::Dotted,
                        color: 3,
                    });
                }
            }
            if !stable.is_empty() {
                series.push(Series {
                    label: String::new(),
                    points: stable,
                    style: Style::Dots,
                    color: 7,
                });
            }
        }
        if let Some(s) = series.iter_mut().find(|s| s.color == 3) {
            s.label = "unstable branch (dotted)".into();
        }
        if let Some(s) = series.iter_mut().find(|s| s.color == 7) {
            s.label = "stable branch (continuation)".into();
        }
        for (sweep, style, color, label) in [
            (&c.first, Style::Line, 0, format!("{} (solid)", l.sweeps.0)),
            (
                &c.second,
                Style::Dashed,
                1,
                format!("{} (dashed)", l.sweeps.1),
            ),
        ] {
            series.push(Series {
                label,
                points: sweep
                    .iter()
                    .map(|p| (x(p.value), col(&p.observables, u, k)))
                    .collect(),
                style,
                color,
            });
        }
        let mut marks = Vec::new();
        for j in &c.jumps {
            let sw = match j.sweep {
                Sweep::First => &c.first,
                Sweep::Second => &c.second,
            };
            for p in &sw[j.index - 1..=j.index] {
                marks.push((x(p.value), col(&p.observables, u, k)));
            }
        }
        if !marks.is_empty() {
            series.push(Series {
                label: "jumps".into(),
                points: marks,
                style: Style::Points,
                color: 2,
            });
        }
        let folds: Vec<(f64, f64)> = c
            .branches
            .iter()
            .flatten()
            .filter(|s| s.point.event == Some(BranchEvent::Fold))
            .map(|s| (x(s.point.value), col(&s.observables, u, k)))
            .collect();
        if !folds.is_empty() {
            series.push(Series {
                label: "folds (saddle-node)".into(),
                points: folds,
                style: Style::Points,
                color: 4,
            });
        }
        save(
            out.path(),
            &format!("{}-{suffix}", l.stem),
            &Figure {
                // energies and forces below 1e-6 of the model's units are round-off (a
                // conservative law's E_dis): drawn as zero on an axis of that extent
                y_min_span: match name {
                    "energy_dissipated" | "virial" => 1e-6 * u.energy,
                    "peak_force" => 1e-6 * u.force,
                    _ => 0.0,
                },
                title: format!("{} curve: {}", l.stem, name.replace('_', " ")),
                x_label: l.x_label.clone(),
                y_label,
                series,
                shade: c
                    .bistable
                    .iter()
                    .map(|&(a, b)| {
                        let (p, q) = (x(a), x(b));
                        (p.min(q), p.max(q))
                    })
                    .collect(),
            },
        )?;
    }
    Ok(())
}

/// `STEM-traces.nc` (NetCDF 3: deflection, distance, force over (point, time), the swept
/// quantity and the time axis in drive periods) and, with plots, `STEM-traces`: the
/// force–distance loops of up to 8 points spread over the sweep.
pub(super) fn write_traces(
    out: &OutDir,
    files: Files,
    t: &afmdyn::analysis::traces::Traces,
    x: &dyn Fn(f64) -> f64,
    units: &CurveUnits,
    labels: &Labels,
) -> Result<(), CliError> {
    let path = out.join(format!("{}-traces.nc", labels.stem));
    let (np, ns) = (t.values.len(), t.time.len());
    let xs: Vec<f64> = t.values.iter().map(|&v| x(v)).collect();
    let scale = |v: &[f64], s: f64| v.iter().map(|a| a * s).collect::<Vec<f64>>();
    let (length, force) = if units.si { ("m", "N") } else { ("g0", "F~") };
    let (deflection, distance, force_values) = (
        scale(&t.deflection, units.length),
        scale(&t.distance, units.length),
        scale(&t.force, units.force),
    );
    let grid: &[&str] = &["point", "time"];
    let vars = vec![
        Variable::f64(
            labels.x_name,
            &["point"],
            labels.x_unit.unwrap_or("1"),
            labels.x_text,
            &xs,
        ),
        Variable::f64(
            "time",
            &["time"],
            "drive periods",
            "time within the cycle",
            &t.time,
        ),
        Variable::f64(
            "deflection",
            grid,
            length,
            "tip deflection W(1,tau)",
            &deflection,
        ),
        Variable::f64(
            "distance",
            grid,
            length,
            "tip-sample distance V_T (<= 0 in contact)",
            &distance,
        ),
        Variable::f64(
            "force",
            grid,
            force,
            "tip-sample force F_c (> 0 repulsive, < 0 attractive)",
            &force_values,
        ),
    ];
    crate::output::write_layout(
        &path,
        &Layout::new(
            format!(
                "afmdyn {} traces: one steady-state cycle per point of the {}",
                labels.stem, labels.sweeps.0
            ),
            &[("point", np), ("time", ns)],
            vars,
        ),
    )?;
    if files != Files::All || np == 0 {
        return Ok(());
    }
    let picks: Vec<usize> = if np <= 8 {
        (0..np).collect()
    } else {
        (0..8).map(|k| k * (np - 1) / 7).collect()
    };
    let series = picks
        .iter()
        .enumerate()
        .map(|(c, &i)| Series {
            label: format!(
                "{} = {}",
                labels.x_text,
                match labels.x_unit {
                    Some(u) => si_value(xs[i], u),
                    None => format!("{:.4}", xs[i]),
                }
            ),
            points: (0..ns)
                .map(|k| (distance[i * ns + k], force_values[i * ns + k]))
                .collect(),
            style: Style::Line,
            color: c,
        })
        .collect();
    save(
        out.path(),
        &format!("{}-traces", labels.stem),
        &Figure {
            y_min_span: 0.0,
            title: format!(
                "Force–distance loops over one cycle ({}; the loop's area is E_dis)",
                labels.sweeps.0
            ),
            x_label: format!("tip–sample distance V_T ({length})"),
            y_label: format!("tip–sample force ({force})"),
            series,
            shade: vec![],
        },
    )?;
    Ok(())
}
