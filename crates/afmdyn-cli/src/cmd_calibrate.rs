//! `afmdyn calibrate`: a lever's spring constant from its measured thermal spectrum, by the
//! thermal method and by Sader's, and the InvOLS of a force curve
//! ([`afmdyn::request::CalibrateRequest`]; the library computes and presents it, this front end
//! maps the flags and runs it through the door).

use crate::args::ModelArgs;
use crate::door::{self, Exit};
use crate::error::CliError;
use crate::flags_afm::CalibrateFlags;
use afmdyn::request::run::Request;
use afmdyn::request::{Params, Resolved};
use clap::Args;
use std::path::PathBuf;

/// `afmdyn calibrate` flags.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// The request's flags: --psd, --signal, --volts, --invols, --force-curve, --temperature, --spot, --peaks, --bands
    #[command(flatten)]
    request: CalibrateFlags,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out/calibrate")]
    out: PathBuf,
    /// Print one JSON document (each mode's estimates and standard errors)
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn calibrate`.
pub fn calibrate(a: &CalibrateArgs) -> Result<(), CliError> {
    let request = a.request.request(a.model.probe.is_some())?;
    let (params, probe) = a
        .model
        .resolve_for(Params::default(), request.probe_needs())?;
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "evaluations",
        ..Exit::default()
    };
    door::run(&request, &Resolved { params, probe }, exit).map(drop)
}
