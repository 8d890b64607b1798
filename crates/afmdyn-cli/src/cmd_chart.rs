//! `afmdyn chart`: a behaviour chart over two parameters (issue 29). The request, its limits,
//! its tasks, its store, its executor and its result layout are the library's
//! ([`afmdyn::request::chart`], [`afmdyn::analysis::chart`],
//! [`afmdyn::study::chart_store`], [`afmdyn::study`]); this front end maps the flags, runs
//! the study with a progress bar, and writes `chart.csv`, `chart.nc` (from the layout) and the
//! maps.

use crate::args::{Dim, IntegratorArgs, ModelArgs, Quantity};
use crate::cmd_analysis::SteadyArgs;
use crate::error::CliError;
use crate::output::{write_bytes, OutDir};
use crate::plot::{save_map, CellMap};
use afmdyn::analysis::chart::ChartCell;
use afmdyn::layout::figure::palette as color;
use afmdyn::layout::figure::Rgb as RGBColor;
use afmdyn::request::chart::{
    axis_name, axis_unit, csv_lines, document, warnings, Chart, ChartArrays, CSV_HEADER,
};
use afmdyn::request::checkpoint::CheckpointError;
use afmdyn::request::{parameter, ChartRequest};
use afmdyn::study::chart_store::{cells, chart_store};
use afmdyn::Params;
use clap::Args;
use std::path::{Path, PathBuf};

/// `afmdyn chart` flags.
#[derive(Debug, Args)]
pub struct ChartArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    integrator: IntegratorArgs,
    #[command(flatten)]
    steady: SteadyArgs,
    /// x parameter (columns): omega, alpha1..alpha6 or their names (drive-amplitude, gap, …),
    /// restitution, hamaker, intermolecular-distance; with --probe also z-c (m) and
    /// drive-frequency (Hz)
    #[arg(long, default_value = "omega")]
    x: String,
    /// First x value, in the axis' unit (with --probe: z-c in m, drive-frequency in Hz; a unit
    /// may follow: 5nm, 299kHz)
    #[arg(long, default_value_t = ChartRequest::default().x_from.into(), allow_hyphen_values = true)]
    x_from: Quantity,
    /// Last x value
    #[arg(long, default_value_t = ChartRequest::default().x_to.into(), allow_hyphen_values = true)]
    x_to: Quantity,
    /// Number of x values
    #[arg(long, default_value_t = ChartRequest::default().x_steps)]
    x_steps: usize,
    /// y parameter (rows), as --x
    #[arg(long, default_value = "drive-amplitude")]
    y: String,
    /// First y value
    #[arg(long, default_value_t = ChartRequest::default().y_from.into(), allow_hyphen_values = true)]
    y_from: Quantity,
    /// Last y value
    #[arg(long, default_value_t = ChartRequest::default().y_to.into(), allow_hyphen_values = true)]
    y_to: Quantity,
    /// Number of y values
    #[arg(long, default_value_t = ChartRequest::default().y_steps)]
    y_steps: usize,
    /// Random initial states per cell (besides continuation from the neighbouring cells)
    #[arg(long, default_value_t = ChartRequest::default().starts)]
    starts: u32,
    /// Seed of the random initial states
    #[arg(long, default_value_t = ChartRequest::default().seed)]
    seed: u64,
    /// Cells per task: continuation runs along x within a tile of this many cells
    #[arg(long, default_value_t = ChartRequest::default().tile)]
    tile: usize,
    /// Drive periods of the λ₁ estimate of each nonperiodic attractor (0: none)
    #[arg(long, default_value_t = ChartRequest::default().lyapunov_periods)]
    lyapunov_periods: usize,
    /// Relative tolerance for two steady states to be one attractor
    #[arg(long, default_value_t = ChartRequest::default().cluster_tol)]
    cluster_tol: f64,
    /// Attractor slots per cell in chart.nc (a cell with more keeps those most starts reached
    /// there; chart.csv and --json list every one)
    #[arg(long, default_value_t = ChartRequest::default().max_attractors)]
    max_attractors: usize,
    /// Worker threads (default: all cores)
    #[arg(long)]
    threads: Option<usize>,
    /// Continue an interrupted chart; refused unless the other arguments are those of the
    /// interrupted run (recorded in OUT/.chart.run.json)
    #[arg(long)]
    resume: bool,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out")]
    out: PathBuf,
    /// Testing: abort the process, as if killed, after this many tasks are stored
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
    /// Print the chart as one JSON document
    #[arg(long)]
    json: bool,
}

fn store_error(e: CheckpointError) -> CliError {
    crate::error::store_error(e, "chart")
}

/// The label of an axis: symbol, name and unit.
fn axis_label(name: &str) -> String {
    let symbol = parameter(name).map_or(name, |p| p.symbol);
    let head = if symbol == name {
        name.to_string()
    } else {
        format!("{symbol} {name}")
    };
    match axis_unit(name) {
        "1" => head,
        unit => format!("{head} ({unit})"),
    }
}

/// Colour and legend label of the class of a period and motion code (the bifurcation
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

/// The class of a cell without an attractor (drawn black).
const NO_ATTRACTOR: usize = usize::MAX;

fn class_color(c: usize) -> RGBColor {
    if c == NO_ATTRACTOR {
        RGBColor(0, 0, 0)
    } else {
        color(c)
    }
}

/// A diverging colour for λ₁ in [−m, m]: blue (negative) through white to red (positive).
fn diverging(v: f64, m: f64) -> RGBColor {
    let t = (v / m).clamp(-1.0, 1.0);
    let mix = |a: u8, b: u8, s: f64| (f64::from(a) + (f64::from(b) - f64::from(a)) * s) as u8;
    if t < 0.0 {
        let s = -t;
        RGBColor(mix(255, 33, s), mix(255, 102, s), mix(255, 172, s))
    } else {
        RGBColor(mix(255, 178, t), mix(255, 24, t), mix(255, 43, t))
    }
}

fn write_csv(path: &Path, chart: &Chart, cells: &[ChartCell]) -> Result<(), CliError> {
    let mut text = CSV_HEADER.join(",");
    text.push('\n');
    for c in cells {
        for line in csv_lines(chart, c) {
            text.push_str(&line);
            text.push('\n');
        }
    }
    Ok(write_bytes(path, text.as_bytes())?)
}

/// The value of `--FLAG` on the axis `axis`: a unit (5nm, 299kHz) must be the axis' SI unit
/// ([`afmdyn::request::chart::axis_unit`]: m or Hz); an axis in another unit or dimensionless
/// takes a plain number.
fn axis_value(q: Quantity, flag: &str, axis: &str) -> Result<f64, CliError> {
    let name = axis_name("x", axis).map_or("", |n| n);
    let want = match axis_unit(name) {
        "m" => Some(Dim::Length),
        "Hz" => Some(Dim::Frequency),
        _ => None,
    };
    match (q.dim, want) {
        (Some(_), None) => Err(CliError::Input(format!(
            "--{flag}: the axis {axis} takes a plain number ({}), not a unit",
            match axis_unit(name) {
                "1" => "dimensionless".to_string(),
                u => format!("in {u}"),
            }
        ))),
        (_, Some(d)) => q.value(flag, d, true),
        (None, None) => Ok(q.value),
    }
}

/// Run `afmdyn chart`.
pub fn chart(a: &ChartArgs) -> Result<(), CliError> {
    let (spec, probe) = a.model.spec_and_probe()?;
    // the chart reads the probe file's text: an axis may be one of its values
    let probe_text = match probe {
        Some(_) => a.model.probe_text()?,
        None => None,
    };
    let request = ChartRequest {
        x: a.x.clone(),
        x_from: axis_value(a.x_from, "x-from", &a.x)?,
        x_to: axis_value(a.x_to, "x-to", &a.x)?,
        x_steps: a.x_steps,
        y: a.y.clone(),
        y_from: axis_value(a.y_from, "y-from", &a.y)?,
        y_to: axis_value(a.y_to, "y-to", &a.y)?,
        y_steps: a.y_steps,
        starts: a.starts,
        seed: a.seed,
        tile: a.tile,
        cluster_tol: a.cluster_tol,
        lyapunov_periods: a.lyapunov_periods,
        max_attractors: a.max_attractors,
        threads: a.threads,
        steady: a.steady.request(),
        integrator: a.integrator.request(),
    };
    let chart = request
        .chart(spec, Params::default(), probe_text.as_deref())
        .map_err(|e| CliError::Input(crate::error::spell(&e)))?;
    let out = OutDir::lock(&a.out)?;
    let mut store = chart_store(out.dir_lock());
    crate::progress::study(
        &chart,
        &mut store,
        a.resume,
        a.threads,
        "cells",
        a.abort_after,
    )
    .map_err(|e| crate::error::study_error(e, "chart"))?;
    let cells = cells(&mut store).map_err(store_error)?;
    let arrays = ChartArrays::new(&chart, &cells);
    write_csv(&out.join("chart.csv"), &chart, &cells)?;
    crate::output::write_layout(
        &out.join("chart.nc"),
        &arrays.layout(chart.model.x, chart.model.y),
    )?;
    draw_maps(out.path(), &chart, &arrays)?;
    if let Some(e) = afmdyn::study::chart::every_cell_failed(&cells) {
        return Err(CliError::Sim(e));
    }
    let empty = cells.iter().filter(|c| c.attractors.is_empty()).count();
    for w in warnings(&chart, &cells) {
        errln!("afmdyn: warning: {w}");
    }
    if a.json {
        let mut doc = document(&chart, &cells);
        doc["files"] = serde_json::json!({
            "csv": out.join("chart.csv"),
            "netcdf": out.join("chart.nc"),
        });
        outln!("{doc}");
    } else {
        let multi = cells.iter().filter(|c| c.attractors.len() > 1).count();
        outln!(
            "chart of {} × {} cells over {} × {}: {} with coexisting attractors, {} without any; \
             outputs in {}",
            chart.spec.x.len(),
            chart.spec.y.len(),
            chart.model.x,
            chart.model.y,
            multi,
            empty,
            out.path().display()
        );
    }
    Ok(())
}

fn draw_maps(dir: &Path, chart: &afmdyn::request::Chart, a: &ChartArrays) -> Result<(), CliError> {
    let (xl, yl) = (axis_label(chart.model.x), axis_label(chart.model.y));
    let labels = (xl.as_str(), yl.as_str());
    // period of the dominant attractor
    let mut classes: Vec<(usize, &str)> = Vec::new();
    let cells: Vec<Option<RGBColor>> = a
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
    let legend: Vec<(String, RGBColor)> = classes
        .iter()
        .map(|(c, l)| (l.to_string(), class_color(*c)))
        .collect();
    save_map(
        dir,
        "chart-period",
        &CellMap {
            title: "Period of the attractor most starts reach".into(),
            labels: (labels.0.to_string(), labels.1.to_string()),
            x: a.x.clone(),
            y: a.y.clone(),
            cells: cells.clone(),
            legend: legend.clone(),
            points: vec![],
        },
    )?;
    // λ₁ of the dominant attractor, where it is nonperiodic
    let lyap: Vec<f64> = (0..a.dominant_period.len())
        .map(|i| a.lyapunov[i * a.slots])
        .collect();
    let m = lyap
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let m = if m > 0.0 { m } else { 1e-3 };
    let grey = RGBColor(200, 200, 200);
    let cells: Vec<Option<RGBColor>> = lyap
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
    let legend: Vec<(String, RGBColor)> = [-1.0, -0.5, 0.0, 0.5, 1.0]
        .iter()
        .map(|&t| (format!("λ₁ = {:.3e} /τ", t * m), diverging(t * m, m)))
        .chain(std::iter::once(("periodic".to_string(), grey)))
        .collect();
    save_map(
        dir,
        "chart-lyapunov",
        &CellMap {
            title: "Largest Lyapunov exponent λ₁ of the nonperiodic attractors".into(),
            labels: (labels.0.to_string(), labels.1.to_string()),
            x: a.x.clone(),
            y: a.y.clone(),
            cells: cells.clone(),
            legend: legend.clone(),
            points: vec![],
        },
    )?;
    // coexisting attractors
    let most = a.attractors.iter().copied().max().unwrap_or(0).max(1);
    let cells: Vec<Option<RGBColor>> = a
        .attractors
        .iter()
        .map(|&n| (n > 0).then(|| color((n as usize - 1) % 10)))
        .collect();
    let legend: Vec<(String, RGBColor)> = (1..=most.min(10))
        .map(|n| {
            (
                format!("{n} attractor{}", if n == 1 { "" } else { "s" }),
                color((n as usize - 1) % 10),
            )
        })
        .collect();
    save_map(
        dir,
        "chart-attractors",
        &CellMap {
            title: "Coexisting attractors per cell".into(),
            labels: (labels.0.to_string(), labels.1.to_string()),
            x: a.x.clone(),
            y: a.y.clone(),
            cells: cells.clone(),
            legend: legend.clone(),
            points: vec![],
        },
    )?;
    Ok(())
}
