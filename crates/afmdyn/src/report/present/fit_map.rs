//! A fitted map's presentation: `fit_map.nc` (its layout over (y, x)), `fit_map.csv` (one row
//! per curve), the figures `modulus` (the map of the first fitted probe key, E by default, on
//! a log scale where it spans more than a decade), `topography` (the contact point's piezo
//! height), `modulus_histogram` and `curves` (a few curves with their fits), and the summary.

use super::super::Presentation;
use crate::analysis::fit::map::{median_spread, CurveFit, CurveFlag, FitMap};
use crate::layout::figure::{AfmImage, Figure, Plot, Series, Style};
use crate::report::fit_map::{layout, short_name, unit_of};
use serde_json::Value;

/// The parameter mapped: the first fitted probe key (`sample.youngs_modulus` by default).
fn mapped(m: &FitMap) -> Option<usize> {
    m.names.iter().position(|n| n.contains('.'))
}

/// Whether a curve's value goes into the maps and histogram: flagged `fitted` (the others are
/// in the dataset with their flags).
fn shown(c: &CurveFit) -> bool {
    c.flag == CurveFlag::Fitted
}

/// The presentation of `m`, its `document` written as `fit_map.json`.
pub(crate) fn fit_map(m: &FitMap, document: &Value) -> Presentation {
    let mut s = Presentation::default();
    s.dataset("fit_map.nc", layout(m));
    s.text("fit_map.csv", csv(m));
    s.json("fit_map.json", document.clone());
    let (nx, ny) = (m.xs.len(), m.ys.len());
    if let Some(k) = mapped(m) {
        let name = &m.names[k];
        let values: Vec<f64> = m
            .curves
            .iter()
            .filter(|c| shown(c))
            .filter_map(|c| c.values[k])
            .collect();
        let wide = median_spread(&values).is_some_and(|[_, lo, hi]| lo > 0.0 && hi / lo > 10.0);
        let mut grid = vec![f64::NAN; nx * ny];
        for c in m.curves.iter().filter(|c| shown(c)) {
            let v = c.values[k].unwrap_or(f64::NAN);
            grid[c.iy * nx + c.ix] = if wide { v.log10() } else { v };
        }
        let unit = unit_of(name);
        let label = if wide {
            format!("log10 of {} in {unit}", short_name(name))
        } else {
            format!("{} ({unit})", short_name(name))
        };
        s.figure(
            "modulus",
            Plot::Image(AfmImage {
                title: format!("{name}, {} curves fitted", values.len()),
                x: m.xs.clone(),
                y: m.ys.clone(),
                values: grid,
                label: label.clone(),
            }),
        );
        s.figure("modulus_histogram", histogram(&values, wide, name, unit));
        if let Some([median, p16, p84]) = median_spread(&values) {
            s.line(format!(
                "{name}: median {median:.4e} {unit} (16th–84th percentile {p16:.4e} to {p84:.4e}) over {} curves",
                values.len()
            ));
        }
    }
    let mut topo = vec![f64::NAN; nx * ny];
    for c in &m.curves {
        topo[c.iy * nx + c.ix] = c.contact_height.unwrap_or(f64::NAN);
    }
    s.figure(
        "topography",
        Plot::Image(AfmImage {
            title: "Topography: the contact point's piezo height".into(),
            x: m.xs.clone(),
            y: m.ys.clone(),
            values: topo,
            label: "height (m)".into(),
        }),
    );
    s.figure("curves", curves(m));
    let counts: Vec<String> = (m.counts().into_iter())
        .map(|(name, n)| format!("{n} {}", name.replace('_', " ")))
        .collect();
    s.summary.insert(
        0,
        format!(
            "fit-map: {} curves on a {nx} × {ny} grid ({} law): {}",
            m.curves.len(),
            m.law.name(),
            counts.join(", ")
        ),
    );
    s
}

/// `fit_map.csv`: per curve x, y (m), flag, each fitted parameter with its standard error,
/// χ²/dof, the contact rows and the contact height (m).
fn csv(m: &FitMap) -> String {
    let mut header = vec!["x".to_string(), "y".into(), "flag".into()];
    for n in &m.names {
        header.push(short_name(n));
        header.push(format!("{}_standard_error", short_name(n)));
    }
    header.extend(["chi2_dof", "contact_rows", "topography", "spring_constant"].map(String::from));
    if m.layer.is_some() {
        header.push("thickness".into());
    }
    let mut text = header.join(",") + "\n";
    let f = |v: Option<f64>| v.map_or_else(String::new, |v| format!("{v:e}"));
    for c in &m.curves {
        let mut row = vec![format!("{:e}", c.x), format!("{:e}", c.y)];
        row.push(CurveFlag::NAMES[c.flag.code() as usize].to_string());
        for k in 0..m.names.len() {
            row.push(f(c.values[k]));
            row.push(f(c.standard_errors[k]));
        }
        row.extend([
            f(c.chi2_dof),
            c.contact_rows.to_string(),
            f(c.contact_height),
            f(c.spring_constant),
        ]);
        if m.layer.is_some() {
            row.push(f(c.thickness));
        }
        text.push_str(&row.join(","));
        text.push('\n');
    }
    text
}

/// A histogram of `values` (of log10 when `wide`) in about √n bins (5 to 40), as a step line.
fn histogram(values: &[f64], wide: bool, name: &str, unit: &str) -> Plot {
    let v: Vec<f64> = values
        .iter()
        .map(|&x| if wide { x.log10() } else { x })
        .filter(|x| x.is_finite())
        .collect();
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let bins = ((v.len() as f64).sqrt().round() as usize).clamp(5, 40);
    let width = if hi > lo {
        (hi - lo) / bins as f64
    } else {
        lo.abs().max(1e-300) * 0.1
    };
    let mut counts = vec![0usize; bins];
    for x in &v {
        let b = (((x - lo) / width) as usize).min(bins - 1);
        counts[b] += 1;
    }
    let mut points = Vec::with_capacity(2 * bins + 2);
    for (b, &n) in counts.iter().enumerate() {
        let x0 = lo + b as f64 * width;
        points.push((x0, n as f64));
        points.push((x0 + width, n as f64));
    }
    let x_label = if wide {
        format!("log10 of {} in {unit}", short_name(name))
    } else {
        format!("{} ({unit})", short_name(name))
    };
    Plot::Lines(Figure {
        title: format!("{name} over the map's curves"),
        x_label,
        y_label: "curves".into(),
        series: vec![Series {
            label: String::new(),
            points,
            style: Style::Line,
            color: 0,
        }],
        shade: Vec::new(),
        y_min_span: 1.0,
    })
}

/// The curves kept with their fits: data as dots, fits as lines.
fn curves(m: &FitMap) -> Plot {
    let mut series = Vec::new();
    for (i, c) in m.curves.iter().filter(|c| c.shown.is_some()).enumerate() {
        let Some(sh) = &c.shown else { continue };
        let pts = |y: &[f64]| {
            sh.tip_position
                .iter()
                .zip(y)
                .map(|(x, y)| (*x, *y))
                .collect()
        };
        series.push(Series {
            label: format!("curve at ({:.3e}, {:.3e}) m", c.x, c.y),
            points: pts(&sh.force),
            style: Style::Dots,
            color: i,
        });
        series.push(Series {
            label: String::new(),
            points: pts(&sh.fit),
            style: Style::Line,
            color: i,
        });
    }
    Plot::Lines(Figure {
        title: "Curves and their fits".into(),
        x_label: "tip position (m)".into(),
        y_label: "force (N)".into(),
        series,
        shade: Vec::new(),
        y_min_span: 0.0,
    })
}
