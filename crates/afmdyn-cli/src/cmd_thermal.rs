//! `afmdyn thermal`: the free lever's thermal spectrum at a temperature — each mode's share
//! and the one-sided PSDs of the tip's deflection and of the optical lever's apparent
//! deflection ([`afmdyn::request::ThermalRequest`]; the library computes and presents it, this
//! front end maps the flags and runs it through the door).

use crate::args::ModelArgs;
use crate::door::{self, Exit};
use crate::error::CliError;
use crate::flags_afm::ThermalFlags;
use afmdyn::request::run::Request;
use afmdyn::request::{Params, Resolved};
use clap::Args;
use std::path::PathBuf;

/// `afmdyn thermal` flags.
#[derive(Debug, Args)]
pub struct ThermalArgs {
    #[command(flatten)]
    model: ModelArgs,
    /// The request's flags: --temperature, --spot, --to, --points
    #[command(flatten)]
    request: ThermalFlags,
    /// Output directory
    #[arg(long, default_value = "afmdyn-out/thermal")]
    out: PathBuf,
    /// Print one JSON document (each mode's share and the spectrum)
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn thermal`.
pub fn thermal(a: &ThermalArgs) -> Result<(), CliError> {
    let request = a.request.request(a.model.probe.is_some())?;
    let (params, probe) = a
        .model
        .resolve_for(Params::default(), request.probe_needs())?;
    let exit = Exit {
        json: a.json,
        out: Some(&a.out),
        unit: "frequencies",
        ..Exit::default()
    };
    door::run(&request, &Resolved { params, probe }, exit).map(drop)
}
