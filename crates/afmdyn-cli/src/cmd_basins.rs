//! `afmdyn basins`: a basin map over two coordinates of the initial state (issue 30). The
//! request, its limits, the map and its document are the library's
//! ([`afmdyn::request::BasinsRequest`], [`afmdyn::analysis::basins`]); this front end parses,
//! runs with a progress bar and writes `basins.csv`, `basins.nc`, the map and the JSON document.

use crate::args::ModelArgs;
use crate::cmd_simulate::parse_modal_state;
use crate::door::{self, Exit, Resume};
use crate::error::CliError;
use crate::flags::BasinsFlags;
use afmdyn::request::Params;
use afmdyn::request::Resolved;
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
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = a
        .request
        .request(parse_modal_state("base", &a.base, params.modes)?);
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "starts",
        ..Exit::default()
    };
    let how = Resume {
        resume: a.resume,
        abort_after: a.abort_after,
        what: "basins",
    };
    door::run_stored(&request, &Resolved { params, probe }, exit, how)
}
