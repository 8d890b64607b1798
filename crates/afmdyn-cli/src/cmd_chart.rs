//! `afmdyn chart`: a behaviour chart over two parameters (issue 29). The request, its limits,
//! its tasks, its store, its executor and its result layout are the library's
//! ([`afmdyn::request::chart`], [`afmdyn::analysis::chart`],
//! [`afmdyn::study::chart_store`], [`afmdyn::study`]); this front end maps the flags, runs
//! the study with a progress bar, and writes `chart.csv`, `chart.nc` (from the layout) and the
//! maps.

use crate::args::{Dim, ModelArgs, Quantity};
use crate::door::{self, Exit, Resume};
use crate::error::CliError;
use crate::flags::ChartFlags;
use afmdyn::request::chart::{axis_name, axis_unit};
use afmdyn::request::{Params, Resolved};
use clap::Args;
use std::path::PathBuf;

/// `afmdyn chart` flags.
#[derive(Debug, Args)]
pub struct ChartArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: ChartFlags,
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
        (_, Some(d)) => crate::args::flag_value(q, flag, d, true),
        (None, None) => Ok(q.value),
    }
}

/// Run `afmdyn chart`: the chart the library builds from the flags (validated, held to the
/// budgets), run through the door resumably into the store in `--out`.
pub fn chart(a: &ChartArgs) -> Result<(), CliError> {
    let (spec, probe) = a.model.spec_and_probe()?;
    // the chart reads the probe file's text: an axis may be one of its values
    let probe_text = match probe {
        Some(_) => a.model.probe_text()?,
        None => None,
    };
    let request = a.request.request(axis_value)?;
    let chart = request
        .chart(spec, Params::default(), probe_text.as_deref())
        .map_err(|e| CliError::Input(crate::error::spell(&e)))?;
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "cells",
        ..Exit::default()
    };
    let how = Resume {
        resume: a.resume,
        abort_after: a.abort_after,
        what: "chart",
    };
    // the chart's model is its own: the one given is not read
    let model = Resolved::plain(Params::default());
    door::run_stored(&chart, &model, exit, how)
}
