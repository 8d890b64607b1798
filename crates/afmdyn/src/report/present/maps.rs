//! `chart` and `basins`: their tables (`chart.csv`, `basins.csv`), datasets (`chart.nc`,
//! `basins.nc`), cell maps and text summaries.

use crate::analysis::basins::{BasinMap, BasinSpec};
use crate::analysis::chart::{ChartCell, ChartSpec};
use crate::error::SimError;
use crate::layout::figure::{palette, CellMap, Plot, Rgb};
use crate::model::CantileverModel;
use crate::report::basins::{csv_text, BasinArrays};
use crate::report::chart_layout::{csv_lines, ChartArrays, ChartAxis, CSV_HEADER};
use crate::report::Presentation;
use serde_json::Value;

/// A chart as its presentation reads it: its grid, the attractor slots of a cell, its axes
/// (x, y) and the metres per g₀ of a cell at (x, y) (1 without a probe).
pub(crate) struct ChartView<'a> {
    /// The chart's values and options.
    pub(crate) spec: &'a ChartSpec,
    /// Attractor slots per cell of its arrays.
    pub(crate) slots: usize,
    /// Its axes, x then y.
    pub(crate) axes: (ChartAxis<'a>, ChartAxis<'a>),
    /// The length unit of the cell at (x, y).
    pub(crate) length: Box<dyn Fn(f64, f64) -> f64 + 'a>,
}

/// The label of a chart axis: symbol, name and unit.
fn axis_label(axis: ChartAxis<'_>) -> String {
    let (symbol, name) = (axis.symbol, axis.name);
    let head = if symbol == name {
        name.to_string()
    } else {
        format!("{symbol} {name}")
    };
    match axis.unit {
        "1" => head,
        unit => format!("{head} ({unit})"),
    }
}

/// The class of a cell without an attractor (drawn black).
const NO_ATTRACTOR: usize = usize::MAX;

/// Colour index and legend label of the class of a period and motion code (the bifurcation
/// diagram's period classes; nonperiodic split by λ₁).
fn period_class(period: i32, motion: i32) -> (usize, &'static str) {
    match (period, motion) {
        (1, _) => (0, "period 1"),
        (2, _) => (1, "period 2"),
        (3, _) => (2, "period 3"),
        (4, _) => (3, "period 4"),
        (5..=8, _) => (4, "period 5–8"),
        (9..=64, _) => (5, "period 9–64"),
        (-1, 2) => (6, "chaotic (λ₁ > 0)"),
        (-1, 3) => (9, "λ₁ ≈ 0: quasi-periodic or settling"),
        (-1, 4) => (8, "not settled (λ₁ < 0)"),
        (-1, _) => (7, "nonperiodic (no λ₁)"),
        _ => (NO_ATTRACTOR, "no attractor (failed)"),
    }
}

fn class_color(c: usize) -> Rgb {
    if c == NO_ATTRACTOR {
        Rgb(0, 0, 0)
    } else {
        palette(c)
    }
}

/// A diverging colour for λ₁ in [−m, m]: blue (negative) through white to red (positive).
fn diverging(v: f64, m: f64) -> Rgb {
    let t = (v / m).clamp(-1.0, 1.0);
    let mix = |a: u8, b: u8, s: f64| (f64::from(a) + (f64::from(b) - f64::from(a)) * s) as u8;
    if t < 0.0 {
        let s = -t;
        Rgb(mix(255, 33, s), mix(255, 102, s), mix(255, 172, s))
    } else {
        Rgb(mix(255, 178, t), mix(255, 24, t), mix(255, 43, t))
    }
}

/// A chart's map of `cells` with `legend` over its axes.
fn chart_map(
    a: &ChartArrays,
    chart: &ChartView<'_>,
    title: &str,
    cells: Vec<Option<Rgb>>,
    legend: Vec<(String, Rgb)>,
) -> Plot {
    Plot::Cells(CellMap {
        title: title.into(),
        labels: (axis_label(chart.axes.0), axis_label(chart.axes.1)),
        x: a.x.clone(),
        y: a.y.clone(),
        cells,
        legend,
        points: vec![],
    })
}

/// The three maps of a chart: the dominant attractor's period class, its λ₁ where it is
/// nonperiodic, the number of coexisting attractors.
fn chart_maps(s: &mut Presentation, chart: &ChartView<'_>, a: &ChartArrays) {
    // period of the dominant attractor
    let mut classes: Vec<(usize, &str)> = Vec::new();
    let cells: Vec<Option<Rgb>> = a
        .dominant_period
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let (c, label) = period_class(if p == 0 { -2 } else { p }, a.motion[i * a.slots]);
            if !classes.contains(&(c, label)) {
                classes.push((c, label));
            }
            Some(class_color(c))
        })
        .collect();
    classes.sort();
    let legend = classes
        .iter()
        .map(|(c, l)| (l.to_string(), class_color(*c)))
        .collect();
    let title = "Period of the attractor most starts reach";
    s.figure("chart-period", chart_map(a, chart, title, cells, legend));
    // λ₁ of the dominant attractor, where it is nonperiodic
    let lyap: Vec<f64> = (0..a.dominant_period.len())
        .map(|i| a.lyapunov[i * a.slots])
        .collect();
    let m = lyap
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let m = if m > 0.0 { m } else { 1e-3 };
    let grey = Rgb(200, 200, 200);
    let cells = lyap
        .iter()
        .zip(&a.dominant_period)
        .map(|(&v, &p)| {
            if v.is_finite() {
                Some(diverging(v, m))
            } else if p > 0 {
                Some(grey)
            } else {
                None
            }
        })
        .collect();
    let legend = [-1.0, -0.5, 0.0, 0.5, 1.0]
        .iter()
        .map(|&t| (format!("λ₁ = {:.3e} /τ", t * m), diverging(t * m, m)))
        .chain(std::iter::once(("periodic".to_string(), grey)))
        .collect();
    let title = "Largest Lyapunov exponent λ₁ of the nonperiodic attractors";
    s.figure("chart-lyapunov", chart_map(a, chart, title, cells, legend));
    // coexisting attractors
    let most = a.attractors.iter().copied().max().unwrap_or(0).max(1);
    let cells = a
        .attractors
        .iter()
        .map(|&n| (n > 0).then(|| palette((n as usize - 1) % 10)))
        .collect();
    let legend = (1..=most.min(10))
        .map(|n| {
            (
                format!("{n} attractor{}", if n == 1 { "" } else { "s" }),
                palette((n as usize - 1) % 10),
            )
        })
        .collect();
    let title = "Coexisting attractors per cell";
    s.figure(
        "chart-attractors",
        chart_map(a, chart, title, cells, legend),
    );
}

/// A finished chart: `chart.csv` (every attractor of every cell), `chart.nc` (the arrays of
/// [`ChartArrays`]), the maps `chart-period`, `chart-lyapunov`, `chart-attractors`, and the
/// summary (the cells with coexisting attractors and without any).
pub(crate) fn chart(chart: &ChartView<'_>, cells: &[ChartCell]) -> Presentation {
    let mut s = Presentation::default();
    let mut text = CSV_HEADER.join(",");
    text.push('\n');
    for c in cells {
        for line in csv_lines((chart.length)(c.x, c.y), c) {
            text.push_str(&line);
            text.push('\n');
        }
    }
    s.text("chart.csv", text);
    let size = (chart.spec.x.len(), chart.spec.y.len());
    let arrays = ChartArrays::region_of((chart.spec, chart.slots), (0, 0), size, cells);
    s.dataset("chart.nc", arrays.layout_over(chart.axes.0, chart.axes.1));
    chart_maps(&mut s, chart, &arrays);
    let multi = cells.iter().filter(|c| c.attractors.len() > 1).count();
    let empty = cells.iter().filter(|c| c.attractors.is_empty()).count();
    s.line(format!(
        "chart of {} × {} cells over {} × {}: {} with coexisting attractors, {} without any",
        chart.spec.x.len(),
        chart.spec.y.len(),
        chart.axes.0.name,
        chart.axes.1.name,
        multi,
        empty,
    ));
    s
}

/// A basin map: `basins.csv`, `basins.nc`, the map `basins` (the attractors' section points on
/// it as rings), its `document` as `basins.json`, and the summary (the attractors and their
/// basin fractions).
///
/// # Errors
/// [`SimError`] when the map's parameters do not build a model.
pub(crate) fn basins(
    spec: &BasinSpec,
    map: &BasinMap,
    document: &Value,
) -> Result<Presentation, SimError> {
    let mut s = Presentation::default();
    s.text("basins.csv", csv_text(spec, map));
    s.dataset("basins.nc", BasinArrays::new(map).layout(spec));
    let colour = |l: i64| -> Rgb {
        if l < 0 {
            Rgb(0, 0, 0)
        } else {
            palette(l as usize)
        }
    };
    let labels = map.labels();
    let cells = labels.iter().map(|&l| Some(colour(l))).collect();
    let mut legend: Vec<(String, Rgb)> = map
        .attractors
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let kind = a
                .period()
                .map_or("nonperiodic".to_string(), |n| format!("period {n}"));
            (format!("attractor {i}: {kind}"), colour(i as i64))
        })
        .collect();
    if labels.iter().any(|&l| l < 0) {
        legend.push(("failed".into(), colour(-2)));
    }
    let model = CantileverModel::new(&spec.params)?;
    let points = map
        .attractors
        .iter()
        .flat_map(|a| a.poincare.iter())
        .map(|q| {
            (
                BasinSpec::coordinate(&model, spec.x, &q.state),
                BasinSpec::coordinate(&model, spec.y, &q.state),
            )
        })
        .collect();
    s.figure(
        "basins",
        Plot::Cells(CellMap {
            title: "Basins of attraction (section points of the attractors: white rings)".into(),
            labels: (
                format!("{} at τ = 0", spec.x),
                format!("{} at τ = 0", spec.y),
            ),
            x: spec.xs.clone(),
            y: spec.ys.clone(),
            cells,
            legend,
            points,
        }),
    );
    s.json("basins.json", document.clone());
    s.line(format!(
        "{} × {} starts: {} attractors, basin fractions {:?}",
        spec.xs.len(),
        spec.ys.len(),
        map.attractors.len(),
        map.basin_fractions()
            .iter()
            .map(|f| (f * 1000.0).round() / 1000.0)
            .collect::<Vec<_>>(),
    ));
    Ok(s)
}
