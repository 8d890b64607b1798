//! `afmdyn basins`: a basin map over two coordinates of the initial state (issue 30). The
//! request, its limits, the map and its document are the library's
//! ([`afmdyn::request::BasinsRequest`], [`afmdyn::analysis::basins`]); this front end parses,
//! runs with a progress bar and writes `basins.csv`, `basins.nc`, the map and the JSON document.

use crate::args::ModelArgs;
use crate::cmd_simulate::parse_modal_state;
use crate::error::CliError;
use crate::flags::BasinsFlags;
use crate::output::OutDir;
use afmdyn::request::Params;
use afmdyn::request::{Analysis, Resolved};
use afmdyn::study::basins::{basin_store, BasinStudy};
use clap::Args;
use std::path::PathBuf;

/// `afmdyn basins` flags.
#[derive(Debug, Args)]
pub struct BasinsArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: BasinsFlags,
    /// The other coordinates of every start, "a1,..,aN;adot1,..,adotN" (default: at rest)
    #[arg(long)]
    base: Option<String>,
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
    let request = a
        .request
        .request(parse_modal_state("base", &a.base, p.modes)?);
    let study = BasinStudy::new(&request, &p)?;
    let out = OutDir::lock(&a.out)?;
    let mut store = basin_store(out.dir_lock());
    let failed = |e| crate::error::study_error(e, "basins");
    crate::progress::study(
        &study,
        &mut store,
        a.resume,
        request.threads,
        "starts",
        a.abort_after,
    )
    .map_err(failed)?;
    let rows = store
        .records()
        .map_err(|e| crate::error::store_error(e, "basins"))?;
    let map = afmdyn::request::in_pool(request.threads, || {
        study.map(rows.into_iter().map(|(_, r)| r))
    })?;
    let resolved = Resolved { params: p, probe };
    let mut doc = afmdyn::request::run::document(&request, &resolved, &map)?;
    doc["csv"] = serde_json::json!(out.join("basins.csv"));
    doc["netcdf"] = serde_json::json!(out.join("basins.nc"));
    let units = crate::output::units_of(resolved.probe.as_ref());
    let shown = request.present(&resolved, &map, &doc, units)?;
    crate::door::emit_as(Some(&out), &shown, &doc, a.json, true)
}
