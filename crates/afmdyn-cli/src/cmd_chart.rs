//! `afmdyn chart`: a behaviour chart over two parameters (issue 29). The request, its limits,
//! its tasks, its store, its executor and its result layout are the library's
//! ([`afmdyn::request::chart`], [`afmdyn::analysis::chart`],
//! [`afmdyn::study::chart_store`], [`afmdyn::study`]); this front end maps the flags, runs
//! the study with a progress bar, and writes `chart.csv`, `chart.nc` (from the layout) and the
//! maps.

use crate::args::{Dim, IntegratorArgs, ModelArgs, Quantity};
use crate::cmd_analysis::SteadyArgs;
use crate::error::CliError;
use crate::output::OutDir;
use afmdyn::request::chart::{axis_name, axis_unit, document};
use afmdyn::request::{present, ChartRequest};
use afmdyn::study::chart::every_cell_failed;
use afmdyn::study::chart_store::{cells, chart_store};
use afmdyn::Params;
use clap::Args;
use std::path::PathBuf;

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
    let cells = cells(&mut store).map_err(|e| crate::error::store_error(e, "chart"))?;
    let shown = present::maps::chart(&chart, &cells);
    if let Some(e) = every_cell_failed(&cells) {
        crate::door::write_files(&out, &shown)?;
        return Err(CliError::Sim(e));
    }
    let mut doc = document(&chart, &cells);
    doc["files"] = serde_json::json!({
        "csv": out.join("chart.csv"),
        "netcdf": out.join("chart.nc"),
    });
    crate::door::emit_as(Some(&out), &shown, &doc, a.json, true)
}
