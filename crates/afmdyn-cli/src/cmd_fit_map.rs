//! `afmdyn fit-map`: every curve of a force-volume or QI map fitted as `afmdyn fit` fits one,
//! the results laid on the map's grid (a modulus map, a topography, flags). The request, the
//! map's reader, the fits, the store and the presentation are the library's
//! ([`afmdyn::request::FitMapRequest`], [`afmdyn::study::fit_map`],
//! [`afmdyn::report::fit_map`]); this front end maps the flags and runs it through the door,
//! resumably into the store in `--out`.

use crate::args::ModelArgs;
use crate::door::{self, Exit, Resume};
use crate::error::CliError;
use crate::flags_afm::FitMapFlags;
use afmdyn::request::run::Request;
use afmdyn::request::{Params, Resolved};
use clap::Args;
use std::path::PathBuf;

/// `afmdyn fit-map` flags.
#[derive(Debug, Args)]
pub struct FitMapArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// The request's flags: --data, --fit, --segment, --range, --threads
    #[command(flatten)]
    request: FitMapFlags,
    /// Continue an interrupted map; refused unless the other arguments are those of the
    /// interrupted run (recorded in OUT/.fit_map.run.json)
    #[arg(long)]
    resume: bool,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/fit-map")]
    out: PathBuf,
    /// Testing: abort the process, as if killed, after this many lines are stored
    #[arg(long, hide = true)]
    abort_after: Option<usize>,
    /// Print one JSON document (the summary and every curve)
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn fit-map`.
pub fn fit_map(a: &FitMapArgs) -> Result<(), CliError> {
    // a range may carry a unit with a probe (SI)
    let request = a.request.request(a.model.probe.is_some())?;
    let (params, probe) = a
        .model
        .resolve_for(Params::default(), request.probe_needs())?;
    let model = Resolved { params, probe };
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "curves",
        ..Exit::default()
    };
    let how = Resume {
        resume: a.resume,
        abort_after: a.abort_after,
        what: "fit-map",
    };
    door::run_stored(&request, &model, exit, how)
}
