//! `afmdyn basins`: a basin map over two coordinates of the initial state (issue 30). The
//! request, its limits, the map and its document are the library's
//! ([`afmdyn::request::BasinsRequest`], [`afmdyn::analysis::basins`]); this front end parses,
//! runs with a progress bar and writes `basins.csv`, `basins.nc`, the map and the JSON document.

use crate::args::{IntegratorArgs, ModelArgs};
use crate::cmd_analysis::SteadyArgs;
use crate::cmd_simulate::parse_modal_state;
use crate::error::CliError;
use crate::output::OutDir;
use afmdyn::request::{Analysis, BasinsRequest, Resolved};
use afmdyn::study::basins::{basin_store, BasinStudy};
use afmdyn::Params;
use clap::Args;
use std::path::PathBuf;

/// `afmdyn basins` flags.
#[derive(Debug, Args)]
pub struct BasinsArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    integrator: IntegratorArgs,
    #[command(flatten)]
    steady: SteadyArgs,
    /// x coordinate of the initial state at τ = 0: a1…aN, adot1…adotN, w or wdot (the tip,
    /// set through mode 1); the others at rest
    #[arg(long, default_value = "a1")]
    x: String,
    /// First x value
    #[arg(long, default_value_t = BasinsRequest::default().x_from, allow_negative_numbers = true)]
    x_from: f64,
    /// Last x value
    #[arg(long, default_value_t = BasinsRequest::default().x_to, allow_negative_numbers = true)]
    x_to: f64,
    /// Number of x values
    #[arg(long, default_value_t = BasinsRequest::default().x_steps)]
    x_steps: usize,
    /// y coordinate, as --x
    #[arg(long, default_value = "adot1")]
    y: String,
    /// First y value
    #[arg(long, default_value_t = BasinsRequest::default().y_from, allow_negative_numbers = true)]
    y_from: f64,
    /// Last y value
    #[arg(long, default_value_t = BasinsRequest::default().y_to, allow_negative_numbers = true)]
    y_to: f64,
    /// Number of y values
    #[arg(long, default_value_t = BasinsRequest::default().y_steps)]
    y_steps: usize,
    /// Relative distance to a periodic attractor's section point that decides a start (after
    /// 3 consecutive returns)
    #[arg(long, default_value_t = BasinsRequest::default().near_tol)]
    near_tol: f64,
    /// Side of the state-space cells of the recurrence test (g0; ×Ω for velocities)
    #[arg(long, default_value_t = BasinsRequest::default().cell)]
    cell: f64,
    /// Consecutive returns in cells of one basin that decide a start (0: no recurrence test)
    #[arg(long, default_value_t = BasinsRequest::default().basin_hits)]
    basin_hits: usize,
    /// Returns tested before the steady-state search takes over
    #[arg(long, default_value_t = BasinsRequest::default().discover_after)]
    discover_after: usize,
    /// Stride of the first pass's coarse grid, halved pass by pass (0: automatic, at least 25
    /// nodes per axis; 1: one pass). Used when the map's plane is the whole section (N = 1, a
    /// position and a velocity)
    #[arg(long, default_value_t = BasinsRequest::default().stride)]
    stride: usize,
    /// The other coordinates of every start, "a1,..,aN;adot1,..,adotN" (default: at rest)
    #[arg(long)]
    base: Option<String>,
    /// Relative tolerance for two steady states to be one attractor
    #[arg(long, default_value_t = BasinsRequest::default().cluster_tol)]
    cluster_tol: f64,
    /// Worker threads (default: all cores)
    #[arg(long)]
    threads: Option<usize>,
    /// Continue an interrupted map; refused unless the other arguments are those of the
    /// interrupted run (recorded in OUT/.basins.run.json)
    #[arg(long)]
    resume: bool,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out")]
    out: PathBuf,
    /// Testing: abort the process, as if killed, after this many rows are stored
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn basins`.
pub fn basins_cmd(a: &BasinsArgs) -> Result<(), CliError> {
    let (p, probe) = a.model.resolve(Params::default())?;
    let request = BasinsRequest {
        x: a.x.clone(),
        x_from: a.x_from,
        x_to: a.x_to,
        x_steps: a.x_steps,
        y: a.y.clone(),
        y_from: a.y_from,
        y_to: a.y_to,
        y_steps: a.y_steps,
        base: parse_modal_state("base", &a.base, p.modes)?,
        near_tol: a.near_tol,
        cell: a.cell,
        basin_hits: a.basin_hits,
        discover_after: a.discover_after,
        stride: a.stride,
        cluster_tol: a.cluster_tol,
        threads: a.threads,
        steady: a.steady.request(),
        integrator: a.integrator.request(),
    };
    let study = BasinStudy::new(&request, &p)?;
    let out = OutDir::lock(&a.out)?;
    let mut store = basin_store(out.dir_lock());
    let failed = |e| crate::error::study_error(e, "basins");
    crate::progress::study(
        &study,
        &mut store,
        a.resume,
        a.threads,
        "starts",
        a.abort_after,
    )
    .map_err(failed)?;
    let rows = store
        .records()
        .map_err(|e| crate::error::store_error(e, "basins"))?;
    let map = afmdyn::request::in_pool(a.threads, || study.map(rows.into_iter().map(|(_, r)| r)))?;
    let resolved = Resolved { params: p, probe };
    let mut doc = afmdyn::request::run::document(&request, &resolved, &map)?;
    doc["csv"] = serde_json::json!(out.join("basins.csv"));
    doc["netcdf"] = serde_json::json!(out.join("basins.nc"));
    let units = crate::output::units_of(resolved.probe.as_ref());
    let shown = request.present(&resolved, &map, &doc, units)?;
    crate::door::emit_as(Some(&out), &shown, &doc, a.json, true)
}
