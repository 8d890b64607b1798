//! `afmdyn basins`: a basin map over two coordinates of the initial state (issue 30). The map,
//! its stopping rules and limits are the library's ([`afmdyn::analysis::basins`]), its
//! measures too ([`afmdyn::analysis::basin_entropy`]); this front end parses, runs and writes
//! `basins.csv`, the map and the JSON document.

use crate::args::{IntegratorArgs, ModelArgs};
use crate::cmd_analysis::SteadyArgs;
use crate::error::CliError;
use crate::output::{write_bytes, OutDir};
use crate::plot::{color, save_map, CellMap};
use afmdyn::analysis::basin_entropy::{basin_entropy, uncertainty_exponent};
use afmdyn::analysis::basins::{
    basins, BasinSpec, Decided, StateCoord, DEFAULT_BASIN_HITS, DEFAULT_CELL,
    DEFAULT_DISCOVER_AFTER, DEFAULT_NEAR_TOL,
};
use afmdyn::analysis::bifurcation::SweepSpec;
use afmdyn::{CantileverModel, Params};
use clap::Args;
use plotters::style::RGBColor;
use serde_json::json;
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
    #[arg(long, default_value_t = -0.6, allow_negative_numbers = true)]
    x_from: f64,
    /// Last x value
    #[arg(long, default_value_t = 0.6, allow_negative_numbers = true)]
    x_to: f64,
    /// Number of x values
    #[arg(long, default_value_t = 40)]
    x_steps: usize,
    /// y coordinate, as --x
    #[arg(long, default_value = "adot1")]
    y: String,
    /// First y value
    #[arg(long, default_value_t = -1.2, allow_negative_numbers = true)]
    y_from: f64,
    /// Last y value
    #[arg(long, default_value_t = 1.2, allow_negative_numbers = true)]
    y_to: f64,
    /// Number of y values
    #[arg(long, default_value_t = 40)]
    y_steps: usize,
    /// Relative distance to a periodic attractor's section point that decides a start (after
    /// 3 consecutive returns)
    #[arg(long, default_value_t = DEFAULT_NEAR_TOL)]
    near_tol: f64,
    /// Side of the state-space cells of the recurrence test (g0; ×Ω for velocities)
    #[arg(long, default_value_t = DEFAULT_CELL)]
    cell: f64,
    /// Consecutive returns in cells of one basin that decide a start (0: no recurrence test)
    #[arg(long, default_value_t = DEFAULT_BASIN_HITS)]
    basin_hits: usize,
    /// Relative tolerance for two steady states to be one attractor
    #[arg(long, default_value_t = 1e-5)]
    cluster_tol: f64,
    /// Worker threads (default: all cores)
    #[arg(long)]
    threads: Option<usize>,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out")]
    out: PathBuf,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

fn coord(field: &str, s: &str) -> Result<StateCoord, CliError> {
    s.parse()
        .map_err(|e: String| CliError::Input(format!("--{field}: {e}")))
}

/// Run `afmdyn basins`.
pub fn basins_cmd(a: &BasinsArgs) -> Result<(), CliError> {
    let (p, _probe) = a.model.resolve(Params::default())?;
    let (x, y) = (coord("x", &a.x)?, coord("y", &a.y)?);
    let input = |e: afmdyn::SimError| CliError::Input(crate::error::spell(&e));
    let spec = BasinSpec {
        params: p,
        x,
        xs: SweepSpec::linspace(a.x_from, a.x_to, a.x_steps).map_err(input)?,
        y,
        ys: SweepSpec::linspace(a.y_from, a.y_to, a.y_steps).map_err(input)?,
        base: nalgebra::DVector::zeros(2 * p.modes),
        near_tol: a.near_tol,
        cell: a.cell,
        basin_hits: a.basin_hits,
        discover_after: DEFAULT_DISCOVER_AFTER,
        steady: a.steady.request().options().map_err(input)?,
        cluster_tol: a.cluster_tol,
        integrator: a.integrator.request().options(1),
    };
    spec.validate().map_err(input)?;
    if let Some(t) = a.threads {
        if !(1..=1024).contains(&t) {
            return Err(CliError::Input(format!(
                "threads = {t}: must be in 1..=1024"
            )));
        }
    }
    let model = CantileverModel::new(&p).map_err(|e| input(e.into()))?;
    let out = OutDir::lock(&a.out)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(a.threads.unwrap_or(0))
        .build()
        .map_err(|e| CliError::Io(format!("cannot start worker threads: {e}")))?;
    let map = pool.install(|| basins(&spec)).map_err(|e| {
        if e.is_input_error() {
            input(e)
        } else {
            CliError::Sim(e)
        }
    })?;
    let (nx, ny) = (spec.xs.len(), spec.ys.len());
    let labels = map.labels();
    // basins.csv
    let mut text = String::from("ix,iy,x,y,label,decided,periods\n");
    for (k, c) in map.cells.iter().enumerate() {
        let (ix, iy) = (k % nx, k / nx);
        text.push_str(&format!(
            "{ix},{iy},{},{},{},{},{}\n",
            spec.xs[ix],
            spec.ys[iy],
            c.label,
            c.decided.name(),
            c.periods
        ));
    }
    write_bytes(&out.join("basins.csv"), text.as_bytes())?;
    // the map, the attractors' section points on it
    let colour = |l: i64| -> RGBColor {
        if l < 0 {
            RGBColor(0, 0, 0)
        } else {
            color(l as usize)
        }
    };
    let cells: Vec<Option<RGBColor>> = labels.iter().map(|&l| Some(colour(l))).collect();
    let mut legend: Vec<(String, RGBColor)> = map
        .attractors
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let kind = s
                .period()
                .map_or("nonperiodic".to_string(), |n| format!("period {n}"));
            (format!("attractor {i}: {kind}"), colour(i as i64))
        })
        .collect();
    if labels.iter().any(|&l| l < 0) {
        legend.push(("failed".into(), colour(-2)));
    }
    let points: Vec<(f64, f64)> = map
        .attractors
        .iter()
        .flat_map(|s| s.poincare.iter())
        .map(|q| {
            (
                BasinSpec::coordinate(&model, x, &q.state),
                BasinSpec::coordinate(&model, y, &q.state),
            )
        })
        .collect();
    let (xl, yl) = (format!("{x} at τ = 0"), format!("{y} at τ = 0"));
    save_map(
        out.path(),
        "basins",
        &CellMap {
            title: "Basins of attraction (section points of the attractors: white rings)",
            labels: (&xl, &yl),
            x: &spec.xs,
            y: &spec.ys,
            cells: &cells,
            legend: &legend,
            points: &points,
        },
    )?;
    let entropy = basin_entropy(&labels, nx, 5);
    let uncertainty = uncertainty_exponent(&labels, nx);
    let count = |d: Decided| map.cells.iter().filter(|c| c.decided == d).count();
    let fractions = map.basin_fractions();
    let doc = json!({
        "params": p,
        "x": {"name": x.to_string(), "values": spec.xs},
        "y": {"name": y.to_string(), "values": spec.ys},
        "labels": labels.chunks(nx).collect::<Vec<_>>(),
        "attractors": map.attractors.iter().enumerate().map(|(i, s)| json!({
            "id": i,
            "period": s.period(),
            "multipliers": map.orbits[i].as_ref().map(|o| o.multipliers.iter()
                .map(|m| [m.re, m.im]).collect::<Vec<_>>()),
            "stable": map.orbits[i].as_ref().map(|o| o.stable),
            "lyapunov": map.lyapunov[i],
            "poincare": {"state": s.poincare.iter()
                .map(|q| q.state.iter().copied().collect::<Vec<f64>>())
                .collect::<Vec<_>>()},
            "x_max": s.stats.x_max,
            "v_t_min": s.stats.v_t_min,
            "contacts_per_period": s.stats.contacts_per_period,
        })).collect::<Vec<_>>(),
        "basin_fractions": fractions,
        "failed": labels.iter().filter(|&&l| l < 0).count(),
        "decided": {
            "near": count(Decided::Near),
            "recurrence": count(Decided::Recurrence),
            "steady": count(Decided::Steady),
            "failed": count(Decided::Failed),
        },
        "periods": map.cells.iter().map(|c| c.periods as u64).sum::<u64>(),
        "basin_entropy": entropy.map(|e| e.basin_entropy),
        "boundary_basin_entropy": entropy.map(|e| e.boundary_basin_entropy),
        "uncertainty_exponent": uncertainty.map(|u| u.0),
        "csv": out.join("basins.csv"),
    });
    if a.json {
        println!("{doc}");
    } else {
        println!(
            "{} × {} starts: {} attractors, basin fractions {:?}; outputs in {}",
            nx,
            ny,
            map.attractors.len(),
            fractions
                .iter()
                .map(|f| (f * 1000.0).round() / 1000.0)
                .collect::<Vec<_>>(),
            out.path().display()
        );
    }
    Ok(())
}
