//! `afmdyn fm`: the frequency-modulation curve at constant amplitude over the rest distance
//! z_c — the drive frequency an ideal PLL locks at and the excitation an ideal amplitude
//! controller sets, as exact periodic orbits. The request, the analysis and the document are
//! the library's ([`afmdyn::request::FmRequest`], [`afmdyn::analysis::fm`]), and so are its
//! summary, `fm.csv`, `fm.json` and the frequency-shift figure
//! ([`afmdyn::report::present::fm`]); this front end maps the flags.

use crate::args::ModelArgs;
use crate::cmd_approach::files;
use crate::cmd_simulate::Files;
use crate::door::{self, Exit};
use crate::error::CliError;
use crate::flags::FmFlags;
use afmdyn::request::{Params, Resolved};
use clap::Args;
use std::path::PathBuf;

/// `afmdyn fm` flags.
#[derive(Debug, Args)]
pub struct FmArgs {
    #[command(flatten)]
    model: ModelArgs,
    #[command(flatten)]
    request: FmFlags,
    /// Output directory (locked during the run)
    #[arg(long, default_value = "afmdyn-out/fm")]
    out: PathBuf,
    /// Files written: all (data and plots), data (no plots) or none (only the summary)
    #[arg(long, value_enum, default_value = "all")]
    files: Files,
    /// Print one JSON document
    #[arg(long)]
    json: bool,
}

/// Run `afmdyn fm` through the door.
pub fn fm(a: &FmArgs) -> Result<(), CliError> {
    let (params, probe) = a.model.resolve(Params::default())?;
    let request = a.request.request(a.model.probe.is_some())?;
    let exit = Exit {
        json: a.json,
        out: (a.files != Files::None).then_some(a.out.as_path()),
        files: files(a.files),
        unit: "z_c values",
        ..Exit::default()
    };
    door::run(&request, &Resolved { params, probe }, exit).map(drop)
}
