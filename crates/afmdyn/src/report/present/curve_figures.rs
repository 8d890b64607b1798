//! The figures of a stepped curve (amplitude, phase, peak force, virial, dissipation against the
//! swept quantity, with branches and folds) and of its force–distance traces, as data.

use crate::analysis::continuation::BranchEvent;
use crate::analysis::observables::Observables;
use crate::analysis::stepped::Sweep;
use crate::analysis::stepped::{BranchSample, SteppedCurve};
use crate::layout::figure::{Figure, Plot, Series, Style};
use crate::report::TextUnits;
use crate::report::{component_columns, component_row, curve_column_index, curve_row, CurveUnits};

/// How one curve is labelled and converted.
pub(crate) struct Labels {
    /// File stem.
    pub stem: &'static str,
    /// Names of the two sweeps.
    pub sweeps: (&'static str, &'static str),
    /// Abscissa column name and axis label.
    pub x_name: &'static str,
    pub x_label: String,
    /// The abscissa's symbol in the printed summary and its SI unit (`None`: dimensionless).
    pub x_text: &'static str,
    pub x_unit: Option<&'static str>,
    /// The text's units.
    pub text: TextUnits,
}

impl Labels {
    /// An abscissa value as the summary prints it: with an SI prefix and the unit (13.4747 nm,
    /// 300.000 kHz), or to 7 significant digits when dimensionless.
    pub(super) fn show(&self, v: f64) -> String {
        match self.x_unit {
            Some(unit) => self.text.value(v, unit),
            None => format!("{v:.6e}"),
        }
    }
}

/// One curve's presentation context: the curve, its abscissa in reported units, its units
/// and labels.
pub(crate) struct Shown<'a> {
    pub c: &'a SteppedCurve,
    pub x: &'a dyn Fn(f64) -> f64,
    pub u: &'a CurveUnits,
    pub l: &'a Labels,
}

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

/// A panel of a curve's figures: (where its values come from, the column's name, the y axis
/// label, the file stem's suffix).
type Panel = (Key, String, String, String);

/// The figures of a curve against its swept quantity, each with its stem: amplitude, phase,
/// dissipation, virial, peak force, each drive component's amplitude and phase, the higher
/// modes' share; the sweeps, the continued branches (unstable dotted), jumps and folds, the
/// bistable ranges shaded.
pub(crate) fn panels(s: &Shown<'_>) -> Vec<(String, Plot)> {
    let (c, x, u, l) = (s.c, s.x, s.u, s.l);
    let mut figures = Vec::new();
    for (k, name, y_label, suffix) in panel_list(s) {
        let name = name.as_str();
        figures.push((
            format!("{}-{suffix}", l.stem),
            Plot::Lines(Figure {
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
                series: panel_series(s, k),
                shade: c
                    .bistable
                    .iter()
                    .map(|&(a, b)| {
                        let (p, q) = (x(a), x(b));
                        (p.min(q), p.max(q))
                    })
                    .collect(),
            }),
        ));
    }
    figures
}

/// The panels of a curve: amplitude (its ratio to the free one against z_c), phase,
/// dissipation, virial, peak force; under a multifrequency drive each component's amplitude
/// and phase; with more than one mode the higher modes' share.
fn panel_list(s: &Shown<'_>) -> Vec<Panel> {
    let (c, u, l) = (s.c, s.u, s.l);
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
        let (y, suffix) = match k % 4 {
            0 => (format!("amplitude A{i} {}", unit("(m)")), "amplitude"),
            1 => (format!("phase lag φ{i} (deg)"), "phase"),
            _ => continue,
        };
        panels.push((Key::Component(k), name, y, format!("{suffix}-{i}")));
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
    panels
}

/// The series of the values `k` of a curve: the continued branches first (underneath: each
/// unstable stretch a dotted line, stable points as small dots), the two sweeps, the jumps
/// and the folds.
fn panel_series(s: &Shown<'_>, k: Key) -> Vec<Series> {
    let (c, x, u, l) = (s.c, s.x, s.u, s.l);
    let mut series = Vec::new();
    let points = |label: &str, points: Vec<(f64, f64)>, color| Series {
        label: label.into(),
        points,
        style: Style::Points,
        color,
    };
    for b in &c.branches {
        let at = |s: &BranchSample| (x(s.point.value), col(&s.observables, u, k));
        let stable: Vec<(f64, f64)> = b.iter().filter(|s| s.point.stable).map(at).collect();
        for run in b.chunk_by(|p, q| p.point.stable == q.point.stable) {
            if !run[0].point.stable {
                series.push(Series {
                    label: String::new(),
                    points: run.iter().map(at).collect(),
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
        series.push(points("jumps", marks, 2));
    }
    let folds: Vec<(f64, f64)> = c
        .branches
        .iter()
        .flatten()
        .filter(|s| s.point.event == Some(BranchEvent::Fold))
        .map(|s| (x(s.point.value), col(&s.observables, u, k)))
        .collect();
    if !folds.is_empty() {
        series.push(points("folds (saddle-node)", folds, 4));
    }
    series
}

/// The force–distance loops of up to 8 of the traces' `xs` spread over the sweep (`distance`
/// and `force` over (point, time), `ns` samples a cycle; in the units `length` and `force`).
pub(crate) fn traces_figure(
    l: &Labels,
    xs: &[f64],
    distance: &[f64],
    force_values: &[f64],
    ns: usize,
    (length, force): (&str, &str),
) -> Plot {
    let np = xs.len();
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
                l.x_text,
                match l.x_unit {
                    Some(u) => l.text.value(xs[i], u),
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
    Plot::Lines(Figure {
        y_min_span: 0.0,
        title: format!(
            "Force–distance loops over one cycle ({}; the loop's area is E_dis)",
            l.sweeps.0
        ),
        x_label: format!("tip–sample distance V_T ({length})"),
        y_label: format!("tip–sample force ({force})"),
        series,
        shade: vec![],
    })
}
