//! `converge`: its table (`converge.csv`), the figure of paper Fig. 4 and its summary.

use crate::analysis::converge::ConvergenceRun;
use crate::layout::figure::{Figure, Plot, Series, Style};
use crate::layout::files::f;
use crate::params::Params;
use crate::report::Presentation;

/// The columns of `converge.csv` with their unit and meaning (the book's reference of the CSV
/// files shows them): τ, then one column per run, `{N}` its number of modes.
pub(crate) const COLUMNS: [(&str, &str, &str); 2] = [
    (
        "tau_from_section",
        "τ (eq. 5)",
        "τ − τ0 from the first run's section point",
    ),
    (
        "w_tip_n{N}",
        "g0",
        "tip deflection W(1,τ) of the run with modes = N",
    ),
];

/// `converge`: `converge.csv` (W(1,τ) of every N over the common samples, τ from the first
/// run's section point), the figure of paper Fig. 4 and the table of periods and RMS changes.
pub(crate) fn converge(p: &Params, runs: &[ConvergenceRun]) -> Presentation {
    let mut s = Presentation::default();
    let k = runs.iter().map(|r| r.w_tip.len()).min().unwrap_or(0);
    let mut header = vec![COLUMNS[0].0.to_string()];
    header.extend(
        runs.iter()
            .map(|r| COLUMNS[1].0.replace("{N}", &r.modes.to_string())),
    );
    let hdr: Vec<&str> = header.iter().map(String::as_str).collect();
    let t0 = runs.first().map_or(0.0, |r| r.tau[0]);
    let rows = (0..k)
        .map(|i| {
            let mut row = vec![f(runs[0].tau[i] - t0)];
            row.extend(runs.iter().map(|r| f(r.w_tip[i])));
            row
        })
        .collect();
    s.csv("converge.csv", &hdr, rows);
    s.figure(
        "converge",
        Plot::Lines(Figure {
            y_min_span: 0.0,
            title: format!("Mode convergence, Ω = {} (paper Fig. 4)", p.omega),
            x_label: "τ − τ₀ (from a section point)".into(),
            y_label: "W(1,τ)".into(),
            series: runs
                .iter()
                .map(|r| Series {
                    label: format!("N = {}", r.modes),
                    points: r
                        .tau
                        .iter()
                        .zip(&r.w_tip)
                        .map(|(t, w)| (t - r.tau[0], *w))
                        .collect(),
                    style: Style::Line,
                    color: r.modes - 1,
                })
                .collect(),
            shade: vec![],
        }),
    );
    if p.alpha3 > 0.0 || p.alpha6 > 0.0 {
        s.line(format!(
            "note: paper eq. 24 is undamped; using α3 = {}, α6 = {} (eq. 26) so a steady state \
             exists",
            p.alpha3, p.alpha6
        ));
    }
    s.line(format!(
        "{:>3} {:>8} {:>22}",
        "N", "period", "RMS ΔW_tip vs N−1"
    ));
    for r in runs {
        s.line(format!(
            "{:>3} {:>8} {:>22}",
            r.modes,
            r.period.map_or("nonper.".to_string(), |n| n.to_string()),
            r.rms_change.map_or("-".to_string(), |v| format!("{v:.4e}"))
        ));
    }
    s
}
