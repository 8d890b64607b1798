//! `afmdyn basins`: a basin map over two coordinates of the initial state (issue 30). The
//! request, its limits, the map and its document are the library's
//! ([`afmdyn::request::BasinsRequest`], [`afmdyn::analysis::basins`]); this front end parses,
//! runs with a progress bar and writes `basins.csv`, `basins.nc`, the map and the JSON document.

use crate::args::{IntegratorArgs, ModelArgs};
use crate::cmd_analysis::SteadyArgs;
use crate::cmd_simulate::parse_modal_state;
use crate::error::CliError;
use crate::output::{atomic, write_bytes, OutDir};
use crate::plot::{color, save_map, CellMap};
use afmdyn::analysis::basins::{
    BasinSpec, Decided, DEFAULT_BASIN_HITS, DEFAULT_CELL, DEFAULT_DISCOVER_AFTER, DEFAULT_NEAR_TOL,
    DEFAULT_STRIDE,
};
use afmdyn::request::{BasinArrays, BasinsRequest, Document, Resolved};
use afmdyn::{CantileverModel, Params};
use clap::Args;
use plotters::style::RGBColor;
use std::path::{Path, PathBuf};

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
    /// Returns tested before the steady-state search takes over
    #[arg(long, default_value_t = DEFAULT_DISCOVER_AFTER)]
    discover_after: usize,
    /// Stride of the first pass's coarse grid, halved pass by pass (0: automatic, at least 25
    /// nodes per axis; 1: one pass). Used when the map's plane is the whole section (N = 1, a
    /// position and a velocity)
    #[arg(long, default_value_t = DEFAULT_STRIDE)]
    stride: usize,
    /// The other coordinates of every start, "a1,..,aN;adot1,..,adotN" (default: at rest)
    #[arg(long)]
    base: Option<String>,
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
    let spec = request.spec(&p)?;
    let model = CantileverModel::new(&p)?;
    let out = OutDir::lock(&a.out)?;
    let Document {
        output: map,
        json: mut doc,
    } = crate::progress::run(&request, &Resolved { params: p, probe }, "starts")?;
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
    write_nc(&out.join("basins.nc"), &spec, &BasinArrays::new(&map))?;
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
                BasinSpec::coordinate(&model, spec.x, &q.state),
                BasinSpec::coordinate(&model, spec.y, &q.state),
            )
        })
        .collect();
    let (xl, yl) = (
        format!("{} at τ = 0", spec.x),
        format!("{} at τ = 0", spec.y),
    );
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
    doc["csv"] = serde_json::json!(out.join("basins.csv"));
    doc["netcdf"] = serde_json::json!(out.join("basins.nc"));
    write_bytes(
        &out.join("basins.json"),
        serde_json::to_string_pretty(&doc).expect("json").as_bytes(),
    )?;
    if a.json {
        println!("{doc}");
    } else {
        println!(
            "{} × {} starts: {} attractors, basin fractions {:?}; outputs in {}",
            nx,
            ny,
            map.attractors.len(),
            map.basin_fractions()
                .iter()
                .map(|f| (f * 1000.0).round() / 1000.0)
                .collect::<Vec<_>>(),
            out.path().display()
        );
    }
    Ok(())
}

/// An integer variable of `basins.nc`: name, dimensions, units, long name, values.
type IntVar<'a> = (&'a str, &'a [&'a str], &'a str, &'a str, &'a Vec<i32>);

/// `basins.nc`: the map's arrays ([`BasinArrays`]) over (y, x) and (attractor), CF-style
/// attributes (`decided` as flag values with their meanings).
fn write_nc(path: &Path, spec: &BasinSpec, a: &BasinArrays) -> Result<(), CliError> {
    use netcdf3::{DataSet, FileWriter, Version};
    let e = |m: String| CliError::Io(format!("cannot write {}: {m}", path.display()));
    let d = |r: Result<(), netcdf3::error::InvalidDataSet>| r.map_err(|x| e(format!("{x:?}")));
    let mut ds = DataSet::new();
    let (nx, ny, na) = (spec.xs.len(), spec.ys.len(), a.period.len());
    d(ds.add_fixed_dim("x", nx))?;
    d(ds.add_fixed_dim("y", ny))?;
    d(ds.add_fixed_dim("attractor", na))?;
    d(ds.add_var_f64("x", &["x"]))?;
    d(ds.add_var_f64("y", &["y"]))?;
    for (var, c) in [("x", spec.x), ("y", spec.y)] {
        d(ds.add_var_attr_string(var, "long_name", format!("{c} at tau = 0")))?;
        let velocity = matches!(
            c,
            afmdyn::analysis::basins::StateCoord::ADot(_)
                | afmdyn::analysis::basins::StateCoord::WDot
        );
        d(ds.add_var_attr_string(
            var,
            "units",
            if velocity { "g0 per unit tau" } else { "g0" },
        ))?;
    }
    let cell = ["y", "x"];
    let ints: [IntVar<'_>; 4] = [
        ("label", &cell, "1", "attractor id; -2 failed", &a.label),
        (
            "decided",
            &cell,
            "1",
            "how the cell was decided",
            &a.decided,
        ),
        (
            "periods",
            &cell,
            "drive periods",
            "drive periods the start ran",
            &a.periods,
        ),
        (
            "period",
            &["attractor"],
            "drive periods",
            "period n; -1 nonperiodic",
            &a.period,
        ),
    ];
    for (name, dims, unit, meaning, _) in ints {
        d(ds.add_var_i32(name, dims))?;
        d(ds.add_var_attr_string(name, "units", unit))?;
        d(ds.add_var_attr_string(name, "long_name", meaning))?;
    }
    let codes: Vec<i32> = Decided::ALL.iter().map(|x| x.code()).collect();
    let meanings: Vec<&str> = Decided::ALL.iter().map(|x| x.name()).collect();
    d(ds.add_var_attr_i32("decided", "flag_values", codes))?;
    d(ds.add_var_attr_string("decided", "flag_meanings", meanings.join(" ")))?;
    let floats: [(&str, &str, &str, &Vec<f64>); 5] = [
        ("x_max", "g0", "largest tip deflection W(1,tau)", &a.x_max),
        ("v_t_min", "g0", "smallest V_T", &a.v_t_min),
        (
            "basin_fraction",
            "1",
            "share of the map's cells",
            &a.basin_fraction,
        ),
        (
            "stable",
            "1",
            "1 stable periodic orbit (shooting), 0 unstable, NaN unknown",
            &a.stable,
        ),
        (
            "lyapunov",
            "1/tau",
            "largest Lyapunov exponent of a nonperiodic attractor",
            &a.lyapunov,
        ),
    ];
    for (name, unit, meaning, _) in floats {
        d(ds.add_var_f64(name, &["attractor"]))?;
        d(ds.add_var_attr_string(name, "units", unit))?;
        d(ds.add_var_attr_string(name, "long_name", meaning))?;
    }
    d(ds.add_global_attr_string(
        "title",
        format!("afmdyn basins of attraction over {} and {}", spec.x, spec.y),
    ))?;
    d(ds.add_global_attr_string("source", format!("afmdyn {}", env!("CARGO_PKG_VERSION"))))?;
    atomic(path, |tmp| {
        let w = |x: netcdf3::error::WriteError| e(format!("{x:?}"));
        let mut f = FileWriter::open(tmp).map_err(w)?;
        f.set_def(&ds, Version::Offset64Bit, 0).map_err(w)?;
        f.write_var_f64("x", &spec.xs).map_err(w)?;
        f.write_var_f64("y", &spec.ys).map_err(w)?;
        for (name, _, _, _, v) in ints {
            f.write_var_i32(name, v).map_err(w)?;
        }
        for (name, _, _, v) in floats {
            f.write_var_f64(name, v).map_err(w)?;
        }
        f.close().map_err(w)
    })
}
